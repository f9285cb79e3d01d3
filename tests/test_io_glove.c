/* test_io_glove.c - the 5DT Data Glove 5 Ultra's reports: byte layout (16
 * little-endian int16 / 4096, sensors at values 0, 3, 6, 9, 12), round
 * trips, short and corrupt reports, calibration fitted from a stream of
 * reports and applied, the tracking sample. The USB reader runs against a
 * configfs HID gadget in tests/vm. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/io/io_dev.h"

static void test_layout(void **st)
{
    (void)st;
    uint8_t r[64];
    memset(r, 0, sizeof r);
    /* value 3 (index finger) = 0x1000 = 1.0; value 12 (little) = -2048 = -0.5 */
    r[6] = 0x00;
    r[7] = 0x10;
    r[24] = 0x00;
    r[25] = 0xf8;
    /* the values between the sensors are ignored */
    r[2] = 0xff;
    r[3] = 0x7f;
    float raw[5];
    io_error err;
    assert_int_equal(io_glove_parse("g", r, 64, raw, &err), IO_OK);
    assert_true(raw[0] == 0.0f);
    assert_true(raw[1] == 1.0f);
    assert_true(raw[2] == 0.0f);
    assert_true(raw[4] == -0.5f);
}

static void test_round_trip(void **st)
{
    (void)st;
    tu_rng rng = {5};
    for (int i = 0; i < 200; i++) {
        float raw[5], back[5];
        for (int k = 0; k < 5; k++) raw[k] = tu_range(&rng, -3.9f, 3.9f);
        uint8_t r[64];
        io_glove_build(raw, r);
        io_error err;
        assert_int_equal(io_glove_parse("g", r, 64, back, &err), IO_OK);
        for (int k = 0; k < 5; k++) assert_true(fabsf(back[k] - raw[k]) <= 0.5f / 4096.0f);
        /* bytes outside the 5 sensors stay zero */
        for (int v = 0; v < 32; v++)
            if (v % 3 || v > 12) {
                assert_int_equal(r[2 * v], 0);
                assert_int_equal(r[2 * v + 1], 0);
            }
    }
}

static void test_bad_reports(void **st)
{
    (void)st;
    uint8_t r[64] = {0};
    float raw[5] = {9, 9, 9, 9, 9};
    io_error err;
    assert_int_equal(io_glove_parse("glove L", r, 17, raw, &err), IO_ERR_SIZE);
    assert_non_null(strstr(err.msg, "glove L: short report: 17 bytes"));
    assert_true(raw[0] == 9.0f); /* untouched */
    assert_int_equal(io_glove_parse("glove L", NULL, 64, raw, &err), IO_ERR_SIZE);
    /* 0x7fff / 4096 = 8 > 4: not a reading a bend sensor gives */
    r[18] = 0xff;
    r[19] = 0x7f;
    assert_int_equal(io_glove_parse("glove L", r, 64, raw, &err), IO_ERR_VALUE);
    assert_non_null(strstr(err.msg, "sensor 3"));
    assert_true(raw[0] == 9.0f);
}

static void test_feed_calibrated(void **st)
{
    (void)st;
    tu_rng rng = {77};
    io_glove g;
    memset(&g, 0, sizeof g);
    snprintf(g.name, sizeof g.name, "glove R");
    g.side = KIN_SIDE_RIGHT;
    /* a calibration session: the hand opens (raw ~0.30) and closes (~1.10);
     * sensor 2 reads lower when bent (1.2 open, 0.4 fist) */
    enum { N = 64 };
    float raw[N * 5], scratch[N];
    for (int i = 0; i < N; i++) {
        float bend = (i / 8) % 2 ? 1.0f : 0.0f;
        for (int k = 0; k < 5; k++) {
            float lo = 0.30f + 0.01f * (float)k, hi = 1.10f;
            float v = k == 2 ? 1.2f - 0.8f * bend : lo + (hi - lo) * bend;
            raw[i * 5 + k] = v + tu_range(&rng, -0.002f, 0.002f);
        }
        uint8_t r[64];
        io_glove_build(&raw[i * 5], r);
        assert_int_equal(io_glove_feed(&g, r, 64, NULL), IO_OK);
        for (int k = 0; k < 5; k++) raw[i * 5 + k] = g.raw[k]; /* as received */
    }
    assert_int_equal(g.reports, N);
    kin_glove_calib c;
    char why[128];
    assert_int_equal(kin_glove_calib_fit(raw, N, 1u << 2, 0.1f, scratch, &c, why, sizeof why), 0);
    io_glove_set_calib(&g, &c);
    /* half bent */
    float half[5];
    for (int k = 0; k < 5; k++) half[k] = k == 2 ? 0.8f : (0.30f + 0.01f * k + 1.10f) / 2;
    uint8_t r[64];
    io_glove_build(half, r);
    assert_int_equal(io_glove_feed(&g, r, 64, NULL), IO_OK);
    for (int k = 0; k < 5; k++) assert_true(fabsf(g.value[k] - 0.5f) < 0.02f);
    /* a short report keeps the last values and says so */
    io_error err;
    assert_int_equal(io_glove_feed(&g, r, 63, &err), IO_ERR_SIZE);
    assert_int_equal(g.bad_reports, 1);
    assert_non_null(strstr(g.status, "glove R: short report: 63 bytes"));
    assert_non_null(strstr(g.status, "keeping the last values"));
    for (int k = 0; k < 5; k++) assert_true(fabsf(g.value[k] - 0.5f) < 0.02f);
    /* into the tracking sample, clamped to 0..1 */
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    g.value[4] = 1.3f;
    io_glove_to_sample(&g, &s);
    assert_int_equal(s.valid, KIN_TRACK_GLOVE_R);
    assert_true(fabsf(s.glove[1][0] - 0.5f) < 0.02f);
    assert_true(s.glove[1][4] == 1.0f);
    assert_true(s.glove[0][0] == 0.0f);
    char w2[256];
    assert_int_equal(kin_track_sample_validate(&s, w2, sizeof w2), 0);
}

static void test_open_errors(void **st)
{
    (void)st;
    io_glove g;
    io_error err;
    assert_int_equal(io_glove_open(&g, "left-glove", &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "left-glove"));
    /* this machine has no glove (and may have no USB at all): a clear
     * message, nothing left open */
    io_result r = io_glove_open(&g, "serial:NO-SUCH-GLOVE-0000", &err);
    assert_int_not_equal(r, IO_OK);
    assert_non_null(strstr(err.msg, "glove"));
    assert_null(g.ctx);
    assert_null(g.handle);
    int fresh;
    assert_int_equal(io_glove_poll(&g, 0, &fresh, &err), IO_ERR_ARGS);
    io_glove_close(&g); /* harmless */
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_layout),          cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_bad_reports),     cmocka_unit_test(test_feed_calibrated),
        cmocka_unit_test(test_open_errors))
