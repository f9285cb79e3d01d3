/* pipe.c - one stereo frame, end to end (see pipe.h). */
#include "pipe.h"
#include "pipe_aa.h"
#include "pipe_morph.h"
#include "pipe_parts.h"
#include "pipe_internal.h"
#include "pipe_ctx.h"
#include "pipe_lens.h"
#include "pipe_nfill.h"
#include "pipe_soft.h"
#include "pipe_reproj.h"
#include "../cpu/ef_n10.h"
#include "../cpu/mask_rows.h"
#include "../fit/fit_band.h"
#include "../fit/fit_holes.h"
#include "../fit/fit_shift.h"
#include "../fit/fit_smooth.h"
#include "../cpu/ef_mem.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>


/* ------------------------------------------------------------- frames */

/* Below this many vertices, splitting the skinning costs more in the
 * hand-over than it saves: measured with the 7.8k-vertex sample arms
 * (make bench), FK + skinning took 0.089 ms on one thread and 0.155 ms
 * split over two. AVX-512 skins about 160k vertices per ms. */
#define PIPE_SPLIT_SKIN_VERTICES 65536

/* Output rows per band of an eye's fuse on two threads (eye_work): 13
 * bands per eye at the sample's 800-row outputs (0.1-0.3 ms each), so the
 * thread that finishes first waits little for the other's last band. Each
 * band costs a setup (the composite's column tables) and leaves 2-4 rows
 * at its border to the eye's tail (fuse_context_frame_finish): callgrind,
 * render of the sample, per eye-frame: +11% of the fuse's instructions
 * at 48 rows, +8% at 64, +6% at 96 (docs/bench.md). */
#define PIPE_BAND_ROWS 64

/* The clock of pipe_frame_stats: wall time, or with pipe_set_stats_clock
 * the calling thread's CPU time. */
static int stats_cpu_clock;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(stats_cpu_clock ? CLOCK_THREAD_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
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
    /* the reprojection samples the whole sensor: buf holds all its rows,
     * the crop's at their place (reproj_eye converts the others) */
    if (p->desc.eye_view == PIPE_VIEW_REPROJECT)
        buf += (size_t)4 * (size_t)p->hmd.cam_width * (size_t)p->geo.crop_y0;
    return (fuse_image){buf, p->hmd.cam_width, p->geo.crop_height, 4 * p->hmd.cam_width};
}

/* Draws the posed model (parts: with the cockpit's hidden parts and
 * props) into tg through cam: straight for a pinhole, else through the
 * eye's lens map (pipe_lens.h), which writes every pixel of tg. Returns
 * the raster's result; *covered: the mask pixels set (covered NULL: not
 * counted). */
static rast_result eye_draw(pipe_ctx *p, eye_state *e, const pipe_lens_map *lens,
                            const kin_camera *cam, const rast_target *tg, int parts,
                            long *covered)
{
    kin_camera pc;
    rast_target it = *tg;
    if (lens) {
        pc = pipe_lens_pinhole(lens, cam);
        cam = &pc;
        it = pipe_lens_target(lens);
    }
    /* only what the last frame drew; the normals not at all where every
     * reader skips the pixels of mask 0 (docs/raster.md section 13): the
     * lighting with the G-buffer's own mask, no lens warp, no refined or
     * anti-aliased mask reaching past it, no smoothing. The reprojection
     * too: the eye's normals are read where its mask is (the back-face
     * count; the lighting under M, which is 0 off the eye's mask), the
     * camera's only by the crop fallback's lighting under its own mask */
    if (!lens && p->desc.refine_band == 0 && p->desc.normal_smooth == 0 && e->aa.count == 0)
        rast_context_clear_keep_attr(e->rast, &it);
    else
        rast_context_clear(e->rast, &it);
    rast_result rr = parts && pipe__cockpit_active(p->ck)
                         ? pipe__cockpit_draw(p->ck, &p->pose, e->eye, e->rast, cam, &it,
                                              p->desc.cull, e->clip, e->vnrm)
                     : parts && p->lod
                         ? pipe_lod_draw(&p->pose, p->lod, p->lod_level, p->lod_px, e->rast, cam,
                                         &it, p->desc.cull, e->clip, e->vnrm, NULL, &e->lod_level)
                         : pipe_pose_draw(&p->pose, e->rast, cam, &it, p->desc.cull, e->clip,
                                          e->vnrm, NULL);
    if (rr != RAST_OK) return rr;
    /* Only the tiles the draws marked are read (the rest is clear);
     * covered NULL (the eye's view): not counted */
    if (lens) {
        long c = pipe_lens_warp(lens, tg);
        if (covered) *covered = c;
    } else if (covered) {
        *covered = rast_context_count(e->rast, &it);
    }
    return RAST_OK;
}

/* The camera's G-buffer as a target. Reprojecting (without a lens map),
 * nothing reads the camera's normals unless the eye falls back to the
 * crop: the lighting reads the eye's, the occlusion test the camera's
 * depth and mask. So its draws (run_eye's, the elbow fit's) write depth
 * and mask only; reproj_eye draws the normals for a fallback. */
/* The camera's G-buffer with its normals, packed or floats (pipe_create). */
static rast_target gbuf_target(const pipe_ctx *p, const eye_state *e)
{
    const int cw = p->geo.crop_width, ch = p->geo.crop_height;
    return (rast_target){cw, ch, e->depth, cw, e->mask, cw, e->nrm, e->nrm ? 3 * cw : 0, 3,
                         e->n10, e->n10 ? cw : 0};
}

static rast_target cam_target(const pipe_ctx *p, const eye_state *e)
{
    const int cw = p->geo.crop_width, ch = p->geo.crop_height;
    if (p->desc.eye_view == PIPE_VIEW_REPROJECT && !e->lens)
        return (rast_target){cw, ch, e->depth, cw, e->mask, cw, NULL, 0, 0, NULL, 0};
    return gbuf_target(p, e);
}

/* Reprojection (pipe_reproj.h): the model drawn from the eye, the camera
 * image sampled through the eye's depths; fe then lights and composites
 * the eye's view. 1 when fe was switched to it, 0 for the fallback to the
 * crop (the eye inside the model), -1 on a raster error (e->why set). */
static int reproj_eye(pipe_ctx *p, eye_state *e, fuse_eye *fe, fuse_intrinsics *K)
{
    pipe__reproj *r = &e->rp;
    const int w = r->width, h = r->height, cw = p->geo.crop_width, ch = p->geo.crop_height;
    r->cam = kin_sthmd_eye_camera(&p->hmd, &e->head, (kin_eye)e->eye, w, h);
    rast_target tg = {w, h, r->depth, w, r->mask, w, NULL, 0, 3, r->n10, w};
    int level = e->lod_level;
    rast_result rr = eye_draw(p, e, NULL, &r->cam, &tg, 1, NULL);
    e->lod_level = level;
    if (rr != RAST_OK)
        return pipe__eye_fail(e, PIPE_ERR_RASTER, "rasterizer (eye view)", rast_result_str(rr));
    r->isa = rast_context_isa(e->rast);
    /* the whole sensor (the rows above and below the crop of eq. 1 too):
     * the RGBA image as given, or the raw frame's other rows converted
     * around the crop's; else (an image of another size) the crop */
    const pipe_frame_in *in = e->in;
    const int cam_w = p->hmd.cam_width, cam_h = p->hmd.cam_height, y0 = p->geo.crop_y0;
    fuse_image S = fe->P;
    int ox = 0, oy = 0;
    if (in->camera_raw[e->eye].data) {
        fuse_image top = {e->cam_rgba, cam_w, y0, 4 * cam_w};
        fuse_image bot = {e->cam_rgba + (size_t)4 * cam_w * (size_t)(y0 + ch), cam_w,
                          cam_h - y0 - ch, 4 * cam_w};
        ef_isa isa = (ef_isa)p->desc.max_isa;
        if ((top.height <= 0 || fuse_frame_to_rgba_isa(&in->camera_raw[e->eye], 0, &top, isa) ==
                                    FUSE_OK) &&
            (bot.height <= 0 || fuse_frame_to_rgba_isa(&in->camera_raw[e->eye], y0 + ch, &bot,
                                                       isa) == FUSE_OK)) {
            S = (fuse_image){e->cam_rgba, cam_w, cam_h, 4 * cam_w};
            ox = p->geo.crop_x0, oy = y0;
        }
    } else if (in->camera[e->eye].pixels && in->camera[e->eye].width == cam_w &&
               in->camera[e->eye].height == cam_h) {
        S = in->camera[e->eye];
        ox = p->geo.crop_x0, oy = y0;
    }
    if (pipe__reproj_sample(r, &e->cam, &S, ox, oy, e->mask, cw, e->depth, cw, cw, ch,
                            p->hmd.znear, p->hmd.zfar)) {
        e->fallbacks++;
        if (!cam_target(p, e).attr) {
            /* the crop's lighting reads the camera's normals: the camera
             * drawn again with them (the same depth and mask). This
             * target shares the depth and mask planes with the camera's
             * depth-only one, so the context's record of what is clear
             * would not hold for it across the other's draws: the
             * context forgets its targets first, and this one is cleared
             * whole (the others next frame) */
            rast_target ct = gbuf_target(p, e);
            rast_context_forget(e->rast);
            rr = eye_draw(p, e, NULL, &e->cam, &ct, 1, NULL);
            e->lod_level = level;
            if (rr != RAST_OK)
                return pipe__eye_fail(e, PIPE_ERR_RASTER, "rasterizer (fallback normals)",
                                      rast_result_str(rr));
        }
        return 0;
    }
    fe->P = (fuse_image){r->P, w, h, 4 * w};
    fe->mask = r->M;
    fe->mask_stride = w;
    *K = (fuse_intrinsics){r->cam.fx, r->cam.fy, r->cam.cx, r->cam.cy};
    fe->intrinsics = K;
    e->view_used = PIPE_VIEW_REPROJECT;
    return 1;
}

int pipe__edge_fade_px(const pipe_desc *d)
{
    return d->edge_fade == 0 ? PIPE_EDGE_FADE_DEFAULT : d->edge_fade < 0 ? 0 : d->edge_fade;
}

unsigned pipe__edge_sides(int vx, int vy, int vw, int vh, int ow, int oh)
{
    return (vx > 0 ? FUSE_EDGE_LEFT : 0u) | (vx + vw < ow ? FUSE_EDGE_RIGHT : 0u) |
           (vy > 0 ? FUSE_EDGE_TOP : 0u) | (vy + vh < oh ? FUSE_EDGE_BOTTOM : 0u);
}

static void run_eye(pipe_ctx *p, eye_state *e)
{
    const pipe_frame_in *in = e->in;
    const int cw = p->geo.crop_width, ch = p->geo.crop_height;
    double t0 = now_ms();
    e->t_start = t0;
    e->result = PIPE_OK;
    e->cam = kin_sthmd_camera(&p->hmd, &e->head, (kin_eye)e->eye);
    rast_target tg = cam_target(p, e);
    long covered = 0;
    e->lod_level = 0;
    rast_result rr = eye_draw(p, e, e->lens, &e->cam, &tg, 1, &covered);
    if (rr == RAST_OK && e->aa.count) { /* no lens here: refused at pipe_create */
        pipe__aa_begin(&e->aa);
        pipe__aa_band(&e->aa, e->mask);
        rr = pipe__cockpit_active(p->ck)
                 ? pipe__cockpit_draw_aa(p->ck, &p->pose, e->eye, e->rast, &e->cam, &e->aa,
                                         p->desc.cull, e->clip)
                 : pipe__aa_draw_pose(&e->aa, &p->pose, e->rast, &e->cam, p->desc.cull, e->clip);
        pipe__aa_resolve(&e->aa);
    }
    double t1 = now_ms();
    e->ms_raster = t1 - t0;
    if (rr != RAST_OK) {
        pipe__eye_fail(e, PIPE_ERR_RASTER, "rasterizer", rast_result_str(rr));
        return;
    }
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
            pipe__eye_fail(e, PIPE_ERR_ARGS, "camera frame", fuse_result_str(cr));
            return;
        }
    } else {
        fe.P = crop_cols(p, fuse_image_rows(&in->camera[e->eye], p->geo.crop_y0, ch));
    }
    fe.mask = e->aa.count ? e->aa.cov : e->mask;
    fe.mask_stride = cw;
    if (p->desc.refine_band > 0 && pipe__refine_eye(p, e, &fe) < 0) return;
    /* the binary mask lit (the G-buffer's or the refined one) */
    const int refined_in = fe.mask == e->refined;
    /* the eye's view instead of the camera's crop (pipe_reproj.h; it
     * reads the camera's G-buffer mask, not fe.mask) */
    const fuse_image Pcam = fe.P;
    fuse_intrinsics EK;
    e->view_used = PIPE_VIEW_CROP;
    if (p->desc.eye_view == PIPE_VIEW_REPROJECT && reproj_eye(p, e, &fe, &EK) < 0) return;
    const int rp = e->view_used == PIPE_VIEW_REPROJECT;
    /* soft silhouettes: a one-pixel ramp inside the shown mask's edge
     * (pipe_soft.h; not with aa_samples: pipe_create): the camera's
     * binary or refined mask, or the eye view's (the same size: its
     * border fade is kept, scaled by the ramp) */
    if (e->soft) {
        pipe__soft_edge_boxed(fe.mask, e->soft, cw, ch, e->soft_box);
        fe.mask = e->soft;
    }
    e->shown = fe.mask;
    /* the normals: the eye's packed, the camera's packed or floats
     * (pipe_create); smoothing reads floats, so the eye's are unpacked
     * for it */
    const uint32_t *n10 = rp ? e->rp.n10 : e->n10;
    if (rp && p->desc.normal_smooth > 0) {
        /* all of it: the smoothing's windows also read the uncovered
         * pixels' normals, which must be 0 (the raster's clear) */
        const size_t np = (size_t)cw * (size_t)ch;
        for (size_t i = 0; i < np; i++) ef_n10_unpack(n10[i], e->rp.nrm + 3 * i);
        n10 = NULL;
    }
    fe.normal = n10 ? NULL : rp ? e->rp.nrm : e->nrm;
    fe.normal_stride = n10 ? 0 : 3 * cw;
    fe.normal_n10 = n10;
    fe.normal_n10_stride = n10 ? cw : 0;
    /* the refined mask's normals come from the model's alone (nfill
     * below: nrm must be 0 outside the model's mask) */
    const int nfill = !rp && refined_in && e->nfill_scratch;
    /* coverage beyond the model's pixel centres: its neighbours' normals */
    if (e->aa.count && p->desc.normal_smooth == 0 && !nfill)
        pipe__aa_fill_normals(&e->aa, fe.mask, e->mask, e->nrm);
    if (nfill) {
        /* the refined mask's normals: the model's, smoothed over the lag
         * and continued beyond its rim (pipe_nfill.h) */
        pipe__nfill_refined(e->refined, e->mask, e->nrm, e->snrm, cw, ch,
                            p->desc.normal_smooth > 0 ? p->desc.normal_smooth : PIPE_NFILL_RADIUS,
                            e->nfill_scratch);
        fe.normal = e->snrm;
    } else if (p->desc.normal_smooth > 0 &&
        fuse_normal_smooth(fe.mask, fe.mask_stride, fe.normal, 3 * cw, e->snrm, 3 * cw, cw, ch,
                           p->desc.normal_smooth) == FUSE_OK)
        fe.normal = e->snrm;
    fe.Q = (fuse_image){e->layer, cw, ch, 4 * cw};
    fe.q_zero_rows = e->layer_zero;   /* only fuse writes the layer */
    fe.V = in->virt[e->eye];
    fe.vp_x0 = rp ? 0 : p->geo.vp_x0;
    fe.vp_y0 = rp ? 0 : p->geo.vp_y0;
    fe.vp_w = rp ? p->hmd.lcd_width : p->geo.vp_width;
    fe.vp_h = rp ? p->hmd.lcd_height : p->geo.vp_height;
    fe.out = in->out[e->eye];
    fe.v_opaque = in->virt_opaque != 0;
    /* soft edges on the viewport's sides inside the output (pipe_desc.edge_fade) */
    fe.edge_fade = pipe__edge_fade_px(&p->desc);
    fe.edge_sides = pipe__edge_sides(fe.vp_x0, fe.vp_y0, fe.vp_w, fe.vp_h, fe.out.width,
                                     fe.out.height);
    fuse_depth dt;
    int filled[4] = {0, 0, 0, 0};
    if (in->virt_depth[e->eye] && rp) {
        /* the eye's own depths: the scene's distances are the eye's */
        dt = (fuse_depth){e->rp.depth, cw, p->hmd.znear, p->hmd.zfar, 0.0f,
                          in->virt_depth[e->eye], in->virt_depth_stride[e->eye],
                          fe.V.width, fe.V.height};
        fe.depth = &dt;
    } else if (in->virt_depth[e->eye]) {
        dt = (fuse_depth){e->depth, cw, p->hmd.znear, p->hmd.zfar, p->hmd.cam_offset_m,
                          in->virt_depth[e->eye], in->virt_depth_stride[e->eye],
                          fe.V.width, fe.V.height};
        fe.depth = &dt;
        /* refined pixels outside the model have no depth: they take the
         * model's beside them, so the depth test hides them too; the same
         * for the anti-aliased coverage beyond the pixel centres */
        if (refined_in) {
            const int b = p->desc.refine_band;
            fuse_depth_fill(e->refined, cw, e->depth, cw, cw, ch, b + b / 8 + 2, filled);
        } else if (e->aa.count) {
            const int b = p->desc.refine_band;
            fuse_depth_fill(fe.mask, cw, e->depth, cw, cw, ch, b > 0 ? b + b / 8 + 3 : 2,
                            filled);
        }
        /* (a prior's pixel beyond the fill's radius from the model gets
         * the far plane from fuse_depth_fill: a virtual object hides it) */
    }
    fuse_result fr = FUSE_OK;
    if (p->desc.tone_match > 0.0f) {
        float tone[3];
        fr = fuse_tone_match(&Pcam, e->mask, cw, &fe.V, fe.vp_x0, fe.vp_y0, fe.vp_w,
                             fe.vp_h, p->desc.tone_match, tone);
        for (int k = 0; k < 3; k++) L.tone[k] *= tone[k];
    }
    /* the fuse in bands of output rows (eye_work): prepared here, the
     * bands on whichever thread is free, eye_finish after the last */
    e->bands = 0;
    if (fr == FUSE_OK)
        fr = fuse_context_frame_prepare(e->fuse, &fe, p->threaded ? PIPE_BAND_ROWS : fe.out.height,
                                        &e->bands);
    if (fr != FUSE_OK) e->bands = 0;
    e->fr = fr;
    memcpy(e->filled, filled, sizeof filled);
    e->fusing = 1;
    e->ms_fuse = now_ms() - t1 - e->ms_convert;
}

/* The tail of an eye's frame, once every band of its fuse is done. */
static void eye_finish(pipe_ctx *p, eye_state *e)
{
    if (!e->fusing) return;   /* run_eye stopped on an error */
    const int cw = p->geo.crop_width;
    double t = now_ms();
    if (e->fr == FUSE_OK) fuse_context_frame_finish(e->fuse);
    /* the raster's planes as it left them (it clears only what it drew):
     * 8 pixels at a time where the model covers them all (nothing to do)
     * or none (all 1) */
    static const float far8[8] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    for (int y = e->filled[1]; y < e->filled[3]; y++) {
        const uint8_t *m = e->mask + (size_t)y * cw;
        float *z = e->depth + (size_t)y * cw;
        int x = e->filled[0];
        for (; x + 8 <= e->filled[2]; x += 8) {
            const uint64_t v = ef_ld8(m + x);
            if (v == 0) memcpy(z + x, far8, sizeof far8);
            else if (ef_has_zero8(v))
                for (int k = x; k < x + 8; k++)
                    if (m[k] == 0) z[k] = 1.0f;
        }
        for (; x < e->filled[2]; x++)
            if (m[x] == 0) z[x] = 1.0f;
    }
    if (e->aa.count) pipe__aa_unfill(&e->aa, e->mask, e->nrm);
    e->ms_fuse += now_ms() - t;
    if (e->fr != FUSE_OK)
        pipe__eye_fail(e, PIPE_ERR_FUSE, "lighting/composite", fuse_result_str(e->fr));
}

/* With p->mu held: the eyes' work of the current JOB_EYE on this thread
 * (0 the caller's, 1 the worker) until none is left to take, each piece
 * with the lock released; returns with it held. First an eye no thread
 * has begun (its raster and refinement do not split), else a band of an
 * eye's fuse (this thread's eye first, then the other's: work stealing),
 * else, while an eye's first part still runs on the other thread, a wait
 * for its bands. The thread that ends an eye's last band runs its tail. */
static void eye_work(pipe_ctx *p, int thread)
{
    for (;;) {
        if (p->eye_next < 2) {
            eye_state *e = &p->eye[p->eye_next++];
            e->thread = thread;
            pthread_mutex_unlock(&p->mu);
            double t = now_ms();
            run_eye(p, e);
            int last = e->bands == 0;
            if (last) eye_finish(p, e);
            t = now_ms() - t;
            pthread_mutex_lock(&p->mu);
            p->ms_busy[thread] += t;
            e->ready = 1;
            if (last) p->eye_done++;
            pthread_cond_broadcast(&p->cv);
            continue;
        }
        eye_state *e = NULL;
        for (int k = 0; k < 2 && !e; k++) {
            eye_state *c = &p->eye[(p->eye[0].thread == thread ? 0 : 1) ^ k];
            if (c->ready && c->band_next < c->bands) e = c;
        }
        if (e) {
            const int b = e->band_next++;
            pthread_mutex_unlock(&p->mu);
            double t = now_ms();
            fuse_context_frame_band(e->fuse, b);
            double tb = now_ms() - t;
            pthread_mutex_lock(&p->mu);
            e->ms_bands += tb;
            p->ms_busy[thread] += tb;
            if (++e->bands_done == e->bands) {
                pthread_mutex_unlock(&p->mu);
                t = now_ms();
                eye_finish(p, e);
                t = now_ms() - t;
                pthread_mutex_lock(&p->mu);
                p->ms_busy[thread] += t;
                p->eye_done++;
                pthread_cond_broadcast(&p->cv);
            }
            continue;
        }
        if (p->eye[0].ready && p->eye[1].ready) return;
        pthread_cond_wait(&p->cv, &p->mu);
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
        if (p->job_kind == JOB_EYE) {
            /* the work not yet taken by the caller's thread (none when it
             * was faster than this thread's wake-up) */
            eye_work(p, 1);
        } else {
            pthread_mutex_unlock(&p->mu);
            pipe__pose_skin_part(&p->pose, p->plans, 1, 2);
            pthread_mutex_lock(&p->mu);
        }
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

static void free_eyes(pipe_ctx *p)
{
    for (int e = 0; e < 2; e++) {
        EF_FREE_ALL(p->eye[e].depth, p->eye[e].nrm, p->eye[e].n10, p->eye[e].snrm,
                    p->eye[e].nfill_scratch, p->eye[e].soft, p->eye[e].clip, p->eye[e].vnrm, p->eye[e].mask, p->eye[e].layer,
                    p->eye[e].layer_zero, p->eye[e].cam_rgba, p->eye[e].refined,
                    p->eye[e].regrow, p->eye[e].prior, p->eye[e].shifted, p->eye[e].unsmoothed,
                    p->eye[e].refine_scratch);
        pipe__aa_free(&p->eye[e].aa);
        pipe__reproj_free(&p->eye[e].rp);
        rast_context_destroy(p->eye[e].rast);
        fuse_context_destroy(p->eye[e].fuse);
        pipe_lens_map_free(p->eye[e].lens);
        free(p->eye[e].lens);
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
        /* morphed meshes and extra influence sets: kin_skin_lbs */
        if (me->skin < 0 || me->target_count > 0 || me->extra_sets > 0) continue;
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
    if (desc && (desc->soft_edge < 0 || desc->soft_edge > 1 ||
                 (desc->soft_edge && desc->aa_samples)))
        return NULL;
    if (desc && (desc->normal_smooth < -1 || desc->normal_smooth > FUSE_NORMAL_SMOOTH_MAX))
        return NULL;
    if (desc && desc->aa_samples != 0 && desc->aa_samples != 4 && desc->aa_samples != 8 &&
        desc->aa_samples != 16)
        return NULL;
    if (desc && desc->eye_view != PIPE_VIEW_CROP &&
        (desc->eye_view != PIPE_VIEW_REPROJECT || desc->aa_samples != 0 ||
         pipe_view_check(&desc->hmd, NULL, 0) != 0))
        return NULL;
    if (desc && (desc->edge_fade < -1 || desc->edge_fade > FUSE_EDGE_FADE_MAX)) return NULL;
    if (desc && (desc->refine_prior < -1 || desc->refine_prior > 0 ||
                 desc->refine_lag_adapt < -1 || desc->refine_lag_adapt > 0 ||
                 desc->refine_fill < -1 || desc->refine_fill > 0 ||
                 desc->refine_shift < -1 || desc->refine_shift > 0 ||
                 desc->refine_smooth < -1 || desc->refine_smooth > 0))
        return NULL;
    pipe_ctx *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    if (desc) p->desc = *desc;
    p->model = model;
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
        /* the camera's normals packed (ef_n10.h: 4 bytes a pixel, not 12;
         * through a distorting lens its pinhole render too) when only the
         * lighting reads them: not with the refinement's fill, the
         * smoothing or the anti-aliased fill (they read floats). The
         * eye's view packs its own always (pipe__reproj_init) */
        kin_camera c0 = kin_sthmd_camera(&p->hmd, NULL, (kin_eye)e);
        const int distorts = kin_lens_distorts(&c0.lens);
        if (p->desc.refine_band == 0 && p->desc.normal_smooth <= 0 && p->desc.aa_samples == 0)
            s->n10 = malloc(sizeof(uint32_t) * px);
        else
            s->nrm = malloc(sizeof(float) * 3 * px);
        s->mask = malloc(px);
        s->layer = malloc(4 * px);
        s->layer_zero = calloc((size_t)p->geo.crop_height, 1);
        s->cam_rgba = malloc(4 * (size_t)p->hmd.cam_width *
                             (size_t)(p->desc.eye_view == PIPE_VIEW_REPROJECT
                                          ? p->hmd.cam_height
                                          : p->geo.crop_height));
        s->clip = malloc(sizeof(float) * 4 * nv);
        s->vnrm = malloc(sizeof(float) * 3 * nv);
        rast_context_desc rd = {p->desc.max_isa, 1};
        fuse_context_desc fd = {(ef_isa)p->desc.max_isa, 1};
        s->rast = rast_context_create(&rd);
        s->fuse = fuse_context_create(&fd);
        ok = ok && s->depth && (s->nrm || s->n10) && s->mask && s->layer && s->layer_zero &&
             s->cam_rgba && s->clip && s->vnrm && s->rast && s->fuse;
        if (ok) {
            /* a calibrated, distorting lens: the mask through it */
            if (distorts) {
                s->lens = calloc(1, sizeof *s->lens);
                ok = s->lens && (s->n10 ? pipe_lens_map_init_n10(s->lens, &c0.lens, 1, NULL, 0)
                                        : pipe_lens_map_init(s->lens, &c0.lens, 1, 3, NULL, 0)) == 0;
                if (ok) { /* the warp writes only what changes: start clear */
                    rast_target t0 = gbuf_target(p, s);
                    rast_target_clear(&t0);
                }
            }
        }
        if (ok && (p->desc.normal_smooth > 0 ||
                   (p->desc.refine_band > 0 && p->desc.normal_smooth == 0))) {
            s->snrm = malloc(sizeof(float) * 3 * px);
            ok = s->snrm != NULL;
        }
        if (ok && p->desc.soft_edge == 1) {
            s->soft = malloc(px);
            ok = s->soft != NULL;
            /* its bytes unknown: all of it cleared at the first frame */
            s->soft_box[0] = s->soft_box[1] = 0;
            s->soft_box[2] = p->geo.crop_width;
            s->soft_box[3] = p->geo.crop_height;
        }
        if (ok && p->desc.refine_band > 0 && p->desc.normal_smooth >= 0) {
            const size_t ns = pipe__nfill_scratch_size(p->geo.crop_width, p->geo.crop_height);
            s->nfill_scratch = aligned_alloc(16, (ns + 15) & ~(size_t)15);
            ok = s->nfill_scratch != NULL;
        }
        if (ok && p->desc.refine_band > 0) {
            fuse_refine_params rp = fuse_refine_params_default();
            rp.band = p->desc.refine_band;
            /* shared with pipe_fit_fill_small and pipe_fit_shift, sized
             * for the largest: each leaves its input unchanged when its
             * scratch is short */
            const int cw = p->geo.crop_width, ch = p->geo.crop_height;
            const size_t rs = fuse_refine_scratch_size(&rp, cw, ch),
                         fs = pipe_fit_fill_scratch_size(cw, ch),
                         ss = pipe_fit_shift_scratch_size(cw, ch);
            s->refine_scratch_size = rs && fs > rs ? fs : rs;
            if (rs && ss > s->refine_scratch_size) s->refine_scratch_size = ss;
            s->refined = malloc(px);
            s->regrow = malloc(px);
            s->refine_scratch = s->refine_scratch_size
                                    ? aligned_alloc(16, (s->refine_scratch_size + 15) & ~(size_t)15)
                                    : NULL;
            ok = s->refined && s->regrow && s->refine_scratch;
            if (ok && p->desc.refine_prior == 0 && p->desc.fit_rig) {
                s->prior = malloc(px);
                ok = s->prior != NULL;
            }
            if (ok && p->desc.refine_shift == 0 && p->desc.fit_rig) {
                s->shifted = malloc(px);
                ok = s->shifted != NULL;
            }
            if (ok && p->desc.refine_smooth == 0 && p->desc.fit_rig) {
                s->unsmoothed = malloc(px);
                ok = s->unsmoothed != NULL;
            }
        }
        /* coverage samples are drawn through the pinhole: not with a
         * distorting lens (pipe.h ANTI-ALIASED EDGES) */
        if (ok && p->desc.aa_samples && s->lens) ok = 0;
        if (ok && p->desc.eye_view == PIPE_VIEW_REPROJECT)
            ok = pipe__reproj_init(&s->rp, p->geo.crop_width, p->geo.crop_height,
                                   p->desc.normal_smooth > 0) == 0;
        if (ok && p->desc.aa_samples)
            ok = pipe__aa_init(&s->aa, p->desc.aa_samples, p->geo.crop_width,
                               p->geo.crop_height, p->desc.refine_band > 0) == 0;
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
        rast_target tg = cam_target(p, s);
        long covered;
        rast_result rr = eye_draw(p, s, s->lens, &cam[e], &tg, 0, &covered);
        const uint8_t *prev = s->have_refined && !p->fit_no_prev
                                  ? (s->have_unsmoothed ? s->unsmoothed : s->refined)
                                  : NULL;
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
    pipe__pose_fk(&p->pose);
    pipe__pose_skin_part(&p->pose, p->plans, 0, 1);
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
    if (in->locals) {
        memcpy(p->pose.locals, in->locals, sizeof *in->locals * (size_t)p->pose.model->node_count);
        pipe__morph_weights(&p->pose, NULL, 0.0f);
    } else
        pipe__pose_locals_anim(&p->pose, in->anim, in->time);
    pipe__pose_fk(&p->pose);
    if (p->threaded && p->skin_split) {
        int job = post_job(p, JOB_SKIN);
        pipe__pose_skin_part(&p->pose, p->plans, 0, 2);
        wait_job(p, job);
    } else {
        pipe__pose_skin_part(&p->pose, p->plans, 0, 1);
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
        /* Eye 0 here, eye 1 on whichever thread is free first: the worker
         * when it has woken, else this one (no wait for a late wake-up);
         * then both threads take the bands of both eyes' fuse (eye_work) */
        pthread_mutex_lock(&p->mu);
        p->eye_next = 0;
        p->eye_done = 0;
        for (int e = 0; e < 2; e++) {
            eye_state *s = &p->eye[e];
            s->thread = 0;
            s->fusing = s->ready = s->bands = s->band_next = s->bands_done = 0;
            s->ms_bands = 0.0;
            p->ms_busy[e] = 0.0;
        }
        p->job_kind = JOB_EYE;
        ++p->job_seq;
        pthread_cond_broadcast(&p->cv);
        eye_work(p, 0);
        while (p->eye_done < 2) pthread_cond_wait(&p->cv, &p->mu);
        pthread_mutex_unlock(&p->mu);
    } else {
        p->ms_busy[0] = p->ms_busy[1] = 0.0;
        for (int e = 0; e < 2; e++) {
            eye_state *s = &p->eye[e];
            double t = now_ms();
            s->thread = 0;
            s->fusing = s->bands = 0;
            s->ms_bands = 0.0;
            run_eye(p, s);
            const double tb = now_ms();
            for (int b = 0; b < s->bands; b++) fuse_context_frame_band(s->fuse, b);
            s->ms_bands = now_ms() - tb;   /* the fuse's stage time, as on two threads */
            eye_finish(p, s);
            p->ms_busy[0] += now_ms() - t;
        }
    }
    double t2 = now_ms();
    if (stats) {
        stats->ms_pose = t1 - t0;
        for (int e = 0; e < 2; e++) {
            stats->ms_raster[e] = p->eye[e].ms_raster;
            stats->ms_convert[e] = p->eye[e].ms_convert;
            stats->ms_fuse[e] = p->eye[e].ms_fuse + p->eye[e].ms_bands;
            stats->ms_busy[e] = p->ms_busy[e];
            stats->coverage[e] = p->eye[e].coverage;
            stats->lod_level[e] = p->eye[e].lod_level;
            int rp = p->eye[e].view_used == PIPE_VIEW_REPROJECT;
            stats->view[e] = p->eye[e].view_used;
            stats->view_sampled[e] = rp ? p->eye[e].rp.sampled : 0;
            stats->view_filled[e] = rp ? p->eye[e].rp.filled : 0;
            stats->view_outside[e] = rp ? p->eye[e].rp.outside : 0;
            stats->eye_thread[e] = p->eye[e].thread;
            stats->ms_eye_start[e] = p->eye[e].t_start - t1;
        }
        stats->view_fallbacks = p->eye[0].fallbacks + p->eye[1].fallbacks;
        stats->ms_eyes = t2 - t1;
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

void pipe_set_stats_clock(int thread_cpu) { stats_cpu_clock = thread_cpu != 0; }
