/* io_natnet.h - an OptiTrack NatNet client (Motive's streaming protocol,
 * NatNet 3.x and 4.x over UDP, unicast or multicast), written from the
 * published protocol (NatNet SDK documentation and samples). It turns
 * rigid bodies into egofuse's five tracking points (kin_track_sample) and
 * keeps the newest pose of every other rigid body (props). The behaviour,
 * the configuration keys and the axis mapping are in docs/tracking.md,
 * section "OptiTrack NatNet".
 *
 * CONVENTIONS
 *   As io.h: every call returns an io_result and fills the caller's
 *   io_error with a message naming the sender (ip:port) and the reason.
 *   Bad packets, unknown bodies and a silent server are counted and
 *   described in n->status, never fatal: io_natnet_poll returns IO_OK and
 *   keeps the last good pose; only socket errors return IO_ERR_DEVICE.
 *   Plain struct owned by the caller; no threads, no global state; poll
 *   never blocks longer than its timeout.
 *
 * USAGE
 *   io_natnet_config c;
 *   io_natnet_config_default(&c);
 *   io_natnet_config_set(&c, "server", "10.0.0.5", &err);
 *   io_natnet_config_set(&c, "body", "head=Helmet", &err);   // or "head=#3"
 *   io_natnet n;
 *   if (io_natnet_open(&n, &c, &err) != IO_OK) { fprintf(stderr, "%s\n", err.msg); ... }
 *   io_natnet_wait_ready(&n, 2000, &err);   // optional: server info + names
 *   for (;;) {
 *       kin_track_sample s; int fresh;
 *       io_natnet_poll(&n, 0, &s, &fresh, &err);   // s.t: CLOCK_MONOTONIC s
 *       if (fresh) kin_filter_push(&filter, &s);
 *   }
 *   io_natnet_close(&n);
 */
#ifndef EGOFUSE_IO_NATNET_H
#define EGOFUSE_IO_NATNET_H

#include <stddef.h>
#include <stdint.h>
#include "io.h"

#ifdef __cplusplus
extern "C" {
#endif

/* NatNet message ids (NatNet SDK, NatNetTypes.h). */
enum {
    IO_NATNET_CONNECT = 0, IO_NATNET_SERVERINFO = 1, IO_NATNET_REQUEST = 2,
    IO_NATNET_RESPONSE = 3, IO_NATNET_REQUEST_MODELDEF = 4, IO_NATNET_MODELDEF = 5,
    IO_NATNET_REQUEST_FRAMEOFDATA = 6, IO_NATNET_FRAMEOFDATA = 7,
    IO_NATNET_MESSAGESTRING = 8, IO_NATNET_DISCONNECT = 9, IO_NATNET_KEEPALIVE = 10,
    IO_NATNET_DISCONNECTBYTIMEOUT = 11, IO_NATNET_ECHOREQUEST = 12,
    IO_NATNET_ECHORESPONSE = 13, IO_NATNET_DISCOVERY = 14,
    IO_NATNET_UNRECOGNIZED_REQUEST = 100
};

#define IO_NATNET_COMMAND_PORT 1510
#define IO_NATNET_DATA_PORT 1511
#define IO_NATNET_MULTICAST "239.255.42.99"
#define IO_NATNET_NAME_MAX 64        /* rigid body names kept (longer: cut) */
#define IO_NATNET_MAX_BODIES 128     /* rigid bodies kept per frame / model */
#define IO_NATNET_ADDR_MAX 256

/* egofuse's five tracking points, in KIN_TRACK_* bit order. */
enum {
    IO_NATNET_HEAD = 0, IO_NATNET_SHOULDER_L, IO_NATNET_SHOULDER_R,
    IO_NATNET_HAND_L, IO_NATNET_HAND_R, IO_NATNET_POINTS
};

/* Which rigid body gives a tracking point, and where the point is in that
 * body's frame (egofuse axes and metres, after the unit and axis
 * conversion): point = body * offset. */
typedef struct io_natnet_map {
    int id;                          /* >= 0: by streaming id */
    char name[IO_NATNET_NAME_MAX];   /* id < 0 and name[0]: by name; both
                                        unset: the point is not tracked */
    kin_vec3 offset_t;               /* default 0 */
    kin_quat offset_r;               /* default identity */
} io_natnet_map;

typedef struct io_natnet_config {
    char server[IO_NATNET_ADDR_MAX]; /* Motive's address (IPv4 or host
                                        name), default "127.0.0.1" */
    char local[IO_NATNET_ADDR_MAX];  /* local address to bind, default
                                        "0.0.0.0"; multicast: the interface
                                        that joins the group */
    char multicast[IO_NATNET_ADDR_MAX]; /* group, "" = unicast (default) */
    int command_port;                /* server's, default 1510 */
    int data_port;                   /* multicast: the group's port, 1511;
                                        unicast: the local port, 0 = any */
    int version_major, version_minor;/* NatNet version of the stream until
                                        the server says it (0 = unknown:
                                        frames are refused until then) */
    float unit_scale;                /* metres per streamed unit: 1 (m,
                                        Motive's default) or 0.001 (mm) */
    int z_up;                        /* 0: Motive's Y-up (default); 1: Z-up */
    io_natnet_map point[IO_NATNET_POINTS];
    int resend_ms;                   /* NAT_CONNECT / model requests while
                                        unanswered, and unicast keep-alive,
                                        default 1000 */
    double restart_s;                /* a server time stamp this far back
                                        is a restart, not a late frame:
                                        default 1.0 */
} io_natnet_config;

/* Defaults above; the points map by name to "Head", "ShoulderL",
 * "ShoulderR", "HandL", "HandR" (the names `egofuse replay-track` serves). */
void io_natnet_config_default(io_natnet_config *c);

/* The name of tracking point k (0 .. IO_NATNET_POINTS-1) in the keys
 * body= and offset= and in messages: "head", "shoulder-left",
 * "shoulder-right", "hand-left", "hand-right"; "?" out of range. */
const char *io_natnet_point_name(int k);
/* Sets one key (docs/tracking.md): server, local, multicast (GROUP or
 * "off"), command-port, data-port, version (3.1, 4.1, ...), units (m|mm),
 * up (y|z), body (POINT=NAME, POINT=#ID or POINT=none), offset
 * (POINT=x,y,z[,qx,qy,qz,qw]); POINT is head, shoulder-left,
 * shoulder-right, hand-left or hand-right (also head, sl, sr, hl, hr).
 * Keys may carry a "natnet-" or "natnet." prefix ("natnet" alone is
 * "server"), so a command line's long option names (--natnet SERVER,
 * --natnet-body ...) can be passed as they are. IO_ERR_ARGS with the
 * key, value and reason on a bad key or value. */
io_result io_natnet_config_set(io_natnet_config *c, const char *key, const char *value,
                               io_error *err);

/* One rigid body of the newest accepted frame, in egofuse's frame. */
typedef struct io_natnet_body_pose {
    int id;
    kin_vec3 pos;
    kin_quat rot;
    float mean_error;                /* metres (converted) */
    int valid;                       /* the tracking-valid bit */
} io_natnet_body_pose;

typedef struct io_natnet_desc {
    int id;
    char name[IO_NATNET_NAME_MAX];
} io_natnet_desc;

typedef struct io_natnet {
    io_natnet_config cfg;
    int fd;                          /* unicast: the only socket (commands,
                                        replies and frames); multicast: the
                                        command socket */
    int data_fd;                     /* multicast: the group socket; -1 */
    uint32_t server_addr;            /* network order */
    int local_port;                  /* bound port of fd */
    int data_port;                   /* bound port of data_fd */
    /* what the server said */
    int have_server_info;
    char server_app[64];
    uint8_t server_version[4], natnet_version[4];
    uint64_t clock_freq;             /* high-resolution ticks per second,
                                        0 = unknown */
    int version_major, version_minor;/* in use (server's, else config's) */
    int have_models;
    int desc_count;
    io_natnet_desc desc[IO_NATNET_MAX_BODIES];
    int resolved[IO_NATNET_POINTS];  /* streaming id per point, -1 */
    /* newest accepted frame */
    int have_frame;
    int32_t frame;
    double server_time;              /* the frame's time stamp, seconds */
    double t_receipt;                /* CLOCK_MONOTONIC at receipt, s */
    double latency;                  /* server's own: transmit - mid
                                        exposure, s (0 = not given) */
    uint64_t stamp_mid_exposure, stamp_received, stamp_transmit;
    uint32_t precision_s, precision_frac, timecode, timecode_sub;
    int body_count;
    io_natnet_body_pose body[IO_NATNET_MAX_BODIES];
    kin_track_sample last;           /* the newest sample (valid = 0
                                        before the first) */
    /* counters */
    uint64_t packets, frames, dropped_order, restarts, bad, other,
             model_defs, dropouts, requests_sent;
    uint64_t unversioned;            /* frames skipped: no version known
                                        yet (before NAT_SERVERINFO) */
    double t_open, t_connect_sent, t_model_sent, t_keepalive;
    int connects_sent, models_sent;
    /* called for every accepted frame with its sample (a poll may accept
     * several: push each into kin_filter here), NULL = none; set after
     * io_natnet_open */
    void (*on_sample)(void *user, const kin_track_sample *s, const struct io_natnet *n);
    void *user;
    char last_error[512];            /* last bad packet / problem */
    char status[512];                /* last report of any kind */
} io_natnet;

/* Opens the sockets (unicast: one bound to local:data_port; multicast: the
 * group socket on data_port joined on local, and a command socket) and
 * sends NAT_CONNECT and NAT_REQUEST_MODELDEF to server:command_port. The
 * addresses may be host names (resolved once, IPv4). */
io_result io_natnet_open(io_natnet *n, const io_natnet_config *c, io_error *err);
/* The socket to wait on for frames (multicast: the group socket; the
 * command socket is read by every poll as well). */
int io_natnet_fd(const io_natnet *n);
/* Reads every pending datagram, waiting up to timeout_ms for the first;
 * resends NAT_CONNECT / NAT_REQUEST_MODELDEF while unanswered (every
 * resend_ms) and the unicast keep-alive. *s gets the newest sample: the
 * five points of the newest accepted frame (a point whose body is missing,
 * untracked or not yet known by name is cleared from s->valid), s->t its
 * capture time on CLOCK_MONOTONIC (receipt time minus the server's own
 * latency, strictly increasing); *fresh (may be NULL) the number of
 * frames accepted now. Frames whose frame number or time stamp go back
 * are dropped (n->dropped_order), unless the time stamp went back by more
 * than restart_s (a restart: accepted, n->restarts). */
io_result io_natnet_poll(io_natnet *n, int timeout_ms, kin_track_sample *s, int *fresh,
                         io_error *err);
/* Waits (polling) up to timeout_ms until the server info and the model
 * definitions arrived and every point mapped by name is known. IO_OK;
 * IO_ERR_DEVICE "no answer from ip:port ..." on timeout; IO_ERR_MISSING
 * naming the unknown bodies and listing those the server has. */
io_result io_natnet_wait_ready(io_natnet *n, int timeout_ms, io_error *err);
/* Pose of any rigid body of the newest frame, by id (id >= 0) or by name
 * (id < 0): *world the body's frame in egofuse's world, *valid its
 * tracking-valid bit. 0, or -1 when no such body is in the newest frame
 * (or the name is not in the model definitions). */
int io_natnet_body(const io_natnet *n, int id, const char *name, kin_mat4 *world, int *valid);
/* The server's rigid body names, "A (#1), B (#2)" into buf. */
void io_natnet_list_bodies(const io_natnet *n, char *buf, size_t size);
void io_natnet_close(io_natnet *n);

/* Decoding without sockets (tests, tools): parses one NatNet frame of
 * data payload (after the 4-byte header) of version major.minor into
 * bodies (up to cap; *count gets the number in the frame, which may be
 * larger), frame number and time stamp. 0, or -1 with the reason. */
int io_natnet_parse_frame(const uint8_t *payload, size_t len, int major, int minor,
                          int32_t *frame, double *timestamp, io_natnet_body_pose *bodies,
                          int cap, int *count, char *why, size_t why_size);

#ifdef __cplusplus
}
#endif
#endif
