/* test_kin_anim.c - rest pose and glTF animation sampling (kin_anim.c).
 * Every expected value is worked by hand from the glTF 2.0 formulas. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

#define TOL 1e-5f

static kin_channel chan(int node, kin_path path, kin_interp in, int keys, int comps,
                        const float *times, const float *values)
{
    kin_channel c;
    memset(&c, 0, sizeof c);
    c.node = node; c.path = path; c.interp = in; c.key_count = keys;
    c.comps = comps; c.times = times; c.values = values;
    return c;
}

static kin_animation anim_of(const kin_channel *ch, int n)
{
    kin_animation a;
    memset(&a, 0, sizeof a);
    a.channel_count = n;
    a.channels = ch;
    a.duration = 0;
    for (int i = 0; i < n; i++)
        if (ch[i].times[ch[i].key_count - 1] > a.duration)
            a.duration = ch[i].times[ch[i].key_count - 1];
    return a;
}

/* Samples one channel on a fresh identity pose of 3 nodes. */
static kin_transform sample1(const kin_channel *ch, float t)
{
    kin_transform loc[3];
    for (int i = 0; i < 3; i++) loc[i] = kin_transform_identity();
    kin_animation a = anim_of(ch, 1);
    kin_anim_sample(&a, 3, t, loc);
    return loc[ch->node];
}

static void quat_near_rot_z(kin_quat q, double deg)
{
    double h = deg * 3.14159265358979323846 / 360.0;
    /* q and -q are the same rotation */
    double sgn = q.w < 0 ? -1 : 1;
    NEAR(sgn * q.x, 0, TOL); NEAR(sgn * q.y, 0, TOL);
    NEAR(sgn * q.z, sin(h), TOL); NEAR(sgn * q.w, cos(h), TOL);
}

/* ------------------------------------------------------------ validity */

static void validity_node_out_of_range_ignored(void **state)
{
    (void)state;
    static const float times[] = { 0, 1 };
    static const float vals[] = { 5, 5, 5, 6, 6, 6 };
    kin_channel ch[3] = {
        chan(3, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 2, 3, times, vals),
        chan(-1, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 2, 3, times, vals),
        chan(100, KIN_PATH_SCALE, KIN_INTERP_LINEAR, 2, 3, times, vals),
    };
    kin_transform loc[4]; /* loc[3] is a guard past node_count = 3 */
    for (int i = 0; i < 4; i++) loc[i] = kin_transform_identity();
    kin_animation a = anim_of(ch, 3);
    kin_anim_sample(&a, 3, 0.5f, loc);
    for (int i = 0; i < 4; i++) {
        NEAR3(loc[i].t, 0, 0, 0, 0);
        NEAR3(loc[i].s, 1, 1, 1, 0);
    }
}

static void validity_weights_ignored(void **state)
{
    (void)state;
    static const float times[] = { 0, 1 };
    static const float vals[] = { 1, 0, 0, 0, 1, 0 }; /* 3 morph targets */
    kin_channel ch = chan(1, KIN_PATH_WEIGHTS, KIN_INTERP_LINEAR, 2, 3, times, vals);
    kin_transform before[3], loc[3];
    for (int i = 0; i < 3; i++) {
        before[i] = kin_transform_identity();
        before[i].t = kin_v3((float)i, 2, 3);
    }
    memcpy(loc, before, sizeof loc);
    kin_animation a = anim_of(&ch, 1);
    kin_anim_sample(&a, 3, 0.5f, loc);
    assert_memory_equal(loc, before, sizeof loc);
}

static void validity_only_animated_paths_change(void **state)
{
    (void)state;
    static const float times[] = { 0, 2 };
    static const float vals[] = { 0, 0, 0, 4, 0, 0 };
    kin_channel ch = chan(2, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 2, 3, times, vals);
    kin_transform loc[3];
    for (int i = 0; i < 3; i++) loc[i] = kin_transform_identity();
    loc[2].r = kin_quat_axis_angle(kin_v3(1, 0, 0), 0.3f);
    loc[2].s = kin_v3(2, 2, 2);
    kin_quat r0 = loc[2].r;
    kin_animation a = anim_of(&ch, 1);
    kin_anim_sample(&a, 3, 1.0f, loc);
    NEAR3(loc[2].t, 2, 0, 0, TOL);
    NEAR(loc[2].r.x, r0.x, 0); NEAR(loc[2].r.w, r0.w, 0);
    NEAR3(loc[2].s, 2, 2, 2, 0);
    NEAR3(loc[1].t, 0, 0, 0, 0);
}

static void validity_pose_rest(void **state)
{
    (void)state;
    int16_t parents[2] = { KIN_NO_PARENT, 0 };
    kin_transform rest[2] = { kin_transform_identity(), kin_transform_identity() };
    rest[1].t = kin_v3(1, 2, 3);
    rest[1].s = kin_v3(0.5f, 1, 2);
    kin_model m;
    memset(&m, 0, sizeof m);
    m.node_count = 2; m.parents = parents; m.rest = rest;
    kin_transform loc[3];
    memset(loc, 0xab, sizeof loc);
    kin_transform guard = loc[2];
    kin_pose_rest(&m, loc);
    assert_memory_equal(loc, rest, sizeof rest);
    assert_memory_equal(&loc[2], &guard, sizeof guard);
}

/* -------------------------------------------------------------- result */

static void result_linear_translation(void **state)
{
    (void)state;
    static const float times[] = { 1, 3 };
    static const float vals[] = { 0, 2, -4, 10, 4, 4 };
    kin_channel ch = chan(1, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 2, 3, times, vals);
    NEAR3(sample1(&ch, 2.0f).t, 5, 3, 0, TOL);
    NEAR3(sample1(&ch, 1.5f).t, 2.5, 2.5, -2, TOL);
    NEAR3(sample1(&ch, 1.0f).t, 0, 2, -4, 0);
    NEAR3(sample1(&ch, 3.0f).t, 10, 4, 4, 0);
    /* scale uses the same lerp */
    ch.path = KIN_PATH_SCALE;
    NEAR3(sample1(&ch, 2.5f).s, 7.5, 3.5, 2, TOL);
}

static void result_linear_many_keys(void **state)
{
    (void)state;
    /* uneven key spacing: the right interval must be found */
    static const float times[] = { 0, 0.1f, 0.5f, 2, 2.25f };
    static const float vals[] = { 0, 0, 0, 1, 0, 0, 3, 0, 0, -3, 0, 0, 5, 0, 0 };
    kin_channel ch = chan(0, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 5, 3, times, vals);
    NEAR(sample1(&ch, 0.05f).t.x, 0.5, TOL);
    NEAR(sample1(&ch, 0.3f).t.x, 2, TOL);
    NEAR(sample1(&ch, 1.25f).t.x, 0, TOL);
    NEAR(sample1(&ch, 2.125f).t.x, 1, TOL);
    NEAR(sample1(&ch, 0.5f).t.x, 3, TOL); /* exactly on a key */
}

static void result_rotation_slerp(void **state)
{
    (void)state;
    static const float times[] = { 0, 1 };
    float s45 = sinf(PI_F / 4), c45 = cosf(PI_F / 4);
    float vals[] = { 0, 0, 0, 1, 0, 0, s45, c45 }; /* 0 and 90 deg about Z */
    kin_channel ch = chan(0, KIN_PATH_ROTATION, KIN_INTERP_LINEAR, 2, 4, times, vals);
    quat_near_rot_z(sample1(&ch, 0.5f).r, 45);
    quat_near_rot_z(sample1(&ch, 0.25f).r, 22.5);
    /* the second key stored as -q: still the short way */
    float neg[] = { 0, 0, 0, 1, 0, 0, -s45, -c45 };
    ch.values = neg;
    quat_near_rot_z(sample1(&ch, 0.5f).r, 45);
    /* unnormalised keys are renormalised */
    float big[] = { 0, 0, 0, 2, 0, 0, 2 * s45, 2 * c45 };
    ch.values = big;
    quat_near_rot_z(sample1(&ch, 0.5f).r, 45);
    quat_near_rot_z(sample1(&ch, 0.0f).r, 0);
}

static void result_step(void **state)
{
    (void)state;
    static const float times[] = { 0, 1, 2 };
    static const float vals[] = { 1, 1, 1, 2, 2, 2, 3, 3, 3 };
    kin_channel ch = chan(0, KIN_PATH_SCALE, KIN_INTERP_STEP, 3, 3, times, vals);
    NEAR3(sample1(&ch, 0.99f).s, 1, 1, 1, 0);
    NEAR3(sample1(&ch, 1.0f).s, 2, 2, 2, 0);
    NEAR3(sample1(&ch, 1.5f).s, 2, 2, 2, 0);
    NEAR3(sample1(&ch, 1.999f).s, 2, 2, 2, 0);
    NEAR3(sample1(&ch, 2.0f).s, 3, 3, 3, 0);
    NEAR3(sample1(&ch, 7.0f).s, 3, 3, 3, 0);
}

static void result_cubicspline(void **state)
{
    (void)state;
    /* keys at t = 1 and 3 (td = 2): values 0 -> 1 in x, out-tangent of key 0
     * b0 = 1, in-tangent of key 1 a1 = -1. At u = 0.5:
     *   h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125
     *   p = 0.5*0 + 2*0.125*1 + 0.5*1 + 2*(-0.125)*(-1) = 1.0
     * At u = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625,
     *   h11 = -0.046875: p = 0.28125 + 0.15625 + 0.09375 = 0.53125.
     * y: v = 2 -> 2, tangents 0: stays 2. z: v 0 -> 0, b0 = 3, a1 = 0:
     *   u = .5: 2*0.125*3 = 0.75. */
    static const float times[] = { 1, 3 };
    static const float vals[] = {
        /* key 0: in-tangent, value, out-tangent */
        9, 9, 9,   0, 2, 0,   1, 0, 3,
        /* key 1 */
        -1, 0, 0,  1, 2, 0,   9, 9, 9,
    };
    kin_channel ch = chan(1, KIN_PATH_TRANSLATION, KIN_INTERP_CUBICSPLINE, 2, 3, times, vals);
    NEAR3(sample1(&ch, 2.0f).t, 1.0, 2, 0.75, TOL);
    NEAR(sample1(&ch, 1.5f).t.x, 0.53125, TOL);
    /* the ends are the values, not the tangents (9 would show) */
    NEAR3(sample1(&ch, 1.0f).t, 0, 2, 0, 0);
    NEAR3(sample1(&ch, 3.0f).t, 1, 2, 0, 0);
    NEAR3(sample1(&ch, 0.0f).t, 0, 2, 0, 0);
    NEAR3(sample1(&ch, 5.0f).t, 1, 2, 0, 0);
}

static void result_cubicspline_rotation(void **state)
{
    (void)state;
    /* zero tangents: at u = 0.5 the Hermite value is the plain average of
     * the keys, (0,0,0,1) and (0,0,1,0) -> (0,0,.5,.5), renormalised to a
     * 90 degree rotation about Z. */
    static const float times[] = { 0, 1 };
    static const float vals[] = {
        0, 0, 0, 0,  0, 0, 0, 1,  0, 0, 0, 0,
        0, 0, 0, 0,  0, 0, 1, 0,  0, 0, 0, 0,
    };
    kin_channel ch = chan(0, KIN_PATH_ROTATION, KIN_INTERP_CUBICSPLINE, 2, 4, times, vals);
    quat_near_rot_z(sample1(&ch, 0.5f).r, 90);
}

static void result_clamp(void **state)
{
    (void)state;
    static const float times[] = { 0.5f, 1.5f };
    static const float vals[] = { 1, 2, 3, 4, 5, 6 };
    kin_channel ch = chan(0, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 2, 3, times, vals);
    NEAR3(sample1(&ch, -10.0f).t, 1, 2, 3, 0);
    NEAR3(sample1(&ch, 0.0f).t, 1, 2, 3, 0);
    NEAR3(sample1(&ch, 1.6f).t, 4, 5, 6, 0);
    NEAR3(sample1(&ch, 1e9f).t, 4, 5, 6, 0);
    NEAR3(sample1(&ch, NAN).t, 1, 2, 3, 0);
}

static void result_one_key(void **state)
{
    (void)state;
    static const float times[] = { 2 };
    static const float vals[] = { 7, 8, 9 };
    kin_channel ch = chan(2, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 1, 3, times, vals);
    NEAR3(sample1(&ch, 0.0f).t, 7, 8, 9, 0);
    NEAR3(sample1(&ch, 2.0f).t, 7, 8, 9, 0);
    NEAR3(sample1(&ch, 3.0f).t, 7, 8, 9, 0);
    static const float cvals[] = { 1, 1, 1, 7, 8, 9, 1, 1, 1 };
    kin_channel cc = chan(2, KIN_PATH_TRANSLATION, KIN_INTERP_CUBICSPLINE, 1, 3, times, cvals);
    NEAR3(sample1(&cc, 5.0f).t, 7, 8, 9, 0);
}

static void result_several_channels(void **state)
{
    (void)state;
    /* one animation moving two nodes on different paths and key sets */
    static const float t1[] = { 0, 1 }, t2[] = { 0, 2, 4 };
    static const float v1[] = { 0, 0, 0, 2, 4, 6 };
    static const float v2[] = { 1, 1, 1, 3, 3, 3, 1, 1, 1 };
    kin_channel ch[2] = {
        chan(0, KIN_PATH_TRANSLATION, KIN_INTERP_LINEAR, 2, 3, t1, v1),
        chan(2, KIN_PATH_SCALE, KIN_INTERP_LINEAR, 3, 3, t2, v2),
    };
    kin_animation a = anim_of(ch, 2);
    NEAR(a.duration, 4, 0);
    kin_transform loc[3];
    for (int i = 0; i < 3; i++) loc[i] = kin_transform_identity();
    kin_anim_sample(&a, 3, 3.0f, loc);
    NEAR3(loc[0].t, 2, 4, 6, 0);  /* clamped after its last key */
    NEAR3(loc[2].s, 2, 2, 2, TOL);
    NEAR3(loc[1].s, 1, 1, 1, 0);
}

TU_MAIN_NAMED("kin_anim", NULL, NULL,
              cmocka_unit_test(validity_node_out_of_range_ignored),
              cmocka_unit_test(validity_weights_ignored),
              cmocka_unit_test(validity_only_animated_paths_change),
              cmocka_unit_test(validity_pose_rest),
              cmocka_unit_test(result_linear_translation),
              cmocka_unit_test(result_linear_many_keys),
              cmocka_unit_test(result_rotation_slerp),
              cmocka_unit_test(result_step),
              cmocka_unit_test(result_cubicspline),
              cmocka_unit_test(result_cubicspline_rotation),
              cmocka_unit_test(result_clamp),
              cmocka_unit_test(result_one_key),
              cmocka_unit_test(result_several_channels))
