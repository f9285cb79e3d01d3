/* kin_skin_plan.c - the skin plan (kin.h): a mesh's vertices grouped by
 * the joints they read, so that the skinning kernels broadcast each joint
 * matrix (or dual quaternion) to 16 vertices instead of gathering one per
 * vertex and influence.
 *
 * Build: every vertex gets a key, the joints of its nonzero weights in
 * influence order (n of them, 0..4), or n = 0 when the reference's weight
 * sum (the same float additions) is 0. Keys are sorted (n, joints, vertex
 * index), and each run of equal joint lists is cut into batches of 16
 * (kin__plan_batch): weights, bind positions and normals transposed to
 * SoA, the destination index per lane. A lane of a batch sums exactly the
 * reference's products in the reference's order (zero weights add +0
 * there, which changes no sum that started at +0), so every output byte
 * equals kin__skin_lbs_ref / kin__skin_dqs_ref; tests/test_kin_skin_plan.c
 * checks it on every ISA.
 *
 * Per frame: the ISA kernels (kin_skin_simd.inl) or, for EF_ISA_REF, the
 * reference itself per lane. No allocation, no state. */
#include "kin.h"
#include "kin_skin_internal.h"
#include "../cpu/cpu.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct plan_key {
    uint16_t j[4];            /* joints of the nonzero weights, rest 0 */
    int32_t n;                /* 0..4; 0: keeps the bind pose */
    int32_t v;                /* vertex index */
} plan_key;

_Static_assert(sizeof(plan_key) == 16, "plan_key is 16 bytes");
_Static_assert(sizeof(kin__plan_batch) % 64 == 0, "batches stay 64-byte aligned");

static int mesh_ok(const kin_mesh *m)
{
    return m && m->vertex_count >= 0 && (m->positions || m->vertex_count == 0) &&
           m->extra_sets == 0;
}

static int key_cmp(const void *pa, const void *pb)
{
    const plan_key *a = pa, *b = pb;
    if (a->n != b->n) return a->n < b->n ? -1 : 1;
    for (int i = 0; i < 4; i++)
        if (a->j[i] != b->j[i]) return a->j[i] < b->j[i] ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

static int same_group(const plan_key *a, const plan_key *b)
{
    return a->n == b->n && !memcmp(a->j, b->j, sizeof a->j);
}

/* Keys of all vertices into k, sorted; returns the batch count. */
static int sort_keys(const kin_mesh *m, plan_key *k, int *groups)
{
    const int skinned = m->joints && m->weights;
    for (int v = 0; v < m->vertex_count; v++) {
        plan_key *e = &k[v];
        memset(e, 0, sizeof *e);
        e->v = v;
        if (!skinned) continue;
        const float *w = m->weights + (size_t)v * 4;
        const uint16_t *j = m->joints + (size_t)v * 4;
        float wsum = 0.0f;    /* the reference's sum, in its order */
        for (int i = 0; i < 4; i++) {
            if (w[i] == 0.0f) continue;
            e->j[e->n++] = j[i];
            wsum += w[i];
        }
        if (wsum == 0.0f) { e->n = 0; memset(e->j, 0, sizeof e->j); }
    }
    if (m->vertex_count > 1) qsort(k, (size_t)m->vertex_count, sizeof *k, key_cmp);
    int batches = 0, g = 0;
    for (int s = 0; s < m->vertex_count;) {
        int e = s + 1;
        while (e < m->vertex_count && same_group(&k[s], &k[e])) e++;
        batches += (e - s + KIN__PLAN_W - 1) / KIN__PLAN_W;
        g++;
        s = e;
    }
    if (groups) *groups = g;
    return batches;
}

size_t kin_skin_plan_scratch_size(const kin_mesh *mesh)
{
    return mesh_ok(mesh) ? (size_t)mesh->vertex_count * sizeof(plan_key) : 0;
}

size_t kin_skin_plan_size(const kin_mesh *mesh, void *scratch)
{
    if (!mesh_ok(mesh) || (!scratch && mesh->vertex_count > 0)) return 0;
    int nb = sort_keys(mesh, scratch, NULL);
    return nb ? (size_t)nb * sizeof(kin__plan_batch) : sizeof(kin__plan_batch);
}

int kin_skin_plan_init(kin_skin_plan *plan, const kin_mesh *mesh, void *scratch,
                       void *mem, size_t size)
{
    if (!plan) return -1;
    memset(plan, 0, sizeof *plan);
    plan->max_joint = -1;
    if (!mesh_ok(mesh) || !mem || ((uintptr_t)mem & 63) || (!scratch && mesh->vertex_count > 0))
        return -1;
    plan_key *k = scratch;
    int groups = 0;
    int nb = sort_keys(mesh, k, &groups);
    if (size < (size_t)nb * sizeof(kin__plan_batch)) return -1;
    kin__plan_batch *bt = mem;
    memset(bt, 0, (size_t)nb * sizeof *bt);
    const int do_n = mesh->normals != NULL;
    int b = 0, max_joint = -1;
    for (int s = 0; s < mesh->vertex_count;) {
        int e = s + 1;
        while (e < mesh->vertex_count && same_group(&k[s], &k[e])) e++;
        for (int q = s; q < e; q += KIN__PLAN_W, b++) {
            kin__plan_batch *B = &bt[b];
            int lanes = e - q < KIN__PLAN_W ? e - q : KIN__PLAN_W;
            B->n = k[q].n;
            B->lanes = lanes;
            for (int i = 0; i < B->n; i++) {
                B->joint[i] = k[q].j[i];
                if (B->joint[i] > max_joint) max_joint = B->joint[i];
            }
            B->first = k[q].v;
            B->contiguous = lanes == KIN__PLAN_W && k[q + KIN__PLAN_W - 1].v == k[q].v + KIN__PLAN_W - 1;
            for (int l = 0; l < KIN__PLAN_W; l++) {
                int v = k[q + (l < lanes ? l : 0)].v;
                B->dest[l] = v;
                const float *p = mesh->positions + (size_t)v * 3;
                for (int c = 0; c < 3; c++) B->p[c][l] = p[c];
                if (do_n)
                    for (int c = 0; c < 3; c++) B->nrm[c][l] = mesh->normals[(size_t)v * 3 + c];
                if (B->n == 0) continue;
                const float *w = mesh->weights + (size_t)v * 4;
                int i2 = 0;
                for (int i = 0; i < 4; i++)
                    if (w[i] != 0.0f) B->w[i2++][l] = w[i];
            }
        }
        s = e;
    }
    *plan = (kin_skin_plan){ .vertex_count = mesh->vertex_count, .batch_count = nb,
                             .normals = do_n, .max_joint = max_joint, .group_count = groups,
                             .batches = bt };
    return 0;
}

int kin_skin_plan_contiguous(const kin_skin_plan *plan)
{
    if (!plan || !plan->batches) return 0;
    const kin__plan_batch *bt = plan->batches;
    int c = 0;
    for (int b = 0; b < plan->batch_count; b++) c += bt[b].contiguous != 0;
    return c;
}

/* ------------------------------------------------------------ per frame */

/* Lane l of batch B as a one-vertex mesh for the reference. */
typedef struct lane_mesh {
    kin_mesh m;
    float p[3], n[3], w[4];
    uint16_t j[4];
} lane_mesh;

static void lane_of(const kin__plan_batch *B, int l, int normals, lane_mesh *o)
{
    memset(o, 0, sizeof *o);
    for (int c = 0; c < 3; c++) { o->p[c] = B->p[c][l]; o->n[c] = B->nrm[c][l]; }
    for (int i = 0; i < B->n; i++) { o->w[i] = B->w[i][l]; o->j[i] = (uint16_t)B->joint[i]; }
    o->m = (kin_mesh){ .vertex_count = 1, .positions = o->p, .normals = normals ? o->n : NULL,
                       .joints = o->j, .weights = o->w, .skin = 0, .node = -1 };
}

static void out_lane(const float r[6], int v, float *pos_out, float *nrm_out)
{
    memcpy(pos_out + (size_t)v * 3, r, 3 * sizeof(float));
    if (nrm_out) memcpy(nrm_out + (size_t)v * 3, r + 3, 3 * sizeof(float));
}

static void range_of(const kin_skin_plan *plan, int part, int parts, int *b0, int *b1)
{
    if (parts < 1 || part < 0 || part >= parts) { *b0 = *b1 = 0; return; }
    long long nb = plan->batch_count;
    *b0 = (int)(nb * part / parts);
    *b1 = (int)(nb * (part + 1) / parts);
}

/* One skinning method: its plan kernel per ISA (NULL: none, the
 * reference per lane) and its reference on a one-vertex mesh. */
typedef struct plan_method {
    kin__plan_kernel simd[EF_ISA_COUNT];
    void (*ref)(const kin_mesh *m, const void *xf, float *pos_out, float *nrm_out);
} plan_method;

static void lbs_ref(const kin_mesh *m, const void *xf, float *pos_out, float *nrm_out)
{
    kin__skin_lbs_ref(m, xf, pos_out, nrm_out, 0, 1);
}

static void dqs_ref(const kin_mesh *m, const void *xf, float *pos_out, float *nrm_out)
{
    kin__skin_dqs_ref(m, xf, pos_out, nrm_out, 0, 1);
}

#if defined(__x86_64__)
#define PLAN_SIMD(kind)                                                                   \
    { [EF_ISA_SSE2] = kin__skin_##kind##_plan_sse2, [EF_ISA_AVX2] = kin__skin_##kind##_plan_avx2, \
      [EF_ISA_AVX512] = kin__skin_##kind##_plan_avx512 }
#elif defined(__aarch64__) && defined(__ARM_NEON)
#define PLAN_SIMD(kind) { [EF_ISA_NEON] = kin__skin_##kind##_plan_neon }
#else
#define PLAN_SIMD(kind) { 0 }
#endif
static const plan_method lbs_method = { PLAN_SIMD(lbs), lbs_ref };
static const plan_method dqs_method = { PLAN_SIMD(dqs), dqs_ref };
#undef PLAN_SIMD

/* Part `part` of `parts` of the plan with method pm. xf NULL: the
 * reference, which keeps the bind pose without transforms. */
static void plan_run(const plan_method *pm, const kin_skin_plan *plan, const void *xf,
                     float *pos_out, float *nrm_out, int part, int parts, int isa)
{
    if (!plan || !plan->batches || !pos_out) return;
    if (!plan->normals) nrm_out = NULL;
    int b0, b1;
    range_of(plan, part, parts, &b0, &b1);
    const kin__plan_batch *bt = plan->batches;
    const kin__plan_kernel k = xf ? pm->simd[kin__skin_isa_of(isa)] : NULL;
    if (k) {
        k(bt, b0, b1, xf, pos_out, nrm_out);
        return;
    }
    for (int b = b0; b < b1; b++)
        for (int l = 0; l < bt[b].lanes; l++) {
            lane_mesh lm;
            float r[6];
            lane_of(&bt[b], l, nrm_out != NULL, &lm);
            pm->ref(&lm.m, xf, r, r + 3);
            out_lane(r, bt[b].dest[l], pos_out, nrm_out);
        }
}

void kin_skin_lbs_plan_part(const kin_skin_plan *plan, const kin_mat4 *jm, float *pos_out,
                            float *nrm_out, int part, int parts, int isa)
{
    plan_run(&lbs_method, plan, jm, pos_out, nrm_out, part, parts, isa);
}

void kin_skin_dqs_plan_part(const kin_skin_plan *plan, const kin_dualquat *dq, float *pos_out,
                            float *nrm_out, int part, int parts, int isa)
{
    plan_run(&dqs_method, plan, dq, pos_out, nrm_out, part, parts, isa);
}

void kin_skin_lbs_plan(const kin_skin_plan *plan, const kin_mat4 *jm, float *pos_out,
                       float *nrm_out)
{
    kin_skin_lbs_plan_part(plan, jm, pos_out, nrm_out, 0, 1, 0);
}

void kin_skin_dqs_plan(const kin_skin_plan *plan, const kin_dualquat *dq, float *pos_out,
                       float *nrm_out)
{
    kin_skin_dqs_plan_part(plan, dq, pos_out, nrm_out, 0, 1, 0);
}
