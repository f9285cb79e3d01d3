/* fuse_depth_fill.c - a hand depth for the mask pixels the rasterizer did
 * not cover (a mask refined by colour), so that the depth test against the
 * virtual scene (fuse_depth) holds for them too. The rule is stated in
 * fuse_refine.h (fuse_depth_fill) and docs/fuse.md ("Depth of refined
 * pixels"). One scalar implementation: every ISA path of the depth test
 * then sees the same hand depths. */
#include "fuse_refine.h"
#include "../cpu/mask_rows.h"

#include <string.h>

/* Known depth: z in [0, 1) (the depth test's rule, fuse.h); NaN fails. */
static int known(float z) { return z >= 0.0f && z < 1.0f; }

/* 1 when the 8 mask bytes at m are all set and the 8 depths at z all
 * known: nothing to do there (branch-free, one test for the block) */
static int block_done(const uint8_t *m, const float *z)
{
    if (ef_has_zero8(ef_ld8(m))) return 0;
    /* known() on the float's bits: +0 .. the largest float below 1 are
     * 0 .. 0x3F7FFFFF, and -0 (0x80000000) is >= 0 too; every other
     * pattern (1 and above, infinities, NaN, negatives) is not known */
    uint32_t u[8];
    memcpy(u, z, sizeof u);
    uint32_t bad = 0;
    for (int i = 0; i < 8; i++) bad |= (uint32_t)(u[i] >= 0x3F800000u) &
                                            (uint32_t)(u[i] != 0x80000000u);
    return !bad;
}

/* The largest float below 1: the far plane; any scene object is nearer. */
static float far_depth(void)
{
    const uint32_t bits = 0x3F7FFFFFu;
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Pass 1 writes into each unknown mask pixel a code >= 2 (still unknown,
 * so never taken as a source): 2 + index of the source's offset in the
 * (2R+1)^2 window, or 2 + (2R+1)^2 for none. Integers below 2^24 are
 * exact in a float. Pass 2 replaces each code by the source's depth
 * (sources are known pixels: pass 1 never wrote them). */
long fuse_depth_fill(const uint8_t *mask, int mask_stride, float *depth, int depth_stride,
                     int width, int height, int radius, int box[4])
{
    const int R = radius, side = 2 * radius + 1;
    int x0 = width, y0 = height, x1 = 0, y1 = 0;
    long n = 0;
    int x, y;
    if (box) {
        box[0] = box[1] = box[2] = box[3] = 0;
    }
    if (!mask || !depth || width < 1 || height < 1 || width > FUSE_MAX_DIM ||
        height > FUSE_MAX_DIM || mask_stride < width || depth_stride < width ||
        radius < 1 || radius > FUSE_DEPTH_FILL_MAX_RADIUS)
        return -1;
    for (y = 0; y < height; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        float *z = depth + (size_t)y * (size_t)depth_stride;
        for (x = 0; x < width; x++) {
            int r, best = -1;
            long bd2 = 0;
            if (m[x] == 0) {   /* on to the next set byte (8 at a time) */
                x = ef_row_first_set(m, x + 1, width) - 1;
                continue;
            }
            if (x + 8 <= width && block_done(m + x, z + x)) {
                x += 7;
                continue;
            }
            if (known(z[x])) continue;
            /* ring 1 away from the borders: the 4-neighbours (d2 1), then
             * the diagonals (d2 2), each in the ties' order (upper row,
             * then left): the ring search's result, which stops there */
            r = 1;
            if (x > 0 && y > 0 && x + 1 < width && y + 1 < height) {
                const float *u = z - depth_stride, *d = z + depth_stride;
                const int c = R * side + R;
                best = known(u[x])       ? c - side
                       : known(z[x - 1]) ? c - 1
                       : known(z[x + 1]) ? c + 1
                       : known(d[x])     ? c + side
                                         : -1;
                bd2 = 1;
                if (best < 0) {
                    best = known(u[x - 1])   ? c - side - 1
                           : known(u[x + 1]) ? c - side + 1
                           : known(d[x - 1]) ? c + side - 1
                           : known(d[x + 1]) ? c + side + 1
                                             : -1;
                    bd2 = 2;
                }
                if (best < 0) bd2 = 0;
                r = best >= 0 ? R + 1 : 2;
            }
            /* rings of growing Chebyshev radius; a pixel of ring r is at
             * least r away, so stop once the best is nearer than r + 1 */
            for (; r <= R; r++) {
                int dy;
                for (dy = -r; dy <= r; dy++) {
                    const int yy = y + dy, edge = dy == -r || dy == r;
                    int dx;
                    if (yy < 0 || yy >= height) continue;
                    for (dx = -r; dx <= r; dx += edge ? 1 : 2 * r) {
                        const int xx = x + dx;
                        long d2;
                        if (xx < 0 || xx >= width) continue;
                        if (!known(depth[(size_t)yy * (size_t)depth_stride + (size_t)xx]))
                            continue;
                        d2 = (long)dx * dx + (long)dy * dy;
                        /* nearest; ties: the upper row, then the left */
                        if (best < 0 || d2 < bd2 ||
                            (d2 == bd2 && (dy + R) * side + (dx + R) < best)) {
                            bd2 = d2;
                            best = (dy + R) * side + (dx + R);
                        }
                    }
                }
                if (best >= 0 && bd2 < (long)(r + 1) * (r + 1)) break;
            }
            z[x] = 2.0f + (float)(best >= 0 ? best : side * side);
            n++;
            if (x < x0) x0 = x;
            if (x + 1 > x1) x1 = x + 1;
            if (y < y0) y0 = y;
            y1 = y + 1;
        }
    }
    if (n == 0) return 0;
    for (y = y0; y < y1; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        float *z = depth + (size_t)y * (size_t)depth_stride;
        for (x = x0; x < x1; x++) {
            int code, dx, dy;
            if (m[x] == 0) {
                x = ef_row_first_set(m, x + 1, x1) - 1;
                continue;
            }
            if (x + 8 <= x1 && block_done(m + x, z + x)) {
                x += 7;
                continue;
            }
            if (known(z[x])) continue;
            code = (int)(z[x] - 2.0f);
            if (code >= side * side) {
                z[x] = far_depth();
                continue;
            }
            dy = code / side - R;
            dx = code % side - R;
            z[x] = depth[(size_t)(y + dy) * (size_t)depth_stride + (size_t)(x + dx)];
        }
    }
    if (box) {
        box[0] = x0;
        box[1] = y0;
        box[2] = x1;
        box[3] = y1;
    }
    return n;
}
