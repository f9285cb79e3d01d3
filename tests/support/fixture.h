/* fixture.h - a per-test fixture for cmocka: each test gets a fresh
 * object as its state, made before it and freed after it, whatever the
 * test did (test_fit_shift.c, test_fit_stereo.c, test_raster_basic.c).
 * Header-only (a macro); include after support/testutil.h and <cmocka.h>.
 *
 *   TU_FIXTURE(scene, scene, s, scene_make(s), scene_free(s))
 *   ... cmocka_unit_test_setup_teardown(a_test, scene_setup, scene_teardown)
 *
 * and in the test: scene *s = *state;
 *
 * What MAKE asserts runs in cmocka's setup: a failure there is reported as
 * the test's setup failing (the run still fails) and its teardown is not
 * run, so keep the checks a test is about in the test's body. */
#ifndef EGOFUSE_TU_FIXTURE_H
#define EGOFUSE_TU_FIXTURE_H

#include <stdlib.h>

/* The cmocka setup NAME_setup and teardown NAME_teardown of a TYPE: the
 * setup allocates it as var (the test fails when out of memory) and runs
 * MAKE on it, the teardown runs RELEASE on it and frees it. */
#define TU_FIXTURE(name, type, var, make, release)                            \
    static int name##_setup(void **state)                                     \
    {                                                                         \
        type *var = malloc(sizeof *var);                                      \
        assert_non_null(var);                                                 \
        make;                                                                 \
        *state = var;                                                         \
        return 0;                                                             \
    }                                                                         \
    static int name##_teardown(void **state)                                  \
    {                                                                         \
        type *var = *state;                                                   \
        release;                                                              \
        free(var);                                                            \
        return 0;                                                             \
    }

#endif
