/* test_pipe_mask.c - pipe_mask_render refuses every bad description with a
 * message naming the field and leaves the caller's buffers untouched.
 * (Its bytes against `egofuse mask`: test_install.c and the CRCs of
 * test_gltf_samples.c, since cmd_mask.c calls it.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "../src/pipe/pipe_mask.h"

static pipe_mask_desc good(void)
{
    pipe_mask_desc d = {0};
    d.width = 8; d.height = 6; d.fov_y = 60.0f; d.eye[2] = 3.0f;
    return d;
}

static void refused(const pipe_mask_desc *d, const char *word)
{
    kin_model m;
    memset(&m, 0, sizeof m);
    uint8_t mask[8 * 6], nrm[8 * 6 * 3];
    float depth[8 * 6];
    memset(mask, 7, sizeof mask);
    memset(nrm, 7, sizeof nrm);
    for (int i = 0; i < 48; i++) depth[i] = 7.0f;
    char why[200] = "";
    assert_int_equal(pipe_mask_render(&m, d, mask, nrm, depth, why, sizeof why), -1);
    if (!strstr(why, word)) fail_msg("message '%s' does not name '%s'", why, word);
    for (int i = 0; i < 48; i++) {
        assert_int_equal(mask[i], 7);
        assert_true(depth[i] == 7.0f);
    }
    for (int i = 0; i < 48 * 3; i++) assert_int_equal(nrm[i], 7);
}

static void test_refusals(void **state)
{
    (void)state;
    pipe_mask_desc d;
    d = good(); d.width = 0; refused(&d, "width");
    d = good(); d.height = 8193; refused(&d, "height");
    d = good(); d.fov_y = 180.0f; refused(&d, "fov_y");
    d = good(); d.fov_y = NAN; refused(&d, "fov_y");
    d = good(); d.znear = -1.0f; refused(&d, "znear");
    d = good(); d.znear = 5.0f; d.zfar = 4.0f; refused(&d, "zfar");
    d = good(); d.eye[2] = 0.0f; refused(&d, "same point");
    d = good(); d.eye[0] = INFINITY; refused(&d, "finite");
    d = good(); d.up[2] = 1.0f; refused(&d, "parallel");
    d = good(); d.time = NAN; refused(&d, "time");
    kin_animation other;
    d = good(); d.anim = &other; refused(&d, "anim");
    char why[64];
    assert_int_equal(pipe_mask_render(NULL, &d, NULL, NULL, NULL, why, sizeof why), -1);
    assert_int_equal(pipe_mask_render(NULL, &d, NULL, NULL, NULL, NULL, 0), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
