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
#include "../src/pipe/pipe.h"
#include "../src/pipe/pipe_lens.h"
#include "../src/cpu/ef_n10.h"
#include "../src/raster/raster.h"
#include "support/pipe_frames.h"
#include "../src/cpu/ef_mem.h"

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
    rast_target out = {L->width, L->height, depth, L->width, mask, L->width, NULL, 0, 0, NULL, 0};
    memset(mask, 0x77, n);
    long set = pipe_lens_warp(&m, &out);
    /* the straight drawing: the lens's pinhole part, no warp */
    rast_target st = {L->width, L->height, depth, L->width, straight, L->width, NULL, 0, 0,
                      NULL, 0};
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
    EF_FREE_ALL(mask, straight, depth, d2);
    pipe_lens_map_free(&m);
}

/* A checked lens of the model at w x h with focal lengths, centre and
 * coefficients k[0..nk). */
static kin_lens lens_of(kin_lens_model model, int w, int h, double fx, double fy, double cx,
                        double cy, const double *k, int nk)
{
    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = model;
    L.width = w, L.height = h;
    L.fx = fx, L.fy = fy, L.cx = cx, L.cy = cy;
    for (int i = 0; i < nk; i++) L.k[i] = k[i];
    assert_true(kin_lens_check(&L, NULL, 0));
    return L;
}

static kin_lens barrel(void)
{
    static const double k[5] = {-0.291, 0.102, 0.0007, -0.0011, -0.0173};
    return lens_of(KIN_LENS_BROWN, 640, 480, 531.8, 532.4, 318.2, 241.7, k, 5);
}

static kin_lens fisheye(void)
{
    static const double k[4] = {-0.00825, 0.0453, -0.0428, 0.00777};
    return lens_of(KIN_LENS_FISHEYE, 848, 800, 286.18, 286.33, 421.3, 403.1, k, 4);
}

/* One silhouette case: the polygon of make_poly's arguments, drawn with
 * ss samples per pixel. */
typedef struct silhouette_case {
    const char *name;
    double cx, cy, cz, rmin, rmax, yaw, pitch;
    uint64_t seed;
    int ss;
} silhouette_case;

/* run_case of each of the n cases through the lens L. */
static void run_silhouettes(const kin_lens *L, const silhouette_case *c, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        poly p = make_poly(c[i].cx, c[i].cy, c[i].cz, c[i].rmin, c[i].rmax, c[i].yaw, c[i].pitch,
                           c[i].seed);
        run_case(c[i].name, L, &p, c[i].ss);
    }
}

static void result_barrel_silhouette(void **state)
{
    (void)state;
    /* a hand-sized star off-centre, and a large tilted one reaching the corners */
    static const silhouette_case cases[] = {
        {"barrel, hand off-centre", 0.12, 0.05, -0.45, 0.05, 0.09, 0.4, -0.3, 1, 1},
        {"barrel, hand off-centre", 0.12, 0.05, -0.45, 0.05, 0.09, 0.4, -0.3, 1, 2},
        {"barrel, large, to the corners", -0.05, -0.02, -0.5, 0.22, 0.42, -0.5, 0.6, 2, 1},
        {"barrel, large, to the corners", -0.05, -0.02, -0.5, 0.22, 0.42, -0.5, 0.6, 2, 2},
    };
    kin_lens L = barrel();
    run_silhouettes(&L, cases, sizeof cases / sizeof cases[0]);
}

static void result_fisheye_silhouette(void **state)
{
    (void)state;
    /* 55 degrees off the axis, and across the centre */
    static const silhouette_case cases[] = {
        {"fisheye, 55 degrees off the axis", 0.3, -0.12, -0.25, 0.06, 0.1, 0.9, 0.2, 3, 1},
        {"fisheye, 55 degrees off the axis", 0.3, -0.12, -0.25, 0.06, 0.1, 0.9, 0.2, 3, 2},
        {"fisheye, across the centre", 0.0, 0.0, -0.3, 0.2, 0.35, 0.3, -0.4, 4, 1},
    };
    kin_lens L = fisheye();
    run_silhouettes(&L, cases, sizeof cases / sizeof cases[0]);
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
    rast_target out = {L.width, L.height, depth, L.width, mask, L.width, attr, 3 * L.width, 3,
                       NULL, 0};
    rast_target_clear(&out);
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
    /* frame after frame: a second draw warped over the first equals the
     * same draw warped into a cleared target (the warp writes only what
     * changes) */
    poly q = make_poly(0.1, -0.05, -0.5, 0.05, 0.12, 0.3, 0.2, 6);
    rast_target_clear(&it);
    for (int i = 0; i < NV; i++) poly_point(&q, q.px[i], q.py[i], pos + 3 * (i + 1));
    poly_point(&q, 0, 0, pos);
    rast_transform_points(pc.view_proj.m, pos, NV + 1, clip);
    assert_int_equal(rast_draw(&it, &d, NULL), RAST_OK);
    long n2 = pipe_lens_warp(&m, &out);
    uint8_t *mask2 = malloc(n);
    float *depth2 = malloc(sizeof(float) * n), *attr2 = malloc(sizeof(float) * 3 * n);
    assert_non_null(mask2), assert_non_null(depth2), assert_non_null(attr2);
    rast_target out2 = {L.width, L.height, depth2, L.width, mask2, L.width, attr2, 3 * L.width, 3,
                        NULL, 0};
    rast_target_clear(&out2);
    assert_int_equal(pipe_lens_warp(&m, &out2), n2);
    assert_true(n2 > 1000);
    assert_memory_equal(mask, mask2, n);
    assert_memory_equal(depth, depth2, sizeof(float) * n);
    assert_memory_equal(attr, attr2, sizeof(float) * 3 * n);
    free(mask2), free(depth2), free(attr2);
    free(mask), free(depth), free(attr);
    pipe_lens_map_free(&m);
}

/* The normals packed (pipe_lens_map_init_n10): the same pinhole render
 * and warp, frame after frame, with every packed pixel ef_n10_pack of the
 * float map's normals and the mask and depth those of the float map. */
static void result_attributes_n10(void **state)
{
    (void)state;
    kin_lens L = barrel();
    pipe_lens_map mf, mq;
    char why[200];
    if (pipe_lens_map_init(&mf, &L, 2, 3, why, sizeof why) != 0) fail_msg("%s", why);
    if (pipe_lens_map_init_n10(&mq, &L, 2, why, sizeof why) != 0) fail_msg("%s", why);
    assert_int_equal(mq.pin_width, mf.pin_width);
    assert_int_equal(mq.pin_height, mf.pin_height);
    assert_null(mq.attr);
    kin_camera cam = lens_camera(&L);
    kin_camera pc = pipe_lens_pinhole(&mf, &cam);
    rast_target itf = pipe_lens_target(&mf), itq = pipe_lens_target(&mq);
    assert_non_null(itq.attr_n10);
    size_t n = (size_t)L.width * L.height;
    uint8_t *mask = malloc(n), *maskq = malloc(n);
    float *depth = malloc(sizeof(float) * n), *depthq = malloc(sizeof(float) * n),
          *attr = malloc(sizeof(float) * 3 * n);
    uint32_t *n10 = malloc(sizeof(uint32_t) * n);
    assert_non_null(mask), assert_non_null(maskq), assert_non_null(depth);
    assert_non_null(depthq), assert_non_null(attr), assert_non_null(n10);
    rast_target out = {L.width, L.height, depth, L.width, mask, L.width, attr, 3 * L.width, 3,
                       NULL, 0};
    rast_target outq = {L.width, L.height, depthq, L.width, maskq, L.width, NULL, 0, 3, n10,
                        L.width};
    rast_target_clear(&out);
    rast_target_clear(&outq);
    tu_rng g = {77};
    for (int f = 0; f < 3; f++) {
        /* a tilted polygon with normals varying per vertex (drawn in
         * this order: x, y, z, the radii, yaw, pitch) */
        double a[7];
        const float lo[7] = {-0.1f, -0.1f, -0.7f, 0.05f, 0.2f, -0.4f, -0.4f},
                    hi[7] = {0.1f, 0.1f, -0.4f, 0.1f, 0.3f, 0.4f, 0.4f};
        for (int k = 0; k < 7; k++) a[k] = tu_range(&g, lo[k], hi[k]);
        poly p = make_poly(a[0], a[1], a[2], a[3], a[4], a[5], a[6], 5 + (uint64_t)f);
        float pos[3 * (NV + 1)], clip[4 * (NV + 1)], nrm[3 * (NV + 1)];
        uint32_t idx[3 * NV];
        poly_point(&p, 0, 0, pos);
        for (int i = 0; i < NV; i++) {
            poly_point(&p, p.px[i], p.py[i], pos + 3 * (i + 1));
            idx[3 * i] = 0, idx[3 * i + 1] = (uint32_t)(i + 1),
            idx[3 * i + 2] = (uint32_t)((i + 1) % NV + 1);
        }
        for (int i = 0; i < 3 * (NV + 1); i++) nrm[i] = tu_range(&g, -1.0f, 1.0f);
        rast_transform_points(pc.view_proj.m, pos, NV + 1, clip);
        rast_mesh_desc d = {clip, NV + 1, nrm, 3, idx, NV, RAST_CULL_NONE};
        rast_target_clear(&itf);
        rast_target_clear(&itq);
        assert_int_equal(rast_draw(&itf, &d, NULL), RAST_OK);
        assert_int_equal(rast_draw(&itq, &d, NULL), RAST_OK);
        const long set = pipe_lens_warp(&mf, &out);
        assert_int_equal(pipe_lens_warp(&mq, &outq), set);
        assert_true(set > 1000);
        assert_memory_equal(mask, maskq, n);
        assert_memory_equal(depth, depthq, sizeof(float) * n);
        for (size_t i = 0; i < n; i++)
            if (n10[i] != ef_n10_pack(attr[3 * i], attr[3 * i + 1], attr[3 * i + 2]))
                fail_msg("frame %d pixel %zu: %08x, ef_n10_pack of the floats %08x", f, i, n10[i],
                         ef_n10_pack(attr[3 * i], attr[3 * i + 1], attr[3 * i + 2]));
    }
    free(mask), free(maskq), free(depth), free(depthq), free(attr), free(n10);
    pipe_lens_map_free(&mf);
    pipe_lens_map_free(&mq);
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

/* A head node and an unskinned quad [x0,x1]x[y0,y1] at depth z, facing +Z. */
static void quad_model(kin_model *m, float x0, float x1, float y0, float y1, float z)
{
    tu_mesh_parts t = tu_mesh_model(m, "head", "quad", 4, 6, 1);
    const float p[12] = {x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z};
    memcpy(t.pos, p, sizeof p);
    for (int i = 0; i < 4; i++) t.nrm[3 * i + 2] = 1.0f;
    const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    memcpy(t.idx, ix, sizeof ix);
}

/* pipe_frame with a calibrated barrel lens on the paper's 640x480 camera:
 * each eye's mask (the crop of eq. 1, 640x400) is the quad's exact
 * silhouette through that eye's lens within the documented distance of
 * its outline; the lens differs per eye (a stereo calibration); one or
 * two threads give the same bytes. */
static void result_pipe_frame_through_lens(void **state)
{
    (void)state;
    const float X0 = -0.21f, X1 = 0.17f, Y0 = -0.12f, Y1 = 0.15f, Z = -0.45f;
    kin_model m;
    quad_model(&m, X0, X1, Y0, Y1, Z);
    pipe_desc pd = {0};
    pd.hmd.lens[0] = barrel();
    pd.hmd.lens[1] = barrel();
    pd.hmd.lens[1].k[0] = -0.25;
    pd.hmd.lens[1].cx = 322.9;
    assert_true(kin_lens_check(&pd.hmd.lens[1], NULL, 0));
    uint8_t *masks[2][2];
    for (int th = 1; th <= 2; th++) {
        pd.threads = th;
        pipe_ctx *p = pipe_create(&pd, &m);
        assert_non_null(p);
        kin_sthmd_desc hd = pipe_hmd(p);
        assert_int_equal(hd.cam_width, 640);
        NEAR(hd.cam_hfov_deg, 2.0 * atan(320.0 / 531.8) * 180.0 / 3.14159265358979, 1e-4);
        pipe_frame_in in;
        memset(&in, 0, sizeof in);
        uint8_t *cam = calloc((size_t)640 * 480 * 4, 1), *virt = calloc((size_t)1280 * 800 * 4, 1),
                *out[2];
        assert_non_null(cam), assert_non_null(virt);
        for (int e = 0; e < 2; e++) {
            out[e] = malloc((size_t)1280 * 800 * 4);
            assert_non_null(out[e]);
            in.camera[e] = (fuse_image){cam, 640, 480, 640 * 4};
            in.virt[e] = (fuse_image){virt, 1280, 800, 1280 * 4};
            in.out[e] = (fuse_image){out[e], 1280, 800, 1280 * 4};
        }
        in.head_node = -1;
        in.lighting = pipe_lighting_default();
        char why[300] = "";
        if (pipe_frame(p, &in, NULL, why, sizeof why) != PIPE_OK) fail_msg("pipe_frame: %s", why);
        for (int e = 0; e < 2; e++) {
            int mw, mh;
            const uint8_t *pm = pipe_mask(p, e, &mw, &mh);
            assert_int_equal(mw, 640);
            assert_int_equal(mh, 400);
            masks[th - 1][e] = malloc((size_t)mw * mh);
            memcpy(masks[th - 1][e], pm, (size_t)mw * mh);
            kin_camera c = pipe_camera(p, e);
            assert_int_equal(c.lens.model, KIN_LENS_BROWN);
            NEAR(c.lens.cy, pd.hmd.lens[e].cy - 40.0, 1e-12); /* the crop's rows */
            /* the camera sits at (+-baseline/2, 0, -D): the quad in its view space */
            double ox = (e ? 0.5 : -0.5) * hd.baseline_m, zc = Z + hd.cam_offset_m;
            long truth_n = 0, differ = 0;
            for (int y = 0; y < mh; y++)
                for (int x = 0; x < mw; x++) {
                    double r[3];
                    assert_true(kin_lens_unproject(&c.lens, x + 0.5, y + 0.5, r));
                    double t = zc / r[2], a = t * r[0] + ox, b = t * r[1];
                    int truth = a >= X0 && a <= X1 && b >= Y0 && b <= Y1;
                    int got = pm[(size_t)y * mw + x] != 0;
                    truth_n += truth;
                    if (got == truth) continue;
                    differ++;
                    /* distance to the outline in the pinhole render (fx px) */
                    double d = fmin(fmin(fabs(a - X0), fabs(a - X1)) * c.lens.fx / -zc,
                                    fmin(fabs(b - Y0), fabs(b - Y1)) * c.lens.fy / -zc);
                    if (!(d <= 0.5 * sqrt(2.0) + 1.0 / 64))
                        fail_msg("eye %d pixel (%d, %d) differs %.3f px from the outline", e, x, y, d);
                }
            if (th == 1)
                print_message("pipe_frame, %s eye: quad %ld px, %ld differ from the exact "
                              "silhouette through the lens\n", e ? "right" : "left", truth_n, differ);
            assert_true(truth_n > 40000);
            assert_true(differ < truth_n / 100);
        }
        pipe_destroy(p);
        free(cam), free(virt), free(out[0]), free(out[1]);
    }
    for (int e = 0; e < 2; e++) {
        assert_memory_equal(masks[0][e], masks[1][e], (size_t)640 * 400);
        free(masks[0][e]), free(masks[1][e]);
    }
    kin_model_free(&m);
}

TU_MAIN_NAMED("pipe_lens", NULL, NULL,
              cmocka_unit_test(result_barrel_silhouette),
              cmocka_unit_test(result_fisheye_silhouette),
              cmocka_unit_test(result_attributes),
              cmocka_unit_test(result_attributes_n10),
              cmocka_unit_test(validity_bad_maps),
              cmocka_unit_test(result_pipe_frame_through_lens))
