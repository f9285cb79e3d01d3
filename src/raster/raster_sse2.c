/* raster_sse2.c - the portable scan: SSE2 (x86-64 baseline, 4 lanes) with
 * raster_simd.inl. Partial vectors go through scalar lane loops, so no
 * access ever leaves the scanned pixels. Bytes equal rast__scan_rows_ref.
 * (On other architectures the dispatcher uses the reference.) */
#include "raster_internal.h"

#if defined(__x86_64__) || (defined(__i386__) && defined(__SSE2__))
#include <emmintrin.h>
#include <string.h>

#define SIMD_V 4
#define SIMD_FN rast__scan_rows_sse2
typedef __m128 vf;
typedef __m128i vi;

#define VF_SET1(x) _mm_set1_ps(x)
#define VF_ADD(a, b) _mm_add_ps(a, b)
#define VF_MUL(a, b) _mm_mul_ps(a, b)
#define VF_DIV(a, b) _mm_div_ps(a, b)
#define VF_MAX(a, b) _mm_max_ps(a, b)
#define VF_MIN(a, b) _mm_min_ps(a, b)
#define VF_CVT(v) _mm_cvtepi32_ps(v)
#define VI_SET1(x) _mm_set1_epi32(x)
#define VI_ADD(a, b) _mm_add_epi32(a, b)
#define VI_OR(a, b) _mm_or_si128(a, b)
#define VI_LOADU(p) _mm_loadu_si128((const __m128i *)(const void *)(p))
#define VI_LANES() _mm_setr_epi32(0, 1, 2, 3)
/* No 32-bit multiply in SSE2: the products in scalar (|3*s| < 2^27). */
#define VI_LANE_MUL(lanes, s) _mm_setr_epi32(0, (s), 2 * (s), 3 * (s))
#define VI_NEG_BITS(v) ((unsigned)_mm_movemask_ps(_mm_castsi128_ps(v)))
#define VF_LT_BITS(a, b) ((unsigned)_mm_movemask_ps(_mm_cmplt_ps(a, b)))
#define VF_STOREA(p, v) _mm_store_ps(p, v)

static inline __m128 load_m(const float *p, unsigned bits, int full)
{
    if (full)
        return _mm_loadu_ps(p);
    _Alignas(16) float tmp[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    for (; bits; bits &= bits - 1)
        tmp[__builtin_ctz(bits)] = p[__builtin_ctz(bits)];
    return _mm_load_ps(tmp);
}

static inline void store_m(float *p, unsigned bits, int full, __m128 v)
{
    if (full) {
        _mm_storeu_ps(p, v);
        return;
    }
    _Alignas(16) float tmp[4];
    _mm_store_ps(tmp, v);
    for (; bits; bits &= bits - 1)
        p[__builtin_ctz(bits)] = tmp[__builtin_ctz(bits)];
}

static inline void mask_store(uint8_t *p, unsigned bits, int full)
{
    if (full) {
        const uint32_t ones = ~(uint32_t)0;
        memcpy(p, &ones, 4);
        return;
    }
    for (; bits; bits &= bits - 1)
        p[__builtin_ctz(bits)] = 255;
}

#define VF_LOAD_M(p, bits, full) load_m(p, bits, full)
#define VF_STORE_M(p, bits, full, v) store_m(p, bits, full, v)
#define MASK_STORE_M(p, bits, full) mask_store(p, bits, full)

/* 4 pixels x 3 attributes, planar -> interleaved. */
static inline void attr3_store(float *p, __m128 a, __m128 b, __m128 c)
{
    const __m128 ab_lo = _mm_unpacklo_ps(a, b);                     /* a0 b0 a1 b1 */
    const __m128 ab_hi = _mm_unpackhi_ps(a, b);                     /* a2 b2 a3 b3 */
    const __m128 ca = _mm_shuffle_ps(c, a, _MM_SHUFFLE(1, 1, 0, 0)); /* c0 c0 a1 a1 */
    const __m128 r0 = _mm_shuffle_ps(ab_lo, ca, _MM_SHUFFLE(2, 0, 1, 0)); /* a0 b0 c0 a1 */
    const __m128 bc = _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 1, 1)); /* b1 b1 c1 c1 */
    const __m128 r1 = _mm_shuffle_ps(bc, ab_hi, _MM_SHUFFLE(1, 0, 2, 0)); /* b1 c1 a2 b2 */
    const __m128 cc = _mm_shuffle_ps(c, ab_hi, _MM_SHUFFLE(3, 2, 2, 2)); /* c2 c2 a3 b3 */
    const __m128 bc3 = _mm_shuffle_ps(ab_hi, c, _MM_SHUFFLE(3, 3, 3, 3)); /* b3 b3 c3 c3 */
    const __m128 r2 = _mm_shuffle_ps(cc, bc3, _MM_SHUFFLE(2, 0, 2, 0));  /* c2 a3 b3 c3 */
    _mm_storeu_ps(p + 0, r0);
    _mm_storeu_ps(p + 4, r1);
    _mm_storeu_ps(p + 8, r2);
}
#define ATTR3_STORE_FULL(p, a, b, c) attr3_store(p, a, b, c)

#include "raster_simd.inl"

/* Anti-aliased coverage: 2 double lanes. */
#define AA_V 2
#define AA_FN rast__scan_aa_sse2
#include "raster_aa.inl"

#else
typedef int rast__sse2_unused;   /* not x86: the dispatcher uses the reference */
#endif
