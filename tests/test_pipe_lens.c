/* test_pipe_lens.c - the mask through a distorting lens (pipe_lens.c)
 * against the exact silhouette: a planar star-shaped polygon, drawn as a
 * triangle fan through the pinhole render and the per-pixel gather, and
 * for every camera pixel the ray of its centre (kin_lens_unproject, itself
 * checked against OpenCV's formulas by test_kin_lens) intersected with
 * the polygon's plane and tested against the polygon in double precision.
 * Every pixel that differs must lie within the documented distance of a
 * polygon edge (half a pinhole pixel per axis: 0.5 sqrt(2), plus the
 * rasterizer's 1/256 px snapping), for a barrel Brown-Conrady lens and a
 * wide fisheye, at supersample 1 and 2; the figures (pixels differing,
 * their largest distance to the edge in camera pixels) are printed. The
 * same polygon drawn straight (the lens's pinhole part, no warp) differs
 * in thousands of pixels: the lens matters at these positions. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/kin/kin.h"
#include "../src/pipe/pipe_lens.h"
#include "../src/raster/raster.h"

#define NV 12 /* polygon vertices */

typedef struct poly {
    double c[3], e1[3], e2[3], n[3]; /* centre, in-plane axes, normal (view space) */
    double px[NV], py[NV];           /* vertices in plane coordinates */
} poly;

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* A star-shaped polygon around c, tilted by yaw/pitch, radii seeded. */
static poly make_poly(double cx, double cy, double cz, double rmin, double rmax, double yaw,
                      double pitch, uint64_t seed)
{
    poly p;
    p.c[0] = cx, p.c[1] = cy, p.c[2] = cz;
    double cyw = cos(yaw), syw = sin(yaw), cp = cos(pitch), sp = sin(pitch);
    double e1[3] = {cyw, 0, -syw}, n0[3] = {syw, 0, cyw};
    double e2[3] = {0, cp, 0}, n[3];
    /* pitch about e1 */
    e2[0] = -sp * n0[0], e2[1] = cp, e2[2] = -sp * n0[2];
    memcpy(p.e1, e1, sizeof e1);
    memcpy(p.e2, e2, sizeof e2);
    cross(e1, e2, n);
    memcpy(p.n, n, sizeof n);
    tu_rng g = {seed};
    for (int i = 0; i < NV; i++) {
        double a = 2.0 * 3.14159265358979 * i / NV, r = rmin + (rmax - rmin) * tu_unit(&g);
        p.px[i] = r * cos(a);
        p.py[i] = r * sin(a);
    }
    return p;
}

static void poly_point(const poly *p, double x, double y, float *o)
{
    for (int k = 0; k < 3; k++) o[k] = (float)(p->c[k] + x * p->e1[k] + y * p->e2[k]);
}

/* Even-odd inside test in plane coordinates. */
static int inside(const poly *p, double x, double y)
{
    int in = 0;
    for (int i = 0, j = NV - 1; i < NV; j = i++) {
        if ((p->py[i] > y) != (p->py[j] > y) &&
            x < (p->px[j] - p->px[i]) * (y - p->py[i]) / (p->py[j] - p->py[i]) + p->px[i])
            in = !in;
    }
    return in;
}

static double seg_dist(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay, t = ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(px - ax - t * dx, py - ay - t * dy);
}

/* A camera at the origin looking down -Z through lens. */
static kin_camera lens_camera(const kin_lens *L)
{
    kin_camera c;
    memset(&c, 0, sizeof c);
    c.view = kin_mat4_identity();
    c.world_from_cam = kin_mat4_identity();
    c.width = L->width;
    c.height = L->height;
    c.fx = (float)L->fx, c.fy = (float)L->fy;
    c.cx = (float)(L->cx + 0.5), c.cy = (float)(L->cy + 0.5);
    c.proj = kin_proj_from_intrinsics(L->fx, L->fy, L->cx + 0.5, L->cy + 0.5, L->skew, c.width,
                                      c.height, 0.01, 100.0);
    c.view_proj = c.proj;
    c.lens = *L;
    return c;
}

/* Draws the polygon as a fan through cam into t. */
static void draw_poly(const poly *p, const kin_camera *cam, const rast_target *t)
{
    float pos[3 * (NV + 1)], clip[4 * (NV + 1)];
    uint32_t idx[3 * NV];
    poly_point(p, 0, 0, pos);
    for (int i = 0; i < NV; i++) {
        poly_point(p, p->px[i], p->py[i], pos + 3 * (i + 1));
        idx[3 * i] = 0;
        idx[3 * i + 1] = (uint32_t)(i + 1);
        idx[3 * i + 2] = (uint32_t)((i + 1) % NV + 1);
    }
    rast_transform_points(cam->view_proj.m, pos, NV + 1, clip);
    rast_mesh_desc d = {clip, NV + 1, NULL, 0, idx, NV, RAST_CULL_NONE};
    assert_int_equal(rast_draw(t, &d, NULL), RAST_OK);
}

typedef struct figures {
    long truth, differ, differ_straight;
    double max_dist_pin, max_dist_cam;
} figures;

/* The exact mask of p through the lens, and for each pixel the distance
 * of its ray's pinhole image to the polygon's outline (pinhole px). */
static figures compare(const poly *p, const kin_lens *L, const pipe_lens_map *m,
                       const uint8_t *mask, const uint8_t *straight)
{
    figures f = {0, 0, 0, 0, 0};
    double vu[NV], vv[NV];
    for (int i = 0; i < NV; i++) {
        float q[3];
        poly_point(p, p->px[i], p->py[i], q);
        vu[i] = m->pin_cx + m->pin_fx * q[0] / -q[2];
        vv[i] = m->pin_cy - m->pin_fy * q[1] / -q[2];
    }
    for (int y = 0; y < L->height; y++)
        for (int x = 0; x < L->width; x++) {
            double r[3];
            int truth = 0;
            double dist = INFINITY;
            if (kin_lens_unproject(L, x + 0.5, y + 0.5, r) && r[2] < -0.01) {
                double den = dot(r, p->n);
                if (fabs(den) > 1e-12) {
                    double t = dot(p->c, p->n) / den;
                    if (t > 0) {
                        double h[3] = {t * r[0] - p->c[0], t * r[1] - p->c[1], t * r[2] - p->c[2]};
                        truth = inside(p, dot(h, p->e1), dot(h, p->e2));
                    }
                }
                double u = m->pin_cx + m->pin_fx * r[0] / -r[2];
                double v = m->pin_cy - m->pin_fy * r[1] / -r[2];
                for (int i = 0, j = NV - 1; i < NV; j = i++)
                    dist = fmin(dist, seg_dist(u, v, vu[j], vv[j], vu[i], vv[i]));
            }
            size_t k = (size_t)y * L->width + x;
            f.truth += truth;
            if ((mask[k] != 0) != truth) {
                f.differ++;
                if (!(dist <= 0.5 * sqrt(2.0) + 1.0 / 128))
                    fail_msg("pixel (%d, %d) differs %g pinhole px from the edge", x, y, dist);
                f.max_dist_pin = fmax(f.max_dist_pin, dist);
                f.max_dist_cam = fmax(f.max_dist_cam, dist / m->supersample);
            }
            if (straight && (straight[k] != 0) != truth) f.differ_straight++;
        }
    return f;
}

static void run_case(const char *name, const kin_lens *L, const poly *p, int ss)
{
    pipe_lens_map m;
    char why[200];
    if (pipe_lens_map_init(&m, L, ss, 0, why, sizeof why) != 0) fail_msg("%s", why);
    kin_camera cam = lens_camera(L);
    kin_camera pc = pipe_lens_pinhole(&m, &cam);
    rast_target it = pipe_lens_target(&m);
    rast_target_clear(&it);
    draw_poly(p, &pc, &it);
    size_t n = (size_t)L->width * L->height;
    uint8_t *mask = malloc(n), *straight = malloc(n);
    float *depth = malloc(sizeof(float) * n);
    assert_non_null(mask);
    assert_non_null(straight);
    assert_non_null(depth);
    rast_target out = {L->width, L->height, depth, L->width, mask, L->width, NULL, 0, 0};
    memset(mask, 0x77, n);
    long set = pipe_lens_warp(&m, &out);
    /* the straight drawing: the lens's pinhole part, no warp */
    rast_target st = {L->width, L->height, depth, L->width, straight, L->width, NULL, 0, 0};
    float *d2 = malloc(sizeof(float) * n);
    assert_non_null(d2);
    st.depth = d2;
    rast_target_clear(&st);
    draw_poly(p, &cam, &st);
    /* the gather wrote every pixel (0 or 255) */
    long cnt = 0;
    for (size_t i = 0; i < n; i++) {
        assert_true(mask[i] == 0 || mask[i] == 255);
        cnt += mask[i] != 0;
    }
    assert_int_equal(cnt, set);
    figures f = compare(p, L, &m, mask, straight);
    print_message("%s, supersample %d: pinhole render %dx%d, %ld px unmapped; silhouette %ld px, "
                  "%ld differ from the exact one (largest distance to the edge %.3f pinhole px = "
                  "%.3f camera px at the centre's scale); drawn straight: %ld differ\n",
                  name, ss, m.pin_width, m.pin_height, m.unmapped, f.truth, f.differ,
                  f.max_dist_pin, f.max_dist_cam, f.differ_straight);
    assert_true(f.truth > 1000);
    assert_true(f.differ_straight > 20 * (f.differ + 1)); /* the lens matters here */
    free(mask);
    free(straight);
    free(depth);
    free(d2);
    pipe_lens_map_free(&m);
}

static kin_lens barrel(void)
{
    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = KIN_LENS_BROWN;
    L.width = 640, L.height = 480;
    L.fx = 531.8, L.fy = 532.4, L.cx = 318.2, L.cy = 241.7;
    L.k[0] = -0.291, L.k[1] = 0.102, L.k[2] = 0.0007, L.k[3] = -0.0011, L.k[4] = -0.0173;
    assert_true(kin_lens_check(&L, NULL, 0));
    return L;
}

static kin_lens fisheye(void)
{
    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = KIN_LENS_FISHEYE;
    L.width = 848, L.height = 800;
    L.fx = 286.18, L.fy = 286.33, L.cx = 421.3, L.cy = 403.1;
    L.k[0] = -0.00825, L.k[1] = 0.0453, L.k[2] = -0.0428, L.k[3] = 0.00777;
    assert_true(kin_lens_check(&L, NULL, 0));
    return L;
}

static void result_barrel_silhouette(void **state)
{
    (void)state;
    kin_lens L = barrel();
    /* a hand-sized star off-centre, and a large tilted one reaching the corners */
    poly a = make_poly(0.12, 0.05, -0.45, 0.05, 0.09, 0.4, -0.3, 1);
    poly b = make_poly(-0.05, -0.02, -0.5, 0.22, 0.42, -0.5, 0.6, 2);
    run_case("barrel, hand off-centre", &L, &a, 1);
    run_case("barrel, hand off-centre", &L, &a, 2);
    run_case("barrel, large, to the corners", &L, &b, 1);
    run_case("barrel, large, to the corners", &L, &b, 2);
}

static void result_fisheye_silhouette(void **state)
{
    (void)state;
    kin_lens L = fisheye();
    /* 55 degrees off the axis, and across the centre */
    poly a = make_poly(0.3, -0.12, -0.25, 0.06, 0.1, 0.9, 0.2, 3);
    poly b = make_poly(0.0, 0.0, -0.3, 0.2, 0.35, 0.3, -0.4, 4);
    run_case("fisheye, 55 degrees off the axis", &L, &a, 1);
    run_case("fisheye, 55 degrees off the axis", &L, &a, 2);
    run_case("fisheye, across the centre", &L, &b, 1);
}

/* Depth and normals come through unchanged: a plane of constant normal
 * gives that normal at every covered pixel, and the depth of the exact
 * ray's hit within the depth of one pinhole pixel's step. */
static void result_attributes(void **state)
{
    (void)state;
    kin_lens L = barrel();
    pipe_lens_map m;
    char why[200];
    if (pipe_lens_map_init(&m, &L, 1, 3, why, sizeof why) != 0) fail_msg("%s", why);
    kin_camera cam = lens_camera(&L);
    kin_camera pc = pipe_lens_pinhole(&m, &cam);
    rast_target it = pipe_lens_target(&m);
    rast_target_clear(&it);
    poly p = make_poly(0.0, 0.0, -0.6, 0.2, 0.3, 0.0, 0.0, 5); /* facing the camera */
    float pos[3 * (NV + 1)], clip[4 * (NV + 1)], nrm[3 * (NV + 1)];
    uint32_t idx[3 * NV];
    poly_point(&p, 0, 0, pos);
    for (int i = 0; i < NV; i++) {
        poly_point(&p, p.px[i], p.py[i], pos + 3 * (i + 1));
        idx[3 * i] = 0, idx[3 * i + 1] = (uint32_t)(i + 1), idx[3 * i + 2] = (uint32_t)((i + 1) % NV + 1);
    }
    for (int i = 0; i <= NV; i++) nrm[3 * i] = 0.0f, nrm[3 * i + 1] = 0.0f, nrm[3 * i + 2] = 1.0f;
    rast_transform_points(pc.view_proj.m, pos, NV + 1, clip);
    rast_mesh_desc d = {clip, NV + 1, nrm, 3, idx, NV, RAST_CULL_NONE};
    assert_int_equal(rast_draw(&it, &d, NULL), RAST_OK);
    size_t n = (size_t)L.width * L.height;
    uint8_t *mask = malloc(n);
    float *depth = malloc(sizeof(float) * n), *attr = malloc(sizeof(float) * 3 * n);
    assert_non_null(mask), assert_non_null(depth), assert_non_null(attr);
    rast_target out = {L.width, L.height, depth, L.width, mask, L.width, attr, 3 * L.width, 3};
    assert_true(pipe_lens_warp(&m, &out) > 10000);
    /* window depth of z = -0.6 with the camera's projection */
    const float *P = cam.proj.m;
    double zc = P[10] * -0.6 + P[14], wc = 0.6, want = zc / wc * 0.5 + 0.5;
    for (size_t i = 0; i < n; i++) {
        if (!mask[i]) {
            NEAR(depth[i], 1.0, 0);
            NEAR(attr[3 * i + 2], 0.0, 0);
            continue;
        }
        NEAR(attr[3 * i], 0.0, 0);
        NEAR(attr[3 * i + 2], 1.0, 0);
        NEAR(depth[i], want, 1e-6);
    }
    free(mask), free(depth), free(attr);
    pipe_lens_map_free(&m);
}

static void validity_bad_maps(void **state)
{
    (void)state;
    pipe_lens_map m;
    char why[200];
    kin_lens L = barrel();
    L.width = 0;
    assert_int_equal(pipe_lens_map_init(&m, &L, 1, 0, why, sizeof why), -1);
    assert_non_null(strstr(why, "size"));
    L = barrel();
    assert_int_equal(pipe_lens_map_init(&m, &L, 9, 0, why, sizeof why), -1);
    assert_non_null(strstr(why, "supersample"));
    /* a fisheye seeing past 90 degrees keeps its centre; the rest is unmapped */
    kin_lens F = fisheye();
    F.fx = F.fy = 150.0; /* about 190 degrees across the width */
    assert_true(kin_lens_check(&F, NULL, 0));
    assert_int_equal(pipe_lens_map_init(&m, &F, 1, 0, why, sizeof why), 0);
    assert_true(m.unmapped > 0);
    assert_true(m.pin_width <= RAST_MAX_DIM && m.pin_height <= RAST_MAX_DIM);
    assert_int_equal(m.src[(size_t)403 * 848 + 421] >= 0, 1);
    pipe_lens_map_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(result_barrel_silhouette),
        cmocka_unit_test(result_fisheye_silhouette),
        cmocka_unit_test(result_attributes),
        cmocka_unit_test(validity_bad_maps),
    };
    return cmocka_run_group_tests_name("pipe_lens", tests, NULL, NULL);
}
