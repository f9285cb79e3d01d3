/* fuse_sse2.c - the SSE2 path of the fuse kernels: the x86-64 baseline
 * (no flags needed). The bytes are the reference's (docs/fuse.md,
 * "Rounding rules"); tests/test_fuse_isa.c checks it.
 * Lighting, depth test, coverage bits, opaque copies: fuse_simd.inl on the
 * vector layer (src/cpu/simd_sse2.h, 4 lanes; the scene values of the
 * depth test lane by lane: SSE2 has no gather).
 * Composite: 4 output pixels per step, taps loaded one by one, blend and
 * over in 16-bit lanes (the exact decomposition at blend16).
 * On a machine without SSE2 (ARM) the reference kernels stand in. */
#include "fuse_internal.h"

#if defined(__SSE2__)
#include <emmintrin.h>

#include "../cpu/simd_sse2.h"

/* 4 interleaved xyz normals -> x, y, z, each vector built from its four
 * scalars in registers (no store and reload through a buffer) */
#define FUSE_LOAD_NORMALS(p, x, y, z) do { const float *q_ = (p); \
        (x) = _mm_setr_ps(q_[0], q_[3], q_[6], q_[9]); \
        (y) = _mm_setr_ps(q_[1], q_[4], q_[7], q_[10]); \
        (z) = _mm_setr_ps(q_[2], q_[5], q_[8], q_[11]); } while (0)

#define FUSE_YUV_ON_LAYER 1
#include "fuse_simd.inl"

static inline uint32_t load_u32(const uint8_t *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}
/* ---- composite ---------------------------------------------------------- */

/* Bilinear blend + over of 2 pixels in 16-bit lanes (a, b, c, d, v: the
 * taps and V widened to u16; wx0/wx1: 256 - fx and fx per channel; wy0/wy1
 * the same for the row). The reference's
 *   q = ((a wx0 + b wx1) wy0 + (c wx0 + d wx1) wy1 + 32768) >> 16
 * is a sum of exact integer products, so it may be grouped by columns:
 *   col0 = a wy0 + c wy1,  col1 = b wy0 + d wy1      (<= 65280: u16)
 *   S = col0 wx0 + col1 wx1 = 256 H + Lo with
 *   H = hi0 wx0 + hi1 wx1, Lo = lo0 wx0 + lo1 wx1 (hi = col >> 8, lo = col & 255)
 *   q = floor((S + 32768) / 65536) = (H + (Lo >> 8) + 128) >> 8
 * where H + (Lo >> 8) <= S / 256 <= 65280, so every step fits in u16. Over:
 *   r = q + div255((255 - qa) v),  div255(t) = (t + 128 + ((t + 128) >> 8)) >> 8
 * with t <= 65025; the final min(255, .) is the saturating pack. */

static inline __m128i blend16(__m128i a, __m128i b, __m128i c, __m128i d, __m128i v,
                              __m128i wx0, __m128i wx1, __m128i wy0, __m128i wy1)
{
    const __m128i lo8 = _mm_set1_epi16(255);
    const __m128i col0 = _mm_add_epi16(_mm_mullo_epi16(a, wy0), _mm_mullo_epi16(c, wy1));
    const __m128i col1 = _mm_add_epi16(_mm_mullo_epi16(b, wy0), _mm_mullo_epi16(d, wy1));
    const __m128i H = _mm_add_epi16(_mm_mullo_epi16(_mm_srli_epi16(col0, 8), wx0),
                                    _mm_mullo_epi16(_mm_srli_epi16(col1, 8), wx1));
    const __m128i L = _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(col0, lo8), wx0),
                                    _mm_mullo_epi16(_mm_and_si128(col1, lo8), wx1));
    const __m128i q = _mm_srli_epi16(
        _mm_add_epi16(_mm_add_epi16(H, _mm_srli_epi16(L, 8)), _mm_set1_epi16(128)), 8);
    const __m128i qa = _mm_shufflehi_epi16(_mm_shufflelo_epi16(q, 0xFF), 0xFF);
    __m128i t = _mm_mullo_epi16(_mm_sub_epi16(lo8, qa), v);
    t = _mm_add_epi16(t, _mm_set1_epi16(128));
    t = _mm_srli_epi16(_mm_add_epi16(t, _mm_srli_epi16(t, 8)), 8);
    return _mm_add_epi16(q, t);
}

void fuse__composite_cols_sse2(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                               const fuse__cols *cols, int c, int n, int sw,
                               const uint8_t *v, uint8_t *out)
{
    const __m128i wy0 = _mm_set1_epi16((short)(256 - fy)), wy1 = _mm_set1_epi16((short)fy);
    const __m128i z = _mm_setzero_si128(), w256 = _mm_set1_epi16(256);
    const __m128i opaque = _mm_set1_epi32((int)0xFF000000u);
    const int32_t *ixs = cols->ix + c, *fxs = cols->fx + c;
    int i = 0;
    for (; i + 4 <= n; i += 4) {
        uint32_t ta[4], tb[4], tc[4], td[4];
        __m128i a, b, cc, d, vv, fx, fl, fh, rl, rh;
        int k;
        for (k = 0; k < 4; k++) {
            const int ix = ixs[i + k], ix1 = ix + 1 < sw ? ix + 1 : sw - 1;
            ta[k] = load_u32(q0 + 4 * ix);
            tb[k] = load_u32(q0 + 4 * ix1);
            tc[k] = load_u32(q1 + 4 * ix);
            td[k] = load_u32(q1 + 4 * ix1);
        }
        a = _mm_loadu_si128((const __m128i *)(const void *)ta);
        b = _mm_loadu_si128((const __m128i *)(const void *)tb);
        cc = _mm_loadu_si128((const __m128i *)(const void *)tc);
        d = _mm_loadu_si128((const __m128i *)(const void *)td);
        vv = _mm_loadu_si128((const __m128i *)(const void *)(v + 4 * i));
        if (_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_or_si128(_mm_or_si128(a, b), _mm_or_si128(cc, d)), z)) == 0xFFFF) {
            _mm_storeu_si128((__m128i *)(void *)(out + 4 * i), _mm_or_si128(vv, opaque));
            continue;
        }
        fx = _mm_loadu_si128((const __m128i *)(const void *)(fxs + i));
        fl = _mm_unpacklo_epi32(fx, fx);
        fl = _mm_or_si128(fl, _mm_slli_epi32(fl, 16));
        fh = _mm_unpackhi_epi32(fx, fx);
        fh = _mm_or_si128(fh, _mm_slli_epi32(fh, 16));
        rl = blend16(_mm_unpacklo_epi8(a, z), _mm_unpacklo_epi8(b, z), _mm_unpacklo_epi8(cc, z),
                     _mm_unpacklo_epi8(d, z), _mm_unpacklo_epi8(vv, z),
                     _mm_sub_epi16(w256, fl), fl, wy0, wy1);
        rh = blend16(_mm_unpackhi_epi8(a, z), _mm_unpackhi_epi8(b, z), _mm_unpackhi_epi8(cc, z),
                     _mm_unpackhi_epi8(d, z), _mm_unpackhi_epi8(vv, z),
                     _mm_sub_epi16(w256, fh), fh, wy0, wy1);
        _mm_storeu_si128((__m128i *)(void *)(out + 4 * i),
                         _mm_or_si128(_mm_packus_epi16(rl, rh), opaque));
    }
    for (; i < n; i++)
        fuse__composite_px(q0, q1, fy, ixs[i], (uint32_t)fxs[i], sw, v + 4 * i, out + 4 * i);
}

#else  /* no SSE2 (e.g. ARM): the reference kernels */

#define FUSE_STUB(name) name##_sse2
#define FUSE_YUV_ON_LAYER 1
#include "fuse_stub.inl"

void fuse__composite_cols_sse2(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                               const fuse__cols *cols, int c, int n, int sw,
                               const uint8_t *v, uint8_t *out)
{
    fuse__composite_cols_ref(q0, q1, fy, cols, c, n, sw, v, out);
}
#endif
