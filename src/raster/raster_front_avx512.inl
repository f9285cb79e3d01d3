/* raster_front_avx512.inl - the 16-lane helpers of the rejection that only
 * AVX-512 has (two-source permutes, 64-bit gathers), shared by the vector
 * front end (raster_front_avx512.c) and the 16-triangle rejection of the
 * cached path (rast__front_avx512 in raster_avx512.c), and
 * raster_front.inl (the steps written on the vector layer). Included once
 * per file, after src/cpu/simd_avx512.h. */

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

#include "raster_front.inl"
