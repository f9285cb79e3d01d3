/* bench_fuse.c - ms per stereo frame of the fuse stages (lighting at
 * 640x400, resampling + composite into 1194x746 of 1280x800, and the whole
 * fuse_context_frame), per ISA, 1 and 2 threads, for a typical hand (25%
 * of the view) and a worst case (70%). In the same run: memcpy of the
 * composite's bytes (V -> out, both eyes: the memory floor) and pixman
 * compositing the same camera image with an a8 mask, bilinear-scaled into
 * the same viewport (no lighting), as ratios. Medians over many runs.
 * Reports, never passes or fails.
 *
 *   bench_fuse [--csv] [--runs N]
 *
 * pixman is used when its header is found: the Makefile builds this file
 * without it; with it:
 *   gcc -std=c11 -O2 -ffp-contract=off -D_GNU_SOURCE $(pkg-config --cflags pixman-1) \
 *       bench/bench_fuse.c build/libegofuse.a $(pkg-config --libs pixman-1) -lm -lpthread */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../src/cpu/cpu.h"
#include "../src/fuse/fuse.h"

#if defined(__has_include)
#if __has_include(<pixman.h>)
#include <pixman.h>
#define HAVE_PIXMAN 1
#endif
#endif

enum { CW = 640, CH = 400, W = 1280, H = 800, VX = 43, VY = 27, VW = 1194, VHH = 746 };

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

static long sysconf_cpus(void) { return sysconf(_SC_NPROCESSORS_ONLN); }

static int cmp_d(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static uint64_t rng = 0x1234567u;
static uint32_t rnd(void)
{
    uint64_t z = (rng += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (uint32_t)(z ^ (z >> 31));
}

typedef struct eye_buf {
    uint8_t *P, *M, *Q, *V, *out;
    float *N;
} eye_buf;

/* Two elliptical "hands" side by side covering about `cover` of the image,
 * with a soft edge of ~3 pixels. */
static double make_eye(eye_buf *e, double cover)
{
    const double a = 0.25 * CW * sqrt(cover * 8 / 3.14159265 / 1.6) * 1.0,
                 b = a * 1.6 * CH / CW * 1.0;
    long on = 0;
    int x, y, i;
    e->P = malloc(CW * CH * 4);
    e->M = malloc(CW * CH);
    e->Q = malloc(CW * CH * 4);
    e->N = malloc(sizeof(float) * CW * CH * 3);
    e->V = malloc(W * H * 4);
    e->out = malloc(W * H * 4);
    if (!e->P || !e->M || !e->Q || !e->N || !e->V || !e->out) exit(2);
    for (i = 0; i < CW * CH * 4; i++) e->P[i] = (uint8_t)rnd();
    for (i = 0; i < W * H * 4; i++) e->V[i] = (uint8_t)rnd();
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
            on += e->M[k] != 0;
        }
    return (double)on / (CW * CH);
}

static void free_eye(eye_buf *e)
{
    free(e->P); free(e->M); free(e->Q); free(e->N); free(e->V); free(e->out);
}

typedef struct result { double light, comp, frame; } result;

static void run_stages(fuse_context *ctx, eye_buf e[2], int runs, result *r)
{
    const fuse_lighting L = fuse_lighting_default();
    const fuse_intrinsics K = { 532.0f, 532.0f, CW / 2.0f, CH / 2.0f };
    double *tl = malloc(sizeof(double) * runs), *tc = malloc(sizeof(double) * runs),
           *tf = malloc(sizeof(double) * runs);
    fuse_eye eyes[2];
    int k, i;
    for (i = 0; i < 2; i++)
        eyes[i] = (fuse_eye){ &L, &K, { e[i].P, CW, CH, 4 * CW }, e[i].M, CW, e[i].N, 3 * CW,
                              { e[i].Q, CW, CH, 4 * CW }, NULL, { e[i].V, W, H, 4 * W },
                              VX, VY, VW, VHH, { e[i].out, W, H, 4 * W } };
    for (k = -2; k < runs; k++) {   /* 2 warm-up runs */
        double t0 = now_ms(), t1, t2, t3;
        for (i = 0; i < 2; i++)
            fuse_context_light(ctx, &L, &K, &eyes[i].P, e[i].M, CW, e[i].N, 3 * CW, &eyes[i].Q);
        t1 = now_ms();
        for (i = 0; i < 2; i++)
            fuse_context_composite(ctx, &eyes[i].Q, &eyes[i].V, VX, VY, VW, VHH, &eyes[i].out);
        t2 = now_ms();
        if (fuse_context_frame(ctx, eyes, 2) != FUSE_OK) exit(3);
        t3 = now_ms();
        if (k >= 0) {
            tl[k] = t1 - t0;
            tc[k] = t2 - t1;
            tf[k] = t3 - t2;
        }
    }
    r->light = median(tl, runs);
    r->comp = median(tc, runs);
    r->frame = median(tf, runs);
    free(tl); free(tc); free(tf);
}

static double bench_memcpy(eye_buf e[2], int runs)
{
    double *t = malloc(sizeof(double) * runs), m;
    int k, i;
    for (k = -2; k < runs; k++) {
        double t0 = now_ms();
        for (i = 0; i < 2; i++) memcpy(e[i].out, e[i].V, (size_t)W * H * 4);
        if (k >= 0) t[k] = now_ms() - t0;
    }
    m = median(t, runs);
    free(t);
    return m;
}

#ifdef HAVE_PIXMAN
/* OVER of the camera image (x8r8g8b8, 640x400) through the a8 mask, both
 * scaled bilinearly into the viewport of the 1280x800 a8r8g8b8 output:
 * the composite without lighting. */
static double bench_pixman(eye_buf e[2], int runs)
{
    pixman_image_t *src[2], *msk[2], *dst[2];
    pixman_transform_t tr;
    double *t = malloc(sizeof(double) * runs), m;
    int k, i;
    pixman_transform_init_scale(&tr, pixman_double_to_fixed((double)CW / VW),
                                pixman_double_to_fixed((double)CH / VHH));
    for (i = 0; i < 2; i++) {
        src[i] = pixman_image_create_bits(PIXMAN_x8r8g8b8, CW, CH, (uint32_t *)(void *)e[i].P, 4 * CW);
        msk[i] = pixman_image_create_bits(PIXMAN_a8, CW, CH, (uint32_t *)(void *)e[i].M,
                                          (CW + 3) & ~3);
        dst[i] = pixman_image_create_bits(PIXMAN_a8r8g8b8, W, H, (uint32_t *)(void *)e[i].out, 4 * W);
        pixman_image_set_transform(src[i], &tr);
        pixman_image_set_transform(msk[i], &tr);
        pixman_image_set_filter(src[i], PIXMAN_FILTER_BILINEAR, NULL, 0);
        pixman_image_set_filter(msk[i], PIXMAN_FILTER_BILINEAR, NULL, 0);
        pixman_image_set_repeat(src[i], PIXMAN_REPEAT_PAD);
        pixman_image_set_repeat(msk[i], PIXMAN_REPEAT_PAD);
    }
    for (k = -2; k < runs; k++) {
        double t0 = now_ms();
        for (i = 0; i < 2; i++)
            pixman_image_composite32(PIXMAN_OP_OVER, src[i], msk[i], dst[i], 0, 0, 0, 0,
                                     VX, VY, VW, VHH);
        if (k >= 0) t[k] = now_ms() - t0;
    }
    m = median(t, runs);
    for (i = 0; i < 2; i++) {
        pixman_image_unref(src[i]);
        pixman_image_unref(msk[i]);
        pixman_image_unref(dst[i]);
    }
    free(t);
    return m;
}
#endif

static void machine(char *buf, size_t n)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[512];
    snprintf(buf, n, "unknown");
    if (!f) return;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "model name", 10)) {
            char *c = strchr(line, ':');
            if (c) {
                c += 2;
                c[strcspn(c, "\n")] = 0;
                snprintf(buf, n, "%s", c);
            }
            break;
        }
    fclose(f);
}

int main(int argc, char **argv)
{
    static const ef_isa isas[] = { EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512 };
    static const double covers[2] = { 0.25, 0.70 };
    static const char *cover_name[2] = { "typical", "worst" };
    int csv = 0, runs = 51, a, c, i, t;
    char cpu[256];
    for (a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--csv")) csv = 1;
        else if (!strcmp(argv[a], "--runs") && a + 1 < argc) runs = atoi(argv[++a]);
        else {
            fprintf(stderr, "usage: %s [--csv] [--runs N]\n", argv[0]);
            return 2;
        }
    }
    if (runs < 3) runs = 3;
    machine(cpu, sizeof cpu);
    printf("%smachine: %s, %ld cpus\n", csv ? "# " : "", cpu, sysconf_cpus());
    printf("%scompiler: %s\n", csv ? "# " : "",
#ifdef __VERSION__
           __VERSION__
#else
           "unknown"
#endif
    );
    printf("%sisa: best %s, EGOFUSE_ISA %s; pixman %s; medians of %d runs\n", csv ? "# " : "",
           ef_isa_name(ef_cpu_best()), getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "unset",
#ifdef HAVE_PIXMAN
           pixman_version_string(),
#else
           "not built in",
#endif
           runs);
    if (csv)
        printf("case,coverage,isa,threads,light_ms,composite_ms,light_plus_composite_ms,frame_ms,"
               "memcpy_ms,pixman_ms,frame_over_memcpy,frame_over_pixman\n");
    for (c = 0; c < 2; c++) {
        eye_buf e[2];
        double cov = 0, mc, px = NAN;
        for (i = 0; i < 2; i++) cov += make_eye(&e[i], covers[c]) / 2;
        mc = bench_memcpy(e, runs);
#ifdef HAVE_PIXMAN
        px = bench_pixman(e, runs);
#endif
        if (!csv)
            printf("\n%s hand: %.1f%% of the camera pixels have M > 0; memcpy floor "
                   "(V -> out, 2 x %.1f MB) %.3f ms; pixman over + a8 mask, bilinear %.3f ms\n"
                   "  %-7s %3s %9s %9s %9s %9s %8s %8s\n", cover_name[c], 100 * cov,
                   W * H * 4 / 1e6, mc, px, "isa", "thr", "light", "comp", "l+c", "frame",
                   "/memcpy", "/pixman");
        for (i = 0; i < 4; i++) {
            if (!ef_cpu_has(isas[i]) || ef_isa_choose(isas[i]) != isas[i]) {
                if (!csv) printf("  %-7s SKIP: not available\n", ef_isa_name(isas[i]));
                continue;
            }
            for (t = 1; t <= 2; t++) {
                fuse_context_desc d = { isas[i], t };
                fuse_context *ctx = fuse_context_create(&d);
                result r;
                const int n = isas[i] == EF_ISA_REF ? (runs < 7 ? runs : 7) : runs;
                if (!ctx) return 2;
                run_stages(ctx, e, n, &r);
                if (csv)
                    printf("%s,%.4f,%s,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.3f,%.3f\n", cover_name[c],
                           cov, ef_isa_name(isas[i]), t, r.light, r.comp, r.light + r.comp, r.frame,
                           mc, px, r.frame / mc, r.frame / px);
                else
                    printf("  %-7s %3d %9.3f %9.3f %9.3f %9.3f %8.2f %8.2f\n", ef_isa_name(isas[i]),
                           t, r.light, r.comp, r.light + r.comp, r.frame, r.frame / mc, r.frame / px);
                fuse_context_destroy(ctx);
            }
        }
        for (i = 0; i < 2; i++) free_eye(&e[i]);
    }
    if (!csv)
        printf("\nms per stereo frame (two eyes). light, comp: the stages called one by one;\n"
               "frame: fuse_context_frame (light + composite, one eye per thread with 2 threads).\n"
               "/memcpy, /pixman: frame time over the memcpy floor and over pixman.\n");
    return 0;
}
