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
typedef __m128d vdouble;   /* raster's doubles: VD_W = 2 lanes */
#define VD_W 2

/* what the x86 ISAs write alike: simd_x86.h, with this ISA's intrinsic names */
#define SIMD_X86_P _mm
#define SIMD_X86_B 128
#include "simd_x86.h"

/* ---- memory */
SIMD_INL vint vi_lanes(void) { return _mm_setr_epi32(0, 1, 2, 3); }

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

/* ---- compares */
SIMD_INL vmask vf_eq(vfloat a, vfloat b) { return _mm_cmpeq_ps(a, b); }
SIMD_INL vmask vf_ne(vfloat a, vfloat b) { return _mm_cmpneq_ps(a, b); }
SIMD_INL vmask vf_lt(vfloat a, vfloat b) { return _mm_cmplt_ps(a, b); }
SIMD_INL vmask vf_le(vfloat a, vfloat b) { return _mm_cmple_ps(a, b); }
SIMD_INL vmask vf_gt(vfloat a, vfloat b) { return _mm_cmpgt_ps(a, b); }
SIMD_INL vmask vf_ge(vfloat a, vfloat b) { return _mm_cmpge_ps(a, b); }

/* ---- selects, bits */
SIMD_INL vfloat vf_sel(vmask m, vfloat a, vfloat b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
SIMD_INL vint vi_sel(vmask m, vint i, vint j)
{
    const __m128i k = _mm_castps_si128(m);
    return _mm_or_si128(_mm_and_si128(k, i), _mm_andnot_si128(k, j));
}

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

/* ---- integer arithmetic: vi_mullo, the low 32 bits of the products by
 * two 32x32->64 multiplies (lanes 0, 2 and 1, 3) and a shuffle of their
 * low halves */
SIMD_INL vint vi_mullo(vint i, vint j)
{
    const __m128i e = _mm_mul_epu32(i, j);
    const __m128i o = _mm_mul_epu32(_mm_srli_epi64(i, 32), _mm_srli_epi64(j, 32));
    return _mm_unpacklo_epi32(_mm_shuffle_epi32(e, 0x08), _mm_shuffle_epi32(o, 0x08));
}

/* ---- masks */
SIMD_INL vmask vm_from_bits(unsigned b)
{
    const __m128i l = _mm_setr_epi32(1, 2, 4, 8);
    return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32((int)b), l), l));
}

/* ---- shuffles */
SIMD_INL void vf_tr4(vfloat a, vfloat b, vfloat c, vfloat d, vfloat o[4])
{
    _MM_TRANSPOSE4_PS(a, b, c, d);
    o[0] = a; o[1] = b; o[2] = c; o[3] = d;
}
/* one block: a copy */
SIMD_INL void vf_tr_blocks(const vfloat in[1], vfloat out[1]) { out[0] = in[0]; }


/* ---- doubles (raster's plane set-up) */
SIMD_INL vdouble vd_load_f(const float *p)
{
    return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(const void *)p)));
}
SIMD_INL void vd_store_f(float *p, vdouble a)
{
    _mm_storel_epi64((__m128i *)(void *)p, _mm_castps_si128(_mm_cvtpd_ps(a)));
}


/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS") */
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
/* clamp to 0..65535, then the low 16 bits sign-extended: packssdw is exact */
SIMD_INL vint vh_packus32(vint i, vint j)
{
    const vint lo = vi_zero(), hi = vi_set1(65535);
    i = vi_min(vi_sel(vi_gt(lo, i), lo, i), hi);
    j = vi_min(vi_sel(vi_gt(lo, j), lo, j), hi);
    return _mm_packs_epi32(_mm_srai_epi32(_mm_slli_epi32(i, 16), 16),
                           _mm_srai_epi32(_mm_slli_epi32(j, 16), 16));
}


/* ---- refine ops (src/fuse's band refinement, fuse_refine_simd.inl;
 * simd.h "REFINE OPS"): SSE2 has no pminuw and no pmovzx; the unsigned
 * 16-bit minimum is a - (a -sat b), widening unpacks with zero */
#define VB_W 16
#define VH_W 8
SIMD_INL uint64_t vb_sign_bits(vint i) { return (uint64_t)(unsigned)_mm_movemask_epi8(i); }
SIMD_INL vint vh_load_u8(const uint8_t *p)
{
    return _mm_unpacklo_epi8(_mm_loadl_epi64((const __m128i *)(const void *)p), _mm_setzero_si128());
}
SIMD_INL vint vh_min_u(vint i, vint j) { return _mm_sub_epi16(i, _mm_subs_epu16(i, j)); }
SIMD_INL int vh_any_leu(vint i, vint j)
{
    return _mm_movemask_epi8(_mm_cmpeq_epi16(_mm_subs_epu16(i, j), _mm_setzero_si128())) != 0;
}
SIMD_INL vint vi_load_u16(const uint16_t *p)
{
    return _mm_unpacklo_epi16(_mm_loadl_epi64((const __m128i *)(const void *)p), _mm_setzero_si128());
}
/* the chamfer's running minima (simd_x86.h's SIMD_X86_RUNMIN3): byte
 * shifts of the vector, the lanes shifted in set to 65535 by an or (the
 * unsigned minimum as above) */
#define VH__UP(t, f, k) _mm_or_si128(_mm_slli_si128(t, 2 * (k)), _mm_srli_si128(f, 16 - 2 * (k)))
#define VH__DN(t, f, k) _mm_or_si128(_mm_srli_si128(t, 2 * (k)), _mm_slli_si128(f, 16 - 2 * (k)))
SIMD_X86_RUNMIN3(vh_runmin3_up, VH__UP, 3, 6, 9, 12, 15, 18, 21, 24)
SIMD_X86_RUNMIN3(vh_runmin3_dn, VH__DN, 24, 21, 18, 15, 12, 9, 6, 3)
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
