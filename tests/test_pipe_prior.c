/* test_pipe_prior.c - the refine method's prior in the pipeline
 * (pipe_desc.refine_prior, issue 14 item 2, docs/accuracy.md): the pipe-level
 * twin of test_fit_band's disc-beyond-the-band case, through pipe_frame.
 *
 * Two skinned arms (tubes) whose hands are 20-35 cm in front of the
 * cameras; each hand has a "fingers" node on the outer side of its tube
 * (the rig's palm and finger joints). The camera images (seeded noise)
 * show the model's arms plus a skin-coloured disc around each fingers
 * node reaching 0.8 x PIPE_PRIOR_RADIUS beyond the tube: tens of pixels,
 * more than the band (16) can take in from the kinematic mask.
 *   - with the prior (the default) the refined mask grows into the disc
 *     frame after frame; with refine_prior -1 it stays at the band;
 *   - hands faster than PIPE_PRIOR_SPEED (pipe_frame_in.hand_speed): the
 *     bytes of refine_prior -1;
 *   - pipe_create refuses refine_prior / refine_lag_adapt outside -1..0.
 */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_band.h"
#include "../src/pipe/pipe.h"
#include "support/pipe_frames.h"
#include "support/pipe_testrig.h"

#define NODES 9
#define W 640
#define H 400

/* The camera images (640x480) of both eyes seen from head: the model's
 * arms and a disc around each fingers node (radius 0.8 x the prior's,
 * projected at the node's depth), skin-red over blue-grey, noise +-4;
 * the silhouette (the crop, 640x400) in sil[e]. */
static void paint_disc(const tu_arms *A, const kin_mat4 *head, kin_sthmd_geometry g,
                       tu_frame_bufs *b, uint64_t seed, uint8_t *const sil[2],
                       float disc_px[2][2], float disc);

static void paint(const tu_arms *A, const kin_mat4 *head, kin_sthmd_geometry g, tu_frame_bufs *b,
                  uint64_t seed, uint8_t *const sil[2], float disc_px[2][2])
{
    paint_disc(A, head, g, b, seed, sil, disc_px, 0.8f);
}

/* paint with a disc of radius disc x the prior's */
static void paint_disc(const tu_arms *A, const kin_mat4 *head, kin_sthmd_geometry g,
                       tu_frame_bufs *b, uint64_t seed, uint8_t *const sil[2],
                       float disc_px[2][2], float disc)
{
    float *clip = malloc(sizeof(float) * 4 * (size_t)A->nv), *depth = malloc(sizeof(float) * W * H);
    kin_mat4 *world = calloc(NODES, sizeof *world);
    assert_true(clip && depth && world);
    tu_rng r = {seed};
    for (int e = 0; e < 2; e++) {
        uint8_t *s = sil[e];
        kin_camera cam = tu_arms_silhouette(A, head, e, s, depth, clip);
        for (int k = 0; k < 2; k++) {
            /* the fingers node's image position: pipe_fit_hand_px of a
             * rig whose hand joints are all that node */
            const int node = 4 + 4 * k;
            world[node] = kin_mat4_from_tr(A->fingers[k], kin_quat_identity());
            kin_arm_rig one = A->rig;
            for (int j = KIN_RIG_HAND; j < KIN_RIG_SIDE_JOINTS; j++) one.joint[k][j] = node;
            float xy[2];
            assert_true(pipe_fit_hand_px(&cam, world, &one, k, xy));
            const float z = head->m[14] - A->fingers[k].z;   /* the head looks down -z */
            const float rr = disc * 0.5f * (cam.fx + cam.fy) * PIPE_PRIOR_RADIUS / z;
            if (e == 0) disc_px[k][0] = rr;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    float dx = (float)x + 0.5f - xy[0], dy = (float)y + 0.5f - xy[1];
                    if (dx * dx + dy * dy <= rr * rr) s[y * W + x] = 255;
                    /* the shrinking disc (paint_disc < 0.8): a dark rim
                     * 2 px wide outside it, neither skin nor background
                     * (an edge's shading and blur) */
                    else if (disc < 0.8f && dx * dx + dy * dy <= (rr + 2.0f) * (rr + 2.0f) &&
                             !s[y * W + x])
                        s[y * W + x] = 1;
                }
        }
        tu_paint_camera(b->cam[e], s, g.crop_y0, &r);
        for (int i = 0; i < W * H; i++)
            if (s[i] == 1) s[i] = 0;
    }
    free(clip);
    free(depth);
    free(world);
}

static double iou(const uint8_t *a, const uint8_t *b)
{
    long i_n = 0, u_n = 0;
    for (int i = 0; i < W * H; i++) {
        int x = a[i] >= 128, y = b[i] >= 128;
        i_n += x && y;
        u_n += x || y;
    }
    return u_n ? (double)i_n / (double)u_n : 1.0;
}

typedef struct scene {
    tu_arms A;
    tu_frame_bufs b;
    pipe_frame_in in;
    kin_mat4 head;
    uint8_t *sil[2];
    float disc_px[2][2];
    pipe_ctx *pipes[4]; /* make_pipe's, destroyed by scene_close */
    int npipes;
} scene;

static scene *scene_open(uint64_t seed)
{
    scene *S = calloc(1, sizeof *S);
    assert_non_null(S);
    tu_arms_build(&S->A, 1);
    tu_frame_make(&S->b, &S->in, seed, 640, 480, 1280, 800);
    /* the head 40 cm forward above the right arm: the right hand 20-35 cm
     * in front of the cameras, the left one out of view */
    S->head = kin_mat4_from_tr(kin_v3(0.2f, 0, -0.4f), kin_quat_identity());
    S->in.head_node = -1;
    S->in.world_from_head = &S->head;
    S->in.locals = S->A.rest;   /* tracked frames (the fit's) */
    for (int e = 0; e < 2; e++) {
        S->sil[e] = malloc(W * H);
        assert_non_null(S->sil[e]);
    }
    pipe_desc d = {0};
    d.refine_band = 16;
    d.fit_rig = &S->A.rig;
    pipe_ctx *p = pipe_create(&d, &S->A.m);
    assert_non_null(p);
    kin_sthmd_geometry g = pipe_geometry(p);
    assert_int_equal(g.crop_width, W);
    assert_int_equal(g.crop_height, H);
    paint(&S->A, &S->head, g, &S->b, seed + 1, S->sil, S->disc_px);
    pipe_destroy(p);
    return S;
}

static void scene_close(scene *S)
{
    for (int k = 0; k < S->npipes; k++) pipe_destroy(S->pipes[k]);
    tu_frame_free(&S->b);
    for (int e = 0; e < 2; e++) free(S->sil[e]);
    free(S);
}

/* A pipe on the scene (the scene's: scene_close destroys it). */
static pipe_ctx *make_pipe_isa(scene *S, int prior, int threads, int isa)
{
    pipe_desc d = {0};
    d.max_isa = isa;
    d.refine_band = 16;
    d.threads = threads;
    d.fit_rig = &S->A.rig;
    d.refine_prior = prior;
    pipe_ctx *p = pipe_create(&d, &S->A.m);
    assert_non_null(p);
    assert_true(S->npipes < 4);
    S->pipes[S->npipes++] = p;
    return p;
}

static pipe_ctx *make_pipe(scene *S, int prior, int threads)
{
    return make_pipe_isa(S, prior, threads, 0);
}

/* The disc beyond the band: 6 frames with and without the prior. */
static void prior_reaches_beyond_band(void **state)
{
    (void)state;
    scene *S = scene_open(41);
    print_message("disc radius %.1f px (the band: 16)\n", (double)S->disc_px[0][0]);
    assert_true(S->disc_px[0][0] > 40.0f);
    pipe_ctx *on = make_pipe(S, 0, 2), *off = make_pipe(S, -1, 2);
    char why[200];
    double i_on[2] = {0}, i_off[2] = {0};
    for (int f = 0; f < 6; f++) {
        assert_int_equal(pipe_frame(on, &S->in, NULL, why, sizeof why), PIPE_OK);
        assert_int_equal(pipe_frame(off, &S->in, NULL, why, sizeof why), PIPE_OK);
        for (int e = 0; e < 2; e++) {
            i_on[e] = iou(pipe_mask(on, e, NULL, NULL), S->sil[e]);
            i_off[e] = iou(pipe_mask(off, e, NULL, NULL), S->sil[e]);
            if (f == 0) assert_true(i_on[e] == i_off[e]);   /* no last mask yet */
        }
    }
    for (int e = 0; e < 2; e++) {
        print_message("eye %d: IoU after 6 frames: prior %.4f, kinematic input %.4f\n", e,
                      i_on[e], i_off[e]);
        assert_true(i_on[e] > 0.97);
        assert_true(i_on[e] > i_off[e] + 0.02);
    }
    scene_close(S);
}

/* Pixels of mask outside sil with a 4-neighbour inside sil: the 1-px
 * rim of background along the true edge. */
static long rim_specks(const uint8_t *mask, const uint8_t *sil)
{
    long n = 0;
    for (int y = 1; y < H - 1; y++)
        for (int x = 1; x < W - 1; x++) {
            const int i = y * W + x;
            if (mask[i] < 128 || sil[i]) continue;
            n += sil[i - 1] || sil[i + 1] || sil[i - W] || sil[i + W];
        }
    return n;
}

/* The hand's outline shrinks (the disc beyond the band loses a pixel of
 * radius every other frame, the kinematic mask stays): last frame's edge,
 * moved with the hand, is then a pixel outside the true one. The prior
 * must not keep it (the dotted line of background pixels along a finger
 * of docs/refine_prior_edge.png). The rim beyond the disc is darker than
 * the background (an edge's shading), colours the local model scores
 * near 0: before the colour checks the band's vote kept it where the
 * prior put it. */
static void prior_keeps_no_rim(void **state)
{
    (void)state;
    scene *S = scene_open(47);
    pipe_ctx *on = make_pipe(S, 0, 1), *off = make_pipe(S, -1, 1);
    kin_sthmd_geometry g = pipe_geometry(on);
    char why[200];
    long sp_on = 0, sp_off = 0;
    for (int f = 0; f < 14; f++) {
        const float disc = f < 4 ? 0.8f : f < 10 ? 0.8f - 0.012f * (float)(f - 3) : 0.728f;
        paint_disc(&S->A, &S->head, g, &S->b, 48 + (uint64_t)f, S->sil, S->disc_px, disc);
        assert_int_equal(pipe_frame(on, &S->in, NULL, why, sizeof why), PIPE_OK);
        assert_int_equal(pipe_frame(off, &S->in, NULL, why, sizeof why), PIPE_OK);
        long a = 0, b = 0;
        for (int e = 0; e < 2; e++) {
            a += rim_specks(pipe_mask(on, e, NULL, NULL), S->sil[e]);
            b += rim_specks(pipe_mask(off, e, NULL, NULL), S->sil[e]);
        }
        print_message("frame %2d disc %.3f: rim pixels prior %ld, kinematic input %ld\n", f,
                      (double)disc, a, b);
        if (f >= 10) {
            sp_on += a;
            sp_off += b;
        }
    }
    /* frames 10-13, both eyes: 241 rim pixels before the colour checks of
     * the prior's rim and of the refined pixels it let in
     * (pipe_fit_prior_colour, pipe_fit_refined_colour), 98 with them (the
     * rest: colours the fit's model never saw, scored as skin); 16 with
     * the kinematic input */
    print_message("frames 10-13: rim pixels prior %ld, kinematic input %ld\n", sp_on, sp_off);
    assert_true(sp_on <= 120);
    scene_close(S);
}

/* A frame of S through the pipe a with the hands at speed_a, then through
 * b at speed_b (NULL: 0 m/s): the same output and mask of eye e. */
static void same_bytes(scene *S, pipe_ctx *a, const float *speed_a, pipe_ctx *b,
                       const float *speed_b, int e)
{
    uint8_t *keep = malloc(1280 * 800 * 4), *m = malloc(W * H);
    assert_true(keep && m);
    char why[200];
    S->in.hand_speed = speed_a;
    assert_int_equal(pipe_frame(a, &S->in, NULL, why, sizeof why), PIPE_OK);
    memcpy(keep, S->b.out[e], 1280 * 800 * 4);
    memcpy(m, pipe_mask(a, e, NULL, NULL), W * H);
    S->in.hand_speed = speed_b;
    assert_int_equal(pipe_frame(b, &S->in, NULL, why, sizeof why), PIPE_OK);
    assert_memory_equal(keep, S->b.out[e], 1280 * 800 * 4);
    assert_memory_equal(m, pipe_mask(b, e, NULL, NULL), W * H);
    free(keep);
    free(m);
}

/* Hands faster than PIPE_PRIOR_SPEED keep the kinematic input: the bytes
 * of refine_prior -1 (masks and outputs); the prior's bytes do not depend
 * on the thread count (one thread, the best ISA, against two, the scalar
 * reference). */
static void fast_hands_and_threads(void **state)
{
    (void)state;
    scene *S = scene_open(43);
    pipe_ctx *on = make_pipe(S, 0, 1), *on2 = make_pipe_isa(S, 0, 2, EF_ISA_REF),
             *off = make_pipe(S, -1, 1);
    const float fast[2] = {0.31f, 0.5f};
    for (int f = 0; f < 3; f++) same_bytes(S, on, fast, off, NULL, 0);
    /* slow (NULL: 0 m/s) from here: one thread against two, ISAs */
    pipe_ctx *on1 = make_pipe(S, 0, 1);
    for (int f = 0; f < 3; f++) same_bytes(S, on2, NULL, on1, NULL, 1);
    scene_close(S);
}

/* The regrow's trail (fit_narrow.h, pipe_fit_regrow_trail) in pipe_frame:
 * a disc 2.5x the prior's (the first refinement lets in more than the
 * regrow's limit), the head moving 8 mm a frame along x (the hand moves in
 * the image). Hands at 0.35 m/s (no prior, no trail) against 0.45 m/s (no
 * prior, the trail): at the first frame where the masks differ, every
 * difference is a pixel the trail cleared (set at 0.35, clear at 0.45),
 * and they lie behind the hand's image motion. */
static void regrow_trail_fast_hands(void **state)
{
    (void)state;
    scene *S = scene_open(47);
    pipe_ctx *slow = make_pipe(S, 0, 1), *fast = make_pipe(S, 0, 1);
    kin_sthmd_geometry g = pipe_geometry(slow);
    const float v_slow[2] = {0.35f, 0.35f}, v_fast[2] = {0.45f, 0.45f};
    uint8_t *m = malloc(W * H);
    assert_non_null(m);
    const kin_mat4 head0 = S->head;
    char why[200];
    long cleared = 0;
    for (int f = 0; f < 6 && !cleared; f++) {
        S->head = head0;
        S->head.m[12] += 0.008f * (float)f;
        paint_disc(&S->A, &S->head, g, &S->b, 48 + (uint64_t)f, S->sil, S->disc_px, 2.5f);
        S->in.hand_speed = v_slow;
        assert_int_equal(pipe_frame(slow, &S->in, NULL, why, sizeof why), PIPE_OK);
        S->in.hand_speed = v_fast;
        assert_int_equal(pipe_frame(fast, &S->in, NULL, why, sizeof why), PIPE_OK);
        for (int e = 0; e < 2; e++) {
            memcpy(m, pipe_mask(slow, e, NULL, NULL), W * H);
            const uint8_t *q = pipe_mask(fast, e, NULL, NULL);
            double sx = 0, cx = 0;
            long n = 0, nm = 0;
            for (int i = 0; i < W * H; i++) {
                if (m[i] >= 128) { sx += i % W; nm++; }
                if ((m[i] >= 128) == (q[i] >= 128)) continue;
                assert_true(m[i] >= 128 && q[i] < 128);   /* only cleared */
                cx += i % W;
                n++;
            }
            if (n) {
                /* the head moves +x: the hand moves -x in the image, the
                 * cleared pixels lie on its +x side */
                print_message("frame %d eye %d: %ld px cleared, their mean x %.1f, the mask's %.1f\n",
                              f, e, n, cx / (double)n, sx / (double)nm);
                assert_true(cx / (double)n > sx / (double)nm);
                cleared += n;
            }
        }
    }
    assert_true(cleared > 0);
    free(m);
    S->head = head0;
    scene_close(S);
}

static void bad_switches(void **state)
{
    (void)state;
    tu_arms *A = malloc(sizeof *A);
    assert_non_null(A);
    tu_arms_build(A, 1);
    pipe_desc d = {0};
    d.refine_band = 16;
    d.fit_rig = &A->rig;
    d.refine_prior = 1;
    assert_null(pipe_create(&d, &A->m));
    d.refine_prior = -2;
    assert_null(pipe_create(&d, &A->m));
    d.refine_prior = 0;
    d.refine_lag_adapt = 2;
    assert_null(pipe_create(&d, &A->m));
    d.refine_lag_adapt = -1;
    pipe_ctx *p = pipe_create(&d, &A->m);
    assert_non_null(p);
    pipe_destroy(p);
    /* the tracking: refine_lag_adapt -1 or no refinement = kin's filter */
    kin_filter_desc fd = pipe_track_filter_desc(&d);
    assert_int_equal(fd.no_lag_comp, 0);
    d.refine_lag_adapt = 0;
    fd = pipe_track_filter_desc(&d);
    assert_int_equal(fd.no_lag_comp, 1);
    d.refine_band = 0;
    fd = pipe_track_filter_desc(&d);
    assert_int_equal(fd.no_lag_comp, 0);
    free(A);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(prior_reaches_beyond_band),
        cmocka_unit_test(fast_hands_and_threads),
        cmocka_unit_test(prior_keeps_no_rim),
        cmocka_unit_test(regrow_trail_fast_hands),
        cmocka_unit_test(bad_switches))
