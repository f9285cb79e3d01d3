/* fuse_moments.c - area, centroid, bounding box of a mask and the shape
 * error of one mask against another (fuse_moments.h). */
#include "fuse_moments.h"

#include <math.h>
#include <string.h>

void fuse_mask_moments(const uint8_t *m, int stride, int w, int h, fuse_moments *out)
{
    memset(out, 0, sizeof *out);
    if (!m || w < 1 || h < 1) return;
    double sx = 0.0, sy = 0.0;
    long n = 0;
    int x0 = w, y0 = h, x1 = -1, y1 = -1;
    for (int y = 0; y < h; y++) {
        const uint8_t *r = m + (long)y * stride;
        long row = 0;
        double rx = 0.0;
        for (int x = 0; x < w; x++) {
            if (r[x] < 128) continue;
            row++;
            rx += (double)x + 0.5;
            if (x < x0) x0 = x;
            if (x > x1) x1 = x;
        }
        if (!row) continue;
        n += row;
        sx += rx;
        sy += ((double)y + 0.5) * (double)row;
        if (y < y0) y0 = y;
        y1 = y;
    }
    if (!n) return;
    out->area = n;
    out->cx = sx / (double)n;
    out->cy = sy / (double)n;
    out->x0 = x0;
    out->y0 = y0;
    out->x1 = x1;
    out->y1 = y1;
}

int fuse_shape_compare(const fuse_moments *a, const fuse_moments *truth, long min_area,
                       fuse_shape_error *out)
{
    memset(out, 0, sizeof *out);
    if (min_area < 1) min_area = 1;
    if (a->area < min_area || truth->area < min_area) return 0;
    out->pos_px = hypot(a->cx - truth->cx, a->cy - truth->cy);
    out->size = sqrt((double)a->area / (double)truth->area) - 1.0;
    out->height = (double)(a->y1 - a->y0 + 1) / (double)(truth->y1 - truth->y0 + 1) - 1.0;
    return 1;
}
