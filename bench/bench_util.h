/* bench_util.h - small helpers shared by the benchmark programs. */
#ifndef EGOFUSE_BENCH_UTIL_H
#define EGOFUSE_BENCH_UTIL_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

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
