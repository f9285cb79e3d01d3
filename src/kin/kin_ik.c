/* kin_ik.c - analytic two-bone arm IK with a swivel rule, soft reach
 * limits and forearm twist, and the arm rig that drives a model by node
 * names from a tracking sample. Rules: kin.h (kin_arm_ik_job) and
 * docs/tracking.md. No allocation, no state. */
#include "kin.h"
#include "kin_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define DEG2RAD(d) ((d) * (PI_F / 180.0f))

#define fail(why, n, ...) kin__fail(why, n, 0, __VA_ARGS__)

/* ----------------------------------------------------------------- IK job */

static int finite3(kin_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static int unitq(kin_quat q)
{
    float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    return isfinite(l) && fabsf(l - 1.0f) <= 1e-3f;
}

typedef struct ik_params {
    float elbow_max, soft, hand_gain, twist_share, twist_max;
} ik_params;

static float def(float v, float d) { return v > 0.0f ? v : d; }

static ik_params params_of(const kin_arm_ik_job *j)
{
    ik_params p;
    p.elbow_max = DEG2RAD(def(j->elbow_max_deg, 150.0f));
    p.soft = def(j->soft, 0.97f);
    p.hand_gain = def(j->hand_gain, 1.0f);
    p.twist_share = def(j->twist_share, 0.5f);
    p.twist_max = DEG2RAD(def(j->twist_max_deg, 85.0f));
    return p;
}

/* Shoulder-wrist distance at elbow flexion f (0 = straight). */
static float reach_at(float l1, float l2, float f)
{
    return sqrtf(fmaxf(0.0f, l1 * l1 + l2 * l2 + 2.0f * l1 * l2 * cosf(f)));
}

int kin_arm_ik_validate(const kin_arm_ik_job *job, char *why, size_t why_size)
{
    if (!job) return fail(why, why_size, "no job");
    if (!finite3(job->shoulder) || !finite3(job->wrist))
        return fail(why, why_size, "shoulder or wrist is not finite");
    if (!unitq(job->hand_rot)) return fail(why, why_size, "hand_rot is not a unit quaternion");
    if (!unitq(job->body_rot)) return fail(why, why_size, "body_rot is not a unit quaternion");
    if (job->side != KIN_SIDE_LEFT && job->side != KIN_SIDE_RIGHT)
        return fail(why, why_size, "bad side %d", (int)job->side);
    if (!(job->upper_len > 0.0f && job->fore_len > 0.0f) || !isfinite(job->upper_len) ||
        !isfinite(job->fore_len))
        return fail(why, why_size, "bone lengths must be finite and > 0");
    const float *fl[] = { &job->elbow_max_deg, &job->soft, &job->hand_gain,
                          &job->twist_share, &job->twist_max_deg };
    for (size_t i = 0; i < sizeof fl / sizeof fl[0]; i++)
        if (!isfinite(*fl[i])) return fail(why, why_size, "a parameter is not finite");
    ik_params p = params_of(job);
    if (p.elbow_max > DEG2RAD(179.0f))
        return fail(why, why_size, "elbow_max_deg must be <= 179");
    if (!(p.soft > 0.5f && p.soft < 1.0f)) return fail(why, why_size, "soft must be in (0.5, 1)");
    if (p.twist_share > 1.0f) return fail(why, why_size, "twist_share must be <= 1");
    if (p.hand_gain > 2.0f) return fail(why, why_size, "hand_gain must be <= 2");
    if (p.twist_max > PI_F) return fail(why, why_size, "twist_max_deg must be <= 180");
    float dmax = job->upper_len + job->fore_len;
    float dmin = reach_at(job->upper_len, job->fore_len, p.elbow_max);
    if (dmin + (1.0f - p.soft) * dmax >= p.soft * dmax)
        return fail(why, why_size, "no reach left between the soft limits "
                                   "(elbow_max too small or bones too unequal)");
    return 1;
}

static kin_vec3 perp(kin_vec3 v, kin_vec3 u)
{
    return kin_v3_sub(v, kin_v3_scale(u, kin_v3_dot(u, v)));
}

static kin_vec3 rot_about(kin_vec3 v, kin_vec3 axis, float a)
{
    return kin_quat_rotate(kin_quat_axis_angle(axis, a), v);
}

int kin_arm_ik_run(kin_arm_ik_job *job)
{
    if (!kin_arm_ik_validate(job, NULL, 0)) return 0;
    const ik_params p = params_of(job);
    const float l1 = job->upper_len, l2 = job->fore_len;
    const float dmax = l1 + l2, dmin = reach_at(l1, l2, p.elbow_max);
    const float side = job->side == KIN_SIDE_RIGHT ? 1.0f : -1.0f;
    const kin_quat br = kin_quat_normalize(job->body_rot);
    const kin_quat hr = kin_quat_normalize(job->hand_rot);

    /* body directions */
    const kin_vec3 down = kin_quat_rotate(br, kin_v3(0.0f, -1.0f, 0.0f));
    const kin_vec3 Q = kin_quat_rotate(br, kin_v3_norm(kin_v3(-side, 0.0f, 1.0f)));
    const kin_vec3 fwd_down = kin_quat_rotate(br, kin_v3_norm(kin_v3(0.3f * side, -1.0f, -1.0f)));

    /* direction of the shoulder-wrist line; fades to fwd_down at the shoulder */
    kin_vec3 D = kin_v3_sub(job->wrist, job->shoulder);
    float d = kin_v3_len(D);
    float r0 = 0.5f * dmin;
    kin_vec3 u = kin_v3_norm(kin_v3_add(D, kin_v3_scale(fwd_down, fmaxf(0.0f, r0 - d))));
    if (kin_v3_len(u) == 0.0f) u = fwd_down;   /* the single point D = -fwd_down r0/2 */

    /* soft reach */
    float m = (1.0f - p.soft) * dmax;
    float hi = p.soft * dmax, lo = dmin + m, dd = d;
    if (dd > hi) dd = hi + m * (1.0f - expf(-(dd - hi) / m));
    else if (dd < lo) dd = lo - m * (1.0f - expf(-(lo - dd) / m));

    /* elbow angle at the shoulder (law of cosines) */
    float ca = (l1 * l1 + dd * dd - l2 * l2) / (2.0f * l1 * dd);
    ca = fminf(1.0f, fmaxf(-1.0f, ca));
    float sa = sqrtf(fmaxf(0.0f, 1.0f - ca * ca));

    /* swivel: the body's dipole field b(u), turned towards the hand */
    kin_vec3 wq = kin_v3_norm(kin_v3_sub(u, Q));
    kin_vec3 refl = kin_v3_sub(down, kin_v3_scale(wq, 2.0f * kin_v3_dot(down, wq)));
    kin_vec3 bh = kin_v3_norm(perp(refl, u));
    if (kin_v3_len(bh) == 0.0f) { /* u = Q exactly: any perpendicular */
        bh = kin_v3_norm(perp(down, u));
        if (kin_v3_len(bh) == 0.0f) bh = kin_v3_norm(perp(kin_v3(1.0f, 0.0f, 0.0f), u));
    }
    kin_vec3 finger = kin_quat_rotate(hr, kin_v3(0.0f, 0.0f, -1.0f));
    kin_vec3 h = perp(kin_v3_scale(finger, -1.0f), u);
    float swv = p.hand_gain * kin_v3_dot(h, kin_v3_cross(u, bh));
    kin_vec3 pv = kin_v3_norm(rot_about(bh, u, swv));

    kin_vec3 S = job->shoulder;
    kin_vec3 du = kin_v3_add(kin_v3_scale(u, ca), kin_v3_scale(pv, sa));
    kin_vec3 E = kin_v3_add(S, kin_v3_scale(du, l1));
    kin_vec3 W = kin_v3_add(S, kin_v3_scale(u, dd));
    kin_vec3 df = kin_v3_norm(kin_v3_sub(W, E));
    kin_vec3 n = kin_v3_norm(kin_v3_cross(pv, u));   /* hinge, = du x df when bent */

    kin_vec3 zu = kin_v3_scale(du, -1.0f);
    kin_quat upper = kin_quat_from_axes(n, kin_v3_cross(zu, n), zu);
    kin_vec3 zf = kin_v3_scale(df, -1.0f);
    kin_vec3 yf = kin_v3_cross(zf, n);
    kin_vec3 yh = kin_quat_rotate(hr, kin_v3(0.0f, 1.0f, 0.0f));
    kin_vec3 yp = perp(yh, zf);
    float roll = atan2f(kin_v3_dot(kin_v3_cross(yf, yp), zf), kin_v3_dot(yf, yp));
    float tw = fminf(p.twist_max, fmaxf(-p.twist_max, p.twist_share * roll));
    kin_vec3 xf = rot_about(n, zf, tw);
    yf = rot_about(yf, zf, tw);
    kin_quat fore = kin_quat_from_axes(xf, yf, zf);

    job->elbow = E;
    job->wrist_out = W;
    job->upper_rot = upper;
    job->fore_rot = fore;
    job->flexion = atan2f(kin_v3_len(kin_v3_cross(du, df)), kin_v3_dot(du, df));
    job->swivel = swv;
    job->reach_error = kin_v3_len(kin_v3_sub(W, job->wrist));
    return 1;
}

/* -------------------------------------------------------------------- rig */

static const char *const rig_names[KIN_RIG_SIDE_JOINTS] = {
    "shoulder", "upper_arm", "forearm", "hand", "palm",
    "thumb_1", "thumb_2", "thumb_3", "index_1", "index_2", "index_3",
    "middle_1", "middle_2", "middle_3", "ring_1", "ring_2", "ring_3",
    "little_1", "little_2", "little_3",
};

const char *kin_arm_rig_joint_name(kin_side side, int j, char *buf, size_t n)
{
    if (j < 0 || j >= KIN_RIG_SIDE_JOINTS) snprintf(buf, n, "?");
    else snprintf(buf, n, "%s%s", side == KIN_SIDE_RIGHT ? "R_" : "L_", rig_names[j]);
    return buf;
}

/* Parent of joint j in the rig chain (-1 for the shoulder: the body). */
static int rig_parent(int j)
{
    if (j == KIN_RIG_SHOULDER) return -1;
    if (j <= KIN_RIG_PALM) return j - 1;
    int k = (j - KIN_RIG_FINGER0) % 3;
    return k == 0 ? KIN_RIG_PALM : j - 1;
}

static int offset_along_minus_z(kin_vec3 t)
{
    float l = kin_v3_len(t);
    return l > 0.0f && fabsf(t.x) <= 1e-3f * l && fabsf(t.y) <= 1e-3f * l && t.z < 0.0f;
}

int kin_arm_rig_init(kin_arm_rig *rig, const kin_model *model, char *why, size_t why_size)
{
    if (!rig || !model || !model->names || !model->parents || !model->rest)
        return fail(why, why_size, "no model") - 1;
    memset(rig, 0, sizeof *rig);
    char missing[512];
    size_t ml = 0;
    int nmiss = 0;
    missing[0] = '\0';
#define MISSING(name)                                                              \
    do {                                                                           \
        nmiss++;                                                                   \
        if (ml < sizeof missing) {                                                 \
            int w_ = snprintf(missing + ml, sizeof missing - ml, "%s%s",           \
                              ml ? ", " : "", (name));                             \
            if (w_ > 0) ml += (size_t)w_;                                          \
        }                                                                          \
    } while (0)
    rig->body = kin_model_find_node(model, "body");
    if (rig->body < 0) MISSING("body");
    rig->head = kin_model_find_node(model, "head");
    if (rig->head < 0) MISSING("head");
    char name[KIN_NAME_MAX];
    for (int s = 0; s < 2; s++)
        for (int j = 0; j < KIN_RIG_SIDE_JOINTS; j++) {
            kin_arm_rig_joint_name((kin_side)s, j, name, sizeof name);
            rig->joint[s][j] = kin_model_find_node(model, name);
            if (rig->joint[s][j] < 0) MISSING(name);
        }
#undef MISSING
    if (nmiss) {
        if (ml >= sizeof missing) memcpy(missing + sizeof missing - 5, ", ...", 5);
        return fail(why, why_size, "missing joints (%d): %s", nmiss, missing) - 1;
    }
    if (model->parents[rig->body] != KIN_NO_PARENT)
        return fail(why, why_size, "'body' must be a root node") - 1;
    if (model->parents[rig->head] != rig->body)
        return fail(why, why_size, "'head' must be a child of 'body'") - 1;
    for (int s = 0; s < 2; s++)
        for (int j = 0; j < KIN_RIG_SIDE_JOINTS; j++) {
            int pj = rig_parent(j);
            int want = pj < 0 ? rig->body : rig->joint[s][pj];
            if (model->parents[rig->joint[s][j]] != want) {
                char a[KIN_NAME_MAX], b[KIN_NAME_MAX];
                kin_arm_rig_joint_name((kin_side)s, j, a, sizeof a);
                snprintf(b, sizeof b, "%s", pj < 0 ? "body"
                                               : kin_arm_rig_joint_name((kin_side)s, pj, name,
                                                                        sizeof name));
                return fail(why, why_size, "'%s' must be a child of '%s'", a, b) - 1;
            }
        }
    for (int s = 0; s < 2; s++) {
        kin_vec3 tf = model->rest[rig->joint[s][KIN_RIG_FOREARM]].t;
        kin_vec3 th = model->rest[rig->joint[s][KIN_RIG_HAND]].t;
        if (!offset_along_minus_z(tf) || !offset_along_minus_z(th)) {
            kin_arm_rig_joint_name((kin_side)s, KIN_RIG_UPPER_ARM, name, sizeof name);
            return fail(why, why_size, "%s: the forearm and hand offsets must lie along "
                                       "-Z of their parents (bone frame convention)", name) - 1;
        }
        rig->upper_len[s] = kin_v3_len(tf);
        rig->fore_len[s] = kin_v3_len(th);
    }
    /* shoulder width: upper_arm positions in the body frame (rest) */
    kin_vec3 pos[2];
    for (int s = 0; s < 2; s++) {
        const kin_transform *sh = &model->rest[rig->joint[s][KIN_RIG_SHOULDER]];
        const kin_transform *ua = &model->rest[rig->joint[s][KIN_RIG_UPPER_ARM]];
        pos[s] = kin_v3_add(sh->t, kin_quat_rotate(sh->r, ua->t));
    }
    rig->shoulder_width = kin_v3_len(kin_v3_sub(pos[1], pos[0]));
    if (!(rig->shoulder_width > 0.0f))
        return fail(why, why_size, "the two shoulders coincide") - 1;
    return 0;
}

/* Rigid transform (no scale) used to place the body chain. */
typedef struct rigid { kin_vec3 t; kin_quat r; } rigid;

static rigid rigid_mul(rigid a, rigid b)
{
    rigid c = { kin_v3_add(a.t, kin_quat_rotate(a.r, b.t)), kin_quat_mul(a.r, b.r) };
    return c;
}

int kin_arm_rig_pose(const kin_arm_rig *rig, const kin_model *model,
                     const kin_user_calib *calib, const kin_arm_ik_job *ik_params,
                     const kin_track_sample *sample, kin_transform *locals,
                     kin_arm_ik_job ik_out[2])
{
    if (!rig || !model || !sample || !locals) return 0;
    if (kin_track_sample_validate(sample, NULL, 0) < 0) return 0;
    kin_user_calib ident = kin_user_calib_identity();
    const kin_user_calib *c = calib ? calib : &ident;
    const kin_transform *rest = model->rest;

    /* 1. bone lengths of this user */
    for (int s = 0; s < 2; s++) {
        const int *J = rig->joint[s];
        locals[J[KIN_RIG_SHOULDER]].t = kin_v3_scale(rest[J[KIN_RIG_SHOULDER]].t, c->shoulder_scale);
        locals[J[KIN_RIG_UPPER_ARM]].t = kin_v3_scale(rest[J[KIN_RIG_UPPER_ARM]].t, c->shoulder_scale);
        locals[J[KIN_RIG_FOREARM]].t = kin_v3_scale(rest[J[KIN_RIG_FOREARM]].t, c->arm_scale[s]);
        locals[J[KIN_RIG_HAND]].t = kin_v3_scale(rest[J[KIN_RIG_HAND]].t, c->arm_scale[s]);
        for (int j = KIN_RIG_PALM; j < KIN_RIG_SIDE_JOINTS; j++)
            locals[J[j]].t = kin_v3_scale(rest[J[j]].t, c->hand_scale[s]);
    }

    /* 2. body at the shoulders */
    const uint32_t v = sample->valid;
    rigid body = { locals[rig->body].t, kin_quat_normalize(locals[rig->body].r) };
    if ((v & KIN_TRACK_SHOULDER_L) && (v & KIN_TRACK_SHOULDER_R)) {
        kin_vec3 mid = kin_v3_scale(kin_v3_add(sample->shoulder[0], sample->shoulder[1]), 0.5f);
        kin_vec3 head = (v & KIN_TRACK_HEAD) ? sample->head_pos : kin_v3_add(mid, kin_v3(0, 1, 0));
        body.r = kin_body_frame(sample->shoulder[0], sample->shoulder[1], head);
        kin_vec3 off = kin_v3(0, 0, 0);
        for (int s = 0; s < 2; s++) {
            const kin_transform *sh = &locals[rig->joint[s][KIN_RIG_SHOULDER]];
            const kin_transform *ua = &locals[rig->joint[s][KIN_RIG_UPPER_ARM]];
            off = kin_v3_add(off, kin_v3_add(sh->t, kin_quat_rotate(sh->r, ua->t)));
        }
        off = kin_v3_scale(off, 0.5f);
        body.t = kin_v3_sub(mid, kin_quat_rotate(body.r, off));
        locals[rig->body].t = body.t;
        locals[rig->body].r = body.r;
        locals[rig->body].s = kin_v3(1, 1, 1);
    }

    /* 3. head (a child of body) */
    if (v & KIN_TRACK_HEAD) {
        kin_quat ib = kin_quat_conjugate(body.r);
        locals[rig->head].t = kin_quat_rotate(ib, kin_v3_sub(sample->head_pos, body.t));
        locals[rig->head].r = kin_quat_normalize(kin_quat_mul(ib, sample->head_rot));
    }

    /* 4. arms and hands */
    for (int s = 0; s < 2; s++) {
        const int *J = rig->joint[s];
        rigid sh = rigid_mul(body, (rigid){ locals[J[KIN_RIG_SHOULDER]].t,
                                            kin_quat_normalize(locals[J[KIN_RIG_SHOULDER]].r) });
        rigid ua = rigid_mul(sh, (rigid){ locals[J[KIN_RIG_UPPER_ARM]].t,
                                          kin_quat_normalize(locals[J[KIN_RIG_UPPER_ARM]].r) });
        if (v & (KIN_TRACK_HAND_L << s)) {
            kin_arm_ik_job job;
            if (ik_params) job = *ik_params;
            else memset(&job, 0, sizeof job);
            job.shoulder = ua.t;
            job.wrist = sample->hand_pos[s];
            job.hand_rot = sample->hand_rot[s];
            job.body_rot = body.r;
            job.side = (kin_side)s;
            job.upper_len = rig->upper_len[s] * c->arm_scale[s];
            job.fore_len = rig->fore_len[s] * c->arm_scale[s];
            if (!kin_arm_ik_run(&job)) return 0;
            locals[J[KIN_RIG_UPPER_ARM]].r =
                kin_quat_normalize(kin_quat_mul(kin_quat_conjugate(sh.r), job.upper_rot));
            locals[J[KIN_RIG_FOREARM]].r =
                kin_quat_normalize(kin_quat_mul(kin_quat_conjugate(job.upper_rot), job.fore_rot));
            locals[J[KIN_RIG_HAND]].r = kin_quat_normalize(
                kin_quat_mul(kin_quat_conjugate(job.fore_rot), sample->hand_rot[s]));
            if (ik_out) ik_out[s] = job;
        }
        if (v & (KIN_TRACK_GLOVE_L << s)) {
            kin_quat rr[KIN_HAND_JOINTS], out[KIN_HAND_JOINTS];
            for (int f = 0; f < KIN_HAND_JOINTS; f++) rr[f] = rest[J[KIN_RIG_FINGER0 + f]].r;
            kin_hand_job hj = { sample->glove[s], NULL, rr, (kin_side)s, out, NULL };
            if (!kin_hand_run(&hj)) return 0;
            for (int f = 0; f < KIN_HAND_JOINTS; f++) locals[J[KIN_RIG_FINGER0 + f]].r = out[f];
        }
    }
    return 1;
}
