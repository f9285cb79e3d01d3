/* test_raster_aa.c - anti-aliased coverage (rast_draw_aa): the standard
 * sample positions, coverage of straight edges against the exact area of
 * each pixel on the inside of the edge (with the stated error bound of
 * each pattern), full and empty pixels, watertight partitions (no sample
 * covered twice, none missed), the resolve rounding, every ISA equal to
 * the reference on a seeded soup (memcmp and a recorded CRC), bad input.
 *
 * Error bound (docs/raster.md section 12): for a pixel cut by one
 * straight edge, |covered/n - area| <= B_n, where B_n is the half-plane
 * discrepancy of the pattern, the largest over all lines (computed by a
 * sweep over every line through a sample, where the extremes lie):
 * B_4 = 0.30858, B_8 = 0.22656, B_16 = 0.17185. The byte mask adds at
 * most 0.5/255 of rounding. The edges here lie exactly on the 1/256 grid,
 * so snapping adds nothing. */
#include "support/testutil.h"
#include <cmocka.h>

#include "test_raster_util.h"

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "../src/cpu/ef_mem.h"

/* Recorded CRC32 of the reference's sample bits over the AA soup. */
#define AA_CRC 0xFE42DF31u /* issue 20: inputs drawn in a defined order (before: 0x97661E8A, gcc only) */

static const int counts[3] = { 4, 8, 16 };

static double bound_for(int n)
{
    return n == 4 ? 0.30858 : n == 8 ? 0.22656 : 0.17185;
}

static rast_aa_target aa_make(int w, int h, int pad, int n)
{
    rast_aa_target t = { w, h, calloc((size_t)(w + pad) * h, sizeof(uint32_t)), w + pad, n };
    return t;
}

/* Runs check(n, r) for each sample count n of counts, in order, with one
 * rng r seeded with seed for all of them. */
static void for_each_count(void (*check)(int n, tu_rng *r), uint64_t seed)
{
    tu_rng r = { seed };
    for (int c = 0; c < 3; c++) check(counts[c], &r);
}

/* Draws the triangle of the fixed-point vertices (X[i], Y[i]) (1/256 px)
 * alone on t, cleared first. */
static void aa_draw_fixed(rast_aa_target *t, const int64_t X[3], const int64_t Y[3])
{
    float clip[12];
    for (int i = 0; i < 3; i++)
        rt_clip_at(X[i], Y[i], t->width, t->height, 0.0f, 1.0f, clip + 4 * i);
    static const uint32_t idx[3] = { 0, 1, 2 };
    rast_mesh_desc m = { clip, 3, NULL, 0, idx, 1, RAST_CULL_NONE };
    rast_aa_clear(t);
    assert_int_equal(rast_draw_aa(t, &m, NULL), RAST_OK);
}

/* Area of the unit pixel square [x, x+1] x [y, y+1] where
 * nx*px + ny*py + c >= 0 (double, polygon clip). */
static double half_plane_area(double nx, double ny, double c, double x, double y)
{
    double in[4][2] = { { x, y }, { x + 1, y }, { x + 1, y + 1 }, { x, y + 1 } };
    double out[8][2];
    int m = 0;
    for (int i = 0; i < 4; i++) {
        const double *a = in[i], *b = in[(i + 1) % 4];
        double da = nx * a[0] + ny * a[1] + c, db = nx * b[0] + ny * b[1] + c;
        if (da >= 0) {
            out[m][0] = a[0];
            out[m][1] = a[1];
            m++;
        }
        if ((da >= 0) != (db >= 0)) {
            double s = da / (da - db);
            out[m][0] = a[0] + s * (b[0] - a[0]);
            out[m][1] = a[1] + s * (b[1] - a[1]);
            m++;
        }
    }
    double s = 0;
    for (int i = 0; i < m; i++)
        s += out[i][0] * out[(i + 1) % m][1] - out[(i + 1) % m][0] * out[i][1];
    return fabs(s) * 0.5;
}

static void test_positions(void **state)
{
    (void)state;
    int xy[2 * RAST_AA_MAX_SAMPLES];
    assert_int_equal(rast_aa_positions(4, xy), 4);
    const int d3d4[8] = { -2, -6, 6, -2, -6, 2, 2, 6 };
    assert_memory_equal(xy, d3d4, sizeof d3d4);
    assert_int_equal(rast_aa_positions(8, xy), 8);
    assert_int_equal(xy[14], 7);
    assert_int_equal(xy[15], -7);
    assert_int_equal(rast_aa_positions(16, xy), 16);
    assert_int_equal(xy[30], -7);
    assert_int_equal(xy[31], -8);
    assert_int_equal(rast_aa_positions(2, xy), 0);
    assert_int_equal(rast_aa_positions(16, NULL), 0);
    for (int c = 0; c < 3; c++) {
        int n = rast_aa_positions(counts[c], xy);
        for (int i = 0; i < n; i++) {
            assert_true(xy[2 * i] >= -8 && xy[2 * i] <= 7);
            assert_true(xy[2 * i + 1] >= -8 && xy[2 * i + 1] <= 7);
            for (int j = 0; j < i; j++)   /* distinct rows and columns (n-rooks) */
                assert_true(xy[2 * i] != xy[2 * j] && xy[2 * i + 1] != xy[2 * j + 1]);
        }
    }
}

/* One straight edge through a 64x64 target at a random angle and offset
 * (vertices on the 1/256 grid, far outside): every pixel the edge crosses,
 * and every other pixel, against the exact area inside the edge. */
static void edge_area(int n, tu_rng *r)
{
    enum { W = 64, H = 64, CASES = 300 };
    const double B = bound_for(n);
    rast_aa_target t = aa_make(W, H, 3, n);
    uint8_t *mask = malloc((size_t)W * H);
    double worst = 0, sum = 0;
    long cut = 0, full = 0;
    for (int k = 0; k < CASES; k++) {
        /* Edge A -> B through a point of the target; C far on one side. */
        double px = tu_range(r, 4, W - 4), py = tu_range(r, 4, H - 4);
        double th = tu_range(r, 0, 6.2831853);
        double dx = cos(th), dy = sin(th);
        int64_t X[3] = { llround((px - 300 * dx) * 256), llround((px + 300 * dx) * 256),
                         llround((px - 300 * dy) * 256) };
        int64_t Y[3] = { llround((py - 300 * dy) * 256), llround((py + 300 * dy) * 256),
                         llround((py + 300 * dx) * 256) };
        aa_draw_fixed(&t, X, Y);
        assert_int_equal(rast_aa_resolve(&t, mask, W), RAST_OK);
        /* The inside of edge A->B: the side of C (pixel units). */
        double ax = X[0] / 256.0, ay = Y[0] / 256.0, bx = X[1] / 256.0, by = Y[1] / 256.0;
        double nx = -(by - ay), ny = bx - ax, cc = -(nx * ax + ny * ay);
        if (nx * (X[2] / 256.0) + ny * (Y[2] / 256.0) + cc < 0) {
            nx = -nx;
            ny = -ny;
            cc = -cc;
        }
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                double a = half_plane_area(nx, ny, cc, x, y);
                int cov = __builtin_popcount(t.samples[(size_t)y * t.stride + x]);
                double e = fabs((double)cov / n - a);
                if (e > B + 1e-9)
                    fail_msg("%d samples, case %d pixel (%d,%d): %d/%d covered, area "
                             "%.5f, error %.5f > %.5f", n, k, x, y, cov, n, a, e, B);
                double em = fabs(mask[y * W + x] / 255.0 - a);
                assert_true(em <= B + 0.5 / 255 + 1e-9);
                if (a == 1.0) {
                    assert_int_equal(cov, n);
                    assert_int_equal(mask[y * W + x], 255);
                    full++;
                } else if (a == 0.0) {
                    assert_int_equal(cov, 0);
                    assert_int_equal(mask[y * W + x], 0);
                } else {
                    cut++;
                    sum += e;
                    if (e > worst)
                        worst = e;
                }
            }
    }
    print_message("NOTE %2d samples: %ld cut pixels, mean |coverage - area| %.4f, "
                  "max %.4f (bound %.4f); %ld full pixels exact\n", n, cut, sum / cut,
                  worst, B, full);
    /* The estimate is useful: well below the bound on average (a wrong
     * pattern or offset gives a mean near 0.25). */
    assert_true(sum / cut < B / 2);
    assert_true(worst > B / 2);   /* the bound is not vacuous */
    free(t.samples);
    free(mask);
}

static void test_edge_area(void **state)
{
    (void)state;
    for_each_count(edge_area, 0xAA11);
}

/* A jittered grid of triangles sharing edges and vertices, each drawn
 * alone: no sample is covered twice and every sample inside the grid's
 * outline is covered (pixels one pixel inside the outline are full). */
static void watertight(int n, tu_rng *r)
{
    enum { W = 64, H = 64, G = 7 };
    rast_aa_target acc = aa_make(W, H, 0, n), one = aa_make(W, H, 0, n);
    rast_aa_clear(&acc);
    int64_t X[G + 1][G + 1], Y[G + 1][G + 1];
    for (int j = 0; j <= G; j++)
        for (int i = 0; i <= G; i++) {
            int edge = i == 0 || j == 0 || i == G || j == G;
            X[j][i] = (int64_t)(4 + i * 8) * 256 + (edge ? 0 : tu_int(r, 1400) - 700);
            Y[j][i] = (int64_t)(4 + j * 8) * 256 + (edge ? 0 : tu_int(r, 1400) - 700);
        }
    long drawn = 0;
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++)
            for (int h = 0; h < 2; h++) {
                int q[2][3][2] = { { { 0, 0 }, { 1, 0 }, { 1, 1 } },
                                   { { 0, 0 }, { 1, 1 }, { 0, 1 } } };
                int64_t tx[3], ty[3];
                for (int v = 0; v < 3; v++) {
                    tx[v] = X[j + q[h][v][1]][i + q[h][v][0]];
                    ty[v] = Y[j + q[h][v][1]][i + q[h][v][0]];
                }
                aa_draw_fixed(&one, tx, ty);
                for (int p = 0; p < W * H; p++) {
                    if (acc.samples[p] & one.samples[p])
                        fail_msg("%d samples: pixel (%d,%d) sample covered twice", n,
                                 p % W, p / W);
                    acc.samples[p] |= one.samples[p];
                }
                drawn++;
            }
    /* Outline [4, 60) px: pixels 4..59 hold only inside samples. */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int cov = __builtin_popcount(acc.samples[y * W + x]);
            int inside = x >= 4 && x < 60 && y >= 4 && y < 60;
            assert_int_equal(cov, inside ? n : 0);
        }
    print_message("NOTE %2d samples: %ld triangles, every sample once\n", n, drawn);
    free(acc.samples);
    free(one.samples);
}

static void test_watertight(void **state)
{
    (void)state;
    for_each_count(watertight, 0xAA22);
}

static void test_resolve(void **state)
{
    (void)state;
    for (int c = 0; c < 3; c++) {
        const int n = counts[c];
        rast_aa_target t = aa_make(n + 1, 1, 2, n);
        for (int k = 0; k <= n; k++)
            t.samples[k] = k == n ? 0xFFFFFFFFu : ((1u << k) - 1u);
        uint8_t mask[RAST_AA_MAX_SAMPLES + 1];
        assert_int_equal(rast_aa_resolve(&t, mask, n + 1), RAST_OK);
        for (int k = 0; k <= n; k++) {
            /* round(255 k / n), halves up; bits above n ignored */
            int want = (int)floor(255.0 * k / n + 0.5);
            assert_int_equal(mask[k], want);
        }
        assert_int_equal(mask[0], 0);
        assert_int_equal(mask[n], 255);
        free(t.samples);
    }
    rast_aa_target t = aa_make(4, 4, 0, 4);
    uint8_t m[16];
    assert_int_equal(rast_aa_resolve(&t, NULL, 4), RAST_ERR_ARGS);
    assert_int_equal(rast_aa_resolve(&t, m, 3), RAST_ERR_ARGS);
    t.count = 5;
    assert_int_equal(rast_aa_resolve(&t, m, 4), RAST_ERR_ARGS);
    t.count = 4;
    t.width = 0;
    assert_int_equal(rast_aa_resolve(&t, m, 4), RAST_ERR_SIZE);
    free(t.samples);
}

static void test_errors(void **state)
{
    (void)state;
    const float clip[12] = { -1, -1, 0, 1, 1, -1, 0, 1, -1, 1, 0, 1 };
    const uint32_t idx[3] = { 0, 1, 2 }, bad_idx[3] = { 0, 1, 3 };
    rast_mesh_desc m = { clip, 3, NULL, 0, idx, 1, RAST_CULL_NONE };
    rast_aa_target t = aa_make(8, 8, 0, 8);
    rast_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_draw_aa(NULL, &m, &st), RAST_ERR_ARGS);
    assert_int_equal(rast_draw_aa(&t, NULL, &st), RAST_ERR_ARGS);
    t.count = 6;
    assert_int_equal(rast_draw_aa(&t, &m, &st), RAST_ERR_ARGS);
    t.count = 8;
    t.stride = 7;
    assert_int_equal(rast_draw_aa(&t, &m, &st), RAST_ERR_ARGS);
    t.stride = 8;
    t.height = RAST_MAX_DIM + 1;
    assert_int_equal(rast_draw_aa(&t, &m, &st), RAST_ERR_SIZE);
    t.height = 8;
    m.indices = bad_idx;
    assert_int_equal(rast_draw_aa(&t, &m, &st), RAST_ERR_INDEX);
    assert_int_equal(st.tris_in, 0);
    m.indices = idx;
    rast_aa_clear(&t);
    assert_int_equal(rast_context_draw_aa(NULL, &t, &m, &st), RAST_ERR_ARGS);
    rast_context *c = rast_context_create(NULL);
    assert_int_equal(rast_context_draw_aa(c, &t, &m, &st), RAST_OK);
    rast_context_destroy(c);
    /* The lower-left half of the target: the diagonal x + y = 8 cuts the
     * diagonal pixels in half; the other pixels are full or empty. */
    assert_int_equal(st.tris_in, 1);
    assert_int_equal(st.tris_drawn, 1);
    int full = 0, part = 0;
    for (int p = 0; p < 64; p++) {
        int cov = __builtin_popcount(t.samples[p]);
        full += cov == 8;
        part += cov > 0 && cov < 8;
    }
    assert_int_equal(full, 28);
    assert_int_equal(part, 8);
    /* NaN vertices: dropped, nothing written. */
    float nanclip[12] = { NAN, -1, 0, 1, 1, -1, 0, 1, -1, 1, 0, 1 };
    m.clip = nanclip;
    rast_aa_clear(&t);
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_draw_aa(&t, &m, &st), RAST_OK);
    assert_int_equal(st.tris_nonfinite, 1);
    for (int p = 0; p < 64; p++)
        assert_int_equal(t.samples[p], 0);
    free(t.samples);
}

/* ---- every ISA equal to the reference ----------------------------------- */

/* A seeded soup case: random, huge, tiny, sliver, behind-the-eye and
 * near-crossing triangles, a NaN now and then, shared-edge quads. */
static void aa_case(int n, rast_aa_target *t, rast_mesh_desc *m, float **clip, uint32_t **idx)
{
    tu_rng r = { 0xAA5000ull + (uint64_t)n * 0x9E3779B97F4A7C15ull };
    int w = tu_int(&r, 10) == 0 ? 200 + tu_int(&r, 300) : 1 + tu_int(&r, 70);
    int h = tu_int(&r, 10) == 0 ? 100 + tu_int(&r, 200) : 1 + tu_int(&r, 50);
    const int shift = tu_int(&r, 4);   /* drawn in order (support/tu_kin.h) */
    *t = aa_make(w, h, shift, counts[tu_int(&r, 3)]);
    int nt = 1 + tu_int(&r, 30);
    *clip = malloc((size_t)nt * 3 * 4 * sizeof(float));
    *idx = malloc((size_t)nt * 3 * sizeof(uint32_t));
    for (int i = 0; i < nt; i++) {
        int kind = tu_int(&r, 8);
        float cx = tu_range(&r, -1.2f, 1.2f), cy = tu_range(&r, -1.2f, 1.2f);
        float s = kind == 0 ? tu_range(&r, 2.0f, 3000.0f) : kind == 1 ? 0.01f : tu_range(&r, 0.02f, 0.7f);
        for (int v = 0; v < 3; v++) {
            float *c = *clip + 12 * i + 4 * v;
            float wv = kind == 2 && v == 0 ? tu_range(&r, -1.0f, 0.1f) : tu_range(&r, 0.3f, 3.0f);
            float aw = fabsf(wv) > 1e-3f ? fabsf(wv) : 1.0f;
            c[0] = (cx + tu_range(&r, -s, s)) * aw;
            c[1] = (cy + tu_range(&r, -s, s)) * aw;
            c[2] = (kind == 3 && v == 1 ? -1.5f : tu_range(&r, -0.9f, 0.9f)) * aw;
            c[3] = wv;
            if (kind == 4 && v == 2) {   /* sliver */
                c[0] = (*clip)[12 * i] + 0.5f * ((*clip)[12 * i + 4] - (*clip)[12 * i]) + 1e-3f;
                c[1] = (*clip)[12 * i + 1] + 0.5f * ((*clip)[12 * i + 5] - (*clip)[12 * i + 1]);
                c[3] = (*clip)[12 * i + 3];
            }
        }
        if (kind == 5 && tu_int(&r, 6) == 0)
            (*clip)[12 * i + tu_int(&r, 12)] = NAN;
        for (int v = 0; v < 3; v++)
            (*idx)[3 * i + v] = (uint32_t)(3 * i + v);
    }
    rast_mesh_desc d = { *clip, 3 * nt, NULL, 0, *idx, nt, (rast_cull)tu_int(&r, 3) };
    *m = d;
}

static void test_isa_equal(void **state)
{
    (void)state;
    enum { CASES = 1500 };
    const int isas[4] = { EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON };
    uint32_t crc = 0;
    long pixels = 0, compared[4] = { 0, 0, 0, 0 };
    for (int k = 0; k < CASES; k++) {
        rast_aa_target t;
        rast_mesh_desc m;
        float *clip;
        uint32_t *idx;
        aa_case(k, &t, &m, &clip, &idx);
        const size_t bytes = (size_t)t.stride * t.height * sizeof(uint32_t);
        memset(t.samples, 0x5A, bytes);     /* padding must stay */
        rast_aa_clear(&t);
        rast_stats sr;
        memset(&sr, 0, sizeof sr);
        assert_int_equal(rast__draw_aa_with(&t, &m, &sr, rast__scan_aa_ref), RAST_OK);
        uint32_t *ref = malloc(bytes);
        memcpy(ref, t.samples, bytes);
        crc = tu_crc32(crc, ref, bytes);
        long sv[3] = { sr.tris_drawn, sr.pixels_written, sr.tris_clipped_away };
        crc = tu_crc32(crc, sv, sizeof sv);
        pixels += sr.pixels_written;
        for (int i = 0; i < 4; i++) {
            if (!ef_cpu_has((ef_isa)isas[i]))
                continue;
            memset(t.samples, 0x5A, bytes);
            rast_aa_clear(&t);
            rast_stats si;
            memset(&si, 0, sizeof si);
            assert_int_equal(rast__draw_aa_with(&t, &m, &si,
                                                rast__scan_aa_for_isa(isas[i])), RAST_OK);
            if (memcmp(t.samples, ref, bytes) || memcmp(&si, &sr, sizeof si))
                fail_msg("AA case %d: %s differs from the reference", k,
                         ef_isa_name((ef_isa)isas[i]));
            compared[i]++;
        }
        EF_FREE_ALL(ref, t.samples, clip, idx);
    }
    for (int i = 0; i < 4; i++)
        if (!compared[i])
            print_message("SKIP AA %s: this CPU does not run it; untested: the AA scan of "
                          "src/raster/raster_%s.c\n", ef_isa_name((ef_isa)isas[i]),
                          ef_isa_name((ef_isa)isas[i]));
    print_message("NOTE AA soup: %d cases, %ld pixels touched, sse2/avx2/avx512/neon "
                  "compared %ld/%ld/%ld/%ld; CRC32 0x%08X (recorded 0x%08X)\n", CASES, pixels,
                  compared[0], compared[1], compared[2], compared[3], crc, AA_CRC);
    assert_true(pixels > 100000);
    assert_int_equal(crc, AA_CRC);
    if (!compared[0] || !compared[1] || !compared[2])
        skip();
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_positions),
        cmocka_unit_test(test_edge_area),
        cmocka_unit_test(test_watertight),
        cmocka_unit_test(test_resolve),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_isa_equal))
