/* x86_only.h - for a test that calls the x86 SIMD kernels by name
 * (rast__setup_isa_avx2, rast__planes_avx512, ...), which exist on x86
 * only. Include it after cmocka.h and wrap the rest of the file:
 *
 *   #include "support/x86_only.h"
 *   #if EF_TEST_X86
 *   ... the tests and their main ...
 *   #else
 *   EF_TEST_X86_SKIP("what the test compares")
 *   #endif
 *
 * Elsewhere (ARM64, ...) the binary is one skipped test that says why;
 * the other tests check the portable path there (docs/portability.md). */
#ifndef EGOFUSE_X86_ONLY_H
#define EGOFUSE_X86_ONLY_H

#if defined(__x86_64__) || defined(__i386__)
#define EF_TEST_X86 1
#else
#define EF_TEST_X86 0
#define EF_TEST_X86_SKIP(what)                                                        \
    static void x86_only(void **state)                                                \
    {                                                                                 \
        (void)state;                                                                  \
        print_message("SKIP: " what ": x86 SIMD kernels, not built for this target\n"); \
        skip();                                                                       \
    }                                                                                 \
    int main(void)                                                                    \
    {                                                                                 \
        const struct CMUnitTest tests[] = { cmocka_unit_test(x86_only) };            \
        return cmocka_run_group_tests(tests, NULL, NULL);                             \
    }
#endif

#endif
