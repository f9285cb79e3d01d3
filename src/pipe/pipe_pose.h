/* pipe_pose.h - posing and skinning of one model, once per frame, into
 * world space; and drawing the posed model through a camera.
 *
 * WHAT IT DOES
 *   pipe_pose_*: poses a kin_model (rest pose, an animation at time t, or
 *   local transforms given by the caller, e.g. from IK), applies its morph
 *   targets (pipe_morph.c) and skins every mesh into world space (both eyes
 *   of a pipe use the same skin). Meshes without normals get smooth,
 *   area-weighted ones once, at pipe_pose_init. pipe_pose_draw rasterizes
 *   the posed meshes through a kin_camera into a rast_target.
 *
 * WHAT IT DOES NOT
 *   No threads of its own (pipe.c splits the skinning of large models over
 *   its two threads), no cameras or images, no I/O. Allocates only in
 *   pipe_pose_init.
 *
 * USAGE
 *   pipe_pose ps;
 *   if (pipe_pose_init(&ps, &model) != 0) return -1;
 *   pipe_pose_anim(&ps, &model.anims[0], t);     // or pipe_pose_locals
 *   pipe_pose_draw(&ps, NULL, &cam, &target, RAST_CULL_BACK, clip, vnrm, NULL);
 *   pipe_pose_free(&ps);
 */
#ifndef EGOFUSE_PIPE_POSE_H
#define EGOFUSE_PIPE_POSE_H

#include "../kin/kin.h"
#include "../raster/raster.h"

#ifdef __cplusplus
extern "C" {
#endif

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
    /* morph targets (pipe_morph.c), per mesh, NULL for meshes without:
     * the current weights (target_count; the node's defaults, or the
     * animation's `weights` channel in pipe_pose_anim / pipe_frame with
     * an animation), and the morphed bind positions / normals that are
     * then skinned (3 per vertex) */
    float **morph_w;
    float **morph_pos;
    float **morph_nrm;
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

#ifdef __cplusplus
}
#endif
#endif
