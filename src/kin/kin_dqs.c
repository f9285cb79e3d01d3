/* kin_dqs.c - dual-quaternion skinning (Kavan, Collins, Zara, O'Sullivan,
 * "Geometric skinning with approximate dual quaternion blending", 2008),
 * the scalar reference.
 *
 * A rigid transform (R, t) is the unit dual quaternion r + e d with r the
 * rotation and d = (t, 0) r / 2. Per vertex: b = sum_i w_i s_i dq_i with
 * s_i = +1 if r_i . r_first >= 0 else -1 (r_first: the first influence
 * with w != 0). Kavan's b / |b.r| is not formed: with u = b.r.v,
 * w = b.r.w, d = b.d and k = 2 / |b.r|^2 (one division, no square root)
 *   p' = p + k (w e + u x e - d.w u),   e = u x p + d.v
 *   n' = n + k (w f + u x f),           f = u x n
 * which is, in exact arithmetic, R(b / |b.r|) p + t(b / |b.r|) and
 * R(b / |b.r|) n (q v q* = |q|^2 v + 2w (u x v) + 2 u x (u x v) for any
 * q; t(q) = 2 (q.r.w q.d.v - q.d.w q.r.v + q.r.v x q.d.v), and
 * e collects both cross products with u). The normal is rotated, not
 * renormalised: a unit normal stays unit to a few ulp, and the length of
 * any other is kept. The result does not change when b is scaled by a
 * positive factor, so when |b.r|^2 is outside (2^-100, 2^100) (a tiny or
 * huge weight sum: 2 / |b.r|^2 would overflow, or |b.r|^2 under- or
 * overflow) b is first scaled by the power of two that brings its largest
 * |b.r| component to [1, 2) (dq_fit: exact); inside that range nothing is
 * scaled. So weights summing to 1e-30 or 1e30 give the rigid transform
 * (not inf/NaN, not the bind pose). A vertex whose weights sum to exactly
 * 0, or whose b.r is 0 (|b.r|^2 still not > 0 after the scaling), keeps
 * its bind pose. Unlike LBS the blend of two rotations is
 * a rotation, so a twisted wrist keeps its cross-section (LBS shrinks it
 * by cos(angle/2)). Scale and mirroring are not representable:
 * kin_dualquat_from_mat4 orthonormalises. No allocation. kin_skin_dqs
 * runs the SIMD kernels (kin_skin_internal.h) on whole vectors of
 * vertices and this reference on the rest (same bytes). */
#include "kin.h"
#include "kin_skin_internal.h"
#include "../cpu/cpu.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

kin_dualquat kin_dualquat_from_mat4(const kin_mat4 *m)
{
    kin_vec3 c0 = kin_v3(m->m[0], m->m[1], m->m[2]);
    kin_vec3 c1 = kin_v3(m->m[4], m->m[5], m->m[6]);
    kin_vec3 x = kin_v3_norm(c0);
    kin_vec3 y = kin_v3_norm(kin_v3_sub(c1, kin_v3_scale(x, kin_v3_dot(x, c1))));
    kin_dualquat q;
    if (kin_v3_len(x) == 0.0f || kin_v3_len(y) == 0.0f) {
        q.r = kin_quat_identity();
    } else {
        kin_vec3 z = kin_v3_cross(x, y);
        q.r = kin_quat_from_axes(x, y, z);
    }
    kin_quat t = { m->m[12], m->m[13], m->m[14], 0.0f };
    kin_quat d = kin_quat_mul(t, q.r);
    q.d = (kin_quat){ 0.5f * d.x, 0.5f * d.y, 0.5f * d.z, 0.5f * d.w };
    return q;
}

/* Translation of a dual quaternion whose real part is unit. */
static kin_vec3 dq_translation(const kin_dualquat *q)
{
    kin_vec3 rv = kin_v3(q->r.x, q->r.y, q->r.z), dv = kin_v3(q->d.x, q->d.y, q->d.z);
    kin_vec3 t = kin_v3_add(kin_v3_sub(kin_v3_scale(dv, q->r.w), kin_v3_scale(rv, q->d.w)),
                            kin_v3_cross(rv, dv));
    return kin_v3_scale(t, 2.0f);
}

kin_vec3 kin_dualquat_transform(const kin_dualquat *q, kin_vec3 p)
{
    return kin_v3_add(kin_quat_rotate(q->r, p), dq_translation(q));
}

void kin_skin_dq_from_matrices(const kin_mat4 *jm, int count, kin_dualquat *dq)
{
    if (!jm || !dq) return;
    for (int j = 0; j < count; j++) dq[j] = kin_dualquat_from_mat4(&jm[j]);
}

/* o = a x b, componentwise as kin_v3_cross (o must not alias). */
static void cross3(const float *a, const float *b, float *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* |b.r|^2 in the kernels' order. */
static float dq_sq(const float b[8])
{
    return b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3];
}

/* maxps / minps: a > b ? a : b and a < b ? a : b (the second operand when
 * either is NaN), as the SIMD kernels' VMAX / VMIN. */
static float maxps(float a, float b) { return a > b ? a : b; }
static float minps(float a, float b) { return a < b ? a : b; }

/* b * 2^-E with 2^E the power of two of m = max |b.r component| (its
 * exponent bits), m clamped to [2^-126, 2^126]: the largest |b.r|
 * component lands in [1, 2) (for m in range), so |b.r|^2 is in [1, 8).
 * Exact (a power of two, results normal), and the skinned vertex does not
 * depend on a positive scale of b, so only the range of k changes. m = 0
 * (b.r = 0) keeps b.r = 0; a NaN stays NaN; an inf stays inf. */
static void dq_fit(float b[8])
{
    float m = maxps(maxps(maxps(fabsf(b[0]), fabsf(b[1])), fabsf(b[2])), fabsf(b[3]));
    m = minps(maxps(m, KIN__DQS_FIT_LO), KIN__DQS_FIT_HI);
    uint32_t u;
    memcpy(&u, &m, sizeof u);
    u &= 0x7F800000u;             /* 2^floor(log2 m) */
    memcpy(&m, &u, sizeof m);
    const float s = 1.0f / m;      /* exact: 2^-E, normal */
    for (int e = 0; e < 8; e++) b[e] *= s;
}

void kin__skin_dqs_ref(const kin_mesh *mesh, const kin_dualquat *dq,
                       float *pos_out, float *nrm_out, int v0, int v1)
{
    const int skinned = mesh->joints && mesh->weights && dq;
    const int extra = kin__extra_sets(mesh);
    for (int v = v0; v < v1; v++) {
        const float *p, *n;
        float *po, *no;
        kin__vertex(mesh, pos_out, nrm_out, v, &p, &po, &n, &no);
        float b[8] = { 0 };
        float wsum = 0.0f;
        const kin_quat *r0 = NULL;
        for (int set = 0; skinned && set <= extra; set++) {
            const uint16_t *j;
            const float *w;
            kin__influences(mesh, extra, v, set, &j, &w);
            for (int i = 0; i < 4; i++) {
                if (w[i] == 0.0f) continue;
                const kin_dualquat *q = &dq[j[i]];
                if (!r0) r0 = &q->r;
                float dot = q->r.x * r0->x + q->r.y * r0->y + q->r.z * r0->z + q->r.w * r0->w;
                float s = dot < 0.0f ? -w[i] : w[i];
                b[0] += s * q->r.x; b[1] += s * q->r.y; b[2] += s * q->r.z; b[3] += s * q->r.w;
                b[4] += s * q->d.x; b[5] += s * q->d.y; b[6] += s * q->d.z; b[7] += s * q->d.w;
                wsum += w[i];
            }
        }
        float sq = dq_sq(b);
        if (!(sq > KIN__DQS_SQ_MIN && sq < KIN__DQS_SQ_MAX)) {
            dq_fit(b);
            sq = dq_sq(b);
        }
        if (wsum == 0.0f || !(sq > 0.0f)) {
            kin__bind_pose(p, po, n, no);
            continue;
        }
        const float k = 2.0f / sq, w = b[3], dw = b[7];
        const float u[3] = { b[0], b[1], b[2] };
        float e[3], g[3];
        cross3(u, p, e);
        for (int c = 0; c < 3; c++) e[c] = e[c] + b[4 + c];
        cross3(u, e, g);
        for (int c = 0; c < 3; c++) po[c] = p[c] + k * ((w * e[c] + g[c]) - dw * u[c]);
        if (n) {
            float f[3];
            cross3(u, n, f);
            cross3(u, f, g);
            for (int c = 0; c < 3; c++) no[c] = n[c] + k * (w * f[c] + g[c]);
        }
    }
}

void kin_skin_dqs_isa(const kin_mesh *mesh, const kin_dualquat *dq,
                      float *pos_out, float *nrm_out, int isa)
{
    if (!mesh || !pos_out) return;
    int v = kin__skin_simd(mesh, dq, 1, pos_out, nrm_out, isa);
    kin__skin_dqs_ref(mesh, dq, pos_out, nrm_out, v, mesh->vertex_count);
}

void kin_skin_dqs(const kin_mesh *mesh, const kin_dualquat *dq, float *pos_out, float *nrm_out)
{
    kin_skin_dqs_isa(mesh, dq, pos_out, nrm_out, 0);
}
