/* fuse_moments.h - the shape of a mask: area, centroid, bounding box, and
 * the position and size error of one mask against another (the eye-view
 * evaluation of `egofuse eval --eyeview`, docs/accuracy.md).
 *
 * WHAT IT DOES
 *   fuse_mask_moments sums a mask's area and first moments and finds its
 *   bounding box; fuse_shape_compare gives the centroid distance (px) and
 *   the size error (sqrt of the area ratio, and the box heights' ratio) of a
 *   mask against a true one.
 *
 * WHAT IT DOES NOT
 *   Overlap metrics (IoU, boundary F: fuse_metrics.h), or any drawing.
 *
 * USAGE
 *   fuse_moments m, t; fuse_shape_error e;
 *   fuse_mask_moments(out, stride, w, h, &m);
 *   fuse_mask_moments(truth, stride, w, h, &t);
 *   if (fuse_shape_compare(&m, &t, 50, &e)) ... e's fields (below)
 *
 * CONVENTIONS
 *   A pixel is inside when its mask value is >= 128 (the masks of
 *   src/fuse). Pixel (x, y) has its centre at (x + 0.5, y + 0.5): the
 *   centroid of a single pixel (0, 0) is (0.5, 0.5). Sums in double, in
 *   row order: the same result on every machine.
 */
#ifndef EGOFUSE_FUSE_MOMENTS_H
#define EGOFUSE_FUSE_MOMENTS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fuse_moments {
    long area;               /* pixels inside */
    double cx, cy;           /* centroid, pixels (0, 0 when area is 0) */
    int x0, y0, x1, y1;      /* bounding box, inclusive (all 0 when empty) */
} fuse_moments;

/* The moments of the w x h mask m (stride bytes per row). A NULL mask or
 * a size below 1 gives the empty moments. */
void fuse_mask_moments(const uint8_t *m, int stride, int w, int h, fuse_moments *out);

typedef struct fuse_shape_error {
    double pos_px;           /* |centroid(a) - centroid(truth)|, pixels */
    double size;             /* sqrt(area(a) / area(truth)) - 1: +0.10 = 10 %
                                larger (linear size, from the areas) */
    double height;           /* bounding-box height(a) / height(truth) - 1 */
} fuse_shape_error;

/* a against truth. Returns 1 with *out filled, or 0 (out zeroed) when
 * either area is below min_area (no shape to compare). */
int fuse_shape_compare(const fuse_moments *a, const fuse_moments *truth, long min_area,
                       fuse_shape_error *out);

#ifdef __cplusplus
}
#endif
#endif
