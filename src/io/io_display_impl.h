/* io_display_impl.h - what the dispatcher (io_display.c) and its backends
 * (io_display_kms.c, io_display_sdl.c) share: the display's state, the
 * backend table, and the helpers of io_display_common.c. Not a public
 * header. */
#ifndef EGOFUSE_IO_DISPLAY_IMPL_H
#define EGOFUSE_IO_DISPLAY_IMPL_H

#include "io_display.h"

#define IO_DISPLAY_QUEUE 8

typedef struct io_display_ops {
    io_result (*present)(io_display *d, const uint8_t *const rgba[2],
                         const size_t stride[2], uint64_t frame_id, io_error *err);
    /* waits up to timeout_ms for events (< 0: forever) and queues the
     * flips; returns at once when none can come */
    io_result (*wait)(io_display *d, int timeout_ms, io_error *err);
    int (*fd)(const io_display *d);
    int (*busy)(const io_display *d);
    /* frees what the backend's state be holds, not be itself (which
     * io_display_close frees after it) */
    void (*release)(void *be);
} io_display_ops;

struct io_display {
    io_display_kind kind;
    const io_display_ops *ops;
    void *be;                       /* backend state */
    int eye_w, eye_h;
    int out_w, out_h;               /* what is scanned out */
    uint64_t refresh_ns;
    int quit;
    char desc[256];
    io_display_flip q[IO_DISPLAY_QUEUE];
    int qhead, qlen;
};

/* Queues a flip event (the oldest is dropped when full). */
void io_display_push_flip(io_display *d, uint64_t frame_id, uint64_t t_ns, uint32_t seq);
uint64_t io_display_now_ns(void);
/* RGBA rows (alpha ignored) into XRGB8888 (little-endian B, G, R, X) at
 * (x0, y0) of a buffer with dst_pitch bytes per row. */
void io_display_blit_xrgb(uint8_t *dst, size_t dst_pitch, int x0, int y0, const uint8_t *src,
                          size_t stride, int w, int h);

io_result io_display_kms_open(io_display *d, const io_display_spec *s, int buffers,
                              io_error *err);
io_result io_display_sdl_open(io_display *d, const io_display_spec *s, io_error *err);

#endif
