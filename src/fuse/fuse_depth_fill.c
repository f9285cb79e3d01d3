/* fuse_depth_fill.c - a hand depth for the mask pixels the rasterizer did
 * not cover (a mask refined by colour), so that the depth test against the
 * virtual scene (fuse_depth) holds for them too. The rule is stated in
 * fuse_refine.h (fuse_depth_fill) and docs/fuse.md ("Depth of refined
 * pixels"). One scalar implementation: every ISA path of the depth test
 * then sees the same hand depths. */
#include "fuse_refine.h"
#include "../cpu/mask_rows.h"

#include <limits.h>
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

/* The nearest known depth of one column, looked up lazily row after row
 * (pass 1's rows only grow, so each direction reads a pixel of the column
 * at most once; the codes pass 1 writes are unknown as the depths they
 * replace, so they change no answer). up_row: the last known row found
 * at or above up_scan (the last row looked at; INT_MIN / 2: none);
 * dn_row: the first known row found at or below the row of the last
 * query, dn_scan the last row looked at (dn_row INT_MAX: none up to it).
 * The states are a cache, FILL_COLS of them on the stack, column x in slot
 * x % FILL_COLS (col: the column it holds, -1: none): a column that finds
 * its slot taken starts afresh, which only costs its first look-ups again
 * (no allocation; images up to FILL_COLS wide never share a slot). */
typedef struct {
    int col, up_row, up_scan, dn_row, dn_scan;
} fill_col;

enum { FILL_NONE = -1, FILL_COLS = 1024 };

/* column x's state, fresh if its slot held another column */
static fill_col *col_state(fill_col *cols, int x)
{
    fill_col *c = &cols[x % FILL_COLS];
    if (c->col != x) *c = (fill_col){x, INT_MIN / 2, INT_MIN / 2, INT_MAX, -1};
    return c;
}

/* the distance from row y to the nearest known depth of column x at or
 * above it, at most R; FILL_NONE: none */
static int col_up(fill_col *c, const float *depth, size_t stride, int x, int y, int R)
{
    int r = c->up_scan + 1 > y - R ? c->up_scan + 1 : y - R;
    if (r < 0) r = 0;
    for (; r <= y; r++)
        if (known(depth[(size_t)r * stride + (size_t)x])) c->up_row = r;
    c->up_scan = y;
    return c->up_row >= y - R ? y - c->up_row : FILL_NONE;
}

/* the same at or below row y (rows 0 .. h - 1) */
static int col_down(fill_col *c, const float *depth, size_t stride, int x, int y, int R, int h)
{
    if (c->dn_row == INT_MAX || c->dn_row < y) {
        /* none found yet, or the one found is above y (dn_scan is then
         * that row): look on from the row after the last looked at */
        const int last = y + R < h - 1 ? y + R : h - 1;
        int r = c->dn_scan + 1 > y ? c->dn_scan + 1 : y;
        c->dn_row = INT_MAX;
        for (; r <= last; r++)
            if (known(depth[(size_t)r * stride + (size_t)x])) {
                c->dn_row = r;
                break;
            }
        c->dn_scan = r <= last ? r : (last > c->dn_scan ? last : c->dn_scan);
    }
    return c->dn_row != INT_MAX && c->dn_row <= y + R ? c->dn_row - y : FILL_NONE;
}

/* The source of the unknown pixel (x, y), as an index into the (2R+1)^2
 * window (dy + R) * side + dx + R, or -1 for none: over the columns of the
 * window from the pixel's own outwards, each column's nearest known depth
 * (the upper one of two as near), the smallest squared distance, ties to
 * the smaller index (the upper row, then the left column); a column dx
 * away is at least dx^2 away, so the search stops past the best. Exactly
 * the nearest pixel of the square with that tie rule: a column's other
 * known pixels are farther than its nearest. */
static int fill_source(fill_col *cols, const float *depth, size_t stride, int x, int y,
                       int R, int w, int h)
{
    const int side = 2 * R + 1;
    long bd2 = 0;
    int best = -1, dx;
    for (dx = 0; dx <= R; dx++) {
        int k;
        if (best >= 0 && (long)dx * dx > bd2) break;
        for (k = 0; k < (dx ? 2 : 1); k++) {
            const int xx = k ? x + dx : x - dx;
            int u, d, dy, code;
            long d2;
            if (xx < 0 || xx >= w) continue;
            fill_col *c = col_state(cols, xx);
            u = col_up(c, depth, stride, xx, y, R);
            d = col_down(c, depth, stride, xx, y, R, h);
            if (u == FILL_NONE && d == FILL_NONE) continue;
            dy = u != FILL_NONE && (d == FILL_NONE || u <= d) ? -u : d;
            d2 = (long)(xx - x) * (xx - x) + (long)dy * dy;
            code = (dy + R) * side + (xx - x + R);
            if (best < 0 || d2 < bd2 || (d2 == bd2 && code < best)) {
                bd2 = d2;
                best = code;
            }
        }
    }
    return best;
}

/* The source of (x, y) when a known depth is among its 8 neighbours (and
 * the pixel not on the border): the 4-neighbours (d2 1), then the
 * diagonals (d2 2), each in the ties' order (the upper row, then the
 * left); -1 otherwise. What fill_source gives there, without its column
 * look-ups. */
static int fill_ring1(const float *z, size_t stride, int x, int y, int w, int h, int R)
{
    const int side = 2 * R + 1, c = R * side + R;
    if (x == 0 || y == 0 || x + 1 == w || y + 1 == h) return -1;
    const float *u = z - stride, *d = z + stride;
    return known(u[x])       ? c - side
           : known(z[x - 1]) ? c - 1
           : known(z[x + 1]) ? c + 1
           : known(d[x])     ? c + side
           : known(u[x - 1]) ? c - side - 1
           : known(u[x + 1]) ? c - side + 1
           : known(d[x - 1]) ? c + side - 1
           : known(d[x + 1]) ? c + side + 1
                             : -1;
}

/* Pass 1 writes into each unknown mask pixel a code >= 2 (still unknown,
 * so never taken as a source): 2 + index of the source's offset in the
 * (2R+1)^2 window, or 2 + (2R+1)^2 for none. Integers below 2^24 are
 * exact in a float. Pass 2 replaces each code by the source's depth
 * (sources are known pixels: pass 1 never wrote them). Pass 1 finds a
 * source among the 8 neighbours (fill_ring1) or else by columns
 * (fill_source, with the columns' cached state). */
long fuse_depth_fill(const uint8_t *mask, int mask_stride, float *depth, int depth_stride,
                     int width, int height, int radius, int box[4])
{
    const int R = radius, side = 2 * radius + 1;
    int x0 = width, y0 = height, x1 = 0, y1 = 0;
    fill_col cols[FILL_COLS];
    long n = 0;
    int x, y;
    if (box) {
        box[0] = box[1] = box[2] = box[3] = 0;
    }
    if (!mask || !depth || width < 1 || height < 1 || width > FUSE_MAX_DIM ||
        height > FUSE_MAX_DIM || mask_stride < width || depth_stride < width ||
        radius < 1 || radius > FUSE_DEPTH_FILL_MAX_RADIUS)
        return -1;
    for (x = 0; x < FILL_COLS; x++) cols[x].col = -1;
    for (y = 0; y < height; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        float *z = depth + (size_t)y * (size_t)depth_stride;
        for (x = 0; x < width; x++) {
            int best;
            if (m[x] == 0) {   /* on to the next set byte (8 at a time) */
                x = ef_row_first_set(m, x + 1, width) - 1;
                continue;
            }
            if (x + 8 <= width && block_done(m + x, z + x)) {
                x += 7;
                continue;
            }
            if (known(z[x])) continue;
            best = fill_ring1(z, (size_t)depth_stride, x, y, width, height, R);
            if (best < 0)
                best = fill_source(cols, depth, (size_t)depth_stride, x, y, R, width, height);
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
