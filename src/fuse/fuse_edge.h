/* fuse_edge.h - soft edges where the camera image ends inside the display
 * (issue 18, item 4).
 *
 * WHAT IT DOES
 *   With the crop method of the paper (eq. 1-4) the lit layer Q (the
 *   camera's 640x400 crop) is resampled into a viewport (1194x746) that is
 *   a sub-rectangle of the display (1280x800): a forearm that leaves the
 *   camera's view ends at the viewport's edge in a hard line. The edge fade
 *   takes the layer's alpha (and, premultiplied, its colour) down to the
 *   border over the last k camera pixels, so the hand fades into V there.
 *
 *   The ramp, for a sample at (sx, sy) in continuous image coordinates
 *   (pixel (x, y) has its centre at (x + 0.5, y + 0.5); the image spans
 *   [0, w] x [0, h]):
 *     d      = the distance to the nearest faded side (sides: FUSE_EDGE_*),
 *              min(sx, w - sx, sy, h - sy) over the sides asked for
 *     weight = clamp(d / k, 0, 1)
 *   For pixel centres this is (2 i + 1) / (2 k) on the i-th pixel from the
 *   side (i = 0 .. k - 1) and 1 from the k-th on: k = 4 gives 1/8, 3/8,
 *   5/8, 7/8. fuse_edge_weight() is the ramp at any position (float), for
 *   a reprojection that samples the camera image at arbitrary points.
 *   fuse_edge_fade_row() / fuse_edge_fade() apply it to a premultiplied
 *   RGBA8 layer, all four channels, in integers (exact rounding):
 *     t = 2 min(i over the sides) + 1        (i: pixels from the side)
 *     q' = (q t + k) / (2 k)   (integer division)   when t < 2 k
 *   so r, g, b <= a stays true, and pixels k or more from every faded side
 *   are not touched (only the border strips are read or written).
 *
 * NUMBERS
 *   One scalar code, integers only: the same bytes on every ISA and thread
 *   count (rows are independent).
 *
 * WHAT IT DOES NOT
 *   No allocation, no threads. It does not know the display: the caller
 *   names the sides of the layer that end inside the display (pipe.c: the
 *   viewport's sides that do not touch the output's border).
 */
#ifndef EGOFUSE_FUSE_EDGE_H
#define EGOFUSE_FUSE_EDGE_H

#include <stdint.h>

#include "fuse.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Sides of the image to fade (bit mask). */
#define FUSE_EDGE_LEFT   1u
#define FUSE_EDGE_RIGHT  2u
#define FUSE_EDGE_TOP    4u
#define FUSE_EDGE_BOTTOM 8u
#define FUSE_EDGE_ALL    15u
/* Widest ramp, in pixels of the layer. */
#define FUSE_EDGE_FADE_MAX 64

/* The ramp at the continuous position (sx, sy) of a w x h image: 0 at a
 * faded side (and outside the image), 1 at k or more pixels from every
 * faded side. k < 1 or no side: 1 (no fade); w or h < 1: 0. NaN -> 0. */
float fuse_edge_weight(float sx, float sy, int w, int h, int k, unsigned sides);

/* Fades row y of a premultiplied RGBA8 layer of w x h pixels in place
 * (row: 4 w bytes). k < 1 (or above FUSE_EDGE_FADE_MAX) or no side: nothing. Only the pixels within k of
 * a faded side are touched. No checks (the caller's are fuse_edge_fade's). */
void fuse_edge_fade_row(uint8_t *row, int y, int w, int h, int k, unsigned sides);

/* Internal (the frame's driver, fuse_ctx.c): fuse_edge_fade_row on the
 * columns [c0, c1) of the row only, for a row known to be 0 outside them
 * (a zero pixel stays zero): the same bytes with fewer pixels visited. */
void fuse__edge_fade_cols(uint8_t *row, int y, int w, int h, int k, unsigned sides, int c0, int c1);

/* fuse_edge_fade_row on every row of Q (only the rows and columns of the
 * border strips are visited). FUSE_ERR_ARGS: Q NULL or not a valid image
 * (NULL pixels, size outside 1..FUSE_MAX_DIM, stride below 4 width), k
 * outside 0..FUSE_EDGE_FADE_MAX, sides beyond FUSE_EDGE_ALL. */
fuse_result fuse_edge_fade(fuse_image *Q, int k, unsigned sides);

#ifdef __cplusplus
}
#endif
#endif
