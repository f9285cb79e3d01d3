/* kin_skin_avx2.c - skinning kernels, AVX2 (8 vertices per vector): the
 * vector layer's AVX2 implementation, the blend below (what AVX2 does its
 * own way) and the one body, kin_skin_simd.inl. A vertex's joint matrix is
 * two ymm (columns 0-1 and 2-3), its dual quaternion one ymm; 8 blended
 * vertices are transposed with in-lane 4x4 transposes and 128-bit lane
 * permutes. Bytes equal the
 * reference (kin_skin.c, kin_dqs.c). Built with -mavx2 (no FMA: the
 * build has -ffp-contract=off and no -mfma). */
#include "kin_skin_internal.h"

#if defined(__x86_64__)
#include <math.h>

#include "../cpu/simd_avx2.h"
#include "kin_skin_x86.inl"

/* The blend with 8 lanes: each vertex's matrix as two ymm (columns 0-1,
 * 2-3), 8 vertices transposed by vf_tr4 per 128-bit half and 128-bit lane
 * permutes (vperm2f128: AVX2's own). */
#define KIN_SKIN_OWN_BLOCK
/* No per-call state here. */
typedef struct skin_tab { int unused; } skin_tab;
SIMD_INL void tab_init(skin_tab *t) { t->unused = 0; }

static inline void lbs_block(skin_tab *tab, const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             __m256 a[12], __m256 *wsum)
{
    _Alignas(32) float ws[8];
    __m256 r[2][8];
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 8; l++, j += 4, w += 4) {
        __m256 lo = _mm256_setzero_ps(), hi = _mm256_setzero_ps();
        float s = 0.0f;
        for (unsigned bits = kin__nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            __m256 wv = _mm256_set1_ps(w[i]);
            lo = _mm256_add_ps(lo, _mm256_mul_ps(wv, _mm256_loadu_ps(jm[j[i]].m)));
            hi = _mm256_add_ps(hi, _mm256_mul_ps(wv, _mm256_loadu_ps(jm[j[i]].m + 8)));
            s += w[i];
        }
        r[0][l] = lo;
        r[1][l] = hi;
        ws[l] = s;
    }
    *wsum = _mm256_load_ps(ws);
    for (int h = 0; h < 2; h++) {
        /* s[I][rho], lane L: column 2h+L, row rho of vertices 4I..4I+3 */
        __m256 s[2][4];
        for (int I = 0; I < 2; I++)
            vf_tr4(r[h][4 * I], r[h][4 * I + 1], r[h][4 * I + 2], r[h][4 * I + 3], s[I]);
        for (int rho = 0; rho < 3; rho++) {
            a[(2 * h) * 3 + rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x20);
            a[(2 * h + 1) * 3 + rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x31);
        }
    }
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
        b[rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x20);
        b[4 + rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x31);
    }
}

#include "kin_skin_simd.inl"

#endif
