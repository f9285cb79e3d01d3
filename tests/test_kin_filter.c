/* test_kin_filter.c - One Euro filter, prediction and dropouts
 * (kin_filter.c): the first updates against the formulas worked by hand,
 * exact prediction of a constant velocity (positions and rotations),
 * NaN parts skipped, time stamps that go backwards dropped (or a restart
 * when far back), hold-then-fade of a lost part, restart after a gap. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

#define PI_D 3.14159265358979323846

static kin_track_sample hand_at(double t, kin_vec3 p, kin_quat q)
{
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.t = t;
    s.valid = KIN_TRACK_HAND_R;
    s.head_rot = s.hand_rot[0] = kin_quat_identity();
    s.hand_pos[1] = p;
    s.hand_rot[1] = q;
    return s;
}

static double alpha(double fc, double dt) { return 1.0 / (1.0 + 1.0 / (2.0 * PI_D * fc * dt)); }

/* ------------------------------------------------------------ validity */

static void validity_nan_parts_and_old_samples(void **state)
{
    (void)state;
    kin_filter f;
    kin_filter_init(&f, NULL);
    kin_track_sample s = hand_at(1.0, kin_v3(0.1f, 1, -0.3f), kin_quat_identity());
    s.valid |= KIN_TRACK_SHOULDER_R;
    s.shoulder[1] = kin_v3(0.2f, 1.0f, 0.0f);
    assert_int_equal(kin_filter_push(&f, &s), KIN_FILTER_ACCEPTED);
    kin_filter keep = f;
    /* NaN hand: skipped, the shoulder still updates */
    kin_track_sample n = s;
    n.t = 1.01;
    n.hand_pos[1].x = NAN;
    n.shoulder[1].x = 0.21f;
    assert_int_equal(kin_filter_push(&f, &n), KIN_FILTER_ACCEPTED | KIN_FILTER_NONFINITE);
    assert_memory_equal(&f.part[4], &keep.part[4], sizeof f.part[4]);
    assert_true(f.part[2].x.x > 0.2f);
    assert_int_equal(f.nonfinite_parts, 1);
    /* a non-unit quaternion and an out-of-range glove count the same */
    n.t = 1.02;
    n.hand_pos[1].x = 0.1f;
    n.hand_rot[1] = (kin_quat){ 0, 0, 0, 0.5f };
    n.valid |= KIN_TRACK_GLOVE_R;
    n.glove[1][2] = 1.5f;
    assert_int_equal(kin_filter_push(&f, &n), KIN_FILTER_ACCEPTED | KIN_FILTER_NONFINITE);
    assert_int_equal(f.nonfinite_parts, 3);
    assert_int_equal(f.part[6].has, 0);
    /* time stamps that go backwards (or repeat) are dropped */
    keep = f;
    n.t = 1.015;
    assert_int_equal(kin_filter_push(&f, &n), KIN_FILTER_OLD);
    n.t = 1.02;
    assert_int_equal(kin_filter_push(&f, &n), KIN_FILTER_OLD);
    assert_int_equal(f.dropped_old, 2);
    assert_memory_equal(f.part, keep.part, sizeof f.part);
    n.t = NAN;
    assert_int_equal(kin_filter_push(&f, &n), KIN_FILTER_NONFINITE);
    assert_memory_equal(f.part, keep.part, sizeof f.part);
    /* far back (> reset_s): the source restarted */
    kin_track_sample r = hand_at(0.2, kin_v3(0.5f, 0.5f, 0.5f), kin_quat_identity());
    assert_int_equal(kin_filter_push(&f, &r), KIN_FILTER_ACCEPTED | KIN_FILTER_RESTART);
    assert_int_equal(f.restarts, 1);
    assert_int_equal(f.part[2].has, 0);            /* old shoulder forgotten */
    kin_track_sample o;
    float conf[KIN_FILTER_PARTS];
    kin_filter_output(&f, 0.2, &o, conf);
    assert_int_equal(o.valid, KIN_TRACK_HAND_R);
    assert_true(o.hand_pos[1].x == 0.5f);
}

/* -------------------------------------------------------------- results */

static void result_first_updates_hand_worked(void **state)
{
    (void)state;
    kin_filter f;
    kin_filter_desc d = { 0 };
    kin_filter_init(&f, &d);
    NEAR(f.desc.min_cutoff_hz, 1.5, 0);
    NEAR(f.desc.beta, 4.0, 0);
    kin_quat id = kin_quat_identity();
    kin_filter_push(&f, &(kin_track_sample){ 0 });      /* empty sample: t = 0 */
    kin_track_sample s = hand_at(0.0 + 0.01, kin_v3(0, 0, 0), id);
    kin_filter_push(&f, &s);
    s = hand_at(0.02, kin_v3(0.01f, 0, 0), id);
    kin_filter_push(&f, &s);
    double ad = alpha(1.0, 0.01);
    double dx = ad * 1.0;                 /* raw velocity 1 m/s */
    double fc = 1.5 + 4.0 * dx;
    double a = alpha(fc, 0.01);
    NEAR(f.part[4].dx.x, dx, 1e-6);
    NEAR(f.part[4].x.x, a * 0.01, 1e-8);
    NEAR(f.part[4].lag, 0.01 * (1 - a) / a, 1e-6);
    /* a constant input stays exactly put, and is predicted put */
    kin_filter g;
    kin_filter_init(&g, NULL);
    for (int i = 0; i < 100; i++) {
        s = hand_at(0.01 * i, kin_v3(0.3f, 1.1f, -0.4f), kin_quat_axis_angle(kin_v3(0, 1, 0), 0.7f));
        kin_filter_push(&g, &s);
    }
    kin_track_sample o;
    kin_filter_output(&g, 0.99 + 0.05, &o, NULL);
    assert_true(o.hand_pos[1].x == 0.3f && o.hand_pos[1].y == 1.1f && o.hand_pos[1].z == -0.4f);
    NEAR(o.hand_rot[1].y, sinf(0.35f), 1e-6);
}

static void result_constant_velocity_predicted(void **state)
{
    (void)state;
    /* 100 Hz, v = (0.5, -0.2, 0.1) m/s, w = 2 rad/s about Y, for 2 s: the
     * prediction 50 ms ahead lands on the true pose */
    kin_filter f;
    kin_filter_init(&f, NULL);
    kin_vec3 v = kin_v3(0.5f, -0.2f, 0.1f), p0 = kin_v3(0.1f, 1.0f, -0.3f);
    double t = 0;
    for (int i = 0; i <= 200; i++) {
        t = 0.01 * i;
        kin_track_sample s = hand_at(t, kin_v3_add(p0, kin_v3_scale(v, (float)t)),
                                     kin_quat_axis_angle(kin_v3(0, 1, 0), 2.0f * (float)t));
        kin_filter_push(&f, &s);
    }
    kin_track_sample o;
    float conf[KIN_FILTER_PARTS];
    double td = t + 0.05;
    kin_filter_output(&f, td, &o, conf);
    kin_vec3 want = kin_v3_add(p0, kin_v3_scale(v, (float)td));
    NEAR(o.hand_pos[1].x, want.x, 2e-4);
    NEAR(o.hand_pos[1].y, want.y, 2e-4);
    NEAR(o.hand_pos[1].z, want.z, 2e-4);
    kin_quat qw = kin_quat_axis_angle(kin_v3(0, 1, 0), 2.0f * (float)td);
    NEAR(fabs(o.hand_rot[1].w * qw.w + o.hand_rot[1].y * qw.y), 1.0, 1e-5);
    NEAR(conf[4], 1.0, 0);
    /* without prediction (display time = last sample) the lag is gone too */
    kin_filter_output(&f, t, &o, NULL);
    want = kin_v3_add(p0, kin_v3_scale(v, (float)t));
    NEAR(o.hand_pos[1].x, want.x, 2e-4);
}

static void result_dropout_hold_then_fade(void **state)
{
    (void)state;
    kin_filter f;
    kin_filter_desc d = { .hold_s = 0.2f, .fade_s = 0.4f, .max_predict_s = 0.05f };
    kin_filter_init(&f, &d);
    double t = 0;
    for (int i = 0; i <= 100; i++) {
        t = 0.01 * i;
        kin_track_sample s = hand_at(t, kin_v3(0.3f * (float)t, 1, -0.3f), kin_quat_identity());
        kin_filter_push(&f, &s);
    }
    kin_track_sample o, o2;
    float conf[KIN_FILTER_PARTS];
    /* within hold: full confidence; past max_predict the pose stops */
    kin_filter_output(&f, t + 0.1, &o, conf);
    NEAR(conf[4], 1.0, 0);
    kin_filter_output(&f, t + 0.2, &o2, conf);
    NEAR(conf[4], 1.0, 0);
    assert_memory_equal(&o.hand_pos[1], &o2.hand_pos[1], sizeof(kin_vec3));
    NEAR(o.hand_pos[1].x, 0.3 * (t + 0.05), 1e-4);      /* held at the horizon */
    /* then it fades linearly to 0 over fade_s */
    kin_filter_output(&f, t + 0.2 + 0.1, &o, conf);
    NEAR(conf[4], 0.75, 1e-5);
    kin_filter_output(&f, t + 0.2 + 0.3, &o, conf);
    NEAR(conf[4], 0.25, 1e-5);
    assert_true(o.valid & KIN_TRACK_HAND_R);
    kin_filter_output(&f, t + 0.61, &o, conf);
    NEAR(conf[4], 0.0, 0);
    assert_false(o.valid & KIN_TRACK_HAND_R);
    NEAR(conf[0], 0.0, 0);                               /* never seen */
    /* data back after the gap: restarts at the measurement (no velocity
     * across the gap) */
    kin_track_sample s = hand_at(t + 1.0, kin_v3(-0.2f, 1.2f, -0.1f), kin_quat_identity());
    kin_filter_push(&f, &s);
    kin_filter_output(&f, t + 1.05, &o, conf);
    assert_true(o.hand_pos[1].x == -0.2f && o.hand_pos[1].y == 1.2f);
    NEAR(conf[4], 1.0, 0);
}

/* RMS error of the output at the sample times for a still hand with
 * uniform noise of 2 mm rms. */
static double still_rms(int no_lag_comp, double *in_rms)
{
    tu_rng g = { 0x6a6974 };
    kin_filter f;
    kin_filter_desc d = { .no_lag_comp = no_lag_comp };
    kin_filter_init(&f, &d);
    double in2 = 0, out2 = 0;
    int n = 0;
    for (int i = 0; i < 1000; i++) {
        float e = 0.002f * (tu_unit(&g) * 2.0f - 1.0f) * 1.732f;
        kin_track_sample s = hand_at(0.01 * i, kin_v3(0.2f + e, 1, -0.3f), kin_quat_identity());
        kin_filter_push(&f, &s);
        if (i < 100) continue;
        kin_track_sample o;
        kin_filter_output(&f, 0.01 * i, &o, NULL);
        in2 += (double)e * e;
        out2 += (o.hand_pos[1].x - 0.2) * (o.hand_pos[1].x - 0.2);
        n++;
    }
    *in_rms = sqrt(in2 / n);
    return sqrt(out2 / n);
}

static void result_jitter_reduced(void **state)
{
    (void)state;
    double rin, rout = still_rms(1, &rin), rin2, rcomp = still_rms(0, &rin2);
    print_message("NOTE jitter: in %.3f mm rms, filtered %.3f mm, with lag compensation "
                  "%.3f mm\n", rin * 1e3, rout * 1e3, rcomp * 1e3);
    assert_true(rout < 0.3 * rin);
    assert_true(rcomp < rin);
}

int main(void)
{
    int f = 0;
    TU_GROUP(f, "kin_filter validity",
             cmocka_unit_test(validity_nan_parts_and_old_samples));
    TU_GROUP(f, "kin_filter results",
             cmocka_unit_test(result_first_updates_hand_worked),
             cmocka_unit_test(result_constant_velocity_predicted),
             cmocka_unit_test(result_dropout_hold_then_fade),
             cmocka_unit_test(result_jitter_reduced));
    return f ? 1 : 0;
}
