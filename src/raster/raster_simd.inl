/* raster_simd.inl - the SIMD scan body shared by raster_sse2.c,
 * raster_avx2.c and raster_avx512.c. Each includes this file once after
 * defining the lane macros below; the body then gives exactly the bytes of
 * rast__scan_rows_ref (raster_ref.c): the same integer coverage test and,
 * per lane, the same IEEE float operations in the same order.
 *
 * Written on the vector layer (src/cpu/simd.h): the including file
 * includes one implementation (simd_sse2.h, simd_avx2.h, simd_avx512.h,
 * simd_neon.h) and then this file, which defines SIMD_FN(rast__scan_rows)
 * (rast__scan_rows_sse2, ...). vf_max(0, z) and vf_min(1, z) have the x86
 * semantics on every ISA (simd.h), which equal the reference's selects,
 * -0.0 and NaN included; vf_from_vi is exact here (|i| < 2^24). Besides
 * the layer (its raster ops: vi_sign_bits, vb_store_bits, vf_store3_bits),
 * an including file may define what its ISA does better:
 *   ATTR3_STORE_M(p, bits, lanes, a0, a1, a2)  vf_store3_bits for the
 *                          pixels in bits, which lie in the first `lanes`
 *                          lanes (the box width of a one-vector row, the
 *                          lanes left in a wider one), so the outputs
 *                          needed are known per triangle.
 *   ATTR3_STATE, ATTR3_PREP(st, tri, lanes), ATTR3_STORE_P(p, bits, st, b1, b2, in)
 *                          three attributes of a one-vector row from the
 *                          pixels' barycentrics b1, b2: PREP fills the
 *                          per-triangle state *st (rows at most `lanes`
 *                          pixels), STORE_P writes the pixels in bits of
 *                          p[3*lanes] as (a0 + b1*d1) + b2*d2 per float.
 *   ATTR3_STORE_PL(p, bits, lanes, st, b1, b2, in)  as ATTR3_STORE_P for a run
 *                          vector of `lanes` pixels of a wider row (bits
 *                          within them; st prepared with SIMD_W lanes).
 *   VF_DIV_LANES(a, b, lanes)  a / b in the first `lanes` lanes (the
 *                          others: any value; nothing derived from them is
 *                          stored).
 *   DEPTH_RUN(p, rem, z, in)  the depth test of a run vector: the lanes
 *                          l < rem (rem >= 1) with z < p[l] (ordered) get
 *                          p[l] = z and are returned as bits; no float of p
 *                          outside the first rem is written (the generic
 *                          one below, on lane bits).
 *   N10_STORE(p, bits, v, in)  the n10 plane's store (rast_target.attr_n10):
 *                          p[l] = lane l of the vint v for the lanes l in
 *                          bits, no other uint32_t written (the generic
 *                          one below: a whole vector, or read, select and
 *                          write back when in, else lane by lane).
 * in (ATTR3_STORE_P, _PL, DEPTH_RUN, N10_STORE): nonzero when the SIMD_W pixels of the
 * vector lie inside the target's row, so that an implementation may read
 * all of the vector's depths and attributes and write back the ones it
 * does not change (rows belong to one thread: bands are rows) instead of
 * a masked store: AVX2's vmaskmovps store costs about 12 cycles on the
 * AMD Zen 4 of the benchmarks against 1 for a load, a blend and a store.
 * (raster_avx512.c defines them with AVX-512 permutes and masks.)
 *
 * COVERAGE. The reference tests E >= 0 with int64 E stepped by multiples of
 * 256 (e_dx = -dy*256, e_dy = dx*256). Since floor((E + 256k)/256) =
 * floor(E/256) + k and E >= 0 <=> floor(E/256) >= 0, the body tests the
 * reduced value E' = floor(E/256) stepped by -dy and dx, the same sign for
 * every pixel. Bounds: |dx|, |dy| < 2^23 (docs/raster.md section 2).
 *   * Fast path (int32 throughout): when the bound |c| + rows*|sy| +
 *     cols*|sx| of |E'| over the scanned rows x [0, nvec*SIMD_W) (at least
 *     the largest corner value, E' being affine) lies below 2^30, every
 *     value and every step difference fits int32: int32 adds give the
 *     exact integers. Triangles one vector wide (most of a fine mesh)
 *     take their own loop (simd_scan_vec1, with its own short prologue):
 *     coverage first, the float row values only for rows with covered
 *     pixels, the attribute set-up only from the first row that writes a
 *     pixel. Wider ones test a row's
 *     coverage vectors first (from the left, up to the end of the row's
 *     one run of covered pixels) and then do the float work on vectors
 *     that start at the run's first pixel: a run of at most SIMD_W
 *     pixels costs one vector wherever it lies (long thin slivers).
 *   * Otherwise (huge triangles, vertices far in the guard band): E' of the
 *     first lane of each vector is computed in int64 and clamped to
 *     [-2^29, 2^29] before adding the lane offsets l*(-dy), |l*dy| <
 *     15 * 2^23 < 2^27. A clamped value keeps its sign, and so does every
 *     lane: 2^29 - 2^27 > 0. Lanes with an unclamped start are exact.
 */

#include "../cpu/ef_n10.h"

#ifndef ATTR3_STORE_M
#define ATTR3_STORE_M(p, bits, lanes, a, b, c) vf_store3_bits(p, bits, a, b, c)
#endif
#define ATTR3_STORE_FULL(p, a, b, c) vf_store3(p, a, b, c)

/* The bits of lanes 0 .. n - 1 (n >= 0; every lane from SIMD_W on). */
static inline unsigned simd_first_lanes(int n)
{
    return n >= SIMD_W ? SIMD_FULL : (1u << n) - 1u;
}

#ifndef DEPTH_RUN
static inline unsigned simd_depth_run(float *p, int rem, vfloat z)
{
    const unsigned run = simd_first_lanes(rem);
    const unsigned pass = run & vm_bits(vf_lt(z, vf_load_bits(p, run)));
    if (pass)
        vf_store_bits(p, pass, z);
    return pass;
}
#define DEPTH_RUN(p, rem, z, in) simd_depth_run(p, rem, z)
#endif

/* Lanes l with a < b (ordered), as bits. */
SIMD_INL unsigned simd_lt_bits(vfloat a, vfloat b)
{
    return vm_bits(vf_lt(a, b));
}

/* Lane l = l * s (int32; |l*s| < 2^27 here). */
SIMD_INL vint simd_lane_mul(vint lanes, int32_t s)
{
    return vi_mullo(lanes, vi_set1(s));
}
#define SIMD_LIM30 ((int64_t)(1 << 30) - 1)
#define SIMD_LIM29 ((int64_t)1 << 29)

/* floor(a / 256) for any sign: an arithmetic shift (gcc, clang and msvc
 * shift signed values arithmetically; checked by the soup test, where
 * half of the edge values are negative). */
static inline int64_t simd_floor256(int64_t a)
{
    return a >> 8;
}

static inline int32_t simd_clamp29(int64_t a)
{
    return (int32_t)(a < -SIMD_LIM29 ? -SIMD_LIM29 : a > SIMD_LIM29 ? SIMD_LIM29 : a);
}

static inline int64_t simd_abs64(int64_t a)
{
    return a < 0 ? -a : a;
}

/* Set bits of a lane mask. Without the popcnt instruction (the SSE2
 * build) __builtin_popcount is a libgcc call, around which every live
 * vector register is spilled: a few integer operations instead. */
static inline int simd_popcount(unsigned v)
{
#ifdef __POPCNT__
    return __builtin_popcount(v);
#else
    v = v - ((v >> 1) & 0x55555555u);
    v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
    v = (v + (v >> 4)) & 0x0F0F0F0Fu;
    return (int)((v * 0x01010101u) >> 24);
#endif
}

/* The attributes of the lanes in pass, written interleaved to dst. */
static inline void simd_attr_store(float *dst, int na, unsigned pass, int lanes, vfloat b1,
                                   vfloat b2, const vfloat *av0, const vfloat *av1, const vfloat *av2)
{
    (void)lanes;
#ifdef ATTR3_STORE_M
    if (na == 3) {
        ATTR3_STORE_M(dst, pass, lanes,
            vf_add(vf_add(av0[0], vf_mul(b1, av1[0])), vf_mul(b2, av2[0])),
            vf_add(vf_add(av0[1], vf_mul(b1, av1[1])), vf_mul(b2, av2[1])),
            vf_add(vf_add(av0[2], vf_mul(b1, av1[2])), vf_mul(b2, av2[2])));
        return;
    }
#endif
    _Alignas(64) float a[RAST_MAX_ATTRS][SIMD_W];
    for (int k = 0; k < na; k++)
        vf_store(a[k], vf_add(vf_add(av0[k], vf_mul(b1, av1[k])), vf_mul(b2, av2[k])));
    for (unsigned bits = pass; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        float *p = dst + (size_t)l * (size_t)na;
        for (int k = 0; k < na; k++)
            p[k] = a[k][l];
    }
}

/* THE N10 PLANE (rast_target.attr_n10). The three attributes of a vector
 * of pixels as three SoA vectors, each lane by the expression (and order)
 * of the float plane's, (a0 + b1 * d1) + b2 * d2, so they are the floats
 * the float plane gets, then packed as ef_n10_pack (src/cpu/ef_n10.h)
 * into one vint stored as one vector: no interleaving. ef_n10_quant per
 * lane: v = a * 511; v > -511 ? v : -511 is vf_max(v, -511) (the layer's
 * x86 semantics on every ISA: the second operand when v is NaN, so NaN
 * gives -511); v > 511 ? 511 : v is vf_min(511, v) (v is no NaN now);
 * vi_from_vf_round converts to nearest, ties to even (cvtps2dq with the
 * default MXCSR, NEON's vcvtnq; lrintf in ef_n10.h), exact here
 * (|v| <= 511). Then the low 10 bits of each, shifted by 0, 10, 20. */
SIMD_INL vint simd_n10_quant(vfloat a)
{
    const vfloat lim = vf_set1(EF_N10_SCALE);
    vfloat v = vf_mul(a, lim);
    v = vf_max(v, vf_set1(-EF_N10_SCALE));
    v = vf_min(lim, v);
    return vi_and(vi_from_vf_round(v), vi_set1(0x3ff));
}

SIMD_INL vint simd_n10_pack(vfloat x, vfloat y, vfloat z)
{
    return vi_or(vi_or(simd_n10_quant(x), vi_slli(simd_n10_quant(y), 10)),
                 vi_slli(simd_n10_quant(z), 20));
}

/* The packed attributes of the pixels of b1, b2 (the float plane's three
 * expressions, as simd_attr_store). */
SIMD_INL vint simd_attr_n10(vfloat b1, vfloat b2, const vfloat *av0, const vfloat *av1,
                            const vfloat *av2)
{
    return simd_n10_pack(vf_add(vf_add(av0[0], vf_mul(b1, av1[0])), vf_mul(b2, av2[0])),
                         vf_add(vf_add(av0[1], vf_mul(b1, av1[1])), vf_mul(b2, av2[1])),
                         vf_add(vf_add(av0[2], vf_mul(b1, av1[2])), vf_mul(b2, av2[2])));
}

#ifndef N10_STORE
SIMD_INL void simd_n10_store(uint32_t *p, unsigned bits, vint v, int in)
{
    if (bits == SIMD_FULL) {
        vi_storeu((int32_t *)p, v);
    } else if (in) {   /* the lanes not written get back the values read */
        const vint old = vi_loadu((const int32_t *)p);
        vi_storeu((int32_t *)p, vi_sel(vm_from_bits(bits), v, old));
    } else {
        _Alignas(64) int32_t l[SIMD_W];
        vi_store(l, v);
        for (; bits; bits &= bits - 1)
            p[__builtin_ctz(bits)] = (uint32_t)l[__builtin_ctz(bits)];
    }
}
#define N10_STORE(p, bits, v, in) simd_n10_store(p, bits, v, in)
#endif

/* One pixel (x, y) of the box: the reference's scalar expressions for
 * that pixel (fi, fj are the same floats, every op the same IEEE op),
 * without the vector set-up of the row scan. Used for boxes of one or two
 * pixels (1x1, 2x1, 1x2), whose vector set-up costs more than their
 * pixels. (Drawn through a context with the vector front end, such boxes
 * come as micro records instead and are not scanned.) */
static inline __attribute__((always_inline)) long simd_scan_pixel(const rast_target *t,
                                                                  const rast__tri *tri, int x,
                                                                  int y, const int n10)
{
    const int64_t i = x - tri->x0, j = y - tri->y0;
    if (((tri->e_c[0] + j * tri->e_dy[0] + i * tri->e_dx[0]) |
         (tri->e_c[1] + j * tri->e_dy[1] + i * tri->e_dx[1]) |
         (tri->e_c[2] + j * tri->e_dy[2] + i * tri->e_dx[2])) < 0)
        return 0;
    const float fj = (float)j, fi = (float)i;
    float z = (tri->z.c + tri->z.dy * fj) + tri->z.dx * fi;
    z = z < 0.0f ? 0.0f : z;
    z = z > 1.0f ? 1.0f : z;
    if (t->depth) {
        float *d = t->depth + (size_t)y * (size_t)t->depth_stride + x;
        if (!(z < *d))
            return 0;
        *d = z;
    }
    t->mask[(size_t)y * (size_t)t->mask_stride + x] = 255;
    const int na = n10 ? 3 : t->attr ? tri->attr_count : 0;
    if (na) {
        const float r = 1.0f / ((tri->q.c + tri->q.dy * fj) + tri->q.dx * fi);
        const float b1 = ((tri->b1.c + tri->b1.dy * fj) + tri->b1.dx * fi) * r;
        const float b2 = ((tri->b2.c + tri->b2.dy * fj) + tri->b2.dx * fi) * r;
        if (n10) {
            float a[3];
            for (int k = 0; k < 3; k++)
                a[k] = (tri->a0[k] + b1 * tri->d1[k]) + b2 * tri->d2[k];
            t->attr_n10[(size_t)y * (size_t)t->attr_n10_stride + x] = ef_n10_pack(a[0], a[1], a[2]);
            return 1;
        }
        float *a = t->attr + (size_t)y * (size_t)t->attr_stride + (size_t)x * (size_t)na;
        for (int k = 0; k < na; k++)
            a[k] = (tri->a0[k] + b1 * tri->d1[k]) + b2 * tri->d2[k];
    }
    return 1;
}

/* BOX DEPTH TEST: simd_zbox_hidden (raster_hidden.inl, shared with the
 * vector front end) on the record's z plane and box, over the rows ys .. ye
 * of the calling thread (bands are rows). */
#include "raster_hidden.inl"

static inline int simd_box_hidden(const rast_target *t, const rast__tri *tri, int ys, int ye,
                                  int nx)
{
    return simd_zbox_hidden(t, tri->z.c, tri->z.dx, tri->z.dy, tri->x0, tri->y0, ys, ye, nx);
}

/* Row state of the one-vector loop. */
typedef struct simd_vec1 {
    vint e0, e1, e2;                /* reduced edges of the current row */
    uint8_t *mrow;
    float *drow, *arow;           /* NULL without depth / attributes */
    uint32_t *nrow;               /* the n10 plane's row (scans with n10 only) */
    long written;
    int inrow;                    /* the SIMD_W pixels from x0 lie in the row */
} simd_vec1;

/* p[l] = 0xFF for the lanes l in bits (the scan's mask store) as one
 * read-modify-write of the SIMD_W bytes p[0 .. SIMD_W) (all of them inside
 * the target's row: the caller checked), the others written back with the
 * values read: no per-pixel loop and no data-dependent branch. Rows
 * belong to one thread (bands are rows), so the bytes written back are
 * never another thread's. With 8 lanes the bytes come from a table of the
 * 256 masks (2 KB: a load and an OR into memory); with 4, byte k of
 * (b * 0x01010101) & 0x08040201 is nonzero iff bit k of b is set, and
 * + 0x7F per byte carries into bit 7 of the byte exactly then (no carry
 * leaves a byte: at most 0x80 + 0x7F). */
#if SIMD_W == 8
#define SIMD_MB1(n) ((((n) & 1) ? 0xFFull : 0) | (((n) & 2) ? 0xFF00ull : 0) | \
                     (((n) & 4) ? 0xFF0000ull : 0) | (((n) & 8) ? 0xFF000000ull : 0) | \
                     (((n) & 16) ? 0xFF00000000ull : 0) | (((n) & 32) ? 0xFF0000000000ull : 0) | \
                     (((n) & 64) ? 0xFF000000000000ull : 0) | \
                     (((n) & 128) ? 0xFF00000000000000ull : 0))
#define SIMD_MB4(n) SIMD_MB1(n), SIMD_MB1((n) + 1), SIMD_MB1((n) + 2), SIMD_MB1((n) + 3)
#define SIMD_MB16(n) SIMD_MB4(n), SIMD_MB4((n) + 4), SIMD_MB4((n) + 8), SIMD_MB4((n) + 12)
#define SIMD_MB64(n) SIMD_MB16(n), SIMD_MB16((n) + 16), SIMD_MB16((n) + 32), SIMD_MB16((n) + 48)
static const uint64_t simd_mask_bytes8[256] = {
    SIMD_MB64(0), SIMD_MB64(64), SIMD_MB64(128), SIMD_MB64(192)
};
#undef SIMD_MB64
#undef SIMD_MB16
#undef SIMD_MB4
#undef SIMD_MB1
#endif

static inline void simd_mask_or(uint8_t *p, unsigned bits)
{
#if SIMD_W == 16
    vb_store_bits(p, bits);
#elif SIMD_W == 8
    uint64_t v;
    memcpy(&v, p, 8);
    v |= simd_mask_bytes8[bits & 0xFFu];
    memcpy(p, &v, 8);
#else
    uint32_t m = ((uint32_t)(bits & 0xFu) * 0x01010101u) & 0x08040201u;
    m = (((m + 0x7F7F7F7Fu) & 0x80808080u) >> 7) * 0xFFu;
    uint32_t v;
    memcpy(&v, p, 4);
    v |= m;
    memcpy(p, &v, 4);
#endif
}

/* Coverage, depth and mask of row y (the reference's z per lane), the
 * edges stepped to the next row; returns the lanes written. Always
 * inlined: called from both copies of simd_scan_vec1_body (floats, n10),
 * the compilers would otherwise make it a call per row. */
static inline __attribute__((always_inline)) unsigned simd_vec1_row(
    simd_vec1 *s, const rast__tri *tri, int y, unsigned valid, vint dy0, vint dy1, vint dy2,
    vfloat zfi)
{
    const unsigned cov = ~vi_sign_bits(vi_or(vi_or(s->e0, s->e1), s->e2)) & valid;
    s->e0 = vi_add(s->e0, dy0);
    s->e1 = vi_add(s->e1, dy1);
    s->e2 = vi_add(s->e2, dy2);
    if (!cov)
        return 0;
    const float fj = (float)(y - tri->y0);
    vfloat z = vf_add(vf_set1(tri->z.c + tri->z.dy * fj), zfi);
    z = vf_max(vf_set1(0.0f), z);
    z = vf_min(vf_set1(1.0f), z);
    unsigned pass = cov;
    if (s->inrow) {
        /* Whole-vector accesses inside the row: the lanes not written
         * get back the bits read (vf_sel copies them). */
        if (s->drow) {
            const vfloat d = vf_loadu(s->drow);
            pass = cov & simd_lt_bits(z, d);
            if (!pass)
                return 0;
            vf_storeu(s->drow, vf_sel(vm_from_bits(pass), z, d));
        }
        simd_mask_or(s->mrow, pass);
    } else {
        if (s->drow) {
            const vfloat d = vf_load_bits(s->drow, cov);
            pass = cov & simd_lt_bits(z, d);
            if (!pass)
                return 0;
            vf_store_bits(s->drow, pass, z);
        }
        vb_store_bits(s->mrow, pass);
    }
    s->written += simd_popcount(pass);
    return pass;
}

static inline __attribute__((always_inline)) void simd_vec1_next(simd_vec1 *s,
                                                                 const rast_target *t, int n10)
{
    s->mrow += t->mask_stride;
    if (s->drow)
        s->drow += t->depth_stride;
    if (n10)
        s->nrow += t->attr_n10_stride;
    else if (s->arow)
        s->arow += t->attr_stride;
}

/* Triangles one vector wide (nx <= SIMD_W; most of a fine mesh), int32
 * coverage (the caller checked the bound, see COVERAGE): c, sx, sy are the
 * reduced edge values at (x0, ys) and their steps. Coverage first, the
 * float work only for rows with covered pixels, and nothing is set up for
 * the attributes before the first row that writes a pixel (many scanned
 * triangles are hidden). Every row-invariant product (dx * fi) is computed
 * once: the same IEEE product in every row. n10 (a constant: the body is
 * compiled into both copies of the scan, see SIMD_FN(rast__scan_rows)):
 * the attributes go to the n10 plane (na is 3), else to the float plane
 * (if na). */
static inline __attribute__((always_inline)) long simd_scan_vec1_body(
    const rast_target *t, const rast__tri *tri, int ys, int ye, int nx, int na, int32_t c0,
    int32_t c1, int32_t c2, int32_t sx0, int32_t sx1, int32_t sx2, int32_t sy0, int32_t sy1,
    int32_t sy2, const int n10)
{
    const unsigned valid = simd_first_lanes(nx);
    const vint lanev = vi_lanes();
    simd_vec1 s;
    s.e0 = vi_add(vi_set1(c0), simd_lane_mul(lanev, sx0));
    s.e1 = vi_add(vi_set1(c1), simd_lane_mul(lanev, sx1));
    s.e2 = vi_add(vi_set1(c2), simd_lane_mul(lanev, sx2));
    s.written = 0;
    s.inrow = tri->x0 + SIMD_W <= t->width;
    s.mrow = t->mask + (size_t)ys * (size_t)t->mask_stride + tri->x0;
    s.drow = t->depth ? t->depth + (size_t)ys * (size_t)t->depth_stride + tri->x0 : NULL;
    s.arow = !n10 && na ? t->attr + (size_t)ys * (size_t)t->attr_stride +
                              (size_t)tri->x0 * (size_t)na
                        : NULL;
    s.nrow = n10 ? t->attr_n10 + (size_t)ys * (size_t)t->attr_n10_stride + tri->x0 : NULL;
    const vint dy0 = vi_set1(sy0), dy1 = vi_set1(sy1), dy2 = vi_set1(sy2);
    const vfloat fi = vf_from_vi(lanev);
    const vfloat zfi = vf_mul(vf_set1(tri->z.dx), fi);
    int y = ys;
    unsigned pass = 0;
    for (; y <= ye; y++, simd_vec1_next(&s, t, n10))
        if ((pass = simd_vec1_row(&s, tri, y, valid, dy0, dy1, dy2, zfi)) && na)
            break;
    if (y > ye)
        return s.written;

    /* Row y wrote pixels (pass) and there are attributes. */
    const vfloat one = vf_set1(1.0f);
    const vfloat qfi = vf_mul(vf_set1(tri->q.dx), fi);
    const vfloat b1fi = vf_mul(vf_set1(tri->b1.dx), fi);
    const vfloat b2fi = vf_mul(vf_set1(tri->b2.dx), fi);
    vfloat av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
#ifdef ATTR3_PREP
    ATTR3_STATE a3;
    if (na == 3 && !n10)
        ATTR3_PREP(&a3, tri, nx);
    else
#endif
        for (int k = 0; k < na; k++) {
            av0[k] = vf_set1(tri->a0[k]);
            av1[k] = vf_set1(tri->d1[k]);
            av2[k] = vf_set1(tri->d2[k]);
        }
    for (;;) {
        const float fj = (float)(y - tri->y0);
        const float qr = tri->q.c + tri->q.dy * fj;
        const float b1r = tri->b1.c + tri->b1.dy * fj;
        const float b2r = tri->b2.c + tri->b2.dy * fj;
#ifdef VF_DIV_LANES
        const vfloat r = VF_DIV_LANES(one, vf_add(vf_set1(qr), qfi), nx);
#else
        const vfloat r = vf_div(one, vf_add(vf_set1(qr), qfi));
#endif
        const vfloat b1 = vf_mul(vf_add(vf_set1(b1r), b1fi), r);
        const vfloat b2 = vf_mul(vf_add(vf_set1(b2r), b2fi), r);
        if (n10)
            N10_STORE(s.nrow, pass, simd_attr_n10(b1, b2, av0, av1, av2), s.inrow);
        else
#ifdef ATTR3_PREP
        if (na == 3)
            ATTR3_STORE_P(s.arow, pass, &a3, b1, b2, s.inrow);
        else
#endif
            simd_attr_store(s.arow, na, pass, nx, b1, b2, av0, av1, av2);
        do {
            if (++y > ye)
                return s.written;
            simd_vec1_next(&s, t, n10);
        } while (!(pass = simd_vec1_row(&s, tri, y, valid, dy0, dy1, dy2, zfi)));
    }
}

/* Rows wider than one vector, int32 coverage (the caller checked the
 * bound over rows ys..ye x [0, nvec*SIMD_W), see COVERAGE): c, sx, sy are
 * the reduced edge values at (x0, ys) and their steps. The covered pixels
 * of a row are one run: each E'_k is affine in i, so E'_k >= 0 holds on a
 * half-line of i and the three intersect in an interval (the box one too).
 * The rows go in chunks of SIMD_WIDE_ROWS, each in two passes:
 *   1. the runs: a row's coverage vectors (aligned at x0) are tested from
 *      the left, leading empty vectors skipped, and the run ends in the
 *      first vector whose last lane is not covered; the rows with a run
 *      are listed (row, first pixel, last + 1). Only the edge vectors are
 *      live in this loop.
 *   2. the float work of the listed rows, on vectors that start at the
 *      run's first pixel (lane l = pixel xf + l, fi = (float)(xf + l): the
 *      same ops per pixel), so a run of at most SIMD_W pixels takes one
 *      vector however it straddles the aligned ones (the slivers of capsule
 *      sides: runs of 4-10 pixels in boxes up to hundreds wide). Only the
 *      planes' values are live here: the edge vectors of pass 1 stay out
 *      of the registers this loop needs (on AVX2's 16 they were spilled and
 *      reloaded at every row, about a sixth of the AVX2 scan).
 * Loads and stores are masked to the run; no other pixel is accessed,
 * except the mask bytes of a vector that lies inside the row, which are
 * read and written back (simd_mask_or; rows belong to one thread). As in
 * simd_scan_vec1, the attribute set-up waits for the first pixel written
 * and a row's attribute bases for its first vector that writes (hidden
 * rows and triangles never pay for them); a run vector of at most half the
 * lanes divides on half a vector where the lane macros allow it
 * (VF_DIV_LANES). Not inlined into the dispatcher: with its own register
 * allocation it runs 0.1 % fewer instructions in the sample's frame
 * (callgrind, AVX2). */
#define SIMD_WIDE_ROWS 32

#if defined(__GNUC__) && !defined(__clang__)
/* a3 below is set at the first written pixel (aset) before any use, which
 * gcc cannot see (-Wmaybe-uninitialized); zeroing it cost a 300-byte
 * memset per triangle. */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
static inline __attribute__((always_inline)) long simd_scan_wide_body(
    const rast_target *t, const rast__tri *tri, int ys, int ye, int nx, int nvec, int na,
    const int64_t *c, const int32_t *sx, const int32_t *sy, const int n10)
{
    const vint lanev = vi_lanes();
    const unsigned lastvalid = SIMD_FULL >> (nvec * SIMD_W - nx);
    const vint st0 = vi_set1((int32_t)(SIMD_W * sx[0]));
    const vint st1 = vi_set1((int32_t)(SIMD_W * sx[1]));
    const vint st2 = vi_set1((int32_t)(SIMD_W * sx[2]));
    const vint sy0 = vi_set1(sy[0]), sy1 = vi_set1(sy[1]), sy2 = vi_set1(sy[2]);
    vint r0 = vi_add(vi_set1((int32_t)c[0]), simd_lane_mul(lanev, sx[0]));
    vint r1 = vi_add(vi_set1((int32_t)c[1]), simd_lane_mul(lanev, sx[1]));
    vint r2 = vi_add(vi_set1((int32_t)c[2]), simd_lane_mul(lanev, sx[2]));
    /* run vectors starting at i0 <= inrow lie inside the target's row */
    const int inrow = t->width - tri->x0 - SIMD_W;
    /* once, not per row: the stores to the float planes may alias *tri
     * for the compiler, which would load and broadcast it again */
    const vfloat zdx = vf_set1(tri->z.dx);
    long written = 0;
    /* Attribute state, set up at the first pixel written (aset). */
    int aset = 0;
    vfloat qdx = vf_set1(0.0f), b1dx = qdx, b2dx = qdx;
    vfloat qrv = qdx, b1rv = qdx, b2rv = qdx;   /* a row's, at its first vector that writes */
    vfloat av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
#if defined(ATTR3_PREP) && defined(ATTR3_STORE_PL)
    ATTR3_STATE a3;
#endif
    for (int yc = ys; yc <= ye; yc += SIMD_WIDE_ROWS) {
        const int n = ye - yc + 1 < SIMD_WIDE_ROWS ? ye - yc + 1 : SIMD_WIDE_ROWS;
        int32_t ry[SIMD_WIDE_ROWS], rf[SIMD_WIDE_ROWS], re[SIMD_WIDE_ROWS];
        int nrun = 0;
        for (int k = 0; k < n; k++) {
            vint e0 = r0, e1 = r1, e2 = r2;
            r0 = vi_add(r0, sy0);
            r1 = vi_add(r1, sy1);
            r2 = vi_add(r2, sy2);
            int v = 0;
            unsigned cov;
            for (;;) {
                cov = ~vi_sign_bits(vi_or(vi_or(e0, e1), e2)) &
                      (v == nvec - 1 ? lastvalid : SIMD_FULL);
                if (cov || v == nvec - 1)
                    break;
                v++;
                e0 = vi_add(e0, st0);
                e1 = vi_add(e1, st1);
                e2 = vi_add(e2, st2);
            }
            if (!cov)
                continue;
            const int xf = v * SIMD_W + __builtin_ctz(cov);
            while ((cov >> (SIMD_W - 1)) && v < nvec - 1) {
                e0 = vi_add(e0, st0);
                e1 = vi_add(e1, st1);
                e2 = vi_add(e2, st2);
                const unsigned nc = ~vi_sign_bits(vi_or(vi_or(e0, e1), e2)) &
                                    (v + 1 == nvec - 1 ? lastvalid : SIMD_FULL);
                if (!nc)
                    break;
                cov = nc;
                v++;
            }
            ry[nrun] = yc + k;
            rf[nrun] = xf;
            re[nrun] = v * SIMD_W + 32 - __builtin_clz(cov);   /* last + 1 */
            nrun++;
        }

        for (int q = 0; q < nrun; q++) {
            const int y = ry[q], xf = rf[q], xe = re[q];
            uint8_t *mrow = t->mask + (size_t)y * (size_t)t->mask_stride + tri->x0;
            float *drow = t->depth ? t->depth + (size_t)y * (size_t)t->depth_stride + tri->x0
                                   : NULL;
            /* Row bases: the reference's scalar expressions (the attribute
             * ones at the row's first vector that writes). */
            const float fj = (float)(y - tri->y0);
            const vfloat zrv = vf_set1(tri->z.c + tri->z.dy * fj);
            float *arow = NULL;   /* at the row's first vector that writes */
            uint32_t *nrow = NULL;   /* with n10: the same */
            for (int i0 = xf; i0 < xe; i0 += SIMD_W) {
                const int rem = xe - i0;
                const int lanes = rem < SIMD_W ? rem : SIMD_W;
                const vfloat fi = vf_from_vi(vi_add(vi_set1(i0), lanev));
                vfloat z = vf_add(zrv, vf_mul(zdx, fi));
                z = vf_max(vf_set1(0.0f), z);
                z = vf_min(vf_set1(1.0f), z);
                unsigned pass;
                if (drow) {
                    pass = DEPTH_RUN(drow + i0, rem, z, i0 <= inrow);
                    if (!pass)
                        continue;
                } else {
                    pass = simd_first_lanes(rem);
                }
                if (i0 <= inrow)
                    simd_mask_or(mrow + i0, pass);
                else
                    vb_store_bits(mrow + i0, pass);
                written += simd_popcount(pass);
                if (!na)
                    continue;
                if (!aset) {
                    aset = 1;
                    qdx = vf_set1(tri->q.dx);
                    b1dx = vf_set1(tri->b1.dx);
                    b2dx = vf_set1(tri->b2.dx);
#if defined(ATTR3_PREP) && defined(ATTR3_STORE_PL)
                    if (na == 3 && !n10)
                        ATTR3_PREP(&a3, tri, SIMD_W);
                    else
#endif
                        for (int k = 0; k < na; k++) {
                            av0[k] = vf_set1(tri->a0[k]);
                            av1[k] = vf_set1(tri->d1[k]);
                            av2[k] = vf_set1(tri->d2[k]);
                        }
                }
                if (n10 ? !nrow : !arow) {
                    if (n10)
                        nrow = t->attr_n10 + (size_t)y * (size_t)t->attr_n10_stride + tri->x0;
                    else
                        arow = t->attr + (size_t)y * (size_t)t->attr_stride +
                               (size_t)tri->x0 * (size_t)na;
                    qrv = vf_set1(tri->q.c + tri->q.dy * fj);
                    b1rv = vf_set1(tri->b1.c + tri->b1.dy * fj);
                    b2rv = vf_set1(tri->b2.c + tri->b2.dy * fj);
                }
#ifdef VF_DIV_LANES
                const vfloat r = VF_DIV_LANES(vf_set1(1.0f), vf_add(qrv, vf_mul(qdx, fi)), lanes);
#else
                const vfloat r = vf_div(vf_set1(1.0f), vf_add(qrv, vf_mul(qdx, fi)));
#endif
                const vfloat b1 = vf_mul(vf_add(b1rv, vf_mul(b1dx, fi)), r);
                const vfloat b2 = vf_mul(vf_add(b2rv, vf_mul(b2dx, fi)), r);
                if (n10) {
                    N10_STORE(nrow + i0, pass, simd_attr_n10(b1, b2, av0, av1, av2),
                              i0 <= inrow);
                    continue;
                }
                float *dst = arow + (size_t)i0 * (size_t)na;
#if defined(ATTR3_PREP) && defined(ATTR3_STORE_PL)
                if (na == 3) {
                    ATTR3_STORE_PL(dst, pass, lanes, &a3, b1, b2, i0 <= inrow);
                    continue;
                }
#elif defined(ATTR3_STORE_FULL)
                if (na == 3 && pass == SIMD_FULL) {
                    ATTR3_STORE_FULL(dst,
                        vf_add(vf_add(av0[0], vf_mul(b1, av1[0])), vf_mul(b2, av2[0])),
                        vf_add(vf_add(av0[1], vf_mul(b1, av1[1])), vf_mul(b2, av2[1])),
                        vf_add(vf_add(av0[2], vf_mul(b1, av1[2])), vf_mul(b2, av2[2])));
                    continue;
                }
#endif
                simd_attr_store(dst, na, pass, lanes, b1, b2, av0, av1, av2);
            }
        }
    }
    return written;
}

__attribute__((noinline)) static long simd_scan_wide(const rast_target *t, const rast__tri *tri,
                                                     int ys, int ye, int nx, int nvec, int na,
                                                     const int64_t *c, const int32_t *sx,
                                                     const int32_t *sy)
{
    return simd_scan_wide_body(t, tri, ys, ye, nx, nvec, na, c, sx, sy, 0);
}

/* The same into the n10 plane (na is 3). */
__attribute__((noinline)) static long simd_scan_wide_n10(const rast_target *t,
                                                         const rast__tri *tri, int ys, int ye,
                                                         int nx, int nvec, const int64_t *c,
                                                         const int32_t *sx, const int32_t *sy)
{
    return simd_scan_wide_body(t, tri, ys, ye, nx, nvec, 3, c, sx, sy, 1);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

/* The scan of the rows ya..yb (SIMD_FN(rast__scan_rows) below), its
 * attributes to the float plane (n10 0) or to the n10 plane (n10 1, a
 * constant: two copies, so the float path's code is what it was without
 * the n10 plane). */
static inline __attribute__((always_inline)) long simd_scan_rows_body(const rast_target *t,
                                                                      const rast__tri *tri,
                                                                      int ya, int yb,
                                                                      const int n10)
{
    const int ys = ya > tri->y0 ? ya : tri->y0;
    const int ye = yb < tri->y1 ? yb : tri->y1;
    if (ys > ye)
        return 0;
    if (tri->x0 == tri->x1) {
        if (ys == ye)
            return simd_scan_pixel(t, tri, tri->x0, ys, n10);
        if (ys + 1 == ye)
            return simd_scan_pixel(t, tri, tri->x0, ys, n10) +
                   simd_scan_pixel(t, tri, tri->x0, ye, n10);
    } else if (tri->x0 + 1 == tri->x1 && ys == ye) {
        return simd_scan_pixel(t, tri, tri->x0, ys, n10) +
               simd_scan_pixel(t, tri, tri->x1, ys, n10);
    }
    const int na = n10 ? 3 : t->attr ? tri->attr_count : 0;
    const int nx = tri->x1 - tri->x0 + 1;
    if (nx <= SIMD_W) {
        if (t->depth && simd_box_hidden(t, tri, ys, ye, nx))
            return 0;
        /* One vector wide: the int32 bound over rows ys..ye and the
         * SIMD_W lanes (as below with nvec = 1); when it fails, the int64
         * loop below. */
        const int64_t dj = ys - tri->y0, rows = ye - ys;
        const int64_t c0 = simd_floor256(tri->e_c[0] + dj * tri->e_dy[0]);
        const int64_t c1 = simd_floor256(tri->e_c[1] + dj * tri->e_dy[1]);
        const int64_t c2 = simd_floor256(tri->e_c[2] + dj * tri->e_dy[2]);
        const int32_t sx0 = (int32_t)(tri->e_dx[0] >> 8), sy0 = (int32_t)(tri->e_dy[0] >> 8);
        const int32_t sx1 = (int32_t)(tri->e_dx[1] >> 8), sy1 = (int32_t)(tri->e_dy[1] >> 8);
        const int32_t sx2 = (int32_t)(tri->e_dx[2] >> 8), sy2 = (int32_t)(tri->e_dy[2] >> 8);
        const int64_t cols = SIMD_W - 1;
        if (simd_abs64(c0) + rows * simd_abs64(sy0) + cols * simd_abs64(sx0) <= SIMD_LIM30 &&
            simd_abs64(c1) + rows * simd_abs64(sy1) + cols * simd_abs64(sx1) <= SIMD_LIM30 &&
            simd_abs64(c2) + rows * simd_abs64(sy2) + cols * simd_abs64(sx2) <= SIMD_LIM30)
            return simd_scan_vec1_body(t, tri, ys, ye, nx, na, (int32_t)c0, (int32_t)c1,
                                       (int32_t)c2, sx0, sx1, sx2, sy0, sy1, sy2, n10);
    }
    const int nvec = (nx + SIMD_W - 1) / SIMD_W;
    if (t->depth && nx > SIMD_W && nvec <= 4 && simd_box_hidden(t, tri, ys, ye, nx))
        return 0;
    const int64_t rows = ye - ys;

    /* Reduced edges, relative to (x0, ys). sx, sy are the snapped edge
     * deltas (|dx|, |dy| < 2^23). The int32 path is taken when a bound
     * of |E'| over the scanned rectangle (|c| + rows*|sy| + cols*|sx|,
     * at least the largest corner value) stays below 2^30 (always fails
     * for nvec == 1: such boxes that fit took simd_scan_vec1). */
    int64_t c[3];
    int32_t sx[3], sy[3];
    int fits = 1;
    const int64_t cols = (int64_t)nvec * SIMD_W - 1;
    for (int k = 0; k < 3; k++) {
        c[k] = simd_floor256(tri->e_c[k] + (int64_t)(ys - tri->y0) * tri->e_dy[k]);
        sx[k] = (int32_t)(tri->e_dx[k] >> 8);      /* exact: multiples of 256 */
        sy[k] = (int32_t)(tri->e_dy[k] >> 8);
        fits &= simd_abs64(c[k]) + rows * simd_abs64(sy[k]) + cols * simd_abs64(sx[k]) <=
                SIMD_LIM30;
    }
    if (fits)
        return n10 ? simd_scan_wide_n10(t, tri, ys, ye, nx, nvec, c, sx, sy)
                   : simd_scan_wide(t, tri, ys, ye, nx, nvec, na, c, sx, sy);
    const vint lanev = vi_lanes();
    const vint off0 = simd_lane_mul(lanev, sx[0]), off1 = simd_lane_mul(lanev, sx[1]),
             off2 = simd_lane_mul(lanev, sx[2]);

    const vfloat zero = vf_set1(0.0f), one = vf_set1(1.0f);
    const vfloat zdx = vf_set1(tri->z.dx);
    vfloat av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
    for (int k = 0; k < na; k++) {
        av0[k] = vf_set1(tri->a0[k]);
        av1[k] = vf_set1(tri->d1[k]);
        av2[k] = vf_set1(tri->d2[k]);
    }

    long written = 0;
    uint8_t *mrow = t->mask + (size_t)ys * (size_t)t->mask_stride + tri->x0;
    float *drow = t->depth ? t->depth + (size_t)ys * (size_t)t->depth_stride + tri->x0
                           : NULL;
    float *arow = na && !n10 ? t->attr + (size_t)ys * (size_t)t->attr_stride +
                                     (size_t)tri->x0 * (size_t)na
                               : NULL;
    uint32_t *nrow = n10 ? t->attr_n10 + (size_t)ys * (size_t)t->attr_n10_stride + tri->x0
                         : NULL;
    const vfloat qdx = vf_set1(tri->q.dx);
    const vfloat b1dx = vf_set1(tri->b1.dx), b2dx = vf_set1(tri->b2.dx);

    /* Int64 coverage (clamped starts, see COVERAGE): vectors aligned at
     * x0, every vector of every row tested. */
    int64_t rb[3] = { c[0], c[1], c[2] };
    for (int y = ys; y <= ye; y++, mrow += t->mask_stride,
             drow = drow ? drow + t->depth_stride : NULL,
             arow = arow ? arow + t->attr_stride : NULL,
             nrow = nrow ? nrow + t->attr_n10_stride : NULL) {
        /* Row bases: the reference's scalar expressions. */
        const float fj = (float)(y - tri->y0);
        const float zr = tri->z.c + tri->z.dy * fj;
        const float qr = tri->q.c + tri->q.dy * fj;
        const float b1r = tri->b1.c + tri->b1.dy * fj;
        const float b2r = tri->b2.c + tri->b2.dy * fj;
        const vfloat zrv = vf_set1(zr);
        int64_t eb0 = rb[0], eb1 = rb[1], eb2 = rb[2];
        for (int v = 0; v < nvec; v++) {
            const int i0 = v * SIMD_W;
            const int rem = nx - i0;
            const unsigned valid = simd_first_lanes(rem);
            const vint t0 = vi_add(vi_set1(simd_clamp29(eb0)), off0);
            const vint t1 = vi_add(vi_set1(simd_clamp29(eb1)), off1);
            const vint t2 = vi_add(vi_set1(simd_clamp29(eb2)), off2);
            const unsigned neg = vi_sign_bits(vi_or(vi_or(t0, t1), t2));
            eb0 += SIMD_W * (int64_t)sx[0];
            eb1 += SIMD_W * (int64_t)sx[1];
            eb2 += SIMD_W * (int64_t)sx[2];
            const unsigned cov = ~neg & valid;
            if (!cov)
                continue;
            const vfloat fi = vf_from_vi(vi_add(vi_set1(i0), lanev));
            vfloat z = vf_add(zrv, vf_mul(zdx, fi));
            z = vf_max(zero, z);
            z = vf_min(one, z);
            unsigned pass = cov;
            if (drow) {
                const vfloat d = vf_load_bits(drow + i0, cov);
                pass = cov & simd_lt_bits(z, d);
                if (!pass)
                    continue;
                vf_store_bits(drow + i0, pass, z);
            }
            vb_store_bits(mrow + i0, pass);
            written += simd_popcount(pass);
            if (!na)
                continue;
            const vfloat r = vf_div(one, vf_add(vf_set1(qr), vf_mul(qdx, fi)));
            const vfloat b1 = vf_mul(vf_add(vf_set1(b1r), vf_mul(b1dx, fi)), r);
            const vfloat b2 = vf_mul(vf_add(vf_set1(b2r), vf_mul(b2dx, fi)), r);
            if (n10) {   /* masked: no lane outside the row is read */
                N10_STORE(nrow + i0, pass, simd_attr_n10(b1, b2, av0, av1, av2), 0);
                continue;
            }
            float *dst = arow + (size_t)i0 * (size_t)na;
#ifdef ATTR3_STORE_FULL
            if (na == 3 && pass == SIMD_FULL) {
                ATTR3_STORE_FULL(dst,
                    vf_add(vf_add(av0[0], vf_mul(b1, av1[0])), vf_mul(b2, av2[0])),
                    vf_add(vf_add(av0[1], vf_mul(b1, av1[1])), vf_mul(b2, av2[1])),
                    vf_add(vf_add(av0[2], vf_mul(b1, av1[2])), vf_mul(b2, av2[2])));
                continue;
            }
#endif
            simd_attr_store(dst, na, pass, rem, b1, b2, av0, av1, av2);
        }
        rb[0] += sy[0];
        rb[1] += sy[1];
        rb[2] += sy[2];
    }
    return written;
}

/* The n10 copy, not inlined into the float one. */
__attribute__((noinline)) static long simd_scan_rows_n10(const rast_target *t,
                                                         const rast__tri *tri, int ya, int yb)
{
    return simd_scan_rows_body(t, tri, ya, yb, 1);
}

/* attr_n10 set: the n10 copy (validated: attr_count 3, attr NULL; a
 * record with another count would have no attributes, as the float copy
 * gives it with attr NULL). */
long SIMD_FN(rast__scan_rows)(const rast_target *t, const rast__tri *tri, int ya, int yb)
{
    if (t->attr_n10 && tri->attr_count == 3)
        return simd_scan_rows_n10(t, tri, ya, yb);
    return simd_scan_rows_body(t, tri, ya, yb, 0);
}
