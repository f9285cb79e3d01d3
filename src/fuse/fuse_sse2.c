/* fuse_sse2.c - the portable SIMD path of the fuse kernels: SSE2, the
 * x86-64 baseline (no flags needed). The bytes are the reference's
 * (docs/fuse.md, "Rounding rules"); tests/test_fuse_isa.c checks it.
 * Lighting: 4 pixels per vector (fuse_body.inl); SSE2 has no floor
 * instruction, so floorf is the exact truncate-and-correct below.
 * Composite: 4 output pixels per step, taps loaded one by one, blend and
 * over in 16-bit lanes (the exact decomposition at blend16). Depth test:
 * 4 pixels a step, the scene loaded lane by lane (no gather in SSE2).
 * On a machine without SSE2 (ARM) the reference kernels stand in. */
#include "fuse_internal.h"

#if defined(__SSE2__)
#include <emmintrin.h>

/* floorf for |a| < 2^31 (the pow01 argument lies in [-126, 1]): truncate,
 * then subtract 1 where that rounded up. Exact; never gives -0 where
 * floorf gives +0 for the values that occur (y + 0.5 is never -0). */
static inline __m128 floor_sse2(__m128 a)
{
    const __m128 t = _mm_cvtepi32_ps(_mm_cvttps_epi32(a));
    return _mm_sub_ps(t, _mm_and_ps(_mm_cmpgt_ps(t, a), _mm_set1_ps(1.0f)));
}

static inline __m128 sel_sse2(__m128 m, __m128 a, __m128 b)
{
    return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b));
}

static inline uint32_t load_u32(const uint8_t *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}

#define LANES 4
#define VF __m128
#define VI __m128i
#define VM __m128
#define F1(c) _mm_set1_ps(c)
#define I1(c) _mm_set1_epi32(c)
#define FADD(a, b) _mm_add_ps(a, b)
#define FSUB(a, b) _mm_sub_ps(a, b)
#define FMUL(a, b) _mm_mul_ps(a, b)
#define FDIV(a, b) _mm_div_ps(a, b)
#define FSQRT(a) _mm_sqrt_ps(a)
#define FNEG(a) _mm_xor_ps(a, _mm_set1_ps(-0.0f))
#define FMAX0(a) _mm_max_ps(a, _mm_setzero_ps())
#define FMIN1(a) _mm_min_ps(a, _mm_set1_ps(1.0f))
#define FGT(a, b) _mm_cmpgt_ps(a, b)
#define FGE(a, b) _mm_cmpge_ps(a, b)
#define FLT(a, b) _mm_cmplt_ps(a, b)
#define MAND(a, b) _mm_and_ps(a, b)
#define FSEL(m, a, b) sel_sse2(m, a, b)
#define FZERO_UNLESS(m, a) _mm_and_ps(m, a)
#define FFLOOR(a) floor_sse2(a)
#define I2F(i) _mm_cvtepi32_ps(i)
#define F2I_TRUNC(f) _mm_cvttps_epi32(f)
#define FBITS(f) _mm_castps_si128(f)
#define IBITS(i) _mm_castsi128_ps(i)
#define IADD(a, b) _mm_add_epi32(a, b)
#define ISUB(a, b) _mm_sub_epi32(a, b)
#define IAND(a, b) _mm_and_si128(a, b)
#define IOR(a, b) _mm_or_si128(a, b)
#define ISRL(a, k) _mm_srli_epi32(a, k)
#define ISLL(a, k) _mm_slli_epi32(a, k)
#define LANE_INDEX _mm_setr_epi32(0, 1, 2, 3)
#define MASK_ZERO(p) (load_u32(p) == 0)
#define LOAD_MASK(p) _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128((int)load_u32(p)), \
                         _mm_setzero_si128()), _mm_setzero_si128())
#define LOAD_RGBA(p) _mm_loadu_si128((const __m128i *)(const void *)(p))
#define LOAD_NORMALS(p, x, y, z) do { const float *q_ = (p); \
        (x) = _mm_setr_ps(q_[0], q_[3], q_[6], q_[9]); \
        (y) = _mm_setr_ps(q_[1], q_[4], q_[7], q_[10]); \
        (z) = _mm_setr_ps(q_[2], q_[5], q_[8], q_[11]); } while (0)
#define STORE_RGBA(p, v) _mm_storeu_si128((__m128i *)(void *)(p), v)
#define STORE_ZERO(p) _mm_storeu_si128((__m128i *)(void *)(p), _mm_setzero_si128())
#define IZERO_IF_EQ0(m, v) _mm_andnot_si128(_mm_cmpeq_epi32(m, _mm_setzero_si128()), v)
#define LIGHT_ROW_NAME fuse__light_row_sse2
#define POW_ROW_NAME fuse__pow01_row_sse2
#define LOADF(p) _mm_loadu_ps(p)
#define STOREF(p, v) _mm_storeu_ps(p, v)

#include "fuse_body.inl"

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

/* ---- coverage bits and opaque copies (fuse_internal.h) ----------------- */

void fuse__cover_row_sse2(const uint8_t *q, int w, uint64_t *bits)
{
    const __m128i z = _mm_setzero_si128();
    const int nb = (w + 7) / 8, full = w / 8;
    int b;
    memset(bits, 0, 8u * (size_t)((nb + 63) / 64));
    for (b = 0; b < full; b++) {
        const __m128i t = _mm_or_si128(_mm_loadu_si128((const __m128i *)(const void *)(q + 32 * (size_t)b)),
                                       _mm_loadu_si128((const __m128i *)(const void *)(q + 32 * (size_t)b + 16)));
        bits[b >> 6] |= (uint64_t)(_mm_movemask_epi8(_mm_cmpeq_epi8(t, z)) != 0xFFFF) << (b & 63);
    }
    if (full < nb) {
        uint32_t acc = 0;
        int x;
        for (x = 8 * full; x < w; x++) acc |= load_u32(q + 4 * (size_t)x);
        if (acc) bits[full >> 6] |= (uint64_t)1 << (full & 63);
    }
}

void fuse__opaque_sse2(const uint8_t *v, uint8_t *out, int n)
{
    const __m128i a = _mm_set1_epi32((int)0xFF000000u);
    int i = 0;
    if (v == out) {
        for (; i + 4 <= n; i += 4) {
            const __m128i x = _mm_loadu_si128((const __m128i *)(const void *)(v + 4 * (size_t)i));
            const __m128i y = _mm_or_si128(x, a);
            if (_mm_movemask_epi8(_mm_cmpeq_epi32(x, y)) != 0xFFFF)
                _mm_storeu_si128((__m128i *)(void *)(out + 4 * (size_t)i), y);
        }
    } else {
        for (; i + 8 <= n; i += 8) {
            const __m128i x0 = _mm_loadu_si128((const __m128i *)(const void *)(v + 4 * (size_t)i));
            const __m128i x1 = _mm_loadu_si128((const __m128i *)(const void *)(v + 4 * (size_t)i + 16));
            _mm_storeu_si128((__m128i *)(void *)(out + 4 * (size_t)i), _mm_or_si128(x0, a));
            _mm_storeu_si128((__m128i *)(void *)(out + 4 * (size_t)i + 16), _mm_or_si128(x1, a));
        }
    }
    fuse__opaque_ref(v + 4 * (size_t)i, out + 4 * (size_t)i, n - i);
}

/* ---- depth test (fuse__depth_span_ref, 4 pixels a step) ----------------- */

/* The row on the layer (bpp 4: a pixel is looked at when it is not 0) or
 * on mask bytes (bpp 1: when its byte is not 0); hidden pixels are zeroed. */
static inline __attribute__((always_inline)) void depth_row(const fuse__depth_prep *p, uint8_t *q,
                                                            const float *hz, const float *sc,
                                                            int w, int bpp)
{
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), two = _mm_set1_ps(2.0f);
    const __m128 two_fn = _mm_set1_ps(p->two_fn), fpn = _mm_set1_ps(p->fpn);
    const __m128 fmn = _mm_set1_ps(p->fmn), off = _mm_set1_ps(p->offset);
    const __m128i zi = _mm_setzero_si128();
    int32_t ox, rem;   /* column of pixel x */
    int x = 0, k;
    fuse__depth_col(p, 0, &ox, &rem);
    for (; x + 4 <= w; x += 4) {
        __m128i qq;
        int32_t c[4];
        for (k = 0; k < 4; k++) {   /* the columns of the 4 pixels, and on */
            c[k] = ox;
            ox += p->step_q;
            rem += p->step_r;
            if (rem >= p->den) {
                rem -= p->den;
                ox++;
            }
        }
        if (bpp == 4)
            qq = _mm_loadu_si128((const __m128i *)(const void *)(q + 4 * (size_t)x));
        else
            qq = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128((int)load_u32(q + x)), zi), zi);
        if (_mm_movemask_epi8(_mm_cmpeq_epi32(qq, zi)) != 0xFFFF) {
            const __m128 nz = _mm_castsi128_ps(_mm_xor_si128(_mm_cmpeq_epi32(qq, zi), _mm_set1_epi32(-1)));
            const __m128 z = _mm_loadu_ps(hz + x);
            const __m128 has = _mm_and_ps(nz, _mm_and_ps(_mm_cmpge_ps(z, zero), _mm_cmplt_ps(z, one)));
            const int hm = _mm_movemask_ps(has);
            if (hm) {
                const __m128 s = _mm_setr_ps((hm & 1) ? sc[c[0]] : 0.0f, (hm & 2) ? sc[c[1]] : 0.0f,
                                             (hm & 4) ? sc[c[2]] : 0.0f, (hm & 8) ? sc[c[3]] : 0.0f);
                const __m128 dist = _mm_add_ps(
                    _mm_div_ps(two_fn, _mm_sub_ps(fpn, _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(two, z), one), fmn))),
                    off);
                const __m128 kill = _mm_and_ps(has, _mm_and_ps(_mm_cmpgt_ps(s, zero), _mm_cmplt_ps(s, dist)));
                const int km = _mm_movemask_ps(kill);
                if (km && bpp == 4)   /* the row is this thread's: rewrite the rest */
                    _mm_storeu_si128((__m128i *)(void *)(q + 4 * (size_t)x),
                                     _mm_andnot_si128(_mm_castps_si128(kill), qq));
                else if (km) {
                    for (k = 0; k < 4; k++)
                        if (km >> k & 1) q[x + k] = 0;
                }
            }
        }
    }
    if (bpp == 4) fuse__depth_span_ref(p, q, hz, sc, x, w);
    else fuse__depth_mspan_ref(p, q, hz, sc, x, w);
}

void fuse__depth_row_sse2(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                          const float *sc, int w)
{
    depth_row(p, q, hz, sc, w, 4);
}

void fuse__depth_mrow_sse2(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                           const float *sc, int w)
{
    depth_row(p, m, hz, sc, w, 1);
}

#else  /* no SSE2 (e.g. ARM): the reference kernels */

void fuse__light_row_sse2(const fuse__light_prep *p, int y, int width,
                          const uint8_t *P, const uint8_t *mask,
                          const float *normal, uint8_t *out)
{
    fuse__light_row_ref(p, y, width, P, mask, normal, out);
}

void fuse__composite_cols_sse2(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                               const fuse__cols *cols, int c, int n, int sw,
                               const uint8_t *v, uint8_t *out)
{
    fuse__composite_cols_ref(q0, q1, fy, cols, c, n, sw, v, out);
}
void fuse__depth_row_sse2(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                          const float *sc, int w)
{
    fuse__depth_row_ref(p, q, hz, sc, w);
}
void fuse__depth_mrow_sse2(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                           const float *sc, int w)
{
    fuse__depth_mrow_ref(p, m, hz, sc, w);
}
void fuse__pow01_row_sse2(const float *x, int n, float s, float *out)
{
    int i;
    for (i = 0; i < n; i++) out[i] = fuse__pow01(x[i], s);
}
void fuse__cover_row_sse2(const uint8_t *q, int w, uint64_t *bits)
{
    fuse__cover_row_ref(q, w, bits);
}
void fuse__opaque_sse2(const uint8_t *v, uint8_t *out, int n)
{
    fuse__opaque_ref(v, out, n);
}
#endif
