/* pipe_pose.c - posing and skinning of one model (see pipe_pose.h). */
#include "pipe_pose.h"
#include "pipe_morph.h"
#include "pipe_internal.h"
#include "../cpu/ef_mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Area-weighted smooth vertex normals for meshes without NORMAL. (glTF
 * asks for flat normals then; they matter only for lighting, and smooth
 * ones shade a rounded model better.) */
static void smooth_normals(const kin_mesh *m, float *out)
{
    memset(out, 0, sizeof(float) * 3 * (size_t)m->vertex_count);
    for (int i = 0; i + 2 < m->index_count; i += 3) {
        const uint32_t v[3] = {m->indices[i], m->indices[i + 1], m->indices[i + 2]};
        const float *a = m->positions + 3 * v[0], *b = m->positions + 3 * v[1],
                    *c = m->positions + 3 * v[2];
        kin_vec3 n = kin_v3_cross(kin_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                                  kin_v3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
        for (int k = 0; k < 3; k++) {
            out[3 * v[k] + 0] += n.x;
            out[3 * v[k] + 1] += n.y;
            out[3 * v[k] + 2] += n.z;
        }
    }
    for (int i = 0; i < m->vertex_count; i++) {
        kin_vec3 n = kin_v3_norm(kin_v3(out[3 * i], out[3 * i + 1], out[3 * i + 2]));
        out[3 * i + 0] = n.x;
        out[3 * i + 1] = n.y;
        out[3 * i + 2] = n.z;
    }
}

int pipe_pose_init(pipe_pose *ps, const kin_model *m)
{
    memset(ps, 0, sizeof *ps);
    ps->model = m;
    size_t nn = (size_t)(m->node_count > 0 ? m->node_count : 1);
    size_t nm = (size_t)m->mesh_count + 1;
    ps->locals = calloc(nn, sizeof *ps->locals);
    ps->world = calloc(nn, sizeof *ps->world);
    ps->joint_mats = calloc((size_t)m->skin_count + 1, sizeof *ps->joint_mats);
    ps->meshes = calloc(nm, sizeof *ps->meshes);
    ps->own_normals = calloc(nm, sizeof(float *));
    ps->pos = calloc(nm, sizeof(float *));
    ps->nrm = calloc(nm, sizeof(float *));
    if (!ps->locals || !ps->world || !ps->joint_mats || !ps->meshes ||
        !ps->own_normals || !ps->pos || !ps->nrm)
        goto oom;
    for (int s = 0; s < m->skin_count; s++) {
        ps->joint_mats[s] = calloc((size_t)m->skins[s].joint_count, sizeof(kin_mat4));
        if (!ps->joint_mats[s]) goto oom;
    }
    ps->max_vertices = 1;
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &m->meshes[i];
        size_t nv = (size_t)me->vertex_count;
        if (me->vertex_count > ps->max_vertices) ps->max_vertices = me->vertex_count;
        ps->meshes[i] = *me;
        if (!me->normals) {
            ps->own_normals[i] = malloc(sizeof(float) * 3 * nv);
            if (!ps->own_normals[i]) goto oom;
            smooth_normals(me, ps->own_normals[i]);
            ps->meshes[i].normals = ps->own_normals[i];
        }
        ps->pos[i] = malloc(sizeof(float) * 3 * nv);
        ps->nrm[i] = malloc(sizeof(float) * 3 * nv);
        if (!ps->pos[i] || !ps->nrm[i]) goto oom;
    }
    if (pipe__morph_init(ps) != 0) goto oom;
    return 0;
oom:
    pipe_pose_free(ps);
    return -1;
}

void pipe_pose_free(pipe_pose *ps)
{
    const kin_model *m = ps->model;
    if (m) {
        for (int s = 0; ps->joint_mats && s < m->skin_count; s++)
            free(ps->joint_mats[s]);
        for (int i = 0; i < m->mesh_count; i++) {
            if (ps->own_normals) free(ps->own_normals[i]);
            if (ps->pos) free(ps->pos[i]);
            if (ps->nrm) free(ps->nrm[i]);
        }
    }
    pipe__morph_free(ps);
    EF_FREE_ALL(ps->joint_mats, ps->own_normals, ps->meshes, ps->pos, ps->nrm, ps->locals,
                ps->world);
    memset(ps, 0, sizeof *ps);
}

/* FK from ps->locals and the joint matrices. */
void pipe__pose_fk(pipe_pose *ps)
{
    const kin_model *m = ps->model;
    kin_fk(m->parents, m->node_count, ps->locals, NULL, ps->world);
    for (int s = 0; s < m->skin_count; s++)
        kin_skin_joint_matrices(&m->skins[s], ps->world, ps->joint_mats[s]);
}

/* Skins part `part` of `parts` of every mesh's vertices into world space.
 * Every vertex is skinned on its own, so the bytes do not depend on how
 * the vertices are split. Parts start on multiples of 16 vertices so that
 * the SIMD paths run full blocks. plans (per mesh, or NULL): skin plans of
 * the skinned meshes (kin_skin_lbs_plan: the same bytes as kin_skin_lbs,
 * about 2x faster; parts are runs of its batches). */
void pipe__pose_skin_part(pipe_pose *ps, const kin_skin_plan *plans, int part, int parts)
{
    const kin_model *m = ps->model;
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        if (me->skin >= 0 && plans && plans[i].batches) {
            kin_skin_lbs_plan_part(&plans[i], ps->joint_mats[me->skin], ps->pos[i], ps->nrm[i],
                                   part, parts, 0);
            continue;
        }
        int per = ((me->vertex_count + parts - 1) / parts + 15) & ~15;
        int v0 = part * per, v1 = v0 + per < me->vertex_count ? v0 + per : me->vertex_count;
        if (v0 >= v1) continue;
        kin_mesh sub = pipe__morph_mesh(ps, i, v0, v1); /* a view of [v0, v1) */
        sub.vertex_count = v1 - v0;
        sub.positions += 3 * v0;
        if (sub.normals) sub.normals += 3 * v0;
        if (sub.joints) sub.joints += 4 * v0;
        if (sub.weights) sub.weights += 4 * v0;
        sub.indices = NULL;
        sub.index_count = 0;
        float *pos = ps->pos[i] + 3 * v0, *nrm = ps->nrm[i] + 3 * v0;
        if (me->skin >= 0) {
            /* glTF: a skinned mesh ignores its own node's transform. */
            kin_skin_lbs(&sub, ps->joint_mats[me->skin], pos, nrm);
        } else {
            kin_mat4 id = kin_mat4_identity();
            kin_mesh_transform(&sub, me->node >= 0 ? &ps->world[me->node] : &id, pos, nrm);
        }
    }
}

static void pose_skin(pipe_pose *ps)
{
    pipe__pose_fk(ps);
    pipe__pose_skin_part(ps, NULL, 0, 1);
}

void pipe__pose_locals_anim(pipe_pose *ps, const kin_animation *anim, float t)
{
    kin_pose_rest(ps->model, ps->locals);
    if (anim) kin_anim_sample(anim, ps->model->node_count, t, ps->locals);
    pipe__morph_weights(ps, anim, t);
}

void pipe_pose_anim(pipe_pose *ps, const kin_animation *anim, float t)
{
    pipe__pose_locals_anim(ps, anim, t);
    pose_skin(ps);
}

void pipe_pose_locals(pipe_pose *ps, const kin_transform *locals)
{
    memcpy(ps->locals, locals, sizeof *locals * (size_t)ps->model->node_count);
    pipe__morph_weights(ps, NULL, 0.0f);
    pose_skin(ps);
}

rast_result pipe_pose_draw(const pipe_pose *ps, rast_context *ctx,
                           const kin_camera *cam, const rast_target *target,
                           rast_cull cull, float *clip, float *vnrm,
                           rast_stats *stats)
{
    const int with_n = target->attr_count == 3;
    for (int i = 0; i < ps->model->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        rast_transform_points(cam->view_proj.m, ps->pos[i], me->vertex_count, clip);
        if (with_n) rast_transform_dirs(cam->view.m, ps->nrm[i], me->vertex_count, vnrm);
        rast_mesh_desc d = {
            .clip = clip,
            .vertex_count = me->vertex_count,
            .attr = with_n ? vnrm : NULL,
            .attr_count = with_n ? 3 : 0,
            .indices = me->indices,
            .tri_count = me->index_count / 3,
            .cull = cull,
        };
        rast_result r = ctx ? rast_context_draw(ctx, target, &d, stats)
                            : rast_draw(target, &d, stats);
        if (r != RAST_OK) return r;
    }
    return RAST_OK;
}
