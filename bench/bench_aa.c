/* bench_aa.c - anti-aliased silhouettes in the pipeline
 * (pipe_desc.aa_samples) against binary masks: composite PSNR, edge
 * flicker and the cost per stereo frame (issue 14 item 3). Reports, never
 * passes or fails.
 *
 * The generated operator of `egofuse eval` (samples/gen, samples/gt: the
 * true arms, their camera images, the workshop as the virtual scene) on
 * reach_grasp, slowed down (--speed, default 0.25: a slow sequence, where
 * a stair-stepped edge crawls pixel by pixel), frames 0..N-1, both eyes.
 * Methods, each with aa 0 (binary), -1 (soft_edge), 4, 8, 16, through
 * pipe_frame:
 *   kin          the mask model posed by the animation;
 *   refine       the same, mask refined by colour (band 16);
 *   kin-track    posed from the tracking (eval's tracker: 5 mm noise,
 *                20 ms latency; One Euro filter, 20 ms prediction, IK);
 *   refine-track the same plus the elbow fit and the refinement (eval's
 *                refine, the README's recommendation).
 * Ground truth, per eye and frame:
 *   sil     the true silhouette at the pixel centres (eval's);
 *   soft    its area coverage: the true arms' coverage of 16 samples per
 *           pixel (rast_draw_aa), except next to a pixel whose centre the
 *           arms cover but a cockpit object hides (there: sil);
 *   ideal   the composite of the camera image with the true mask and the
 *           true normals: I_bin with sil, I_soft with soft (the camera
 *           images themselves are rendered at the pixel centres: their
 *           edge pixels are either arm or background).
 * Measures (inside the viewport; per method, mean over frames and eyes):
 *   PSNR bin / soft   composite against I_bin / I_soft, dB;
 *   edge err          mean |M - soft| / 255 over the edge pixels of the
 *                     truth (0 < soft < 255 or a sil boundary pixel);
 *   flicker mask      mean over the edge pixels of frames f-1, f of
 *                     |(M_f - M_f-1) - (soft_f - soft_f-1)| / 255: mask
 *                     change at the silhouette that the true coverage does
 *                     not have (a binary edge pops a whole pixel);
 *   flicker comp      the same on the composite's rgb (levels 0..255), over
 *                     the output pixels whose layer pixel is such an edge
 *                     pixel, against I_soft;
 *   ms                pipe_frame's wall time per stereo frame: the median
 *                     of R repetitions of the last frame (--reps, 40), and
 *                     the minimum.
 *   cpu med           the median of the process CPU time of those runs.
 * --cull-back: both draws skip back faces (as `egofuse render --cull-back`;
 * the arm meshes are closed).
 * Usage: build/bench/bench_aa [--frames N] [--speed S] [--reps R]
 *                             [--seq NAME] [--threads T] [--cull-back] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../samples/gt/gt.h"
#include "../src/fuse/fuse_metrics.h"
#include "../src/pipe/pipe.h"
#include "bench_util.h"
#include "../src/cpu/ef_mem.h"

enum { CW = 640, CH = 400, OW = GEN_VIRT_W, OH = GEN_VIRT_H };
enum { M_KIN, M_REFINE, M_KIN_TRACK, M_REFINE_TRACK, M_COUNT };
static const char *mname[M_COUNT] = {"kin", "refine", "kin-track", "refine-track"};
/* samples per pixel; -1: pipe_desc.soft_edge (the binary mask's edge
 * faded by its 3x3 window, pipe_soft.h), printed as aa -1 */
static const int aa_of[5] = {0, -1, 4, 8, 16};
#define NAA 5
#define NCFG (M_COUNT * NAA)

typedef struct cfg_run {
    int method, aa;
    pipe_ctx *p;
    kin_filter flt;
    int next;
    uint8_t *prev_mask[2], *prev_out[2];
    double mse_bin, mse_soft, edge_err, flick_m, flick_c;
    long n_eye, n_edge, n_fm, n_fc;
    double ms_sum;
    long ms_n;
} cfg_run;

static double now_ms(void) { return bench_now_ms(CLOCK_MONOTONIC); }

/* CPU time of the process (all threads): on a shared machine the wall
 * time also counts the time the threads wait for a core. */
static double cpu_ms(void) { return bench_now_ms(CLOCK_PROCESS_CPUTIME_ID); }

static pipe_lighting workshop_world(const gen_scene *ws)
{
    pipe_lighting pl = pipe_lighting_default();
    fuse_lighting *L = &pl.light;
    L->light_count = ws->light_count < FUSE_MAX_LIGHTS ? ws->light_count : FUSE_MAX_LIGHTS;
    for (int i = 0; i < 3; i++) L->ambient[i] = ws->ambient[i];
    L->kd = 0.80f;
    L->ks = 0.12f;
    L->shininess = 20.0f;
    L->kf = 0.50f;
    L->tone[0] = 1.0f;
    L->tone[1] = 0.98f;
    L->tone[2] = 0.96f;
    for (int i = 0; i < L->light_count; i++)
        for (int k = 0; k < 3; k++) {
            L->lights[i].dir[k] = ws->light_dir[i][k];
            L->lights[i].color[k] = ws->light_color[i][k];
        }
    return pl;
}

/* pl's lights into cam's view space (as pipe_frame does). */
static fuse_lighting view_lighting(const pipe_lighting *pl, const kin_camera *cam)
{
    fuse_lighting L = pl->light;
    for (int i = 0; i < L.light_count; i++) {
        kin_vec3 d = kin_v3_norm(kin_mat4_mul_dir(
            &cam->view, kin_v3(L.lights[i].dir[0], L.lights[i].dir[1], L.lights[i].dir[2])));
        L.lights[i].dir[0] = d.x;
        L.lights[i].dir[1] = d.y;
        L.lights[i].dir[2] = d.z;
    }
    return L;
}

int main(int argc, char **argv)
{
    int frames = 120, reps = 40, threads = 2, first = 0, cull_back = 0;
    float speed = 0.25f;
    const char *seq = "reach_grasp";
    for (int i = 1; i < argc; i += 2) {
        if (!strcmp(argv[i], "--cull-back")) {
            cull_back = 1;
            i--;
            continue;
        }
        if (i + 1 == argc) {
            fprintf(stderr, "bench_aa: %s wants a value; usage: bench_aa [--frames N] [--speed S] "
                            "[--reps R] [--seq NAME] [--first F] [--threads T] [--cull-back]\n",
                    argv[i]);
            return 2;
        }
        if (!strcmp(argv[i], "--frames")) frames = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--speed")) speed = (float)atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--reps")) reps = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--seq")) seq = argv[i + 1];
        else if (!strcmp(argv[i], "--first")) first = atoi(argv[i + 1]);
        else if (!strcmp(argv[i], "--threads")) threads = atoi(argv[i + 1]);
        else {
            fprintf(stderr, "bench_aa: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (frames < 2 || reps < 1 || speed <= 0.0f) {
        fprintf(stderr, "bench_aa: --frames >= 2, --reps >= 1, --speed > 0\n");
        return 2;
    }
    gen_arms mask, truth;
    gen_scene cockpit, workshop;
    gen_frame_ctx gctx;
    kin_arm_rig rig;
    gt_operator_desc op = gt_operator_default();
    char why[256];
    if (gen_arms_build(&mask) < 0 || gt_truth_build(&mask, &op, &truth) < 0 ||
        gt_sequence_build(&mask, seq, &truth) < 0 || gt_cockpit_build(&cockpit) < 0 ||
        gen_scene_workshop(&workshop, &mask) < 0 ||
        gen_frame_ctx_init(&gctx, &truth, &cockpit, &workshop, 1) < 0 ||
        kin_arm_rig_init(&rig, &mask.model, why, sizeof why) < 0) {
        fprintf(stderr, "bench_aa: cannot build the generated world (%s)\n", seq);
        return 1;
    }
    const kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    const pipe_lighting pl = workshop_world(&workshop);
    /* the tracker: eval's defaults, on the slowed motion */
    gt_track_desc td = gt_track_default();
    td.speed = speed;
    const int nsamples = (int)((float)(first + frames) / GEN_FPS * td.rate_hz) + 2;
    kin_track_sample *samples = malloc(sizeof *samples * (size_t)nsamples);
    kin_transform *tl = malloc(sizeof *tl * (size_t)truth.model.node_count);
    kin_mat4 *tw = malloc(sizeof *tw * (size_t)truth.model.node_count);
    kin_transform *locals = malloc(sizeof *locals * (size_t)mask.model.node_count);
    uint8_t *rgb = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 3);
    uint8_t *cam[2], *V[2], *out[2], *Ibin[2], *Isoft[2], *pIsoft[2], *sil[2], *soft[2], *psoft[2];
    float *tnrm = malloc(sizeof(float) * 3 * CW * CH);
    float *snrm = malloc(sizeof(float) * 3 * CW * CH);
    float *sd = malloc(sizeof(float) * GEN_CAM_W * GEN_CAM_H);
    uint8_t *sm = malloc((size_t)GEN_CAM_W * GEN_CAM_H);
    uint32_t *aas = malloc(sizeof(uint32_t) * GEN_CAM_W * GEN_CAM_H);
    uint8_t *cov = malloc((size_t)GEN_CAM_W * GEN_CAM_H);
    uint8_t *layer = malloc((size_t)CW * CH * 4);
    float *vdepth = malloc(sizeof(float) * OW * OH);
    uint8_t *vrgb = malloc((size_t)OW * OH * 3);
    for (int e = 0; e < 2; e++) {
        cam[e] = malloc((size_t)GEN_CAM_W * GEN_CAM_H * 4);
        V[e] = malloc((size_t)OW * OH * 4);
        out[e] = malloc((size_t)OW * OH * 4);
        Ibin[e] = malloc((size_t)OW * OH * 4);
        Isoft[e] = malloc((size_t)OW * OH * 4);
        pIsoft[e] = malloc((size_t)OW * OH * 4);
        sil[e] = malloc((size_t)CW * CH);
        soft[e] = malloc((size_t)CW * CH);
        psoft[e] = malloc((size_t)CW * CH);
    }
    for (int k = 0; k < nsamples; k++) gt_track_sample(&truth, &td, k, tl, tw, &samples[k]);

    cfg_run R[NCFG];
    memset(R, 0, sizeof R);
    for (int i = 0; i < NCFG; i++) {
        cfg_run *r = &R[i];
        r->method = i / NAA;
        r->aa = aa_of[i % NAA];
        pipe_desc d = {0};
        d.threads = threads;
        d.aa_samples = r->aa > 0 ? r->aa : 0;
        d.soft_edge = r->aa < 0;
        if (cull_back) d.cull = RAST_CULL_BACK; /* closed arm meshes: the same masks */
        if (r->method == M_REFINE || r->method == M_REFINE_TRACK) d.refine_band = 16;
        if (r->method == M_REFINE_TRACK) d.fit_rig = &rig;
        r->p = pipe_create(&d, &mask.model);
        kin_filter_init(&r->flt, NULL);
        for (int e = 0; e < 2; e++) {
            r->prev_mask[e] = malloc((size_t)CW * CH);
            r->prev_out[e] = malloc((size_t)OW * OH * 4);
        }
        if (!r->p) {
            fprintf(stderr, "bench_aa: pipe_create failed\n");
            return 1;
        }
    }
    pipe_frame_in in;
    const size_t vp_off = (size_t)g.vp_y0 * 4 * OW + (size_t)g.vp_x0 * 4;
    for (int f = first; f < first + frames; f++) {
        const float t = (float)f / GEN_FPS * speed;
        kin_mat4 wfh;
        gen_pose(&gctx, t, &wfh);
        for (int e = 0; e < 2; e++) {
            memcpy(psoft[e], soft[e], (size_t)CW * CH);
            uint8_t *sw = pIsoft[e];
            pIsoft[e] = Isoft[e];
            Isoft[e] = sw;
            gt_render_eye(&gctx, &wfh, (kin_eye)e, f, rgb, sil[e], tnrm, sd, sm);
            fuse_image ci = {cam[e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W};
            fuse_rgb24_to_rgba(rgb, 3 * GEN_CAM_W, GEN_CAM_W, GEN_CAM_H, &ci);
            gen_render_virtual(&gctx, &wfh, (kin_eye)e, f, vrgb, vdepth);
            fuse_image vi = {V[e], OW, OH, 4 * OW};
            fuse_rgb24_to_rgba(vrgb, 3 * OW, OW, OH, &vi);
            /* the true coverage, 16 samples, through gt_render_eye's camera */
            kin_camera kc = kin_sthmd_camera(NULL, &wfh, (kin_eye)e);
            kin_mat4 proj = gen_proj_from_intrinsics(kc.fx, kc.fy, kc.cx, kc.cy + (float)g.crop_y0,
                                                     GEN_CAM_W, GEN_CAM_H, GEN_CAM_ZNEAR,
                                                     GEN_CAM_ZFAR);
            kin_mat4 vp = kin_mat4_mul(&proj, &kc.view);
            const kin_mesh *me = &truth.model.meshes[0];
            rast_transform_points(vp.m, gctx.skin_pos, me->vertex_count, gctx.clip);
            rast_aa_target at = {GEN_CAM_W, GEN_CAM_H, aas, GEN_CAM_W, 16};
            rast_aa_clear(&at);
            rast_mesh_desc md = {gctx.clip, me->vertex_count, NULL, 0, me->indices,
                                 me->index_count / 3, RAST_CULL_NONE};
            rast_draw_aa(&at, &md, NULL);
            rast_aa_resolve(&at, cov, GEN_CAM_W);
            memcpy(snrm, tnrm, sizeof(float) * 3 * CW * CH);
            for (int y = 0; y < CH; y++)
                for (int x = 0; x < CW; x++) {
                    const size_t o = (size_t)y * CW + x;
                    const size_t ii = (size_t)(y + g.crop_y0) * GEN_CAM_W + x;
                    int hidden = 0;
                    for (int dy = -1; dy <= 1; dy++)
                        for (int dx = -1; dx <= 1; dx++) {
                            const int yy = y + g.crop_y0 + dy, xx = x + dx;
                            if (yy < 0 || yy >= GEN_CAM_H || xx < 0 || xx >= GEN_CAM_W) continue;
                            const size_t j = (size_t)yy * GEN_CAM_W + xx;
                            hidden |= sm[j] && !(gctx.mask[j] && sd[j] <= gctx.depth[j]);
                        }
                    soft[e][o] = hidden ? sil[e][o] : cov[ii];
                    if (soft[e][o] && !sil[e][o]) {
                        float s3[3] = {0, 0, 0};
                        for (int dy = -1; dy <= 1; dy++)
                            for (int dx = -1; dx <= 1; dx++) {
                                const int yy = y + dy, xx = x + dx;
                                if (yy < 0 || yy >= CH || xx < 0 || xx >= CW ||
                                    !sil[e][(size_t)yy * CW + xx])
                                    continue;
                                for (int k = 0; k < 3; k++)
                                    s3[k] += tnrm[3 * ((size_t)yy * CW + xx) + k];
                            }
                        memcpy(&snrm[3 * o], s3, sizeof s3);
                    }
                }
            fuse_lighting L = view_lighting(&pl, &kc);
            fuse_intrinsics K = {kc.fx, kc.fy, kc.cx, kc.cy};
            fuse_image P = fuse_image_rows(&ci, g.crop_y0, CH);
            fuse_image Q = {layer, CW, CH, 4 * CW};
            fuse_image Ib = {Ibin[e], OW, OH, 4 * OW}, Is = {Isoft[e], OW, OH, 4 * OW};
            fuse_light(&L, &K, &P, sil[e], CW, tnrm, 3 * CW, &Q);
            fuse_composite(&Q, &vi, g.vp_x0, g.vp_y0, g.vp_width, g.vp_height, &Ib);
            fuse_light(&L, &K, &P, soft[e], CW, snrm, 3 * CW, &Q);
            fuse_composite(&Q, &vi, g.vp_x0, g.vp_y0, g.vp_width, g.vp_height, &Is);
        }
        for (int i = 0; i < NCFG; i++) {
            cfg_run *r = &R[i];
            memset(&in, 0, sizeof in);
            in.head_node = mask.head;
            in.lighting = pl;
            if (r->method == M_KIN || r->method == M_REFINE) {
                in.anim = &mask.model.anims[0];
                in.time = t;
            } else {
                const double tc = (double)f / GEN_FPS, lat = 0.020;
                while (r->next < nsamples && (double)r->next / td.rate_hz + lat <= tc + 1e-9)
                    kin_filter_push(&r->flt, &samples[r->next++]);
                kin_track_sample cur;
                memset(&cur, 0, sizeof cur);
                if (r->next > 0) kin_filter_output(&r->flt, tc + 0.020, &cur, NULL);
                kin_pose_rest(&mask.model, locals);
                if (!kin_arm_rig_pose(&rig, &mask.model, NULL, NULL, &cur, locals, NULL))
                    kin_pose_rest(&mask.model, locals);
                in.locals = locals;
            }
            for (int e = 0; e < 2; e++) {
                in.camera[e] = (fuse_image){cam[e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W};
                in.virt[e] = (fuse_image){V[e], OW, OH, 4 * OW};
                in.out[e] = (fuse_image){out[e], OW, OH, 4 * OW};
            }
            in.virt_opaque = 1;
            pipe_frame_stats st;
            if (pipe_frame(r->p, &in, &st, why, sizeof why) != PIPE_OK) {
                fprintf(stderr, "bench_aa: %s\n", why);
                return 1;
            }
            for (int e = 0; e < 2; e++) {
                const uint8_t *M = pipe_mask(r->p, e, NULL, NULL);
                r->mse_bin += fuse_mse(out[e] + vp_off, 4 * OW, Ibin[e] + vp_off, 4 * OW,
                                       g.vp_width, g.vp_height, 4, 3);
                r->mse_soft += fuse_mse(out[e] + vp_off, 4 * OW, Isoft[e] + vp_off, 4 * OW,
                                        g.vp_width, g.vp_height, 4, 3);
                r->n_eye++;
                for (int y = 1; y < CH - 1; y++)
                    for (int x = 1; x < CW - 1; x++) {
                        const size_t o = (size_t)y * CW + x;
                        const int s = sil[e][o];
                        const int edge = (soft[e][o] > 0 && soft[e][o] < 255) ||
                                         (s && (!sil[e][o - 1] || !sil[e][o + 1] ||
                                                !sil[e][o - CW] || !sil[e][o + CW]));
                        if (!edge) continue;
                        r->edge_err += fabs((double)M[o] - soft[e][o]) / 255.0;
                        r->n_edge++;
                        if (f == first) continue;
                        const double dm = (double)M[o] - r->prev_mask[e][o];
                        const double dt = (double)soft[e][o] - psoft[e][o];
                        r->flick_m += fabs(dm - dt) / 255.0;
                        r->n_fm++;
                        /* the output pixels of this layer pixel (centre rule) */
                        const int ox0 = g.vp_x0 + (int)((int64_t)x * g.vp_width / CW);
                        const int ox1 = g.vp_x0 + (int)((int64_t)(x + 1) * g.vp_width / CW);
                        const int oy0 = g.vp_y0 + (int)((int64_t)y * g.vp_height / CH);
                        const int oy1 = g.vp_y0 + (int)((int64_t)(y + 1) * g.vp_height / CH);
                        for (int oy = oy0; oy < oy1; oy++)
                            for (int ox = ox0; ox < ox1; ox++) {
                                const size_t q = ((size_t)oy * OW + ox) * 4;
                                for (int c = 0; c < 3; c++) {
                                    const double dr = (double)out[e][q + c] - r->prev_out[e][q + c];
                                    const double di = (double)Isoft[e][q + c] - pIsoft[e][q + c];
                                    r->flick_c += fabs(dr - di);
                                    r->n_fc++;
                                }
                            }
                    }
                memcpy(r->prev_mask[e], M, (size_t)CW * CH);
                memcpy(r->prev_out[e], out[e], (size_t)OW * OH * 4);
            }
        }
        if ((f - first + 1) % 20 == 0)
            fprintf(stderr, "bench_aa: frame %d of %d\n", f - first + 1, frames);
    }
    /* cost: the last frame again, reps times per configuration, the
     * configurations interleaved (the machine's load hits all alike) */
    double *ms = malloc(sizeof(double) * (size_t)reps * NCFG);
    double *cpu = malloc(sizeof(double) * (size_t)reps * NCFG);
    for (int k = 0; k < reps; k++)
        for (int i = 0; i < NCFG; i++) {
            cfg_run *r = &R[i];
            memset(&in, 0, sizeof in);
            in.head_node = mask.head;
            in.lighting = pl;
            in.anim = &mask.model.anims[0];
            in.time = (float)(first + frames - 1) / GEN_FPS * speed;
            if (r->method == M_KIN_TRACK || r->method == M_REFINE_TRACK) {
                in.anim = NULL;
                in.locals = locals;   /* the last tracked pose */
            }
            for (int e = 0; e < 2; e++) {
                in.camera[e] = (fuse_image){cam[e], GEN_CAM_W, GEN_CAM_H, 4 * GEN_CAM_W};
                in.virt[e] = (fuse_image){V[e], OW, OH, 4 * OW};
                in.out[e] = (fuse_image){out[e], OW, OH, 4 * OW};
            }
            in.virt_opaque = 1;
            const double t0 = now_ms(), c0 = cpu_ms();
            pipe_frame(r->p, &in, NULL, why, sizeof why);
            ms[(size_t)i * reps + k] = now_ms() - t0;
            cpu[(size_t)i * reps + k] = cpu_ms() - c0;
        }
    printf("bench_aa: %s at speed %.2f, %d frames, both eyes, pipe threads %d, ISA %s\n", seq,
           (double)speed, frames, threads, ef_isa_name((ef_isa)pipe_isa(R[0].p)));
    printf("%-13s %3s %9s %9s %8s %9s %9s %8s %8s %8s\n", "method", "aa", "PSNR bin", "PSNR soft",
           "edge err", "flick msk", "flick rgb", "ms med", "ms min", "cpu med");
    for (int i = 0; i < NCFG; i++) {
        cfg_run *r = &R[i];
        double *v = ms + (size_t)i * reps;
        double *cv = cpu + (size_t)i * reps;
        qsort(v, (size_t)reps, sizeof *v, bench_cmp_double);
        qsort(cv, (size_t)reps, sizeof *cv, bench_cmp_double);
        printf("%-13s %3d %9.3f %9.3f %8.4f %9.4f %9.3f %8.3f %8.3f %8.3f\n", mname[r->method], r->aa,
               fuse_psnr_of_mse(r->mse_bin / (double)r->n_eye),
               fuse_psnr_of_mse(r->mse_soft / (double)r->n_eye),
               r->edge_err / (double)(r->n_edge ? r->n_edge : 1),
               r->flick_m / (double)(r->n_fm ? r->n_fm : 1),
               r->flick_c / (double)(r->n_fc ? r->n_fc : 1), v[reps / 2], v[0], cv[reps / 2]);
    }
    for (int i = 0; i < NCFG; i++) {
        pipe_destroy(R[i].p);
        for (int e = 0; e < 2; e++) {
            free(R[i].prev_mask[e]);
            free(R[i].prev_out[e]);
        }
    }
    for (int e = 0; e < 2; e++) {
        EF_FREE_ALL(cam[e], V[e], out[e], Ibin[e], Isoft[e], pIsoft[e], sil[e], soft[e], psoft[e]);
    }
    EF_FREE_ALL(ms, cpu, samples, tl, tw, locals, rgb, tnrm, snrm, sd, sm, aas, cov, layer, vdepth,
                vrgb);
    gen_frame_ctx_free(&gctx);
    gen_scene_free(&cockpit);
    gen_scene_free(&workshop);
    gen_arms_free(&truth);
    gen_arms_free(&mask);
    return 0;
}
