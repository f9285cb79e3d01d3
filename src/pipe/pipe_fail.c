/* pipe_fail.c - the error path of the room's checked calls (pipe__fail,
 * pipe_internal.h), at the bottom of the room: pipe_mask.c and pipe_lens.c
 * both call it, and it calls neither; and an eye's error in the frame
 * (pipe__eye_fail, pipe_ctx.h: pipe.c, pipe_refine.c). */
#include <stdarg.h>
#include <stdio.h>

#include "pipe_ctx.h"
#include "pipe_internal.h"

int pipe__fail(char *why, int why_size, const char *fmt, ...)
{
    if (why && why_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(why, (size_t)why_size, fmt, ap);
        va_end(ap);
    }
    return -1;
}

int pipe__eye_fail(eye_state *e, pipe_result r, const char *what, const char *detail)
{
    e->result = r;
    const char *side = e->eye ? "right" : "left";
    if (detail)
        snprintf(e->why, sizeof e->why, "%s eye: %s: %s", side, what, detail);
    else
        snprintf(e->why, sizeof e->why, "%s eye: %s", side, what);
    return -1;
}
