/* pipe_track.c - the tracking filter of a pipe with the refine method's
 * adaptive lag compensation (pipe.h: pipe_track_output). */
#include "pipe.h"
#include "../fit/fit_band.h"

#include <string.h>

static int lag_adapt(const pipe_desc *d)
{
    return d && d->refine_band > 0 && d->refine_lag_adapt == 0;
}

kin_filter_desc pipe_track_filter_desc(const pipe_desc *d)
{
    kin_filter_desc fd;
    memset(&fd, 0, sizeof fd);
    fd.no_lag_comp = lag_adapt(d);
    return fd;
}

void pipe_track_output(const pipe_desc *d, const kin_filter *f, double display_t,
                       kin_track_sample *out, float speed[2])
{
    if (lag_adapt(d)) {
        pipe_fit_filter_output(f, display_t, PIPE_LAG_V0, PIPE_LAG_V1, out, speed);
        return;
    }
    /* the speeds as pipe_fit_filter_output gives them, the output kin's
     * (v1 <= v0: kin_filter_output) */
    pipe_fit_filter_output(f, display_t, 0.0f, 0.0f, out, speed);
}
