/* mask_rows.h - finding the set bytes of a mask row 8 bytes at a time.
 *
 * WHAT IT DOES
 *   Scalar helpers shared by the rooms that skip the empty parts of a mask
 *   row (the depth fill, the refined mask's normal fill, the anti-aliased
 *   coverage, the fit's colour checks): an unaligned 8-byte load, whether
 *   8 bytes hold a zero, the first and one past the last non-zero byte of
 *   a range, the box of a mask's non-zero bytes. Plain C, the same answer
 *   on every ISA and compiler.
 *
 * WHAT IT DOES NOT
 *   No SIMD (the kernels' vector layer is simd.h), no state.
 *
 * USAGE
 *   int x0 = ef_row_first_set(r, 0, w);      // w if the row is empty
 *   int x1 = ef_row_last_set(r, x0, w);      // one past the last set
 *   int box[4]; ef_mask_box(m, w, h, box);   // x0, y0, x1, y1
 */
#ifndef EGOFUSE_MASK_ROWS_H
#define EGOFUSE_MASK_ROWS_H

#include <stdint.h>
#include <string.h>

/* The 8 bytes at p (any alignment), in memory order. */
static inline uint64_t ef_ld8(const uint8_t *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

/* 1 when one of the 8 bytes of v is zero (exact: a borrow can only run
 * on from a zero byte). */
static inline int ef_has_zero8(uint64_t v)
{
    return ((v - 0x0101010101010101ull) & ~v & 0x8080808080808080ull) != 0;
}

/* The first non-zero byte of r[x0 .. x1 - 1]; x1 if none. */
static inline int ef_row_first_set(const uint8_t *r, int x0, int x1)
{
    while (x0 + 8 <= x1 && ef_ld8(r + x0) == 0) x0 += 8;
    while (x0 < x1 && r[x0] == 0) x0++;
    return x0;
}

/* One past the last non-zero byte of r[x0 .. x1 - 1]; x0 if none. */
static inline int ef_row_last_set(const uint8_t *r, int x0, int x1)
{
    while (x1 - 8 >= x0 && ef_ld8(r + x1 - 8) == 0) x1 -= 8;
    while (x1 > x0 && r[x1 - 1] == 0) x1--;
    return x1;
}

/* The box (x0, y0, x1, y1; ends exclusive) of the non-zero bytes of the
 * w x h mask m (stride w), found from each row's two ends; {0, 0, 0, 0}
 * when there is none. */
static inline void ef_mask_box(const uint8_t *m, int w, int h, int b[4])
{
    b[0] = w;
    b[1] = h;
    b[2] = b[3] = 0;
    for (int y = 0; y < h; y++) {
        const uint8_t *r = m + (size_t)y * (size_t)w;
        const int x0 = ef_row_first_set(r, 0, w);
        if (x0 == w) continue;
        const int x1 = ef_row_last_set(r, x0, w);
        if (x0 < b[0]) b[0] = x0;
        if (x1 > b[2]) b[2] = x1;
        if (y < b[1]) b[1] = y;
        b[3] = y + 1;
    }
    if (b[2] == 0) b[0] = b[1] = b[3] = 0;
}

#endif
