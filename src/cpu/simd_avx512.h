/* simd_avx512.h - the vector layer (simd.h) on AVX-512 F/BW/DQ/VL, 16
 * lanes (files built with -mavx512f -mavx512bw -mavx512dq -mavx512vl
 * -mavx2 -mf16c, no -mfma). Masks are __mmask16: selects, masked loads
 * and stores are one instruction. Include once per file. */
#ifndef EGOFUSE_SIMD_IMPL
#define EGOFUSE_SIMD_IMPL "avx512"
#if !defined(__AVX512F__) || !defined(__AVX512BW__) || !defined(__AVX512DQ__) || \
    !defined(__AVX512VL__)
#error "simd_avx512.h: AVX-512 F/BW/DQ/VL is not enabled for this file (-mavx512*)"
#endif

#include <immintrin.h>

#include "simd.h"

#define SIMD_W 16
#define SIMD_ISA EF_ISA_AVX512
#define SIMD_NAME "avx512"
#define SIMD_FN(name) SIMD_CAT(name, avx512)
#define SIMD_ALIGN 64
#define SIMD_FULL 0xFFFFu

typedef __m512 vfloat;
typedef __m512i vint;
typedef __mmask16 vmask;
typedef __m512d vdouble;   /* raster's doubles: VD_W = 8 lanes */
#define VD_W 8

/* what the x86 ISAs write alike: simd_x86.h, with this ISA's intrinsic
 * names and its halves of a vector (h 0: the low half) and their join */
#define SIMD_X86_P _mm512
#define SIMD_X86_B 512
#define SIMD_X86_HALF_PS(a, h) ((h) ? _mm512_extractf32x8_ps(a, 1) : _mm512_castps512_ps256(a))
#define SIMD_X86_HALF_SI(i, h) ((h) ? _mm512_extracti32x8_epi32(i, 1) : _mm512_castsi512_si256(i))
#define SIMD_X86_JOIN_PS(lo, hi) _mm512_insertf32x8(_mm512_castps256_ps512(lo), hi, 1)
#include "simd_x86.h"

/* ---- memory */
SIMD_INL vint vi_lanes(void)
{
    return _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
}
/* masked lanes are not accessed (fault suppression) */
SIMD_INL vint vi_load_u8(const uint8_t *p)
{
    return _mm512_cvtepu8_epi32(_mm_loadu_si128((const __m128i *)(const void *)p));
}

SIMD_INL void vi_store2(int32_t *p, vint i, vint j)
{
    const __m512i k0 = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
    const __m512i k1 = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
    _mm512_storeu_si512((void *)p, _mm512_permutex2var_epi32(i, k0, j));
    _mm512_storeu_si512((void *)(p + 16), _mm512_permutex2var_epi32(i, k1, j));
}

SIMD_INL vfloat vf_load_bits(const float *p, unsigned bits) { return _mm512_maskz_loadu_ps((__mmask16)bits, p); }
SIMD_INL void vf_store_bits(float *p, unsigned bits, vfloat a) { _mm512_mask_storeu_ps(p, (__mmask16)bits, a); }

/* x y z x y z ... (48 floats) <-> SoA. Component k of vertex v is float
 * 3v + k: register (3v+k)/16, lane (3v+k)%16; two mask blends gather a
 * component's lanes into one register, one permute orders them (the
 * masks and indices are those lane sets, tests/test_cpu_simd.c checks
 * every lane). */
SIMD_INL void vf_load3(const float *p, vfloat *x, vfloat *y, vfloat *z)
{
    const __m512 a = _mm512_loadu_ps(p), b = _mm512_loadu_ps(p + 16), c = _mm512_loadu_ps(p + 32);
    *x = _mm512_permutexvar_ps(_mm512_setr_epi32(0, 3, 6, 9, 12, 15, 2, 5, 8, 11, 14, 1, 4, 7, 10, 13),
                               _mm512_mask_blend_ps(0x2492, _mm512_mask_blend_ps(0x4924, a, b), c));
    *y = _mm512_permutexvar_ps(_mm512_setr_epi32(1, 4, 7, 10, 13, 0, 3, 6, 9, 12, 15, 2, 5, 8, 11, 14),
                               _mm512_mask_blend_ps(0x4924, _mm512_mask_blend_ps(0x9249, a, b), c));
    *z = _mm512_permutexvar_ps(_mm512_setr_epi32(2, 5, 8, 11, 14, 1, 4, 7, 10, 13, 0, 3, 6, 9, 12, 15),
                               _mm512_mask_blend_ps(0x9249, _mm512_mask_blend_ps(0x2492, a, b), c));
}

SIMD_INL void vf_store3(float *p, vfloat x, vfloat y, vfloat z)
{
    x = _mm512_permutexvar_ps(_mm512_setr_epi32(0, 11, 6, 1, 12, 7, 2, 13, 8, 3, 14, 9, 4, 15, 10, 5), x);
    y = _mm512_permutexvar_ps(_mm512_setr_epi32(5, 0, 11, 6, 1, 12, 7, 2, 13, 8, 3, 14, 9, 4, 15, 10), y);
    z = _mm512_permutexvar_ps(_mm512_setr_epi32(10, 5, 0, 11, 6, 1, 12, 7, 2, 13, 8, 3, 14, 9, 4, 15), z);
    _mm512_storeu_ps(p, _mm512_mask_blend_ps(0x4924, _mm512_mask_blend_ps(0x2492, x, y), z));
    _mm512_storeu_ps(p + 16, _mm512_mask_blend_ps(0x2492, _mm512_mask_blend_ps(0x9249, x, y), z));
    _mm512_storeu_ps(p + 32, _mm512_mask_blend_ps(0x9249, _mm512_mask_blend_ps(0x4924, x, y), z));
}

/* ---- shuffles */
/* 4 x 4 blocks: two rounds of vshuff32x4 */
SIMD_INL void vf_tr_blocks(const vfloat in[4], vfloat out[4])
{
    const __m512 abl = _mm512_shuffle_f32x4(in[0], in[1], 0x44);
    const __m512 cdl = _mm512_shuffle_f32x4(in[2], in[3], 0x44);
    const __m512 abh = _mm512_shuffle_f32x4(in[0], in[1], 0xEE);
    const __m512 cdh = _mm512_shuffle_f32x4(in[2], in[3], 0xEE);
    out[0] = _mm512_shuffle_f32x4(abl, cdl, 0x88);
    out[1] = _mm512_shuffle_f32x4(abl, cdl, 0xDD);
    out[2] = _mm512_shuffle_f32x4(abh, cdh, 0x88);
    out[3] = _mm512_shuffle_f32x4(abh, cdh, 0xDD);
}

/* an in-block transpose gives each lane's x y z (and a spare) in one
 * 128-bit block, stored with a 3-float mask */
SIMD_INL void vf_scatter3(float *out, const int32_t *dest, vfloat x, vfloat y, vfloat z)
{
    __m512 t[4];
    vf_tr4(x, y, z, z, t);   /* t[k], block J: lane 4J + k */
#define SIMD__SCAT(J, k) \
    _mm_mask_storeu_ps(out + 3 * (size_t)dest[4 * (J) + (k)], 0x7, _mm512_extractf32x4_ps(t[k], J));
#define SIMD__SCAT_BLOCK(J) SIMD__SCAT(J, 0) SIMD__SCAT(J, 1) SIMD__SCAT(J, 2) SIMD__SCAT(J, 3)
    SIMD__SCAT_BLOCK(0)
    SIMD__SCAT_BLOCK(1)
    SIMD__SCAT_BLOCK(2)
    SIMD__SCAT_BLOCK(3)
#undef SIMD__SCAT_BLOCK
#undef SIMD__SCAT
}

/* ---- float arithmetic (vf_neg_if: a masked xor) */
SIMD_INL vfloat vf_neg_if(vmask m, vfloat a) { return _mm512_mask_xor_ps(a, m, a, _mm512_set1_ps(-0.0f)); }
SIMD_INL vfloat vf_floor(vfloat a) { return _mm512_roundscale_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }

/* ---- compares (the float ones: simd_x86.h) */
SIMD_INL vmask vi_eq(vint i, vint j) { return _mm512_cmpeq_epi32_mask(i, j); }
SIMD_INL vmask vi_gt(vint i, vint j) { return _mm512_cmpgt_epi32_mask(i, j); }

/* ---- selects, bits */
SIMD_INL vfloat vf_sel(vmask m, vfloat a, vfloat b) { return _mm512_mask_blend_ps(m, b, a); }
SIMD_INL vfloat vf_selz(vmask m, vfloat a) { return _mm512_maskz_mov_ps(m, a); }
SIMD_INL vint vi_sel(vmask m, vint i, vint j) { return _mm512_mask_blend_epi32(m, j, i); }

/* ---- masks */
SIMD_INL vmask vm_and(vmask m, vmask n) { return (vmask)(m & n); }
SIMD_INL vmask vm_or(vmask m, vmask n) { return (vmask)(m | n); }
SIMD_INL vmask vm_andnot(vmask m, vmask n) { return (vmask)(~m & n); }
SIMD_INL vmask vm_not(vmask m) { return (vmask)~m; }
SIMD_INL unsigned vm_bits(vmask m) { return (unsigned)m; }
SIMD_INL vmask vm_from_bits(unsigned b) { return (vmask)b; }
SIMD_INL int vm_all(vmask m) { return m == (vmask)0xFFFF; }
SIMD_INL int vm_any(vmask m) { return m != 0; }


/* ---- raster ops (src/raster's scan; simd.h "RASTER OPS") */
SIMD_INL unsigned vi_sign_bits(vint i) { return (unsigned)_mm512_movepi32_mask(i); }
SIMD_INL void vb_store_bits(uint8_t *p, unsigned bits)
{
    _mm_mask_storeu_epi8(p, (__mmask16)bits, _mm_set1_epi8((char)-1));
}
/* vf_store3's interleave, each output vector stored under the mask of the
 * pixels its floats belong to (float f of vector o: pixel (16o + f) / 3),
 * made by one vptestmd against a table of those pixels' bits. */
static const int32_t simd__sel3[3][16] __attribute__((aligned(64))) = {
    { 1 << 0, 1 << 0, 1 << 0, 1 << 1, 1 << 1, 1 << 1, 1 << 2, 1 << 2,
      1 << 2, 1 << 3, 1 << 3, 1 << 3, 1 << 4, 1 << 4, 1 << 4, 1 << 5 },
    { 1 << 5, 1 << 5, 1 << 6, 1 << 6, 1 << 6, 1 << 7, 1 << 7, 1 << 7,
      1 << 8, 1 << 8, 1 << 8, 1 << 9, 1 << 9, 1 << 9, 1 << 10, 1 << 10 },
    { 1 << 10, 1 << 11, 1 << 11, 1 << 11, 1 << 12, 1 << 12, 1 << 12, 1 << 13,
      1 << 13, 1 << 13, 1 << 14, 1 << 14, 1 << 14, 1 << 15, 1 << 15, 1 << 15 },
};
SIMD_INL void vf_store3_bits(float *p, unsigned bits, vfloat x, vfloat y, vfloat z)
{
    const __m512i pb = _mm512_set1_epi32((int)(bits & SIMD_FULL));
    x = _mm512_permutexvar_ps(_mm512_setr_epi32(0, 11, 6, 1, 12, 7, 2, 13, 8, 3, 14, 9, 4, 15, 10, 5), x);
    y = _mm512_permutexvar_ps(_mm512_setr_epi32(5, 0, 11, 6, 1, 12, 7, 2, 13, 8, 3, 14, 9, 4, 15, 10), y);
    z = _mm512_permutexvar_ps(_mm512_setr_epi32(10, 5, 0, 11, 6, 1, 12, 7, 2, 13, 8, 3, 14, 9, 4, 15), z);
    _mm512_mask_storeu_ps(p, _mm512_test_epi32_mask(pb, _mm512_load_si512(simd__sel3[0])),
                          _mm512_mask_blend_ps(0x4924, _mm512_mask_blend_ps(0x2492, x, y), z));
    _mm512_mask_storeu_ps(p + 16, _mm512_test_epi32_mask(pb, _mm512_load_si512(simd__sel3[1])),
                          _mm512_mask_blend_ps(0x2492, _mm512_mask_blend_ps(0x9249, x, y), z));
    _mm512_mask_storeu_ps(p + 32, _mm512_test_epi32_mask(pb, _mm512_load_si512(simd__sel3[2])),
                          _mm512_mask_blend_ps(0x9249, _mm512_mask_blend_ps(0x4924, x, y), z));
}


/* ---- doubles (raster's plane set-up) */
SIMD_INL vdouble vd_load_f(const float *p) { return _mm512_cvtps_pd(_mm256_loadu_ps(p)); }
SIMD_INL void vd_store_f(float *p, vdouble a) { _mm256_storeu_ps(p, _mm512_cvtpd_ps(a)); }


/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS") */
SIMD_INL unsigned vd_gt_bits(vdouble a, vdouble b)
{
    return (unsigned)_mm512_cmp_pd_mask(a, b, _CMP_GT_OQ);
}
/* ---- raster edge ops (x86 only; simd.h "RASTER EDGE OPS") */
SIMD_INL unsigned vl_sign_bits(vlong a) { return (unsigned)_mm512_movepi64_mask(a); }
/* one masked subtract: the lanes of half h whose flag is clear */
SIMD_INL vlong vl_dec_unless(vlong a, vmask m, int h)
{
    return _mm512_mask_sub_epi64(a, (__mmask8)~(m >> (8 * h)), a, _mm512_set1_epi64(1));
}
SIMD_INL vint vi_compress_lanes(unsigned bits)
{
    return _mm512_maskz_compress_epi32((__mmask16)bits, vi_lanes());
}
/* ---- row-cache ops (src/fuse's composite; simd.h "ROW-CACHE OPS") */
SIMD_INL vint vi_permute(vint i, vint idx) { return _mm512_permutexvar_epi32(idx, i); }
SIMD_INL vint vi_gather(const int32_t *p, vint idx)
{
    return _mm512_i32gather_epi32(idx, (const void *)p, 4);
}


/* ---- refine ops (src/fuse's band refinement, fuse_refine_simd.inl;
 * simd.h "REFINE OPS"; fuse_refine_avx512.c keeps its own masked-row
 * algorithm) */
#define VB_W 64
#define VH_W 32
SIMD_INL uint64_t vb_sign_bits(vint i) { return (uint64_t)_mm512_movepi8_mask(i); }
SIMD_INL vint vb_sign_fill(vint i) { return _mm512_movm_epi8(_mm512_movepi8_mask(i)); }
SIMD_INL vint vh_load_u8(const uint8_t *p)
{
    return _mm512_cvtepu8_epi16(_mm256_loadu_si256((const __m256i *)(const void *)p));
}
SIMD_INL int vh_any_leu(vint i, vint j) { return _mm512_cmple_epu16_mask(i, j) != 0; }
SIMD_INL vint vi_load_u16(const uint16_t *p)
{
    return _mm512_cvtepu16_epi32(_mm256_loadu_si256((const __m256i *)(const void *)p));
}
/* the chamfer's running minima: lane l takes lane l - k (up) or l + k
 * (dn) by vpermw, the lanes beyond the vector 65535 (the mask's blend) */
SIMD_INL __m512i vh__lane_idx(int k)
{
    static const uint16_t iota[32] = { 0,  1,  2,  3,  4,  5,  6,  7,  8,  9,  10,
                                       11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21,
                                       22, 23, 24, 25, 26, 27, 28, 29, 30, 31 };
    return _mm512_sub_epi16(_mm512_loadu_si512((const void *)iota), _mm512_set1_epi16((short)k));
}
SIMD_INL vint vh_runmin3_up(vint i, unsigned c)
{
    const __m512i f = _mm512_set1_epi16(-1);
    __m512i t = i;
    for (int k = 1, s = 3; k < 32; k *= 2, s *= 2)
        t = _mm512_min_epu16(t, _mm512_adds_epu16(_mm512_mask_permutexvar_epi16(
                                                      f, (__mmask32)(0xFFFFFFFFu << k),
                                                      vh__lane_idx(k), t),
                                                  _mm512_set1_epi16((short)s)));
    const __m512i l3 = _mm512_mullo_epi16(vh__lane_idx(-1), _mm512_set1_epi16(3));   /* 3 (l + 1) */
    return _mm512_min_epu16(t, _mm512_adds_epu16(_mm512_set1_epi16((short)c), l3));
}
SIMD_INL vint vh_runmin3_dn(vint i, unsigned c)
{
    const __m512i f = _mm512_set1_epi16(-1);
    __m512i t = i;
    for (int k = 1, s = 3; k < 32; k *= 2, s *= 2)
        t = _mm512_min_epu16(t, _mm512_adds_epu16(_mm512_mask_permutexvar_epi16(
                                                      f, (__mmask32)(0xFFFFFFFFu >> k),
                                                      vh__lane_idx(-k), t),
                                                  _mm512_set1_epi16((short)s)));
    /* 3 (32 - l) */
    const __m512i l3 = _mm512_mullo_epi16(_mm512_sub_epi16(_mm512_set1_epi16(32), vh__lane_idx(0)),
                                          _mm512_set1_epi16(3));
    return _mm512_min_epu16(t, _mm512_adds_epu16(_mm512_set1_epi16((short)c), l3));
}


/* ---- reprojection ops (src/pipe's taps, pipe_reproj_simd.inl; simd.h
 * "REPROJ OPS") */
SIMD_INL vfloat vf_gather(const float *p, vint idx) { return _mm512_i32gather_ps(idx, (const void *)p, 4); }
SIMD_INL vfloat vf_gather_m(const float *p, vint idx, vmask m)
{
    return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), m, idx, (const void *)p, 4);
}
SIMD_INL vint vi_gather_u8x4(const uint8_t *p, vint idx)
{
    return _mm512_i32gather_epi32(idx, (const void *)p, 1);
}
SIMD_INL void vi_store_u8(uint8_t *p, vint i)
{
    _mm_storeu_si128((__m128i *)(void *)p, _mm512_cvtepi32_epi8(i));
}

#else
#error "simd_avx512.h: another implementation of the vector layer is already included"
#endif
