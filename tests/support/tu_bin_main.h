/* tu_bin_main.h - the main of a test binary that runs the egofuse binary
 * (tu_bin()): without it built, the binary says SKIP and succeeds.
 * Include after support/testutil.h and <cmocka.h>. */
#ifndef EGOFUSE_TU_BIN_MAIN_H
#define EGOFUSE_TU_BIN_MAIN_H

/* TU_MAIN(setup, teardown, entries...) when tu_bin() exists; else
 * "SKIP: ... not built" and exit status 0. */
#define TU_MAIN_NEEDS_BIN(setup, teardown, ...)                               \
    int main(void)                                                            \
    {                                                                         \
        if (!tu_exists(tu_bin())) {                                           \
            printf("SKIP: %s not built\n", tu_bin());                         \
            return 0;                                                         \
        }                                                                     \
        const struct CMUnitTest tests[] = {__VA_ARGS__};                      \
        return cmocka_run_group_tests(tests, setup, teardown);                \
    }

#endif
