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
typedef __m256d vdouble;   /* raster's doubles: VD_W = 4 lanes */
#define VD_W 4

/* what the x86 ISAs write alike: simd_x86.h, with this ISA's intrinsic
 * names and its halves of a vector (h 0: the low half) and their join */
#define SIMD_X86_P _mm256
#define SIMD_X86_B 256
#define SIMD_X86_HALF_PS(a, h) ((h) ? _mm256_extractf128_ps(a, 1) : _mm256_castps256_ps128(a))
#define SIMD_X86_HALF_SI(i, h) ((h) ? _mm256_extracti128_si256(i, 1) : _mm256_castsi256_si128(i))
#define SIMD_X86_JOIN_PS(lo, hi) _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1)
#include "simd_x86.h"

/* ---- memory */
SIMD_INL vint vi_lanes(void) { return _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7); }

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

/* ---- shuffles */
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
SIMD_INL vfloat vf_floor(vfloat a) { return _mm256_round_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }

/* ---- selects, bits (blendv reads the mask's sign bit: masks are
 * all-ones / all-zero lanes, so that is the lane flag) */
SIMD_INL vfloat vf_sel(vmask m, vfloat a, vfloat b) { return _mm256_blendv_ps(b, a, m); }
SIMD_INL vint vi_sel(vmask m, vint i, vint j)
{
    return _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(j), _mm256_castsi256_ps(i), m));
}

/* ---- masks */
SIMD_INL vmask vm_from_bits(unsigned b) { return _mm256_castsi256_ps(simd__lanes_of(b)); }


/* ---- doubles (raster's plane set-up) */
SIMD_INL vdouble vd_load_f(const float *p) { return _mm256_cvtps_pd(_mm_loadu_ps(p)); }
SIMD_INL void vd_store_f(float *p, vdouble a) { _mm_storeu_ps(p, _mm256_cvtpd_ps(a)); }


/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS") */
SIMD_INL unsigned vd_gt_bits(vdouble a, vdouble b)
{
    return (unsigned)_mm256_movemask_pd(_mm256_cmp_pd(a, b, _CMP_GT_OQ));
}
/* ---- raster edge ops (x86 only; simd.h "RASTER EDGE OPS") */
SIMD_INL unsigned vl_sign_bits(vlong a) { return (unsigned)_mm256_movemask_pd(_mm256_castsi256_pd(a)); }
/* the int32 flags of half h widened: -1 (all ones) -> subtract 0, else 1 */
SIMD_INL vlong vl_dec_unless(vlong a, vmask m, int h)
{
    const __m256i one = _mm256_andnot_si256(_mm256_castps_si256(m), _mm256_set1_epi32(1));
    return _mm256_sub_epi64(a, vl_from_vi(one, h));
}
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


/* ---- refine ops (src/fuse's band refinement, fuse_refine_simd.inl;
 * simd.h "REFINE OPS") */
#define VB_W 32
#define VH_W 16
SIMD_INL uint64_t vb_sign_bits(vint i) { return (uint64_t)(uint32_t)_mm256_movemask_epi8(i); }
SIMD_INL vint vh_load_u8(const uint8_t *p)
{
    return _mm256_cvtepu8_epi16(_mm_loadu_si128((const __m128i *)(const void *)p));
}
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
/* the chamfer's running minima (simd_x86.h's SIMD_X86_RUNMIN3): lane l
 * takes lane l - k (up; the lanes below k take the fill f) by a 128-bit
 * block permute and a byte align, and lane l + k (dn) the same mirrored */
#define VH__UP(t, f, k) _mm256_alignr_epi8(t, _mm256_permute2x128_si256(t, f, 0x02), 16 - 2 * (k))
#define VH__DN(t, f, k) _mm256_alignr_epi8(_mm256_permute2x128_si256(t, f, 0x31), t, 2 * (k))
SIMD_X86_RUNMIN3(vh_runmin3_up, VH__UP, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33, 36, 39, 42, 45, 48)
SIMD_X86_RUNMIN3(vh_runmin3_dn, VH__DN, 48, 45, 42, 39, 36, 33, 30, 27, 24, 21, 18, 15, 12, 9, 6, 3)
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
