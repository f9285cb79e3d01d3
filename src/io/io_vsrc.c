/* io_vsrc.c - the virtual or remote scene V as a live input (io_vsrc.h):
 * V4L2 capture devices (through io_cam) and frame streams on pipes, FIFOs,
 * files or stdin (through the reader of io_vstream.c), latest frame wins,
 * converted and scaled into the two eye images; status for the caller's
 * status line. docs/vstream.md. */
#include "io_vsrc.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/timerfd.h>
#include <time.h>
#include <unistd.h>

#include "io_vstream.h"

enum { K_V4L2 = 1, K_STREAM = 2 };

struct io_vsrc {
    io_vsrc_config cfg;
    char spec[1024];
    int kind;
    int ew, eh;
    /* output */
    uint8_t *eyebuf[2];           /* scaled eyes (ew x eh RGBA) */
    const uint8_t *eye[2];
    size_t eye_stride[2];
    float *dbuf[2];
    int has_depth;
    uint8_t *stage[2];            /* converted source frame per device */
    size_t stage_cap[2];
    int *xt, *yt;                 /* scaler scratch */
    uint16_t *rows;
    int have_eye[2];
    /* status */
    io_vsrc_state hard;           /* 0, IO_VSRC_ENDED or IO_VSRC_FAILED */
    uint64_t t_frame[2], t_arrival[2];
    uint64_t frames, skipped, bad, reopens;
    int src_w, src_h, layout;
    uint32_t fourcc;
    char msg[384];
    /* v4l2 */
    int ndev;
    io_cam cam[2];
    uint64_t last_try[2];
    uint64_t cam_skipped_base[2];
    /* stream */
    char path[1024];
    int fd, own_fd;
    int fd_flags;                 /* stdin's flags before, restored at close */
    int is_fifo, is_reg;
    vs_reader r;
    uint64_t retry_ns;
    int reopened;
    /* pacing of regular files */
    int paced;
    uint64_t pace_t0, pace_period, pace_taken;
    int tfd;
    int rewind;                   /* loop: rewind before the next read */
    uint64_t since_rewind;        /* frames parsed since the (re)start */
};

static uint64_t clock_of(const io_vsrc *v)
{
    return v->cfg.clock_ns ? *v->cfg.clock_ns : io_now_ns();
}

static void set_msg(io_vsrc *v, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_msg(io_vsrc *v, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->msg, sizeof v->msg, fmt, ap);
    va_end(ap);
}

const char *io_vsrc_state_name(io_vsrc_state s)
{
    static const char *const n[] = {"waiting", "live", "stale", "ended", "failed"};
    return (int)s >= 0 && (int)s < 5 ? n[s] : "unknown";
}

const char *io_vsrc_layout_name(int l)
{
    static const char *const n[] = {"auto", "mono", "sbs", "tb"};
    return l >= 0 && l < 4 ? n[l] : "unknown";
}

int io_vsrc_layout_parse(const char *s)
{
    if (!s) return -1;
    for (int l = 0; l < 4; l++)
        if (!strcmp(s, io_vsrc_layout_name(l))) return l;
    return -1;
}

io_vsrc_config io_vsrc_config_default(const char *spec)
{
    io_vsrc_config c;
    memset(&c, 0, sizeof c);
    c.spec = spec;
    c.eye_width = 1280;
    c.eye_height = 800;
    c.layout = IO_VSRC_AUTO;
    c.stale_ms = 200;
    c.input = -1;
    return c;
}

/* ------------------------------------------------------------- output */

/* AUTO: side by side when the frame is at least 1.5 times as wide (for
 * its height) as an eye, top-bottom when at most 0.75 times, else mono. */
static int resolve_layout(const io_vsrc *v, int layout, int w, int h)
{
    if (layout >= IO_VSRC_MONO && layout <= IO_VSRC_TB) return layout;
    if (v->cfg.layout >= IO_VSRC_MONO && v->cfg.layout <= IO_VSRC_TB) return v->cfg.layout;
    double r = ((double)w / h) / ((double)v->ew / v->eh);
    return r >= 1.5 ? IO_VSRC_SBS : r <= 0.75 ? IO_VSRC_TB : IO_VSRC_MONO;
}

static void eye_region(int layout, int e, int w, int h, int *x0, int *y0, int *rw, int *rh)
{
    *x0 = *y0 = 0;
    *rw = w;
    *rh = h;
    if (layout == IO_VSRC_SBS) {
        *rw = w / 2;
        *x0 = e * (w / 2);
    } else if (layout == IO_VSRC_TB) {
        *rh = h / 2;
        *y0 = e * (h / 2);
    }
}

/* Converts frame f (from device `dev`) into the eyes: both eyes split by
 * layout (eye_only < 0), or only eye `eye_only` (one device per eye). */
static io_result apply_frame(io_vsrc *v, const io_frame *f, int full, int layout, int dev,
                             int eye_only, io_error *err)
{
    size_t ss = 4 * (size_t)f->width, need = ss * (size_t)f->height;
    char fs[5];
    size_t fb = io_fmt_image_bytes(f->fourcc, f->stride, f->width, f->height);
    if (!fb || f->bytes < fb)
        return io_fail(err, IO_ERR_FORMAT, "%s: %dx%d %s frame of %zu bytes cannot be converted",
                       v->spec, f->width, f->height, io_fourcc_str(f->fourcc, fs), f->bytes);
    if (need > v->stage_cap[dev]) {
        /* (only the first frame grows it: the size of a source is fixed) */
        uint8_t *nb = realloc(v->stage[dev], need);
        if (!nb) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory for a %dx%d frame", v->spec,
                                f->width, f->height);
        v->stage[dev] = nb;
        v->stage_cap[dev] = need;
    }
    io_result r = io_frame_to_rgba_range(f, v->stage[dev], ss, full, err);
    if (r != IO_OK) return r;
    if (eye_only >= 0) layout = IO_VSRC_MONO;
    else layout = resolve_layout(v, layout, f->width, f->height);
    for (int e = 0; e < 2; e++) {
        if (eye_only >= 0 && e != eye_only) continue;
        int x0, y0, rw, rh;
        eye_region(layout, e, f->width, f->height, &x0, &y0, &rw, &rh);
        const uint8_t *src = v->stage[dev] + (size_t)y0 * ss + 4 * (size_t)x0;
        if (rw == v->ew && rh == v->eh) {
            v->eye[e] = src;
            v->eye_stride[e] = ss;
        } else if (layout == IO_VSRC_MONO && e == 1 && eye_only < 0) {
            v->eye[1] = v->eye[0];
            v->eye_stride[1] = v->eye_stride[0];
        } else {
            vs_scale_rgba(src, rw, rh, ss, v->eyebuf[e], v->ew, v->eh, 4 * (size_t)v->ew, v->xt,
                          v->yt, v->rows);
            v->eye[e] = v->eyebuf[e];
            v->eye_stride[e] = 4 * (size_t)v->ew;
        }
        v->have_eye[e] = 1;
    }
    v->src_w = f->width;
    v->src_h = f->height;
    v->fourcc = f->fourcc;
    v->layout = layout;
    return IO_OK;
}

static void apply_depth(io_vsrc *v, const uint8_t *d, int fmt, float scale, int w, int h,
                        int layout)
{
    size_t bpp = fmt == VS_DEPTH_F32 ? 4 : 2, ss = bpp * (size_t)w;
    for (int e = 0; e < 2; e++) {
        int x0, y0, rw, rh;
        eye_region(layout, e, w, h, &x0, &y0, &rw, &rh);
        vs_scale_depth(d + (size_t)y0 * ss + bpp * (size_t)x0, fmt, scale, rw, rh, ss, v->dbuf[e],
                       v->ew, v->eh, (size_t)v->ew);
    }
    v->has_depth = 1;
}

/* -------------------------------------------------------------- v4l2 */

static io_result open_v4l2(io_vsrc *v, const char *list, io_error *err)
{
    char devs[2][IO_CAM_NAME_MAX];
    const char *comma = strchr(list, ',');
    if (comma) {
        snprintf(devs[0], sizeof devs[0], "%.*s", (int)(comma - list), list);
        snprintf(devs[1], sizeof devs[1], "%s", comma + 1);
        v->ndev = 2;
    } else {
        snprintf(devs[0], sizeof devs[0], "%s", list);
        v->ndev = 1;
    }
    for (int i = 0; i < v->ndev; i++) {
        if (!devs[i][0] || strchr(devs[i], ','))
            return io_fail(err, IO_ERR_ARGS, "%s: expected v4l2:/dev/videoN or "
                           "v4l2:/dev/videoA,/dev/videoB", v->spec);
        io_cam_config c = io_cam_config_default(devs[i]);
        c.fourcc = v->cfg.fourcc;
        c.width = v->cfg.width;
        c.height = v->cfg.height;
        c.fps = v->cfg.fps;
        c.input = v->cfg.input;
        c.dv_timings = v->cfg.dv_timings;
        io_error e2;
        io_result r = io_cam_open(&v->cam[i], &io_cam_v4l2, &c, &e2);
        if (r == IO_OK) r = io_cam_start(&v->cam[i], &e2);
        if (r != IO_OK) {
            io_cam_close(&v->cam[i]);
            return io_fail(err, r, "V source %s: %s", v->spec, e2.msg);
        }
    }
    return IO_OK;
}

static void poll_v4l2_once(io_vsrc *v, uint64_t now, int *fresh)
{
    for (int i = 0; i < v->ndev; i++) {
        io_cam *c = &v->cam[i];
        io_error e2;
        if (c->state != IO_CAM_STREAMING) {
            if (now - v->last_try[i] < 1000000000ull && v->last_try[i]) continue;
            v->last_try[i] = now;
            io_result r = io_cam_reopen(c, NULL, &e2);
            if (r == IO_OK && c->state != IO_CAM_STREAMING) r = io_cam_start(c, &e2);
            if (r == IO_OK) {
                v->reopens++;
                set_msg(v, "V source %s: %s is back", v->spec, c->cfg.path);
            } else {
                io_cam_close(c); /* nothing held between tries */
                set_msg(v, "V source %s: %s (reopening once a second)", v->spec, e2.msg);
            }
            continue;
        }
        io_frame f;
        int got = 0;
        io_result r = io_cam_grab(c, 0, &f, &got, &e2);
        if (r != IO_OK) {
            /* gone: let go of the node at once (a replugged device may
             * take the same number), try again in a second */
            io_cam_close(c);
            v->hard = IO_VSRC_FAILED;
            v->last_try[i] = now;
            set_msg(v, "V source %s: %s (reopening once a second)", v->spec, e2.msg);
            continue;
        }
        if (!got) continue;
        io_result ar = apply_frame(v, &f, 0, v->cfg.layout, i, v->ndev == 2 ? i : -1, &e2);
        io_cam_release(c, &f, NULL);
        if (ar != IO_OK) {
            v->bad++;
            set_msg(v, "V source %s: %s", v->spec, e2.msg);
            continue;
        }
        int eyes = v->ndev == 2 ? (1 << i) : 3;
        for (int e = 0; e < 2; e++)
            if (eyes & (1 << e)) {
                v->t_frame[e] = f.t_ns;
                v->t_arrival[e] = now;
            }
        v->frames++;
        *fresh = 1;
    }
    int failed = 0;
    for (int i = 0; i < v->ndev; i++) failed |= v->cam[i].state != IO_CAM_STREAMING;
    if (failed) v->hard = IO_VSRC_FAILED;
    else if (v->hard == IO_VSRC_FAILED) v->hard = 0;
}

/* ------------------------------------------------------------ stream */

static void stream_close_fd(io_vsrc *v)
{
    if (v->fd >= 0 && v->own_fd) close(v->fd);
    else if (v->fd >= 0 && v->fd_flags >= 0) fcntl(v->fd, F_SETFL, v->fd_flags); /* a shared tty */
    v->fd = -1;
}

static io_result stream_open_fd(io_vsrc *v, io_error *err)
{
    if (!strcmp(v->path, "-")) {
        v->fd = 0;
        v->own_fd = 0;
    } else {
        int fd = open(v->path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0) {
            int e = errno;
            return io_fail(err, e == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_READ,
                           "V source %s: cannot open %s: %s", v->spec, v->path, strerror(e));
        }
        v->fd = fd;
        v->own_fd = 1;
    }
    struct stat st;
    if (fstat(v->fd, &st) == 0) {
        v->is_fifo = S_ISFIFO(st.st_mode) && v->own_fd;
        v->is_reg = S_ISREG(st.st_mode);
        if (S_ISDIR(st.st_mode)) {
            stream_close_fd(v);
            return io_fail(err, IO_ERR_READ, "V source %s: %s is a directory", v->spec, v->path);
        }
    }
    int fl = fcntl(v->fd, F_GETFL);
    v->fd_flags = fl;
    if (fl >= 0 && !(fl & O_NONBLOCK)) fcntl(v->fd, F_SETFL, fl | O_NONBLOCK);
    return IO_OK;
}

static io_result open_stream(io_vsrc *v, const char *rest, int raw, io_error *err)
{
    vs_init(&v->r, v->spec);
    v->tfd = -1;
    if (raw) {
        /* raw:WxH:FMT:PATH */
        int w = 0, h = 0, n = 0;
        char fmt[32];
        if (sscanf(rest, "%dx%d:%31[a-z0-9]:%n", &w, &h, fmt, &n) != 3 || n == 0)
            return io_fail(err, IO_ERR_ARGS, "%s: expected raw:WIDTHxHEIGHT:FORMAT:PATH, e.g. "
                           "raw:2560x800:rgb24:-", v->spec);
        uint32_t f = vs_raw_format(fmt);
        if (!f)
            return io_fail(err, IO_ERR_ARGS, "%s: raw format '%s' is not known (rgb24, bgr24, "
                           "rgba, bgra, rgb0, bgr0, yuyv, uyvy, nv12, i420, gray)", v->spec, fmt);
        if (w <= 0 || h <= 0 || w > VS_MAX_DIM || h > VS_MAX_DIM)
            return io_fail(err, IO_ERR_ARGS, "%s: size %dx%d is not valid", v->spec, w, h);
        if ((w & 1) && (f == IO_FMT_YUYV || f == IO_FMT_UYVY || f == IO_FMT_NV12 || f == IO_FMT_YU12))
            return io_fail(err, IO_ERR_ARGS, "%s: %s needs an even width", v->spec, fmt);
        if (v->cfg.width && (v->cfg.width != w || v->cfg.height != h))
            return io_fail(err, IO_ERR_ARGS, "%s: the spec says %dx%d, %dx%d was asked", v->spec, w,
                           h, v->cfg.width, v->cfg.height);
        v->r.framing = VS_RAW;
        v->r.raw_w = w;
        v->r.raw_h = h;
        v->r.raw_fmt = f;
        rest += n;
    }
    if (!rest[0]) return io_fail(err, IO_ERR_ARGS, "%s: no path (use - for stdin)", v->spec);
    snprintf(v->path, sizeof v->path, "%s", rest);
    v->r.lock_w = v->cfg.width;
    v->r.lock_h = v->cfg.height;
    if (raw) {
        v->r.lock_w = v->r.raw_w;
        v->r.lock_h = v->r.raw_h;
    }
    io_result r = stream_open_fd(v, err);
    if (r != IO_OK) return r;
    if (v->is_reg) {
        v->paced = 1;
        v->tfd = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
    }
    return IO_OK;
}

static void arm_timer(io_vsrc *v)
{
    if (v->tfd < 0 || !v->pace_period || v->cfg.clock_ns) return;
    struct itimerspec it;
    memset(&it, 0, sizeof it);
    uint64_t t = v->pace_t0 + v->pace_taken * v->pace_period;
    it.it_value.tv_sec = (time_t)(t / 1000000000ull);
    it.it_value.tv_nsec = (long)(t % 1000000000ull);
    if (!it.it_value.tv_sec && !it.it_value.tv_nsec) it.it_value.tv_nsec = 1;
    timerfd_settime(v->tfd, TFD_TIMER_ABSTIME, &it, NULL);
}

/* The stream ended (EOF) or broke: hold the last V. */
static void stream_end(io_vsrc *v, io_vsrc_state s, uint64_t now)
{
    v->hard = s;
    stream_close_fd(v);
    if (v->is_fifo) v->retry_ns = now + 1000000000ull;
}

/* Reads what is there and converts the newest complete frame. */
static void stream_take(io_vsrc *v, uint64_t now, int *fresh)
{
    vs_reader *r = &v->r;
    vs_frame pend;
    memset(&pend, 0, sizeof pend);
    int have = 0;
    size_t pend_start = 0;
    uint64_t max_frames = UINT64_MAX, taken = 0;
    if (v->paced) {
        if (!v->pace_t0) v->pace_t0 = now;
        if (!v->pace_period) {
            int fps = v->cfg.fps;
            v->pace_period = fps > 0 ? 1000000000ull / (uint64_t)fps : 0;
        }
        if (v->pace_period) {
            uint64_t due = now >= v->pace_t0 ? (now - v->pace_t0) / v->pace_period + 1 : 0;
            if (due <= v->pace_taken) return;
            max_frames = due - v->pace_taken;
        } else {
            max_frames = 1; /* the rate is known after the first header */
        }
        if (v->tfd >= 0) {
            uint64_t x;
            if (read(v->tfd, &x, sizeof x) < 0) { /* not expired yet: fine */ }
        }
    }
    if (v->rewind) {
        v->rewind = 0;
        if (lseek(v->fd, 0, SEEK_SET) == 0) {
            vs_restart(r);
            v->since_rewind = 0;
        }
    }
    size_t read_total = 0;
    for (;;) {
        /* parse every complete frame in the buffer */
        int fatal = 0;
        while (taken < max_frames) {
            vs_frame f;
            size_t start = r->pos;
            int st = vs_parse(r, &f);
            if (st == VS_FRAME) {
                v->since_rewind++;
                if (have) v->skipped++;
                pend = f;
                pend_start = start;
                have = 1;
                taken++;
            } else if (st == VS_BAD) {
                v->bad++;
                set_msg(v, "V source %s", r->msg);
            } else if (st == VS_FATAL) {
                set_msg(v, "V source %s", r->msg);
                fatal = 1;
                break;
            } else {
                break;
            }
        }
        if (fatal) {
            /* a truncated last frame is the end of the stream, not a fault */
            stream_end(v, r->eof ? IO_VSRC_ENDED : IO_VSRC_FAILED, now);
            break;
        }
        if (v->paced && !v->pace_period && r->fps_num > 0)
            v->pace_period = 1000000000ull * (uint64_t)r->fps_den / (uint64_t)r->fps_num;
        if (v->paced && !v->pace_period && r->framing != VS_UNKNOWN && have)
            v->pace_period = 1000000000ull / 30u;
        size_t keep = have ? pend_start : r->pos;
        vs_drop(r, keep);
        if (have) {
            pend.off -= keep;
            pend.depth_off -= keep;
            pend_start -= keep;
        }
        if (taken >= max_frames) break;
        if (r->eof) {
            if (v->paced && v->cfg.loop && v->since_rewind > 0) {
                /* start again; a pending frame is converted first */
                if (have) {
                    v->rewind = 1;
                    break;
                }
                if (lseek(v->fd, 0, SEEK_SET) == 0) {
                    vs_restart(r);
                    v->since_rewind = 0;
                    continue;
                }
            }
            if (r->len > r->pos)
                set_msg(v, "V source %s: end of stream; its last %zu bytes are not a whole frame",
                        v->spec, r->len - r->pos);
            else
                set_msg(v, "V source %s: end of stream (the producer closed it)%s", v->spec,
                        v->is_fifo ? "; waiting for a new writer" : "");
            stream_end(v, IO_VSRC_ENDED, now);
            break;
        }
        if (v->fd < 0) break;
        if (!v->paced && read_total > 4 * (r->need > 1048576 ? r->need : 1048576)) break;
        long n = vs_fill(r, v->fd, 0);
        if (n > 0) {
            read_total += (size_t)n;
            continue;
        }
        if (n == 0 && v->is_fifo && r->offset + r->len == 0) {
            /* a FIFO without a writer yet: not an end, look again later */
            r->eof = 0;
            stream_close_fd(v);
            v->retry_ns = now + 1000000000ull;
            if (!v->have_eye[0])
                set_msg(v, "V source %s: no writer on the FIFO yet (looking once a second)", v->spec);
            break;
        }
        if (n == 0) continue; /* EOF: parse the rest with eof set */
        if (n == -1) break;   /* nothing more now */
        set_msg(v, "V source %s", r->msg);
        stream_end(v, IO_VSRC_FAILED, now);
        break;
    }
    if (v->paced) {
        v->pace_taken += taken;
        if (have && v->pace_period) {
            /* behind by more than a frame: do not catch up in a burst */
            uint64_t due = now >= v->pace_t0 ? (now - v->pace_t0) / v->pace_period + 1 : 0;
            if (due > v->pace_taken) v->pace_taken = due;
        }
        arm_timer(v);
    }
    if (!have) return;
    io_frame f;
    memset(&f, 0, sizeof f);
    f.data = r->buf + pend.off;
    f.bytes = pend.bytes;
    f.width = pend.width;
    f.height = pend.height;
    f.stride = io_fmt_min_stride(pend.fourcc, pend.width);
    f.fourcc = pend.fourcc;
    f.index = -1;
    io_error e2;
    if (apply_frame(v, &f, pend.full_range, pend.layout, 0, -1, &e2) != IO_OK) {
        v->bad++;
        set_msg(v, "V source %s", e2.msg);
        return;
    }
    if (pend.depth_fmt)
        apply_depth(v, r->buf + pend.depth_off, pend.depth_fmt, pend.depth_scale, pend.width,
                    pend.height, v->layout);
    else
        v->has_depth = 0;
    v->frames++;
    v->t_arrival[0] = v->t_arrival[1] = now;
    v->t_frame[0] = v->t_frame[1] = pend.t_ns && pend.t_ns <= now ? pend.t_ns : now;
    if (v->reopened) {
        v->reopened = 0;
        if (v->frames > 1) { /* not the first writer */
            v->reopens++;
            set_msg(v, "V source %s: a new writer (reopen %llu)", v->spec,
                    (unsigned long long)v->reopens);
        }
    }
    if (v->hard == IO_VSRC_ENDED && v->fd >= 0) v->hard = 0;
    *fresh = 1;
}

static void stream_retry(io_vsrc *v, uint64_t now)
{
    if (v->fd >= 0 || !v->is_fifo || v->hard == IO_VSRC_FAILED || now < v->retry_ns) return;
    io_error e2;
    v->retry_ns = now + 1000000000ull;
    if (stream_open_fd(v, &e2) != IO_OK) {
        set_msg(v, "%s", e2.msg);
        return;
    }
    vs_restart(&v->r);
    v->reopened = 1;
}

/* ---------------------------------------------------------------- API */

io_result io_vsrc_open(io_vsrc **out, const io_vsrc_config *c, io_error *err)
{
    if (!out || !c || !c->spec) return io_fail(err, IO_ERR_ARGS, "V source: no spec given");
    *out = NULL;
    if (c->eye_width <= 0 || c->eye_height <= 0 || c->eye_width > VS_MAX_DIM ||
        c->eye_height > VS_MAX_DIM)
        return io_fail(err, IO_ERR_ARGS, "V source %s: eye size %dx%d is not valid", c->spec,
                       c->eye_width, c->eye_height);
    if (c->layout < 0 || c->layout > IO_VSRC_TB)
        return io_fail(err, IO_ERR_ARGS, "V source %s: layout %d is not valid", c->spec, c->layout);
    if (c->width < 0 || c->height < 0 || c->fps < 0 || c->stale_ms < 0)
        return io_fail(err, IO_ERR_ARGS, "V source %s: negative size, rate or stale time", c->spec);
    io_vsrc *v = calloc(1, sizeof *v);
    if (!v) return io_fail(err, IO_ERR_NOMEM, "V source %s: out of memory", c->spec);
    v->cfg = *c;
    snprintf(v->spec, sizeof v->spec, "%s", c->spec);
    v->cfg.spec = v->spec;
    if (!v->cfg.stale_ms) v->cfg.stale_ms = 200;
    v->fd = v->tfd = -1;
    v->cam[0].fd = v->cam[1].fd = -1;
    v->ew = c->eye_width;
    v->eh = c->eye_height;
    size_t eb = 4 * (size_t)v->ew * (size_t)v->eh;
    v->eyebuf[0] = malloc(eb);
    v->eyebuf[1] = malloc(eb);
    v->dbuf[0] = malloc(eb);
    v->dbuf[1] = malloc(eb);
    v->xt = malloc(sizeof(int) * 2 * (size_t)v->ew);
    v->yt = malloc(sizeof(int) * 2 * (size_t)v->eh);
    v->rows = malloc(sizeof(uint16_t) * 6 * (size_t)v->ew);
    io_result r = IO_OK;
    if (!v->eyebuf[0] || !v->eyebuf[1] || !v->dbuf[0] || !v->dbuf[1] || !v->xt || !v->yt || !v->rows) {
        r = io_fail(err, IO_ERR_NOMEM, "V source %s: out of memory for %dx%d eyes", c->spec, v->ew,
                    v->eh);
    } else if (!strncmp(v->spec, "v4l2:", 5)) {
        v->kind = K_V4L2;
        r = open_v4l2(v, v->spec + 5, err);
    } else if (!strncmp(v->spec, "stream:", 7)) {
        v->kind = K_STREAM;
        r = open_stream(v, v->spec + 7, 0, err);
    } else if (!strncmp(v->spec, "raw:", 4)) {
        v->kind = K_STREAM;
        r = open_stream(v, v->spec + 4, 1, err);
    } else {
        r = io_fail(err, IO_ERR_ARGS, "V source '%s': expected v4l2:/dev/videoN[,/dev/videoM], "
                    "stream:PATH (- for stdin) or raw:WxH:FORMAT:PATH", v->spec);
    }
    if (r != IO_OK) {
        io_vsrc_close(v);
        return r;
    }
    *out = v;
    return IO_OK;
}

int io_vsrc_pollfds(const io_vsrc *v, struct pollfd *fds, int cap)
{
    int n = 0;
    if (!v || !fds) return 0;
    if (v->kind == K_V4L2) {
        for (int i = 0; i < v->ndev && n < cap; i++)
            if (v->cam[i].state == IO_CAM_STREAMING && v->cam[i].fd >= 0) {
                fds[n].fd = v->cam[i].fd;
                fds[n].events = POLLIN;
                fds[n].revents = 0;
                n++;
            }
    } else if (v->paced) {
        if (v->tfd >= 0 && v->fd >= 0 && n < cap) {
            fds[n].fd = v->tfd;
            fds[n].events = POLLIN;
            fds[n].revents = 0;
            n++;
        }
    } else if (v->fd >= 0 && n < cap) {
        fds[n].fd = v->fd;
        fds[n].events = POLLIN;
        fds[n].revents = 0;
        n++;
    }
    return n;
}

io_result io_vsrc_poll(io_vsrc *v, int timeout_ms, int *fresh, io_error *err)
{
    int fr = 0;
    if (fresh) *fresh = 0;
    if (!v) return io_fail(err, IO_ERR_ARGS, "V source: io_vsrc_poll of nothing");
    uint64_t start = io_now_ns();
    uint64_t deadline = start + (uint64_t)(timeout_ms > 0 ? timeout_ms : 0) * 1000000ull;
    for (;;) {
        uint64_t now = clock_of(v);
        if (v->kind == K_V4L2) {
            poll_v4l2_once(v, now, &fr);
        } else {
            stream_retry(v, now);
            if (v->fd >= 0) stream_take(v, now, &fr);
        }
        if (fr) break;
        uint64_t t = io_now_ns();
        if (t >= deadline) break;
        struct pollfd pf[2];
        int n = io_vsrc_pollfds(v, pf, 2);
        int ms = (int)((deadline - t + 999999) / 1000000);
        if (n == 0) {
            /* nothing to wait on (a FIFO without writer, a failed device):
             * sleep up to the next retry, within the timeout */
            if (ms > 50) ms = 50;
            struct timespec ts = {0, (long)ms * 1000000L};
            nanosleep(&ts, NULL);
            continue;
        }
        int pr;
        do pr = poll(pf, (nfds_t)n, ms);
        while (pr < 0 && errno == EINTR && io_now_ns() < deadline);
        if (pr <= 0) {
            /* timeout: one last look (a FIFO's writer may have gone) */
            now = clock_of(v);
            if (v->kind == K_STREAM && v->fd >= 0) stream_take(v, now, &fr);
            break;
        }
    }
    if (fresh) *fresh = fr;
    return IO_OK;
}

const uint8_t *io_vsrc_eye(const io_vsrc *v, int eye, size_t *stride)
{
    if (!v || eye < 0 || eye > 1 || !v->have_eye[eye]) return NULL;
    if (stride) *stride = v->eye_stride[eye];
    return v->eye[eye];
}

const float *io_vsrc_depth(const io_vsrc *v, int eye, size_t *stride)
{
    if (!v || eye < 0 || eye > 1 || !v->have_eye[eye] || !v->has_depth) return NULL;
    if (stride) *stride = (size_t)v->ew;
    return v->dbuf[eye];
}

void io_vsrc_status(const io_vsrc *v, uint64_t now, io_vsrc_stat *st)
{
    memset(st, 0, sizeof *st);
    if (!v) return;
    if (!now) now = clock_of(v);
    int have = v->have_eye[0] && v->have_eye[1];
    uint64_t ta = v->t_arrival[0] < v->t_arrival[1] ? v->t_arrival[0] : v->t_arrival[1];
    uint64_t tf = v->t_frame[0] < v->t_frame[1] ? v->t_frame[0] : v->t_frame[1];
    if (v->hard) st->state = v->hard;
    else if (!have) st->state = IO_VSRC_WAITING;
    else st->state = now > ta && now - ta > (uint64_t)v->cfg.stale_ms * 1000000ull ? IO_VSRC_STALE
                                                                                   : IO_VSRC_LIVE;
    st->t_ns = have ? tf : 0;
    st->arrival_ns = have ? ta : 0;
    st->age_ns = have ? (int64_t)(now - tf) : -1;
    st->frames = v->frames;
    st->skipped = v->skipped;
    for (int i = 0; i < v->ndev; i++) st->skipped += v->cam[i].stats.skipped;
    st->bad = v->bad;
    for (int i = 0; i < v->ndev; i++)
        st->bad += v->cam[i].stats.short_frames + v->cam[i].stats.corrupt;
    st->reopens = v->reopens;
    st->src_width = v->src_w;
    st->src_height = v->src_h;
    st->fourcc = v->fourcc;
    st->layout = v->layout;
    st->has_depth = v->has_depth && have;
    st->kind = v->kind == K_V4L2 ? "v4l2"
               : v->r.framing == VS_EGFV ? "egofuse"
               : v->r.framing == VS_Y4M ? "y4m"
               : v->r.framing == VS_RAW ? "raw" : "stream";
    if (st->state == IO_VSRC_STALE && !v->msg[0])
        snprintf(st->msg, sizeof st->msg, "V source %.200s: no frame for %.0f ms", v->spec,
                 1e-6 * (double)(now - ta));
    else if (st->state == IO_VSRC_STALE)
        snprintf(st->msg, sizeof st->msg, "V source %.100s: no frame for %.0f ms (last problem: %.200s)",
                 v->spec, 1e-6 * (double)(now - ta), v->msg);
    else
        snprintf(st->msg, sizeof st->msg, "%s", v->msg);
}

void io_vsrc_close(io_vsrc *v)
{
    if (!v) return;
    for (int i = 0; i < 2; i++) {
        if (v->cam[i].be) io_cam_close(&v->cam[i]);
        free(v->eyebuf[i]);
        free(v->dbuf[i]);
        free(v->stage[i]);
    }
    free(v->xt);
    free(v->yt);
    free(v->rows);
    stream_close_fd(v);
    if (v->tfd >= 0) close(v->tfd);
    vs_free(&v->r);
    free(v);
}
