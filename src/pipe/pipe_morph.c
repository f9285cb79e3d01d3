/* pipe_morph.c - morph targets in the posing of src/pipe: the weighted
 * deltas go into a scratch copy of the bind positions / normals, which is
 * then skinned (or moved rigidly) as a mesh without targets. */
#include "pipe_morph.h"

#include <stdlib.h>
#include <string.h>

int pipe__morph_init(pipe_pose *ps)
{
    const kin_model *m = ps->model;
    size_t nm = (size_t)m->mesh_count + 1;
    ps->morph_w = calloc(nm, sizeof(float *));
    ps->morph_pos = calloc(nm, sizeof(float *));
    ps->morph_nrm = calloc(nm, sizeof(float *));
    if (!ps->morph_w || !ps->morph_pos || !ps->morph_nrm) return -1;
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        if (me->target_count <= 0 || !me->target_positions) continue;
        size_t nv = (size_t)me->vertex_count;
        ps->morph_w[i] = malloc(sizeof(float) * (size_t)me->target_count);
        ps->morph_pos[i] = malloc(sizeof(float) * 3 * nv);
        ps->morph_nrm[i] = malloc(sizeof(float) * 3 * nv);
        if (!ps->morph_w[i] || !ps->morph_pos[i] || !ps->morph_nrm[i]) return -1;
        for (int k = 0; k < me->target_count; k++)
            ps->morph_w[i][k] = me->target_weights ? me->target_weights[k] : 0.0f;
    }
    return 0;
}

void pipe__morph_free(pipe_pose *ps)
{
    const kin_model *m = ps->model;
    for (int i = 0; m && i < m->mesh_count; i++) {
        if (ps->morph_w) free(ps->morph_w[i]);
        if (ps->morph_pos) free(ps->morph_pos[i]);
        if (ps->morph_nrm) free(ps->morph_nrm[i]);
    }
    free(ps->morph_w);
    free(ps->morph_pos);
    free(ps->morph_nrm);
    ps->morph_w = ps->morph_pos = ps->morph_nrm = NULL;
}

void pipe__morph_weights(pipe_pose *ps, const kin_animation *anim, float t)
{
    const kin_model *m = ps->model;
    for (int i = 0; ps->morph_w && i < m->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        float *w = ps->morph_w[i];
        if (!w) continue;
        for (int k = 0; k < me->target_count; k++)
            w[k] = me->target_weights ? me->target_weights[k] : 0.0f;
        if (anim) kin_anim_sample_weights(anim, me->node, t, w, me->target_count);
    }
}

kin_mesh pipe__morph_mesh(const pipe_pose *ps, int i, int v0, int v1)
{
    kin_mesh me = ps->meshes[i];
    if (!ps->morph_w || !ps->morph_w[i]) return me;
    kin_morph_apply(&ps->meshes[i], ps->morph_w[i], ps->morph_pos[i],
                    me.normals ? ps->morph_nrm[i] : NULL, v0, v1);
    me.positions = ps->morph_pos[i];
    if (me.normals) me.normals = ps->morph_nrm[i];
    me.target_count = 0;
    me.target_positions = me.target_normals = me.target_weights = NULL;
    return me;
}
