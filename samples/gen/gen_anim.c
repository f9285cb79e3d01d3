/* gen_anim.c - the "reach_grasp" animation of the sample arms: 3 s at
 * 60 Hz, LINEAR rotation keys every 1/60 s.
 *
 * The motion is written as a few key postures in the world (wrist position,
 * finger direction and back-of-hand direction, grip, head yaw/pitch) joined
 * by minimum-jerk interpolation (the bell-shaped speed profile of human
 * reaching). Each key frame solves the arms with an analytic two-bone IK
 * (elbow in the plane of a pole vector, down and out), shares the hand's
 * roll between forearm and wrist (pronation), and turns the grip into
 * finger flexion. Quaternions are kept on one hemisphere from key to key,
 * so the sampled rotations never flip. */
#include "gen.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define DEG(d) ((d) * (PI_F / 180.0f))

/* -------------------------------------------------------------- helpers */


static kin_quat qconj(kin_quat q)
{
    kin_quat c = { -q.x, -q.y, -q.z, q.w };
    return c;
}

/* Minimum-jerk blend 10u^3 - 15u^4 + 6u^5. */
static float minjerk(float u)
{
    if (u <= 0.0f) return 0.0f;
    if (u >= 1.0f) return 1.0f;
    return u * u * u * (10.0f + u * (-15.0f + 6.0f * u));
}

/* A control track: n keys of dim values, evaluated with minimum jerk
 * between consecutive keys (rest at each key). */
typedef struct track {
    int n, dim;
    const float *t;
    const float *v;
} track;

static void track_eval(const track *tr, float t, float *out)
{
    int i = 0;
    if (t <= tr->t[0]) {
        memcpy(out, tr->v, sizeof(float) * (size_t)tr->dim);
        return;
    }
    while (i + 1 < tr->n && tr->t[i + 1] <= t) i++;
    if (i + 1 >= tr->n) {
        memcpy(out, tr->v + (size_t)(tr->n - 1) * (size_t)tr->dim,
               sizeof(float) * (size_t)tr->dim);
        return;
    }
    float u = minjerk((t - tr->t[i]) / (tr->t[i + 1] - tr->t[i]));
    const float *a = tr->v + (size_t)i * (size_t)tr->dim, *b = a + tr->dim;
    for (int k = 0; k < tr->dim; k++) out[k] = a[k] + (b[k] - a[k]) * u;
}

/* ------------------------------------------------------------- the motion */

/* Per side: wrist xyz, finger direction xyz, back-of-hand direction xyz,
 * grip (-0.3 open .. 0 relaxed .. 1 closed). World coordinates; the eyes
 * are at (0, 1.25, -0.08), the shoulders at (+-0.19, 0.97, 0). */
#define ARM_DIM 10
static const float r_times[] = { 0.0f, 0.25f, 1.05f, 1.30f, 1.65f, 1.95f, 2.30f, 2.90f, 3.0f };
static const float r_vals[][ARM_DIM] = {
    { 0.130f, 1.075f, -0.320f, -0.25f, -0.12f, -1.0f, 0.35f, 1.0f, 0.0f, 0.0f },
    { 0.130f, 1.075f, -0.320f, -0.25f, -0.12f, -1.0f, 0.35f, 1.0f, 0.0f, 0.0f },
    { 0.150f, 1.005f, -0.495f, -0.02f, -0.22f, -1.0f, 0.85f, 0.6f, 0.0f, -0.30f },
    { 0.155f, 0.990f, -0.520f, 0.00f, -0.22f, -1.0f, 0.90f, 0.55f, 0.0f, -0.25f },
    { 0.155f, 0.990f, -0.520f, 0.00f, -0.22f, -1.0f, 0.90f, 0.55f, 0.0f, 1.00f },
    { 0.155f, 0.995f, -0.515f, 0.00f, -0.20f, -1.0f, 0.90f, 0.55f, 0.0f, 1.00f },
    { 0.150f, 1.015f, -0.480f, -0.05f, -0.18f, -1.0f, 0.80f, 0.65f, 0.0f, -0.10f },
    { 0.125f, 1.075f, -0.330f, -0.25f, -0.12f, -1.0f, 0.40f, 1.0f, 0.0f, 0.10f },
    { 0.125f, 1.075f, -0.330f, -0.25f, -0.12f, -1.0f, 0.40f, 1.0f, 0.0f, 0.10f },
};
static const float l_times[] = { 0.0f, 0.6f, 1.5f, 2.4f, 3.0f };
static const float l_vals[][ARM_DIM] = {
    { -0.120f, 1.070f, -0.310f, 0.25f, -0.12f, -1.0f, -0.35f, 1.0f, 0.0f, 0.10f },
    { -0.120f, 1.070f, -0.310f, 0.25f, -0.12f, -1.0f, -0.35f, 1.0f, 0.0f, 0.10f },
    { -0.095f, 1.045f, -0.370f, 0.15f, -0.18f, -1.0f, -0.55f, 1.0f, 0.0f, 0.40f },
    { -0.120f, 1.070f, -0.315f, 0.25f, -0.12f, -1.0f, -0.35f, 1.0f, 0.0f, 0.10f },
    { -0.120f, 1.070f, -0.315f, 0.25f, -0.12f, -1.0f, -0.35f, 1.0f, 0.0f, 0.10f },
};
/* Head: yaw (deg, + turns left), pitch (deg, - looks down). */
static const float h_times[] = { 0.0f, 0.4f, 1.3f, 2.0f, 2.9f, 3.0f };
static const float h_vals[][2] = {
    { 0.0f, -27.0f }, { 0.0f, -27.0f }, { -4.5f, -29.5f },
    { -3.5f, -28.5f }, { 0.5f, -26.5f }, { 0.5f, -26.5f },
};

/* Finger flexion (deg) at grip 0 (relaxed) and grip 1 (closed round a cup)
 * for index, middle, ring, little: MCP, PIP, DIP. */
static const float flex_relax[4][3] = {
    { 10.0f, 18.0f, 8.0f }, { 14.0f, 22.0f, 10.0f },
    { 18.0f, 26.0f, 12.0f }, { 22.0f, 30.0f, 14.0f },
};
static const float flex_grasp[4][3] = {
    { 42.0f, 62.0f, 30.0f }, { 48.0f, 66.0f, 32.0f },
    { 54.0f, 70.0f, 34.0f }, { 60.0f, 72.0f, 36.0f },
};

#define UPPER 0.30f
#define FORE 0.26f

/* Two-bone IK: elbow position for shoulder S and wrist W (W is pulled in
 * when out of reach). */
static kin_vec3 solve_elbow(kin_vec3 S, kin_vec3 *W, kin_vec3 pole)
{
    kin_vec3 d = kin_v3_sub(*W, S);
    float L = kin_v3_len(d);
    float maxl = 0.985f * (UPPER + FORE), minl = FORE - UPPER + 0.05f;
    if (minl < 0.05f) minl = 0.05f;
    kin_vec3 u = kin_v3_norm(d);
    if (L > maxl) { L = maxl; *W = kin_v3_add(S, kin_v3_scale(u, L)); }
    if (L < minl) { L = minl; *W = kin_v3_add(S, kin_v3_scale(u, L)); }
    float ca = (UPPER * UPPER + L * L - FORE * FORE) / (2.0f * UPPER * L);
    if (ca > 1.0f) ca = 1.0f;
    float sa = sqrtf(fmaxf(0.0f, 1.0f - ca * ca));
    kin_vec3 p = kin_v3_norm(kin_v3_sub(pole, kin_v3_scale(u, kin_v3_dot(pole, u))));
    return kin_v3_add(S, kin_v3_scale(kin_v3_add(kin_v3_scale(u, ca),
                                                 kin_v3_scale(p, sa)), UPPER));
}

static kin_vec3 rot_about(kin_vec3 v, kin_vec3 axis, float a)
{
    return kin_quat_rotate(kin_quat_axis_angle(axis, a), v);
}

/* World rotations of upper arm, forearm and hand for one side. */
static void solve_arm(kin_vec3 S, const float *c, float s, kin_quat out[3])
{
    kin_vec3 W = kin_v3(c[0], c[1], c[2]);
    kin_vec3 pole = kin_v3(0.45f * s, -1.0f, 0.25f);
    kin_vec3 E = solve_elbow(S, &W, pole);
    kin_vec3 du = kin_v3_norm(kin_v3_sub(E, S));
    kin_vec3 df = kin_v3_norm(kin_v3_sub(W, E));
    kin_vec3 n = kin_v3_cross(du, df);
    if (kin_v3_len(n) < 1e-4f) n = kin_v3_cross(du, pole);
    n = kin_v3_norm(n);
    /* upper arm: -Z along the bone, X the elbow hinge */
    kin_vec3 zu = kin_v3_scale(du, -1.0f);
    kin_vec3 yu = kin_v3_cross(zu, n);
    out[0] = kin_quat_from_axes(n, yu, zu);
    /* hand */
    kin_vec3 zh = kin_v3_scale(kin_v3_norm(kin_v3(c[3], c[4], c[5])), -1.0f);
    kin_vec3 dors = kin_v3(c[6], c[7], c[8]);
    kin_vec3 yh = kin_v3_norm(kin_v3_sub(dors, kin_v3_scale(zh, kin_v3_dot(dors, zh))));
    kin_vec3 xh = kin_v3_cross(yh, zh);
    out[2] = kin_quat_from_axes(xh, yh, zh);
    /* forearm: hinge frame, rolled by half of the hand's roll about it */
    kin_vec3 zf = kin_v3_scale(df, -1.0f);
    kin_vec3 yf = kin_v3_cross(zf, n);
    kin_vec3 yp = kin_v3_sub(yh, kin_v3_scale(zf, kin_v3_dot(yh, zf)));
    float roll = atan2f(kin_v3_dot(kin_v3_cross(yf, yp), zf), kin_v3_dot(yf, yp));
    kin_vec3 xf = rot_about(n, zf, 0.5f * roll);
    yf = rot_about(yf, zf, 0.5f * roll);
    out[1] = kin_quat_from_axes(xf, yf, zf);
}

/* Local rotations of every animated node at time t into q[node]. */
static void pose_at(const gen_arms *a, const kin_vec3 shoulder[2], float t,
                    kin_quat *q)
{
    const kin_model *m = &a->model;
    for (int i = 0; i < m->node_count; i++) q[i] = m->rest[i].r;
    float hv[2];
    track ht = { 6, 2, h_times, &h_vals[0][0] };
    track_eval(&ht, t, hv);
    q[a->head] = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 1, 0), DEG(hv[0])),
                              kin_quat_axis_angle(kin_v3(1, 0, 0), DEG(hv[1])));
    for (int side = 0; side < 2; side++) {
        const int *J = a->joint[side];
        float s = side ? 1.0f : -1.0f, c[ARM_DIM];
        track tr = side ? (track){ 9, ARM_DIM, r_times, &r_vals[0][0] }
                        : (track){ 5, ARM_DIM, l_times, &l_vals[0][0] };
        track_eval(&tr, t, c);
        kin_quat w[3];
        solve_arm(shoulder[side], c, s, w);
        /* parents of the upper arm (body, shoulder) do not rotate */
        kin_quat pw = kin_quat_mul(m->rest[a->body].r, m->rest[J[GEN_J_SHOULDER]].r);
        q[J[GEN_J_UPPER_ARM]] = kin_quat_normalize(kin_quat_mul(qconj(pw), w[0]));
        q[J[GEN_J_FOREARM]] = kin_quat_normalize(kin_quat_mul(qconj(w[0]), w[1]));
        q[J[GEN_J_HAND]] = kin_quat_normalize(kin_quat_mul(qconj(w[1]), w[2]));
        float g = c[9];
        kin_vec3 X = kin_v3(1, 0, 0);
        for (int f = 1; f < 5; f++) {
            int j1 = GEN_J_THUMB_1 + 3 * f;
            for (int k = 0; k < 3; k++) {
                float fl = flex_relax[f - 1][k] +
                           g * (flex_grasp[f - 1][k] - flex_relax[f - 1][k]);
                kin_quat r = kin_quat_axis_angle(X, -DEG(fl));
                q[J[j1 + k]] = k == 0 ? kin_quat_mul(m->rest[J[j1]].r, r) : r;
            }
        }
        /* thumb: opposition about the palm's long axis, then flexion */
        float opp = DEG(12.0f + 28.0f * g) * s;
        q[J[GEN_J_THUMB_1]] = kin_quat_mul(
            kin_quat_axis_angle(kin_v3(0, 0, 1), opp),
            kin_quat_mul(m->rest[J[GEN_J_THUMB_1]].r,
                         kin_quat_axis_angle(X, -DEG(6.0f + 10.0f * g))));
        q[J[GEN_J_THUMB_2]] = kin_quat_axis_angle(X, -DEG(10.0f + 22.0f * g));
        q[J[GEN_J_THUMB_3]] = kin_quat_axis_angle(X, -DEG(12.0f + 30.0f * g));
    }
}

#define ALLOC(ptr, n)                                                      \
    do {                                                                   \
        (ptr) = kin_block_alloc(&m->block, sizeof(*(ptr)) * (size_t)(n));  \
        if (!(ptr)) return -1;                                             \
    } while (0)

int gen_anim_nodes(const gen_arms *a, int nodes[GEN_ANIM_NODES])
{
    int n = 0;
    nodes[n++] = a->head;
    for (int side = 0; side < 2; side++) {
        nodes[n++] = a->joint[side][GEN_J_UPPER_ARM];
        nodes[n++] = a->joint[side][GEN_J_FOREARM];
        nodes[n++] = a->joint[side][GEN_J_HAND];
        for (int j = GEN_J_THUMB_1; j < GEN_SIDE_JOINTS; j++)
            nodes[n++] = a->joint[side][j];
    }
    return n;
}

kin_animation *gen_rot_anim(kin_model *m, const char *name, const int *nodes, int nch,
                            int keys)
{
    float *times = kin_block_alloc(&m->block, sizeof(float) * (size_t)keys);
    kin_channel *ch = kin_block_alloc(&m->block, sizeof(kin_channel) * (size_t)nch);
    kin_animation *an = kin_block_alloc(&m->block, sizeof(kin_animation));
    if (!times || !ch || !an) return NULL;
    for (int k = 0; k < keys; k++) times[k] = (float)k / (float)GEN_FPS;
    for (int c = 0; c < nch; c++) {
        float *v = kin_block_alloc(&m->block, sizeof(float) * 4 * (size_t)keys);
        if (!v) return NULL;
        ch[c] = (kin_channel){ nodes[c], KIN_PATH_ROTATION, KIN_INTERP_LINEAR, keys, 4, times, v };
    }
    snprintf(an->name, KIN_NAME_MAX, "%s", name);
    an->channel_count = nch;
    an->channels = ch;
    an->duration = times[keys - 1];
    return an;
}

void gen_rot_anim_key(kin_animation *an, int k, const kin_quat *q)
{
    for (int c = 0; c < an->channel_count; c++) {
        kin_quat r = q[an->channels[c].node];
        float *v = (float *)an->channels[c].values;
        if (k > 0) {
            const float *p = v + (k - 1) * 4;
            if (p[0] * r.x + p[1] * r.y + p[2] * r.z + p[3] * r.w < 0.0f) {
                r.x = -r.x; r.y = -r.y; r.z = -r.z; r.w = -r.w;
            }
        }
        v[k * 4 + 0] = r.x;
        v[k * 4 + 1] = r.y;
        v[k * 4 + 2] = r.z;
        v[k * 4 + 3] = r.w;
    }
}

int gen_anim_build(gen_arms *a)
{
    kin_model *m = &a->model;
    int nodes[GEN_ANIM_NODES];
    const int nch = gen_anim_nodes(a, nodes);
    kin_animation *an = gen_rot_anim(m, GEN_ANIM_NAME, nodes, nch, GEN_ANIM_KEYS);
    kin_quat *q;
    if (!an) return -1;
    ALLOC(q, m->node_count);
    /* shoulder joints (upper_arm origins) in the rest pose */
    kin_vec3 shoulder[2];
    for (int side = 0; side < 2; side++) {
        kin_vec3 p = kin_v3(0, 0, 0);
        for (int n = a->joint[side][GEN_J_UPPER_ARM]; n != KIN_NO_PARENT;
             n = m->parents[n])
            p = kin_v3_add(kin_quat_rotate(m->rest[n].r, p), m->rest[n].t);
        shoulder[side] = p;
    }
    for (int k = 0; k < GEN_ANIM_KEYS; k++) {
        pose_at(a, shoulder, an->channels[0].times[k], q);
        gen_rot_anim_key(an, k, q);
    }
    m->anim_count = 1;
    m->anims = an;

    /* where the right hand closes: between palm and fingers at the end of
     * the grasp, 3 cm to the palm side of the palm node */
    a->grasp_time = 1.65f;
    pose_at(a, shoulder, a->grasp_time, q);
    int palm = a->joint[1][GEN_J_PALM];
    kin_vec3 p = kin_v3(0.0f, -0.035f, -0.045f);
    for (int n = palm; n != KIN_NO_PARENT; n = m->parents[n])
        p = kin_v3_add(kin_quat_rotate(q[n], p), m->rest[n].t);
    a->grasp_point = p;
    return 0;
}
