/* eval.c - the frames of the accuracy evaluation (see eval.h): the shared
 * context, the ground truth of each frame, and each method configuration's
 * run of it (eval__run_batch). Which configurations, in which batches, and
 * the summaries: eval_plan.c.
 *
 * Per display frame (60 Hz): the true operator is posed and rendered into
 * both camera images over the cockpit (with its exact silhouettes and the
 * ideal composite); then every method configuration, with its own tracking
 * stream (noise, latency, dropouts) and its own state (filter, last
 * sample, previous masks, elbow fit), makes its masks and composites, which
 * are timed and measured. A report runs several such batches (methods,
 * knobs, tracking sweeps, other sequences), each on its own ground truth. */
#include "eval_internal.h"
#include "../io/io.h"
#include "../io/io_term.h"
#include "../io/io_lod.h"
#include "../fit/fit_band.h"
#include "../fit/fit_holes.h"
#include "../fit/fit_narrow.h"
#include "../fit/fit_shift.h"
#include "../fit/fit_smooth.h"
#include "../cpu/ef_mem.h"

/* The ground truth comes from samples/gt/ and the sample generator
 * (samples/gen/), linked into the program as build/libegofuse_samples.a. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* ------------------------------------------------------------ lighting */

static fuse_lighting workshop_lighting(const gen_scene *ws, const kin_camera *cam)
{
    fuse_lighting L = fuse_lighting_default();
    L.light_count = ws->light_count < FUSE_MAX_LIGHTS ? ws->light_count : FUSE_MAX_LIGHTS;
    for (int i = 0; i < 3; i++) L.ambient[i] = ws->ambient[i];
    L.kd = 0.80f;
    L.ks = 0.12f;
    L.shininess = 20.0f;
    L.kf = 0.0f;   /* the samples' (gen_main.c): the best against the opaque ideal (eval_kf.c) */
    L.tone[0] = 1.0f;
    L.tone[1] = 0.98f;
    L.tone[2] = 0.96f;
    for (int i = 0; i < L.light_count; i++) {
        kin_vec3 d = kin_v3_norm(kin_mat4_mul_dir(
            &cam->view, kin_v3(ws->light_dir[i][0], ws->light_dir[i][1], ws->light_dir[i][2])));
        L.lights[i].dir[0] = d.x;
        L.lights[i].dir[1] = d.y;
        L.lights[i].dir[2] = d.z;
        for (int k = 0; k < 3; k++) L.lights[i].color[k] = ws->light_color[i][k];
    }
    return L;
}

/* ----------------------------------------------------------- elbow fit */

/* The refine method fits the elbows to the images with the library's
 * pipe_fit (src/pipe/pipe.h: the swivel of each arm about its
 * shoulder-wrist line whose surface falls on the most arm-coloured
 * pixels), the same code as `egofuse render/run --refine`. */
#define DEG2RAD 0.01745329252f

/* ------------------------------------------------------------- set-up */

void eval__ctx_free(eval_ctx *c)
{
    eval__lod_free(c); /* before the model it points into */
    gen_frame_ctx_free(&c->gctx);
    gen_arms_free(&c->truth);
    gen_arms_free(&c->mask_fine);
    gen_arms_free(&c->mask);
    gen_scene_free(&c->cockpit);
    gen_scene_free(&c->workshop);
    eval__pose_free(&c->ps);
    free(c->dq); free(c->vdepth); free(c->vrgb);
    for (int e = 0; e < 2; e++) {
        free(c->P[e]); free(c->sil[e]); free(c->sil_prev[e]); free(c->tnrm[e]); free(c->V[e]); free(c->ideal[e]);
    }
    free(c->aa_samples);
    free(c->mask_lo); free(c->mask_up); free(c->refined); free(c->mask_prior); free(c->mask_shift); free(c->mask_smooth); free(c->layer); free(c->out);
    free(c->depth_lo); free(c->nrm_lo); free(c->mnrm);
    free(c->refine_scratch);
    free(c->stereo_scratch);
    rast_context_destroy(c->rast);
    memset(c, 0, sizeof *c);
}

/* The user calibration as a cockpit would make it: the true operator
 * stretches the arms forward and sideways, then presses the middle
 * fingertips of both hands together (gt sequence "calib", 7.7 s), the
 * tracker records it (noise, dropouts) and kin_user_calib_estimate_tips
 * turns it into scales: the hands' from the gesture and the mask model's
 * fingertips (kin_user_calib_hand_tips), never from the truth's. */
static int estimate_calib(eval_ctx *c, const gt_track_desc *track)
{
    gen_arms cal = c->truth;
    if (gt_sequence_build(&c->mask, "calib", &cal) < 0) return -1;
    c->truth.model.block = cal.model.block;   /* the same block, maybe moved */
    int n = (int)(cal.model.anims[0].duration * track->rate_hz) + 1;
    kin_track_sample *S = malloc(sizeof *S * (size_t)n);
    float *scratch = malloc(sizeof(float) * (size_t)n);
    int rc = -1;
    kin_vec3 tips[2];
    if (S && scratch) {
        for (int k = 0; k < n; k++)
            gt_track_sample(&cal, track, k, c->ps.tlocals, c->ps.tworld, &S[k]);
        int have_tips = kin_user_calib_hand_tips(&c->rig, &c->mask.model, tips, c->calib_why,
                                                 sizeof c->calib_why) == 0;
        rc = kin_user_calib_estimate_tips(S, n, &c->rig, have_tips ? tips : NULL, scratch,
                                          &c->calib, c->calib_why, sizeof c->calib_why);
        c->calib_hand_fallback = rc == 1;
        if (rc == 1) rc = 0;
    }
    free(S);
    free(scratch);
    return rc;
}

static int ctx_init(eval_ctx *c, uint64_t seed, const char *sequence, const gt_track_desc *track)
{
    memset(c, 0, sizeof *c);
    c->g = kin_sthmd_geometry_of(NULL);
    c->op = gt_operator_default();
    gt_operator_desc same = { 1, 1, 1, 1, 1, 1, 1, 1 };
    if (gen_arms_build(&c->mask) < 0 || gt_truth_build(&c->mask, &c->op, &c->truth) < 0 ||
        gt_truth_build(&c->mask, &same, &c->mask_fine) < 0 ||
        gt_cockpit_build(&c->cockpit) < 0 || gen_scene_workshop(&c->workshop, &c->mask) < 0 ||
        gen_frame_ctx_init(&c->gctx, &c->truth, &c->cockpit, &c->workshop, seed) < 0)
        return -1;
    char why[256];
    if (kin_arm_rig_init(&c->rig, &c->mask.model, why, sizeof why) < 0) {
        io_term_fail("mask model: %s", why);
        return -1;
    }
    const kin_model *m = &c->mask.model;
    size_t J = (size_t)m->skins[0].joint_count;
    const size_t cp = (size_t)CW * CH, vp = (size_t)GEN_VIRT_W * GEN_VIRT_H;
    int ok = eval__pose_init(&c->ps, m, c->mask_fine.model.meshes[0].vertex_count) == 0;
    c->dq = malloc(sizeof *c->dq * J);
    c->vdepth = malloc(sizeof(float) * vp);
    c->vrgb = malloc(vp * 3);
    ok = ok && c->dq && c->vdepth && c->vrgb;
    for (int e = 0; e < 2 && ok; e++) {
        c->P[e] = malloc(cp * 4);
        c->sil[e] = malloc(cp);
        c->sil_prev[e] = malloc(cp);
        c->tnrm[e] = malloc(sizeof(float) * 3 * cp);
        c->V[e] = malloc(vp * 4);
        c->ideal[e] = malloc(vp * 4);
        ok = c->P[e] && c->sil[e] && c->sil_prev[e] && c->tnrm[e] && c->V[e] && c->ideal[e];
    }
    c->mask_lo = malloc(cp);
    c->aa_samples = malloc(sizeof(uint32_t) * cp);
    c->mask_up = malloc(cp);
    c->refined = malloc(cp);
    c->mask_prior = malloc(cp);
    c->mask_shift = malloc(cp);
    c->mask_smooth = malloc(cp);
    c->layer = malloc(cp * 4);
    c->out = malloc(vp * 4);
    c->depth_lo = malloc(sizeof(float) * cp);
    c->nrm_lo = malloc(sizeof(float) * 3 * cp);
    c->mnrm = malloc(sizeof(float) * 3 * cp);
    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = 64;
    rp.margin = 64;
    c->refine_scratch_size = fuse_refine_scratch_size(&rp, CW, CH);
    if (pipe_fit_fill_scratch_size(CW, CH) > c->refine_scratch_size)   /* shared (as pipe_frame) */
        c->refine_scratch_size = pipe_fit_fill_scratch_size(CW, CH);
    if (pipe_fit_smooth_scratch_size(CW, CH) > c->refine_scratch_size)
        c->refine_scratch_size = pipe_fit_smooth_scratch_size(CW, CH);
    if (pipe_fit_shift_scratch_size(CW, CH) > c->refine_scratch_size)
        c->refine_scratch_size = pipe_fit_shift_scratch_size(CW, CH);
    c->refine_scratch = aligned_alloc(16, (c->refine_scratch_size + 15) & ~(size_t)15);
    c->stereo_scratch_size = pipe_fit_stereo_scratch_size(CW, CH);
    c->stereo_scratch = aligned_alloc(16, (c->stereo_scratch_size + 15) & ~(size_t)15);
    const rast_context_desc rd = {0, 1};
    c->rast = rast_context_create(&rd);
    ok = ok && c->rast && c->aa_samples && c->mask_lo && c->mask_up && c->refined && 
         c->mask_prior && c->mask_shift && c->mask_smooth && c->layer && c->out && c->depth_lo &&
         c->nrm_lo && c->mnrm && c->refine_scratch && c->stereo_scratch;
    if (!ok) return -1;
    if (estimate_calib(c, track) < 0) {
        io_term_fail("user calibration from the calibration motion: %s", c->calib_why);
        return -2;
    }
    if (gt_sequence_build(&c->mask, sequence, &c->truth) < 0) return -1;
    return 0;
}

/* ------------------------------------------------------- ground truth */

static int make_truth(eval_ctx *c, int frame, float speed, int first)
{
    c->have_sil_prev = !first;
    for (int e = 0; e < 2; e++) {
        uint8_t *tmp = c->sil_prev[e];
        c->sil_prev[e] = c->sil[e];
        c->sil[e] = tmp;
    }
    float t = (float)frame / (float)GEN_FPS * speed;
    kin_mat4 wfh;
    gen_pose(&c->gctx, t, &wfh);
    for (int e = 0; e < 2; e++) {
        kin_camera cam = kin_sthmd_camera(NULL, &wfh, (kin_eye)e);
        c->tcam[e] = cam;
        gt_render_eye(&c->gctx, &wfh, (kin_eye)e, frame, c->ps.cam_rgb, c->sil[e], c->tnrm[e],
                      c->ps.gt_depth, c->ps.gt_mask);
        const uint8_t *src = c->ps.cam_rgb + (size_t)c->g.crop_y0 * GEN_CAM_W * 3;
        if (fuse_rgb24_to_rgba(src, GEN_CAM_W * 3, CW, CH,
                               &(fuse_image){ c->P[e], CW, CH, 4 * CW }) != FUSE_OK)
            return -1;
        gen_render_virtual(&c->gctx, &wfh, (kin_eye)e, frame, c->vrgb, c->vdepth);
        fuse_image V = { c->V[e], GEN_VIRT_W, GEN_VIRT_H, 4 * GEN_VIRT_W };
        if (fuse_rgb24_to_rgba(c->vrgb, GEN_VIRT_W * 3, GEN_VIRT_W, GEN_VIRT_H, &V) != FUSE_OK)
            return -1;
        c->L[e] = workshop_lighting(&c->workshop, &cam);
        fuse_intrinsics K = { cam.fx, cam.fy, cam.cx, cam.cy };
        fuse_image P = { c->P[e], CW, CH, 4 * CW }, Q = { c->layer, CW, CH, 4 * CW };
        fuse_image I = { c->ideal[e], GEN_VIRT_W, GEN_VIRT_H, 4 * GEN_VIRT_W };
        fuse_lighting Li = c->L[e];
        if (c->light.opaque_ideal) Li.kf = 0.0f;   /* the Fresnel sweep: a real hand is opaque */
        if (fuse_light(&Li, &K, &P, c->sil[e], CW, c->tnrm[e], 3 * CW, &Q) != FUSE_OK ||
            fuse_composite(&Q, &V, c->g.vp_x0, c->g.vp_y0, c->g.vp_width, c->g.vp_height,
                           &I) != FUSE_OK)
            return -1;
        /* the lighting-mismatch sweep: the methods see the cockpit under
         * another light than the ideal composite was made from */
        if (c->light.on && eval__light_render(c, &wfh, e, frame) < 0) return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ methods */

static int run_init(method_run *r, const method_cfg *cfg, const eval_ctx *c)
{
    memset(r, 0, sizeof *r);
    r->cfg = *cfg;
    /* the tracker runs for a second before the first frame (the motion
     * holds its first pose before t = 0) */
    r->next_k = -(int)ceilf(cfg->track.rate_hz);
    /* The filter as egofuse configures it: kin's defaults without the
     * ramp-lag compensation (it adds the low-pass's lag times a noisy
     * velocity: on 5 mm noise it costs IoU and triples the edge flicker,
     * see the "lagcomp" row of the report) */
    kin_filter_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.no_lag_comp = !cfg->lag_comp;
    kin_filter_init(&r->filter, &fd);
    r->locals = malloc(sizeof *r->locals * (size_t)c->mask.model.node_count);
    r->prev[0] = malloc((size_t)CW * CH);
    r->prev[1] = malloc((size_t)CW * CH);
    if (!r->locals || !r->prev[0] || !r->prev[1]) return -1;
    if (cfg->kind == M_REFINE) {
        r->fit = pipe_fit_create(NULL, cfg->fine ? &c->mask_fine.model : &c->mask.model,
                                 &c->rig, CW, CH);
        if (!r->fit) return -1;
    }
    kin_pose_rest(&c->mask.model, r->locals);
    return 0;
}

static int cmp_float(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The error area's mean, 95th percentile (nearest rank) and max over
 * every eye and frame (eval__print_error_area). */
static void error_area_stats(method_run *r)
{
    if (r->n_err < 1) return;
    qsort(r->err, (size_t)r->n_err, sizeof *r->err, cmp_float);
    double sum = 0.0;
    for (long k = 0; k < r->n_err; k++) sum += (double)r->err[k];
    long r95 = (long)ceil(0.95 * (double)r->n_err) - 1;
    if (r95 < 0) r95 = 0;
    r->err_mean = sum / (double)r->n_err;
    r->err_p95 = (double)r->err[r95];
    r->err_max = (double)r->err[r->n_err - 1];
}

static void run_free(method_run *r)
{
    error_area_stats(r);
    EF_FREE_ALL(r->locals, r->prev[0], r->prev[1], r->err);
    r->err = NULL;
    pipe_fit_destroy(r->fit);
}

/* Copies the valid parts of s over *dst. */
static void merge_sample(kin_track_sample *dst, const kin_track_sample *s)
{
    uint32_t v = s->valid;
    dst->t = s->t;
    if (v & KIN_TRACK_HEAD) { dst->head_pos = s->head_pos; dst->head_rot = s->head_rot; }
    for (int k = 0; k < 2; k++) {
        if (v & (KIN_TRACK_SHOULDER_L << k)) dst->shoulder[k] = s->shoulder[k];
        if (v & (KIN_TRACK_HAND_L << k)) {
            dst->hand_pos[k] = s->hand_pos[k];
            dst->hand_rot[k] = s->hand_rot[k];
        }
        if (v & (KIN_TRACK_GLOVE_L << k)) memcpy(dst->glove[k], s->glove[k], sizeof s->glove[k]);
    }
    dst->valid |= v;
}

/* The estimated calibration (estimate_calib) with every scale times
 * (1 + err): the calibration-error sweep. */
static kin_user_calib calib_of(const eval_ctx *c, float err)
{
    kin_user_calib u = c->calib;
    for (int s = 0; s < 2; s++) {
        u.arm_scale[s] *= 1.0f + err;
        u.hand_scale[s] *= 1.0f + err;
    }
    u.shoulder_scale *= 1.0f + err;
    return u;
}

/* The true proportions the calibration should find (for the report). */
void eval__true_scales(const eval_ctx *c, float *arm, float *hand, float *shoulder)
{
    float model = c->rig.upper_len[0] + c->rig.fore_len[0];
    *arm = (c->rig.upper_len[0] * c->op.upper_scale + c->rig.fore_len[0] * c->op.fore_scale) / model;
    *hand = c->op.hand_scale;
    *shoulder = c->op.shoulder_scale;
}

/* Upsamples a w x h mask (nearest) to CW x CH, and normals likewise. */
static void upsample(const uint8_t *lo, const float *nlo, int div, uint8_t *m, float *n)
{
    int w = CW / div;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            size_t s = (size_t)(y / div) * (size_t)w + (size_t)(x / div);
            size_t d = (size_t)y * CW + (size_t)x;
            m[d] = lo[s];
            memcpy(&n[d * 3], &nlo[s * 3], sizeof(float) * 3);
        }
}

/* One frame of one method: both eyes, measured. Returns -1 on failure. */
/* DIR/<method>_<setting>_<eye>_NNNN.png: red = true silhouette, green =
 * the method's mask, blue = the camera image's luma / 2. */
static int dump_masks(const char *dir, const method_cfg *cfg, int frame, int eye,
                      const uint8_t *mask, const uint8_t *sil, const uint8_t *P, uint8_t *rgb)
{
    for (size_t i = 0; i < (size_t)CW * CH; i++) {
        rgb[i * 3 + 0] = sil[i];
        rgb[i * 3 + 1] = mask[i] >= 128 ? 255 : 0;
        rgb[i * 3 + 2] = (uint8_t)((P[i * 4] + 2 * P[i * 4 + 1] + P[i * 4 + 2]) / 8);
    }
    char path[IO_PATH_MAX + 128];
    snprintf(path, sizeof path, "%s/%s_%s_%s_%04d.png", dir, kind_name[cfg->kind], cfg->setting,
             eye ? "right" : "left", frame);
    io_image img = { rgb, CW, CH, 3, IO_U8, (size_t)CW * 3 };
    io_error err;
    if (io_image_save(path, &img, &err) != IO_OK) return io_term_fail("%s", err.msg);
    return IO_EXIT_OK;
}

/* FK and skinning of locals into c->ps.world, c->ps.pos, c->ps.nrm. */
static void pose_skin(eval_ctx *c, const method_cfg *cfg, const kin_model *m,
                      const kin_transform *locals)
{
    const kin_mesh *me = &m->meshes[0];
    kin_fk(m->parents, m->node_count, locals, NULL, c->ps.world);
    kin_skin_joint_matrices(&m->skins[0], c->ps.world, c->ps.jm);
    if (cfg->dqs) {
        kin_skin_dq_from_matrices(c->ps.jm, m->skins[0].joint_count, c->dq);
        kin_skin_dqs(me, c->dq, c->ps.pos, c->ps.nrm);
    } else {
        kin_skin_lbs(me, c->ps.jm, c->ps.pos, c->ps.nrm);
    }
}

/* Mask (and normals) of the posed model through cam at the method's
 * resolution; *mask, *nrm point at the full-resolution result. */
static int draw_mask(eval_ctx *c, const method_cfg *cfg, const kin_mesh *me, int posed,
                     const kin_camera *cam, const uint8_t **mask, const float **nrm)
{
    int div = cfg->div, w = CW / div, h = CH / div;
    rast_target tg = { w, h, c->depth_lo, w, c->mask_lo, w, c->nrm_lo, 3 * w, 3, NULL, 0 };
    /* as pipe_frame: through a context (the same bytes as rast_draw),
     * clearing what its last draw of this target touched */
    rast_context_clear(c->rast, &tg);
    if (posed) {
        rast_transform_points(cam->view_proj.m, c->ps.pos, me->vertex_count, c->ps.clip);
        rast_transform_dirs(cam->view.m, c->ps.nrm, me->vertex_count, c->ps.vnrm);
        /* the method's level of detail (eval_lod.c): its index list
         * over the same vertices */
        c->lod_drawn = eval__lod_level(c, cfg, c->ps.clip, me->vertex_count, cam);
        const kin_mesh *lm = c->lod_drawn ? &c->lod.level[c->lod_drawn].meshes[0] : me;
        rast_mesh_desc d = { c->ps.clip, me->vertex_count, c->ps.vnrm, 3, lm->indices,
                             lm->index_count / 3, RAST_CULL_NONE };
        if (rast_context_draw(c->rast, &tg, &d, NULL) != RAST_OK) return -1;
        if (cfg->aa > 1) {
            /* the mask from cfg->aa coverage samples per pixel (depth and
             * normals stay those of the centres) */
            rast_aa_target at = { w, h, c->aa_samples, w, cfg->aa };
            rast_aa_clear(&at);
            /* (the resolve writes the mask beyond the draw's record: the
             * next clear of it is whole) */
            rast_context_forget(c->rast);
            if (rast_draw_aa(&at, &d, NULL) != RAST_OK ||
                rast_aa_resolve(&at, c->mask_lo, w) != RAST_OK)
                return -1;
        }
    }
    if (div == 1) {
        *mask = c->mask_lo;
        *nrm = c->nrm_lo;
    } else {
        upsample(c->mask_lo, c->nrm_lo, div, c->mask_up, c->mnrm);
        *mask = c->mask_up;
        *nrm = c->mnrm;
    }
    return 0;
}

static kin_camera eye_camera(const eval_ctx *c, int e)
{
    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    return kin_sthmd_camera(&hd, &c->ps.world[c->rig.head], (kin_eye)e);
}

/* The elbow fit of the refine method (pipe_fit): learns the colour
 * models where the kinematic mask and the last refined mask agree, finds
 * the swivels, turns the arms in r->locals. */
static int fit_elbows(eval_ctx *c, method_run *r, const kin_model *m, uint32_t valid)
{
    const kin_mesh *me = &m->meshes[0];
    kin_camera cam[2];
    fuse_image P[2];
    for (int e = 0; e < 2; e++) {
        cam[e] = eye_camera(c, e);
        P[e] = (fuse_image){ c->P[e], CW, CH, 4 * CW };
        /* the colour model learned after the last frame's refinement
         * (run_frame); only without one is the kinematic mask drawn here */
        if (pipe_fit_learned(r->fit, e)) continue;
        const uint8_t *m0;
        const float *nrm;
        if (draw_mask(c, &r->cfg, me, 1, &cam[e], &m0, &nrm) < 0) return -1;
        if (pipe_fit_learn(r->fit, e, &P[e], m0, CW, r->have_prev ? r->prev[e] : NULL, CW) !=
            FUSE_OK)
            return -1;
    }
    unsigned sides = ((valid & KIN_TRACK_HAND_L) ? 1u : 0u) | ((valid & KIN_TRACK_HAND_R) ? 2u : 0u);
    pipe_fit_elbows(r->fit, c->ps.world, c->ps.pos, cam, P, sides, r->locals, r->swivel);
    return 0;
}

/* This thread's CPU time, seconds (the method's time on a shared
 * machine, where the wall clock counts the other processes). */
static double thread_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static pipe_fit_band_desc band_desc(const method_cfg *cfg)
{
    pipe_fit_band_desc bd = pipe_fit_band_desc_default();
    bd.sigma = cfg->band_sigma;
    bd.tau = cfg->band_tau;
    bd.band_min = cfg->band;
    bd.band_max = cfg->band_max;
    return bd;
}

static int run_frame(eval_ctx *c, method_run *r, int frame, int per_frame, const char *dump)
{
    const method_cfg *cfg = &r->cfg;
    double T = (double)frame / GEN_FPS;
    double t0 = io_now_s();
    /* tracking: every sample delivered by now */
    const double lat = cfg->track.latency_ms * 1e-3;
    for (;;) {
        double tc = (double)r->next_k / cfg->track.rate_hz;
        if (tc + lat > T + 1e-9) break;
        kin_track_sample s;
        gt_track_sample(&c->truth, &cfg->track, r->next_k, c->ps.tlocals, c->ps.tworld, &s);
        r->next_k++;
        if (cfg->kind == M_KIN) {
            if (!r->have_last) { r->last = s; r->have_last = 1; }
            else merge_sample(&r->last, &s);
        } else if (cfg->kind != M_SKIN) {
            kin_filter_push(&r->filter, &s);
            r->have_last = 1;
        }
    }
    t0 = io_now_s();   /* the tracker's simulation is not the method's time */
    double c0 = thread_cpu();   /* and the same as this thread's CPU time */
    const kin_model *m = cfg->fine ? &c->mask_fine.model : &c->mask.model;
    const kin_mesh *me = &m->meshes[0];
    int posed = 0;
    if (cfg->kind != M_SKIN && r->have_last) {
        kin_track_sample s;
        kin_user_calib cal = calib_of(c, cfg->calib_error);
        const kin_user_calib *cp = NULL;
        if (cfg->kind == M_KIN) {
            s = r->last;
        } else {
            /* the hands' lag compensated by their speed (fit_band.h;
             * v1 0: kin_filter_output) */
            pipe_fit_filter_output(&r->filter, T, cfg->lag_adapt_v0, cfg->lag_adapt_v1, &s, NULL);
            cp = &cal;
        }
        posed = kin_arm_rig_pose(&c->rig, m, cp, NULL, &s, r->locals, NULL);
        r->sides = ((s.valid & KIN_TRACK_HAND_L) ? 1u : 0u) | ((s.valid & KIN_TRACK_HAND_R) ? 2u : 0u);
        for (int k = 0; k < 2; k++) {
            /* the wrist's speed: the filter's velocity (raw methods: 0) */
            const kin_vec3 v = cfg->kind == M_KIN ? kin_v3(0, 0, 0) : r->filter.part[3 + k].dx;
            r->speed[k] = sqrtf(v.x * v.x + v.y * v.y + v.z * v.z);
        }
        if (posed) pose_skin(c, cfg, m, r->locals);
        if (posed && cfg->kind == M_REFINE && cfg->fit) {
            pipe_fit_shape(r->fit, c->ps.world, c->ps.pos);
            if (fit_elbows(c, r, m, s.valid) < 0) return -1;
            pose_skin(c, cfg, m, r->locals);
            pipe_fit_shape(r->fit, c->ps.world, c->ps.pos);
        }
    }
    double secs = io_now_s() - t0, cpu = thread_cpu() - c0;
    for (int e = 0; e < 2; e++) {
        t0 = io_now_s();
        c0 = thread_cpu();
        kin_camera cam = posed ? eye_camera(c, e) : c->tcam[e];
        const uint8_t *mask = c->mask_up;
        const float *nrm = c->mnrm;
        if (cfg->kind == M_SKIN) {
            fuse_image P = { c->P[e], CW, CH, 4 * CW };
            fuse_skin_params sp = fuse_skin_params_default();
            if (fuse_skin_key(&sp, &P, c->mask_up, CW) != FUSE_OK) return -1;
            memset(c->mnrm, 0, sizeof(float) * 3 * CW * CH);
        } else {
            /* the raster's own time: this thread's CPU time (the
                 * machine may be shared; the wall clock counts the others) */
            struct timespec tr0, tr1;
            clock_gettime(CLOCK_THREAD_CPUTIME_ID, &tr0);
            if (draw_mask(c, cfg, me, posed, &cam, &mask, &nrm) < 0) return -1;
            clock_gettime(CLOCK_THREAD_CPUTIME_ID, &tr1);
            if (posed) {
                r->raster_secs += (double)(tr1.tv_sec - tr0.tv_sec) +
                                  1e-9 * (double)(tr1.tv_nsec - tr0.tv_nsec);
                r->n_raster++;
                r->lod_sum += c->lod_drawn;
                r->tris_sum += (c->lod_drawn ? c->lod.level[c->lod_drawn].meshes[0].index_count
                                             : me->index_count) / 3;
            }
            if (cfg->kind == M_REFINE) {
                fuse_refine_params rp = fuse_refine_params_default();
                rp.band = cfg->band;
                if (cfg->band_auto && posed) {
                    /* the band from the projected uncertainty (fit_band.h),
                     * at least --band */
                    pipe_fit_band_desc bd = band_desc(cfg);
                    rp.band = pipe_fit_band(&bd, &cam, c->ps.world, &c->rig, r->sides, r->speed);
                }
                r->band_sum += rp.band;
                r->n_band++;
                fuse_image P = { c->P[e], CW, CH, 4 * CW };
                const uint8_t *kmask = mask;   /* the kinematic mask */
                if (cfg->prior_radius > 0.0f && posed && r->have_prev) {
                    /* the last refined mask as the input around the slow
                     * hands (fit_band.h) */
                    pipe_fit_band_desc bd = band_desc(cfg);
                    bd.hand_radius = cfg->prior_radius;
                    /* moved with the hand: its image motion since the
                     * last frame (the kinematic pose's, lag and all) */
                    float shift[2][2] = { { 0, 0 }, { 0, 0 } };
                    for (int k = 0; k < 2; k++)
                        if (cfg->prior_mc && r->have_hand_px[e][k] &&
                            pipe_fit_hand_px(&cam, c->ps.world, &c->rig, k, shift[k])) {
                            shift[k][0] -= r->hand_px[e][k][0];
                            shift[k][1] -= r->hand_px[e][k][1];
                        } else {
                            shift[k][0] = shift[k][1] = 0.0f;
                        }
                    mask = pipe_fit_prior(&bd, &cam, c->ps.world, &c->rig, r->sides, r->speed,
                                          cfg->prior_speed, shift, mask, r->prev[e],
                                          c->mask_prior, CW);
                    /* its rim must look like the hand (last frame's
                     * edge a pixel off: fit_band.h) */
                    if (mask == c->mask_prior && cfg->fit && pipe_fit_learned(r->fit, e))
                        pipe_fit_prior_colour(pipe_fit_colour(r->fit, e), &P, c->mask_prior, CW);
                }
                const int from_prior = mask == c->mask_prior;
                /* the hands of the input moved to where the colour
                 * says they are (fit_shift.h): the hands without the
                 * prior, or every tracked hand */
                if (cfg->shift && posed && cfg->fit && pipe_fit_learned(r->fit, e)) {
                    unsigned ss = r->sides;
                    if (cfg->shift == 1 && from_prior)
                        for (int k = 0; k < 2; k++)
                            if (r->speed[k] < cfg->prior_speed) ss &= ~(1u << k);
                    const pipe_fit_shift_desc sd = pipe_fit_shift_desc_default();
                    mask = pipe_fit_shift(&sd, pipe_fit_colour(r->fit, e), &P, &cam, c->ps.world,
                                          &c->rig, ss, mask, c->mask_shift, CW,
                                          c->refine_scratch, c->refine_scratch_size, NULL);
                }
                /* the hands' image motion since the last frame (for the
                 * regrow's trail below) */
                float hmot[2][2] = { { 0, 0 }, { 0, 0 } };
                unsigned hseen = 0;
                for (int k = 0; k < 2; k++) {
                    const int had = r->have_hand_px[e][k];
                    const float ox = r->hand_px[e][k][0], oy = r->hand_px[e][k][1];
                    r->have_hand_px[e][k] =
                        posed && pipe_fit_hand_px(&cam, c->ps.world, &c->rig, k, r->hand_px[e][k]);
                    if (r->have_hand_px[e][k]) hseen |= 1u << k;
                    if (had && r->have_hand_px[e][k]) {
                        hmot[k][0] = r->hand_px[e][k][0] - ox;
                        hmot[k][1] = r->hand_px[e][k][1] - oy;
                    }
                }
                /* the global term only once the fit has a colour model
                 * (as pipe_frame): an all-zero one would halve the local
                 * term */
                const uint8_t *rin = mask;   /* the refinement's input */
                fuse_refine_stats rs;
                /* the band halved (down to 4 px) where the hand is too
                 * thin for its learning ring (fit_narrow.h, as pipe_frame) */
                fuse_result fr = pipe_fit_refine_narrow(
                    &rp,
                    cfg->fit && cfg->global > 0.0f && pipe_fit_learned(r->fit, e)
                        ? pipe_fit_colour(r->fit, e) : NULL,
                    cfg->global, PIPE_NARROW_MIN_BAND, &P, mask, CW, c->refined, CW,
                    c->refine_scratch, c->refine_scratch_size, &rs, NULL);
                if (fr != FUSE_OK) return -1;
                /* once more from its own edge where it let in much: the
                 * hand beyond the band (fit_narrow.h, as pipe_frame) */
                const int regrown = pipe_fit_refine_regrow(
                    &rp,
                    cfg->fit && cfg->global > 0.0f && pipe_fit_learned(r->fit, e)
                        ? pipe_fit_colour(r->fit, e) : NULL,
                    cfg->global, &P, c->refined, CW, c->mask_smooth, c->refine_scratch,
                    c->refine_scratch_size, &rs);
                if (regrown < 0) return -1;
                /* what it added behind a moving hand taken back: where
                 * the hand was, not where it is (fit_narrow.h) */
                if (regrown > 0 && posed &&
                    pipe_fit_regrow_trail(c->mask_smooth, CW, c->refined, CW, CW, CH,
                                          r->sides & hseen, r->hand_px[e], hmot, r->speed,
                                          PIPE_TRAIL_STEPS) < 0)
                    return -1;
                /* and so must the pixels the vote let in beyond it */
                if (from_prior && rs.used_colour && cfg->fit &&
                    pipe_fit_learned(r->fit, e))
                    pipe_fit_refined_colour(pipe_fit_colour(r->fit, e), &P, mask, c->refined, CW);
                /* the stereo pair's depth test (fit_stereo.h): refined
                 * pixels found behind the hand in the other camera */
                if (cfg->stereo && posed && rs.used_colour && cfg->div == 1) {
                    const pipe_fit_stereo_desc sd = pipe_fit_stereo_desc_default();
                    kin_camera oc = eye_camera(c, 1 - e);
                    fuse_image Qo = { c->P[1 - e], CW, CH, 4 * CW };
                    pipe_fit_stereo_stats ss;
                    if (pipe_fit_stereo(&sd, &cam, &P, &oc, &Qo, c->depth_lo, CW, c->refined, CW,
                                        c->stereo_scratch, c->stereo_scratch_size, &ss) < 0)
                        return -1;
                    r->stereo_tested += ss.tested;
                    r->stereo_cleared += ss.cleared;
                    r->stereo_added += ss.added;
                }
                /* small islands (and holes) of the refined mask
                 * (fit_holes.h, as pipe_frame) */
                if (rs.used_colour && cfg->fill_hole + cfg->fill_island > 0)
                    pipe_fit_fill_small(c->refined, CW, CW, CH, cfg->fill_hole, cfg->fill_island,
                                        kmask, CW, c->refine_scratch, c->refine_scratch_size);
                /* its ragged edge smoothed (fit_smooth.h; the default,
                 * 3, as pipe_frame: the shown mask only, below) */
                /* 1, 4 (the closing only inside the refinement's input):
                 * in place, before the learning */
                if (rs.used_colour && (cfg->smooth == 1 || cfg->smooth == 4))
                    pipe_fit_smooth(c->refined, CW, CW, CH, cfg->smooth == 4 ? mask : NULL, CW,
                                    c->refine_scratch, c->refine_scratch_size);
                /* not from a fallback (out = M): its widths are the
                 * model's own (as pipe_frame) */
                if (cfg->fit && posed && rs.used_colour) {
                    /* the next frame's fit: the colour model from this
                     * frame's kinematic and refined masks (no extra
                     * raster), and the limb widths (self-calibration) */
                    if (pipe_fit_learn(r->fit, e, &P, kmask, CW, c->refined, CW) != FUSE_OK)
                        return -1;
                    pipe_fit_measure(r->fit, e, &cam, c->ps.world, kmask, CW, c->refined, CW);
                }
                mask = c->refined;
                /* smoothed after the learning: 2 the prior smoothed too,
                 * 3 the output only */
                if (rs.used_colour && cfg->smooth == 2)
                    pipe_fit_smooth(c->refined, CW, CW, CH, NULL, 0, c->refine_scratch,
                                    c->refine_scratch_size);
                if (rs.used_colour && (cfg->smooth == 3 || cfg->smooth >= 5)) {
                    memcpy(c->mask_smooth, c->refined, (size_t)CW * CH);
                    pipe_fit_smooth_ops(c->mask_smooth, CW, CW, CH, cfg->smooth == 5 ? rin : NULL,
                                        CW, c->refine_scratch, c->refine_scratch_size,
                                        cfg->smooth == 6 ? 1u : cfg->smooth == 7 ? 2u : 3u);
                    mask = c->mask_smooth;
                }
            }
        }
        fuse_intrinsics K = { cam.fx, cam.fy, cam.cx, cam.cy };
        fuse_image P = { c->P[e], CW, CH, 4 * CW }, Q = { c->layer, CW, CH, 4 * CW };
        fuse_image V = { c->V[e], GEN_VIRT_W, GEN_VIRT_H, 4 * GEN_VIRT_W };
        fuse_image O = { c->out, GEN_VIRT_W, GEN_VIRT_H, 4 * GEN_VIRT_W };
        fuse_lighting L = workshop_lighting(&c->workshop, &cam);
        if (cfg->kf_set) L.kf = cfg->kf;
        if (cfg->tone > 0.0f) {   /* as pipe_desc.tone_match */
            float tone[3];
            if (fuse_tone_match(&P, mask, CW, &V, c->g.vp_x0, c->g.vp_y0, c->g.vp_width,
                                c->g.vp_height, cfg->tone, tone) != FUSE_OK)
                return -1;
            for (int k = 0; k < 3; k++) L.tone[k] *= tone[k];
        }
        if (fuse_light(&L, &K, &P, mask, CW, nrm, 3 * CW, &Q) != FUSE_OK ||
            fuse_composite(&Q, &V, c->g.vp_x0, c->g.vp_y0, c->g.vp_width, c->g.vp_height,
                           &O) != FUSE_OK)
            return -1;
        secs += io_now_s() - t0;
        cpu += thread_cpu() - c0;
        if (cfg->lod != 0 && posed && c->full_mask && cfg->div == 1 && !cfg->fine &&
            cfg->kind != M_SKIN) {
            /* the kinematic mask (c->mask_lo) against the full model's in
             * the same pose (not timed) */
            rast_target ft = { CW, CH, c->full_depth, CW, c->full_mask, CW, NULL, 0, 0, NULL, 0 };
            rast_target_clear(&ft);
            rast_transform_points(cam.view_proj.m, c->ps.pos, me->vertex_count, c->ps.clip);
            rast_mesh_desc d = { c->ps.clip, me->vertex_count, NULL, 0, me->indices,
                                 me->index_count / 3, RAST_CULL_NONE };
            if (rast_draw(&ft, &d, NULL) != RAST_OK) return -1;
            fuse_confusion fc;
            fuse_mask_confusion(c->mask_lo, CW, c->full_mask, CW, CW, CH, &fc);
            r->iou_full += fuse_confusion_iou(&fc);
            r->bf1_full += fuse_boundary_f(c->mask_lo, CW, c->full_mask, CW, CW, CH, 1.0f, NULL,
                                           NULL);
            r->n_full++;
        }

        /* measures */
        fuse_confusion cf;
        fuse_mask_confusion(mask, CW, c->sil[e], CW, CW, CH, &cf);
        double iou = fuse_confusion_iou(&cf);
        double bf1 = fuse_boundary_f(mask, CW, c->sil[e], CW, CW, CH, 1.0f, NULL, NULL);
        double bf3 = fuse_boundary_f(mask, CW, c->sil[e], CW, CW, CH, 3.0f, NULL, NULL);
        size_t off = (size_t)c->g.vp_y0 * 4 * GEN_VIRT_W + (size_t)c->g.vp_x0 * 4;
        double mse = fuse_mse(c->out + off, 4 * GEN_VIRT_W, c->ideal[e] + off, 4 * GEN_VIRT_W,
                              c->g.vp_width, c->g.vp_height, 4, 3);
        r->iou += iou;
        r->bf1 += bf1;
        r->bf3 += bf3;
        r->fp += (double)cf.fp;
        r->fn += (double)cf.fn;
        if (r->n_err == r->err_cap) {
            const long cap = r->err_cap ? 2 * r->err_cap : 256;
            float *ne = realloc(r->err, sizeof *ne * (size_t)cap);
            if (!ne) return -1;
            r->err = ne;
            r->err_cap = cap;
        }
        r->err[r->n_err++] = (float)(cf.fp + cf.fn);
        r->tp_sum += (double)cf.tp;
        r->union_sum += (double)(cf.tp + cf.fp + cf.fn);
        r->mse += mse;
        r->n_eye++;
        if (per_frame) {
            float th[2][2] = { { 1, 1 }, { 1, 1 } };
            if (r->fit) pipe_fit_thickness(r->fit, th, NULL);
            printf("%4d %-5s %-14s %-22s iou %.4f bf1 %.3f bf3 %.3f fp %6ld fn %6ld psnr %5.2f"
                   " swivel %+.0f %+.0f deg thick %.3f %.3f %.3f %.3f\n",
                   frame, e ? "right" : "left", kind_name[cfg->kind], cfg->setting, iou, bf1,
                   bf3, cf.fp, cf.fn, fuse_psnr_of_mse(mse), (double)(r->swivel[0] / DEG2RAD),
                   (double)(r->swivel[1] / DEG2RAD), (double)th[0][0], (double)th[0][1],
                   (double)th[1][0], (double)th[1][1]);
        }
        if (dump && dump_masks(dump, cfg, frame, e, mask, c->sil[e], c->P[e], c->vrgb))
            return -1;
        if (r->have_prev && c->have_sil_prev) {
            /* summed as numerator and denominator (spurious swept area over
             * true edge length), so frames where the hand leaves the view
             * (a few edge pixels) do not dominate the mean */
            double fl = fuse_edge_flicker(r->prev[e], mask, c->sil_prev[e], c->sil[e], CW, CW, CH);
            long edge = fuse_boundary_count(c->sil[e], CW, CW, CH);
            double den = edge > 1 ? (double)edge : 1.0;
            r->flicker += fl * den;
            r->flicker_den += den;
            r->n_flicker++;
        }
        memcpy(r->prev[e], cfg->kind == M_REFINE && (cfg->smooth == 3 || cfg->smooth >= 5) ? c->refined
                                                                           : mask,
               (size_t)CW * CH);
    }
    r->have_prev = 1;
    r->secs += secs;
    r->cpu_secs += cpu;
    r->n_frames++;
    if (r->fit && cfg->fit) {
        pipe_fit_thickness(r->fit, r->thick, NULL);
        r->have_thick = 1;
    }
    return 0;
}

/* ---------------------------------------------------------------- run */

/* Runs configurations cfgs[0..n) into R on `frames` frames of sequence
 * seq (one ground truth, its tracking `track`). The context is left in *c
 * for the caller to free. */
int eval__run_batch(const eval_opts *o, const gt_track_desc *track, eval_ctx *c, const char *seq,
                    int frames, float speed, const eval_light *light, const method_cfg *cfgs,
                    method_run *R, int n)
{
    int irc = ctx_init(c, (uint64_t)o->seed, seq, track);
    if (irc < 0)
        return irc == -2 ? IO_EXIT_FAIL : io_term_fail("cannot build the ground truth (out of memory)");
    if (light) c->light = *light;
    int rc = IO_EXIT_FAIL;
    int inited = 0;
    for (int i = 0; i < n; i++)
        if (cfgs[i].lod != 0 && eval__lod_init(c) < 0) return IO_EXIT_FAIL;
    for (; inited < n; inited++)
        if (run_init(&R[inited], &cfgs[inited], c) < 0) { io_term_fail("out of memory"); goto done; }
    io_progress pr;
    io_progress_start(&pr, frames);
    if (o->quiet) pr.enabled = 0;
    for (int f = 0; f < frames; f++) {
        if (make_truth(c, f, speed, f == 0) < 0) { io_term_fail("frame %d: ground truth", f); goto done; }
        for (int i = 0; i < n; i++)
            if (run_frame(c, &R[i], f, o->per_frame, o->dump) < 0) {
                io_term_fail("frame %d: %s %s failed", f, kind_name[R[i].cfg.kind], R[i].cfg.setting);
                goto done;
            }
        char what[64];
        snprintf(what, sizeof what, "eval %s frame", seq);
        io_progress_step(&pr, f + 1, what);
    }
    io_progress_end(&pr);
    rc = IO_EXIT_OK;
done:
    for (int i = 0; i < inited; i++) run_free(&R[i]);
    return rc;
}

/* The workshop's lighting in cam's view space (eval_eye.c). */
fuse_lighting eval__lighting(const gen_scene *ws, const kin_camera *cam)
{
    return workshop_lighting(ws, cam);
}
