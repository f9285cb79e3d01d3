/* fuse_refine_avx2.c - AVX2 row kernels of the band-only refinement
 * (fuse_refine_kern.h), built with the flags of *_avx2.c and chosen only
 * when cpuid reports AVX2. Same bytes as the reference
 * (tests/test_fuse_refine.c). Whole vectors inside the row; the few
 * pixels at a row's ends (and the histogram, the running minimum of the
 * chamfer passes) go through the portable kernels, which give the same
 * values:
 *   edges      32 mask pixels per step as bit masks (vpmovmskb);
 *   chamfer    the vertical minimum 16 distances per step;
 *   scores     8 per step: bins in lanes, look-ups by vgatherdps;
 *   decision   8 per step, the window sum in the reference's order. */
#include "fuse_refine_kern.h"

#if defined(__AVX2__)
#include <immintrin.h>

#define KC fuse__refine_kern_c

static inline uint32_t in_bits(const uint8_t *p)
{
    return (uint32_t)_mm256_movemask_epi8(_mm256_loadu_si256((const __m256i *)(const void *)p));
}

/* Edge bits of the 32 pixels at x; needs 1 <= x and x + 32 < w. */
static inline uint32_t edge_bits(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                 int x)
{
    const uint32_t m = in_bits(row + x), l = in_bits(row + x - 1), r = in_bits(row + x + 1);
    const uint32_t u = in_bits(up + x), d = in_bits(dn + x);
    return (m ^ l) | (m ^ r) | (m ^ u) | (m ^ d);
}

static int edge_span_avx2(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                          int *x0, int *x1)
{
    int a = -1, b = -1;
    for (int x = 0; x < w;) {
        if (x >= 1 && x + 32 < w) {
            const uint32_t e = edge_bits(up, row, dn, x);
            if (e) { a = x + __builtin_ctz(e); break; }
            x += 32;
        } else {
            if (fuse__refine_edge_at(up, row, dn, w, x)) { a = x; break; }
            x++;
        }
    }
    if (a < 0) return 0;
    for (int x = w - 1; x >= a;) {
        if (x - 31 >= 1 && x + 1 < w) {
            const uint32_t e = edge_bits(up, row, dn, x - 31);
            if (e) { b = x - __builtin_clz(e); break; }
            x -= 32;
        } else {
            if (fuse__refine_edge_at(up, row, dn, w, x)) { b = x; break; }
            x--;
        }
    }
    *x0 = a;
    *x1 = b;
    return 1;
}

static void dt_init_avx2(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                         int a, int b, uint16_t cap, uint16_t *d)
{
    const __m256i vcap = _mm256_set1_epi16((short)cap), v3 = _mm256_set1_epi16(3);
    const __m256i bit = _mm256_setr_epi16(1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048,
                                          4096, 8192, 16384, (short)-32768);
    int x = a;
    if (x < 1) {   /* pixel 0: no left neighbour */
        KC.dt_init(up, row, dn, w, 0, 0, cap, d);
        x = 1;
    }
    for (; x + 31 <= b && x + 32 < w; x += 32) {
        const uint32_t e = edge_bits(up, row, dn, x);
        for (int h = 0; h < 2; h++) {
            const __m256i eb = _mm256_set1_epi16((short)(uint16_t)(e >> (16 * h)));
            const __m256i sel = _mm256_cmpeq_epi16(_mm256_and_si256(eb, bit), bit);
            _mm256_storeu_si256((__m256i *)(void *)(d + x + 16 * h),
                                _mm256_blendv_epi8(vcap, v3, sel));
        }
    }
    if (x <= b) KC.dt_init(up, row, dn, w, x, b, cap, d);
}

/* min(r, v + 3, v[-1] + 4, v[+1] + 4) of 16 lanes at x (1 <= x, x + 16 < w) */
static inline void vert16(uint16_t *r, const uint16_t *v, int x)
{
    const __m256i three = _mm256_set1_epi16(3), four = _mm256_set1_epi16(4);
    __m256i m = _mm256_loadu_si256((const __m256i *)(const void *)(r + x));
    m = _mm256_min_epu16(m, _mm256_adds_epu16(
        _mm256_loadu_si256((const __m256i *)(const void *)(v + x)), three));
    m = _mm256_min_epu16(m, _mm256_adds_epu16(
        _mm256_loadu_si256((const __m256i *)(const void *)(v + x - 1)), four));
    m = _mm256_min_epu16(m, _mm256_adds_epu16(
        _mm256_loadu_si256((const __m256i *)(const void *)(v + x + 1)), four));
    _mm256_storeu_si256((__m256i *)(void *)(r + x), m);
}

/* the vertical part on [a, b]: vectors inside, the portable rule at the ends */
static void vert_row(uint16_t *r, const uint16_t *v, int w, int a, int b)
{
    int x = a;
    for (; x <= b && x < 1; x++) r[x] = fuse__refine_vert_px(r, v, w, x);
    for (; x + 15 <= b && x + 16 < w; x += 16) vert16(r, v, x);
    for (; x <= b; x++) r[x] = fuse__refine_vert_px(r, v, w, x);
}

static void dt_fwd_avx2(uint16_t *r, const uint16_t *u, int w, int a, int b)
{
    if (u) vert_row(r, u, w, a, b);
    KC.dt_fwd(r, NULL, w, a, b);   /* the running minimum */
}

static void dt_bwd_avx2(uint16_t *r, const uint16_t *dn, int w, int a, int b)
{
    if (dn) vert_row(r, dn, w, a, b);
    KC.dt_bwd(r, NULL, w, a, b);
}

static void hist_row_avx2(const uint8_t *px, const uint8_t *m, const uint16_t *d, int a,
                          int b, unsigned band3, unsigned outer3, int bits, uint32_t *hf,
                          uint32_t *hb, long *nf, long *nb)
{
    /* skip 16 distances at a time that hold no ring pixel */
    const __m256i lo = _mm256_set1_epi16((short)(band3 + 1u));
    const __m256i span = _mm256_set1_epi16((short)(outer3 - band3 - 1u));
    int x = a;
    while (x <= b) {
        if (x + 15 <= b) {
            const __m256i t = _mm256_sub_epi16(
                _mm256_loadu_si256((const __m256i *)(const void *)(d + x)), lo);
            /* t <= span unsigned  <=>  max(t, span) == span */
            const __m256i le = _mm256_cmpeq_epi16(_mm256_max_epu16(t, span), span);
            if (_mm256_testz_si256(le, le)) { x += 16; continue; }
            KC.hist_row(px, m, d, x, x + 15, band3, outer3, bits, hf, hb, nf, nb);
            x += 16;
        } else {
            KC.hist_row(px, m, d, x, b, band3, outer3, bits, hf, hb, nf, nb);
            break;
        }
    }
}

static inline __m256i bins8(const uint8_t *px, int bits)
{
    const __m256i v = _mm256_loadu_si256((const __m256i *)(const void *)px);
    const __m128i s = _mm_cvtsi32_si128(8 - bits);
    const __m256i ff = _mm256_set1_epi32(0xFF);
    const __m256i r = _mm256_srl_epi32(_mm256_and_si256(v, ff), s);
    const __m256i g = _mm256_srl_epi32(_mm256_and_si256(_mm256_srli_epi32(v, 8), ff), s);
    const __m256i bl = _mm256_srl_epi32(_mm256_and_si256(_mm256_srli_epi32(v, 16), ff), s);
    return _mm256_or_si256(_mm256_or_si256(_mm256_sll_epi32(r, _mm_cvtsi32_si128(2 * bits)),
                                           _mm256_sll_epi32(g, _mm_cvtsi32_si128(bits))),
                           bl);
}

static void score_row_avx2(const fuse__refine_tabs *t, const uint8_t *px, const uint8_t *m,
                           const uint16_t *d, float *s, int a, int b)
{
    const __m256i vb3 = _mm256_set1_epi32((int)t->band3), v127 = _mm256_set1_epi32(127);
    const __m256 p4 = _mm256_set1_ps(4.0f), n4 = _mm256_set1_ps(-4.0f);
    const __m256 w0 = _mm256_set1_ps(t->w0), gw = _mm256_set1_ps(t->gw);
    const __m256i off = _mm256_set1_epi32((int)(t->pr_out - t->pr_in));
    int x = a;
    for (; x + 7 <= b; x += 8) {
        const __m256i dv = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(d + x)));
        const __m256i mv = _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(const void *)(m + x)));
        const __m256i in = _mm256_cmpgt_epi32(mv, v127);
        const __m256i band = _mm256_xor_si256(_mm256_cmpgt_epi32(dv, vb3), _mm256_set1_epi32(-1));
        __m256 o = _mm256_blendv_ps(n4, p4, _mm256_castsi256_ps(in));
        if (!_mm256_testz_si256(band, band)) {
            const __m256 bm = _mm256_castsi256_ps(band);
            const __m256i bin = bins8(px + 4 * (size_t)x, t->bits);
            __m256 c = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), t->llr,
                                                _mm256_and_si256(bin, band), bm, 4);
            if (t->gllr) {
                const __m256i gbin = bins8(px + 4 * (size_t)x, t->gbits);
                const __m256 gc = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), t->gllr,
                                                           _mm256_and_si256(gbin, band), bm, 4);
                c = _mm256_add_ps(_mm256_mul_ps(w0, c), _mm256_mul_ps(gw, gc));
            }
            const __m256i pidx = _mm256_and_si256(
                _mm256_add_epi32(dv, _mm256_andnot_si256(in, off)), band);
            const __m256 pr = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), t->pr_in, pidx, bm, 4);
            o = _mm256_blendv_ps(o, _mm256_add_ps(c, pr), bm);
        }
        _mm256_storeu_ps(s + x, o);
    }
    if (x <= b) KC.score_row(t, px, m, d, s, x, b);
}

static void decide_row_avx2(const float *s, ptrdiff_t ss, int rad, const uint8_t *m,
                            const uint16_t *d, unsigned band3, uint8_t *out, int a, int b,
                            long cnt[3])
{
    const __m256i vb3 = _mm256_set1_epi32((int)band3);
    long nb = 0, fi = 0, fo = 0;
    int x = a;
    for (; x + 7 <= b; x += 8) {
        const __m256i dv = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)(d + x)));
        const unsigned band = 0xFFu & ~(unsigned)_mm256_movemask_ps(
                                            _mm256_castsi256_ps(_mm256_cmpgt_epi32(dv, vb3)));
        unsigned in = 0;
        for (int j = 0; j < 8; j++) in |= (unsigned)(m[x + j] >= 128) << j;
        unsigned v = in;
        if (band) {
            __m256 sum = _mm256_setzero_ps();
            for (int dy = -rad; dy <= rad; dy++) {
                const float *r = s + dy * ss + x;
                for (int dx = -rad; dx <= rad; dx++)
                    sum = _mm256_add_ps(sum, _mm256_loadu_ps(r + dx));
            }
            const unsigned pos = (unsigned)_mm256_movemask_ps(
                _mm256_cmp_ps(sum, _mm256_setzero_ps(), _CMP_GT_OQ));
            v = (in & ~band) | (pos & band);
            nb += __builtin_popcount(band);
            fi += __builtin_popcount(band & pos & ~in);
            fo += __builtin_popcount(band & ~pos & in & 0xFFu);
        }
        for (int j = 0; j < 8; j++) out[x + j] = (v >> j) & 1u ? 255 : 0;
    }
    cnt[0] += nb;
    cnt[1] += fi;
    cnt[2] += fo;
    if (x <= b) KC.decide_row(s, ss, rad, m, d, band3, out, x, b, cnt);
}

static void binarise_avx2(const uint8_t *m, uint8_t *out, int a, int b)
{
    const __m256i z = _mm256_setzero_si256();
    int x = a;
    for (; x + 31 <= b; x += 32) {
        const __m256i v = _mm256_loadu_si256((const __m256i *)(const void *)(m + x));
        _mm256_storeu_si256((__m256i *)(void *)(out + x), _mm256_cmpgt_epi8(z, v));
    }
    if (x <= b) KC.binarise(m, out, x, b);
}

static const fuse__refine_kern kern = {
    edge_span_avx2, dt_init_avx2, dt_fwd_avx2, dt_bwd_avx2, hist_row_avx2,
    score_row_avx2, decide_row_avx2, binarise_avx2,
};

const fuse__refine_kern *fuse__refine_kern_avx2(void) { return &kern; }

#else
const fuse__refine_kern *fuse__refine_kern_avx2(void) { return NULL; }
#endif
