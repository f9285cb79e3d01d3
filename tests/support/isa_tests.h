/* isa_tests.h - the frame of per-ISA tests: the skip of an ISA this CPU
 * does not run (test_raster_records.c, test_raster_xform.c), reported as
 * SKIP (cmocka skip()), never as a pass, with what goes untested; and the
 * cmocka tests of a check run once per ISA, generated from the check
 * (test_raster_hidden.c, test_raster_span.c, test_kin_skin_isa.c,
 * test_kin_skin_plan.c):
 *
 *   static void span_isa(int isa) { ... }
 *   TU_ISA_TESTS(test_span_, span_isa)   // test_span_sse2 ... test_span_neon
 *   TU_MAIN(NULL, NULL, TU_ISA_UNIT_TESTS(test_span_))
 *
 * Header-only; include after support/testutil.h, <cmocka.h> and
 * src/cpu/cpu.h. */
#ifndef EGOFUSE_TU_ISA_TESTS_H
#define EGOFUSE_TU_ISA_TESTS_H

/* Returns when this CPU runs isa; else prints "SKIP <isa>: not supported
 * by this CPU; untested: <untested>" and skips the test. */
static inline void tu_skip_unless_isa(ef_isa isa, const char *untested)
{
    if (ef_cpu_has(isa)) return;
    print_message("SKIP %s: not supported by this CPU; untested: %s\n", ef_isa_name(isa),
                  untested);
    skip();
}

/* The cmocka test NAME: check(isa). */
#define TU_ISA_TEST_(name, check, isa)                                        \
    static void name(void **state)                                            \
    {                                                                         \
        (void)state;                                                          \
        check(isa);                                                           \
    }

/* The tests PREFIX##avx2 and PREFIX##avx512 of check (TU_AVX_ISA_TESTS),
 * with PREFIX##sse2 before them (TU_X86_ISA_TESTS), and PREFIX##neon
 * after those (TU_ISA_TESTS); each calls check(EF_ISA_<its ISA>). */
#define TU_AVX_ISA_TESTS(prefix, check)                                       \
    TU_ISA_TEST_(prefix##avx2, check, EF_ISA_AVX2)                            \
    TU_ISA_TEST_(prefix##avx512, check, EF_ISA_AVX512)
#define TU_X86_ISA_TESTS(prefix, check)                                       \
    TU_ISA_TEST_(prefix##sse2, check, EF_ISA_SSE2)                            \
    TU_AVX_ISA_TESTS(prefix, check)
#define TU_ISA_TESTS(prefix, check)                                           \
    TU_X86_ISA_TESTS(prefix, check)                                           \
    TU_ISA_TEST_(prefix##neon, check, EF_ISA_NEON)

/* Those tests, in that order, as entries of a cmocka test list. */
#define TU_AVX_ISA_UNIT_TESTS(prefix)                                         \
    cmocka_unit_test(prefix##avx2), cmocka_unit_test(prefix##avx512)
#define TU_X86_ISA_UNIT_TESTS(prefix)                                         \
    cmocka_unit_test(prefix##sse2), TU_AVX_ISA_UNIT_TESTS(prefix)
#define TU_ISA_UNIT_TESTS(prefix)                                             \
    TU_X86_ISA_UNIT_TESTS(prefix), cmocka_unit_test(prefix##neon)

#endif
