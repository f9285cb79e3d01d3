/* test_raster_n10.c - the packed normal plane (rast_target.attr_n10).
 *
 * Seeded random meshes (3 attributes per vertex; clipped, huge, tiny,
 * wide, sliver and edge-on triangles, shared edges, all cull modes,
 * attributes beyond [-1, 1], NaN, infinities, -0 and constant triangles
 * whose value times 511 is a float tie k + 0.5, so that the rounding
 * rule shows; targets of several sizes with and without depth and with
 * padded strides) drawn in a defined order twice per path: once into a
 * float attribute plane, once into an attr_n10 plane. For every scan the
 * machine runs (the scalar reference, SSE2, AVX2, AVX-512, NEON:
 * rast__draw_with), rast_draw (EGOFUSE_ISA), and contexts capped at each
 * ISA with 1 and 3 threads (the vector front end's micro records, bands)
 * and their jobs:
 *   - the n10 plane equals ef_n10_pack of the float plane, pixel by pixel;
 *   - the n10 plane is the same bytes on every path;
 *   - depth, mask and stats equal the float run's;
 *   - the padding of every plane is untouched.
 * Also: rast_context_clear / _keep_attr on an n10 target, and the
 * validation errors of the new fields.
 *
 * An ISA the CPU lacks is reported (SKIP) and not counted as tested.
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/cpu/ef_n10.h"
#include "../src/raster/raster_internal.h"

#define NCASES 700
#define PAD_BYTE 0xA7u   /* the pattern of every plane before the clear */

typedef struct ncase {
    int w, h, depth, pad;
    float *clip, *attr;
    uint32_t *idx;
    rast_mesh_desc m;
} ncase;

/* Constant attribute values with a rule each must get right. */
static float special_value(tu_rng *r)
{
    switch (tu_int(r, 9)) {
    case 0: {   /* a tie: (a * 511) is exactly k + 0.5 in float */
        for (;;) {
            const int k = tu_int(r, 1022) - 511;
            const float a = (float)((k + 0.5) / 511.0);
            if (a * 511.0f == (float)k + 0.5f)
                return a;
            const float b = nextafterf(a, 2.0f);
            if (b * 511.0f == (float)k + 0.5f)
                return b;
            const float c = nextafterf(a, -2.0f);
            if (c * 511.0f == (float)k + 0.5f)
                return c;
        }
    }
    case 1: return NAN;
    case 2: return tu_int(r, 2) ? INFINITY : -INFINITY;
    case 3: return -0.0f;
    case 4: return tu_int(r, 2) ? 1.0f : -1.0f;
    case 5: return tu_range(r, -3.0f, 3.0f);   /* beyond [-1, 1]: clamped */
    case 6: return tu_range(r, -1e-3f, 1e-3f);
    case 7: return (float)(tu_int(r, 1023) - 511) / 511.0f;
    default: return tu_range(r, -1.0f, 1.0f);
    }
}

static float pick_w(tu_rng *r)
{
    switch (tu_int(r, 6)) {
    case 0: return tu_range(r, -2.0f, 0.05f);      /* behind / at the eye */
    case 1: return tu_range(r, 0.01f, 0.2f);
    default: return tu_range(r, 0.5f, 4.0f);
    }
}

static void make_case(int n, ncase *k)
{
    tu_rng r = { 0x7A10000ull + (uint64_t)n * 0x9E3779B97F4A7C15ull };
    memset(k, 0, sizeof *k);
    const int big = tu_int(&r, 12) == 0;
    k->w = big ? 150 + tu_int(&r, 500) : 1 + tu_int(&r, 90);
    k->h = big ? 80 + tu_int(&r, 200) : 1 + tu_int(&r, 60);
    k->pad = tu_int(&r, 3) == 0 ? 0 : 1 + tu_int(&r, 17);
    k->depth = tu_int(&r, 5) != 0;
    const int ntri = big ? 1 + tu_int(&r, 24) : 1 + tu_int(&r, 40);
    const int nv = 3 * ntri + 4;
    k->clip = malloc((size_t)nv * 4 * sizeof(float));
    k->attr = malloc((size_t)nv * 3 * sizeof(float));
    k->idx = malloc((size_t)ntri * 3 * sizeof(uint32_t));
    assert_true(k->clip && k->attr && k->idx);
    int v = 0, ti = 0;
    while (ti < ntri) {
        const int kind = big && tu_int(&r, 3) == 0 ? 2 : tu_int(&r, 10);
        const float cx = tu_range(&r, -1.2f, 1.2f), cy = tu_range(&r, -1.2f, 1.2f);
        const float s = tu_range(&r, 0.01f, 0.8f);
        const int constant = tu_int(&r, 3) == 0;
        float ca[3];
        for (int a = 0; a < 3; a++)
            ca[a] = special_value(&r);
        if (kind == 0 && ti + 2 <= ntri) {   /* a quad: two triangles sharing an edge */
            const float wq = tu_range(&r, 0.5f, 3.0f);
            for (int i = 0; i < 4; i++) {
                float *c = k->clip + 4 * (v + i);
                c[0] = (cx + ((i == 1 || i == 2) ? s : -s)) * wq;
                c[1] = (cy + (i >= 2 ? s : -s)) * wq;
                c[2] = tu_range(&r, -0.9f, 0.9f) * wq;
                c[3] = wq;
                for (int a = 0; a < 3; a++)
                    k->attr[3 * (v + i) + a] = constant ? ca[a] : tu_range(&r, -1.2f, 1.2f);
            }
            const uint32_t q[6] = { 0, 1, 2, 0, 2, 3 };
            for (int i = 0; i < 6; i++)
                k->idx[3 * ti + i] = (uint32_t)v + q[i];
            v += 4;
            ti += 2;
            continue;
        }
        float *c = k->clip + 4 * v;
        for (int i = 0; i < 3; i++) {
            const float w = pick_w(&r), aw = fabsf(w) > 1e-3f ? fabsf(w) : 1.0f;
            c[4 * i] = (cx + tu_range(&r, -s, s)) * aw;
            c[4 * i + 1] = (cy + tu_range(&r, -s, s)) * aw;
            c[4 * i + 2] = tu_range(&r, -1.3f, 1.3f) * aw;
            c[4 * i + 3] = w;
        }
        switch (kind) {
        case 1:   /* sliver */
        {
            const float f = tu_range(&r, -0.5f, 1.5f);
            for (int q = 0; q < 4; q++)
                c[8 + q] = c[q] + f * (c[4 + q] - c[q]);
            c[8] += tu_range(&r, -1e-3f, 1e-3f) * fabsf(c[11]);
            break;
        }
        case 2:   /* huge, up to far beyond the guard band (the int64 scan) */
            for (int i = 0; i < 3; i++) {
                const float a = tu_range(&r, 0.0f, 6.2831853f);
                const float rad = 1.5f * powf(8000.0f, tu_unit(&r));
                const float aw = fabsf(c[4 * i + 3]) > 1e-3f ? fabsf(c[4 * i + 3]) : 1.0f;
                c[4 * i] = (cx + rad * cosf(a)) * aw;
                c[4 * i + 1] = (cy + rad * sinf(a)) * aw;
            }
            break;
        case 3:   /* tiny: a pixel or two (single pixels, micro records) */
        case 4:
            for (int i = 1; i < 3; i++) {
                c[4 * i + 3] = c[3];
                c[4 * i] = c[0] + tu_range(&r, -0.03f, 0.03f) * fabsf(c[3]);
                c[4 * i + 1] = c[1] + tu_range(&r, -0.03f, 0.03f) * fabsf(c[3]);
            }
            break;
        case 5:   /* across the near plane */
            c[2] = -2.0f * fabsf(c[3]);
            c[6] = 0.5f * fabsf(c[7]);
            break;
        case 6:   /* edge-on */
            for (int i = 1; i < 3; i++)
                c[4 * i] = c[0] / c[3] * c[4 * i + 3];
            break;
        case 7:   /* wide and flat: long rows (the wide scan) */
            c[1] = c[5] = cy * fabsf(c[3]);
            c[5] = cy * fabsf(c[7]);
            c[0] = -1.5f * fabsf(c[3]);
            c[4] = 1.5f * fabsf(c[7]);
            break;
        default:
            break;
        }
        for (int i = 0; i < 3; i++) {
            for (int a = 0; a < 3; a++)
                k->attr[3 * (v + i) + a] = constant ? ca[a]
                                           : tu_int(&r, 20) == 0 ? special_value(&r)
                                                                 : tu_range(&r, -1.2f, 1.2f);
            k->idx[3 * ti + i] = (uint32_t)(v + i);
        }
        v += 3;
        ti++;
    }
    k->m.clip = k->clip;
    k->m.vertex_count = v;
    k->m.attr = k->attr;
    k->m.attr_count = 3;
    k->m.indices = k->idx;
    k->m.tri_count = ti;
    k->m.cull = (rast_cull)tu_int(&r, 3);
}

static void free_case(ncase *k)
{
    free(k->clip);
    free(k->attr);
    free(k->idx);
}

/* A target of case k: floats (n10 0) or packed (n10 1) attributes. */
static rast_target make_target(const ncase *k, int n10)
{
    rast_target t;
    memset(&t, 0, sizeof t);
    t.width = k->w;
    t.height = k->h;
    t.mask_stride = k->w + k->pad;
    t.mask = malloc((size_t)t.mask_stride * (size_t)k->h);
    if (k->depth) {
        t.depth_stride = k->w + (k->pad + 3) % 7;
        t.depth = malloc((size_t)t.depth_stride * (size_t)k->h * sizeof(float));
    }
    t.attr_count = 3;
    if (n10) {
        t.attr_n10_stride = k->w + k->pad;
        t.attr_n10 = malloc((size_t)t.attr_n10_stride * (size_t)k->h * sizeof(uint32_t));
    } else {
        t.attr_stride = 3 * k->w + (k->pad + 5) % 11;
        t.attr = malloc((size_t)t.attr_stride * (size_t)k->h * sizeof(float));
    }
    assert_non_null(t.mask);
    return t;
}

static size_t depth_bytes(const rast_target *t)
{
    return t->depth ? (size_t)t->depth_stride * (size_t)t->height * sizeof(float) : 0;
}

/* Every byte of every plane (padding included) to PAD_BYTE, then clear. */
static void reset_target(const rast_target *t)
{
    memset(t->mask, PAD_BYTE, (size_t)t->mask_stride * (size_t)t->height);
    if (t->depth)
        memset(t->depth, PAD_BYTE, depth_bytes(t));
    if (t->attr)
        memset(t->attr, PAD_BYTE, (size_t)t->attr_stride * (size_t)t->height * sizeof(float));
    if (t->attr_n10)
        memset(t->attr_n10, PAD_BYTE,
               (size_t)t->attr_n10_stride * (size_t)t->height * sizeof(uint32_t));
    rast_target_clear(t);
}

static void free_target(rast_target *t)
{
    free(t->mask);
    free(t->depth);
    free(t->attr);
    free(t->attr_n10);
}

static const uint32_t pad_word = PAD_BYTE * 0x01010101u;

/* 0 when tn (an n10 target drawn as tf, a float target, was) has the
 * float run's depth, mask and stats, n10 = ef_n10_pack of the floats and
 * untouched padding; else prints the first difference and returns 1. */
static int check_pair(const rast_target *tf, const rast_stats *sf, const rast_target *tn,
                      const rast_stats *sn, const char *what, int n)
{
    if (memcmp(tf->mask, tn->mask, (size_t)tf->mask_stride * (size_t)tf->height)) {
        print_message("case %d %s: mask differs between the float and n10 runs\n", n, what);
        return 1;
    }
    if (tf->depth && memcmp(tf->depth, tn->depth, depth_bytes(tf))) {
        print_message("case %d %s: depth differs between the float and n10 runs\n", n, what);
        return 1;
    }
    if (memcmp(sf, sn, sizeof *sf)) {
        print_message("case %d %s: stats differ (pixels %ld / %ld)\n", n, what,
                      sf->pixels_written, sn->pixels_written);
        return 1;
    }
    for (int y = 0; y < tn->height; y++) {
        const uint32_t *row = tn->attr_n10 + (size_t)y * (size_t)tn->attr_n10_stride;
        const float *a = tf->attr + (size_t)y * (size_t)tf->attr_stride;
        for (int x = 0; x < tn->width; x++) {
            const uint32_t want = ef_n10_pack(a[3 * x], a[3 * x + 1], a[3 * x + 2]);
            if (row[x] != want) {
                print_message("case %d %s: n10 at x=%d y=%d is 0x%08X, ef_n10_pack of "
                              "(%a, %a, %a) is 0x%08X\n", n, what, x, y, row[x], a[3 * x],
                              a[3 * x + 1], a[3 * x + 2], want);
                return 1;
            }
        }
        for (int x = tn->width; x < tn->attr_n10_stride; x++)
            if (row[x] != pad_word) {
                print_message("case %d %s: n10 padding written at x=%d y=%d\n", n, what, x, y);
                return 1;
            }
    }
    return 0;
}

/* The ISAs of this build, in ef_isa order, the reference first. */
static const int all_isas[] = { EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512,
                                EF_ISA_NEON };
#define NISAS ((int)(sizeof all_isas / sizeof all_isas[0]))

static int isa_runs(int isa)
{
    return isa == EF_ISA_REF || ef_cpu_has((ef_isa)isa);
}

typedef struct run_totals {
    long pixels, nan_pixels, tie_pixels, clamped;
    int paths;
} run_totals;

/* Counts what the float plane of case k holds (the test must reach
 * NaN, ties and clamped values). */
static void tally(const rast_target *tf, run_totals *tot)
{
    for (int y = 0; y < tf->height; y++)
        for (int x = 0; x < tf->width; x++) {
            if (!tf->mask[(size_t)y * (size_t)tf->mask_stride + x])
                continue;
            tot->pixels++;
            const float *a = tf->attr + (size_t)y * (size_t)tf->attr_stride + 3 * (size_t)x;
            for (int c = 0; c < 3; c++) {
                const float v = a[c] * 511.0f;
                if (isnan(a[c]))
                    tot->nan_pixels++;
                else if (fabsf(v) > 511.0f)
                    tot->clamped++;
                else if (v - floorf(v) == 0.5f)
                    tot->tie_pixels++;
            }
        }
}

/* Case n on every path; fails the test at the first difference. */
static void run_case(int n, run_totals *tot)
{
    ncase k;
    make_case(n, &k);
    rast_target tf = make_target(&k, 0), tn = make_target(&k, 1);
    uint32_t *ref_n10 = NULL;
    const size_t n10_bytes = (size_t)tn.attr_n10_stride * (size_t)tn.height * sizeof(uint32_t);
    char what[64];
    /* every scan of the build, through rast__draw_with */
    for (int i = 0; i < NISAS; i++) {
        const int isa = all_isas[i];
        if (!isa_runs(isa))
            continue;
        rast__scan_rows_fn scan = isa == EF_ISA_REF ? rast__scan_rows_ref
                                                    : rast__scan_for_isa(isa);
        rast_stats sf = { 0 }, sn = { 0 };
        reset_target(&tf);
        reset_target(&tn);
        assert_int_equal(rast__draw_with(&tf, &k.m, &sf, scan), RAST_OK);
        assert_int_equal(rast__draw_with(&tn, &k.m, &sn, scan), RAST_OK);
        snprintf(what, sizeof what, "scan %s", ef_isa_name((ef_isa)isa));
        if (check_pair(&tf, &sf, &tn, &sn, what, n))
            fail_msg("case %d: %s", n, what);
        if (!ref_n10) {
            tally(&tf, tot);
            ref_n10 = malloc(n10_bytes);
            assert_non_null(ref_n10);
            memcpy(ref_n10, tn.attr_n10, n10_bytes);
        } else if (memcmp(ref_n10, tn.attr_n10, n10_bytes)) {
            fail_msg("case %d: the n10 plane of %s differs from the reference's", n, what);
        }
        tot->paths++;
    }
    /* rast_draw: the ISA of EGOFUSE_ISA */
    {
        rast_stats sf = { 0 }, sn = { 0 };
        reset_target(&tf);
        reset_target(&tn);
        assert_int_equal(rast_draw(&tf, &k.m, &sf), RAST_OK);
        assert_int_equal(rast_draw(&tn, &k.m, &sn), RAST_OK);
        if (check_pair(&tf, &sf, &tn, &sn, "rast_draw", n) ||
            memcmp(ref_n10, tn.attr_n10, n10_bytes))
            fail_msg("case %d: rast_draw", n);
        tot->paths++;
    }
    /* contexts capped at each ISA, 1 and 3 threads; jobs; context clears */
    for (int i = 0; i < NISAS; i++) {
        const int isa = all_isas[i];
        if (!isa_runs(isa) || (n % 3 && isa != EF_ISA_REF && i + 1 < NISAS &&
                               isa_runs(all_isas[i + 1])))
            continue;   /* every third case on every ISA, the others on the best and ref */
        for (int th = 1; th <= 3; th += 2) {
            rast_context_desc d = { isa, th };
            rast_context *c = rast_context_create(&d);
            assert_non_null(c);
            rast_stats sf = { 0 }, sn = { 0 };
            reset_target(&tf);
            reset_target(&tn);
            rast_context_clear(c, &tf);   /* known: the next clears are by tiles */
            rast_context_clear(c, &tn);
            assert_int_equal(rast_context_draw(c, &tf, &k.m, &sf), RAST_OK);
            assert_int_equal(rast_context_draw(c, &tn, &k.m, &sn), RAST_OK);
            snprintf(what, sizeof what, "context %s x%d",
                     ef_isa_name((ef_isa)rast_context_isa(c)), th);
            if (check_pair(&tf, &sf, &tn, &sn, what, n) ||
                memcmp(ref_n10, tn.attr_n10, n10_bytes))
                fail_msg("case %d: %s", n, what);
            /* the context's clear of what was drawn: all 0, padding kept */
            rast_context_clear(c, &tn);
            for (int y = 0; y < tn.height; y++)
                for (int x = 0; x < tn.attr_n10_stride; x++)
                    if (tn.attr_n10[(size_t)y * (size_t)tn.attr_n10_stride + x] !=
                        (x < tn.width ? 0u : pad_word))
                        fail_msg("case %d %s: rast_context_clear left n10 (%d, %d) = 0x%08X",
                                 n, what, x, y, tn.attr_n10[(size_t)y * tn.attr_n10_stride + x]);
            /* jobs: the float and the n10 target at once */
            rast_target tf2 = tf;
            reset_target(&tf);
            reset_target(&tn);
            const rast_target *jt[2] = { &tf2, &tn };
            const rast_mesh_desc *jm[2] = { &k.m, &k.m };
            rast_stats sj = { 0 };
            assert_int_equal(rast_context_draw_jobs(c, 2, jt, jm, &sj), RAST_OK);
            rast_stats s2 = sf;   /* stats sum over the jobs: 2x the float run's */
            rast__stats_add(&s2, &sf);
            assert_memory_equal(&sj, &s2, sizeof sj);
            if (check_pair(&tf, &sf, &tn, &sn, what, n) ||
                memcmp(ref_n10, tn.attr_n10, n10_bytes))
                fail_msg("case %d: jobs of %s", n, what);
            rast_context_destroy(c);
            tot->paths++;
        }
    }
    free(ref_n10);
    free_target(&tf);
    free_target(&tn);
    free_case(&k);
}

static void test_n10_equals_pack_of_floats(void **state)
{
    (void)state;
    for (int i = 1; i < NISAS; i++)
        if (!isa_runs(all_isas[i]))
            print_message("SKIP n10 isa %s: this CPU (or build) does not run it\n",
                          ef_isa_name((ef_isa)all_isas[i]));
    run_totals tot = { 0 };
    for (int n = 0; n < NCASES; n++)
        run_case(n, &tot);
    print_message("NOTE n10: %d cases, %d paths drawn, %ld pixels (ref), %ld NaN, %ld tie, "
                  "%ld clamped components, every n10 plane ef_n10_pack of its float plane\n",
                  NCASES, tot.paths, tot.pixels, tot.nan_pixels, tot.tie_pixels, tot.clamped);
    /* the cases reach the rules the packing must get right */
    assert_true(tot.pixels > 100000 && tot.nan_pixels > 100 && tot.tie_pixels > 100 &&
                tot.clamped > 1000);
}

/* keep_attr on an n10 target: depth and mask as a fresh target's, the
 * pixels of nonzero mask with this frame's packed attributes. */
static void test_n10_keep_attr(void **state)
{
    (void)state;
    ncase k0, k1;
    make_case(11, &k0);
    make_case(12, &k1);
    k1.w = k0.w;
    k1.h = k0.h;
    rast_target tn = make_target(&k0, 1), fresh = make_target(&k0, 1);
    rast_context_desc d = { 0, 2 };
    rast_context *c = rast_context_create(&d);
    assert_non_null(c);
    reset_target(&tn);
    rast_context_clear(c, &tn);
    assert_int_equal(rast_context_draw(c, &tn, &k0.m, NULL), RAST_OK);
    rast_context_clear_keep_attr(c, &tn);
    assert_int_equal(rast_context_draw(c, &tn, &k1.m, NULL), RAST_OK);
    reset_target(&fresh);
    assert_int_equal(rast_draw(&fresh, &k1.m, NULL), RAST_OK);
    assert_memory_equal(tn.mask, fresh.mask, (size_t)tn.mask_stride * tn.height);
    if (tn.depth)
        assert_memory_equal(tn.depth, fresh.depth, depth_bytes(&tn));
    for (int y = 0; y < tn.height; y++)
        for (int x = 0; x < tn.width; x++)
            if (tn.mask[(size_t)y * tn.mask_stride + x])
                assert_int_equal(tn.attr_n10[(size_t)y * tn.attr_n10_stride + x],
                                 fresh.attr_n10[(size_t)y * tn.attr_n10_stride + x]);
    /* a full clear after keep_attr clears the n10 plane whole */
    rast_context_clear(c, &tn);
    for (int y = 0; y < tn.height; y++)
        for (int x = 0; x < tn.width; x++)
            assert_int_equal(tn.attr_n10[(size_t)y * tn.attr_n10_stride + x], 0);
    rast_context_destroy(c);
    free_target(&tn);
    free_target(&fresh);
    free_case(&k0);
    free_case(&k1);
}

static void test_n10_validation(void **state)
{
    (void)state;
    enum { W = 8, H = 4 };
    float depth[W * H], attr[W * H * 3], clip[12] = { 0 };
    uint8_t mask[W * H];
    uint32_t n10[W * H * 2], idx[3] = { 0, 1, 2 };
    float va[9] = { 0 };
    rast_mesh_desc m = { clip, 3, va, 3, idx, 1, RAST_CULL_NONE };
    const rast_target ok = { W, H, depth, W, mask, W, NULL, 0, 3, n10, W };
    rast_context *c = rast_context_create(NULL);
    assert_non_null(c);
    rast_target t = ok;
    assert_int_equal(rast_draw(&t, &m, NULL), RAST_OK);
    assert_int_equal(rast_context_draw(c, &t, &m, NULL), RAST_OK);
    t.attr = attr;   /* both planes */
    t.attr_stride = 3 * W;
    assert_int_equal(rast_draw(&t, &m, NULL), RAST_ERR_ARGS);
    assert_int_equal(rast_context_draw(c, &t, &m, NULL), RAST_ERR_ARGS);
    t = ok;
    t.attr_n10_stride = W - 1;
    assert_int_equal(rast_draw(&t, &m, NULL), RAST_ERR_ARGS);
    assert_int_equal(rast_context_draw(c, &t, &m, NULL), RAST_ERR_ARGS);
    t.attr_n10_stride = 2 * W;   /* a larger stride is fine */
    t.height = H / 2;
    assert_int_equal(rast_draw(&t, &m, NULL), RAST_OK);
    for (int na = 0; na <= RAST_MAX_ATTRS; na++) {
        if (na == 3)
            continue;
        t = ok;
        t.attr_count = na;
        rast_mesh_desc mm = m;
        mm.attr_count = na;   /* matching, but not 3 */
        assert_int_equal(rast_draw(&t, &mm, NULL), RAST_ERR_ARGS);
        assert_int_equal(rast_context_draw(c, &t, &mm, NULL), RAST_ERR_ARGS);
    }
    /* jobs: two targets whose planes share memory are refused, the n10
     * plane included */
    t = ok;
    uint8_t mask2[W * H];
    rast_target u = ok;
    u.depth = NULL;
    u.mask = mask2;
    u.attr_n10 = n10 + W * H;   /* its own memory */
    const rast_target *jt[2] = { &t, &u };
    const rast_mesh_desc *jm[2] = { &m, &m };
    assert_int_equal(rast_context_draw_jobs(c, 2, jt, jm, NULL), RAST_OK);
    u.attr_n10 = n10 + W * H - 1;   /* t's last element */
    assert_int_equal(rast_context_draw_jobs(c, 2, jt, jm, NULL), RAST_ERR_ARGS);
    u.attr_n10 = (uint32_t *)(void *)(depth + W * H - 1);   /* t's depth */
    assert_int_equal(rast_context_draw_jobs(c, 2, jt, jm, NULL), RAST_ERR_ARGS);
    u.attr_n10 = n10 + W * H;
    u.mask = (uint8_t *)(void *)(n10 + 3);   /* u's mask in t's n10 plane */
    assert_int_equal(rast_context_draw_jobs(c, 2, jt, jm, NULL), RAST_ERR_ARGS);
    rast_context_destroy(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_n10_validation),
        cmocka_unit_test(test_n10_keep_attr),
        cmocka_unit_test(test_n10_equals_pack_of_floats),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
