/* test_raster_span.c - the SIMD scans of boxes wider than one vector (issue
 * 3): long thin slivers (capsule sides) whose row runs of covered pixels
 * straddle the boundaries of vectors aligned at the box's x0, which the
 * scan's multi-vector path does with vectors starting at each run's first
 * pixel. Byte for byte against the scalar reference scan.
 *
 * Triangles are set up by rast__setup_tri from snapped positions: slivers
 * from A to B (box 17..200 px wide, 1..300 rows, every slope, both
 * windings) with the third vertex 0.1..6 px off the line AB (a quarter of
 * the coordinates on a pixel centre or half a pixel off, so top-left ties
 * occur), some fat wide triangles (runs longer than a vector) and some
 * with a vertex far in the guard band (the int64 coverage path). Targets
 * of 24..300 x 1..320 pixels with padded strides, boxes clamped at every
 * border, random row bands ya..yb (as band threads scan), depth on and
 * off (filled with random values, so the LESS test passes and fails),
 * 0, 3 or 5 attributes with and without an attribute plane, depth planes
 * crossing 0 and 1, random w (perspective). Every plane, padding
 * included, and the returned pixel count are compared with memcmp; a
 * CRC over the reference output of all cases is checked against a
 * recorded constant, and the cases must hit the shapes named above. An
 * ISA the CPU lacks is reported ("SKIP") and skipped.
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "support/isa_tests.h"
#include "support/raster_planes.h"

#define NCASES 2500
#define PERIOD 1021
/* Recorded: the reference output of all cases. */
#define SPAN_CRC 0x0B137BDBu

/* A snapped coordinate (1/256 px) at pixel position c (in pixels, float):
 * on the centre of the pixel, half a pixel off, or c itself snapped. */
static int32_t snap_at(tu_rng *r, float c)
{
    const int32_t p = (int32_t)(c * (float)RAST__FIX_ONE);
    const int32_t centre = (p >> 8) * RAST__FIX_ONE + RAST__FIX_HALF;
    switch (tu_int(r, 8)) {
    case 0: return centre;
    case 1: return centre + RAST__FIX_HALF;
    default: return p;
    }
}

enum { KIND_SLIVER, KIND_FAT, KIND_GUARD };

/* Builds case n into *ref (planes filled) and *tri; returns the kind, or
 * -1 when the triangle was not set up (degenerate, off screen). */
static int make_case(int n, planes *ref, rast__tri *tri, int *ya, int *yb)
{
    tu_rng r = { 0x59A40000ull + (uint64_t)n * 0x9E3779B97F4A7C15ull };
    planes_draw(ref, &r, 24, 277, 320, 19, 20, 23);
    const rast_target shape = ref->t;
    const int na = shape.attr_count;
    /* Random contents (cheap: tables of a prime period, at a random
     * phase; depth 1.0 for a quarter of the pixels). */
    float dtab[PERIOD], atab[PERIOD];
    uint8_t mtab[PERIOD];
    for (int i = 0; i < PERIOD; i++) {
        dtab[i] = tu_int(&r, 4) ? tu_range(&r, 0.0f, 1.0f) : 1.0f;
        atab[i] = tu_range(&r, -1.0f, 1.0f);
        mtab[i] = (uint8_t)tu_int(&r, 2);
    }
    const int phase = tu_int(&r, PERIOD);
    for (size_t i = 0, k = (size_t)phase; i < ref->nd; i++, k = k + 1 < PERIOD ? k + 1 : 0)
        ref->depth[i] = dtab[k];
    for (size_t i = 0, k = (size_t)phase; i < ref->nm; i++, k = k + 1 < PERIOD ? k + 1 : 0)
        ref->mask[i] = mtab[k];
    for (size_t i = 0, k = (size_t)phase; i < ref->na; i++, k = k + 1 < PERIOD ? k + 1 : 0)
        ref->attr[i] = atab[k];

    /* A from which B lies bw px to the right (or left) and bh rows up or
     * down; A anywhere so that the box crosses every border at times. */
    const int kind = tu_int(&r, 16) < 13 ? KIND_SLIVER : tu_int(&r, 3) ? KIND_FAT : KIND_GUARD;
    /* whole, then fraction: drawn in order */
    const float bw_whole = (float)(17 + tu_int(&r, 184));
    const float bw = bw_whole - tu_unit(&r);
    float bh = 0.0f;
    if (tu_int(&r, 4)) bh = (float)tu_int(&r, 300);
    bh = bh + tu_unit(&r);
    const float ax = tu_range(&r, -0.5f * bw, (float)shape.width - 0.5f * bw);
    const float ay = tu_range(&r, -0.5f * bh, (float)shape.height + 0.5f * bh);
    const float sx = tu_int(&r, 2) ? 1.0f : -1.0f, sy = tu_int(&r, 2) ? 1.0f : -1.0f;
    const float bx = ax + sx * bw, by = ay + sy * bh;
    /* C: a point of AB pushed off the line by `off` px along the normal. */
    const float u = tu_unit(&r);
    const float len = sqrtf(bw * bw + bh * bh);
    /* A sliver's rows have runs of about `run` px: off = run * bh / len,
     * clamped to 0.1..6 px (near-horizontal slivers have longer runs). */
    const float run = tu_range(&r, 0.5f, 20.0f);
    float off = kind == KIND_SLIVER ? run * bh / len : tu_range(&r, 12.0f, 60.0f);
    off = off < 0.1f ? 0.1f : off > 60.0f ? 60.0f : off;
    if (kind == KIND_SLIVER && off > 6.0f)
        off = 6.0f;
    off *= tu_int(&r, 2) ? 1.0f : -1.0f;
    float cx = ax + u * (bx - ax) - off * (by - ay) / len;
    float cy = ay + u * (by - ay) + off * (bx - ax) / len;
    if (kind == KIND_GUARD) {   /* far out: |E'| beyond the int32 bound */
        cx = tu_int(&r, 2) ? tu_range(&r, -8000.0f, -3000.0f) : tu_range(&r, 3000.0f, 8000.0f);
        cy = tu_range(&r, -8000.0f, 8000.0f);
    }
    const float px[3] = { ax, bx, cx }, py[3] = { ay, by, cy };
    rast__vert v[3];
    int32_t fx[3], fy[3];
    for (int i = 0; i < 3; i++) {
        fx[i] = snap_at(&r, px[i]);
        fy[i] = snap_at(&r, py[i]);
        planes_draw_vert(&r, &v[i], na);
    }
    rast__view view;
    rast__view_init(&view, shape.width, shape.height, na);
    const rast__vert *pv[3] = { &v[0], &v[1], &v[2] };
    if (rast__setup_tri(&view, pv, fx, fy, RAST_CULL_NONE, tri) != RAST__SETUP_OK)
        return -1;
    /* Whole box, or a random band of rows (as a band thread scans). */
    *ya = tri->y0;
    *yb = tri->y1;
    if (tu_int(&r, 3) == 0) {
        *ya = tri->y0 + tu_int(&r, tri->y1 - tri->y0 + 2) - 1;
        *yb = *ya + tu_int(&r, 40);
    }
    return kind;
}

/* What the cases cover: rows of the scanned bands by the run of covered
 * pixels relative to 16-pixel vectors aligned at x0 (the AVX-512 scan's
 * widest vectors; narrower ones see at least as many crossings). */
typedef struct cover {
    long cases[3];           /* by kind */
    long straddle;           /* run <= 16 px across a boundary */
    long inside;             /* run <= 16 px inside one aligned vector */
    long longrun;            /* run > 16 px */
    long lead;               /* run starting after an empty aligned vector */
    long borders[4];         /* boxes touching left, right, top, bottom */
    long wide;               /* boxes wider than 16 px */
} cover;

static void cover_add(cover *cv, const rast__tri *tri, const rast_target *t, int ya, int yb)
{
    const int ys = ya > tri->y0 ? ya : tri->y0, ye = yb < tri->y1 ? yb : tri->y1;
    for (int y = ys; y <= ye; y++) {
        const int64_t j = y - tri->y0;
        int first = -1, last = -1;
        for (int64_t i = 0; i <= tri->x1 - tri->x0; i++) {
            const int64_t e = (tri->e_c[0] + j * tri->e_dy[0] + i * tri->e_dx[0]) |
                              (tri->e_c[1] + j * tri->e_dy[1] + i * tri->e_dx[1]) |
                              (tri->e_c[2] + j * tri->e_dy[2] + i * tri->e_dx[2]);
            if (e >= 0) {
                if (first < 0)
                    first = (int)i;
                last = (int)i;
            }
        }
        if (first < 0)
            continue;
        if (last - first + 1 > 16)
            cv->longrun++;
        else if (first / 16 != last / 16)
            cv->straddle++;
        else
            cv->inside++;
        cv->lead += first >= 16;
    }
    cv->borders[0] += tri->x0 == 0;
    cv->borders[1] += tri->x1 == t->width - 1;
    cv->borders[2] += tri->y0 == 0;
    cv->borders[3] += tri->y1 == t->height - 1;
    cv->wide += tri->x1 - tri->x0 + 1 > 16;
}

/* CRC of the pixel count and of the scanned rows of the box in every
 * plane (the scan writes nothing else: the rest is compared by memcmp). */
static uint32_t box_crc(uint32_t crc, const rast_target *t, const rast__tri *tri, int ya, int yb,
                        long written)
{
    const int ys = ya > tri->y0 ? ya : tri->y0, ye = yb < tri->y1 ? yb : tri->y1;
    const int64_t w = written;
    crc = tu_crc32(crc, &w, sizeof w);
    const size_t nx = (size_t)(tri->x1 - tri->x0 + 1);
    for (int y = ys; y <= ye; y++) {
        crc = tu_crc32(crc, t->mask + (size_t)y * (size_t)t->mask_stride + tri->x0, nx);
        if (t->depth)
            crc = tu_crc32(crc, t->depth + (size_t)y * (size_t)t->depth_stride + tri->x0,
                           nx * sizeof(float));
        if (t->attr)
            crc = tu_crc32(crc,
                           t->attr + (size_t)y * (size_t)t->attr_stride +
                               (size_t)tri->x0 * (size_t)t->attr_count,
                           nx * (size_t)t->attr_count * sizeof(float));
    }
    return crc;
}

/* The reference alone: what the cases cover, and the CRC of its output
 * (the same for every ISA, so computed once). */
static void test_span_reference(void **state)
{
    (void)state;
    uint32_t crc = 0;
    cover cv;
    memset(&cv, 0, sizeof cv);
    long written = 0;
    for (int n = 0; n < NCASES; n++) {
        planes ref;
        rast__tri tri;
        int ya, yb;
        const int kind = make_case(n, &ref, &tri, &ya, &yb);
        if (kind >= 0) {
            const long wr = rast__scan_rows_ref(&ref.t, &tri, ya, yb);
            cv.cases[kind]++;
            cover_add(&cv, &tri, &ref.t, ya, yb);
            crc = box_crc(crc, &ref.t, &tri, ya, yb, wr);
            written += wr;
        }
        planes_free(&ref);
    }
    print_message("NOTE reference: %ld slivers, %ld fat, %ld guard-band triangles (%ld boxes "
                  "wider than 16 px), %ld pixels written; rows with a run of <= 16 px across "
                  "a 16-px boundary %ld, inside one %ld, runs > 16 px %ld, after an empty "
                  "vector %ld; boxes on the left/right/top/bottom border %ld/%ld/%ld/%ld; "
                  "CRC32 0x%08X (recorded 0x%08X)\n",
                  cv.cases[KIND_SLIVER], cv.cases[KIND_FAT], cv.cases[KIND_GUARD], cv.wide,
                  written, cv.straddle, cv.inside, cv.longrun, cv.lead, cv.borders[0],
                  cv.borders[1], cv.borders[2], cv.borders[3], crc, SPAN_CRC);
    /* The shapes named in the header are all hit. */
    assert_true(cv.cases[KIND_SLIVER] > 1000 && cv.cases[KIND_FAT] > 50 &&
                cv.cases[KIND_GUARD] > 20);
    assert_true(cv.wide > 1000);
    assert_true(cv.straddle > 3000 && cv.inside > 10000 && cv.longrun > 5000);
    assert_true(cv.lead > 10000);
    for (int b = 0; b < 4; b++)
        assert_true(cv.borders[b] > 100);
    assert_true(written > 100000);
    assert_int_equal(crc, SPAN_CRC);
}

/* Every case through the ISA's scan and the reference on copies of the
 * same planes: equal bytes everywhere (padding included) and counts. */
static void span_isa(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP %s: not supported by this CPU; untested: the row scan of "
                      "src/raster/raster_%s.c\n", ef_isa_name((ef_isa)isa), ef_isa_name((ef_isa)isa));
        skip();
    }
    const rast__scan_rows_fn scan = rast__scan_for_isa(isa);
    long cases = 0, written = 0;
    for (int n = 0; n < NCASES; n++) {
        planes ref;
        rast__tri tri;
        int ya, yb;
        if (make_case(n, &ref, &tri, &ya, &yb) < 0) {
            planes_free(&ref);
            continue;
        }
        const long wr = planes_check_scan(&ref, &tri, ya, yb, scan, isa, n);
        cases++;
        written += wr;
        planes_free(&ref);
    }
    print_message("NOTE %s: %ld wide triangles, %ld pixels written, equal to the reference\n",
                  ef_isa_name((ef_isa)isa), cases, written);
    assert_true(cases > 1000 && written > 100000);
}

TU_ISA_TESTS(test_span_, span_isa)

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_span_reference),
        TU_ISA_UNIT_TESTS(test_span_))
