/* raster_avx2.c - the AVX2 scan (8 lanes): raster_simd.inl with AVX2 lane
 * macros. Built with -mavx2 -mf16c (Makefile); called only when cpuid
 * reports AVX2 (raster_context.c). Bytes equal rast__scan_rows_ref. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <string.h>

#define SIMD_V 8
#define SIMD_FN rast__scan_rows_avx2
typedef __m256 vf;
typedef __m256i vi;

#define VF_SET1(x) _mm256_set1_ps(x)
#define VF_ADD(a, b) _mm256_add_ps(a, b)
#define VF_MUL(a, b) _mm256_mul_ps(a, b)
#define VF_DIV(a, b) _mm256_div_ps(a, b)
#define VF_MAX(a, b) _mm256_max_ps(a, b)
#define VF_MIN(a, b) _mm256_min_ps(a, b)
#define VF_CVT(v) _mm256_cvtepi32_ps(v)
#define VI_SET1(x) _mm256_set1_epi32(x)
#define VI_ADD(a, b) _mm256_add_epi32(a, b)
#define VI_OR(a, b) _mm256_or_si256(a, b)
#define VI_LOADU(p) _mm256_loadu_si256((const __m256i *)(const void *)(p))
#define VI_LANES() _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
#define VI_LANE_MUL(lanes, s) _mm256_mullo_epi32(lanes, _mm256_set1_epi32(s))
#define VI_NEG_BITS(v) ((unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(v)))
#define VF_LT_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LT_OQ)))
#define VF_STOREA(p, v) _mm256_store_ps(p, v)

/* Lane mask vector from bits: lane l all ones iff bit l is set. */
static inline __m256i bits_vec(unsigned bits)
{
    const __m256i sel = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)bits), sel), sel);
}

#define VF_LOAD_M(p, bits, full) \
    ((full) ? _mm256_loadu_ps(p) : _mm256_maskload_ps(p, bits_vec(bits)))
#define VF_STORE_M(p, bits, full, v)                       \
    do {                                                   \
        if (full) _mm256_storeu_ps(p, v);                  \
        else _mm256_maskstore_ps(p, bits_vec(bits), v);    \
    } while (0)

static inline void mask_store(uint8_t *p, unsigned bits, int full)
{
    if (full) {
        const uint64_t ones = ~(uint64_t)0;
        memcpy(p, &ones, 8);
        return;
    }
    for (; bits; bits &= bits - 1)
        p[__builtin_ctz(bits)] = 255;
}
#define MASK_STORE_M(p, bits, full) mask_store(p, bits, full)

/* 8 pixels x 3 attributes, planar -> interleaved (x0 y0 z0 x1 y1 z1 ...):
 * r[0..2] are floats 0..11 (pixels 0..3) in their low halves and floats
 * 12..23 (pixels 4..7) in their high halves. */
static inline void attr3_interleave(__m256 a, __m256 b, __m256 c, __m256 r[3])
{
    /* Per 128-bit half: lanes 0..3 of a, b, c -> 12 floats. */
    const __m256 ab_lo = _mm256_unpacklo_ps(a, b);   /* a0 b0 a1 b1 | a4 b4 a5 b5 */
    const __m256 ab_hi = _mm256_unpackhi_ps(a, b);   /* a2 b2 a3 b3 | a6 b6 a7 b7 */
    const __m256 c0 = _mm256_shuffle_ps(c, c, _MM_SHUFFLE(0, 0, 0, 0));
    const __m256 c1 = _mm256_shuffle_ps(c, c, _MM_SHUFFLE(1, 1, 1, 1));
    const __m256 c2 = _mm256_shuffle_ps(c, c, _MM_SHUFFLE(2, 2, 2, 2));
    const __m256 c3 = _mm256_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 3, 3));
    /* r0 = a0 b0 c0 a1 | a4 b4 c4 a5 */
    __m256 r0 = _mm256_shuffle_ps(ab_lo, c0, _MM_SHUFFLE(0, 0, 1, 0)); /* a0 b0 c0 c0 */
    r0 = _mm256_blend_ps(r0, _mm256_shuffle_ps(ab_lo, ab_lo, _MM_SHUFFLE(2, 2, 2, 2)), 0x88);
    /* r1 = b1 c1 a2 b2 | b5 c5 a6 b6 */
    __m256 r1 = _mm256_shuffle_ps(ab_lo, c1, _MM_SHUFFLE(0, 0, 3, 3)); /* b1 b1 c1 c1 */
    r1 = _mm256_shuffle_ps(r1, ab_hi, _MM_SHUFFLE(1, 0, 2, 0));         /* b1 c1 a2 b2 */
    /* r2 = c2 a3 b3 c3 | c6 a7 b7 c7 */
    __m256 r2 = _mm256_shuffle_ps(c2, ab_hi, _MM_SHUFFLE(3, 2, 0, 0));  /* c2 c2 a3 b3 */
    r2 = _mm256_shuffle_ps(r2, c3, _MM_SHUFFLE(0, 0, 3, 2));            /* a3 b3 c3 c3 */
    r2 = _mm256_permute_ps(r2, _MM_SHUFFLE(2, 1, 0, 3));                /* c3 a3 b3 c3 */
    r2 = _mm256_blend_ps(r2, c2, 0x11);                                 /* c2 a3 b3 c3 */
    r[0] = r0;
    r[1] = r1;
    r[2] = r2;
}

static inline void attr3_store(float *p, __m256 a, __m256 b, __m256 c)
{
    __m256 r[3];
    attr3_interleave(a, b, c, r);
    /* Halves: low = pixels 0..3 (12 floats), high = pixels 4..7. */
    _mm_storeu_ps(p + 0, _mm256_castps256_ps128(r[0]));
    _mm_storeu_ps(p + 4, _mm256_castps256_ps128(r[1]));
    _mm_storeu_ps(p + 8, _mm256_castps256_ps128(r[2]));
    _mm_storeu_ps(p + 12, _mm256_extractf128_ps(r[0], 1));
    _mm_storeu_ps(p + 16, _mm256_extractf128_ps(r[1], 1));
    _mm_storeu_ps(p + 20, _mm256_extractf128_ps(r[2], 1));
}

/* The pixels in bits only: the three vectors to the stack, then three
 * scalar stores per set bit, so no other float is touched. This replaced
 * the interleave with six 128-bit vmaskmovps per call (slow on AMD): the
 * AVX2 scan of the bench scene's records took 0.80-0.88 of the time
 * (one process, alternating). An interleaved copy with vector stores for
 * the whole 4-float chunks of a run of set bits was slower (1.02). */
static inline void attr3_store_m(float *p, unsigned bits, __m256 a, __m256 b, __m256 c)
{
    _Alignas(32) float t[3][8];
    _mm256_store_ps(t[0], a);
    _mm256_store_ps(t[1], b);
    _mm256_store_ps(t[2], c);
    for (; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        float *q = p + 3 * l;
        q[0] = t[0][l];
        q[1] = t[1][l];
        q[2] = t[2][l];
    }
}
#define ATTR3_STORE_M(p, bits, lanes, a, b, c) attr3_store_m(p, bits, a, b, c)
#define ATTR3_STORE_FULL(p, a, b, c) attr3_store(p, a, b, c)

#include "raster_simd.inl"

/* Anti-aliased coverage: 4 double lanes. */
#define AA_V 4
#define AA_FN rast__scan_aa_avx2
#include "raster_aa.inl"

/* Batched set-up (raster_planes.inl): planes in 4 double lanes, vertex fills. */
#define PD_V 4
#define PLANES_FN rast__planes_avx2
typedef __m256d vd;
#define PD_LOAD(p) _mm256_load_pd(p)
#define PD_SET1(x) _mm256_set1_pd(x)
#define PD_ADD(a, b) _mm256_add_pd(a, b)
#define PD_SUB(a, b) _mm256_sub_pd(a, b)
#define PD_MUL(a, b) _mm256_mul_pd(a, b)
#define PD_DIV(a, b) _mm256_div_pd(a, b)
#define PD_MAX(a, b) _mm256_max_pd(a, b)
#define PD_STORE_F(p, v) _mm_storeu_ps(p, _mm256_cvtpd_ps(v))
#define PS_V 8
#define VFILL_FN rast__vfill_avx2
#define SETUP_ISA rast__setup_isa_avx2
typedef __m256 vs;
#define PS_LOAD(p) _mm256_load_ps(p)
#define PS_SET1(x) _mm256_set1_ps(x)
#define PS_ADD(a, b) _mm256_add_ps(a, b)
#define PS_SUB(a, b) _mm256_sub_ps(a, b)
#define PS_MUL(a, b) _mm256_mul_ps(a, b)
#define PS_DIV(a, b) _mm256_div_ps(a, b)
#define PS_MAX(a, b) _mm256_max_ps(a, b)
#define PS_MIN(a, b) _mm256_min_ps(a, b)
#define PS_LT_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LT_OQ)))
#define PS_LE_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ)))
#define PS_GT_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_GT_OQ)))
#define PS_CVT_STORE(p, v) _mm256_store_si256((__m256i *)(void *)(p), _mm256_cvtps_epi32(v))
#define PD_LOAD_F(p) _mm256_cvtps_pd(_mm_load_ps(p))
#define PD_STORE(p, v) _mm256_store_pd(p, v)
/* The vector front end: raster_front_avx2.c. */
#define VPASS_FN rast__vpass_avx2
#define FRONTV_FN rast__frontv_avx2
#include "raster_planes.inl"

#else
typedef int rast__avx2_unused;   /* not an x86 build: the dispatcher skips it */
#endif
