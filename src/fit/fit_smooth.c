/* The refined mask's 3x3 closing then opening (fit_smooth.h), on a bit
 * plane: the mask packed one bit per pixel (bit j of word i of a row is
 * pixel 64 i + j), each dilation / erosion separable: a 3-tap OR / AND
 * along the row (the neighbours by shifting in the next word's bit),
 * then along the column, 64 pixels at a time. Bits beyond the width
 * hold the pad the next row pass needs (0 before a dilation, 1 before an
 * erosion). Only the rows that can change (the set rows and 2 around
 * them; a zero row 2+ from set rows stays zero under all four steps)
 * and the 64-px blocks around set pixels are processed and written back. */
#include "fit_smooth.h"

#include <string.h>

static int words(int width) { return (width + 63) / 64; }

size_t pipe_fit_smooth_scratch_size(int width, int height)
{
    if (width < 1 || height < 1 || width > (1 << 16) || height > (1 << 16)) return 0;
    /* two bit planes and the unpacking table */
    return 2 * (size_t)words(width) * (size_t)height * sizeof(uint64_t) + 256 * sizeof(uint64_t);
}

/* rows [y0, y1) of a -> b (n words a row): 3-tap along x over words
 * [i0, i1); beyond them: the image's border (pad) or pixels 2+ from any
 * set one (zero in every step) */
static void pass_x(const uint64_t *a, uint64_t *b, int n, int y0, int y1, int i0, int i1, int dil)
{
    const uint64_t pad = dil ? 0 : ~(uint64_t)0;
    const uint64_t before = i0 == 0 ? pad : 0, after = i1 == n ? pad : 0;
    for (int y = y0; y < y1; y++) {
        const uint64_t *r = a + (size_t)y * n;
        uint64_t *d = b + (size_t)y * n;
        uint64_t prev = before, cur = r[i0];
        for (int i = i0; i < i1; i++) {
            const uint64_t next = i + 1 < i1 ? r[i + 1] : after;
            const uint64_t lft = (cur << 1) | (prev >> 63), rgt = (cur >> 1) | (next << 63);
            d[i] = dil ? (cur | lft | rgt) : (cur & lft & rgt);
            prev = cur;
            cur = next;
        }
    }
}

/* rows [y0, y1) of a -> b: 3-tap along y, rows outside [0, h) = pad */
static void pass_y(const uint64_t *a, uint64_t *b, int n, int h, int y0, int y1, int i0, int i1,
                   int dil)
{
    const uint64_t pad = dil ? 0 : ~(uint64_t)0;
    for (int y = y0; y < y1; y++) {
        const uint64_t *u = y > 0 ? a + (size_t)(y - 1) * n : NULL;
        const uint64_t *c = a + (size_t)y * n;
        const uint64_t *l = y + 1 < h ? a + (size_t)(y + 1) * n : NULL;
        uint64_t *d = b + (size_t)y * n;
        for (int i = i0; i < i1; i++) {
            const uint64_t vu = u ? u[i] : pad, vl = l ? l[i] : pad;
            d[i] = dil ? (vu | c[i] | vl) : (vu & c[i] & vl);
        }
    }
}

/* the bits beyond the width of the last word of rows [y0, y1) set to v */
static void tail(uint64_t *a, int w, int n, int y0, int y1, int v)
{
    const int k = w % 64;
    if (!k) return;
    const uint64_t hi = ~(uint64_t)0 << k;
    for (int y = y0; y < y1; y++) {
        uint64_t *p = a + (size_t)y * n + n - 1;
        *p = v ? (*p | hi) : (*p & ~hi);
    }
}

/* One 3x3 step on rows [y0, y1), words [i0, i1) of a (b its scratch):
 * dilate (dil 1) or erode (dil 0), the tail bits beyond the width first
 * set so they neither grow nor eat the row's last pixels (tl: the last
 * word is processed). */
static void step(uint64_t *a, uint64_t *b, int w, int n, int h, int y0, int y1, int i0, int i1,
                 int tl, int dil)
{
    if (tl) tail(a, w, n, y0, y1, !dil);
    pass_x(a, b, n, y0, y1, i0, i1, dil);
    pass_y(b, a, n, h, y0, y1, i0, i1, dil);
}

int pipe_fit_smooth(uint8_t *mask, int stride, int width, int height, const uint8_t *inside,
                    int inside_stride, void *scratch, size_t scratch_size)
{
    return pipe_fit_smooth_ops(mask, stride, width, height, inside, inside_stride, scratch,
                               scratch_size, 3u);
}

int pipe_fit_smooth_ops(uint8_t *mask, int stride, int width, int height, const uint8_t *inside,
                        int inside_stride, void *scratch, size_t scratch_size, unsigned ops)
{
    if (inside && inside_stride < width) return -1;
    if (!mask || !scratch || stride < width) return -1;
    const size_t need = pipe_fit_smooth_scratch_size(width, height);
    if (!need || scratch_size < need) return -1;
    const int w = width, h = height, n = words(width);
    uint64_t *a = scratch, *b = a + (size_t)n * h, *lut = b + (size_t)n * h;
    /* the mask packed (>= 128 set) into a; its set rows and words */
    int first = -1, last = -1, i0 = n, i1 = -1;
    for (int y = 0; y < h; y++) {
        const uint8_t *r = mask + (size_t)y * stride;
        uint64_t *d = a + (size_t)y * n;
        uint64_t any = 0;
        for (int i = 0; i < n; i++) {
            uint64_t v = 0;
            const int x0 = 64 * i, x1 = x0 + 64 > w ? w : x0 + 64;
            int x = x0;
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
            /* 8 pixels: their top bits gathered into one byte */
            for (; x + 8 <= x1; x += 8) {
                uint64_t t;
                memcpy(&t, r + x, 8);
                t = (t >> 7) & 0x0101010101010101ull;
                v |= ((t * 0x0102040810204080ull) >> 56) << (x - x0);
            }
#endif
            for (; x < x1; x++) v |= (uint64_t)(r[x] >> 7) << (x - x0);
            d[i] = v;
            if (v) {
                if (i < i0) i0 = i;
                if (i > i1) i1 = i;
            }
            any |= v;
        }
        if (any) {
            if (first < 0) first = y;
            last = y;
        }
    }
    if (first < 0) return 0;
    /* the words that can change: those of set pixels and one each side */
    i0 = i0 - 1 < 0 ? 0 : i0 - 1;
    i1 = i1 + 2 > n ? n : i1 + 2;
    const int y0 = first - 2 < 0 ? 0 : first - 2;
    const int y1 = last + 3 > h ? h : last + 3;
    /* the column passes read one row beyond [y0, y1): those rows are
     * zero in the mask and in every intermediate (2+ rows from set
     * pixels), zero in a and b */
    if (y0 > 0) {
        memset(a + (size_t)(y0 - 1) * n, 0, sizeof(uint64_t) * (size_t)n);
        memset(b + (size_t)(y0 - 1) * n, 0, sizeof(uint64_t) * (size_t)n);
    }
    if (y1 < h) {
        memset(a + (size_t)y1 * n, 0, sizeof(uint64_t) * (size_t)n);
        memset(b + (size_t)y1 * n, 0, sizeof(uint64_t) * (size_t)n);
    }
    const int tl = i1 == n;   /* the last word is processed: its tail bits */
    /* close: dilate (a -> b -> a), erode (a -> b -> a) */
    if (ops & 1u) {
        step(a, b, w, n, h, y0, y1, i0, i1, tl, 1);
        step(a, b, w, n, h, y0, y1, i0, i1, tl, 0);
        /* the closing's new pixels only where inside is set */
        if (inside)
            for (int y = y0; y < y1; y++) {
                const uint8_t *r = mask + (size_t)y * stride,
                              *in = inside + (size_t)y * inside_stride;
                uint64_t *d = a + (size_t)y * n;
                for (int x = 64 * i0; x < w && x < 64 * i1; x++)
                    if (r[x] < 128 && in[x] < 128) d[x / 64] &= ~((uint64_t)1 << (x % 64));
            }
    }
    /* open: erode (a -> b -> a), dilate (a -> b -> a) */
    if (ops & 2u) {
        step(a, b, w, n, h, y0, y1, i0, i1, tl, 0);
        step(a, b, w, n, h, y0, y1, i0, i1, tl, 1);
    }
    /* unpacked: 8 pixels a byte of the word through the table (byte k of
     * an entry 0xFF where bit k of its index is set) */
    for (int e = 0; e < 256; e++) {
        uint8_t by[8];
        for (int k = 0; k < 8; k++) by[k] = (e >> k) & 1 ? 255 : 0;
        memcpy(&lut[e], by, 8);
    }
    const int c0 = 64 * i0, c1 = 64 * i1 > w ? w : 64 * i1;
    for (int y = y0; y < y1; y++) {
        uint8_t *r = mask + (size_t)y * stride;
        const uint64_t *s = a + (size_t)y * n;
        int x = c0;
        for (; x + 8 <= c1; x += 8) memcpy(r + x, &lut[(s[x / 64] >> (x % 64)) & 0xFF], 8);
        for (; x < c1; x++) r[x] = (s[x / 64] >> (x % 64)) & 1 ? 255 : 0;
    }
    return 0;
}
