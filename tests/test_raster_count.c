/* test_raster_count.c - rast_context_count: the number of nonzero mask
 * bytes of a target, read only in the tiles the context's draws marked
 * since its last rast_context_clear of that target (the pipe's coverage).
 *
 * Seeded frames of random triangle soups (on screen, across the borders,
 * behind the eye; both windings, every cull mode) drawn through contexts
 * of 1 and 2 threads (single draws: band mode; pairs: one job per
 * thread) into targets of 1x1 up to 700x300 with padded rows, the padding
 * filled with nonzero bytes: every count equals a scalar count of the
 * whole mask. Also: targets the context does not know (counted whole),
 * ctx NULL, arbitrary byte values, rows longer than the 16-bit-lane
 * chunk (255 x 16 bytes), bad targets (0), and that the tile restriction
 * is real (a byte written behind the context's back outside the marked
 * tiles is not counted; after rast_context_forget it is).
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "../src/raster/raster.h"
#include "test_raster_util.h"

static long count_ref(const rast_target *t)
{
    long n = 0;
    for (int y = 0; y < t->height; y++)
        for (int x = 0; x < t->width; x++)
            n += t->mask[(size_t)y * (size_t)t->mask_stride + x] != 0;
    return n;
}

typedef struct soup {
    float *clip;
    uint32_t *idx;
    int nv, nt;
} soup;

static void make_soup(tu_rng *r, soup *s)
{
    s->nt = 1 + tu_int(r, 60);
    s->nv = 3 * s->nt;
    s->clip = malloc((size_t)s->nv * 4 * sizeof(float));
    s->idx = malloc((size_t)s->nt * 3 * sizeof(uint32_t));
    assert_non_null(s->clip);
    assert_non_null(s->idx);
    for (int t = 0; t < s->nt; t++) {
        const int kind = tu_int(r, 10);
        const float cx = tu_range(r, -1.3f, 1.3f), cy = tu_range(r, -1.3f, 1.3f);
        const float size = kind < 6 ? tu_range(r, 0.001f, 0.2f) : tu_range(r, 0.2f, 2.5f);
        for (int k = 0; k < 3; k++) {
            float *c = s->clip + 4 * (3 * t + k);
            const float w = kind == 9 ? tu_range(r, -0.5f, 1.5f) : tu_range(r, 0.5f, 2.0f);
            c[0] = (cx + tu_range(r, -size, size)) * w;
            c[1] = (cy + tu_range(r, -size, size)) * w;
            c[2] = tu_range(r, -0.9f, 0.9f) * w;
            c[3] = w;
            s->idx[3 * t + k] = (uint32_t)(3 * t + k);
        }
    }
}

static void free_soup(soup *s)
{
    free(s->clip);
    free(s->idx);
}

static rast_target make_target(tu_rng *r, int big)
{
    const int W = big ? 200 + tu_int(r, 501) : 1 + tu_int(r, 90);
    const int H = big ? 100 + tu_int(r, 201) : 1 + tu_int(r, 60);
    const int ms = W + tu_int(r, 9), ds = W + tu_int(r, 5);
    rast_target t = { W, H, malloc((size_t)ds * H * sizeof(float)), ds, malloc((size_t)ms * H),
                      ms, NULL, 0, 0, NULL, 0 };
    assert_non_null(t.depth);
    assert_non_null(t.mask);
    memset(t.mask, 0x5A, (size_t)ms * H);   /* padding stays nonzero */
    return t;
}

static void free_target(rast_target *t)
{
    free(t->depth);
    free(t->mask);
}

static void test_count_frames(void **state)
{
    (void)state;
    tu_rng r = { 0xC0047ull };
    int counted = 0, nonzero = 0;
    for (int th = 1; th <= 2; th++) {
        for (int round = 0; round < 40; round++) {
            rast_context_desc d = { 0, th };
            rast_context *c = rast_context_create(&d);
            assert_non_null(c);
            rast_target t[2];
            for (int e = 0; e < 2; e++)
                t[e] = make_target(&r, round % 8 == 0);
            /* Not known yet: counted whole (the padding is not counted). */
            for (int e = 0; e < 2; e++)
                assert_int_equal(rast_context_count(c, &t[e]), count_ref(&t[e]));
            for (int frame = 0; frame < 6; frame++) {
                soup s[2];
                rast_mesh_desc m[2];
                for (int e = 0; e < 2; e++) {
                    rast_context_clear(c, &t[e]);
                    make_soup(&r, &s[e]);
                    rast_mesh_desc md = { s[e].clip, s[e].nv, NULL, 0, s[e].idx, s[e].nt,
                                          (rast_cull)tu_int(&r, 3) };
                    m[e] = md;
                }
                rt_context_draw_two(c, frame % 2, t, m);
                for (int e = 0; e < 2; e++) {
                    const long want = count_ref(&t[e]);
                    assert_int_equal(rast_context_count(c, &t[e]), want);
                    assert_int_equal(rast_context_count(NULL, &t[e]), want);
                    counted++;
                    nonzero += want > 0;
                    free_soup(&s[e]);
                }
            }
            for (int e = 0; e < 2; e++)
                free_target(&t[e]);
            rast_context_destroy(c);
        }
    }
    /* The cases must draw something most of the time. */
    assert_true(nonzero > counted / 2);
}

/* Arbitrary byte values, row lengths around the 255 x 16 byte chunk of
 * the 8-bit counters, unaligned starts. */
static void test_count_bytes(void **state)
{
    (void)state;
    tu_rng r = { 77 };
    static const int widths[] = { 1, 15, 16, 17, 31, 4079, 4080, 4081, 4096, 8192 };
    for (unsigned i = 0; i < sizeof widths / sizeof widths[0]; i++) {
        for (int rep = 0; rep < 8; rep++) {
            const int W = widths[i], H = 1 + tu_int(&r, 4), off = tu_int(&r, 16);
            const int stride = W + tu_int(&r, 3);
            uint8_t *buf = malloc((size_t)stride * H + 16);
            assert_non_null(buf);
            const int density = tu_int(&r, 4);   /* all zero .. all set */
            for (size_t k = 0; k < (size_t)stride * H + 16; k++)
                buf[k] = density == 0   ? 0
                         : density == 3 ? (uint8_t)(1 + tu_int(&r, 255))
                         : tu_int(&r, density + 1) ? (uint8_t)tu_int(&r, 256) : 0;
            rast_target t = { W, H, NULL, W, buf + off, stride, NULL, 0, 0, NULL, 0 };
            assert_int_equal(rast_context_count(NULL, &t), count_ref(&t));
            free(buf);
        }
    }
    rast_target bad = { 0, 4, NULL, 4, NULL, 4, NULL, 0, 0, NULL, 0 };
    assert_int_equal(rast_context_count(NULL, NULL), 0);
    assert_int_equal(rast_context_count(NULL, &bad), 0);
    uint8_t m[16] = { 1 };
    rast_target narrow = { 4, 4, NULL, 4, m, 3, NULL, 0, 0, NULL, 0 };   /* stride < width */
    assert_int_equal(rast_context_count(NULL, &narrow), 0);
}

/* The count of a known target reads only the marked tiles. */
static void test_count_tiles_only(void **state)
{
    (void)state;
    enum { W = 64, H = 48 };
    float depth[W * H];
    uint8_t mask[W * H];
    rast_target t = { W, H, depth, W, mask, W, NULL, 0, 0, NULL, 0 };
    rast_context *c = rast_context_create(NULL);
    assert_non_null(c);
    rast_context_clear(c, &t);
    /* One small triangle in the top-left tile. */
    const float clip[12] = { -1.0f, 1.0f, 0, 1, -0.8f, 1.0f, 0, 1, -1.0f, 0.7f, 0, 1 };
    const uint32_t idx[3] = { 0, 2, 1 };
    rast_mesh_desc md = { clip, 3, NULL, 0, idx, 1, RAST_CULL_NONE };
    assert_int_equal(rast_context_draw(c, &t, &md, NULL), RAST_OK);
    const long drawn = count_ref(&t);
    assert_true(drawn > 0);
    assert_int_equal(rast_context_count(c, &t), drawn);
    mask[(H - 1) * W + W - 1] = 255;   /* behind the context's back */
    assert_int_equal(rast_context_count(c, &t), drawn);
    assert_int_equal(rast_context_count(NULL, &t), drawn + 1);
    rast_context_forget(c);
    assert_int_equal(rast_context_count(c, &t), drawn + 1);
    rast_context_destroy(c);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_count_frames),
        cmocka_unit_test(test_count_bytes),
        cmocka_unit_test(test_count_tiles_only))
