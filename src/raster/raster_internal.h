/* raster_internal.h - the parts of the rasterizer shared by the scalar
 * reference (raster_ref.c) and any SIMD scan path (raster_<isa>.c).
 *
 * Layers, each calling only those below it (function pointers chosen by
 * the context go downwards too):
 *   raster_context.c  ISA dispatch (the only file naming per-ISA kernels),
 *                     threads, rast_draw / rast_draw_aa / transforms
 *   raster_draw.c     the draw driver (chunks through set-up and a scan),
 *   raster_aa.c       the anti-aliased draw driver and reference scan
 *   per-ISA kernels   raster_ref.c, raster_<isa>.c, raster_front_<isa>.c
 *   raster_setup.c    the scalar per-triangle set-up they share
 *
 * Split of the work (docs/raster.md has the full rules):
 *   raster_setup.c  validation, clipping, perspective divide, viewport,
 *                   sub-pixel snapping, culling, edge and plane setup, and
 *                   the per-range set-up rast__prepare_range(). Scalar; it
 *                   defines the set-up's bits. Three parts of it have SIMD
 *                   versions that give the same bits (rast__setup_isa:
 *                   raster_planes.inl, raster_avx2.c, raster_avx512.c):
 *                   the float planes of 4/8 triangles per vector, vertex
 *                   cache fills of 16 vertices, and (AVX-512) the trivial
 *                   rejection of 16 triangles at once.
 *   raster_front_avx512.c, raster_front_avx2.c
 *                   the vector front end (below: rast__vbuf): vertex pass,
 *                   rejection and set-up in lanes, for whole-job draws
 *                   through a context; same records as the scalar set-up.
 *                   Written once on the vector layer: raster_front.inl
 *                   (rejection), raster_frontv.inl (vertex pass, planes,
 *                   micro values), raster_frontq.inl (group loop, queue,
 *                   edges, records); the two .c files hold only their
 *                   ISA's loads and attribute copies. raster_front_avx512.inl
 *                   holds the 16-lane index de-interleave and rejection
 *                   helpers, also used by rast__front_avx512
 *                   (raster_avx512.c).
 *   raster_ref.c    rast__scan_ref(): the per-pixel loop over one set-up
 *                   triangle. This is the only thing a SIMD path replaces,
 *                   and it must give the same bytes (op order below).
 *
 * Per-pixel rule (rast__scan_ref; a SIMD scan must copy it exactly):
 *   i = x - tri->x0, j = y - tri->y0 (pixel offsets inside the bounding box)
 *   coverage: e_k = e_c[k] + j*e_dy[k] + i*e_dx[k] (int64, exact; any order)
 *             covered iff e_0 >= 0 && e_1 >= 0 && e_2 >= 0
 *   plane p : v = (p.c + p.dy * (float)j) + p.dx * (float)i   (float32)
 *   depth   : z = min(max(v_z, 0), 1); pass iff depth == NULL || z < d[x]
 *   attrs   : r = 1.0f / v_q;  b1 = v_b1 * r;  b2 = v_b2 * r;
 *             a_k = (a0[k] + b1 * d1[k]) + b2 * d2[k]
 */
#ifndef EGOFUSE_RASTER_INTERNAL_H
#define EGOFUSE_RASTER_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "raster.h"

#define RAST__FIX_ONE (1 << RAST_SUBPIXEL_BITS)     /* 256: one pixel */
#define RAST__FIX_HALF (1 << (RAST_SUBPIXEL_BITS - 1))
/* Sutherland-Hodgman adds at most one vertex per plane: 3 + 6. */
#define RAST__MAX_POLY 9
#define RAST__PLANE_COUNT 6

/* Clip planes, in the order they are applied (bit i of an outcode). */
enum {
    RAST__PLANE_NEAR = 0,   /* d = z + w        */
    RAST__PLANE_FAR,        /* d = w - z        */
    RAST__PLANE_LEFT,       /* d = gx*w + x     */
    RAST__PLANE_RIGHT,      /* d = gx*w - x     */
    RAST__PLANE_BOTTOM,     /* d = gy*w + y     */
    RAST__PLANE_TOP         /* d = gy*w - y     */
};

/* A clip-space vertex with its attributes. */
typedef struct rast__vert {
    float x, y, z, w;
    float a[RAST_MAX_ATTRS];
} rast__vert;

/* What does not change between triangles of one draw. */
typedef struct rast__view {
    int width, height;
    float gx, gy;            /* guard-band factors: |x| <= gx*w, |y| <= gy*w */
    int32_t min_x, max_x;    /* snapped x clamp: -G*256 .. (W+G)*256 */
    int32_t min_y, max_y;
    int attr_count;          /* attributes carried through clipping */
    /* The target whose depth the vector front end tests boxes against
     * before writing a record (docs/raster.md section 14): NULL (set by
     * rast__view_init) for no test; rast__draw_valid_vb sets it when the
     * target has depth. */
    const rast_target *hz;
} rast__view;

/* A float plane: value at the centre of the bounding box's first pixel
 * (x0, y0) and its change per pixel step in x and y. */
typedef struct rast__plane {
    float c, dx, dy;
} rast__plane;

/* One triangle ready to scan. Edge values are in 1/65536 pixel^2 units
 * (fixed x fixed), already biased for the top-left rule, so a pixel is
 * covered iff all three are >= 0. */
typedef struct rast__tri {
    int x0, y0, x1, y1;          /* inclusive pixel bounding box, clamped */
    int64_t e_c[3];              /* edge values at the centre of (x0, y0) */
    int64_t e_dx[3], e_dy[3];    /* change per pixel step */
    rast__plane z;               /* window depth */
    /* Perspective-correct barycentrics: q is 1/w scaled so that its
     * largest vertex value is 1; b1, b2 are q times the screen-space
     * barycentric weights of vertices 1 and 2 (vertex values (0, q1, 0)
     * and (0, 0, q2)). At a pixel, b_i = v_bi / v_q. */
    rast__plane q, b1, b2;
    /* Attribute k = (a0 + b1 * d1) + b2 * d2, with d1 = a1 - a0 and
     * d2 = a2 - a0 (float), vertices in the order after winding
     * normalisation. A constant attribute is reproduced exactly. */
    float a0[RAST_MAX_ATTRS], d1[RAST_MAX_ATTRS], d2[RAST_MAX_ATTRS];
    int attr_count;
    /* 0: a triangle to scan (every set-up path writes 0). Otherwise a
     * "micro record" of the vector front end (docs/raster.md section 11):
     * RAST__MICRO | the covered pixels of a box of at most 2x2 (bit
     * i + 2*j for pixel (x0 + i, y0 + j)); the edges and planes are not
     * written, mz, mb1, mb2 hold the clamped depth and the barycentrics
     * b1, b2 of each covered pixel, computed with the scan's float
     * operations, and a0, d1, d2 the attributes as usual. */
    int micro;
    float mz[4], mb1[4], mb2[4];
} rast__tri;
#define RAST__MICRO 0x10
/* micro == RAST__HIDDEN: a record the vector front end found hidden (its
 * box holds no depth a pixel of it could pass, docs/raster.md section 14):
 * only the box and micro are written; rast__scan_list marks its tiles as
 * after a scan and scans nothing. */
#define RAST__HIDDEN 0x20

/* Result of rast__setup_tri. */
enum {
    RAST__SETUP_OK = 0,
    RAST__SETUP_DEGENERATE,      /* zero area after snapping */
    RAST__SETUP_CULLED,
    RAST__SETUP_OFFSCREEN,       /* bounding box misses the target */
    /* Set up (counted as drawn) but provably writes no pixel: a box of
     * at most 2x2 pixels whose centres all fail the edge test.
     * rast__prepare and the cached path count it as drawn and emit no
     * triangle (its scan would write nothing); *tri has the box and
     * edges but no planes. */
    RAST__SETUP_EMPTY
};

/* Scans one triangle into t; returns the number of pixels written. */
typedef long (*rast__scan_fn)(const rast_target *t, const rast__tri *tri);
/* The same, restricted to the rows ya..yb (inclusive; intersected with the
 * triangle's box). Every pixel gets exactly the bytes of the full scan, so
 * a target may be split into row bands drawn by different threads. */
typedef long (*rast__scan_rows_fn)(const rast_target *t, const rast__tri *tri,
                                   int ya, int yb);

/* A triangle becomes at most RAST__MAX_POLY - 2 fan triangles. */
#define RAST__MAX_FAN (RAST__MAX_POLY - 2)

/* Fills the per-draw constants for target size w x h. */
void rast__view_init(rast__view *v, int width, int height, int attr_count);

/* Outcode of a vertex: bit i set when it is outside plane i. */
unsigned rast__outcode(const rast__view *v, const rast__vert *p);

/* Sutherland-Hodgman against the planes in `planes` (bit mask), in plane
 * order. poly holds n vertices and room for RAST__MAX_POLY; tmp is scratch
 * of the same size. Returns the vertex count left in poly (0..9). */
int rast__clip_polygon(const rast__view *v, unsigned planes, rast__vert *poly,
                       int n, rast__vert *tmp);

/* Perspective divide, viewport and snapping of one vertex (w > 0, finite).
 * Writes fixed-point screen coordinates (1/256 pixel). */
void rast__snap(const rast__view *v, const rast__vert *p, int32_t *fx,
                int32_t *fy);

/* Sets up the triangle (p[0], p[1], p[2]) with snapped positions fx, fy.
 * Returns RAST__SETUP_*; *tri is valid only for RAST__SETUP_OK. */
int rast__setup_tri(const rast__view *v, const rast__vert *const p[3],
                    const int32_t fx[3], const int32_t fy[3], rast_cull cull,
                    rast__tri *tri);

/* Checks the arguments (RAST_OK or the error of rast_draw). */
rast_result rast__validate(const rast_target *t, const rast_mesh_desc *m);
/* rast__validate in two parts: everything but the indices (_desc), and
 * every index below the vertex count (_indices; m already passed _desc). */
rast_result rast__validate_desc(const rast_target *t, const rast_mesh_desc *m);
rast_result rast__validate_indices(const rast_mesh_desc *m);

/* rast_draw on the calling thread with a given row scan (the reference
 * or a SIMD one) and the set-up kernels of its ISA (raster_context.c,
 * the dispatch). */
rast_result rast__draw_with(const rast_target *t, const rast_mesh_desc *m,
                            rast_stats *stats, rast__scan_rows_fn scan);

/* Tiles of 16x16 pixels a draw may have written, one bit per tile:
 * bit (tx % 64) of bits[ty][tx / 64]. */
#define RAST__TILE 16
#define RAST__TILE_ROWS (RAST_MAX_DIM / RAST__TILE)
#define RAST__TILE_WORDS (RAST_MAX_DIM / RAST__TILE / 64)
typedef struct rast__tiles {
    uint64_t bits[RAST__TILE_ROWS][RAST__TILE_WORDS];
} rast__tiles;
/* n floats of 1.0f (the cleared depth) from d, eight at a time by 32-byte
 * copies of a constant: gcc -O2 leaves the plain loop as one 4-byte store
 * per float (the context clear's depth spans were 96% of its
 * instructions). */
static inline void rast__fill_depth(float *d, size_t n)
{
    static const float ones[8] = { 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f };
    size_t x = 0;
    for (; x + 8 <= n; x += 8)
        __builtin_memcpy(d + x, ones, sizeof ones);
    for (; x < n; x++)
        d[x] = 1.0f;
}

/* Marks the tiles of pixels x0..x1 x ya..yb (inclusive, not empty). */
void rast__tiles_add(rast__tiles *tl, int ya, int yb, int x0, int x1);

/* The body of rast__draw_with for validated arguments (raster_draw.c),
 * with the set-up kernels isa (those of the scan's ISA, or
 * &rast__setup_isa_ref). When tiles is not NULL, the pixel box of every
 * scanned triangle is marked in it (every pixel the draw may have written
 * lies in a marked tile). */
struct rast__setup_isa;
void rast__draw_valid(const rast_target *t, const rast_mesh_desc *m,
                      rast_stats *stats, rast__scan_rows_fn scan,
                      const struct rast__setup_isa *isa, rast__tiles *tiles);
/* Scans the n set-up triangles tri in order into t (micro: micro records
 * may occur, their pixels are written as the scan would write them);
 * marks the tiles of every triangle that may write a pixel in tiles
 * (unless NULL; last: the tile rectangle marked last, x0, x1, y0, y1, as
 * {1, 0, 1, 0} before the first call). Returns the pixels written. */
long rast__scan_list(const rast_target *t, const rast__tri *tri, int n,
                     rast__scan_rows_fn scan, rast__tiles *tiles, int last[4], int micro);
/* The same with a vertex buffer: when isa has a vector front end and
 * the mesh fits (vertex_count <= vb->cap), the draw runs it with micro
 * records (same bytes and counters); otherwise (or vb NULL)
 * rast__draw_valid. */
struct rast__vbuf;
void rast__draw_valid_vb(const rast_target *t, const rast_mesh_desc *m,
                         rast_stats *stats, rast__scan_rows_fn scan,
                         const struct rast__setup_isa *isa, rast__tiles *tiles,
                         struct rast__vbuf *vb);

/* Fetch, clip, snap and set up submitted triangle ti of m (indices already
 * validated): writes 0..RAST__MAX_FAN triangles to out, returns their
 * count and adds every counter but tris_in and pixels_written to *st. */
int rast__prepare(const rast__view *view, const rast_mesh_desc *m, int ti,
                  rast__tri *out, rast_stats *st);
/* Per-vertex results of the front end for one draw, in a small
 * direct-mapped cache keyed by vertex index (RAST__VCACHE entries). Every
 * value is a pure function of the vertex, so a cached value is the bit
 * the scalar per-triangle path computes (docs/raster.md section 11):
 * flags (RAST__VF_*), the outcode, the snapped position and the double
 * per-vertex plane inputs zw = (z/w)*0.5+0.5 and iw = 1/w. */
#define RAST__VCACHE 1024
enum {
    RAST__VF_NONFINITE = 1 << 6,   /* a NaN or infinite coordinate */
    RAST__VF_SLOW = 1 << 7         /* outcode != 0 or w <= 0: clip path */
};
typedef struct rast__vc_entry {
    uint32_t tag;                  /* vertex index, UINT32_MAX = empty */
    uint32_t flags;                /* outcode (bits 0..5) | RAST__VF_* */
    int32_t X, Y;                  /* snapped (valid when flags == 0) */
    double zw, iw;
} rast__vc_entry;
typedef struct rast__vcache {
    rast__vc_entry e[RAST__VCACHE];
} rast__vcache;

/* Empties the cache (once per draw: clip data may change between draws). */
void rast__vcache_reset(rast__vcache *c);

/* rast__prepare with the vertex cache: triangles whose three vertices are
 * finite and inside every clip plane (the usual case) are set up from the
 * cached per-vertex values; the others go through rast__prepare. Same
 * triangles, bytes and counters as rast__prepare. */
int rast__prepare_cached(const rast__view *view, const rast_mesh_desc *m, int ti,
                         rast__vcache *vc, rast__tri *out, rast_stats *st);

/* Deferred plane set-up. The float planes (z, q, b1, b2) of a triangle
 * are the division-bound part of its set-up (docs/raster.md section 6.1).
 * The front end queues the inputs of trivially accepted triangles here
 * (structure of arrays, values already in double) and a planes function
 * computes RAST__PBATCH of them at once, one triangle per SIMD lane, with
 * the scalar set-up's IEEE double operations in its order per lane: the
 * same bits as rast__planes_ref.
 *   X, Y  vertex positions in pixels ((double)fixed / 256, exact), after
 *         winding normalisation; area = snapped area / 65536 (> 0, exact);
 *   cx, cy  the centre of the box's first pixel; zw, iw per vertex. */
#define RAST__PBATCH 16
typedef struct rast__pbatch {
    int n;
    rast__tri *tri[RAST__PBATCH];
    _Alignas(64) double X[3][RAST__PBATCH];
    _Alignas(64) double Y[3][RAST__PBATCH];
    _Alignas(64) double zw[3][RAST__PBATCH];
    _Alignas(64) double iw[3][RAST__PBATCH];
    _Alignas(64) double area[RAST__PBATCH];
    _Alignas(64) double cx[RAST__PBATCH];
    _Alignas(64) double cy[RAST__PBATCH];
} rast__pbatch;
/* Writes the z, q, b1, b2 planes of b->tri[0 .. b->n-1] and sets b->n = 0.
 * Lanes n .. RAST__PBATCH-1 may be overwritten with harmless values. */
typedef void (*rast__planes_fn)(rast__pbatch *b);
void rast__planes_ref(rast__pbatch *b);
void rast__planes_avx2(rast__pbatch *b);
void rast__planes_avx512(rast__pbatch *b);
void rast__planes_sse2(rast__pbatch *b);
void rast__planes_neon(rast__pbatch *b);

/* Vertex cache fill of a block: e[l] = the entry of vertex base + l for
 * l < count (count 1..RAST__VBLOCK; clip: the mesh's clip coordinates),
 * the bits the scalar fill gives (tag, flags and, when flags == 0, the
 * snapped position, zw and iw; other fields are unspecified). */
#define RAST__VBLOCK 16
typedef void (*rast__vfill_fn)(const rast__view *v, const float *clip, uint32_t base,
                               int count, rast__vc_entry *e);
void rast__vfill_ref(const rast__view *v, const float *clip, uint32_t base, int count,
                     rast__vc_entry *e);
void rast__vfill_avx2(const rast__view *v, const float *clip, uint32_t base, int count,
                      rast__vc_entry *e);
void rast__vfill_avx512(const rast__view *v, const float *clip, uint32_t base, int count,
                        rast__vc_entry *e);
void rast__vfill_sse2(const rast__view *v, const float *clip, uint32_t base, int count,
                      rast__vc_entry *e);
void rast__vfill_neon(const rast__view *v, const float *clip, uint32_t base, int count,
                      rast__vc_entry *e);

/* The set-up kernels of an ISA for rast__prepare_range: planes in
 * batches, and vertex cache misses filled RAST__VBLOCK aligned vertices
 * at a time (meshes index nearby vertices together). */
/* Trivial rejection of RAST__FRONT_GROUP submitted triangles ti .. ti+15
 * at once (one per lane): for triangles whose three vertices are cached
 * and valid (flags 0), the area, culling, pixel box and, for boxes of at
 * most 2x2 pixels, the empty-centre test of the scalar set-up; those rejected (and
 * empty ones) are counted in *st exactly as the scalar path counts them.
 * Returns the lanes the scalar path must still run (survivors, vertices
 * not cached or needing clipping), bit l for triangle ti + l. May fill
 * cache entries (as a lookup does). */
#define RAST__FRONT_GROUP 16
typedef unsigned (*rast__front_fn)(const rast__view *v, const rast_mesh_desc *m,
                                   rast__vcache *vc, int ti, rast_stats *st,
                                   rast__vfill_fn vfill);
unsigned rast__front_avx512(const rast__view *v, const rast_mesh_desc *m, rast__vcache *vc,
                            int ti, rast_stats *st, rast__vfill_fn vfill);

/* ---- the vector front end (sixth round, docs/raster.md section 11) ------
 *
 * Per draw, every vertex is transformed once into a vertex buffer owned by
 * the context (no tags, no misses): the snapped position as one 64-bit
 * pair (X low, Y high; X = RAST__VX_SPECIAL when the vertex is not finite,
 * outside a clip plane or at w <= 0, i.e. when the vertex cache would give
 * it flags != 0) and the double plane inputs zw, iw (valid when X is not
 * the marker). Then groups of RAST__FRONT_GROUP submitted triangles are
 * rejected in lanes (area, culling, box, empty boxes up to 2x2), the
 * survivors queued (compressed) and set up RAST__FRONT_GROUP at a time in
 * lanes straight into their scan-ready records: box, biased int64 edges,
 * planes (the double operations of planes_one per lane) and attributes.
 * Triangles with a marked vertex go through rast__prepare in order. The
 * records and counters are those of rast__prepare_range. With micro set,
 * the survivors whose box is at most 2x2 pixels get micro records instead
 * (rast__tri.micro: the scan's per-pixel values computed in lanes, one
 * triangle per lane), in the same slots; rast__scan_list with micro set
 * writes their pixels. */
#define RAST__VX_SPECIAL INT32_MIN
/* Y of a marked vertex (both vertex passes): its outcode (bits 0..5,
 * RAST__VX_OUTCODE) | RAST__VX_NONFINITE when a coordinate is not finite
 * (then the outcode bits are unspecified). */
#define RAST__VX_OUTCODE 0x3F
#define RAST__VX_NONFINITE 0x40
#define RAST__VX_CHUNK 128                        /* submitted triangles per chunk */
#define RAST__VX_CAP (1 << 17)                    /* vertices per buffer */
typedef struct rast__vbuf {
    int cap;                  /* vertices (a multiple of 16) */
    int32_t *xy;              /* 2 per vertex: X, Y */
    double *zw, *iw;          /* 1 per vertex */
    rast__tri *out;           /* RAST__VX_CHUNK * RAST__MAX_FAN records */
} rast__vbuf;
/* A buffer for cap vertices (rounded up to 16) in one 64-byte aligned
 * block, or NULL; rast__vbuf_free(NULL) is fine. */
rast__vbuf *rast__vbuf_alloc(int cap);
void rast__vbuf_free(rast__vbuf *vb);
/* Fills vb for the count vertices at clip (count <= vb->cap). */
typedef void (*rast__vpass_fn)(const rast__view *v, const float *clip, int count,
                               rast__vbuf *vb);
/* The set-up of submitted triangles ti0 .. ti1-1 (indices validated, vb
 * filled by the vpass of the same ISA for m's clip coordinates) into out
 * (room for (ti1 - ti0) * RAST__MAX_FAN): returns the record count; adds
 * the counters but tris_in and pixels_written to *st. Records and
 * counters equal rast__prepare_range's (bytes of the fields it writes)
 * when micro is 0. */
typedef int (*rast__frontv_fn)(const rast__view *v, const rast_mesh_desc *m,
                               const rast__vbuf *vb, int ti0, int ti1, rast__tri *out,
                               rast_stats *st, int micro);
void rast__vpass_avx2(const rast__view *v, const float *clip, int count, rast__vbuf *vb);
int rast__frontv_avx2(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                      int ti0, int ti1, rast__tri *out, rast_stats *st, int micro);
void rast__vpass_avx512(const rast__view *v, const float *clip, int count, rast__vbuf *vb);
int rast__frontv_avx512(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                        int ti0, int ti1, rast__tri *out, rast_stats *st, int micro);

typedef struct rast__setup_isa {
    rast__planes_fn planes;
    rast__vfill_fn vfill;
    rast__front_fn front;     /* NULL: every triangle through the scalar path */
    rast__vpass_fn vpass;     /* NULL (with frontv): no vector front end */
    rast__frontv_fn frontv;
} rast__setup_isa;
extern const rast__setup_isa rast__setup_isa_ref, rast__setup_isa_sse2, rast__setup_isa_avx2,
    rast__setup_isa_avx512, rast__setup_isa_neon;
/* The set-up kernels that go with a row scan (those of the scan's ISA;
 * the scalar ones for the reference). */
const rast__setup_isa *rast__setup_for_scan(rast__scan_rows_fn scan);

/* rast__prepare_cached for submitted triangles ti0 .. ti1-1 in order,
 * writing their fan triangles one after the other to out (room for
 * (ti1 - ti0) * RAST__MAX_FAN); returns their count. The same triangles,
 * bytes and counters as rast__prepare_cached per triangle, without a call
 * per triangle for the common rejections. With isa not NULL, the planes
 * of trivially accepted triangles are computed in batches by isa->planes
 * (before the function returns) and cache misses filled in blocks by
 * isa->vfill; NULL: one by one as rast__prepare_cached. */
int rast__prepare_range(const rast__view *view, const rast_mesh_desc *m, int ti0,
                        int ti1, rast__vcache *vc, rast__tri *out, rast_stats *st,
                        const rast__setup_isa *isa);

/* ---- anti-aliased coverage (raster_aa.c, raster_aa.inl) ---------------- */

/* rast__prepare for anti-aliased coverage: the same fetch, clip, snap,
 * culling and counters, then edges only (planes and attributes left
 * zero) and the pixel box of the samples instead of the centres. */
int rast__prepare_aa(const rast__view *view, const rast_mesh_desc *m, int ti,
                     rast__tri *out, rast_stats *st);

/* Sample offsets from the pixel centre in 1/16 px (D3D standard
 * patterns), count = 4, 8 or 16; NULL otherwise. */
const int8_t (*rast__aa_pattern(int count))[2];

/* ORs the samples of tri covered in each pixel into t (rows ya..yb of the
 * box); returns the number of pixels with at least one covered sample.
 * Sample s of pixel (x, y) is covered iff every edge value at
 * p = centre + 16 * offset_s (1/256 px units) is >= 0 (int64, the biased
 * edges of the tri: the top-left rule for samples):
 *   E_k(p) = e_c[k] + i * e_dx[k] + j * e_dy[k] + dx_k * 16*oy_s - dy_k * 16*ox_s
 * with dx_k = e_dy[k] / 256, dy_k = -e_dx[k] / 256. */
typedef long (*rast__scan_aa_fn)(const rast_aa_target *t, const rast__tri *tri,
                                 int ya, int yb);
long rast__scan_aa_ref(const rast_aa_target *t, const rast__tri *tri, int ya, int yb);
long rast__scan_aa_sse2(const rast_aa_target *t, const rast__tri *tri, int ya, int yb);
long rast__scan_aa_avx2(const rast_aa_target *t, const rast__tri *tri, int ya, int yb);
long rast__scan_aa_avx512(const rast_aa_target *t, const rast__tri *tri, int ya, int yb);
long rast__scan_aa_neon(const rast_aa_target *t, const rast__tri *tri, int ya, int yb);
rast__scan_aa_fn rast__scan_aa_for_isa(int isa);
/* rast_draw_aa with a given scan. */
rast_result rast__draw_aa_with(const rast_aa_target *t, const rast_mesh_desc *m,
                               rast_stats *stats, rast__scan_aa_fn scan);

/* dst += s, every counter. */
void rast__stats_add(rast_stats *dst, const rast_stats *s);
/* Attribute count carried through clipping for this draw (0 unless both
 * the target and the mesh have attributes). */
int rast__draw_na(const rast_target *t, const rast_mesh_desc *m);

/* The scalar reference scan. */
long rast__scan_ref(const rast_target *t, const rast__tri *tri);
long rast__scan_rows_ref(const rast_target *t, const rast__tri *tri, int ya,
                         int yb);

/* SIMD scans (raster_sse2.c, raster_avx2.c, raster_avx512.c,
 * raster_neon.c; one body, raster_simd.inl on src/cpu's vector layer). Each gives the bytes of rast__scan_ref. They may only
 * be called when ef_cpu_has() says the CPU runs the ISA. */
long rast__scan_rows_sse2(const rast_target *t, const rast__tri *tri, int ya,
                          int yb);
long rast__scan_rows_avx2(const rast_target *t, const rast__tri *tri, int ya,
                          int yb);
long rast__scan_rows_avx512(const rast_target *t, const rast__tri *tri,
                            int ya, int yb);
long rast__scan_rows_neon(const rast_target *t, const rast__tri *tri, int ya,
                          int yb);
/* The vertex transforms of raster.h: the scalar reference (raster_ref.c)
 * and the AVX2 and AVX-512 versions (raster_xform.inl compiled by
 * raster_avx2.c and raster_avx512.c, same bytes; call only when the CPU
 * runs that ISA). rast_transform_points / _dirs use the best one
 * rast_draw_isa() allows. */
void rast__transform_points_ref(const float mvp[16], const float *pos, int n, float *clip);
void rast__transform_dirs_ref(const float m[16], const float *v, int n, float *out);
void rast__transform_points_avx2(const float mvp[16], const float *pos, int n, float *clip);
void rast__transform_dirs_avx2(const float m[16], const float *v, int n, float *out);
void rast__transform_points_avx512(const float mvp[16], const float *pos, int n, float *clip);
void rast__transform_dirs_avx512(const float m[16], const float *v, int n, float *out);
/* The row scan for an ISA (an ef_isa value); the reference for
 * EF_ISA_REF, for an ISA not compiled in, and for unknown values. */
rast__scan_rows_fn rast__scan_for_isa(int isa);

#endif
