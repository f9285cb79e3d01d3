/* fit_stereo.h - depth from the stereo pair in the refinement (issue 14
 * item 2, docs/accuracy.md "Every sequence").
 *
 * WHAT IT DOES
 *   The band refinement decides by colour alone, so a skin-coloured
 *   object behind the hand (a beige pad, a tan box) or a dark desk the
 *   colour models have learned as sleeve is taken in. The two cameras of
 *   the HMD see the scene from 65 mm apart: a pixel of the hand must look
 *   the same in the other camera at the disparity of the hand's depth,
 *   and a pixel of the desk behind it at a smaller disparity (farther).
 *   pipe_fit_stereo tests that photo-consistency on one eye's refined
 *   mask:
 *     1. the hand's depth near each pixel: the model's window depth at the
 *        pixel (the G-buffer of this eye's kinematic draw), or, where the
 *        model does not cover it, the depth of the nearest covered pixel
 *        within fill_radius (fuse_depth_fill's rule); pixels without one
 *        are not tested;
 *     2. a grey patch of (2 radius + 1)^2 pixels around the pixel; its
 *        texture t = the mean absolute deviation from its mean; below
 *        min_texture the patch is ambiguous (a plain surface matches at
 *        every disparity) and the pixel keeps the colour decision;
 *     3. the mean absolute difference (per pixel) of the patch against the
 *        other camera's image along the epipolar line, every pixel of it,
 *        for the depths of the hand, z_h - hand_dz .. z_h + hand_dz
 *        (c_hand, the smallest), and for the depths behind the hand,
 *        z_h + gap .. far_m (c_back, the smallest); a candidate whose
 *        patch leaves the other image is skipped; with none in a range
 *        that range's cost is unknown and the pixel is not decided;
 *     4. a tested pixel of out (>= 128) is background, set to 0, when
 *        c_back + margin < c_hand and c_back <= match * t (the patch
 *        really is found behind the hand, not just less badly missed);
 *        with `accept`, a tested pixel outside out within `accept` px of
 *        a set pixel (chamfer 1/1) is set to 255 when c_hand + margin <
 *        c_back and c_hand <= match * t (fingers beyond the model, at the
 *        hand's depth).
 *   Only every `step`-th pixel in x and y is tested (the grid); with step
 *   > 1 a decision applies to the step x step cell around its sample and
 *   the cells on the border between a background cell and a hand or
 *   untested cell are tested again at every pixel.
 *   The cameras need not be rectified: each candidate is the other
 *   camera's projection of the point at that depth on the pixel's ray
 *   (pinhole part of each camera: a distorting lens is not undone).
 *
 * WHAT IT DOES NOT
 *   No allocation (the caller gives scratch), no threads, no state. Pure
 *   C, libc + libm.
 */
#ifndef EGOFUSE_FIT_STEREO_H
#define EGOFUSE_FIT_STEREO_H

#include <stddef.h>
#include <stdint.h>

#include "../fuse/fuse.h"
#include "../kin/kin.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pipe_fit_stereo_desc {
    int radius;          /* patch half width, 1..4 (2: 5x5) */
    int step;            /* grid step, 1..8 (2) */
    float hand_dz;       /* metres either side of the model's depth (0.04) */
    float gap;           /* metres behind the model where the background
                            starts (0.06) */
    float far_m;         /* farthest depth tested, metres (3) */
    float min_texture;   /* grey levels (4) */
    float margin;        /* grey levels per pixel (2) */
    float match;         /* the winning cost must be <= match * texture (1) */
    float ratio;         /* and <= ratio * the losing cost (1: off) */
    int fill_radius;     /* pixels, 1..128 (32) */
    int accept;          /* pixels beyond out tested for the hand (0: none) */
    int connected;       /* 1: background only where connected to the
                            outside of out through background (1) */
} pipe_fit_stereo_desc;

pipe_fit_stereo_desc pipe_fit_stereo_desc_default(void);

/* Bytes of scratch pipe_fit_stereo needs for a width x height image. */
size_t pipe_fit_stereo_scratch_size(int width, int height);

typedef struct pipe_fit_stereo_stats {
    long tested;         /* patches compared (grid and border pixels) */
    long textureless;    /* of those, below min_texture */
    long cleared;        /* pixels of out set to 0 */
    long added;          /* pixels set to 255 */
} pipe_fit_stereo_stats;

/* One eye's step: cam and P (RGBA8) are this eye's camera and image,
 * other and Q the other camera's (the same size); depth: this eye's
 * window depths of the model (rast_target's, 1 = not covered; depth_stride
 * floats per row), out: the refined mask (0/255, stride bytes per row),
 * changed in place. scratch: pipe_fit_stereo_scratch_size bytes, 16-byte
 * aligned. d NULL = defaults. Returns 0, or -1 for bad arguments (nothing
 * changed). stats may be NULL. */
int pipe_fit_stereo(const pipe_fit_stereo_desc *d, const kin_camera *cam, const fuse_image *P,
                    const kin_camera *other, const fuse_image *Q, const float *depth,
                    int depth_stride, uint8_t *out, int stride, void *scratch,
                    size_t scratch_size, pipe_fit_stereo_stats *stats);

#ifdef __cplusplus
}
#endif
#endif
