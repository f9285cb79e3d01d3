/* raster_front_avx2.c - the vector front end with AVX2 (8 lanes): what
 * AVX2 does its own way around the steps written once on the vector layer
 * (raster_front.inl: rejection; raster_frontv.inl: vertex pass
 * rast__vpass_avx2, plane set-up, micro values), same bytes as
 * rast__prepare_range with the scalar set-up (docs/raster.md section 11,
 * sixth round). Groups of 8 submitted triangles; survivors are compressed
 * into the queue by a vpermd index built from the lane bits and set up 8
 * at a time (edges in 4 int64 lanes, planes in 4 double lanes). Built with
 * -mavx2 -mf16c; called only when cpuid reports AVX2.
 *
 * Here (issue 3, tenth round): vertices loaded by 16-byte loads and a
 * transpose instead of gathers (fv_load_xyzw); the survivor queue kept in
 * vectors (survivors merged in by one permutation and blend per field, no
 * unaligned store reloaded by flush); flush keeps the edges and planes in
 * vectors and writes each record by 16-byte copies from lane-transposed
 * stack layouts (quads, pairs) instead of a scalar copy per field; the
 * small loops unrolled (GCC -O2 left them rolled, with the vectors going
 * through the stack). */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <stddef.h>
#include <string.h>

#include "../cpu/simd_avx2.h"

/* ---- vertex pass -------------------------------------------------------- */

/* cnt (1..8) vertices xyzw at c, de-interleaved; lanes past cnt 0. Eight
 * 16-byte loads (masked loads for a partial block: no float past the last
 * vertex is read) and a 4x4 transpose per 128-bit half, instead of four
 * vgatherdps (the vertex pass's hottest spot: 0.4 of its samples). */
static inline __attribute__((always_inline)) void fv_load_xyzw(const float *c, int cnt, vfloat *x,
                                                               vfloat *y, vfloat *z, vfloat *w)
{
    __m256 r[4];   /* r[i] = vertex i in the low half, vertex i + 4 in the high half */
    if (cnt == 8) {
#pragma GCC unroll 4
        for (int i = 0; i < 4; i++)
            r[i] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(c + 4 * i)),
                                        _mm_loadu_ps(c + 16 + 4 * i), 1);
    } else {
        const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        __m256 v[4];   /* v[i] = vertices 2i, 2i + 1 */
#pragma GCC unroll 4
        for (int i = 0; i < 4; i++)
            v[i] = _mm256_maskload_ps(c + 8 * i, _mm256_cmpgt_epi32(
                                                     _mm256_set1_epi32(4 * cnt - 8 * i), iota));
        r[0] = _mm256_permute2f128_ps(v[0], v[2], 0x20);
        r[1] = _mm256_permute2f128_ps(v[0], v[2], 0x31);
        r[2] = _mm256_permute2f128_ps(v[1], v[3], 0x20);
        r[3] = _mm256_permute2f128_ps(v[1], v[3], 0x31);
    }
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]);   /* x0 x1 y0 y1 */
    const __m256 t1 = _mm256_unpacklo_ps(r[2], r[3]);   /* x2 x3 y2 y3 */
    const __m256 t2 = _mm256_unpackhi_ps(r[0], r[1]);   /* z0 z1 w0 w1 */
    const __m256 t3 = _mm256_unpackhi_ps(r[2], r[3]);   /* z2 z3 w2 w3 */
    *x = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0));
    *y = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2));
    *z = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0));
    *w = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

/* ---- helpers ------------------------------------------------------------ */

static inline unsigned bits8(__m256i m)
{
    return (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(m));
}

static inline __m128i half4(__m256i v, int h)
{
    return h ? _mm256_extracti128_si256(v, 1) : _mm256_castsi256_si128(v);
}

static inline __m256i blend8(__m256i a, __m256i b, __m256i m)
{
    return _mm256_castps_si256(
        _mm256_blendv_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), _mm256_castsi256_ps(m)));
}

/* Lane mask vector of bits. */
static inline __m256i lanes8(unsigned bits)
{
    const __m256i sel = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)bits), sel), sel);
}

/* Permutation of the set lanes of b to the front: 8 3-bit lane numbers. */
static inline __m256i compress_idx(unsigned b)
{
    uint32_t p = 0;
    int k = 0;
    for (unsigned x = b; x; x &= x - 1, k++)
        p |= (uint32_t)__builtin_ctz(x) << (3 * k);
    const __m256i sh = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    return _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)p), sh),
                            _mm256_set1_epi32(7));
}

/* p[lane of half h of V] by four scalar loads (fv_gather_d of
 * raster_frontv.inl) instead of a masked vgatherdpd (12 per flush: the
 * front end took 0.98-0.99 of the time with these, one process,
 * alternating). Every lane of V must index a readable double: flush
 * masks its vertex indices with the lanes in use (unused lanes read
 * vertex 0, which every mesh with a triangle has). */
static inline __attribute__((always_inline)) vdouble fv_gather_d(const double *p, vint V, int h)
{
    const __m128i i = half4(V, h);
    return _mm256_setr_pd(p[_mm_cvtsi128_si32(i)], p[_mm_extract_epi32(i, 1)],
                          p[_mm_extract_epi32(i, 2)], p[_mm_extract_epi32(i, 3)]);
}

/* The steps written on the vector layer (raster_front.inl: rejection;
 * raster_frontv.inl: vertex pass rast__vpass_avx2, planes, micro values). */
#include "raster_front.inl"
#include "raster_frontv.inl"

/* ---- survivor set-up ---------------------------------------------------- */

/* The survivor queue lives in vectors (qf[field], lanes 0 .. qn-1; the
 * fields Q_* of raster_front.inl) and flush keeps the edges and
 * planes in vectors; the records are written per lane from two stack
 * layouts filled by shuffles (instead of a scalar copy per field):
 *   quads  4 float or int32 vectors a, b, c, d: lane l's (a, b, c, d) as 16
 *          bytes at s + QUAD_AT(l) (4 stores of 32 bytes);
 *   pairs  2 int64 vectors a, b of lanes 4h .. 4h+3: lane l's (a, b) as 16
 *          bytes at s + PAIR_AT(l) (2 stores of 32 bytes per half). */
#define QUAD_AT(l) (8 * ((l) & 3) + 4 * ((l) >> 2))
#define PAIR_AT(l) (8 * ((l) >> 2) + 4 * ((l) & 1) + 2 * (((l) >> 1) & 1))

static inline __attribute__((always_inline)) void quads(__m256 a, __m256 b, __m256 c, __m256 d,
                                                        float *s)
{
    const __m256d ablo = _mm256_castps_pd(_mm256_unpacklo_ps(a, b));   /* a0 b0 a1 b1 */
    const __m256d abhi = _mm256_castps_pd(_mm256_unpackhi_ps(a, b));   /* a2 b2 a3 b3 */
    const __m256d cdlo = _mm256_castps_pd(_mm256_unpacklo_ps(c, d));
    const __m256d cdhi = _mm256_castps_pd(_mm256_unpackhi_ps(c, d));
    _mm256_store_pd((double *)(void *)s, _mm256_unpacklo_pd(ablo, cdlo));   /* lanes 0, 4 */
    _mm256_store_pd((double *)(void *)(s + 8), _mm256_unpackhi_pd(ablo, cdlo));
    _mm256_store_pd((double *)(void *)(s + 16), _mm256_unpacklo_pd(abhi, cdhi));
    _mm256_store_pd((double *)(void *)(s + 24), _mm256_unpackhi_pd(abhi, cdhi));
}

static inline __attribute__((always_inline)) void pairs(__m256i a, __m256i b, int64_t *s)
{
    _mm256_store_si256((__m256i *)(void *)s, _mm256_unpacklo_epi64(a, b));   /* lanes 0, 2 */
    _mm256_store_si256((__m256i *)(void *)(s + 4), _mm256_unpackhi_epi64(a, b));
}

/* 16 bytes from s to d. */
static inline __attribute__((always_inline)) void copy16(void *d, const void *s)
{
    _mm_storeu_si128((__m128i *)d, _mm_load_si128((const __m128i *)s));
}

#include "raster_front_rec.inl"

/* Micro lanes (clamped box at most 2x2 pixels; raster_front_avx512.c,
 * micro_lanes): the covered pixels (bit i + 2j of cov[l]) by the int64
 * edge test of the scan (E as in flush), and the clamped depth and the
 * barycentrics of the box's four pixels by the scan's float operations
 * per lane (P as fv_planes), lane l's as quads (mz, mb1, mb2 of its record)
 * at mq + QUAD_AT(l), mq + 32 + QUAD_AT(l), mq + 64 + QUAD_AT(l). Returns
 * the micro lanes (of L). */
static inline __attribute__((always_inline)) unsigned micro_lanes(const __m256i *qf, unsigned L,
                                                                   const __m256i (*E)[2],
                                                                   const __m256 *P,
                                                                   int32_t *cov, float *mq)
{
    const __m256i one = _mm256_set1_epi32(1), two = _mm256_set1_epi32(2);
    const __m256i w1 = _mm256_sub_epi32(qf[Q_BX1], qf[Q_BX0]);
    const __m256i h1 = _mm256_sub_epi32(qf[Q_BY1], qf[Q_BY0]);
    const unsigned wide = bits8(_mm256_cmpeq_epi32(w1, one));   /* 2 columns */
    const unsigned tall = bits8(_mm256_cmpeq_epi32(h1, one));   /* 2 rows */
    const unsigned mic = L & bits8(_mm256_and_si256(_mm256_cmpgt_epi32(two, w1),
                                                    _mm256_cmpgt_epi32(two, h1)));
    if (!mic)
        return 0;
    /* Coverage: E = e_c + i*e_dx + j*e_dy, int64, at the four pixels. */
    unsigned cv[4] = { 0, 0, 0, 0 };
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        __m256i o[4] = { _mm256_setzero_si256(), _mm256_setzero_si256(),
                         _mm256_setzero_si256(), _mm256_setzero_si256() };
#pragma GCC unroll 3
        for (int e = 0; e < 3; e++) {
            const __m256i c = E[e][h], ex = E[3 + e][h], ey = E[6 + e][h];
            const __m256i c01 = _mm256_add_epi64(c, ey);
            o[0] = _mm256_or_si256(o[0], c);
            o[1] = _mm256_or_si256(o[1], _mm256_add_epi64(c, ex));
            o[2] = _mm256_or_si256(o[2], c01);
            o[3] = _mm256_or_si256(o[3], _mm256_add_epi64(c01, ex));
        }
#pragma GCC unroll 4
        for (int p = 0; p < 4; p++)
            cv[p] |= (~(unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(o[p])) & 15u) << (4 * h);
    }
    cv[0] &= mic;
    cv[1] &= mic & wide;
    cv[2] &= mic & tall;
    cv[3] &= mic & wide & tall;
    if (!(cv[0] | cv[1] | cv[2] | cv[3]))
        return mic;
    __m256i cb = _mm256_and_si256(lanes8(cv[0]), one);
#pragma GCC unroll 3
    for (int p = 1; p < 4; p++)
        cb = _mm256_or_si256(cb, _mm256_and_si256(lanes8(cv[p]), _mm256_set1_epi32(1 << p)));
    _mm256_store_si256((__m256i *)(void *)cov, cb);
    /* The values (the scan's expressions; unused lanes compute garbage). */
    __m256 Z[4], B1[4], B2[4];
    fv_micro_values(P, Z, B1, B2);
    quads(Z[0], Z[1], Z[2], Z[3], mq);
    quads(B1[0], B1[1], B1[2], B1[3], mq + 32);
    quads(B2[0], B2[1], B2[2], B2[3], mq + 64);
    return mic;
}

/* The first n (1..4) floats of v to p; no other byte is written. */
static inline void store_n(float *p, __m128 v, int n)
{
    switch (n) {
    case 1:
        _mm_store_ss(p, v);
        break;
    case 2:
        _mm_storel_pi((__m64 *)(void *)p, v);
        break;
    case 3:
        _mm_storel_pi((__m64 *)(void *)p, v);
        _mm_store_ss(p + 2, _mm_movehl_ps(v, v));
        break;
    default:
        _mm_storeu_ps(p, v);
        break;
    }
}

/* setup_attrs for one record: a0 = attribute of vertex v0, d1 = a1 - a0,
 * d2 = a2 - a0 (ac = 1..8 floats each), by masked loads (am: the first
 * ac lanes; no byte past a vertex's ac floats is read) and stores of
 * exactly ac floats (no byte past a0[ac - 1], d1[ac - 1], d2[ac - 1] is
 * written), as raster_front_avx512.c. This replaced 3 * ac 8-lane
 * gathers per flush, an SoA scratch and 3 * ac scalar copies per record. */
_Static_assert(RAST_MAX_ATTRS <= 8, "attributes by one 8-lane masked load");
static inline void record_attrs(rast__tri *t, const float *attr, int ac, __m256i am,
                                 int32_t v0, int32_t v1, int32_t v2)
{
    const float *p0 = attr + (size_t)v0 * (size_t)ac;
    const float *p1 = attr + (size_t)v1 * (size_t)ac;
    const float *p2 = attr + (size_t)v2 * (size_t)ac;
    if (ac <= 4) {
        const __m128i m4 = _mm256_castsi256_si128(am);
        const __m128 a0 = _mm_maskload_ps(p0, m4);
        const __m128 a1 = _mm_maskload_ps(p1, m4);
        const __m128 a2 = _mm_maskload_ps(p2, m4);
        store_n(t->a0, a0, ac);
        store_n(t->d1, _mm_sub_ps(a1, a0), ac);
        store_n(t->d2, _mm_sub_ps(a2, a0), ac);
    } else {
        const __m256 a0 = _mm256_maskload_ps(p0, am);
        const __m256 a1 = _mm256_maskload_ps(p1, am);
        const __m256 a2 = _mm256_maskload_ps(p2, am);
        const __m256 d1 = _mm256_sub_ps(a1, a0), d2 = _mm256_sub_ps(a2, a0);
        _mm_storeu_ps(t->a0, _mm256_castps256_ps128(a0));
        _mm_storeu_ps(t->d1, _mm256_castps256_ps128(d1));
        _mm_storeu_ps(t->d2, _mm256_castps256_ps128(d2));
        store_n(t->a0 + 4, _mm256_extractf128_ps(a0, 1), ac - 4);
        store_n(t->d1 + 4, _mm256_extractf128_ps(d1, 1), ac - 4);
        store_n(t->d2 + 4, _mm256_extractf128_ps(d2, 1), ac - 4);
    }
}

/* Sets up queue lanes 0 .. k-1 (k = 1..8; qf[field] as in the queue) into
 * their records (micro: the micro records of boxes of at most 2x2
 * pixels). */
static void flush(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                  const __m256i *qf, int k, rast__tri *out, int micro)
{
    const __m256i L = _mm256_cmpgt_epi32(_mm256_set1_epi32(k),
                                         _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    __m256i X[3], Y[3], V[3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; i++) {
        X[i] = qf[Q_X0 + i];
        Y[i] = qf[Q_Y0 + i];
        V[i] = _mm256_and_si256(L, qf[Q_V0 + i]);   /* unused lanes: vertex 0 */
    }
    const __m256i bx0 = qf[Q_BX0], by0 = qf[Q_BY0];
    /* the per-lane fields the record loop reads */
    _Alignas(32) int32_t qs[Q_FIELDS][8];
#pragma GCC unroll 3
    for (int f = Q_V0; f <= Q_V2; f++)
        _mm256_store_si256((__m256i *)(void *)qs[f], qf[f]);
    _mm256_store_si256((__m256i *)(void *)qs[Q_SLOT], qf[Q_SLOT]);
    const __m256i c128 = _mm256_set1_epi32(RAST__FIX_HALF);
    const __m256i cx = _mm256_add_epi32(_mm256_slli_epi32(bx0, RAST_SUBPIXEL_BITS), c128);
    const __m256i cy = _mm256_add_epi32(_mm256_slli_epi32(by0, RAST_SUBPIXEL_BITS), c128);

    /* setup_edges: edge e from vertex ea[e] to eb[e]; E[f][h] the int64
     * lanes 4h .. 4h+3 of e_c[e] (f = e), e_dx[e] (3 + e), e_dy[e] (6 + e),
     * the order of the record. */
    __m256i E[9][2];
    static const int ea[3] = { 1, 2, 0 }, eb[3] = { 2, 0, 1 };
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi32(1);
#pragma GCC unroll 3
    for (int e = 0; e < 3; e++) {
        const int a = ea[e], b = eb[e];
        const __m256i dx = _mm256_sub_epi32(X[b], X[a]), dy = _mm256_sub_epi32(Y[b], Y[a]);
        const __m256i bias = _mm256_andnot_si256(vf_as_vi(top_left(dx, dy)), one);
        const __m256i oy = _mm256_sub_epi32(cy, Y[a]), ox = _mm256_sub_epi32(cx, X[a]);
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
            const __m256i dx64 = _mm256_cvtepi32_epi64(half4(dx, h));
            const __m256i dy64 = _mm256_cvtepi32_epi64(half4(dy, h));
            const __m256i p1 = _mm256_mul_epi32(dx64, _mm256_cvtepi32_epi64(half4(oy, h)));
            const __m256i p2 = _mm256_mul_epi32(dy64, _mm256_cvtepi32_epi64(half4(ox, h)));
            E[e][h] = _mm256_sub_epi64(_mm256_sub_epi64(p1, p2),
                                       _mm256_cvtepi32_epi64(half4(bias, h)));
            E[3 + e][h] = _mm256_sub_epi64(zero, _mm256_slli_epi64(dy64, RAST_SUBPIXEL_BITS));
            E[6 + e][h] = _mm256_slli_epi64(dx64, RAST_SUBPIXEL_BITS);
        }
    }

    /* planes_one per lane. */
    __m256 P[12];
    fv_planes(X, Y, V, bx0, by0, k, vb, P);

    /* The records: lane l -> out[slot l]. */
    const unsigned Lb = (1u << k) - 1u;
    _Alignas(32) int32_t cov[8] = { 0 };
    _Alignas(32) float mq[3 * 32];
    const unsigned mic = micro ? micro_lanes(qf, Lb, (const __m256i (*)[2])E, P, cov, mq) : 0u;
    const unsigned hid =
        fv_hidden(micro ? v->hz : NULL, P, bx0, by0, qf[Q_BX1], qf[Q_BY1], Lb & ~mic);
    /* box; the planes z.c .. q.c, q.dx .. b1.dx, b1.dy .. b2.dy */
    _Alignas(32) int32_t bq[32];
    _Alignas(32) float pq[3 * 32];
    quads(_mm256_castsi256_ps(bx0), _mm256_castsi256_ps(by0), _mm256_castsi256_ps(qf[Q_BX1]),
          _mm256_castsi256_ps(qf[Q_BY1]), (float *)(void *)bq);
    /* the edge pairs (e_c[0], e_c[1]) .. (e_dy[0], e_dy[1]) and e_dy[2] */
    _Alignas(32) int64_t eq[4][16], e8[8];
    if ((mic | hid) != Lb) {
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++)
            quads(P[4 * i], P[4 * i + 1], P[4 * i + 2], P[4 * i + 3], pq + 32 * i);
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
#pragma GCC unroll 4
            for (int i = 0; i < 4; i++)
                pairs(E[2 * i][h], E[2 * i + 1][h], eq[i] + 8 * h);
            _mm256_store_si256((__m256i *)(void *)(e8 + 4 * h), E[8][h]);
        }
    }
    const int ac = v->attr_count;
    const __m256i am = _mm256_cmpgt_epi32(_mm256_set1_epi32(ac),
                                          _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    for (int l = 0; l < k; l++) {
        rast__tri *t = out + qs[Q_SLOT][l];
        if ((hid >> l) & 1u) {
            front_hidden_record(t, l, bq);
            continue;
        }
        if (!front_write_record(t, l, (int)((mic >> l) & 1u), (unsigned)cov[l], ac, bq, mq, pq,
                                (const int64_t (*)[2 * FRONT_V])eq, e8))
            continue;
        if (ac > 0)
            record_attrs(t, m->attr, ac, am, qs[Q_V0][l], qs[Q_V1][l], qs[Q_V2][l]);
    }
}

/* The vertex indices of cnt (1..8) triangles at ix, de-interleaved:
 * iv[k] lane l = ix[3l + k], 0 for l >= cnt. Three vector loads (masked
 * for a partial group: no index past the group is read), blends and
 * permutes; the scalar copy through a stack array it replaced cost a
 * store-forwarding stall before the position gathers. */
static inline void load_tris(const uint32_t *ix, int cnt, __m256i iv[3])
{
    __m256i v[3];
    if (cnt == 8) {
        for (int i = 0; i < 3; i++)
            v[i] = _mm256_loadu_si256((const __m256i *)(const void *)(ix + 8 * i));
    } else {
        const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        for (int i = 0; i < 3; i++)
            v[i] = _mm256_maskload_epi32((const int *)(const void *)(ix + 8 * i),
                                         _mm256_cmpgt_epi32(_mm256_set1_epi32(3 * cnt - 8 * i),
                                                            iota));
    }
    /* Component k of triangle j is int 3j + k, in v[(3j + k) / 8]: lane p
     * of blend k is lane p of v[(p - k) mod 3], which holds int 3j + k for
     * the j whose lane is p = (3j + k) mod 8; the vpermd moves it to j. */
    const __m256i a = _mm256_blend_epi32(_mm256_blend_epi32(v[0], v[1], 0x92), v[2], 0x24);
    const __m256i b = _mm256_blend_epi32(_mm256_blend_epi32(v[0], v[1], 0x24), v[2], 0x49);
    const __m256i c = _mm256_blend_epi32(_mm256_blend_epi32(v[0], v[1], 0x49), v[2], 0x92);
    iv[0] = _mm256_permutevar8x32_epi32(a, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
    iv[1] = _mm256_permutevar8x32_epi32(b, _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6));
    iv[2] = _mm256_permutevar8x32_epi32(c, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
}

/* The (X, Y) pairs of the vertices ix[0], ix[3], ix[6], ix[9] as four
 * 64-bit lanes: scalar 64-bit loads (the two vpgatherdq per vertex of a
 * group they replaced were the front end's hottest spot). */
static inline __m256i pairs4(const long long *xyb, const uint32_t *ix)
{
    const __m128d a = _mm_loadh_pd(_mm_castsi128_pd(_mm_loadl_epi64(
                                       (const __m128i *)(const void *)(xyb + ix[0]))),
                                   (const double *)(const void *)(xyb + ix[3]));
    const __m128d b = _mm_loadh_pd(_mm_castsi128_pd(_mm_loadl_epi64(
                                       (const __m128i *)(const void *)(xyb + ix[6]))),
                                   (const double *)(const void *)(xyb + ix[9]));
    return _mm256_insertf128_si256(_mm256_castsi128_si256(_mm_castpd_si128(a)),
                                   _mm_castpd_si128(b), 1);
}

int rast__frontv_avx2(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                      int ti0, int ti1, rast__tri *out, rast_stats *st, int micro)
{
    rast_stats ls = *st;
    /* The survivor queue in vectors: qf[field] lanes 0 .. qn-1. */
    __m256i qf[Q_FIELDS];
#pragma GCC unroll 14
    for (int f = 0; f < Q_FIELDS; f++)
        qf[f] = _mm256_setzero_si256();
    int qn = 0;
    int n = 0;
    const long long *xyb = (const long long *)(const void *)vb->xy;
    const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i seven = _mm256_set1_epi32(7);
    const int vw = v->width, vh = v->height;   /* kept in registers */
    for (int ti = ti0; ti < ti1; ti += 8) {
        const int cnt = ti1 - ti < 8 ? ti1 - ti : 8;
        const unsigned L = (1u << cnt) - 1u;
        /* Indices, de-interleaved (lanes past cnt: vertex 0). */
        __m256i iv[3], X[3], Y[3];
        const uint32_t *ix = m->indices + 3 * (size_t)ti;
        load_tris(ix, cnt, iv);
        uint32_t pad[24];
        if (cnt < 8) {
            /* the same indices, lanes past cnt vertex 0 */
            memset(pad, 0, sizeof pad);
            memcpy(pad, ix, 3 * (size_t)cnt * sizeof *ix);
            ix = pad;
        }
#pragma GCC unroll 3
        for (int k = 0; k < 3; k++) {
            const __m256i p0 = pairs4(xyb, ix + k);
            const __m256i p1 = pairs4(xyb, ix + 12 + k);
            const __m256 s0 = _mm256_castsi256_ps(p0), s1 = _mm256_castsi256_ps(p1);
            X[k] = _mm256_permute4x64_epi64(
                _mm256_castps_si256(_mm256_shuffle_ps(s0, s1, _MM_SHUFFLE(2, 0, 2, 0))),
                _MM_SHUFFLE(3, 1, 2, 0));
            Y[k] = _mm256_permute4x64_epi64(
                _mm256_castps_si256(_mm256_shuffle_ps(s0, s1, _MM_SHUFFLE(3, 1, 3, 1))),
                _MM_SHUFFLE(3, 1, 2, 0));
        }
        /* lanes with a marked vertex; those needing the scalar path */
        unsigned marked;
        const unsigned special0 = fv_marked(X, Y, L, &ls, &marked);
        /* prepare_cached_one: area sign, degenerate, culling. */
        unsigned pos, neg;
        front_area_signs(X, Y, &pos, &neg);
        const front_class c = front_classify(m->cull, L & ~marked, pos, neg);
        /* setup_box_edges: the clamped pixel box, off screen, empty (as
         * raster_front_avx512.c). */
        const front_box b = front_box_of(X, Y, vw, vh);
        const unsigned csmall = c.live & ~b.off & b.small;
        const unsigned odd = csmall & ~b.usmall;
        const unsigned special = special0 | odd;
        const unsigned live2 = c.live & ~b.off & ~odd;
        const __m256i sw = lanes8(neg);
        const __m256i x1 = blend8(X[1], X[2], sw), x2 = blend8(X[2], X[1], sw);
        const __m256i y1 = blend8(Y[1], Y[2], sw), y2 = blend8(Y[2], Y[1], sw);
        const unsigned small = csmall & b.usmall;
        unsigned empty = 0;
        if (small)
            empty = small & front_empty_small(X[0], Y[0], x1, y1, x2, y2, b.bx0, b.by0,
                                              b.bx1, b.by1);
        const unsigned surv = live2 & ~empty;
        front_count(&ls, c.degen, c.culled, c.live & b.off, live2);
        if (!surv && !special)
            continue;
        /* Append the survivors to the queue vectors: queue lane j >= qn
         * takes survivor j - qn, i.e. group lane pr[j] (the compression
         * index rotated by qn); lanes j < qn of the same permutation hold
         * the survivors past lane 7 (survivor j - qn + 8), the next queue. */
        const __m256i rot = _mm256_and_si256(_mm256_sub_epi32(iota, _mm256_set1_epi32(qn)), seven);
        const __m256i pr = _mm256_permutevar8x32_epi32(compress_idx(surv), rot);
        __m256i slot;
        if (special) {
            _Alignas(32) int32_t sl[8] = { 0 };
            n = front_slots(v, m, ti, special, surv, out, n, &ls, sl);
            slot = _mm256_permutevar8x32_epi32(
                _mm256_load_si256((const __m256i *)(const void *)sl), pr);
        } else {
            slot = _mm256_permutevar8x32_epi32(_mm256_add_epi32(_mm256_set1_epi32(n), iota), rot);
            n += __builtin_popcount(surv);
        }
        if (!surv)
            continue;
        const __m256i vi1 = blend8(iv[1], iv[2], sw), vi2 = blend8(iv[2], iv[1], sw);
        const __m256i fld[Q_SLOT] = { X[0], x1, x2, Y[0], y1, y2, iv[0], vi1, vi2,
                                      b.bx0, b.by0, b.bx1, b.by1 };
        __m256i mv[Q_FIELDS];
#pragma GCC unroll 13
        for (int f = 0; f < Q_SLOT; f++)
            mv[f] = _mm256_permutevar8x32_epi32(fld[f], pr);
        mv[Q_SLOT] = slot;
        const __m256i up = _mm256_cmpgt_epi32(iota, _mm256_set1_epi32(qn - 1));
#pragma GCC unroll 14
        for (int f = 0; f < Q_FIELDS; f++)
            qf[f] = blend8(qf[f], mv[f], up);
        qn += __builtin_popcount(surv);
        if (qn >= 8) {
            flush(v, m, vb, qf, 8, out, micro);
            qn -= 8;
#pragma GCC unroll 14
            for (int f = 0; f < Q_FIELDS; f++)
                qf[f] = mv[f];
        }
    }
    if (qn)
        flush(v, m, vb, qf, qn, out, micro);
    *st = ls;
    return n;
}

#else
typedef int rast__front_avx2_unused;   /* not an x86 build */
#endif
