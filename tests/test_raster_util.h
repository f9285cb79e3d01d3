/* test_raster_util.h - helpers shared by tests/test_raster_*.c (static,
 * header only; include after <cmocka.h>): targets with padded strides,
 * clip coordinates that land exactly on a chosen sub-pixel position, and
 * an independent coverage reference for the top-left rule.
 *
 * The reference coverage uses the equivalent "perturbed sample" form of
 * the top-left rule instead of the rasterizer's bias: a pixel centre p is
 * covered iff p + (e, e^2) lies strictly inside the triangle for an
 * infinitesimal e > 0. For each edge that means: the sign of E(p), or if
 * it is 0 the sign of dE/dx, or if that is 0 the sign of dE/dy, must equal
 * the sign of the triangle's area (any winding). */
#ifndef EGOFUSE_TEST_RASTER_UTIL_H
#define EGOFUSE_TEST_RASTER_UTIL_H

#include "support/testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/raster/raster.h"

/* A target with its own buffers; strides are padded by `pad` so that
 * writes outside the width would show. */

static inline rast_target rt_make(int w, int h, int with_depth, int na, int pad)
{
    rast_target t;
    memset(&t, 0, sizeof t);
    t.width = w;
    t.height = h;
    t.mask_stride = w + pad;
    t.mask = calloc((size_t)t.mask_stride * (size_t)h, 1);
    if (with_depth) {
        t.depth_stride = w + pad;
        t.depth = calloc((size_t)t.depth_stride * (size_t)h, sizeof(float));
    }
    t.attr_count = na;
    if (na > 0) {
        t.attr_stride = w * na + pad;
        t.attr = calloc((size_t)t.attr_stride * (size_t)h, sizeof(float));
    }
    rast_target_clear(&t);
    return t;
}

static inline void rt_free(rast_target *t)
{
    free(t->mask);
    free(t->depth);
    free(t->attr);
    memset(t, 0, sizeof *t);
}

/* Clip coordinates (x, y, z, w) whose viewport position is exactly the
 * fixed-point position (fx, fy) (1/256 px) on a w x h target, for w, h
 * powers of two and a power-of-two clip w (all steps are then exact). */
static inline void rt_clip_at(int64_t fx, int64_t fy, int width, int height, float z,
                       float cw, float out[4])
{
    double nx = (double)fx / 256.0 / width * 2.0 - 1.0;
    double ny = 1.0 - (double)fy / 256.0 / height * 2.0;
    out[0] = (float)nx * cw;
    out[1] = (float)ny * cw;
    out[2] = z * cw;
    out[3] = cw;
}

static inline int rt_sgn(int64_t v) { return (v > 0) - (v < 0); }

/* Independent top-left coverage of pixel centre (px, py) (fixed point) by
 * the triangle (X[i], Y[i]) (fixed point), either winding. */
static inline int rt_covers(const int64_t X[3], const int64_t Y[3], int64_t px,
                     int64_t py)
{
    int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area == 0)
        return 0;
    int s = rt_sgn(area);
    for (int k = 0; k < 3; k++) {
        int a = k, b = (k + 1) % 3;
        int64_t dx = X[b] - X[a], dy = Y[b] - Y[a];
        int64_t e = dx * (py - Y[a]) - dy * (px - X[a]);
        int se = rt_sgn(e);
        if (se == 0)
            se = rt_sgn(-dy);      /* d/dx of e */
        if (se == 0)
            se = rt_sgn(dx);       /* d/dy of e */
        if (se != s)
            return 0;
    }
    return 1;
}

/* Draws one triangle of 3 clip vertices (with optional attributes). */
static inline rast_result rt_draw_tri(const rast_target *t, const float clip[12],
                               const float *attr, rast_cull cull,
                               rast_stats *st)
{
    static const uint32_t idx[3] = { 0, 1, 2 };
    rast_mesh_desc d;
    memset(&d, 0, sizeof d);
    d.clip = clip;
    d.vertex_count = 3;
    d.attr = attr;
    d.attr_count = t->attr_count;
    d.indices = idx;
    d.tri_count = 1;
    d.cull = cull;
    return rast_draw(t, &d, st);
}

/* Number of mask pixels equal to 255 (and checks all others are 0). */
static inline long rt_count_mask(const rast_target *t, int *bad)
{
    long n = 0;
    for (int y = 0; y < t->height; y++)
        for (int x = 0; x < t->width; x++) {
            uint8_t m = t->mask[(size_t)y * t->mask_stride + x];
            if (m == 255) n++;
            else if (m != 0 && bad) *bad = 1;
        }
    return n;
}

/* Draws the triangle clip (no culling) on t, cleared first, and checks
 * that it is clipped away entirely: counted so, and nothing drawn. */
static inline void rt_expect_clipped_away(const rast_target *t, const float clip[12])
{
    rast_stats st;
    memset(&st, 0, sizeof st);
    rast_target_clear(t);
    rt_draw_tri(t, clip, NULL, RAST_CULL_NONE, &st);
    assert_int_equal(st.tris_clipped_away, 1);
    assert_int_equal(rt_count_mask(t, NULL), 0);
}

/* Draws m[0] on t[0] and m[1] on t[1] in the context c: in one
 * rast_context_draw_jobs call when jobs is set, else with one
 * rast_context_draw each; every call must succeed. */
static inline void rt_context_draw_two(rast_context *c, int jobs, const rast_target t[2],
                                       const rast_mesh_desc m[2])
{
    if (jobs) {
        const rast_target *tp[2] = { &t[0], &t[1] };
        const rast_mesh_desc *mp[2] = { &m[0], &m[1] };
        assert_int_equal(rast_context_draw_jobs(c, 2, tp, mp, NULL), RAST_OK);
    } else {
        for (int e = 0; e < 2; e++)
            assert_int_equal(rast_context_draw(c, &t[e], &m[e], NULL), RAST_OK);
    }
}

/* Column-major perspective matrix (OpenGL glFrustum-like, symmetric). */
static inline void rt_perspective(double fovy_rad, double aspect, double n, double f,
                           float m[16])
{
    double t = 1.0 / tan(fovy_rad * 0.5);
    memset(m, 0, 16 * sizeof(float));
    m[0] = (float)(t / aspect);
    m[5] = (float)t;
    m[10] = (float)((f + n) / (n - f));
    m[11] = -1.0f;
    m[14] = (float)(2.0 * f * n / (n - f));
}

#endif
