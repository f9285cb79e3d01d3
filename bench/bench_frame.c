/* bench_frame.c - the whole stereo frame of egofuse against the 60 FPS
 * budget (issue 8), on the sample sequence (build/samples), in one run:
 *
 *   per frame   camera YUYV -> RGBA (fuse_frame_to_rgba, the eq. 1 rows
 *               only, as a V4L2 camera delivers it; one eye per thread with
 *               2 threads), tracking (One Euro filter + prediction, rig
 *               pose: two-bone IK per arm, gloves -> fingers), FK, LBS
 *               skinning, raster of both eyes, lighting, depth test against
 *               the virtual scene, resampling, composite into both 1280x800
 *               outputs (pipe_frame).
 *   cases       typical: the recorded sequence (reach_grasp, head from the
 *               tracking); worst: one pose with the head moved towards the
 *               hands until they cover ~70% of the camera images (searched
 *               at start-up by bisection on pipe_frame_stats.coverage).
 *   grid        every ISA the CPU runs (ref, sse2, avx2, avx512; the others
 *               are reported as skipped), 1 and 2 threads.
 *   figures     median, p99, max and mean per frame, sustained FPS,
 *               headroom against 16.67 ms (taken from the p99), per-stage
 *               medians, processing latency (camera frame in memory ->
 *               both outputs composited).
 *   peers       memcpy of the frame's output bytes (the memory floor);
 *               pixman compositing the same lit layer into the same
 *               viewport (the composite stage), with the byte difference.
 *               Mesa llvmpipe is bench/llvmpipe/llvmpipe_frame (it needs
 *               EGL/GLES); both write rows of bench/out/bench.csv.
 *   scaling     time per frame against the triangle count (bench_mesh.h
 *               arms, 2k..100k, skinned to one joint), the covered area
 *               and the output resolution (640x400 .. 2560x1600).
 *   HMDs        the typical sequence on the named HMDs (kin_sthmd_preset:
 *               paper, consumer 1280x1024 -> 2x 2064x2208, highend
 *               1920x1080 -> 2x 2880x2720), avx2 (1 and 2 threads) and
 *               the best ISA (2), against the memcpy of those outputs:
 *               rows frame_hmd / floor_hmd, frame_hmd.csv.
 *
 * Inputs are preloaded (a window of --window frames, camera frames turned
 * into YUYV once), so no file I/O is timed. Wall-clock times on a shared
 * machine: read ratios measured side by side, and medians.
 *
 *   bench_frame [--samples DIR] [--out DIR] [--frames N] [--ref-frames N]
 *               [--scale-frames N] [--window N] [--quick] [--no-scaling]
 *               [--no-hmds] [--hmds-only] [--hmd-frames N] [--hmd NAME]
 *               [--isa I] [--threads T]   (the grid: only that ISA / thread count)
 *               [--inplace]  (the grid composites in place, V copied into the
 *                             output untimed before each frame)
 *               [--hard-edges] (the binary mask's edges instead of the soft
 *                             silhouettes that render, run and demo draw)
 *               [--cpu-time] (frame and stage times in thread CPU time)
 *               [--lod N|auto] [--lod-px PX] (the sample model's levels of
 *                             detail, as egofuse render --lod: level N, or
 *                             the rule at PX pixels, default 2; its CSV rows
 *                             say egofuse_lodN or egofuse_lodauto@PXpx)
 *
 * Writes DIR/bench.csv (header + egofuse, memcpy and pixman rows),
 * DIR/frame_tris.csv, DIR/frame_cover.csv, DIR/frame_res.csv,
 * DIR/frame_hmd.csv. Reports,
 * never passes or fails (exit 1 only when the samples cannot be read). */
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../src/cpu/cpu.h"
#include "../src/io/io.h"
#include "../src/io/io_lod.h"
#include "../src/pipe/pipe.h"
#include "bench_mesh.h"
#include "bench_sample.h"
#include "bench_util.h"
#include "bench_worst.h"
#include "../src/cpu/ef_mem.h"

#if defined(__has_include)
#if __has_include(<pixman.h>)
#include <pixman.h>
#define HAVE_PIXMAN 1
#endif
#endif

#define BUDGET_MS (1000.0 / 60.0)
#define MAX_WINDOW 64
#define CSV_HEADER                                                                    \
    "case,impl,isa,threads,median_ms,p99_ms,max_ms,mean_ms,frames,fps,headroom_ms,"   \
    "coverage,convert_ms,track_ms,skin_ms,raster_ms,fuse_ms,tris,out_w,out_h,"          \
    "path_ms,outside_ms,raster_l_ms,raster_r_ms,fuse_l_ms,fuse_r_ms,convert_l_ms,"      \
    "convert_r_ms,handoff_ms,eye1_worker,inplace"

/* ------------------------------------------------------------- helpers */

static double now_ms(void) { return bench_now_ms(CLOCK_MONOTONIC); }

/* CPU time of the whole process (every thread), ms: on a shared machine
 * the work of a frame, without the time its threads waited for a core. */
static double cpu_ms(void) { return bench_now_ms(CLOCK_PROCESS_CPUTIME_ID); }

/* Summary of n samples (sorts v). */
typedef struct summary { double median, p99, max, mean; } summary;

static summary summarize(double *v, int n)
{
    summary s = {0, 0, 0, 0};
    if (n < 1) return s;
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    double sum = 0;
    for (int i = 0; i < n; i++) sum += v[i];
    s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    int k = (int)ceil(0.99 * n) - 1;
    s.p99 = v[k < 0 ? 0 : k];
    s.max = v[n - 1];
    s.mean = sum / n;
    return s;
}

static double median_of(double *v, int n) { return summarize(v, n).median; }

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "bench_frame: out of memory (%zu bytes)\n", n);
        exit(1);
    }
    return p;
}

/* A helper thread that runs one job at a time (the second eye's camera
 * conversion, the second half of a memcpy). */
typedef struct helper {
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    void (*fn)(void *);
    void *arg;
    int seq, done, quit;
} helper;

static void *helper_main(void *p)
{
    helper *h = p;
    int seen = 0;
    pthread_mutex_lock(&h->mu);
    for (;;) {
        while (h->seq == seen && !h->quit) pthread_cond_wait(&h->cv, &h->mu);
        if (h->quit) break;
        seen = h->seq;
        void (*fn)(void *) = h->fn;
        void *arg = h->arg;
        pthread_mutex_unlock(&h->mu);
        fn(arg);
        pthread_mutex_lock(&h->mu);
        h->done = seen;
        pthread_cond_broadcast(&h->cv);
    }
    pthread_mutex_unlock(&h->mu);
    return NULL;
}

static int helper_init(helper *h)
{
    memset(h, 0, sizeof *h);
    pthread_mutex_init(&h->mu, NULL);
    pthread_cond_init(&h->cv, NULL);
    return pthread_create(&h->th, NULL, helper_main, h) == 0;
}

static void helper_start(helper *h, void (*fn)(void *), void *arg)
{
    pthread_mutex_lock(&h->mu);
    h->fn = fn;
    h->arg = arg;
    h->seq++;
    pthread_cond_broadcast(&h->cv);
    pthread_mutex_unlock(&h->mu);
}

static void helper_wait(helper *h)
{
    pthread_mutex_lock(&h->mu);
    while (h->done != h->seq) pthread_cond_wait(&h->cv, &h->mu);
    pthread_mutex_unlock(&h->mu);
}

static void helper_stop(helper *h)
{
    pthread_mutex_lock(&h->mu);
    h->quit = 1;
    pthread_cond_broadcast(&h->cv);
    pthread_mutex_unlock(&h->mu);
    pthread_join(h->th, NULL);
    pthread_mutex_destroy(&h->mu);
    pthread_cond_destroy(&h->cv);
}

/* --------------------------------------------------------- camera YUYV */


/* ------------------------------------------------------------- the bench */

/* Virtual images of one output resolution: a window of frames. */
typedef struct imgset {
    int n, w, h;
    uint8_t *virt[MAX_WINDOW][2];
    float *depth[MAX_WINDOW][2];
    int opaque;               /* every image has alpha 255 everywhere:
                                 pipe_frame_in.virt_opaque is set */
} imgset;

/* 1 when every virtual image of the set is opaque (pipe_image_opaque
 * over the whole image, so over any viewport). */
static int imgset_opaque(const imgset *is)
{
    for (int f = 0; f < is->n; f++)
        for (int e = 0; e < 2; e++) {
            fuse_image im = {is->virt[f][e], is->w, is->h, 4 * is->w};
            if (!pipe_image_opaque(&im, 0, 0, is->w, is->h)) return 0;
        }
    return 1;
}

/* Where the pose of frame i comes from. */
typedef struct posesrc {
    const kin_track_sample *samples;  /* tracking, through filter + rig */
    int count;                        /* samples[i % count] */
    const kin_mat4 *head;             /* head override, or NULL: the rig's */
    int rest;                         /* 1: no tracking, the rest pose */
} posesrc;

/* Per-frame times of one measured case. */
typedef struct times {
    double *total, *convert, *track, *skin, *raster, *fuse, *cover, *cpu;
    /* the breakdown (issue 17 item 1), per frame: the stages on the
     * critical path (track + pose + the larger of the two threads' sums of
     * their eyes' stages), the rest of the frame's wall time, each eye's
     * stages, the worker's start after the hand-off, eye 1 on the worker */
    double *path, *outside, *eye[2][3], *handoff, *eye1w;
    double *busy[2];          /* per thread: its time in the eyes' work */
    int cap;
} times;

typedef struct result {
    summary total;
    double convert, track, skin, raster, fuse, coverage, fps;
    double cpu;               /* median process CPU time per frame, ms */
    double path, outside;     /* medians of the per-frame path and rest */
    double eye[2][3];         /* medians per eye: raster, convert, fuse */
    double busy[2];           /* medians per thread: the eyes' work */
    double handoff, eye1w;    /* median hand-off (frames with a worker eye),
                                 share of frames with eye 1 on the worker */
    int frames;
} result;

typedef struct bench {
    kin_model model;
    const kin_animation *anim;
    int head;                 /* head node */
    kin_arm_rig rig;
    kin_sthmd_desc hmd;
    kin_sthmd_geometry geo;
    pipe_lighting lighting;
    float fps;
    int seq_frames;
    kin_track_sample *samples;
    /* camera frames as the camera delivers them, and the RGBA buffers
     * the conversion fills (full 640x480: the pipe crops) */
    int window;
    uint8_t *yuyv[MAX_WINDOW][2];
    size_t yuyv_size;
    uint8_t *cam_rgba[2];
    /* the camera frames frame_step feeds (the base set above, or an HMD's
     * in run_hmds): cam_n frames of cam_w x cam_h YUYV */
    uint8_t *(*cam)[2];
    int cam_n, cam_w, cam_h;
    size_t cam_size;
    io_scene sc;              /* the sample scene */
    int inplace;              /* 1: V is copied into out before each frame
                                 (untimed) and composited in place there,
                                 as into a renderer's fresh buffer */
    int window_frame[MAX_WINDOW]; /* sequence frame of each window slot */
    imgset base;              /* 1280x800 */
    uint8_t *out[2];          /* sized for the largest resolution */
    size_t out_bytes;
    kin_transform *locals;
    kin_filter filt;
    long tick;                /* frames fed to the filter (its clock) */
    helper help;
    times tm;
    FILE *csv;
    const char *outdir;
    /* worst case */
    int worst_frame;
    bench_worst worst;        /* the head of the worst case (bench_worst.h) */
    result lat[2][2];         /* best ISA: [worst][threads - 1] */
} bench;

static fuse_image img_of(uint8_t *px, int w, int h) { return (fuse_image){px, w, h, 4 * w}; }

static kin_quat mat_rot(const kin_mat4 *m)
{
    kin_vec3 x = kin_v3_norm(kin_v3(m->m[0], m->m[1], m->m[2]));
    kin_vec3 y = kin_v3_norm(kin_v3(m->m[4], m->m[5], m->m[6]));
    kin_vec3 z = kin_v3_cross(x, y);
    y = kin_v3_cross(z, x);
    return kin_quat_from_axes(x, y, z);
}

/* The tracking sample a perfect tracker would give at sequence frame k:
 * head, shoulders, wrists from the animation's FK, gloves from the
 * fingers' middle-joint flexion. */
static void make_samples(bench *b)
{
    pipe_pose ps;
    if (pipe_pose_init(&ps, &b->model) != 0) exit(1);
    const kin_hand_params hp = kin_hand_params_default();
    b->samples = xmalloc(sizeof *b->samples * (size_t)b->seq_frames);
    for (int k = 0; k < b->seq_frames; k++) {
        pipe_pose_anim(&ps, b->anim, (float)k / b->fps);
        kin_track_sample *s = &b->samples[k];
        memset(s, 0, sizeof *s);
        s->t = k / (double)b->fps;
        s->valid = KIN_TRACK_ALL;
        s->head_pos = kin_mat4_translation(&ps.world[b->rig.head]);
        s->head_rot = mat_rot(&ps.world[b->rig.head]);
        for (int sd = 0; sd < 2; sd++) {
            s->shoulder[sd] = kin_mat4_translation(&ps.world[b->rig.joint[sd][KIN_RIG_UPPER_ARM]]);
            s->hand_pos[sd] = kin_mat4_translation(&ps.world[b->rig.joint[sd][KIN_RIG_HAND]]);
            s->hand_rot[sd] = mat_rot(&ps.world[b->rig.joint[sd][KIN_RIG_HAND]]);
            for (int f = 0; f < KIN_GLOVE_SENSORS; f++) {
                int node = b->rig.joint[sd][KIN_RIG_FINGER0 + 3 * f + 1];
                kin_quat q = ps.locals[node].r, r = b->model.rest[node].r;
                float d = fabsf(q.x * r.x + q.y * r.y + q.z * r.z + q.w * r.w);
                float a = 2.0f * acosf(d > 1.0f ? 1.0f : d) * 57.29578f;
                float g = (a - hp.open_deg[f][1]) / (hp.fist_deg[f][1] - hp.open_deg[f][1]);
                s->glove[sd][f] = g < 0 ? 0 : g > 1 ? 1 : g;
            }
        }
    }
    pipe_pose_free(&ps);
}

static int load_rgba(const char *path, int w, int h, io_image *img)
{
    return bench_load_image(path, IO_U8, 4, w, h, img, "bench_frame");
}

/* Scene, model, tracking samples and the window of frames. */
static int preload(bench *b, const char *samples_dir, int window)
{
    char path[IO_PATH_MAX + 64];
    io_scene sc;
    io_error err;
    snprintf(path, sizeof path, "%s/scene.txt", samples_dir);
    if (io_scene_load(path, &b->sc, &err) != IO_OK) memset(&b->sc, 0, sizeof b->sc);
    if (!bench_sample_posed(samples_dir, "bench_frame", 1, &sc, &b->model, &b->anim, &b->head))
        return 0;
    char why[256];
    if (!b->anim || b->head < 0 || kin_arm_rig_init(&b->rig, &b->model, why, sizeof why) != 0) {
        fprintf(stderr, "bench_frame: the sample model lacks the animation, head or rig\n");
        return 0;
    }
    bench_sample_play(&sc, &b->fps, &b->seq_frames, &b->hmd, &b->geo, &b->lighting.light);
    make_samples(b);

    const int cw = b->hmd.cam_width, ch = b->hmd.cam_height;
    const int lw = b->hmd.lcd_width, lh = b->hmd.lcd_height;
    if (window > sc.frames) window = sc.frames;
    b->window = window;
    b->yuyv_size = (size_t)cw * ch * 2;
    b->base.n = window;
    b->base.w = lw;
    b->base.h = lh;
    for (int f = 0; f < window; f++) {
        /* spread the window over the sequence */
        int fr = (int)((long)f * sc.frames / window);
        b->window_frame[f] = fr;
        for (int e = 0; e < 2; e++)
            if (!bench_sample_eye(&sc, fr, e, cw, ch, lw, lh, "bench_frame", &b->yuyv[f][e],
                                  &b->base.virt[f][e], &b->base.depth[f][e]))
                return 0;
    }
    b->base.opaque = imgset_opaque(&b->base);
    for (int e = 0; e < 2; e++) b->cam_rgba[e] = xmalloc((size_t)cw * ch * 4);
    b->cam = b->yuyv;
    b->cam_n = b->window;
    b->cam_w = cw;
    b->cam_h = ch;
    b->cam_size = b->yuyv_size;
    /* the outputs: the largest of the resolution scaling and the HMDs */
    b->out_bytes = (size_t)2560 * 1600 * 4;
    for (int k = 0; kin_sthmd_preset_name(k); k++) {
        kin_sthmd_desc hd;
        kin_sthmd_preset(kin_sthmd_preset_name(k), &hd);
        if ((size_t)hd.lcd_width * hd.lcd_height * 4 > b->out_bytes)
            b->out_bytes = (size_t)hd.lcd_width * hd.lcd_height * 4;
    }
    for (int e = 0; e < 2; e++) {
        b->out[e] = xmalloc(b->out_bytes);
        memset(b->out[e], 0, b->out_bytes);
    }
    b->locals = xmalloc(sizeof *b->locals * (size_t)b->model.node_count);
    kin_filter_init(&b->filt, NULL);
    return 1;
}

static void times_init(times *t, int cap)
{
    t->cap = cap;
    t->total = xmalloc(sizeof(double) * cap);
    t->convert = xmalloc(sizeof(double) * cap);
    t->track = xmalloc(sizeof(double) * cap);
    t->skin = xmalloc(sizeof(double) * cap);
    t->raster = xmalloc(sizeof(double) * cap);
    t->fuse = xmalloc(sizeof(double) * cap);
    t->cover = xmalloc(sizeof(double) * cap);
    t->cpu = xmalloc(sizeof(double) * cap);
    t->path = xmalloc(sizeof(double) * cap);
    t->outside = xmalloc(sizeof(double) * cap);
    for (int e = 0; e < 2; e++)
        for (int k = 0; k < 3; k++) t->eye[e][k] = xmalloc(sizeof(double) * cap);
    t->handoff = xmalloc(sizeof(double) * cap);
    t->eye1w = xmalloc(sizeof(double) * cap);
    t->busy[0] = xmalloc(sizeof(double) * cap);
    t->busy[1] = xmalloc(sizeof(double) * cap);
}

/* --cpu-time: the frame's times (and pipe_frame_stats', pipe_set_stats_clock)
 * are the CPU time of the thread that runs each part, not wall time */
static int frame_cpu_clock = 0;

static double frame_ms(void)
{
    return bench_now_ms(frame_cpu_clock ? CLOCK_THREAD_CPUTIME_ID : CLOCK_MONOTONIC);
}

/* One whole stereo frame i: convert, track, pipe_frame. Fills slot k of
 * the times (k < 0: not recorded). Returns 0 on a pipe error. */
static int frame_step(bench *b, pipe_ctx *p, const imgset *is, const posesrc *src, long i,
                      int k)
{
    const int w = (int)(i % is->n);
    const int cw = b->cam_w, ch = b->cam_h;
    if (b->inplace)
        for (int e = 0; e < 2; e++) memcpy(b->out[e], is->virt[w][e], (size_t)is->w * is->h * 4);
    double c0 = cpu_ms();
    double t0 = frame_ms();
    double t1 = frame_ms();
    pipe_frame_in in = {0};
    if (!src->rest) {
        kin_track_sample s = src->samples[i % src->count], o;
        s.t = (double)(b->tick++) / b->fps;   /* the filter's clock runs on */
        kin_filter_push(&b->filt, &s);
        kin_filter_output(&b->filt, s.t + 1.0 / b->fps, &o, NULL); /* display time */
        kin_pose_rest(&b->model, b->locals);
        kin_arm_rig_pose(&b->rig, &b->model, NULL, NULL, &o, b->locals, NULL);
        in.locals = b->locals;
    }
    double t2 = frame_ms();
    in.head_node = src->head || src->rest ? -1 : b->rig.head;
    in.world_from_head = src->head;
    for (int e = 0; e < 2; e++) {
        /* As the camera delivers it: each eye's thread converts its crop. */
        in.camera_raw[e] = (fuse_frame){b->cam[w % b->cam_n][e], b->cam_size, cw, ch,
                                        2 * cw, FUSE_FMT_YUYV};
        in.virt[e] = img_of(b->inplace ? b->out[e] : is->virt[w][e], is->w, is->h);
        in.out[e] = img_of(b->out[e], is->w, is->h);
        in.virt_depth[e] = is->depth[w][e];
        in.virt_depth_stride[e] = is->w;
    }
    in.virt_opaque = is->opaque;
    in.lighting = b->lighting;
    pipe_frame_stats st;
    char why[256];
    pipe_result r = pipe_frame(p, &in, &st, why, sizeof why);
    double t3 = frame_ms();
    double c3 = cpu_ms();
    if (r != PIPE_OK) {
        fprintf(stderr, "bench_frame: frame %ld: %s\n", i, why);
        return 0;
    }
    if (k >= 0 && k < b->tm.cap) {
        b->tm.total[k] = t3 - t0;
        b->tm.convert[k] = st.ms_convert[0] + st.ms_convert[1];
        b->tm.track[k] = t2 - t1;
        b->tm.skin[k] = st.ms_pose;
        b->tm.raster[k] = st.ms_raster[0] + st.ms_raster[1];
        b->tm.fuse[k] = st.ms_fuse[0] + st.ms_fuse[1];
        b->tm.cover[k] = 0.5 * (st.coverage[0] + st.coverage[1]);
        b->tm.cpu[k] = c3 - c0;
        /* the critical path: per thread its time in the eyes' work (each
         * eye's raster, then bands of either eye's fuse: pipe.c eye_work) */
        double thr[2] = {st.ms_busy[0], st.ms_busy[1]}, hand = -1;
        for (int e = 0; e < 2; e++) {
            b->tm.eye[e][0][k] = st.ms_raster[e];
            b->tm.eye[e][1][k] = st.ms_convert[e];
            b->tm.eye[e][2][k] = st.ms_fuse[e];
            b->tm.busy[e][k] = st.ms_busy[e];
            if (st.eye_thread[e]) hand = st.ms_eye_start[e];
        }
        /* (--cpu-time: the frame's time is the caller's thread's CPU time,
         * so its path is that thread's own stages; no hand-off) */
        if (frame_cpu_clock) thr[1] = 0, hand = -1;
        b->tm.path[k] = (t2 - t1) + st.ms_pose + (thr[0] > thr[1] ? thr[0] : thr[1]);
        b->tm.outside[k] = (t3 - t0) - b->tm.path[k];
        b->tm.handoff[k] = hand;
        b->tm.eye1w[k] = st.eye_thread[1] ? 1.0 : 0.0;
    }
    return 1;
}

/* Warm-up frames, then n measured frames on p, or fewer when max_s
 * seconds have passed (but at least min(n, 100)): the time box keeps
 * `make bench` to a few minutes on a loaded machine. */
static int measure(bench *b, pipe_ctx *p, const imgset *is, const posesrc *src, int n,
                   double max_s, result *r)
{
    if (n > b->tm.cap) n = b->tm.cap;
    kin_filter_init(&b->filt, NULL);   /* every case starts from its first sample */
    long i0 = b->tick;
    for (int k = -8; k < 0; k++)
        if (!frame_step(b, p, is, src, i0 + 8 + k, -1)) return 0;
    double t0 = now_ms();
    const int n_min = n < 100 ? n : 100;
    for (int k = 0; k < n; k++) {
        if (!frame_step(b, p, is, src, i0 + 8 + k, k)) return 0;
        if (k + 1 >= n_min && now_ms() - t0 > 1e3 * max_s) {
            n = k + 1;
            break;
        }
    }
    double wall = now_ms() - t0;
    r->frames = n;
    r->fps = 1e3 * n / wall;
    r->convert = median_of(b->tm.convert, n);
    r->track = median_of(b->tm.track, n);
    r->skin = median_of(b->tm.skin, n);
    r->raster = median_of(b->tm.raster, n);
    r->fuse = median_of(b->tm.fuse, n);
    r->cpu = median_of(b->tm.cpu, n);
    r->path = median_of(b->tm.path, n);
    r->outside = median_of(b->tm.outside, n);
    for (int e = 0; e < 2; e++)
        for (int q = 0; q < 3; q++) r->eye[e][q] = median_of(b->tm.eye[e][q], n);
    for (int t = 0; t < 2; t++) r->busy[t] = median_of(b->tm.busy[t], n);
    {   /* the hand-off over the frames where the worker ran an eye */
        int m = 0;
        double w = 0;
        for (int k = 0; k < n; k++) {
            w += b->tm.eye1w[k];
            if (b->tm.handoff[k] >= 0) b->tm.handoff[m++] = b->tm.handoff[k];
        }
        r->handoff = m ? median_of(b->tm.handoff, m) : 0;
        r->eye1w = w / n;
    }
    double cs = 0;
    for (int k = 0; k < n; k++) cs += b->tm.cover[k];
    r->coverage = cs / n;
    r->total = summarize(b->tm.total, n);
    return 1;
}

static void csv_row(bench *b, const char *cs, const char *impl, const char *isa, int threads,
                    const result *r, int tris, int ow, int oh)
{
    if (!b->csv) return;
    fprintf(b->csv,
            "%s,%s,%s,%d,%.4f,%.4f,%.4f,%.4f,%d,%.1f,%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d,%d,%d,"
            "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%d\n",
            cs, impl, isa, threads, r->total.median, r->total.p99, r->total.max, r->total.mean,
            r->frames, r->fps, BUDGET_MS - r->total.p99, r->coverage, r->convert, r->track,
            r->skin, r->raster, r->fuse, tris, ow, oh, r->path, r->outside, r->eye[0][0],
            r->eye[1][0], r->eye[0][2], r->eye[1][2], r->eye[0][1], r->eye[1][1], r->handoff,
            r->eye1w, b->inplace);
    fflush(b->csv);
}

/* --hard-edges: the pipes draw the binary mask's stair-stepped edges
 * (pipe_desc.soft_edge 0) instead of the default soft silhouettes */
static int grid_hard_edges = 0;

/* --lod N|auto, --lod-px PX: the pipes of the sample model draw its levels
 * of detail as `egofuse render --lod` does (pipe_set_lod; the chain built
 * once at load by io_lod_build); 0: the full model (the default path). */
static int grid_lod = 0;
static float grid_lod_px = 2.0f;
static pipe_lod grid_lod_chain;
/* the impl column of the sample model's rows: "egofuse", or with --lod
 * "egofuse_lodN" / "egofuse_lodauto@PXpx", so that no chart or summary
 * takes them for the default path */
static char grid_impl[48] = "egofuse";

static pipe_ctx *make_pipe(bench *b, const kin_model *m, ef_isa isa, int threads,
                           const kin_sthmd_desc *hmd)
{
    pipe_desc d = {0};
    if (hmd) d.hmd = *hmd;
    d.threads = threads;
    d.max_isa = (int)isa;
    /* The sample arms are closed and consistently wound: culling back
     * faces gives the same masks (checked over the whole sequence) for
     * about half the triangle setups, as `egofuse demo` runs it. */
    d.cull = RAST_CULL_BACK;
    /* The default path of `render`, `run` and `demo`: soft silhouettes
     * (one pass over the mask, counted in the fuse stage); --hard-edges
     * measures the binary mask's frame. */
    d.soft_edge = !grid_hard_edges;
    pipe_ctx *p = pipe_create(&d, m);
    if (p && grid_lod && m == &b->model &&
        pipe_set_lod(p, &grid_lod_chain, grid_lod, grid_lod_px) != 0) {
        fprintf(stderr, "bench_frame: the levels of detail do not fit the sample model\n");
        pipe_destroy(p);
        return NULL;
    }
    return p;
}

/* -------------------------------------------------------- worst case */

typedef struct worst_ctx {
    bench *b;
    pipe_ctx *p;
    posesrc src;
} worst_ctx;

/* The coverage of one frame of the worst case's pose with head h. */
static double worst_cover(void *ctx, const kin_mat4 *h)
{
    worst_ctx *w = ctx;
    posesrc src = w->src;
    src.head = h;
    kin_filter_init(&w->b->filt, NULL);   /* the pose at once, no filter lag */
    if (!frame_step(w->b, w->p, &w->b->base, &src, w->b->tick, 0)) return 0;
    return w->b->tm.cover[0];
}

/* The worst case (bench_worst.h): the pose of the grasp (1.5 s), the head
 * moved towards a palm or between them until about 70% is covered. */
static void find_worst(bench *b, pipe_ctx *p)
{
    b->worst_frame = (int)(1.5f * b->fps) < b->seq_frames ? (int)(1.5f * b->fps) : 0;
    if (bench_worst_init(&b->worst, &b->model, &b->rig, b->anim,
                         (float)b->worst_frame / b->fps) != 0)
        exit(1);
    worst_ctx w = {b, p, {&b->samples[b->worst_frame], 1, NULL, 0}};
    bench_worst_find(&b->worst, worst_cover, &w);
}

/* ---------------------------------------------------------- the grid */

static void print_head(void)
{
    printf("  %-8s %-7s %3s %7s %7s %7s %7s %6s %8s %6s | %7s %7s %7s %7s %7s %6s\n", "case",
           "isa", "thr", "median", "p99", "max", "mean", "fps", "headroom", "cover", "convert",
           "track", "skin", "raster", "fuse", "frames");
}

static void print_row(const char *cs, const char *isa, int thr, const result *r)
{
    printf("  %-8s %-7s %3d %7.3f %7.3f %7.3f %7.3f %6.0f %8.2f %5.1f%% | %7.3f %7.3f %7.3f "
           "%7.3f %7.3f %6d\n",
           cs, isa, thr, r->total.median, r->total.p99, r->total.max, r->total.mean, r->fps,
           BUDGET_MS - r->total.p99, 100 * r->coverage, r->convert, r->track, r->skin, r->raster,
           r->fuse, r->frames);
}

/* Where the frame's time goes (issue 17 item 1), one line under the row. */
static void print_breakdown(const result *r, int threads)
{
    printf("  %-8s per eye L/R: raster %.3f/%.3f convert %.3f/%.3f fuse %.3f/%.3f; stages on "
           "the path %.3f, outside them %.3f (%.1f%% of the path)",
           "", r->eye[0][0], r->eye[1][0], r->eye[0][1], r->eye[1][1], r->eye[0][2], r->eye[1][2],
           r->path, r->outside, r->path > 0 ? 100.0 * r->outside / r->path : 0.0);
    if (threads > 1 && frame_cpu_clock)
        printf("; eye 1 on the worker in %.0f%% of the frames (path: the caller's thread)",
               100.0 * r->eye1w);
    else if (threads > 1)
        printf("; eye 1 on the worker in %.0f%% of the frames, its start %.3f ms after the "
               "hand-off", 100.0 * r->eye1w, r->handoff);
    if (threads > 1)   /* (--cpu-time: each thread's own CPU time) */
        printf("; busy per thread (caller/worker) %.3f/%.3f", r->busy[0], r->busy[1]);
    printf("\n");
}

typedef struct budget {
    int frames_best, frames, ref_frames, scale_frames;   /* caps */
    double s_best, s_other, s_ref, s_scale;               /* time boxes */
} budget;

/* --isa / --threads: only that ISA / thread count in the grid (0: all) */
static ef_isa grid_isa = EF_ISA_DEFAULT;
static int grid_threads = 0;
/* --inplace: the grid composites in place (V copied into out before each
 * frame, untimed: the renderer's fresh buffer) */
static int grid_inplace = 0;

static void run_grid(bench *b, const budget *bu)
{
    const ef_isa best = ef_isa_choose(EF_ISA_DEFAULT);
    static const ef_isa isas[] = {EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512};
    posesrc typical = {b->samples, b->seq_frames, NULL, 0};
    posesrc worst = {&b->samples[b->worst_frame], 1, &b->worst.head, 0};
    printf("\nWhole stereo frame (ms; stage columns are medians, raster and fuse summed over\n"
           "both eyes, which run in parallel with 2 threads; raster = context clear + vertex\n"
           "transforms + draw with normals, back faces culled, as bench_raster's \"pipe\" rows;\n"
           "fuse includes the %s; headroom = 16.67 - p99):\n",
           grid_hard_edges ? "binary mask's hard edges (--hard-edges)"
                           : "soft silhouettes (render's and run's default)");
    if (grid_inplace)
        printf("(in place: V copied into the output before each frame, untimed, as a renderer's "
               "fresh buffer)\n");
    print_head();
    b->inplace = grid_inplace;
    for (int c = 0; c < 2; c++) {
        for (int i = 0; i < 4; i++) {
            if (grid_isa != EF_ISA_DEFAULT && grid_isa != isas[i]) continue;
            if (!ef_cpu_has(isas[i]) || ef_isa_choose(isas[i]) != isas[i]) {
                printf("  %-8s %-7s SKIPPED: %s\n", c ? "worst" : "typical", ef_isa_name(isas[i]),
                       ef_cpu_has(isas[i]) ? "capped by EGOFUSE_ISA" : "the CPU lacks it");
                continue;
            }
            for (int t = 1; t <= 2; t++) {
                if (grid_threads && t != grid_threads) continue;
                pipe_ctx *p = make_pipe(b, &b->model, isas[i], t, NULL);
                if (!p || pipe_isa(p) != (int)isas[i]) {
                    printf("  %-8s %-7s SKIPPED: the pipe runs %s\n", c ? "worst" : "typical",
                           ef_isa_name(isas[i]), p ? ef_isa_name((ef_isa)pipe_isa(p)) : "nothing");
                    pipe_destroy(p);
                    continue;
                }
                result r;
                int n = isas[i] == EF_ISA_REF ? bu->ref_frames
                        : isas[i] == best     ? bu->frames_best
                                              : bu->frames;
                double s = isas[i] == EF_ISA_REF ? bu->s_ref
                           : isas[i] == best     ? bu->s_best
                                                 : bu->s_other;
                if (measure(b, p, &b->base, c ? &worst : &typical, n, s, &r)) {
                    print_row(c ? "worst" : "typical", ef_isa_name(isas[i]), t, &r);
                    print_breakdown(&r, t);
                    if (isas[i] == best) b->lat[c][t - 1] = r;
                    csv_row(b, c ? "frame_worst" : "frame_typical", grid_impl, ef_isa_name(isas[i]),
                            t, &r, -1, b->hmd.lcd_width, b->hmd.lcd_height);
                }
                pipe_destroy(p);
            }
        }
    }
    b->inplace = 0;
}

/* ----------------------------------------------- memcpy and pixman */

typedef struct copy_job { uint8_t *dst; const uint8_t *src; size_t n; } copy_job;
static void copy_run(void *p)
{
    copy_job *j = p;
    memcpy(j->dst, j->src, j->n);
}

static void result_from(result *r, double *v, int n, double wall)
{
    memset(r, 0, sizeof *r);
    r->frames = n;
    r->fps = 1e3 * n / wall;
    r->total = summarize(v, n);
}

/* memcpy of both outputs of is from its virtual images, t threads (one
 * eye each with 2), n times after 5 warm-ups. */
static void memcpy_floor(bench *b, const imgset *is, int t, int n, result *r)
{
    const size_t bytes = (size_t)is->w * is->h * 4;
    double *v = xmalloc(sizeof(double) * n);
    double w0 = 0;
    for (int k = -5; k < n; k++) {
        int f = (k + 5) % is->n;
        if (k == 0) w0 = now_ms();
        double t0 = now_ms();
        copy_job j[2] = {{b->out[0], is->virt[f][0], bytes}, {b->out[1], is->virt[f][1], bytes}};
        if (t == 2) {
            helper_start(&b->help, copy_run, &j[1]);
            copy_run(&j[0]);
            helper_wait(&b->help);
        } else {
            copy_run(&j[0]);
            copy_run(&j[1]);
        }
        if (k >= 0) v[k] = now_ms() - t0;
    }
    result_from(r, v, n, now_ms() - w0);
    free(v);
}

/* The memory floor: both 1280x800 outputs written from the virtual
 * images (8.2 MB read, 8.2 MB written), 1 thread and 2 (one eye each). */
static void run_memcpy(bench *b, int n)
{
    const size_t bytes = (size_t)b->base.w * b->base.h * 4;
    printf("\nmemcpy floor (both %dx%d outputs from the virtual images, 2 x %.1f MB):\n",
           b->base.w, b->base.h, bytes / 1e6);
    for (int t = 1; t <= 2; t++) {
        result r;
        memcpy_floor(b, &b->base, t, n, &r);
        printf("  %d thread%s: median %.3f ms, p99 %.3f ms (%.1f GB/s copied)\n", t,
               t > 1 ? "s" : " ", r.total.median, r.total.p99, 2 * bytes / r.total.median / 1e6);
        csv_row(b, "memcpy_floor", "memcpy", "-", t, &r, -1, b->base.w, b->base.h);
    }
}

/* The composite stage alone, egofuse (each ISA, 1 thread; the best, 2)
 * against pixman (OVER, premultiplied a8b8g8r8 source = the same byte
 * order as egofuse's RGBA, bilinear, pad repeat) on the same lit layers
 * of one typical frame, in place over copies of the virtual images. */
static void run_composite(bench *b, int n)
{
    const int cw = b->geo.crop_width, ch = b->geo.crop_height, lw = b->base.w, lh = b->base.h;
    const int vx = b->geo.vp_x0, vy = b->geo.vp_y0, vw = b->geo.vp_width, vh = b->geo.vp_height;
    /* the lit layers Q of frame 0 of the window, eyes 0 and 1 */
    pipe_pose ps;
    if (pipe_pose_init(&ps, &b->model) != 0) exit(1);
    kin_pose_rest(&b->model, b->locals);
    kin_arm_rig_pose(&b->rig, &b->model, NULL, NULL, &b->samples[b->worst_frame], b->locals, NULL);
    pipe_pose_locals(&ps, b->locals);
    float *depth = xmalloc(sizeof(float) * cw * ch), *nrm = xmalloc(sizeof(float) * 3 * cw * ch);
    float *clip = xmalloc(sizeof(float) * 4 * ps.max_vertices);
    float *vn = xmalloc(sizeof(float) * 3 * ps.max_vertices);
    uint8_t *mask = xmalloc((size_t)cw * ch), *Q[2], *R[2];
    fuse_context_desc fd = {EF_ISA_DEFAULT, 1};
    fuse_context *fc = fuse_context_create(&fd);
    double cover = 0;
    for (int e = 0; e < 2; e++) {
        Q[e] = xmalloc((size_t)cw * ch * 4);
        R[e] = xmalloc((size_t)lw * lh * 4);
        kin_camera cam = kin_sthmd_camera(&b->hmd, &ps.world[b->head], (kin_eye)e);
        rast_target tg = {cw, ch, depth, cw, mask, cw, nrm, 3 * cw, 3, NULL, 0};
        rast_target_clear(&tg);
        pipe_pose_draw(&ps, NULL, &cam, &tg, RAST_CULL_NONE, clip, vn, NULL);
        long on = 0;
        for (int i = 0; i < cw * ch; i++) on += mask[i] != 0;
        cover += 0.5 * on / (double)(cw * ch);
        fuse_intrinsics K = {cam.fx, cam.fy, cam.cx, cam.cy};
        fuse_image full = img_of(b->cam_rgba[e], b->hmd.cam_width, b->hmd.cam_height);
        fuse_image P = fuse_image_rows(&full, b->geo.crop_y0, ch), Qi = img_of(Q[e], cw, ch);
        fuse_lighting L = b->lighting.light;  /* directions as given: timing only */
        fuse_context_light(fc, &L, &K, &P, mask, cw, nrm, 3 * cw, &Qi);
    }
    fuse_context_destroy(fc);
    printf("\nComposite stage alone (resample the lit 640x400 layer into %dx%d at (%d,%d), over "
           "V, both eyes, in place; %.0f%% of the camera pixels lit):\n",
           vw, vh, vx, vy, 100 * cover);
    double *v = xmalloc(sizeof(double) * n);
    static const ef_isa isas[] = {EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512};
    ef_isa best = ef_isa_choose(EF_ISA_DEFAULT);
    double eg_best = 0;
    for (int i = 0; i < 4; i++)
        for (int t = 1; t <= 2; t++) {
            if (!ef_cpu_has(isas[i]) || ef_isa_choose(isas[i]) != isas[i]) continue;
            if (t == 2 && isas[i] != best) continue;
            fuse_context_desc d = {isas[i], t};
            fuse_context *c = fuse_context_create(&d);
            if (!c) continue;
            double w0 = 0;
            int nn = isas[i] == EF_ISA_REF ? (n < 50 ? n : 50) : n;
            for (int k = -3; k < nn; k++) {
                if (k == 0) w0 = now_ms();
                double t0 = now_ms();
                for (int e = 0; e < 2; e++) {
                    fuse_image Qi = img_of(Q[e], cw, ch), Vi = img_of(b->out[e], lw, lh);
                    fuse_context_composite(c, &Qi, &Vi, vx, vy, vw, vh, &Vi);
                }
                if (k >= 0) v[k] = now_ms() - t0;
            }
            result r;
            result_from(&r, v, nn, now_ms() - w0);
            r.coverage = cover;
            if (isas[i] == best && t == 1) eg_best = r.total.median;
            printf("  egofuse %-7s %d thread%s: median %.3f ms, p99 %.3f ms\n", ef_isa_name(isas[i]),
                   t, t > 1 ? "s" : " ", r.total.median, r.total.p99);
            csv_row(b, "composite", "egofuse", ef_isa_name(isas[i]), t, &r, -1, lw, lh);
            fuse_context_destroy(c);
        }
    /* egofuse's bytes, for the comparison */
    for (int e = 0; e < 2; e++) {
        fuse_image Qi = img_of(Q[e], cw, ch), Vi = img_of(b->base.virt[0][e], lw, lh),
                   Ri = img_of(R[e], lw, lh);
        fuse_composite(&Qi, &Vi, vx, vy, vw, vh, &Ri);
    }
#ifdef HAVE_PIXMAN
    pixman_image_t *src[2], *dst[2];
    pixman_transform_t tr;
    pixman_transform_init_scale(&tr, pixman_double_to_fixed((double)cw / vw),
                                pixman_double_to_fixed((double)ch / vh));
    for (int e = 0; e < 2; e++) {
        src[e] = pixman_image_create_bits(PIXMAN_a8b8g8r8, cw, ch, (uint32_t *)(void *)Q[e], 4 * cw);
        dst[e] = pixman_image_create_bits(PIXMAN_a8b8g8r8, lw, lh, (uint32_t *)(void *)b->out[e],
                                          4 * lw);
        pixman_image_set_transform(src[e], &tr);
        pixman_image_set_filter(src[e], PIXMAN_FILTER_BILINEAR, NULL, 0);
        pixman_image_set_repeat(src[e], PIXMAN_REPEAT_PAD);
    }
    double w0 = 0;
    for (int k = -3; k < n; k++) {
        if (k == 0) w0 = now_ms();
        double t0 = now_ms();
        for (int e = 0; e < 2; e++)
            pixman_image_composite32(PIXMAN_OP_OVER, src[e], NULL, dst[e], 0, 0, 0, 0, vx, vy, vw,
                                     vh);
        if (k >= 0) v[k] = now_ms() - t0;
    }
    result r;
    result_from(&r, v, n, now_ms() - w0);
    r.coverage = cover;
    csv_row(b, "composite", "pixman", "-", 1, &r, -1, lw, lh);
    /* the same composite by pixman onto a fresh copy of V, against egofuse */
    double sum = 0;
    int maxd = 0;
    long big = 0, cnt = 0;
    for (int e = 0; e < 2; e++) {
        memcpy(b->out[e], b->base.virt[0][e], (size_t)lw * lh * 4);
        pixman_image_composite32(PIXMAN_OP_OVER, src[e], NULL, dst[e], 0, 0, 0, 0, vx, vy, vw, vh);
        for (int y = vy; y < vy + vh; y++)
            for (int x = vx; x < vx + vw; x++) {
                int px_d = 0;
                for (int k = 0; k < 3; k++) {
                    size_t o = ((size_t)y * lw + x) * 4 + k;
                    int d = abs((int)b->out[e][o] - (int)R[e][o]);
                    sum += d;
                    if (d > maxd) maxd = d;
                    if (d > px_d) px_d = d;
                }
                big += px_d > 8;
                cnt++;
            }
        pixman_image_unref(src[e]);
        pixman_image_unref(dst[e]);
    }
    printf("  pixman %s 1 thread : median %.3f ms, p99 %.3f ms; pixman / egofuse %s 1 thread = "
           "%.2fx\n  pixman's bytes against egofuse's in the viewport: mean |d| %.3f, max %d, "
           "%.3f%% of pixels differ by > 8\n",
           pixman_version_string(), r.total.median, r.total.p99, ef_isa_name(best),
           eg_best > 0 ? r.total.median / eg_best : 0, sum / (3.0 * cnt), maxd, 100.0 * big / cnt);
#else
    (void)eg_best;
    printf("  pixman: not built in (no pixman.h)\n");
#endif
    for (int e = 0; e < 2; e++) {
        free(Q[e]);
        free(R[e]);
    }
    EF_FREE_ALL(v, depth, nrm, clip, vn, mask);
    pipe_pose_free(&ps);
}

/* ------------------------------------------------------------ scaling */

static FILE *open_csv(const bench *b, const char *name, const char *header)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", b->outdir, name);
    FILE *f = fopen(path, "w");
    if (f) fprintf(f, "%s\n", header);
    return f;
}

/* The bench_mesh.h arms as a kin_model: one joint (the rest pose), every
 * vertex weighted to it, so the frame still skins every vertex. */
typedef struct mesh_model {
    kin_model m;
    bm_mesh bm;
    int16_t parent;
    kin_transform rest;
    char name[1][KIN_NAME_MAX];
    int src, joint;
    kin_mat4 ibind;
    kin_skin skin;
    kin_mesh mesh;
    uint16_t *joints;
    float *weights;
} mesh_model;

static int mesh_model_make(mesh_model *mm, int tris)
{
    memset(mm, 0, sizeof *mm);
    if (!bm_arms(&mm->bm, tris)) return 0;
    const int nv = mm->bm.vertex_count;
    mm->joints = xmalloc(sizeof(uint16_t) * 4 * nv);
    mm->weights = xmalloc(sizeof(float) * 4 * nv);
    for (int v = 0; v < nv; v++) {
        mm->joints[4 * v] = mm->joints[4 * v + 1] = mm->joints[4 * v + 2] = mm->joints[4 * v + 3] = 0;
        mm->weights[4 * v] = 1.0f;
        mm->weights[4 * v + 1] = mm->weights[4 * v + 2] = mm->weights[4 * v + 3] = 0.0f;
    }
    mm->parent = KIN_NO_PARENT;
    mm->rest = kin_transform_identity();
    snprintf(mm->name[0], KIN_NAME_MAX, "arms");
    mm->ibind = kin_mat4_identity();
    mm->skin = (kin_skin){1, &mm->joint, &mm->ibind};
    mm->mesh = (kin_mesh){nv, mm->bm.pos, mm->bm.nrm, mm->joints, mm->weights,
                          3 * mm->bm.tri_count, mm->bm.idx, 0, 0, .target_count = 0};
    mm->m.node_count = 1;
    mm->m.parents = &mm->parent;
    mm->m.rest = &mm->rest;
    mm->m.names = (const char(*)[KIN_NAME_MAX])mm->name;
    mm->m.node_src = &mm->src;
    mm->m.mesh_count = 1;
    mm->m.meshes = &mm->mesh;
    mm->m.skin_count = 1;
    mm->m.skins = &mm->skin;
    char why[256];
    if (kin_model_validate(&mm->m, why, sizeof why) != 0) {
        fprintf(stderr, "bench_frame: mesh model: %s\n", why);
        return 0;
    }
    return 1;
}

static void mesh_model_free(mesh_model *mm)
{
    bm_free(&mm->bm);
    free(mm->joints);
    free(mm->weights);
}

static void scale_tris(bench *b, int n, double max_s, ef_isa isa)
{
    static const int counts[] = {2000, 5000, 10000, 20000, 50000, 100000};
    FILE *f = open_csv(b, "frame_tris.csv", "tris,coverage,median_1t_ms,p99_1t_ms,median_2t_ms,p99_2t_ms");
    printf("\nScaling with the triangle count (bench_mesh.h arms skinned to one joint, head at the "
           "origin; %s, medians of up to %d frames):\n  %8s %10s %10s %7s\n",
           ef_isa_name(isa), n, "tris", "1 thread", "2 threads", "cover");
    posesrc rest = {NULL, 1, NULL, 1};
    kin_mat4 id = kin_mat4_identity();
    rest.head = &id;
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
        mesh_model mm;
        if (!mesh_model_make(&mm, counts[i])) continue;
        double med[2] = {0, 0}, p99[2] = {0, 0}, cov = 0;
        for (int t = 1; t <= 2; t++) {
            pipe_ctx *p = make_pipe(b, &mm.m, isa, t, NULL);
            result r;
            if (p && measure(b, p, &b->base, &rest, n, max_s, &r)) {
                med[t - 1] = r.total.median;
                cov = r.coverage;
                csv_row(b, "scale_tris", "egofuse", ef_isa_name(isa), t, &r, mm.bm.tri_count,
                        b->base.w, b->base.h);
                p99[t - 1] = r.total.p99;
            }
            pipe_destroy(p);
        }
        if (f) fprintf(f, "%d,%.4f,%.4f,%.4f,%.4f,%.4f\n", mm.bm.tri_count, cov, med[0], p99[0],
                       med[1], p99[1]);
        printf("  %8d %10.3f %10.3f %6.1f%%\n", mm.bm.tri_count, med[0], med[1], 100 * cov);
        mesh_model_free(&mm);
    }
    if (f) fclose(f);
}

static void scale_cover(bench *b, int n, double max_s, ef_isa isa)
{
    FILE *f = open_csv(b, "frame_cover.csv",
                       "coverage,head_dist_m,median_1t_ms,p99_1t_ms,median_2t_ms,p99_2t_ms");
    double d0 = bench_worst_d0(&b->worst);
    printf("\nScaling with the covered area (pose of frame %d, the head moved towards the hands; "
           "%s, medians of up to %d frames):\n  %7s %8s %10s %10s\n",
           b->worst_frame, ef_isa_name(isa), n, "cover", "dist m", "1 thread", "2 threads");
    for (int s = 0; s < 7; s++) {
        double d = d0 + (b->worst.d * 0.85 - d0) * s / 6.0;
        kin_mat4 h = bench_worst_head_at(&b->worst, b->worst.target, d);
        posesrc src = {&b->samples[b->worst_frame], 1, &h, 0};
        double med[2] = {0, 0}, p99[2] = {0, 0}, cov = 0;
        for (int t = 1; t <= 2; t++) {
            pipe_ctx *p = make_pipe(b, &b->model, isa, t, NULL);
            result r;
            if (p && measure(b, p, &b->base, &src, n, max_s, &r)) {
                med[t - 1] = r.total.median;
                cov = r.coverage;
                csv_row(b, "scale_cover", "egofuse", ef_isa_name(isa), t, &r, -1, b->base.w,
                        b->base.h);
                p99[t - 1] = r.total.p99;
            }
            pipe_destroy(p);
        }
        if (f) fprintf(f, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", cov, d, med[0], p99[0], med[1], p99[1]);
        printf("  %6.1f%% %8.3f %10.3f %10.3f\n", 100 * cov, d, med[0], med[1]);
    }
    if (f) fclose(f);
}

/* Nearest-neighbour resize of the window's first frames. */
static void imgset_resized(const bench *b, imgset *o, int w, int h, int frames)
{
    o->n = frames < b->base.n ? frames : b->base.n;
    o->w = w;
    o->h = h;
    for (int f = 0; f < o->n; f++)
        for (int e = 0; e < 2; e++) {
            o->virt[f][e] = xmalloc((size_t)w * h * 4);
            o->depth[f][e] = b->base.depth[f][e] ? xmalloc(sizeof(float) * w * h) : NULL;
            for (int y = 0; y < h; y++) {
                int sy = (int)((long)y * b->base.h / h);
                for (int x = 0; x < w; x++) {
                    int sx = (int)((long)x * b->base.w / w);
                    memcpy(o->virt[f][e] + ((size_t)y * w + x) * 4,
                           b->base.virt[f][e] + ((size_t)sy * b->base.w + sx) * 4, 4);
                    if (o->depth[f][e])
                        o->depth[f][e][(size_t)y * w + x] =
                            b->base.depth[f][e][(size_t)sy * b->base.w + sx];
                }
            }
        }
    o->opaque = imgset_opaque(o);
}

static void imgset_free(imgset *o)
{
    for (int f = 0; f < o->n; f++)
        for (int e = 0; e < 2; e++) {
            free(o->virt[f][e]);
            free(o->depth[f][e]);
        }
}

static void scale_res(bench *b, int n, double max_s, ef_isa isa)
{
    static const int sizes[][2] = {{640, 400}, {1280, 800}, {1920, 1200}, {2560, 1600}};
    FILE *f = open_csv(b, "frame_res.csv",
                       "width,height,megapixels,median_1t_ms,p99_1t_ms,median_2t_ms,p99_2t_ms");
    printf("\nScaling with the output resolution (per eye; camera 640x480, typical sequence; %s, "
           "medians of up to %d frames):\n  %10s %10s %10s %10s\n",
           ef_isa_name(isa), n, "size", "viewport", "1 thread", "2 threads");
    posesrc typical = {b->samples, b->seq_frames, NULL, 0};
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        kin_sthmd_desc hd = b->hmd;
        hd.lcd_width = sizes[i][0];
        hd.lcd_height = sizes[i][1];
        kin_sthmd_geometry g = kin_sthmd_geometry_of(&hd);
        imgset is;
        imgset_resized(b, &is, sizes[i][0], sizes[i][1], 4);
        double med[2] = {0, 0}, p99[2] = {0, 0};
        for (int t = 1; t <= 2; t++) {
            pipe_ctx *p = make_pipe(b, &b->model, isa, t, &hd);
            result r;
            if (p && measure(b, p, &is, &typical, n, max_s, &r)) {
                med[t - 1] = r.total.median;
                csv_row(b, "scale_res", "egofuse", ef_isa_name(isa), t, &r, -1, sizes[i][0],
                        sizes[i][1]);
                p99[t - 1] = r.total.p99;
            }
            pipe_destroy(p);
        }
        char sz[32], vp[32];
        snprintf(sz, sizeof sz, "%dx%d", sizes[i][0], sizes[i][1]);
        snprintf(vp, sizeof vp, "%dx%d", g.vp_width, g.vp_height);
        if (f) fprintf(f, "%d,%d,%.3f,%.4f,%.4f,%.4f,%.4f\n", sizes[i][0], sizes[i][1],
                       sizes[i][0] * sizes[i][1] / 1e6, med[0], p99[0], med[1], p99[1]);
        printf("  %10s %10s %10.3f %10.3f\n", sz, vp, med[0], med[1]);
        imgset_free(&is);
    }
    if (f) fclose(f);
}

/* --------------------------------------------------- the named HMDs */

/* Camera frames of hd's sensor made from the sample's (the paper's camera,
 * 640x480 at 62 deg), the frames of the window's first n slots: each
 * pixel of hd's sensor takes the sample pixel on the same ray (nearest;
 * mid grey where hd's wider FOV sees past the sample's), as YUYV. The
 * arms land about where hd's camera sees them (its cameras sit a few mm
 * elsewhere); the frame's time depends on the sizes and on the area the
 * mask model covers, which comes from the model and hd, not from these
 * pixels. Returns 0 when a sample image cannot be read. */
static int hmd_cameras(bench *b, const kin_sthmd_desc *hd, int n, uint8_t *(*yuyv)[2])
{
    const double d2r = 3.14159265358979323846 / 180.0;
    const int sw = b->hmd.cam_width, sh = b->hmd.cam_height;
    const int w = hd->cam_width, h = hd->cam_height;
    const double f0 = 0.5 * sw / tan(0.5 * b->hmd.cam_hfov_deg * d2r);
    const double f1 = 0.5 * w / tan(0.5 * hd->cam_hfov_deg * d2r);
    int *mx = xmalloc(sizeof(int) * (size_t)w), *my = xmalloc(sizeof(int) * (size_t)h);
    for (int x = 0; x < w; x++) {
        double u = 0.5 * sw + (x + 0.5 - 0.5 * w) * f0 / f1;
        mx[x] = u >= 0 && u < sw ? (int)u : -1;
    }
    for (int y = 0; y < h; y++) {
        double v = 0.5 * sh + (y + 0.5 - 0.5 * h) * f0 / f1;
        my[y] = v >= 0 && v < sh ? (int)v : -1;
    }
    uint8_t *rgba = xmalloc((size_t)w * h * 4);
    char path[IO_PATH_MAX + 64];
    int ok = 1;
    for (int f = 0; f < n && ok; f++)
        for (int e = 0; e < 2 && ok; e++) {
            io_image img = {0};
            io_scene_frame_path(&b->sc, b->sc.camera[e], b->window_frame[f], path, sizeof path);
            if (!load_rgba(path, sw, sh, &img)) {
                ok = 0;
                break;
            }
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    uint8_t *d = rgba + ((size_t)y * w + x) * 4;
                    if (mx[x] < 0 || my[y] < 0) {
                        d[0] = d[1] = d[2] = 128;
                        d[3] = 255;
                    } else {
                        memcpy(d, (uint8_t *)img.data + (size_t)my[y] * img.stride + 4 * mx[x], 4);
                    }
                }
            io_image_free(&img);
            yuyv[f][e] = xmalloc((size_t)w * h * 2);
            bench_rgba_to_yuyv(rgba, w, h, (size_t)w * 4, yuyv[f][e]);
        }
    free(rgba);
    free(mx);
    free(my);
    return ok;
}

/* The typical sequence on each named HMD (kin_sthmd_preset: the paper's,
 * a consumer one with 1280x1024 cameras and 2064x2208 per eye, a high-end
 * one with 1920x1080 cameras and 2880x2720 per eye): AVX2 with 1 and 2
 * threads, the best ISA with 2, against the memory floor of that output
 * size. Rows frame_hmd / floor_hmd of bench.csv (out_w, out_h), and
 * frame_hmd.csv for the chart. */
static void run_hmds(bench *b, int n, double max_s, const char *only)
{
    const ef_isa best = ef_isa_choose(EF_ISA_DEFAULT);
    const int has_avx2 = ef_cpu_has(EF_ISA_AVX2) && ef_isa_choose(EF_ISA_AVX2) == EF_ISA_AVX2;
    FILE *f = open_csv(b, "frame_hmd.csv",
                       "hmd,cam_w,cam_h,out_w,out_h,out_mp_both,crop_w,crop_h,vp_w,vp_h,coverage,"
                       "avx2_1t_ms,avx2_2t_ms,best_isa,best_2t_ms,floor_1t_ms,floor_2t_ms,"
                       "convert_ms,track_ms,skin_ms,raster_ms,fuse_ms,avx2_2t_inplace_ms,"
                       "best_2t_inplace_ms,inplace_fuse_ms,cpu_avx2_1t_ms,cpu_avx2_2t_ms,"
                       "cpu_best_2t_ms,cpu_avx2_2t_inplace_ms,cpu_best_2t_inplace_ms");
    printf("\nNamed HMDs (docs/kin.md): the typical sequence at each HMD's camera and display\n"
           "sizes (camera frames remapped from the samples' by ray, virtual images resized;\n"
           "medians of up to %d frames or %.1f s per case; stage columns as above, raster and\n"
           "fuse summed over both eyes) against the memcpy of both outputs; rows NAME/ip:\n"
           "composited in place (out = V's buffer, refreshed untimed before each frame):\n",
           n, max_s);
    posesrc typical = {b->samples, b->seq_frames, NULL, 0};
    for (int k = 0; kin_sthmd_preset_name(k); k++) {
        const char *name = kin_sthmd_preset_name(k);
        if (only && strcmp(only, name)) continue;
        kin_sthmd_desc hd;
        kin_sthmd_preset(name, &hd);
        const kin_sthmd_geometry g = kin_sthmd_geometry_of(&hd);
        const int nf = b->window < 4 ? b->window : 4;
        uint8_t *yuyv[MAX_WINDOW][2];
        memset(yuyv, 0, sizeof yuyv);
        if (!hmd_cameras(b, &hd, nf, yuyv)) {
            printf("  %s: SKIPPED (the sample camera images cannot be read)\n", name);
            for (int i = 0; i < nf; i++) free(yuyv[i][0]), free(yuyv[i][1]);
            continue;
        }
        imgset is;
        imgset_resized(b, &is, hd.lcd_width, hd.lcd_height, nf);
        b->cam = yuyv;
        b->cam_n = nf;
        b->cam_w = hd.cam_width;
        b->cam_h = hd.cam_height;
        b->cam_size = (size_t)hd.cam_width * hd.cam_height * 2;
        printf("\n  %s: camera %dx%d -> crop %dx%d at (%d, %d); display %dx%d per eye "
               "(%.2f MP both eyes), viewport %dx%d at (%d, %d)\n",
               name, hd.cam_width, hd.cam_height, g.crop_width, g.crop_height, g.crop_x0,
               g.crop_y0, hd.lcd_width, hd.lcd_height, 2e-6 * hd.lcd_width * hd.lcd_height,
               g.vp_width, g.vp_height, g.vp_x0, g.vp_y0);
        print_head();
        /* out of place (V read, out written), then in place (out = a
         * fresh copy of V, untimed: the hand's pixels only are written) */
        struct { ef_isa isa; int t, inplace; } cases[5] = {
            {EF_ISA_AVX2, 1, 0}, {EF_ISA_AVX2, 2, 0}, {best, 2, 0}, {EF_ISA_AVX2, 2, 1}, {best, 2, 1}};
        double ms[5] = {NAN, NAN, NAN, NAN, NAN}, cpu[5] = {NAN, NAN, NAN, NAN, NAN}, ip_fuse = NAN;
        result r2 = {0};
        for (int c = 0; c < 5; c++) {
            if ((c < 2 || c == 3) && !has_avx2) continue;
            if ((c == 2 || c == 4) && has_avx2 && best == EF_ISA_AVX2) {
                ms[c] = ms[c - 1];
                cpu[c] = cpu[c - 1];
                continue;
            }
            pipe_ctx *p = make_pipe(b, &b->model, cases[c].isa, cases[c].t, &hd);
            result r;
            b->inplace = cases[c].inplace;
            if (p && pipe_isa(p) == (int)cases[c].isa &&
                measure(b, p, &is, &typical, n, max_s, &r)) {
                char label[32];
                snprintf(label, sizeof label, "%s%s", name, cases[c].inplace ? "/ip" : "");
                print_row(label, ef_isa_name(cases[c].isa), cases[c].t, &r);
                printf("  %-8s CPU time of the process per frame (median): %.3f ms%s\n", "",
                       r.cpu, cases[c].t == 2 ? " (both threads)" : "");
                cpu[c] = r.cpu;
                csv_row(b, cases[c].inplace ? "frame_hmd_inplace" : "frame_hmd", grid_impl,
                        ef_isa_name(cases[c].isa), cases[c].t, &r, -1, hd.lcd_width,
                        hd.lcd_height);
                ms[c] = r.total.median;
                if (c == 1 || (c == 2 && !has_avx2)) r2 = r;
                if (c == 3 || (c == 4 && !has_avx2)) ip_fuse = r.fuse;
            }
            b->inplace = 0;
            pipe_destroy(p);
        }
        result fl[2];
        for (int t = 1; t <= 2; t++) {
            memcpy_floor(b, &is, t, n, &fl[t - 1]);
            csv_row(b, "floor_hmd", "memcpy", "-", t, &fl[t - 1], -1, hd.lcd_width, hd.lcd_height);
        }
        const double bytes = 2.0 * 2.0 * hd.lcd_width * hd.lcd_height * 4;
        printf("  memcpy floor (both outputs, %.1f MB read + written): 1 thread %.3f ms, "
               "2 threads %.3f ms (%.1f GB/s)\n",
               bytes / 1e6, fl[0].total.median, fl[1].total.median,
               bytes / fl[1].total.median / 1e6);
        if (!isnan(ms[1]))
            printf("  frame / floor (avx2, 2 threads): %.1fx; %s / avx2: %.2fx; in place "
                   "(rows /ip: V composited in its own buffer) / out of place, avx2: %.2fx\n",
                   ms[1] / fl[1].total.median, ef_isa_name(best), ms[2] / ms[1], ms[3] / ms[1]);
        if (f)
            fprintf(f, "%s,%d,%d,%d,%d,%.4f,%d,%d,%d,%d,%.4f,%.4f,%.4f,%s,%.4f,%.4f,%.4f,%.4f,%.4f,"
                       "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n",
                    name, hd.cam_width, hd.cam_height, hd.lcd_width, hd.lcd_height,
                    2e-6 * hd.lcd_width * hd.lcd_height, g.crop_width, g.crop_height, g.vp_width,
                    g.vp_height, r2.coverage, ms[0], ms[1], ef_isa_name(best), ms[2],
                    fl[0].total.median, fl[1].total.median, r2.convert, r2.track, r2.skin,
                    r2.raster, r2.fuse, ms[3], ms[4], ip_fuse, cpu[0], cpu[1], cpu[2], cpu[3],
                    cpu[4]);
        b->cam = b->yuyv;
        b->cam_n = b->window;
        b->cam_w = b->hmd.cam_width;
        b->cam_h = b->hmd.cam_height;
        b->cam_size = b->yuyv_size;
        imgset_free(&is);
        for (int i = 0; i < nf; i++) free(yuyv[i][0]), free(yuyv[i][1]);
    }
    if (f) fclose(f);
}

/* -------------------------------------------------------------- main */

static int parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (*s == 0 || *end != 0 || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

int main(int argc, char **argv)
{
    const char *samples = "build/samples", *outdir = "bench/out";
    /* caps: frames per case and seconds per case (the time box) */
    budget bu = {3000, 1000, 30, 200, 6.0, 2.5, 2.0, 1.0};
    int window = 16, scaling = 1, hmds = 1, hmd_frames = 400;
    double hmd_s = 4.0;
    const char *hmd_only = NULL;
    for (int a = 1; a < argc; a++) {
        const char *o = argv[a], *v = a + 1 < argc ? argv[a + 1] : NULL;
        int ok = 1, sec = 0;
        if (!strcmp(o, "--samples") && v) samples = v, a++;
        else if (!strcmp(o, "--out") && v) outdir = v, a++;
        else if (!strcmp(o, "--frames") && v) {
            ok = parse_int(v, 1, 1000000, &bu.frames_best), a++;
            bu.frames = bu.frames_best;
        } else if (!strcmp(o, "--ref-frames") && v) ok = parse_int(v, 1, 1000000, &bu.ref_frames), a++;
        else if (!strcmp(o, "--scale-frames") && v) ok = parse_int(v, 1, 1000000, &bu.scale_frames), a++;
        else if (!strcmp(o, "--seconds") && v) {
            ok = parse_int(v, 1, 100000, &sec), a++;
            bu.s_best = sec, bu.s_other = sec / 2.0, bu.s_ref = sec / 2.0, bu.s_scale = sec / 5.0;
        } else if (!strcmp(o, "--window") && v) ok = parse_int(v, 1, MAX_WINDOW, &window), a++;
        else if (!strcmp(o, "--quick")) {
            budget q = {300, 200, 5, 40, 1.0, 0.5, 0.5, 0.3};
            bu = q;
            hmd_frames = 60;
            hmd_s = 1.0;
        } else if (!strcmp(o, "--no-scaling")) scaling = 0;
        else if (!strcmp(o, "--no-hmds")) hmds = 0;
        else if (!strcmp(o, "--hmds-only")) scaling = 0, hmds = 2;
        else if (!strcmp(o, "--hmd-frames") && v) ok = parse_int(v, 1, 1000000, &hmd_frames), a++;
        else if (!strcmp(o, "--hmd") && v) {
            hmd_only = v, a++;
            ok = kin_sthmd_preset(v, NULL) == 0;
        }
        else if (!strcmp(o, "--isa") && v) {
            grid_isa = ef_isa_parse(v), a++;
            ok = grid_isa != EF_ISA_DEFAULT;
        } else if (!strcmp(o, "--threads") && v) ok = parse_int(v, 1, 2, &grid_threads), a++;
        else if (!strcmp(o, "--inplace")) grid_inplace = 1;
        else if (!strcmp(o, "--hard-edges")) grid_hard_edges = 1;
        else if (!strcmp(o, "--cpu-time")) frame_cpu_clock = 1;
        else if (!strcmp(o, "--lod") && v) {
            if (!strcmp(v, "auto")) grid_lod = PIPE_LOD_AUTO;
            else ok = parse_int(v, 0, PIPE_LOD_MAX - 1, &grid_lod);
            a++;
        } else if (!strcmp(o, "--lod-px") && v) {
            char *e = NULL;
            grid_lod_px = strtof(v, &e);
            ok = e != v && *e == 0 && grid_lod_px > 0.0f && grid_lod_px <= 1000.0f;
            a++;
        }
        else ok = 0;
        if (!ok) {
            if (v && strncmp(o, "--", 2) == 0 && !(v[0] == '-' && v[1] == '-'))
                fprintf(stderr, "bench_frame: %s '%s': not a valid value, or not an option\n", o, v);
            else
                fprintf(stderr, "bench_frame: %s: not an option, or its value is missing\n", o);
            fprintf(stderr,
                    "usage: %s [--samples DIR] [--out DIR] [--frames N] [--ref-frames N]\n"
                    "       [--scale-frames N] [--seconds S] [--window N] [--quick] "
                    "[--no-scaling]\n"
                    "       [--no-hmds] [--hmds-only] [--hmd-frames N] [--hmd NAME]\n"
                    "       [--isa ref|sse2|avx2|avx512] [--threads 1|2] [--inplace] [--hard-edges]\n"
                    "       [--cpu-time] [--lod N|auto] [--lod-px PX]\n",
                    argv[0]);
            return 2;
        }
    }
    static bench b;
    setvbuf(stdout, NULL, _IOLBF, 0);
    pipe_set_stats_clock(frame_cpu_clock);
    if (frame_cpu_clock)
        printf("--cpu-time: every frame and stage time below is the CPU time of the thread that "
               "ran it (waits do not count; the memcpy and composite peers stay wall time)\n");
    (void)bm_eye_mvp; /* bench_mesh.h: the cameras here are the HMD's */
    b.outdir = outdir;
    mkdir(outdir, 0755);
    char cpu[256];
    bench_cpu_name(cpu, sizeof cpu);
    printf("machine: %s, %ld cpus online\n", cpu, sysconf(_SC_NPROCESSORS_ONLN));
#if defined(__clang__)
    printf("compiler: clang %s, -O2 -ffp-contract=off\n", __clang_version__);
#elif defined(__GNUC__)
    printf("compiler: gcc %s, -O2 -ffp-contract=off\n", __VERSION__);
#endif
    printf("ISA: best %s, EGOFUSE_ISA %s\n", ef_isa_name(ef_cpu_best()),
           getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "unset");
    double t_load = now_ms();
    if (!preload(&b, samples, window)) return 1;
    if (!helper_init(&b.help)) return 1;
    int cap = bu.frames_best > bu.frames ? bu.frames_best : bu.frames;
    if (bu.ref_frames > cap) cap = bu.ref_frames;
    if (bu.scale_frames > cap) cap = bu.scale_frames;
    if (hmd_frames > cap) cap = hmd_frames;
    if (cap < 16) cap = 16;
    times_init(&b.tm, cap);
    char path[1024];
    snprintf(path, sizeof path, "%s/bench.csv", outdir);
    b.csv = fopen(path, "w");
    if (b.csv) fprintf(b.csv, CSV_HEADER "\n");
    long tris = 0;
    for (int i = 0; i < b.model.mesh_count; i++) tris += b.model.meshes[i].index_count / 3;
    printf("samples: %s, %d frames at %.0f fps, model %d nodes, %ld triangles; %d stereo frames "
           "preloaded (%.0f MB, camera as YUYV) in %.1f s\n",
           samples, b.seq_frames, b.fps, b.model.node_count, tris, b.window,
           b.window * 2 * (b.yuyv_size + (size_t)b.base.w * b.base.h * 8) / 1e6,
           (now_ms() - t_load) / 1e3);
    printf("virtual images: %s\n",
           b.base.opaque ? "opaque (alpha 255 everywhere, checked at load): pipe_frame_in.virt_opaque "
                           "= 1, the composite copies V where the hand is not without reading alpha"
                         : "not opaque: pipe_frame_in.virt_opaque = 0");
    printf("frames per case: up to %d for the best ISA (%s), %d for the other SIMD paths, %d for "
           "the scalar reference,\n%d per scaling point, each case also stopped after %.1f / %.1f / "
           "%.1f / %.1f s (at least 100 frames); poses cycle through the %d-frame sequence, images "
           "through the window\n",
           bu.frames_best, ef_isa_name(ef_isa_choose(EF_ISA_DEFAULT)), bu.frames, bu.ref_frames,
           bu.scale_frames, bu.s_best, bu.s_other, bu.s_ref, bu.s_scale, b.seq_frames);

    if (grid_lod) {
        io_error err;
        char ln[32];
        double t0 = now_ms();
        if (io_lod_build(samples, &b.model, NULL, &grid_lod_chain, &err) != IO_OK) {
            fprintf(stderr, "bench_frame: %s\n", err.msg);
            return 1;
        }
        if (grid_lod == PIPE_LOD_AUTO) snprintf(ln, sizeof ln, "auto@%gpx", (double)grid_lod_px);
        else snprintf(ln, sizeof ln, "L%d", grid_lod);
        snprintf(grid_impl, sizeof grid_impl, "egofuse_lod%s", ln[0] == 'L' ? ln + 1 : ln);
        printf("levels of detail (--lod): %s of %d levels (", ln, grid_lod_chain.level_count);
        for (int l = 0; l < grid_lod_chain.level_count; l++)
            printf("%s%ld", l ? ", " : "", grid_lod_chain.level[l].triangles);
        printf(" triangles), built in %.1f ms; the scaling rows' models draw whole\n",
               now_ms() - t0);
    }
    ef_isa best = ef_isa_choose(EF_ISA_DEFAULT);
    if (hmds == 2) {   /* --hmds-only */
        run_hmds(&b, hmd_frames, hmd_s, hmd_only);
        if (b.csv) fclose(b.csv);
        helper_stop(&b.help);
        io_lod_free(&grid_lod_chain);
        return 0;
    }
    pipe_ctx *p = make_pipe(&b, &b.model, best, 2, NULL);
    if (!p) return 1;
    find_worst(&b, p);
    pipe_destroy(p);
    printf("worst case: pose of frame %d, head %.3f m from %s (%.3f m recorded), looking at it: "
           "%.1f%% of the camera pixels covered\n",
           b.worst_frame, b.worst.d, bench_worst_target_name[b.worst.target],
           bench_worst_d0(&b.worst), 100 * b.worst.cover);

    run_grid(&b, &bu);
    printf("\nLatency: the pipeline's processing latency (camera frame in memory -> both "
           "outputs composited; the frame is\nprocessed in one call, nothing is queued), %s:\n",
           ef_isa_name(best));
    for (int t = 0; t < 2; t++)
        for (int c = 0; c < 2; c++)
            if (b.lat[c][t].frames)
                printf("  %-7s %d thread%s: median %.3f ms, p99 %.3f ms, max %.3f ms\n",
                       c ? "worst" : "typical", t + 1, t ? "s" : " ", b.lat[c][t].total.median,
                       b.lat[c][t].total.p99, b.lat[c][t].total.max);
    printf("Capture-to-output latency of the live path (V4L2 time stamp -> output) is not measured: "
           "there is no camera here.\n");
    const int stage_n = bu.frames_best < 500 ? bu.frames_best : 500;
    run_memcpy(&b, stage_n);
    run_composite(&b, stage_n);
    if (scaling) {
        scale_tris(&b, bu.scale_frames, bu.s_scale, best);
        scale_cover(&b, bu.scale_frames, bu.s_scale, best);
        scale_res(&b, bu.scale_frames, bu.s_scale, best);
    }
    if (hmds) run_hmds(&b, hmd_frames, hmd_s, hmd_only);
    if (b.csv) fclose(b.csv);
    printf("\nCSV: %s (egofuse, memcpy, pixman rows; llvmpipe_frame appends its own), "
           "frame_tris.csv, frame_cover.csv, frame_res.csv in %s/\n",
           path, outdir);
    helper_stop(&b.help);
    io_lod_free(&grid_lod_chain);
    return 0;
}
