/* bench_lod.c - what each level of detail of the mask model costs and
 * saves (issue 17, item 4; docs/bench.md "Levels of detail").
 *
 * The sample model (--samples DIR, default build/samples, as bench_raster)
 * gets its level chain (io_lod_build, the defaults of `egofuse run`); it
 * is posed at --poses times evenly over its animation and drawn for both
 * eyes of the STHMD cameras at the crop resolution, as src/pipe run_eye
 * does (one 1-thread rast_context per eye: rast_context_clear, per mesh
 * rast_transform_points + rast_transform_dirs + rast_context_draw with the
 * view-space normals), with the cache made cold between stages (--cold MB,
 * as bench_raster). Configurations: every level fixed, and the rule of
 * pipe_lod.h (pipe_lod_choose on pipe_lod_px_per_m of the eye's clip
 * coordinates) at targets of 0.5, 1, 2 and 4 px. Per configuration, cull
 * none (the pipe's default) and cull back: the median over --runs passes
 * of the stage time per eye and of its draw (the configurations
 * interleaved: each run times one pass of every configuration in turn, so
 * the machine's load falls on all alike), the triangles submitted and
 * scanned per eye, and the mask's IoU and boundary F (1 px) against the
 * full model's mask (level 0, same cull) over all poses and eyes (mean,
 * and the worst IoU). Times are thread CPU time (CLOCK_THREAD_CPUTIME_ID),
 * the build of the chain wall time. Reports, never fails.
 *
 *   bench_lod [--csv] [--runs N] [--poses N] [--samples DIR] [--cold MB]
 *             [--isa ref|sse2|avx2|avx512] [--whole]
 */
#include "../src/cpu/cpu.h"
#include "../src/fuse/fuse_metrics.h"
#include "../src/io/io.h"
#include "../src/io/io_lod.h"
#include "../src/pipe/pipe.h"
#include "../src/pipe/pipe_lod.h"
#include "../src/raster/raster.h"
#include "bench_sample.h"
#include "bench_util.h"
#include "../src/cpu/ef_mem.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Times are the calling thread's CPU time: the machine is shared, and a
 * preempted stage would count other processes' time on the wall clock
 * (cache and memory-bandwidth sharing still count). */
#define CLK CLOCK_THREAD_CPUTIME_ID

typedef struct pose_eye {
    float vp[16], view[16], focal;
} pose_eye;

typedef struct bench {
    int np, nm, W, H;
    float **pos, **nrm;           /* [p * nm + i] */
    pose_eye (*cam)[2];
    const pipe_lod *lod;
    rast_context *ctx[2];
    rast_target tg[2];
    float *clip, *vn;
    uint8_t *junk;
    int cold;
} bench;

static void evict(uint8_t *junk, int mb, int r)
{
    if (!junk || mb <= 0) return;
    uint64_t *q = (uint64_t *)(void *)junk;
    const size_t n = ((size_t)mb << 20) / sizeof *q;
    for (size_t i = 0; i < n; i++) q[i] += (uint64_t)(unsigned)r;
}

/* One eye's raster stage at level `level` (< 0: the rule with target
 * px). Adds the stage and draw times; returns the level drawn (of the
 * last mesh). */
static int stage(bench *b, int p, int e, int level, float target, rast_cull cull,
                 double *t_stage, double *t_draw, rast_stats *st)
{
    double t0 = bench_now_ms(CLK);
    rast_context_clear(b->ctx[e], &b->tg[e]);
    int drawn = 0;
    for (int i = 0; i < b->nm; i++) {
        const kin_mesh *full = &b->lod->level[0].meshes[i];
        const int nv = full->vertex_count;
        rast_transform_points(b->cam[p][e].vp, b->pos[(size_t)p * b->nm + i], nv, b->clip);
        rast_transform_dirs(b->cam[p][e].view, b->nrm[(size_t)p * b->nm + i], nv, b->vn);
        int l = level;
        if (l < 0)
            l = pipe_lod_choose(b->lod, pipe_lod_px_per_m(b->clip, nv, b->cam[p][e].focal),
                                target);
        const kin_mesh *me = &b->lod->level[l].meshes[i];
        double a = bench_now_ms(CLK);
        rast_mesh_desc d = {b->clip, nv, b->vn, 3, me->indices, me->index_count / 3, cull};
        rast_context_draw(b->ctx[e], &b->tg[e], &d, st);
        *t_draw += bench_now_ms(CLK) - a;
        drawn = l;
    }
    *t_stage += bench_now_ms(CLK) - t0;
    return drawn;
}

int main(int argc, char **argv)
{
    int csv = 0, runs = 31, np = 24, cold = 24, only_isa = 0, whole = 0;
    const char *dir = "build/samples";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv")) csv = 1;
        else if (!strcmp(argv[i], "--whole")) whole = 1;
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc) runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--poses") && i + 1 < argc) np = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--cold") && i + 1 < argc) cold = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--isa") && i + 1 < argc) only_isa = (int)ef_isa_parse(argv[++i]);
        else {
            fprintf(stderr, "usage: %s [--csv] [--runs N] [--poses N] [--samples DIR] "
                            "[--cold MB] [--isa NAME] [--whole]\n", argv[0]);
            return 2;
        }
    }
    if (runs < 1 || np < 1 || np > 1000 || cold < 0 || cold > 1024) {
        fprintf(stderr, "bad --runs, --poses or --cold\n");
        return 2;
    }
    const char *pfx = csv ? "# " : "";
    char path[IO_PATH_MAX + 64];
    io_scene sc;
    io_error err;
    kin_model model;
    if (!bench_sample_model(dir, pfx, &sc, &model, path, sizeof path)) return 0;
    pipe_lod lod;
    io_lod_desc ld = {0};
    ld.whole = whole;
    double tb = bench_now_ms(CLOCK_MONOTONIC);
    if (io_lod_build(path, &model, &ld, &lod, &err) != IO_OK) {
        printf("%slevels: skipped (%s)\n", pfx, err.msg);
        kin_model_free(&model);
        return 0;
    }
    tb = bench_now_ms(CLOCK_MONOTONIC) - tb;
    const kin_animation *anim = kin_model_find_anim(&model, sc.animation);
    const int head = kin_model_find_node(&model, sc.head_node[0] ? sc.head_node : "head");
    pipe_pose ps;
    if (head < 0 || pipe_pose_init(&ps, &model) != 0) {
        printf("%ssample model: skipped (no head node)\n", pfx);
        return 0;
    }
    char cpu[128];
    bench_cpu_name(cpu, sizeof cpu);
    printf("%smachine: %s, %ld online cpus; meshoptimizer %d\n", pfx, cpu,
           sysconf(_SC_NPROCESSORS_ONLN), io_lod_version());
    printf("%smodel %s: %d levels built in %.1f ms (%s):", pfx, path, lod.level_count, tb,
           whole ? "whole meshes" : "joint groups, locked borders");
    for (int l = 0; l < lod.level_count; l++)
        printf(" L%d %ld tris, error %.2f mm, edge %.2f mm;", l, lod.level[l].triangles,
               1e3 * (double)lod.level[l].error_m, 1e3 * (double)lod.level[l].edge_m);
    printf("\n");

    const kin_sthmd_desc hmd = kin_sthmd_desc_resolved(NULL);
    const kin_sthmd_geometry geo = kin_sthmd_geometry_of(&hmd);
    bench b;
    memset(&b, 0, sizeof b);
    b.np = np;
    b.nm = model.mesh_count;
    b.W = geo.crop_width;
    b.H = geo.crop_height;
    b.lod = &lod;
    b.cold = cold;
    b.pos = calloc((size_t)np * b.nm, sizeof *b.pos);
    b.nrm = calloc((size_t)np * b.nm, sizeof *b.nrm);
    b.cam = calloc((size_t)np, sizeof *b.cam);
    b.clip = malloc((size_t)ps.max_vertices * 4 * sizeof(float));
    b.vn = malloc((size_t)ps.max_vertices * 3 * sizeof(float));
    b.junk = cold ? malloc((size_t)cold << 20) : NULL;
    if (!b.pos || !b.nrm || !b.cam || !b.clip || !b.vn || (cold && !b.junk)) exit(1);
    if (b.junk) memset(b.junk, 1, (size_t)cold << 20);
    for (int p = 0; p < np; p++) {
        const float t = anim ? anim->duration * (float)p / (float)np : 0.0f;
        pipe_pose_anim(&ps, anim, t);
        for (int i = 0; i < b.nm; i++) {
            size_t n = (size_t)ps.meshes[i].vertex_count * 3;
            b.pos[(size_t)p * b.nm + i] = malloc(n * sizeof(float));
            b.nrm[(size_t)p * b.nm + i] = malloc(n * sizeof(float));
            if (!b.pos[(size_t)p * b.nm + i] || !b.nrm[(size_t)p * b.nm + i]) exit(1);
            memcpy(b.pos[(size_t)p * b.nm + i], ps.pos[i], n * sizeof(float));
            memcpy(b.nrm[(size_t)p * b.nm + i], ps.nrm[i], n * sizeof(float));
        }
        for (int e = 0; e < 2; e++) {
            kin_camera cam = kin_sthmd_camera(&hmd, &ps.world[head], (kin_eye)e);
            memcpy(b.cam[p][e].vp, cam.view_proj.m, sizeof b.cam[p][e].vp);
            memcpy(b.cam[p][e].view, cam.view.m, sizeof b.cam[p][e].view);
            b.cam[p][e].focal = cam.fx > cam.fy ? cam.fx : cam.fy;
        }
    }
    const size_t plane = (size_t)b.W * b.H;
    float *planes[2];
    for (int e = 0; e < 2; e++) {
        planes[e] = malloc(plane * 16 + plane);
        if (!planes[e]) exit(1);
        rast_target t = {b.W, b.H, planes[e], b.W, (uint8_t *)(planes[e] + plane * 4), b.W,
                         planes[e] + plane, 3 * b.W, 3, NULL, 0};
        b.tg[e] = t;
    }
    /* reference masks: level 0 of every pose and eye */
    uint8_t *ref = malloc(plane * (size_t)np * 2);
    double *ts = malloc(sizeof(double) * (size_t)runs * 2 * (PIPE_LOD_MAX + 4));
    if (!ref || !ts) exit(1);
    printf("%s%d poses over '%s', both eyes, %dx%d per eye, cache cold (%d MB), median of %d "
           "runs\n", pfx, np, anim ? anim->name : "rest", b.W, b.H, cold, runs);
    if (csv)
        printf("lod,config,level,target_px,isa,cull,tris_per_eye,scanned_per_eye,"
               "ms_stage_per_eye,ms_draw_per_eye,iou_vs_full,iou_min_vs_full,bf1_vs_full,"
               "level_mean\n");
    else
        printf("%-10s %-6s %-4s %8s %8s %9s %9s %8s %8s %8s %6s\n", "config", "isa", "cull",
               "tris/eye", "scanned", "stage ms", "draw ms", "IoU", "IoU min", "BF1",
               "level");
    static const float targets[4] = {0.5f, 1.0f, 2.0f, 4.0f};
    const int nconf = lod.level_count + 4;
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa) || (only_isa && isa != only_isa)) continue;
        if (!only_isa && isa != (int)ef_cpu_best()) continue; /* the best ISA by default */
        for (int ci = 0; ci < 2; ci++) {
            const rast_cull cull = ci ? RAST_CULL_BACK : RAST_CULL_NONE;
            rast_context_desc cd = {isa, 1};
            for (int e = 0; e < 2; e++)
                if (!(b.ctx[e] = rast_context_create(&cd))) exit(1);
            /* accuracy and counts: one pass per configuration */
            double iou[PIPE_LOD_MAX + 4], iou_min[PIPE_LOD_MAX + 4], bf[PIPE_LOD_MAX + 4],
                lsum[PIPE_LOD_MAX + 4];
            long tris[PIPE_LOD_MAX + 4], scanned[PIPE_LOD_MAX + 4];
            int level[PIPE_LOD_MAX + 4];
            float target[PIPE_LOD_MAX + 4];
            for (int c = 0; c < nconf; c++) {
                level[c] = c < lod.level_count ? c : -1;
                target[c] = level[c] < 0 ? targets[c - lod.level_count] : 0.0f;
                iou[c] = 0, iou_min[c] = 1, bf[c] = 0, lsum[c] = 0, tris[c] = 0, scanned[c] = 0;
                for (int p = 0; p < np; p++)
                    for (int e = 0; e < 2; e++) {
                        double a = 0, d = 0;
                        rast_stats st = {0};
                        int l = stage(&b, p, e, level[c], target[c], cull, &a, &d, &st);
                        lsum[c] += l;
                        for (int i = 0; i < b.nm; i++)
                            tris[c] += lod.level[l].meshes[i].index_count / 3;
                        scanned[c] += st.tris_drawn;
                        uint8_t *r = ref + plane * (size_t)(2 * p + e);
                        if (c == 0) memcpy(r, b.tg[e].mask, plane);
                        fuse_confusion cf;
                        fuse_mask_confusion(b.tg[e].mask, b.W, r, b.W, b.W, b.H, &cf);
                        double u = fuse_confusion_iou(&cf);
                        iou[c] += u;
                        if (u < iou_min[c]) iou_min[c] = u;
                        bf[c] += fuse_boundary_f(b.tg[e].mask, b.W, r, b.W, b.W, b.H, 1.0f, NULL,
                                                 NULL);
                    }
            }
            /* times: the configurations interleaved, one pass each per run,
             * so that the machine's load falls on all of them alike */
            const double n2 = 2.0 * np;
            for (int r = -2; r < runs; r++)
                for (int c = 0; c < nconf; c++) {
                    double t_stage = 0, t_draw = 0;
                    for (int p = 0; p < np; p++) {
                        evict(b.junk, cold, r * np + p);
                        for (int e = 0; e < 2; e++)
                            stage(&b, p, e, level[c], target[c], cull, &t_stage, &t_draw, NULL);
                    }
                    if (r >= 0) {
                        ts[(size_t)c * 2 * runs + r] = t_stage / n2;
                        ts[(size_t)c * 2 * runs + runs + r] = t_draw / n2;
                    }
                }
            for (int c = 0; c < nconf; c++) {
                double ms_stage = bench_median(ts + (size_t)c * 2 * runs, runs);
                double ms_draw = bench_median(ts + (size_t)c * 2 * runs + runs, runs);
                char name[32];
                if (level[c] >= 0) snprintf(name, sizeof name, "L%d", level[c]);
                else snprintf(name, sizeof name, "auto@%gpx", (double)target[c]);
                if (csv)
                    printf("lod,%s,%d,%g,%s,%s,%.0f,%.0f,%.4f,%.4f,%.5f,%.5f,%.5f,%.3f\n", name,
                           level[c], (double)target[c], ef_isa_name((ef_isa)isa),
                           ci ? "back" : "none", (double)tris[c] / n2, (double)scanned[c] / n2,
                           ms_stage, ms_draw, iou[c] / n2, iou_min[c], bf[c] / n2, lsum[c] / n2);
                else
                    printf("%-10s %-6s %-4s %8.0f %8.0f %9.4f %9.4f %8.5f %8.5f %8.5f %6.2f\n",
                           name, ef_isa_name((ef_isa)isa), ci ? "back" : "none",
                           (double)tris[c] / n2, (double)scanned[c] / n2, ms_stage, ms_draw,
                           iou[c] / n2, iou_min[c], bf[c] / n2, lsum[c] / n2);
            }
            fflush(stdout);
            for (int e = 0; e < 2; e++) rast_context_destroy(b.ctx[e]);
        }
    }
    for (int i = 0; i < np * b.nm; i++) {
        free(b.pos[i]);
        free(b.nrm[i]);
    }
    EF_FREE_ALL(b.pos, b.nrm, b.cam, b.clip, b.vn, b.junk, ref, ts);
    for (int e = 0; e < 2; e++) free(planes[e]);
    pipe_pose_free(&ps);
    io_lod_free(&lod);
    kin_model_free(&model);
    return 0;
}
