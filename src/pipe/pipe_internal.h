/* pipe_internal.h - internal to src/pipe: the steps of posing
 * (pipe_pose.c) that the frame (pipe.c) runs on its own, one at a time or
 * split over its two threads. Nothing here is public. */
#ifndef EGOFUSE_PIPE_INTERNAL_H
#define EGOFUSE_PIPE_INTERNAL_H

#include "pipe_pose.h"

/* FK from ps->locals and the joint matrices. */
void pipe__pose_fk(pipe_pose *ps);
/* Skins part `part` of `parts` of every mesh's vertices into world space
 * (the bytes do not depend on the split); plans: per mesh, or NULL. */
void pipe__pose_skin_part(pipe_pose *ps, const kin_skin_plan *plans, int part, int parts);
/* ps->locals from anim at t (NULL: the rest pose) and the morph weights. */
void pipe__pose_locals_anim(pipe_pose *ps, const kin_animation *anim, float t);

/* Writes the printf-style message into why[why_size] (when why is not
 * NULL) and returns -1: the error path of the room's checked calls
 * (pipe_mask.c, pipe_lens.c); defined in pipe_fail.c. */
int pipe__fail(char *why, int why_size, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Soft viewport edges (pipe_desc.edge_fade, fuse_edge.h): the ramp width in
 * camera pixels the desc asks for (0: off), and the sides of the viewport
 * (vx, vy, vw, vh) that end inside an ow x oh output (FUSE_EDGE_*). A
 * reprojection fades its camera samples with fuse_edge_weight(sx, sy,
 * cam_w, cam_h, pipe__edge_fade_px(d), FUSE_EDGE_ALL). */
struct pipe_desc;
int pipe__edge_fade_px(const struct pipe_desc *d);
unsigned pipe__edge_sides(int vx, int vy, int vw, int vh, int ow, int oh);

#endif
