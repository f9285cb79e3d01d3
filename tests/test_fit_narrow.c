/* test_fit_narrow.c - the band refinement with a narrower band where the
 * hand is thin (src/fit/fit_narrow.h, issue 14 item 2), on a seeded image:
 * a skin-coloured vertical stripe over a noisy blue background, the input
 * mask the stripe widened by 3 px on each side.
 * - a stripe thinner than twice band + margin: band 16 has no hand
 *   samples (out = input); the narrow refinement halves the band to 8,
 *   uses the colour and brings the mask closer to the stripe;
 * - min_band 16 (no halving): the plain refinement's bytes and stats;
 * - a wide stripe: no fallback, the plain refinement's bytes exactly;
 * - the regrow (pipe_fit_refine_regrow): a mask 18 px short of the stripe
 *   on each side (the band reaches 16): the first refinement lets in more
 *   than PIPE_REGROW_PER_MILLE of the image, the second from its result
 *   (the same bytes as a plain refinement of it) brings the last 2 px in;
 *   below the limit, or after a fallback, the refined mask is left as it
 *   is;
 * - the regrow's trail (pipe_fit_regrow_trail): a disc hand moving right by
 *   6 px a frame, the regrow 10 px all round: the pixels within 6 px
 *   behind it (left) are cleared, those ahead and beside it kept; a hand
 *   at rest, an untracked hand, bad arguments clear nothing; 300 seeded
 *   masks (blobs, two hands, random motions and steps) against a direct
 *   reference. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_narrow.h"

enum { W = 160, H = 80 };

static uint8_t img[4 * W * H], mask[W * H], out[W * H], out2[W * H], tmp[W * H];

static unsigned rng = 12345u;
static unsigned rnd(void) { rng = rng * 1664525u + 1013904223u; return rng >> 24; }

/* stripe x0..x1-1 of skin, the mask widened by grow px (< 0: narrower) */
static void scene_grow(int x0, int x1, int grow)
{
    rng = 12345u;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            uint8_t *p = img + 4 * (y * W + x);
            const int skin = x >= x0 && x < x1;
            const unsigned n = rnd() % 16;
            p[0] = (uint8_t)(skin ? 200 + n : 30 + n);
            p[1] = (uint8_t)(skin ? 140 + n : 50 + n);
            p[2] = (uint8_t)(skin ? 110 + n : 160 + n);
            p[3] = 255;
            mask[y * W + x] = (x >= x0 - grow && x < x1 + grow) ? 255 : 0;
        }
}

static void scene(int x0, int x1) { scene_grow(x0, x1, 3); }

static long errors(const uint8_t *m, int x0, int x1)
{
    long e = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) e += (m[y * W + x] >= 128) != (x >= x0 && x < x1);
    return e;
}

static void *scratch;
static size_t scratch_size;

/* fuse_refine_mask of in into o on the scene's image, with the default
 * parameters but a band of band px; fails the test unless FUSE_OK. */
static fuse_refine_stats plain(int band, const uint8_t *in, uint8_t *o)
{
    fuse_refine_params p = fuse_refine_params_default();
    p.band = band;
    fuse_image P = { img, W, H, 4 * W };
    fuse_refine_stats rs;
    assert_int_equal(fuse_refine_mask(&p, &P, in, W, o, W, scratch, scratch_size, &rs), FUSE_OK);
    return rs;
}

/* pipe_fit_refine_narrow (default parameters) of the scene's mask into out
 * with min_band; *band: the band it used. Fails the test unless FUSE_OK. */
static fuse_refine_stats narrow(int min_band, int *band)
{
    const fuse_refine_params p = fuse_refine_params_default();
    fuse_image P = { img, W, H, 4 * W };
    fuse_refine_stats rs;
    assert_int_equal(pipe_fit_refine_narrow(&p, NULL, 0.0f, min_band, &P, mask, W, out, W,
                                            scratch, scratch_size, &rs, band),
                     FUSE_OK);
    return rs;
}

/* pipe_fit_refine_regrow (default parameters) of out, refined with the
 * stats first, tmp its scratch mask: its return value. */
static int regrow(uint8_t *tmp_mask, const fuse_refine_stats *first)
{
    const fuse_refine_params p = fuse_refine_params_default();
    fuse_image P = { img, W, H, 4 * W };
    return pipe_fit_refine_regrow(&p, NULL, 0.0f, &P, out, W, tmp_mask, scratch, scratch_size,
                                  first);
}

static void test_thin_halves(void **st)
{
    (void)st;
    scene(50, 70);   /* 20 px stripe, mask 26 px: nothing deeper than 13 px */
    const int band16 = fuse_refine_params_default().band;
    assert_int_equal(plain(band16, mask, out2).used_colour, 0);
    assert_memory_equal(out2, mask, sizeof mask);
    int band = 0;
    fuse_refine_stats rs = narrow(4, &band);
    assert_int_equal(rs.used_colour, 1);
    assert_int_equal(band, 8);
    assert_true(rs.fg_samples >= fuse_refine_params_default().min_samples);
    const long e_in = errors(mask, 50, 70), e_out = errors(out, 50, 70);
    assert_int_equal(e_in, 6 * H);
    assert_true(e_out * 4 < e_in);
    /* the same as the plain refinement with band 8 */
    plain(8, mask, out2);
    assert_memory_equal(out, out2, sizeof out);
    /* min_band 16: no halving, the fallback's bytes */
    rs = narrow(16, &band);
    assert_int_equal(rs.used_colour, 0);
    assert_int_equal(band, 16);
    assert_memory_equal(out, mask, sizeof mask);
}

static void test_wide_unchanged(void **st)
{
    (void)st;
    scene(30, 90);   /* 60 px: band 16 learns */
    int band = 0;
    const fuse_refine_stats rs = narrow(4, &band);
    assert_int_equal(band, 16);
    assert_int_equal(rs.used_colour, 1);
    plain(fuse_refine_params_default().band, mask, out2);
    assert_memory_equal(out, out2, sizeof out);
    assert_true(errors(out, 30, 90) * 4 < errors(mask, 30, 90));
}

static void test_regrow(void **st)
{
    (void)st;
    scene_grow(30, 130, -18);   /* the hand 18 px beyond the band's 16 */
    const int band16 = fuse_refine_params_default().band;
    fuse_refine_stats rs = plain(band16, mask, out);
    assert_int_equal(rs.used_colour, 1);
    assert_true((double)rs.flipped_in > PIPE_REGROW_PER_MILLE / 1000.0 * W * H);
    const long e1 = errors(out, 30, 130);
    assert_true(e1 >= 3 * H);   /* the band left the last 2 px on each side out */
    /* the plain second refinement, from the first's result */
    plain(band16, out, out2);
    assert_int_equal(regrow(tmp, &rs), 1);
    assert_memory_equal(out, out2, sizeof out);
    assert_true(errors(out, 30, 130) * 4 < e1);
    /* below the limit: left as it is */
    memcpy(out2, out, sizeof out);
    rs.flipped_in = (long)(PIPE_REGROW_PER_MILLE / 1000.0 * W * H);
    assert_int_equal(regrow(tmp, &rs), 0);
    assert_memory_equal(out, out2, sizeof out);
    /* after a fallback: left as it is */
    rs.flipped_in = W * H;
    rs.used_colour = 0;
    assert_int_equal(regrow(tmp, &rs), 0);
    assert_memory_equal(out, out2, sizeof out);
    assert_int_equal(regrow(NULL, &rs), -1);
}

static int in_disc(int x, int y, int cx, int cy, int r)
{
    return (x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r;
}

static void test_trail(void **st)
{
    (void)st;
    static uint8_t first[W * H], reg[W * H], keep[W * H];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            first[y * W + x] = in_disc(x, y, 80, 40, 20) ? 255 : 0;
            reg[y * W + x] = in_disc(x, y, 80, 40, 30) ? 255 : 0;
        }
    memcpy(keep, reg, sizeof reg);
    const float hp[2][2] = { { 80, 40 }, { 0, 0 } };
    const float mv[2][2] = { { 6, 0 }, { 0, 0 } };
    const float fast[2] = { PIPE_TRAIL_SPEED, 0.0f };
    const long n = pipe_fit_regrow_trail(first, W, reg, W, W, H, 1u, hp, mv, fast, 1);
    assert_true(n > 0);
    long cl = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const int was = keep[y * W + x] >= 128, now = reg[y * W + x] >= 128;
            if (first[y * W + x]) assert_int_equal(now, 1);   /* the first's kept */
            if (was && !now) {
                cl++;
                assert_true(x < 80);                            /* behind only */
                assert_true(in_disc(x + 6, y, 80, 40, 20));     /* within 6 px of it */
            }
        }
    assert_int_equal(cl, n);
    assert_int_equal(reg[40 * W + 57], 0);      /* 3 px behind: cleared */
    assert_int_equal(reg[40 * W + 103], 255);   /* 3 px ahead: kept */
    assert_int_equal(reg[17 * W + 80], 255);    /* 3 px beside: kept */
    assert_int_equal(reg[40 * W + 52], 255);    /* 8 px behind, beyond 1 step: kept */
    /* two steps reach 12 px behind */
    memcpy(reg, keep, sizeof reg);
    assert_true(pipe_fit_regrow_trail(first, W, reg, W, W, H, 1u, hp, mv, fast, 2) > n);
    assert_int_equal(reg[40 * W + 52], 0);
    /* at rest, untracked, bad arguments: nothing cleared */
    const float rest[2][2] = { { 0.4f, -0.3f }, { 0, 0 } };
    memcpy(reg, keep, sizeof reg);
    assert_int_equal(pipe_fit_regrow_trail(first, W, reg, W, W, H, 1u, hp, rest, fast, 1), 0);
    assert_int_equal(pipe_fit_regrow_trail(first, W, reg, W, W, H, 2u, hp, mv, fast, 1), 0);
    const float slow[2] = { 0.5f * PIPE_TRAIL_SPEED, 0.0f };   /* slower than the gate */
    assert_int_equal(pipe_fit_regrow_trail(first, W, reg, W, W, H, 1u, hp, mv, slow, 1), 0);
    assert_int_equal(pipe_fit_regrow_trail(first, W, reg, W, W, H, 1u, hp, mv, fast, 0), -1);
    assert_int_equal(pipe_fit_regrow_trail(NULL, W, reg, W, W, H, 1u, hp, mv, fast, 1), -1);
    assert_int_equal(pipe_fit_regrow_trail(first, W - 1, reg, W, W, H, 1u, hp, mv, fast, 1), -1);
    assert_memory_equal(reg, keep, sizeof reg);
}

/* the rule written out directly (fit_narrow.h) */
static long trail_ref(const uint8_t *first, uint8_t *reg, unsigned sides, const float hp[2][2],
                      const float mv[2][2], int steps)
{
    static uint8_t src[W * H];
    memcpy(src, reg, sizeof src);
    long n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            if (src[y * W + x] < 128 || first[y * W + x] >= 128) continue;
            int k = -1;
            double best = 1e30;
            for (int j = 0; j < 2; j++) {
                if (!(sides & (1u << j))) continue;
                const double d2 = (x - hp[j][0]) * (x - hp[j][0]) + (y - hp[j][1]) * (y - hp[j][1]);
                if (d2 < best) { best = d2; k = j; }
            }
            if (k < 0) continue;
            const int dx = (int)lrintf(mv[k][0]), dy = (int)lrintf(mv[k][1]);
            if (!dx && !dy) continue;
            int behind = 0, ahead = 0;
            for (int j = 1; j <= steps; j++) {
                const int bx = x + j * dx, by = y + j * dy, ax = x - j * dx, ay = y - j * dy;
                if (bx >= 0 && by >= 0 && bx < W && by < H && first[by * W + bx] >= 128) behind = 1;
                if (ax >= 0 && ay >= 0 && ax < W && ay < H && first[ay * W + ax] >= 128) ahead = 1;
            }
            if (behind && !ahead) {
                reg[y * W + x] = 0;
                n++;
            }
        }
    return n;
}

static void test_trail_reference(void **st)
{
    (void)st;
    static uint8_t first[W * H], a[W * H], b[W * H];
    rng = 777u;
    long total = 0;
    for (int c = 0; c < 300; c++) {
        memset(first, 0, sizeof first);
        memset(a, 0, sizeof a);
        const int nb = 1 + (int)(rnd() % 4);
        for (int i = 0; i < nb; i++) {
            const int cx = (int)(rnd() * W / 256), cy = (int)(rnd() * H / 256);
            const int r = 4 + (int)(rnd() % 20), g = 1 + (int)(rnd() % 12);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    if (in_disc(x, y, cx, cy, r)) first[y * W + x] = (uint8_t)(128 + rnd() % 128);
                    if (in_disc(x, y, cx, cy, r + g)) a[y * W + x] = (uint8_t)(128 + rnd() % 128);
                }
        }
        for (int i = 0; i < W * H; i++)
            if (rnd() < 4) a[i] = (uint8_t)rnd();   /* specks, values below 128 too */
        float hp[2][2], mv[2][2];
        for (int k = 0; k < 2; k++) {
            hp[k][0] = (float)(rnd() * W / 256);
            hp[k][1] = (float)(rnd() * H / 256);
            mv[k][0] = ((float)rnd() - 128.0f) / 12.0f;
            mv[k][1] = ((float)rnd() - 128.0f) / 12.0f;
        }
        const unsigned sides = rnd() % 4;
        const int steps = 1 + (int)(rnd() % 3);
        memcpy(b, a, sizeof a);
        const long na = pipe_fit_regrow_trail(first, W, a, W, W, H, sides, hp, mv, NULL, steps);
        const long nb2 = trail_ref(first, b, sides, hp, mv, steps);
        assert_int_equal(na, nb2);
        assert_memory_equal(a, b, sizeof a);
        total += na;
    }
    assert_true(total > 1000);   /* the cases do clear pixels */
}

int main(void)
{
    fuse_refine_params p = fuse_refine_params_default();
    scratch_size = fuse_refine_scratch_size(&p, W, H);
    scratch = malloc(scratch_size);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_thin_halves),
        cmocka_unit_test(test_wide_unchanged),
        cmocka_unit_test(test_regrow),
        cmocka_unit_test(test_trail),
        cmocka_unit_test(test_trail_reference),
    };
    const int r = cmocka_run_group_tests(tests, NULL, NULL);
    free(scratch);
    return r;
}
