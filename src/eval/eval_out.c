/* eval_out.c - the bottom of the evaluation room: a report file's open
 * and commit, a table's two passes (the terminal, then DIR/NAME.md) and a
 * run's per-eye means. The writers of the report (eval_report.c), the
 * level-of-detail, lighting and filter sweeps (eval_lod.c, eval_light.c,
 * eval_kf.c) call these; they call nothing of the room above them. */
#include "eval_internal.h"
#include "../io/io.h"
#include "../io/io_term.h"

#include <stdarg.h>
#include <stdio.h>

eval_summary eval__summarise(const method_run *r)
{
    eval_summary s;
    double n = r->n_eye > 0 ? (double)r->n_eye : 1.0;
    s.iou = r->iou / n;
    s.bf1 = r->bf1 / n;
    s.bf3 = r->bf3 / n;
    s.fp = r->fp / n;
    s.fn = r->fn / n;
    s.psnr = fuse_psnr_of_mse(r->mse / n);
    s.ms = 1e3 * r->secs / (r->n_frames > 0 ? (double)r->n_frames : 1.0);
    s.flicker = r->flicker_den > 0.0 ? r->flicker / r->flicker_den : 0.0;
    return s;
}

FILE *eval__out_open(io_out *o, const char *dir, const char *name, ...)
{
    char path[IO_PATH_MAX + 128], nm[IO_PATH_MAX + 64];
    va_list ap;
    va_start(ap, name);
    vsnprintf(nm, sizeof nm, name, ap);
    va_end(ap);
    if (dir) snprintf(path, sizeof path, "%s/%s", dir, nm);
    else snprintf(path, sizeof path, "%s", nm);
    io_error err;
    if (io_out_open(o, path, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        return NULL;
    }
    return o->f;
}

int eval__out_commit(io_out *o)
{
    io_error err;
    if (io_out_commit(o, &err) != IO_OK) return io_term_fail("%s", err.msg);
    return IO_EXIT_OK;
}

int eval__table_pass(int pass, const char *dir, const char *name, io_out *o, FILE **f)
{
    if (pass == 0) {
        *f = stdout;
        return 1;
    }
    if (pass > 1 || !dir) return 0;
    *f = eval__out_open(o, dir, "%s", name);
    return *f ? 1 : -1;
}
