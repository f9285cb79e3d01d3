/* io_dummy.c - a synthetic camera backend (io_cam_dummy, io_dev.h) for
 * fast, deterministic unit tests of everything above the driver: frame k
 * carries the time stamp t0 + offset + k * period and the pattern
 * io_dummy_pixel(x, y, k); it becomes ready when the test's clock reaches
 * its time. Faults on request: lost frames (sequence gaps), short and
 * corrupt buffers, unplugging (ENODEV), a missing or busy device, no
 * controls. Like a real driver it loses a frame when no buffer is queued. */
#include "io_dev.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct dummy_priv {
    io_dummy_cam_opts o;
    const io_dummy_cam_opts *live;  /* the test's struct: faults may change */
    uint64_t next_k;                /* next frame the "sensor" captures */
    int gone;                       /* unplugged */
    int order[IO_CAM_MAX_BUFFERS];  /* queued (empty) buffers, FIFO */
    int nq;
    int done[IO_CAM_MAX_BUFFERS];   /* filled buffers, FIFO */
    uint64_t done_k[IO_CAM_MAX_BUFFERS];
    int nd;
    int ctrl[IO_CTRL_COUNT];
} dummy_priv;

uint8_t io_dummy_pixel(int x, int y, uint32_t k)
{
    return (uint8_t)((unsigned)x * 3u + (unsigned)y * 5u + k * 7u);
}

static dummy_priv *priv_of(io_cam *cam) { return (dummy_priv *)cam->priv; }

static const io_dummy_cam_opts *opts_of(io_cam *cam)
{
    dummy_priv *p = priv_of(cam);
    return p->live ? p->live : &p->o;
}

static uint64_t frame_time(const io_dummy_cam_opts *o, uint64_t k)
{
    return o->t0_ns + o->offset_ns + k * o->period_ns;
}

static io_result dummy_open(io_cam *cam, io_error *err)
{
    typedef char fits[sizeof(dummy_priv) <= sizeof cam->priv_store ? 1 : -1];
    (void)sizeof(fits);
    dummy_priv *p = (dummy_priv *)cam->priv_store;
    memset(p, 0, sizeof *p);
    cam->priv = p;
    if (cam->cfg.backend_opts) {
        p->live = (const io_dummy_cam_opts *)cam->cfg.backend_opts;
        p->o = *p->live;
    }
    if (!p->o.period_ns) p->o.period_ns = 1000000000ull / 60u;
    const io_dummy_cam_opts *o = opts_of(cam);
    if (o->fail_open == 1)
        return io_fail(err, IO_ERR_NOT_FOUND, "%s: cannot open: No such file or directory "
                       "(no such camera)", cam->cfg.path);
    if (o->fail_open == 2)
        return io_fail(err, IO_ERR_DEVICE, "%s: cannot open: Device or resource busy (busy: "
                       "another program uses it)", cam->cfg.path);
    static const uint32_t fmts[3] = {IO_FMT_YUYV, IO_FMT_GREY, IO_FMT_RGGB};
    uint32_t mask = o->formats_mask ? o->formats_mask : 7u;
    uint32_t want = cam->cfg.fourcc;
    uint32_t pick = 0;
    for (int i = 0; i < 3; i++)
        if ((mask >> i) & 1u) {
            if (!want && !pick) pick = fmts[i];
            if (want == fmts[i]) pick = want;
        }
    if (!pick) {
        char fs[5], list[64] = "";
        for (int i = 0; i < 3; i++)
            if ((mask >> i) & 1u) {
                char f2[5];
                size_t l = strlen(list);
                snprintf(list + l, sizeof list - l, "%s%s", l ? ", " : "", io_fourcc_str(fmts[i], f2));
            }
        return io_fail(err, IO_ERR_FORMAT, "%s: format %s not offered (the device offers: %s)",
                       cam->cfg.path, io_fourcc_str(want, fs), list);
    }
    cam->fourcc = pick;
    if (cam->cfg.width == 0 && cam->cfg.height == 0) {
        cam->cfg.width = 640;
        cam->cfg.height = 480;
    }
    cam->width = cam->cfg.width;
    cam->height = cam->cfg.height;
    cam->stride = io_fmt_min_stride(pick, cam->width);
    cam->image_bytes = cam->stride * (size_t)cam->height;
    uint64_t per = p->o.period_ns;
    cam->fps_num = 1;
    cam->fps_den = (int)((1000000000ull + per / 2) / per);
    if (cam->cfg.fps > 0) {
        /* the dummy honours the frame rate asked when the test set none */
        if (!(cam->cfg.backend_opts && ((const io_dummy_cam_opts *)cam->cfg.backend_opts)->period_ns)) {
            p->o.period_ns = 1000000000ull / (uint64_t)cam->cfg.fps;
            cam->fps_den = cam->cfg.fps;
        }
    }
    snprintf(cam->driver, sizeof cam->driver, "dummy");
    snprintf(cam->card, sizeof cam->card, "egofuse dummy camera");
    snprintf(cam->bus_info, sizeof cam->bus_info, "dummy:%.50s", cam->cfg.path);
    for (int i = 0; i < cam->cfg.buffers; i++) {
        cam->buf[i] = malloc(cam->image_bytes);
        if (!cam->buf[i])
            return io_fail(err, IO_ERR_NOMEM, "%s: out of memory for buffer %d", cam->cfg.path, i);
        cam->buf_len[i] = cam->image_bytes;
        cam->nbuf = i + 1;
    }
    p->ctrl[IO_CTRL_EXPOSURE] = 100;
    p->ctrl[IO_CTRL_AUTO_EXPOSURE] = 1;
    p->ctrl[IO_CTRL_GAIN] = 0;
    p->ctrl[IO_CTRL_WHITE_BALANCE] = 4600;
    p->ctrl[IO_CTRL_AUTO_WHITE_BALANCE] = 1;
    p->ctrl[IO_CTRL_BRIGHTNESS] = 128;
    return IO_OK;
}

static void fill(io_cam *cam, int idx, uint64_t k)
{
    uint8_t *d = cam->buf[idx];
    for (int y = 0; y < cam->height; y++) {
        uint8_t *row = d + (size_t)y * cam->stride;
        if (cam->fourcc == IO_FMT_YUYV) {
            for (int x = 0; x < cam->width; x++) {
                row[2 * x] = io_dummy_pixel(x, y, (uint32_t)k);
                row[2 * x + 1] = 128;
            }
        } else {
            for (int x = 0; x < cam->width; x++) row[x] = io_dummy_pixel(x, y, (uint32_t)k);
        }
    }
}

/* The "hardware": captures every frame whose time has come into the oldest
 * queued buffer, or loses it when none is queued. Free-running (no clock):
 * one frame per call while a buffer is queued. */
static void run_hw(io_cam *cam)
{
    dummy_priv *p = priv_of(cam);
    const io_dummy_cam_opts *o = opts_of(cam);
    for (;;) {
        if (p->gone) return;
        uint64_t k = p->next_k;
        if (o->clock_ns && *o->clock_ns < frame_time(&p->o, k)) return;
        if (o->unplug_at && k >= (uint64_t)o->unplug_at) {
            p->gone = 1;
            return;
        }
        if (!o->clock_ns && (p->nq == 0 || p->nd > 0)) return;
        p->next_k++;
        if (o->drop_every && (k + 1) % (uint64_t)o->drop_every == 0) continue;
        if (p->nq == 0) continue; /* no buffer: the frame is lost */
        int idx = p->order[0];
        memmove(p->order, p->order + 1, sizeof(int) * (size_t)(p->nq - 1));
        p->nq--;
        fill(cam, idx, k);
        p->done[p->nd] = idx;
        p->done_k[p->nd] = k;
        p->nd++;
        if (!o->clock_ns) return;
    }
}

static io_result gone_fail(io_cam *cam, const char *what, io_error *err)
{
    return io_fail(err, IO_ERR_DEVICE, "%s: %s: No such device (unplugged?)", cam->cfg.path, what);
}

static io_result dummy_queue(io_cam *cam, int index, io_error *err)
{
    dummy_priv *p = priv_of(cam);
    run_hw(cam);
    if (p->gone) return gone_fail(cam, "VIDIOC_QBUF", err);
    if (p->nq >= IO_CAM_MAX_BUFFERS)
        return io_fail(err, IO_ERR_DEVICE, "%s: buffer %d queued twice", cam->cfg.path, index);
    p->order[p->nq++] = index;
    return IO_OK;
}

static io_result dummy_start(io_cam *cam, io_error *err)
{
    dummy_priv *p = priv_of(cam);
    const io_dummy_cam_opts *o = opts_of(cam);
    p->nq = p->nd = 0;
    p->gone = 0;
    /* start with the first frame not yet in the past, as a camera does */
    p->next_k = 0;
    if (o->clock_ns) {
        uint64_t base = p->o.t0_ns + p->o.offset_ns;
        if (*o->clock_ns > base) p->next_k = (*o->clock_ns - base + p->o.period_ns - 1) / p->o.period_ns;
    }
    (void)err;
    for (int i = 0; i < cam->nbuf; i++) {
        p->order[p->nq++] = i; /* before STREAMON: the sensor is not running */
        cam->queued[i] = 1;
    }
    return IO_OK;
}

static int frame_ready(io_cam *cam)
{
    run_hw(cam);
    return priv_of(cam)->nd > 0;
}

static io_result dummy_dequeue(io_cam *cam, io_frame *f, int *got, uint32_t *flags,
                               io_error *err)
{
    dummy_priv *p = priv_of(cam);
    const io_dummy_cam_opts *o = opts_of(cam);
    *got = 0;
    run_hw(cam);
    if (p->nd == 0) {
        if (p->gone) return gone_fail(cam, "VIDIOC_DQBUF", err);
        return IO_OK;
    }
    int idx = p->done[0];
    uint64_t k = p->done_k[0];
    memmove(p->done, p->done + 1, sizeof(int) * (size_t)(p->nd - 1));
    memmove(p->done_k, p->done_k + 1, sizeof(uint64_t) * (size_t)(p->nd - 1));
    p->nd--;
    f->index = idx;
    f->data = cam->buf[idx];
    f->bytes = cam->image_bytes;
    if (o->short_at && k == (uint64_t)o->short_at) f->bytes = cam->image_bytes / 2;
    *flags = (o->corrupt_at && k == (uint64_t)o->corrupt_at) ? IO_BUF_ERROR : 0;
    f->t_ns = frame_time(&p->o, k);
    f->sequence = (uint32_t)k;
    *got = 1;
    return IO_OK;
}

static int dummy_wait(io_cam *cam, int timeout_ms)
{
    (void)timeout_ms; /* the test's clock does not move while we wait */
    return frame_ready(cam) ? 1 : 0;
}

static io_result dummy_set_ctrl(io_cam *cam, io_cam_ctrl c, int value, io_error *err)
{
    static const int lo[IO_CTRL_COUNT] = {1, 0, 0, 2800, 0, 0};
    static const int hi[IO_CTRL_COUNT] = {10000, 3, 255, 6500, 1, 255};
    if (opts_of(cam)->lacks_ctrls)
        return io_fail(err, IO_ERR_VALUE, "%s: %s has no %s control", cam->cfg.path, cam->card,
                       io_cam_ctrl_name(c));
    priv_of(cam)->ctrl[c] = value < lo[c] ? lo[c] : value > hi[c] ? hi[c] : value;
    return IO_OK;
}

static io_result dummy_get_ctrl(io_cam *cam, io_cam_ctrl c, int *value, io_error *err)
{
    if (opts_of(cam)->lacks_ctrls)
        return io_fail(err, IO_ERR_VALUE, "%s: %s has no %s control", cam->cfg.path, cam->card,
                       io_cam_ctrl_name(c));
    *value = priv_of(cam)->ctrl[c];
    return IO_OK;
}

static void dummy_stop(io_cam *cam)
{
    dummy_priv *p = priv_of(cam);
    p->nq = p->nd = 0;
}

static void dummy_close(io_cam *cam)
{
    for (int i = 0; i < cam->nbuf; i++) {
        free(cam->buf[i]);
        cam->buf[i] = NULL;
    }
    cam->nbuf = 0;
}

const io_cam_backend io_cam_dummy = {
    "dummy",    dummy_open,     dummy_start,    dummy_dequeue, dummy_queue,
    dummy_wait, dummy_set_ctrl, dummy_get_ctrl, dummy_stop,    dummy_close,
};
