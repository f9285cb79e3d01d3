/* pipe.c - one stereo frame, end to end (see pipe.h). */
#include "pipe.h"
#include "pipe_parts.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ------------------------------------------------------------- posing */

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
    free(ps->joint_mats);
    free(ps->own_normals);
    free(ps->meshes);
    free(ps->pos);
    free(ps->nrm);
    free(ps->locals);
    free(ps->world);
    memset(ps, 0, sizeof *ps);
}

/* FK from ps->locals and the joint matrices. */
static void pose_fk(pipe_pose *ps)
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
static void pose_skin_part(pipe_pose *ps, const kin_skin_plan *plans, int part, int parts)
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
        kin_mesh sub = *me; /* a view of vertices [v0, v1) */
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
    pose_fk(ps);
    pose_skin_part(ps, NULL, 0, 1);
}

static void pose_locals_anim(pipe_pose *ps, const kin_animation *anim, float t)
{
    kin_pose_rest(ps->model, ps->locals);
    if (anim) kin_anim_sample(anim, ps->model->node_count, t, ps->locals);
}

void pipe_pose_anim(pipe_pose *ps, const kin_animation *anim, float t)
{
    pose_locals_anim(ps, anim, t);
    pose_skin(ps);
}

void pipe_pose_locals(pipe_pose *ps, const kin_transform *locals)
{
    memcpy(ps->locals, locals, sizeof *locals * (size_t)ps->model->node_count);
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

/* ------------------------------------------------------------- frames */

typedef struct eye_state {
    int eye;
    float *depth, *nrm, *clip, *vnrm;
    uint8_t *mask, *layer;
    uint8_t *cam_rgba;        /* the cropped camera image, when given raw */
    uint8_t *refined;         /* the refined mask (refine_band) */
    void *refine_scratch;
    size_t refine_scratch_size;
    int have_refined;         /* refined holds the last frame's mask */
    int converted;            /* cam_rgba already holds this frame's crop */
    rast_context *rast;
    fuse_context *fuse;
    kin_camera cam;
    /* per-frame job */
    const pipe_frame_in *in;
    kin_mat4 head;
    pipe_result result;
    char why[160];
    double ms_raster, ms_convert, ms_fuse, coverage;
} eye_state;

struct pipe_ctx {
    pipe_desc desc;
    kin_sthmd_desc hmd;
    kin_sthmd_geometry geo;
    pipe_pose pose;
    eye_state eye[2];
    /* the worker thread runs eye 1 when threads == 2 */
    int threaded;
    pthread_t worker;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int job_seq, done_seq, quit;
    int job_kind;             /* JOB_SKIN or JOB_EYE */
    int skin_split;           /* skin on both threads (large models) */
    kin_skin_plan *plans;     /* per mesh: the skin plan of a skinned mesh */
    void **plan_mem;          /* per mesh: its memory, or NULL */
    pipe_fit *fit;            /* elbow fit (refine_band and fit_rig) */
    kin_arm_rig fit_rig;
    int fit_no_prev;          /* pipe_reset_fit: the refined masks are of
                                 before it, not to be learned from */
    pipe__cockpit *ck;        /* hidden parts and props (pipe_parts.c) */
};

enum { JOB_SKIN, JOB_EYE };
/* Below this many vertices, splitting the skinning costs more in the
 * hand-over than it saves: measured with the 7.8k-vertex sample arms
 * (make bench), FK + skinning took 0.089 ms on one thread and 0.155 ms
 * split over two. AVX-512 skins about 160k vertices per ms. */
#define PIPE_SPLIT_SKIN_VERTICES 65536

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return 1e3 * (double)ts.tv_sec + 1e-6 * (double)ts.tv_nsec;
}

/* 1 if im is a w x h RGBA8 image, else 0 with a sentence in why. */
static int image_fits(const fuse_image *im, int w, int h, int eye,
                      const char *what, char *why, int why_size)
{
    if (im->pixels && im->width == w && im->height == h && im->stride >= 4 * w)
        return 1;
    if (why && why_size > 0)
        snprintf(why, (size_t)why_size,
                 "%s eye: the %s image is %dx%d (stride %d), expected %dx%d RGBA8",
                 eye ? "right" : "left", what, im->width, im->height, im->stride, w, h);
    return 0;
}

/* Columns crop_x0 .. of rows already cropped (eq. 1 with a camera wider
 * than the LCD's aspect; v itself otherwise). */
static fuse_image crop_cols(const pipe_ctx *p, fuse_image v)
{
    if (v.pixels && v.width != p->geo.crop_width) {
        v.pixels += (size_t)4 * (size_t)p->geo.crop_x0;
        v.width = p->geo.crop_width;
    }
    return v;
}

/* buf (an eye's cam_rgba) as the cropped rows of a raw frame, converted
 * at the sensor's width. */
static fuse_image raw_rows(const pipe_ctx *p, uint8_t *buf)
{
    return (fuse_image){buf, p->hmd.cam_width, p->geo.crop_height, 4 * p->hmd.cam_width};
}

static void run_eye(pipe_ctx *p, eye_state *e)
{
    const pipe_frame_in *in = e->in;
    const int cw = p->geo.crop_width, ch = p->geo.crop_height;
    double t0 = now_ms();
    e->result = PIPE_OK;
    e->cam = kin_sthmd_camera(&p->hmd, &e->head, (kin_eye)e->eye);
    rast_target tg = {cw, ch, e->depth, cw, e->mask, cw, e->nrm, 3 * cw, 3};
    rast_context_clear(e->rast, &tg); /* only what the last frame drew */
    rast_result rr = pipe__cockpit_active(p->ck)
                         ? pipe__cockpit_draw(p->ck, &p->pose, e->eye, e->rast, &e->cam, &tg,
                                              p->desc.cull, e->clip, e->vnrm)
                         : pipe_pose_draw(&p->pose, e->rast, &e->cam, &tg, p->desc.cull,
                                          e->clip, e->vnrm, NULL);
    double t1 = now_ms();
    e->ms_raster = t1 - t0;
    if (rr != RAST_OK) {
        e->result = PIPE_ERR_RASTER;
        snprintf(e->why, sizeof e->why, "%s eye: rasterizer: %s",
                 e->eye ? "right" : "left", rast_result_str(rr));
        return;
    }
    /* Only the tiles the draws marked are read (the rest is clear). */
    const long covered = rast_context_count(e->rast, &tg);
    e->coverage = (double)covered / (double)(cw * ch);

    /* Lights from world space into this camera's view space. */
    fuse_lighting L = in->lighting.light;
    for (int i = 0; i < L.light_count && i < FUSE_MAX_LIGHTS; i++) {
        kin_vec3 d = kin_v3(L.lights[i].dir[0], L.lights[i].dir[1], L.lights[i].dir[2]);
        d = kin_v3_norm(kin_mat4_mul_dir(&e->cam.view, d));
        L.lights[i].dir[0] = d.x;
        L.lights[i].dir[1] = d.y;
        L.lights[i].dir[2] = d.z;
    }
    fuse_intrinsics K = {e->cam.fx, e->cam.fy, e->cam.cx, e->cam.cy};
    fuse_eye fe = {0};
    fe.lighting = &L;
    fe.intrinsics = &K;
    e->ms_convert = 0.0;
    if (e->converted) {
        fe.P = crop_cols(p, raw_rows(p, e->cam_rgba));
    } else if (in->camera_raw[e->eye].data) {
        double tc = now_ms();
        fuse_image rows = raw_rows(p, e->cam_rgba);
        fuse_result cr = fuse_frame_to_rgba_isa(&in->camera_raw[e->eye], p->geo.crop_y0, &rows,
                                                (ef_isa)p->desc.max_isa);
        fe.P = crop_cols(p, rows);
        e->ms_convert = now_ms() - tc;
        if (cr != FUSE_OK) {
            e->result = PIPE_ERR_ARGS;
            snprintf(e->why, sizeof e->why, "%s eye: camera frame: %s",
                     e->eye ? "right" : "left", fuse_result_str(cr));
            return;
        }
    } else {
        fe.P = crop_cols(p, fuse_image_rows(&in->camera[e->eye], p->geo.crop_y0, ch));
    }
    fe.mask = e->mask;
    fe.mask_stride = cw;
    if (p->desc.refine_band > 0) {
        fuse_refine_params rp = fuse_refine_params_default();
        rp.band = p->desc.refine_band;
        /* the elbow fit's colour model as the global term only once it
         * has one: before that (or when the last learning found too few
         * samples) its all-zero model would only halve the local term */
        fuse_refine_stats rs;
        fuse_result rr2 =
            p->fit && pipe_fit_learned(p->fit, e->eye)
                ? fuse_refine_mask_global(&rp, pipe_fit_colour(p->fit, e->eye), 0.5f, &fe.P,
                                          e->mask, cw, e->refined, cw, e->refine_scratch,
                                          e->refine_scratch_size, &rs)
                : fuse_refine_mask(&rp, &fe.P, e->mask, cw, e->refined, cw, e->refine_scratch,
                                   e->refine_scratch_size, &rs);
        if (rr2 != FUSE_OK) {
            e->result = PIPE_ERR_FUSE;
            snprintf(e->why, sizeof e->why, "%s eye: mask refinement: %s",
                     e->eye ? "right" : "left", fuse_result_str(rr2));
            return;
        }
        pipe__cockpit_clamp(p->ck, &p->pose, e->eye, e->rast, &e->cam, e->mask, cw, e->refined,
                            cw, p->desc.refine_band, e->clip);
        e->have_refined = 1;
        fe.mask = e->refined;
        if (p->fit && in->locals && rs.used_colour) {
            /* the next frame's fit: its colour model from this frame's
             * kinematic and refined masks, and the limb widths; not when
             * the refinement fell back to the kinematic mask (out = M):
             * its widths would be the model's own, samples equal to the
             * factor in use */
            if (pipe_fit_learn(p->fit, e->eye, &fe.P, e->mask, cw, e->refined, cw) != FUSE_OK) {
                e->result = PIPE_ERR_FUSE;
                snprintf(e->why, sizeof e->why, "%s eye: elbow fit: colour model",
                         e->eye ? "right" : "left");
                return;
            }
            pipe_fit_measure(p->fit, e->eye, &e->cam, p->pose.world, e->mask, cw, e->refined, cw);
        }
    }
    fe.normal = e->nrm;
    fe.normal_stride = 3 * cw;
    fe.Q = (fuse_image){e->layer, cw, ch, 4 * cw};
    fe.V = in->virt[e->eye];
    fe.vp_x0 = p->geo.vp_x0;
    fe.vp_y0 = p->geo.vp_y0;
    fe.vp_w = p->geo.vp_width;
    fe.vp_h = p->geo.vp_height;
    fe.out = in->out[e->eye];
    fe.v_opaque = in->virt_opaque != 0;
    fuse_depth dt;
    if (in->virt_depth[e->eye]) {
        dt = (fuse_depth){e->depth, cw, p->hmd.znear, p->hmd.zfar, p->hmd.cam_offset_m,
                          in->virt_depth[e->eye], in->virt_depth_stride[e->eye],
                          fe.V.width, fe.V.height};
        fe.depth = &dt;
    }
    fuse_result fr = FUSE_OK;
    if (p->desc.tone_match > 0.0f) {
        float tone[3];
        fr = fuse_tone_match(&fe.P, e->mask, cw, &fe.V, fe.vp_x0, fe.vp_y0, fe.vp_w,
                             fe.vp_h, p->desc.tone_match, tone);
        for (int k = 0; k < 3; k++) L.tone[k] *= tone[k];
    }
    if (fr == FUSE_OK) fr = fuse_context_frame(e->fuse, &fe, 1);
    e->ms_fuse = now_ms() - t1 - e->ms_convert;
    if (fr != FUSE_OK) {
        e->result = PIPE_ERR_FUSE;
        snprintf(e->why, sizeof e->why, "%s eye: lighting/composite: %s",
                 e->eye ? "right" : "left", fuse_result_str(fr));
    }
}

static void *worker_main(void *arg)
{
    pipe_ctx *p = arg;
    int seen = 0;
    pthread_mutex_lock(&p->mu);
    for (;;) {
        while (p->job_seq == seen && !p->quit) pthread_cond_wait(&p->cv, &p->mu);
        if (p->quit) break;
        seen = p->job_seq;
        int kind = p->job_kind;
        pthread_mutex_unlock(&p->mu);
        if (kind == JOB_SKIN) pose_skin_part(&p->pose, p->plans, 1, 2);
        else run_eye(p, &p->eye[1]);
        pthread_mutex_lock(&p->mu);
        p->done_seq = seen;
        pthread_cond_broadcast(&p->cv);
    }
    pthread_mutex_unlock(&p->mu);
    return NULL;
}

/* Hands a job to the worker; returns its number for wait_job. */
static int post_job(pipe_ctx *p, int kind)
{
    pthread_mutex_lock(&p->mu);
    p->job_kind = kind;
    int job = ++p->job_seq;
    pthread_cond_broadcast(&p->cv);
    pthread_mutex_unlock(&p->mu);
    return job;
}

static void wait_job(pipe_ctx *p, int job)
{
    pthread_mutex_lock(&p->mu);
    while (p->done_seq != job) pthread_cond_wait(&p->cv, &p->mu);
    pthread_mutex_unlock(&p->mu);
}

pipe_lighting pipe_lighting_default(void)
{
    pipe_lighting l = {fuse_lighting_default()};
    return l;
}

static void free_eyes(pipe_ctx *p)
{
    for (int e = 0; e < 2; e++) {
        free(p->eye[e].depth);
        free(p->eye[e].nrm);
        free(p->eye[e].clip);
        free(p->eye[e].vnrm);
        free(p->eye[e].mask);
        free(p->eye[e].layer);
        free(p->eye[e].cam_rgba);
        free(p->eye[e].refined);
        free(p->eye[e].refine_scratch);
        rast_context_destroy(p->eye[e].rast);
        fuse_context_destroy(p->eye[e].fuse);
    }
    pipe_fit_destroy(p->fit);
    p->fit = NULL;
    pipe__cockpit_destroy(p->ck);
    p->ck = NULL;
}

static void skin_plans_free(pipe_ctx *p)
{
    for (int i = 0; p->plan_mem && i < p->pose.model->mesh_count; i++) free(p->plan_mem[i]);
    free(p->plan_mem);
    free(p->plans);
    p->plan_mem = NULL;
    p->plans = NULL;
}

/* A skin plan per skinned mesh (of pose.meshes, whose normals are filled
 * in), built once. Returns 0, or -1 when out of memory. */
static int skin_plans_build(pipe_ctx *p)
{
    const int nm = p->pose.model->mesh_count;
    p->plans = calloc((size_t)nm + 1, sizeof *p->plans);
    p->plan_mem = calloc((size_t)nm + 1, sizeof *p->plan_mem);
    if (!p->plans || !p->plan_mem) return -1;
    for (int i = 0; i < nm; i++) {
        const kin_mesh *me = &p->pose.meshes[i];
        if (me->skin < 0) continue;
        void *scratch = malloc(kin_skin_plan_scratch_size(me) + 16);
        size_t bytes = scratch ? kin_skin_plan_size(me, scratch) : 0;
        p->plan_mem[i] = bytes ? aligned_alloc(64, (bytes + 63) & ~(size_t)63) : NULL;
        int rc = p->plan_mem[i] ? kin_skin_plan_init(&p->plans[i], me, scratch, p->plan_mem[i], bytes) : -1;
        free(scratch);
        if (rc != 0) return -1;
    }
    return 0;
}

pipe_ctx *pipe_create(const pipe_desc *desc, const kin_model *model)
{
    if (!model) return NULL;
    pipe_ctx *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    if (desc) p->desc = *desc;
    p->hmd = kin_sthmd_desc_resolved(&p->desc.hmd);
    p->geo = kin_sthmd_geometry_of(&p->hmd);
    if (pipe_pose_init(&p->pose, model) != 0) {
        free(p);
        return NULL;
    }
    size_t px = (size_t)p->geo.crop_width * (size_t)p->geo.crop_height;
    size_t nv = (size_t)p->pose.max_vertices;
    int ok = 1;
    for (int e = 0; e < 2; e++) {
        eye_state *s = &p->eye[e];
        s->eye = e;
        s->depth = malloc(sizeof(float) * px);
        s->nrm = malloc(sizeof(float) * 3 * px);
        s->mask = malloc(px);
        s->layer = malloc(4 * px);
        s->cam_rgba = malloc(4 * (size_t)p->hmd.cam_width * (size_t)p->geo.crop_height);
        s->clip = malloc(sizeof(float) * 4 * nv);
        s->vnrm = malloc(sizeof(float) * 3 * nv);
        rast_context_desc rd = {p->desc.max_isa, 1};
        fuse_context_desc fd = {(ef_isa)p->desc.max_isa, 1};
        s->rast = rast_context_create(&rd);
        s->fuse = fuse_context_create(&fd);
        ok = ok && s->depth && s->nrm && s->mask && s->layer && s->cam_rgba && s->clip && s->vnrm &&
             s->rast && s->fuse;
        if (ok && p->desc.refine_band > 0) {
            fuse_refine_params rp = fuse_refine_params_default();
            rp.band = p->desc.refine_band;
            s->refine_scratch_size =
                fuse_refine_scratch_size(&rp, p->geo.crop_width, p->geo.crop_height);
            s->refined = malloc(px);
            s->refine_scratch = s->refine_scratch_size
                                    ? aligned_alloc(16, (s->refine_scratch_size + 15) & ~(size_t)15)
                                    : NULL;
            ok = s->refined && s->refine_scratch;
        }
    }
    if (ok && p->desc.refine_band > 0 && p->desc.fit_rig) {
        p->fit_rig = *p->desc.fit_rig;
        p->desc.fit_rig = &p->fit_rig;
        p->fit = pipe_fit_create(NULL, model, &p->fit_rig, p->geo.crop_width, p->geo.crop_height);
        ok = p->fit != NULL;
    }
    ok = ok && skin_plans_build(p) == 0;
    if (ok) {
        p->ck = pipe__cockpit_create(model, p->desc.fit_rig, p->geo.crop_width,
                                     p->geo.crop_height, p->desc.refine_band);
        ok = p->ck != NULL;
    }
    p->threaded = p->desc.threads != 1;
    long nv_all = 0;
    for (int i = 0; i < model->mesh_count; i++) nv_all += model->meshes[i].vertex_count;
    p->skin_split = nv_all >= PIPE_SPLIT_SKIN_VERTICES;
    if (ok && p->threaded) {
        pthread_mutex_init(&p->mu, NULL);
        pthread_cond_init(&p->cv, NULL);
        if (pthread_create(&p->worker, NULL, worker_main, p) != 0) {
            pthread_mutex_destroy(&p->mu);
            pthread_cond_destroy(&p->cv);
            ok = 0;
            p->threaded = 0;
        }
    }
    if (!ok) {
        free_eyes(p);
        skin_plans_free(p);
        pipe_pose_free(&p->pose);
        free(p);
        return NULL;
    }
    return p;
}

void pipe_destroy(pipe_ctx *p)
{
    if (!p) return;
    if (p->threaded) {
        pthread_mutex_lock(&p->mu);
        p->quit = 1;
        pthread_cond_broadcast(&p->cv);
        pthread_mutex_unlock(&p->mu);
        pthread_join(p->worker, NULL);
        pthread_mutex_destroy(&p->mu);
        pthread_cond_destroy(&p->cv);
    }
    free_eyes(p);
    skin_plans_free(p);
    pipe_pose_free(&p->pose);
    free(p);
}

/* The elbow fit (pipe_fit) on the caller's thread: each eye's cropped
 * camera image (converted here when raw: the eye's thread then uses it)
 * and kinematic mask, the colour models, the swivels; then the pose is
 * skinned again. */
static pipe_result fit_elbows(pipe_ctx *p, const pipe_frame_in *in, const kin_mat4 *head,
                              char *why, int why_size)
{
    const int cw = p->geo.crop_width, ch = p->geo.crop_height;
    kin_camera cam[2];
    fuse_image P[2];
    for (int e = 0; e < 2; e++) {
        eye_state *s = &p->eye[e];
        cam[e] = kin_sthmd_camera(&p->hmd, head, (kin_eye)e);
        if (in->camera_raw[e].data) {
            fuse_image rows = raw_rows(p, s->cam_rgba);
            fuse_result cr = fuse_frame_to_rgba_isa(&in->camera_raw[e], p->geo.crop_y0, &rows,
                                                    (ef_isa)p->desc.max_isa);
            P[e] = crop_cols(p, rows);
            if (cr != FUSE_OK) {
                if (why && why_size > 0)
                    snprintf(why, (size_t)why_size, "%s eye: camera frame: %s",
                             e ? "right" : "left", fuse_result_str(cr));
                return PIPE_ERR_ARGS;
            }
            s->converted = 1;
        } else {
            P[e] = crop_cols(p, fuse_image_rows(&in->camera[e], p->geo.crop_y0, ch));
        }
        /* the colour model of the last frame's masks (run_eye) when there
         * is one; else this frame's kinematic mask is drawn for it */
        if (pipe_fit_learned(p->fit, e)) continue;
        rast_target tg = {cw, ch, s->depth, cw, s->mask, cw, s->nrm, 3 * cw, 3};
        rast_context_clear(s->rast, &tg);
        rast_result rr = pipe_pose_draw(&p->pose, s->rast, &cam[e], &tg, p->desc.cull, s->clip,
                                        s->vnrm, NULL);
        const uint8_t *prev = s->have_refined && !p->fit_no_prev ? s->refined : NULL;
        fuse_result lr =
            rr == RAST_OK ? pipe_fit_learn(p->fit, e, &P[e], s->mask, cw, prev, cw) : FUSE_OK;
        if (rr != RAST_OK || lr != FUSE_OK) {
            if (why && why_size > 0)
                snprintf(why, (size_t)why_size, "%s eye: elbow fit: %s", e ? "right" : "left",
                         rr != RAST_OK ? rast_result_str(rr) : fuse_result_str(lr));
            return rr != RAST_OK ? PIPE_ERR_RASTER : PIPE_ERR_FUSE;
        }
    }
    pipe_fit_elbows(p->fit, p->pose.world, p->pose.pos[0], cam, P, 3u & ~in->fit_skip,
                    p->pose.locals, NULL);
    pose_fk(&p->pose);
    pose_skin_part(&p->pose, p->plans, 0, 1);
    pipe_fit_shape(p->fit, p->pose.world, p->pose.pos[0]);
    return PIPE_OK;
}

pipe_result pipe_frame(pipe_ctx *p, const pipe_frame_in *in,
                       pipe_frame_stats *stats, char *why, int why_size)
{
    const int cam_w = p->hmd.cam_width, cam_h = p->hmd.cam_height;
    const int lcd_w = p->hmd.lcd_width, lcd_h = p->hmd.lcd_height;
    if (!in) return PIPE_ERR_ARGS;
    for (int e = 0; e < 2; e++) {
        const fuse_frame *raw = &in->camera_raw[e];
        if (raw->data) {
            /* Checked here, before any eye writes its output. */
            int rb = fuse_format_row_bytes(raw->format, raw->width);
            const char *bad = NULL;
            if (raw->width != cam_w || raw->height != cam_h) bad = "size";
            else if (rb == 0) bad = "format";
            else if (raw->stride < rb ||
                     raw->size < (size_t)(raw->height - 1) * (size_t)raw->stride + (size_t)rb)
                bad = "buffer";
            if (bad) {
                if (why && why_size > 0)
                    snprintf(why, (size_t)why_size,
                             "%s eye: camera frame %dx%d, format %d, stride %d, %zu bytes: "
                             "bad %s (expected %dx%d)", e ? "right" : "left", raw->width,
                             raw->height, (int)raw->format, raw->stride, raw->size, bad,
                             cam_w, cam_h);
                return PIPE_ERR_ARGS;
            }
        }
        if ((!raw->data && !image_fits(&in->camera[e], cam_w, cam_h, e, "camera", why, why_size)) ||
            !image_fits(&in->virt[e], lcd_w, lcd_h, e, "virtual", why, why_size) ||
            !image_fits(&in->out[e], lcd_w, lcd_h, e, "output", why, why_size))
            return PIPE_ERR_ARGS;
    }
    if (in->head_node >= p->pose.model->node_count) {
        if (why && why_size > 0)
            snprintf(why, (size_t)why_size, "head node %d of %d", in->head_node,
                     p->pose.model->node_count);
        return PIPE_ERR_ARGS;
    }
    pipe_result cr = pipe__cockpit_frame(p->ck, in, why, why_size);
    if (cr != PIPE_OK) return cr;

    double t0 = now_ms();
    if (in->locals)
        memcpy(p->pose.locals, in->locals, sizeof *in->locals * (size_t)p->pose.model->node_count);
    else
        pose_locals_anim(&p->pose, in->anim, in->time);
    pose_fk(&p->pose);
    if (p->threaded && p->skin_split) {
        int job = post_job(p, JOB_SKIN);
        pose_skin_part(&p->pose, p->plans, 0, 2);
        wait_job(p, job);
    } else {
        pose_skin_part(&p->pose, p->plans, 0, 1);
    }
    kin_mat4 head = in->head_node >= 0 ? p->pose.world[in->head_node]
                    : in->world_from_head ? *in->world_from_head
                                          : kin_mat4_identity();
    for (int e = 0; e < 2; e++) p->eye[e].converted = 0;
    /* the measured thickness on every frame, animation-posed ones too: the
     * arm drawn does not switch between the calibrated and the model's
     * thickness when tracked and animated frames mix */
    if (p->fit) pipe_fit_shape(p->fit, p->pose.world, p->pose.pos[0]);
    if (p->fit && in->locals) {
        pipe_result fr = fit_elbows(p, in, &head, why, why_size);
        if (fr != PIPE_OK) return fr;
    }
    double t1 = now_ms();
    for (int e = 0; e < 2; e++) {
        p->eye[e].in = in;
        p->eye[e].head = head;
    }
    if (p->threaded) {
        int job = post_job(p, JOB_EYE);
        run_eye(p, &p->eye[0]);
        wait_job(p, job);
    } else {
        run_eye(p, &p->eye[0]);
        run_eye(p, &p->eye[1]);
    }
    if (stats) {
        stats->ms_pose = t1 - t0;
        for (int e = 0; e < 2; e++) {
            stats->ms_raster[e] = p->eye[e].ms_raster;
            stats->ms_convert[e] = p->eye[e].ms_convert;
            stats->ms_fuse[e] = p->eye[e].ms_fuse;
            stats->coverage[e] = p->eye[e].coverage;
        }
        stats->ms_total = now_ms() - t0;
    }
    for (int e = 0; e < 2; e++) {
        if (p->eye[e].result != PIPE_OK) {
            if (why && why_size > 0) snprintf(why, (size_t)why_size, "%s", p->eye[e].why);
            return p->eye[e].result;
        }
    }
    p->fit_no_prev = 0;
    return PIPE_OK;
}

void pipe_reset_fit(pipe_ctx *p)
{
    if (!p || !p->fit) return;
    pipe_fit_forget(p->fit);
    p->fit_no_prev = 1;
}

const uint8_t *pipe_mask(const pipe_ctx *p, int eye, int *width, int *height)
{
    if (width) *width = p->geo.crop_width;
    if (height) *height = p->geo.crop_height;
    const eye_state *e = &p->eye[eye ? 1 : 0];
    return e->have_refined ? e->refined : e->mask;
}

kin_camera pipe_camera(const pipe_ctx *p, int eye) { return p->eye[eye ? 1 : 0].cam; }

kin_sthmd_geometry pipe_geometry(const pipe_ctx *p) { return p->geo; }

kin_sthmd_desc pipe_hmd(const pipe_ctx *p) { return p->hmd; }

unsigned pipe_parts_present(const pipe_ctx *p) { return p ? pipe__cockpit_present(p->ck) : 0; }

int pipe_add_prop(pipe_ctx *p, const kin_model *m)
{
    return p ? pipe__cockpit_add_prop(p->ck, m) : -1;
}

int pipe_prop_count(const pipe_ctx *p) { return p ? pipe__cockpit_prop_count(p->ck) : 0; }

int pipe_image_opaque(const fuse_image *im, int x0, int y0, int w, int h)
{
    if (!im || !im->pixels || w < 1 || h < 1 || x0 < 0 || y0 < 0 || x0 > im->width - w ||
        y0 > im->height - h || im->stride < 4 * im->width)
        return 0;
    for (int y = y0; y < y0 + h; y++) {
        const uint8_t *a = im->pixels + (size_t)y * (size_t)im->stride + (size_t)x0 * 4 + 3;
        unsigned all = 255;
        for (int x = 0; x < w; x++) all &= a[(size_t)x * 4];
        if (all != 255) return 0;
    }
    return 1;
}

int pipe_isa(const pipe_ctx *p) { return rast_context_isa(p->eye[0].rast); }

const char *pipe_result_str(pipe_result r)
{
    switch (r) {
    case PIPE_OK: return "ok";
    case PIPE_ERR_ARGS: return "invalid arguments";
    case PIPE_ERR_RASTER: return "rasterizer error";
    case PIPE_ERR_FUSE: return "lighting/composite error";
    }
    return "unknown error";
}

/* ------------------------------------------------------- elbow fit */

#define FIT_DEG2RAD 0.01745329252f
#define FIT_STATIONS 6            /* width stations per segment and eye */
#define FIT_MAX_WALK 160          /* px: longest half width measured */
#define FIT_MIN_SAMPLES 12        /* widths before a thickness is used */
#define FIT_WINDOW_GEOS 14        /* poses checking the points in view: every
                                     30 deg over up to 360 deg, and its end */

struct pipe_fit {
    pipe_fit_desc d;
    const kin_model *model;
    kin_arm_rig rig;
    int width, height;
    int *v[2];                /* fit vertex indices per side */
    uint8_t *use[2];          /* per side, eye-major: 1 = the point is in
                                 view in every candidate of this search */
    int n[2];
    float swivel[2];
    int have_prev;
    float *llr[2];            /* colour model per eye */
    fuse_colour_model cm[2];
    int learned[2];           /* 1: cm[eye] holds a model */
    uint8_t *learn[2];        /* width x height per eye (the eyes may
                                 learn on two threads) */
    void *scratch[2];
    size_t scratch_size;
    /* limb thickness (self-calibration from the masks) */
    int *sv[2];               /* per side: vertices weighted to its arm */
    float *sw[2];             /* per side: 2 weights (upper arm, forearm) */
    int sn[2];
    float thick[2][2];        /* [side][segment]: factor in use */
    float radius[2][2];       /* [side][segment]: the model's mean limb
                                 radius (bind pose), metres */
    float *samples[2][2][2];  /* [eye][side][segment]: measured factors */
    int ns[2][2][2];
    int cap;                  /* capacity of each samples array */
    int done[2][2];           /* [side][segment]: frozen */
    int frozen;               /* all four are */
    float *sort;              /* 2 cap floats: medians */
};

/* Vertices bound (weight >= 0.9) to the upper arm or forearm of a side,
 * at most d.points, evenly picked, and every vertex with any weight on
 * them (for pipe_fit_shape). -1 when a side has none. */
static int fit_vertices(pipe_fit *f)
{
    const kin_mesh *me = &f->model->meshes[0];
    const kin_skin *sk = &f->model->skins[me->skin];
    const int P = f->d.points;
    for (int s = 0; s < 2; s++) {
        int ua = f->rig.joint[s][KIN_RIG_UPPER_ARM], fa = f->rig.joint[s][KIN_RIG_FOREARM];
        int count = 0;
        f->n[s] = 0;
        f->sn[s] = 0;
        for (int pass = 0; pass < 2; pass++) {
            int k = 0;
            for (int v = 0; v < me->vertex_count; v++) {
                float wu = 0.0f, wf = 0.0f;
                for (int j = 0; j < 4; j++) {
                    int node = sk->joints[me->joints[v * 4 + j]];
                    if (node == ua) wu += me->weights[v * 4 + j];
                    if (node == fa) wf += me->weights[v * 4 + j];
                }
                if (pass == 1 && wu + wf > 0.0f) {
                    f->sv[s][f->sn[s]] = v;
                    f->sw[s][2 * f->sn[s]] = wu;
                    f->sw[s][2 * f->sn[s] + 1] = wf;
                    f->sn[s]++;
                }
                if (wu + wf < 0.9f) continue;
                if (pass == 1) {
                    long lo = (long)k * P / count, hi = (long)(k + 1) * P / count;
                    if (hi > lo && f->n[s] < P) f->v[s][f->n[s]++] = v;
                }
                k++;
            }
            if (pass == 0) {
                count = k;
                if (count == 0) return -1;
            }
        }
    }
    return 0;
}

/* The model's mean limb radius per side and segment: the mean distance
 * of the vertices bound to the bone (weight >= 0.9) from its axis segment
 * (bone to child joint) in the bind pose; 0 when there are none. */
static void fit_radii(pipe_fit *f)
{
    const kin_mesh *me = &f->model->meshes[0];
    const kin_skin *sk = &f->model->skins[me->skin];
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            int j0 = f->rig.joint[s][g ? KIN_RIG_FOREARM : KIN_RIG_UPPER_ARM];
            int j1 = f->rig.joint[s][g ? KIN_RIG_HAND : KIN_RIG_FOREARM];
            int k0 = -1, k1 = -1;
            for (int k = 0; k < sk->joint_count; k++) {
                if (sk->joints[k] == j0) k0 = k;
                if (sk->joints[k] == j1) k1 = k;
            }
            f->radius[s][g] = 0.0f;
            kin_mat4 b0, b1;
            if (k0 < 0 || k1 < 0 || !sk->inverse_bind ||
                !kin_mat4_inverse(&sk->inverse_bind[k0], &b0) ||
                !kin_mat4_inverse(&sk->inverse_bind[k1], &b1))
                continue;
            kin_vec3 A = kin_v3(b0.m[12], b0.m[13], b0.m[14]), B = kin_v3(b1.m[12], b1.m[13], b1.m[14]);
            kin_vec3 d = kin_v3_sub(B, A);
            float dd = kin_v3_dot(d, d);
            if (!(dd > 0.0f)) continue;
            double sum = 0.0;
            long n = 0;
            for (int v = 0; v < me->vertex_count; v++) {
                float w = 0.0f;
                for (int j = 0; j < 4; j++)
                    if (me->joints[v * 4 + j] == k0) w += me->weights[v * 4 + j];
                if (w < 0.9f) continue;
                const float *p = &me->positions[(size_t)v * 3];
                kin_vec3 P = kin_v3(p[0], p[1], p[2]);
                float a = kin_v3_dot(kin_v3_sub(P, A), d) / dd;
                a = a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a;
                sum += kin_v3_len(kin_v3_sub(P, kin_v3_add(A, kin_v3_scale(d, a))));
                n++;
            }
            f->radius[s][g] = n ? (float)(sum / (double)n) : 0.0f;
        }
}

/* One setting of pipe_fit_desc: 0 = def, else it must lie in (0, hi] and
 * be >= lo (NaN fails). */
static int fit_setting(float *v, float def, float lo, float hi)
{
    if (*v == 0.0f) {
        *v = def;
        return 1;
    }
    return *v > 0.0f && *v >= lo && *v <= hi;
}

/* The settings with defaults filled in; 0 when one is out of bounds. */
static int fit_settings(pipe_fit_desc *d)
{
    if (!fit_setting(&d->range_deg, 60.0f, 0.0f, PIPE_FIT_MAX_RANGE_DEG) ||
        !fit_setting(&d->step_deg, 5.0f, PIPE_FIT_MIN_STEP_DEG, PIPE_FIT_MAX_STEP_DEG) ||
        !fit_setting(&d->rate_deg, 12.0f, 0.0f, PIPE_FIT_MAX_RANGE_DEG) ||
        !fit_setting(&d->prior, 0.05f, 0.0f, PIPE_FIT_MAX_PRIOR))
        return 0;
    if (d->points == 0) d->points = 400;
    if (d->shape_samples == 0) d->shape_samples = 48;
    return d->points >= 1 && d->points <= PIPE_FIT_MAX_POINTS &&
           d->shape_samples <= PIPE_FIT_MAX_SHAPE_SAMPLES;
}

/* 1 when mesh 0 is skinned by one of the model's skins, whose joints are
 * nodes, and every joint index of its vertices names one of them. */
static int fit_mesh_ok(const kin_model *m)
{
    const kin_mesh *me = &m->meshes[0];
    if (me->skin < 0 || me->skin >= m->skin_count || !me->joints || !me->weights ||
        !me->positions || me->vertex_count < 1)
        return 0;
    const kin_skin *sk = &m->skins[me->skin];
    if (sk->joint_count < 1 || !sk->joints) return 0;
    for (int k = 0; k < sk->joint_count; k++)
        if (sk->joints[k] < 0 || sk->joints[k] >= m->node_count) return 0;
    for (size_t i = 0; i < 4 * (size_t)me->vertex_count; i++)
        if (me->joints[i] >= sk->joint_count) return 0;
    return 1;
}

/* 1 when node a is a proper ancestor of node d. */
static int fit_ancestor(const kin_model *m, int a, int d)
{
    for (int k = 0, n = d; k < m->node_count; k++) {
        n = m->parents[n];
        if (n < 0 || n >= m->node_count) return 0;
        if (n == a) return 1;
    }
    return 0;
}

/* 1 when each side's upper arm, forearm and hand are nodes, each a proper
 * descendant of the one before: turning the upper arm then moves the
 * forearm and the hand, and the hand's correction (fit_apply) is taken in
 * its parent's frame, whichever node that is. */
static int fit_rig_ok(const kin_model *m, const kin_arm_rig *rig)
{
    if (!m->parents) return 0;
    for (int s = 0; s < 2; s++) {
        const int j[3] = { rig->joint[s][KIN_RIG_UPPER_ARM], rig->joint[s][KIN_RIG_FOREARM],
                           rig->joint[s][KIN_RIG_HAND] };
        for (int k = 0; k < 3; k++)
            if (j[k] < 0 || j[k] >= m->node_count) return 0;
        if (!fit_ancestor(m, j[0], j[1]) || !fit_ancestor(m, j[1], j[2])) return 0;
    }
    /* the arms apart: two chains that share a node (or one hanging below
     * the other's upper arm) have one upper arm at or below the other's,
     * and would turn and thicken the same limb twice */
    const int a = rig->joint[0][KIN_RIG_UPPER_ARM], b = rig->joint[1][KIN_RIG_UPPER_ARM];
    return a != b && !fit_ancestor(m, a, b) && !fit_ancestor(m, b, a);
}

pipe_fit *pipe_fit_create(const pipe_fit_desc *desc, const kin_model *model,
                          const kin_arm_rig *rig, int width, int height)
{
    if (!model || !rig || width < 1 || height < 1 || model->mesh_count < 1 ||
        !model->meshes || !model->skins || !fit_mesh_ok(model) || !fit_rig_ok(model, rig))
        return NULL;
    pipe_fit_desc d = {0};
    if (desc) d = *desc;
    if (!fit_settings(&d)) return NULL;
    pipe_fit *f = calloc(1, sizeof *f);
    if (!f) return NULL;
    f->d = d;
    f->model = model;
    f->rig = *rig;
    f->width = width;
    f->height = height;
    f->scratch_size = fuse_colour_model_scratch_size(PIPE_FIT_BITS);
    const size_t nv = (size_t)model->meshes[0].vertex_count;
    f->cap = f->d.shape_samples > 0 ? f->d.shape_samples : 1;
    f->sort = malloc(sizeof(float) * 2 * (size_t)f->cap);
    int ok = f->sort != NULL;
    for (int e = 0; e < 2; e++) {
        f->llr[e] = calloc((size_t)1 << (3 * PIPE_FIT_BITS), sizeof(float));
        f->cm[e] = (fuse_colour_model){ PIPE_FIT_BITS, 0, 0, f->llr[e] };
        f->v[e] = malloc(sizeof(int) * (size_t)f->d.points);
        f->use[e] = malloc(2 * (size_t)f->d.points);
        f->sv[e] = malloc(sizeof(int) * nv);
        f->sw[e] = malloc(sizeof(float) * 2 * nv);
        f->scratch[e] = malloc(f->scratch_size);
        f->learn[e] = malloc((size_t)width * (size_t)height);
        ok = ok && f->llr[e] && f->v[e] && f->use[e] && f->sv[e] && f->sw[e] && f->scratch[e] && f->learn[e];
        for (int s = 0; s < 2; s++)
            for (int g = 0; g < 2; g++) {
                f->samples[e][s][g] = malloc(sizeof(float) * (size_t)f->cap);
                ok = ok && f->samples[e][s][g];
            }
    }
    if (!ok || fit_vertices(f) < 0) {
        pipe_fit_destroy(f);
        return NULL;
    }
    fit_radii(f);
    pipe_fit_reset(f);
    pipe_fit_reset_shape(f);
    return f;
}

void pipe_fit_destroy(pipe_fit *f)
{
    if (!f) return;
    for (int e = 0; e < 2; e++) {
        free(f->llr[e]);
        free(f->v[e]);
        free(f->use[e]);
        free(f->sv[e]);
        free(f->sw[e]);
        free(f->scratch[e]);
        free(f->learn[e]);
        for (int s = 0; s < 2; s++)
            for (int g = 0; g < 2; g++) free(f->samples[e][s][g]);
    }
    free(f->sort);
    free(f);
}

void pipe_fit_reset(pipe_fit *f)
{
    if (!f) return;
    f->have_prev = 0;
    f->swivel[0] = f->swivel[1] = 0.0f;
}

void pipe_fit_reset_shape(pipe_fit *f)
{
    if (!f) return;
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            f->thick[s][g] = 1.0f;
            f->ns[0][s][g] = f->ns[1][s][g] = 0;
            f->done[s][g] = f->d.shape_samples < 0;
        }
    f->frozen = f->d.shape_samples < 0;
}

void pipe_fit_forget(pipe_fit *f)
{
    if (!f) return;
    pipe_fit_reset(f);
    pipe_fit_reset_shape(f);
    for (int e = 0; e < 2; e++) {
        f->learned[e] = 0;
        f->cm[e].fg_samples = f->cm[e].bg_samples = 0;
        memset(f->llr[e], 0, sizeof(float) << (3 * PIPE_FIT_BITS));
    }
}

const fuse_colour_model *pipe_fit_colour(const pipe_fit *f, int eye)
{
    return f ? &f->cm[eye ? 1 : 0] : NULL;
}

int pipe_fit_learned(const pipe_fit *f, int eye)
{
    return f ? f->learned[eye ? 1 : 0] : 0;
}

fuse_result pipe_fit_learn(pipe_fit *f, int eye, const fuse_image *P, const uint8_t *mask,
                           int mask_stride, const uint8_t *prev, int prev_stride)
{
    if (!f || !P || !P->pixels || !mask || eye < 0 || eye > 1 || P->width != f->width ||
        P->height != f->height || mask_stride < f->width || (prev && prev_stride < f->width))
        return FUSE_ERR_ARGS;
    const uint8_t *learn = f->learn[eye];
    const int stride = f->width;
    if (!prev) {
        /* inside = >= 128: 255 or 0 (fuse_colour_model_learn leaves any
         * other value out) */
        for (int y = 0; y < f->height; y++) {
            const uint8_t *a = mask + (size_t)y * (size_t)mask_stride;
            uint8_t *L = f->learn[eye] + (size_t)y * (size_t)f->width;
            for (int x = 0; x < f->width; x++) L[x] = (uint8_t)(0u - (unsigned)(a[x] >> 7));
        }
    } else {
        /* 255 where both hold the pixel, 0 where neither does, else 128
         * (branch-free, so that the compiler vectorises the rows) */
        for (int y = 0; y < f->height; y++) {
            const uint8_t *a = mask + (size_t)y * (size_t)mask_stride;
            const uint8_t *b = prev + (size_t)y * (size_t)prev_stride;
            uint8_t *L = f->learn[eye] + (size_t)y * (size_t)f->width;
            for (int x = 0; x < f->width; x++) {
                unsigned ia = a[x] >> 7, ib = b[x] >> 7;
                L[x] = (uint8_t)(128u + 127u * (ia & ib) - 128u * ((ia | ib) ^ 1u));
            }
        }
    }
    fuse_result r = fuse_colour_model_learn(&f->cm[eye], P, learn, stride, 4, 2, 3.0f, 64,
                                            f->scratch[eye], f->scratch_size);
    if (r != FUSE_OK) return r;
    f->learned[eye] = f->cm[eye].fg_samples >= 64 && f->cm[eye].bg_samples >= 64;
    return FUSE_OK;
}

static kin_vec3 fit_node_pos(const kin_mat4 *m) { return kin_v3(m->m[12], m->m[13], m->m[14]); }

static kin_quat fit_node_rot(const kin_mat4 *m)
{
    kin_vec3 x = kin_v3_norm(kin_v3(m->m[0], m->m[1], m->m[2]));
    kin_vec3 y = kin_v3_norm(kin_v3(m->m[4], m->m[5], m->m[6]));
    kin_vec3 z = kin_v3_norm(kin_v3_cross(x, y));
    y = kin_v3_cross(z, x);
    return kin_quat_normalize(kin_quat_from_axes(x, y, z));
}

/* Swivel phi of side s's arm: its points turned about the
 * shoulder-wrist line through S (unit u). */
typedef struct fit_geo {
    kin_vec3 S;
    float R[9];               /* row-major rotation */
} fit_geo;

static void fit_geo_of(kin_vec3 S, kin_vec3 u, float phi, fit_geo *g)
{
    kin_quat q = kin_quat_axis_angle(u, phi);
    kin_vec3 ex = kin_quat_rotate(q, kin_v3(1, 0, 0)), ey = kin_quat_rotate(q, kin_v3(0, 1, 0)),
             ez = kin_quat_rotate(q, kin_v3(0, 0, 1));
    const float R[9] = { ex.x, ey.x, ez.x, ex.y, ey.y, ez.y, ex.z, ey.z, ez.z };
    memcpy(g->R, R, sizeof R);
    g->S = S;
}

/* Pixel of fit point i of side s moved by g, seen by eye e; 0 when it
 * falls outside the image or behind the camera. */
static int fit_pixel(const pipe_fit *f, int s, int i, const float *pos, const fit_geo *g,
                     const kin_camera *cam, int *px, int *py)
{
    const float *M = cam->view_proj.m;
    const float *p = &pos[(size_t)f->v[s][i] * 3], *R = g->R;
    const float dx = p[0] - g->S.x, dy = p[1] - g->S.y, dz = p[2] - g->S.z;
    kin_vec3 r = kin_v3(g->S.x + R[0] * dx + R[1] * dy + R[2] * dz,
                        g->S.y + R[3] * dx + R[4] * dy + R[5] * dz,
                        g->S.z + R[6] * dx + R[7] * dy + R[8] * dz);
    float w = M[3] * r.x + M[7] * r.y + M[11] * r.z + M[15];
    if (!(w > 1e-3f)) return 0;
    float x = (M[0] * r.x + M[4] * r.y + M[8] * r.z + M[12]) / w;
    float y = (M[1] * r.x + M[5] * r.y + M[9] * r.z + M[13]) / w;
    float fx = (x * 0.5f + 0.5f) * (float)f->width, fy = (0.5f - y * 0.5f) * (float)f->height;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)f->width && fy < (float)f->height)) return 0;
    *px = (int)fx;
    *py = (int)fy;
    return 1;
}

/* The points of side s that are in view of each eye in all n candidate
 * poses g (f->use[s]); returns their number. Only they are scored: a
 * point that leaves the image for some candidate is unknown there, and
 * scoring it in the others would favour or penalise candidates by what
 * leaves the view (dropping it where unseen, i.e. scoring it 0 there,
 * rewards pushing the arm out of view wherever the visible part scores
 * below 0; scoring it as an average arm pixel rewards it wherever the
 * visible part scores below that). */
static int fit_common(pipe_fit *f, int s, const float *pos, const fit_geo *g, int n,
                      const kin_camera cam[2])
{
    int count = 0;
    for (int e = 0; e < 2; e++)
        for (int i = 0; i < f->n[s]; i++) {
            int ok = 1, px, py;
            for (int k = 0; k < n && ok; k++) ok = fit_pixel(f, s, i, pos, &g[k], &cam[e], &px, &py);
            f->use[s][e * f->n[s] + i] = (uint8_t)ok;
            count += ok;
        }
    return count;
}

/* Colour score of side s's arm moved by g: the sum over both eyes of the
 * ratio at the pixel of each point in use (fit_common); a point that
 * still falls outside scores 0. */
static float fit_score(const pipe_fit *f, int s, const float *pos, const fit_geo *g,
                       const kin_camera cam[2], const fuse_image P[2])
{
    float score = 0.0f;
    for (int e = 0; e < 2; e++) {
        const float *llr = f->llr[e];
        const uint8_t *use = &f->use[s][e * f->n[s]];
        for (int i = 0; i < f->n[s]; i++) {
            int px, py;
            if (!use[i] || !fit_pixel(f, s, i, pos, g, &cam[e], &px, &py)) continue;
            const uint8_t *rgb = P[e].pixels + (size_t)py * (size_t)P[e].stride + (size_t)px * 4;
            score += llr[fuse_colour_bin(rgb, PIPE_FIT_BITS)];
        }
    }
    return score;
}

/* Turns the arm of side s by phi about its shoulder-wrist line in locals
 * (world = FK of locals; the hand keeps its world rotation). Turning the
 * upper arm's local by phi about u turns every node below it, the hand's
 * parent hp included, by phi about u in world space; the hand's local
 * then turns by -phi about u seen in hp's frame (the forearm, or a wrist
 * or twist node between them: pipe_fit_create checked the chain). */
static void fit_apply(const pipe_fit *f, const kin_mat4 *world, int s, float phi,
                      kin_transform *locals)
{
    const kin_model *m = f->model;
    int ua = f->rig.joint[s][KIN_RIG_UPPER_ARM], hd = f->rig.joint[s][KIN_RIG_HAND];
    kin_vec3 u = kin_v3_norm(kin_v3_sub(fit_node_pos(&world[hd]), fit_node_pos(&world[ua])));
    int par = m->parents[ua], hp = m->parents[hd];
    kin_quat qp = par >= 0 ? fit_node_rot(&world[par]) : kin_quat_identity();
    kin_quat qf = fit_node_rot(&world[hp]);
    kin_vec3 ap = kin_quat_rotate(kin_quat_conjugate(qp), u);
    kin_vec3 af = kin_quat_rotate(kin_quat_conjugate(qf), u);
    locals[ua].r = kin_quat_normalize(kin_quat_mul(kin_quat_axis_angle(ap, phi), locals[ua].r));
    locals[hd].r = kin_quat_normalize(kin_quat_mul(kin_quat_axis_angle(af, -phi), locals[hd].r));
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* The thickness factors from the widths measured so far: per side and
 * segment the median over both eyes once there are FIT_MIN_SAMPLES of
 * them; a segment is frozen once it has shape_samples (each eye keeps at
 * most that many: the eyes measure on their own threads), and measuring
 * stops when all four are. Runs while no eye measures. */
static void fit_update_shape(pipe_fit *f)
{
    if (f->frozen) return;
    int done = 0;
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            if (f->done[s][g]) { done++; continue; }
            int n = 0;
            for (int e = 0; e < 2; e++) {
                memcpy(f->sort + n, f->samples[e][s][g], sizeof(float) * (size_t)f->ns[e][s][g]);
                n += f->ns[e][s][g];
            }
            if (n < FIT_MIN_SAMPLES) continue;
            qsort(f->sort, (size_t)n, sizeof(float), cmp_float);
            f->thick[s][g] = n & 1 ? f->sort[n / 2] : 0.5f * (f->sort[n / 2 - 1] + f->sort[n / 2]);
            if (n >= f->d.shape_samples) {
                f->done[s][g] = 1;
                done++;
            }
        }
    f->frozen = done == 4;
}

void pipe_fit_elbows(pipe_fit *f, const kin_mat4 *world, const float *pos,
                     const kin_camera cam[2], const fuse_image P[2], unsigned sides,
                     kin_transform *locals, float swivel[2])
{
    const float D = FIT_DEG2RAD;
    float best[2];
    for (int s = 0; s < 2; s++) {
        int ua = f->rig.joint[s][KIN_RIG_UPPER_ARM], hd = f->rig.joint[s][KIN_RIG_HAND];
        kin_vec3 S = fit_node_pos(&world[ua]);
        kin_vec3 u = kin_v3_norm(kin_v3_sub(fit_node_pos(&world[hd]), S));
        const float range = f->d.range_deg * D, rate = f->d.rate_deg * D;
        float p0 = f->have_prev ? f->swivel[s] : 0.0f;
        float lo = f->have_prev ? p0 - rate : -range, hi = f->have_prev ? p0 + rate : range;
        if (lo < -range) lo = -range;
        if (hi > range) hi = range;
        float bphi = p0 < lo ? lo : p0 > hi ? hi : p0;
        const float pk = f->d.prior * 2.0f * (float)f->n[s] / (30.0f * 30.0f * D * D);
        /* the points in view over the whole window: at its ends and every
         * 30 degrees between (the projections move smoothly with phi) */
        fit_geo gw[FIT_WINDOW_GEOS];
        int nw = 0;
        for (float phi = lo; nw < FIT_WINDOW_GEOS - 1 && phi < hi; phi += 30.0f * D)
            fit_geo_of(S, u, phi, &gw[nw++]);
        fit_geo_of(S, u, hi, &gw[nw++]);
        fit_common(f, s, pos, gw, nw, cam);
        fit_geo g;
        fit_geo_of(S, u, bphi, &g);
        float bsc = fit_score(f, s, pos, &g, cam, P) - pk * bphi * bphi;
        for (int pass = 0; pass < 2; pass++) {
            float step = (pass ? 1.0f : f->d.step_deg) * D;
            float lo2 = pass ? bphi - 0.5f * f->d.step_deg * D : lo;
            float hi2 = pass ? bphi + 0.5f * f->d.step_deg * D : hi;
            /* The candidates of phi += step (bit for bit those of the
             * first version: `egofuse eval` and render --refine keep their
             * bytes), bounded by an index: phi += step alone never ended
             * for a step too small to move phi; with the desc's bounds
             * (step >= 0.1 deg) every addition moves it and at most
             * 2 * 180 / 0.1 + 2 candidates run. */
            const float span = (hi2 + 1e-6f - lo2) / step;
            const int nc = span >= 0.0f && span < 8192.0f ? (int)span + 1 : -1;
            float phi = lo2;
            for (int i = 0; i <= nc && phi <= hi2 + 1e-6f; i++, phi += step) {
                if (phi < lo || phi > hi) continue;
                fit_geo_of(S, u, phi, &g);
                float sc = fit_score(f, s, pos, &g, cam, P) - pk * phi * phi;
                if (sc > bsc) { bsc = sc; bphi = phi; }
            }
        }
        best[s] = bphi;
    }
    for (int s = 0; s < 2; s++) {
        if (!(sides & (1u << s))) continue;
        fit_apply(f, world, s, best[s], locals);
        f->swivel[s] = best[s];
    }
    f->have_prev = 1;
    fit_update_shape(f);
    if (swivel) {
        swivel[0] = best[0];
        swivel[1] = best[1];
    }
}

/* ------------------------------------------- limb thickness */

/* Pixel position of world point p through cam (width x height image);
 * 0 when behind the camera. */
static int fit_project(const kin_camera *cam, int W, int H, kin_vec3 p, float *x, float *y)
{
    const float *M = cam->view_proj.m;
    float w = M[3] * p.x + M[7] * p.y + M[11] * p.z + M[15];
    if (!(w > 1e-3f)) return 0;
    *x = ((M[0] * p.x + M[4] * p.y + M[8] * p.z + M[12]) / w * 0.5f + 0.5f) * (float)W;
    *y = (0.5f - (M[1] * p.x + M[5] * p.y + M[9] * p.z + M[13]) / w * 0.5f) * (float)H;
    return 1;
}

/* Steps from (x, y) along (dx, dy) while m is inside (>= 128); the
 * number of inside steps, or -1 when the walk reaches the image's
 * border or FIT_MAX_WALK (the edge is not seen). */
static int fit_walk(const uint8_t *m, int stride, int W, int H, float x, float y, float dx,
                    float dy)
{
    for (int k = 1; k <= FIT_MAX_WALK; k++) {
        float fx = x + dx * (float)k, fy = y + dy * (float)k;
        if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)W && fy < (float)H)) return -1;
        if (m[(size_t)(int)fy * (size_t)stride + (size_t)(int)fx] < 128) return k - 1;
    }
    return -1;
}

void pipe_fit_measure(pipe_fit *f, int eye, const kin_camera *cam, const kin_mat4 *world,
                      const uint8_t *mask, int mask_stride, const uint8_t *refined,
                      int refined_stride)
{
    if (!f || eye < 0 || eye > 1 || !cam || !world || !mask || !refined || f->frozen ||
        mask_stride < f->width || refined_stride < f->width)
        return;
    const int W = f->width, H = f->height;
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            if (f->done[s][g]) continue;
            int j0 = f->rig.joint[s][g ? KIN_RIG_FOREARM : KIN_RIG_UPPER_ARM];
            int j1 = f->rig.joint[s][g ? KIN_RIG_HAND : KIN_RIG_FOREARM];
            kin_vec3 A = fit_node_pos(&world[j0]), B = fit_node_pos(&world[j1]);
            float ax, ay, bx, by;
            if (!fit_project(cam, W, H, A, &ax, &ay) || !fit_project(cam, W, H, B, &bx, &by))
                continue;
            float len = sqrtf((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
            if (len < 16.0f) continue;        /* seen end-on: no direction */
            float nx = -(by - ay) / len, ny = (bx - ax) / len;
            /* stations on the projected axis, over the part of its
             * [0.2, 0.9] (away from the joints where the limbs blend)
             * that is in view 8 px in from the borders; none when less
             * than 12 px of it is */
            float t0 = 0.2f, t1 = 0.9f;
            const float lim[2][2] = { { 8.0f, (float)W - 8.0f }, { 8.0f, (float)H - 8.0f } };
            const float a2[2] = { ax, ay }, d2[2] = { bx - ax, by - ay };
            for (int c = 0; c < 2 && t0 < t1; c++) {
                if (d2[c] == 0.0f) {
                    if (a2[c] < lim[c][0] || a2[c] > lim[c][1]) t1 = t0;
                    continue;
                }
                float u0 = (lim[c][0] - a2[c]) / d2[c], u1 = (lim[c][1] - a2[c]) / d2[c];
                if (u0 > u1) { float tmp = u0; u0 = u1; u1 = tmp; }
                if (u0 > t0) t0 = u0;
                if (u1 < t1) t1 = u1;
            }
            if ((t1 - t0) * len < 12.0f) continue;
            for (int k = 0; k < FIT_STATIONS; k++) {
                if (f->ns[eye][s][g] >= f->cap) break;
                float t = t0 + (t1 - t0) * ((float)k + 0.5f) / (float)FIT_STATIONS;
                float qx = ax + t * (bx - ax), qy = ay + t * (by - ay);
                if (!(qx >= 0.0f && qy >= 0.0f && qx < (float)W && qy < (float)H)) continue;
                size_t o = (size_t)(int)qy;
                if (mask[o * (size_t)mask_stride + (size_t)(int)qx] < 128 ||
                    refined[o * (size_t)refined_stride + (size_t)(int)qx] < 128)
                    continue;
                int k0 = fit_walk(mask, mask_stride, W, H, qx, qy, nx, ny);
                int k1 = fit_walk(mask, mask_stride, W, H, qx, qy, -nx, -ny);
                int r0 = fit_walk(refined, refined_stride, W, H, qx, qy, nx, ny);
                int r1 = fit_walk(refined, refined_stride, W, H, qx, qy, -nx, -ny);
                if (k0 < 0 || k1 < 0 || r0 < 0 || r1 < 0 || k0 + k1 < 6) continue;
                /* the kinematic width must be the limb's own: the model's
                 * radius (times the factor in use) projected at the
                 * station's depth, within 0.7-1.4x; wider walks ran into
                 * a hand or the other arm in front of or behind it */
                kin_vec3 Q = kin_v3_add(A, kin_v3_scale(kin_v3_sub(B, A), t));
                float z = -kin_mat4_mul_point(&cam->view, Q).z;
                if (!(z > 1e-3f) || !(f->radius[s][g] > 0.0f)) continue;
                float expect = 2.0f * f->radius[s][g] * f->thick[s][g] * cam->fx / z;
                float kw = (float)(k0 + k1 + 1);
                if (kw < 0.7f * expect || kw > 1.4f * expect) continue;
                /* only thinner counts: a refined mask narrower than the
                 * model's took pixels that look like background, a wider
                 * one may have taken a skin-coloured object beside the
                 * arm (egofuse eval's cross: the desk pad made a forearm
                 * 1.48x, IoU 0.893 -> 0.845). Clamped, not dropped, so
                 * that the median stays unbiased for a limb that fits. */
                float sample = f->thick[s][g] * (float)(r0 + r1 + 1) / kw;
                if (sample < 0.6f) continue;
                f->samples[eye][s][g][f->ns[eye][s][g]++] = sample < 1.0f ? sample : 1.0f;
            }
        }
}

void pipe_fit_shape(const pipe_fit *f, const kin_mat4 *world, float *pos)
{
    if (!f || !world || !pos) return;
    for (int s = 0; s < 2; s++) {
        float t0 = f->thick[s][0] - 1.0f, t1 = f->thick[s][1] - 1.0f;
        if (t0 == 0.0f && t1 == 0.0f) continue;
        kin_vec3 J[3];
        J[0] = fit_node_pos(&world[f->rig.joint[s][KIN_RIG_UPPER_ARM]]);
        J[1] = fit_node_pos(&world[f->rig.joint[s][KIN_RIG_FOREARM]]);
        J[2] = fit_node_pos(&world[f->rig.joint[s][KIN_RIG_HAND]]);
        kin_vec3 d[2] = { kin_v3_sub(J[1], J[0]), kin_v3_sub(J[2], J[1]) };
        float dd[2] = { kin_v3_dot(d[0], d[0]), kin_v3_dot(d[1], d[1]) };
        const float tk[2] = { t0, t1 };
        for (int i = 0; i < f->sn[s]; i++) {
            float *p = &pos[(size_t)f->sv[s][i] * 3];
            kin_vec3 P0 = kin_v3(p[0], p[1], p[2]), P1 = P0;
            for (int g = 0; g < 2; g++) {
                float w = f->sw[s][2 * i + g];
                if (w == 0.0f || tk[g] == 0.0f || !(dd[g] > 0.0f)) continue;
                /* radially away from the closest point of the bone */
                float a = kin_v3_dot(kin_v3_sub(P0, J[g]), d[g]) / dd[g];
                a = a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a;
                kin_vec3 c = kin_v3_add(J[g], kin_v3_scale(d[g], a));
                P1 = kin_v3_add(P1, kin_v3_scale(kin_v3_sub(P0, c), w * tk[g]));
            }
            p[0] = P1.x;
            p[1] = P1.y;
            p[2] = P1.z;
        }
    }
}

void pipe_fit_thickness(const pipe_fit *f, float thick[2][2], int *frozen)
{
    if (thick)
        for (int s = 0; s < 2; s++)
            for (int g = 0; g < 2; g++) thick[s][g] = f ? f->thick[s][g] : 1.0f;
    if (frozen) *frozen = f ? f->frozen : 0;
}
