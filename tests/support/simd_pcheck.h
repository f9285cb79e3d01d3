/* simd_pcheck.h - runs the reprojection ops of the vector layer
 * (src/cpu/simd.h, "REPROJ OPS": vf_gather, vf_gather_m, vi_gather_u8x4,
 * vi_store_u8)
 * of one ISA over arrays, for tests/test_cpu_simd_reproj.c, which compares
 * the results with a scalar model of the contract. simd_pcheck.inl is the
 * one body; simd_pcheck_<isa>.c compile it once per ISA. */
#ifndef EGOFUSE_TU_SIMD_PCHECK_H
#define EGOFUSE_TU_SIMD_PCHECK_H

#include <stdint.h>

enum {
    PC_FGATHER,   /* out[i] = bits of vf_gather((float *)a, idx)[i] */
    PC_U8X4,      /* out[i] = vi_gather_u8x4((uint8_t *)a, idx)[i] */
    PC_STORE_U8,  /* ((uint8_t *)out)[i] = vi_store_u8 of a's vector */
    PC_FGATHER_M, /* out[i] = bits of vf_gather_m((float *)a, idx, idx >= 0)[i]:
                     lanes with idx[i] < 0 are off (and must not be read) */
    PC_COUNT
};

/* n: a multiple of 16; idx[i] indices (floats or bytes) into a. Returns
 * the lanes (SIMD_W), 0 when this build lacks the ISA. */
typedef int tu_simd_pcheck_fn(int op, const uint32_t *a, const int32_t *idx, int n,
                              uint32_t *out);
tu_simd_pcheck_fn tu_simd_pcheck_sse2, tu_simd_pcheck_avx2, tu_simd_pcheck_avx512,
    tu_simd_pcheck_neon;

#endif
