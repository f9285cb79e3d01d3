/* io_usb.c - USB discovery (io_dev.h): libusb listing with port paths and
 * serials, the same from a sysfs tree, the capture node of a USB camera
 * through sysfs, selectors that survive reboots and replugs, left/right
 * assignment and hotplug (libusb callbacks, or rescans). */
#include "io_dev.h"

#include <dirent.h>
#include <errno.h>
#include <libusb.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <time.h>

void io_usb_port_path(int bus, const uint8_t *ports, int depth, char *out, size_t n)
{
    if (depth <= 0) {
        snprintf(out, n, "usb%d", bus);
        return;
    }
    size_t l = (size_t)snprintf(out, n, "%d-", bus);
    for (int i = 0; i < depth && l < n; i++)
        l += (size_t)snprintf(out + l, n - l, "%s%u", i ? "." : "", (unsigned)ports[i]);
}

/* snprintf for paths; a path that does not fit is cut (and then not found). */
static void join(char *out, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void join(char *out, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(out, n, fmt, ap);
    va_end(ap);
}

static void copy_str(char *dst, size_t n, const char *src)
{
    size_t l = strlen(src);
    if (l >= n) l = n - 1;
    memcpy(dst, src, l);
    dst[l] = '\0';
}

/* Reads a one-line sysfs attribute without its newline; "" on failure. */
static int read_attr(const char *dir, const char *name, char *out, size_t n)
{
    char path[PATH_MAX];
    out[0] = '\0';
    if ((size_t)snprintf(path, sizeof path, "%s/%s", dir, name) >= sizeof path) return -1;
    FILE *fp = fopen(path, "r");
    if (!fp) return -1;
    if (!fgets(out, (int)n, fp)) out[0] = '\0';
    fclose(fp);
    size_t l = strlen(out);
    while (l && (out[l - 1] == '\n' || out[l - 1] == '\r' || out[l - 1] == ' ')) out[--l] = '\0';
    return 0;
}

/* "1-2.3" (a device, not an interface "1-2.3:1.0" nor a root hub "usb1"). */
static int is_device_name(const char *s)
{
    const char *p = s;
    if (*p < '0' || *p > '9') return 0;
    while (*p >= '0' && *p <= '9') p++;
    if (*p++ != '-') return 0;
    if (*p < '0' || *p > '9') return 0;
    for (; *p; p++)
        if (!((*p >= '0' && *p <= '9') || *p == '.')) return 0;
    return p[-1] != '.';
}

static int parse_port_path(const char *s, io_usb_dev *d)
{
    char *end;
    long bus = strtol(s, &end, 10);
    if (*end != '-') return -1;
    d->bus = (int)bus;
    d->depth = 0;
    const char *p = end + 1;
    while (*p && d->depth < IO_USB_MAX_PORTS) {
        long v = strtol(p, &end, 10);
        if (end == p || v < 0 || v > 255) return -1;
        d->ports[d->depth++] = (uint8_t)v;
        p = *end == '.' ? end + 1 : end;
        if (*end && *end != '.') return -1;
    }
    copy_str(d->port_path, sizeof d->port_path, s);
    return 0;
}

static int cmp_dev(const void *a, const void *b)
{
    const io_usb_dev *x = a, *y = b;
    if (x->bus != y->bus) return x->bus - y->bus;
    for (int i = 0; i < x->depth && i < y->depth; i++)
        if (x->ports[i] != y->ports[i]) return (int)x->ports[i] - (int)y->ports[i];
    return x->depth - y->depth;
}

/* Interface classes from the sysfs interface folders "port:C.I". */
static int sysfs_has_video(const char *devdir, const char *name)
{
    DIR *d = opendir(devdir);
    if (!d) return 0;
    struct dirent *e;
    int video = 0;
    size_t nl = strlen(name);
    char sub[PATH_MAX], cls[16];
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, name, nl) || e->d_name[nl] != ':') continue;
        if ((size_t)snprintf(sub, sizeof sub, "%s/%s", devdir, e->d_name) >= sizeof sub) continue;
        if (read_attr(sub, "bInterfaceClass", cls, sizeof cls) == 0 && strtol(cls, NULL, 16) == 0x0e)
            video = 1;
    }
    closedir(d);
    return video;
}

static void classify(io_usb_dev *d, int video)
{
    if (d->vid == IO_GLOVE_VID) d->kind = IO_USB_KIND_GLOVE;
    else if (video || d->usb_class == 0x0e) d->kind = IO_USB_KIND_CAMERA;
    else d->kind = IO_USB_KIND_OTHER;
}

io_result io_usb_list_sysfs(const char *root, io_usb_dev *out, int cap, int *count, io_error *err)
{
    char dir[PATH_MAX], dev[PATH_MAX], v[IO_USB_STR_MAX];
    *count = 0;
    snprintf(dir, sizeof dir, "%s/bus/usb/devices", root);
    DIR *d = opendir(dir);
    if (!d)
        return io_fail(err, IO_ERR_NOT_FOUND, "%s: cannot list USB devices: %s", dir, strerror(errno));
    struct dirent *e;
    int n = 0;
    while ((e = readdir(d)) != NULL) {
        if (!is_device_name(e->d_name)) continue;
        if (n < cap) {
            io_usb_dev *u = &out[n];
            memset(u, 0, sizeof *u);
            if (parse_port_path(e->d_name, u) != 0) continue;
            join(dev, sizeof dev, "%s/%s", dir, e->d_name);
            read_attr(dev, "idVendor", v, sizeof v);
            u->vid = (uint16_t)strtol(v, NULL, 16);
            read_attr(dev, "idProduct", v, sizeof v);
            u->pid = (uint16_t)strtol(v, NULL, 16);
            read_attr(dev, "bDeviceClass", v, sizeof v);
            u->usb_class = (int)strtol(v, NULL, 16);
            read_attr(dev, "devnum", v, sizeof v);
            u->address = atoi(v);
            read_attr(dev, "serial", u->serial, sizeof u->serial);
            read_attr(dev, "manufacturer", u->manufacturer, sizeof u->manufacturer);
            read_attr(dev, "product", u->product, sizeof u->product);
            classify(u, sysfs_has_video(dir, e->d_name));
            if (u->kind == IO_USB_KIND_CAMERA)
                io_usb_video_node(root, u->port_path, u->video, sizeof u->video, NULL);
        }
        n++;
    }
    closedir(d);
    qsort(out, (size_t)(n < cap ? n : cap), sizeof *out, cmp_dev);
    *count = n;
    return IO_OK;
}

io_result io_usb_video_node(const char *root, const char *port_path, char *out, size_t n,
                            io_error *err)
{
    char dir[PATH_MAX], link[PATH_MAX], real[PATH_MAX], idx[16];
    snprintf(dir, sizeof dir, "%s/class/video4linux", root);
    if (n) out[0] = '\0';
    DIR *d = opendir(dir);
    if (!d)
        return io_fail(err, IO_ERR_NOT_FOUND, "%s: no video4linux devices (%s)", dir, strerror(errno));
    struct dirent *e;
    int best_idx = INT_MAX, best_num = INT_MAX;
    size_t pl = strlen(port_path);
    while ((e = readdir(d)) != NULL) {
        if (strncmp(e->d_name, "video", 5)) continue;
        char *end;
        long num = strtol(e->d_name + 5, &end, 10);
        if (end == e->d_name + 5 || *end) continue;
        join(link, sizeof link, "%s/%s/device", dir, e->d_name);
        if (!realpath(link, real)) continue;
        const char *base = strrchr(real, '/');
        base = base ? base + 1 : real;
        /* the device link points at the interface "1-2.3:1.0" */
        if (strncmp(base, port_path, pl) || base[pl] != ':') continue;
        join(link, sizeof link, "%s/%s", dir, e->d_name);
        int index = read_attr(link, "index", idx, sizeof idx) == 0 ? atoi(idx) : 0;
        if (index < best_idx || (index == best_idx && num < best_num)) {
            best_idx = index;
            best_num = (int)num;
        }
    }
    closedir(d);
    if (best_num == INT_MAX)
        return io_fail(err, IO_ERR_NOT_FOUND, "USB device %s has no video node under %s", port_path,
                       dir);
    snprintf(out, n, "/dev/video%d", best_num);
    return IO_OK;
}

/* ------------------------------------------------------------ libusb list */

static void usb_strings(libusb_device *dev, const struct libusb_device_descriptor *dd, io_usb_dev *u)
{
    libusb_device_handle *h = NULL;
    if (libusb_open(dev, &h) == 0) {
        unsigned char s[IO_USB_STR_MAX];
        if (dd->iSerialNumber &&
            libusb_get_string_descriptor_ascii(h, dd->iSerialNumber, s, sizeof s) > 0)
            copy_str(u->serial, sizeof u->serial, (const char *)s);
        if (dd->iManufacturer &&
            libusb_get_string_descriptor_ascii(h, dd->iManufacturer, s, sizeof s) > 0)
            copy_str(u->manufacturer, sizeof u->manufacturer, (const char *)s);
        if (dd->iProduct && libusb_get_string_descriptor_ascii(h, dd->iProduct, s, sizeof s) > 0)
            copy_str(u->product, sizeof u->product, (const char *)s);
        libusb_close(h);
        return;
    }
    /* no permission: sysfs has the same strings */
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "/sys/bus/usb/devices/%s", u->port_path);
    read_attr(dir, "serial", u->serial, sizeof u->serial);
    read_attr(dir, "manufacturer", u->manufacturer, sizeof u->manufacturer);
    read_attr(dir, "product", u->product, sizeof u->product);
}

static int has_video_iface(libusb_device *dev)
{
    struct libusb_config_descriptor *cfg;
    if (libusb_get_active_config_descriptor(dev, &cfg) != 0 &&
        libusb_get_config_descriptor(dev, 0, &cfg) != 0)
        return 0;
    int video = 0;
    for (int i = 0; i < cfg->bNumInterfaces; i++)
        for (int a = 0; a < cfg->interface[i].num_altsetting; a++)
            if (cfg->interface[i].altsetting[a].bInterfaceClass == LIBUSB_CLASS_VIDEO) video = 1;
    libusb_free_config_descriptor(cfg);
    return video;
}

static io_result list_ctx(libusb_context *ctx, io_usb_dev *out, int cap, int *count, int strings,
                          io_error *err)
{
    libusb_device **list;
    ssize_t nd = libusb_get_device_list(ctx, &list);
    *count = 0;
    if (nd < 0)
        return io_fail(err, IO_ERR_DEVICE, "USB: cannot list devices: %s", libusb_strerror((int)nd));
    int n = 0;
    for (ssize_t i = 0; i < nd; i++) {
        libusb_device *dev = list[i];
        uint8_t ports[IO_USB_MAX_PORTS];
        int depth = libusb_get_port_numbers(dev, ports, IO_USB_MAX_PORTS);
        if (depth <= 0) continue; /* root hubs */
        if (n < cap) {
            io_usb_dev *u = &out[n];
            struct libusb_device_descriptor dd;
            memset(u, 0, sizeof *u);
            u->bus = libusb_get_bus_number(dev);
            u->address = libusb_get_device_address(dev);
            u->depth = depth;
            memcpy(u->ports, ports, (size_t)depth);
            io_usb_port_path(u->bus, ports, depth, u->port_path, sizeof u->port_path);
            if (libusb_get_device_descriptor(dev, &dd) == 0) {
                u->vid = dd.idVendor;
                u->pid = dd.idProduct;
                u->usb_class = dd.bDeviceClass;
                if (strings) usb_strings(dev, &dd, u);
            }
            classify(u, has_video_iface(dev));
            if (u->kind == IO_USB_KIND_CAMERA)
                io_usb_video_node("/sys", u->port_path, u->video, sizeof u->video, NULL);
        }
        n++;
    }
    libusb_free_device_list(list, 1);
    qsort(out, (size_t)(n < cap ? n : cap), sizeof *out, cmp_dev);
    *count = n;
    return IO_OK;
}

io_result io_usb_list(io_usb_dev *out, int cap, int *count, io_error *err)
{
    libusb_context *ctx = NULL;
    *count = 0;
    int r = libusb_init(&ctx);
    if (r != 0)
        return io_fail(err, IO_ERR_DEVICE, "USB: libusb cannot start: %s (no USB host or no "
                       "/dev/bus/usb?)", libusb_strerror(r));
    io_result res = list_ctx(ctx, out, cap, count, 1, err);
    libusb_exit(ctx);
    return res;
}

/* -------------------------------------------------------------- selectors */

io_result io_usb_selector_check(const char *sel, io_error *err)
{
    if (!sel || !*sel) return io_fail(err, IO_ERR_ARGS, "empty device selector");
    if (!strncmp(sel, "serial:", 7)) {
        if (!sel[7]) return io_fail(err, IO_ERR_ARGS, "selector '%s': no serial number", sel);
        return IO_OK;
    }
    if (!strncmp(sel, "port:", 5)) {
        io_usb_dev d;
        if (!is_device_name(sel + 5) || parse_port_path(sel + 5, &d) != 0)
            return io_fail(err, IO_ERR_ARGS, "selector '%s': the port path must look like 1-2.3",
                           sel);
        return IO_OK;
    }
    if (!strncmp(sel, "id:", 3)) {
        unsigned v, p;
        char tail;
        if (sscanf(sel + 3, "%4x:%4x%c", &v, &p, &tail) != 2)
            return io_fail(err, IO_ERR_ARGS, "selector '%s': expected id:VVVV:PPPP (hex)", sel);
        return IO_OK;
    }
    if (!strncmp(sel, "/dev/", 5)) return IO_OK;
    return io_fail(err, IO_ERR_ARGS, "selector '%s': use serial:SN, port:1-2.3, id:VVVV:PPPP "
                   "or /dev/videoN", sel);
}

int io_usb_match(const io_usb_dev *d, const char *sel)
{
    if (!d || io_usb_selector_check(sel, NULL) != IO_OK) return 0;
    if (!strncmp(sel, "serial:", 7)) return d->serial[0] && !strcmp(d->serial, sel + 7);
    if (!strncmp(sel, "port:", 5)) return !strcmp(d->port_path, sel + 5);
    if (!strncmp(sel, "id:", 3)) {
        unsigned v = 0, p = 0;
        sscanf(sel + 3, "%4x:%4x", &v, &p);
        return d->vid == v && d->pid == p;
    }
    return d->video[0] && !strcmp(d->video, sel);
}

io_result io_usb_assign(const io_usb_dev *devs, int n, const char *sel_l, const char *sel_r,
                        int *left, int *right, io_error *err)
{
    const char *sel[2] = {sel_l, sel_r};
    static const char *const eye[2] = {"left", "right"};
    int pick[2] = {-1, -1};
    *left = *right = -1;
    if (!sel_l != !sel_r)
        return io_fail(err, IO_ERR_ARGS, "cameras: give selectors for both eyes or for neither");
    if (!sel_l) {
        int k = 0;
        for (int i = 0; i < n && k < 2; i++)
            if (devs[i].kind == IO_USB_KIND_CAMERA) pick[k++] = i;
        if (k < 2)
            return io_fail(err, IO_ERR_NOT_FOUND, "cameras: %d USB camera%s found, 2 needed", k,
                           k == 1 ? "" : "s");
    } else {
        for (int e = 0; e < 2; e++) {
            io_result r = io_usb_selector_check(sel[e], err);
            if (r != IO_OK) return r;
            int hits = 0;
            for (int i = 0; i < n; i++)
                if (io_usb_match(&devs[i], sel[e])) {
                    if (!hits) pick[e] = i;
                    hits++;
                }
            if (!hits)
                return io_fail(err, IO_ERR_NOT_FOUND, "%s camera: no USB device matches '%s' "
                               "(%d devices seen; 'egofuse devices' lists them)", eye[e], sel[e], n);
            if (hits > 1 && strncmp(sel[e], "id:", 3))
                return io_fail(err, IO_ERR_VALUE, "%s camera: %d devices match '%s' (the first at port "
                               "%s); use serial: or port:", eye[e], hits, sel[e],
                               devs[pick[e]].port_path);
        }
        if (pick[0] == pick[1])
            return io_fail(err, IO_ERR_VALUE, "cameras: '%s' and '%s' both name the device at "
                           "port %s", sel_l, sel_r, devs[pick[0]].port_path);
    }
    *left = pick[0];
    *right = pick[1];
    return IO_OK;
}

static int same_dev(const io_usb_dev *a, const io_usb_dev *b)
{
    return !strcmp(a->port_path, b->port_path) && a->vid == b->vid && a->pid == b->pid &&
           !strcmp(a->serial, b->serial);
}

void io_usb_diff(const io_usb_dev *before, int nb, const io_usb_dev *now, int nn, int *added,
                 int *nadded, int *removed, int *nremoved)
{
    *nadded = *nremoved = 0;
    for (int i = 0; i < nn; i++) {
        int found = 0;
        for (int j = 0; j < nb && !found; j++) found = same_dev(&now[i], &before[j]);
        if (!found) added[(*nadded)++] = i;
    }
    for (int j = 0; j < nb; j++) {
        int found = 0;
        for (int i = 0; i < nn && !found; i++) found = same_dev(&now[i], &before[j]);
        if (!found) removed[(*nremoved)++] = j;
    }
}

/* ---------------------------------------------------------------- hotplug */

static int LIBUSB_CALL hotplug_cb(libusb_context *ctx, libusb_device *dev,
                                  libusb_hotplug_event ev, void *user)
{
    (void)ctx;
    (void)dev;
    io_usb_watch *w = user;
    if (ev == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) w->arrived++;
    else w->left++;
    w->events++;
    return 0;
}

io_result io_usb_watch_open(io_usb_watch *w, io_error *err)
{
    memset(w, 0, sizeof *w);
    libusb_context *ctx = NULL;
    int r = libusb_init(&ctx);
    if (r != 0)
        return io_fail(err, IO_ERR_DEVICE, "USB: libusb cannot start: %s", libusb_strerror(r));
    w->ctx = ctx;
    if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) {
        libusb_hotplug_callback_handle h;
        if (libusb_hotplug_register_callback(ctx, LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                                      LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT,
                                             0, LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
                                             LIBUSB_HOTPLUG_MATCH_ANY, hotplug_cb, w, &h) == 0) {
            w->hotplug = 1;
            w->handle = h;
        }
    }
    int n = 0;
    io_usb_list_sysfs("/sys", w->last, 32, &n, NULL);
    w->nlast = n < 32 ? n : 32;
    return IO_OK;
}

io_result io_usb_watch_poll(io_usb_watch *w, int timeout_ms, int *changed, io_error *err)
{
    *changed = 0;
    if (!w->ctx) return io_fail(err, IO_ERR_ARGS, "USB watch is not open");
    libusb_context *ctx = w->ctx;
    struct timeval tv = {timeout_ms / 1000, (timeout_ms % 1000) * 1000};
    if (w->hotplug) {
        int r = libusb_handle_events_timeout_completed(ctx, &tv, NULL);
        if (r != 0 && r != LIBUSB_ERROR_INTERRUPTED && r != LIBUSB_ERROR_TIMEOUT)
            return io_fail(err, IO_ERR_DEVICE, "USB watch: %s", libusb_strerror(r));
    } else if (timeout_ms > 0) {
        struct timespec ts = {tv.tv_sec, tv.tv_usec * 1000};
        nanosleep(&ts, NULL);
    }
    /* a rescan also catches what the events may miss (no udev daemon) */
    io_usb_dev now[32];
    int n = 0, add[32], rem[32], na, nr;
    io_result res = io_usb_list_sysfs("/sys", now, 32, &n, err);
    if (res != IO_OK) return res;
    if (n > 32) n = 32;
    io_usb_diff(w->last, w->nlast, now, n, add, &na, rem, &nr);
    if (w->events) {
        w->by_event = 1;
    } else if (na || nr) {
        w->by_event = 0;
        w->arrived += na;
        w->left += nr;
    }
    if (na || nr || w->events) *changed = 1;
    w->events = 0;
    memcpy(w->last, now, sizeof(io_usb_dev) * (size_t)n);
    w->nlast = n;
    return IO_OK;
}

void io_usb_watch_close(io_usb_watch *w)
{
    if (!w || !w->ctx) return;
    if (w->hotplug) libusb_hotplug_deregister_callback(w->ctx, w->handle);
    libusb_exit(w->ctx);
    w->ctx = NULL;
}
