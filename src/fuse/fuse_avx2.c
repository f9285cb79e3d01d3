/* fuse_avx2.c - AVX2 path of the fuse kernels (built with -mavx2 -mf16c,
 * called only when cpuid reports AVX2). The bytes are the reference's
 * (docs/fuse.md, "Rounding rules"); tests/test_fuse_isa.c checks it.
 *
 * Lighting, depth test, coverage bits, opaque copies: fuse_simd.inl on the
 * vector layer (src/cpu/simd_avx2.h, 8 lanes); AVX2's own part there is
 * the depth test's scene values (a window of the row and vpermps, or a
 * gather) and the lighting's normals (128-bit loads and shufps).
 * The row-cached composite (fuse__hrow_avx2 once per layer row,
 * fuse__vrow_avx2 per output row; fuse_internal.h) is fuse_simd.inl's too
 * (FUSE_ROWCACHE_ON_LAYER: the layer's "ROW-CACHE OPS"), as for AVX-512.
 * AVX2's own: the YUYV conversion below (16-bit madd; AVX-512 runs it too,
 * SSE2 and NEON the layer's int32 one). */
#include "fuse_internal.h"

#if defined(__AVX2__)
#include <immintrin.h>

#include "../cpu/simd_avx2.h"

/* The scene values of the lanes in has: when the 8 columns lie in a window
 * of 16 (always when the layer is enlarged), two loads of the window
 * (masked to the viewport's width where it ends inside the window: nothing
 * beyond it is read), two vpermps and a blend; otherwise a gather. Lanes
 * outside has are never used. */
static inline __m256 scene_avx2(const fuse__depth_prep *p, const float *sc, __m256i ox, __m256 has)
{
    const int32_t c0 = _mm_cvtsi128_si32(_mm256_castsi256_si128(ox));
    const int32_t c7 = _mm_extract_epi32(_mm256_extracti128_si256(ox, 1), 3);
    if (c7 - c0 < 16) {
        const __m256i idx = _mm256_sub_epi32(ox, _mm256_set1_epi32(c0));
        __m256 lo, hi;
        if (p->vw - c0 >= 16) {   /* (loads that vpermps takes as operands) */
            lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(sc + c0), idx);
            hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(sc + c0 + 8), idx);
        } else {
            const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
            const __m256i left = _mm256_set1_epi32(p->vw - c0);
            lo = _mm256_permutevar8x32_ps(_mm256_maskload_ps(sc + c0, _mm256_cmpgt_epi32(left, lane)),
                                          idx);
            hi = _mm256_permutevar8x32_ps(_mm256_maskload_ps(sc + c0 + 8, _mm256_cmpgt_epi32(
                left, _mm256_add_epi32(lane, _mm256_set1_epi32(8)))), idx);
        }
        /* idx in [0, 15]: bit 3 (idx >= 8, from hi) shifted into the sign
         * bit, which is what blendv reads (no constant to compare with) */
        return _mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(_mm256_slli_epi32(idx, 28)));
    }
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), sc, ox, has, 4);
}
#define FUSE_SCENE_LANES(p, sc, ox, has) scene_avx2(p, sc, ox, has)

/* 8 interleaved xyz normals -> x, y, z for the lighting: the 128-bit
 * thirds of the first 12 floats in the low halves, of the next 12 in the
 * high halves (m03: x0 y0 z0 x1, m14: y1 z1 x2 y2, m25: z2 x3 y3 z3, and
 * pixels 4-7 alike), then five in-block shufps: 11 instructions where the
 * layer's vf_load3 (blends and vpermps, for any use) takes 12 and three
 * index vectors. */
static inline void normals_avx2(const float *p, __m256 *x, __m256 *y, __m256 *z)
{
    const __m256 m03 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p)), _mm_loadu_ps(p + 12), 1);
    const __m256 m14 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p + 4)), _mm_loadu_ps(p + 16), 1);
    const __m256 m25 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p + 8)), _mm_loadu_ps(p + 20), 1);
    const __m256 xy = _mm256_shuffle_ps(m14, m25, _MM_SHUFFLE(2, 1, 3, 2));   /* x2 y2 x3 y3 */
    const __m256 yz = _mm256_shuffle_ps(m03, m14, _MM_SHUFFLE(1, 0, 2, 1));   /* y0 z0 y1 z1 */
    *x = _mm256_shuffle_ps(m03, xy, _MM_SHUFFLE(2, 0, 3, 0));
    *y = _mm256_shuffle_ps(yz, xy, _MM_SHUFFLE(3, 1, 2, 0));
    *z = _mm256_shuffle_ps(yz, m25, _MM_SHUFFLE(3, 0, 3, 1));
}
#define FUSE_LOAD_NORMALS(p, x, y, z) normals_avx2(p, &(x), &(y), &(z))

/* vrow's alpha in each pixel's four 16-bit lanes: bytes 6-7 (14-15) of
 * each block copied by one pshufb where vh_bcast3 takes pshuflw and
 * pshufhw (qq's lanes hold 0..255, any copy of the word is exact). */
#define FUSE_ALPHA4(q)                                                           \
    _mm256_shuffle_epi8(q, _mm256_setr_epi8(6, 7, 6, 7, 6, 7, 6, 7, 14, 15, 14, 15, 14, 15, \
                                            14, 15, 6, 7, 6, 7, 6, 7, 6, 7, 14, 15, 14, 15, \
                                            14, 15, 14, 15))

/* vrow's all-opaque test: (q0 & q1) has every bit of each pixel's alpha
 * byte (lane 3 of 4, 0..255), one vptest */
#define FUSE_ALPHA255(q0, q1)                                                    \
    _mm256_testc_si256(_mm256_and_si256(q0, q1), _mm256_set1_epi64x(0x00FF000000000000LL))

/* hrow's empty window: one vptest */
#define FUSE_ZERO(v) _mm256_testz_si256(v, v)

#define FUSE_ROWCACHE_ON_LAYER 1
#include "fuse_simd.inl"

#else  /* not built for AVX2: never chosen by cpuid, falls back */

#define FUSE_STUB(name) name##_avx2
#define FUSE_ROWCACHE_ON_LAYER 1
#include "fuse_stub.inl"
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
