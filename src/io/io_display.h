/* io_display.h - the HMD's displays as an output, without a GPU: DRM/KMS
 * through libdrm (dumb buffers, page flips on vblank with the flip
 * event's time stamp, the previous mode restored on close), and an SDL2
 * window for development machines (libSDL2 is loaded with dlopen only
 * when a window is opened). docs/devices.md "Displays" describes the
 * specs, the defaults and the restore behaviour.
 *
 * SPECS
 *   kms[:/dev/dri/cardN][,connector=NAME|ID[+NAME2|ID2]][,mode=WxH[@HZ]]
 *      [,layout=sbs|two][,buffers=2|3]
 *     sbs: one panel of at least 2*eye_width x eye_height, left eye in the
 *          left half, right eye in the right half;
 *     two: two connectors (one per eye), each at least eye_width x
 *          eye_height, driven by their own CRTCs; a frame counts as shown
 *          when both have flipped.
 *     Defaults: the first /dev/dri/card* with a connected connector; with
 *     no layout and no connector, sbs on the first connected connector
 *     when one of its modes fits 2W x H, else two on the first two
 *     connected connectors; the mode is the preferred one when it fits,
 *     else the smallest that fits (then the highest refresh). An eye
 *     image smaller than its half (or panel) is centred on black; a mode
 *     smaller than the eyes is refused ("no mode fits").
 *   sdl[:WxH]
 *     A resizable window (default 2*eye_width x eye_height), the eyes
 *     side by side, scaled by SDL to the window. Closing it or pressing
 *     Esc or q sets io_display_quit_requested. Flip events are synthesized
 *     when the present returns (no vblank time stamps: refresh_ns is 0 and
 *     the scheduler free-runs).
 *
 * CONVENTIONS
 *   As io.h: io_result + io_error naming the device and the reason, e.g.
 *   "/dev/dri/card0: another DRM master holds it (a desktop session?)",
 *   "/dev/dri/card0: Virtual-1: no mode fits 2560x800; modes: 1024x768@60
 *   ...". Nothing is leaked on failure; the display is restored by
 *   io_display_close, which is idempotent (it takes the handle's address
 *   and clears it). Not thread-safe: one thread drives a display.
 *
 * USAGE
 *   io_display_config c = {"kms", 1280, 800, 2};
 *   io_display *d;
 *   if (io_display_open(&d, &c, &err) != IO_OK) { fprintf(stderr, "egofuse: %s\n", err.msg); ... }
 *   const uint8_t *rgba[2] = {left, right};  size_t stride[2] = {1280 * 4, 1280 * 4};
 *   io_display_present(d, rgba, stride, frame_id, &err);
 *   io_display_flip ev; int got;
 *   io_display_poll(d, 100, &ev, &got, &err);  // ev.frame_id, ev.t_ns
 *   io_display_close(&d);                      // d == NULL afterwards
 */
#ifndef EGOFUSE_IO_DISPLAY_H
#define EGOFUSE_IO_DISPLAY_H

#include <stddef.h>
#include <stdint.h>
#include "io.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct io_display io_display;        /* opaque */

typedef struct io_display_config {
    const char *spec;          /* "kms...", "sdl..." (see above) */
    int eye_width, eye_height; /* size of each eye image */
    int buffers;               /* KMS buffers per CRTC, 2..3 (0 = 2) */
} io_display_config;

/* A parsed spec (io_display_parse; io_display_open parses for you). */
typedef enum io_display_kind { IO_DISPLAY_KMS = 1, IO_DISPLAY_SDL = 2 } io_display_kind;
typedef enum io_display_layout {
    IO_LAYOUT_AUTO = 0, IO_LAYOUT_SBS = 1, IO_LAYOUT_TWO = 2
} io_display_layout;
typedef struct io_display_spec {
    io_display_kind kind;
    char device[256];          /* kms: "" = the first card with a display */
    char connector[2][64];     /* kms: names or ids, "" = automatic */
    int nconnectors;           /* 0, 1 or 2 named */
    int mode_w, mode_h, mode_hz;   /* kms: 0 = automatic (hz 0 = any) */
    io_display_layout layout;
    int buffers;               /* 0 = from the config */
    int win_w, win_h;          /* sdl: 0 = 2*eye_width x eye_height */
} io_display_spec;
io_result io_display_parse(const char *spec, io_display_spec *out, io_error *err);

io_result io_display_open(io_display **out, const io_display_config *c, io_error *err);

/* Descriptor to poll() for POLLIN (flip events); -1 when there is none
 * (SDL: call io_display_poll with a timeout instead). */
int io_display_fd(const io_display *d);

/* Queues the two eye images (RGBA8 rows top to bottom, alpha ignored,
 * eye_width x eye_height each) for the next vblank; frame_id comes back
 * in the flip event that shows them. KMS: converts into a free dumb
 * buffer and page-flips every CRTC; if a flip is still pending it first
 * waits for it (up to 1 s; the event is kept for io_display_poll), so
 * call it when io_display_busy is 0 to never block. */
io_result io_display_present(io_display *d, const uint8_t *const rgba[2],
                             const size_t stride[2], uint64_t frame_id,
                             io_error *err);

typedef struct io_display_flip {
    uint64_t frame_id;         /* of the present that is now on screen */
    uint64_t t_ns;             /* vblank time stamp, CLOCK_MONOTONIC (the
                                  later CRTC's with two connectors) */
    uint32_t seq;              /* driver's vblank counter (0 when it keeps
                                  none: qemu's displays, SDL) */
} io_display_flip;

/* Hands out the next flip event, waiting up to timeout_ms (0 = no wait,
 * < 0 = until one comes): *got = 1 with *ev filled, or 0. Returns at once
 * with *got = 0 when no flip is pending (none can come). A signal (the
 * caller's SIGINT handler) ends the wait early with IO_OK and *got = 0.
 * SDL: also handles the window's events (quit requests). */
io_result io_display_poll(io_display *d, int timeout_ms, io_display_flip *ev,
                          int *got, io_error *err);
/* 1 while a flip is pending (presenting now would wait for it). */
int io_display_busy(const io_display *d);
/* Refresh period of the mode in ns; 0 = unknown (SDL). */
uint64_t io_display_refresh_ns(const io_display *d);
/* 1 once the window was closed or Esc / q pressed (SDL; KMS: 0). */
int io_display_quit_requested(const io_display *d);
/* "kms /dev/dri/card0 Virtual-1 2560x800@60 sbs", "sdl 2560x800 window". */
const char *io_display_describe(const io_display *d);
/* Size of what is scanned out (the mode; sbs: both eyes' panel). */
void io_display_size(const io_display *d, int *width, int *height);
/* Restores the previous CRTC state (mode, framebuffer, position), frees
 * the buffers, drops DRM master and closes the device (KMS), or closes
 * the window (SDL). Safe to call with *d == NULL and twice; sets *d to
 * NULL. Call it from the main loop after a SIGINT handler set a flag. */
void io_display_close(io_display **d);

#ifdef __cplusplus
}
#endif

#endif
