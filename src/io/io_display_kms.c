/* io_display_kms.c - the KMS display backend (io_display.h) on libdrm's
 * legacy mode-setting calls: one or two connectors, each on its own CRTC,
 * 2 or 3 XRGB8888 dumb buffers per CRTC, drmModeSetCrtc at open (black),
 * then drmModePageFlip with DRM_MODE_PAGE_FLIP_EVENT per frame; events
 * through drmHandleEvent (page_flip_handler2: the CRTC of each event).
 * The CRTC state found at open (drmModeGetCrtc) is set again on close. */
#include "io_display_impl.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <drm_fourcc.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#define KMS_MAX_BUF 3

typedef struct kms_buf {
    uint32_t handle, fb_id, pitch;
    uint64_t size;
    uint8_t *map;
} kms_buf;

struct kms;

typedef struct kms_out {
    struct kms *k;
    uint32_t conn_id, crtc_id;
    char name[40];
    drmModeModeInfo mode;
    drmModeCrtc *saved;          /* the state to restore */
    kms_buf buf[KMS_MAX_BUF];
    int nbuf;
    int front;                   /* buffer on screen */
    int pending;                 /* buffer of the flip in flight, -1 none */
    int set;                     /* our mode is set: restore on close */
    int eye0, eyes;              /* eyes shown: sbs 0,2; two i,1 */
} kms_out;

typedef struct kms {
    int fd;
    char path[256];
    int mono;                    /* DRM_CAP_TIMESTAMP_MONOTONIC */
    int master;
    int nout;
    kms_out out[2];
    io_display *d;
    /* the frame in flight */
    uint64_t frame_id;
    int flips_left;
    uint64_t frame_t;
    uint32_t frame_seq;
} kms;

/* ------------------------------------------------------------ helpers */

static void conn_name(const drmModeConnector *c, char *out, size_t n)
{
    const char *t = drmModeGetConnectorTypeName(c->connector_type);
    snprintf(out, n, "%s-%u", t ? t : "Unknown", c->connector_type_id);
}

static int mode_hz(const drmModeModeInfo *m)
{
    if (m->vrefresh) return (int)m->vrefresh;
    if (!m->htotal || !m->vtotal) return 0;
    return (int)((m->clock * 1000ull + (uint64_t)m->htotal * m->vtotal / 2) /
                 ((uint64_t)m->htotal * m->vtotal));
}

static uint64_t mode_period_ns(const drmModeModeInfo *m)
{
    if (!m->clock || !m->htotal || !m->vtotal) {
        int hz = mode_hz(m);
        return hz ? 1000000000ull / (uint64_t)hz : 0;
    }
    uint64_t lines = m->vtotal;
    if (m->flags & DRM_MODE_FLAG_INTERLACE) lines /= 2;
    if (m->flags & DRM_MODE_FLAG_DBLSCAN) lines *= 2;
    if (m->vscan > 1) lines *= m->vscan;
    /* clock in kHz: pixels * 1e6 / clock ns */
    return ((uint64_t)m->htotal * lines * 1000000ull + m->clock / 2) / m->clock;
}

/* "1024x768@60 800x600@60 ..." (unique, at most ~30) */
static void list_modes(const drmModeConnector *c, char *out, size_t n)
{
    size_t len = 0;
    out[0] = '\0';
    int shown = 0;
    for (int i = 0; i < c->count_modes; i++) {
        const drmModeModeInfo *m = &c->modes[i];
        int dup = 0;
        for (int j = 0; j < i && !dup; j++)
            dup = c->modes[j].hdisplay == m->hdisplay && c->modes[j].vdisplay == m->vdisplay &&
                  mode_hz(&c->modes[j]) == mode_hz(m);
        if (dup) continue;
        if (shown == 30) {
            snprintf(out + len, n - len, " ...");
            return;
        }
        int w = snprintf(out + len, n - len, "%s%dx%d@%d", shown ? " " : "", m->hdisplay, m->vdisplay,
                         mode_hz(m));
        if (w < 0 || (size_t)w >= n - len) return;
        len += (size_t)w;
        shown++;
    }
    if (!shown) snprintf(out, n, "(none)");
}

/* The mode for connector c that shows need_w x need_h: the asked one
 * (w, h, hz; w = 0: automatic), else the preferred one if it fits, else
 * the smallest that fits, then the highest refresh. -1 when none. */
static int pick_mode(const drmModeConnector *c, int need_w, int need_h, int w, int h, int hz)
{
    int best = -1;
    for (int i = 0; i < c->count_modes; i++) {
        const drmModeModeInfo *m = &c->modes[i];
        if (w) {
            if (m->hdisplay == w && m->vdisplay == h && (!hz || mode_hz(m) == hz)) {
                if (best < 0 || mode_hz(m) > mode_hz(&c->modes[best])) best = i;
            }
            continue;
        }
        if (m->hdisplay < need_w || m->vdisplay < need_h) continue;
        if (m->type & DRM_MODE_TYPE_PREFERRED) return i;
        if (best < 0) {
            best = i;
            continue;
        }
        const drmModeModeInfo *b = &c->modes[best];
        long area = (long)m->hdisplay * m->vdisplay, barea = (long)b->hdisplay * b->vdisplay;
        if (area < barea || (area == barea && mode_hz(m) > mode_hz(b))) best = i;
    }
    return best;
}

static int fits(const drmModeConnector *c, int need_w, int need_h)
{
    return pick_mode(c, need_w, need_h, 0, 0, 0) >= 0;
}

/* ------------------------------------------------------------ buffers */

static void buf_destroy(kms *k, kms_buf *b)
{
    if (b->map) munmap(b->map, b->size);
    if (b->fb_id) drmModeRmFB(k->fd, b->fb_id);
    if (b->handle) {
        struct drm_mode_destroy_dumb dd = {0};
        dd.handle = b->handle;
        drmIoctl(k->fd, DRM_IOCTL_MODE_DESTROY_DUMB, &dd);
    }
    memset(b, 0, sizeof *b);
}

static io_result buf_create(kms *k, kms_out *o, kms_buf *b, io_error *err)
{
    struct drm_mode_create_dumb cd = {0};
    cd.width = o->mode.hdisplay;
    cd.height = o->mode.vdisplay;
    cd.bpp = 32;
    if (drmIoctl(k->fd, DRM_IOCTL_MODE_CREATE_DUMB, &cd) != 0)
        return io_fail(err, IO_ERR_DEVICE, "%s: %s: cannot create a %ux%u dumb buffer: %s", k->path, o->name,
                       cd.width, cd.height, strerror(errno));
    b->handle = cd.handle;
    b->pitch = cd.pitch;
    b->size = cd.size;
    uint32_t handles[4] = {cd.handle}, pitches[4] = {cd.pitch}, offsets[4] = {0};
    if (drmModeAddFB2(k->fd, cd.width, cd.height, DRM_FORMAT_XRGB8888, handles, pitches, offsets, &b->fb_id,
                      0) != 0) {
        int e = errno;
        b->fb_id = 0;
        if (drmModeAddFB(k->fd, cd.width, cd.height, 24, 32, cd.pitch, cd.handle, &b->fb_id) != 0) {
            b->fb_id = 0;
            return io_fail(err, IO_ERR_DEVICE, "%s: %s: cannot add an XRGB8888 framebuffer: %s", k->path,
                           o->name, strerror(e));
        }
    }
    struct drm_mode_map_dumb md = {0};
    md.handle = cd.handle;
    if (drmIoctl(k->fd, DRM_IOCTL_MODE_MAP_DUMB, &md) != 0)
        return io_fail(err, IO_ERR_DEVICE, "%s: %s: cannot map a dumb buffer: %s", k->path, o->name,
                       strerror(errno));
    void *p = mmap(NULL, cd.size, PROT_READ | PROT_WRITE, MAP_SHARED, k->fd, (off_t)md.offset);
    if (p == MAP_FAILED)
        return io_fail(err, IO_ERR_DEVICE, "%s: %s: mmap of a dumb buffer: %s", k->path, o->name,
                       strerror(errno));
    b->map = p;
    memset(b->map, 0, cd.size);                 /* black */
    return IO_OK;
}

/* ------------------------------------------------------------- events */

static uint64_t event_ns(const kms *k, unsigned sec, unsigned usec)
{
    uint64_t t = (uint64_t)sec * 1000000000ull + (uint64_t)usec * 1000ull;
    if (k->mono) return t;
    /* CLOCK_REALTIME stamps (old kernels): move them to CLOCK_MONOTONIC */
    struct timespec r, m;
    clock_gettime(CLOCK_REALTIME, &r);
    clock_gettime(CLOCK_MONOTONIC, &m);
    int64_t off = ((int64_t)m.tv_sec - (int64_t)r.tv_sec) * 1000000000ll + (m.tv_nsec - r.tv_nsec);
    return (uint64_t)((int64_t)t + off);
}

static void on_flip(kms *k, kms_out *o, unsigned seq, unsigned sec, unsigned usec)
{
    if (!o || o->pending < 0) return;
    o->front = o->pending;
    o->pending = -1;
    uint64_t t = event_ns(k, sec, usec);
    if (t > k->frame_t) k->frame_t = t;
    if (o == &k->out[0]) k->frame_seq = seq;
    if (k->flips_left > 0 && --k->flips_left == 0)
        io_display_push_flip(k->d, k->frame_id, k->frame_t, k->frame_seq);
}

#if defined(DRM_EVENT_CONTEXT_VERSION) && DRM_EVENT_CONTEXT_VERSION >= 3
static void flip_handler2(int fd, unsigned seq, unsigned sec, unsigned usec, unsigned crtc_id, void *data)
{
    (void)fd;
    kms_out *o = data;
    kms *k = o->k;
    /* the CRTC names the output; user data is the fallback */
    for (int i = 0; i < k->nout; i++)
        if (k->out[i].crtc_id == crtc_id) o = &k->out[i];
    on_flip(k, o, seq, sec, usec);
}
#else
static void flip_handler(int fd, unsigned seq, unsigned sec, unsigned usec, void *data)
{
    (void)fd;
    kms_out *o = data;
    on_flip(o->k, o, seq, sec, usec);
}
#endif

static int any_pending(const kms *k)
{
    for (int i = 0; i < k->nout; i++)
        if (k->out[i].pending >= 0) return 1;
    return 0;
}

/* Reads the events ready on the descriptor, waiting up to timeout_ms. */
static io_result kms_read_events(kms *k, int timeout_ms, io_error *err)
{
    struct pollfd pf = {k->fd, POLLIN, 0};
    int n = poll(&pf, 1, timeout_ms);
    if (n < 0) {
        if (errno == EINTR) return IO_OK;      /* Ctrl-C: let the caller see its flag */
        return io_fail(err, IO_ERR_DEVICE, "%s: poll: %s", k->path, strerror(errno));
    }
    if (n == 0) return IO_OK;
    if (pf.revents & (POLLERR | POLLHUP | POLLNVAL))
        return io_fail(err, IO_ERR_DEVICE, "%s: the device failed (poll revents 0x%x)", k->path, pf.revents);
    drmEventContext ev;
    memset(&ev, 0, sizeof ev);
#if defined(DRM_EVENT_CONTEXT_VERSION) && DRM_EVENT_CONTEXT_VERSION >= 3
    ev.version = 3;
    ev.page_flip_handler2 = flip_handler2;
#else
    ev.version = 2;
    ev.page_flip_handler = flip_handler;
#endif
    if (drmHandleEvent(k->fd, &ev) != 0)
        return io_fail(err, IO_ERR_DEVICE, "%s: reading DRM events: %s", k->path, strerror(errno));
    return IO_OK;
}

/* Waits until no flip is pending, at most timeout_ms in all. */
static io_result kms_drain(kms *k, int timeout_ms, io_error *err)
{
    uint64_t until = io_display_now_ns() + (uint64_t)timeout_ms * 1000000ull;
    while (any_pending(k)) {
        uint64_t now = io_display_now_ns();
        if (now >= until)
            return io_fail(err, IO_ERR_DEVICE, "%s: no flip event within %d ms", k->path, timeout_ms);
        io_result r = kms_read_events(k, (int)((until - now) / 1000000ull) + 1, err);
        if (r != IO_OK) return r;
    }
    return IO_OK;
}

/* ------------------------------------------------------------ backend */

static int kms_fd(const io_display *d) { return ((const kms *)d->be)->fd; }
static int kms_busy(const io_display *d) { return any_pending((const kms *)d->be); }

static io_result kms_wait(io_display *d, int timeout_ms, io_error *err)
{
    kms *k = d->be;
    if (!any_pending(k)) return IO_OK;          /* nothing can come */
    return kms_read_events(k, timeout_ms, err);
}

static io_result kms_present(io_display *d, const uint8_t *const rgba[2], const size_t stride[2],
                             uint64_t frame_id, io_error *err)
{
    kms *k = d->be;
    if (any_pending(k)) {                        /* one flip in flight per CRTC */
        io_result r = kms_drain(k, 1000, err);
        if (r != IO_OK) return r;
    }
    k->frame_id = frame_id;
    k->frame_t = 0;
    k->frame_seq = 0;
    k->flips_left = 0;
    for (int i = 0; i < k->nout; i++) {
        kms_out *o = &k->out[i];
        int back = (o->front + 1) % o->nbuf;
        kms_buf *b = &o->buf[back];
        int half = o->mode.hdisplay / o->eyes;
        for (int e = 0; e < o->eyes; e++) {
            int x0 = e * half + (half - d->eye_w) / 2, y0 = (o->mode.vdisplay - d->eye_h) / 2;
            io_display_blit_xrgb(b->map, b->pitch, x0, y0, rgba[o->eye0 + e], stride[o->eye0 + e], d->eye_w,
                                 d->eye_h);
        }
        if (drmModePageFlip(k->fd, o->crtc_id, b->fb_id, DRM_MODE_PAGE_FLIP_EVENT, o) != 0) {
            int e = errno;
            if (e == EACCES || e == EPERM)
                return io_fail(err, IO_ERR_DEVICE, "%s: %s: page flip refused: DRM master lost (a VT switch or "
                               "another program took the display)", k->path, o->name);
            return io_fail(err, IO_ERR_DEVICE, "%s: %s: page flip: %s", k->path, o->name, strerror(e));
        }
        o->pending = back;
        k->flips_left++;
    }
    return IO_OK;
}

static void kms_release(void *be)
{
    kms *k = be;
    io_error ignore;
    if (k->fd >= 0 && any_pending(k)) kms_drain(k, 200, &ignore);
    for (int i = 0; i < k->nout; i++) {
        kms_out *o = &k->out[i];
        if (o->set && k->fd >= 0) {
            drmModeCrtc *s = o->saved;
            int ok = -1;
            if (s && s->mode_valid && s->buffer_id)
                ok = drmModeSetCrtc(k->fd, s->crtc_id, s->buffer_id, s->x, s->y, &o->conn_id, 1, &s->mode);
            else if (s)     /* it was off: switch it off again */
                ok = drmModeSetCrtc(k->fd, s->crtc_id, 0, 0, 0, NULL, 0, NULL);
            (void)ok;       /* failing that, removing our buffers switches the CRTC off and the
                               kernel's console takes it back when the device is closed */
            o->set = 0;
        }
        for (int b = 0; b < KMS_MAX_BUF; b++)
            if (o->buf[b].handle || o->buf[b].map) buf_destroy(k, &o->buf[b]);
        if (o->saved) drmModeFreeCrtc(o->saved);
        o->saved = NULL;
    }
    if (k->fd >= 0) {
        if (k->master) drmDropMaster(k->fd);
        close(k->fd);
    }
    k->fd = -1;
}

static const io_display_ops kms_ops = {kms_present, kms_wait, kms_fd, kms_busy, kms_release};

/* ------------------------------------------------------------- opening */

static int name_matches(const char *want, const drmModeConnector *c, const char *name)
{
    char *end;
    unsigned long id = strtoul(want, &end, 10);
    if (*want && !*end) return id == c->connector_id;
    return !strcasecmp(want, name);
}

/* A CRTC for connector c not in taken[]; 0 when none. */
static uint32_t find_crtc(int fd, const drmModeRes *res, const drmModeConnector *c, const uint32_t *taken,
                          int ntaken)
{
    if (c->encoder_id) {
        drmModeEncoder *e = drmModeGetEncoder(fd, c->encoder_id);
        if (e) {
            uint32_t id = e->crtc_id;
            drmModeFreeEncoder(e);
            int used = 0;
            for (int t = 0; t < ntaken; t++) used |= taken[t] == id;
            if (id && !used) return id;
        }
    }
    for (int i = 0; i < c->count_encoders; i++) {
        drmModeEncoder *e = drmModeGetEncoder(fd, c->encoders[i]);
        if (!e) continue;
        uint32_t possible = e->possible_crtcs;
        drmModeFreeEncoder(e);
        for (int j = 0; j < res->count_crtcs && j < 32; j++) {
            if (!(possible & (1u << j))) continue;
            int used = 0;
            for (int t = 0; t < ntaken; t++) used |= taken[t] == res->crtcs[j];
            if (!used) return res->crtcs[j];
        }
    }
    return 0;
}

#define MAX_CONN 16

/* Opens one card; k->fd is -1 or open on return, the caller releases. */
static io_result open_card(kms *k, const char *path, const io_display_spec *s, int eye_w, int eye_h,
                           int buffers, io_error *err)
{
    snprintf(k->path, sizeof k->path, "%s", path);
    k->fd = open(path, O_RDWR | O_CLOEXEC);
    if (k->fd < 0) {
        int e = errno;
        if (e == ENOENT) return io_fail(err, IO_ERR_NOT_FOUND, "%s: no such device", path);
        if (e == EACCES) return io_fail(err, IO_ERR_DEVICE, "%s: permission denied (is the user in the "
                                        "'video' group?)", path);
        return io_fail(err, IO_ERR_DEVICE, "%s: cannot open: %s", path, strerror(e));
    }
    drmModeRes *res = drmModeGetResources(k->fd);
    if (!res) {
        int e = errno;
        return io_fail(err, IO_ERR_DEVICE, "%s: not a KMS display device (drmModeGetResources: %s)", path,
                       strerror(e));
    }
    io_result r = IO_OK;
    drmModeConnector *conn[MAX_CONN] = {0};
    char names[MAX_CONN][40];
    int nconn = res->count_connectors < MAX_CONN ? res->count_connectors : MAX_CONN;
    char all[1024] = "";
    size_t alen = 0;
    uint64_t cap = 0;
    if (drmGetCap(k->fd, DRM_CAP_DUMB_BUFFER, &cap) != 0 || !cap) {
        r = io_fail(err, IO_ERR_DEVICE, "%s: the driver has no dumb buffers", path);
        goto done;
    }
    cap = 0;
    k->mono = drmGetCap(k->fd, DRM_CAP_TIMESTAMP_MONOTONIC, &cap) == 0 && cap;
    if (drmSetMaster(k->fd) != 0) {
        int e = errno;
        r = io_fail(err, IO_ERR_DEVICE, "%s: another DRM master holds it (a desktop session?) "
                    "(drmSetMaster: %s)", path, strerror(e));
        goto done;
    }
    k->master = 1;
    for (int i = 0; i < nconn; i++) {
        conn[i] = drmModeGetConnector(k->fd, res->connectors[i]);
        if (!conn[i]) {
            snprintf(names[i], sizeof names[i], "connector %u", res->connectors[i]);
            continue;
        }
        conn_name(conn[i], names[i], sizeof names[i]);
        int w = snprintf(all + alen, sizeof all - alen, "%s%s (id %u, %s)", alen ? ", " : "", names[i],
                         conn[i]->connector_id,
                         conn[i]->connection == DRM_MODE_CONNECTED ? "connected" : "not connected");
        if (w > 0 && (size_t)w < sizeof all - alen) alen += (size_t)w;
    }
    if (!nconn) snprintf(all, sizeof all, "none");

    /* which connectors, which layout */
    int pick[2] = {-1, -1}, npick = 0;
    io_display_layout layout = s->layout;
    if (s->nconnectors) {
        for (int n = 0; n < s->nconnectors; n++) {
            for (int i = 0; i < nconn && pick[n] < 0; i++)
                if (conn[i] && name_matches(s->connector[n], conn[i], names[i])) pick[n] = i;
            if (pick[n] < 0) {
                r = io_fail(err, IO_ERR_NOT_FOUND, "%s: no connector '%s' (connectors: %s)", path,
                            s->connector[n], all);
                goto done;
            }
            if (conn[pick[n]]->connection != DRM_MODE_CONNECTED) {
                r = io_fail(err, IO_ERR_DEVICE, "%s: connector %s is not connected (connectors: %s)", path,
                            names[pick[n]], all);
                goto done;
            }
        }
        npick = s->nconnectors;
        if (npick == 2 && pick[0] == pick[1]) {
            r = io_fail(err, IO_ERR_ARGS, "%s: the same connector %s named for both eyes", path, names[pick[0]]);
            goto done;
        }
    } else {
        int connected[MAX_CONN], nc = 0;
        for (int i = 0; i < nconn; i++)
            if (conn[i] && conn[i]->connection == DRM_MODE_CONNECTED) connected[nc++] = i;
        if (!nc) {
            r = io_fail(err, IO_ERR_NOT_FOUND, "%s: no connected connector (connectors: %s)", path, all);
            goto done;
        }
        if (layout == IO_LAYOUT_AUTO) {
            if (s->mode_w || fits(conn[connected[0]], 2 * eye_w, eye_h) || nc < 2)
                layout = IO_LAYOUT_SBS;
            else if (fits(conn[connected[0]], eye_w, eye_h) && fits(conn[connected[1]], eye_w, eye_h))
                layout = IO_LAYOUT_TWO;
            else
                layout = IO_LAYOUT_SBS;          /* reported below as "no mode fits" */
        }
        if (layout == IO_LAYOUT_TWO && nc < 2) {
            r = io_fail(err, IO_ERR_NOT_FOUND, "%s: layout=two needs two connected connectors (connectors: %s)",
                        path, all);
            goto done;
        }
        npick = layout == IO_LAYOUT_TWO ? 2 : 1;
        for (int n = 0; n < npick; n++) pick[n] = connected[n];
    }
    if (layout == IO_LAYOUT_AUTO) layout = npick == 2 ? IO_LAYOUT_TWO : IO_LAYOUT_SBS;

    /* modes and CRTCs */
    uint32_t taken[2];
    int need_w = layout == IO_LAYOUT_SBS ? 2 * eye_w : eye_w;
    for (int n = 0; n < npick; n++) {
        drmModeConnector *c = conn[pick[n]];
        kms_out *o = &k->out[n];
        o->k = k;
        o->pending = -1;
        o->conn_id = c->connector_id;
        o->eye0 = layout == IO_LAYOUT_SBS ? 0 : n;
        o->eyes = layout == IO_LAYOUT_SBS ? 2 : 1;
        snprintf(o->name, sizeof o->name, "%s", names[pick[n]]);
        int m = pick_mode(c, need_w, eye_h, s->mode_w, s->mode_h, s->mode_hz);
        char modes[700];
        list_modes(c, modes, sizeof modes);
        if (m < 0 && s->mode_w) {
            char hz[16] = "";
            if (s->mode_hz) snprintf(hz, sizeof hz, "@%d", s->mode_hz);
            r = io_fail(err, IO_ERR_VALUE, "%s: %s: no mode %dx%d%s; modes: %s", path, o->name, s->mode_w,
                        s->mode_h, hz, modes);
            goto done;
        }
        if (m < 0) {
            r = io_fail(err, IO_ERR_VALUE, "%s: %s: no mode fits %dx%d; modes: %s", path, o->name, need_w, eye_h,
                        modes);
            goto done;
        }
        if (c->modes[m].hdisplay < need_w || c->modes[m].vdisplay < eye_h) {
            r = io_fail(err, IO_ERR_VALUE, "%s: %s: mode %dx%d is smaller than the %dx%d the eyes need "
                        "(no scaling)", path, o->name, c->modes[m].hdisplay, c->modes[m].vdisplay, need_w, eye_h);
            goto done;
        }
        o->mode = c->modes[m];
        o->crtc_id = find_crtc(k->fd, res, c, taken, n);
        if (!o->crtc_id) {
            r = io_fail(err, IO_ERR_DEVICE, "%s: %s: no free CRTC for it", path, o->name);
            goto done;
        }
        taken[n] = o->crtc_id;
        k->nout = n + 1;
        o->saved = drmModeGetCrtc(k->fd, o->crtc_id);
        o->nbuf = buffers;
        for (int b = 0; b < buffers; b++)
            if ((r = buf_create(k, o, &o->buf[b], err)) != IO_OK) goto done;
    }
    /* the mode, black, on every output */
    for (int n = 0; n < k->nout; n++) {
        kms_out *o = &k->out[n];
        if (drmModeSetCrtc(k->fd, o->crtc_id, o->buf[0].fb_id, 0, 0, &o->conn_id, 1, &o->mode) != 0) {
            int e = errno;
            if (e == EACCES || e == EPERM)
                r = io_fail(err, IO_ERR_DEVICE, "%s: another DRM master holds it (a desktop session?) "
                            "(drmModeSetCrtc: %s)", path, strerror(e));
            else
                r = io_fail(err, IO_ERR_DEVICE, "%s: %s: cannot set mode %dx%d@%d: %s", path, o->name,
                            o->mode.hdisplay, o->mode.vdisplay, mode_hz(&o->mode), strerror(e));
            goto done;
        }
        o->set = 1;
        o->front = 0;
    }
    {
        kms_out *o = &k->out[0];
        io_display *d = k->d;
        d->refresh_ns = mode_period_ns(&o->mode);
        if (layout == IO_LAYOUT_SBS) {
            d->out_w = o->mode.hdisplay;
            d->out_h = o->mode.vdisplay;
            snprintf(d->desc, sizeof d->desc, "kms %s %s %dx%d@%d sbs", path, o->name, o->mode.hdisplay,
                     o->mode.vdisplay, mode_hz(&o->mode));
        } else {
            kms_out *p = &k->out[1];
            d->out_w = o->mode.hdisplay + p->mode.hdisplay;
            d->out_h = o->mode.vdisplay > p->mode.vdisplay ? o->mode.vdisplay : p->mode.vdisplay;
            snprintf(d->desc, sizeof d->desc, "kms %s %s %dx%d@%d + %s %dx%d@%d two", path, o->name,
                     o->mode.hdisplay, o->mode.vdisplay, mode_hz(&o->mode), p->name, p->mode.hdisplay,
                     p->mode.vdisplay, mode_hz(&p->mode));
        }
    }
done:
    for (int i = 0; i < nconn; i++)
        if (conn[i]) drmModeFreeConnector(conn[i]);
    drmModeFreeResources(res);
    return r;
}

static int card_number(const char *name)
{
    if (strncmp(name, "card", 4) || !name[4]) return -1;
    for (const char *p = name + 4; *p; p++)
        if (!isdigit((unsigned char)*p)) return -1;
    return atoi(name + 4);
}

io_result io_display_kms_open(io_display *d, const io_display_spec *s, int buffers, io_error *err)
{
    kms *k = calloc(1, sizeof *k);
    if (!k) return io_fail(err, IO_ERR_NOMEM, "kms: out of memory");
    k->fd = -1;
    k->d = d;
    d->be = k;
    d->ops = &kms_ops;
    if (s->device[0]) {
        io_result r = open_card(k, s->device, s, d->eye_w, d->eye_h, buffers, err);
        if (r != IO_OK) {
            kms_release(k);
            free(k);
            d->be = NULL;
        }
        return r;
    }
    /* the first card, in number order, that gives a display */
    int nums[64], n = 0;
    DIR *dir = opendir("/dev/dri");
    if (dir) {
        struct dirent *e;
        while ((e = readdir(dir)) != NULL && n < 64) {
            int c = card_number(e->d_name);
            if (c >= 0) nums[n++] = c;
        }
        closedir(dir);
    }
    if (!n) {
        free(k);
        d->be = NULL;
        return io_fail(err, IO_ERR_NOT_FOUND, "kms: no /dev/dri/card* (no DRM driver loaded; on a desktop use "
                       "--display sdl; in qemu add -device bochs-display)");
    }
    for (int i = 1; i < n; i++)
        for (int j = i; j > 0 && nums[j - 1] > nums[j]; j--) {
            int t = nums[j];
            nums[j] = nums[j - 1];
            nums[j - 1] = t;
        }
    char msgs[1024] = "";
    size_t mlen = 0;
    io_result r = IO_ERR_NOT_FOUND;
    for (int i = 0; i < n; i++) {
        char path[64];
        snprintf(path, sizeof path, "/dev/dri/card%d", nums[i]);
        io_error e1;
        memset(k, 0, sizeof *k);
        k->fd = -1;
        k->d = d;
        r = open_card(k, path, s, d->eye_w, d->eye_h, buffers, &e1);
        if (r == IO_OK) return IO_OK;
        kms_release(k);
        int w = snprintf(msgs + mlen, sizeof msgs - mlen, "%s%s", mlen ? "; " : "", e1.msg);
        if (w > 0 && (size_t)w < sizeof msgs - mlen) mlen += (size_t)w;
    }
    free(k);
    d->be = NULL;
    return io_fail(err, r, "%s", msgs);
}
