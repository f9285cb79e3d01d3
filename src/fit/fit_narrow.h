#ifndef EGOFUSE_FIT_NARROW_H
#define EGOFUSE_FIT_NARROW_H
/* fit_narrow.h - the band refinement with a narrower band where the hand
 * is thin, and once more where the hand lies beyond the band (issue 14
 * item 2, docs/accuracy.md "Where `edge` loses the hand", "The band once
 * more from the refined edge").
 *
 * WHAT IT DOES
 *   The local histograms of the band refinement (fuse_refine.h) learn the
 *   hand from the ring band..band+margin px inside the mask; a hand at the
 *   image border thinner than twice that has no hand samples (fg_samples <
 *   min_samples), the refinement returns its input unchanged, and a prior
 *   (the last refined mask moved) is then carried for many frames without
 *   any colour decision. pipe_fit_refine_narrow runs the refinement again
 *   with the band halved while it falls back.
 *   Where the tracking is off by more than the band (hands crossing, hands
 *   at 15 cm), the colour takes in pixels up to the band's outer edge and
 *   the rest of the hand stays out. pipe_fit_refine_regrow runs the
 *   refinement once more from its own result (the band re-centred on the
 *   refined edge reaches band px further) when the first let in more than
 *   PIPE_REGROW_PER_MILLE / 1000 of the image's pixels.
 *   Behind a fast hand (fast: the hand trailing its kinematic model over a
 *   skin-coloured box) the regrow takes in where the hand was;
 *   pipe_fit_regrow_trail takes back what it added behind the hands' image
 *   motion.
 *
 * WHAT IT DOES NOT
 *   No allocation (the caller's scratch and buffer), no threads; never
 *   widens the band.
 *
 * USAGE
 *   eval's refine and pipe_refine.c call it where they called
 *   fuse_refine_mask(_global); the result is that call's whenever it did
 *   not fall back.
 */
#include "../fuse/fuse_refine.h"

/* The narrowest band tried (px; edge: 4 measured, docs/accuracy.md). */
#define PIPE_NARROW_MIN_BAND 4

/* The weight of the fit's global colour model (pipe_fit_colour) against
 * the band's local histograms in the refinement, pipeline and eval alike
 * (eval --global): 1, the global model alone (the local histograms then
 * only gate it by their counts). Measured against 0.5, 0.75 and 0.9 on
 * every sequence (docs/accuracy.md, "The global colour model alone"). */
#define PIPE_GLOBAL_WEIGHT 1.0f
/* With the global model alone (g and weight 1) the refinement's local
 * histograms only gate it: p->min_samples is lowered to this (edge gains
 * 0.0056 IoU over 90 frames, the other sequences are unchanged: docs/
 * accuracy.md). */
#define PIPE_GLOBAL_MIN_SAMPLES 1

/* fuse_refine_mask_global (g not NULL) or fuse_refine_mask with p (its
 * min_samples at most PIPE_GLOBAL_MIN_SAMPLES when g is not NULL and
 * weight >= 1); when that falls back (stats->used_colour 0), again with
 * the band halved while the band stays >= min_band and the scratch
 * suffices for it. *band_used
 * (not NULL) receives the band of the result. stats must not be NULL
 * (FUSE_ERR_ARGS). Returns what the last refinement returned. */
fuse_result pipe_fit_refine_narrow(const fuse_refine_params *p, const fuse_colour_model *g,
                                   float weight, int min_band, const fuse_image *P,
                                   const uint8_t *mask, int mask_stride, uint8_t *out,
                                   int out_stride, void *scratch, size_t scratch_size,
                                   fuse_refine_stats *stats, int *band_used);
/* More pixels let in than this many per mille of the image (flipped_in;
 * 4480 at 640x400): the refinement runs once more (measured on the eval
 * sequences: docs/accuracy.md). */
#define PIPE_REGROW_PER_MILLE 17.5

/* When first (the stats of the refinement that wrote refined, P's size,
 * stride bytes per row) used the colour and let in more than
 * PIPE_REGROW_PER_MILLE / 1000 of P's pixels: refined copied into tmp (P's
 * width x height bytes, its own stride P->width) and refined again from it
 * with pipe_fit_refine_narrow (p, g, weight, PIPE_NARROW_MIN_BAND) into
 * refined. Returns 1 when it ran, 0 when not (refined unchanged), -1 when
 * the refinement failed (FUSE_ERR_ARGS). */
int pipe_fit_refine_regrow(const fuse_refine_params *p, const fuse_colour_model *g,
                           float weight, const fuse_image *P, uint8_t *refined, int stride,
                           uint8_t *tmp, void *scratch, size_t scratch_size,
                           const fuse_refine_stats *first);

/* How far behind a moving hand the regrow's pixels are taken back, in
 * frames of the hand's image motion (measured on fast: docs/accuracy.md
 * "Where fast's boundary misses sit"). */
#define PIPE_TRAIL_STEPS 1
/* Only hands at least this fast (m/s, the filtered wrist speed): slower
 * hands lag less than a pixel or two, and a hand coming nearer grows on
 * every side (near: measured). */
#define PIPE_TRAIL_SPEED 0.4f

/* The regrow's pixels behind a moving hand taken back. A hand moving fast
 * trails its kinematic model; what the regrow (above) adds behind it is
 * where the hand was a frame before, over a skin-coloured object (fast: the
 * cardboard box), not hand. For every pixel set in refined (stride bytes
 * per row, w x h) and clear in first (the refinement before the regrow,
 * first_stride): k the nearest hand of sides (bit k: hand_px[k] valid, the
 * hand's image position in this frame), d = motion[k] (its image motion
 * since the last frame, px; hands moving less than 1 px per frame, or
 * slower than PIPE_TRAIL_SPEED by speed[k] (m/s; speed NULL: every hand)
 * are skipped); the pixel is cleared when first is set at p + j d for some j
 * in 1..steps (the hand lies ahead of it along its motion) and at no
 * p - j d (not between two parts of the hand). Returns the pixels cleared,
 * -1 on bad arguments (refined unchanged). */
long pipe_fit_regrow_trail(const uint8_t *first, int first_stride, uint8_t *refined, int stride,
                           int w, int h, unsigned sides, const float hand_px[2][2],
                           const float motion[2][2], const float *speed, int steps);
#endif
