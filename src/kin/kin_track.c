/* kin_track.c - tracking samples: validation, the recorded text format
 * "egofuse-track 1", the live UDP packet (bytes only; sockets are in
 * src/io/io_track.c) and the body frame. Formats: docs/tracking.md.
 *
 * Strict parsing: every number must be a plain decimal ([+-]d[.d][e[+-]d],
 * no "nan", "inf" or hex), every tag appears at most once, each with its
 * exact count of numbers, quaternions must be unit within 1e-3 (they are
 * then renormalised), glove values in [0, 1]. No allocation. */
#include "kin.h"
#include "kin_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LINE_CAP 1024
#define QUAT_TOL 1e-3f

#define fail(why, n, ...) kin__fail(why, n, -1, __VA_ARGS__)

static int finite3(kin_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static int finite4(kin_quat q)
{
    return isfinite(q.x) && isfinite(q.y) && isfinite(q.z) && isfinite(q.w);
}
static float qlen(kin_quat q) { return sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w); }

static const char *const side_name[2] = { "left", "right" };

int kin_track_sample_validate(const kin_track_sample *s, char *why, size_t why_size)
{
    if (!s) return fail(why, why_size, "no sample");
    if (!isfinite(s->t)) return fail(why, why_size, "time stamp is not finite");
    if (s->valid & ~(uint32_t)KIN_TRACK_ALL)
        return fail(why, why_size, "unknown valid bits 0x%x", (unsigned)s->valid);
    if (s->valid & KIN_TRACK_HEAD) {
        if (!finite3(s->head_pos) || !finite4(s->head_rot))
            return fail(why, why_size, "head pose is not finite");
        if (fabsf(qlen(s->head_rot) - 1.0f) > QUAT_TOL)
            return fail(why, why_size, "head rotation is not a unit quaternion (|q| = %g)",
                        (double)qlen(s->head_rot));
    }
    for (int k = 0; k < 2; k++) {
        if ((s->valid & (KIN_TRACK_SHOULDER_L << k)) && !finite3(s->shoulder[k]))
            return fail(why, why_size, "%s shoulder is not finite", side_name[k]);
        if (s->valid & (KIN_TRACK_HAND_L << k)) {
            if (!finite3(s->hand_pos[k]) || !finite4(s->hand_rot[k]))
                return fail(why, why_size, "%s hand pose is not finite", side_name[k]);
            if (fabsf(qlen(s->hand_rot[k]) - 1.0f) > QUAT_TOL)
                return fail(why, why_size,
                            "%s hand rotation is not a unit quaternion (|q| = %g)",
                            side_name[k], (double)qlen(s->hand_rot[k]));
        }
        if (s->valid & (KIN_TRACK_GLOVE_L << k))
            for (int f = 0; f < KIN_GLOVE_SENSORS; f++) {
                float g = s->glove[k][f];
                if (!(g >= 0.0f && g <= 1.0f)) /* also rejects NaN */
                    return fail(why, why_size, "%s glove value %d is %g, not in [0, 1]",
                                side_name[k], f + 1, (double)g);
            }
    }
    return 0;
}

/* ------------------------------------------------------------ text format */

const char *kin_track_header(void) { return "egofuse-track 1\n"; }

#define parse_number kin__parse_number

typedef struct tag_info { const char *name; int count; uint32_t bit; } tag_info;

/* The tags of a data line, in the order they are written. */
static const tag_info tags[] = {
    { "H", 7, KIN_TRACK_HEAD },
    { "SL", 3, KIN_TRACK_SHOULDER_L }, { "SR", 3, KIN_TRACK_SHOULDER_R },
    { "HL", 7, KIN_TRACK_HAND_L }, { "HR", 7, KIN_TRACK_HAND_R },
    { "GL", 5, KIN_TRACK_GLOVE_L }, { "GR", 5, KIN_TRACK_GLOVE_R },
};
#define TAG_COUNT (int)(sizeof tags / sizeof tags[0])

static void store(kin_track_sample *s, int tag, const float *v)
{
    switch (tags[tag].bit) {
    case KIN_TRACK_HEAD:
        s->head_pos = kin_v3(v[0], v[1], v[2]);
        s->head_rot = (kin_quat){ v[3], v[4], v[5], v[6] };
        break;
    case KIN_TRACK_SHOULDER_L: s->shoulder[0] = kin_v3(v[0], v[1], v[2]); break;
    case KIN_TRACK_SHOULDER_R: s->shoulder[1] = kin_v3(v[0], v[1], v[2]); break;
    case KIN_TRACK_HAND_L:
    case KIN_TRACK_HAND_R: {
        int k = tags[tag].bit == KIN_TRACK_HAND_R;
        s->hand_pos[k] = kin_v3(v[0], v[1], v[2]);
        s->hand_rot[k] = (kin_quat){ v[3], v[4], v[5], v[6] };
        break;
    }
    default: {
        int k = tags[tag].bit == KIN_TRACK_GLOVE_R;
        for (int f = 0; f < KIN_GLOVE_SENSORS; f++) s->glove[k][f] = v[f];
    }
    }
}


int kin_track_parse_line(const char *line, size_t len, kin_track_sample *out,
                         char *why, size_t why_size)
{
    if (!line || !out) return fail(why, why_size, "no input");
    if (len >= LINE_CAP) return fail(why, why_size, "line longer than %d bytes", LINE_CAP - 1);
    char buf[LINE_CAP];
    char *tok[64];
    const char *reason;
    int nt = kin__line_tokens(line, len, buf, tok, 64, &reason);
    if (nt < 0) return fail(why, why_size, "%s", reason);
    if (nt == 0) return 0;

    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.head_rot = s.hand_rot[0] = s.hand_rot[1] = kin_quat_identity();
    if (strcmp(tok[0], "t") != 0)
        return fail(why, why_size, "a sample line starts with 't', not '%.32s'", tok[0]);
    if (nt < 2) return fail(why, why_size, "'t' needs a time stamp");
    double t;
    if (parse_number(tok[1], &t) < 0)
        return fail(why, why_size, "bad time stamp '%.32s'", tok[1]);
    s.t = t;
    int i = 2;
    while (i < nt) {
        int tag = -1;
        for (int k = 0; k < TAG_COUNT; k++)
            if (strcmp(tok[i], tags[k].name) == 0) tag = k;
        if (tag < 0) return fail(why, why_size, "unknown tag '%.32s'", tok[i]);
        if (s.valid & tags[tag].bit)
            return fail(why, why_size, "tag %s given twice", tags[tag].name);
        float v[7];
        for (int k = 0; k < tags[tag].count; k++) {
            int at = i + 1 + k;
            int is_tag = 0;
            for (int q = 0; at < nt && q < TAG_COUNT; q++)
                if (strcmp(tok[at], tags[q].name) == 0) is_tag = 1;
            if (at >= nt || is_tag)
                return fail(why, why_size, "%s needs %d numbers, got %d",
                            tags[tag].name, tags[tag].count, k);
            const int r = kin__parse_float(tok[at], &v[k]);
            if (r == -1)
                return fail(why, why_size, "%s value %d: bad number '%.32s'",
                            tags[tag].name, k + 1, tok[at]);
            if (r != 0)
                return fail(why, why_size, "%s value %d out of range", tags[tag].name, k + 1);
        }
        store(&s, tag, v);
        s.valid |= tags[tag].bit;
        i += 1 + tags[tag].count;
    }
    if (kin_track_sample_validate(&s, why, why_size) < 0) return -1;
    if (s.valid & KIN_TRACK_HEAD) s.head_rot = kin_quat_normalize(s.head_rot);
    for (int k = 0; k < 2; k++)
        if (s.valid & (KIN_TRACK_HAND_L << k)) s.hand_rot[k] = kin_quat_normalize(s.hand_rot[k]);
    *out = s;
    return 1;
}

int kin_track_parse(const char *text, size_t text_len, kin_track_sample *out, int cap,
                    int *count, int *err_line, char *why, size_t why_size)
{
    int dummy_line, dummy_count;
    if (!err_line) err_line = &dummy_line;
    if (!count) count = &dummy_count;
    *err_line = 0;
    *count = 0;
    if (!text) return fail(why, why_size, "no input");
    if (out && cap < 0) return fail(why, why_size, "negative capacity");
    size_t pos = 0;
    int line_no = 0, n = 0, have_header = 0;
    double last_t = 0.0;
    const char *ln;
    size_t len;
    while ((ln = kin__next_line(text, text_len, &pos, &len))) {
        line_no++;
        if (!have_header) {
            size_t l = len;
            if (l && ln[l - 1] == '\r') l--;
            const char *hdr = "egofuse-track 1";
            if (l != strlen(hdr) || memcmp(ln, hdr, l) != 0) {
                *err_line = line_no;
                return fail(why, why_size, "first line must be '%s'", hdr);
            }
            have_header = 1;
            continue;
        }
        kin_track_sample s;
        int r = kin_track_parse_line(ln, len, &s, why, why_size);
        if (r < 0) { *err_line = line_no; return -1; }
        if (r == 0) continue;
        if (n > 0 && !(s.t > last_t)) {
            *err_line = line_no;
            return fail(why, why_size, "time stamp %.9g does not increase (previous %.9g)",
                        s.t, last_t);
        }
        last_t = s.t;
        if (out) {
            if (n >= cap) {
                *err_line = line_no;
                return fail(why, why_size, "more than %d samples (capacity)", cap);
            }
            out[n] = s;
        }
        n++;
    }
    if (!have_header) return fail(why, why_size, "empty input: no 'egofuse-track 1' header");
    *count = n;
    return 0;
}

typedef kin__sink sink;
#define put kin__put

static void put_floats(sink *k, const float *v, int n)
{
    for (int i = 0; i < n; i++) put(k, " %.9g", (double)v[i]);
}

int kin_track_format_line(const kin_track_sample *s, char *buf, size_t size)
{
    sink k = { buf, buf ? size : 0, 0 };
    if (k.size) buf[0] = '\0';
    put(&k, "t %.17g", s->t);
    for (int tag = 0; tag < TAG_COUNT; tag++) {
        if (!(s->valid & tags[tag].bit)) continue;
        float v[7];
        switch (tags[tag].bit) {
        case KIN_TRACK_HEAD:
            memcpy(v, &s->head_pos, 3 * sizeof(float));
            memcpy(v + 3, &s->head_rot, 4 * sizeof(float));
            break;
        case KIN_TRACK_SHOULDER_L: memcpy(v, &s->shoulder[0], 3 * sizeof(float)); break;
        case KIN_TRACK_SHOULDER_R: memcpy(v, &s->shoulder[1], 3 * sizeof(float)); break;
        case KIN_TRACK_HAND_L:
        case KIN_TRACK_HAND_R: {
            int h = tags[tag].bit == KIN_TRACK_HAND_R;
            memcpy(v, &s->hand_pos[h], 3 * sizeof(float));
            memcpy(v + 3, &s->hand_rot[h], 4 * sizeof(float));
            break;
        }
        default:
            memcpy(v, s->glove[tags[tag].bit == KIN_TRACK_GLOVE_R], 5 * sizeof(float));
        }
        put(&k, " %s", tags[tag].name);
        put_floats(&k, v, tags[tag].count);
    }
    put(&k, "\n");
    return (int)k.len;
}

/* ----------------------------------------------------------------- packets */

static uint32_t crc32_ieee(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int b = 0; b < 8; b++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

static void put_u16(uint8_t *p, uint16_t v) { p[0] = (uint8_t)v; p[1] = (uint8_t)(v >> 8); }
static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (uint8_t)(v >> (8 * i));
}
static void put_u64(uint8_t *p, uint64_t v)
{
    for (int i = 0; i < 8; i++) p[i] = (uint8_t)(v >> (8 * i));
}
static uint16_t get_u16(const uint8_t *p) { return (uint16_t)(p[0] | (p[1] << 8)); }
static uint32_t get_u32(const uint8_t *p)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++) v |= (uint32_t)p[i] << (8 * i);
    return v;
}
static uint64_t get_u64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) v |= (uint64_t)p[i] << (8 * i);
    return v;
}

#define PKT_FLOATS 37

/* The 37 floats of a sample, in packet order. */
static void sample_floats(const kin_track_sample *s, float *f)
{
    memcpy(f + 0, &s->head_pos, 12);
    memcpy(f + 3, &s->head_rot, 16);
    memcpy(f + 7, &s->shoulder[0], 12);
    memcpy(f + 10, &s->shoulder[1], 12);
    memcpy(f + 13, &s->hand_pos[0], 12);
    memcpy(f + 16, &s->hand_rot[0], 16);
    memcpy(f + 20, &s->hand_pos[1], 12);
    memcpy(f + 23, &s->hand_rot[1], 16);
    memcpy(f + 27, s->glove[0], 20);
    memcpy(f + 32, s->glove[1], 20);
}

static void floats_sample(const float *f, kin_track_sample *s)
{
    memcpy(&s->head_pos, f + 0, 12);
    memcpy(&s->head_rot, f + 3, 16);
    memcpy(&s->shoulder[0], f + 7, 12);
    memcpy(&s->shoulder[1], f + 10, 12);
    memcpy(&s->hand_pos[0], f + 13, 12);
    memcpy(&s->hand_rot[0], f + 16, 16);
    memcpy(&s->hand_pos[1], f + 20, 12);
    memcpy(&s->hand_rot[1], f + 23, 16);
    memcpy(s->glove[0], f + 27, 20);
    memcpy(s->glove[1], f + 32, 20);
}

void kin_track_packet_write(const kin_track_sample *s, uint32_t seq,
                            uint8_t out[KIN_TRACK_PACKET_SIZE])
{
    memset(out, 0, KIN_TRACK_PACKET_SIZE);
    memcpy(out, "EGTK", 4);
    put_u16(out + 4, KIN_TRACK_PACKET_VERSION);
    put_u16(out + 6, (uint16_t)(s->valid & KIN_TRACK_ALL));
    put_u32(out + 8, seq);
    uint64_t tb;
    memcpy(&tb, &s->t, 8);
    put_u64(out + 12, tb);
    float f[PKT_FLOATS];
    sample_floats(s, f);
    for (int i = 0; i < PKT_FLOATS; i++) {
        uint32_t b;
        memcpy(&b, &f[i], 4);
        put_u32(out + 20 + 4 * i, b);
    }
    put_u32(out + 168, crc32_ieee(out, 168));
}

int kin_track_packet_read(const uint8_t *buf, size_t len, kin_track_sample *out,
                          uint32_t *seq, char *why, size_t why_size)
{
    if (!buf || !out) return fail(why, why_size, "no input");
    if (len != KIN_TRACK_PACKET_SIZE)
        return fail(why, why_size, "size %zu, expected %d bytes", len, KIN_TRACK_PACKET_SIZE);
    if (memcmp(buf, "EGTK", 4) != 0) return fail(why, why_size, "bad magic (not \"EGTK\")");
    uint16_t ver = get_u16(buf + 4);
    if (ver != KIN_TRACK_PACKET_VERSION)
        return fail(why, why_size, "unsupported version %u", (unsigned)ver);
    uint32_t crc = get_u32(buf + 168), want = crc32_ieee(buf, 168);
    if (crc != want)
        return fail(why, why_size, "CRC mismatch (0x%08x, computed 0x%08x)", (unsigned)crc,
                    (unsigned)want);
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.valid = get_u16(buf + 6);
    uint64_t tb = get_u64(buf + 12);
    memcpy(&s.t, &tb, 8);
    float f[PKT_FLOATS];
    for (int i = 0; i < PKT_FLOATS; i++) {
        uint32_t b = get_u32(buf + 20 + 4 * i);
        memcpy(&f[i], &b, 4);
    }
    floats_sample(f, &s);
    if (kin_track_sample_validate(&s, why, why_size) < 0) return -1;
    if (s.valid & KIN_TRACK_HEAD) s.head_rot = kin_quat_normalize(s.head_rot);
    for (int k = 0; k < 2; k++)
        if (s.valid & (KIN_TRACK_HAND_L << k)) s.hand_rot[k] = kin_quat_normalize(s.hand_rot[k]);
    *out = s;
    if (seq) *seq = get_u32(buf + 8);
    return 0;
}

/* -------------------------------------------------------------- body frame */

kin_quat kin_body_frame(kin_vec3 shoulder_l, kin_vec3 shoulder_r, kin_vec3 head)
{
    kin_vec3 x = kin_v3_norm(kin_v3_sub(shoulder_r, shoulder_l));
    if (kin_v3_len(x) == 0.0f) x = kin_v3(1, 0, 0);
    kin_vec3 wy = kin_v3(0, 1, 0);
    kin_vec3 y = kin_v3_sub(wy, kin_v3_scale(x, kin_v3_dot(x, wy)));
    if (kin_v3_len(y) < 0.1f) { /* shoulder line near vertical: towards the head */
        kin_vec3 mid = kin_v3_scale(kin_v3_add(shoulder_l, shoulder_r), 0.5f);
        kin_vec3 up = kin_v3_sub(head, mid);
        kin_vec3 yh = kin_v3_sub(up, kin_v3_scale(x, kin_v3_dot(x, up)));
        if (finite3(yh) && kin_v3_len(yh) > 1e-4f) y = yh;
        else if (kin_v3_len(y) < 1e-3f) y = kin_v3_sub(kin_v3(0, 0, -1), kin_v3_scale(x, x.z * -1.0f));
    }
    y = kin_v3_norm(y);
    kin_vec3 z = kin_v3_cross(x, y);
    return kin_quat_from_axes(x, y, z);
}
