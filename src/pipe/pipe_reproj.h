/* pipe_reproj.h - the hands as the eye sees them: reprojection from the
 * cameras to the eyes by the model's depth (issue 18 items 1, 3; docs/eyeview.md).
 *
 * WHAT IT DOES
 *   The paper's correction of the camera offset D (eq. 2-4: crop, scale,
 *   viewport) is exact only for a plane at F = 1 m. With
 *   pipe_desc.eye_view = PIPE_VIEW_REPROJECT each eye instead
 *     1. draws the posed model from the EYE (kin_sthmd_eye_camera: the
 *        eye at +-ipd/2 with the head's orientation, a pinhole of the
 *        display's FOVs) into an eye G-buffer of the crop's size
 *        (640 x 400 for the paper), covering the whole display;
 *     2. for every covered eye pixel, takes its 3D point from the eye
 *        depth, projects it into the real camera (pipe_camera(), through
 *        its lens: kin_lens_project, so no undistort pass) and samples
 *        the cropped camera image there (bilinear, only the taps inside
 *        the camera's own mask that show the same surface (the occlusion
 *        test below), renormalised, so neither the room behind the hand
 *        nor a part in front of the point bleeds into it);
 *     3. hands that eye-view image, mask and normals to the unchanged fuse
 *        stage (lighting in the eye's view, depth test against the virtual
 *        scene with the EYE's depths, offset 0), composited into the
 *        whole display (viewport 0, 0, lcd_width, lcd_height): the output
 *        geometry is the eye's, as a virtual scene rendered for the eye.
 *   The crop method (PIPE_VIEW_CROP, the default) is untouched: its bytes
 *   are those of before.
 *
 * THE FILL (pixels the eye sees but the camera does not)
 *   A covered eye pixel is
 *     sampled  its point projects inside the camera image and the camera
 *              sees it: the camera's G-buffer has the model at the nearest
 *              camera pixel, no nearer than the point's own distance minus
 *              PIPE_REPROJ_TOL_M + PIPE_REPROJ_TOL_REL * distance;
 *     filled   it projects inside the camera image but the camera does not
 *              see it (hidden behind another part: a finger behind the
 *              palm, the disocclusion at a hand's edge): it takes the
 *              colour of a sampled pixel on its own surface
 *              (pipe__reproj_fill): of the nearest sampled pixels to its
 *              left and right in its eye row and above and below in its
 *              column (each search ends where the eye's mask does: a run
 *              of the part's pixels), those whose eye distance is within
 *              the occlusion test's slack of the nearest one, the nearest
 *              in pixels (left, right, above, below on a tie), so the
 *              background that a disocclusion reveals is filled from the
 *              background, not from the hand in front, and not from
 *              another part far along the row; a pixel with none of the
 *              four takes the colour of the nearest coloured pixel of the
 *              nearest other row that has sampled pixels
 *              (pipe__reproj_fill_cols); an
 *              eye without any is not shown (mask 0);
 *     outside  its point projects outside the camera image (or behind
 *              the camera, or beyond the lens's valid region): mask 0.
 *   Near the camera image's border the mask fades: M = 255 * min(1, b /
 *   PIPE_REPROJ_FADE_PX) (rounded), b the distance in camera pixels of the
 *   projected point to the nearest border, so the hands fade out where the
 *   camera's view ends instead of a hard cut.
 *
 * FALLBACK (the eye inside the model)
 *   When the eye's view is inside the model - more than half the covered
 *   eye pixels see a back face (the normal turned away from the eye), or
 *   the model comes nearer than PIPE_REPROJ_MIN_DIST_M to the eye - the
 *   eye falls back to the crop method for that frame
 *   (pipe_frame_stats.view[eye] = PIPE_VIEW_CROP, view_fallbacks counts
 *   them). With RAST_CULL_BACK an eye inside a closed mesh sees none of
 *   it: the frame shows what else is in front, never garbage.
 *
 * NUMBERS
 *   On the eye's thread: the per-pixel geometry on the vector layer
 *   (pipe_reproj_simd.inl, 4/8/16 lanes; a distorting lens in scalar
 *   double), equal lane by lane to the scalar reference row_ref (float,
 *   fixed operation order); the taps too (pipe__reproj_taps_<isa>: the
 *   G-buffer and image by gathers, integer bilinear weights with 8-bit
 *   fractions as fuse_composite, the renormalisation exact), equal to the
 *   scalar taps of pipe__reproj_sample: the same bytes on every ISA and
 *   thread count.
 *
 * THE WHOLE SENSOR
 *   The image sampled is the whole camera image (pipe_frame_in.camera[e]
 *   of the HMD's camera size, or camera_raw[e] converted whole), not only
 *   the crop of eq. 1; the camera's G-buffer covers the crop only, and
 *   beyond it the camera is taken to see the point (every tap counts).
 *
 * LIMITS
 *   pipe_desc.aa_samples is refused with reprojection (pipe_create NULL).
 *   refine_band still refines the camera's mask (the elbow fit learns
 *   from it) but the eye's mask composited is the model's. The tone
 *   match compares the camera's room with V over the whole display.
 */
#ifndef EGOFUSE_PIPE_REPROJ_H
#define EGOFUSE_PIPE_REPROJ_H

#include <stdint.h>

#include "../fuse/fuse.h"
#include "../kin/kin.h"
#include "../kin/kin_lens.h"

#ifdef __cplusplus
extern "C" {
#endif

/* pipe_desc.eye_view */
enum { PIPE_VIEW_CROP = 0, PIPE_VIEW_REPROJECT = 1 };

#define PIPE_REPROJ_FADE_PX 4.0f     /* fade width at the camera's border */
#define PIPE_REPROJ_TOL_M 0.005f     /* occlusion test: absolute slack */
#define PIPE_REPROJ_TOL_REL 0.02f    /* ... plus this fraction of the distance */
#define PIPE_REPROJ_MIN_DIST_M 0.02f /* nearer to the eye: inside the model */
/* The physical range of the reprojection's HMD numbers (pipe_view_check):
 * IPD 40..90 mm (adults span about 50..78 mm), D 0..250 mm. */
#define PIPE_IPD_MIN_M 0.04f
#define PIPE_IPD_MAX_M 0.09f
#define PIPE_CAM_OFFSET_MAX_M 0.25f

/* "crop" or "reproject" -> PIPE_VIEW_*: 0, or -1 for another name. */
int pipe_view_parse(const char *name, int *view);
/* "crop", "reproject", or "?" */
const char *pipe_view_name(int view);
/* The resolved ipd_m and cam_offset_m of hmd within the ranges above: 0,
 * or -1 with a sentence naming the field, its value and the range. Zero
 * is the default (65 mm, 85 mm); a negative or NaN value, which
 * kin_sthmd_desc_resolved would also take as the default, is refused
 * here: for the reprojection it is a mistake, not a wish. */
int pipe_view_check(const kin_sthmd_desc *hmd, char *why, int why_size);

/* ---------------------------------------- internal to src/pipe (pipe.c) */

typedef struct pipe__reproj {
    int width, height;        /* the eye layer: the crop's size */
    float *depth;             /* the eye's G-buffer: depth, */
    uint32_t *n10;            /* normals packed (ef_n10.h), */
    uint8_t *mask;            /* mask; and the normals as floats for */
    float *nrm;               /* fuse_normal_smooth, or NULL (init) */
    uint8_t *P;               /* RGBA8: camera colours seen from the eye */
    uint8_t *M;               /* the mask composited (fade, fill) */
    int32_t *row;             /* width: the eye rays' x; then height bytes: the rows' kinds */
    int32_t *lanes;           /* 8 * width: one row's geometry (pipe__reproj_lanes) */
    int isa;                  /* the geometry pass's ISA (ef_isa; pipe.c sets it) */
    kin_camera cam;           /* this frame's eye camera */
    long sampled, filled, outside; /* this frame's pixels of each kind */
    int inside;               /* this frame: the eye is inside the model */
} pipe__reproj;

/* One eye row's per-pixel geometry, for the covered pixels (the others
 * are not written): mv the mask (0: outside the camera image, else the
 * faded 1..255), zmin the occlusion bound as a window depth of the
 * camera, iu/iv the nearest camera pixel, tx/ty the bilinear's top-left
 * tap, fx/fy its 8-bit fractions. */
typedef struct pipe__reproj_lanes {
    int32_t *mv, *iu, *iv, *tx, *ty, *fx, *fy;
    float *zmin;
} pipe__reproj_lanes;

/* What the geometry pass needs of the frame (the eye view -> camera view
 * matrix, column-major, the camera's pinhole, the image's size, the depth
 * range). */
typedef struct pipe__reproj_geo {
    float a[16];
    float cfx, cfy, ccx, ccy;
    float cw, ch, cw1, ch1; /* the sampled image's size and size - 1 */
    float ox, oy;           /* the crop's (the G-buffer's) origin in the image */
    int icw1, ich1;
    float n, f, fpn, fmn, two_fn; /* near, far, f + n, f - n, 2 f n */
    int pinhole;
    const kin_lens *lens;   /* !pinhole: kin_lens_project */
    const float *rxs;       /* the eye rays' x per column */
} pipe__reproj_geo;

/* The vector geometry pass per ISA (pipe_reproj_simd.inl) over columns
 * [x0, w): the first column it did not do. The pinhole camera only. */
typedef int pipe__reproj_row_t(const pipe__reproj_geo *g, const uint8_t *em, const float *ed,
                               const uint32_t *en, float ry, int x0, int w,
                               const pipe__reproj_lanes *o, long *back, float *mind);
typedef pipe__reproj_row_t *pipe__reproj_row_fn;
pipe__reproj_row_t pipe__reproj_row_sse2, pipe__reproj_row_avx2, pipe__reproj_row_avx512,
    pipe__reproj_row_neon;

/* What the taps pass needs (the camera's G-buffer of the crop, the image
 * sampled as int32 RGBA pixels). mlim: the last mask offset with 4
 * readable bytes ((gh - 1) * cms + gw - 4). */
typedef struct pipe__reproj_tapd {
    const uint8_t *cmask;
    const float *cdepth;
    const uint8_t *P;      /* the sampled image, RGBA8, stride ps4 pixels */
    int cms, cds, gw, gh, ox, oy, ps4, icw1, ich1, mlim;
} pipe__reproj_tapd;

/* The taps pass per ISA (pipe_reproj_simd.inl) over columns [x0, w):
 * from one eye row's geometry (o, the covered pixels em), M (the mask
 * composited: the fade or 0), Po (RGBA + the kind in alpha, written
 * where the scalar reference writes), cnt[] += covered, outside, filled, sampled; the first column not done
 * (the scalar taps finish). Equal to the scalar taps in pipe_reproj.c. */
typedef int pipe__reproj_taps_t(const pipe__reproj_tapd *t, const uint8_t *em,
                                const pipe__reproj_lanes *o, int x0, int w, uint8_t *M,
                                uint8_t *Po, long cnt[4]);
typedef pipe__reproj_taps_t *pipe__reproj_taps_fn;
pipe__reproj_taps_t pipe__reproj_taps_sse2, pipe__reproj_taps_avx2, pipe__reproj_taps_avx512,
    pipe__reproj_taps_neon;

/* The filled pixels (THE FILL above) of the eye layer (w x h: M the mask,
 * P the RGBA image whose alpha holds each pixel's kind, 1 sampled, 2
 * filled, where M != 0; ed the eye's window depths, near n, far f), in
 * the rows whose rows[y] has bit 0 set (bit 1: the row has sampled
 * pixels): each takes the RGB of the nearest sampled pixel on its surface
 * to its left or right in its row or above or below in its column, each
 * search ending at a pixel of M 0 (THE FILL above for the rule). A
 * filled pixel with none of the four gets the kind 3 and its row keeps
 * bit 0 (pipe__reproj_fill_cols then fills it); the other rows' bit 0 is
 * cleared. */
void pipe__reproj_fill(uint8_t *rows, int w, int h, uint8_t *M, uint8_t *P, const float *ed,
                       float n, float f);

/* After pipe__reproj_fill: the pixels of kind 3 (M != 0; none of the four
 * searches found a sampled pixel) in the rows whose rows[y] has bit 0 set,
 * filled from the nearest other row above or below that has sampled
 * pixels (bit 1; the one above on a tie): each takes the RGB of that row's
 * nearest coloured pixel (M != 0 and not of kind 3: sampled or filled),
 * the left one on a tie. Without any row of sampled pixels they get M = 0
 * (not shown). At the end every kind 3 of the flagged rows becomes 2.
 * near: w ints of scratch. */
void pipe__reproj_fill_cols(const uint8_t *rows, int w, int h, uint8_t *M, uint8_t *P,
                            int32_t *near);

/* float_normals: also a float plane of normals (r->nrm) for the
 * smoothing, which pipe.c unpacks the packed ones into. -1 when out of
 * memory (r then empty). */
int pipe__reproj_init(pipe__reproj *r, int width, int height, int float_normals);
void pipe__reproj_free(pipe__reproj *r);
/* From the eye's G-buffer (drawn through r->cam), the camera (cam, its
 * lens, its intrinsics those of the crop), the camera image P sampled
 * (the whole sensor, or the crop itself), the crop's origin (ox, oy) in
 * P, and the camera's G-buffer of the crop (gw x gh: cmask, cdepth;
 * window depths of cam's projection, near n, far f): r->P and r->M, the
 * counts and r->inside. Returns r->inside. Where P reaches beyond the
 * G-buffer (the sensor rows above and below the crop of eq. 1) the
 * camera is taken to see the point: every tap there counts. */
int pipe__reproj_sample(pipe__reproj *r, const kin_camera *cam, const fuse_image *P, int ox,
                        int oy, const uint8_t *cmask, int cmask_stride, const float *cdepth,
                        int cdepth_stride, int gw, int gh, float n, float f);

#ifdef __cplusplus
}
#endif
#endif
