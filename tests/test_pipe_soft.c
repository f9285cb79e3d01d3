/* test_pipe_soft.c - soft silhouettes from the binary mask
 * (src/pipe/pipe_soft.h, pipe_desc.soft_edge; issue 14 item 3):
 * - against a direct count of the 3x3 window on seeded masks (values 0,
 *   255 and other non-zero bytes, the image's border counting as set), the
 *   box limiting what is written; the boxed form over 120 frames of one
 *   output equal to the whole image's, frame by frame;
 * - a straight edge becomes a one-pixel ramp inside the mask, a stair a
 *   ramp whose corners differ (not a hard step), the mask never grows;
 * - pipe_create refuses soft_edge with aa_samples or a value other than
 *   0 and 1 (with the eye view it softens the eye's mask:
 *   test_pipe_reproj.c). */
#include "support/testutil.h"

#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe.h"
#include "../src/pipe/pipe_soft.h"

enum { W = 53, H = 37 };

static uint8_t m[W * H], o[W * H];

static int count(int x, int y)
{
    int n = 0;
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            const int xx = x + dx, yy = y + dy;
            n += xx < 0 || yy < 0 || xx >= W || yy >= H ? 1 : m[yy * W + xx] != 0;
        }
    return n;
}

static void against_reference(void **state)
{
    (void)state;
    tu_rng g = {99};
    for (int c = 0; c < 200; c++) {
        const int dens = 1 + tu_int(&g, 9);
        for (int i = 0; i < W * H; i++) {
            const int on = tu_int(&g, 10) < dens;
            m[i] = on ? (tu_int(&g, 4) ? 255 : (uint8_t)(1 + tu_int(&g, 254))) : 0;
        }
        if (c % 2) {   /* solid discs of 255 (the 8-pixel paths) and specks */
            memset(m, 0, sizeof m);
            for (int k = 1 + tu_int(&g, 3); k > 0; k--) {
                const int cx = tu_int(&g, W), cy = tu_int(&g, H), r = 3 + tu_int(&g, 15);
                for (int y = 0; y < H; y++)
                    for (int x = 0; x < W; x++)
                        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r) m[y * W + x] = 255;
            }
            for (int k = tu_int(&g, 12); k > 0; k--) {
                const int y = tu_int(&g, H), x = tu_int(&g, W);
                m[y * W + x] = (uint8_t)tu_int(&g, 256);
            }
        }
        memset(o, 0xA5, sizeof o);
        int box[4] = {0, 0, 0, 0};
        box[0] = tu_int(&g, W);
        box[1] = tu_int(&g, H);
        box[2] = box[0] + 1 + tu_int(&g, W - box[0]);
        box[3] = box[1] + 1 + tu_int(&g, H - box[1]);
        pipe__soft_edge(m, o, W, H, c % 3 ? box : NULL);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const int in = c % 3 == 0 ||
                               (x >= box[0] && x < box[2] && y >= box[1] && y < box[3]);
                const uint8_t want =
                    !in ? 0xA5
                    : m[y * W + x] == 0 ? 0
                    : (uint8_t)(((unsigned)m[y * W + x] * (unsigned)count(x, y) + 4u) / 9u);
                if (o[y * W + x] != want)
                    fail_msg("case %d (%d, %d): %d, want %d", c, x, y, o[y * W + x], want);
            }
    }
}

/* pipe__soft_edge_boxed over 120 frames of one persistent output (its
 * bytes unknown at first: held = the whole image): blobs that move, grow,
 * vanish (empty frames) and touch the borders; after each frame out is,
 * byte for byte, pipe__soft_edge of the whole image, and held is the box
 * of the frame's set pixels. */
static void boxed_over_frames(void **state)
{
    (void)state;
    static uint8_t ref[W * H];
    tu_rng g = {0x50f7b0c5};
    int held[4] = {0, 0, W, H};
    memset(o, 0x5A, sizeof o);
    long empty = 0;
    for (int f = 0; f < 120; f++) {
        memset(m, 0, sizeof m);
        const int blobs = f % 7 == 3 ? 0 : 1 + tu_int(&g, 3);
        for (int k = 0; k < blobs; k++) {
            const int cx = tu_int(&g, W + 10) - 5, cy = tu_int(&g, H + 10) - 5, r = 1 + tu_int(&g, 12);
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++)
                    if ((x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r) m[y * W + x] = 255;
        }
        for (int k = blobs ? tu_int(&g, 4) : 0; k > 0; k--) {
            const int y = tu_int(&g, H), x = tu_int(&g, W), v = 1 + tu_int(&g, 255);
            m[y * W + x] = (uint8_t)v;
        }
        int bx[4] = {W, H, 0, 0};
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                if (m[y * W + x]) {
                    if (x < bx[0]) bx[0] = x;
                    if (x + 1 > bx[2]) bx[2] = x + 1;
                    if (y < bx[1]) bx[1] = y;
                    bx[3] = y + 1;
                }
        if (bx[2] == 0) {
            bx[0] = bx[1] = bx[3] = 0;
            empty++;
        }
        pipe__soft_edge_boxed(m, o, W, H, held);
        pipe__soft_edge(m, ref, W, H, NULL);
        if (memcmp(o, ref, sizeof ref)) fail_msg("frame %d: out differs from the whole image's", f);
        assert_memory_equal(held, bx, sizeof bx);
    }
    assert_true(empty > 10);
}

static void edges_become_ramps(void **state)
{
    (void)state;
    /* a half plane below row 20: the row 20 gets 6/9, the rest stays */
    memset(m, 0, sizeof m);
    for (int y = 20; y < H; y++)
        for (int x = 0; x < W; x++) m[y * W + x] = 255;
    pipe__soft_edge(m, o, W, H, NULL);
    for (int x = 1; x + 1 < W; x++) {   /* (beyond the border counts as set) */
        assert_int_equal(o[19 * W + x], 0);
        assert_int_equal(o[20 * W + x], (255 * 6 + 4) / 9);
        assert_int_equal(o[21 * W + x], 255);
    }
    /* a stair (one row down every 4 columns): the step's outer corner is
     * fainter than the straight run beside it, the inner corner fuller */
    memset(m, 0, sizeof m);
    for (int x = 0; x < W; x++)
        for (int y = 10 + x / 4; y < H; y++) m[y * W + x] = 255;
    pipe__soft_edge(m, o, W, H, NULL);
    /* column 7 is the last of the run starting at row 11, column 8 the
     * first at row 12: (7, 11) sticks out (5 of 9 set), (8, 12) sits in
     * the step's inner corner (7 of 9), (5, 11) is straight (6 of 9) */
    const int run = o[11 * W + 5];
    const int outer = o[11 * W + 7];
    const int inner = o[12 * W + 8];
    assert_int_equal(run, (255 * 6 + 4) / 9);
    assert_true(outer < run);
    assert_true(inner > run);
    for (int i = 0; i < W * H; i++) assert_true(o[i] <= m[i]);
}

static void create_refuses(void **state)
{
    (void)state;
    kin_model km;
    memset(&km, 0, sizeof km);
    pipe_desc d = {0};
    d.soft_edge = 2;
    assert_null(pipe_create(&d, &km));
    d.soft_edge = -1;
    assert_null(pipe_create(&d, &km));
    d.soft_edge = 1;
    d.aa_samples = 4;
    assert_null(pipe_create(&d, &km));
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(against_reference),
        cmocka_unit_test(boxed_over_frames),
        cmocka_unit_test(edges_become_ramps),
        cmocka_unit_test(create_refuses))
