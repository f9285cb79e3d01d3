/* raster_frontv.inl - the vector front end's steps written once on the
 * vector layer (src/cpu/simd.h) and compiled per ISA by
 * raster_front_avx2.c (8 lanes) and raster_front_avx512.c (16 lanes)
 * (issue 19 item 4; docs/raster.md sections 1 and 11):
 *
 *   SIMD_FN(rast__vpass)   the vertex pass (rast__vpass_fn): vc_fill_one per
 *                          lane (finiteness, outcode, w > 0, snap, zw, iw);
 *   fv_marked              the triangles with a marked vertex, and those of
 *                          three marked vertices dropped as non-finite or
 *                          clipped away (clip_snap's first steps);
 *   fv_planes_z, _qb       planes_one per lane (the double plane set-up of
 *                          section 6.1, one triangle per double lane): the
 *                          z plane, then q, b1, b2;
 *   fv_micro_values        the scan's per-pixel values of the micro records
 *                          (boxes of at most 2x2 pixels).
 *
 * Every lane runs the scalar path's operations in its order (no
 * contraction: -ffp-contract=off), so the bytes equal rast__prepare_range
 * with the scalar set-up at every lane width. The group loop, the survivor
 * queue, the int64 edges and the records are written once too
 * (raster_frontq.inl, on the layer's x86 RASTER EDGE OPS); what stays in
 * the ISA files is the de-interleaving loads of vertices, indices and
 * (X, Y) pairs, the double gathers and the attribute copies.
 *
 * Included after one layer implementation, raster_front.inl and the
 * includer's two helpers:
 *   void fv_load_xyzw(const float *c, int cnt, vfloat *x, *y, *z, *w)
 *        cnt (1..SIMD_W) vertices xyzw at c de-interleaved, lanes past cnt
 *        0, no float past the last vertex read;
 *   vdouble fv_gather_d(const double *p, vint V, int h)
 *        p[V[l]] for the lanes l of half h (every lane of V indexes a
 *        readable double). */

/* ---- vertex pass -------------------------------------------------------- */

void SIMD_FN(rast__vpass)(const rast__view *v, const float *clip, int count, rast__vbuf *vb)
{
    const vfloat zero = vf_zero(), half = vf_set1(0.5f);
    const vfloat fix = vf_set1((float)RAST__FIX_ONE);
    const vfloat big = vf_set1(FLT_MAX), nbig = vf_set1(-FLT_MAX);
    const vfloat gx = vf_set1(v->gx), gy = vf_set1(v->gy);
    const vfloat fw = vf_set1((float)v->width), fh = vf_set1((float)v->height);
    const vfloat lox = vf_set1((float)v->min_x), hix = vf_set1((float)v->max_x);
    const vfloat loy = vf_set1((float)v->min_y), hiy = vf_set1((float)v->max_y);
    const vint mark = vi_set1(RAST__VX_SPECIAL);
    const vdouble dhalf = vd_set1(0.5), done = vd_set1(1.0);
    for (int base = 0; base < count; base += SIMD_W) {
        const int cnt = count - base < SIMD_W ? count - base : SIMD_W;
        vfloat x, y, z, w;
        fv_load_xyzw(clip + 4 * (size_t)base, cnt, &x, &y, &z, &w);
        /* vc_fill_one: finite (|c| <= FLT_MAX), outcode 0, w > 0. */
        const vmask fin = vm_and(vm_and(vm_and(vf_le(x, big), vf_le(nbig, x)),
                                        vm_and(vf_le(y, big), vf_le(nbig, y))),
                                 vm_and(vm_and(vf_le(z, big), vf_le(nbig, z)),
                                        vm_and(vf_le(w, big), vf_le(nbig, w))));
        const vfloat gxw = vf_mul(gx, w), gyw = vf_mul(gy, w);
        /* outcode_inl, plane by plane (the same float expressions) */
        const vmask ob[6] = { vf_lt(vf_add(z, w), zero),   vf_lt(vf_sub(w, z), zero),
                              vf_lt(vf_add(gxw, x), zero), vf_lt(vf_sub(gxw, x), zero),
                              vf_lt(vf_add(gyw, y), zero), vf_lt(vf_sub(gyw, y), zero) };
        const vmask out =
            vm_or(vm_or(vm_or(ob[0], ob[1]), vm_or(ob[2], ob[3])), vm_or(ob[4], ob[5]));
        /* Y of a marked vertex: its outcode | RAST__VX_NONFINITE */
        vint oc = vf_as_vi(vf_selz(vm_not(fin), vi_as_vf(vi_set1(RAST__VX_NONFINITE))));
#pragma GCC unroll 6
        for (int b = 0; b < 6; b++)
            oc = vi_or(oc, vf_as_vi(vf_selz(ob[b], vi_as_vf(vi_set1(1 << b)))));
        /* special = !fin | out | !(w > 0) */
        const vmask ok = vm_andnot(out, vm_and(fin, vf_gt(w, zero)));
        /* snap_inl */
        const vfloat nx = vf_div(x, w), ny = vf_div(y, w);
        const vfloat sx = vf_mul(vf_add(vf_mul(nx, half), half), fw);
        const vfloat sy = vf_mul(vf_sub(half, vf_mul(ny, half)), fh);
        vint X = vi_from_vf_round(vf_min(vf_max(vf_mul(sx, fix), lox), hix));
        vint Y = vi_from_vf_round(vf_min(vf_max(vf_mul(sy, fix), loy), hiy));
        X = vi_sel(ok, X, mark);
        Y = vi_sel(ok, Y, oc);
        vi_store2(vb->xy + 2 * (size_t)base, X, Y);
        /* vert_zw, vert_iw in double */
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
            const vdouble dz = vd_from_vf(z, h), dw = vd_from_vf(w, h);
            vd_storeu(vb->zw + base + VD_W * h,
                      vd_add(vd_mul(vd_div(dz, dw), dhalf), dhalf));
            vd_storeu(vb->iw + base + VD_W * h, vd_div(done, dw));
        }
    }
}

/* ---- rejection ---------------------------------------------------------- */

/* The lanes (of L) with a marked vertex (X == RAST__VX_SPECIAL) to
 * *marked; returns those of them that need the scalar path: of the
 * triangles whose three vertices are marked (Y: outcode |
 * RAST__VX_NONFINITE), a non-finite vertex drops the triangle as
 * non-finite, else an outcode bit shared by the three as clipped away
 * (counted in st); the rest (to be clipped) take the scalar path. */
SIMD_INL unsigned fv_marked(const vint X[3], const vint Y[3], unsigned L, rast_stats *st,
                            unsigned *marked)
{
    const vint mark = vi_set1(RAST__VX_SPECIAL);
    const vmask m0 = vi_eq(X[0], mark), m1 = vi_eq(X[1], mark), m2 = vi_eq(X[2], mark);
    const unsigned mk = vm_bits(vm_or(vm_or(m0, m1), m2)) & L;
    *marked = mk;
    const unsigned all3 = mk & vm_bits(vm_and(vm_and(m0, m1), m2));
    if (!all3)
        return mk;
    const vint yo = vi_or(vi_or(Y[0], Y[1]), Y[2]);
    const vint ya = vi_and(vi_and(Y[0], Y[1]), Y[2]);
    const vint z = vi_zero();
    const unsigned nf =
        all3 & ~vm_bits(vi_eq(vi_and(yo, vi_set1(RAST__VX_NONFINITE)), z));
    const unsigned away =
        all3 & ~nf & ~vm_bits(vi_eq(vi_and(ya, vi_set1(RAST__VX_OUTCODE)), z));
    st->tris_nonfinite += __builtin_popcount(nf);
    st->tris_clipped_away += __builtin_popcount(away);
    return mk & ~(nf | away);
}

/* ---- survivor set-up ---------------------------------------------------- */

/* front_plane per double lane: c, dx, dy to r[0 .. 2]. */
SIMD_INL void fv_plane(vdouble f0, vdouble f1, vdouble f2, vdouble ex1, vdouble ey1,
                       vdouble ex2, vdouble ey2, vdouble ox, vdouble oy, vdouble area,
                       vdouble *r)
{
    const vdouble df1 = vd_sub(f1, f0), df2 = vd_sub(f2, f0);
    const vdouble gx = vd_div(vd_sub(vd_mul(df1, ey2), vd_mul(df2, ey1)), area);
    const vdouble gy = vd_div(vd_sub(vd_mul(df2, ex1), vd_mul(df1, ex2)), area);
    r[0] = vd_add(vd_add(f0, vd_mul(gx, ox)), vd_mul(gy, oy));
    r[1] = gx;
    r[2] = gy;
}

/* planes_one (raster_setup.c) per lane, in two steps so that a flush
 * whose lanes all turn out hidden (about half of them with the sample
 * model, where only the z plane is tested) skips the rest: fv_planes_z
 * the z plane, fv_planes_qb the planes q, b1, b2, as vectors
 * P[plane * 3 + {c, dx, dy}] (the same operations per lane; rounded to
 * float once, at the end, both halves joined in registers). Lanes past k
 * compute garbage (never stored); with k <= VD_W the upper half is not
 * computed (its lanes copy the lower's). */
typedef struct fv_geom {   /* what the four planes share, per half */
    vdouble ex1, ey1, ex2, ey2, area, ox, oy;
} fv_geom;

SIMD_INL void fv_planes_z(const vint X[3], const vint Y[3], const vint V[3], vint bx0, vint by0,
                          int k, const rast__vbuf *vb, fv_geom g[2], vfloat P[12])
{
    const vdouble inv256 = vd_set1(1.0 / RAST__FIX_ONE), dhalf = vd_set1(0.5);
    vdouble r[2][3];
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        if (h && k <= VD_W) {
#pragma GCC unroll 3
            for (int j = 0; j < 3; j++)
                r[1][j] = r[0][j];
            break;
        }
        vdouble Xd[3], Yd[3], zw[3];
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++)
            zw[i] = fv_gather_d(vb->zw, V[i], h);
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++) {
            /* (double)X / 256: exact, as a multiplication by 2^-8 */
            Xd[i] = vd_mul(vd_from_vi(X[i], h), inv256);
            Yd[i] = vd_mul(vd_from_vi(Y[i], h), inv256);
        }
        fv_geom *G = &g[h];
        G->ex1 = vd_sub(Xd[1], Xd[0]);
        G->ey1 = vd_sub(Yd[1], Yd[0]);
        G->ex2 = vd_sub(Xd[2], Xd[0]);
        G->ey2 = vd_sub(Yd[2], Yd[0]);
        /* |snapped area| / 65536, exact (raster_front.inl) */
        G->area = vd_sub(vd_mul(G->ex1, G->ey2), vd_mul(G->ey1, G->ex2));
        const vdouble ocx = vd_add(vd_from_vi(bx0, h), dhalf);
        const vdouble ocy = vd_add(vd_from_vi(by0, h), dhalf);
        G->ox = vd_sub(ocx, Xd[0]);
        G->oy = vd_sub(ocy, Yd[0]);
        fv_plane(zw[0], zw[1], zw[2], G->ex1, G->ey1, G->ex2, G->ey2, G->ox, G->oy, G->area,
                 r[h]);
    }
#pragma GCC unroll 3
    for (int j = 0; j < 3; j++)
        P[j] = vf_from_vd(r[0][j], r[1][j]);
}

SIMD_INL void fv_planes_qb(const vint V[3], int k, const rast__vbuf *vb, const fv_geom g[2],
                           vfloat P[12])
{
    const vdouble dzero = vd_set1(0.0);
    vdouble r[2][9];
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        if (h && k <= VD_W) {
#pragma GCC unroll 9
            for (int j = 0; j < 9; j++)
                r[1][j] = r[0][j];
            break;
        }
        vdouble iw[3];
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++)
            iw[i] = fv_gather_d(vb->iw, V[i], h);
        const fv_geom *G = &g[h];
        /* max(a, b) = a > b ? a : b, as the scalar loop */
        const vdouble qmax = vd_max(iw[2], vd_max(iw[1], vd_max(iw[0], dzero)));
        const vdouble q0 = vd_div(iw[0], qmax), q1 = vd_div(iw[1], qmax);
        const vdouble q2 = vd_div(iw[2], qmax);
        fv_plane(q0, q1, q2, G->ex1, G->ey1, G->ex2, G->ey2, G->ox, G->oy, G->area, r[h]);
        fv_plane(dzero, q1, dzero, G->ex1, G->ey1, G->ex2, G->ey2, G->ox, G->oy, G->area,
                 r[h] + 3);
        fv_plane(dzero, dzero, q2, G->ex1, G->ey1, G->ex2, G->ey2, G->ox, G->oy, G->area,
                 r[h] + 6);
    }
#pragma GCC unroll 9
    for (int j = 0; j < 9; j++)
        P[3 + j] = vf_from_vd(r[0][j], r[1][j]);
}

/* The scan's values at the four pixels (i, j) of a micro record's box,
 * p = i + 2j: the clamped depth Z[p] and the barycentrics B1[p], B2[p],
 * per lane with the float operations of rast__scan_rows_ref in its order
 * (fi, fj are 0.0f or 1.0f, multiplied as the scan multiplies them; P as
 * fv_planes_z and fv_planes_qb; lanes that are not micro compute garbage). */
SIMD_INL void fv_micro_values(const vfloat *P, vfloat Z[4], vfloat B1[4], vfloat B2[4])
{
    const vfloat zero = vf_zero(), fone = vf_set1(1.0f);
#pragma GCC unroll 2
    for (int j = 0; j < 2; j++) {
        const vfloat fj = j ? fone : zero;
        const vfloat zr = vf_add(P[0], vf_mul(P[2], fj));
        const vfloat qr = vf_add(P[3], vf_mul(P[5], fj));
        const vfloat b1r = vf_add(P[6], vf_mul(P[8], fj));
        const vfloat b2r = vf_add(P[9], vf_mul(P[11], fj));
#pragma GCC unroll 2
        for (int i = 0; i < 2; i++) {
            const int p = i + 2 * j;
            const vfloat fi = i ? fone : zero;
            vfloat z = vf_add(zr, vf_mul(P[1], fi));
            z = vf_max(zero, z);
            Z[p] = vf_min(fone, z);
            const vfloat r = vf_div(fone, vf_add(qr, vf_mul(P[4], fi)));
            B1[p] = vf_mul(vf_add(b1r, vf_mul(P[7], fi)), r);
            B2[p] = vf_mul(vf_add(b2r, vf_mul(P[10], fi)), r);
        }
    }
}

/* ---- hidden records ----------------------------------------------------- */

#include "raster_hidden.inl"

/* fv_hidden's lanes one at a time through the scan's whole test (a
 * depth plane too large for the gather's int32 offsets). */
static unsigned fv_hidden_lanes(const rast_target *t, const vfloat *P, vint bx0, vint by0,
                                vint bx1, vint by1, unsigned lanes)
{
    _Alignas(64) float zc[SIMD_W], zx[SIMD_W], zy[SIMD_W];
    _Alignas(64) int32_t b[4][SIMD_W];
    vf_store(zc, P[0]);
    vf_store(zx, P[1]);
    vf_store(zy, P[2]);
    vi_store(b[0], bx0);
    vi_store(b[1], by0);
    vi_store(b[2], bx1);
    vi_store(b[3], by1);
    unsigned hid = 0;
    for (unsigned bits = lanes; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        const int nx = b[2][l] - b[0][l] + 1;
        if (nx <= 4 * SIMD_W &&
            simd_zbox_hidden(t, zc[l], zx[l], zy[l], b[0][l], b[1][l], b[1][l], b[3][l], nx))
            hid |= 1u << l;
    }
    return hid;
}

/* The lanes (of lanes) whose record the scan would find hidden: the box
 * depth test of the scan (simd_zbox_hidden) on the lane's float z plane
 * (P[0 .. 2] as fv_planes_z: the record's z.c, z.dx, z.dy) and clamped box,
 * over all its rows, against t's depth plane as it is now (before the
 * scans of this chunk's earlier records: depth only decreases during a
 * draw, so an older state is conservative). Boxes wider than four vectors
 * are not tested (as in the scan). Only on the single-thread driver
 * (rast__draw_valid_vb: no other thread writes t). t NULL: none. */
SIMD_INL unsigned fv_hidden(const rast_target *t, const vfloat *P, vint bx0, vint by0, vint bx1,
                            vint by1, unsigned lanes)
{
    if (!t || !lanes)
        return 0;
    /* simd_zbox_hidden's first step for every lane at once: a depth above
     * z.c at the box's first pixel (most visible triangles) ends the
     * lane's test; one gather (unused lanes read pixel 0) instead of a
     * data-dependent branch per lane. Offsets in int32: the plane's
     * size checked; otherwise every lane takes simd_zbox_hidden whole. */
    if ((size_t)t->depth_stride * (size_t)t->height > (size_t)INT32_MAX)
        return fv_hidden_lanes(t, P, bx0, by0, bx1, by1, lanes);
    const vint at = vi_add(vi_mullo(by0, vi_set1(t->depth_stride)), bx0);
    const vfloat d0 = vf_gather(t->depth, vi_sel(vm_from_bits(lanes), at, vi_zero()));
    lanes &= ~vm_bits(vf_gt(d0, P[0]));
    if (!lanes)
        return 0;
    /* The bound zf of simd_zbox_hidden (rows y0 .. y1 of the box, so
     * ys - y0 = 0) for every lane at once, per lane its double
     * operations: min(a, b) = a < b ? a : b as -max(-a, -b) (negation
     * is exact) and |a| as max(a, -a), which differs from a < 0 ? -a : a
     * only in the sign of a zero or a NaN: that reaches zb only when S
     * is 0 or NaN, where zb is zmin (so the same) or NaN. The first-pixel
     * test above is simd_zbox_hidden's (its z.c + z.dy * 0 compares as
     * z.c for a finite z.dy; for another it is NaN and never ends the
     * test), so the lanes left go straight to the rows. */
    const vdouble zero = vd_set1(0.0), nzero = vd_set1(-0.0), neg1 = vd_set1(-1.0);
    const vdouble margin = vd_set1(0x1p-18), big = vd_set1(1e30);
    const vint w1 = vi_sub(bx1, bx0), h1 = vi_sub(by1, by0);
    vdouble zf[2];
    unsigned ok = 0;
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        const vdouble c = vd_from_vf(P[0], h), zdx = vd_from_vf(P[1], h);
        const vdouble zdy = vd_from_vf(P[2], h);
        const vdouble ay = vd_mul(zdy, zero), by = vd_mul(zdy, vd_from_vi(h1, h));
        const vdouble ax = vd_mul(zdx, vd_from_vi(w1, h));
        const vdouble nay = vd_mul(ay, neg1), nby = vd_mul(by, neg1), nax = vd_mul(ax, neg1);
        /* c + (ay < by ? ay : by) + (ax < 0 ? ax : 0) */
        const vdouble mn = vd_mul(vd_max(nay, nby), neg1);
        const vdouble zmin = vd_add(vd_add(c, mn), vd_mul(vd_max(nax, nzero), neg1));
        const vdouble aay = vd_max(ay, nay), aby = vd_max(by, nby);
        const vdouble sy = vd_max(aay, aby);
        const vdouble S = vd_add(vd_add(vd_max(c, vd_mul(c, neg1)), sy), vd_max(ax, nax));
        const vdouble zb = vd_sub(zmin, vd_mul(S, margin));
        ok |= (vd_gt_bits(zb, zero) & vd_gt_bits(big, zb)) << (VD_W * h);
        zf[h] = vd_mul(vd_max(vd_mul(zb, neg1), neg1), neg1);   /* zb < 1 ? zb : 1 */
    }
    lanes &= ok;
    if (!lanes)
        return 0;
    _Alignas(64) float zq[SIMD_W];
    _Alignas(64) int32_t b[4][SIMD_W];
    vf_store(zq, vf_from_vd(zf[0], zf[1]));
    vi_store(b[0], bx0);
    vi_store(b[1], by0);
    vi_store(b[2], bx1);
    vi_store(b[3], by1);
    unsigned hid = 0;
    for (unsigned bits = lanes; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        const int nx = b[2][l] - b[0][l] + 1;
        const float *d = t->depth + (size_t)b[1][l] * (size_t)t->depth_stride + b[0][l];
        if (nx <= 4 * SIMD_W &&
            simd_zbox_rows(t, d, vf_set1(zq[l]), b[0][l], b[1][l], b[3][l], nx, 1))
            hid |= 1u << l;
    }
    return hid;
}
