/* bench_reproj.c - the eye reprojection (pipe_desc.eye_view =
 * PIPE_VIEW_REPROJECT, docs/eyeview.md) against the paper's crop, side by
 * side (issue 18 item 6). Reports, never passes or fails.
 *
 * The demo's samples (build/samples: the arms, the cockpit camera images,
 * the workshop with its depth), K frames spread over the sequence,
 * loaded once; two pipes of the demo's settings (RAST_CULL_BACK, T
 * threads, virtual depth on, opaque V promised), one per method. Each run
 * renders every preloaded frame with both methods, alternating which goes
 * first, so that the machine's load falls on both alike. Per stereo frame:
 *   wall  pipe_frame's wall time (CLOCK_MONOTONIC);
 *   cpu   the process's CPU time over the call (CLOCK_PROCESS_CPUTIME_ID:
 *         both threads; less sensitive to other processes on a shared
 *         machine than the wall clock, but it counts the waits' spinning
 *         none: the pipe's threads sleep on a condition variable).
 * Medians over runs x frames, the difference and the ratio; the share of
 * eye pixels sampled / filled / outside from the last run.
 * --only crop|reproject|none runs one method (none: only the loading), for
 * instruction counts (valgrind --tool=cachegrind --cache-sim=no): the
 * differences of three runs are the methods' instructions.
 * --lod auto|N draws both at a level of detail (io_lod_build's chain of
 * the model, pipe_set_lod: auto the level of pipe_lod.h's rule for 2 px,
 * N that level; the default none): the eye's and the camera's draws
 * alike (issue 18 item 6, option 3).
 * Usage: build/bench/bench_reproj [--samples DIR] [--runs N] [--frames K]
 *                                 [--threads T] [--csv FILE] [--only M]
 *                                 [--lod auto|N] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../src/io/io.h"
#include "../src/io/io_lod.h"
#include "../src/pipe/pipe_lod.h"
#include "../src/pipe/pipe.h"
#include "bench_util.h"

typedef struct frame_set {
    io_image cam[2], virt[2], depth[2], out[2];
} frame_set;

static int load(const char *path, int ch, io_type t, io_image *img)
{
    io_error err;
    if (io_image_load(path, t, ch, img, &err) != IO_OK) {
        fprintf(stderr, "bench_reproj: %s\n", err.msg);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    const char *samples = "build/samples", *csv = NULL;
    int runs = 15, nframes = 8, threads = 2, only = -1; /* --only: 0 crop, 1 reproject, 2 none */
    int lod_level = 0;                                   /* --lod: 0 none, PIPE_LOD_AUTO, a level */
    for (int i = 1; i < argc; i++) {
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(argv[i], "--samples") && v) samples = v, i++;
        else if (!strcmp(argv[i], "--runs") && v) runs = atoi(v), i++;
        else if (!strcmp(argv[i], "--frames") && v) nframes = atoi(v), i++;
        else if (!strcmp(argv[i], "--threads") && v) threads = atoi(v), i++;
        else if (!strcmp(argv[i], "--csv") && v) csv = v, i++;
        else if (!strcmp(argv[i], "--only") && v && (!strcmp(v, "crop") || !strcmp(v, "reproject") ||
                                                     !strcmp(v, "none")))
            only = !strcmp(v, "crop") ? 0 : !strcmp(v, "reproject") ? 1 : 2, i++;
        else if (!strcmp(argv[i], "--lod") && v && (!strcmp(v, "auto") || atoi(v) > 0))
            lod_level = !strcmp(v, "auto") ? PIPE_LOD_AUTO : atoi(v), i++;
        else {
            fprintf(stderr, "usage: %s [--samples DIR] [--runs N] [--frames K] [--threads T] "
                            "[--csv FILE] [--only crop|reproject|none] [--lod auto|N]\n", argv[0]);
            return 2;
        }
    }
    if (runs < 1 || nframes < 1 || nframes > 64 || threads < 1 || threads > 2) {
        fprintf(stderr, "bench_reproj: --runs >= 1, --frames 1..64, --threads 1|2\n");
        return 2;
    }
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/scene.txt", samples);
    io_scene sc;
    io_error err;
    if (io_scene_load(path, &sc, &err) != IO_OK) {
        fprintf(stderr, "bench_reproj: %s (make samples first)\n", err.msg);
        return 1;
    }
    kin_model model;
    io_scene_frame_path(&sc, sc.model, 0, path, sizeof path);
    if (io_gltf_load(path, &model, &err) != IO_OK) {
        fprintf(stderr, "bench_reproj: %s\n", err.msg);
        return 1;
    }
    int head = sc.head_node[0] ? kin_model_find_node(&model, sc.head_node) : -1;
    const kin_animation *anim = model.anim_count ? &model.anims[0] : NULL;
    for (int i = 0; i < model.anim_count && sc.animation[0]; i++)
        if (!strcmp(model.anims[i].name, sc.animation)) anim = &model.anims[i];
    if (nframes > sc.frames) nframes = sc.frames;
    frame_set *fs = calloc((size_t)nframes, sizeof *fs);
    int *fno = calloc((size_t)nframes, sizeof *fno);
    if (!fs || !fno) return 2;
    for (int k = 0; k < nframes; k++) {
        fno[k] = (int)((long)sc.frames * (2 * k + 1) / (2 * nframes));
        for (int e = 0; e < 2; e++) {
            io_scene_frame_path(&sc, sc.camera[e], fno[k], path, sizeof path);
            if (load(path, 4, IO_U8, &fs[k].cam[e])) return 1;
            io_scene_frame_path(&sc, sc.virt[e], fno[k], path, sizeof path);
            if (load(path, 4, IO_U8, &fs[k].virt[e])) return 1;
            if (sc.virt_depth[e][0]) {
                io_scene_frame_path(&sc, sc.virt_depth[e], fno[k], path, sizeof path);
                if (load(path, 1, IO_F32, &fs[k].depth[e])) return 1;
            }
            const io_image *v = &fs[k].virt[e];
            if (io_image_alloc(&fs[k].out[e], v->width, v->height, 4, IO_U8, &err) != IO_OK)
                return 2;
        }
    }
    pipe_lod lod;
    memset(&lod, 0, sizeof lod);
    if (lod_level) {
        io_scene_frame_path(&sc, sc.model, 0, path, sizeof path);
        if (io_lod_build(path, &model, NULL, &lod, &err) != IO_OK) {
            fprintf(stderr, "bench_reproj: %s\n", err.msg);
            return 1;
        }
    }
    pipe_ctx *p[2];
    for (int m = 0; m < 2; m++) {
        pipe_desc d;
        memset(&d, 0, sizeof d);
        d.threads = threads;
        d.cull = RAST_CULL_BACK;
        d.eye_view = m ? PIPE_VIEW_REPROJECT : PIPE_VIEW_CROP;
        d.soft_edge = 1;    /* each view's default in render and run */
        if (sc.hmd[0]) kin_sthmd_preset(sc.hmd, &d.hmd);
        p[m] = pipe_create(&d, &model);
        if (!p[m]) {
            fprintf(stderr, "bench_reproj: cannot create the pipe\n");
            return 1;
        }
        if (lod_level && pipe_set_lod(p[m], &lod, lod_level, 2.0f) != 0) {
            fprintf(stderr, "bench_reproj: the levels of detail do not fit the pipe's model\n");
            return 1;
        }
    }
    long lod_sum[2] = {0, 0}, lod_n[2] = {0, 0};
    const int n = runs * nframes;
    double *wall[2], *cpu[2];
    for (int m = 0; m < 2; m++) {
        wall[m] = bench_xmalloc(sizeof(double) * (size_t)n, "bench_reproj");
        cpu[m] = bench_xmalloc(sizeof(double) * (size_t)n, "bench_reproj");
    }
    long px[3] = {0, 0, 0};
    pipe_frame_stats st;
    char why[256];
    /* one warm-up pass of each */
    for (int r = -1, i = 0; r < runs; r++)
        for (int k = 0; k < nframes; k++) {
            for (int j = 0; j < 2; j++) {
                const int m = (r + k + j) & 1; /* alternate which goes first */
                if (only >= 0 && m != only) continue; /* instruction counts of one method */
                pipe_frame_in in;
                memset(&in, 0, sizeof in);
                in.anim = anim;
                in.time = sc.anim_start + (float)fno[k] / sc.fps;
                in.head_node = head;
                in.lighting.light = io_scene_lighting(&sc);
                in.virt_opaque = 1;
                for (int e = 0; e < 2; e++) {
                    const io_image *c = &fs[k].cam[e], *v = &fs[k].virt[e], *o = &fs[k].out[e];
                    in.camera[e] = (fuse_image){c->data, c->width, c->height, (int)c->stride};
                    in.virt[e] = (fuse_image){v->data, v->width, v->height, (int)v->stride};
                    in.out[e] = (fuse_image){o->data, o->width, o->height, (int)o->stride};
                    if (fs[k].depth[e].data) {
                        in.virt_depth[e] = fs[k].depth[e].data;
                        in.virt_depth_stride[e] = (int)(fs[k].depth[e].stride / sizeof(float));
                    }
                }
                double w0 = bench_now_ms(CLOCK_MONOTONIC), c0 = bench_now_ms(CLOCK_PROCESS_CPUTIME_ID);
                if (pipe_frame(p[m], &in, &st, why, sizeof why) != PIPE_OK) {
                    fprintf(stderr, "bench_reproj: frame %d: %s\n", fno[k], why);
                    return 1;
                }
                double c1 = bench_now_ms(CLOCK_PROCESS_CPUTIME_ID), w1 = bench_now_ms(CLOCK_MONOTONIC);
                if (r < 0) continue;
                for (int e = 0; e < 2; e++) lod_sum[m] += st.lod_level[e], lod_n[m]++;
                wall[m][i + 0] = w1 - w0;
                cpu[m][i + 0] = c1 - c0;
                if (m == 1 && r == runs - 1)
                    for (int e = 0; e < 2; e++) {
                        px[0] += st.view_sampled[e];
                        px[1] += st.view_filled[e];
                        px[2] += st.view_outside[e];
                    }
            }
            if (r >= 0) i++;
        }
    if (lod_level)
        printf("bench_reproj: levels of detail %s: %d levels, mean level drawn: crop %.2f, "
               "reproject %.2f\n", lod_level == PIPE_LOD_AUTO ? "auto@2px" : "fixed",
               lod.level_count, lod_n[0] ? (double)lod_sum[0] / (double)lod_n[0] : 0.0,
               lod_n[1] ? (double)lod_sum[1] / (double)lod_n[1] : 0.0);
    if (only >= 0) {
        printf("bench_reproj: --only %s: %d stereo frames (+%d warm-up)\n",
               only == 0 ? "crop" : only == 1 ? "reproject" : "none", only < 2 ? n : 0,
               only < 2 ? nframes : 0);
        return 0;
    }
    double mw[2], mc[2];
    for (int m = 0; m < 2; m++) {
        mw[m] = bench_median(wall[m], n);
        mc[m] = bench_median(cpu[m], n);
    }
    char cpu_name[256];
    bench_cpu_name(cpu_name, sizeof cpu_name);
    double la[3] = {0, 0, 0};
    FILE *lf = fopen("/proc/loadavg", "r");
    if (lf) {
        if (fscanf(lf, "%lf %lf %lf", &la[0], &la[1], &la[2]) != 3) la[0] = la[1] = la[2] = 0;
        fclose(lf);
    }
    const long tot = px[0] + px[1] + px[2];
    printf("bench_reproj: %s, %s, %d thread%s; %d frames of %s x %d runs (medians); load %.2f "
           "%.2f %.2f\n", cpu_name, ef_isa_name((ef_isa)pipe_isa(p[0])), threads,
           threads == 1 ? "" : "s", nframes, samples, runs, la[0], la[1], la[2]);
    printf("  %-10s %12s %12s\n", "method", "wall ms", "cpu ms");
    printf("  %-10s %12.3f %12.3f\n", "crop", mw[0], mc[0]);
    printf("  %-10s %12.3f %12.3f\n", "reproject", mw[1], mc[1]);
    printf("  %-10s %+12.3f %+12.3f   (per stereo frame)\n", "difference", mw[1] - mw[0],
           mc[1] - mc[0]);
    printf("  %-10s %12.3f %12.3f\n", "ratio", mw[1] / mw[0], mc[1] / mc[0]);
    if (tot)
        printf("  eye pixels of the model (last run, both eyes): %.1f%% sampled, %.1f%% filled, "
               "%.1f%% outside the camera's view\n", 100.0 * px[0] / tot, 100.0 * px[1] / tot,
               100.0 * px[2] / tot);
    if (csv) {
        FILE *f = fopen(csv, "a");
        if (f) {
            fprintf(f, "reproj,%d,%s,%.4f,%.4f,%.4f,%.4f,%.2f\n", threads,
                    ef_isa_name((ef_isa)pipe_isa(p[0])), mw[0], mw[1], mc[0], mc[1], la[0]);
            fclose(f);
        }
    }
    for (int m = 0; m < 2; m++) {
        pipe_destroy(p[m]);
        free(wall[m]);
        free(cpu[m]);
    }
    io_lod_free(&lod);
    for (int k = 0; k < nframes; k++)
        for (int e = 0; e < 2; e++) {
            io_image_free(&fs[k].cam[e]);
            io_image_free(&fs[k].virt[e]);
            io_image_free(&fs[k].depth[e]);
            io_image_free(&fs[k].out[e]);
        }
    free(fs);
    free(fno);
    kin_model_free(&model);
    return 0;
}
