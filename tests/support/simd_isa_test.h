/* simd_isa_test.h - the frame the per-ISA tests (tests/test_cpu_simd*.c,
 * test_raster_small.c) share: the seeded xorshift draw of the vector
 * layer's tests, the skip of an ISA this machine does not run (reported as
 * SKIP, never as a pass), and the four per-ISA tests test_sse2, test_avx2,
 * test_avx512, test_neon.
 * Header-only (static inline); include after support/testutil.h,
 * <cmocka.h> and src/cpu/cpu.h.
 *
 *   static void check_isa(void **state)
 *   {
 *       const ef_isa isa = tu_simd_test_isa(state, " fuse", "the row-cache ops of ");
 *       tu_simd_fcheck_fn *const fn = tu_simd_fcheck_isa[tu_simd_isa_index_of(state)];
 *       ...
 *   }
 *   int main(void) { return tu_simd_run_isas(check_isa); }
 */
#ifndef EGOFUSE_TU_SIMD_ISA_TEST_H
#define EGOFUSE_TU_SIMD_ISA_TEST_H

#include <stdint.h>

#include "simd_check.h"
#include "simd_fcheck.h"
#include "simd_qcheck.h"
#include "simd_rcheck.h"

/* The check functions of each layer by the index of tu_simd_isas: sse2,
 * avx2, avx512, neon (support/simd_isa_fns.c). */
extern tu_simd_check_fn *const tu_simd_check_isa[4];
extern tu_simd_fcheck_fn *const tu_simd_fcheck_isa[4];
extern tu_simd_qcheck_fn *const tu_simd_qcheck_isa[4];
extern tu_simd_rcheck_fn *const tu_simd_rcheck_isa[4];

/* xorshift64 (13, 7, 17) of *s; returns bits 16..47 of the new state. */
static inline uint32_t tu_xorshift(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (uint32_t)(*s >> 16);
}

/* The ISAs of the vector layer, in the order of their tests. */
static const ef_isa tu_simd_isas[4] = {EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON};
static int tu_simd_isa_index[4] = {0, 1, 2, 3};

/* The index into tu_simd_isas of a per-ISA test (its state). */
static inline int tu_simd_isa_index_of(void **state) { return *(const int *)*state; }

/* The ISA of a per-ISA test; the test skipped (cmocka skip()) when this
 * CPU or build does not run it, with "SKIP cpu simd<what> <isa>: ...;
 * untested: <ops>src/cpu/simd_<isa>.h" (what: "" or " fuse", ...; ops: ""
 * or "the fuse ops of "). */
static inline ef_isa tu_simd_test_isa(void **state, const char *what, const char *ops)
{
    const ef_isa isa = tu_simd_isas[tu_simd_isa_index_of(state)];
    if (ef_cpu_has(isa)) return isa;
    print_message("SKIP cpu simd%s %s: this CPU (or this build's architecture) does not run "
                  "it; untested: %ssrc/cpu/simd_%s.h\n", what, ef_isa_name(isa), ops,
                  ef_isa_name(isa));
    skip();
    return isa;
}

/* The per-ISA test i (0..3) of test: named test_<isa>, its state
 * &tu_simd_isa_index[i]. */
static inline struct CMUnitTest tu_simd_isa_test(CMUnitTestFunction test, int i)
{
    static const char *const names[4] = {"test_sse2", "test_avx2", "test_avx512", "test_neon"};
    struct CMUnitTest t = {names[i], test, NULL, NULL, &tu_simd_isa_index[i]};
    return t;
}

/* Runs the four per-ISA tests of test as the binary's tests. */
static inline int tu_simd_run_isas(CMUnitTestFunction test)
{
    const struct CMUnitTest tests[] = {
        tu_simd_isa_test(test, 0), tu_simd_isa_test(test, 1), tu_simd_isa_test(test, 2),
        tu_simd_isa_test(test, 3),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

#endif
