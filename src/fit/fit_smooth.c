/* The refined mask's 3x3 closing then opening (fit_smooth.h). Each
 * dilation / erosion is separable: a 3-tap max / min along the row into
 * a buffer, then along the column. Only the rows that can change (the
 * set rows and 2 around them; an all-zero row far from set pixels stays
 * zero under all four steps) are processed. */
#include "fit_smooth.h"

#include <string.h>

size_t pipe_fit_smooth_scratch_size(int width, int height)
{
    if (width < 1 || height < 1 || width > (1 << 16) || height > (1 << 16)) return 0;
    return 2 * (size_t)width * (size_t)height;
}

static inline uint8_t mx(uint8_t a, uint8_t b) { return a > b ? a : b; }
static inline uint8_t mn(uint8_t a, uint8_t b) { return a < b ? a : b; }

/* rows [y0, y1) of src (stride ss) -> dst (stride ds): 3-tap along x,
 * outside = pad */
static void pass_x(const uint8_t *src, int ss, uint8_t *dst, int ds, int w, int y0, int y1, int dil)
{
    const uint8_t pad = dil ? 0 : 255;
    for (int y = y0; y < y1; y++) {
        const uint8_t *s = src + (size_t)y * ss;
        uint8_t *d = dst + (size_t)y * ds;
        if (w == 1) { d[0] = s[0]; continue; }
        if (dil) {
            d[0] = mx(mx(pad, s[0]), s[1]);
            for (int x = 1; x < w - 1; x++) d[x] = mx(mx(s[x - 1], s[x]), s[x + 1]);
            d[w - 1] = mx(mx(s[w - 2], s[w - 1]), pad);
        } else {
            d[0] = mn(mn(pad, s[0]), s[1]);
            for (int x = 1; x < w - 1; x++) d[x] = mn(mn(s[x - 1], s[x]), s[x + 1]);
            d[w - 1] = mn(mn(s[w - 2], s[w - 1]), pad);
        }
    }
}

/* rows [y0, y1): 3-tap along y of src (rows y-1..y+1 read within [0, h),
 * outside = pad) */
static void pass_y(const uint8_t *src, int ss, uint8_t *dst, int ds, int w, int h, int y0, int y1,
                   int dil)
{
    const uint8_t pad = dil ? 0 : 255;
    for (int y = y0; y < y1; y++) {
        const uint8_t *a = y > 0 ? src + (size_t)(y - 1) * ss : NULL;
        const uint8_t *b = src + (size_t)y * ss;
        const uint8_t *c = y + 1 < h ? src + (size_t)(y + 1) * ss : NULL;
        uint8_t *d = dst + (size_t)y * ds;
        if (dil) {
            if (a && c)
                for (int x = 0; x < w; x++) d[x] = mx(mx(a[x], b[x]), c[x]);
            else
                for (int x = 0; x < w; x++)
                    d[x] = mx(mx(a ? a[x] : pad, b[x]), c ? c[x] : pad);
        } else {
            if (a && c)
                for (int x = 0; x < w; x++) d[x] = mn(mn(a[x], b[x]), c[x]);
            else
                for (int x = 0; x < w; x++)
                    d[x] = mn(mn(a ? a[x] : pad, b[x]), c ? c[x] : pad);
        }
    }
}

static int row_set(const uint8_t *r, int w)
{
    for (int x = 0; x < w; x++)
        if (r[x]) return 1;
    return 0;
}

int pipe_fit_smooth(uint8_t *mask, int stride, int width, int height, void *scratch,
                    size_t scratch_size)
{
    if (!mask || !scratch || stride < width) return -1;
    const size_t need = pipe_fit_smooth_scratch_size(width, height);
    if (!need || scratch_size < need) return -1;
    int first = -1, last = -1;
    for (int y = 0; y < height; y++)
        if (row_set(mask + (size_t)y * stride, width)) {
            if (first < 0) first = y;
            last = y;
        }
    if (first < 0) return 0;
    /* the rows that can change: a set pixel reaches 2 rows under the
     * closing's dilation; the erosions and the opening stay inside */
    const int y0 = first - 2 < 0 ? 0 : first - 2;
    const int y1 = last + 3 > height ? height : last + 3;
    /* the passes read one row beyond [y0, y1): those rows are zero in
     * the mask (or outside the image) and stay zero in every
     * intermediate (a zero row 3+ from set pixels), so a and b hold them
     * as zero */
    const int r0 = y0 - 1 < 0 ? 0 : y0 - 1, r1 = y1 + 1 > height ? height : y1 + 1;
    uint8_t *a = scratch, *b = a + (size_t)width * height;
    const int w = width;
    for (int y = r0; y < r1; y++)
        if (y < y0 || y >= y1) {
            memset(a + (size_t)y * w, 0, (size_t)w);
            memset(b + (size_t)y * w, 0, (size_t)w);
        }
    /* close: dilate (mask -> a -> b), erode (b -> a -> b) */
    pass_x(mask, stride, a, w, w, y0, y1, 1);
    pass_y(a, w, b, w, w, height, y0, y1, 1);
    pass_x(b, w, a, w, w, y0, y1, 0);
    /* the erosion along y must see 255 beyond the image but the zero
     * rows beyond [y0, y1) as zero: they are in a (zeroed above) */
    pass_y(a, w, b, w, w, height, y0, y1, 0);
    /* open: erode (b -> a -> b), dilate (b -> a -> mask) */
    pass_x(b, w, a, w, w, y0, y1, 0);
    pass_y(a, w, b, w, w, height, y0, y1, 0);
    pass_x(b, w, a, w, w, y0, y1, 1);
    pass_y(a, w, mask, stride, w, height, y0, y1, 1);
    return 0;
}
