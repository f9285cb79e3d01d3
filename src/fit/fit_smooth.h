/* fit_smooth.h - the refined mask's ragged edge smoothed (issue 14 item 2,
 * docs/accuracy.md, "The refined edge smoothed").
 *
 * WHAT IT DOES
 *   The colour vote decides each band pixel on its own: shadowed skin on
 *   the hand's underside and the finger sides falls out as notches and
 *   cracks 1-2 px wide, background specks stick out as 1-px spurs. Each
 *   is an edge of the mask a few pixels from the true edge (a miss of
 *   boundary F at 3 px). pipe_fit_smooth makes the mask binary (set:
 *   >= 128, written 255; clear 0) and applies a 3x3 closing, then a
 *   3x3 opening (square structuring element: OR / AND over the 3x3
 *   neighbourhood):
 *     close(m) = erode(dilate(m)),  open(m) = dilate(erode(m)),
 *     c        = close(m), or with a mask `inside`: m | (close(m) & inside)
 *                (the closing adds only pixels inside sets),
 *     out      = open(c),   in place;
 *   outside the image a dilation sees 0 and an erosion sees 255 (a mask
 *   touching the border is not cut back from it). Only the rows and
 *   8-pixel column blocks within 2 rows / 1 block of a set pixel are
 *   rewritten: a clear pixel (< 128) farther out keeps its value (0 in a
 *   0/255 mask).
 *
 * WHAT IT DOES NOT
 *   No allocation (the caller passes scratch), no colour, no state.
 *   Gaps wider than 2 px (between fingers) and islands wider than 2 px
 *   stay; notches 1-2 px wide are filled and spurs 1-2 px wide cut.
 */
#ifndef EGOFUSE_FIT_SMOOTH_H
#define EGOFUSE_FIT_SMOOTH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Bytes of scratch for a width x height mask (0 for bad sizes). */
size_t pipe_fit_smooth_scratch_size(int width, int height);

/* See above. mask: width x height bytes at stride >= width, rewritten in
 * place; inside: NULL or a mask of the same size (>= 128 set) at
 * inside_stride >= width. Returns 0, or -1 (mask unchanged) for bad
 * arguments or a scratch smaller than pipe_fit_smooth_scratch_size. */
int pipe_fit_smooth(uint8_t *mask, int stride, int width, int height, const uint8_t *inside,
                    int inside_stride, void *scratch, size_t scratch_size);

/* The same with the steps chosen: ops bit 0 the closing, bit 1 the
 * opening (3: pipe_fit_smooth). */
int pipe_fit_smooth_ops(uint8_t *mask, int stride, int width, int height, const uint8_t *inside,
                        int inside_stride, void *scratch, size_t scratch_size, unsigned ops);

#ifdef __cplusplus
}
#endif

#endif
