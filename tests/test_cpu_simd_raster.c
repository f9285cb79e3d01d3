/* test_cpu_simd_raster.c - the raster ops of the vector layer
 * (src/cpu/simd.h, "RASTER OPS": vi_sign_bits, vb_store_bits,
 * vf_store3_bits) of every implementation this machine runs (sse2, avx2,
 * avx512 on x86-64; neon on aarch64, under qemu-aarch64 in CI) against a
 * scalar model of the contract: the bits, and that no byte or float
 * outside the lanes in bits is written; and the raster front-end ops
 * (vi_min, vi_max, vd_from_vf, vd_from_vi, vf_from_vd, vd_gt_bits, vd_sqrt) against
 * their scalar definitions, and the raster edge ops (vl_*,
 * vi_compress_lanes; AVX2 and AVX-512 only). Seeded inputs; every lane subset
 * for 4 and 8 lanes, seeded subsets (and the empty and full ones) for 16.
 * An ISA the machine does not run is reported as SKIP, never as a pass.
 * (A test of its own so that test_cpu_simd.c stays the fuse port's.) */
#include "support/testutil.h"
#include <cmocka.h>

#include <string.h>

#include "../src/cpu/cpu.h"
#include "support/simd_isa_test.h"
#include "support/simd_rcheck.h"

#define N 480   /* 3 * 16 * 10 */

/* A seeded float: random bits (finite), or a special value. */
static float rnd_float(uint64_t *s)
{
    static const uint32_t sp[] = { 0x00000000u, 0x80000000u, 0x7F800000u, 0xFF800000u,
                                   0x00000001u, 0x807FFFFFu, 0x7F7FFFFFu, 0x3F800000u };
    uint32_t b = tu_xorshift(s) * 2654435761u ^ tu_xorshift(s);
    if ((tu_xorshift(s) & 7) == 0)
        b = sp[tu_xorshift(s) % 8];
    else if ((b & 0x7F800000u) == 0x7F800000u)
        b &= 0xBFFFFFFFu;   /* no NaN: its payload is not part of the contract */
    float f;
    memcpy(&f, &b, 4);
    return f;
}

/* A seeded double: around the float range (rounding, overflow, underflow
 * to float denormals), exact ties, signed zeros, infinities, NaN. */
static double rnd_double(uint64_t *s)
{
    const uint32_t r = tu_xorshift(s) % 16;
    if (r == 0) {
        static const double sp[] = { 0.0, -0.0, 1.0 / 0.0, -1.0 / 0.0, 0.0 / 0.0,
                                     3.4028235677973366e38, 1.401298464324817e-45,
                                     1.0 + 0x1p-24 };
        return sp[tu_xorshift(s) % 8];
    }
    const double m = (double)(int32_t)(tu_xorshift(s) * 2654435761u ^ tu_xorshift(s)) * 0x1p-31 +
                     (double)tu_xorshift(s) * 0x1p-55;
    const int e = (int)(tu_xorshift(s) % 300) - 150;
    return r == 1 ? (double)(tu_xorshift(s) % 5) - 2.0 : __builtin_ldexp(m, e);
}

/* The raster front-end ops (vi_min, vi_max, vd_from_vf, vd_from_vi,
 * vf_from_vd, vd_gt_bits, vd_sqrt) against their scalar definitions. */
static void check_front_ops(ef_isa isa, tu_simd_rcheck_fn *fn, int W, uint64_t *s,
                            long *checked, long *bad)
{
    static _Alignas(64) uint32_t a[N], out[N];
    const int VD = W / 2;
    for (int round = 0; round < 8; round++) {
        /* vi_min / vi_max */
        for (int i = 0; i < N; i++)
            a[i] = (tu_xorshift(s) & 3) == 0 ? (uint32_t[]){ 0u, 0x80000000u, 0x7FFFFFFFu,
                                                    0xFFFFFFFFu }[tu_xorshift(s) % 4]
                                     : tu_xorshift(s) * 2654435761u;
        if (round & 1)   /* equal pairs too */
            for (int i = 0; i < N; i += 2 * W) a[i + W] = a[i];
        assert_int_equal(fn(RC_VI_MINMAX, a, 0, N, out), W);
        for (int v = 0; v < N; v += 2 * W)
            for (int l = 0; l < W; l++) {
                const int32_t x = (int32_t)a[v + l], y = (int32_t)a[v + W + l];
                const int32_t mn = x < y ? x : y, mx = x > y ? x : y;
                *checked += 2;
                if (((int32_t)out[v + l] != mn || (int32_t)out[v + W + l] != mx) &&
                    (*bad)++ < 8)
                    print_message("FAIL %s vi_min/vi_max lane %d: %d %d -> %d %d\n",
                                  ef_isa_name(isa), l, x, y, (int32_t)out[v + l],
                                  (int32_t)out[v + W + l]);
            }
        /* vd_from_vf, vd_from_vi */
        for (int i = 0; i < N / 2; i++) {
            const float f = rnd_float(s);
            memcpy(&a[i], &f, 4);
        }
        assert_int_equal(fn(RC_VD_FROM_VF, a, 0, N, out), W);
        for (int i = 0; i < N / 2; i++) {
            float f;
            double got;
            memcpy(&f, &a[i], 4);
            memcpy(&got, &out[2 * i], 8);
            const double want = (double)f;
            (*checked)++;
            if (memcmp(&got, &want, 8) != 0 && (*bad)++ < 8)
                print_message("FAIL %s vd_from_vf %d: %a -> %a\n", ef_isa_name(isa), i,
                              (double)f, got);
        }
        for (int i = 0; i < N / 2; i++)
            a[i] = (tu_xorshift(s) & 7) == 0 ? 0x80000000u : tu_xorshift(s) * 2654435761u;
        assert_int_equal(fn(RC_VD_FROM_VI, a, 0, N, out), W);
        for (int i = 0; i < N / 2; i++) {
            double got;
            memcpy(&got, &out[2 * i], 8);
            const double want = (double)(int32_t)a[i];
            (*checked)++;
            if (memcmp(&got, &want, 8) != 0 && (*bad)++ < 8)
                print_message("FAIL %s vd_from_vi %d: %d -> %a\n", ef_isa_name(isa), i,
                              (int32_t)a[i], got);
        }
        /* vf_from_vd (no NaN: only its bits would differ between targets) */
        for (int i = 0; i < N / 2; i++) {
            double d = rnd_double(s);
            if (d != d) d = 1.5;
            memcpy(&a[2 * i], &d, 8);
        }
        assert_int_equal(fn(RC_VF_FROM_VD, a, 0, N, out), W);
        for (int i = 0; i < N / 2; i++) {
            double d;
            memcpy(&d, &a[2 * i], 8);
            const float want = (float)d;
            (*checked)++;
            if (memcmp(&out[i], &want, 4) != 0 && (*bad)++ < 8)
                print_message("FAIL %s vf_from_vd %d: %a -> 0x%08X\n", ef_isa_name(isa), i, d,
                              out[i]);
        }
        /* vd_sqrt (no negative input: the NaN it creates differs between
         * targets) */
        for (int i = 0; i < N / 2; i++) {
            double d = __builtin_fabs(rnd_double(s));
            if (d != d) d = 2.0;
            memcpy(&a[2 * i], &d, 8);
        }
        assert_int_equal(fn(RC_VD_SQRT, a, 0, N, out), W);
        for (int i = 0; i < N / 2; i++) {
            double d, got;
            memcpy(&d, &a[2 * i], 8);
            memcpy(&got, &out[2 * i], 8);
            const double want = __builtin_sqrt(d);
            (*checked)++;
            if (memcmp(&got, &want, 8) != 0 && (*bad)++ < 8)
                print_message("FAIL %s vd_sqrt %d: %a -> %a\n", ef_isa_name(isa), i, d, got);
        }
        /* vd_gt_bits: pairs, a third of them equal */
        for (int i = 0; i < N / 2; i++) {
            double d = rnd_double(s);
            if (i % (2 * VD) >= VD && tu_xorshift(s) % 3 == 0)
                memcpy(&d, &a[2 * (i - VD)], 8);
            memcpy(&a[2 * i], &d, 8);
        }
        assert_int_equal(fn(RC_VD_GT_BITS, a, 0, N, out), W);
        for (int g = 0; g < N / 2; g += 2 * VD)
            for (int l = 0; l < VD; l++) {
                double x, y;
                memcpy(&x, &a[2 * (g + l)], 8);
                memcpy(&y, &a[2 * (g + VD + l)], 8);
                (*checked)++;
                if ((out[g + l] != (uint32_t)(x > y) || out[g + VD + l] != 0) && (*bad)++ < 8)
                    print_message("FAIL %s vd_gt_bits lane %d: %a > %a -> %u\n",
                                  ef_isa_name(isa), l, x, y, out[g + l]);
            }
    }
}

/* The raster edge ops (vl_*, vi_compress_lanes: AVX2 and AVX-512 only)
 * against their scalar definitions; *has 0 on an ISA without them. */
static void check_edge_ops(ef_isa isa, tu_simd_rcheck_fn *fn, int W, uint64_t *s,
                           long *checked, long *bad, int *has)
{
    static _Alignas(64) uint32_t a[N], out[N];
    const int VD = W / 2;
    *has = fn(RC_COMPRESS, a, 0, N, out) != 0;
    if (!*has)
        return;
    for (int round = 0; round < 8; round++) {
        static const uint32_t sp[] = { 0u, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 1u };
        for (int i = 0; i < N; i++)
            a[i] = (tu_xorshift(s) & 7) == 0 ? sp[tu_xorshift(s) % 5]
                                             : tu_xorshift(s) * 2654435761u;
        /* vl_from_vi, vl_mul32, vl_slli, vl_sub, vl_add, vl_or, vl_zero,
         * vl_dec_unless, vl_store, vl_sign_bits */
        assert_int_equal(fn(RC_VL_ARITH, a, 0, N, out), W);
        for (int b = 0; 3 * W * (b + 1) <= N; b++)
            for (int l = 0; l < W; l++) {
                const int64_t i = (int32_t)a[3 * W * b + l], j = (int32_t)a[3 * W * b + W + l];
                const int f = (int32_t)a[3 * W * b + 2 * W + l] < 0;
                const int64_t want = i * j - i * 256 + j - (f ? 0 : 1);
                int64_t got;
                memcpy(&got, &out[2 * (W * b + l)], 8);
                const uint32_t sb = out[2 * N / 3 + W * b + l];
                *checked += 2;
                if ((got != want || sb != (uint32_t)(want < 0)) && (*bad)++ < 8)
                    print_message("FAIL %s vl ops lane %d: %lld %lld %d -> %lld sign %u\n",
                                  ef_isa_name(isa), l, (long long)i, (long long)j, f,
                                  (long long)got, sb);
            }
        /* vl_zip_lo, vl_zip_hi: per 128-bit block of int64 lanes */
        assert_int_equal(fn(RC_VL_ZIP, a, 0, N, out), W);
        for (int b = 0; 4 * W * (b + 1) <= N; b++)
            for (int h = 0; h < 2; h++)
                for (int q = 0; q < VD; q++) {
                    /* zip_lo lane q: block q/2, a (even q) or b (odd q) of
                     * int64 lane 2 (q/2); zip_hi: lane 2 (q/2) + 1 */
                    for (int z = 0; z < 2; z++) {
                        const int src = (q & 1) ? W : 0, lane = 2 * (q / 2) + z;
                        const int64_t want = (int32_t)a[2 * W * b + src + VD * h + lane];
                        int64_t got;
                        memcpy(&got, &out[2 * (2 * W * b + 2 * VD * h + VD * z + q)], 8);
                        (*checked)++;
                        if (got != want && (*bad)++ < 8)
                            print_message("FAIL %s vl_zip_%s half %d lane %d: %lld, want %lld\n",
                                          ef_isa_name(isa), z ? "hi" : "lo", h, q,
                                          (long long)got, (long long)want);
                    }
                }
    }
    /* vi_compress_lanes: every subset (W <= 8), seeded ones for 16 */
    const unsigned full = (1u << W) - 1u;
    const int nk = W <= 8 ? (int)full + 1 : 512;
    for (int ki = 0; ki < nk; ki++) {
        const unsigned k = W <= 8 ? (unsigned)ki
                           : ki == 0 ? 0u : ki == 1 ? full : tu_xorshift(s) & full;
        assert_int_equal(fn(RC_COMPRESS, a, k, N, out), W);
        int j = 0;
        for (int l = 0; l < W; l++) {
            (*checked)++;
            if ((k >> l) & 1u) {
                if (out[j] != (uint32_t)l && (*bad)++ < 8)
                    print_message("FAIL %s vi_compress_lanes 0x%X lane %d: %u, want %d\n",
                                  ef_isa_name(isa), k, j, out[j], l);
                j++;
            }
        }
        for (; j < W; j++) {
            (*checked)++;
            if (out[j] >= (uint32_t)W && (*bad)++ < 8)
                print_message("FAIL %s vi_compress_lanes 0x%X lane %d: %u out of range\n",
                              ef_isa_name(isa), k, j, out[j]);
        }
    }
}

static void check_isa(void **state)
{
    const ef_isa isa = tu_simd_test_isa(state, " raster", "the raster ops of ");
    tu_simd_rcheck_fn *const fn = tu_simd_rcheck_isa[tu_simd_isa_index_of(state)];
    static _Alignas(64) uint32_t a[N], out[N], before[N];
    static uint8_t ob[N], bb[N];
    long checked = 0, bad = 0;
    uint64_t s = 0x9E3779B97F4A7C15ull;
    const int W = fn(RC_SIGN_BITS, a, 0, 0, out);
    assert_true(W == 4 || W == 8 || W == 16);
    const unsigned full = (1u << W) - 1u;
    for (int round = 0; round < 4; round++) {
        /* vi_sign_bits: random ints, and 0, -1, INT32_MIN, INT32_MAX */
        static const uint32_t sp[] = { 0u, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 1u };
        for (int i = 0; i < N; i++)
            a[i] = (tu_xorshift(&s) & 7) == 0 ? sp[tu_xorshift(&s) % 5]
                   : tu_xorshift(&s) * 2654435761u;
        assert_int_equal(fn(RC_SIGN_BITS, a, 0, N, out), W);
        for (int i = 0; i < N; i++) {
            checked++;
            if (out[i] != (a[i] >> 31) && bad++ < 8)
                print_message("FAIL %s vi_sign_bits lane %d: a=0x%08X got %u\n",
                              ef_isa_name(isa), i, a[i], out[i]);
        }
        /* the stores: every subset of the lanes (W <= 8), else seeded ones */
        const int nk = W <= 8 ? (int)full + 1 : 64;
        for (int ki = 0; ki < nk; ki++) {
            const unsigned k = W <= 8 ? (unsigned)ki
                               : ki == 0 ? 0u : ki == 1 ? full : tu_xorshift(&s) & full;
            for (int i = 0; i < N; i++) {
                bb[i] = ob[i] = (uint8_t)tu_xorshift(&s);
                before[i] = out[i] = tu_xorshift(&s);
                a[i] = tu_xorshift(&s);
            }
            assert_int_equal(fn(RC_VB_STORE_BITS, a, k, N, ob), W);
            for (int i = 0; i < N; i++) {
                const uint8_t want = ((k >> (i % W)) & 1u) ? 0xFF : bb[i];
                checked++;
                if (ob[i] != want && bad++ < 8)
                    print_message("FAIL %s vb_store_bits k=0x%X byte %d: got 0x%02X want "
                                  "0x%02X\n", ef_isa_name(isa), k, i, ob[i], want);
            }
            assert_int_equal(fn(RC_STORE3_BITS, a, k, N, out), W);
            for (int i = 0; i < N; i++) {
                const int g = i / (3 * W) * (3 * W), f = i - g, l = f / 3, c = f % 3;
                const uint32_t want = ((k >> l) & 1u) ? a[g + c * W + l] : before[i];
                checked++;
                if (out[i] != want && bad++ < 8)
                    print_message("FAIL %s vf_store3_bits k=0x%X float %d: got 0x%08X want "
                                  "0x%08X\n", ef_isa_name(isa), k, i, out[i], want);
            }
        }
    }
    check_front_ops(isa, fn, W, &s, &checked, &bad);
    int has_vl;
    check_edge_ops(isa, fn, W, &s, &checked, &bad, &has_vl);
    print_message("NOTE cpu simd raster %s: %d lanes, %ld results equal to the scalar model%s\n",
                  ef_isa_name(isa), W, checked - bad,
                  has_vl ? "" : " (no RASTER EDGE OPS on this ISA)");
    assert_int_equal(bad, 0);
}

int main(void) { return tu_simd_run_isas(check_isa); }
