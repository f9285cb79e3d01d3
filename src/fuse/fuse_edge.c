/* fuse_edge.c - the edge fade (fuse_edge.h). */
#include "fuse_edge.h"

#include <stddef.h>
#include <string.h>

float fuse_edge_weight(float sx, float sy, int w, int h, int k, unsigned sides)
{
    float d = 1e30f, t;
    if (w < 1 || h < 1) return 0.0f;
    if (!(sx == sx) || !(sy == sy)) return 0.0f;
    if (k < 1 || (sides & FUSE_EDGE_ALL) == 0) return 1.0f;
    if (sides & FUSE_EDGE_LEFT) d = sx < d ? sx : d;
    if (sides & FUSE_EDGE_RIGHT) d = (float)w - sx < d ? (float)w - sx : d;
    if (sides & FUSE_EDGE_TOP) d = sy < d ? sy : d;
    if (sides & FUSE_EDGE_BOTTOM) d = (float)h - sy < d ? (float)h - sy : d;
    if (d <= 0.0f) return 0.0f;
    t = d / (float)k;
    return t < 1.0f ? t : 1.0f;
}

/* q' = (q t + k) / (2k) for the four bytes of a pixel. The division is a
 * multiplication by m = floor((2^32 - 1) / 2k) + 1 and a shift by 32:
 * exact for every numerator below 2^32 / 2k (here below 2^15, 2k <= 128),
 * since the product's error n (m 2k - 2^32) / 2^32 / 2k < n / 2^32 stays
 * below 1 / 2k. A zero pixel (most of the strips) stays zero. */
static void fade_px(uint8_t *p, unsigned t, unsigned k, uint64_t m)
{
    uint32_t v;
    memcpy(&v, p, 4);
    if (v == 0) return;
    p[0] = (uint8_t)(((uint64_t)(p[0] * t + k) * m) >> 32);
    p[1] = (uint8_t)(((uint64_t)(p[1] * t + k) * m) >> 32);
    p[2] = (uint8_t)(((uint64_t)(p[2] * t + k) * m) >> 32);
    p[3] = (uint8_t)(((uint64_t)(p[3] * t + k) * m) >> 32);
}

/* pixels from the nearest faded side of column x, at most cap */
static int col_dist(int x, int w, int cap, unsigned sides)
{
    int i = cap;
    if ((sides & FUSE_EDGE_LEFT) && x < i) i = x;
    if ((sides & FUSE_EDGE_RIGHT) && w - 1 - x < i) i = w - 1 - x;
    return i;
}

void fuse__edge_fade_cols(uint8_t *row, int y, int w, int h, int k, unsigned sides, int c0, int c1)
{
    int iy = k, x, xl, xr;   /* iy: pixels from the nearest faded side, rows only */
    if (k < 1 || k > FUSE_EDGE_FADE_MAX || (sides & FUSE_EDGE_ALL) == 0 || row == NULL || w < 1 ||
        y < 0 || y >= h)
        return;
    if (c0 < 0) c0 = 0;
    if (c1 > w) c1 = w;
    const uint64_t m = 0xFFFFFFFFu / (2u * (unsigned)k) + 1u;
    if ((sides & FUSE_EDGE_TOP) && y < iy) iy = y;
    if ((sides & FUSE_EDGE_BOTTOM) && h - 1 - y < iy) iy = h - 1 - y;
    /* the left strip [0, xl), the middle [xl, xr), the right strip [xr, w)
     * (each pixel once), each cut to [c0, c1); the middle is faded only in
     * a top or bottom strip, where its pixels are all iy from the nearest
     * side */
    xl = (sides & FUSE_EDGE_LEFT) ? (k < w ? k : w) : 0;
    xr = (sides & FUSE_EDGE_RIGHT) ? (w - k > xl ? w - k : xl) : w;
    for (x = c0; x < xl && x < c1; x++) {
        const int i = col_dist(x, w, iy, sides);
        if (i < k) fade_px(row + 4 * (size_t)x, 2u * (unsigned)i + 1u, (unsigned)k, m);
    }
    if (iy < k)
        for (x = xl > c0 ? xl : c0; x < xr && x < c1; x++)
            fade_px(row + 4 * (size_t)x, 2u * (unsigned)iy + 1u, (unsigned)k, m);
    for (x = xr > c0 ? xr : c0; x < c1; x++) {
        const int i = col_dist(x, w, iy, sides);
        if (i < k) fade_px(row + 4 * (size_t)x, 2u * (unsigned)i + 1u, (unsigned)k, m);
    }
}

void fuse_edge_fade_row(uint8_t *row, int y, int w, int h, int k, unsigned sides)
{
    fuse__edge_fade_cols(row, y, w, h, k, sides, 0, w);
}

fuse_result fuse_edge_fade(fuse_image *Q, int k, unsigned sides)
{
    int y;
    if (Q == NULL || Q->pixels == NULL || Q->width < 1 || Q->height < 1 ||
        Q->width > FUSE_MAX_DIM || Q->height > FUSE_MAX_DIM || Q->stride < 4 * Q->width ||
        k < 0 || k > FUSE_EDGE_FADE_MAX || (sides & ~FUSE_EDGE_ALL) != 0)
        return FUSE_ERR_ARGS;
    if (k == 0 || sides == 0) return FUSE_OK;
    for (y = 0; y < Q->height; y++) {
        const int strip = ((sides & FUSE_EDGE_TOP) && y < k) ||
                          ((sides & FUSE_EDGE_BOTTOM) && Q->height - 1 - y < k);
        if (!strip && (sides & (FUSE_EDGE_LEFT | FUSE_EDGE_RIGHT)) == 0) continue;
        fuse_edge_fade_row(Q->pixels + (size_t)y * (size_t)Q->stride, y, Q->width, Q->height, k,
                           sides);
    }
    return FUSE_OK;
}
