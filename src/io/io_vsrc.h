/* io_vsrc.h - the virtual or remote scene V (and its depth) as a live
 * input, and cameras fed from recorded files (dry runs). docs/vstream.md
 * documents the sources, the stream framing and working producer command
 * lines; src/io/io_vsrc.c, io_vstream.c and io_file_cam.c implement it.
 *
 * SOURCES (io_vsrc_config.spec)
 *   v4l2:/dev/videoN            one capture device carrying both eyes
 *                               (layout: side by side, top-bottom, mono)
 *   v4l2:/dev/videoA,/dev/videoB one device per eye (left, right)
 *   stream:PATH                 a pipe, FIFO, regular file or "-" (stdin);
 *                               the framing is detected from the first
 *                               bytes: egofuse framing ("EGFV" header per
 *                               frame, optional depth) or YUV4MPEG2
 *   raw:WxH:FMT:PATH            headerless frames of one size and format,
 *                               FMT rgb24, bgr24, rgba, bgra, yuyv, uyvy,
 *                               nv12, i420, gray (PATH as for stream:)
 *
 * BEHAVIOUR
 *   io_vsrc_poll never blocks longer than its timeout: descriptors are
 *   non-blocking, partial frames wait in an internal buffer, and of the
 *   complete frames available only the newest is converted (the older
 *   ones count as skipped). The eye images are opaque RGBA8 (alpha 255)
 *   of eye_width x eye_height; a source of another size is scaled
 *   bilinearly (docs/vstream.md gives the exact integer rule), depth by
 *   nearest neighbour. The last good frame stays available in every state
 *   (stale, ended, failed): nothing here stops the caller. A FIFO whose
 *   writer went away is reopened once a second (a new producer may come);
 *   a V4L2 device that fails is reopened at most once a second.
 *   Regular files are paced at cfg.fps (0: the y4m header's rate, else 30)
 *   and start again at the end with cfg.loop.
 *
 * USAGE
 *   io_vsrc_config c = io_vsrc_config_default("stream:-");
 *   io_vsrc *v;
 *   if (io_vsrc_open(&v, &c, &err) != IO_OK) { fprintf(stderr, "%s\n", err.msg); ... }
 *   for (each camera pair) {
 *       int fresh;
 *       io_vsrc_poll(v, 0, &fresh, &err);          // takes the newest V
 *       size_t st;
 *       const uint8_t *l = io_vsrc_eye(v, 0, &st); // NULL before the first
 *       io_vsrc_stat s;
 *       io_vsrc_status(v, now_ns, &s);             // s.state, s.age_ns, s.msg
 *   }
 *   io_vsrc_close(v);
 */
#ifndef EGOFUSE_IO_VSRC_H
#define EGOFUSE_IO_VSRC_H

#include <stddef.h>
#include <stdint.h>
#include "io_dev.h"

#ifdef __cplusplus
extern "C" {
#endif

struct pollfd;
typedef struct io_vsrc io_vsrc;   /* opaque */

typedef enum io_vsrc_layout {
    IO_VSRC_AUTO = 0,             /* from the frame's shape (or the header) */
    IO_VSRC_MONO = 1,             /* the same image for both eyes */
    IO_VSRC_SBS = 2,              /* left | right */
    IO_VSRC_TB = 3                /* left above right */
} io_vsrc_layout;

typedef enum io_vsrc_state {
    IO_VSRC_WAITING = 0,          /* no frame yet */
    IO_VSRC_LIVE,                 /* a frame came within stale_ms */
    IO_VSRC_STALE,                /* none for more than stale_ms */
    IO_VSRC_ENDED,                /* end of stream, producer gone */
    IO_VSRC_FAILED                /* device gone (reopening) or the stream
                                     cannot be read on */
} io_vsrc_state;

const char *io_vsrc_state_name(io_vsrc_state s);   /* "live", ... */
const char *io_vsrc_layout_name(int layout);        /* "sbs", ... */
/* "sbs", "tb", "mono", "auto" -> io_vsrc_layout; -1 when unknown. */
int io_vsrc_layout_parse(const char *s);

typedef struct io_vsrc_config {
    const char *spec;             /* see SOURCES; copied by io_vsrc_open */
    int eye_width, eye_height;    /* 1280 x 800 */
    int layout;                   /* io_vsrc_layout; AUTO. The egofuse
                                     framing's header wins over AUTO */
    int fps;                      /* v4l2: rate asked (0 = keep); regular
                                     files: pacing (0 = y4m F, else 30) */
    uint32_t fourcc;              /* v4l2: format (0 = the first offered of
                                     YUYV, UYVY, NV12, RGB3, BGR4, ...) */
    int width, height;            /* v4l2: capture size (0 = the device's
                                     current one); streams: the size every
                                     frame must have (0 = the first's) */
    int stale_ms;                 /* 200 */
    int input;                    /* v4l2: VIDIOC_S_INPUT, -1 = keep */
    int dv_timings;               /* v4l2: pick DV timings of width x height */
    int loop;                     /* regular files: start again at the end */
    const uint64_t *clock_ns;     /* tests: the clock (NULL = CLOCK_MONOTONIC) */
} io_vsrc_config;

/* The defaults above for spec. */
io_vsrc_config io_vsrc_config_default(const char *spec);

typedef struct io_vsrc_stat {
    io_vsrc_state state;          /* at the `now` given */
    uint64_t t_ns;                /* time stamp of the newest frame: kernel
                                     (v4l2; the older eye's with two
                                     devices), the header's (egofuse
                                     framing, if set), else its arrival;
                                     0 before the first */
    uint64_t arrival_ns;          /* when it was taken in (CLOCK_MONOTONIC) */
    int64_t age_ns;               /* now - t_ns; -1 before the first */
    uint64_t frames;              /* frames converted into the eyes */
    uint64_t skipped;             /* complete frames superseded unseen */
    uint64_t bad;                 /* frames refused (size, header, ...) */
    uint64_t reopens;             /* successful reopens (device, FIFO) */
    int src_width, src_height;    /* of the newest frame, all eyes */
    uint32_t fourcc;              /* its pixel format */
    int layout;                   /* its layout (io_vsrc_layout) */
    int has_depth;                /* 1 when io_vsrc_depth gives depth */
    const char *kind;             /* "v4l2", "egofuse", "y4m", "raw", or
                                     "stream" before the framing is known */
    char msg[384];                /* the last problem, naming the source
                                     and the reason; "" when none */
} io_vsrc_stat;

/* Opens the source. Streams: the path is opened (non-blocking; a FIFO
 * without a writer is fine) but nothing is read. V4L2: the devices are
 * opened and streaming. Errors name the spec and the reason. */
io_result io_vsrc_open(io_vsrc **out, const io_vsrc_config *c, io_error *err);
/* Descriptors to poll() for POLLIN together with the cameras (at most 2;
 * returns how many were written, 0 when there is nothing to wait on). */
int io_vsrc_pollfds(const io_vsrc *v, struct pollfd *fds, int cap);
/* Reads what is available, waiting up to timeout_ms (0 = not at all) for
 * a new frame; converts the newest complete one into the eyes. *fresh
 * (may be NULL) = 1 when the eyes changed. Returns IO_OK also when the
 * source is stale, ended or failed (see io_vsrc_status); errors only for
 * bad arguments. Problems are in the status message, never fatal. */
io_result io_vsrc_poll(io_vsrc *v, int timeout_ms, int *fresh, io_error *err);
/* The eye's image (0 left, 1 right): RGBA8, alpha 255, eye_width x
 * eye_height, *stride bytes per row; NULL before the first frame. Valid
 * (and unchanged) until the next io_vsrc_poll or io_vsrc_close. Read
 * only: with a mono source both eyes may be the same memory. */
const uint8_t *io_vsrc_eye(const io_vsrc *v, int eye, size_t *stride);
/* The eye's depth as pipe_frame_in.virt_depth wants it: float metres
 * along the view axis, 0 = nothing there, eye_width x eye_height,
 * *stride FLOATS per row (pipe_frame_in.virt_depth_stride). NULL when the
 * newest frame has no depth. Same lifetime as io_vsrc_eye. */
const float *io_vsrc_depth(const io_vsrc *v, int eye, size_t *stride);
/* The state at now_ns (CLOCK_MONOTONIC; 0 = now). Cheap, no I/O. */
void io_vsrc_status(const io_vsrc *v, uint64_t now_ns, io_vsrc_stat *st);
/* Closes every descriptor, frees every buffer; NULL is fine. */
void io_vsrc_close(io_vsrc *v);

/* ================================================ cameras from files
 * io_cam_file: an io_cam backend (io_dev.h) that plays recorded camera
 * frames in real time, for `egofuse run` without cameras. cfg.path:
 *   file:PATTERN     a printf frame pattern (one %d or %0Nd, as in scene
 *                    files: "build/samples/cam/left_%04d.png"), frames
 *                    from 0 (or 1 when there is no frame 0) up to the
 *                    first missing file, loaded with io_image_load
 *   file:VIDEO.y4m   a YUV4MPEG2 file, read directly
 *   file:VIDEO       any other video, decoded by `ffmpeg -loglevel error
 *                    -i VIDEO -f yuv4mpegpipe -pix_fmt yuv420p -s WxH -`
 *                    (scaled by ffmpeg to the configured camera size)
 * ("file:" may be left out). Frames must have the configured size (an
 * image sequence or .y4m of another size is refused at open). Formats:
 * RGB3 (cfg.fourcc 0 or RGB3), YUYV (BT.601 limited) or GREY. Frame k
 * has the time stamp t0 + k * period (period = 1 s / cfg.fps, 30 FPS when
 * 0) and becomes ready then (a timerfd on cam->fd wakes poll()); the
 * camera hands out the newest due frame (later ones are dropped as a
 * camera would, counted in stats.dropped). Give both eyes the same t0_ns
 * so frame k of both shares its time stamp (io_stereo pairs them). At the
 * end: with loop the recording starts again, else the camera fails with
 * "end of the recording" (io_cam_file_ended tells this apart). */
typedef struct io_file_cam_opts {
    int loop;                     /* start again after the last frame */
    uint64_t t0_ns;               /* time of frame 0 (CLOCK_MONOTONIC);
                                     0 = when io_cam_start is called */
    const uint64_t *clock_ns;     /* tests: the clock (NULL = CLOCK_MONOTONIC);
                                     then cam->fd is -1 */
    size_t cache_bytes;           /* image sequences up to this total are
                                     decoded once at open (default 64 MiB;
                                     beyond it each frame is decoded when
                                     due) */
} io_file_cam_opts;

extern const io_cam_backend io_cam_file;
/* 1 when cam is a file camera that played its last frame (no loop). */
int io_cam_file_ended(const io_cam *cam);
/* 1 when a camera selector names a file camera ("file:..."). */
int io_cam_file_selector(const char *sel);

#ifdef __cplusplus
}
#endif
#endif
