/* test_io_natnet.c - the NatNet client (src/io/io_natnet.c) against
 * packets from tests/natnet_gen.py, a generator written from the
 * published NatNet layout independently of the parser. The test plays
 * Motive's side over UDP on 127.0.0.1: it answers NAT_CONNECT and
 * NAT_REQUEST_MODELDEF on a command socket and sends frames unicast to
 * the client (and, in one test, to a multicast group on the loopback).
 * No sleeps: every wait is a poll bounded by a timeout. */
#include "support/testutil.h"
#include <cmocka.h>

#include <arpa/inet.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "../src/io/io_natnet.h"

static char g_dir[1024];
static char g_skip[2048];

/* ------------------------------------------------------------ helpers */

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static size_t load(const char *name, uint8_t *buf, size_t cap)
{
    char p[1200];
    snprintf(p, sizeof p, "%s/%s", g_dir, name);
    FILE *f = fopen(p, "rb");
    if (!f) fail_msg("%s: missing (generator output)", p);
    size_t n = fread(buf, 1, cap, f);
    fclose(f);
    return n;
}

/* Expected pose of body id in a generated file (Motive Y-up metres). */
typedef struct expect { double p[3], q[4]; int valid, found; } expect;
static expect expected(const char *file, int id)
{
    expect e;
    memset(&e, 0, sizeof e);
    char p[1200], line[512];
    snprintf(p, sizeof p, "%s/expected.txt", g_dir);
    FILE *f = fopen(p, "r");
    assert_non_null(f);
    while (fgets(line, sizeof line, f)) {
        char fn[128];
        int rid;
        expect x;
        memset(&x, 0, sizeof x);
        if (sscanf(line, "%127s %d %lf %lf %lf %lf %lf %lf %lf %d", fn, &rid, &x.p[0], &x.p[1],
                   &x.p[2], &x.q[0], &x.q[1], &x.q[2], &x.q[3], &x.valid) == 10 &&
            !strcmp(fn, file) && rid == id) {
            e = x;
            e.found = 1;
        }
    }
    fclose(f);
    if (!e.found) fail_msg("expected.txt: no body %d in %s", id, file);
    return e;
}

/* Motive's side: a command socket on 127.0.0.1. */
typedef struct server { int fd, port; struct sockaddr_in client; int have_client; } server;

static void server_open(server *s)
{
    memset(s, 0, sizeof *s);
    s->fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    assert_true(s->fd >= 0);
    struct sockaddr_in sa = { .sin_family = AF_INET };
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(s->fd, (struct sockaddr *)&sa, sizeof sa), 0);
    socklen_t sl = sizeof sa;
    getsockname(s->fd, (struct sockaddr *)&sa, &sl);
    s->port = ntohs(sa.sin_port);
}

/* Waits (<= 3 s) for a request with message id `want`; other requests
 * (keep-alives, repeats) are skipped. Returns its payload size. */
static int server_expect(server *s, int want)
{
    double end = now_s() + 3.0;
    while (now_s() < end) {
        struct pollfd pf = { s->fd, POLLIN, 0 };
        if (poll(&pf, 1, 100) <= 0) continue;
        uint8_t buf[2048];
        struct sockaddr_in from;
        socklen_t sl = sizeof from;
        ssize_t n = recvfrom(s->fd, buf, sizeof buf, 0, (struct sockaddr *)&from, &sl);
        if (n < 4) continue;
        s->client = from;
        s->have_client = 1;
        int id = buf[0] | buf[1] << 8;
        if (id == want) return (int)(buf[2] | buf[3] << 8);
    }
    fail_msg("no request %d from the client within 3 s", want);
    return -1;
}

static void server_send(server *s, const char *file)
{
    uint8_t buf[70000];
    size_t n = load(file, buf, sizeof buf);
    assert_true(s->have_client);
    assert_int_equal(sendto(s->fd, buf, n, 0, (struct sockaddr *)&s->client, sizeof s->client),
                     (ssize_t)n);
}

/* Polls until `packets` more datagrams were handled (<= 3 s). */
static int pump(io_natnet *n, uint64_t packets, kin_track_sample *s)
{
    uint64_t want = n->packets + packets;
    int fresh_total = 0;
    double end = now_s() + 3.0;
    io_error err;
    while (n->packets < want && now_s() < end) {
        int fresh = 0;
        assert_int_equal(io_natnet_poll(n, 100, s, &fresh, &err), IO_OK);
        fresh_total += fresh;
    }
    if (n->packets < want) fail_msg("client handled %llu packets, expected %llu",
                                    (unsigned long long)n->packets, (unsigned long long)want);
    return fresh_total;
}

static void client_config(io_natnet_config *c, const server *s)
{
    io_error err;
    io_natnet_config_default(c);
    char port[16];
    snprintf(port, sizeof port, "%d", s->port);
    assert_int_equal(io_natnet_config_set(c, "server", "127.0.0.1", &err), IO_OK);
    assert_int_equal(io_natnet_config_set(c, "local", "127.0.0.1", &err), IO_OK);
    assert_int_equal(io_natnet_config_set(c, "command-port", port, &err), IO_OK);
}

/* Connect handshake: NAT_CONNECT (with "Ping"), the model request, then
 * the server info of version v. */
static void handshake(server *s, io_natnet *n, const char *v)
{
    assert_int_equal(server_expect(s, IO_NATNET_CONNECT), 271);
    server_expect(s, IO_NATNET_REQUEST_MODELDEF);
    char f[64];
    snprintf(f, sizeof f, "serverinfo_%s.bin", v);
    server_send(s, f);
    pump(n, 1, NULL);
    assert_true(n->have_server_info);
}

/* A fake server and the default configuration of a client of it. */
static void server_and_config(server *s, io_natnet_config *c)
{
    server_open(s);
    client_config(c, s);
}

/* A fake server and a client of the default configuration connected to
 * it, past the version 4.1 handshake; then the server sends the model
 * definitions of the file modeldef (not handled yet). */
static void connected(server *s, io_natnet *n, const char *modeldef)
{
    io_natnet_config c;
    server_and_config(s, &c);
    io_error err;
    assert_int_equal(io_natnet_open(n, &c, &err), IO_OK);
    handshake(s, n, "4.1");
    server_send(s, modeldef);
}

/* The point k of s against body id of file (identity axes, metres). */
static void check_point(const kin_track_sample *s, int k, const char *file, int id, double tol)
{
    expect e = expected(file, id);
    kin_vec3 p;
    kin_quat q = kin_quat_identity();
    switch (k) {
    case 0: p = s->head_pos; q = s->head_rot; break;
    case 1: p = s->shoulder[0]; break;
    case 2: p = s->shoulder[1]; break;
    case 3: p = s->hand_pos[0]; q = s->hand_rot[0]; break;
    default: p = s->hand_pos[1]; q = s->hand_rot[1]; break;
    }
    NEAR3(p, e.p[0], e.p[1], e.p[2], tol);
    if (k == 0 || k >= 3) {
        NEAR(q.x, e.q[0], 1e-5);
        NEAR(q.y, e.q[1], 1e-5);
        NEAR(q.z, e.q[2], 1e-5);
        NEAR(q.w, e.q[3], 1e-5);
    }
}

/* --------------------------------------------------------------- setup */

static int group_setup(void **state)
{
    (void)state;
    char gen[1024], log[4096];
    tu_root_path("tests/natnet_gen.py", gen, sizeof gen);
    tu_tmp_path("natnet_packets", g_dir, sizeof g_dir);
    const char *py = tu_exists("/usr/bin/python3") ? "/usr/bin/python3" : NULL;
    if (!py) {
        snprintf(g_skip, sizeof g_skip, "SKIP test_io_natnet: no /usr/bin/python3 to run %s", gen);
        return 0;
    }
    char *argv[] = { (char *)py, gen, g_dir, NULL };
    if (tu_run(argv, log, sizeof log) != 0) {
        fprintf(stderr, "natnet_gen.py failed:\n%s\n", log);
        return -1;
    }
    return 0;
}

static int group_teardown(void **state)
{
    (void)state;
    char log[256];
    char *argv[] = { "/bin/rm", "-rf", g_dir, NULL };
    if (g_dir[0]) tu_run(argv, log, sizeof log);
    return 0;
}

#define NEED_GEN()                          \
    do {                                    \
        if (g_skip[0]) {                    \
            printf("%s\n", g_skip);         \
            skip();                         \
        }                                   \
    } while (0)

/* -------------------------------------------------------------- result */

/* Points mapped by id work from the first frame; those mapped by name once
 * the model definitions come (after frames here); every other rigid body
 * by id and by name; time stamps and the server's latency. */
static void stream_version(const char *v, int major, int minor)
{
    server s;
    io_natnet_config c;
    server_and_config(&s, &c);
    io_error err;
    assert_int_equal(io_natnet_config_set(&c, "body", "head=#11", &err), IO_OK);
    io_natnet n;
    assert_int_equal(io_natnet_open(&n, &c, &err), IO_OK);
    handshake(&s, &n, v);
    assert_int_equal(n.version_major, major);
    assert_int_equal(n.version_minor, minor);
    assert_string_equal(n.server_app, "Motive");

    kin_track_sample smp;
    char f[64];
    snprintf(f, sizeof f, "frame_%s_1.bin", v);
    server_send(&s, f);
    assert_int_equal(pump(&n, 1, &smp), 1);
    /* before the model definitions only the point mapped by id */
    assert_int_equal(smp.valid, KIN_TRACK_HEAD);
    check_point(&smp, 0, f, 11, 1e-6);
    assert_int_equal(n.frame, 101);
    NEAR(n.server_time, 10.0 + 1 / 120.0, 1e-12);
    NEAR(n.latency, 0.005, 1e-9);                  /* 5000 ticks of 1 MHz */
    NEAR(smp.t, n.t_receipt - 0.005, 1e-9);
    assert_int_equal(io_natnet_body(&n, -1, "Joystick", NULL, NULL), -1); /* no names yet */

    snprintf(f, sizeof f, "modeldef_%s.bin", v);
    server_send(&s, f);
    pump(&n, 1, NULL);
    assert_true(n.have_models);
    assert_int_equal(n.desc_count, 6);
    snprintf(f, sizeof f, "frame_%s_2.bin", v);
    server_send(&s, f);
    assert_int_equal(pump(&n, 1, &smp), 1);
    assert_int_equal(smp.valid, KIN_TRACK_HEAD | KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R |
                                KIN_TRACK_HAND_L | KIN_TRACK_HAND_R);
    for (int k = 0; k < 5; k++) check_point(&smp, k, f, 11 + k, 1e-6);
    double t2 = smp.t;
    /* a prop's body, by id and by name */
    kin_mat4 w;
    int valid = 0;
    assert_int_equal(io_natnet_body(&n, 20, NULL, &w, &valid), 0);
    assert_true(valid);
    expect e = expected(f, 20);
    NEAR(w.m[12], e.p[0], 1e-6);
    NEAR(w.m[13], e.p[1], 1e-6);
    NEAR(w.m[14], e.p[2], 1e-6);
    kin_mat4 w2;
    assert_int_equal(io_natnet_body(&n, -1, "Joystick", &w2, NULL), 0);
    assert_memory_equal(&w, &w2, sizeof w);
    assert_int_equal(io_natnet_body(&n, -1, "Nothing", &w2, NULL), -1);
    assert_int_equal(io_natnet_body(&n, 99, NULL, &w2, NULL), -1);

    /* dropouts: HandL's tracking-valid bit clear, HandR not in the frame */
    snprintf(f, sizeof f, "frame_%s_drop.bin", v);
    server_send(&s, f);
    assert_int_equal(pump(&n, 1, &smp), 1);
    assert_int_equal(smp.valid, KIN_TRACK_HEAD | KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R);
    assert_true(smp.t > t2);
    assert_int_equal(n.dropouts, 2);
    assert_int_equal(io_natnet_body(&n, 14, NULL, &w, &valid), 0);
    assert_false(valid);
    assert_int_equal(io_natnet_body(&n, 15, NULL, &w, &valid), -1);
    /* the dropped parts go through the filter as missing parts */
    kin_filter flt;
    kin_filter_init(&flt, NULL);
    assert_int_equal(kin_filter_push(&flt, &smp) & KIN_FILTER_ACCEPTED, KIN_FILTER_ACCEPTED);
    assert_false(flt.part[3].has);
    assert_true(flt.part[0].has);

    /* out of order: an older frame number, then a time stamp going back */
    double t_drop = smp.t;
    snprintf(f, sizeof f, "frame_%s_old.bin", v);
    server_send(&s, f);
    assert_int_equal(pump(&n, 1, &smp), 0);
    snprintf(f, sizeof f, "frame_%s_tsback.bin", v);
    server_send(&s, f);
    assert_int_equal(pump(&n, 1, &smp), 0);
    assert_int_equal(n.dropped_order, 2);
    assert_int_equal(n.frame, 107);
    NEAR(smp.t, t_drop, 0);
    assert_non_null(strstr(n.status, "dropped"));
    /* a restart (time back by more than restart_s) is taken */
    snprintf(f, sizeof f, "frame_%s_restart.bin", v);
    server_send(&s, f);
    assert_int_equal(pump(&n, 1, &smp), 1);
    assert_int_equal(n.restarts, 1);
    assert_int_equal(n.frame, 1);
    assert_int_equal(n.bad, 0);
    io_natnet_close(&n);
    close(s.fd);
}

static void result_stream_3_1(void **state) { (void)state; NEED_GEN(); stream_version("3.1", 3, 1); }
static void result_stream_4_1(void **state) { (void)state; NEED_GEN(); stream_version("4.1", 4, 1); }

/* Z-up millimetres into egofuse's Y-up metres: the generator's Z-up frame
 * of the poses of frame 1 gives the same points. */
static void result_axes_and_units(void **state)
{
    (void)state;
    NEED_GEN();
    for (int vi = 0; vi < 2; vi++) {
        const char *v = vi ? "4.1" : "3.1";
        server s;
        io_natnet_config c;
        server_and_config(&s, &c);
        io_error err;
        assert_int_equal(io_natnet_config_set(&c, "up", "z", &err), IO_OK);
        assert_int_equal(io_natnet_config_set(&c, "units", "mm", &err), IO_OK);
        assert_int_equal(io_natnet_config_set(&c, "body", "hand-right=#15", &err), IO_OK);
        io_natnet n;
        assert_int_equal(io_natnet_open(&n, &c, &err), IO_OK);
        handshake(&s, &n, v);
        char f[64];
        snprintf(f, sizeof f, "modeldef_%s.bin", v);
        server_send(&s, f);
        snprintf(f, sizeof f, "frame_%s_zupmm.bin", v);
        server_send(&s, f);
        kin_track_sample smp;
        pump(&n, 2, &smp);
        assert_int_equal(smp.valid, 0x1F);
        for (int k = 0; k < 5; k++) check_point(&smp, k, f, 11 + k, 2e-6);
        /* by hand: Head streamed at (-249, 302, 1000) mm Z-up is
         * (-0.249, 1.0, -0.302) m Y-up */
        NEAR3(smp.head_pos, -0.249, 1.0, -0.302, 1e-6);
        /* an offset in the body's frame: 10 cm along the body's -Z */
        assert_int_equal(io_natnet_config_set(&n.cfg, "offset", "hand-right=0,0,-0.1", &err), IO_OK);
        snprintf(f, sizeof f, "frame_%s_2.bin", v);   /* Y-up m, read as Z-up mm */
        server_send(&s, f);
        pump(&n, 1, &smp);
        kin_mat4 w;
        assert_int_equal(io_natnet_body(&n, 15, NULL, &w, NULL), 0);
        kin_vec3 want = kin_mat4_mul_point(&w, kin_v3(0, 0, -0.1f));
        NEAR3(smp.hand_pos[1], want.x, want.y, want.z, 1e-6);
        io_natnet_close(&n);
        close(s.fd);
    }
}

/* The same stream over a multicast group on the loopback. */
static void result_multicast(void **state)
{
    (void)state;
    NEED_GEN();
    server s;
    server_open(&s);
    /* a free port for the group */
    server tmp;
    server_open(&tmp);
    int port = tmp.port;
    close(tmp.fd);
    io_natnet_config c;
    client_config(&c, &s);
    io_error err;
    char ps[16];
    snprintf(ps, sizeof ps, "%d", port);
    assert_int_equal(io_natnet_config_set(&c, "multicast", "239.255.42.99", &err), IO_OK);
    assert_int_equal(io_natnet_config_set(&c, "data-port", ps, &err), IO_OK);
    io_natnet n;
    if (io_natnet_open(&n, &c, &err) != IO_OK) {
        printf("SKIP multicast on the loopback: %s\n", err.msg);
        close(s.fd);
        skip();
    }
    handshake(&s, &n, "4.1");
    server_send(&s, "modeldef_4.1.bin");
    pump(&n, 1, NULL);
    int mfd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    struct in_addr lo = { htonl(INADDR_LOOPBACK) };
    setsockopt(mfd, IPPROTO_IP, IP_MULTICAST_IF, &lo, sizeof lo);
    struct sockaddr_in g = { .sin_family = AF_INET, .sin_port = htons((uint16_t)port) };
    inet_pton(AF_INET, "239.255.42.99", &g.sin_addr);
    uint8_t buf[70000];
    size_t len = load("frame_4.1_3.bin", buf, sizeof buf);
    assert_int_equal(sendto(mfd, buf, len, 0, (struct sockaddr *)&g, sizeof g), (ssize_t)len);
    kin_track_sample smp;
    assert_int_equal(pump(&n, 1, &smp), 1);
    assert_int_equal(smp.valid, 0x1F);
    for (int k = 0; k < 5; k++) check_point(&smp, k, "frame_4.1_3.bin", 11 + k, 1e-6);
    assert_int_equal(io_natnet_fd(&n), n.data_fd);
    close(mfd);
    io_natnet_close(&n);
    close(s.fd);
}

/* ------------------------------------------------------------ validity */

/* Every bad packet is counted and named (sender and reason); the stream
 * goes on with the next good frame. */
static void validity_bad_packets(void **state)
{
    (void)state;
    NEED_GEN();
    server s;
    io_natnet n;
    io_error err;
    connected(&s, &n, "modeldef_4.1.bin");
    server_send(&s, "frame_4.1_1.bin");
    kin_track_sample good;
    pump(&n, 2, &good);
    char from[32];
    snprintf(from, sizeof from, "from 127.0.0.1:%d", s.port);
    static const struct { const char *file, *why; } bad[] = {
        { "tiny.bin", "short packet: 2 bytes" },
        { "short_hdr_4.1.bin", "header says" },
        { "short_body_4.1.bin", "only" },
        { "overflow_4.1.bin", "rigid body count: count 100000 needs at least 3800000 bytes" },
        { "unknown_id.bin", "unknown message id 77" },
        { "serverinfo_7.0.bin", "NatNet version 7.0.0.0 not supported" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint64_t before = n.bad;
        server_send(&s, bad[i].file);
        kin_track_sample smp;
        assert_int_equal(pump(&n, 1, &smp), 0);
        if (n.bad != before + 1) fail_msg("%s: not counted as bad (%s)", bad[i].file, n.status);
        if (!strstr(n.last_error, from) || !strstr(n.last_error, bad[i].why))
            fail_msg("%s: message '%s' lacks '%s' or '%s'", bad[i].file, n.last_error, from,
                     bad[i].why);
        assert_memory_equal(&smp, &good, sizeof smp);   /* the last good pose kept */
    }
    assert_int_equal(n.version_major, 4);               /* 7.0 was not taken */
    server_send(&s, "message.bin");                     /* a known message: no error */
    pump(&n, 1, NULL);
    assert_int_equal(n.other, 1);
    server_send(&s, "frame_4.1_2.bin");
    kin_track_sample smp;
    assert_int_equal(pump(&n, 1, &smp), 1);             /* the stream goes on */
    check_point(&smp, 3, "frame_4.1_2.bin", 14, 1e-6);
    /* the 3.1 bad packets on a 3.1 stream */
    io_natnet_close(&n);
    close(s.fd);

    /* frames before any server info, no version configured: refused, named */
    io_natnet_config c;
    server_and_config(&s, &c);
    assert_int_equal(io_natnet_open(&n, &c, &err), IO_OK);
    server_expect(&s, IO_NATNET_CONNECT);
    server_send(&s, "frame_3.1_1.bin");
    assert_int_equal(pump(&n, 1, NULL), 0);
    assert_non_null(strstr(n.last_error, "NatNet version is unknown"));
    assert_int_equal(n.unversioned, 1);
    assert_int_equal(n.bad, 0);
    io_natnet_close(&n);
    /* ... and taken with a configured version */
    assert_int_equal(io_natnet_config_set(&c, "version", "3.1", &err), IO_OK);
    assert_int_equal(io_natnet_open(&n, &c, &err), IO_OK);
    server_expect(&s, IO_NATNET_CONNECT);
    server_send(&s, "frame_3.1_1.bin");
    assert_int_equal(pump(&n, 1, NULL), 1);
    server_send(&s, "overflow_3.1.bin");
    server_send(&s, "short_body_3.1.bin");
    pump(&n, 2, NULL);
    assert_int_equal(n.bad, 2);
    io_natnet_close(&n);
    close(s.fd);
}

/* Names the server does not have: the message names them and lists the
 * bodies it has; the points stay invalid, the rest works. */
static void validity_unknown_names(void **state)
{
    (void)state;
    NEED_GEN();
    server s;
    io_natnet n;
    io_error err;
    connected(&s, &n, "modeldef_nohands_4.1.bin");
    pump(&n, 1, NULL);
    assert_int_equal(io_natnet_wait_ready(&n, 100, &err), IO_ERR_MISSING);
    assert_non_null(strstr(err.msg, "'HandL' (hand-left), 'HandR' (hand-right)"));
    assert_non_null(strstr(err.msg, "it has: Head (#11), ShoulderL (#12), ShoulderR (#13), "
                                    "Joystick (#20)"));
    assert_non_null(strstr(n.last_error, "has no rigid body 'HandL'"));
    server_send(&s, "frame_4.1_1.bin");
    kin_track_sample smp;
    assert_int_equal(pump(&n, 1, &smp), 1);
    assert_int_equal(smp.valid, KIN_TRACK_HEAD | KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R);
    /* later model definitions with the hands: resolved */
    server_send(&s, "modeldef_4.1.bin");
    server_send(&s, "frame_4.1_2.bin");
    pump(&n, 2, &smp);
    assert_int_equal(smp.valid, 0x1F);
    assert_int_equal(io_natnet_wait_ready(&n, 100, &err), IO_OK);
    io_natnet_close(&n);
    close(s.fd);
}

/* A server that never answers: NAT_CONNECT is sent again, the wait ends
 * with a message naming the server. */
static void validity_no_answer(void **state)
{
    (void)state;
    server s;
    io_natnet_config c;
    server_and_config(&s, &c);   /* bound, never answers */
    c.resend_ms = 50;
    io_error err;
    io_natnet n;
    assert_int_equal(io_natnet_open(&n, &c, &err), IO_OK);
    assert_int_equal(io_natnet_wait_ready(&n, 300, &err), IO_ERR_DEVICE);
    char want[64];
    snprintf(want, sizeof want, "natnet server 127.0.0.1:%d: no answer in 300 ms", s.port);
    assert_non_null(strstr(err.msg, want));
    assert_true(n.connects_sent >= 2);   /* sent again while unanswered */
    assert_non_null(strstr(n.last_error, "no answer to NAT_CONNECT"));
    /* the requests did arrive */
    assert_int_equal(server_expect(&s, IO_NATNET_CONNECT), 271);
    io_natnet_close(&n);
    close(s.fd);
}

static void validity_config(void **state)
{
    (void)state;
    io_natnet_config c;
    io_natnet_config_default(&c);
    io_error err;
    assert_int_equal(c.point[IO_NATNET_HAND_L].id, -1);
    assert_string_equal(c.point[IO_NATNET_HAND_L].name, "HandL");
    assert_int_equal(io_natnet_config_set(&c, "natnet-body", "sl=#7", &err), IO_OK);
    assert_int_equal(c.point[IO_NATNET_SHOULDER_L].id, 7);
    assert_int_equal(io_natnet_config_set(&c, "natnet.body", "shoulder-right=none", &err), IO_OK);
    assert_int_equal(c.point[IO_NATNET_SHOULDER_R].name[0], 0);
    assert_int_equal(io_natnet_config_set(&c, "version", "4.1", &err), IO_OK);
    assert_int_equal(io_natnet_config_set(&c, "natnet", "10.1.2.3", &err), IO_OK);
    assert_string_equal(c.server, "10.1.2.3");
    assert_int_equal(c.version_major * 10 + c.version_minor, 41);
    static const struct { const char *k, *v, *why; } bad[] = {
        { "colour", "red", "unknown key 'colour'" },
        { "body", "elbow=X", "POINT=... with POINT one of head" },
        { "body", "head=#x", "'#' needs a body id" },
        { "version", "2.9", "not a supported NatNet version" },
        { "multicast", "10.0.0.1", "not an IPv4 multicast group" },
        { "units", "cm", "'m' or 'mm'" },
        { "up", "x", "'y' or 'z'" },
        { "offset", "head=1,2", "3 numbers" },
        { "offset", "head=0,0,0,0,0,0,2", "not a unit quaternion" },
        { "command-port", "70000", "not a port" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(io_natnet_config_set(&c, bad[i].k, bad[i].v, &err), IO_ERR_ARGS);
        if (!strstr(err.msg, bad[i].why)) fail_msg("%s=%s: '%s'", bad[i].k, bad[i].v, err.msg);
    }
    assert_int_equal(io_natnet_config_set(&c, "server", "no-such-host.invalid", &err), IO_OK);
    io_natnet n;
    assert_int_equal(io_natnet_open(&n, &c, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "natnet server 'no-such-host.invalid': not an IPv4 address "
                                    "or a known host name"));
}

/* io_natnet_parse_frame on the generator's bytes, and every truncation of
 * a frame refused without reading past its end. */
static void validity_truncations(void **state)
{
    (void)state;
    NEED_GEN();
    for (int vi = 0; vi < 2; vi++) {
        uint8_t buf[70000];
        const char *file = vi ? "frame_4.1_4.bin" : "frame_3.1_4.bin";
        size_t len = load(file, buf, sizeof buf);
        io_natnet_body_pose b[8];
        int32_t fr;
        double ts;
        int cnt;
        char why[256];
        if (io_natnet_parse_frame(buf + 4, len - 4, 3 + vi, 1, &fr, &ts, b, 8, &cnt, why,
                                  sizeof why))
            fail_msg("%s: %s", file, why);
        assert_int_equal(fr, 104);
        assert_int_equal(cnt, 6);
        assert_int_equal(b[5].id, 20);
        /* the wrong version's layout is refused, not misread */
        assert_int_equal(io_natnet_parse_frame(buf + 4, len - 4, vi ? 3 : 4, 1, &fr, &ts, b, 8,
                                               &cnt, why, sizeof why), -1);
        /* every cut short of the end-of-data tag fails */
        for (size_t cut = 0; cut + 4 < len - 4; cut++) {
            uint8_t *copy = malloc(cut ? cut : 1);
            memcpy(copy, buf + 4, cut);
            int rc = io_natnet_parse_frame(copy, cut, 3 + vi, 1, &fr, &ts, b, 8, &cnt, why,
                                           sizeof why);
            free(copy);
            if (rc != -1) fail_msg("%s cut to %zu bytes: accepted", file, cut);
        }
    }
}

TU_MAIN(group_setup, group_teardown,
        cmocka_unit_test(validity_config),
        cmocka_unit_test(validity_no_answer),
        cmocka_unit_test(validity_bad_packets),
        cmocka_unit_test(validity_unknown_names),
        cmocka_unit_test(validity_truncations),
        cmocka_unit_test(result_stream_3_1),
        cmocka_unit_test(result_stream_4_1),
        cmocka_unit_test(result_axes_and_units),
        cmocka_unit_test(result_multicast))
