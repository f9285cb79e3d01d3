/* fuse_avx2.c - AVX2 path of the fuse kernels (built with -mavx2 -mf16c,
 * called only when cpuid reports AVX2). The bytes are the reference's
 * (docs/fuse.md, "Rounding rules"); tests/test_fuse_isa.c checks it.
 *
 * Lighting, depth test, coverage bits, opaque copies: fuse_simd.inl on the
 * vector layer (src/cpu/simd_avx2.h, 8 lanes); AVX2's own part there is
 * the depth test's scene values (a window of the row and vpermps, or a
 * gather).
 * Composite through the row cache (fuse_internal.h): fuse__hrow_avx2 once
 * per layer row, fuse__vrow_avx2 per output row. The taps of 8 consecutive
 * output pixels lie in a window of 8 source pixels when the layer is
 * enlarged (640 -> 1194: at most 5), so one load and vpermd give them;
 * otherwise (reductions, narrow layers) vpgatherdd. */
#include "fuse_internal.h"

#if defined(__AVX2__)
#include <immintrin.h>

#include "../cpu/simd_avx2.h"

/* The scene values of the lanes in has: when the 8 columns lie in a window
 * of 16 (always when the layer is enlarged), two loads of the window
 * (masked to the viewport's width: nothing beyond it is read), two vpermps
 * and a blend; otherwise a gather. Lanes outside has are never used. */
static inline __m256 scene_avx2(const fuse__depth_prep *p, const float *sc, __m256i ox, __m256 has)
{
    const int32_t c0 = _mm_cvtsi128_si32(_mm256_castsi256_si128(ox));
    const int32_t c7 = _mm_extract_epi32(_mm256_extracti128_si256(ox, 1), 3);
    if (c7 - c0 < 16) {
        const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        const __m256i left = _mm256_set1_epi32(p->vw - c0);
        const __m256 lo = _mm256_maskload_ps(sc + c0, _mm256_cmpgt_epi32(left, lane));
        const __m256 hi = _mm256_maskload_ps(sc + c0 + 8, _mm256_cmpgt_epi32(
            left, _mm256_add_epi32(lane, _mm256_set1_epi32(8))));
        const __m256i idx = _mm256_sub_epi32(ox, _mm256_set1_epi32(c0));
        return _mm256_blendv_ps(_mm256_permutevar8x32_ps(lo, idx), _mm256_permutevar8x32_ps(hi, idx),
                                _mm256_castsi256_ps(_mm256_cmpgt_epi32(idx, _mm256_set1_epi32(7))));
    }
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), sc, ox, has, 4);
}
#define FUSE_SCENE_LANES(p, sc, ox, has) scene_avx2(p, sc, ox, has)

#include "fuse_simd.inl"
/* ---- row-cached composite (fuse_internal.h, fuse__hrow_fn) ------------- */

/* The fx of 4 pixels (int32) in each pixel's 4 u16 lanes. */
static inline __m256i wx4_256(const int32_t *fx)
{
    const __m256i pat = _mm256_setr_epi8(0, -128, 0, -128, 0, -128, 0, -128, 4, -128, 4, -128, 4, -128, 4, -128,
                                         8, -128, 8, -128, 8, -128, 8, -128, 12, -128, 12, -128, 12, -128, 12, -128);
    const __m128i f = _mm_loadu_si128((const __m128i *)(const void *)fx);
    return _mm256_shuffle_epi8(_mm256_broadcastsi128_si256(f), pat);
}

void fuse__hrow_avx2(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                     uint16_t *h)
{
    const __m256i one = _mm256_set1_epi32(1), last = _mm256_set1_epi32(sw - 1);
    const __m256i w256 = _mm256_set1_epi16(256), bias = _mm256_set1_epi16((short)FUSE__H_BIAS);
    const int32_t *ixs = cols->ix + c, *fxs = cols->fx + c;
    int i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m256i ix = _mm256_loadu_si256((const __m256i *)(const void *)(ixs + i));
        const __m256i ix1 = _mm256_min_epi32(_mm256_add_epi32(ix, one), last);
        __m256i a, b, w1;
        int base = ixs[i];
        const int hi = ixs[i + 7] + 1 < sw ? ixs[i + 7] + 1 : sw - 1;
        if (base > sw - 8) base = sw - 8;
        if (base >= 0 && hi - base < 8) {
            const __m256i s0 = _mm256_loadu_si256((const __m256i *)(const void *)(q + 4 * base));
            const __m256i bb = _mm256_set1_epi32(base);
            if (_mm256_testz_si256(s0, s0)) {   /* every tap 0: h = 0 */
                _mm256_storeu_si256((__m256i *)(void *)(h + 4 * i), bias);
                _mm256_storeu_si256((__m256i *)(void *)(h + 4 * i + 16), bias);
                continue;
            }
            a = _mm256_permutevar8x32_epi32(s0, _mm256_sub_epi32(ix, bb));
            b = _mm256_permutevar8x32_epi32(s0, _mm256_sub_epi32(ix1, bb));
        } else {
            a = _mm256_i32gather_epi32((const int *)(const void *)q, ix, 4);
            b = _mm256_i32gather_epi32((const int *)(const void *)q, ix1, 4);
        }
        w1 = wx4_256(fxs + i);
        _mm256_storeu_si256((__m256i *)(void *)(h + 4 * i),
                            _mm256_xor_si256(_mm256_add_epi16(
                                _mm256_mullo_epi16(_mm256_cvtepu8_epi16(_mm256_castsi256_si128(a)),
                                                   _mm256_sub_epi16(w256, w1)),
                                _mm256_mullo_epi16(_mm256_cvtepu8_epi16(_mm256_castsi256_si128(b)), w1)), bias));
        w1 = wx4_256(fxs + i + 4);
        _mm256_storeu_si256((__m256i *)(void *)(h + 4 * i + 16),
                            _mm256_xor_si256(_mm256_add_epi16(
                                _mm256_mullo_epi16(_mm256_cvtepu8_epi16(_mm256_extracti128_si256(a, 1)),
                                                   _mm256_sub_epi16(w256, w1)),
                                _mm256_mullo_epi16(_mm256_cvtepu8_epi16(_mm256_extracti128_si256(b, 1)), w1)), bias));
    }
    for (; i < n; i++) fuse__hpx(q, ixs[i], (uint32_t)fxs[i], sw, h + 4 * i);
}

/* 4 pixels of the vertical blend and over (see vblend8_512 in
 * fuse_avx512.c). */
static inline __m256i vblend4_256(__m256i a, __m256i b, __m256i vw, __m256i w)
{
    const __m256i lo8 = _mm256_set1_epi16(255), r128 = _mm256_set1_epi16(128);
    const __m256i k = _mm256_set1_epi32(32768 * 257);
    const __m256i sl = _mm256_srli_epi32(_mm256_add_epi32(_mm256_madd_epi16(_mm256_unpacklo_epi16(a, b), w), k), 16);
    const __m256i sh = _mm256_srli_epi32(_mm256_add_epi32(_mm256_madd_epi16(_mm256_unpackhi_epi16(a, b), w), k), 16);
    const __m256i q = _mm256_packus_epi32(sl, sh);
    const __m256i qa = _mm256_shufflehi_epi16(_mm256_shufflelo_epi16(q, 0xFF), 0xFF);
    __m256i t = _mm256_mullo_epi16(_mm256_sub_epi16(lo8, qa), vw);
    /* div255: ((t + 128) + ((t + 128) >> 8)) >> 8 is ((t + 128) 257) >> 16 (the
     * inner floor cannot move the outer one: an integer plus a fraction
     * below 1 never crosses a multiple of 256), one vpmulhuw */
    t = _mm256_mulhi_epu16(_mm256_add_epi16(t, r128), _mm256_set1_epi16(257));
    return _mm256_add_epi16(q, t);
}

void fuse__vrow_avx2(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                     const uint8_t *v, uint8_t *out, int n)
{
    const __m256i w = _mm256_set1_epi32((int)((fy << 16) | (256u - fy)));
    const __m256i opaque = _mm256_set1_epi32((int)0xFF000000u);
    int i = 0;
    for (; i + 8 <= n; i += 8) {
        const __m256i vv = _mm256_loadu_si256((const __m256i *)(const void *)(v + 4 * i));
        const __m256i r0 = vblend4_256(_mm256_loadu_si256((const __m256i *)(const void *)(h0 + 4 * i)),
                                       _mm256_loadu_si256((const __m256i *)(const void *)(h1 + 4 * i)),
                                       _mm256_cvtepu8_epi16(_mm256_castsi256_si128(vv)), w);
        const __m256i r1 = vblend4_256(_mm256_loadu_si256((const __m256i *)(const void *)(h0 + 4 * i + 16)),
                                       _mm256_loadu_si256((const __m256i *)(const void *)(h1 + 4 * i + 16)),
                                       _mm256_cvtepu8_epi16(_mm256_extracti128_si256(vv, 1)), w);
        /* packus interleaves the halves per 128-bit lane: qwords 0 2 1 3 */
        const __m256i r = _mm256_permute4x64_epi64(_mm256_packus_epi16(r0, r1), 0xD8);
        _mm256_storeu_si256((__m256i *)(void *)(out + 4 * i), _mm256_or_si256(r, opaque));
    }
    for (; i < n; i++) fuse__vpx(h0 + 4 * i, h1 + 4 * i, fy, v + 4 * i, out + 4 * i);
}

#else  /* not built for AVX2: never chosen by cpuid, falls back */

#define FUSE_STUB(name) name##_avx2
#include "fuse_stub.inl"

void fuse__hrow_avx2(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                     uint16_t *h)
{
    int i;
    for (i = 0; i < n; i++) fuse__hpx(q, cols->ix[c + i], (uint32_t)cols->fx[c + i], sw, h + 4 * i);
}
void fuse__vrow_avx2(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                     const uint8_t *v, uint8_t *out, int n)
{
    int i;
    for (i = 0; i < n; i++) fuse__vpx(h0 + 4 * i, h1 + 4 * i, fy, v + 4 * i, out + 4 * i);
}
#endif

#if defined(__AVX2__)
/* ---- camera formats: YUYV / UYVY rows (fuse_formats.c, yuv_px) ---------
 *
 * 16 pixels a step, the reference's integer formula exactly: with
 * C = Y-16, D = U-128, E = V-128 every channel is base + a pair product,
 *   base = 298 C + 128 (one madd of (C, 1) by (298, 128)),
 *   R = base + 409 E, G = base - 100 D - 208 E, B = base + 516 D
 * (madd of (D, E) by (0, 409), (-100, -208), (516, 0)), all in int32;
 * then v >> 8 (arithmetic) and the unsigned saturating packs give exactly
 * clamp255: a negative v has a negative v >> 8, packed to 0, and v >> 8 is
 * at most 534, which packs to 255. */
static inline __m256i yuv_channel(__m256i base_lo, __m256i base_hi, __m256i de_lo,
                                  __m256i de_hi, __m256i k)
{
    __m256i lo = _mm256_srai_epi32(_mm256_add_epi32(base_lo, _mm256_madd_epi16(de_lo, k)), 8);
    __m256i hi = _mm256_srai_epi32(_mm256_add_epi32(base_hi, _mm256_madd_epi16(de_hi, k)), 8);
    return _mm256_packs_epi32(lo, hi); /* int16, pixel order kept per lane */
}

int fuse__yuv422_row_avx2(const uint8_t *src, int width, int uyvy, uint8_t *dst)
{
    const __m256i lo8 = _mm256_set1_epi16(0x00FF);
    const __m256i c16 = _mm256_set1_epi16(16), c128 = _mm256_set1_epi16(128);
    const __m256i one = _mm256_set1_epi16(1), alpha = _mm256_set1_epi16(255);
    const __m256i kbase = _mm256_set1_epi32((128 << 16) | 298);
    const __m256i kr = _mm256_set1_epi32(409 << 16);
    const __m256i kg = _mm256_set1_epi32((int)(((uint32_t)(uint16_t)-208 << 16) | (uint16_t)-100));
    const __m256i kb = _mm256_set1_epi32(516);
    int x = 0;
    for (; x + 16 <= width; x += 16) {
        __m256i v = _mm256_loadu_si256((const __m256i *)(const void *)(src + 2 * x));
        __m256i yw = uyvy ? _mm256_srli_epi16(v, 8) : _mm256_and_si256(v, lo8);
        __m256i cw = uyvy ? _mm256_and_si256(v, lo8) : _mm256_srli_epi16(v, 8);
        __m256i c = _mm256_sub_epi16(yw, c16);
        __m256i ch = _mm256_sub_epi16(cw, c128);           /* D0 E0 D1 E1 ... */
        __m256i d = _mm256_shufflehi_epi16(_mm256_shufflelo_epi16(ch, 0xA0), 0xA0);
        __m256i e = _mm256_shufflehi_epi16(_mm256_shufflelo_epi16(ch, 0xF5), 0xF5);
        __m256i base_lo = _mm256_madd_epi16(_mm256_unpacklo_epi16(c, one), kbase);
        __m256i base_hi = _mm256_madd_epi16(_mm256_unpackhi_epi16(c, one), kbase);
        __m256i de_lo = _mm256_unpacklo_epi16(d, e), de_hi = _mm256_unpackhi_epi16(d, e);
        __m256i r = yuv_channel(base_lo, base_hi, de_lo, de_hi, kr);
        __m256i g = yuv_channel(base_lo, base_hi, de_lo, de_hi, kg);
        __m256i b = yuv_channel(base_lo, base_hi, de_lo, de_hi, kb);
        __m256i rg = _mm256_packus_epi16(r, g);             /* R0-7 G0-7 | R8-15 G8-15 */
        __m256i ba = _mm256_packus_epi16(b, alpha);         /* B0-7 A    | B8-15 A */
        __m256i rb = _mm256_unpacklo_epi8(rg, ba);          /* R0 B0 R1 B1 ... */
        __m256i ga = _mm256_unpackhi_epi8(rg, ba);          /* G0 A  G1 A  ... */
        __m256i p0 = _mm256_unpacklo_epi8(rb, ga);          /* px 0-3 | 8-11 */
        __m256i p1 = _mm256_unpackhi_epi8(rb, ga);          /* px 4-7 | 12-15 */
        _mm256_storeu_si256((__m256i *)(void *)(dst + 4 * x), _mm256_permute2x128_si256(p0, p1, 0x20));
        _mm256_storeu_si256((__m256i *)(void *)(dst + 4 * x + 32), _mm256_permute2x128_si256(p0, p1, 0x31));
    }
    return x; /* pixels done; the caller finishes the row */
}
#endif /* __AVX2__ */
