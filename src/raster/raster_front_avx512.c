/* raster_front_avx512.c - the vector front end with AVX-512 (F+BW+DQ+VL,
 * 16 lanes): vertex pass, rejection of 16 submitted triangles per group
 * and the set-up of 16 survivors per vector, straight into scan-ready
 * records (rast__vpass_fn, rast__frontv_fn in raster_internal.h; design
 * and figures in docs/raster.md section 11, sixth round).
 *
 * The front end is written once on the vector layer (raster_front.inl:
 * rejection; raster_frontv.inl: vertex pass rast__vpass_avx512, planes,
 * micro values; raster_frontq.inl: the group loop rast__frontv_avx512,
 * the survivor queue, the int64 edges, the records) and compiled here on
 * simd_avx512.h; this file keeps what AVX-512 does its own way: the
 * de-interleaving loads of vertices (two-source permutes), of indices
 * (raster_front_avx512.inl) and (X, Y) pairs (fv_load_group), the double
 * gathers (fv_gather_d) and the masked attribute loads and stores
 * (fv_record_attrs). Every lane runs the operations of the scalar path in
 * its order (-ffp-contract=off), so every byte equals rast__prepare_range
 * with the scalar set-up. */
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
/* The indices and (X, Y) pairs of cnt (1..16) triangles at ix
 * (raster_frontq.inl): the indices by three (masked) loads and two-source
 * permutes (deint_tris); the (X, Y) pairs by one 64-bit load per vertex,
 * by scalar loads (faster than vpgatherdq on Zen 4: 0.95-0.97 of the
 * whole draw's time at 41k triangles, 0.97-0.99 at 10k, in one process),
 * the indices read from the mesh (a partial group: from a copy of the
 * de-interleaved vectors, vertex 0 past cnt). */
static inline __attribute__((always_inline)) void fv_load_group(const uint32_t *ix,
                                                                const long long *xyb, int cnt,
                                                                vint iv[3], vint X[3],
                                                                vint Y[3])
{
    const int ne = 3 * cnt;
    __m512i iw3[3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; i++) {
        const int left = ne - 16 * i;
        iw3[i] = left >= 16 ? _mm512_loadu_si512((const void *)(ix + 16 * i))
                 : left > 0 ? _mm512_maskz_loadu_epi32((__mmask16)((1u << left) - 1u),
                                                       (const void *)(ix + 16 * i))
                            : _mm512_setzero_si512();
    }
    deint_tris(iw3[0], iw3[1], iw3[2], iv);
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
}

/* setup_attrs for one record: a0 = attribute of vertex v0, d1 = a1 - a0,
 * d2 = a2 - a0, by masked loads (no byte past the vertex's ac floats is
 * read) and masked stores (no byte past a0[ac - 1], d1[ac - 1],
 * d2[ac - 1] is written). */
static inline __attribute__((always_inline)) void fv_record_attrs(rast__tri *t,
                                                                  const float *attr, int ac,
                                                                  int32_t v0, int32_t v1,
                                                                  int32_t v2)
{
    const __mmask8 AM = (__mmask8)((1u << ac) - 1u);
    const __m256 a0 = _mm256_maskz_loadu_ps(AM, attr + (size_t)v0 * (size_t)ac);
    const __m256 a1 = _mm256_maskz_loadu_ps(AM, attr + (size_t)v1 * (size_t)ac);
    const __m256 a2 = _mm256_maskz_loadu_ps(AM, attr + (size_t)v2 * (size_t)ac);
    _mm256_mask_storeu_ps(t->a0, AM, a0);
    _mm256_mask_storeu_ps(t->d1, AM, _mm256_sub_ps(a1, a0));
    _mm256_mask_storeu_ps(t->d2, AM, _mm256_sub_ps(a2, a0));
}

_Static_assert(RAST__FRONT_GROUP == 16, "one group per 16-lane vector");

/* The survivors' lane numbers: the layer's vpcompressd. */
static inline vint fv_compress_lanes(unsigned bits)
{
    return vi_compress_lanes(bits);
}

/* The group loop, the survivor queue and set-up written once. */
#include "raster_frontq.inl"

#else
typedef int rast__front_avx512_unused;   /* not an x86 build */
#endif
