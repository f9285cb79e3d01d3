/* kin_skin_avx2.c - skinning kernels, AVX2 (8 vertices per vector): the
 * vector layer's AVX2 implementation and the one body, kin_skin_simd.inl.
 * The LBS blend is the layer's (kin_skin_rows.inl: a vertex's joint matrix
 * two ymm, columns 0-1 and 2-3); the DQS blend keeps a vertex's dual
 * quaternion in one ymm (kin_skin_x86.inl, shared with AVX-512), 8
 * vertices transposed by vf_tr4 and vf_tr_blocks. Bytes equal the
 * reference (kin_skin.c, kin_dqs.c). Built with -mavx2 (no FMA: the
 * build has -ffp-contract=off and no -mfma). */
#include "kin_skin_internal.h"

#if defined(__x86_64__)
#include <math.h>

#include "../cpu/simd_avx2.h"
#include "kin_skin_x86.inl"
#include "kin_skin_rows.inl"

#define KIN_SKIN_OWN_BLOCK
/* No per-call state here. */
typedef struct skin_tab { int unused; } skin_tab;
SIMD_INL void tab_init(skin_tab *t) { t->unused = 0; }

static inline void lbs_block(skin_tab *tab, const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             vfloat a[12], vfloat *wsum)
{
    (void)tab;
    lbs_rows(mesh, jm, v, a, wsum);
}

static inline void dqs_block(skin_tab *tab, const kin_mesh *mesh, const kin_dualquat *dq, int v,
                             __m256 b[8], __m256 *wsum)
{
    _Alignas(32) float ws[8];
    __m256 r[8];
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 8; l++, j += 4, w += 4) r[l] = dqs_vertex8(dq, j, w, &ws[l]);
    *wsum = _mm256_load_ps(ws);
    __m256 s[2][4];
    for (int I = 0; I < 2; I++) vf_tr4(r[4 * I], r[4 * I + 1], r[4 * I + 2], r[4 * I + 3], s[I]);
    for (int rho = 0; rho < 4; rho++) {
        const vfloat in[2] = {s[0][rho], s[1][rho]};
        vfloat o[2];
        vf_tr_blocks(in, o);
        b[rho] = o[0];
        b[4 + rho] = o[1];
    }
}

#include "kin_skin_simd.inl"

#endif
