/* test_raster_isa.c - every SIMD scan against the scalar reference, byte
 * for byte: seeded random triangle soups (slivers, huge, tiny, edge-on,
 * behind the camera, across the near plane, shared edges, NaN vertices,
 * attribute counts 0..8, odd target sizes and padded strides), a CRC over
 * all cases against a recorded constant, the public dispatch (rast_draw,
 * contexts, EGOFUSE_ISA) and band-parallel drawing with 1, 2, 3 and 4
 * threads giving the same bytes.
 *
 * An ISA the CPU lacks is reported ("SKIP ...") and skipped, never passed.
 *
 *   test_raster_isa        run the tests
 *   test_raster_isa N      rerun case N on every ISA and print the first
 *                          differing pixel (exit 1 if any differs)
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "test_raster_util.h"
#include "support/x86_only.h"
#include "../src/cpu/ef_mem.h"

#if EF_TEST_X86

/* Recorded CRC32 of the reference output over all NCASES cases (update it
 * together with SOUP_CRC of test_raster_basic.c when a rule changes). */
#define ISA_CRC 0x554E1221u
#define NCASES 4000

typedef struct rcase {
    rast_target t;
    rast_mesh_desc m;
    float *clip, *attr;
    uint32_t *idx;
    int attr_plane;       /* target has an attr plane */
} rcase;

static const int isas[] = { EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512 };

/* ---- case generator ----------------------------------------------------- */

static float pick_w(tu_rng *r)
{
    switch (tu_int(r, 6)) {
    case 0: return tu_range(r, -2.0f, 0.05f);      /* behind / at the eye */
    case 1: return tu_range(r, 0.01f, 0.2f);
    default: return tu_range(r, 0.5f, 4.0f);
    }
}

/* One vertex of kind k around NDC centre (cx, cy) with size s. */
static void make_vertex(tu_rng *r, float cx, float cy, float s, float *c)
{
    float w = pick_w(r);
    float aw = fabsf(w) > 1e-3f ? fabsf(w) : 1.0f;
    c[0] = (cx + tu_range(r, -s, s)) * aw;
    c[1] = (cy + tu_range(r, -s, s)) * aw;
    c[2] = tu_range(r, -1.3f, 1.3f) * aw;
    c[3] = w;
}

/* k's mesh: its nv vertices (na attributes each) and nt triangles, the
 * culling mode drawn from r. */
static void case_mesh(rcase *k, int nv, int na, int nt, tu_rng *r)
{
    rast_mesh_desc *m = &k->m;
    m->clip = k->clip;
    m->vertex_count = nv;
    m->attr = k->attr;
    m->attr_count = na;
    m->indices = k->idx;
    m->tri_count = nt;
    m->cull = (rast_cull)tu_int(r, 3);
}

/* Builds case n (seeded by n alone). */
static void make_case(int n, rcase *k)
{
    tu_rng r = { 0x15A0000ull + (uint64_t)n * 0x9E3779B97F4A7C15ull };
    memset(k, 0, sizeof *k);
    int big = tu_int(&r, 20) == 0;
    int w = big ? 200 + tu_int(&r, 500) : 1 + tu_int(&r, 90);
    int h = big ? 100 + tu_int(&r, 200) : 1 + tu_int(&r, 60);
    int pad = tu_int(&r, 3) == 0 ? 0 : 1 + tu_int(&r, 17);
    int na = tu_int(&r, 9);
    k->attr_plane = tu_int(&r, 4) != 0;
    rast_target *t = &k->t;
    t->width = w;
    t->height = h;
    t->mask_stride = w + pad;
    t->mask = malloc((size_t)t->mask_stride * h);
    if (tu_int(&r, 5) != 0) {
        t->depth_stride = w + tu_int(&r, 9);
        t->depth = malloc((size_t)t->depth_stride * h * sizeof(float));
    }
    t->attr_count = na;
    if (k->attr_plane && na > 0) {
        t->attr_stride = w * na + tu_int(&r, 11);
        t->attr = malloc((size_t)t->attr_stride * h * sizeof(float));
    }

    int ntri = big ? 1 + tu_int(&r, 12) : 1 + tu_int(&r, 40);
    int nv = 3 * ntri + 16;
    k->clip = malloc((size_t)nv * 4 * sizeof(float));
    k->attr = na ? malloc((size_t)nv * na * sizeof(float)) : NULL;
    k->idx = malloc((size_t)ntri * 3 * sizeof(uint32_t));
    int v = 0, ti = 0;
    while (ti < ntri) {
        int kind = big && tu_int(&r, 2) ? 2 : tu_int(&r, 10);
        float cx = tu_range(&r, -1.2f, 1.2f), cy = tu_range(&r, -1.2f, 1.2f);
        float s = tu_range(&r, 0.01f, 0.6f);
        if (kind == 0 && ti + 2 <= ntri && v + 4 <= nv) {
            /* Shared edges: a quad as two triangles (same w, same depth
             * plane), or a fan of four around a centre vertex. */
            float wq = tu_range(&r, 0.5f, 3.0f);
            for (int i = 0; i < 4; i++) {
                float *c = k->clip + 4 * (v + i);
                c[0] = (cx + ((i == 1 || i == 2) ? s : -s) + tu_range(&r, -0.1f, 0.1f) * s) * wq;
                c[1] = (cy + (i >= 2 ? s : -s) + tu_range(&r, -0.1f, 0.1f) * s) * wq;
                c[2] = tu_range(&r, -0.9f, 0.9f) * wq;
                c[3] = wq;
            }
            uint32_t q[6] = { 0, 1, 2, 0, 2, 3 };
            for (int i = 0; i < 6; i++)
                k->idx[3 * ti + i] = (uint32_t)v + q[i];
            v += 4;
            ti += 2;
            continue;
        }
        if (v + 3 > nv)
            break;
        float *c = k->clip + 4 * v;
        for (int i = 0; i < 3; i++)
            make_vertex(&r, cx, cy, s, c + 4 * i);
        switch (kind) {
        case 1:   /* sliver: third vertex near the line of the first two */
        {
            float f = tu_range(&r, -0.5f, 1.5f);
            for (int q = 0; q < 4; q++)
                c[8 + q] = c[q] + f * (c[4 + q] - c[q]);
            c[8] += tu_range(&r, -1e-3f, 1e-3f) * fabsf(c[11]);
            break;
        }
        case 2:   /* huge: around the view, up to far beyond the guard band
                     (long edges far from the pixels: the int64 path) */
            for (int i = 0; i < 3; i++) {
                float a = tu_range(&r, 0.0f, 6.2831853f);
                float rad = 1.5f * powf(8000.0f, tu_unit(&r));
                float aw = fabsf(c[4 * i + 3]) > 1e-3f ? fabsf(c[4 * i + 3]) : 1.0f;
                c[4 * i] = (cx + rad * cosf(a)) * aw;
                c[4 * i + 1] = (cy + rad * sinf(a)) * aw;
            }
            break;
        case 3:   /* tiny: within a pixel or two */
            for (int i = 1; i < 3; i++) {
                c[4 * i + 3] = c[3];
                c[4 * i] = c[0] + tu_range(&r, -0.02f, 0.02f) * fabsf(c[3]);
                c[4 * i + 1] = c[1] + tu_range(&r, -0.02f, 0.02f) * fabsf(c[3]);
            }
            break;
        case 4:   /* edge-on: a plane through the eye (same x/w for all) */
            for (int i = 1; i < 3; i++) {
                c[4 * i] = c[0] / c[3] * c[4 * i + 3];
            }
            break;
        case 5:   /* across the near plane */
            c[2] = -2.0f * fabsf(c[3]);
            c[6] = 0.5f * fabsf(c[7]);
            break;
        case 6:   /* rarely: a NaN or infinite coordinate */
            if (tu_int(&r, 8) == 0) {
                const int at = tu_int(&r, 12);   /* drawn in order */
                c[at] = tu_int(&r, 2) ? NAN : INFINITY;
            }
            break;
        default:
            break;
        }
        for (int i = 0; i < 3; i++)
            k->idx[3 * ti + i] = (uint32_t)(v + i);
        v += 3;
        ti++;
    }
    for (int i = 0; i < v * na; i++)
        k->attr[i] = tu_int(&r, 16) == 0 ? 1e5f * tu_range(&r, -1, 1) : tu_range(&r, -1, 1);
    case_mesh(k, v, na, ti, &r);
}

/* Fills every byte of the planes (padding included) with a pattern, then
 * clears: padding must come out unchanged. */
static void reset_target(const rast_target *t)
{
    memset(t->mask, 0x5A, (size_t)t->mask_stride * t->height);
    if (t->depth)
        memset(t->depth, 0x5A, (size_t)t->depth_stride * t->height * sizeof(float));
    if (t->attr)
        memset(t->attr, 0x5A, (size_t)t->attr_stride * t->height * sizeof(float));
    rast_target_clear(t);
}

static void free_case(rcase *k)
{
    EF_FREE_ALL(k->t.mask, k->t.depth, k->t.attr, k->clip, k->attr, k->idx);
}

typedef struct snapshot {
    uint8_t *mask;
    float *depth, *attr;
    rast_stats st;
} snapshot;

static size_t mask_bytes(const rast_target *t) { return (size_t)t->mask_stride * t->height; }
static size_t depth_n(const rast_target *t) { return t->depth ? (size_t)t->depth_stride * t->height : 0; }
static size_t attr_n(const rast_target *t) { return t->attr ? (size_t)t->attr_stride * t->height : 0; }

static void take(const rast_target *t, const rast_stats *st, snapshot *s)
{
    s->mask = malloc(mask_bytes(t));
    memcpy(s->mask, t->mask, mask_bytes(t));
    s->depth = depth_n(t) ? malloc(depth_n(t) * sizeof(float)) : NULL;
    if (s->depth) memcpy(s->depth, t->depth, depth_n(t) * sizeof(float));
    s->attr = attr_n(t) ? malloc(attr_n(t) * sizeof(float)) : NULL;
    if (s->attr) memcpy(s->attr, t->attr, attr_n(t) * sizeof(float));
    s->st = *st;
}

static void drop(snapshot *s)
{
    free(s->mask);
    free(s->depth);
    free(s->attr);
}

/* The first ISA from isa on (in the order of ef_isa) that this CPU runs,
 * or EF_ISA_COUNT when there is none. */
static int cpu_isa_from(int isa)
{
    while (isa < EF_ISA_COUNT && !ef_cpu_has((ef_isa)isa)) isa++;
    return isa;
}

/* A new context of the ISA isa with th threads (the test fails when it
 * cannot be made). */
static rast_context *context_of(int isa, int th)
{
    rast_context_desc d = { isa, th };
    rast_context *c = rast_context_create(&d);
    assert_non_null(c);
    return c;
}

/* The index of the first of the n elements (size bytes each) where a and b
 * differ, or n when none does. */
static size_t first_diff(const void *a, const void *b, size_t n, size_t size)
{
    for (size_t i = 0; i < n; i++)
        if (memcmp((const char *)a + i * size, (const char *)b + i * size, size)) return i;
    return n;
}

/* 0 if t equals the snapshot; else prints (when verbose) the first
 * differing element and returns 1. */
static int differs(const rast_target *t, const rast_stats *st, const snapshot *s,
                   const char *what, int verbose)
{
    if (!memcmp(t->mask, s->mask, mask_bytes(t)) &&
        (!t->depth || !memcmp(t->depth, s->depth, depth_n(t) * sizeof(float))) &&
        (!t->attr || !memcmp(t->attr, s->attr, attr_n(t) * sizeof(float))) &&
        !memcmp(st, &s->st, sizeof *st))
        return 0;
    if (!verbose)
        return 1;
    const size_t nm = mask_bytes(t), nd = depth_n(t), na = attr_n(t);
    size_t i;
    if ((i = first_diff(t->mask, s->mask, nm, 1)) < nm) {
        printf("%s: mask differs at x=%d y=%d: ref %d, got %d\n", what,
               (int)(i % t->mask_stride), (int)(i / t->mask_stride), s->mask[i], t->mask[i]);
    } else if ((i = first_diff(t->depth, s->depth, nd, sizeof(float))) < nd) {
        printf("%s: depth differs at x=%d y=%d: ref %.9g, got %.9g\n", what,
               (int)(i % t->depth_stride), (int)(i / t->depth_stride), s->depth[i], t->depth[i]);
    } else if ((i = first_diff(t->attr, s->attr, na, sizeof(float))) < na) {
        const size_t col = i % t->attr_stride;
        printf("%s: attribute %d differs at x=%d y=%d: ref %.9g, got %.9g\n", what,
               (int)(col % t->attr_count), (int)(col / t->attr_count),
               (int)(i / t->attr_stride), s->attr[i], t->attr[i]);
    } else {
        printf("%s: stats differ: pixels ref %ld got %ld, drawn ref %ld got %ld\n", what,
               s->st.pixels_written, st->pixels_written, s->st.tris_drawn, st->tris_drawn);
    }
    return 1;
}

/* 64-bit digest of a buffer (word-wise multiply-xorshift; tu_crc32 is
 * bitwise and would dominate the run time on megabytes per case). */
static uint64_t digest(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i += 8) {
        uint64_t w = 0;
        memcpy(&w, b + i, n - i < 8 ? n - i : 8);
        h = (h ^ w) * 0x100000001B3ull;
        h ^= h >> 29;
    }
    return h;
}

/* The CRC over all cases: CRC32 of the per-case digests of every plane
 * (padding included) and the stats. */
static uint32_t crc_target(uint32_t crc, const rast_target *t, const rast_stats *st)
{
    uint64_t h = digest(0xCBF29CE484222325ull, t->mask, mask_bytes(t));
    if (t->depth) h = digest(h, t->depth, depth_n(t) * sizeof(float));
    if (t->attr) h = digest(h, t->attr, attr_n(t) * sizeof(float));
    long v[7] = { st->tris_in, st->tris_nonfinite, st->tris_clipped_away,
                  st->tris_degenerate, st->tris_culled, st->tris_drawn,
                  st->pixels_written };
    h = digest(h, v, sizeof v);
    return tu_crc32(crc, &h, sizeof h);
}

/* Draws case k with scan into a freshly reset target. */
static void draw_case(rcase *k, rast__scan_rows_fn scan, rast_stats *st)
{
    reset_target(&k->t);
    memset(st, 0, sizeof *st);
    rast_target tt = k->t;
    assert_int_equal(rast__draw_with(&tt, &k->m, st, scan), RAST_OK);
}

/* ---- tests ------------------------------------------------------------- */

/* The soup on one ISA: every case equal to the reference. */
static void soup_isa(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP raster isa %s: this CPU does not run it; untested: the row scan of "
                      "src/raster/raster_%s.c\n", ef_isa_name((ef_isa)isa), ef_isa_name((ef_isa)isa));
        skip();
    }
    rast__scan_rows_fn scan = rast__scan_for_isa(isa);
    assert_true(scan != rast__scan_rows_ref);
    uint32_t crc_ref = 0;
    long pixels = 0, drawn = 0, clipped = 0, nonfinite = 0, degenerate = 0;
    for (int n = 0; n < NCASES; n++) {
        rcase k;
        make_case(n, &k);
        rast_stats st;
        draw_case(&k, rast__scan_rows_ref, &st);
        snapshot s;
        take(&k.t, &st, &s);
        crc_ref = crc_target(crc_ref, &k.t, &st);
        pixels += st.pixels_written;
        drawn += st.tris_drawn;
        clipped += st.tris_clipped_away;
        nonfinite += st.tris_nonfinite;
        degenerate += st.tris_degenerate;
        draw_case(&k, scan, &st);
        if (differs(&k.t, &st, &s, ef_isa_name((ef_isa)isa), 1))
            fail_msg("case %d: %s differs from the reference; rerun with "
                     "test_raster_isa %d", n, ef_isa_name((ef_isa)isa), n);
        drop(&s);
        free_case(&k);
    }
    print_message("NOTE %s: %d cases, %ld triangles drawn, %ld pixels, %ld clipped "
                  "away, %ld non-finite, %ld degenerate, all equal to the reference; "
                  "CRC32 0x%08X (recorded 0x%08X)\n", ef_isa_name((ef_isa)isa), NCASES,
                  drawn, pixels, clipped, nonfinite, degenerate, crc_ref, ISA_CRC);
    /* The soup really exercises every path. */
    assert_true(drawn > 20000 && pixels > 1000000 && clipped > 1000 &&
                nonfinite > 50 && degenerate > 500);
    assert_int_equal(crc_ref, ISA_CRC);
}

static void test_soup_sse2(void **state) { (void)state; soup_isa(EF_ISA_SSE2); }
static void test_soup_avx2(void **state) { (void)state; soup_isa(EF_ISA_AVX2); }
static void test_soup_avx512(void **state) { (void)state; soup_isa(EF_ISA_AVX512); }

/* A scene bigger than one batch round: a perspective grid of 4000 quads
 * (8000 triangles) with overlapping layers, drawn at 333 x 211 with 1, 2,
 * 3 and 4 threads on every ISA: all equal to the single-thread reference. */
static void test_threads_equal(void **state)
{
    (void)state;
    enum { W = 333, H = 211, G = 40, L = 5 };   /* 40x20 grid, 5 layers */
    const int nv = L * (G + 1) * (G / 2 + 1), nt = L * G * (G / 2) * 2;
    float *clip = malloc((size_t)nv * 4 * sizeof(float));
    float *attr = malloc((size_t)nv * 3 * sizeof(float));
    uint32_t *idx = malloc((size_t)nt * 3 * sizeof(uint32_t));
    tu_rng r = { 77 };
    int v = 0, ti = 0;
    for (int l = 0; l < L; l++) {
        int base = v;
        for (int j = 0; j <= G / 2; j++)
            for (int i = 0; i <= G; i++) {
                float w = tu_range(&r, 0.8f, 2.5f);
                clip[4 * v + 0] = (-1.3f + 2.6f * i / G + tu_range(&r, -0.02f, 0.02f)) * w;
                clip[4 * v + 1] = (-1.3f + 2.6f * j / (G / 2) + tu_range(&r, -0.02f, 0.02f)) * w;
                clip[4 * v + 2] = tu_range(&r, -0.9f, 0.9f) * w;
                clip[4 * v + 3] = w;
                for (int a = 0; a < 3; a++)
                    attr[3 * v + a] = tu_range(&r, -1, 1);
                v++;
            }
        for (int j = 0; j < G / 2; j++)
            for (int i = 0; i < G; i++) {
                uint32_t a = (uint32_t)(base + j * (G + 1) + i);
                uint32_t q[6] = { a, a + 1, a + G + 2, a, a + G + 2, a + G + 1 };
                memcpy(idx + 3 * ti, q, sizeof q);
                ti += 2;
            }
    }
    assert_int_equal(v, nv);
    assert_int_equal(ti, nt);
    rast_mesh_desc m = { clip, nv, attr, 3, idx, nt, RAST_CULL_NONE };
    rast_target t = { W, H, malloc((size_t)(W + 3) * H * sizeof(float)), W + 3,
                      malloc((size_t)(W + 1) * H), W + 1,
                      malloc((size_t)(W * 3 + 2) * H * sizeof(float)), W * 3 + 2, 3, NULL, 0 };
    rast_stats st;
    memset(&st, 0, sizeof st);
    reset_target(&t);
    assert_int_equal(rast__draw_with(&t, &m, &st, rast__scan_rows_ref), RAST_OK);
    snapshot s;
    take(&t, &st, &s);
    assert_true(st.pixels_written > 2 * W * H);
    int runs = 0;
    for (int isa = cpu_isa_from(EF_ISA_REF); isa < EF_ISA_COUNT; isa = cpu_isa_from(isa + 1)) {
        for (int th = 1; th <= 4; th++) {
            rast_context *c = context_of(isa, th);
            assert_int_equal(rast_context_threads(c), th);
            assert_true(rast_context_isa(c) <= isa);
            for (int rep = 0; rep < 2; rep++) {   /* reuse of the pool */
                reset_target(&t);
                memset(&st, 0, sizeof st);
                assert_int_equal(rast_context_draw(c, &t, &m, &st), RAST_OK);
                char what[64];
                snprintf(what, sizeof what, "%s, %d threads", ef_isa_name((ef_isa)isa), th);
                if (differs(&t, &st, &s, what, 1))
                    fail_msg("%s differs from the single-thread reference", what);
                runs++;
            }
            rast_context_destroy(c);
        }
    }
    print_message("NOTE threads: %d runs equal (pixels %ld)\n", runs, s.st.pixels_written);
    drop(&s);
    EF_FREE_ALL(t.depth, t.mask, t.attr, clip, attr, idx);
}

/* Contexts: bad descs, errors like rast_draw, the EGOFUSE_ISA cap. */
static void test_context_api(void **state)
{
    (void)state;
    rast_context_desc bad1 = { 0, -1 }, bad2 = { 0, RAST_MAX_THREADS + 1 },
                      bad3 = { EF_ISA_COUNT, 1 };
    assert_null(rast_context_create(&bad1));
    assert_null(rast_context_create(&bad2));
    assert_null(rast_context_create(&bad3));
    rast_context_destroy(NULL);
    assert_int_equal(rast_context_draw(NULL, NULL, NULL, NULL), RAST_ERR_ARGS);

    rast_context *c = rast_context_create(NULL);
    assert_non_null(c);
    assert_int_equal(rast_context_threads(c), 1);
    assert_int_equal(rast_context_isa(c), rast_draw_isa());
    rast_context_destroy(c);

    /* Errors through a threaded context: the same as rast_draw, stats
     * untouched. */
    rast_context_desc d2 = { 0, 2 };
    c = rast_context_create(&d2);
    assert_non_null(c);
    uint8_t mask[4 * 4];
    const float clip[12] = { -1, -1, 0, 1, 1, -1, 0, 1, -1, 1, 0, 1 };
    const uint32_t bad_idx[3] = { 0, 1, 3 }, idx[3] = { 0, 1, 2 };
    rast_target t = { 4, 4, NULL, 4, mask, 4, NULL, 0, 0, NULL, 0 };
    rast_mesh_desc m = { clip, 3, NULL, 0, bad_idx, 1, RAST_CULL_NONE };
    rast_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_context_draw(c, &t, &m, &st), RAST_ERR_INDEX);
    assert_int_equal(st.tris_in, 0);
    t.width = 0;
    m.indices = idx;
    assert_int_equal(rast_context_draw(c, &t, &m, &st), RAST_ERR_SIZE);
    t.width = 4;
    assert_int_equal(rast_context_draw(c, NULL, &m, &st), RAST_ERR_ARGS);
    rast_target_clear(&t);
    assert_int_equal(rast_context_draw(c, &t, &m, &st), RAST_OK);
    assert_int_equal(st.tris_in, 1);
    assert_int_equal(st.pixels_written, 6);     /* below the diagonal; the
                                                   diagonal is a right edge */

    /* Two jobs: the index check runs once per index set (same indices,
     * triangle and vertex counts), but a job whose vertex count is
     * smaller, or whose indices differ, is checked on its own: an error,
     * nothing drawn, stats untouched. */
    uint8_t mask2[4 * 4];
    rast_target t2 = { 4, 4, NULL, 4, mask2, 4, NULL, 0, 0, NULL, 0 };
    rast_mesh_desc m2 = m;
    const rast_target *tj[2] = { &t, &t2 };
    const rast_mesh_desc *mj[2] = { &m, &m2 };
    rast_target_clear(&t);
    rast_target_clear(&t2);
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_context_draw_jobs(c, 2, tj, mj, &st), RAST_OK);
    assert_int_equal(st.pixels_written, 12);
    m2.vertex_count = 2;                        /* index 2 now out of range */
    rast_target_clear(&t);
    rast_target_clear(&t2);
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_context_draw_jobs(c, 2, tj, mj, &st), RAST_ERR_INDEX);
    assert_int_equal(st.tris_in, 0);
    m2.vertex_count = 3;
    m2.indices = bad_idx;
    assert_int_equal(rast_context_draw_jobs(c, 2, tj, mj, &st), RAST_ERR_INDEX);
    m.indices = bad_idx;                        /* the shared set, bad */
    assert_int_equal(rast_context_draw_jobs(c, 2, tj, mj, &st), RAST_ERR_INDEX);
    assert_int_equal(st.tris_in, 0);
    for (int i = 0; i < 16; i++)
        assert_true(mask[i] == 0 && mask2[i] == 0);
    m.indices = idx;
    rast_context_destroy(c);

    /* EGOFUSE_ISA caps both rast_draw and new contexts. */
    const char *old = getenv("EGOFUSE_ISA");
    char saved[32] = "";
    if (old)
        snprintf(saved, sizeof saved, "%s", old);
    setenv("EGOFUSE_ISA", "ref", 1);
    assert_int_equal(rast_draw_isa(), EF_ISA_REF);
    c = rast_context_create(NULL);
    assert_int_equal(rast_context_isa(c), EF_ISA_REF);
    rast_context_destroy(c);
    setenv("EGOFUSE_ISA", "sse2", 1);
    assert_int_equal(rast_draw_isa(), ef_cpu_has(EF_ISA_SSE2) ? EF_ISA_SSE2 : EF_ISA_REF);
    if (old)
        setenv("EGOFUSE_ISA", saved, 1);
    else
        unsetenv("EGOFUSE_ISA");
    /* A cap below the environment wins. */
    rast_context_desc cap = { EF_ISA_REF, 1 };
    c = rast_context_create(&cap);
    assert_int_equal(rast_context_isa(c), EF_ISA_REF);
    rast_context_destroy(c);
    print_message("NOTE rast_draw uses %s\n", ef_isa_name((ef_isa)rast_draw_isa()));
}

/* The cached front end (trivial accept from per-vertex values) sets up
 * exactly what the per-triangle clip path sets up: every triangle of the
 * soup through rast__prepare_cached and rast__prepare, the fan triangles
 * and the counters compared with memcmp. */
static void test_prepare_cached_equal(void **state)
{
    (void)state;
    long fast = 0, total = 0;
    for (int n = 0; n < NCASES; n++) {
        rcase k;
        make_case(n, &k);
        rast__view view;
        rast__view_init(&view, k.t.width, k.t.height, rast__draw_na(&k.t, &k.m));
        rast__vcache vc;
        rast__vcache_reset(&vc);
        for (int ti = 0; ti < k.m.tri_count; ti++) {
            rast__tri a[RAST__MAX_FAN], b[RAST__MAX_FAN];
            memset(a, 0, sizeof a);
            memset(b, 0, sizeof b);
            rast_stats sa, sb;
            memset(&sa, 0, sizeof sa);
            memset(&sb, 0, sizeof sb);
            int na = rast__prepare_cached(&view, &k.m, ti, &vc, a, &sa);
            int nb = rast__prepare(&view, &k.m, ti, b, &sb);
            assert_int_equal(na, nb);
            if (memcmp(a, b, sizeof a) || memcmp(&sa, &sb, sizeof sa))
                fail_msg("case %d triangle %d: the cached front end differs", n, ti);
            /* Count the triangles the trivial-accept path took. */
            const uint32_t *ix = k.m.indices + 3 * (size_t)ti;
            int inside = 1;
            for (int i = 0; i < 3; i++) {
                const rast__vc_entry *e = &vc.e[ix[i] & (RAST__VCACHE - 1)];
                inside &= e->tag == ix[i] && e->flags == 0;
            }
            fast += inside;
            total++;
        }
        free_case(&k);
    }
    print_message("NOTE cached front end: %ld of %ld triangles trivially accepted, all "
                  "equal to the clip path\n", fast, total);
    assert_true(fast > total / 4 && fast < total);
}

/* The batched (SIMD) plane set-up equals the scalar one bit for bit.
 * 1. Raw batches: random snapped triangles from sub-pixel slivers to
 *    guard-band size (|X|, |Y| up to 2^22 / 256 px), 1/w spread over 2^-40
 *    .. 2^40 (near and far vertices of one triangle), depth in and out of
 *    [0, 1], every batch length 1..16: rast__planes_avx2/avx512 against
 *    rast__planes_ref with memcmp, and a CRC over the reference planes.
 * 2. Front end: every soup case (NaN, huge, behind the camera, slivers,
 *    culling) through rast__prepare_range with no set-up ISA (one by
 *    one), the scalar one and each SIMD one (batched planes, block vertex
 *    fills, AVX-512 rejection of 16 triangles at once), in chunks of
 *    1..40 triangles: the same set-up triangles (memcmp) and counters.
 * 3. Vertex block fills against the scalar fill (below). */
#define SETUP_CRC 0x3F58FF06u /* issue 20: inputs drawn in a defined order (before: 0xFA07FF57, gcc only) */
static void test_setup_isa_equal(void **state)
{
    (void)state;
    static const int simd[3] = { EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512 };
    const rast__planes_fn fns[3] = { rast__planes_sse2, rast__planes_avx2,
                                     rast__planes_avx512 };
    int have[3], nhave = 0;
    for (int i = 0; i < 3; i++) {
        have[i] = ef_cpu_has((ef_isa)simd[i]);
        nhave += have[i];
        if (!have[i])
            print_message("SKIP setup isa %s: this CPU does not run it; untested: "
                          "rast__planes_%s (triangle set-up)\n", ef_isa_name((ef_isa)simd[i]),
                          ef_isa_name((ef_isa)simd[i]));
    }
    if (!nhave)
        skip();
    tu_rng r = { 0x5E7u };
    uint32_t crc = 0;
    long lanes = 0;
    static rast__tri ta[RAST__PBATCH], tb[RAST__PBATCH];
    for (int it = 0; it < 3000; it++) {
        rast__pbatch a, b;
        a.n = 1 + tu_int(&r, RAST__PBATCH);
        for (int l = 0; l < a.n; l++) {
            int32_t X[3], Y[3];
            int64_t area;
            do {
                const int scale = 1 << tu_int(&r, 23);   /* 1 .. 2^22 sub-pixels */
                const int32_t ox = tu_int(&r, 1 << 21) - (1 << 20);
                const int32_t oy = tu_int(&r, 1 << 21) - (1 << 20);
                for (int i = 0; i < 3; i++) {
                    X[i] = ox + tu_int(&r, 2 * scale + 1) - scale;
                    Y[i] = oy + tu_int(&r, 2 * scale + 1) - scale;
                }
                area = (int64_t)(X[1] - X[0]) * (Y[2] - Y[0]) -
                       (int64_t)(Y[1] - Y[0]) * (X[2] - X[0]);
            } while (area == 0);
            if (area < 0) {   /* winding normalised as the set-up does */
                int32_t tx = X[1], ty = Y[1];
                X[1] = X[2]; Y[1] = Y[2]; X[2] = tx; Y[2] = ty;
                area = -area;
            }
            int32_t xmin = X[0], ymin = Y[0];
            for (int i = 0; i < 3; i++) {
                a.X[i][l] = (double)X[i] / 256.0;
                a.Y[i][l] = (double)Y[i] / 256.0;
                a.zw[i][l] = tu_int(&r, 8) ? tu_unit(&r) : tu_range(&r, -3.0f, 3.0f);
                const double m = 0.5 + tu_unit(&r);   /* drawn in order */
                a.iw[i][l] = ldexp(m, tu_int(&r, 81) - 40);
                xmin = X[i] < xmin ? X[i] : xmin;
                ymin = Y[i] < ymin ? Y[i] : ymin;
            }
            a.area[l] = (double)area / 65536.0;
            a.cx[l] = (double)((xmin + 127) >> 8) + 0.5;
            a.cy[l] = (double)((ymin + 127) >> 8) + 0.5;
            a.tri[l] = &ta[l];
        }
        memset(ta, 0, sizeof ta);
        b = a;
        rast__planes_ref(&a);
        assert_int_equal(a.n, 0);
        for (int l = 0; l < b.n; l++)
            crc = tu_crc32(crc, &ta[l].z, 4 * sizeof(rast__plane));
        lanes += b.n;
        for (int i = 0; i < 3; i++) {
            if (!have[i])
                continue;
            rast__pbatch c = b;
            memset(tb, 0, sizeof tb);
            for (int l = 0; l < c.n; l++)
                c.tri[l] = &tb[l];
            fns[i](&c);
            assert_int_equal(c.n, 0);
            if (memcmp(ta, tb, sizeof ta))
                fail_msg("batch %d: %s planes differ from the reference", it,
                         ef_isa_name((ef_isa)simd[i]));
        }
    }
    print_message("NOTE planes: %ld random triangles, SIMD equal to the reference; "
                  "CRC32 0x%08X (recorded 0x%08X)\n", lanes, crc, SETUP_CRC);
    assert_int_equal(crc, SETUP_CRC);

    /* 2. The front end with every planes function. */
    const int nf = 5;
    const rast__setup_isa *pf[5] = { NULL, &rast__setup_isa_ref, &rast__setup_isa_sse2,
                                     &rast__setup_isa_avx2, &rast__setup_isa_avx512 };
    long batched = 0;
    for (int n = 0; n < NCASES; n++) {
        rcase k;
        make_case(n, &k);
        rast__view view;
        rast__view_init(&view, k.t.width, k.t.height, rast__draw_na(&k.t, &k.m));
        const size_t cap = (size_t)k.m.tri_count * RAST__MAX_FAN;
        rast__tri *out[5];
        rast_stats st[5];
        int cnt[5];
        const int chunk = 1 + tu_int(&r, 40);
        for (int f = 0; f < nf; f++) {
            out[f] = calloc(cap, sizeof(rast__tri));
            memset(&st[f], 0, sizeof st[f]);
            cnt[f] = 0;
            if (f >= 2 && !have[f - 2])
                continue;
            rast__vcache vc;
            rast__vcache_reset(&vc);
            for (int ti = 0; ti < k.m.tri_count; ti += chunk) {
                const int te = ti + chunk < k.m.tri_count ? ti + chunk : k.m.tri_count;
                cnt[f] += rast__prepare_range(&view, &k.m, ti, te, &vc, out[f] + cnt[f],
                                              &st[f], pf[f]);
            }
            /* The triangles made (slots past them are scratch). */
            if (f == 0 || (cnt[f] == cnt[0] && !memcmp(&st[f], &st[0], sizeof st[0]) &&
                           !memcmp(out[f], out[0], (size_t)cnt[0] * sizeof(rast__tri))))
                continue;
            fail_msg("case %d: the front end with set-up ISA %d differs (count %d vs %d; "
                     "drawn %ld vs %ld, culled %ld vs %ld, degenerate %ld vs %ld, clipped "
                     "%ld vs %ld)", n, f, cnt[f], cnt[0], st[f].tris_drawn, st[0].tris_drawn,
                     st[f].tris_culled, st[0].tris_culled, st[f].tris_degenerate,
                     st[0].tris_degenerate, st[f].tris_clipped_away, st[0].tris_clipped_away);
        }
        batched += cnt[0];
        for (int f = 0; f < nf; f++)
            free(out[f]);
        free_case(&k);
    }
    print_message("NOTE front end: %d soup cases, %ld set-up triangles, equal with every "
                  "set-up ISA\n", NCASES, batched);
    assert_true(batched > 20000);

    /* 3. Vertex block fills: random vertices (inside, beyond the guard
     * band, behind the eye, w = 0, at the clip-space origin, tiny and huge
     * w, NaN and infinities), every block length, SIMD entries equal to
     * the scalar ones (tag and flags always, the values where valid). */
    static const rast__vfill_fn vf[3] = { rast__vfill_sse2, rast__vfill_avx2,
                                           rast__vfill_avx512 };
    long valid = 0, slow = 0, bad = 0;
    for (int it = 0; it < 4000; it++) {
        rast__view view;
        const int vw = 1 + tu_int(&r, 800);   /* drawn in order */
        rast__view_init(&view, vw, 1 + tu_int(&r, 600), 0);
        float clip[4 * RAST__VBLOCK];
        for (int i = 0; i < 4 * RAST__VBLOCK; i += 4) {
            float wv;   /* mantissa, then exponent: drawn in order */
            if (tu_int(&r, 10) == 0) {
                wv = tu_range(&r, -1.0f, 0.01f);
            } else if (tu_int(&r, 10) == 0) {
                wv = tu_unit(&r);
                wv = ldexpf(wv, -tu_int(&r, 140));
            } else if (tu_int(&r, 20) == 0) {
                wv = 1.0f + tu_unit(&r);
                wv = ldexpf(wv, tu_int(&r, 127));
            } else {
                wv = tu_range(&r, 0.05f, 5.0f);
            }
            const float reach = tu_int(&r, 4) == 0 ? 2e4f : 1.3f;
            clip[i] = tu_range(&r, -reach, reach) * wv;
            clip[i + 1] = tu_range(&r, -reach, reach) * wv;
            clip[i + 2] = tu_range(&r, -1.2f, 1.2f) * wv;
            clip[i + 3] = wv;
            if (tu_int(&r, 50) == 0)
                clip[i] = clip[i + 1] = clip[i + 2] = clip[i + 3] = 0.0f;
            if (tu_int(&r, 40) == 0) {
                const int at = tu_int(&r, 4);   /* drawn in order */
                clip[i + at] = tu_int(&r, 3) == 0 ? NAN : tu_int(&r, 2) ? INFINITY : -INFINITY;
            }
        }
        const int count = 1 + tu_int(&r, RAST__VBLOCK);
        const uint32_t base = (uint32_t)tu_int(&r, 1 << 20) * RAST__VBLOCK;
        rast__vc_entry want[RAST__VBLOCK], got[RAST__VBLOCK];
        rast__vfill_ref(&view, clip - 4 * (size_t)base, base, count, want);
        for (int l = 0; l < count; l++) {
            valid += want[l].flags == 0;
            slow += (want[l].flags & RAST__VF_SLOW) != 0;
            bad += (want[l].flags & RAST__VF_NONFINITE) != 0;
        }
        for (int i = 0; i < 3; i++) {
            if (!have[i])
                continue;
            memset(got, 0xA5, sizeof got);
            vf[i](&view, clip - 4 * (size_t)base, base, count, got);
            for (int l = 0; l < count; l++) {
                const rast__vc_entry *a = &want[l], *b = &got[l];
                if (a->tag != b->tag || a->flags != b->flags ||
                    (a->flags == 0 && (a->X != b->X || a->Y != b->Y ||
                                       memcmp(&a->zw, &b->zw, sizeof a->zw) ||
                                       memcmp(&a->iw, &b->iw, sizeof a->iw))))
                    fail_msg("vertex fill %d lane %d: %s differs from the scalar fill "
                             "(flags %u vs %u)", it, l, ef_isa_name((ef_isa)simd[i]),
                             a->flags, b->flags);
            }
        }
    }
    print_message("NOTE vertex fills: %ld valid, %ld to clip, %ld non-finite vertices, "
                  "SIMD equal to the scalar fill\n", valid, slow, bad);
    assert_true(valid > 10000 && slow > 5000 && bad > 500);
}

/* rast_context_draw_jobs: three jobs (two eyes and a small padded target,
 * different meshes and attribute counts) with 1, 2 and 3 threads on every
 * ISA, each job equal to rast_draw of it alone; bad jobs are rejected
 * before anything is drawn; overlapping targets are rejected. */
static void test_jobs_equal(void **state)
{
    (void)state;
    /* The first three soup cases with attributes and a few hundred
     * pixels. */
    rcase k[3];
    for (int j = 0, n = 0; j < 3; n++) {
        make_case(n, &k[j]);
        rast_stats st;
        draw_case(&k[j], rast__scan_rows_ref, &st);
        if (k[j].t.attr && st.pixels_written > 300)
            j++;
        else
            free_case(&k[j]);
    }
    const rast_target *tp[3] = { &k[0].t, &k[1].t, &k[2].t };
    const rast_mesh_desc *mp[3] = { &k[0].m, &k[1].m, &k[2].m };
    snapshot ref[3];
    rast_stats sum;
    memset(&sum, 0, sizeof sum);
    for (int j = 0; j < 3; j++) {
        rast_stats st;
        draw_case(&k[j], rast__scan_rows_ref, &st);
        take(&k[j].t, &st, &ref[j]);
        rast__stats_add(&sum, &st);
    }
    assert_true(sum.pixels_written > 100);
    int runs = 0;
    for (int isa = cpu_isa_from(EF_ISA_REF); isa < EF_ISA_COUNT; isa = cpu_isa_from(isa + 1)) {
        for (int th = 1; th <= 3; th++) {
            rast_context *c = context_of(isa, th);
            for (int nj = 1; nj <= 3; nj++) {
                for (int j = 0; j < 3; j++)
                    reset_target(&k[j].t);
                rast_stats st;
                memset(&st, 0, sizeof st);
                assert_int_equal(rast_context_draw_jobs(c, nj, tp, mp, &st), RAST_OK);
                rast_stats want;
                memset(&want, 0, sizeof want);
                for (int j = 0; j < nj; j++) {
                    char what[64];
                    snprintf(what, sizeof what, "%s, %d threads, job %d of %d",
                             ef_isa_name((ef_isa)isa), th, j, nj);
                    if (differs(&k[j].t, &ref[j].st, &ref[j], what, 1))
                        fail_msg("%s differs from rast_draw", what);
                    rast__stats_add(&want, &ref[j].st);
                }
                assert_memory_equal(&st, &want, sizeof st);
                runs++;
            }
            /* An invalid job: an error, nothing drawn, stats untouched. */
            rast_mesh_desc bad = k[2].m;
            bad.cull = (rast_cull)7;
            const rast_mesh_desc *mb[3] = { &k[0].m, &k[1].m, &bad };
            for (int j = 0; j < 3; j++)
                reset_target(&k[j].t);
            rast_stats st;
            memset(&st, 0x11, sizeof st);
            rast_stats st0 = st;
            assert_int_equal(rast_context_draw_jobs(c, 3, tp, mb, &st), RAST_ERR_ARGS);
            assert_memory_equal(&st, &st0, sizeof st);
            for (int j = 0; j < 2; j++)
                for (size_t i = 0; i < mask_bytes(&k[j].t); i++)
                    if (k[j].t.mask[i] != 0 && (int)(i % k[j].t.mask_stride) < k[j].t.width)
                        fail_msg("job %d drawn although job 2 is invalid", j);
            /* The same target twice, or overlapping planes: rejected. */
            const rast_target *same[2] = { &k[0].t, &k[0].t };
            assert_int_equal(rast_context_draw_jobs(c, 2, same, mp, NULL), RAST_ERR_ARGS);
            rast_target half = k[1].t;
            /* The last pixel of k[0]'s mask plane is the first of half's. */
            half.mask = k[0].t.mask + (size_t)(k[0].t.height - 1) * k[0].t.mask_stride +
                        k[0].t.width - 1;
            half.depth = NULL;
            half.attr = NULL;
            const rast_target *ov[2] = { &k[0].t, &half };
            const rast_mesh_desc *mo[2] = { &k[0].m, &k[1].m };
            assert_int_equal(rast_context_draw_jobs(c, 2, ov, mo, NULL), RAST_ERR_ARGS);
            assert_int_equal(rast_context_draw_jobs(c, RAST_MAX_JOBS + 1, tp, mp, NULL),
                             RAST_ERR_ARGS);
            assert_int_equal(rast_context_draw_jobs(c, 0, NULL, NULL, NULL), RAST_OK);
            rast_context_destroy(c);
        }
    }
    assert_int_equal(rast_context_draw_jobs(NULL, 1, tp, mp, NULL), RAST_ERR_ARGS);
    print_message("NOTE jobs: %d runs equal to rast_draw of each job\n", runs);
    for (int j = 0; j < 3; j++) {
        drop(&ref[j]);
        free_case(&k[j]);
    }
}

/* rast_context_clear: a sequence of frames (different soups into the same
 * two targets, through jobs and single draws, 1 and 2 threads) cleared by
 * the context gives, after every clear and every draw, the bytes of the
 * same frames cleared with rast_target_clear (padding included, which
 * neither may touch). A target the context does not know and a forgotten
 * one are cleared whole. */
static void make_mesh(int n, rcase *k);
static void test_context_clear(void **state)
{
    (void)state;
    enum { W = 150, H = 70 };
    int checked = 0;
    for (int th = 1; th <= 2; th++) {
        rast_context_desc d = { 0, th };
        rast_context *c = rast_context_create(&d);
        assert_non_null(c);
        rast_target a[2], b[2];
        for (int e = 0; e < 2; e++) {
            rast_target t = { W, H, malloc((size_t)(W + 5) * H * sizeof(float)), W + 5,
                              malloc((size_t)(W + 3) * H), W + 3,
                              malloc((size_t)(3 * W + 2) * H * sizeof(float)), 3 * W + 2, 3,
                              NULL, 0 };
            a[e] = t;
            rast_target u = { W, H, malloc((size_t)(W + 5) * H * sizeof(float)), W + 5,
                              malloc((size_t)(W + 3) * H), W + 3,
                              malloc((size_t)(3 * W + 2) * H * sizeof(float)), 3 * W + 2, 3,
                              NULL, 0 };
            b[e] = u;
            reset_target(&a[e]);   /* pattern in the padding, then clear */
            reset_target(&b[e]);
            memset(a[e].mask, 0x77, (size_t)a[e].mask_stride * H);   /* garbage: the */
            memset(a[e].depth, 0x77, (size_t)a[e].depth_stride * H * 4);  /* first clear */
            memset(b[e].mask, 0x77, (size_t)b[e].mask_stride * H);   /* must be whole */
            memset(b[e].depth, 0x77, (size_t)b[e].depth_stride * H * 4);
        }
        for (int frame = 0; frame < 12; frame++) {
            if (frame == 8)
                rast_context_forget(c);
            for (int e = 0; e < 2; e++) {
                if (frame == 8) {   /* written behind the context's back */
                    memset(a[e].mask, 0x33, (size_t)W);
                    memset(b[e].mask, 0x33, (size_t)W);
                }
                rast_context_clear(c, &a[e]);
                rast_target_clear(&b[e]);
                assert_memory_equal(a[e].mask, b[e].mask, (size_t)a[e].mask_stride * H);
                assert_memory_equal(a[e].depth, b[e].depth, (size_t)a[e].depth_stride * H * 4);
                assert_memory_equal(a[e].attr, b[e].attr, (size_t)a[e].attr_stride * H * 4);
            }
            rcase k[2];
            rast_mesh_desc m[2];
            for (int e = 0; e < 2; e++) {
                /* A soup case (big triangles, whole tile rows) or, every
                 * third frame, a grid mesh (small triangles in a window:
                 * runs of marked tiles ending inside a row), with 3
                 * attributes, drawn on this target. */
                int n = 11 * frame + e;
                do {
                    if (frame % 3 == 2)
                        make_mesh(n++, &k[e]);
                    else
                        make_case(n++, &k[e]);
                    if (k[e].m.attr_count == 3)
                        break;
                    free_case(&k[e]);
                } while (1);
                m[e] = k[e].m;
            }
            rt_context_draw_two(c, frame % 2, a, m);
            for (int e = 0; e < 2; e++) {
                assert_int_equal(rast_draw(&b[e], &m[e], NULL), RAST_OK);
                assert_memory_equal(a[e].mask, b[e].mask, (size_t)a[e].mask_stride * H);
                assert_memory_equal(a[e].depth, b[e].depth, (size_t)a[e].depth_stride * H * 4);
                assert_memory_equal(a[e].attr, b[e].attr, (size_t)a[e].attr_stride * H * 4);
                free_case(&k[e]);
                checked++;
            }
        }
        for (int e = 0; e < 2; e++) {
            free(a[e].depth); free(a[e].mask); free(a[e].attr);
            free(b[e].depth); free(b[e].mask); free(b[e].attr);
        }
        rast_context_destroy(c);
    }
    rast_context_clear(NULL, NULL);      /* no crash */
    print_message("NOTE context clear: %d frames equal to full clears (%d of grid meshes)\n",
                  checked, checked / 3);
}

/* ---- the vector front end (rast__vpass_*, rast__frontv_*) --------------- */

/* Case n of the mesh generator: a jittered grid of shared vertices (2x2
 * to 61x61) over a window of NDC from a few pixels to far beyond the
 * view, both windings, w from behind the eye to far (a tilted w plane
 * crossing 0 in a quarter of the cases, so triangles straddle the near
 * plane), depth in and out of the clip volume, rare NaN / infinite
 * vertices, repeated indices (degenerate), triangles between random far
 * vertices, a shuffled order in half the cases, every cull mode,
 * 0..8 attributes, odd target sizes and padded strides. */
static void make_mesh(int n, rcase *k)
{
    tu_rng r = { 0xF0E7000ull + (uint64_t)n * 0x9E3779B97F4A7C15ull };
    memset(k, 0, sizeof *k);
    const int w = tu_int(&r, 8) == 0 ? 1 + tu_int(&r, 20) : 16 + tu_int(&r, 700);
    const int h = tu_int(&r, 8) == 0 ? 1 + tu_int(&r, 20) : 16 + tu_int(&r, 400);
    const int na = tu_int(&r, 2) ? 3 : tu_int(&r, 9);
    rast_target *t = &k->t;
    t->width = w;
    t->height = h;
    t->mask_stride = w + tu_int(&r, 5);
    t->mask = malloc((size_t)t->mask_stride * h);
    if (tu_int(&r, 5) != 0) {
        t->depth_stride = w + tu_int(&r, 5);
        t->depth = malloc((size_t)t->depth_stride * h * sizeof(float));
    }
    t->attr_count = na;
    k->attr_plane = tu_int(&r, 4) != 0;
    if (k->attr_plane && na > 0) {
        t->attr_stride = w * na + tu_int(&r, 7);
        t->attr = malloc((size_t)t->attr_stride * h * sizeof(float));
    }
    const int G = 2 + tu_int(&r, 60);
    const int nv = G * G;
    const float ext = powf(2.0f, tu_range(&r, -7.0f, 2.0f));   /* grid size in NDC */
    const float cx = tu_range(&r, -0.8f, 0.8f), cy = tu_range(&r, -0.8f, 0.8f);
    const float jit = tu_int(&r, 3) == 0 ? 0.0f : tu_range(&r, 0.0f, 0.45f);
    const int tilt = tu_int(&r, 4) == 0;
    const float w0 = tu_range(&r, 0.2f, 3.0f), wx = tilt ? tu_range(&r, -3.0f, 3.0f) : 0.0f;
    const float zlo = tu_int(&r, 4) == 0 ? -1.5f : -0.9f, zhi = tu_int(&r, 4) == 0 ? 1.5f : 0.9f;
    k->clip = malloc((size_t)nv * 4 * sizeof(float));
    k->attr = na ? malloc((size_t)nv * na * sizeof(float)) : NULL;
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            float *c = k->clip + 4 * (j * G + i);
            const float u = ((float)i + tu_range(&r, -jit, jit)) / (float)(G - 1) - 0.5f;
            const float v = ((float)j + tu_range(&r, -jit, jit)) / (float)(G - 1) - 0.5f;
            const float wv = w0 + wx * u + tu_range(&r, -0.01f, 0.01f);
            const float aw = fabsf(wv) > 1e-3f ? fabsf(wv) : 1.0f;
            c[0] = (cx + ext * u) * aw;
            c[1] = (cy + ext * v) * aw;
            c[2] = tu_range(&r, zlo, zhi) * aw;
            c[3] = wv;
            if (tu_int(&r, 400) == 0) {
                const int at = tu_int(&r, 4);   /* drawn in order */
                c[at] = tu_int(&r, 2) ? NAN : -INFINITY;
            }
        }
    for (int i = 0; i < nv * na; i++)
        k->attr[i] = tu_range(&r, -1.0f, 1.0f);
    const int nt = 2 * (G - 1) * (G - 1);
    k->idx = malloc((size_t)nt * 3 * sizeof(uint32_t));
    const int flip_all = tu_int(&r, 2);
    for (int q = 0; q < (G - 1) * (G - 1); q++) {
        const uint32_t a = (uint32_t)(q / (G - 1) * G + q % (G - 1));
        const uint32_t quad[6] = { a, a + 1, a + (uint32_t)G + 1, a, a + (uint32_t)G + 1,
                                   a + (uint32_t)G };
        for (int i = 0; i < 6; i++)
            k->idx[6 * q + i] = quad[i];
    }
    for (int ti = 0; ti < nt; ti++) {
        uint32_t *x = k->idx + 3 * ti;
        if (flip_all ^ (tu_int(&r, 10) == 0)) {
            const uint32_t s = x[1];
            x[1] = x[2];
            x[2] = s;
        }
        if (tu_int(&r, 50) == 0) {
            const int to = tu_int(&r, 3);   /* drawn in order */
            x[to] = x[tu_int(&r, 3)];
        }
        if (tu_int(&r, 40) == 0) {
            const int to = tu_int(&r, 3);
            x[to] = (uint32_t)tu_int(&r, nv);
        }
    }
    if (tu_int(&r, 2))
        for (int ti = nt - 1; ti > 0; ti--) {
            const int o = tu_int(&r, ti + 1);
            uint32_t s[3];
            memcpy(s, k->idx + 3 * ti, sizeof s);
            memcpy(k->idx + 3 * ti, k->idx + 3 * o, sizeof s);
            memcpy(k->idx + 3 * o, s, sizeof s);
        }
    case_mesh(k, nv, na, nt, &r);
}

/* One case through the vector front end of an ISA against the scalar
 * path: the vertex pass against the scalar vertex fill (every vertex),
 * then the front end in random chunks of 1..300 submitted triangles
 * against rast__prepare_range with the scalar set-up (memcmp of the
 * records, counters). Adds the reference records and counters to *crc
 * and counts the set-up triangles and those of special vertices. */
/* m through the vector front end of isa in random chunks of 1..300
 * submitted triangles (a quarter of them 1..16); returns the records. */
static int frontv_chunks(const rast__setup_isa *isa, const rast__view *view,
                         const rast_mesh_desc *m, rast__vbuf *vb, tu_rng *r, rast__tri *out,
                         rast_stats *st, int micro)
{
    int n = 0;
    for (int ti = 0; ti < m->tri_count;) {
        const int len = tu_int(r, 4) == 0 ? 1 + tu_int(r, 16) : 1 + tu_int(r, 300);
        const int te = m->tri_count - ti > len ? ti + len : m->tri_count;
        n += isa->frontv(view, m, vb, ti, te, out + n, st, micro);
        ti = te;
    }
    return n;
}

static long frontv_micro, frontv_border;   /* micro records seen by frontv_case, on a border */
static void frontv_case(const rcase *k, const rast__setup_isa *isa, tu_rng *r, uint32_t *crc,
                        long *made, long *clipped, const char *what)
{
    rast__view view;
    rast__view_init(&view, k->t.width, k->t.height, rast__draw_na(&k->t, &k->m));
    const rast_mesh_desc *m = &k->m;
    rast__vbuf *vb = rast__vbuf_alloc(m->vertex_count);
    assert_non_null(vb);
    isa->vpass(&view, m->clip, m->vertex_count, vb);
    for (int i = 0; i < m->vertex_count; i++) {
        rast__vc_entry e;
        rast__vfill_ref(&view, m->clip, (uint32_t)i, 1, &e);
        const int mark = vb->xy[2 * i] == RAST__VX_SPECIAL;
        /* a marked vertex's Y: its outcode | RAST__VX_NONFINITE */
        const int32_t oy = vb->xy[2 * i + 1];
        const int32_t ocbits = RAST__VX_NONFINITE | RAST__VX_OUTCODE;
        const int bad_oc =
            mark && ((e.flags & RAST__VF_NONFINITE)
                         ? !(oy & RAST__VX_NONFINITE) || (oy & ~ocbits)
                         : oy != (int32_t)(e.flags & RAST__VX_OUTCODE));
        if (mark != (e.flags != 0) || bad_oc ||
            (!mark && (vb->xy[2 * i] != e.X || vb->xy[2 * i + 1] != e.Y ||
                       memcmp(&vb->zw[i], &e.zw, sizeof e.zw) ||
                       memcmp(&vb->iw[i], &e.iw, sizeof e.iw))))
            fail_msg("%s: vertex %d of the vertex pass differs from the scalar fill "
                     "(flags %u, Y %d)", what, i, e.flags, (int)oy);
    }
    const size_t cap = (size_t)m->tri_count * RAST__MAX_FAN + 1;
    rast__tri *a = calloc(cap, sizeof *a), *b = calloc(cap, sizeof *b);
    rast_stats sa, sb;
    memset(&sa, 0, sizeof sa);
    memset(&sb, 0, sizeof sb);
    rast__vcache vc;
    rast__vcache_reset(&vc);
    const int na = rast__prepare_range(&view, m, 0, m->tri_count, &vc, a, &sa,
                                       &rast__setup_isa_ref);
    const int nb = frontv_chunks(isa, &view, m, vb, r, b, &sb, 0);
    if (na != nb || memcmp(&sa, &sb, sizeof sa))
        fail_msg("%s: %d vs %d records; drawn %ld vs %ld, culled %ld vs %ld, degenerate "
                 "%ld vs %ld, clipped %ld vs %ld, non-finite %ld vs %ld", what, nb, na,
                 sb.tris_drawn, sa.tris_drawn, sb.tris_culled, sa.tris_culled,
                 sb.tris_degenerate, sa.tris_degenerate, sb.tris_clipped_away,
                 sa.tris_clipped_away, sb.tris_nonfinite, sa.tris_nonfinite);
    for (int i = 0; i < na; i++)
        if (memcmp(&a[i], &b[i], sizeof a[i]))
            fail_msg("%s: record %d of %d differs (box %d %d %d %d vs %d %d %d %d, e_c0 "
                     "%lld vs %lld, z.c %.9g vs %.9g)", what, i, na, b[i].x0, b[i].y0,
                     b[i].x1, b[i].y1, a[i].x0, a[i].y0, a[i].x1, a[i].y1,
                     (long long)b[i].e_c[0], (long long)a[i].e_c[0], b[i].z.c, a[i].z.c);
    /* With micro records (boxes of at most 2x2 pixels): the same slots,
     * and scan_list writes the bytes the full records' reference scan
     * writes, in random chunks again. */
    rast__tri *c = calloc(cap, sizeof *c);
    rast_stats sc;
    memset(&sc, 0, sizeof sc);
    const int nc = frontv_chunks(isa, &view, m, vb, r, c, &sc, 1);
    if (nc != na || memcmp(&sa, &sc, sizeof sa))
        fail_msg("%s: with micro records %d vs %d records, or other counters", what, nc, na);
    for (int i = 0; i < nc; i++) {
        /* covered pixels inside the (clamped) box only */
        const unsigned cb = (unsigned)c[i].micro & 15u;
        if (c[i].micro &&
            ((c[i].micro & ~(RAST__MICRO | 15)) != 0 ||
             (cb && (c[i].x0 < 0 || c[i].y0 < 0 || c[i].x1 >= k->t.width ||
                     c[i].y1 >= k->t.height || c[i].x1 - c[i].x0 > 1 ||
                     c[i].y1 - c[i].y0 > 1)) ||
             ((cb & 10u) && c[i].x1 == c[i].x0) || ((cb & 12u) && c[i].y1 == c[i].y0)))
            fail_msg("%s: record %d: micro %#x, box %d..%d x %d..%d", what, i,
                     (unsigned)c[i].micro, c[i].x0, c[i].x1, c[i].y0, c[i].y1);
        frontv_border += cb && (c[i].x1 == k->t.width - 1 || c[i].y1 == k->t.height - 1 ||
                                c[i].x0 == 0 || c[i].y0 == 0);
        if (!c[i].micro && memcmp(&a[i], &c[i], sizeof a[i]))
            fail_msg("%s: record %d differs with micro records on", what, i);
        frontv_micro += c[i].micro != 0;
    }
    rast_stats pa, pc;
    memset(&pa, 0, sizeof pa);
    memset(&pc, 0, sizeof pc);
    int last[4] = { 1, 0, 1, 0 };
    reset_target(&k->t);
    pa.pixels_written = rast__scan_list(&k->t, a, na, rast__scan_rows_ref, NULL, last, 0);
    snapshot ref;
    take(&k->t, &pa, &ref);
    reset_target(&k->t);
    pc.pixels_written = rast__scan_list(&k->t, c, nc, rast__scan_rows_ref, NULL, last, 1);
    if (differs(&k->t, &pc, &ref, what, 1))
        fail_msg("%s: the micro records write other bytes than the scan", what);
    drop(&ref);
    free(c);
    *crc = tu_crc32(*crc, a, (size_t)na * sizeof *a);
    const long cnt[5] = { sa.tris_nonfinite, sa.tris_clipped_away, sa.tris_degenerate,
                          sa.tris_culled, sa.tris_drawn };
    *crc = tu_crc32(*crc, cnt, sizeof cnt);
    *made += na;
    *clipped += sa.tris_clipped_away + sa.tris_nonfinite;
    free(a);
    free(b);
    rast__vbuf_free(vb);
}

/* The vector front end equals the scalar set-up: every soup case and
 * 300 grid meshes (shared vertices, slivers, huge, behind the eye, NaN,
 * culling, degenerate) record for record, a CRC of the reference records
 * and counters against a recorded constant, and whole draws of the
 * meshes through a context (which takes the vector front end) against
 * rast_draw with the reference scan, byte for byte; an index out of
 * range is still RAST_ERR_INDEX with nothing drawn. With micro records on,
 * the same slots, every other record unchanged, the covered pixels inside
 * the box, and rast__scan_list writing the reference scan's bytes. The
 * CRC changed in the ninth round of issue 3 (0x79E6CFE7 before): the
 * record grew the micro fields, and empty boxes up to 2x2 pixels (one
 * pixel before) are no longer records. */
#define FRONTV_CRC 0xDF7DA642u /* issue 20: inputs drawn in a defined order (before: 0xC50B16FA, gcc only) */
static void test_frontv_equal(void **state)
{
    (void)state;
    static const int simd[2] = { EF_ISA_AVX2, EF_ISA_AVX512 };
    const rast__setup_isa *isas_v[2] = { &rast__setup_isa_avx2, &rast__setup_isa_avx512 };
    int nhave = 0;
    for (int i = 0; i < 2; i++) {
        if (ef_cpu_has((ef_isa)simd[i]) && isas_v[i]->vpass)
            nhave++;
        else
            print_message("SKIP vector front end %s: this CPU does not run it; untested: the "
                          "vector front end of src/raster/raster_front_%s.c\n",
                          ef_isa_name((ef_isa)simd[i]), ef_isa_name((ef_isa)simd[i]));
    }
    if (!nhave)
        skip();
    tu_rng r = { 0xF70u };
    for (int i = 0; i < 2; i++) {
        if (!ef_cpu_has((ef_isa)simd[i]))
            continue;
        uint32_t crc = 0;
        long made = 0, clipped = 0, made_soup = 0, clipped_soup = 0, tris = 0;
        for (int n = 0; n < NCASES; n++) {
            rcase k;
            make_case(n, &k);
            char what[64];
            snprintf(what, sizeof what, "%s soup case %d", ef_isa_name((ef_isa)simd[i]), n);
            frontv_case(&k, isas_v[i], &r, &crc, &made_soup, &clipped_soup, what);
            free_case(&k);
        }
        rast_context_desc d = { simd[i], 1 };
        rast_context *c = rast_context_create(&d);
        assert_non_null(c);
        /* EGOFUSE_ISA caps the context too (the records above call the
         * set-up of simd[i] directly): its draws against the reference
         * hold either way. */
        assert_int_equal(rast_context_isa(c), ef_isa_choose((ef_isa)simd[i]));
        for (int n = 0; n < 300; n++) {
            rcase k;
            make_mesh(n, &k);
            char what[64];
            snprintf(what, sizeof what, "%s mesh %d", ef_isa_name((ef_isa)simd[i]), n);
            frontv_case(&k, isas_v[i], &r, &crc, &made, &clipped, what);
            tris += k.m.tri_count;
            /* The whole draw through the context. */
            rast_stats st;
            draw_case(&k, rast__scan_rows_ref, &st);
            snapshot ref;
            take(&k.t, &st, &ref);
            reset_target(&k.t);
            memset(&st, 0, sizeof st);
            assert_int_equal(rast_context_draw(c, &k.t, &k.m, &st), RAST_OK);
            if (differs(&k.t, &st, &ref, what, 1))
                fail_msg("%s: the context draw differs from the reference", what);
            drop(&ref);
            if (n % 50 == 0) {
                /* A bad index anywhere: an error, nothing drawn. */
                const int at = tu_int(&r, 3 * k.m.tri_count);
                const uint32_t keep = k.idx[at];
                k.idx[at] = (uint32_t)k.m.vertex_count + (uint32_t)tu_int(&r, 3);
                reset_target(&k.t);
                memset(&st, 0x33, sizeof st);
                const rast_stats st0 = st;
                assert_int_equal(rast_context_draw(c, &k.t, &k.m, &st), RAST_ERR_INDEX);
                assert_memory_equal(&st, &st0, sizeof st);
                for (int y = 0; y < k.t.height; y++)
                    for (int x = 0; x < k.t.width; x++)
                        assert_int_equal(k.t.mask[(size_t)y * k.t.mask_stride + x], 0);
                k.idx[at] = keep;
            }
            free_case(&k);
        }
        rast_context_destroy(c);
        print_message("NOTE vector front end %s: soup %ld records (%ld clipped or "
                      "non-finite triangles), meshes %ld triangles, %ld records (%ld "
                      "clipped or non-finite), equal to the scalar set-up and the reference "
                      "draw; %ld micro records writing the scan's bytes; CRC32 0x%08X "
                      "(recorded 0x%08X)\n", ef_isa_name((ef_isa)simd[i]),
                      made_soup, clipped_soup, tris, made, clipped, frontv_micro, crc,
                      FRONTV_CRC);
        assert_true(made > 100000 && clipped > 1000 && made_soup > 20000 &&
                    frontv_micro > 10000);
        print_message("NOTE %ld micro records on a border\n", frontv_border);
        frontv_micro = frontv_border = 0;
        assert_int_equal(crc, FRONTV_CRC);
    }
}

/* ---- rerun of one case --------------------------------------------------- */

static int rerun(int n)
{
    rcase k;
    make_case(n, &k);
    printf("case %d: %dx%d, strides mask %d depth %d attr %d, %d attributes%s, "
           "%d triangles, cull %d\n", n, k.t.width, k.t.height, k.t.mask_stride,
           k.t.depth_stride, k.t.attr_stride, k.t.attr_count,
           k.t.attr ? "" : " (no plane)", k.m.tri_count, (int)k.m.cull);
    rast_stats st;
    draw_case(&k, rast__scan_rows_ref, &st);
    snapshot s;
    take(&k.t, &st, &s);
    int bad = 0;
    for (size_t i = 0; i < sizeof isas / sizeof isas[0]; i++) {
        if (!ef_cpu_has((ef_isa)isas[i])) {
            printf("SKIP %s: this CPU does not run it\n", ef_isa_name((ef_isa)isas[i]));
            continue;
        }
        draw_case(&k, rast__scan_for_isa(isas[i]), &st);
        if (differs(&k.t, &st, &s, ef_isa_name((ef_isa)isas[i]), 1))
            bad = 1;
        else
            printf("%s: equal to the reference (%ld pixels)\n",
                   ef_isa_name((ef_isa)isas[i]), st.pixels_written);
    }
    drop(&s);
    free_case(&k);
    return bad;
}

int main(int argc, char **argv)
{
    if (argc > 1)
        return rerun(atoi(argv[1]));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_soup_sse2),
        cmocka_unit_test(test_soup_avx2),
        cmocka_unit_test(test_soup_avx512),
        cmocka_unit_test(test_threads_equal),
        cmocka_unit_test(test_context_api),
        cmocka_unit_test(test_prepare_cached_equal),
        cmocka_unit_test(test_setup_isa_equal),
        cmocka_unit_test(test_jobs_equal),
        cmocka_unit_test(test_context_clear),
        cmocka_unit_test(test_frontv_equal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

#else
EF_TEST_X86_SKIP("the AVX2/AVX-512 raster kernels against the reference")
#endif
