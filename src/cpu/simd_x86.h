/* simd_x86.h - the operations of the vector layer (simd.h) that the x86
 * implementations write alike, written once: the same instruction under
 * each ISA's intrinsic names. Not included on its own: simd_sse2.h,
 * simd_avx2.h and simd_avx512.h include it after their types (vfloat,
 * vint, vmask, vdouble) with
 *   SIMD_X86_P  the intrinsics' prefix: _mm, _mm256, _mm512
 *   SIMD_X86_B  the vector's bits, the suffix of its integer intrinsics
 *               (_mm256_and_si256): 128, 256, 512
 *   and on AVX2 and AVX-512 SIMD_X86_HALF_PS(a, h), SIMD_X86_HALF_SI(i, h)
 *   (half h of a vector, h 0 or 1) and SIMD_X86_JOIN_PS(lo, hi)
 * defined. Three parts: what all three write alike; what SSE2 and AVX2
 * write alike (their masks are vectors); what AVX2 and AVX-512 write
 * alike. What one ISA does its own way stays in its header. The operation
 * names pasted (SIMD_MM_SI(and), ...) are plain C tokens: the header is C
 * only, and must not follow <iso646.h> (whose and, or, xor are macros). */
#if !defined(SIMD_X86_P) || !defined(SIMD_X86_B)
#error "simd_x86.h: include simd_sse2.h, simd_avx2.h or simd_avx512.h instead"
#endif

/* (one paste of all the pieces: a partial name such as _mm512_setzero
 * may be a macro of its own, clang's is) */
#define SIMD_X86_CAT_(a, b, c, d, e) a##b##c##d##e
#define SIMD_X86_CAT(a, b, c, d, e) SIMD_X86_CAT_(a, b, c, d, e)
/* SIMD_MM(op): the ISA's intrinsic _mm_op, _mm256_op or _mm512_op */
#define SIMD_MM(op) SIMD_X86_CAT(SIMD_X86_P, _, op, , )
/* SIMD_MM_SI(op): its whole-vector integer form _mm_op_si128, ... */
#define SIMD_MM_SI(op) SIMD_X86_CAT(SIMD_X86_P, _, op, _si, SIMD_X86_B)
/* the integer vector's bits as floats: _mm_castsi128_ps, ... */
#define SIMD_MM_CASTSI_PS SIMD_X86_CAT(SIMD_X86_P, _castsi, SIMD_X86_B, _ps, )

/* ==== SSE2, AVX2 and AVX-512 */

/* The IEEE operations floats and doubles share (the doubles: raster's
 * plane set-up and front end), for the vector type T of scalars t, the
 * names' prefix v and the intrinsics' suffix s: v_set1 v_loadu v_storeu
 * v_add v_sub v_mul v_div v_sqrt v_max, for vf_ (ps) and vd_ (pd). */
#define SIMD_X86_IEEE(T, t, v, s)                                      \
    SIMD_INL T v##_set1(t x) { return SIMD_MM(set1_##s)(x); }          \
    SIMD_INL T v##_loadu(const t *p) { return SIMD_MM(loadu_##s)(p); } \
    SIMD_INL void v##_storeu(t *p, T a) { SIMD_MM(storeu_##s)(p, a); } \
    SIMD_INL T v##_add(T a, T b) { return SIMD_MM(add_##s)(a, b); }    \
    SIMD_INL T v##_sub(T a, T b) { return SIMD_MM(sub_##s)(a, b); }    \
    SIMD_INL T v##_mul(T a, T b) { return SIMD_MM(mul_##s)(a, b); }    \
    SIMD_INL T v##_div(T a, T b) { return SIMD_MM(div_##s)(a, b); }    \
    SIMD_INL T v##_sqrt(T a) { return SIMD_MM(sqrt_##s)(a); }          \
    SIMD_INL T v##_max(T a, T b) { return SIMD_MM(max_##s)(a, b); }
SIMD_X86_IEEE(vfloat, float, vf, ps)
SIMD_X86_IEEE(vdouble, double, vd, pd)
#undef SIMD_X86_IEEE

/* ---- memory */
SIMD_INL vint vi_set1(int32_t x) { return SIMD_MM(set1_epi32)(x); }
SIMD_INL vfloat vf_zero(void) { return SIMD_MM(setzero_ps)(); }
SIMD_INL vint vi_zero(void) { return SIMD_MM_SI(setzero)(); }
SIMD_INL vfloat vf_load(const float *p) { return SIMD_MM(load_ps)(p); }
SIMD_INL void vf_store(float *p, vfloat a) { SIMD_MM(store_ps)(p, a); }
/* (the integer loads and stores pass their pointer as a void *: SSE2's
 * and AVX2's take it for their __m128i * / __m256i *, AVX-512's want one) */
SIMD_INL vint vi_load(const int32_t *p) { return SIMD_MM_SI(load)((const void *)p); }
SIMD_INL vint vi_loadu(const int32_t *p) { return SIMD_MM_SI(loadu)((const void *)p); }
SIMD_INL void vi_store(int32_t *p, vint i) { SIMD_MM_SI(store)((void *)p, i); }
SIMD_INL void vi_storeu(int32_t *p, vint i) { SIMD_MM_SI(storeu)((void *)p, i); }

/* ---- bits (before the arithmetic: vf_neg and vf_abs are bit operations) */
SIMD_INL vfloat vf_and(vfloat a, vfloat b) { return SIMD_MM(and_ps)(a, b); }
SIMD_INL vfloat vf_or(vfloat a, vfloat b) { return SIMD_MM(or_ps)(a, b); }
SIMD_INL vfloat vf_xor(vfloat a, vfloat b) { return SIMD_MM(xor_ps)(a, b); }
SIMD_INL vfloat vf_andnot(vfloat a, vfloat b) { return SIMD_MM(andnot_ps)(a, b); }
SIMD_INL vint vi_and(vint i, vint j) { return SIMD_MM_SI(and)(i, j); }
SIMD_INL vint vi_or(vint i, vint j) { return SIMD_MM_SI(or)(i, j); }
SIMD_INL vint vi_xor(vint i, vint j) { return SIMD_MM_SI(xor)(i, j); }
SIMD_INL vint vi_andnot(vint i, vint j) { return SIMD_MM_SI(andnot)(i, j); }
SIMD_INL vint vf_as_vi(vfloat a) { return SIMD_MM_SI(castps)(a); }
SIMD_INL vfloat vi_as_vf(vint i) { return SIMD_MM_CASTSI_PS(i); }

/* ---- float arithmetic (vf_set1 .. vf_max: SIMD_X86_IEEE above) */
SIMD_INL vfloat vf_min(vfloat a, vfloat b) { return SIMD_MM(min_ps)(a, b); }
SIMD_INL vfloat vf_neg(vfloat a) { return vf_xor(a, vf_set1(-0.0f)); }
SIMD_INL vfloat vf_abs(vfloat a) { return vf_and(a, vi_as_vf(vi_set1(0x7FFFFFFF))); }

/* ---- integer arithmetic */
SIMD_INL vint vi_add(vint i, vint j) { return SIMD_MM(add_epi32)(i, j); }
SIMD_INL vint vi_sub(vint i, vint j) { return SIMD_MM(sub_epi32)(i, j); }
#define vi_slli(i, k) SIMD_MM(slli_epi32)(i, k)
#define vi_srli(i, k) SIMD_MM(srli_epi32)(i, k)
#define vi_srai(i, k) SIMD_MM(srai_epi32)(i, k)
SIMD_INL vint vi_sll(vint i, int k) { return SIMD_MM(sll_epi32)(i, _mm_cvtsi32_si128(k)); }
SIMD_INL vint vi_srl(vint i, int k) { return SIMD_MM(srl_epi32)(i, _mm_cvtsi32_si128(k)); }

/* ---- conversions (x86's own: the contract's reference) */
SIMD_INL vfloat vf_from_vi(vint i) { return SIMD_MM(cvtepi32_ps)(i); }
SIMD_INL vint vi_from_vf_trunc(vfloat a) { return SIMD_MM(cvttps_epi32)(a); }
SIMD_INL vint vi_from_vf_round(vfloat a) { return SIMD_MM(cvtps_epi32)(a); }

/* ---- zips (per 128-bit block) */
SIMD_INL vint vi_zip_lo(vint i, vint j) { return SIMD_MM(unpacklo_epi32)(i, j); }
SIMD_INL vint vi_zip_hi(vint i, vint j) { return SIMD_MM(unpackhi_epi32)(i, j); }

/* ---- 16-bit lanes (simd.h, "16-bit lanes"; per 128-bit block as x86's
 * unpack, pack and shuffle work) */
SIMD_INL vint vh_set1(int x) { return SIMD_MM(set1_epi16)((short)x); }
SIMD_INL vint vh_add(vint i, vint j) { return SIMD_MM(add_epi16)(i, j); }
SIMD_INL vint vh_sub(vint i, vint j) { return SIMD_MM(sub_epi16)(i, j); }
SIMD_INL vint vh_mullo(vint i, vint j) { return SIMD_MM(mullo_epi16)(i, j); }
#define vh_srli(i, k) SIMD_MM(srli_epi16)(i, k)
SIMD_INL vint vh_from_u8_lo(vint i) { return SIMD_MM(unpacklo_epi8)(i, vi_zero()); }
SIMD_INL vint vh_from_u8_hi(vint i) { return SIMD_MM(unpackhi_epi8)(i, vi_zero()); }
SIMD_INL vint vh_packus(vint i, vint j) { return SIMD_MM(packus_epi16)(i, j); }
SIMD_INL vint vh_bcast3(vint i)
{
    return SIMD_MM(shufflehi_epi16)(SIMD_MM(shufflelo_epi16)(i, 0xFF), 0xFF);
}

/* ---- row-cache ops (src/fuse's composite; simd.h "ROW-CACHE OPS") */
SIMD_INL vint vh_zip_lo(vint i, vint j) { return SIMD_MM(unpacklo_epi16)(i, j); }
SIMD_INL vint vh_zip_hi(vint i, vint j) { return SIMD_MM(unpackhi_epi16)(i, j); }
SIMD_INL vint vh_madd(vint i, vint j) { return SIMD_MM(madd_epi16)(i, j); }
SIMD_INL vint vh_mulhi(vint i, vint j) { return SIMD_MM(mulhi_epu16)(i, j); }

/* ---- refine ops (src/fuse's band refinement; simd.h "REFINE OPS") */
SIMD_INL vint vb_loadu(const uint8_t *p) { return SIMD_MM_SI(loadu)((const void *)p); }
SIMD_INL void vb_storeu(uint8_t *p, vint i) { SIMD_MM_SI(storeu)((void *)p, i); }
SIMD_INL vint vh_loadu(const uint16_t *p) { return SIMD_MM_SI(loadu)((const void *)p); }
SIMD_INL void vh_storeu(uint16_t *p, vint i) { SIMD_MM_SI(storeu)((void *)p, i); }
SIMD_INL vint vh_adds_u(vint i, vint j) { return SIMD_MM(adds_epu16)(i, j); }


#if SIMD_W <= 8
/* ==== SSE2 and AVX2: masks are vectors of all-ones / all-zero lanes, the
 * float bit operations serve them */
SIMD_INL vfloat vf_neg_if(vmask m, vfloat a) { return vf_xor(a, vf_and(m, vf_set1(-0.0f))); }
SIMD_INL vfloat vf_selz(vmask m, vfloat a) { return vf_and(m, a); }
SIMD_INL vmask vi_eq(vint i, vint j) { return vi_as_vf(SIMD_MM(cmpeq_epi32)(i, j)); }
SIMD_INL vmask vi_gt(vint i, vint j) { return vi_as_vf(SIMD_MM(cmpgt_epi32)(i, j)); }
SIMD_INL vmask vm_and(vmask m, vmask n) { return vf_and(m, n); }
SIMD_INL vmask vm_or(vmask m, vmask n) { return vf_or(m, n); }
SIMD_INL vmask vm_andnot(vmask m, vmask n) { return vf_andnot(m, n); }
SIMD_INL vmask vm_not(vmask m) { return vf_xor(m, vi_as_vf(vi_set1(-1))); }
SIMD_INL unsigned vm_bits(vmask m) { return (unsigned)SIMD_MM(movemask_ps)(m); }
SIMD_INL int vm_all(vmask m) { return SIMD_MM(movemask_ps)(m) == (int)SIMD_FULL; }
SIMD_INL int vm_any(vmask m) { return SIMD_MM(movemask_ps)(m) != 0; }

/* ---- raster ops (src/raster's scan; simd.h "RASTER OPS") */
SIMD_INL unsigned vi_sign_bits(vint i) { return vm_bits(vi_as_vf(i)); }
SIMD_INL void vb_store_bits(uint8_t *p, unsigned bits)
{
    simd__bytes_store_bits(p, bits, SIMD_FULL, SIMD_W);
}
/* The three vectors to the stack, then three scalar stores per set bit
 * (raster measured six 128-bit vmaskmovps slower on AMD, and an
 * interleave with vector stores of whole runs slower too). */
SIMD_INL void vf_store3_bits(float *p, unsigned bits, vfloat x, vfloat y, vfloat z)
{
    _Alignas(SIMD_ALIGN) float t[3][SIMD_W];
    vf_store(t[0], x); vf_store(t[1], y); vf_store(t[2], z);
    simd__store3_lanes(p, bits & SIMD_FULL, SIMD_W, t);
}

/* ---- refine ops */
SIMD_INL vint vb_sign_fill(vint i) { return SIMD_MM(cmpgt_epi8)(vi_zero(), i); }
/* The chamfer's running minima, vh_runmin3_up and vh_runmin3_dn from one
 * body (expanded in the ISA's header, after its vh_min_u and VH_W): SH(t,
 * f, k) the ISA's shift of the 16-bit lanes by k, up (lane l takes lane
 * l - k) or down (l + k), the lanes shifted in taken from f (65535);
 * steps of 1, 2, 4 and, on AVX2's 16 lanes, 8 lanes, each adding 3 per
 * lane saturating; then the carry c plus the lanes given after SH,
 * 3 (l + 1) (up) or 3 (VH_W - l) (dn). */
#define SIMD_X86_RUNMIN3(name, SH, ...)                                     \
    SIMD_INL vint name(vint i, unsigned c)                                  \
    {                                                                       \
        const vint f = vh_set1(-1);                                         \
        vint t = i;                                                         \
        t = vh_min_u(t, vh_adds_u(SH(t, f, 1), vh_set1(3)));                \
        t = vh_min_u(t, vh_adds_u(SH(t, f, 2), vh_set1(6)));                \
        t = vh_min_u(t, vh_adds_u(SH(t, f, 4), vh_set1(12)));               \
        if (VH_W > 8) t = vh_min_u(t, vh_adds_u(SH(t, f, 8), vh_set1(24))); \
        const vint l3 = SIMD_MM(setr_epi16)(__VA_ARGS__);                   \
        return vh_min_u(t, vh_adds_u(vh_set1((int)c), l3));                 \
    }
#endif


#if SIMD_W >= 8
/* ==== AVX2 and AVX-512 */

/* ---- compares (one constant predicate each: clang and gcc -Os need it);
 * vcmpps gives a vector on AVX2, a __mmask16 on AVX-512 */
#if SIMD_W == 16
#define SIMD_X86_CMP_PS _mm512_cmp_ps_mask
#else
#define SIMD_X86_CMP_PS _mm256_cmp_ps
#endif
SIMD_INL vmask vf_eq(vfloat a, vfloat b) { return SIMD_X86_CMP_PS(a, b, _CMP_EQ_OQ); }
SIMD_INL vmask vf_ne(vfloat a, vfloat b) { return SIMD_X86_CMP_PS(a, b, _CMP_NEQ_UQ); }
SIMD_INL vmask vf_lt(vfloat a, vfloat b) { return SIMD_X86_CMP_PS(a, b, _CMP_LT_OQ); }
SIMD_INL vmask vf_le(vfloat a, vfloat b) { return SIMD_X86_CMP_PS(a, b, _CMP_LE_OQ); }
SIMD_INL vmask vf_gt(vfloat a, vfloat b) { return SIMD_X86_CMP_PS(a, b, _CMP_GT_OQ); }
SIMD_INL vmask vf_ge(vfloat a, vfloat b) { return SIMD_X86_CMP_PS(a, b, _CMP_GE_OQ); }

SIMD_INL vint vi_mullo(vint i, vint j) { return SIMD_MM(mullo_epi32)(i, j); }

/* ---- shuffles: the in-block 4x4 transpose by two rounds of unpacks */
SIMD_INL void vf_tr4(vfloat a, vfloat b, vfloat c, vfloat d, vfloat o[4])
{
    const vdouble t0 = SIMD_MM(castps_pd)(SIMD_MM(unpacklo_ps)(a, b));
    const vdouble t1 = SIMD_MM(castps_pd)(SIMD_MM(unpacklo_ps)(c, d));
    const vdouble t2 = SIMD_MM(castps_pd)(SIMD_MM(unpackhi_ps)(a, b));
    const vdouble t3 = SIMD_MM(castps_pd)(SIMD_MM(unpackhi_ps)(c, d));
    o[0] = SIMD_MM(castpd_ps)(SIMD_MM(unpacklo_pd)(t0, t1));
    o[1] = SIMD_MM(castpd_ps)(SIMD_MM(unpackhi_pd)(t0, t1));
    o[2] = SIMD_MM(castpd_ps)(SIMD_MM(unpacklo_pd)(t2, t3));
    o[3] = SIMD_MM(castpd_ps)(SIMD_MM(unpackhi_pd)(t2, t3));
}

/* ---- raster front-end ops (simd.h "RASTER FRONT-END OPS"): half h of
 * a vector (SIMD_X86_HALF_PS / _SI, h 0 or 1) widened, two halves joined
 * (SIMD_X86_JOIN_PS), by the ISA's own extract and insert (its header) */
SIMD_INL vdouble vd_from_vf(vfloat a, int h) { return SIMD_MM(cvtps_pd)(SIMD_X86_HALF_PS(a, h)); }
SIMD_INL vdouble vd_from_vi(vint i, int h) { return SIMD_MM(cvtepi32_pd)(SIMD_X86_HALF_SI(i, h)); }
SIMD_INL vfloat vf_from_vd(vdouble lo, vdouble hi)
{
    return SIMD_X86_JOIN_PS(SIMD_MM(cvtpd_ps)(lo), SIMD_MM(cvtpd_ps)(hi));
}
SIMD_INL vint vi_min(vint i, vint j) { return SIMD_MM(min_epi32)(i, j); }
SIMD_INL vint vi_max(vint i, vint j) { return SIMD_MM(max_epi32)(i, j); }

/* ---- raster edge ops (x86 only; simd.h "RASTER EDGE OPS"): VD_W int64
 * lanes in a vint */
#define SIMD_HAS_VL 1
typedef vint vlong;
SIMD_INL vlong vl_zero(void) { return vi_zero(); }
SIMD_INL vlong vl_from_vi(vint i, int h) { return SIMD_MM(cvtepi32_epi64)(SIMD_X86_HALF_SI(i, h)); }
SIMD_INL vlong vl_add(vlong a, vlong b) { return SIMD_MM(add_epi64)(a, b); }
SIMD_INL vlong vl_sub(vlong a, vlong b) { return SIMD_MM(sub_epi64)(a, b); }
SIMD_INL vlong vl_or(vlong a, vlong b) { return vi_or(a, b); }
SIMD_INL vlong vl_mul32(vlong a, vlong b) { return SIMD_MM(mul_epi32)(a, b); }
#define vl_slli(a, k) SIMD_MM(slli_epi64)(a, k)
SIMD_INL vlong vl_zip_lo(vlong a, vlong b) { return SIMD_MM(unpacklo_epi64)(a, b); }
SIMD_INL vlong vl_zip_hi(vlong a, vlong b) { return SIMD_MM(unpackhi_epi64)(a, b); }
SIMD_INL void vl_store(int64_t *p, vlong a) { SIMD_MM_SI(store)((void *)p, a); }

/* ---- row-cache and refine ops */
SIMD_INL vint vh_packus32(vint i, vint j) { return SIMD_MM(packus_epi32)(i, j); }
SIMD_INL vint vh_min_u(vint i, vint j) { return SIMD_MM(min_epu16)(i, j); }
#endif
