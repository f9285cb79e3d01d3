/* raster_avx512.c - the AVX-512 scan (16 lanes, F+BW+DQ+VL): raster_simd.inl
 * on the vector layer's AVX-512 implementation (src/cpu/simd_avx512.h),
 * plus what only AVX-512 does (below: attributes stored through
 * permutes and lane masks per output vector, a division on 8 lanes);
 * masked loads and stores never touch disabled lanes. Called only when
 * cpuid reports AVX-512 (raster_context.c). Bytes equal
 * rast__scan_rows_ref. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <stddef.h>
#include <string.h>

#include "../cpu/simd_avx512.h"

/* simd__sel3 (the layer's vf_store3_bits table): lane f of simd__sel3[o]
 * holds the bit of the pixel that float 16*o + f belongs to,
 * 1 << ((16*o + f) / 3). */

/* The attributes of a one-vector row computed in the interleaved layout:
 * lane f of output vector o is attribute (16*o + f) % 3 of pixel
 * (16*o + f) / 3. Its barycentrics are lanes of the pixels' b1, b2
 * (permutes copy bits) and its constants a0, d1, d2 of that attribute, so
 * each float gets the reference's (a0 + b1 * d1) + b2 * d2, and no
 * transposition is needed: two permutes, four operations and a masked
 * store per output vector (a row of up to 5 pixels needs one;
 * attr3_prep, attr3_out below). pix3[o][f] = (16*o + f) / 3, att3[o][f] =
 * (16*o + f) % 3; attr3_store_m takes attribute 2's lanes by pix3 too. */
static const int32_t pix3[3][16] __attribute__((aligned(64))) = {
    { 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5 },
    { 5, 5, 6, 6, 6, 7, 7, 7, 8, 8, 8, 9, 9, 9, 10, 10 },
    { 10, 11, 11, 11, 12, 12, 12, 13, 13, 13, 14, 14, 14, 15, 15, 15 },
};
static const int32_t att3[3][16] __attribute__((aligned(64))) = {
    { 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0 },
    { 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1 },
    { 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2 },
};
/* The pixels in bits only (masked stores: other floats are not touched),
 * bits within the first `lanes` lanes. Only the output vectors those lanes
 * reach are built (a box 5 pixels wide needs one of the three: the count
 * is fixed per triangle, so the loop is predicted), and their store masks
 * come from one broadcast and a vptestmd each (a zero mask stores
 * nothing). */
static inline void attr3_store_m(float *p, unsigned bits, int lanes, __m512 a, __m512 b,
                                 __m512 c)
{
    static const int32_t idx_ab[3][16] __attribute__((aligned(64))) = {
        { 0, 16, 0, 1, 17, 0, 2, 18, 0, 3, 19, 0, 4, 20, 0, 5 },
        { 21, 0, 6, 22, 0, 7, 23, 0, 8, 24, 0, 9, 25, 0, 10, 26 },
        { 0, 11, 27, 0, 12, 28, 0, 13, 29, 0, 14, 30, 0, 15, 31, 0 },
    };
    static const __mmask16 mc[3] = { 0x4924, 0x2492, 0x9249 };
    const __m512i pb = _mm512_set1_epi32((int)bits);
    const int nout = lanes >= 16 ? 3 : (3 * lanes + 15) >> 4;
    for (int o = 0; o < nout; o++) {
        const __mmask16 k = _mm512_test_epi32_mask(pb, _mm512_load_si512(simd__sel3[o]));
        __m512 v = _mm512_permutex2var_ps(a, _mm512_load_si512(idx_ab[o]), b);
        /* the lanes of attribute 2 (mc): pixel pix3 of c */
        v = _mm512_mask_permutexvar_ps(v, mc[o], _mm512_load_si512(pix3[o]), c);
        _mm512_mask_storeu_ps(p + 16 * o, k, v);
    }
}
#define ATTR3_STORE_M(p, bits, lanes, a, b, c) attr3_store_m(p, bits, lanes, a, b, c)

typedef struct attr3_state {
    __m512 a0[3], d1[3], d2[3];   /* per output vector, its lanes' constants */
    int nout;                     /* output vectors a row needs (1..3) */
} attr3_state;

static inline void attr3_prep(attr3_state *st, const rast__tri *tri, int lanes)
{
    const __m512 a0 = _mm512_castps128_ps512(_mm_maskz_loadu_ps(7, tri->a0));
    const __m512 d1 = _mm512_castps128_ps512(_mm_maskz_loadu_ps(7, tri->d1));
    const __m512 d2 = _mm512_castps128_ps512(_mm_maskz_loadu_ps(7, tri->d2));
    st->nout = lanes >= 16 ? 3 : (3 * lanes + 15) >> 4;
    for (int o = 0; o < 3; o++) {
        const __m512i k = _mm512_load_si512(att3[o]);
        st->a0[o] = _mm512_permutexvar_ps(k, a0);
        st->d1[o] = _mm512_permutexvar_ps(k, d1);
        st->d2[o] = _mm512_permutexvar_ps(k, d2);
    }
}

static inline void attr3_out(float *p, __m512i pb, const attr3_state *st, int o, __m512 b1,
                             __m512 b2)
{
    const __m512i pix = _mm512_load_si512(pix3[o]);
    const __m512 b1o = _mm512_permutexvar_ps(pix, b1);
    const __m512 b2o = _mm512_permutexvar_ps(pix, b2);
    const __m512 a = _mm512_add_ps(_mm512_add_ps(st->a0[o], _mm512_mul_ps(b1o, st->d1[o])),
                                   _mm512_mul_ps(b2o, st->d2[o]));
    const __mmask16 k = _mm512_test_epi32_mask(pb, _mm512_load_si512(simd__sel3[o]));
    _mm512_mask_storeu_ps(p + 16 * o, k, a);
}

static inline void attr3_store_p(float *p, unsigned bits, const attr3_state *st, __m512 b1,
                                 __m512 b2)
{
    const __m512i pb = _mm512_set1_epi32((int)bits);
    attr3_out(p, pb, st, 0, b1, b2);
    if (st->nout > 1) {
        attr3_out(p, pb, st, 1, b1, b2);
        if (st->nout > 2)
            attr3_out(p, pb, st, 2, b1, b2);
    }
}

/* As attr3_store_p for a vector of `lanes` pixels (bits within them) of
 * a wider row: the output vectors those lanes reach, whatever the state
 * was prepared for. */
static inline void attr3_store_pl(float *p, unsigned bits, int lanes, const attr3_state *st,
                                  __m512 b1, __m512 b2)
{
    const __m512i pb = _mm512_set1_epi32((int)bits);
    attr3_out(p, pb, st, 0, b1, b2);
    if (lanes > 5) {
        attr3_out(p, pb, st, 1, b1, b2);
        if (lanes > 10)
            attr3_out(p, pb, st, 2, b1, b2);
    }
}

/* a / b in the first `lanes` lanes (the others 0 or a / b, never stored):
 * one 256-bit division when they fit in 8 (half the divider's time on
 * Zen 4). */
static inline __m512 div_lanes(__m512 a, __m512 b, int lanes)
{
    if (lanes <= 8)
        return _mm512_zextps256_ps512(
            _mm256_div_ps(_mm512_castps512_ps256(a), _mm512_castps512_ps256(b)));
    return _mm512_div_ps(a, b);
}
#define VF_DIV_LANES(a, b, lanes) div_lanes(a, b, lanes)
#define ATTR3_STATE attr3_state
#define ATTR3_PREP(st, tri, lanes) attr3_prep(st, tri, lanes)
#define ATTR3_STORE_P(p, bits, st, b1, b2, in) attr3_store_p(p, bits, st, b1, b2)
#define ATTR3_STORE_PL(p, bits, lanes, st, b1, b2, in) attr3_store_pl(p, bits, lanes, st, b1, b2)
/* The n10 plane's store (N10_STORE, raster_simd.inl): one masked store of
 * the packed lanes in bits (no other uint32_t touched). */
#define N10_STORE(p, bits, v, in) _mm512_mask_storeu_epi32(p, (__mmask16)(bits), v)

#include "raster_simd.inl"

/* ---- vertex transforms (rast_transform_points / rast_transform_dirs):
 * raster_xform.inl on the layer, 16 vertices per step; the four component
 * vectors interleaved by two-source permutes: output o of 4, float f is
 * component f % 4 of vertex 4o + f / 4; (c0, c1) and (c2, c3) are permuted
 * with the same index, then blended (components 2 and 3: mask 0xCCCC). */
SIMD_INL void xf_store4(float *p, vfloat c0, vfloat c1, vfloat c2, vfloat c3)
{
    static const int32_t inter4[4][16] __attribute__((aligned(64))) = {
        { 0, 16, 0, 16, 1, 17, 1, 17, 2, 18, 2, 18, 3, 19, 3, 19 },
        { 4, 20, 4, 20, 5, 21, 5, 21, 6, 22, 6, 22, 7, 23, 7, 23 },
        { 8, 24, 8, 24, 9, 25, 9, 25, 10, 26, 10, 26, 11, 27, 11, 27 },
        { 12, 28, 12, 28, 13, 29, 13, 29, 14, 30, 14, 30, 15, 31, 15, 31 },
    };
#pragma GCC unroll 4
    for (int o = 0; o < 4; o++) {
        const __m512i idx = _mm512_load_si512(inter4[o]);
        const __m512 a = _mm512_permutex2var_ps(c0, idx, c1);
        const __m512 b = _mm512_permutex2var_ps(c2, idx, c3);
        _mm512_storeu_ps(p + 16 * o, _mm512_mask_blend_ps((__mmask16)0xCCCC, a, b));
    }
}
#include "raster_xform.inl"

/* Anti-aliased coverage: 8 double lanes. */
#define AA_V 8
#define AA_FN rast__scan_aa_avx512
#include "raster_aa.inl"

/* Batched set-up (raster_planes.inl, 8 double lanes): the de-interleave of
 * a vertex block, the 16-lane rejection, then the one body. */
/* 16 vertices xyzw: per pair of input vectors one two-source permute puts
 * x (low half) and y (high half), another z and w; 128-bit shuffles join
 * the halves of the two pairs. */
static inline void load_block_xyzw(const float *c, float *x, float *y, float *z, float *w)
{
    const __m512 v0 = _mm512_loadu_ps(c), v1 = _mm512_loadu_ps(c + 16);
    const __m512 v2 = _mm512_loadu_ps(c + 32), v3 = _mm512_loadu_ps(c + 48);
    const __m512i ixy = _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 1, 5, 9, 13, 17, 21,
                                          25, 29);
    const __m512i izw = _mm512_add_epi32(ixy, _mm512_set1_epi32(2));
    const __m512 xy01 = _mm512_permutex2var_ps(v0, ixy, v1);
    const __m512 xy23 = _mm512_permutex2var_ps(v2, ixy, v3);
    const __m512 zw01 = _mm512_permutex2var_ps(v0, izw, v1);
    const __m512 zw23 = _mm512_permutex2var_ps(v2, izw, v3);
    _mm512_store_ps(x, _mm512_shuffle_f32x4(xy01, xy23, 0x44));
    _mm512_store_ps(y, _mm512_shuffle_f32x4(xy01, xy23, 0xEE));
    _mm512_store_ps(z, _mm512_shuffle_f32x4(zw01, zw23, 0x44));
    _mm512_store_ps(w, _mm512_shuffle_f32x4(zw01, zw23, 0xEE));
}
#define LOAD_BLOCK_XYZW(c, x, y, z, w) load_block_xyzw(c, x, y, z, w)

/* Lane macros, the rejection helpers and raster_front.inl. */
#include "raster_front_avx512.inl"

_Static_assert(sizeof(rast__vc_entry) == 32 && offsetof(rast__vc_entry, flags) == 4 &&
                   offsetof(rast__vc_entry, X) == 8 && offsetof(rast__vc_entry, Y) == 12,
               "rast__front_avx512 gathers (tag, flags) and (X, Y) as qwords 4s, 4s+1");

/* Trivial rejection of 16 submitted triangles (rast__front_fn, see
 * raster_internal.h). Per lane, the decisions of the scalar front end
 * (prepare_cached_one and setup_box_edges in raster_setup.c):
 *   area sign: p1 = dx1*dy2 and p2 = dy1*dx2 in double (|d| < 2^23, so
 *     both products and their order are exact), area = p1 - p2;
 *   degenerate (area 0), culled (back: area > 0, front: area < 0);
 *   box: x0 = max((xmin + 127) >> 8, 0), x1 = min((xmax - 128) >> 8, W-1)
 *     (y alike), off screen when empty;
 *   box of at most 2x2 pixels (before clamping too, so every coordinate
 *     difference is below 768 and the int32 products below 2^20): the
 *     three biased edge values at each pixel centre of the clamped box,
 *     winding normalised; empty when no centre has all three >= 0. */
unsigned rast__front_avx512(const rast__view *v, const rast_mesh_desc *m, rast__vcache *vc,
                            int ti, rast_stats *st, rast__vfill_fn vfill)
{
    const uint32_t *ix = m->indices + 3 * (size_t)ti;
    const __m512i a = _mm512_loadu_si512(ix), b = _mm512_loadu_si512(ix + 16),
                  c = _mm512_loadu_si512(ix + 32);
    const __m512i one = _mm512_set1_epi32(1);
    __m512i iv[3];
    deint_tris(a, b, c, iv);
    /* Cache entries are 32 bytes: qword 4s of slot s holds (tag, flags),
     * qword 4s + 1 the snapped (X, Y). Each pair comes with one 64-bit
     * gather element (8 lanes per gather, half the element loads of
     * 32-bit gathers) and is split into 16-lane vectors by permutes. */
    const long long *eb = (const long long *)(const void *)vc->e;
    const __m512i smask = _mm512_set1_epi32(RAST__VCACHE - 1);
    __m512i so[3], tf[3][2];
    unsigned miss = 0;
    for (int k = 0; k < 3; k++) {
        so[k] = _mm512_slli_epi32(_mm512_and_si512(iv[k], smask), 2);
        gather_pairs(eb, so[k], tf[k]);
        miss |= _mm512_cmpneq_epi32_mask(pairs_lo(tf[k]), iv[k]);
    }
    if (miss) {
        _Alignas(64) uint32_t idx[3][16];
        for (int k = 0; k < 3; k++)
            _mm512_store_si512(idx[k], iv[k]);
        for (unsigned bits = miss; bits; bits &= bits - 1) {
            const int l = __builtin_ctz(bits);
            for (int k = 0; k < 3; k++) {
                const uint32_t i = idx[k][l];
                if (vc->e[i & (RAST__VCACHE - 1)].tag == i)
                    continue;
                const uint32_t base = i & ~(uint32_t)(RAST__VBLOCK - 1);
                const uint32_t left = (uint32_t)m->vertex_count - base;
                vfill(v, m->clip, base, left < RAST__VBLOCK ? (int)left : RAST__VBLOCK,
                      &vc->e[base & (RAST__VCACHE - 1)]);
            }
        }
        unsigned still = 0;
        for (int k = 0; k < 3; k++) {
            gather_pairs(eb, so[k], tf[k]);
            still |= _mm512_cmpneq_epi32_mask(pairs_lo(tf[k]), iv[k]);
        }
        if (still)   /* slots shared inside the group: the scalar path */
            return 0xFFFFu;
    }
    __m512i X[3], Y[3], fl = _mm512_setzero_si512();
    for (int k = 0; k < 3; k++) {
        __m512i xy[2];
        fl = _mm512_or_si512(fl, pairs_hi(tf[k]));
        gather_pairs(eb, _mm512_add_epi32(so[k], one), xy);
        X[k] = pairs_lo(xy);
        Y[k] = pairs_hi(xy);
    }
    const unsigned special = _mm512_test_epi32_mask(fl, fl);
    unsigned pos, neg;
    front_area_signs(X, Y, &pos, &neg);
    const front_class cl = front_classify(m->cull, ~special & 0xFFFFu, pos, neg);
    const front_box bx = front_box_of(X, Y, v->width, v->height);
    const unsigned live2 = cl.live & ~bx.off;
    unsigned empty = 0;
    const unsigned small = live2 & bx.usmall;
    if (small) {
        const __mmask16 sw = (__mmask16)neg;   /* normalise: swap 1 and 2 */
        const __m512i x1 = _mm512_mask_blend_epi32(sw, X[1], X[2]);
        const __m512i x2 = _mm512_mask_blend_epi32(sw, X[2], X[1]);
        const __m512i y1 = _mm512_mask_blend_epi32(sw, Y[1], Y[2]);
        const __m512i y2 = _mm512_mask_blend_epi32(sw, Y[2], Y[1]);
        empty = small & front_empty_small(X[0], Y[0], x1, y1, x2, y2, bx.bx0, bx.by0, bx.bx1,
                                          bx.by1);
    }
    front_count(st, cl.degen, cl.culled, cl.live & bx.off, empty);
    return special | (live2 & ~empty);
}
#define FRONT_FN rast__front_avx512
/* The vector front end: raster_front_avx512.c. */
#define VPASS_FN rast__vpass_avx512
#define FRONTV_FN rast__frontv_avx512
#include "raster_planes.inl"

#else
typedef int rast__avx512_unused;   /* not an x86 build: the dispatcher skips it */
#endif
