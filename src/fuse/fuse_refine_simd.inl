/* fuse_refine_simd.inl - the row kernels of the band-only refinement
 * (fuse_refine_kern.h), written ONCE on the vector layer (src/cpu/simd.h,
 * its REFINE OPS for the byte and 16-bit lanes, vf_gather_m for the score
 * look-ups) and included by fuse_refine_avx2.c, fuse_refine_avx512.c and
 * fuse_refine_neon.c after their simd_*.h. Same bytes as the reference
 * (tests/test_fuse_refine.c). Whole vectors inside the row; the few pixels
 * at a row's ends (and the histogram) go through the portable kernels,
 * which give the same values:
 *   edges      VB_W mask pixels per step: inside is the byte's bit 7, so
 *              the edge is bit 7 of (m^l)|(m^r)|(m^u)|(m^d), its bits by
 *              vb_sign_bits (pmovmskb);
 *   dt_init    VH_W per step, the same rule on 16-bit lanes;
 *   chamfer    the vertical minimum and the running minimum (a log-step
 *              scan, vh_runmin3_up / _dn) VH_W distances per step;
 *   ring skip  VH_W distances per step;
 *   scores     SIMD_W per step: colour bins in lanes (refine_bins), the
 *              table look-ups by vf_gather_m (the band's lanes), the
 *              last vector ending at the row's end (it overlaps the one
 *              before and writes the same values again);
 *   decision   SIMD_W per step, the window sum in the reference's order;
 *   binarise   VB_W per step.
 * This file defines SIMD_FN(fuse__refine_kern)(), e.g.
 * fuse__refine_kern_avx2(), whose table names the eight kernels
 * SIMD_FN(refine_edge_span) ... SIMD_FN(refine_binarise) (prototypes
 * below). What an ISA does its own way, the includer defines before or
 * after the include, with a switch:
 *   REFINE_OWN_ROWS   every kernel but the scores (fuse_refine_avx512.c:
 *                     masked row ends, a vpermw running minimum, the ring
 *                     pixels' mask bits; it calls SIMD_FN(refine_bins));
 *   REFINE_OWN_SCORE  the scores (fuse_refine_neon.c: the portable kernel;
 *                     NEON has no gather, vf_gather_m would go lane by lane). */

#define KC fuse__refine_kern_c

static int SIMD_FN(refine_edge_span)(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                     int w, int *x0, int *x1);
static void SIMD_FN(refine_dt_init)(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                    int w, int a, int b, uint16_t cap, uint16_t *d);
static void SIMD_FN(refine_dt_fwd)(uint16_t *r, const uint16_t *u, int w, int a, int b);
static void SIMD_FN(refine_dt_bwd)(uint16_t *r, const uint16_t *dn, int w, int a, int b);
static void SIMD_FN(refine_hist_row)(const uint8_t *px, const uint8_t *m, const uint16_t *d,
                                     int a, int b, unsigned band3, unsigned outer3, int bits,
                                     uint32_t *hf, uint32_t *hb, long *nf, long *nb);
static void SIMD_FN(refine_score_row)(const fuse__refine_tabs *t, const uint8_t *px,
                                      const uint8_t *m, const uint16_t *d, float *s, int a,
                                      int b);
static void SIMD_FN(refine_decide_row)(const float *s, ptrdiff_t ss, int rad, const uint8_t *m,
                                       const uint16_t *d, unsigned band3, uint8_t *out, int a,
                                       int b, long cnt[3]);
static void SIMD_FN(refine_binarise)(const uint8_t *m, uint8_t *out, int a, int b);

/* the colour bins of SIMD_W RGBA8 pixels (int32 lanes, R in the low
 * byte), as the portable bin_of: (R >> s) << 2 bits | (G >> s) << bits |
 * B >> s, s = 8 - bits */
SIMD_INL vint SIMD_FN(refine_bins)(vint v, int bits)
{
    const vint ff = vi_set1(0xFF);
    const int s = 8 - bits;
    const vint r = vi_srl(vi_and(v, ff), s);
    const vint g = vi_srl(vi_and(vi_srli(v, 8), ff), s);
    const vint bl = vi_srl(vi_and(vi_srli(v, 16), ff), s);
    return vi_or(vi_or(vi_sll(r, 2 * bits), vi_sll(g, bits)), bl);
}

#ifndef REFINE_OWN_ROWS

/* bit 7 of each byte: the edge pixels of the VB_W at x (1 <= x,
 * x + VB_W < w) */
SIMD_INL vint SIMD_FN(refine_edge_bytes)(const uint8_t *up, const uint8_t *row,
                                         const uint8_t *dn, int x)
{
    const vint m = vb_loadu(row + x);
    const vint l = vi_xor(m, vb_loadu(row + x - 1)), r = vi_xor(m, vb_loadu(row + x + 1));
    const vint u = vi_xor(m, vb_loadu(up + x)), d = vi_xor(m, vb_loadu(dn + x));
    return vi_or(vi_or(l, r), vi_or(u, d));
}

static int SIMD_FN(refine_edge_span)(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                     int w, int *x0, int *x1)
{
    int a = -1, b = -1;
    for (int x = 0; x < w;) {
        if (x >= 1 && x + VB_W < w) {
            const uint64_t e = vb_sign_bits(SIMD_FN(refine_edge_bytes)(up, row, dn, x));
            if (e) { a = x + __builtin_ctzll(e); break; }
            x += VB_W;
        } else {
            if (fuse__refine_edge_at(up, row, dn, w, x)) { a = x; break; }
            x++;
        }
    }
    if (a < 0) return 0;
    for (int x = w - 1; x >= a;) {
        if (x - (VB_W - 1) >= 1 && x + 1 < w) {
            const uint64_t e = vb_sign_bits(SIMD_FN(refine_edge_bytes)(up, row, dn,
                                                                       x - (VB_W - 1)));
            /* the highest set bit h: pixel x - (VB_W - 1) + h */
            if (e) { b = x - (VB_W - 1) + (63 - __builtin_clzll(e)); break; }
            x -= VB_W;
        } else {
            if (fuse__refine_edge_at(up, row, dn, w, x)) { b = x; break; }
            x--;
        }
    }
    *x0 = a;
    *x1 = b;
    return 1;
}

static void SIMD_FN(refine_dt_init)(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                    int w, int a, int b, uint16_t cap, uint16_t *d)
{
    const vint vcap = vh_set1(cap), flip = vh_set1(cap ^ 3u), one = vh_set1(1);
    int x = a;
    if (x < 1) {   /* pixel 0: no left neighbour */
        KC.dt_init(up, row, dn, w, 0, 0, cap, d);
        x = 1;
    }
    for (; x + VH_W - 1 <= b && x + VH_W < w; x += VH_W) {
        const vint m = vh_load_u8(row + x);
        const vint e = vi_or(vi_or(vi_xor(m, vh_load_u8(row + x - 1)),
                                   vi_xor(m, vh_load_u8(row + x + 1))),
                             vi_or(vi_xor(m, vh_load_u8(up + x)),
                                   vi_xor(m, vh_load_u8(dn + x))));
        /* 0xFFFF on the edge lanes (bit 7 of the byte), else 0 */
        const vint sel = vh_sub(vi_zero(), vi_and(vh_srli(e, 7), one));
        vh_storeu(d + x, vi_xor(vcap, vi_and(sel, flip)));   /* edge ? 3 : cap */
    }
    if (x <= b) KC.dt_init(up, row, dn, w, x, b, cap, d);
}

/* the vertical part of VH_W lanes at x (1 <= x, x + VH_W < w): min(r, v + 3,
 * v[-1] + 4, v[+1] + 4); the saturating add gives the reference's minimum
 * (v + k > 65535 never wins against r <= 65535) */
SIMD_INL vint SIMD_FN(refine_vert)(vint m, const uint16_t *v, int x)
{
    m = vh_min_u(m, vh_adds_u(vh_loadu(v + x), vh_set1(3)));
    m = vh_min_u(m, vh_adds_u(vh_loadu(v + x - 1), vh_set1(4)));
    return vh_min_u(m, vh_adds_u(vh_loadu(v + x + 1), vh_set1(4)));
}

/* A chamfer row pass in one sweep: VH_W lanes per step get the vertical
 * part (v: the row above / below, NULL: none), then the running minimum
 * (vh_runmin3_up / _dn, the carry the pixel before the vector, 65535 when
 * the reference's loop leaves the row's first / last pixel alone); pixel
 * 0 / w - 1 and what the vectors do not cover go through the portable
 * kernel, which then reads the neighbour already final. Pixel x's vertical
 * part reads only r[x] and v, so doing it per vector gives the portable
 * kernel's values. */
static void SIMD_FN(refine_dt_fwd)(uint16_t *r, const uint16_t *u, int w, int a, int b)
{
    int x = a;
    if (x == 0 && u) {   /* pixel 0: no left neighbour; the running minimum keeps it */
        r[0] = fuse__refine_vert_px(r, u, w, 0);
        x = 1;
    }
    unsigned c = x > 0 ? r[x - 1] : 0xFFFFu;
    if (u)
        for (; x + VH_W - 1 <= b && x + VH_W < w; x += VH_W) {
            vh_storeu(r + x, vh_runmin3_up(SIMD_FN(refine_vert)(vh_loadu(r + x), u, x), c));
            c = r[x + VH_W - 1];
        }
    else
        for (; x + VH_W - 1 <= b; x += VH_W) {
            vh_storeu(r + x, vh_runmin3_up(vh_loadu(r + x), c));
            c = r[x + VH_W - 1];
        }
    if (x <= b) KC.dt_fwd(r, u, w, x, b);
}

static void SIMD_FN(refine_dt_bwd)(uint16_t *r, const uint16_t *dn, int w, int a, int b)
{
    int x = b;   /* the last pixel not done */
    if (x == w - 1 && dn) {   /* pixel w - 1: no right neighbour; kept by the minimum */
        r[x] = fuse__refine_vert_px(r, dn, w, x);
        x--;
    }
    unsigned c = x + 1 < w ? r[x + 1] : 0xFFFFu;
    if (dn)
        for (; x - (VH_W - 1) >= a && x - (VH_W - 1) >= 1; x -= VH_W) {
            const int x0 = x - (VH_W - 1);
            vh_storeu(r + x0, vh_runmin3_dn(SIMD_FN(refine_vert)(vh_loadu(r + x0), dn, x0), c));
            c = r[x0];
        }
    else
        for (; x - (VH_W - 1) >= a; x -= VH_W) {
            const int x0 = x - (VH_W - 1);
            vh_storeu(r + x0, vh_runmin3_dn(vh_loadu(r + x0), c));
            c = r[x0];
        }
    if (x >= a) KC.dt_bwd(r, dn, w, a, x);
}

static void SIMD_FN(refine_hist_row)(const uint8_t *px, const uint8_t *m, const uint16_t *d,
                                     int a, int b, unsigned band3, unsigned outer3, int bits,
                                     uint32_t *hf, uint32_t *hb, long *nf, long *nb)
{
    /* skip VH_W distances at a time that hold no ring pixel:
     * band3 < d <= outer3  <=>  (uint16)(d - band3 - 1) <= outer3 - band3 - 1 */
    const vint lo = vh_set1((int)(band3 + 1u)), span = vh_set1((int)(outer3 - band3 - 1u));
    int x = a;
    while (x <= b) {
        if (x + VH_W - 1 <= b) {
            if (vh_any_leu(vh_sub(vh_loadu(d + x), lo), span))
                KC.hist_row(px, m, d, x, x + VH_W - 1, band3, outer3, bits, hf, hb, nf, nb);
            x += VH_W;
        } else {
            KC.hist_row(px, m, d, x, b, band3, outer3, bits, hf, hb, nf, nb);
            break;
        }
    }
}

#endif /* REFINE_OWN_ROWS: the score kernel, then the decision and binarise */

#ifndef REFINE_OWN_SCORE
/* SIMD_W scores per step (rows shorter than a vector: the portable
 * kernel); the look-ups only in the band's lanes (vf_gather_m) */
static void SIMD_FN(refine_score_row)(const fuse__refine_tabs *t, const uint8_t *px,
                                      const uint8_t *m, const uint16_t *d, float *s, int a,
                                      int b)
{
    if (b - a + 1 < SIMD_W) {
        KC.score_row(t, px, m, d, s, a, b);
        return;
    }
    const vint vb3 = vi_set1((int)t->band3), v127 = vi_set1(127);
    const vint off = vi_set1((int)(t->pr_out - t->pr_in));
    const vfloat p4 = vf_set1(4.0f), n4 = vf_set1(-4.0f);
    const vfloat w0 = vf_set1(t->w0), gw = vf_set1(t->gw);
    /* the table fields in locals: the stores to s could alias *t */
    const float *const llr = t->llr, *const gllr = t->gllr, *const pr_in = t->pr_in;
    const int bits = t->bits, gbits = t->gbits;
    for (int x = a;; x += SIMD_W) {
        if (x > b - (SIMD_W - 1)) x = b - (SIMD_W - 1);   /* the last vector ends at b */
        const vint dv = vi_load_u16(d + x);
        const vmask in = vi_gt(vi_load_u8(m + x), v127);
        const vmask band = vm_not(vi_gt(dv, vb3));
        vfloat o = vf_sel(in, p4, n4);
        if (vm_any(band)) {
            const vint v = vi_loadu((const int32_t *)(const void *)(px + 4 * (size_t)x));
            vfloat c = vf_gather_m(llr, SIMD_FN(refine_bins)(v, bits), band);
            if (gllr) {
                const vfloat gc = vf_gather_m(gllr, SIMD_FN(refine_bins)(v, gbits), band);
                c = vf_add(vf_mul(w0, c), vf_mul(gw, gc));
            }
            const vint pidx = vi_sel(in, dv, vi_add(dv, off));
            o = vf_sel(band, vf_add(c, vf_gather_m(pr_in, pidx, band)), o);
        }
        vf_storeu(s + x, o);
        if (x == b - (SIMD_W - 1)) break;
    }
}
#endif

#ifndef REFINE_OWN_ROWS
static void SIMD_FN(refine_decide_row)(const float *s, ptrdiff_t ss, int rad, const uint8_t *m,
                                       const uint16_t *d, unsigned band3, uint8_t *out, int a,
                                       int b, long cnt[3])
{
    const vint vb3 = vi_set1((int)band3), v127 = vi_set1(127), ff = vi_set1(255);
    long nb = 0, fi = 0, fo = 0;
    int x = a;
    for (; x + SIMD_W - 1 <= b; x += SIMD_W) {
        const vmask bandm = vm_not(vi_gt(vi_load_u16(d + x), vb3));
        const vmask inm = vi_gt(vi_load_u8(m + x), v127);
        vmask v = inm;
        if (vm_any(bandm)) {
            vfloat sum = vf_zero();
            for (int dy = -rad; dy <= rad; dy++) {
                const float *r = s + dy * ss + x;
                for (int dx = -rad; dx <= rad; dx++) sum = vf_add(sum, vf_loadu(r + dx));
            }
            const vmask posm = vf_gt(sum, vf_zero());
            v = vm_or(vm_andnot(bandm, inm), vm_and(posm, bandm));
            const unsigned band = vm_bits(bandm), in = vm_bits(inm), pos = vm_bits(posm);
            nb += __builtin_popcount(band);
            fi += __builtin_popcount(band & pos & ~in);
            fo += __builtin_popcount(band & ~pos & in & SIMD_FULL);
        }
        /* the lanes' bytes: 255 where set, else 0 */
        vi_store_u8(out + x, vi_sel(v, ff, vi_zero()));
    }
    cnt[0] += nb;
    cnt[1] += fi;
    cnt[2] += fo;
    if (x <= b) KC.decide_row(s, ss, rad, m, d, band3, out, x, b, cnt);
}

static void SIMD_FN(refine_binarise)(const uint8_t *m, uint8_t *out, int a, int b)
{
    int x = a;
    for (; x + VB_W - 1 <= b; x += VB_W) vb_storeu(out + x, vb_sign_fill(vb_loadu(m + x)));
    if (x <= b) KC.binarise(m, out, x, b);
}
#endif /* REFINE_OWN_ROWS */

static const fuse__refine_kern SIMD_FN(refine_kern) = {
    SIMD_FN(refine_edge_span), SIMD_FN(refine_dt_init),   SIMD_FN(refine_dt_fwd),
    SIMD_FN(refine_dt_bwd),    SIMD_FN(refine_hist_row),  SIMD_FN(refine_score_row),
    SIMD_FN(refine_decide_row), SIMD_FN(refine_binarise),
};

const fuse__refine_kern *SIMD_FN(fuse__refine_kern)(void) { return &SIMD_FN(refine_kern); }

#undef KC
