/* raster_avx512.c - the AVX-512 scan (16 lanes, F+BW+DQ+VL): raster_simd.inl
 * with AVX-512 lane macros; masked loads and stores never touch disabled
 * lanes. Called only when cpuid reports AVX-512 (raster_context.c). Bytes
 * equal rast__scan_rows_ref. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

#define SIMD_V 16
#define SIMD_FN rast__scan_rows_avx512
typedef __m512 vf;
typedef __m512i vi;

#define VF_SET1(x) _mm512_set1_ps(x)
#define VF_ADD(a, b) _mm512_add_ps(a, b)
#define VF_MUL(a, b) _mm512_mul_ps(a, b)
#define VF_DIV(a, b) _mm512_div_ps(a, b)
#define VF_MAX(a, b) _mm512_max_ps(a, b)
#define VF_MIN(a, b) _mm512_min_ps(a, b)
#define VF_CVT(v) _mm512_cvtepi32_ps(v)
#define VI_SET1(x) _mm512_set1_epi32(x)
#define VI_ADD(a, b) _mm512_add_epi32(a, b)
#define VI_OR(a, b) _mm512_or_si512(a, b)
#define VI_LOADU(p) _mm512_loadu_si512((const void *)(p))
#define VI_LANES() \
    _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15)
#define VI_LANE_MUL(lanes, s) _mm512_mullo_epi32(lanes, _mm512_set1_epi32(s))
#define VI_NEG_BITS(v) ((unsigned)_mm512_movepi32_mask(v))
#define VF_LT_BITS(a, b) ((unsigned)_mm512_cmp_ps_mask(a, b, _CMP_LT_OQ))
#define VF_STOREA(p, v) _mm512_store_ps(p, v)
#define VF_LOAD_M(p, bits, full) _mm512_maskz_loadu_ps((__mmask16)(bits), p)
#define VF_STORE_M(p, bits, full, v) _mm512_mask_storeu_ps(p, (__mmask16)(bits), v)
#define MASK_STORE_M(p, bits, full) \
    _mm_mask_storeu_epi8(p, (__mmask16)(bits), _mm_set1_epi8((char)-1))

/* 16 pixels x 3 attributes, planar -> interleaved, with two-source
 * permutes: output vector o holds floats 16*o .. 16*o+15, float f being
 * attribute f % 3 of pixel f / 3. */
static inline void attr3_interleave(__m512 a, __m512 b, __m512 c, __m512 r[3])
{
    /* Index tables: (source << 4) | lane, source 0 = a/b pair, c merged
     * after. First permutex2var(a, idx_ab, b) places a and b floats, then a
     * masked permutexvar places c. */
    static const int32_t idx_ab[3][16] = {
        { 0, 16, 0, 1, 17, 0, 2, 18, 0, 3, 19, 0, 4, 20, 0, 5 },
        { 21, 0, 6, 22, 0, 7, 23, 0, 8, 24, 0, 9, 25, 0, 10, 26 },
        { 0, 11, 27, 0, 12, 28, 0, 13, 29, 0, 14, 30, 0, 15, 31, 0 },
    };
    static const int32_t idx_c[3][16] = {
        { 0, 0, 0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0 },
        { 0, 5, 0, 0, 6, 0, 0, 7, 0, 0, 8, 0, 0, 9, 0, 0 },
        { 10, 0, 0, 11, 0, 0, 12, 0, 0, 13, 0, 0, 14, 0, 0, 15 },
    };
    static const __mmask16 mc[3] = { 0x4924, 0x2492, 0x9249 };
    for (int o = 0; o < 3; o++) {
        __m512 v = _mm512_permutex2var_ps(a, _mm512_loadu_si512(idx_ab[o]), b);
        r[o] = _mm512_mask_permutexvar_ps(v, mc[o], _mm512_loadu_si512(idx_c[o]), c);
    }
}

static inline void attr3_store(float *p, __m512 a, __m512 b, __m512 c)
{
    __m512 r[3];
    attr3_interleave(a, b, c, r);
    for (int o = 0; o < 3; o++)
        _mm512_storeu_ps(p + 16 * o, r[o]);
}

/* Bit l of b -> bits 3l, 3l+1, 3l+2 (4 pixels -> 12 floats). */
static const uint16_t spread3_4[16] = {
    0x000, 0x007, 0x038, 0x03F, 0x1C0, 0x1C7, 0x1F8, 0x1FF,
    0xE00, 0xE07, 0xE38, 0xE3F, 0xFC0, 0xFC7, 0xFF8, 0xFFF,
};

/* The pixels in bits only (masked stores: other floats are not touched). */
static inline void attr3_store_m(float *p, unsigned bits, __m512 a, __m512 b, __m512 c)
{
    __m512 r[3];
    attr3_interleave(a, b, c, r);
    const uint64_t m = (uint64_t)spread3_4[bits & 15u] |
                       (uint64_t)spread3_4[(bits >> 4) & 15u] << 12 |
                       (uint64_t)spread3_4[(bits >> 8) & 15u] << 24 |
                       (uint64_t)spread3_4[(bits >> 12) & 15u] << 36;
    for (int o = 0; o < 3; o++)
        if ((m >> (16 * o)) & 0xFFFFu)
            _mm512_mask_storeu_ps(p + 16 * o, (__mmask16)(m >> (16 * o)), r[o]);
}
#define ATTR3_STORE_M(p, bits, a, b, c) attr3_store_m(p, bits, a, b, c)
#define ATTR3_STORE_FULL(p, a, b, c) attr3_store(p, a, b, c)

#include "raster_simd.inl"

/* Anti-aliased coverage: 8 double lanes. */
#define AA_V 8
#define AA_FN rast__scan_aa_avx512
#include "raster_aa.inl"

#else
typedef int rast__avx512_unused;   /* not an x86 build: the dispatcher skips it */
#endif
