/* test_pipe_nfill.c - the normals a refined mask is lit with
 * (src/pipe/pipe_nfill.h, issue 14 item 3), on seeded masks and normals:
 * - every pixel of the refined mask within r of the model gets the sum of
 *   the model's normals over its window (against a direct sum);
 * - every other pixel of the refined mask connected to those (8-connected,
 *   through the mask) gets exactly the sum of one of them, no farther (3-4
 *   chamfer) than its shortest path through the mask (the seeds: the
 *   mask's pixels with a model pixel in their window); an unconnected one
 *   stays 0 (the lighting's view vector);
 * - a jump of the model's normal becomes a ramp 2 r + 1 px wide.
 * (pipe_frame's refined bytes on every ISA and thread count:
 * test_pipe_prior, test_pipe.) */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe_nfill.h"

enum { W = 61, H = 43 };

static float nrm[W * H * 3], out[W * H * 3], ref[W * H * 3];
static uint8_t km[W * H], rm[W * H];
static int cnt[W * H], geo[W * H];

static void direct(int r)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float s[3] = {0, 0, 0};
            int c = 0;
            for (int yy = y - r; yy <= y + r; yy++)
                for (int xx = x - r; xx <= x + r; xx++) {
                    if (xx < 0 || yy < 0 || xx >= W || yy >= H || !km[yy * W + xx]) continue;
                    for (int k = 0; k < 3; k++) s[k] += nrm[3 * (yy * W + xx) + k];
                    c++;
                }
            cnt[y * W + x] = c;
            memcpy(&ref[3 * (y * W + x)], s, sizeof s);
        }
}

/* shortest 3-4 chamfer path from a seed (a mask pixel with cnt > 0)
 * through mask pixels
 * (Bellman-Ford until stable); INT32 max: none */
static void geodesic(void)
{
    for (int i = 0; i < W * H; i++) geo[i] = cnt[i] > 0 && rm[i] ? 0 : 0x7fffffff;
    for (int changed = 1; changed;) {
        changed = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const int i = y * W + x;
                if (geo[i] == 0 || !rm[i]) continue;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        const int nx = x + dx, ny = y + dy;
                        if ((!dx && !dy) || nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
                        const int j = ny * W + nx;
                        if (geo[j] == 0x7fffffff) continue;
                        const int d = geo[j] + (dx && dy ? 4 : 3);
                        if (d < geo[i]) {
                            geo[i] = d;
                            changed = 1;
                        }
                    }
            }
    }
}

static int chamfer(int x0, int y0, int x1, int y1)
{
    int dx = abs(x1 - x0), dy = abs(y1 - y0);
    int lo = dx < dy ? dx : dy, hi = dx < dy ? dy : dx;
    return 4 * lo + 3 * (hi - lo);
}

static void make_case(tu_rng *g)
{
    memset(km, 0, sizeof km);
    memset(rm, 0, sizeof rm);
    memset(nrm, 0, sizeof nrm);
    /* the model: a few discs; the refined mask: those grown and shifted,
     * plus specks (some unconnected) and holes */
    const int nd = 1 + tu_int(g, 3);
    for (int d = 0; d < nd; d++) {
        const float cx = tu_range(g, 5, W - 5), cy = tu_range(g, 5, H - 5);
        const float rad = tu_range(g, 3, 12), grow = tu_range(g, 0, 9);
        const float sx = tu_range(g, -5, 5), sy = tu_range(g, -5, 5);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const float ex = x + 0.5f - cx, ey = y + 0.5f - cy;
                if (ex * ex + ey * ey < rad * rad) km[y * W + x] = 255;
                const float fx = ex - sx, fy = ey - sy;
                if (fx * fx + fy * fy < (rad + grow) * (rad + grow)) rm[y * W + x] = 255;
            }
    }
    for (int v = 255; v >= 0; v -= 255)   /* specks set, then holes */
        for (int k = tu_int(g, 20); k > 0; k--) {
            const int y = tu_int(g, H);
            rm[y * W + tu_int(g, W)] = (uint8_t)v;
        }
    for (int i = 0; i < W * H; i++)
        if (km[i])
            for (int k = 0; k < 3; k++) nrm[3 * i + k] = tu_range(g, -1, 1);
}

static void against_reference(void **state)
{
    (void)state;
    void *scratch = aligned_alloc(16, (pipe__nfill_scratch_size(W, H) + 15) & ~(size_t)15);
    assert_non_null(scratch);
    tu_rng g = {2024};
    long filled = 0, summed = 0, unconnected = 0;
    for (int c = 0; c < 300; c++) {
        make_case(&g);
        const int r = 1 + c % 4;
        for (int i = 0; i < W * H * 3; i++) out[i] = -99.0f;
        pipe__nfill_refined(rm, km, nrm, out, W, H, r, scratch);
        direct(r);
        geodesic();
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const int i = y * W + x;
                if (!rm[i]) continue;
                const float *o = &out[3 * i];
                if (cnt[i] > 0) {
                    for (int k = 0; k < 3; k++)
                        assert_true(fabsf(o[k] - ref[3 * i + k]) <= 1e-4f * (float)cnt[i]);
                    summed++;
                } else if (geo[i] == 0x7fffffff) {
                    assert_true(o[0] == 0.0f && o[1] == 0.0f && o[2] == 0.0f);
                    unconnected++;
                } else {
                    /* a seed's value, no farther than the path */
                    int found = 0;
                    for (int yy = 0; yy < H && !found; yy++)
                        for (int xx = 0; xx < W && !found; xx++) {
                            const int j = yy * W + xx;
                            found = cnt[j] > 0 && rm[j] && chamfer(x, y, xx, yy) <= geo[i] &&
                                    fabsf(o[0] - ref[3 * j]) <= 1e-4f * (float)cnt[j] &&
                                    fabsf(o[1] - ref[3 * j + 1]) <= 1e-4f * (float)cnt[j] &&
                                    fabsf(o[2] - ref[3 * j + 2]) <= 1e-4f * (float)cnt[j];
                        }
                    if (!found) fail_msg("case %d (%d, %d): no seed within %d", c, x, y, geo[i]);
                    filled++;
                }
            }
    }
    print_message("summed %ld, filled %ld, unconnected %ld\n", summed, filled, unconnected);
    assert_true(filled > 1000 && unconnected > 10);
    free(scratch);
}

/* a normal that jumps at x = 30 (left (0,0,1), right (1,0,0)): its
 * direction turns over 2 r + 1 columns, not at once */
static void jump_becomes_ramp(void **state)
{
    (void)state;
    void *scratch = aligned_alloc(16, (pipe__nfill_scratch_size(W, H) + 15) & ~(size_t)15);
    assert_non_null(scratch);
    for (int r = 1; r <= 4; r++) {
        memset(nrm, 0, sizeof nrm);
        for (int i = 0; i < W * H; i++) {
            km[i] = rm[i] = 255;
            nrm[3 * i + ((i % W) < 30 ? 2 : 0)] = 1.0f;
        }
        pipe__nfill_refined(rm, km, nrm, out, W, H, r, scratch);
        const int y = H / 2;
        int mixed = 0;
        for (int x = 0; x < W; x++) {
            const float *o = &out[3 * (y * W + x)];
            const float a = atan2f(o[0], o[2]);
            if (a > 0.01f && a < 1.56f) mixed++;
            if (x > 0) {
                const float *p = o - 3;
                assert_true(a + 1e-6f >= atan2f(p[0], p[2])); /* monotone */
            }
        }
        assert_int_equal(mixed, 2 * r);
    }
    free(scratch);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(against_reference),
        cmocka_unit_test(jump_becomes_ramp))
