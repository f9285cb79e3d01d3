/* kin_calib.c - per-user calibration: bone-length scales estimated from a
 * short recording (arms stretched forward and sideways; the hands from the
 * fingertip gesture), and its text file
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
    return (kin_user_calib){ .arm_scale = { 1.0f, 1.0f }, .hand_scale = { 1.0f, 1.0f },
                             .shoulder_scale = 1.0f };
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

/* Arm and shoulder scales; hand_scale = arm_scale. */
static int estimate_arms(const kin_track_sample *samples, int n, const kin_arm_rig *rig,
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

int kin_user_calib_estimate(const kin_track_sample *samples, int n, const kin_arm_rig *rig,
                            float *scratch, kin_user_calib *out, char *why, size_t why_size)
{
    return estimate_arms(samples, n, rig, scratch, out, why, why_size);
}

/* ------------------------------------------------------ fingertip gesture */

#define TOUCH_MIN_SAMPLES 20
#define TOUCH_MIN_OPPOSED 0.75f  /* |d| / (|tip_L| + |tip_R|) */
#define TOUCH_MAX_RESIDUAL 0.02f /* metres */

/* World matrix of node i in the rest pose (the chain of its parents). */
static kin_mat4 rest_world(const kin_model *m, int i)
{
    kin_mat4 w = kin_mat4_from_transform(&m->rest[i]);
    for (int p = m->parents[i]; p >= 0; p = m->parents[p]) {
        kin_mat4 l = kin_mat4_from_transform(&m->rest[p]);
        w = kin_mat4_mul(&l, &w);
    }
    return w;
}

int kin_user_calib_hand_tips(const kin_arm_rig *rig, const kin_model *model, kin_vec3 tip[2],
                             char *why, size_t why_size)
{
    if (!rig || !model || !tip) return fail(why, why_size, "no input");
    if (model->mesh_count < 1 || model->skin_count < 1 || model->meshes[0].skin < 0 ||
        model->meshes[0].skin >= model->skin_count || !model->meshes[0].joints ||
        !model->meshes[0].weights)
        return fail(why, why_size, "the model has no skinned mesh");
    const kin_mesh *me = &model->meshes[0];
    const kin_skin *sk = &model->skins[me->skin];
    for (int s = 0; s < 2; s++) {
        int hand = rig->joint[s][KIN_RIG_HAND];
        int m3 = rig->joint[s][KIN_RIG_FINGER0 + 3 * 2 + 2];   /* middle_3 */
        if (hand < 0 || m3 < 0 || hand >= model->node_count || m3 >= model->node_count)
            return fail(why, why_size, "%s hand: no hand or middle_3 joint", s ? "right" : "left");
        kin_mat4 wh = rest_world(model, hand), w3 = rest_world(model, m3), inv;
        if (!kin_mat4_inverse(&wh, &inv))
            return fail(why, why_size, "%s hand: singular rest matrix", s ? "right" : "left");
        kin_vec3 o = kin_mat4_translation(&w3);
        kin_vec3 axis = kin_v3_norm(kin_v3(-w3.m[8], -w3.m[9], -w3.m[10]));
        int jm3 = -1;
        for (int j = 0; j < sk->joint_count; j++)
            if (sk->joints[j] == m3) jm3 = j;
        float ext = 0.0f;
        if (jm3 >= 0) {
            /* rest = world(m3) * inverse_bind: the bound vertices at rest */
            kin_mat4 bind = kin_mat4_mul(&w3, &sk->inverse_bind[jm3]);
            for (int v = 0; v < me->vertex_count; v++) {
                float w = 0.0f;
                for (int k = 0; k < 4; k++)
                    if (me->joints[v * 4 + k] == jm3) w += me->weights[v * 4 + k];
                if (w < 0.5f) continue;
                const float *p = &me->positions[v * 3];
                kin_vec3 q = kin_mat4_mul_point(&bind, kin_v3(p[0], p[1], p[2]));
                float e = kin_v3_dot(kin_v3_sub(q, o), axis);
                if (e > ext) ext = e;
            }
        }
        tip[s] = kin_mat4_mul_point(&inv, kin_v3_add(o, kin_v3_scale(axis, ext)));
    }
    return 0;
}

/* Midpoint of the shortest interval holding half of v[0..n) (sorted in
 * place): the mode of a cluster that holds more than half of the values. */
static float shortest_half(float *v, int n)
{
    qsort(v, (size_t)n, sizeof(float), cmp_float);
    int h = (n + 1) / 2, best = 0;
    for (int i = 1; i + h - 1 < n; i++)
        if (v[i + h - 1] - v[i] < v[best + h - 1] - v[best]) best = i;
    return 0.5f * (v[best] + v[best + h - 1]);
}

int kin_user_calib_estimate_tips(const kin_track_sample *samples, int n, const kin_arm_rig *rig,
                                 const kin_vec3 tip[2], float *scratch, kin_user_calib *out,
                                 char *why, size_t why_size)
{
    kin_user_calib c;
    if (estimate_arms(samples, n, rig, scratch, &c, why, why_size) < 0) return -1;
    if (why && why_size) why[0] = '\0';
    if (!tip) {
        *out = c;
        kin__fail(why, why_size, 0, "no fingertip reference of the model: hand scale = arm scale");
        return 1;
    }
    const float tl = kin_v3_len(tip[0]), tr = kin_v3_len(tip[1]);
    if (!(tl > 0.0f) || !(tr > 0.0f) || !isfinite(tl + tr)) {
        *out = c;
        kin__fail(why, why_size, 0, "fingertip reference of zero length: hand scale = arm scale");
        return 1;
    }
    const uint32_t hands = KIN_TRACK_HAND_L | KIN_TRACK_HAND_R;
    int m = 0;
    for (int i = 0; i < n; i++) {
        const kin_track_sample *q = &samples[i];
        if ((q->valid & hands) != hands) continue;
        kin_vec3 a = kin_quat_rotate(q->hand_rot[0], tip[0]);
        kin_vec3 b = kin_quat_rotate(q->hand_rot[1], tip[1]);
        kin_vec3 d = kin_v3_sub(a, b), g = kin_v3_sub(q->hand_pos[1], q->hand_pos[0]);
        float dd = kin_v3_dot(d, d);
        if (!(dd >= (TOUCH_MIN_OPPOSED * (tl + tr)) * (TOUCH_MIN_OPPOSED * (tl + tr)))) continue;
        float s = kin_v3_dot(g, d) / dd;
        if (!scale_ok(s)) continue;
        if (!(kin_v3_len(kin_v3_sub(g, kin_v3_scale(d, s))) <= TOUCH_MAX_RESIDUAL)) continue;
        scratch[m++] = s;
    }
    if (m < TOUCH_MIN_SAMPLES) {
        *out = c;
        kin__fail(why, why_size, 0, "fingertip gesture: %d samples with the middle fingertips "
                  "together, need %d: hand scale = arm scale", m, TOUCH_MIN_SAMPLES);
        return 1;
    }
    float s = shortest_half(scratch, m);
    for (int k = 0; k < 2; k++) {
        c.hand_scale[k] = s;
        c.hand_length[k] = s * (k ? tr : tl);
    }
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
    if (c->hand_length[0] > 0.0f || c->hand_length[1] > 0.0f)
        put(&k, "hand_length %.9g %.9g\n", (double)c->hand_length[0], (double)c->hand_length[1]);
    for (int s = 0; s < 2; s++) {
        if (!c->has_glove[s]) continue;
        put(&k, "%s", s ? "glove_right" : "glove_left");
        for (int i = 0; i < KIN_GLOVE_SENSORS; i++) put(&k, " %.9g", (double)c->glove[s].raw_open[i]);
        for (int i = 0; i < KIN_GLOVE_SENSORS; i++) put(&k, " %.9g", (double)c->glove[s].raw_fist[i]);
        put(&k, "\n");
    }
    return (int)k.len;
}

enum { K_ARM, K_HAND, K_SHOULDER, K_ARMLEN, K_WIDTH, K_GLOVE_L, K_GLOVE_R, K_HANDLEN, K_COUNT };
static const char *const keys[K_COUNT] = { "arm_scale", "hand_scale", "shoulder_scale",
                                           "arm_length", "shoulder_width", "glove_left",
                                           "glove_right", "hand_length" };
static const int key_count[K_COUNT] = { 2, 2, 1, 2, 1, 10, 10, 2 };
#define REQUIRED_KEYS 5 /* the first five */

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
    const char *ln;
    size_t l;
    while ((ln = kin__next_line(text, len, &pos, &l))) {
        line_no++;
        *err_line = line_no;
        char buf[512];
        if (l >= sizeof buf) return fail(why, why_size, "line too long");
        char *tok[16];
        const char *reason;
        int nt = kin__line_tokens(ln, l, buf, tok, 16, &reason);
        if (nt < 0) return fail(why, why_size, "%s", reason);
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
        float v[10] = { 0 };
        for (int i = 0; i < key_count[key]; i++)
            if (kin__parse_float(tok[1 + i], &v[i]) != 0)
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
        case K_HANDLEN:
            for (int i = 0; i < key_count[key]; i++)
                if (v[i] < 0.0f || v[i] > 5.0f)
                    return fail(why, why_size, "'%s' %g outside [0, 5] m", keys[key], (double)v[i]);
            if (key == K_ARMLEN) { c.arm_length[0] = v[0]; c.arm_length[1] = v[1]; }
            else if (key == K_HANDLEN) { c.hand_length[0] = v[0]; c.hand_length[1] = v[1]; }
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
