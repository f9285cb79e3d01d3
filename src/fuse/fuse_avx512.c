/* fuse_avx512.c - AVX-512 (F, BW, DQ, VL) path of the fuse kernels, built
 * with the flags of *_avx512.c and called only when cpuid reports them.
 * The bytes are the reference's (docs/fuse.md, "Rounding rules");
 * tests/test_fuse_isa.c checks it.
 * Lighting: 16 pixels per vector (fuse_body.inl), lane masks in k
 * registers. Composite through the row cache (fuse__hrow_avx512 once per
 * layer row, fuse__vrow_avx512 per output row; fuse_internal.h): taps from
 * a window of 16 source pixels per row (vpermd) when it holds them all,
 * else vpgatherdd. Depth test: 16 pixels a step, the scene gathered. */
#include "fuse_internal.h"

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__)
#include <immintrin.h>

#define LANES 16
#define VF __m512
#define VI __m512i
#define VM __mmask16
#define F1(c) _mm512_set1_ps(c)
#define I1(c) _mm512_set1_epi32(c)
#define FADD(a, b) _mm512_add_ps(a, b)
#define FSUB(a, b) _mm512_sub_ps(a, b)
#define FMUL(a, b) _mm512_mul_ps(a, b)
#define FDIV(a, b) _mm512_div_ps(a, b)
#define FSQRT(a) _mm512_sqrt_ps(a)
#define FNEG(a) _mm512_xor_ps(a, _mm512_set1_ps(-0.0f))
#define FMAX0(a) _mm512_max_ps(a, _mm512_setzero_ps())
#define FMIN1(a) _mm512_min_ps(a, _mm512_set1_ps(1.0f))
#define FGT(a, b) _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ)
#define FGE(a, b) _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ)
#define FLT(a, b) _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ)
#define MAND(a, b) ((__mmask16)((a) & (b)))
#define FSEL(m, a, b) _mm512_mask_blend_ps(m, b, a)
#define FZERO_UNLESS(m, a) _mm512_maskz_mov_ps(m, a)
#define FFLOOR(a) _mm512_roundscale_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)
#define I2F(i) _mm512_cvtepi32_ps(i)
#define F2I_TRUNC(f) _mm512_cvttps_epi32(f)
#define FBITS(f) _mm512_castps_si512(f)
#define IBITS(i) _mm512_castsi512_ps(i)
#define IADD(a, b) _mm512_add_epi32(a, b)
#define ISUB(a, b) _mm512_sub_epi32(a, b)
#define IAND(a, b) _mm512_and_si512(a, b)
#define IOR(a, b) _mm512_or_si512(a, b)
#define ISRL(a, k) _mm512_srli_epi32(a, k)
#define ISLL(a, k) _mm512_slli_epi32(a, k)
#define LANE_INDEX _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15)
#define MASK_ZERO(p) mask_zero16(p)
#define LOAD_MASK(p) _mm512_cvtepu8_epi32(_mm_loadu_si128((const __m128i *)(const void *)(p)))
#define LOAD_RGBA(p) _mm512_loadu_si512((const void *)(p))
#define LOAD_NORMALS(p, x, y, z) load_normals(p, &(x), &(y), &(z))
#define STORE_RGBA(p, v) _mm512_storeu_si512((void *)(p), v)
#define STORE_ZERO(p) _mm512_storeu_si512((void *)(p), _mm512_setzero_si512())
#define IZERO_IF_EQ0(m, v) _mm512_maskz_mov_epi32(_mm512_test_epi32_mask(m, m), v)
#define LIGHT_ROW_NAME fuse__light_row_avx512
#define POW_ROW_NAME fuse__pow01_row_avx512
#define LOADF(p) _mm512_loadu_ps(p)
#define STOREF(p, v) _mm512_storeu_ps(p, v)

static inline int mask_zero16(const uint8_t *p)
{
    uint64_t a, b;
    memcpy(&a, p, 8);
    memcpy(&b, p + 8, 8);
    return (a | b) == 0;
}

/* 16 interleaved xyz normals -> x, y, z: element k of component c is at
 * g = 3k + c; two vpermt2ps pick g < 32 from the first two loads, then the
 * rest from the third. */
static inline void load_normals(const float *p, __m512 *x, __m512 *y, __m512 *z)
{
    const __m512 m0 = _mm512_loadu_ps(p), m1 = _mm512_loadu_ps(p + 16),
                 m2 = _mm512_loadu_ps(p + 32);
    const __m512i x1 = _mm512_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0);
    const __m512i x2 = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29);
    const __m512i y1 = _mm512_setr_epi32(1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0);
    const __m512i y2 = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30);
    const __m512i z1 = _mm512_setr_epi32(2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0);
    const __m512i z2 = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31);
    *x = _mm512_permutex2var_ps(_mm512_permutex2var_ps(m0, x1, m1), x2, m2);
    *y = _mm512_permutex2var_ps(_mm512_permutex2var_ps(m0, y1, m1), y2, m2);
    *z = _mm512_permutex2var_ps(_mm512_permutex2var_ps(m0, z1, m1), z2, m2);
}

#include "fuse_body.inl"

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

/* ---- coverage bits and opaque copies (fuse_internal.h) ----------------- */

void fuse__cover_row_avx512(const uint8_t *q, int w, uint64_t *bits)
{
    const int nb = (w + 7) / 8, pairs = w / 16;
    int k, b;
    memset(bits, 0, 8u * (size_t)((nb + 63) / 64));
    for (k = 0; k < pairs; k++) {   /* blocks 2k and 2k + 1: qwords 0-3 and 4-7 */
        const __m512i t = _mm512_loadu_si512((const void *)(q + 64 * (size_t)k));
        const unsigned m = _mm512_test_epi64_mask(t, t);
        const uint64_t two = (uint64_t)((m & 15u) != 0) | ((uint64_t)((m >> 4) != 0) << 1);
        bits[k >> 5] |= two << (2 * (k & 31));
    }
    for (b = 2 * pairs; b < nb; b++) {
        const int x1 = 8 * b + 8 < w ? 8 * b + 8 : w;
        uint32_t acc = 0, t;
        int x;
        for (x = 8 * b; x < x1; x++) {
            memcpy(&t, q + 4 * (size_t)x, 4);
            acc |= t;
        }
        if (acc) bits[b >> 6] |= (uint64_t)1 << (b & 63);
    }
}

void fuse__opaque_avx512(const uint8_t *v, uint8_t *out, int n)
{
    const __m512i a = _mm512_set1_epi32((int)0xFF000000u);
    int i = 0;
    if (v == out) {
        for (; i + 16 <= n; i += 16) {
            const __m512i x = _mm512_loadu_si512((const void *)(v + 4 * (size_t)i));
            const __mmask16 low = _mm512_cmpneq_epi32_mask(_mm512_and_si512(x, a), a);
            if (low)   /* some alpha below 255 */
                _mm512_storeu_si512((void *)(out + 4 * (size_t)i), _mm512_or_si512(x, a));
        }
        if (i < n) {   /* the last n - i < 16 pixels, masked (no access beyond them) */
            const __mmask16 k = (__mmask16)((1u << (n - i)) - 1u);
            const __m512i x = _mm512_maskz_loadu_epi32(k, (const void *)(v + 4 * (size_t)i));
            const __mmask16 low = _mm512_mask_cmpneq_epi32_mask(k, _mm512_and_si512(x, a), a);
            if (low)
                _mm512_mask_storeu_epi32((void *)(out + 4 * (size_t)i), k, _mm512_or_si512(x, a));
        }
        return;
    } else {
        for (; i + 32 <= n; i += 32) {
            const __m512i x0 = _mm512_loadu_si512((const void *)(v + 4 * (size_t)i));
            const __m512i x1 = _mm512_loadu_si512((const void *)(v + 4 * (size_t)i + 64));
            _mm512_storeu_si512((void *)(out + 4 * (size_t)i), _mm512_or_si512(x0, a));
            _mm512_storeu_si512((void *)(out + 4 * (size_t)i + 64), _mm512_or_si512(x1, a));
        }
    }
    fuse__opaque_ref(v + 4 * (size_t)i, out + 4 * (size_t)i, n - i);
}

/* ---- depth test (fuse__depth_span_ref, 16 pixels a step) ---------------- */

/* The row on the layer (bpp 4: a pixel is looked at when it is not 0) or
 * on mask bytes (bpp 1: when its byte is not 0); hidden pixels are zeroed. */
static inline __attribute__((always_inline)) void depth_row(const fuse__depth_prep *p, uint8_t *q,
                                                            const float *hz, const float *sc,
                                                            int w, int bpp)
{
    const __m512 zero = _mm512_setzero_ps(), one = _mm512_set1_ps(1.0f), two = _mm512_set1_ps(2.0f);
    const __m512 two_fn = _mm512_set1_ps(p->two_fn), fpn = _mm512_set1_ps(p->fpn);
    const __m512 fmn = _mm512_set1_ps(p->fmn), off = _mm512_set1_ps(p->offset);
    /* the column walk of 16 lanes, stepped by 16 pixels: 32 vw = sq den + sr */
    const int32_t step = 32 * p->vw;
    const __m512i den = _mm512_set1_epi32(p->den), sq = _mm512_set1_epi32(step / p->den);
    const __m512i sr = _mm512_set1_epi32(step % p->den), one_i = _mm512_set1_epi32(1);
    int32_t ox0[16], rem0[16];
    __m512i ox, rem;
    int x, k;
    if (w < 16) {
        if (bpp == 4) fuse__depth_span_ref(p, q, hz, sc, 0, w);
        else fuse__depth_mspan_ref(p, q, hz, sc, 0, w);
        return;
    }
    for (k = 0; k < 16; k++) fuse__depth_col(p, k, &ox0[k], &rem0[k]);
    ox = _mm512_loadu_si512((const void *)ox0);
    rem = _mm512_loadu_si512((const void *)rem0);
    for (x = 0; x + 16 <= w; x += 16) {
        __mmask16 nz;
        if (bpp == 4) {
            const __m512i qq = _mm512_loadu_si512((const void *)(q + 4 * (size_t)x));
            nz = _mm512_test_epi32_mask(qq, qq);
        } else {
            const __m128i mm = _mm_loadu_si128((const __m128i *)(const void *)(q + x));
            nz = _mm_test_epi8_mask(mm, mm);
        }
        if (nz) {
            const __m512 z = _mm512_loadu_ps(hz + x);
            const __mmask16 has = _mm512_mask_cmp_ps_mask(_mm512_mask_cmp_ps_mask(nz, z, zero, _CMP_GE_OQ),
                                                          z, one, _CMP_LT_OQ);
            if (has) {
                /* the scene values: when the 16 columns lie in a window of 32
                 * (always when the layer is enlarged), two loads of the window
                 * (masked to the viewport's width: nothing beyond it is read)
                 * and vpermt2ps; otherwise a gather. Lanes outside has are
                 * never used. */
                const int32_t c0 = _mm_cvtsi128_si32(_mm512_castsi512_si128(ox));
                const int32_t c15 = _mm_extract_epi32(_mm512_extracti32x4_epi32(ox, 3), 3);
                __m512 s;
                if (c15 - c0 < 32) {
                    const int32_t left = p->vw - c0;
                    const __mmask16 k0 = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
                    const __mmask16 k1 = left >= 32 ? (__mmask16)0xFFFF
                                         : left <= 16 ? (__mmask16)0 : (__mmask16)((1u << (left - 16)) - 1u);
                    const __m512 lo = _mm512_maskz_loadu_ps(k0, sc + c0);
                    const __m512 hi = _mm512_maskz_loadu_ps(k1, sc + c0 + 16);
                    s = _mm512_permutex2var_ps(lo, _mm512_sub_epi32(ox, _mm512_set1_epi32(c0)), hi);
                } else {
                    s = _mm512_mask_i32gather_ps(zero, has, ox, sc, 4);
                }
                const __m512 dist = _mm512_add_ps(
                    _mm512_div_ps(two_fn, _mm512_sub_ps(fpn, _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(two, z), one), fmn))),
                    off);
                const __mmask16 kill = _mm512_mask_cmp_ps_mask(_mm512_mask_cmp_ps_mask(has, s, zero, _CMP_GT_OQ),
                                                               s, dist, _CMP_LT_OQ);
                if (kill) {
                    if (bpp == 4)
                        _mm512_mask_storeu_epi32((void *)(q + 4 * (size_t)x), kill, _mm512_setzero_si512());
                    else
                        _mm_mask_storeu_epi8((void *)(q + x), kill, _mm_setzero_si128());
                }
            }
        }
        rem = _mm512_add_epi32(rem, sr);
        {
            const __mmask16 carry = _mm512_cmpge_epi32_mask(rem, den);
            rem = _mm512_mask_sub_epi32(rem, carry, rem, den);
            ox = _mm512_add_epi32(ox, sq);
            ox = _mm512_mask_add_epi32(ox, carry, ox, one_i);
        }
    }
    if (bpp == 4) fuse__depth_span_ref(p, q, hz, sc, x, w);
    else fuse__depth_mspan_ref(p, q, hz, sc, x, w);
}

void fuse__depth_row_avx512(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                            const float *sc, int w)
{
    depth_row(p, q, hz, sc, w, 4);
}

void fuse__depth_mrow_avx512(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                             const float *sc, int w)
{
    depth_row(p, m, hz, sc, w, 1);
}

#else  /* not built for AVX-512: never chosen by cpuid, falls back */

void fuse__light_row_avx512(const fuse__light_prep *p, int y, int width,
                            const uint8_t *P, const uint8_t *mask,
                            const float *normal, uint8_t *out)
{
    fuse__light_row_ref(p, y, width, P, mask, normal, out);
}

void fuse__depth_row_avx512(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                            const float *sc, int w)
{
    fuse__depth_row_ref(p, q, hz, sc, w);
}
void fuse__depth_mrow_avx512(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                             const float *sc, int w)
{
    fuse__depth_mrow_ref(p, m, hz, sc, w);
}
void fuse__pow01_row_avx512(const float *x, int n, float s, float *out)
{
    int i;
    for (i = 0; i < n; i++) out[i] = fuse__pow01(x[i], s);
}
void fuse__cover_row_avx512(const uint8_t *q, int w, uint64_t *bits)
{
    fuse__cover_row_ref(q, w, bits);
}
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
void fuse__opaque_avx512(const uint8_t *v, uint8_t *out, int n)
{
    fuse__opaque_ref(v, out, n);
}
#endif
