/* fuse_metrics.h - how right a mask and a composite are: IoU, boundary
 * F-score, false-positive and false-negative area, PSNR, temporal edge
 * flicker. Used by `egofuse eval` (docs/accuracy.md) against the ground
 * truth of samples/gt/.
 *
 * WHAT IT DOES
 *   Masks are 8-bit planes (any stride); a pixel is "inside" when its value
 *   is >= 128 (so anti-aliased coverage counts by its majority). Images
 *   are interleaved 8-bit pixels of `bpp` bytes of which the first
 *   `channels` are compared (RGBA8 with channels 3 ignores alpha).
 *
 *   Definitions (P = predicted mask, T = true mask):
 *     confusion   tp = |P & T|, fp = |P & ~T| (background that leaks
 *                 through: the paper's "outline of the local
 *                 environment"), fn = |~P & T| (hand that is cut off),
 *                 tn = the rest.
 *     IoU         tp / (tp + fp + fn); 1 when both masks are empty.
 *     boundary    a pixel of a mask is a boundary pixel when it is inside
 *                 and one of its 4 neighbours inside the image is outside
 *                 (the image border is not a boundary).
 *     BF(d)       precision = fraction of P's boundary pixels with a T
 *                 boundary pixel within Euclidean distance d (pixel
 *                 centres), recall = the same from T to P,
 *                 F = 2 P R / (P + R) (0 when P + R = 0). Both boundaries
 *                 empty: F = 1 (precision = recall = 1); one empty: 0.
 *     PSNR        10 log10(255^2 / MSE) over the compared channels, in dB;
 *                 +INFINITY for identical images.
 *     flicker     temporal edge flicker between two consecutive frames:
 *                 | |P0 ^ P1| - |T0 ^ T1| | / max(1, boundary pixels of
 *                 T1): how much more (or less) area the predicted mask
 *                 swept than the true one, in pixels per pixel of edge,
 *                 i.e. the spurious edge motion in pixels. 0 when the
 *                 prediction moves as the truth does (even with a constant
 *                 offset) or both are static; an edge jittering by k px
 *                 on a static truth gives k.
 *
 * WHAT IT DOES NOT
 *   No allocation, no threads, no global state. Pure C, libc + libm.
 *   Invalid arguments (NULL planes, sizes < 1, strides too small) give
 *   a zeroed result and -1 (the double-valued calls return NAN).
 */
#ifndef EGOFUSE_FUSE_METRICS_H
#define EGOFUSE_FUSE_METRICS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fuse_confusion {
    long tp, fp, fn, tn;
} fuse_confusion;

/* Pixel counts of P against T (see above). Returns 0, or -1 on bad
 * arguments (out zeroed when out is not NULL). */
int fuse_mask_confusion(const uint8_t *pred, int pred_stride,
                        const uint8_t *truth, int truth_stride, int width,
                        int height, fuse_confusion *out);

/* tp / (tp + fp + fn), 1 when that is 0. */
double fuse_confusion_iou(const fuse_confusion *c);

/* Boundary precision, recall and F-score within distance d (pixels, >= 0).
 * precision / recall may be NULL. Cost: boundary pixels x (2d+1)^2. */
double fuse_boundary_f(const uint8_t *pred, int pred_stride,
                       const uint8_t *truth, int truth_stride, int width,
                       int height, float d, double *precision,
                       double *recall);

/* Number of boundary pixels of a mask. */
long fuse_boundary_count(const uint8_t *mask, int stride, int width,
                         int height);

/* Mean squared error over the first `channels` bytes of every pixel of
 * bpp bytes (1 <= channels <= bpp <= 16), and PSNR from it. */
double fuse_mse(const uint8_t *a, int a_stride, const uint8_t *b,
                int b_stride, int width, int height, int bpp, int channels);
double fuse_psnr(const uint8_t *a, int a_stride, const uint8_t *b,
                 int b_stride, int width, int height, int bpp, int channels);
/* PSNR of an MSE (the sum of several images' MSE averaged first). */
double fuse_psnr_of_mse(double mse);

/* Temporal edge flicker between frames 0 and 1 (see above). All four
 * masks share one stride. */
double fuse_edge_flicker(const uint8_t *pred0, const uint8_t *pred1,
                         const uint8_t *truth0, const uint8_t *truth1,
                         int stride, int width, int height);

#ifdef __cplusplus
}
#endif
#endif
