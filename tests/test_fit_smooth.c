/* test_fit_smooth.c - the refined mask's 3x3 closing then opening
 * (src/fit/fit_smooth.h, issue 14 item 2), on seeded masks against a
 * direct reference (the mask made 0/255 at 128, then each output pixel
 * the min / max over its 3x3 window, pixels outside the image 0 for a
 * dilation and 255 for an erosion):
 * - 300 seeded masks (discs, notches, specks, set values 128..255, masks touching
 *   the border, empty rows above and below) equal to the reference;
 * - every other one with a mask `inside` (the closing adds pixels only
 *   where it is set);
 * - a disc with a 1-px crack and a 1-px spur: both gone; a gap of 4 px
 *   between two blocks and a 4x4 island: kept;
 * - bad arguments and a scratch too small: -1, the mask as it was. */
#include "support/testutil.h"

#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_smooth.h"

enum { W = 141, H = 37, S = 150 };   /* 3 words a row, the last partial */

static uint8_t m[S * H], orig[S * H], ins[S * H];

static uint64_t rng = 0x9E3779B97F4A7C15ull;
static uint32_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (uint32_t)(rng >> 11);
}

/* one 3x3 min or max of a (W x H, stride W) into b */
static void ref_step(const uint8_t *a, uint8_t *b, int dil)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int v = dil ? 0 : 255;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    const int xx = x + dx, yy = y + dy;
                    const int s = xx < 0 || yy < 0 || xx >= W || yy >= H
                                      ? (dil ? 0 : 255)
                                      : a[yy * W + xx];
                    v = dil ? (s > v ? s : v) : (s < v ? s : v);
                }
            b[y * W + x] = (uint8_t)v;
        }
}

static void reference(const uint8_t *in, const uint8_t *inside, uint8_t *out)
{
    uint8_t a[W * H], b[W * H];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) a[y * W + x] = in[y * S + x] >= 128 ? 255 : 0;
    ref_step(a, b, 1);
    ref_step(b, a, 0);
    if (inside)   /* the closing's new pixels only inside */
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                if (in[y * S + x] < 128 && inside[y * S + x] < 128) a[y * W + x] = 0;
    ref_step(a, b, 0);
    ref_step(b, out, 1);
}

static void against_reference(void **state)
{
    (void)state;
    const size_t sz = pipe_fit_smooth_scratch_size(W, H);
    assert_true(sz > 0);
    void *scratch = malloc(sz);
    assert_non_null(scratch);
    uint8_t want[W * H];
    for (int it = 0; it < 300; it++) {
        memset(orig, 0, sizeof orig);
        const int nd = 1 + (int)(next() % 4), grey = it % 5 == 4;
        for (int k = 0; k < nd; k++) {
            const int cx = (int)(next() % (W + 10)) - 5, cy = (int)(next() % (H + 10)) - 5,
                      r = 2 + (int)(next() % 12);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++)
                    if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r)
                        orig[y * S + x] = grey ? (uint8_t)(128 + next() % 128) : 255;
        }
        /* notches and specks: single pixels flipped */
        const int nf = (int)(next() % 60);
        for (int k = 0; k < nf; k++) {
            uint8_t *p = &orig[(int)(next() % H) * S + (int)(next() % W)];
            *p = *p ? 0 : 255;
        }
        /* the padding between rows must not be read or written */
        for (int y = 0; y < H; y++) memset(orig + y * S + W, 0xA5, S - W);
        /* every other mask: the closing only inside a disc */
        const int use_in = it % 2;
        if (use_in) {
            const int cx = (int)(next() % W), cy = (int)(next() % H), r = 5 + (int)(next() % 20);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < S; x++)
                    ins[y * S + x] = (x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r ? 200 : 7;
        }
        memcpy(m, orig, sizeof m);
        assert_int_equal(pipe_fit_smooth(m, S, W, H, use_in ? ins : NULL, S, scratch, sz), 0);
        reference(orig, use_in ? ins : NULL, want);
        for (int y = 0; y < H; y++) {
            assert_memory_equal(m + y * S, want + y * W, W);
            assert_memory_equal(m + y * S + W, orig + y * S + W, S - W);
        }
    }
    free(scratch);
}

static void cracks_and_gaps(void **state)
{
    (void)state;
    const size_t sz = pipe_fit_smooth_scratch_size(W, H);
    void *scratch = malloc(sz);
    assert_non_null(scratch);
    memset(orig, 0, sizeof orig);
    /* a disc at (15, 18) r 10 with a 1-px crack into it and a 1-px spur */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < 30; x++)
            if ((x - 15) * (x - 15) + (y - 18) * (y - 18) <= 100) orig[y * S + x] = 255;
    for (int x = 15; x < 26; x++) orig[18 * S + x] = 0;   /* crack */
    for (int y = 4; y < 8; y++) orig[y * S + 15] = 255;   /* spur above */
    /* two blocks 4 px apart, and a 4x4 island */
    for (int y = 2; y < 12; y++)
        for (int x = 34; x < 52; x++)
            if (x < 40 || x >= 44) orig[y * S + x] = 255;
    for (int y = 25; y < 29; y++)
        for (int x = 40; x < 44; x++) orig[y * S + x] = 255;
    memcpy(m, orig, sizeof m);
    assert_int_equal(pipe_fit_smooth(m, S, W, H, NULL, 0, scratch, sz), 0);
    for (int x = 15; x < 24; x++) assert_int_equal(m[18 * S + x], 255);
    for (int y = 4; y < 7; y++) assert_int_equal(m[y * S + 15], 0);
    for (int y = 3; y < 11; y++)
        for (int x = 34; x < 52; x++) assert_int_equal(m[y * S + x], (x < 40 || x >= 44) ? 255 : 0);
    for (int y = 25; y < 29; y++)
        for (int x = 40; x < 44; x++) assert_int_equal(m[y * S + x], 255);
    /* an empty mask stays empty; a full one full */
    memset(m, 0, sizeof m);
    assert_int_equal(pipe_fit_smooth(m, S, W, H, NULL, 0, scratch, sz), 0);
    for (int i = 0; i < S * H; i++) assert_int_equal(m[i], 0);
    memset(m, 255, sizeof m);
    assert_int_equal(pipe_fit_smooth(m, S, W, H, NULL, 0, scratch, sz), 0);
    for (int i = 0; i < S * H; i++) assert_int_equal(m[i], 255);
    /* bad arguments, scratch too small: the mask as it was */
    memcpy(m, orig, sizeof m);
    assert_int_equal(pipe_fit_smooth(m, S, W, H, NULL, 0, scratch, sz - 1), -1);
    assert_int_equal(pipe_fit_smooth(m, W - 1, W, H, NULL, 0, scratch, sz), -1);
    assert_int_equal(pipe_fit_smooth(NULL, S, W, H, NULL, 0, scratch, sz), -1);
    assert_int_equal(pipe_fit_smooth(m, S, W, H, NULL, 0, NULL, sz), -1);
    assert_int_equal(pipe_fit_smooth(m, S, W, H, orig, W - 1, scratch, sz), -1);
    assert_memory_equal(m, orig, sizeof m);
    assert_int_equal(pipe_fit_smooth_scratch_size(0, H), 0);
    free(scratch);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(against_reference),
        cmocka_unit_test(cracks_and_gaps))
