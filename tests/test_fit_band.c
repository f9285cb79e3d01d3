/* test_fit_band.c - the refinement's band and prior from the hands
 * (src/fit/fit_band.h), on generated data: a "hand" of skin colour, a
 * disc of radius 64 px over a dark-blue background with seeded noise,
 * whose kinematic mask is a disc of radius 40 (24 px short: beyond the
 * 16 px band).
 *   - prior: refining the kinematic mask frame after frame stays at
 *     40 + 16 px (IoU < 0.85); with pipe_fit_prior (the last refined
 *     mask as the input around the slow hand) the edge reaches the true
 *     one within 3 frames (IoU > 0.97); a fast hand keeps the kinematic
 *     mask (pipe_fit_prior returns it); no prior without a last mask.
 *   - band: f sigma / z of the nearest hand joint in view, clamped; 4x
 *     nearer = 4x wider; a hand out of view or untracked: band_min; the
 *     speed term.
 *   - region: the pixels within f r / z + band of the joints, none for
 *     untracked sides; merge picks wide inside, narrow outside; the prior
 *     moved by a shift; the hand's image position.
 *   - adaptive lag compensation: a hand moving at 2 m/s is predicted
 *     closer to its true position than by the uncompensated filter (which
 *     trails it), a hand at rest exactly as by kin_filter_output.
 *   - the colour checks of the prior's rim and of the refinement's
 *     additions: byte for byte their per-pixel rule, 300 seeded masks.
 */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/fit_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_band.h"
#include "../src/fuse/fuse_refine.h"
#include "../src/cpu/ef_mem.h"

enum { W = 320, H = 240 };
static const float F = 300.0f;

static void disc(uint8_t *m, float cx, float cy, float r)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float dx = (float)x + 0.5f - cx, dy = (float)y + 0.5f - cy;
            m[y * W + x] = dx * dx + dy * dy <= r * r ? 255 : 0;
        }
}

static double iou(const uint8_t *a, const uint8_t *b) { return fit_scene_iou(a, b, (long)W * H); }

typedef struct scene {
    uint8_t *img, *truth, *kin, *prev, *out, *region, *prior;
    float *llr;
    void *scratch, *cscratch;
    size_t scratch_size;
    fuse_colour_model g;
    fuse_refine_params rp;
} scene;

static void scene_make(scene *s)
{
    fit_scene_alloc(W, H, &s->img, &s->truth, &s->kin, &s->out);
    s->prev = malloc(W * H);
    s->region = malloc(W * H);
    s->prior = malloc(W * H);
    assert_non_null(s->prev && s->region && s->prior);
    disc(s->truth, W / 2.0f, H / 2.0f, 64.0f);
    disc(s->kin, W / 2.0f, H / 2.0f, 40.0f);
    /* the image-wide colour model, learned from the true mask */
    fit_scene_learn(&s->g, s->img, s->truth, W, H, 0x5eed0f17ull, &s->llr, &s->cscratch);
    s->rp = fit_scene_refine_params();
    s->scratch_size = fuse_refine_scratch_size(&s->rp, W, H);
    s->scratch = fit_scene_scratch(s->scratch_size);
}

static void scene_free(scene *s)
{
    free(s->img); free(s->truth); free(s->kin); free(s->prev); free(s->out);
    free(s->region); free(s->prior); free(s->llr); free(s->scratch); free(s->cscratch);
}

/* n frames of refinement; with_prior: the last refined mask is the input
 * around the hand (speed: its wrist speed, m/s). */
static double run_frames(scene *s, int n, int with_prior, float speed, int *used_prior)
{
    kin_camera cam = fit_scene_camera(W, H, F);
    kin_arm_rig rig;
    fit_scene_rig(&rig);
    kin_mat4 world[2] = { fit_scene_at(0, 0, -0.4f), fit_scene_at(5.0f, 0, -0.4f) };   /* right hand out of view */
    pipe_fit_band_desc d = pipe_fit_band_desc_default();
    d.hand_radius = 0.1f;   /* 75 px at 0.4 m */
    const float sp[2] = { speed, speed };
    fuse_image P = { s->img, W, H, 4 * W };
    int have_prev = 0;
    *used_prior = 0;
    for (int i = 0; i < n; i++) {
        const uint8_t *in = s->kin;
        if (with_prior)
            in = pipe_fit_prior(&d, &cam, world, &rig, 3u, sp, 0.3f, NULL, s->kin,
                                have_prev ? s->prev : NULL, s->prior, W);
        if (in != s->kin) (*used_prior)++;
        fuse_refine_stats st;
        assert_int_equal(fuse_refine_mask_global(&s->rp, &s->g, 1.0f, &P, in, W, s->out, W,
                                                 s->scratch, s->scratch_size, &st),
                         FUSE_OK);
        assert_true(st.used_colour);
        memcpy(s->prev, s->out, W * H);
        have_prev = 1;
    }
    return iou(s->out, s->truth);
}

static void prior_reaches_beyond_band(void **state)
{
    (void)state;
    scene s;
    scene_make(&s);
    int used;
    double without = run_frames(&s, 4, 0, 0.0f, &used);
    assert_int_equal(used, 0);
    double with = run_frames(&s, 4, 1, 0.0f, &used);
    assert_int_equal(used, 3);   /* not on the first frame: no last mask */
    print_message("IoU after 4 frames: kinematic input %.4f, with the prior %.4f\n", without, with);
    assert_true(without < 0.85);
    assert_true(with > 0.97);
    /* a fast hand: the last mask is not where it is, kin stays the input */
    double fast = run_frames(&s, 4, 1, 1.0f, &used);
    assert_int_equal(used, 0);
    assert_true(fabs(fast - without) < 1e-9);
    scene_free(&s);
}

static void band_follows_depth_and_speed(void **state)
{
    (void)state;
    kin_camera cam = fit_scene_camera(W, H, F);
    kin_arm_rig rig;
    fit_scene_rig(&rig);
    pipe_fit_band_desc d = pipe_fit_band_desc_default();
    d.sigma = 0.02f;
    d.band_min = 4;
    d.band_max = 64;
    kin_mat4 world[2] = { fit_scene_at(0, 0, -0.4f), fit_scene_at(0.05f, 0, -0.1f) };
    /* left only: 300 * 0.02 / 0.4 = 15 px */
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 1u, NULL), 15);
    /* right, 4x nearer: 60 px; both: the nearer */
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 2u, NULL), 60);
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 3u, NULL), 60);
    /* clamped */
    d.band_max = 32;
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 3u, NULL), 32);
    d.band_max = 64;
    /* the speed term: (0.02 + 1 m/s * 0.02 s) * 300 / 0.4 = 30 */
    d.tau = 0.02f;
    const float sp[2] = { 1.0f, 0.0f };
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 1u, sp), 30);
    d.tau = 0.0f;
    /* out of view (far beyond the reach) or behind: band_min */
    world[0] = fit_scene_at(2.0f, 0, -0.4f);
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 1u, NULL), 4);
    world[0] = fit_scene_at(0, 0, 0.4f);
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 1u, NULL), 4);
    /* untracked, bad arguments */
    assert_int_equal(pipe_fit_band(&d, &cam, world, &rig, 0u, NULL), 4);
    assert_int_equal(pipe_fit_band(&d, NULL, world, &rig, 3u, NULL), 4);
    assert_int_equal(pipe_fit_band(&d, &cam, NULL, &rig, 3u, NULL), 4);
}

static void region_and_merge(void **state)
{
    (void)state;
    kin_camera cam = fit_scene_camera(W, H, F);
    kin_arm_rig rig;
    fit_scene_rig(&rig);
    kin_mat4 world[2] = { fit_scene_at(0, 0, -0.4f), fit_scene_at(5.0f, 0, -0.4f) };
    pipe_fit_band_desc d = pipe_fit_band_desc_default();
    d.hand_radius = 0.04f;   /* 30 px at 0.4 m, + band 10 = 40 */
    uint8_t *reg = malloc(W * H), *a = malloc(W * H), *b = malloc(W * H), *o = malloc(W * H);
    assert_non_null(reg && a && b && o);
    long n = pipe_fit_band_region(&d, &cam, world, &rig, 3u, 10, reg, W);
    assert_true(n > 4800 && n < 5300);   /* pi 40^2 = 5027 */
    assert_int_equal(reg[120 * W + 160], 255);
    assert_int_equal(reg[120 * W + 160 + 38], 255);
    assert_int_equal(reg[120 * W + 160 + 42], 0);
    assert_int_equal(reg[0], 0);
    assert_int_equal(pipe_fit_band_region(&d, &cam, world, &rig, 2u, 10, reg, W), 0);
    assert_int_equal(reg[120 * W + 160], 0);
    pipe_fit_band_region(&d, &cam, world, &rig, 1u, 10, reg, W);
    memset(a, 1, W * H);
    memset(b, 2, W * H);
    pipe_fit_band_merge(a, b, reg, o, W, W, H);
    assert_int_equal(o[120 * W + 160], 2);
    assert_int_equal(o[0], 1);
    /* no prior without a last mask, or with an untracked hand */
    const float sp[2] = { 0, 0 };
    assert_ptr_equal(pipe_fit_prior(&d, &cam, world, &rig, 1u, sp, 0.3f, NULL, a, NULL, o, W), a);
    assert_ptr_equal(pipe_fit_prior(&d, &cam, world, &rig, 0u, sp, 0.3f, NULL, a, b, o, W), a);
    assert_ptr_equal(pipe_fit_prior(&d, &cam, world, &rig, 1u, sp, 0.3f, NULL, a, b, o, W), o);
    /* moved with the hand: the last mask shifted by 10 px right, 4 down
     * inside the region; the hand's image position */
    float xy[2];
    assert_int_equal(pipe_fit_hand_px(&cam, world, &rig, 0, xy), 1);
    assert_true(fabsf(xy[0] - 160.0f) < 1e-3f && fabsf(xy[1] - 120.0f) < 1e-3f);
    assert_int_equal(pipe_fit_hand_px(&cam, world, &rig, 2, xy), 0);
    disc(a, 160.0f, 120.0f, 10.0f);
    disc(b, 150.0f, 116.0f, 20.0f);
    const float sh[2][2] = { { 10.0f, 4.0f }, { 0, 0 } };
    assert_ptr_equal(pipe_fit_prior(&d, &cam, world, &rig, 1u, sp, 0.3f, sh, a, b, o, W), o);
    disc(a, 160.0f, 120.0f, 20.0f);
    assert_memory_equal(o, a, W * H);
    free(reg); free(a); free(b); free(o);
}

/* The filter fed with the left hand at x = v t (90 Hz, no noise) until
 * t_end; returns the error of the prediction at t_end + 0.02 s. */
static float lag_error(float v, float v0, float v1, kin_track_sample *out, float speed[2])
{
    kin_filter_desc fd = kin_filter_desc_resolved(NULL);
    fd.no_lag_comp = 1;
    kin_filter f;
    kin_filter_init(&f, &fd);
    double t = 0.0;
    for (int i = 0; i < 90; i++) {
        kin_track_sample s;
        memset(&s, 0, sizeof s);
        t = i / 90.0;
        s.t = t;
        s.valid = KIN_TRACK_HEAD | KIN_TRACK_HAND_L;
        s.head_pos = kin_v3(0, 1.6f, 0);
        s.head_rot = (kin_quat){ 0, 0, 0, 1 };
        s.hand_pos[0] = kin_v3(v * (float)t, 1.2f, -0.4f);
        s.hand_rot[0] = (kin_quat){ 0, 0, 0, 1 };
        assert_true(kin_filter_push(&f, &s) & KIN_FILTER_ACCEPTED);
    }
    const double T = t + 0.02;
    pipe_fit_filter_output(&f, T, v0, v1, out, speed);
    return fabsf(out->hand_pos[0].x - v * (float)T);
}

static void lag_adapts_to_speed(void **state)
{
    (void)state;
    kin_track_sample a, b;
    float sp[2] = { -1, -1 };
    float plain = lag_error(2.0f, 0.0f, 0.0f, &a, sp);
    assert_true(sp[0] > 1.5f && sp[0] < 2.5f);
    float adapt = lag_error(2.0f, 0.2f, 0.8f, &b, NULL);
    print_message("2 m/s: error %.1f mm uncompensated, %.1f mm adaptive\n", 1e3 * plain, 1e3 * adapt);
    assert_true(plain > 0.005f);
    assert_true(adapt < 0.5f * plain);
    /* at rest: the same as the filter's own output */
    lag_error(0.0f, 0.0f, 0.0f, &a, NULL);
    lag_error(0.0f, 0.2f, 0.8f, &b, NULL);
    assert_memory_equal(&a.hand_pos[0], &b.hand_pos[0], sizeof a.hand_pos[0]);
    assert_memory_equal(&a.hand_rot[0], &b.hand_rot[0], sizeof a.hand_rot[0]);
}

/* The colour checks (pipe_fit_prior_colour, pipe_fit_refined_colour)
 * against their rule written out per pixel, on 300 seeded cases: sizes
 * 1..70 x 1..40 with padded strides, masks of blobs, runs, empty rows
 * and single pixels (0 / 255), random colours and a 3-bit model with
 * exact zeros. Every pixel's neighbours are those of the mask as given,
 * so the rule does not depend on the scan's order. */
static long clear_rule(const fuse_colour_model *g, const fuse_image *P, const uint8_t *in,
                       const uint8_t *o, uint8_t *want, int stride)
{
    const int W = P->width, H = P->height;
    long n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const size_t k = (size_t)y * (size_t)stride + (size_t)x;
            if (o[k] < 128 || (in && in[k] >= 128)) continue;
            const int nb = (x > 0 && o[k - 1]) + (x + 1 < W && o[k + 1]) + (y > 0 && o[k - stride]) +
                           (y + 1 < H && o[k + stride]);
            const int border = (x > 0) + (x + 1 < W) + (y > 0) + (y + 1 < H);
            if (in ? nb > 2 : nb >= border) continue;
            const uint8_t *px = P->pixels + (size_t)y * (size_t)P->stride + 4 * (size_t)x;
            if (g->llr[fuse_colour_bin(px, g->bits)] <= 0.0f) {
                want[k] = 0;
                n++;
            }
        }
    return n;
}

static void colour_checks_match_rule(void **state)
{
    (void)state;
    tu_rng r = { 0xc0105c1eull };
    float llr[512];
    long cleared = 0;
    for (int c = 0; c < 300; c++) {
        const int W = 1 + tu_int(&r, 70), H = 1 + tu_int(&r, 40), stride = W + tu_int(&r, 9);
        const size_t nb = (size_t)stride * (size_t)H;
        uint8_t *pix = malloc(4 * (size_t)W * (size_t)H), *o = calloc(nb, 1), *in = calloc(nb, 1);
        uint8_t *got = malloc(nb), *want = malloc(nb);
        assert_non_null(pix);
        assert_non_null(o);
        assert_non_null(in);
        assert_non_null(got);
        assert_non_null(want);
        for (size_t i = 0; i < 4 * (size_t)W * (size_t)H; i++) pix[i] = (uint8_t)tu_next(&r);
        for (int b = 0; b < 512; b++) {
            const int k = tu_int(&r, 8);
            llr[b] = k == 0 ? 0.0f : tu_range(&r, -1.0f, 1.0f);
        }
        /* blobs (discs), runs along rows, single pixels */
        const int blobs = tu_int(&r, 4), runs = tu_int(&r, 6), dots = tu_int(&r, 12);
        for (int b = 0; b < blobs; b++) {
            const float cx = tu_range(&r, 0.0f, (float)W), cy = tu_range(&r, 0.0f, (float)H);
            const float rad = tu_range(&r, 0.5f, 12.0f);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++)
                    if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= rad * rad)
                        o[(size_t)y * (size_t)stride + (size_t)x] = 255;
        }
        for (int b = 0; b < runs; b++) {
            const int y = tu_int(&r, H), x0 = tu_int(&r, W), len = 1 + tu_int(&r, 24);
            for (int x = x0; x < W && x < x0 + len; x++) o[(size_t)y * (size_t)stride + (size_t)x] = 255;
        }
        for (int b = 0; b < dots; b++) {
            const int y = tu_int(&r, H), x = tu_int(&r, W);
            o[(size_t)y * (size_t)stride + (size_t)x] = 255;
        }
        /* the refinement's input: the mask less a few pixels of its own */
        for (size_t i = 0; i < nb; i++) in[i] = o[i] && tu_int(&r, 4) ? 255 : 0;
        const fuse_colour_model g = { 3, 100, 100, llr };
        const fuse_image P = { pix, W, H, 4 * W };
        for (int refined = 0; refined < 2; refined++) {
            memcpy(got, o, nb);
            memcpy(want, o, nb);
            const long nw = clear_rule(&g, &P, refined ? in : NULL, o, want, stride);
            const long n = refined ? pipe_fit_refined_colour(&g, &P, in, got, stride)
                                   : pipe_fit_prior_colour(&g, &P, got, stride);
            assert_int_equal(n, nw);
            assert_memory_equal(got, want, nb);
            cleared += n;
        }
        EF_FREE_ALL(pix, o, in, got, want);
    }
    print_message("colour checks: %ld pixels cleared in 600 calls, all as the rule\n", cleared);
    assert_true(cleared > 1000);
}

TU_MAIN_NAMED("fit_band", NULL, NULL,
              cmocka_unit_test(prior_reaches_beyond_band),
              cmocka_unit_test(band_follows_depth_and_speed),
              cmocka_unit_test(region_and_merge),
              cmocka_unit_test(lag_adapts_to_speed),
              cmocka_unit_test(colour_checks_match_rule))
