/* raster_front.inl - the steps of the vector front end that are the same at
 * every lane width, written once on the vector layer (src/cpu/simd.h) and
 * shared by the front end (raster_frontv.inl, raster_frontq.inl) of
 * raster_front_avx2.c (8 lanes) and raster_front_avx512.c, and by the
 * 16-triangle rejection of raster_avx512.c (16 lanes). Every step runs,
 * per lane, the operations of the scalar path (raster_setup.c) in its
 * order, so the bytes do not depend on the lane width (docs/raster.md
 * section 11). Included after one layer implementation (simd_<isa>.h);
 * FRONT_V is its SIMD_W. */

#define FRONT_V SIMD_W

/* Lanes with a*b > c*d (gt) or a*b < c*d (!gt), exact in double
 * (|a|, |b|, |c|, |d| < 2^23: products below 2^46). */
SIMD_INL unsigned prod_cmp(vint a, vint b, vint c, vint d, int gt)
{
    unsigned r = 0;
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        const vdouble p1 = vd_mul(vd_from_vi(a, h), vd_from_vi(b, h));
        const vdouble p2 = vd_mul(vd_from_vi(c, h), vd_from_vi(d, h));
        /* p1 < p2 as p2 > p1: the predicate stays a constant (clang, -Os) */
        r |= vd_gt_bits(gt ? p1 : p2, gt ? p2 : p1) << (VD_W * h);
    }
    return r;
}

/* Lanes whose edge (deltas dx, dy) keeps E == 0 (top-left rule: dy < 0,
 * or dy == 0 and dx > 0). */
SIMD_INL vmask top_left(vint dx, vint dy)
{
    const vint zero = vi_zero();
    return vm_or(vi_gt(zero, dy), vm_and(vi_eq(dy, zero), vi_gt(dx, zero)));
}

/* Biased edge value from a to b at (cx, cy) in int32 (boxes up to 2x2:
 * differences below 768, products below 2^20; front_empty_small): e, or
 * e - 1 where the edge is not top-left. */
SIMD_INL vint front_edge32(vint xa, vint ya, vint xb, vint yb, vint cx, vint cy)
{
    const vint dx = vi_sub(xb, xa), dy = vi_sub(yb, ya);
    const vint e = vi_sub(vi_mullo(dx, vi_sub(cy, ya)), vi_mullo(dy, vi_sub(cx, xa)));
    return vi_add(e, vi_sel(top_left(dx, dy), vi_zero(), vi_set1(-1)));
}

/* ---- rejection ---------------------------------------------------------- */

/* Lanes with area > 0 (pos) and area < 0 (neg) of the triangles X, Y
 * (the sign of dx1*dy2 - dy1*dx2, exact in double). */
static inline void front_area_signs(const vint X[3], const vint Y[3], unsigned *pos,
                                    unsigned *neg)
{
    const vint dx1 = vi_sub(X[1], X[0]), dy1 = vi_sub(Y[1], Y[0]);
    const vint dx2 = vi_sub(X[2], X[0]), dy2 = vi_sub(Y[2], Y[0]);
    *pos = prod_cmp(dx1, dy2, dy1, dx2, 1);
    *neg = prod_cmp(dx1, dy2, dy1, dx2, 0);
}

/* prepare_cached_one: lanes (of valid) with zero area, removed by the cull
 * mode, and left (area sign pos / neg, exact). */
typedef struct front_class {
    unsigned degen, culled, live;
} front_class;

static inline front_class front_classify(rast_cull cull, unsigned valid, unsigned pos,
                                         unsigned neg)
{
    const unsigned cullm = cull == RAST_CULL_BACK ? pos : cull == RAST_CULL_FRONT ? neg : 0u;
    front_class c;
    c.degen = valid & ~(pos | neg);
    c.culled = valid & cullm & (pos | neg);
    c.live = valid & (pos | neg) & ~cullm;
    return c;
}

/* setup_box_edges: the pixel box before (r*) and after (b*) clamping to
 * the target; off: the clamped box is empty; small, usmall: the clamped,
 * the unclamped box is at most 2x2 pixels. */
typedef struct front_box {
    vint rx0, rx1, ry0, ry1, bx0, by0, bx1, by1;
    unsigned off, small, usmall;
} front_box;

static inline front_box front_box_of(const vint X[3], const vint Y[3], int width, int height)
{
    const vint c127 = vi_set1(RAST__FIX_ONE - 1 - RAST__FIX_HALF);
    const vint c128 = vi_set1(RAST__FIX_HALF);
    const vint xmin = vi_min(X[0], vi_min(X[1], X[2]));
    const vint xmax = vi_max(X[0], vi_max(X[1], X[2]));
    const vint ymin = vi_min(Y[0], vi_min(Y[1], Y[2]));
    const vint ymax = vi_max(Y[0], vi_max(Y[1], Y[2]));
    front_box b;
    b.rx0 = vi_srai(vi_add(xmin, c127), RAST_SUBPIXEL_BITS);
    b.rx1 = vi_srai(vi_sub(xmax, c128), RAST_SUBPIXEL_BITS);
    b.ry0 = vi_srai(vi_add(ymin, c127), RAST_SUBPIXEL_BITS);
    b.ry1 = vi_srai(vi_sub(ymax, c128), RAST_SUBPIXEL_BITS);
    b.bx0 = vi_max(b.rx0, vi_zero());
    b.by0 = vi_max(b.ry0, vi_zero());
    b.bx1 = vi_min(b.rx1, vi_set1(width - 1));
    b.by1 = vi_min(b.ry1, vi_set1(height - 1));
    b.off = vm_bits(vm_or(vi_gt(b.bx0, b.bx1), vi_gt(b.by0, b.by1)));
    /* at most 2 pixels a side: x1 < x0 + 2 */
    const vint two = vi_set1(2);
    b.small = vm_bits(vm_and(vi_gt(vi_add(b.bx0, two), b.bx1), vi_gt(vi_add(b.by0, two), b.by1))) &
              ~b.off;
    b.usmall = vm_bits(vm_and(vi_gt(vi_add(b.rx0, two), b.rx1), vi_gt(vi_add(b.ry0, two), b.ry1))) &
               ~b.off;
    return b;
}

/* Boxes of at most 2x2 pixels, before clamping too: lanes where no pixel
 * centre of the clamped box bx0..bx1 x by0..by1 lies inside the triangle
 * (X0, Y0), (x1, y1), (x2, y2), winding normalised (area > 0): the
 * biased edge test of the scan at each centre. int32 is exact here: with
 * an unclamped box of at most 2 pixels a side, every vertex coordinate
 * difference is below 768 (1/256 px) and every centre lies within 768 of
 * every vertex, so the products stay below 2^20 and the steps below
 * 2^18. */
static inline unsigned front_empty_small(vint X0, vint Y0, vint x1, vint y1, vint x2, vint y2,
                                         vint bx0, vint by0, vint bx1, vint by1)
{
    const vint c128 = vi_set1(RAST__FIX_HALF);
    const vint cx = vi_add(vi_slli(bx0, RAST_SUBPIXEL_BITS), c128);
    const vint cy = vi_add(vi_slli(by0, RAST_SUBPIXEL_BITS), c128);
    const vint e0 = front_edge32(x1, y1, x2, y2, cx, cy);
    const vint e1 = front_edge32(x2, y2, X0, Y0, cx, cy);
    const vint e2 = front_edge32(X0, Y0, x1, y1, cx, cy);
    /* one pixel right: E - dy*256; one pixel down: E + dx*256 */
    const vint r0 = vi_slli(vi_sub(y2, y1), RAST_SUBPIXEL_BITS);
    const vint r1 = vi_slli(vi_sub(Y0, y2), RAST_SUBPIXEL_BITS);
    const vint r2 = vi_slli(vi_sub(y1, Y0), RAST_SUBPIXEL_BITS);
    const vint d0 = vi_slli(vi_sub(x2, x1), RAST_SUBPIXEL_BITS);
    const vint d1 = vi_slli(vi_sub(X0, x2), RAST_SUBPIXEL_BITS);
    const vint d2 = vi_slli(vi_sub(x1, X0), RAST_SUBPIXEL_BITS);
    const vint e0d = vi_add(e0, d0), e1d = vi_add(e1, d1), e2d = vi_add(e2, d2);
    const unsigned wide = vm_bits(vi_gt(bx1, bx0)), tall = vm_bits(vi_gt(by1, by0));
    const unsigned c00 = ~vi_sign_bits(vi_or(vi_or(e0, e1), e2));
    const unsigned c10 = ~vi_sign_bits(vi_or(vi_or(vi_sub(e0, r0), vi_sub(e1, r1)),
                                            vi_sub(e2, r2))) & wide;
    const unsigned c01 = ~vi_sign_bits(vi_or(vi_or(e0d, e1d), e2d)) & tall;
    const unsigned c11 = ~vi_sign_bits(vi_or(vi_or(vi_sub(e0d, r0), vi_sub(e1d, r1)),
                                            vi_sub(e2d, r2))) & wide & tall;
    return ~(c00 | c10 | c01 | c11);
}

/* The statistics of one group. */
static inline void front_count(rast_stats *st, unsigned degen, unsigned culled, unsigned off,
                               unsigned drawn)
{
    st->tris_degenerate += __builtin_popcount(degen);
    st->tris_culled += __builtin_popcount(culled);
    st->tris_clipped_away += __builtin_popcount(off);
    st->tris_drawn += __builtin_popcount(drawn);
}

/* ---- survivor queue and set-up ------------------------------------------ */

/* The fields of a survivor waiting for its set-up (one int32 vector per
 * field in the front ends' queues): oriented (area > 0) snapped positions
 * and vertex indices, the clamped pixel box and the record's index in
 * out. */
enum { Q_X0, Q_X1, Q_X2, Q_Y0, Q_Y1, Q_Y2, Q_V0, Q_V1, Q_V2, Q_BX0, Q_BY0, Q_BX1, Q_BY1,
       Q_SLOT, Q_FIELDS };

/* Record slots in submission order for the lanes of special | surv of the
 * group at ti: special triangles through the scalar path at their place
 * (records out[n ..]), survivors' slots to sl[lane]. Returns the new n. */
static inline int front_slots(const rast__view *v, const rast_mesh_desc *m, int ti,
                              unsigned special, unsigned surv, rast__tri *out, int n,
                              rast_stats *st, int32_t *sl)
{
    for (unsigned bits = special | surv; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        if ((special >> l) & 1u)
            n += rast__prepare(v, m, ti + l, out + n, st);
        else
            sl[l] = n++;
    }
    return n;
}
