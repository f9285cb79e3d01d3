/* pipe_lod.h - levels of detail of the mask model: plain data the core
 * draws, and the rule that picks a level per frame and per eye.
 *
 * WHAT IT IS
 *   A pipe_lod is a chain of levels of one kin_model. Level 0 is the model
 *   itself (its own index lists, the same bytes as without levels); level
 *   L > 0 holds, for every mesh of the model, a kin_mesh that shares ALL
 *   the model's vertex arrays (positions, normals, joints, weights, morph
 *   targets: the same pointers, the same vertex_count) and has an index
 *   list of its own with fewer triangles. Every vertex a level draws is a
 *   vertex of the model, so skinning, morphing, the parts (pipe_parts.c)
 *   and the elbow fit (which read vertices) are those of the full model:
 *   one skin per frame serves every level and both eyes.
 *   The chain is built when the model is loaded, outside the core
 *   (src/io/io_lod.h, meshoptimizer); the core only reads it.
 *
 * THE RULE (pipe_lod_choose)
 *   Each level L carries error_m: the largest distance (metres, the mesh's
 *   space) between its surface and the full model's, as the simplifier
 *   measured it (0 for level 0; nondecreasing along the chain). An eye
 *   draws the coarsest level whose error, seen from the eye at the
 *   nearest point of the model in view, is at most target_px pixels:
 *       px_per_m = f / z_near          (f: the camera's focal length in
 *                                       pixels, max of fx and fy; z_near:
 *                                       the smallest view depth of the
 *                                       model's vertices inside the view)
 *       level = max { L : level[L'].error_m * px_per_m <= target_px
 *                          for every L' <= L }
 *   Equality counts as inside. Nothing in view (z_near unknown), a vertex
 *   at or behind the eye, target_px <= 0 or a non-finite input: level 0.
 *   The nearest point is where a deviation is largest on the screen, so
 *   no point of the model shows a deviation above target_px (up to the
 *   simplifier's own error estimate and the skin's stretching).
 */
#ifndef EGOFUSE_PIPE_LOD_H
#define EGOFUSE_PIPE_LOD_H

#include "../kin/kin.h"
#include "../raster/raster.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PIPE_LOD_MAX 8

typedef struct pipe_lod_level {
    const kin_mesh *meshes;   /* mesh_count meshes (level 0: the model's) */
    long triangles;           /* over all meshes */
    float error_m;            /* the simplifier's error, metres; 0 at level 0 */
    float edge_m;             /* mean triangle edge length, metres (reports) */
} pipe_lod_level;

typedef struct pipe_lod {
    int mesh_count;           /* of the model */
    int level_count;          /* 1..PIPE_LOD_MAX (1: the model alone) */
    pipe_lod_level level[PIPE_LOD_MAX];
    void *block;              /* owner of the levels' memory (the builder's) */
} pipe_lod;

/* The rule above: the level for px_per_m (pixels per metre at the nearest
 * point of the model in view; <= 0 or not finite: level 0) and target_px.
 * 0 for lod NULL. */
int pipe_lod_choose(const pipe_lod *lod, float px_per_m, float target_px);

/* px_per_m of the rule from clip coordinates (4 floats per vertex, as
 * rast_transform_points writes them) of n vertices and the camera's focal
 * length focal_px: focal_px / (smallest w of a vertex with w > 0 and
 * |x|, |y| <= w); 0 when no vertex is inside the view. A vertex inside the
 * view with w <= 1e-6 gives +inf (level 0). */
float pipe_lod_px_per_m(const float *clip, int n, float focal_px);

/* 1 when lod is a chain of model: mesh_count equal, each level's meshes
 * share the model's vertex arrays and have index lists < vertex_count,
 * level 0's meshes the model's; 0 otherwise (why gets the reason). */
int pipe_lod_check(const pipe_lod *lod, const kin_model *model, char *why, int why_size);

/* pipe_pose_draw with levels: per mesh i of the posed model, the vertices
 * are transformed as pipe_pose_draw does, then the index list of level
 * `level` (clamped to the chain) is drawn, or with level PIPE_LOD_AUTO
 * the level pipe_lod_choose gives for pipe_lod_px_per_m(mesh i's clip
 * coordinates, max(cam->fx, cam->fy)) and target_px. Level 0 draws the
 * bytes of pipe_pose_draw. *drawn (may be NULL): the finest level drawn
 * over the meshes that have triangles (0 without any). pose is a
 * pipe_pose (pipe.h) of the chain's model; lod NULL: pipe_pose_draw. */
#define PIPE_LOD_AUTO (-1)
struct pipe_pose;
rast_result pipe_lod_draw(const struct pipe_pose *pose, const pipe_lod *lod, int level,
                          float target_px, rast_context *ctx, const kin_camera *cam,
                          const rast_target *target, rast_cull cull, float *clip, float *vnrm,
                          rast_stats *stats, int *drawn);

#ifdef __cplusplus
}
#endif
#endif
