/* kin_model.c - ownership and validation of kin_model. */
#include "kin.h"
#include "kin_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Each allocation is preceded by a header linking it into the chain. The
 * header is 16 bytes so the payload stays 16-byte aligned. */
typedef struct block_hdr {
    struct block_hdr *next;
    size_t size;
} block_hdr;

void *kin_block_alloc(void **block, size_t size)
{
    block_hdr *h = calloc(1, sizeof(block_hdr) + (size ? size : 1));
    if (!h) return NULL;
    h->next = *block;
    h->size = size;
    *block = h;
    return h + 1;
}

void kin_model_free(kin_model *model)
{
    if (!model) return;
    block_hdr *h = model->block;
    while (h) {
        block_hdr *next = h->next;
        free(h);
        h = next;
    }
    memset(model, 0, sizeof *model);
}

int kin_model_find_node(const kin_model *model, const char *name)
{
    if (!model || !name || !model->names) return -1;
    for (int i = 0; i < model->node_count; i++)
        if (strcmp(model->names[i], name) == 0) return i;
    return -1;
}

const kin_animation *kin_model_find_anim(const kin_model *model, const char *name)
{
    if (!model) return NULL;
    for (int i = 0; i < model->anim_count; i++)
        if (!name || !name[0] || strcmp(model->anims[i].name, name) == 0) return &model->anims[i];
    return NULL;
}

#define fail(why, n, ...) kin__fail(why, n, -1, __VA_ARGS__)

static int finite_all(const float *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

int kin_model_validate(const kin_model *m, char *why, size_t why_size)
{
    if (!m) return fail(why, why_size, "no model");
    if (m->node_count < 0 || m->node_count > KIN_MAX_NODES)
        return fail(why, why_size, "node count %d out of range (0..%d)",
                    m->node_count, KIN_MAX_NODES);
    if (m->node_count > 0 && (!m->parents || !m->rest))
        return fail(why, why_size, "nodes without parents or rest transforms");
    for (int i = 0; i < m->node_count; i++) {
        int p = m->parents[i];
        if (p != KIN_NO_PARENT && (p < 0 || p >= i))
            return fail(why, why_size,
                        "node %d has parent %d: parents must come first", i, p);
        const kin_transform *t = &m->rest[i];
        if (!finite_all(&t->t.x, 3) || !finite_all(&t->r.x, 4) ||
            !finite_all(&t->s.x, 3))
            return fail(why, why_size, "node %d has a non-finite transform", i);
    }
    for (int s = 0; s < m->skin_count; s++) {
        const kin_skin *sk = &m->skins[s];
        if (sk->joint_count <= 0 || !sk->joints || !sk->inverse_bind)
            return fail(why, why_size, "skin %d has no joints", s);
        for (int j = 0; j < sk->joint_count; j++) {
            if (sk->joints[j] < 0 || sk->joints[j] >= m->node_count)
                return fail(why, why_size, "skin %d joint %d names node %d of %d",
                            s, j, sk->joints[j], m->node_count);
            if (!finite_all(sk->inverse_bind[j].m, 16))
                return fail(why, why_size,
                            "skin %d inverse bind matrix %d is not finite", s, j);
        }
    }
    for (int k = 0; k < m->mesh_count; k++) {
        const kin_mesh *me = &m->meshes[k];
        if (me->vertex_count <= 0 || !me->positions)
            return fail(why, why_size, "mesh %d has no positions", k);
        if (me->index_count < 0 || me->index_count % 3 != 0 ||
            (me->index_count > 0 && !me->indices))
            return fail(why, why_size,
                        "mesh %d has %d indices (not a multiple of 3)", k,
                        me->index_count);
        for (int i = 0; i < me->index_count; i++)
            if (me->indices[i] >= (uint32_t)me->vertex_count)
                return fail(why, why_size,
                            "mesh %d index %d is %u, past its %d vertices", k, i,
                            me->indices[i], me->vertex_count);
        if (!finite_all(me->positions, (size_t)me->vertex_count * 3))
            return fail(why, why_size, "mesh %d has non-finite positions", k);
        if (me->normals &&
            !finite_all(me->normals, (size_t)me->vertex_count * 3))
            return fail(why, why_size, "mesh %d has non-finite normals", k);
        if (me->target_count < 0 ||
            (me->target_count > 0 && (!me->target_positions || !me->target_weights)))
            return fail(why, why_size, "mesh %d has %d morph targets without data", k,
                        me->target_count);
        if (me->target_count > 0) {
            size_t nd = (size_t)me->target_count * (size_t)me->vertex_count * 3;
            if (!finite_all(me->target_positions, nd) ||
                (me->target_normals && !finite_all(me->target_normals, nd)) ||
                !finite_all(me->target_weights, (size_t)me->target_count))
                return fail(why, why_size, "mesh %d has non-finite morph targets or weights", k);
        }
        if (me->extra_sets < 0 ||
            (me->extra_sets > 0 && (!me->joints_extra || !me->weights_extra || !me->joints)))
            return fail(why, why_size, "mesh %d has %d extra influence sets without data", k,
                        me->extra_sets);
        if (me->node < -1 || me->node >= m->node_count)
            return fail(why, why_size, "mesh %d belongs to node %d of %d", k,
                        me->node, m->node_count);
        if (me->skin >= 0) {
            if (me->skin >= m->skin_count)
                return fail(why, why_size, "mesh %d uses skin %d of %d", k,
                            me->skin, m->skin_count);
            if (!me->joints || !me->weights)
                return fail(why, why_size,
                            "mesh %d is skinned but has no JOINTS_0/WEIGHTS_0", k);
            int jc = m->skins[me->skin].joint_count;
            for (int v = 0; v < me->vertex_count; v++) {
                for (int c = 0; c < 4; c++) {
                    float w = me->weights[v * 4 + c];
                    if (!isfinite(w) || w < 0.0f)
                        return fail(why, why_size,
                                    "mesh %d vertex %d has weight %g", k, v, w);
                    if (w > 0.0f && me->joints[v * 4 + c] >= jc)
                        return fail(why, why_size,
                                    "mesh %d vertex %d uses joint %u of %d", k,
                                    v, me->joints[v * 4 + c], jc);
                }
                for (int c = 0; c < 4 * me->extra_sets; c++) {
                    size_t e = (size_t)v * 4 * (size_t)me->extra_sets + (size_t)c;
                    float w = me->weights_extra[e];
                    if (!isfinite(w) || w < 0.0f)
                        return fail(why, why_size,
                                    "mesh %d vertex %d has weight %g (set %d)", k, v, w,
                                    1 + c / 4);
                    if (w > 0.0f && me->joints_extra[e] >= jc)
                        return fail(why, why_size,
                                    "mesh %d vertex %d uses joint %u of %d (set %d)", k,
                                    v, me->joints_extra[e], jc, 1 + c / 4);
                }
            }
        }
    }
    for (int a = 0; a < m->anim_count; a++) {
        const kin_animation *an = &m->anims[a];
        for (int c = 0; c < an->channel_count; c++) {
            const kin_channel *ch = &an->channels[c];
            if (ch->node < 0 || ch->node >= m->node_count)
                return fail(why, why_size,
                            "animation %d channel %d targets node %d of %d", a,
                            c, ch->node, m->node_count);
            if (ch->key_count < 1 || !ch->times || !ch->values || ch->comps < 1)
                return fail(why, why_size, "animation %d channel %d has no keys",
                            a, c);
            for (int i = 0; i < ch->key_count; i++) {
                if (!isfinite(ch->times[i]) ||
                    (i > 0 && !(ch->times[i] > ch->times[i - 1])))
                    return fail(why, why_size,
                                "animation %d channel %d: key time %d (%g) is "
                                "not finite and increasing", a, c, i,
                                ch->times[i]);
            }
            size_t nv = (size_t)ch->key_count * (size_t)ch->comps *
                        (ch->interp == KIN_INTERP_CUBICSPLINE ? 3u : 1u);
            if (!finite_all(ch->values, nv))
                return fail(why, why_size,
                            "animation %d channel %d has non-finite values", a, c);
        }
    }
    return 0;
}
