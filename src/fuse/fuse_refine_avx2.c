/* fuse_refine_avx2.c - AVX2 row kernels of the band-only refinement
 * (fuse_refine_kern.h), built with the flags of *_avx2.c and chosen only
 * when cpuid reports AVX2. Same bytes as the reference
 * (tests/test_fuse_refine.c). The kernels are fuse_refine_simd.inl on the
 * vector layer (src/cpu/simd_avx2.h); what is AVX2's own is the score
 * kernel: 8 per step, bins in lanes, the look-ups by vgatherdps (the
 * layer has no float gather), the row end by the portable kernel. */
#include "fuse_refine_kern.h"

#if defined(__AVX2__)
#include <immintrin.h>

#include "../cpu/simd_avx2.h"

#define KC fuse__refine_kern_c

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

static void SIMD_FN(refine_score_row)(const fuse__refine_tabs *t, const uint8_t *px, const uint8_t *m,
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

#undef KC

#include "fuse_refine_simd.inl"

#else
const fuse__refine_kern *fuse__refine_kern_avx2(void) { return NULL; }
#endif
