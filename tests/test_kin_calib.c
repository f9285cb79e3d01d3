/* test_kin_calib.c - per-user calibration (kin_calib.c): bone scales
 * estimated from a synthetic recording of a user 1.1x the model's size,
 * the hand scale from the fingertip gesture (exact on exact samples,
 * robust to the approach, within the noise on noisy ones, the fallback to
 * the arm scale when the gesture is missing), the model's fingertip
 * reference on a hand-built model, the file format (exact round trip, old
 * files without hand_length, strict errors with line numbers), and the
 * effect: the calibrated rig reaches targets the model's own
 * arm cannot. */
#include "support/testutil.h"
#include "support/tu_kin.h"
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
            const float jx = tu_range(g, -1, 1);   /* drawn in order (tu_kin.h) */
            const float jz = tu_range(g, -1, 1);
            kin_vec3 sh = kin_v3(0.5f * width * sx + 0.002f * jx, 1.0f, 0.002f * jz);
            kin_vec3 dir;
            int phase = (i / 50) % 5;
            if (phase == 0) dir = kin_v3(0, 0, -1);
            else if (phase == 1) dir = kin_v3(sx, 0, 0);
            else dir = kin_v3_norm(kin_v3(0.3f * sx, -0.5f, -1));
            float len = phase <= 1 ? arm_len : arm_len * tu_range(g, 0.4f, 0.85f);
            kin_vec3 noise = kin_v3_scale(tu_v3(g, -1, 1), 0.002f);
            s[i].shoulder[k] = sh;
            s[i].hand_pos[k] = kin_v3_add(kin_v3_add(sh, kin_v3_scale(dir, len)), noise);
        }
    }
    return n;
}

/* The model's middle fingertips in the hand frames (left mirrored). */
static const kin_vec3 TIP_L = { 0.008f, -0.004f, -0.195f };
static const kin_vec3 TIP_R = { -0.008f, -0.004f, -0.195f };

/* Appends n samples of the fingertip gesture of a user whose hands are
 * `scale` times the model's: the middle fingertips pressed together at
 * C, the left hand's fingers pointing to +X, the right hand's to -X,
 * the pair turning up to 25 deg about Y and tilting 15 deg about Z; the
 * fingertips `gap` metres apart along the fingers (0: touching); wrist
 * noise `noise` (uniform per axis, metres). */
static int gesture(kin_track_sample *s, int n, float scale, float gap, float noise, tu_rng *g)
{
    for (int i = 0; i < n; i++) {
        memset(&s[i], 0, sizeof s[i]);
        s[i].t = 0.01 * i;
        s[i].valid = KIN_TRACK_ALL & ~(uint32_t)(KIN_TRACK_GLOVE_L | KIN_TRACK_GLOVE_R);
        s[i].head_rot = kin_quat_identity();
        s[i].head_pos = kin_v3(0, 1.3f, -0.08f);
        s[i].shoulder[0] = kin_v3(-0.21f, 1.0f, 0.0f);
        s[i].shoulder[1] = kin_v3(0.21f, 1.0f, 0.0f);
        tu_fingertip_gesture(&s[i], i, kin_v3_scale(TIP_L, scale), kin_v3_scale(TIP_R, scale), gap);
        for (int k = 0; k < 2; k++)
            s[i].hand_pos[k] = kin_v3_add(s[i].hand_pos[k],
                                          kin_v3_scale(tu_v3(g, -1, 1), noise));
    }
    return n;
}

/* What the estimation tests share: a recording of up to 1000 samples, its
 * scratch, the model's rig and fingertips, the result and its reason. */
typedef struct calib_run {
    kin_track_sample s[1000];
    float scratch[1000];
    kin_arm_rig rig;
    kin_vec3 tips[2];
    kin_user_calib c;
    char why[256];
} calib_run;

/* The run of an estimation test (static: too big for the stack): the
 * model's rig and fingertips, and the first n samples recorded (record())
 * of a user 1.1x the model's size (arms 0.616 m, shoulders 0.42 m). */
static calib_run *calib_start(int n, tu_rng *g)
{
    static calib_run r;
    memset(&r, 0, sizeof r);   /* nothing of the last test's run survives */
    r.rig = model_rig();
    r.tips[0] = TIP_L;
    r.tips[1] = TIP_R;
    record(r.s, n, 0.616f, 0.42f, g);
    return &r;
}

/* kin_user_calib_estimate of r's first n samples into r->c, r->why. */
static int estimate(calib_run *r, int n)
{
    return kin_user_calib_estimate(r->s, n, &r->rig, r->scratch, &r->c, r->why, sizeof r->why);
}

/* kin_user_calib_estimate_tips of r's first n samples with the fingertip
 * reference tips (NULL: none) into r->c, r->why. */
static int estimate_tips(calib_run *r, int n, const kin_vec3 *tips)
{
    return kin_user_calib_estimate_tips(r->s, n, &r->rig, tips, r->scratch, &r->c, r->why,
                                        sizeof r->why);
}

/* ------------------------------------------------------------ validity */

static void validity_estimate_rejects(void **state)
{
    (void)state;
    tu_rng g = { 0x63616c31 };
    calib_run *r = calib_start(500, &g);
    assert_int_equal(estimate(r, 19), -1);
    assert_non_null(strstr(r->why, "left arm: 19 samples"));
    for (int i = 0; i < 500; i++) r->s[i].valid &= ~(uint32_t)KIN_TRACK_HAND_R;
    assert_int_equal(estimate(r, 500), -1);
    assert_non_null(strstr(r->why, "right arm: 0 samples"));
    record(r->s, 500, 0.2f, 0.42f, &g);            /* never stretched */
    assert_int_equal(estimate(r, 500), -1);
    assert_non_null(strstr(r->why, "were the arms stretched"));
}

/* Without the gesture (or without a fingertip reference) the hand scale
 * falls back to the arm scale, with the reason. */
static void validity_gesture_missing_falls_back(void **state)
{
    (void)state;
    tu_rng g = { 0x63616c33 };
    calib_run *r = calib_start(500, &g);
    assert_int_equal(estimate_tips(r, 500, r->tips), 1);
    assert_non_null(strstr(r->why, "fingertip gesture: 0 samples"));
    assert_non_null(strstr(r->why, "hand scale = arm scale"));
    NEAR(r->c.hand_scale[0], r->c.arm_scale[0], 0);
    NEAR(r->c.hand_scale[1], r->c.arm_scale[1], 0);
    NEAR(r->c.hand_length[0], 0, 0);
    assert_int_equal(estimate_tips(r, 500, NULL), 1);
    assert_non_null(strstr(r->why, "no fingertip reference"));
    /* 19 gesture samples are too few; the hands 4 cm apart are no touch */
    gesture(r->s + 500, 19, 1.05f, 0.0f, 0.0f, &g);
    assert_int_equal(estimate_tips(r, 519, r->tips), 1);
    assert_non_null(strstr(r->why, "19 samples"));
    gesture(r->s + 500, 200, 1.05f, 0.04f, 0.0f, &g);
    for (int i = 500; i < 700; i++) r->s[i].hand_pos[1].y += 0.03f;   /* 3 cm off the line */
    assert_int_equal(estimate_tips(r, 700, r->tips), 1);
    NEAR(r->c.hand_scale[1], r->c.arm_scale[1], 0);
    /* a failing arm estimate still fails */
    assert_int_equal(estimate_tips(r, 19, r->tips), -1);
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
    /* above 1e30 as a float (1.0000001e30 rounds to the float after 1e30f) */
    expect_parse_error("egofuse-calib 1\nglove_left 1 2 3 1.0000001e30 5 6 7 8 9 10\n", 2,
                       "value 4: bad number");
    expect_parse_error("egofuse-calib 1\narm_scale 1 1\n", 0, "missing key 'hand_scale'");
}

/* -------------------------------------------------------------- results */

/* Exact gesture samples of hands 1.05x the model's: the scale comes back
 * to float rounding, whatever the arms say (1.1x); 60 samples of the
 * approach (the fingertips 1-5 cm apart: s up to 1.05 + 0.05 / 0.39) do
 * not move it. */
static void result_hand_scale_from_gesture(void **state)
{
    (void)state;
    tu_rng g = { 0x63616c34 };
    calib_run *r = calib_start(500, &g);
    gesture(r->s + 500, 240, 1.05f, 0.0f, 0.0f, &g);
    for (int i = 0; i < 60; i++)
        gesture(r->s + 740 + i, 1, 1.05f, 0.01f + 0.04f * (float)i / 59.0f, 0.0f, &g);
    int rc = estimate_tips(r, 800, r->tips);
    if (rc != 0) fail_msg("%d: %s", rc, r->why);
    NEAR(r->c.hand_scale[0], 1.05, 2e-6);
    NEAR(r->c.hand_scale[1], 1.05, 2e-6);
    NEAR(r->c.arm_scale[1], 1.1, 0.006);
    NEAR(r->c.hand_length[0], 1.05 * sqrt(0.008 * 0.008 + 0.004 * 0.004 + 0.195 * 0.195), 1e-6);
    NEAR(r->c.hand_length[1], r->c.hand_length[0], 1e-7);
    /* hands 0.92x, 3 mm wrist noise per axis: each sample's s is off by
     * about 3 mm * 1.4 / 0.39 m; the shortest half of 240 within 0.005 */
    gesture(r->s + 500, 240, 0.92f, 0.0f, 0.003f, &g);
    for (int i = 0; i < 60; i++)
        gesture(r->s + 740 + i, 1, 0.92f, 0.01f + 0.04f * (float)i / 59.0f, 0.003f, &g);
    rc = estimate_tips(r, 800, r->tips);
    if (rc != 0) fail_msg("%d: %s", rc, r->why);
    NEAR(r->c.hand_scale[0], 0.92, 0.005);
}

/* The fingertip reference of a hand-built model: hand joint at
 * (0.1, 1, -0.3) turned 90 deg about Y, middle_3 at (0.01, 0, -0.15) in
 * it; vertices bound to middle_3 at 0.005 and 0.02 beyond it along its
 * bone (-Z) and one 0.05 beyond with weight 0.4 (not bound): the tip is
 * (0.01, 0, -0.17) in the hand frame, on both sides. */
static void result_hand_tips_of_a_model(void **state)
{
    (void)state;
    int16_t parents[2] = { KIN_NO_PARENT, 0 };
    kin_transform rest[2];
    rest[0].t = kin_v3(0.1f, 1.0f, -0.3f);
    rest[0].r = kin_quat_axis_angle(kin_v3(0, 1, 0), 1.5707963f);
    rest[0].s = kin_v3(1, 1, 1);
    rest[1].t = kin_v3(0.01f, 0.0f, -0.15f);
    rest[1].r = kin_quat_axis_angle(kin_v3(1, 0, 0), 0.3f);
    rest[1].s = kin_v3(1, 1, 1);
    kin_mat4 w0 = kin_mat4_from_transform(&rest[0]), l1 = kin_mat4_from_transform(&rest[1]);
    kin_mat4 w1 = kin_mat4_mul(&w0, &l1), ibm[2];
    assert_true(kin_mat4_inverse(&w0, &ibm[0]));
    assert_true(kin_mat4_inverse(&w1, &ibm[1]));
    /* bind-space positions: world(1) * local offsets along -Z */
    float pos[9];
    const float along[3] = { 0.005f, 0.02f, 0.05f };
    for (int v = 0; v < 3; v++) {
        kin_vec3 p = kin_mat4_mul_point(&w1, kin_v3(0.001f, 0.002f, -along[v]));
        pos[v * 3] = p.x; pos[v * 3 + 1] = p.y; pos[v * 3 + 2] = p.z;
    }
    uint16_t joints[12] = { 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0 };
    float weights[12] = { 1, 0, 0, 0, 0.7f, 0.3f, 0, 0, 0.4f, 0.6f, 0, 0 };
    uint32_t idx[3] = { 0, 1, 2 };
    const int jn[2] = { 0, 1 };
    kin_skin sk = { 2, jn, ibm };
    kin_mesh me;
    memset(&me, 0, sizeof me);
    me.vertex_count = 3; me.positions = pos; me.joints = joints; me.weights = weights;
    me.index_count = 3; me.indices = idx; me.node = -1; me.skin = 0;
    kin_model m;
    memset(&m, 0, sizeof m);
    m.node_count = 2; m.parents = parents; m.rest = rest;
    m.mesh_count = 1; m.meshes = &me; m.skin_count = 1; m.skins = &sk;
    kin_arm_rig rig = model_rig();
    for (int s = 0; s < 2; s++) {
        rig.joint[s][KIN_RIG_HAND] = 0;
        rig.joint[s][KIN_RIG_FINGER0 + 8] = 1;   /* middle_3 */
    }
    kin_vec3 tip[2];
    char why[128];
    if (kin_user_calib_hand_tips(&rig, &m, tip, why, sizeof why)) fail_msg("%s", why);
    /* middle_3's -Z in the hand frame: Rx(0.3) (0, 0, -1) */
    double ez = 0.02 * cos(0.3), ey = 0.02 * sin(0.3);
    NEAR3(tip[0], 0.01, ey, -0.15 - ez, 1e-6);
    NEAR3(tip[1], 0.01, ey, -0.15 - ez, 1e-6);
    m.mesh_count = 0;
    assert_int_equal(kin_user_calib_hand_tips(&rig, &m, tip, why, sizeof why), -1);
    assert_non_null(strstr(why, "no skinned mesh"));
}

static void result_estimate_user_size(void **state)
{
    (void)state;
    tu_rng g = { 0x63616c32 };
    calib_run *r = calib_start(1000, &g);
    if (estimate(r, 1000)) fail_msg("%s", r->why);
    /* 0.616 / 0.56 = 1.1; the 95th percentile of the stretched distance
     * sits within the 2 mm noise */
    const kin_user_calib *c = &r->c;
    NEAR(c->arm_scale[0], 1.1, 0.006);
    NEAR(c->arm_scale[1], 1.1, 0.006);
    NEAR(c->hand_scale[1], c->arm_scale[1], 0);
    NEAR(c->arm_length[0], 0.616, 0.003);
    NEAR(c->shoulder_width, 0.42, 0.003);
    NEAR(c->shoulder_scale, 0.42 / 0.38, 0.008);
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
    c.hand_length[0] = 0.203125f; c.hand_length[1] = 0.1875f;
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
    assert_non_null(strstr(buf, "\nhand_length 0.203125 0.1875\n"));
    /* a file of the arms-only estimate has no hand_length line, and an old
     * file without it reads back with hand_length 0 */
    c.hand_length[0] = c.hand_length[1] = 0.0f;
    n = kin_user_calib_format(&c, buf, sizeof buf);
    assert_null(strstr(buf, "hand_length"));
    const char *old = "egofuse-calib 1\narm_scale 1.1 1.1\nhand_scale 1.1 1.1\n"
                      "shoulder_scale 1\narm_length 0.6 0.6\nshoulder_width 0.4\n";
    if (kin_user_calib_parse(old, strlen(old), &back, &line, why, sizeof why)) fail_msg("%s", why);
    NEAR(back.hand_scale[1], 1.1f, 0);
    NEAR(back.hand_length[0], 0, 0);
    NEAR(back.hand_length[1], 0, 0);
    /* A reading next to the 1e30 limit (fuzz_kin_calib's find): 1e30 as a
     * double, 1e30f = 1.00000002e30 as the float kept; the file written
     * from it reads back to the same values. */
    const char *edge = "egofuse-calib 1\narm_scale 1.1 1.1\nhand_scale 1.1 1.1\nshoulder_scale 1\n"
                       "arm_length 0 0\nshoulder_width 0.42\n"
                       "glove_left 0.1 0.1 0.1 1000000000000000000084467440731 0.1 0.9 0.9 0.9 0.9 "
                       "0.9\n";
    if (kin_user_calib_parse(edge, strlen(edge), &c, &line, why, sizeof why)) fail_msg("%s", why);
    assert_true(c.glove[0].raw_open[3] == 1e30f);
    n = kin_user_calib_format(&c, buf, sizeof buf);
    assert_true(n > 0 && n < (int)sizeof buf);
    if (kin_user_calib_parse(buf, (size_t)n, &back, &line, why, sizeof why)) fail_msg("%s: %s", why, buf);
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
    int f = 0;
    TU_GROUP(f, "kin_calib validity",
             cmocka_unit_test(validity_estimate_rejects),
             cmocka_unit_test(validity_file_errors),
             cmocka_unit_test(validity_gesture_missing_falls_back));
    TU_GROUP(f, "kin_calib results",
             cmocka_unit_test(result_estimate_user_size),
             cmocka_unit_test(result_hand_scale_from_gesture),
             cmocka_unit_test(result_hand_tips_of_a_model),
             cmocka_unit_test(result_file_round_trip),
             cmocka_unit_test(result_calibration_lets_the_arm_reach));
    return f ? 1 : 0;
}
