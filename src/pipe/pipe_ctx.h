/* pipe_ctx.h - internal to src/pipe: the state of a pipe (struct pipe_ctx)
 * and of each of its eyes, shared by the frame (pipe.c: creation, the
 * eyes' work, the worker thread) and the queries of the last frame
 * (pipe_query.c). Nothing here is public: pipe.h's callers see an opaque
 * pipe_ctx. */
#ifndef EGOFUSE_PIPE_CTX_H
#define EGOFUSE_PIPE_CTX_H

#include "pipe.h"
#include "pipe_aa.h"
#include "pipe_internal.h"
#include "pipe_lens.h"
#include "pipe_parts.h"
#include "pipe_reproj.h"

#include <pthread.h>

typedef struct eye_state {
    int eye;
    float *depth, *clip, *vnrm;
    float *nrm;               /* the camera's normals as floats, or NULL: */
    uint32_t *n10;            /* packed (ef_n10.h) when nothing but the
                                 lighting reads them (pipe_create) */
    uint8_t *mask, *layer;
    uint8_t *layer_zero;      /* fuse_eye.q_zero_rows of layer */
    uint8_t *cam_rgba;        /* the cropped camera image, when given raw */
    float *snrm;              /* smoothed normals (normal_smooth), or
                                 the refined mask's (pipe_nfill.h) */
    void *nfill_scratch;      /* refine_band, normal_smooth >= 0 */
    uint8_t *soft;            /* soft_edge: the softened mask */
    int soft_box[4];          /* where soft may be non-zero (pipe_soft.h) */
    uint8_t *refined;         /* the refined mask (refine_band) */
    uint8_t *regrow;          /* refine_band: the refined mask refined once
                                 more from (pipe_fit_refine_regrow) */
    void *refine_scratch;
    size_t refine_scratch_size;
    int have_refined;         /* refined holds the last frame's mask */
    uint8_t *prior;           /* refine_prior: this frame's input mask */
    uint8_t *shifted;         /* refine_shift: the input's hands moved */
    uint8_t *unsmoothed;      /* refine_smooth: the refined mask before
                                 pipe_fit_smooth (the fit learns from it
                                 and the next prior is it) */
    int have_unsmoothed;      /* unsmoothed holds this frame's */
    float hand_px[2][2];      /* refine_prior: each hand's image position */
    int have_hand_px[2];      /* last frame (pipe_fit_hand_px) */
    pipe__aa aa;              /* anti-aliased coverage (aa_samples) */
    const uint8_t *shown;     /* the mask composited last frame */
    int converted;            /* cam_rgba already holds this frame's crop */
    rast_context *rast;
    fuse_context *fuse;
    pipe_lens_map *lens;      /* a distorting lens: the mask through it */
    kin_camera cam;
    /* per-frame job */
    const pipe_frame_in *in;
    kin_mat4 head;
    pipe_result result;
    char why[160];
    double ms_raster, ms_convert, ms_fuse, coverage;
    int lod_level;            /* the level drawn */
    pipe__reproj rp;          /* eye_view REPROJECT: the eye's view */
    int view_used;            /* this frame: PIPE_VIEW_* */
    long fallbacks;           /* reprojecting frames that fell back */
    int thread;               /* 0 the caller's thread, 1 the worker */
    double t_start;           /* now_ms() at the eye's start */
    /* the fuse in row bands shared by the threads (pipe.c eye_work) */
    int fusing;               /* run_eye reached the fuse: eye_finish's part runs */
    fuse_result fr;           /* the fuse's prepare (tone match) result */
    int filled[4];            /* fuse_depth_fill's box, restored after the fuse */
    int ready;                /* run_eye done: bands open to both threads */
    int bands, band_next, bands_done;
    double ms_bands;          /* the bands' time, summed over threads */
} eye_state;

struct pipe_ctx {
    pipe_desc desc;
    kin_sthmd_desc hmd;
    kin_sthmd_geometry geo;
    pipe_pose pose;
    eye_state eye[2];
    /* threads == 2: the worker shares the eyes' work (pipe.c eye_work) */
    int threaded;
    pthread_t worker;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int job_seq, done_seq, quit;
    int job_kind;             /* JOB_SKIN or JOB_EYE */
    int eye_next, eye_done;   /* JOB_EYE: the next eye to take (2: none
                                 left), the eyes finished */
    double ms_busy[2];        /* JOB_EYE: per thread, time in the eyes' work */
    int skin_split;           /* skin on both threads (large models) */
    kin_skin_plan *plans;     /* per mesh: the skin plan of a skinned mesh */
    void **plan_mem;          /* per mesh: its memory, or NULL */
    pipe_fit *fit;            /* elbow fit (refine_band and fit_rig) */
    kin_arm_rig fit_rig;
    int fit_no_prev;          /* pipe_reset_fit: the refined masks are of
                                 before it, not to be learned from */
    pipe__cockpit *ck;        /* hidden parts and props (pipe_parts.c) */
    const kin_model *model;
    const pipe_lod *lod;      /* pipe_set_lod, or NULL */
    int lod_level;            /* a level, or PIPE_LOD_AUTO */
    float lod_px;             /* the rule's target, pixels */
};

enum { JOB_SKIN, JOB_EYE };

/* pipe_refine.c: eye e's colour refinement (run_eye, when
 * desc.refine_band > 0); fe->mask set to the mask to light. 0, or -1 with
 * e->result and e->why set. */
int pipe__refine_eye(pipe_ctx *p, eye_state *e, fuse_eye *fe);

/* Eye e's error: e->result = r, e->why = "<left|right> eye: what: detail"
 * (detail NULL: "<left|right> eye: what"); returns -1 (pipe_fail.c). */
int pipe__eye_fail(eye_state *e, pipe_result r, const char *what, const char *detail);

#endif
