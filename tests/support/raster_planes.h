/* raster_planes.h - a render target with its own planes for the raster
 * scan tests (tests/test_raster_small.c, tests/test_raster_span.c): the
 * planes of a target shape allocated (padding included), copied and
 * compared byte for byte. Header-only (static inline); include after
 * support/testutil.h, <cmocka.h> and src/raster/raster.h. */
#ifndef EGOFUSE_RASTER_PLANES_H
#define EGOFUSE_RASTER_PLANES_H

#include <stdlib.h>
#include <string.h>

typedef struct planes {
    rast_target t;
    float *depth, *attr;
    uint8_t *mask;
    size_t nd, nm, na;   /* floats, bytes, floats (whole strides) */
} planes;

/* Planes for shape (its depth and attr pointers only say whether the
 * plane exists); t is shape with the new planes. */
static inline void planes_alloc(planes *p, const rast_target *shape)
{
    p->t = *shape;
    p->nd = shape->depth ? (size_t)shape->depth_stride * (size_t)shape->height : 0;
    p->nm = (size_t)shape->mask_stride * (size_t)shape->height;
    p->na = shape->attr ? (size_t)shape->attr_stride * (size_t)shape->height : 0;
    p->depth = p->nd ? malloc(p->nd * sizeof(float)) : NULL;
    p->mask = malloc(p->nm);
    p->attr = p->na ? malloc(p->na * sizeof(float)) : NULL;
    assert_true(p->mask && (!p->nd || p->depth) && (!p->na || p->attr));
    p->t.depth = p->depth;
    p->t.mask = p->mask;
    p->t.attr = p->attr;
}

/* A random target shape drawn from r and its planes (in this order:
 * width w0 + [0, wn), height 1 + [0, hn), mask padding (none in a third of
 * the cases, else 1 + [0, padn)), 0, 3 or 5 attributes, a depth plane in
 * three cases of four with padding [0, dpadn), an attribute plane in four
 * of five when there are attributes, padding [0, apadn)); the planes are
 * not initialised. */
static inline void planes_draw(planes *p, tu_rng *r, int w0, int wn, int hn, int padn,
                               int dpadn, int apadn)
{
    rast_target shape;
    memset(&shape, 0, sizeof shape);
    shape.width = w0 + tu_int(r, wn);
    shape.height = 1 + tu_int(r, hn);
    const int pad = tu_int(r, 3) ? 1 + tu_int(r, padn) : 0;
    static const int nas[3] = { 0, 3, 5 };
    const int na = nas[tu_int(r, 3)];
    shape.mask_stride = shape.width + pad;
    if (tu_int(r, 4)) {
        shape.depth_stride = shape.width + tu_int(r, dpadn);
        shape.depth = (float *)1;   /* allocated by planes_alloc */
    }
    shape.attr_count = na;
    if (na && tu_int(r, 5)) {
        shape.attr_stride = shape.width * na + tu_int(r, apadn);
        shape.attr = (float *)1;
    }
    planes_alloc(p, &shape);
}

static inline void planes_copy(planes *dst, const planes *src)
{
    if (src->nd)
        memcpy(dst->depth, src->depth, src->nd * sizeof(float));
    memcpy(dst->mask, src->mask, src->nm);
    if (src->na)
        memcpy(dst->attr, src->attr, src->na * sizeof(float));
}

static inline int planes_equal(const planes *a, const planes *b)
{
    return (!a->nd || !memcmp(a->depth, b->depth, a->nd * sizeof(float))) &&
           !memcmp(a->mask, b->mask, a->nm) &&
           (!a->na || !memcmp(a->attr, b->attr, a->na * sizeof(float)));
}

static inline void planes_free(planes *p)
{
    free(p->depth);
    free(p->mask);
    free(p->attr);
}

#endif
