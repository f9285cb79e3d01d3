/* raster_front_avx2.c - the vector front end with AVX2 (8 lanes): the
 * front end written once on the vector layer (raster_front.inl: rejection;
 * raster_frontv.inl: vertex pass rast__vpass_avx2, plane set-up, micro
 * values; raster_frontq.inl: the group loop rast__frontv_avx2, the
 * survivor queue, the int64 edges and the records) compiled on
 * simd_avx2.h, plus what AVX2 does its own way: the de-interleaving loads
 * of vertices (fv_load_xyzw), of indices and (X, Y) pairs
 * (fv_load_group), the double gathers (fv_gather_d) and the attributes of
 * a record (fv_record_attrs). Same bytes as rast__prepare_range with the
 * scalar set-up (docs/raster.md section 11). Built with -mavx2 -mf16c;
 * called only when cpuid reports AVX2.
 *
 * Here (issue 3, tenth round): vertices loaded by 16-byte loads and a
 * transpose instead of gathers (fv_load_xyzw); indices by three vector
 * loads and blends, (X, Y) pairs by scalar 64-bit loads (load_tris,
 * pairs4); attributes by masked loads (fv_record_attrs). */
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

/* ---- ISA parts of the survivor set-up ---------------------------------- */

static inline __m128i half4(__m256i v, int h)
{
    return h ? _mm256_extracti128_si256(v, 1) : _mm256_castsi256_si128(v);
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

/* The rejection and the vertex pass, planes and micro values written once
 * on the vector layer. */
#include "raster_front.inl"
#include "raster_frontv.inl"

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
static inline void fv_record_attrs(rast__tri *t, const float *attr, int ac, int32_t v0,
                                   int32_t v1, int32_t v2)
{
    const __m256i am = _mm256_cmpgt_epi32(_mm256_set1_epi32(ac),
                                          _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
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
/* The indices and (X, Y) pairs of cnt (1..8) triangles at ix
 * (raster_frontq.inl). */
static inline __attribute__((always_inline)) void fv_load_group(const uint32_t *ix,
                                                                const long long *xyb, int cnt,
                                                                vint iv[3], vint X[3],
                                                                vint Y[3])
{
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
}

/* vi_compress_lanes by two 16-entry tables instead of its loop over the
 * set bits (1.2 M of the 13.5 M instructions of rast__frontv_avx2 in 8
 * stereo frames of egofuse render): the lane numbers of the set bits of
 * a nibble, 3 bits each in order, for lanes 0-3 (lo) and lanes 4-7 (hi);
 * the high nibble's numbers follow the low nibble's. The same packed
 * index, so the same vector. */
static const uint16_t compress_lo[16] = { 0x000, 0x000, 0x001, 0x008, 0x002, 0x010,
                                          0x011, 0x088, 0x003, 0x018, 0x019, 0x0c8,
                                          0x01a, 0x0d0, 0x0d1, 0x688 };
static const uint16_t compress_hi[16] = { 0x000, 0x004, 0x005, 0x02c, 0x006, 0x034,
                                          0x035, 0x1ac, 0x007, 0x03c, 0x03d, 0x1ec,
                                          0x03e, 0x1f4, 0x1f5, 0xfac };
static inline vint fv_compress_lanes(unsigned bits)
{
    const unsigned lo = bits & 15u, hi = (bits >> 4) & 15u;
    const uint32_t p = (uint32_t)compress_lo[lo] |
                       ((uint32_t)compress_hi[hi] << (3 * __builtin_popcount(lo)));
    const __m256i sh = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    return _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)p), sh),
                            _mm256_set1_epi32(7));
}

/* The group loop, the survivor queue and set-up written once. */
#include "raster_frontq.inl"

#else
typedef int rast__front_avx2_unused;   /* not an x86 build */
#endif
