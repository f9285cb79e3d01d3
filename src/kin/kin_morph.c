/* kin_morph.c - glTF morph targets: weights from an animation's `weights`
 * channel, and the weighted sum of the targets' deltas (before skinning).
 *
 * Sampling follows kin_anim.c (clamp to the first and last key; STEP,
 * LINEAR per component, CUBICSPLINE with the Hermite basis of glTF
 * appendix C) for any number of components. No allocation, no state. */
#include "kin.h"

#include <string.h>

/* Index k of the last key with times[k] <= t, for times[0] < t < times[n-1]. */
static int find_key(const float *times, int n, float t)
{
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (times[mid] <= t) lo = mid;
        else hi = mid;
    }
    return lo;
}

static const float *key_value(const kin_channel *ch, int k)
{
    if (ch->interp == KIN_INTERP_CUBICSPLINE)
        return ch->values + ((size_t)k * 3 + 1) * (size_t)ch->comps;
    return ch->values + (size_t)k * (size_t)ch->comps;
}

static void sample_weights(const kin_channel *ch, float t, float *out)
{
    const int n = ch->key_count, c = ch->comps;
    const float *times = ch->times;
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
        const float *b0 = v0 + c, *a1 = v1 - c;
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
        for (int i = 0; i < c; i++) out[i] = v0[i] + (v1[i] - v0[i]) * u;
        return;
    }
}

int kin_anim_sample_weights(const kin_animation *anim, int node, float t,
                            float *weights, int count)
{
    if (!anim || !anim->channels || !weights || count <= 0) return 0;
    const kin_channel *last = NULL;
    for (int i = 0; i < anim->channel_count; i++) {
        const kin_channel *ch = &anim->channels[i];
        if (ch->path != KIN_PATH_WEIGHTS || ch->node != node || ch->comps != count) continue;
        if (ch->key_count < 1 || !ch->times || !ch->values) continue;
        last = ch;
    }
    if (!last) return 0;
    sample_weights(last, t, weights);
    return 1;
}

void kin_morph_apply(const kin_mesh *mesh, const float *weights, float *pos_out,
                     float *nrm_out, int v0, int v1)
{
    if (!mesh || !pos_out || !mesh->positions) return;
    if (v0 < 0) v0 = 0;
    if (v1 > mesh->vertex_count) v1 = mesh->vertex_count;
    if (v0 >= v1) return;
    const size_t nv = (size_t)mesh->vertex_count;
    const int nt = weights && mesh->target_positions ? mesh->target_count : 0;
    const int do_n = mesh->normals && nrm_out;
    const int nt_n = do_n && mesh->target_normals ? nt : 0;
    memcpy(pos_out + (size_t)v0 * 3, mesh->positions + (size_t)v0 * 3,
           sizeof(float) * 3 * (size_t)(v1 - v0));
    if (do_n)
        memcpy(nrm_out + (size_t)v0 * 3, mesh->normals + (size_t)v0 * 3,
               sizeof(float) * 3 * (size_t)(v1 - v0));
    for (int k = 0; k < nt; k++) {
        const float w = weights[k];
        if (w == 0.0f) continue;
        const float *d = mesh->target_positions + (size_t)k * nv * 3;
        for (size_t i = (size_t)v0 * 3; i < (size_t)v1 * 3; i++) pos_out[i] += w * d[i];
        if (k < nt_n) {
            const float *dn = mesh->target_normals + (size_t)k * nv * 3;
            for (size_t i = (size_t)v0 * 3; i < (size_t)v1 * 3; i++) nrm_out[i] += w * dn[i];
        }
    }
}
