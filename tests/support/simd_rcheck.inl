/* simd_rcheck.inl - the body of tu_simd_rcheck_<isa> (simd_rcheck.h), on
 * the vector layer included before it (named RC_NAME); without one (the ISA
 * is not this target's) a stub that returns 0. */
#include "simd_rcheck.h"

#ifndef SIMD_W
int RC_NAME(int op, const uint32_t *a, unsigned k, int n, void *out)
{
    (void)op, (void)a, (void)k, (void)n, (void)out;
    return 0;
}
#else
int RC_NAME(int op, const uint32_t *a, unsigned k, int n, void *out)
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
    case RC_VI_MINMAX: {
        int32_t *o = out;
        const int32_t *p = (const int32_t *)(const void *)a;
        for (int v = 0; v + 2 * W <= n; v += 2 * W) {
            const vint i = vi_loadu(p + v), j = vi_loadu(p + v + W);
            vi_storeu(o + v, vi_min(i, j));
            vi_storeu(o + v + W, vi_max(i, j));
        }
        return W;
    }
    case RC_VD_FROM_VF:
    case RC_VD_FROM_VI: {
        double *o = out;
        for (int v = 0; v + W <= n / 2; v += W) {
            const vfloat f = vf_loadu((const float *)(const void *)(a + v));
            const vint i = vi_loadu((const int32_t *)(const void *)(a + v));
            vd_storeu(o + v, op == RC_VD_FROM_VF ? vd_from_vf(f, 0) : vd_from_vi(i, 0));
            vd_storeu(o + v + VD_W, op == RC_VD_FROM_VF ? vd_from_vf(f, 1) : vd_from_vi(i, 1));
        }
        return W;
    }
    case RC_VF_FROM_VD: {
        float *o = out;
        const double *d = (const double *)(const void *)a;
        for (int v = 0; v + W <= n / 2; v += W)
            vf_storeu(o + v, vf_from_vd(vd_loadu(d + v), vd_loadu(d + v + VD_W)));
        return W;
    }
    case RC_VD_GT_BITS: {
        uint32_t *o = out;
        const double *d = (const double *)(const void *)a;
        for (int g = 0; g + 2 * VD_W <= n / 2; g += 2 * VD_W) {
            const unsigned bits = vd_gt_bits(vd_loadu(d + g), vd_loadu(d + g + VD_W));
            for (int l = 0; l < VD_W; l++) {
                o[g + l] = (bits >> l) & 1u;
                o[g + VD_W + l] = 0;
            }
            if (bits >> VD_W) o[g] = 0xBAD;
        }
        return W;
    }
    case RC_VD_SQRT: {
        double *o = out;
        const double *d = (const double *)(const void *)a;
        for (int v = 0; v + VD_W <= n / 2; v += VD_W) vd_storeu(o + v, vd_sqrt(vd_loadu(d + v)));
        return W;
    }
#ifdef SIMD_HAS_VL
    case RC_VL_ARITH: {
        int64_t *o = out;
        uint32_t *sb = (uint32_t *)out + 2 * n / 3;
        const int32_t *p = (const int32_t *)(const void *)a;
        _Alignas(SIMD_ALIGN) int64_t t[VD_W];
        for (int b = 0; 3 * W * (b + 1) <= n; b++) {
            const vint i = vi_loadu(p + 3 * W * b), j = vi_loadu(p + 3 * W * b + W);
            const vmask m = vi_gt(vi_zero(), vi_loadu(p + 3 * W * b + 2 * W));
            for (int h = 0; h < 2; h++) {
                const vlong I = vl_from_vi(i, h), J = vl_from_vi(j, h);
                const vlong r = vl_add(vl_sub(vl_mul32(I, J), vl_slli(I, 8)), vl_or(J, vl_zero()));
                const vlong d = h ? vl_dec_unless(r, m, 1) : vl_dec_unless(r, m, 0);
                vl_store(t, d);
                const unsigned bits = vl_sign_bits(d);
                for (int l = 0; l < VD_W; l++) {
                    o[W * b + VD_W * h + l] = t[l];
                    sb[W * b + VD_W * h + l] = (bits >> l) & 1u;
                }
                if (bits >> VD_W) sb[W * b + VD_W * h] = 0xBAD;
            }
        }
        return W;
    }
    case RC_VL_ZIP: {
        int64_t *o = out;
        const int32_t *p = (const int32_t *)(const void *)a;
        _Alignas(SIMD_ALIGN) int64_t t[2][VD_W];
        for (int b = 0; 4 * W * (b + 1) <= n; b++) {
            const vint i = vi_loadu(p + 2 * W * b), j = vi_loadu(p + 2 * W * b + W);
            for (int h = 0; h < 2; h++) {
                const vlong I = h ? vl_from_vi(i, 1) : vl_from_vi(i, 0);
                const vlong J = h ? vl_from_vi(j, 1) : vl_from_vi(j, 0);
                vl_store(t[0], vl_zip_lo(I, J));
                vl_store(t[1], vl_zip_hi(I, J));
                __builtin_memcpy(o + 2 * W * b + 2 * VD_W * h, t, sizeof t);
            }
        }
        return W;
    }
    case RC_COMPRESS: {
        vi_storeu((int32_t *)out, vi_compress_lanes(k));
        return W;
    }
#else
    case RC_VL_ARITH:
    case RC_VL_ZIP:
    case RC_COMPRESS: return 0;
#endif
    default: return -1;
    }
}
#endif
