/* pose.c - pose a kin_model, skin it once per frame, draw it per camera. */
#include "cli.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Area-weighted smooth vertex normals, for meshes without NORMAL. (glTF
 * asks for flat normals then; they only matter for lighting and the
 * --normals image, and smooth ones shade a rounded model better.) */
static void smooth_normals(const kin_mesh *m, float *out)
{
    memset(out, 0, sizeof(float) * 3 * (size_t)m->vertex_count);
    for (int i = 0; i + 2 < m->index_count; i += 3) {
        const uint32_t a = m->indices[i], b = m->indices[i + 1],
                       c = m->indices[i + 2];
        const float *pa = m->positions + 3 * a, *pb = m->positions + 3 * b,
                    *pc = m->positions + 3 * c;
        kin_vec3 e1 = kin_v3(pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]);
        kin_vec3 e2 = kin_v3(pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]);
        kin_vec3 n = kin_v3_cross(e1, e2); /* length = 2 * area */
        const uint32_t v[3] = {a, b, c};
        for (int k = 0; k < 3; k++) {
            out[3 * v[k] + 0] += n.x;
            out[3 * v[k] + 1] += n.y;
            out[3 * v[k] + 2] += n.z;
        }
    }
    for (int v = 0; v < m->vertex_count; v++) {
        kin_vec3 n = kin_v3_norm(kin_v3(out[3 * v], out[3 * v + 1], out[3 * v + 2]));
        out[3 * v + 0] = n.x;
        out[3 * v + 1] = n.y;
        out[3 * v + 2] = n.z;
    }
}

int pose_init(pose_state *ps, const kin_model *m)
{
    memset(ps, 0, sizeof *ps);
    ps->model = m;
    size_t nn = (size_t)(m->node_count > 0 ? m->node_count : 1);
    ps->locals = calloc(nn, sizeof *ps->locals);
    ps->world = calloc(nn, sizeof *ps->world);
    ps->joint_mats = calloc((size_t)m->skin_count + 1, sizeof *ps->joint_mats);
    ps->bind_normals = calloc((size_t)m->mesh_count + 1, sizeof(float *));
    ps->meshes = calloc((size_t)m->mesh_count + 1, sizeof *ps->meshes);
    ps->pos = calloc((size_t)m->mesh_count + 1, sizeof(float *));
    ps->nrm = calloc((size_t)m->mesh_count + 1, sizeof(float *));
    if (!ps->locals || !ps->world || !ps->joint_mats || !ps->bind_normals ||
        !ps->meshes || !ps->pos || !ps->nrm)
        goto oom;
    for (int s = 0; s < m->skin_count; s++) {
        ps->joint_mats[s] = calloc((size_t)m->skins[s].joint_count, sizeof(kin_mat4));
        if (!ps->joint_mats[s]) goto oom;
    }
    size_t maxv = 1;
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &m->meshes[i];
        size_t nv = (size_t)me->vertex_count;
        if (nv > maxv) maxv = nv;
        ps->meshes[i] = *me;
        if (!me->normals) {
            ps->bind_normals[i] = malloc(sizeof(float) * 3 * nv);
            if (!ps->bind_normals[i]) goto oom;
            smooth_normals(me, ps->bind_normals[i]);
            ps->meshes[i].normals = ps->bind_normals[i];
        }
        ps->pos[i] = malloc(sizeof(float) * 3 * nv);
        ps->nrm[i] = malloc(sizeof(float) * 3 * nv);
        if (!ps->pos[i] || !ps->nrm[i]) goto oom;
    }
    ps->clip = malloc(sizeof(float) * 4 * maxv);
    ps->vnrm = malloc(sizeof(float) * 3 * maxv);
    if (!ps->clip || !ps->vnrm) goto oom;
    return 0;
oom:
    pose_free(ps);
    return -1;
}

void pose_free(pose_state *ps)
{
    const kin_model *m = ps->model;
    if (m) {
        for (int s = 0; ps->joint_mats && s < m->skin_count; s++)
            free(ps->joint_mats[s]);
        for (int i = 0; i < m->mesh_count; i++) {
            if (ps->bind_normals) free(ps->bind_normals[i]);
            if (ps->pos) free(ps->pos[i]);
            if (ps->nrm) free(ps->nrm[i]);
        }
    }
    free(ps->joint_mats);
    free(ps->bind_normals);
    free(ps->meshes);
    free(ps->pos);
    free(ps->nrm);
    free(ps->locals);
    free(ps->world);
    free(ps->clip);
    free(ps->vnrm);
    memset(ps, 0, sizeof *ps);
}

void pose_eval(pose_state *ps, const kin_animation *anim, float t)
{
    const kin_model *m = ps->model;
    kin_pose_rest(m, ps->locals);
    if (anim) kin_anim_sample(anim, m->node_count, t, ps->locals);
    kin_fk(m->parents, m->node_count, ps->locals, NULL, ps->world);
    for (int s = 0; s < m->skin_count; s++)
        kin_skin_joint_matrices(&m->skins[s], ps->world, ps->joint_mats[s]);
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        if (me->skin >= 0) {
            /* glTF: a skinned mesh ignores its node's transform. */
            kin_skin_lbs(me, ps->joint_mats[me->skin], ps->pos[i], ps->nrm[i]);
        } else {
            kin_mat4 id = kin_mat4_identity();
            const kin_mat4 *w = me->node >= 0 ? &ps->world[me->node] : &id;
            kin_mesh_transform(me, w, ps->pos[i], ps->nrm[i]);
        }
    }
}

rast_result pose_draw(pose_state *ps, const kin_camera *cam,
                      const rast_target *target, rast_stats *stats)
{
    const kin_model *m = ps->model;
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        rast_transform_points(cam->view_proj.m, ps->pos[i], me->vertex_count,
                              ps->clip);
        if (target->attr_count == 3)
            rast_transform_dirs(cam->view.m, ps->nrm[i], me->vertex_count,
                                ps->vnrm);
        rast_mesh_desc d = {
            .clip = ps->clip,
            .vertex_count = me->vertex_count,
            .attr = target->attr_count == 3 ? ps->vnrm : NULL,
            .attr_count = target->attr_count == 3 ? 3 : 0,
            .indices = me->indices,
            .tri_count = me->index_count / 3,
            .cull = RAST_CULL_NONE,
        };
        rast_result r = rast_draw(target, &d, stats);
        if (r != RAST_OK) return r;
    }
    return RAST_OK;
}
