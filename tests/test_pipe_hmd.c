/* test_pipe_hmd.c - one HMD description through the whole pipeline
 * (kin_sthmd_desc in pipe_desc.hmd): a headset unlike the paper's (a
 * 1440x1600 portrait display per eye, 100 x 106 deg, a 1280x720 camera
 * of 100 deg, cameras 64 mm apart and 70 mm in front of eyes 68 mm
 * apart):
 *   - eq. 1-4 for that desc, computed here from the equations (the wide
 *     camera keeps its 720 rows and is cropped to 648 columns, centred),
 *     and the cameras at +-baseline/2, the eyes (kin_sthmd_eye) at
 *     +-ipd/2, ipd 0 = the baseline;
 *   - pipe_frame end to end: outputs of the display's size, the mask of
 *     the crop's size, and the same bytes as the stages called by hand on
 *     that crop (rows 0..719, columns 316..963 of the sensor) and viewport;
 *     outside the viewport the output is the virtual image;
 *   - raw YUYV frames of 1280x720: the bytes of their RGBA conversion;
 *     one or two threads: the same bytes; images of the paper's sizes are
 *     refused with the sizes named.
 * Run under ASan + UBSan (make debug) it checks that nothing reads
 * outside the images of the non-default sizes. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe.h"
#include "support/pipe_frames.h"
#include "support/pipe_quad_check.h"

enum { CAMW = 1280, CAMH = 720, LCDW = 1440, LCDH = 1600 };
#define D2R 0.017453292519943295

static kin_sthmd_desc vr_desc(void)
{
    kin_sthmd_desc d;
    memset(&d, 0, sizeof d);
    d.cam_width = CAMW;
    d.cam_height = CAMH;
    d.cam_hfov_deg = 100.0f;
    d.baseline_m = 0.064f;
    d.ipd_m = 0.068f;
    d.cam_offset_m = 0.07f;
    d.lcd_width = LCDW;
    d.lcd_height = LCDH;
    d.hmd_hfov_deg = 100.0f;
    d.hmd_vfov_deg = 106.0f;
    return d;
}

/* A head node at the origin and an unskinned quad [-s,s]^2 at depth z. */
static void quad_model(kin_model *m, float s, float z) { tu_quad_model(m, s, z, 0.4f, "quad"); }

/* Eq. 1-4 for vr_desc, from the equations (docs/kin.md). */
static void geometry_numbers(void **state)
{
    (void)state;
    kin_sthmd_desc d = vr_desc();
    kin_sthmd_geometry g = kin_sthmd_geometry_of(&d);
    /* eq. 1: 1280 * 1600 / 1440 = 1422 rows > 720: keep the rows, crop the
     * width to 720 * 1440 / 1600 = 648, centred at (1280 - 648) / 2 */
    assert_int_equal(g.crop_width, 648);
    assert_int_equal(g.crop_height, 720);
    assert_int_equal(g.crop_x0, 316);
    assert_int_equal(g.crop_y0, 0);
    /* eq. 2 with the crop's horizontal FOV */
    double f = 0.5 * CAMW / tan(50.0 * D2R);
    double hfov_crop = 2.0 * atan(324.0 / f);
    double w1 = 2.0 * 1000.0 * tan(50.0 * D2R), w2 = 2.0 * (1000.0 - 70.0) * tan(0.5 * hfov_crop);
    NEAR(g.w1_mm, w1, 1e-9);
    NEAR(g.w2_mm, w2, 1e-6);
    NEAR(g.ratio, w2 / w1, 1e-9);
    /* eq. 4 */
    assert_int_equal(g.vp_width, (int)floor(LCDW * w2 / w1));
    assert_int_equal(g.vp_height, (int)floor(LCDH * w2 / w1));
    assert_int_equal(g.vp_x0, (LCDW - g.vp_width) / 2);
    assert_int_equal(g.vp_y0, (LCDH - g.vp_height) / 2);
    print_message("NOTE 1440x1600 / 1280x720 at 100 deg: crop %dx%d at (%d, %d), W1 %.1f mm, "
                  "W2 %.1f mm, ratio %.4f, viewport %dx%d at (%d, %d)\n", g.crop_width,
                  g.crop_height, g.crop_x0, g.crop_y0, g.w1_mm, g.w2_mm, g.ratio, g.vp_width,
                  g.vp_height, g.vp_x0, g.vp_y0);
    assert_int_equal(g.vp_width, 677);
    assert_int_equal(g.vp_height, 753);
    NEAR(g.crop_vfov_deg, 2.0 * atan(360.0 / f) / D2R, 1e-4);
    /* the paper's HMD keeps its numbers (and no column crop) */
    kin_sthmd_geometry p = kin_sthmd_geometry_of(NULL);
    assert_int_equal(p.crop_x0, 0);
    assert_int_equal(p.crop_width, 640);
    assert_int_equal(p.vp_width, 1194);
    /* a 16:9 camera on the 1.6 LCD: all 360 rows, 576 columns */
    kin_sthmd_desc w;
    memset(&w, 0, sizeof w);
    w.cam_width = 640;
    w.cam_height = 360;
    g = kin_sthmd_geometry_of(&w);
    assert_int_equal(g.crop_width, 576);
    assert_int_equal(g.crop_height, 360);
    assert_int_equal(g.crop_x0, 32);
}

/* Cameras at +-baseline/2 and D in front, eyes at +-ipd/2; the principal
 * point is the sensor's centre in the crop. */
static void cameras_and_eyes(void **state)
{
    (void)state;
    kin_sthmd_desc d = vr_desc();
    kin_sthmd_desc r = kin_sthmd_desc_resolved(&d);
    NEAR(r.ipd_m, 0.068f, 0);
    NEAR(r.baseline_m, 0.064f, 0);
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0.1f, 1.2f, -0.2f), kin_quat_identity());
    for (int e = 0; e < 2; e++) {
        float s = e ? 1.0f : -1.0f;
        kin_camera c = kin_sthmd_camera(&d, &head, (kin_eye)e);
        NEAR(c.world_from_cam.m[12], 0.1f + s * 0.032f, 1e-6);
        NEAR(c.world_from_cam.m[13], 1.2f, 1e-6);
        NEAR(c.world_from_cam.m[14], -0.2f - 0.07f, 1e-6);
        assert_int_equal(c.width, 648);
        assert_int_equal(c.height, 720);
        NEAR(c.cx, 324.0f, 0);
        NEAR(c.cy, 360.0f, 0);
        kin_mat4 eye = kin_sthmd_eye(&d, &head, (kin_eye)e);
        NEAR(eye.m[12], 0.1f + s * 0.034f, 1e-6);
        NEAR(eye.m[13], 1.2f, 1e-6);
        NEAR(eye.m[14], -0.2f, 1e-6);
    }
    /* ipd 0: the baseline, for the cameras and the eyes alike */
    d.ipd_m = 0.0f;
    r = kin_sthmd_desc_resolved(&d);
    NEAR(r.ipd_m, 0.064f, 0);
    kin_mat4 eye = kin_sthmd_eye(&d, NULL, KIN_EYE_RIGHT);
    NEAR(eye.m[12], 0.032f, 0);
    r = kin_sthmd_desc_resolved(NULL);
    NEAR(r.ipd_m, 0.065f, 0);
}

typedef tu_frame_bufs bufs;

static void bufs_make(bufs *b, pipe_frame_in *in, uint64_t seed)
{
    tu_frame_make(b, in, seed, CAMW, CAMH, LCDW, LCDH);
}

static void bufs_free(bufs *b) { tu_frame_free(b); }

/* pipe_frame with vr_desc equals its stages called by hand. */
static void frame_end_to_end(void **state)
{
    (void)state;
    pipe_desc pd = {0};
    pd.hmd = vr_desc();
    pd.threads = 1;
    tu_quad_rig r;
    tu_quad_rig_open(&r, 0.12f, -0.45f, 0.4f, &pd, 3, CAMW, CAMH, LCDW, LCDH);
    kin_sthmd_desc hd = pipe_hmd(r.p);
    assert_int_equal(hd.lcd_width, LCDW);
    assert_int_equal(hd.cam_height, CAMH);
    NEAR(hd.ipd_m, 0.068f, 0);
    const kin_sthmd_geometry g = pipe_geometry(r.p);
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0.01f, -0.02f, 0.0f),
                                     kin_quat_axis_angle(kin_v3(0, 1, 0), 0.08f));
    pipe_frame_stats st;
    tu_quad_rig_run(&r, &head, &st);
    assert_true(st.coverage[0] > 0.02 && st.coverage[0] < 0.6);

    /* the crop: rows 0..719, columns 316..963 */
    const int crop[4] = {316, 0, 648, 720};
    const int vp[4] = {g.vp_x0, g.vp_y0, g.vp_width, g.vp_height};
    tu_quad_frame_equals_stages(r.p, &r.m, &r.b, &pd.hmd, &head, CAMW, crop, LCDW, LCDH, vp);
    for (int e = 0; e < 2; e++) {
        /* outside the viewport: V */
        for (int y = 0; y < LCDH; y++)
            for (int x = 0; x < LCDW; x++) {
                if (x >= g.vp_x0 && x < g.vp_x0 + g.vp_width && y >= g.vp_y0 &&
                    y < g.vp_y0 + g.vp_height)
                    continue;
                size_t o = ((size_t)y * LCDW + (size_t)x) * 4;
                if (memcmp(r.b.out[e] + o, r.b.virt[e] + o, 4))
                    fail_msg("eye %d pixel (%d, %d) outside the viewport is not V's", e, x, y);
            }
    }

    /* the paper's sizes are refused, naming the expected ones */
    char why[300];
    pipe_frame_in bad = r.in;
    uint8_t *small = calloc(640 * 480, 4);
    bad.camera[1] = (fuse_image){small, 640, 480, 640 * 4};
    assert_int_equal(pipe_frame(r.p, &bad, NULL, why, sizeof why), PIPE_ERR_ARGS);
    assert_non_null(strstr(why, "right eye: the camera image is 640x480"));
    assert_non_null(strstr(why, "expected 1280x720"));
    bad = r.in;
    bad.out[0] = (fuse_image){small, 1280, 240, 1280 * 4};
    assert_int_equal(pipe_frame(r.p, &bad, NULL, why, sizeof why), PIPE_ERR_ARGS);
    assert_non_null(strstr(why, "expected 1440x1600"));
    free(small);
    tu_quad_rig_close(&r);
}

/* Raw YUYV 1280x720 frames give the bytes of their RGBA conversion, with
 * one and two threads; with the refinement as well (its scratch is sized
 * by the crop). */
static void raw_and_threads(void **state)
{
    (void)state;
    kin_model m;
    quad_model(&m, 0.1f, -0.4f);
    tu_rng r = {9};
    uint8_t *yuyv[2];
    uint32_t crc[2][2] = {{0, 0}, {0, 0}};
    tu_yuyv_frames(yuyv, CAMW, CAMH, &r);
    for (int refine = 0; refine < 2; refine++)
        for (int th = 1; th <= 2; th++) {
            pipe_desc pd = {0};
            pd.hmd = vr_desc();
            pd.threads = th;
            pd.refine_band = refine ? 12 : 0;
            pipe_ctx *p = pipe_create(&pd, &m);
            assert_non_null(p);
            bufs b, c;
            pipe_frame_in in, ref;
            bufs_make(&b, &in, 17);
            bufs_make(&c, &ref, 17);
            tu_raw_cameras(&in, yuyv, CAMW, CAMH, &c);
            char why[300];
            if (pipe_frame(p, &ref, NULL, why, sizeof why) != PIPE_OK) fail_msg("%s", why);
            if (pipe_frame(p, &in, NULL, why, sizeof why) != PIPE_OK) fail_msg("%s", why);
            for (int e = 0; e < 2; e++) {
                assert_memory_equal(b.out[e], c.out[e], (size_t)LCDW * LCDH * 4);
                crc[refine][th - 1] = tu_crc32(crc[refine][th - 1], b.out[e], (size_t)LCDW * LCDH * 4);
            }
            bufs_free(&b);
            bufs_free(&c);
            pipe_destroy(p);
        }
    assert_int_equal(crc[0][0], crc[0][1]);
    assert_int_equal(crc[1][0], crc[1][1]);
    for (int e = 0; e < 2; e++) free(yuyv[e]);
    kin_model_free(&m);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(geometry_numbers),
        cmocka_unit_test(cameras_and_eyes),
        cmocka_unit_test(frame_end_to_end),
        cmocka_unit_test(raw_and_threads))
