/* cmd_replay.c - `egofuse replay-track`: replays a recorded tracking file
 * (egofuse-track 1) in real time, paced by its time stamps, as egofuse's
 * UDP packets or as an OptiTrack NatNet server (answering NAT_CONNECT and
 * NAT_REQUEST_MODELDEF, streaming frames of data unicast to the clients
 * that connected, or to a multicast group), so a cockpit can be dry-run
 * without a tracker. docs/tracking.md, "Replaying a recording". */
#include "cli.h"

#include <arpa/inet.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "../io/io_natnet.h"

static const char *replay_usage =
    "usage: egofuse replay-track FILE --to DEST [--speed X] [--loop] [options]\n"
    "\n"
    "Replays a recorded tracking file (egofuse-track 1, docs/tracking.md) in\n"
    "real time, paced by its time stamps, so a cockpit can be dry-run\n"
    "without a tracker.\n"
    "\n"
    "  --to udp:HOST:PORT    egofuse's UDP packets to HOST:PORT\n"
    "                        (egofuse run --track-port PORT)\n"
    "  --to natnet:ADDR[:PORT]  an OptiTrack NatNet server with its command\n"
    "                        port on ADDR:PORT (default 1510): answers\n"
    "                        NAT_CONNECT and NAT_REQUEST_MODELDEF, streams\n"
    "                        rigid bodies 1 Head, 2 ShoulderL, 3 ShoulderR,\n"
    "                        4 HandL, 5 HandR (a part missing from a sample:\n"
    "                        its tracking-valid bit clear; gloves are not\n"
    "                        sent). Unicast (default): frames go to every\n"
    "                        client that sent NAT_CONNECT, and the replay\n"
    "                        starts with the first one (once it asked for the\n"
    "                        model definitions, or 1 s after it came)\n"
    "  --multicast GROUP[:PORT]  natnet: frames to the group instead\n"
    "                        (239.255.42.99:1511 is Motive's default); starts\n"
    "                        at once\n"
    "  --natnet-version V    3.1 or 4.1 (default)\n"
    "  --natnet-up y|z       axes of the stream: Motive's Y-up (default) or\n"
    "                        Z-up\n"
    "  --natnet-units m|mm   units of the stream (default m)\n"
    "  --speed X             X times real time (default 1)\n"
    "  --loop                start again at the end (until Ctrl-C); time\n"
    "                        stamps and frame numbers keep increasing\n"
    "  --wait S              natnet unicast: give up when no client connected\n"
    "                        within S seconds (default: wait)\n"
    "  --quiet               no progress line\n"
    "  -h, --help            this text\n";

typedef struct replay_opts {
    const char *file, *to, *multicast;
    int natnet, major, minor, z_up, quiet, loop;
    float unit_scale;
    double speed, wait_s;
} replay_opts;

static volatile sig_atomic_t stop_flag;
static void on_signal(int s)
{
    (void)s;
    stop_flag = 1;
}

/* --------------------------------------------------- NatNet server side */

typedef struct buf { uint8_t d[8192]; size_t n; } buf;
static void put(buf *b, const void *p, size_t k)
{
    if (b->n + k <= sizeof b->d) memcpy(b->d + b->n, p, k);
    b->n += k;
}
static void put_le(buf *b, uint64_t v, int k)
{
    uint8_t t[8];
    for (int i = 0; i < k; i++) t[i] = (uint8_t)(v >> (8 * i));
    put(b, t, (size_t)k);
}
static void put_i32(buf *b, int32_t v) { put_le(b, (uint32_t)v, 4); }
static void put_f32(buf *b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put_le(b, u, 4);
}
static void put_str(buf *b, const char *s) { put(b, s, strlen(s) + 1); }
static void set_i32(buf *b, size_t at, int32_t v)
{
    for (int i = 0; i < 4; i++) b->d[at + (size_t)i] = (uint8_t)((uint32_t)v >> (8 * i));
}
static void header(buf *b, int id)
{
    b->n = 0;
    put_le(b, (uint16_t)id, 2);
    put_le(b, 0, 2);   /* payload size, set by finish() */
}
static void finish(buf *b)
{
    size_t pl = b->n - 4;
    b->d[2] = (uint8_t)pl;
    b->d[3] = (uint8_t)(pl >> 8);
}

static const char *const body_names[5] = { "Head", "ShoulderL", "ShoulderR", "HandL", "HandR" };

typedef struct server {
    int cmd_fd, data_fd;
    int major, minor, z_up, multicast;
    float unit_scale;
    struct sockaddr_in group;
    struct sockaddr_in client[16];
    int clients;
    uint64_t requests, model_requests;
} server;

static int v41(const server *s) { return s->major > 4 || (s->major == 4 && s->minor >= 1); }

static void send_to(int fd, const buf *b, const struct sockaddr_in *to)
{
    if (b->n <= sizeof b->d) sendto(fd, b->d, b->n, 0, (const struct sockaddr *)to, sizeof *to);
}

static void server_info(server *s, buf *b)
{
    header(b, IO_NATNET_SERVERINFO);
    char name[256];
    memset(name, 0, sizeof name);
    snprintf(name, sizeof name, "egofuse replay-track");
    put(b, name, 256);
    const uint8_t ver[8] = { 0, 1, 0, 0, (uint8_t)s->major, (uint8_t)s->minor, 0, 0 };
    put(b, ver, 8);
    put_le(b, 1000000000ull, 8);   /* high-resolution clock: CLOCK_MONOTONIC ns */
    put_le(b, ntohs(s->group.sin_port), 2);
    put_le(b, s->multicast ? 1 : 0, 1);
    put(b, &s->group.sin_addr, 4);
    finish(b);
}

static void model_def(server *s, buf *b)
{
    header(b, IO_NATNET_MODELDEF);
    put_i32(b, 5);
    for (int k = 0; k < 5; k++) {
        put_i32(b, 1);   /* rigid body */
        size_t size_at = b->n;
        if (v41(s)) put_i32(b, 0);
        size_t start = b->n;
        put_str(b, body_names[k]);
        put_i32(b, k + 1);     /* id */
        put_i32(b, -1);        /* parent */
        for (int i = 0; i < 3; i++) put_f32(b, 0.0f);
        if (s->major > 4 || (s->major == 4 && s->minor >= 2))
            for (int i = 0; i < 4; i++) put_f32(b, i == 3 ? 1.0f : 0.0f);
        put_i32(b, 0);         /* markers */
        if (v41(s)) set_i32(b, size_at, (int32_t)(b->n - start));
    }
    finish(b);
}

/* An empty section: count 0 (and a byte count 0 from 4.1). */
static void empty(server *s, buf *b)
{
    put_i32(b, 0);
    if (v41(s)) put_i32(b, 0);
}

static void frame(server *s, buf *b, int32_t number, double ts, const kin_track_sample *smp,
                  uint64_t t_ns)
{
    header(b, IO_NATNET_FRAMEOFDATA);
    put_i32(b, number);
    empty(s, b);   /* marker sets */
    empty(s, b);   /* unlabeled markers */
    put_i32(b, 5);
    size_t size_at = b->n;
    if (v41(s)) put_i32(b, 0);
    size_t start = b->n;
    static const uint32_t bit[5] = { KIN_TRACK_HEAD, KIN_TRACK_SHOULDER_L, KIN_TRACK_SHOULDER_R,
                                     KIN_TRACK_HAND_L, KIN_TRACK_HAND_R };
    for (int k = 0; k < 5; k++) {
        kin_vec3 p;
        kin_quat q = kin_quat_identity();
        switch (k) {
        case 0: p = smp->head_pos; q = smp->head_rot; break;
        case 1: p = smp->shoulder[0]; break;
        case 2: p = smp->shoulder[1]; break;
        case 3: p = smp->hand_pos[0]; q = smp->hand_rot[0]; break;
        default: p = smp->hand_pos[1]; q = smp->hand_rot[1]; break;
        }
        int valid = (smp->valid & bit[k]) != 0;
        if (!valid) {
            p = kin_v3(0, 0, 0);
            q = kin_quat_identity();
        }
        if (s->z_up) {   /* egofuse Y-up -> Z-up: (x, y, z) -> (x, -z, y) */
            p = kin_v3(p.x, -p.z, p.y);
            q = (kin_quat){ q.x, -q.z, q.y, q.w };
        }
        float u = 1.0f / s->unit_scale;
        put_i32(b, k + 1);
        put_f32(b, p.x * u);
        put_f32(b, p.y * u);
        put_f32(b, p.z * u);
        put_f32(b, q.x);
        put_f32(b, q.y);
        put_f32(b, q.z);
        put_f32(b, q.w);
        put_f32(b, 0.0f);                 /* mean marker error */
        put_le(b, valid ? 1 : 0, 2);      /* params: tracking valid */
    }
    if (v41(s)) set_i32(b, size_at, (int32_t)(b->n - start));
    empty(s, b);   /* skeletons */
    if (v41(s)) empty(s, b);   /* assets */
    empty(s, b);   /* labeled markers */
    empty(s, b);   /* force plates */
    empty(s, b);   /* devices */
    put_le(b, 0, 4);   /* timecode */
    put_le(b, 0, 4);   /* timecode subframe */
    uint64_t u;
    memcpy(&u, &ts, 8);
    put_le(b, u, 8);
    for (int i = 0; i < 3; i++) put_le(b, t_ns, 8);   /* mid-exposure, received, transmit */
    if (v41(s)) {
        put_le(b, 0, 4);
        put_le(b, 0, 4);
    }
    put_le(b, 0, 2);   /* params */
    put_i32(b, 0);     /* end of data */
    finish(b);
}

/* Answers pending requests on the command socket. */
static void serve(server *s, const replay_opts *o)
{
    for (;;) {
        uint8_t in[2048];
        struct sockaddr_in from;
        socklen_t sl = sizeof from;
        ssize_t n = recvfrom(s->cmd_fd, in, sizeof in, MSG_DONTWAIT, (struct sockaddr *)&from, &sl);
        if (n < 0) return;
        if (n < 4) continue;
        s->requests++;
        int id = in[0] | in[1] << 8;
        buf b;
        if (id == IO_NATNET_CONNECT) {
            server_info(s, &b);
            send_to(s->cmd_fd, &b, &from);
            int known = 0;
            for (int i = 0; i < s->clients; i++)
                if (s->client[i].sin_addr.s_addr == from.sin_addr.s_addr &&
                    s->client[i].sin_port == from.sin_port)
                    known = 1;
            if (!known && !s->multicast && s->clients < 16) {
                s->client[s->clients++] = from;
                if (!o->quiet) {
                    char ip[INET_ADDRSTRLEN];
                    inet_ntop(AF_INET, &from.sin_addr, ip, sizeof ip);
                    fprintf(stderr, "egofuse replay-track: NatNet client %s:%d connected\n", ip,
                            ntohs(from.sin_port));
                }
            }
        } else if (id == IO_NATNET_REQUEST_MODELDEF) {
            s->model_requests++;
            model_def(s, &b);
            send_to(s->cmd_fd, &b, &from);
        } else if (id == IO_NATNET_REQUEST) {
            header(&b, IO_NATNET_UNRECOGNIZED_REQUEST);
            finish(&b);
            send_to(s->cmd_fd, &b, &from);
        }
        /* keep-alives and anything else: nothing to answer */
    }
}

/* HOST[:PORT] syntax: fills host and port, or prints a usage error and
 * returns -1 (the command line is wrong: exit 2, checked before any file is
 * read; a host that does not resolve is found later and exits 1). */
static int split_hostport(const char *s, int need_port, int def_port, char host[256], int *port,
                          const char *what)
{
    const char *colon = strrchr(s, ':');
    *port = def_port;
    if (colon) {
        if (!cli_parse_int(colon + 1, 1, 65535, port)) {
            cli_usage_error("replay-track", "%s '%s': '%s' is not a port", what, s, colon + 1);
            return -1;
        }
        snprintf(host, 256, "%.*s", (int)(colon - s), s);
    } else if (need_port) {
        cli_usage_error("replay-track", "%s '%s': needs HOST:PORT", what, s);
        return -1;
    } else {
        snprintf(host, 256, "%s", s);
    }
    if (!host[0]) {
        cli_usage_error("replay-track", "%s '%s': no host", what, s);
        return -1;
    }
    return 0;
}

static int parse_hostport(const char *s, int need_port, int def_port, struct sockaddr_in *sa,
                          const char *what)
{
    char host[256];
    int port;
    if (split_hostport(s, need_port, def_port, host, &port, what) != 0) return -1;
    memset(sa, 0, sizeof *sa);
    sa->sin_family = AF_INET;
    sa->sin_port = htons((uint16_t)port);
    const char *why;
    if (io_ipv4_resolve(host, &sa->sin_addr.s_addr, &why) != 0) {
        io_term_fail("%s '%s': '%s' is neither an IPv4 address nor a known host name (%s)", what, s,
                 host, why);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ the replay */

static int replay(const replay_opts *o)
{
    io_error err;
    kin_track_sample *smp = NULL;
    int count = 0;
    if (io_track_load(o->file, &smp, &count, &err) != IO_OK) return io_term_fail("%s", err.msg);
    if (count < 1) {
        io_track_free(smp);
        return io_term_fail("%s: no samples to replay", o->file);
    }
    double span = smp[count - 1].t - smp[0].t;
    double period = span + (count > 1 ? span / (count - 1) : 1.0 / 60.0);
    int rc = EXIT_FAIL;
    io_track_udp udp;
    memset(&udp, 0, sizeof udp);
    udp.fd = -1;
    server srv;
    memset(&srv, 0, sizeof srv);
    srv.cmd_fd = srv.data_fd = -1;
    char dest[300];
    if (!o->natnet) {
        struct sockaddr_in sa;
        if (parse_hostport(o->to + 4, 1, 0, &sa, "--to") != 0) goto done;
        char ip[INET_ADDRSTRLEN];
        inet_ntop(AF_INET, &sa.sin_addr, ip, sizeof ip);
        if (io_track_udp_connect(&udp, ip, ntohs(sa.sin_port), &err) != IO_OK) {
            io_term_fail("--to %s: %s", o->to, err.msg);
            goto done;
        }
        snprintf(dest, sizeof dest, "udp %s:%d", ip, ntohs(sa.sin_port));
    } else {
        struct sockaddr_in sa;
        if (parse_hostport(o->to + 7, 0, IO_NATNET_COMMAND_PORT, &sa, "--to") != 0) goto done;
        srv.major = o->major;
        srv.minor = o->minor;
        srv.z_up = o->z_up;
        srv.unit_scale = o->unit_scale;
        srv.cmd_fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        srv.data_fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
        int one = 1;
        if (srv.cmd_fd < 0 || srv.data_fd < 0) {
            io_term_fail("socket: %s", strerror(errno));
            goto done;
        }
        setsockopt(srv.cmd_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        char ip[INET_ADDRSTRLEN];
        inet_ntop(AF_INET, &sa.sin_addr, ip, sizeof ip);
        if (bind(srv.cmd_fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
            io_term_fail("--to %s: bind %s:%d: %s", o->to, ip, ntohs(sa.sin_port), strerror(errno));
            goto done;
        }
        struct sockaddr_in da = sa;
        da.sin_port = 0;
        if (bind(srv.data_fd, (struct sockaddr *)&da, sizeof da) != 0) {
            io_term_fail("--to %s: bind %s:0: %s", o->to, ip, strerror(errno));
            goto done;
        }
        if (o->multicast) {
            if (parse_hostport(o->multicast, 0, IO_NATNET_DATA_PORT, &srv.group, "--multicast"))
                goto done;
            if ((ntohl(srv.group.sin_addr.s_addr) >> 28) != 14) {
                cli_usage_error("replay-track", "--multicast '%s': not a multicast group",
                                o->multicast);
                goto done;
            }
            srv.multicast = 1;
            if (sa.sin_addr.s_addr != htonl(INADDR_ANY))
                setsockopt(srv.data_fd, IPPROTO_IP, IP_MULTICAST_IF, &sa.sin_addr,
                           sizeof sa.sin_addr);
            setsockopt(srv.data_fd, IPPROTO_IP, IP_MULTICAST_LOOP, &one, sizeof one);
        }
        char gs[64] = "";
        if (srv.multicast) {
            char g[INET_ADDRSTRLEN];
            inet_ntop(AF_INET, &srv.group.sin_addr, g, sizeof g);
            snprintf(gs, sizeof gs, ", frames to %s:%d", g, ntohs(srv.group.sin_port));
        }
        snprintf(dest, sizeof dest, "NatNet %d.%d server %s:%d%s", o->major, o->minor, ip,
                 ntohs(sa.sin_port), gs);
        if (!srv.multicast) {
            if (!o->quiet)
                fprintf(stderr, "egofuse replay-track: %s waiting for a client\n", dest);
            uint64_t t_end = o->wait_s > 0 ? io_now_ns() + (uint64_t)(o->wait_s * 1e9) : 0;
            uint64_t t_client = 0;
            /* start when the first client connected and asked for the
             * model definitions (its frames then carry names), or 1 s
             * after it connected */
            while (!stop_flag && (!srv.clients || (!srv.model_requests &&
                                                   io_now_ns() - t_client < 1000000000ull))) {
                struct pollfd pf = { srv.cmd_fd, POLLIN, 0 };
                poll(&pf, 1, srv.clients ? 10 : 100);
                int had = srv.clients;
                serve(&srv, o);
                if (!had && srv.clients) t_client = io_now_ns();
                if (srv.clients) continue;
                if (t_end && io_now_ns() > t_end) {
                    io_term_fail("%s: no NatNet client connected within %g s", dest, o->wait_s);
                    goto done;
                }
            }
        }
    }
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    if (!o->quiet)
        fprintf(stderr, "egofuse replay-track: %s, %d samples over %.3f s, to %s at %gx%s\n",
                o->file, count, span, dest, o->speed, o->loop ? ", looping" : "");
    uint64_t t0 = io_now_ns();
    long sent = 0, send_errors = 0;
    int loops = 0;
    for (int loop = 0; !stop_flag; loop++) {
        for (int i = 0; i < count && !stop_flag; i++) {
            double rel = (smp[i].t - smp[0].t) + loop * period;
            uint64_t due = t0 + (uint64_t)llround(rel / o->speed * 1e9);
            for (;;) {   /* wait, answering requests meanwhile */
                uint64_t now = io_now_ns();
                if (now >= due || stop_flag) break;
                int ms = (int)((due - now) / 1000000ull);
                if (o->natnet) {
                    struct pollfd pf = { srv.cmd_fd, POLLIN, 0 };
                    poll(&pf, 1, ms > 50 ? 50 : ms);
                    serve(&srv, o);
                } else {
                    uint64_t w = due - now;
                    struct timespec ts = { (time_t)(w / 1000000000ull), (long)(w % 1000000000ull) };
                    nanosleep(&ts, NULL);
                }
            }
            if (stop_flag) break;
            kin_track_sample s = smp[i];
            s.t = smp[i].t + loop * period;   /* the file's own stamp on the first pass */
            if (o->natnet) {
                serve(&srv, o);
                buf b;
                frame(&srv, &b, (int32_t)(1 + i + (long)loop * count), s.t, &s, io_now_ns());
                if (b.n > sizeof b.d) {
                    io_term_fail("frame too large");
                    goto done;
                }
                if (srv.multicast) send_to(srv.data_fd, &b, &srv.group);
                else
                    for (int c = 0; c < srv.clients; c++) send_to(srv.data_fd, &b, &srv.client[c]);
            } else if (io_track_udp_send(&udp, &s, (uint32_t)(1 + i + (long)loop * count), &err) !=
                       IO_OK) {
                /* a receiver that is not there (yet) is not fatal: counted */
                if (!send_errors++ && !o->quiet)
                    fprintf(stderr, "egofuse replay-track: %s: %s (going on)\n", dest, err.msg);
            }
            sent++;
        }
        loops++;
        if (!o->loop) break;
    }
    printf("egofuse replay-track: sent %ld samples (%d pass%s) to %s in %.3f s", sent, loops,
           loops == 1 ? "" : "es", dest, 1e-9 * (double)(io_now_ns() - t0));
    if (send_errors) printf(", %ld refused (no receiver)", send_errors);
    printf("\n");
    rc = EXIT_OK;
done:
    io_track_free(smp);
    if (udp.fd >= 0) io_track_udp_close(&udp);
    if (srv.cmd_fd >= 0) close(srv.cmd_fd);
    if (srv.data_fd >= 0) close(srv.data_fd);
    return rc;
}

enum { O_TO = 256, O_SPEED, O_LOOP, O_MCAST, O_VER, O_UP, O_UNITS, O_WAIT, O_QUIET };

int cmd_replay(int argc, char **argv)
{
    static const struct option opts[] = {
        {"to", required_argument, 0, O_TO},        {"speed", required_argument, 0, O_SPEED},
        {"loop", no_argument, 0, O_LOOP},          {"multicast", required_argument, 0, O_MCAST},
        {"natnet-version", required_argument, 0, O_VER},
        {"natnet-up", required_argument, 0, O_UP}, {"natnet-units", required_argument, 0, O_UNITS},
        {"wait", required_argument, 0, O_WAIT},    {"quiet", no_argument, 0, O_QUIET},
        {"help", no_argument, 0, 'h'},             {0, 0, 0, 0},
    };
    replay_opts o;
    memset(&o, 0, sizeof o);
    o.speed = 1.0;
    o.major = 4;
    o.minor = 1;
    o.unit_scale = 1.0f;
    int c, k, rc;
    float f;
    cli_getopt_begin();
    while ((c = cli_getopt("replay-track", replay_usage, argc, argv, opts, &rc)) > 0) {
        switch (c) {
        case O_TO: o.to = optarg; break;
        case O_SPEED:
            if (!cli_parse_float(optarg, &f) || !(f > 0) || f > 1e6f)
                return cli_usage_error("replay-track", "--speed '%s': a factor in (0, 1e6]", optarg);
            o.speed = f;
            break;
        case O_LOOP: o.loop = 1; break;
        case O_MCAST: o.multicast = optarg; break;
        case O_VER: /* 3.1 or 4.1 */
            k = cli_pick(optarg, (const char *const[]){"3.1", "4.1", NULL});
            if (k < 0)
                return cli_usage_error("replay-track", "--natnet-version '%s': 3.1 or 4.1", optarg);
            o.major = 3 + k;
            o.minor = 1;
            break;
        case O_UP:
            o.z_up = cli_pick(optarg, (const char *const[]){"y", "z", NULL});
            if (o.z_up < 0)
                return cli_usage_error("replay-track", "--natnet-up '%s': y or z", optarg);
            break;
        case O_UNITS:
            k = cli_pick(optarg, (const char *const[]){"m", "mm", NULL});
            if (k < 0)
                return cli_usage_error("replay-track", "--natnet-units '%s': m or mm", optarg);
            o.unit_scale = k == 0 ? 1.0f : 0.001f;
            break;
        case O_WAIT:
            if (!cli_parse_float(optarg, &f) || !(f > 0))
                return cli_usage_error("replay-track", "--wait '%s': seconds > 0", optarg);
            o.wait_s = f;
            break;
        case O_QUIET: o.quiet = 1; break;
        }
    }
    if (c < 0) return rc;
    if (optind >= argc) return cli_usage_error("replay-track", "no tracking FILE given");
    o.file = argv[optind++];
    if (optind < argc)
        return cli_usage_error("replay-track", "unexpected argument '%s'", argv[optind]);
    if (!o.to) return cli_usage_error("replay-track", "--to udp:HOST:PORT or natnet:ADDR[:PORT] is "
                                      "required");
    if (!strncmp(o.to, "udp:", 4)) o.natnet = 0;
    else if (!strncmp(o.to, "natnet:", 7)) o.natnet = 1;
    else return cli_usage_error("replay-track", "--to '%s': udp:HOST:PORT or natnet:ADDR[:PORT]",
                                o.to);
    if (!o.natnet && o.multicast)
        return cli_usage_error("replay-track", "--multicast needs --to natnet:...");
    char host[256];
    int port;
    if (split_hostport(o.to + (o.natnet ? 7 : 4), !o.natnet, IO_NATNET_COMMAND_PORT, host, &port,
                       "--to") != 0)
        return EXIT_USAGE;
    return replay(&o);
}
