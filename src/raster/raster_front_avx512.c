/* raster_front_avx512.c - the vector front end (AVX-512 F+BW+DQ+VL):
 * vertex pass, rejection of 16 submitted triangles per group and the
 * set-up of 16 survivors per vector, straight into scan-ready records
 * (rast__vpass_fn, rast__frontv_fn in raster_internal.h; design and
 * figures in docs/raster.md section 11, sixth round).
 *
 * Every lane runs the operations of the scalar path in its order (no
 * contraction: -ffp-contract=off), so every byte equals rast__prepare_range
 * with the scalar set-up:
 *   vertex pass   vc_fill_one (finiteness, outcode, w > 0, snap, zw, iw);
 *   rejection     prepare_cached_one + setup_box_edges (area sign exact in
 *                 double, culling, clamped box, empty boxes of at most
 *                 2x2 pixels);
 *   set-up        setup_edges (int64 edges by vpmuldq), planes_one (the
 *                 double plane set-up, as raster_planes.inl), setup_attrs;
 *                 for boxes of at most 2x2 pixels, micro records instead
 *                 (micro_lanes: the scan's per-pixel values, in lanes).
 * Triangles with a vertex that is not finite, outside a clip plane or at
 * w <= 0 go through rast__prepare at their place in the order. The vertex
 * pass, the rejection's steps, the planes and the micro values are written
 * once on the vector layer (raster_front.inl, raster_frontv.inl); this file
 * keeps what AVX-512 does with mask registers and two-source permutes (the
 * index de-interleave, the queue's masked permutes, the int64 edges, the
 * record layouts).
 *
 * Speed (issue 3, tenth round; Zen 4): the survivor queue stays in
 * registers (survivors merged in by one masked permutation per field, no
 * unaligned store reloaded by flush); flush keeps the edges and planes in
 * vectors (fv_planes, the loops written out or unrolled so that no vector
 * goes through the stack) and writes each record by 16-byte copies from
 * lane-transposed stack layouts (quads, pairs) instead of a scalar copy
 * per field; the positions are loaded with the indices read from the mesh. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <stddef.h>
#include <string.h>

#include "../cpu/simd_avx512.h"

/* ---- vertex pass -------------------------------------------------------- */

/* count (1..16) vertices xyzw at c, de-interleaved; lanes past count 0. */
static inline __attribute__((always_inline)) void fv_load_xyzw(const float *c, int count,
                                                               vfloat *x, vfloat *y,
                                                               vfloat *z, vfloat *w)
{
    __m512 v[4];
    for (int i = 0; i < 4; i++) {
        const int left = 4 * count - 16 * i;
        if (left >= 16)
            v[i] = _mm512_loadu_ps(c + 16 * i);
        else if (left > 0)
            v[i] = _mm512_maskz_loadu_ps((__mmask16)((1u << left) - 1u), c + 16 * i);
        else
            v[i] = _mm512_setzero_ps();
    }
    const __m512i ixy = _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 1, 5, 9, 13, 17, 21,
                                          25, 29);
    const __m512i izw = _mm512_add_epi32(ixy, _mm512_set1_epi32(2));
    const __m512 xy01 = _mm512_permutex2var_ps(v[0], ixy, v[1]);
    const __m512 xy23 = _mm512_permutex2var_ps(v[2], ixy, v[3]);
    const __m512 zw01 = _mm512_permutex2var_ps(v[0], izw, v[1]);
    const __m512 zw23 = _mm512_permutex2var_ps(v[2], izw, v[3]);
    *x = _mm512_shuffle_f32x4(xy01, xy23, 0x44);
    *y = _mm512_shuffle_f32x4(xy01, xy23, 0xEE);
    *z = _mm512_shuffle_f32x4(zw01, zw23, 0x44);
    *w = _mm512_shuffle_f32x4(zw01, zw23, 0xEE);
}

/* The rejection helpers of AVX-512 and raster_front.inl (the rejection on
 * the vector layer). */
#include "raster_front_avx512.inl"

/* p[V[l]] for the lanes l of half h (fv_gather_d of raster_frontv.inl):
 * every lane, flush masks V to vertex 0 where unused. */
static inline __attribute__((always_inline)) vdouble fv_gather_d(const double *p, vint V, int h)
{
    return _mm512_i32gather_pd(half_i(V, h), p, 8);
}

/* The vertex pass rast__vpass_avx512, the planes and the micro values,
 * written once on the vector layer. */
#include "raster_frontv.inl"

/* The (X, Y) pairs p64[ix[s * l]] of the 16 lanes l, by scalar 64-bit
 * loads (gather_pairs without vpgatherdq), split into X (low dwords) and
 * Y (high dwords). Written out so that no vector goes through memory. */
static inline __attribute__((always_inline)) void load_xy(const long long *p64,
                                                          const uint32_t *ix, ptrdiff_t s,
                                                          __m512i *X, __m512i *Y)
{
#define PAIR(l0, l1) _mm_set_epi64x(p64[ix[s * (l1)]], p64[ix[s * (l0)]])
#define QUAD(l) _mm256_inserti128_si256(_mm256_castsi128_si256(PAIR(l, l + 1)), \
                                        PAIR(l + 2, l + 3), 1)
    const __m512i p0 = _mm512_inserti64x4(_mm512_castsi256_si512(QUAD(0)), QUAD(4), 1);
    const __m512i p1 = _mm512_inserti64x4(_mm512_castsi256_si512(QUAD(8)), QUAD(12), 1);
#undef QUAD
#undef PAIR
    const __m512i ie = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26,
                                         28, 30);
    *X = _mm512_permutex2var_epi32(p0, ie, p1);
    *Y = _mm512_permutex2var_epi32(p0, _mm512_add_epi32(ie, _mm512_set1_epi32(1)), p1);
}

/* ---- survivor set-up ---------------------------------------------------- */

/* The records are written per lane from two stack layouts filled by
 * shuffles (instead of a scalar copy per field):
 *   quads  4 float or int32 vectors a, b, c, d: lane l's (a, b, c, d) as 16
 *          bytes at s + QUAD_AT(l) (4 stores of 64 bytes);
 *   pairs  2 int64 vectors a, b of lanes 8h .. 8h+7: lane l's (a, b) as 16
 *          bytes at s + PAIR_AT(l) (2 stores of 64 bytes per half). */
#define QUAD_AT(l) (16 * ((l) & 3) + 4 * ((l) >> 2))
#define PAIR_AT(l) (16 * ((l) >> 3) + 8 * ((l) & 1) + 2 * (((l) >> 1) & 3))

static inline void quads(__m512 a, __m512 b, __m512 c, __m512 d, float *s)
{
    const __m512d ablo = _mm512_castps_pd(_mm512_unpacklo_ps(a, b));   /* a0 b0 a1 b1 */
    const __m512d abhi = _mm512_castps_pd(_mm512_unpackhi_ps(a, b));   /* a2 b2 a3 b3 */
    const __m512d cdlo = _mm512_castps_pd(_mm512_unpacklo_ps(c, d));
    const __m512d cdhi = _mm512_castps_pd(_mm512_unpackhi_ps(c, d));
    _mm512_store_pd((double *)(void *)s, _mm512_unpacklo_pd(ablo, cdlo));   /* lanes 4k */
    _mm512_store_pd((double *)(void *)(s + 16), _mm512_unpackhi_pd(ablo, cdlo));
    _mm512_store_pd((double *)(void *)(s + 32), _mm512_unpacklo_pd(abhi, cdhi));
    _mm512_store_pd((double *)(void *)(s + 48), _mm512_unpackhi_pd(abhi, cdhi));
}

static inline void pairs(__m512i a, __m512i b, int64_t *s)
{
    _mm512_store_si512((void *)s, _mm512_unpacklo_epi64(a, b));         /* lanes 2k */
    _mm512_store_si512((void *)(s + 8), _mm512_unpackhi_epi64(a, b));   /* lanes 2k+1 */
}

/* 16 bytes from s to d. */
static inline void copy16(void *d, const void *s)
{
    _mm_storeu_si128((__m128i *)d, _mm_load_si128((const __m128i *)s));
}

#include "raster_front_rec.inl"

/* Micro lanes (clamped box at most 2x2 pixels): the covered pixels and,
 * for each of the box's four pixels (i, j), the scan's values: the clamped
 * depth z and the barycentrics b1, b2, computed per lane with the float
 * operations of rast__scan_rows_ref in its order (fi, fj are 0.0f or
 * 1.0f, multiplied as the scan multiplies them). cov[l]: bit i + 2j for
 * a covered pixel (the int64 edge test of the scan at that pixel); the
 * values of lane l as quads (mz, mb1, mb2 of its record) at mq + QUAD_AT(l),
 * mq + 64 + QUAD_AT(l), mq + 128 + QUAD_AT(l). */
static inline __attribute__((always_inline)) unsigned micro_lanes(const __m512i *qf,
                                                                   __mmask16 L,
                                                                   const __m512i (*E)[2],
                                                                   const __m512 *P,
                                                                   uint8_t *cov, float *mq)
{
    const __m512i one = _mm512_set1_epi32(1);
    const __m512i w1 = _mm512_sub_epi32(qf[Q_BX1], qf[Q_BX0]);
    const __m512i h1 = _mm512_sub_epi32(qf[Q_BY1], qf[Q_BY0]);
    const __mmask16 wide = _mm512_cmpeq_epi32_mask(w1, one);   /* 2 columns */
    const __mmask16 tall = _mm512_cmpeq_epi32_mask(h1, one);   /* 2 rows */
    const __mmask16 mic = L & _mm512_cmple_epi32_mask(w1, one) &
                          _mm512_cmple_epi32_mask(h1, one);
    if (!mic)
        return 0;
    /* Coverage: E = e_c + i*e_dx + j*e_dy, int64, at the four pixels. */
    __mmask16 cv[4] = { 0, 0, 0, 0 };
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        __m512i o[4] = { _mm512_setzero_si512(), _mm512_setzero_si512(),
                         _mm512_setzero_si512(), _mm512_setzero_si512() };
#pragma GCC unroll 3
        for (int e = 0; e < 3; e++) {
            const __m512i c = E[e][h], ex = E[3 + e][h], ey = E[6 + e][h];
            const __m512i c01 = _mm512_add_epi64(c, ey);
            o[0] = _mm512_or_si512(o[0], c);
            o[1] = _mm512_or_si512(o[1], _mm512_add_epi64(c, ex));
            o[2] = _mm512_or_si512(o[2], c01);
            o[3] = _mm512_or_si512(o[3], _mm512_add_epi64(c01, ex));
        }
#pragma GCC unroll 4
        for (int p = 0; p < 4; p++)
            cv[p] |= (__mmask16)((unsigned)(uint8_t)~_mm512_movepi64_mask(o[p]) << (8 * h));
    }
    cv[0] &= mic;
    cv[1] &= mic & wide;
    cv[2] &= mic & tall;
    cv[3] &= mic & wide & tall;
    const __mmask16 any = cv[0] | cv[1] | cv[2] | cv[3];
    if (!any)
        return mic;
    const __m512i bit = _mm512_set1_epi32(1);
    __m512i cb = _mm512_setzero_si512();
#pragma GCC unroll 4
    for (int p = 0; p < 4; p++)
        cb = _mm512_mask_or_epi32(cb, cv[p], cb, _mm512_slli_epi32(bit, p));
    _mm_storeu_si128((__m128i *)(void *)cov, _mm512_cvtepi32_epi8(cb));
    /* The values (the scan's expressions; unused lanes compute garbage). */
    __m512 Z[4], B1[4], B2[4];
    fv_micro_values(P, Z, B1, B2);
    quads(Z[0], Z[1], Z[2], Z[3], mq);
    quads(B1[0], B1[1], B1[2], B1[3], mq + 64);
    quads(B2[0], B2[1], B2[2], B2[3], mq + 128);
    return mic;
}

/* Sets up queue lanes 0 .. k-1 (k = 1..16; qf[field] as in the queue)
 * into their records. */
static void flush(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                  const __m512i *qf, int k, rast__tri *out, int micro)
{
    const __mmask16 L = k >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << k) - 1u);
    __m512i X[3], Y[3], V[3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; i++) {
        X[i] = qf[Q_X0 + i];
        Y[i] = qf[Q_Y0 + i];
        V[i] = _mm512_maskz_mov_epi32(L, qf[Q_V0 + i]);
    }
    const __m512i bx0 = qf[Q_BX0], by0 = qf[Q_BY0];
    /* the per-lane fields the record loop reads */
    _Alignas(64) int32_t qs[Q_FIELDS][16];
#pragma GCC unroll 3
    for (int f = Q_V0; f <= Q_V2; f++)
        _mm512_store_si512((void *)qs[f], qf[f]);
    _mm512_store_si512((void *)qs[Q_SLOT], qf[Q_SLOT]);
    const __m512i c128 = _mm512_set1_epi32(RAST__FIX_HALF);
    const __m512i cx = _mm512_add_epi32(_mm512_slli_epi32(bx0, RAST_SUBPIXEL_BITS), c128);
    const __m512i cy = _mm512_add_epi32(_mm512_slli_epi32(by0, RAST_SUBPIXEL_BITS), c128);

    /* setup_edges: edge e from vertex ea[e] to eb[e]; E[f][h] the int64
     * lanes 8h .. 8h+7 of e_c[e] (f = e), e_dx[e] (3 + e), e_dy[e] (6 + e),
     * the order of the record. */
    __m512i E[9][2];
    static const int ea[3] = { 1, 2, 0 }, eb[3] = { 2, 0, 1 };
    const __m512i one64 = _mm512_set1_epi64(1), zero = _mm512_setzero_si512();
#pragma GCC unroll 3
    for (int e = 0; e < 3; e++) {
        const int a = ea[e], b = eb[e];
        const __m512i dx = _mm512_sub_epi32(X[b], X[a]), dy = _mm512_sub_epi32(Y[b], Y[a]);
        const __mmask16 tl = top_left(dx, dy);
        const __m512i oy = _mm512_sub_epi32(cy, Y[a]), ox = _mm512_sub_epi32(cx, X[a]);
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
            const __m512i dx64 = _mm512_cvtepi32_epi64(half_i(dx, h));
            const __m512i dy64 = _mm512_cvtepi32_epi64(half_i(dy, h));
            const __m512i p1 = _mm512_mul_epi32(dx64, _mm512_cvtepi32_epi64(half_i(oy, h)));
            const __m512i p2 = _mm512_mul_epi32(dy64, _mm512_cvtepi32_epi64(half_i(ox, h)));
            const __m512i r = _mm512_sub_epi64(p1, p2);
            const __mmask8 bias = (__mmask8)~(tl >> (8 * h));
            E[e][h] = _mm512_mask_sub_epi64(r, bias, r, one64);
            E[3 + e][h] = _mm512_sub_epi64(zero, _mm512_slli_epi64(dy64, RAST_SUBPIXEL_BITS));
            E[6 + e][h] = _mm512_slli_epi64(dx64, RAST_SUBPIXEL_BITS);
        }
    }

    /* planes_one per lane. */
    __m512 P[12];
    fv_planes(X, Y, V, bx0, by0, k, vb, P);

    /* The records: lane l -> out[slot l]. */
    _Alignas(64) uint8_t cov[16] = { 0 };
    _Alignas(64) float mq[3 * 64];
    const unsigned mic = micro ? micro_lanes(qf, L, (const __m512i (*)[2])E, P, cov, mq)
                               : 0u;
    const unsigned hid =
        fv_hidden(micro ? v->hz : NULL, P, bx0, by0, qf[Q_BX1], qf[Q_BY1], L & ~mic);
    /* box; the planes z.c .. q.c, q.dx .. b1.dx, b1.dy .. b2.dy */
    _Alignas(64) int32_t bq[64];
    _Alignas(64) float pq[3 * 64];
    quads(_mm512_castsi512_ps(bx0), _mm512_castsi512_ps(by0), _mm512_castsi512_ps(qf[Q_BX1]),
          _mm512_castsi512_ps(qf[Q_BY1]), (float *)(void *)bq);
    /* the edge pairs (e_c[0], e_c[1]) .. (e_dy[0], e_dy[1]) at 16 .. 79 and
     * e_dy[2] at 80 */
    _Alignas(64) int64_t eq[4][32], e8[16];
    if ((mic | hid) != L) {
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++)
            quads(P[4 * i], P[4 * i + 1], P[4 * i + 2], P[4 * i + 3], pq + 64 * i);
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
#pragma GCC unroll 4
            for (int i = 0; i < 4; i++)
                pairs(E[2 * i][h], E[2 * i + 1][h], eq[i] + 16 * h);
            _mm512_store_si512((void *)(e8 + 8 * h), E[8][h]);
        }
    }
    const int ac = v->attr_count;
    const __mmask8 AM = (__mmask8)((1u << ac) - 1u);
    for (int l = 0; l < k; l++) {
        rast__tri *t = out + qs[Q_SLOT][l];
        if ((hid >> l) & 1u) {
            front_hidden_record(t, l, bq);
            continue;
        }
        if (!front_write_record(t, l, (int)((mic >> l) & 1u), (unsigned)cov[l], ac, bq, mq, pq,
                                (const int64_t (*)[2 * FRONT_V])eq, e8))
            continue;
        /* setup_attrs: a0 = attribute of vertex 0, d1 = a1 - a0,
         * d2 = a2 - a0, per record by masked loads (no byte past the
         * vertex's ac floats is read) and masked stores (no byte past
         * a0[ac - 1], d1[ac - 1], d2[ac - 1] is written). */
        if (ac > 0) {
            const float *a0p = m->attr + (size_t)qs[Q_V0][l] * (size_t)ac;
            const float *a1p = m->attr + (size_t)qs[Q_V1][l] * (size_t)ac;
            const float *a2p = m->attr + (size_t)qs[Q_V2][l] * (size_t)ac;
            const __m256 a0 = _mm256_maskz_loadu_ps(AM, a0p);
            const __m256 a1 = _mm256_maskz_loadu_ps(AM, a1p);
            const __m256 a2 = _mm256_maskz_loadu_ps(AM, a2p);
            _mm256_mask_storeu_ps(t->a0, AM, a0);
            _mm256_mask_storeu_ps(t->d1, AM, _mm256_sub_ps(a1, a0));
            _mm256_mask_storeu_ps(t->d2, AM, _mm256_sub_ps(a2, a0));
        }
    }
}

_Static_assert(RAST__FRONT_GROUP == 16, "one group per 16-lane vector");
_Static_assert(RAST_MAX_ATTRS <= 8, "attributes by 8-lane masked loads and stores");

int rast__frontv_avx512(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                        int ti0, int ti1, rast__tri *out, rast_stats *st, int micro)
{
    rast_stats ls = *st;
    /* The survivor queue in registers: qf[field] lanes 0 .. qn-1. */
    __m512i qf[Q_FIELDS];
#pragma GCC unroll 14
    for (int f = 0; f < Q_FIELDS; f++)
        qf[f] = _mm512_setzero_si512();
    int qn = 0;
    int n = 0;
    const long long *xyb = (const long long *)(const void *)vb->xy;
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i zero = _mm512_setzero_si512();
    const int vw = v->width, vh = v->height;   /* kept in registers */
    for (int ti = ti0; ti < ti1; ti += 16) {
        const int cnt = ti1 - ti < 16 ? ti1 - ti : 16;
        const unsigned L = cnt == 16 ? 0xFFFFu : (1u << cnt) - 1u;
        /* Indices of the group, de-interleaved (lanes past cnt: vertex 0). */
        const uint32_t *ix = m->indices + 3 * (size_t)ti;
        const int ne = 3 * cnt;
        __m512i iw3[3];
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++) {
            const int left = ne - 16 * i;
            iw3[i] = left >= 16 ? _mm512_loadu_si512((const void *)(ix + 16 * i))
                     : left > 0 ? _mm512_maskz_loadu_epi32((__mmask16)((1u << left) - 1u),
                                                           (const void *)(ix + 16 * i))
                                : zero;
        }
        __m512i iv[3], X[3], Y[3];
        deint_tris(iw3[0], iw3[1], iw3[2], iv);
        /* (X, Y) pairs: one 64-bit load per vertex, by scalar loads
         * (faster than vpgatherdq on Zen 4: 0.95-0.97 of the whole draw's
         * time at 41k triangles, 0.97-0.99 at 10k, in one process), the
         * indices read from the mesh (a partial group: from a copy of the
         * de-interleaved vectors, vertex 0 past cnt). */
        if (cnt == 16) {
#pragma GCC unroll 3
            for (int k = 0; k < 3; k++)
                load_xy(xyb, ix + k, 3, &X[k], &Y[k]);
        } else {
            _Alignas(64) uint32_t ivs[3][16];
            for (int k = 0; k < 3; k++)
                _mm512_store_si512((void *)ivs[k], iv[k]);
            for (int k = 0; k < 3; k++)
                load_xy(xyb, ivs[k], 1, &X[k], &Y[k]);
        }
        /* lanes with a marked vertex; those needing the scalar path */
        unsigned marked;
        const unsigned special0 = fv_marked(X, Y, L, &ls, &marked);
        /* prepare_cached_one: area sign, degenerate, culling. */
        unsigned pos, neg;
        front_area_signs(X, Y, &pos, &neg);
        const front_class c = front_classify(m->cull, L & ~marked, pos, neg);
        /* setup_box_edges: the clamped pixel box, off screen, empty. */
        const front_box b = front_box_of(X, Y, vw, vh);
        /* A box of at most 2x2 pixels after clamping but not before (a
         * triangle across the border): the empty test needs int64 edges
         * there, so the (rare) lane takes the scalar path, which counts
         * it. */
        const unsigned csmall = c.live & ~b.off & b.small;
        const unsigned odd = csmall & ~b.usmall;
        const unsigned special = special0 | odd;
        const unsigned live2 = c.live & ~b.off & ~odd;
        /* Winding normalised (vertices 1 and 2 swapped where area < 0). */
        const __mmask16 sw = (__mmask16)neg;
        const __m512i x1 = _mm512_mask_blend_epi32(sw, X[1], X[2]);
        const __m512i x2 = _mm512_mask_blend_epi32(sw, X[2], X[1]);
        const __m512i y1 = _mm512_mask_blend_epi32(sw, Y[1], Y[2]);
        const __m512i y2 = _mm512_mask_blend_epi32(sw, Y[2], Y[1]);
        /* at most 2x2 before clamping: differences below 768, int32 edges */
        const unsigned small = csmall & b.usmall;
        unsigned empty = 0;
        if (small)
            empty = small & front_empty_small(X[0], Y[0], x1, y1, x2, y2, b.bx0, b.by0,
                                              b.bx1, b.by1);
        const unsigned surv = live2 & ~empty;
        /* drawn: survivors and empty ones */
        front_count(&ls, c.degen, c.culled, c.live & b.off, live2);
        if (!surv && !special)
            continue;
        /* Record slots in submission order; special triangles through the
         * scalar path at their place. */
        __m512i slot;
        if (special) {
            _Alignas(64) int32_t sl[16] = { 0 };
            n = front_slots(v, m, ti, special, surv, out, n, &ls, sl);
            slot = _mm512_maskz_compress_epi32((__mmask16)surv,
                                               _mm512_load_si512((const void *)sl));
        } else {
            slot = _mm512_add_epi32(_mm512_set1_epi32(n), iota);
            n += __builtin_popcount(surv);
        }
        if (!surv)
            continue;
        const __m512i vi1 = _mm512_mask_blend_epi32(sw, iv[1], iv[2]);
        const __m512i vi2 = _mm512_mask_blend_epi32(sw, iv[2], iv[1]);
        const __m512i fld[Q_FIELDS] = { X[0], x1, x2, Y[0], y1, y2, iv[0], vi1, vi2,
                                        b.bx0, b.by0, b.bx1, b.by1, slot };
        /* Append the survivors in registers: queue lane j >= qn takes
         * survivor j - qn, i.e. group lane idx[j] (rot: the slots, already
         * compressed); lanes j < qn of the same permutation hold the
         * survivors past lane 15 (survivor j - qn + 16), the next queue. */
        const int ns = __builtin_popcount(surv);
        const __m512i rot = _mm512_sub_epi32(iota, _mm512_set1_epi32(qn));
        const __m512i idx =
            _mm512_permutexvar_epi32(rot, _mm512_maskz_compress_epi32((__mmask16)surv, iota));
        const __mmask16 up = (__mmask16)(0xFFFFu << qn);
#pragma GCC unroll 13
        for (int f = 0; f < Q_SLOT; f++)
            qf[f] = _mm512_mask_permutexvar_epi32(qf[f], up, idx, fld[f]);
        qf[Q_SLOT] = _mm512_mask_permutexvar_epi32(qf[Q_SLOT], up, rot, slot);
        qn += ns;
        if (qn >= 16) {
            flush(v, m, vb, qf, 16, out, micro);
            qn -= 16;
#pragma GCC unroll 13
            for (int f = 0; f < Q_SLOT; f++)
                qf[f] = _mm512_permutexvar_epi32(idx, fld[f]);
            qf[Q_SLOT] = _mm512_permutexvar_epi32(rot, slot);
        }
    }
    if (qn)
        flush(v, m, vb, qf, qn, out, micro);
    *st = ls;
    return n;
}

#else
typedef int rast__front_avx512_unused;   /* not an x86 build */
#endif
