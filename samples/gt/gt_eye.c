/* gt_eye.c - the true operator seen from the true eye (gt_eye.h). */
#include "gt_eye.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

kin_camera gt_eye_camera(const kin_sthmd_desc *hd, const kin_mat4 *world_from_head,
                         kin_eye eye)
{
    kin_sthmd_desc r = kin_sthmd_desc_resolved(hd);
    kin_camera c;
    memset(&c, 0, sizeof c);
    c.world_from_cam = kin_sthmd_eye(&r, world_from_head, eye);
    if (!kin_mat4_inverse(&c.world_from_cam, &c.view)) c.view = kin_mat4_identity();
    c.width = r.lcd_width;
    c.height = r.lcd_height;
    c.fx = 0.5f * (float)r.lcd_width / tanf(0.5f * r.hmd_hfov_deg * PI_F / 180.0f);
    c.fy = 0.5f * (float)r.lcd_height / tanf(0.5f * r.hmd_vfov_deg * PI_F / 180.0f);
    c.cx = 0.5f * (float)r.lcd_width;
    c.cy = 0.5f * (float)r.lcd_height;
    c.proj = gen_proj_from_intrinsics(c.fx, c.fy, c.cx, c.cy, c.width, c.height, GEN_VIRT_ZNEAR,
                                      GEN_VIRT_ZFAR);
    c.view_proj = kin_mat4_mul(&c.proj, &c.view);
    return c;
}

/* 1 when node is joint first..last of a side in sides. */
static int is_part_node(const gen_arms *a, unsigned sides, int first, int last, int node)
{
    for (int s = 0; s < 2; s++)
        for (int j = first; j <= last; j++)
            if ((sides >> s & 1u) && a->joint[s][j] == node) return 1;
    return 0;
}

uint32_t *gt_part_triangles(const gen_arms *arms, unsigned sides, int first, int last,
                            int *tri_count)
{
    const kin_model *m = &arms->model;
    const kin_mesh *me = &m->meshes[0];
    const kin_skin *sk = &m->skins[0];
    *tri_count = 0;
    if (!me->joints || !me->weights) return NULL;
    uint8_t *hv = malloc((size_t)me->vertex_count);
    uint32_t *idx = malloc(sizeof *idx * (size_t)(me->index_count > 0 ? me->index_count : 1));
    if (!hv || !idx) {
        free(hv);
        free(idx);
        return NULL;
    }
    for (int v = 0; v < me->vertex_count; v++) {
        float w = 0.0f;
        for (int k = 0; k < 4; k++)
            if (is_part_node(arms, sides, first, last, sk->joints[me->joints[v * 4 + k]])) w += me->weights[v * 4 + k];
        hv[v] = w >= 0.5f;
    }
    int n = 0;
    for (int t = 0; t < me->index_count / 3; t++) {
        const uint32_t *q = &me->indices[t * 3];
        if (!hv[q[0]] || !hv[q[1]] || !hv[q[2]]) continue;
        memcpy(&idx[n * 3], q, sizeof *q * 3);
        n++;
    }
    free(hv);
    if (n == 0) {
        free(idx);
        return NULL;
    }
    *tri_count = n;
    return idx;
}

static uint8_t to_u8(float x)
{
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    return (uint8_t)(x * 255.0f + 0.5f);
}

void gt_render_view(gen_frame_ctx *c, const kin_camera *cam, const uint32_t *hand_idx,
                    int hand_tris, uint8_t *rgba, uint8_t *sil, uint8_t *hand, float *nrm,
                    float *scratch_depth, double *hand_depth)
{
    const int w = cam->width, h = cam->height;
    const kin_mesh *me = &c->arms->model.meshes[0];
    rast_target t = { w, h, c->depth, w, c->mask, w, c->tattr, w * GEN_ATTRS, GEN_ATTRS, NULL, 0 };
    rast_target_clear(&t);
    rast_transform_points(cam->view_proj.m, c->skin_pos, me->vertex_count, c->clip);
    rast_mesh_desc d = { c->clip, me->vertex_count, c->arm_attr, GEN_ATTRS, me->indices,
                         me->index_count / 3, RAST_CULL_NONE };
    rast_draw(&t, &d, NULL);
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        int arm = c->mask[i] != 0;
        sil[i] = arm ? 255 : 0;
        const float *a = &c->tattr[i * GEN_ATTRS];
        if (rgba) {
            float col[3] = { 0, 0, 0 };
            if (arm) gen_shade(c->cockpit, a, col);
            for (int k = 0; k < 3; k++) rgba[i * 4 + (size_t)k] = arm ? to_u8(col[k]) : 0;
            rgba[i * 4 + 3] = arm ? 255 : 0;
        }
        if (nrm) {
            kin_vec3 n = kin_v3(0, 0, 0);
            if (arm)
                n = kin_v3_norm(kin_mat4_mul_dir(&cam->view,
                                                 kin_v3(a[GEN_A_NX], a[GEN_A_NY], a[GEN_A_NZ])));
            nrm[i * 3 + 0] = n.x;
            nrm[i * 3 + 1] = n.y;
            nrm[i * 3 + 2] = n.z;
        }
    }
    if (hand && hand_idx && hand_tris > 0) {
        rast_target th = { w, h, scratch_depth, w, hand, w, NULL, 0, 0, NULL, 0 };
        rast_target_clear(&th);
        rast_mesh_desc dh = { c->clip, me->vertex_count, NULL, 0, hand_idx, hand_tris,
                              RAST_CULL_NONE };
        rast_draw(&th, &dh, NULL);
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) hand[i] = hand[i] ? 255 : 0;
    } else if (hand) {
        memset(hand, 0, (size_t)w * (size_t)h);
    }
    if (hand_depth) {
        /* the hands' vertices: those of the hand triangles (counted once
         * per use; the mean of a closed surface's vertices) */
        double sum = 0.0;
        long n = 0;
        for (int i = 0; i < 3 * hand_tris; i++) {
            const float *p = &c->skin_pos[(size_t)hand_idx[i] * 3];
            kin_vec3 v = kin_mat4_mul_point(&cam->view, kin_v3(p[0], p[1], p[2]));
            if (v.z < 0.0f) {
                sum += -(double)v.z;
                n++;
            }
        }
        *hand_depth = n ? sum / (double)n : 0.0;
    }
}

void gt_view_seen_by(const gen_frame_ctx *c, const kin_camera *eye, float znear, float zfar,
                     const kin_camera *cam, const uint8_t *sil, uint8_t *out)
{
    const int w = eye->width, h = eye->height;
    const double n = znear, f = zfar;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            out[i] = 0;
            if (!sil[i]) continue;
            /* the view-space point of the pixel centre at its depth */
            double zn = 2.0 * (double)c->depth[i] - 1.0;
            double d = 2.0 * f * n / ((f + n) - zn * (f - n));
            kin_vec3 pv = kin_v3((float)(((double)x + 0.5 - eye->cx) / eye->fx * d),
                                 (float)(-((double)y + 0.5 - eye->cy) / eye->fy * d), (float)-d);
            kin_vec3 pw = kin_mat4_mul_point(&eye->world_from_cam, pv);
            kin_vec3 pc = kin_mat4_mul_point(&cam->view, pw);
            if (!(pc.z < 0.0f)) continue;
            double u = cam->cx + cam->fx * pc.x / -pc.z, v = cam->cy - cam->fy * pc.y / -pc.z;
            if (u >= 0.0 && u < cam->width && v >= 0.0 && v < cam->height) out[i] = 255;
        }
}
