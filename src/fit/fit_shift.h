/* fit_shift.h - the hands of the refinement's input moved in the image to
 * where the colour says they are (issue 14 item 2, docs/accuracy.md).
 *
 * WHAT IT DOES
 *   The band refinement moves the input's edge at most `band` pixels; a
 *   hand whose model lies farther off (the filter's lag behind a fast
 *   hand, a near hand's size) stays off. pipe_fit_shift moves each given
 *   side's hand part of the input mask by one whole-pixel 2D shift, the
 *   one whose mask points fall on the most hand-coloured pixels:
 *     points  = the pixels of in (>= 128) inside the side's region
 *               (pipe_fit_band_region of that side alone, band = range),
 *               on a grid of even step q (q >= 2, chosen so that there
 *               are at most about d->max_points of them);
 *     score(s)= sum over points p of clamp(llr(P(p + s)), -3, 3) (0 where
 *               p + s is outside the image: unknown)
 *               - d->cost * |s| * npoints;
 *     s       = searched on the grid -range..range step 8, then step 4 and
 *               2 around the best (the first best in row order wins ties);
 *     taken when score(s) - score(0) > d->min_gain * npoints, else 0.
 *   out = in(x - s) in the side's region (0 where x - s is outside the
 *   image), in elsewhere; sides in order left, right, each side's region
 *   written from in.
 *
 * WHAT IT DOES NOT
 *   No allocation (the caller passes scratch), no rotation, no state.
 */
#ifndef EGOFUSE_FIT_SHIFT_H
#define EGOFUSE_FIT_SHIFT_H

#include <stddef.h>
#include <stdint.h>

#include "fit_band.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pipe_fit_shift_desc {
    int range;        /* pixels searched each way, even, 2..64 (24) */
    int max_points;   /* points per side at most, >= 16 (1500) */
    float min_gain;   /* nats per point the best shift must gain (0.1) */
    float cost;       /* nats per point and pixel of shift (0.004) */
    float hand_radius;/* metres around each hand joint: the region (0.04) */
} pipe_fit_shift_desc;

/* range 24, max_points 1500, min_gain 0.1, cost 0.004, hand_radius 0.04. */
pipe_fit_shift_desc pipe_fit_shift_desc_default(void);

/* Bytes of scratch for an image of width x height (stride >= width). */
size_t pipe_fit_shift_scratch_size(int stride, int height);

/* See above. g: the fit's colour model (pipe_fit_colour, once
 * pipe_fit_learned); P: RGBA8 of cam's size; in, out: masks of cam's
 * size and the same stride, out must not overlap in; sides: bit 0 left,
 * bit 1 right; shift (NULL or [2][2]) receives each side's shift (0 for
 * sides not given). scratch: pipe_fit_shift_scratch_size bytes, 4-byte
 * aligned. Returns out when a side moved, in otherwise (nothing moved, g
 * NULL or without samples, bad arguments). */
const uint8_t *pipe_fit_shift(const pipe_fit_shift_desc *d, const fuse_colour_model *g,
                              const fuse_image *P, const kin_camera *cam,
                              const kin_mat4 *world, const kin_arm_rig *rig, unsigned sides,
                              const uint8_t *in, uint8_t *out, int stride, void *scratch,
                              size_t scratch_size, int shift[2][2]);

#ifdef __cplusplus
}
#endif

#endif
