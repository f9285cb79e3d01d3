/* pipe.h - one stereo frame of egofuse, end to end: pose -> skin ->
 * rasterize per eye -> lighting layer -> resample -> composite.
 *
 * WHAT IT DOES
 *   pipe_pose_*: poses a kin_model (rest pose, an animation at time t, or
 *   local transforms given by the caller, e.g. from IK) and skins every mesh
 *   once per frame into world space (both eyes use the same skin).
 *   pipe_frame(): for each eye, the STHMD camera from the head pose, the
 *   G-buffer (depth, mask, view-space normals) at the cropped camera
 *   resolution, the lighting layer on the camera image inside the mask, the
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

#include "../fuse/fuse.h"
#include "../fuse/fuse_refine.h"
#include "../kin/kin.h"
#include "../raster/raster.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------- posing */

/* Posing and skinning state of one model; buffers allocated once. */
typedef struct pipe_pose {
    const kin_model *model;
    kin_transform *locals;    /* node_count: the pose being evaluated */
    kin_mat4 *world;          /* node_count: world matrices after FK */
    kin_mat4 **joint_mats;    /* per skin, joint_count */
    kin_mesh *meshes;         /* the model's meshes; normals filled in
                                 (smooth, area-weighted) where the file
                                 has none */
    float **own_normals;      /* per mesh: normals computed here, or NULL */
    float **pos;              /* per mesh, 3 per vertex, world space */
    float **nrm;              /* per mesh, 3 per vertex, world space, unit */
    int max_vertices;         /* of the largest mesh */
} pipe_pose;

/* 0 on success, -1 when out of memory (nothing to free then). */
int  pipe_pose_init(pipe_pose *ps, const kin_model *m);
void pipe_pose_free(pipe_pose *ps);
/* Poses at time t of anim (NULL: the rest pose), then skins. */
void pipe_pose_anim(pipe_pose *ps, const kin_animation *anim, float t);
/* Poses with the caller's local transforms (node_count), then skins. */
void pipe_pose_locals(pipe_pose *ps, const kin_transform *locals);

/* Draws every mesh of a posed model through cam into target (attr_count
 * 3 receives view-space normals; 0 draws depth and mask only), culling
 * as cull says, with ctx
 * (NULL: rast_draw, the best ISA on the calling thread). clip and vnrm are
 * scratch arrays of 4 and 3 floats per vertex of the largest mesh
 * (ps->max_vertices). */
rast_result pipe_pose_draw(const pipe_pose *ps, rast_context *ctx,
                           const kin_camera *cam, const rast_target *target,
                           rast_cull cull, float *clip, float *vnrm,
                           rast_stats *stats);

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
                                 with it, weight 0.5: `egofuse eval`'s
                                 refine method; before that, and for a
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
} pipe_desc;

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
    double ms_fuse[2];        /* per eye: lighting, resampling, composite */
    double ms_total;          /* wall time of pipe_frame */
    double coverage[2];       /* fraction of camera pixels in the mask */
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
 * refined one with pipe_desc.refine_band, else the G-buffer's. */
const uint8_t *pipe_mask(const pipe_ctx *p, int eye, int *width, int *height);
/* The camera of one eye in the last frame. */
kin_camera pipe_camera(const pipe_ctx *p, int eye);
/* The ISA that raster and fuse use (an ef_isa value). */
int pipe_isa(const pipe_ctx *p);
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

/* ------------------------------------------------------- elbow fit
 *
 * The IK places each elbow by a rule (kin_arm_ik_job: a swivel about the
 * shoulder-wrist line); a real operator's elbow is elsewhere on that
 * circle (the paper's "mismatch posture of elbows"). pipe_fit turns each
 * arm (upper arm and forearm; the wrist and the hand keep their world
 * pose) about that line to the swivel whose surface points (up to
 * `points` vertices bound to the upper arm or forearm with weight >= 0.9,
 * evenly picked) fall on the most arm-coloured pixels of both camera
 * images: the sum over both eyes of the clamped log-likelihood ratio of
 * the colour model (fuse_colour_model_learn, PIPE_FIT_BITS bits per
 * channel) at the pixel each point projects to, minus a prior
 * prior * 2 points * (phi / 30 deg)^2 that trusts the IK. Search: every
 * step_deg within +-range_deg of the IK's elbow on the first frame after
 * a reset, then within +-rate_deg of the last swivel; then 1-degree steps
 * within +-step_deg/2 of the best. The colour model of each eye is learned
 * from the camera image where a kinematic mask and a refined mask agree
 * (learning margin 4 px, every 2nd pixel, clamp 3 nats, >= 64 samples
 * per class). pipe_frame and `egofuse eval` learn it after each frame's
 * refinement, from that frame's masks (not when the refinement fell
 * back to the kinematic mask), and fit the next frame with it (no raster
 * for the fit); only while there is no model (pipe_fit_learned 0) do
 * they draw the kinematic mask first and learn from it (and the last
 * refined mask, if any). The same model, once learned, is the band
 * refinement's global term (fuse_refine_mask_global; plain
 * fuse_refine_mask before). 5 bits per channel: on `egofuse eval`'s
 * reach_grasp the finer model separates the dark sleeve from the dark
 * desk, IoU 0.960 -> 0.973 against 4 bits (6 bits: 0.973, slower).
 * Points outside the image are unknown, not dropped: per eye, only the
 * points that project into the image (and in front of the camera) for
 * every swivel of the window searched (its ends and every 30 degrees
 * between) are scored, for every candidate alike. Dropping a point only
 * where it leaves the view (scoring it 0 there) made the score favour
 * swivels that push the arm out of view wherever its visible part scores
 * below 0 (a dark sleeve over a dark desk), and scoring it as an average
 * arm pixel favoured the opposite.
 * Used by `egofuse eval` (method refine), and by pipe_frame when
 * pipe_desc.refine_band and fit_rig are set (docs/accuracy.md). No
 * allocation after pipe_fit_create. */
#define PIPE_FIT_BITS 5

/* Bounds of pipe_fit_desc (pipe_fit_create refuses a setting outside
 * them: the search must end and its buffers stay small). */
#define PIPE_FIT_MIN_STEP_DEG 0.1f
#define PIPE_FIT_MAX_STEP_DEG 45.0f
#define PIPE_FIT_MAX_RANGE_DEG 180.0f   /* range_deg and rate_deg */
#define PIPE_FIT_MAX_PRIOR 100.0f
#define PIPE_FIT_MAX_POINTS 4096
#define PIPE_FIT_MAX_SHAPE_SAMPLES 4096

typedef struct pipe_fit_desc {
    float range_deg;          /* default 60; (0, PIPE_FIT_MAX_RANGE_DEG] */
    float step_deg;           /* default 5; [PIPE_FIT_MIN_STEP_DEG,
                                 PIPE_FIT_MAX_STEP_DEG] */
    float rate_deg;           /* per frame, default 12; (0, 180] */
    float prior;              /* nats per point at 30 deg, default 0.05;
                                 (0, PIPE_FIT_MAX_PRIOR] */
    int points;               /* per arm, default 400; 1..PIPE_FIT_MAX_POINTS */
    int shape_samples;        /* limb widths measured per segment (both
                                 eyes) before its thickness is frozen
                                 (pipe_fit_measure), default 48, at most
                                 PIPE_FIT_MAX_SHAPE_SAMPLES; < 0 = no
                                 thickness calibration (factors stay 1) */
} pipe_fit_desc;

typedef struct pipe_fit pipe_fit;

/* For mesh 0 of model (skinned by its own skin, meshes[0].skin) and the
 * rig's joints; images of width x height. desc NULL or zero fields =
 * defaults. NULL when out of memory, for a setting outside the bounds
 * above (NaN, infinite and negative included; zero = the default), when
 * mesh 0 has no valid skin (its skin index or a joint index out of
 * range), when a side's rig joints are not a chain upper arm -> forearm
 * -> hand (each a descendant of the one before: nodes between them, e.g.
 * a twist or wrist node, are fine), when the two sides' chains share a
 * node or one side's upper arm is a descendant of the other's (the same
 * limb would be turned and thickened twice), or the model has no vertex
 * bound to an arm. */
pipe_fit *pipe_fit_create(const pipe_fit_desc *desc, const kin_model *model,
                          const kin_arm_rig *rig, int width, int height);
void pipe_fit_destroy(pipe_fit *f);
/* Forgets the last swivels (the next fit searches the whole range); the
 * colour models and the thickness are kept (pipe_fit_forget drops them
 * too). Nothing for f NULL. */
void pipe_fit_reset(pipe_fit *f);
/* Forgets everything learned: pipe_fit_reset, pipe_fit_reset_shape, and
 * the colour models (pipe_fit_learned 0, all-zero llr): the state of
 * pipe_fit_create. Nothing for f NULL. */
void pipe_fit_forget(pipe_fit *f);
/* Learns eye's colour model from P (RGBA8, width x height) and a
 * kinematic mask (inside = >= 128): arm where it and the refined mask
 * prev agree on inside, background where they agree on outside (prev
 * NULL: the kinematic mask alone, inside = >= 128 as well). FUSE_ERR_ARGS
 * for bad arguments (f NULL, strides < width included). */
fuse_result pipe_fit_learn(pipe_fit *f, int eye, const fuse_image *P,
                           const uint8_t *mask, int mask_stride,
                           const uint8_t *prev, int prev_stride);
/* Fits both swivels for the posed model (world: FK of locals, pos: mesh
 * 0 skinned to world space) seen by cam[0], cam[1] (view_proj maps onto
 * the images P[0], P[1], width x height), turns the arms of the sides
 * whose bit is set in `sides` (bit 0 left, bit 1 right: those whose hand
 * is tracked) in locals and remembers their swivels. swivel (NULL or 2
 * floats) receives the swivels of this frame, radians from the IK's. */
void pipe_fit_elbows(pipe_fit *f, const kin_mat4 *world, const float *pos,
                     const kin_camera cam[2], const fuse_image P[2],
                     unsigned sides, kin_transform *locals, float swivel[2]);
/* The colour model eye learned last (for fuse_refine_mask_global; all
 * zero while pipe_fit_learned is 0: use fuse_refine_mask then); NULL for
 * f NULL. */
const fuse_colour_model *pipe_fit_colour(const pipe_fit *f, int eye);
/* 1 when eye has a colour model (both classes had >= 64 samples). A
 * caller that learns each frame's model after its refinement, from that
 * frame's kinematic and refined masks (pipe_frame and `egofuse eval` do),
 * fits the next frame with it and needs no extra raster per eye; only
 * while this is 0 (the first frame) does it draw the kinematic mask for
 * pipe_fit_learn before the fit. 0 for f NULL. */
int pipe_fit_learned(const pipe_fit *f, int eye);

/* ---------------------------------------- limb thickness (self-calibration)
 *
 * The mask model's limbs are not the operator's (in `egofuse eval`'s
 * ground truth the forearm is 7 % thinner and the upper arm 12 %
 * thicker). pipe_fit measures how much thinner they are from the images
 * of the first frames of a run and then freezes it: nothing but the
 * camera images is used. Per eye and frame, pipe_fit_measure takes the
 * kinematic mask (drawn with the thickness in use) and the refined mask,
 * and per arm segment (upper arm: shoulder to elbow joint, forearm: elbow
 * to wrist) puts 6 stations on the projected axis, evenly over the part
 * of its [0.2, 0.9] that lies 8 px or more inside the image (none if that
 * is under 12 px long). At each station whose pixel both masks hold it
 * walks perpendicular to the axis to both edges of each mask; a station
 * counts when all four walks end inside the image within 160 px, the
 * kinematic width is >= 7 px and within 0.7-1.4x the model's own (its
 * mean limb radius in the bind pose times the factor in use, projected
 * at the station's depth: wider walks ran into a hand or the other arm),
 * and the sample
 *   thickness in use * (refined width + 1) / (kinematic width + 1)
 * (the +1: the centre pixel) is >= 0.6 (a skin without inverse bind
 * matrices has no bind pose for the radius: no thickness). Samples above
 * 1 count as 1: only thinner limbs are measured, since a refined mask
 * wider than the model may hold a skin-coloured object beside the arm
 * (in `egofuse eval`'s cross sequence the desk pad made a forearm 1.48x
 * and cost 0.05 IoU), while a narrower one dropped pixels that look like
 * background.
 * pipe_fit_elbows sets each factor to the median of its samples over
 * both eyes once there are >= 12, and freezes it when it has
 * shape_samples (each eye keeps up to shape_samples).
 * pipe_fit_shape applies the factors to a posed mesh: each vertex moves
 * away from the closest point of each arm bone's axis segment by
 * weight * (factor - 1) of that distance (weight: the vertex's skin
 * weight on that bone). A segment never seen keeps factor 1. The eyes may
 * measure on two threads (pipe_frame does); pipe_fit_elbows must not run
 * meanwhile. */

/* Scales the arms of the posed mesh 0 (pos: 3 floats per vertex, world
 * space; world: FK of the pose) radially about their bones by the
 * thickness factors; nothing while they are 1 or for NULL arguments. Call
 * after each skinning of the pose that is fitted or drawn. */
void pipe_fit_shape(const pipe_fit *f, const kin_mat4 *world, float *pos);
/* Measures one eye (see above): cam and world of the frame as drawn,
 * mask = its kinematic mask, refined = its refined mask (inside = >= 128,
 * width x height). Does nothing once frozen or for bad arguments (NULL
 * pointers, eye not 0 or 1, a stride < width). A caller measures only
 * masks the colour refined (fuse_refine_stats.used_colour): a fallback
 * mask is the kinematic one and adds samples equal to the factor in use. */
void pipe_fit_measure(pipe_fit *f, int eye, const kin_camera *cam, const kin_mat4 *world,
                      const uint8_t *mask, int mask_stride, const uint8_t *refined,
                      int refined_stride);
/* The factors in use, [side][0 upper arm, 1 forearm]; *frozen (may be
 * NULL) = 1 once frozen. f NULL: factors 1, not frozen. */
void pipe_fit_thickness(const pipe_fit *f, float thick[2][2], int *frozen);
/* Forgets the thickness (factors 1, measuring again from the next
 * frame); pipe_fit_create starts so. Nothing for f NULL. */
void pipe_fit_reset_shape(pipe_fit *f);

#ifdef __cplusplus
}
#endif
#endif
