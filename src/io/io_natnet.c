/* io_natnet.c - OptiTrack NatNet 3.x / 4.x client (io_natnet.h). Layout of
 * the messages as published with the NatNet SDK (documentation, the
 * PacketClient and Python client samples); every read is bounds-checked
 * against the datagram, every count against the bytes left. Behaviour and
 * configuration: docs/tracking.md, "OptiTrack NatNet".
 *
 * Why one file of this length: one job, one protocol client. The frame of
 * data, the model definitions and the server's answers are read with one
 * bounds-checked reader under one set of version rules (NatNet 3.x / 4.x
 * layouts), and the sockets, the command channel and the mapping of rigid
 * bodies and skeletons to names and tracking samples share the client's
 * state (io_natnet, io_natnet.h); nothing here is used without the rest.
 * Its configuration (keys and values, io_natnet_config_*) is parsed in
 * io_natnet_config.c. */
#include "io_natnet.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static double mono_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------- reader */

typedef struct rd {
    const uint8_t *p;
    size_t n, at, base;   /* base: offset of p in the datagram (messages) */
    int bad;
    char why[256];
} rd;

static void rd_fail(rd *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void rd_fail(rd *r, const char *fmt, ...)
{
    if (r->bad) return;
    r->bad = 1;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->why, sizeof r->why, fmt, ap);
    va_end(ap);
}

static int rd_need(rd *r, size_t k, const char *what)
{
    if (r->bad) return 0;
    if (r->n - r->at < k) {
        rd_fail(r, "%s: needs %zu bytes at offset %zu, only %zu left", what, k, r->base + r->at,
                r->n - r->at);
        return 0;
    }
    return 1;
}

static uint64_t rd_le(rd *r, int k, const char *what)
{
    if (!rd_need(r, (size_t)k, what)) return 0;
    uint64_t v = 0;
    for (int i = k - 1; i >= 0; i--) v = v << 8 | r->p[r->at + (size_t)i];
    r->at += (size_t)k;
    return v;
}
static int32_t rd_i32(rd *r, const char *what) { return (int32_t)(uint32_t)rd_le(r, 4, what); }
static uint32_t rd_u32(rd *r, const char *what) { return (uint32_t)rd_le(r, 4, what); }
static int16_t rd_i16(rd *r, const char *what) { return (int16_t)(uint16_t)rd_le(r, 2, what); }
static uint64_t rd_u64(rd *r, const char *what) { return rd_le(r, 8, what); }
static float rd_f32(rd *r, const char *what)
{
    uint32_t u = (uint32_t)rd_le(r, 4, what);
    float f;
    memcpy(&f, &u, 4);
    return f;
}
static double rd_f64(rd *r, const char *what)
{
    uint64_t u = rd_le(r, 8, what);
    double d;
    memcpy(&d, &u, 8);
    return d;
}
static void rd_skip(rd *r, size_t k, const char *what)
{
    if (rd_need(r, k, what)) r->at += k;
}
/* A NUL-terminated string, copied (cut) into out when out != NULL. */
static void rd_str(rd *r, char *out, size_t cap, const char *what)
{
    if (out && cap) out[0] = 0;
    if (r->bad) return;
    const uint8_t *s = r->p + r->at;
    const uint8_t *z = memchr(s, 0, r->n - r->at);
    if (!z) {
        rd_fail(r, "%s: string at offset %zu not terminated within the packet", what,
                r->base + r->at);
        return;
    }
    size_t len = (size_t)(z - s);
    if (out && cap) {
        size_t c = len < cap - 1 ? len : cap - 1;
        memcpy(out, s, c);
        out[c] = 0;
    }
    r->at += len + 1;
}
/* A count of items of at least min_bytes each: negative or more than the
 * bytes left can hold is an error. */
static int32_t rd_count(rd *r, size_t min_bytes, const char *what)
{
    int32_t c = rd_i32(r, what);
    if (r->bad) return 0;
    if (c < 0) {
        rd_fail(r, "%s: negative count %d", what, (int)c);
        return 0;
    }
    if (min_bytes && (uint64_t)c * min_bytes > r->n - r->at) {
        rd_fail(r, "%s: count %d needs at least %llu bytes, only %zu left in the packet", what,
                (int)c, (unsigned long long)((uint64_t)c * min_bytes), r->n - r->at);
        return 0;
    }
    return c;
}

static int ver_ge(int major, int minor, int a, int b)
{
    return major > a || (major == a && minor >= b);
}

/* NatNet 4.1+: a byte count after each section's count. Returns the
 * offset where the section must end, or 0 when there is none. */
static size_t section_size(rd *r, int major, int minor, const char *what)
{
    if (!ver_ge(major, minor, 4, 1)) return 0;
    int32_t sz = rd_i32(r, what);
    if (r->bad) return 0;
    if (sz < 0 || (size_t)sz > r->n - r->at) {
        rd_fail(r, "%s: byte count %d, only %zu bytes left", what, (int)sz, r->n - r->at);
        return 0;
    }
    return r->at + (size_t)sz;
}

/* The head of a section of the frame: its item count (each item at least
 * min_bytes), then (NatNet 4.1+) its byte count, *end where that ends it
 * (0: not given); the messages name "WHAT count" and "WHAT bytes". */
static int32_t section_begin(rd *r, int major, int minor, size_t min_bytes, const char *what,
                             size_t *end)
{
    char w[64];
    snprintf(w, sizeof w, "%s count", what);
    int32_t n = rd_count(r, min_bytes, w);
    snprintf(w, sizeof w, "%s bytes", what);
    *end = section_size(r, major, minor, w);
    return n;
}

static void section_end(rd *r, size_t end, const char *what)
{
    if (end && !r->bad && r->at != end)
        rd_fail(r, "%s: the byte count ends the section at offset %zu, its contents at %zu",
                what, r->base + end, r->base + r->at);
}

/* ------------------------------------------------------ frame of data */

#define RB_BYTES 38   /* id, pos, quat, mean error, params (NatNet 3+) */

static void parse_rb(rd *r, io_natnet_body_pose *b, int16_t *params)
{
    b->id = rd_i32(r, "rigid body id");
    b->pos.x = rd_f32(r, "rigid body x");
    b->pos.y = rd_f32(r, "rigid body y");
    b->pos.z = rd_f32(r, "rigid body z");
    b->rot.x = rd_f32(r, "rigid body qx");
    b->rot.y = rd_f32(r, "rigid body qy");
    b->rot.z = rd_f32(r, "rigid body qz");
    b->rot.w = rd_f32(r, "rigid body qw");
    b->mean_error = rd_f32(r, "rigid body mean error");
    *params = rd_i16(r, "rigid body params");
    b->valid = (*params & 1) != 0;
}

typedef struct frame_data {
    int32_t frame;
    double ts;
    uint64_t stamp[3];
    uint32_t prec_s, prec_frac, timecode, timecode_sub;
    int16_t params;
    int count;
} frame_data;

static int parse_frame(rd *r, int major, int minor, frame_data *f, io_natnet_body_pose *bodies,
                       int cap)
{
    memset(f, 0, sizeof *f);
    f->frame = rd_i32(r, "frame number");
    /* marker sets: name, count, xyz each */
    size_t end;
    int32_t n = section_begin(r, major, minor, 5, "marker set", &end);
    for (int32_t i = 0; i < n && !r->bad; i++) {
        rd_str(r, NULL, 0, "marker set name");
        int32_t m = rd_count(r, 12, "marker set marker count");
        rd_skip(r, (size_t)m * 12, "marker set markers");
    }
    section_end(r, end, "marker sets");
    /* legacy unlabeled ("other") markers */
    n = section_begin(r, major, minor, 12, "unlabeled marker", &end);
    rd_skip(r, (size_t)n * 12, "unlabeled markers");
    section_end(r, end, "unlabeled markers");
    /* rigid bodies */
    n = section_begin(r, major, minor, RB_BYTES, "rigid body", &end);
    for (int32_t i = 0; i < n && !r->bad; i++) {
        io_natnet_body_pose b;
        int16_t params;
        parse_rb(r, &b, &params);
        if (i < cap && bodies) bodies[i] = b;
    }
    f->count = n;
    section_end(r, end, "rigid bodies");
    /* skeletons: id, bone count, bones as rigid bodies */
    n = section_begin(r, major, minor, 8, "skeleton", &end);
    for (int32_t i = 0; i < n && !r->bad; i++) {
        rd_i32(r, "skeleton id");
        int32_t m = rd_count(r, RB_BYTES, "skeleton bone count");
        rd_skip(r, (size_t)m * RB_BYTES, "skeleton bones");
    }
    section_end(r, end, "skeletons");
    /* assets (NatNet 4.1+): id, rigid bodies, markers */
    if (ver_ge(major, minor, 4, 1)) {
        n = section_begin(r, major, minor, 12, "asset", &end);
        for (int32_t i = 0; i < n && !r->bad; i++) {
            rd_i32(r, "asset id");
            int32_t m = rd_count(r, RB_BYTES, "asset rigid body count");
            rd_skip(r, (size_t)m * RB_BYTES, "asset rigid bodies");
            m = rd_count(r, 26, "asset marker count");
            rd_skip(r, (size_t)m * 26, "asset markers");
        }
        section_end(r, end, "assets");
    }
    /* labeled markers: id, xyz, size, params, residual */
    n = section_begin(r, major, minor, 26, "labeled marker", &end);
    rd_skip(r, (size_t)n * 26, "labeled markers");
    section_end(r, end, "labeled markers");
    /* force plates and devices: id, channels of (frame count, floats) */
    for (int k = 0; k < 2; k++) {
        n = section_begin(r, major, minor, 8, k ? "device" : "force plate", &end);
        for (int32_t i = 0; i < n && !r->bad; i++) {
            rd_i32(r, k ? "device id" : "force plate id");
            int32_t ch = rd_count(r, 4, k ? "device channel count" : "force plate channel count");
            for (int32_t c = 0; c < ch && !r->bad; c++) {
                int32_t fr = rd_count(r, 4, k ? "device channel frame count"
                                              : "force plate channel frame count");
                rd_skip(r, (size_t)fr * 4, k ? "device samples" : "force plate samples");
            }
        }
        section_end(r, end, k ? "devices" : "force plates");
    }
    /* suffix */
    f->timecode = rd_u32(r, "timecode");
    f->timecode_sub = rd_u32(r, "timecode subframe");
    f->ts = rd_f64(r, "timestamp");
    for (int k = 0; k < 3; k++) f->stamp[k] = rd_u64(r, "high-resolution timestamps");
    if (ver_ge(major, minor, 4, 1)) {
        f->prec_s = rd_u32(r, "precision timestamp");
        f->prec_frac = rd_u32(r, "precision timestamp fraction");
    }
    f->params = rd_i16(r, "frame params");
    if (!r->bad && r->n - r->at >= 4) rd_i32(r, "end of data");
    if (!r->bad && !isfinite(f->ts)) rd_fail(r, "timestamp is not finite");
    return r->bad ? -1 : 0;
}

int io_natnet_parse_frame(const uint8_t *payload, size_t len, int major, int minor,
                          int32_t *frame, double *timestamp, io_natnet_body_pose *bodies,
                          int cap, int *count, char *why, size_t why_size)
{
    rd r = { payload, len, 0, 4, 0, "" };
    frame_data f;
    if (!payload || parse_frame(&r, major, minor, &f, bodies, cap) != 0) {
        if (why && why_size) snprintf(why, why_size, "%s", payload ? r.why : "no data");
        return -1;
    }
    if (frame) *frame = f.frame;
    if (timestamp) *timestamp = f.ts;
    if (count) *count = f.count;
    return 0;
}

/* ---------------------------------------------------- model definitions */

static void parse_rb_desc(rd *r, int major, int minor, io_natnet_desc *d)
{
    char name[IO_NATNET_NAME_MAX];
    rd_str(r, name, sizeof name, "rigid body name");
    int32_t id = rd_i32(r, "rigid body id");
    rd_i32(r, "rigid body parent id");
    rd_skip(r, 12, "rigid body offset");
    if (ver_ge(major, minor, 4, 2)) rd_skip(r, 16, "rigid body rotation");
    int32_t m = rd_count(r, 16, "rigid body marker count");
    rd_skip(r, (size_t)m * 16, "rigid body marker offsets and labels");
    if (major >= 4)
        for (int32_t i = 0; i < m && !r->bad; i++) rd_str(r, NULL, 0, "rigid body marker name");
    if (d) {
        d->id = id;
        snprintf(d->name, sizeof d->name, "%s", name);
    }
}

static void parse_names(rd *r, const char *what)
{
    int32_t c = rd_count(r, 1, what);
    for (int32_t i = 0; i < c && !r->bad; i++) rd_str(r, NULL, 0, what);
}

/* Fills desc[] with the rigid bodies (type 1). Returns 0 or -1. */
static int parse_modeldef(rd *r, int major, int minor, io_natnet_desc *desc, int cap, int *count)
{
    *count = 0;
    int32_t n = rd_count(r, 4, "dataset count");
    for (int32_t i = 0; i < n && !r->bad; i++) {
        int32_t type = rd_i32(r, "dataset type");
        size_t end = section_size(r, major, minor, "dataset bytes");
        switch (type) {
        case 0: /* marker set */
            rd_str(r, NULL, 0, "marker set name");
            parse_names(r, "marker set marker names");
            break;
        case 1: { /* rigid body */
            io_natnet_desc d;
            parse_rb_desc(r, major, minor, &d);
            if (!r->bad && *count < cap) desc[(*count)++] = d;
            break;
        }
        case 2: { /* skeleton */
            rd_str(r, NULL, 0, "skeleton name");
            rd_i32(r, "skeleton id");
            int32_t m = rd_count(r, 29, "skeleton bone count");
            for (int32_t k = 0; k < m && !r->bad; k++) parse_rb_desc(r, major, minor, NULL);
            break;
        }
        case 3: /* force plate */
            rd_i32(r, "force plate id");
            rd_str(r, NULL, 0, "force plate serial");
            rd_skip(r, 4 * (2 + 3 + 144 + 12), "force plate geometry");
            rd_i32(r, "force plate type");
            rd_i32(r, "force plate channel type");
            parse_names(r, "force plate channel names");
            break;
        case 4: /* device */
            rd_i32(r, "device id");
            rd_str(r, NULL, 0, "device name");
            rd_str(r, NULL, 0, "device serial");
            rd_i32(r, "device type");
            rd_i32(r, "device channel type");
            parse_names(r, "device channel names");
            break;
        case 5: /* camera */
            rd_str(r, NULL, 0, "camera name");
            rd_skip(r, 28, "camera pose");
            break;
        case 6: { /* asset */
            rd_str(r, NULL, 0, "asset name");
            rd_i32(r, "asset type");
            rd_i32(r, "asset id");
            int32_t m = rd_count(r, 29, "asset rigid body count");
            for (int32_t k = 0; k < m && !r->bad; k++) parse_rb_desc(r, major, minor, NULL);
            m = rd_count(r, 23, "asset marker count");
            for (int32_t k = 0; k < m && !r->bad; k++) {
                rd_str(r, NULL, 0, "asset marker name");
                rd_skip(r, 4 + 12 + 4 + 2, "asset marker");
            }
            break;
        }
        default:
            if (end) r->at = end;   /* 4.1+: sized, skip it */
            else rd_fail(r, "dataset %d: unknown description type %d (NatNet %d.%d has no size "
                         "to skip it)", (int)i, (int)type, major, minor);
        }
        section_end(r, end, "dataset");
    }
    return r->bad ? -1 : 0;
}

/* ------------------------------------------------------------ sockets */

static io_result resolve4(const char *host, uint32_t *addr, const char *what, io_error *err)
{
    const char *why;
    if (io_ipv4_resolve(host, addr, &why) != 0)
        return io_fail(err, IO_ERR_ARGS, "natnet %s '%s': not an IPv4 address or a known host "
                       "name (%s)", what, host, why);
    return IO_OK;
}

static int udp_socket(uint32_t addr, int port, int reuse, int *bound_port, io_error *err,
                      const char *what, const char *host)
{
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        io_fail(err, IO_ERR_DEVICE, "natnet %s socket: %s", what, strerror(errno));
        return -1;
    }
    int one = 1, big = 1 << 20;
    if (reuse) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
    struct sockaddr_in sa;
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons((uint16_t)port);
    sa.sin_addr.s_addr = addr;
    if (bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        int e = errno;
        close(fd);
        io_fail(err, IO_ERR_DEVICE, "natnet %s: bind %s:%d: %s", what, host, port, strerror(e));
        return -1;
    }
    socklen_t sl = sizeof sa;
    getsockname(fd, (struct sockaddr *)&sa, &sl);
    *bound_port = ntohs(sa.sin_port);
    return fd;
}

static void addr_str(const struct sockaddr_in *sa, char *buf, size_t n)
{
    char ip[INET_ADDRSTRLEN] = "?";
    inet_ntop(AF_INET, &sa->sin_addr, ip, sizeof ip);
    snprintf(buf, n, "%s:%d", ip, ntohs(sa->sin_port));
}

static void send_cmd(io_natnet *n, int id)
{
    uint8_t pk[4 + 271];
    size_t len = 4;
    if (id == IO_NATNET_CONNECT) {
        /* "Ping" in a 270-byte field, the NatNet version asked for at
         * 265..268 (zeros: the server's own), then a NUL */
        memset(pk + 4, 0, 271);
        memcpy(pk + 4, "Ping", 4);
        pk[4 + 265] = (uint8_t)n->cfg.version_major;
        pk[4 + 266] = (uint8_t)n->cfg.version_minor;
        len += 271;
    } else {
        pk[4] = 0;   /* empty string */
        len += 1;
    }
    size_t payload = len - 4;
    if (id == IO_NATNET_REQUEST_MODELDEF || id == IO_NATNET_KEEPALIVE) payload = 0;
    pk[0] = (uint8_t)id;
    pk[1] = (uint8_t)(id >> 8);
    pk[2] = (uint8_t)payload;
    pk[3] = (uint8_t)(payload >> 8);
    struct sockaddr_in sa;
    memset(&sa, 0, sizeof sa);
    sa.sin_family = AF_INET;
    sa.sin_port = htons((uint16_t)n->cfg.command_port);
    sa.sin_addr.s_addr = n->server_addr;
    if (sendto(n->fd, pk, len, 0, (struct sockaddr *)&sa, sizeof sa) >= 0) n->requests_sent++;
}

static void set_status(io_natnet *n, int is_error, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void set_status(io_natnet *n, int is_error, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(n->status, sizeof n->status, fmt, ap);
    va_end(ap);
    if (is_error) snprintf(n->last_error, sizeof n->last_error, "%s", n->status);
}

io_result io_natnet_open(io_natnet *n, const io_natnet_config *c, io_error *err)
{
    if (!n || !c) return io_fail(err, IO_ERR_ARGS, "io_natnet_open: NULL argument");
    memset(n, 0, sizeof *n);
    n->fd = n->data_fd = -1;
    n->cfg = *c;
    if (n->cfg.command_port <= 0 || n->cfg.command_port > 65535)
        return io_fail(err, IO_ERR_ARGS, "natnet: command port %d out of range", c->command_port);
    if (!(n->cfg.unit_scale > 0)) n->cfg.unit_scale = 1.0f;
    if (n->cfg.resend_ms <= 0) n->cfg.resend_ms = 1000;
    if (!(n->cfg.restart_s > 0)) n->cfg.restart_s = 1.0;
    for (int k = 0; k < IO_NATNET_POINTS; k++) n->resolved[k] = n->cfg.point[k].id;
    uint32_t local;
    io_result r = resolve4(c->local[0] ? c->local : "0.0.0.0", &local, "local", err);
    if (r != IO_OK) return r;
    if ((r = resolve4(c->server[0] ? c->server : "127.0.0.1", &n->server_addr, "server", err)) != IO_OK)
        return r;
    const char *lname = c->local[0] ? c->local : "0.0.0.0";
    if (c->multicast[0]) {
        struct in_addr grp;
        if (inet_pton(AF_INET, c->multicast, &grp) != 1 || (ntohl(grp.s_addr) >> 28) != 14)
            return io_fail(err, IO_ERR_ARGS, "natnet multicast '%s': not an IPv4 multicast group",
                           c->multicast);
        int port = c->data_port ? c->data_port : IO_NATNET_DATA_PORT;
        /* bound to the port on any address, so the group's datagrams arrive */
        n->data_fd = udp_socket(htonl(INADDR_ANY), port, 1, &n->data_port, err, "data", "0.0.0.0");
        if (n->data_fd < 0) return err ? err->code : IO_ERR_DEVICE;
        struct ip_mreq mr;
        mr.imr_multiaddr = grp;
        mr.imr_interface.s_addr = local;
        if (setsockopt(n->data_fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) != 0) {
            int e = errno;
            close(n->data_fd);
            n->data_fd = -1;
            return io_fail(err, IO_ERR_DEVICE, "natnet: joining multicast group %s on %s: %s",
                           c->multicast, lname, strerror(e));
        }
        n->fd = udp_socket(local, 0, 0, &n->local_port, err, "command", lname);
    } else {
        n->fd = udp_socket(local, c->data_port, 0, &n->local_port, err, "unicast", lname);
    }
    if (n->fd < 0) {
        if (n->data_fd >= 0) close(n->data_fd);
        n->data_fd = -1;
        return err ? err->code : IO_ERR_DEVICE;
    }
    n->version_major = c->version_major;
    n->version_minor = c->version_minor;
    n->last.head_rot = n->last.hand_rot[0] = n->last.hand_rot[1] = kin_quat_identity();
    double now = mono_now();
    n->t_open = n->t_connect_sent = n->t_model_sent = n->t_keepalive = now;
    send_cmd(n, IO_NATNET_CONNECT);
    send_cmd(n, IO_NATNET_REQUEST_MODELDEF);
    n->connects_sent = n->models_sent = 1;
    char sv[64];
    struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons((uint16_t)c->command_port),
                              .sin_addr = { n->server_addr } };
    addr_str(&sa, sv, sizeof sv);
    set_status(n, 0, "NAT_CONNECT sent to %s; %s on port %d; no answer yet", sv,
               c->multicast[0] ? "multicast" : "unicast",
               c->multicast[0] ? n->data_port : n->local_port);
    return IO_OK;
}

int io_natnet_fd(const io_natnet *n)
{
    if (!n) return -1;
    return n->data_fd >= 0 ? n->data_fd : n->fd;
}

/* --------------------------------------------------------------- names */

void io_natnet_list_bodies(const io_natnet *n, char *buf, size_t size)
{
    if (!buf || !size) return;
    buf[0] = 0;
    size_t at = 0;
    for (int i = 0; n && i < n->desc_count && at < size; i++) {
        int w = snprintf(buf + at, size - at, "%s%s (#%d)", i ? ", " : "", n->desc[i].name,
                         n->desc[i].id);
        if (w < 0) break;
        at += (size_t)w;
    }
    if (n && n->desc_count == 0) snprintf(buf, size, "no rigid bodies");
}

static int find_desc(const io_natnet *n, const char *name)
{
    for (int i = 0; i < n->desc_count; i++)
        if (!strcmp(n->desc[i].name, name)) return n->desc[i].id;
    return -1;
}

/* After new model definitions: ids of the points named; a message naming
 * the unknown ones. Returns the number of unknown names. */
static int resolve_names(io_natnet *n, char *why, size_t why_size)
{
    int missing = 0;
    size_t at = 0;
    if (why && why_size) why[0] = 0;
    for (int k = 0; k < IO_NATNET_POINTS; k++) {
        const io_natnet_map *m = &n->cfg.point[k];
        if (m->id >= 0 || !m->name[0]) continue;
        n->resolved[k] = find_desc(n, m->name);
        if (n->resolved[k] >= 0) continue;
        if (why && at < why_size) {
            int w = snprintf(why + at, why_size - at, "%s'%s' (%s)", missing ? ", " : "",
                             m->name, io_natnet_point_name(k));
            if (w > 0) at += (size_t)w;
        }
        missing++;
    }
    return missing;
}

/* ----------------------------------------------------------- the frame */

static void convert(const io_natnet *n, io_natnet_body_pose *b)
{
    float s = n->cfg.unit_scale;
    kin_vec3 p = kin_v3_scale(b->pos, s);
    kin_quat q = b->rot;
    if (n->cfg.z_up) {
        /* Z-up (x, y, z) -> Y-up (x, z, -y): a rotation by -90 deg about X;
         * a quaternion's vector part turns the same way */
        p = kin_v3(p.x, p.z, -p.y);
        q = (kin_quat){ q.x, q.z, -q.y, q.w };
    }
    float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (!(isfinite(p.x) && isfinite(p.y) && isfinite(p.z)) || !(fabsf(l - 1.0f) <= 1e-2f))
        b->valid = 0;   /* not a pose: treated as a dropout */
    else
        q = kin_quat_normalize(q);
    b->pos = p;
    b->rot = q;
    b->mean_error *= s;
}

static const io_natnet_body_pose *body_by_id(const io_natnet *n, int id)
{
    for (int i = 0; i < n->body_count; i++)
        if (n->body[i].id == id) return &n->body[i];
    return NULL;
}

static const uint32_t point_bit[IO_NATNET_POINTS] = {
    KIN_TRACK_HEAD, KIN_TRACK_SHOULDER_L, KIN_TRACK_SHOULDER_R, KIN_TRACK_HAND_L, KIN_TRACK_HAND_R
};

static void build_sample(io_natnet *n, double t)
{
    kin_track_sample s = n->last;
    s.t = t;
    s.valid &= (uint32_t)(KIN_TRACK_GLOVE_L | KIN_TRACK_GLOVE_R);
    for (int k = 0; k < IO_NATNET_POINTS; k++) {
        if (n->resolved[k] < 0) continue;
        const io_natnet_body_pose *b = body_by_id(n, n->resolved[k]);
        if (!b || !b->valid) {
            n->dropouts++;
            continue;
        }
        const io_natnet_map *m = &n->cfg.point[k];
        kin_vec3 p = kin_v3_add(b->pos, kin_quat_rotate(b->rot, m->offset_t));
        kin_quat q = kin_quat_normalize(kin_quat_mul(b->rot, m->offset_r));
        switch (k) {
        case IO_NATNET_HEAD: s.head_pos = p; s.head_rot = q; break;
        case IO_NATNET_SHOULDER_L: s.shoulder[0] = p; break;
        case IO_NATNET_SHOULDER_R: s.shoulder[1] = p; break;
        case IO_NATNET_HAND_L: s.hand_pos[0] = p; s.hand_rot[0] = q; break;
        default: s.hand_pos[1] = p; s.hand_rot[1] = q; break;
        }
        s.valid |= point_bit[k];
    }
    n->last = s;
}

static void bad_packet(io_natnet *n, const char *from, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void bad_packet(io_natnet *n, const char *from, const char *fmt, ...)
{
    char why[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    n->bad++;
    if (n->have_frame)
        set_status(n, 1, "natnet packet from %s: %s; keeping frame %d (t = %.3f s)", from, why,
                   (int)n->frame, n->server_time);
    else
        set_status(n, 1, "natnet packet from %s: %s; no frame yet", from, why);
}

static void on_frame(io_natnet *n, const uint8_t *pl, size_t len, const char *from, double t_rx,
                     int *got)
{
    if (n->version_major < 3) {   /* not the packet's fault: counted apart */
        n->unversioned++;
        set_status(n, 1, "natnet frame from %s: the NatNet version is unknown (no NAT_SERVERINFO "
                   "yet and no version configured); %llu frames skipped", from,
                   (unsigned long long)n->unversioned);
        return;
    }
    io_natnet_body_pose bodies[IO_NATNET_MAX_BODIES];
    rd r = { pl, len, 0, 4, 0, "" };
    frame_data f;
    if (parse_frame(&r, n->version_major, n->version_minor, &f, bodies, IO_NATNET_MAX_BODIES)) {
        bad_packet(n, from, "frame of data (NatNet %d.%d, %zu bytes): %s", n->version_major,
                   n->version_minor, len, r.why);
        return;
    }
    int restart = 0;
    if (n->have_frame) {
        if (f.ts < n->server_time - n->cfg.restart_s) {
            restart = 1;
        } else if ((int32_t)((uint32_t)f.frame - (uint32_t)n->frame) <= 0 || f.ts < n->server_time) {
            n->dropped_order++;
            set_status(n, 0, "natnet frame %d (t = %.4f s) from %s: not after frame %d (t = %.4f "
                       "s); dropped (out of order or duplicate)", (int)f.frame, f.ts, from,
                       (int)n->frame, n->server_time);
            return;
        }
    }
    if (restart) n->restarts++;
    n->body_count = f.count < IO_NATNET_MAX_BODIES ? f.count : IO_NATNET_MAX_BODIES;
    for (int i = 0; i < n->body_count; i++) {
        n->body[i] = bodies[i];
        convert(n, &n->body[i]);
    }
    n->have_frame = 1;
    n->frame = f.frame;
    n->server_time = f.ts;
    n->t_receipt = t_rx;
    n->stamp_mid_exposure = f.stamp[0];
    n->stamp_received = f.stamp[1];
    n->stamp_transmit = f.stamp[2];
    n->precision_s = f.prec_s;
    n->precision_frac = f.prec_frac;
    n->timecode = f.timecode;
    n->timecode_sub = f.timecode_sub;
    n->latency = 0;
    if (n->clock_freq && f.stamp[0] && f.stamp[2] >= f.stamp[0]) {
        double l = (double)(f.stamp[2] - f.stamp[0]) / (double)n->clock_freq;
        if (l < 1.0) n->latency = l;
    }
    double t = t_rx - n->latency;
    if (n->frames && !restart && !(t > n->last.t)) t = n->last.t + 1e-6;
    build_sample(n, t);
    n->frames++;
    if (n->on_sample) n->on_sample(n->user, &n->last, n);
    (*got)++;
    if (f.params & 2) {   /* the tracked models changed: ask again */
        send_cmd(n, IO_NATNET_REQUEST_MODELDEF);
        n->t_model_sent = t_rx;
        n->have_models = 0;
    }
    set_status(n, 0, "natnet frame %d (t = %.3f s) from %s accepted%s", (int)f.frame, f.ts, from,
               restart ? " (server restarted: time went back)" : "");
}

static void on_server_info(io_natnet *n, const uint8_t *pl, size_t len, const char *from)
{
    if (len < 264) {
        bad_packet(n, from, "server info of %zu bytes, needs at least 264", len);
        return;
    }
    char name[257];
    memcpy(name, pl, 256);
    name[256] = 0;
    int ma = pl[260], mi = pl[261];
    if (ma < 3 || ma > 4) {
        bad_packet(n, from, "server info: NatNet version %d.%d.%d.%d not supported (3.x, 4.x)",
                   ma, mi, pl[262], pl[263]);
        return;
    }
    n->have_server_info = 1;
    snprintf(n->server_app, sizeof n->server_app, "%.63s", name);
    memcpy(n->server_version, pl + 256, 4);
    memcpy(n->natnet_version, pl + 260, 4);
    n->version_major = ma;
    n->version_minor = mi;
    if (len >= 279) {
        uint64_t f = 0;
        for (int i = 7; i >= 0; i--) f = f << 8 | pl[264 + i];
        n->clock_freq = f;
    }
    if (!n->have_models) {
        send_cmd(n, IO_NATNET_REQUEST_MODELDEF);
        n->t_model_sent = mono_now();
    }
    set_status(n, 0, "natnet server %s: %s %d.%d.%d.%d, NatNet %d.%d.%d.%d", from, n->server_app,
               pl[256], pl[257], pl[258], pl[259], ma, mi, pl[262], pl[263]);
}

static void on_modeldef(io_natnet *n, const uint8_t *pl, size_t len, const char *from)
{
    if (n->version_major < 3) {
        bad_packet(n, from, "model definitions, but the NatNet version is unknown (no "
                   "NAT_SERVERINFO yet and no version configured)");
        return;
    }
    io_natnet_desc d[IO_NATNET_MAX_BODIES];
    int cnt = 0;
    rd r = { pl, len, 0, 4, 0, "" };
    if (parse_modeldef(&r, n->version_major, n->version_minor, d, IO_NATNET_MAX_BODIES, &cnt)) {
        bad_packet(n, from, "model definitions (NatNet %d.%d, %zu bytes): %s", n->version_major,
                   n->version_minor, len, r.why);
        return;
    }
    memcpy(n->desc, d, sizeof d[0] * (size_t)cnt);
    n->desc_count = cnt;
    n->have_models = 1;
    n->model_defs++;
    char why[300];
    if (resolve_names(n, why, sizeof why)) {
        char have[200];
        io_natnet_list_bodies(n, have, sizeof have);
        set_status(n, 1, "natnet server %s has no rigid body %s; it has: %s", from, why, have);
    } else {
        set_status(n, 0, "natnet model definitions from %s: %d rigid bodies", from, cnt);
    }
}

static void handle(io_natnet *n, const uint8_t *buf, size_t len, const struct sockaddr_in *sa,
                   double t_rx, int *got)
{
    char from[48];
    addr_str(sa, from, sizeof from);
    n->packets++;
    if (len < 4) {
        bad_packet(n, from, "short packet: %zu bytes, the header alone takes 4", len);
        return;
    }
    int id = buf[0] | buf[1] << 8;
    size_t nbytes = (size_t)(buf[2] | buf[3] << 8);
    if (nbytes > len - 4) {
        bad_packet(n, from, "message %d: header says %zu payload bytes, the datagram has %zu", id,
                   nbytes, len - 4);
        return;
    }
    const uint8_t *pl = buf + 4;
    switch (id) {
    case IO_NATNET_FRAMEOFDATA: on_frame(n, pl, nbytes, from, t_rx, got); break;
    case IO_NATNET_SERVERINFO: on_server_info(n, pl, nbytes, from); break;
    case IO_NATNET_MODELDEF: on_modeldef(n, pl, nbytes, from); break;
    default:
        if (id <= IO_NATNET_DISCOVERY || id == IO_NATNET_UNRECOGNIZED_REQUEST) n->other++;
        else bad_packet(n, from, "unknown message id %d (%zu bytes)", id, len);
    }
}

static io_result drain(io_natnet *n, int fd, int *got, io_error *err)
{
    uint8_t buf[65536];
    for (;;) {
        struct sockaddr_in sa;
        socklen_t sl = sizeof sa;
        ssize_t k = recvfrom(fd, buf, sizeof buf, MSG_TRUNC, (struct sockaddr *)&sa, &sl);
        if (k < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK) return IO_OK;
            if (errno == EINTR) continue;
            if (errno == ECONNREFUSED) continue;   /* an ICMP reply to a request */
            return io_fail(err, IO_ERR_DEVICE, "natnet recv: %s", strerror(errno));
        }
        double t_rx = mono_now();
        if ((size_t)k > sizeof buf) {
            char from[48];
            addr_str(&sa, from, sizeof from);
            n->packets++;
            bad_packet(n, from, "datagram of %zd bytes, more than %zu", k, sizeof buf);
            continue;
        }
        handle(n, buf, (size_t)k, &sa, t_rx, got);
    }
}

io_result io_natnet_poll(io_natnet *n, int timeout_ms, kin_track_sample *s, int *fresh,
                         io_error *err)
{
    if (fresh) *fresh = 0;
    if (!n || n->fd < 0) return io_fail(err, IO_ERR_ARGS, "io_natnet_poll: not open");
    if (timeout_ms > 0) {
        struct pollfd pf[2] = { { n->fd, POLLIN, 0 }, { n->data_fd, POLLIN, 0 } };
        int pr = poll(pf, n->data_fd >= 0 ? 2 : 1, timeout_ms);
        if (pr < 0 && errno != EINTR)
            return io_fail(err, IO_ERR_DEVICE, "natnet poll: %s", strerror(errno));
    }
    int got = 0;
    io_result r = drain(n, n->fd, &got, err);
    if (r == IO_OK && n->data_fd >= 0) r = drain(n, n->data_fd, &got, err);
    /* requests that went unanswered, and the unicast keep-alive */
    double now = mono_now(), every = 1e-3 * n->cfg.resend_ms;
    if (!n->have_server_info && now - n->t_connect_sent >= every) {
        send_cmd(n, IO_NATNET_CONNECT);
        n->t_connect_sent = now;
        n->connects_sent++;
        char sv[64];
        struct sockaddr_in sa = { .sin_family = AF_INET,
                                  .sin_port = htons((uint16_t)n->cfg.command_port),
                                  .sin_addr = { n->server_addr } };
        addr_str(&sa, sv, sizeof sv);
        set_status(n, 1, "natnet server %s: no answer to NAT_CONNECT for %.1f s (%d sent)%s", sv,
                   now - n->t_open, n->connects_sent,
                   n->have_frame ? "; frames are arriving" : "; no frame either");
    }
    if (!n->have_models && now - n->t_model_sent >= every) {
        send_cmd(n, IO_NATNET_REQUEST_MODELDEF);
        n->t_model_sent = now;
        n->models_sent++;
    }
    if (!n->cfg.multicast[0] && now - n->t_keepalive >= every) {
        send_cmd(n, IO_NATNET_KEEPALIVE);
        n->t_keepalive = now;
    }
    if (s) *s = n->last;
    if (fresh) *fresh = got;
    return r;
}

io_result io_natnet_wait_ready(io_natnet *n, int timeout_ms, io_error *err)
{
    if (!n || n->fd < 0) return io_fail(err, IO_ERR_ARGS, "io_natnet_wait_ready: not open");
    double end = mono_now() + 1e-3 * (timeout_ms > 0 ? timeout_ms : 0);
    for (;;) {
        char why[300];
        if (n->have_server_info && n->have_models) {
            if (resolve_names(n, why, sizeof why)) {
                char have[300];
                io_natnet_list_bodies(n, have, sizeof have);
                return io_fail(err, IO_ERR_MISSING, "natnet server %s: no rigid body %s; it has: %s",
                               n->cfg.server, why, have);
            }
            return IO_OK;
        }
        double left = end - mono_now();
        if (left <= 0) break;
        int slice = (int)(left * 1e3) + 1;
        if (slice > n->cfg.resend_ms) slice = n->cfg.resend_ms;   /* resend on time */
        io_result r = io_natnet_poll(n, slice, NULL, NULL, err);
        if (r != IO_OK) return r;
    }
    return io_fail(err, IO_ERR_DEVICE, "natnet server %s:%d: no answer in %d ms (%s%s); is Motive "
                   "streaming, and is the address right?", n->cfg.server, n->cfg.command_port,
                   timeout_ms, n->have_server_info ? "server info came" : "no server info",
                   n->have_models ? ", model definitions came" : ", no model definitions");
}

int io_natnet_body(const io_natnet *n, int id, const char *name, kin_mat4 *world, int *valid)
{
    if (!n) return -1;
    if (id < 0) {
        if (!name) return -1;
        id = find_desc(n, name);
        if (id < 0) return -1;
    }
    const io_natnet_body_pose *b = body_by_id(n, id);
    if (!b) return -1;
    if (world) *world = kin_mat4_from_tr(b->pos, b->rot);
    if (valid) *valid = b->valid;
    return 0;
}

void io_natnet_close(io_natnet *n)
{
    if (!n) return;
    if (n->fd >= 0) close(n->fd);
    if (n->data_fd >= 0) close(n->data_fd);
    n->fd = n->data_fd = -1;
}
