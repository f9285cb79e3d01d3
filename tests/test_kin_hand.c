/* test_kin_hand.c - gloves (kin_hand.c): calibration of the raw range
 * (percentiles, inverted sensors, dead sensors rejected), the mapping of
 * 5 values to 15 joints against hand-worked angles (DIP = 2/3 PIP, thumb
 * opposition mirrored for the left hand), and validity. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

static void near_q(kin_quat a, kin_quat b, float tol)
{
    float d = fabsf(a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w);
    NEAR(d, 1.0, tol);
}

/* ------------------------------------------------------------ validity */

static void validity_glove_calib(void **state)
{
    (void)state;
    float raw[50 * 5], scratch[50];
    kin_glove_calib c;
    char why[128];
    for (int i = 0; i < 50 * 5; i++) raw[i] = (float)(i / 5) * 10.0f;
    assert_int_equal(kin_glove_calib_fit(raw, 7, 0, 1.0f, scratch, &c, why, sizeof why), -1);
    assert_non_null(strstr(why, "need at least 8"));
    raw[5 * 3 + 2] = NAN;
    assert_int_equal(kin_glove_calib_fit(raw, 50, 0, 1.0f, scratch, &c, why, sizeof why), -1);
    assert_non_null(strstr(why, "reading 4, sensor 3"));
    raw[5 * 3 + 2] = 30.0f;
    for (int i = 0; i < 50; i++) raw[i * 5 + 4] = 100.0f + (float)(i % 2); /* dead sensor */
    assert_int_equal(kin_glove_calib_fit(raw, 50, 0, 5.0f, scratch, &c, why, sizeof why), -1);
    assert_non_null(strstr(why, "sensor 5 moves over 1"));
    float g[5], r5[5] = { 1, 2, NAN, 4, 5 };
    assert_int_equal(kin_glove_calib_apply(&c, r5, g), -1);
}

static void validity_hand_job(void **state)
{
    (void)state;
    float glove[5] = { 0, 0.2f, 0.4f, 0.6f, 1.0f };
    kin_quat out[15];
    kin_hand_job j = { glove, NULL, NULL, KIN_SIDE_RIGHT, out, NULL };
    char why[128];
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 1);
    glove[3] = 1.01f;
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 0);
    assert_non_null(strstr(why, "glove value 4"));
    glove[3] = NAN;
    assert_int_equal(kin_hand_run(&j), 0);
    glove[3] = 0.5f;
    j.out = NULL;
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 0);
    j.out = out;
    kin_quat rest[15];
    for (int i = 0; i < 15; i++) rest[i] = kin_quat_identity();
    rest[7] = (kin_quat){ 0, 0, 0, 2 };
    j.rest = rest;
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 0);
    j.rest = NULL;
    kin_hand_params p = kin_hand_params_default();
    p.fist_deg[2][1] = INFINITY;
    j.params = &p;
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 0);
    p = kin_hand_params_default();
    p.dip_coupling = -1;
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 0);
    j.params = NULL;
    j.side = (kin_side)2;
    assert_int_equal(kin_hand_validate(&j, why, sizeof why), 0);
}

/* -------------------------------------------------------------- results */

static void result_glove_calib_percentiles(void **state)
{
    (void)state;
    /* 100 readings per sensor: 0..99 plus scale; one spike at 10000 */
    enum { N = 100 };
    float raw[N * 5], scratch[N];
    for (int i = 0; i < N; i++)
        for (int k = 0; k < 5; k++) raw[i * 5 + k] = 200.0f + 3.0f * (float)i + (float)k;
    raw[50 * 5 + 1] = 10000.0f;
    kin_glove_calib c;
    char why[128];
    /* sensor 3 (bit 2) reads lower when bent */
    assert_int_equal(kin_glove_calib_fit(raw, N, 1u << 2, 1.0f, scratch, &c, why, sizeof why), 0);
    /* nearest rank: index round(0.02 * 99) = 2 and round(0.98 * 99) = 97 */
    NEAR(c.raw_open[0], 206.0, 0);
    NEAR(c.raw_fist[0], 491.0, 0);
    NEAR(c.raw_fist[1], 3.0f * 98 + 201, 0);   /* the spike shifts one rank */
    NEAR(c.raw_open[2], 493.0, 0);
    NEAR(c.raw_fist[2], 208.0, 0);
    float g[5];
    float r[5] = { 206.0f, 10000.0f, 350.5f, 0.0f, 350.0f };
    assert_int_equal(kin_glove_calib_apply(&c, r, g), 0);
    NEAR(g[0], 0.0, 1e-6);
    NEAR(g[1], 1.0, 1e-6);                       /* clamped */
    NEAR(g[2], (350.5 - 493.0) / (208.0 - 493.0), 1e-6);
    NEAR(g[3], 0.0, 1e-6);
    NEAR(g[4], (350.0 - 210.0) / (495.0 - 210.0), 1e-6);
}

static void result_hand_mapping_hand_worked(void **state)
{
    (void)state;
    float glove[5] = { 0.5f, 0.0f, 1.0f, 0.25f, 0.75f };
    kin_quat out[15], outl[15];
    float ang[15];
    kin_hand_job j = { glove, NULL, NULL, KIN_SIDE_RIGHT, out, ang };
    assert_int_equal(kin_hand_run(&j), 1);
    /* defaults: index open (5, 8), middle fist (85, 100), ring 1/4 of
     * (8, 12) -> (85, 100), little 3/4 of (10, 14) -> (85, 95); DIP 2/3 PIP */
    NEAR(ang[3], 5.0, 1e-5);  NEAR(ang[4], 8.0, 1e-5);   NEAR(ang[5], 16.0 / 3.0, 1e-5);
    NEAR(ang[6], 85.0, 1e-5); NEAR(ang[7], 100.0, 1e-5); NEAR(ang[8], 200.0 / 3.0, 1e-5);
    NEAR(ang[9], 8 + 0.25 * 77, 1e-4);  NEAR(ang[10], 12 + 0.25 * 88, 1e-4);
    NEAR(ang[11], (12 + 0.25 * 88) * 2.0 / 3.0, 1e-4);
    NEAR(ang[12], 10 + 0.75 * 75, 1e-4); NEAR(ang[13], 14 + 0.75 * 81, 1e-4);
    /* thumb: (5,5,5) -> (20,50,65) at 0.5 */
    NEAR(ang[0], 12.5, 1e-5); NEAR(ang[1], 27.5, 1e-5); NEAR(ang[2], 35.0, 1e-5);
    /* rotations: flexion about +X by -angle (towards the palm, -Y) */
    near_q(out[7], kin_quat_axis_angle(kin_v3(1, 0, 0), -100.0f * PI_F / 180.0f), 1e-6f);
    kin_vec3 tip = kin_quat_rotate(out[6], kin_v3(0, 0, -1));
    assert_true(tip.y < -0.99f);             /* 85 degrees: pointing at the palm side */
    /* thumb base: Rz(opp) * Rx(-12.5), opp = 12 + 0.5 * 28 = 26 degrees */
    kin_quat want = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 0, 1), 26.0f * PI_F / 180.0f),
                                 kin_quat_axis_angle(kin_v3(1, 0, 0), -12.5f * PI_F / 180.0f));
    near_q(out[0], want, 1e-6f);
    /* the left hand mirrors the opposition only */
    j.side = KIN_SIDE_LEFT;
    j.out = outl;
    assert_int_equal(kin_hand_run(&j), 1);
    want = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 0, 1), -26.0f * PI_F / 180.0f),
                        kin_quat_axis_angle(kin_v3(1, 0, 0), -12.5f * PI_F / 180.0f));
    near_q(outl[0], want, 1e-6f);
    for (int i = 1; i < 15; i++) near_q(outl[i], out[i], 1e-6f);
    /* rest rotations compose on the left */
    kin_quat rest[15];
    for (int i = 0; i < 15; i++) rest[i] = kin_quat_axis_angle(kin_v3(0, 1, 0), 0.1f * (float)i);
    j.side = KIN_SIDE_RIGHT;
    j.rest = rest;
    j.out = outl;
    assert_int_equal(kin_hand_run(&j), 1);
    near_q(outl[7], kin_quat_mul(rest[7], out[7]), 1e-6f);
}

static void result_hand_monotone_and_continuous(void **state)
{
    (void)state;
    /* sweeping one sensor 0 -> 1 moves only its finger, monotonically and
     * with a bounded step (max joint range / steps) */
    kin_hand_params p = kin_hand_params_default();
    for (int f = 0; f < 5; f++) {
        float prev[15] = { 0 };
        for (int i = 0; i <= 100; i++) {
            float glove[5] = { 0.3f, 0.3f, 0.3f, 0.3f, 0.3f }, ang[15];
            glove[f] = (float)i / 100.0f;
            kin_quat out[15];
            kin_hand_job j = { glove, &p, NULL, KIN_SIDE_RIGHT, out, ang };
            assert_int_equal(kin_hand_run(&j), 1);
            for (int k = 0; k < 15; k++) {
                if (i > 0 && k / 3 == f) {
                    assert_true(ang[k] >= prev[k] - 1e-5f);
                    assert_true(ang[k] - prev[k] <= 1.0f + 1e-4f); /* <= 100 deg / 100 */
                } else if (i > 0) {
                    NEAR(ang[k], prev[k], 0);
                }
                prev[k] = ang[k];
            }
        }
    }
}

int main(void)
{
    int f = 0;
    TU_GROUP(f, "kin_hand validity",
             cmocka_unit_test(validity_glove_calib),
             cmocka_unit_test(validity_hand_job));
    TU_GROUP(f, "kin_hand results",
             cmocka_unit_test(result_glove_calib_percentiles),
             cmocka_unit_test(result_hand_mapping_hand_worked),
             cmocka_unit_test(result_hand_monotone_and_continuous));
    return f ? 1 : 0;
}
