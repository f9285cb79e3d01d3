/* pipe_soft.h - internal to src/pipe: soft silhouettes from a binary mask
 * at the cost of one pass over its edge (pipe_desc.soft_edge, issue 14
 * item 3).
 *
 * WHY
 *   The binary mask of the pixel centres gives the hands a hard,
 *   stair-stepped outline in every demo frame. The coverage samples of
 *   pipe_desc.aa_samples soften it, but a second draw of the model costs
 *   +66..+127 % of the frame (docs/antialias.md), and where the camera
 *   image's own edge is binary (the samples') a partly covered pixel
 *   outside the model shows the background at its fraction: a dotted rim.
 *
 * WHAT IT DOES
 *   pipe__soft_edge() writes out = M x n / 9, rounded, for every pixel of
 *   the binary mask M (0 or not), n the number of its 3x3 window's pixels
 *   (itself included) that are set; pixels beyond the image count as set
 *   (no fade at the image's border: the viewport's sides have their own,
 *   fuse_edge.h). Inside the hand n = 9 and out = M; on a straight edge the
 *   outer row of the hand gets 6/9 or 5/9, a stair's corner 4/9..7/9: the
 *   one-pixel steps become a ramp one pixel wide, inside the mask only, so
 *   every pixel lit has the model's normal and depth (no fill needed).
 *
 * NUMBERS
 *   Integers only: out = (M n + 4) / 9. The same bytes on every ISA and
 *   thread count (plain C, the counts summed one per byte of a 64-bit
 *   word). Pixels of M 0 are written 0. The work is one pass over each
 *   row's set span, 8 pixels at a time: all clear, all 255 with every
 *   neighbour (the hand's inside), or the edge, whose 8 counts are summed
 *   at once; one by one only in the image's first and last columns. The
 *   pipeline's form (pipe__soft_edge_boxed) finds the box of the mask's
 *   set pixels from the same spans and clears only what the last frame's
 *   box left outside them.
 */
#ifndef EGOFUSE_PIPE_SOFT_H
#define EGOFUSE_PIPE_SOFT_H

#include <stdint.h>

/* mask, out: w x h bytes, strides w; out must not overlap mask. box (x0,
 * y0, x1, y1, exclusive ends) limits the work to where mask may be set
 * (NULL: the whole image); out outside the box is not written. */
void pipe__soft_edge(const uint8_t *mask, uint8_t *out, int w, int h, const int box[4]);

/* The same bytes of out over the whole image, worked only over the box of
 * mask's set pixels: out keeps the box it was last given in held (x0, y0,
 * x1, y1; the whole image, {0, 0, w, h}, when out's bytes are unknown),
 * zeroes what of it lies outside the new box, writes the new box
 * (pipe__soft_edge) and leaves the new box in held. */
void pipe__soft_edge_boxed(const uint8_t *mask, uint8_t *out, int w, int h, int held[4]);

#endif
