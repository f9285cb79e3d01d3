/* bench_fuse.c - ms per stereo frame of the fuse stages, per ISA, 1 and 2
 * threads, for a typical hand (25% of the camera view) and a worst case
 * (70%), against the memory floor and pixman measured in the same run.
 * Reports, never passes or fails.
 *
 *   bench_fuse [--csv] [--runs N] [--isa ref|sse2|avx2|avx512]
 *              [--threads 1|2] [--case typical|worst] [--no-pixman] [--cpu-time]
 *              [--stage NAME] [--float-normals]
 *
 * Per stereo frame (two eyes: 640x400 camera images lit, resampled into
 * the 1194x746 viewport at (43, 27) of 1280x800, composited over V):
 *   light      fuse_context_light, both eyes
 *   comp       fuse_context_composite into a separate out (reads V, writes
 *              out: the whole 1280x800 frame is written)
 *   frame      fuse_context_frame, out separate from V
 *   frame_ip   fuse_context_frame in place (out == V), what src/pipe does:
 *              transparent spans of the layer cost a read of V and no write
 *   frame_dp   frame_ip with the depth test against the virtual scene's
 *              depth (a "bottle" at 0.38 m over a tenth of the width, in
 *              front of part of the hands at 0.33-0.45 m)
 *   frame_op   frame_ip with fuse_eye.v_opaque = 1 (V is opaque: the spans
 *              the layer does not reach are neither read nor written)
 *   frame_dop  frame_dp with v_opaque = 1
 *   dop_l2     frame_dop with the sample scene's lighting (build/samples'
 *              scene.txt: two lights, ks 0.12, s 20), as bench_frame lights
 *   dop_cold   frame_dop with its inputs out of the caches (64 MB written
 *              right before the call, untimed), as in a frame whose V and
 *              scene depth come from memory
 *   dop_l2c    both
 *   like_frame dop_l2c out of place (out != V, as bench_frame runs the
 *              pipe: its V images are kept, so the transparent spans are a
 *              copy V -> out): what the frame's fuse stage does
 *   memcpy     V -> out of both eyes (2 x 4.1 MB) with as many threads as
 *              the row (one eye per thread with 2): the memory floor
 *   pixman     single-threaded, in place on a copy of V (pixman's dst):
 *     pm_blend   OVER of a 1194x746 premultiplied layer through a 1194x746
 *                a8 mask, no scaling: the pure blend cost
 *     pm_scaled  OVER of the 640x400 premultiplied layer Q, bilinear into
 *                the viewport (PAD edges): what fuse_composite does
 *     pm_scaled_mask  the camera image (x8r8g8b8) through the a8 mask, both
 *                bilinear into the viewport (a composite without lighting)
 * The lighting reads the normals packed as ef_n10 (src/cpu/ef_n10.h, packed
 * once at setup with ef_n10_pack): fuse_context_light_n10 and
 * fuse_eye.normal_n10, 4 bytes a pixel, as the pipe does by default;
 * --float-normals reads 3 floats (12 bytes) instead (the bytes differ by
 * the packing's rounding only).
 * Every number is the median over --runs runs; the ratios are medians of
 * the per-run ratios (each run times memcpy, then the stages, back to
 * back), which cancels most of the noise of a shared machine. The scene V
 * is opaque (alpha 255), as a rendered scene is. */
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../src/cpu/cpu.h"
#include "../src/cpu/ef_n10.h"
#include "../src/fuse/fuse.h"
#include "bench_util.h"

#if defined(__has_include)
#if __has_include(<pixman.h>)
#include <pixman.h>
#define HAVE_PIXMAN 1
#endif
#endif

enum { CW = 640, CH = 400, W = 1280, H = 800, VX = 43, VY = 27, VW = 1194, VHH = 746 };

/* --cpu-time: the calling thread's CPU time instead of the wall clock
 * (insensitive to being descheduled on a loaded machine; meaningful for
 * the 1-thread rows only, as the other threads' time is not counted). */
static clockid_t clock_id = CLOCK_MONOTONIC;

/* --stage NAME: run (and time) only that stage of each run (the others
 * print 0), for profilers (perf record, cachegrind): light, comp, frame,
 * ip, dp, op, dop, l2, cold, l2c, like; NULL: all of them. */
static const char *only_stage;
static int want(const char *name) { return only_stage == NULL || !strcmp(only_stage, name); }

/* the lighting reads eye_buf.Nq (ef_n10), or N (floats: --float-normals) */
static int use_n10 = 1;

static double now_ms(void) { return bench_now_ms(clock_id); }

static uint64_t rng = 0x1234567u;
static uint32_t rnd(void) { return bench_rand(&rng); }

static void *xmalloc(size_t n) { return bench_xmalloc(n, "bench_fuse"); }

typedef struct eye_buf {
    uint8_t *P, *M, *Q, *V, *out, *Vip;   /* Vip: V for the in-place runs */
    float *N;
    uint32_t *Nq;                         /* N packed as ef_n10 */
    float *hz, *sd;                       /* hand window depth, scene metres */
} eye_buf;

/* the depth test's projection */
#define ZNEAR 0.05f
#define ZFAR 10.0f

/* window depth of metric distance d (fuse.h, "depth test", inverted) */
static float window_z(double d)
{
    const double fpn = ZFAR + ZNEAR, fmn = ZFAR - ZNEAR, two_fn = 2.0 * ZFAR * ZNEAR;
    return (float)(((fpn - two_fn / d) / fmn + 1.0) * 0.5);
}

/* Two elliptical "hands" side by side covering about `cover` of the image,
 * with a soft edge of ~3 pixels. Returns the share of pixels with M > 0. */
static double make_eye(eye_buf *e, double cover)
{
    const double a = 0.25 * CW * sqrt(cover * 8 / 3.14159265 / 1.6), b = a * 1.6 * CH / CW;
    long on = 0;
    int x, y, i;
    e->P = xmalloc(CW * CH * 4);
    e->M = xmalloc(CW * CH);
    e->Q = xmalloc(CW * CH * 4);
    e->N = xmalloc(sizeof(float) * CW * CH * 3);
    e->Nq = xmalloc(sizeof(uint32_t) * CW * CH);
    e->V = xmalloc(W * H * 4);
    e->out = xmalloc(W * H * 4);
    e->Vip = xmalloc(W * H * 4);
    e->hz = xmalloc(sizeof(float) * CW * CH);
    e->sd = xmalloc(sizeof(float) * W * H);
    for (i = 0; i < W * H; i++)
        e->sd[i] = (i % W) >= W * 45 / 100 && (i % W) < W * 55 / 100 ? 0.38f : 0.0f;
    for (i = 0; i < CW * CH * 4; i++) e->P[i] = (uint8_t)rnd();
    for (i = 0; i < W * H * 4; i++) e->V[i] = (uint8_t)(i % 4 == 3 ? 255 : rnd());
    memcpy(e->Vip, e->V, W * H * 4);
    memcpy(e->out, e->V, W * H * 4);
    for (y = 0; y < CH; y++)
        for (x = 0; x < CW; x++) {
            const double cx = x < CW / 2 ? CW * 0.25 : CW * 0.75;
            const double dx = (x + 0.5 - cx) / a, dy = (y + 0.5 - CH * 0.5) / b;
            const double d = sqrt(dx * dx + dy * dy);
            const size_t k = (size_t)y * CW + x;
            const double edge = 3.0 / a;
            e->M[k] = d < 1 - edge ? 255 : d < 1 ? (uint8_t)(255 * (1 - d) / edge) : 0;
            e->N[3 * k] = (float)dx;
            e->N[3 * k + 1] = (float)-dy;
            e->N[3 * k + 2] = (float)sqrt(fmax(0.05, 1 - d * d));
            e->Nq[k] = ef_n10_pack(e->N[3 * k], e->N[3 * k + 1], e->N[3 * k + 2]);
            e->hz[k] = d < 1 ? window_z(0.45 - 0.12 * sqrt(1 - d * d)) : 1.0f;
            on += e->M[k] != 0;
        }
    return (double)on / (CW * CH);
}

static void free_eye(eye_buf *e)
{
    free(e->P); free(e->M); free(e->Q); free(e->N); free(e->Nq); free(e->V); free(e->out); free(e->Vip);
    free(e->hz); free(e->sd);
}

/* ---- the memory floor: memcpy on 1 or 2 threads ------------------------- */

typedef struct copier {
    pthread_t th;
    pthread_barrier_t start, done;
    eye_buf *eye;      /* the eye the helper copies */
    int quit;
} copier;

static void *copier_main(void *p)
{
    copier *c = p;
    for (;;) {
        pthread_barrier_wait(&c->start);
        if (c->quit) break;
        memcpy(c->eye->out, c->eye->V, (size_t)W * H * 4);
        pthread_barrier_wait(&c->done);
    }
    return NULL;
}

static void copier_start(copier *c, eye_buf *second)
{
    c->eye = second;
    c->quit = 0;
    pthread_barrier_init(&c->start, NULL, 2);
    pthread_barrier_init(&c->done, NULL, 2);
    if (pthread_create(&c->th, NULL, copier_main, c) != 0) exit(2);
}

static void copier_stop(copier *c)
{
    c->quit = 1;
    pthread_barrier_wait(&c->start);
    pthread_join(c->th, NULL);
    pthread_barrier_destroy(&c->start);
    pthread_barrier_destroy(&c->done);
}

/* ms of memcpy V -> out of both eyes, on the calling thread or (c != NULL)
 * one eye per thread. */
static double time_memcpy(eye_buf e[2], copier *c)
{
    const double t0 = now_ms();
    if (c != NULL) {
        pthread_barrier_wait(&c->start);
        memcpy(e[0].out, e[0].V, (size_t)W * H * 4);
        pthread_barrier_wait(&c->done);
    } else {
        memcpy(e[0].out, e[0].V, (size_t)W * H * 4);
        memcpy(e[1].out, e[1].V, (size_t)W * H * 4);
    }
    return now_ms() - t0;
}

/* ---- egofuse ------------------------------------------------------------ */

typedef struct stats {
    double light, comp, frame, frame_ip, frame_dp, frame_op, frame_dop, memcpy;
    double r_frame, r_frame_ip, r_frame_dp, r_frame_op, r_frame_dop;   /* medians of x / memcpy per run */
    double dop_l2, dop_cold, dop_l2c;   /* frame_dop: scene lighting, cold inputs, both */
    double like_frame;                  /* dop_l2c out of place */
} stats;

/* The sample scene's lighting (samples/gen: build/samples/scene.txt), the
 * directions taken as view-space directions (timing only). */
static fuse_lighting scene_lighting(void)
{
    static const fuse_lighting L = {
        2,
        { { { -0.7884f, 0.5781f, 0.2102f }, { 0.620f, 0.700f, 0.820f } },
          { { 0.3271f, 0.9345f, 0.1402f }, { 0.450f, 0.380f, 0.280f } } },
        { 0.28f, 0.30f, 0.32f },   /* ambient */
        0.80f, 0.12f, 20.0f,        /* kd, ks, shininess */
        0.50f,                      /* kf */
        { 1.0f, 0.98f, 0.96f }      /* tone */
    };
    return L;
}

/* Writes and reads 64 MB (more than the last-level cache) so that the
 * next call finds its inputs in memory. Untimed. */
static volatile uint64_t evict_sink;
static void evict_caches(void);

/* One stereo frame of stage `stage` (if wanted) in ms; cold: the caches
 * evicted before it (not timed). */
static double frame_ms(fuse_context *ctx, const char *stage, fuse_eye *eyes, int cold)
{
    if (cold && want(stage)) evict_caches();
    double t0 = now_ms();
    if (want(stage) && fuse_context_frame(ctx, eyes, 2) != FUSE_OK) exit(3);
    return now_ms() - t0;
}

static void evict_caches(void)
{
    static uint64_t *buf;
    const size_t n = (64u << 20) / 8;
    uint64_t acc = 0;
    size_t i;
    if (buf == NULL) buf = xmalloc(n * 8);
    for (i = 0; i < n; i += 8) buf[i] = i;
    for (i = 0; i < n; i += 8) acc += buf[i];
    evict_sink = acc;
}

static void run_stages(fuse_context *ctx, eye_buf e[2], int threads, int runs, stats *s)
{
    const fuse_lighting L = fuse_lighting_default(), L2 = scene_lighting();
    const fuse_intrinsics K = { 532.0f, 532.0f, CW / 2.0f, CH / 2.0f };
    double *t[17];
    fuse_eye eyes[2], ip[2], dp[2], op[2], dop[2], dop2[2], like[2];
    fuse_depth depth[2];
    copier cp;
    int k, i;
    for (i = 0; i < 17; i++) t[i] = xmalloc(sizeof(double) * (size_t)runs);
    for (i = 0; i < 2; i++) {
        eyes[i] = (fuse_eye){ &L, &K, { e[i].P, CW, CH, 4 * CW }, e[i].M, CW, e[i].N, 3 * CW,
                              { e[i].Q, CW, CH, 4 * CW }, NULL, { e[i].V, W, H, 4 * W },
                              VX, VY, VW, VHH, { e[i].out, W, H, 4 * W }, 0, 0, 0u, NULL, NULL, 0 };
        if (use_n10) {
            eyes[i].normal = NULL;
            eyes[i].normal_n10 = e[i].Nq;
            eyes[i].normal_n10_stride = CW;
        }
        ip[i] = eyes[i];
        ip[i].V = ip[i].out = (fuse_image){ e[i].Vip, W, H, 4 * W };
        depth[i] = (fuse_depth){ e[i].hz, CW, ZNEAR, ZFAR, 0.0f, e[i].sd, W, W, H };
        dp[i] = ip[i];
        dp[i].depth = &depth[i];
        op[i] = ip[i];
        op[i].v_opaque = 1;
        dop[i] = dp[i];
        dop[i].v_opaque = 1;
        dop2[i] = dop[i];
        dop2[i].lighting = &L2;
        like[i] = dop2[i];
        like[i].V = eyes[i].V;
        like[i].out = eyes[i].out;
    }
    /* the frames' times (index 0) and their ratios to memcpy (1) */
    static const int ratio[5][2] = { { 2, 5 }, { 3, 6 }, { 7, 8 }, { 9, 10 }, { 11, 12 } };
    if (threads > 1) copier_start(&cp, &e[1]);
    for (k = -3; k < runs; k++) {   /* 3 warm-up runs */
        double m, t0, t1, t2;
        const int k0 = k < 0 ? 0 : k;   /* the warm-up runs' times: overwritten */
        m = only_stage == NULL || !strcmp(only_stage, "memcpy") ? time_memcpy(e, threads > 1 ? &cp : NULL) : 1.0;
        t0 = now_ms();
        for (i = 0; i < 2 && want("light"); i++)
            if ((use_n10 ? fuse_context_light_n10(ctx, &L, &K, &eyes[i].P, e[i].M, CW, e[i].Nq, CW,
                                                  &eyes[i].Q)
                         : fuse_context_light(ctx, &L, &K, &eyes[i].P, e[i].M, CW, e[i].N, 3 * CW,
                                              &eyes[i].Q)) != FUSE_OK) exit(3);
        t1 = now_ms();
        for (i = 0; i < 2 && want("comp"); i++)
            if (fuse_context_composite(ctx, &eyes[i].Q, &eyes[i].V, VX, VY, VW, VHH,
                                       &eyes[i].out) != FUSE_OK) exit(3);
        t2 = now_ms();
        t[2][k0] = frame_ms(ctx, "frame", eyes, 0);
        t[3][k0] = frame_ms(ctx, "ip", ip, 0);
        t[7][k0] = frame_ms(ctx, "dp", dp, 0);
        t[9][k0] = frame_ms(ctx, "op", op, 0);
        t[11][k0] = frame_ms(ctx, "dop", dop, 0);
        t[13][k0] = frame_ms(ctx, "l2", dop2, 0);
        t[14][k0] = frame_ms(ctx, "cold", dop, 1);
        t[15][k0] = frame_ms(ctx, "l2c", dop2, 1);
        t[16][k0] = frame_ms(ctx, "like", like, 1);
        if (k < 0) continue;
        t[0][k] = t1 - t0;
        t[1][k] = t2 - t1;
        t[4][k] = m;
        for (i = 0; i < 5; i++) t[ratio[i][1]][k] = t[ratio[i][0]][k] / m;
    }
    if (threads > 1) copier_stop(&cp);
    {   /* t[i] -> its field */
        double *const dst[17] = { &s->light, &s->comp, &s->frame, &s->frame_ip, &s->memcpy,
                                  &s->r_frame, &s->r_frame_ip, &s->frame_dp, &s->r_frame_dp,
                                  &s->frame_op, &s->r_frame_op, &s->frame_dop, &s->r_frame_dop,
                                  &s->dop_l2, &s->dop_cold, &s->dop_l2c, &s->like_frame };
        for (i = 0; i < 17; i++) {
            *dst[i] = bench_median(t[i], runs);
            free(t[i]);
        }
    }
}

/* ---- pixman ------------------------------------------------------------- */

typedef struct pm_stats { double blend, scaled, scaled_mask, memcpy; } pm_stats;

#ifdef HAVE_PIXMAN
/* The three pixman composites of both eyes (see the top), each timed with a
 * memcpy right before it; medians. dst is a copy of V per eye. */
static void bench_pixman(eye_buf e[2], int runs, pm_stats *s)
{
    pixman_image_t *lay[2], *lmask[2], *q[2], *cam[2], *msk[2], *dst[2];
    uint8_t *big[2], *bigm[2], *dbuf[2];
    pixman_transform_t tr;
    double *t[4];
    int k, i, x, y;
    const int mstride = (VW + 3) & ~3;
    for (i = 0; i < 4; i++) t[i] = xmalloc(sizeof(double) * (size_t)runs);
    pixman_transform_init_scale(&tr, pixman_double_to_fixed((double)CW / VW),
                                pixman_double_to_fixed((double)CH / VHH));
    for (i = 0; i < 2; i++) {
        /* the lit layer and the mask, nearest-upscaled to the viewport */
        big[i] = xmalloc((size_t)VW * VHH * 4);
        bigm[i] = xmalloc((size_t)mstride * VHH);
        dbuf[i] = xmalloc((size_t)W * H * 4);
        memcpy(dbuf[i], e[i].V, (size_t)W * H * 4);
        for (y = 0; y < VHH; y++)
            for (x = 0; x < VW; x++) {
                const int sx = x * CW / VW, sy = y * CH / VHH;
                memcpy(big[i] + 4 * ((size_t)y * VW + x), e[i].Q + 4 * ((size_t)sy * CW + sx), 4);
                bigm[i][(size_t)y * mstride + x] = e[i].M[(size_t)sy * CW + sx];
            }
        lay[i] = pixman_image_create_bits(PIXMAN_a8r8g8b8, VW, VHH, (uint32_t *)(void *)big[i], 4 * VW);
        lmask[i] = pixman_image_create_bits(PIXMAN_a8, VW, VHH, (uint32_t *)(void *)bigm[i], mstride);
        q[i] = pixman_image_create_bits(PIXMAN_a8r8g8b8, CW, CH, (uint32_t *)(void *)e[i].Q, 4 * CW);
        cam[i] = pixman_image_create_bits(PIXMAN_x8r8g8b8, CW, CH, (uint32_t *)(void *)e[i].P, 4 * CW);
        msk[i] = pixman_image_create_bits(PIXMAN_a8, CW, CH, (uint32_t *)(void *)e[i].M, CW);
        dst[i] = pixman_image_create_bits(PIXMAN_a8r8g8b8, W, H, (uint32_t *)(void *)dbuf[i], 4 * W);
        pixman_image_set_transform(q[i], &tr);
        pixman_image_set_transform(cam[i], &tr);
        pixman_image_set_transform(msk[i], &tr);
        pixman_image_set_filter(q[i], PIXMAN_FILTER_BILINEAR, NULL, 0);
        pixman_image_set_filter(cam[i], PIXMAN_FILTER_BILINEAR, NULL, 0);
        pixman_image_set_filter(msk[i], PIXMAN_FILTER_BILINEAR, NULL, 0);
        pixman_image_set_repeat(q[i], PIXMAN_REPEAT_PAD);
        pixman_image_set_repeat(cam[i], PIXMAN_REPEAT_PAD);
        pixman_image_set_repeat(msk[i], PIXMAN_REPEAT_PAD);
    }
    for (k = -2; k < runs; k++) {
        double m = time_memcpy(e, NULL), t0, t1, t2, t3;
        t0 = now_ms();
        for (i = 0; i < 2; i++)
            pixman_image_composite32(PIXMAN_OP_OVER, lay[i], lmask[i], dst[i], 0, 0, 0, 0, VX, VY, VW, VHH);
        t1 = now_ms();
        for (i = 0; i < 2; i++)
            pixman_image_composite32(PIXMAN_OP_OVER, q[i], NULL, dst[i], 0, 0, 0, 0, VX, VY, VW, VHH);
        t2 = now_ms();
        for (i = 0; i < 2; i++)
            pixman_image_composite32(PIXMAN_OP_OVER, cam[i], msk[i], dst[i], 0, 0, 0, 0, VX, VY, VW, VHH);
        t3 = now_ms();
        if (k < 0) continue;
        t[0][k] = t1 - t0;
        t[1][k] = t2 - t1;
        t[2][k] = t3 - t2;
        t[3][k] = m;
    }
    s->blend = bench_median(t[0], runs);
    s->scaled = bench_median(t[1], runs);
    s->scaled_mask = bench_median(t[2], runs);
    s->memcpy = bench_median(t[3], runs);
    for (i = 0; i < 2; i++) {
        pixman_image_unref(lay[i]); pixman_image_unref(lmask[i]); pixman_image_unref(q[i]);
        pixman_image_unref(cam[i]); pixman_image_unref(msk[i]); pixman_image_unref(dst[i]);
        free(big[i]); free(bigm[i]); free(dbuf[i]);
    }
    for (i = 0; i < 4; i++) free(t[i]);
}
#endif

static void usage(const char *argv0)
{
    fprintf(stderr, "usage: %s [--csv] [--runs N] [--isa ref|sse2|avx2|avx512] "
            "[--threads 1|2] [--case typical|worst] [--no-pixman] [--cpu-time] [--stage NAME] "
            "[--float-normals]\n"
            "  --float-normals: the lighting reads 3 floats per pixel, not ef_n10\n"
            "  --stage light|comp|frame|ip|dp|op|dop|l2|cold|l2c|like|memcpy: only that stage\n", argv0);
    exit(2);
}

int main(int argc, char **argv)
{
    static const ef_isa isas[] = { EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512 };
    static const double covers[2] = { 0.25, 0.70 };
    static const char *cover_name[2] = { "typical", "worst" };
    int csv = 0, runs = 51, a, c, i, t, only_threads = 0, only_case = -1, no_pixman = 0;
    ef_isa only_isa = EF_ISA_DEFAULT;
    char cpu[256];
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--csv")) csv = 1;
        else if (!strcmp(argv[a], "--runs") && a + 1 < argc) runs = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--isa") && a + 1 < argc) {
            only_isa = ef_isa_parse(argv[++a]);
            if (only_isa == EF_ISA_DEFAULT) usage(argv[0]);
        } else if (!strcmp(argv[a], "--threads") && a + 1 < argc) {
            only_threads = atoi(argv[++a]);
            if (only_threads < 1 || only_threads > 2) usage(argv[0]);
        } else if (!strcmp(argv[a], "--case") && a + 1 < argc) {
            a++;
            only_case = !strcmp(argv[a], "typical") ? 0 : !strcmp(argv[a], "worst") ? 1 : -2;
            if (only_case == -2) usage(argv[0]);
        } else if (!strcmp(argv[a], "--no-pixman"))
            no_pixman = 1;
        else if (!strcmp(argv[a], "--cpu-time"))
            clock_id = CLOCK_THREAD_CPUTIME_ID;
        else if (!strcmp(argv[a], "--float-normals"))
            use_n10 = 0;
        else if (!strcmp(argv[a], "--stage") && a + 1 < argc) {
            only_stage = argv[++a];
            no_pixman = 1;
        }
        else
            usage(argv[0]);
    }
    if (runs < 3) runs = 3;
    bench_cpu_name(cpu, sizeof cpu);
    printf("%smachine: %s, %ld cpus\n", csv ? "# " : "", cpu, sysconf(_SC_NPROCESSORS_ONLN));
    printf("%scompiler: %s\n", csv ? "# " : "",
#ifdef __VERSION__
           __VERSION__
#else
           "unknown"
#endif
    );
    printf("%sisa: cpu best %s, EGOFUSE_ISA %s; pixman %s; medians of %d runs; %s\n",
           csv ? "# " : "",
           ef_isa_name(ef_cpu_best()), getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "unset",
#ifdef HAVE_PIXMAN
           pixman_version_string(),
#else
           "not built in",
#endif
           runs, clock_id == CLOCK_MONOTONIC ? "wall clock" : "CPU time of the calling thread");
    printf("%snormals: %s\n", csv ? "# " : "",
           use_n10 ? "ef_n10 (4 bytes a pixel)" : "3 floats (12 bytes a pixel)");
    if (csv)
        printf("case,coverage,isa,threads,light_ms,composite_ms,light_plus_composite_ms,frame_ms,"
               "frame_inplace_ms,memcpy_ms,frame_over_memcpy,frame_inplace_over_memcpy,"
               "pixman_blend_ms,pixman_scaled_ms,pixman_scaled_mask_ms,pixman_memcpy_ms,"
               "frame_inplace_over_pixman_blend,frame_inplace_over_pixman_scaled,"
               "frame_depth_ms,frame_depth_over_memcpy,frame_opaque_ms,frame_opaque_over_memcpy,"
               "frame_opaque_depth_ms,frame_opaque_depth_over_memcpy,"
               "frame_opaque_depth_scene_light_ms,frame_opaque_depth_cold_ms,"
               "frame_opaque_depth_scene_light_cold_ms,like_frame_ms\n");
    for (c = 0; c < 2; c++) {
        eye_buf e[2];
        double cov = 0;
        pm_stats pm = { NAN, NAN, NAN, NAN };
        if (only_case >= 0 && only_case != c) continue;
        for (i = 0; i < 2; i++) cov += make_eye(&e[i], covers[c]) / 2;
        {   /* a lit layer for pixman's inputs */
            const fuse_lighting L = fuse_lighting_default();
            const fuse_intrinsics K = { 532.0f, 532.0f, CW / 2.0f, CH / 2.0f };
            for (i = 0; i < 2; i++) {
                fuse_image P = { e[i].P, CW, CH, 4 * CW }, Q = { e[i].Q, CW, CH, 4 * CW };
                if (fuse_light(&L, &K, &P, e[i].M, CW, e[i].N, 3 * CW, &Q) != FUSE_OK) return 3;
            }
        }
#ifdef HAVE_PIXMAN
        if (!no_pixman) bench_pixman(e, runs, &pm);
#endif
        if (!csv)
            printf("\n%s hand: %.1f%% of the camera pixels have M > 0\n"
                   "  pixman (1 thread, in place): blend 1:1 + a8 mask %.3f ms, layer bilinear "
                   "%.3f ms, camera + a8 mask bilinear %.3f ms (memcpy 1 thread %.3f ms)\n"
                   "  %-7s %3s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %7s %8s %8s %8s %7s %7s %7s %7s\n",
                   cover_name[c], 100 * cov, pm.blend, pm.scaled, pm.scaled_mask, pm.memcpy,
                   "isa", "thr", "light", "comp", "frame", "frm_ip", "frm_dp", "frm_op", "frm_dop",
                   "memcpy", "frm/mc", "ip/mc", "dp/mc", "op/mc", "dop/mc", "ip/pm_bl", "ip/pm_sc",
                   "ip/pm_sm", "dop_l2", "dop_cld", "dop_l2c", "like_fr");
        for (i = 0; i < 4; i++) {
            if (only_isa != EF_ISA_DEFAULT && only_isa != isas[i]) continue;
            if (!ef_cpu_has(isas[i]) || ef_isa_choose(isas[i]) != isas[i]) {
                if (!csv) printf("  %-7s SKIP: not available\n", ef_isa_name(isas[i]));
                continue;
            }
            for (t = 1; t <= 2; t++) {
                fuse_context_desc d = { isas[i], t };
                fuse_context *ctx;
                stats s;
                const int n = isas[i] == EF_ISA_REF ? (runs < 7 ? runs : 7) : runs;
                if (only_threads && t != only_threads) continue;
                ctx = fuse_context_create(&d);
                if (!ctx) return 2;
                run_stages(ctx, e, t, n, &s);
                if (csv)
                    printf("%s,%.4f,%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f,%.4f,%.4f,%.4f,"
                           "%.4f,%.3f,%.3f,%.4f,%.3f,%.4f,%.3f,%.4f,%.3f,%.4f,%.4f,%.4f,%.4f\n", cover_name[c], cov,
                           ef_isa_name(isas[i]), t,
                           s.light, s.comp, s.light + s.comp, s.frame, s.frame_ip, s.memcpy,
                           s.r_frame, s.r_frame_ip, pm.blend, pm.scaled, pm.scaled_mask, pm.memcpy,
                           s.frame_ip / pm.blend, s.frame_ip / pm.scaled, s.frame_dp, s.r_frame_dp,
                           s.frame_op, s.r_frame_op, s.frame_dop, s.r_frame_dop, s.dop_l2,
                           s.dop_cold, s.dop_l2c, s.like_frame);
                else
                    printf("  %-7s %3d %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %7.2f %7.2f %7.2f "
                           "%7.2f %7.2f %8.2f %8.2f %8.3f %7.3f %7.3f %7.3f %7.3f\n",
                           ef_isa_name(isas[i]), t, s.light, s.comp, s.frame, s.frame_ip, s.frame_dp,
                           s.frame_op, s.frame_dop, s.memcpy, s.r_frame, s.r_frame_ip, s.r_frame_dp,
                           s.r_frame_op, s.r_frame_dop, s.frame_ip / pm.blend,
                           s.frame_ip / pm.scaled, s.frame_ip / pm.scaled_mask, s.dop_l2, s.dop_cold,
                           s.dop_l2c, s.like_frame);
                fuse_context_destroy(ctx);
            }
        }
        for (i = 0; i < 2; i++) free_eye(&e[i]);
    }
    if (!csv)
        printf("\nms per stereo frame (two eyes), medians. light, comp: the stages called one by\n"
               "one (comp into a separate out); frame: fuse_context_frame (both stages, one eye per\n"
               "thread with 2 threads), out separate; frm_ip: the same in place (out == V, as\n"
               "src/pipe runs it); frm_dp: frm_ip with the depth test; frm_op, frm_dop: frm_ip,\n"
               "frm_dp with fuse_eye.v_opaque = 1. memcpy: V -> out of both eyes with the row's\n"
               "thread count (the floor); frm/mc, ip/mc, dp/mc, op/mc, dop/mc: medians of the\n"
               "per-run ratios to it. ip/pm_*: frm_ip over\n"
               "pixman's blend 1:1 + a8 mask, layer bilinear, camera + mask bilinear (below 1:\n"
               "egofuse is faster). dop_l2: frm_dop with the sample scene's two lights; dop_cld:\n"
               "frm_dop with cold inputs (64 MB written before it); dop_l2c: both (the frame's\n"
               "conditions in place); like_fr: dop_l2c out of place, as bench_frame runs the pipe.\n"
               "The machine is shared: compare ratios, not ms.\n");
    return 0;
}
