/* test_kin_hmd.c - the named HMDs (kin_sthmd_preset) and the generalised
 * crop of eq. 1 (docs/kin.md):
 *   - the presets: "paper" resolves to exactly the defaults (the same
 *     geometry bytes as kin_sthmd_geometry_of(NULL), so the pipeline's
 *     outputs for the paper's HMD cannot change), unknown names refused;
 *   - eq. 1-4 of the three HMDs, recomputed here from the equations: the
 *     paper's 640x400 / 1194x746 unchanged; the consumer one (1280x1024
 *     cameras, 2064x2208 per eye: taller than wide) and the high-end one
 *     (1920x1080, 2880x2720) crop the camera's width, the crop inside the
 *     sensor, the viewport inside the display;
 *   - 2000 seeded random sensor / display sizes: the crop keeps one whole
 *     side, cuts the other centred to the display's aspect (nearest
 *     pixel, at least 1), and stays inside the sensor;
 *   - a small portrait HMD (160x128 cameras, 172x184 per eye, the
 *     consumer one's FOVs) through pipe_frame: the bytes of the stages
 *     called by hand on columns 20..139 of the sensor and the viewport,
 *     V outside the viewport, the same bytes with two threads. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe.h"
#include "support/pipe_frames.h"
#include "../src/cpu/ef_mem.h"

#define D2R 0.017453292519943295

/* Eq. 1-4 recomputed in double from the desc (docs/kin.md). */
typedef struct expect_geo {
    int cw, ch, x0, y0, vw, vh, vx, vy;
    double w1, w2, ratio;
} expect_geo;

static expect_geo expect_of(const kin_sthmd_desc *d)
{
    expect_geo g;
    double H = (double)d->cam_width * d->lcd_height / d->lcd_width;
    if (floor(H + 0.5) <= d->cam_height) {
        g.cw = d->cam_width;
        g.ch = (int)floor(H + 0.5);
    } else {
        g.ch = d->cam_height;
        g.cw = (int)floor((double)d->cam_height * d->lcd_width / d->lcd_height + 0.5);
    }
    g.x0 = (d->cam_width - g.cw) / 2;
    g.y0 = (d->cam_height - g.ch) / 2;
    double fx = 0.5 * d->cam_width / tan(0.5 * d->cam_hfov_deg * D2R);
    g.w1 = 2.0 * 1000.0 * d->focal_m * tan(0.5 * d->hmd_hfov_deg * D2R);
    g.w2 = 2.0 * 1000.0 * (d->focal_m - d->cam_offset_m) * (0.5 * g.cw / fx);
    g.ratio = g.w2 / g.w1;
    g.vw = (int)floor(d->lcd_width * g.ratio);
    g.vh = (int)floor(d->lcd_height * g.ratio);
    g.vx = (d->lcd_width - g.vw) / 2;
    g.vy = (d->lcd_height - g.vh) / 2;
    return g;
}

static void check_geo(const kin_sthmd_desc *d, const kin_sthmd_geometry *g)
{
    expect_geo e = expect_of(d);
    assert_int_equal(g->crop_width, e.cw);
    assert_int_equal(g->crop_height, e.ch);
    assert_int_equal(g->crop_x0, e.x0);
    assert_int_equal(g->crop_y0, e.y0);
    NEAR(g->w1_mm, e.w1, 1e-6);
    NEAR(g->w2_mm, e.w2, 1e-3);
    NEAR(g->ratio, e.ratio, 1e-6);
    assert_int_equal(g->vp_width, e.vw);
    assert_int_equal(g->vp_height, e.vh);
    assert_int_equal(g->vp_x0, e.vx);
    assert_int_equal(g->vp_y0, e.vy);
    /* the crop inside the sensor, the viewport inside the display */
    assert_true(g->crop_x0 >= 0 && g->crop_x0 + g->crop_width <= d->cam_width);
    assert_true(g->crop_y0 >= 0 && g->crop_y0 + g->crop_height <= d->cam_height);
    assert_true(g->vp_x0 >= 0 && g->vp_x0 + g->vp_width <= d->lcd_width);
    assert_true(g->vp_y0 >= 0 && g->vp_y0 + g->vp_height <= d->lcd_height);
}

static void presets(void **state)
{
    (void)state;
    const char *want[] = {"paper", "consumer", "highend"};
    int n = 0;
    while (kin_sthmd_preset_name(n)) {
        assert_true(n < 3);
        assert_string_equal(kin_sthmd_preset_name(n), want[n]);
        n++;
    }
    assert_int_equal(n, 3);
    assert_null(kin_sthmd_preset_name(-1));
    kin_sthmd_desc d, keep;
    memset(&keep, 0x5A, sizeof keep);
    d = keep;
    assert_int_equal(kin_sthmd_preset("quest", &d), -1);
    assert_int_equal(kin_sthmd_preset(NULL, &d), -1);
    assert_int_equal(kin_sthmd_preset("Paper", &d), -1);
    assert_memory_equal(&d, &keep, sizeof d);
    /* "paper" is the defaults, field by field, and gives the same bytes */
    assert_int_equal(kin_sthmd_preset("paper", &d), 0);
    kin_sthmd_desc r = kin_sthmd_desc_resolved(NULL);
    assert_memory_equal(&d, &r, sizeof d);
    kin_sthmd_desc rd = kin_sthmd_desc_resolved(&d);
    assert_memory_equal(&rd, &r, sizeof rd);
    kin_sthmd_geometry a = kin_sthmd_geometry_of(&d), b = kin_sthmd_geometry_of(NULL);
    assert_memory_equal(&a, &b, sizeof a);
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0.1f, 1.5f, 0.2f), kin_quat_axis_angle(kin_v3(0, 1, 0), 0.3f));
    for (int e = 0; e < 2; e++) {
        kin_camera c1 = kin_sthmd_camera(&d, &head, (kin_eye)e);
        kin_camera c2 = kin_sthmd_camera(NULL, &head, (kin_eye)e);
        assert_memory_equal(&c1, &c2, sizeof c1);
    }
    /* every preset is fully set: resolving changes nothing */
    for (int i = 0; i < n; i++) {
        assert_int_equal(kin_sthmd_preset(kin_sthmd_preset_name(i), &d), 0);
        rd = kin_sthmd_desc_resolved(&d);
        assert_memory_equal(&rd, &d, sizeof d);
    }
}

/* The preset `name` into *d and its geometry: check_geo, then the figures
 * quoted in docs/kin.md, want = crop width, height, x0, y0, viewport
 * width, height, x0, y0; note: printed as a NOTE. */
static kin_sthmd_geometry preset_geo(const char *name, kin_sthmd_desc *d, const int want[8],
                                     int note)
{
    assert_int_equal(kin_sthmd_preset(name, d), 0);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(d);
    check_geo(d, &g);
    const int got[8] = {g.crop_width, g.crop_height, g.crop_x0, g.crop_y0,
                        g.vp_width,   g.vp_height,   g.vp_x0,   g.vp_y0};
    static const char *const what[8] = {"crop_width", "crop_height", "crop_x0", "crop_y0",
                                        "vp_width",   "vp_height",   "vp_x0",   "vp_y0"};
    for (int i = 0; i < 8; i++)
        if (got[i] != want[i]) fail_msg("%s: %s = %d, expected %d", name, what[i], got[i], want[i]);
    if (note)
        print_message("NOTE %s: crop %dx%d at (%d, %d), W1 %.1f mm, W2 %.1f mm, ratio %.4f, "
                      "viewport %dx%d at (%d, %d)\n", name, g.crop_width, g.crop_height,
                      g.crop_x0, g.crop_y0, g.w1_mm, g.w2_mm, g.ratio, g.vp_width, g.vp_height,
                      g.vp_x0, g.vp_y0);
    return g;
}

/* The geometry of d with a display lw x lh and cameras cw x ch. */
static kin_sthmd_geometry sized_geo(kin_sthmd_desc *d, int lw, int lh, int cw, int ch)
{
    d->lcd_width = lw;
    d->lcd_height = lh;
    d->cam_width = cw;
    d->cam_height = ch;
    return kin_sthmd_geometry_of(d);
}

/* The three HMDs: eq. 1-4 from the equations, and the figures quoted in
 * docs/kin.md. */
static void three_hmds(void **state)
{
    (void)state;
    kin_sthmd_desc d;
    kin_sthmd_geometry g;
    /* the paper: keeps the width, 640 x 400 at row 40; 1194 x 746 at (43, 27) */
    g = preset_geo("paper", &d, (const int[8]){640, 400, 0, 40, 1194, 746, 43, 27}, 0);
    NEAR(g.ratio, 0.93335, 1e-5);

    /* consumer: keeping the width needs round(1280 * 2208 / 2064) = 1369
     * rows of 1024: the height is kept, the width cut to
     * round(1024 * 2064 / 2208) = 957 at column (1280 - 957) / 2 = 161 */
    g = preset_geo("consumer", &d, (const int[8]){957, 1024, 161, 0, 1539, 1647, 262, 280}, 1);
    assert_true(d.lcd_height > d.lcd_width);
    /* the camera images the crop; its principal point is the sensor's centre */
    kin_camera c = kin_sthmd_camera(&d, NULL, KIN_EYE_LEFT);
    assert_int_equal(c.width, 957);
    assert_int_equal(c.height, 1024);
    NEAR(c.cx, 640.0f - 161.0f, 0);
    NEAR(c.cy, 512.0f, 0);
    NEAR(c.fx, 640.0 / tan(50.0 * D2R), 1e-3);

    /* high-end: round(1920 * 2720 / 2880) = 1813 rows of 1080: the width is
     * cut to round(1080 * 2880 / 2720) = 1144 at column 388 */
    g = preset_geo("highend", &d, (const int[8]){1144, 1080, 388, 0, 1891, 1786, 494, 467}, 1);

    /* the same consumer display held landscape (2208x2064): the height is
     * cut instead, round(1280 * 2064 / 2208) = 1197 > 1024 still: width */
    g = sized_geo(&d, 2208, 2064, 1280, 1024);
    assert_int_equal(g.crop_height, 1024);
    assert_int_equal(g.crop_width, 1095);
    /* a 4:3 camera on a 16:9 display: the height is cut */
    g = sized_geo(&d, 1920, 1080, 1280, 960);
    assert_int_equal(g.crop_width, 1280);
    assert_int_equal(g.crop_height, 720);
    assert_int_equal(g.crop_y0, 120);
    assert_int_equal(g.crop_x0, 0);
}

/* Random sensors and displays: one whole side kept, the other cut to the
 * display's aspect (nearest pixel), centred, inside the sensor. */
static void crop_rule_random(void **state)
{
    (void)state;
    tu_rng r = {2026};
    int cut_w = 0, cut_h = 0;
    for (int i = 0; i < 2000; i++) {
        kin_sthmd_desc d;
        memset(&d, 0, sizeof d);
        d.cam_width = 16 + tu_int(&r, 4000);
        d.cam_height = 16 + tu_int(&r, 4000);
        d.lcd_width = 16 + tu_int(&r, 4000);
        d.lcd_height = 16 + tu_int(&r, 4000);
        kin_sthmd_geometry g = kin_sthmd_geometry_of(&d);
        assert_true(g.crop_width >= 1 && g.crop_height >= 1);
        assert_true(g.crop_x0 >= 0 && g.crop_x0 + g.crop_width <= d.cam_width);
        assert_true(g.crop_y0 >= 0 && g.crop_y0 + g.crop_height <= d.cam_height);
        assert_int_equal(g.crop_x0, (d.cam_width - g.crop_width) / 2);
        assert_int_equal(g.crop_y0, (d.cam_height - g.crop_height) / 2);
        const double h = (double)d.cam_width * d.lcd_height / d.lcd_width;
        if (floor(h + 0.5) <= d.cam_height) {
            /* the width kept, the height the nearest row to the aspect */
            assert_int_equal(g.crop_width, d.cam_width);
            /* (at least one row: a display 200 times wider than tall) */
            const int hr = h < 0.5 ? 1 : (int)floor(h + 0.5);
            if (g.crop_height != hr)
                fail_msg("cam %dx%d lcd %dx%d: crop %dx%d, h %.3f", d.cam_width, d.cam_height,
                         d.lcd_width, d.lcd_height, g.crop_width, g.crop_height, h);
            cut_h += g.crop_height < d.cam_height;
        } else {
            /* the height kept, the width the nearest column to the aspect */
            assert_int_equal(g.crop_height, d.cam_height);
            const double w = (double)d.cam_height * d.lcd_width / d.lcd_height;
            const int wr = w < 0.5 ? 1 : (int)floor(w + 0.5);
            assert_int_equal(g.crop_width, wr < d.cam_width ? wr : d.cam_width);
            cut_w++;
        }
    }
    assert_true(cut_w > 500 && cut_h > 500);
}

/* --------------------------------------- a small portrait HMD end to end */

enum { CAMW = 160, CAMH = 128, LCDW = 172, LCDH = 184 };

static kin_sthmd_desc small_desc(void)
{
    kin_sthmd_desc d;
    assert_int_equal(kin_sthmd_preset("consumer", &d), 0);
    d.cam_width = CAMW;
    d.cam_height = CAMH;
    d.lcd_width = LCDW;
    d.lcd_height = LCDH;
    return d;
}

/* A head node at the origin and an unskinned quad [-s,s]^2 at depth z,
 * turned about +Y. */
static void quad_model(kin_model *m, float s, float z) { tu_quad_model(m, s, z, 0.3f, "quad"); }

static void small_portrait_frame(void **state)
{
    (void)state;
    kin_model m;
    quad_model(&m, 0.1f, -0.35f);
    const kin_sthmd_desc hd = small_desc();
    const kin_sthmd_geometry g = kin_sthmd_geometry_of(&hd);
    /* round(160 * 184 / 172) = 171 > 128 rows: 128 rows, 120 columns at 20 */
    assert_int_equal(g.crop_width, 120);
    assert_int_equal(g.crop_height, 128);
    assert_int_equal(g.crop_x0, 20);
    check_geo(&hd, &g);

    tu_rng r = {77};
    uint8_t *cam[2], *virt[2], *out[2][2];
    for (int e = 0; e < 2; e++) {
        cam[e] = malloc((size_t)CAMW * CAMH * 4);
        virt[e] = malloc((size_t)LCDW * LCDH * 4);
        assert_non_null(cam[e]);
        assert_non_null(virt[e]);
        for (size_t i = 0; i < (size_t)CAMW * CAMH * 4; i++) cam[e][i] = (uint8_t)tu_next(&r);
        for (size_t i = 0; i < (size_t)LCDW * LCDH * 4; i++) virt[e][i] = (uint8_t)tu_next(&r);
    }
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0.005f, 0.01f, 0.0f),
                                     kin_quat_axis_angle(kin_v3(1, 0, 0), 0.05f));
    for (int th = 1; th <= 2; th++) {
        pipe_desc pd = {0};
        pd.hmd = hd;
        pd.threads = th;
        pipe_ctx *p = pipe_create(&pd, &m);
        assert_non_null(p);
        pipe_frame_in in;
        memset(&in, 0, sizeof in);
        for (int e = 0; e < 2; e++) {
            out[th - 1][e] = malloc((size_t)LCDW * LCDH * 4);
            assert_non_null(out[th - 1][e]);
            memset(out[th - 1][e], 0xCD, (size_t)LCDW * LCDH * 4);
            in.camera[e] = (fuse_image){cam[e], CAMW, CAMH, CAMW * 4};
            in.virt[e] = (fuse_image){virt[e], LCDW, LCDH, LCDW * 4};
            in.out[e] = (fuse_image){out[th - 1][e], LCDW, LCDH, LCDW * 4};
        }
        in.head_node = -1;
        in.world_from_head = &head;
        in.lighting = pipe_lighting_default();
        pipe_frame_stats st;
        char why[300] = "";
        if (pipe_frame(p, &in, &st, why, sizeof why) != PIPE_OK) fail_msg("pipe_frame: %s", why);
        for (int e = 0; e < 2; e++)
            assert_true(st.coverage[e] > 0.05 && st.coverage[e] < 0.8);
        pipe_destroy(p);
    }
    /* two threads: the same bytes */
    for (int e = 0; e < 2; e++)
        assert_memory_equal(out[0][e], out[1][e], (size_t)LCDW * LCDH * 4);

    /* the stages by hand on the crop (columns 20..139) and the viewport */
    const int cw = g.crop_width, ch = g.crop_height;
    tu_stages s;
    tu_stages_make(&s, cw, ch);
    uint8_t *expect = malloc((size_t)LCDW * LCDH * 4);
    assert_non_null(expect);
    for (int e = 0; e < 2; e++) {
        kin_camera c = kin_sthmd_camera(&hd, &head, (kin_eye)e);
        assert_int_equal(c.width, cw);
        assert_int_equal(c.height, ch);
        fuse_image P = {cam[e] + 20 * 4, cw, ch, CAMW * 4};
        fuse_image V = {virt[e], LCDW, LCDH, LCDW * 4};
        fuse_image R = {expect, LCDW, LCDH, LCDW * 4};
        tu_quad_stages(&m, &c, &s, &P, &V, g.vp_x0, g.vp_y0, g.vp_width, g.vp_height, &R);
        assert_memory_equal(expect, out[0][e], (size_t)LCDW * LCDH * 4);
        long differs = 0;
        for (int y = 0; y < LCDH; y++)
            for (int x = 0; x < LCDW; x++) {
                size_t o = ((size_t)y * LCDW + (size_t)x) * 4;
                int in_vp = x >= g.vp_x0 && x < g.vp_x0 + g.vp_width && y >= g.vp_y0 &&
                            y < g.vp_y0 + g.vp_height;
                int same = !memcmp(out[0][e] + o, virt[e] + o, 4);
                if (!in_vp && !same)
                    fail_msg("eye %d pixel (%d, %d) outside the viewport is not V's", e, x, y);
                differs += !same;
            }
        /* the hand is in the output */
        assert_true(differs > (long)(0.05 * g.vp_width * g.vp_height));
    }
    tu_stages_free(&s);
    free(expect);
    for (int e = 0; e < 2; e++) {
        EF_FREE_ALL(cam[e], virt[e], out[0][e], out[1][e]);
    }
    kin_model_free(&m);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(presets),
        cmocka_unit_test(three_hmds),
        cmocka_unit_test(crop_rule_random),
        cmocka_unit_test(small_portrait_frame))
