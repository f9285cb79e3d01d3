/* fuse_refine_avx512.c - AVX-512 (F, BW, DQ, VL) row kernels of the
 * band-only refinement (fuse_refine_kern.h), built with the flags of
 * *_avx512.c and chosen only when cpuid reports them. Same bytes as the
 * reference (tests/test_fuse_refine.c). The scores and the colour bins
 * are fuse_refine_simd.inl on the vector layer (src/cpu/simd_avx512.h);
 * the other kernels are AVX-512's own (REFINE_OWN_ROWS), as the layer's
 * other ISAs cannot do them: every row end is one masked step (k
 * registers), and
 *   edges      64 mask pixels per step as bit masks (vpmovb2m), the four
 *              neighbours as shifted loads;
 *   chamfer    32 distances per step: the vertical minimum in lanes, the
 *              horizontal running minimum as a log-step scan (vpermw) on
 *              d - 3 lane (forward) or d + 3 lane (backward), exact in
 *              16-bit integers;
 *   histogram  ring pixels found 32 at a time as mask bits, bins computed
 *              16 at a time (refine_bins), counted in scalar;
 *   decision   16 per step: the window sum in the reference's order
 *              (rows top down, columns left to right), one float add per
 *              term per lane, as the reference adds them. */
#include "fuse_refine_kern.h"

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__) && \
    defined(__AVX512VL__)
#include "../cpu/simd_avx512.h"

#define REFINE_OWN_ROWS
#include "fuse_refine_simd.inl"

/* lanes [0, n) of a 64 / 32 / 16-lane mask (n may be <= 0 or >= lanes) */
static inline __mmask64 lanes64(int n)
{
    return n <= 0 ? 0 : n >= 64 ? ~(__mmask64)0 : (((__mmask64)1 << n) - 1);
}
static inline __mmask32 lanes32(int n)
{
    return n <= 0 ? 0 : n >= 32 ? ~(__mmask32)0 : (__mmask32)((1u << n) - 1u);
}
static inline __mmask16 lanes16(int n)
{
    return n <= 0 ? 0 : n >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << n) - 1u);
}

/* "inside" bits of 64 mask bytes at p, lanes in `valid` (others 0) */
static inline uint64_t in_bits(const uint8_t *p, __mmask64 valid)
{
    return (uint64_t)_mm512_movepi8_mask(_mm512_maskz_loadu_epi8(valid, p));
}

/* Edge bits of the 64 pixels at x (lanes past w are 0). */
static inline uint64_t edge_bits(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                 int w, int x)
{
    const __mmask64 valid = lanes64(w - x), rvalid = lanes64(w - x - 1);
    const uint64_t m = in_bits(row + x, valid);
    uint64_t l, r;
    if (x > 0) l = in_bits(row + x - 1, valid);
    else l = (m << 1) | (m & 1u);   /* pixel 0 has no left neighbour */
    r = in_bits(row + x + 1, rvalid);
    r = (r & (uint64_t)rvalid) | (m & ~(uint64_t)rvalid);
    const uint64_t u = in_bits(up + x, valid), d = in_bits(dn + x, valid);
    return ((m ^ l) | (m ^ r) | (m ^ u) | (m ^ d)) & (uint64_t)valid;
}

static int SIMD_FN(refine_edge_span)(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                            int *x0, int *x1)
{
    int a = -1;
    for (int x = 0; x < w; x += 64) {
        uint64_t e = edge_bits(up, row, dn, w, x);
        if (e) {
            a = x + (int)__builtin_ctzll(e);
            break;
        }
    }
    if (a < 0) return 0;
    const int last = (w - 1) & ~63;
    for (int x = last; x >= (a & ~63); x -= 64) {
        uint64_t e = edge_bits(up, row, dn, w, x);
        if (e) {
            *x1 = x + 63 - (int)__builtin_clzll(e);
            break;
        }
    }
    *x0 = a;
    return 1;
}

static void SIMD_FN(refine_dt_init)(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                           int a, int b, uint16_t cap, uint16_t *d)
{
    const __m512i vcap = _mm512_set1_epi16((short)cap), v3 = _mm512_set1_epi16(3);
    for (int x = a; x <= b; x += 64) {
        uint64_t e = edge_bits(up, row, dn, w, x);
        const __mmask64 st = lanes64(b + 1 - x);
        _mm512_mask_storeu_epi16(d + x, (__mmask32)st,
                                 _mm512_mask_blend_epi16((__mmask32)e, vcap, v3));
        if (b + 1 - x > 32)
            _mm512_mask_storeu_epi16(d + x + 32, (__mmask32)(st >> 32),
                                     _mm512_mask_blend_epi16((__mmask32)(e >> 32), vcap, v3));
    }
}

/* vpermw indices: lane j takes lane j - k (up) or j + k (down) */
static inline __m512i shift_idx(int k)
{
    short t[32];
    for (int j = 0; j < 32; j++) t[j] = (short)(j - k < 0 ? 0 : j - k > 31 ? 31 : j - k);
    return _mm512_loadu_si512(t);
}

#define BIG 30000

/* The vertical part of a chamfer row pass: min(r, v + 3, v[-1] + 4,
 * v[+1] + 4) over the 32 lanes at x (v: the neighbouring row). */
static inline __m512i vert_min(__m512i cur, const uint16_t *v, int w, int x, __mmask32 ld)
{
    const __m512i big = _mm512_set1_epi16(-1);   /* saturates: never the minimum */
    const __m512i c = _mm512_mask_loadu_epi16(big, ld, v + x);
    __m512i lv;
    if (x > 0) lv = _mm512_mask_loadu_epi16(big, ld, v + x - 1);
    else lv = _mm512_mask_permutexvar_epi16(big, ~(__mmask32)1, shift_idx(1), c);
    const __m512i rv = _mm512_mask_loadu_epi16(big, lanes32(w - x - 1) & ld, v + x + 1);
    const __m512i four = _mm512_set1_epi16(4), three = _mm512_set1_epi16(3);
    __m512i m = _mm512_min_epu16(cur, _mm512_adds_epu16(c, three));
    m = _mm512_min_epu16(m, _mm512_adds_epu16(lv, four));
    return _mm512_min_epu16(m, _mm512_adds_epu16(rv, four));
}

/* 3 * lane: 0, 3, ..., 93 */
static inline __m512i lane3(void)
{
    short l3[32];
    for (int j = 0; j < 32; j++) l3[j] = (short)(3 * j);
    return _mm512_loadu_si512(l3);
}

/* One step of run_min: lane j takes min(t[j], t[j - k]) (fwd) or
 * min(t[j], t[j + k]), through s = shift_idx(k) / shift_idx(-k); lanes
 * j - k < 0 / j + k > 31 take `big` (the masks are constants once
 * inlined). */
static inline __m512i run_step(__m512i t, __m512i big, __m512i s, int k, int fwd)
{
    const __mmask32 take = fwd ? (__mmask32)(0xFFFFFFFFu << k) : (__mmask32)(0xFFFFFFFFu >> k);
    return _mm512_min_epi16(t, _mm512_mask_permutexvar_epi16(big, take, s, t));
}

/* The inclusive running minimum over the 32 lanes of t, from lane 0 up
 * (fwd: lane j = min of lanes 0..j) or from lane 31 down (lane j = min of
 * lanes j..31), as a log-step scan in five steps k = 1, 2, 4, 8, 16;
 * s[i] = shift_idx(k) forward, shift_idx(-k) backward. Shared by both
 * chamfer passes (the same machine code as the two unrolled scans). */
static inline __m512i run_min(__m512i t, __m512i big, const __m512i s[5], int fwd)
{
    t = run_step(t, big, s[0], 1, fwd);
    t = run_step(t, big, s[1], 2, fwd);
    t = run_step(t, big, s[2], 4, fwd);
    t = run_step(t, big, s[3], 8, fwd);
    return run_step(t, big, s[4], 16, fwd);
}

/* The 32 lanes of row r at x after the vertical part of a pass (v: the
 * row above or below, NULL: none), lanes outside ld `big`. */
static inline __m512i pass_in(const uint16_t *r, const uint16_t *v, int w, int x, __mmask32 ld,
                              __m512i big)
{
    __m512i c = _mm512_mask_loadu_epi16(big, ld, r + x);
    if (v) c = vert_min(c, v, w, x, ld);
    return _mm512_mask_blend_epi16(ld, big, c);
}

static void SIMD_FN(refine_dt_fwd)(uint16_t *r, const uint16_t *u, int w, int a, int b)
{
    const __m512i l3 = lane3(), big = _mm512_set1_epi16(BIG);
    const __m512i s[5] = {shift_idx(1), shift_idx(2), shift_idx(4), shift_idx(8),
                          shift_idx(16)};
    int carry = BIG - 3;   /* r[a - 1] is the cap (or absent) */
    for (int x = a; x <= b; x += 32) {
        const __mmask32 ld = lanes32(b + 1 - x);
        const __m512i v = pass_in(r, u, w, x, ld, big);
        /* t = v - 3 lane; prefix minimum; the carry enters as r[x-1] + 3 */
        __m512i t = run_min(_mm512_sub_epi16(v, l3), big, s, 1);
        t = _mm512_min_epi16(t, _mm512_set1_epi16((short)(carry + 3)));
        _mm512_mask_storeu_epi16(r + x, ld, _mm512_add_epi16(t, l3));
        carry = (uint16_t)r[x + 31 < b ? x + 31 : b];
    }
}

static void SIMD_FN(refine_dt_bwd)(uint16_t *r, const uint16_t *dn, int w, int a, int b)
{
    const __m512i l3 = lane3(), big = _mm512_set1_epi16(BIG);
    const __m512i s[5] = {shift_idx(-1), shift_idx(-2), shift_idx(-4), shift_idx(-8),
                          shift_idx(-16)};
    const int n = (b - a) / 32;
    int carry = BIG - 96;   /* r[b + 1] is the cap (or absent) */
    for (int i = n; i >= 0; i--) {
        const int x = a + 32 * i;
        const __mmask32 ld = lanes32(b + 1 - x);
        const __m512i v = pass_in(r, dn, w, x, ld, big);
        /* t = v + 3 lane; suffix minimum; the carry at lane 32 enters as
         * r[x + 32] + 3 (32 - j) = (r[x + 32] + 96) - 3 j */
        __m512i t = run_min(_mm512_add_epi16(v, l3), big, s, 0);
        t = _mm512_min_epi16(t, _mm512_set1_epi16((short)(carry + 96)));
        _mm512_mask_storeu_epi16(r + x, ld, _mm512_sub_epi16(t, l3));
        carry = r[x];
    }
}

static void SIMD_FN(refine_hist_row)(const uint8_t *px, const uint8_t *m, const uint16_t *d, int a,
                            int b, unsigned band3, unsigned outer3, int bits, uint32_t *hf,
                            uint32_t *hb, long *nf, long *nb)
{
    const __m512i lo = _mm512_set1_epi16((short)(band3 + 1u));
    const __m512i span = _mm512_set1_epi16((short)(outer3 - band3 - 1u));
    long f = 0, g = 0;
    uint32_t bn[32];
    for (int x = a; x <= b; x += 32) {
        const __mmask32 ld = lanes32(b + 1 - x);
        const __m512i dv = _mm512_maskz_loadu_epi16(ld, d + x);
        /* band3 < d <= outer3  <=>  (d - band3 - 1) <= outer3 - band3 - 1, unsigned */
        __mmask32 ring = _mm512_mask_cmple_epu16_mask(ld, _mm512_sub_epi16(dv, lo), span);
        if (!ring) continue;
        const uint32_t in = (uint32_t)_mm256_movepi8_mask(
            _mm256_maskz_loadu_epi8(ld, m + x));
        const int32_t *p = (const int32_t *)(const void *)(px + 4 * (size_t)x);
        _mm512_storeu_si512(bn, SIMD_FN(refine_bins)(
                                    _mm512_maskz_loadu_epi32((__mmask16)ring, p), bits));
        _mm512_storeu_si512(bn + 16, SIMD_FN(refine_bins)(_mm512_maskz_loadu_epi32(
                                                              (__mmask16)(ring >> 16), p + 16),
                                                          bits));
        uint32_t rf = ring & in, rb = ring & ~in;
        f += __builtin_popcount(rf);
        g += __builtin_popcount(rb);
        while (rf) {
            hf[bn[__builtin_ctz(rf)]]++;
            rf &= rf - 1;
        }
        while (rb) {
            hb[bn[__builtin_ctz(rb)]]++;
            rb &= rb - 1;
        }
    }
    *nf += f;
    *nb += g;
}

static void SIMD_FN(refine_decide_row)(const float *s, ptrdiff_t ss, int rad, const uint8_t *m,
                              const uint16_t *d, unsigned band3, uint8_t *out, int a, int b,
                              long cnt[3])
{
    const __m512i vb3 = _mm512_set1_epi32((int)band3);
    const __m128i ff = _mm_set1_epi8((char)0xFF);
    long nb = 0, fi = 0, fo = 0;
    for (int x = a; x <= b; x += 16) {
        const __mmask16 ld = lanes16(b + 1 - x);
        const __mmask16 in = _mm_movepi8_mask(_mm_maskz_loadu_epi8(ld, m + x));
        const __m512i dv = _mm512_cvtepu16_epi32(_mm256_maskz_loadu_epi16(ld, d + x));
        const __mmask16 band = _mm512_mask_cmple_epu32_mask(ld, dv, vb3);
        __mmask16 v = in;
        if (band) {
            __m512 sum = _mm512_setzero_ps();
            for (int dy = -rad; dy <= rad; dy++) {
                const float *r = s + dy * ss + x;
                for (int dx = -rad; dx <= rad; dx++)
                    sum = _mm512_add_ps(sum, _mm512_maskz_loadu_ps(band, r + dx));
            }
            const __mmask16 pos = _mm512_cmp_ps_mask(sum, _mm512_setzero_ps(), _CMP_GT_OQ);
            v = (__mmask16)((in & ~band) | (pos & band));
            nb += __builtin_popcount(band);
            fi += __builtin_popcount(band & pos & ~in);
            fo += __builtin_popcount(band & ~pos & in);
        }
        _mm_mask_storeu_epi8(out + x, ld, _mm_maskz_mov_epi8(v, ff));
    }
    cnt[0] += nb;
    cnt[1] += fi;
    cnt[2] += fo;
}

static void SIMD_FN(refine_binarise)(const uint8_t *m, uint8_t *out, int a, int b)
{
    const __m512i ff = _mm512_set1_epi8((char)0xFF);
    for (int x = a; x <= b; x += 64) {
        const __mmask64 ld = lanes64(b + 1 - x);
        const __mmask64 in = _mm512_movepi8_mask(_mm512_maskz_loadu_epi8(ld, m + x));
        _mm512_mask_storeu_epi8(out + x, ld, _mm512_maskz_mov_epi8(in, ff));
    }
}

#else
const fuse__refine_kern *fuse__refine_kern_avx512(void) { return NULL; }
#endif
