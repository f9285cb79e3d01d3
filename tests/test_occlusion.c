/* test_occlusion.c - occlusion by the virtual scene is never broken, for
 * every method (issue 14).
 *
 * Generated frames (samples/gen, samples/gt: the true operator of
 * `egofuse eval`, its camera images and tracking, frames 136-140 of
 * reach_grasp, both eyes) are composited over a virtual image whose depth
 * puts an object 5 cm from the eye across a band of columns where the
 * most of the arms are (nearer than any part of the hand can be), nothing
 * elsewhere. For each method:
 *   kin          the model posed by the animation (pipe_frame);
 *   kin-pred     posed from the tracking through the One Euro filter with
 *                20 ms prediction and the arm IK (render --pose tracking);
 *   refine       the same plus the elbow fit and the colour refinement of
 *                the mask (render --pose tracking --refine 16, eval's
 *                refine);
 *   refine-anim  animation-posed, colour-refined (render --refine 16);
 *   skin         the skin-colour key of eval's skin method (no model, no
 *                depth: fuse_depth_fill gives its pixels the far plane)
 * and on every ISA the CPU has (ref, sse2, avx2, avx512), it checks:
 *   - no lit layer pixel (the mask after the depth test) whose scene
 *     pixel is in the object's band has alpha > 0;
 *   - inside the band (2 output pixels in from its sides: the bilinear
 *     resampling reaches one layer pixel across) the output is V, byte
 *     for byte: no composited hand colour;
 *   - the same frames without the depth test do show the hand there (at
 *     least 300 differing output pixels per eye and frame: the test is not
 *     vacuous);
 *   - every ISA gives the reference's bytes (outputs and layers).
 * The pipe methods run again with anti-aliased silhouettes
 * (pipe_desc.aa_samples 4, 8 or 16: occl_*_aa) and with soft silhouettes
 * (pipe_desc.soft_edge: occl_*_soft), the same checks.
 * Before fuse_depth_fill (the refined pixels outside the model had no
 * depth and were kept) refine and refine-anim drew hundreds of hand
 * pixels inside the band per frame (with the fill disabled: refine 25,913,
 * refine-anim 9,939, skin 527,555 over the 5 stereo frames). */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../samples/gt/gt.h"
#include "../src/pipe/pipe.h"
#include "../src/cpu/ef_mem.h"

#define NF 5
#define F0 136
#define CW 640
#define CH 400
#define OW GEN_VIRT_W
#define OH GEN_VIRT_H
#define BAND_W 140       /* output columns of the occluder */
#define NEAR_M 0.05f
#define MIN_SHOWN 300

enum { M_KIN, M_KIN_PRED, M_REFINE, M_REFINE_ANIM, M_SKIN, M_COUNT };
static const char *method_name[M_COUNT] = {"kin", "kin-pred", "refine", "refine-anim", "skin"};

typedef struct world {
    gen_arms mask, truth;
    gen_scene cockpit, workshop;
    gen_frame_ctx gctx;
    kin_arm_rig rig;
    kin_sthmd_geometry g;
    uint8_t *cam[NF][2];          /* 640x480 RGBA */
    int band[NF][2];              /* first occluded output column */
    float *vdepth[NF][2];         /* OW x OH */
    uint8_t *V;                   /* OW x OH RGBA, opaque */
    kin_track_sample *samples;
    int nsamples;
    float rate;
    kin_transform *locals;
} world;

static world W;
/* pipe_desc.aa_samples of the pipe methods (0: binary masks) */
static int g_aa;
/* pipe_desc.soft_edge of the pipe methods */
static int g_soft;
/* 1: every tracked hand reported fast (pipe_frame_in.hand_speed), so
 * none takes the prior and every one may be moved to its colour
 * (pipe_desc.refine_shift); g_shift: refine_shift's value */
static int g_fast, g_shift;

/* The band of BAND_W output columns holding the most silhouette pixels. */
static int best_band(const uint8_t *sil, const kin_sthmd_geometry *g)
{
    static long col[OW];
    memset(col, 0, sizeof col);
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++)
            if (sil[(size_t)y * CW + x]) {
                int ox = g->vp_x0 + (int)(((int64_t)2 * x + 1) * g->vp_width / (2 * CW));
                col[ox]++;
            }
    long best = -1, sum = 0;
    int at = g->vp_x0;
    for (int x = g->vp_x0; x < g->vp_x0 + g->vp_width; x++) {
        sum += col[x];
        if (x - BAND_W >= g->vp_x0) sum -= col[x - BAND_W];
        if (x - BAND_W + 1 >= g->vp_x0 && sum > best) {
            best = sum;
            at = x - BAND_W + 1;
        }
    }
    return at;
}

static int setup(void **state)
{
    (void)state;
    memset(&W, 0, sizeof W);
    gt_operator_desc op = gt_operator_default();
    if (gen_arms_build(&W.mask) < 0 || gt_truth_build(&W.mask, &op, &W.truth) < 0 ||
        gt_cockpit_build(&W.cockpit) < 0 || gen_scene_workshop(&W.workshop, &W.mask) < 0 ||
        gen_frame_ctx_init(&W.gctx, &W.truth, &W.cockpit, &W.workshop, 1) < 0)
        return -1;
    char why[256];
    if (kin_arm_rig_init(&W.rig, &W.mask.model, why, sizeof why) < 0) return -1;
    W.g = kin_sthmd_geometry_of(NULL);
    uint8_t *rgb = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 3);
    uint8_t *sil = malloc((size_t)CW * CH);
    float *sd = malloc(sizeof(float) * GEN_CAM_W * GEN_CAM_H);
    uint8_t *sm = malloc((size_t)GEN_CAM_W * GEN_CAM_H);
    W.V = malloc((size_t)OW * OH * 4);
    W.locals = malloc(sizeof *W.locals * (size_t)W.mask.model.node_count);
    if (!rgb || !sil || !sd || !sm || !W.V || !W.locals) return -1;
    for (size_t i = 0; i < (size_t)OW * OH; i++) {
        W.V[4 * i + 0] = 40;
        W.V[4 * i + 1] = 200;
        W.V[4 * i + 2] = 60;
        W.V[4 * i + 3] = 255;
    }
    for (int f = 0; f < NF; f++) {
        kin_mat4 wfh;
        gen_pose(&W.gctx, (float)(F0 + f) / GEN_FPS, &wfh);
        for (int e = 0; e < 2; e++) {
            gt_render_eye(&W.gctx, &wfh, (kin_eye)e, F0 + f, rgb, sil, NULL, sd, sm);
            W.cam[f][e] = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 4);
            W.vdepth[f][e] = calloc((size_t)OW * OH, sizeof(float));
            if (!W.cam[f][e] || !W.vdepth[f][e]) return -1;
            fuse_image im = {W.cam[f][e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W};
            if (fuse_rgb24_to_rgba(rgb, 3 * GEN_CAM_W, GEN_CAM_W, GEN_CAM_H, &im) != FUSE_OK)
                return -1;
            int b = best_band(sil, &W.g);
            W.band[f][e] = b;
            for (int y = 0; y < OH; y++)
                for (int x = b; x < b + BAND_W; x++) W.vdepth[f][e][(size_t)y * OW + x] = NEAR_M;
        }
    }
    /* the tracker of eval's defaults (5 mm noise, 20 ms latency, seed 1) */
    gt_track_desc td = gt_track_default();
    W.rate = td.rate_hz;
    W.nsamples = (int)((float)(F0 + NF) / GEN_FPS * td.rate_hz) + 1;
    W.samples = malloc(sizeof *W.samples * (size_t)W.nsamples);
    kin_transform *tl = malloc(sizeof *tl * (size_t)W.truth.model.node_count);
    kin_mat4 *tw = malloc(sizeof *tw * (size_t)W.truth.model.node_count);
    if (!W.samples || !tl || !tw) return -1;
    for (int k = 0; k < W.nsamples; k++) gt_track_sample(&W.truth, &td, k, tl, tw, &W.samples[k]);
    EF_FREE_ALL(tl, tw, rgb, sil, sd, sm);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    for (int f = 0; f < NF; f++)
        for (int e = 0; e < 2; e++) {
            free(W.cam[f][e]);
            free(W.vdepth[f][e]);
        }
    free(W.V);
    free(W.samples);
    free(W.locals);
    gen_frame_ctx_free(&W.gctx);
    gen_scene_free(&W.cockpit);
    gen_scene_free(&W.workshop);
    gen_arms_free(&W.truth);
    gen_arms_free(&W.mask);
    return 0;
}

/* A fast 64-bit hash of n bytes (n a multiple of 8), chained from h: the
 * ISA paths are compared by it (CRC32 byte by byte took half the time). */
static uint64_t hash64(uint64_t h, const void *data, size_t n)
{
    const uint8_t *b = data;
    for (size_t i = 0; i + 8 <= n; i += 8) {
        uint64_t w;
        memcpy(&w, b + i, 8);
        h = (h ^ w) * 0x100000001B3ull;
        h ^= h >> 29;
    }
    return h;
}

/* Checks one eye's layer (CW x CH premultiplied) and output against the
 * band; returns the number of offending pixels, *shown the output pixels
 * inside the band that differ from V. */
static long check_eye(const uint8_t *layer, const uint8_t *out, int band, long *shown)
{
    const kin_sthmd_geometry *g = &W.g;
    long bad = 0, diff = 0;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            int ox = g->vp_x0 + (int)(((int64_t)2 * x + 1) * g->vp_width / (2 * CW));
            if (ox >= band && ox < band + BAND_W && layer[((size_t)y * CW + x) * 4 + 3] != 0)
                bad++;
        }
    for (int y = g->vp_y0; y < g->vp_y0 + g->vp_height; y++)
        for (int x = band + 2; x < band + BAND_W - 2; x++)
            if (memcmp(out + ((size_t)y * OW + x) * 4, W.V + ((size_t)y * OW + x) * 4, 4)) diff++;
    *shown = diff;
    return bad + diff;
}

/* The pose from tracking at frame time t (as `egofuse render --pose
 * tracking`): the samples delivered by t (20 ms latency) through the
 * filter, predicted 20 ms. */
static void pose_at(kin_filter *flt, int *next, double t)
{
    const double lat = 0.020;
    while (*next < W.nsamples && (double)*next / W.rate + lat <= t + 1e-9)
        kin_filter_push(flt, &W.samples[(*next)++]);
    kin_track_sample cur;
    memset(&cur, 0, sizeof cur);
    if (*next > 0) kin_filter_output(flt, t + 0.020, &cur, NULL);
    kin_pose_rest(&W.mask.model, W.locals);
    if (!kin_arm_rig_pose(&W.rig, &W.mask.model, NULL, NULL, &cur, W.locals, NULL))
        kin_pose_rest(&W.mask.model, W.locals);
}

/* Runs method m on isa; with_depth 0 runs without the depth test.
 * crc[f] receives the hash of frame f's outputs and layers. Returns the
 * offending pixels; *min_shown the fewest output pixels in a band that
 * differ from V (per eye and frame). */
static long run_pipe(int m, ef_isa isa, int with_depth, uint64_t crc[NF], long *min_shown)
{
    pipe_desc d = {0};
    d.threads = 2;
    d.max_isa = (int)isa;
    d.aa_samples = g_aa;
    d.soft_edge = g_soft;
    d.refine_shift = g_shift;
    if (m == M_REFINE || m == M_REFINE_ANIM) d.refine_band = 16;
    if (m == M_REFINE) d.fit_rig = &W.rig;
    pipe_ctx *p = pipe_create(&d, &W.mask.model);
    assert_non_null(p);
    uint8_t *out[2] = {malloc((size_t)OW * OH * 4), malloc((size_t)OW * OH * 4)};
    assert_non_null(out[0]);
    assert_non_null(out[1]);
    kin_filter flt;
    kin_filter_init(&flt, NULL);
    int next = 0;
    long bad = 0;
    *min_shown = -1;
    for (int f = 0; f < NF; f++) {
        const double t = (double)(F0 + f) / GEN_FPS;
        pipe_frame_in in = {0};
        in.head_node = W.mask.head;
        if (m == M_KIN || m == M_REFINE_ANIM) {
            in.anim = &W.mask.model.anims[0];
            in.time = (float)t;
        } else {
            pose_at(&flt, &next, t);
            in.locals = W.locals;
            static const float fast[2] = {1.0f, 1.0f};
            if (g_fast) in.hand_speed = fast;
        }
        in.lighting = pipe_lighting_default();
        for (int e = 0; e < 2; e++) {
            in.camera[e] = (fuse_image){W.cam[f][e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W};
            in.virt[e] = (fuse_image){W.V, OW, OH, 4 * OW};
            in.out[e] = (fuse_image){out[e], OW, OH, 4 * OW};
            if (with_depth) {
                in.virt_depth[e] = W.vdepth[f][e];
                in.virt_depth_stride[e] = OW;
            }
        }
        in.virt_opaque = 1;
        char why[256];
        assert_int_equal(pipe_frame(p, &in, NULL, why, sizeof why), PIPE_OK);
        crc[f] = 0;
        for (int e = 0; e < 2; e++) {
            int lw, lh;
            const uint8_t *layer = pipe_layer(p, e, &lw, &lh);
            assert_int_equal(lw, CW);
            assert_int_equal(lh, CH);
            long shown;
            long b = check_eye(layer, out[e], W.band[f][e], &shown);
            if (with_depth && b)
                printf("  %s %s frame %d %s eye: %ld hand pixels behind the object\n",
                       method_name[m], ef_isa_name(isa), F0 + f, e ? "right" : "left", b);
            if (with_depth) bad += b;
            if (*min_shown < 0 || shown < *min_shown) *min_shown = shown;
            crc[f] = hash64(crc[f], out[e], (size_t)OW * OH * 4);
            crc[f] = hash64(crc[f], layer, (size_t)CW * CH * 4);
        }
    }
    free(out[0]);
    free(out[1]);
    pipe_destroy(p);
    return bad;
}

/* eval's skin method: the skin-colour key is the mask; no model, so no
 * depth: fuse_depth_fill gives every pixel the far plane. */
static long run_skin(ef_isa isa, int with_depth, uint64_t crc[NF], long *min_shown)
{
    fuse_context_desc cd = {isa, 1};
    fuse_context *ctx = fuse_context_create(&cd);
    assert_non_null(ctx);
    uint8_t *mask = malloc((size_t)CW * CH), *layer = malloc((size_t)CW * CH * 4);
    uint8_t *out = malloc((size_t)OW * OH * 4);
    float *nrm = calloc((size_t)CW * CH * 3, sizeof(float));
    float *hz = malloc(sizeof(float) * CW * CH);
    assert_true(mask && layer && out && nrm && hz);
    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    fuse_lighting L = fuse_lighting_default();
    long bad = 0;
    *min_shown = -1;
    for (int f = 0; f < NF; f++) {
        crc[f] = 0;
        for (int e = 0; e < 2; e++) {
            fuse_image P = fuse_image_rows(
                &(fuse_image){W.cam[f][e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W}, W.g.crop_y0, CH);
            fuse_skin_params sp = fuse_skin_params_default();
            assert_int_equal(fuse_skin_key(&sp, &P, mask, CW), FUSE_OK);
            for (size_t i = 0; i < (size_t)CW * CH; i++) hz[i] = 1.0f;
            assert_true(fuse_depth_fill(mask, CW, hz, CW, CW, CH, 2, NULL) >= 0);
            fuse_intrinsics K = {500.0f, 500.0f, 320.0f, 200.0f};
            fuse_depth dt = {hz, CW, hd.znear, hd.zfar, hd.cam_offset_m,
                             W.vdepth[f][e], OW, OW, OH};
            fuse_eye fe = { .lighting = &L, .intrinsics = &K, .P = P, .mask = mask,
                            .mask_stride = CW, .normal = nrm, .normal_stride = 3 * CW,
                            .Q = { layer, CW, CH, 4 * CW }, .depth = with_depth ? &dt : NULL,
                            .V = { W.V, OW, OH, 4 * OW }, .vp_x0 = W.g.vp_x0,
                            .vp_y0 = W.g.vp_y0, .vp_w = W.g.vp_width, .vp_h = W.g.vp_height,
                            .out = { out, OW, OH, 4 * OW } };
            assert_int_equal(fuse_context_frame(ctx, &fe, 1), FUSE_OK);
            long shown;
            long b = check_eye(layer, out, W.band[f][e], &shown);
            if (with_depth) bad += b;
            if (*min_shown < 0 || shown < *min_shown) *min_shown = shown;
            crc[f] = hash64(crc[f], out, (size_t)OW * OH * 4);
            crc[f] = hash64(crc[f], layer, (size_t)CW * CH * 4);
        }
    }
    EF_FREE_ALL(mask, layer, out, nrm, hz);
    fuse_context_destroy(ctx);
    return bad;
}

static long run_method(int m, ef_isa isa, int with_depth, uint64_t crc[NF], long *min_shown)
{
    return m == M_SKIN ? run_skin(isa, with_depth, crc, min_shown)
                       : run_pipe(m, isa, with_depth, crc, min_shown);
}

static void method_case(int m)
{
    uint64_t ref_crc[NF], crc[NF];
    long shown;
    /* not vacuous: without the depth test the hand is in the band */
    run_method(m, EF_ISA_REF, 0, crc, &shown);
    printf("%-11s without the depth test: at least %ld hand pixels in the band\n",
           method_name[m], shown);
    assert_true(shown >= MIN_SHOWN);
    long bad = run_method(m, EF_ISA_REF, 1, ref_crc, &shown);
    printf("%-11s aa %d ref: %ld hand pixels behind the object\n", method_name[m], g_aa, bad);
    assert_int_equal(bad, 0);
    for (int isa = EF_ISA_SSE2; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa)) continue;
        bad = run_method(m, (ef_isa)isa, 1, crc, &shown);
        printf("%-11s %s: %ld hand pixels behind the object\n", method_name[m],
               ef_isa_name((ef_isa)isa), bad);
        assert_int_equal(bad, 0);
        for (int f = 0; f < NF; f++) assert_true(crc[f] == ref_crc[f]);
    }
}

static void occl_kin(void **state) { (void)state; method_case(M_KIN); }
static void occl_kin_pred(void **state) { (void)state; method_case(M_KIN_PRED); }
static void occl_refine(void **state) { (void)state; method_case(M_REFINE); }
static void occl_refine_anim(void **state) { (void)state; method_case(M_REFINE_ANIM); }
static void occl_skin(void **state) { (void)state; method_case(M_SKIN); }
/* The same with anti-aliased silhouettes (pipe_desc.aa_samples): the
 * coverage beyond the model's pixel centres takes the model's depth
 * beside it. The skin method has no model (no coverage samples). */
static void aa_case(int m, int aa)
{
    g_aa = aa;
    method_case(m);
    g_aa = 0;
}
static void occl_kin_aa(void **state) { (void)state; aa_case(M_KIN, 16); }
static void occl_kin_pred_aa(void **state) { (void)state; aa_case(M_KIN_PRED, 4); }
static void occl_refine_aa(void **state) { (void)state; aa_case(M_REFINE, 8); }
static void occl_refine_anim_aa(void **state) { (void)state; aa_case(M_REFINE_ANIM, 16); }
/* The same with soft silhouettes (pipe_desc.soft_edge: the binary mask's
 * edge faded inside it, pipe_soft.h). */
static void soft_case(int m)
{
    g_soft = 1;
    method_case(m);
    g_soft = 0;
}
static void occl_kin_pred_soft(void **state) { (void)state; soft_case(M_KIN_PRED); }
static void occl_refine_soft(void **state) { (void)state; soft_case(M_REFINE); }
/* Fast hands: no prior, each hand moved to where its colour is
 * (fit_shift.h) before the band; the moved pixels the depth fill does not
 * reach get the far plane, so the object still hides them. Not vacuous:
 * without the shift (refine_shift -1) some frame's bytes differ. */
static void occl_refine_fast(void **state)
{
    (void)state;
    g_fast = 1;
    method_case(M_REFINE);
    uint64_t on[NF], off[NF];
    long shown;
    run_method(M_REFINE, EF_ISA_REF, 1, on, &shown);
    g_shift = -1;
    run_method(M_REFINE, EF_ISA_REF, 1, off, &shown);
    g_shift = 0;
    g_fast = 0;
    int differ = 0;
    for (int f = 0; f < NF; f++) differ += on[f] != off[f];
    printf("refine fast: %d of %d frames moved by the shift\n", differ, NF);
    assert_true(differ > 0);
}

/* fuse_depth_fill's rule on small cases: nearest known depth, ties to
 * the upper row then the left column, sources only the depths before the
 * call, the far plane beyond the radius, nothing else written, bad
 * arguments refused. */
static void fill_rule(void **state)
{
    (void)state;
    enum { w = 9, h = 7 };
    uint8_t m[w * h];
    float z[w * h];
    int box[4];
    memset(m, 0, sizeof m);
    for (int i = 0; i < w * h; i++) z[i] = 1.0f;
    z[3 * w + 1] = 0.25f;             /* (1, 3) */
    z[3 * w + 5] = 0.75f;             /* (5, 3) */
    m[3 * w + 3] = 255;               /* equidistant (2): ties -> same row: left */
    m[2 * w + 3] = 255;               /* (3,2): d2 5 to both: upper row equal -> left */
    m[3 * w + 6] = 255;               /* next to (5,3) */
    m[3 * w + 1] = 255;               /* known: untouched */
    m[0 * w + 8] = 255;               /* (8,0): nearest (5,3) at d2 18 */
    z[6 * w + 0] = NAN;               /* unknown, mask 0: untouched */
    long n = fuse_depth_fill(m, w, z, w, w, h, 4, box);
    assert_int_equal(n, 4);
    assert_true(z[3 * w + 3] == 0.25f);
    assert_true(z[2 * w + 3] == 0.25f);
    assert_true(z[3 * w + 6] == 0.75f);
    assert_true(z[0 * w + 8] == 0.75f);
    assert_true(z[3 * w + 1] == 0.25f);
    assert_true(isnan(z[6 * w + 0]));
    assert_true(z[0] == 1.0f);
    assert_int_equal(box[0], 3);
    assert_int_equal(box[1], 0);
    assert_int_equal(box[2], 9);
    assert_int_equal(box[3], 4);
    /* beyond the radius: the far plane (below 1, so the depth test uses it) */
    for (int i = 0; i < w * h; i++) z[i] = 1.0f;
    memset(m, 0, sizeof m);
    z[0] = 0.5f;
    m[6 * w + 8] = 255;
    assert_int_equal(fuse_depth_fill(m, w, z, w, w, h, 3, box), 1);
    assert_true(z[6 * w + 8] < 1.0f && z[6 * w + 8] > 0.99999f);
    /* filled pixels are never sources: a row of unknown pixels all take
     * the one known depth, not their neighbour's */
    for (int i = 0; i < w * h; i++) z[i] = 1.0f;
    memset(m, 0, sizeof m);
    z[0] = 0.125f;
    for (int x = 1; x < w; x++) m[x] = 255;
    assert_int_equal(fuse_depth_fill(m, w, z, w, w, h, 4, NULL), 8);
    for (int x = 1; x <= 4; x++) assert_true(z[x] == 0.125f);
    for (int x = 5; x < w; x++) assert_true(z[x] < 1.0f && z[x] > 0.99999f);
    /* nothing to do */
    memset(m, 0, sizeof m);
    assert_int_equal(fuse_depth_fill(m, w, z, w, w, h, 4, box), 0);
    assert_int_equal(box[2], 0);
    /* bad arguments */
    assert_int_equal(fuse_depth_fill(NULL, w, z, w, w, h, 4, box), -1);
    assert_int_equal(fuse_depth_fill(m, w, NULL, w, w, h, 4, box), -1);
    assert_int_equal(fuse_depth_fill(m, w - 1, z, w, w, h, 4, box), -1);
    assert_int_equal(fuse_depth_fill(m, w, z, w - 1, w, h, 4, box), -1);
    assert_int_equal(fuse_depth_fill(m, w, z, w, 0, h, 4, box), -1);
    assert_int_equal(fuse_depth_fill(m, w, z, w, w, h, 0, box), -1);
    assert_int_equal(fuse_depth_fill(m, w, z, w, w, h, FUSE_DEPTH_FILL_MAX_RADIUS + 1, box), -1);
}

/* One seeded case of fill_reference: blobs of known depths, masks grown
 * around them, specks and unknown depths of every kind on a w x h image;
 * fuse_depth_fill with radius R against a brute-force reference of its
 * rule (every pixel of the square, in the ties' order). Counts the pixels
 * filled from a source and with the far plane. */
enum { FILL_MAX_PX = 1300 * 37 };

static void fill_case(tu_rng *g, int w, int h, int R, int nb, const char *what, int c,
                      long *near, long *far)
{
    static uint8_t m[FILL_MAX_PX];
    static float z[FILL_MAX_PX], z0[FILL_MAX_PX], want[FILL_MAX_PX];
    assert_true(w * h <= FILL_MAX_PX);
    for (int i = 0; i < w * h; i++) {
        const int k = tu_int(g, 50);
        z0[i] = k == 0 ? NAN : k == 1 ? -0.0f : k == 2 ? 2.5f : 1.0f;
        m[i] = tu_int(g, 30) == 0 ? 255 : 0;
    }
    for (int b = 0; b < nb; b++) {
        const float cx = tu_range(g, 0, w), cy = tu_range(g, 0, h);
        const float rad = tu_range(g, 1, 8), grow = tu_range(g, 0, 6);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                const float dx = x + 0.5f - cx, dy = y + 0.5f - cy, d2 = dx * dx + dy * dy;
                if (d2 < rad * rad) z0[y * w + x] = tu_range(g, 0.0f, 0.999f);
                if (d2 < (rad + grow) * (rad + grow)) m[y * w + x] = 255;
            }
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const int i = y * w + x;
            const float v = z0[i];
            want[i] = v;
            if (!m[i] || (v >= 0.0f && v < 1.0f)) continue;
            long bd = -1;
            float src = 0.0f;
            for (int dy = -R; dy <= R; dy++)
                for (int dx = -R; dx <= R; dx++) {
                    const int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    const float s = z0[yy * w + xx];
                    if (!(s >= 0.0f && s < 1.0f)) continue;
                    const long d2 = (long)dx * dx + (long)dy * dy;
                    if (bd < 0 || d2 < bd) {
                        bd = d2;
                        src = s;
                    }
                }
            if (bd < 0) {
                const uint32_t bits = 0x3F7FFFFFu;
                memcpy(&src, &bits, sizeof src);
                (*far)++;
            } else
                (*near)++;
            want[i] = src;
        }
    memcpy(z, z0, sizeof z[0] * (size_t)(w * h));
    assert_true(fuse_depth_fill(m, w, z, w, w, h, R, NULL) >= 0);
    if (memcmp(z, want, sizeof z[0] * (size_t)(w * h)) != 0)
        fail_msg("%s case %d (%dx%d, radius %d): other bytes", what, c, w, h, R);
}

/* fuse_depth_fill against the brute-force reference (fill_case): 400
 * small images with radii 1-9, 150 with the pipeline's radii (10-24, the
 * sample's band 16 gives 20) and 12 wider than the depth fill's cache of
 * column states (1024), where columns x and x + 1024 share a slot. */
static void fill_reference(void **state)
{
    (void)state;
    tu_rng g = {77};
    long near = 0, far = 0, near_big = 0, far_big = 0;
    for (int c = 0; c < 400; c++) {
        const int R = 1 + c % 9;
        fill_case(&g, 37, 29, R, tu_int(&g, 4), "small", c, &near, &far);
    }
    printf("fill_reference: %ld filled from a source, %ld the far plane\n", near, far);
    assert_true(near > 10000 && far > 100);
    for (int c = 0; c < 150; c++)
        fill_case(&g, 61, 47, 10 + c % 15, 1 + tu_int(&g, 6), "radius", c, &near_big, &far_big);
    for (int c = 0; c < 12; c++)
        fill_case(&g, 1300, 37, 4 + 2 * c, 20 + tu_int(&g, 40), "wide", c, &near_big, &far_big);
    printf("fill_reference, large radii and wide: %ld from a source, %ld the far plane\n",
           near_big, far_big);
    assert_true(near_big > 10000 && far_big > 100);
}

TU_MAIN(setup, teardown,
        cmocka_unit_test(fill_rule),
        cmocka_unit_test(fill_reference),
        cmocka_unit_test(occl_kin),
        cmocka_unit_test(occl_kin_pred),
        cmocka_unit_test(occl_refine),
        cmocka_unit_test(occl_refine_anim),
        cmocka_unit_test(occl_skin),
        cmocka_unit_test(occl_kin_aa),
        cmocka_unit_test(occl_kin_pred_aa),
        cmocka_unit_test(occl_refine_aa),
        cmocka_unit_test(occl_refine_anim_aa),
        cmocka_unit_test(occl_kin_pred_soft),
        cmocka_unit_test(occl_refine_soft),
        cmocka_unit_test(occl_refine_fast))
