/* kin_calib.c - per-user calibration: bone-length scales estimated from a
 * short recording (arms stretched forward and sideways), and its text file
 * "egofuse-calib 1" (docs/tracking.md), formatted into and parsed from
 * caller buffers (the file itself is opened by src/io). No allocation. */
#include "kin.h"
#include "kin_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MIN_SAMPLES 20
#define SCALE_MIN 0.5f
#define SCALE_MAX 2.0f

#define fail(why, n, ...) kin__fail(why, n, -1, __VA_ARGS__)

kin_user_calib kin_user_calib_identity(void)
{
    kin_user_calib c;
    memset(&c, 0, sizeof c);
    c.arm_scale[0] = c.arm_scale[1] = 1.0f;
    c.hand_scale[0] = c.hand_scale[1] = 1.0f;
    c.shoulder_scale = 1.0f;
    return c;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Nearest-rank quantile of v[0..n) (sorted in place). */
static float quantile(float *v, int n, float q)
{
    qsort(v, (size_t)n, sizeof(float), cmp_float);
    return v[(int)lrintf(q * (float)(n - 1))];
}

static int scale_ok(float s) { return isfinite(s) && s >= SCALE_MIN && s <= SCALE_MAX; }

int kin_user_calib_estimate(const kin_track_sample *samples, int n, const kin_arm_rig *rig,
                            float *scratch, kin_user_calib *out, char *why, size_t why_size)
{
    static const char *const side[2] = { "left", "right" };
    if (!samples || !rig || !scratch || !out || n < 0) return fail(why, why_size, "no input");
    kin_user_calib c = kin_user_calib_identity();
    for (int s = 0; s < 2; s++) {
        uint32_t need = (uint32_t)((KIN_TRACK_SHOULDER_L | KIN_TRACK_HAND_L) << s);
        int m = 0;
        for (int i = 0; i < n; i++) {
            if ((samples[i].valid & need) != need) continue;
            float d = kin_v3_len(kin_v3_sub(samples[i].hand_pos[s], samples[i].shoulder[s]));
            if (!isfinite(d)) return fail(why, why_size, "sample %d: not finite", i + 1);
            scratch[m++] = d;
        }
        if (m < MIN_SAMPLES)
            return fail(why, why_size, "%s arm: %d samples with shoulder and hand, need %d",
                        side[s], m, MIN_SAMPLES);
        float len = quantile(scratch, m, 0.95f);
        float scale = len / (rig->upper_len[s] + rig->fore_len[s]);
        if (!scale_ok(scale))
            return fail(why, why_size, "%s arm: length %.3f m gives scale %.3f, outside "
                        "[%.1f, %.1f]: were the arms stretched?", side[s], (double)len,
                        (double)scale, (double)SCALE_MIN, (double)SCALE_MAX);
        c.arm_length[s] = len;
        c.arm_scale[s] = scale;
        c.hand_scale[s] = scale;
    }
    int m = 0;
    const uint32_t both = KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R;
    for (int i = 0; i < n; i++)
        if ((samples[i].valid & both) == both)
            scratch[m++] = kin_v3_len(kin_v3_sub(samples[i].shoulder[1], samples[i].shoulder[0]));
    if (m < MIN_SAMPLES)
        return fail(why, why_size, "%d samples with both shoulders, need %d", m, MIN_SAMPLES);
    c.shoulder_width = quantile(scratch, m, 0.5f);
    c.shoulder_scale = c.shoulder_width / rig->shoulder_width;
    if (!scale_ok(c.shoulder_scale))
        return fail(why, why_size, "shoulder width %.3f m gives scale %.3f, outside [%.1f, %.1f]",
                    (double)c.shoulder_width, (double)c.shoulder_scale, (double)SCALE_MIN,
                    (double)SCALE_MAX);
    *out = c;
    return 0;
}

/* ------------------------------------------------------------------- file */

typedef kin__sink sink;
#define put kin__put

int kin_user_calib_format(const kin_user_calib *c, char *buf, size_t size)
{
    sink k = { buf, buf ? size : 0, 0 };
    if (k.size) buf[0] = '\0';
    put(&k, "egofuse-calib 1\n");
    put(&k, "arm_scale %.9g %.9g\n", (double)c->arm_scale[0], (double)c->arm_scale[1]);
    put(&k, "hand_scale %.9g %.9g\n", (double)c->hand_scale[0], (double)c->hand_scale[1]);
    put(&k, "shoulder_scale %.9g\n", (double)c->shoulder_scale);
    put(&k, "arm_length %.9g %.9g\n", (double)c->arm_length[0], (double)c->arm_length[1]);
    put(&k, "shoulder_width %.9g\n", (double)c->shoulder_width);
    for (int s = 0; s < 2; s++) {
        if (!c->has_glove[s]) continue;
        put(&k, "%s", s ? "glove_right" : "glove_left");
        for (int i = 0; i < KIN_GLOVE_SENSORS; i++) put(&k, " %.9g", (double)c->glove[s].raw_open[i]);
        for (int i = 0; i < KIN_GLOVE_SENSORS; i++) put(&k, " %.9g", (double)c->glove[s].raw_fist[i]);
        put(&k, "\n");
    }
    return (int)k.len;
}

enum { K_ARM, K_HAND, K_SHOULDER, K_ARMLEN, K_WIDTH, K_GLOVE_L, K_GLOVE_R, K_COUNT };
static const char *const keys[K_COUNT] = { "arm_scale", "hand_scale", "shoulder_scale",
                                           "arm_length", "shoulder_width", "glove_left",
                                           "glove_right" };
static const int key_count[K_COUNT] = { 2, 2, 1, 2, 1, 10, 10 };
#define REQUIRED_KEYS 5 /* the first five */

/* Strict decimal number (kin__parse_number), at most 1e30 in magnitude. */
static int number(const char *tok, float *out)
{
    double v;
    if (kin__parse_number(tok, &v) != 0 || fabs(v) > 1e30) return -1;
    *out = (float)v;
    return 0;
}

int kin_user_calib_parse(const char *text, size_t len, kin_user_calib *out, int *err_line,
                         char *why, size_t why_size)
{
    int dummy;
    if (!err_line) err_line = &dummy;
    *err_line = 0;
    if (!text || !out) return fail(why, why_size, "no input");
    kin_user_calib c = kin_user_calib_identity();
    int seen[K_COUNT] = { 0 };
    size_t pos = 0;
    int line_no = 0, have_header = 0;
    while (pos < len) {
        const char *ln = text + pos;
        const char *nl = memchr(ln, '\n', len - pos);
        size_t l = nl ? (size_t)(nl - ln) : len - pos;
        pos += l + (nl ? 1 : 0);
        line_no++;
        *err_line = line_no;
        char buf[512];
        if (l >= sizeof buf) return fail(why, why_size, "line too long");
        memcpy(buf, ln, l);
        buf[l] = '\0';
        if (memchr(buf, '\0', l)) return fail(why, why_size, "NUL byte in line");
        char *tok[16];
        int nt = 0;
        char *p = buf;
        for (;;) {
            while (*p == ' ' || *p == '\t' || *p == '\r') p++;
            if (!*p || *p == '#') break;
            if (nt == 16) return fail(why, why_size, "too many fields");
            tok[nt++] = p;
            while (*p && *p != ' ' && *p != '\t' && *p != '\r') p++;
            if (*p) *p++ = '\0';
        }
        if (!have_header) {
            if (nt != 2 || strcmp(tok[0], "egofuse-calib") != 0 || strcmp(tok[1], "1") != 0)
                return fail(why, why_size, "first line must be 'egofuse-calib 1'");
            have_header = 1;
            continue;
        }
        if (nt == 0) continue;
        int key = -1;
        for (int k = 0; k < K_COUNT; k++)
            if (strcmp(tok[0], keys[k]) == 0) key = k;
        if (key < 0) return fail(why, why_size, "unknown key '%.32s'", tok[0]);
        if (seen[key]) return fail(why, why_size, "key '%s' given twice", keys[key]);
        seen[key] = 1;
        if (nt - 1 != key_count[key])
            return fail(why, why_size, "'%s' needs %d numbers, got %d", keys[key],
                        key_count[key], nt - 1);
        float v[10];
        for (int i = 0; i < key_count[key]; i++)
            if (number(tok[1 + i], &v[i]) < 0)
                return fail(why, why_size, "'%s' value %d: bad number '%.32s'", keys[key], i + 1,
                            tok[1 + i]);
        switch (key) {
        case K_ARM:
        case K_HAND:
        case K_SHOULDER:
            for (int i = 0; i < key_count[key]; i++)
                if (!scale_ok(v[i]))
                    return fail(why, why_size, "'%s' %g outside [%.1f, %.1f]", keys[key],
                                (double)v[i], (double)SCALE_MIN, (double)SCALE_MAX);
            if (key == K_ARM) { c.arm_scale[0] = v[0]; c.arm_scale[1] = v[1]; }
            else if (key == K_HAND) { c.hand_scale[0] = v[0]; c.hand_scale[1] = v[1]; }
            else c.shoulder_scale = v[0];
            break;
        case K_ARMLEN:
        case K_WIDTH:
            for (int i = 0; i < key_count[key]; i++)
                if (v[i] < 0.0f || v[i] > 5.0f)
                    return fail(why, why_size, "'%s' %g outside [0, 5] m", keys[key], (double)v[i]);
            if (key == K_ARMLEN) { c.arm_length[0] = v[0]; c.arm_length[1] = v[1]; }
            else c.shoulder_width = v[0];
            break;
        default: {
            int s = key == K_GLOVE_R;
            for (int i = 0; i < KIN_GLOVE_SENSORS; i++) {
                if (v[i] == v[5 + i])
                    return fail(why, why_size, "'%s' sensor %d: open and fist readings are equal",
                                keys[key], i + 1);
                c.glove[s].raw_open[i] = v[i];
                c.glove[s].raw_fist[i] = v[5 + i];
            }
            c.has_glove[s] = 1;
        }
        }
    }
    if (!have_header) {
        *err_line = 0;
        return fail(why, why_size, "empty input: no 'egofuse-calib 1' header");
    }
    *err_line = 0;
    for (int k = 0; k < REQUIRED_KEYS; k++)
        if (!seen[k]) return fail(why, why_size, "missing key '%s'", keys[k]);
    *out = c;
    return 0;
}
