/* kin_anim.c - rest pose and glTF 2.0 animation sampling.
 *
 * Per channel: clamp t to [first, last] key, find the key interval
 * [t0, t1) holding t, u = (t - t0) / (t1 - t0), then
 *   STEP:        v_k
 *   LINEAR:      (1-u) v_k + u v_k+1       (slerp for rotations)
 *   CUBICSPLINE: (2u^3 - 3u^2 + 1) v_k + td (u^3 - 2u^2 + u) b_k
 *              + (-2u^3 + 3u^2) v_k+1 + td (u^3 - u^2) a_k+1
 * with td = t1 - t0, a = in-tangent, b = out-tangent (glTF appendix C).
 * Rotations are renormalised. No allocation, no state. */
#include "kin.h"
#include "kin_internal.h"

#include <string.h>

void kin_pose_rest(const kin_model *model, kin_transform *locals)
{
    if (!model || !locals || model->node_count <= 0 || !model->rest) return;
    memcpy(locals, model->rest, (size_t)model->node_count * sizeof *locals);
}

/* Index k of the last key with times[k] <= t, for times[0] < t < times[n-1]. */
static int find_key(const float *times, int n, float t)
{
    int lo = 0, hi = n - 1; /* invariant: times[lo] <= t < times[hi] */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (times[mid] <= t) lo = mid;
        else hi = mid;
    }
    return lo;
}

/* Start of the value of key k (skipping the in-tangent for CUBICSPLINE). */
static const float *key_value(const kin_channel *ch, int k)
{
    if (ch->interp == KIN_INTERP_CUBICSPLINE)
        return ch->values + ((size_t)k * 3 + 1) * (size_t)ch->comps;
    return ch->values + (size_t)k * (size_t)ch->comps;
}

/* The channel's comps values at time t (kin_internal.h): the sampling
 * of the file's opening comment, LINEAR rotations by slerp; also the
 * morph weights of kin_morph.c. */
void kin__channel_value(const kin_channel *ch, float t, float *out)
{
    const int n = ch->key_count, c = ch->comps;
    const float *times = ch->times;

    /* Clamp (NaN goes to the first key). */
    if (n == 1 || !(t > times[0])) {
        memcpy(out, key_value(ch, 0), sizeof(float) * (size_t)c);
        return;
    }
    if (t >= times[n - 1]) {
        memcpy(out, key_value(ch, n - 1), sizeof(float) * (size_t)c);
        return;
    }

    int k = find_key(times, n, t);
    float td = times[k + 1] - times[k];
    float u = (t - times[k]) / td;
    const float *v0 = key_value(ch, k), *v1 = key_value(ch, k + 1);

    switch (ch->interp) {
    case KIN_INTERP_STEP:
        memcpy(out, v0, sizeof(float) * (size_t)c);
        return;
    case KIN_INTERP_CUBICSPLINE: {
        const float *b0 = v0 + c;  /* out-tangent of key k */
        const float *a1 = v1 - c;  /* in-tangent of key k+1 */
        float u2 = u * u, u3 = u2 * u;
        float h00 = 2.0f * u3 - 3.0f * u2 + 1.0f;
        float h10 = (u3 - 2.0f * u2 + u) * td;
        float h01 = -2.0f * u3 + 3.0f * u2;
        float h11 = (u3 - u2) * td;
        for (int i = 0; i < c; i++)
            out[i] = h00 * v0[i] + h10 * b0[i] + h01 * v1[i] + h11 * a1[i];
        return;
    }
    case KIN_INTERP_LINEAR:
    default:
        if (ch->path == KIN_PATH_ROTATION) {
            kin_quat a = { v0[0], v0[1], v0[2], v0[3] };
            kin_quat b = { v1[0], v1[1], v1[2], v1[3] };
            kin_quat q = kin_quat_slerp(a, b, u);
            out[0] = q.x; out[1] = q.y; out[2] = q.z; out[3] = q.w;
        } else {
            for (int i = 0; i < c; i++) out[i] = v0[i] + (v1[i] - v0[i]) * u;
        }
        return;
    }
}

static void store(const kin_channel *ch, const float *v, kin_transform *dst)
{
    switch (ch->path) {
    case KIN_PATH_TRANSLATION: dst->t = kin_v3(v[0], v[1], v[2]); break;
    case KIN_PATH_SCALE: dst->s = kin_v3(v[0], v[1], v[2]); break;
    case KIN_PATH_ROTATION: {
        kin_quat q = { v[0], v[1], v[2], v[3] };
        dst->r = kin_quat_normalize(q);
        break;
    }
    default: break;
    }
}

static void sample_channel(const kin_channel *ch, float t, kin_transform *dst)
{
    float out[4];
    kin__channel_value(ch, t, out);
    store(ch, out, dst);
}

void kin_anim_sample(const kin_animation *anim, int node_count, float t,
                     kin_transform *locals)
{
    if (!anim || !locals || !anim->channels) return;
    for (int i = 0; i < anim->channel_count; i++) {
        const kin_channel *ch = &anim->channels[i];
        if (ch->node < 0 || ch->node >= node_count) continue;
        if (ch->key_count < 1 || !ch->times || !ch->values) continue;
        int want;
        switch (ch->path) {
        case KIN_PATH_TRANSLATION:
        case KIN_PATH_SCALE: want = 3; break;
        case KIN_PATH_ROTATION: want = 4; break;
        default: continue; /* WEIGHTS (morph targets) and INVALID: not applied */
        }
        if (ch->comps != want) continue;
        sample_channel(ch, t, &locals[ch->node]);
    }
}
