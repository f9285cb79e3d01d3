/* gt.h - ground truth for `egofuse eval` (docs/accuracy.md).
 *
 * WHAT IT DOES
 *   Builds on the sample generator (samples/gen/gen.h):
 *     gt_truth_build()   a "true" operator whose arms and hands differ from
 *                        the mask model: other bone lengths (shoulders,
 *                        upper arm, forearm, hand), thicker or thinner limbs
 *                        (radial scale per segment) and a more detailed
 *                        surface (one level of PN-triangle subdivision:
 *                        4x the triangles, curved rather than faceted).
 *                        It moves with the joint angles of the samples'
 *                        animation, so with its own bones its hands are
 *                        elsewhere than the mask model's would be.
 *     gt_cockpit_build() the samples' cockpit plus objects of skin-like
 *                        colour (a cardboard box, a beige desk pad, a
 *                        wooden tray, a tan folder on the side console).
 *     gt_render_eye()    the camera image of one eye (textured skin, the
 *                        cockpit's own lighting, vignetting, noise: see
 *                        gen_render_camera), the exact silhouette of the
 *                        true arms in the cropped 640x400 image (pixel
 *                        centres, the rasterizer's rule) and their
 *                        view-space normals.
 *     gt_true_sample()   the true tracking sample at a time (head, shoulder
 *                        and wrist poses from the true skeleton, glove
 *                        flexure from its finger angles).
 *     gt_track_sample()  the k-th sample of a tracker: capture time k/rate,
 *                        the true sample plus noise (seeded, per capture),
 *                        delivered `latency` later, lost with probability
 *                        `dropout` (hands and gloves; head and shoulders
 *                        are kept).
 *   Everything is deterministic for a seed: no global state, no rand().
 */
#ifndef EGOFUSE_GT_H
#define EGOFUSE_GT_H

#include <stdint.h>

#include "../gen/gen.h"

typedef struct gt_operator_desc {
    float shoulder_scale;   /* shoulder offsets (width), vs the mask model */
    float upper_scale;      /* upper arm length */
    float fore_scale;       /* forearm length */
    float hand_scale;       /* palm and fingers, all dimensions */
    float upper_thick;      /* radial scale of the upper arm surface */
    float fore_thick;       /* forearm and wrist */
    float hand_thick;       /* palm and fingers (on top of hand_scale) */
    int subdivide;          /* 0 or 1 level of PN-triangle subdivision */
} gt_operator_desc;

/* shoulders 1.03, upper arm 1.07, forearm 0.95, hand 1.05; thickness
 * 1.12 (upper arm), 0.93 (forearm), 1.04 (hand); subdivide 1. */
gt_operator_desc gt_operator_default(void);

/* Builds the true operator from the mask model. truth->model shares the
 * mask model's animation (truth->model.anims points into mask's memory:
 * free the truth first). Returns 0, or -1 when out of memory. */
int gt_truth_build(const gen_arms *mask, const gt_operator_desc *d,
                   gen_arms *truth);

/* Motion sequences of the true operator (docs/accuracy.md): index 0 is
 * the generator's "reach_grasp", then "cross" (the hands cross, one in
 * front of the other), "near" (the hands 15 cm from the eyes), "edge"
 * (the hands at and beyond the image borders), "fast" (reaches of
 * 0.25-0.3 s) and "calib" (7.7 s: the arms stretched forward and
 * sideways, then the fingertip gesture, the middle fingertips of both
 * hands pressed together: the calibration motion of
 * kin_user_calib_estimate_tips, solved for the true operator's own bones
 * so that its fingertips touch; not meant to be rendered). NULL past the
 * last. Not listed, for the eye-view evaluation (docs/accuracy.md):
 * "holdNN", NN = 10..60, the right hand held NN cm in front of the eyes,
 * palm towards them, the middle fingertip midway between the eyes,
 * swaying 0.5-1.5 cm in the plane at that depth, the left hand down out
 * of view (gt_sequence_build takes these names). */
const char *gt_sequence_name(int i);

/* Makes truth move through sequence `name`: its animation (joint angles
 * solved for the mask model's bones, as the generator does) is allocated
 * in truth->model's memory block and becomes truth->model.anims[0]
 * ("reach_grasp": the mask model's own animation). Returns 0, or -1 for
 * an unknown name or when out of memory. */
int gt_sequence_build(const gen_arms *mask, const char *name, gen_arms *truth);

/* The cockpit with skin-coloured objects. 0, or -1 when out of memory. */
int gt_cockpit_build(gen_scene *s);

/* Renders eye `eye` of frame `frame` of the true operator posed by
 * gen_pose(c, ...) (c built on the truth): rgb (640x480x3 sensor image),
 * sil (640x400, 255 on the true arms: the pixel centres they cover where
 * nothing of the cockpit is in front), nrm (640x400x3 view-space unit
 * normals of the arms, 0 elsewhere; may be NULL). scratch_depth and
 * scratch_mask: 640x480 floats and bytes. */
void gt_render_eye(gen_frame_ctx *c, const kin_mat4 *world_from_head,
                   kin_eye eye, int frame, uint8_t *rgb, uint8_t *sil,
                   float *nrm, float *scratch_depth, uint8_t *scratch_mask);

/* The true sample at animation time t (seconds). locals and world:
 * scratch of truth->model.node_count entries. All parts valid. */
void gt_true_sample(const gen_arms *truth, float t, kin_transform *locals,
                    kin_mat4 *world, kin_track_sample *out);

typedef struct gt_track_desc {
    float noise_mm;         /* RMS 3-D position error, millimetres */
    float rot_noise_deg;    /* RMS rotation error of the hands, degrees */
    float head_rot_noise_deg; /* RMS rotation error of the head, degrees */
    float glove_noise;      /* RMS flexure error (0..1 scale) */
    float latency_ms;       /* capture to delivery */
    float dropout;          /* probability that a sample loses the hands */
    float rate_hz;          /* sample rate */
    float speed;            /* animation time = speed * capture time */
    uint64_t seed;
} gt_track_desc;

/* noise 5 mm, hands 0.5 deg, head 0.1 deg, glove 0.03, latency 20 ms,
 * dropout 0.02, 90 Hz, speed 1, seed 1. */
gt_track_desc gt_track_default(void);

/* Sample k (capture time k / rate, on the display clock; delivered at
 * capture + latency). */
void gt_track_sample(const gen_arms *truth, const gt_track_desc *d, int k,
                     kin_transform *locals, kin_mat4 *world,
                     kin_track_sample *out);

#endif
