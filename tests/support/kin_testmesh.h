/* kin_testmesh.h - seeded skinning test meshes shared by
 * tests/test_kin_skin_isa.c and tests/test_kin_skin_plan.c: the case
 * struct, the joint draw (rigid joints, antipodal dual quaternions, scale
 * and shear, mirroring, a singular joint, a NaN joint), the special weight
 * kinds, weight sums scaled to the ends of the float range, and the
 * byte-comparison that fails the test. Header-only (static inline);
 * include after support/testutil.h, <cmocka.h> and src/kin/kin.h. The
 * random draws are in the order the tests had them, so their cases (and
 * the recorded CRC) are unchanged. */
#ifndef EGOFUSE_KIN_TESTMESH_H
#define EGOFUSE_KIN_TESTMESH_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tu_kin.h"

#define TU_SKIN_JOINTS 80   /* capacity; a case uses 24, 48 or 80 */

typedef struct tu_skin_case {
    kin_mesh mesh;
    float *pos, *nrm, *w;
    uint16_t *jt;
    kin_mat4 jm[TU_SKIN_JOINTS];
    kin_dualquat dq[TU_SKIN_JOINTS];
    int nj;
} tu_skin_case;

static inline kin_quat tu_rand_quat(tu_rng *r)
{
    kin_quat q = tu_quat(r, -1, 1);
    return kin_quat_normalize(q);
}

/* Allocates nv vertices (filled by the test) and draws nj joints: rigid
 * matrices and their dual quaternions, every third one antipodal (j % 3
 * == 1), scale and shear in the matrix for j % 4 == 2, mirroring for
 * j % 5 == 3; joint nj - 2 singular (all zero), joint nj - 1 with a NaN
 * (the test reads it only with weight 0). */
static inline void tu_skin_case_begin(tu_skin_case *k, tu_rng *r, int nv, int nj)
{
    k->pos = malloc((size_t)nv * 3 * sizeof(float));
    k->nrm = malloc((size_t)nv * 3 * sizeof(float));
    k->w = malloc((size_t)nv * 4 * sizeof(float));
    k->jt = malloc((size_t)nv * 4 * sizeof(uint16_t));
    assert_true(k->pos && k->nrm && k->w && k->jt && nj >= 3 && nj <= TU_SKIN_JOINTS);
    k->nj = nj;
    for (int j = 0; j < nj; j++) {
        kin_vec3 t = tu_v3(r, -2, 2);
        k->jm[j] = kin_mat4_from_tr(t, tu_rand_quat(r));
        k->dq[j] = kin_dualquat_from_mat4(&k->jm[j]);
        if (j % 3 == 1) { /* the other sign of the same transform */
            kin_quat *q = &k->dq[j].r, *d = &k->dq[j].d;
            *q = (kin_quat){ -q->x, -q->y, -q->z, -q->w };
            *d = (kin_quat){ -d->x, -d->y, -d->z, -d->w };
        }
        if (j % 4 == 2) { /* scale, shear */
            for (int e = 0; e < 12; e++) k->jm[j].m[e] *= tu_range(r, 0.5f, 1.5f);
            k->jm[j].m[4] += tu_range(r, -0.3f, 0.3f);
        }
        if (j % 5 == 3) /* mirrored */
            for (int e = 0; e < 3; e++) k->jm[j].m[e] = -k->jm[j].m[e];
    }
    k->jm[nj - 2] = (kin_mat4){ { 0 } };                 /* singular */
    k->jm[nj - 1].m[0] = NAN;                            /* read with w = 0 only */
    k->dq[nj - 1].r.x = NAN;
}

/* The special weight kinds of vertex v (others: nothing): 3 weights 0.5
 * and -0.5 (sum 0: bind pose), 4 all zero, 5 a negative last weight, 6
 * the NaN joint with weight 0, 7 the singular joint first, 8 an
 * out-of-range joint (60000) with weight 0 (never read). */
static inline void tu_skin_weight_kind(tu_skin_case *k, int v, int kind)
{
    float *w = k->w + 4 * (size_t)v;
    uint16_t *jt = k->jt + 4 * (size_t)v;
    switch (kind) {
    case 3: w[0] = 0.5f; w[1] = -0.5f; w[2] = w[3] = 0; break;
    case 4: w[0] = w[1] = w[2] = w[3] = 0.0f; break;
    case 5: w[3] = -0.25f; break;
    case 6: jt[3] = (uint16_t)(k->nj - 1); w[3] = 0.0f; break;
    case 7: jt[0] = (uint16_t)(k->nj - 2); break;
    case 8: jt[2] = 60000; w[2] = 0.0f; break;
    default: break;
    }
}

/* The mesh of nv vertices over the case's arrays, with or without normals. */
static inline void tu_skin_case_end(tu_skin_case *k, int nv, int normals)
{
    memset(&k->mesh, 0, sizeof k->mesh);
    k->mesh.vertex_count = nv;
    k->mesh.positions = k->pos;
    k->mesh.normals = normals ? k->nrm : NULL;
    k->mesh.joints = k->jt;
    k->mesh.weights = k->w;
    k->mesh.skin = 0;
    k->mesh.node = -1;
}

static inline void tu_skin_case_free(tu_skin_case *k)
{
    free(k->pos); free(k->nrm); free(k->w); free(k->jt);
}

/* Weight factors for the ends of the float range (DQS: k = 2 / |b.r|^2
 * and |b.r|^2 itself under- and overflow there): vertex v gets factor
 * tu_skin_weight_scale(v). Index 0 is 1, 1 and 2 are powers of two
 * (2^-64, 2^64: the result must not change by a single byte), the rest
 * are not. */
#define TU_SKIN_SCALES 9
static inline float tu_skin_weight_scale(int v)
{
    static const float f[TU_SKIN_SCALES] = { 1.0f, 0x1p-64f, 0x1p64f, 3e-20f, 1e-30f,
                                             2e19f, 1e30f, 1e-21f, 1e-23f };
    return f[v % TU_SKIN_SCALES];
}

/* A copy of the case's weights (4 nv floats) with vertex v's scaled by
 * tu_skin_weight_scale(v). */
static inline float *tu_skin_scaled_weights(const tu_skin_case *k)
{
    const int nv = k->mesh.vertex_count;
    float *w = malloc((size_t)nv * 4 * sizeof(float));
    assert_non_null(w);
    for (int v = 0; v < nv; v++)
        for (int i = 0; i < 4; i++) w[4 * v + i] = k->w[4 * v + i] * tu_skin_weight_scale(v);
    return w;
}

/* Fails at the first float of got whose bytes differ from ref. */
static inline void tu_skin_first_diff(const float *ref, const float *got, int n,
                                      const char *what, int c, const char *isa)
{
    for (int i = 0; i < n; i++)
        if (memcmp(&ref[i], &got[i], sizeof(float)))
            fail_msg("case %d: %s %s vertex %d comp %d: %.9g (ref %.9g)", c, isa, what,
                     i / 3, i % 3, (double)got[i], (double)ref[i]);
}

#endif
