/* test_cpu_simd.c - the vector layer (src/cpu/simd.h): every operation of
 * every implementation this machine runs (sse2, avx2, avx512 on x86-64;
 * neon on aarch64, under qemu-aarch64 in CI) gives, lane by lane, the bits
 * of a scalar model of the contract written here. Inputs: the special
 * values the contract names (+-0, +-inf, quiet NaNs with payloads,
 * denormals, 2^23 and 2^31 boundaries, halves for the rounding), every
 * pair of them, and seeded random floats and ints. An ISA the machine
 * does not run is reported as SKIP, never as a pass.
 *
 * NaN rule checked: an operation with one NaN input returns that NaN,
 * quieted (payload kept); with two NaN inputs the result is a NaN (which
 * payload is not in the contract); a NaN the operation creates is the
 * target's default NaN (the same as the scalar model computes here). */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "support/simd_check.h"
#include "support/simd_isa_test.h"

#define N 960   /* 3 * 16 * 4 * 5 */

static float fb_(uint32_t u) { float f; memcpy(&f, &u, 4); return f; }
static uint32_t bf_(float f) { uint32_t u; memcpy(&u, &f, 4); return u; }
static int isnan_u(uint32_t u) { return (u & 0x7F800000u) == 0x7F800000u && (u & 0x7FFFFFu); }

static const uint32_t specials[] = {
    0x00000000u, 0x80000000u, 0x3F800000u, 0xBF800000u, /* +-0, +-1 */
    0x3F000000u, 0xBF000000u, 0x3FC00000u, 0x40200000u, /* 0.5 -0.5 1.5 2.5 */
    0xC0200000u, 0xBFC00000u, 0x7F800000u, 0xFF800000u, /* -2.5 -1.5 +-inf */
    0x7FC00000u, 0xFFC00000u, 0x7FC12345u, 0xFFD00001u, /* quiet NaNs */
    0x00000001u, 0x80000001u, 0x007FFFFFu, 0x00400000u, /* denormals */
    0x7F7FFFFFu, 0xFF7FFFFFu, 0x4B000000u, 0x4B000001u, /* +-FLT_MAX, 2^23, 2^23+1 */
    0xCB000001u, 0x4AFFFFFFu, 0xCAFFFFFFu, 0x4EFFFFFFu, /* -(2^23+1), 2^23-0.5, -, 2^31-128 */
    0x4F000000u, 0xCF000000u, 0xCF000001u, 0x3EFFFFFFu, /* 2^31, -2^31, below -2^31, 0.49999997 */
    0x4F32D05Eu, 0xCF32D05Eu, 0x00800000u, 0x80800000u, /* +-3e9, +-FLT_MIN */
    0x7FFFFFFFu, 0x80000001u, 0xFFFFFFFFu, 0x12345678u, /* int edges as ints */
};
#define NS ((int)(sizeof specials / sizeof specials[0]))

static void make_inputs(uint32_t *a, uint32_t *b, int seed)
{
    tu_rng r = { 0x5EEDu + (uint64_t)seed * 7919u };
    for (int i = 0; i < N; i++) {
        if (seed == 0) {
            /* every pair of specials (NS^2 > N: two seeds cover them) */
            a[i] = specials[i % NS];
            b[i] = specials[(i / NS) % NS];
        } else if (seed == 1) {
            a[i] = specials[(i + N) % NS];
            b[i] = specials[((i + N) / NS) % NS];
        } else {
            const int kind = tu_int(&r, 4);
            uint32_t x = (uint32_t)tu_next(&r);
            uint32_t y = (uint32_t)tu_next(&r);
            if (kind == 0) { /* floats in a small range, halves included */
                a[i] = bf_(floorf(tu_range(&r, -40.0f, 40.0f) * 2.0f) * 0.5f);
                b[i] = bf_(tu_range(&r, -40.0f, 40.0f));
            } else if (kind == 1) { /* any bits but signalling NaNs */
                a[i] = isnan_u(x) ? x | 0x00400000u : x;
                b[i] = isnan_u(y) ? y | 0x00400000u : y;
            } else if (kind == 2) { /* equal values */
                a[i] = bf_(tu_range(&r, -1e6f, 1e6f));
                b[i] = tu_int(&r, 2) ? a[i] : a[i] ^ 0x80000000u;
            } else { /* ints (no signalling NaN as floats: outside the contract) */
                a[i] = isnan_u(x) ? x | 0x00400000u : x;
                b[i] = tu_int(&r, 2) ? (isnan_u(y) ? y | 0x00400000u : y) : a[i];
            }
        }
    }
}

/* The contract's rule for one NaN input: that NaN, quieted. */
static uint32_t nan_in(uint32_t a, uint32_t b)
{
    return isnan_u(a) ? a | 0x00400000u : b | 0x00400000u;
}

/* volatile: the model computes at run time, on this target's scalar unit */
static uint32_t farith(int op, uint32_t ua, uint32_t ub)
{
    volatile float a = fb_(ua), b = fb_(ub);
    float r;
    switch (op) {
    case SC_ADD: r = a + b; break;
    case SC_SUB: r = a - b; break;
    case SC_MUL: r = a * b; break;
    case SC_DIV: r = a / b; break;
    default: r = sqrtf(a); break;
    }
    if (op != SC_SQRT && (isnan_u(ua) || isnan_u(ub))) return nan_in(ua, ub);
    if (op == SC_SQRT && isnan_u(ua)) return ua | 0x00400000u;
    return bf_(r);
}

static int32_t cvt_trunc(uint32_t u)
{
    float f = fb_(u);
    if (!(fabsf(f) < 2147483648.0f)) return INT32_MIN;
    return (int32_t)f;
}

static int32_t cvt_round(uint32_t u)
{
    float f = fb_(u);
    if (!(fabsf(f) < 2147483648.0f)) return INT32_MIN;
    float r = nearbyintf(f);   /* the default mode: nearest, ties to even */
    if (!(fabsf(r) < 2147483648.0f)) return INT32_MIN;
    return (int32_t)r;
}

static uint32_t mflag(int c) { return c ? 0xFFFFFFFFu : 0u; }
/* two 16-bit lanes (low, high) of a 32-bit lane, each taken mod 2^16 */
static uint32_t h2(uint32_t lo, uint32_t hi) { return (lo & 0xFFFFu) | (hi & 0xFFFFu) << 16; }

/* The model of lane i (W lanes per vector) of op. */
static uint32_t model(int op, const uint32_t *A, const uint32_t *B, int i, int W, int k,
                      const uint32_t *out_before)
{
    const uint32_t ua = A[i], ub = B[i];
    const float a = fb_(ua), b = fb_(ub);
    const int32_t ia = (int32_t)ua, ib = (int32_t)ub;
    const int v0 = i - i % W, l = i % W;
    switch (op) {
    case SC_ADD: case SC_SUB: case SC_MUL: case SC_DIV: case SC_SQRT:
        return farith(op, ua, ub);
    case SC_MIN: return a < b ? ua : ub;
    case SC_MAX: return a > b ? ua : ub;
    case SC_NEG: return ua ^ 0x80000000u;
    case SC_ABS: return ua & 0x7FFFFFFFu;
    case SC_FLOOR:
        if (isnan_u(ua)) return ua | 0x00400000u;
        return bf_(floorf(a));
    case SC_EQ: return mflag(a == b);
    case SC_NE: return mflag(!(a == b));
    case SC_LT: return mflag(a < b);
    case SC_LE: return mflag(a <= b);
    case SC_GT: return mflag(a > b);
    case SC_GE: return mflag(a >= b);
    case SC_BITS_LT: return a < b;
    case SC_ALL_LT: case SC_ANY_LT: {
        int all = 1, any = 0;
        for (int j = v0; j < v0 + W; j++) {
            int c = fb_(A[j]) < fb_(B[j]);
            all &= c;
            any |= c;
        }
        return (uint32_t)(op == SC_ALL_LT ? all : any);
    }
    case SC_SEL: return a < b ? ua : ub;
    case SC_SELZ: return a < b ? ua : 0u;
    case SC_NEG_IF: return a < b ? ua ^ 0x80000000u : ua;
    case SC_FAND: case SC_IAND: return ua & ub;
    case SC_FOR: case SC_IOR: return ua | ub;
    case SC_FXOR: case SC_IXOR: return ua ^ ub;
    case SC_FANDNOT: case SC_IANDNOT: return ~ua & ub;
    case SC_IADD: return ua + ub;
    case SC_ISUB: return ua - ub;
    case SC_IMULLO: return (uint32_t)((uint64_t)ua * (uint64_t)ub);
    case SC_IEQ: return mflag(ia == ib);
    case SC_IGT: return mflag(ia > ib);
    case SC_ISEL: return ia > ib ? ua : ub;
    case SC_SLLI3: return ua << 3;
    case SC_SRLI5: return ua >> 5;
    case SC_SRAI7: return (uint32_t)(ia < 0 ? ~(~ia >> 7) : ia >> 7);
    case SC_SLL: return ua << k;
    case SC_SRL: return ua >> k;
    case SC_CVT_I2F: return bf_((float)ia);
    case SC_CVT_TRUNC: return (uint32_t)cvt_trunc(ua);
    case SC_CVT_ROUND: return (uint32_t)cvt_round(ua);
    case SC_MAND: return mflag(a < b && a > b);
    case SC_MOR: return mflag(a < b || a > b);
    case SC_MANDNOT: return mflag(!(a < b) && !(a > b));
    case SC_MNOT: return mflag(!(a < b));
    case SC_FROM_BITS: return mflag((k >> l) & 1);
    case SC_LANES: return (uint32_t)l;
    case SC_LOAD: return ua;
    case SC_ZIPLO: case SC_ZIPHI: {   /* block of 4: lane j from lane (hi ? 2 : 0) + j / 2 */
        const int g = i - i % 4, j = i % 4, src = g + (op == SC_ZIPHI ? 2 : 0) + j / 2;
        return (j & 1) ? B[src] : A[src];
    }
    case SC_HADD: return h2(ua + (ub & 0xFFFFu), (ua >> 16) + (ub >> 16));
    case SC_HSUB: return h2(ua - (ub & 0xFFFFu), (ua >> 16) - (ub >> 16));
    case SC_HMUL: return h2((ua & 0xFFFFu) * (ub & 0xFFFFu), (ua >> 16) * (ub >> 16));
    case SC_HSRLI5: return h2((ua & 0xFFFFu) >> 5, (ua >> 16) >> 5);
    case SC_HSET1: return h2((uint32_t)k, (uint32_t)k);
    case SC_HLO8: case SC_HHI8: {   /* lane l of a 4-lane block: bytes 2l', 2l'+1 */
        const uint8_t *by = (const uint8_t *)(const void *)(A + (i - i % 4));
        const int off = (op == SC_HHI8 ? 8 : 0) + 2 * (i % 4);
        return h2(by[off], by[off + 1]);
    }
    case SC_HPACKUS: {   /* block: bytes 0-7 from a's 8 lanes, 8-15 from b's */
        const uint32_t *src = (i % 4) < 2 ? A : B;
        const uint16_t *h = (const uint16_t *)(const void *)(src + (i - i % 4));
        const int m0 = 4 * ((i % 4) % 2);
        uint32_t r = 0;
        for (int q = 0; q < 4; q++) {
            const int16_t v = (int16_t)h[m0 + q];
            r |= (uint32_t)(v < 0 ? 0 : v > 255 ? 255 : v) << (8 * q);
        }
        return r;
    }
    case SC_HBCAST3: {   /* 16-bit lane 3 of the pixel: the high half of lane 2p+1 */
        const uint32_t s = A[i - i % 2 + 1] >> 16;
        return h2(s, s);
    }
    case SC_STORE2: {   /* group of 2W: out[2l] = A[l], out[2l + 1] = A[W + l] */
        const int g = i - i % (2 * W), j = i - g;
        return A[g + (j & 1) * W + j / 2];
    }
    case SC_LOAD_U8: return ((const uint8_t *)(const void *)A)[v0 + l];
    case SC_LOAD_BITS: return ((unsigned)k >> l) & 1u ? ua : 0u;
    case SC_STORE_BITS: return ((unsigned)k >> l) & 1u ? ua : out_before[i];
    case SC_LOAD3: {   /* group of 3W: out x[W] y[W] z[W] from x y z x y z */
        const int g = i - i % (3 * W), j = i - g, c = j / W, v = j % W;
        return A[g + 3 * v + c];
    }
    case SC_STORE3: {
        const int g = i - i % (3 * W), j = i - g, v = j / 3, c = j % 3;
        return A[g + c * W + v];
    }
    case SC_SCATTER3: {  /* dest[l] = (5l + 3) % W: lane of out vertex d */
        const int g = i - i % (3 * W), j = i - g, d = j / 3, c = j % 3;
        int lane = 0;
        while ((lane * 5 + 3) % W != d) lane++;
        return A[g + c * W + lane];
    }
    case SC_TR4: {   /* group of 4W: lane 4J+q of o[kk] = lane 4J+kk of input q */
        const int g = i - i % (4 * W), j = i - g, kk = j / W, lane = j % W;
        const int J = lane / 4, q = lane % 4;
        return A[g + q * W + 4 * J + kk];
    }
    case SC_TRB: {   /* group of (W/4) W: block J of o[kk] = block kk of input J */
        const int g = i - i % (W / 4 * W), j = i - g, kk = j / W, lane = j % W;
        return A[g + (lane / 4) * W + 4 * kk + lane % 4];
    }
    default: return 0xDEADBEEFu;
    }
}

static const char *const op_names[SC_COUNT] = {
    "add", "sub", "mul", "div", "min", "max", "sqrt", "neg", "abs", "floor",
    "eq", "ne", "lt", "le", "gt", "ge", "bits(lt)", "all(lt)", "any(lt)",
    "sel", "selz", "neg_if", "f_and", "f_or", "f_xor", "f_andnot",
    "i_add", "i_sub", "i_mullo", "i_and", "i_or", "i_xor", "i_andnot",
    "i_eq", "i_gt", "i_sel", "slli3", "srli5", "srai7", "sll", "srl",
    "from_vi", "trunc", "round", "m_and", "m_or", "m_andnot", "m_not",
    "from_bits", "lanes", "load", "load_bits", "store_bits",
    "load3", "store3", "scatter3", "tr4", "load_u8", "store2",
    "h_add", "h_sub", "h_mullo", "h_srli5", "h_set1", "h_from_u8_lo", "h_from_u8_hi", "h_packus",
    "h_bcast3", "zip_lo", "zip_hi", "tr_blocks",
};

/* Both NaN inputs: any NaN. */
static int two_nans(int op, uint32_t ua, uint32_t ub)
{
    return (op == SC_ADD || op == SC_SUB || op == SC_MUL || op == SC_DIV) && isnan_u(ua) &&
           isnan_u(ub);
}

static void check_isa(void **state)
{
    const ef_isa isa = tu_simd_test_isa(state, "", "");
    tu_simd_check_fn *const fn = tu_simd_check_isa[tu_simd_isa_index_of(state)];
    static uint32_t a[N], b[N], out[N], before[N];
    long lanes = 0, bad = 0;
    int W = 0;
    static const int ks[] = { 0, 1, 13, 31, 0x5, 0xA, 0xFFFF, 0x8001, 0x3C, 0x7F };
    for (int seed = 0; seed < 6; seed++) {
        make_inputs(a, b, seed);
        for (int op = 0; op < SC_COUNT; op++) {
            for (int ki = 0; ki < (int)(sizeof ks / sizeof ks[0]); ki++) {
                int k = ks[ki];
                if ((op == SC_SLL || op == SC_SRL) && k > 31) continue;
                if (op != SC_SLL && op != SC_SRL && op != SC_FROM_BITS && op != SC_LOAD_BITS &&
                    op != SC_STORE_BITS && op != SC_HSET1 && ki > 0)
                    break;
                for (int i = 0; i < N; i++) out[i] = before[i] = b[i] ^ 0x5A5A5A5Au;
                W = fn(op, a, b, k, N, out);
                assert_true(W == 4 || W == 8 || W == 16);
                unsigned full = (1u << W) - 1u;
                int kk = (op == SC_FROM_BITS || op == SC_LOAD_BITS || op == SC_STORE_BITS)
                         ? (int)((unsigned)k & full) : k;
                for (int i = 0; i < N; i++) {
                    uint32_t want = model(op, a, b, i, W, kk, before);
                    int ok = out[i] == want ||
                             (two_nans(op, a[i], b[i]) && isnan_u(out[i]));
                    lanes++;
                    if (!ok && bad++ < 8)
                        print_message("FAIL %s %s k=%d lane %d: a=0x%08X b=0x%08X got 0x%08X "
                                      "want 0x%08X\n", ef_isa_name(isa), op_names[op], kk, i,
                                      a[i], b[i], out[i], want);
                }
            }
        }
    }
    print_message("NOTE cpu simd %s: %d lanes, %d operations, %ld lane results equal to the "
                  "scalar model\n", ef_isa_name(isa), W, SC_COUNT, lanes - bad);
    assert_int_equal(bad, 0);
}

/* Levels: one cap means the same on every architecture. */
static void test_levels(void **state)
{
    (void)state;
    assert_int_equal(ef_isa_level(EF_ISA_REF), 0);
    assert_int_equal(ef_isa_level(EF_ISA_SSE2), 1);
    assert_int_equal(ef_isa_level(EF_ISA_NEON), 1);
    assert_int_equal(ef_isa_level(EF_ISA_AVX2), 2);
    assert_int_equal(ef_isa_level(EF_ISA_AVX512), 3);
    assert_int_equal(ef_isa_parse("neon"), EF_ISA_NEON);
    assert_string_equal(ef_isa_name(EF_ISA_NEON), "neon");
    assert_int_equal(ef_cpu_cap(EF_ISA_REF), EF_ISA_REF);
    const ef_isa best = ef_cpu_best();
    assert_true(ef_cpu_has(best));
    assert_int_equal(ef_cpu_cap(EF_ISA_DEFAULT), best);
    /* a 4-lane cap runs this architecture's 4-lane path */
    const ef_isa four = ef_cpu_cap(EF_ISA_NEON);
    assert_int_equal(four, ef_cpu_cap(EF_ISA_SSE2));
#if defined(__x86_64__)
    assert_int_equal(four, EF_ISA_SSE2);
    assert_false(ef_cpu_has(EF_ISA_NEON));
#elif defined(__aarch64__)
    assert_int_equal(best, EF_ISA_NEON);
    assert_int_equal(four, EF_ISA_NEON);
    assert_int_equal(ef_cpu_cap(EF_ISA_AVX512), EF_ISA_NEON);
    assert_false(ef_cpu_has(EF_ISA_SSE2));
    assert_false(ef_cpu_has(EF_ISA_AVX2));
#endif
    for (int i = EF_ISA_REF; i < EF_ISA_COUNT; i++)
        if (ef_cpu_has((ef_isa)i)) assert_int_equal(ef_cpu_cap((ef_isa)i), i);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_levels),
        tu_simd_isa_test(check_isa, 0),
        tu_simd_isa_test(check_isa, 1),
        tu_simd_isa_test(check_isa, 2),
        tu_simd_isa_test(check_isa, 3))
