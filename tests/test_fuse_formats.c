/* test_fuse_formats.c - fuse_frame_to_rgba: YUYV/UYVY against hand-worked
 * pixels and the double-precision BT.601 matrix (every Y, U, V), GREY,
 * RGB24/BGR24, the four Bayer patterns against a double-precision bilinear
 * demosaic written here and on linear ramps, the eq. 1 crop (rows next to
 * the crop are used), padded strides, and bad input (nothing written). */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse.h"

static uint8_t *px(const fuse_image *im, int x, int y)
{
    return im->pixels + (size_t)y * im->stride + 4 * (size_t)x;
}

static fuse_frame frame(const uint8_t *d, size_t size, int w, int h, int stride, fuse_format f)
{
    return (fuse_frame){d, size, w, h, stride, f};
}

/* Converts the frame (d, size, w x h, stride, format f) from row y0 into
 * o; fails the test unless FUSE_OK. */
static void convert(const uint8_t *d, size_t size, int w, int h, int stride, fuse_format f,
                    int y0, fuse_image *o)
{
    fuse_frame s = frame(d, size, w, h, stride, f);
    assert_int_equal(fuse_frame_to_rgba(&s, y0, o), FUSE_OK);
}

static void expect_px(const fuse_image *o, int x, int y, int r, int g, int b)
{
    const uint8_t *p = px(o, x, y);
    if (p[0] != r || p[1] != g || p[2] != b || p[3] != 255) {
        print_error("pixel (%d,%d): got %d %d %d %d, want %d %d %d 255\n", x, y,
                    p[0], p[1], p[2], p[3], r, g, b);
        fail();
    }
}

/* ---- YUV ---------------------------------------------------------------- */

static void test_yuyv_hand(void **state)
{
    /* black, white, mid grey, BT.601 red (81, 90, 240): 2 pairs per row */
    const uint8_t yuyv[] = { 16, 128, 235, 128,   128, 128, 128, 128,
                             81, 90, 81, 240,     0, 0, 0, 0 };   /* row 1 */
    const uint8_t uyvy[] = { 128, 16, 128, 235,   128, 128, 128, 128,
                             90, 81, 240, 81,     0, 0, 0, 0 };
    uint8_t buf[4 * 4 * 2];
    fuse_image o = { buf, 4, 2, 16 };
    (void)state;
    convert(yuyv, sizeof yuyv, 4, 2, 8, FUSE_FMT_YUYV, 0, &o);
    expect_px(&o, 0, 0, 0, 0, 0);
    expect_px(&o, 1, 0, 255, 255, 255);        /* 298 * 219 + 128 >> 8 = 255 */
    expect_px(&o, 2, 0, 130, 130, 130);        /* (128 - 16) 255 / 219 = 130.4 */
    expect_px(&o, 0, 1, 255, 0, 0);            /* the red of BT.601 */
    expect_px(&o, 1, 1, 255, 0, 0);
    /* U = V = 0, Y = 0: 298 * -16 + 409 * -128 < 0 -> 0; G = ... + 100*128 + 208*128 */
    expect_px(&o, 2, 1, 0, (298 * -16 + 100 * 128 + 208 * 128 + 128) >> 8, 0);
    {
        uint8_t buf2[sizeof buf];
        fuse_image o2 = { buf2, 4, 2, 16 };
        convert(uyvy, sizeof uyvy, 4, 2, 8, FUSE_FMT_UYVY, 0, &o2);
        assert_memory_equal(buf, buf2, sizeof buf);
    }
}

/* Every (Y, U, V) against the BT.601 limited-range matrix in double:
 * within 1 of the rounded value (docs/fuse.md gives the figures). */
static void test_yuv_vs_double(void **state)
{
    uint8_t row[4 * 256], out[4 * 4 * 256];
    fuse_image o = { out, 2 * 256, 1, 4 * 2 * 256 };
    const double k = 255.0 / 219.0, cs = 255.0 / 224.0, kr = 0.299, kb = 0.114, kg = 1 - kr - kb;
    double max_err = 0;
    long ones = 0, n = 0;
    int Y, U, V, c;
    (void)state;
    for (U = 0; U < 256; U++)
        for (V = 0; V < 256; V++) {
            fuse_frame s = frame(row, sizeof row, 2 * 256, 1, sizeof row, FUSE_FMT_YUYV);
            for (Y = 0; Y < 256; Y++) {   /* pair Y: (Y, U, Y, V) */
                row[4 * Y] = (uint8_t)Y;
                row[4 * Y + 1] = (uint8_t)U;
                row[4 * Y + 2] = (uint8_t)Y;
                row[4 * Y + 3] = (uint8_t)V;
            }
            s.size = 4 * 256;
            s.stride = 4 * 256;
            assert_int_equal(fuse_frame_to_rgba(&s, 0, &o), FUSE_OK);
            for (Y = 0; Y < 256; Y++) {
                const double C = Y - 16, D = U - 128, E = V - 128;
                const double ref[3] = { k * C + cs * 2 * (1 - kr) * E,
                                        k * C - cs * 2 * (1 - kb) * kb / kg * D - cs * 2 * (1 - kr) * kr / kg * E,
                                        k * C + cs * 2 * (1 - kb) * D };
                const uint8_t *p = out + 8 * Y;
                assert_memory_equal(p, p + 4, 4);   /* both pixels of the pair */
                for (c = 0; c < 3; c++) {
                    const double x = fmin(255, fmax(0, ref[c]));
                    const double e = fabs(p[c] - x);
                    const long d = labs((long)p[c] - (long)floor(x + 0.5));
                    if (e > max_err) max_err = e;
                    if (d > 1) {
                        print_error("YUV %d %d %d ch %d: got %d, double %.3f\n", Y, U, V, c, p[c], x);
                        fail();
                    }
                    ones += d;
                    n++;
                }
            }
        }
    printf("NOTE YUV->RGB vs double BT.601: max error %.3f LSB, %ld of %ld channels off by 1\n",
           max_err, ones, n);
    assert_true(max_err < 1.0);
}

static void test_grey_rgb(void **state)
{
    const uint8_t grey[] = { 0, 7, 255, 9, /* pad */ 1, 2, 3, 4, 5, 6, 99, 99 };
    const uint8_t rgb[] = { 1, 2, 3, 4, 5, 6, 200, 201, 202 };
    uint8_t buf[4 * 4 * 2];
    fuse_image o = { buf, 3, 2, 16 };
    (void)state;
    convert(grey, sizeof grey, 3, 2, 6, FUSE_FMT_GREY, 0, &o);
    expect_px(&o, 0, 0, 0, 0, 0);
    expect_px(&o, 1, 0, 7, 7, 7);
    expect_px(&o, 2, 0, 255, 255, 255);
    expect_px(&o, 0, 1, 3, 3, 3);   /* row 1 starts at byte 6 */
    expect_px(&o, 2, 1, 5, 5, 5);
    o.height = 1;
    convert(rgb, sizeof rgb, 3, 1, 9, FUSE_FMT_RGB24, 0, &o);
    expect_px(&o, 0, 0, 1, 2, 3);
    expect_px(&o, 2, 0, 200, 201, 202);
    convert(rgb, sizeof rgb, 3, 1, 9, FUSE_FMT_BGR24, 0, &o);
    expect_px(&o, 0, 0, 3, 2, 1);
    expect_px(&o, 1, 0, 6, 5, 4);
    assert_int_equal(fuse_format_row_bytes(FUSE_FMT_RGB24, 640), 1920);
    assert_int_equal(fuse_format_row_bytes(FUSE_FMT_YUYV, 640), 1280);
    assert_int_equal(fuse_format_row_bytes((fuse_format)99, 640), 0);
}

/* ---- Bayer --------------------------------------------------------------- */

/* colour of (x, y) for pattern index f (RGGB, GRBG, GBRG, BGGR) */
static int pat_colour(int f, int x, int y)
{
    static const int pats[4][4] = { { 0, 1, 1, 2 }, { 1, 0, 2, 1 }, { 1, 2, 0, 1 }, { 2, 1, 1, 0 } };
    return pats[f][((y & 1) << 1) | (x & 1)];
}

static int mir(int i, int n) { return i < 0 ? -i : i >= n ? 2 * (n - 1) - i : i; }

/* Bilinear demosaic in double: a channel present at the pixel is copied;
 * otherwise the mean of that colour's samples among the 4 edge neighbours
 * if there are any, else among the 4 diagonal ones (mirrored at borders);
 * rounded half up. */
static int ref_demosaic(const uint8_t *raw, int w, int h, int f, int x, int y, int c)
{
    static const int nb[2][4][2] = { { { 1, 0 }, { -1, 0 }, { 0, 1 }, { 0, -1 } },
                                     { { 1, 1 }, { -1, 1 }, { 1, -1 }, { -1, -1 } } };
    int set, k;
    if (pat_colour(f, x, y) == c) return raw[y * w + x];
    for (set = 0; set < 2; set++) {
        double sum = 0;
        int cnt = 0;
        for (k = 0; k < 4; k++) {
            const int xx = x + nb[set][k][0], yy = y + nb[set][k][1];
            if (pat_colour(f, xx & 1, yy & 1) != c) continue;   /* phase of the unmirrored spot */
            sum += raw[mir(yy, h) * w + mir(xx, w)];
            cnt++;
        }
        if (cnt) return (int)floor(sum / cnt + 0.5);
    }
    return -1;
}

static void test_bayer_vs_double(void **state)
{
    tu_rng r = { 0xBA7E5u };
    static const fuse_format fmts[4] = { FUSE_FMT_BAYER_RGGB, FUSE_FMT_BAYER_GRBG,
                                         FUSE_FMT_BAYER_GBRG, FUSE_FMT_BAYER_BGGR };
    int f, k;
    (void)state;
    for (k = 0; k < 24; k++)
        for (f = 0; f < 4; f++) {
            const int w = 2 + tu_int(&r, 40), h = 2 + tu_int(&r, 20), pad = tu_int(&r, 5);
            uint8_t *raw = malloc((size_t)w * h), *src = malloc((size_t)(w + pad) * h);
            uint8_t *out = malloc((size_t)w * h * 4 + 16);
            fuse_image o = { out, w, h, 4 * w };
            int x, y, c;
            assert_true(raw && src && out);
            for (x = 0; x < w * h; x++) raw[x] = (uint8_t)tu_int(&r, 256);
            for (y = 0; y < h; y++) {
                memcpy(src + (size_t)y * (w + pad), raw + (size_t)y * w, (size_t)w);
                memset(src + (size_t)y * (w + pad) + w, 0xEE, (size_t)pad);
            }
            convert(src, (size_t)(w + pad) * h, w, h, w + pad, fmts[f], 0, &o);
            for (y = 0; y < h; y++)
                for (x = 0; x < w; x++) {
                    for (c = 0; c < 3; c++) {
                        const int want = ref_demosaic(raw, w, h, f, x, y, c);
                        if (px(&o, x, y)[c] != want) {
                            print_error("fmt %d %dx%d pixel (%d,%d) ch %d: got %d want %d\n",
                                        f, w, h, x, y, c, px(&o, x, y)[c], want);
                            fail();
                        }
                    }
                    assert_int_equal(px(&o, x, y)[3], 255);
                }
            free(raw);
            free(src);
            free(out);
        }
}

/* A linear ramp survives bilinear demosaicing in the interior (the mean
 * of symmetric samples of a linear function is its centre value). */
static void test_bayer_ramp(void **state)
{
    enum { W = 32, H = 16 };
    uint8_t raw[W * H], out[W * H * 4];
    fuse_image o = { out, W, H, 4 * W };
    int f, x, y;
    (void)state;
    for (f = 0; f < 4; f++) {
        for (y = 0; y < H; y++)
            for (x = 0; x < W; x++) {
                const int c = pat_colour(f, x, y);
                raw[y * W + x] = (uint8_t)(c == 0 ? 4 * x + 2 * y : c == 1 ? 100 + 2 * x + 3 * y : 200 - 3 * x - 2 * y);
            }
        convert(raw, sizeof raw, W, H, W, (fuse_format)(FUSE_FMT_BAYER_RGGB + f), 0, &o);
        for (y = 1; y < H - 1; y++)
            for (x = 1; x < W - 1; x++) {
                expect_px(&o, x, y, 4 * x + 2 * y, 100 + 2 * x + 3 * y, 200 - 3 * x - 2 * y);
            }
    }
}

/* Crop (eq. 1): rows 40..439 of a 640x480 frame equal the same rows of
 * the full conversion, for every format (Bayer reads the rows beside the
 * crop, so the cut rows are not mirrored). */
static void test_crop(void **state)
{
    enum { W = 640, H = 480, Y0 = 40, CH = 400 };
    tu_rng r = { 0xC209u };
    const int stride = 3 * W + 8;
    uint8_t *src = malloc((size_t)stride * H), *full = malloc((size_t)W * H * 4), *crop = malloc((size_t)W * CH * 4);
    int f, i;
    (void)state;
    assert_true(src && full && crop);
    for (i = 0; i < stride * H; i++) src[i] = (uint8_t)tu_int(&r, 256);
    for (f = FUSE_FMT_YUYV; f <= FUSE_FMT_BGR24; f++) {
        fuse_image F = { full, W, H, 4 * W }, C = { crop, W, CH, 4 * W };
        convert(src, (size_t)stride * H, W, H, stride, (fuse_format)f, 0, &F);
        convert(src, (size_t)stride * H, W, H, stride, (fuse_format)f, Y0, &C);
        assert_memory_equal(crop, full + (size_t)Y0 * 4 * W, (size_t)W * CH * 4);
    }
    free(src);
    free(full);
    free(crop);
}

static void test_bad_input(void **state)
{
    uint8_t src[64 * 8], out[64 * 8 * 4], copy[sizeof out];
    fuse_image o = { out, 8, 4, 32 };
    fuse_frame s = frame(src, sizeof src, 8, 4, 16, FUSE_FMT_YUYV);
    (void)state;
    memset(src, 100, sizeof src);
    memset(out, 0x3C, sizeof out);
    memcpy(copy, out, sizeof out);
#define BAD(expr, err) do { fuse_frame t = s; fuse_image u = o; (void)t; (void)u; expr; \
        assert_int_equal(fuse_frame_to_rgba(&t, 0, &u), err); \
        assert_memory_equal(out, copy, sizeof out); } while (0)
    BAD(t.data = NULL, FUSE_ERR_ARGS);
    BAD(t.format = (fuse_format)0, FUSE_ERR_ARGS);
    BAD(t.format = (fuse_format)77, FUSE_ERR_ARGS);
    BAD((t.width = 7, u.width = 7), FUSE_ERR_ARGS);              /* odd YUYV */
    BAD((t.width = 7, u.width = 7, t.format = FUSE_FMT_UYVY), FUSE_ERR_ARGS);
    BAD(t.stride = 15, FUSE_ERR_ARGS);                           /* < 2 * 8 */
    BAD(t.width = 0, FUSE_ERR_ARGS);
    BAD(t.height = 0, FUSE_ERR_ARGS);
    BAD((t.width = FUSE_MAX_DIM + 2, t.stride = 2 * (FUSE_MAX_DIM + 2)), FUSE_ERR_ARGS);
    BAD((t.format = FUSE_FMT_BAYER_RGGB, t.height = 1, u.height = 1), FUSE_ERR_ARGS);
    BAD((t.format = FUSE_FMT_BAYER_GBRG, t.width = 1, u.width = 1), FUSE_ERR_ARGS);
    BAD(t.size = 3 * 16 + 15, FUSE_ERR_SIZE);                    /* one byte short */
    BAD((t.format = FUSE_FMT_RGB24, t.stride = 24, t.size = 3 * 24 + 23), FUSE_ERR_SIZE);
    BAD(u.width = 6, FUSE_ERR_SIZE);                             /* out of another width */
    BAD(u.height = 5, FUSE_ERR_SIZE);                            /* crop beyond the frame */
    BAD(u.stride = 31, FUSE_ERR_ARGS);
    BAD(u.pixels = NULL, FUSE_ERR_ARGS);
    BAD(u.pixels = (uint8_t *)src, FUSE_ERR_ARGS);               /* overlaps the frame */
    {
        fuse_image u = o;
        u.height = 2;
        assert_int_equal(fuse_frame_to_rgba(&s, 3, &u), FUSE_ERR_SIZE);
        assert_int_equal(fuse_frame_to_rgba(&s, -1, &u), FUSE_ERR_SIZE);
        assert_int_equal(fuse_frame_to_rgba(NULL, 0, &u), FUSE_ERR_ARGS);
        assert_int_equal(fuse_frame_to_rgba(&s, 0, NULL), FUSE_ERR_ARGS);
        assert_memory_equal(out, copy, sizeof out);
        assert_int_equal(fuse_frame_to_rgba(&s, 2, &u), FUSE_OK);   /* exact fit */
        s.size = 3 * 16 + 16;
        assert_int_equal(fuse_frame_to_rgba(&s, 2, &u), FUSE_OK);   /* size exact */
    }
#undef BAD
}

/* The SIMD YUYV/UYVY rows give the reference's bytes: AVX2's 16-bit
 * kernel (AVX2, AVX-512) and the vector layer's (SSE2, NEON: under
 * qemu-aarch64), each path the CPU has: seeded random frames of every even
 * width up to 70 and the camera's 640, odd offsets; every Y, U, V corner
 * value (clamping at both ends). */
static void test_yuv_isa(void **state)
{
    static const ef_isa isas[] = {EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON};
    int ran = 0;
    (void)state;
    for (int k = 0; k < 4; k++) {
        const ef_isa isa = isas[k];
        if (ef_isa_choose(isa) != isa) {
            printf("SKIP yuv %s: not on this CPU\n", ef_isa_name(isa));
            continue;
        }
        ran++;
        tu_rng r = {77};
        uint32_t crc = 0;
        for (int fmt = 0; fmt < 2; fmt++)
            for (int w = 2; w <= 642; w += (w < 70 ? 2 : 572)) {
                const int h = 5;
                uint8_t *src = malloc((size_t)(2 * w + 6) * h);
                uint8_t *a = malloc((size_t)4 * w * 3), *b = malloc((size_t)4 * w * 3);
                for (int i = 0; i < (2 * w + 6) * h; i++) src[i] = (uint8_t)tu_next(&r);
                fuse_frame f = {src + 1, (size_t)(2 * w + 6) * h - 1, w, h, 2 * w + 5,
                                fmt ? FUSE_FMT_UYVY : FUSE_FMT_YUYV};
                fuse_image ia = {a, w, 3, 4 * w}, ib = {b, w, 3, 4 * w};
                assert_int_equal(fuse_frame_to_rgba_isa(&f, 1, &ia, EF_ISA_REF), FUSE_OK);
                assert_int_equal(fuse_frame_to_rgba_isa(&f, 1, &ib, isa), FUSE_OK);
                assert_memory_equal(a, b, (size_t)4 * w * 3);
                crc = tu_crc32(crc, a, (size_t)4 * w * 3);
                free(src);
                free(a);
                free(b);
            }
        static const uint8_t corner[16 * 2] = {0, 0, 255, 0, 0, 255, 255, 255, 16, 128, 235, 128,
                                               255, 0, 0, 255, 16, 240, 235, 16, 1, 2, 254, 253,
                                               128, 128, 128, 128, 0, 128, 255, 128};
        for (int fmt = 0; fmt < 2; fmt++) {
            uint8_t a[64], b[64];
            fuse_frame f = {corner, sizeof corner, 16, 1, 32, fmt ? FUSE_FMT_UYVY : FUSE_FMT_YUYV};
            fuse_image ia = {a, 16, 1, 64}, ib = {b, 16, 1, 64};
            assert_int_equal(fuse_frame_to_rgba_isa(&f, 0, &ia, EF_ISA_REF), FUSE_OK);
            assert_int_equal(fuse_frame_to_rgba_isa(&f, 0, &ib, isa), FUSE_OK);
            assert_memory_equal(a, b, sizeof a);
        }
        printf("NOTE yuv %s: reference bytes, CRC32 0x%08X\n", ef_isa_name(isa), (unsigned)crc);
    }
    if (ran == 0) skip();
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_yuyv_hand),
        cmocka_unit_test(test_yuv_vs_double),
        cmocka_unit_test(test_grey_rgb),
        cmocka_unit_test(test_bayer_vs_double),
        cmocka_unit_test(test_bayer_ramp),
        cmocka_unit_test(test_crop),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_yuv_isa))
