/* raster_setup.c - per-triangle work shared by every scan path: validation,
 * homogeneous clipping, viewport, snapping, culling, edge and plane setup.
 * The rules and their bounds are written down in docs/raster.md. */
#include "raster_internal.h"

#include <math.h>
#include <stddef.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* ---- constants --------------------------------------------------------- */

void rast__view_init(rast__view *v, int width, int height, int attr_count)
{
    /* Guard factor g such that |x/w| <= g maps to sx in [-(G-1), W+G-1]:
     * sx = (x/w*0.5+0.5)*W = W/2*(1+g) = W+G-1  <=>  g = (W+2G-2)/W. The
     * one pixel kept in reserve absorbs rounding of the clipped vertices;
     * the snap clamp below makes the bound hard. */
    v->width = width;
    v->height = height;
    v->gx = (float)(width + 2 * RAST_GUARD_PX - 2) / (float)width;
    v->gy = (float)(height + 2 * RAST_GUARD_PX - 2) / (float)height;
    v->min_x = -RAST_GUARD_PX * RAST__FIX_ONE;
    v->max_x = (width + RAST_GUARD_PX) * RAST__FIX_ONE;
    v->min_y = -RAST_GUARD_PX * RAST__FIX_ONE;
    v->max_y = (height + RAST_GUARD_PX) * RAST__FIX_ONE;
    v->attr_count = attr_count;
}

/* ---- clipping ---------------------------------------------------------- */

/* Signed distance to plane i; >= 0 is inside. One fixed formula per plane
 * (float, no contraction), so the same vertex always gives the same value. */
static float plane_dist(const rast__view *v, const rast__vert *p, int i)
{
    switch (i) {
    case RAST__PLANE_NEAR:   return p->z + p->w;
    case RAST__PLANE_FAR:    return p->w - p->z;
    case RAST__PLANE_LEFT:   return v->gx * p->w + p->x;
    case RAST__PLANE_RIGHT:  return v->gx * p->w - p->x;
    case RAST__PLANE_BOTTOM: return v->gy * p->w + p->y;
    default:                 return v->gy * p->w - p->y;
    }
}

unsigned rast__outcode(const rast__view *v, const rast__vert *p)
{
    unsigned code = 0;
    for (int i = 0; i < RAST__PLANE_COUNT; i++)
        if (plane_dist(v, p, i) < 0.0f)
            code |= 1u << i;
    return code;
}

/* The point where edge (in, out) crosses the plane. Always computed from
 * the inside vertex towards the outside one, whatever the direction the
 * polygon walks the edge, so two triangles sharing the edge get the same
 * bits: t = d_in / (d_in - d_out); c = c_in + t * (c_out - c_in). */
static void intersect(const rast__vert *in, float d_in, const rast__vert *out,
                      float d_out, int attr_count, rast__vert *r)
{
    float t = d_in / (d_in - d_out);
    r->x = in->x + t * (out->x - in->x);
    r->y = in->y + t * (out->y - in->y);
    r->z = in->z + t * (out->z - in->z);
    r->w = in->w + t * (out->w - in->w);
    for (int k = 0; k < attr_count; k++)
        r->a[k] = in->a[k] + t * (out->a[k] - in->a[k]);
}

static int clip_plane(const rast__view *v, int plane, const rast__vert *src,
                      int n, rast__vert *dst)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const rast__vert *a = &src[i];
        const rast__vert *b = &src[i + 1 < n ? i + 1 : 0];
        float da = plane_dist(v, a, plane);
        float db = plane_dist(v, b, plane);
        int ina = da >= 0.0f, inb = db >= 0.0f;
        if (ina)
            dst[m++] = *a;
        if (ina && !inb)
            intersect(a, da, b, db, v->attr_count, &dst[m++]);
        else if (!ina && inb)
            intersect(b, db, a, da, v->attr_count, &dst[m++]);
    }
    return m;
}

int rast__clip_polygon(const rast__view *v, unsigned planes, rast__vert *poly,
                       int n, rast__vert *tmp)
{
    rast__vert *src = poly, *dst = tmp;
    for (int i = 0; i < RAST__PLANE_COUNT && n >= 3; i++) {
        if (!(planes & (1u << i)))
            continue;
        n = clip_plane(v, i, src, n, dst);
        rast__vert *s = src;
        src = dst;
        dst = s;
    }
    if (n < 3)
        return 0;
    if (src != poly)
        for (int i = 0; i < n; i++)
            poly[i] = src[i];
    return n;
}

/* ---- viewport and snapping --------------------------------------------- */

static int32_t snap_axis(float s, int32_t lo, int32_t hi)
{
    /* s * 256 is exact (power of two). Clamping before rounding equals
     * clamping after, because lo and hi are integers. */
    float f = s * (float)RAST__FIX_ONE;
    if (f < (float)lo) f = (float)lo;
    if (f > (float)hi) f = (float)hi;
#if defined(__SSE2__)
    /* cvtss2si rounds in the current mode (half to even by default), as
     * lrintf does, without a libm call. f is in range (clamped above). */
    return (int32_t)_mm_cvtss_si32(_mm_set_ss(f));
#else
    return (int32_t)lrintf(f);   /* round half to even (default mode) */
#endif
}

void rast__snap(const rast__view *v, const rast__vert *p, int32_t *fx,
                int32_t *fy)
{
    float nx = p->x / p->w;
    float ny = p->y / p->w;
    float sx = (nx * 0.5f + 0.5f) * (float)v->width;
    float sy = (0.5f - ny * 0.5f) * (float)v->height;
    *fx = snap_axis(sx, v->min_x, v->max_x);
    *fy = snap_axis(sy, v->min_y, v->max_y);
}

/* ---- triangle setup ---------------------------------------------------- */

/* floor(a / 256) for any sign. */
static int64_t floor_fix(int64_t a)
{
    int64_t q = a / RAST__FIX_ONE;
    if (a % RAST__FIX_ONE != 0 && a < 0)
        q--;
    return q;
}

/* Plane through (X_i, Y_i, f_i) in pixel units, in double, stored as
 * float: value at (cx, cy) and the gradient. area = ex1*ey2 - ex2*ey1. */
static void plane_setup(const double X[3], const double Y[3], double area,
                        double f0, double f1, double f2, double cx, double cy,
                        rast__plane *pl)
{
    double ex1 = X[1] - X[0], ey1 = Y[1] - Y[0];
    double ex2 = X[2] - X[0], ey2 = Y[2] - Y[0];
    double df1 = f1 - f0, df2 = f2 - f0;
    double gx = (df1 * ey2 - df2 * ey1) / area;
    double gy = (df2 * ex1 - df1 * ex2) / area;
    double c = (f0 + gx * (cx - X[0])) + gy * (cy - Y[0]);
    pl->c = (float)c;
    pl->dx = (float)gx;
    pl->dy = (float)gy;
}

int rast__setup_tri(const rast__view *v, const rast__vert *const p[3],
                    const int32_t fx[3], const int32_t fy[3], rast_cull cull,
                    rast__tri *tri)
{
    /* Twice the signed area in 1/65536 pixel^2; every coordinate lies in
     * [-2^21, 2^22], so each product is below 2^46 (docs/raster.md). */
    int64_t area = (int64_t)(fx[1] - fx[0]) * (fy[2] - fy[0]) -
                   (int64_t)(fy[1] - fy[0]) * (fx[2] - fx[0]);
    if (area == 0)
        return RAST__SETUP_DEGENERATE;
    /* The viewport flips y, so a triangle counter-clockwise in NDC (front,
     * as OpenGL) has a negative area in screen coordinates (y down). */
    int front = area < 0;
    if ((cull == RAST_CULL_BACK && !front) || (cull == RAST_CULL_FRONT && front))
        return RAST__SETUP_CULLED;

    /* Normalise to area > 0 (clockwise on the screen, y down): then the
     * interior is where every edge function is positive. */
    int o[3] = { 0, 1, 2 };
    if (area < 0) {
        o[1] = 2;
        o[2] = 1;
        area = -area;
    }
    int64_t X[3], Y[3];
    for (int i = 0; i < 3; i++) {
        X[i] = fx[o[i]];
        Y[i] = fy[o[i]];
    }

    /* Pixel bounding box: pixel x is a candidate iff xmin <= 256x+128 <= xmax. */
    int64_t xmin = X[0], xmax = X[0], ymin = Y[0], ymax = Y[0];
    for (int i = 1; i < 3; i++) {
        if (X[i] < xmin) xmin = X[i];
        if (X[i] > xmax) xmax = X[i];
        if (Y[i] < ymin) ymin = Y[i];
        if (Y[i] > ymax) ymax = Y[i];
    }
    int64_t bx0 = floor_fix(xmin - RAST__FIX_HALF + RAST__FIX_ONE - 1);
    int64_t bx1 = floor_fix(xmax - RAST__FIX_HALF);
    int64_t by0 = floor_fix(ymin - RAST__FIX_HALF + RAST__FIX_ONE - 1);
    int64_t by1 = floor_fix(ymax - RAST__FIX_HALF);
    if (bx0 < 0) bx0 = 0;
    if (by0 < 0) by0 = 0;
    if (bx1 > v->width - 1) bx1 = v->width - 1;
    if (by1 > v->height - 1) by1 = v->height - 1;
    if (bx0 > bx1 || by0 > by1)
        return RAST__SETUP_OFFSCREEN;
    tri->x0 = (int)bx0;
    tri->y0 = (int)by0;
    tri->x1 = (int)bx1;
    tri->y1 = (int)by1;

    /* Edge k runs from vertex k+1 to vertex k+2 (opposite vertex k):
     * E(p) = dx*(py - ya) - dy*(px - xa), positive inside. Top-left rule:
     * with this winding an edge is top (dy == 0, dx > 0) or left (dy < 0);
     * those keep E == 0, the others get a -1 bias so that E == 0 fails the
     * sign test. */
    int64_t cx = bx0 * RAST__FIX_ONE + RAST__FIX_HALF;
    int64_t cy = by0 * RAST__FIX_ONE + RAST__FIX_HALF;
    for (int k = 0; k < 3; k++) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        int64_t dx = X[b] - X[a], dy = Y[b] - Y[a];
        int top_left = dy < 0 || (dy == 0 && dx > 0);
        tri->e_c[k] = dx * (cy - Y[a]) - dy * (cx - X[a]) - (top_left ? 0 : 1);
        tri->e_dx[k] = -dy * RAST__FIX_ONE;
        tri->e_dy[k] = dx * RAST__FIX_ONE;
    }

    /* Float planes, set up in double from the snapped positions (exact in
     * double) and stored as float. The origin is the centre of (x0, y0). */
    double Xd[3], Yd[3];
    for (int i = 0; i < 3; i++) {
        Xd[i] = (double)X[i] / RAST__FIX_ONE;
        Yd[i] = (double)Y[i] / RAST__FIX_ONE;
    }
    double aread = (double)area / ((double)RAST__FIX_ONE * RAST__FIX_ONE);
    double ocx = (double)bx0 + 0.5, ocy = (double)by0 + 0.5;
    double zw[3], q[3], qmax = 0.0;
    for (int i = 0; i < 3; i++) {
        const rast__vert *pv = p[o[i]];
        zw[i] = ((double)pv->z / (double)pv->w) * 0.5 + 0.5;
        q[i] = 1.0 / (double)pv->w;
        if (q[i] > qmax) qmax = q[i];
    }
    for (int i = 0; i < 3; i++)
        q[i] = q[i] / qmax;
    plane_setup(Xd, Yd, aread, zw[0], zw[1], zw[2], ocx, ocy, &tri->z);
    plane_setup(Xd, Yd, aread, q[0], q[1], q[2], ocx, ocy, &tri->q);
    plane_setup(Xd, Yd, aread, 0.0, q[1], 0.0, ocx, ocy, &tri->b1);
    plane_setup(Xd, Yd, aread, 0.0, 0.0, q[2], ocx, ocy, &tri->b2);
    tri->attr_count = v->attr_count;
    for (int k = 0; k < v->attr_count; k++) {
        const float a0 = p[o[0]]->a[k];
        tri->a0[k] = a0;
        tri->d1[k] = p[o[1]]->a[k] - a0;
        tri->d2[k] = p[o[2]]->a[k] - a0;
    }
    return RAST__SETUP_OK;
}

/* ---- validation and the driver ----------------------------------------- */

rast_result rast__validate(const rast_target *t, const rast_mesh_desc *m)
{
    if (!t || !m || !t->mask)
        return RAST_ERR_ARGS;
    if (t->width <= 0 || t->height <= 0 || t->width > RAST_MAX_DIM ||
        t->height > RAST_MAX_DIM)
        return RAST_ERR_SIZE;
    if (t->mask_stride < t->width || (t->depth && t->depth_stride < t->width))
        return RAST_ERR_ARGS;
    if (t->attr_count < 0 || t->attr_count > RAST_MAX_ATTRS ||
        m->attr_count != t->attr_count)
        return RAST_ERR_ARGS;
    if (t->attr && t->attr_count > 0 && t->attr_stride < t->width * t->attr_count)
        return RAST_ERR_ARGS;
    if (m->vertex_count < 0 || m->tri_count < 0)
        return RAST_ERR_ARGS;
    if ((m->vertex_count > 0 && !m->clip) || (m->tri_count > 0 && !m->indices))
        return RAST_ERR_ARGS;
    if (m->attr_count > 0 && m->vertex_count > 0 && !m->attr)
        return RAST_ERR_ARGS;
    if (m->cull != RAST_CULL_NONE && m->cull != RAST_CULL_BACK &&
        m->cull != RAST_CULL_FRONT)
        return RAST_ERR_ARGS;
    for (long i = 0; i < 3L * m->tri_count; i++)
        if (m->indices[i] >= (uint32_t)m->vertex_count)
            return RAST_ERR_INDEX;
    return RAST_OK;
}

static int finite_vert(const rast__vert *p)
{
    return isfinite(p->x) && isfinite(p->y) && isfinite(p->z) && isfinite(p->w);
}

int rast__prepare(const rast__view *view, const rast_mesh_desc *m, int ti,
                  rast__tri *out, rast_stats *st)
{
    const int na = view->attr_count;
    rast__vert poly[RAST__MAX_POLY], tmp[RAST__MAX_POLY];
    int32_t fx[RAST__MAX_POLY], fy[RAST__MAX_POLY];
    int bad = 0;
    for (int i = 0; i < 3; i++) {
        uint32_t idx = m->indices[3 * (size_t)ti + i];
        const float *c = m->clip + 4 * (size_t)idx;
        rast__vert *pv = &poly[i];
        pv->x = c[0];
        pv->y = c[1];
        pv->z = c[2];
        pv->w = c[3];
        for (int k = 0; k < na; k++)
            pv->a[k] = m->attr[(size_t)idx * m->attr_count + k];
        bad |= !finite_vert(pv);
    }
    if (bad) {
        st->tris_nonfinite++;
        return 0;
    }
    unsigned c0 = rast__outcode(view, &poly[0]);
    unsigned c1 = rast__outcode(view, &poly[1]);
    unsigned c2 = rast__outcode(view, &poly[2]);
    if (c0 & c1 & c2) {
        st->tris_clipped_away++;
        return 0;
    }
    int n = 3;
    if (c0 | c1 | c2)
        n = rast__clip_polygon(view, c0 | c1 | c2, poly, n, tmp);
    /* After near and far, w >= |z| >= 0 for every vertex; w == 0 only
     * at the clip-space origin (x = y = z = w = 0), which has no
     * projection: such polygons are dropped here, before the divide.
     * Overflow in the clipper (|coords| near FLT_MAX) is caught too. */
    int state = n >= 3 ? 0 : 1;          /* 0 ok, 1 clipped, 2 nonfinite */
    for (int i = 0; i < n && state == 0; i++) {
        if (!finite_vert(&poly[i]))
            state = 2;
        else if (!(poly[i].w > 0.0f))
            state = 1;
    }
    if (state == 1) {
        st->tris_clipped_away++;
        return 0;
    }
    if (state == 2) {
        st->tris_nonfinite++;
        return 0;
    }
    for (int i = 0; i < n; i++)
        rast__snap(view, &poly[i], &fx[i], &fy[i]);
    int made = 0;
    for (int i = 1; i + 1 < n; i++) {
        const rast__vert *pv[3] = { &poly[0], &poly[i], &poly[i + 1] };
        int32_t tx[3] = { fx[0], fx[i], fx[i + 1] };
        int32_t ty[3] = { fy[0], fy[i], fy[i + 1] };
        switch (rast__setup_tri(view, pv, tx, ty, m->cull, &out[made])) {
        case RAST__SETUP_OK:
            st->tris_drawn++;
            made++;
            break;
        case RAST__SETUP_DEGENERATE: st->tris_degenerate++; break;
        case RAST__SETUP_CULLED:     st->tris_culled++; break;
        default:                     st->tris_clipped_away++; break;
        }
    }
    return made;
}

void rast__stats_add(rast_stats *dst, const rast_stats *s)
{
    dst->tris_in += s->tris_in;
    dst->tris_nonfinite += s->tris_nonfinite;
    dst->tris_clipped_away += s->tris_clipped_away;
    dst->tris_degenerate += s->tris_degenerate;
    dst->tris_culled += s->tris_culled;
    dst->tris_drawn += s->tris_drawn;
    dst->pixels_written += s->pixels_written;
}

int rast__draw_na(const rast_target *t, const rast_mesh_desc *m)
{
    /* Attributes go through clipping only if both sides have them. */
    return (t->attr && m->attr) ? m->attr_count : 0;
}

rast_result rast__draw_with(const rast_target *t, const rast_mesh_desc *m,
                            rast_stats *stats, rast__scan_rows_fn scan)
{
    rast_result r = rast__validate(t, m);
    if (r != RAST_OK)
        return r;

    rast__view view;
    rast__view_init(&view, t->width, t->height, rast__draw_na(t, m));
    rast_stats st = { 0 };
    st.tris_in = m->tri_count;
    rast__tri tri[RAST__MAX_FAN];
    for (int ti = 0; ti < m->tri_count; ti++) {
        int n = rast__prepare(&view, m, ti, tri, &st);
        for (int i = 0; i < n; i++)
            st.pixels_written += scan(t, &tri[i], tri[i].y0, tri[i].y1);
    }
    if (stats)
        rast__stats_add(stats, &st);
    return RAST_OK;
}
