/* simd_fcheck.h - runs the row-cache ops of the vector layer (src/cpu/simd.h,
 * "ROW-CACHE OPS") of one ISA over arrays, for tests/test_cpu_simd_fuse.c,
 * which compares the results with a scalar model of the contract.
 * simd_fcheck.inl is the one body; simd_fcheck_<isa>.c compile it once per
 * ISA (apart from simd_check.* and simd_rcheck.*, so that each port adds
 * its ops without touching the others' files). */
#ifndef EGOFUSE_TU_SIMD_FCHECK_H
#define EGOFUSE_TU_SIMD_FCHECK_H

#include <stdint.h>

enum {
    FC_MIN,        /* vi_min(a, b) */
    FC_PERMUTE,    /* vi_permute(a, b) */
    FC_GATHER,     /* vi_gather(a, b): b holds indices into a[0 .. n) */
    FC_HZIP_LO,    /* vh_zip_lo(a, b) */
    FC_HZIP_HI,    /* vh_zip_hi(a, b) */
    FC_HMADD,      /* vh_madd(a, b) */
    FC_HPACKUS32,  /* vh_packus32(a, b) */
    FC_HMULHI,     /* vh_mulhi(a, b) */
    FC_COUNT
};

/* n: a multiple of 16. Vector v of out is op(vector v of a, vector v of
 * b). Returns the lanes (SIMD_W), 0 when this build lacks the ISA. */
typedef int tu_simd_fcheck_fn(int op, const uint32_t *a, const uint32_t *b, int n,
                              uint32_t *out);
tu_simd_fcheck_fn tu_simd_fcheck_sse2, tu_simd_fcheck_avx2, tu_simd_fcheck_avx512,
    tu_simd_fcheck_neon;

#endif
