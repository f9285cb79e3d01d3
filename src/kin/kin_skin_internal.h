/* kin_skin_internal.h - the skinning kernels behind kin_skin_lbs and
 * kin_skin_dqs (not a public header).
 *
 * The scalar reference (kin_skin.c, kin_dqs.c) defines every byte; the
 * SIMD kernels (kin_skin_sse2.c, kin_skin_avx2.c, kin_skin_avx512.c,
 * kin_skin_neon.c: one body in kin_skin_simd.inl on the vector layer
 * src/cpu/simd.h) compute the same operations in the same
 * order lane by lane (no FMA, exact sqrt and division), so they are
 * memcmp-equal. A kernel skins the vertices [v0, v1) of a skinned mesh
 * (joints, weights and matrices present) and returns the first vertex it
 * did not do (it only does whole vectors); the dispatcher finishes the
 * rest with the reference. The plan kernels (kin_skin_plan.c, same .inl)
 * do whole batches of a skin plan instead. */
#ifndef EGOFUSE_KIN_SKIN_INTERNAL_H
#define EGOFUSE_KIN_SKIN_INTERNAL_H

#include "kin.h"

/* Bit i set when weight i of a vertex is not 0 (NaN counts as not 0, as
 * in the reference's "w == 0: skip"); the SIMD kernels' influence loop.
 * One SSE compare where there is SSE2 (a plain-C version of the loop was
 * measured 10-30% slower in bench_kin's mesh rows). */
#if defined(__SSE2__)
#include <emmintrin.h>
static inline unsigned kin__nonzero4(const float *w)
{
    return (unsigned)_mm_movemask_ps(_mm_cmpneq_ps(_mm_loadu_ps(w), _mm_setzero_ps()));
}
#else
static inline unsigned kin__nonzero4(const float *w)
{
    return (unsigned)(w[0] != 0.0f) | (unsigned)(w[1] != 0.0f) << 1 |
           (unsigned)(w[2] != 0.0f) << 2 | (unsigned)(w[3] != 0.0f) << 3;
}
#endif

/* The references' per-vertex parts (kin_skin.c, kin_dqs.c). How many
 * extra influence sets they read (0 unless the mesh has them all). */
static inline int kin__extra_sets(const kin_mesh *mesh)
{
    return mesh->joints_extra && mesh->weights_extra && mesh->extra_sets > 0
           ? mesh->extra_sets : 0;
}

/* Vertex v's bind position p and its output po; with normals (nrm_out
 * and the mesh's), its normal n and output no, else both NULL. */
static inline void kin__vertex(const kin_mesh *mesh, float *pos_out, float *nrm_out, int v,
                               const float **p, float **po, const float **n, float **no)
{
    const int do_n = mesh->normals && nrm_out;
    *p = mesh->positions + (size_t)v * 3;
    *po = pos_out + (size_t)v * 3;
    *n = do_n ? mesh->normals + (size_t)v * 3 : NULL;
    *no = do_n ? nrm_out + (size_t)v * 3 : NULL;
}

/* Influence set `set` of vertex v: 0 is JOINTS_0/WEIGHTS_0, then the
 * mesh's extra sets in order (extra: kin__extra_sets); its 4 joints and
 * weights. */
static inline void kin__influences(const kin_mesh *mesh, int extra, int v, int set,
                                   const uint16_t **j, const float **w)
{
    const size_t e = ((size_t)v * (size_t)extra + (size_t)(set - 1)) * 4;
    *j = set ? mesh->joints_extra + e : mesh->joints + (size_t)v * 4;
    *w = set ? mesh->weights_extra + e : mesh->weights + (size_t)v * 4;
}

/* A vertex that keeps its bind pose: p to po, and n to no when n. */
static inline void kin__bind_pose(const float *p, float *po, const float *n, float *no)
{
    po[0] = p[0]; po[1] = p[1]; po[2] = p[2];
    if (n) { no[0] = n[0]; no[1] = n[1]; no[2] = n[2]; }
}

/* DQS range rule (kin_dqs.c dq_fit, kin_skin_simd.inl dqs_fit): when
 * |b.r|^2 is not in (KIN__DQS_SQ_MIN, KIN__DQS_SQ_MAX) (a tiny or huge
 * weight sum: k = 2 / |b.r|^2 would overflow, or |b.r|^2 under- or
 * overflow), b is first scaled by the power of two that brings its
 * largest |b.r| component to [1, 2) (that component clamped to
 * [KIN__DQS_FIT_LO, KIN__DQS_FIT_HI] first). Inside the range nothing is
 * scaled, so those bytes are the unscaled formula's. */
#define KIN__DQS_SQ_MIN 0x1p-100f
#define KIN__DQS_SQ_MAX 0x1p100f
#define KIN__DQS_FIT_LO 0x1p-126f
#define KIN__DQS_FIT_HI 0x1p126f

/* The ISA (an ef_isa value) a request of kin_skin_lbs_isa & co. runs:
 * 0 (or out of range) = kin_skin_isa(), else the request capped by what
 * the CPU has (never by EGOFUSE_ISA). */
int kin__skin_isa_of(int isa);

/* The SIMD kernel of a request over a mesh (kin_skin.c): LBS (dqs 0, xf
 * kin_mat4 *) or DQS (dqs 1, xf kin_dualquat *); returns the first vertex
 * not done (0: none), from where the caller runs the reference. */
int kin__skin_simd(const kin_mesh *mesh, const void *xf, int dqs, float *pos_out,
                   float *nrm_out, int isa);

void kin__skin_lbs_ref(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
                       float *nrm_out, int v0, int v1);
void kin__skin_dqs_ref(const kin_mesh *mesh, const kin_dualquat *dq,
                       float *pos_out, float *nrm_out, int v0, int v1);

/* The SIMD kernels over vertices [v0, v1), one per ISA (the body
 * kin_skin_simd.inl compiled per ISA), each its method's function type;
 * they return the first vertex not done. */
typedef int kin__lbs_fn(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
                        float *nrm_out, int v0, int v1);
typedef int kin__dqs_fn(const kin_mesh *mesh, const kin_dualquat *dq, float *pos_out,
                        float *nrm_out, int v0, int v1);
kin__lbs_fn kin__skin_lbs_sse2, kin__skin_lbs_avx2, kin__skin_lbs_avx512, kin__skin_lbs_neon;
kin__dqs_fn kin__skin_dqs_sse2, kin__skin_dqs_avx2, kin__skin_dqs_avx512, kin__skin_dqs_neon;

/* ---- skin plan (kin_skin_plan.c) -----------------------------------
 * One batch: up to KIN__PLAN_W vertices that read the same joints with
 * nonzero weight, in the same influence order (n of them; n = 0: vertices
 * whose reference weight sum is 0, which keep their bind pose). Lanes past
 * `lanes` repeat lane 0 (same vertex, same bytes written twice). When
 * contiguous, dest[l] = first + l for all 16 lanes. */
#define KIN__PLAN_W 16
typedef struct kin__plan_batch {
    int32_t n, lanes, contiguous, first;
    int32_t joint[4];
    int32_t pad[8];
    int32_t dest[KIN__PLAN_W];
    float w[4][KIN__PLAN_W];    /* nonzero weights, influence order */
    float p[3][KIN__PLAN_W];    /* bind positions, SoA */
    float nrm[3][KIN__PLAN_W];  /* bind normals, SoA (when the plan has them) */
} kin__plan_batch;

/* Batches [b0, b1) of a plan; they do every batch (no scalar tail). xf:
 * the joint matrices (kin_mat4, LBS) or dual quaternions (kin_dualquat,
 * DQS), not NULL; one function type, so kin_skin_plan.c picks them from
 * a table. */
typedef void kin__plan_fn(const kin__plan_batch *bt, int b0, int b1, const void *xf,
                          float *pos_out, float *nrm_out);
typedef kin__plan_fn *kin__plan_kernel;
kin__plan_fn kin__skin_lbs_plan_sse2, kin__skin_lbs_plan_avx2, kin__skin_lbs_plan_avx512;
kin__plan_fn kin__skin_dqs_plan_sse2, kin__skin_dqs_plan_avx2, kin__skin_dqs_plan_avx512;
kin__plan_fn kin__skin_lbs_plan_neon, kin__skin_dqs_plan_neon;

#endif
