/* test_cpu_simd_fuse.c - the row-cache ops of the vector layer
 * (src/cpu/simd.h, "ROW-CACHE OPS": vi_min, vi_permute, vi_gather,
 * vh_zip_lo/hi, vh_madd, vh_packus32, vh_mulhi) of every implementation
 * this machine runs (sse2, avx2, avx512 on x86-64; neon on aarch64, under
 * qemu-aarch64 in CI) against a scalar model of the contract, lane by lane.
 * Seeded inputs with the edges mixed in (0, -1, INT16/INT32 limits, 65535,
 * 65536); indices of every lane. An ISA the machine does not run is
 * reported as SKIP, never as a pass. */
#include "support/testutil.h"
#include <cmocka.h>

#include <string.h>

#include "../src/cpu/cpu.h"
#include "support/simd_fcheck.h"
#include "support/simd_isa_test.h"

#define N 960

static uint16_t lo16(uint32_t x) { return (uint16_t)(x & 0xFFFFu); }
static uint16_t hi16(uint32_t x) { return (uint16_t)(x >> 16); }
static uint32_t h2(uint32_t lo, uint32_t hi) { return (lo & 0xFFFFu) | (hi << 16); }

/* 16-bit lane m (0 .. 7) of the 4-lane block starting at p */
static uint16_t hlane(const uint32_t *p, int m) { return m & 1 ? hi16(p[m / 2]) : lo16(p[m / 2]); }

static uint32_t sat16(int32_t v) { return v < 0 ? 0u : v > 65535 ? 65535u : (uint32_t)v; }

static uint32_t model(int op, const uint32_t *A, const uint32_t *B, int i, int W)
{
    const int v = i - i % W, l = i % W, g = i - i % 4, j = i % 4;
    switch (op) {
    case FC_MIN: return (int32_t)A[i] < (int32_t)B[i] ? A[i] : B[i];
    case FC_PERMUTE: return A[v + (int)(B[i] & (uint32_t)(W - 1))];
    case FC_GATHER: return A[B[i]];
    case FC_HZIP_LO: case FC_HZIP_HI: {   /* 16-bit lanes 2j, 2j+1 of the block */
        const int m = (op == FC_HZIP_HI ? 4 : 0) + j;
        return h2(hlane(A + g, m), hlane(B + g, m));
    }
    case FC_HMADD: {
        const int64_t s = (int64_t)(int16_t)lo16(A[i]) * (int16_t)lo16(B[i]) +
                          (int64_t)(int16_t)hi16(A[i]) * (int16_t)hi16(B[i]);
        return (uint32_t)s;
    }
    case FC_HPACKUS32: {   /* lanes 0-1 of the block from a's 4, 2-3 from b's */
        const uint32_t *src = j < 2 ? A + g : B + g;
        const int m = 2 * (j % 2);
        return h2(sat16((int32_t)src[m]), sat16((int32_t)src[m + 1]));
    }
    case FC_HMULHI:
        return h2(((uint32_t)lo16(A[i]) * lo16(B[i])) >> 16, ((uint32_t)hi16(A[i]) * hi16(B[i])) >> 16);
    }
    (void)l;
    return 0xDEADBEEFu;
}

static const char *const names[FC_COUNT] = {
    "vi_min", "vi_permute", "vi_gather", "vh_zip_lo", "vh_zip_hi", "vh_madd", "vh_packus32", "vh_mulhi",
};

static void check_isa(void **state)
{
    const ef_isa isa = tu_simd_test_isa(state, " fuse", "the row-cache ops of ");
    tu_simd_fcheck_fn *const fn = tu_simd_fcheck_isa[tu_simd_isa_index_of(state)];
    static uint32_t a[N], b[N], out[N];
    static const uint32_t sp[] = { 0u, 0xFFFFFFFFu, 0x80000000u, 0x7FFFFFFFu, 0x8000u, 0x7FFFu,
                                   0xFFFFu, 0x10000u, 0x80008000u, 0xFFFF0000u, 1u, 0x00FF00FFu };
    const int ns = (int)(sizeof sp / sizeof sp[0]);
    long checked = 0, bad = 0;
    uint64_t s = 0x2545F4914F6CDD1Dull;
    for (int round = 0; round < 8; round++) {
        for (int op = 0; op < FC_COUNT; op++) {
            for (int i = 0; i < N; i++) {
                a[i] = (tu_xorshift(&s) & 3) == 0 ? sp[tu_xorshift(&s) % (unsigned)ns]
                       : tu_xorshift(&s) * 2654435761u;
                b[i] = (tu_xorshift(&s) & 3) == 0 ? sp[tu_xorshift(&s) % (unsigned)ns]
                       : tu_xorshift(&s) * 2246822519u;
                if (op == FC_PERMUTE && round == 0) b[i] = (uint32_t)(i % 16); /* every lane */
                if (op == FC_GATHER) b[i] = tu_xorshift(&s) % N;
                out[i] = 0xA5A5A5A5u;
            }
            const int W = fn(op, a, b, N, out);
            assert_true(W == 4 || W == 8 || W == 16);
            for (int i = 0; i < N; i++) {
                const uint32_t want = model(op, a, b, i, W);
                checked++;
                if (out[i] != want && bad++ < 8)
                    print_message("FAIL %s %s lane %d: a=0x%08X b=0x%08X got 0x%08X want 0x%08X\n",
                                  ef_isa_name(isa), names[op], i, a[i], b[i], out[i], want);
            }
        }
    }
    print_message("NOTE cpu simd fuse %s: %ld lane results equal to the scalar model\n",
                  ef_isa_name(isa), checked - bad);
    assert_int_equal(bad, 0);
}

int main(void) { return tu_simd_run_isas(check_isa); }
