/* test_fuse_refine.c - the skin-colour key (colours on either side of the
 * model's ellipse, worked out by hand) and the edge-band refinement: a
 * noisy skin-coloured disc on a two-colour textured background, refined
 * from a kinematic mask that is displaced, too small or too large; the
 * refined mask must come back to the true disc (IoU and boundary F
 * measured with fuse_metrics), and the refinement must leave the mask
 * alone when the colours cannot tell hand from background; the global
 * colour model (fuse_colour_model_learn): its log-likelihood ratios on
 * colours whose counts are known, the pixels it leaves out, and the
 * refinement that mixes it in; the band-only paths (portable, AVX2,
 * AVX-512, NEON under qemu-aarch64: fuse_refine_mask_isa) byte for byte and stat for stat against
 * the scalar reference on 400 seeded random cases each (skipped where the
 * CPU lacks the ISA), each path's chamfer row passes (dt_fwd / dt_bwd, the
 * vertical part and the running minimum) against a scalar model on seeded
 * rows, and the reference's CRC on the disc scene. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse_metrics.h"
#include "../src/fuse/fuse_refine.h"
#include "../src/fuse/fuse_refine_kern.h"
#include "../src/cpu/ef_mem.h"

enum { W = 160, H = 120 };
/* CRC-32 of the reference's output in test_refine_crc */
#define CRC_BAND5 0x6c9574c7u
#define CRC_BAND16 0x3f86ac59u

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
    EF_FREE_ALL(scratch, img, truth, km, out);
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
    EF_FREE_ALL(scratch, img, km, out);
}

/* Two flat colours, counts known: a 40x40 "arm" square of colour A in a
 * 160x120 image of colour B, a 1-pixel ring of colour C round the square
 * (not learned with margin >= 2: its neighbours differ) and a 10x10 patch
 * of colour D marked 128 in the mask (not learned at all). With step 1 and
 * margin 2: fg = the square minus its 2-px rim, bg = the rest minus the
 * 2 px beside the ring and the patch. */
static void test_colour_model_counts(void **state)
{
    (void)state;
    uint8_t *img = malloc(4 * W * H), *m = malloc(W * H);
    const int bits = 4, bins = 1 << (3 * bits);
    float *llr = malloc(sizeof(float) * (size_t)bins);
    size_t ss = fuse_colour_model_scratch_size(bits);
    assert_int_equal(ss, 2u * (size_t)bins * 4u);
    assert_int_equal(fuse_colour_model_scratch_size(7), 0);
    void *scratch = malloc(ss);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int sq = x >= 60 && x < 100 && y >= 40 && y < 80;
            int ring = !sq && x >= 59 && x < 101 && y >= 39 && y < 81;
            int patch = x >= 10 && x < 20 && y >= 10 && y < 20;
            if (sq) set_px(img, x, y, 200, 150, 120);            /* A */
            else if (ring) set_px(img, x, y, 20, 200, 20);       /* C */
            else if (patch) set_px(img, x, y, 200, 20, 200);     /* D */
            else set_px(img, x, y, 60, 70, 90);                  /* B */
            m[y * W + x] = sq ? 255 : patch ? 128 : 0;
        }
    fuse_colour_model cm = { bits, 0, 0, llr };
    fuse_image P = { img, W, H, 4 * W };
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W, 2, 1, 5.0f, 10, scratch, ss),
                     FUSE_OK);
    /* fg: the square's pixels whose 4 neighbours at distance 2 are inside:
     * 36 x 36 minus the 4 x 4 ... all of the inner 36x36 (the plus-shaped
     * test is exact for a square) */
    assert_int_equal(cm.fg_samples, 36 * 36);
    /* bg: value 0 everywhere but the square and the patch; excluded are the
     * pixels within 2 (4-neighbour plus shape) of a non-0 pixel */
    long bg = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int ok = m[y * W + x] == 0;
            const int d[4][2] = { { -2, 0 }, { 2, 0 }, { 0, -2 }, { 0, 2 } };
            for (int k = 0; k < 4 && ok; k++) {
                int xx = x + d[k][0], yy = y + d[k][1];
                xx = xx < 0 ? 0 : xx >= W ? W - 1 : xx;
                yy = yy < 0 ? 0 : yy >= H ? H - 1 : yy;
                ok = m[yy * W + xx] == 0;
            }
            bg += ok;
        }
    assert_int_equal(cm.bg_samples, bg);
    /* the ring (C) is in the bg pixels near the square: some of it is
     * learned as background; A only as fg, B only as bg */
    const uint8_t A[3] = { 200, 150, 120 }, B[3] = { 60, 70, 90 }, D[3] = { 200, 20, 200 };
    float a = 4.0f / (float)bins;
    float expect_a = logf((1296.0f + a) / a) + logf((float)bg + 4.0f) - logf(1296.0f + 4.0f);
    if (expect_a > 5.0f) expect_a = 5.0f;
    assert_float_equal(llr[fuse_colour_bin(A, bits)], expect_a, 1e-4);
    assert_float_equal(llr[fuse_colour_bin(A, bits)], 5.0f, 1e-6);   /* clamped */
    assert_true(llr[fuse_colour_bin(B, bits)] < -4.99f);
    /* D was never learned: only the prior ratio of the class sizes */
    assert_float_equal(llr[fuse_colour_bin(D, bits)],
                       logf((float)bg + 4.0f) - logf(1296.0f + 4.0f), 1e-4);
    /* too few samples: all zero */
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W, 2, 1, 5.0f, 2000, scratch, ss),
                     FUSE_OK);
    for (int b = 0; b < bins; b++) assert_true(llr[b] == 0.0f);
    /* argument checks */
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W, 2, 1, 5.0f, 10, scratch, ss - 1),
                     FUSE_ERR_ARGS);
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W, 65, 1, 5.0f, 10, scratch, ss),
                     FUSE_ERR_ARGS);
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W, 2, 0, 5.0f, 10, scratch, ss),
                     FUSE_ERR_ARGS);
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W - 1, 2, 1, 5.0f, 10, scratch, ss),
                     FUSE_ERR_ARGS);
    cm.bits = 7;
    assert_int_equal(fuse_colour_model_learn(&cm, &P, m, W, 2, 1, 5.0f, 10, scratch, ss),
                     FUSE_ERR_ARGS);
    EF_FREE_ALL(img, m, llr, scratch);
}

/* The disc of test_refine_recovers_disc, but the kinematic mask is shifted
 * by 11 px with a band of 8 (margin 8): the local rings learn part of the
 * true disc as background and part of the background as hand. A global
 * model learned from a better mask (here: the truth eroded by 3 px, marked
 * 128 in between) must do better mixed in at weight 0.5 and better still
 * alone (the 3 px beyond the band stay wrong either way, so the gain is
 * small: 0.914 -> 0.918 on this seed). */
static void test_refine_global(void **state)
{
    (void)state;
    uint8_t *img = malloc(4 * W * H), *truth = malloc(W * H), *km = malloc(W * H);
    uint8_t *out = malloc(W * H), *learn = malloc(W * H), *inner = malloc(W * H);
    const int bits = 4, bins = 1 << (3 * bits);
    float *llr = malloc(sizeof(float) * (size_t)bins);
    size_t cs = fuse_colour_model_scratch_size(bits);
    void *cscr = malloc(cs);
    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = 8;
    size_t ss = fuse_refine_scratch_size(&rp, W, H);
    void *scratch = aligned_alloc(16, (ss + 15) & ~(size_t)15);
    fuse_image P = { img, W, H, 4 * W };
    scene(img, truth, 80.3f, 61.7f, 30.0f, 21u);
    disc(km, 91.3f, 61.7f, 30.0f);
    disc(inner, 80.3f, 61.7f, 27.0f);
    for (int i = 0; i < W * H; i++) learn[i] = inner[i] ? 255 : truth[i] ? 128 : 0;
    fuse_colour_model cm = { bits, 0, 0, llr };
    assert_int_equal(fuse_colour_model_learn(&cm, &P, learn, W, 1, 1, 3.0f, 64, cscr, cs),
                     FUSE_OK);
    assert_true(cm.fg_samples > 2000 && cm.bg_samples > 10000);
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss, NULL), FUSE_OK);
    double local = iou(out, truth);
    assert_int_equal(fuse_refine_mask_global(&rp, &cm, 0.5f, &P, km, W, out, W, scratch, ss,
                                             NULL), FUSE_OK);
    double mixed = iou(out, truth);
    assert_int_equal(fuse_refine_mask_global(&rp, &cm, 1.0f, &P, km, W, out, W, scratch, ss,
                                             NULL), FUSE_OK);
    double global = iou(out, truth);
    print_message("shift 11, band 8: IoU kinematic %.4f, local %.4f, mixed %.4f, global %.4f\n",
                  iou(km, truth), local, mixed, global);
    assert_true(local < 0.95);
    assert_true(mixed > local);
    assert_true(global > mixed);
    /* weight 0 is the local refinement, byte for byte */
    uint8_t *out0 = malloc(W * H);
    assert_int_equal(fuse_refine_mask(&rp, &P, km, W, out, W, scratch, ss, NULL), FUSE_OK);
    assert_int_equal(fuse_refine_mask_global(&rp, &cm, 0.0f, &P, km, W, out0, W, scratch, ss,
                                             NULL), FUSE_OK);
    assert_memory_equal(out, out0, W * H);
    assert_int_equal(fuse_refine_mask_global(&rp, NULL, 0.5f, &P, km, W, out, W, scratch, ss,
                                             NULL), FUSE_ERR_ARGS);
    assert_int_equal(fuse_refine_mask_global(&rp, &cm, 1.5f, &P, km, W, out, W, scratch, ss,
                                             NULL), FUSE_ERR_ARGS);
    free(out0);
    free(img); free(truth); free(km); free(out); free(learn); free(inner);
    free(llr); free(cscr); free(scratch);
}

/* ------------------------------------------ fast paths against the reference */

/* A random case: odd sizes, padded strides, a mask of random discs (or
 * empty, full, pixel noise, touching the border), grey values around 128
 * in the mask, two colour clusters plus noise in P, random parameters
 * (band 1..64, margin, bits, smooth, prior incl. 0), sometimes a global
 * model of the same or other bits. */
typedef struct rcase {
    int w, h, ms, os, ps;
    uint8_t *img, *mask;
    fuse_refine_params rp;
    fuse_colour_model g;
    int use_g;
    float weight;
} rcase;

static void make_case(rcase *c, tu_rng *r, int k)
{
    c->w = 1 + tu_int(r, k < 8 ? 9 : 97);
    c->h = 1 + tu_int(r, k < 8 ? 9 : 71);
    if (k % 13 == 5) { c->w = 129 + tu_int(r, 64); c->h = 97 + tu_int(r, 40); }
    c->ms = c->w + tu_int(r, 5);
    c->os = c->w + tu_int(r, 5);
    c->ps = 4 * c->w + 4 * tu_int(r, 3);
    c->img = malloc((size_t)c->ps * (size_t)c->h);
    c->mask = malloc((size_t)c->ms * (size_t)c->h);
    const int kind = k % 7;   /* 0 empty, 1 full, 2 noise, else discs */
    const int nd = 1 + tu_int(r, 4);
    float cx[4], cy[4], rr[4];
    for (int i = 0; i < nd; i++) {
        cx[i] = tu_range(r, -0.2f, 1.2f) * (float)c->w;
        cy[i] = tu_range(r, -0.2f, 1.2f) * (float)c->h;
        rr[i] = tu_range(r, 0.5f, 0.6f * (float)(c->w > c->h ? c->w : c->h));
    }
    for (int y = 0; y < c->h; y++)
        for (int x = 0; x < c->w; x++) {
            int in = 0;
            if (kind == 1) in = 1;
            else if (kind == 2) in = tu_int(r, 3) == 0;
            else if (kind > 2)
                for (int i = 0; i < nd; i++) {
                    float dx = (float)x + 0.5f - cx[i], dy = (float)y + 0.5f - cy[i];
                    in |= dx * dx + dy * dy <= rr[i] * rr[i];
                }
            c->mask[(size_t)y * (size_t)c->ms + (size_t)x] =
                (uint8_t)(in ? 128 + tu_int(r, 128) : tu_int(r, 128));
            /* the colour follows the mask (noisily), sometimes it lies */
            int skin = tu_int(r, 8) == 0 ? !in : in;
            int n = tu_int(r, 41) - 20;
            uint8_t *p = c->img + (size_t)y * (size_t)c->ps + 4 * (size_t)x;
            int rgb[3] = { skin ? 200 : 60, skin ? 140 : 90, skin ? 110 : 120 };
            for (int j = 0; j < 3; j++) {
                int v = rgb[j] + n + tu_int(r, 31) - 15;
                p[j] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
            }
            p[3] = (uint8_t)tu_int(r, 256);
        }
    for (int y = 0; y < c->h; y++)   /* padding bytes: garbage */
        for (int x = c->w; x < c->ms; x++) c->mask[(size_t)y * (size_t)c->ms + (size_t)x] = 200;
    c->rp = fuse_refine_params_default();
    c->rp.band = k % 11 == 0 ? 64 : 1 + tu_int(r, k % 3 ? 12 : 64);
    c->rp.margin = 1 + tu_int(r, k % 4 ? 10 : 64);
    c->rp.bits = k % 29 == 3 ? 6 : 2 + tu_int(r, 4);
    c->rp.smooth = tu_int(r, 4);
    c->rp.prior = k % 5 == 0 ? 0.0f : tu_range(r, 0.0f, 3.0f);
    c->rp.min_samples = k % 17 == 1 ? 100000 : 1 + tu_int(r, 20);
    c->use_g = tu_int(r, 3) == 0;
    c->g.bits = tu_int(r, 2) ? c->rp.bits : 2 + tu_int(r, 4);
    c->g.fg_samples = c->g.bg_samples = 0;
    size_t gb = (size_t)1 << (3 * c->g.bits);
    c->g.llr = malloc(gb * sizeof(float));
    for (size_t i = 0; i < gb; i++) c->g.llr[i] = tu_range(r, -3.0f, 3.0f);
    c->weight = tu_int(r, 4) == 0 ? (float)tu_int(r, 2) : tu_unit(r);
}

static void free_case(rcase *c)
{
    free(c->img);
    free(c->mask);
    free(c->g.llr);
}

/* Runs a case on the reference and on isa; fails on any byte or stat that
 * differs. Returns the CRC of the reference output. */
static uint32_t check_case(const rcase *c, ef_isa isa, int k)
{
    fuse_image P = { c->img, c->w, c->h, c->ps };
    size_t ss = fuse_refine_scratch_size(&c->rp, c->w, c->h);
    assert_true(ss > 0);
    void *s1 = aligned_alloc(64, (ss + 63) & ~(size_t)63);
    void *s2 = aligned_alloc(64, (ss + 63) & ~(size_t)63);
    size_t on = (size_t)c->os * (size_t)c->h;
    uint8_t *o1 = malloc(on), *o2 = malloc(on);
    memset(o1, 0x5a, on);
    memset(o2, 0x5a, on);
    memset(s2, 0xa5, ss);   /* the fast path must not read stale scratch */
    fuse_refine_stats t1, t2;
    const fuse_colour_model *g = c->use_g ? &c->g : NULL;
    assert_int_equal(fuse_refine_mask_isa(&c->rp, g, c->weight, &P, c->mask, c->ms, o1, c->os,
                                          s1, ss, &t1, EF_ISA_REF), FUSE_OK);
    assert_int_equal(fuse_refine_mask_isa(&c->rp, g, c->weight, &P, c->mask, c->ms, o2, c->os,
                                          s2, ss, &t2, isa), FUSE_OK);
    if (memcmp(o1, o2, on) != 0) {
        for (size_t i = 0; i < on; i++)
            if (o1[i] != o2[i]) {
                print_error("case %d (%dx%d band %d margin %d bits %d smooth %d g %d): "
                            "byte %zu (x %zu, y %zu) ref %d %s %d\n", k, c->w, c->h,
                            c->rp.band, c->rp.margin, c->rp.bits, c->rp.smooth, c->use_g, i,
                            i % (size_t)c->os, i / (size_t)c->os, o1[i], ef_isa_name(isa),
                            o2[i]);
                break;
            }
        fail();
    }
    assert_int_equal(t1.band_pixels, t2.band_pixels);
    assert_int_equal(t1.flipped_in, t2.flipped_in);
    assert_int_equal(t1.flipped_out, t2.flipped_out);
    assert_int_equal(t1.fg_samples, t2.fg_samples);
    assert_int_equal(t1.bg_samples, t2.bg_samples);
    assert_int_equal(t1.used_colour, t2.used_colour);
    uint32_t crc = tu_crc32(0, o1, on);
    free(s1); free(s2); free(o1); free(o2);
    return crc;
}

static void check_isa(ef_isa isa)
{
    if (!ef_cpu_has(isa) || ef_isa_choose(isa) != isa) {
        print_message("SKIP %s: not available here (or capped by EGOFUSE_ISA); untested: "
                      "src/fuse/fuse_refine_%s.c\n", ef_isa_name(isa), ef_isa_name(isa));
        skip();
    }
    assert_int_equal(fuse_refine_isa(isa), isa);
    tu_rng r = { 0x5eed0007u };
    long used = 0, flips = 0;
    for (int k = 0; k < 400; k++) {
        rcase c;
        make_case(&c, &r, k);
        check_case(&c, isa, k);
        fuse_refine_stats st;
        fuse_image P = { c.img, c.w, c.h, c.ps };
        size_t ss = fuse_refine_scratch_size(&c.rp, c.w, c.h);
        void *s = aligned_alloc(64, (ss + 63) & ~(size_t)63);
        uint8_t *o = malloc((size_t)c.os * (size_t)c.h);
        assert_int_equal(fuse_refine_mask_isa(&c.rp, NULL, 0.0f, &P, c.mask, c.ms, o, c.os, s, ss,
                                              &st, isa), FUSE_OK);
        used += st.used_colour;
        flips += st.flipped_in + st.flipped_out;
        free(s);
        free(o);
        free_case(&c);
    }
    /* the cases exercise the colour decision, not only the copy of M */
    print_message("%s: 400 cases, colour used in %ld, %ld pixels flipped\n", ef_isa_name(isa),
                  used, flips);
    assert_true(used > 80);
    assert_true(flips > 1000);
}

static void test_fast_c(void **state) { (void)state; check_isa(EF_ISA_SSE2); }
static void test_fast_avx2(void **state) { (void)state; check_isa(EF_ISA_AVX2); }
static void test_fast_avx512(void **state) { (void)state; check_isa(EF_ISA_AVX512); }
static void test_fast_neon(void **state) { (void)state; check_isa(EF_ISA_NEON); }

/* The chamfer row passes of fuse_refine_kern.h as the reference
 * (fuse_refine.c) states them: the vertical part on [a, b], then the
 * running minimum, the row's first (forward) / last (backward) pixel kept. */
static unsigned min3u(unsigned m, unsigned v) { return v < m ? v : m; }
static void model_pass(uint16_t *r, const uint16_t *v, int w, int a, int b, int fwd)
{
    if (v)
        for (int x = a; x <= b; x++) {
            unsigned m = min3u(r[x], v[x] + 3u);
            if (x > 0) m = min3u(m, v[x - 1] + 4u);
            if (x + 1 < w) m = min3u(m, v[x + 1] + 4u);
            r[x] = (uint16_t)m;
        }
    if (fwd)
        for (int x = a > 0 ? a : 1; x <= b; x++) r[x] = (uint16_t)min3u(r[x], r[x - 1] + 3u);
    else
        for (int x = b + 1 < w ? b : w - 2; x >= a; x--)
            r[x] = (uint16_t)min3u(r[x], r[x + 1] + 3u);
}

/* a chamfer-like row: edges (3), caps, short slopes and noise in 0..cap */
static void chamfer_row(tu_rng *g, uint16_t *r, int n, unsigned cap)
{
    for (int x = 0; x < n;) {
        const int run = 1 + tu_int(g, 40), kind = tu_int(g, 5);
        unsigned v = (unsigned)tu_int(g, (int)cap + 1);
        for (int i = 0; i < run && x < n; i++, x++) {
            unsigned o = kind == 0 ? cap : kind == 1 ? 3u : kind == 2 ? (unsigned)tu_int(g, (int)cap + 1)
                                                                     : v;
            if (kind == 3) v = v + 3u + (unsigned)tu_int(g, 3) > cap ? cap : v + 3u + (unsigned)tu_int(g, 3);
            if (kind == 4) v = v < 4u ? 3u : v - 3u - (unsigned)tu_int(g, 2);
            r[x] = (uint16_t)o;
        }
    }
}

/* Every path's dt_fwd / dt_bwd against model_pass on 6000 seeded rows:
 * widths 1..300 (not multiples of the vectors), [a, b] anywhere (both
 * borders included), with and without the neighbouring row, caps
 * 3 (band + margin + 1) for band, margin 1..64; the whole row compared
 * (outside [a, b] untouched), guards around it. */
static void test_chamfer_rows(void **state)
{
    (void)state;
    /* capped: the kernel does not read r[a - 1] / r[b + 1] (AVX-512's own
     * scan: right where they hold the cap, as the driver's rows do outside
     * [a, b]): only the rows with the cap there; the others read them,
     * any value */
    struct { const char *name; ef_isa isa; const fuse__refine_kern *k; int capped; } paths[] = {
        { "portable", EF_ISA_SSE2, &fuse__refine_kern_c, 0 },
        { "avx2", EF_ISA_AVX2, fuse__refine_kern_avx2(), 0 },
        { "avx512", EF_ISA_AVX512, fuse__refine_kern_avx512(), 1 },
        { "neon", EF_ISA_NEON, fuse__refine_kern_neon(), 0 },
    };
    enum { MAXW = 300, G = 40 };
    static uint16_t r0[MAXW + 2 * G], v0[MAXW + 2 * G], want[MAXW + 2 * G], got[MAXW + 2 * G];
    int ran = 0;
    for (size_t p = 0; p < sizeof paths / sizeof paths[0]; p++) {
        if (!paths[p].k || (paths[p].isa != EF_ISA_SSE2 &&
                            (!ef_cpu_has(paths[p].isa) || ef_isa_choose(paths[p].isa) != paths[p].isa))) {
            print_message("SKIP chamfer rows %s: not available here (or capped by EGOFUSE_ISA)\n",
                          paths[p].name);
            continue;
        }
        tu_rng g = { 0xC4A3F3u };
        long px = 0, changed = 0, rows = 0;
        for (int c = 0; c < 6000; c++) {
            const int w = c < 300 ? 1 + c : 1 + tu_int(&g, MAXW);
            int a = tu_int(&g, w), b = tu_int(&g, w);
            if (tu_int(&g, 4) == 0) a = 0;
            if (tu_int(&g, 4) == 0) b = w - 1;
            if (a > b) { const int t = a; a = b; b = t; }
            const int c1 = tu_int(&g, 64), c2 = tu_int(&g, 64); /* in this order */
            const unsigned cap = 3u * (unsigned)(2 + c1 + c2);
            const int fwd = c & 1, hasv = tu_int(&g, 4) != 0;
            for (int i = 0; i < MAXW + 2 * G; i++) r0[i] = v0[i] = (uint16_t)(0xA000u + (unsigned)i);
            chamfer_row(&g, r0 + G, w, cap);
            chamfer_row(&g, v0 + G, w, cap);
            /* half the rows: the cap outside [a, b], as the driver's */
            if (tu_int(&g, 2) == 0) {
                for (int x = 0; x < a; x++) r0[G + x] = (uint16_t)cap;
                for (int x = b + 1; x < w; x++) r0[G + x] = (uint16_t)cap;
            } else if (paths[p].capped) {
                continue;
            }
            memcpy(want, r0, sizeof r0);
            memcpy(got, r0, sizeof r0);
            model_pass(want + G, hasv ? v0 + G : NULL, w, a, b, fwd);
            (fwd ? paths[p].k->dt_fwd : paths[p].k->dt_bwd)(got + G, hasv ? v0 + G : NULL, w, a, b);
            for (int i = 0; i < MAXW + 2 * G; i++) {
                if (got[i] != want[i]) {
                    print_message("FAIL chamfer rows %s case %d (%s, w %d, [%d, %d], %s): "
                                  "x %d got %u want %u\n", paths[p].name, c, fwd ? "fwd" : "bwd",
                                  w, a, b, hasv ? "row" : "no row", i - G, got[i], want[i]);
                    fail();
                }
                changed += want[i] != r0[i];
            }
            px += b - a + 1;
            rows++;
        }
        print_message("chamfer rows %s: %ld rows, %ld pixels, %ld changed by the passes\n",
                      paths[p].name, rows, px, changed);
        assert_true(changed > px / 20);
        ran++;
    }
    assert_true(ran >= 1);
}

/* The disc scene with a shifted kinematic mask (defaults, band 5 and 16):
 * the reference's bytes as a constant (the result of the whole-image
 * implementation this path replaced), and every path available gives them. */
static void test_refine_crc(void **state)
{
    (void)state;
    uint8_t *img = malloc(4 * W * H), *truth = malloc(W * H), *km = malloc(W * H);
    uint8_t *out = malloc(W * H);
    const uint32_t expect[2] = { CRC_BAND5, CRC_BAND16 };
    const int bands[2] = { 5, 16 };
    scene(img, truth, 80.3f, 61.7f, 30.0f, 77u);
    disc(km, 82.3f, 60.2f, 28.5f);
    fuse_image P = { img, W, H, 4 * W };
    for (int b = 0; b < 2; b++) {
        fuse_refine_params rp = fuse_refine_params_default();
        rp.band = bands[b];
        size_t ss = fuse_refine_scratch_size(&rp, W, H);
        void *scratch = aligned_alloc(64, (ss + 63) & ~(size_t)63);
        for (int i = EF_ISA_REF; i < EF_ISA_COUNT; i++) {
            if (i != EF_ISA_REF && (!ef_cpu_has((ef_isa)i) || (int)fuse_refine_isa((ef_isa)i) != i))
                continue;
            fuse_refine_stats st;
            memset(out, 0, W * H);
            assert_int_equal(fuse_refine_mask_isa(&rp, NULL, 0.0f, &P, km, W, out, W, scratch,
                                                  ss, &st, (ef_isa)i), FUSE_OK);
            uint32_t crc = tu_crc32(0, out, W * H);
            print_message("band %d %s: crc 0x%08x, band pixels %ld, flipped %ld/%ld\n",
                          bands[b], ef_isa_name((ef_isa)i), (unsigned)crc, st.band_pixels,
                          st.flipped_in, st.flipped_out);
            assert_int_equal(st.used_colour, 1);
            assert_int_equal(crc, expect[b]);
        }
        free(scratch);
    }
    free(img); free(truth); free(km); free(out);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_skin_key),
        cmocka_unit_test(test_refine_recovers_disc),
        cmocka_unit_test(test_refine_keeps_mask),
        cmocka_unit_test(test_colour_model_counts),
        cmocka_unit_test(test_refine_global),
        cmocka_unit_test(test_fast_c),
        cmocka_unit_test(test_fast_avx2),
        cmocka_unit_test(test_fast_neon),
        cmocka_unit_test(test_fast_avx512),
        cmocka_unit_test(test_chamfer_rows),
        cmocka_unit_test(test_refine_crc))
