/* raster_frontq.inl - the vector front end's group loop, survivor queue and
 * survivor set-up, written once on the vector layer (src/cpu/simd.h, with
 * its x86 "RASTER EDGE OPS": int64 lanes, vi_compress_lanes) and compiled
 * per ISA by raster_front_avx2.c (8 lanes) and raster_front_avx512.c (16
 * lanes) (issue 19 item 4; docs/raster.md sections 1 and 11):
 *
 *   SIMD_FN(rast__frontv)  the front end (rast__frontv_fn): groups of SIMD_W
 *                          submitted triangles through the rejection
 *                          (raster_front.inl), survivors compressed into a
 *                          queue kept in vectors (one permutation and one
 *                          select per field), set up SIMD_W at a time;
 *   fq_flush               setup_edges (int64 edges, VD_W lanes per half),
 *                          planes_one (fv_planes_z, _qb), micro records, hidden
 *                          records, and the records by 16-byte copies
 *                          (raster_front_rec.inl);
 *   fq_micro_lanes         the micro records' coverage and values.
 *
 * Every lane runs the scalar path's operations in its order, so the bytes
 * equal rast__prepare_range with the scalar set-up at every lane width.
 *
 * Included after one layer implementation, raster_front.inl,
 * raster_frontv.inl and the includer's three further helpers (what the
 * ISAs do their own way):
 *   void fv_load_group(const uint32_t *ix, const long long *xyb, int cnt,
 *                      vint iv[3], vint X[3], vint Y[3])
 *        the vertex indices of cnt (1..SIMD_W) triangles at ix
 *        de-interleaved (iv[k] lane l = ix[3l + k]) and their snapped
 *        (X, Y) pairs xyb[iv[k]]; lanes past cnt vertex 0; no index past
 *        the group is read;
 *   void fv_record_attrs(rast__tri *t, const float *attr, int ac,
 *                        int32_t v0, int32_t v1, int32_t v2)
 *        setup_attrs for one record: a0 = attribute of v0, d1 = a1 - a0,
 *        d2 = a2 - a0 (ac = 1..RAST_MAX_ATTRS floats each); no byte past
 *        a vertex's ac floats is read, none past t->a0[ac - 1],
 *        t->d1[ac - 1], t->d2[ac - 1] written;
 *   vint fv_compress_lanes(unsigned bits)
 *        vi_compress_lanes: the lane numbers of the set bits of bits in
 *        order, then 0. */

#ifndef SIMD_HAS_VL
#error "raster_frontq.inl: the vector layer has no RASTER EDGE OPS (x86 AVX2 / AVX-512 only)"
#endif

#include "raster_front_rec.inl"

/* The micro lanes (of L): clamped box at most 2x2 pixels. */
SIMD_INL unsigned fq_micro_box(const vint *qf, unsigned L)
{
    const vint two = vi_set1(2);
    const vint w1 = vi_sub(qf[Q_BX1], qf[Q_BX0]);
    const vint h1 = vi_sub(qf[Q_BY1], qf[Q_BY0]);
    return L & vm_bits(vm_and(vi_gt(two, w1), vi_gt(two, h1)));
}

/* The micro lanes mic (fq_micro_box, not 0): the covered pixels and, for
 * each of the box's four pixels (i, j), the scan's values (the clamped
 * depth z and the barycentrics b1, b2, fv_micro_values). cov[l]: bit
 * i + 2j for a covered pixel (the int64 edge test of the scan at that
 * pixel, E as in fq_flush); the values of lane l as quads (mz, mb1, mb2 of
 * its record) at mq + QUAD_AT(l), mq + 4 SIMD_W + QUAD_AT(l),
 * mq + 8 SIMD_W + QUAD_AT(l). */
SIMD_INL void fq_micro_lanes(const vint *qf, unsigned mic, const vlong (*E)[2], const vfloat *P,
                             int32_t *cov, float *mq)
{
    const vint one = vi_set1(1);
    const vint w1 = vi_sub(qf[Q_BX1], qf[Q_BX0]);
    const vint h1 = vi_sub(qf[Q_BY1], qf[Q_BY0]);
    const unsigned wide = vm_bits(vi_eq(w1, one));   /* 2 columns */
    const unsigned tall = vm_bits(vi_eq(h1, one));   /* 2 rows */
    /* Coverage: E = e_c + i*e_dx + j*e_dy, int64, at the four pixels. */
    unsigned cv[4] = { 0, 0, 0, 0 };
#pragma GCC unroll 2
    for (int h = 0; h < 2; h++) {
        vlong o[4] = { vl_zero(), vl_zero(), vl_zero(), vl_zero() };
#pragma GCC unroll 3
        for (int e = 0; e < 3; e++) {
            const vlong c = E[e][h], ex = E[3 + e][h], ey = E[6 + e][h];
            const vlong c01 = vl_add(c, ey);
            o[0] = vl_or(o[0], c);
            o[1] = vl_or(o[1], vl_add(c, ex));
            o[2] = vl_or(o[2], c01);
            o[3] = vl_or(o[3], vl_add(c01, ex));
        }
#pragma GCC unroll 4
        for (int p = 0; p < 4; p++)
            cv[p] |= (~vl_sign_bits(o[p]) & ((1u << VD_W) - 1u)) << (VD_W * h);
    }
    cv[0] &= mic;
    cv[1] &= mic & wide;
    cv[2] &= mic & tall;
    cv[3] &= mic & wide & tall;
    if (!(cv[0] | cv[1] | cv[2] | cv[3]))
        return;
    vint cb = vi_zero();
#pragma GCC unroll 4
    for (int p = 0; p < 4; p++)
        cb = vi_sel(vm_from_bits(cv[p]), vi_or(cb, vi_set1(1 << p)), cb);
    vi_store(cov, cb);
    /* The values (the scan's expressions; unused lanes compute garbage). */
    vfloat Z[4], B1[4], B2[4];
    fv_micro_values(P, Z, B1, B2);
    quads(Z[0], Z[1], Z[2], Z[3], mq);
    quads(B1[0], B1[1], B1[2], B1[3], mq + 4 * SIMD_W);
    quads(B2[0], B2[1], B2[2], B2[3], mq + 8 * SIMD_W);
}

/* Sets up queue lanes 0 .. k-1 (k = 1..SIMD_W; qf[field] as in the queue)
 * into their records (micro: the micro records of boxes of at most 2x2
 * pixels, and the hidden records). The edges, planes and micro values stay
 * in vectors; the records are written per lane from the stack layouts of
 * raster_front_rec.inl. */
static void fq_flush(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                     const vint *qf, int k, rast__tri *out, int micro)
{
    const vmask Lm = vi_gt(vi_set1(k), vi_lanes());
    vint X[3], Y[3], V[3];
#pragma GCC unroll 3
    for (int i = 0; i < 3; i++) {
        X[i] = qf[Q_X0 + i];
        Y[i] = qf[Q_Y0 + i];
        V[i] = vi_sel(Lm, qf[Q_V0 + i], vi_zero());   /* unused lanes: vertex 0 */
    }
    const vint bx0 = qf[Q_BX0], by0 = qf[Q_BY0];
    /* the per-lane fields the record loop reads */
    _Alignas(SIMD_ALIGN) int32_t qs[Q_FIELDS][SIMD_W];
#pragma GCC unroll 3
    for (int f = Q_V0; f <= Q_V2; f++)
        vi_store(qs[f], qf[f]);
    vi_store(qs[Q_SLOT], qf[Q_SLOT]);
    const vint c128 = vi_set1(RAST__FIX_HALF);
    const vint cx = vi_add(vi_slli(bx0, RAST_SUBPIXEL_BITS), c128);
    const vint cy = vi_add(vi_slli(by0, RAST_SUBPIXEL_BITS), c128);
    const unsigned Lb = k >= SIMD_W ? SIMD_FULL : (1u << k) - 1u;

    /* The z plane first: when every lane's record is hidden (no micro
     * lane; about half of the flushes with the sample model) the rest,
     * edges, the other planes and micro values, is not needed. */
    fv_geom g[2];
    vfloat P[12];
    fv_planes_z(X, Y, V, bx0, by0, k, vb, g, P);
    const unsigned mic = micro ? fq_micro_box(qf, Lb) : 0u;
    const unsigned hid =
        fv_hidden(micro ? v->hz : NULL, P, bx0, by0, qf[Q_BX1], qf[Q_BY1], Lb & ~mic);
    _Alignas(SIMD_ALIGN) int32_t bq[4 * SIMD_W];
    quads(vi_as_vf(bx0), vi_as_vf(by0), vi_as_vf(qf[Q_BX1]), vi_as_vf(qf[Q_BY1]),
          (float *)(void *)bq);
    if (hid == Lb) {
        for (int l = 0; l < k; l++)
            front_hidden_record(out + qs[Q_SLOT][l], l, bq);
        return;
    }

    /* setup_edges: edge e from vertex ea[e] to eb[e]; E[f][h] the int64
     * lanes of half h of e_c[e] (f = e), e_dx[e] (3 + e), e_dy[e] (6 + e),
     * the order of the record. */
    vlong E[9][2];
    static const int ea[3] = { 1, 2, 0 }, eb[3] = { 2, 0, 1 };
#pragma GCC unroll 3
    for (int e = 0; e < 3; e++) {
        const int a = ea[e], b = eb[e];
        const vint dx = vi_sub(X[b], X[a]), dy = vi_sub(Y[b], Y[a]);
        const vmask tl = top_left(dx, dy);
        const vint oy = vi_sub(cy, Y[a]), ox = vi_sub(cx, X[a]);
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
            const vlong dx64 = vl_from_vi(dx, h), dy64 = vl_from_vi(dy, h);
            const vlong p1 = vl_mul32(dx64, vl_from_vi(oy, h));
            const vlong p2 = vl_mul32(dy64, vl_from_vi(ox, h));
            E[e][h] = vl_dec_unless(vl_sub(p1, p2), tl, h);
            E[3 + e][h] = vl_sub(vl_zero(), vl_slli(dy64, RAST_SUBPIXEL_BITS));
            E[6 + e][h] = vl_slli(dx64, RAST_SUBPIXEL_BITS);
        }
    }

    /* the planes q, b1, b2 */
    fv_planes_qb(V, k, vb, g, P);

    /* The records: lane l -> out[slot l]. */
    _Alignas(SIMD_ALIGN) int32_t cov[SIMD_W] = { 0 };
    _Alignas(SIMD_ALIGN) float mq[3 * 4 * SIMD_W];
    if (mic)
        fq_micro_lanes(qf, mic, (const vlong (*)[2])E, P, cov, mq);
    /* the planes z.c .. q.c, q.dx .. b1.dx, b1.dy .. b2.dy */
    _Alignas(SIMD_ALIGN) float pq[3 * 4 * SIMD_W];
    /* the edge pairs (e_c[0], e_c[1]) .. (e_dy[0], e_dy[1]) and e_dy[2] */
    _Alignas(SIMD_ALIGN) int64_t eq[4][2 * SIMD_W], e8[SIMD_W];
    if ((mic | hid) != Lb) {
#pragma GCC unroll 3
        for (int i = 0; i < 3; i++)
            quads(P[4 * i], P[4 * i + 1], P[4 * i + 2], P[4 * i + 3], pq + 4 * SIMD_W * i);
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
#pragma GCC unroll 4
            for (int i = 0; i < 4; i++)
                pairs(E[2 * i][h], E[2 * i + 1][h], eq[i] + 2 * VD_W * h);
            vl_store(e8 + VD_W * h, E[8][h]);
        }
    }
    const int ac = v->attr_count;
    for (int l = 0; l < k; l++) {
        rast__tri *t = out + qs[Q_SLOT][l];
        if ((hid >> l) & 1u) {
            front_hidden_record(t, l, bq);
            continue;
        }
        if (!front_write_record(t, l, (int)((mic >> l) & 1u), (unsigned)cov[l], ac, bq, mq, pq,
                                (const int64_t (*)[2 * FRONT_V])eq, e8))
            continue;
        if (ac > 0)
            fv_record_attrs(t, m->attr, ac, qs[Q_V0][l], qs[Q_V1][l], qs[Q_V2][l]);
    }
}

_Static_assert(RAST_MAX_ATTRS <= 8, "attributes of a record by one 8-lane masked load");

int SIMD_FN(rast__frontv)(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                          int ti0, int ti1, rast__tri *out, rast_stats *st, int micro)
{
    rast_stats ls = *st;
    /* The survivor queue in vectors: qf[field] lanes 0 .. qn-1. */
    vint qf[Q_FIELDS];
#pragma GCC unroll 14
    for (int f = 0; f < Q_FIELDS; f++)
        qf[f] = vi_zero();
    int qn = 0;
    int n = 0;
    const long long *xyb = (const long long *)(const void *)vb->xy;
    const vint iota = vi_lanes();
    const int vw = v->width, vh = v->height;   /* kept in registers */
    for (int ti = ti0; ti < ti1; ti += SIMD_W) {
        const int cnt = ti1 - ti < SIMD_W ? ti1 - ti : SIMD_W;
        const unsigned L = cnt == SIMD_W ? SIMD_FULL : (1u << cnt) - 1u;
        /* Indices, de-interleaved, and positions (lanes past cnt: vertex 0). */
        vint iv[3], X[3], Y[3];
        fv_load_group(m->indices + 3 * (size_t)ti, xyb, cnt, iv, X, Y);
        /* lanes with a marked vertex; those needing the scalar path */
        unsigned marked;
        const unsigned special0 = fv_marked(X, Y, L, &ls, &marked);
        /* prepare_cached_one: area sign, degenerate, culling. */
        unsigned pos, neg;
        front_area_signs(X, Y, &pos, &neg);
        const front_class c = front_classify(m->cull, L & ~marked, pos, neg);
        /* setup_box_edges: the clamped pixel box, off screen, empty. */
        const front_box b = front_box_of(X, Y, vw, vh);
        /* A box of at most 2x2 pixels after clamping but not before (a
         * triangle across the border): the empty test needs int64 edges
         * there, so the (rare) lane takes the scalar path, which counts
         * it. */
        const unsigned csmall = c.live & ~b.off & b.small;
        const unsigned odd = csmall & ~b.usmall;
        const unsigned special = special0 | odd;
        const unsigned live2 = c.live & ~b.off & ~odd;
        /* Winding normalised (vertices 1 and 2 swapped where area < 0). */
        const vmask sw = vm_from_bits(neg);
        const vint x1 = vi_sel(sw, X[2], X[1]), x2 = vi_sel(sw, X[1], X[2]);
        const vint y1 = vi_sel(sw, Y[2], Y[1]), y2 = vi_sel(sw, Y[1], Y[2]);
        /* at most 2x2 before clamping: differences below 768, int32 edges */
        const unsigned small = csmall & b.usmall;
        unsigned empty = 0;
        if (small)
            empty = small & front_empty_small(X[0], Y[0], x1, y1, x2, y2, b.bx0, b.by0,
                                              b.bx1, b.by1);
        const unsigned surv = live2 & ~empty;
        /* drawn: survivors and empty ones */
        front_count(&ls, c.degen, c.culled, c.live & b.off, live2);
        if (!surv && !special)
            continue;
        /* Append the survivors to the queue vectors: queue lane j >= qn
         * takes survivor j - qn, i.e. group lane pr[j] (the compressed
         * lane numbers rotated by qn: vi_permute reads an index modulo
         * SIMD_W); lanes j < qn of the same permutation hold the survivors
         * past the last lane (survivor j - qn + SIMD_W), the next queue. */
        const vint rot = vi_sub(iota, vi_set1(qn));
        const vint pr = vi_permute(fv_compress_lanes(surv), rot);
        /* Record slots in submission order; special triangles through the
         * scalar path at their place. */
        vint slot;
        if (special) {
            _Alignas(SIMD_ALIGN) int32_t sl[SIMD_W] = { 0 };
            n = front_slots(v, m, ti, special, surv, out, n, &ls, sl);
            slot = vi_permute(vi_load(sl), pr);
        } else {
            slot = vi_permute(vi_add(vi_set1(n), iota), rot);
            n += __builtin_popcount(surv);
        }
        if (!surv)
            continue;
        const vint vi1 = vi_sel(sw, iv[2], iv[1]), vi2 = vi_sel(sw, iv[1], iv[2]);
        const vint fld[Q_SLOT] = { X[0], x1, x2, Y[0], y1, y2, iv[0], vi1, vi2,
                                   b.bx0, b.by0, b.bx1, b.by1 };
        const vmask up = vi_gt(iota, vi_set1(qn - 1));
#pragma GCC unroll 13
        for (int f = 0; f < Q_SLOT; f++)
            qf[f] = vi_sel(up, vi_permute(fld[f], pr), qf[f]);
        qf[Q_SLOT] = vi_sel(up, slot, qf[Q_SLOT]);
        qn += __builtin_popcount(surv);
        if (qn >= SIMD_W) {
            fq_flush(v, m, vb, qf, SIMD_W, out, micro);
            qn -= SIMD_W;
#pragma GCC unroll 13
            for (int f = 0; f < Q_SLOT; f++)
                qf[f] = vi_permute(fld[f], pr);
            qf[Q_SLOT] = slot;
        }
    }
    if (qn)
        fq_flush(v, m, vb, qf, qn, out, micro);
    *st = ls;
    return n;
}
