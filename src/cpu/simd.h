/* simd.h - the thin vector layer: one contract, one header per ISA.
 *
 * WHAT IT DOES. Gives the SIMD kernels of egofuse (raster, fuse, kin) one
 * vocabulary of lane operations, so a kernel is written ONCE and compiled
 * once per ISA. A kernel file includes exactly one implementation,
 *
 *   simd_sse2.h    x86-64 SSE2         SIMD_W  4   (the x86-64 baseline)
 *   simd_avx2.h    x86-64 AVX2 (+F16C) SIMD_W  8   (file built with -mavx2)
 *   simd_avx512.h  AVX-512 F/BW/DQ/VL  SIMD_W 16   (built with -mavx512*)
 *   simd_neon.h    AArch64 Advanced SIMD (NEON)  SIMD_W 4 (no flag: baseline)
 *
 * (the three x86 headers include simd_x86.h, the operations they write
 * alike, once, under each ISA's intrinsic names)
 * and then the kernel body (a .inl) written on the names below. Each
 * operation's result is defined here, lane by lane, bit for bit; every
 * implementation gives those bits (tests/test_cpu_simd.c checks each op of
 * each ISA the machine runs against a scalar model, special values
 * included). A kernel that keeps to these operations, in the scalar
 * reference's order, gives the reference's bytes on every ISA.
 *
 * WHAT IT DOES NOT. No dispatch (src/cpu/cpu.h picks the ISA; each room
 * keeps one dispatch table), no FMA, no estimates (rcp/rsqrt), no fast-math;
 * gathers (vi_gather, vf_gather, vf_gather_m) are one instruction on AVX2
 * and AVX-512 only, lane by lane on SSE2 and NEON; of byte
 * and 16-bit lanes only what the fuse's composites and the refinement
 * need (vh_*, per 128-bit block; vb_*, REFINE OPS);
 * bytes widen to int32 lanes with vi_load_u8, RGBA8 pixels are int32
 * lanes through vi_loadu. What one
 * ISA does in a way the others cannot (AVX-512's joint tables and masked
 * row ends in the skinning and refinement kernels) stays in that ISA's
 * kernel file, on the layer's types; what two ISAs would write alike is
 * an operation here (vf_gather_m: their masked look-ups; vf_tr_blocks:
 * their 128-bit block transposes).
 *
 * USAGE (a kernel file, e.g. src/kin/kin_skin_avx2.c):
 *
 *   #if defined(__x86_64__)
 *   #include "../cpu/simd_avx2.h"
 *   #include "kin_skin_simd.inl"   // defines SIMD_FN(kin__skin_lbs) ...
 *   #endif
 *
 * and in the body:
 *
 *   void SIMD_FN(scale_row)(float *p, int n, float s)   // scale_row_avx2
 *   {
 *       const vfloat k = vf_set1(s);
 *       int x = 0;
 *       for (; n - x >= SIMD_W; x += SIMD_W)
 *           vf_storeu(p + x, vf_mul(vf_loadu(p + x), k));
 *       for (; x < n; x++) p[x] = p[x] * s;        // the scalar tail
 *   }
 *
 * BUILD. Kernel files are compiled with -ffp-contract=off (the Makefile's
 * CFLAGS_COMMON): a*b + c stays two roundings on every ISA. The x86 files
 * get their -m flags by name (*_avx2.c, *_avx512.c), on x86 targets only;
 * *_neon.c files need no flag on aarch64 (NEON is the baseline there) and
 * compile to nothing elsewhere. Each header #errors when its ISA is not
 * enabled for the file, so a missing flag cannot silently give wrong code.
 *
 * ---------------------------------------------------------------------
 * WHAT EACH IMPLEMENTATION DEFINES
 *
 *   SIMD_W         lanes per vector (4, 8, 16, 4)
 *   SIMD_ISA       the ef_isa value (EF_ISA_SSE2, EF_ISA_AVX2, ...)
 *   SIMD_NAME      "sse2", "avx2", "avx512", "neon"
 *   SIMD_FN(name)  name##_sse2 (_avx2, _avx512, _neon): the kernel's names
 *   SIMD_ALIGN     bytes of a vector (the alignment vf_load/vf_store need)
 *   SIMD_FULL      the lane bits of every lane, (1u << SIMD_W) - 1
 *   SIMD_INL       static inline, always inlined (vectors never pass
 *                  through memory at a call)
 *   vfloat         SIMD_W IEEE binary32 lanes
 *   vint           SIMD_W int32 lanes (two's complement; wrap on overflow)
 *   vmask          SIMD_W lane flags (a vector of all-ones / all-zero
 *                  lanes on SSE2, AVX2 and NEON, a __mmask16 on AVX-512:
 *                  only make them with the compares and vm_* below)
 *
 * Lane l of a vector is element l in memory order (p[l] after vf_loadu).
 * "bits" are an unsigned with bit l for lane l (SIMD_W <= 16).
 *
 * OPERATIONS (a, b: vfloat; i, j: vint; m, n: vmask; p: pointer; k: int)
 *
 * Memory
 *   vf_set1(x) vi_set1(x)    every lane x
 *   vf_zero()  vi_zero()     every lane +0.0f / 0
 *   vi_lanes()               lane l = l
 *   vf_load(p)  vf_store(p, a)     p aligned to SIMD_ALIGN
 *   vf_loadu(p) vf_storeu(p, a)    any float alignment
 *   vi_load(p) vi_store(p, i) vi_loadu(p) vi_storeu(p, i)   int32 *p
 *   vf_load_bits(p, bits)    lanes in bits from p[l]; the others are +0 and
 *                            their p[l] is NOT read (may be unmapped)
 *   vf_store_bits(p, bits, a)  writes p[l] for the lanes in bits only;
 *                            nothing else is read or written
 *   vi_load_u8(p)            lane l = p[l] (uint8_t *p, any alignment),
 *                            zero-extended; reads exactly SIMD_W bytes
 *   vf_load3(p, &x, &y, &z)  de-interleaves 3*SIMD_W floats x y z x y z ..:
 *                            lane l of x = p[3l], y = p[3l+1], z = p[3l+2]
 *   vi_store2(p, i, j)       interleaves two vectors: p[2l] = i[l],
 *                            p[2l+1] = j[l] (int32_t *p, any alignment);
 *                            writes exactly 2 SIMD_W int32
 *   vf_store3(p, x, y, z)    the inverse: writes p[0 .. 3*SIMD_W)
 *   vf_scatter3(p, dest, x, y, z)  lane l to p[3*dest[l] + 0..2] (int32
 *                            dest[SIMD_W]; the order of the lanes' stores
 *                            is unspecified: lanes with the same dest must
 *                            carry the same values)
 *
 * Float arithmetic: IEEE binary32, round to nearest even, no flush of
 * denormals (x86: MXCSR default; aarch64: FPCR default, FZ = 0).
 *   vf_add vf_sub vf_mul vf_div(a, b), vf_sqrt(a)   correctly rounded
 *   vf_min(a, b)   a < b ? a : b   (x86 minps: b when either is NaN; b for
 *                                   -0.0 vs +0.0 in either order)
 *   vf_max(a, b)   a > b ? a : b   (x86 maxps, likewise)
 *   vf_neg(a)      sign bit flipped (also for NaN, 0, inf)
 *   vf_abs(a)      sign bit cleared
 *   vf_neg_if(m, a)  sign bit flipped where m
 *   vf_floor(a)    floorf(a) exactly, -0.0 kept, |a| >= 2^23 and inf
 *                  unchanged; a quiet NaN gives a quiet NaN (its payload
 *                  may differ between ISAs: do not store it)
 *   NaN created by an operation from non-NaN inputs (0/0, inf-inf,
 *   sqrt(-1)) is the target's default NaN: 0xFFC00000 on x86, 0x7FC00000
 *   on aarch64, as the scalar reference gives on that target. Same-target
 *   equality holds; bytes that must match ACROSS targets must not carry a
 *   created NaN (the kernels select such lanes away).
 *
 * Compares (to vmask): ordered ones are false when a or b is NaN.
 *   vf_eq vf_lt vf_le vf_gt vf_ge(a, b)   ordered
 *   vf_ne(a, b)    unordered or not equal (true when either is NaN)
 *   vi_eq(i, j)  vi_gt(i, j)   signed int32
 *
 * Selects and bit operations
 *   vf_sel(m, a, b)  m ? a : b per lane (bits of a or b, NaN kept)
 *   vf_selz(m, a)    m ? a : +0.0f
 *   vi_sel(m, i, j)  m ? i : j
 *   vf_and vf_or vf_xor(a, b)  bitwise on the float bits
 *   vf_andnot(a, b)  ~a & b (x86 order)
 *   vi_and vi_or vi_xor(i, j), vi_andnot(i, j) = ~i & j
 *   vf_as_vi(a) vi_as_vf(i)    the same bits, other type (no conversion)
 *
 * Integer arithmetic (int32, wrapping)
 *   vi_add vi_sub(i, j), vi_mullo(i, j) (low 32 bits of the product)
 *   vi_slli(i, k) vi_srli(i, k) vi_srai(i, k)   by a CONSTANT k: slli
 *                  0 <= k <= 31, srli/srai 1 <= k <= 31 (NEON's immediate
 *                  right shifts do not take 0); srli fills zeros, srai signs
 *   vi_sll(i, k) vi_srl(i, k)    by a run-time k, 0 <= k <= 31, all lanes
 *
 * Conversions
 *   vf_from_vi(i)        int32 -> float, round to nearest even
 *   vi_from_vf_trunc(a)  float -> int32 toward zero (cvttps)
 *   vi_from_vf_round(a)  float -> int32 to nearest, ties to even (cvtps
 *                        with the default MXCSR)
 *                        both: NaN and lanes outside [-2^31, 2^31) give
 *                        INT32_MIN (0x80000000), x86's "integer
 *                        indefinite" (NEON saturates and gives 0 for NaN:
 *                        simd_neon.h selects INT32_MIN there)
 *
 * Masks
 *   vm_and vm_or(m, n), vm_andnot(m, n) = ~m & n, vm_not(m)
 *   vm_bits(m)       unsigned, bit l set where lane l is set
 *   vm_from_bits(b)  lane l set where bit l of b is set
 *   vm_all(m)        1 when every lane is set, else 0
 *   vm_any(m)        1 when some lane is set, else 0
 *   vf_lt_bits(a, b) etc. are vm_bits(vf_lt(a, b)): write them that way;
 *                    on NEON prefer vm_any / vm_all where only that is
 *                    needed (one instruction; bits cost four)
 *
 * Zips, in each 128-bit block (4 int32 lanes; "block" as below)
 *   vi_zip_lo(i, j)          the block's lanes i0 j0 i1 j1 (x86 unpacklo)
 *   vi_zip_hi(i, j)          i2 j2 i3 j3 (x86 unpackhi)
 *
 * 16-bit lanes: a vint read as 2 SIMD_W uint16 lanes (lane m is bytes
 * 2m, 2m+1 of the vector in memory order); "block": each 128-bit part
 * (16 bytes; SSE2 and NEON have one, AVX2 two, AVX-512 four), where the
 * x86 unpack, pack and shuffle instructions work
 *   vh_set1(x)               every 16-bit lane x & 0xFFFF
 *   vh_add vh_sub vh_mullo(i, j)  wrapping, the low 16 bits
 *   vh_srli(i, k)            logical shift right by a CONSTANT 1 <= k <= 15
 *   vh_from_u8_lo(i), vh_from_u8_hi(i)   in each block: bytes 0-7 (lo) or
 *                            8-15 (hi) zero-extended to its 8 16-bit lanes
 *   vh_packus(i, j)          in each block: the 8 lanes of i, then those of
 *                            j, each read as int16 and saturated to 0..255,
 *                            as its 16 bytes (x86 packuswb)
 *   vh_bcast3(i)             in each group of 4 lanes (8 bytes: one RGBA
 *                            pixel of 16-bit channels), lane 3 to all four
 *
 * Shuffles
 *   vf_tr4(a, b, c, d, o)  4x4 transpose within each 4-lane block J
 *                          (lanes 4J .. 4J+3): lane 4J+i of o[k] is lane
 *                          4J+k of the i-th input (o is vfloat[4]). On
 *                          SSE2 and NEON the whole transpose.
 *   vf_tr_blocks(in, out)  the transpose of SIMD_W / 4 vectors as a matrix
 *                          of 128-bit blocks: block J of out[k] is block k
 *                          of in[J] (in, out: vfloat[SIMD_W / 4]; SSE2 and
 *                          NEON a copy, AVX2 vperm2f128, AVX-512
 *                          vshuff32x4); with vf_tr4, SIMD_W vertices of 4
 *                          floats each to 4 vectors
 *
 * RASTER OPS (added for src/raster's scan; a separate block at the end of
 * each implementation)
 *   vi_sign_bits(i)          bits of the lanes whose sign bit is set (the
 *                            edge test's E < 0; vm_bits(vi_gt(0, i)))
 *   vb_store_bits(p, bits)   p[l] = 0xFF for the lanes in bits (uint8_t *p;
 *                            no other byte is read or written)
 *   vf_store3_bits(p, bits, x, y, z)  vf_store3 for the lanes in bits only:
 *                            p[3l .. 3l+2] = x, y, z of lane l; no other
 *                            float is read or written
 *   VD_W, vdouble            SIMD_W / 2 IEEE binary64 lanes (2, 4, 8, 2)
 *   vd_set1(x) vd_loadu(p) vd_storeu(p, a)      double *p, any alignment
 *   vd_add vd_sub vd_mul vd_div(a, b)  correctly rounded
 *   vd_max(a, b)             a > b ? a : b (x86 maxpd, as vf_max)
 *   vd_load_f(p)             VD_W floats p[0 .. VD_W) converted (exactly)
 *   vd_store_f(p, a)         the lanes rounded to float (nearest even) and
 *                            stored to p[0 .. VD_W)
 *
 * RASTER FRONT-END OPS (src/raster's vector front end, raster_frontv.inl:
 * the vertex pass, the rejection and the double plane set-up of survivors;
 * and the vertex transforms, raster_xform.inl;
 * a block after the raster ops; h is a constant 0 or 1, "half h" the lanes
 * h*VD_W .. h*VD_W + VD_W - 1)
 *   vi_min(i, j) vi_max(i, j)  signed int32 minimum / maximum
 *   vd_from_vf(a, h)         the float lanes of half h of a as doubles (exact)
 *   vd_from_vi(i, h)         the int32 lanes of half h of i as doubles (exact)
 *   vf_from_vd(lo, hi)       lanes 0 .. VD_W-1 = lo, VD_W .. = hi, each
 *                            rounded to float (nearest even; x86 cvtpd2ps)
 *   vd_gt_bits(a, b)         bits (VD_W of them) of the lanes with a > b,
 *                            ordered (false when either is NaN)
 *   vd_sqrt(a)               square root, correctly rounded (the vertex
 *                            transforms' normal length, raster_xform.inl)
 * RASTER EDGE OPS (src/raster's vector front end, raster_frontq.inl: the
 * int64 edge values of the survivors and the survivor queue's compression;
 * x86 only: simd_avx2.h and simd_avx512.h define SIMD_HAS_VL 1 and these,
 * SSE2 and NEON do not, and their raster kernels do not compile the
 * vector front end; h as above)
 *   vlong                    VD_W int64 lanes (a vector of vint's size)
 *   vl_zero()                every lane 0
 *   vl_from_vi(i, h)         the int32 lanes of half h of i, sign-extended
 *   vl_add vl_sub vl_or(a, b)  int64, wrapping
 *   vl_mul32(a, b)           the low 32 bits of each lane of a and b read
 *                            as int32, their exact int64 product (vpmuldq)
 *   vl_slli(a, k)            shift left by a CONSTANT 0 <= k <= 63
 *   vl_sign_bits(a)          bits (VD_W of them) of the lanes with the sign
 *                            bit set
 *   vl_dec_unless(a, m, h)   a - 1 in lane l of a where lane h*VD_W + l of
 *                            the vmask m is clear; a where it is set
 *   vl_zip_lo(a, b)          in each 128-bit block (2 int64 lanes): a0 b0
 *   vl_zip_hi(a, b)          a1 b1 (x86 punpcklqdq / punpckhqdq)
 *   vl_store(p, a)           int64_t *p aligned to SIMD_ALIGN
 *   vi_compress_lanes(bits)  lane j = the lane number of the j-th set bit
 *                            of bits (j < popcount(bits)); the other lanes
 *                            are in 0 .. SIMD_W-1, otherwise unspecified
 * ROW-CACHE OPS (added for src/fuse's row-cached composite, fuse_simd.inl
 * fuse__hrow / fuse__vrow; a separate block at the end of each
 * implementation; tests/test_cpu_simd_fuse.c)
 *   (vi_min: see RASTER FRONT-END OPS)
 *   vi_permute(i, idx)       lane l = lane (idx[l] & (SIMD_W - 1)) of i
 *                            (AVX2 vpermd, AVX-512 vpermd, NEON TBL; SSE2
 *                            through memory)
 *   vi_gather(p, idx)        lane l = p[idx[l]] (const int32_t *p; every
 *                            p[idx[l]] must be readable); SSE2 and NEON
 *                            lane by lane
 *   vh_zip_lo(i, j), vh_zip_hi(i, j)   16-bit lanes, in each block: lanes
 *                            i0 j0 i1 j1 .. i3 j3 (lo) or i4 j4 .. i7 j7 (hi)
 *                            (x86 punpcklwd / punpckhwd)
 *   vh_madd(i, j)            int32 lane l = i[2l] j[2l] + i[2l+1] j[2l+1],
 *                            the 16-bit lanes read as int16, the sum
 *                            wrapping (x86 pmaddwd)
 *   vh_packus32(i, j)        in each block: the 4 int32 lanes of i, then
 *                            those of j, each saturated to 0..65535, as its
 *                            8 16-bit lanes (x86 packusdw)
 *   vh_mulhi(i, j)           16-bit lanes: (i j) >> 16, unsigned (x86
 *                            pmulhuw)
 * REFINE OPS (added for src/fuse's band refinement, fuse_refine_simd.inl:
 * the mask's bytes and the chamfer distances' 16-bit lanes in MEMORY
 * order, no blocks; a separate block at the end of each implementation)
 *   VB_W, VH_W               byte / 16-bit lanes of a vint: 4 SIMD_W and
 *                            2 SIMD_W (16, 32, 64, 16 / 8, 16, 32, 8)
 *   vb_loadu(p) vb_storeu(p, i)  VB_W bytes (uint8_t *p, any alignment)
 *   vb_sign_bits(i)          uint64_t, bit l set where byte l has bit 7 set
 *                            (x86 pmovmskb; NEON by a weighted add)
 *   vb_sign_fill(i)          byte l = 0xFF where byte l has bit 7 set, else 0
 *   vh_load_u8(p)            16-bit lane l = p[l], zero-extended; reads
 *                            exactly VH_W bytes (uint8_t *p, any alignment)
 *   vh_loadu(p) vh_storeu(p, i)  VH_W uint16 (uint16_t *p, any alignment)
 *   vh_min_u(i, j)           16-bit lanes: the unsigned minimum
 *   vh_adds_u(i, j)          16-bit lanes: i + j unsigned, saturated to 65535
 *   vh_any_leu(i, j)         1 when some 16-bit lane has i <= j unsigned,
 *                            else 0
 *   vi_load_u16(p)           int32 lane l = p[l] (uint16_t *p, any
 *                            alignment), zero-extended; reads exactly
 *                            SIMD_W uint16
 *   vh_runmin3_up(i, c)      16-bit lane l = min(i_l, i_j + 3 (l - j) for
 *                            j < l, c + 3 (l + 1)): the chamfer's forward
 *                            running minimum r[x] = min(r[x], r[x-1] + 3)
 *                            over the VH_W lanes, c (0..65535) being
 *                            r[x - 1] before lane 0 (65535: none); exact
 *                            (the sums saturate at 65535, which never wins
 *                            against i_l); a log-step scan, shifts of 1, 2,
 *                            4, ... lanes filled with 65535 and +3, +6,
 *                            +12, ... saturating
 *   vh_runmin3_dn(i, c)      the mirror: lane l = min(i_l, i_j + 3 (j - l)
 *                            for j > l, c + 3 (VH_W - l)), c the value
 *                            after the last lane (the backward pass)
 *
 * REPROJ OPS (added for src/pipe's reprojection taps, pipe_reproj_simd.inl;
 * a separate block at the end of each implementation)
 *   vf_gather(p, idx)        float lane l = p[idx_l] (float *p), the bits
 *                            as stored; reads exactly those SIMD_W floats
 *                            (AVX2/AVX-512 vgatherdps, SSE2/NEON lane by lane)
 *   vf_gather_m(p, idx, m)   float lane l = p[idx_l] where lane l of the
 *                            vmask m is set, +0.0f elsewhere; reads only
 *                            the lanes in m (the others' idx_l may point
 *                            anywhere; AVX2/AVX-512 masked vgatherdps,
 *                            SSE2/NEON lane by lane; the refinement's
 *                            score look-ups, fuse_refine_simd.inl)
 *   vi_gather_u8x4(p, idx)   int32 lane l = the 4 bytes p[idx_l .. idx_l+3]
 *                            as a little-endian int32 (uint8_t *p, any
 *                            offset): all 4 bytes must be readable; the
 *                            byte p[idx_l] is lane & 0xFF
 *   vi_store_u8(p, i)        p[l] = the low 8 bits of lane l; writes
 *                            exactly SIMD_W bytes (any alignment)
 *
 * NEW ISA. Copy simd_neon.h (the plainest), keep every name, meet every
 * line of this contract (the semantics above are x86's where the ISAs
 * differ: min/max, conversion out of range), add the ISA to
 * tests/test_cpu_simd.c and to the kernels' files; see
 * docs/portability.md, "A new ISA".
 */
#ifndef EGOFUSE_SIMD_H
#define EGOFUSE_SIMD_H

#include <stdint.h>

#include "cpu.h"

#define SIMD_INL static inline __attribute__((always_inline))
#define SIMD_CAT_(a, b) a##_##b
#define SIMD_CAT(a, b) SIMD_CAT_(a, b)

/* Scalar lane loops the implementations share where the ISA has no
 * masked byte or interleaved store (not part of the contract above;
 * "bits" as above, full = SIMD_FULL of the caller, w = SIMD_W). */

/* vb_store_bits: 0xFF to p[l] for each lane l of bits; one w-byte store
 * when every lane is set. */
SIMD_INL void simd__bytes_store_bits(uint8_t *p, unsigned bits, unsigned full, int w)
{
    if ((bits & full) == full) {
        __builtin_memset(p, 0xFF, (unsigned)w);
        return;
    }
    for (bits &= full; bits; bits &= bits - 1) p[__builtin_ctz(bits)] = 0xFF;
}

/* vf_store3_bits from the three vectors already stored to t[0] (x),
 * t[1] (y), t[2] (z): p[3l + c] = t[c][l] for each lane l of bits. */
SIMD_INL void simd__store3_lanes(float *p, unsigned bits, int w, const float t[3][w])
{
    for (; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        p[3 * l] = t[0][l]; p[3 * l + 1] = t[1][l]; p[3 * l + 2] = t[2][l];
    }
}

#endif
