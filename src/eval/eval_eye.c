/* eval_eye.c - the eye's viewpoint in `egofuse eval --eyeview` (eval.h,
 * docs/accuracy.md "The eye's viewpoint", issue 18 item 5).
 *
 * The HMD's cameras sit D = 85 mm in front of the eyes. The paper's
 * correction (eq. 2-4: the 640x400 crop scaled into the 1194x746 viewport)
 * is exact only for a plane F = 1 m from the eyes; this measures how far
 * off each way of showing the camera's hand is, against ground truth
 * rendered from the TRUE eye (samples/gt/gt_eye.h):
 *   per distance (sequences hold15, hold20, hold30, hold40: the right hand
 *   held 15-40 cm in front of the eyes, palm towards them, swaying 1-2 cm),
 *   per tracking noise (0, 5, 10, 20 mm; no latency, no dropouts; at 0 mm
 *   no rotation or glove noise either) and per view method:
 *     crop     the paper's crop and scale (today's pipeline, eq. 1-4);
 *     reproj   the reprojection to the eye (pipe_desc.eye_view
 *              PIPE_VIEW_REPROJECT), once it is merged;
 *   the hand's position error (centroid of the hands' part of the output
 *   silhouette against the true eye-view one, display pixels), its size
 *   error (sqrt of their area ratio - 1, and the bounding-box height
 *   ratio - 1), the IoU of the output silhouette against the true eye-view
 *   silhouette of the arms (over the 1280x800 display), the composite's
 *   PSNR against the ideal eye-view composite (the true arms seen from the
 *   eye, relit and composited over V by the same lighting layer), and the
 *   method's time per stereo frame (thread CPU time: pose, skin, per eye
 *   raster, lighting, view transfer and composite).
 *
 * The true operator here has the mask model's proportions (no
 * subdivision): the errors measured are those of the viewpoint and the
 * tracking, not of the model's shape (the main evaluation measures that).
 * The hands' part of a method's output is its mask model's hand triangles
 * drawn by the same method (gt_hand_triangles), so the arm that enters
 * the view from below does not weigh in the hand's position and size. */
#include "eval_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../../samples/gt/gt_eye.h"
#include "../io/io.h"
#include "../io/io_term.h"
#include "../fuse/fuse_moments.h"

enum { DW = GEN_VIRT_W, DH = GEN_VIRT_H };

typedef enum eye_method { EM_CROP, EM_REPROJ, EM_COUNT } eye_method;
static const char *em_name[EM_COUNT] = { "crop", "reproj" };

static const int dist_cm[] = { 15, 20, 30, 40 };
enum { NDIST = sizeof dist_cm / sizeof dist_cm[0] };
static const float noise_mm[] = { 0.0f, 5.0f, 10.0f, 20.0f };
enum { NNOISE = sizeof noise_mm / sizeof noise_mm[0] };

/* Below this many pixels a hand is not compared (out of view). */
#define MIN_HAND_PX 200

typedef struct eye_run {
    eye_method method;
    int dist;                /* nominal cm */
    float noise;             /* mm */
    gt_track_desc track;
    int next_k;
    int have;
    kin_filter filter;
    kin_transform *locals;
    /* sums over frames and eyes */
    double pos, size, size_abs, height, iou, iou_seen, mse, secs, depth;
    long n_shape, n_eye, n_frames, n_depth;
    long fallbacks;          /* reprojection: eye-frames that fell back to the crop */
} eye_run;

typedef struct eye_ctx {
    gen_arms mask, truth;
    gen_scene cockpit, workshop;
    gen_frame_ctx g;
    kin_arm_rig rig;
    kin_sthmd_geometry geo;
    uint32_t *hand_m, *hand_t;   /* hand triangles of the mask model, the truth */
    int ntri_m, ntri_t;
    eval_pose ps;
    uint8_t *P[2], *V[2], *ideal[2], *sil[2], *hand[2], *seen[2];
    double hand_depth[2];
    float *vdepth, *enrm, *scratch;
    uint8_t *vrgb, *eye_rgba;
    uint8_t *cam_full[2];        /* the camera images, RGBA 640x480 */
    /* the methods: one pipe each (pipe_desc.eye_view), one thread */
    pipe_ctx *pipe[EM_COUNT];
    pipe_lighting light;
    /* method scratch */
    uint8_t *mask_c, *hmask_c, *layer, *out[2], *disp, *disp_sil, *disp_hand, *black, *white;
    float *depth_c, *nrm_c;
} eye_ctx;

static void ctx_free(eye_ctx *c)
{
    for (int k = 0; k < EM_COUNT; k++) pipe_destroy(c->pipe[k]);
    gen_frame_ctx_free(&c->g);
    gen_arms_free(&c->truth);
    gen_arms_free(&c->mask);
    gen_scene_free(&c->cockpit);
    gen_scene_free(&c->workshop);
    free(c->hand_m); free(c->hand_t);
    eval__pose_free(&c->ps);
    for (int e = 0; e < 2; e++) {
        free(c->P[e]); free(c->V[e]); free(c->ideal[e]); free(c->sil[e]); free(c->hand[e]);
        free(c->cam_full[e]); free(c->out[e]); free(c->seen[e]);
    }
    free(c->vdepth); free(c->enrm); free(c->scratch); free(c->vrgb); free(c->eye_rgba);
    free(c->mask_c); free(c->hmask_c); free(c->layer); free(c->disp);
    free(c->disp_sil); free(c->disp_hand); free(c->black); free(c->white);
    free(c->depth_c); free(c->nrm_c);
    memset(c, 0, sizeof *c);
}

/* -1: out of memory or a model error (message printed). */
static int ctx_init(eye_ctx *c, uint64_t seed, const char *seq)
{
    memset(c, 0, sizeof *c);
    c->geo = kin_sthmd_geometry_of(NULL);
    gt_operator_desc same = { 1, 1, 1, 1, 1, 1, 1, 0 };
    if (gen_arms_build(&c->mask) < 0 || gt_truth_build(&c->mask, &same, &c->truth) < 0 ||
        gt_cockpit_build(&c->cockpit) < 0 || gen_scene_workshop(&c->workshop, &c->mask) < 0 ||
        gen_frame_ctx_init(&c->g, &c->truth, &c->cockpit, &c->workshop, seed) < 0)
        return io_term_fail("cannot build the ground truth (out of memory)");
    if (gt_sequence_build(&c->mask, seq, &c->truth) < 0)
        return io_term_fail("sequence %s: cannot build it", seq);
    char why[256];
    if (kin_arm_rig_init(&c->rig, &c->mask.model, why, sizeof why) < 0)
        return io_term_fail("mask model: %s", why);
    c->hand_m = gt_part_triangles(&c->mask, 2u, GEN_J_MIDDLE_3, GEN_J_MIDDLE_3, &c->ntri_m);
    c->hand_t = gt_part_triangles(&c->truth, 2u, GEN_J_MIDDLE_3, GEN_J_MIDDLE_3, &c->ntri_t);
    const kin_model *m = &c->mask.model;
    const size_t cp = (size_t)CW * CH, dp = (size_t)DW * DH;
    int ok = eval__pose_init(&c->ps, m, m->meshes[0].vertex_count) == 0 && c->hand_m && c->hand_t;
    for (int e = 0; e < 2 && ok; e++) {
        c->P[e] = malloc(cp * 4);
        c->V[e] = malloc(dp * 4);
        c->ideal[e] = malloc(dp * 4);
        c->sil[e] = malloc(dp);
        c->hand[e] = malloc(dp);
        c->cam_full[e] = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 4);
        c->out[e] = malloc(dp * 4);
        c->seen[e] = malloc(dp);
        ok = c->seen[e] && c->P[e] && c->V[e] && c->ideal[e] && c->sil[e] && c->hand[e] && c->cam_full[e] &&
             c->out[e];
    }
    c->vdepth = malloc(sizeof(float) * dp);
    c->enrm = malloc(sizeof(float) * 3 * dp);
    c->scratch = malloc(sizeof(float) * dp);
    c->vrgb = malloc(dp * 3);
    c->eye_rgba = malloc(dp * 4);
    c->mask_c = malloc(cp);
    c->hmask_c = malloc(cp);
    c->layer = malloc(dp * 4);
    c->disp = malloc(dp * 4);
    c->disp_hand = malloc(dp);
    c->disp_sil = malloc(dp);
    c->black = malloc(dp * 4);
    c->white = malloc(cp * 4);
    c->depth_c = malloc(sizeof(float) * cp);
    c->nrm_c = malloc(sizeof(float) * 3 * cp);
    ok = ok && c->vdepth && c->enrm && c->scratch && c->vrgb && c->eye_rgba && c->mask_c &&
         c->hmask_c && c->layer && c->disp && c->disp_sil && c->disp_hand && c->black && c->white &&
         c->depth_c && c->nrm_c;
    if (!ok) return io_term_fail("out of memory");
    for (int k = 0; k < EM_COUNT; k++) {
        pipe_desc pd;
        memset(&pd, 0, sizeof pd);
        pd.threads = 1;
        pd.eye_view = k == EM_CROP ? PIPE_VIEW_CROP : PIPE_VIEW_REPROJECT;
        c->pipe[k] = pipe_create(&pd, m);
        if (!c->pipe[k]) return io_term_fail("the %s pipeline: cannot create it", em_name[k]);
    }
    /* the workshop's lights in world space (pipe_frame turns them into
     * each view's space) */
    kin_camera id;
    memset(&id, 0, sizeof id);
    id.view = kin_mat4_identity();
    c->light.light = eval__lighting(&c->workshop, &id);
    for (size_t i = 0; i < dp; i++) {
        c->black[i * 4 + 0] = c->black[i * 4 + 1] = c->black[i * 4 + 2] = 0;
        c->black[i * 4 + 3] = 255;
    }
    return 0;
}

/* ------------------------------------------------------- ground truth */

static int make_truth(eye_ctx *c, int fi)
{
    float t = (float)fi / (float)GEN_FPS;
    kin_mat4 wfh;
    gen_pose(&c->g, t, &wfh);
    for (int e = 0; e < 2; e++) {
        /* the camera image (sil, normals: the camera's, unused here) */
        gt_render_eye(&c->g, &wfh, (kin_eye)e, fi, c->ps.cam_rgb, c->mask_c, NULL, c->ps.gt_depth,
                      c->ps.gt_mask);
        const uint8_t *src = c->ps.cam_rgb + (size_t)c->geo.crop_y0 * GEN_CAM_W * 3;
        if (fuse_rgb24_to_rgba(src, GEN_CAM_W * 3, CW, CH,
                               &(fuse_image){ c->P[e], CW, CH, 4 * CW }) != FUSE_OK ||
            fuse_rgb24_to_rgba(c->ps.cam_rgb, GEN_CAM_W * 3, GEN_CAM_W, GEN_CAM_H,
                               &(fuse_image){ c->cam_full[e], GEN_CAM_W, GEN_CAM_H,
                                              4 * GEN_CAM_W }) != FUSE_OK)
            return -1;
        gen_render_virtual(&c->g, &wfh, (kin_eye)e, fi, c->vrgb, c->vdepth);
        fuse_image V = { c->V[e], DW, DH, 4 * DW };
        if (fuse_rgb24_to_rgba(c->vrgb, DW * 3, DW, DH, &V) != FUSE_OK) return -1;
        /* the arms from the true eye, and the ideal composite */
        kin_camera ec = gt_eye_camera(NULL, &wfh, (kin_eye)e);
        gt_render_view(&c->g, &ec, c->hand_t, c->ntri_t, c->eye_rgba, c->sil[e], c->hand[e],
                       c->enrm, c->scratch, &c->hand_depth[e]);
        kin_camera tc = kin_sthmd_camera(NULL, &wfh, (kin_eye)e);
        gt_view_seen_by(&c->g, &ec, GEN_VIRT_ZNEAR, GEN_VIRT_ZFAR, &tc, c->sil[e], c->seen[e]);
        fuse_lighting L = eval__lighting(&c->workshop, &ec);
        fuse_intrinsics K = { ec.fx, ec.fy, ec.cx, ec.cy };
        fuse_image P = { c->eye_rgba, DW, DH, 4 * DW }, Q = { c->layer, DW, DH, 4 * DW };
        fuse_image I = { c->ideal[e], DW, DH, 4 * DW };
        if (fuse_light(&L, &K, &P, c->sil[e], DW, c->enrm, 3 * DW, &Q) != FUSE_OK ||
            fuse_composite(&Q, &V, 0, 0, DW, DH, &I) != FUSE_OK)
            return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ methods */

static double thread_secs(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The display silhouette of a view layer's mask (w x h) composited into
 * the display at (x0, y0, vw, vh) (the crop: the viewport; the
 * reprojection: the whole display): the mask as a premultiplied white
 * layer over opaque black, by the pipeline's own resampling
 * (fuse_composite); 255 where the result is >= 128. dst: DW x DH bytes. */
static int layer_to_display(eye_ctx *c, const uint8_t *mask, int w, int h, int x0, int y0,
                            int vw, int vh, uint8_t *dst)
{
    for (size_t i = 0; i < (size_t)w * h; i++)
        memset(&c->white[i * 4], mask[i], 4);
    fuse_image Q = { c->white, w, h, 4 * w }, B = { c->black, DW, DH, 4 * DW };
    fuse_image O = { c->disp, DW, DH, 4 * DW };
    if (fuse_composite(&Q, &B, x0, y0, vw, vh, &O) != FUSE_OK) return -1;
    for (size_t i = 0; i < (size_t)DW * DH; i++) dst[i] = c->disp[i * 4] >= 128 ? 255 : 0;
    return 0;
}

static int run_init(eye_run *r, const eye_ctx *c)
{
    r->next_k = -(int)ceilf(r->track.rate_hz);
    kin_filter_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.no_lag_comp = 1;     /* as egofuse configures it (eval.c) */
    kin_filter_init(&r->filter, &fd);
    r->locals = malloc(sizeof *r->locals * (size_t)c->mask.model.node_count);
    if (!r->locals) return -1;
    kin_pose_rest(&c->mask.model, r->locals);
    return 0;
}

/* DIR/eye_hold<cm>_<method>_<noise>mm_<eye>_NNNN.png: red = the true
 * eye-view silhouette, green = the method's output silhouette, blue = the
 * true hand (full) and the method's hand (half). */
static int dump_view(const char *dir, const eye_run *r, int fi, int e, const uint8_t *tsil,
                     const uint8_t *msil, const uint8_t *thand, const uint8_t *mhand,
                     uint8_t *rgb)
{
    for (size_t i = 0; i < (size_t)DW * DH; i++) {
        rgb[i * 3 + 0] = tsil[i];
        rgb[i * 3 + 1] = msil[i];
        rgb[i * 3 + 2] = (uint8_t)((thand[i] ? 160 : 0) + (mhand[i] ? 95 : 0));
    }
    char path[IO_PATH_MAX + 128];
    snprintf(path, sizeof path, "%s/eye_hold%d_%s_%gmm_%s_%04d.png", dir, r->dist,
             em_name[r->method], (double)r->noise, e ? "right" : "left", fi);
    io_image img = { rgb, DW, DH, 3, IO_U8, (size_t)DW * 3 };
    io_error err;
    if (io_image_save(path, &img, &err) != IO_OK) return io_term_fail("%s", err.msg);
    return IO_EXIT_OK;
}

/* One display frame fi of one configuration, both eyes, measured. */
static int run_frame(eye_ctx *c, eye_run *r, int fi, int per_frame, const char *dump)
{
    const double T = (double)fi / GEN_FPS;
    for (;;) {
        double tc = (double)r->next_k / r->track.rate_hz;
        if (tc + r->track.latency_ms * 1e-3 > T + 1e-9) break;
        kin_track_sample s;
        gt_track_sample(&c->truth, &r->track, r->next_k, c->ps.tlocals, c->ps.tworld, &s);
        r->next_k++;
        kin_filter_push(&r->filter, &s);
        r->have = 1;
    }
    const kin_model *m = &c->mask.model;
    const kin_mesh *me = &m->meshes[0];
    int posed = 0;
    if (r->noise == 0.0f) {
        /* perfect tracking: the true pose (the view's error alone) */
        memcpy(r->locals, c->g.locals, sizeof *r->locals * (size_t)m->node_count);
        posed = 1;
    } else if (r->have) {
        kin_track_sample s;
        kin_filter_output(&r->filter, T, &s, NULL);
        posed = kin_arm_rig_pose(&c->rig, m, NULL, NULL, &s, r->locals, NULL);
        /* the fingers as the truth's (perfect gloves): the fingertip's
         * error is then the tracked hand's, not the glove model's */
        for (int sd = 0; sd < 2 && posed; sd++)
            for (int j = GEN_J_THUMB_1; j < GEN_SIDE_JOINTS; j++)
                r->locals[c->mask.joint[sd][j]] = c->g.locals[c->mask.joint[sd][j]];
    }
    /* the method: one stereo frame of the pipeline, timed (this thread's
     * CPU time: pipe_desc.threads 1, the machine may be shared) */
    pipe_ctx *p = c->pipe[r->method];
    pipe_frame_in in;
    memset(&in, 0, sizeof in);
    in.locals = r->locals;
    in.head_node = c->mask.head;
    in.lighting = c->light;
    for (int e = 0; e < 2; e++) {
        in.camera[e] = (fuse_image){ c->cam_full[e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W };
        in.virt[e] = (fuse_image){ c->V[e], DW, DH, 4 * DW };
        in.out[e] = (fuse_image){ c->out[e], DW, DH, 4 * DW };
    }
    pipe_frame_stats st;
    char why[256];
    double t0 = thread_secs();
    if (pipe_frame(p, &in, &st, why, sizeof why) != PIPE_OK) return io_term_fail("%s", why);
    double secs = thread_secs() - t0;
    /* the posed model, for its fingertip (not timed) */
    kin_fk(m->parents, m->node_count, r->locals, NULL, c->ps.world);
    kin_skin_joint_matrices(&m->skins[0], c->ps.world, c->ps.jm);
    kin_skin_lbs(me, c->ps.jm, c->ps.pos, c->ps.nrm);
    (void)posed;
    for (int e = 0; e < 2; e++) {
        /* the view layer's mask and camera, and where it goes */
        int w = 0, h = 0, x0 = 0, y0 = 0, vw = DW, vh = DH;
        const uint8_t *M;
        kin_camera cam;
        if (st.view[e] != (r->method == EM_CROP ? PIPE_VIEW_CROP : PIPE_VIEW_REPROJECT))
            r->fallbacks++;   /* the eye inside the model: the crop this frame */
        if (st.view[e] == PIPE_VIEW_REPROJECT) {
            M = pipe_view_mask(p, e, &w, &h);
            cam = pipe_view_camera(p, e);
        } else {
            M = pipe_mask(p, e, &w, &h);
            cam = pipe_camera(p, e);
            x0 = c->geo.vp_x0;
            y0 = c->geo.vp_y0;
            vw = c->geo.vp_width;
            vh = c->geo.vp_height;
        }
        if (!M || w != CW || h != CH) return io_term_fail("the %s pipeline: no mask", em_name[r->method]);
        uint8_t *sil = c->disp_sil;
        if (layer_to_display(c, M, w, h, x0, y0, vw, vh, sil) < 0) return -1;
        fuse_confusion cf;
        fuse_mask_confusion(sil, DW, c->sil[e], DW, DW, DH, &cf);
        double iou = fuse_confusion_iou(&cf);
        fuse_mask_confusion(sil, DW, c->seen[e], DW, DW, DH, &cf);
        double iou_seen = fuse_confusion_iou(&cf);
        /* the fingertip's part of the layer: the model's fingertip drawn
         * through the layer's camera, where the layer shows the hand */
        rast_target th = { CW, CH, c->depth_c, CW, c->hmask_c, CW, NULL, 0, 0, NULL, 0 };
        rast_target_clear(&th);
        rast_transform_points(cam.view_proj.m, c->ps.pos, me->vertex_count, c->ps.clip);
        rast_mesh_desc dh = { c->ps.clip, me->vertex_count, NULL, 0, c->hand_m, c->ntri_m,
                              RAST_CULL_NONE };
        if (rast_draw(&th, &dh, NULL) != RAST_OK) return -1;
        for (size_t i = 0; i < (size_t)CW * CH; i++)
            c->hmask_c[i] = c->hmask_c[i] && M[i] >= 128 ? 255 : 0;
        if (layer_to_display(c, c->hmask_c, CW, CH, x0, y0, vw, vh, c->disp_hand) < 0) return -1;
        fuse_moments mm, mt;
        fuse_mask_moments(c->disp_hand, DW, DW, DH, &mm);
        fuse_mask_moments(c->hand[e], DW, DW, DH, &mt);
        fuse_shape_error se;
        int have_shape = fuse_shape_compare(&mm, &mt, MIN_HAND_PX, &se);
        double mse = fuse_mse(c->out[e], 4 * DW, c->ideal[e], 4 * DW, DW, DH, 4, 3);
        if (dump && dump_view(dump, r, fi, e, c->sil[e], sil, c->hand[e], c->disp_hand, c->vrgb))
            return -1;
        if (have_shape) {
            r->pos += se.pos_px;
            r->size += se.size;
            r->size_abs += fabs(se.size);
            r->height += se.height;
            r->n_shape++;
        }
        if (mt.area >= MIN_HAND_PX) {
            r->depth += c->hand_depth[e];
            r->n_depth++;
        }
        r->iou += iou;
        r->iou_seen += iou_seen;
        r->mse += mse;
        r->n_eye++;
        if (per_frame)
            printf("%4d %-5s %-6s d=%2dcm noise %4.1fmm hand depth %.3f m pos %6.2f px size %+6.2f%%"
                   " height %+6.2f%% iou %.4f psnr %5.2f%s\n",
                   fi, e ? "right" : "left", em_name[r->method], r->dist, (double)r->noise,
                   c->hand_depth[e], have_shape ? se.pos_px : NAN,
                   have_shape ? 100.0 * se.size : NAN, have_shape ? 100.0 * se.height : NAN, iou,
                   fuse_psnr_of_mse(mse),
                   st.view[e] != (r->method == EM_CROP ? PIPE_VIEW_CROP : PIPE_VIEW_REPROJECT)
                       ? " (fell back to the crop)" : "");
    }
    r->secs += secs;
    r->n_frames++;
    return 0;
}

/* ------------------------------------------------------------- report */

typedef struct eye_sum {
    double pos, size, size_abs, height, iou, iou_seen, psnr, ms, depth_cm;
} eye_sum;

static eye_sum summarise(const eye_run *r)
{
    eye_sum s;
    double ns = r->n_shape ? (double)r->n_shape : NAN;
    double ne = r->n_eye ? (double)r->n_eye : NAN;
    s.pos = r->pos / ns;
    s.size = 100.0 * r->size / ns;
    s.size_abs = 100.0 * r->size_abs / ns;
    s.height = 100.0 * r->height / ns;
    s.iou = r->iou / ne;
    s.iou_seen = r->iou_seen / ne;
    s.psnr = fuse_psnr_of_mse(r->mse / ne);
    s.ms = r->n_frames ? 1e3 * r->secs / (double)r->n_frames : NAN;
    s.depth_cm = r->n_depth ? 100.0 * r->depth / (double)r->n_depth : NAN;
    return s;
}

/* The crop's size error predicted by the geometry for a small object z
 * metres in front of the eyes (on the view axis, the camera's axis
 * parallel, D in front): the crop shows the camera's angle tan a = X /
 * (z - D) at display offset vp/crop * fc * tan a, the eye sees it at
 * f_eye * X / z; per axis k = (vp / crop) fc / f_eye, the ratio k z / (z -
 * D), 1 at z = F = 1 m (eq. 2-4); from the areas sqrt(kx ky) z / (z - D). */
static double crop_predicted(const eye_ctx *c, double z)
{
    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    kin_camera cam = kin_sthmd_camera(&hd, NULL, KIN_EYE_LEFT);
    kin_camera ec = gt_eye_camera(&hd, NULL, KIN_EYE_LEFT);
    double kx = (double)c->geo.vp_width / CW * cam.fx / ec.fx;
    double ky = (double)c->geo.vp_height / CH * cam.fy / ec.fy;
    double D = hd.cam_offset_m;
    return 100.0 * (sqrt(kx * ky) * z / (z - D) - 1.0);
}

static void print_table(FILE *f, const eye_ctx *c, const eye_run *R, int n, int markdown)
{
    if (markdown)
        fprintf(f, "| hand at | hand depth | method | noise mm | position error px | size error %% "
                   "| abs size error %% | height error %% | crop geometry %% | IoU | IoU camera's view | "
                   "PSNR dB | ms/stereo frame |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    else
        fprintf(f, "%-7s %-9s %-6s %5s %9s %9s %9s %9s %9s %7s %7s %7s %8s\n", "hand at",
                "depth cm", "method", "noise", "pos px", "size %", "|size| %", "height %",
                "geom %", "IoU", "IoU cam", "PSNR", "ms");
    for (int i = 0; i < n; i++) {
        eye_sum s = summarise(&R[i]);
        double g = crop_predicted(c, s.depth_cm / 100.0);
        if (markdown)
            fprintf(f, "| %d cm | %.1f cm | %s | %g | %.2f | %+.1f | %.1f | %+.1f | %+.1f | %.4f | "
                       "%.4f | %.2f | %.2f |\n",
                    R[i].dist, s.depth_cm, em_name[R[i].method], (double)R[i].noise, s.pos, s.size,
                    s.size_abs, s.height, g, s.iou, s.iou_seen, s.psnr, s.ms);
        else
            fprintf(f, "%4d cm %9.1f %-6s %5g %9.2f %+9.1f %9.1f %+9.1f %+9.1f %7.4f %7.4f %7.2f "
                       "%8.2f\n",
                    R[i].dist, s.depth_cm, em_name[R[i].method], (double)R[i].noise, s.pos,
                    s.size, s.size_abs, s.height, g, s.iou, s.iou_seen, s.psnr, s.ms);
    }
}

/* dir/name, or (dir NULL) the file name */
static int write_csv(const char *dir, const char *name, const eye_ctx *c, const eye_run *R,
                     int n)
{
    io_out of;
    if (!eval__out_open(&of, dir, "%s", name)) return IO_EXIT_FAIL;
    fprintf(of.f, "distance_cm,hand_depth_cm,method,noise_mm,pos_px,size_pct,size_abs_pct,"
                  "height_pct,crop_geometry_pct,iou,iou_camera_view,psnr_db,ms_per_stereo_frame,"
                  "frames,eyes_with_hand,fallbacks\n");
    for (int i = 0; i < n; i++) {
        eye_sum s = summarise(&R[i]);
        fprintf(of.f, "%d,%.2f,%s,%g,%.3f,%.2f,%.2f,%.2f,%.2f,%.5f,%.5f,%.3f,%.3f,%ld,%ld,%ld\n",
                R[i].dist, s.depth_cm, em_name[R[i].method], (double)R[i].noise, s.pos, s.size,
                s.size_abs, s.height, crop_predicted(c, s.depth_cm / 100.0), s.iou, s.iou_seen,
                s.psnr, s.ms, R[i].n_frames, R[i].n_shape, R[i].fallbacks);
    }
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    return IO_EXIT_OK;
}

/* DIR/eyeview.csv, eyeview.md, eyeview.dat (gnuplot blocks: per method
 * and noise, rows of distance, position px, size %, IoU, PSNR, the crop's
 * predicted size %), eyeview.gp and the charts eyeview_pos.png,
 * eyeview_size.png, eyeview_iou.png. */
static int write_report(const char *dir, const eye_ctx *c, const eye_run *R, int n,
                        const eval_opts *o)
{
    if (write_csv(dir, "eyeview.csv", c, R, n)) return IO_EXIT_FAIL;
    io_out of;
    if (!eval__out_open(&of, dir, "eyeview.md")) return IO_EXIT_FAIL;
    int fr = o->frames < 180 ? o->frames : 180;
    fprintf(of.f, "Eye viewpoint: sequences hold15/20/30/40, %d frames each (one display frame "
                  "in %d of the 3 s), seed %d; tracking noise 0 (the true pose), 5, 10, 20 mm (One "
                  "Euro filter, arm IK, the true fingers), no latency, no dropouts. Position and "
                  "size: the middle fingertip's part of the output silhouette against the true "
                  "eye-view one (display px, 1280x800); IoU: the output silhouette against the "
                  "true eye-view silhouette of the arms, and against its part that the camera "
                  "sees; PSNR: against the ideal eye-view composite (whole display); crop "
                  "geometry: the crop's size error predicted for a point at the measured "
                  "fingertip depth; ms: pipe_frame, one thread, thread CPU time.\n\n",
            fr, 180 / fr, o->seed);
    print_table(of.f, c, R, n, 1);
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    if (!eval__out_open(&of, dir, "eyeview.dat")) return IO_EXIT_FAIL;
    int blocks = 0;
    char titles[EM_COUNT * NNOISE][48];
    for (int mth = 0; mth < EM_COUNT; mth++)
        for (int k = 0; k < NNOISE; k++) {
            int any = 0;
            for (int i = 0; i < n; i++) {
                if ((int)R[i].method != mth || R[i].noise != noise_mm[k]) continue;
                if (!any) fprintf(of.f, "# %s noise %g mm\n", em_name[mth], (double)noise_mm[k]);
                any = 1;
                eye_sum s = summarise(&R[i]);
                fprintf(of.f, "%d %.4f %.4f %.5f %.4f %.4f %.4f %.5f\n", R[i].dist, s.pos, s.size,
                        s.iou, s.psnr, crop_predicted(c, s.depth_cm / 100.0), s.size_abs,
                        s.iou_seen);
            }
            if (!any) continue;
            snprintf(titles[blocks++], sizeof titles[0], "%s, noise %g mm", em_name[mth],
                     (double)noise_mm[k]);
            fprintf(of.f, "\n\n");
        }
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    if (!eval__out_open(&of, dir, "eyeview.gp")) return IO_EXIT_FAIL;
    FILE *f = of.f;
    static const char *const charts[] = { "eyeview_pos", "eyeview_size", "eyeview_iou",
                                          "eyeview_psnr" };
    enum { NCH = sizeof charts / sizeof charts[0] };
    static const char *const ylab[NCH] = {
        "fingertip position error, display px (1280x800)",
        "fingertip size error, % (sqrt of the area ratio - 1)",
        "IoU against the eye-view silhouette where the camera sees",
        "composite PSNR against the ideal eye-view composite, dB" };
    static const char *const ttl[NCH] = {
        "Hand position error against distance from the eye",
        "Hand size error against distance from the eye",
        "Silhouette IoU (eye view, within the camera field of view) against distance",
        "Composite PSNR (eye view) against distance" };
    static const int col[NCH] = { 2, 3, 8, 5 };
    fprintf(f, "if (!exists('sfx')) sfx = ''\nset grid\n");
    for (int ch = 0; ch < NCH; ch++) {
        fprintf(f, "set terminal pngcairo noenhanced size 900,600 font ',11'\n"
                   "set output '%s/%s.png'.sfx\nset title '%s'\nset xlabel 'hand distance from "
                   "the eyes, cm'\nset ylabel '%s'\nset key top right box opaque\nset xrange [12:43]\n"
                   "set xtics (15, 20, 30, 40)\nset key %s right box opaque\n",
                dir, charts[ch], ttl[ch], ylab[ch], ch >= 2 ? "bottom" : "top");
        fprintf(f, "plot ");
        for (int b = 0; b < blocks; b++)
            fprintf(f, "%s'%s/eyeview.dat' index %d using 1:%d with linespoints lw 2 pt %d "
                       "lc %d dt %d title '%s'",
                    b ? ", \\\n     " : "", dir, b, col[ch], 7 + (b / NNOISE) * 2,
                    1 + b / NNOISE, 1 + b % NNOISE, titles[b]);
        if (ch == 1 && blocks > 0)
            fprintf(f, ", \\\n     '%s/eyeview.dat' index 0 using 1:6 with lines lw 2 lc rgb "
                       "'#000000' dt 2 title 'crop: geometry (eq. 2-4 exact at 1 m)'",
                    dir);
        if (!blocks) fprintf(f, "NaN notitle");
        fprintf(f, "\n");
    }
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    return eval__gnuplot(dir, "eyeview.gp", charts, NCH);
}

/* ---------------------------------------------------------------- run */

int eval_eye_run(const eval_opts *o)
{
    if (o->report && io_mkdirs(o->report) != 0)
        return io_term_fail("%s: cannot create the report folder", o->report);
    if (o->dump && io_mkdirs(o->dump) != 0)
        return io_term_fail("%s: cannot create the folder", o->dump);
    int methods[EM_COUNT] = { 1, 1 };
    int nm = 0;
    for (int k = 0; k < EM_COUNT; k++) nm += methods[k];
    const int n = NDIST * NNOISE * nm;
    eye_run *R = calloc((size_t)n, sizeof *R);
    eye_ctx c;
    memset(&c, 0, sizeof c);
    int rc = IO_EXIT_FAIL, i = 0;
    if (!R) return io_term_fail("out of memory");
    const int frames = o->frames < 180 ? o->frames : 180;
    const int stride = 180 / frames;
    io_progress pr;
    io_progress_start(&pr, NDIST * frames);
    if (o->quiet) pr.enabled = 0;
    for (int d = 0; d < NDIST; d++) {
        char seq[16];
        snprintf(seq, sizeof seq, "hold%d", dist_cm[d]);
        ctx_free(&c);
        if (ctx_init(&c, (uint64_t)o->seed, seq) < 0) goto done;
        int first = i;
        for (int mth = 0; mth < EM_COUNT; mth++) {
            if (!methods[mth]) continue;
            for (int k = 0; k < NNOISE; k++, i++) {
                eye_run *r = &R[i];
                r->method = (eye_method)mth;
                r->dist = dist_cm[d];
                r->noise = noise_mm[k];
                r->track = gt_track_default();
                r->track.noise_mm = noise_mm[k];
                r->track.latency_ms = 0.0f;
                r->track.dropout = 0.0f;
                r->track.seed = (uint64_t)o->seed;
                if (noise_mm[k] == 0.0f) {
                    r->track.rot_noise_deg = 0.0f;
                    r->track.head_rot_noise_deg = 0.0f;
                    r->track.glove_noise = 0.0f;
                }
                if (run_init(r, &c) < 0) { io_term_fail("out of memory"); goto done; }
            }
        }
        for (int f = 0; f < frames; f++) {
            int fi = f * stride;
            if (make_truth(&c, fi) < 0) { io_term_fail("%s frame %d: ground truth", seq, fi); goto done; }
            for (int j = first; j < i; j++)
                if (run_frame(&c, &R[j], fi, o->per_frame, o->dump) < 0) {
                    io_term_fail("%s frame %d: %s failed", seq, fi, em_name[R[j].method]);
                    goto done;
                }
            io_progress_step(&pr, d * frames + f + 1, "eval eye view frame");
        }
    }
    io_progress_end(&pr);
    printf("egofuse eval --eyeview: the right hand held 15-40 cm from the eyes (sequences "
           "holdNN), %d frames each, tracking noise 0-20 mm (no latency, no dropouts); "
           "errors of the hand in the 1280x800 display against the true eye's view\n",
           frames);
    print_table(stdout, &c, R, n, 0);
    if (o->csv && write_csv(NULL, o->csv, &c, R, n)) goto done;
    if (o->report && write_report(o->report, &c, R, n, o)) goto done;
    if (o->report) printf("egofuse eval --eyeview: report in %s (eyeview.csv, eyeview.md, eyeview_pos/size/iou/psnr.png)\n", o->report);
    rc = IO_EXIT_OK;
done:
    for (int j = 0; j < n; j++) free(R[j].locals);
    free(R);
    ctx_free(&c);
    return rc;
}
