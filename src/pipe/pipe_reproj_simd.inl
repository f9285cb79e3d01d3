/* pipe_reproj_simd.inl - the reprojection's per-pixel geometry (the eye
 * ray times its distance, into the camera's pinhole, the border fade, the
 * occlusion bound and the bilinear taps' positions and weights) for
 * SIMD_W eye pixels a step, written once on the vector layer
 * (src/cpu/simd.h). Included by pipe_reproj_{sse2,avx2,avx512,neon}.c
 * after their simd_*.h. Every lane is the scalar reference's arithmetic
 * (pipe_reproj.c, row_ref) in its order: the same bytes on every ISA. */

/* Columns [0, w) of one eye row, SIMD_W at a time, skipping blocks with
 * no covered pixel; the first column not done (row_ref finishes). back:
 * covered pixels facing away added; *mind: the least distance of a
 * covered pixel. The pinhole camera only (g->pinhole). */
int SIMD_FN(pipe__reproj_row)(const pipe__reproj_geo *g, const uint8_t *em, const float *ed,
                              const float *en, float ry_s, int w, const pipe__reproj_lanes *o,
                              long *back, float *mind)
{
    const vfloat zero = vf_zero(), one = vf_set1(1.0f), two = vf_set1(2.0f);
    const vfloat ry = vf_set1(ry_s), two_fn = vf_set1(g->two_fn), fpn = vf_set1(g->fpn),
                 fmn = vf_set1(g->fmn), nn = vf_set1(g->n);
    const vfloat a0 = vf_set1(g->a[0]), a1 = vf_set1(g->a[1]), a2 = vf_set1(g->a[2]),
                 a4 = vf_set1(g->a[4]), a5 = vf_set1(g->a[5]), a6 = vf_set1(g->a[6]),
                 a8 = vf_set1(g->a[8]), a9 = vf_set1(g->a[9]), a10 = vf_set1(g->a[10]),
                 a12 = vf_set1(g->a[12]), a13 = vf_set1(g->a[13]), a14 = vf_set1(g->a[14]);
    const vfloat cfx = vf_set1(g->cfx), cfy = vf_set1(g->cfy), ccx = vf_set1(g->ccx),
                 ccy = vf_set1(g->ccy), cw = vf_set1(g->cw), ch = vf_set1(g->ch),
                 cw1 = vf_set1(g->cw1), ch1 = vf_set1(g->ch1);
    const vfloat behind = vf_set1(-1e-6f), fade = vf_set1(PIPE_REPROJ_FADE_PX),
                 k255 = vf_set1(255.0f), half = vf_set1(0.5f), k256 = vf_set1(256.0f),
                 tol = vf_set1(PIPE_REPROJ_TOL_M), rel = vf_set1(PIPE_REPROJ_TOL_REL);
    const vint icw1 = vi_set1(g->icw1), ich1 = vi_set1(g->ich1), i255 = vi_set1(255);
    vfloat vmind = vf_set1(*mind);
    long bk = 0;
    int x = 0;
    for (; w - x >= SIMD_W; x += SIMD_W) {
        const vmask cov = vm_not(vi_eq(vi_load_u8(em + x), vi_zero()));
        if (!vm_any(cov)) continue;
        const vfloat rx = vf_loadu(g->rxs + x);
        vfloat n0, n1, n2;
        vf_load3(en + 3 * x, &n0, &n1, &n2);
        const vmask bm = vf_gt(vf_sub(vf_add(vf_mul(n0, rx), vf_mul(n1, ry)), n2), zero);
        bk += __builtin_popcount(vm_bits(vm_and(bm, cov)));
        const vfloat zn = vf_sub(vf_mul(two, vf_loadu(ed + x)), one);
        const vfloat dist = vf_div(two_fn, vf_sub(fpn, vf_mul(zn, fmn)));
        vmind = vf_sel(vm_and(cov, vf_lt(dist, vmind)), dist, vmind);
        const vfloat ex = vf_mul(rx, dist), ey = vf_mul(ry, dist), ez = vf_neg(dist);
        const vfloat px = vf_add(vf_add(vf_add(vf_mul(a0, ex), vf_mul(a4, ey)), vf_mul(a8, ez)), a12);
        const vfloat py = vf_add(vf_add(vf_add(vf_mul(a1, ex), vf_mul(a5, ey)), vf_mul(a9, ez)), a13);
        const vfloat pz = vf_add(vf_add(vf_add(vf_mul(a2, ex), vf_mul(a6, ey)), vf_mul(a10, ez)), a14);
        const vmask ok = vf_lt(pz, behind);
        const vfloat iz = vf_div(one, vf_neg(pz));
        const vfloat fu = vf_add(ccx, vf_mul(vf_mul(cfx, px), iz));
        const vfloat fv = vf_sub(ccy, vf_mul(vf_mul(cfy, py), iz));
        vfloat b = fu, t = vf_sub(cw, fu);
        b = vf_sel(vf_lt(t, b), t, b);
        b = vf_sel(vf_lt(fv, b), fv, b);
        t = vf_sub(ch, fv);
        b = vf_sel(vf_lt(t, b), t, b);
        const vmask in = vm_and(ok, vf_gt(b, zero));
        const vint mf = vi_from_vf_trunc(vf_add(vf_mul(k255, vf_div(b, fade)), half));
        const vint mv = vi_sel(vf_ge(b, fade), i255, mf);
        vi_storeu(o->mv + x, vi_sel(in, mv, vi_zero()));
        const vfloat dp = vf_neg(pz), dmin = vf_sub(dp, vf_add(tol, vf_mul(rel, dp)));
        const vfloat zm = vf_add(vf_div(vf_mul(half, vf_sub(fpn, vf_div(two_fn, dmin))), fmn), half);
        vf_storeu(o->zmin + x, vf_selz(vf_gt(dmin, nn), zm));
        vi_storeu(o->iu + x, vi_min(vi_from_vf_trunc(fu), icw1));
        vi_storeu(o->iv + x, vi_min(vi_from_vf_trunc(fv), ich1));
        vfloat sx = vf_sub(fu, half), sy = vf_sub(fv, half);
        sx = vf_sel(vf_lt(sx, zero), zero, sx);
        sy = vf_sel(vf_lt(sy, zero), zero, sy);
        sx = vf_sel(vf_gt(sx, cw1), cw1, sx);
        sy = vf_sel(vf_gt(sy, ch1), ch1, sy);
        const vint x0 = vi_from_vf_trunc(sx), y0 = vi_from_vf_trunc(sy);
        vi_storeu(o->tx + x, x0);
        vi_storeu(o->ty + x, y0);
        vi_storeu(o->fx + x, vi_from_vf_trunc(vf_mul(vf_sub(sx, vf_from_vi(x0)), k256)));
        vi_storeu(o->fy + x, vi_from_vf_trunc(vf_mul(vf_sub(sy, vf_from_vi(y0)), k256)));
    }
    _Alignas(64) float ms[SIMD_W];
    vf_storeu(ms, vmind);
    for (int l = 0; l < SIMD_W; l++)
        if (ms[l] < *mind) *mind = ms[l];
    *back += bk;
    return x;
}
