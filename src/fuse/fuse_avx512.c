/* fuse_avx512.c - AVX-512 (F, BW, DQ, VL) path of the fuse kernels, built
 * with the flags of *_avx512.c and called only when cpuid reports them.
 * The bytes are the reference's (docs/fuse.md, "Rounding rules");
 * tests/test_fuse_isa.c checks it.
 * Lighting, depth test, coverage bits, opaque copies: fuse_simd.inl on the
 * vector layer (src/cpu/simd_avx512.h, 16 lanes, masks in k registers);
 * AVX-512's own part there is the depth test's scene values (two masked
 * loads of a window and vpermt2ps, or a masked gather).
 * The row-cached composite (fuse__hrow_avx512, fuse__vrow_avx512) is
 * fuse_simd.inl's too (FUSE_ROWCACHE_ON_LAYER), as for AVX2. */
#include "fuse_internal.h"

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
#include <immintrin.h>

#include "../cpu/simd_avx512.h"

/* The scene values of the lanes in has: when the 16 columns lie in a
 * window of 32 (always when the layer is enlarged), two loads of the window
 * (masked to the viewport's width: nothing beyond it is read) and
 * vpermt2ps; otherwise a gather. Lanes outside has are never used. */
static inline __m512 scene_avx512(const fuse__depth_prep *p, const float *sc, __m512i ox,
                                  __mmask16 has)
{
    const int32_t c0 = _mm_cvtsi128_si32(_mm512_castsi512_si128(ox));
    const int32_t c15 = _mm_extract_epi32(_mm512_extracti32x4_epi32(ox, 3), 3);
    if (c15 - c0 < 32) {
        const int32_t left = p->vw - c0;
        const __mmask16 k0 = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
        const __mmask16 k1 = left >= 32 ? (__mmask16)0xFFFF
                             : left <= 16 ? (__mmask16)0 : (__mmask16)((1u << (left - 16)) - 1u);
        const __m512 lo = _mm512_maskz_loadu_ps(k0, sc + c0);
        const __m512 hi = _mm512_maskz_loadu_ps(k1, sc + c0 + 16);
        return _mm512_permutex2var_ps(lo, _mm512_sub_epi32(ox, _mm512_set1_epi32(c0)), hi);
    }
    return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), has, ox, sc, 4);
}
#define FUSE_SCENE_LANES(p, sc, ox, has) scene_avx512(p, sc, ox, has)

/* vrow's alpha in each pixel's four 16-bit lanes by one pshufb (as AVX2) */
#define FUSE_ALPHA4(q)                                                                        \
    _mm512_shuffle_epi8(q, _mm512_broadcast_i32x4(_mm_setr_epi8(6, 7, 6, 7, 6, 7, 6, 7, 14, 15, \
                                                                14, 15, 14, 15, 14, 15)))

/* vrow's all-opaque test: no alpha lane (3 of 4) of q0 & q1 below 255 */
#define FUSE_ALPHA255(q0, q1)                                                       \
    (_mm512_mask_cmpneq_epu16_mask((__mmask32)0x88888888u, _mm512_and_si512(q0, q1), \
                                   _mm512_set1_epi16(255)) == 0)

/* hrow's empty window: one vptestmd */
#define FUSE_ZERO(v) (_mm512_test_epi32_mask(v, v) == 0)

#define FUSE_ROWCACHE_ON_LAYER 1
#include "fuse_simd.inl"

#else  /* not built for AVX-512: never chosen by cpuid, falls back */

#define FUSE_STUB(name) name##_avx512
#define FUSE_ROWCACHE_ON_LAYER 1
#include "fuse_stub.inl"
#endif
