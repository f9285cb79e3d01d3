/* pipe_morph.h - morph targets in the posing of src/pipe (internal). */
#ifndef EGOFUSE_PIPE_MORPH_H
#define EGOFUSE_PIPE_MORPH_H

#include "pipe.h"

/* Allocates ps->morph_* for the meshes with morph targets (their default
 * weights copied). 0, or -1 when out of memory (pipe_pose_free frees). */
int  pipe__morph_init(pipe_pose *ps);
void pipe__morph_free(pipe_pose *ps);
/* Weights of every morphed mesh: its defaults, then anim's `weights`
 * channel of its node at t (anim NULL: the defaults). */
void pipe__morph_weights(pipe_pose *ps, const kin_animation *anim, float t);
/* Morphs vertices [v0, v1) of mesh i into ps->morph_pos/nrm[i] and returns
 * a view of the mesh reading them (the mesh itself when it has no
 * targets). */
kin_mesh pipe__morph_mesh(const pipe_pose *ps, int i, int v0, int v1);

#endif
