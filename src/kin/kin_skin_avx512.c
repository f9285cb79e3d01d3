/* kin_skin_avx512.c - skinning kernels, AVX-512 (16 vertices per vector):
 * the vector layer's AVX-512 implementation, the blend below (AVX-512's
 * own: masks, vpermt2ps joint tables) and the one body, kin_skin_simd.inl. A vertex's joint matrix is one zmm (LBS), its
 * dual quaternion one ymm (DQS); 16 blended vertices are transposed with
 * in-lane 4x4 transposes and 128-bit block shuffles. Bytes equal the
 * reference (kin_skin.c, kin_dqs.c). Built with -mavx512f/bw/dq/vl. */
#include "kin_skin_internal.h"

#if defined(__x86_64__)
#include <math.h>
#include <string.h>

#include "../cpu/simd_avx512.h"
#include "kin_skin_x86.inl"

#define KIN_SKIN_OWN_BLOCK
static inline void lbs_rows(const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             __m512 a[12], __m512 *wsum)
{
    _Alignas(64) float ws[16];
    __m512 r[16];
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 16; l++, j += 4, w += 4) {
        __m512 acc = _mm512_setzero_ps();
        float s = 0.0f;
        for (unsigned bits = kin__nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            acc = _mm512_add_ps(acc, _mm512_mul_ps(_mm512_set1_ps(w[i]),
                                                   _mm512_loadu_ps(jm[j[i]].m)));
            s += w[i];
        }
        r[l] = acc;
        ws[l] = s;
    }
    *wsum = _mm512_load_ps(ws);
    /* s[I][rho], block J: column J, row rho of vertices 4I..4I+3 */
    __m512 s[4][4];
    for (int I = 0; I < 4; I++) vf_tr4(r[4 * I], r[4 * I + 1], r[4 * I + 2], r[4 * I + 3], s[I]);
    for (int rho = 0; rho < 3; rho++) {
        __m512 abl = _mm512_shuffle_f32x4(s[0][rho], s[1][rho], 0x44);
        __m512 cdl = _mm512_shuffle_f32x4(s[2][rho], s[3][rho], 0x44);
        __m512 abh = _mm512_shuffle_f32x4(s[0][rho], s[1][rho], 0xEE);
        __m512 cdh = _mm512_shuffle_f32x4(s[2][rho], s[3][rho], 0xEE);
        a[0 * 3 + rho] = _mm512_shuffle_f32x4(abl, cdl, 0x88);
        a[1 * 3 + rho] = _mm512_shuffle_f32x4(abl, cdl, 0xDD);
        a[2 * 3 + rho] = _mm512_shuffle_f32x4(abh, cdh, 0x88);
        a[3 * 3 + rho] = _mm512_shuffle_f32x4(abh, cdh, 0xDD);
    }
}

static inline void dqs_rows(const kin_mesh *mesh, const kin_dualquat *dq, int v,
                             __m512 b[8], __m512 *wsum)
{
    /* vertex l = 8I + 4h + i goes to slot 8I + 2i + h, so the in-lane
     * transposes of slot pairs give 4 consecutive vertices per block */
    _Alignas(64) float blk[16 * 8];
    _Alignas(64) float ws[16];
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 16; l++, j += 4, w += 4) {
        __m256 acc = dqs_vertex8(dq, j, w, &ws[l]);
        int slot = (l & 8) + 2 * (l & 3) + ((l >> 2) & 1);
        _mm256_store_ps(blk + 8 * slot, acc);
    }
    *wsum = _mm512_load_ps(ws);
    __m512 s[2][4];
    for (int I = 0; I < 2; I++)
        vf_tr4(_mm512_load_ps(blk + 64 * I), _mm512_load_ps(blk + 64 * I + 16),
            _mm512_load_ps(blk + 64 * I + 32), _mm512_load_ps(blk + 64 * I + 48), s[I]);
    for (int rho = 0; rho < 4; rho++) {
        b[rho] = _mm512_shuffle_f32x4(s[0][rho], s[1][rho], 0x88);
        b[4 + rho] = _mm512_shuffle_f32x4(s[0][rho], s[1][rho], 0xDD);
    }
}

/* ---- joint-table blend: no per-vertex loop --------------------------
 * When every joint a block of 16 vertices reads (nonzero weight) is below
 * 64, the blend runs in SoA: the needed elements of joints 0..63 sit
 * transposed in a table (one 64-float row per element, built on demand
 * from the joints the mesh reads, as the reference reads them), and
 * per influence slot i one vpermt2ps (two and a blend above joint 31)
 * looks up all 16 lanes at once. Lanes with w_i == 0 add +0 (masked
 * product): the same sum as the reference's skip, since a sum started at
 * +0 is never -0. The weight sum adds every w_i in order: adding a zero
 * weight changes nothing either. Blocks reading joints >= 64 use the
 * per-vertex rows path above. */
typedef struct skin_tab {
    _Alignas(64) float t[12][64];  /* [element][joint] */
    int built;                     /* joints [0, built) are in t */
    __m512i sel01, sel23;          /* word picks: slots 0|1 and 2|3 */
    __m512i widx[4];               /* float picks: slot i of 8 vertices */
} skin_tab;

SIMD_INL void tab_init(skin_tab *T)
{
    T->built = 0;
    _Alignas(64) short s01[32], s23[32];
    _Alignas(64) int wi[4][16];
    for (int l = 0; l < 32; l++) {
        s01[l] = (short)(4 * (l & 15) + (l >> 4));
        s23[l] = (short)(4 * (l & 15) + 2 + (l >> 4));
    }
    for (int i = 0; i < 4; i++)
        for (int l = 0; l < 16; l++) wi[i][l] = 4 * (l & 7) + i;
    T->sel01 = _mm512_load_si512(s01);
    T->sel23 = _mm512_load_si512(s23);
    for (int i = 0; i < 4; i++) T->widx[i] = _mm512_load_si512(wi[i]);
}

/* SoA weights, their nonzero masks, joint indices of 16 vertices, and
 * the largest joint read with a nonzero weight (-1: none). */
typedef struct blk16 {
    __m512 w[4];
    __mmask16 k[4];
    __m512i j[4];
    int maxj;
} blk16;

static inline void blk16_load(const skin_tab *T, const kin_mesh *mesh, int v, blk16 *b)
{
    const float *wp = mesh->weights + (size_t)v * 4;
    const uint16_t *jp = mesh->joints + (size_t)v * 4;
    const __m512 zero = _mm512_setzero_ps();
    __m512 A = _mm512_loadu_ps(wp), B = _mm512_loadu_ps(wp + 16),
           C = _mm512_loadu_ps(wp + 32), D = _mm512_loadu_ps(wp + 48);
    __mmask32 kx = (__mmask32)_mm512_cmp_ps_mask(A, zero, _CMP_NEQ_UQ) |
                   ((__mmask32)_mm512_cmp_ps_mask(B, zero, _CMP_NEQ_UQ) << 16);
    __mmask32 ky = (__mmask32)_mm512_cmp_ps_mask(C, zero, _CMP_NEQ_UQ) |
                   ((__mmask32)_mm512_cmp_ps_mask(D, zero, _CMP_NEQ_UQ) << 16);
    __m512i X = _mm512_loadu_si512(jp), Y = _mm512_loadu_si512(jp + 32);
    if (!(kx | ky)) {
        b->maxj = -1;
    } else {
        __m512i mx = _mm512_max_epu16(_mm512_maskz_mov_epi16(kx, X), _mm512_maskz_mov_epi16(ky, Y));
        __m256i m2 = _mm256_max_epu16(_mm512_castsi512_si256(mx), _mm512_extracti64x4_epi64(mx, 1));
        __m128i m1 = _mm_max_epu16(_mm256_castsi256_si128(m2), _mm256_extracti128_si256(m2, 1));
        m1 = _mm_minpos_epu16(_mm_xor_si128(m1, _mm_set1_epi32(-1)));
        b->maxj = 0xFFFF - (_mm_cvtsi128_si32(m1) & 0xFFFF);
    }
    __m512i p01 = _mm512_permutex2var_epi16(X, T->sel01, Y);
    __m512i p23 = _mm512_permutex2var_epi16(X, T->sel23, Y);
    b->j[0] = _mm512_cvtepu16_epi32(_mm512_castsi512_si256(p01));
    b->j[1] = _mm512_cvtepu16_epi32(_mm512_extracti64x4_epi64(p01, 1));
    b->j[2] = _mm512_cvtepu16_epi32(_mm512_castsi512_si256(p23));
    b->j[3] = _mm512_cvtepu16_epi32(_mm512_extracti64x4_epi64(p23, 1));
    for (int i = 0; i < 4; i++) {
        b->w[i] = _mm512_shuffle_f32x4(_mm512_permutex2var_ps(A, T->widx[i], B),
                                       _mm512_permutex2var_ps(C, T->widx[i], D), 0x44);
        b->k[i] = _mm512_cmp_ps_mask(b->w[i], zero, _CMP_NEQ_UQ);
    }
}

/* Element e of joints j[] (lanes), from a table row of 64 joints. */
static inline __m512 lookup(const float *row, __m512i j, int wide, __mmask16 hi)
{
    __m512 lo = _mm512_permutex2var_ps(_mm512_load_ps(row), j, _mm512_load_ps(row + 16));
    if (!wide) return lo;
    __m512 up = _mm512_permutex2var_ps(_mm512_load_ps(row + 32), j, _mm512_load_ps(row + 48));
    return _mm512_mask_blend_ps(hi, lo, up);
}

/* The four influence slots of one block: LBS (DQS 0: 12 matrix
 * elements) or DQS (DQS 1: 8 dual-quaternion elements); WIDE: joints up
 * to 63 (else up to 31). Per slot i the weight sum adds w_i in every
 * lane; in lanes with w_i != 0 the slot's joint elements x are looked up
 * and w_i * x added (masked product: +0 elsewhere). DQS first flips w_i
 * to -w_i where r_i . r_first < 0, in lanes that had a first influence
 * (the first one's own dot is >= 0: s = w, as the reference). Always
 * called with constant WIDE and DQS, so each call is its own loop. */
SIMD_INL void blend_slots(const skin_tab *T, const blk16 *b, const int WIDE, const int DQS,
                          __m512 acc[12], __m512 *wsum)
{
    const __m512 zero = _mm512_setzero_ps();
    __m512 ws = zero, r0[4] = { zero, zero, zero, zero };
    __mmask16 have = 0;   /* DQS: lanes whose first influence is known */
    for (int i = 0; i < 4; i++) {
        ws = _mm512_add_ps(ws, b->w[i]);
        const __mmask16 k = b->k[i];
        if (!k) continue;
        __mmask16 hi = _mm512_test_epi32_mask(b->j[i], _mm512_set1_epi32(32));
        if (!DQS) {   /* LBS: each element looked up and added at once */
#pragma GCC unroll 12
            for (int e = 0; e < 12; e++)
                acc[e] = _mm512_add_ps(acc[e], _mm512_maskz_mul_ps(
                    k, b->w[i], lookup(T->t[e], b->j[i], WIDE, hi)));
            continue;
        }
        __m512 x[8];
#pragma GCC unroll 8
        for (int e = 0; e < 8; e++) x[e] = lookup(T->t[e], b->j[i], WIDE, hi);
        __m512 dot = _mm512_add_ps(_mm512_add_ps(_mm512_add_ps(
                         _mm512_mul_ps(x[0], r0[0]), _mm512_mul_ps(x[1], r0[1])),
                         _mm512_mul_ps(x[2], r0[2])), _mm512_mul_ps(x[3], r0[3]));
        __mmask16 neg = _mm512_mask_cmp_ps_mask(have, dot, zero, _CMP_LT_OQ);
        __m512 sw = _mm512_mask_xor_ps(b->w[i], neg, b->w[i], _mm512_set1_ps(-0.0f));
        __mmask16 first = (__mmask16)(k & ~have);
#pragma GCC unroll 4
        for (int e = 0; e < 4; e++) r0[e] = _mm512_mask_mov_ps(r0[e], first, x[e]);
        have = (__mmask16)(have | k);
#pragma GCC unroll 8
        for (int e = 0; e < 8; e++) acc[e] = _mm512_add_ps(acc[e], _mm512_maskz_mul_ps(k, sw, x[e]));
    }
    *wsum = ws;
}

/* A block of 16 vertices by the joint table: LBS (DQS 0: xf the joint
 * matrices, o[12] as kin_skin_simd.inl's a[]) or DQS (DQS 1: xf the dual
 * quaternions, o[8]); blocks reading joints >= 64 take the rows path. The
 * table gets the joints up to the block's largest on demand, the
 * elements the blend reads: columns 0-3, rows 0-2 of a matrix (element
 * c * 3 + r), r.xyzw d.xyzw of a dual quaternion. */
SIMD_INL void table_block(skin_tab *T, const kin_mesh *mesh, const void *xf, int v,
                          const int DQS, __m512 *o, __m512 *wsum)
{
    blk16 b;
    blk16_load(T, mesh, v, &b);
    if (b.maxj >= 64) {
        if (DQS) dqs_rows(mesh, xf, v, o, wsum);
        else lbs_rows(mesh, xf, v, o, wsum);
        return;
    }
    if (b.maxj >= T->built) {
        if (T->built == 0) memset(T->t, 0, sizeof T->t);
        for (int jj = T->built; jj <= b.maxj; jj++) {
            if (DQS) {
                const float *src = &((const kin_dualquat *)xf)[jj].r.x;
                for (int e = 0; e < 8; e++) T->t[e][jj] = src[e];
            } else {
                const float *m = ((const kin_mat4 *)xf)[jj].m;
                for (int c = 0; c < 4; c++)
                    for (int r = 0; r < 3; r++) T->t[c * 3 + r][jj] = m[c * 4 + r];
            }
        }
        T->built = b.maxj + 1;
    }
    const int n = DQS ? 8 : 12;
    __m512 acc[12];
#pragma GCC unroll 12
    for (int e = 0; e < n; e++) acc[e] = _mm512_setzero_ps();
    if (b.maxj >= 32) blend_slots(T, &b, 1, DQS, acc, wsum);
    else blend_slots(T, &b, 0, DQS, acc, wsum);
#pragma GCC unroll 12
    for (int e = 0; e < n; e++) o[e] = acc[e];
}

static inline void lbs_block(skin_tab *T, const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             __m512 a[12], __m512 *wsum)
{
    table_block(T, mesh, jm, v, 0, a, wsum);
}

static inline void dqs_block(skin_tab *T, const kin_mesh *mesh, const kin_dualquat *dq, int v,
                             __m512 q[8], __m512 *wsum)
{
    table_block(T, mesh, dq, v, 1, q, wsum);
}

#include "kin_skin_simd.inl"

#endif
