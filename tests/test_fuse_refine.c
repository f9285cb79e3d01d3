/* test_fuse_refine.c - the skin-colour key (colours on either side of the
 * model's ellipse, worked out by hand) and the edge-band refinement: a
 * noisy skin-coloured disc on a two-colour textured background, refined
 * from a kinematic mask that is displaced, too small or too large; the
 * refined mask must come back to the true disc (IoU and boundary F
 * measured with fuse_metrics), and the refinement must leave the mask
 * alone when the colours cannot tell hand from background. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse_metrics.h"
#include "../src/fuse/fuse_refine.h"

enum { W = 160, H = 120 };

static void set_px(uint8_t *img, int x, int y, int r, int g, int b)
{
    uint8_t *p = img + ((size_t)y * W + (size_t)x) * 4;
    p[0] = (uint8_t)(r < 0 ? 0 : r > 255 ? 255 : r);
    p[1] = (uint8_t)(g < 0 ? 0 : g > 255 ? 255 : g);
    p[2] = (uint8_t)(b < 0 ? 0 : b > 255 ? 255 : b);
    p[3] = 255;
}

static void test_skin_key(void **state)
{
    (void)state;
    fuse_skin_params sp = fuse_skin_params_default();
    uint8_t img[4 * 4], out[4];
    fuse_image P = { img, 4, 1, 16 };
    /* the model's mean chroma at Y = 150 (inverse BT.601): skin */
    float Y = 150.0f, cb = sp.mean_cb - 128.0f, cr = sp.mean_cr - 128.0f;
    int r = (int)lroundf(Y + 1.402f * cr);
    int g = (int)lroundf(Y - 0.344136f * cb - 0.714136f * cr);
    int b = (int)lroundf(Y + 1.772f * cb);
    uint8_t px[4][3] = {
        { (uint8_t)r, (uint8_t)g, (uint8_t)b },
        { 40, 60, 200 },     /* blue: Cb far above the mean */
        { 128, 128, 128 },   /* grey: squared distance 3.4 > 2.5 */
        { 20, 12, 10 },      /* skin chroma but too dark (Y < 40) */
    };
    for (int i = 0; i < 4; i++) {
        img[4 * i] = px[i][0];
        img[4 * i + 1] = px[i][1];
        img[4 * i + 2] = px[i][2];
        img[4 * i + 3] = 0;
    }
    assert_int_equal(fuse_skin_key(&sp, &P, out, 4), FUSE_OK);
    assert_int_equal(out[0], 255);
    assert_int_equal(out[1], 0);
    assert_int_equal(out[2], 0);
    assert_int_equal(out[3], 0);
    /* a wider threshold takes the grey in */
    sp.max_dist2 = 4.0f;
    assert_int_equal(fuse_skin_key(&sp, &P, out, 4), FUSE_OK);
    assert_int_equal(out[2], 255);
    sp.cov[1] = 1000.0f;   /* not positive definite */
    assert_int_equal(fuse_skin_key(&sp, &P, out, 4), FUSE_ERR_ARGS);
    sp = fuse_skin_params_default();
    assert_int_equal(fuse_skin_key(&sp, &P, out, 3), FUSE_ERR_ARGS);
}

/* A noisy skin disc of radius R at (cx, cy) over stripes of blue-grey and
 * dark green; truth = the disc. */
static void scene(uint8_t *img, uint8_t *truth, float cx, float cy, float R,
                  uint64_t seed)
{
    tu_rng rng = { seed };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float dx = (float)x + 0.5f - cx, dy = (float)y + 0.5f - cy;
            int in = dx * dx + dy * dy <= R * R;
            int n = tu_int(&rng, 13) - 6;
            if (in) set_px(img, x, y, 210 + n, 150 + n, 125 + n);
            else if ((x / 7 + y / 5) & 1) set_px(img, x, y, 90 + n, 100 + n, 120 + n);
            else set_px(img, x, y, 40 + n, 80 + n, 50 + n);
            truth[y * W + x] = in ? 255 : 0;
        }
}

static void disc(uint8_t *m, float cx, float cy, float R)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float dx = (float)x + 0.5f - cx, dy = (float)y + 0.5f - cy;
            m[y * W + x] = dx * dx + dy * dy <= R * R ? 255 : 0;
        }
}

static double iou(const uint8_t *a, const uint8_t *b)
{
    fuse_confusion c;
    assert_int_equal(fuse_mask_confusion(a, W, b, W, W, H, &c), 0);
    return fuse_confusion_iou(&c);
}

static void test_refine_recovers_disc(void **state)
{
    (void)state;
    uint8_t *img = malloc(4 * W * H), *truth = malloc(W * H), *km = malloc(W * H);
    uint8_t *out = malloc(W * H);
    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = 5;   /* the kinematic errors here are <= 3.6 px */
    size_t ss = fuse_refine_scratch_size(&rp, W, H);
    assert_true(ss > 0);
    void *scratch = aligned_alloc(16, (ss + 15) & ~(size_t)15);
    assert_non_null(scratch);
    fuse_image P = { img, W, H, 4 * W };
    /* kinematic errors: shifted by (3, -2), 3 px too small, 3 px too big */
    const float err[3][3] = { { 3.0f, -2.0f, 0.0f }, { 0, 0, -3.0f }, { 0, 0, 3.0f } };
    for (int k = 0; k < 3; k++) {
        scene(img, truth, 80.3f, 61.7f, 30.0f, 11u + (uint64_t)k);
        disc(km, 80.3f + err[k][0], 61.7f + err[k][1], 30.0f + err[k][2]);
        fuse_refine_stats st;
        assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss, &st), FUSE_OK);
        assert_int_equal(st.used_colour, 1);
        assert_true(st.band_pixels > 0);
        double before = iou(km, truth), after = iou(out, truth);
        double bf_before = fuse_boundary_f(km, W, truth, W, W, H, 1.0f, NULL, NULL);
        double bf_after = fuse_boundary_f(out, W, truth, W, W, H, 1.0f, NULL, NULL);
        print_message("case %d: IoU %.4f -> %.4f, BF1 %.3f -> %.3f\n", k, before,
                      after, bf_before, bf_after);
        assert_true(before < 0.9);
        assert_true(after > 0.99);
        assert_true(bf_after > 0.95);
        assert_true(bf_before < 0.5);
    }
    free(scratch);
    free(img);
    free(truth);
    free(km);
    free(out);
}

/* One colour everywhere: the colour model cannot decide, the prior keeps
 * the mask exactly. Too few samples: the mask is returned as it is. */
static void test_refine_keeps_mask(void **state)
{
    (void)state;
    uint8_t *img = malloc(4 * W * H), *km = malloc(W * H), *out = malloc(W * H);
    fuse_refine_params rp = fuse_refine_params_default();
    size_t ss = fuse_refine_scratch_size(&rp, W, H);
    void *scratch = aligned_alloc(16, (ss + 15) & ~(size_t)15);
    assert_non_null(scratch);
    fuse_image P = { img, W, H, 4 * W };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) set_px(img, x, y, 200, 150, 120);
    disc(km, 70.0f, 60.0f, 25.0f);
    fuse_refine_stats st;
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss, &st), FUSE_OK);
    assert_int_equal(st.used_colour, 1);
    assert_memory_equal(out, km, W * H);
    assert_int_equal(st.flipped_in + st.flipped_out, 0);
    /* a tiny disc: the hand histogram is too small */
    disc(km, 70.0f, 60.0f, 2.0f);
    rp.min_samples = 1000;
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss, &st), FUSE_OK);
    assert_int_equal(st.used_colour, 0);
    assert_memory_equal(out, km, W * H);
    /* argument checks */
    rp = fuse_refine_params_default();
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss - 1, &st),
                     FUSE_ERR_ARGS);
    rp.band = 0;
    assert_int_equal(fuse_refine_scratch_size(&rp, W, H), 0);
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss, &st),
                     FUSE_ERR_ARGS);
    rp = fuse_refine_params_default();
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W - 1, out, W, scratch, ss, &st),
                     FUSE_ERR_ARGS);
    free(scratch);
    free(img);
    free(km);
    free(out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_skin_key),
        cmocka_unit_test(test_refine_recovers_disc),
        cmocka_unit_test(test_refine_keeps_mask),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
