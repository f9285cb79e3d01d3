/* test_raster_hidden.c - the SIMD scans' box depth test (raster_simd.inl,
 * simd_box_hidden: a triangle whose box holds no depth value above a
 * bound of its z is not scanned) against the scalar reference, byte for
 * byte, where the bound's margin matters: one plane tessellated twice
 * (the two diagonals: the same depths up to the set-up's rounding),
 * copies with every vertex's z moved by a few ulps, layers far behind
 * (hidden: the test's main use) and partly in front, cells from 2 to 40
 * pixels wide (the one-vector and the wide loops), boxes cut by the
 * target's right edge (masked loads), depth values of NaN and above 1.
 * Seeded; every plane, padding included, and the
 * counters must equal the reference's.
 *
 * The same test in the vector front ends (raster_frontv.inl, fv_hidden:
 * records found hidden before they are written, RAST__HIDDEN): the draw
 * through rast__draw_valid_vb (AVX2, AVX-512 front ends with their scans)
 * against the reference, planes, counters and dirty tiles; and record by
 * record, every record a front end marks hidden, set up without the test
 * and scanned by the reference at that point of the draw, writes nothing
 * (and the others are the records written without the test, byte for
 * byte), with at least one hidden record over the cases.
 *
 * An ISA the CPU lacks is reported ("SKIP ...") and skipped. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "support/isa_tests.h"
#include "support/x86_only.h"
#include "../src/cpu/ef_mem.h"

#if EF_TEST_X86

#define NA 3
#define NCASES 60

typedef struct hcase {
    int w, h, pad;
    int nv, nt;
    float *clip, *attr;
    uint32_t *idx;
    int poison;   /* 0: cleared depth; 1: some NaN and > 1 depth values */
} hcase;

/* One layer: a grid of gx x gy cells over the NDC rectangle (x0, y0) ..
 * (x1, y1) on the plane z_ndc = a + b*x + c*y, per-vertex w; diag picks
 * the diagonal; zulp moves each vertex's clip z by up to zulp ulps. */
static void add_layer(hcase *k, tu_rng *r, int cap_v, int cap_t, float x0, float y0, float x1,
                      float y1, int gx, int gy, float a, float b, float c, int diag, int zulp)
{
    const int base = k->nv;
    if (base + (gx + 1) * (gy + 1) > cap_v || k->nt + 2 * gx * gy > cap_t)
        return;
    for (int j = 0; j <= gy; j++)
        for (int i = 0; i <= gx; i++) {
            const float x = x0 + (x1 - x0) * (float)i / (float)gx;
            const float y = y0 + (y1 - y0) * (float)j / (float)gy;
            const float w = tu_range(r, 0.5f, 3.0f);
            float *p = k->clip + 4 * k->nv;
            p[0] = x * w;
            p[1] = y * w;
            p[2] = (a + b * x + c * y) * w;
            p[3] = w;
            for (int u = zulp ? tu_int(r, 2 * zulp + 1) - zulp : 0; u != 0; u += u > 0 ? -1 : 1)
                p[2] = nextafterf(p[2], u > 0 ? INFINITY : -INFINITY);
            for (int q = 0; q < NA; q++)
                k->attr[NA * k->nv + q] = tu_range(r, -1.0f, 1.0f);
            k->nv++;
        }
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            const uint32_t v00 = (uint32_t)(base + j * (gx + 1) + i), v10 = v00 + 1;
            const uint32_t v01 = v00 + (uint32_t)(gx + 1), v11 = v01 + 1;
            uint32_t *t = k->idx + 3 * k->nt;
            if (diag) {
                t[0] = v00; t[1] = v10; t[2] = v11;
                t[3] = v00; t[4] = v11; t[5] = v01;
            } else {
                t[0] = v00; t[1] = v10; t[2] = v01;
                t[3] = v10; t[4] = v11; t[5] = v01;
            }
            k->nt += 2;
        }
}

static void make_case(int n, hcase *k)
{
    tu_rng r = { 0x9E3779B97F4A7C15ull ^ (uint64_t)(n + 1) * 0xD1B54A32D192ED03ull };
    memset(k, 0, sizeof *k);
    k->w = 64 + tu_int(&r, 200);
    k->h = 32 + tu_int(&r, 120);
    k->pad = tu_int(&r, 9);
    k->poison = n % 4 == 3;
    const int cap_v = 12000, cap_t = 20000;
    k->clip = calloc((size_t)cap_v * 4, sizeof(float));
    k->attr = calloc((size_t)cap_v * NA, sizeof(float));
    k->idx = calloc((size_t)cap_t * 3, sizeof(uint32_t));
    assert_non_null(k->clip);
    assert_non_null(k->attr);
    assert_non_null(k->idx);
    /* the plane: depth in about 0.2 .. 0.8, a random slope */
    const float a = tu_range(&r, -0.4f, 0.4f);
    /* half of the planes nearly flat (a few ulps of depth across a box:
     * where the set-up's and the scan's roundings decide) */
    const float sl = n % 2 ? 0.3f : 2e-6f;
    const float b = tu_range(&r, -sl, sl), c = tu_range(&r, -sl, sl);
    /* a rectangle reaching past the right edge now and then */
    const float x0 = tu_range(&r, -1.2f, 0.2f), y0 = tu_range(&r, -1.1f, 0.0f);
    const float x1 = tu_range(&r, x0 + 0.3f, 1.3f), y1 = tu_range(&r, y0 + 0.3f, 1.1f);
    /* cells of 2 .. 40 pixels */
    const float cw = tu_range(&r, 2.0f, 40.0f), ch = tu_range(&r, 2.0f, 20.0f);
    int gx = (int)((x1 - x0) * 0.5f * (float)k->w / cw) + 1;
    int gy = (int)((y1 - y0) * 0.5f * (float)k->h / ch) + 1;
    gx = gx > 60 ? 60 : gx;
    gy = gy > 40 ? 40 : gy;
    const int diag = tu_int(&r, 2);
    add_layer(k, &r, cap_v, cap_t, x0, y0, x1, y1, gx, gy, a, b, c, diag, 0);
    const int nl = 3 + tu_int(&r, 4);
    for (int l = 0; l < nl; l++) {
        switch (tu_int(&r, 5)) {
        /* each layer's draws one statement at a time (a defined order) */
        case 0: { /* the same plane, the other diagonal, other cells */
            const int cx = 1 + tu_int(&r, gx + 2), cy = 1 + tu_int(&r, gy + 2);
            add_layer(k, &r, cap_v, cap_t, x0, y0, x1, y1, cx, cy, a, b, c, !diag, 0);
            break;
        }
        case 1: { /* the same grid, z moved by a few ulps */
            const int dg = tu_int(&r, 2), ulps = 1 + tu_int(&r, 4);
            add_layer(k, &r, cap_v, cap_t, x0, y0, x1, y1, gx, gy, a, b, c, dg, ulps);
            break;
        }
        case 2: { /* behind: hidden where the first layer covers */
            const float dz = tu_range(&r, 1e-6f, 0.1f);
            const float sx = tu_range(&r, -0.2f, 0.2f);
            const float sy = tu_range(&r, -0.2f, 0.2f);
            const int cx = 1 + tu_int(&r, 2 * gx + 1);
            const int cy = 1 + tu_int(&r, 2 * gy + 1);
            const int dg = tu_int(&r, 2);
            add_layer(k, &r, cap_v, cap_t, x0 + sx, y0, x1, y1 + sy, cx, cy, a + dz, b, c, dg, 0);
            break;
        }
        case 3: { /* in front, a smaller patch */
            const float dz = tu_range(&r, 1e-6f, 0.05f);
            const int cx = 1 + tu_int(&r, gx), cy = 1 + tu_int(&r, gy), dg = tu_int(&r, 2);
            add_layer(k, &r, cap_v, cap_t, x0 * 0.5f, y0 * 0.5f, x1 * 0.5f, y1 * 0.5f, cx, cy,
                      a - dz, b, c, dg, 0);
            break;
        }
        default: { /* a tilted plane through the first one */
            const int cx = 1 + tu_int(&r, gx + 1), cy = 1 + tu_int(&r, gy + 1);
            const float dc = tu_range(&r, -0.2f, 0.2f);
            const int dg = tu_int(&r, 2);
            add_layer(k, &r, cap_v, cap_t, x0, y0, x1, y1, cx, cy, a, -b, c + dc, dg, 0);
            break;
        }
        }
    }
}

static void free_case(hcase *k)
{
    free(k->clip);
    free(k->attr);
    free(k->idx);
}

static rast_target target_make(const hcase *k)
{
    rast_target t;
    memset(&t, 0, sizeof t);
    t.width = k->w;
    t.height = k->h;
    t.mask_stride = k->w + k->pad;
    t.depth_stride = k->w + k->pad;
    t.attr_count = NA;
    t.attr_stride = k->w * NA + k->pad;
    t.mask = malloc((size_t)t.mask_stride * (size_t)t.height);
    t.depth = malloc((size_t)t.depth_stride * (size_t)t.height * sizeof(float));
    t.attr = malloc((size_t)t.attr_stride * (size_t)t.height * sizeof(float));
    assert_non_null(t.mask);
    assert_non_null(t.depth);
    assert_non_null(t.attr);
    return t;
}

static void target_reset(const hcase *k, const rast_target *t)
{
    memset(t->mask, 0x5A, (size_t)t->mask_stride * (size_t)t->height);
    memset(t->depth, 0x5A, (size_t)t->depth_stride * (size_t)t->height * sizeof(float));
    memset(t->attr, 0x5A, (size_t)t->attr_stride * (size_t)t->height * sizeof(float));
    rast_target_clear(t);
    if (k->poison) {
        /* NaN (no box holding one may be skipped) and 2.0 (a clamped z
         * of 1 passes it) in a pattern of columns and rows. */
        for (int y = 0; y < t->height; y++)
            for (int x = 0; x < t->width; x++)
                if ((x * 7 + y * 3) % 11 == 0)
                    t->depth[(size_t)y * (size_t)t->depth_stride + (size_t)x] =
                        (x + y) % 2 ? NAN : 2.0f;
    }
}

static int planes_equal(const rast_target *a, const rast_target *b)
{
    return !memcmp(a->mask, b->mask, (size_t)a->mask_stride * (size_t)a->height) &&
           !memcmp(a->depth, b->depth, (size_t)a->depth_stride * (size_t)a->height * 4) &&
           !memcmp(a->attr, b->attr, (size_t)a->attr_stride * (size_t)a->height * 4);
}

static rast_mesh_desc mesh_of(const hcase *k)
{
    rast_mesh_desc m;
    memset(&m, 0, sizeof m);
    m.clip = k->clip;
    m.vertex_count = k->nv;
    m.attr = k->attr;
    m.attr_count = NA;
    m.indices = k->idx;
    m.tri_count = k->nt;
    m.cull = RAST_CULL_NONE;
    return m;
}

static void draw(const hcase *k, const rast_target *t, rast__scan_rows_fn scan, rast_stats *st)
{
    const rast_mesh_desc m = mesh_of(k);
    target_reset(k, t);
    memset(st, 0, sizeof *st);
    assert_int_equal(rast__draw_with(t, &m, st, scan), RAST_OK);
}

static void hidden_isa(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP raster hidden %s: this CPU does not run it\n",
                      ef_isa_name((ef_isa)isa));
        skip();
    }
    const rast__scan_rows_fn scan = rast__scan_for_isa(isa);
    assert_true(scan != rast__scan_rows_ref);
    long written = 0;
    for (int n = 0; n < NCASES; n++) {
        hcase k;
        make_case(n, &k);
        rast_target ref = target_make(&k), got = target_make(&k);
        rast_stats sr, sg;
        draw(&k, &ref, rast__scan_rows_ref, &sr);
        draw(&k, &got, scan, &sg);
        if (!planes_equal(&ref, &got) || memcmp(&sr, &sg, sizeof sr)) {
            print_error("case %d (%dx%d, %d triangles, poison %d) on %s differs from the "
                        "reference (pixels %ld / %ld)\n", n, k.w, k.h, k.nt, k.poison,
                        ef_isa_name((ef_isa)isa), sr.pixels_written, sg.pixels_written);
            fail();
        }
        written += sr.pixels_written;
        EF_FREE_ALL(ref.mask, ref.depth, ref.attr, got.mask, got.depth, got.attr);
        free_case(&k);
    }
    assert_true(written > 0);
}

/* The vector front end of isa (avx2 or avx512); NULL, with the skip's
 * reason printed, when this CPU does not run it. */
static const rast__setup_isa *front_setup(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP raster hidden front %s: this CPU does not run it\n",
                      ef_isa_name((ef_isa)isa));
        return NULL;
    }
    return isa == EF_ISA_AVX512 ? &rast__setup_isa_avx512 : &rast__setup_isa_avx2;
}

/* The whole draw through the vector front end against the reference;
 * dirty tiles against the scalar set-up's with the same scan. */
static void front_draw_isa(int isa)
{
    const rast__setup_isa *si = front_setup(isa);
    if (!si)
        skip();
    const rast__scan_rows_fn scan = rast__scan_for_isa(isa);
    rast__vbuf *vb = rast__vbuf_alloc(12000);
    rast__tiles *tr = calloc(1, sizeof *tr), *tg = calloc(1, sizeof *tg);
    assert_non_null(vb);
    assert_non_null(tr);
    assert_non_null(tg);
    for (int n = 0; n < NCASES; n++) {
        hcase k;
        make_case(n, &k);
        const rast_mesh_desc m = mesh_of(&k);
        rast_target ref = target_make(&k), got = target_make(&k), sc = target_make(&k);
        rast_stats sr, sg = { 0 }, ss = { 0 };
        draw(&k, &ref, rast__scan_rows_ref, &sr);
        target_reset(&k, &got);
        target_reset(&k, &sc);
        memset(tr, 0, sizeof *tr);
        memset(tg, 0, sizeof *tg);
        rast__draw_valid_vb(&got, &m, &sg, scan, si, tg, vb);
        rast__draw_valid(&sc, &m, &ss, scan, si, tr);
        if (!planes_equal(&ref, &got) || memcmp(&sr, &sg, sizeof sr) ||
            memcmp(tr, tg, sizeof *tr)) {
            print_error("case %d (%dx%d, %d triangles, poison %d): the %s front end differs "
                        "from the reference (pixels %ld / %ld)\n", n, k.w, k.h, k.nt,
                        k.poison, ef_isa_name((ef_isa)isa), sr.pixels_written,
                        sg.pixels_written);
            fail();
        }
        rast_target *ts[3] = { &ref, &got, &sc };
        for (int i = 0; i < 3; i++) {
            free(ts[i]->mask);
            free(ts[i]->depth);
            free(ts[i]->attr);
        }
        free_case(&k);
    }
    free(tr);
    free(tg);
    rast__vbuf_free(vb);
}

/* Record by record: chunks set up with and without the test against the
 * depth of the chunks before (scanned by the reference). */
static void front_records_isa(int isa)
{
    const rast__setup_isa *si = front_setup(isa);
    if (!si)
        skip();
    const size_t nout = (size_t)RAST__VX_CHUNK * RAST__MAX_FAN;
    rast__vbuf *vb = rast__vbuf_alloc(12000);
    rast__tri *with = malloc(nout * sizeof *with), *without = malloc(nout * sizeof *without);
    assert_non_null(vb);
    assert_non_null(with);
    assert_non_null(without);
    long hidden = 0, records = 0;
    for (int n = 0; n < NCASES; n++) {
        hcase k;
        make_case(n, &k);
        const rast_mesh_desc m = mesh_of(&k);
        rast_target t = target_make(&k);
        target_reset(&k, &t);
        rast__view vw, vn;
        rast__view_init(&vn, t.width, t.height, NA);
        rast__view_init(&vw, t.width, t.height, NA);
        vw.hz = &t;
        si->vpass(&vn, m.clip, m.vertex_count, vb);
        rast_stats s1 = { 0 }, s2 = { 0 };
        int last[4] = { 1, 0, 1, 0 };
        for (int ti = 0; ti < m.tri_count; ti += RAST__VX_CHUNK) {
            const int te = m.tri_count - ti > RAST__VX_CHUNK ? ti + RAST__VX_CHUNK : m.tri_count;
            memset(with, 0x33, nout * sizeof *with);
            memset(without, 0x33, nout * sizeof *without);
            const int n1 = si->frontv(&vw, &m, vb, ti, te, with, &s1, 1);
            const int n2 = si->frontv(&vn, &m, vb, ti, te, without, &s2, 1);
            assert_int_equal(n1, n2);
            for (int i = 0; i < n1; i++) {
                records++;
                if (with[i].micro != RAST__HIDDEN) {
                    assert_memory_equal(&with[i], &without[i], sizeof with[i]);
                    continue;
                }
                hidden++;
                assert_int_equal(without[i].micro, 0);
                assert_memory_equal(&with[i], &without[i], 16);   /* the box */
                if (rast__scan_rows_ref(&t, &without[i], without[i].y0, without[i].y1) != 0) {
                    print_error("case %d: record %d of chunk %d marked hidden by the %s "
                                "front end writes pixels\n", n, i, ti / RAST__VX_CHUNK,
                                ef_isa_name((ef_isa)isa));
                    fail();
                }
            }
            rast__scan_list(&t, without, n2, rast__scan_rows_ref, NULL, last, 1);
        }
        assert_memory_equal(&s1, &s2, sizeof s1);
        free(t.mask);
        free(t.depth);
        free(t.attr);
        free_case(&k);
    }
    print_message("%s front end: %ld of %ld records hidden\n", ef_isa_name((ef_isa)isa), hidden,
                  records);
    assert_true(hidden > 0);
    free(with);
    free(without);
    rast__vbuf_free(vb);
}

TU_AVX_ISA_TESTS(test_front_draw_, front_draw_isa)
TU_AVX_ISA_TESTS(test_front_records_, front_records_isa)
TU_X86_ISA_TESTS(test_hidden_, hidden_isa)

TU_MAIN(NULL, NULL,
        TU_X86_ISA_UNIT_TESTS(test_hidden_),
        TU_AVX_ISA_UNIT_TESTS(test_front_draw_),
        TU_AVX_ISA_UNIT_TESTS(test_front_records_))

#else
EF_TEST_X86_SKIP("the SIMD scans' box depth test against the reference")
#endif
