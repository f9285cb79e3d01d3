/* cmd_eval.c - `egofuse eval`: accuracy of the masks and composites of
 * several methods against generated ground truth (samples/gt/, the
 * definitions in src/fuse/fuse_metrics.h, the report in docs/accuracy.md).
 *
 * Per display frame (60 Hz): the true operator is posed and rendered into
 * both camera images over the cockpit (with its exact silhouettes and the
 * ideal composite); then every method configuration, with its own tracking
 * stream (noise, latency, dropouts) and its own state (filter, last
 * sample, previous masks, elbow fit), makes its masks and composites, which
 * are timed and measured. A report runs several such batches (methods,
 * knobs, tracking sweeps, other sequences), each on its own ground truth. */
#include "cli.h"

/* The ground truth comes from samples/gt/ and the sample generator
 * (samples/gen/), linked into the program as build/libegofuse_samples.a. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../fuse/fuse_metrics.h"
#include "../fuse/fuse_refine.h"
#include "../pipe/pipe.h"
#include "../../samples/gt/gt.h"

static const char *eval_usage =
    "usage: egofuse eval [--sequence NAME] [--frames N] [--noise MM] [--latency MS]\n"
    "                    [--dropout P] [--calib-error E] [--speed S] [--seed S]\n"
    "                    [--methods LIST] [--band PX] [--global W] [--per-frame]\n"
    "                    [--csv FILE] [--report DIR] [--sweep-frames N]\n"
    "                    [--seq-frames N] [--dump DIR] [--quiet]\n"
    "\n"
    "Generates ground truth (a true operator whose bones and limbs differ from\n"
    "the mask model, filmed over a cockpit with skin-coloured objects, camera\n"
    "noise and its own lighting; exact silhouettes; the ideal composite) and\n"
    "measures the masks and composites of each method against it: mask IoU,\n"
    "boundary F within 1 and 3 px, false-positive and false-negative area,\n"
    "PSNR of the composite, temporal edge flicker, and the time per stereo\n"
    "frame. Methods: kin (the paper: fixed-size model, IK from the tracked\n"
    "hands, latest sample), kin-cal-pred (user calibration estimated from a\n"
    "calibration motion, One Euro filter and prediction to the camera frame's\n"
    "time), skin (YCbCr skin-colour key), refine (kin-cal-pred with the elbows\n"
    "fitted to the images and the limbs thinned to them, refined by colour in a\n"
    "band around its edge).\n"
    "\n"
    "  --sequence NAME  reach_grasp (default), cross (hands crossing), near\n"
    "                   (hands 15 cm from the eyes), edge (hands at the image\n"
    "                   borders), fast (0.25 s reaches)\n"
    "  --frames N       display frames at 60 Hz (default 60; sequences are 3 s)\n"
    "  --noise MM       RMS tracking position error (default 5)\n"
    "  --latency MS     tracking latency (default 20)\n"
    "  --dropout P      probability that a sample loses a hand (default 0.02)\n"
    "  --calib-error E  relative error added to the estimated user calibration\n"
    "                   (default 0)\n"
    "  --speed S        playback speed of the motion (default 1)\n"
    "  --seed S         seed of the camera and tracking noise (default 1)\n"
    "  --methods LIST   comma-separated subset of kin,kin-cal-pred,skin,refine\n"
    "                   (default: all four)\n"
    "  --band PX        refinement band half width, 1..64 (default 16)\n"
    "  --global W       refine: weight of the image-wide colour model against\n"
    "                   the band's local one, 0..1 (default 0.5)\n"
    "  --per-frame      print every frame's figures per method\n"
    "  --csv FILE       write the summary table as CSV\n"
    "  --report DIR     also run the speed knobs (band width, elbow fit, global\n"
    "                   colour model, filter lag compensation, mask resolution,\n"
    "                   coverage samples per pixel (aa 4/8/16), triangles,\n"
    "                   LBS/DQS) and the tracking sweeps (noise, latency,\n"
    "                   calibration error) on --sweep-frames frames, and\n"
    "                   the methods on every other sequence on --seq-frames\n"
    "                   frames; write DIR/summary.csv, DIR/table.md, data files\n"
    "                   and the charts (gnuplot, PNG)\n"
    "  --sweep-frames N frames of the knobs and tracking sweeps (default 60)\n"
    "  --seq-frames N   frames of each other sequence in a report (default 90)\n"
    "  --dump DIR       write every mask: DIR/METHOD_SETTING_EYE_NNNN.png (red:\n"
    "                   true silhouette, green: the method's mask)\n"
    "  --quiet          no progress line\n"
    "  -h, --help       this text\n";

enum { CW = 640, CH = 400 };

typedef enum method_kind { M_KIN, M_KIN_CAL, M_SKIN, M_REFINE } method_kind;
static const char *kind_name[] = { "kin", "kin-cal-pred", "skin", "refine" };

typedef struct method_cfg {
    method_kind kind;
    char setting[64];
    char group[16];          /* methods, band, res, tris, skin, noise, ... */
    float x;                 /* the swept value, for the charts */
    int dqs;
    int aa;                  /* coverage samples per pixel: 1, 4, 8, 16 */
    int div;                 /* mask resolution divisor */
    int fine;                /* 1: the subdivided (4x triangles) mask model */
    int band;
    int fit;                 /* refine: 1 = fit the elbows to the image */
    float global;            /* refine: weight of the global colour model */
    int lag_comp;            /* 1: the One Euro filter's ramp-lag compensation */
    gt_track_desc track;
    float calib_error;
} method_cfg;

/* Per-configuration state and sums. */
typedef struct method_run {
    method_cfg cfg;
    int next_k;              /* next tracking sample to deliver */
    kin_track_sample last;   /* latest delivered parts (raw methods) */
    int have_last;
    kin_filter filter;
    kin_transform *locals;
    uint8_t *prev[2];        /* previous masks per eye */
    int have_prev;
    float swivel[2];         /* elbow fit of the last frame, radians */
    pipe_fit *fit;           /* refine: the elbow fit and colour models */
    float thick[2][2];       /* refine: limb thickness measured by the fit */
    int have_thick;
    /* sums over frames and eyes */
    double iou, bf1, bf3, fp, fn, mse, flicker, flicker_den, secs;
    long n_eye, n_flicker, n_frames;
} method_run;

/* Shared per-frame buffers. */
typedef struct eval_ctx {
    gen_arms mask, mask_fine, truth;
    gen_scene cockpit, workshop;
    gen_frame_ctx gctx;
    kin_arm_rig rig;
    gt_operator_desc op;
    kin_mat4 *world, *jm;
    kin_transform *tlocals;
    kin_mat4 *tworld;
    kin_dualquat *dq;
    float *pos, *nrm, *clip, *vnrm;
    /* per eye */
    uint8_t *cam_rgb;                       /* 640x480x3 */
    uint8_t *P[2];                          /* 640x400 RGBA */
    uint8_t *sil[2], *sil_prev[2];          /* true silhouettes, 640x400 */
    int have_sil_prev;
    float *tnrm[2];
    uint8_t *V[2], *ideal[2];               /* 1280x800 RGBA */
    float *vdepth;
    uint8_t *vrgb;
    fuse_lighting L[2];
    kin_camera tcam[2];
    /* method scratch */
    uint8_t *mask_lo, *mask_up, *refined, *layer, *out;
    uint32_t *aa_samples;    /* anti-aliased coverage, 640x400 */
    float *depth_lo, *nrm_lo, *mnrm;
    void *refine_scratch;
    size_t refine_scratch_size;
    kin_sthmd_geometry g;
    float *gt_depth;          /* gt_render_eye scratch, 640x480 */
    uint8_t *gt_mask;
    kin_user_calib calib;     /* estimated from the calibration motion */
    char calib_why[256];
    int calib_hand_fallback;  /* 1: no fingertip gesture, hand = arm scale */
} eval_ctx;

typedef struct eval_opts {
    int frames, per_frame, quiet;
    float noise, latency, dropout, calib_error, speed;
    int seed;
    const char *csv, *report, *dump;
    unsigned methods;        /* bit k: method_kind k is run */
    const char *sequence;    /* gt_sequence_name() */
    int sweep_frames, seq_frames; /* report: tracking sweeps, other sequences */
    float global;            /* refine: weight of the global colour model */
    int band;                /* refinement band of the default refine */
} eval_opts;

/* ------------------------------------------------------------ lighting */

static fuse_lighting workshop_lighting(const gen_scene *ws, const kin_camera *cam)
{
    fuse_lighting L = fuse_lighting_default();
    L.light_count = ws->light_count < FUSE_MAX_LIGHTS ? ws->light_count : FUSE_MAX_LIGHTS;
    for (int i = 0; i < 3; i++) L.ambient[i] = ws->ambient[i];
    L.kd = 0.80f;
    L.ks = 0.12f;
    L.shininess = 20.0f;
    L.kf = 0.50f;
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

static void ctx_free(eval_ctx *c)
{
    gen_frame_ctx_free(&c->gctx);
    gen_arms_free(&c->truth);
    gen_arms_free(&c->mask_fine);
    gen_arms_free(&c->mask);
    gen_scene_free(&c->cockpit);
    gen_scene_free(&c->workshop);
    free(c->world); free(c->jm); free(c->tlocals); free(c->tworld); free(c->dq);
    free(c->pos); free(c->nrm); free(c->clip); free(c->vnrm);
    free(c->cam_rgb); free(c->vdepth); free(c->vrgb);
    for (int e = 0; e < 2; e++) {
        free(c->P[e]); free(c->sil[e]); free(c->sil_prev[e]); free(c->tnrm[e]); free(c->V[e]); free(c->ideal[e]);
    }
    free(c->aa_samples);
    free(c->mask_lo); free(c->mask_up); free(c->refined); free(c->layer); free(c->out);
    free(c->depth_lo); free(c->nrm_lo); free(c->mnrm);
    free(c->refine_scratch);
    free(c->gt_depth); free(c->gt_mask);
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
            gt_track_sample(&cal, track, k, c->tlocals, c->tworld, &S[k]);
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
        cli_fail("mask model: %s", why);
        return -1;
    }
    const kin_model *m = &c->mask.model;
    size_t N = (size_t)m->node_count;
    size_t V = (size_t)c->mask_fine.model.meshes[0].vertex_count;
    size_t J = (size_t)m->skins[0].joint_count;
    const size_t cp = (size_t)CW * CH, vp = (size_t)GEN_VIRT_W * GEN_VIRT_H;
    c->world = malloc(sizeof *c->world * N);
    c->tworld = malloc(sizeof *c->tworld * N);
    c->tlocals = malloc(sizeof *c->tlocals * N);
    c->jm = malloc(sizeof *c->jm * J);
    c->dq = malloc(sizeof *c->dq * J);
    c->pos = malloc(sizeof(float) * 3 * V);
    c->nrm = malloc(sizeof(float) * 3 * V);
    c->clip = malloc(sizeof(float) * 4 * V);
    c->vnrm = malloc(sizeof(float) * 3 * V);
    c->cam_rgb = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 3);
    c->vdepth = malloc(sizeof(float) * vp);
    c->vrgb = malloc(vp * 3);
    int ok = c->world && c->tworld && c->tlocals && c->jm && c->dq && c->pos && c->nrm &&
             c->clip && c->vnrm && c->cam_rgb && c->vdepth && c->vrgb;
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
    c->layer = malloc(cp * 4);
    c->out = malloc(vp * 4);
    c->depth_lo = malloc(sizeof(float) * cp);
    c->nrm_lo = malloc(sizeof(float) * 3 * cp);
    c->mnrm = malloc(sizeof(float) * 3 * cp);
    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = 64;
    rp.margin = 64;
    c->refine_scratch_size = fuse_refine_scratch_size(&rp, CW, CH);
    c->refine_scratch = aligned_alloc(16, (c->refine_scratch_size + 15) & ~(size_t)15);
    ok = ok && c->aa_samples && c->mask_lo && c->mask_up && c->refined && c->layer && c->out && c->depth_lo &&
         c->nrm_lo && c->mnrm && c->refine_scratch;
    c->gt_depth = malloc(sizeof(float) * GEN_CAM_W * GEN_CAM_H);
    c->gt_mask = malloc((size_t)GEN_CAM_W * GEN_CAM_H);
    ok = ok && c->gt_depth && c->gt_mask;
    if (!ok) return -1;
    if (estimate_calib(c, track) < 0) {
        cli_fail("user calibration from the calibration motion: %s", c->calib_why);
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
        gt_render_eye(&c->gctx, &wfh, (kin_eye)e, frame, c->cam_rgb, c->sil[e], c->tnrm[e],
                      c->gt_depth, c->gt_mask);
        const uint8_t *src = c->cam_rgb + (size_t)c->g.crop_y0 * GEN_CAM_W * 3;
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
        if (fuse_light(&c->L[e], &K, &P, c->sil[e], CW, c->tnrm[e], 3 * CW, &Q) != FUSE_OK ||
            fuse_composite(&Q, &V, c->g.vp_x0, c->g.vp_y0, c->g.vp_width, c->g.vp_height,
                           &I) != FUSE_OK)
            return -1;
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

static void run_free(method_run *r)
{
    free(r->locals);
    free(r->prev[0]);
    free(r->prev[1]);
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
static void true_scales(const eval_ctx *c, float *arm, float *hand, float *shoulder)
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
    if (io_image_save(path, &img, &err) != IO_OK) return cli_fail("%s", err.msg);
    return EXIT_OK;
}

/* FK and skinning of locals into c->world, c->pos, c->nrm. */
static void pose_skin(eval_ctx *c, const method_cfg *cfg, const kin_model *m,
                      const kin_transform *locals)
{
    const kin_mesh *me = &m->meshes[0];
    kin_fk(m->parents, m->node_count, locals, NULL, c->world);
    kin_skin_joint_matrices(&m->skins[0], c->world, c->jm);
    if (cfg->dqs) {
        kin_skin_dq_from_matrices(c->jm, m->skins[0].joint_count, c->dq);
        kin_skin_dqs(me, c->dq, c->pos, c->nrm);
    } else {
        kin_skin_lbs(me, c->jm, c->pos, c->nrm);
    }
}

/* Mask (and normals) of the posed model through cam at the method's
 * resolution; *mask, *nrm point at the full-resolution result. */
static int draw_mask(eval_ctx *c, const method_cfg *cfg, const kin_mesh *me, int posed,
                     const kin_camera *cam, const uint8_t **mask, const float **nrm)
{
    int div = cfg->div, w = CW / div, h = CH / div;
    rast_target tg = { w, h, c->depth_lo, w, c->mask_lo, w, c->nrm_lo, 3 * w, 3 };
    rast_target_clear(&tg);
    if (posed) {
        rast_transform_points(cam->view_proj.m, c->pos, me->vertex_count, c->clip);
        rast_transform_dirs(cam->view.m, c->nrm, me->vertex_count, c->vnrm);
        rast_mesh_desc d = { c->clip, me->vertex_count, c->vnrm, 3, me->indices,
                             me->index_count / 3, RAST_CULL_NONE };
        if (rast_draw(&tg, &d, NULL) != RAST_OK) return -1;
        if (cfg->aa > 1) {
            /* the mask from cfg->aa coverage samples per pixel (depth and
             * normals stay those of the centres) */
            rast_aa_target at = { w, h, c->aa_samples, w, cfg->aa };
            rast_aa_clear(&at);
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
    return kin_sthmd_camera(&hd, &c->world[c->rig.head], (kin_eye)e);
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
    pipe_fit_elbows(r->fit, c->world, c->pos, cam, P, sides, r->locals, r->swivel);
    return 0;
}

static int run_frame(eval_ctx *c, method_run *r, int frame, int per_frame, const char *dump)
{
    const method_cfg *cfg = &r->cfg;
    double T = (double)frame / GEN_FPS;
    double t0 = cli_now();
    /* tracking: every sample delivered by now */
    const double lat = cfg->track.latency_ms * 1e-3;
    for (;;) {
        double tc = (double)r->next_k / cfg->track.rate_hz;
        if (tc + lat > T + 1e-9) break;
        kin_track_sample s;
        gt_track_sample(&c->truth, &cfg->track, r->next_k, c->tlocals, c->tworld, &s);
        r->next_k++;
        if (cfg->kind == M_KIN) {
            if (!r->have_last) { r->last = s; r->have_last = 1; }
            else merge_sample(&r->last, &s);
        } else if (cfg->kind != M_SKIN) {
            kin_filter_push(&r->filter, &s);
            r->have_last = 1;
        }
    }
    t0 = cli_now();   /* the tracker's simulation is not the method's time */
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
            kin_filter_output(&r->filter, T, &s, NULL);
            cp = &cal;
        }
        posed = kin_arm_rig_pose(&c->rig, m, cp, NULL, &s, r->locals, NULL);
        if (posed) pose_skin(c, cfg, m, r->locals);
        if (posed && cfg->kind == M_REFINE && cfg->fit) {
            pipe_fit_shape(r->fit, c->world, c->pos);
            if (fit_elbows(c, r, m, s.valid) < 0) return -1;
            pose_skin(c, cfg, m, r->locals);
            pipe_fit_shape(r->fit, c->world, c->pos);
        }
    }
    double secs = cli_now() - t0;
    for (int e = 0; e < 2; e++) {
        t0 = cli_now();
        kin_camera cam = posed ? eye_camera(c, e) : c->tcam[e];
        const uint8_t *mask = c->mask_up;
        const float *nrm = c->mnrm;
        if (cfg->kind == M_SKIN) {
            fuse_image P = { c->P[e], CW, CH, 4 * CW };
            fuse_skin_params sp = fuse_skin_params_default();
            if (fuse_skin_key(&sp, &P, c->mask_up, CW) != FUSE_OK) return -1;
            memset(c->mnrm, 0, sizeof(float) * 3 * CW * CH);
        } else {
            if (draw_mask(c, cfg, me, posed, &cam, &mask, &nrm) < 0) return -1;
            if (cfg->kind == M_REFINE) {
                fuse_refine_params rp = fuse_refine_params_default();
                rp.band = cfg->band;
                fuse_image P = { c->P[e], CW, CH, 4 * CW };
                /* the global term only once the fit has a colour model
                 * (as pipe_frame): an all-zero one would halve the local
                 * term */
                fuse_refine_stats rs;
                fuse_result fr =
                    cfg->fit && cfg->global > 0.0f && pipe_fit_learned(r->fit, e)
                        ? fuse_refine_mask_global(&rp, pipe_fit_colour(r->fit, e), cfg->global, &P, mask, CW, c->refined,
                                                  CW, c->refine_scratch, c->refine_scratch_size,
                                                  &rs)
                        : fuse_refine_mask(&rp, &P, mask, CW, c->refined, CW, c->refine_scratch,
                                           c->refine_scratch_size, &rs);
                if (fr != FUSE_OK) return -1;
                /* not from a fallback (out = M): its widths are the
                 * model's own (as pipe_frame) */
                if (cfg->fit && posed && rs.used_colour) {
                    /* the next frame's fit: the colour model from this
                     * frame's kinematic and refined masks (no extra
                     * raster), and the limb widths (self-calibration) */
                    if (pipe_fit_learn(r->fit, e, &P, mask, CW, c->refined, CW) != FUSE_OK)
                        return -1;
                    pipe_fit_measure(r->fit, e, &cam, c->world, mask, CW, c->refined, CW);
                }
                mask = c->refined;
            }
        }
        fuse_intrinsics K = { cam.fx, cam.fy, cam.cx, cam.cy };
        fuse_image P = { c->P[e], CW, CH, 4 * CW }, Q = { c->layer, CW, CH, 4 * CW };
        fuse_image V = { c->V[e], GEN_VIRT_W, GEN_VIRT_H, 4 * GEN_VIRT_W };
        fuse_image O = { c->out, GEN_VIRT_W, GEN_VIRT_H, 4 * GEN_VIRT_W };
        fuse_lighting L = workshop_lighting(&c->workshop, &cam);
        if (fuse_light(&L, &K, &P, mask, CW, nrm, 3 * CW, &Q) != FUSE_OK ||
            fuse_composite(&Q, &V, c->g.vp_x0, c->g.vp_y0, c->g.vp_width, c->g.vp_height,
                           &O) != FUSE_OK)
            return -1;
        secs += cli_now() - t0;

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
        memcpy(r->prev[e], mask, (size_t)CW * CH);
    }
    r->have_prev = 1;
    r->secs += secs;
    r->n_frames++;
    if (r->fit && cfg->fit) {
        pipe_fit_thickness(r->fit, r->thick, NULL);
        r->have_thick = 1;
    }
    return 0;
}

/* ------------------------------------------------------ configurations */

static method_cfg base_cfg(const eval_opts *o, method_kind k)
{
    method_cfg c;
    memset(&c, 0, sizeof c);
    c.kind = k;
    c.div = 1;
    c.aa = 1;
    c.band = o->band;
    c.fit = k == M_REFINE;
    c.global = o->global;
    c.track = gt_track_default();
    c.track.noise_mm = o->noise;
    c.track.latency_ms = o->latency;
    c.track.dropout = o->dropout;
    c.track.speed = o->speed;
    c.track.seed = (uint64_t)o->seed;
    c.calib_error = o->calib_error;
    snprintf(c.group, sizeof c.group, "methods");
    snprintf(c.setting, sizeof c.setting, "default");
    return c;
}

static int add_cfg(method_cfg *list, int n, int cap, method_cfg c)
{
    if (n < cap) list[n] = c;
    return n + 1;
}

/* Phases of a report (each on its own ground truth and frame count). */
enum { PH_METHODS, PH_KNOBS, PH_TRACK, PH_SEQ };

/* A configuration of a sweep: group, swept value and setting "name=" x
 * (x as %g) followed by unit. */
static method_cfg named_cfg(const eval_opts *o, method_kind k, const char *group, float x,
                            const char *name, const char *unit)
{
    method_cfg c = base_cfg(o, k);
    c.x = x;
    snprintf(c.group, sizeof c.group, "%s", group);
    snprintf(c.setting, sizeof c.setting, "%s=%g%s", name, (double)x, unit);
    return c;
}

/* PH_METHODS: the selected methods at the given tracking; PH_KNOBS: the
 * same (group "knobs") with every speed knob; PH_TRACK: the tracking sweeps (and the methods at the
 * given tracking, group "track"); PH_SEQ: the methods on sequence seq. */
static int make_configs(const eval_opts *o, int phase, const char *seq, method_cfg *L, int cap)
{
    int n = 0;
    method_cfg c;
    if (phase == PH_METHODS || phase == PH_KNOBS || phase == PH_SEQ)
        for (int k = 0; k < 4; k++) {
            if (!(o->methods & (1u << k))) continue;
            c = base_cfg(o, (method_kind)k);
            if (phase == PH_SEQ) {
                snprintf(c.group, sizeof c.group, "sequence");
                snprintf(c.setting, sizeof c.setting, "seq=%s", seq);
            } else if (phase == PH_KNOBS) {
                snprintf(c.group, sizeof c.group, "knobs");
            }
            n = add_cfg(L, n, cap, c);
        }
    if (phase == PH_KNOBS) {
        static const int bands[] = { 4, 8, 12, 24, 32 };
        for (int i = 0; i < 5; i++) {
            c = named_cfg(o, M_REFINE, "band", (float)bands[i], "band", "");
            c.band = bands[i];
            n = add_cfg(L, n, cap, c);
        }
        c = named_cfg(o, M_REFINE, "fit", 0.0f, "fit", "");
        c.fit = 0;
        n = add_cfg(L, n, cap, c);
        c = named_cfg(o, M_REFINE, "global", 0.0f, "global", "");
        c.global = 0.0f;
        n = add_cfg(L, n, cap, c);
        for (int k = M_KIN_CAL; k <= M_REFINE; k += 2) {
            c = named_cfg(o, (method_kind)k, "lagcomp", 1.0f, "lagcomp", "");
            c.lag_comp = 1;
            n = add_cfg(L, n, cap, c);
        }
        for (int k = M_KIN_CAL; k <= M_REFINE; k += 2) {
            for (int div = 2; div <= 4; div *= 2) {
                c = named_cfg(o, (method_kind)k, "res", (float)div, "div", "");
                snprintf(c.setting, sizeof c.setting, "mask=%dx%d", CW / div, CH / div);
                c.div = div;
                n = add_cfg(L, n, cap, c);
            }
            for (int aa = 4; aa <= 16; aa *= 2) {
                c = named_cfg(o, (method_kind)k, "aa", (float)aa, "aa", "");
                c.aa = aa;
                n = add_cfg(L, n, cap, c);
            }
            c = named_cfg(o, (method_kind)k, "tris", 4.0f, "tris", "x");
            c.fine = 1;
            n = add_cfg(L, n, cap, c);
            c = named_cfg(o, (method_kind)k, "dqs", 1.0f, "dqs", "");
            snprintf(c.setting, sizeof c.setting, "dqs");
            c.dqs = 1;
            n = add_cfg(L, n, cap, c);
        }
    }
    if (phase == PH_TRACK) {
        static const float noise[] = { 0, 10, 20 };
        static const float lat[] = { 0, 50, 100 };
        static const float cal[] = { -0.10f, -0.05f, 0.05f, 0.10f };
        for (int k = 0; k < 4; k++) {
            if (k == M_SKIN || !(o->methods & (1u << k))) continue;
            c = base_cfg(o, (method_kind)k);
            snprintf(c.group, sizeof c.group, "track");
            n = add_cfg(L, n, cap, c);
            for (int i = 0; i < 3; i++) {
                c = named_cfg(o, (method_kind)k, "noise", noise[i], "noise", "mm");
                c.track.noise_mm = noise[i];
                n = add_cfg(L, n, cap, c);
            }
            for (int i = 0; i < 3; i++) {
                c = named_cfg(o, (method_kind)k, "latency", lat[i], "latency", "ms");
                c.track.latency_ms = lat[i];
                n = add_cfg(L, n, cap, c);
            }
            if (k == M_KIN) continue;    /* the paper's method has no calibration */
            for (int i = 0; i < 4; i++) {
                c = named_cfg(o, (method_kind)k, "calib", 100.0f * (o->calib_error + cal[i]),
                              "calib", "%");
                c.calib_error = o->calib_error + cal[i];
                n = add_cfg(L, n, cap, c);
            }
        }
    }
    return n;
}

/* ---------------------------------------------------------- reporting */

typedef struct summary {
    double iou, bf1, bf3, fp, fn, psnr, ms, flicker;
} summary;

static summary summarise(const method_run *r)
{
    summary s;
    double n = r->n_eye > 0 ? (double)r->n_eye : 1.0;
    s.iou = r->iou / n;
    s.bf1 = r->bf1 / n;
    s.bf3 = r->bf3 / n;
    s.fp = r->fp / n;
    s.fn = r->fn / n;
    s.psnr = fuse_psnr_of_mse(r->mse / n);
    s.ms = 1e3 * r->secs / (r->n_frames > 0 ? (double)r->n_frames : 1.0);
    s.flicker = r->flicker_den > 0.0 ? r->flicker / r->flicker_den : 0.0;
    return s;
}

static void print_calib(FILE *f, const eval_ctx *c)
{
    float arm, hand, sh;
    true_scales(c, &arm, &hand, &sh);
    fprintf(f, "calibration (kin_user_calib_estimate_tips on the calibration motion): arm "
               "x%.3f (true %.3f), hand x%.3f (true %.3f, %s), shoulders x%.3f (true %.3f)\n",
            (double)c->calib.arm_scale[1], (double)arm, (double)c->calib.hand_scale[1],
            (double)hand, c->calib_hand_fallback ? c->calib_why : "fingertip gesture",
            (double)c->calib.shoulder_scale, (double)sh);
}

/* Report files go through io_out: complete or absent, a failed write is
 * "path: write failed: reason" and exit 1 (io.h, OUTPUT FILES). */
static FILE *out_open(io_out *o, const char *path)
{
    io_error err;
    if (io_out_open(o, path, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        return NULL;
    }
    return o->f;
}

static int out_commit(io_out *o)
{
    io_error err;
    if (io_out_commit(o, &err) != IO_OK) return cli_fail("%s", err.msg);
    return EXIT_OK;
}

static int write_csv(const char *path, const method_run *R, int n)
{
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f, "method,setting,iou,bf1,bf3,fp_area,fn_area,psnr,ms_per_frame,flicker,group\n");
    for (int i = 0; i < n; i++) {
        summary s = summarise(&R[i]);
        fprintf(f, "%s,%s,%.5f,%.5f,%.5f,%.1f,%.1f,%.3f,%.3f,%.4f,%s\n",
                kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp, s.fn,
                s.psnr, s.ms, s.flicker, R[i].cfg.group);
    }
    return out_commit(&of);
}

/* The limb thickness the first refine run with the elbow fit measured
 * from the images (pipe_fit_measure), against the truth's. */
static void print_thickness(FILE *f, const eval_ctx *c, const method_run *R, int n)
{
    for (int i = 0; i < n; i++) {
        if (R[i].cfg.kind != M_REFINE || !R[i].have_thick) continue;
        fprintf(f, "refine's limb thickness from the images (pipe_fit, only thinner is "
                   "measured): forearm x%.3f x%.3f (true %.2f), upper arm x%.3f x%.3f "
                   "(true %.2f)\n",
                (double)R[i].thick[0][1], (double)R[i].thick[1][1], (double)c->op.fore_thick,
                (double)R[i].thick[0][0], (double)R[i].thick[1][0], (double)c->op.upper_thick);
        return;
    }
}

static void print_table(FILE *f, const method_run *R, int n, int markdown)
{
    if (markdown)
        fprintf(f, "| method | setting | IoU | BF 1px | BF 3px | FP px | FN px | PSNR dB | "
                   "flicker px | ms/stereo frame |\n|---|---|---|---|---|---|---|---|---|---|\n");
    else
        fprintf(f, "%-13s %-16s %7s %6s %6s %8s %8s %6s %7s %8s\n", "method", "setting", "IoU",
                "BF1", "BF3", "FP px", "FN px", "PSNR", "flicker", "ms/frame");
    for (int i = 0; i < n; i++) {
        summary s = summarise(&R[i]);
        if (markdown)
            fprintf(f, "| %s | %s | %.4f | %.3f | %.3f | %.0f | %.0f | %.2f | %.3f | %.2f |\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp,
                    s.fn, s.psnr, s.flicker, s.ms);
        else
            fprintf(f, "%-13s %-16s %7.4f %6.3f %6.3f %8.0f %8.0f %6.2f %7.3f %8.2f\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp,
                    s.fn, s.psnr, s.flicker, s.ms);
    }
}

/* DIR/<group>.dat: one block per method (gnuplot index), x y columns,
 * sorted by x; the method at the given tracking (group "track") is the
 * point at the given value of a tracking curve, the default refine (group
 * "knobs") the default band's point. */
static int write_group(const char *dir, const char *group, const method_run *R, int n,
                       const eval_opts *o)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/%s.dat", dir, group);
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    for (int k = 0; k < 4; k++) {
        fprintf(f, "# %s\n", kind_name[k]);
        float xs[64];
        int idx[64], m = 0;
        for (int i = 0; i < n && m < 64; i++) {
            const method_cfg *c = &R[i].cfg;
            if ((int)c->kind != k) continue;
            float x;
            if (!strcmp(c->group, group)) x = c->x;
            else if (!strcmp(c->group, "track") && !strcmp(group, "noise")) x = o->noise;
            else if (!strcmp(c->group, "track") && !strcmp(group, "latency")) x = o->latency;
            else if (!strcmp(c->group, "track") && !strcmp(group, "calib") && k != M_KIN)
                x = 100.0f * o->calib_error;
            else if (!strcmp(c->group, "knobs") && !strcmp(group, "band") && k == M_REFINE)
                x = (float)o->band;
            else continue;
            int j = m++;
            while (j > 0 && xs[j - 1] > x) { xs[j] = xs[j - 1]; idx[j] = idx[j - 1]; j--; }
            xs[j] = x;
            idx[j] = i;
        }
        for (int j = 0; j < m; j++) {
            summary s = summarise(&R[idx[j]]);
            fprintf(f, "%g %.5f %.5f %.3f %.3f\n", (double)xs[j], s.iou, s.bf3, s.ms, s.psnr);
        }
        if (!m) fprintf(f, "nan nan nan nan nan\n");
        fprintf(f, "\n\n");
    }
    return out_commit(&of);
}

/* DIR/sequences.dat: per sequence, IoU then BF(3 px) of the four methods. */
static int write_sequences(const char *dir, const method_run *R, int n, const eval_opts *o)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/sequences.dat", dir);
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f, "# sequence iou(kin kin-cal-pred skin refine) bf3(same)\n");
    for (int q = 0; gt_sequence_name(q); q++) {
        const char *name = gt_sequence_name(q);
        char want[64];
        snprintf(want, sizeof want, "seq=%s", name);
        double iou[4], bf3[4];
        int any = 0;
        for (int k = 0; k < 4; k++) {
            iou[k] = bf3[k] = NAN;
            for (int i = 0; i < n; i++) {
                const method_cfg *c = &R[i].cfg;
                if ((int)c->kind != k) continue;
                int hit = !strcmp(name, o->sequence) ? !strcmp(c->group, "methods")
                                                     : !strcmp(c->setting, want);
                if (!hit) continue;
                summary s = summarise(&R[i]);
                iou[k] = s.iou;
                bf3[k] = s.bf3;
                any = 1;
            }
        }
        if (!any) continue;
        fprintf(f, "%s", name);
        for (int k = 0; k < 4; k++) fprintf(f, " %.5f", iou[k]);
        for (int k = 0; k < 4; k++) fprintf(f, " %.5f", bf3[k]);
        fprintf(f, "\n");
    }
    return out_commit(&of);
}

/* Runs gnuplot on DIR/charts.gp with its outputs named "<chart>.tmp.<pid>",
 * then checks each chart decodes whole before giving it its name: gnuplot
 * does not report a failed write, so a full disk would leave truncated
 * charts. gnuplot missing or failing: a warning (the data is written);
 * a chart written incomplete: removed, an error. */
static int write_charts(const char *dir)
{
    static const char *const charts[] = {"speed_iou", "speed_bf", "noise", "latency",
                                         "calib", "band", "sequences"};
    enum { NCHART = sizeof charts / sizeof charts[0] };
    char cmd[3 * IO_PATH_MAX], tmp[IO_PATH_MAX + 96], path[IO_PATH_MAX + 64];
    long pid = (long)getpid();
    snprintf(cmd, sizeof cmd, "gnuplot -e \"sfx='.tmp.%ld'\" '%s/charts.gp'", pid, dir);
    int rc = system(cmd);
    int bad = 0;
    for (int i = 0; i < NCHART; i++) {
        snprintf(path, sizeof path, "%s/%s.png", dir, charts[i]);
        snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, pid);
        if (rc != 0) {
            remove(tmp);
            continue;
        }
        io_image img;
        io_error err;
        if (io_image_load(tmp, IO_U8, 0, &img, &err) != IO_OK) {
            remove(tmp);
            if (!bad) fprintf(stderr, "egofuse: %s: gnuplot wrote it incomplete or not at all "
                              "(%s); removed\n", path, err.msg);
            bad = 1;
            continue;
        }
        io_image_free(&img);
        if (rename(tmp, path) != 0) {
            fprintf(stderr, "egofuse: %s: cannot name it (rename from %s): %s\n", path, tmp,
                    strerror(errno));
            remove(tmp);
            bad = 1;
        }
    }
    if (rc != 0)
        fprintf(stderr, "egofuse eval: gnuplot failed (status %d): the data files and "
                        "%s/charts.gp are written, the PNG charts are not\n", rc, dir);
    return bad ? EXIT_FAIL : EXIT_OK;
}

static int write_report(const char *dir, const method_run *R, int n, const eval_opts *o,
                        const eval_ctx *c)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/summary.csv", dir);
    if (write_csv(path, R, n)) return EXIT_FAIL;
    snprintf(path, sizeof path, "%s/table.md", dir);
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f, "Ground truth: sequence %s, tracking noise %g mm, latency %g ms, dropout %g, "
               "calibration error %g, speed %g, seed %d. Frames: %d for the methods (group "
               "methods), %d for the speed knobs (groups knobs, band, fit, global, lagcomp, "
               "res, aa, tris, dqs) and the tracking sweeps (groups track, noise, latency, calib), "
               "%d per other sequence (group sequence).\n\n",
            o->sequence, (double)o->noise, (double)o->latency, (double)o->dropout,
            (double)o->calib_error, (double)o->speed, o->seed, o->frames, o->sweep_frames,
            o->seq_frames);
    print_calib(f, c);
    print_thickness(f, c, R, n);
    fprintf(f, "\n");
    print_table(f, R, n, 1);
    if (out_commit(&of)) return EXIT_FAIL;
    /* speed-accuracy points: label, ms, iou, bf3 */
    snprintf(path, sizeof path, "%s/speed.dat", dir);
    f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    for (int k = 0; k < 4; k++) {
        fprintf(f, "# %s\n", kind_name[k]);
        for (int i = 0; i < n; i++) {
            const method_cfg *cf = &R[i].cfg;
            if ((int)cf->kind != k) continue;
            if (strcmp(cf->group, "knobs") && strcmp(cf->group, "band") &&
                strcmp(cf->group, "res") && strcmp(cf->group, "tris") &&
                strcmp(cf->group, "dqs") && strcmp(cf->group, "fit") && strcmp(cf->group, "aa") &&
                strcmp(cf->group, "global") && strcmp(cf->group, "lagcomp"))
                continue;
            summary s = summarise(&R[i]);
            fprintf(f, "%.3f %.5f %.5f \"%s\"\n", s.ms, s.iou, s.bf3, cf->setting);
        }
        fprintf(f, "\n\n");
    }
    if (out_commit(&of)) return EXIT_FAIL;
    static const char *groups[] = { "noise", "latency", "calib", "band" };
    for (int g = 0; g < 4; g++)
        if (write_group(dir, groups[g], R, n, o)) return EXIT_FAIL;
    if (write_sequences(dir, R, n, o)) return EXIT_FAIL;
    snprintf(path, sizeof path, "%s/charts.gp", dir);
    f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f,
        "if (!exists('sfx')) sfx = ''\n"
        "set terminal pngcairo noenhanced size 900,600 font ',10'\n"
        "set grid\nset key bottom right\n"
        "titles = 'kin kin-cal-pred skin refine'\n"
        "set output '%s/speed_iou.png'.sfx\n"
        "set title 'Speed against accuracy: mask IoU (labels: setting)'\n"
        "set xlabel 'ms per stereo frame (pose, skin, raster, refine, light, composite; 1 thread)'\n"
        "set ylabel 'mask IoU'\nset logscale x\n"
        "plot for [i=0:3] '%s/speed.dat' index i using 1:2 with points pt 7 ps 1.3 title word(titles, i+1), \\\n"
        "     for [i=0:3] '%s/speed.dat' index i using 1:2:4 with labels offset 0,0.8 font ',7' notitle\n"
        "set output '%s/speed_bf.png'.sfx\n"
        "set title 'Speed against accuracy: boundary F-score within 3 px'\n"
        "set ylabel 'BF (3 px)'\n"
        "plot for [i=0:3] '%s/speed.dat' index i using 1:3 with points pt 7 ps 1.3 title word(titles, i+1), \\\n"
        "     for [i=0:3] '%s/speed.dat' index i using 1:3:4 with labels offset 0,0.8 font ',7' notitle\n"
        "unset logscale x\n"
        "set output '%s/noise.png'.sfx\nset title 'Accuracy against tracking noise (latency %g ms)'\n"
        "set xlabel 'RMS position noise, mm'\nset ylabel 'mask IoU'\n"
        "plot for [i=0:3] '%s/noise.dat' index i using 1:2 with linespoints lw 2 title word(titles, i+1)\n"
        "set output '%s/latency.png'.sfx\nset title 'Accuracy against tracking latency (noise %g mm)'\n"
        "set xlabel 'latency, ms'\n"
        "plot for [i=0:3] '%s/latency.dat' index i using 1:2 with linespoints lw 2 title word(titles, i+1)\n"
        "set output '%s/calib.png'.sfx\nset title 'Accuracy against calibration error (on top of the estimate)'\n"
        "set xlabel 'error of the arm, hand and shoulder scales, %%'\n"
        "plot for [i=0:3] '%s/calib.dat' index i using 1:2 with linespoints lw 2 title word(titles, i+1)\n"
        "set output '%s/band.png'.sfx\nset title 'Refinement band width'\n"
        "set xlabel 'band half width, px'\nset ylabel 'IoU, BF(3 px)'\n"
        "plot '%s/band.dat' index 3 using 1:2 with linespoints lw 2 title 'IoU', \\\n"
        "     '%s/band.dat' index 3 using 1:3 with linespoints lw 2 title 'BF 3px'\n"
        "set output '%s/sequences.png'.sfx\nset title 'Mask IoU per sequence and method'\n"
        "set style data histograms\nset style histogram clustered gap 1\n"
        "set style fill solid 0.8 border -1\nset yrange [0:1.15]\nset key top center horizontal\n"
        "set xlabel 'sequence'\nset ylabel 'mask IoU'\n"
        "plot '%s/sequences.dat' using 2:xtic(1) title 'kin', '' using 3 title 'kin-cal-pred', "
        "'' using 4 title 'skin', '' using 5 title 'refine'\n",
        dir, dir, dir, dir, dir, dir, dir, (double)o->latency, dir, dir, (double)o->noise, dir,
        dir, dir, dir, dir, dir, dir, dir);
    if (out_commit(&of)) return EXIT_FAIL;
    return write_charts(dir);
}

/* ---------------------------------------------------------------- run */

/* Runs configurations cfgs[0..n) into R on `frames` frames of sequence
 * seq (one ground truth). The context is left in *c for the caller to
 * free. */
static int run_batch(const eval_opts *o, eval_ctx *c, const char *seq, int frames,
                     const method_cfg *cfgs, method_run *R, int n)
{
    method_cfg base = base_cfg(o, M_KIN_CAL);
    int irc = ctx_init(c, (uint64_t)o->seed, seq, &base.track);
    if (irc < 0)
        return irc == -2 ? EXIT_FAIL : cli_fail("cannot build the ground truth (out of memory)");
    int rc = EXIT_FAIL;
    int inited = 0;
    for (; inited < n; inited++)
        if (run_init(&R[inited], &cfgs[inited], c) < 0) { cli_fail("out of memory"); goto done; }
    progress pr;
    progress_start(&pr, frames);
    if (o->quiet) pr.enabled = 0;
    for (int f = 0; f < frames; f++) {
        if (make_truth(c, f, o->speed, f == 0) < 0) { cli_fail("frame %d: ground truth", f); goto done; }
        for (int i = 0; i < n; i++)
            if (run_frame(c, &R[i], f, o->per_frame, o->dump) < 0) {
                cli_fail("frame %d: %s %s failed", f, kind_name[R[i].cfg.kind], R[i].cfg.setting);
                goto done;
            }
        char what[64];
        snprintf(what, sizeof what, "eval %s frame", seq);
        progress_step(&pr, f + 1, what);
    }
    progress_end(&pr);
    rc = EXIT_OK;
done:
    for (int i = 0; i < inited; i++) run_free(&R[i]);
    return rc;
}

static int eval_run(const eval_opts *o)
{
    if (o->dump && cli_mkdirs(o->dump) != 0)
        return cli_fail("%s: cannot create the folder", o->dump);
    if (o->report && cli_mkdirs(o->report) != 0)
        return cli_fail("%s: cannot create the report folder", o->report);
    enum { CAP = 160 };
    method_cfg *cfgs = calloc(CAP, sizeof *cfgs);
    method_run *R = calloc(CAP, sizeof *R);
    eval_ctx c;
    memset(&c, 0, sizeof c);
    int n = 0, rc = EXIT_FAIL;
    if (!cfgs || !R) { cli_fail("out of memory"); goto done; }
    /* batches: (sequence, frames, phase) */
    const char *bseq[8];
    int bframes[8], bphase[8], nb = 0;
    bseq[nb] = o->sequence; bframes[nb] = o->frames; bphase[nb++] = PH_METHODS;
    if (o->report) {
        bseq[nb] = o->sequence; bframes[nb] = o->sweep_frames; bphase[nb++] = PH_KNOBS;
        bseq[nb] = o->sequence; bframes[nb] = o->sweep_frames; bphase[nb++] = PH_TRACK;
        for (int q = 0; gt_sequence_name(q) && nb < 8; q++) {
            const char *name = gt_sequence_name(q);
            if (!strcmp(name, o->sequence) || !strcmp(name, "calib")) continue;
            bseq[nb] = name; bframes[nb] = o->seq_frames; bphase[nb++] = PH_SEQ;
        }
    }
    for (int b = 0; b < nb; b++) {
        int m = make_configs(o, bphase[b], bseq[b], cfgs + n, CAP - n);
        if (n + m > CAP) { cli_fail("too many configurations"); goto done; }
        ctx_free(&c);
        if (run_batch(o, &c, bseq[b], bframes[b], cfgs + n, R + n, m)) goto done;
        if (b == 0 || !o->quiet) {
            printf("egofuse eval: sequence %s, %d frames, tracking noise %g mm, latency %g ms, "
                   "dropout %g, calibration error %g, speed %g; means per eye (640x400 masks)\n",
                   bseq[b], bframes[b], (double)o->noise, (double)o->latency,
                   (double)o->dropout, (double)o->calib_error, (double)o->speed);
            if (b == 0) print_calib(stdout, &c);
            print_table(stdout, R + n, m, 0);
            print_thickness(stdout, &c, R + n, m);
        }
        n += m;
    }
    if (o->csv && write_csv(o->csv, R, n)) goto done;
    if (o->report && write_report(o->report, R, n, o, &c)) goto done;
    if (o->report) printf("egofuse eval: report in %s (summary.csv, table.md, *.png)\n", o->report);
    rc = EXIT_OK;
done:
    ctx_free(&c);
    free(R);
    free(cfgs);
    return rc;
}

enum { O_FRAMES = 256, O_NOISE, O_LATENCY, O_DROPOUT, O_CALIB, O_SPEED, O_SEED, O_PERFRAME,
       O_CSV, O_REPORT, O_QUIET, O_DUMP, O_METHODS, O_BAND, O_SEQUENCE, O_SWEEP_FRAMES,
       O_SEQ_FRAMES, O_GLOBAL };

/* "kin,refine" -> bits of method_kind; 0 when a name is unknown. */
static unsigned parse_methods(const char *list)
{
    unsigned bits = 0;
    const char *p = list;
    while (*p) {
        size_t n = strcspn(p, ",");
        int found = 0;
        for (int k = 0; k < 4; k++)
            if (strlen(kind_name[k]) == n && !strncmp(p, kind_name[k], n)) {
                bits |= 1u << k;
                found = 1;
            }
        if (!found) return 0;
        p += n;
        if (*p == ',') p++;
    }
    return bits;
}

int cmd_eval(int argc, char **argv)
{
    static const struct option opts[] = {
        {"frames", required_argument, 0, O_FRAMES},
        {"noise", required_argument, 0, O_NOISE},
        {"latency", required_argument, 0, O_LATENCY},
        {"dropout", required_argument, 0, O_DROPOUT},
        {"calib-error", required_argument, 0, O_CALIB},
        {"speed", required_argument, 0, O_SPEED},
        {"seed", required_argument, 0, O_SEED},
        {"per-frame", no_argument, 0, O_PERFRAME},
        {"csv", required_argument, 0, O_CSV},
        {"report", required_argument, 0, O_REPORT},
        {"quiet", no_argument, 0, O_QUIET},
        {"dump", required_argument, 0, O_DUMP},
        {"methods", required_argument, 0, O_METHODS},
        {"band", required_argument, 0, O_BAND},
        {"sequence", required_argument, 0, O_SEQUENCE},
        {"sweep-frames", required_argument, 0, O_SWEEP_FRAMES},
        {"seq-frames", required_argument, 0, O_SEQ_FRAMES},
        {"global", required_argument, 0, O_GLOBAL},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    eval_opts o = { 60, 0, 0, 5.0f, 20.0f, 0.02f, 0.0f, 1.0f, 1, NULL, NULL, NULL, 15u,
                    GEN_ANIM_NAME, 60, 90, 0.5f, 16 };
    optind = 1;
    opterr = 0;
    int ch;
    float v;
    while ((ch = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (ch) {
        case 'h': fputs(eval_usage, stdout); return EXIT_OK;
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 100000, &o.frames))
                return cli_usage_error("eval", "--frames '%s': not a positive count", optarg);
            break;
        case O_NOISE:
            if (!cli_parse_float(optarg, &v) || v < 0.0f || v > 200.0f)
                return cli_usage_error("eval", "--noise '%s': not in 0..200 mm", optarg);
            o.noise = v;
            break;
        case O_LATENCY:
            if (!cli_parse_float(optarg, &v) || v < 0.0f || v > 1000.0f)
                return cli_usage_error("eval", "--latency '%s': not in 0..1000 ms", optarg);
            o.latency = v;
            break;
        case O_DROPOUT:
            if (!cli_parse_float(optarg, &v) || v < 0.0f || v > 1.0f)
                return cli_usage_error("eval", "--dropout '%s': not in 0..1", optarg);
            o.dropout = v;
            break;
        case O_CALIB:
            if (!cli_parse_float(optarg, &v) || v < -0.3f || v > 0.3f)
                return cli_usage_error("eval", "--calib-error '%s': not in -0.3..0.3", optarg);
            o.calib_error = v;
            break;
        case O_SPEED:
            if (!cli_parse_float(optarg, &v) || v < 0.1f || v > 10.0f)
                return cli_usage_error("eval", "--speed '%s': not in 0.1..10", optarg);
            o.speed = v;
            break;
        case O_SEED:
            if (!cli_parse_int(optarg, 0, 1 << 30, &o.seed))
                return cli_usage_error("eval", "--seed '%s': not a number", optarg);
            break;
        case O_PERFRAME: o.per_frame = 1; break;
        case O_CSV: o.csv = optarg; break;
        case O_REPORT: o.report = optarg; break;
        case O_QUIET: o.quiet = 1; break;
        case O_DUMP: o.dump = optarg; break;
        case O_METHODS:
            o.methods = parse_methods(optarg);
            if (!o.methods)
                return cli_usage_error("eval", "--methods '%s': not a list of kin, "
                                       "kin-cal-pred, skin, refine", optarg);
            break;
        case O_SEQUENCE: {
            int known = 0;
            for (int i = 0; gt_sequence_name(i); i++)
                known |= !strcmp(optarg, gt_sequence_name(i)) && strcmp(optarg, "calib");
            if (!known)
                return cli_usage_error("eval", "--sequence '%s': not one of reach_grasp, cross, "
                                       "near, edge, fast", optarg);
            o.sequence = optarg;
            break;
        }
        case O_SWEEP_FRAMES:
            if (!cli_parse_int(optarg, 1, 100000, &o.sweep_frames))
                return cli_usage_error("eval", "--sweep-frames '%s': not a positive count", optarg);
            break;
        case O_GLOBAL:
            if (!cli_parse_float(optarg, &v) || v < 0.0f || v > 1.0f)
                return cli_usage_error("eval", "--global '%s': not in 0..1", optarg);
            o.global = v;
            break;
        case O_SEQ_FRAMES:
            if (!cli_parse_int(optarg, 1, 100000, &o.seq_frames))
                return cli_usage_error("eval", "--seq-frames '%s': not a positive count", optarg);
            break;
        case O_BAND:
            if (!cli_parse_int(optarg, 1, 64, &o.band))
                return cli_usage_error("eval", "--band '%s': not in 1..64 px", optarg);
            break;
        case ':': return cli_usage_error("eval", "option %s needs a value", argv[optind - 1]);
        default: return cli_usage_error("eval", "unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind < argc) return cli_usage_error("eval", "unexpected argument '%s'", argv[optind]);
    return eval_run(&o);
}

