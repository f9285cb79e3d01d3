/* simd_rcheck.h - runs the raster ops of the vector layer (src/cpu/simd.h,
 * "RASTER OPS") of one ISA over arrays, for tests/test_cpu_simd_raster.c,
 * which compares the results with a scalar model of the contract.
 * simd_rcheck.inl is the one body; simd_rcheck_<isa>.c compile it once per
 * ISA (kept apart from simd_check.* so that the fuse port can add its ops
 * there without touching these files). */
#ifndef EGOFUSE_TU_SIMD_RCHECK_H
#define EGOFUSE_TU_SIMD_RCHECK_H

#include <stdint.h>

enum {
    RC_SIGN_BITS,     /* a: int lanes; out[l] = bit l of vi_sign_bits (out[v] = 0xBAD
                       * when a bit above the lanes is set) */
    RC_VB_STORE_BITS, /* out: bytes, vb_store_bits per SIMD_W bytes with bits k */
    RC_STORE3_BITS,   /* out: floats, vf_store3_bits per 3*SIMD_W floats of a (x, y,
                       * z vectors one after the other) with bits k */
    /* the raster front-end ops (simd.h "RASTER FRONT-END OPS") */
    RC_VI_MINMAX,     /* a: int lanes, blocks of 2*SIMD_W (i, j); out: vi_min(i, j)
                       * then vi_max(i, j) at the block's place */
    RC_VD_FROM_VF,    /* a: n/2 floats; out: n/2 doubles, vd_from_vf per half */
    RC_VD_FROM_VI,    /* a: n/2 int32; out: n/2 doubles, vd_from_vi per half */
    RC_VF_FROM_VD,    /* a: n/2 doubles; out: n/2 floats, vf_from_vd(lo, hi) */
    RC_VD_GT_BITS,    /* a: n/2 doubles, blocks of 2*VD_W (x, y); out[block + l] =
                       * bit l of vd_gt_bits(x, y), out[block + VD_W + l] = 0
                       * (0xBAD in out[block] when a bit above VD_W is set) */
    RC_VD_SQRT,       /* a: n/2 doubles; out: n/2 doubles, vd_sqrt */
    /* the raster edge ops (simd.h "RASTER EDGE OPS"; the op returns 0 on an
     * ISA without them) */
    RC_VL_ARITH,      /* a: blocks b of 3*SIMD_W int32 (i, j, f); out: int64
                       * out64[b*SIMD_W + l] = vl_dec_unless(i*j - (i << 8) + j,
                       * f < 0, h) by vl_mul32, vl_slli, vl_sub, vl_add, vl_or
                       * (with vl_zero), lane l of half h; then, at out + 2n/3,
                       * uint32 per lane: bit of vl_sign_bits of that value
                       * (0xBAD when a bit above VD_W is set) */
    RC_VL_ZIP,        /* a: blocks b of 2*SIMD_W int32 (i, j), n/(4*SIMD_W) of them
                       * (the output is twice the input); out: int64, per half
                       * h: vl_zip_lo then vl_zip_hi of the widened halves
                       * (2*VD_W int64 per half) */
    RC_COMPRESS,      /* out[l] = lane l of vi_compress_lanes(k), l < SIMD_W */
    RC_COUNT
};

/* n: a multiple of 3 * 16 (floats, ints or, for bytes, bytes). Returns
 * the lanes (SIMD_W), 0 when this build does not have the ISA. */
typedef int tu_simd_rcheck_fn(int op, const uint32_t *a, unsigned k, int n, void *out);
tu_simd_rcheck_fn tu_simd_rcheck_sse2, tu_simd_rcheck_avx2, tu_simd_rcheck_avx512,
    tu_simd_rcheck_neon;

#endif
