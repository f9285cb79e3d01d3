/* fit_band.h - the width of the refinement band from the projected
 * uncertainty of the hands (issue 14 item 2, docs/accuracy.md).
 *
 * WHAT IT DOES
 *   The band refinement (fuse_refine_mask*) can only move the kinematic
 *   mask's edge within `band` pixels. The kinematic error is a distance in
 *   the world (the model's hand shape and finger angles, tracking noise,
 *   the filter's lag behind a moving hand), so in pixels it grows as the
 *   hand comes nearer to the camera and as it moves faster. pipe_fit_band
 *   gives one eye's band for this frame:
 *     u(side) = f * (sigma + speed(side) * tau) / z(side)
 *   with f the camera's focal length in pixels (the mean of fx and fy),
 *   z(side) the smallest depth in front of the camera of the side's hand
 *   joints (hand, palm and the 15 finger joints of the rig) that project
 *   within the image grown by `reach` pixels (a hand out of view does not
 *   widen the band), and speed(side) the tracked wrist's speed (m/s);
 *     band = clamp(ceil(max over the tracked sides of u), band_min, band_max).
 *   With no hand joint in view the band is band_min.
 *
 * WHAT IT DOES NOT
 *   No allocation, no state; it does not refine (the caller passes the
 *   band to fuse_refine_mask*, whose scratch must be sized for band_max).
 */
#ifndef EGOFUSE_FIT_BAND_H
#define EGOFUSE_FIT_BAND_H

#include <stdint.h>

#include "../fuse/fuse_refine.h"
#include "../kin/kin.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pipe_fit_band_desc {
    float sigma;     /* world error of the hand's outline, metres (0.02) */
    float tau;       /* seconds of motion counted as error (0: speed unused) */
    float reach;     /* pixels beyond the image a joint may project (32) */
    int band_min;    /* 1..64 (16) */
    int band_max;    /* band_min..64 (64) */
    float hand_radius; /* metres around each hand joint that get the wide
                          band (pipe_fit_band_region; 0.04) */
} pipe_fit_band_desc;

/* sigma 0.02, tau 0, reach 32, band_min 16, band_max 64, hand_radius 0.04. */
pipe_fit_band_desc pipe_fit_band_desc_default(void);

/* The band of one eye (see above). world: FK of the pose as drawn; sides:
 * bit 0 left, bit 1 right (the tracked hands); speed: 2 floats, m/s (NULL:
 * 0). d NULL = defaults. Returns band_min for bad arguments (cam, world or
 * rig NULL, a joint index < 0), and clamps d's fields to 1..64. */
int pipe_fit_band(const pipe_fit_band_desc *d, const kin_camera *cam, const kin_mat4 *world,
                  const kin_arm_rig *rig, unsigned sides, const float speed[2]);

/* The hands' part of the image: region (width x height = cam's image,
 * stride bytes per row) is set to 255, per row, from the leftmost to the
 * rightmost column covered by a disc of radius
 * f * d->hand_radius / z_j + band around a hand joint j (hand, palm,
 * fingers) of a tracked side (bit 0 left) that counts in pipe_fit_band
 * (in front, within reach of the image); 0 elsewhere. A few memsets per
 * row (the discs of 17 joints overlap heavily; painting each cost about
 * as much as the refinement). Returns the number of pixels set (0 for
 * none and for bad arguments; nothing is written when region is NULL or
 * an argument is bad). */
long pipe_fit_band_region(const pipe_fit_band_desc *d, const kin_camera *cam,
                          const kin_mat4 *world, const kin_arm_rig *rig, unsigned sides,
                          int band, uint8_t *region, int stride);

/* out = where region is set, wide; elsewhere narrow (four masks of
 * width x height, the same stride; out may be narrow). */
void pipe_fit_band_merge(const uint8_t *narrow, const uint8_t *wide, const uint8_t *region,
                         uint8_t *out, int stride, int width, int height);

/* The previous refined mask as the prior of this frame's refinement
 * (docs/accuracy.md): the band refinement can move the edge only `band`
 * pixels from its input mask, and a hand whose fingers reach farther
 * beyond the model (a near hand: 1 cm is 80 px at 10 cm) is never filled
 * from the kinematic mask alone. Around the hands that move slowly the
 * input is the last refined mask instead, moved with the hand, so that
 * the edge keeps what the colour found and moves on from there frame by
 * frame:
 *   sides' = the tracked sides (bit 0 left) whose wrist speed is below
 *            max_speed (m/s);
 *   per side s of sides', in its region (pipe_fit_band_region of that
 *            side alone, band 0): out(x) = prev(x - shift[s]) (shift: the
 *            hand's motion in the image since the last frame,
 *            pipe_fit_hand_px; NULL = none; rounded to whole pixels; kin
 *            where the source is outside the image); the right hand's
 *            region last;
 *   out    = kin elsewhere.
 * Returns out, or kin when no side qualifies, the regions are empty or an
 * argument is bad (prev NULL included: the first frame). kin, prev and
 * out: cam's image size, the same stride; out must not overlap them. */
const uint8_t *pipe_fit_prior(const pipe_fit_band_desc *d, const kin_camera *cam,
                              const kin_mat4 *world, const kin_arm_rig *rig, unsigned sides,
                              const float speed[2], float max_speed, const float shift[2][2],
                              const uint8_t *kin, const uint8_t *prev, uint8_t *out,
                              int stride);

/* The colour check of a prior (pipe_fit_prior's out, docs/accuracy.md):
 * the last refined mask moved with the hand keeps last frame's edge, and
 * where the hand moved by a fraction of a pixel or changed its outline
 * that edge is a pixel off. The band refinement then keeps such a 1-px
 * rim (its 3x3 vote is carried by the confident hand beside it, and the
 * model prior counts it as inside) and the prior keeps it frame after
 * frame: a dotted line of background pixels along the hand's edge. So
 * the prior's rim must also look like the hand: every pixel of prior
 * (>= 128) with a 4-neighbour in the image outside it (< 128) is set to 0
 * where g's log-likelihood ratio at P(x) is <= 0 (background at least as
 * likely); the neighbours are those of prior as given (one pass, a rim
 * 1 px deep). g: the fit's colour model (pipe_fit_colour, once
 * pipe_fit_learned); NULL or a model without samples: nothing changes. P:
 * RGBA8 of the mask's size. Returns the pixels cleared (0 for bad
 * arguments). */
long pipe_fit_prior_colour(const fuse_colour_model *g, const fuse_image *P, uint8_t *prior,
                           int stride);

/* The colour check of the refinement's output where its input was a
 * prior (after fuse_refine_mask*, docs/accuracy.md): the band's 3x3 vote
 * adds a pixel outside its input where the confident hand beside it
 * outweighs its own colour, at the corners of the prior's stair-stepped
 * edge: single background pixels along the hand's edge. out(x) = 0 where
 * in(x) < 128, out(x) >= 128, at most 2 of its 4-neighbours in the image
 * are set in out (a corner or a spur, not a straight edge: clearing those
 * too made the edge flicker, docs/accuracy.md) and g's log-likelihood
 * ratio at P(x) is <= 0; the neighbours are those of out as given. g, P:
 * as pipe_fit_prior_colour; in, out: the same stride. Returns the pixels
 * cleared (0 for bad arguments or g NULL / without samples). */
long pipe_fit_refined_colour(const fuse_colour_model *g, const fuse_image *P, const uint8_t *in,
                             uint8_t *out, int stride);

/* The mean image position (pixels) of side's hand joints (hand, palm,
 * fingers) that are in front of cam; 0 when none is (or bad arguments). */
int pipe_fit_hand_px(const kin_camera *cam, const kin_mat4 *world, const kin_arm_rig *rig,
                     int side, float xy[2]);

/* Adaptive lag compensation of the hands (docs/accuracy.md): the One
 * Euro filter's prediction without lag compensation (f->desc.no_lag_comp
 * 1, the default of the refine method: less jitter) trails a fast hand by
 * its speed times the low-pass's lag. out = kin_filter_output(f,
 * display_t) as configured; then per hand whose filtered wrist speed s is
 * above v0, its position and rotation move towards the lag-compensated
 * prediction (the same filter with no_lag_comp 0) by
 * a = min(1, (s - v0) / (v1 - v0)) (lerp, slerp). speed (NULL or 2
 * floats) receives the wrist speeds, m/s. Nothing else changes; with
 * f->desc.no_lag_comp 0 or v1 <= v0 it is kin_filter_output. */
void pipe_fit_filter_output(const kin_filter *f, double display_t, float v0, float v1,
                            kin_track_sample *out, float speed[2]);

#ifdef __cplusplus
}
#endif
#endif
