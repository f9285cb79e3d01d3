/* pipe.h - one stereo frame of egofuse, end to end: pose -> skin ->
 * rasterize per eye -> lighting layer -> resample -> composite.
 *
 * WHAT IT DOES
 *   The umbrella header of the room: it includes pipe_pose.h (posing and
 *   skinning, pipe_pose.c) and ../fit/fit.h (the fit of the model to the
 *   camera images, src/fit), so callers include pipe.h alone. This file
 *   declares the frame (pipe.c, with its worker thread) and the cockpit
 *   (pipe_parts.c).
 *   pipe_frame(): poses and skins once per frame (both eyes use the same
 *   skin), then for each eye the STHMD camera from the head pose, the
 *   G-buffer (depth, mask, view-space normals) at the cropped camera
 *   resolution (the normals packed in 32 bits, src/cpu/ef_n10.h, unless
 *   the refinement, the smoothing or the anti-aliased fill reads them as
 *   floats), the lighting layer on the camera image inside the mask, the
 *   bilinear resampling into the viewport and the composite over the
 *   virtual image. With threads = 2 the two eyes run on two threads; the
 *   bytes do not depend on the thread count.
 *
 * WHAT IT DOES NOT
 *   No file or device I/O (see src/io), no allocation per frame: buffers
 *   and the worker thread are made by pipe_create. One pipe is used by one
 *   caller thread at a time.
 *
 * USAGE
 *   pipe_desc d = {0};                       // defaults: paper's HMD, 2 threads
 *   pipe_ctx *p = pipe_create(&d, &model);
 *   pipe_frame_in in = {0};
 *   in.anim = &model.anims[0]; in.time = f / 60.0f; in.head_node = head;
 *   in.camera[0] = left_640x480; in.virt[0] = left_1280x800; in.out[0] = ...;
 *   // (the sizes of pipe_hmd(p): cam_width x cam_height, lcd_width x lcd_height)
 *   in.lighting = pipe_lighting_default(); // lights in world space
 *   in.hide = PIPE_PART_HAND_R;             // optional: parts not shown
 *   pipe_frame(p, &in, &stats);
 *   pipe_destroy(p);
 */
#ifndef EGOFUSE_PIPE_H
#define EGOFUSE_PIPE_H

#include "../fit/fit.h"
#include "../fuse/fuse.h"
#include "../fuse/fuse_edge.h"
#include "../fuse/fuse_normals.h"
#include "../fuse/fuse_refine.h"
#include "../kin/kin.h"
#include "../raster/raster.h"
#include "pipe_lod.h"
#include "pipe_pose.h"
#include "pipe_reproj.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------- frames */

typedef struct pipe_desc {
    kin_sthmd_desc hmd;       /* zero = the paper's HMD */
    int threads;              /* 0 = 2 (one eye each); 1 = one thread */
    int max_isa;              /* cap for raster and fuse: an ef_isa value
                                 (src/cpu/cpu.h), 0 = the best the CPU has;
                                 EGOFUSE_ISA caps further */
    float tone_match;         /* 0 = off; (0,1]: strength of the gray-world
                                 colour tone matching (fuse_tone_match) */
    rast_cull cull;           /* RAST_CULL_NONE (default): both faces, right
                                 for any model; RAST_CULL_BACK: about half
                                 the triangle setups, right for closed,
                                 consistently wound meshes (the samples'
                                 arms: the masks are identical) */
    int refine_band;          /* 0 = off; 1..64: each eye's mask is refined
                                 by colour in a band of this half width
                                 around its edge (fuse_refine_mask; with
                                 fit_rig, once the eye's colour model is
                                 learned (pipe_fit_learned), fuse_refine_mask_global
                                 with it, weight PIPE_GLOBAL_WEIGHT (1:
                                 the global model alone, the band's local
                                 histograms only gate it; fit_narrow.h):
                                 `egofuse eval`'s refine method; before
                                 that, and for a
                                 fresh pipe on animation-posed frames, the
                                 bytes of no fit_rig) */
    const kin_arm_rig *fit_rig; /* with refine_band, and frames posed by
                                 pipe_frame_in.locals: fit the elbows to the
                                 camera images (pipe_fit) before the eyes
                                 are drawn, then learn the colour models
                                 and measure the limb widths from the
                                 refined masks (not where the refinement
                                 fell back to the kinematic mask,
                                 fuse_refine_stats.used_colour 0). The
                                 thickness measured applies to every frame,
                                 animation-posed ones too. NULL = no fit.
                                 Copied. */
    int normal_smooth;        /* 0 = off (default); 1..FUSE_NORMAL_SMOOTH_MAX:
                                 the lit mask's normals are summed over
                                 the (2r + 1)^2 window before lighting
                                 (fuse_normal_smooth): for models of
                                 crossing parts with their own normals,
                                 whose shading seams become ramps. With
                                 refine_band (and no aa_samples, the crop
                                 view) the refined mask is always lit
                                 with the model's normals summed over the
                                 window (radius PIPE_NFILL_RADIUS 3 for 0)
                                 and continued beyond the model's rim
                                 (src/pipe/pipe_nfill.h: no halo, no
                                 second edge where the model lags the
                                 hand); -1 there: the model's own normals,
                                 the view vector beyond them (the bytes
                                 before issue 14's fill). Out of range:
                                 pipe_create returns NULL. */
    int aa_samples;           /* 0 = off (default): the binary mask of the
                                 pixel centres, the bytes of before; 4, 8
                                 or 16: anti-aliased edges, the mask is
                                 the coverage of that many samples per
                                 pixel (see "ANTI-ALIASED EDGES" below).
                                 Another value, or with a distorting lens
                                 (hmd.lens; the samples are drawn through
                                 the pinhole): pipe_create returns NULL.
                                 With a level of detail the samples still
                                 draw the full model. */
    int eye_view;             /* PIPE_VIEW_CROP = 0 (default): the paper's
                                 crop and scale (eq. 1-4), the bytes of
                                 before; PIPE_VIEW_REPROJECT: each eye's
                                 hands reprojected from its camera by the
                                 model's depth, composited into the whole
                                 display (pipe_reproj.h, docs/eyeview.md).
                                 Another value, reprojection with
                                 aa_samples, or hmd.ipd_m / cam_offset_m
                                 out of range (pipe_view_check):
                                 pipe_create returns NULL. */
    int edge_fade;            /* soft viewport edges (issue 18, fuse_edge.h):
                                 where the camera image ends inside the
                                 display (the viewport's sides that do not
                                 touch the output's border), the hands fade
                                 over the last k camera pixels of the
                                 layer. 0 = the default,
                                 PIPE_EDGE_FADE_DEFAULT pixels; 1..
                                 FUSE_EDGE_FADE_MAX: k; -1: off (the hard
                                 cut, the bytes of before). Other values:
                                 pipe_create returns NULL. */
    int refine_prior;         /* with refine_band and fit_rig (the rig's
                                 hand joints): 0 = the default, on: around
                                 each tracked hand slower than
                                 PIPE_PRIOR_SPEED (pipe_frame_in.hand_speed),
                                 within PIPE_PRIOR_RADIUS of its joints, the
                                 refinement starts from the eye's last
                                 refined mask moved by the hand's image
                                 motion since the last frame
                                 (pipe_fit_prior, docs/accuracy.md), not
                                 from the kinematic mask; the colour model
                                 and the limb widths are still learned
                                 against the kinematic mask. A refined
                                 pixel the depth fill does not reach gets
                                 the far plane's depth, so a virtual object
                                 still hides it. -1: off (the bytes of
                                 before). Other values: pipe_create
                                 returns NULL. */
    int refine_lag_adapt;     /* with refine_band: 0 = the default, on; -1
                                 off. Not used by pipe_frame (the pipe
                                 runs no filter): it tells the caller's
                                 tracking how to pose the frames, see
                                 pipe_track_output. Other values:
                                 pipe_create returns NULL. */
    int soft_edge;            /* 0 = off (default): the binary mask; 1:
                                 soft silhouettes, the binary (G-buffer's
                                 or refined) mask's edge pixels faded by
                                 the share of their 3x3 window inside it,
                                 a one-pixel ramp instead of stair-steps
                                 (src/pipe/pipe_soft.h, docs/antialias.md),
                                 one pass over the mask; with eye_view
                                 REPROJECT the eye view's mask (its
                                 border fade scaled by the ramp). With
                                 aa_samples or another value:
                                 pipe_create returns NULL. */
    int refine_fill;          /* with refine_band and a fit (fit_rig): 0 =
                                 the default, on: the refined mask's
                                 islands (set components touching no image
                                 border) of at most PIPE_FILL_ISLAND pixels
                                 are cleared, and its holes of at most
                                 PIPE_FILL_HOLE pixels that the kinematic
                                 mask covers filled (0: none, the default:
                                 measured, filling them lost on edge)
                                 (pipe_fit_fill_small, src/fit/fit_holes.h,
                                 docs/accuracy.md), before the colour model
                                 learns from it. -1: off (the bytes of
                                 before). Other values: pipe_create
                                 returns NULL. */
    int refine_shift;         /* with refine_band and a fit (fit_rig): 0 =
                                 the default, on: on tracked frames
                                 (pipe_frame_in.locals), once the fit has
                                 learned the hand's colour, each hand of
                                 the refinement's input that did not take
                                 the prior (refine_prior; a hand at least
                                 PIPE_PRIOR_SPEED fast, or every hand on
                                 frames without the prior) is moved by
                                 the whole-pixel 2D shift, at most 24 px,
                                 that puts its mask on the most
                                 hand-coloured pixels (pipe_fit_shift,
                                 src/fit/fit_shift.h, docs/accuracy.md):
                                 the tracking's error beyond the band. A
                                 moved pixel the depth fill does not reach
                                 gets the far plane's depth, so a virtual
                                 object still hides it. -1: off (the
                                 bytes of before). Other values:
                                 pipe_create returns NULL. */
    int refine_smooth;        /* with refine_band and a fit (fit_rig): 0 =
                                 the default, on: on tracked frames
                                 (pipe_frame_in.locals), after refine_fill
                                 and the cockpit clamp, the refined mask
                                 shown gets a 3x3 closing then opening
                                 (pipe_fit_smooth, src/fit/fit_smooth.h,
                                 docs/accuracy.md): its 1-2 px notches
                                 filled and spurs cut; the fit learns from
                                 the mask before it and the next frame's
                                 prior is that one; the cockpit clamp runs
                                 again after it. -1: off (the bytes of
                                 before). Other values: pipe_create
                                 returns NULL. */
} pipe_desc;

/* The defaults of the refine method (`egofuse eval`'s, docs/accuracy.md). */
#define PIPE_PRIOR_RADIUS 0.03f   /* metres around each hand joint */
#define PIPE_FILL_HOLE 0          /* px: refine_fill's largest hole filled (0 off) */
#define PIPE_FILL_ISLAND 64       /* px: and largest island cleared */
#define PIPE_PRIOR_SPEED 0.3f     /* m/s: faster hands keep the kinematic mask */
#define PIPE_LAG_V0 0.2f          /* m/s: the lag compensation starts ... */
#define PIPE_LAG_V1 0.8f          /* ... and is whole here */

/* The tracking of a pipe (egofuse render/run): with refine_band > 0 and
 * refine_lag_adapt 0 the filter runs without its ramp-lag compensation
 * (pipe_track_filter_desc sets no_lag_comp 1) and each hand's compensation
 * grows with its speed from PIPE_LAG_V0 to PIPE_LAG_V1
 * (pipe_fit_filter_output); otherwise the filter is kin's default and the
 * output kin_filter_output's. speed (NULL or 2 floats) receives the
 * filtered wrist speeds (m/s) for pipe_frame_in.hand_speed. */
kin_filter_desc pipe_track_filter_desc(const pipe_desc *d);
void pipe_track_output(const pipe_desc *d, const kin_filter *f, double display_t,
                       kin_track_sample *out, float speed[2]);

/* The default width of the soft viewport edges, in camera pixels (about
 * 7.5 display pixels with the paper's viewport). */
#define PIPE_EDGE_FADE_DEFAULT 4

/* ANTI-ALIASED EDGES (pipe_desc.aa_samples = n). Each eye's model is drawn
 * a second time into n coverage samples per pixel (rast_draw_aa, the
 * standard Direct3D positions; the G-buffer's depth and normals stay those
 * of the pixel centres) and the mask composited is their resolve
 * M = round(255 covered / n), so R = M P' + (1 - M) V with fractional M
 * (fuse_light and fuse_composite take any M). Pixels that the coverage
 * reaches but whose centre the model misses get
 *   a normal: the sum of the normals of their 3x3 neighbours inside the
 *             model (none: 0, lit as facing the camera), unless
 *             normal_smooth (which already sums over its window);
 *   a depth:  fuse_depth_fill's (the nearest model pixel's, radius 2; with
 *             the refinement band + band / 8 + 3), so the depth test
 *             against the virtual scene hides them as it hides the model
 *             beside them: occlusion is never weaker than without AA.
 * With refine_band the refinement still decides on the binary G-buffer
 * mask (its bytes do not change); the mask composited is then the refined
 * coverage: M = the coverage above where the refined mask agrees with the
 * model in the pixel's 3x3 window, else round(255 k / 9) for k refined
 * pixels in that window (a colour-decided edge gets a one-pixel ramp).
 * The tone match, the elbow fit and pipe_frame_stats.coverage use the
 * binary masks. pipe_mask returns the mask composited. */

typedef struct pipe_ctx pipe_ctx;

/* Lighting of the virtual scene. Directions are in WORLD space (towards
 * the light); pipe_frame turns them into each camera's view space. */
typedef struct pipe_lighting {
    fuse_lighting light;      /* with light[i].dir in world space */
} pipe_lighting;

/* fuse_lighting_default() with its light direction taken as world space. */
pipe_lighting pipe_lighting_default(void);

typedef struct pipe_frame_in {
    /* The pose: locals (node_count transforms) if not NULL, else anim at
     * time (anim NULL = the rest pose). */
    const kin_transform *locals;
    const kin_animation *anim;
    float time;
    /* The head: world matrix of node head_node after posing, or
     * *world_from_head when head_node < 0 (identity when that is NULL). */
    int head_node;
    const kin_mat4 *world_from_head;
    /* Per eye (0 left, 1 right): the full camera image (hmd cam_width x
     * cam_height, cropped here by eq. 1), the virtual image and the output
     * (lcd_width x lcd_height; out may be the same memory as virt). */
    fuse_image camera[2];
    fuse_image virt[2];
    fuse_image out[2];
    /* Optional: the camera frames as the camera delivers them (YUYV, UYVY,
     * GREY, Bayer, RGB24: fuse_frame_to_rgba). When camera_raw[e].data is
     * set, the eye's thread converts only the cropped rows itself and
     * camera[e] is not used. */
    fuse_frame camera_raw[2];
    /* Optional depth of the virtual scene per eye (output resolution,
     * metres along the eye's view axis; 0, inf or NaN = nothing there):
     * a virtual object in front of the hand hides it (fuse_depth_test). */
    const float *virt_depth[2];
    int virt_depth_stride[2]; /* floats per row */
    pipe_lighting lighting;
    /* With an elbow fit (pipe_desc.fit_rig): bit 0 / bit 1 = do not turn
     * the left / right arm (its hand is not tracked this frame). */
    unsigned fit_skip;
    /* With pipe_desc.refine_prior: the left and right wrists' speeds, m/s
     * (pipe_track_output). NULL: 0 (every tracked hand takes the prior). */
    const float *hand_speed;
    /* 1: the caller promises that both virtual images have alpha 255 at
     * every pixel of the viewport (pipe_geometry: vp_x0, vp_y0, vp_width,
     * vp_height), e.g. checked once with pipe_image_opaque. The composite
     * then skips V wherever the hand is not (fuse_eye.v_opaque: in place,
     * out == virt, those pixels are neither read nor written; ~0.4x a
     * memcpy of the output per frame); the bytes are those of 0. A broken
     * promise keeps rgb exact, but the alpha of those pixels may be V's
     * instead of 255. 0 (the default): no promise. */
    int virt_opaque;
    /* What the operator sees of the real cockpit (see "the operator's
     * cockpit" below). hide: PIPE_PART_* bits of the arm model's parts
     * not drawn this frame (0: all shown). prop_world[i] (i < prop_count,
     * at most pipe_prop_count): the world matrix of prop i this frame, or
     * NULL when it is not seen (its rigid body is lost); props from
     * prop_count on are not drawn. prop_world NULL: no props. */
    unsigned hide;
    const kin_mat4 *const *prop_world;
    int prop_count;
} pipe_frame_in;

typedef struct pipe_frame_stats {
    double ms_pose;           /* posing + skinning */
    double ms_raster[2];      /* per eye: camera, G-buffer */
    double ms_convert[2];     /* per eye: camera format conversion (raw) */
    double ms_fuse[2];        /* per eye: lighting, resampling, composite
                                 (with PIPE_VIEW_REPROJECT also the eye's
                                 raster and the sampling of the camera) */
    double ms_total;          /* wall time of pipe_frame */
    double coverage[2];       /* fraction of camera pixels in the mask */
    int lod_level[2];         /* per eye: the level of detail drawn
                                 (pipe_set_lod; 0 = the full model) */
    int view[2];              /* per eye: the method used, PIPE_VIEW_*
                                 (CROP when a reprojecting eye fell back:
                                 the eye inside the model) */
    long view_sampled[2];     /* reprojection, per eye: eye pixels sampled
                                 from the camera, filled (seen by the eye,
                                 not by the camera) and outside the
                                 camera's image (pipe_reproj.h) */
    long view_filled[2];
    long view_outside[2];
    long view_fallbacks;      /* reprojection: eye-frames that fell back
                                 to the crop, since pipe_create */
    /* Where the eyes ran (threads 2: each eye's raster and refinement is
     * taken by whichever thread is free first, so the caller's thread runs
     * both when the worker has not woken by the time it finished its
     * first; the bands of its fuse then run on both threads, ms_busy) */
    int eye_thread[2];        /* per eye: the thread of its raster (0 the caller's, 1 the worker) */
    double ms_eye_start[2];   /* per eye: ms from the eyes' hand-off to its start */
    double ms_eyes;           /* wall time from the hand-off to both eyes done */
    /* Per thread (0 the caller's, 1 the worker): time in the eyes' work
     * (each eye's raster and refinement, then bands of either eye's fuse:
     * a thread that finished its own eye takes the other's bands) */
    double ms_busy[2];
} pipe_frame_stats;

typedef enum pipe_result {
    PIPE_OK = 0,
    PIPE_ERR_ARGS,            /* NULL pointers, image sizes that do not fit */
    PIPE_ERR_RASTER,          /* the rasterizer refused the model */
    PIPE_ERR_FUSE             /* the fuse stage refused its inputs */
} pipe_result;

/* NULL when out of memory or the thread cannot start, or with
 * refine_band and fit_rig when pipe_fit_create refuses the model or the
 * rig (mesh 0's skin, the arms' node chains). */
pipe_ctx *pipe_create(const pipe_desc *desc, const kin_model *model);
void  pipe_destroy(pipe_ctx *p);
/* Forgets the elbow fit's state (pipe_fit_forget: swivels, colour
 * models, limb thickness; the next frame's colour model is learned from
 * its kinematic mask alone), e.g. when the operator or the scene changes.
 * Nothing without a fit (fit_rig NULL) or for p NULL. Not during
 * pipe_frame. */
void  pipe_reset_fit(pipe_ctx *p);
/* One stereo frame. stats may be NULL. On error, why (if not NULL) gets a
 * sentence naming the eye and the reason. */
pipe_result pipe_frame(pipe_ctx *p, const pipe_frame_in *in,
                       pipe_frame_stats *stats, char *why, int why_size);
/* The last frame's mask of one eye (valid until the next frame): the
 * refined one with pipe_desc.refine_band, else the G-buffer's; with
 * pipe_desc.aa_samples the coverage mask composited (0..255); with
 * pipe_desc.soft_edge the mask before its softening (binary or refined;
 * the softened one is composited). */
const uint8_t *pipe_mask(const pipe_ctx *p, int eye, int *width, int *height);
/* The last frame's lit layer of one eye (premultiplied RGBA8, the
 * mask's size, 4 * width bytes per row; valid until the next frame):
 * alpha 0 wherever the mask was 0 or the depth test hid the hand. With
 * PIPE_VIEW_REPROJECT the eye view's layer (of pipe_view_mask; the same
 * size), unless the eye fell back to the crop in that frame. */
const uint8_t *pipe_layer(const pipe_ctx *p, int eye, int *width, int *height);
/* The camera of one eye in the last frame. */
kin_camera pipe_camera(const pipe_ctx *p, int eye);
/* With pipe_desc.eye_view = PIPE_VIEW_REPROJECT: the eye's own camera of
 * the last frame (kin_sthmd_eye_camera at the layer's size, which
 * pipe_layer then has), and the eye-view mask composited (0..255: the
 * border fade, 0 outside the camera's view; width x height = the crop's
 * size, covering the whole display). pipe_view_mask is NULL, and
 * pipe_view_camera the camera's, for the crop method and for an eye that
 * fell back to it in the last frame. With pipe_desc.soft_edge the
 * eye-view mask is the softened one (pipe_soft.h), as composited. */
kin_camera pipe_view_camera(const pipe_ctx *p, int eye);
const uint8_t *pipe_view_mask(const pipe_ctx *p, int eye, int *width, int *height);
/* The ISA that raster and fuse use (an ef_isa value). */
int pipe_isa(const pipe_ctx *p);

/* The clock of every pipe_frame_stats time, for all contexts: 0 (the
 * default) wall time (CLOCK_MONOTONIC), 1 the CPU time of the thread that
 * runs the stage (CLOCK_THREAD_CPUTIME_ID: for benchmarks on a shared
 * machine, where wall time measures the neighbours; a thread's waits do
 * not count). Set it before any pipe_frame runs. */
void pipe_set_stats_clock(int thread_cpu);
/* The derived HMD numbers in use (crop, viewport). */
kin_sthmd_geometry pipe_geometry(const pipe_ctx *p);
/* 1 when every pixel of the rectangle (x0, y0, w, h) of the RGBA8 image
 * im has alpha 255 (for pipe_frame_in.virt_opaque: the viewport of
 * pipe_geometry), else 0; 0 as well for NULL pixels, an empty rectangle
 * or one not inside the image. Reads the rectangle's alpha bytes once. */
int pipe_image_opaque(const fuse_image *im, int x0, int y0, int w, int h);

const char *pipe_result_str(pipe_result r);
/* The resolved HMD description the pipe uses (pipe_desc.hmd with its
 * defaults filled in): the sizes of pipe_frame_in's images. */
kin_sthmd_desc pipe_hmd(const pipe_ctx *p);

/* Levels of detail of the pipe's model (pipe_lod.h; built by
 * io_lod_build when the model is loaded). From the next frame on, each
 * eye draws level `level` of lod (clamped to the chain), or with level
 * PIPE_LOD_AUTO the level of the rule of pipe_lod.h for target_px
 * (pixels, > 0), per eye and per mesh (pipe_lod_draw). lod NULL or level
 * 0: the full model, the bytes of a pipe without levels (the default).
 * The chain must be of the pipe's model (pipe_lod_check) and outlive the
 * pipe or the next pipe_set_lod. Frames that hide a part or draw a prop
 * (the operator's cockpit, below) and the elbow fit's own drawing use the
 * full model. Returns 0, or -1 (nothing changed) for p NULL, a chain not
 * of the model, a level < PIPE_LOD_AUTO, or PIPE_LOD_AUTO with target_px
 * not > 0 and finite. Not during pipe_frame. */
int pipe_set_lod(pipe_ctx *p, const pipe_lod *lod, int level, float target_px);

/* ------------------------------------------------ the operator's cockpit
 *
 * PARTS. pipe_create classifies the model's triangles once into four
 * parts that a frame may hide (pipe_frame_in.hide):
 *   nodes: per side, the arm chain is found by name as the rig names it
 *   (kin_arm_rig: "L_shoulder", "L_upper_arm", "L_forearm", "L_hand"; the
 *   fit rig's joints when pipe_desc.fit_rig is set) or as generic glTF
 *   arms do (pipe_parts_of_nodes: "LeftArm", "mixamorig:LeftForeArm",
 *   "upperarm_l", "hand.L", "Bip01 L Clavicle", "J_Bip_L_Hand", ...). A
 *   hand is the hand (wrist) joint and all its descendants; an arm is the
 *   shoulder (clavicle) joint, the upper arm and its descendants that are
 *   not in the hand (forearm, twist and elbow nodes). Every other node
 *   (body, head, spine, a prop of the model) is in no part.
 *   vertices: a skinned vertex gives each of its four weights to the part
 *   of that joint's node (or to "no part"); a vertex of an unskinned mesh
 *   gives weight 1 to the part of its mesh's node.
 *   triangles: a triangle is in the part holding the largest total
 *   weight of its three vertices (summed in double); a triangle whose
 *   largest total is "no part", and every tie with "no part", is in no
 *   part and always drawn; a tie between parts goes to the lower
 *   PIPE_PART_* bit. So a triangle across the wrist is hidden with the
 *   hand when most of its weight is the hand's.
 * A hidden triangle is not drawn at all: per visibility set (the hide
 * bits of the parts the model has), the meshes' index lists are filtered
 * once, in their order, on the first frame that uses it, and kept (at
 * most 15 sets, each a list per mesh). With hide = 0 and no props the
 * frame is drawn exactly as before (the same bytes).
 * With the refinement (pipe_desc.refine_band) a hidden part does not come
 * back by colour: the refined mask keeps no pixel outside the kinematic
 * mask within refine_band px (chessboard distance) of the hidden
 * triangles' silhouette (drawn for it on the eye's thread). The elbow fit
 * still turns and measures both arms (a hidden arm has no mask pixels to
 * measure) and learns its first colour model from the whole model's
 * mask. */
enum {
    PIPE_PART_HAND_L = 1u << 0,
    PIPE_PART_ARM_L = 1u << 1,
    PIPE_PART_HAND_R = 1u << 2,
    PIPE_PART_ARM_R = 1u << 3,
    PIPE_PART_ALL = 0xFu
};

/* The part (a PIPE_PART_* bit, 0 = none) of every node of model into
 * part[node_count], by the rule above; rig (or NULL) names the chain
 * joints first (its shoulder, upper arm, forearm, hand). Returns the OR of
 * the parts found, 0 for a NULL model or part. */
unsigned pipe_parts_of_nodes(const kin_model *model, const kin_arm_rig *rig,
                             unsigned char *part);
/* The parts of the pipe's model that own at least one triangle. */
unsigned pipe_parts_present(const pipe_ctx *p);
/* Parses a comma list of part names ("left-hand", "left-arm",
 * "right-hand", "right-arm", "hands", "arms", "all"; "none" or "" = 0)
 * into PIPE_PART_* bits. 0, or -1 with a sentence naming the bad name in
 * why. */
int pipe_parts_parse(const char *list, unsigned *bits, char *why, int why_size);

/* PROPS: real objects the operator touches (a joystick, a keyboard, the
 * seat's armrests) cut in like the hands. Each is a kin_model (e.g. from
 * io_gltf_load) in its rest pose (node transforms applied, skinned meshes
 * skinned at rest), placed each frame by pipe_frame_in.prop_world[i]
 * (world_from_prop: fixed in the cockpit, or the pose of its tracked
 * rigid body). Its triangles (both faces: a prop need not be closed) go
 * into the same depth, mask and normals as the arms: the depth test
 * between arms and props is per pixel, the virtual scene's depth hides
 * them like the hands, and they are lit like the hands (their normals
 * are the mesh's, smooth ones where it has none). A hidden part of the
 * arms does not hide a prop. Props are neither refined differently nor
 * seen by the elbow fit, but the fit's colour model is learned from the
 * mask with them. */
/* Adds a prop; the model must outlive the pipe. Returns its index (0, 1,
 * ...), or -1 when out of memory or the model has no triangles or fails
 * kin_model_validate. Not during pipe_frame. */
int pipe_add_prop(pipe_ctx *p, const kin_model *m);
/* The number of props added. */
int pipe_prop_count(const pipe_ctx *p);

#ifdef __cplusplus
}
#endif
#endif
