/* eval_internal.h - internal to src/eval: the method configurations
 * (eval_plan.c makes them), their runs (state and sums) and the shared
 * per-frame context of the evaluation (eval.c), which the report writer
 * (eval_report.c) reads. */
#ifndef EGOFUSE_EVAL_INTERNAL_H
#define EGOFUSE_EVAL_INTERNAL_H

#include <stdio.h>

#include "eval.h"
#include "../fuse/fuse_metrics.h"
#include "../fuse/fuse_refine.h"
#include "../pipe/pipe.h"
#include "../fit/fit_stereo.h"

enum { CW = 640, CH = 400 };

typedef enum method_kind { M_KIN, M_KIN_CAL, M_SKIN, M_REFINE } method_kind;
static const char *kind_name[] __attribute__((unused)) = { "kin", "kin-cal-pred", "skin", "refine" };

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
    int lod;                 /* level of detail: 0 = full, a level, or
                                PIPE_LOD_AUTO (eval_lod.c) */
    float lod_px;            /* the rule's target, px */
    float tone;              /* > 0: gray-world tone matching of this
                                strength (fuse_tone_match, as
                                pipe_desc.tone_match) before lighting */
    int kf_set;              /* 1: the Fresnel fade kf below instead of the
                                workshop lighting's 0.5 (eval_kf.c) */
    float kf;
    int band_auto;           /* refine: band from the projected uncertainty
                                (pipe_fit_band, band = its minimum); 0 off */
    float band_sigma, band_tau;
    int band_max;
    float prior_radius;      /* refine: the last refined mask is the input
                                within this many metres of slow hands (0 off) */
    float prior_speed;       /* m/s: slower hands use it */
    int prior_mc;            /* 1: moved with the hand (pipe_fit_hand_px) */
    int shift;               /* refine: the hands of the input moved to the
                                colour (fit_shift.h): 0 off, 1 the hands
                                without the prior, 2 every tracked hand */
    int fill_hole, fill_island; /* refine: holes / islands of the refined
                                   mask up to this many pixels filled /
                                   cleared (fit_holes.h); 0 off */
    int smooth;              /* refine: the refined mask's 3x3 closing and
                                opening (fit_smooth.h): EVAL_SMOOTH */
    int stereo;              /* refine: 1 = the stereo pair's depth test of
                                the refined mask (fit_stereo.h) */
    float lag_adapt_v0, lag_adapt_v1;   /* refine, kin-cal-pred: lag
                                           compensation of the hands from
                                           speed v0 (none) to v1 (full), m/s;
                                           v1 0 = off */
} method_cfg;

/* refine's variants in --methods (eval_plan.c): refine-nomc (the prior
 * not moved with the hand), refine-noshift (the hands of the input not
 * moved to the colour, fit_shift.h), refine-shiftall (every tracked hand
 * moved, those of the prior too), refine-nosmooth (the refined mask
 * not smoothed, fit_smooth.h) and the smoothing's other placements
 * (refine-smoothlate 2, -smoothout 3, -smoothin 4, -smoothoutin 5,
 * -closeout 6, -openout 7: EVAL_SMOOTH) */
#define EVAL_VARIANTS 10
method_cfg eval__variant_cfg(const eval_opts *o, int v);

/* refine's defaults (docs/accuracy.md, issue 14 item 2) */
#define EVAL_PRIOR_RADIUS 0.03f
#define EVAL_PRIOR_SPEED 0.3f
#define EVAL_LAG_V0 0.2f
#define EVAL_LAG_V1 0.8f
/* refine: the hands without the prior moved to the colour before the
 * band (fit_shift.h; 0 off, 2 every hand) */
#define EVAL_SHIFT 1
/* refine: the refined mask's ragged edge smoothed (fit_smooth.h; 0 off;
 * 1 in place before the learning, 2 after it (the next prior smoothed),
 * 3 the shown mask only: the learning and the next prior unsmoothed (as
 * pipe_frame), 4 as 1 and 5 as 3 with the closing only inside the
 * refinement's input, 6 the closing only, 7 the opening only, both as
 * 3; docs/accuracy.md) */
#define EVAL_SMOOTH 3
/* refine: the refined mask's holes up to this many pixels filled and its
 * islands up to this many cleared (fit_holes.h; as PIPE_FILL_HOLE,
 * PIPE_FILL_ISLAND) */
#define EVAL_FILL_HOLE PIPE_FILL_HOLE
#define EVAL_FILL_ISLAND PIPE_FILL_ISLAND

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
    unsigned sides;          /* tracked hands of the frame (bit 0 left) */
    float speed[2];          /* the filter's wrist speeds, m/s */
    float hand_px[2][2][2];  /* [eye][side]: the hand in the image, last frame */
    int have_hand_px[2][2];
    double cpu_secs;         /* the method's thread CPU time (ms/frame is wall) */
    long stereo_tested, stereo_cleared, stereo_added;   /* refine: fit_stereo.h */
    double band_sum;         /* refine: the bands used, summed over eyes */
    long n_band;
    /* sums over frames and eyes */
    double iou, bf1, bf3, fp, fn, mse, flicker, flicker_den, secs;
    float *err;              /* FP + FN px of every eye and frame (the error
                                area, eval__print_error_area) */
    long n_err, err_cap;
    double err_mean, err_p95, err_max; /* of err, set when the run ends */
    double tp_sum, union_sum;  /* pooled IoU: sums over every eye and frame */
    long n_eye, n_flicker, n_frames;
    /* levels of detail (cfg.lod != 0): the kinematic mask against the
     * full model's in the same pose, the level drawn, the raster's time */
    double iou_full, bf1_full, lod_sum, tris_sum, raster_secs;
    long n_full, n_raster;
} method_run;

/* A lighting mismatch between the cockpit (the camera images) and the
 * virtual scene (eval_light.c): the cockpit's lights and ambient times
 * gain, tinted to the colour temperature kelvin (6500: no tint, the
 * luma kept), the lights' directions turned by roll_deg about the world's
 * forward axis (0: from above as built; 90: from the side). on 0: none.
 * opaque_ideal 1: the ideal composite without the Fresnel fade (kf 0: a
 * real hand is opaque; the Fresnel sweep, eval_kf.c). */
typedef struct eval_light {
    int on;
    float gain, kelvin, roll_deg;
    int opaque_ideal;
} eval_light;

/* The posed mask model's buffers both evaluations (eval.c, eval_eye.c)
 * need, and the ground truth renderer's scratch (eval_pose.c). */
typedef struct eval_pose {
    kin_mat4 *world, *jm, *tworld;      /* node_count, joint_count, node_count */
    kin_transform *tlocals;             /* node_count: the truth's locals */
    float *pos, *nrm, *clip, *vnrm;     /* vertex_count x 3, 3, 4, 3 */
    uint8_t *cam_rgb, *gt_mask;         /* 640x480x3, 640x480 */
    float *gt_depth;                    /* 640x480 */
} eval_pose;

/* p's buffers for model m (its first skin) and meshes of vertex_count
 * vertices: 0, or -1 when out of memory (what was allocated is held:
 * eval__pose_free frees it). */
int eval__pose_init(eval_pose *p, const kin_model *m, int vertex_count);
void eval__pose_free(eval_pose *p);

/* Shared per-frame buffers. */
typedef struct eval_ctx {
    gen_arms mask, mask_fine, truth;
    gen_scene cockpit, workshop;
    gen_frame_ctx gctx;
    kin_arm_rig rig;
    gt_operator_desc op;
    eval_pose ps;
    kin_dualquat *dq;
    /* per eye */
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
    uint8_t *mask_prior;     /* refine: the prior (fit_band.h) */
    uint8_t *mask_shift;     /* refine: the hands moved (fit_shift.h) */
    uint8_t *mask_smooth;    /* refine: the output smoothed (fit_smooth.h) */
    uint32_t *aa_samples;    /* anti-aliased coverage, 640x400 */
    float *depth_lo, *nrm_lo, *mnrm;
    void *refine_scratch;
    size_t refine_scratch_size;
    void *stereo_scratch;    /* refine: fit_stereo.h */
    size_t stereo_scratch_size;
    kin_sthmd_geometry g;
    kin_user_calib calib;     /* estimated from the calibration motion */
    char calib_why[256];
    int calib_hand_fallback;  /* 1: no fingertip gesture, hand = arm scale */
    /* levels of detail of c->mask (eval_lod.c), when a method uses them */
    pipe_lod lod;
    int lod_drawn;            /* the level the last draw_mask drew */
    /* the mask draws' context (one thread), as pipe_frame draws: its
     * vector front end and a clear of what the last draw touched */
    rast_context *rast;
    uint8_t *full_mask;       /* the full model's mask, 640x400 */
    float *full_depth;
    /* the lighting-mismatch sweep (eval_light.c): the ideal composite is
     * made from the camera images under the cockpit's own light, the
     * methods get the images under the mismatched light */
    eval_light light;
} eval_ctx;

/* eval_plan.c: a method's default configuration under the options o
 * (group "methods", setting "default"). */
method_cfg eval__base_cfg(const eval_opts *o, method_kind k);

/* eval.c: runs the configurations cfgs[0..n) into R on `frames` frames of
 * sequence seq (one ground truth built into *c with the tracking `track`,
 * eval__base_cfg's; left there for the caller to free with eval__ctx_free;
 * light: the lighting mismatch, or NULL). IO_EXIT_OK, or IO_EXIT_FAIL with
 * the message printed. */
int eval__run_batch(const eval_opts *o, const gt_track_desc *track, eval_ctx *c, const char *seq,
                    int frames, float speed, const eval_light *light, const method_cfg *cfgs,
                    method_run *R, int n);
void eval__ctx_free(eval_ctx *c);

/* eval.c: the true operator's scales (arm, hand, shoulder width) against
 * the mask model's. */
void eval__true_scales(const eval_ctx *c, float *arm, float *hand, float *shoulder);

/* eval.c: the workshop's lighting (the composite's) in cam's view space. */
fuse_lighting eval__lighting(const gen_scene *ws, const kin_camera *cam);

/* eval_report.c: runs gnuplot on DIR/script, whose charts write
 * "DIR/<chart>.png".sfx, and names each chart once it decodes whole
 * (gnuplot missing or failing: a warning, IO_EXIT_OK; a chart incomplete:
 * removed, IO_EXIT_FAIL). */
int eval__gnuplot(const char *dir, const char *script, const char *const *charts, int n);

/* eval_lod.c: levels of detail. The chain of c->mask and the full
 * model's scratch (0, or -1 with the message printed); the level a
 * method draws for an eye whose clip coordinates are clip (n vertices);
 * the table of the "lod" group; DIR/lod.csv and DIR/lod.dat. */
int eval__lod_init(eval_ctx *c);
void eval__lod_free(eval_ctx *c);
int eval__lod_level(const eval_ctx *c, const method_cfg *cfg, const float *clip, int n,
                    const kin_camera *cam);
void eval__print_lod(FILE *f, const method_run *R, int n, int markdown);
int eval__write_lod(const char *dir, const method_run *R, int n);

/* eval_light.c: the lighting-mismatch sweep. The levels (the first the
 * matched one; at most cap), written into L, their count returned; each
 * level's x and its axis ("gain", "kelvin", "roll"): an axis's points
 * are the matched level and the levels of that axis. */
int eval__light_levels(eval_light *L, int cap);
float eval__light_x(const eval_light *l, const char *axis);
/* The camera image of eye e under c->light into c->P[e] (make_truth calls
 * it after the ideal composite when c->light.on). 0, or -1. */
int eval__light_render(eval_ctx *c, const kin_mat4 *world_from_head, int e, int frame);
/* The methods of a level: kin-cal-pred, skin, refine, and refine with
 * full tone matching ("refine+tone"), group "light" (base: the method's
 * default configuration of o, in kind order). */
int eval__light_configs(const method_cfg base[4], const eval_light *l, method_cfg *L, int cap);
/* The table (stdout and DIR/light.md), DIR/light.dat and the chart
 * DIR/light.png (gnuplot; missing: a warning). */
int eval__write_light(const char *dir, const method_run *R, int n);

/* eval_kf.c: the Fresnel fade against the opaque ideal composite: the
 * configurations (kin-cal-pred and refine at kf 0 .. 1, group "kf"), and
 * the table (stdout and DIR/kf.md when dir is set). */
int eval__kf_configs(const method_cfg base[4], method_cfg *L, int cap);
int eval__write_kf(const char *dir, const method_run *R, int n);

/* eval_out.c (the bottom of the room: eval_report.c and the sweeps call
 * it, it calls nothing above it): a run's means, the report files' open
 * and commit, a table's two passes. */
/* A run's figures per eye (mask IoU, boundary F within 1 and 3 px, false
 * positive and negative area, composite PSNR), per stereo frame (ms) and
 * its edge flicker: eval__summarise divides its sums by their counts (a
 * count of 0 counts as 1; no flicker samples: flicker 0). */
typedef struct eval_summary {
    double iou, bf1, bf3, fp, fn, psnr, ms, flicker;
} eval_summary;
eval_summary eval__summarise(const method_run *r);
/* Report files go through io_out: complete or absent, a failed write is
 * "path: write failed: reason" and exit 1 (io.h, OUTPUT FILES).
 * eval__out_open: the file dir/name (name printf-style; dir NULL: name
 * alone); its stream, or NULL after the message on stderr.
 * eval__out_commit: IO_EXIT_OK, or IO_EXIT_FAIL after the message. */
struct io_out;
FILE *eval__out_open(struct io_out *o, const char *dir, const char *name, ...)
    __attribute__((format(printf, 3, 4)));
int eval__out_commit(struct io_out *o);
/* The passes of a table printed twice: pass 0 as text on stdout, pass 1
 * as Markdown into DIR/name (opened into *o; no pass 1 without dir). Sets
 * *f to the pass's stream and returns 1; 0 when there is no such pass;
 * -1 when DIR/name did not open (the message printed). */
int eval__table_pass(int pass, const char *dir, const char *name, struct io_out *o, FILE **f);

/* eval_report.c: the tables, the CSV and the report folder. */
void eval__print_calib(FILE *f, const eval_ctx *c);
void eval__print_table(FILE *f, const method_run *R, int n, int markdown);
void eval__print_thickness(FILE *f, const eval_ctx *c, const method_run *R, int n);
/* Per method: the error area per eye and frame (FP + FN pixels: mean,
 * 95th percentile, max) and the pooled IoU (the sum of intersections
 * over the sum of unions, every eye and frame): the fair figures where
 * the true mask gets small (a hand leaving the view, docs/accuracy.md). */
void eval__print_error_area(FILE *f, const method_run *R, int n);
int eval__write_csv(const char *path, const method_run *R, int n);
int eval__write_report(const char *dir, const method_run *R, int n, const eval_opts *o,
                       const eval_ctx *c);

#endif
