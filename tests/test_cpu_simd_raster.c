/* test_cpu_simd_raster.c - the raster ops of the vector layer
 * (src/cpu/simd.h, "RASTER OPS": vi_sign_bits, vb_store_bits,
 * vf_store3_bits) of every implementation this machine runs (sse2, avx2,
 * avx512 on x86-64; neon on aarch64, under qemu-aarch64 in CI) against a
 * scalar model of the contract: the bits, and that no byte or float
 * outside the lanes in bits is written. Seeded inputs; every lane subset
 * for 4 and 8 lanes, seeded subsets (and the empty and full ones) for 16.
 * An ISA the machine does not run is reported as SKIP, never as a pass.
 * (A test of its own so that test_cpu_simd.c stays the fuse port's.) */
#include "support/testutil.h"
#include <cmocka.h>

#include <string.h>

#include "../src/cpu/cpu.h"
#include "support/simd_rcheck.h"

#define N 480   /* 3 * 16 * 10 */

static uint32_t rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (uint32_t)(*s >> 16);
}

static void check_isa(ef_isa isa, tu_simd_rcheck_fn *fn)
{
    if (!ef_cpu_has(isa)) {
        print_message("SKIP cpu simd raster %s: this CPU (or this build's architecture) does "
                      "not run it; untested: the raster ops of src/cpu/simd_%s.h\n",
                      ef_isa_name(isa), ef_isa_name(isa));
        skip();
    }
    static uint32_t a[N], out[N], before[N];
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
            a[i] = (rnd(&s) & 7) == 0 ? sp[rnd(&s) % 5] : rnd(&s) * 2654435761u;
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
                               : ki == 0 ? 0u : ki == 1 ? full : rnd(&s) & full;
            for (int i = 0; i < N; i++) {
                bb[i] = ob[i] = (uint8_t)rnd(&s);
                before[i] = out[i] = rnd(&s);
                a[i] = rnd(&s);
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
    print_message("NOTE cpu simd raster %s: %d lanes, %ld results equal to the scalar model\n",
                  ef_isa_name(isa), W, checked - bad);
    assert_int_equal(bad, 0);
}

static void test_sse2(void **state) { (void)state; check_isa(EF_ISA_SSE2, tu_simd_rcheck_sse2); }
static void test_avx2(void **state) { (void)state; check_isa(EF_ISA_AVX2, tu_simd_rcheck_avx2); }
static void test_avx512(void **state) { (void)state; check_isa(EF_ISA_AVX512, tu_simd_rcheck_avx512); }
static void test_neon(void **state) { (void)state; check_isa(EF_ISA_NEON, tu_simd_rcheck_neon); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sse2),
        cmocka_unit_test(test_avx2),
        cmocka_unit_test(test_avx512),
        cmocka_unit_test(test_neon),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
