/* io_natnet_config.c - the configuration of the OptiTrack NatNet client
 * (io_natnet.h): defaults and the key = value settings of the command
 * line and the cockpit file (docs/tracking.md, "OptiTrack NatNet"). Split
 * from io_natnet.c: it reads no packet and opens no socket. */
#include "io_natnet.h"

#include <arpa/inet.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *const point_names[IO_NATNET_POINTS] = {
    "head", "shoulder-left", "shoulder-right", "hand-left", "hand-right"
};
static const char *const point_short[IO_NATNET_POINTS] = { "head", "sl", "sr", "hl", "hr" };
static const char *const default_bodies[IO_NATNET_POINTS] = {
    "Head", "ShoulderL", "ShoulderR", "HandL", "HandR"
};

const char *io_natnet_point_name(int k)
{
    return k >= 0 && k < IO_NATNET_POINTS ? point_names[k] : "?";
}

void io_natnet_config_default(io_natnet_config *c)
{
    memset(c, 0, sizeof *c);
    snprintf(c->server, sizeof c->server, "127.0.0.1");
    snprintf(c->local, sizeof c->local, "0.0.0.0");
    c->command_port = IO_NATNET_COMMAND_PORT;
    c->data_port = 0;
    c->unit_scale = 1.0f;
    c->resend_ms = 1000;
    c->restart_s = 1.0;
    for (int k = 0; k < IO_NATNET_POINTS; k++) {
        c->point[k].id = -1;
        snprintf(c->point[k].name, sizeof c->point[k].name, "%s", default_bodies[k]);
        c->point[k].offset_r = kin_quat_identity();
    }
}

static int find_point(const char *s, size_t len)
{
    for (int k = 0; k < IO_NATNET_POINTS; k++)
        if ((strlen(point_names[k]) == len && !strncasecmp(s, point_names[k], len)) ||
            (strlen(point_short[k]) == len && !strncasecmp(s, point_short[k], len)))
            return k;
    return -1;
}

io_result io_natnet_config_set(io_natnet_config *c, const char *key, const char *value,
                               io_error *err)
{
    if (!c || !key || !value) return io_fail(err, IO_ERR_ARGS, "natnet: NULL key or value");
    if (!strcmp(key, "natnet")) key = "server";   /* `--natnet SERVER` */
    if (!strncmp(key, "natnet-", 7) || !strncmp(key, "natnet.", 7)) key += 7;
#define BAD(...) return io_fail(err, IO_ERR_ARGS, "natnet %s '%s': " __VA_ARGS__)
    if (!strcmp(key, "server") || !strcmp(key, "local")) {
        char *dst = key[0] == 's' ? c->server : c->local;
        if (!*value || strlen(value) >= IO_NATNET_ADDR_MAX) BAD("empty or too long", key, value);
        snprintf(dst, IO_NATNET_ADDR_MAX, "%s", value);
        return IO_OK;
    }
    if (!strcmp(key, "multicast")) {
        if (!strcmp(value, "off") || !strcmp(value, "no") || !*value) {
            c->multicast[0] = 0;
            return IO_OK;
        }
        if (!strcmp(value, "on") || !strcmp(value, "default")) value = IO_NATNET_MULTICAST;
        struct in_addr a;
        if (inet_pton(AF_INET, value, &a) != 1 || (ntohl(a.s_addr) >> 28) != 14)
            BAD("not an IPv4 multicast group (224.0.0.0 - 239.255.255.255)", key, value);
        snprintf(c->multicast, sizeof c->multicast, "%s", value);
        return IO_OK;
    }
    if (!strcmp(key, "command-port") || !strcmp(key, "data-port")) {
        int p;
        if (!io_parse_int(value, key[0] == 'c' ? 1 : 0, 65535, &p)) BAD("not a port", key, value);
        if (key[0] == 'c') c->command_port = p;
        else c->data_port = p;
        return IO_OK;
    }
    if (!strcmp(key, "version")) {
        int a = 0, b = 0;
        char tail;
        if (sscanf(value, "%d.%d%c", &a, &b, &tail) != 2 || a < 3 || a > 4 || b < 0 || b > 99)
            BAD("not a supported NatNet version (3.x or 4.x, e.g. 3.1, 4.1)", key, value);
        c->version_major = a;
        c->version_minor = b;
        return IO_OK;
    }
    if (!strcmp(key, "units")) {
        if (!strcmp(value, "m")) c->unit_scale = 1.0f;
        else if (!strcmp(value, "mm")) c->unit_scale = 0.001f;
        else BAD("'m' or 'mm'", key, value);
        return IO_OK;
    }
    if (!strcmp(key, "up")) {
        if (!strcasecmp(value, "y")) c->z_up = 0;
        else if (!strcasecmp(value, "z")) c->z_up = 1;
        else BAD("'y' or 'z'", key, value);
        return IO_OK;
    }
    if (!strcmp(key, "body") || !strcmp(key, "offset")) {
        const char *eq = strchr(value, '=');
        int k = eq ? find_point(value, (size_t)(eq - value)) : -1;
        if (k < 0)
            BAD("POINT=... with POINT one of head, shoulder-left, shoulder-right, hand-left, "
                "hand-right", key, value);
        const char *v = eq + 1;
        io_natnet_map *m = &c->point[k];
        if (key[0] == 'b') {
            if (!*v) BAD("no body after '='", key, value);
            if (!strcmp(v, "none")) {
                m->id = -1;
                m->name[0] = 0;
            } else if (v[0] == '#') {
                int id;
                if (!io_parse_int(v + 1, 0, INT32_MAX, &id)) BAD("'#' needs a body id >= 0", key, value);
                m->id = id;
                m->name[0] = 0;
            } else {
                if (strlen(v) >= IO_NATNET_NAME_MAX)
                    BAD("body name longer than %d bytes", key, value, IO_NATNET_NAME_MAX - 1);
                m->id = -1;
                snprintf(m->name, sizeof m->name, "%s", v);
            }
            return IO_OK;
        }
        float f[7];
        int nf = 0;
        char buf[256];
        snprintf(buf, sizeof buf, "%s", v);
        for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
            char *e;
            if (nf == 7) BAD("3 or 7 numbers", key, value);
            double d = strtod(tok, &e);
            if (e == tok || *e || !isfinite(d)) BAD("'%s' is not a number", key, value, tok);
            f[nf++] = (float)d;
        }
        if (nf != 3 && nf != 7) BAD("3 numbers (x,y,z) or 7 (x,y,z,qx,qy,qz,qw)", key, value);
        m->offset_t = kin_v3(f[0], f[1], f[2]);
        m->offset_r = kin_quat_identity();
        if (nf == 7) {
            kin_quat q = { f[3], f[4], f[5], f[6] };
            float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
            if (!(fabsf(l - 1.0f) <= 1e-3f)) BAD("the rotation is not a unit quaternion", key, value);
            m->offset_r = kin_quat_normalize(q);
        }
        return IO_OK;
    }
#undef BAD
    return io_fail(err, IO_ERR_ARGS, "natnet: unknown key '%s' (server, local, multicast, "
                   "command-port, data-port, version, units, up, body, offset)", key);
}
