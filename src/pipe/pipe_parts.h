/* pipe_parts.h - internal to src/pipe: what the operator sees of the real
 * cockpit (pipe.h, "the operator's cockpit"): the parts of the arm model
 * that are hidden, and the props. pipe.c keeps one pipe__cockpit per
 * pipe and calls it at the points named below; nothing here is public.
 *
 * Per frame, on the caller's thread: pipe__cockpit_frame (checks the
 * frame's hide bits and props, picks the cached index lists of the
 * visibility set, poses the visible props). Then per eye, on the eye's
 * thread: pipe__cockpit_draw instead of pipe_pose_draw when
 * pipe__cockpit_active, and pipe__cockpit_clamp after the refinement. */
#ifndef EGOFUSE_PIPE_PARTS_H
#define EGOFUSE_PIPE_PARTS_H

#include "pipe.h"
#include "pipe_aa.h"

typedef struct pipe__cockpit pipe__cockpit;

/* For the pipe's model (mesh triangles classified here, once), rig: the
 * fit rig or NULL. width x height: the eyes' G-buffer; refine_band > 0:
 * scratch for pipe__cockpit_clamp. NULL when out of memory. */
pipe__cockpit *pipe__cockpit_create(const kin_model *m, const kin_arm_rig *rig, int width,
                                    int height, int refine_band);
void pipe__cockpit_destroy(pipe__cockpit *c);
/* pipe_add_prop. */
int pipe__cockpit_add_prop(pipe__cockpit *c, const kin_model *m);
int pipe__cockpit_prop_count(const pipe__cockpit *c);
/* The parts that own at least one triangle. */
unsigned pipe__cockpit_present(const pipe__cockpit *c);
/* Checks in->hide / prop_world / prop_count and prepares the frame.
 * PIPE_ERR_ARGS (with why) for a bad prop count or when the index lists of
 * a new visibility set cannot be allocated. Nothing is drawn. */
pipe_result pipe__cockpit_frame(pipe__cockpit *c, const pipe_frame_in *in, char *why,
                                int why_size);
/* 1 when this frame hides a part the model has or draws a prop: the eyes
 * draw through pipe__cockpit_draw; 0: pipe_pose_draw, the bytes of old. */
int pipe__cockpit_active(const pipe__cockpit *c);
/* pipe_pose_draw with the visible triangles of ps, then the visible props
 * (both faces), into the same target. clip and vnrm: as pipe_pose_draw
 * (ps->max_vertices); props use scratch of their own (per eye). */
rast_result pipe__cockpit_draw(pipe__cockpit *c, const pipe_pose *ps, int eye,
                               rast_context *ctx, const kin_camera *cam,
                               const rast_target *target, rast_cull cull, float *clip,
                               float *vnrm);
/* pipe__cockpit_draw's visible triangles and props into the eye's
 * anti-aliased coverage (pipe_aa.h) instead of a G-buffer. */
rast_result pipe__cockpit_draw_aa(pipe__cockpit *c, const pipe_pose *ps, int eye,
                                  rast_context *ctx, const kin_camera *cam, pipe__aa *aa,
                                  rast_cull cull, float *clip);
/* After the refinement of eye's mask: where a part is hidden, the refined
 * mask keeps no pixel outside the kinematic mask within band px
 * (chessboard distance) of the hidden triangles' silhouette. Nothing
 * unless active and something is hidden. clip: as pipe__cockpit_draw. */
void pipe__cockpit_clamp(pipe__cockpit *c, const pipe_pose *ps, int eye, rast_context *ctx,
                         const kin_camera *cam, const uint8_t *mask, int mask_stride,
                         uint8_t *refined, int refined_stride, int band, float *clip);

#endif
