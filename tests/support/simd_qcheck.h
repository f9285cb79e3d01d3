/* simd_qcheck.h - runs the refine ops of the vector layer (src/cpu/simd.h,
 * "REFINE OPS") of one ISA over arrays, for tests/test_cpu_simd_refine.c,
 * which compares the results with a scalar model of the contract.
 * simd_qcheck.inl is the one body; simd_qcheck_<isa>.c compile it once per
 * ISA (apart from the other simd_*check files, so that each block of ops
 * keeps its own files). */
#ifndef EGOFUSE_TU_SIMD_QCHECK_H
#define EGOFUSE_TU_SIMD_QCHECK_H

#include <stdint.h>

enum {
    QC_SIGN_BITS,  /* bytes: out[k] = bit (k % VB_W) of vb_sign_bits(vb_loadu) */
    QC_SIGN_FILL,  /* bytes: vb_storeu(vb_sign_fill(vb_loadu)) */
    QC_H_LOAD_U8,  /* a's bytes to out's uint16: vh_storeu(vh_load_u8) */
    QC_H_MIN_U,    /* uint16: vh_min_u(a, b) */
    QC_H_ADDS_U,   /* uint16: vh_adds_u(a, b) */
    QC_H_ANY_LEU,  /* uint16: out[first lane of each VH_W] = vh_any_leu(a, b), others 0 */
    QC_LOAD_U16,   /* a's uint16 to out's uint32: vi_storeu(vi_load_u16) */
    QC_H_RUNMIN3_UP, /* uint16: vh_runmin3_up(a, b[first lane of the vector]) */
    QC_H_RUNMIN3_DN, /* uint16: vh_runmin3_dn(a, b[first lane of the vector]) */
    QC_COUNT
};

/* n elements (a multiple of 64) of the op's input type (bytes of a, or
 * uint16 of a and b), out sized for n uint32. Returns the lanes (SIMD_W),
 * 0 when this build lacks the ISA. */
typedef int tu_simd_qcheck_fn(int op, const uint16_t *a, const uint16_t *b, int n,
                              uint32_t *out);
tu_simd_qcheck_fn tu_simd_qcheck_sse2, tu_simd_qcheck_avx2, tu_simd_qcheck_avx512,
    tu_simd_qcheck_neon;

#endif
