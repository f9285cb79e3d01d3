/* simd_avx2.h - the vector layer (simd.h) on AVX2, 8 lanes (files built
 * with -mavx2 -mf16c, no -mfma). Masks are __m256 of all-ones / all-zero
 * lanes. Include once per file. */
#ifndef EGOFUSE_SIMD_IMPL
#define EGOFUSE_SIMD_IMPL "avx2"
#if !defined(__AVX2__)
#error "simd_avx2.h: AVX2 is not enabled for this file (-mavx2)"
#endif

#include <immintrin.h>

#include "simd.h"

#define SIMD_W 8
#define SIMD_ISA EF_ISA_AVX2
#define SIMD_NAME "avx2"
#define SIMD_FN(name) SIMD_CAT(name, avx2)
#define SIMD_ALIGN 32
#define SIMD_FULL 0xFFu

typedef __m256 vfloat;
typedef __m256i vint;
typedef __m256 vmask;

/* ---- memory */
SIMD_INL vfloat vf_set1(float x) { return _mm256_set1_ps(x); }
SIMD_INL vint vi_set1(int32_t x) { return _mm256_set1_epi32(x); }
SIMD_INL vfloat vf_zero(void) { return _mm256_setzero_ps(); }
SIMD_INL vint vi_zero(void) { return _mm256_setzero_si256(); }
SIMD_INL vint vi_lanes(void) { return _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7); }
SIMD_INL vfloat vf_load(const float *p) { return _mm256_load_ps(p); }
SIMD_INL vfloat vf_loadu(const float *p) { return _mm256_loadu_ps(p); }
SIMD_INL void vf_store(float *p, vfloat a) { _mm256_store_ps(p, a); }
SIMD_INL void vf_storeu(float *p, vfloat a) { _mm256_storeu_ps(p, a); }
SIMD_INL vint vi_load(const int32_t *p) { return _mm256_load_si256((const __m256i *)(const void *)p); }
SIMD_INL vint vi_loadu(const int32_t *p) { return _mm256_loadu_si256((const __m256i *)(const void *)p); }
SIMD_INL void vi_store(int32_t *p, vint i) { _mm256_store_si256((__m256i *)(void *)p, i); }
SIMD_INL void vi_storeu(int32_t *p, vint i) { _mm256_storeu_si256((__m256i *)(void *)p, i); }

/* lane l all-ones where bit l of b is set */
SIMD_INL __m256i simd__lanes_of(unsigned b)
{
    const __m256i l = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)b), l), l);
}

/* vmaskmovps: masked lanes are not accessed (no fault) and load as 0 */
SIMD_INL vint vi_load_u8(const uint8_t *p)
{
    return _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(const void *)p));
}

/* unpack works per 128-bit half: lo = i0 j0 i1 j1 | i4 j4 i5 j5, hi =
 * i2 j2 i3 j3 | i6 j6 i7 j7; the halves recombined in memory order */
SIMD_INL void vi_store2(int32_t *p, vint i, vint j)
{
    const __m256i lo = _mm256_unpacklo_epi32(i, j), hi = _mm256_unpackhi_epi32(i, j);
    _mm256_storeu_si256((__m256i *)(void *)p, _mm256_permute2x128_si256(lo, hi, 0x20));
    _mm256_storeu_si256((__m256i *)(void *)(p + 8), _mm256_permute2x128_si256(lo, hi, 0x31));
}

SIMD_INL vfloat vf_load_bits(const float *p, unsigned bits)
{
    if ((bits & SIMD_FULL) == SIMD_FULL) return _mm256_loadu_ps(p);
    return _mm256_maskload_ps(p, simd__lanes_of(bits));
}

SIMD_INL void vf_store_bits(float *p, unsigned bits, vfloat a)
{
    if ((bits & SIMD_FULL) == SIMD_FULL) { _mm256_storeu_ps(p, a); return; }
    _mm256_maskstore_ps(p, simd__lanes_of(bits), a);
}

/* x y z x y z ... (24 floats) <-> SoA. Component k of vertex v is float
 * 3v + k: register (3v+k)/8, lane (3v+k)%8; the lanes of one component
 * are distinct, so two blends gather them into one register and one
 * permute puts them in vertex order (lane v of the gather index:
 * (3v+k)%8; of the scatter index: the inverse). */
SIMD_INL void vf_load3(const float *p, vfloat *x, vfloat *y, vfloat *z)
{
    const __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
    /* lanes of x in b: 1 4 7, in c: 2 5; y: b 2 5, c 0 3 6; z: b 0 3 6, c 1 4 7 */
    *x = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(a, b, 0x92), c, 0x24),
                                  _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
    *y = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(a, b, 0x24), c, 0x49),
                                  _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6));
    *z = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(a, b, 0x49), c, 0x92),
                                  _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
}

SIMD_INL void vf_store3(float *p, vfloat x, vfloat y, vfloat z)
{
    x = _mm256_permutevar8x32_ps(x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
    y = _mm256_permutevar8x32_ps(y, _mm256_setr_epi32(5, 0, 3, 6, 1, 4, 7, 2));
    z = _mm256_permutevar8x32_ps(z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
    /* register 0: y in lanes 1 4 7, z in 2 5; 1: y 2 5, z 0 3 6; 2: y 0 3 6, z 1 4 7 */
    _mm256_storeu_ps(p, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x92), z, 0x24));
    _mm256_storeu_ps(p + 8, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x24), z, 0x49));
    _mm256_storeu_ps(p + 16, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x49), z, 0x92));
}

/* ---- zips (per 128-bit block) */
SIMD_INL vint vi_zip_lo(vint i, vint j) { return _mm256_unpacklo_epi32(i, j); }
SIMD_INL vint vi_zip_hi(vint i, vint j) { return _mm256_unpackhi_epi32(i, j); }

/* ---- 16-bit lanes (simd.h, "16-bit lanes"; per 128-bit block as AVX2's
 * unpack, pack and shuffle work) */
SIMD_INL vint vh_set1(int x) { return _mm256_set1_epi16((short)x); }
SIMD_INL vint vh_add(vint i, vint j) { return _mm256_add_epi16(i, j); }
SIMD_INL vint vh_sub(vint i, vint j) { return _mm256_sub_epi16(i, j); }
SIMD_INL vint vh_mullo(vint i, vint j) { return _mm256_mullo_epi16(i, j); }
#define vh_srli(i, k) _mm256_srli_epi16(i, k)
SIMD_INL vint vh_from_u8_lo(vint i) { return _mm256_unpacklo_epi8(i, _mm256_setzero_si256()); }
SIMD_INL vint vh_from_u8_hi(vint i) { return _mm256_unpackhi_epi8(i, _mm256_setzero_si256()); }
SIMD_INL vint vh_packus(vint i, vint j) { return _mm256_packus_epi16(i, j); }
SIMD_INL vint vh_bcast3(vint i) { return _mm256_shufflehi_epi16(_mm256_shufflelo_epi16(i, 0xFF), 0xFF); }

/* ---- shuffles */
SIMD_INL void vf_tr4(vfloat a, vfloat b, vfloat c, vfloat d, vfloat o[4])
{
    const __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(a, b));
    const __m256d t1 = _mm256_castps_pd(_mm256_unpacklo_ps(c, d));
    const __m256d t2 = _mm256_castps_pd(_mm256_unpackhi_ps(a, b));
    const __m256d t3 = _mm256_castps_pd(_mm256_unpackhi_ps(c, d));
    o[0] = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t1));
    o[1] = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t1));
    o[2] = _mm256_castpd_ps(_mm256_unpacklo_pd(t2, t3));
    o[3] = _mm256_castpd_ps(_mm256_unpackhi_pd(t2, t3));
}
/* 2 x 2 blocks: vperm2f128 */
SIMD_INL void vf_tr_blocks(const vfloat in[2], vfloat out[2])
{
    const __m256 a = in[0], b = in[1];
    out[0] = _mm256_permute2f128_ps(a, b, 0x20);
    out[1] = _mm256_permute2f128_ps(a, b, 0x31);
}

/* one lane's x y z (lanes 0-2 of a) to q: 8 bytes and 4 bytes */
SIMD_INL void simd__store3_one(float *q, __m128 a)
{
    _mm_storel_pi((__m64 *)(void *)q, a);
    _mm_store_ss(q + 2, _mm_movehl_ps(a, a));
}

SIMD_INL void vf_scatter3(float *out, const int32_t *dest, vfloat x, vfloat y, vfloat z)
{
    __m256 t[4];
    vf_tr4(x, y, z, z, t);   /* t[k], block J: lane 4J + k */
#pragma GCC unroll 4
    for (int k = 0; k < 4; k++) {
        simd__store3_one(out + 3 * (size_t)dest[k], _mm256_castps256_ps128(t[k]));
        simd__store3_one(out + 3 * (size_t)dest[4 + k], _mm256_extractf128_ps(t[k], 1));
    }
}

/* ---- float arithmetic */
SIMD_INL vfloat vf_add(vfloat a, vfloat b) { return _mm256_add_ps(a, b); }
SIMD_INL vfloat vf_sub(vfloat a, vfloat b) { return _mm256_sub_ps(a, b); }
SIMD_INL vfloat vf_mul(vfloat a, vfloat b) { return _mm256_mul_ps(a, b); }
SIMD_INL vfloat vf_div(vfloat a, vfloat b) { return _mm256_div_ps(a, b); }
SIMD_INL vfloat vf_sqrt(vfloat a) { return _mm256_sqrt_ps(a); }
SIMD_INL vfloat vf_min(vfloat a, vfloat b) { return _mm256_min_ps(a, b); }
SIMD_INL vfloat vf_max(vfloat a, vfloat b) { return _mm256_max_ps(a, b); }
SIMD_INL vfloat vf_neg(vfloat a) { return _mm256_xor_ps(a, _mm256_set1_ps(-0.0f)); }
SIMD_INL vfloat vf_abs(vfloat a) { return _mm256_and_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF))); }
SIMD_INL vfloat vf_neg_if(vmask m, vfloat a) { return _mm256_xor_ps(a, _mm256_and_ps(m, _mm256_set1_ps(-0.0f))); }
SIMD_INL vfloat vf_floor(vfloat a) { return _mm256_round_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }

/* ---- compares (one constant predicate each: clang and gcc -Os need it) */
SIMD_INL vmask vf_eq(vfloat a, vfloat b) { return _mm256_cmp_ps(a, b, _CMP_EQ_OQ); }
SIMD_INL vmask vf_ne(vfloat a, vfloat b) { return _mm256_cmp_ps(a, b, _CMP_NEQ_UQ); }
SIMD_INL vmask vf_lt(vfloat a, vfloat b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
SIMD_INL vmask vf_le(vfloat a, vfloat b) { return _mm256_cmp_ps(a, b, _CMP_LE_OQ); }
SIMD_INL vmask vf_gt(vfloat a, vfloat b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
SIMD_INL vmask vf_ge(vfloat a, vfloat b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
SIMD_INL vmask vi_eq(vint i, vint j) { return _mm256_castsi256_ps(_mm256_cmpeq_epi32(i, j)); }
SIMD_INL vmask vi_gt(vint i, vint j) { return _mm256_castsi256_ps(_mm256_cmpgt_epi32(i, j)); }

/* ---- selects, bits (blendv reads the mask's sign bit: masks are
 * all-ones / all-zero lanes, so that is the lane flag) */
SIMD_INL vfloat vf_sel(vmask m, vfloat a, vfloat b) { return _mm256_blendv_ps(b, a, m); }
SIMD_INL vfloat vf_selz(vmask m, vfloat a) { return _mm256_and_ps(m, a); }
SIMD_INL vint vi_sel(vmask m, vint i, vint j)
{
    return _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(j), _mm256_castsi256_ps(i), m));
}
SIMD_INL vfloat vf_and(vfloat a, vfloat b) { return _mm256_and_ps(a, b); }
SIMD_INL vfloat vf_or(vfloat a, vfloat b) { return _mm256_or_ps(a, b); }
SIMD_INL vfloat vf_xor(vfloat a, vfloat b) { return _mm256_xor_ps(a, b); }
SIMD_INL vfloat vf_andnot(vfloat a, vfloat b) { return _mm256_andnot_ps(a, b); }
SIMD_INL vint vi_and(vint i, vint j) { return _mm256_and_si256(i, j); }
SIMD_INL vint vi_or(vint i, vint j) { return _mm256_or_si256(i, j); }
SIMD_INL vint vi_xor(vint i, vint j) { return _mm256_xor_si256(i, j); }
SIMD_INL vint vi_andnot(vint i, vint j) { return _mm256_andnot_si256(i, j); }
SIMD_INL vint vf_as_vi(vfloat a) { return _mm256_castps_si256(a); }
SIMD_INL vfloat vi_as_vf(vint i) { return _mm256_castsi256_ps(i); }

/* ---- integer arithmetic */
SIMD_INL vint vi_add(vint i, vint j) { return _mm256_add_epi32(i, j); }
SIMD_INL vint vi_sub(vint i, vint j) { return _mm256_sub_epi32(i, j); }
SIMD_INL vint vi_mullo(vint i, vint j) { return _mm256_mullo_epi32(i, j); }
#define vi_slli(i, k) _mm256_slli_epi32(i, k)
#define vi_srli(i, k) _mm256_srli_epi32(i, k)
#define vi_srai(i, k) _mm256_srai_epi32(i, k)
SIMD_INL vint vi_sll(vint i, int k) { return _mm256_sll_epi32(i, _mm_cvtsi32_si128(k)); }
SIMD_INL vint vi_srl(vint i, int k) { return _mm256_srl_epi32(i, _mm_cvtsi32_si128(k)); }

/* ---- conversions */
SIMD_INL vfloat vf_from_vi(vint i) { return _mm256_cvtepi32_ps(i); }
SIMD_INL vint vi_from_vf_trunc(vfloat a) { return _mm256_cvttps_epi32(a); }
SIMD_INL vint vi_from_vf_round(vfloat a) { return _mm256_cvtps_epi32(a); }

/* ---- masks */
SIMD_INL vmask vm_and(vmask m, vmask n) { return _mm256_and_ps(m, n); }
SIMD_INL vmask vm_or(vmask m, vmask n) { return _mm256_or_ps(m, n); }
SIMD_INL vmask vm_andnot(vmask m, vmask n) { return _mm256_andnot_ps(m, n); }
SIMD_INL vmask vm_not(vmask m) { return _mm256_xor_ps(m, _mm256_castsi256_ps(_mm256_set1_epi32(-1))); }
SIMD_INL unsigned vm_bits(vmask m) { return (unsigned)_mm256_movemask_ps(m); }
SIMD_INL vmask vm_from_bits(unsigned b) { return _mm256_castsi256_ps(simd__lanes_of(b)); }
SIMD_INL int vm_all(vmask m) { return _mm256_movemask_ps(m) == 0xFF; }
SIMD_INL int vm_any(vmask m) { return _mm256_movemask_ps(m) != 0; }


/* ---- raster ops (src/raster's scan; simd.h "RASTER OPS") */
SIMD_INL unsigned vi_sign_bits(vint i) { return (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(i)); }
SIMD_INL void vb_store_bits(uint8_t *p, unsigned bits)
{
    simd__bytes_store_bits(p, bits, SIMD_FULL, SIMD_W);
}
/* The three vectors to the stack, then three scalar stores per set bit
 * (raster measured six 128-bit vmaskmovps slower on AMD, and an
 * interleave with vector stores of whole runs slower too). */
SIMD_INL void vf_store3_bits(float *p, unsigned bits, vfloat x, vfloat y, vfloat z)
{
    _Alignas(32) float t[3][8];
    _mm256_store_ps(t[0], x); _mm256_store_ps(t[1], y); _mm256_store_ps(t[2], z);
    simd__store3_lanes(p, bits & SIMD_FULL, SIMD_W, t);
}


/* doubles (raster's plane set-up): VD_W = 4 lanes */
#define VD_W 4
typedef __m256d vdouble;
SIMD_INL vdouble vd_set1(double x) { return _mm256_set1_pd(x); }
SIMD_INL vdouble vd_loadu(const double *p) { return _mm256_loadu_pd(p); }
SIMD_INL void vd_storeu(double *p, vdouble a) { _mm256_storeu_pd(p, a); }
SIMD_INL vdouble vd_add(vdouble a, vdouble b) { return _mm256_add_pd(a, b); }
SIMD_INL vdouble vd_sub(vdouble a, vdouble b) { return _mm256_sub_pd(a, b); }
SIMD_INL vdouble vd_mul(vdouble a, vdouble b) { return _mm256_mul_pd(a, b); }
SIMD_INL vdouble vd_div(vdouble a, vdouble b) { return _mm256_div_pd(a, b); }
SIMD_INL vdouble vd_max(vdouble a, vdouble b) { return _mm256_max_pd(a, b); }
SIMD_INL vdouble vd_load_f(const float *p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }
SIMD_INL void vd_store_f(float *p, vdouble a) { _mm_storeu_ps(p, _mm256_cvtpd_ps(a)); }


/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS") */
SIMD_INL vdouble vd_sqrt(vdouble a) { return _mm256_sqrt_pd(a); }
SIMD_INL vint vi_min(vint i, vint j) { return _mm256_min_epi32(i, j); }
SIMD_INL vint vi_max(vint i, vint j) { return _mm256_max_epi32(i, j); }
SIMD_INL vdouble vd_from_vf(vfloat a, int h)
{
    return _mm256_cvtps_pd(h ? _mm256_extractf128_ps(a, 1) : _mm256_castps256_ps128(a));
}
SIMD_INL vdouble vd_from_vi(vint i, int h)
{
    return _mm256_cvtepi32_pd(h ? _mm256_extracti128_si256(i, 1) : _mm256_castsi256_si128(i));
}
SIMD_INL vfloat vf_from_vd(vdouble lo, vdouble hi)
{
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(lo)), _mm256_cvtpd_ps(hi), 1);
}
SIMD_INL unsigned vd_gt_bits(vdouble a, vdouble b)
{
    return (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(a, b, _CMP_GT_OQ));
}
/* ---- raster edge ops (x86 only; simd.h "RASTER EDGE OPS") */
#define SIMD_HAS_VL 1
typedef __m256i vlong;   /* VD_W = 4 int64 lanes */
SIMD_INL vlong vl_zero(void) { return _mm256_setzero_si256(); }
SIMD_INL vlong vl_from_vi(vint i, int h)
{
    return _mm256_cvtepi32_epi64(h ? _mm256_extracti128_si256(i, 1) : _mm256_castsi256_si128(i));
}
SIMD_INL vlong vl_add(vlong a, vlong b) { return _mm256_add_epi64(a, b); }
SIMD_INL vlong vl_sub(vlong a, vlong b) { return _mm256_sub_epi64(a, b); }
SIMD_INL vlong vl_or(vlong a, vlong b) { return _mm256_or_si256(a, b); }
SIMD_INL vlong vl_mul32(vlong a, vlong b) { return _mm256_mul_epi32(a, b); }
#define vl_slli(a, k) _mm256_slli_epi64(a, k)
SIMD_INL unsigned vl_sign_bits(vlong a) { return (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(a)); }
/* the int32 flags of half h widened: -1 (all ones) -> subtract 0, else 1 */
SIMD_INL vlong vl_dec_unless(vlong a, vmask m, int h)
{
    const __m256i one = _mm256_andnot_si256(_mm256_castps_si256(m), _mm256_set1_epi32(1));
    return _mm256_sub_epi64(a, vl_from_vi(one, h));
}
SIMD_INL vlong vl_zip_lo(vlong a, vlong b) { return _mm256_unpacklo_epi64(a, b); }
SIMD_INL vlong vl_zip_hi(vlong a, vlong b) { return _mm256_unpackhi_epi64(a, b); }
SIMD_INL void vl_store(int64_t *p, vlong a) { _mm256_store_si256((__m256i *)(void *)p, a); }
/* 8 3-bit lane numbers packed in one int, spread by a variable shift */
SIMD_INL vint vi_compress_lanes(unsigned bits)
{
    uint32_t p = 0;
    int k = 0;
    for (unsigned x = bits & SIMD_FULL; x; x &= x - 1, k++)
        p |= (uint32_t)__builtin_ctz(x) << (3 * k);
    const __m256i sh = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    return _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32((int)p), sh), _mm256_set1_epi32(7));
}
/* ---- row-cache ops (src/fuse's composite; simd.h "ROW-CACHE OPS") */
SIMD_INL vint vi_permute(vint i, vint idx) { return _mm256_permutevar8x32_epi32(i, idx); }
SIMD_INL vint vi_gather(const int32_t *p, vint idx)
{
    return _mm256_i32gather_epi32((const int *)(const void *)p, idx, 4);
}
SIMD_INL vint vh_zip_lo(vint i, vint j) { return _mm256_unpacklo_epi16(i, j); }
SIMD_INL vint vh_zip_hi(vint i, vint j) { return _mm256_unpackhi_epi16(i, j); }
SIMD_INL vint vh_madd(vint i, vint j) { return _mm256_madd_epi16(i, j); }
SIMD_INL vint vh_packus32(vint i, vint j) { return _mm256_packus_epi32(i, j); }
SIMD_INL vint vh_mulhi(vint i, vint j) { return _mm256_mulhi_epu16(i, j); }


/* ---- refine ops (src/fuse's band refinement, fuse_refine_simd.inl;
 * simd.h "REFINE OPS") */
#define VB_W 32
#define VH_W 16
SIMD_INL vint vb_loadu(const uint8_t *p) { return _mm256_loadu_si256((const __m256i *)(const void *)p); }
SIMD_INL void vb_storeu(uint8_t *p, vint i) { _mm256_storeu_si256((__m256i *)(void *)p, i); }
SIMD_INL uint64_t vb_sign_bits(vint i) { return (uint64_t)(uint32_t)_mm256_movemask_epi8(i); }
SIMD_INL vint vb_sign_fill(vint i) { return _mm256_cmpgt_epi8(_mm256_setzero_si256(), i); }
SIMD_INL vint vh_load_u8(const uint8_t *p)
{
    return _mm256_cvtepu8_epi16(_mm_loadu_si128((const __m128i *)(const void *)p));
}
SIMD_INL vint vh_loadu(const uint16_t *p) { return _mm256_loadu_si256((const __m256i *)(const void *)p); }
SIMD_INL void vh_storeu(uint16_t *p, vint i) { _mm256_storeu_si256((__m256i *)(void *)p, i); }
SIMD_INL vint vh_min_u(vint i, vint j) { return _mm256_min_epu16(i, j); }
SIMD_INL vint vh_adds_u(vint i, vint j) { return _mm256_adds_epu16(i, j); }
/* i <= j unsigned  <=>  max(i, j) == j */
SIMD_INL int vh_any_leu(vint i, vint j)
{
    const __m256i le = _mm256_cmpeq_epi16(_mm256_max_epu16(i, j), j);
    return !_mm256_testz_si256(le, le);
}
SIMD_INL vint vi_load_u16(const uint16_t *p)
{
    return _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)p));
}
/* the chamfer's running minima: lane l takes lane l - k (up; the lanes
 * below k take the fill f) by a 128-bit block permute and a byte align,
 * and lane l + k (dn) the same mirrored. VH__RUNMIN3 writes both: SH the
 * shift, the rest the 16 lanes the carry c is added to, 3 (l + 1) (up) or
 * 3 (16 - l) (dn). */
#define VH__UP(t, f, k) _mm256_alignr_epi8(t, _mm256_permute2x128_si256(t, f, 0x02), 16 - 2 * (k))
#define VH__DN(t, f, k) _mm256_alignr_epi8(_mm256_permute2x128_si256(t, f, 0x31), t, 2 * (k))
#define VH__RUNMIN3(name, SH, ...)                                                      \
    SIMD_INL vint name(vint i, unsigned c)                                              \
    {                                                                                   \
        const __m256i f = _mm256_set1_epi16(-1);                                        \
        __m256i t = i;                                                                  \
        t = _mm256_min_epu16(t, _mm256_adds_epu16(SH(t, f, 1), _mm256_set1_epi16(3)));  \
        t = _mm256_min_epu16(t, _mm256_adds_epu16(SH(t, f, 2), _mm256_set1_epi16(6)));  \
        t = _mm256_min_epu16(t, _mm256_adds_epu16(SH(t, f, 4), _mm256_set1_epi16(12))); \
        t = _mm256_min_epu16(t, _mm256_adds_epu16(SH(t, f, 8), _mm256_set1_epi16(24))); \
        const __m256i l3 = _mm256_setr_epi16(__VA_ARGS__);                              \
        return _mm256_min_epu16(t, _mm256_adds_epu16(_mm256_set1_epi16((short)c), l3)); \
    }
VH__RUNMIN3(vh_runmin3_up, VH__UP, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33, 36, 39, 42, 45, 48)
VH__RUNMIN3(vh_runmin3_dn, VH__DN, 48, 45, 42, 39, 36, 33, 30, 27, 24, 21, 18, 15, 12, 9, 6, 3)
#undef VH__RUNMIN3
#undef VH__UP
#undef VH__DN


/* ---- reprojection ops (src/pipe's taps, pipe_reproj_simd.inl; simd.h
 * "REPROJ OPS") */
SIMD_INL vfloat vf_gather(const float *p, vint idx) { return _mm256_i32gather_ps(p, idx, 4); }
SIMD_INL vfloat vf_gather_m(const float *p, vint idx, vmask m)
{
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), p, idx, m, 4);
}
SIMD_INL vint vi_gather_u8x4(const uint8_t *p, vint idx)
{
    return _mm256_i32gather_epi32((const int *)(const void *)p, idx, 1);
}
/* byte 0 of each dword to the low 4 bytes of each 128-bit half, joined */
SIMD_INL void vi_store_u8(uint8_t *p, vint i)
{
    const __m256i t = _mm256_shuffle_epi8(
        i, _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,
                            0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1));
    _mm_storel_epi64((__m128i *)(void *)p,
                     _mm_unpacklo_epi32(_mm256_castsi256_si128(t), _mm256_extracti128_si256(t, 1)));
}

#else
#error "simd_avx2.h: another implementation of the vector layer is already included"
#endif
