/* test_fuse_metrics.c - the accuracy metrics of fuse_metrics.h on cases
 * whose answers are known in closed form: rectangles (IoU, fp, fn areas),
 * straight edges shifted by k pixels (boundary F is 1 within d >= k and 0
 * below), constant image differences (PSNR = 20 log10(255 / e)), edges
 * that move or stay (flicker), empty masks, threshold 128, strides and
 * argument checks. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse_metrics.h"

enum { W = 96, H = 64, S = 100 };   /* S: a stride larger than W */

static void fill_rect(uint8_t *m, int stride, int x0, int y0, int x1, int y1,
                      uint8_t v)
{
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) m[y * stride + x] = v;
}

static int overlap(int a0, int a1, int b0, int b1)
{
    int lo = a0 > b0 ? a0 : b0, hi = a1 < b1 ? a1 : b1;
    return hi > lo ? hi - lo : 0;
}

/* Seeded random rectangle pairs: tp, fp, fn, tn and IoU exactly. */
static void test_confusion_rectangles(void **state)
{
    (void)state;
    tu_rng r = { 7 };
    uint8_t *p = malloc(S * H), *t = malloc(W * H);
    assert_non_null(p);
    assert_non_null(t);
    for (int it = 0; it < 200; it++) {
        int ax0 = tu_int(&r, W), ax1 = ax0 + tu_int(&r, W - ax0 + 1);
        int ay0 = tu_int(&r, H), ay1 = ay0 + tu_int(&r, H - ay0 + 1);
        int bx0 = tu_int(&r, W), bx1 = bx0 + tu_int(&r, W - bx0 + 1);
        int by0 = tu_int(&r, H), by1 = by0 + tu_int(&r, H - by0 + 1);
        /* values just above and below the threshold, and padding junk */
        memset(p, 200, S * H);
        fill_rect(p, S, 0, 0, W, H, 127);
        fill_rect(p, S, ax0, ay0, ax1, ay1, 128);
        memset(t, 0, W * H);
        fill_rect(t, W, bx0, by0, bx1, by1, 255);
        long a = (long)(ax1 - ax0) * (ay1 - ay0), b = (long)(bx1 - bx0) * (by1 - by0);
        long i = (long)overlap(ax0, ax1, bx0, bx1) * overlap(ay0, ay1, by0, by1);
        fuse_confusion c;
        assert_int_equal(fuse_mask_confusion(p, S, t, W, W, H, &c), 0);
        assert_int_equal(c.tp, i);
        assert_int_equal(c.fp, a - i);
        assert_int_equal(c.fn, b - i);
        assert_int_equal(c.tn, (long)W * H - a - b + i);
        double iou = fuse_confusion_iou(&c);
        double want = (a + b - i) ? (double)i / (double)(a + b - i) : 1.0;
        assert_true(fabs(iou - want) < 1e-15);
    }
    free(p);
    free(t);
}

static void test_iou_known(void **state)
{
    (void)state;
    uint8_t p[W * H], t[W * H];
    memset(p, 0, sizeof p);
    memset(t, 0, sizeof t);
    fuse_confusion c;
    /* both empty: 1 */
    assert_int_equal(fuse_mask_confusion(p, W, t, W, W, H, &c), 0);
    assert_true(fuse_confusion_iou(&c) == 1.0);
    /* 10x10 and the same square shifted by 5: 50 / 150 */
    fill_rect(p, W, 10, 10, 20, 20, 255);
    fill_rect(t, W, 15, 10, 25, 20, 255);
    assert_int_equal(fuse_mask_confusion(p, W, t, W, W, H, &c), 0);
    assert_true(fabs(fuse_confusion_iou(&c) - 1.0 / 3.0) < 1e-15);
    assert_int_equal(c.fp, 50);
    assert_int_equal(c.fn, 50);
    /* bad arguments */
    assert_int_equal(fuse_mask_confusion(NULL, W, t, W, W, H, &c), -1);
    assert_int_equal(c.tp, 0);
    assert_int_equal(fuse_mask_confusion(p, W - 1, t, W, W, H, &c), -1);
    assert_int_equal(fuse_mask_confusion(p, W, t, W, 0, H, &c), -1);
}

/* Truth: x < a over the full height; prediction: x < a + k. The boundaries
 * are the columns a-1 and a+k-1 (the image border is no boundary), k
 * pixels apart: F = 1 for d >= |k|, 0 below. */
static void test_boundary_shifted_edge(void **state)
{
    (void)state;
    uint8_t p[W * H], t[W * H];
    const int a = 40;
    for (int k = -4; k <= 4; k++) {
        memset(p, 0, sizeof p);
        memset(t, 0, sizeof t);
        fill_rect(t, W, 0, 0, a, H, 255);
        fill_rect(p, W, 0, 0, a + k, H, 255);
        assert_int_equal(fuse_boundary_count(t, W, W, H), H);
        for (int d = 0; d <= 5; d++) {
            double pr, rc;
            double f = fuse_boundary_f(p, W, t, W, W, H, (float)d, &pr, &rc);
            double want = d >= abs(k) ? 1.0 : 0.0;
            assert_true(f == want);
            assert_true(pr == want);
            assert_true(rc == want);
        }
    }
}

/* Part of the edge matched: a 20x20 square (boundary 76 pixels) against
 * its left half (10x20, boundary 56 pixels), within d = 0. */
static void test_boundary_partial(void **state)
{
    (void)state;
    uint8_t p[W * H], t[W * H];
    memset(p, 0, sizeof p);
    memset(t, 0, sizeof t);
    fill_rect(t, W, 10, 10, 30, 30, 255);  /* boundary: 4*20-4 = 76 */
    fill_rect(p, W, 10, 10, 20, 30, 255);  /* boundary: 2*10+2*20-4 = 56 */
    assert_int_equal(fuse_boundary_count(t, W, W, H), 76);
    assert_int_equal(fuse_boundary_count(p, W, W, H), 56);
    double pr, rc;
    /* d = 0: common boundary pixels: the left column (20) and the top and
     * bottom rows for x = 11..19 (9 each): 38. The prediction's right
     * column x = 19, rows 11..28 (18 pixels) is interior to the truth. */
    double f = fuse_boundary_f(p, W, t, W, W, H, 0.0f, &pr, &rc);
    assert_true(fabs(pr - 38.0 / 56.0) < 1e-15);
    assert_true(fabs(rc - 38.0 / 76.0) < 1e-15);
    double P = 38.0 / 56.0, R = 38.0 / 76.0;
    assert_true(fabs(f - 2 * P * R / (P + R)) < 1e-15);
}

static void test_boundary_empty_and_disjoint(void **state)
{
    (void)state;
    uint8_t p[W * H], t[W * H];
    memset(p, 0, sizeof p);
    memset(t, 0, sizeof t);
    assert_true(fuse_boundary_f(p, W, t, W, W, H, 3.0f, NULL, NULL) == 1.0);
    fill_rect(t, W, 5, 5, 15, 15, 255);
    assert_true(fuse_boundary_f(p, W, t, W, W, H, 3.0f, NULL, NULL) == 0.0);
    fill_rect(p, W, 60, 30, 70, 40, 255);
    assert_true(fuse_boundary_f(p, W, t, W, W, H, 3.0f, NULL, NULL) == 0.0);
    /* the same disc: 1 at every d */
    memset(p, 0, sizeof p);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            p[y * W + x] = (x - 40) * (x - 40) + (y - 30) * (y - 30) <= 400 ? 255 : 0;
    assert_true(fuse_boundary_f(p, W, p, W, W, H, 0.0f, NULL, NULL) == 1.0);
    /* a full image has no boundary: against itself 1 */
    memset(t, 255, sizeof t);
    assert_int_equal(fuse_boundary_count(t, W, W, H), 0);
    assert_true(fuse_boundary_f(t, W, t, W, W, H, 1.0f, NULL, NULL) == 1.0);
    assert_true(isnan(fuse_boundary_f(t, W, t, W, W, H, -1.0f, NULL, NULL)));
}

/* Every compared channel differs by e: MSE e^2, PSNR 20 log10(255/e). */
static void test_psnr_constant(void **state)
{
    (void)state;
    enum { IW = 33, IH = 17, ST = IW * 4 + 8 };
    uint8_t *a = malloc(ST * IH), *b = malloc(ST * IH);
    assert_non_null(a);
    assert_non_null(b);
    tu_rng r = { 3 };
    for (int e = 1; e <= 40; e += 13) {
        for (int i = 0; i < ST * IH; i++) a[i] = (uint8_t)(e + tu_int(&r, 256 - e));
        /* every colour channel differs by e: b = a - e; alpha (byte 3)
         * scrambled, which channels = 3 must ignore */
        for (int y = 0; y < IH; y++)
            for (int x = 0; x < IW; x++)
                for (int k = 0; k < 4; k++) {
                    int i = y * ST + x * 4 + k;
                    b[i] = k < 3 ? (uint8_t)(a[i] - e) : (uint8_t)tu_int(&r, 256);
                }
        double mse = fuse_mse(a, ST, b, ST, IW, IH, 4, 3);
        assert_true(fabs(mse - (double)e * e) < 1e-9);
        double ps = fuse_psnr(a, ST, b, ST, IW, IH, 4, 3);
        assert_true(fabs(ps - 20.0 * log10(255.0 / e)) < 1e-9);
    }
    /* identical: +inf; e = 255 everywhere: 0 dB */
    assert_true(isinf(fuse_psnr(a, ST, a, ST, IW, IH, 4, 4)));
    memset(a, 255, ST * IH);
    memset(b, 0, ST * IH);
    assert_true(fabs(fuse_psnr(a, ST, b, ST, IW, IH, 4, 3)) < 1e-12);
    assert_true(isnan(fuse_psnr(a, ST, b, ST, IW, IH, 4, 5)));
    assert_true(isnan(fuse_psnr(a, 3, b, ST, IW, IH, 4, 3)));
    assert_true(isnan(fuse_psnr_of_mse(-1.0)));
    free(a);
    free(b);
}

/* Flicker: an edge at x < a moving one column right per frame. */
static void test_flicker(void **state)
{
    (void)state;
    uint8_t t0[W * H], t1[W * H], p0[W * H], p1[W * H];
    memset(t0, 0, sizeof t0);
    memset(t1, 0, sizeof t1);
    fill_rect(t0, W, 0, 0, 40, H, 255);
    fill_rect(t1, W, 0, 0, 41, H, 255);
    /* prediction follows exactly (even offset by 3 px): 0 */
    memset(p0, 0, sizeof p0);
    memset(p1, 0, sizeof p1);
    fill_rect(p0, W, 0, 0, 43, H, 255);
    fill_rect(p1, W, 0, 0, 44, H, 255);
    assert_true(fuse_edge_flicker(p0, p1, t0, t1, W, W, H) == 0.0);
    /* prediction static while the truth moves: one column of H pixels
     * over an edge of H pixels: 1 */
    assert_true(fuse_edge_flicker(p0, p0, t0, t1, W, W, H) == 1.0);
    /* prediction jumps 2 columns back while the truth is static: 2 */
    memset(p1, 0, sizeof p1);
    fill_rect(p1, W, 0, 0, 41, H, 255);
    assert_true(fuse_edge_flicker(p0, p1, t1, t1, W, W, H) == 2.0);
    assert_true(isnan(fuse_edge_flicker(NULL, p1, t1, t1, W, W, H)));
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_confusion_rectangles),
        cmocka_unit_test(test_iou_known),
        cmocka_unit_test(test_boundary_shifted_edge),
        cmocka_unit_test(test_boundary_partial),
        cmocka_unit_test(test_boundary_empty_and_disjoint),
        cmocka_unit_test(test_psnr_constant),
        cmocka_unit_test(test_flicker))
