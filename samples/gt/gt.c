/* gt.c - the ground truth of `egofuse eval`: the true operator, the
 * cockpit with skin-coloured objects, the exact silhouettes and the noisy,
 * late, lossy tracking of the true motion (gt.h). */
#include "gt.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

gt_operator_desc gt_operator_default(void)
{
    gt_operator_desc d;
    d.shoulder_scale = 1.03f;
    d.upper_scale = 1.07f;
    d.fore_scale = 0.95f;
    d.hand_scale = 1.05f;
    d.upper_thick = 1.12f;
    d.fore_thick = 0.93f;
    d.hand_thick = 1.04f;
    d.subdivide = 1;
    return d;
}

gt_track_desc gt_track_default(void)
{
    gt_track_desc d;
    d.noise_mm = 5.0f;
    d.rot_noise_deg = 0.5f;
    d.head_rot_noise_deg = 0.1f;
    d.glove_noise = 0.03f;
    d.latency_ms = 20.0f;
    d.dropout = 0.02f;
    d.rate_hz = 90.0f;
    d.speed = 1.0f;
    d.seed = 1;
    return d;
}

/* ------------------------------------------------------------ the body */

static kin_vec3 mat_t(const kin_mat4 *m)
{
    return kin_v3(m->m[12], m->m[13], m->m[14]);
}

static kin_quat mat_q(const kin_mat4 *m)
{
    kin_vec3 x = kin_v3_norm(kin_v3(m->m[0], m->m[1], m->m[2]));
    kin_vec3 y = kin_v3_norm(kin_v3(m->m[4], m->m[5], m->m[6]));
    kin_vec3 z = kin_v3_norm(kin_v3_cross(x, y));
    y = kin_v3_cross(z, x);
    return kin_quat_normalize(gen_quat_from_axes(x, y, z));
}

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
    kin_skin *skin;
    int *joints;
    kin_mat4 *ibm;
    ALLOC(skin, 1);
    ALLOC(joints, sk->joint_count);
    ALLOC(ibm, sk->joint_count);
    for (int j = 0; j < sk->joint_count; j++) {
        joints[j] = sk->joints[j];
        if (!kin_mat4_inverse(&bnew[joints[j]], &ibm[j])) goto oom;
    }
    skin->joint_count = sk->joint_count;
    skin->joints = joints;
    skin->inverse_bind = ibm;
    t->skin_count = 1;
    t->skins = skin;
    kin_mesh *mesh;
    ALLOC(mesh, 1);
    mesh->vertex_count = fin.nv;
    mesh->positions = fin.pos;
    mesh->normals = fin.nrm;
    mesh->joints = fin.jnt;
    mesh->weights = fin.w;
    mesh->index_count = fin.nt * 3;
    mesh->indices = fin.idx;
    mesh->node = me->node;
    mesh->skin = 0;
    t->mesh_count = 1;
    t->meshes = mesh;
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
                   float *nrm)
{
    gen_render_camera(c, world_from_head, eye, frame, rgb, NULL);
    kin_camera cam = kin_sthmd_camera(NULL, world_from_head, eye);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    for (int y = 0; y < g.crop_height; y++)
        for (int x = 0; x < g.crop_width; x++) {
            size_t i = (size_t)(y + g.crop_y0) * GEN_CAM_W + (size_t)x;
            size_t o = (size_t)y * (size_t)g.crop_width + (size_t)x;
            const float *a = &c->tattr[i * GEN_ATTRS];
            int pat = pattern_of(a[GEN_A_U]);
            int arm = c->mask[i] && (pat == GEN_PAT_SKIN || pat == GEN_PAT_FABRIC);
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
    out->head_pos = mat_t(&world[truth->head]);
    out->head_rot = mat_q(&world[truth->head]);
    kin_hand_params hp = kin_hand_params_default();
    for (int s = 0; s < 2; s++) {
        const int *J = truth->joint[s];
        out->shoulder[s] = mat_t(&world[J[GEN_J_UPPER_ARM]]);
        out->hand_pos[s] = mat_t(&world[J[GEN_J_HAND]]);
        out->hand_rot[s] = mat_q(&world[J[GEN_J_HAND]]);
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
