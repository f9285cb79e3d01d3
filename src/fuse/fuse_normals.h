/* fuse_normals.h - screen-space smoothing of the rasterizer's normals
 * before lighting (issue 14).
 *
 * WHAT IT DOES
 *   A model built from parts that cross (a forearm running into a separate
 *   palm, fingers starting inside a palm), each with its own vertex
 *   normals, has a jump of the normal where the parts' surfaces meet: the
 *   lighting layer shows a seam with the staircase of that crossing. The
 *   sample model no longer has one (samples/README.md), a user's model
 *   may. fuse_normal_smooth() replaces each normal of the lit mask by the
 *   sum of the normals in the (2 radius + 1)^2 window around it (clipped
 *   to the image; the lighting normalises it): a jump becomes a ramp
 *   2 radius + 1 pixels wide. Pixels the rasterizer did not cover have the
 *   normal 0 (its clear value) and add nothing, so a pixel a colour
 *   refinement added beside the model gets the model's normal beside it
 *   (with no covered pixel in its window it stays 0: the lighting then
 *   uses the view vector, as before).
 *   Measured on the old sample model (two crossing parts at each wrist),
 *   frames 0, 15, ..., 165 of reach_grasp, both eyes: neighbouring pixels
 *   whose diffuse lighting differs by more than 0.12 (the hard jumps):
 *   13,182 without smoothing, 2,925 with radius 1 (the seamless model:
 *   9,441 and 2,859), 1,222 with radius 2. docs/fuse.md, "Normals".
 *
 * NUMBERS
 *   out = ((sum over the window's rows, top to bottom, of the row's sum
 *   left to right)) per component, IEEE single, no FMA: one scalar code,
 *   the same bytes on every ISA.
 *
 * WHAT IT DOES NOT
 *   No allocation, no threads. Pixels with mask 0 are not written.
 */
#ifndef EGOFUSE_FUSE_NORMALS_H
#define EGOFUSE_FUSE_NORMALS_H

#include <stdint.h>

#include "fuse.h"

#ifdef __cplusplus
extern "C" {
#endif

#define FUSE_NORMAL_SMOOTH_MAX 4

/* nrm, out: 3 floats per pixel, strides in floats (>= 3 width); mask:
 * strides in bytes (>= width); radius 1..FUSE_NORMAL_SMOOTH_MAX; out
 * must not overlap nrm. FUSE_ERR_ARGS otherwise (nothing written).
 * Float normals only, in and out: there is no ef_n10 form of it (a
 * pipeline that smooths lights from the smoothed floats, fuse_eye.normal;
 * fuse_eye.normal_n10 is for the raster's normals as they are). */
fuse_result fuse_normal_smooth(const uint8_t *mask, int mask_stride, const float *nrm,
                               int nrm_stride, float *out, int out_stride, int width,
                               int height, int radius);

#ifdef __cplusplus
}
#endif
#endif
