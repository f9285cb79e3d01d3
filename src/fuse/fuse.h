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
 *          F  = clamp01(1 - N.V)^5,  H_i = normalize(L_i + V)
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
 *   power x^s is not powf(): an integer s up to 64 by squaring in a fixed
 *   order, any other s as exp2(s log2 x) with fixed polynomials
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
 *   3 * width floats, n10 normals: width uint32_t, RGB24: 3 * width
 *   bytes), both or neither of fuse_eye's normal forms, light_count outside
 *   0..FUSE_MAX_LIGHTS, shininess outside [1, FUSE_PARAM_MAX], another
 *   lighting float non-finite or beyond +-FUSE_PARAM_MAX, a light
 *   direction of (near) zero length, intrinsics with fx or fy outside
 *   [1e-3, 1e7] or |cx|, |cy| > 1e7, an empty viewport, or outputs that
 *   overlap their inputs other than as allowed below. FUSE_ERR_SIZE: out
 *   of another size than required, a viewport not inside V.
 *
 * WHAT IT DOES NOT
 *   fuse_light, fuse_composite and the format, depth and tone calls: no
 *   allocation, no threads, no global state, no file I/O. A fuse_context
 *   (below) owns a thread pool, created once.
 *
 * USAGE
 *   fuse_lighting L = fuse_lighting_default();
 *   fuse_image P = fuse_image_rows(cam640x480, 40, 400);   // eq. 1 crop
 *   fuse_light(&L, &K, &P, mask, mstride, nrm, nstride, &Q);
 *   fuse_composite(&Q, &V, 43, 27, 1194, 746, &R);
 */
#ifndef EGOFUSE_FUSE_H
#define EGOFUSE_FUSE_H

#include <stddef.h>
#include <stdint.h>

#include "../cpu/cpu.h"

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

/* fuse_light with the normals packed as ef_n10 (src/cpu/ef_n10.h: one
 * uint32_t per pixel, bits 0-9 x, 10-19 y, 20-29 z, each k in -511..511
 * meaning k / 511), normal_n10_stride uint32_t per row (>= P's width, else
 * FUSE_ERR_ARGS; NULL normal_n10: FUSE_ERR_ARGS). Bits 30-31 are ignored
 * (ef_n10_pack writes 0 there); k = -512 (0x200), which ef_n10_pack never
 * writes, stands for -512 / 511. The bytes are, on every ISA, those of
 * fuse_light given the floats ef_n10_unpack makes of the same normals:
 * (float)k * (1.0f / 511.0f) per component (a zero normal, as any normal
 * without a usable length, is replaced by V). Same checks, overlaps and
 * errors otherwise. */
fuse_result fuse_light_n10(const fuse_lighting *L, const fuse_intrinsics *K,
                           const fuse_image *P, const uint8_t *mask,
                           int mask_stride, const uint32_t *normal_n10,
                           int normal_n10_stride, fuse_image *out);

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

/* ---- camera formats ----------------------------------------------------
 *
 * What V4L2 delivers, to RGBA8 (alpha 255), with the eq. 1 crop: rows
 * [y0, y0 + out->height) of the frame become out (out->width = frame
 * width). Integer arithmetic, the same bytes on every machine
 * (docs/fuse.md, "Camera formats"):
 *   YUYV, UYVY  4:2:2, BT.601 limited range (V4L2's default for them):
 *               C = Y-16, D = U-128, E = V-128,
 *               R = (298C + 409E + 128) >> 8, G = (298C - 100D - 208E + 128) >> 8,
 *               B = (298C + 516D + 128) >> 8, each clamped to 0..255
 *               (within 1 of the double-precision BT.601 matrix, tested);
 *               both pixels of a pair use the pair's U, V. Width even.
 *   GREY        R = G = B = Y (full range).
 *   BAYER_*     8-bit raw Bayer, named by the colours of the top-left 2x2
 *               (of the whole frame: the crop keeps the pattern's phase),
 *               bilinear demosaic: a missing colour is the rounded mean of
 *               its 2 or 4 nearest samples of that colour; beyond the frame
 *               the samples mirror (x = -1 reads x = 1). Rows just outside
 *               the crop are read when the frame has them. Width, height >= 2.
 *   RGB24, BGR24 packed 3 bytes per pixel.
 * FUSE_ERR_ARGS: NULL, unknown format, width/height outside
 * 1..FUSE_MAX_DIM, stride below the row's bytes, odd width for YUYV/UYVY,
 * Bayer narrower or lower than 2. FUSE_ERR_SIZE: size below
 * (height - 1) * stride + row bytes, a crop outside the frame, out of
 * another width. Nothing is written unless FUSE_OK. */
typedef enum fuse_format {
    FUSE_FMT_YUYV = 1,
    FUSE_FMT_UYVY,
    FUSE_FMT_GREY,
    FUSE_FMT_BAYER_RGGB,
    FUSE_FMT_BAYER_GRBG,
    FUSE_FMT_BAYER_GBRG,
    FUSE_FMT_BAYER_BGGR,
    FUSE_FMT_RGB24,
    FUSE_FMT_BGR24
} fuse_format;

typedef struct fuse_frame {
    const uint8_t *data;
    size_t size;              /* bytes available at data */
    int width, height;        /* pixels */
    int stride;               /* bytes per row */
    fuse_format format;
} fuse_frame;

/* Bytes of one row of width pixels in format f (0 for an unknown f). */
int fuse_format_row_bytes(fuse_format f, int width);
fuse_result fuse_frame_to_rgba(const fuse_frame *src, int y0, fuse_image *out);
/* The same on at most ISA cap (EF_ISA_DEFAULT: the best; EGOFUSE_ISA caps
 * further). YUYV and UYVY have an AVX2 path; the bytes never differ. */
fuse_result fuse_frame_to_rgba_isa(const fuse_frame *src, int y0, fuse_image *out,
                                   ef_isa cap);

/* ---- depth test against the virtual scene ------------------------------
 *
 * Conventions (docs/fuse.md, "Depth"):
 *   hand   window depth z in [0, 1] per pixel of the lit layer Q (camera
 *          resolution), as the rasterizer writes it (rast_target.depth,
 *          z = z_ndc/2 + 1/2 of an OpenGL-style projection with znear,
 *          zfar, e.g. kin_mat4_perspective). z >= 1 (the clear value) or
 *          not finite: no depth known, the hand pixel is kept.
 *          Its metric distance along the view axis is
 *            d = 2 zfar znear / ((zfar + znear) - (2z - 1)(zfar - znear))
 *          and offset is added (metres: e.g. D = 0.085 when the scene's
 *          distances are measured from the eye and the camera sits D in
 *          front of it; 0 when both are from the camera).
 *   scene  per pixel of V (output resolution): the virtual scene's metric
 *          distance along the view axis, metres. 0, negative, inf or NaN:
 *          nothing there (the hand is in front).
 * A pixel (x, y) of Q compares with the scene pixel its centre falls on,
 *   ox = vp_x0 + floor((2x + 1) vp_w / (2 Q.width)), the same for y,
 * and is set to (0, 0, 0, 0) when scene < d + offset (strictly): the
 * virtual object in front hides the hand; the hand in front shows. The
 * test runs at camera resolution before the composite, so the bilinear
 * resampling softens the occlusion edge like the mask's edge. Float, in
 * the operation order above; pixels of Q that are 0 are not looked at. */
typedef struct fuse_depth {
    const float *hand;        /* Q's size, hand_stride floats per row */
    int hand_stride;
    float znear, zfar;        /* 0 < znear < zfar <= 1e7 */
    float offset;             /* metres added to the hand's distance */
    const float *scene;       /* V's size, scene_stride floats per row */
    int scene_stride;
    int scene_width, scene_height;   /* V's size */
} fuse_depth;

/* Hides the pixels of the layer Q (in place) that the virtual scene
 * covers; vp_* is the composite's viewport in V. FUSE_ERR_ARGS: NULL,
 * strides below the widths, near/far out of range, offset not finite or
 * beyond +-FUSE_PARAM_MAX. FUSE_ERR_SIZE: viewport not inside the scene.
 * Runs on the best ISA allowed (as fuse_light); every ISA gives the
 * bytes of the scalar reference (fuse_context_depth_test below). */
fuse_result fuse_depth_test(const fuse_depth *d, fuse_image *Q, int vp_x0,
                            int vp_y0, int vp_w, int vp_h);

/* ---- colour tone matching ----------------------------------------------
 *
 * Gray-world statistics: the mean colour of the camera image where the
 * mask is 0 (the real room, whose light also falls on the hands) and the
 * mean colour of V inside the viewport (the virtual scene's light). The
 * tone that carries one into the other is
 *   t_c = (mean_V_c + 1) / (mean_P_c + 1),  clamped to [1/4, 4],
 *   tone_c = t_c ^ strength           (strength 0: 1, no change; 1: full)
 * which matches white balance and brightness at once. Every 4th pixel of
 * every 4th row is sampled (x, y multiples of 4 from the image's or the
 * viewport's corner); sums are exact integers, the rest in double, so the
 * result is the same on every machine. A scene of one strong colour
 * (a blue sky) tints the hands: lower strength for such scenes. Put
 * tone into fuse_lighting.tone. FUSE_ERR_ARGS: NULL, bad image or mask
 * stride, strength outside [0, 1]. FUSE_ERR_SIZE: viewport not in V. */
fuse_result fuse_tone_match(const fuse_image *P, const uint8_t *mask,
                            int mask_stride, const fuse_image *V, int vp_x0,
                            int vp_y0, int vp_w, int vp_h, float strength,
                            float tone[3]);

/* ---- contexts: ISA choice and threads ---------------------------------
 *
 * fuse_light and fuse_composite above run on the calling thread with the
 * best ISA that ef_isa_choose(EF_ISA_DEFAULT) allows (cpuid capped by
 * EGOFUSE_ISA). A context lets the caller cap the ISA and use several
 * threads. Every ISA and every thread count gives the same bytes as the
 * scalar reference (EF_ISA_REF), which defines them (docs/fuse.md).
 *
 *   fuse_context_desc d = {0};
 *   d.max_isa = EF_ISA_DEFAULT;   // or EF_ISA_REF .. EF_ISA_AVX512
 *   d.threads = 2;
 *   fuse_context *ctx = fuse_context_create(&d);
 *   printf("fuse: %s\n", ef_isa_name(fuse_context_isa(ctx)));
 *   fuse_eye eyes[2] = {...};
 *   fuse_context_frame(ctx, eyes, 2);        // both eyes, every stage
 *   fuse_context_destroy(ctx);
 *
 * fuse_context_create allocates the context and starts threads - 1 worker
 * threads; the calls below allocate nothing. A context runs one call at a
 * time (calls on one context from several threads must be serialised);
 * different contexts are independent. */
#define FUSE_MAX_THREADS 16

typedef struct fuse_context fuse_context;

typedef struct fuse_context_desc {
    ef_isa max_isa;   /* cap: EF_ISA_DEFAULT (0) = the best the CPU has; */
                      /* EGOFUSE_ISA caps further (ef_isa_choose)        */
    int threads;      /* 0 or 1: the calling thread only; at most        */
                      /* FUSE_MAX_THREADS (larger values are clamped)    */
} fuse_context_desc;

/* NULL desc = defaults. Returns NULL if out of memory or a thread could
 * not start. */
fuse_context *fuse_context_create(const fuse_context_desc *desc);
/* Stops the workers and frees ctx (NULL is a no-op). */
void fuse_context_destroy(fuse_context *ctx);
/* The ISA in use (ref, sse2, avx2, avx512) and the thread count. */
ef_isa fuse_context_isa(const fuse_context *ctx);
int fuse_context_threads(const fuse_context *ctx);

/* fuse_light and fuse_composite on ctx's ISA and threads (row bands).
 * Same arguments, checks, errors and bytes; ctx NULL -> FUSE_ERR_ARGS. */
fuse_result fuse_context_light(fuse_context *ctx, const fuse_lighting *L,
                               const fuse_intrinsics *K, const fuse_image *P,
                               const uint8_t *mask, int mask_stride,
                               const float *normal, int normal_stride,
                               fuse_image *out);
/* fuse_light_n10 on ctx's ISA and threads; ctx NULL -> FUSE_ERR_ARGS. */
fuse_result fuse_context_light_n10(fuse_context *ctx, const fuse_lighting *L,
                                   const fuse_intrinsics *K, const fuse_image *P,
                                   const uint8_t *mask, int mask_stride,
                                   const uint32_t *normal_n10, int normal_n10_stride,
                                   fuse_image *out);
fuse_result fuse_context_composite(fuse_context *ctx, const fuse_image *Q,
                                   const fuse_image *V, int vp_x0, int vp_y0,
                                   int vp_w, int vp_h, fuse_image *out);
/* fuse_depth_test on ctx's ISA and threads; ctx NULL -> FUSE_ERR_ARGS. */
fuse_result fuse_context_depth_test(fuse_context *ctx, const fuse_depth *d, fuse_image *Q,
                                    int vp_x0, int vp_y0, int vp_w, int vp_h);

/* One eye of a stereo frame for fuse_context_frame: light P into Q (the
 * caller's scratch layer, P's size), optionally hide what the virtual
 * scene covers (depth, NULL: no depth test), composite Q into the viewport
 * of V giving out (out may be V). Each field as in the calls above. */
typedef struct fuse_eye {
    const fuse_lighting *lighting;
    const fuse_intrinsics *intrinsics;
    fuse_image P;
    const uint8_t *mask;
    int mask_stride;
    const float *normal;
    int normal_stride;
    fuse_image Q;
    const fuse_depth *depth;
    fuse_image V;
    int vp_x0, vp_y0, vp_w, vp_h;
    fuse_image out;
    /* 1: the caller promises that every pixel of V inside the viewport has
     * alpha 255 (a rendered scene, a frame already composited once). The
     * pixels that the layer does not reach (four zero taps) are then out = V
     * without a look at V: in place (out == V) they are neither read nor
     * written, out of place they are copied. With an opaque V the bytes are
     * those of v_opaque = 0. If the promise is broken, rgb is still exact
     * and the alpha of those pixels is V's or 255: V's in every group of
     * 16 viewport columns whose taps all lie in blocks of 8 layer pixels
     * that are zero (both layer rows), 255 in the others; the same bytes
     * on every ISA, the reference included. 0 (the default): no promise,
     * alpha 255 everywhere in the viewport (an in-place composite reads
     * all of V to check it). */
    int v_opaque;
    /* Soft edges where the camera image ends inside the display (issue 18;
     * fuse_edge.h): edge_fade = k (0: off, the bytes of before; at most
     * FUSE_EDGE_FADE_MAX), edge_sides = the FUSE_EDGE_* sides of Q to fade.
     * Each row of Q, once lit and depth-tested, is faded over its last k
     * pixels towards those sides (fuse_edge_fade_row), before the
     * composite reads it. */
    int edge_fade;
    unsigned edge_sides;
    /* NULL (the default): every row of Q is written. Otherwise Q.height
     * bytes that the caller keeps with Q from one call to the next, 0 at
     * first (or whenever Q was written by anything else): the call sets
     * byte y to 1 when it leaves row y of Q all 0 because the mask's row
     * is empty, to 0 otherwise, and does not clear again a row whose byte
     * is 1 and whose mask row is still empty. Q's bytes are those of NULL;
     * the hand's rows only are written (issue 17: the empty rows were
     * about 1 MB of memset per stereo frame). */
    uint8_t *q_zero_rows;
    /* With normal NULL: the normals packed as ef_n10 (src/cpu/ef_n10.h; as
     * fuse_light_n10), normal_n10_stride uint32_t per row >= P's width.
     * Exactly one of normal and normal_n10 is set (both or neither:
     * FUSE_ERR_ARGS); the stride of the one not set is not looked at. At
     * the end of the struct, so positional initialisers written before it
     * still mean what they meant (normal_n10 then 0). fuse_normal_smooth
     * (fuse_normals.h) reads and writes float normals only: a caller that
     * smooths passes the smoothed floats in normal. */
    const uint32_t *normal_n10;
    int normal_n10_stride;
} fuse_eye;

/* Every stage of count eyes (1..FUSE_MAX_THREADS) on ctx's threads: with
 * as many threads as eyes (or a multiple), each thread takes whole eyes;
 * otherwise every stage is split into row bands. All eyes are checked
 * before any is written; on an error nothing is written. */
fuse_result fuse_context_frame(fuse_context *ctx, const fuse_eye *eyes, int count);

/* One eye of fuse_context_frame in bands of output rows, for threads of
 * the caller's own (issue 17: two threads share an eye's work):
 *
 *   int n;
 *   if (fuse_context_frame_prepare(ctx, &eye, 64, &n) == FUSE_OK) {
 *       for (int b = 0; b < n; b++)            // on any threads, each b once
 *           fuse_context_frame_band(ctx, b);
 *       fuse_context_frame_finish(ctx);        // once every band returned
 *   }
 *
 * prepare checks eye as fuse_context_frame(ctx, eye, 1) does (same errors;
 * nothing written) and keeps it in ctx: *bands = ceil(out.height /
 * band_rows) (band_rows >= out.height: one band). The images, mask and
 * normals of eye must stay as they are until finish returns; eye itself,
 * its lighting, intrinsics and depth description are copied. Band b lights
 * (and depth-tests, fades) the layer rows that only its output rows
 * [b band_rows, (b + 1) band_rows) read first, then composites those rows,
 * interleaved as fuse_context_frame's own order, except the few last rows
 * that also read the next band's first layer row: finish composites them.
 * Different bands write different bytes, so they may run at once on
 * different threads (never the same band twice; prepare and finish on one
 * thread, ordered before and after every band by the caller, e.g. with a
 * mutex). The bytes are fuse_context_frame's on every ISA and band size.
 * The bands run on the calling thread (ctx's pool is not used); a context
 * holds one prepared eye at a time. */
fuse_result fuse_context_frame_prepare(fuse_context *ctx, const fuse_eye *eye, int band_rows,
                                       int *bands);
void fuse_context_frame_band(const fuse_context *ctx, int band);
void fuse_context_frame_finish(fuse_context *ctx);

/* A static English message for r (never NULL). */
const char *fuse_result_str(fuse_result r);

#ifdef __cplusplus
}
#endif
#endif
