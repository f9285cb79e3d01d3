/* fuse.h - lighting layer, resampling and compositing of egofuse (scalar
 * reference).
 *
 * WHAT IT DOES
 *   For one eye, from the cropped camera image P (640x400 by default), the
 *   model's coverage mask M and per-pixel view-space normals N (both from
 *   the rasterizer, at the camera's resolution), and the virtual scene's
 *   image V (1280x800):
 *     1. fuse_light(): the lighting layer of the paper (Blinn-Phong + Fresnel,
 *        eq. 6), at camera resolution, only where M > 0:
 *          C  = a + sum_i c_i (kd max(0, N.L_i) + ks max(0, N.H_i)^s)
 *          F  = max(0, 1 - N.V)^2,   H_i = normalize(L_i + V)
 *          P' = clamp(P * C * tone),  M' = M * clamp(1 - kf F)
 *        and writes the premultiplied layer Q = (M' P', M') as RGBA8.
 *     2. fuse_composite(): bilinear resampling of Q into the viewport (eq. 4,
 *        1194x746 centred in 1280x800) and R = Q + (1 - M') V ("over" with a
 *        premultiplied source, which is R = M'P' + (1-M')V). Outside the
 *        viewport R = V.
 *   Resampling premultiplied colour keeps the background that the mask cut
 *   away from bleeding into the edge of the hand.
 *
 * NUMBERS (docs/fuse.md states every rule once, with the exact float
 * operation order; the fuse part of docs/rounding.md refers to it)
 *   Images are RGBA8, 4 bytes per pixel in memory order R G B A.
 *   fuse_light works in float (IEEE single, no FMA, one fixed operation
 *   order; u8/255 is computed as u8 * (1.0f/255.0f)): P/255, lighting,
 *   clamp to [0,1], then u8 = (int)(v * 255 + 0.5).
 *   Rgb of Q is rounded from M'*P' in float, alpha from M'. The specular
 *   power x^s is not powf() but exp2(s log2 x) with fixed polynomials
 *   (fuse_internal.h), so that every ISA gives the same bits.
 *   The view vector of pixel (x, y) comes from the intrinsics (below);
 *   N is normalised, and a normal of zero, huge or non-finite length
 *   (|N|^2 outside (1e-30, 1e30)) is replaced by V. Pixels with M == 0
 *   are (0,0,0,0) whatever N and P hold.
 *   fuse_composite is integer: the source coordinate of output pixel centre
 *   x (counted from the viewport's left edge) is sx = (x + 0.5) sw / vw - 0.5
 *   in 16.16 fixed point, computed exactly as
 *     sx16 = floor(((2x + 1) sw - vw) 65536 / (2 vw)),
 *   clamped to [0, (sw - 1) 65536] (edge pixels replicate: the taps beyond
 *   the last pixel repeat it); the same for y with sh, vh. Weights are the
 *   top 8 bits of the fraction, fx = (sx16 >> 8) & 255; the four taps are
 *   blended as
 *     ((a(256-fx) + b fx)(256-fy) + (c(256-fx) + d fx) fy + 32768) >> 16
 *   and over is R = min(255, Q + div255((255 - Qa) V)) per colour, with
 *   div255(t) = (t + 128 + ((t + 128) >> 8)) >> 8 (exact rounding).
 *
 * ERRORS
 *   Nothing is written unless the call returns FUSE_OK. FUSE_ERR_ARGS: a
 *   NULL pointer, an image with NULL pixels, a width or height outside
 *   1..FUSE_MAX_DIM, a stride below 4 * width (mask: width, normal:
 *   3 * width floats, RGB24: 3 * width bytes), light_count outside
 *   0..FUSE_MAX_LIGHTS, shininess outside [1, FUSE_PARAM_MAX], another
 *   lighting float non-finite or beyond +-FUSE_PARAM_MAX, a light
 *   direction of (near) zero length, intrinsics with fx or fy outside
 *   [1e-3, 1e7] or |cx|, |cy| > 1e7, an empty viewport, or outputs that
 *   overlap their inputs other than as allowed below. FUSE_ERR_SIZE: out
 *   of another size than required, a viewport not inside V.
 *
 * WHAT IT DOES NOT
 *   No allocation, no threads, no global state, no file I/O.
 *
 * USAGE
 *   fuse_lighting L = fuse_lighting_default();
 *   fuse_image P = fuse_image_rows(cam640x480, 40, 400);   // eq. 1 crop
 *   fuse_light(&L, &K, &P, mask, mstride, nrm, nstride, &Q);
 *   fuse_composite(&Q, &V, 43, 27, 1194, 746, &R);
 */
#ifndef EGOFUSE_FUSE_H
#define EGOFUSE_FUSE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FUSE_MAX_LIGHTS 8
/* Largest width or height of any image (keeps the 16.16 positions in
 * int32 and every product in range). */
#define FUSE_MAX_DIM 16384
/* Bound on the magnitude of every float in fuse_lighting (no overflow). */
#define FUSE_PARAM_MAX 1.0e6f

typedef enum fuse_result {
    FUSE_OK = 0,
    FUSE_ERR_ARGS,        /* NULL pointer, bad stride, bad parameter */
    FUSE_ERR_SIZE         /* images whose sizes do not fit together */
} fuse_result;

/* An RGBA8 image (or view of one). stride in bytes, >= 4 * width. */
typedef struct fuse_image {
    uint8_t *pixels;
    int width, height;
    int stride;
} fuse_image;

/* A directional light, in the camera's view space. */
typedef struct fuse_light_src {
    float dir[3];         /* unit vector from the surface towards the light */
    float color[3];       /* linear weights, usually 0..1 */
} fuse_light_src;

typedef struct fuse_lighting {
    int light_count;                      /* 0..FUSE_MAX_LIGHTS */
    fuse_light_src lights[FUSE_MAX_LIGHTS];
    float ambient[3];                     /* a */
    float kd, ks, shininess;              /* k_d, k_s, s (s >= 1) */
    float kf;                             /* Fresnel edge fade, 0..1 */
    float tone[3];                        /* colour tone multiplier */
} fuse_lighting;

/* Camera intrinsics of the image being lit, in pixels of that image
 * (after the crop: cy is relative to the crop's first row). The view
 * vector of pixel (x, y), from the surface towards the camera, is
 * V = -normalize(((x+.5-cx)/fx, -(y+.5-cy)/fy, -1)) (view space: x right,
 * y up, the camera looks down -z). */
typedef struct fuse_intrinsics { float fx, fy, cx, cy; } fuse_intrinsics;

/* One white light from above-front (dir (0, 0.6, 0.8), colour 1),
 * ambient 0.35, kd 0.75, ks 0.15, s 16, kf 0.6, tone 1: gentle shading,
 * soft edges. */
fuse_lighting fuse_lighting_default(void);

/* A view of rows [y0, y0+h) of img (the crop of eq. 1 costs no copy).
 * Returns a zeroed image (pixels NULL, which every call rejects) if img
 * is NULL or the rows are not inside it (y0 < 0, h < 1, y0 + h > height). */
fuse_image fuse_image_rows(const fuse_image *img, int y0, int h);

/* The lighting layer (step 1). P, mask (u8, mask_stride bytes per row) and
 * normal (3 floats per pixel, normal_stride floats per row, need not be
 * unit length) have P's size; out (premultiplied RGBA8) too. Pixels with
 * M == 0 get (0,0,0,0). P's alpha is ignored. Light directions are
 * normalised once per call. out may be P itself (same pixels and stride)
 * and must not otherwise overlap P, mask or normal. Every written pixel
 * has r, g, b <= a. */
fuse_result fuse_light(const fuse_lighting *L, const fuse_intrinsics *K,
                       const fuse_image *P, const uint8_t *mask,
                       int mask_stride, const float *normal,
                       int normal_stride, fuse_image *out);

/* Resample the premultiplied layer Q into the viewport (vp_x0, vp_y0,
 * vp_w, vp_h) of V and composite; out has V's size (out may be V itself,
 * same pixels and stride; otherwise out overlaps neither V nor Q).
 * The viewport must lie inside V. Outside it out = V byte for byte
 * (alpha included); inside, alpha of out is 255. Q's rgb should not
 * exceed its alpha (premultiplied); if it does the sum is clamped to 255. */
fuse_result fuse_composite(const fuse_image *Q, const fuse_image *V,
                           int vp_x0, int vp_y0, int vp_w, int vp_h,
                           fuse_image *out);

/* Fills an RGBA8 image from packed RGB24 (stride in bytes), alpha 255.
 * out must have width x height pixels and must not overlap rgb. */
fuse_result fuse_rgb24_to_rgba(const uint8_t *rgb, int stride, int width,
                               int height, fuse_image *out);

/* A static English message for r (never NULL). */
const char *fuse_result_str(fuse_result r);

#ifdef __cplusplus
}
#endif
#endif
