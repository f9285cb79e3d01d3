/* test_cpu_simd_reproj.c - the reprojection ops of the vector layer
 * (src/cpu/simd.h, "REPROJ OPS": vf_gather, vf_gather_m, vi_gather_u8x4,
 * vi_store_u8)
 * of every implementation this machine runs (sse2, avx2, avx512 on x86-64;
 * neon on aarch64) against a scalar model of the contract, lane by lane.
 * Seeded inputs with special floats (NaN payloads, -0, infinities,
 * denormals) and byte offsets of every alignment up to the last readable
 * 4 bytes. An ISA the machine does not run is reported as SKIP, never as a
 * pass. */
#include "support/testutil.h"
#include <cmocka.h>

#include <string.h>

#include "../src/cpu/cpu.h"
#include "support/simd_pcheck.h"

#define N 960

static uint32_t rnd(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return (uint32_t)(*s >> 16);
}

static const char *const names[PC_COUNT] = {"vf_gather", "vi_gather_u8x4", "vi_store_u8",
                                             "vf_gather_m"};

static void check_isa(ef_isa isa, tu_simd_pcheck_fn *fn)
{
    if (!ef_cpu_has(isa)) {
        print_message("SKIP cpu simd reproj %s: this CPU (or this build's architecture) does "
                      "not run it; untested: the reprojection ops of src/cpu/simd_%s.h\n",
                      ef_isa_name(isa), ef_isa_name(isa));
        skip();
    }
    static uint32_t a[N], out[N];
    static int32_t idx[N];
    static const uint32_t sp[] = {0u,          0x80000000u, 0x7FC00001u, 0xFFC12345u, 0x7F800000u,
                                  0xFF800000u, 0x00000001u, 0x807FFFFFu, 0x3F800000u, 0xFFu,
                                  0x100u,      0xFFFFFF80u};
    const int ns = (int)(sizeof sp / sizeof sp[0]);
    long checked = 0, bad = 0;
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (int round = 0; round < 8; round++) {
        for (int op = 0; op < PC_COUNT; op++) {
            for (int i = 0; i < N; i++) {
                a[i] = (rnd(&s) & 3) == 0 ? sp[rnd(&s) % (unsigned)ns] : rnd(&s) * 2654435761u;
                /* floats: any of the N; bytes: any offset with 4 readable */
                idx[i] = op == PC_FGATHER ? (int32_t)(rnd(&s) % N)
                                          : (int32_t)(rnd(&s) % (4 * N - 3));
                if (op == PC_U8X4 && round == 0 && i < 16) idx[i] = 4 * N - 4 - i; /* the end */
                /* vf_gather_m: about a third of the lanes off, their index
                 * far outside a (reading one would fault) */
                if (op == PC_FGATHER_M) {
                    idx[i] = (int32_t)(rnd(&s) % N);
                    if (rnd(&s) % 3 == 0) idx[i] = -0x10000000 - (int32_t)(rnd(&s) & 0xFFFF);
                }
                out[i] = 0xA5A5A5A5u;
            }
            const int W = fn(op, a, idx, N, out);
            assert_true(W == 4 || W == 8 || W == 16);
            const uint8_t *ab = (const uint8_t *)a, *ob = (const uint8_t *)out;
            for (int i = 0; i < N; i++) {
                uint32_t want, got;
                if (op == PC_FGATHER) {
                    want = a[idx[i]], got = out[i];
                } else if (op == PC_FGATHER_M) {
                    want = idx[i] >= 0 ? a[idx[i]] : 0u, got = out[i];
                } else if (op == PC_U8X4) {
                    want = (uint32_t)ab[idx[i]] | (uint32_t)ab[idx[i] + 1] << 8 |
                           (uint32_t)ab[idx[i] + 2] << 16 | (uint32_t)ab[idx[i] + 3] << 24;
                    got = out[i];
                } else {
                    want = a[i] & 0xFFu, got = ob[i];
                }
                checked++;
                if (got != want && bad++ < 8)
                    print_message("FAIL %s %s lane %d: a=0x%08X idx=%d got 0x%08X want 0x%08X\n",
                                  ef_isa_name(isa), names[op], i, a[i], idx[i], got, want);
            }
            /* vi_store_u8 wrote exactly N bytes */
            if (op == PC_STORE_U8)
                for (int i = N; i < 4 * N; i++) {
                    checked++;
                    if (ob[i] != 0xA5 && bad++ < 8)
                        print_message("FAIL %s vi_store_u8 wrote byte %d\n", ef_isa_name(isa), i);
                }
        }
    }
    print_message("NOTE cpu simd reproj %s: %ld results equal to the scalar model\n",
                  ef_isa_name(isa), checked - bad);
    assert_int_equal(bad, 0);
}

static const ef_isa isas[4] = {EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON};
static tu_simd_pcheck_fn *const fns[4] = {tu_simd_pcheck_sse2, tu_simd_pcheck_avx2,
                                          tu_simd_pcheck_avx512, tu_simd_pcheck_neon};
static int idx4[4] = {0, 1, 2, 3};

static void test_isa(void **state)
{
    const int i = *(const int *)*state;
    check_isa(isas[i], fns[i]);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test_prestate(test_isa, &idx4[0]), cmocka_unit_test_prestate(test_isa, &idx4[1]),
        cmocka_unit_test_prestate(test_isa, &idx4[2]), cmocka_unit_test_prestate(test_isa, &idx4[3]))
