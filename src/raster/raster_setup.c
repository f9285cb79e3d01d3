/* raster_setup.c - per-triangle work shared by every scan path: validation,
 * homogeneous clipping, viewport, snapping, culling, edge and plane setup,
 * the vertex cache and the set-up of a range of submitted triangles (with
 * the set-up kernels of an ISA it is given), the anti-aliasing sample
 * patterns. The bottom layer of the room: it calls no other raster file
 * (the draw driver is raster_draw.c, the dispatch raster_context.c). The
 * rules and their bounds are written down in docs/raster.md. */
#include "raster_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* The magic-number rounding of snap_axis needs float arithmetic in float
 * (no x87 excess precision). */
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "raster_setup.c needs FLT_EVAL_METHOD == 0 (SSE2 or NEON float arithmetic)"
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
    v->hz = NULL;
}

/* ---- clipping ---------------------------------------------------------- */

/* Signed distance to each plane (>= 0 inside): one fixed formula per
 * plane (float, no contraction; the table of RAST__PLANE_*), so the same
 * vertex always gives the same value. */
static inline unsigned outcode_inl(const rast__view *v, const rast__vert *p)
{
    /* The six distances (the same float expressions as clip_plane's, so
     * the same bits), tested without branches. */
    const float x = p->x, y = p->y, z = p->z, w = p->w;
    const float gxw = v->gx * w, gyw = v->gy * w;
    return (unsigned)((z + w) < 0.0f) << RAST__PLANE_NEAR |
           (unsigned)((w - z) < 0.0f) << RAST__PLANE_FAR |
           (unsigned)((gxw + x) < 0.0f) << RAST__PLANE_LEFT |
           (unsigned)((gxw - x) < 0.0f) << RAST__PLANE_RIGHT |
           (unsigned)((gyw + y) < 0.0f) << RAST__PLANE_BOTTOM |
           (unsigned)((gyw - y) < 0.0f) << RAST__PLANE_TOP;
}

unsigned rast__outcode(const rast__view *v, const rast__vert *p)
{
    return outcode_inl(v, p);
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
    /* Each vertex's distance once (every vertex starts one edge and ends
     * another), as k*w + s*c with the plane's k (1, gx or gy), sign s and
     * coordinate c chosen once: 1*w = w, (-1)*c = -c and a - b = a + (-b)
     * are exact and the sum commutes, so every d has the bits of the
     * plane's formula. */
    float d[RAST__MAX_POLY];
    const float k = plane <= RAST__PLANE_FAR ? 1.0f : plane <= RAST__PLANE_RIGHT ? v->gx : v->gy;
    const float sg = (plane & 1) ? -1.0f : 1.0f;
    const int axis = plane <= RAST__PLANE_FAR ? 2 : plane <= RAST__PLANE_RIGHT ? 0 : 1;
    for (int i = 0; i < n; i++) {
        const float c[3] = { src[i].x, src[i].y, src[i].z };
        d[i] = k * src[i].w + sg * c[axis];
    }
    int m = 0;
    for (int i = 0; i < n; i++) {
        const int j = i + 1 < n ? i + 1 : 0;
        const rast__vert *a = &src[i];
        const rast__vert *b = &src[j];
        const float da = d[i], db = d[j];
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
    /* The planes in order, over the set bits only (mostly one or two). */
    for (unsigned left = planes & ((1u << RAST__PLANE_COUNT) - 1u); left && n >= 3;
         left &= left - 1) {
        n = clip_plane(v, __builtin_ctz(left), src, n, dst);
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
    /* Round half to even (the default mode), as lrintf and cvtss2si do,
     * without a libm call or an intrinsic: |f| <= 2^22 after the clamp
     * (lo >= -2^21, hi <= 2^22, section 2 of docs/raster.md), and for
     * |f| <= 2^22 the sum f + 1.5 * 2^23 lies in [2^23, 2^24], where the
     * float grid is 1, so the addition rounds f to an integer in the
     * current mode and the subtraction is exact. */
    const float magic = 12582912.0f; /* 1.5 * 2^23 */
    return (int32_t)((f + magic) - magic);
}

static inline void snap_inl(const rast__view *v, const rast__vert *p, int32_t *fx,
                            int32_t *fy)
{
    float nx = p->x / p->w;
    float ny = p->y / p->w;
    float sx = (nx * 0.5f + 0.5f) * (float)v->width;
    float sy = (0.5f - ny * 0.5f) * (float)v->height;
    *fx = snap_axis(sx, v->min_x, v->max_x);
    *fy = snap_axis(sy, v->min_y, v->max_y);
}

void rast__snap(const rast__view *v, const rast__vert *p, int32_t *fx,
                int32_t *fy)
{
    snap_inl(v, p, fx, fy);
}

/* ---- triangle setup ---------------------------------------------------- */

#if defined(__GNUC__) || defined(__clang__)
#define RAST__NOINLINE __attribute__((noinline))
#else
#define RAST__NOINLINE
#endif

/* The four planes of a triangle (z, q, b1, b2) in double, stored as
 * float: value at (cx, cy) and the gradient, area = ex1*ey2 - ex2*ey1.
 * Per plane, with vertex values f0, f1, f2 (docs/raster.md section 6.1):
 *   df1 = f1 - f0; df2 = f2 - f0;
 *   gx = (df1*ey2 - df2*ey1) / area;  gy = (df2*ex1 - df1*ex2) / area;
 *   c  = (f0 + gx*(cx - X0)) + gy*(cy - Y0)
 * The four planes share the geometry, so they are computed as the four
 * lanes of one vector: every lane runs exactly these IEEE double
 * operations (no contraction: -ffp-contract=off), so the result is the
 * bits of four scalar evaluations, with two vector divisions instead of
 * eight scalar ones. */
#if defined(__GNUC__) || defined(__clang__)
typedef double v4d __attribute__((vector_size(32)));
typedef float v4f __attribute__((vector_size(16)));

static void planes_setup(const double X[3], const double Y[3], double area,
                         const v4d *pf0, const v4d *pf1, const v4d *pf2, double cx,
                         double cy, rast__tri *tri)
{
    const v4d f0 = *pf0, f1 = *pf1, f2 = *pf2;
    const double ex1 = X[1] - X[0], ey1 = Y[1] - Y[0];
    const double ex2 = X[2] - X[0], ey2 = Y[2] - Y[0];
    const double ox = cx - X[0], oy = cy - Y[0];
    const v4d df1 = f1 - f0, df2 = f2 - f0;
    const v4d gx = (df1 * ey2 - df2 * ey1) / area;
    const v4d gy = (df2 * ex1 - df1 * ex2) / area;
    const v4d c = (f0 + gx * ox) + gy * oy;
    const v4f fc = __builtin_convertvector(c, v4f);
    const v4f fgx = __builtin_convertvector(gx, v4f);
    const v4f fgy = __builtin_convertvector(gy, v4f);
    rast__plane *pl[4] = { &tri->z, &tri->q, &tri->b1, &tri->b2 };
    for (int i = 0; i < 4; i++) {
        pl[i]->c = fc[i];
        pl[i]->dx = fgx[i];
        pl[i]->dy = fgy[i];
    }
}
#define PLANES_SETUP(X, Y, area, zw, q, cx, cy, tri)                           \
    do {                                                                      \
        const v4d f0_ = { zw[0], q[0], 0.0, 0.0 }, f1_ = { zw[1], q[1], q[1], 0.0 }, \
                  f2_ = { zw[2], q[2], 0.0, q[2] };                           \
        planes_setup(X, Y, area, &f0_, &f1_, &f2_, cx, cy, tri);              \
    } while (0)
#else
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
#define PLANES_SETUP(X, Y, area, zw, q, cx, cy, tri)                           \
    do {                                                                      \
        plane_setup(X, Y, area, zw[0], zw[1], zw[2], cx, cy, &(tri)->z);      \
        plane_setup(X, Y, area, q[0], q[1], q[2], cx, cy, &(tri)->q);         \
        plane_setup(X, Y, area, 0.0, q[1], 0.0, cx, cy, &(tri)->b1);          \
        plane_setup(X, Y, area, 0.0, 0.0, q[2], cx, cy, &(tri)->b2);          \
    } while (0)
#endif

/* Twice the signed area of the snapped triangle in 1/65536 pixel^2; every
 * coordinate lies in [-2^21, 2^22], so each product is below 2^46
 * (docs/raster.md). The viewport flips y, so a triangle counter-clockwise
 * in NDC (front, as OpenGL) has a negative area (y down). */
static inline int64_t snapped_area(int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                                   int32_t x2, int32_t y2)
{
    return (int64_t)(x1 - x0) * (y2 - y0) - (int64_t)(y1 - y0) * (x2 - x0);
}

/* RAST__SETUP_OK, _DEGENERATE or _CULLED for a signed snapped area. */
static inline int area_test(int64_t area, rast_cull cull)
{
    if (area == 0)
        return RAST__SETUP_DEGENERATE;
    const int front = area < 0;
    if ((cull == RAST_CULL_BACK && !front) || (cull == RAST_CULL_FRONT && front))
        return RAST__SETUP_CULLED;
    return RAST__SETUP_OK;
}

/* The area test of triangle fx, fy (area_test); when it passes, *area
 * the absolute snapped area and X, Y the vertices normalised to area > 0
 * by swapping vertices 1 and 2, whose source indices go to *s1, *s2. */
static inline int orient(const int32_t fx[3], const int32_t fy[3], rast_cull cull,
                         int64_t *area, int *s1, int *s2, int32_t X[3], int32_t Y[3])
{
    const int64_t a = snapped_area(fx[0], fy[0], fx[1], fy[1], fx[2], fy[2]);
    const int r = area_test(a, cull);
    if (r != RAST__SETUP_OK)
        return r;
    *s1 = a < 0 ? 2 : 1, *s2 = a < 0 ? 1 : 2;
    X[0] = fx[0], X[1] = fx[*s1], X[2] = fx[*s2];
    Y[0] = fy[0], Y[1] = fy[*s1], Y[2] = fy[*s2];
    *area = a < 0 ? -a : a;
    return RAST__SETUP_OK;
}

/* Clamps the pixel box x0..x1, y0..y1 (inclusive) to the view; 0 when
 * nothing of it is left (the triangle is off the screen). */
static inline int box_in_view(const rast__view *v, int32_t *x0, int32_t *y0, int32_t *x1,
                              int32_t *y1)
{
    *x0 = *x0 < 0 ? 0 : *x0;
    *y0 = *y0 < 0 ? 0 : *y0;
    *x1 = *x1 > v->width - 1 ? v->width - 1 : *x1;
    *y1 = *y1 > v->height - 1 ? v->height - 1 : *y1;
    return *x0 <= *x1 && *y0 <= *y1;
}

/* Bounds of the snapped vertices. */
static inline void snapped_bounds(const int32_t X[3], const int32_t Y[3], int32_t *xmin,
                                  int32_t *xmax, int32_t *ymin, int32_t *ymax)
{
    *xmin = *xmax = X[0];
    *ymin = *ymax = Y[0];
    for (int i = 1; i < 3; i++) {
        *xmin = X[i] < *xmin ? X[i] : *xmin;
        *xmax = X[i] > *xmax ? X[i] : *xmax;
        *ymin = Y[i] < *ymin ? Y[i] : *ymin;
        *ymax = Y[i] > *ymax ? Y[i] : *ymax;
    }
}

/* The pixel box and the edge functions of a triangle of positive area.
 * Edge k runs from vertex k+1 to vertex k+2 (opposite vertex k):
 * E(p) = dx*(py - ya) - dy*(px - xa), positive inside, evaluated at the
 * centre of the box's first pixel. Top-left rule: with this winding an
 * edge is top (dy == 0, dx > 0) or left (dy < 0); those keep E == 0, the
 * others get a -1 bias so that E == 0 fails the sign test. Deltas and
 * offsets are below 2^24, products below 2^47. */
static inline void setup_edges(rast__tri *tri, const int32_t X[3], const int32_t Y[3],
                               int32_t bx0, int32_t by0, int32_t bx1, int32_t by1)
{
    tri->x0 = bx0;
    tri->y0 = by0;
    tri->x1 = bx1;
    tri->y1 = by1;
    tri->micro = 0;
    const int32_t cx = bx0 * RAST__FIX_ONE + RAST__FIX_HALF;
    const int32_t cy = by0 * RAST__FIX_ONE + RAST__FIX_HALF;
    static const int ea[3] = { 1, 2, 0 }, eb[3] = { 2, 0, 1 };
    for (int k = 0; k < 3; k++) {
        const int a = ea[k], b = eb[k];
        const int32_t dx = X[b] - X[a], dy = Y[b] - Y[a];
        const int top_left = dy < 0 || (dy == 0 && dx > 0);
        tri->e_c[k] = (int64_t)dx * (cy - Y[a]) - (int64_t)dy * (cx - X[a]) -
                      (top_left ? 0 : 1);
        tri->e_dx[k] = -(int64_t)dy * RAST__FIX_ONE;
        tri->e_dy[k] = (int64_t)dx * RAST__FIX_ONE;
    }
}

/* The pixel box and the edges of a triangle already normalised to area
 * > 0 (clockwise on the screen, y down: the interior is where every edge
 * function is positive) with snapped positions X, Y: RAST__SETUP_OK,
 * _OFFSCREEN or _EMPTY. */
static inline int setup_box_edges(const rast__view *v, const int32_t X[3],
                                  const int32_t Y[3], rast__tri *tri)
{
    /* Pixel bounding box: pixel x is a candidate iff xmin <= 256x+128 <= xmax,
     * i.e. x0 = floor((xmin - 128 + 255) / 256), x1 = floor((xmax - 128) / 256)
     * (|X| < 2^23: int32, and >> is a floor division for the arithmetic
     * shift of gcc, clang and msvc). */
    int32_t xmin, xmax, ymin, ymax;
    snapped_bounds(X, Y, &xmin, &xmax, &ymin, &ymax);
    int32_t bx0 = (xmin - RAST__FIX_HALF + RAST__FIX_ONE - 1) >> RAST_SUBPIXEL_BITS;
    int32_t bx1 = (xmax - RAST__FIX_HALF) >> RAST_SUBPIXEL_BITS;
    int32_t by0 = (ymin - RAST__FIX_HALF + RAST__FIX_ONE - 1) >> RAST_SUBPIXEL_BITS;
    int32_t by1 = (ymax - RAST__FIX_HALF) >> RAST_SUBPIXEL_BITS;
    if (!box_in_view(v, &bx0, &by0, &bx1, &by1))
        return RAST__SETUP_OFFSCREEN;
    setup_edges(tri, X, Y, bx0, by0, bx1, by1);
    /* A box of at most 2x2 pixels none of whose centres is inside (at
     * 10k triangles a third of the triangles the bench model used to
     * scan; one-pixel boxes only until the ninth round, docs/raster.md
     * section 11): the scan would write nothing, so the planes are not
     * set up and the triangle is not scanned; it still counts as drawn
     * (the counters of the full path). */
    if (bx1 - bx0 <= 1 && by1 - by0 <= 1) {
        for (int j = 0; j <= by1 - by0; j++)
            for (int i = 0; i <= bx1 - bx0; i++)
                if (((tri->e_c[0] + i * tri->e_dx[0] + j * tri->e_dy[0]) |
                     (tri->e_c[1] + i * tri->e_dx[1] + j * tri->e_dy[1]) |
                     (tri->e_c[2] + i * tri->e_dx[2] + j * tri->e_dy[2])) >= 0)
                    return RAST__SETUP_OK;
        return RAST__SETUP_EMPTY;
    }
    return RAST__SETUP_OK;
}

/* The float planes of one triangle from the double inputs of
 * rast__pbatch (docs/raster.md section 6.1). The one definition of the
 * planes' bits: rast__planes_ref runs it per triangle, the SIMD planes
 * functions per lane. */
static void planes_one(const double Xd[3], const double Yd[3], double aread,
                       const double zwv[3], const double iwv[3], double ocx,
                       double ocy, rast__tri *tri)
{
    double qmax = 0.0;
    for (int i = 0; i < 3; i++)
        if (iwv[i] > qmax) qmax = iwv[i];
    const double q[3] = { iwv[0] / qmax, iwv[1] / qmax, iwv[2] / qmax };
    PLANES_SETUP(Xd, Yd, aread, zwv, q, ocx, ocy, tri);
}

/* The plane inputs in double (exact conversions of the snapped values). */
static inline void plane_inputs(const int32_t X[3], const int32_t Y[3], int64_t area,
                                const rast__tri *tri, double Xd[3], double Yd[3],
                                double *aread, double *ocx, double *ocy)
{
    for (int i = 0; i < 3; i++) {
        Xd[i] = (double)X[i] / RAST__FIX_ONE;
        Yd[i] = (double)Y[i] / RAST__FIX_ONE;
    }
    *aread = (double)area / ((double)RAST__FIX_ONE * RAST__FIX_ONE);
    *ocx = (double)tri->x0 + 0.5;
    *ocy = (double)tri->y0 + 0.5;
}

static inline void setup_attrs(const rast__view *v, const float *const attr[3],
                               rast__tri *tri)
{
    tri->attr_count = v->attr_count;
    for (int k = 0; k < v->attr_count; k++) {
        const float a0 = attr[0][k];
        tri->a0[k] = a0;
        tri->d1[k] = attr[1][k] - a0;
        tri->d2[k] = attr[2][k] - a0;
    }
}

/* The rest of the setup for a triangle already normalised to area > 0:
 * snapped positions X, Y, per-vertex plane inputs zw_i = (z/w)*0.5+0.5
 * and iw_i = 1/w (double) and attributes (attr_count floats per vertex,
 * unused when 0), all in that order. */
static int setup_oriented(const rast__view *v, const int32_t X[3], const int32_t Y[3],
                          int64_t area, const double zwv[3], const double iwv[3],
                          const float *const attr[3], rast__tri *tri)
{
    const int r = setup_box_edges(v, X, Y, tri);
    if (r != RAST__SETUP_OK)
        return r;
    /* Float planes, set up in double from the snapped positions (exact in
     * double) and stored as float. The origin is the centre of (x0, y0). */
    double Xd[3], Yd[3], aread, ocx, ocy;
    plane_inputs(X, Y, area, tri, Xd, Yd, &aread, &ocx, &ocy);
    planes_one(Xd, Yd, aread, zwv, iwv, ocx, ocy, tri);
    setup_attrs(v, attr, tri);
    return RAST__SETUP_OK;
}

const rast__setup_isa rast__setup_isa_ref = { rast__planes_ref, rast__vfill_ref, NULL, NULL,
                                               NULL };

void rast__planes_ref(rast__pbatch *b)
{
    for (int i = 0; i < b->n; i++) {
        const double X[3] = { b->X[0][i], b->X[1][i], b->X[2][i] };
        const double Y[3] = { b->Y[0][i], b->Y[1][i], b->Y[2][i] };
        const double zw[3] = { b->zw[0][i], b->zw[1][i], b->zw[2][i] };
        const double iw[3] = { b->iw[0][i], b->iw[1][i], b->iw[2][i] };
        planes_one(X, Y, b->area[i], zw, iw, b->cx[i], b->cy[i], b->tri[i]);
    }
    b->n = 0;
}

/* Per-vertex plane inputs (docs/raster.md section 6.1). */
static double vert_zw(const rast__vert *p)
{
    return ((double)p->z / (double)p->w) * 0.5 + 0.5;
}

static double vert_iw(const rast__vert *p)
{
    return 1.0 / (double)p->w;
}

int rast__setup_tri(const rast__view *v, const rast__vert *const p[3],
                    const int32_t fx[3], const int32_t fy[3], rast_cull cull,
                    rast__tri *tri)
{
    /* The area test first: the plane inputs (two divisions per vertex)
     * only for the pieces it keeps (with back faces culled, about half of
     * the clipped fans' pieces are dropped here). */
    int64_t area;
    int s1, s2;
    int32_t X[3], Y[3];
    const int r = orient(fx, fy, cull, &area, &s1, &s2, X, Y);
    if (r != RAST__SETUP_OK)
        return r;
    const rast__vert *const q[3] = { p[0], p[s1], p[s2] };
    double zw[3], iw[3];
    const float *attr[3];
    for (int i = 0; i < 3; i++) {
        zw[i] = vert_zw(q[i]);
        iw[i] = vert_iw(q[i]);
        attr[i] = q[i]->a;
    }
    return setup_oriented(v, X, Y, area, zw, iw, attr, tri);
}

/* ---- validation and the driver ----------------------------------------- */

rast_result rast__validate(const rast_target *t, const rast_mesh_desc *m)
{
    const rast_result r = rast__validate_desc(t, m);
    return r != RAST_OK ? r : rast__validate_indices(m);
}

rast_result rast__validate_desc(const rast_target *t, const rast_mesh_desc *m)
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
    if (t->attr_n10 && (t->attr || t->attr_count != 3 || t->attr_n10_stride < t->width))
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
    return RAST_OK;
}

rast_result rast__validate_indices(const rast_mesh_desc *m)
{
    /* Every index below the vertex count, without a branch per index
     * (unsigned idx > nv - 1). */
    const size_t ni = 3 * (size_t)m->tri_count;
    if (ni == 0)
        return RAST_OK;
    if (m->vertex_count == 0)
        return RAST_ERR_INDEX;
    const uint32_t last = (uint32_t)m->vertex_count - 1u;
    uint32_t bad = 0;
    size_t i = 0;
    /* Sixteen lanes of or-ed compares, as four groups of four: the
     * compilers turn each group into one vector compare per four indices
     * (the SSE2 code this file had by hand), the loop's own instructions
     * paid once per sixteen; any other target gets the scalar loop. */
    uint32_t a0[4] = { 0 }, a1[4] = { 0 }, a2[4] = { 0 }, a3[4] = { 0 };
    for (; i + 16 <= ni; i += 16) {
        const uint32_t *p = m->indices + i;
        for (int k = 0; k < 4; k++) {
            a0[k] |= (uint32_t)-(uint32_t)(p[k] > last);
            a1[k] |= (uint32_t)-(uint32_t)(p[4 + k] > last);
            a2[k] |= (uint32_t)-(uint32_t)(p[8 + k] > last);
            a3[k] |= (uint32_t)-(uint32_t)(p[12 + k] > last);
        }
    }
    for (int k = 0; k < 4; k++)
        bad |= (a0[k] | a1[k]) | (a2[k] | a3[k]);
    for (; i < ni; i++)
        bad |= (uint32_t)(m->indices[i] > last);
    return bad ? RAST_ERR_INDEX : RAST_OK;
}

static int finite_vert(const rast__vert *p)
{
    /* isfinite of each coordinate (|c| <= FLT_MAX is false for NaN and
     * infinities), without a branch per coordinate. */
    return (fabsf(p->x) <= FLT_MAX) & (fabsf(p->y) <= FLT_MAX) & (fabsf(p->z) <= FLT_MAX) &
           (fabsf(p->w) <= FLT_MAX);
}

/* Fetch, clip and snap submitted triangle ti: the snapped polygon (fx, fy;
 * vertices in poly) and its vertex count, or 0 when the triangle is
 * dropped (counted in *st). */
static int clip_snap(const rast__view *view, const rast_mesh_desc *m, int ti,
                     rast__vert *poly, int32_t *fx, int32_t *fy, rast_stats *st)
{
    const int na = view->attr_count;
    rast__vert tmp[RAST__MAX_POLY];
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
    return n;
}

static int count_setup(int r, rast_stats *st)
{
    switch (r) {
    case RAST__SETUP_OK:         st->tris_drawn++; return 1;
    case RAST__SETUP_EMPTY:      st->tris_drawn++; return 0;
    case RAST__SETUP_DEGENERATE: st->tris_degenerate++; return 0;
    case RAST__SETUP_CULLED:     st->tris_culled++; return 0;
    default:                     st->tris_clipped_away++; return 0;
    }
}

static int setup_aa(const rast__view *v, const int32_t fx[3], const int32_t fy[3],
                    rast_cull cull, rast__tri *tri);

/* The fan of one submitted triangle after clip_snap, each piece set up by
 * rast__setup_tri (aa = 0) or setup_aa (aa = 1, the sample scan's set-up)
 * and counted; returns the records made. */
static inline __attribute__((always_inline)) int prepare_fan(const rast__view *view,
                                                             const rast_mesh_desc *m, int ti,
                                                             rast__tri *out, rast_stats *st,
                                                             int aa)
{
    rast__vert poly[RAST__MAX_POLY];
    int32_t fx[RAST__MAX_POLY], fy[RAST__MAX_POLY];
    const int n = clip_snap(view, m, ti, poly, fx, fy, st);
    int made = 0;
    for (int i = 1; i + 1 < n; i++) {
        const rast__vert *pv[3] = { &poly[0], &poly[i], &poly[i + 1] };
        int32_t tx[3] = { fx[0], fx[i], fx[i + 1] };
        int32_t ty[3] = { fy[0], fy[i], fy[i + 1] };
        made += count_setup(aa ? setup_aa(view, tx, ty, m->cull, &out[made])
                               : rast__setup_tri(view, pv, tx, ty, m->cull, &out[made]),
                            st);
    }
    return made;
}

int rast__prepare(const rast__view *view, const rast_mesh_desc *m, int ti,
                  rast__tri *out, rast_stats *st)
{
    return prepare_fan(view, m, ti, out, st, 0);
}

void rast__vcache_reset(rast__vcache *c)
{
    for (int i = 0; i < RAST__VCACHE; i++)
        c->e[i].tag = UINT32_MAX;
}

/* The cache entry of the vertex at c (index idx). */
static inline void vc_fill_one(const rast__view *view, const float *c, uint32_t idx,
                               rast__vc_entry *e)
{
    rast__vert p;
    p.x = c[0];
    p.y = c[1];
    p.z = c[2];
    p.w = c[3];
    e->tag = idx;
    if (!finite_vert(&p)) {
        e->flags = RAST__VF_NONFINITE;
        return;
    }
    const unsigned oc = outcode_inl(view, &p);
    /* w <= 0 inside every plane: only the clip-space origin, which the
     * clip path drops (docs/raster.md section 3.3). */
    if (oc || !(p.w > 0.0f)) {
        e->flags = oc | RAST__VF_SLOW;
        return;
    }
    e->flags = 0;
    snap_inl(view, &p, &e->X, &e->Y);
    e->zw = vert_zw(&p);
    e->iw = vert_iw(&p);
}

/* Fills the cache entry of vertex idx (a miss). */
static RAST__NOINLINE void vc_fill(const rast__view *view, const rast_mesh_desc *m,
                                   rast__vc_entry *e, uint32_t idx)
{
    vc_fill_one(view, m->clip + 4 * (size_t)idx, idx, e);
}

void rast__vfill_ref(const rast__view *v, const float *clip, uint32_t base, int count,
                     rast__vc_entry *e)
{
    for (int l = 0; l < count; l++)
        vc_fill_one(v, clip + 4 * ((size_t)base + (size_t)l), base + (uint32_t)l, &e[l]);
}

/* A miss with block fills: the aligned block of RAST__VBLOCK vertices
 * around idx (its slots are consecutive: RAST__VCACHE is a multiple). */
static RAST__NOINLINE void vc_fill_block(const rast__view *view, const rast_mesh_desc *m,
                                         rast__vcache *vc, uint32_t idx,
                                         rast__vfill_fn vfill)
{
    const uint32_t base = idx & ~(uint32_t)(RAST__VBLOCK - 1);
    const uint32_t left = (uint32_t)m->vertex_count - base;
    const int count = left < RAST__VBLOCK ? (int)left : RAST__VBLOCK;
    vfill(view, m->clip, base, count, &vc->e[base & (RAST__VCACHE - 1)]);
}

static inline const rast__vc_entry *vc_get(const rast__view *view,
                                           const rast_mesh_desc *m, rast__vcache *vc,
                                           uint32_t idx, rast__vfill_fn vfill)
{
    rast__vc_entry *e = &vc->e[idx & (RAST__VCACHE - 1)];
    if (e->tag != idx) {
        if (vfill)
            vc_fill_block(view, m, vc, idx, vfill);
        else
            vc_fill(view, m, e, idx);
    }
    return e;
}

#if defined(__GNUC__) || defined(__clang__)
#define RAST__INLINE inline __attribute__((always_inline))
#else
#define RAST__INLINE inline
#endif

/* The body of rast__prepare_cached, inlined into the range loop of
 * rast__prepare_range so that the common rejections (back faces, tiny
 * and off-screen triangles: 75-85% of the bench model) cost no call. */
static RAST__INLINE int prepare_cached_one(const rast__view *view,
                                           const rast_mesh_desc *m, int ti,
                                           rast__vcache *vc, rast__tri *out,
                                           rast_stats *st, rast__pbatch *pb,
                                           const rast__setup_isa *isa)
{
    const uint32_t *ix = m->indices + 3 * (size_t)ti;
    const rast__vfill_fn vfill = isa ? isa->vfill : NULL;
    const rast__vc_entry *e0 = vc_get(view, m, vc, ix[0], vfill);
    const rast__vc_entry *e1 = vc_get(view, m, vc, ix[1], vfill);
    const rast__vc_entry *e2 = vc_get(view, m, vc, ix[2], vfill);
    /* Two indices of one triangle in the same cache slot: the later
     * lookup evicted the earlier one; take the uncached path (the same
     * result, computed again). */
    if (e0->tag != ix[0] || e1->tag != ix[1])
        return rast__prepare(view, m, ti, out, st);
    const unsigned fa = e0->flags | e1->flags | e2->flags;
    if (fa) {
        /* The order of rast__prepare: non-finite, all outside one plane,
         * then clipping (which also drops w <= 0). */
        if (fa & RAST__VF_NONFINITE) {
            st->tris_nonfinite++;
            return 0;
        }
        if (e0->flags & e1->flags & e2->flags & ((1u << RAST__PLANE_COUNT) - 1u)) {
            st->tris_clipped_away++;
            return 0;
        }
        return rast__prepare(view, m, ti, out, st);
    }
    /* Trivial accept: no clipping, one fan triangle. Area and culling
     * first (half of a closed mesh faces away). */
    const int64_t area = snapped_area(e0->X, e0->Y, e1->X, e1->Y, e2->X, e2->Y);
    const int r = area_test(area, m->cull);
    if (r != RAST__SETUP_OK)
        return count_setup(r, st);
    const rast__vc_entry *v1 = area < 0 ? e2 : e1, *v2 = area < 0 ? e1 : e2;
    const uint32_t i1 = area < 0 ? ix[2] : ix[1], i2 = area < 0 ? ix[1] : ix[2];
    const int32_t X[3] = { e0->X, v1->X, v2->X }, Y[3] = { e0->Y, v1->Y, v2->Y };
    const double zw[3] = { e0->zw, v1->zw, v2->zw }, iw[3] = { e0->iw, v1->iw, v2->iw };
    const float *attr[3] = { NULL, NULL, NULL };
    if (view->attr_count > 0) {
        const size_t ac = (size_t)m->attr_count;
        attr[0] = m->attr + (size_t)ix[0] * ac;
        attr[1] = m->attr + (size_t)i1 * ac;
        attr[2] = m->attr + (size_t)i2 * ac;
    }
    if (!pb)
        return count_setup(setup_oriented(view, X, Y, area < 0 ? -area : area, zw, iw,
                                          attr, out), st);
    /* Batched planes: box, edges and attributes now, the planes queued. */
    const int r2 = setup_box_edges(view, X, Y, out);
    if (r2 != RAST__SETUP_OK)
        return count_setup(r2, st);
    setup_attrs(view, attr, out);
    const int k = pb->n;
    double Xd[3], Yd[3];
    plane_inputs(X, Y, area < 0 ? -area : area, out, Xd, Yd, &pb->area[k], &pb->cx[k],
                 &pb->cy[k]);
    for (int i = 0; i < 3; i++) {
        pb->X[i][k] = Xd[i];
        pb->Y[i][k] = Yd[i];
        pb->zw[i][k] = zw[i];
        pb->iw[i][k] = iw[i];
    }
    pb->tri[k] = out;
    pb->n = k + 1;
    if (pb->n == RAST__PBATCH)
        isa->planes(pb);
    st->tris_drawn++;
    return 1;
}

int rast__prepare_cached(const rast__view *view, const rast_mesh_desc *m, int ti,
                         rast__vcache *vc, rast__tri *out, rast_stats *st)
{
    return prepare_cached_one(view, m, ti, vc, out, st, NULL, NULL);
}

int rast__prepare_range(const rast__view *view, const rast_mesh_desc *m, int ti0,
                        int ti1, rast__vcache *vc, rast__tri *out, rast_stats *st,
                        const rast__setup_isa *isa)
{
    /* Counters in a local copy: built with -fno-strict-aliasing, the
     * compiler would otherwise store and reload them around every write
     * to out. */
    rast_stats ls = *st;
    int n = 0;
    if (isa) {
        rast__pbatch pb;
        pb.n = 0;
        int ti = ti0;
        if (isa->front)
            for (; ti + RAST__FRONT_GROUP <= ti1; ti += RAST__FRONT_GROUP)
                for (unsigned rest = isa->front(view, m, vc, ti, &ls, isa->vfill); rest;
                     rest &= rest - 1)
                    n += prepare_cached_one(view, m, ti + __builtin_ctz(rest), vc, out + n,
                                            &ls, &pb, isa);
        for (; ti < ti1; ti++)
            n += prepare_cached_one(view, m, ti, vc, out + n, &ls, &pb, isa);
        if (pb.n)
            isa->planes(&pb);
    } else {
        for (int ti = ti0; ti < ti1; ti++)
            n += prepare_cached_one(view, m, ti, vc, out + n, &ls, NULL, NULL);
    }
    *st = ls;
    return n;
}


/* Anti-aliased coverage: the setup of one fan triangle (edges only, pixel
 * box of the samples). Samples lie at the pixel centre plus offsets in
 * [-8, 7]/16 px, i.e. within [x, x + 15/16] of pixel x, so pixel x may
 * hold a covered sample only if 256x <= Xmax and 256x + 240 >= Xmin:
 * x0 = ceil((Xmin - 240) / 256) = (Xmin + 15) >> 8, x1 = Xmax >> 8. */
static int setup_aa(const rast__view *v, const int32_t fx[3], const int32_t fy[3],
                    rast_cull cull, rast__tri *tri)
{
    int64_t area;
    int s1, s2;
    int32_t X[3], Y[3];
    const int r = orient(fx, fy, cull, &area, &s1, &s2, X, Y);
    if (r != RAST__SETUP_OK)
        return r;
    int32_t xmin, xmax, ymin, ymax;
    snapped_bounds(X, Y, &xmin, &xmax, &ymin, &ymax);
    int32_t bx0 = (xmin + 15) >> RAST_SUBPIXEL_BITS, bx1 = xmax >> RAST_SUBPIXEL_BITS;
    int32_t by0 = (ymin + 15) >> RAST_SUBPIXEL_BITS, by1 = ymax >> RAST_SUBPIXEL_BITS;
    if (!box_in_view(v, &bx0, &by0, &bx1, &by1))
        return RAST__SETUP_OFFSCREEN;
    memset(tri, 0, sizeof *tri);
    setup_edges(tri, X, Y, bx0, by0, bx1, by1);
    return RAST__SETUP_OK;
}

int rast__prepare_aa(const rast__view *view, const rast_mesh_desc *m, int ti,
                     rast__tri *out, rast_stats *st)
{
    return prepare_fan(view, m, ti, out, st, 1);
}

/* ---- anti-aliasing sample patterns ------------------------------------ */

/* Direct3D standard multisample positions, 1/16 px from the pixel centre
 * (x right, y down). */
static const int8_t pattern4[4][2] = { { -2, -6 }, { 6, -2 }, { -6, 2 }, { 2, 6 } };
static const int8_t pattern8[8][2] = { { 1, -3 }, { -1, 3 }, { 5, 1 },  { -3, -5 },
                                       { -5, 5 }, { -7, -1 }, { 3, 7 }, { 7, -7 } };
static const int8_t pattern16[16][2] = {
    { 1, 1 },   { -1, -3 }, { -3, 2 },  { 4, -1 }, { -5, -2 }, { 2, 5 },  { 5, 3 },   { 3, -5 },
    { -2, 6 },  { 0, -7 },  { -4, -6 }, { -6, 4 }, { -8, 0 },  { 7, -4 }, { 6, 7 },   { -7, -8 },
};

const int8_t (*rast__aa_pattern(int count))[2]
{
    switch (count) {
    case 4:  return pattern4;
    case 8:  return pattern8;
    case 16: return pattern16;
    default: return NULL;
    }
}
