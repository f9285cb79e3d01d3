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
 *   is. */
#include "support/testutil.h"

#include <cmocka.h>
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

static void test_thin_halves(void **st)
{
    (void)st;
    scene(50, 70);   /* 20 px stripe, mask 26 px: nothing deeper than 13 px */
    fuse_refine_params p = fuse_refine_params_default();
    fuse_image P = { img, W, H, 4 * W };
    fuse_refine_stats rs, rs2;
    assert_int_equal(fuse_refine_mask(&p, &P, mask, W, out2, W, scratch, scratch_size, &rs2),
                     FUSE_OK);
    assert_int_equal(rs2.used_colour, 0);
    assert_memory_equal(out2, mask, sizeof mask);
    int band = 0;
    assert_int_equal(pipe_fit_refine_narrow(&p, NULL, 0.0f, 4, &P, mask, W, out, W, scratch,
                                            scratch_size, &rs, &band),
                     FUSE_OK);
    assert_int_equal(rs.used_colour, 1);
    assert_int_equal(band, 8);
    assert_true(rs.fg_samples >= p.min_samples);
    const long e_in = errors(mask, 50, 70), e_out = errors(out, 50, 70);
    assert_int_equal(e_in, 6 * H);
    assert_true(e_out * 4 < e_in);
    /* the same as the plain refinement with band 8 */
    fuse_refine_params p8 = p;
    p8.band = 8;
    assert_int_equal(fuse_refine_mask(&p8, &P, mask, W, out2, W, scratch, scratch_size, &rs2),
                     FUSE_OK);
    assert_memory_equal(out, out2, sizeof out);
    /* min_band 16: no halving, the fallback's bytes */
    assert_int_equal(pipe_fit_refine_narrow(&p, NULL, 0.0f, 16, &P, mask, W, out, W, scratch,
                                            scratch_size, &rs, &band),
                     FUSE_OK);
    assert_int_equal(rs.used_colour, 0);
    assert_int_equal(band, 16);
    assert_memory_equal(out, mask, sizeof mask);
}

static void test_wide_unchanged(void **st)
{
    (void)st;
    scene(30, 90);   /* 60 px: band 16 learns */
    fuse_refine_params p = fuse_refine_params_default();
    fuse_image P = { img, W, H, 4 * W };
    fuse_refine_stats rs, rs2;
    int band = 0;
    assert_int_equal(pipe_fit_refine_narrow(&p, NULL, 0.0f, 4, &P, mask, W, out, W, scratch,
                                            scratch_size, &rs, &band),
                     FUSE_OK);
    assert_int_equal(band, 16);
    assert_int_equal(rs.used_colour, 1);
    assert_int_equal(fuse_refine_mask(&p, &P, mask, W, out2, W, scratch, scratch_size, &rs2),
                     FUSE_OK);
    assert_memory_equal(out, out2, sizeof out);
    assert_true(errors(out, 30, 90) * 4 < errors(mask, 30, 90));
}

static void test_regrow(void **st)
{
    (void)st;
    scene_grow(30, 130, -18);   /* the hand 18 px beyond the band's 16 */
    fuse_refine_params p = fuse_refine_params_default();
    fuse_image P = { img, W, H, 4 * W };
    fuse_refine_stats rs, rs2;
    assert_int_equal(fuse_refine_mask(&p, &P, mask, W, out, W, scratch, scratch_size, &rs),
                     FUSE_OK);
    assert_int_equal(rs.used_colour, 1);
    assert_true((double)rs.flipped_in > PIPE_REGROW_PER_MILLE / 1000.0 * W * H);
    const long e1 = errors(out, 30, 130);
    assert_true(e1 >= 3 * H);   /* the band left the last 2 px on each side out */
    /* the plain second refinement, from the first's result */
    assert_int_equal(fuse_refine_mask(&p, &P, out, W, out2, W, scratch, scratch_size, &rs2),
                     FUSE_OK);
    assert_int_equal(pipe_fit_refine_regrow(&p, NULL, 0.0f, &P, out, W, tmp, scratch,
                                            scratch_size, &rs),
                     1);
    assert_memory_equal(out, out2, sizeof out);
    assert_true(errors(out, 30, 130) * 4 < e1);
    /* below the limit: left as it is */
    memcpy(out2, out, sizeof out);
    rs.flipped_in = (long)(PIPE_REGROW_PER_MILLE / 1000.0 * W * H);
    assert_int_equal(pipe_fit_refine_regrow(&p, NULL, 0.0f, &P, out, W, tmp, scratch,
                                            scratch_size, &rs),
                     0);
    assert_memory_equal(out, out2, sizeof out);
    /* after a fallback: left as it is */
    rs.flipped_in = W * H;
    rs.used_colour = 0;
    assert_int_equal(pipe_fit_refine_regrow(&p, NULL, 0.0f, &P, out, W, tmp, scratch,
                                            scratch_size, &rs),
                     0);
    assert_memory_equal(out, out2, sizeof out);
    assert_int_equal(pipe_fit_refine_regrow(&p, NULL, 0.0f, &P, out, W, NULL, scratch,
                                            scratch_size, &rs),
                     -1);
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
    };
    const int r = cmocka_run_group_tests(tests, NULL, NULL);
    free(scratch);
    return r;
}
