/* io_track.c - tracking input of egofuse: recorded files, per-user
 * calibration files and the live UDP stream (POSIX sockets, IPv4).
 * Parsing is kin's (kin_track_parse, kin_track_packet_read,
 * kin_user_calib_parse); this file only moves bytes and names the input
 * in errors. Formats: docs/tracking.md. */
#include "io.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <unistd.h>

#define MAX_FILE_BYTES (256u << 20)

/* Reads a whole file (NUL-terminated copy). */
static io_result read_all(const char *path, char **out, size_t *len, io_error *err)
{
    io_result r0 = io_check_file(path, err);  /* says "is a directory" */
    if (r0 != IO_OK) return r0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return io_fail(err, errno == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_READ, "%s: %s", path,
                       strerror(errno));
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap + 1);
    if (!buf) { fclose(f); return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path); }
    for (;;) {
        if (n == cap) {
            if (cap >= MAX_FILE_BYTES) {
                free(buf); fclose(f);
                return io_fail(err, IO_ERR_SIZE, "%s: larger than %u bytes", path, MAX_FILE_BYTES);
            }
            char *nb = realloc(buf, cap * 2 + 1);
            if (!nb) { free(buf); fclose(f); return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path); }
            buf = nb;
            cap *= 2;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (r == 0) break;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        int e = errno;
        free(buf);
        return io_fail(err, IO_ERR_READ, "%s: read error: %s", path, strerror(e));
    }
    buf[n] = '\0';
    *out = buf;
    *len = n;
    return IO_OK;
}

/* The whole file through io_out: complete or absent (io.h, OUTPUT FILES). */
static io_result write_atomic(const char *path, const char *data, size_t len, io_error *err)
{
    return io_write_file(path, data, len, err);
}

io_result io_track_load(const char *path, kin_track_sample **out, int *count, io_error *err)
{
    if (!path || !out || !count) return io_fail(err, IO_ERR_ARGS, "io_track_load: NULL argument");
    *out = NULL;
    *count = 0;
    char *text;
    size_t len;
    io_result r = read_all(path, &text, &len, err);
    if (r != IO_OK) return r;
    int n = 0, line = 0;
    char why[512];
    if (kin_track_parse(text, len, NULL, 0, &n, &line, why, sizeof why) < 0) {
        free(text);
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s", path, line, why);
    }
    kin_track_sample *s = malloc(sizeof *s * (size_t)(n > 0 ? n : 1));
    if (!s) { free(text); return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path); }
    if (kin_track_parse(text, len, s, n, &n, &line, why, sizeof why) < 0) {
        free(text); free(s);
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s", path, line, why);
    }
    free(text);
    *out = s;
    *count = n;
    return IO_OK;
}

void io_track_free(kin_track_sample *samples) { free(samples); }

io_result io_track_save(const char *path, const kin_track_sample *samples, int count,
                        io_error *err)
{
    if (!path || (!samples && count > 0) || count < 0)
        return io_fail(err, IO_ERR_ARGS, "io_track_save: bad arguments");
    size_t len = strlen(kin_track_header());
    for (int i = 0; i < count; i++) {
        char why[256];
        if (kin_track_sample_validate(&samples[i], why, sizeof why) < 0)
            return io_fail(err, IO_ERR_VALUE, "%s: sample %d: %s", path, i + 1, why);
        if (i > 0 && !(samples[i].t > samples[i - 1].t))
            return io_fail(err, IO_ERR_VALUE, "%s: sample %d: time stamp does not increase",
                           path, i + 1);
        len += (size_t)kin_track_format_line(&samples[i], NULL, 0);
    }
    char *buf = malloc(len + 1);
    if (!buf) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    size_t at = (size_t)snprintf(buf, len + 1, "%s", kin_track_header());
    for (int i = 0; i < count; i++)
        at += (size_t)kin_track_format_line(&samples[i], buf + at, len + 1 - at);
    io_result r = write_atomic(path, buf, at, err);
    free(buf);
    return r;
}

io_result io_user_calib_load(const char *path, kin_user_calib *out, io_error *err)
{
    if (!path || !out) return io_fail(err, IO_ERR_ARGS, "io_user_calib_load: NULL argument");
    char *text;
    size_t len;
    io_result r = read_all(path, &text, &len, err);
    if (r != IO_OK) return r;
    int line = 0;
    char why[512];
    int bad = kin_user_calib_parse(text, len, out, &line, why, sizeof why);
    free(text);
    if (bad < 0) {
        if (line > 0) return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s", path, line, why);
        return io_fail(err, IO_ERR_FORMAT, "%s: %s", path, why);
    }
    return IO_OK;
}

io_result io_user_calib_save(const char *path, const kin_user_calib *c, io_error *err)
{
    if (!path || !c) return io_fail(err, IO_ERR_ARGS, "io_user_calib_save: NULL argument");
    int n = kin_user_calib_format(c, NULL, 0);
    char *buf = malloc((size_t)n + 1);
    if (!buf) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    kin_user_calib_format(c, buf, (size_t)n + 1);
    /* never write a file that later runs could not load */
    kin_user_calib back;
    int line = 0;
    char why[256];
    if (kin_user_calib_parse(buf, (size_t)n, &back, &line, why, sizeof why) < 0) {
        free(buf);
        return io_fail(err, IO_ERR_VALUE, "%s: calibration not storable: %s", path, why);
    }
    io_result r = write_atomic(path, buf, (size_t)n, err);
    free(buf);
    return r;
}

/* -------------------------------------------------------------------- UDP */

static void udp_reset(io_track_udp *u)
{
    memset(u, 0, sizeof *u);
    u->fd = -1;
}

int io_ipv4_resolve(const char *host, uint32_t *addr, const char **why)
{
    struct in_addr a;
    if (inet_pton(AF_INET, host, &a) == 1) {
        *addr = a.s_addr;
        return 0;
    }
    struct addrinfo hints, *res = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    int rc = getaddrinfo(host, NULL, &hints, &res);
    if (rc != 0 || !res) {
        if (why) *why = gai_strerror(rc);
        if (res) freeaddrinfo(res);
        return -1;
    }
    *addr = ((struct sockaddr_in *)res->ai_addr)->sin_addr.s_addr;
    freeaddrinfo(res);
    return 0;
}

static io_result addr_of(const char *addr, int port, struct sockaddr_in *sa, io_error *err)
{
    if (port < 0 || port > 65535) return io_fail(err, IO_ERR_ARGS, "port %d out of range", port);
    memset(sa, 0, sizeof *sa);
    sa->sin_family = AF_INET;
    sa->sin_port = htons((uint16_t)port);
    const char *a = addr && *addr ? addr : "127.0.0.1";
    /* a dotted address or a host name (the tracking PC's, or this
     * machine's own) */
    const char *why;
    if (io_ipv4_resolve(a, &sa->sin_addr.s_addr, &why) != 0)
        return io_fail(err, IO_ERR_ARGS, "'%s' is neither a dotted IPv4 address nor a known host "
                       "name (%s)", a, why);
    return IO_OK;
}

/* The opening of io_track_udp_listen and _connect (fn, for the message):
 * u checked and reset, sa the address. */
static io_result udp_begin(io_track_udp *u, const char *fn, const char *addr, int port,
                           struct sockaddr_in *sa, io_error *err)
{
    if (!u) return io_fail(err, IO_ERR_ARGS, "%s: NULL argument", fn);
    udp_reset(u);
    return addr_of(addr, port, sa, err);
}

io_result io_track_udp_listen(io_track_udp *u, const char *addr, int port, io_error *err)
{
    struct sockaddr_in sa;
    io_result r = udp_begin(u, "io_track_udp_listen", addr, port, &sa, err);
    if (r != IO_OK) return r;
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) return io_fail(err, IO_ERR_DEVICE, "udp socket: %s", strerror(errno));
    if (bind(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        int e = errno;
        close(fd);
        return io_fail(err, IO_ERR_DEVICE, "udp bind %s:%d: %s", addr ? addr : "127.0.0.1", port,
                       strerror(e));
    }
    socklen_t sl = sizeof sa;
    if (getsockname(fd, (struct sockaddr *)&sa, &sl) != 0) {
        int e = errno;
        close(fd);
        return io_fail(err, IO_ERR_DEVICE, "udp getsockname: %s", strerror(e));
    }
    u->fd = fd;
    u->port = ntohs(sa.sin_port);
    snprintf(u->status, sizeof u->status, "listening on port %d; no packet yet", u->port);
    return IO_OK;
}

io_result io_track_udp_poll(io_track_udp *u, int timeout_ms, kin_track_sample *out, int *fresh,
                            io_error *err)
{
    if (fresh) *fresh = 0;
    if (!u || u->fd < 0) return io_fail(err, IO_ERR_ARGS, "io_track_udp_poll: not listening");
    int got = 0;
    if (timeout_ms > 0) {
        struct pollfd pf = { u->fd, POLLIN, 0 };
        int pr = poll(&pf, 1, timeout_ms);
        if (pr < 0 && errno != EINTR)
            return io_fail(err, IO_ERR_DEVICE, "udp poll: %s", strerror(errno));
    }
    for (;;) {
        uint8_t buf[2048];
        ssize_t n = recv(u->fd, buf, sizeof buf, MSG_TRUNC);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK) break;
            if (errno == EINTR) continue;
            return io_fail(err, IO_ERR_DEVICE, "udp recv: %s", strerror(errno));
        }
        u->packets++;
        kin_track_sample s;
        uint32_t seq = 0;
        char why[256];
        size_t len = (size_t)n; /* MSG_TRUNC: the real size, even if larger than buf */
        if (len > sizeof buf) {
            snprintf(why, sizeof why, "size %zu, expected %d bytes", len, KIN_TRACK_PACKET_SIZE);
        } else if (kin_track_packet_read(buf, len, &s, &seq, why, sizeof why) == 0) {
            if (u->have_good && (int32_t)(seq - u->last_seq) <= 0) {
                u->stale++;
                snprintf(u->status, sizeof u->status,
                         "packet %llu: seq %u not newer than %u (reordered or duplicate); "
                         "ignored", (unsigned long long)u->packets, (unsigned)seq,
                         (unsigned)u->last_seq);
                continue;
            }
            u->have_good = 1;
            u->last_seq = seq;
            u->last_good = s;
            u->accepted++;
            got++;
            snprintf(u->status, sizeof u->status, "packet %llu: seq %u accepted (t = %.3f s)",
                     (unsigned long long)u->packets, (unsigned)seq, s.t);
            continue;
        }
        u->rejected++;
        if (u->have_good)
            snprintf(u->status, sizeof u->status,
                     "packet %llu: %s; keeping the pose of seq %u (t = %.3f s)",
                     (unsigned long long)u->packets, why, (unsigned)u->last_seq,
                     u->last_good.t);
        else
            snprintf(u->status, sizeof u->status, "packet %llu: %s; no good pose yet",
                     (unsigned long long)u->packets, why);
    }
    if (out) {
        if (u->have_good) *out = u->last_good;
        else {
            memset(out, 0, sizeof *out);
            out->head_rot = out->hand_rot[0] = out->hand_rot[1] = kin_quat_identity();
        }
    }
    if (fresh) *fresh = got;
    return IO_OK;
}

io_result io_track_udp_connect(io_track_udp *u, const char *addr, int port, io_error *err)
{
    struct sockaddr_in sa;
    io_result r = udp_begin(u, "io_track_udp_connect", addr, port, &sa, err);
    if (r != IO_OK) return r;
    if (port == 0) return io_fail(err, IO_ERR_ARGS, "udp sender needs a port");
    int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return io_fail(err, IO_ERR_DEVICE, "udp socket: %s", strerror(errno));
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        int e = errno;
        close(fd);
        return io_fail(err, IO_ERR_DEVICE, "udp connect: %s", strerror(e));
    }
    u->fd = fd;
    u->port = port;
    u->dest_addr = sa.sin_addr.s_addr;
    return IO_OK;
}

io_result io_track_udp_send_raw(io_track_udp *u, const void *bytes, size_t n, io_error *err)
{
    if (!u || u->fd < 0 || (!bytes && n)) return io_fail(err, IO_ERR_ARGS, "udp send: not connected");
    ssize_t w = send(u->fd, bytes, n, 0);
    if (w < 0 || (size_t)w != n)
        return io_fail(err, IO_ERR_DEVICE, "udp send: %s", w < 0 ? strerror(errno) : "short");
    return IO_OK;
}

io_result io_track_udp_send(io_track_udp *u, const kin_track_sample *s, uint32_t seq,
                            io_error *err)
{
    if (!s) return io_fail(err, IO_ERR_ARGS, "udp send: no sample");
    uint8_t pk[KIN_TRACK_PACKET_SIZE];
    kin_track_packet_write(s, seq, pk);
    return io_track_udp_send_raw(u, pk, sizeof pk, err);
}

void io_track_udp_close(io_track_udp *u)
{
    if (!u) return;
    if (u->fd >= 0) close(u->fd);
    u->fd = -1;
}
