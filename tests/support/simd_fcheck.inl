/* simd_fcheck.inl - the body of tu_simd_fcheck_<isa> (simd_fcheck.h), named
 * FC_NAME, on the vector layer included before it; without one (the ISA
 * is not this target's) a stub that returns 0. */
#include "simd_fcheck.h"

#ifndef SIMD_W
int FC_NAME(int op, const uint32_t *a, const uint32_t *b, int n, uint32_t *out)
{
    (void)op, (void)a, (void)b, (void)n, (void)out;
    return 0;
}
#else
int FC_NAME(int op, const uint32_t *a, const uint32_t *b, int n, uint32_t *out)
{
    for (int v = 0; v + SIMD_W <= n; v += SIMD_W) {
        const vint i = vi_loadu((const int32_t *)(const void *)(a + v));
        const vint j = vi_loadu((const int32_t *)(const void *)(b + v));
        vint r;
        switch (op) {
        case FC_MIN: r = vi_min(i, j); break;
        case FC_PERMUTE: r = vi_permute(i, j); break;
        case FC_GATHER: r = vi_gather((const int32_t *)(const void *)a, j); break;
        case FC_HZIP_LO: r = vh_zip_lo(i, j); break;
        case FC_HZIP_HI: r = vh_zip_hi(i, j); break;
        case FC_HMADD: r = vh_madd(i, j); break;
        case FC_HPACKUS32: r = vh_packus32(i, j); break;
        case FC_HMULHI: r = vh_mulhi(i, j); break;
        default: return -1;
        }
        vi_storeu((int32_t *)(void *)(out + v), r);
    }
    return SIMD_W;
}
#endif
