/* pipe_nfill.h - internal to src/pipe: the normals a refined mask is lit
 * with (issue 14 item 3).
 *
 * WHY
 *   With pipe_desc.refine_band the mask is the camera's hand, the normals
 *   are the model's. Where the two disagree (the tracked model lags a
 *   moving hand by a few pixels, or its fingers are a little off) the
 *   lighting showed it in every refined frame (demo frame 140, left eye,
 *   --pose tracking --refine 16):
 *   - a light halo 2-6 px wide around the hand: the refined pixels beyond
 *     the model have no normal (the rasterizer's 0), the lighting used the
 *     view vector, i.e. a surface facing the camera, brighter than the
 *     model's rim beside it;
 *   - a dark line inside the palm: the model's thumb edge 6 px above the
 *     camera's, the back of the hand's shadowed rim in the camera image
 *     lit with the thumb's and the back's darkest normals, a second edge
 *     beside the true one.
 *   The picture's shading detail is in the camera image already; the
 *   model's normals only need to say where the scene's light comes from.
 *
 * WHAT IT DOES
 *   pipe__nfill_refined() writes, for every pixel of mask (the refined
 *   mask), out = the sum of the model's normals nrm over the
 *   (2 r + 1)^2 window (nrm is 0 outside the model's mask kmask: the
 *   rasterizer's clear value); a jump of the model's normal becomes a
 *   ramp 2 r + 1 px wide, wider than the lag it must hide. A pixel of
 *   mask whose window holds no model pixel (kmask) gets the normal of the
 *   nearest pixel of mask that has one (3-4 chamfer distance, through
 *   mask pixels only, forward and backward passes until none changes):
 *   the model's rim normal continued outwards instead of the view vector.
 *   A refined blob not connected to the model keeps 0 (the lighting uses
 *   the view vector, as before).
 *
 * NUMBERS
 *   Vertical then horizontal running sums in IEEE single, no FMA, one
 *   scalar code: the same bytes on every ISA and thread count. The
 *   window's model pixels are counted in integers, so an empty window is
 *   known exactly (not from a sum that rounds to a tiny non-zero).
 *   Cost: the vertical sums over the box's columns (the row coming in
 *   added, the one going out taken, 4 floats at a time; the counts 8
 *   bytes at a time), the horizontal ones over the mask's runs only, and
 *   2-3 pairs of the fill's passes over each row's span of candidates (no
 *   allocation). docs/accuracy.md, "Refine's cost inside the pipeline".
 */
#ifndef EGOFUSE_PIPE_NFILL_H
#define EGOFUSE_PIPE_NFILL_H

#include <stddef.h>
#include <stdint.h>

#define PIPE_NFILL_RADIUS 3 /* pipe_desc.normal_smooth 0 with refine_band */

/* Scratch bytes pipe__nfill_refined needs for a w x h image. */
size_t pipe__nfill_scratch_size(int w, int h);

/* mask, kmask: w x h bytes (stride w); nrm, out: 3 floats per pixel
 * (stride 3 w), out not overlapping nrm, nrm 0 where kmask is 0; r in
 * 1..8; scratch of pipe__nfill_scratch_size(w, h) bytes, 16-byte
 * aligned. out is written at mask's pixels only. */
void pipe__nfill_refined(const uint8_t *mask, const uint8_t *kmask, const float *nrm,
                         float *out, int w, int h, int r, void *scratch);

#endif
