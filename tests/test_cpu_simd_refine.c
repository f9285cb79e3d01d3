/* test_cpu_simd_refine.c - the refine ops of the vector layer
 * (src/cpu/simd.h, "REFINE OPS": vb_loadu/storeu, vb_sign_bits,
 * vb_sign_fill, vh_load_u8, vh_loadu/storeu, vh_min_u, vh_adds_u,
 * vh_any_leu, vi_load_u16, vh_runmin3_up/_dn) of every implementation this machine runs
 * (sse2, avx2, avx512 on x86-64; neon on aarch64, under qemu-aarch64 in
 * CI) against a scalar model of the contract, lane by lane. Seeded inputs
 * with the edges mixed in (0, 1, 127, 128, 255, 0x7FFF, 0x8000, 0xFFFF);
 * vh_any_leu also on rows where no lane (or one) is <=. An ISA the
 * machine does not run is reported as SKIP, never as a pass. */
#include "support/testutil.h"
#include <cmocka.h>

#include "../src/cpu/cpu.h"
#include "support/simd_isa_test.h"
#include "support/simd_qcheck.h"

#define N 1024

static const char *const names[QC_COUNT] = {
    "vb_sign_bits", "vb_sign_fill", "vh_load_u8", "vh_min_u", "vh_adds_u", "vh_any_leu",
    "vi_load_u16", "vh_runmin3_up", "vh_runmin3_dn",
};

/* the model of element k of op's output, as uint32 */
static uint32_t model(int op, const uint16_t *a, const uint16_t *b, int k, int W)
{
    const uint8_t *ab = (const uint8_t *)(const void *)a;
    const int vh = 2 * W;
    switch (op) {
    case QC_SIGN_BITS: return ab[k] >> 7;
    case QC_SIGN_FILL: return ab[k] >= 128 ? 0xFFu : 0u;
    case QC_H_LOAD_U8: return ab[k];
    case QC_H_MIN_U: return a[k] < b[k] ? a[k] : b[k];
    case QC_H_ADDS_U: return (uint32_t)a[k] + b[k] > 65535u ? 65535u : (uint32_t)a[k] + b[k];
    case QC_H_ANY_LEU: {
        if (k % vh) return 0;
        for (int l = k; l < k + vh; l++)
            if (a[l] <= b[l]) return 1;
        return 0;
    }
    case QC_LOAD_U16: return a[k];
    case QC_H_RUNMIN3_UP: case QC_H_RUNMIN3_DN: {
        /* the chamfer's scalar running minimum over the vector's lanes, in
         * exact integers, the carry b[first lane] before lane 0 / after
         * the last lane */
        const int v0 = k - k % vh;
        uint32_t m = a[k];
        if (op == QC_H_RUNMIN3_UP) {
            for (int j = v0; j < k; j++)
                if (a[j] + 3u * (uint32_t)(k - j) < m) m = a[j] + 3u * (uint32_t)(k - j);
            if (b[v0] + 3u * (uint32_t)(k - v0 + 1) < m) m = b[v0] + 3u * (uint32_t)(k - v0 + 1);
        } else {
            for (int j = k + 1; j < v0 + vh; j++)
                if (a[j] + 3u * (uint32_t)(j - k) < m) m = a[j] + 3u * (uint32_t)(j - k);
            if (b[v0] + 3u * (uint32_t)(v0 + vh - k) < m) m = b[v0] + 3u * (uint32_t)(v0 + vh - k);
        }
        return m;
    }
    }
    return 0xDEADBEEFu;
}

/* element k of the output in the op's type */
static uint32_t got(int op, const uint32_t *out, int k)
{
    switch (op) {
    case QC_SIGN_BITS: case QC_SIGN_FILL: return ((const uint8_t *)(const void *)out)[k];
    case QC_LOAD_U16: return out[k];
    default: return ((const uint16_t *)(const void *)out)[k];
    }
}

static void check_isa(void **state)
{
    const ef_isa isa = tu_simd_test_isa(state, " refine", "the refine ops of ");
    tu_simd_qcheck_fn *const fn = tu_simd_qcheck_isa[tu_simd_isa_index_of(state)];
    static uint16_t a[N], b[N];
    static uint32_t out[N];
    static const uint16_t sp[] = { 0, 1, 127, 128, 255, 0x7F80u, 0x80FFu, 0x7FFFu, 0x8000u,
                                   0xFFFFu, 0xFFFEu, 0x00FFu };
    const int ns = (int)(sizeof sp / sizeof sp[0]);
    long checked = 0, bad = 0, leu_true = 0, leu_false = 0;
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (int round = 0; round < 8; round++) {
        for (int op = 0; op < QC_COUNT; op++) {
            for (int i = 0; i < N; i++) {
                a[i] = (tu_xorshift(&s) & 3) == 0 ? sp[tu_xorshift(&s) % (unsigned)ns]
                       : (uint16_t)tu_xorshift(&s);
                b[i] = (tu_xorshift(&s) & 3) == 0 ? sp[tu_xorshift(&s) % (unsigned)ns]
                       : (uint16_t)tu_xorshift(&s);
                /* odd rounds: b below a, so that a row's any-<= is often false
                 * (and true by a single lane where a is 0 or a planted one) */
                /* the running minima: half the rounds chamfer-like rows
                 * (small rising / falling values, caps), so that long
                 * chains of +3 win; the others the full range */
                if ((op == QC_H_RUNMIN3_UP || op == QC_H_RUNMIN3_DN) && round % 2) {
                    const unsigned r = tu_xorshift(&s) % 8u;
                    a[i] = r == 0 ? 387u : r == 1 ? 3u : (uint16_t)(tu_xorshift(&s) % 400u);
                    b[i] = (uint16_t)(tu_xorshift(&s) % 64u);
                }
                if (op == QC_H_ANY_LEU && round % 2) {
                    a[i] = (uint16_t)(a[i] | 1u);
                    b[i] = (uint16_t)(a[i] - 1u);
                    if (tu_xorshift(&s) % 97 == 0) b[i] = a[i];
                }
                out[i] = 0xA5A5A5A5u;
            }
            const int W = fn(op, a, b, N, out);
            assert_true(W == 4 || W == 8 || W == 16);
            for (int k = 0; k < N; k++) {
                const uint32_t want = model(op, a, b, k, W), g = got(op, out, k);
                if (op == QC_H_ANY_LEU && k % (2 * W) == 0) *(want ? &leu_true : &leu_false) += 1;
                checked++;
                if (g != want && bad++ < 8)
                    print_message("FAIL %s %s element %d: a=0x%04X b=0x%04X got 0x%X want 0x%X\n",
                                  ef_isa_name(isa), names[op], k, a[k], b[k], g, want);
            }
        }
    }
    print_message("NOTE cpu simd refine %s: %ld results equal to the scalar model "
                  "(vh_any_leu %ld true, %ld false)\n",
                  ef_isa_name(isa), checked - bad, leu_true, leu_false);
    assert_true(leu_true > 0 && leu_false > 0);
    assert_int_equal(bad, 0);
}

int main(void) { return tu_simd_run_isas(check_isa); }
