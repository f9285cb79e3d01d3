/* test_raster_depth.c - depth and attributes: window depth equals the
 * analytic screen-space plane at pixel centres within a few ulp; the
 * nearer of two triangles wins whatever the draw order (LESS); without a
 * depth plane the later triangle wins; attributes are perspective-correct
 * against a double ray/plane computation for a tilted textured quad (and
 * the test shows affine interpolation would fail it). */
#include "support/testutil.h"
#include <cmocka.h>

#include "test_raster_util.h"

#define CENTRE(i) ((int64_t)(i) * 256 + 128)

/* Plane through (X_i, Y_i, f_i) (pixel units) evaluated at (x, y), by
 * barycentric weights (a different formula from the rasterizer's). */
static double bary_eval(const double X[3], const double Y[3], const double f[3],
                        double x, double y)
{
    double a = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    double l1 = ((x - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (y - Y[0])) / a;
    double l2 = ((X[1] - X[0]) * (y - Y[0]) - (x - X[0]) * (Y[1] - Y[0])) / a;
    return f[0] * (1.0 - l1 - l2) + f[1] * l1 + f[2] * l2;
}

static void test_depth_plane_exact(void **state)
{
    (void)state;
    enum { W = 128, H = 64 };
    rast_target t = rt_make(W, H, 1, 0, 2);
    tu_rng r = { 555 };
    double worst = 0, worst_shaped = 0;
    long checked = 0;
    for (int n = 0; n < 200; n++) {
        int64_t X[3], Y[3];
        double Xd[3], Yd[3], zw[3];
        float clip[12];
        int big = n % 4 == 0;          /* vertices far outside the target */
        for (int i = 0; i < 3; i++) {
            /* pixel, then subpixel: drawn in order */
            X[i] = big ? 256 * (tu_int(&r, 6 * W) - 2 * W) : 256 * tu_int(&r, W);
            X[i] += tu_int(&r, 256);
            Y[i] = big ? 256 * (tu_int(&r, 6 * H) - 2 * H) : 256 * tu_int(&r, H);
            Y[i] += tu_int(&r, 256);
            float cw = (float)(1 << tu_int(&r, 3));
            float z = tu_range(&r, -0.99f, 0.99f);
            rt_clip_at(X[i], Y[i], W, H, z, cw, clip + 4 * i);
            Xd[i] = X[i] / 256.0;
            Yd[i] = Y[i] / 256.0;
            zw[i] = (double)clip[4 * i + 2] / clip[4 * i + 3] * 0.5 + 0.5;
        }
        rast_target_clear(&t);
        rt_draw_tri(&t, clip, NULL, RAST_CULL_NONE, NULL);
        /* The plane is evaluated from the corner of the pixel bounding box
         * (clamped to the target), so the float error scales with the
         * largest |plane| over that box, M (docs/raster.md, "depth"). For
         * a well-shaped triangle M <= 1. */
        int64_t mnx = X[0], mxx = X[0], mny = Y[0], mxy = Y[0];
        for (int i = 1; i < 3; i++) {
            mnx = X[i] < mnx ? X[i] : mnx; mxx = X[i] > mxx ? X[i] : mxx;
            mny = Y[i] < mny ? Y[i] : mny; mxy = Y[i] > mxy ? Y[i] : mxy;
        }
        double bx0 = fmax(0, ceil((mnx - 128) / 256.0)), bx1 = fmin(W - 1, floor((mxx - 128) / 256.0));
        double by0 = fmax(0, ceil((mny - 128) / 256.0)), by1 = fmin(H - 1, floor((mxy - 128) / 256.0));
        double M = 0.5;
        for (int k = 0; k < 4; k++) {
            double v = bary_eval(Xd, Yd, zw, (k & 1 ? bx1 : bx0) + 0.5, (k & 2 ? by1 : by0) + 0.5);
            M = fmax(M, fabs(v));
        }
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                if (t.mask[y * t.mask_stride + x] != 255) continue;
                double want = bary_eval(Xd, Yd, zw, x + 0.5, y + 0.5);
                double got = t.depth[y * t.depth_stride + x];
                /* In ulps of M's scale: 2^-24 * M (one ulp of [0.5,1) for M <= 1). */
                double err = fabs(got - want) / (ldexp(1.0, -24) * M);
                if (err > worst) worst = err;
                if (M <= 1.0 && err > worst_shaped) worst_shaped = err;
                if (err > 8.0)
                    fail_msg("triangle %d pixel (%d,%d): depth %.9g want %.9g (%.1f ulp, M %.3g)",
                             n, x, y, got, want, err, M);
                checked++;
            }
    }
    print_message("NOTE depth: %ld pixels, worst error %.2f ulp (scaled by M), %.2f "
                  "ulp when M <= 1\n", checked, worst, worst_shaped);
    assert_true(worst_shaped <= 4.0);
    assert_true(checked > 20000);
    rt_free(&t);
}

/* Two tilted triangles crossing each other; each carries its id. */
static void test_depth_order(void **state)
{
    (void)state;
    enum { W = 64, H = 64 };
    tu_rng r = { 99 };
    rast_target a = rt_make(W, H, 1, 1, 0), b = rt_make(W, H, 1, 1, 0);
    rast_target ab = rt_make(W, H, 1, 1, 0), ba = rt_make(W, H, 1, 1, 0);
    long both = 0;
    for (int n = 0; n < 40; n++) {
        float c0[12], c1[12];
        for (int i = 0; i < 3; i++) {
            float w0 = tu_range(&r, 0.5f, 3), w1 = tu_range(&r, 0.5f, 3);
            c0[4 * i + 0] = tu_range(&r, -1.2f, 1.2f) * w0;
            c0[4 * i + 1] = tu_range(&r, -1.2f, 1.2f) * w0;
            c0[4 * i + 2] = tu_range(&r, -0.9f, 0.9f) * w0;
            c0[4 * i + 3] = w0;
            c1[4 * i + 0] = tu_range(&r, -1.2f, 1.2f) * w1;
            c1[4 * i + 1] = tu_range(&r, -1.2f, 1.2f) * w1;
            c1[4 * i + 2] = tu_range(&r, -0.9f, 0.9f) * w1;
            c1[4 * i + 3] = w1;
        }
        const float id0[3] = { 1, 1, 1 }, id1[3] = { 2, 2, 2 };
        rast_target_clear(&a);
        rast_target_clear(&b);
        rast_target_clear(&ab);
        rast_target_clear(&ba);
        rt_draw_tri(&a, c0, id0, RAST_CULL_NONE, NULL);
        rt_draw_tri(&b, c1, id1, RAST_CULL_NONE, NULL);
        rt_draw_tri(&ab, c0, id0, RAST_CULL_NONE, NULL);
        rt_draw_tri(&ab, c1, id1, RAST_CULL_NONE, NULL);
        rt_draw_tri(&ba, c1, id1, RAST_CULL_NONE, NULL);
        rt_draw_tri(&ba, c0, id0, RAST_CULL_NONE, NULL);
        for (int i = 0; i < W * H; i++) {
            float da = a.depth[i], db = b.depth[i];
            float dmin = da < db ? da : db;
            assert_true(ab.depth[i] == dmin && ba.depth[i] == dmin);
            assert_int_equal(ab.mask[i], a.mask[i] | b.mask[i]);
            assert_int_equal(ba.mask[i], ab.mask[i]);
            if (a.mask[i] && b.mask[i]) {
                both++;
                float want = da < db ? 1.0f : db < da ? 2.0f : -1.0f;
                if (want > 0) {
                    assert_true(ab.attr[i] == want);
                    assert_true(ba.attr[i] == want);
                } else {            /* exact tie: LESS keeps the first */
                    assert_true(ab.attr[i] == 1.0f && ba.attr[i] == 2.0f);
                }
            }
        }
    }
    assert_true(both > 1000);
    rt_free(&a); rt_free(&b); rt_free(&ab); rt_free(&ba);
}

static void test_no_depth_later_wins(void **state)
{
    (void)state;
    rast_target t = rt_make(16, 16, 0, 1, 0);
    const float near_tri[12] = { -1, -1, -0.9f, 1,   3, -1, -0.9f, 1,   -1, 3, -0.9f, 1 };
    const float far_tri[12] = { -1, -1, 0.9f, 1,   3, -1, 0.9f, 1,   -1, 3, 0.9f, 1 };
    const float one[3] = { 1, 1, 1 }, two[3] = { 2, 2, 2 };
    rast_stats st;
    memset(&st, 0, sizeof st);
    rt_draw_tri(&t, near_tri, one, RAST_CULL_NONE, &st);
    rt_draw_tri(&t, far_tri, two, RAST_CULL_NONE, &st);
    for (int i = 0; i < 16 * 16; i++)
        assert_true(t.attr[i] == 2.0f);
    assert_int_equal(st.pixels_written, 2 * 16 * 16);
    /* With depth the near one stays and the far one is rejected. */
    rast_target d = rt_make(16, 16, 1, 1, 0);
    memset(&st, 0, sizeof st);
    rt_draw_tri(&d, near_tri, one, RAST_CULL_NONE, &st);
    rt_draw_tri(&d, far_tri, two, RAST_CULL_NONE, &st);
    const float z_near = (float)((double)-0.9f * 0.5 + 0.5);
    for (int i = 0; i < 16 * 16; i++)
        assert_true(d.attr[i] == 1.0f && d.depth[i] == z_near);
    assert_int_equal(st.pixels_written, 16 * 16);
    /* Depth exactly 1 (the far plane) never passes LESS against the clear. */
    const float at_far[12] = { -1, -1, 1, 1,   3, -1, 1, 1,   -1, 3, 1, 1 };
    rast_target_clear(&d);
    memset(&st, 0, sizeof st);
    rt_draw_tri(&d, at_far, one, RAST_CULL_NONE, &st);
    assert_int_equal(st.pixels_written, 0);
    assert_int_equal(st.tris_drawn, 1);
    rt_free(&t);
    rt_free(&d);
}

static void test_perspective_attributes(void **state)
{
    (void)state;
    enum { W = 128, H = 96 };
    float proj[16];
    rt_perspective(1.0, (double)W / H, 0.1, 100.0, proj);
    /* A quad tilted away from the camera: near edge at z = -1.2, far edge
     * at z = -6; uv = (0,0) (1,0) (1,1) (0,1). */
    const float pos[12] = { -0.8f, -0.6f, -1.2f,   0.9f, -0.6f, -1.2f,
                             0.9f, 0.7f, -6.0f,   -0.8f, 0.7f, -6.0f };
    const float uv[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    float clip[16];
    rast_transform_points(proj, pos, 4, clip);
    rast_target t = rt_make(W, H, 1, 2, 3);
    rast_mesh_desc d = { clip, 4, uv, 2, idx, 2, RAST_CULL_NONE };
    assert_int_equal(rast_draw(&t, &d, NULL), RAST_OK);

    /* Analytic: ray through the pixel centre meets the quad's plane at
     * P = O + s*U + t*V (O = pos0, U = pos1 - pos0, V = pos3 - pos0), and
     * (u, v) = (s, t) because the quad is a parallelogram. */
    double O[3], U[3], V[3];
    for (int k = 0; k < 3; k++) {
        O[k] = pos[k];
        U[k] = (double)pos[3 + k] - pos[k];
        V[k] = (double)pos[9 + k] - pos[k];
    }
    double worst = 0, worst_affine = 0;
    long n = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            if (t.mask[y * t.mask_stride + x] != 255) continue;
            double nx = (x + 0.5) / W * 2 - 1, ny = 1 - (y + 0.5) / H * 2;
            double D[3] = { nx / proj[0], ny / proj[5], -1 };
            /* Solve O + s U + t V = l D (3x3, Cramer). */
            double M[3][3] = { { U[0], V[0], -D[0] }, { U[1], V[1], -D[1] },
                               { U[2], V[2], -D[2] } };
            double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                         M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                         M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
            double b[3] = { -O[0], -O[1], -O[2] };
            double ds = b[0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                        M[0][1] * (b[1] * M[2][2] - M[1][2] * b[2]) +
                        M[0][2] * (b[1] * M[2][1] - M[1][1] * b[2]);
            double dt = M[0][0] * (b[1] * M[2][2] - M[1][2] * b[2]) -
                        b[0] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                        M[0][2] * (M[1][0] * b[2] - b[1] * M[2][0]);
            double s = ds / det, tt = dt / det;
            const float *a = t.attr + (size_t)y * t.attr_stride + 2 * x;
            double err = fmax(fabs(a[0] - s), fabs(a[1] - tt));
            if (err > worst) worst = err;
            /* What plain screen-space interpolation would give. */
            double sy0 = (0.5 - clip[1] / clip[3] * 0.5) * H;
            double sy1 = (0.5 - clip[9] / clip[11] * 0.5) * H;
            double affine_v = ((y + 0.5) - sy0) / (sy1 - sy0);
            if (fabs(affine_v - tt) > worst_affine) worst_affine = fabs(affine_v - tt);
            n++;
        }
    print_message("NOTE attributes: %ld pixels, worst error %.2e (affine would be %.2e)\n",
                  n, worst, worst_affine);
    assert_true(n > 2000);
    assert_true(worst < 2e-4);
    assert_true(worst_affine > 0.05);   /* the test can tell the difference */
    rt_free(&t);
}

/* Attributes at a pixel centre that is a vertex equal the vertex value. */
static void test_attribute_at_vertex(void **state)
{
    (void)state;
    enum { W = 32, H = 32 };
    rast_target t = rt_make(W, H, 1, 3, 0);
    tu_rng r = { 8 };
    for (int n = 0; n < 100; n++) {
        int64_t X[3], Y[3];
        float clip[12], attr[9];
        X[0] = CENTRE(5 + tu_int(&r, 20));
        Y[0] = CENTRE(5 + tu_int(&r, 20));
        /* Vertex 0 must be covered: make it the top-left corner region. */
        X[1] = X[0] + 256 * (3 + tu_int(&r, 5));
        Y[1] = Y[0] + tu_int(&r, 256);
        X[2] = X[0] - tu_int(&r, 256);
        Y[2] = Y[0] + 256 * (3 + tu_int(&r, 5));
        for (int i = 0; i < 3; i++) {
            float cw = (float)(1 << tu_int(&r, 4));
            rt_clip_at(X[i], Y[i], W, H, 0.0f, cw, clip + 4 * i);
            for (int k = 0; k < 3; k++) attr[3 * i + k] = tu_range(&r, -5, 5);
        }
        if (!rt_covers(X, Y, X[0], Y[0])) continue;
        rast_target_clear(&t);
        rt_draw_tri(&t, clip, attr, RAST_CULL_NONE, NULL);
        int px = (int)(X[0] / 256), py = (int)(Y[0] / 256);
        const float *a = t.attr + (size_t)py * t.attr_stride + 3 * px;
        assert_int_equal(t.mask[py * t.mask_stride + px], 255);
        for (int k = 0; k < 3; k++)
            assert_true(fabsf(a[k] - attr[k]) < 2e-5f);
    }
    rt_free(&t);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_depth_plane_exact),
        cmocka_unit_test(test_depth_order),
        cmocka_unit_test(test_no_depth_later_wins),
        cmocka_unit_test(test_perspective_attributes),
        cmocka_unit_test(test_attribute_at_vertex))
