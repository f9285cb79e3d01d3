/* pipe_lens.c - the mask through a distorting lens: a pinhole render and a
 * per-pixel gather (pipe_lens.h). */
#include "pipe_lens.h"
#include "pipe_internal.h"
#include "../cpu/ef_mem.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void pipe_lens_map_free(pipe_lens_map *m)
{
    if (!m) return;
    EF_FREE_ALL(m->src, m->depth, m->mask, m->attr, m->attr_n10);
    memset(m, 0, sizeof *m);
}

/* The largest symmetric clamp L of [lo, hi] (to [max(lo,-L), min(hi,L)])
 * whose width fits into span. */
static void fit_range(double *lo, double *hi, double span)
{
    if (*hi - *lo <= span) return;
    double a = 0.0, b = fmax(fabs(*lo), fabs(*hi));
    for (int i = 0; i < 100; i++) {
        double L = 0.5 * (a + b);
        if (fmin(*hi, L) - fmax(*lo, -L) <= span) a = L;
        else b = L;
    }
    *lo = fmax(*lo, -a);
    *hi = fmin(*hi, a);
}

static int map_init(pipe_lens_map *m, const kin_lens *lens, int supersample, int attr_count,
                    int n10, char *why, int why_size)
{
    memset(m, 0, sizeof *m);
    if (!lens || lens->width < 1 || lens->height < 1 || lens->width > RAST_MAX_DIM ||
        lens->height > RAST_MAX_DIM)
        return pipe__fail(why, why_size, "the lens has no image size in 1..%d", RAST_MAX_DIM);
    if (supersample < 1 || supersample > 4)
        return pipe__fail(why, why_size, "supersample %d: 1..4", supersample);
    if (attr_count < 0 || attr_count > RAST_MAX_ATTRS)
        return pipe__fail(why, why_size, "attr_count %d: 0..%d", attr_count, RAST_MAX_ATTRS);
    const int W = lens->width, H = lens->height;
    const size_t n = (size_t)W * (size_t)H;
    double *xy = malloc(sizeof(double) * 2 * n);
    m->src = malloc(sizeof(int32_t) * n);
    if (!xy || !m->src) {
        free(xy);
        pipe_lens_map_free(m);
        return pipe__fail(why, why_size, "out of memory for a %dx%d lens map", W, H);
    }
    /* every pixel centre's ray, as the pinhole's normalized (X/-Z, Y/-Z) */
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t i = (size_t)y * W + x;
            double r[3];
            /* rays within about 89.4 degrees of the axis (|X/-Z| < 100) */
            if (!kin_lens_unproject(lens, x + 0.5, y + 0.5, r) || !(r[2] < -0.01)) {
                xy[2 * i] = NAN;
                continue;
            }
            double a = r[0] / -r[2], b = r[1] / -r[2];
            xy[2 * i] = a;
            xy[2 * i + 1] = b;
            xlo = fmin(xlo, a), xhi = fmax(xhi, a);
            ylo = fmin(ylo, b), yhi = fmax(yhi, b);
        }
    const double s = supersample;
    m->pin_fx = s * lens->fx;
    m->pin_fy = s * lens->fy;
    if (!(xlo <= xhi)) { /* no pixel has a ray: a 1x1 render, nothing mapped */
        xlo = xhi = ylo = yhi = 0.0;
    }
    /* one pixel of margin each side; at most PIPE_LENS_REACH times the
     * camera's size (times supersample) and RAST_MAX_DIM */
    double capw = fmin(RAST_MAX_DIM, PIPE_LENS_REACH * s * W), caph = fmin(RAST_MAX_DIM, PIPE_LENS_REACH * s * H);
    fit_range(&xlo, &xhi, (capw - 2) / m->pin_fx);
    fit_range(&ylo, &yhi, (caph - 2) / m->pin_fy);
    m->pin_width = (int)ceil((xhi - xlo) * m->pin_fx) + 2;
    m->pin_height = (int)ceil((yhi - ylo) * m->pin_fy) + 2;
    if (m->pin_width > RAST_MAX_DIM) m->pin_width = RAST_MAX_DIM;
    if (m->pin_height > RAST_MAX_DIM) m->pin_height = RAST_MAX_DIM;
    /* u' = cx' + fx' a, v' = cy' - fy' b (b is up): xlo at u' = 1 */
    m->pin_cx = 1.0 - m->pin_fx * xlo;
    m->pin_cy = 1.0 + m->pin_fy * yhi;
    m->width = W;
    m->height = H;
    m->supersample = supersample;
    m->attr_count = attr_count;
    for (size_t i = 0; i < n; i++) {
        m->src[i] = -1;
        double a = xy[2 * i], b = xy[2 * i + 1];
        if (isnan(a)) {
            m->unmapped++;
            continue;
        }
        double u = m->pin_cx + m->pin_fx * a, v = m->pin_cy - m->pin_fy * b;
        double fu = floor(u), fv = floor(v);
        if (!(fu >= 0.0 && fu < m->pin_width && fv >= 0.0 && fv < m->pin_height)) {
            m->unmapped++;
            continue;
        }
        m->src[i] = (int32_t)((long)fv * m->pin_width + (long)fu);
    }
    free(xy);
    size_t pn = (size_t)m->pin_width * (size_t)m->pin_height;
    m->depth = malloc(sizeof(float) * pn);
    m->mask = malloc(pn);
    if (n10)
        m->attr_n10 = malloc(sizeof(uint32_t) * pn);
    else if (attr_count)
        m->attr = malloc(sizeof(float) * (size_t)attr_count * pn);
    if (!m->depth || !m->mask || (n10 ? !m->attr_n10 : attr_count && !m->attr)) {
        pipe_lens_map_free(m);
        return pipe__fail(why, why_size, "out of memory for a %dx%d pinhole render", m->pin_width,
                    m->pin_height);
    }
    rast_target t = pipe_lens_target(m);
    rast_target_clear(&t);
    return 0;
}

int pipe_lens_map_init(pipe_lens_map *m, const kin_lens *lens, int supersample, int attr_count,
                       char *why, int why_size)
{
    return map_init(m, lens, supersample, attr_count, 0, why, why_size);
}

int pipe_lens_map_init_n10(pipe_lens_map *m, const kin_lens *lens, int supersample, char *why,
                           int why_size)
{
    return map_init(m, lens, supersample, 3, 1, why, why_size);
}

kin_camera pipe_lens_pinhole(const pipe_lens_map *m, const kin_camera *cam)
{
    kin_camera c = *cam;
    c.width = m->pin_width;
    c.height = m->pin_height;
    c.fx = (float)m->pin_fx;
    c.fy = (float)m->pin_fy;
    c.cx = (float)m->pin_cx;
    c.cy = (float)m->pin_cy;
    c.proj = kin_proj_from_intrinsics(m->pin_fx, m->pin_fy, m->pin_cx, m->pin_cy, 0.0, c.width,
                                      c.height, 0.01, 100.0);
    /* the same window depth as the camera's own projection */
    c.proj.m[2] = cam->proj.m[2];
    c.proj.m[6] = cam->proj.m[6];
    c.proj.m[10] = cam->proj.m[10];
    c.proj.m[14] = cam->proj.m[14];
    c.view_proj = kin_mat4_mul(&c.proj, &c.view);
    memset(&c.lens, 0, sizeof c.lens);
    c.lens.model = KIN_LENS_PINHOLE;
    c.lens.width = c.width;
    c.lens.height = c.height;
    c.lens.fx = m->pin_fx;
    c.lens.fy = m->pin_fy;
    c.lens.cx = m->pin_cx - 0.5;
    c.lens.cy = m->pin_cy - 0.5;
    kin_lens_check(&c.lens, NULL, 0);
    return c;
}

rast_target pipe_lens_target(const pipe_lens_map *m)
{
    rast_target t = {m->pin_width, m->pin_height, m->depth, m->pin_width, m->mask, m->pin_width,
                     m->attr, m->attr ? m->attr_count * m->pin_width : 0, m->attr_count,
                     m->attr_n10, m->attr_n10 ? m->pin_width : 0};
    return t;
}

long pipe_lens_warp(const pipe_lens_map *m, const rast_target *dst)
{
    long set = 0;
    const int ac = m->attr_count;
    for (int y = 0; y < m->height; y++) {
        const int32_t *src = m->src + (size_t)y * m->width;
        uint8_t *mk = dst->mask + (size_t)y * dst->mask_stride;
        float *dp = dst->depth ? dst->depth + (size_t)y * dst->depth_stride : NULL;
        float *at = dst->attr && m->attr && ac ? dst->attr + (size_t)y * dst->attr_stride : NULL;
        uint32_t *an = dst->attr_n10 && m->attr_n10
                           ? dst->attr_n10 + (size_t)y * dst->attr_n10_stride
                           : NULL;
        for (int x = 0; x < m->width; x++) {
            int32_t i = src[x];
            if (i < 0 || m->mask[i] == 0) {
                /* nothing here: a pixel already clear stays untouched */
                if (mk[x] == 0) continue;
                mk[x] = 0;
                if (dp) dp[x] = 1.0f;
                if (at)
                    for (int k = 0; k < ac; k++) at[x * ac + k] = 0.0f;
                if (an) an[x] = 0;
                continue;
            }
            mk[x] = m->mask[i];
            set++;
            if (dp) dp[x] = m->depth[i];
            if (at)
                for (int k = 0; k < ac; k++) at[x * ac + k] = m->attr[(size_t)i * ac + k];
            if (an) an[x] = m->attr_n10[i];
        }
    }
    return set;
}
