/* raster_hidden.inl - the box depth test of the hidden-triangle skip,
 * on the vector layer (src/cpu/simd.h), shared by the row scans
 * (raster_simd.inl: before a record's scan) and the vector front end
 * (raster_frontv.inl: before a record is written; docs/raster.md section
 * 14). Included once per ISA after the layer implementation. */
#ifndef RAST_HIDDEN_INL
#define RAST_HIDDEN_INL

/* BOX DEPTH TEST. 1 when no pixel of the box x0 .. x0+nx-1 (z plane zc,
 * zdx, zdy at the centre of pixel (x0, y0), as a record's) x ys .. ye can pass the depth test, read from the depth rows themselves
 * (no hierarchical buffer to keep: the box is the "tile"). Then the scan
 * writes nothing and is skipped (a triangle hidden behind drawn ones:
 * 55% of the sample model's scanned triangles write no pixel, docs/raster.md
 * section 14). Conservative: every scanned pixel's z (the reference's
 * z = (c + dy*fj) + dx*fi in float, then clamped to [0, 1]) is at least
 * zf below, and the box is hidden when every depth value d of it satisfies
 * d <= zf (ordered: a NaN d keeps the scan), so z < d fails for every
 * pixel. zf: the affine z's minimum over the box (at a corner; in double,
 * whose rounding is far below the margin) minus 2^-18 * S, S = |c| +
 * max |dy*fj| + |dx|*(nx-1) bounding every magnitude in the float
 * expression: its three roundings move z by at most about 2^-22 * S and
 * the conversion of the bound to float by 2^-24 * S. A bound not above 0
 * (or not finite) skips the test; above 1 it is 1 (the clamped z is 1 then).
 * The rows ys .. ye are the calling thread's (bands are rows), and the
 * SIMD_W values read from x0 lie in the row when x0 + SIMD_W <= width
 * (else a masked load of the box's lanes). */
static inline double simd_absd(double a)
{
    return a < 0.0 ? -a : a;
}

/* The rows of the box test: 1 when every depth value of the box x0 ..
 * x0+nx-1 (nx <= 4 * SIMD_W) x ys .. ye, row ys at d, is <= zv (ordered).
 * The result is the conjunction over the box. With pairs (a constant: the
 * vector front end, whose boxes are mostly hidden, so every row is read)
 * rows are tested two at a time and boxes of two vectors as one, one mask
 * extraction and one branch per pair of rows; without (the scan, whose
 * boxes mostly end at their first row or vector) one row and one vector
 * at a time. Inlined: called out of line, the calls cost more than the
 * rows of most boxes. */
static inline __attribute__((always_inline)) int simd_zbox_rows(const rast_target *t,
                                                                const float *d, vfloat zv,
                                                                int x0, int ys, int ye, int nx,
                                                                int pairs)
{
    const size_t s = (size_t)t->depth_stride;
    int y = ys;
    if (nx <= SIMD_W) {
        const unsigned valid = nx >= SIMD_W ? SIMD_FULL : (1u << nx) - 1u;
        if (x0 + SIMD_W <= t->width) {
            if (pairs) {
                for (; y < ye; y += 2, d += 2 * s)
                    if (~vm_bits(vm_and(vf_le(vf_loadu(d), zv), vf_le(vf_loadu(d + s), zv))) &
                        valid)
                        return 0;
                return !(y == ye && (~vm_bits(vf_le(vf_loadu(d), zv)) & valid));
            }
            for (; y <= ye; y++, d += s)
                if (~vm_bits(vf_le(vf_loadu(d), zv)) & valid)
                    return 0;
        } else {
            for (; y <= ye; y++, d += s)
                if (~vm_bits(vf_le(vf_load_bits(d, valid), zv)) & valid)
                    return 0;
        }
        return 1;
    }
    /* Boxes of two vectors inside the row (most wide ones), with pairs:
     * both loaded whole, the second one's lanes past the box counted as
     * passing. */
    if (pairs && nx <= 2 * SIMD_W && x0 + 2 * SIMD_W <= t->width) {
        const int n2 = nx - SIMD_W;
        const unsigned v2 = n2 >= SIMD_W ? SIMD_FULL : (1u << n2) - 1u;
        const vmask past = vm_from_bits(~v2 & SIMD_FULL);
        for (; y < ye; y += 2, d += 2 * s) {
            const vmask r0 = vm_and(vf_le(vf_loadu(d), zv),
                                    vm_or(vf_le(vf_loadu(d + SIMD_W), zv), past));
            const vmask r1 = vm_and(vf_le(vf_loadu(d + s), zv),
                                    vm_or(vf_le(vf_loadu(d + s + SIMD_W), zv), past));
            if (~vm_bits(vm_and(r0, r1)) & SIMD_FULL)
                return 0;
        }
        return !(y == ye && (~vm_bits(vm_and(vf_le(vf_loadu(d), zv),
                                             vm_or(vf_le(vf_loadu(d + SIMD_W), zv), past))) &
                             SIMD_FULL));
    }
    /* Other wide boxes: whole vectors, the last one's lanes masked to the
     * box (a masked load when it would cross the row's end). */
    const int nfull = nx / SIMD_W, rem = nx % SIMD_W;
    const unsigned lastvalid = (1u << rem) - 1u;
    const int lastin = x0 + nfull * SIMD_W + SIMD_W <= t->width;
    for (; y <= ye; y++, d += s) {
        for (int v = 0; v < nfull; v++)
            if (~vm_bits(vf_le(vf_loadu(d + v * SIMD_W), zv)) & SIMD_FULL)
                return 0;
        if (rem) {
            const float *p = d + nfull * SIMD_W;
            const vfloat dv = lastin ? vf_loadu(p) : vf_load_bits(p, lastvalid);
            if (~vm_bits(vf_le(dv, zv)) & lastvalid)
                return 0;
        }
    }
    return 1;
}

static inline int simd_zbox_hidden(const rast_target *t, float zc, float zdx, float zdy, int x0,
                                   int y0, int ys, int ye, int nx)
{
    /* Most visible triangles: a depth above the box corner's z (the
     * cleared 1.0 or a farther surface) at the box's first pixel ends the
     * test before its set-up (returning 0 only costs the scan). */
    const float *d = t->depth + (size_t)ys * (size_t)t->depth_stride + x0;
    if (*d > zc + zdy * (float)(ys - y0))
        return 0;
    const double c = zc, fi1 = nx - 1;
    const double ay = (double)zdy * (double)(ys - y0);
    const double by = (double)zdy * (double)(ye - y0);
    const double ax = (double)zdx * fi1;
    const double zmin = c + (ay < by ? ay : by) + (ax < 0.0 ? ax : 0.0);
    const double sy = simd_absd(ay) > simd_absd(by) ? simd_absd(ay) : simd_absd(by);
    const double zb = zmin - (simd_absd(c) + sy + simd_absd(ax)) * 0x1p-18;
    if (!(zb > 0.0 && zb < 1e30))
        return 0;
    return simd_zbox_rows(t, d, vf_set1(zb < 1.0 ? (float)zb : 1.0f), x0, ys, ye, nx, 0);
}
#endif /* RAST_HIDDEN_INL */
