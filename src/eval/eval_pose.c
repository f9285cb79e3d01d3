/* eval_pose.c - the posed mask model's buffers (eval_internal.h:
 * eval_pose), allocated and freed in one place for eval.c and
 * eval_eye.c. */
#include "eval_internal.h"

#include <stdlib.h>
#include <string.h>

#include "../../samples/gen/gen.h"

int eval__pose_init(eval_pose *p, const kin_model *m, int vertex_count)
{
    const size_t N = (size_t)m->node_count, V = (size_t)vertex_count;
    const size_t J = (size_t)m->skins[0].joint_count;
    p->world = malloc(sizeof *p->world * N);
    p->tworld = malloc(sizeof *p->tworld * N);
    p->tlocals = malloc(sizeof *p->tlocals * N);
    p->jm = malloc(sizeof *p->jm * J);
    p->pos = malloc(sizeof(float) * 3 * V);
    p->nrm = malloc(sizeof(float) * 3 * V);
    p->clip = malloc(sizeof(float) * 4 * V);
    p->vnrm = malloc(sizeof(float) * 3 * V);
    p->cam_rgb = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 3);
    p->gt_mask = malloc((size_t)GEN_CAM_W * GEN_CAM_H);
    p->gt_depth = malloc(sizeof(float) * GEN_CAM_W * GEN_CAM_H);
    return p->world && p->tworld && p->tlocals && p->jm && p->pos && p->nrm && p->clip &&
                   p->vnrm && p->cam_rgb && p->gt_mask && p->gt_depth
               ? 0
               : -1;
}

void eval__pose_free(eval_pose *p)
{
    free(p->world); free(p->jm); free(p->tworld); free(p->tlocals);
    free(p->pos); free(p->nrm); free(p->clip); free(p->vnrm);
    free(p->cam_rgb); free(p->gt_mask); free(p->gt_depth);
    memset(p, 0, sizeof *p);
}
