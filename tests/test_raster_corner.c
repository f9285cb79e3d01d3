/* test_raster_corner.c - big triangles whose pixel box becomes at most 2x2
 * pixels only after clamping to the target (issue 3, review of the empty
 * 2x2 boxes): every set-up path against the scalar reference, byte for
 * byte.
 *
 * The front ends drop a triangle whose clamped box is at most 2x2 pixels
 * and holds no covered pixel centre (RAST__SETUP_EMPTY). Their vector
 * test evaluates edges in int32, exact only when the UNCLAMPED box is at
 * most 2x2 too; a triangle that crosses a corner or an edge of the target
 * from hundreds or thousands of pixels away (or any triangle over a
 * target of one or two pixels) must take the scalar int64 path. This test
 * builds exactly those triangles:
 *   corner  a tip within two pixels of a target corner, the two other
 *           vertices 2..8192 px outside (a few beyond the guard band, so
 *           the clipper runs), clamped box 1x1..2x2;
 *   edge    a thin triangle across one edge, its far vertices outside,
 *           less than two pixels wide along the edge;
 *   any     a random big triangle over a target of at most 2x2 pixels;
 *   small   ordinary triangles of a few pixels, in and across the target.
 * Targets of 1x1 .. 4x4 pixels and 640x400 (corners only), padded strides,
 * depth on / off, 0 or 3 attributes (also a mesh with attributes over a
 * target without the plane), perspective w, both windings, all three cull
 * modes. Meshes are groups of 16 triangles (full lane groups of the
 * 16-lane rejection and of the vector front end): all corner/edge lanes,
 * mixed lanes, all small, and groups of 16 copies of one triangle, plus a
 * partial group at the end.
 *
 * Every mesh is drawn by the reference (rast__draw_with with
 * rast__scan_rows_ref) and, per ISA, by (b) rast__draw_with with the ISA's
 * scan (its set-up kernels: the cached 16-lane rejection for AVX-512),
 * (c) a 1-thread context (the vector front end with micro records) and
 * (d) a 2-thread context (band mode); every plane, padding included, and
 * every rast_stats counter must equal the reference's. The NOTE line
 * gives how many triangles had a clamped box <= 2x2 with an unclamped box
 * > 2x2 (counted independently from the snapped vertices) and how many of
 * those cover a pixel centre (independent top-left coverage,
 * rt_covers); both must stay large. A fixed case from the review (a
 * triangle the int32 test reports empty) is checked on its own first.
 * An ISA the CPU lacks is reported ("SKIP") and skipped, never passed.
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "test_raster_util.h"

#define NMESH 700            /* random meshes per ISA */
#define MAX_GROUPS 6         /* full groups of 16 per mesh */
#define MAX_TRIS (MAX_GROUPS * 16 + 15)

/* ---- planes: a target with its own (padded) buffers --------------------- */

typedef struct planes {
    rast_target t;
    size_t nd, nm, na;   /* elements of each plane, padding included */
} planes;

static void planes_alloc(planes *p, int w, int h, int with_depth, int attr_plane, int na,
                         int pad)
{
    memset(p, 0, sizeof *p);
    p->t.width = w;
    p->t.height = h;
    p->t.mask_stride = w + pad;
    p->nm = (size_t)p->t.mask_stride * (size_t)h;
    p->t.mask = malloc(p->nm);
    if (with_depth) {
        p->t.depth_stride = w + pad;
        p->nd = (size_t)p->t.depth_stride * (size_t)h;
        p->t.depth = malloc(p->nd * sizeof(float));
    }
    p->t.attr_count = na;
    if (attr_plane) {
        p->t.attr_stride = w * na + pad;
        p->na = (size_t)p->t.attr_stride * (size_t)h;
        p->t.attr = malloc(p->na * sizeof(float));
    }
    assert_non_null(p->t.mask);
    assert_true(!with_depth || p->t.depth);
    assert_true(!attr_plane || p->t.attr);
}

static void planes_copy(planes *dst, const planes *src)
{
    if (src->nd)
        memcpy(dst->t.depth, src->t.depth, src->nd * sizeof(float));
    memcpy(dst->t.mask, src->t.mask, src->nm);
    if (src->na)
        memcpy(dst->t.attr, src->t.attr, src->na * sizeof(float));
}

static int planes_equal(const planes *a, const planes *b)
{
    return (!a->nd || !memcmp(a->t.depth, b->t.depth, a->nd * sizeof(float))) &&
           !memcmp(a->t.mask, b->t.mask, a->nm) &&
           (!a->na || !memcmp(a->t.attr, b->t.attr, a->na * sizeof(float)));
}

static void planes_free(planes *p)
{
    free(p->t.depth);
    free(p->t.mask);
    free(p->t.attr);
    memset(p, 0, sizeof *p);
}

/* ---- mesh building ------------------------------------------------------ */

typedef struct mesh {
    rast_mesh_desc d;
    float clip[3 * MAX_TRIS * 4];
    float attr[3 * MAX_TRIS * 3];
    uint32_t idx[3 * MAX_TRIS];
    int kind[MAX_TRIS];   /* generator kind of each triangle */
    int nv, nt, na;
} mesh;

enum { K_CORNER, K_EDGE, K_ANY, K_SMALL, K_COUNT };
static const char *const kind_name[K_COUNT] = { "corner", "edge", "any", "small" };

/* Appends a vertex at pixel position (px, py) with NDC depth z and clip w. */
static uint32_t add_vertex(mesh *m, tu_rng *r, int W, int H, double px, double py, double z,
                           double w)
{
    float *c = &m->clip[4 * m->nv];
    c[0] = (float)((px / W * 2.0 - 1.0) * w);
    c[1] = (float)((1.0 - 2.0 * py / H) * w);
    c[2] = (float)(z * w);
    c[3] = (float)w;
    for (int k = 0; k < m->na; k++)
        m->attr[m->na * m->nv + k] = tu_range(r, -2.0f, 2.0f);
    return (uint32_t)m->nv++;
}

static double urand(tu_rng *r) { return (double)(tu_next(r) >> 11) * (1.0 / 9007199254740992.0); }
static double urange(tu_rng *r, double lo, double hi) { return lo + (hi - lo) * urand(r); }

/* A distance of 2..8192 px (log-uniform), or 9000..60000 px (beyond the
 * guard band: the clipper runs) for one vertex in 24. */
static double far_dist(tu_rng *r)
{
    if (tu_int(r, 24) == 0)
        return urange(r, 9000.0, 60000.0);
    return pow(2.0, 1.0 + 12.0 * urand(r));
}

/* Pixel positions (local a, b: inward distances from a corner or an edge)
 * of the three vertices of a triangle of kind k on a W x H target. */
static void make_positions(tu_rng *r, int k, int W, int H, double px[3], double py[3])
{
    if (k == K_CORNER) {
        /* local a (along x, inward from the corner), b (along y) <= 2 */
        const double D = far_dist(r), D2 = tu_int(r, 2) ? D : far_dist(r);
        double a[3], b[3];
        a[0] = urange(r, -0.25, 2.0);
        b[0] = urange(r, -0.25, 2.0);
        a[1] = -D * urange(r, 0.1, 1.0);
        b[1] = urange(r, -D, 2.0);
        a[2] = urange(r, -D2, 2.0);
        b[2] = -D2 * urange(r, 0.1, 1.0);
        const int right = tu_int(r, 2), bottom = tu_int(r, 2);
        for (int i = 0; i < 3; i++) {
            px[i] = right ? W - a[i] : a[i];
            py[i] = bottom ? H - b[i] : b[i];
        }
    } else if (k == K_EDGE) {
        /* along the edge: inside [p, p + 1.99]; across: one or two
         * vertices up to 2 px in, the others far outside */
        const int side = tu_int(r, 4);   /* 0 top, 1 bottom, 2 left, 3 right */
        const int len = side < 2 ? W : H;
        const double p = urange(r, -0.5, len > 2 ? len - 1.5 : 0.5);
        double a[3], b[3];
        a[0] = p + urange(r, 0.0, 1.99);
        a[1] = p + urange(r, 0.0, 0.4);
        a[2] = p + urange(r, 1.59, 1.99);
        if (tu_int(r, 2)) {
            /* one far apex, the wide side inside */
            b[0] = -far_dist(r);   /* then the factor: drawn in order */
            b[0] *= urange(r, 0.1, 1.0);
            b[1] = urange(r, -0.25, 2.0);
            b[2] = urange(r, -0.25, 2.0);
        } else {
            /* the tip inside, two far vertices */
            b[0] = urange(r, -0.25, 2.0);
            b[1] = -far_dist(r);
            b[1] *= urange(r, 0.1, 1.0);
            if (tu_int(r, 2)) {
                b[2] = b[1] + urange(r, -1.0, 1.0);
            } else {
                b[2] = -far_dist(r);
                b[2] *= urange(r, 0.1, 1.0);
            }
        }
        for (int i = 0; i < 3; i++) {
            const double across = (side & 1) ? (side < 2 ? H : W) - b[i] : b[i];
            px[i] = side < 2 ? a[i] : across;
            py[i] = side < 2 ? across : a[i];
        }
    } else if (k == K_ANY) {
        /* anything around the target, mostly big */
        const double D = far_dist(r);
        for (int i = 0; i < 3; i++) {
            px[i] = W * 0.5 + urange(r, -D, D);
            py[i] = H * 0.5 + urange(r, -D, D);
        }
    } else {
        const double s = urange(r, 0.3, 4.0);
        const double cx = urange(r, -1.0, W + 1.0), cy = urange(r, -1.0, H + 1.0);
        for (int i = 0; i < 3; i++) {
            px[i] = cx + urange(r, -s, s);
            py[i] = cy + urange(r, -s, s);
        }
    }
}

static void add_tri(mesh *m, tu_rng *r, int k, int W, int H)
{
    double px[3], py[3];
    make_positions(r, k, W, H, px, py);
    const int persp = tu_int(r, 3) == 0;
    uint32_t v[3];
    for (int i = 0; i < 3; i++) {
        const double w = persp ? urange(r, 0.25, 4.0) : 1.0;
        const double z = tu_int(r, 16) ? urange(r, -0.95, 0.95) : urange(r, -1.1, 1.1);
        v[i] = add_vertex(m, r, W, H, px[i], py[i], z, w);
    }
    if (tu_int(r, 2)) {   /* the other winding */
        const uint32_t s = v[1];
        v[1] = v[2];
        v[2] = s;
    }
    memcpy(&m->idx[3 * m->nt], v, sizeof v);
    m->kind[m->nt++] = k;
}

/* The kind of a big (box-crossing) triangle for a W x H target. */
static int big_kind(tu_rng *r, int W, int H)
{
    if (W <= 2 && H <= 2 && tu_int(r, 4) == 0)
        return K_ANY;
    if (W > 4)
        return K_CORNER;   /* the 640x400 target: corners */
    return tu_int(r, 3) ? K_CORNER : K_EDGE;
}

/* A mesh of 1..MAX_GROUPS groups of 16 and a partial group of 0..15. */
static void make_mesh(mesh *m, tu_rng *r, int W, int H, int na, rast_cull cull)
{
    m->nv = m->nt = 0;
    m->na = na;
    const int groups = 1 + tu_int(r, MAX_GROUPS);
    for (int g = 0; g < groups; g++) {
        const int gk = tu_int(r, 8);
        if (gk == 0) {
            /* 16 copies of one big triangle (shared vertices) */
            const int t0 = m->nt;
            add_tri(m, r, big_kind(r, W, H), W, H);
            for (int l = 1; l < 16; l++) {
                memcpy(&m->idx[3 * m->nt], &m->idx[3 * t0], 3 * sizeof(uint32_t));
                m->kind[m->nt] = m->kind[t0];
                m->nt++;
            }
        } else {
            /* 1..3: every lane big; 4..6: mixed; 7: every lane small */
            for (int l = 0; l < 16; l++) {
                const int big = gk <= 3 ? 1 : gk <= 6 ? tu_int(r, 2) : 0;
                add_tri(m, r, big ? big_kind(r, W, H) : K_SMALL, W, H);
            }
        }
    }
    const int tail = tu_int(r, 3) ? 0 : tu_int(r, 16);
    for (int l = 0; l < tail; l++)
        add_tri(m, r, tu_int(r, 2) ? big_kind(r, W, H) : K_SMALL, W, H);
    memset(&m->d, 0, sizeof m->d);
    m->d.clip = m->clip;
    m->d.vertex_count = m->nv;
    m->d.attr = na ? m->attr : NULL;
    m->d.attr_count = na;
    m->d.indices = m->idx;
    m->d.tri_count = m->nt;
    m->d.cull = cull;
}

/* ---- independent classification ---------------------------------------- */

typedef struct counts {
    long gap[K_COUNT];       /* clamped box <= 2x2, unclamped box > 2x2 */
    long gap_cover[K_COUNT]; /* ... not culled, covering a pixel centre */
    long clipped;            /* a vertex outside a clip plane (clipper) */
    long big_gap;            /* gap triangles on the 640x400 target */
    long pixels;             /* pixels the reference wrote */
    long meshes;
} counts;

static int32_t floor_shift(int64_t v) { return (int32_t)(v >= 0 ? v / 256 : -((-v + 255) / 256)); }

/* Classifies triangle ti of m on a W x H target: the box before and
 * after clamping from the snapped vertices, and the covered centres. */
static void classify(const mesh *m, int ti, int W, int H, counts *c)
{
    rast__view view;
    rast__view_init(&view, W, H, 0);
    int64_t X[3], Y[3];
    for (int i = 0; i < 3; i++) {
        const float *p = &m->clip[4 * m->idx[3 * ti + i]];
        rast__vert v;
        memset(&v, 0, sizeof v);
        v.x = p[0];
        v.y = p[1];
        v.z = p[2];
        v.w = p[3];
        if (rast__outcode(&view, &v) != 0 || !(v.w > 0.0f)) {
            c->clipped++;
            return;
        }
        int32_t fx, fy;
        rast__snap(&view, &v, &fx, &fy);
        X[i] = fx;
        Y[i] = fy;
    }
    const int64_t area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area == 0)
        return;
    int64_t xmin = X[0], xmax = X[0], ymin = Y[0], ymax = Y[0];
    for (int i = 1; i < 3; i++) {
        xmin = X[i] < xmin ? X[i] : xmin;
        xmax = X[i] > xmax ? X[i] : xmax;
        ymin = Y[i] < ymin ? Y[i] : ymin;
        ymax = Y[i] > ymax ? Y[i] : ymax;
    }
    /* pixels whose centre (x + 0.5) lies in [min, max] */
    const int rx0 = floor_shift(xmin + 127), rx1 = floor_shift(xmax - 128);
    const int ry0 = floor_shift(ymin + 127), ry1 = floor_shift(ymax - 128);
    const int bx0 = rx0 > 0 ? rx0 : 0, bx1 = rx1 < W - 1 ? rx1 : W - 1;
    const int by0 = ry0 > 0 ? ry0 : 0, by1 = ry1 < H - 1 ? ry1 : H - 1;
    if (bx0 > bx1 || by0 > by1)
        return;
    const int csmall = bx1 - bx0 < 2 && by1 - by0 < 2;
    const int usmall = rx1 - rx0 < 2 && ry1 - ry0 < 2;
    if (!csmall || usmall)
        return;
    const int k = m->kind[ti];
    c->gap[k]++;
    c->big_gap += W > 4;
    const int front = area < 0;   /* y down: counter-clockwise in NDC */
    if ((m->d.cull == RAST_CULL_BACK && !front) || (m->d.cull == RAST_CULL_FRONT && front))
        return;
    for (int y = by0; y <= by1; y++)
        for (int x = bx0; x <= bx1; x++)
            if (rt_covers(X, Y, (int64_t)x * 256 + 128, (int64_t)y * 256 + 128)) {
                c->gap_cover[k]++;
                return;
            }
}

/* ---- drawing and comparing ---------------------------------------------- */

static int stats_equal(const rast_stats *a, const rast_stats *b)
{
    return a->tris_in == b->tris_in && a->tris_nonfinite == b->tris_nonfinite &&
           a->tris_clipped_away == b->tris_clipped_away &&
           a->tris_degenerate == b->tris_degenerate && a->tris_culled == b->tris_culled &&
           a->tris_drawn == b->tris_drawn && a->pixels_written == b->pixels_written;
}

typedef struct paths {
    int isa;                 /* ef_isa (EF_ISA_REF: contexts only) */
    rast_context *ctx1, *ctx2;
} paths;

static void report(const char *what, const char *label, const rast_stats *r,
                   const rast_stats *g, const planes *ref, const planes *got)
{
    print_error("%s: %s differs: planes %s; pixels %ld vs %ld, drawn %ld vs %ld, "
                "clipped away %ld vs %ld, culled %ld vs %ld, degenerate %ld vs %ld\n",
                label, what, planes_equal(ref, got) ? "equal" : "differ", r->pixels_written,
                g->pixels_written, r->tris_drawn, g->tris_drawn, r->tris_clipped_away,
                g->tris_clipped_away, r->tris_culled, g->tris_culled, r->tris_degenerate,
                g->tris_degenerate);
}

/* Draws m into a copy of init by the reference and every path of p;
 * fails on the first difference. Returns the reference's pixel count. */
static long draw_compare(const paths *p, const planes *init, const rast_mesh_desc *m,
                         const char *label)
{
    planes ref, got;
    planes_alloc(&ref, init->t.width, init->t.height, init->nd > 0, init->na > 0,
                 init->t.attr_count,
                 init->t.mask_stride - init->t.width);
    planes_alloc(&got, init->t.width, init->t.height, init->nd > 0, init->na > 0,
                 init->t.attr_count, init->t.mask_stride - init->t.width);
    planes_copy(&ref, init);
    rast_stats rs;
    memset(&rs, 0, sizeof rs);
    assert_int_equal(rast__draw_with(&ref.t, m, &rs, rast__scan_rows_ref), RAST_OK);
    for (int path = 0; path < 3; path++) {
        if (path == 0 && p->isa == EF_ISA_REF)
            continue;   /* rast__draw_with of the reference is the reference */
        planes_copy(&got, init);
        rast_stats gs;
        memset(&gs, 0, sizeof gs);
        rast_result res;
        if (path == 0)
            res = rast__draw_with(&got.t, m, &gs, rast__scan_for_isa(p->isa));
        else
            res = rast_context_draw(path == 1 ? p->ctx1 : p->ctx2, &got.t, m, &gs);
        assert_int_equal(res, RAST_OK);
        if (!planes_equal(&ref, &got) || !stats_equal(&rs, &gs)) {
            static const char *const what[3] = { "rast__draw_with(ISA scan)",
                                                 "context, 1 thread", "context, 2 threads" };
            report(what[path], label, &rs, &gs, &ref, &got);
            fail();
        }
    }
    planes_free(&ref);
    planes_free(&got);
    return rs.pixels_written;
}

/* The initial planes of a case: padding and contents random, then either
 * cleared or random depth (so the LESS test both passes and fails). */
static void planes_init(planes *p, tu_rng *r)
{
    if (p->nm > 4096) {   /* big targets: a byte pattern, then cleared */
        memset(p->t.mask, 0xA5, p->nm);
        if (p->nd)
            memset(p->t.depth, 0x3E, p->nd * sizeof(float));
        if (p->na)
            memset(p->t.attr, 0x41, p->na * sizeof(float));
        rast_target_clear(&p->t);
        return;
    }
    for (size_t i = 0; i < p->nm; i++)
        p->t.mask[i] = (uint8_t)tu_next(r);
    for (size_t i = 0; i < p->nd; i++)
        p->t.depth[i] = tu_range(r, -0.5f, 1.5f);
    for (size_t i = 0; i < p->na; i++)
        p->t.attr[i] = tu_range(r, -4.0f, 4.0f);
    if (tu_int(r, 3))
        rast_target_clear(&p->t);
}

static int open_paths(paths *p, int isa)
{
    memset(p, 0, sizeof *p);
    p->isa = isa;
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP %s: not supported by this CPU; untested: the corner cases through "
                      "rast_draw on %s (src/raster/raster_%s.c, raster_front_%s.c)\n", ef_isa_name((ef_isa)isa),
                      ef_isa_name((ef_isa)isa), ef_isa_name((ef_isa)isa), ef_isa_name((ef_isa)isa));
        return 0;
    }
    rast_context_desc d1 = { isa, 1 }, d2 = { isa, 2 };
    p->ctx1 = rast_context_create(&d1);
    p->ctx2 = rast_context_create(&d2);
    assert_non_null(p->ctx1);
    assert_non_null(p->ctx2);
    if (rast_context_isa(p->ctx1) != isa || rast_context_isa(p->ctx2) != isa) {
        print_message("SKIP %s: capped to %s (EGOFUSE_ISA)\n", ef_isa_name((ef_isa)isa),
                      ef_isa_name((ef_isa)rast_context_isa(p->ctx1)));
        rast_context_destroy(p->ctx1);
        rast_context_destroy(p->ctx2);
        return 0;
    }
    assert_int_equal(rast_context_threads(p->ctx2), 2);
    return 1;
}

static void close_paths(paths *p)
{
    rast_context_destroy(p->ctx1);
    rast_context_destroy(p->ctx2);
}

/* ---- the tests ---------------------------------------------------------- */

/* The review's case: 8x8 target, a triangle across the top-left corner
 * from about 450 px away, 16 copies (one full lane group). Its int32
 * empty test overflows; the reference writes 32 pixels (two per copy). */
static void fixed_case(int isa)
{
    paths p;
    if (!open_paths(&p, isa))
        skip();
    static const double pos[3][2] = { { 1.7148438, 1.8007812 },
                                      { -421.29688, -15.0 },
                                      { -436.87891, -471.73438 } };
    mesh *m = calloc(1, sizeof *m);
    assert_non_null(m);
    tu_rng r = { 0xC0C0A9ull };
    for (int na = 0; na <= 3; na += 3)
        for (int depth = 0; depth < 2; depth++) {
            m->nv = m->nt = 0;
            m->na = na;
            for (int i = 0; i < 3; i++)
                add_vertex(m, &r, 8, 8, pos[i][0], pos[i][1], 0.25 * i, 1.0);
            for (int l = 0; l < 16; l++) {
                for (int i = 0; i < 3; i++)
                    m->idx[3 * l + i] = (uint32_t)i;
                m->kind[l] = K_CORNER;
            }
            m->nt = 16;
            memset(&m->d, 0, sizeof m->d);
            m->d.clip = m->clip;
            m->d.vertex_count = 3;
            m->d.attr = na ? m->attr : NULL;
            m->d.attr_count = na;
            m->d.indices = m->idx;
            m->d.tri_count = 16;
            m->d.cull = RAST_CULL_NONE;
            counts c;
            memset(&c, 0, sizeof c);
            classify(m, 0, 8, 8, &c);
            assert_int_equal(c.gap[K_CORNER], 1);       /* the case is in the gap */
            assert_int_equal(c.gap_cover[K_CORNER], 1);
            planes init;
            planes_alloc(&init, 8, 8, depth, na > 0, na, 3);
            memset(init.t.mask, 0x5A, init.nm);
            rast_target_clear(&init.t);
            char label[64];
            snprintf(label, sizeof label, "review case (%s, depth %d, %d attrs)",
                     ef_isa_name((ef_isa)isa), depth, na);
            const long px = draw_compare(&p, &init, &m->d, label);
            /* 16 copies: without depth every copy writes its 2 pixels;
             * with depth the first copy only (LESS fails for the rest). */
            assert_int_equal(px, depth ? 2 : 32);
            planes_free(&init);
        }
    free(m);
    close_paths(&p);
}

static void corner_isa(int isa)
{
    paths p;
    if (!open_paths(&p, isa))
        skip();
    mesh *m = calloc(1, sizeof *m);
    assert_non_null(m);
    counts c;
    memset(&c, 0, sizeof c);
    for (int n = 0; n < NMESH; n++) {
        tu_rng r = { 0xC02E4000ull + (uint64_t)n * 0x9E3779B97F4A7C15ull };
        int W, H;
        if (n % 20 == 19) {
            W = 640;
            H = 400;
        } else {
            W = 1 + tu_int(&r, 4);
            H = 1 + tu_int(&r, 4);
        }
        const int depth = tu_int(&r, 2);
        const int na = tu_int(&r, 2) ? 3 : 0;
        const int attr_plane = na && tu_int(&r, 6);
        const int pad = tu_int(&r, 3) ? 1 + tu_int(&r, 7) : 0;
        const rast_cull cull = (rast_cull)(n % 3);
        make_mesh(m, &r, W, H, na, cull);
        planes init;
        planes_alloc(&init, W, H, depth, attr_plane, na, pad);
        planes_init(&init, &r);
        for (int ti = 0; ti < m->nt; ti++)
            classify(m, ti, W, H, &c);
        char label[96];
        snprintf(label, sizeof label, "mesh %d (%s, %dx%d, depth %d, %d attrs%s, cull %d, %d tris)",
                 n, ef_isa_name((ef_isa)isa), W, H, depth, na,
                 na && !attr_plane ? " no plane" : "", (int)cull, m->nt);
        c.pixels += draw_compare(&p, &init, &m->d, label);
        c.meshes++;
        planes_free(&init);
    }
    long gap = 0, cover = 0;
    for (int k = 0; k < K_COUNT; k++) {
        gap += c.gap[k];
        cover += c.gap_cover[k];
    }
    print_message("NOTE %s: %ld meshes equal to the reference (%ld pixels); clamped box <= 2x2 "
                  "with unclamped box > 2x2: %ld triangles (%s %ld, %s %ld, %s %ld, %s %ld), "
                  "%ld of them covering pixels (%ld, %ld, %ld, %ld), %ld on 640x400; %ld with a "
                  "vertex for the clipper\n",
                  ef_isa_name((ef_isa)isa), c.meshes, c.pixels, gap, kind_name[K_CORNER],
                  c.gap[K_CORNER], kind_name[K_EDGE], c.gap[K_EDGE], kind_name[K_ANY],
                  c.gap[K_ANY], kind_name[K_SMALL], c.gap[K_SMALL], cover,
                  c.gap_cover[K_CORNER], c.gap_cover[K_EDGE], c.gap_cover[K_ANY],
                  c.gap_cover[K_SMALL], c.big_gap, c.clipped);
    /* the cases keep testing the gap: many such triangles of every big
     * kind, many of them covering pixels (small ones across a border are
     * counted too when their box is over 2x2 before clamping) */
    assert_true(gap > 10000 && cover > 3000);
    for (int k = 0; k < K_SMALL; k++)
        assert_true(c.gap[k] > 500 && c.gap_cover[k] > 100);
    assert_true(c.big_gap > 300 && c.pixels > 3000);
    assert_true(c.clipped > 500);
    free(m);
    close_paths(&p);
}

static void test_fixed_ref(void **state) { (void)state; fixed_case(EF_ISA_REF); }
static void test_fixed_sse2(void **state) { (void)state; fixed_case(EF_ISA_SSE2); }
static void test_fixed_avx2(void **state) { (void)state; fixed_case(EF_ISA_AVX2); }
static void test_fixed_avx512(void **state) { (void)state; fixed_case(EF_ISA_AVX512); }
static void test_corner_ref(void **state) { (void)state; corner_isa(EF_ISA_REF); }
static void test_corner_sse2(void **state) { (void)state; corner_isa(EF_ISA_SSE2); }
static void test_corner_avx2(void **state) { (void)state; corner_isa(EF_ISA_AVX2); }
static void test_corner_avx512(void **state) { (void)state; corner_isa(EF_ISA_AVX512); }
static void test_fixed_neon(void **state) { (void)state; fixed_case(EF_ISA_NEON); }
static void test_corner_neon(void **state) { (void)state; corner_isa(EF_ISA_NEON); }

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_fixed_ref),    cmocka_unit_test(test_fixed_sse2),
        cmocka_unit_test(test_fixed_avx2),   cmocka_unit_test(test_fixed_avx512),
        cmocka_unit_test(test_corner_ref),   cmocka_unit_test(test_corner_sse2),
        cmocka_unit_test(test_corner_avx2),  cmocka_unit_test(test_corner_avx512),
        cmocka_unit_test(test_fixed_neon),   cmocka_unit_test(test_corner_neon))
