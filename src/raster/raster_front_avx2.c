/* raster_front_avx2.c - the vector front end with AVX2 (8 lanes): the
 * port of raster_front_avx512.c (same steps, same operations per lane,
 * same bytes as rast__prepare_range with the scalar set-up; docs/raster.md
 * section 11, sixth round). Groups of 8 submitted triangles; survivors
 * are compressed into the queue by a vpermd index built from the lane
 * bits and set up 8 at a time (edges in 4 int64 lanes, planes in 4 double
 * lanes). Built with -mavx2 -mf16c; called only when cpuid reports AVX2.
 *
 * Speed (issue 3, tenth round, the AVX-512 file's changes where they pay
 * on Zen 4): vertices loaded by 16-byte loads and a transpose instead of
 * gathers; the survivor queue kept in vectors (survivors merged in by one
 * permutation and blend per field, no unaligned store reloaded by flush);
 * flush keeps the edges and planes in vectors (planes8: the two halves
 * joined in registers) and writes each record by 16-byte copies from
 * lane-transposed stack layouts (quads, pairs) instead of a scalar copy
 * per field; the small loops unrolled (GCC -O2 left them rolled, with
 * the vectors going through the stack). */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <stddef.h>
#include <string.h>

/* ---- vertex pass -------------------------------------------------------- */

/* cnt (1..8) vertices xyzw at c, de-interleaved; lanes past cnt 0. Eight
 * 16-byte loads (masked loads for a partial block: no float past the last
 * vertex is read) and a 4x4 transpose per 128-bit half, instead of four
 * vgatherdps (the vertex pass's hottest spot: 0.4 of its samples). */
static inline __attribute__((always_inline)) void load_xyzw(const float *c, int cnt, __m256 *x,
                                                            __m256 *y, __m256 *z, __m256 *w)
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

void rast__vpass_avx2(const rast__view *v, const float *clip, int count, rast__vbuf *vb)
{
    const __m256 zero = _mm256_setzero_ps(), half = _mm256_set1_ps(0.5f);
    const __m256 fix = _mm256_set1_ps((float)RAST__FIX_ONE);
    const __m256 big = _mm256_set1_ps(FLT_MAX), nbig = _mm256_set1_ps(-FLT_MAX);
    const __m256 gx = _mm256_set1_ps(v->gx), gy = _mm256_set1_ps(v->gy);
    const __m256 fw = _mm256_set1_ps((float)v->width), fh = _mm256_set1_ps((float)v->height);
    const __m256 lox = _mm256_set1_ps((float)v->min_x), hix = _mm256_set1_ps((float)v->max_x);
    const __m256 loy = _mm256_set1_ps((float)v->min_y), hiy = _mm256_set1_ps((float)v->max_y);
    const __m256i mark = _mm256_set1_epi32(RAST__VX_SPECIAL);
    const __m256d dhalf = _mm256_set1_pd(0.5), done = _mm256_set1_pd(1.0);
    for (int base = 0; base < count; base += 8) {
        const int cnt = count - base < 8 ? count - base : 8;
        const float *c = clip + 4 * (size_t)base;
        __m256 x, y, z, w;
        load_xyzw(c, cnt, &x, &y, &z, &w);
        const __m256 fin = _mm256_and_ps(
            _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(x, big, _CMP_LE_OQ),
                                        _mm256_cmp_ps(nbig, x, _CMP_LE_OQ)),
                          _mm256_and_ps(_mm256_cmp_ps(y, big, _CMP_LE_OQ),
                                        _mm256_cmp_ps(nbig, y, _CMP_LE_OQ))),
            _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(z, big, _CMP_LE_OQ),
                                        _mm256_cmp_ps(nbig, z, _CMP_LE_OQ)),
                          _mm256_and_ps(_mm256_cmp_ps(w, big, _CMP_LE_OQ),
                                        _mm256_cmp_ps(nbig, w, _CMP_LE_OQ))));
        const __m256 gxw = _mm256_mul_ps(gx, w), gyw = _mm256_mul_ps(gy, w);
        /* outcode_inl, plane by plane (the same float expressions) */
        const __m256 ob[6] = { _mm256_cmp_ps(_mm256_add_ps(z, w), zero, _CMP_LT_OQ),
                               _mm256_cmp_ps(_mm256_sub_ps(w, z), zero, _CMP_LT_OQ),
                               _mm256_cmp_ps(_mm256_add_ps(gxw, x), zero, _CMP_LT_OQ),
                               _mm256_cmp_ps(_mm256_sub_ps(gxw, x), zero, _CMP_LT_OQ),
                               _mm256_cmp_ps(_mm256_add_ps(gyw, y), zero, _CMP_LT_OQ),
                               _mm256_cmp_ps(_mm256_sub_ps(gyw, y), zero, _CMP_LT_OQ) };
        const __m256 out = _mm256_or_ps(_mm256_or_ps(_mm256_or_ps(ob[0], ob[1]),
                                                     _mm256_or_ps(ob[2], ob[3])),
                                        _mm256_or_ps(ob[4], ob[5]));
        /* Y of a marked vertex: its outcode | RAST__VX_NONFINITE */
        __m256i oc = _mm256_andnot_si256(_mm256_castps_si256(fin),
                                         _mm256_set1_epi32(RAST__VX_NONFINITE));
#pragma GCC unroll 6
        for (int b = 0; b < 6; b++)
            oc = _mm256_or_si256(oc, _mm256_and_si256(_mm256_castps_si256(ob[b]),
                                                      _mm256_set1_epi32(1 << b)));
        const __m256 wpos = _mm256_cmp_ps(w, zero, _CMP_GT_OQ);
        /* special = !fin | out | !(w > 0) */
        const __m256 ok = _mm256_andnot_ps(out, _mm256_and_ps(fin, wpos));
        const __m256 nx = _mm256_div_ps(x, w), ny = _mm256_div_ps(y, w);
        const __m256 sx = _mm256_mul_ps(_mm256_add_ps(_mm256_mul_ps(nx, half), half), fw);
        const __m256 sy = _mm256_mul_ps(_mm256_sub_ps(half, _mm256_mul_ps(ny, half)), fh);
        __m256i X = _mm256_cvtps_epi32(_mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(sx, fix), lox), hix));
        __m256i Y =
            _mm256_cvtps_epi32(_mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(sy, fix), loy), hiy));
        X = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(mark),
                                                 _mm256_castsi256_ps(X), ok));
        Y = _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(oc),
                                                 _mm256_castsi256_ps(Y), ok));
        const __m256i lo = _mm256_unpacklo_epi32(X, Y), hi = _mm256_unpackhi_epi32(X, Y);
        int32_t *xy = vb->xy + 2 * (size_t)base;
        _mm256_store_si256((__m256i *)(void *)xy, _mm256_permute2x128_si256(lo, hi, 0x20));
        _mm256_store_si256((__m256i *)(void *)(xy + 8), _mm256_permute2x128_si256(lo, hi, 0x31));
        for (int h = 0; h < 2; h++) {
            const __m256d dz = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(z, 1)
                                                 : _mm256_castps256_ps128(z));
            const __m256d dw = _mm256_cvtps_pd(h ? _mm256_extractf128_ps(w, 1)
                                                 : _mm256_castps256_ps128(w));
            _mm256_store_pd(vb->zw + base + 4 * h,
                            _mm256_add_pd(_mm256_mul_pd(_mm256_div_pd(dz, dw), dhalf), dhalf));
            _mm256_store_pd(vb->iw + base + 4 * h, _mm256_div_pd(done, dw));
        }
    }
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

/* Lanes with a*b > c*d (gt) or a*b < c*d (!gt), exact in double. */
static inline unsigned prod_cmp(__m256i a, __m256i b, __m256i c, __m256i d, int gt)
{
    unsigned r = 0;
    for (int h = 0; h < 2; h++) {
        const __m256d p1 = _mm256_mul_pd(_mm256_cvtepi32_pd(half4(a, h)),
                                         _mm256_cvtepi32_pd(half4(b, h)));
        const __m256d p2 = _mm256_mul_pd(_mm256_cvtepi32_pd(half4(c, h)),
                                         _mm256_cvtepi32_pd(half4(d, h)));
        /* p1 < p2 as p2 > p1: the predicate stays a constant (clang, -Os) */
        r |= (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(gt ? p1 : p2, gt ? p2 : p1, _CMP_GT_OQ))
             << (4 * h);
    }
    return r;
}

/* All ones in the lanes whose edge keeps E == 0 (top-left rule). */
static inline __m256i top_left(__m256i dx, __m256i dy)
{
    const __m256i zero = _mm256_setzero_si256();
    return _mm256_or_si256(_mm256_cmpgt_epi32(zero, dy),
                           _mm256_and_si256(_mm256_cmpeq_epi32(dy, zero),
                                            _mm256_cmpgt_epi32(dx, zero)));
}

/* Biased edge value in int32 (boxes of at most 2x2 pixels only). */
static inline __m256i front_edge32(__m256i xa, __m256i ya, __m256i xb, __m256i yb,
                                   __m256i cx, __m256i cy)
{
    const __m256i dx = _mm256_sub_epi32(xb, xa), dy = _mm256_sub_epi32(yb, ya);
    const __m256i e = _mm256_sub_epi32(_mm256_mullo_epi32(dx, _mm256_sub_epi32(cy, ya)),
                                       _mm256_mullo_epi32(dy, _mm256_sub_epi32(cx, xa)));
    /* e - 1 where not top-left: e + (tl ? 0 : -1) = e + ~tl */
    return _mm256_add_epi32(e, _mm256_xor_si256(top_left(dx, dy), _mm256_set1_epi32(-1)));
}

static inline __m256i blend8(__m256i a, __m256i b, __m256i m)
{
    return _mm256_castps_si256(
        _mm256_blendv_ps(_mm256_castsi256_ps(a), _mm256_castsi256_ps(b), _mm256_castsi256_ps(m)));
}

/* Lane mask vector of bits. */
static inline __m256i vmask(unsigned bits)
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

/* p[lane of half h of v] where lh, else d, by four scalar
 * loads and a blend instead of a masked vgatherdpd (12 per flush: the
 * front end took 0.98-0.99 of the time with these, one process,
 * alternating). Every lane of v must index a readable double: flush
 * masks its vertex indices with the lanes in use (unused lanes read
 * vertex 0, which every mesh with a triangle has). */
static inline __m256d gather4(__m256d d, const double *p, __m256i v, int h, __m256d lh)
{
    const __m128i i = half4(v, h);
    const __m256d g = _mm256_setr_pd(p[_mm_cvtsi128_si32(i)], p[_mm_extract_epi32(i, 1)],
                                     p[_mm_extract_epi32(i, 2)], p[_mm_extract_epi32(i, 3)]);
    return _mm256_blendv_pd(d, g, lh);
}

/* Lane macros of raster_front.inl (8 int32 lanes). */
#define FRONT_V 8
typedef __m256i fvi;
#define FI_ZERO() _mm256_setzero_si256()
#define FI_SET1(x) _mm256_set1_epi32(x)
#define FI_ADD(a, b) _mm256_add_epi32(a, b)
#define FI_SUB(a, b) _mm256_sub_epi32(a, b)
#define FI_OR(a, b) _mm256_or_si256(a, b)
#define FI_MIN(a, b) _mm256_min_epi32(a, b)
#define FI_MAX(a, b) _mm256_max_epi32(a, b)
#define FI_SRAI(v, n) _mm256_srai_epi32(v, n)
#define FI_SLLI(v, n) _mm256_slli_epi32(v, n)
typedef __m256i fvm;
#define FI_GT(a, b) _mm256_cmpgt_epi32(a, b)
#define FI_EQ(a, b) _mm256_cmpeq_epi32(a, b)
#define FM_OR(a, b) _mm256_or_si256(a, b)
#define FM_AND(a, b) _mm256_and_si256(a, b)
#define FM_BITS(m) bits8(m)
#define FI_NEG_BITS(v) bits8(v)
#include "raster_front.inl"

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

/* front_plane with the results as vectors: c, dx, dy of 4 lanes. */
static inline __attribute__((always_inline)) void plane4(__m256d f0, __m256d f1, __m256d f2,
                                                         __m256d ex1, __m256d ey1,
                                                         __m256d ex2, __m256d ey2,
                                                         __m256d ox, __m256d oy,
                                                         __m256d area, __m128 *r)
{
    const __m256d df1 = _mm256_sub_pd(f1, f0), df2 = _mm256_sub_pd(f2, f0);
    const __m256d gx = _mm256_div_pd(
        _mm256_sub_pd(_mm256_mul_pd(df1, ey2), _mm256_mul_pd(df2, ey1)), area);
    const __m256d gy = _mm256_div_pd(
        _mm256_sub_pd(_mm256_mul_pd(df2, ex1), _mm256_mul_pd(df1, ex2)), area);
    const __m256d cc =
        _mm256_add_pd(_mm256_add_pd(f0, _mm256_mul_pd(gx, ox)), _mm256_mul_pd(gy, oy));
    r[0] = _mm256_cvtpd_ps(cc);
    r[1] = _mm256_cvtpd_ps(gx);
    r[2] = _mm256_cvtpd_ps(gy);
}

/* planes_one (raster_setup.c) per lane: the planes z, q, b1, b2 of the 8
 * queue lanes as vectors P[plane * 3 + {c, dx, dy}] (the same operations
 * per lane; the halves joined in registers: 16-byte stores reloaded as
 * 32 bytes cannot be forwarded). L: the lanes in use (the first k); with
 * k <= 4 the upper half is not computed (its lanes copy the lower's). */
static inline __attribute__((always_inline)) void planes8(const __m256i X[3], const __m256i Y[3],
                                                          const __m256i V[3], __m256i bx0,
                                                          __m256i by0, __m256i L, int k,
                                                          const rast__vbuf *vb, __m256 P[12])
{
    const __m256d inv256 = _mm256_set1_pd(1.0 / RAST__FIX_ONE), dzero = _mm256_setzero_pd();
    const __m256d dhalf = _mm256_set1_pd(0.5), done = _mm256_set1_pd(1.0);
    __m128 r[2][12];
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        if (h && k <= 4) {
#pragma GCC unroll 12
            for (int j = 0; j < 12; j++)
                r[1][j] = r[0][j];
            break;
        }
        const __m256d lh = _mm256_castsi256_pd(_mm256_cvtepi32_epi64(half4(L, h)));
        __m256d Xd[3], Yd[3], zw[3], iw[3];
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++) {
            zw[i] = gather4(dzero, vb->zw, V[i], h, lh);
            iw[i] = gather4(done, vb->iw, V[i], h, lh);
        }
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++) {
            /* (double)X / 256: exact, as a multiplication by 2^-8 */
            Xd[i] = _mm256_mul_pd(_mm256_cvtepi32_pd(half4(X[i], h)), inv256);
            Yd[i] = _mm256_mul_pd(_mm256_cvtepi32_pd(half4(Y[i], h)), inv256);
        }
        const __m256d ex1 = _mm256_sub_pd(Xd[1], Xd[0]), ey1 = _mm256_sub_pd(Yd[1], Yd[0]);
        const __m256d ex2 = _mm256_sub_pd(Xd[2], Xd[0]), ey2 = _mm256_sub_pd(Yd[2], Yd[0]);
        /* |snapped area| / 65536, exact (raster_front.inl); unused lanes 1 */
        const __m256d area = _mm256_blendv_pd(
            done, _mm256_sub_pd(_mm256_mul_pd(ex1, ey2), _mm256_mul_pd(ey1, ex2)), lh);
        const __m256d ocx = _mm256_add_pd(_mm256_cvtepi32_pd(half4(bx0, h)), dhalf);
        const __m256d ocy = _mm256_add_pd(_mm256_cvtepi32_pd(half4(by0, h)), dhalf);
        const __m256d ox = _mm256_sub_pd(ocx, Xd[0]), oy = _mm256_sub_pd(ocy, Yd[0]);
        /* max(a, b) = a > b ? a : b, as the scalar loop */
        const __m256d qmax =
            _mm256_max_pd(iw[2], _mm256_max_pd(iw[1], _mm256_max_pd(iw[0], dzero)));
        const __m256d q0 = _mm256_div_pd(iw[0], qmax), q1 = _mm256_div_pd(iw[1], qmax);
        const __m256d q2 = _mm256_div_pd(iw[2], qmax);
        plane4(zw[0], zw[1], zw[2], ex1, ey1, ex2, ey2, ox, oy, area, r[h]);
        plane4(q0, q1, q2, ex1, ey1, ex2, ey2, ox, oy, area, r[h] + 3);
        plane4(dzero, q1, dzero, ex1, ey1, ex2, ey2, ox, oy, area, r[h] + 6);
        plane4(dzero, dzero, q2, ex1, ey1, ex2, ey2, ox, oy, area, r[h] + 9);
    }
#pragma GCC unroll 12
    for (int j = 0; j < 12; j++)
        P[j] = _mm256_insertf128_ps(_mm256_castps128_ps256(r[0][j]), r[1][j], 1);
}

/* Micro lanes (clamped box at most 2x2 pixels; raster_front_avx512.c,
 * micro_lanes): the covered pixels (bit i + 2j of cov[l]) by the int64
 * edge test of the scan (E as in flush), and the clamped depth and the
 * barycentrics of the box's four pixels by the scan's float operations
 * per lane (P as planes8), lane l's as quads (mz, mb1, mb2 of its record)
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
    __m256i cb = _mm256_and_si256(vmask(cv[0]), one);
#pragma GCC unroll 3
    for (int p = 1; p < 4; p++)
        cb = _mm256_or_si256(cb, _mm256_and_si256(vmask(cv[p]), _mm256_set1_epi32(1 << p)));
    _mm256_store_si256((__m256i *)(void *)cov, cb);
    /* The values (the scan's expressions; unused lanes compute garbage). */
    const __m256 zero = _mm256_setzero_ps(), fone = _mm256_set1_ps(1.0f);
    __m256 Z[4], B1[4], B2[4];
#pragma GCC unroll 2
    for (int j = 0; j < 2; j++) {
        const __m256 fj = j ? fone : zero;
        const __m256 zr = _mm256_add_ps(P[0], _mm256_mul_ps(P[2], fj));
        const __m256 qr = _mm256_add_ps(P[3], _mm256_mul_ps(P[5], fj));
        const __m256 b1r = _mm256_add_ps(P[6], _mm256_mul_ps(P[8], fj));
        const __m256 b2r = _mm256_add_ps(P[9], _mm256_mul_ps(P[11], fj));
#pragma GCC unroll 2
        for (int i = 0; i < 2; i++) {
            const int p = i + 2 * j;
            const __m256 fi = i ? fone : zero;
            __m256 z = _mm256_add_ps(zr, _mm256_mul_ps(P[1], fi));
            z = _mm256_max_ps(zero, z);
            Z[p] = _mm256_min_ps(fone, z);
            const __m256 r = _mm256_div_ps(fone, _mm256_add_ps(qr, _mm256_mul_ps(P[4], fi)));
            B1[p] = _mm256_mul_ps(_mm256_add_ps(b1r, _mm256_mul_ps(P[7], fi)), r);
            B2[p] = _mm256_mul_ps(_mm256_add_ps(b2r, _mm256_mul_ps(P[10], fi)), r);
        }
    }
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
        const __m256i bias = _mm256_andnot_si256(top_left(dx, dy), one);
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
    planes8(X, Y, V, bx0, by0, L, k, vb, P);

    /* The records: lane l -> out[slot l]. */
    const unsigned Lb = (1u << k) - 1u;
    _Alignas(32) int32_t cov[8] = { 0 };
    _Alignas(32) float mq[3 * 32];
    const unsigned mic = micro ? micro_lanes(qf, Lb, (const __m256i (*)[2])E, P, cov, mq) : 0u;
    /* box; the planes z.c .. q.c, q.dx .. b1.dx, b1.dy .. b2.dy */
    _Alignas(32) int32_t bq[32];
    _Alignas(32) float pq[3 * 32];
    quads(_mm256_castsi256_ps(bx0), _mm256_castsi256_ps(by0), _mm256_castsi256_ps(qf[Q_BX1]),
          _mm256_castsi256_ps(qf[Q_BY1]), (float *)(void *)bq);
    /* the edge pairs (e_c[0], e_c[1]) .. (e_dy[0], e_dy[1]) and e_dy[2] */
    _Alignas(32) int64_t eq[4][16], e8[8];
    if (mic != Lb) {
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
    const __m256i mark = _mm256_set1_epi32(RAST__VX_SPECIAL);
    const __m256i zero = _mm256_setzero_si256();
    const int vw = v->width, vh = v->height;   /* kept in registers */
    for (int ti = ti0; ti < ti1; ti += 8) {
        const int cnt = ti1 - ti < 8 ? ti1 - ti : 8;
        const unsigned L = (1u << cnt) - 1u;
        /* Indices, de-interleaved (lanes past cnt: vertex 0). */
        __m256i iv[3], X[3], Y[3], spec = zero;
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
            spec = _mm256_or_si256(spec, _mm256_cmpeq_epi32(X[k], mark));
        }
        const unsigned marked = bits8(spec) & L;   /* lanes with a marked vertex */
        unsigned special0 = marked;
        const unsigned all3 = marked & bits8(_mm256_cmpeq_epi32(X[0], mark)) &
                              bits8(_mm256_cmpeq_epi32(X[1], mark)) &
                              bits8(_mm256_cmpeq_epi32(X[2], mark));
        if (all3) {
            /* As raster_front_avx512.c: three marked vertices, a
             * non-finite one or an outcode bit shared by the three. */
            const __m256i yo = _mm256_or_si256(_mm256_or_si256(Y[0], Y[1]), Y[2]);
            const __m256i ya = _mm256_and_si256(_mm256_and_si256(Y[0], Y[1]), Y[2]);
            const __m256i z8 = _mm256_setzero_si256();
            const unsigned nf = all3 & ~bits8(_mm256_cmpeq_epi32(
                _mm256_and_si256(yo, _mm256_set1_epi32(RAST__VX_NONFINITE)), z8));
            const unsigned away = all3 & ~nf & ~bits8(_mm256_cmpeq_epi32(
                _mm256_and_si256(ya, _mm256_set1_epi32(RAST__VX_OUTCODE)), z8));
            ls.tris_nonfinite += __builtin_popcount(nf);
            ls.tris_clipped_away += __builtin_popcount(away);
            special0 &= ~(nf | away);
        }
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
        const __m256i sw = vmask(neg);
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
