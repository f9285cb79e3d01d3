/* pipe_soft.c - soft silhouettes from a binary mask (pipe_soft.h). */
#include "pipe_soft.h"
#include "../cpu/mask_rows.h"

#include <string.h>

#define ONES8 0x0101010101010101ull

/* 0x01 in each byte of v that is not zero, 0x00 in each zero byte: the
 * low seven bits plus 0x7f carry into bit 7 unless they are all clear
 * (never beyond it: 0x7f + 0x7f = 0xfe), and or-ing v adds bit 7 itself. */
static inline uint64_t nz8(uint64_t v)
{
    const uint64_t low7 = 0x7f7f7f7f7f7f7f7full;
    return ((((v & low7) + low7) | v) >> 7) & ONES8;
}

/* The 8 pixels of one row at x, each with its 3x3 window inside the image
 * (x >= 1, x + 9 <= w, rows u above and d below): out = (M n + 4) / 9 for
 * all 8, the counts n (0..9) summed one per byte, no carry between bytes. */
static void soft8(const uint8_t *u, const uint8_t *m, const uint8_t *d, uint8_t *o, int x,
                  uint64_t a)
{
    const uint64_t n = nz8(ef_ld8(u + x - 1)) + nz8(ef_ld8(u + x)) + nz8(ef_ld8(u + x + 1)) +
                       nz8(ef_ld8(m + x - 1)) + nz8(a) + nz8(ef_ld8(m + x + 1)) +
                       nz8(ef_ld8(d + x - 1)) + nz8(ef_ld8(d + x)) + nz8(ef_ld8(d + x + 1));
    const uint64_t set = nz8(a);
    if (a == set * 0xff) {
        /* M 0 or 255 (the binary mask's): (255 n + 4) / 9 = 28 n +
         * (n + 1) / 3 for n = 0..9, the third as (n + 1) 11 >> 5; each
         * byte's product and sum stays below 256 (28 * 9 + 3 = 255), and
         * M 0 masks its byte to 0 */
        uint64_t v = n * 28u + ((((n + ONES8) * 11u) >> 5) & 0x0707070707070707ull);
        v &= a;
        memcpy(o + x, &v, 8);
        return;
    }
    uint8_t mb[8], nb[8];
    memcpy(mb, &a, 8);
    memcpy(nb, &n, 8);
    for (int i = 0; i < 8; i++) o[x + i] = (uint8_t)(((unsigned)mb[i] * nb[i] + 4u) / 9u);
}

/* One pixel, its window clipped by the image (beyond it counts as set). */
static uint8_t soft1(const uint8_t *u, const uint8_t *m, const uint8_t *d, int x, int w)
{
    if (m[x] == 0) return 0;
    int n = 0;
    for (int dx = -1; dx <= 1; dx++) {
        const int xx = x + dx;
        if (xx < 0 || xx >= w) {
            n += 3;
            continue;
        }
        n += (u ? u[xx] != 0 : 1) + (m[xx] != 0) + (d ? d[xx] != 0 : 1);
    }
    return (uint8_t)(((unsigned)m[x] * (unsigned)n + 4u) / 9u);
}

/* The first set byte of r[x0 .. x1 - 1] (x1 if none), 32 bytes a step
 * over the clear run: the margins left and right of the hand and the rows
 * without it are most of the mask. */
static int first_set(const uint8_t *r, int x0, int x1)
{
    while (x0 + 32 <= x1 &&
           (ef_ld8(r + x0) | ef_ld8(r + x0 + 8) | ef_ld8(r + x0 + 16) | ef_ld8(r + x0 + 24)) == 0)
        x0 += 32;
    return ef_row_first_set(r, x0, x1);
}

/* One past the last set byte of r[x0 .. x1 - 1] (x0 if none), likewise. */
static int last_set(const uint8_t *r, int x0, int x1)
{
    while (x1 - 32 >= x0 &&
           (ef_ld8(r + x1 - 8) | ef_ld8(r + x1 - 16) | ef_ld8(r + x1 - 24) | ef_ld8(r + x1 - 32)) == 0)
        x1 -= 32;
    return ef_row_last_set(r, x0, x1);
}

/* Row m's out over [xa, x1), where xa is its first set byte at or after the
 * box's left end, xb one past its last before x1; returns where it stopped
 * (at or past xb, at most x1): the bytes from there to x1 are 0. */
static int soft_row(const uint8_t *u, const uint8_t *m, const uint8_t *d, uint8_t *o, int w,
                    int xa, int xb, int x1)
{
    int x = xa;
    if (u && d) {   /* the 8-pixel steps whose windows lie inside the image */
        const int gmax = w - 9 < x1 - 8 ? w - 9 : x1 - 8;
        const int last = xb - 1 < gmax ? xb - 1 : gmax;   /* of a step's start */
        if (x == 0 && x < xb) {
            o[0] = soft1(u, m, d, 0, w);
            x = 1;
        }
        for (; x <= last; x += 8) {
            const uint64_t a = ef_ld8(m + x);
            if (a == 0)
                memset(o + x, 0, 8);
            else if ((ef_ld8(u + x - 1) & ef_ld8(u + x + 1) & ef_ld8(m + x - 1) &
                      ef_ld8(m + x + 1) & ef_ld8(d + x - 1) & ef_ld8(d + x + 1)) == ~(uint64_t)0)
                memcpy(o + x, m + x, 8);   /* the hand's inside: 255 with every neighbour */
            else
                soft8(u, m, d, o, x, a);
        }
        /* a span up to the image's right side (the arm entering there):
         * the last step placed at gmax, over bytes already written (the
         * same values), leaves at most the last column one by one */
        if (x < xb && gmax >= xa && gmax >= 1 && gmax + 8 > x) {
            soft8(u, m, d, o, gmax, ef_ld8(m + gmax));
            x = gmax + 8;
        }
    }
    for (; x < xb; x++) o[x] = soft1(u, m, d, x, w);   /* at the image's sides */
    return x;
}

void pipe__soft_edge(const uint8_t *mask, uint8_t *out, int w, int h, const int box[4])
{
    const int x0 = box ? box[0] : 0, y0 = box ? box[1] : 0;
    const int x1 = box ? box[2] : w, y1 = box ? box[3] : h;
    for (int y = y0; y < y1; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)w;
        uint8_t *o = out + (size_t)y * (size_t)w;
        /* only the row's own set span needs its windows: out is 0 where M
         * is, so the box's bytes beyond the span are cleared at once */
        const int xa = first_set(m, x0, x1);
        const int xb = xa < x1 ? last_set(m, xa, x1) : xa;
        if (xa > x0) memset(o + x0, 0, (size_t)(xa - x0));
        const int x = soft_row(y > 0 ? m - w : NULL, m, y + 1 < h ? m + w : NULL, o, w, xa, xb, x1);
        if (x1 > x) memset(o + x, 0, (size_t)(x1 - x));
    }
}

void pipe__soft_edge_boxed(const uint8_t *mask, uint8_t *out, int w, int h, int held[4])
{
    /* one pass over the rows: each row's set span (its margins scanned
     * once, where finding the box first and then the spans inside it
     * scanned them twice) is written, and what the held box has of the row
     * outside the span cleared; the new box grows from the spans */
    int b[4] = {w, h, 0, 0};
    for (int y = 0; y < h; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)w;
        uint8_t *o = out + (size_t)y * (size_t)w;
        const int in_held = y >= held[1] && y < held[3] && held[0] < held[2];
        const int xa = first_set(m, 0, w);
        if (xa == w) {
            if (in_held) memset(o + held[0], 0, (size_t)(held[2] - held[0]));
            continue;
        }
        const int xb = last_set(m, xa, w);
        if (xa < b[0]) b[0] = xa;
        if (xb > b[2]) b[2] = xb;
        if (y < b[1]) b[1] = y;
        b[3] = y + 1;
        if (in_held && held[0] < xa)
            memset(o + held[0], 0, (size_t)((held[2] < xa ? held[2] : xa) - held[0]));
        const int x = soft_row(y > 0 ? m - w : NULL, m, y + 1 < h ? m + w : NULL, o, w, xa, xb, w);
        if (in_held && held[2] > x) {
            const int r = held[0] > x ? held[0] : x;
            memset(o + r, 0, (size_t)(held[2] - r));
        }
    }
    if (b[2] == 0) b[0] = b[1] = b[3] = 0;
    memcpy(held, b, sizeof b);
}
