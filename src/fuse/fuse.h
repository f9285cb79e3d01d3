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
 * NUMBERS (docs/rounding.md says it once for all paths)
 *   Images are RGBA8, 4 bytes per pixel in memory order R G B A.
 *   fuse_light works in float: P/255, lighting, clamp to [0,1], then
 *   u8 = (int)(v * 255 + 0.5). Rgb of Q is rounded from M'*P' in float.
 *   fuse_composite is integer: the source coordinate of output pixel centre
 *   x is sx = (x + 0.5) * sw / vw - 0.5 in 16.16 fixed point, clamped to
 *   the edge pixels (edge pixels replicate); weights are the top 8 bits of
 *   the fraction; the four taps are blended as
 *     ((a(256-fx) + b fx)(256-fy) + (c(256-fx) + d fx) fy + 32768) >> 16
 *   and over is R = Q + div255((255 - Ma) V) with
 *   div255(t) = (t + 128 + ((t + 128) >> 8)) >> 8 (exact rounding).
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

/* Camera intrinsics of the image being lit: the view vector of pixel
 * (x, y) is V = -normalize(((x+.5-cx)/fx, -(y+.5-cy)/fy, -1)). */
typedef struct fuse_intrinsics { float fx, fy, cx, cy; } fuse_intrinsics;

/* One light from above-front, ambient 0.35, kd 0.75, ks 0.15, s 16,
 * kf 0.6, tone 1: gentle shading, soft edges. */
fuse_lighting fuse_lighting_default(void);

/* A view of rows [y0, y0+h) of img (the crop of eq. 1 costs no copy). */
fuse_image fuse_image_rows(const fuse_image *img, int y0, int h);

/* The lighting layer (step 1). P, mask (u8, mask_stride bytes per row) and
 * normal (3 floats per pixel, normal_stride floats per row, need not be
 * unit length) have P's size; out (premultiplied RGBA8) too. Pixels with
 * M == 0 get (0,0,0,0). */
fuse_result fuse_light(const fuse_lighting *L, const fuse_intrinsics *K,
                       const fuse_image *P, const uint8_t *mask,
                       int mask_stride, const float *normal,
                       int normal_stride, fuse_image *out);

/* Resample the premultiplied layer Q into the viewport (vp_x0, vp_y0,
 * vp_w, vp_h) of V and composite; out has V's size (out may be V itself).
 * The viewport must lie inside V. Alpha of out is 255. */
fuse_result fuse_composite(const fuse_image *Q, const fuse_image *V,
                           int vp_x0, int vp_y0, int vp_w, int vp_h,
                           fuse_image *out);

/* Fills an RGBA8 image from packed RGB24 (stride in bytes), alpha 255. */
fuse_result fuse_rgb24_to_rgba(const uint8_t *rgb, int stride, int width,
                               int height, fuse_image *out);

const char *fuse_result_str(fuse_result r);

#ifdef __cplusplus
}
#endif
#endif
