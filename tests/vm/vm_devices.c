/* vm_devices.c - device tests run inside the test VM (tests/vm/guest.sh)
 * against the kernel's own drivers: vivid cameras, USB devices on qemu's
 * xHCI, and a fake 5DT glove made with dummy_hcd + a configfs HID gadget.
 * Prints "VMTEST name PASS|FAIL detail" and "VMMEASURE name value" lines
 * that tests/test_vm.c reads; exit status 0 when every check passed.
 *
 *   vm_devices capture              both vivid cameras
 *   vm_devices usb-list FILE        lists USB devices into FILE
 *   vm_devices usb-assign L R       assigns left/right by selectors
 *   vm_devices usb-watch MS         waits for a hotplug change
 *   vm_devices glove HIDG SEL       writes reports to /dev/hidgN, reads
 *                                   them back over libusb
 *   vm_devices vsrc                 the V source (io_vsrc) on video2 +
 *                                   video3: formats, side by side, unplug
 *   vm_devices vivid-disconnect DEV presses vivid's "Disconnect" button on
 *                                   DEV: that one device fails as if
 *                                   unplugged (ENODEV) until the driver is
 *                                   bound again (tests/vm/soak.sh) */
#include <dirent.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../../src/io/io_dev.h"
#include "../../src/io/io_vsrc.h"
#include "vm_check.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------- capture */

typedef struct stream_result {
    uint64_t frames[2], pairs;
    double cam_fps[2];       /* from sequence numbers and time stamps */
    double got_fps[2];       /* frames handed to the caller per second */
    int monotonic;           /* time stamps increased on each eye */
    int formats_ok;
    uint64_t max_skew_ns;
    double mean_skew_ms;
    uint64_t dropped[2];
} stream_result;

/* The VMTEST line of a stream check: its figures, whether ok or not. */
static void check_stream(int ok, const char *name, const stream_result *r)
{
    check(ok, name, "frames %llu/%llu, pairs %llu, camera %.2f/%.2f FPS, "
          "delivered %.1f/%.1f FPS, dropped %llu/%llu, skew mean %.3f ms max %.3f ms",
          (unsigned long long)r->frames[0], (unsigned long long)r->frames[1],
          (unsigned long long)r->pairs, r->cam_fps[0], r->cam_fps[1], r->got_fps[0],
          r->got_fps[1], (unsigned long long)r->dropped[0], (unsigned long long)r->dropped[1],
          r->mean_skew_ms, 1e-6 * (double)r->max_skew_ns);
}

static int stream(io_cam cam[2], double seconds, stream_result *r, uint8_t *rgba)
{
    io_stereo s;
    io_error err;
    io_stereo_init(&s, &cam[0], &cam[1], 0);
    memset(r, 0, sizeof *r);
    r->monotonic = r->formats_ok = 1;
    uint64_t t_first[2] = {0, 0}, t_last[2] = {0, 0};
    uint32_t s_first[2] = {0, 0}, s_last[2] = {0, 0};
    double t0 = now_s();
    while (now_s() - t0 < seconds) {
        io_frame out[2];
        int got;
        if (io_stereo_grab(&s, 200, out, &got, &err) != IO_OK) {
            printf("stream: %s\n", err.msg);
            return -1;
        }
        for (int e = 0; e < 2; e++) {
            if (!(got & (1 << e))) continue;
            io_frame *f = &out[e];
            if (r->frames[e]) {
                if (f->t_ns <= t_last[e]) r->monotonic = 0;
            } else {
                t_first[e] = f->t_ns;
                s_first[e] = f->sequence;
            }
            t_last[e] = f->t_ns;
            s_last[e] = f->sequence;
            r->frames[e]++;
            if (f->width != 640 || f->height != 480 || f->stride < 640) r->formats_ok = 0;
            if (rgba && e == 0 && r->frames[e] == 1 &&
                io_frame_to_rgba(f, rgba, 640 * 4, &err) != IO_OK) r->formats_ok = 0;
        }
        if (got == 3) io_stereo_release(&s, out, &err);
        else
            for (int e = 0; e < 2; e++)
                if (got & (1 << e)) io_cam_release(&cam[e], &out[e], &err);
    }
    double wall = now_s() - t0;
    for (int e = 0; e < 2; e++) {
        double dt = 1e-9 * (double)(t_last[e] - t_first[e]);
        r->cam_fps[e] = dt > 0 ? (double)(s_last[e] - s_first[e]) / dt : 0;
        r->got_fps[e] = (double)r->frames[e] / wall;
        r->dropped[e] = cam[e].stats.dropped;
    }
    r->pairs = s.pairs;
    r->max_skew_ns = s.max_abs_skew_ns;
    r->mean_skew_ms = s.pairs ? 1e-6 * s.sum_abs_skew_ns / (double)s.pairs : 0;
    io_stereo_flush(&s);
    return 0;
}

static int open_pair(io_cam cam[2], const char *dev[2], io_cam_config *c)
{
    io_error err;
    for (int e = 0; e < 2; e++) {
        snprintf(c->path, sizeof c->path, "%s", dev[e]);
        if (io_cam_open(&cam[e], &io_cam_v4l2, c, &err) != IO_OK ||
            io_cam_start(&cam[e], &err) != IO_OK) {
            printf("open: %s\n", err.msg);
            if (e) io_cam_close(&cam[0]);
            return -1;
        }
    }
    return 0;
}

static int cmd_capture(void)
{
    const char *dev[2] = {"/dev/video0", "/dev/video1"};
    io_cam cam[2];
    io_error err;
    stream_result r;
    static uint8_t rgba[640 * 480 * 4];
    int fds0 = count_fds();

    /* formats: YUYV, GREY and Bayer are negotiated and converted */
    static const uint32_t fmts[3] = {IO_FMT_YUYV, IO_FMT_GREY, IO_FMT_BGGR};
    for (int k = 0; k < 3; k++) {
        io_cam_config c = io_cam_config_default(dev[0]);
        c.fourcc = fmts[k];
        c.fps = 25;
        char fs[5];
        io_frame f;
        int got = 0;
        io_result rr = io_cam_open(&cam[0], &io_cam_v4l2, &c, &err);
        if (rr == IO_OK) rr = io_cam_start(&cam[0], &err);
        if (rr == IO_OK) rr = io_cam_grab(&cam[0], 2000, &f, &got, &err);
        int conv = got && io_frame_to_rgba(&f, rgba, 640 * 4, &err) == IO_OK;
        /* vivid's test pattern is not flat: the picture has contrast */
        int lo = 255, hi = 0;
        for (int i = 0; conv && i < 640 * 480; i += 97) {
            if (rgba[4 * i + 1] < lo) lo = rgba[4 * i + 1];
            if (rgba[4 * i + 1] > hi) hi = rgba[4 * i + 1];
        }
        check(rr == IO_OK && got && conv && hi - lo > 50 && cam[0].fourcc == fmts[k],
              "capture_format", "%s: %s %s %dx%d stride %zu, green %d..%d%s%s",
              dev[0], cam[0].driver, io_fourcc_str(fmts[k], fs), cam[0].width, cam[0].height,
              cam[0].stride, lo, hi, rr == IO_OK ? "" : ": ", rr == IO_OK ? "" : err.msg);
        if (got) io_cam_release(&cam[0], &f, &err);
        io_cam_close(&cam[0]);
    }

    /* webcam input: 640x480 at 25 FPS on both */
    io_cam_config c = io_cam_config_default(NULL);
    c.fps = 25;
    c.input = 0;
    if (open_pair(cam, dev, &c) == 0) {
        int ok = stream(cam, 3.0, &r, rgba) == 0;
        check_stream(ok && r.monotonic && r.formats_ok && r.pairs >= 20 && r.cam_fps[0] > 20 &&
                         r.cam_fps[0] < 30,
                     "capture_webcam", &r);
        /* the second user of a streaming camera is refused, with the reason */
        io_cam other;
        io_cam_config c2 = c;
        snprintf(c2.path, sizeof c2.path, "%s", dev[0]);
        io_result busy = io_cam_open(&other, &io_cam_v4l2, &c2, &err);
        check(busy != IO_OK && strstr(err.msg, dev[0]) != NULL, "capture_busy", "%s",
              busy != IO_OK ? err.msg : "second open succeeded");
        if (busy == IO_OK) io_cam_close(&other);
        /* controls */
        int v = -1;
        io_result cr = io_cam_set_ctrl(&cam[0], IO_CTRL_BRIGHTNESS, 100, &err);
        if (cr == IO_OK) cr = io_cam_get_ctrl(&cam[0], IO_CTRL_BRIGHTNESS, &v, &err);
        check(cr == IO_OK && v == 100, "capture_ctrl_brightness", "brightness %d%s%s", v,
              cr == IO_OK ? "" : ": ", cr == IO_OK ? "" : err.msg);
        io_result gr = io_cam_set_ctrl(&cam[1], IO_CTRL_GAIN, 40, &err);
        if (gr == IO_OK) {
            gr = io_cam_get_ctrl(&cam[1], IO_CTRL_GAIN, &v, &err);
            check(gr == IO_OK, "capture_ctrl_gain", "gain set, reads %d", v);
        } else {
            check(gr == IO_ERR_VALUE && strstr(err.msg, "gain"), "capture_ctrl_gain",
                  "reported: %s", err.msg);
        }
        io_result xr = io_cam_set_ctrl(&cam[0], IO_CTRL_WHITE_BALANCE, 5000, &err);
        check(xr == IO_OK || (xr == IO_ERR_VALUE && strstr(err.msg, "white balance")),
              "capture_ctrl_wb", "%s", xr == IO_OK ? "set" : err.msg);
        /* clean stop and reopen */
        io_result rr = io_cam_reopen(&cam[1], NULL, &err);
        io_frame f;
        int got = 0;
        if (rr == IO_OK) rr = io_cam_grab(&cam[1], 2000, &f, &got, &err);
        check(rr == IO_OK && got && cam[1].stats.reopens == 1, "capture_reopen", "%s",
              rr == IO_OK ? "streaming again" : err.msg);
        if (got) io_cam_release(&cam[1], &f, &err);
        io_cam_close(&cam[0]);
        io_cam_close(&cam[1]);
    } else {
        check(0, "capture_webcam", "cannot open both cameras");
    }

    /* HDMI input with DV timings 640x480p59.94: about 60 FPS */
    c.fps = 60;
    c.input = 1;
    c.dv_timings = 1;
    if (open_pair(cam, dev, &c) == 0) {
        int ok = stream(cam, 4.0, &r, NULL) == 0;
        check_stream(ok && r.monotonic && r.formats_ok && r.pairs >= 40 && r.cam_fps[0] > 55 &&
                         r.cam_fps[0] < 65 && r.cam_fps[1] > 55 && r.cam_fps[1] < 65,
                     "capture_hdmi60", &r);
        printf("VMMEASURE hdmi_camera_fps %.2f %.2f\n", r.cam_fps[0], r.cam_fps[1]);
        printf("VMMEASURE hdmi_delivered_fps %.2f %.2f\n", r.got_fps[0], r.got_fps[1]);
        io_cam_close(&cam[0]);
        io_cam_close(&cam[1]);
    } else {
        check(0, "capture_hdmi60", "cannot open both cameras on the HDMI input");
    }

    /* bad input */
    io_cam_config bad = io_cam_config_default(dev[0]);
    bad.fourcc = IO_FOURCC('M', 'J', 'P', 'G');
    io_result br = io_cam_open(&cam[0], &io_cam_v4l2, &bad, &err);
    check(br == IO_ERR_FORMAT && strstr(err.msg, "MJPG not offered"), "capture_bad_format", "%s",
          br == IO_OK ? "accepted" : err.msg);
    if (br == IO_OK) io_cam_close(&cam[0]);
    bad = io_cam_config_default("/dev/video9");
    br = io_cam_open(&cam[0], &io_cam_v4l2, &bad, &err);
    check(br == IO_ERR_NOT_FOUND, "capture_missing", "%s", br == IO_OK ? "opened" : err.msg);
    int fds1 = count_fds();
    check(fds0 == fds1, "capture_no_fd_leak", "descriptors before %d, after %d", fds0, fds1);
    return failures ? 1 : 0;
}

/* ----------------------------------------------------------------- usb */

static int cmd_usb_list(const char *file)
{
    io_usb_dev d[32];
    int n = 0;
    io_error err;
    FILE *fp = file ? fopen(file, "w") : stdout;
    if (!fp) return 1;
    io_result r = io_usb_list(d, 32, &n, &err);
    check(r == IO_OK, "usb_list", "%d devices%s%s", n, r == IO_OK ? "" : ": ",
          r == IO_OK ? "" : err.msg);
    for (int i = 0; i < n && i < 32; i++)
        fprintf(fp, "%s %04x:%04x serial=%s kind=%d %s\n", d[i].port_path, d[i].vid, d[i].pid,
                d[i].serial, d[i].kind, d[i].product);
    if (file) fclose(fp);
    return r == IO_OK ? 0 : 1;
}

static int cmd_usb_assign(const char *sl, const char *sr, const char *want_l, const char *want_r)
{
    io_usb_dev d[32];
    int n = 0, l = -1, r = -1;
    io_error err;
    if (io_usb_list(d, 32, &n, &err) != IO_OK) {
        check(0, "usb_assign", "%s", err.msg);
        return 1;
    }
    if (n > 32) n = 32;
    /* the qemu devices are not cameras: assign among every device */
    for (int i = 0; i < n; i++) d[i].kind = IO_USB_KIND_CAMERA;
    io_result rr = io_usb_assign(d, n, sl, sr, &l, &r, &err);
    if (!strcmp(want_r, "-")) {
        /* the right camera is unplugged: a clear message, no pick */
        int ok = rr == IO_ERR_NOT_FOUND && strstr(err.msg, "right camera") && strstr(err.msg, sr);
        check(ok, "usb_assign_missing", "%s", rr == IO_OK ? "assigned a missing camera" : err.msg);
        return ok ? 0 : 1;
    }
    int ok = rr == IO_OK && !strcmp(d[l].serial, want_l) && !strcmp(d[r].serial, want_r);
    if (ok) {
        /* the same by port path */
        char pl[48], pr[48];
        int l2 = -1, r2 = -1;
        snprintf(pl, sizeof pl, "port:%s", d[l].port_path);
        snprintf(pr, sizeof pr, "port:%s", d[r].port_path);
        io_result r3 = io_usb_assign(d, n, pl, pr, &l2, &r2, &err);
        check(r3 == IO_OK && l2 == l && r2 == r, "usb_assign_port", "%s %s", pl, pr);
        if (r3 != IO_OK || l2 != l || r2 != r) ok = 0;
    }
    check(ok, "usb_assign", "%s -> %s (%s), %s -> %s (%s)%s%s", sl, rr == IO_OK ? d[l].port_path : "-",
          rr == IO_OK ? d[l].serial : "-", sr, rr == IO_OK ? d[r].port_path : "-",
          rr == IO_OK ? d[r].serial : "-", rr == IO_OK ? "" : ": ", rr == IO_OK ? "" : err.msg);
    return ok ? 0 : 1;
}

static int cmd_usb_watch(int ms, const char *what)
{
    io_usb_watch w;
    io_error err;
    if (io_usb_watch_open(&w, &err) != IO_OK) {
        check(0, "usb_hotplug", "%s", err.msg);
        return 1;
    }
    printf("VMSYNC %s\n", what);
    fflush(stdout);
    double t0 = now_s();
    int changed = 0, arrived = 0, left = 0;
    while (now_s() - t0 < ms / 1000.0) {
        if (io_usb_watch_poll(&w, 100, &changed, &err) != IO_OK) {
            check(0, "usb_hotplug", "%s", err.msg);
            break;
        }
        arrived = w.arrived;
        left = w.left;
        if (changed) break;
    }
    check(changed, "usb_hotplug", "%s: %d arrived, %d left (%s, %.2f s)", what, arrived, left,
          w.by_event ? "libusb hotplug event" : "sysfs rescan", now_s() - t0);
    io_usb_watch_close(&w);
    return changed ? 0 : 1;
}

/* --------------------------------------------------------------- glove */

static int cmd_glove(const char *hidg, const char *sel)
{
    io_glove g;
    io_error err;
    int fd = open(hidg, O_RDWR);
    if (fd < 0) {
        check(0, "glove", "%s: %s", hidg, strerror(errno));
        return 1;
    }
    io_result r = io_glove_open(&g, sel, &err);
    check(r == IO_OK, "glove_open", "%s", r == IO_OK ? g.name : err.msg);
    if (r != IO_OK) {
        close(fd);
        return 1;
    }
    /* calibration: open hand reads 0.2, fist 1.4 (raw, 1/4096 units) */
    kin_glove_calib cal;
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
        cal.raw_open[k] = 0.2f;
        cal.raw_fist[k] = 1.4f;
    }
    io_glove_set_calib(&g, &cal);
    int good = 0, sent = 0;
    double worst = 0;
    for (int i = 0; i < 40; i++) {
        float raw[KIN_GLOVE_SENSORS], want[KIN_GLOVE_SENSORS];
        for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
            want[k] = (float)((i * 7 + k * 13) % 11) / 10.0f;
            raw[k] = 0.2f + 1.2f * want[k];
        }
        uint8_t rep[IO_GLOVE_REPORT_SIZE];
        io_glove_build(raw, rep);
        if (write(fd, rep, sizeof rep) != (ssize_t)sizeof rep) break;
        sent++;
        int fresh = 0;
        double t0 = now_s();
        while (!fresh && now_s() - t0 < 2.0)
            if (io_glove_poll(&g, 100, &fresh, &err) != IO_OK) break;
        if (!fresh) continue;
        double d = 0;
        for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
            double e = g.value[k] > want[k] ? g.value[k] - want[k] : want[k] - g.value[k];
            if (e > d) d = e;
        }
        if (d > worst) worst = d;
        if (d < 1e-3) good++;
    }
    check(good == sent && sent == 40, "glove_values", "%d of %d reports arrived as calibrated "
          "values (worst error %.5f), %llu bad", good, sent, worst,
          (unsigned long long)g.bad_reports);
    /* a short report: the gadget sends 16 bytes */
    uint8_t shortrep[16] = {0};
    ssize_t wn = write(fd, shortrep, sizeof shortrep);
    int fresh = 0;
    double t0 = now_s();
    r = IO_OK;
    while (wn > 0 && g.bad_reports == 0 && now_s() - t0 < 2.0 && r == IO_OK)
        r = io_glove_poll(&g, 100, &fresh, &err);
    check(g.bad_reports == 1 && strstr(g.status, "16 bytes"), "glove_short_report", "%s",
          g.status);
    io_glove_close(&g);
    close(fd);
    return failures ? 1 : 0;
}

/* ---------------------------------------------------------------- vsrc */

/* Polls the V source until both eyes have had `frames` frames or the
 * time is up; returns the frames converted. */
static uint64_t vsrc_run(io_vsrc *v, uint64_t frames, double seconds)
{
    io_error err;
    io_vsrc_stat st;
    double t0 = now_s();
    do {
        int fresh;
        io_vsrc_poll(v, 100, &fresh, &err);
        io_vsrc_status(v, 0, &st);
    } while (st.frames < frames && now_s() - t0 < seconds);
    return st.frames;
}

/* vivid's 75% colour bars, scaled into a 640x400 eye (small: TCG is
 * slow): the first bar is grey-white, the second yellow, the last black;
 * alpha 255. */
#define VS_EW 640
#define VS_EH 400
static int vsrc_pixels_sane(io_vsrc *v, int eye, char *why, size_t n)
{
    size_t stride;
    const uint8_t *im = io_vsrc_eye(v, eye, &stride);
    if (!im) {
        snprintf(why, n, "eye %d: no image", eye);
        return 0;
    }
    const int y = 250;
    const uint8_t *w = im + (size_t)y * stride + 4 * 40, *yel = im + (size_t)y * stride + 4 * 120,
                  *blk = im + (size_t)y * stride + 4 * 600;
    int alpha = 1;
    for (int x = 0; x < VS_EW; x += 7) alpha &= im[(size_t)y * stride + 4 * (size_t)x + 3] == 255;
    snprintf(why, n, "eye %d row %d: bar 1 %d,%d,%d bar 2 %d,%d,%d bar 8 %d,%d,%d, alpha %s", eye,
             y, w[0], w[1], w[2], yel[0], yel[1], yel[2], blk[0], blk[1], blk[2],
             alpha ? "255" : "not 255");
    return alpha && w[0] > 140 && abs(w[0] - w[1]) < 16 && abs(w[1] - w[2]) < 16 && yel[0] > 140 &&
           yel[1] > 140 && yel[2] < 60 && blk[0] < 50 && blk[1] < 50 && blk[2] < 50;
}

static int vivid_sysfs(char *dev, size_t n)
{
    DIR *d = opendir("/sys/bus/platform/drivers/vivid");
    struct dirent *e;
    int found = 0;
    while (d && (e = readdir(d)) != NULL)
        if (!strncmp(e->d_name, "vivid", 5)) {
            snprintf(dev, n, "%.100s", e->d_name);
            found = 1;
            break;
        }
    if (d) closedir(d);
    return found;
}

static int write_sys(const char *path, const char *val)
{
    int fd = open(path, O_WRONLY);
    if (fd < 0) return -1;
    ssize_t k = write(fd, val, strlen(val));
    close(fd);
    return k == (ssize_t)strlen(val) ? 0 : -1;
}

/* The config of the vivid source spec: fourcc frames of w x h at 25 FPS
 * from input 0, scaled to eyes of VS_EW x VS_EH. */
static io_vsrc_config vsrc_config(const char *spec, uint32_t fourcc, int w, int h)
{
    io_vsrc_config c = io_vsrc_config_default(spec);
    c.fourcc = fourcc;
    c.width = w;
    c.height = h;
    c.eye_width = VS_EW;
    c.eye_height = VS_EH;
    c.fps = 25;
    c.input = 0;
    return c;
}

static int cmd_vsrc(void)
{
    io_error err;
    io_vsrc_stat st;
    int fds0 = count_fds();
    /* one device per eye, each format vivid offers, 640x360 scaled to 640x400 */
    static const uint32_t fmts[] = {IO_FMT_YUYV, IO_FMT_NV12, IO_FMT_RGB3, IO_FMT_BGR4, IO_FMT_XR24};
    for (size_t k = 0; k < sizeof fmts / sizeof fmts[0]; k++) {
        char fs[5];
        io_vsrc_config c = vsrc_config("v4l2:/dev/video2,/dev/video3", fmts[k], 640, 360);
        io_vsrc *v;
        io_result r = io_vsrc_open(&v, &c, &err);
        if (r == IO_ERR_FORMAT && strstr(err.msg, "not offered")) {
            printf("VMINFO vsrc %s not offered by vivid: %s\n", io_fourcc_str(fmts[k], fs), err.msg);
            continue;
        }
        if (r != IO_OK) {
            check(0, "vsrc_format", "%s: %s", io_fourcc_str(fmts[k], fs), err.msg);
            continue;
        }
        double t0 = now_s();
        uint64_t n = vsrc_run(v, 4, 6.0);
        double dt = now_s() - t0;
        io_vsrc_status(v, 0, &st);
        char w0[256], w1[256];
        int ok0 = vsrc_pixels_sane(v, 0, w0, sizeof w0), ok1 = vsrc_pixels_sane(v, 1, w1, sizeof w1);
        size_t s0 = 0;
        io_vsrc_eye(v, 0, &s0);
        /* (under TCG scaling two eyes takes long: stale is fine here) */
        check(n >= 4 && (st.state == IO_VSRC_LIVE || st.state == IO_VSRC_STALE) &&
                  st.src_width == 640 && st.fourcc == fmts[k] && s0 == 4 * VS_EW && ok0 && ok1 &&
                  /* vivid stamps a frame up to a few ms ahead of our read of the clock */
                  st.age_ns > -50000000 && st.age_ns < 5000000000,
              "vsrc_format", "%s 640x360 x2 -> eyes 640x400: %llu frames in %.2f s (%s), "
              "skipped %llu, age %.1f ms; %s; %s", io_fourcc_str(fmts[k], fs),
              (unsigned long long)n, dt, io_vsrc_state_name(st.state),
              (unsigned long long)st.skipped, 1e-6 * (double)st.age_ns, w0, w1);
        io_vsrc_close(v);
    }

    /* one device carrying both eyes side by side: 1280x720 -> 2 x 640x720 */
    {
        io_vsrc_config c = vsrc_config("v4l2:/dev/video2", IO_FMT_YUYV, 1280, 720);
        c.layout = IO_VSRC_SBS;
        io_vsrc *v;
        io_result r = io_vsrc_open(&v, &c, &err);
        uint64_t n = r == IO_OK ? vsrc_run(v, 4, 6.0) : 0;
        if (r == IO_OK) io_vsrc_status(v, 0, &st);
        /* left eye = the left half of the bars: bar 1 white, bar 4 (green) at its right */
        size_t stride = 0;
        const uint8_t *l = r == IO_OK ? io_vsrc_eye(v, 0, &stride) : NULL;
        const uint8_t *rr = r == IO_OK ? io_vsrc_eye(v, 1, NULL) : NULL;
        int ok = l && rr && l != rr;
        const uint8_t *g = ok ? l + 250 * stride + 4 * 600 : NULL;  /* green bar */
        const uint8_t *b = ok ? rr + 250 * stride + 4 * 600 : NULL; /* black bar */
        check(r == IO_OK && n >= 2 && ok && g[1] > 120 && g[0] < 60 && g[2] < 60 && b[1] < 50,
              "vsrc_sbs", "%s%s: %llu frames, left eye's right end %d,%d,%d (green), right eye's "
              "%d,%d,%d (black)", r == IO_OK ? "v4l2:/dev/video2 1280x720 sbs" : "",
              r == IO_OK ? "" : err.msg, (unsigned long long)n, g ? g[0] : -1, g ? g[1] : -1,
              g ? g[2] : -1, b ? b[0] : -1, b ? b[1] : -1, b ? b[2] : -1);
        if (r == IO_OK) io_vsrc_close(v);
    }

    /* the devices vanish (driver unbound) and come back: failed, the last V
     * held, reopened at most once a second */
    char pdev[128];
    if (!vivid_sysfs(pdev, sizeof pdev)) {
        check(0, "vsrc_unplug", "no vivid device under /sys/bus/platform/drivers/vivid");
    } else {
        io_vsrc_config c = vsrc_config("v4l2:/dev/video2,/dev/video3", IO_FMT_YUYV, 640, 360);
        io_vsrc *v;
        io_result r = io_vsrc_open(&v, &c, &err);
        uint64_t n = r == IO_OK ? vsrc_run(v, 4, 6.0) : 0;
        int unbound = r == IO_OK && write_sys("/sys/bus/platform/drivers/vivid/unbind", pdev) == 0;
        io_vsrc_stat gone;
        memset(&gone, 0, sizeof gone);
        double t0 = now_s();
        int seen_failed = 0;
        /* both devices must notice (and let go of their nodes) */
        while (unbound && now_s() - t0 < 2.0) {
            int fresh;
            io_vsrc_poll(v, 100, &fresh, &err);
            io_vsrc_status(v, 0, &gone);
            if (gone.state == IO_VSRC_FAILED && !seen_failed) {
                seen_failed = 1;
                printf("VMINFO vsrc unplug seen after %.2f s: %s\n", now_s() - t0, gone.msg);
            }
        }
        int held = r == IO_OK && io_vsrc_eye(v, 0, NULL) != NULL;
        int bound = unbound && write_sys("/sys/bus/platform/drivers/vivid/bind", pdev) == 0;
        io_vsrc_stat back;
        memset(&back, 0, sizeof back);
        t0 = now_s();
        uint64_t f0 = gone.frames;
        while (bound && now_s() - t0 < 8.0) {
            int fresh;
            io_vsrc_poll(v, 100, &fresh, &err);
            io_vsrc_status(v, 0, &back);
            if (back.reopens >= 1 && back.frames > f0 + 2) break;
        }
        check(r == IO_OK && n >= 4 && seen_failed && gone.state == IO_VSRC_FAILED && held &&
                  strstr(gone.msg, "/dev/video") && back.reopens >= 1 && back.frames > f0 &&
                  (back.state == IO_VSRC_LIVE || back.state == IO_VSRC_STALE),
              "vsrc_unplug", "%s%s unbound: %s (%s), last V %s; bound again: %s, reopens %llu, "
              "frames %llu -> %llu", pdev, r == IO_OK ? "" : err.msg,
              io_vsrc_state_name(gone.state), gone.msg, held ? "held" : "lost",
              io_vsrc_state_name(back.state), (unsigned long long)back.reopens,
              (unsigned long long)gone.frames, (unsigned long long)back.frames);
        if (r == IO_OK) io_vsrc_close(v);
        if (unbound && !bound) write_sys("/sys/bus/platform/drivers/vivid/bind", pdev);
        /* the HMD cameras of the later steps are back too */
        printf("VMINFO vsrc after rebind: /dev/video0 %s, /dev/video1 %s\n",
               access("/dev/video0", F_OK) == 0 ? "present" : "MISSING",
               access("/dev/video1", F_OK) == 0 ? "present" : "MISSING");
    }
    int fds1 = count_fds();
    check(fds0 == fds1, "vsrc_no_fd_leak", "descriptors before %d, after %d", fds0, fds1);
    return failures ? 1 : 0;
}

/* vivid's "Disconnect" button (a driver-private control, found by name). */
static int cmd_vivid_disconnect(const char *dev)
{
    int fd = open(dev, O_RDWR | O_NONBLOCK);
    if (fd < 0) {
        fprintf(stderr, "%s: %s\n", dev, strerror(errno));
        return 1;
    }
    struct v4l2_queryctrl q;
    memset(&q, 0, sizeof q);
    q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
    int found = 0;
    while (ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
        if (!strcmp((const char *)q.name, "Disconnect")) {
            found = 1;
            break;
        }
        q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
    }
    int rc = 1;
    if (!found) {
        fprintf(stderr, "%s: no \"Disconnect\" control\n", dev);
    } else {
        struct v4l2_control c = {q.id, 1};
        if (ioctl(fd, VIDIOC_S_CTRL, &c) != 0)
            fprintf(stderr, "%s: VIDIOC_S_CTRL Disconnect: %s\n", dev, strerror(errno));
        else
            rc = 0;
    }
    close(fd);
    return rc;
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc >= 2 && !strcmp(argv[1], "capture")) return cmd_capture();
    if (argc >= 2 && !strcmp(argv[1], "usb-list")) return cmd_usb_list(argc > 2 ? argv[2] : NULL);
    if (argc >= 6 && !strcmp(argv[1], "usb-assign"))
        return cmd_usb_assign(argv[2], argv[3], argv[4], argv[5]);
    if (argc >= 4 && !strcmp(argv[1], "usb-watch")) return cmd_usb_watch(atoi(argv[2]), argv[3]);
    if (argc >= 4 && !strcmp(argv[1], "glove")) return cmd_glove(argv[2], argv[3]);
    if (argc >= 2 && !strcmp(argv[1], "vsrc")) return cmd_vsrc();
    if (argc >= 3 && !strcmp(argv[1], "vivid-disconnect")) return cmd_vivid_disconnect(argv[2]);
    fprintf(stderr, "usage: vm_devices capture | usb-list [FILE] | usb-assign SEL_L SEL_R "
                    "SERIAL_L SERIAL_R | usb-watch MS WHAT | glove /dev/hidgN SELECTOR | vsrc\n");
    return 2;
}
