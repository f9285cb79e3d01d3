/* kin_morph.c - glTF morph targets: weights from an animation's `weights`
 * channel, and the weighted sum of the targets' deltas (before skinning).
 *
 * Sampling is kin_anim.c's kin__channel_value (clamp to the first and
 * last key; STEP, LINEAR per component, CUBICSPLINE with the Hermite
 * basis of glTF appendix C) for any number of components. No allocation, no state. */
#include "kin.h"
#include "kin_internal.h"

#include <string.h>

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
    kin__channel_value(last, t, weights);
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
