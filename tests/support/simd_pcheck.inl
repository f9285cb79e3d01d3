/* simd_pcheck.inl - the body of tu_simd_pcheck_<isa> (simd_pcheck.h), named
 * PC_NAME, on the vector layer included before it; without one (the ISA
 * is not this target's) a stub that returns 0. */
#include "simd_pcheck.h"

#ifndef SIMD_W
int PC_NAME(int op, const uint32_t *a, const int32_t *idx, int n, uint32_t *out)
{
    (void)op, (void)a, (void)idx, (void)n, (void)out;
    return 0;
}
#else
int PC_NAME(int op, const uint32_t *a, const int32_t *idx, int n, uint32_t *out)
{
    for (int v = 0; v + SIMD_W <= n; v += SIMD_W) {
        const vint j = vi_loadu(idx + v);
        switch (op) {
        case PC_FGATHER:
            vi_storeu((int32_t *)(void *)(out + v),
                      vf_as_vi(vf_gather((const float *)(const void *)a, j)));
            break;
        case PC_FGATHER_M:
            vi_storeu((int32_t *)(void *)(out + v),
                      vf_as_vi(vf_gather_m((const float *)(const void *)a, j,
                                           vi_gt(j, vi_set1(-1)))));
            break;
        case PC_U8X4:
            vi_storeu((int32_t *)(void *)(out + v),
                      vi_gather_u8x4((const uint8_t *)(const void *)a, j));
            break;
        case PC_STORE_U8:
            vi_store_u8((uint8_t *)(void *)out + v, vi_loadu((const int32_t *)(const void *)(a + v)));
            break;
        default: return -1;
        }
    }
    return SIMD_W;
}
#endif
