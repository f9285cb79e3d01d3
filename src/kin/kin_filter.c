/* kin_filter.c - One Euro filter (Casiez, Roussel, Vogel, CHI 2012) per
 * tracked part, constant-velocity prediction to the display time, and
 * dropout handling (hold the pose, then fade its confidence).
 *
 * Per part and accepted measurement z at time t (dt = t - t_part > 0):
 *   a(fc)  = 1 / (1 + 1 / (2 pi fc dt))
 *   dx     = dx + a(d_cutoff) ((z - z_prev) / dt - dx)   velocity, smoothed
 *   fc     = min_cutoff + beta |dx|
 *   x      = x + a(fc) (z - x)
 * The velocity is taken from raw differences (z_prev: the previous raw
 * measurement), not from the filtered value as in the paper's pseudo code,
 * whose derivative is 1/a times too large on a ramp; it only drives the
 * cutoff there, here it also drives the prediction.
 * Rotations: the measured quaternion is put on the filtered one's
 * hemisphere, w (world angular velocity) is smoothed from the rotation
 * z * conj(z_prev) over dt, and q = slerp(q, z, a(fc)). Gloves: the same
 * scalar filter per sensor with beta = 1 s (no prediction).
 * Prediction adds the low-pass's ramp lag dt (1 - a) / a to the horizon,
 * so a constant velocity is extrapolated without the filter's delay.
 * A part whose last measurement is older than hold_s + fade_s restarts
 * from the next measurement (no velocity across a long gap). */
#include "kin.h"

#include <math.h>
#include <string.h>

#define PI_D 3.14159265358979323846
#define GLOVE_BETA 1.0f

enum { P_HEAD = 0, P_SH_L, P_SH_R, P_HAND_L, P_HAND_R, P_GLOVE_L, P_GLOVE_R };

static float def(float v, float d) { return (v > 0.0f && isfinite(v)) ? v : d; }

kin_filter_desc kin_filter_desc_resolved(const kin_filter_desc *d)
{
    kin_filter_desc z;
    memset(&z, 0, sizeof z);
    if (!d) d = &z;
    kin_filter_desc r;
    r.min_cutoff_hz = def(d->min_cutoff_hz, 1.5f);
    r.beta = def(d->beta, 4.0f);
    r.rot_min_cutoff_hz = def(d->rot_min_cutoff_hz, 1.5f);
    r.rot_beta = def(d->rot_beta, 0.5f);
    r.glove_min_cutoff_hz = def(d->glove_min_cutoff_hz, 3.0f);
    r.d_cutoff_hz = def(d->d_cutoff_hz, 1.0f);
    r.max_predict_s = def(d->max_predict_s, 0.1f);
    r.hold_s = def(d->hold_s, 0.15f);
    r.fade_s = def(d->fade_s, 0.35f);
    r.reset_s = def(d->reset_s, 0.5f);
    r.no_lag_comp = d->no_lag_comp ? 1 : 0;
    return r;
}

void kin_filter_init(kin_filter *f, const kin_filter_desc *desc)
{
    memset(f, 0, sizeof *f);
    f->desc = kin_filter_desc_resolved(desc);
}

static float alpha(float fc, float dt)
{
    return (float)(1.0 / (1.0 + 1.0 / (2.0 * PI_D * (double)fc * (double)dt)));
}

static kin_vec3 lerp3(kin_vec3 a, kin_vec3 b, float t)
{
    return kin_v3_add(a, kin_v3_scale(kin_v3_sub(b, a), t));
}

static int finite3(kin_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }
static int goodq(kin_quat q)
{
    float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    return isfinite(l) && fabsf(l - 1.0f) <= 1e-3f;
}

/* Rotation vector (axis * angle, angle in [0, pi]) of a unit quaternion. */
static kin_vec3 quat_log2(kin_quat q)
{
    if (q.w < 0.0f) { q.x = -q.x; q.y = -q.y; q.z = -q.z; q.w = -q.w; }
    float s = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
    if (s < 1e-12f) return kin_v3(2.0f * q.x, 2.0f * q.y, 2.0f * q.z);
    float a = 2.0f * atan2f(s, q.w);
    return kin_v3_scale(kin_v3(q.x, q.y, q.z), a / s);
}

static kin_quat quat_exp2(kin_vec3 r)
{
    float a = kin_v3_len(r);
    if (a < 1e-12f) return kin_quat_normalize((kin_quat){ 0.5f * r.x, 0.5f * r.y, 0.5f * r.z, 1.0f });
    return kin_quat_axis_angle(kin_v3_scale(r, 1.0f / a), a);
}

/* Updates a part's position / rotation (either may be NULL). */
static void update(const kin_filter_desc *d, kin_filter_part *p, double t, const kin_vec3 *z,
                   const kin_quat *zq, const float *zg)
{
    float dt = (float)(t - p->t);
    int fresh = !p->has || !(dt > 0.0f) || (double)dt > (double)d->hold_s + d->fade_s;
    if (fresh) {
        p->has = 1;
        if (z) { p->x = p->z = *z; p->dx = kin_v3(0, 0, 0); p->lag = 0.0f; }
        if (zq) {
            p->q = p->zq = kin_quat_normalize(*zq);
            p->w = kin_v3(0, 0, 0);
            p->rot_lag = 0.0f;
        }
        if (zg)
            for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
                p->g[k] = p->zg[k] = zg[k];
                p->dg[k] = 0.0f;
            }
        p->t = t;
        return;
    }
    float ad = alpha(d->d_cutoff_hz, dt);
    if (z) {
        kin_vec3 raw = kin_v3_scale(kin_v3_sub(*z, p->z), 1.0f / dt);
        p->dx = lerp3(p->dx, raw, ad);
        float fc = d->min_cutoff_hz + d->beta * kin_v3_len(p->dx);
        float a = alpha(fc, dt);
        p->x = lerp3(p->x, *z, a);
        p->lag = dt * (1.0f - a) / a;
        p->z = *z;
    }
    if (zq) {
        kin_quat m = kin_quat_normalize(*zq);
        if (m.x * p->q.x + m.y * p->q.y + m.z * p->q.z + m.w * p->q.w < 0.0f) {
            m.x = -m.x; m.y = -m.y; m.z = -m.z; m.w = -m.w;
        }
        kin_vec3 raw = kin_v3_scale(quat_log2(kin_quat_mul(m, kin_quat_conjugate(p->zq))), 1.0f / dt);
        p->w = lerp3(p->w, raw, ad);
        float fc = d->rot_min_cutoff_hz + d->rot_beta * kin_v3_len(p->w);
        float a = alpha(fc, dt);
        p->q = kin_quat_normalize(kin_quat_slerp(p->q, m, a));
        p->rot_lag = dt * (1.0f - a) / a;
        p->zq = m;
    }
    if (zg)
        for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
            float raw = (zg[k] - p->zg[k]) / dt;
            p->dg[k] += ad * (raw - p->dg[k]);
            float fc = d->glove_min_cutoff_hz + GLOVE_BETA * fabsf(p->dg[k]);
            p->g[k] += alpha(fc, dt) * (zg[k] - p->g[k]);
            p->zg[k] = zg[k];
        }
    p->t = t;
}

int kin_filter_push(kin_filter *f, const kin_track_sample *s)
{
    if (!f || !s) return 0;
    if (!isfinite(s->t)) { f->nonfinite_parts++; return KIN_FILTER_NONFINITE; }
    int res = 0;
    if (f->started && !(s->t > f->last_t)) {
        if (f->last_t - s->t > (double)f->desc.reset_s) {
            kin_filter_desc d = f->desc;
            uint32_t acc = f->accepted, old = f->dropped_old, rs = f->restarts,
                     nf = f->nonfinite_parts;
            kin_filter_init(f, &d);
            f->accepted = acc; f->dropped_old = old; f->restarts = rs + 1; f->nonfinite_parts = nf;
            res |= KIN_FILTER_RESTART;
        } else {
            f->dropped_old++;
            return KIN_FILTER_OLD;
        }
    }
    f->started = 1;
    f->last_t = s->t;
    f->accepted++;
    res |= KIN_FILTER_ACCEPTED;
    const kin_filter_desc *d = &f->desc;
    const uint32_t v = s->valid;
    int bad = 0;
    if (v & KIN_TRACK_HEAD) {
        if (finite3(s->head_pos) && goodq(s->head_rot))
            update(d, &f->part[P_HEAD], s->t, &s->head_pos, &s->head_rot, NULL);
        else bad++;
    }
    for (int k = 0; k < 2; k++) {
        if (v & (KIN_TRACK_SHOULDER_L << k)) {
            if (finite3(s->shoulder[k])) update(d, &f->part[P_SH_L + k], s->t, &s->shoulder[k], NULL, NULL);
            else bad++;
        }
        if (v & (KIN_TRACK_HAND_L << k)) {
            if (finite3(s->hand_pos[k]) && goodq(s->hand_rot[k]))
                update(d, &f->part[P_HAND_L + k], s->t, &s->hand_pos[k], &s->hand_rot[k], NULL);
            else bad++;
        }
        if (v & (KIN_TRACK_GLOVE_L << k)) {
            int ok = 1;
            for (int g = 0; g < KIN_GLOVE_SENSORS; g++)
                if (!(s->glove[k][g] >= 0.0f && s->glove[k][g] <= 1.0f)) ok = 0;
            if (ok) update(d, &f->part[P_GLOVE_L + k], s->t, NULL, NULL, s->glove[k]);
            else bad++;
        }
    }
    if (bad) { f->nonfinite_parts += (uint32_t)bad; res |= KIN_FILTER_NONFINITE; }
    return res;
}

void kin_filter_output(const kin_filter *f, double display_t, kin_track_sample *out, float *conf)
{
    static const uint32_t bits[KIN_FILTER_PARTS] = {
        KIN_TRACK_HEAD, KIN_TRACK_SHOULDER_L, KIN_TRACK_SHOULDER_R, KIN_TRACK_HAND_L,
        KIN_TRACK_HAND_R, KIN_TRACK_GLOVE_L, KIN_TRACK_GLOVE_R,
    };
    memset(out, 0, sizeof *out);
    out->t = display_t;
    out->head_rot = out->hand_rot[0] = out->hand_rot[1] = kin_quat_identity();
    const kin_filter_desc *d = &f->desc;
    for (int i = 0; i < KIN_FILTER_PARTS; i++) {
        const kin_filter_part *p = &f->part[i];
        float c = 0.0f;
        if (p->has && isfinite(display_t)) {
            double age = display_t - p->t;
            float h = (float)(age < 0.0 ? 0.0 : (age > d->max_predict_s ? d->max_predict_s : age));
            if (age <= d->hold_s) c = 1.0f;
            else c = 1.0f - (float)((age - d->hold_s) / d->fade_s);
            if (c < 0.0f) c = 0.0f;
            if (c > 0.0f) {
                out->valid |= bits[i];
                float lag = d->no_lag_comp ? 0.0f : p->lag;
                float rlag = d->no_lag_comp ? 0.0f : p->rot_lag;
                kin_vec3 x = kin_v3_add(p->x, kin_v3_scale(p->dx, h + lag));
                kin_quat q = kin_quat_normalize(
                    kin_quat_mul(quat_exp2(kin_v3_scale(p->w, h + rlag)), p->q));
                switch (i) {
                case P_HEAD: out->head_pos = x; out->head_rot = q; break;
                case P_SH_L: case P_SH_R: out->shoulder[i - P_SH_L] = x; break;
                case P_HAND_L: case P_HAND_R:
                    out->hand_pos[i - P_HAND_L] = x; out->hand_rot[i - P_HAND_L] = q; break;
                default:
                    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
                        float g = p->g[k];
                        out->glove[i - P_GLOVE_L][k] = g < 0.0f ? 0.0f : (g > 1.0f ? 1.0f : g);
                    }
                }
            }
        }
        if (conf) conf[i] = c;
    }
}
