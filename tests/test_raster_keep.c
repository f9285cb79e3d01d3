/* test_raster_keep.c - rast_context_clear_keep_attr: depth and mask as
 * rast_context_clear, the attribute plane left as the earlier draws
 * wrote it.
 *
 * Seeded frames (a large soup, then small ones) drawn through a context
 * of 1 or 2 threads into a target with 3 attributes and padded rows,
 * cleared with keep_attr: the depth and mask equal those of a fresh
 * target drawn with the same soup, bytes for bytes, and so do the
 * attributes of every pixel whose mask is nonzero (the contract); the
 * attributes elsewhere do hold stale values (the clear is really
 * skipped). Then rast_context_clear of the same target clears it whole
 * once: every byte, attributes included, equals the fresh target's.
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "../src/raster/raster.h"

typedef struct soup {
    float *clip, *attr;
    uint32_t *idx;
    int nv, nt;
} soup;

static void make_soup(tu_rng *r, soup *s, float size_max, int nt)
{
    s->nt = nt;
    s->nv = 3 * nt;
    s->clip = malloc((size_t)s->nv * 4 * sizeof(float));
    s->attr = malloc((size_t)s->nv * 3 * sizeof(float));
    s->idx = malloc((size_t)nt * 3 * sizeof(uint32_t));
    assert_non_null(s->clip);
    assert_non_null(s->attr);
    assert_non_null(s->idx);
    for (int t = 0; t < nt; t++) {
        const float cx = tu_range(r, -0.9f, 0.9f), cy = tu_range(r, -0.9f, 0.9f);
        for (int k = 0; k < 3; k++) {
            float *c = s->clip + 4 * (3 * t + k);
            const float w = tu_range(r, 0.5f, 2.0f);
            c[0] = (cx + tu_range(r, -size_max, size_max)) * w;
            c[1] = (cy + tu_range(r, -size_max, size_max)) * w;
            c[2] = tu_range(r, -0.9f, 0.9f) * w;
            c[3] = w;
            for (int a = 0; a < 3; a++) s->attr[3 * (3 * t + k) + a] = tu_range(r, -1.0f, 1.0f);
            s->idx[3 * t + k] = (uint32_t)(3 * t + k);
        }
    }
}

static void free_soup(soup *s)
{
    free(s->clip);
    free(s->attr);
    free(s->idx);
}


static rast_target make_target(int W, int H, int pad)
{
    const int ds = W + pad, ms = W + 2 * pad, as = 3 * W + pad;
    rast_target t = { W, H, malloc((size_t)ds * H * sizeof(float)), ds, malloc((size_t)ms * H), ms,
                      malloc((size_t)as * H * sizeof(float)), as, 3, NULL, 0 };
    assert_non_null(t.depth);
    assert_non_null(t.mask);
    assert_non_null(t.attr);
    memset(t.depth, 0, (size_t)ds * H * sizeof(float));
    memset(t.mask, 0, (size_t)ms * H);
    memset(t.attr, 0, (size_t)as * H * sizeof(float));
    return t;
}

static void free_target(rast_target *t)
{
    free(t->depth);
    free(t->mask);
    free(t->attr);
}

/* 1 when the planes of a and b (same size) hold the same bytes; attributes
 * only where a's mask is nonzero when masked_attr. */
static int same(const rast_target *a, const rast_target *b, int masked_attr)
{
    for (int y = 0; y < a->height; y++) {
        if (memcmp(a->depth + (size_t)y * a->depth_stride, b->depth + (size_t)y * b->depth_stride,
                   sizeof(float) * (size_t)a->width) ||
            memcmp(a->mask + (size_t)y * a->mask_stride, b->mask + (size_t)y * b->mask_stride,
                   (size_t)a->width))
            return 0;
        for (int x = 0; x < a->width; x++) {
            if (masked_attr && a->mask[(size_t)y * a->mask_stride + x] == 0) continue;
            if (memcmp(a->attr + (size_t)y * a->attr_stride + 3 * x,
                       b->attr + (size_t)y * b->attr_stride + 3 * x, 3 * sizeof(float)))
                return 0;
        }
    }
    return 1;
}

/* Nonzero attributes of pixels whose mask is 0. */
static long stale(const rast_target *a)
{
    long n = 0;
    for (int y = 0; y < a->height; y++)
        for (int x = 0; x < a->width; x++)
            if (a->mask[(size_t)y * a->mask_stride + x] == 0)
                for (int k = 0; k < 3; k++)
                    n += a->attr[(size_t)y * a->attr_stride + 3 * x + k] != 0.0f;
    return n;
}

static void draw(rast_context *c, const rast_target *t, const soup *s)
{
    rast_mesh_desc md = { s->clip, s->nv, s->attr, 3, s->idx, s->nt, RAST_CULL_NONE };
    assert_int_equal(rast_context_draw(c, t, &md, NULL), RAST_OK);
}

static void test_keep_attr_frames(void **state)
{
    (void)state;
    tu_rng r = { 0x6C1EA4ull };
    long stale_seen = 0;
    for (int th = 1; th <= 2; th++) {
        for (int round = 0; round < 6; round++) {
            rast_context_desc d = { 0, th };
            rast_context *c = rast_context_create(&d);
            assert_non_null(c);
            const int W = 100 + tu_int(&r, 400), H = 60 + tu_int(&r, 200);
            rast_target t = make_target(W, H, 1 + tu_int(&r, 7));
            soup s;
            make_soup(&r, &s, 0.8f, 40); /* large */
            rast_context_clear_keep_attr(c, &t); /* unknown: cleared whole */
            draw(c, &t, &s);
            free_soup(&s);
            for (int frame = 0; frame < 4; frame++) {
                make_soup(&r, &s, 0.1f, 1 + tu_int(&r, 6)); /* small */
                rast_context_clear_keep_attr(c, &t);
                draw(c, &t, &s);
                rast_target f = make_target(W, H, 0);
                rast_target_clear(&f);
                assert_int_equal(rast_draw(&f, &(rast_mesh_desc){ s.clip, s.nv, s.attr, 3, s.idx,
                                                                  s.nt, RAST_CULL_NONE },
                                           NULL),
                                 RAST_OK);
                assert_true(same(&t, &f, 1));
                stale_seen += stale(&t);
                /* the full clear after keep_attr: every byte */
                if (frame == 3) {
                    rast_context_clear(c, &t);
                    draw(c, &t, &s);
                    assert_true(same(&t, &f, 0));
                    assert_int_equal(stale(&t), 0);
                    rast_context_clear(c, &t); /* and the tile path again */
                    draw(c, &t, &s);
                    assert_true(same(&t, &f, 0));
                }
                free_target(&f);
                free_soup(&s);
            }
            free_target(&t);
            rast_context_destroy(c);
        }
    }
    assert_true(stale_seen > 0); /* the attribute clear was skipped */
}

/* ctx NULL and a target without attributes: as rast_context_clear. */
static void test_keep_attr_null(void **state)
{
    (void)state;
    rast_target t = make_target(33, 17, 2);
    memset(t.attr, 0x3F, (size_t)t.attr_stride * 17 * sizeof(float));
    memset(t.mask, 7, (size_t)t.mask_stride * 17);
    rast_context_clear_keep_attr(NULL, &t);
    rast_target f = make_target(33, 17, 2);
    rast_target_clear(&f);
    assert_true(same(&t, &f, 0));
    free_target(&f);
    free_target(&t);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_keep_attr_frames),
        cmocka_unit_test(test_keep_attr_null))
