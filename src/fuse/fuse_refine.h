/* fuse_refine.h - masks from colour: the skin-colour key of the related
 * work, and egofuse's edge-band refinement of the kinematic mask.
 *
 * WHAT IT DOES
 *   fuse_skin_key(): a fixed chroma model. Each pixel of an RGBA8 image
 *   is converted to YCbCr (BT.601, full range:
 *     Y  =  0.299 R + 0.587 G + 0.114 B
 *     Cb = 128 - 0.168736 R - 0.331264 G + 0.5 B
 *     Cr = 128 + 0.5 R - 0.418688 G - 0.081312 B)
 *   and is skin when its squared Mahalanobis distance in (Cb, Cr) to a
 *   Gaussian skin model is <= max_dist2 and min_luma <= Y <= max_luma.
 *   The default model is the widely used one of Hsu, Abdel-Mottaleb and
 *   Jain (mean Cb 117.43, Cr 156.56, covariance [[160.13, 12.14],
 *   [12.14, 299.46]]), max_dist2 = 2.5 (so that neutral grey, at 3.4,
 *   is not skin) and luma 40..250.
 *   Sleeves, shadows and skin-coloured objects defeat it: that is what the
 *   accuracy report shows.
 *
 *   fuse_refine_mask(): the kinematic mask M (from the posed model) is
 *   right except near its edge, where tracking noise, latency and the
 *   model's shape put it a few pixels off. Per frame:
 *     1. d(x) = chamfer (3-4) distance of every pixel to M's edge
 *        (pixels with a 4-neighbour of the other class are at distance 1),
 *        in pixels;
 *     2. two colour histograms are learned from this frame: "hand" from
 *        the pixels inside M with band < d <= band + margin, "background"
 *        from those outside M at the same distances (the certain inside
 *        and outside, near the edge where the colours that matter are);
 *        colours are quantised to `bits` bits per channel of RGB;
 *     3. every pixel with d <= band is decided again by the log-likelihood
 *        ratio of its colour, log((h_fg + a)/(n_fg + a K)) -
 *        log((h_bg + a)/(n_bg + a K)) (K bins, a K = 4 pseudo-samples),
 *        plus a prior that trusts the model: +prior * (1 - 0.75 (d-1) /
 *        band) inside M and the negative outside (strongest at the edge,
 *        a quarter at the band's border); pixels beyond the band score
 *        +4 inside M and -4 outside;
 *     4. a band pixel is inside when the sum of the scores over the
 *        (2 smooth + 1)^2 window around it (clipped to the image) is > 0:
 *        camera noise and skin texture do not fray the edge.
 *   Pixels farther than band from the edge keep M (binarised to 0/255).
 *   When either histogram has fewer than min_samples pixels the colour
 *   model is not trusted and the output is M.
 *
 *   The result is defined by the scalar reference (whole-image passes,
 *   fuse_refine_mask_isa with EF_ISA_REF); the default path does the same
 *   work only where it can change a byte (rows and columns within band +
 *   margin of the edge) with SIMD row kernels, and gives the same bytes.
 *
 * WHAT IT DOES NOT
 *   No allocation (the caller gives the scratch memory), no threads, no
 *   global state. Pure C, libc + libm.
 */
#ifndef EGOFUSE_FUSE_REFINE_H
#define EGOFUSE_FUSE_REFINE_H

#include <stddef.h>
#include <stdint.h>

#include "fuse.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------- skin-colour key */

typedef struct fuse_skin_params {
    float mean_cb, mean_cr;
    float cov[3];             /* var(Cb), cov(Cb, Cr), var(Cr) */
    float max_dist2;          /* squared Mahalanobis distance, > 0 */
    float min_luma, max_luma; /* 0..255 */
} fuse_skin_params;

fuse_skin_params fuse_skin_params_default(void);

/* out[y * out_stride + x] = 255 for skin, 0 otherwise; P is RGBA8 (alpha
 * ignored). FUSE_ERR_ARGS for NULL pointers, out_stride < width, a
 * covariance that is not positive definite or max_dist2 <= 0. */
fuse_result fuse_skin_key(const fuse_skin_params *p, const fuse_image *P,
                          uint8_t *out, int out_stride);

/* ------------------------------------------------- edge-band refinement */

typedef struct fuse_refine_params {
    int band;           /* uncertain half width, pixels, 1..64 (default 16) */
    int margin;         /* learning ring beyond it, pixels, 1..64 (8) */
    int bits;           /* colour bits per channel, 2..6 (4) */
    float prior;        /* model trust at the edge, nats, >= 0 (1.0) */
    int smooth;         /* decision window radius, 0..3 (default 1) */
    int min_samples;    /* per histogram, >= 1 (64) */
} fuse_refine_params;

/* band 16, margin 8, bits 4, prior 1.0, smooth 1, min_samples 64. */
fuse_refine_params fuse_refine_params_default(void);

/* Bytes of scratch memory fuse_refine_mask needs for this size (0 when
 * the size or the parameters are invalid). */
size_t fuse_refine_scratch_size(const fuse_refine_params *p, int width,
                                int height);

typedef struct fuse_refine_stats {
    long band_pixels;       /* pixels decided again */
    long flipped_in;        /* outside M, now inside */
    long flipped_out;       /* inside M, now outside */
    long fg_samples, bg_samples;
    int used_colour;        /* 0: the histograms were too small, out = M */
} fuse_refine_stats;

/* Refines mask (P's size, mask_stride bytes per row, inside = >= 128)
 * with the colours of P (RGBA8) into out (0/255, out_stride bytes per
 * row; out may not overlap mask or scratch). scratch: at least
 * fuse_refine_scratch_size() bytes, 16-byte aligned. stats may be NULL.
 * FUSE_ERR_ARGS on NULL pointers, bad strides, out-of-range parameters,
 * or too little scratch. */
fuse_result fuse_refine_mask(const fuse_refine_params *p, const fuse_image *P,
                             const uint8_t *mask, int mask_stride,
                             uint8_t *out, int out_stride, void *scratch,
                             size_t scratch_size, fuse_refine_stats *stats);

/* ----------------------------------------------- global colour model */

/* A two-class colour model of a whole image (arm against background),
 * learned from a rough mask: a 3-D histogram of RGB quantised to `bits`
 * bits per channel (2..6) per class, turned into a log-likelihood ratio
 * per bin, llr = log((h_fg + a) / (n_fg + a K)) - log((h_bg + a) /
 * (n_bg + a K)) (K bins, a K = 4 pseudo-samples), clamped to +-clamp.
 * Only pixels whose four neighbours at distance `margin` (pixels, 0..64)
 * have the same value are learned (the mask's edge, which may be off by
 * a few pixels, is left out); every `step`-th pixel (1..8) in x and y.
 * Used by `egofuse eval` to score where an arm lies in the image (its
 * elbow, which the IK can only guess, docs/accuracy.md). */
typedef struct fuse_colour_model {
    int bits;                 /* 2..6 */
    long fg_samples, bg_samples;
    float *llr;               /* 1 << (3 bits) floats, caller-owned */
} fuse_colour_model;

/* Bytes of scratch for fuse_colour_model_learn (the two histograms). */
size_t fuse_colour_model_scratch_size(int bits);
/* The bin of an RGB pixel: (r >> (8-bits)) << 2 bits | (g >> (8-bits))
 * << bits | (b >> (8-bits)). */
unsigned fuse_colour_bin(const uint8_t *rgb, int bits);
/* Learns cm->llr (cm->bits and cm->llr set by the caller) from P (RGBA8)
 * and mask: 255 = arm, 0 = background, any other value = not learned
 * (e.g. where two estimates disagree). scratch: fuse_colour_model_scratch_size()
 * bytes, 4-byte aligned. When either class has fewer than min_samples
 * pixels, llr is all 0 and FUSE_OK is still returned (check the counts).
 * FUSE_ERR_ARGS on NULL pointers, bad sizes or parameters. */
fuse_result fuse_colour_model_learn(fuse_colour_model *cm, const fuse_image *P,
                                    const uint8_t *mask, int mask_stride,
                                    int margin, int step, float clamp,
                                    long min_samples, void *scratch,
                                    size_t scratch_size);

/* fuse_refine_mask with the band's colour term mixed from the frame's
 * local histograms (weight 1 - weight) and a global colour model g
 * (fuse_colour_model_learn, e.g. learned where two estimates of the mask
 * agree; weight in [0, 1], 1 = g alone). The local histograms must still
 * have min_samples pixels, else out = M as before. FUSE_ERR_ARGS also for
 * a NULL or invalid g. */
fuse_result fuse_refine_mask_global(const fuse_refine_params *p,
                                    const fuse_colour_model *g, float weight,
                                    const fuse_image *P, const uint8_t *mask,
                                    int mask_stride, uint8_t *out,
                                    int out_stride, void *scratch,
                                    size_t scratch_size,
                                    fuse_refine_stats *stats);

/* ------------------------------------- refined pixels and the depth test
 *
 * The depth test against the virtual scene (fuse_depth, fuse_eye.depth)
 * needs the hand's depth at every pixel of the mask it tests, and keeps a
 * pixel whose depth is unknown (z not in [0, 1): the rasterizer's clear
 * value 1). A mask refined by colour (fuse_refine_mask*) has pixels the
 * model did not cover: they have no depth and would be drawn over a
 * virtual object that hides the hand beside them. fuse_depth_fill gives
 * them one:
 *   every pixel with mask != 0 whose depth is unknown takes the depth of
 *   the nearest pixel (Euclidean; ties: the upper row, then the left
 *   column) within a square of half width radius whose depth is known
 *   (the depths as they were before the call: filled pixels are never
 *   sources); with none there it gets the largest float below 1 (the far
 *   plane), so that any virtual object hides it.
 * A refined pixel lies within band (chamfer, which is at most 6% short of
 * Euclidean) of the kinematic mask's edge, so radius = band + band / 8 + 2
 * always finds the model's surface beside it. The pixel is then hidden
 * exactly where the virtual scene is in front of that surface. Pixels
 * with mask == 0 and pixels with a known depth are not written. One
 * scalar code for every ISA (the depth test's ISA paths then see the same
 * depths). Returns the number of pixels written and, in box (may be NULL),
 * their bounding box x0, y0, x1, y1 (exclusive; all 0 when none): a
 * caller whose depth buffer must stay the rasterizer's (rast_context_clear
 * clears only what the draws touched) sets the box's pixels outside the
 * kinematic mask back to 1 after the depth test. -1 for NULL pointers, a
 * size outside 1..FUSE_MAX_DIM, strides below width, radius outside
 * 1..FUSE_DEPTH_FILL_MAX_RADIUS (nothing written). */
#define FUSE_DEPTH_FILL_MAX_RADIUS 128
long fuse_depth_fill(const uint8_t *mask, int mask_stride, float *depth, int depth_stride,
                     int width, int height, int radius, int box[4]);

/* ------------------------------------------------- paths */

/* The refinement (fuse_refine_mask_global with g, fuse_refine_mask when g
 * is NULL: weight is then ignored) on a chosen path:
 *   EF_ISA_REF      the scalar reference above, whole-image passes: the
 *                   definition of every output byte;
 *   anything else   the band-only path (fuse_refine_fast.c: work only in
 *                   per-row ranges around the mask's edge, integer
 *                   histograms, tables, SIMD row kernels) of the ISA
 *                   fuse_refine_isa(isa) names.
 * Every path gives the same bytes and the same stats.
 * fuse_refine_mask and fuse_refine_mask_global run EF_ISA_DEFAULT (the
 * best the CPU has, capped by EGOFUSE_ISA). Same errors as those two. */
fuse_result fuse_refine_mask_isa(const fuse_refine_params *p, const fuse_colour_model *g,
                                 float weight, const fuse_image *P, const uint8_t *mask,
                                 int mask_stride, uint8_t *out, int out_stride, void *scratch,
                                 size_t scratch_size, fuse_refine_stats *stats, ef_isa isa);
/* The path fuse_refine_mask_isa takes for isa: EF_ISA_REF for EF_ISA_REF,
 * else ef_isa_choose(isa) (EF_ISA_DEFAULT: no cap) limited to the paths
 * this build has; EF_ISA_SSE2 names the portable band-only kernels. */
ef_isa fuse_refine_isa(ef_isa isa);

#ifdef __cplusplus
}
#endif
#endif
