/* io_live.h - the parts of a live cockpit session that are neither a
 * device nor a file format of their own: the cockpit configuration file
 * (`egofuse run --config cockpit.conf`), the per-frame latency record with
 * its running median and p99, and the CSV log of every frame
 * (`egofuse run --stats FILE`). docs/cockpit.md describes the file.
 *
 * CONVENTIONS as io.h: io_result + io_error naming the file (and line) and
 * the reason; outputs are written to "<path>.tmp.<pid>" and renamed only
 * when complete and every write succeeded.
 */
#ifndef EGOFUSE_IO_LIVE_H
#define EGOFUSE_IO_LIVE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------- cockpit configuration */

/* A configuration file turned into command-line options: every
 * "key = value" line becomes "--key=value" (sections prefix their keys,
 * docs/cockpit.md), in file order, so that the options given on the
 * command line after them win. origin[i] is "FILE:LINE" of argv[i]. */
typedef struct io_conf_args {
    int argc;
    char **argv;        /* owned */
    char **origin;      /* owned, one per argv */
} io_conf_args;

/* Parses path. Relative paths in path-valued keys (scene, model, calib,
 * virt, stats, out and a prop's model) are resolved against the file's
 * folder. Errors name the file, the line and the reason (an unknown
 * section, a line without '=', an unterminated quote, a prop without a
 * model). Unknown keys are not checked here: the command reports them,
 * naming the origin. */
io_result io_conf_load(const char *path, io_conf_args *out, io_error *err);
void io_conf_free(io_conf_args *a);

/* ------------------------------------------------------ latency figures */

/* A window of the latest values (milliseconds) and their quantiles. */
#define IO_LAT_WINDOW 512
typedef struct io_lat {
    double v[IO_LAT_WINDOW];
    int n, head;
} io_lat;

void io_lat_reset(io_lat *l);
void io_lat_push(io_lat *l, double ms);
/* Quantile q in [0, 1] of the window (nearest rank: the value at rank
 * ceil(q * n), 1-based, of the sorted window); NaN when empty. */
double io_lat_quantile(const io_lat *l, double q);

/* ------------------------------------------------------- per-frame log */

/* One composited stereo frame of `egofuse run`. Times are CLOCK_MONOTONIC
 * nanoseconds (0 = did not happen); stage times in milliseconds. */
typedef struct io_frame_log {
    uint64_t frame;
    uint64_t t_cam_l, t_cam_r;   /* the cameras' kernel time stamps */
    uint64_t t_dequeue;          /* the pair was taken from the drivers */
    uint64_t t_start, t_done;    /* pipe_frame */
    uint64_t t_present;          /* handed to the output */
    uint64_t t_shown;            /* flip event (KMS), else the output's
                                    own completion (file written, window
                                    presented) */
    double ms_pose, ms_raster[2], ms_fuse[2], ms_total;
    double v_age_ms;             /* age of the virtual frame used; -1 none */
    int v_state;                 /* the V source's state (io_vsrc_state) */
    double skew_ms;              /* right - left camera time stamp */
    double track_age_ms;         /* age of the pose sample; -1 none */
} io_frame_log;

typedef struct io_stats_log {
    FILE *f;
    char path[IO_PATH_MAX];
    char tmp[IO_PATH_MAX + 32];
    int failed;                  /* a write failed: the log is not kept */
    int err_no;
    uint64_t rows;
} io_stats_log;

/* Creates "<path>.tmp.<pid>" and writes the CSV header. */
io_result io_stats_open(io_stats_log *s, const char *path, io_error *err);
/* Appends one row (a failed write is remembered, reported by close). */
void io_stats_row(io_stats_log *s, const io_frame_log *r);
/* Flushes, closes and renames into place; on any failed write the
 * temporary is removed and err says why. Safe on a log never opened. */
io_result io_stats_close(io_stats_log *s, io_error *err);
/* Removes the temporary without keeping anything. */
void io_stats_abandon(io_stats_log *s);

#ifdef __cplusplus
}
#endif
#endif
