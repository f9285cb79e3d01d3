/* pipe_reproj_simd.inl - the reprojection's per-pixel geometry (the eye
 * ray times its distance, into the camera's pinhole, the border fade, the
 * occlusion bound and the bilinear taps' positions and weights) for
 * SIMD_W eye pixels a step, written once on the vector layer
 * (src/cpu/simd.h). Included by pipe_reproj_{sse2,avx2,avx512,neon}.c
 * after their simd_*.h. Every lane is the scalar reference's arithmetic
 * (pipe_reproj.c, row_ref) in its order: the same bytes on every ISA.
 * Then the taps (pipe__reproj_taps): the camera G-buffer's mask and depth
 * and the image's pixels by gathers (vi_gather_u8x4, vf_gather, vi_gather:
 * AVX2/AVX-512 gathers, SSE2/NEON lane by lane), the bilinear in int32
 * lanes, the renormalising division in float (exact, see there). */

#include "../cpu/ef_n10.h"

/* Columns [x0, w) of one eye row, SIMD_W at a time, skipping blocks with
 * no covered pixel; the first column not done (row_ref finishes). back:
 * covered pixels facing away added; *mind: the least distance of a
 * covered pixel. The pinhole camera only (g->pinhole). */
int SIMD_FN(pipe__reproj_row)(const pipe__reproj_geo *g, const uint8_t *em, const float *ed,
                              const uint32_t *en, float ry_s, int x0, int w,
                              const pipe__reproj_lanes *o, long *back, float *mind)
{
    const vfloat zero = vf_zero(), one = vf_set1(1.0f), two = vf_set1(2.0f),
                 inv511 = vf_set1(EF_N10_INV);
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
    int x = x0;
    for (; w - x >= SIMD_W; x += SIMD_W) {
        const vmask cov = vm_not(vi_eq(vi_load_u8(em + x), vi_zero()));
        if (!vm_any(cov)) continue;
        const vfloat rx = vf_loadu(g->rxs + x);
        /* the packed normals (ef_n10_unpack: each 10-bit field
         * sign-extended, k / 511) */
        const vint pn = vi_loadu((const int32_t *)(en + x));
        const vfloat n0 = vf_mul(vf_from_vi(vi_srai(vi_slli(pn, 22), 22)), inv511),
                     n1 = vf_mul(vf_from_vi(vi_srai(vi_slli(pn, 12), 22)), inv511),
                     n2 = vf_mul(vf_from_vi(vi_srai(vi_slli(pn, 2), 22)), inv511);
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

/* ------------------------------------------------------------ the taps */

/* lanes with 0 <= gx < gw and 0 <= gy < gh */
static inline vmask rp_inside(vint gx, vint gy, vint gw, vint gh)
{
    const vint m1 = vi_set1(-1);
    return vm_and(vm_and(vi_gt(gx, m1), vi_gt(gw, gx)), vm_and(vi_gt(gy, m1), vi_gt(gh, gy)));
}

/* The scalar shows() (pipe_reproj.c) for the lanes of valid at G-buffer
 * pixel (gx, gy): outside the G-buffer yes, else the camera's mask there
 * and its depth not nearer than zmin. The other lanes: no. A mask byte
 * with fewer than 4 readable bytes from it (the last pixels of the
 * buffer) is read alone. */
static inline vmask rp_shows(const pipe__reproj_tapd *t, vmask valid, vint gx, vint gy,
                             vfloat zmin)
{
    const vint gw = vi_set1(t->gw), gh = vi_set1(t->gh), mlim = vi_set1(t->mlim);
    const vmask in = vm_and(valid, rp_inside(gx, gy, gw, gh));
    const vint mo = vi_sel(in, vi_add(vi_mullo(gy, vi_set1(t->cms)), gx), vi_zero());
    const vint dof = vi_sel(in, vi_add(vi_mullo(gy, vi_set1(t->cds)), gx), vi_zero());
    const vmask late = vm_and(in, vi_gt(mo, mlim));
    vint mb = vi_and(vi_gather_u8x4(t->cmask, vi_sel(late, vi_zero(), mo)), vi_set1(0xFF));
    if (vm_any(late)) {
        _Alignas(64) int32_t off[SIMD_W], b[SIMD_W];
        vi_storeu(off, mo);
        vi_storeu(b, mb);
        for (unsigned k = vm_bits(late); k; k &= k - 1) {
            const int l = __builtin_ctz(k);
            b[l] = t->cmask[off[l]];
        }
        mb = vi_loadu(b);
    }
    const vfloat d = vf_gather(t->cdepth, dof);
    const vmask sh = vm_and(vm_not(vi_eq(mb, vi_zero())), vm_not(vf_lt(d, zmin)));
    return vm_or(vm_andnot(in, valid), vm_and(in, sh));
}

/* rp_shows for the two taps (gx, gy) and (gx + dx, gy) of one row of the
 * bilinear (dx 0 or 1) at once: where both are inside the G-buffer, one
 * 4-byte mask gather gives both mask bytes and the depths are two
 * gathers of one offset; a lane with one of them inside and the other
 * not (the G-buffer's side edges inside the image: a crop by columns)
 * goes through rp_shows tap by tap. */
SIMD_INL void rp_shows2(const pipe__reproj_tapd *t, vmask valid, vint gx, vint dx, vint gy,
                             vfloat zmin, vmask *s0, vmask *s1)
{
    const vint gw = vi_set1(t->gw), gh = vi_set1(t->gh), m1 = vi_set1(-1);
    const vint gx1 = vi_add(gx, dx);
    const vmask row = vm_and(valid, vm_and(vi_gt(gy, m1), vi_gt(gh, gy)));
    const vmask c0 = vm_and(vi_gt(gx, m1), vi_gt(gw, gx));
    const vmask c1 = vm_and(vi_gt(gx1, m1), vi_gt(gw, gx1));
    const vmask in = vm_and(row, vm_and(c0, c1));
    vmask a = vm_andnot(in, valid), b = a;
    if (vm_any(in)) {
        const vint mo = vi_sel(in, vi_add(vi_mullo(gy, vi_set1(t->cms)), gx), vi_zero());
        const vint dof = vi_sel(in, vi_add(vi_mullo(gy, vi_set1(t->cds)), gx), vi_zero());
        const vmask late = vm_and(in, vi_gt(mo, vi_set1(t->mlim)));
        vint mb = vi_gather_u8x4(t->cmask, vi_sel(late, vi_zero(), mo));
        if (vm_any(late)) { /* fewer than 4 readable bytes: the two alone */
            _Alignas(64) int32_t off[SIMD_W], d[SIMD_W], bb[SIMD_W];
            vi_storeu(off, mo);
            vi_storeu(d, dx);
            vi_storeu(bb, mb);
            for (unsigned k = vm_bits(late); k; k &= k - 1) {
                const int l = __builtin_ctz(k);
                bb[l] = t->cmask[off[l]] | t->cmask[off[l] + d[l]] << 8;
            }
            mb = vi_loadu(bb);
        }
        const vint k255 = vi_set1(0xFF), zero = vi_zero();
        const vint mb0 = vi_and(mb, k255);
        const vint mb1 = vi_sel(vi_eq(dx, zero), mb0, vi_and(vi_srli(mb, 8), k255));
        const vfloat d0 = vf_gather(t->cdepth, dof), d1 = vf_gather(t->cdepth, vi_add(dof, dx));
        a = vm_or(a, vm_and(in, vm_andnot(vi_eq(mb0, zero), vm_not(vf_lt(d0, zmin)))));
        b = vm_or(b, vm_and(in, vm_andnot(vi_eq(mb1, zero), vm_not(vf_lt(d1, zmin)))));
    }
    const vmask mixed = vm_andnot(in, vm_and(row, vm_or(c0, c1)));
    if (vm_any(mixed)) {
        a = vm_or(vm_andnot(mixed, a), rp_shows(t, mixed, gx, gy, zmin));
        b = vm_or(vm_andnot(mixed, b), rp_shows(t, mixed, gx1, gy, zmin));
    }
    *s0 = a;
    *s1 = b;
}

#define RP_CH(p, k) vi_and(vi_srli(p, 8 * (k)), vi_set1(0xFF))

/* Columns [x0, w) of one eye row, SIMD_W at a time (the scalar taps of
 * pipe_reproj.c lane by lane); the first column not done. */
int SIMD_FN(pipe__reproj_taps)(const pipe__reproj_tapd *t, const uint8_t *em,
                               const pipe__reproj_lanes *o, int x0, int w, uint8_t *M, uint8_t *Po,
                               long cnt[4])
{
    const vint zero = vi_zero(), one = vi_set1(1), k256 = vi_set1(256);
    const vint ox = vi_set1(t->ox), oy = vi_set1(t->oy), ps4 = vi_set1(t->ps4);
    const vint icw1 = vi_set1(t->icw1), ich1 = vi_set1(t->ich1);
    const vint rgb = vi_set1(0x00FFFFFF), a_fill = vi_set1(2 << 24), a_samp = vi_set1(1 << 24);
    const int32_t *P = (const int32_t *)(const void *)t->P;
    long ncov = 0, nout = 0, nfill = 0, nsamp = 0;
    int x = x0;
    for (; w - x >= SIMD_W; x += SIMD_W) {
        const vmask cov = vm_not(vi_eq(vi_load_u8(em + x), zero));
        const unsigned cb = vm_bits(cov);
        if (!cb) continue;
        const vint mv = vi_loadu(o->mv + x);
        const vmask valid = vm_and(cov, vi_gt(mv, zero));
        vi_store_u8(M + x, vi_sel(cov, mv, zero));
        const unsigned vb = vm_bits(valid);
        ncov += __builtin_popcount(cb);
        nout += __builtin_popcount(cb & ~vb);
        if (!vb) continue;
        /* the four bilinear taps: which show the point. The nearest camera
         * pixel (iu, iv) is one of them (fu - 0.5 is exact below 2^23, so
         * trunc(fu) is tx + 1 exactly where the fraction fx is >= 128, and
         * likewise for y), so its test, whether the camera sees the point
         * at all, is read from theirs */
        const vfloat zmin = vf_loadu(o->zmin + x);
        const vint tx = vi_loadu(o->tx + x), ty = vi_loadu(o->ty + x);
        const vint fx = vi_loadu(o->fx + x), fy = vi_loadu(o->fy + x);
        const vint dx = vi_sel(vi_gt(icw1, tx), one, zero);
        const vint y1 = vi_add(ty, vi_sel(vi_gt(ich1, ty), one, zero));
        const vint gx = vi_sub(tx, ox);
        vmask t00, t01, t10, t11;
        rp_shows2(t, valid, gx, dx, vi_sub(ty, oy), zmin, &t00, &t01);
        rp_shows2(t, valid, gx, dx, vi_sub(y1, oy), zmin, &t10, &t11);
        const vint h127 = vi_set1(127);
        const vmask right = vi_gt(fx, h127), down = vi_gt(fy, h127);
        const vmask seen =
            vm_and(valid, vm_or(vm_and(down, vm_or(vm_and(right, t11), vm_andnot(right, t10))),
                                vm_andnot(down, vm_or(vm_and(right, t01), vm_andnot(right, t00)))));
        const vmask fill = vm_andnot(seen, valid);
        const unsigned sb = vm_bits(seen);
        nfill += __builtin_popcount(vm_bits(fill));
        nsamp += __builtin_popcount(sb);
        int32_t *po = (int32_t *)(void *)(Po + 4 * (size_t)x);
        const vint old = vi_loadu(po);
        vint out = vi_sel(fill, vi_or(vi_and(old, rgb), a_fill), old);
        if (sb) {
            /* bilinear, the taps that show the point, renormalised */
            t00 = vm_and(t00, seen), t01 = vm_and(t01, seen);
            t10 = vm_and(t10, seen), t11 = vm_and(t11, seen);
            const vint ifx = vi_sub(k256, fx), ify = vi_sub(k256, fy);
            const vint w00 = vi_sel(t00, vi_mullo(ifx, ify), zero);
            const vint w01 = vi_sel(t01, vi_mullo(fx, ify), zero);
            const vint w10 = vi_sel(t10, vi_mullo(ifx, fy), zero);
            const vint w11 = vi_sel(t11, vi_mullo(fx, fy), zero);
            /* never 0 where seen: the nearest pixel's tap shows the point
             * and its weight is not 0 (the scalar's "only the nearest
             * pixel" case cannot arise) */
            vint ws = vi_add(vi_add(vi_add(w00, w01), w10), w11);
            const vint r0 = vi_sel(seen, vi_mullo(ty, ps4), zero);
            const vint r1 = vi_sel(seen, vi_mullo(y1, ps4), zero);
            const vint c0 = vi_sel(seen, tx, zero), c1 = vi_sel(seen, vi_add(tx, dx), zero);
            const vint p00 = vi_gather(P, vi_add(r0, c0)), p01 = vi_gather(P, vi_add(r0, c1));
            const vint p10 = vi_gather(P, vi_add(r1, c0)), p11 = vi_gather(P, vi_add(r1, c1));
#define RP_ACC(k)                                                                          \
    vi_add(vi_add(vi_add(vi_mullo(w00, RP_CH(p00, k)), vi_mullo(w01, RP_CH(p01, k))),       \
                  vi_mullo(w10, RP_CH(p10, k))),                                            \
           vi_mullo(w11, RP_CH(p11, k)))
            const vint a0 = RP_ACC(0), a1 = RP_ACC(1), a2 = RP_ACC(2);
#undef RP_ACC
            /* (acc + ws / 2) / ws: below 2^24 over at most 2^16, so the
             * float quotient truncates to the integer one */
            ws = vi_sel(seen, ws, one);
            const vint hw = vi_srli(ws, 1);
            const vfloat fw = vf_from_vi(ws);
            const vint q0 = vi_from_vf_trunc(vf_div(vf_from_vi(vi_add(a0, hw)), fw));
            const vint q1 = vi_from_vf_trunc(vf_div(vf_from_vi(vi_add(a1, hw)), fw));
            const vint q2 = vi_from_vf_trunc(vf_div(vf_from_vi(vi_add(a2, hw)), fw));
            const vint px = vi_or(vi_or(q0, vi_slli(q1, 8)), vi_or(vi_slli(q2, 16), a_samp));
            out = vi_sel(seen, px, out);
        }
        vi_storeu(po, out);
    }
    cnt[0] += ncov;
    cnt[1] += nout;
    cnt[2] += nfill;
    cnt[3] += nsamp;
    return x;
}
#undef RP_CH
