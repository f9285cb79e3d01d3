/* bench_refine.c - ms per eye of the edge-band colour refinement of the
 * kinematic mask (fuse_refine_mask, fuse_refine_mask_global): the scalar
 * reference (whole-image passes, the definition of the bytes) against the
 * band-only path per ISA, in one run. Reports, never passes or fails.
 *
 *   bench_refine [--csv] [--runs N] [--band PX] [--isa ref|sse2|avx2|avx512]
 *                [--samples DIR --masks DIR [--count N]]
 *
 * Cases (640x400 camera crop per eye, like the pipeline's):
 *   synthetic  two arms from the bottom edge with palms and fingers (about
 *              20% of the image, the samples' mean), the camera image skin
 *              coloured with shading and noise over a textured cockpit with
 *              a skin-coloured object; the kinematic mask 2-3 px off and
 *              with too short fingers (what tracking noise and the model's
 *              shape do)
 *   frames     with --samples DIR (build/gen_samples output) and --masks
 *              DIR (`egofuse render --masks --pose tracking` output): the
 *              left camera image NNNN (rows 40..439) with mask_left_NNNN,
 *              N = 0 .. count-1
 * Modes: local (fuse_refine_mask) and global (fuse_refine_mask_global,
 * weight 0.5, a colour model of the same bits learned from the mask: what
 * `egofuse render --refine` runs).
 * Every time is the median over --runs runs of one call (one eye); each
 * run times the reference and every path back to back, and the speed-up is
 * the median of the per-run ratios (robust on a shared machine). The
 * bytes of every path are checked against the reference once. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../src/cpu/cpu.h"
#include "../src/fuse/fuse_refine.h"
#include "../src/io/io.h"
#include "bench_util.h"

enum { CW = 640, CH = 400, CROP_Y0 = 40, MAX_CASES = 64 };

static double now_ms(void) { return bench_now_ms(CLOCK_MONOTONIC); }

static uint64_t rng = 0x7e57ab1eu;
static uint32_t rnd(void) { return bench_rand(&rng); }

static void *xmalloc(size_t n) { return bench_xmalloc(n, "bench_refine"); }

typedef struct ecase {
    char name[64];
    uint8_t *P;   /* RGBA, CW x CH */
    uint8_t *M;   /* kinematic mask */
    double cover;
} ecase;

/* ---- the synthetic hands ------------------------------------------------ */

/* Distance of (x, y) to the segment a-b. */
static double seg_dist(double x, double y, double ax, double ay, double bx, double by)
{
    double vx = bx - ax, vy = by - ay, wx = x - ax, wy = y - ay;
    double t = (vx * wx + vy * wy) / (vx * vx + vy * vy);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double dx = wx - t * vx, dy = wy - t * vy;
    return sqrt(dx * dx + dy * dy);
}

/* Arm with hand at wrist (wx, wy), forearm to the bottom edge; grow: px
 * added to every radius, finger: px added to the finger lengths. */
static int in_arm(double x, double y, double wx, double wy, double side, double grow,
                  double finger)
{
    if (seg_dist(x, y, wx + side * 60, CH + 60, wx, wy) <= 34 + grow) return 1;
    double px = wx, py = wy - 48;
    double dx = (x - px) / (40 + grow), dy = (y - py) / (50 + grow);
    if (dx * dx + dy * dy <= 1) return 1;
    for (int f = 0; f < 4; f++) {
        double fx = px - 27 + 18 * f, fy = py - 40, len = (f == 1 || f == 2 ? 66 : 55) + finger;
        double ang = (f - 1.5) * 0.12;
        if (seg_dist(x, y, fx, fy, fx + len * sin(ang), fy - len * cos(ang)) <= 8.5 + grow)
            return 1;
    }
    return seg_dist(x, y, px - side * 38, py + 10, px - side * 85, py - 25) <= 10 + grow;
}

static void make_synthetic(ecase *c)
{
    snprintf(c->name, sizeof c->name, "synthetic");
    c->P = xmalloc((size_t)CW * CH * 4);
    c->M = xmalloc((size_t)CW * CH);
    long on = 0;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            const double X = x + 0.5, Y = y + 0.5;
            int hand = in_arm(X, Y, 200, 250, -1, 0, 0) || in_arm(X, Y, 450, 230, 1, 0, 0);
            int km = in_arm(X - 3, Y + 2, 200, 250, -1, -1.5, -7) ||
                     in_arm(X + 2, Y - 2, 450, 230, 1, 1.5, -7);
            uint8_t *p = c->P + ((size_t)y * CW + (size_t)x) * 4;
            int n = (int)(rnd() % 17) - 8, r, g, b;
            if (hand) {
                double shade = 0.8 + 0.25 * sin(X * 0.05) * cos(Y * 0.04);
                r = (int)(205 * shade) + n;
                g = (int)(145 * shade) + n;
                b = (int)(118 * shade) + n;
            } else if (x > 520 && y < 120) {   /* a skin-coloured object */
                r = 190 + n; g = 140 + n; b = 105 + n;
            } else {
                int stripe = ((x / 23) + (y / 17)) & 1;
                r = (stripe ? 70 : 110) + (x >> 4) + n;
                g = (stripe ? 80 : 100) + (y >> 4) + n;
                b = (stripe ? 95 : 90) + n;
            }
            p[0] = bench_clamp_u8(r);
            p[1] = bench_clamp_u8(g);
            p[2] = bench_clamp_u8(b);
            p[3] = 255;
            c->M[(size_t)y * CW + (size_t)x] = km ? 255 : 0;
            on += km;
        }
    c->cover = (double)on / (CW * CH);
}

/* ---- sample frames -------------------------------------------------------- */

static int load_frame(ecase *c, const char *samples, const char *masks, int i)
{
    char path[1024];
    io_image cam, m;
    io_error err;
    snprintf(path, sizeof path, "%s/cam/left_%04d.png", samples, i);
    if (io_image_load(path, IO_U8, 4, &cam, &err) != IO_OK) {
        fprintf(stderr, "bench_refine: %s\n", err.msg);
        return 0;
    }
    snprintf(path, sizeof path, "%s/mask_left_%04d.png", masks, i);
    if (io_image_load(path, IO_U8, 1, &m, &err) != IO_OK) {
        fprintf(stderr, "bench_refine: %s\n", err.msg);
        io_image_free(&cam);
        return 0;
    }
    if (cam.width != CW || cam.height < CROP_Y0 + CH || m.width != CW || m.height != CH) {
        fprintf(stderr, "bench_refine: frame %d: unexpected sizes\n", i);
        io_image_free(&cam);
        io_image_free(&m);
        return 0;
    }
    snprintf(c->name, sizeof c->name, "frame_%04d", i);
    c->P = xmalloc((size_t)CW * CH * 4);
    c->M = xmalloc((size_t)CW * CH);
    long on = 0;
    for (int y = 0; y < CH; y++) {
        memcpy(c->P + (size_t)y * CW * 4, (uint8_t *)cam.data + (size_t)(y + CROP_Y0) * cam.stride,
               (size_t)CW * 4);
        memcpy(c->M + (size_t)y * CW, (uint8_t *)m.data + (size_t)y * m.stride, CW);
        for (int x = 0; x < CW; x++) on += c->M[(size_t)y * CW + (size_t)x] >= 128;
    }
    c->cover = (double)on / (CW * CH);
    io_image_free(&cam);
    io_image_free(&m);
    return 1;
}

/* ---- the measurement ------------------------------------------------------ */

static void usage(const char *argv0)
{
    fprintf(stderr,
            "usage: %s [--csv] [--runs N] [--band PX] [--isa ref|sse2|avx2|avx512]\n"
            "          [--samples DIR --masks DIR [--count N]]\n"
            "ms per eye (640x400) of the mask refinement: the scalar reference against\n"
            "the band-only path per ISA, medians over N runs (default 51), speed-ups\n"
            "as medians of per-run ratios. --samples: gen_samples output; --masks:\n"
            "`egofuse render --masks` output of the same scene (mask_left_NNNN.png);\n"
            "without them a synthetic two-arm case.\n",
            argv0);
}

int main(int argc, char **argv)
{
    int csv = 0, runs = 51, band = 16, count = 8;
    ef_isa only = EF_ISA_DEFAULT;
    const char *samples = NULL, *masks = NULL;
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--csv")) csv = 1;
        else if (!strcmp(argv[a], "--runs") && a + 1 < argc) runs = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--band") && a + 1 < argc) band = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--count") && a + 1 < argc) count = atoi(argv[++a]);
        else if (!strcmp(argv[a], "--samples") && a + 1 < argc) samples = argv[++a];
        else if (!strcmp(argv[a], "--masks") && a + 1 < argc) masks = argv[++a];
        else if (!strcmp(argv[a], "--isa") && a + 1 < argc) {
            only = ef_isa_parse(argv[++a]);
            if (only == EF_ISA_DEFAULT) { usage(argv[0]); return 1; }
        } else {
            usage(argv[0]);
            return !strcmp(argv[a], "--help") || !strcmp(argv[a], "-h") ? 0 : 1;
        }
    }
    if (runs < 1) runs = 1;
    if (count < 1) count = 1;
    if (count > MAX_CASES) count = MAX_CASES;
    if ((samples == NULL) != (masks == NULL)) { usage(argv[0]); return 1; }

    ecase cases[MAX_CASES];
    int nc = 0;
    if (samples) {
        for (int i = 0; i < count; i++)
            if (load_frame(&cases[nc], samples, masks, i)) nc++;
        if (nc == 0) return 1;
    } else {
        make_synthetic(&cases[nc++]);
    }

    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = band;
    const size_t ss = fuse_refine_scratch_size(&rp, CW, CH);
    if (ss == 0) { usage(argv[0]); return 1; }
    void *scratch = aligned_alloc(64, (ss + 63) & ~(size_t)63);
    uint8_t *ref_out = xmalloc((size_t)CW * CH), *out = xmalloc((size_t)CW * CH);
    const int gbits = rp.bits, gbins = 1 << (3 * gbits);
    float *gllr = xmalloc(sizeof(float) * (size_t)gbins);
    size_t gs = fuse_colour_model_scratch_size(gbits);
    void *gscr = xmalloc(gs);

    ef_isa paths[EF_ISA_COUNT];
    int np = 0;
    for (int i = EF_ISA_SSE2; i < EF_ISA_COUNT; i++) {
        if (only != EF_ISA_DEFAULT && only != EF_ISA_REF && i != (int)only) continue;
        if (!ef_cpu_has((ef_isa)i) || (int)fuse_refine_isa((ef_isa)i) != i) continue;
        paths[np++] = (ef_isa)i;
    }

    char cpu[256];
    bench_cpu_name(cpu, sizeof cpu);
    printf("%smachine: %s, %ld cpus; 1 thread; %d runs; band %d, margin %d, bits %d, "
           "smooth %d; scratch %.1f MB per eye\n",
           csv ? "# " : "", cpu, sysconf(_SC_NPROCESSORS_ONLN), runs, rp.band, rp.margin,
           rp.bits, rp.smooth, (double)ss / 1e6);
    if (csv) printf("case,mode,cover,band_pixels,path,ms_per_eye,ms_stereo,speedup_vs_ref\n");
    else
        printf("%-11s %-6s %6s %8s  %-7s %10s %10s %9s\n", "case", "mode", "cover", "band_px",
               "path", "ms/eye", "ms/stereo", "x ref");

    double sum_ref[2] = { 0, 0 }, sum_p[2][EF_ISA_COUNT];
    memset(sum_p, 0, sizeof sum_p);
    double *t_ref = xmalloc(sizeof(double) * (size_t)runs);
    double *t_p = xmalloc(sizeof(double) * (size_t)runs * EF_ISA_COUNT);
    double *ratio = xmalloc(sizeof(double) * (size_t)runs);
    for (int c = 0; c < nc; c++) {
        fuse_image P = { cases[c].P, CW, CH, 4 * CW };
        fuse_colour_model g = { gbits, 0, 0, gllr };
        fuse_colour_model_learn(&g, &P, cases[c].M, CW, 12, 2, 4.0f, 64, gscr, gs);
        for (int mode = 0; mode < 2; mode++) {
            const fuse_colour_model *gm = mode ? &g : NULL;
            fuse_refine_stats st;
            fuse_refine_mask_isa(&rp, gm, 0.5f, &P, cases[c].M, CW, ref_out, CW, scratch, ss,
                                 &st, EF_ISA_REF);
            for (int k = 0; k < np; k++) {
                fuse_refine_mask_isa(&rp, gm, 0.5f, &P, cases[c].M, CW, out, CW, scratch, ss,
                                     NULL, paths[k]);
                if (memcmp(out, ref_out, (size_t)CW * CH) != 0)
                    printf("%s%s %s: BYTES DIFFER from the reference\n", csv ? "# " : "",
                           cases[c].name, ef_isa_name(paths[k]));
            }
            for (int r = 0; r < runs; r++) {
                double t0 = now_ms();
                fuse_refine_mask_isa(&rp, gm, 0.5f, &P, cases[c].M, CW, out, CW, scratch, ss,
                                     NULL, EF_ISA_REF);
                t_ref[r] = now_ms() - t0;
                for (int k = 0; k < np; k++) {
                    t0 = now_ms();
                    fuse_refine_mask_isa(&rp, gm, 0.5f, &P, cases[c].M, CW, out, CW, scratch,
                                         ss, NULL, paths[k]);
                    t_p[(size_t)k * runs + r] = now_ms() - t0;
                }
            }
            const char *mname = mode ? "global" : "local";
            for (int k = -1; k < np; k++) {
                double *t = k < 0 ? t_ref : t_p + (size_t)k * runs;
                double sp = 1.0;
                if (k >= 0) {
                    for (int r = 0; r < runs; r++) ratio[r] = t_ref[r] / t[r];
                    sp = bench_median(ratio, runs);
                }
                double *tc = xmalloc(sizeof(double) * (size_t)runs);
                memcpy(tc, t, sizeof(double) * (size_t)runs);
                double ms = bench_median(tc, runs);
                free(tc);
                const char *pn = k < 0 ? "ref" : ef_isa_name(paths[k]);
                if (k < 0) sum_ref[mode] += ms;
                else sum_p[mode][k] += ms;
                if (csv)
                    printf("%s,%s,%.4f,%ld,%s,%.4f,%.4f,%.2f\n", cases[c].name, mname,
                           cases[c].cover, st.band_pixels, pn, ms, 2 * ms, sp);
                else
                    printf("%-11s %-6s %6.3f %8ld  %-7s %10.4f %10.4f %9.2f\n", cases[c].name,
                           mname, cases[c].cover, st.band_pixels, pn, ms, 2 * ms, sp);
            }
        }
    }
    if (nc > 1 && !csv) {
        printf("mean over %d frames (ms per stereo frame = 2 eyes):\n", nc);
        for (int mode = 0; mode < 2; mode++) {
            printf("  %-6s ref %.3f", mode ? "global" : "local", 2 * sum_ref[mode] / nc);
            for (int k = 0; k < np; k++)
                printf(", %s %.3f", ef_isa_name(paths[k]), 2 * sum_p[mode][k] / nc);
            printf("\n");
        }
    }
    for (int c = 0; c < nc; c++) {
        free(cases[c].P);
        free(cases[c].M);
    }
    free(t_ref); free(t_p); free(ratio);
    free(scratch); free(ref_out); free(out); free(gllr); free(gscr);
    return 0;
}
