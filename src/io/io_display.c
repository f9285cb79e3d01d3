/* io_display.c - display outputs (io_display.h): the spec parser, and
 * the public calls that open a backend (io_display_kms.c, io_display_sdl.c)
 * and dispatch to it. What the backends share lies below them, in
 * io_display_common.c. */
#include "io_display_impl.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* "WxH" or "WxH@HZ" into w, h, hz (hz may be NULL: then no @ allowed). */
static int parse_size(const char *s, int *w, int *h, int *hz)
{
    char *end;
    errno = 0;
    long a = strtol(s, &end, 10);
    if (end == s || (*end != 'x' && *end != 'X') || a <= 0 || a > 16384) return -1;
    const char *p = end + 1;
    long b = strtol(p, &end, 10);
    if (end == p || b <= 0 || b > 16384) return -1;
    long c = 0;
    if (*end == '@' && hz) {
        p = end + 1;
        c = strtol(p, &end, 10);
        if (end == p || c <= 0 || c > 1000) return -1;
    }
    if (*end != '\0') return -1;
    *w = (int)a;
    *h = (int)b;
    if (hz) *hz = (int)c;
    return 0;
}

#define SPEC_HELP "kms[:/dev/dri/cardN][,connector=NAME[+NAME2]][,mode=WxH[@HZ]][,layout=sbs|two] or sdl[:WxH]"

io_result io_display_parse(const char *spec, io_display_spec *o, io_error *err)
{
    memset(o, 0, sizeof *o);
    if (!spec || !spec[0])
        return io_fail(err, IO_ERR_ARGS, "display: no display given (%s)", SPEC_HELP);
    char buf[512];
    if (strlen(spec) >= sizeof buf)
        return io_fail(err, IO_ERR_ARGS, "display '%.40s...': too long", spec);
    snprintf(buf, sizeof buf, "%s", spec);
    char *opts = strchr(buf, ',');
    if (opts) *opts++ = '\0';
    char *arg = strchr(buf, ':');
    if (arg) *arg++ = '\0';
    if (!strcmp(buf, "kms")) {
        o->kind = IO_DISPLAY_KMS;
        if (arg) {
            if (!arg[0] || strlen(arg) >= sizeof o->device)
                return io_fail(err, IO_ERR_ARGS, "display '%s': the device after 'kms:' is empty or too long", spec);
            snprintf(o->device, sizeof o->device, "%s", arg);
        }
    } else if (!strcmp(buf, "sdl")) {
        o->kind = IO_DISPLAY_SDL;
        if (arg && parse_size(arg, &o->win_w, &o->win_h, NULL) != 0)
            return io_fail(err, IO_ERR_ARGS, "display '%s': window size '%s' is not WxH", spec, arg);
        if (opts)
            return io_fail(err, IO_ERR_ARGS, "display '%s': sdl takes no options (sdl[:WxH])", spec);
        return IO_OK;
    } else {
        return io_fail(err, IO_ERR_ARGS, "display '%s': unknown kind '%s' (%s)", spec, buf, SPEC_HELP);
    }
    while (opts && *opts) {
        char *next = strchr(opts, ',');
        if (next) *next++ = '\0';
        char *val = strchr(opts, '=');
        if (!val)
            return io_fail(err, IO_ERR_ARGS, "display '%s': option '%s' is not key=value", spec, opts);
        *val++ = '\0';
        if (!val[0])
            return io_fail(err, IO_ERR_ARGS, "display '%s': option '%s' has no value", spec, opts);
        if (!strcmp(opts, "connector")) {
            char *plus = strchr(val, '+');
            if (plus) *plus++ = '\0';
            const char *names[2] = {val, plus};
            for (int i = 0; i < 2 && names[i]; i++) {
                if (!names[i][0] || strlen(names[i]) >= sizeof o->connector[0] || strchr(names[i], '+'))
                    return io_fail(err, IO_ERR_ARGS, "display '%s': connector '%s' is not NAME or NAME+NAME",
                                   spec, names[i]);
                snprintf(o->connector[i], sizeof o->connector[i], "%s", names[i]);
                o->nconnectors = i + 1;
            }
        } else if (!strcmp(opts, "mode")) {
            if (parse_size(val, &o->mode_w, &o->mode_h, &o->mode_hz) != 0)
                return io_fail(err, IO_ERR_ARGS, "display '%s': mode '%s' is not WxH or WxH@HZ", spec, val);
        } else if (!strcmp(opts, "layout")) {
            if (!strcmp(val, "sbs")) o->layout = IO_LAYOUT_SBS;
            else if (!strcmp(val, "two")) o->layout = IO_LAYOUT_TWO;
            else return io_fail(err, IO_ERR_ARGS, "display '%s': layout '%s' is not sbs or two", spec, val);
        } else if (!strcmp(opts, "buffers")) {
            char *end;
            long b = strtol(val, &end, 10);
            if (*end || b < 2 || b > 3)
                return io_fail(err, IO_ERR_ARGS, "display '%s': buffers '%s' is not 2 or 3", spec, val);
            o->buffers = (int)b;
        } else {
            return io_fail(err, IO_ERR_ARGS,
                           "display '%s': unknown option '%s' (connector, mode, layout, buffers)", spec, opts);
        }
        opts = next;
    }
    if (o->layout == IO_LAYOUT_SBS && o->nconnectors == 2)
        return io_fail(err, IO_ERR_ARGS, "display '%s': layout=sbs takes one connector, two are named", spec);
    if (o->layout == IO_LAYOUT_TWO && o->nconnectors == 1)
        return io_fail(err, IO_ERR_ARGS, "display '%s': layout=two needs two connectors (connector=A+B)", spec);
    if (o->nconnectors == 2) o->layout = IO_LAYOUT_TWO;
    if (o->nconnectors == 1) o->layout = IO_LAYOUT_SBS;
    return IO_OK;
}

io_result io_display_open(io_display **out, const io_display_config *c, io_error *err)
{
    if (!out || !c) return io_fail(err, IO_ERR_ARGS, "display: io_display_open needs out and a config");
    *out = NULL;
    io_display_spec s;
    io_result r = io_display_parse(c->spec, &s, err);
    if (r != IO_OK) return r;
    if (c->eye_width <= 0 || c->eye_height <= 0 || c->eye_width > 8192 || c->eye_height > 8192)
        return io_fail(err, IO_ERR_ARGS, "display '%s': eye size %dx%d is not valid", c->spec,
                       c->eye_width, c->eye_height);
    int buffers = s.buffers ? s.buffers : c->buffers ? c->buffers : 2;
    if (buffers < 2 || buffers > 3)
        return io_fail(err, IO_ERR_ARGS, "display '%s': %d buffers asked, 2 or 3 possible", c->spec, buffers);
    io_display *d = calloc(1, sizeof *d);
    if (!d) return io_fail(err, IO_ERR_NOMEM, "display '%s': out of memory", c->spec);
    d->kind = s.kind;
    d->eye_w = c->eye_width;
    d->eye_h = c->eye_height;
    r = s.kind == IO_DISPLAY_KMS ? io_display_kms_open(d, &s, buffers, err)
                                 : io_display_sdl_open(d, &s, err);
    if (r != IO_OK) {
        free(d);
        return r;
    }
    *out = d;
    return IO_OK;
}

int io_display_fd(const io_display *d) { return d && d->ops->fd ? d->ops->fd(d) : -1; }

io_result io_display_present(io_display *d, const uint8_t *const rgba[2], const size_t stride[2],
                             uint64_t frame_id, io_error *err)
{
    if (!d || !rgba || !stride || !rgba[0] || !rgba[1])
        return io_fail(err, IO_ERR_ARGS, "display: io_display_present needs a display and two images");
    for (int i = 0; i < 2; i++)
        if (stride[i] < (size_t)d->eye_w * 4)
            return io_fail(err, IO_ERR_ARGS, "%s: eye %d stride %zu is less than %d pixels of RGBA",
                           d->desc, i, stride[i], d->eye_w);
    return d->ops->present(d, rgba, stride, frame_id, err);
}

io_result io_display_poll(io_display *d, int timeout_ms, io_display_flip *ev, int *got, io_error *err)
{
    if (got) *got = 0;
    if (!d || !ev || !got) return io_fail(err, IO_ERR_ARGS, "display: io_display_poll needs a display, ev and got");
    if (!d->qlen) {
        io_result r = d->ops->wait(d, timeout_ms, err);
        if (r != IO_OK) return r;
    }
    if (d->qlen) {
        *ev = d->q[d->qhead];
        d->qhead = (d->qhead + 1) % IO_DISPLAY_QUEUE;
        d->qlen--;
        *got = 1;
    }
    return IO_OK;
}

int io_display_busy(const io_display *d) { return d ? d->ops->busy(d) : 0; }
uint64_t io_display_refresh_ns(const io_display *d) { return d ? d->refresh_ns : 0; }
int io_display_quit_requested(const io_display *d) { return d ? d->quit : 0; }
const char *io_display_describe(const io_display *d) { return d ? d->desc : "no display"; }

void io_display_size(const io_display *d, int *width, int *height)
{
    if (width) *width = d ? d->out_w : 0;
    if (height) *height = d ? d->out_h : 0;
}

void io_display_close(io_display **pd)
{
    if (!pd || !*pd) return;
    io_display *d = *pd;
    *pd = NULL;
    if (d->be) {
        d->ops->release(d->be);
        free(d->be);
    }
    free(d);
}
