/* raster_front_avx512.inl - the AVX-512 (F+BW+DQ+VL) lane macros of
 * raster_front.inl and the 16-lane helpers of the rejection, shared by the
 * vector front end (raster_front_avx512.c) and the 16-triangle rejection
 * of the cached path (rast__front_avx512 in raster_avx512.c). Included
 * once per file, after <immintrin.h>. */

#define FRONT_V 16
typedef __m512i fvi;
#define FI_ZERO() _mm512_setzero_si512()
#define FI_SET1(x) _mm512_set1_epi32(x)
#define FI_ADD(a, b) _mm512_add_epi32(a, b)
#define FI_SUB(a, b) _mm512_sub_epi32(a, b)
#define FI_OR(a, b) _mm512_or_si512(a, b)
#define FI_MIN(a, b) _mm512_min_epi32(a, b)
#define FI_MAX(a, b) _mm512_max_epi32(a, b)
#define FI_SRAI(v, n) _mm512_srai_epi32(v, n)
#define FI_SLLI(v, n) _mm512_slli_epi32(v, n)
typedef __mmask16 fvm;
#define FI_GT(a, b) _mm512_cmpgt_epi32_mask(a, b)
#define FI_EQ(a, b) _mm512_cmpeq_epi32_mask(a, b)
#define FM_OR(a, b) ((__mmask16)((a) | (b)))
#define FM_AND(a, b) ((__mmask16)((a) & (b)))
#define FM_BITS(m) ((unsigned)(m))
#define FI_NEG_BITS(v) ((unsigned)_mm512_movepi32_mask(v))

static inline __m256i half_i(__m512i v, int h)
{
    return h ? _mm512_extracti32x8_epi32(v, 1) : _mm512_castsi512_si256(v);
}

/* lane l = element idx[l] of the 48 indices a | b | c (idx < 48). */
static inline __m512i deint(__m512i a, __m512i b, __m512i c, __m512i idx)
{
    const __mmask16 hi = _mm512_cmpge_epi32_mask(idx, _mm512_set1_epi32(32));
    return _mm512_mask_permutexvar_epi32(_mm512_permutex2var_epi32(a, idx, b), hi, idx, c);
}

/* The vertex indices of the 16 triangles whose 48 indices are a | b | c,
 * de-interleaved: iv[k] = vertex k of each triangle. */
static inline void deint_tris(__m512i a, __m512i b, __m512i c, __m512i iv[3])
{
    const __m512i l3 = _mm512_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33, 36, 39,
                                         42, 45);
    const __m512i one = _mm512_set1_epi32(1);
    iv[0] = deint(a, b, c, l3);
    iv[1] = deint(a, b, c, _mm512_add_epi32(l3, one));
    iv[2] = deint(a, b, c, _mm512_add_epi32(l3, _mm512_set1_epi32(2)));
}

/* The qwords p64[q_l] for the 16 lanes l of q: lanes 0..7 in p[0], 8..15
 * in p[1]. */
static inline void gather_pairs(const long long *p64, __m512i q, __m512i p[2])
{
    p[0] = _mm512_i32gather_epi64(half_i(q, 0), p64, 8);
    p[1] = _mm512_i32gather_epi64(half_i(q, 1), p64, 8);
}

/* The low (even) and high (odd) dwords of the 16 qwords p[0], p[1]. */
static inline __m512i pairs_lo(const __m512i p[2])
{
    const __m512i ie = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26,
                                         28, 30);
    return _mm512_permutex2var_epi32(p[0], ie, p[1]);
}

static inline __m512i pairs_hi(const __m512i p[2])
{
    const __m512i io = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27,
                                         29, 31);
    return _mm512_permutex2var_epi32(p[0], io, p[1]);
}

/* Lanes with a*b > c*d (gt) or a*b < c*d (!gt), exact in double
 * (|a|, |b|, |c|, |d| < 2^23). */
static inline unsigned prod_cmp(__m512i a, __m512i b, __m512i c, __m512i d, int gt)
{
    unsigned r = 0;
    for (int h = 0; h < 2; h++) {
        const __m512d p1 = _mm512_mul_pd(_mm512_cvtepi32_pd(half_i(a, h)),
                                         _mm512_cvtepi32_pd(half_i(b, h)));
        const __m512d p2 = _mm512_mul_pd(_mm512_cvtepi32_pd(half_i(c, h)),
                                         _mm512_cvtepi32_pd(half_i(d, h)));
        /* p1 < p2 as p2 > p1: the predicate stays a constant (clang, -Os) */
        r |= (unsigned)_mm512_cmp_pd_mask(gt ? p1 : p2, gt ? p2 : p1, _CMP_GT_OQ) << (8 * h);
    }
    return r;
}

/* Top-left bias mask of the edges with deltas dx, dy: lanes that keep
 * E == 0 (dy < 0, or dy == 0 and dx > 0). */
static inline __mmask16 top_left(__m512i dx, __m512i dy)
{
    const __m512i zero = _mm512_setzero_si512();
    return _mm512_cmplt_epi32_mask(dy, zero) |
           (_mm512_cmpeq_epi32_mask(dy, zero) & _mm512_cmpgt_epi32_mask(dx, zero));
}

/* Biased edge value from a to b at (cx, cy) in int32 (boxes up to 2x2:
 * differences below 768, products below 2^20; front_empty_small). */
static inline __m512i front_edge32(__m512i xa, __m512i ya, __m512i xb, __m512i yb,
                                   __m512i cx, __m512i cy)
{
    const __m512i dx = _mm512_sub_epi32(xb, xa), dy = _mm512_sub_epi32(yb, ya);
    const __m512i e = _mm512_sub_epi32(_mm512_mullo_epi32(dx, _mm512_sub_epi32(cy, ya)),
                                       _mm512_mullo_epi32(dy, _mm512_sub_epi32(cx, xa)));
    return _mm512_mask_sub_epi32(e, (__mmask16)~top_left(dx, dy), e, _mm512_set1_epi32(1));
}

#include "raster_front.inl"
