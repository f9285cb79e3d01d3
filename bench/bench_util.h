/* bench_util.h - small helpers shared by the benchmark programs. */
#ifndef EGOFUSE_BENCH_UTIL_H
#define EGOFUSE_BENCH_UTIL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* Milliseconds on clock clk (CLOCK_MONOTONIC: the wall clock;
 * CLOCK_THREAD_CPUTIME_ID: the calling thread's CPU time). */
static inline double bench_now_ms(clockid_t clk)
{
    struct timespec t;
    clock_gettime(clk, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

static inline int bench_cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The median of v[0..n-1], n >= 1 (sorts v). */
static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* splitmix64 on *state: the benchmarks' seeded pseudo-random numbers. */
static inline uint32_t bench_rand(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (uint32_t)(z ^ (z >> 31));
}

/* malloc that exits (status 2, "who: out of memory") when it fails. */
static inline void *bench_xmalloc(size_t n, const char *who)
{
    void *p = malloc(n);
    if (p == NULL) {
        fprintf(stderr, "%s: out of memory\n", who);
        exit(2);
    }
    return p;
}

/* The CPU's model name from /proc/cpuinfo, or "unknown". */
static inline void bench_cpu_name(char *buf, size_t n)
{
    snprintf(buf, n, "unknown");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f) return;
    char line[512];
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

static inline uint8_t bench_clamp_u8(int v) { return (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v); }

/* RGBA8 -> YUYV (BT.601 limited range, the inverse of fuse's conversion;
 * U and V are the pair's mean): what a V4L2 camera delivers. */
static inline void bench_rgba_to_yuyv(const uint8_t *rgba, int w, int h, size_t stride,
                                      uint8_t *out)
{
    for (int y = 0; y < h; y++) {
        const uint8_t *s = rgba + (size_t)y * stride;
        uint8_t *d = out + (size_t)y * 2 * (size_t)w;
        for (int x = 0; x + 1 < w; x += 2) {
            int yy[2], uu = 0, vv = 0;
            for (int k = 0; k < 2; k++) {
                const int r = s[4 * (x + k)], g = s[4 * (x + k) + 1], b = s[4 * (x + k) + 2];
                yy[k] = 16 + ((66 * r + 129 * g + 25 * b + 128) >> 8);
                uu += (-38 * r - 74 * g + 112 * b + 128) >> 8;
                vv += (112 * r - 94 * g - 18 * b + 128) >> 8;
            }
            d[2 * x + 0] = bench_clamp_u8(yy[0]);
            d[2 * x + 1] = bench_clamp_u8(128 + (uu >> 1));
            d[2 * x + 2] = bench_clamp_u8(yy[1]);
            d[2 * x + 3] = bench_clamp_u8(128 + (vv >> 1));
        }
    }
}

#endif
