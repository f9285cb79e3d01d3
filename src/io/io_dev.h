/* io_dev.h - live devices of egofuse: V4L2 cameras (stereo pairing by
 * time stamp), USB discovery (libusb + sysfs) and the 5DT data glove.
 * docs/devices.md describes the behaviour, the failure handling and the
 * VM tests against the kernel's own drivers (tests/vm/).
 *
 * CONVENTIONS
 *   As io.h: every call returns an io_result and fills the caller's
 *   io_error with a message naming the device and the reason
 *   ("/dev/video3: VIDIOC_S_FMT: format GREY not offered (YUYV, BA81)").
 *   Objects are plain structs owned by the caller; nothing here keeps
 *   global state. io_cam_grab / io_stereo_grab / io_glove_poll never
 *   allocate and never block longer than the timeout they are given.
 *
 * CAMERA BACKENDS
 *   An io_cam talks to its device through an io_cam_backend (a table of
 *   functions, see src/io/io_backend_template.c for what one must do):
 *   io_cam_v4l2 (the kernel, io_v4l2.c) and io_cam_dummy (io_dummy.c, a
 *   deterministic synthetic camera with fault injection for unit tests).
 *
 * USAGE
 *   io_cam_config c = io_cam_config_default("/dev/video0");
 *   io_cam cam;
 *   if (io_cam_open(&cam, &io_cam_v4l2, &c, &err) != IO_OK ||
 *       io_cam_start(&cam, &err) != IO_OK) { fprintf(stderr, "%s\n", err.msg); ... }
 *   io_frame f;
 *   int got;
 *   io_cam_grab(&cam, 100, &f, &got, &err);   // newest frame, waits <= 100 ms
 *   if (got) { use f.data ...; io_cam_release(&cam, &f, &err); }
 *   io_cam_close(&cam);
 */
#ifndef EGOFUSE_IO_DEV_H
#define EGOFUSE_IO_DEV_H

#include <stddef.h>
#include <stdint.h>
#include "io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ================================================================ camera */

#define IO_CAM_MAX_BUFFERS 16
#define IO_CAM_NAME_MAX 256

/* Four-character codes (the values of linux/videodev2.h). */
#define IO_FOURCC(a, b, c, d) \
    ((uint32_t)(a) | ((uint32_t)(b) << 8) | ((uint32_t)(c) << 16) | ((uint32_t)(d) << 24))
#define IO_FMT_YUYV IO_FOURCC('Y', 'U', 'Y', 'V')   /* 4:2:2, 2 bytes/pixel */
#define IO_FMT_GREY IO_FOURCC('G', 'R', 'E', 'Y')   /* 8-bit luma */
#define IO_FMT_RGGB IO_FOURCC('R', 'G', 'G', 'B')   /* 8-bit Bayer RGGB */
#define IO_FMT_BGGR IO_FOURCC('B', 'A', '8', '1')   /* 8-bit Bayer BGGR */
#define IO_FMT_GBRG IO_FOURCC('G', 'B', 'R', 'G')   /* 8-bit Bayer GBRG */
#define IO_FMT_GRBG IO_FOURCC('G', 'R', 'B', 'G')   /* 8-bit Bayer GRBG */
/* What capture cards and video streams give (the V source, io_vsrc.h).
 * Bytes in memory order; YUV is BT.601 limited range. */
#define IO_FMT_UYVY IO_FOURCC('U', 'Y', 'V', 'Y')   /* 4:2:2 packed, U Y V Y */
#define IO_FMT_NV12 IO_FOURCC('N', 'V', '1', '2')   /* 4:2:0: Y plane, then
                                                       interleaved U V rows,
                                                       both of stride bytes */
#define IO_FMT_YU12 IO_FOURCC('Y', 'U', '1', '2')   /* 4:2:0 planar (I420): Y,
                                                       U, V; chroma stride =
                                                       (stride + 1) / 2 */
#define IO_FMT_422P IO_FOURCC('4', '2', '2', 'P')   /* 4:2:2 planar: Y, U, V */
#define IO_FMT_444P IO_FOURCC('4', '4', '4', 'P')   /* 4:4:4 planar: Y, U, V
                                                       (egofuse's code, y4m) */
#define IO_FMT_RGB3 IO_FOURCC('R', 'G', 'B', '3')   /* RGB24: r g b */
#define IO_FMT_BGR3 IO_FOURCC('B', 'G', 'R', '3')   /* BGR24: b g r */
#define IO_FMT_BGR4 IO_FOURCC('B', 'G', 'R', '4')   /* BGR32: b g r x */
#define IO_FMT_RGB4 IO_FOURCC('R', 'G', 'B', '4')   /* RGB32: x r g b */
#define IO_FMT_XR24 IO_FOURCC('X', 'R', '2', '4')   /* XBGR32: b g r x */
#define IO_FMT_AR24 IO_FOURCC('A', 'R', '2', '4')   /* ABGR32: b g r a */
#define IO_FMT_XB24 IO_FOURCC('X', 'B', '2', '4')   /* RGBX32: r g b x */
#define IO_FMT_AB24 IO_FOURCC('A', 'B', '2', '4')   /* RGBA32: r g b a */
#define IO_FMT_BX24 IO_FOURCC('B', 'X', '2', '4')   /* XRGB32: x r g b */
#define IO_FMT_BA24 IO_FOURCC('B', 'A', '2', '4')   /* ARGB32: a r g b */

/* "YUYV" for a code (buf of at least 5 bytes). */
const char *io_fourcc_str(uint32_t fourcc, char buf[5]);
/* Bytes per line of a tightly packed image, 0 for unsupported formats
 * (for the planar and semi-planar formats: of the Y plane). */
size_t io_fmt_min_stride(uint32_t fourcc, int width);
/* Bytes an image of the format needs with `stride` bytes per line (of
 * the Y plane for planar formats; the last line may be short: only its
 * width counts), 0 for unsupported formats. NV12: stride * height +
 * stride * ((height + 1) / 2); YU12: stride * height plus two chroma
 * planes of (stride + 1) / 2 bytes by (height + 1) / 2 lines. */
size_t io_fmt_image_bytes(uint32_t fourcc, size_t stride, int width, int height);

/* Controls that matter for the see-through pipeline. */
typedef enum io_cam_ctrl {
    IO_CTRL_EXPOSURE = 0,      /* V4L2_CID_EXPOSURE_ABSOLUTE (100 us) or V4L2_CID_EXPOSURE */
    IO_CTRL_AUTO_EXPOSURE,     /* V4L2_CID_EXPOSURE_AUTO: 1 manual, 0/3 auto */
    IO_CTRL_GAIN,              /* V4L2_CID_GAIN */
    IO_CTRL_WHITE_BALANCE,     /* V4L2_CID_WHITE_BALANCE_TEMPERATURE, K */
    IO_CTRL_AUTO_WHITE_BALANCE,/* V4L2_CID_AUTO_WHITE_BALANCE: 0 / 1 */
    IO_CTRL_BRIGHTNESS,        /* V4L2_CID_BRIGHTNESS */
    IO_CTRL_COUNT
} io_cam_ctrl;
const char *io_cam_ctrl_name(io_cam_ctrl c);

typedef struct io_cam_config {
    char path[IO_CAM_NAME_MAX];   /* "/dev/video0", or a dummy's name */
    uint32_t fourcc;              /* wanted format; 0 = the first the
                                     device offers of YUYV, GREY, Bayer */
    int width, height;            /* 640 x 480; 0 x 0 = the size the
                                     device has now (V4L2; dummy 640x480) */
    int fps;                      /* frames per second; 0 = keep */
    int buffers;                  /* mmap buffers, 2..IO_CAM_MAX_BUFFERS */
    int input;                    /* VIDIOC_S_INPUT; -1 = keep */
    int dv_timings;               /* 1: the input takes DV timings (HDMI):
                                     pick the preset matching width x
                                     height at fps before the format */
    const void *backend_opts;     /* backend-specific (io_dummy_cam_opts) */
} io_cam_config;

/* YUYV 640x480 at 60 FPS, 4 buffers, input unchanged. */
io_cam_config io_cam_config_default(const char *path);

/* One captured frame. Its pixels belong to the camera: valid until
 * io_cam_release(), which gives the buffer back to the driver. */
typedef struct io_frame {
    const uint8_t *data;
    size_t bytes;                 /* bytes used */
    int width, height;
    size_t stride;                /* bytes per line */
    uint32_t fourcc;
    uint64_t t_ns;                /* kernel time stamp, CLOCK_MONOTONIC */
    uint32_t sequence;            /* driver's frame counter */
    int index;                    /* buffer index, -1 = none */
} io_frame;

typedef enum io_cam_state {
    IO_CAM_CLOSED = 0,
    IO_CAM_OPEN,                  /* format negotiated, buffers mapped */
    IO_CAM_STREAMING,
    IO_CAM_FAILED                 /* device gone or broken: reopen it */
} io_cam_state;

typedef struct io_cam_stats {
    uint64_t frames;              /* frames delivered by the driver */
    uint64_t dropped;             /* gaps in the sequence numbers */
    uint64_t skipped;             /* dequeued but superseded by a newer one */
    uint64_t short_frames;        /* fewer bytes than the format needs */
    uint64_t corrupt;             /* V4L2_BUF_FLAG_ERROR */
    uint64_t errors;              /* failed ioctls / dequeues */
    uint64_t reopens;             /* successful io_cam_reopen calls */
} io_cam_stats;

struct io_cam_backend;

typedef struct io_cam {
    const struct io_cam_backend *be;
    io_cam_config cfg;            /* as asked (path copied) */
    io_cam_state state;
    int fd;                       /* -1 when closed */
    /* negotiated */
    uint32_t fourcc;
    int width, height;
    size_t stride, image_bytes;   /* bytes per line / per image */
    int fps_num, fps_den;         /* frame interval den/num seconds */
    char driver[32], card[64], bus_info[64];
    /* buffers */
    int nbuf;
    void *buf[IO_CAM_MAX_BUFFERS];
    size_t buf_len[IO_CAM_MAX_BUFFERS];
    int queued[IO_CAM_MAX_BUFFERS]; /* 1 while the driver owns it */
    /* bookkeeping */
    int have_seq;
    uint32_t last_seq;
    io_cam_stats stats;
    char status[256];             /* last problem seen, "" when none */
    void *priv;                   /* backend state (dummy) */
    unsigned char priv_store[512];/* storage for priv, no allocation */
} io_cam;

/* Opens the device, negotiates input, DV timings, format, size, frame rate
 * and maps cfg->buffers buffers. On failure the camera is closed and err
 * names the device and the reason (missing, busy, not a capture device,
 * format not offered, ...). */
io_result io_cam_open(io_cam *cam, const struct io_cam_backend *be,
                      const io_cam_config *cfg, io_error *err);
/* Queues every buffer and starts streaming. */
io_result io_cam_start(io_cam *cam, io_error *err);
/* File descriptor to poll() for POLLIN (-1 for backends without one). */
int io_cam_fd(const io_cam *cam);
/* Dequeues every ready frame and hands out the newest (the older ones go
 * straight back to the driver and count as skipped), waiting up to
 * timeout_ms for the first (0 = do not wait). *got = 1 with *f filled, or
 * 0 when none came. Short or corrupt buffers are requeued, counted and
 * described in cam->status, never handed out. When the device is gone or
 * fails (ENODEV, EIO...) the camera becomes IO_CAM_FAILED and the call
 * returns IO_ERR_DEVICE; io_cam_reopen() brings it back. */
io_result io_cam_grab(io_cam *cam, int timeout_ms, io_frame *f, int *got,
                      io_error *err);
/* Lower level: dequeues one ready frame without skipping (*got 0/1). */
io_result io_cam_dequeue(io_cam *cam, io_frame *f, int *got, io_error *err);
/* Gives the frame's buffer back to the driver (no-op for index -1). */
io_result io_cam_release(io_cam *cam, io_frame *f, io_error *err);
/* Sets / reads a control; IO_ERR_VALUE when the device lacks it. The
 * value is clamped to the control's range by the driver. */
io_result io_cam_set_ctrl(io_cam *cam, io_cam_ctrl c, int value, io_error *err);
io_result io_cam_get_ctrl(io_cam *cam, io_cam_ctrl c, int *value, io_error *err);
/* Stops streaming (buffers stay mapped); safe to call twice. */
void io_cam_stop(io_cam *cam);
/* Stops, unmaps every buffer and closes the descriptor; safe to call on a
 * closed or failed camera, and twice. */
void io_cam_close(io_cam *cam);
/* Closes and opens again with the same configuration and backend; if
 * new_path is not NULL the device is looked for there (its /dev/videoN
 * may have changed after a replug). Starts streaming if it was streaming
 * or failed. Statistics are kept; stats.reopens counts successes. */
io_result io_cam_reopen(io_cam *cam, const char *new_path, io_error *err);

/* A V4L2 node found by io_cam_list. */
typedef struct io_cam_info {
    char path[64];                /* "/dev/video0" */
    char driver[32], card[64], bus_info[64];
    int capture;                  /* 1: video capture with streaming */
} io_cam_info;
/* Lists dev_dir/video* (dev_dir NULL = "/dev") in number order with what
 * VIDIOC_QUERYCAP says; nodes that cannot be opened are listed with the
 * reason in card. *count may exceed cap. IO_OK also when there are none. */
io_result io_cam_list(const char *dev_dir, io_cam_info *out, int cap, int *count,
                      io_error *err);

/* Converts a frame to RGBA8 (alpha 255) of the same size: YUYV, UYVY,
 * NV12, YU12, 422P, 444P (BT.601 limited range, chroma of a 2x1 or 2x2
 * block shared by its pixels), GREY, 8-bit Bayer (bilinear), RGB3, BGR3
 * and the 32-bit RGB formats above (their alpha byte ignored). dst_stride
 * in bytes. */
io_result io_frame_to_rgba(const io_frame *f, uint8_t *dst, size_t dst_stride,
                           io_error *err);
/* The same with full-range YUV when full_range is 1 (y4m XCOLORRANGE=FULL). */
io_result io_frame_to_rgba_range(const io_frame *f, uint8_t *dst, size_t dst_stride,
                                 int full_range, io_error *err);

/* ------------------------------------------------------------- stereo */

/* Pairs left and right frames whose time stamps differ by at most
 * max_skew_ns. Plain data, owned by the caller. */
typedef struct io_stereo {
    io_cam *cam[2];               /* left, right (the caller's) */
    uint64_t max_skew_ns;         /* default: half a frame period */
    io_frame held[2];             /* newest frame of each eye not paired yet */
    int have[2];
    /* statistics */
    uint64_t pairs;
    uint64_t unpaired[2];         /* frames dropped for want of a partner */
    int64_t last_skew_ns;         /* right - left of the last pair */
    uint64_t max_abs_skew_ns;
    double sum_abs_skew_ns;
    int failed[2];                /* eye's camera is IO_CAM_FAILED */
    char status[512];
} io_stereo;

/* Pure pairing rule (unit-tested): given the held frame times of both
 * eyes (have = 0/1), returns 1 when they form a pair (|l - r| <= max
 * skew), else 0 and in *drop the eye whose frame is older and must be
 * dropped (-1 when one side is missing: wait). */
int io_stereo_match(int have_l, uint64_t t_l, int have_r, uint64_t t_r,
                    uint64_t max_skew_ns, int *drop);

/* max_skew_ns 0 = half of the left camera's frame period. */
void io_stereo_init(io_stereo *s, io_cam *left, io_cam *right,
                    uint64_t max_skew_ns);
/* Grabs from both cameras (polling both descriptors together) until a
 * pair is found or timeout_ms passes. *got = 1: out[0], out[1] are the
 * pair (release them with io_stereo_release). A failed eye is reported
 * in s->failed[] and s->status and the call returns IO_ERR_DEVICE with
 * *got = 0; the other camera keeps streaming (its frames are dropped as
 * unpaired until the failed one is reopened). */
io_result io_stereo_grab(io_stereo *s, int timeout_ms, io_frame out[2],
                         int *got, io_error *err);
/* Gives both frames of a pair back to their cameras. */
io_result io_stereo_release(io_stereo *s, io_frame out[2], io_error *err);
/* Gives back held frames (before closing or reopening a camera). */
void io_stereo_flush(io_stereo *s);

/* ----------------------------------------------------------- backends */

/* What a camera backend provides (io_backend_template.c documents each
 * entry; io_cam_* does the bookkeeping around them). */
typedef struct io_cam_backend {
    const char *name;
    io_result (*open)(io_cam *cam, io_error *err);
    io_result (*start)(io_cam *cam, io_error *err);
    /* one ready buffer, non-blocking: *got 0 when none */
    io_result (*dequeue)(io_cam *cam, io_frame *f, int *got, uint32_t *flags,
                         io_error *err);
    io_result (*queue)(io_cam *cam, int index, io_error *err);
    /* waits until a frame may be ready: 1 ready, 0 timeout, -1 error */
    int (*wait)(io_cam *cam, int timeout_ms);
    io_result (*set_ctrl)(io_cam *cam, io_cam_ctrl c, int value, io_error *err);
    io_result (*get_ctrl)(io_cam *cam, io_cam_ctrl c, int *value, io_error *err);
    void (*stop)(io_cam *cam);
    void (*close)(io_cam *cam);
} io_cam_backend;

/* Flags a backend's dequeue reports. */
enum { IO_BUF_ERROR = 1 };

extern const io_cam_backend io_cam_v4l2;
extern const io_cam_backend io_cam_dummy;

/* Options of the dummy camera (cfg.backend_opts; NULL = defaults). It
 * offers YUYV, GREY and RGGB at any size; frame k (k = 0, 1, ...) has the
 * time stamp t0_ns + offset_ns + k * period_ns and becomes ready once
 * *clock_ns (the test's clock; NULL = always) reaches it. Pixels are a
 * pattern of (x, y, k), see io_dummy_pixel. */
typedef struct io_dummy_cam_opts {
    uint64_t period_ns;           /* default 1e9/60 */
    uint64_t t0_ns, offset_ns;
    const uint64_t *clock_ns;
    uint32_t formats_mask;        /* bit 0 YUYV, 1 GREY, 2 RGGB; 0 = all */
    int drop_every;               /* every Nth frame is lost (sequence gap) */
    int short_at;                 /* frame k delivered short (k >= 1) */
    int corrupt_at;               /* frame k flagged as error (k >= 1) */
    int unplug_at;                /* from frame k on: ENODEV (k >= 1) */
    int fail_open;                /* open fails: 1 missing, 2 busy */
    int lacks_ctrls;              /* no controls */
} io_dummy_cam_opts;

/* The dummy's byte at (x, y) of frame k: for YUYV the Y at even bytes is
 * this and U/V are 128; GREY/RGGB carry it directly. */
uint8_t io_dummy_pixel(int x, int y, uint32_t k);

/* ================================================================= USB */

#define IO_USB_MAX_PORTS 7
#define IO_USB_STR_MAX 128

enum {
    IO_USB_KIND_OTHER = 0,
    IO_USB_KIND_CAMERA = 1,       /* has a video (0x0e) interface */
    IO_USB_KIND_GLOVE = 2         /* 5DT vendor 0x5d70 */
};

typedef struct io_usb_dev {
    int bus, address;
    int depth;                    /* number of port numbers */
    uint8_t ports[IO_USB_MAX_PORTS];
    char port_path[32];           /* "1-2.3", as sysfs names it */
    uint16_t vid, pid;
    int usb_class;                /* device class */
    int kind;                     /* IO_USB_KIND_* */
    char serial[IO_USB_STR_MAX];  /* "" when it has none */
    char manufacturer[IO_USB_STR_MAX], product[IO_USB_STR_MAX];
    char video[64];               /* "/dev/video3" for cameras, else "" */
} io_usb_dev;

/* "1-2.3" from a bus number and port numbers. */
void io_usb_port_path(int bus, const uint8_t *ports, int depth, char *out,
                      size_t n);
/* Lists the USB devices seen by libusb (strings from the descriptors, or
 * from sysfs when the device cannot be opened). Cameras get their video
 * node through io_usb_video_node with sysfs_root "/sys". *count may exceed
 * cap (then only cap are written). */
io_result io_usb_list(io_usb_dev *out, int cap, int *count, io_error *err);
/* The same from a sysfs tree only (sysfs_root "/sys", or a fake tree in
 * tests): sysfs_root/bus/usb/devices/B-P.P... with idVendor, idProduct,
 * serial, manufacturer, product, bDeviceClass, busnum, devnum and the
 * interfaces' bInterfaceClass. Sorted by port path. */
io_result io_usb_list_sysfs(const char *sysfs_root, io_usb_dev *out, int cap,
                            int *count, io_error *err);
/* The capture node of the USB device at port_path: the lowest-index
 * sysfs_root/class/video4linux/videoN whose device link lies under an
 * interface "port_path:C.I". out = "/dev/videoN". IO_ERR_NOT_FOUND when
 * the device has none. */
io_result io_usb_video_node(const char *sysfs_root, const char *port_path,
                            char *out, size_t n, io_error *err);
/* Selectors name a device so the name survives reboots and replugs:
 *   "serial:ABC123"  the USB serial number
 *   "port:1-2.3"     the physical port path
 *   "id:5d70:0011"   vendor:product (first match)
 *   "/dev/video2"    a fixed node (does not survive replugs)
 * Returns 1 if the device matches. A malformed selector never matches
 * (io_usb_selector_check reports why). */
int io_usb_match(const io_usb_dev *d, const char *selector);
io_result io_usb_selector_check(const char *selector, io_error *err);
/* Picks the left and right cameras among devs: by selectors, or (NULL
 * selectors) the first two cameras in port-path order. Errors: a
 * selector that matches nothing, several devices, or the same device for
 * both eyes. */
io_result io_usb_assign(const io_usb_dev *devs, int n, const char *sel_left,
                        const char *sel_right, int *left, int *right,
                        io_error *err);

/* Hotplug: compares two listings by port path + vid/pid/serial. Fills
 * added[] / removed[] with indices into now[] / before[]. */
void io_usb_diff(const io_usb_dev *before, int nb, const io_usb_dev *now,
                 int nn, int *added, int *nadded, int *removed, int *nremoved);

/* Hotplug: libusb callbacks where they work, and on every poll a rescan
 * of /sys/bus/usb/devices diffed with the last one (libusb's own list is
 * only refreshed by its hotplug monitor, which needs a udev daemon). The
 * struct is registered with libusb: do not move it while open. */
typedef struct io_usb_watch {
    void *ctx;                    /* libusb_context */
    int hotplug;                  /* 1: libusb callbacks, 0: rescans */
    int handle;                   /* libusb callback handle */
    int events;                   /* pending arrivals + departures */
    int arrived, left;            /* totals */
    int by_event;                 /* the last change came as a libusb event
                                     (0: found by a sysfs rescan) */
    io_usb_dev last[32];
    int nlast;
} io_usb_watch;
io_result io_usb_watch_open(io_usb_watch *w, io_error *err);
/* Handles pending events, waiting up to timeout_ms. *changed = 1 when a
 * device came or went since the last call (then list again). */
io_result io_usb_watch_poll(io_usb_watch *w, int timeout_ms, int *changed,
                            io_error *err);
void io_usb_watch_close(io_usb_watch *w);

/* =============================================================== glove */

/* 5DT Data Glove 5 Ultra over USB HID: 64-byte input reports holding 16
 * little-endian signed 16-bit values, value / 4096 is the reading; the
 * five sensors (thumb .. little) are values 0, 3, 6, 9, 12. */
#define IO_GLOVE_VID 0x5d70
#define IO_GLOVE_PID_RIGHT 0x0010
#define IO_GLOVE_PID_LEFT 0x0011
#define IO_GLOVE_REPORT_SIZE 64
#define IO_GLOVE_VALUES 16

/* Parses one report into the 5 raw sensor readings. IO_ERR_SIZE for a
 * report that is not 64 bytes, IO_ERR_VALUE for a value that is not a
 * plausible reading (|v| / 4096 > 4): the message names the source. */
io_result io_glove_parse(const char *source, const uint8_t *report, size_t n,
                         float raw[KIN_GLOVE_SENSORS], io_error *err);
/* Builds a report from 5 raw readings (tests, the VM's fake glove). */
void io_glove_build(const float raw[KIN_GLOVE_SENSORS],
                    uint8_t report[IO_GLOVE_REPORT_SIZE]);

typedef struct io_glove {
    char name[64];                /* "glove R (5d70:0010 port 1-1)" */
    int side;                     /* KIN_SIDE_LEFT / KIN_SIDE_RIGHT */
    void *ctx, *handle;           /* libusb context / device handle */
    void *xfer;                   /* libusb_transfer in flight */
    int iface, endpoint, claimed, detached;
    uint8_t report[IO_GLOVE_REPORT_SIZE];
    int done;                     /* transfer completed, not handled */
    int gone;                     /* device vanished */
    int has_calib;
    kin_glove_calib calib;
    float raw[KIN_GLOVE_SENSORS]; /* newest readings */
    float value[KIN_GLOVE_SENSORS];/* calibrated 0..1 (raw if no calib) */
    uint64_t reports, bad_reports;
    char status[256];
} io_glove;

/* Feeds one received report: parses, calibrates, counts. */
io_result io_glove_feed(io_glove *g, const uint8_t *report, size_t n,
                        io_error *err);
/* Opens the first glove matching selector (NULL = any 5DT glove; see
 * io_usb_match), detaches the kernel's HID driver, claims the interface
 * and starts reading its interrupt endpoint. */
io_result io_glove_open(io_glove *g, const char *selector, io_error *err);
/* Handles completed reports, waiting up to timeout_ms; *fresh = number of
 * reports taken (values in g->value). IO_ERR_DEVICE when it is gone. */
io_result io_glove_poll(io_glove *g, int timeout_ms, int *fresh, io_error *err);
void io_glove_set_calib(io_glove *g, const kin_glove_calib *c);
/* Copies the calibrated values into a tracking sample (sets the side's
 * KIN_TRACK_GLOVE_* bit). */
void io_glove_to_sample(const io_glove *g, kin_track_sample *s);
void io_glove_close(io_glove *g);

/* Internal to src/io (io_common.c): snprintf into a status field of the
 * devices (a truncated message is fine there); io_v4l2.c, io_glove.c. */
void io__status(char *dst, size_t n, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#ifdef __cplusplus
}
#endif
#endif
