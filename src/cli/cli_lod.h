/* cli_lod.h - the --lod and --lod-px options of `egofuse render`, `run`
 * and `eval` (levels of detail of the mask model: src/io/io_lod.h,
 * src/pipe/pipe_lod.h; docs/bench.md "Levels of detail"). */
#ifndef EGOFUSE_CLI_LOD_H
#define EGOFUSE_CLI_LOD_H

#include "../io/io_lod.h"
#include "../pipe/pipe.h"

/* The default of --lod: off (level 0, the full model), the figures of
 * docs/bench.md "Levels of detail" say why; and of --lod-px. */
#define CLI_LOD_DEFAULT 0
#define CLI_LOD_PX_DEFAULT 2.0f

#define CLI_LOD_USAGE                                                          \
    "  --lod MODE     levels of detail of the mask model (built when it is\n"   \
    "                 loaded, meshoptimizer): off or 0 (the full model, the\n"  \
    "                 default), a level 1..7 (coarser; the last level when\n"   \
    "                 the model has fewer), or auto: per frame and eye the\n"   \
    "                 coarsest level whose simplification error is at most\n"   \
    "                 --lod-px pixels where the model is nearest the camera\n"  \
    "  --lod-px PX    the error auto allows, pixels (default 2; > 0)\n"

/* Parses MODE of --lod into *level (0..PIPE_LOD_MAX-1, or PIPE_LOD_AUTO).
 * 1, or 0 for a bad MODE. */
int cli_lod_parse(const char *mode, int *level);
/* Parses PX of --lod-px (> 0, finite, <= 1000). 1 or 0. */
int cli_lod_parse_px(const char *s, float *px);
/* For level != 0: builds the chain of model (name: its path, for
 * messages) into *lod and sets it on p (pipe_set_lod). EXIT_OK, or
 * EXIT_FAIL with the message printed (lod then holds nothing). level 0:
 * nothing, *lod zeroed. Free with io_lod_free after the pipe. */
int cli_lod_setup(const char *name, const kin_model *model, int level, float px, pipe_ctx *p,
                  pipe_lod *lod);
/* "off", "L2", "auto@2px" into buf. */
const char *cli_lod_name(int level, float px, char *buf, size_t n);

#endif
