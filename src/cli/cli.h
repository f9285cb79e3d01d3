/* cli.h - internals of the egofuse program (not a library interface). */
#ifndef EGOFUSE_CLI_H
#define EGOFUSE_CLI_H

#include <stdio.h>

#include "../fuse/fuse.h"
#include "../io/io.h"
#include "../io/io_term.h"
#include "../kin/kin.h"
#include "../pipe/pipe.h"
#include "../raster/raster.h"

/* Exit codes of every subcommand (io_term.h). */
enum { EXIT_OK = IO_EXIT_OK, EXIT_FAIL = IO_EXIT_FAIL, EXIT_USAGE = IO_EXIT_USAGE };

int cmd_mask(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_demo(int argc, char **argv);
int cmd_eval(int argc, char **argv);   /* cmd_eval.c, docs/accuracy.md */
int cmd_run(int argc, char **argv);    /* cmd_run.c, docs/devices.md */
int cmd_devices(int argc, char **argv);/* cmd_devices.c, docs/devices.md */
int cmd_replay(int argc, char **argv); /* cmd_replay.c, docs/tracking.md */
int cmd_calibrate(int argc, char **argv); /* cmd_calibrate.c, docs/tracking.md */

/* Messages with the program's name (io_term_fail), progress, folders and
 * the clock: src/io/io_term.h, shared with the evaluation (src/eval). */
/* Prints "egofuse CMD: " + message + a hint to run --help; EXIT_USAGE. */
int cli_usage_error(const char *cmd, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* getopt_long's answer c to a bad option (opterr 0): ':' "option --X
 * needs a value", else "unknown option '--X'", as cli_usage_error (the
 * option is argv[optind - 1]). */
int cli_option_error(const char *cmd, int c, char *const *argv);

/* A subcommand's option loop: cli_getopt_begin, then cli_getopt until it
 * returns 0 or less. cli_getopt_begin: getopt_long starts again at
 * argv[1], with its own messages off. cli_getopt: the next option's value
 * for the command's switch (getopt_long with -h the only short option); 0
 * after the last option; -1 when the command is to return *rc: after -h or
 * --help (cmd's usage printed on stdout; EXIT_OK) or a bad option
 * (cli_option_error; EXIT_USAGE). */
struct option;
void cli_getopt_begin(void);
int cli_getopt(const char *cmd, const char *usage, int argc, char **argv,
               const struct option *opts, int *rc);

/* Reads OpenCV calibration files (io_calib.h) into hmd->lens: both for
 * both cameras (a stereo file: its first camera left, its second right),
 * left / right for one each (they win over both); NULL = none. Checks the
 * image size against hmd's camera size when that is set (the same aspect;
 * kin_sthmd_desc_resolved scales). EXIT_OK, or EXIT_FAIL with the file
 * and the reason printed. cli_lens.c, docs/lens.md. */
int cli_lens_load(const char *both, const char *left, const char *right, kin_sthmd_desc *hmd);
/* 1 if hmd's lenses (when given, with a size) have its camera's aspect;
 * else 0 with a sentence in why (e.g. a scene's named HMD, known only
 * after the options). */
int cli_lens_fits(const kin_sthmd_desc *hmd, char *why, size_t why_size);

/* --view of render and run (cli_view.c, docs/eyeview.md): "crop" or
 * "reproject" into *view (PIPE_VIEW_*), EXIT_OK, else EXIT_USAGE with a
 * message. cli_view_check: with PIPE_VIEW_REPROJECT, no --aa and the
 * resolved IPD and camera offset D in pipe_view_check's ranges, else
 * EXIT_USAGE naming the option and the range. cli_hmd_len_parse: a
 * length option --OPT in lo..hi metres (EXIT_USAGE otherwise). */
int cli_view_parse(const char *cmd, const char *arg, int *view);
int cli_view_check(const char *cmd, int view, int aa, const kin_sthmd_desc *hmd);
int cli_hmd_len_parse(const char *cmd, const char *opt, const char *arg, float lo, float hi,
                      float *out);
/* Soft silhouettes of render and run (pipe_desc.soft_edge, issue 14 item
 * 3): *soft is 1 (--soft-edges), 0 (--hard-edges) or -1 (neither: the
 * default). The default is on without --aa (whose coverage samples are
 * soft already), in either view, and off with it; --soft-edges with --aa
 * is EXIT_USAGE with a message. On EXIT_OK *soft is 0 or 1. */
int cli_soft_edges(const char *cmd, int *soft, int aa);

/* Strict parsers: the whole string must be the number(s); finite. */
int cli_parse_int(const char *s, int lo, int hi, int *out);
int cli_parse_float(const char *s, float *out);
int cli_parse_vec3(const char *s, float out[3]);
/* A keyword option's value: the index of s in words (a list ending in
 * NULL), or -1 when s is none of them. */
int cli_pick(const char *s, const char *const *words);

/* A float option checked against a closed range, one row of a command's
 * table of them (instead of a case each): getopt's value for it, its name
 * ("--noise"), the range, what the message says after "NAME 'VALUE': "
 * ("not in 0..200 mm"), and where the value goes. */
typedef struct cli_float_opt {
    int id;
    const char *name;
    float lo, hi;
    const char *range;
    float *dst;
} cli_float_opt;
/* The row of t[0..n) for getopt's value id, or NULL. */
const cli_float_opt *cli_float_opt_find(const cli_float_opt *t, int n, int id);
/* arg (cli_parse_float) into *e->dst when it is in [e->lo, e->hi]: 1;
 * else 0, *e->dst unchanged. */
int cli_float_opt_parse(const cli_float_opt *e, const char *arg);

#endif
