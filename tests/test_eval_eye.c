/* test_eval_eye.c - the eye-view evaluation (`egofuse eval --eyeview`,
 * src/eval/eval_eye.c, issue 18 item 5): its metrics and its ground truth.
 *
 *   moments_*        fuse_mask_moments / fuse_shape_compare on hand-made
 *                    masks: area, centroid (pixel centres), bounding box,
 *                    the 128 threshold, position, size and height errors of
 *                    known rectangles, the empty and too-small cases.
 *   crop_geometry_*  the ground truth of samples/gt (gt_eye.h, the
 *                    "holdNN" sequences): the middle fingertip of the true
 *                    operator held 20 (40) cm from the eyes, seen by the
 *                    true camera, cropped and scaled into the viewport as
 *                    the paper does (eq. 1-4, the pipeline's own
 *                    fuse_composite), against the same fingertip rendered
 *                    from the true eye. The crop is exact only for a plane
 *                    at F = 1 m: a point z from the eyes is z - D from the
 *                    camera, which the crop shows at (vp / crop) fc tan a,
 *                    the eye at f_eye X / z, so its size is off by
 *                    k z / (z - D) - 1 per axis, k = (vp / crop) fc /
 *                    f_eye: +56.5 % (from the areas) at 20 cm, +15.2 % at
 *                    40 cm. The metric must give that within 3 points, the
 *                    sequence must put the fingertip within 1 cm of the
 *                    distance asked, and the position error must be the
 *                    scale's: (s - 1) times the true offset from the
 *                    display's centre (within 15 %).
 *   cli_eyeview      `egofuse eval --eyeview --frames 1 --csv`: every row,
 *                    the crop's size error equal to the geometry's column
 *                    (20-40 cm), the reprojection exact with perfect
 *                    tracking (position < 2 px, size < 2 %) and its
 *                    position and size errors several times below the
 *                    crop's at 15-20 cm; no fallbacks.
 *   cli_eyeview_bad  --frames beyond the sequence (exit 2, the message),
 *                    a report folder that cannot be made (exit 1, named).
 * Seeded (the generator's fixed seed), no timings. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../samples/gt/gt.h"
#include "../samples/gt/gt_eye.h"
#include "../src/fuse/fuse.h"
#include "../src/fuse/fuse_moments.h"
#include "../src/cpu/ef_mem.h"

/* ------------------------------------------------------------ metrics */

static void rect(uint8_t *m, int stride, int x0, int y0, int w, int h, uint8_t v)
{
    for (int y = y0; y < y0 + h; y++)
        for (int x = x0; x < x0 + w; x++) m[y * stride + x] = v;
}

static void moments_known(void **state)
{
    (void)state;
    enum { W = 100, H = 80 };
    uint8_t *a = calloc(W * H, 1), *b = calloc(W * H, 1);
    assert_non_null(a);
    assert_non_null(b);
    /* 10 x 20 at (5, 7), values 128 (in); 127 around it (out) */
    rect(a, W, 4, 6, 12, 22, 127);
    rect(a, W, 5, 7, 10, 20, 128);
    fuse_moments ma;
    fuse_mask_moments(a, W, W, H, &ma);
    assert_int_equal(ma.area, 200);
    assert_true(fabs(ma.cx - 10.0) < 1e-12);
    assert_true(fabs(ma.cy - 17.0) < 1e-12);
    assert_int_equal(ma.x0, 5);
    assert_int_equal(ma.y0, 7);
    assert_int_equal(ma.x1, 14);
    assert_int_equal(ma.y1, 26);
    /* twice the size (20 x 40 at (40, 30): centre (50, 50)) */
    rect(b, W, 40, 30, 20, 40, 255);
    fuse_moments mb;
    fuse_mask_moments(b, W, W, H, &mb);
    fuse_shape_error e;
    assert_int_equal(fuse_shape_compare(&mb, &ma, 1, &e), 1);
    assert_true(fabs(e.size - 1.0) < 1e-12);
    assert_true(fabs(e.height - 1.0) < 1e-12);
    assert_true(fabs(e.pos_px - hypot(40.0, 33.0)) < 1e-9);
    assert_int_equal(fuse_shape_compare(&ma, &mb, 1, &e), 1);
    assert_true(fabs(e.size + 0.5) < 1e-12);
    assert_true(fabs(e.height + 0.5) < 1e-12);
    /* a single pixel: centre (x + 0.5, y + 0.5) */
    memset(a, 0, W * H);
    a[3 * W + 2] = 255;
    fuse_mask_moments(a, W, W, H, &ma);
    assert_int_equal(ma.area, 1);
    assert_true(ma.cx == 2.5 && ma.cy == 3.5);
    /* too small or empty: nothing to compare */
    assert_int_equal(fuse_shape_compare(&ma, &mb, 2, &e), 0);
    assert_true(e.pos_px == 0.0 && e.size == 0.0);
    memset(a, 0, W * H);
    fuse_mask_moments(a, W, W, H, &ma);
    assert_int_equal(ma.area, 0);
    assert_int_equal(fuse_shape_compare(&ma, &mb, 1, &e), 0);
    fuse_mask_moments(NULL, W, W, H, &ma);
    assert_int_equal(ma.area, 0);
    free(a);
    free(b);
}

/* ------------------------------------------------- crop vs the eye */

typedef struct world {
    gen_arms mask, truth;
    gen_scene cockpit, workshop;
    gen_frame_ctx g;
    uint32_t *tip;
    int ntri;
} world;

static int world_init(world *w, int cm)
{
    memset(w, 0, sizeof *w);
    gt_operator_desc same = { 1, 1, 1, 1, 1, 1, 1, 0 };
    char seq[16];
    snprintf(seq, sizeof seq, "hold%d", cm);
    if (gen_arms_build(&w->mask) < 0 || gt_truth_build(&w->mask, &same, &w->truth) < 0 ||
        gt_cockpit_build(&w->cockpit) < 0 || gen_scene_workshop(&w->workshop, &w->mask) < 0 ||
        gt_sequence_build(&w->mask, seq, &w->truth) < 0 ||
        gen_frame_ctx_init(&w->g, &w->truth, &w->cockpit, &w->workshop, 1) < 0)
        return -1;
    w->tip = gt_part_triangles(&w->truth, 2u, GEN_J_MIDDLE_3, GEN_J_MIDDLE_3, &w->ntri);
    return w->tip ? 0 : -1;
}

static void world_free(world *w)
{
    free(w->tip);
    gen_frame_ctx_free(&w->g);
    gen_arms_free(&w->truth);
    gen_arms_free(&w->mask);
    gen_scene_free(&w->cockpit);
    gen_scene_free(&w->workshop);
}

/* The crop's display mask of a camera-space mask: a premultiplied white
 * layer composited into the viewport over opaque black (the pipeline's
 * resampling), >= 128. */
static void crop_display(const kin_sthmd_geometry *g, const uint8_t *m, int cw, int ch,
                         uint8_t *out, int dw, int dh)
{
    uint8_t *q = malloc((size_t)cw * ch * 4), *b = malloc((size_t)dw * dh * 4);
    assert_non_null(q);
    assert_non_null(b);
    for (size_t i = 0; i < (size_t)cw * ch; i++) memset(&q[i * 4], m[i], 4);
    for (size_t i = 0; i < (size_t)dw * dh; i++) {
        memset(&b[i * 4], 0, 3);
        b[i * 4 + 3] = 255;
    }
    fuse_image Q = { q, cw, ch, 4 * cw }, B = { b, dw, dh, 4 * dw };
    assert_int_equal(fuse_composite(&Q, &B, g->vp_x0, g->vp_y0, g->vp_width, g->vp_height, &B),
                     FUSE_OK);
    for (size_t i = 0; i < (size_t)dw * dh; i++) out[i] = b[i * 4] >= 128 ? 255 : 0;
    free(q);
    free(b);
}

static void crop_geometry_at(int cm, double expect_pct)
{
    world w;
    assert_int_equal(world_init(&w, cm), 0);
    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(&hd);
    const int cw = g.crop_width, ch = g.crop_height, dw = hd.lcd_width, dh = hd.lcd_height;
    uint8_t *sil = malloc((size_t)dw * dh), *tip_cam = malloc((size_t)cw * ch);
    uint8_t *tip_disp = malloc((size_t)dw * dh), *tip_eye = malloc((size_t)dw * dh);
    float *scratch = malloc(sizeof(float) * (size_t)dw * dh);
    assert_true(sil && tip_cam && tip_disp && tip_eye && scratch);
    int checked = 0;
    for (int f = 0; f < 180; f += 45) {
        kin_mat4 wfh;
        gen_pose(&w.g, (float)f / GEN_FPS, &wfh);
        for (int e = 0; e < 2; e++) {
            kin_camera cam = kin_sthmd_camera(&hd, &wfh, (kin_eye)e);
            kin_camera eye = gt_eye_camera(&hd, &wfh, (kin_eye)e);
            double zc, z;
            gt_render_view(&w.g, &cam, w.tip, w.ntri, NULL, sil, tip_cam, NULL, scratch, &zc);
            gt_render_view(&w.g, &eye, w.tip, w.ntri, NULL, sil, tip_eye, NULL, scratch, &z);
            crop_display(&g, tip_cam, cw, ch, tip_disp, dw, dh);
            /* the sequence's distance, and D between camera and eye */
            assert_true(fabs(z - 0.01 * cm) < 0.01);
            assert_true(fabs((z - zc) - hd.cam_offset_m) < 1e-3);
            /* the geometry's prediction at the fingertip's depth */
            double kx = (double)g.vp_width / cw * cam.fx / eye.fx;
            double ky = (double)g.vp_height / ch * cam.fy / eye.fy;
            double s = sqrt(kx * ky) * z / (z - hd.cam_offset_m);
            assert_true(fabs(100.0 * (s - 1.0) - expect_pct) < 1.5);
            fuse_moments mc, mt;
            fuse_mask_moments(tip_disp, dw, dw, dh, &mc);
            fuse_mask_moments(tip_eye, dw, dw, dh, &mt);
            fuse_shape_error se;
            assert_int_equal(fuse_shape_compare(&mc, &mt, 200, &se), 1);
            print_message("hold%d frame %d eye %d: depth %.4f m, size error %+.2f %% (geometry "
                          "%+.2f %%), position error %.1f px\n", cm, f, e, z, 100.0 * se.size,
                          100.0 * (s - 1.0), se.pos_px);
            assert_true(fabs(100.0 * se.size - 100.0 * (s - 1.0)) < 3.0);
            /* the crop scales about the display's centre (the camera's
             * axis maps to it): the centroid moves by (s - 1) times its
             * true offset (the scale per axis) */
            double ox = mt.cx - 0.5 * dw, oy = mt.cy - 0.5 * dh;
            double px = (kx * z / (z - hd.cam_offset_m) - 1.0) * ox;
            double py = (ky * z / (z - hd.cam_offset_m) - 1.0) * oy;
            double want = hypot(px, py);
            assert_true(fabs(se.pos_px - want) < 0.15 * want + 2.0);
            checked++;
        }
    }
    assert_int_equal(checked, 8);
    EF_FREE_ALL(sil, tip_cam, tip_disp, tip_eye, scratch);
    world_free(&w);
}

static void crop_geometry_20cm(void **state)
{
    (void)state;
    crop_geometry_at(20, 56.5);
}

static void crop_geometry_40cm(void **state)
{
    (void)state;
    crop_geometry_at(40, 15.2);
}

/* An unknown hold distance is refused; the named sequences still build. */
static void hold_names(void **state)
{
    (void)state;
    gen_arms mask, truth;
    gt_operator_desc same = { 1, 1, 1, 1, 1, 1, 1, 0 };
    assert_int_equal(gen_arms_build(&mask), 0);
    assert_int_equal(gt_truth_build(&mask, &same, &truth), 0);
    assert_int_equal(gt_sequence_build(&mask, "hold9", &truth), -1);
    assert_int_equal(gt_sequence_build(&mask, "hold61", &truth), -1);
    assert_int_equal(gt_sequence_build(&mask, "hold20x", &truth), -1);
    assert_int_equal(gt_sequence_build(&mask, "hold", &truth), -1);
    assert_int_equal(gt_sequence_build(&mask, "hold15", &truth), 0);
    assert_string_equal(truth.model.anims[0].name, "hold15");
    assert_int_equal(gt_sequence_build(&mask, "near", &truth), 0);
    gen_arms_free(&truth);
    gen_arms_free(&mask);
}

/* ------------------------------------------------ egofuse eval --eyeview */

static char out[1 << 16];

/* One row of eyeview.csv: distance, method, noise -> the fields. */
typedef struct csv_row {
    int dist;
    char method[16];
    double noise, depth, pos, size, size_abs, height, geom, iou, iou_cam, psnr, ms;
    long frames, eyes, fallbacks;
} csv_row;

static int read_csv(const char *path, csv_row *rows, int cap)
{
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    char line[512];
    int n = 0;
    if (!fgets(line, sizeof line, f)) { fclose(f); return -1; }
    while (n < cap && fgets(line, sizeof line, f)) {
        csv_row *r = &rows[n];
        if (sscanf(line, "%d,%lf,%15[^,],%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%ld,%ld,%ld",
                   &r->dist, &r->depth, r->method, &r->noise, &r->pos, &r->size, &r->size_abs,
                   &r->height, &r->geom, &r->iou, &r->iou_cam, &r->psnr, &r->ms, &r->frames,
                   &r->eyes, &r->fallbacks) != 16)
            break;
        n++;
    }
    fclose(f);
    return n;
}

static const csv_row *find(const csv_row *rows, int n, int dist, const char *method, double noise)
{
    for (int i = 0; i < n; i++)
        if (rows[i].dist == dist && !strcmp(rows[i].method, method) && rows[i].noise == noise)
            return &rows[i];
    fail_msg("eyeview.csv: no row %d cm %s %g mm", dist, method, noise);
    return NULL;
}

/* One frame per distance: every row there, the crop's size error as the
 * geometry's column, the reprojection exact with perfect tracking (the
 * model is the truth's) and several times better than the crop at 15-20
 * cm (issue 18's expectation, here a check that the two views are told
 * apart: swapping them fails). */
static void cli_eyeview(void **state)
{
    (void)state;
    char csv[512];
    tu_tmp_path("eyeview.csv", csv, sizeof csv);
    remove(csv);
    int rc = tu_runl(out, sizeof out, tu_bin(), "eval", "--eyeview", "--frames", "1", "--quiet",
                     "--csv", csv, NULL);
    if (rc != 0) fail_msg("egofuse eval --eyeview: exit %d: %s", rc, out);
    assert_non_null(strstr(out, "reproj"));
    csv_row rows[64];
    int n = read_csv(csv, rows, 64);
    assert_int_equal(n, 32);   /* 4 distances x 2 methods x 4 noise levels */
    static const int dist[] = { 15, 20, 30, 40 };
    for (int d = 0; d < 4; d++) {
        const csv_row *c = find(rows, n, dist[d], "crop", 0);
        const csv_row *r = find(rows, n, dist[d], "reproj", 0);
        print_message("%d cm: crop pos %.1f px size %+.1f %% (geometry %+.1f %%); reproj pos %.2f px "
                      "size %+.2f %%\n", dist[d], c->pos, c->size, c->geom, r->pos, r->size);
        assert_true(fabs(c->depth - dist[d]) < 1.0);
        assert_int_equal(c->eyes, 2);
        if (dist[d] >= 20) {
            assert_true(fabs(c->size - c->geom) < 3.0);
            assert_true(fabs(r->size) < 2.0);
            assert_true(r->pos < 2.0);
        }
        if (dist[d] <= 20) {
            assert_true(c->pos > 3.0 * (r->pos + 1.0));
            assert_true(c->size_abs > 3.0 * r->size_abs);
        }
        assert_int_equal(r->fallbacks, 0);
    }
    remove(csv);
}

static void cli_eyeview_bad(void **state)
{
    (void)state;
    int rc = tu_runl(out, sizeof out, tu_bin(), "eval", "--eyeview", "--frames", "181", NULL);
    assert_int_equal(rc, 2);
    assert_non_null(strstr(out, "--frames 181"));
    assert_non_null(strstr(out, "at most 180"));
    char path[512];
    tu_tmp_path("eyeview_not_a_dir", path, sizeof path);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fclose(f);
    char rep[600];
    snprintf(rep, sizeof rep, "%s/sub", path);
    rc = tu_runl(out, sizeof out, tu_bin(), "eval", "--eyeview", "--frames", "1", "--report", rep,
                 NULL);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, rep));
    remove(path);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(moments_known),
        cmocka_unit_test(hold_names),
        cmocka_unit_test(crop_geometry_20cm),
        cmocka_unit_test(crop_geometry_40cm),
        cmocka_unit_test(cli_eyeview_bad),
        cmocka_unit_test(cli_eyeview))
