/* gt.c - the ground truth of `egofuse eval`: the true operator, the
 * cockpit with skin-coloured objects, the exact silhouettes and the noisy,
 * late, lossy tracking of the true motion (gt.h). */
#include "gt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

gt_operator_desc gt_operator_default(void)
{
    return (gt_operator_desc){.shoulder_scale = 1.03f, .upper_scale = 1.07f, .fore_scale = 0.95f,
                              .hand_scale = 1.05f, .upper_thick = 1.12f, .fore_thick = 0.93f,
                              .hand_thick = 1.04f, .subdivide = 1};
}

gt_track_desc gt_track_default(void)
{
    return (gt_track_desc){.noise_mm = 5.0f, .rot_noise_deg = 0.5f, .head_rot_noise_deg = 0.1f,
                           .glove_noise = 0.03f, .latency_ms = 20.0f, .dropout = 0.02f,
                           .rate_hz = 90.0f, .speed = 1.0f, .seed = 1};
}

/* ------------------------------------------------------------ the body */

/* Area-weighted smooth normals. */
static void normals_of(const float *pos, int nv, const uint32_t *idx, int nt,
                       float *nrm)
{
    memset(nrm, 0, sizeof(float) * 3 * (size_t)nv);
    for (int t = 0; t < nt; t++) {
        const uint32_t *ix = &idx[t * 3];
        const float *a = &pos[ix[0] * 3], *b = &pos[ix[1] * 3], *c = &pos[ix[2] * 3];
        kin_vec3 n = kin_v3_cross(kin_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]),
                                  kin_v3(c[0] - a[0], c[1] - a[1], c[2] - a[2]));
        for (int k = 0; k < 3; k++) {
            nrm[ix[k] * 3 + 0] += n.x;
            nrm[ix[k] * 3 + 1] += n.y;
            nrm[ix[k] * 3 + 2] += n.z;
        }
    }
    for (int v = 0; v < nv; v++) {
        kin_vec3 n = kin_v3_norm(kin_v3(nrm[v * 3], nrm[v * 3 + 1], nrm[v * 3 + 2]));
        if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) n = kin_v3(0, 1, 0);
        nrm[v * 3 + 0] = n.x;
        nrm[v * 3 + 1] = n.y;
        nrm[v * 3 + 2] = n.z;
    }
}

/* Vertex arrays of a mesh under construction. */
typedef struct vbuf {
    int nv, nt;
    float *pos, *nrm, *w, *albedo, *uv;
    uint16_t *jnt;
    uint32_t *idx;
} vbuf;

static int vbuf_alloc(void **block, vbuf *b, int nv, int nt)
{
    b->nv = nv;
    b->nt = nt;
    b->pos = kin_block_alloc(block, sizeof(float) * 3 * (size_t)nv);
    b->nrm = kin_block_alloc(block, sizeof(float) * 3 * (size_t)nv);
    b->w = kin_block_alloc(block, sizeof(float) * 4 * (size_t)nv);
    b->albedo = kin_block_alloc(block, sizeof(float) * 3 * (size_t)nv);
    b->uv = kin_block_alloc(block, sizeof(float) * 2 * (size_t)nv);
    b->jnt = kin_block_alloc(block, sizeof(uint16_t) * 4 * (size_t)nv);
    b->idx = kin_block_alloc(block, sizeof(uint32_t) * 3 * (size_t)nt);
    return b->pos && b->nrm && b->w && b->albedo && b->uv && b->jnt && b->idx ? 0 : -1;
}

static int pattern_of(float u)
{
    return (int)floorf(u / GEN_PATTERN_STRIDE + 0.5f);
}

/* Midpoint vertex m of edge (a, b) of src into dst (PN-triangle edge
 * midpoint: the cubic through both ends with the ends' normals). */
static void midpoint(const vbuf *s, int a, int b, vbuf *d, int m)
{
    kin_vec3 pa = kin_v3(s->pos[a * 3], s->pos[a * 3 + 1], s->pos[a * 3 + 2]);
    kin_vec3 pb = kin_v3(s->pos[b * 3], s->pos[b * 3 + 1], s->pos[b * 3 + 2]);
    kin_vec3 na = kin_v3(s->nrm[a * 3], s->nrm[a * 3 + 1], s->nrm[a * 3 + 2]);
    kin_vec3 nb = kin_v3(s->nrm[b * 3], s->nrm[b * 3 + 1], s->nrm[b * 3 + 2]);
    float wab = kin_v3_dot(kin_v3_sub(pb, pa), na);
    float wba = kin_v3_dot(kin_v3_sub(pa, pb), nb);
    kin_vec3 p = kin_v3_sub(kin_v3_scale(kin_v3_add(pa, pb), 0.5f),
                            kin_v3_scale(kin_v3_add(kin_v3_scale(na, wab),
                                                    kin_v3_scale(nb, wba)), 0.125f));
    d->pos[m * 3 + 0] = p.x;
    d->pos[m * 3 + 1] = p.y;
    d->pos[m * 3 + 2] = p.z;
    /* weights: the mean of both ends, the 4 largest kept, renormalised */
    int j[8];
    float w[8];
    int n = 0;
    for (int e = 0; e < 2; e++) {
        int v = e ? b : a;
        for (int k = 0; k < 4; k++) {
            float wk = 0.5f * s->w[v * 4 + k];
            if (wk <= 0.0f) continue;
            int jk = s->jnt[v * 4 + k], f = 0;
            for (int i = 0; i < n; i++)
                if (j[i] == jk) { w[i] += wk; f = 1; }
            if (!f) { j[n] = jk; w[n] = wk; n++; }
        }
    }
    float sum = 0.0f;
    for (int k = 0; k < 4; k++) {
        int best = -1;
        for (int i = 0; i < n; i++)
            if (w[i] > 0.0f && (best < 0 || w[i] > w[best])) best = i;
        d->jnt[m * 4 + k] = best >= 0 ? (uint16_t)j[best] : 0;
        d->w[m * 4 + k] = best >= 0 ? w[best] : 0.0f;
        if (best >= 0) { sum += w[best]; w[best] = 0.0f; }
    }
    for (int k = 0; k < 4; k++) d->w[m * 4 + k] /= sum > 0.0f ? sum : 1.0f;
    for (int k = 0; k < 3; k++)
        d->albedo[m * 3 + k] = 0.5f * (s->albedo[a * 3 + k] + s->albedo[b * 3 + k]);
    if (pattern_of(s->uv[a * 2]) == pattern_of(s->uv[b * 2])) {
        d->uv[m * 2 + 0] = 0.5f * (s->uv[a * 2] + s->uv[b * 2]);
        d->uv[m * 2 + 1] = 0.5f * (s->uv[a * 2 + 1] + s->uv[b * 2 + 1]);
    } else {
        d->uv[m * 2 + 0] = s->uv[a * 2];
        d->uv[m * 2 + 1] = s->uv[a * 2 + 1];
    }
}

/* One level of PN-triangle subdivision of s into d (allocated here). */
static int subdivide(void **block, const vbuf *s, vbuf *d)
{
    size_t cap = 1;
    while (cap < (size_t)s->nt * 4) cap <<= 1;
    uint64_t *keys = malloc(sizeof *keys * cap);
    int *vals = malloc(sizeof *vals * cap);
    if (!keys || !vals) {
        free(keys);
        free(vals);
        return -1;
    }
    memset(keys, 0xFF, sizeof *keys * cap);
    /* count the edges first */
    int edges = 0;
    for (int t = 0; t < s->nt * 3; t++) {
        uint32_t a = s->idx[t], b = s->idx[t % 3 == 2 ? t - 2 : t + 1];
        uint64_t k = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
        size_t h = (size_t)((k * 0x9E3779B97F4A7C15ull) >> 20) & (cap - 1);
        while (keys[h] != UINT64_MAX && keys[h] != k) h = (h + 1) & (cap - 1);
        if (keys[h] == UINT64_MAX) {
            keys[h] = k;
            vals[h] = s->nv + edges++;
        }
    }
    if (vbuf_alloc(block, d, s->nv + edges, s->nt * 4) < 0) {
        free(keys);
        free(vals);
        return -1;
    }
    memcpy(d->pos, s->pos, sizeof(float) * 3 * (size_t)s->nv);
    memcpy(d->w, s->w, sizeof(float) * 4 * (size_t)s->nv);
    memcpy(d->jnt, s->jnt, sizeof(uint16_t) * 4 * (size_t)s->nv);
    memcpy(d->albedo, s->albedo, sizeof(float) * 3 * (size_t)s->nv);
    memcpy(d->uv, s->uv, sizeof(float) * 2 * (size_t)s->nv);
    for (size_t h = 0; h < cap; h++)
        if (keys[h] != UINT64_MAX)
            midpoint(s, (int)(keys[h] >> 32), (int)(keys[h] & 0xFFFFFFFFu), d, vals[h]);
    for (int t = 0; t < s->nt; t++) {
        uint32_t v[3], m[3];
        for (int e = 0; e < 3; e++) {
            v[e] = s->idx[t * 3 + e];
            uint32_t a = s->idx[t * 3 + e], b = s->idx[t * 3 + (e + 1) % 3];
            uint64_t k = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
            size_t h = (size_t)((k * 0x9E3779B97F4A7C15ull) >> 20) & (cap - 1);
            while (keys[h] != k) h = (h + 1) & (cap - 1);
            m[e] = (uint32_t)vals[h];
        }
        uint32_t *o = &d->idx[t * 12];
        const uint32_t tri[4][3] = { { v[0], m[0], m[2] }, { m[0], v[1], m[1] },
                                     { m[2], m[1], v[2] }, { m[0], m[1], m[2] } };
        memcpy(o, tri, sizeof tri);
    }
    free(keys);
    free(vals);
    normals_of(d->pos, d->nv, d->idx, d->nt, d->nrm);
    return 0;
}

#define ALLOC(ptr, n)                                                        \
    do {                                                                     \
        (ptr) = kin_block_alloc(&t->block, sizeof(*(ptr)) * (size_t)(n));    \
        if (!(ptr)) goto oom;                                                \
    } while (0)

int gt_truth_build(const gen_arms *mask, const gt_operator_desc *d,
                   gen_arms *truth)
{
    memset(truth, 0, sizeof *truth);
    const kin_model *m = &mask->model;
    kin_model *t = &truth->model;
    const int N = m->node_count;
    kin_mat4 *bold = malloc(sizeof *bold * (size_t)N);
    kin_mat4 *bnew = malloc(sizeof *bnew * (size_t)N);
    kin_mat4 *def = malloc(sizeof *def * (size_t)N);
    if (!bold || !bnew || !def) goto oom;
    truth->body = mask->body;
    truth->head = mask->head;
    truth->mesh_node = mask->mesh_node;
    memcpy(truth->joint, mask->joint, sizeof truth->joint);
    truth->grasp_point = mask->grasp_point;
    truth->grasp_time = mask->grasp_time;

    int16_t *parents;
    kin_transform *rest;
    char (*names)[KIN_NAME_MAX];
    int *src;
    ALLOC(parents, N);
    ALLOC(rest, N);
    ALLOC(names, N);
    ALLOC(src, N);
    memcpy(parents, m->parents, sizeof *parents * (size_t)N);
    memcpy(rest, m->rest, sizeof *rest * (size_t)N);
    memcpy(names, m->names, sizeof *names * (size_t)N);
    memcpy(src, m->node_src, sizeof *src * (size_t)N);

    /* bones: scale the offsets; per joint the deformation of its part of
     * the surface, in its bind frame (x, y across the bone, z along it) */
    float sxy[KIN_MAX_NODES], sz[KIN_MAX_NODES];
    for (int i = 0; i < N; i++) sxy[i] = sz[i] = 1.0f;
    for (int s = 0; s < 2; s++) {
        const int *J = mask->joint[s];
        rest[J[GEN_J_SHOULDER]].t = kin_v3_scale(rest[J[GEN_J_SHOULDER]].t, d->shoulder_scale);
        rest[J[GEN_J_UPPER_ARM]].t = kin_v3_scale(rest[J[GEN_J_UPPER_ARM]].t, d->shoulder_scale);
        rest[J[GEN_J_FOREARM]].t = kin_v3_scale(rest[J[GEN_J_FOREARM]].t, d->upper_scale);
        rest[J[GEN_J_HAND]].t = kin_v3_scale(rest[J[GEN_J_HAND]].t, d->fore_scale);
        for (int j = GEN_J_PALM; j < GEN_SIDE_JOINTS; j++)
            rest[J[j]].t = kin_v3_scale(rest[J[j]].t, d->hand_scale);
        sxy[J[GEN_J_UPPER_ARM]] = d->upper_thick;
        sz[J[GEN_J_UPPER_ARM]] = d->upper_scale;
        sxy[J[GEN_J_FOREARM]] = d->fore_thick;
        sz[J[GEN_J_FOREARM]] = d->fore_scale;
        for (int j = GEN_J_HAND; j < GEN_SIDE_JOINTS; j++) {
            sxy[J[j]] = d->hand_scale * d->hand_thick;
            sz[J[j]] = d->hand_scale;
        }
    }
    kin_fk(m->parents, N, m->rest, NULL, bold);
    kin_fk(parents, N, rest, NULL, bnew);
    for (int i = 0; i < N; i++) {
        kin_mat4 inv, s = kin_mat4_identity(), tmp;
        if (!kin_mat4_inverse(&bold[i], &inv)) goto oom;
        s.m[0] = s.m[5] = sxy[i];
        s.m[10] = sz[i];
        tmp = kin_mat4_mul(&s, &inv);
        def[i] = kin_mat4_mul(&bnew[i], &tmp);
    }

    const kin_mesh *me = &m->meshes[0];
    const kin_skin *sk = &m->skins[0];
    vbuf a;
    if (vbuf_alloc(&t->block, &a, me->vertex_count, me->index_count / 3) < 0) goto oom;
    memcpy(a.w, me->weights, sizeof(float) * 4 * (size_t)a.nv);
    memcpy(a.jnt, me->joints, sizeof(uint16_t) * 4 * (size_t)a.nv);
    memcpy(a.albedo, mask->albedo, sizeof(float) * 3 * (size_t)a.nv);
    memcpy(a.uv, mask->uv, sizeof(float) * 2 * (size_t)a.nv);
    memcpy(a.idx, me->indices, sizeof(uint32_t) * (size_t)me->index_count);
    for (int v = 0; v < a.nv; v++) {
        kin_vec3 p = kin_v3(me->positions[v * 3], me->positions[v * 3 + 1],
                            me->positions[v * 3 + 2]);
        kin_vec3 q = kin_v3(0, 0, 0);
        for (int k = 0; k < 4; k++) {
            float w = me->weights[v * 4 + k];
            if (w <= 0.0f) continue;
            int node = sk->joints[me->joints[v * 4 + k]];
            q = kin_v3_add(q, kin_v3_scale(kin_mat4_mul_point(&def[node], p), w));
        }
        a.pos[v * 3 + 0] = q.x;
        a.pos[v * 3 + 1] = q.y;
        a.pos[v * 3 + 2] = q.z;
    }
    normals_of(a.pos, a.nv, a.idx, a.nt, a.nrm);
    vbuf fin = a;
    if (d->subdivide && subdivide(&t->block, &a, &fin) < 0) goto oom;

    t->node_count = N;
    t->parents = parents;
    t->rest = rest;
    t->names = (const char (*)[KIN_NAME_MAX])names;
    t->node_src = src;
    if (gen_model_skin(t, sk->joint_count, sk->joints, bnew) < 0 ||
        gen_model_mesh(t, fin.nv, fin.pos, fin.nrm, fin.jnt, fin.w, fin.nt, fin.idx, me->node) < 0)
        goto oom;
    t->anim_count = m->anim_count;
    t->anims = m->anims;
    truth->albedo = fin.albedo;
    truth->uv = fin.uv;
    free(bold);
    free(bnew);
    free(def);
    return 0;
oom:
    free(bold);
    free(bnew);
    free(def);
    kin_model_free(t);
    memset(truth, 0, sizeof *truth);
    return -1;
}

/* ---------------------------------------------------------- the cockpit */

static void add_box(gen_scene *s, kin_vec3 lo, kin_vec3 hi, const float rgb[3])
{
    if (s->failed) return;
    if (s->vertex_count + 24 > s->vertex_cap) {
        int cap = s->vertex_count + 24 + 256;
        float *p = realloc(s->pos, sizeof(float) * 3 * (size_t)cap);
        if (p) s->pos = p;
        float *a = p ? realloc(s->attr, sizeof(float) * GEN_ATTRS * (size_t)cap) : NULL;
        if (a) s->attr = a;
        if (!p || !a) { s->failed = 1; return; }
        s->vertex_cap = cap;
    }
    if (s->tri_count + 12 > s->tri_cap) {
        int cap = s->tri_count + 12 + 256;
        uint32_t *t = realloc(s->idx, sizeof(uint32_t) * 3 * (size_t)cap);
        if (!t) { s->failed = 1; return; }
        s->idx = t;
        s->tri_cap = cap;
    }
    const float lo3[3] = { lo.x, lo.y, lo.z }, hi3[3] = { hi.x, hi.y, hi.z };
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            int u = (axis + 1) % 3, v = (axis + 2) % 3, base = s->vertex_count;
            for (int c = 0; c < 4; c++) {
                float p[3];
                p[axis] = side ? hi3[axis] : lo3[axis];
                p[u] = (c == 1 || c == 2) ? hi3[u] : lo3[u];
                p[v] = (c >= 2) ? hi3[v] : lo3[v];
                int i = s->vertex_count++;
                memcpy(&s->pos[i * 3], p, sizeof p);
                float *at = &s->attr[i * GEN_ATTRS];
                at[GEN_A_NX] = axis == 0 ? (side ? 1.0f : -1.0f) : 0.0f;
                at[GEN_A_NY] = axis == 1 ? (side ? 1.0f : -1.0f) : 0.0f;
                at[GEN_A_NZ] = axis == 2 ? (side ? 1.0f : -1.0f) : 0.0f;
                at[GEN_A_R] = rgb[0];
                at[GEN_A_G] = rgb[1];
                at[GEN_A_B] = rgb[2];
                at[GEN_A_U] = (float)GEN_PAT_PLAIN * GEN_PATTERN_STRIDE + (p[u] - lo3[u]);
                at[GEN_A_V] = p[v] - lo3[v];
            }
            uint32_t *t = &s->idx[s->tri_count * 3];
            const uint32_t q[6] = { 0, 1, 2, 0, 2, 3 };
            for (int k = 0; k < 6; k++) t[k] = (uint32_t)base + q[k];
            s->tri_count += 2;
        }
}

int gt_cockpit_build(gen_scene *s)
{
    if (gen_scene_cockpit(s) < 0) return -1;
    static const float cardboard[3] = { 0.78f, 0.58f, 0.42f };
    static const float beige[3] = { 0.88f, 0.70f, 0.58f };
    static const float tray[3] = { 0.74f, 0.52f, 0.38f };
    static const float folder[3] = { 0.85f, 0.62f, 0.48f };
    /* a cardboard box left of centre, a beige pad under the hands' path,
     * a wooden tray on the right, a tan folder on the right console */
    add_box(s, kin_v3(-0.36f, 0.76f, -0.72f), kin_v3(-0.12f, 0.90f, -0.52f), cardboard);
    add_box(s, kin_v3(-0.05f, 0.76f, -0.78f), kin_v3(0.32f, 0.768f, -0.44f), beige);
    add_box(s, kin_v3(0.22f, 0.76f, -0.92f), kin_v3(0.50f, 0.79f, -0.74f), tray);
    add_box(s, kin_v3(0.55f, 0.90f, -0.70f), kin_v3(0.75f, 1.20f, -0.66f), folder);
    return s->failed ? -1 : 0;
}

/* ---------------------------------------------------------- the frames */

void gt_render_eye(gen_frame_ctx *c, const kin_mat4 *world_from_head,
                   kin_eye eye, int frame, uint8_t *rgb, uint8_t *sil,
                   float *nrm, float *scratch_depth, uint8_t *scratch_mask)
{
    gen_render_camera(c, world_from_head, eye, frame, rgb, NULL);
    kin_camera cam = kin_sthmd_camera(NULL, world_from_head, eye);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    /* The arms alone, with the camera's projection: a pixel is arm when
     * they cover its centre and their depth is the scene's (nothing of the
     * cockpit in front). Not from the render's pattern codes: those are
     * interpolated across the triangles where skin meets sleeve, and the
     * cuff would fall out of the silhouette. */
    kin_mat4 proj = gen_proj_from_intrinsics(cam.fx, cam.fy, cam.cx, cam.cy + (float)g.crop_y0,
                                             GEN_CAM_W, GEN_CAM_H, GEN_CAM_ZNEAR, GEN_CAM_ZFAR);
    kin_mat4 vp = kin_mat4_mul(&proj, &cam.view);
    const kin_mesh *me = &c->arms->model.meshes[0];
    rast_target t = { GEN_CAM_W, GEN_CAM_H, scratch_depth, GEN_CAM_W, scratch_mask, GEN_CAM_W,
                      NULL, 0, 0, NULL, 0 };
    rast_target_clear(&t);
    rast_transform_points(vp.m, c->skin_pos, me->vertex_count, c->clip);
    rast_mesh_desc d = { c->clip, me->vertex_count, NULL, 0, me->indices, me->index_count / 3,
                         RAST_CULL_NONE };
    rast_draw(&t, &d, NULL);
    for (int y = 0; y < g.crop_height; y++)
        for (int x = 0; x < g.crop_width; x++) {
            size_t i = (size_t)(y + g.crop_y0) * GEN_CAM_W + (size_t)x;
            size_t o = (size_t)y * (size_t)g.crop_width + (size_t)x;
            const float *a = &c->tattr[i * GEN_ATTRS];
            int arm = scratch_mask[i] && c->mask[i] && scratch_depth[i] <= c->depth[i];
            sil[o] = arm ? 255 : 0;
            if (!nrm) continue;
            kin_vec3 n = kin_v3(0, 0, 0);
            if (arm)
                n = kin_v3_norm(kin_mat4_mul_dir(&cam.view,
                                                 kin_v3(a[GEN_A_NX], a[GEN_A_NY], a[GEN_A_NZ])));
            nrm[o * 3 + 0] = n.x;
            nrm[o * 3 + 1] = n.y;
            nrm[o * 3 + 2] = n.z;
        }
}

/* ---------------------------------------------------------- tracking */

static float finger_angle_deg(kin_quat q)
{
    return -2.0f * atan2f(q.x, q.w) * (180.0f / PI_F);
}

void gt_true_sample(const gen_arms *truth, float t, kin_transform *locals,
                    kin_mat4 *world, kin_track_sample *out)
{
    const kin_model *m = &truth->model;
    kin_pose_rest(m, locals);
    kin_anim_sample(&m->anims[0], m->node_count, t, locals);
    kin_fk(m->parents, m->node_count, locals, NULL, world);
    memset(out, 0, sizeof *out);
    out->t = t;
    out->valid = KIN_TRACK_ALL;
    out->head_pos = kin_mat4_translation(&world[truth->head]);
    out->head_rot = kin_mat4_rotation(&world[truth->head]);
    kin_hand_params hp = kin_hand_params_default();
    for (int s = 0; s < 2; s++) {
        const int *J = truth->joint[s];
        out->shoulder[s] = kin_mat4_translation(&world[J[GEN_J_UPPER_ARM]]);
        out->hand_pos[s] = kin_mat4_translation(&world[J[GEN_J_HAND]]);
        out->hand_rot[s] = kin_mat4_rotation(&world[J[GEN_J_HAND]]);
        for (int f = 0; f < 5; f++) {
            float a = finger_angle_deg(locals[J[GEN_J_THUMB_1 + 3 * f + 1]].r);
            float g = (a - hp.open_deg[f][1]) / (hp.fist_deg[f][1] - hp.open_deg[f][1]);
            out->glove[s][f] = g < 0.0f ? 0.0f : g > 1.0f ? 1.0f : g;
        }
    }
}

typedef struct rng { uint64_t s; } rng;

static uint64_t next(rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static float unit(rng *r) { return ((float)(next(r) >> 40) + 0.5f) * (1.0f / 16777216.0f); }

static float gauss(rng *r)
{
    float u = unit(r), v = unit(r);
    return sqrtf(-2.0f * logf(u)) * cosf(2.0f * PI_F * v);
}

static kin_vec3 jitter(rng *r, kin_vec3 p, float rms)
{
    float s = rms / sqrtf(3.0f);
    return kin_v3(p.x + s * gauss(r), p.y + s * gauss(r), p.z + s * gauss(r));
}

static kin_quat rjitter(rng *r, kin_quat q, float rms_deg)
{
    float s = rms_deg * (PI_F / 180.0f) / sqrtf(3.0f);
    kin_vec3 w = kin_v3(s * gauss(r), s * gauss(r), s * gauss(r));
    float a = kin_v3_len(w);
    if (a <= 0.0f) return q;
    return kin_quat_normalize(kin_quat_mul(kin_quat_axis_angle(kin_v3_scale(w, 1.0f / a), a), q));
}

void gt_track_sample(const gen_arms *truth, const gt_track_desc *d, int k,
                     kin_transform *locals, kin_mat4 *world,
                     kin_track_sample *out)
{
    double tc = (double)k / (double)d->rate_hz;
    gt_true_sample(truth, (float)(tc * d->speed), locals, world, out);
    out->t = tc;
    rng r = { d->seed * 0xD1B54A32D192ED03ull + (uint64_t)k * 0x9E3779B97F4A7C15ull + 7u };
    next(&r);
    float pos = d->noise_mm * 0.001f;
    out->head_pos = jitter(&r, out->head_pos, pos);
    out->head_rot = rjitter(&r, out->head_rot, d->head_rot_noise_deg);
    for (int s = 0; s < 2; s++) {
        out->shoulder[s] = jitter(&r, out->shoulder[s], pos);
        out->hand_pos[s] = jitter(&r, out->hand_pos[s], pos);
        out->hand_rot[s] = rjitter(&r, out->hand_rot[s], d->rot_noise_deg);
        for (int f = 0; f < 5; f++) {
            float g = out->glove[s][f] + d->glove_noise * gauss(&r);
            out->glove[s][f] = g < 0.0f ? 0.0f : g > 1.0f ? 1.0f : g;
        }
        if (unit(&r) < d->dropout)
            out->valid &= ~(uint32_t)((KIN_TRACK_HAND_L | KIN_TRACK_GLOVE_L) << s);
    }
}

/* ---------------------------------------------------------- sequences */

/* Key postures per side: wrist xyz, finger direction xyz, back-of-hand
 * direction xyz, grip (-0.3 open .. 0 relaxed .. 1 closed), in the world
 * of samples/gen (eyes at (0, 1.25, -0.08) looking 27 deg down, shoulders
 * at (+-0.19, 0.97, 0)); joined by minimum-jerk blends (rest at each key),
 * as the generator's reach_grasp. */
#define SEQ_DIM 10
#define SEQ_MAX_KEYS 12

typedef struct seq_side {
    int n;
    float t[SEQ_MAX_KEYS];
    float v[SEQ_MAX_KEYS][SEQ_DIM];
    int tip[SEQ_MAX_KEYS];     /* 1: xyz is the middle fingertip, not the wrist */
} seq_side;

typedef struct seq_desc {
    const char *name;
    float duration;
    seq_side side[2];          /* [0] left, [1] right */
    int nh;
    float ht[SEQ_MAX_KEYS];
    float hv[SEQ_MAX_KEYS][2]; /* head yaw (+ left), pitch (- down), deg */
    int true_bones;            /* 1: the angles are solved for the true
                                  operator's bones (its wrists and
                                  fingertips go where the keys say) */
} seq_desc;

#define RREST 0.130f, 1.075f, -0.320f, -0.25f, -0.12f, -1.0f, 0.35f, 1.0f, 0.0f
#define LREST -0.120f, 1.070f, -0.310f, 0.25f, -0.12f, -1.0f, -0.35f, 1.0f, 0.0f
#define HEAD0 { 0.0f, -27.0f }

static const seq_desc sequences[] = {
    /* the hands cross: the right hand reaches to the left in front of the
     * left hand, which goes to the right, nearer the eyes; then back */
    { "cross", 3.0f,
      { { 5, { 0.0f, 0.4f, 1.3f, 2.1f, 3.0f },
          { { LREST, 0.1f }, { LREST, 0.1f },
            { 0.100f, 1.080f, -0.280f, 0.70f, 0.05f, -1.0f, -0.2f, 1.0f, 0.1f, 0.2f },
            { 0.060f, 1.090f, -0.270f, 0.60f, 0.05f, -1.0f, -0.2f, 1.0f, 0.1f, 0.0f },
            { LREST, 0.1f } }, { 0 } },
        { 5, { 0.0f, 0.3f, 1.2f, 2.0f, 3.0f },
          { { RREST, 0.0f }, { RREST, 0.0f },
            { -0.120f, 1.030f, -0.440f, -0.70f, -0.15f, -1.0f, 0.2f, 1.0f, 0.0f, -0.2f },
            { -0.080f, 1.020f, -0.460f, -0.60f, -0.15f, -1.0f, 0.2f, 1.0f, 0.0f, 0.6f },
            { RREST, 0.0f } }, { 0 } } },
      4, { 0.0f, 0.8f, 2.0f, 3.0f }, { HEAD0, { 3.0f, -28.0f }, { 2.0f, -28.0f }, HEAD0 }, 0 },
    /* the hands come up to 15 cm in front of the eyes (the right one
     * first, as if looking at the palm), then go back to 40 cm */
    { "near", 3.0f,
      { { 4, { 0.0f, 1.0f, 1.9f, 3.0f },
          { { LREST, 0.1f },
            { -0.050f, 1.160f, -0.230f, 0.20f, 0.45f, -1.0f, -0.6f, 0.6f, 0.6f, -0.2f },
            { -0.060f, 1.140f, -0.250f, 0.20f, 0.45f, -1.0f, -0.6f, 0.6f, 0.6f, 0.3f },
            { -0.100f, 1.040f, -0.420f, 0.25f, -0.12f, -1.0f, -0.35f, 1.0f, 0.0f, 0.1f } }, { 0 } },
        { 5, { 0.0f, 0.7f, 1.4f, 2.2f, 3.0f },
          { { RREST, 0.0f },
            { 0.040f, 1.170f, -0.220f, -0.20f, 0.50f, -1.0f, 0.6f, 0.5f, 0.6f, -0.3f },
            { 0.045f, 1.175f, -0.215f, -0.20f, 0.50f, -1.0f, 0.6f, 0.5f, 0.6f, 0.5f },
            { 0.100f, 1.060f, -0.400f, -0.25f, -0.12f, -1.0f, 0.35f, 1.0f, 0.0f, 0.0f },
            { 0.110f, 1.050f, -0.430f, -0.25f, -0.12f, -1.0f, 0.35f, 1.0f, 0.0f, 0.0f } }, { 0 } } },
      3, { 0.0f, 1.2f, 3.0f }, { HEAD0, { 0.0f, -20.0f }, { 0.0f, -26.0f } }, 0 },
    /* the hands go out to the image edges (left hand beyond the left
     * border, right hand to the right and the bottom), partly out of view */
    { "edge", 3.0f,
      { { 4, { 0.0f, 0.9f, 1.8f, 3.0f },
          { { LREST, 0.1f },
            { -0.300f, 1.060f, -0.400f, -0.30f, -0.10f, -1.0f, -0.35f, 1.0f, 0.0f, -0.1f },
            { -0.320f, 1.080f, -0.380f, -0.30f, -0.10f, -1.0f, -0.35f, 1.0f, 0.0f, 0.4f },
            { LREST, 0.1f } }, { 0 } },
        { 5, { 0.0f, 0.6f, 1.3f, 2.2f, 3.0f },
          { { RREST, 0.0f },
            { 0.300f, 1.040f, -0.420f, 0.30f, -0.10f, -1.0f, 0.35f, 1.0f, 0.0f, 0.0f },
            { 0.260f, 0.960f, -0.300f, 0.20f, -0.30f, -1.0f, 0.35f, 1.0f, 0.0f, 0.3f },
            { 0.150f, 0.950f, -0.280f, 0.00f, -0.30f, -1.0f, 0.35f, 1.0f, 0.0f, 0.0f },
            { RREST, 0.0f } }, { 0 } } },
      3, { 0.0f, 1.5f, 3.0f }, { HEAD0, { -2.0f, -25.0f }, HEAD0 }, 0 },
    /* fast moves: reaches of 0.25-0.3 s (up to ~2 m/s at the wrist),
     * both hands, out and back twice */
    { "fast", 3.0f,
      { { 9, { 0.0f, 0.3f, 0.55f, 0.85f, 1.1f, 1.6f, 1.85f, 2.15f, 3.0f },
          { { LREST, 0.1f }, { LREST, 0.1f },
            { -0.200f, 1.000f, -0.520f, 0.10f, -0.20f, -1.0f, -0.4f, 1.0f, 0.0f, 0.5f },
            { -0.200f, 1.000f, -0.520f, 0.10f, -0.20f, -1.0f, -0.4f, 1.0f, 0.0f, 0.5f },
            { LREST, 0.1f }, { LREST, 0.1f },
            { 0.020f, 1.020f, -0.480f, 0.30f, -0.20f, -1.0f, -0.4f, 1.0f, 0.0f, -0.2f },
            { LREST, 0.1f }, { LREST, 0.1f } }, { 0 } },
        { 9, { 0.0f, 0.2f, 0.45f, 0.75f, 1.0f, 1.4f, 1.65f, 1.95f, 3.0f },
          { { RREST, 0.0f }, { RREST, 0.0f },
            { 0.220f, 0.990f, -0.530f, -0.10f, -0.20f, -1.0f, 0.4f, 1.0f, 0.0f, 0.8f },
            { 0.220f, 0.990f, -0.530f, -0.10f, -0.20f, -1.0f, 0.4f, 1.0f, 0.0f, 0.8f },
            { RREST, 0.0f }, { RREST, 0.0f },
            { -0.040f, 1.010f, -0.500f, -0.30f, -0.20f, -1.0f, 0.4f, 1.0f, 0.0f, -0.2f },
            { RREST, 0.0f }, { RREST, 0.0f } }, { 0 } } },
      4, { 0.0f, 0.5f, 1.5f, 3.0f }, { HEAD0, { -6.0f, -30.0f }, { 5.0f, -28.0f }, HEAD0 }, 0 },
    /* calibration: both arms stretched forward, then sideways
     * (kin_user_calib_estimate takes the 95th percentile of the
     * shoulder-hand distance); then the fingertip gesture of
     * kin_user_calib_estimate_tips: the middle fingertips of both hands
     * pressed together in front of the chest, fingers as straight as they
     * go (grip -0.3), the pair turning 20 deg left, tilting 20 deg and
     * turning 15 deg right, 2.1 s; the angles are solved for the true
     * operator's own bones, so that its fingertips touch. Not rendered. */
#define CTIP(x, y, z, fx, fy, fz, bx, by, bz) { x, y, z, fx, fy, fz, bx, by, bz, -0.3f }
    { "calib", 7.7f,
      { { 11, { 0.0f, 0.6f, 1.4f, 2.2f, 3.0f, 4.0f, 4.8f, 5.5f, 6.2f, 6.9f, 7.7f },
          { { LREST, 0.0f },
            { -0.190f, 0.970f, -0.700f, 0.0f, 0.0f, -1.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { -0.190f, 0.970f, -0.700f, 0.0f, 0.0f, -1.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { -0.890f, 0.970f, 0.000f, -1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { -0.890f, 0.970f, 0.000f, -1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { LREST, 0.0f },
            CTIP(0.000f, 1.000f, -0.360f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f),
            CTIP(0.020f, 1.020f, -0.370f, 0.94f, 0.0f, -0.342f, 0.0f, 1.0f, 0.0f),
            CTIP(0.000f, 1.030f, -0.350f, 0.94f, 0.342f, 0.0f, -0.342f, 0.94f, 0.0f),
            CTIP(-0.010f, 1.000f, -0.380f, 0.966f, 0.0f, 0.259f, 0.0f, 1.0f, 0.0f),
            { LREST, 0.0f } },
          { 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 0 } },
        { 11, { 0.0f, 0.6f, 1.4f, 2.2f, 3.0f, 4.0f, 4.8f, 5.5f, 6.2f, 6.9f, 7.7f },
          { { RREST, 0.0f },
            { 0.190f, 0.970f, -0.700f, 0.0f, 0.0f, -1.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { 0.190f, 0.970f, -0.700f, 0.0f, 0.0f, -1.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { 0.890f, 0.970f, 0.000f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { 0.890f, 0.970f, 0.000f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, -0.3f },
            { RREST, 0.0f },
            CTIP(0.000f, 1.000f, -0.360f, -1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f),
            CTIP(0.020f, 1.020f, -0.370f, -0.94f, 0.0f, 0.342f, 0.0f, 1.0f, 0.0f),
            CTIP(0.000f, 1.030f, -0.350f, -0.94f, -0.342f, 0.0f, -0.342f, 0.94f, 0.0f),
            CTIP(-0.010f, 1.000f, -0.380f, -0.966f, 0.0f, -0.259f, 0.0f, 1.0f, 0.0f),
            { RREST, 0.0f } },
          { 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 0 } } },
      2, { 0.0f, 7.7f }, { HEAD0, HEAD0 }, 1 },
#undef CTIP
};

const char *gt_sequence_name(int i)
{
    if (i == 0) return GEN_ANIM_NAME;
    int n = (int)(sizeof sequences / sizeof sequences[0]);
    return i >= 1 && i <= n ? sequences[i - 1].name : NULL;
}

static float minjerk(float u)
{
    if (u <= 0.0f) return 0.0f;
    if (u >= 1.0f) return 1.0f;
    return u * u * u * (10.0f + u * (-15.0f + 6.0f * u));
}

static void keys_eval(int n, const float *t, const float *v, int dim, float x, float *out)
{
    int i = 0;
    if (x <= t[0]) { memcpy(out, v, sizeof(float) * (size_t)dim); return; }
    while (i + 1 < n && t[i + 1] <= x) i++;
    if (i + 1 >= n) { memcpy(out, v + (size_t)(n - 1) * (size_t)dim, sizeof(float) * (size_t)dim); return; }
    float u = minjerk((x - t[i]) / (t[i + 1] - t[i]));
    const float *a = v + (size_t)i * (size_t)dim, *b = a + dim;
    for (int k = 0; k < dim; k++) out[k] = a[k] + (b[k] - a[k]) * u;
}

/* Finger flexion (degrees) of fingers 1..4 (index..little), joints 0..2,
 * relaxed (grip 0) and grasping (grip 1). */
static const float relax[4][3] = { { 10, 18, 8 }, { 14, 22, 10 }, { 18, 26, 12 }, { 22, 30, 14 } };
static const float grasp[4][3] = { { 42, 62, 30 }, { 48, 66, 32 }, { 54, 70, 34 }, { 60, 72, 36 } };

/* Local rotation of joint j (0..2) of finger f (1..4) at grip g. */
static kin_quat finger_rot(const kin_model *m, const int *J, int f, int j, float g)
{
    int j1 = GEN_J_THUMB_1 + 3 * f;
    float fl = relax[f - 1][j] + g * (grasp[f - 1][j] - relax[f - 1][j]);
    kin_quat r = kin_quat_axis_angle(kin_v3(1, 0, 0), -fl * (PI_F / 180.0f));
    return j == 0 ? kin_quat_mul(m->rest[J[j1]].r, r) : r;
}

/* The hand's world rotation of a key (-Z along the fingers c[3..5], +Y
 * towards the back of the hand c[6..8]). */
static kin_quat key_hand_rot(const float *c)
{
    kin_vec3 zh = kin_v3_scale(kin_v3_norm(kin_v3(c[3], c[4], c[5])), -1.0f);
    kin_vec3 dors = kin_v3(c[6], c[7], c[8]);
    kin_vec3 yh = kin_v3_norm(kin_v3_sub(dors, kin_v3_scale(zh, kin_v3_dot(dors, zh))));
    return kin_quat_from_axes(kin_v3_cross(yh, zh), yh, zh);
}

/* What turns fingertip keys into wrist keys: the operator whose
 * fingertips they are, and per side how far its middle fingertip's
 * surface reaches beyond the middle_3 joint. */
typedef struct tipper {
    const kin_model *m;
    const int *J[2];
    float ext[2];
} tipper;

/* The middle fingertip in the hand joint's frame at grip g. */
static kin_vec3 tip_in_hand(const tipper *tp, int s, float g)
{
    const kin_model *m = tp->m;
    const int *J = tp->J[s];
    kin_vec3 p = kin_v3(0.0f, 0.0f, -tp->ext[s]);
    for (int j = 2; j >= 0; j--)
        p = kin_v3_add(m->rest[J[GEN_J_MIDDLE_1 + j]].t, kin_quat_rotate(finger_rot(m, J, 2, j, g), p));
    return kin_v3_add(m->rest[J[GEN_J_PALM]].t, kin_quat_rotate(m->rest[J[GEN_J_PALM]].r, p));
}

/* Key values c (xyz the middle fingertip) into a wrist key. */
static void tip_to_wrist(const tipper *tp, int s, float *c)
{
    kin_vec3 t = kin_quat_rotate(key_hand_rot(c), tip_in_hand(tp, s, c[9]));
    c[0] -= t.x;
    c[1] -= t.y;
    c[2] -= t.z;
}

/* The keys of one side at time x, as wrist keys: between two fingertip
 * keys the fingertip is interpolated (it stays where the keys put it),
 * else the wrists. Without fingertip keys this is keys_eval. */
static void side_eval(const seq_side *sd, const tipper *tp, int s, float x, float *out)
{
    int n = sd->n, i = 0;
    while (i + 1 < n && sd->t[i + 1] <= x) i++;
    if (x <= sd->t[0] || i + 1 >= n) {
        int k = x <= sd->t[0] ? 0 : n - 1;
        memcpy(out, sd->v[k], sizeof(float) * SEQ_DIM);
        if (sd->tip[k]) tip_to_wrist(tp, s, out);
        return;
    }
    if (sd->tip[i] && sd->tip[i + 1]) {
        keys_eval(n, sd->t, &sd->v[0][0], SEQ_DIM, x, out);
        tip_to_wrist(tp, s, out);
        return;
    }
    float a[SEQ_DIM], b[SEQ_DIM];
    memcpy(a, sd->v[i], sizeof a);
    memcpy(b, sd->v[i + 1], sizeof b);
    if (sd->tip[i]) tip_to_wrist(tp, s, a);
    if (sd->tip[i + 1]) tip_to_wrist(tp, s, b);
    float u = minjerk((x - sd->t[i]) / (sd->t[i + 1] - sd->t[i]));
    for (int k = 0; k < SEQ_DIM; k++) out[k] = a[k] + (b[k] - a[k]) * u;
}

/* World rotations of upper arm, forearm and hand of one side (the
 * generator's rule: elbow in the plane of the pole (0.45 s, -1, 0.25),
 * the forearm takes half of the hand's roll). */
static void seq_arm(kin_vec3 S, float L1, float L2, const float *c, float s, kin_quat out[3])
{
    kin_vec3 W = kin_v3(c[0], c[1], c[2]), pole = kin_v3(0.45f * s, -1.0f, 0.25f);
    kin_vec3 d = kin_v3_sub(W, S);
    float L = kin_v3_len(d), maxl = 0.985f * (L1 + L2), minl = fmaxf(L2 - L1 + 0.05f, 0.05f);
    kin_vec3 u = kin_v3_norm(d);
    if (L > maxl) L = maxl;
    if (L < minl) L = minl;
    W = kin_v3_add(S, kin_v3_scale(u, L));
    float ca = (L1 * L1 + L * L - L2 * L2) / (2.0f * L1 * L);
    ca = ca > 1.0f ? 1.0f : ca;
    float sa = sqrtf(fmaxf(0.0f, 1.0f - ca * ca));
    kin_vec3 p = kin_v3_norm(kin_v3_sub(pole, kin_v3_scale(u, kin_v3_dot(pole, u))));
    kin_vec3 E = kin_v3_add(S, kin_v3_scale(kin_v3_add(kin_v3_scale(u, ca), kin_v3_scale(p, sa)), L1));
    kin_vec3 du = kin_v3_norm(kin_v3_sub(E, S)), df = kin_v3_norm(kin_v3_sub(W, E));
    kin_vec3 n = kin_v3_cross(du, df);
    if (kin_v3_len(n) < 1e-4f) n = kin_v3_cross(du, pole);
    n = kin_v3_norm(n);
    kin_vec3 zu = kin_v3_scale(du, -1.0f);
    out[0] = kin_quat_from_axes(n, kin_v3_cross(zu, n), zu);
    kin_vec3 zh = kin_v3_scale(kin_v3_norm(kin_v3(c[3], c[4], c[5])), -1.0f);
    kin_vec3 dors = kin_v3(c[6], c[7], c[8]);
    kin_vec3 yh = kin_v3_norm(kin_v3_sub(dors, kin_v3_scale(zh, kin_v3_dot(dors, zh))));
    out[2] = kin_quat_from_axes(kin_v3_cross(yh, zh), yh, zh);   /* key_hand_rot(c) */
    kin_vec3 zf = kin_v3_scale(df, -1.0f), yf = kin_v3_cross(zf, n);
    kin_vec3 yp = kin_v3_sub(yh, kin_v3_scale(zf, kin_v3_dot(yh, zf)));
    float roll = 0.5f * atan2f(kin_v3_dot(kin_v3_cross(yf, yp), zf), kin_v3_dot(yf, yp));
    kin_quat rr = kin_quat_axis_angle(zf, roll);
    out[1] = kin_quat_from_axes(kin_quat_rotate(rr, n), kin_quat_rotate(rr, yf), zf);
}

static kin_quat qconj(kin_quat q) { kin_quat c = { -q.x, -q.y, -q.z, q.w }; return c; }

/* "holdNN" (NN = 10..60 cm): the right hand held up NN cm in front of the
 * eyes, palm towards them, fingers straight along the head's up axis, the
 * middle fingertip midway between the eyes, 2 deg below their view axis
 * (so in view of both cameras at 15 cm: 6.5 cm from them), swaying
 * +-0.5 cm sideways and 1.5 cm up and back in the plane at that depth
 * (keys at 0, 0.75, 1.5, 2.25, 3 s); the left hand down by the side, out
 * of view. The head holds HEAD0. Keys from the mask model's head: the eyes'
 * midpoint (the head node) and axes at that pitch. -1 for another name. */
static int hold_desc(const gen_arms *mask, const char *name, seq_desc *sq)
{
    int cm = 0, used = 0;
    if (sscanf(name, "hold%d%n", &cm, &used) != 1 || name[used] || cm < 10 || cm > 60)
        return -1;
    const kin_model *m = &mask->model;
    kin_transform *L = malloc(sizeof *L * (size_t)m->node_count);
    kin_mat4 *W = malloc(sizeof *W * (size_t)m->node_count);
    if (!L || !W) {
        free(L);
        free(W);
        return -1;
    }
    memcpy(L, m->rest, sizeof *L * (size_t)m->node_count);
    static const float head0[2] = HEAD0;
    L[mask->head].r = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 1, 0), head0[0] * PI_F / 180.0f),
                                   kin_quat_axis_angle(kin_v3(1, 0, 0), head0[1] * PI_F / 180.0f));
    kin_fk(m->parents, m->node_count, L, NULL, W);
    const kin_mat4 *H = &W[mask->head];
    kin_vec3 E = kin_mat4_translation(H);
    kin_vec3 xh = kin_v3_norm(kin_v3(H->m[0], H->m[1], H->m[2]));
    kin_vec3 yh = kin_v3_norm(kin_v3(H->m[4], H->m[5], H->m[6]));
    kin_vec3 zh = kin_v3_norm(kin_v3(H->m[8], H->m[9], H->m[10]));
    free(L);
    free(W);
    const float d = 0.01f * (float)cm;
    static const float sway[5][2] = { { 0, 0 }, { 0.005f, 0.01f }, { 0, 0.015f },
                                      { -0.005f, 0.01f }, { 0, 0 } };
    memset(sq, 0, sizeof *sq);
    sq->name = "hold";
    sq->duration = 3.0f;
    seq_side *r = &sq->side[1], *l = &sq->side[0];
    r->n = 5;
    for (int k = 0; k < 5; k++) {
        r->t[k] = 0.75f * (float)k;
        float x = sway[k][0];
        float y = -d * tanf(2.0f * PI_F / 180.0f) + sway[k][1];
        r->tip[k] = 1;
        kin_vec3 w = kin_v3_add(E, kin_v3_add(kin_v3_scale(xh, x),
                                              kin_v3_add(kin_v3_scale(yh, y), kin_v3_scale(zh, -d))));
        float *v = r->v[k];
        v[0] = w.x; v[1] = w.y; v[2] = w.z;
        v[3] = yh.x; v[4] = yh.y; v[5] = yh.z;       /* fingers up */
        v[6] = -zh.x; v[7] = -zh.y; v[8] = -zh.z;    /* back of the hand away */
        v[9] = -0.2f;                                /* fingers nearly straight */
    }
    static const float lhang[SEQ_DIM] = { -0.240f, 0.880f, -0.200f, 0.25f, -0.5f, -1.0f,
                                          -0.35f, 1.0f, 0.0f, 0.1f };
    l->n = 2;
    l->t[0] = 0.0f;
    l->t[1] = 3.0f;
    memcpy(l->v[0], lhang, sizeof lhang);
    memcpy(l->v[1], lhang, sizeof lhang);
    sq->nh = 2;
    sq->ht[0] = 0.0f;
    sq->ht[1] = 3.0f;
    memcpy(sq->hv[0], head0, sizeof head0);
    memcpy(sq->hv[1], head0, sizeof head0);
    return 0;
}

int gt_sequence_build(const gen_arms *mask, const char *name, gen_arms *truth)
{
    if (!strcmp(name, GEN_ANIM_NAME)) {
        truth->model.anim_count = mask->model.anim_count;
        truth->model.anims = mask->model.anims;
        return 0;
    }
    const seq_desc *sq = NULL;
    for (size_t i = 0; i < sizeof sequences / sizeof sequences[0]; i++)
        if (!strcmp(sequences[i].name, name)) sq = &sequences[i];
    seq_desc hold;
    if (!sq && hold_desc(mask, name, &hold) == 0) sq = &hold;
    if (!sq) return -1;
    const kin_model *m = &mask->model;
    kin_model *t = &truth->model;
    const int keys = (int)lroundf(sq->duration * GEN_FPS) + 1;
    /* channels: the generator's (gen_anim_nodes) */
    int nodes[GEN_ANIM_NODES];
    const int nch = gen_anim_nodes(mask, nodes);
    kin_animation *an = gen_rot_anim(t, name, nodes, nch, keys);
    const float *times = an ? an->channels[0].times : NULL;
    kin_quat *q;
    kin_mat4 *w;
    if (!an) goto oom;
    ALLOC(q, m->node_count);
    ALLOC(w, m->node_count);
    /* the mask model's shoulders and bone lengths (the angles are then
     * given to the true operator, as the generator does), or for a
     * true_bones sequence the true operator's own */
    const kin_model *bones = sq->true_bones ? t : m;
    kin_fk(bones->parents, bones->node_count, bones->rest, NULL, w);
    tipper tp = { bones, { mask->joint[0], mask->joint[1] }, { 0.0f, 0.0f } };
    const kin_mesh *bm = &bones->meshes[0];
    const kin_skin *bs = &bones->skins[0];
    for (int s = 0; s < 2; s++) {
        /* the middle fingertip's surface beyond middle_3, along its bone
         * (the mesh is in the bind pose, which is the rest pose) */
        int m3 = mask->joint[s][GEN_J_MIDDLE_3];
        kin_vec3 o = kin_mat4_translation(&w[m3]);
        kin_vec3 ax = kin_v3_norm(kin_v3(-w[m3].m[8], -w[m3].m[9], -w[m3].m[10]));
        for (int v = 0; v < bm->vertex_count; v++) {
            float wt = 0.0f;
            for (int k = 0; k < 4; k++)
                if (bs->joints[bm->joints[v * 4 + k]] == m3) wt += bm->weights[v * 4 + k];
            if (wt < 0.5f) continue;
            const float *p = &bm->positions[v * 3];
            float e = kin_v3_dot(kin_v3_sub(kin_v3(p[0], p[1], p[2]), o), ax);
            if (e > tp.ext[s]) tp.ext[s] = e;
        }
    }
    kin_vec3 S[2];
    float L1[2], L2[2];
    for (int s = 0; s < 2; s++) {
        const int *J = mask->joint[s];
        S[s] = kin_mat4_translation(&w[J[GEN_J_UPPER_ARM]]);
        L1[s] = kin_v3_len(kin_v3_sub(kin_mat4_translation(&w[J[GEN_J_FOREARM]]), S[s]));
        L2[s] = kin_v3_len(kin_v3_sub(kin_mat4_translation(&w[J[GEN_J_HAND]]), kin_mat4_translation(&w[J[GEN_J_FOREARM]])));
    }
    const float D = PI_F / 180.0f;
    const kin_vec3 X = kin_v3(1, 0, 0);
    for (int k = 0; k < keys; k++) {
        float tk = times[k], hv[2];
        for (int i = 0; i < m->node_count; i++) q[i] = m->rest[i].r;
        keys_eval(sq->nh, sq->ht, &sq->hv[0][0], 2, tk, hv);
        q[mask->head] = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 1, 0), hv[0] * D),
                                     kin_quat_axis_angle(X, hv[1] * D));
        for (int s = 0; s < 2; s++) {
            const int *J = mask->joint[s];
            float sg = s ? 1.0f : -1.0f, c[SEQ_DIM];
            side_eval(&sq->side[s], &tp, s, tk, c);
            kin_quat wr[3];
            seq_arm(S[s], L1[s], L2[s], c, sg, wr);
            kin_quat pw = kin_quat_mul(m->rest[mask->body].r, m->rest[J[GEN_J_SHOULDER]].r);
            q[J[GEN_J_UPPER_ARM]] = kin_quat_normalize(kin_quat_mul(qconj(pw), wr[0]));
            q[J[GEN_J_FOREARM]] = kin_quat_normalize(kin_quat_mul(qconj(wr[0]), wr[1]));
            q[J[GEN_J_HAND]] = kin_quat_normalize(kin_quat_mul(qconj(wr[1]), wr[2]));
            float g = c[9];
            for (int f = 1; f < 5; f++) {
                int j1 = GEN_J_THUMB_1 + 3 * f;
                for (int j = 0; j < 3; j++) {
                    float fl = relax[f - 1][j] + g * (grasp[f - 1][j] - relax[f - 1][j]);
                    kin_quat r = kin_quat_axis_angle(X, -fl * D);
                    q[J[j1 + j]] = j == 0 ? kin_quat_mul(m->rest[J[j1]].r, r) : r;
                }
            }
            q[J[GEN_J_THUMB_1]] = kin_quat_mul(
                kin_quat_axis_angle(kin_v3(0, 0, 1), (12.0f + 28.0f * g) * D * sg),
                kin_quat_mul(m->rest[J[GEN_J_THUMB_1]].r,
                             kin_quat_axis_angle(X, -(6.0f + 10.0f * g) * D)));
            q[J[GEN_J_THUMB_2]] = kin_quat_axis_angle(X, -(10.0f + 22.0f * g) * D);
            q[J[GEN_J_THUMB_3]] = kin_quat_axis_angle(X, -(12.0f + 30.0f * g) * D);
        }
        gen_rot_anim_key(an, k, q);
    }
    t->anim_count = 1;
    t->anims = an;
    return 0;
oom:
    return -1;
}
