/* io_backend_template.c - what a camera backend must provide (io_dev.h,
 * io_cam_backend). Copy this file to io_<name>.c, rename the functions,
 * and fill in the bodies; io_v4l2.c (the kernel) and io_dummy.c (a
 * synthetic camera for tests) are the two complete examples.
 *
 * The generic layer (io_cam_* in io_v4l2.c) does all bookkeeping: argument
 * checks, state, sequence gaps (stats.dropped), short and corrupt buffers
 * (stats.short_frames / stats.corrupt, requeued, never handed out), the
 * newest-frame policy of io_cam_grab, failure (IO_CAM_FAILED) and reopen.
 * A backend only talks to its device. Rules for every entry:
 *   - fill err through io_fail with a message naming cam->cfg.path and the
 *     reason; return IO_ERR_DEVICE when the device is gone or broken;
 *   - no allocation after open (dequeue, queue and wait run per frame);
 *   - backend state lives in cam->priv_store (512 bytes; point cam->priv
 *     at it in open), never in globals.
 *
 * This template is compiled (so it stays in step with the header) but its
 * table is not exported; the functions below are the minimal correct
 * behaviour of a device that has no frames. */
#include "io_dev.h"

#include <string.h>

/* open: called by io_cam_open with cam->cfg filled and cam->fd = -1.
 * Open the device, negotiate the input, format (cam->cfg.fourcc, or the
 * first of YUYV, GREY, Bayer), size and frame rate; set cam->fourcc,
 * width, height, stride, image_bytes, fps_num/fps_den, driver, card,
 * bus_info; map or allocate cam->cfg.buffers buffers into cam->buf[] /
 * cam->buf_len[] and set cam->nbuf. On failure return the error: close()
 * is called next and must undo whatever was done. */
static io_result tmpl_open(io_cam *cam, io_error *err)
{
    cam->priv = cam->priv_store;
    return io_fail(err, IO_ERR_NOT_FOUND, "%s: the template backend has no device", cam->cfg.path);
}

/* start: queue every buffer whose cam->queued[i] is 0 (set it to 1) and
 * start streaming. */
static io_result tmpl_start(io_cam *cam, io_error *err)
{
    return io_fail(err, IO_ERR_DEVICE, "%s: cannot stream", cam->cfg.path);
}

/* dequeue: non-blocking. When a filled buffer is ready set *got = 1 and
 * f->index, f->data, f->bytes (bytes used), f->t_ns (CLOCK_MONOTONIC
 * nanoseconds of the exposure), f->sequence (the device's frame counter,
 * gaps = frames lost), and *flags (IO_BUF_ERROR for a corrupt buffer).
 * None ready: *got = 0 and IO_OK. */
static io_result tmpl_dequeue(io_cam *cam, io_frame *f, int *got, uint32_t *flags, io_error *err)
{
    (void)cam;
    (void)f;
    (void)flags;
    (void)err;
    *got = 0;
    return IO_OK;
}

/* queue: give buffer `index` back to the device. */
static io_result tmpl_queue(io_cam *cam, int index, io_error *err)
{
    return io_fail(err, IO_ERR_DEVICE, "%s: cannot queue buffer %d", cam->cfg.path, index);
}

/* wait: block up to timeout_ms until a frame may be ready: 1 ready, 0
 * timeout, -1 error (the next dequeue reports it). Backends with a file
 * descriptor set cam->fd in open so io_stereo_grab can poll() both
 * cameras together; without one (cam->fd = -1) wait is called with 0. */
static int tmpl_wait(io_cam *cam, int timeout_ms)
{
    (void)cam;
    (void)timeout_ms;
    return 0;
}

/* set_ctrl / get_ctrl: the controls of io_cam_ctrl; IO_ERR_VALUE naming
 * the control when the device lacks it (io_cam_ctrl_name). Clamp to the
 * control's range. */
static io_result tmpl_set_ctrl(io_cam *cam, io_cam_ctrl c, int value, io_error *err)
{
    (void)value;
    return io_fail(err, IO_ERR_VALUE, "%s: no %s control", cam->cfg.path, io_cam_ctrl_name(c));
}

static io_result tmpl_get_ctrl(io_cam *cam, io_cam_ctrl c, int *value, io_error *err)
{
    (void)value;
    return io_fail(err, IO_ERR_VALUE, "%s: no %s control", cam->cfg.path, io_cam_ctrl_name(c));
}

/* stop: stop streaming; buffers stay allocated (io_cam_start may follow). */
static void tmpl_stop(io_cam *cam) { (void)cam; }

/* close: release the buffers and the device; must work after a failed
 * open (partially set up) and after the device vanished. */
static void tmpl_close(io_cam *cam)
{
    memset(cam->buf, 0, sizeof cam->buf);
    cam->nbuf = 0;
    cam->fd = -1;
}

/* The table. A real backend exports it (extern in io_dev.h). */
const io_cam_backend *io__cam_template(void);
const io_cam_backend *io__cam_template(void)
{
    static const io_cam_backend be = {
        "template",    tmpl_open,     tmpl_start,    tmpl_dequeue, tmpl_queue,
        tmpl_wait,     tmpl_set_ctrl, tmpl_get_ctrl, tmpl_stop,    tmpl_close,
    };
    return &be;
}
