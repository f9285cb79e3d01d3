/* io_v4l2.c - cameras (io_dev.h): the bookkeeping shared by every backend
 * (sequence gaps, short and corrupt buffers, newest-frame grabbing, failure
 * and reopen), stereo pairing by time stamp, and the V4L2 backend on the
 * kernel API (linux/videodev2.h, mmap streaming, poll, non-blocking). libv4l2 is used for the descriptor calls when
 * EGOFUSE_LIBV4L2=1 is set in the environment (its format emulation can
 * then offer RGB3 for cameras that only do compressed formats). The pixel
 * formats and their conversion to RGBA live in io_pixfmt.c. */
#include "io_dev.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <libv4l2.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* ============================================================== helpers */

const char *io_cam_ctrl_name(io_cam_ctrl c)
{
    static const char *const names[IO_CTRL_COUNT] = {
        "exposure", "auto exposure", "gain", "white balance",
        "auto white balance", "brightness"};
    return (int)c >= 0 && c < IO_CTRL_COUNT ? names[c] : "unknown control";
}

io_cam_config io_cam_config_default(const char *path)
{
    io_cam_config c;
    memset(&c, 0, sizeof c);
    if (path) snprintf(c.path, sizeof c.path, "%s", path);
    c.fourcc = IO_FMT_YUYV;
    c.width = 640;
    c.height = 480;
    c.fps = 60;
    c.buffers = 4;
    c.input = -1;
    return c;
}

static uint64_t mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u;
}

/* ========================================================= generic camera */

io_result io_cam_open(io_cam *cam, const io_cam_backend *be,
                      const io_cam_config *cfg, io_error *err)
{
    if (!cam || !be || !cfg)
        return io_fail(err, IO_ERR_ARGS, "camera: io_cam_open needs a camera, a backend and a config");
    memset(cam, 0, sizeof *cam);
    cam->fd = -1;
    cam->be = be;
    cam->cfg = *cfg;
    cam->cfg.path[sizeof cam->cfg.path - 1] = '\0';
    for (int i = 0; i < IO_CAM_MAX_BUFFERS; i++) cam->buf[i] = NULL;
    if (!cfg->path[0])
        return io_fail(err, IO_ERR_ARGS, "camera: no device path given");
    if (!(cfg->width == 0 && cfg->height == 0) &&
        (cfg->width <= 0 || cfg->height <= 0 || cfg->width > 16384 || cfg->height > 16384))
        return io_fail(err, IO_ERR_ARGS, "%s: size %dx%d is not valid", cfg->path,
                       cfg->width, cfg->height);
    if (cfg->buffers < 2 || cfg->buffers > IO_CAM_MAX_BUFFERS)
        return io_fail(err, IO_ERR_ARGS, "%s: %d buffers asked, 2..%d possible", cfg->path,
                       cfg->buffers, IO_CAM_MAX_BUFFERS);
    if (cfg->fps < 0 || cfg->fps > 1000)
        return io_fail(err, IO_ERR_ARGS, "%s: %d frames per second is not valid", cfg->path,
                       cfg->fps);
    io_result r = be->open(cam, err);
    if (r != IO_OK) {
        be->close(cam);
        cam->state = IO_CAM_CLOSED;
        cam->fd = -1;
        cam->nbuf = 0;
        return r;
    }
    cam->state = IO_CAM_OPEN;
    return IO_OK;
}

io_result io_cam_start(io_cam *cam, io_error *err)
{
    if (!cam || cam->state == IO_CAM_CLOSED || cam->state == IO_CAM_FAILED)
        return io_fail(err, IO_ERR_ARGS, "%s: camera is not open",
                       cam ? cam->cfg.path : "camera");
    if (cam->state == IO_CAM_STREAMING) return IO_OK;
    io_result r = cam->be->start(cam, err);
    if (r != IO_OK) {
        cam->stats.errors++;
        return r;
    }
    cam->have_seq = 0;
    cam->state = IO_CAM_STREAMING;
    return IO_OK;
}

int io_cam_fd(const io_cam *cam) { return cam ? cam->fd : -1; }

static void cam_failed(io_cam *cam, const io_error *e)
{
    cam->state = IO_CAM_FAILED;
    cam->stats.errors++;
    io__status(cam->status, sizeof cam->status, "%s", e->msg);
}

io_result io_cam_dequeue(io_cam *cam, io_frame *f, int *got, io_error *err)
{
    *got = 0;
    if (!cam || cam->state != IO_CAM_STREAMING)
        return io_fail(err, IO_ERR_DEVICE, "%s: camera is not streaming%s%s",
                       cam ? cam->cfg.path : "camera",
                       cam && cam->status[0] ? ": " : "", cam ? cam->status : "");
    for (;;) {
        io_frame fr;
        uint32_t flags = 0;
        int g = 0;
        io_error e;
        memset(&fr, 0, sizeof fr);
        fr.index = -1;
        io_result r = cam->be->dequeue(cam, &fr, &g, &flags, &e);
        if (r != IO_OK) {
            cam_failed(cam, &e);
            if (err) *err = e;
            return r;
        }
        if (!g) return IO_OK;
        if (fr.index >= 0 && fr.index < cam->nbuf) cam->queued[fr.index] = 0;
        cam->stats.frames++;
        if (cam->have_seq) {
            uint32_t gap = fr.sequence - cam->last_seq - 1u;
            if (gap != 0 && gap < 0x80000000u) cam->stats.dropped += gap;
        }
        cam->have_seq = 1;
        cam->last_seq = fr.sequence;
        fr.width = cam->width;
        fr.height = cam->height;
        fr.stride = cam->stride;
        fr.fourcc = cam->fourcc;
        const char *bad = NULL;
        if (flags & IO_BUF_ERROR) {
            cam->stats.corrupt++;
            bad = "flagged as corrupt by the driver";
        } else if (fr.bytes < cam->image_bytes) {
            cam->stats.short_frames++;
            bad = "short";
        }
        if (bad) {
            io__status(cam->status, sizeof cam->status,
                     "%s: frame %u %s (%zu of %zu bytes): dropped", cam->cfg.path,
                     (unsigned)fr.sequence, bad, fr.bytes, cam->image_bytes);
            io_result q = io_cam_release(cam, &fr, err);
            if (q != IO_OK) return q;
            continue;
        }
        *f = fr;
        *got = 1;
        return IO_OK;
    }
}

io_result io_cam_release(io_cam *cam, io_frame *f, io_error *err)
{
    if (!cam || !f || f->index < 0) return IO_OK;
    int i = f->index;
    f->index = -1;
    f->data = NULL;
    if (i >= cam->nbuf || cam->queued[i]) return IO_OK;
    if (cam->state != IO_CAM_STREAMING) return IO_OK; /* start requeues */
    io_error e;
    io_result r = cam->be->queue(cam, i, &e);
    if (r != IO_OK) {
        cam_failed(cam, &e);
        if (err) *err = e;
        return r;
    }
    cam->queued[i] = 1;
    return IO_OK;
}

io_result io_cam_grab(io_cam *cam, int timeout_ms, io_frame *f, int *got,
                      io_error *err)
{
    *got = 0;
    uint64_t deadline = mono_ms() + (uint64_t)(timeout_ms > 0 ? timeout_ms : 0);
    for (;;) {
        io_frame fr;
        int g;
        io_result r;
        while ((r = io_cam_dequeue(cam, &fr, &g, err)) == IO_OK && g) {
            if (*got) {
                cam->stats.skipped++;
                io_result q = io_cam_release(cam, f, err);
                if (q != IO_OK) return q;
            }
            *f = fr;
            *got = 1;
        }
        if (r != IO_OK) {
            if (*got) io_cam_release(cam, f, NULL);
            *got = 0;
            return r;
        }
        if (*got) return IO_OK;
        uint64_t now = mono_ms();
        if (now >= deadline) return IO_OK;
        int w = cam->be->wait(cam, (int)(deadline - now));
        if (w < 0) {
            /* POLLERR: the next dequeue names the reason */
            r = io_cam_dequeue(cam, &fr, &g, err);
            if (r != IO_OK) return r;
            if (g) {
                *f = fr;
                *got = 1;
                return IO_OK;
            }
            if (cam->fd < 0) return IO_OK;
            io_error e;
            io_fail(&e, IO_ERR_DEVICE, "%s: poll reports an error on the device", cam->cfg.path);
            cam_failed(cam, &e);
            if (err) *err = e;
            return IO_ERR_DEVICE;
        }
        if (w == 0 && cam->fd < 0) return IO_OK; /* no descriptor to wait on */
    }
}

io_result io_cam_set_ctrl(io_cam *cam, io_cam_ctrl c, int value, io_error *err)
{
    if (!cam || cam->state == IO_CAM_CLOSED || cam->state == IO_CAM_FAILED)
        return io_fail(err, IO_ERR_ARGS, "%s: camera is not open", cam ? cam->cfg.path : "camera");
    if ((int)c < 0 || c >= IO_CTRL_COUNT)
        return io_fail(err, IO_ERR_ARGS, "%s: unknown control %d", cam->cfg.path, (int)c);
    return cam->be->set_ctrl(cam, c, value, err);
}

io_result io_cam_get_ctrl(io_cam *cam, io_cam_ctrl c, int *value, io_error *err)
{
    if (!cam || cam->state == IO_CAM_CLOSED || cam->state == IO_CAM_FAILED)
        return io_fail(err, IO_ERR_ARGS, "%s: camera is not open", cam ? cam->cfg.path : "camera");
    if ((int)c < 0 || c >= IO_CTRL_COUNT)
        return io_fail(err, IO_ERR_ARGS, "%s: unknown control %d", cam->cfg.path, (int)c);
    return cam->be->get_ctrl(cam, c, value, err);
}

void io_cam_stop(io_cam *cam)
{
    if (!cam || cam->state != IO_CAM_STREAMING) return;
    cam->be->stop(cam);
    for (int i = 0; i < cam->nbuf; i++) cam->queued[i] = 0;
    cam->state = IO_CAM_OPEN;
}

void io_cam_close(io_cam *cam)
{
    if (!cam || !cam->be) return;
    if (cam->state == IO_CAM_STREAMING) io_cam_stop(cam);
    if (cam->state != IO_CAM_CLOSED) cam->be->close(cam);
    for (int i = 0; i < IO_CAM_MAX_BUFFERS; i++) {
        cam->queued[i] = 0;
        cam->buf[i] = NULL;
        cam->buf_len[i] = 0;
    }
    cam->nbuf = 0;
    cam->fd = -1;
    cam->state = IO_CAM_CLOSED;
}

io_result io_cam_reopen(io_cam *cam, const char *new_path, io_error *err)
{
    if (!cam || !cam->be)
        return io_fail(err, IO_ERR_ARGS, "camera: reopen of a camera never opened");
    int stream = cam->state == IO_CAM_STREAMING || cam->state == IO_CAM_FAILED;
    io_cam_stats st = cam->stats;
    const io_cam_backend *be = cam->be;
    io_cam_config cfg = cam->cfg;
    if (new_path) snprintf(cfg.path, sizeof cfg.path, "%s", new_path);
    io_cam_close(cam);
    io_result r = io_cam_open(cam, be, &cfg, err);
    cam->stats = st;
    if (r != IO_OK) {
        /* keep what is needed for the next try */
        cam->be = be;
        cam->cfg = cfg;
        cam->state = IO_CAM_FAILED;
        io__status(cam->status, sizeof cam->status, "%s", err ? err->msg : "reopen failed");
        return r;
    }
    if (stream && (r = io_cam_start(cam, err)) != IO_OK) {
        io_cam_close(cam);
        cam->be = be;
        cam->cfg = cfg;
        cam->state = IO_CAM_FAILED;
        cam->stats = st;
        return r;
    }
    cam->stats.reopens++;
    cam->status[0] = '\0';
    return IO_OK;
}

/* ================================================================ stereo */

int io_stereo_match(int have_l, uint64_t t_l, int have_r, uint64_t t_r,
                    uint64_t max_skew_ns, int *drop)
{
    *drop = -1;
    if (!have_l || !have_r) return 0;
    uint64_t d = t_l > t_r ? t_l - t_r : t_r - t_l;
    if (d <= max_skew_ns) return 1;
    *drop = t_l < t_r ? 0 : 1;
    return 0;
}

void io_stereo_init(io_stereo *s, io_cam *left, io_cam *right, uint64_t max_skew_ns)
{
    memset(s, 0, sizeof *s);
    s->cam[0] = left;
    s->cam[1] = right;
    if (!max_skew_ns) {
        uint64_t period = 1000000000ull / 60u;
        if (left && left->fps_num > 0 && left->fps_den > 0)
            period = 1000000000ull * (uint64_t)left->fps_num / (uint64_t)left->fps_den;
        max_skew_ns = period / 2;
    }
    s->max_skew_ns = max_skew_ns;
    s->held[0].index = s->held[1].index = -1;
}

static void stereo_drop(io_stereo *s, int e)
{
    if (!s->have[e]) return;
    io_cam_release(s->cam[e], &s->held[e], NULL);
    s->have[e] = 0;
}

void io_stereo_flush(io_stereo *s)
{
    for (int e = 0; e < 2; e++) stereo_drop(s, e);
}

io_result io_stereo_release(io_stereo *s, io_frame out[2], io_error *err)
{
    io_result r0 = io_cam_release(s->cam[0], &out[0], err);
    io_result r1 = io_cam_release(s->cam[1], &out[1], r0 == IO_OK ? err : NULL);
    return r0 != IO_OK ? r0 : r1;
}

static const char *const eye_name[2] = {"left", "right"};

io_result io_stereo_grab(io_stereo *s, int timeout_ms, io_frame out[2], int *got,
                         io_error *err)
{
    *got = 0;
    out[0].index = out[1].index = -1;
    uint64_t deadline = mono_ms() + (uint64_t)(timeout_ms > 0 ? timeout_ms : 0);
    for (;;) {
        int alive = 0;
        for (int e = 0; e < 2; e++) {
            io_cam *c = s->cam[e];
            if (c->state == IO_CAM_STREAMING) s->failed[e] = 0;
            if (c->state != IO_CAM_STREAMING) {
                if (!s->failed[e]) {
                    s->failed[e] = 1;
                    s->have[e] = 0; /* its buffers are gone with it */
                    io__status(s->status, sizeof s->status, "%s camera %s failed: %s", eye_name[e],
                             c->cfg.path, c->status[0] ? c->status : "not streaming");
                }
                continue;
            }
            alive++;
            io_frame f;
            int g;
            io_error e2;
            io_result r;
            while ((r = io_cam_dequeue(c, &f, &g, &e2)) == IO_OK && g) {
                if (s->have[e]) {
                    s->unpaired[e]++;
                    io_cam_release(c, &s->held[e], NULL);
                }
                s->held[e] = f;
                s->have[e] = 1;
            }
            if (r != IO_OK) {
                s->failed[e] = 1;
                s->have[e] = 0;
                alive--;
                io__status(s->status, sizeof s->status, "%s camera failed: %s", eye_name[e], e2.msg);
            }
        }
        if (!alive) {
            return io_fail(err, IO_ERR_DEVICE, "stereo: both cameras failed (%s: %s; %s: %s)",
                           s->cam[0]->cfg.path, s->cam[0]->status, s->cam[1]->cfg.path,
                           s->cam[1]->status);
        }
        if (alive == 1) {
            /* one eye away: hand out the other eye's newest frame alone */
            int e = s->failed[0] ? 1 : 0;
            if (s->have[e]) {
                out[e] = s->held[e];
                s->have[e] = 0;
                *got = 1 << e;
                return IO_OK;
            }
        } else {
            int drop;
            while (!io_stereo_match(s->have[0], s->held[0].t_ns, s->have[1], s->held[1].t_ns,
                                    s->max_skew_ns, &drop) && drop >= 0) {
                s->unpaired[drop]++;
                stereo_drop(s, drop);
            }
            if (s->have[0] && s->have[1]) {
                out[0] = s->held[0];
                out[1] = s->held[1];
                s->have[0] = s->have[1] = 0;
                int64_t skew = (int64_t)(out[1].t_ns - out[0].t_ns);
                uint64_t a = (uint64_t)(skew < 0 ? -skew : skew);
                s->pairs++;
                s->last_skew_ns = skew;
                if (a > s->max_abs_skew_ns) s->max_abs_skew_ns = a;
                s->sum_abs_skew_ns += (double)a;
                *got = 3;
                return IO_OK;
            }
        }
        uint64_t now = mono_ms();
        if (now >= deadline) return IO_OK;
        /* wait on both descriptors together */
        struct pollfd pf[2];
        int np = 0, nofd = 0;
        for (int e = 0; e < 2; e++) {
            if (s->failed[e]) continue;
            if (s->cam[e]->fd >= 0) {
                pf[np].fd = s->cam[e]->fd;
                pf[np].events = POLLIN;
                pf[np].revents = 0;
                np++;
            } else if (s->cam[e]->be->wait(s->cam[e], 0) <= 0) {
                nofd++;
            }
        }
        if (nofd && !np) return IO_OK; /* backends without descriptors: nothing ready */
        if (np) poll(pf, (nfds_t)np, (int)(deadline - now));
    }
}

/* ========================================================== V4L2 backend */

typedef struct v4l2_ops {
    int (*ioctl_fn)(int, unsigned long, ...);
    void *(*mmap_fn)(void *, size_t, int, int, int, int64_t);
    int (*munmap_fn)(void *, size_t);
    int (*close_fn)(int);
} v4l2_ops;

/* An ioctl through `call` (the kernel's, or libv4l2's), again while
 * interrupted (EINTR): one definition for both. */
#define V4L2_RETRY_IOCTL(name, call)                                  \
    static int name(int fd, unsigned long req, ...)                    \
    {                                                                  \
        va_list ap;                                                    \
        va_start(ap, req);                                             \
        void *arg = va_arg(ap, void *);                                \
        va_end(ap);                                                    \
        int r;                                                         \
        do r = call(fd, req, arg);                                     \
        while (r < 0 && errno == EINTR);                               \
        return r;                                                      \
    }
V4L2_RETRY_IOCTL(plain_ioctl, ioctl)
V4L2_RETRY_IOCTL(lib_ioctl, v4l2_ioctl)
#undef V4L2_RETRY_IOCTL

static void *plain_mmap(void *a, size_t n, int prot, int flags, int fd, int64_t off)
{
    return mmap(a, n, prot, flags, fd, (off_t)off);
}

static const v4l2_ops plain_ops = {plain_ioctl, plain_mmap, munmap, close};
static const v4l2_ops lib_ops = {lib_ioctl, v4l2_mmap, v4l2_munmap, v4l2_close};

typedef struct v4l2_priv {
    const v4l2_ops *ops;
} v4l2_priv;

static const v4l2_ops *ops_of(io_cam *cam) { return ((v4l2_priv *)cam->priv)->ops; }

static io_result errno_fail(io_cam *cam, io_error *err, const char *what, int e)
{
    io_result code = (e == ENODEV || e == ENXIO || e == EIO || e == EPIPE || e == EBUSY)
                         ? IO_ERR_DEVICE
                         : e == EINVAL || e == ENOTTY ? IO_ERR_FORMAT : IO_ERR_DEVICE;
    const char *hint = e == ENODEV || e == ENXIO ? " (unplugged?)" : "";
    return io_fail(err, code, "%s: %s: %s%s", cam->cfg.path, what, strerror(e), hint);
}

static int xioctl(io_cam *cam, unsigned long req, void *arg)
{
    return ops_of(cam)->ioctl_fn(cam->fd, req, arg);
}

/* Picks the DV timings preset matching the configured size and rate. */
static io_result set_dv_timings(io_cam *cam, io_error *err)
{
    struct v4l2_enum_dv_timings en;
    struct v4l2_dv_timings best;
    double best_d = 1e30;
    int found = 0;
    for (unsigned i = 0; i < 256; i++) {
        memset(&en, 0, sizeof en);
        en.index = i;
        if (xioctl(cam, VIDIOC_ENUM_DV_TIMINGS, &en) < 0) break;
        const struct v4l2_bt_timings *bt = &en.timings.bt;
        if (en.timings.type != V4L2_DV_BT_656_1120 || bt->interlaced) continue;
        if ((int)bt->width != cam->cfg.width || (int)bt->height != cam->cfg.height) continue;
        double tot = (double)V4L2_DV_BT_FRAME_WIDTH(bt) * (double)V4L2_DV_BT_FRAME_HEIGHT(bt);
        double fps = tot > 0 ? (double)bt->pixelclock / tot : 0;
        double d = cam->cfg.fps > 0 ? (fps - cam->cfg.fps) * (fps - cam->cfg.fps) : 0;
        if (d < best_d) {
            best_d = d;
            best = en.timings;
            found = 1;
        }
    }
    if (!found)
        return io_fail(err, IO_ERR_FORMAT, "%s: no DV timings preset for %dx%d at %d FPS",
                       cam->cfg.path, cam->cfg.width, cam->cfg.height, cam->cfg.fps);
    if (xioctl(cam, VIDIOC_S_DV_TIMINGS, &best) < 0)
        return errno_fail(cam, err, "VIDIOC_S_DV_TIMINGS", errno);
    return IO_OK;
}

/* Cameras first (YUYV, GREY, Bayer), then what capture cards give. */
static const uint32_t preferred[] = {IO_FMT_YUYV, IO_FMT_GREY, IO_FMT_RGGB, IO_FMT_BGGR,
                                     IO_FMT_GBRG, IO_FMT_GRBG, IO_FMT_UYVY, IO_FMT_NV12,
                                     IO_FMT_YU12, IO_FMT_RGB3, IO_FMT_BGR3, IO_FMT_BGR4,
                                     IO_FMT_XR24, IO_FMT_AR24, IO_FMT_XB24, IO_FMT_AB24,
                                     IO_FMT_RGB4, IO_FMT_BX24, IO_FMT_BA24};

static io_result pick_format(io_cam *cam, uint32_t *out, io_error *err)
{
    uint32_t offered[128];
    int n = 0;
    for (unsigned i = 0; i < 128; i++) {
        struct v4l2_fmtdesc d;
        memset(&d, 0, sizeof d);
        d.index = i;
        d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        if (xioctl(cam, VIDIOC_ENUM_FMT, &d) < 0) break;
        offered[n++] = d.pixelformat;
    }
    char list[720] = "", fs[5];
    for (int i = 0; i < n; i++) {
        size_t l = strlen(list);
        snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", io_fourcc_str(offered[i], fs));
    }
    if (cam->cfg.fourcc) {
        for (int i = 0; i < n; i++)
            if (offered[i] == cam->cfg.fourcc) {
                *out = cam->cfg.fourcc;
                return IO_OK;
            }
        return io_fail(err, IO_ERR_FORMAT, "%s: format %s not offered (the device offers: %s)",
                       cam->cfg.path, io_fourcc_str(cam->cfg.fourcc, fs), n ? list : "nothing");
    }
    for (size_t k = 0; k < sizeof preferred / sizeof preferred[0]; k++)
        for (int i = 0; i < n; i++)
            if (offered[i] == preferred[k]) {
                *out = preferred[k];
                return IO_OK;
            }
    return io_fail(err, IO_ERR_FORMAT, "%s: none of YUYV, GREY, Bayer, UYVY, NV12, YU12, "
                   "RGB24, BGR24, 32-bit RGB offered (the device offers: %s)", cam->cfg.path,
                   n ? list : "nothing");
}

/* The mmap capture buffer `index`, as VIDIOC_QUERYBUF and VIDIOC_QBUF
 * take it (VIDIOC_DQBUF fills in the index). */
static struct v4l2_buffer mmap_buffer(int index)
{
    struct v4l2_buffer b;
    memset(&b, 0, sizeof b);
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = (uint32_t)index;
    return b;
}

static io_result v4l2_open_cb(io_cam *cam, io_error *err)
{
    v4l2_priv *p = (v4l2_priv *)cam->priv_store;
    cam->priv = p;
    const char *env = getenv("EGOFUSE_LIBV4L2");
    p->ops = env && env[0] == '1' ? &lib_ops : &plain_ops;
    const char *path = cam->cfg.path;
    int fd = open(path, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        int e = errno;
        return io_fail(err, e == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_DEVICE, "%s: cannot open: %s%s",
                       path, strerror(e),
                       e == ENOENT ? " (no such camera)"
                       : e == EBUSY ? " (busy: another program uses it)"
                       : e == EACCES ? " (no permission: is the user in group video?)" : "");
    }
    if (p->ops == &lib_ops) {
        int lfd = v4l2_fd_open(fd, 0);
        if (lfd < 0) {
            close(fd);
            return io_fail(err, IO_ERR_DEVICE, "%s: libv4l2 cannot take the device", path);
        }
        fd = lfd;
    }
    cam->fd = fd;
    struct stat st;
    if (fstat(fd, &st) == 0 && !S_ISCHR(st.st_mode))
        return io_fail(err, IO_ERR_DEVICE, "%s: not a device node", path);

    struct v4l2_capability cap;
    memset(&cap, 0, sizeof cap);
    if (xioctl(cam, VIDIOC_QUERYCAP, &cap) < 0)
        return io_fail(err, IO_ERR_DEVICE, "%s: VIDIOC_QUERYCAP: %s (not a V4L2 device?)", path,
                       strerror(errno));
    uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
    snprintf(cam->driver, sizeof cam->driver, "%s", (const char *)cap.driver);
    snprintf(cam->card, sizeof cam->card, "%s", (const char *)cap.card);
    snprintf(cam->bus_info, sizeof cam->bus_info, "%s", (const char *)cap.bus_info);
    if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
        return io_fail(err, IO_ERR_DEVICE, "%s: %s (%s) is not a video capture device", path,
                       cam->card, cam->driver);
    if (!(caps & V4L2_CAP_STREAMING))
        return io_fail(err, IO_ERR_DEVICE, "%s: %s cannot stream (no V4L2_CAP_STREAMING)", path,
                       cam->card);

    if (cam->cfg.input >= 0) {
        int in = cam->cfg.input;
        if (xioctl(cam, VIDIOC_S_INPUT, &in) < 0)
            return io_fail(err, IO_ERR_DEVICE, "%s: cannot select input %d: %s", path,
                           cam->cfg.input, strerror(errno));
    }
    io_result r;
    if (cam->cfg.dv_timings && (r = set_dv_timings(cam, err)) != IO_OK) return r;

    uint32_t fourcc = 0;
    if ((r = pick_format(cam, &fourcc, err)) != IO_OK) return r;
    struct v4l2_format fmt;
    memset(&fmt, 0, sizeof fmt);
    fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (cam->cfg.width == 0 && cam->cfg.height == 0) {
        /* 0 x 0: the size the device has now (an HDMI input's timings) */
        if (xioctl(cam, VIDIOC_G_FMT, &fmt) < 0) return errno_fail(cam, err, "VIDIOC_G_FMT", errno);
        cam->cfg.width = (int)fmt.fmt.pix.width;
        cam->cfg.height = (int)fmt.fmt.pix.height;
        memset(&fmt, 0, sizeof fmt);
        fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    }
    fmt.fmt.pix.width = (uint32_t)cam->cfg.width;
    fmt.fmt.pix.height = (uint32_t)cam->cfg.height;
    fmt.fmt.pix.pixelformat = fourcc;
    fmt.fmt.pix.field = V4L2_FIELD_NONE;
    if (xioctl(cam, VIDIOC_S_FMT, &fmt) < 0) return errno_fail(cam, err, "VIDIOC_S_FMT", errno);
    char fs[5], fs2[5];
    if (fmt.fmt.pix.pixelformat != fourcc)
        return io_fail(err, IO_ERR_FORMAT, "%s: asked for %s, the driver set %s", path,
                       io_fourcc_str(fourcc, fs), io_fourcc_str(fmt.fmt.pix.pixelformat, fs2));
    if ((int)fmt.fmt.pix.width != cam->cfg.width || (int)fmt.fmt.pix.height != cam->cfg.height)
        return io_fail(err, IO_ERR_FORMAT, "%s: asked for %dx%d %s, the driver gives %ux%u", path,
                       cam->cfg.width, cam->cfg.height, io_fourcc_str(fourcc, fs),
                       fmt.fmt.pix.width, fmt.fmt.pix.height);
    cam->fourcc = fourcc;
    cam->width = (int)fmt.fmt.pix.width;
    cam->height = (int)fmt.fmt.pix.height;
    size_t minst = io_fmt_min_stride(fourcc, cam->width);
    cam->stride = fmt.fmt.pix.bytesperline >= minst ? fmt.fmt.pix.bytesperline : minst;
    cam->image_bytes = io_fmt_image_bytes(fourcc, cam->stride, cam->width, cam->height);
    if (fmt.fmt.pix.sizeimage < cam->image_bytes)
        return io_fail(err, IO_ERR_FORMAT, "%s: the driver's image size %u is below %zu", path,
                       fmt.fmt.pix.sizeimage, cam->image_bytes);

    struct v4l2_streamparm parm;
    memset(&parm, 0, sizeof parm);
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (cam->cfg.fps > 0 && xioctl(cam, VIDIOC_G_PARM, &parm) == 0 &&
        (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
        parm.parm.capture.timeperframe.numerator = 1;
        parm.parm.capture.timeperframe.denominator = (uint32_t)cam->cfg.fps;
        xioctl(cam, VIDIOC_S_PARM, &parm); /* the driver rounds; read back below */
    }
    memset(&parm, 0, sizeof parm);
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(cam, VIDIOC_G_PARM, &parm) == 0 && parm.parm.capture.timeperframe.numerator) {
        cam->fps_num = (int)parm.parm.capture.timeperframe.numerator;
        cam->fps_den = (int)parm.parm.capture.timeperframe.denominator;
    }

    struct v4l2_requestbuffers rb;
    memset(&rb, 0, sizeof rb);
    rb.count = (uint32_t)cam->cfg.buffers;
    rb.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    rb.memory = V4L2_MEMORY_MMAP;
    if (xioctl(cam, VIDIOC_REQBUFS, &rb) < 0)
        return errno_fail(cam, err, "VIDIOC_REQBUFS (mmap streaming)", errno);
    if (rb.count < 2)
        return io_fail(err, IO_ERR_DEVICE, "%s: the driver grants %u buffers, 2 needed", path,
                       rb.count);
    int n = rb.count > IO_CAM_MAX_BUFFERS ? IO_CAM_MAX_BUFFERS : (int)rb.count;
    for (int i = 0; i < n; i++) {
        struct v4l2_buffer b = mmap_buffer(i);
        if (xioctl(cam, VIDIOC_QUERYBUF, &b) < 0) return errno_fail(cam, err, "VIDIOC_QUERYBUF", errno);
        void *m = ops_of(cam)->mmap_fn(NULL, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd,
                                       (int64_t)b.m.offset);
        if (m == MAP_FAILED) return errno_fail(cam, err, "mmap of a buffer", errno);
        cam->buf[i] = m;
        cam->buf_len[i] = b.length;
        cam->nbuf = i + 1;
    }
    return IO_OK;
}

static io_result v4l2_queue_cb(io_cam *cam, int index, io_error *err)
{
    struct v4l2_buffer b = mmap_buffer(index);
    if (xioctl(cam, VIDIOC_QBUF, &b) < 0) return errno_fail(cam, err, "VIDIOC_QBUF", errno);
    return IO_OK;
}

static io_result v4l2_start_cb(io_cam *cam, io_error *err)
{
    for (int i = 0; i < cam->nbuf; i++) {
        if (cam->queued[i]) continue;
        io_result r = v4l2_queue_cb(cam, i, err);
        if (r != IO_OK) return r;
        cam->queued[i] = 1;
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (xioctl(cam, VIDIOC_STREAMON, &type) < 0) return errno_fail(cam, err, "VIDIOC_STREAMON", errno);
    return IO_OK;
}

static io_result v4l2_dequeue_cb(io_cam *cam, io_frame *f, int *got, uint32_t *flags,
                                 io_error *err)
{
    struct v4l2_buffer b = mmap_buffer(0); /* the driver fills in the index */
    *got = 0;
    if (xioctl(cam, VIDIOC_DQBUF, &b) < 0) {
        if (errno == EAGAIN) return IO_OK;
        return errno_fail(cam, err, "VIDIOC_DQBUF", errno);
    }
    if ((int)b.index >= cam->nbuf)
        return io_fail(err, IO_ERR_DEVICE, "%s: the driver returned buffer %u of %d", cam->cfg.path,
                       b.index, cam->nbuf);
    f->index = (int)b.index;
    f->data = cam->buf[b.index];
    f->bytes = b.bytesused > cam->buf_len[b.index] ? cam->buf_len[b.index] : b.bytesused;
    f->t_ns = (uint64_t)b.timestamp.tv_sec * 1000000000ull + (uint64_t)b.timestamp.tv_usec * 1000ull;
    f->sequence = b.sequence;
    *flags = (b.flags & V4L2_BUF_FLAG_ERROR) ? IO_BUF_ERROR : 0;
    *got = 1;
    return IO_OK;
}

static int v4l2_wait_cb(io_cam *cam, int timeout_ms)
{
    struct pollfd pf = {cam->fd, POLLIN, 0};
    int r;
    do r = poll(&pf, 1, timeout_ms);
    while (r < 0 && errno == EINTR);
    if (r < 0) return -1;
    if (r == 0) return 0;
    if (pf.revents & POLLIN) return 1;
    return (pf.revents & (POLLERR | POLLHUP | POLLNVAL)) ? -1 : 0;
}

static const uint32_t ctrl_ids[IO_CTRL_COUNT][2] = {
    {V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_CID_EXPOSURE},
    {V4L2_CID_EXPOSURE_AUTO, 0},
    {V4L2_CID_GAIN, 0},
    {V4L2_CID_WHITE_BALANCE_TEMPERATURE, 0},
    {V4L2_CID_AUTO_WHITE_BALANCE, 0},
    {V4L2_CID_BRIGHTNESS, 0},
};

static io_result find_ctrl(io_cam *cam, io_cam_ctrl c, struct v4l2_queryctrl *q, io_error *err)
{
    for (int k = 0; k < 2 && ctrl_ids[c][k]; k++) {
        memset(q, 0, sizeof *q);
        q->id = ctrl_ids[c][k];
        if (xioctl(cam, VIDIOC_QUERYCTRL, q) == 0 && !(q->flags & V4L2_CTRL_FLAG_DISABLED))
            return IO_OK;
    }
    return io_fail(err, IO_ERR_VALUE, "%s: %s has no %s control", cam->cfg.path, cam->card,
                   io_cam_ctrl_name(c));
}

static io_result v4l2_set_ctrl_cb(io_cam *cam, io_cam_ctrl c, int value, io_error *err)
{
    struct v4l2_queryctrl q;
    io_result r = find_ctrl(cam, c, &q, err);
    if (r != IO_OK) return r;
    if (value < q.minimum) value = q.minimum;
    if (value > q.maximum) value = q.maximum;
    struct v4l2_control ctl = {q.id, value};
    if (xioctl(cam, VIDIOC_S_CTRL, &ctl) < 0)
        return io_fail(err, IO_ERR_DEVICE, "%s: cannot set %s to %d: %s", cam->cfg.path,
                       io_cam_ctrl_name(c), value, strerror(errno));
    return IO_OK;
}

static io_result v4l2_get_ctrl_cb(io_cam *cam, io_cam_ctrl c, int *value, io_error *err)
{
    struct v4l2_queryctrl q;
    io_result r = find_ctrl(cam, c, &q, err);
    if (r != IO_OK) return r;
    struct v4l2_control ctl = {q.id, 0};
    if (xioctl(cam, VIDIOC_G_CTRL, &ctl) < 0)
        return io_fail(err, IO_ERR_DEVICE, "%s: cannot read %s: %s", cam->cfg.path,
                       io_cam_ctrl_name(c), strerror(errno));
    *value = ctl.value;
    return IO_OK;
}

static void v4l2_stop_cb(io_cam *cam)
{
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (cam->fd >= 0) xioctl(cam, VIDIOC_STREAMOFF, &type);
}

static void v4l2_close_cb(io_cam *cam)
{
    if (!cam->priv) cam->priv = cam->priv_store;
    const v4l2_ops *ops = ops_of(cam) ? ops_of(cam) : &plain_ops;
    for (int i = 0; i < cam->nbuf; i++)
        if (cam->buf[i]) ops->munmap_fn(cam->buf[i], cam->buf_len[i]);
    if (cam->fd >= 0) {
        if (cam->nbuf) {
            struct v4l2_requestbuffers rb;
            memset(&rb, 0, sizeof rb);
            rb.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            rb.memory = V4L2_MEMORY_MMAP;
            ops->ioctl_fn(cam->fd, VIDIOC_REQBUFS, &rb); /* frees them; fails if gone */
        }
        ops->close_fn(cam->fd);
    }
    cam->fd = -1;
    cam->nbuf = 0;
}

const io_cam_backend io_cam_v4l2 = {
    "v4l2",          v4l2_open_cb,     v4l2_start_cb,    v4l2_dequeue_cb, v4l2_queue_cb,
    v4l2_wait_cb,    v4l2_set_ctrl_cb, v4l2_get_ctrl_cb, v4l2_stop_cb,    v4l2_close_cb,
};

/* ============================================================== listing */

static int cmp_info(const void *a, const void *b)
{
    const io_cam_info *x = a, *y = b;
    return atoi(x->path + strcspn(x->path, "0123456789")) -
           atoi(y->path + strcspn(y->path, "0123456789"));
}

io_result io_cam_list(const char *dev_dir, io_cam_info *out, int cap, int *count, io_error *err)
{
    if (!dev_dir) dev_dir = "/dev";
    *count = 0;
    DIR *d = opendir(dev_dir);
    if (!d) return io_fail(err, IO_ERR_NOT_FOUND, "%s: %s", dev_dir, strerror(errno));
    struct dirent *e;
    int n = 0;
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, "video", 5) || !e->d_name[5]) continue;
        if (strspn(e->d_name + 5, "0123456789") != strlen(e->d_name + 5)) continue;
        if (n < cap) {
            io_cam_info *c = &out[n];
            memset(c, 0, sizeof *c);
            io__status(c->path, sizeof c->path, "%s/%s", dev_dir, e->d_name);
            int fd = open(c->path, O_RDWR | O_NONBLOCK | O_CLOEXEC);
            struct v4l2_capability cp;
            memset(&cp, 0, sizeof cp);
            if (fd < 0) {
                io__status(c->card, sizeof c->card, "cannot open: %s", strerror(errno));
            } else if (ioctl(fd, VIDIOC_QUERYCAP, &cp) < 0) {
                io__status(c->card, sizeof c->card, "not a V4L2 device: %s", strerror(errno));
            } else {
                uint32_t caps = (cp.capabilities & V4L2_CAP_DEVICE_CAPS) ? cp.device_caps
                                                                           : cp.capabilities;
                io__status(c->driver, sizeof c->driver, "%.31s", (const char *)cp.driver);
                io__status(c->card, sizeof c->card, "%.63s", (const char *)cp.card);
                io__status(c->bus_info, sizeof c->bus_info, "%.63s", (const char *)cp.bus_info);
                c->capture = (caps & V4L2_CAP_VIDEO_CAPTURE) && (caps & V4L2_CAP_STREAMING);
            }
            if (fd >= 0) close(fd);
        }
        n++;
    }
    closedir(d);
    qsort(out, (size_t)(n < cap ? n : cap), sizeof *out, cmp_info);
    *count = n;
    return IO_OK;
}
