/* raster_planes.h - a render target with its own planes for the raster
 * scan tests (tests/test_raster_small.c, tests/test_raster_span.c): the
 * planes of a target shape allocated (padding included), copied and
 * compared byte for byte, and one scan checked against the reference.
 * Header-only (static inline); include after support/testutil.h,
 * <cmocka.h>, src/cpu/cpu.h and src/raster/raster_internal.h. */
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

/* The clip-space part of a test vertex the set-up will use with a snapped
 * position given apart: w (1 in two cases of three, else 0.05..8), depth
 * z/w in -1.2..1.2, na attributes in -2..2 (x, y 0), drawn from r in this
 * order. */
static inline void planes_draw_vert(tu_rng *r, rast__vert *v, int na)
{
    const float w = tu_int(r, 3) ? 1.0f : tu_range(r, 0.05f, 8.0f);
    v->x = 0.0f;   /* the set-up uses the snapped fx, fy */
    v->y = 0.0f;
    v->z = tu_range(r, -1.2f, 1.2f) * w;
    v->w = w;
    for (int k = 0; k < na; k++)
        v->a[k] = tu_range(r, -2.0f, 2.0f);
}

/* Scans tri over rows ya..yb into ref's planes with the reference and into
 * a copy with scan (of ISA isa, for the message); fails the test (case n)
 * unless the pixel counts and every byte of the planes agree. Returns the
 * reference's pixel count. */
static inline long planes_check_scan(planes *ref, const rast__tri *tri, int ya, int yb,
                                     rast__scan_rows_fn scan, int isa, int n)
{
    planes got;
    planes_alloc(&got, &ref->t);
    planes_copy(&got, ref);
    const long wr = rast__scan_rows_ref(&ref->t, tri, ya, yb);
    const long wg = scan(&got.t, tri, ya, yb);
    if (wr != wg || !planes_equal(ref, &got)) {
        print_error("case %d (%s): box %d..%d x %d..%d rows %d..%d: %ld vs %ld pixels, "
                    "planes %s\n",
                    n, ef_isa_name((ef_isa)isa), tri->x0, tri->x1, tri->y0, tri->y1, ya, yb,
                    wr, wg, planes_equal(ref, &got) ? "equal" : "differ");
        fail();
    }
    planes_free(&got);
    return wr;
}

#endif
