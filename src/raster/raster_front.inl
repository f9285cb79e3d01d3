/* raster_front.inl - the steps of the vector front end that are the same at
 * every lane width, shared by raster_front_avx2.c (8 lanes) and, through
 * raster_front_avx512.inl, by raster_front_avx512.c and the 16-triangle
 * rejection of raster_avx512.c. Every step runs, per lane, the operations
 * of the scalar path (raster_setup.c) in its order, so the bytes do not
 * depend on the lane width (docs/raster.md section 11).
 *
 * Lane macros, defined by the includer (bits = unsigned, bit l for lane l):
 *   FRONT_V                lanes (8 or 16)
 *   fvi                    the int32 vector type
 *   FI_ZERO() FI_SET1(x)
 *   FI_ADD FI_SUB FI_OR FI_MIN FI_MAX   one int32 operation per lane
 *   FI_SRAI(v, n) FI_SLLI(v, n)         shifts by a constant
 *   fvm                    a lane mask (vector or mask register)
 *   FI_GT(a, b), FI_EQ(a, b)  the lanes with a > b, a == b as fvm
 *   FM_OR(a, b), FM_AND(a, b), FM_BITS(m)  on fvm; FM_BITS: as bits
 *   FI_NEG_BITS(v)         lanes whose sign bit is set
 * and, before the include, two static inline functions:
 *   unsigned prod_cmp(fvi a, fvi b, fvi c, fvi d, int gt)   lanes with
 *                          a*b > c*d (gt) or a*b < c*d (!gt), exact
 *   fvi front_edge32(fvi xa, fvi ya, fvi xb, fvi yb, fvi cx, fvi cy)
 *                          the int32 edge value from a to b at (cx, cy),
 *                          minus one where the edge is not top-left. */

/* ---- rejection ---------------------------------------------------------- */

/* Lanes with area > 0 (pos) and area < 0 (neg) of the triangles X, Y
 * (the sign of dx1*dy2 - dy1*dx2, exact in double). */
static inline void front_area_signs(const fvi X[3], const fvi Y[3], unsigned *pos,
                                    unsigned *neg)
{
    const fvi dx1 = FI_SUB(X[1], X[0]), dy1 = FI_SUB(Y[1], Y[0]);
    const fvi dx2 = FI_SUB(X[2], X[0]), dy2 = FI_SUB(Y[2], Y[0]);
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
    fvi rx0, rx1, ry0, ry1, bx0, by0, bx1, by1;
    unsigned off, small, usmall;
} front_box;

static inline front_box front_box_of(const fvi X[3], const fvi Y[3], int width, int height)
{
    const fvi c127 = FI_SET1(RAST__FIX_ONE - 1 - RAST__FIX_HALF);
    const fvi c128 = FI_SET1(RAST__FIX_HALF);
    const fvi xmin = FI_MIN(X[0], FI_MIN(X[1], X[2]));
    const fvi xmax = FI_MAX(X[0], FI_MAX(X[1], X[2]));
    const fvi ymin = FI_MIN(Y[0], FI_MIN(Y[1], Y[2]));
    const fvi ymax = FI_MAX(Y[0], FI_MAX(Y[1], Y[2]));
    front_box b;
    b.rx0 = FI_SRAI(FI_ADD(xmin, c127), RAST_SUBPIXEL_BITS);
    b.rx1 = FI_SRAI(FI_SUB(xmax, c128), RAST_SUBPIXEL_BITS);
    b.ry0 = FI_SRAI(FI_ADD(ymin, c127), RAST_SUBPIXEL_BITS);
    b.ry1 = FI_SRAI(FI_SUB(ymax, c128), RAST_SUBPIXEL_BITS);
    b.bx0 = FI_MAX(b.rx0, FI_ZERO());
    b.by0 = FI_MAX(b.ry0, FI_ZERO());
    b.bx1 = FI_MIN(b.rx1, FI_SET1(width - 1));
    b.by1 = FI_MIN(b.ry1, FI_SET1(height - 1));
    b.off = FM_BITS(FM_OR(FI_GT(b.bx0, b.bx1), FI_GT(b.by0, b.by1)));
    /* at most 2 pixels a side: x1 < x0 + 2 */
    const fvi two = FI_SET1(2);
    b.small = FM_BITS(FM_AND(FI_GT(FI_ADD(b.bx0, two), b.bx1), FI_GT(FI_ADD(b.by0, two), b.by1))) &
              ~b.off;
    b.usmall = FM_BITS(FM_AND(FI_GT(FI_ADD(b.rx0, two), b.rx1), FI_GT(FI_ADD(b.ry0, two), b.ry1))) &
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
static inline unsigned front_empty_small(fvi X0, fvi Y0, fvi x1, fvi y1, fvi x2, fvi y2,
                                         fvi bx0, fvi by0, fvi bx1, fvi by1)
{
    const fvi c128 = FI_SET1(RAST__FIX_HALF);
    const fvi cx = FI_ADD(FI_SLLI(bx0, RAST_SUBPIXEL_BITS), c128);
    const fvi cy = FI_ADD(FI_SLLI(by0, RAST_SUBPIXEL_BITS), c128);
    const fvi e0 = front_edge32(x1, y1, x2, y2, cx, cy);
    const fvi e1 = front_edge32(x2, y2, X0, Y0, cx, cy);
    const fvi e2 = front_edge32(X0, Y0, x1, y1, cx, cy);
    /* one pixel right: E - dy*256; one pixel down: E + dx*256 */
    const fvi r0 = FI_SLLI(FI_SUB(y2, y1), RAST_SUBPIXEL_BITS);
    const fvi r1 = FI_SLLI(FI_SUB(Y0, y2), RAST_SUBPIXEL_BITS);
    const fvi r2 = FI_SLLI(FI_SUB(y1, Y0), RAST_SUBPIXEL_BITS);
    const fvi d0 = FI_SLLI(FI_SUB(x2, x1), RAST_SUBPIXEL_BITS);
    const fvi d1 = FI_SLLI(FI_SUB(X0, x2), RAST_SUBPIXEL_BITS);
    const fvi d2 = FI_SLLI(FI_SUB(x1, X0), RAST_SUBPIXEL_BITS);
    const fvi e0d = FI_ADD(e0, d0), e1d = FI_ADD(e1, d1), e2d = FI_ADD(e2, d2);
    const unsigned wide = FM_BITS(FI_GT(bx1, bx0)), tall = FM_BITS(FI_GT(by1, by0));
    const unsigned c00 = ~FI_NEG_BITS(FI_OR(FI_OR(e0, e1), e2));
    const unsigned c10 = ~FI_NEG_BITS(FI_OR(FI_OR(FI_SUB(e0, r0), FI_SUB(e1, r1)),
                                            FI_SUB(e2, r2))) & wide;
    const unsigned c01 = ~FI_NEG_BITS(FI_OR(FI_OR(e0d, e1d), e2d)) & tall;
    const unsigned c11 = ~FI_NEG_BITS(FI_OR(FI_OR(FI_SUB(e0d, r0), FI_SUB(e1d, r1)),
                                            FI_SUB(e2d, r2))) & wide & tall;
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
