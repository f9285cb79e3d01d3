/* test_raster_clip.c - homogeneous clipping: triangles crossing the near
 * plane or reaching behind the eye (w < 0) against a double-precision ray
 * test per pixel; a floor grid through the near plane and a grid far past
 * the guard band stay watertight; huge triangles (1e6*w) equal a full-
 * screen fill; w == 0 vertices never reach the divide.
 *
 * Tolerance: pixels whose centre lies within EDGE_TOL of the analytic
 * visible polygon may differ. Snapping to 1/256 px moves a vertex by up to
 * sqrt(2)/512 = 0.0028 px and an edge by at most as much, so a 1e-3 px
 * band cannot be promised; EDGE_TOL is that bound plus float slack. The
 * number of such pixels is printed and must stay small. */
#include "support/testutil.h"
#include <cmocka.h>

#include "test_raster_util.h"
#include "../src/raster/raster_internal.h"

#define EDGE_TOL 0.0035
enum { W = 96, H = 64 };

typedef struct cam {
    float proj[16];
    double n_eff, f_eff;       /* near/far of the float matrix, eye units */
} cam;

static void cam_init(cam *c)
{
    rt_perspective(1.0, (double)W / H, 0.5, 50.0, c->proj);
    double m10 = c->proj[10], m14 = c->proj[14];
    c->n_eff = m14 / (m10 - 1.0);   /* z_clip + w = 0 at z_eye = -n_eff */
    c->f_eff = m14 / (m10 + 1.0);
    if (c->n_eff < 0) c->n_eff = -c->n_eff;
    if (c->f_eff < 0) c->f_eff = -c->f_eff;
}

/* Double ray test: does the ray through pixel centre (px, py) hit the
 * eye-space triangle e between the near and far planes? */
static int ray_hits(const cam *c, const double e[3][3], double px, double py)
{
    double nx = px / W * 2.0 - 1.0, ny = 1.0 - py / H * 2.0;
    double d[3] = { nx / c->proj[0], ny / c->proj[5], -1.0 };
    double e1[3], e2[3], p[3], q[3];
    for (int k = 0; k < 3; k++) { e1[k] = e[1][k] - e[0][k]; e2[k] = e[2][k] - e[0][k]; }
    p[0] = d[1] * e2[2] - d[2] * e2[1];
    p[1] = d[2] * e2[0] - d[0] * e2[2];
    p[2] = d[0] * e2[1] - d[1] * e2[0];
    double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (fabs(det) < 1e-300) return 0;
    double s[3] = { -e[0][0], -e[0][1], -e[0][2] };     /* origin - v0 */
    double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    q[0] = s[1] * e1[2] - s[2] * e1[1];
    q[1] = s[2] * e1[0] - s[0] * e1[2];
    q[2] = s[0] * e1[1] - s[1] * e1[0];
    double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    return u >= 0 && v >= 0 && u + v <= 1 && t >= c->n_eff && t <= c->f_eff;
}

/* Distance (px) from (px, py) to the boundary of the visible part: the
 * triangle cut at z = -n_eff in eye space, projected. */
static double edge_dist(const cam *c, const double e[3][3], double px, double py)
{
    double poly[8][3];
    int n = 0;
    for (int i = 0; i < 3; i++) {
        const double *a = e[i], *b = e[(i + 1) % 3];
        double da = -a[2] - c->n_eff, db = -b[2] - c->n_eff;
        if (da >= 0) { memcpy(poly[n], a, sizeof poly[n]); n++; }
        if ((da >= 0) != (db >= 0)) {
            double t = da / (da - db);
            for (int k = 0; k < 3; k++) poly[n][k] = a[k] + t * (b[k] - a[k]);
            n++;
        }
    }
    double sx[8], sy[8];
    for (int i = 0; i < n; i++) {
        double w = -poly[i][2];
        sx[i] = (c->proj[0] * poly[i][0] / w * 0.5 + 0.5) * W;
        sy[i] = (0.5 - c->proj[5] * poly[i][1] / w * 0.5) * H;
    }
    double best = 1e300;
    for (int i = 0; i < n; i++) {
        double ax = sx[i], ay = sy[i], bx = sx[(i + 1) % n], by = sy[(i + 1) % n];
        double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
        double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double ex = ax + t * dx - px, ey = ay + t * dy - py;
        double dist = sqrt(ex * ex + ey * ey);
        if (dist < best) best = dist;
    }
    return best;
}

/* Draws the eye-space triangle and compares every pixel with the ray test.
 * Returns the number of pixels covered; adds near-edge differences. */
static long check_eye_tri(const cam *c, rast_target *t, const double e[3][3],
                          long *near_diff, double *max_dist, int tag)
{
    float pos[9], clip[12];
    double ef[3][3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            pos[3 * i + k] = (float)e[i][k];
            ef[i][k] = pos[3 * i + k];
        }
    rast_transform_points(c->proj, pos, 3, clip);
    rast_target_clear(t);
    assert_int_equal(rt_draw_tri(t, clip, NULL, RAST_CULL_NONE, NULL), RAST_OK);
    long covered = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int got = t->mask[y * t->mask_stride + x] == 255;
            int want = ray_hits(c, ef, x + 0.5, y + 0.5);
            covered += got;
            if (got == want) continue;
            double dist = edge_dist(c, ef, x + 0.5, y + 0.5);
            if (dist >= EDGE_TOL)
                fail_msg("case %d: pixel (%d,%d) got %d want %d, %.6f px from an edge",
                         tag, x, y, got, want, dist);
            (*near_diff)++;
            if (dist > *max_dist) *max_dist = dist;
        }
    for (int i = 0; i < W * H; i++)
        if (t->depth && !(t->depth[i] >= 0.0f && t->depth[i] <= 1.0f))
            fail_msg("case %d: depth %g at %d", tag, (double)t->depth[i], i);
    return covered;
}

/* Random eye-space point at eye depth -z in [zlo, zhi], roughly in view. */
static void rand_eye(tu_rng *r, double zlo, double zhi, double spread, double p[3])
{
    double z = tu_range(r, (float)zlo, (float)zhi);
    double s = fabs(z) < 0.5 ? 0.5 : fabs(z);
    p[0] = tu_range(r, -1, 1) * spread * s;
    p[1] = tu_range(r, -1, 1) * spread * s * 0.7;
    p[2] = -z;
}

/* 300 triangles of seed: 1 or 2 vertices (alternately) in front of z in
 * [zlo, zhi] with spread, the others at 0.6..8 (spread 0.6), each checked
 * with check_eye_tri (index n0 + n). Pixels covered; near-edge
 * differences and the farthest distance added up. */
static long clip_sweep(cam *c, rast_target *t, uint64_t seed, double zlo, double zhi,
                       double spread, int n0, long *near_diff, double *max_dist)
{
    tu_rng r = { seed };
    long covered = 0;
    for (int n = 0; n < 300; n++) {
        double e[3][3];
        int first = 1 + n % 2;
        for (int i = 0; i < 3; i++) {
            if (i < first) rand_eye(&r, zlo, zhi, spread, e[i]);
            else rand_eye(&r, 0.6, 8.0, 0.6, e[i]);
        }
        covered += check_eye_tri(c, t, e, near_diff, max_dist, n0 + n);
    }
    return covered;
}

/* clip_sweep(seed, zlo, zhi, spread, n0) covers more than 20000 pixels
 * and fewer than 1 in 1000 of them, each near an edge, differ. */
static void sweep_checked(cam *c, rast_target *t, const char *what, uint64_t seed, double zlo,
                          double zhi, double spread, int n0)
{
    long near_diff = 0;
    double max_dist = 0;
    long covered = clip_sweep(c, t, seed, zlo, zhi, spread, n0, &near_diff, &max_dist);
    print_message("NOTE %s: %ld pixels covered, %ld within %.4f px of an edge differ "
                  "(farthest %.5f px)\n", what, covered, near_diff, EDGE_TOL, max_dist);
    assert_true(covered > 20000);
    assert_true(near_diff * 1000 < covered);
}

static void test_near_plane_crossing(void **state)
{
    (void)state;
    cam c;
    cam_init(&c);
    rast_target t = rt_make(W, H, 1, 0, 0);
    /* 1 or 2 vertices before the near plane */
    sweep_checked(&c, &t, "near plane", 31337, 0.01, 0.45, 0.6, 0);
    rt_free(&t);
}

static void test_vertex_behind_camera(void **state)
{
    (void)state;
    cam c;
    cam_init(&c);
    rast_target t = rt_make(W, H, 1, 0, 0);
    /* w < 0 for 1 or 2 vertices */
    sweep_checked(&c, &t, "behind", 4711, -6.0, -0.05, 0.8, 1000);

    /* All three behind the eye: nothing, counted as clipped away. */
    const double e[3][3] = { { -1, -1, 2 }, { 1, -1, 2 }, { 0, 1, 3 } };
    float pos[9], clip[12];
    for (int i = 0; i < 9; i++) pos[i] = (float)e[i / 3][i % 3];
    rast_transform_points(c.proj, pos, 3, clip);
    rt_expect_clipped_away(&t, clip);
    rt_free(&t);
}

static void test_w_zero(void **state)
{
    (void)state;
    rast_target t = rt_make(32, 32, 1, 1, 0);
    const float attr[3] = { 1, 2, 3 };
    /* A vertex at the clip-space origin has no projection: dropped. */
    const float origin[12] = { 0, 0, 0, 0,   1, -1, 0, 1,   -1, 1, 0, 1 };
    rast_stats st;
    memset(&st, 0, sizeof st);
    rt_draw_tri(&t, origin, attr, RAST_CULL_NONE, &st);
    assert_int_equal(st.tris_clipped_away, 1);
    assert_int_equal(rt_count_mask(&t, NULL), 0);
    /* Points at infinity (w = 0, z != 0) are cut by near or far. */
    const float inf_far[12] = { 1, 0, 0.5f, 0,   -0.5f, -0.5f, 0, 1,   0.5f, 0.5f, 0, 1 };
    const float inf_near[12] = { 1, 0, -0.5f, 0,   -0.5f, -0.5f, 0, 1,   0.5f, 0.5f, 0, 1 };
    const float *cases[2] = { inf_far, inf_near };
    for (int k = 0; k < 2; k++) {
        memset(&st, 0, sizeof st);
        rast_target_clear(&t);
        rt_draw_tri(&t, cases[k], attr, RAST_CULL_NONE, &st);
        assert_int_equal(st.tris_drawn >= 1, 1);
        assert_true(st.pixels_written > 0);
        for (int i = 0; i < 32 * 32; i++) {
            assert_true(t.depth[i] >= 0.0f && t.depth[i] <= 1.0f);
            assert_true(isfinite(t.attr[i]));
        }
    }
    rt_free(&t);
}

static void test_huge_triangles(void **state)
{
    (void)state;
    static const int sizes[][2] = { { 96, 64 }, { 1, 1 }, { 333, 17 } };
    static const float ws[] = { 1.0f, 3.7f, 0.01f, 250.0f };
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        rast_target t = rt_make(w, h, 1, 0, 0);
        for (size_t k = 0; k < sizeof ws / sizeof ws[0]; k++) {
            float cw = ws[k];
            const float clip[12] = { -1e6f * cw, -1e6f * cw, 0.25f * cw, cw,
                                      1e6f * cw, -1e6f * cw, 0.25f * cw, cw,
                                      0.0f, 1e6f * cw, 0.25f * cw, cw };
            rast_stats st;
            memset(&st, 0, sizeof st);
            rast_target_clear(&t);
            rt_draw_tri(&t, clip, NULL, RAST_CULL_NONE, &st);
            assert_int_equal(rt_count_mask(&t, NULL), (long)w * h);
            assert_int_equal(st.pixels_written, (long)w * h);
            /* Depth: constant 0.25*0.5+0.5 = 0.625 up to float rounding. */
            for (int i = 0; i < h; i++)
                for (int x = 0; x < w; x++)
                    assert_true(fabsf(t.depth[i * t.depth_stride + x] - 0.625f) < 1e-6f);
        }
        rt_free(&t);
    }
}

/* The (n+1) x (n+1) grid of clip-space vertices, two triangles a quad,
 * each drawn alone with CULL_NONE: count[] := how many covered each
 * pixel. */
static void count_grid(rast_target *t, int n, const float *clip, int *count)
{
    memset(count, 0, sizeof(int) * W * H);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i, b = a + 1, cc = a + n + 1, d = cc + 1;
            const int tris[2][3] = { { a, b, d }, { a, d, cc } };
            for (int k = 0; k < 2; k++) {
                float tc[12];
                for (int m = 0; m < 3; m++)
                    memcpy(tc + 4 * m, clip + 4 * tris[k][m], 4 * sizeof(float));
                rast_target_clear(t);
                assert_int_equal(rt_draw_tri(t, tc, NULL, RAST_CULL_NONE, NULL), RAST_OK);
                for (int y = 0; y < H; y++)
                    for (int x = 0; x < W; x++)
                        count[y * W + x] += t->mask[y * t->mask_stride + x] == 255;
            }
        }
}

/* A grid mesh in eye space given by a point function; drawn triangle by
 * triangle with CULL_NONE into a count buffer. */
static void grid_count(const cam *c, rast_target *t, int n, double x0, double x1,
                       double z0, double z1, double yplane, int *count)
{
    static float pos[41 * 41 * 3], clip[41 * 41 * 4];
    assert_true(n <= 40);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            /* Non-uniform spacing so that edges are not aligned. */
            double u = (double)i / n, v = (double)j / n;
            u = u * u * (3 - 2 * u) * 0.3 + u * 0.7;
            v = v * v * 0.5 + v * 0.5;
            float *p = pos + 3 * (j * (n + 1) + i);
            p[0] = (float)(x0 + (x1 - x0) * u);
            p[1] = (float)yplane;
            p[2] = (float)(z0 + (z1 - z0) * v);
        }
    rast_transform_points(c->proj, pos, (n + 1) * (n + 1), clip);
    count_grid(t, n, clip, count);
}

static void test_clipped_grids_watertight(void **state)
{
    (void)state;
    cam c;
    cam_init(&c);
    rast_target t = rt_make(W, H, 0, 0, 0);
    int *count = calloc(W * H, sizeof(int));
    /* 1. A floor at y = -1 from behind the eye (z = +5) to z = -40: cut by
     * the near plane and the guard band. Below the horizon every pixel is
     * covered exactly once (the floor ends at 40 units, well below it). */
    grid_count(&c, &t, 30, -300.0, 300.0, 5.0, -40.0, -1.0, count);
    long once = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int v = count[y * W + x];
            double ny = 1.0 - (y + 0.5) / H * 2.0;
            /* Ray hits y = -1 at depth t = 1/(-ny/m5); inside the floor's
             * z range when that depth is < 40 (with a margin). */
            double depth = ny < 0 ? c.proj[5] / -ny : 1e9;
            int want = depth < 39.0 ? 1 : depth > 41.0 ? 0 : -1;
            if (v > 1 || (want >= 0 && v != want))
                fail_msg("floor: pixel (%d,%d) covered %d times, want %d", x, y, v, want);
            once += v;
        }
    assert_true(once > W * H / 3);
    /* 2. A wall facing the camera, 1e4 units wide (far past the guard
     * band): every pixel exactly once. */
    static float pos[21 * 21 * 3], clip[21 * 21 * 4];
    const int n = 20;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            float *p = pos + 3 * (j * (n + 1) + i);
            p[0] = (float)(-5e3 + 1e4 * i / n + (i % 3) * 7.0);
            p[1] = (float)(-5e3 + 1e4 * j / n - (j % 2) * 3.0);
            p[2] = -2.0f;
        }
    rast_transform_points(c.proj, pos, (n + 1) * (n + 1), clip);
    count_grid(&t, n, clip, count);
    for (int i = 0; i < W * H; i++)
        if (count[i] != 1)
            fail_msg("wall: pixel (%d,%d) covered %d times", i % W, i / W, count[i]);
    free(count);
    rt_free(&t);
}

/* The clipper computes an edge's intersection from its inside vertex, so
 * two triangles sharing an edge (walked in opposite directions) get the
 * same bits for the new vertex: the basis of watertight clipping. */
static void test_shared_edge_clip_bits(void **state)
{
    (void)state;
    rast__view v;
    rast__view_init(&v, 640, 400, 2);
    tu_rng r = { 2024 };
    int found = 0;
    for (int n = 0; n < 500; n++) {
        rast__vert p, q, r1, r2, A[RAST__MAX_POLY], B[RAST__MAX_POLY], tmp[RAST__MAX_POLY];
        rast__vert *pv[4] = { &p, &q, &r1, &r2 };
        memset(pv[0], 0, sizeof p); memset(pv[1], 0, sizeof p);
        memset(pv[2], 0, sizeof p); memset(pv[3], 0, sizeof p);
        for (int i = 0; i < 4; i++) {
            pv[i]->w = tu_range(&r, 0.1f, 5.0f);
            pv[i]->x = tu_range(&r, -1, 1) * pv[i]->w;
            pv[i]->y = tu_range(&r, -1, 1) * pv[i]->w;
            pv[i]->z = tu_range(&r, -0.9f, 0.9f) * pv[i]->w;
            pv[i]->a[0] = tu_range(&r, -1, 1);
            pv[i]->a[1] = tu_range(&r, -1, 1);
        }
        q.z = -q.w - tu_range(&r, 0.01f, 3.0f);       /* q before the near plane */
        A[0] = p; A[1] = q; A[2] = r1;
        B[0] = q; B[1] = p; B[2] = r2;
        int na = rast__clip_polygon(&v, 1u << RAST__PLANE_NEAR, A, 3, tmp);
        int nb = rast__clip_polygon(&v, 1u << RAST__PLANE_NEAR, B, 3, tmp);
        assert_int_equal(na, 4);
        assert_int_equal(nb, 4);
        /* The new vertex on edge pq follows p in A and precedes p in B. */
        const rast__vert *ea = &A[1], *eb;
        assert_memory_equal(&A[0], &p, sizeof p);
        assert_memory_equal(&B[1], &p, sizeof p);
        eb = &B[0];
        assert_true(ea->x == eb->x && ea->y == eb->y && ea->z == eb->z && ea->w == eb->w &&
                    ea->a[0] == eb->a[0] && ea->a[1] == eb->a[1]);
        found++;
    }
    assert_int_equal(found, 500);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_near_plane_crossing),
        cmocka_unit_test(test_vertex_behind_camera),
        cmocka_unit_test(test_w_zero),
        cmocka_unit_test(test_huge_triangles),
        cmocka_unit_test(test_clipped_grids_watertight),
        cmocka_unit_test(test_shared_edge_clip_bits))
