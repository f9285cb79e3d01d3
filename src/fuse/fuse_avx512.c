/* fuse_avx512.c - AVX-512 (F, BW, DQ, VL) path of the fuse kernels, built
 * with the flags of *_avx512.c and called only when cpuid reports them.
 * The bytes are the reference's (docs/fuse.md, "Rounding rules");
 * tests/test_fuse_isa.c checks it.
 * Lighting, depth test, coverage bits, opaque copies: fuse_simd.inl on the
 * vector layer (src/cpu/simd_avx512.h, 16 lanes, masks in k registers);
 * AVX-512's own part there is the depth test's scene values (two masked
 * loads of a window and vpermt2ps, or a masked gather).
 * Composite through the row cache (fuse__hrow_avx512 once per layer row,
 * fuse__vrow_avx512 per output row; fuse_internal.h): taps from a window
 * of 16 source pixels per row (vpermd) when it holds them all, else
 * vpgatherdd. */
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

#include "fuse_simd.inl"
/* ---- row-cached composite (fuse_internal.h, fuse__hrow_fn) ------------- */

/* The fx of 8 pixels (int32) in each pixel's 4 u16 lanes. */
static inline __m512i wx8_512(const int32_t *fx)
{
    const __m512i idx = _mm512_setr_epi32(0, 0, 0x00020002, 0x00020002, 0x00040004, 0x00040004,
                                          0x00060006, 0x00060006, 0x00080008, 0x00080008,
                                          0x000A000A, 0x000A000A, 0x000C000C, 0x000C000C,
                                          0x000E000E, 0x000E000E);
    const __m256i f = _mm256_loadu_si256((const __m256i *)(const void *)fx);
    return _mm512_permutexvar_epi16(idx, _mm512_castsi256_si512(f));
}

void fuse__hrow_avx512(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                       uint16_t *h)
{
    const __m512i one = _mm512_set1_epi32(1), last = _mm512_set1_epi32(sw - 1);
    const __m512i w256 = _mm512_set1_epi16(256), bias = _mm512_set1_epi16((short)FUSE__H_BIAS);
    const int32_t *ixs = cols->ix + c, *fxs = cols->fx + c;
    int i = 0;
    for (; i + 16 <= n; i += 16) {
        const __m512i ix = _mm512_loadu_si512((const void *)(ixs + i));
        const __m512i ix1 = _mm512_min_epi32(_mm512_add_epi32(ix, one), last);
        __m512i a, b, w1;
        int base = ixs[i];
        const int hi = ixs[i + 15] + 1 < sw ? ixs[i + 15] + 1 : sw - 1;
        if (base > sw - 16) base = sw - 16;
        if (base >= 0 && hi - base < 16) {
            const __m512i s0 = _mm512_loadu_si512((const void *)(q + 4 * base));
            const __m512i bb = _mm512_set1_epi32(base);
            if (_mm512_test_epi32_mask(s0, s0) == 0) {   /* every tap 0: h = 0 */
                _mm512_storeu_si512((void *)(h + 4 * i), bias);
                _mm512_storeu_si512((void *)(h + 4 * i + 32), bias);
                continue;
            }
            a = _mm512_permutexvar_epi32(_mm512_sub_epi32(ix, bb), s0);
            b = _mm512_permutexvar_epi32(_mm512_sub_epi32(ix1, bb), s0);
        } else {
            a = _mm512_i32gather_epi32(ix, (const void *)q, 4);
            b = _mm512_i32gather_epi32(ix1, (const void *)q, 4);
        }
        w1 = wx8_512(fxs + i);
        _mm512_storeu_si512((void *)(h + 4 * i),
                            _mm512_xor_si512(_mm512_add_epi16(
                                _mm512_mullo_epi16(_mm512_cvtepu8_epi16(_mm512_castsi512_si256(a)),
                                                   _mm512_sub_epi16(w256, w1)),
                                _mm512_mullo_epi16(_mm512_cvtepu8_epi16(_mm512_castsi512_si256(b)), w1)), bias));
        w1 = wx8_512(fxs + i + 8);
        _mm512_storeu_si512((void *)(h + 4 * i + 32),
                            _mm512_xor_si512(_mm512_add_epi16(
                                _mm512_mullo_epi16(_mm512_cvtepu8_epi16(_mm512_extracti64x4_epi64(a, 1)),
                                                   _mm512_sub_epi16(w256, w1)),
                                _mm512_mullo_epi16(_mm512_cvtepu8_epi16(_mm512_extracti64x4_epi64(b, 1)), w1)), bias));
    }
    for (; i < n; i++) fuse__hpx(q, ixs[i], (uint32_t)fxs[i], sw, h + 4 * i);
}

/* 8 pixels: q = ((h0 - 32768) w0 + (h1 - 32768) w1 + 32768 * 257) >> 16
 * per channel (fuse_internal.h: the stored values are h - 32768; w holds
 * the pairs (w0, w1)), then over with the 8 pixels of V in vw (u16
 * lanes). unpacklo/hi pair the channels of pixels 0, 2, 4, 6 and 1, 3, 5,
 * 7; packus puts them back in order. */
static inline __m512i vblend8_512(__m512i a, __m512i b, __m512i vw, __m512i w)
{
    const __m512i lo8 = _mm512_set1_epi16(255), r128 = _mm512_set1_epi16(128);
    const __m512i k = _mm512_set1_epi32(32768 * 257);
    const __m512i sl = _mm512_srli_epi32(_mm512_add_epi32(_mm512_madd_epi16(_mm512_unpacklo_epi16(a, b), w), k), 16);
    const __m512i sh = _mm512_srli_epi32(_mm512_add_epi32(_mm512_madd_epi16(_mm512_unpackhi_epi16(a, b), w), k), 16);
    const __m512i q = _mm512_packus_epi32(sl, sh);
    const __m512i qa = _mm512_shufflehi_epi16(_mm512_shufflelo_epi16(q, 0xFF), 0xFF);
    __m512i t = _mm512_mullo_epi16(_mm512_sub_epi16(lo8, qa), vw);
    /* div255: ((t + 128) + ((t + 128) >> 8)) >> 8 is ((t + 128) 257) >> 16 (the
     * inner floor cannot move the outer one: an integer plus a fraction
     * below 1 never crosses a multiple of 256), one vpmulhuw */
    t = _mm512_mulhi_epu16(_mm512_add_epi16(t, r128), _mm512_set1_epi16(257));
    return _mm512_add_epi16(q, t);
}

void fuse__vrow_avx512(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                       const uint8_t *v, uint8_t *out, int n)
{
    const __m512i w = _mm512_set1_epi32((int)((fy << 16) | (256u - fy)));
    const __m512i order = _mm512_setr_epi64(0, 2, 4, 6, 1, 3, 5, 7);
    const __m512i opaque = _mm512_set1_epi32((int)0xFF000000u);
    int i = 0;
    for (; i + 16 <= n; i += 16) {
        const __m512i vv = _mm512_loadu_si512((const void *)(v + 4 * i));
        const __m512i r0 = vblend8_512(_mm512_loadu_si512((const void *)(h0 + 4 * i)),
                                       _mm512_loadu_si512((const void *)(h1 + 4 * i)),
                                       _mm512_cvtepu8_epi16(_mm512_castsi512_si256(vv)), w);
        const __m512i r1 = vblend8_512(_mm512_loadu_si512((const void *)(h0 + 4 * i + 32)),
                                       _mm512_loadu_si512((const void *)(h1 + 4 * i + 32)),
                                       _mm512_cvtepu8_epi16(_mm512_extracti64x4_epi64(vv, 1)), w);
        /* packus interleaves the halves per 128-bit lane: qwords 0 2 4 6 1 3 5 7 */
        const __m512i r = _mm512_permutexvar_epi64(order, _mm512_packus_epi16(r0, r1));
        _mm512_storeu_si512((void *)(out + 4 * i), _mm512_or_si512(r, opaque));
    }
    for (; i < n; i++) fuse__vpx(h0 + 4 * i, h1 + 4 * i, fy, v + 4 * i, out + 4 * i);
}

#else  /* not built for AVX-512: never chosen by cpuid, falls back */

#define FUSE_STUB(name) name##_avx512
#include "fuse_stub.inl"

void fuse__hrow_avx512(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                       uint16_t *h)
{
    int i;
    for (i = 0; i < n; i++) fuse__hpx(q, cols->ix[c + i], (uint32_t)cols->fx[c + i], sw, h + 4 * i);
}
void fuse__vrow_avx512(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                       const uint8_t *v, uint8_t *out, int n)
{
    int i;
    for (i = 0; i < n; i++) fuse__vpx(h0 + 4 * i, h1 + 4 * i, fy, v + 4 * i, out + 4 * i);
}
#endif
