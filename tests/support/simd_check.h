/* simd_check.h - runs each operation of the vector layer (src/cpu/simd.h)
 * of one ISA over arrays of lanes, for tests/test_cpu_simd.c, which
 * compares every lane's bits with a scalar model of the contract.
 * simd_check.inl is the one body; simd_check_<isa>.c compile it once per
 * ISA (the Makefile gives *_avx2.c / *_avx512.c their -m flags), each to
 * a stub that returns 0 where the ISA's architecture is not the target's. */
#ifndef EGOFUSE_TU_SIMD_CHECK_H
#define EGOFUSE_TU_SIMD_CHECK_H

#include <stdint.h>

/* Operations; a, b, out: n lanes of bits (float or int32 by the op). */
enum {
    SC_ADD, SC_SUB, SC_MUL, SC_DIV, SC_MIN, SC_MAX,          /* float a, b */
    SC_SQRT, SC_NEG, SC_ABS, SC_FLOOR,                       /* float a */
    SC_EQ, SC_NE, SC_LT, SC_LE, SC_GT, SC_GE,                /* float -> lane mask */
    SC_BITS_LT, SC_ALL_LT, SC_ANY_LT,                        /* vm_bits / all / any */
    SC_SEL, SC_SELZ, SC_NEG_IF,                              /* with m = a < b */
    SC_FAND, SC_FOR, SC_FXOR, SC_FANDNOT,
    SC_IADD, SC_ISUB, SC_IMULLO, SC_IAND, SC_IOR, SC_IXOR, SC_IANDNOT,
    SC_IEQ, SC_IGT, SC_ISEL,                                 /* int a, b */
    SC_SLLI3, SC_SRLI5, SC_SRAI7, SC_SLL, SC_SRL,            /* SLL, SRL by k */
    SC_CVT_I2F, SC_CVT_TRUNC, SC_CVT_ROUND,
    SC_MAND, SC_MOR, SC_MANDNOT, SC_MNOT,                    /* on a < b, a > b */
    SC_FROM_BITS,                                            /* k: the bits */
    SC_LANES, SC_LOAD, SC_LOAD_BITS, SC_STORE_BITS,          /* bits k; out = b first */
    SC_LOAD3, SC_STORE3, SC_SCATTER3, SC_TR4,
    SC_LOAD_U8,                                              /* bytes of a from lane v0 */
    SC_STORE2,                                               /* groups of 2W: a's two vectors */
    SC_HADD, SC_HSUB, SC_HMUL, SC_HSRLI5, SC_HSET1,          /* 16-bit lanes; HSET1: k */
    SC_HLO8, SC_HHI8, SC_HPACKUS, SC_HBCAST3,
    SC_ZIPLO, SC_ZIPHI,                                      /* int a, b, per block */
    SC_TRB,                                                  /* vf_tr_blocks, groups of W*W/4 */
    SC_COUNT
};

/* n: a multiple of 3 * 16 * 4. Returns the lanes (SIMD_W) of the ISA, 0
 * when this build does not have it. */
typedef int tu_simd_check_fn(int op, const uint32_t *a, const uint32_t *b, int k, int n,
                             uint32_t *out);
tu_simd_check_fn tu_simd_check_sse2, tu_simd_check_avx2, tu_simd_check_avx512,
    tu_simd_check_neon;

#endif
