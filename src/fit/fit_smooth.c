/* The refined mask's 3x3 closing then opening (fit_smooth.h). Each
 * dilation / erosion is separable: a 3-tap OR / AND along the row, then
 * along the column, on 0/255 bytes 8 at a time (a uint64_t: the row's
 * neighbours by shifting in the next word's byte). The rows are copied
 * into scratch rows of a stride rounded up to 8, whose tail bytes hold
 * the pad the next row pass needs (0 before a dilation, 255 before an
 * erosion). Only the rows that can change (the set rows and 2 around
 * them; a zero row 2+ from set rows stays zero under all four steps)
 * are processed. */
#include "fit_smooth.h"

#include <string.h>

static int stride8(int width) { return (width + 7) / 8 * 8; }

size_t pipe_fit_smooth_scratch_size(int width, int height)
{
    if (width < 1 || height < 1 || width > (1 << 16) || height > (1 << 16)) return 0;
    return 2 * (size_t)stride8(width) * (size_t)height;
}

static inline uint64_t ld(const uint8_t *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

static inline void st(uint8_t *p, uint64_t v) { memcpy(p, &v, 8); }

/* rows [y0, y1) of a -> b (stride s8, n8 words a row): 3-tap along x
 * (byte j of a word is the pixel at the lowest address + j: little and
 * big endian handled by the shifts' direction) */
static void pass_x(const uint8_t *a, uint8_t *b, int s8, int y0, int y1, int i0, int i1, int n8,
                   int dil)
{
    const uint64_t pad = dil ? 0 : ~(uint64_t)0;
    /* beyond the word range: the image's border (pad), or pixels 2+ from
     * any set one (zero in every step) */
    const uint64_t before = i0 == 0 ? pad : 0, after = i1 == n8 ? pad : 0;
    for (int y = y0; y < y1; y++) {
        const uint8_t *r = a + (size_t)y * s8;
        uint8_t *d = b + (size_t)y * s8;
        uint64_t prev = before, cur = ld(r + 8 * i0);
        for (int i = i0; i < i1; i++) {
            const uint64_t next = i + 1 < i1 ? ld(r + 8 * (i + 1)) : after;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
            const uint64_t lft = (cur >> 8) | (prev << 56), rgt = (cur << 8) | (next >> 56);
#else
            const uint64_t lft = (cur << 8) | (prev >> 56), rgt = (cur >> 8) | (next << 56);
#endif
            st(d + 8 * i, dil ? (cur | lft | rgt) : (cur & lft & rgt));
            prev = cur;
            cur = next;
        }
    }
}

/* rows [y0, y1) of a -> b: 3-tap along y, rows outside [0, h) = pad */
static void pass_y(const uint8_t *a, uint8_t *b, int s8, int h, int y0, int y1, int i0, int i1,
                   int dil)
{
    const uint64_t pad = dil ? 0 : ~(uint64_t)0;
    for (int y = y0; y < y1; y++) {
        const uint8_t *u = y > 0 ? a + (size_t)(y - 1) * s8 : NULL;
        const uint8_t *c = a + (size_t)y * s8;
        const uint8_t *l = y + 1 < h ? a + (size_t)(y + 1) * s8 : NULL;
        uint8_t *d = b + (size_t)y * s8;
        for (int i = i0; i < i1; i++) {
            const uint64_t vu = u ? ld(u + 8 * i) : pad, vc = ld(c + 8 * i),
                           vl = l ? ld(l + 8 * i) : pad;
            st(d + 8 * i, dil ? (vu | vc | vl) : (vu & vc & vl));
        }
    }
}

/* the tail bytes [w, s8) of rows [y0, y1) of a set to v */
static void tail(uint8_t *a, int w, int s8, int y0, int y1, uint8_t v)
{
    if (w == s8) return;
    for (int y = y0; y < y1; y++) memset(a + (size_t)y * s8 + w, v, (size_t)(s8 - w));
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
    const int w = width, h = height, s8 = stride8(width);
    uint8_t *a = scratch, *b = a + (size_t)s8 * h;
    /* the mask made 0/255 into a; its set rows */
    int first = -1, last = -1, x0 = w, x1 = -1;
    for (int y = 0; y < h; y++) {
        const uint8_t *r = mask + (size_t)y * stride;
        uint8_t *d = a + (size_t)y * s8;
        uint64_t any = 0;
        int x = 0;
        for (; x + 8 <= w; x += 8) {
            /* the top bit of each byte spread over the byte: 0 or 0xFF */
            const uint64_t t = (ld(r + x) >> 7) & 0x0101010101010101ull;
            const uint64_t v = t * 0xFF;
            st(d + x, v);
            if (v) {
                if (x < x0) x0 = x;
                if (x + 7 > x1) x1 = x + 7;
            }
            any |= v;
        }
        for (; x < w; x++) {
            d[x] = r[x] >= 128 ? 255 : 0;
            if (d[x]) {
                if (x < x0) x0 = x;
                if (x > x1) x1 = x;
            }
            any |= d[x];
        }
        if (any) {
            if (first < 0) first = y;
            last = y;
        }
    }
    if (first < 0) return 0;
    /* the words that can change: those of set pixels and one each side */
    const int n8 = s8 / 8, i0 = x0 / 8 - 1 < 0 ? 0 : x0 / 8 - 1,
              i1 = x1 / 8 + 2 > n8 ? n8 : x1 / 8 + 2;
    const int y0 = first - 2 < 0 ? 0 : first - 2;
    const int y1 = last + 3 > h ? h : last + 3;
    /* the column passes read one row beyond [y0, y1): those rows are
     * zero in the mask and in every intermediate (2+ rows from set
     * pixels), zero in a and b */
    const int r0 = y0 - 1 < 0 ? 0 : y0 - 1, r1 = y1 + 1 > h ? h : y1 + 1;
    if (r0 < y0) {
        memset(a + (size_t)r0 * s8, 0, (size_t)s8);
        memset(b + (size_t)r0 * s8, 0, (size_t)s8);
    }
    if (r1 > y1) {
        memset(a + (size_t)y1 * s8, 0, (size_t)s8);
        memset(b + (size_t)y1 * s8, 0, (size_t)s8);
    }
    /* close: dilate (a -> b -> a), erode (a -> b -> a) */
    if (ops & 1u) {
    tail(a, w, s8, y0, y1, 0);
    pass_x(a, b, s8, y0, y1, i0, i1, n8, 1);
    pass_y(b, a, s8, h, y0, y1, i0, i1, 1);
    tail(a, w, s8, y0, y1, 255);
    pass_x(a, b, s8, y0, y1, i0, i1, n8, 0);
    pass_y(b, a, s8, h, y0, y1, i0, i1, 0);
    /* the closing's new pixels only where inside is set */
    if (inside)
        for (int y = y0; y < y1; y++) {
            const uint8_t *r = mask + (size_t)y * stride, *in = inside + (size_t)y * inside_stride;
            uint8_t *d = a + (size_t)y * s8;
            for (int x = 8 * i0; x < w && x < 8 * i1; x++)
                if (r[x] < 128 && in[x] < 128) d[x] = 0;
        }
    }
    /* open: erode (a -> b -> a), dilate (a -> b -> a) */
    if (ops & 2u) {
    tail(a, w, s8, y0, y1, 255);
    pass_x(a, b, s8, y0, y1, i0, i1, n8, 0);
    pass_y(b, a, s8, h, y0, y1, i0, i1, 0);
    tail(a, w, s8, y0, y1, 0);
    pass_x(a, b, s8, y0, y1, i0, i1, n8, 1);
    pass_y(b, a, s8, h, y0, y1, i0, i1, 1);
    }
    const int c0 = 8 * i0, c1 = 8 * i1 > w ? w : 8 * i1;
    for (int y = y0; y < y1; y++)
        memcpy(mask + (size_t)y * stride + c0, a + (size_t)y * s8 + c0, (size_t)(c1 - c0));
    return 0;
}
