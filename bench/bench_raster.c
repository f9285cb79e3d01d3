/* bench_raster.c - rasterizer speed: both eyes of the two-arm scene of
 * bench_mesh.h at 640x400, depth + coverage + normals (3 attributes), at
 * about 2k, 10k and 40k triangles, per ISA the CPU runs, with 1 and 2
 * threads (one rast_context each). Reports medians over many runs of:
 * ms per eye and for both eyes (draw only; clear and vertex transform
 * reported apart), and triangles per second. Reports, never fails.
 *
 * Then the pipeline's configuration ("pipe" rows): the raster stage of
 * src/pipe run_eye as it runs per eye (each eye its own 1-thread
 * context: rast_context_clear, then per mesh rast_transform_points +
 * rast_transform_dirs and rast_context_draw with the view-space normals as
 * 3 attributes), cull back (bench_frame, `egofuse demo`, --cull-back) and
 * cull none (the pipe's default), with the cache cold as in a frame (the
 * lighting and composite stage write about 24 MB between two raster
 * stages; --cold MB, 0 = hot): for the bench scene at each --tris count
 * (which covers ~8% of the view) and for the sample model at 12 poses
 * over its animation (--samples DIR, default build/samples: 15.6k
 * triangles, ~20% of the view, about 3x the pixels and 1.7x the scanned
 * triangles of the bench scene at 16k; --samples none skips it). Columns: ms per eye of
 * the stage and of its parts, pixels written and triangles scanned per
 * eye. The stage of the last pose is checked against pipe_pose_draw
 * (same bytes). The transforms run with rast_draw_isa() (capped by
 * EGOFUSE_ISA, not by the row's ISA), as in the pipe.
 *
 *   bench_raster [--csv] [--runs N] [--tris N,N,...] [--size WxH]
 *                [--isa ref|sse2|avx2|avx512] [--threads 1|2]
 *                [--samples DIR|none] [--cold MB] [--no-pipe]
 *                [--sample-only] [--cull back|none] [--clear-normals]
 *                [--cpu-time] [--float-normals]
 *
 * --sample-only skips the bench scene (its draw rows and pipe rows), --cull
 * runs one cull mode of the pipe rows: for counting instructions of the
 * sample model's stage alone (valgrind --tool=callgrind
 * --toggle-collect=rast_context_draw, docs/bench.md raster section).
 * The pipe rows draw the normals packed into an attr_n10 plane
 * (rast_target.attr_n10, 4 bytes per pixel) as the pipe does by default
 * (src/pipe/pipe.h); --float-normals draws 3 floats per pixel instead
 * (the pipe's plane with refinement, smoothing or --aa).
 *
 * The same scene through Mesa llvmpipe, with the ratio, is
 * bench/llvmpipe/llvmpipe_raster (built separately: it needs EGL/GLES). */
#include "../src/cpu/cpu.h"
#include "../src/io/io.h"
#include "../src/pipe/pipe.h"
#include "../src/raster/raster.h"
#include "bench_mesh.h"
#include "bench_sample.h"
#include "bench_util.h"
#include "../src/cpu/ef_mem.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* --cpu-time: every time is the calling thread's CPU time (the pipe rows
 * run each eye's 1-thread context on the caller: on a shared machine the
 * CPU time is the figure to compare; the 2-thread draw rows then count
 * the caller's thread only). */
static clockid_t bench_clock = CLOCK_MONOTONIC;

static double now_ms(void) { return bench_now_ms(bench_clock); }
static double median(double *v, int n) { return bench_median(v, n); }


/* ---- the pipeline's configuration ------------------------------------- */

/* One posed frame of a model: meshes (positions, normals in the head's
 * world), indices, and the two eyes' matrices. */
typedef struct pipe_scene {
    int meshes;
    const int *vcount, *icount;
    const float *const *pos, *const *nrm;
    const uint32_t *const *idx;
} pipe_scene;

/* --clear-normals: the pipe rows' clear also clears the normals
 * (rast_context_clear; the pipe with a refined, anti-aliased, smoothed or
 * reprojected mask, or a lens), else not (rast_context_clear_keep_attr,
 * the pipe's default path, docs/raster.md section 13). */
static int clear_normals = 0;
static int use_n10 = 1;   /* 0: --float-normals */

typedef struct pipe_eye {
    rast_context *ctx;
    rast_target tg;
    float *clip, *vn;
} pipe_eye;

/* The raster stage of run_eye for one eye: context clear, then per mesh
 * the two transforms and the draw. Adds the parts' times to t[3] (clear,
 * transforms, draw) and the stats to *st. */
static void pipe_stage(pipe_eye *e, const pipe_scene *sc, const float vp[16],
                       const float view[16], rast_cull cull, double t[3], rast_stats *st)
{
    double t0 = now_ms();
    if (clear_normals)
        rast_context_clear(e->ctx, &e->tg);
    else
        rast_context_clear_keep_attr(e->ctx, &e->tg); /* the pipe's default path */
    t[0] += now_ms() - t0;
    for (int i = 0; i < sc->meshes; i++) {
        double a = now_ms();
        rast_transform_points(vp, sc->pos[i], sc->vcount[i], e->clip);
        rast_transform_dirs(view, sc->nrm[i], sc->vcount[i], e->vn);
        double b = now_ms();
        rast_mesh_desc d = { e->clip, sc->vcount[i], e->vn, 3, sc->idx[i], sc->icount[i] / 3,
                             cull };
        rast_context_draw(e->ctx, &e->tg, &d, st);
        t[1] += b - a;
        t[2] += now_ms() - b;
    }
}

/* Stands for the rest of a frame between two raster stages: updates mb MB
 * with plain stores (a memset this large may use non-temporal stores,
 * which leave the caches, and so the target planes, alone). */
static void evict(uint8_t *junk, int mb, int r)
{
    if (!junk || mb <= 0)
        return;
    uint64_t *q = (uint64_t *)(void *)junk;
    const size_t n = ((size_t)mb << 20) / sizeof *q;
    for (size_t i = 0; i < n; i++)
        q[i] += (uint64_t)(unsigned)r;
}

static const char *cull_name(rast_cull c)
{
    return c == RAST_CULL_BACK ? "back" : c == RAST_CULL_FRONT ? "front" : "none";
}

static void pipe_print_head(int csv)
{
    if (csv)
        printf("pipe,model,tris,isa,cull,ms_stage_per_eye,ms_clear_per_eye,ms_xform_per_eye,"
               "ms_draw_per_eye,pixels_per_eye,scanned_per_eye,cold_mb\n");
    else
        printf("%-6s %7s %-7s %-4s %9s %8s %8s %8s %7s %7s\n", "model", "tris", "isa", "cull",
               "stage/eye", "clear", "xform", "draw", "px/eye", "scanned");
}

static void pipe_print_row(int csv, const char *model, int tris, int isa, rast_cull cull,
                           double stage, double clr, double xf, double draw, long px,
                           long scanned, int cold)
{
    if (csv)
        printf("pipe,%s,%d,%s,%s,%.4f,%.4f,%.4f,%.4f,%ld,%ld,%d\n", model, tris,
               ef_isa_name((ef_isa)isa), cull_name(cull), stage, clr, xf, draw, px, scanned,
               cold);
    else
        printf("%-6s %7d %-7s %-4s %9.4f %8.4f %8.4f %8.4f %7ld %7ld\n", model, tris,
               ef_isa_name((ef_isa)isa), cull_name(cull), stage, clr, xf, draw, px, scanned);
    fflush(stdout);
}

/* The pipe rows of one scene: poses[p] (np of them) are the per-pose
 * scenes, vp[p][e] / view[p][e] the eyes' matrices. Medians over runs of
 * whole passes through the poses (ms per eye: the pass time / (2 np)). */
static int only_cull = -1;   /* --cull: RAST_CULL_BACK or RAST_CULL_NONE, -1 both */

static void pipe_rows(int csv, const char *model, int tris, const pipe_scene *poses, int np,
                      float (*vp)[2][16], float (*view)[2][16], int W, int H, int runs,
                      int only_isa, int cold, uint8_t *junk)
{
    int maxv = 0;
    for (int p = 0; p < np; p++)
        for (int i = 0; i < poses[p].meshes; i++)
            maxv = poses[p].vcount[i] > maxv ? poses[p].vcount[i] : maxv;
    pipe_eye eye[2];
    float *planes[2];
    for (int e = 0; e < 2; e++) {
        planes[e] = malloc((size_t)W * H * 16 + (size_t)W * H);
        eye[e].clip = malloc((size_t)maxv * 4 * sizeof(float));
        eye[e].vn = malloc((size_t)maxv * 3 * sizeof(float));
        if (!planes[e] || !eye[e].clip || !eye[e].vn) {
            fprintf(stderr, "out of memory\n");
            exit(1);
        }
        rast_target t = { W, H, planes[e], W, (uint8_t *)(planes[e] + (size_t)W * H * 4), W,
                          planes[e] + (size_t)W * H, 3 * W, 3, NULL, 0 };
        if (use_n10) {
            t.attr_n10 = (uint32_t *)(void *)t.attr;
            t.attr_n10_stride = W;
            t.attr = NULL;
            t.attr_stride = 0;
        }
        eye[e].tg = t;
    }
    double *ts = malloc((size_t)runs * 4 * sizeof(double));
    if (!ts)
        exit(1);
    static const rast_cull culls[2] = { RAST_CULL_BACK, RAST_CULL_NONE };
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa) || (only_isa && isa != only_isa))
            continue;
        for (int ci = 0; ci < 2; ci++) {
            if (only_cull >= 0 && (int)culls[ci] != only_cull)
                continue;
            rast_context_desc d = { isa, 1 };
            for (int e = 0; e < 2; e++)
                if (!(eye[e].ctx = rast_context_create(&d)))
                    exit(1);
            long px = 0, scanned = 0;
            for (int r = -2; r < runs; r++) {   /* 2 warm-up passes */
                double t[3] = { 0, 0, 0 };
                rast_stats st = { 0 };
                for (int p = 0; p < np; p++) {
                    evict(junk, cold, r * np + p);
                    for (int e = 0; e < 2; e++)
                        pipe_stage(&eye[e], &poses[p], vp[p][e], view[p][e], culls[ci], t, &st);
                }
                if (r >= 0) {
                    for (int k = 0; k < 3; k++)
                        ts[(size_t)runs * (size_t)(k + 1) + (size_t)r] = t[k] / (2.0 * np);
                    ts[r] = (t[0] + t[1] + t[2]) / (2.0 * np);
                }
                px = st.pixels_written / (2 * np);
                scanned = st.tris_drawn / (2 * np);
            }
            double m[4];
            for (int k = 0; k < 4; k++)
                m[k] = median(ts + (size_t)runs * (size_t)k, runs);
            pipe_print_row(csv, model, tris, rast_context_isa(eye[0].ctx), culls[ci], m[0],
                           m[1], m[2], m[3], px, scanned, cold);
            for (int e = 0; e < 2; e++)
                rast_context_destroy(eye[e].ctx);
        }
    }
    free(ts);
    for (int e = 0; e < 2; e++) {
        free(planes[e]);
        free(eye[e].clip);
        free(eye[e].vn);
    }
}

/* The sample model (DIR/scene.txt) posed at np times evenly over its
 * animation, both eyes of the STHMD cameras at the crop resolution, as
 * pipe_frame draws them. Returns 0 (and prints why) when it cannot. */
static int pipe_samples(int csv, const char *dir, int np, int runs, int only_isa, int cold,
                        uint8_t *junk)
{
    char path[IO_PATH_MAX + 64];
    io_scene sc;
    kin_model model;
    if (!bench_sample_model(dir, csv ? "# " : "", &sc, &model, path, sizeof path)) return 0;
    const kin_animation *anim = kin_model_find_anim(&model, sc.animation);
    const int head = kin_model_find_node(&model, sc.head_node[0] ? sc.head_node : "head");
    pipe_pose ps;
    if (head < 0 || pipe_pose_init(&ps, &model) != 0) {
        printf("%ssample model: skipped (no head node '%s')\n", csv ? "# " : "", sc.head_node);
        kin_model_free(&model);
        return 0;
    }
    const kin_sthmd_desc hmd = kin_sthmd_desc_resolved(NULL);
    const kin_sthmd_geometry geo = kin_sthmd_geometry_of(&hmd);
    const int W = geo.crop_width, H = geo.crop_height, nm = model.mesh_count;
    /* Every pose's skinned meshes, copied (pipe_pose holds one pose). */
    pipe_scene *poses = calloc((size_t)np, sizeof *poses);
    float(*vp)[2][16] = malloc((size_t)np * sizeof *vp);
    float(*view)[2][16] = malloc((size_t)np * sizeof *view);
    int *vcount = malloc((size_t)nm * sizeof(int)), *icount = malloc((size_t)nm * sizeof(int));
    const uint32_t **idx = malloc((size_t)nm * sizeof *idx);
    float **pos = malloc((size_t)np * nm * sizeof *pos);
    float **nrm = malloc((size_t)np * nm * sizeof *nrm);
    if (!poses || !vp || !view || !vcount || !icount || !idx || !pos || !nrm)
        exit(1);
    long tris = 0;
    for (int i = 0; i < nm; i++) {
        vcount[i] = ps.meshes[i].vertex_count;
        icount[i] = ps.meshes[i].index_count;
        idx[i] = ps.meshes[i].indices;
        tris += icount[i] / 3;
    }
    for (int p = 0; p < np; p++) {
        const float tp = anim ? anim->duration * (float)p / (float)np : 0.0f;
        pipe_pose_anim(&ps, anim, tp);
        for (int i = 0; i < nm; i++) {
            const size_t n = (size_t)vcount[i] * 3;
            pos[(size_t)p * nm + i] = malloc(n * sizeof(float));
            nrm[(size_t)p * nm + i] = malloc(n * sizeof(float));
            if (!pos[(size_t)p * nm + i] || !nrm[(size_t)p * nm + i])
                exit(1);
            memcpy(pos[(size_t)p * nm + i], ps.pos[i], n * sizeof(float));
            memcpy(nrm[(size_t)p * nm + i], ps.nrm[i], n * sizeof(float));
        }
        for (int e = 0; e < 2; e++) {
            const kin_camera cam = kin_sthmd_camera(&hmd, &ps.world[head], (kin_eye)e);
            memcpy(vp[p][e], cam.view_proj.m, sizeof vp[p][e]);
            memcpy(view[p][e], cam.view.m, sizeof view[p][e]);
        }
        pipe_scene s = { nm, vcount, icount, (const float *const *)(pos + (size_t)p * nm),
                         (const float *const *)(nrm + (size_t)p * nm), idx };
        poses[p] = s;
    }
    /* The stage here equals the pipe's: the last pose through
     * pipe_pose_draw and through pipe_stage, both cull modes. */
    int same = 1;
    {
        rast_context *c = rast_context_create(NULL);
        size_t plane = (size_t)W * H * 17;
        uint8_t *a = malloc(plane), *b = malloc(plane);
        float *clip = malloc((size_t)ps.max_vertices * 4 * sizeof(float));
        float *vn = malloc((size_t)ps.max_vertices * 3 * sizeof(float));
        if (!c || !a || !b || !clip || !vn)
            exit(1);
        for (int ci = 0; ci < 2; ci++) {
            const rast_cull cull = ci ? RAST_CULL_NONE : RAST_CULL_BACK;
            for (int k = 0; k < 2; k++) {
                uint8_t *m = k ? b : a;
                rast_target t = { W, H, (float *)(void *)m, W, m + (size_t)W * H * 16, W,
                                  (float *)(void *)(m + (size_t)W * H * 4), 3 * W, 3, NULL, 0 };
                if (k == 0) {
                    kin_camera cam = kin_sthmd_camera(&hmd, &ps.world[head], KIN_EYE_LEFT);
                    rast_target_clear(&t);
                    pipe_pose_draw(&ps, c, &cam, &t, cull, clip, vn, NULL);
                } else {
                    pipe_eye e = { c, t, clip, vn };
                    double tt[3] = { 0, 0, 0 };
                    rast_target_clear(&t);
                    rast_context_forget(c);
                    pipe_stage(&e, &poses[np - 1], vp[np - 1][0], view[np - 1][0], cull, tt,
                               NULL);
                }
            }
            same &= memcmp(a, b, plane) == 0;
        }
        rast_context_destroy(c);
        EF_FREE_ALL(a, b, clip, vn);
    }
    printf("%ssample model %s: %ld triangles in %d mesh%s, %d poses over '%s', %dx%d per eye; "
           "stage equal to pipe_pose_draw: %s\n",
           csv ? "# " : "", path, tris, nm, nm == 1 ? "" : "es", np, anim ? anim->name : "rest",
           W, H, same ? "yes" : "NO");
    pipe_rows(csv, "sample", (int)tris, poses, np, vp, view, W, H, runs, only_isa, cold, junk);
    for (int i = 0; i < np * nm; i++) {
        free(pos[i]);
        free(nrm[i]);
    }
    EF_FREE_ALL(pos, nrm, idx, vcount, icount, vp, view, poses);
    pipe_pose_free(&ps);
    kin_model_free(&model);
    return 1;
}

int main(int argc, char **argv)
{
    int csv = 0, runs = 301, W = 640, H = 400;
    int tris_list[8] = { 2000, 10000, 40000 }, ntl = 3;
    int only_isa = 0, only_threads = 0, pipe = 1, cold = 24;
    const char *samples = "build/samples";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv"))
            csv = 1;
        else if (!strcmp(argv[i], "--no-pipe"))
            pipe = 0;
        else if (!strcmp(argv[i], "--clear-normals"))
            clear_normals = 1;
        else if (!strcmp(argv[i], "--float-normals"))
            use_n10 = 0;
        else if (!strcmp(argv[i], "--sample-only"))
            ntl = 0;
        else if (!strcmp(argv[i], "--cpu-time"))
            bench_clock = CLOCK_THREAD_CPUTIME_ID;
        else if (!strcmp(argv[i], "--cull") && i + 1 < argc) {
            i++;
            only_cull = !strcmp(argv[i], "back") ? (int)RAST_CULL_BACK
                        : !strcmp(argv[i], "none") ? (int)RAST_CULL_NONE : -2;
            if (only_cull == -2) {
                fprintf(stderr, "--cull: back or none, not '%s'\n", argv[i]);
                return 2;
            }
        }
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc)
            samples = argv[++i];
        else if (!strcmp(argv[i], "--cold") && i + 1 < argc)
            cold = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--isa") && i + 1 < argc)
            only_isa = (int)ef_isa_parse(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            only_threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc)
            sscanf(argv[++i], "%dx%d", &W, &H);
        else if (!strcmp(argv[i], "--tris") && i + 1 < argc) {
            ntl = 0;
            for (char *s = strtok(argv[++i], ","); s && ntl < 8; s = strtok(NULL, ","))
                tris_list[ntl++] = atoi(s);
        } else {
            fprintf(stderr, "usage: %s [--csv] [--runs N] [--tris N,N,...] [--size WxH] "
                            "[--isa NAME] [--threads N] [--samples DIR|none] [--cold MB] "
                            "[--no-pipe] [--sample-only] [--cull back|none] [--clear-normals] "
                            "[--cpu-time] [--float-normals]\n",
                    argv[0]);
            return 2;
        }
    }
    if (runs < 1 || W < 1 || H < 1 || W > RAST_MAX_DIM || H > RAST_MAX_DIM || cold < 0 ||
        cold > 1024) {
        fprintf(stderr, "bad --runs or --size\n");
        return 2;
    }
    char cpu[128];
    bench_cpu_name(cpu, sizeof cpu);
    const char *p = csv ? "# " : "";
    printf("%smachine: %s, %ld online cpus\n", p, cpu, sysconf(_SC_NPROCESSORS_ONLN));
    printf("%scompiler: %s (" __VERSION__ "), flags -O2 -ffp-contract=off\n", p,
#if defined(__clang__)
           "clang"
#else
           "gcc"
#endif
    );
    printf("%sbest ISA: %s; rast_draw uses %s; EGOFUSE_ISA=%s\n", p,
           ef_isa_name(ef_cpu_best()), ef_isa_name((ef_isa)rast_draw_isa()),
           getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "(unset)");
    printf("%sscene: two arms (bench_mesh.h), %dx%d per eye, depth + mask + 3 normals, "
           "median of %d runs\n", p, W, H, runs);
    if (csv)
        printf("tris,isa,threads,mode,ms_per_eye,ms_both_eyes,mtris_per_s,pixels_per_eye,"
               "ms_clear_full_both,ms_clear_ctx_both,ms_transform_both\n");
    else
        printf("%7s %-7s %3s %-5s %9s %9s %8s %7s %9s %9s %8s\n", "tris", "isa", "thr",
               "mode", "ms/eye", "ms/2eyes", "Mtri/s", "px/eye", "clr full", "clr ctx",
               "xform");

    bm_eyes eyes;
    double *t_draw = malloc((size_t)runs * sizeof(double));
    double *t_clear = malloc((size_t)runs * sizeof(double));
    double *t_xf = malloc((size_t)runs * sizeof(double));
    double *t_cclear = malloc((size_t)runs * sizeof(double));
    if (!bm_eyes_init(&eyes, W, H) || !t_draw || !t_clear || !t_xf || !t_cclear)
        return 1;
    rast_target *tg = eyes.tg;

    for (int ti = 0; ti < ntl; ti++) {
        bm_mesh mesh;
        if (!bm_arms(&mesh, tris_list[ti]))
            return 1;
        float *clip[2], *vn = malloc((size_t)mesh.vertex_count * 3 * sizeof(float));
        float mvp[2][16], view[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
        for (int e = 0; e < 2; e++) {
            clip[e] = malloc((size_t)mesh.vertex_count * 4 * sizeof(float));
            bm_eye_mvp(e, W, H, mvp[e]);
        }
        for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
            if (!ef_cpu_has((ef_isa)isa) || (only_isa && isa != only_isa))
                continue;
            for (int th = 1; th <= 2; th++) {
                if (only_threads && th != only_threads)
                    continue;
                for (int mode = 0; mode < (th > 1 ? 2 : 1); mode++) {
                rast_context_desc d = { isa, th };
                rast_context *c = rast_context_create(&d);
                if (!c) {
                    fprintf(stderr, "cannot create a context (%s, %d threads)\n",
                            ef_isa_name((ef_isa)isa), th);
                    return 1;
                }
                rast_stats st;
                long pixels = 0;
                rast_mesh_desc md[2];
                for (int e = 0; e < 2; e++) {
                    rast_mesh_desc m1 = { clip[e], mesh.vertex_count, vn, 3, mesh.idx,
                                          mesh.tri_count, RAST_CULL_BACK };
                    md[e] = m1;
                }
                const rast_target *tp[2] = { &tg[0], &tg[1] };
                const rast_mesh_desc *mp[2] = { &md[0], &md[1] };
                for (int r = -5; r < runs; r++) {      /* 5 warm-up runs */
                    double t0 = now_ms();
                    for (int e = 0; e < 2; e++)
                        rast_transform_points(mvp[e], mesh.pos, mesh.vertex_count, clip[e]);
                    rast_transform_dirs(view, mesh.nrm, mesh.vertex_count, vn);
                    double t1 = now_ms();
                    rast_target_clear(&tg[0]);
                    rast_target_clear(&tg[1]);
                    double t2 = now_ms();
                    memset(&st, 0, sizeof st);
                    if (mode == 0) {
                        if (rast_context_draw_jobs(c, 2, tp, mp, &st) != RAST_OK)
                            return 1;
                    } else {
                        for (int e = 0; e < 2; e++)
                            if (rast_context_draw(c, &tg[e], &md[e], &st) != RAST_OK)
                                return 1;
                    }
                    double t3 = now_ms();
                    /* The context clear of the next frame: only the box
                     * drawn (the first one clears whole). */
                    rast_context_clear(c, &tg[0]);
                    rast_context_clear(c, &tg[1]);
                    double t4 = now_ms();
                    if (r >= 0) {
                        t_xf[r] = t1 - t0;
                        t_clear[r] = t2 - t1;
                        t_draw[r] = t3 - t2;
                        t_cclear[r] = t4 - t3;
                    }
                    pixels = st.pixels_written;
                }
                double mdr = median(t_draw, runs), mc = median(t_clear, runs),
                       mx = median(t_xf, runs), mcc = median(t_cclear, runs);
                double mtps = 2.0 * mesh.tri_count / mdr * 1e-3;
                const char *mname = mode == 0 ? "eyes" : "bands";
                if (csv)
                    printf("%d,%s,%d,%s,%.4f,%.4f,%.2f,%ld,%.4f,%.4f,%.4f\n", mesh.tri_count,
                           ef_isa_name((ef_isa)rast_context_isa(c)), th, mname, mdr / 2, mdr,
                           mtps, pixels / 2, mc, mcc, mx);
                else
                    printf("%7d %-7s %3d %-5s %9.4f %9.4f %8.2f %7ld %9.4f %9.4f %8.4f\n",
                           mesh.tri_count, ef_isa_name((ef_isa)rast_context_isa(c)), th,
                           mname, mdr / 2, mdr, mtps, pixels / 2, mc, mcc, mx);
                fflush(stdout);
                rast_context_destroy(c);
                }
            }
        }
        for (int e = 0; e < 2; e++)
            free(clip[e]);
        free(vn);
        bm_free(&mesh);
    }
    bm_eyes_free(&eyes);
    EF_FREE_ALL(t_draw, t_clear, t_xf, t_cclear);
    if (!pipe || only_threads > 1)
        return 0;

    /* The pipeline's configuration (see the top of the file). */
    uint8_t *junk = cold > 0 ? calloc((size_t)cold << 20, 1) : NULL;
    printf("\n%spipeline configuration: the raster stage of run_eye per eye (1-thread "
           "context per eye, context clear + transforms + draw, normals %s), "
           "%d MB written between stages (--cold), medians of up to 31 passes (bench scene) "
           "and 9 passes over 12 poses (sample model), ms per eye%s\n",
           p, use_n10 ? "packed (ef_n10)" : "as 3 floats (--float-normals)", junk ? cold : 0,
           bench_clock == CLOCK_MONOTONIC ? "" : " (thread CPU time, --cpu-time)");
    pipe_print_head(csv);
    for (int ti = 0; ti < ntl; ti++) {
        bm_mesh mesh;
        if (!bm_arms(&mesh, tris_list[ti]))
            return 1;
        float vp[1][2][16], view[1][2][16];
        for (int e = 0; e < 2; e++) {
            bm_eye_mvp(e, W, H, vp[0][e]);
            for (int k = 0; k < 16; k++)
                view[0][e][k] = k % 5 == 0 ? 1.0f : 0.0f;
        }
        const int vc = mesh.vertex_count, ic = 3 * mesh.tri_count;
        const float *pp = mesh.pos, *np = mesh.nrm;
        const uint32_t *ip = mesh.idx;
        pipe_scene sc = { 1, &vc, &ic, &pp, &np, &ip };
        pipe_rows(csv, "bench", mesh.tri_count, &sc, 1, vp, view, W, H, runs < 31 ? runs : 31,
                  only_isa, junk ? cold : 0, junk);
        bm_free(&mesh);
    }
    if (strcmp(samples, "none") != 0)
        pipe_samples(csv, samples, 12, runs < 9 ? runs : 9, only_isa, junk ? cold : 0, junk);
    free(junk);
    return 0;
}
