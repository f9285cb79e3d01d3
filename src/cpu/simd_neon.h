/* simd_neon.h - the vector layer (simd.h) on AArch64 Advanced SIMD (NEON),
 * 4 lanes, native arm_neon.h (why not SIMDe: docs/portability.md). NEON
 * is the aarch64 baseline: no flag. Masks are uint32x4_t of all-ones /
 * all-zero lanes.
 *
 * Where NEON's own instruction differs from the contract (x86's
 * semantics), the difference is handled here, once:
 *   min/max     FMIN/FMAX propagate NaN and order -0 < +0; the contract's
 *               a < b ? a : b is a compare and a bit select (2 instr.)
 *   float->int  FCVTZS/FCVTNS saturate and give 0 for NaN; the contract
 *               wants INT32_MIN there: a range compare and a select
 *   div, sqrt   FDIV/FSQRT are IEEE correctly rounded on aarch64 (not the
 *               ARMv7 estimates): used as they are
 *   denormals   the default FPCR has FZ = 0 (no flush), like x86's MXCSR
 *   contraction -ffp-contract=off (Makefile): no FMLA is formed from
 *               vmulq + vaddq
 *   default NaN 0x7FC00000 (x86: 0xFFC00000): simd.h, "NaN created"
 * Include once per file. */
#ifndef EGOFUSE_SIMD_IMPL
#define EGOFUSE_SIMD_IMPL "neon"
#if !defined(__aarch64__) || !defined(__ARM_NEON)
#error "simd_neon.h: AArch64 NEON is not available for this file"
#endif

#include <arm_neon.h>
#include <stddef.h>
#include <string.h>

#include "simd.h"

#define SIMD_W 4
#define SIMD_ISA EF_ISA_NEON
#define SIMD_NAME "neon"
#define SIMD_FN(name) SIMD_CAT(name, neon)
#define SIMD_ALIGN 16
#define SIMD_FULL 0xFu

typedef float32x4_t vfloat;
typedef int32x4_t vint;
typedef uint32x4_t vmask;

/* ---- memory */
SIMD_INL vfloat vf_set1(float x) { return vdupq_n_f32(x); }
SIMD_INL vint vi_set1(int32_t x) { return vdupq_n_s32(x); }
SIMD_INL vfloat vf_zero(void) { return vdupq_n_f32(0.0f); }
SIMD_INL vint vi_zero(void) { return vdupq_n_s32(0); }
SIMD_INL vint vi_lanes(void)
{
    static const int32_t l[4] = { 0, 1, 2, 3 };
    return vld1q_s32(l);
}
SIMD_INL vfloat vf_load(const float *p) { return vld1q_f32(p); }
SIMD_INL vfloat vf_loadu(const float *p) { return vld1q_f32(p); }
SIMD_INL void vf_store(float *p, vfloat a) { vst1q_f32(p, a); }
SIMD_INL void vf_storeu(float *p, vfloat a) { vst1q_f32(p, a); }
SIMD_INL vint vi_load(const int32_t *p) { return vld1q_s32(p); }
SIMD_INL vint vi_loadu(const int32_t *p) { return vld1q_s32(p); }
SIMD_INL void vi_store(int32_t *p, vint i) { vst1q_s32(p, i); }
SIMD_INL void vi_storeu(int32_t *p, vint i) { vst1q_s32(p, i); }

SIMD_INL vint vi_load_u8(const uint8_t *p)
{
    uint32_t t;
    memcpy(&t, p, 4);
    const uint16x8_t h = vmovl_u8(vreinterpret_u8_u32(vdup_n_u32(t)));
    return vreinterpretq_s32_u32(vmovl_u16(vget_low_u16(h)));
}

SIMD_INL void vi_store2(int32_t *p, vint i, vint j)
{
    int32x4x2_t t;
    t.val[0] = i;
    t.val[1] = j;
    vst2q_s32(p, t);   /* ST2: the interleaving store */
}

/* lane by lane: NEON has no masked load or store */
SIMD_INL vfloat vf_load_bits(const float *p, unsigned bits)
{
    if ((bits & SIMD_FULL) == SIMD_FULL) return vld1q_f32(p);
    vfloat r = vdupq_n_f32(0.0f);
    if (bits & 1u) r = vld1q_lane_f32(p, r, 0);
    if (bits & 2u) r = vld1q_lane_f32(p + 1, r, 1);
    if (bits & 4u) r = vld1q_lane_f32(p + 2, r, 2);
    if (bits & 8u) r = vld1q_lane_f32(p + 3, r, 3);
    return r;
}

SIMD_INL void vf_store_bits(float *p, unsigned bits, vfloat a)
{
    if ((bits & SIMD_FULL) == SIMD_FULL) { vst1q_f32(p, a); return; }
    if (bits & 1u) vst1q_lane_f32(p, a, 0);
    if (bits & 2u) vst1q_lane_f32(p + 1, a, 1);
    if (bits & 4u) vst1q_lane_f32(p + 2, a, 2);
    if (bits & 8u) vst1q_lane_f32(p + 3, a, 3);
}

/* LD3 / ST3: de-interleaving loads and stores are native */
SIMD_INL void vf_load3(const float *p, vfloat *x, vfloat *y, vfloat *z)
{
    const float32x4x3_t t = vld3q_f32(p);
    *x = t.val[0]; *y = t.val[1]; *z = t.val[2];
}

SIMD_INL void vf_store3(float *p, vfloat x, vfloat y, vfloat z)
{
    float32x4x3_t t;
    t.val[0] = x; t.val[1] = y; t.val[2] = z;
    vst3q_f32(p, t);
}

SIMD_INL void vf_scatter3(float *out, const int32_t *dest, vfloat x, vfloat y, vfloat z)
{
    float32x4x3_t t;
    t.val[0] = x; t.val[1] = y; t.val[2] = z;
    vst3q_lane_f32(out + 3 * (size_t)dest[0], t, 0);
    vst3q_lane_f32(out + 3 * (size_t)dest[1], t, 1);
    vst3q_lane_f32(out + 3 * (size_t)dest[2], t, 2);
    vst3q_lane_f32(out + 3 * (size_t)dest[3], t, 3);
}

/* ---- float arithmetic */
SIMD_INL vfloat vf_add(vfloat a, vfloat b) { return vaddq_f32(a, b); }
SIMD_INL vfloat vf_sub(vfloat a, vfloat b) { return vsubq_f32(a, b); }
SIMD_INL vfloat vf_mul(vfloat a, vfloat b) { return vmulq_f32(a, b); }
SIMD_INL vfloat vf_div(vfloat a, vfloat b) { return vdivq_f32(a, b); }
SIMD_INL vfloat vf_sqrt(vfloat a) { return vsqrtq_f32(a); }
/* x86's rule, not FMIN/FMAX's */
SIMD_INL vfloat vf_min(vfloat a, vfloat b) { return vbslq_f32(vcltq_f32(a, b), a, b); }
SIMD_INL vfloat vf_max(vfloat a, vfloat b) { return vbslq_f32(vcgtq_f32(a, b), a, b); }
SIMD_INL vfloat vf_neg(vfloat a) { return vnegq_f32(a); }   /* FNEG: sign flip, NaN too */
SIMD_INL vfloat vf_abs(vfloat a) { return vabsq_f32(a); }   /* FABS: sign clear, NaN too */
SIMD_INL vfloat vf_neg_if(vmask m, vfloat a)
{
    return vreinterpretq_f32_u32(veorq_u32(vreinterpretq_u32_f32(a), vandq_u32(m, vdupq_n_u32(0x80000000u))));
}
SIMD_INL vfloat vf_floor(vfloat a) { return vrndmq_f32(a); }   /* FRINTM: exact, keeps -0 */

/* ---- compares */
SIMD_INL vmask vf_eq(vfloat a, vfloat b) { return vceqq_f32(a, b); }
SIMD_INL vmask vf_ne(vfloat a, vfloat b) { return vmvnq_u32(vceqq_f32(a, b)); }
SIMD_INL vmask vf_lt(vfloat a, vfloat b) { return vcltq_f32(a, b); }
SIMD_INL vmask vf_le(vfloat a, vfloat b) { return vcleq_f32(a, b); }
SIMD_INL vmask vf_gt(vfloat a, vfloat b) { return vcgtq_f32(a, b); }
SIMD_INL vmask vf_ge(vfloat a, vfloat b) { return vcgeq_f32(a, b); }
SIMD_INL vmask vi_eq(vint i, vint j) { return vceqq_s32(i, j); }
SIMD_INL vmask vi_gt(vint i, vint j) { return vcgtq_s32(i, j); }

/* ---- selects, bits */
SIMD_INL vfloat vf_sel(vmask m, vfloat a, vfloat b) { return vbslq_f32(m, a, b); }
SIMD_INL vfloat vf_selz(vmask m, vfloat a)
{
    return vreinterpretq_f32_u32(vandq_u32(m, vreinterpretq_u32_f32(a)));
}
SIMD_INL vint vi_sel(vmask m, vint i, vint j) { return vbslq_s32(m, i, j); }
#define SIMD__FBIT(op, a, b) \
    vreinterpretq_f32_u32(op(vreinterpretq_u32_f32(a), vreinterpretq_u32_f32(b)))
SIMD_INL vfloat vf_and(vfloat a, vfloat b) { return SIMD__FBIT(vandq_u32, a, b); }
SIMD_INL vfloat vf_or(vfloat a, vfloat b) { return SIMD__FBIT(vorrq_u32, a, b); }
SIMD_INL vfloat vf_xor(vfloat a, vfloat b) { return SIMD__FBIT(veorq_u32, a, b); }
SIMD_INL vfloat vf_andnot(vfloat a, vfloat b) { return SIMD__FBIT(vbicq_u32, b, a); }   /* b & ~a */
#undef SIMD__FBIT
SIMD_INL vint vi_and(vint i, vint j) { return vandq_s32(i, j); }
SIMD_INL vint vi_or(vint i, vint j) { return vorrq_s32(i, j); }
SIMD_INL vint vi_xor(vint i, vint j) { return veorq_s32(i, j); }
SIMD_INL vint vi_andnot(vint i, vint j) { return vbicq_s32(j, i); }   /* j & ~i */
SIMD_INL vint vf_as_vi(vfloat a) { return vreinterpretq_s32_f32(a); }
SIMD_INL vfloat vi_as_vf(vint i) { return vreinterpretq_f32_s32(i); }

/* ---- integer arithmetic */
SIMD_INL vint vi_add(vint i, vint j) { return vaddq_s32(i, j); }
SIMD_INL vint vi_sub(vint i, vint j) { return vsubq_s32(i, j); }
SIMD_INL vint vi_mullo(vint i, vint j) { return vmulq_s32(i, j); }
#define vi_slli(i, k) vshlq_n_s32(i, k)
#define vi_srli(i, k) vreinterpretq_s32_u32(vshrq_n_u32(vreinterpretq_u32_s32(i), k))
#define vi_srai(i, k) vshrq_n_s32(i, k)
SIMD_INL vint vi_sll(vint i, int k) { return vshlq_s32(i, vdupq_n_s32(k)); }
SIMD_INL vint vi_srl(vint i, int k)
{
    return vreinterpretq_s32_u32(vshlq_u32(vreinterpretq_u32_s32(i), vdupq_n_s32(-k)));
}

/* ---- conversions: NaN and |a| >= 2^31 (but -2^31 itself) give INT32_MIN
 * as on x86; FACLT (|a| < 2^31) is false for NaN */
SIMD_INL vfloat vf_from_vi(vint i) { return vcvtq_f32_s32(i); }
SIMD_INL vint simd__cvt_fix(vfloat a, vint r)
{
    return vbslq_s32(vcaltq_f32(a, vdupq_n_f32(2147483648.0f)), r, vdupq_n_s32(INT32_MIN));
}
SIMD_INL vint vi_from_vf_trunc(vfloat a) { return simd__cvt_fix(a, vcvtq_s32_f32(a)); }
SIMD_INL vint vi_from_vf_round(vfloat a) { return simd__cvt_fix(a, vcvtnq_s32_f32(a)); }

/* ---- masks */
SIMD_INL vmask vm_and(vmask m, vmask n) { return vandq_u32(m, n); }
SIMD_INL vmask vm_or(vmask m, vmask n) { return vorrq_u32(m, n); }
SIMD_INL vmask vm_andnot(vmask m, vmask n) { return vbicq_u32(n, m); }
SIMD_INL vmask vm_not(vmask m) { return vmvnq_u32(m); }
SIMD_INL unsigned vm_bits(vmask m)
{
    static const uint32_t w[4] = { 1, 2, 4, 8 };
    return vaddvq_u32(vandq_u32(m, vld1q_u32(w)));
}
SIMD_INL vmask vm_from_bits(unsigned b)
{
    static const uint32_t w[4] = { 1, 2, 4, 8 };
    return vtstq_u32(vdupq_n_u32(b), vld1q_u32(w));
}
SIMD_INL int vm_all(vmask m) { return vminvq_u32(m) != 0; }
SIMD_INL int vm_any(vmask m) { return vmaxvq_u32(m) != 0; }

/* ---- zips (one block: ZIP1/ZIP2) */
SIMD_INL vint vi_zip_lo(vint i, vint j) { return vzip1q_s32(i, j); }
SIMD_INL vint vi_zip_hi(vint i, vint j) { return vzip2q_s32(i, j); }

/* ---- 16-bit lanes (simd.h, "16-bit lanes"; one 128-bit block) */
SIMD_INL vint vh_set1(int x) { return vreinterpretq_s32_u16(vdupq_n_u16((uint16_t)x)); }
SIMD_INL vint vh_add(vint i, vint j)
{
    return vreinterpretq_s32_u16(vaddq_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
SIMD_INL vint vh_sub(vint i, vint j)
{
    return vreinterpretq_s32_u16(vsubq_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
SIMD_INL vint vh_mullo(vint i, vint j)
{
    return vreinterpretq_s32_u16(vmulq_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
#define vh_srli(i, k) vreinterpretq_s32_u16(vshrq_n_u16(vreinterpretq_u16_s32(i), k))
SIMD_INL vint vh_from_u8_lo(vint i)
{
    return vreinterpretq_s32_u16(vmovl_u8(vget_low_u8(vreinterpretq_u8_s32(i))));
}
SIMD_INL vint vh_from_u8_hi(vint i)
{
    return vreinterpretq_s32_u16(vmovl_u8(vget_high_u8(vreinterpretq_u8_s32(i))));
}
/* x86's packus: each lane read as int16, saturated to 0..255 (SQXTUN) */
SIMD_INL vint vh_packus(vint i, vint j)
{
    return vreinterpretq_s32_u8(vcombine_u8(vqmovun_s16(vreinterpretq_s16_s32(i)),
                                            vqmovun_s16(vreinterpretq_s16_s32(j))));
}
SIMD_INL vint vh_bcast3(vint i)
{
    const uint16x8_t u = vreinterpretq_u16_s32(i);
    return vreinterpretq_s32_u16(vcombine_u16(vdup_lane_u16(vget_low_u16(u), 3),
                                              vdup_lane_u16(vget_high_u16(u), 3)));
}

/* ---- shuffles: TRN1/TRN2 on 32- then 64-bit elements */
SIMD_INL void vf_tr4(vfloat a, vfloat b, vfloat c, vfloat d, vfloat o[4])
{
    const float32x4_t ab0 = vtrn1q_f32(a, b), ab1 = vtrn2q_f32(a, b);
    const float32x4_t cd0 = vtrn1q_f32(c, d), cd1 = vtrn2q_f32(c, d);
    o[0] = vreinterpretq_f32_f64(vtrn1q_f64(vreinterpretq_f64_f32(ab0), vreinterpretq_f64_f32(cd0)));
    o[1] = vreinterpretq_f32_f64(vtrn1q_f64(vreinterpretq_f64_f32(ab1), vreinterpretq_f64_f32(cd1)));
    o[2] = vreinterpretq_f32_f64(vtrn2q_f64(vreinterpretq_f64_f32(ab0), vreinterpretq_f64_f32(cd0)));
    o[3] = vreinterpretq_f32_f64(vtrn2q_f64(vreinterpretq_f64_f32(ab1), vreinterpretq_f64_f32(cd1)));
}
/* one block: a copy */
SIMD_INL void vf_tr_blocks(const vfloat in[1], vfloat out[1]) { out[0] = in[0]; }


/* ---- raster ops (src/raster's scan; simd.h "RASTER OPS") */
SIMD_INL unsigned vi_sign_bits(vint i)
{
    static const uint32_t w[4] = { 1, 2, 4, 8 };
    return vaddvq_u32(vandq_u32(vreinterpretq_u32_s32(vshrq_n_s32(i, 31)), vld1q_u32(w)));
}
SIMD_INL void vb_store_bits(uint8_t *p, unsigned bits)
{
    simd__bytes_store_bits(p, bits, SIMD_FULL, SIMD_W);
}
SIMD_INL void vf_store3_bits(float *p, unsigned bits, vfloat x, vfloat y, vfloat z)
{
    float32x4x3_t t;
    t.val[0] = x; t.val[1] = y; t.val[2] = z;
    if (bits & 1u) vst3q_lane_f32(p, t, 0);
    if (bits & 2u) vst3q_lane_f32(p + 3, t, 1);
    if (bits & 4u) vst3q_lane_f32(p + 6, t, 2);
    if (bits & 8u) vst3q_lane_f32(p + 9, t, 3);
}


/* doubles (raster's plane set-up): VD_W = 2 lanes */
#define VD_W 2
typedef float64x2_t vdouble;
SIMD_INL vdouble vd_set1(double x) { return vdupq_n_f64(x); }
SIMD_INL vdouble vd_loadu(const double *p) { return vld1q_f64(p); }
SIMD_INL void vd_storeu(double *p, vdouble a) { vst1q_f64(p, a); }
SIMD_INL vdouble vd_add(vdouble a, vdouble b) { return vaddq_f64(a, b); }
SIMD_INL vdouble vd_sub(vdouble a, vdouble b) { return vsubq_f64(a, b); }
SIMD_INL vdouble vd_mul(vdouble a, vdouble b) { return vmulq_f64(a, b); }
SIMD_INL vdouble vd_div(vdouble a, vdouble b) { return vdivq_f64(a, b); }
/* x86's maxpd: a > b ? a : b (b when either is NaN, b for +-0) */
SIMD_INL vdouble vd_max(vdouble a, vdouble b) { return vbslq_f64(vcgtq_f64(a, b), a, b); }
SIMD_INL vdouble vd_load_f(const float *p) { return vcvt_f64_f32(vld1_f32(p)); }
SIMD_INL void vd_store_f(float *p, vdouble a) { vst1_f32(p, vcvt_f32_f64(a)); }


/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS") */
SIMD_INL vdouble vd_sqrt(vdouble a) { return vsqrtq_f64(a); }
SIMD_INL vint vi_min(vint i, vint j) { return vminq_s32(i, j); }
SIMD_INL vint vi_max(vint i, vint j) { return vmaxq_s32(i, j); }
SIMD_INL vdouble vd_from_vf(vfloat a, int h) { return vcvt_f64_f32(h ? vget_high_f32(a) : vget_low_f32(a)); }
/* int32 -> int64 -> double: exact (|i| < 2^31 < 2^53) */
SIMD_INL vdouble vd_from_vi(vint i, int h) { return vcvtq_f64_s64(vmovl_s32(h ? vget_high_s32(i) : vget_low_s32(i))); }
SIMD_INL vfloat vf_from_vd(vdouble lo, vdouble hi) { return vcombine_f32(vcvt_f32_f64(lo), vcvt_f32_f64(hi)); }
SIMD_INL unsigned vd_gt_bits(vdouble a, vdouble b)
{
    const uint64x2_t g = vcgtq_f64(a, b);
    return (unsigned)(vgetq_lane_u64(g, 0) & 1u) | ((unsigned)(vgetq_lane_u64(g, 1) & 1u) << 1);
}

/* ---- row-cache ops (src/fuse's composite; simd.h "ROW-CACHE OPS") */
/* TBL on bytes: lane l's four bytes from 4 (idx[l] & 3) + 0..3 */
SIMD_INL vint vi_permute(vint i, vint idx)
{
    const uint32x4_t b = vmlaq_n_u32(vdupq_n_u32(0x03020100u),
                                     vandq_u32(vreinterpretq_u32_s32(idx), vdupq_n_u32(3)),
                                     0x04040404u);
    return vreinterpretq_s32_u8(vqtbl1q_u8(vreinterpretq_u8_s32(i), vreinterpretq_u8_u32(b)));
}
SIMD_INL vint vi_gather(const int32_t *p, vint idx)
{
    int32x4_t r = vdupq_n_s32(p[vgetq_lane_s32(idx, 0)]);
    r = vsetq_lane_s32(p[vgetq_lane_s32(idx, 1)], r, 1);
    r = vsetq_lane_s32(p[vgetq_lane_s32(idx, 2)], r, 2);
    return vsetq_lane_s32(p[vgetq_lane_s32(idx, 3)], r, 3);
}
SIMD_INL vint vh_zip_lo(vint i, vint j)
{
    return vreinterpretq_s32_u16(vzip1q_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
SIMD_INL vint vh_zip_hi(vint i, vint j)
{
    return vreinterpretq_s32_u16(vzip2q_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
/* pmaddwd: the products of the int16 pairs, added in pairs (wrapping) */
SIMD_INL vint vh_madd(vint i, vint j)
{
    const int16x8_t a = vreinterpretq_s16_s32(i), b = vreinterpretq_s16_s32(j);
    const int32x4_t lo = vmull_s16(vget_low_s16(a), vget_low_s16(b));
    const int32x4_t hi = vmull_high_s16(a, b);
    return vreinterpretq_s32_u32(vreinterpretq_u32_s32(vpaddq_s32(lo, hi)));
}
/* packusdw: each int32 saturated to 0..65535 (SQXTUN) */
SIMD_INL vint vh_packus32(vint i, vint j)
{
    return vreinterpretq_s32_u16(vcombine_u16(vqmovun_s32(i), vqmovun_s32(j)));
}
/* the 32-bit products narrowed by 16 (SHRN) */
SIMD_INL vint vh_mulhi(vint i, vint j)
{
    const uint16x8_t a = vreinterpretq_u16_s32(i), b = vreinterpretq_u16_s32(j);
    return vreinterpretq_s32_u16(vcombine_u16(vshrn_n_u32(vmull_u16(vget_low_u16(a), vget_low_u16(b)), 16),
                                              vshrn_n_u32(vmull_high_u16(a, b), 16)));
}


/* ---- refine ops (src/fuse's band refinement, fuse_refine_simd.inl;
 * simd.h "REFINE OPS"): NEON's own u8 / u16 lanes; the byte sign bits
 * (x86 pmovmskb) by a weighted add of each half */
#define VB_W 16
#define VH_W 8
SIMD_INL vint vb_loadu(const uint8_t *p) { return vreinterpretq_s32_u8(vld1q_u8(p)); }
SIMD_INL void vb_storeu(uint8_t *p, vint i) { vst1q_u8(p, vreinterpretq_u8_s32(i)); }
SIMD_INL uint64_t vb_sign_bits(vint i)
{
    static const uint8_t w[16] = { 1, 2, 4, 8, 16, 32, 64, 128, 1, 2, 4, 8, 16, 32, 64, 128 };
    const uint8x16_t b = vandq_u8(vcltzq_s8(vreinterpretq_s8_s32(i)), vld1q_u8(w));
    return (uint64_t)vaddv_u8(vget_low_u8(b)) | (uint64_t)vaddv_u8(vget_high_u8(b)) << 8;
}
SIMD_INL vint vb_sign_fill(vint i) { return vreinterpretq_s32_u8(vcltzq_s8(vreinterpretq_s8_s32(i))); }
SIMD_INL vint vh_load_u8(const uint8_t *p) { return vreinterpretq_s32_u16(vmovl_u8(vld1_u8(p))); }
SIMD_INL vint vh_loadu(const uint16_t *p) { return vreinterpretq_s32_u16(vld1q_u16(p)); }
SIMD_INL void vh_storeu(uint16_t *p, vint i) { vst1q_u16(p, vreinterpretq_u16_s32(i)); }
SIMD_INL vint vh_min_u(vint i, vint j)
{
    return vreinterpretq_s32_u16(vminq_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
SIMD_INL vint vh_adds_u(vint i, vint j)
{
    return vreinterpretq_s32_u16(vqaddq_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j)));
}
SIMD_INL int vh_any_leu(vint i, vint j)
{
    return vmaxvq_u16(vcleq_u16(vreinterpretq_u16_s32(i), vreinterpretq_u16_s32(j))) != 0;
}
SIMD_INL vint vi_load_u16(const uint16_t *p) { return vreinterpretq_s32_u32(vmovl_u16(vld1_u16(p))); }
/* the chamfer's running minima: vext with a vector of 65535. VH__RUNMIN3
 * writes both directions: SH the shift of k lanes up (lane l takes l - k)
 * or down, the rest the 8 lanes the carry c is added to, 3 (l + 1) (up) or
 * 3 (8 - l) (dn). */
#define VH__STEP(t, sh, s) vminq_u16(t, vqaddq_u16(sh, vdupq_n_u16(s)))
#define VH__UP(t, f, k) vextq_u16(f, t, 8 - (k))
#define VH__DN(t, f, k) vextq_u16(t, f, k)
#define VH__RUNMIN3(name, SH, ...)                                                     \
    SIMD_INL vint name(vint i, unsigned c)                                             \
    {                                                                                  \
        const uint16x8_t f = vdupq_n_u16(0xFFFF);                                      \
        uint16x8_t t = vreinterpretq_u16_s32(i);                                       \
        t = VH__STEP(t, SH(t, f, 1), 3);                                               \
        t = VH__STEP(t, SH(t, f, 2), 6);                                               \
        t = VH__STEP(t, SH(t, f, 4), 12);                                              \
        static const uint16_t l3[8] = { __VA_ARGS__ };                                 \
        return vreinterpretq_s32_u16(vminq_u16(t, vqaddq_u16(vdupq_n_u16((uint16_t)c), \
                                                             vld1q_u16(l3))));         \
    }
VH__RUNMIN3(vh_runmin3_up, VH__UP, 3, 6, 9, 12, 15, 18, 21, 24)
VH__RUNMIN3(vh_runmin3_dn, VH__DN, 24, 21, 18, 15, 12, 9, 6, 3)
#undef VH__RUNMIN3
#undef VH__UP
#undef VH__DN
#undef VH__STEP


/* ---- reprojection ops (src/pipe's taps, pipe_reproj_simd.inl; simd.h
 * "REPROJ OPS"): no gather, lane by lane */
SIMD_INL vfloat vf_gather(const float *p, vint idx)
{
    float32x4_t r = vdupq_n_f32(p[vgetq_lane_s32(idx, 0)]);
    r = vsetq_lane_f32(p[vgetq_lane_s32(idx, 1)], r, 1);
    r = vsetq_lane_f32(p[vgetq_lane_s32(idx, 2)], r, 2);
    return vsetq_lane_f32(p[vgetq_lane_s32(idx, 3)], r, 3);
}
/* lane by lane, only the lanes in m read */
SIMD_INL vfloat vf_gather_m(const float *p, vint idx, vmask m)
{
    float r[4];
    for (int l = 0; l < 4; l++) r[l] = 0.0f;
    if (vgetq_lane_u32(m, 0)) r[0] = p[vgetq_lane_s32(idx, 0)];
    if (vgetq_lane_u32(m, 1)) r[1] = p[vgetq_lane_s32(idx, 1)];
    if (vgetq_lane_u32(m, 2)) r[2] = p[vgetq_lane_s32(idx, 2)];
    if (vgetq_lane_u32(m, 3)) r[3] = p[vgetq_lane_s32(idx, 3)];
    return vld1q_f32(r);
}
SIMD_INL vint vi_gather_u8x4(const uint8_t *p, vint idx)
{
    int32_t r[4];
    for (int l = 0; l < 4; l++) {
        const int32_t o = l == 0 ? vgetq_lane_s32(idx, 0) : l == 1 ? vgetq_lane_s32(idx, 1)
                          : l == 2 ? vgetq_lane_s32(idx, 2) : vgetq_lane_s32(idx, 3);
        __builtin_memcpy(&r[l], p + o, 4);
    }
    return vld1q_s32(r);
}
/* XTN twice: the low bytes */
SIMD_INL void vi_store_u8(uint8_t *p, vint i)
{
    const uint16x4_t h = vmovn_u32(vreinterpretq_u32_s32(i));
    const uint8x8_t b = vmovn_u16(vcombine_u16(h, h));
    vst1_lane_u32((uint32_t *)(void *)p, vreinterpret_u32_u8(b), 0);
}

#else
#error "simd_neon.h: another implementation of the vector layer is already included"
#endif
