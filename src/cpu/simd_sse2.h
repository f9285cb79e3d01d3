/* simd_sse2.h - the vector layer (simd.h) on SSE2, 4 lanes: the x86-64
 * baseline, no flag. Masks are __m128 of all-ones / all-zero lanes. SSE2
 * has no floor, no 32-bit multiply, no variable permute and no masked
 * load: those are the exact emulations below. Include once per file,
 * after nothing else of the layer. */
#ifndef EGOFUSE_SIMD_IMPL
#define EGOFUSE_SIMD_IMPL "sse2"
#if !defined(__SSE2__)
#error "simd_sse2.h: SSE2 is not enabled for this file"
#endif

#include <emmintrin.h>
#include <string.h>

#include "simd.h"

#define SIMD_W 4
#define SIMD_ISA EF_ISA_SSE2
#define SIMD_NAME "sse2"
#define SIMD_FN(name) SIMD_CAT(name, sse2)
#define SIMD_ALIGN 16
#define SIMD_FULL 0xFu

typedef __m128 vfloat;
typedef __m128i vint;
typedef __m128 vmask;

/* ---- memory */
SIMD_INL vfloat vf_set1(float x) { return _mm_set1_ps(x); }
SIMD_INL vint vi_set1(int32_t x) { return _mm_set1_epi32(x); }
SIMD_INL vfloat vf_zero(void) { return _mm_setzero_ps(); }
SIMD_INL vint vi_zero(void) { return _mm_setzero_si128(); }
SIMD_INL vint vi_lanes(void) { return _mm_setr_epi32(0, 1, 2, 3); }
SIMD_INL vfloat vf_load(const float *p) { return _mm_load_ps(p); }
SIMD_INL vfloat vf_loadu(const float *p) { return _mm_loadu_ps(p); }
SIMD_INL void vf_store(float *p, vfloat a) { _mm_store_ps(p, a); }
SIMD_INL void vf_storeu(float *p, vfloat a) { _mm_storeu_ps(p, a); }
SIMD_INL vint vi_load(const int32_t *p) { return _mm_load_si128((const __m128i *)(const void *)p); }
SIMD_INL vint vi_loadu(const int32_t *p) { return _mm_loadu_si128((const __m128i *)(const void *)p); }
SIMD_INL void vi_store(int32_t *p, vint i) { _mm_store_si128((__m128i *)(void *)p, i); }
SIMD_INL void vi_storeu(int32_t *p, vint i) { _mm_storeu_si128((__m128i *)(void *)p, i); }

SIMD_INL vint vi_load_u8(const uint8_t *p)
{
    uint32_t t;
    memcpy(&t, p, 4);
    const __m128i z = _mm_setzero_si128();
    return _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128((int)t), z), z);
}

SIMD_INL void vi_store2(int32_t *p, vint i, vint j)
{
    _mm_storeu_si128((__m128i *)(void *)p, _mm_unpacklo_epi32(i, j));
    _mm_storeu_si128((__m128i *)(void *)(p + 4), _mm_unpackhi_epi32(i, j));
}

SIMD_INL vfloat vf_load_bits(const float *p, unsigned bits)
{
    if ((bits & SIMD_FULL) == SIMD_FULL) return _mm_loadu_ps(p);
    _Alignas(16) float t[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    for (bits &= SIMD_FULL; bits; bits &= bits - 1) t[__builtin_ctz(bits)] = p[__builtin_ctz(bits)];
    return _mm_load_ps(t);
}

SIMD_INL void vf_store_bits(float *p, unsigned bits, vfloat a)
{
    if ((bits & SIMD_FULL) == SIMD_FULL) { _mm_storeu_ps(p, a); return; }
    _Alignas(16) float t[4];
    _mm_store_ps(t, a);
    for (bits &= SIMD_FULL; bits; bits &= bits - 1) p[__builtin_ctz(bits)] = t[__builtin_ctz(bits)];
}

/* x y z x y z ... <-> SoA through a small aligned buffer (the compiler
 * makes it a few moves; no SSE2 shuffle sequence was faster in bench_kin) */
SIMD_INL void vf_load3(const float *p, vfloat *x, vfloat *y, vfloat *z)
{
    _Alignas(16) float t[3][4];
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++) t[k][v] = p[3 * v + k];
    *x = _mm_load_ps(t[0]); *y = _mm_load_ps(t[1]); *z = _mm_load_ps(t[2]);
}

SIMD_INL void vf_store3(float *p, vfloat x, vfloat y, vfloat z)
{
    _Alignas(16) float t[3][4];
    _mm_store_ps(t[0], x); _mm_store_ps(t[1], y); _mm_store_ps(t[2], z);
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++) p[3 * v + k] = t[k][v];
}

SIMD_INL void vf_scatter3(float *out, const int32_t *dest, vfloat x, vfloat y, vfloat z)
{
    __m128 w = z;
    _MM_TRANSPOSE4_PS(x, y, z, w);
    const __m128 r[4] = { x, y, z, w };
#pragma GCC unroll 4
    for (int k = 0; k < 4; k++) {
        float *q = out + 3 * (size_t)dest[k];
        _mm_storel_pi((__m64 *)(void *)q, r[k]);
        _mm_store_ss(q + 2, _mm_movehl_ps(r[k], r[k]));
    }
}

/* ---- float arithmetic */
SIMD_INL vfloat vf_add(vfloat a, vfloat b) { return _mm_add_ps(a, b); }
SIMD_INL vfloat vf_sub(vfloat a, vfloat b) { return _mm_sub_ps(a, b); }
SIMD_INL vfloat vf_mul(vfloat a, vfloat b) { return _mm_mul_ps(a, b); }
SIMD_INL vfloat vf_div(vfloat a, vfloat b) { return _mm_div_ps(a, b); }
SIMD_INL vfloat vf_sqrt(vfloat a) { return _mm_sqrt_ps(a); }
SIMD_INL vfloat vf_min(vfloat a, vfloat b) { return _mm_min_ps(a, b); }
SIMD_INL vfloat vf_max(vfloat a, vfloat b) { return _mm_max_ps(a, b); }
SIMD_INL vfloat vf_neg(vfloat a) { return _mm_xor_ps(a, _mm_set1_ps(-0.0f)); }
SIMD_INL vfloat vf_abs(vfloat a) { return _mm_and_ps(a, _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF))); }
SIMD_INL vfloat vf_neg_if(vmask m, vfloat a) { return _mm_xor_ps(a, _mm_and_ps(m, _mm_set1_ps(-0.0f))); }

/* ---- compares */
SIMD_INL vmask vf_eq(vfloat a, vfloat b) { return _mm_cmpeq_ps(a, b); }
SIMD_INL vmask vf_ne(vfloat a, vfloat b) { return _mm_cmpneq_ps(a, b); }
SIMD_INL vmask vf_lt(vfloat a, vfloat b) { return _mm_cmplt_ps(a, b); }
SIMD_INL vmask vf_le(vfloat a, vfloat b) { return _mm_cmple_ps(a, b); }
SIMD_INL vmask vf_gt(vfloat a, vfloat b) { return _mm_cmpgt_ps(a, b); }
SIMD_INL vmask vf_ge(vfloat a, vfloat b) { return _mm_cmpge_ps(a, b); }
SIMD_INL vmask vi_eq(vint i, vint j) { return _mm_castsi128_ps(_mm_cmpeq_epi32(i, j)); }
SIMD_INL vmask vi_gt(vint i, vint j) { return _mm_castsi128_ps(_mm_cmpgt_epi32(i, j)); }

/* ---- selects, bits */
SIMD_INL vfloat vf_sel(vmask m, vfloat a, vfloat b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
SIMD_INL vfloat vf_selz(vmask m, vfloat a) { return _mm_and_ps(m, a); }
SIMD_INL vint vi_sel(vmask m, vint i, vint j)
{
    const __m128i k = _mm_castps_si128(m);
    return _mm_or_si128(_mm_and_si128(k, i), _mm_andnot_si128(k, j));
}
SIMD_INL vfloat vf_and(vfloat a, vfloat b) { return _mm_and_ps(a, b); }
SIMD_INL vfloat vf_or(vfloat a, vfloat b) { return _mm_or_ps(a, b); }
SIMD_INL vfloat vf_xor(vfloat a, vfloat b) { return _mm_xor_ps(a, b); }
SIMD_INL vfloat vf_andnot(vfloat a, vfloat b) { return _mm_andnot_ps(a, b); }
SIMD_INL vint vi_and(vint i, vint j) { return _mm_and_si128(i, j); }
SIMD_INL vint vi_or(vint i, vint j) { return _mm_or_si128(i, j); }
SIMD_INL vint vi_xor(vint i, vint j) { return _mm_xor_si128(i, j); }
SIMD_INL vint vi_andnot(vint i, vint j) { return _mm_andnot_si128(i, j); }
SIMD_INL vint vf_as_vi(vfloat a) { return _mm_castps_si128(a); }
SIMD_INL vfloat vi_as_vf(vint i) { return _mm_castsi128_ps(i); }

/* floorf: truncate, subtract 1 where that rounded up, put back the sign
 * of -0.0 (the truncation gives +0), keep lanes with !(|a| < 2^23)
 * (already integers, inf, NaN) as they are (a select: after vf_sel). */
SIMD_INL vfloat vf_floor(vfloat a)
{
    const __m128 sign = _mm_set1_ps(-0.0f);
    __m128 t = _mm_cvtepi32_ps(_mm_cvttps_epi32(a));
    t = _mm_sub_ps(t, _mm_and_ps(_mm_cmpgt_ps(t, a), _mm_set1_ps(1.0f)));
    t = _mm_or_ps(t, _mm_and_ps(a, sign));
    const __m128 small = _mm_cmplt_ps(_mm_andnot_ps(sign, a), _mm_set1_ps(8388608.0f));
    return vf_sel(small, t, a);
}

/* ---- integer arithmetic */
SIMD_INL vint vi_add(vint i, vint j) { return _mm_add_epi32(i, j); }
SIMD_INL vint vi_sub(vint i, vint j) { return _mm_sub_epi32(i, j); }
/* low 32 bits of the products: two 32x32->64 multiplies (lanes 0, 2 and
 * 1, 3) and a shuffle of their low halves */
SIMD_INL vint vi_mullo(vint i, vint j)
{
    const __m128i e = _mm_mul_epu32(i, j);
    const __m128i o = _mm_mul_epu32(_mm_srli_epi64(i, 32), _mm_srli_epi64(j, 32));
    return _mm_unpacklo_epi32(_mm_shuffle_epi32(e, 0x08), _mm_shuffle_epi32(o, 0x08));
}
#define vi_slli(i, k) _mm_slli_epi32(i, k)
#define vi_srli(i, k) _mm_srli_epi32(i, k)
#define vi_srai(i, k) _mm_srai_epi32(i, k)
SIMD_INL vint vi_sll(vint i, int k) { return _mm_sll_epi32(i, _mm_cvtsi32_si128(k)); }
SIMD_INL vint vi_srl(vint i, int k) { return _mm_srl_epi32(i, _mm_cvtsi32_si128(k)); }

/* ---- conversions (x86's own: the contract's reference) */
SIMD_INL vfloat vf_from_vi(vint i) { return _mm_cvtepi32_ps(i); }
SIMD_INL vint vi_from_vf_trunc(vfloat a) { return _mm_cvttps_epi32(a); }
SIMD_INL vint vi_from_vf_round(vfloat a) { return _mm_cvtps_epi32(a); }

/* ---- masks */
SIMD_INL vmask vm_and(vmask m, vmask n) { return _mm_and_ps(m, n); }
SIMD_INL vmask vm_or(vmask m, vmask n) { return _mm_or_ps(m, n); }
SIMD_INL vmask vm_andnot(vmask m, vmask n) { return _mm_andnot_ps(m, n); }
SIMD_INL vmask vm_not(vmask m) { return _mm_xor_ps(m, _mm_castsi128_ps(_mm_set1_epi32(-1))); }
SIMD_INL unsigned vm_bits(vmask m) { return (unsigned)_mm_movemask_ps(m); }
SIMD_INL vmask vm_from_bits(unsigned b)
{
    const __m128i l = _mm_setr_epi32(1, 2, 4, 8);
    return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32((int)b), l), l));
}
SIMD_INL int vm_all(vmask m) { return _mm_movemask_ps(m) == 0xF; }
SIMD_INL int vm_any(vmask m) { return _mm_movemask_ps(m) != 0; }

/* ---- zips (per block) */
SIMD_INL vint vi_zip_lo(vint i, vint j) { return _mm_unpacklo_epi32(i, j); }
SIMD_INL vint vi_zip_hi(vint i, vint j) { return _mm_unpackhi_epi32(i, j); }

/* ---- 16-bit lanes (simd.h, "16-bit lanes") */
SIMD_INL vint vh_set1(int x) { return _mm_set1_epi16((short)x); }
SIMD_INL vint vh_add(vint i, vint j) { return _mm_add_epi16(i, j); }
SIMD_INL vint vh_sub(vint i, vint j) { return _mm_sub_epi16(i, j); }
SIMD_INL vint vh_mullo(vint i, vint j) { return _mm_mullo_epi16(i, j); }
#define vh_srli(i, k) _mm_srli_epi16(i, k)
SIMD_INL vint vh_from_u8_lo(vint i) { return _mm_unpacklo_epi8(i, _mm_setzero_si128()); }
SIMD_INL vint vh_from_u8_hi(vint i) { return _mm_unpackhi_epi8(i, _mm_setzero_si128()); }
SIMD_INL vint vh_packus(vint i, vint j) { return _mm_packus_epi16(i, j); }
SIMD_INL vint vh_bcast3(vint i) { return _mm_shufflehi_epi16(_mm_shufflelo_epi16(i, 0xFF), 0xFF); }

/* ---- shuffles */
SIMD_INL void vf_tr4(vfloat a, vfloat b, vfloat c, vfloat d, vfloat o[4])
{
    _MM_TRANSPOSE4_PS(a, b, c, d);
    o[0] = a; o[1] = b; o[2] = c; o[3] = d;
}
/* one block: a copy */
SIMD_INL void vf_tr_blocks(const vfloat in[1], vfloat out[1]) { out[0] = in[0]; }


/* ---- raster ops (src/raster's scan; simd.h "RASTER OPS") */
SIMD_INL unsigned vi_sign_bits(vint i) { return (unsigned)_mm_movemask_ps(_mm_castsi128_ps(i)); }
SIMD_INL void vb_store_bits(uint8_t *p, unsigned bits)
{
    simd__bytes_store_bits(p, bits, SIMD_FULL, SIMD_W);
}
SIMD_INL void vf_store3_bits(float *p, unsigned bits, vfloat x, vfloat y, vfloat z)
{
    _Alignas(16) float t[3][4];
    _mm_store_ps(t[0], x); _mm_store_ps(t[1], y); _mm_store_ps(t[2], z);
    simd__store3_lanes(p, bits & SIMD_FULL, SIMD_W, t);
}


/* doubles (raster's plane set-up): VD_W = 2 lanes */
#define VD_W 2
typedef __m128d vdouble;
SIMD_INL vdouble vd_set1(double x) { return _mm_set1_pd(x); }
SIMD_INL vdouble vd_loadu(const double *p) { return _mm_loadu_pd(p); }
SIMD_INL void vd_storeu(double *p, vdouble a) { _mm_storeu_pd(p, a); }
SIMD_INL vdouble vd_add(vdouble a, vdouble b) { return _mm_add_pd(a, b); }
SIMD_INL vdouble vd_sub(vdouble a, vdouble b) { return _mm_sub_pd(a, b); }
SIMD_INL vdouble vd_mul(vdouble a, vdouble b) { return _mm_mul_pd(a, b); }
SIMD_INL vdouble vd_div(vdouble a, vdouble b) { return _mm_div_pd(a, b); }
SIMD_INL vdouble vd_max(vdouble a, vdouble b) { return _mm_max_pd(a, b); }
SIMD_INL vdouble vd_load_f(const float *p)
{
    return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(const void *)p)));
}
SIMD_INL void vd_store_f(float *p, vdouble a)
{
    _mm_storel_epi64((__m128i *)(void *)p, _mm_castps_si128(_mm_cvtpd_ps(a)));
}


/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS") */
SIMD_INL vdouble vd_sqrt(vdouble a) { return _mm_sqrt_pd(a); }
/* no pminsd / pmaxsd: a compare and a select */
SIMD_INL vint vi_min(vint i, vint j) { return vi_sel(vi_gt(i, j), j, i); }
SIMD_INL vint vi_max(vint i, vint j) { return vi_sel(vi_gt(i, j), i, j); }
SIMD_INL vdouble vd_from_vf(vfloat a, int h) { return _mm_cvtps_pd(h ? _mm_movehl_ps(a, a) : a); }
SIMD_INL vdouble vd_from_vi(vint i, int h) { return _mm_cvtepi32_pd(h ? _mm_shuffle_epi32(i, 0xEE) : i); }
SIMD_INL vfloat vf_from_vd(vdouble lo, vdouble hi) { return _mm_movelh_ps(_mm_cvtpd_ps(lo), _mm_cvtpd_ps(hi)); }
SIMD_INL unsigned vd_gt_bits(vdouble a, vdouble b) { return (unsigned)_mm_movemask_pd(_mm_cmpgt_pd(a, b)); }
/* ---- row-cache ops (src/fuse's composite; simd.h "ROW-CACHE OPS"): SSE2
 * has no pminsd, no variable permute, no gather and no packusdw */
SIMD_INL vint vi_permute(vint i, vint idx)
{
    _Alignas(16) int32_t s[4], x[4], r[4];
    _mm_store_si128((__m128i *)(void *)s, i);
    _mm_store_si128((__m128i *)(void *)x, idx);
    for (int l = 0; l < 4; l++) r[l] = s[x[l] & 3];
    return _mm_load_si128((const __m128i *)(const void *)r);
}
SIMD_INL vint vi_gather(const int32_t *p, vint idx)
{
    _Alignas(16) int32_t x[4];
    _mm_store_si128((__m128i *)(void *)x, idx);
    return _mm_setr_epi32(p[x[0]], p[x[1]], p[x[2]], p[x[3]]);
}
SIMD_INL vint vh_zip_lo(vint i, vint j) { return _mm_unpacklo_epi16(i, j); }
SIMD_INL vint vh_zip_hi(vint i, vint j) { return _mm_unpackhi_epi16(i, j); }
SIMD_INL vint vh_madd(vint i, vint j) { return _mm_madd_epi16(i, j); }
/* clamp to 0..65535, then the low 16 bits sign-extended: packssdw is exact */
SIMD_INL vint vh_packus32(vint i, vint j)
{
    const vint lo = vi_zero(), hi = vi_set1(65535);
    i = vi_min(vi_sel(vi_gt(lo, i), lo, i), hi);
    j = vi_min(vi_sel(vi_gt(lo, j), lo, j), hi);
    return _mm_packs_epi32(_mm_srai_epi32(_mm_slli_epi32(i, 16), 16),
                           _mm_srai_epi32(_mm_slli_epi32(j, 16), 16));
}
SIMD_INL vint vh_mulhi(vint i, vint j) { return _mm_mulhi_epu16(i, j); }


/* ---- refine ops (src/fuse's band refinement, fuse_refine_simd.inl;
 * simd.h "REFINE OPS"): SSE2 has no pminuw and no pmovzx; the unsigned
 * 16-bit minimum is a - (a -sat b), widening unpacks with zero */
#define VB_W 16
#define VH_W 8
SIMD_INL vint vb_loadu(const uint8_t *p) { return _mm_loadu_si128((const __m128i *)(const void *)p); }
SIMD_INL void vb_storeu(uint8_t *p, vint i) { _mm_storeu_si128((__m128i *)(void *)p, i); }
SIMD_INL uint64_t vb_sign_bits(vint i) { return (uint64_t)(unsigned)_mm_movemask_epi8(i); }
SIMD_INL vint vb_sign_fill(vint i) { return _mm_cmpgt_epi8(_mm_setzero_si128(), i); }
SIMD_INL vint vh_load_u8(const uint8_t *p)
{
    return _mm_unpacklo_epi8(_mm_loadl_epi64((const __m128i *)(const void *)p), _mm_setzero_si128());
}
SIMD_INL vint vh_loadu(const uint16_t *p) { return _mm_loadu_si128((const __m128i *)(const void *)p); }
SIMD_INL void vh_storeu(uint16_t *p, vint i) { _mm_storeu_si128((__m128i *)(void *)p, i); }
SIMD_INL vint vh_min_u(vint i, vint j) { return _mm_sub_epi16(i, _mm_subs_epu16(i, j)); }
SIMD_INL vint vh_adds_u(vint i, vint j) { return _mm_adds_epu16(i, j); }
SIMD_INL int vh_any_leu(vint i, vint j)
{
    return _mm_movemask_epi8(_mm_cmpeq_epi16(_mm_subs_epu16(i, j), _mm_setzero_si128())) != 0;
}
SIMD_INL vint vi_load_u16(const uint16_t *p)
{
    return _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)p), _mm_setzero_si128());
}
/* the chamfer's running minima: byte shifts of the vector, the lanes
 * shifted in set to 65535 by an or (the unsigned minimum as above).
 * VH__RUNMIN3 writes both directions: SH the shift, the rest the 8 lanes
 * the carry c is added to, 3 (l + 1) (up) or 3 (8 - l) (dn). */
#define VH__UP(t, f, k) _mm_or_si128(_mm_slli_si128(t, 2 * (k)), _mm_srli_si128(f, 16 - 2 * (k)))
#define VH__DN(t, f, k) _mm_or_si128(_mm_srli_si128(t, 2 * (k)), _mm_slli_si128(f, 16 - 2 * (k)))
#define VH__RUNMIN3(name, SH, ...)                                        \
    SIMD_INL vint name(vint i, unsigned c)                                \
    {                                                                     \
        const __m128i f = _mm_set1_epi16(-1);                             \
        __m128i t = i;                                                    \
        t = vh_min_u(t, _mm_adds_epu16(SH(t, f, 1), _mm_set1_epi16(3)));  \
        t = vh_min_u(t, _mm_adds_epu16(SH(t, f, 2), _mm_set1_epi16(6)));  \
        t = vh_min_u(t, _mm_adds_epu16(SH(t, f, 4), _mm_set1_epi16(12))); \
        const __m128i l3 = _mm_setr_epi16(__VA_ARGS__);                   \
        return vh_min_u(t, _mm_adds_epu16(_mm_set1_epi16((short)c), l3)); \
    }
VH__RUNMIN3(vh_runmin3_up, VH__UP, 3, 6, 9, 12, 15, 18, 21, 24)
VH__RUNMIN3(vh_runmin3_dn, VH__DN, 24, 21, 18, 15, 12, 9, 6, 3)
#undef VH__RUNMIN3
#undef VH__UP
#undef VH__DN


/* ---- reprojection ops (src/pipe's taps, pipe_reproj_simd.inl; simd.h
 * "REPROJ OPS"): SSE2 has no gather, lane by lane */
SIMD_INL vfloat vf_gather(const float *p, vint idx)
{
    _Alignas(16) int32_t x[4];
    _mm_store_si128((__m128i *)(void *)x, idx);
    return _mm_setr_ps(p[x[0]], p[x[1]], p[x[2]], p[x[3]]);
}
/* lane by lane, only the lanes in m read */
SIMD_INL vfloat vf_gather_m(const float *p, vint idx, vmask m)
{
    _Alignas(16) int32_t x[4];
    _Alignas(16) float r[4];
    const unsigned bits = (unsigned)_mm_movemask_ps(m);
    _mm_store_si128((__m128i *)(void *)x, idx);
    for (int l = 0; l < 4; l++) r[l] = (bits >> l) & 1u ? p[x[l]] : 0.0f;
    return _mm_load_ps(r);
}
SIMD_INL vint vi_gather_u8x4(const uint8_t *p, vint idx)
{
    _Alignas(16) int32_t x[4], r[4];
    _mm_store_si128((__m128i *)(void *)x, idx);
    for (int l = 0; l < 4; l++) __builtin_memcpy(&r[l], p + x[l], 4);
    return _mm_load_si128((const __m128i *)(const void *)r);
}
/* the low bytes: masked to 0..255, packs and packus are exact */
SIMD_INL void vi_store_u8(uint8_t *p, vint i)
{
    const __m128i b = _mm_and_si128(i, _mm_set1_epi32(0xFF));
    const __m128i h = _mm_packs_epi32(b, b);
    const int v = _mm_cvtsi128_si32(_mm_packus_epi16(h, h));
    __builtin_memcpy(p, &v, 4);
}

#else
#error "simd_sse2.h: another implementation of the vector layer is already included"
#endif
