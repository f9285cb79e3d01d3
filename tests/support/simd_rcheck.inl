/* simd_rcheck.inl - the body of tu_simd_rcheck_<isa> (simd_rcheck.h), on
 * the vector layer included before it. */
#include "simd_rcheck.h"

int SIMD_FN(tu_simd_rcheck)(int op, const uint32_t *a, unsigned k, int n, void *out)
{
    const int W = SIMD_W;
    switch (op) {
    case RC_SIGN_BITS: {
        uint32_t *o = out;
        for (int v = 0; v + W <= n; v += W) {
            const unsigned bits = vi_sign_bits(vi_loadu((const int32_t *)(const void *)(a + v)));
            for (int l = 0; l < W; l++) o[v + l] = (bits >> l) & 1u;
            if (bits >> W) o[v] = 0xBAD;
        }
        return W;
    }
    case RC_VB_STORE_BITS: {
        uint8_t *o = out;
        for (int v = 0; v + W <= n; v += W) vb_store_bits(o + v, k);
        return W;
    }
    case RC_STORE3_BITS: {
        float *o = out;
        const float *p = (const float *)(const void *)a;
        for (int g = 0; g + 3 * W <= n; g += 3 * W)
            vf_store3_bits(o + g, k, vf_loadu(p + g), vf_loadu(p + g + W), vf_loadu(p + g + 2 * W));
        return W;
    }
    default: return -1;
    }
}
