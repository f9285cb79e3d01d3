/* gen_render.c - the frames of the samples: what the HMD cameras see (the
 * posed arms in front of the cockpit, 640x480 sensor images with mild
 * noise) and what the HMD shows of the remote workshop from the eyes
 * (1280x800 colour and view-space depth). Geometry goes through kin (FK,
 * LBS, the STHMD camera) and raster (rast_draw with depth and attributes);
 * this file only shades the pixels the rasterizer wrote. */
#include "gen.h"
#include "../../src/cpu/ef_mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

/* ------------------------------------------------------------ projection */

kin_mat4 gen_proj_from_intrinsics(float fx, float fy, float cx, float cy,
                                  int width, int height, float znear,
                                  float zfar)
{
    kin_mat4 p;
    memset(&p, 0, sizeof p);
    /* column-major m[col*4 + row] */
    p.m[0] = 2.0f * fx / (float)width;
    p.m[5] = 2.0f * fy / (float)height;
    p.m[8] = 1.0f - 2.0f * cx / (float)width;
    p.m[9] = 2.0f * cy / (float)height - 1.0f;
    p.m[10] = -(zfar + znear) / (zfar - znear);
    p.m[11] = -1.0f;
    p.m[14] = -2.0f * zfar * znear / (zfar - znear);
    return p;
}

/* ------------------------------------------------------------------ noise */

static uint32_t hash3(int32_t x, int32_t y, uint32_t seed)
{
    uint64_t z = (uint64_t)(uint32_t)x * 0x9E3779B97F4A7C15ull ^
                 (uint64_t)(uint32_t)y * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)seed * 0x165667B19E3779F9ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (uint32_t)((z ^ (z >> 31)) >> 32);
}

static float hashf(int32_t x, int32_t y, uint32_t seed)
{
    return (float)(hash3(x, y, seed) >> 8) * (1.0f / 16777216.0f);
}

/* Smooth value noise in [0, 1). */
static float vnoise(float x, float y, uint32_t seed)
{
    float fx = floorf(x), fy = floorf(y);
    int32_t ix = (int32_t)fx, iy = (int32_t)fy;
    float tx = x - fx, ty = y - fy;
    tx = tx * tx * (3.0f - 2.0f * tx);
    ty = ty * ty * (3.0f - 2.0f * ty);
    float a = hashf(ix, iy, seed), b = hashf(ix + 1, iy, seed);
    float c = hashf(ix, iy + 1, seed), d = hashf(ix + 1, iy + 1, seed);
    return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

static float fract(float x) { return x - floorf(x); }

/* -------------------------------------------------------------- shading */

/* Colour of a lit surface point (display values 0..1, unclamped). */
static void shade(const gen_scene *sc, const float *a, float out[3])
{
    kin_vec3 n = kin_v3_norm(kin_v3(a[GEN_A_NX], a[GEN_A_NY], a[GEN_A_NZ]));
    float pu = a[GEN_A_U], v = a[GEN_A_V];
    int pat = (int)floorf(pu / GEN_PATTERN_STRIDE + 0.5f);
    float u = pu - (float)pat * GEN_PATTERN_STRIDE;
    float alb[3] = { a[GEN_A_R], a[GEN_A_G], a[GEN_A_B] };
    float light[3] = { sc->ambient[0], sc->ambient[1], sc->ambient[2] };
    for (int i = 0; i < sc->light_count; i++) {
        float d = n.x * sc->light_dir[i][0] + n.y * sc->light_dir[i][1] +
                  n.z * sc->light_dir[i][2];
        if (d > 0.0f)
            for (int k = 0; k < 3; k++) light[k] += d * sc->light_color[i][k];
    }
    float mul = 1.0f, emit[3] = { 0, 0, 0 }, tint[3] = { 1, 1, 1 };
    switch (pat) {
    case GEN_PAT_SKIN: {
        float m1 = vnoise(u * 260.0f, v * 260.0f, 11u) - 0.5f;
        float m2 = vnoise(u * 45.0f, v * 45.0f, 12u) - 0.5f;
        mul = 1.0f + 0.07f * m1 + 0.08f * m2;
        tint[0] = 1.0f + 0.05f * m2;
        tint[2] = 1.0f - 0.05f * m2;
        break;
    }
    case GEN_PAT_FABRIC: {
        float w = sinf(u * 2.0f * PI_F * 350.0f) * sinf(v * 2.0f * PI_F * 350.0f);
        mul = 0.92f + 0.08f * w + 0.10f * (vnoise(u * 30.0f, v * 30.0f, 13u) - 0.5f);
        break;
    }
    case GEN_PAT_TILES: {
        float tu = u / 0.5f, tv = v / 0.5f;
        float gu = fract(tu), gv = fract(tv);
        if (gu < 0.015f || gv < 0.015f) mul = 0.6f;
        else mul = 0.9f + 0.2f * hashf((int32_t)floorf(tu), (int32_t)floorf(tv), 21u) +
                   0.08f * (vnoise(u * 20.0f, v * 20.0f, 22u) - 0.5f);
        break;
    }
    case GEN_PAT_SCREEN: {
        int row = (int)floorf(v / 0.018f);
        float len = 0.05f + 0.3f * hashf(row, 0, 31u);
        if (fract(v / 0.018f) < 0.55f && u > 0.02f && u < len && row > 0) {
            float g = 0.5f + 0.5f * hashf(row, 1, 32u);
            emit[0] = 0.15f * g; emit[1] = 0.75f * g; emit[2] = 0.85f * g;
        }
        mul = 0.6f;
        break;
    }
    case GEN_PAT_WOOD: {
        float ring = sinf(u * 160.0f + 5.0f * vnoise(u * 6.0f, v * 30.0f, 41u));
        mul = 0.94f + 0.05f * ring + 0.06f * (vnoise(u * 90.0f, v * 6.0f, 42u) - 0.5f);
        break;
    }
    case GEN_PAT_BUTTONS: {
        int bx = (int)floorf(u / 0.03f), by = (int)floorf(v / 0.03f);
        float fu = fract(u / 0.03f), fv = fract(v / 0.03f);
        uint32_t h = hash3(bx, by, 51u) % 10u;
        if (fu > 0.25f && fu < 0.75f && fv > 0.25f && fv < 0.75f && h < 6u) {
            static const float col[6][3] = {
                { 0.75f, 0.2f, 0.15f }, { 0.25f, 0.7f, 0.3f }, { 0.8f, 0.7f, 0.2f },
                { 0.7f, 0.7f, 0.7f }, { 0.7f, 0.7f, 0.7f }, { 0.2f, 0.4f, 0.9f },
            };
            alb[0] = col[h][0]; alb[1] = col[h][1]; alb[2] = col[h][2];
            if (h < 3) {
                emit[0] = 0.25f * col[h][0];
                emit[1] = 0.25f * col[h][1];
                emit[2] = 0.25f * col[h][2];
            }
        }
        break;
    }
    case GEN_PAT_WINDOW:
        for (int k = 0; k < 3; k++) { emit[k] = alb[k] * 0.95f; light[k] = 0.0f; }
        break;
    default:
        mul = 1.0f + 0.04f * (vnoise(u * 12.0f, v * 12.0f, 61u) - 0.5f);
        break;
    }
    for (int k = 0; k < 3; k++) out[k] = alb[k] * mul * tint[k] * light[k] + emit[k];
}

static uint8_t to_u8(float x)
{
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    return (uint8_t)(x * 255.0f + 0.5f);
}

/* ------------------------------------------------------------- contexts */

void gen_frame_ctx_free(gen_frame_ctx *c)
{
    EF_FREE_ALL(c->locals, c->world, c->jm, c->skin_pos, c->skin_nrm, c->arm_attr, c->clip,
                c->depth, c->tattr, c->mask);
    memset(c, 0, sizeof *c);
}

int gen_frame_ctx_init(gen_frame_ctx *c, const gen_arms *arms,
                       const gen_scene *cockpit, const gen_scene *workshop,
                       uint64_t seed)
{
    memset(c, 0, sizeof *c);
    const kin_model *m = &arms->model;
    int V = m->meshes[0].vertex_count;
    size_t maxv = (size_t)V;
    if ((size_t)cockpit->vertex_count > maxv) maxv = (size_t)cockpit->vertex_count;
    if ((size_t)workshop->vertex_count > maxv) maxv = (size_t)workshop->vertex_count;
    size_t px = (size_t)GEN_VIRT_W * GEN_VIRT_H;
    c->arms = arms;
    c->cockpit = cockpit;
    c->workshop = workshop;
    c->seed = seed;
    c->locals = malloc(sizeof *c->locals * (size_t)m->node_count);
    c->world = malloc(sizeof *c->world * (size_t)m->node_count);
    c->jm = malloc(sizeof *c->jm * (size_t)m->skins[0].joint_count);
    c->skin_pos = malloc(sizeof(float) * 3 * (size_t)V);
    c->skin_nrm = malloc(sizeof(float) * 3 * (size_t)V);
    c->arm_attr = malloc(sizeof(float) * GEN_ATTRS * (size_t)V);
    c->clip = malloc(sizeof(float) * 4 * maxv);
    c->clip_cap = maxv;
    c->depth = malloc(sizeof(float) * px);
    c->tattr = malloc(sizeof(float) * GEN_ATTRS * px);
    c->mask = malloc(px);
    c->px_cap = px;
    c->hmd = kin_sthmd_desc_resolved(NULL);
    if (!c->locals || !c->world || !c->jm || !c->skin_pos || !c->skin_nrm ||
        !c->arm_attr || !c->clip || !c->depth || !c->tattr || !c->mask) {
        gen_frame_ctx_free(c);
        return -1;
    }
    for (int v = 0; v < V; v++) {
        float *a = &c->arm_attr[v * GEN_ATTRS];
        a[GEN_A_R] = arms->albedo[v * 3 + 0];
        a[GEN_A_G] = arms->albedo[v * 3 + 1];
        a[GEN_A_B] = arms->albedo[v * 3 + 2];
        a[GEN_A_U] = arms->uv[v * 2 + 0];
        a[GEN_A_V] = arms->uv[v * 2 + 1];
    }
    return 0;
}

int gen_frame_ctx_set_hmd(gen_frame_ctx *c, const kin_sthmd_desc *hd)
{
    const kin_sthmd_desc r = kin_sthmd_desc_resolved(hd);
    size_t px = (size_t)r.cam_width * (size_t)r.cam_height;
    if ((size_t)r.lcd_width * (size_t)r.lcd_height > px)
        px = (size_t)r.lcd_width * (size_t)r.lcd_height;
    if (px > c->px_cap) {
        float *depth = malloc(sizeof(float) * px);
        float *tattr = malloc(sizeof(float) * GEN_ATTRS * px);
        uint8_t *mask = malloc(px);
        if (!depth || !tattr || !mask) {
            free(depth);
            free(tattr);
            free(mask);
            return -1;
        }
        free(c->depth);
        free(c->tattr);
        free(c->mask);
        c->depth = depth;
        c->tattr = tattr;
        c->mask = mask;
        c->px_cap = px;
    }
    c->hmd = r;
    return 0;
}

void gen_pose(gen_frame_ctx *c, float t, kin_mat4 *world_from_head)
{
    const kin_model *m = &c->arms->model;
    const kin_mesh *me = &m->meshes[0];
    kin_pose_rest(m, c->locals);
    kin_anim_sample(&m->anims[0], m->node_count, t, c->locals);
    kin_fk(m->parents, m->node_count, c->locals, NULL, c->world);
    kin_skin_joint_matrices(&m->skins[0], c->world, c->jm);
    kin_skin_lbs(me, c->jm, c->skin_pos, c->skin_nrm);
    for (int v = 0; v < me->vertex_count; v++) {
        float *a = &c->arm_attr[v * GEN_ATTRS];
        a[GEN_A_NX] = c->skin_nrm[v * 3 + 0];
        a[GEN_A_NY] = c->skin_nrm[v * 3 + 1];
        a[GEN_A_NZ] = c->skin_nrm[v * 3 + 2];
    }
    *world_from_head = c->world[c->arms->head];
}

static rast_target target_of(gen_frame_ctx *c, int w, int h)
{
    rast_target t = { w, h, c->depth, w, c->mask, w, c->tattr, w * GEN_ATTRS, GEN_ATTRS, NULL, 0 };
    return t;
}

static void draw(gen_frame_ctx *c, const rast_target *t, const kin_mat4 *vp,
                 const float *pos, const float *attr, int nv,
                 const uint32_t *idx, int ntri)
{
    rast_transform_points(vp->m, pos, nv, c->clip);
    rast_mesh_desc d = { c->clip, nv, attr, GEN_ATTRS, idx, ntri, RAST_CULL_NONE };
    rast_draw(t, &d, NULL);
}

static void draw_scene(gen_frame_ctx *c, const rast_target *t,
                       const kin_mat4 *vp, const gen_scene *s)
{
    draw(c, t, vp, s->pos, s->attr, s->vertex_count, s->idx, s->tri_count);
}

static void draw_arms(gen_frame_ctx *c, const rast_target *t, const kin_mat4 *vp)
{
    const kin_mesh *me = &c->arms->model.meshes[0];
    draw(c, t, vp, c->skin_pos, c->arm_attr, me->vertex_count, me->indices,
         me->index_count / 3);
}

static int is_arm_pixel(const float *a)
{
    int pat = (int)floorf(a[GEN_A_U] / GEN_PATTERN_STRIDE + 0.5f);
    return pat == GEN_PAT_SKIN || pat == GEN_PAT_FABRIC;
}

static uint64_t mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void gen_render_camera(gen_frame_ctx *c, const kin_mat4 *world_from_head,
                       kin_eye eye, int frame, uint8_t *rgb, float *coverage)
{
    const int cw = c->hmd.cam_width, ch = c->hmd.cam_height;
    kin_camera cam = kin_sthmd_camera(&c->hmd, world_from_head, eye);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(&c->hmd);
    /* the full sensor: same focal length, principal point crop_x0 right
     * of and crop_y0 below the crop's */
    const float cx = cam.cx + (float)g.crop_x0;
    kin_mat4 proj = gen_proj_from_intrinsics(cam.fx, cam.fy, cx,
                                             cam.cy + (float)g.crop_y0,
                                             cw, ch,
                                             GEN_CAM_ZNEAR, GEN_CAM_ZFAR);
    kin_mat4 vp = kin_mat4_mul(&proj, &cam.view);
    rast_target t = target_of(c, cw, ch);
    rast_target_clear(&t);
    draw_scene(c, &t, &vp, c->cockpit);
    draw_arms(c, &t, &vp);
    /* camera noise: splitmix64 stream of (seed, frame, eye) */
    uint64_t st = mix64(c->seed * 0x9E3779B97F4A7C15ull + (uint64_t)frame * 2u +
                        (uint64_t)eye + 1u);
    long covered = 0;
    for (int y = 0; y < ch; y++) {
        for (int x = 0; x < cw; x++) {
            size_t i = (size_t)y * (size_t)cw + (size_t)x;
            float col[3];
            if (c->mask[i]) {
                const float *a = &c->tattr[i * GEN_ATTRS];
                shade(c->cockpit, a, col);
                if (is_arm_pixel(a) && y >= g.crop_y0 && y < g.crop_y0 + g.crop_height &&
                    x >= g.crop_x0 && x < g.crop_x0 + g.crop_width)
                    covered++;
            } else {
                col[0] = c->cockpit->sky[0];
                col[1] = c->cockpit->sky[1];
                col[2] = c->cockpit->sky[2];
            }
            /* slight lens vignetting */
            float dx = ((float)x + 0.5f - cx) / cam.fx;
            float dy = ((float)y + 0.5f - cam.cy - (float)g.crop_y0) / cam.fy;
            float vig = 1.0f - 0.12f * (dx * dx + dy * dy);
            for (int k = 0; k < 3; k++) {
                st += 0x9E3779B97F4A7C15ull;
                uint64_t r = mix64(st);
                /* triangular noise, about +-2.5 levels */
                float nz = ((float)(r & 0xFFFF) + (float)((r >> 16) & 0xFFFF)) *
                               (1.0f / 65536.0f) - 1.0f;
                rgb[i * 3 + (size_t)k] = to_u8(col[k] * vig + nz * (2.5f / 255.0f));
            }
        }
    }
    if (coverage)
        *coverage = (float)covered / (float)(g.crop_width * g.crop_height);
}

void gen_render_virtual(gen_frame_ctx *c, const kin_mat4 *world_from_head,
                        kin_eye eye, int frame, uint8_t *rgb, float *depth)
{
    (void)frame;
    kin_transform te = kin_transform_identity();
    const float half = 0.5f * c->hmd.ipd_m;   /* the paper: GEN_EYE_HALF_BASELINE */
    const int vw = c->hmd.lcd_width, vh = c->hmd.lcd_height;
    te.t.x = eye == KIN_EYE_LEFT ? -half : half;
    kin_mat4 he = kin_mat4_from_transform(&te);
    kin_mat4 world_from_eye = kin_mat4_mul(world_from_head, &he), view;
    kin_mat4_inverse(&world_from_eye, &view);
    float fx = 0.5f * (float)vw / tanf(0.5f * c->hmd.hmd_hfov_deg * PI_F / 180.0f);
    float fy = 0.5f * (float)vh / tanf(0.5f * c->hmd.hmd_vfov_deg * PI_F / 180.0f);
    kin_mat4 proj = gen_proj_from_intrinsics(fx, fy, 0.5f * (float)vw, 0.5f * (float)vh,
                                             vw, vh,
                                             GEN_VIRT_ZNEAR, GEN_VIRT_ZFAR);
    kin_mat4 vp = kin_mat4_mul(&proj, &view);
    rast_target t = target_of(c, vw, vh);
    rast_target_clear(&t);
    draw_scene(c, &t, &vp, c->workshop);
    const double n = GEN_VIRT_ZNEAR, f = GEN_VIRT_ZFAR;
    for (size_t i = 0; i < (size_t)vw * (size_t)vh; i++) {
        float col[3];
        if (c->mask[i]) {
            shade(c->workshop, &c->tattr[i * GEN_ATTRS], col);
            double zn = 2.0 * (double)c->depth[i] - 1.0;
            depth[i] = (float)(2.0 * f * n / ((f + n) - zn * (f - n)));
        } else {
            col[0] = c->workshop->sky[0];
            col[1] = c->workshop->sky[1];
            col[2] = c->workshop->sky[2];
            depth[i] = GEN_VIRT_ZFAR;
        }
        for (int k = 0; k < 3; k++) rgb[i * 3 + (size_t)k] = to_u8(col[k]);
    }
}

void gen_shade(const gen_scene *sc, const float *attr, float out[3])
{
    shade(sc, attr, out);
}
