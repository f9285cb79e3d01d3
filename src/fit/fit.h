/* fit.h - the fit of the arm model to the operator's arms in the camera
 * images: the elbow swivel, the colour model it scores with, and the limb
 * thickness (self-calibration).
 *
 * WHAT IT DOES
 *   pipe_fit_learn: learns a colour model per eye where a kinematic mask
 *   and a refined mask agree. pipe_fit_elbows: turns each arm about its
 *   shoulder-wrist line to the swivel that puts its surface points on the
 *   most arm-coloured pixels of both eyes. pipe_fit_measure /
 *   pipe_fit_shape: measures how much thinner or thicker the operator's
 *   limbs are than the model's over the first frames, then freezes and
 *   applies it. The details of each are below.
 *
 * WHAT IT DOES NOT
 *   No drawing (the caller draws the masks, see pipe_pose_draw), no
 *   threads, no I/O, no allocation after pipe_fit_create. It does not pose
 *   or skin: it changes the caller's local transforms and skinned
 *   positions. Used by pipe_frame (src/pipe, pipe_desc.refine_band with
 *   fit_rig) and by the evaluation (src/eval, method refine).
 *
 * USAGE
 *   pipe_fit *f = pipe_fit_create(NULL, &model, &rig, cam_w, cam_h);
 *   // per frame, after posing: fit with the model learned so far
 *   pipe_fit_elbows(f, world, pos, cams, images, 3u, locals, NULL);
 *   // ... re-pose from locals, draw and refine the masks, then per eye:
 *   pipe_fit_learn(f, eye, &image, kin_mask, stride, refined, stride);
 *   pipe_fit_destroy(f);
 */
#ifndef EGOFUSE_FIT_H
#define EGOFUSE_FIT_H

#include "../fuse/fuse.h"
#include "../fuse/fuse_refine.h"
#include "../kin/kin.h"

#ifdef __cplusplus
extern "C" {
#endif

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
 * per class), kept over frames (pipe_fit_desc.learn_memory: each frame's
 * histograms weigh 0.95 per frame since). pipe_frame and `egofuse eval`
 * learn it after each frame's
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
/* The learning's pseudo-count per bin (4 / bins) in the log ratio, and the
 * floor under which a kept, decayed count is set to 0 (2^-30 of it: far
 * below half an ulp of the pseudo-count and of a sample's +1, so no llr
 * byte depends on the counts under it; fit_learn_memory). */
#define PIPE_FIT_PSEUDO_COUNT (4.0f / (float)(1 << (3 * PIPE_FIT_BITS)))
#define PIPE_FIT_COUNT_FLOOR (PIPE_FIT_PSEUDO_COUNT * 0x1p-30f)

/* Bounds of pipe_fit_desc (pipe_fit_create refuses a setting outside
 * them: the search must end and its buffers stay small). */
#define PIPE_FIT_MIN_STEP_DEG 0.1f
#define PIPE_FIT_MAX_STEP_DEG 45.0f
#define PIPE_FIT_MAX_RANGE_DEG 180.0f   /* range_deg and rate_deg */
#define PIPE_FIT_MAX_PRIOR 100.0f
#define PIPE_FIT_MAX_POINTS 4096
#define PIPE_FIT_MAX_SHAPE_SAMPLES 4096
/* The default learn_memory (issue 14 item 2): each frame's samples weigh
 * 0.95 per frame since (a memory of about 20 frames). Learned from one
 * frame alone, a model that took in the desk pad under crossing hands or
 * the dark desk beside a hand leaving the image once (where the kinematic
 * mask was off and the refined mask followed the colour) learned it as
 * arm, refined it in the next frame, and learned it again; kept over
 * frames, the frames that saw it as background outweigh it. On `egofuse
 * eval` (60 frames, refine): cross IoU 0.916 -> 0.935, edge 0.707 ->
 * 0.729 (docs/accuracy.md, Every sequence). */
#define PIPE_FIT_LEARN_MEMORY 0.95f
/* the learning skips arm samples whose bin the kept model calls background
 * by more than this (nats; the model is clamped to +-3). 1.5, not 1: at 1
 * the hand's own warm-lit colours (a 3000 K cockpit light) that the first
 * models called mildly background were never learned (BF 3 px 0.916 ->
 * 0.869 in the lighting sweep); at 1.5 the sweep is back to 0.916 and the
 * sequences within 0.002 of 1 (docs/accuracy.md, "The rejection at 1.5") */
#define PIPE_FIT_LEARN_REJECT 1.5f

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
    float learn_memory;       /* pipe_fit_learn keeps its histograms over
                                 frames, each frame's weighted by this
                                 factor per frame since (default
                                 PIPE_FIT_LEARN_MEMORY; (0, 1)); < 0 = each
                                 frame's model from that frame alone (the
                                 bytes of before) */
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
 * NULL: the kinematic mask alone, inside = >= 128 as well), added to what
 * the eye learned in earlier frames, each weighted by learn_memory per
 * frame since (pipe_fit_desc; off: this frame alone). FUSE_ERR_ARGS
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
