/* test_kin_ik.c - two-bone arm IK (kin_ik.c): validity, hand-worked
 * elbow positions, the swivel rule, reach limits, forearm twist, mirror
 * symmetry, and stability sweeps (targets through and beyond reach, the
 * straight-arm singularity, the target at the shoulder, hand rotations):
 * no NaN and no jump above the bounds stated in docs/tracking.md. Also the
 * arm rig on a small model built here (names, errors, pose). */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../src/kin/kin.h"

#define TOL 1e-5f

#define NEARV(v, X, Y, Z, tol) \
    do { NEAR((v).x, X, tol); NEAR((v).y, Y, tol); NEAR((v).z, Z, tol); } while (0)

/* Stated bounds (docs/tracking.md): per step of the target, the elbow
 * moves at most ELBOW_GAIN times as far, plus 0.1 mm. */
#define ELBOW_GAIN 12.0f
/* The same for targets passing through the shoulder (within d_min / 2 the
 * whole arm turns around). */
#define SHOULDER_GAIN 24.0f

static kin_arm_ik_job job_of(kin_vec3 s, kin_vec3 w, kin_quat hand, kin_side side)
{
    kin_arm_ik_job j;
    memset(&j, 0, sizeof j);
    j.shoulder = s;
    j.wrist = w;
    j.hand_rot = hand;
    j.body_rot = kin_quat_identity();
    j.side = side;
    j.upper_len = 0.3f;
    j.fore_len = 0.26f;
    return j;
}

static int finite_job(const kin_arm_ik_job *j)
{
    const float *f = (const float *)&j->elbow;
    /* elbow .. reach_error are consecutive floats */
    size_t n = (size_t)((const char *)(&j->reach_error + 1) - (const char *)&j->elbow) / sizeof(float);
    for (size_t i = 0; i < n; i++)
        if (!isfinite(f[i])) return 0;
    return 1;
}

static float dist(kin_vec3 a, kin_vec3 b) { return kin_v3_len(kin_v3_sub(a, b)); }

static void check_solution(const kin_arm_ik_job *j)
{
    assert_true(finite_job(j));
    NEAR(dist(j->elbow, j->shoulder), j->upper_len, 1e-5);
    NEAR(dist(j->wrist_out, j->elbow), j->fore_len, 1e-5);
    /* the bone frames: -Z along the bones, +X the hinge (perpendicular) */
    kin_vec3 e = kin_v3_add(j->shoulder, kin_quat_rotate(j->upper_rot, kin_v3(0, 0, -j->upper_len)));
    kin_vec3 w = kin_v3_add(j->elbow, kin_quat_rotate(j->fore_rot, kin_v3(0, 0, -j->fore_len)));
    NEARV(e, j->elbow.x, j->elbow.y, j->elbow.z, 1e-5);
    NEARV(w, j->wrist_out.x, j->wrist_out.y, j->wrist_out.z, 1e-5);
    kin_vec3 hinge = kin_quat_rotate(j->upper_rot, kin_v3(1, 0, 0));
    kin_vec3 df = kin_v3_norm(kin_v3_sub(j->wrist_out, j->elbow));
    NEAR(kin_v3_dot(hinge, df), 0.0, 1e-5);
}

/* ------------------------------------------------------------ validity */

static void validity_rejects_bad_jobs(void **state)
{
    (void)state;
    kin_arm_ik_job ok = job_of(kin_v3(0, 0, 0), kin_v3(0, 0, -0.4f), kin_quat_identity(),
                               KIN_SIDE_RIGHT);
    char why[128];
    assert_int_equal(kin_arm_ik_validate(&ok, why, sizeof why), 1);
    kin_arm_ik_job b;
    b = ok; b.wrist.y = NAN;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b.elbow = kin_v3(7, 7, 7);
    assert_int_equal(kin_arm_ik_run(&b), 0);
    NEARV(b.elbow, 7, 7, 7, 0);                 /* outputs untouched */
    b = ok; b.shoulder.x = INFINITY;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.hand_rot = (kin_quat){ 0, 0, 0, 0.5f };
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    assert_non_null(strstr(why, "hand_rot"));
    b = ok; b.body_rot = (kin_quat){ 1, 1, 0, 0 };
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.upper_len = 0;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.fore_len = -1;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.soft = 1.2f;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.elbow_max_deg = 200;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.elbow_max_deg = 5;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    assert_non_null(strstr(why, "no reach left"));
    b = ok; b.twist_share = 1.5f;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.hand_gain = NAN;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.hand_gain = 3;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    b = ok; b.side = (kin_side)3;
    assert_int_equal(kin_arm_ik_validate(&b, why, sizeof why), 0);
    assert_int_equal(kin_arm_ik_validate(NULL, why, sizeof why), 0);
}

/* -------------------------------------------------------------- results */

/* Target straight ahead with the hand along the line: the hand term
 * vanishes and the body field at u = -Z is b = perp(down, u)(1 - Q.u) =
 * 1.707 down, so the elbow points straight down. L1 = L2 = 0.3,
 * d = 0.3 sqrt 2: 45 degrees at the shoulder, 90 of flexion, hinge +X. */
static void result_hand_worked_elbow(void **state)
{
    (void)state;
    kin_arm_ik_job j = job_of(kin_v3(0.2f, 1.0f, 0.0f), kin_v3(0.2f, 1.0f, -0.3f * sqrtf(2.0f)),
                              kin_quat_identity(), KIN_SIDE_RIGHT);
    j.upper_len = j.fore_len = 0.3f;
    assert_int_equal(kin_arm_ik_run(&j), 1);
    check_solution(&j);
    float h = 0.3f * sqrtf(0.5f);
    NEARV(j.elbow, 0.2f, 1.0f - h, -h, TOL);
    NEARV(j.wrist_out, j.wrist.x, j.wrist.y, j.wrist.z, TOL);
    NEAR(j.flexion, PI_F / 2, TOL);
    NEAR(j.swivel, 0.0, TOL);
    NEAR(j.reach_error, 0.0, TOL);
    kin_vec3 hinge = kin_quat_rotate(j.upper_rot, kin_v3(1, 0, 0));
    NEARV(hinge, 1.0f, 0.0f, 0.0f, TOL);
    /* the same with the body turned 90 degrees left: everything turns */
    kin_quat turn = kin_quat_axis_angle(kin_v3(0, 1, 0), PI_F / 2);
    kin_arm_ik_job k = j;
    k.body_rot = turn;
    k.shoulder = kin_quat_rotate(turn, j.shoulder);
    k.wrist = kin_quat_rotate(turn, j.wrist);
    k.hand_rot = turn;
    assert_int_equal(kin_arm_ik_run(&k), 1);
    kin_vec3 e = kin_quat_rotate(turn, j.elbow);
    NEARV(k.elbow, e.x, e.y, e.z, TOL);
}

/* The hand pointing to the left (-X), target ahead (u = -Z): h = +X,
 * h.(u x b) = (1,0,0).(-1,0,0) = -1, so the elbow turns by -1 rad about
 * -Z: p = (sin 1, -cos 1, 0), out to the right. */
static void result_swivel_follows_hand(void **state)
{
    (void)state;
    kin_quat point_left = kin_quat_axis_angle(kin_v3(0, 1, 0), PI_F / 2); /* -Z -> -X */
    kin_arm_ik_job j = job_of(kin_v3(0, 0, 0), kin_v3(0, 0, -0.4f), point_left, KIN_SIDE_RIGHT);
    assert_int_equal(kin_arm_ik_run(&j), 1);
    check_solution(&j);
    kin_vec3 p = kin_v3(sinf(1.0f), -cosf(1.0f), 0.0f);
    float d = 0.4f, l1 = 0.3f, l2 = 0.26f;
    float ca = (l1 * l1 + d * d - l2 * l2) / (2 * l1 * d), sa = sqrtf(1 - ca * ca);
    NEARV(j.elbow, l1 * sa * p.x, l1 * sa * p.y, -l1 * ca, TOL);
    NEAR(j.swivel, -1.0, TOL);
    j.hand_gain = 0.5f;
    assert_int_equal(kin_arm_ik_run(&j), 1);
    NEAR(j.swivel, -0.5, TOL);

    /* turning towards the hand never bends the wrist more than the body
     * direction alone would (gain <= 1 never overshoots) */
    tu_rng g = { 0x737769 };
    for (int it = 0; it < 500; it++) {
        kin_quat hr = kin_quat_normalize(tu_quat(&g, -1, 1));
        kin_vec3 w = tu_v3b(&g, -0.4f, 0.4f, -0.4f, 0.4f, -0.4f, -0.1f);
        kin_arm_ik_job k = job_of(kin_v3(0, 0, 0), w, hr, KIN_SIDE_RIGHT), k0;
        k0 = k;
        k0.hand_gain = 1e-9f;
        assert_int_equal(kin_arm_ik_run(&k), 1);
        assert_int_equal(kin_arm_ik_run(&k0), 1);
        kin_vec3 finger = kin_quat_rotate(hr, kin_v3(0, 0, -1));
        float with = kin_v3_dot(kin_v3_norm(kin_v3_sub(k.wrist_out, k.elbow)), finger);
        float without = kin_v3_dot(kin_v3_norm(kin_v3_sub(k0.wrist_out, k0.elbow)), finger);
        if (with < without - 1e-6f)
            fail_msg("iteration %d: forearm.finger %.6f with the hand term, %.6f without", it,
                     (double)with, (double)without);
    }
}

static void result_reach_limits(void **state)
{
    (void)state;
    const float l1 = 0.3f, l2 = 0.26f, dmax = l1 + l2, m = 0.03f * dmax, hi = 0.97f * dmax;
    /* out of reach: pulled in along the line by the soft formula */
    kin_arm_ik_job j = job_of(kin_v3(0, 0, 0), kin_v3(0, 0, -1.2f), kin_quat_identity(),
                              KIN_SIDE_RIGHT);
    assert_int_equal(kin_arm_ik_run(&j), 1);
    check_solution(&j);
    float want = hi + m * (1.0f - expf(-(1.2f - hi) / m));
    NEARV(j.wrist_out, 0, 0, -want, TOL);
    NEAR(j.reach_error, 1.2f - want, TOL);
    assert_true(j.flexion >= 0.0f); /* the straight arm is approached smoothly */
    /* within the soft zone the target is reached exactly */
    j.wrist = kin_v3(0, -0.5f, 0);
    assert_int_equal(kin_arm_ik_run(&j), 1);
    NEAR(j.reach_error, 0.0, TOL);
    /* too close: pushed out to beyond the minimum reach */
    float dmin = sqrtf(l1 * l1 + l2 * l2 + 2 * l1 * l2 * cosf(150.0f * PI_F / 180.0f));
    j.wrist = kin_v3(0.0f, 0.0f, -0.1f);
    assert_int_equal(kin_arm_ik_run(&j), 1);
    check_solution(&j);
    float d = kin_v3_len(j.wrist_out);
    float lo = dmin + m;
    NEAR(d, lo - m * (1.0f - expf(-(lo - 0.1f) / m)), TOL);
    assert_true(j.flexion < 150.0f * PI_F / 180.0f);
    /* exactly at the shoulder: the arm folds forward-down, defined */
    j.wrist = j.shoulder;
    assert_int_equal(kin_arm_ik_run(&j), 1);
    check_solution(&j);
    assert_true(j.wrist_out.z < 0 && j.wrist_out.y < 0);
}

static void result_twist_share_and_limit(void **state)
{
    (void)state;
    /* straight ahead, hand rolled by r about its finger axis (the forearm
     * axis when the hand is in line): the forearm takes r / 2 */
    float rolls[] = { -120, -60, 0, 30, 90, 150, 175 };
    for (size_t i = 0; i < sizeof rolls / sizeof rolls[0]; i++) {
        float r = rolls[i] * PI_F / 180.0f;
        kin_arm_ik_job base = job_of(kin_v3(0, 0, 0), kin_v3(0, 0, -0.45f), kin_quat_identity(),
                                     KIN_SIDE_RIGHT);
        base.twist_share = 1e-9f;   /* the untwisted forearm frame F0 */
        assert_int_equal(kin_arm_ik_run(&base), 1);
        /* the hand: F0 rolled by r about the forearm axis */
        kin_vec3 zf = kin_v3_norm(kin_v3_sub(base.elbow, base.wrist_out));
        kin_quat hr = kin_quat_mul(kin_quat_axis_angle(zf, r), base.fore_rot);
        kin_arm_ik_job j = base;
        j.hand_rot = hr;
        j.twist_share = 0.0f;       /* default 0.5 */
        assert_int_equal(kin_arm_ik_run(&j), 1);
        check_solution(&j);
        NEARV(j.elbow, base.elbow.x, base.elbow.y, base.elbow.z, 1e-4);
        kin_vec3 x0 = kin_quat_rotate(base.fore_rot, kin_v3(1, 0, 0));
        kin_vec3 x1 = kin_quat_rotate(j.fore_rot, kin_v3(1, 0, 0));
        float tw = atan2f(kin_v3_dot(kin_v3_cross(x0, x1), zf), kin_v3_dot(x0, x1));
        float want = fminf(85.0f, fmaxf(-85.0f, rolls[i] * 0.5f)) * PI_F / 180.0f;
        NEAR(tw, want, 2e-4);
    }
}

/* Mirroring the world in x = 0 mirrors a right-arm solution onto the left
 * arm (rotations mirror as (x, -y, -z, w)). */
static void result_left_mirrors_right(void **state)
{
    (void)state;
    tu_rng g = { 0x6d697272 };
    for (int it = 0; it < 100; it++) {
        kin_quat hr = kin_quat_normalize(tu_quat(&g, -1, 1));
        kin_vec3 s = kin_v3(0.19f, 1.0f, 0.0f);
        kin_vec3 w = tu_v3b(&g, -0.3f, 0.7f, 0.5f, 1.5f, -0.6f, 0.2f);
        kin_arm_ik_job r = job_of(s, w, hr, KIN_SIDE_RIGHT);
        kin_arm_ik_job l = job_of(kin_v3(-s.x, s.y, s.z), kin_v3(-w.x, w.y, w.z),
                                  (kin_quat){ hr.x, -hr.y, -hr.z, hr.w }, KIN_SIDE_LEFT);
        assert_int_equal(kin_arm_ik_run(&r), 1);
        assert_int_equal(kin_arm_ik_run(&l), 1);
        NEARV(l.elbow, -r.elbow.x, r.elbow.y, r.elbow.z, 1e-4);
        NEAR(l.flexion, r.flexion, 1e-4);
    }
}

/* ---------------------------------------------------- stability sweeps */

/* The documented singular direction of the swivel rule for the right arm
 * (body frame = world here): Q = (-0.707, 0, 0.707), into the torso. */
static int near_q(kin_vec3 s, kin_vec3 w)
{
    kin_vec3 u = kin_v3_norm(kin_v3_sub(w, s));
    return kin_v3_dot(u, kin_v3_norm(kin_v3(-1, 0, 1))) > cosf(30.0f * PI_F / 180.0f);
}

/* Walks the target along a path; checks finiteness, bone lengths and
 * that no step moves the elbow more than ELBOW_GAIN times the target's
 * step (+0.1 mm), except within 30 degrees of the singular direction Q.
 * Returns the largest ratio seen. */
static float sweep(kin_vec3 s, kin_vec3 a, kin_vec3 b, kin_quat h0, kin_quat h1, int steps,
                   float gain, const char *what)
{
    kin_arm_ik_job prev;
    float worst = 0.0f;
    for (int i = 0; i <= steps; i++) {
        float t = (float)i / (float)steps;
        kin_vec3 w = kin_v3_add(a, kin_v3_scale(kin_v3_sub(b, a), t));
        kin_arm_ik_job j = job_of(s, w, kin_quat_slerp(h0, h1, t), KIN_SIDE_RIGHT);
        if (!kin_arm_ik_run(&j)) fail_msg("%s: step %d rejected", what, i);
        if (!finite_job(&j)) fail_msg("%s: step %d not finite", what, i);
        NEAR(dist(j.elbow, s), 0.3, 1e-4);
        if (i > 0 && !near_q(s, w) && !near_q(s, prev.wrist)) {
            float dw = dist(w, prev.wrist), de = dist(j.elbow, prev.elbow);
            float step = dw > 1e-6f ? dw : 1e-6f;
            if (de > gain * step + 1e-4f)
                fail_msg("%s: step %d: elbow jumped %.4f m for a target step of %.5f m", what, i,
                         (double)de, (double)dw);
            if (de / step > worst) worst = de / step;
        }
        prev = j;
    }
    return worst;
}

static void sweep_targets_through_and_beyond_reach(void **state)
{
    (void)state;
    tu_rng g = { 0x73776565 };
    kin_vec3 s = kin_v3(0.19f, 1.0f, 0.0f);
    float worst = 0.0f;
    for (int it = 0; it < 300; it++) {
        /* random lines through the reach sphere, from 1.6x reach to 1.6x */
        kin_vec3 dir = kin_v3_norm(tu_v3(&g, -1, 1));
        /* closest approach to the shoulder: 0.12 .. 0.5 m */
        kin_vec3 r = tu_v3(&g, -1, 1);
        r = kin_v3_norm(kin_v3_sub(r, kin_v3_scale(dir, kin_v3_dot(r, dir))));
        kin_vec3 off = kin_v3_scale(r, tu_range(&g, 0.12f, 0.5f));
        kin_vec3 mid = kin_v3_add(s, off);
        kin_vec3 a = kin_v3_sub(mid, kin_v3_scale(dir, 0.9f)), b = kin_v3_add(mid, kin_v3_scale(dir, 0.9f));
        kin_quat h0 = tu_quat(&g, -0.3f, 0.3f);
        h0.w = 1.0f;
        h0 = kin_quat_normalize(h0);
        kin_quat h1 = tu_quat(&g, -0.3f, 0.3f);
        h1.w = 1.0f;
        h1 = kin_quat_normalize(h1);
        char what[64];
        snprintf(what, sizeof what, "line %d", it);
        float ratio = sweep(s, a, b, h0, h1, 900, ELBOW_GAIN, what);
        if (ratio > worst) worst = ratio;
    }
    print_message("NOTE worst elbow/target step ratio over 300 lines: %.2f (bound %.0f)\n",
                  (double)worst, (double)ELBOW_GAIN);
}

static void sweep_straight_arm_and_shoulder(void **state)
{
    (void)state;
    kin_vec3 s = kin_v3(0.19f, 1.0f, 0.0f);
    kin_quat id = kin_quat_identity();
    /* along the straight-arm line, out to 2x reach: the elbow never
     * snaps and the flexion shrinks monotonically towards 0 */
    kin_vec3 dirs[] = { kin_v3(0, 0, -1), kin_v3(1, 0, 0), kin_v3(0, -1, 0),
                        kin_v3_norm(kin_v3(0.3f, 0.4f, -1)) };
    for (size_t k = 0; k < sizeof dirs / sizeof dirs[0]; k++) {
        kin_vec3 a = kin_v3_add(s, kin_v3_scale(dirs[k], 0.3f));
        kin_vec3 b = kin_v3_add(s, kin_v3_scale(dirs[k], 1.12f));
        sweep(s, a, b, id, id, 2000, ELBOW_GAIN, "straight arm");
        float prev = 10.0f;
        for (int i = 0; i <= 200; i++) {
            kin_vec3 w = kin_v3_add(a, kin_v3_scale(kin_v3_sub(b, a), (float)i / 200.0f));
            kin_arm_ik_job j = job_of(s, w, id, KIN_SIDE_RIGHT);
            assert_int_equal(kin_arm_ik_run(&j), 1);
            assert_true(j.flexion >= 0.0f);
            assert_true(j.flexion <= prev + 1e-4f);
            prev = j.flexion;
        }
    }
    /* through the shoulder point itself, in several directions (not the
     * documented singular direction, see docs/tracking.md) */
    kin_vec3 through[] = { kin_v3(1, 0, 0), kin_v3(0, 1, 0), kin_v3(0, 0, 1),
                           kin_v3_norm(kin_v3(1, 1, -1)) };
    for (size_t k = 0; k < sizeof through / sizeof through[0]; k++) {
        kin_vec3 a = kin_v3_sub(s, kin_v3_scale(through[k], 0.25f));
        kin_vec3 b = kin_v3_add(s, kin_v3_scale(through[k], 0.25f));
        float r = sweep(s, a, b, id, id, 2000, SHOULDER_GAIN, "through the shoulder");
        print_message("NOTE through the shoulder %zu: worst ratio %.2f (bound %.0f)\n", k,
                      (double)r, (double)SHOULDER_GAIN);
    }
}

static void sweep_hand_rotation(void **state)
{
    (void)state;
    /* a full turn of the hand about each axis, target fixed: the elbow
     * moves at most 0.3 m * 4 * angle step (bounded, no flip) */
    kin_vec3 s = kin_v3(0.19f, 1.0f, 0.0f), w = kin_v3(0.3f, 0.9f, -0.35f);
    kin_vec3 axes[] = { kin_v3(1, 0, 0), kin_v3(0, 1, 0), kin_v3(0, 0, 1),
                        kin_v3_norm(kin_v3(1, -1, 0.5f)) };
    for (size_t k = 0; k < sizeof axes / sizeof axes[0]; k++) {
        kin_vec3 prev = kin_v3(0, 0, 0);
        const int steps = 3600;
        for (int i = 0; i <= steps; i++) {
            float ang = 2.0f * PI_F * (float)i / (float)steps;
            kin_arm_ik_job j = job_of(s, w, kin_quat_axis_angle(axes[k], ang), KIN_SIDE_RIGHT);
            assert_int_equal(kin_arm_ik_run(&j), 1);
            assert_true(finite_job(&j));
            if (i > 0 && dist(j.elbow, prev) > 0.3f * 4.0f * (2.0f * PI_F / steps))
                fail_msg("axis %zu step %d: elbow jumped %.4f m", k, i,
                         (double)dist(j.elbow, prev));
            prev = j.elbow;
        }
    }
}

/* ---------------------------------------------------------------- rig */

/* A minimal model with the rig's names, in the generated model's layout. */
typedef struct mini {
    kin_model m;
    int16_t parents[48];
    kin_transform rest[48];
    char names[48][KIN_NAME_MAX];
    int src[48];
} mini;

static int add(mini *k, const char *name, int parent, kin_vec3 t)
{
    int i = k->m.node_count++;
    snprintf(k->names[i], KIN_NAME_MAX, "%s", name);
    k->parents[i] = (int16_t)parent;
    k->rest[i].t = t;
    k->rest[i].r = kin_quat_identity();
    k->rest[i].s = kin_v3(1, 1, 1);
    k->src[i] = i;
    return i;
}

static void build_mini(mini *k, const char *skip)
{
    memset(k, 0, sizeof *k);
    k->m.parents = k->parents;
    k->m.rest = k->rest;
    k->m.names = (const char(*)[KIN_NAME_MAX])k->names;
    k->m.node_src = k->src;
    int body = add(k, "body", -1, kin_v3(0, 1, 0));
    add(k, "head", body, kin_v3(0, 0.25f, -0.08f));
    char nm[KIN_NAME_MAX];
    for (int s = 0; s < 2; s++) {
        float sx = s ? 1.0f : -1.0f;
        int J[KIN_RIG_SIDE_JOINTS];
        kin_vec3 off[5] = { kin_v3(0.035f * sx, -0.015f, 0), kin_v3(0.155f * sx, -0.015f, 0),
                            kin_v3(0, 0, -0.3f), kin_v3(0, 0, -0.26f), kin_v3(0, 0, -0.03f) };
        for (int j = 0; j < 5; j++) {
            kin_arm_rig_joint_name((kin_side)s, j, nm, sizeof nm);
            if (skip && strcmp(nm, skip) == 0) strcat(nm, "_x");
            J[j] = add(k, nm, j ? J[j - 1] : body, off[j]);
        }
        for (int f = 0; f < 5; f++)
            for (int q = 0; q < 3; q++) {
                int j = KIN_RIG_FINGER0 + 3 * f + q;
                kin_arm_rig_joint_name((kin_side)s, j, nm, sizeof nm);
                if (skip && strcmp(nm, skip) == 0) strcat(nm, "_x");
                J[j] = add(k, nm, q ? J[j - 1] : J[KIN_RIG_PALM],
                           q ? kin_v3(0, 0, -0.03f) : kin_v3(0.02f * (float)(f - 2), 0, -0.07f));
            }
    }
}

static void rig_missing_joints_listed(void **state)
{
    (void)state;
    mini k;
    kin_arm_rig rig;
    char why[512];
    build_mini(&k, NULL);
    assert_int_equal(kin_arm_rig_init(&rig, &k.m, why, sizeof why), 0);
    NEAR(rig.upper_len[1], 0.3, 1e-6);
    NEAR(rig.fore_len[0], 0.26, 1e-6);
    NEAR(rig.shoulder_width, 0.38, 1e-6);
    build_mini(&k, "R_ring_2");
    assert_int_equal(kin_arm_rig_init(&rig, &k.m, why, sizeof why), -1);
    assert_string_equal(why, "missing joints (1): R_ring_2");
    build_mini(&k, "L_palm");
    snprintf(k.names[1], KIN_NAME_MAX, "HEAD");
    assert_int_equal(kin_arm_rig_init(&rig, &k.m, why, sizeof why), -1);
    assert_string_equal(why, "missing joints (2): head, L_palm");
    /* a forearm offset off the -Z axis breaks the bone convention */
    build_mini(&k, NULL);
    int fa = kin_model_find_node(&k.m, "L_forearm");
    k.rest[fa].t = kin_v3(0.1f, 0, -0.3f);
    assert_int_equal(kin_arm_rig_init(&rig, &k.m, why, sizeof why), -1);
    assert_non_null(strstr(why, "-Z"));
}

static void rig_pose_reaches_the_tracked_points(void **state)
{
    (void)state;
    mini k;
    build_mini(&k, NULL);
    kin_arm_rig rig;
    char why[256];
    assert_int_equal(kin_arm_rig_init(&rig, &k.m, why, sizeof why), 0);
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.valid = KIN_TRACK_ALL;
    s.shoulder[0] = kin_v3(-0.25f, 1.1f, 0.1f);
    s.shoulder[1] = kin_v3(0.25f, 1.1f, 0.1f);
    s.head_pos = kin_v3(0.0f, 1.38f, 0.02f);
    s.head_rot = kin_quat_axis_angle(kin_v3(0, 1, 0), 0.3f);
    s.hand_pos[0] = kin_v3(-0.2f, 1.0f, -0.35f);
    s.hand_pos[1] = kin_v3(0.1f, 1.2f, -0.4f);
    s.hand_rot[0] = kin_quat_identity();
    s.hand_rot[1] = kin_quat_axis_angle(kin_v3(0, 0, 1), 0.5f);
    for (int f = 0; f < 5; f++) s.glove[0][f] = s.glove[1][f] = 0.5f;
    kin_user_calib c = kin_user_calib_identity();
    c.shoulder_scale = 0.5f / 0.38f;   /* this user's shoulders are 0.5 m apart */
    c.arm_scale[1] = 1.1f;
    kin_transform loc[48];
    kin_mat4 world[48];
    kin_pose_rest(&k.m, loc);
    kin_arm_ik_job out[2];
    assert_int_equal(kin_arm_rig_pose(&rig, &k.m, &c, NULL, &s, loc, out), 1);
    kin_fk(k.m.parents, k.m.node_count, loc, NULL, world);
    for (int side = 0; side < 2; side++) {
        const int *J = rig.joint[side];
        kin_vec3 ua = kin_v3(world[J[KIN_RIG_UPPER_ARM]].m[12], world[J[KIN_RIG_UPPER_ARM]].m[13],
                             world[J[KIN_RIG_UPPER_ARM]].m[14]);
        kin_vec3 hd = kin_v3(world[J[KIN_RIG_HAND]].m[12], world[J[KIN_RIG_HAND]].m[13],
                             world[J[KIN_RIG_HAND]].m[14]);
        kin_vec3 el = kin_v3(world[J[KIN_RIG_FOREARM]].m[12], world[J[KIN_RIG_FOREARM]].m[13],
                             world[J[KIN_RIG_FOREARM]].m[14]);
        NEARV(ua, s.shoulder[side].x, s.shoulder[side].y, s.shoulder[side].z, 1e-5);
        NEARV(hd, s.hand_pos[side].x, s.hand_pos[side].y, s.hand_pos[side].z, 1e-5);
        NEARV(el, out[side].elbow.x, out[side].elbow.y, out[side].elbow.z, 1e-5);
        NEAR(dist(el, ua), 0.3f * c.arm_scale[side], 1e-5);
        /* the hand joint's world rotation is the tracked one */
        kin_vec3 fz = kin_mat4_mul_dir(&world[J[KIN_RIG_HAND]], kin_v3(0, 0, -1));
        kin_vec3 tz = kin_quat_rotate(s.hand_rot[side], kin_v3(0, 0, -1));
        NEARV(fz, tz.x, tz.y, tz.z, 1e-5);
    }
    int head = rig.head;
    NEARV(kin_v3(world[head].m[12], world[head].m[13], world[head].m[14]), s.head_pos.x,
          s.head_pos.y, s.head_pos.z, 1e-5);
    /* missing hands keep their locals; a NaN sample is refused */
    s.valid = KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R;
    kin_transform before[48];
    memcpy(before, loc, sizeof loc);
    assert_int_equal(kin_arm_rig_pose(&rig, &k.m, &c, NULL, &s, loc, NULL), 1);
    assert_memory_equal(&before[rig.joint[1][KIN_RIG_FOREARM]].r,
                        &loc[rig.joint[1][KIN_RIG_FOREARM]].r, sizeof(kin_quat));
    s.shoulder[0].x = NAN;
    assert_int_equal(kin_arm_rig_pose(&rig, &k.m, &c, NULL, &s, loc, NULL), 0);
}

int main(void)
{
    int f = 0;
    TU_GROUP(f, "kin_ik validity",
             cmocka_unit_test(validity_rejects_bad_jobs),
             cmocka_unit_test(rig_missing_joints_listed));
    TU_GROUP(f, "kin_ik results",
             cmocka_unit_test(result_hand_worked_elbow),
             cmocka_unit_test(result_swivel_follows_hand),
             cmocka_unit_test(result_reach_limits),
             cmocka_unit_test(result_twist_share_and_limit),
             cmocka_unit_test(result_left_mirrors_right),
             cmocka_unit_test(rig_pose_reaches_the_tracked_points));
    TU_GROUP(f, "kin_ik stability sweeps",
             cmocka_unit_test(sweep_targets_through_and_beyond_reach),
             cmocka_unit_test(sweep_straight_arm_and_shoulder),
             cmocka_unit_test(sweep_hand_rotation));
    return f ? 1 : 0;
}
