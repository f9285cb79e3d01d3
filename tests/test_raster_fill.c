/* test_raster_fill.c - coverage: exact pixel sets of seeded small
 * triangles against an independent top-left reference (many centres
 * exactly on edges and vertices), full-screen quads, off-screen and
 * sub-pixel triangles, and watertightness: seeded tessellations of a
 * square (jittered grids and fans) and a closed icosphere seen through a
 * perspective camera must cover every pixel exactly once. */
#include "support/testutil.h"
#include <cmocka.h>

#include "test_raster_util.h"

/* Fixed-point centre of pixel i. */
#define CENTRE(i) ((int64_t)(i) * 256 + 128)

/* A random fixed-point coordinate near c: on a pixel centre, on a pixel
 * corner or anywhere, so that edges often pass exactly through centres. */
static int64_t pick_coord(tu_rng *r, int64_t lo_px, int64_t hi_px)
{
    int64_t p = lo_px + tu_int(r, (int)(hi_px - lo_px + 1));
    switch (tu_int(r, 4)) {
    case 0:
    case 1: return p * 256 + 128;
    case 2: return p * 256;
    default: return p * 256 + tu_int(r, 256);
    }
}

/* Draws triangle (X, Y) (fixed point) alone into a cleared mask. */
static void draw_fixed(rast_target *t, const int64_t X[3], const int64_t Y[3],
                       float cw, rast_stats *st)
{
    float clip[12];
    for (int i = 0; i < 3; i++)
        rt_clip_at(X[i], Y[i], t->width, t->height, 0.25f, cw, clip + 4 * i);
    rast_target_clear(t);
    assert_int_equal(rt_draw_tri(t, clip, NULL, RAST_CULL_NONE, st), RAST_OK);
}

static void test_known_triangles(void **state)
{
    (void)state;
    enum { W = 64, H = 32 };
    rast_target t = rt_make(W, H, 0, 0, 5);
    tu_rng r = { 1234 };
    long on_edge = 0, covered = 0, tested = 0;
    for (int n = 0; n < 3000; n++) {
        int64_t X[3], Y[3];
        int64_t cx = tu_int(&r, W + 8) - 4, cy = tu_int(&r, H + 8) - 4;
        int span = 1 + tu_int(&r, n % 3 == 0 ? 20 : 5);
        for (int i = 0; i < 3; i++) {
            X[i] = pick_coord(&r, cx - span, cx + span);
            Y[i] = pick_coord(&r, cy - span, cy + span);
        }
        float cw = (float)(1 << tu_int(&r, 4));
        rast_stats st;
        memset(&st, 0, sizeof st);
        draw_fixed(&t, X, Y, cw, &st);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int want = rt_covers(X, Y, CENTRE(x), CENTRE(y));
                int got = t.mask[y * t.mask_stride + x];
                if (got != (want ? 255 : 0))
                    fail_msg("triangle %d (%lld,%lld) (%lld,%lld) (%lld,%lld): pixel "
                             "(%d,%d) got %d want %d", n, (long long)X[0],
                             (long long)Y[0], (long long)X[1], (long long)Y[1],
                             (long long)X[2], (long long)Y[2], x, y, got, want);
                covered += want;
                for (int k = 0; k < 3; k++) {
                    int b = (k + 1) % 3;
                    int64_t e = (X[b] - X[k]) * (CENTRE(y) - Y[k]) -
                                (Y[b] - Y[k]) * (CENTRE(x) - X[k]);
                    int64_t lo = X[k] < X[b] ? X[k] : X[b], hi = X[k] ^ X[b] ^ lo;
                    int64_t ylo = Y[k] < Y[b] ? Y[k] : Y[b], yhi = Y[k] ^ Y[b] ^ ylo;
                    on_edge += e == 0 && CENTRE(x) >= lo && CENTRE(x) <= hi &&
                               CENTRE(y) >= ylo && CENTRE(y) <= yhi;
                }
            }
        for (int y = 0; y < H; y++)      /* padding untouched */
            for (int x = W; x < t.mask_stride; x++)
                assert_int_equal(t.mask[y * t.mask_stride + x], 0);
        tested++;
    }
    print_message("NOTE %ld triangles, %ld covered pixels, %ld centres on edges\n",
                  tested, covered, on_edge);
    assert_true(on_edge > 1000);    /* the rule is really exercised */
    assert_true(covered > 10000);
    rt_free(&t);
}

/* Pixel-exact counting pass: each triangle into a cleared mask, summed. */
static void count_pass(rast_target *t, const float *clip, const uint32_t *idx,
                       int ntri, rast_cull cull, int *count)
{
    memset(count, 0, sizeof(int) * (size_t)t->width * t->height);
    for (int i = 0; i < ntri; i++) {
        float c[12];
        for (int k = 0; k < 3; k++)
            memcpy(c + 4 * k, clip + 4 * idx[3 * i + k], 4 * sizeof(float));
        rast_target_clear(t);
        assert_int_equal(rt_draw_tri(t, c, NULL, cull, NULL), RAST_OK);
        for (int y = 0; y < t->height; y++)
            for (int x = 0; x < t->width; x++)
                count[y * t->width + x] += t->mask[y * t->mask_stride + x] == 255;
    }
}

static void test_full_screen_quad(void **state)
{
    (void)state;
    static const int sizes[][2] = { { 1, 1 }, { 37, 23 }, { 64, 64 }, { 640, 400 }, { 3, 200 } };
    static const float clip[16] = { -1, -1, 0, 1,  1, -1, 0, 1,  1, 1, 0, 1,  -1, 1, 0, 1 };
    static const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        rast_target t = rt_make(w, h, 0, 0, 0);
        int *count = calloc((size_t)w * h, sizeof(int));
        count_pass(&t, clip, idx, 2, RAST_CULL_NONE, count);
        for (int i = 0; i < w * h; i++)
            assert_int_equal(count[i], 1);
        /* And with the depth test and both triangles in one draw. */
        rast_target td = rt_make(w, h, 1, 0, 0);
        /* the quad is counter-clockwise: front */
        rast_mesh_desc d = { clip, 4, NULL, 0, idx, 2, RAST_CULL_BACK };
        rast_stats st;
        memset(&st, 0, sizeof st);
        assert_int_equal(rast_draw(&td, &d, &st), RAST_OK);
        assert_int_equal(st.pixels_written, (long)w * h);
        assert_int_equal(rt_count_mask(&td, NULL), (long)w * h);
        for (int i = 0; i < w * h; i++)
            assert_true(td.depth[i] == 0.5f);
        free(count);
        rt_free(&t);
        rt_free(&td);
    }
}

static void test_offscreen(void **state)
{
    (void)state;
    rast_target t = rt_make(64, 48, 1, 0, 0);
    /* Beside the target but inside the guard band, then far outside it. */
    static const float tris[][12] = {
        { 1.01f, -0.5f, 0, 1,  1.8f, -0.5f, 0, 1,  1.4f, 0.5f, 0, 1 },
        { -0.5f, 1.001f, 0, 1,  0.5f, 1.5f, 0, 1,  0, 3.0f, 0, 1 },
        { -2.0f, -0.5f, 0, 1,  -1.01f, -0.5f, 0, 1,  -1.5f, -3.0f, 0, 1 },
        { -0.5f, -5.0f, 0, 1,  0.5f, -5.0f, 0, 1,  0.0f, -1.02f, 0, 1 },
        { 1e4f, 1e4f, 0, 1,  2e4f, 1e4f, 0, 1,  1e4f, 2e4f, 0, 1 },
        { -0.5f, -0.5f, 1.5f, 1,  0.5f, -0.5f, 1.5f, 1,  0, 0.5f, 1.5f, 1 },   /* beyond far */
        { -0.5f, -0.5f, -1.5f, 1,  0.5f, -0.5f, -1.5f, 1,  0, 0.5f, -1.5f, 1 }, /* before near */
    };
    for (size_t i = 0; i < sizeof tris / sizeof tris[0]; i++) {
        rast_stats st;
        memset(&st, 0, sizeof st);
        rast_target_clear(&t);
        assert_int_equal(rt_draw_tri(&t, tris[i], NULL, RAST_CULL_NONE, &st), RAST_OK);
        assert_int_equal(rt_count_mask(&t, NULL), 0);
        assert_int_equal(st.tris_clipped_away, 1);
        assert_int_equal(st.tris_drawn, 0);
        for (int p = 0; p < 64 * 48; p++)
            assert_true(t.depth[p] == 1.0f);
    }
    rt_free(&t);
}

/* Checks count[] against the half-open fixed-point rectangle [L,R)x[T,B). */
static void check_rect(const int *count, int w, int h, int64_t L, int64_t R,
                       int64_t T, int64_t B, const char *what, int seed)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int in = CENTRE(x) >= L && CENTRE(x) < R && CENTRE(y) >= T && CENTRE(y) < B;
            if (count[y * w + x] != in)
                fail_msg("%s seed %d: pixel (%d,%d) covered %d times, want %d",
                         what, seed, x, y, count[y * w + x], in);
        }
}

static void test_watertight_grid(void **state)
{
    (void)state;
    enum { W = 64, H = 64, MAXN = 12 };
    rast_target t = rt_make(W, H, 0, 0, 0);
    int *count = calloc(W * H, sizeof(int));
    static float clip[(MAXN + 1) * (MAXN + 1) * 4];
    static uint32_t idx[MAXN * MAXN * 6];
    for (int seed = 0; seed < 24; seed++) {
        tu_rng r = { 100 + (uint64_t)seed };
        int n = 2 + tu_int(&r, MAXN - 1);
        /* Square with sub-pixel offsets; cells at least 2 px. Even seeds
         * put the corners on pixel centres (edges through centres). */
        /* pixel, then subpixel: drawn in order */
        int64_t L = 256 * (2 + tu_int(&r, 6));
        L += seed % 2 ? tu_int(&r, 256) : 128;
        int64_t T = 256 * (2 + tu_int(&r, 6));
        T += seed % 2 ? tu_int(&r, 256) : 128;
        int64_t cell = 256 * (2 + tu_int(&r, (40 / n)));
        cell += seed % 2 ? tu_int(&r, 256) : 0;
        int64_t R = L + n * cell, B = T + n * cell;
        float cw = (float)(1 << tu_int(&r, 3));
        for (int j = 0; j <= n; j++)
            for (int i = 0; i <= n; i++) {
                int64_t X = L + i * cell, Y = T + j * cell;
                if (i > 0 && i < n && j > 0 && j < n) {
                    X += tu_int(&r, (int)cell / 2) - cell / 4;  /* jitter < cell/4 */
                    Y += tu_int(&r, (int)cell / 2) - cell / 4;
                }
                rt_clip_at(X, Y, W, H, 0.0f, cw, clip + 4 * (j * (n + 1) + i));
            }
        int nt = 0;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1;
                uint32_t c = a + (uint32_t)(n + 1), d = c + 1;
                uint32_t q[6];
                if (tu_int(&r, 2)) {
                    uint32_t q0[6] = { a, b, d, a, d, c };
                    memcpy(q, q0, sizeof q);
                } else {
                    uint32_t q0[6] = { a, b, c, b, d, c };
                    memcpy(q, q0, sizeof q);
                }
                for (int k = 0; k < 2; k++) {     /* random winding */
                    uint32_t *tri = q + 3 * k;
                    if (tu_int(&r, 2)) { uint32_t s = tri[1]; tri[1] = tri[2]; tri[2] = s; }
                    memcpy(idx + 3 * nt++, tri, 3 * sizeof(uint32_t));
                }
            }
        count_pass(&t, clip, idx, nt, RAST_CULL_NONE, count);
        check_rect(count, W, H, L, R, T, B, "grid", seed);
    }
    free(count);
    rt_free(&t);
}

static void test_watertight_fan(void **state)
{
    (void)state;
    enum { W = 64, H = 64, MAXP = 80 };
    rast_target t = rt_make(W, H, 0, 0, 0);
    int *count = calloc(W * H, sizeof(int));
    static float clip[(MAXP + 1) * 4];
    static uint32_t idx[MAXP * 3];
    for (int seed = 0; seed < 24; seed++) {
        tu_rng r = { 900 + (uint64_t)seed };
        /* pixel, then subpixel: drawn in order */
        int64_t L = 256 * (1 + tu_int(&r, 8));
        L += tu_int(&r, 256);
        int64_t T = 256 * (1 + tu_int(&r, 8));
        T += seed % 3 ? tu_int(&r, 256) : 128;
        int64_t R = L + 256 * (10 + tu_int(&r, 40));
        R += tu_int(&r, 256);
        int64_t B = T + 256 * (10 + tu_int(&r, 40));
        B += tu_int(&r, 256);
        /* Perimeter points, clockwise on the screen from (L, T). */
        int64_t PX[MAXP], PY[MAXP];
        int np = 0;
        for (int side = 0; side < 4; side++) {
            int k = 1 + tu_int(&r, MAXP / 4 - 1);
            int64_t pos[MAXP / 4];
            int64_t len = (side % 2 == 0) ? R - L : B - T;
            pos[0] = 0;
            for (int i = 1; i < k; i++) pos[i] = 1 + tu_int(&r, (int)len - 1);
            for (int i = 1; i < k; i++)          /* insertion sort */
                for (int j = i; j > 0 && pos[j] < pos[j - 1]; j--) {
                    int64_t s = pos[j]; pos[j] = pos[j - 1]; pos[j - 1] = s;
                }
            for (int i = 0; i < k; i++, np++) {
                switch (side) {
                case 0: PX[np] = L + pos[i]; PY[np] = T; break;
                case 1: PX[np] = R; PY[np] = T + pos[i]; break;
                case 2: PX[np] = R - pos[i]; PY[np] = B; break;
                default: PX[np] = L; PY[np] = B - pos[i]; break;
                }
            }
        }
        int64_t cx = L + 1 + tu_int(&r, (int)(R - L - 1));
        int64_t cy = T + 1 + tu_int(&r, (int)(B - T - 1));
        float cw = (float)(1 << tu_int(&r, 3));
        rt_clip_at(cx, cy, W, H, 0.0f, cw, clip);
        for (int i = 0; i < np; i++)
            rt_clip_at(PX[i], PY[i], W, H, 0.0f, cw, clip + 4 * (i + 1));
        int nt = 0;
        for (int i = 0; i < np; i++) {
            uint32_t a = (uint32_t)(i + 1), b = (uint32_t)((i + 1) % np + 1);
            if (PX[a - 1] == PX[b - 1] && PY[a - 1] == PY[b - 1])
                continue;                        /* duplicate perimeter point */
            idx[3 * nt] = 0; idx[3 * nt + 1] = a; idx[3 * nt + 2] = b;
            nt++;
        }
        count_pass(&t, clip, idx, nt, RAST_CULL_NONE, count);
        check_rect(count, W, H, L, R, T, B, "fan", seed);
    }
    free(count);
    rt_free(&t);
}

/* Icosphere: 12 vertices subdivided `level` times, unit radius. */
enum { ICO_MAXV = 642, ICO_MAXT = 1280 };
static int ico_mid(double (*v)[3], int *nv, int a, int b, int (*cache)[3], int *nc)
{
    int lo = a < b ? a : b, hi = a ^ b ^ lo;
    for (int i = 0; i < *nc; i++)
        if (cache[i][0] == lo && cache[i][1] == hi) return cache[i][2];
    double m[3], l = 0;
    for (int k = 0; k < 3; k++) { m[k] = v[a][k] + v[b][k]; l += m[k] * m[k]; }
    l = sqrt(l);
    for (int k = 0; k < 3; k++) v[*nv][k] = m[k] / l;
    cache[*nc][0] = lo; cache[*nc][1] = hi; cache[*nc][2] = *nv;
    (*nc)++;
    return (*nv)++;
}

static int icosphere(int level, double (*v)[3], int *nv, uint32_t *tri)
{
    const double p = (1.0 + sqrt(5.0)) / 2.0;
    const double b[12][3] = { { -1, p, 0 }, { 1, p, 0 }, { -1, -p, 0 }, { 1, -p, 0 },
                              { 0, -1, p }, { 0, 1, p }, { 0, -1, -p }, { 0, 1, -p },
                              { p, 0, -1 }, { p, 0, 1 }, { -p, 0, -1 }, { -p, 0, 1 } };
    static const int f[20][3] = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 },
        { 0, 10, 11 }, { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
        { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 }, { 4, 9, 5 },
        { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
    *nv = 12;
    for (int i = 0; i < 12; i++) {
        double l = sqrt(b[i][0] * b[i][0] + b[i][1] * b[i][1] + b[i][2] * b[i][2]);
        for (int k = 0; k < 3; k++) v[i][k] = b[i][k] / l;
    }
    int nt = 20;
    for (int i = 0; i < 20; i++)
        for (int k = 0; k < 3; k++) tri[3 * i + k] = (uint32_t)f[i][k];
    static int cache[ICO_MAXT * 3][3];
    static uint32_t tmp[ICO_MAXT * 3];
    for (int l = 0; l < level; l++) {
        int nc = 0, n2 = 0;
        for (int i = 0; i < nt; i++) {
            int a = (int)tri[3 * i], bb = (int)tri[3 * i + 1], c = (int)tri[3 * i + 2];
            int ab = ico_mid(v, nv, a, bb, cache, &nc);
            int bc = ico_mid(v, nv, bb, c, cache, &nc);
            int ca = ico_mid(v, nv, c, a, cache, &nc);
            const int q[12] = { a, ab, ca, bb, bc, ab, c, ca, bc, ab, bc, ca };
            for (int k = 0; k < 12; k++) tmp[3 * n2 + k] = (uint32_t)q[k];
            n2 += 4;
        }
        nt = n2;
        memcpy(tri, tmp, sizeof(uint32_t) * 3 * (size_t)nt);
    }
    return nt;
}

static void test_closed_mesh_once(void **state)
{
    (void)state;
    enum { W = 96, H = 64 };
    static double v[ICO_MAXV][3];
    static uint32_t tri[ICO_MAXT * 3];
    static float pos[ICO_MAXV * 3], clip[ICO_MAXV * 4];
    int nv;
    int nt = icosphere(3, v, &nv, tri);
    assert_int_equal(nv, 642);
    assert_int_equal(nt, 1280);
    rast_target t = rt_make(W, H, 0, 0, 0);
    int *cf = calloc(W * H, sizeof(int)), *cb = calloc(W * H, sizeof(int));
    int *cn = calloc(W * H, sizeof(int));
    float proj[16];
    rt_perspective(1.0, (double)W / H, 0.1, 100.0, proj);
    /* Centred, off-centre, and partly outside the view. */
    static const double place[][4] = { { 0, 0, -4, 1 }, { 0.7, -0.4, -3, 0.8 },
                                       { 1.9, 1.0, -3, 1.2 } };
    tu_rng r = { 77 };
    for (size_t s = 0; s < sizeof place / sizeof place[0]; s++) {
        double ang = tu_range(&r, 0, 6.283f);
        for (int i = 0; i < nv; i++) {
            double x = v[i][0], z = v[i][2];
            pos[3 * i] = (float)((cos(ang) * x + sin(ang) * z) * place[s][3] + place[s][0]);
            pos[3 * i + 1] = (float)(v[i][1] * place[s][3] + place[s][1]);
            pos[3 * i + 2] = (float)((-sin(ang) * x + cos(ang) * z) * place[s][3] + place[s][2]);
        }
        rast_transform_points(proj, pos, nv, clip);
        count_pass(&t, clip, tri, nt, RAST_CULL_BACK, cf);
        count_pass(&t, clip, tri, nt, RAST_CULL_FRONT, cb);
        count_pass(&t, clip, tri, nt, RAST_CULL_NONE, cn);
        long inside = 0;
        for (int i = 0; i < W * H; i++) {
            if (cf[i] > 1 || cb[i] > 1 || cf[i] != cb[i] || cn[i] != cf[i] + cb[i])
                fail_msg("placement %zu pixel (%d,%d): front %d back %d all %d", s,
                         i % W, i / W, cf[i], cb[i], cn[i]);
            inside += cf[i];
        }
        /* The silhouette is roughly the projected disc: radius r/d*f px. */
        double d = sqrt(place[s][0] * place[s][0] + place[s][1] * place[s][1] +
                        place[s][2] * place[s][2]);
        double rad = place[s][3] / sqrt(d * d - place[s][3] * place[s][3]) *
                     (H / 2.0) / tan(0.5);
        print_message("NOTE placement %zu: %ld pixels covered once (disc ~%.0f)\n",
                      s, inside, 3.14159 * rad * rad);
        assert_true(inside > 100);
        if (s == 0)
            assert_true(fabs(inside - 3.14159 * rad * rad) < 0.1 * 3.14159 * rad * rad);
    }
    free(cf);
    free(cb);
    free(cn);
    rt_free(&t);
}

static void test_tiny_triangles(void **state)
{
    (void)state;
    enum { W = 32, H = 32 };
    rast_target t = rt_make(W, H, 0, 0, 0);
    tu_rng r = { 4242 };
    int hits = 0, misses = 0;
    for (int n = 0; n < 4000; n++) {
        int64_t ox = 256 * (2 + tu_int(&r, W - 4));   /* drawn in order */
        ox += tu_int(&r, 256);
        int64_t oy = 256 * (2 + tu_int(&r, H - 4));
        oy += tu_int(&r, 256);
        int64_t ccx = CENTRE(ox / 256), ccy = CENTRE(oy / 256);
        if (n % 4 == 0) {                 /* one vertex on a pixel centre */
            ox = ccx - tu_int(&r, 200);
            oy = ccy - tu_int(&r, 200);
        }
        int64_t X[3], Y[3];
        for (int i = 0; i < 3; i++) {     /* extent < 1 px: at most one centre */
            X[i] = ox + tu_int(&r, 200);
            Y[i] = oy + tu_int(&r, 200);
        }
        if (n % 4 == 0) { X[0] = ccx; Y[0] = ccy; }
        rast_stats st;
        memset(&st, 0, sizeof st);
        draw_fixed(&t, X, Y, 1.0f, &st);
        long want = 0;
        int wx = -1, wy = -1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                if (rt_covers(X, Y, CENTRE(x), CENTRE(y))) { want++; wx = x; wy = y; }
        assert_true(want <= 1);
        assert_int_equal(rt_count_mask(&t, NULL), want);
        assert_int_equal(st.pixels_written, want);
        if (want) {
            assert_int_equal(t.mask[wy * t.mask_stride + wx], 255);
            hits++;
        } else {
            misses++;
        }
    }
    print_message("NOTE tiny triangles: %d cover one pixel, %d none\n", hits, misses);
    assert_true(hits > 100 && misses > 100);
    rt_free(&t);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_known_triangles),
        cmocka_unit_test(test_full_screen_quad),
        cmocka_unit_test(test_offscreen),
        cmocka_unit_test(test_watertight_grid),
        cmocka_unit_test(test_watertight_fan),
        cmocka_unit_test(test_closed_mesh_once),
        cmocka_unit_test(test_tiny_triangles))
