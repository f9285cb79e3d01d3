/* test_fuse_composite.c - fuse_composite (bilinear resampling of the
 * premultiplied layer into the viewport, then "over") against a double
 * precision reference written here, exact cases (zero layer, opaque layer,
 * 1:1 scale, edge replication, the paper's letterbox), in-place use,
 * validation, fuse_rgb24_to_rgba, and a CRC32 of seeded cases. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse.h"
#include "../src/fuse/fuse_internal.h"

/* CRC32 over the outputs of test_crc(). It changes only when the rules of
 * docs/fuse.md change on purpose; then record the printed value. */
#define COMPOSITE_CRC 0xBC16BD50u

/* The paper's geometry: 640x400 camera layer, 1194x746 viewport centred
 * in the 1280x800 LCD image. */
enum { CAM_W = 640, CAM_H = 400, LCD_W = 1280, LCD_H = 800,
       VP_W = 1194, VP_H = 746, VP_X = (LCD_W - VP_W) / 2, VP_Y = (LCD_H - VP_H) / 2 };

typedef struct img {
    fuse_image im;
    uint8_t *buf;
} img;

static img img_new(int w, int h, int pad)
{
    img m;
    m.buf = malloc((size_t)(w + pad) * 4 * h);
    assert_non_null(m.buf);
    m.im = (fuse_image){ m.buf, w, h, (w + pad) * 4 };
    memset(m.buf, 0x5A, (size_t)(w + pad) * 4 * h);
    return m;
}

static uint8_t *px(const fuse_image *im, int x, int y)
{
    return im->pixels + (size_t)y * im->stride + 4 * (size_t)x;
}

/* Random premultiplied layer: transparent, opaque and soft pixels. */
static void fill_layer(fuse_image *q, tu_rng *r)
{
    int x, y, c;
    for (y = 0; y < q->height; y++)
        for (x = 0; x < q->width; x++) {
            uint8_t *p = px(q, x, y);
            int k = tu_int(r, 4);
            int a = k == 0 ? 0 : k == 1 ? 255 : tu_int(r, 256);
            for (c = 0; c < 3; c++) p[c] = (uint8_t)tu_int(r, a + 1);
            p[3] = (uint8_t)a;
        }
}

static void fill_random(fuse_image *v, tu_rng *r)
{
    int x, y, c;
    for (y = 0; y < v->height; y++)
        for (x = 0; x < v->width; x++)
            for (c = 0; c < 4; c++) px(v, x, y)[c] = (uint8_t)tu_int(r, 256);
}

/* ---- double-precision reference ------------------------------------ */

/* Tap index and 8-bit weight (as a fraction) of destination pixel i: the
 * pixel centre (i + 0.5) src/dst - 0.5, clamped to the edge pixels, with
 * its fraction cut to 8 bits as fuse.h specifies. */
static void ref_tap(int i, int src, int dst, int *i0, int *i1, double *w)
{
    double pos256 = floor((double)((2.0 * i + 1.0) * src - dst) * 256.0 / (2.0 * dst));
    if (pos256 < 0) pos256 = 0;
    if (pos256 > 256.0 * (src - 1)) pos256 = 256.0 * (src - 1);
    *i0 = (int)floor(pos256 / 256.0);
    *i1 = *i0 + 1 < src ? *i0 + 1 : src - 1;
    *w = (pos256 - 256.0 * *i0) / 256.0;
}

/* Checks out against the reference over every pixel of V. Inside the
 * viewport:
 *   ideal:  |out - round(R)| <= 1, R = q + (1 - qa/255) V in double with
 *           q bilinear and no intermediate rounding;
 *   staged: out == round(round(q) + (1 - round(qa)/255) V) exactly, the
 *           rounding points of fuse.h (the resampled layer is rounded to
 *           8 bits, half up, then composited with one rounding).
 * Outside, out == V exactly. Returns the number of channels off by one
 * from the ideal. */
static long check_ref(const fuse_image *Q, const fuse_image *V,
                      const fuse_image *O, int x0, int y0, int vw, int vh,
                      double *max_err)
{
    long ones = 0;
    int x, y, c;
    for (y = 0; y < V->height; y++)
        for (x = 0; x < V->width; x++) {
            const uint8_t *v = px(V, x, y), *o = px(O, x, y);
            int ix0, ix1, iy0, iy1;
            double wx, wy, q[4];
            if (x < x0 || x >= x0 + vw || y < y0 || y >= y0 + vh) {
                assert_memory_equal(o, v, 4);
                continue;
            }
            ref_tap(x - x0, Q->width, vw, &ix0, &ix1, &wx);
            ref_tap(y - y0, Q->height, vh, &iy0, &iy1, &wy);
            for (c = 0; c < 4; c++)
                q[c] = px(Q, ix0, iy0)[c] * (1 - wx) * (1 - wy) +
                       px(Q, ix1, iy0)[c] * wx * (1 - wy) +
                       px(Q, ix0, iy1)[c] * (1 - wx) * wy +
                       px(Q, ix1, iy1)[c] * wx * wy;
            for (c = 0; c < 3; c++) {
                double qa = floor(q[3] + 0.5), qc = floor(q[c] + 0.5);
                double S = fmin(255.0, floor(qc + (255.0 - qa) * v[c] / 255.0 + 0.5));
                double R = fmin(255.0, q[c] + (1.0 - q[3] / 255.0) * v[c]);
                if (o[c] != S) {
                    print_error("pixel (%d,%d) ch %d: got %d, staged reference %.0f\n",
                                x, y, c, o[c], S);
                    fail();
                }
                double e = fabs(o[c] - R);
                long d = labs((long)o[c] - (long)floor(R + 0.5));
                if (e > *max_err) *max_err = e;
                if (d > 1) {
                    print_error("pixel (%d,%d) ch %d: got %d, reference %.4f\n",
                                x, y, c, o[c], R);
                    fail();
                }
                ones += d;
            }
            assert_int_equal(o[3], 255);
        }
    return ones;
}

static void test_vs_double(void **state)
{
    tu_rng r = { 0xC0FF0001u };
    double max_err = 0;
    long ones = 0;
    int k;
    (void)state;
    /* The real sizes, then random small ones (up and down scaling). */
    for (k = 0; k < 60; k++) {
        int sw, sh, W, H, vw, vh, x0, y0;
        img Q, V, O;
        if (k == 0) {
            sw = CAM_W; sh = CAM_H; W = LCD_W; H = LCD_H;
            vw = VP_W; vh = VP_H; x0 = VP_X; y0 = VP_Y;
        } else {
            sw = 1 + tu_int(&r, 24); sh = 1 + tu_int(&r, 24);
            vw = 1 + tu_int(&r, 60); vh = 1 + tu_int(&r, 60);
            W = vw + tu_int(&r, 5); H = vh + tu_int(&r, 5);
            x0 = tu_int(&r, W - vw + 1); y0 = tu_int(&r, H - vh + 1);
        }
        Q = img_new(sw, sh, k % 3);
        V = img_new(W, H, k % 2);
        O = img_new(W, H, 0);
        fill_layer(&Q.im, &r);
        fill_random(&V.im, &r);
        assert_int_equal(fuse_composite(&Q.im, &V.im, x0, y0, vw, vh, &O.im), FUSE_OK);
        ones += check_ref(&Q.im, &V.im, &O.im, x0, y0, vw, vh, &max_err);
        free(Q.buf); free(V.buf); free(O.buf);
    }
    printf("NOTE composite vs double: max error %.4f LSB, %ld channels off by 1\n",
           max_err, ones);
}

/* ---- exact cases ----------------------------------------------------- */

typedef struct trio { img Q, V, O; } trio;

static trio trio_new(int sw, int sh, int W, int H)
{
    trio t = { img_new(sw, sh, 1), img_new(W, H, 2), img_new(W, H, 0) };
    return t;
}
static void trio_free(trio *t) { free(t->Q.buf); free(t->V.buf); free(t->O.buf); }

static int inside(int x, int y, int x0, int y0, int w, int h)
{
    return x >= x0 && x < x0 + w && y >= y0 && y < y0 + h;
}

static void test_zero_layer(void **state)
{
    tu_rng r = { 0xC0FF0002u };
    trio t = trio_new(64, 40, 120, 80);
    int x, y;
    (void)state;
    memset(t.Q.buf, 0, (size_t)t.Q.im.stride * 40);
    fill_random(&t.V.im, &r);
    for (y = 0; y < 80; y++)                       /* opaque V: out == V */
        for (x = 0; x < 120; x++) px(&t.V.im, x, y)[3] = 255;
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 7, 5, 100, 70, &t.O.im), FUSE_OK);
    for (y = 0; y < 80; y++)
        assert_memory_equal(px(&t.O.im, 0, y), px(&t.V.im, 0, y), 4 * 120);
    /* Translucent V: rgb kept everywhere, alpha 255 only inside. */
    fill_random(&t.V.im, &r);
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 7, 5, 100, 70, &t.O.im), FUSE_OK);
    for (y = 0; y < 80; y++)
        for (x = 0; x < 120; x++) {
            const uint8_t *o = px(&t.O.im, x, y), *v = px(&t.V.im, x, y);
            assert_memory_equal(o, v, 3);
            assert_int_equal(o[3], inside(x, y, 7, 5, 100, 70) ? 255 : v[3]);
        }
    trio_free(&t);
}

static void test_opaque_layer(void **state)
{
    tu_rng r = { 0xC0FF0003u };
    trio t = trio_new(CAM_W, CAM_H, LCD_W, LCD_H);
    static const uint8_t col[4] = { 201, 13, 99, 255 };
    int x, y;
    (void)state;
    for (y = 0; y < CAM_H; y++)
        for (x = 0; x < CAM_W; x++) memcpy(px(&t.Q.im, x, y), col, 4);
    fill_random(&t.V.im, &r);
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, VP_X, VP_Y, VP_W, VP_H, &t.O.im),
                     FUSE_OK);
    for (y = 0; y < LCD_H; y++)
        for (x = 0; x < LCD_W; x++)
            assert_memory_equal(px(&t.O.im, x, y),
                                inside(x, y, VP_X, VP_Y, VP_W, VP_H) ? col : px(&t.V.im, x, y), 4);
    trio_free(&t);
}

/* vw == sw and vh == sh: every weight is 0, the layer comes through as is. */
static void test_identity_scale(void **state)
{
    tu_rng r = { 0xC0FF0004u };
    trio t = trio_new(53, 31, 60, 40);
    int x, y, c;
    (void)state;
    fill_layer(&t.Q.im, &r);
    fill_random(&t.V.im, &r);
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 4, 6, 53, 31, &t.O.im), FUSE_OK);
    for (y = 0; y < 31; y++)
        for (x = 0; x < 53; x++) {
            const uint8_t *q = px(&t.Q.im, x, y), *v = px(&t.V.im, x + 4, y + 6);
            const uint8_t *o = px(&t.O.im, x + 4, y + 6);
            for (c = 0; c < 3; c++)
                assert_int_equal(o[c], q[c] + (int)floor((255 - q[3]) * v[c] / 255.0 + 0.5));
            if (q[3] == 255) assert_memory_equal(o, q, 4);   /* the source itself */
        }
    trio_free(&t);
}

/* Upscaling 4x: output pixels whose centre maps left of the first source
 * pixel centre repeat it exactly, likewise at the right, top and bottom. */
static void test_edges_replicate(void **state)
{
    static const uint8_t val[4] = { 0, 255, 30, 200 };
    const int sw = 4, sh = 3, vw = 16, vh = 12;
    trio t = trio_new(sw, sh, vw, vh);
    int x, y, c, pass, lo = 0, hi = 0;
    (void)state;
    memset(t.V.buf, 0, (size_t)t.V.im.stride * vh);
    for (pass = 0; pass < 2; pass++) {
        /* pass 0: Q varies along x only; pass 1: along y only. */
        for (y = 0; y < sh; y++)
            for (x = 0; x < sw; x++) {
                uint8_t *q = px(&t.Q.im, x, y);
                for (c = 0; c < 3; c++) q[c] = val[pass ? y : x];
                q[3] = 255;
            }
        assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 0, 0, vw, vh, &t.O.im), FUSE_OK);
        for (y = 0; y < vh; y++)
            for (x = 0; x < vw; x++) {
                int i = pass ? y : x, s = pass ? sh : sw, d = pass ? vh : vw;
                int num = (2 * i + 1) * s - d;          /* 2d * source position */
                const uint8_t *o = px(&t.O.im, x, y);
                if (num <= 0) {
                    assert_int_equal(o[0], val[0]);
                    lo++;
                } else if (num >= 2 * d * (s - 1)) {
                    assert_int_equal(o[0], val[s - 1]);
                    hi++;
                } else if (i == 2 || i == d - 3) {
                    /* the first blended pixel is not the edge value */
                    assert_int_not_equal(o[0], i == 2 ? val[0] : val[s - 1]);
                }
            }
    }
    /* x: columns 0,1 and 14,15 in 12 rows; y: rows 0,1 and 10,11 in 16
     * columns ((2i + 1) 3 - 12 <= 0, resp. >= 2 * 12 * 2). */
    assert_int_equal(lo, 2 * 12 + 2 * 16);
    assert_int_equal(hi, 2 * 12 + 2 * 16);
    trio_free(&t);
}

static void test_in_place(void **state)
{
    tu_rng r = { 0xC0FF0005u };
    trio t = trio_new(37, 29, 90, 70);
    int y;
    (void)state;
    fill_layer(&t.Q.im, &r);
    fill_random(&t.V.im, &r);
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 3, 8, 81, 55, &t.O.im), FUSE_OK);
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 3, 8, 81, 55, &t.V.im), FUSE_OK);
    for (y = 0; y < 70; y++)
        assert_memory_equal(px(&t.O.im, 0, y), px(&t.V.im, 0, y), 4 * 90);
    trio_free(&t);
}

/* Eq. 4 of the paper: a 1194x746 viewport centred in 1280x800 leaves
 * rows 0..26 and 773..799, columns 0..42 and 1237..1279 to V. */
static void test_paper_geometry(void **state)
{
    tu_rng r = { 0xC0FF0006u };
    trio t = trio_new(CAM_W, CAM_H, LCD_W, LCD_H);
    int x, y;
    (void)state;
    assert_int_equal(VP_X, 43);
    assert_int_equal(VP_Y, 27);
    fill_layer(&t.Q.im, &r);
    fill_random(&t.V.im, &r);
    for (y = 0; y < LCD_H; y++)               /* alpha 77: shows what is written */
        for (x = 0; x < LCD_W; x++) px(&t.V.im, x, y)[3] = 77;
    assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, 43, 27, 1194, 746, &t.O.im), FUSE_OK);
    for (y = 0; y < LCD_H; y++)
        for (x = 0; x < LCD_W; x++) {
            int border = y < 27 || y >= 773 || x < 43 || x >= 1237;
            const uint8_t *o = px(&t.O.im, x, y);
            if (border) assert_memory_equal(o, px(&t.V.im, x, y), 4);
            else assert_int_equal(o[3], 255);
        }
    trio_free(&t);
}

/* The exact column walk of the kernel equals the direct formula
 * floor(((2i + 1) src - dst) 65536 / (2 dst)), clamped, for every pixel,
 * including the largest sizes (no overflow, no drift). */
static void test_positions(void **state)
{
    static const int pairs[][2] = { { CAM_W, VP_W }, { CAM_H, VP_H }, { 1, 1 },
                                    { 1, 9 }, { 9, 1 }, { FUSE_MAX_DIM, 3 },
                                    { 3, FUSE_MAX_DIM }, { FUSE_MAX_DIM, FUSE_MAX_DIM },
                                    { FUSE_MAX_DIM - 1, FUSE_MAX_DIM } };
    tu_rng r = { 0xC0FF0009u };
    int k, i;
    (void)state;
    for (k = 0; k < 60; k++) {
        int src = k < 9 ? pairs[k][0] : 1 + tu_int(&r, 3000);
        int dst = k < 9 ? pairs[k][1] : 1 + tu_int(&r, 3000);
        fuse__axis a;
        fuse__axis_init(&a, src, dst);
        for (i = 0; i < dst; i++) {
            int32_t p = fuse__axis_pos(&a);
            double exact = floor(((2.0 * i + 1.0) * src - dst) * 65536.0 / (2.0 * dst));
            if (exact < 0) exact = 0;
            if (exact > 65536.0 * (src - 1)) exact = 65536.0 * (src - 1);
            if (p != fuse__src_pos(i, src, dst) || p != (int32_t)exact) {
                print_error("src %d dst %d i %d: walk %d direct %d exact %.0f\n",
                            src, dst, i, p, fuse__src_pos(i, src, dst), exact);
                fail();
            }
            fuse__axis_next(&a);
        }
    }
    /* 1:1 lands on pixel centres: weight 0. */
    for (i = 0; i < 640; i++) assert_int_equal(fuse__src_pos(i, 640, 640), i << 16);
}

/* ---- validation -------------------------------------------------------- */

static void test_bad_input(void **state)
{
    uint8_t qb[4 * 4 * 4], vb[8 * 6 * 4], ob[8 * 6 * 4], big[16 * 8 * 4], keep[sizeof big];
    fuse_image Q = { qb, 4, 4, 16 }, V = { vb, 8, 6, 32 }, O = { ob, 8, 6, 32 }, X;
    size_t i;
    (void)state;
    memset(qb, 100, sizeof qb);
    memset(vb, 50, sizeof vb);
    memset(ob, 0xEE, sizeof ob);
#define BAD(code, call) do { \
        assert_int_equal((call), (code)); \
        for (i = 0; i < sizeof ob; i++) assert_int_equal(ob[i], 0xEE); \
    } while (0)
    BAD(FUSE_ERR_ARGS, fuse_composite(NULL, &V, 0, 0, 8, 6, &O));
    BAD(FUSE_ERR_ARGS, fuse_composite(&Q, NULL, 0, 0, 8, 6, &O));
    BAD(FUSE_ERR_ARGS, fuse_composite(&Q, &V, 0, 0, 8, 6, NULL));
    X = Q; X.stride = 15;
    BAD(FUSE_ERR_ARGS, fuse_composite(&X, &V, 0, 0, 8, 6, &O));
    X = Q; X.pixels = NULL;
    BAD(FUSE_ERR_ARGS, fuse_composite(&X, &V, 0, 0, 8, 6, &O));
    X = Q; X.height = 0;
    BAD(FUSE_ERR_ARGS, fuse_composite(&X, &V, 0, 0, 8, 6, &O));
    X = Q; X.width = FUSE_MAX_DIM + 1; X.stride = 4 * X.width;
    BAD(FUSE_ERR_ARGS, fuse_composite(&X, &V, 0, 0, 8, 6, &O));
    X = V; X.stride = 31;
    BAD(FUSE_ERR_ARGS, fuse_composite(&Q, &X, 0, 0, 8, 6, &O));
    X = O; X.stride = 28;
    BAD(FUSE_ERR_ARGS, fuse_composite(&Q, &V, 0, 0, 8, 6, &X));
    BAD(FUSE_ERR_ARGS, fuse_composite(&Q, &V, 0, 0, 0, 6, &O));   /* empty viewport */
    BAD(FUSE_ERR_ARGS, fuse_composite(&Q, &V, 0, 0, 8, -1, &O));
    X = O; X.width = 7;                                           /* sizes */
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, 0, 0, 7, 6, &X));
    X = O; X.height = 5;
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, 0, 0, 8, 5, &X));
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, -1, 0, 8, 6, &O));
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, 0, -1, 4, 4, &O));
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, 1, 0, 8, 6, &O));
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, 0, 3, 8, 4, &O));
    BAD(FUSE_ERR_SIZE, fuse_composite(&Q, &V, 0, 0, 9, 6, &O));
    /* out overlapping Q, or V other than exactly. */
    memset(big, 9, sizeof big);
    memcpy(keep, big, sizeof big);
    {
        fuse_image Vb = { big, 8, 4, 64 }, Ob = { big + 4, 8, 4, 64 }, Qb = { big, 4, 4, 64 };
        assert_int_equal(fuse_composite(&Q, &Vb, 0, 0, 8, 4, &Ob), FUSE_ERR_ARGS);
        Ob.stride = 32; Ob.pixels = big;
        assert_int_equal(fuse_composite(&Q, &Vb, 0, 0, 8, 4, &Ob), FUSE_ERR_ARGS);
        Ob = Vb;
        assert_int_equal(fuse_composite(&Qb, &V, 0, 0, 8, 6, &O), FUSE_OK);  /* fine */
        Vb.pixels = vb; Vb.stride = 32;
        Ob.pixels = big + 8;
        assert_int_equal(fuse_composite(&Qb, &Vb, 0, 0, 8, 4, &Ob), FUSE_ERR_ARGS);
        assert_memory_equal(keep, big, sizeof big);
    }
#undef BAD
}

/* ---- RGB24 to RGBA ------------------------------------------------------ */

static void test_rgb24(void **state)
{
    tu_rng r = { 0xC0FF0007u };
    uint8_t rgb[7 * 3 * 5 + 2 * 5], out[8 * 4 * 5], keep[sizeof out];
    fuse_image O = { out, 7, 5, 32 }, X;
    int x, y, c;
    size_t i;
    (void)state;
    for (i = 0; i < sizeof rgb; i++) rgb[i] = (uint8_t)tu_int(&r, 256);
    memset(out, 0xEE, sizeof out);
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 23, 7, 5, &O), FUSE_OK);
    for (y = 0; y < 5; y++) {
        for (x = 0; x < 7; x++) {
            for (c = 0; c < 3; c++) assert_int_equal(out[y * 32 + 4 * x + c], rgb[y * 23 + 3 * x + c]);
            assert_int_equal(out[y * 32 + 4 * x + 3], 255);
        }
        for (c = 28; c < 32; c++) assert_int_equal(out[y * 32 + c], 0xEE);   /* padding */
    }
    memcpy(keep, out, sizeof out);
    assert_int_equal(fuse_rgb24_to_rgba(NULL, 23, 7, 5, &O), FUSE_ERR_ARGS);
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 23, 7, 5, NULL), FUSE_ERR_ARGS);
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 20, 7, 5, &O), FUSE_ERR_ARGS);
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 23, 0, 5, &O), FUSE_ERR_ARGS);
    X = O; X.stride = 27;
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 23, 7, 5, &X), FUSE_ERR_ARGS);
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 23, 6, 5, &O), FUSE_ERR_SIZE);
    assert_int_equal(fuse_rgb24_to_rgba(rgb, 23, 7, 4, &O), FUSE_ERR_SIZE);
    assert_memory_equal(keep, out, sizeof out);
}

/* ---- checksum ----------------------------------------------------------- */

static void test_crc(void **state)
{
    tu_rng r = { 0xC0FF0008u };
    uint32_t crc = 0;
    int k, y;
    (void)state;
    for (k = 0; k < 200; k++) {
        int sw = 1 + tu_int(&r, 48), sh = 1 + tu_int(&r, 48);
        int vw = 1 + tu_int(&r, 96), vh = 1 + tu_int(&r, 96);
        int W = vw + tu_int(&r, 9), H = vh + tu_int(&r, 9);
        int x0 = tu_int(&r, W - vw + 1), y0 = tu_int(&r, H - vh + 1);
        trio t = trio_new(sw, sh, W, H);
        fill_layer(&t.Q.im, &r);
        fill_random(&t.V.im, &r);
        assert_int_equal(fuse_composite(&t.Q.im, &t.V.im, x0, y0, vw, vh, &t.O.im), FUSE_OK);
        for (y = 0; y < H; y++) crc = tu_crc32(crc, px(&t.O.im, 0, y), 4 * (size_t)W);
        trio_free(&t);
    }
    printf("NOTE fuse_composite CRC32 0x%08X (expected 0x%08X)\n", crc, COMPOSITE_CRC);
    assert_int_equal(crc, COMPOSITE_CRC);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_vs_double),
        cmocka_unit_test(test_zero_layer),
        cmocka_unit_test(test_opaque_layer),
        cmocka_unit_test(test_identity_scale),
        cmocka_unit_test(test_edges_replicate),
        cmocka_unit_test(test_in_place),
        cmocka_unit_test(test_paper_geometry),
        cmocka_unit_test(test_positions),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_rgb24),
        cmocka_unit_test(test_crc))
