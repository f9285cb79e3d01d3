/* eval.h - the accuracy evaluation of egofuse (`egofuse eval`, the report
 * in docs/accuracy.md): the masks and composites of several methods
 * against generated ground truth (samples/gt/, the metrics of
 * src/fuse/fuse_metrics.h).
 *
 * WHAT IT DOES
 *   eval_run(): per display frame (60 Hz) the true operator is posed and
 *   rendered into both camera images over the cockpit (with its exact
 *   silhouettes and the ideal composite); then every method configuration
 *   (kin, kin-cal-pred, skin, refine and their knobs), with its own
 *   tracking stream (noise, latency, dropouts) and its own state (filter,
 *   last sample, previous masks, elbow fit of src/fit), makes its masks and
 *   composites, which are timed and measured. A report runs several such
 *   batches (methods, knobs, tracking sweeps, other sequences), each on its
 *   own ground truth, and writes the tables (summary.csv, table.md, per
 *   group and sequence) and the charts (*.png).
 *
 * WHAT IT DOES NOT
 *   No option parsing (src/cli/cmd_eval.c does it and fills eval_opts). It
 *   is not part of the core library: it needs the sample generator and the
 *   ground truth (samples/gen, samples/gt, build/libegofuse_samples.a) and
 *   is linked into the egofuse program only. Messages and the progress
 *   line go through src/io/io_term.h (shared with the commands).
 *
 * USAGE
 *   eval_opts o = ...;              // see cmd_eval.c for the defaults
 *   o.methods = eval_parse_methods("kin,refine");
 *   return eval_run(&o);            // IO_EXIT_OK or IO_EXIT_FAIL (message printed)
 */
#ifndef EGOFUSE_EVAL_H
#define EGOFUSE_EVAL_H

#include "../../samples/gt/gt.h"

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
    int lod;                 /* level of detail of the mask model for every
                                method: 0 = the full model, a level, or
                                PIPE_LOD_AUTO (src/pipe/pipe_lod.h) */
    float lod_px;            /* the rule's target with PIPE_LOD_AUTO */
    int lod_sweep;           /* 1: also the levels batch (group "lod"; a
                                report always runs it) */
    int eyeview;             /* 1: `egofuse eval --eyeview` (eval_eye_run) */
    int light_sweep;         /* 1: also the lighting-mismatch sweep (group
                                "light", eval_light.c; a report always
                                runs it, on sweep_frames) */
    const char *light_dir;   /* with light_sweep and no report: the folder
                                of its table, data and chart (NULL: the
                                table on stdout only) */
    int kf_sweep;            /* 1: also the Fresnel fade kf 0..1 against the
                                opaque ideal composite (group "kf",
                                eval_kf.c; a report always runs it) */
    int stereo;              /* 1: refine with the stereo pair's depth test
                                (src/fit/fit_stereo.h; measured, off by
                                default: docs/accuracy.md) */
} eval_opts;

/* "kin,refine" -> bits of the methods (kin, kin-cal-pred, skin, refine:
 * bits 0..3; refine's variants refine-nomc, refine-noshift,
 * refine-shiftall: bits 4..6); 0 when a name is unknown. */
unsigned eval_parse_methods(const char *list);
/* Runs the evaluation o describes, prints its tables, writes o->csv and
 * the report folder o->report when set. IO_EXIT_OK, or IO_EXIT_FAIL with the
 * message printed. */
int eval_run(const eval_opts *o);

/* The eye's viewpoint (src/eval/eval_eye.c, docs/accuracy.md): the hand
 * held 15, 20, 30, 40 cm from the eyes, tracking noise 0-20 mm, per view
 * method (crop, reproj) the hand's position and size error, the IoU and
 * PSNR against ground truth from the true eye, the ms per stereo frame.
 * Uses frames (per distance, at most 180), seed, csv, report, quiet,
 * per_frame. IO_EXIT_OK, or IO_EXIT_FAIL with the message printed. */
int eval_eye_run(const eval_opts *o);

#endif
