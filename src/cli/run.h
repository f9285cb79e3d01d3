/* run.h - `egofuse run`, the live cockpit: its options (run_opts.c: the
 * command line merged with the cockpit configuration file) and the loop
 * (cmd_run.c) and its --dump files (run_dump.c). docs/cockpit.md. */
#ifndef EGOFUSE_RUN_H
#define EGOFUSE_RUN_H

#include "cli.h"
#include "../io/io_dev.h"

#define RUN_MAX_PROPS 8
#define RUN_MAX_NATNET 32

/* A real object of the cockpit cut in like the hands (--prop). */
typedef struct run_prop {
    char name[64];
    char model[IO_PATH_MAX];
    float at[3];              /* metres: world position, or offset in the
                                 body's frame when body is set */
    float rot_deg[3];         /* yaw (about +Y), pitch (+X), roll (+Z) */
    char body[64];            /* tracked rigid body (name or #id), "" = fixed */
} run_prop;

typedef struct run_opts {
    const char *scene, *model, *virt[2], *sel[2], *glove_sel[2], *calib, *out, *stats, *dump;
    const char *virt_source, *virt_layout, *display;
    const char *track_addr;
    /* NatNet: key, value pairs for io_natnet_config_set, in order */
    int natnet;                   /* 1: --natnet given */
    const char *natnet_kv[RUN_MAX_NATNET][2];
    int natnet_kv_count;
    int virt_stale_ms, virt_fps;
    uint32_t fourcc;
    int fps, input, dv, buffers, track_port, raw, frames, quiet;
    int format_set;           /* --format given (file cameras default to RGB) */
    int loop;                 /* file cameras: start again at the end */
    int hold;                 /* --display: keep the last frame shown until Ctrl-C */
    int refine;               /* refinement band, px; 0 = off */
    int lod;                  /* --lod: a level, PIPE_LOD_AUTO; 0 = off */
    float lod_px;             /* --lod-px */
    int aa;                   /* coverage samples per pixel (--aa); 0 = off */
    int view;                 /* --view: PIPE_VIEW_CROP (default), _REPROJECT */
    int edge_fade;            /* pipe_desc.edge_fade (--edge-fade): 0 default, -1 off */
    int soft_edge;            /* pipe_desc.soft_edge (--soft-edges, --hard-edges) */
    float predict_ms;         /* pose time = camera time + this */
    unsigned hide;            /* PIPE_PART_* bits hidden */
    kin_sthmd_desc hmd;       /* zero fields = the paper's */
    const char *hmd_calib[3]; /* --hmd-calibration, -left, -right (docs/lens.md) */
    run_prop prop[RUN_MAX_PROPS];
    int prop_count;
    char *storage;            /* owned strings (config values) */
} run_opts;

/* Parses the command line of `egofuse run` (argv[0] = "run"), after the
 * options of --config FILE when one is given (the command line wins).
 * Returns -1 when the options are fine, else the exit code to return
 * (EXIT_OK for --help, EXIT_USAGE / EXIT_FAIL with a message printed). */
int run_parse(int argc, char **argv, run_opts *o);
void run_opts_free(run_opts *o);

extern const char *run_usage;

/* The cameras of a run (run_cams.c): --left / --right resolved (a USB
 * selector to its /dev/videoN), or recorded frames (*file_cams 1), or
 * without selectors the first two capture nodes in /dev. EXIT_OK with
 * path[0] left and path[1] right, else the exit status with the message
 * printed (how to make a dry run when no camera is found). */
int run_find_cameras(const run_opts *o, char path[2][IO_CAM_NAME_MAX], int *file_cams);
/* A camera selector to a /dev/videoN path: 0, or -1 with err set. */
int run_resolve_camera(const char *sel, char *path, size_t n, io_error *err);

/* What --dump reads of the run besides its options (cmd_run.c's state). */
typedef struct run_dump_src {
    const io_image *camimg;       /* [2] the camera images as converted */
    const io_image *vdepth;       /* [2] the still virtual images' depth (data NULL: none) */
    const char (*vdepth_path)[IO_PATH_MAX + 64]; /* [2] their files */
    const char *model_path;
    const io_scene *sc;           /* the scene file's, NULL without one */
} run_dump_src;

/* --dump DIR (run_dump.c): the inputs of the last frame as a one-frame
 * scene that `egofuse render` composites to the same bytes (camera images
 * as converted, the virtual images used, the pose sample used; the
 * scene's lighting lines copied verbatim), and the render command in
 * command.txt. With --refine the elbow fit's learned state is not part of
 * it, so render differs there. EXIT_OK, or EXIT_FAIL with the message
 * printed. */
int run_dump_frame(const run_opts *o, const run_dump_src *src, const pipe_frame_in *in,
                   const kin_track_sample *sample, int tracked, int W, int H);

#endif
