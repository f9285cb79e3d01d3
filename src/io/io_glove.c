/* io_glove.c - the 5DT Data Glove 5 Ultra over libusb (io_dev.h): report
 * parsing (16 little-endian int16 values / 4096, sensors at values 0, 3,
 * 6, 9, 12), calibration through kin_glove_calib_apply, and an
 * asynchronous interrupt-IN reader that never blocks longer than asked. */
#include "io_dev.h"

#include <libusb.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/time.h>

static const int sensor_value[KIN_GLOVE_SENSORS] = {0, 3, 6, 9, 12};

io_result io_glove_parse(const char *src, const uint8_t *rep, size_t n,
                         float raw[KIN_GLOVE_SENSORS], io_error *err)
{
    if (!src) src = "glove";
    if (!rep || n != IO_GLOVE_REPORT_SIZE)
        return io_fail(err, IO_ERR_SIZE, "%s: short report: %zu bytes, a report has %d", src,
                       rep ? n : 0, IO_GLOVE_REPORT_SIZE);
    float v[KIN_GLOVE_SENSORS];
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
        int i = sensor_value[k];
        int16_t x = (int16_t)((uint16_t)rep[2 * i] | (uint16_t)((uint16_t)rep[2 * i + 1] << 8));
        v[k] = (float)x / 4096.0f;
        if (fabsf(v[k]) > 4.0f)
            return io_fail(err, IO_ERR_VALUE, "%s: sensor %d reads %.4f, outside -4..4: corrupt "
                           "report", src, k, (double)v[k]);
    }
    memcpy(raw, v, sizeof v);
    return IO_OK;
}

void io_glove_build(const float raw[KIN_GLOVE_SENSORS], uint8_t rep[IO_GLOVE_REPORT_SIZE])
{
    memset(rep, 0, IO_GLOVE_REPORT_SIZE);
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
        float f = raw[k] * 4096.0f;
        long q = lroundf(f < -32768.0f ? -32768.0f : f > 32767.0f ? 32767.0f : f);
        uint16_t u = (uint16_t)(int16_t)q;
        int i = sensor_value[k];
        rep[2 * i] = (uint8_t)(u & 0xff);
        rep[2 * i + 1] = (uint8_t)(u >> 8);
    }
}

void io_glove_set_calib(io_glove *g, const kin_glove_calib *c)
{
    if (c) {
        g->calib = *c;
        g->has_calib = 1;
    } else {
        g->has_calib = 0;
    }
}

io_result io_glove_feed(io_glove *g, const uint8_t *rep, size_t n, io_error *err)
{
    float raw[KIN_GLOVE_SENSORS];
    io_error e;
    io_result r = io_glove_parse(g->name[0] ? g->name : "glove", rep, n, raw, &e);
    if (r != IO_OK) {
        g->bad_reports++;
        io__status(g->status, sizeof g->status, "%s (report %llu dropped, keeping the last "
                   "values)", e.msg, (unsigned long long)(g->reports + g->bad_reports));
        if (err) *err = e;
        return r;
    }
    memcpy(g->raw, raw, sizeof raw);
    if (g->has_calib) kin_glove_calib_apply(&g->calib, raw, g->value);
    else memcpy(g->value, raw, sizeof raw);
    g->reports++;
    return IO_OK;
}

void io_glove_to_sample(const io_glove *g, kin_track_sample *s)
{
    int side = g->side == KIN_SIDE_LEFT ? 0 : 1;
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
        float v = g->value[k];
        s->glove[side][k] = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
    }
    s->valid |= side ? KIN_TRACK_GLOVE_R : KIN_TRACK_GLOVE_L;
}

/* ------------------------------------------------------------------ USB */

static void LIBUSB_CALL xfer_cb(struct libusb_transfer *t)
{
    io_glove *g = t->user_data;
    g->done = 1;
}

static io_result submit(io_glove *g, io_error *err)
{
    struct libusb_transfer *t = g->xfer;
    libusb_fill_interrupt_transfer(t, g->handle, (unsigned char)g->endpoint, g->report,
                                   IO_GLOVE_REPORT_SIZE, xfer_cb, g, 0);
    g->done = 0;
    int r = libusb_submit_transfer(t);
    if (r != 0) {
        if (r == LIBUSB_ERROR_NO_DEVICE) g->gone = 1;
        return io_fail(err, IO_ERR_DEVICE, "%s: cannot read reports: %s", g->name,
                       libusb_strerror(r));
    }
    return IO_OK;
}

io_result io_glove_open(io_glove *g, const char *sel, io_error *err)
{
    memset(g, 0, sizeof *g);
    if (sel && io_usb_selector_check(sel, err) != IO_OK) return IO_ERR_ARGS;
    libusb_context *ctx = NULL;
    int r = libusb_init(&ctx);
    if (r != 0)
        return io_fail(err, IO_ERR_DEVICE, "glove: libusb cannot start: %s", libusb_strerror(r));
    g->ctx = ctx;
    libusb_device **list;
    ssize_t nd = libusb_get_device_list(ctx, &list);
    libusb_device *found = NULL;
    io_usb_dev u;
    for (ssize_t i = 0; nd > 0 && i < nd && !found; i++) {
        struct libusb_device_descriptor dd;
        if (libusb_get_device_descriptor(list[i], &dd) != 0) continue;
        if (dd.idVendor != IO_GLOVE_VID ||
            (dd.idProduct != IO_GLOVE_PID_LEFT && dd.idProduct != IO_GLOVE_PID_RIGHT))
            continue;
        memset(&u, 0, sizeof u);
        u.bus = libusb_get_bus_number(list[i]);
        u.depth = libusb_get_port_numbers(list[i], u.ports, IO_USB_MAX_PORTS);
        io_usb_port_path(u.bus, u.ports, u.depth, u.port_path, sizeof u.port_path);
        u.vid = dd.idVendor;
        u.pid = dd.idProduct;
        libusb_device_handle *h;
        if (libusb_open(list[i], &h) != 0) continue;
        unsigned char s[IO_USB_STR_MAX];
        if (dd.iSerialNumber &&
            libusb_get_string_descriptor_ascii(h, dd.iSerialNumber, s, sizeof s) > 0)
            snprintf(u.serial, sizeof u.serial, "%s", (const char *)s);
        if (sel && !io_usb_match(&u, sel)) {
            libusb_close(h);
            continue;
        }
        found = list[i];
        g->handle = h;
    }
    if (nd >= 0) libusb_free_device_list(list, 1);
    if (!found) {
        io_glove_close(g);
        return io_fail(err, IO_ERR_NOT_FOUND, "glove: no 5DT glove (USB %04x:%04x or %04x:%04x)%s%s "
                       "found", IO_GLOVE_VID, IO_GLOVE_PID_RIGHT, IO_GLOVE_VID, IO_GLOVE_PID_LEFT,
                       sel ? " matching " : "", sel ? sel : "");
    }
    g->side = u.pid == IO_GLOVE_PID_LEFT ? KIN_SIDE_LEFT : KIN_SIDE_RIGHT;
    snprintf(g->name, sizeof g->name, "glove %c (%04x:%04x port %.20s)",
             g->side == KIN_SIDE_LEFT ? 'L' : 'R', u.vid, u.pid, u.port_path);
    /* the interrupt IN endpoint of the HID interface */
    struct libusb_config_descriptor *cfg;
    g->endpoint = -1;
    if (libusb_get_active_config_descriptor(found, &cfg) == 0) {
        for (int i = 0; i < cfg->bNumInterfaces && g->endpoint < 0; i++) {
            const struct libusb_interface_descriptor *id = &cfg->interface[i].altsetting[0];
            for (int e = 0; e < id->bNumEndpoints; e++) {
                const struct libusb_endpoint_descriptor *ep = &id->endpoint[e];
                if ((ep->bEndpointAddress & LIBUSB_ENDPOINT_IN) &&
                    (ep->bmAttributes & 3) == LIBUSB_TRANSFER_TYPE_INTERRUPT) {
                    g->endpoint = ep->bEndpointAddress;
                    g->iface = id->bInterfaceNumber;
                    break;
                }
            }
        }
        libusb_free_config_descriptor(cfg);
    }
    if (g->endpoint < 0) {
        io_glove_close(g);
        return io_fail(err, IO_ERR_DEVICE, "%s: no interrupt IN endpoint", g->name);
    }
    libusb_set_auto_detach_kernel_driver(g->handle, 1);
    r = libusb_claim_interface(g->handle, g->iface);
    if (r != 0) {
        io_glove_close(g);
        return io_fail(err, IO_ERR_DEVICE, "%s: cannot claim interface %d: %s%s", g->name,
                       g->iface, libusb_strerror(r),
                       r == LIBUSB_ERROR_BUSY ? " (another program reads the glove)" : "");
    }
    g->claimed = 1;
    g->xfer = libusb_alloc_transfer(0);
    if (!g->xfer) {
        io_glove_close(g);
        return io_fail(err, IO_ERR_NOMEM, "glove: out of memory");
    }
    io_result res = submit(g, err);
    if (res != IO_OK) {
        libusb_free_transfer(g->xfer);
        g->xfer = NULL;
        io_glove_close(g);
    }
    return res;
}

io_result io_glove_poll(io_glove *g, int timeout_ms, int *fresh, io_error *err)
{
    *fresh = 0;
    if (!g->ctx || !g->xfer) return io_fail(err, IO_ERR_ARGS, "glove is not open");
    if (g->gone) return io_fail(err, IO_ERR_DEVICE, "%s: unplugged", g->name);
    struct timeval tv = {timeout_ms / 1000, (timeout_ms % 1000) * 1000};
    int r = libusb_handle_events_timeout_completed(g->ctx, &tv, &g->done);
    if (r != 0 && r != LIBUSB_ERROR_INTERRUPTED && r != LIBUSB_ERROR_TIMEOUT)
        return io_fail(err, IO_ERR_DEVICE, "%s: %s", g->name, libusb_strerror(r));
    while (g->done) {
        struct libusb_transfer *t = g->xfer;
        g->done = 0;
        if (t->status == LIBUSB_TRANSFER_NO_DEVICE) {
            g->gone = 1;
            io__status(g->status, sizeof g->status, "%s: unplugged", g->name);
            return io_fail(err, IO_ERR_DEVICE, "%s: unplugged", g->name);
        }
        if (t->status == LIBUSB_TRANSFER_COMPLETED && t->actual_length == 0) {
            /* an empty transfer carries no report */
        } else if (t->status == LIBUSB_TRANSFER_COMPLETED) {
            if (io_glove_feed(g, t->buffer, (size_t)t->actual_length, NULL) == IO_OK) (*fresh)++;
        } else if (t->status != LIBUSB_TRANSFER_TIMED_OUT && t->status != LIBUSB_TRANSFER_CANCELLED) {
            g->bad_reports++;
            io__status(g->status, sizeof g->status, "%s: transfer failed (status %d)", g->name,
                       (int)t->status);
        }
        io_result s = submit(g, err);
        if (s != IO_OK) return s;
        /* more completions may already be there */
        struct timeval zero = {0, 0};
        libusb_handle_events_timeout_completed(g->ctx, &zero, &g->done);
    }
    return IO_OK;
}

void io_glove_close(io_glove *g)
{
    if (!g) return;
    if (g->xfer) {
        if (!g->done && !g->gone && libusb_cancel_transfer(g->xfer) == 0) {
            for (int i = 0; i < 50 && !g->done; i++) {
                struct timeval tv = {0, 10000};
                libusb_handle_events_timeout_completed(g->ctx, &tv, &g->done);
            }
        }
        libusb_free_transfer(g->xfer);
        g->xfer = NULL;
    }
    if (g->handle) {
        if (g->claimed) libusb_release_interface(g->handle, g->iface);
        libusb_close(g->handle);
        g->handle = NULL;
    }
    if (g->ctx) libusb_exit(g->ctx);
    g->ctx = NULL;
    g->claimed = 0;
}
