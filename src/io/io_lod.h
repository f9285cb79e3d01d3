/* io_lod.h - the level-of-detail chain of a model (src/pipe/pipe_lod.h),
 * built with meshoptimizer when the model is loaded. The core never
 * includes this header; it reads the plain pipe_lod this fills.
 *
 * HOW A LEVEL IS BUILT
 *   Per mesh, the triangles are grouped by their dominant joint (the joint
 *   with the largest weight summed over the triangle's three vertices,
 *   every influence set; ties to the lower joint index; an unskinned mesh
 *   is one group). Each group is simplified on its own by
 *   meshopt_simplify (positions only; meshoptimizer 0.18 has no attribute
 *   metric) with meshopt_SimplifyLockBorder, to ratio^L of its triangles
 *   (rounded down to whole triangles), so the vertices where two joints'
 *   triangles meet stay where they are: the rings at the joints, where the
 *   skin bends, keep their full detail, and no triangle of a level spans
 *   joints the full model's triangles do not. The groups' lists, in group
 *   order, are then ordered for the vertex cache
 *   (meshopt_optimizeVertexCache). meshopt_simplify only removes vertices
 *   (it collapses edges onto existing vertices), so a level's index list
 *   reads the model's own vertices: joints, weights, normals and morph
 *   targets are the model's, untouched (pipe_lod.h).
 *   error_m: the largest meshopt_simplify error of the level's groups
 *   (relative) times meshopt_simplifyScale of the mesh's positions
 *   (metres), the largest over meshes, and at least the previous level's.
 *   The chain stops before a level that keeps more than 90% of the
 *   previous level's triangles (nothing left to simplify: a model that
 *   cannot be simplified has level 0 alone) or has fewer than
 *   min_triangles.
 *
 * DETERMINISM
 *   meshoptimizer's simplifier and cache optimizer are deterministic for
 *   the same inputs (no threads, no randomness, integer and float code
 *   without FMA contraction in Debian's build); the grouping is integer
 *   and double sums in a fixed order. The same model gives the same chain
 *   bytes for the same meshoptimizer version (Debian 12: 0.18+dfsg-2,
 *   MESHOPTIMIZER_VERSION 180; io_lod_version reports the one linked).
 *
 * USAGE
 *   pipe_lod lod;
 *   if (io_lod_build("arms.glb", &model, NULL, &lod, &err) != IO_OK) ...
 *   ... pipe_set_lod(p, &lod) / draw lod.level[l].meshes ...
 *   io_lod_free(&lod);                 // before the model is freed
 */
#ifndef EGOFUSE_IO_LOD_H
#define EGOFUSE_IO_LOD_H

#include "io.h"
#include "../pipe/pipe_lod.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct io_lod_desc {
    int max_levels;           /* levels after level 0; 0 = 4, at most
                                 PIPE_LOD_MAX - 1 */
    float ratio;              /* triangles of level L: ratio^L of the
                                 model's; 0 = 0.5, in (0, 1) */
    int min_triangles;        /* no level below this many; 0 = 64 */
    int whole;                /* 1: simplify each mesh whole, no joint
                                 groups and no locked borders (for
                                 comparison); 0 = the groups above */
} io_lod_desc;

/* Builds the chain of model into *lod (zeroed first; level 0 is the
 * model's own meshes). name names the model in messages (a path). desc
 * NULL = defaults. IO_ERR_ARGS for NULL pointers or a setting out of
 * range, IO_ERR_VALUE "name: reason" for a model kin_model_validate
 * refuses or one without triangles, IO_ERR_NOMEM; nothing to free then.
 * The chain points into the model: free it first. */
io_result io_lod_build(const char *name, const kin_model *model, const io_lod_desc *desc,
                       pipe_lod *lod, io_error *err);
void io_lod_free(pipe_lod *lod);
/* MESHOPTIMIZER_VERSION of the headers built against (180 = 0.18). */
int io_lod_version(void);

#ifdef __cplusplus
}
#endif
#endif
