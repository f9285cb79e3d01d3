/* test_fit_stereo.c - the stereo pair's depth test of a refined mask
 * (src/fit/fit_stereo.h), on generated data: the HMD's two cameras
 * (kin_sthmd_camera, 65 mm apart), a "hand" (a textured skin-coloured
 * rectangle 0.35 m in front of them) over a background plane 0.75 m away
 * with the same skin colour and texture statistics (colour cannot tell
 * them apart), seeded camera noise. The model covers the hand exactly
 * (its window depth in the left camera); the refined mask also took in a
 * strip of the background beside the hand.
 *   - the strip is cleared (>= 85 % of it), the hand kept (>= 98 %);
 *   - a plain (textureless) background strip is left alone: ambiguous;
 *   - with accept, a strip of the hand cut from the mask (fingers beyond
 *     the model) is put back; background beyond the mask is not taken in;
 *   - background seen through a hole in the hand (inside the mask, not
 *     connected to its outside) is kept; without `connected` the part the
 *     other camera sees through the hole goes;
 *   - the grid (step 4) decides like every pixel within a few percent;
 *   - bad arguments: -1 and the mask untouched.
 */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_stereo.h"
#include "../src/cpu/ef_mem.h"
#include "support/fixture.h"

static kin_camera cams[2];
static int W, H;

/* hand: 0.35 m in front of the cameras, x in [-0.05, 0.03] m, y in
 * [-0.06, 0.06] m (world = head frame, the cameras at z -0.085) */
#define Z_CAM (-0.085f)
#define Z_HAND (Z_CAM - 0.35f)
#define Z_BACK (Z_CAM - 0.75f)
#define HX0 (-0.05f)
#define HX1 0.03f
#define HY 0.06f

static uint32_t hash2(int32_t x, int32_t y, uint32_t s)
{
    uint32_t h = (uint32_t)x * 374761393u + (uint32_t)y * 668265263u + s * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return h ^ (h >> 16);
}

/* value noise, cells of `cell` metres, in [0, 1) */
static float vnoise(float x, float y, float cell, uint32_t s)
{
    float u = x / cell, v = y / cell;
    int32_t i = (int32_t)floorf(u), j = (int32_t)floorf(v);
    float fu = u - (float)i, fv = v - (float)j;
    float a = (float)(hash2(i, j, s) & 0xffff) / 65536.0f;
    float b = (float)(hash2(i + 1, j, s) & 0xffff) / 65536.0f;
    float c = (float)(hash2(i, j + 1, s) & 0xffff) / 65536.0f;
    float d = (float)(hash2(i + 1, j + 1, s) & 0xffff) / 65536.0f;
    fu = fu * fu * (3 - 2 * fu);
    fv = fv * fv * (3 - 2 * fv);
    return (a + (b - a) * fu) * (1 - fv) + (c + (d - c) * fu) * fv;
}

/* a hole through the hand (render's hole): x in [HOX0, HOX1], |y| <= HOY */
#define HOX0 (-0.025f)
#define HOX1 (-0.005f)
#define HOY 0.02f
static int hole;

/* Renders camera e: the hand over the background (plain: the background
 * without texture). */
static void render(int e, int plain, uint8_t *rgba, uint32_t seed)
{
    const kin_camera *c = &cams[e];
    const float ox = c->world_from_cam.m[12];
    uint32_t n = seed * 2654435761u + (uint32_t)e;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const float a = ((float)x + 0.5f - c->cx) / c->fx;
            const float b = -((float)y + 0.5f - c->cy) / c->fy;
            float t = Z_CAM - Z_HAND, X = ox + a * t, Y = b * t, m;
            const int hand = X >= HX0 && X <= HX1 && Y >= -HY && Y <= HY &&
                             !(hole && X >= HOX0 && X <= HOX1 && Y >= -HOY && Y <= HOY);
            if (hand) {
                m = 0.75f + 0.5f * vnoise(X, Y, 0.0015f, 7u);
            } else {
                t = Z_CAM - Z_BACK;
                X = ox + a * t;
                Y = b * t;
                m = plain ? 1.0f : 0.75f + 0.5f * vnoise(X, Y, 0.003f, 9u);
            }
            n = n * 1664525u + 1013904223u;
            const int noise = (int)((n >> 24) % 5u) - 2;
            static const float skin[3] = { 200.0f, 150.0f, 120.0f };
            uint8_t *p = rgba + ((size_t)y * W + x) * 4;
            for (int k = 0; k < 3; k++) {
                int v = (int)(skin[k] * m) + noise;
                p[k] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
            }
            p[3] = 255;
        }
}

/* left camera's column range of the hand (at row H/2) */
static void hand_cols(int *x0, int *x1)
{
    const kin_camera *c = &cams[0];
    const float ox = c->world_from_cam.m[12], t = Z_CAM - Z_HAND;
    *x0 = (int)ceilf(c->cx + c->fx * (HX0 - ox) / t - 0.5f);
    *x1 = (int)floorf(c->cx + c->fx * (HX1 - ox) / t - 0.5f);
}

static int hand_row(int y)
{
    const kin_camera *c = &cams[0];
    const float b = -((float)y + 0.5f - c->cy) / c->fy;
    const float Y = b * (Z_CAM - Z_HAND);
    return Y >= -HY && Y <= HY;
}

typedef struct scene {
    uint8_t *P, *Q, *mask;
    float *depth;
    void *scratch;
    size_t scratch_size;
    int hx0, hx1;
} scene;

static void scene_make(scene *s, int plain)
{
    s->P = malloc((size_t)W * H * 4);
    s->Q = malloc((size_t)W * H * 4);
    s->mask = malloc((size_t)W * H);
    s->depth = malloc(sizeof(float) * (size_t)W * H);
    s->scratch_size = pipe_fit_stereo_scratch_size(W, H);
    s->scratch = aligned_alloc(16, (s->scratch_size + 15) & ~(size_t)15);
    assert_non_null(s->P);
    assert_non_null(s->Q);
    assert_non_null(s->mask);
    assert_non_null(s->depth);
    assert_non_null(s->scratch);
    render(0, plain, s->P, 1u);
    render(1, plain, s->Q, 1u);
    hand_cols(&s->hx0, &s->hx1);
    /* the hand's window depth in the left camera */
    const float zv = Z_HAND - Z_CAM;   /* view z, negative */
    const float *m = cams[0].proj.m;
    const float ndc = (m[10] * zv + m[14]) / -zv;
    const float wd = 0.5f * ndc + 0.5f;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            s->depth[(size_t)y * W + x] =
                hand_row(y) && x >= s->hx0 && x <= s->hx1 ? wd : 1.0f;
}

static void scene_free(scene *s)
{
    EF_FREE_ALL(s->P, s->Q, s->mask, s->depth, s->scratch);
}

/* The mask: the hand's columns [x0, x1] on its rows. */
static void mask_cols(scene *s, int x0, int x1)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            s->mask[(size_t)y * W + x] = hand_row(y) && x >= x0 && x <= x1 ? 255 : 0;
}

static long count(const scene *s, int x0, int x1, int inner)
{
    long n = 0;
    for (int y = 0; y < H; y++) {
        if (!hand_row(y)) continue;
        /* rows well inside the hand's (patches straddle its top and bottom) */
        if (inner && (!hand_row(y - 4) || !hand_row(y + 4))) continue;
        for (int x = x0; x <= x1; x++) n += s->mask[(size_t)y * W + x] >= 128;
    }
    return n;
}

static long rows_inner(void)
{
    long n = 0;
    for (int y = 0; y < H; y++) n += hand_row(y) && hand_row(y - 4) && hand_row(y + 4);
    return n;
}

/* pipe_fit_stereo on the scene with the left camera cam, the right image
 * q_width wide, the depth's stride depth_stride and scratch_size bytes of
 * the scene's scratch (the arguments bad_arguments varies). */
static int run_args(scene *s, const pipe_fit_stereo_desc *d, const kin_camera *cam, int q_width,
                    int depth_stride, size_t scratch_size, pipe_fit_stereo_stats *st)
{
    fuse_image P = { s->P, W, H, 4 * W }, Q = { s->Q, q_width, H, 4 * W };
    return pipe_fit_stereo(d, cam, &P, &cams[1], &Q, s->depth, depth_stride, s->mask, W,
                           s->scratch, scratch_size, st);
}

/* pipe_fit_stereo on the scene as it is. */
static int run(scene *s, const pipe_fit_stereo_desc *d, pipe_fit_stereo_stats *st)
{
    return run_args(s, d, &cams[0], W, W, s->scratch_size, st);
}

static int setup(void **state)
{
    (void)state;
    for (int e = 0; e < 2; e++) cams[e] = kin_sthmd_camera(NULL, NULL, (kin_eye)e);
    W = cams[0].width;
    H = cams[0].height;
    return 0;
}

/* A scene with a hole in the hand, the background seen through it. */
static void scene_make_hole(scene *s)
{
    hole = 1;
    scene_make(s, 0);
    hole = 0;
}

/* Each test's fixture: a fresh scene as its state, of the textured
 * background, the plain one, or the textured one seen through a hole. */
TU_FIXTURE(scene, scene, s, scene_make(s, 0), scene_free(s))
TU_FIXTURE(plain, scene, s, scene_make(s, 1), scene_free(s))
TU_FIXTURE(hole, scene, s, scene_make_hole(s), scene_free(s))

static void rejects_background_behind_the_hand(void **state)
{
    scene *s = *state;
    /* refined: the hand and a strip of 24 px of the background beside it */
    mask_cols(s, s->hx0, s->hx1 + 24);
    const long hand0 = count(s, s->hx0 + 3, s->hx1 - 3, 1);
    const long strip0 = count(s, s->hx1 + 4, s->hx1 + 24, 1);
    assert_true(strip0 == rows_inner() * 21);
    pipe_fit_stereo_stats st;
    pipe_fit_stereo_desc d = pipe_fit_stereo_desc_default();
    assert_int_equal(run(s, &d, &st), 0);
    const long hand1 = count(s, s->hx0 + 3, s->hx1 - 3, 1);
    const long strip1 = count(s, s->hx1 + 4, s->hx1 + 24, 1);
    print_message("stereo: strip %ld -> %ld px, hand %ld -> %ld px (tested %ld, cleared %ld)\n",
                  strip0, strip1, hand0, hand1, st.tested, st.cleared);
    assert_true(strip1 * 100 <= strip0 * 15);
    assert_true(hand1 * 100 >= hand0 * 98);
    assert_int_equal(st.added, 0);
}

static void plain_background_is_ambiguous(void **state)
{
    scene *s = *state;
    mask_cols(s, s->hx0, s->hx1 + 24);
    const long strip0 = count(s, s->hx1 + 4, s->hx1 + 24, 1);
    pipe_fit_stereo_stats st;
    assert_int_equal(run(s, NULL, &st), 0);
    const long strip1 = count(s, s->hx1 + 4, s->hx1 + 24, 1);
    print_message("plain: strip %ld -> %ld px (textureless %ld of %ld)\n", strip0, strip1,
                  st.textureless, st.tested);
    assert_true(strip1 * 100 >= strip0 * 98);
    assert_true(st.textureless > 0);
}

static void accepts_the_hand_beyond_the_mask(void **state)
{
    scene *s = *state;
    /* the model's hand stops 12 px short of the true right edge: the
     * depth covers only the mask */
    mask_cols(s, s->hx0, s->hx1 - 12);
    for (int y = 0; y < H; y++)
        for (int x = s->hx1 - 11; x <= s->hx1; x++) s->depth[(size_t)y * W + x] = 1.0f;
    pipe_fit_stereo_desc d = pipe_fit_stereo_desc_default();
    d.accept = 16;
    pipe_fit_stereo_stats st;
    assert_int_equal(run(s, &d, &st), 0);
    const long cut = count(s, s->hx1 - 9, s->hx1 - 3, 1);
    const long beyond = count(s, s->hx1 + 4, s->hx1 + 16, 1);
    print_message("accept: %ld of %ld hand px back, %ld background px taken (added %ld)\n", cut,
                  rows_inner() * 7, beyond, st.added);
    assert_true(cut * 100 >= rows_inner() * 7 * 85);
    assert_true(beyond * 100 <= rows_inner() * 13 * 5);
    /* without accept nothing outside the mask changes */
    mask_cols(s, s->hx0, s->hx1 - 12);
    d.accept = 0;
    assert_int_equal(run(s, &d, &st), 0);
    assert_int_equal(count(s, s->hx1 - 11, s->hx1 + 16, 0), 0);
}

/* The left camera's pixels of the hole (x, y ranges). */
static void hole_px(int *x0, int *x1, int *y0, int *y1)
{
    const kin_camera *c = &cams[0];
    const float ox = c->world_from_cam.m[12], t = Z_CAM - Z_HAND;
    *x0 = (int)ceilf(c->cx + c->fx * (HOX0 - ox) / t - 0.5f);
    *x1 = (int)floorf(c->cx + c->fx * (HOX1 - ox) / t - 0.5f);
    *y0 = (int)ceilf(c->cy - c->fy * HOY / t - 0.5f);
    *y1 = (int)floorf(c->cy + c->fy * HOY / t - 0.5f);
}

/* Background seen through a hole in the hand, which the model covers: a
 * depth edge inside the mask, not connected to its outside, is kept
 * (connected 1); without the rule it is cleared. */
static void enclosed_background_is_kept(void **state)
{
    scene *s = *state;
    int x0, x1, y0, y1;
    hole_px(&x0, &x1, &y0, &y1);
    const long area = (long)(x1 - x0 - 5) * (y1 - y0 - 5);
    long kept[2];
    for (int conn = 1; conn >= 0; conn--) {
        mask_cols(s, s->hx0, s->hx1);
        pipe_fit_stereo_desc d = pipe_fit_stereo_desc_default();
        d.connected = conn;
        assert_int_equal(run(s, &d, NULL), 0);
        long k = 0;
        for (int y = y0 + 3; y < y1 - 2; y++)
            for (int x = x0 + 3; x < x1 - 2; x++) k += s->mask[(size_t)y * W + x] >= 128;
        kept[conn] = k;
    }
    print_message("hole: %ld px, kept %ld connected, %ld not\n", area, kept[1], kept[0]);
    assert_true(kept[1] * 100 >= area * 98);
    assert_true(kept[0] * 100 <= area * 75);   /* the half the other camera sees */
}

static void grid_decides_like_every_pixel(void **state)
{
    scene *s = *state;
    mask_cols(s, s->hx0, s->hx1 + 24);
    pipe_fit_stereo_desc d = pipe_fit_stereo_desc_default();
    d.step = 1;
    pipe_fit_stereo_stats st1, st4;
    assert_int_equal(run(s, &d, &st1), 0);
    uint8_t *m1 = malloc((size_t)W * H);
    assert_non_null(m1);
    memcpy(m1, s->mask, (size_t)W * H);
    mask_cols(s, s->hx0, s->hx1 + 24);
    d.step = 4;
    assert_int_equal(run(s, &d, &st4), 0);
    long diff = 0, set = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        diff += (m1[i] >= 128) != (s->mask[i] >= 128);
        set += m1[i] >= 128;
    }
    print_message("grid: %ld of %ld px differ, tested %ld -> %ld\n", diff, set, st1.tested,
                  st4.tested);
    assert_true(diff * 100 <= set * 3);
    assert_true(st4.tested * 2 < st1.tested);
    free(m1);
}

static void bad_arguments(void **state)
{
    scene *s = *state;
    mask_cols(s, s->hx0, s->hx1 + 24);
    uint8_t *m0 = malloc((size_t)W * H);
    assert_non_null(m0);
    memcpy(m0, s->mask, (size_t)W * H);
    const size_t sz = s->scratch_size;
    pipe_fit_stereo_desc d = pipe_fit_stereo_desc_default();
    assert_int_equal(run_args(s, &d, NULL, W, W, sz, NULL), -1);
    assert_int_equal(run_args(s, &d, &cams[0], W - 1, W, sz, NULL), -1);
    assert_int_equal(run_args(s, &d, &cams[0], W, W, sz - 1, NULL), -1);
    assert_int_equal(run_args(s, &d, &cams[0], W, W - 1, sz, NULL), -1);
    d.radius = 5;
    assert_int_equal(run_args(s, &d, &cams[0], W, W, sz, NULL), -1);
    d = pipe_fit_stereo_desc_default();
    d.gap = 0.01f;   /* must not overlap the hand's range */
    assert_int_equal(run_args(s, &d, &cams[0], W, W, sz, NULL), -1);
    assert_memory_equal(m0, s->mask, (size_t)W * H);
    assert_int_equal(pipe_fit_stereo_scratch_size(0, 10), 0);
    free(m0);
}

TU_MAIN(setup, NULL,
        cmocka_unit_test_setup_teardown(rejects_background_behind_the_hand, scene_setup,
                                        scene_teardown),
        cmocka_unit_test_setup_teardown(plain_background_is_ambiguous, plain_setup,
                                        plain_teardown),
        cmocka_unit_test_setup_teardown(accepts_the_hand_beyond_the_mask, scene_setup,
                                        scene_teardown),
        cmocka_unit_test_setup_teardown(enclosed_background_is_kept, hole_setup,
                                        hole_teardown),
        cmocka_unit_test_setup_teardown(grid_decides_like_every_pixel, scene_setup,
                                        scene_teardown),
        cmocka_unit_test_setup_teardown(bad_arguments, scene_setup, scene_teardown))
