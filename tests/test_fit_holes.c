/* test_fit_holes.c - small holes and islands of a refined mask
 * (src/fit/fit_holes.h, issue 14 item 2), on seeded masks against a
 * direct reference (4-connected flood fill per component):
 * - every hole (clear component touching no border) of at most max_hole
 *   pixels is set to 255, every island (set component touching no border)
 *   of at most max_island pixels cleared, nothing else changes;
 * - with a kinematic mask `inside`, only holes it covers wholly are filled;
 * - the count returned is the pixels changed; a scratch too small leaves
 *   the mask as it was and returns -1; max 0 turns a half off. */
#include "support/testutil.h"

#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_holes.h"

enum { W = 67, H = 41, S = 70 };

static uint8_t m[S * H], ref[S * H], orig[S * H], ins[S * H];
static int comp[W * H], stack_[W * H];

/* ref = the rule applied by flood fill over orig */
static long reference(int max_hole, int max_island, const uint8_t *inside)
{
    memcpy(ref, orig, sizeof ref);
    for (int i = 0; i < W * H; i++) comp[i] = -1;
    long changed = 0;
    for (int s = 0; s < W * H; s++) {
        if (comp[s] >= 0) continue;
        const int v = orig[(s / W) * S + s % W] >= 128;
        int n = 0, top = 0, border = 0;
        stack_[top++] = s;
        comp[s] = s;
        int *members = malloc(sizeof(int) * W * H);
        assert_non_null(members);
        while (top) {
            const int p = stack_[--top], x = p % W, y = p / W;
            members[n++] = p;
            if (x == 0 || y == 0 || x == W - 1 || y == H - 1) border = 1;
            const int nb[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
            for (int k = 0; k < 4; k++) {
                const int xx = nb[k][0], yy = nb[k][1];
                if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                const int q = yy * W + xx;
                if (comp[q] >= 0 || (orig[yy * S + xx] >= 128) != v) continue;
                comp[q] = s;
                stack_[top++] = q;
            }
        }
        const int lim = v ? max_island : max_hole;
        int out = 0;   /* a hole's pixels outside `inside` */
        for (int k = 0; k < n && inside && !v; k++)
            out += inside[(members[k] / W) * S + members[k] % W] < 128;
        if (!border && n <= lim && !out)
            for (int k = 0; k < n; k++) {
                ref[(members[k] / W) * S + members[k] % W] = v ? 0 : 255;
                changed++;
            }
        free(members);
    }
    return changed;
}

/* blobs of random discs and rectangles, values 0..255 (>= 128 set) */
static void make_case(tu_rng *g)
{
    memset(orig, 0, sizeof orig);
    const int nd = 3 + tu_int(g, 12);
    for (int d = 0; d < nd; d++) {
        const int cx = tu_int(g, W);
        const int cy = tu_int(g, H);
        const int r = 1 + tu_int(g, 14);
        const int set = tu_int(g, 3) != 0;
        const int lvl = set ? 128 + tu_int(g, 128) : tu_int(g, 128);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r) orig[y * S + x] = (uint8_t)lvl;
    }
    const int ns = tu_int(g, 40);   /* specks */
    for (int k = 0; k < ns; k++) {
        const int x = tu_int(g, W);
        const int y = tu_int(g, H);
        orig[y * S + x] = orig[y * S + x] >= 128 ? 0 : 255;
    }
    /* the padding beyond W must not be read: a value that would join */
    for (int y = 0; y < H; y++) memset(orig + y * S + W, 0x5a, S - W);
}

static void against_reference(void **state)
{
    (void)state;
    tu_rng g = {1414};
    const size_t sz = pipe_fit_fill_scratch_size(W, H);
    assert_true(sz > 0);
    void *scratch = malloc(sz);
    assert_non_null(scratch);
    long total = 0;
    for (int c = 0; c < 400; c++) {
        make_case(&g);
        const int mh = tu_int(&g, 60);
        const int mi = tu_int(&g, 60);
        /* every other case: holes only where `inside` (random discs) is set */
        const uint8_t *in = NULL;
        if (c & 1) {
            memset(ins, 0, sizeof ins);
            const int nd = 1 + tu_int(&g, 6);
            for (int d = 0; d < nd; d++) {
                const int cx = tu_int(&g, W);
                const int cy = tu_int(&g, H);
                const int r = 3 + tu_int(&g, 20);
                for (int y = 0; y < H; y++)
                    for (int x = 0; x < W; x++)
                        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r) ins[y * S + x] = 255;
            }
            in = ins;
        }
        const long want = reference(mh, mi, in);
        memcpy(m, orig, sizeof m);
        const long got = pipe_fit_fill_small(m, S, W, H, mh, mi, in, S, scratch, sz);
        if (got != want || memcmp(m, ref, sizeof m) != 0)
            fail_msg("case %d (holes %d, islands %d): %ld changed, want %ld", c, mh, mi, got, want);
        total += got;
    }
    assert_true(total > 1000);   /* the cases have holes and islands */
    free(scratch);
}

/* a disc with a 12-px hole and a 30-px hole, a 5-px island beside it */
static void disc_case(void)
{
    memset(orig, 0, sizeof orig);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            if ((x - 30) * (x - 30) + (y - 20) * (y - 20) <= 15 * 15) orig[y * S + x] = 255;
    for (int y = 15; y < 18; y++)
        for (int x = 25; x < 29; x++) orig[y * S + x] = 0;   /* 12 px */
    for (int y = 20; y < 25; y++)
        for (int x = 30; x < 36; x++) orig[y * S + x] = 0;   /* 30 px */
    for (int x = 55; x < 60; x++) orig[10 * S + x] = 200;   /* island, 5 px */
    for (int x = 0; x < 6; x++) orig[40 * S + x] = 255;     /* on the border: kept */
}

static void sizes_and_off(void **state)
{
    (void)state;
    const size_t sz = pipe_fit_fill_scratch_size(W, H);
    void *scratch = malloc(sz);
    assert_non_null(scratch);
    disc_case();
    memcpy(m, orig, sizeof m);
    assert_int_equal(pipe_fit_fill_small(m, S, W, H, 12, 0, NULL, 0, scratch, sz), 12);
    assert_int_equal(m[16 * S + 26], 255);
    assert_int_equal(m[22 * S + 32], 0);
    assert_int_equal(m[10 * S + 57], 200);
    memcpy(m, orig, sizeof m);
    assert_int_equal(pipe_fit_fill_small(m, S, W, H, 30, 5, NULL, 0, scratch, sz), 47);
    assert_int_equal(m[22 * S + 32], 255);
    assert_int_equal(m[10 * S + 57], 0);
    assert_int_equal(m[40 * S + 2], 255);
    /* with the kinematic mask: only the hole it covers is filled */
    memset(ins, 0, sizeof ins);
    for (int y = 14; y < 19; y++)
        for (int x = 24; x < 30; x++) ins[y * S + x] = 255;
    memcpy(m, orig, sizeof m);
    assert_int_equal(pipe_fit_fill_small(m, S, W, H, 30, 0, ins, S, scratch, sz), 12);
    assert_int_equal(m[16 * S + 26], 255);
    assert_int_equal(m[22 * S + 32], 0);
    /* off, bad arguments, scratch too small: the mask as it was */
    memcpy(m, orig, sizeof m);
    assert_int_equal(pipe_fit_fill_small(m, S, W, H, 0, 0, NULL, 0, scratch, sz), 0);
    assert_int_equal(pipe_fit_fill_small(m, S, W, H, -1, 5, NULL, 0, scratch, sz), -1);
    assert_int_equal(pipe_fit_fill_small(m, W - 1, W, H, 30, 5, NULL, 0, scratch, sz), -1);
    assert_int_equal(pipe_fit_fill_small(m, S, W, H, 30, 5, NULL, 0, scratch, 200), -1);
    assert_int_equal(pipe_fit_fill_small(NULL, S, W, H, 30, 5, NULL, 0, scratch, sz), -1);
    assert_memory_equal(m, orig, sizeof m);
    assert_int_equal(pipe_fit_fill_scratch_size(0, H), 0);
    free(scratch);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(against_reference),
        cmocka_unit_test(sizes_and_off))
