/* test_kin_calib.c - per-user calibration (kin_calib.c): bone scales
 * estimated from a synthetic recording of a user 1.1x the model's size,
 * the file format (exact round trip, strict errors with line numbers),
 * and the effect: the calibrated rig reaches targets the model's own
 * arm cannot. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../src/kin/kin.h"

/* A rig as kin_arm_rig_init would give for the generated model. */
static kin_arm_rig model_rig(void)
{
    kin_arm_rig r;
    memset(&r, 0, sizeof r);
    r.upper_len[0] = r.upper_len[1] = 0.30f;
    r.fore_len[0] = r.fore_len[1] = 0.26f;
    r.shoulder_width = 0.38f;
    return r;
}

/* The recording: the user stretches the arms forward, sideways and up
 * (40% of the samples), the rest with bent arms; 2 mm tracker noise. */
static int record(kin_track_sample *s, int n, float arm_len, float width, tu_rng *g)
{
    for (int i = 0; i < n; i++) {
        memset(&s[i], 0, sizeof s[i]);
        s[i].t = 0.01 * i;
        s[i].valid = KIN_TRACK_ALL & ~(uint32_t)(KIN_TRACK_GLOVE_L | KIN_TRACK_GLOVE_R);
        s[i].head_rot = s[i].hand_rot[0] = s[i].hand_rot[1] = kin_quat_identity();
        s[i].head_pos = kin_v3(0, 1.3f, -0.08f);
        for (int k = 0; k < 2; k++) {
            float sx = k ? 1.0f : -1.0f;
            kin_vec3 sh = kin_v3(0.5f * width * sx + 0.002f * tu_range(g, -1, 1), 1.0f,
                                 0.002f * tu_range(g, -1, 1));
            kin_vec3 dir;
            int phase = (i / 50) % 5;
            if (phase == 0) dir = kin_v3(0, 0, -1);
            else if (phase == 1) dir = kin_v3(sx, 0, 0);
            else dir = kin_v3_norm(kin_v3(0.3f * sx, -0.5f, -1));
            float len = phase <= 1 ? arm_len : arm_len * tu_range(g, 0.4f, 0.85f);
            kin_vec3 noise = kin_v3(0.002f * tu_range(g, -1, 1), 0.002f * tu_range(g, -1, 1),
                                    0.002f * tu_range(g, -1, 1));
            s[i].shoulder[k] = sh;
            s[i].hand_pos[k] = kin_v3_add(kin_v3_add(sh, kin_v3_scale(dir, len)), noise);
        }
    }
    return n;
}

/* ------------------------------------------------------------ validity */

static void validity_estimate_rejects(void **state)
{
    (void)state;
    static kin_track_sample s[500];
    float scratch[500];
    tu_rng g = { 0x63616c31 };
    kin_arm_rig rig = model_rig();
    kin_user_calib c;
    char why[256];
    record(s, 500, 0.616f, 0.42f, &g);
    assert_int_equal(kin_user_calib_estimate(s, 19, &rig, scratch, &c, why, sizeof why), -1);
    assert_non_null(strstr(why, "left arm: 19 samples"));
    for (int i = 0; i < 500; i++) s[i].valid &= ~(uint32_t)KIN_TRACK_HAND_R;
    assert_int_equal(kin_user_calib_estimate(s, 500, &rig, scratch, &c, why, sizeof why), -1);
    assert_non_null(strstr(why, "right arm: 0 samples"));
    record(s, 500, 0.2f, 0.42f, &g);            /* never stretched */
    assert_int_equal(kin_user_calib_estimate(s, 500, &rig, scratch, &c, why, sizeof why), -1);
    assert_non_null(strstr(why, "were the arms stretched"));
}

static void expect_parse_error(const char *text, int line, const char *in_why)
{
    kin_user_calib c;
    int el = -1;
    char why[256] = "";
    if (kin_user_calib_parse(text, strlen(text), &c, &el, why, sizeof why) != -1)
        fail_msg("accepted: %s", text);
    if (el != line) fail_msg("line %d, expected %d (%s)", el, line, why);
    if (!strstr(why, in_why)) fail_msg("'%s' lacks '%s'", why, in_why);
}

static void validity_file_errors(void **state)
{
    (void)state;
    const char *ok = "arm_scale 1 1\nhand_scale 1 1\nshoulder_scale 1\narm_length 0 0\n"
                     "shoulder_width 0\n";
    char t[512];
    expect_parse_error("", 0, "header");
    expect_parse_error("egofuse-calib 2\n", 1, "first line");
    snprintf(t, sizeof t, "egofuse-calib 1\n%sfoo 1\n", ok);
    expect_parse_error(t, 7, "unknown key 'foo'");
    snprintf(t, sizeof t, "egofuse-calib 1\n%sarm_scale 1 1\n", ok);
    expect_parse_error(t, 7, "given twice");
    expect_parse_error("egofuse-calib 1\narm_scale 1\n", 2, "needs 2 numbers, got 1");
    expect_parse_error("egofuse-calib 1\narm_scale 1 nan\n", 2, "bad number 'nan'");
    expect_parse_error("egofuse-calib 1\narm_scale 1 2.5\n", 2, "outside [0.5, 2.0]");
    expect_parse_error("egofuse-calib 1\narm_length 1 -1\n", 2, "outside [0, 5]");
    expect_parse_error("egofuse-calib 1\nglove_left 1 2 3 4 5 1 7 8 9 10\n", 2,
                       "sensor 1: open and fist readings are equal");
    expect_parse_error("egofuse-calib 1\narm_scale 1 1\n", 0, "missing key 'hand_scale'");
}

/* -------------------------------------------------------------- results */

static void result_estimate_user_size(void **state)
{
    (void)state;
    static kin_track_sample s[1000];
    float scratch[1000];
    tu_rng g = { 0x63616c32 };
    kin_arm_rig rig = model_rig();
    record(s, 1000, 0.616f, 0.42f, &g);
    kin_user_calib c;
    char why[256];
    if (kin_user_calib_estimate(s, 1000, &rig, scratch, &c, why, sizeof why)) fail_msg("%s", why);
    /* 0.616 / 0.56 = 1.1; the 95th percentile of the stretched distance
     * sits within the 2 mm noise */
    NEAR(c.arm_scale[0], 1.1, 0.006);
    NEAR(c.arm_scale[1], 1.1, 0.006);
    NEAR(c.hand_scale[1], c.arm_scale[1], 0);
    NEAR(c.arm_length[0], 0.616, 0.003);
    NEAR(c.shoulder_width, 0.42, 0.003);
    NEAR(c.shoulder_scale, 0.42 / 0.38, 0.008);
}

static void result_file_round_trip(void **state)
{
    (void)state;
    kin_user_calib c = kin_user_calib_identity(), back;
    c.arm_scale[0] = 1.0987654f; c.arm_scale[1] = 0.9123457f;
    c.hand_scale[0] = 1.05f; c.hand_scale[1] = 1.0f / 3.0f + 0.5f;
    c.shoulder_scale = 1.1052631f;
    c.arm_length[0] = 0.6153f; c.arm_length[1] = 0.511f;
    c.shoulder_width = 0.42f;
    c.has_glove[0] = 1;
    for (int i = 0; i < 5; i++) { c.glove[0].raw_open[i] = 0.1f * i; c.glove[0].raw_fist[i] = 3.0f - i; }
    char buf[1024];
    int n = kin_user_calib_format(&c, buf, sizeof buf);
    assert_true(n > 0 && n < (int)sizeof buf);
    assert_int_equal(kin_user_calib_format(&c, NULL, 0), n);
    assert_int_equal(strncmp(buf, "egofuse-calib 1\narm_scale 1.098765", 34), 0);
    int line;
    char why[256];
    if (kin_user_calib_parse(buf, (size_t)n, &back, &line, why, sizeof why)) fail_msg("%s", why);
    assert_memory_equal(&back, &c, sizeof c);
}

/* The calibrated rig reaches a stretched-arm target of the bigger user;
 * the model's own size falls short by the length difference. */
static void result_calibration_lets_the_arm_reach(void **state)
{
    (void)state;
    kin_arm_rig rig = model_rig();
    kin_user_calib c = kin_user_calib_identity();
    c.arm_scale[1] = 1.1f;
    kin_vec3 sh = kin_v3(0.21f, 1.0f, 0.0f);
    kin_vec3 target = kin_v3_add(sh, kin_v3(0, 0, -0.59f));  /* < 0.97 * 0.616 */
    kin_arm_ik_job j;
    memset(&j, 0, sizeof j);
    j.shoulder = sh; j.wrist = target; j.hand_rot = kin_quat_identity();
    j.body_rot = kin_quat_identity(); j.side = KIN_SIDE_RIGHT;
    j.upper_len = rig.upper_len[1]; j.fore_len = rig.fore_len[1];
    assert_int_equal(kin_arm_ik_run(&j), 1);
    /* the model's soft limit: 0.5432 + 0.0168 (1 - exp(-(0.59 - 0.5432) / 0.0168)) */
    double hi = 0.97 * 0.56, m = 0.03 * 0.56;
    NEAR(j.reach_error, 0.59 - (hi + m * (1.0 - exp(-(0.59 - hi) / m))), 2e-5);
    assert_true(j.reach_error > 0.03f);
    j.upper_len *= c.arm_scale[1]; j.fore_len *= c.arm_scale[1];
    assert_int_equal(kin_arm_ik_run(&j), 1);
    NEAR(j.reach_error, 0.0, 1e-5);
}

int main(void)
{
    const struct CMUnitTest validity[] = {
        cmocka_unit_test(validity_estimate_rejects),
        cmocka_unit_test(validity_file_errors),
    };
    const struct CMUnitTest results[] = {
        cmocka_unit_test(result_estimate_user_size),
        cmocka_unit_test(result_file_round_trip),
        cmocka_unit_test(result_calibration_lets_the_arm_reach),
    };
    int f = cmocka_run_group_tests_name("kin_calib validity", validity, NULL, NULL);
    f += cmocka_run_group_tests_name("kin_calib results", results, NULL, NULL);
    return f ? 1 : 0;
}
