/* kin_skin.c - linear blend skinning (glTF 2.0) and rigid mesh transforms.
 *
 * Per vertex: B = sum_i w_i * jm[joint_i] (only influences with w_i != 0
 * are read), p' = B p. Normals: n' = C n with C = sign(det A) * cof(A),
 * A the upper 3x3 of B, cof(A) = det(A) A^-T its cofactor matrix, so C is
 * the inverse transpose times |det A| (a positive scale) and needs no
 * division; n' is then renormalised. A vertex whose weights sum to 0 keeps
 * its bind position and normal. No allocation.
 *
 * kin_skin_lbs runs the SIMD kernels (kin_skin_internal.h) on whole
 * vectors of vertices and this reference on the rest; both give the same
 * bytes. */
#include "kin.h"
#include "kin_skin_internal.h"
#include "../cpu/cpu.h"

#include <math.h>

void kin_skin_joint_matrices(const kin_skin *skin, const kin_mat4 *world,
                             kin_mat4 *jm)
{
    if (!skin || !world || !jm) return;
    for (int j = 0; j < skin->joint_count; j++) {
        const kin_mat4 *w = &world[skin->joints[j]];
        jm[j] = skin->inverse_bind ? kin_mat4_mul(w, &skin->inverse_bind[j]) : *w;
    }
}

/* Affine 3x4 part of a matrix, column-major like kin_mat4 (a[col*3+row]). */
typedef struct affine { float a[12]; } affine;

static void affine_of(const kin_mat4 *m, affine *out)
{
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 3; r++) out->a[c * 3 + r] = m->m[c * 4 + r];
}

static void xform_point(const affine *b, const float *p, float *o)
{
    const float *a = b->a;
    o[0] = a[0] * p[0] + a[3] * p[1] + a[6] * p[2] + a[9];
    o[1] = a[1] * p[0] + a[4] * p[1] + a[7] * p[2] + a[10];
    o[2] = a[2] * p[0] + a[5] * p[1] + a[8] * p[2] + a[11];
}

/* n' = sign(det A) cof(A) n, renormalised. cof(A) has the columns
 * a1 x a2, a2 x a0, a0 x a1 (a_i the columns of A). */
static void xform_normal(const affine *b, const float *n, float *o)
{
    const float *a = b->a;
    kin_vec3 a0 = kin_v3(a[0], a[1], a[2]);
    kin_vec3 a1 = kin_v3(a[3], a[4], a[5]);
    kin_vec3 a2 = kin_v3(a[6], a[7], a[8]);
    kin_vec3 c0 = kin_v3_cross(a1, a2), c1 = kin_v3_cross(a2, a0),
             c2 = kin_v3_cross(a0, a1);
    float det = kin_v3_dot(a0, c0);
    kin_vec3 r = kin_v3_add(kin_v3_add(kin_v3_scale(c0, n[0]), kin_v3_scale(c1, n[1])),
                            kin_v3_scale(c2, n[2]));
    if (det < 0.0f) r = kin_v3_scale(r, -1.0f);
    r = kin_v3_norm(r);
    o[0] = r.x; o[1] = r.y; o[2] = r.z;
}

void kin__skin_lbs_ref(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
                       float *nrm_out, int v0, int v1)
{
    const int skinned = mesh->joints && mesh->weights && jm;
    const int extra = kin__extra_sets(mesh);
    for (int v = v0; v < v1; v++) {
        const float *p, *n;
        float *po, *no;
        kin__vertex(mesh, pos_out, nrm_out, v, &p, &po, &n, &no);

        affine b = { { 0 } };
        float wsum = 0.0f;
        for (int set = 0; skinned && set <= extra; set++) {
            /* set 0: JOINTS_0/WEIGHTS_0; then the extra sets in order */
            const uint16_t *j;
            const float *w;
            kin__influences(mesh, extra, v, set, &j, &w);
            for (int i = 0; i < 4; i++) {
                if (w[i] == 0.0f) continue;
                const float *m = jm[j[i]].m;
                for (int c = 0; c < 4; c++)
                    for (int r = 0; r < 3; r++) b.a[c * 3 + r] += w[i] * m[c * 4 + r];
                wsum += w[i];
            }
        }
        if (wsum == 0.0f) {
            kin__bind_pose(p, po, n, no);
            continue;
        }
        xform_point(&b, p, po);
        if (n) xform_normal(&b, n, no);
    }
}

/* ------------------------------------------------------------ dispatch */

int kin_skin_isa(void)
{
    return (int)ef_isa_choose(EF_ISA_DEFAULT);
}

/* Never capped by EGOFUSE_ISA: tests and benchmarks name the path they
 * want. */
int kin__skin_isa_of(int isa)
{
    if (isa <= (int)EF_ISA_DEFAULT || isa >= (int)EF_ISA_COUNT) return (int)ef_isa_choose(EF_ISA_DEFAULT);
    return (int)ef_cpu_cap((ef_isa)isa);
}

/* The SIMD kernel of the request's ISA over a mesh's vertices, LBS (xf:
 * kin_mat4 joint matrices) or DQS (xf: kin_dualquat); the first vertex
 * it did not do (0 where no kernel runs: extra influence sets, no joints
 * or weights, the reference ISA). kin_skin_lbs_isa and kin_skin_dqs_isa
 * finish from there with their reference. */
int kin__skin_simd(const kin_mesh *mesh, const void *xf, int dqs, float *pos_out,
                   float *nrm_out, int isa)
{
    /* extra influence sets: the reference alone */
    if (!mesh->joints || !mesh->weights || !xf || mesh->extra_sets != 0) return 0;
    const int n = mesh->vertex_count;
    const kin_mat4 *jm = xf;
    const kin_dualquat *dq = xf;
    switch ((ef_isa)kin__skin_isa_of(isa)) {
#if defined(__x86_64__)
    case EF_ISA_AVX512: return dqs ? kin__skin_dqs_avx512(mesh, dq, pos_out, nrm_out, 0, n)
                                   : kin__skin_lbs_avx512(mesh, jm, pos_out, nrm_out, 0, n);
    case EF_ISA_AVX2: return dqs ? kin__skin_dqs_avx2(mesh, dq, pos_out, nrm_out, 0, n)
                                 : kin__skin_lbs_avx2(mesh, jm, pos_out, nrm_out, 0, n);
    case EF_ISA_SSE2: return dqs ? kin__skin_dqs_sse2(mesh, dq, pos_out, nrm_out, 0, n)
                                 : kin__skin_lbs_sse2(mesh, jm, pos_out, nrm_out, 0, n);
#elif defined(__aarch64__) && defined(__ARM_NEON)
    case EF_ISA_NEON: return dqs ? kin__skin_dqs_neon(mesh, dq, pos_out, nrm_out, 0, n)
                                 : kin__skin_lbs_neon(mesh, jm, pos_out, nrm_out, 0, n);
#endif
    default: return 0;
    }
}

void kin_skin_lbs_isa(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
                      float *nrm_out, int isa)
{
    if (!mesh || !pos_out) return;
    int v = kin__skin_simd(mesh, jm, 0, pos_out, nrm_out, isa);
    kin__skin_lbs_ref(mesh, jm, pos_out, nrm_out, v, mesh->vertex_count);
}

void kin_skin_lbs(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
                  float *nrm_out)
{
    kin_skin_lbs_isa(mesh, jm, pos_out, nrm_out, 0);
}

void kin_mesh_transform(const kin_mesh *mesh, const kin_mat4 *m, float *pos_out,
                        float *nrm_out)
{
    if (!mesh || !m || !pos_out) return;
    const int do_n = mesh->normals && nrm_out;
    affine b;
    affine_of(m, &b);
    for (int v = 0; v < mesh->vertex_count; v++) {
        xform_point(&b, mesh->positions + (size_t)v * 3, pos_out + (size_t)v * 3);
        if (do_n)
            xform_normal(&b, mesh->normals + (size_t)v * 3, nrm_out + (size_t)v * 3);
    }
}
