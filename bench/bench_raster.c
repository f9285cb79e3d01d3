/* bench_raster.c - rasterizer speed: both eyes of the two-arm scene of
 * bench_mesh.h at 640x400, depth + coverage + normals (3 attributes), at
 * about 2k, 10k and 40k triangles, per ISA the CPU runs, with 1 and 2
 * threads (one rast_context each). Reports medians over many runs of:
 * ms per eye and for both eyes (draw only; clear and vertex transform
 * reported apart), and triangles per second. Reports, never fails.
 *
 *   bench_raster [--csv] [--runs N] [--tris N,N,...] [--size WxH]
 *                [--isa ref|sse2|avx2|avx512] [--threads 1|2]
 *
 * The same scene through Mesa llvmpipe, with the ratio, is
 * bench/llvmpipe/llvmpipe_raster (built separately: it needs EGL/GLES). */
#include "../src/cpu/cpu.h"
#include "../src/raster/raster.h"
#include "bench_mesh.h"
#include "bench_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int main(int argc, char **argv)
{
    int csv = 0, runs = 301, W = 640, H = 400;
    int tris_list[8] = { 2000, 10000, 40000 }, ntl = 3;
    int only_isa = 0, only_threads = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--csv"))
            csv = 1;
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
                            "[--isa NAME] [--threads N]\n",
                    argv[0]);
            return 2;
        }
    }
    if (runs < 1 || W < 1 || H < 1 || W > RAST_MAX_DIM || H > RAST_MAX_DIM) {
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

    float *depth = malloc((size_t)W * H * 2 * sizeof(float));
    uint8_t *mask = malloc((size_t)W * H * 2);
    float *nrm = malloc((size_t)W * H * 2 * 3 * sizeof(float));
    double *t_draw = malloc((size_t)runs * sizeof(double));
    double *t_clear = malloc((size_t)runs * sizeof(double));
    double *t_xf = malloc((size_t)runs * sizeof(double));
    double *t_cclear = malloc((size_t)runs * sizeof(double));
    if (!depth || !mask || !nrm || !t_draw || !t_clear || !t_xf || !t_cclear)
        return 1;
    rast_target tg[2];
    for (int e = 0; e < 2; e++) {
        rast_target t = { W, H, depth + (size_t)e * W * H, W, mask + (size_t)e * W * H, W,
                          nrm + (size_t)e * W * H * 3, 3 * W, 3 };
        tg[e] = t;
    }

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
    free(depth);
    free(mask);
    free(nrm);
    free(t_draw);
    free(t_clear);
    free(t_xf);
    free(t_cclear);
    return 0;
}
