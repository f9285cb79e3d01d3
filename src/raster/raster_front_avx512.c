/* raster_front_avx512.c - the vector front end (AVX-512 F+BW+DQ+VL):
 * vertex pass, rejection of 16 submitted triangles per group and the
 * set-up of 16 survivors per vector, straight into scan-ready records
 * (rast__vpass_fn, rast__frontv_fn in raster_internal.h; design and
 * figures in docs/raster.md section 11, sixth round).
 *
 * Every lane runs the operations of the scalar path in its order (no
 * contraction: -ffp-contract=off), so every byte equals rast__prepare_range
 * with the scalar set-up:
 *   vertex pass   vc_fill_one (finiteness, outcode, w > 0, snap, zw, iw);
 *   rejection     prepare_cached_one + setup_box_edges (area sign exact in
 *                 double, culling, clamped box, empty boxes of at most
 *                 2x2 pixels);
 *   set-up        setup_edges (int64 edges by vpmuldq), planes_one (the
 *                 double plane set-up, as raster_planes.inl), setup_attrs;
 *                 for boxes of at most 2x2 pixels, micro records instead
 *                 (micro_lanes: the scan's per-pixel values, in lanes).
 * Triangles with a vertex that is not finite, outside a clip plane or at
 * w <= 0 go through rast__prepare at their place in the order. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <stddef.h>

/* ---- vertex pass -------------------------------------------------------- */

/* count (1..16) vertices xyzw at c, de-interleaved; lanes past count 0. */
static inline void load_xyzw(const float *c, int count, __m512 *x, __m512 *y, __m512 *z,
                             __m512 *w)
{
    __m512 v[4];
    for (int i = 0; i < 4; i++) {
        const int left = 4 * count - 16 * i;
        if (left >= 16)
            v[i] = _mm512_loadu_ps(c + 16 * i);
        else if (left > 0)
            v[i] = _mm512_maskz_loadu_ps((__mmask16)((1u << left) - 1u), c + 16 * i);
        else
            v[i] = _mm512_setzero_ps();
    }
    const __m512i ixy = _mm512_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28, 1, 5, 9, 13, 17, 21,
                                          25, 29);
    const __m512i izw = _mm512_add_epi32(ixy, _mm512_set1_epi32(2));
    const __m512 xy01 = _mm512_permutex2var_ps(v[0], ixy, v[1]);
    const __m512 xy23 = _mm512_permutex2var_ps(v[2], ixy, v[3]);
    const __m512 zw01 = _mm512_permutex2var_ps(v[0], izw, v[1]);
    const __m512 zw23 = _mm512_permutex2var_ps(v[2], izw, v[3]);
    *x = _mm512_shuffle_f32x4(xy01, xy23, 0x44);
    *y = _mm512_shuffle_f32x4(xy01, xy23, 0xEE);
    *z = _mm512_shuffle_f32x4(zw01, zw23, 0x44);
    *w = _mm512_shuffle_f32x4(zw01, zw23, 0xEE);
}

void rast__vpass_avx512(const rast__view *v, const float *clip, int count, rast__vbuf *vb)
{
    const __m512 zero = _mm512_setzero_ps(), half = _mm512_set1_ps(0.5f);
    const __m512 fix = _mm512_set1_ps((float)RAST__FIX_ONE);
    const __m512 big = _mm512_set1_ps(FLT_MAX), nbig = _mm512_set1_ps(-FLT_MAX);
    const __m512 gx = _mm512_set1_ps(v->gx), gy = _mm512_set1_ps(v->gy);
    const __m512 fw = _mm512_set1_ps((float)v->width), fh = _mm512_set1_ps((float)v->height);
    const __m512 lox = _mm512_set1_ps((float)v->min_x), hix = _mm512_set1_ps((float)v->max_x);
    const __m512 loy = _mm512_set1_ps((float)v->min_y), hiy = _mm512_set1_ps((float)v->max_y);
    const __m512i mark = _mm512_set1_epi32(RAST__VX_SPECIAL);
    const __m512i ilo = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7,
                                          23);
    const __m512i ihi = _mm512_add_epi32(ilo, _mm512_set1_epi32(8));
    const __m512d dhalf = _mm512_set1_pd(0.5), done = _mm512_set1_pd(1.0);
    for (int base = 0; base < count; base += 16) {
        const int cnt = count - base < 16 ? count - base : 16;
        __m512 x, y, z, w;
        load_xyzw(clip + 4 * (size_t)base, cnt, &x, &y, &z, &w);
        /* vc_fill_one: finite (|c| <= FLT_MAX), outcode 0, w > 0. */
        const __mmask16 fin =
            _mm512_cmp_ps_mask(x, big, _CMP_LE_OQ) & _mm512_cmp_ps_mask(nbig, x, _CMP_LE_OQ) &
            _mm512_cmp_ps_mask(y, big, _CMP_LE_OQ) & _mm512_cmp_ps_mask(nbig, y, _CMP_LE_OQ) &
            _mm512_cmp_ps_mask(z, big, _CMP_LE_OQ) & _mm512_cmp_ps_mask(nbig, z, _CMP_LE_OQ) &
            _mm512_cmp_ps_mask(w, big, _CMP_LE_OQ) & _mm512_cmp_ps_mask(nbig, w, _CMP_LE_OQ);
        const __m512 gxw = _mm512_mul_ps(gx, w), gyw = _mm512_mul_ps(gy, w);
        const __mmask16 out =
            _mm512_cmp_ps_mask(_mm512_add_ps(z, w), zero, _CMP_LT_OQ) |
            _mm512_cmp_ps_mask(_mm512_sub_ps(w, z), zero, _CMP_LT_OQ) |
            _mm512_cmp_ps_mask(_mm512_add_ps(gxw, x), zero, _CMP_LT_OQ) |
            _mm512_cmp_ps_mask(_mm512_sub_ps(gxw, x), zero, _CMP_LT_OQ) |
            _mm512_cmp_ps_mask(_mm512_add_ps(gyw, y), zero, _CMP_LT_OQ) |
            _mm512_cmp_ps_mask(_mm512_sub_ps(gyw, y), zero, _CMP_LT_OQ);
        const __mmask16 wpos = _mm512_cmp_ps_mask(w, zero, _CMP_GT_OQ);
        const __mmask16 special = (__mmask16)(~fin | out | ~wpos);
        /* snap_inl */
        const __m512 nx = _mm512_div_ps(x, w), ny = _mm512_div_ps(y, w);
        const __m512 sx = _mm512_mul_ps(_mm512_add_ps(_mm512_mul_ps(nx, half), half), fw);
        const __m512 sy = _mm512_mul_ps(_mm512_sub_ps(half, _mm512_mul_ps(ny, half)), fh);
        __m512i X = _mm512_cvtps_epi32(_mm512_min_ps(_mm512_max_ps(_mm512_mul_ps(sx, fix), lox), hix));
        const __m512i Y =
            _mm512_cvtps_epi32(_mm512_min_ps(_mm512_max_ps(_mm512_mul_ps(sy, fix), loy), hiy));
        X = _mm512_mask_blend_epi32(special, X, mark);
        int32_t *xy = vb->xy + 2 * (size_t)base;
        _mm512_store_si512((void *)xy, _mm512_permutex2var_epi32(X, ilo, Y));
        _mm512_store_si512((void *)(xy + 16), _mm512_permutex2var_epi32(X, ihi, Y));
        /* vert_zw, vert_iw in double */
        for (int h = 0; h < 2; h++) {
            const __m512d dz = _mm512_cvtps_pd(h ? _mm512_extractf32x8_ps(z, 1)
                                                 : _mm512_castps512_ps256(z));
            const __m512d dw = _mm512_cvtps_pd(h ? _mm512_extractf32x8_ps(w, 1)
                                                 : _mm512_castps512_ps256(w));
            _mm512_store_pd(vb->zw + base + 8 * h,
                            _mm512_add_pd(_mm512_mul_pd(_mm512_div_pd(dz, dw), dhalf), dhalf));
            _mm512_store_pd(vb->iw + base + 8 * h, _mm512_div_pd(done, dw));
        }
    }
}

/* Lane macros, the rejection helpers and raster_front.inl. */
#include "raster_front_avx512.inl"

/* The qwords p64[idx[l]] for the 16 lanes l: lanes 0..7 in p[0], 8..15
 * in p[1] (gather_pairs by scalar loads). */
static inline void load_pairs(const long long *p64, const uint32_t *idx, __m512i p[2])
{
    for (int h = 0; h < 2; h++) {
        const uint32_t *s = idx + 8 * h;
        const __m128i q0 = _mm_set_epi64x(p64[s[1]], p64[s[0]]);
        const __m128i q1 = _mm_set_epi64x(p64[s[3]], p64[s[2]]);
        const __m128i q2 = _mm_set_epi64x(p64[s[5]], p64[s[4]]);
        const __m128i q3 = _mm_set_epi64x(p64[s[7]], p64[s[6]]);
        const __m256i lo = _mm256_inserti128_si256(_mm256_castsi128_si256(q0), q1, 1);
        const __m256i hi = _mm256_inserti128_si256(_mm256_castsi128_si256(q2), q3, 1);
        p[h] = _mm512_inserti64x4(_mm512_castsi256_si512(lo), hi, 1);
    }
}

/* ---- survivor set-up ---------------------------------------------------- */

/* Sets up queue lanes 0 .. k-1 (k = 1..16) into their records. */
/* Micro lanes (clamped box at most 2x2 pixels): the covered pixels and,
 * for each of the box's four pixels (i, j), the scan's values: the clamped
 * depth z and the barycentrics b1, b2, computed per lane with the float
 * operations of rast__scan_rows_ref in its order (fi, fj are 0.0f or
 * 1.0f, multiplied as the scan multiplies them). cov[l]: bit i + 2j for
 * a covered pixel (the int64 edge test of the scan at that pixel). */
static inline unsigned micro_lanes(const squeue *q, __mmask16 L, const int64_t (*ec)[16],
                                   const int64_t (*edx)[16], const int64_t (*edy)[16],
                                   const float (*pl)[16], uint8_t *cov, float (*mz)[16],
                                   float (*mb1)[16], float (*mb2)[16])
{
    const __m512i one = _mm512_set1_epi32(1);
    const __m512i w1 = _mm512_sub_epi32(_mm512_load_si512((const void *)q->f[Q_BX1]),
                                        _mm512_load_si512((const void *)q->f[Q_BX0]));
    const __m512i h1 = _mm512_sub_epi32(_mm512_load_si512((const void *)q->f[Q_BY1]),
                                        _mm512_load_si512((const void *)q->f[Q_BY0]));
    const __mmask16 wide = _mm512_cmpeq_epi32_mask(w1, one);   /* 2 columns */
    const __mmask16 tall = _mm512_cmpeq_epi32_mask(h1, one);   /* 2 rows */
    const __mmask16 mic = L & _mm512_cmple_epi32_mask(w1, one) &
                          _mm512_cmple_epi32_mask(h1, one);
    if (!mic)
        return 0;
    /* Coverage: E = e_c + i*e_dx + j*e_dy, int64, at the four pixels. */
    __mmask16 cv[4];
    for (int p = 0; p < 4; p++)
        cv[p] = 0;
    for (int h = 0; h < 2; h++) {
        __m512i o[4] = { _mm512_setzero_si512(), _mm512_setzero_si512(),
                         _mm512_setzero_si512(), _mm512_setzero_si512() };
        for (int e = 0; e < 3; e++) {
            const __m512i c = _mm512_load_si512((const void *)&ec[e][8 * h]);
            const __m512i ex = _mm512_load_si512((const void *)&edx[e][8 * h]);
            const __m512i ey = _mm512_load_si512((const void *)&edy[e][8 * h]);
            const __m512i c01 = _mm512_add_epi64(c, ey);
            o[0] = _mm512_or_si512(o[0], c);
            o[1] = _mm512_or_si512(o[1], _mm512_add_epi64(c, ex));
            o[2] = _mm512_or_si512(o[2], c01);
            o[3] = _mm512_or_si512(o[3], _mm512_add_epi64(c01, ex));
        }
        for (int p = 0; p < 4; p++)
            cv[p] |= (__mmask16)((unsigned)(uint8_t)~_mm512_movepi64_mask(o[p]) << (8 * h));
    }
    cv[0] &= mic;
    cv[1] &= mic & wide;
    cv[2] &= mic & tall;
    cv[3] &= mic & wide & tall;
    const __mmask16 any = cv[0] | cv[1] | cv[2] | cv[3];
    if (!any)
        return mic;
    const __m512i bit = _mm512_set1_epi32(1);
    __m512i cb = _mm512_setzero_si512();
    for (int p = 0; p < 4; p++)
        cb = _mm512_mask_or_epi32(cb, cv[p], cb, _mm512_slli_epi32(bit, p));
    _mm_storeu_si128((__m128i *)(void *)cov, _mm512_cvtepi32_epi8(cb));
    /* The values (the scan's expressions; unused lanes compute garbage). */
    const __m512 zero = _mm512_setzero_ps(), fone = _mm512_set1_ps(1.0f);
    __m512 P[12];
    for (int i = 0; i < 12; i++)
        P[i] = _mm512_load_ps(pl[i]);
    for (int j = 0; j < 2; j++) {
        const __m512 fj = j ? fone : zero;
        const __m512 zr = _mm512_add_ps(P[0], _mm512_mul_ps(P[2], fj));
        const __m512 qr = _mm512_add_ps(P[3], _mm512_mul_ps(P[5], fj));
        const __m512 b1r = _mm512_add_ps(P[6], _mm512_mul_ps(P[8], fj));
        const __m512 b2r = _mm512_add_ps(P[9], _mm512_mul_ps(P[11], fj));
        for (int i = 0; i < 2; i++) {
            const int p = i + 2 * j;
            const __m512 fi = i ? fone : zero;
            __m512 z = _mm512_add_ps(zr, _mm512_mul_ps(P[1], fi));
            z = _mm512_max_ps(zero, z);
            z = _mm512_min_ps(fone, z);
            _mm512_store_ps(mz[p], z);
            const __m512 r = _mm512_div_ps(fone, _mm512_add_ps(qr, _mm512_mul_ps(P[4], fi)));
            _mm512_store_ps(mb1[p], _mm512_mul_ps(_mm512_add_ps(b1r, _mm512_mul_ps(P[7], fi)), r));
            _mm512_store_ps(mb2[p], _mm512_mul_ps(_mm512_add_ps(b2r, _mm512_mul_ps(P[10], fi)), r));
        }
    }
    return mic;
}

static void flush(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                  const squeue *q, int k, rast__tri *out, int micro)
{
    const __mmask16 L = k >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << k) - 1u);
    __m512i X[3], Y[3], V[3];
    for (int i = 0; i < 3; i++) {
        X[i] = _mm512_load_si512((const void *)q->f[Q_X0 + i]);
        Y[i] = _mm512_load_si512((const void *)q->f[Q_Y0 + i]);
        V[i] = _mm512_maskz_load_epi32(L, (const void *)q->f[Q_V0 + i]);
    }
    const __m512i bx0 = _mm512_load_si512((const void *)q->f[Q_BX0]);
    const __m512i by0 = _mm512_load_si512((const void *)q->f[Q_BY0]);
    const __m512i c128 = _mm512_set1_epi32(RAST__FIX_HALF);
    const __m512i cx = _mm512_add_epi32(_mm512_slli_epi32(bx0, RAST_SUBPIXEL_BITS), c128);
    const __m512i cy = _mm512_add_epi32(_mm512_slli_epi32(by0, RAST_SUBPIXEL_BITS), c128);

    /* setup_edges: edge e from vertex ea[e] to eb[e]. */
    _Alignas(64) int64_t ec[3][16], edx[3][16], edy[3][16];
    static const int ea[3] = { 1, 2, 0 }, eb[3] = { 2, 0, 1 };
    const __m512i one64 = _mm512_set1_epi64(1), zero = _mm512_setzero_si512();
    for (int e = 0; e < 3; e++) {
        const int a = ea[e], b = eb[e];
        const __m512i dx = _mm512_sub_epi32(X[b], X[a]), dy = _mm512_sub_epi32(Y[b], Y[a]);
        const __mmask16 tl = top_left(dx, dy);
        const __m512i oy = _mm512_sub_epi32(cy, Y[a]), ox = _mm512_sub_epi32(cx, X[a]);
        for (int h = 0; h < 2; h++) {
            const __m512i dx64 = _mm512_cvtepi32_epi64(half_i(dx, h));
            const __m512i dy64 = _mm512_cvtepi32_epi64(half_i(dy, h));
            const __m512i p1 = _mm512_mul_epi32(dx64, _mm512_cvtepi32_epi64(half_i(oy, h)));
            const __m512i p2 = _mm512_mul_epi32(dy64, _mm512_cvtepi32_epi64(half_i(ox, h)));
            const __m512i r = _mm512_sub_epi64(p1, p2);
            const __mmask8 bias = (__mmask8)~(tl >> (8 * h));
            _mm512_store_si512((void *)&ec[e][8 * h], _mm512_mask_sub_epi64(r, bias, r, one64));
            _mm512_store_si512((void *)&edx[e][8 * h],
                               _mm512_sub_epi64(zero, _mm512_slli_epi64(dy64, RAST_SUBPIXEL_BITS)));
            _mm512_store_si512((void *)&edy[e][8 * h], _mm512_slli_epi64(dx64, RAST_SUBPIXEL_BITS));
        }
    }

    /* planes_one per lane. */
    _Alignas(64) float pl[12][16];
    for (int h = 0; h < 2; h++)
        front_planes_half(X, Y, V, bx0, by0, (__mmask8)(L >> (8 * h)), h, vb, pl);

    /* The records: lane l -> out[slot l]. */
    _Alignas(64) uint8_t cov[16] = { 0 };
    _Alignas(64) float mz[4][16], mb1[4][16], mb2[4][16];
    const unsigned mic = micro ? micro_lanes(q, L, ec, edx, edy,
                                             (const float (*)[16])pl, cov, mz, mb1, mb2)
                               : 0u;

    const int ac = v->attr_count;
    const __mmask8 AM = (__mmask8)((1u << ac) - 1u);
    for (int l = 0; l < k; l++) {
        rast__tri *t;
        if ((mic >> l) & 1u) {
            t = out + q->f[Q_SLOT][l];
            t->micro = RAST__MICRO | cov[l];
            if (!cov[l])
                continue;
            t->x0 = q->f[Q_BX0][l];
            t->y0 = q->f[Q_BY0][l];
            t->x1 = q->f[Q_BX1][l];
            t->y1 = q->f[Q_BY1][l];
            t->attr_count = ac;
            for (int p = 0; p < 4; p++) {
                t->mz[p] = mz[p][l];
                t->mb1[p] = mb1[p][l];
                t->mb2[p] = mb2[p][l];
            }
        } else {
            t = front_record(q, l, ec, edx, edy, pl, ac, out);
        }
        /* setup_attrs: a0 = attribute of vertex 0, d1 = a1 - a0,
         * d2 = a2 - a0, per record by masked loads (no byte past the
         * vertex's ac floats is read) and masked stores (no byte past
         * a0[ac - 1], d1[ac - 1], d2[ac - 1] is written). */
        if (ac > 0) {
            const float *a0p = m->attr + (size_t)q->f[Q_V0][l] * (size_t)ac;
            const float *a1p = m->attr + (size_t)q->f[Q_V1][l] * (size_t)ac;
            const float *a2p = m->attr + (size_t)q->f[Q_V2][l] * (size_t)ac;
            const __m256 a0 = _mm256_maskz_loadu_ps(AM, a0p);
            const __m256 a1 = _mm256_maskz_loadu_ps(AM, a1p);
            const __m256 a2 = _mm256_maskz_loadu_ps(AM, a2p);
            _mm256_mask_storeu_ps(t->a0, AM, a0);
            _mm256_mask_storeu_ps(t->d1, AM, _mm256_sub_ps(a1, a0));
            _mm256_mask_storeu_ps(t->d2, AM, _mm256_sub_ps(a2, a0));
        }
    }
}

_Static_assert(RAST__FRONT_GROUP == 16, "one group per 16-lane vector");
_Static_assert(RAST_MAX_ATTRS <= 8, "attributes by 8-lane masked loads and stores");

int rast__frontv_avx512(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                        int ti0, int ti1, rast__tri *out, rast_stats *st, int micro)
{
    rast_stats ls = *st;
    squeue q;
    q.n = 0;
    int n = 0;
    const long long *xyb = (const long long *)(const void *)vb->xy;
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i mark = _mm512_set1_epi32(RAST__VX_SPECIAL);
    const __m512i zero = _mm512_setzero_si512();
    const int vw = v->width, vh = v->height;   /* kept in registers */
    for (int ti = ti0; ti < ti1; ti += 16) {
        const int cnt = ti1 - ti < 16 ? ti1 - ti : 16;
        const unsigned L = cnt == 16 ? 0xFFFFu : (1u << cnt) - 1u;
        /* Indices of the group, de-interleaved (lanes past cnt: vertex 0). */
        const uint32_t *ix = m->indices + 3 * (size_t)ti;
        const int ne = 3 * cnt;
        __m512i iw3[3];
        for (int i = 0; i < 3; i++) {
            const int left = ne - 16 * i;
            iw3[i] = left >= 16 ? _mm512_loadu_si512((const void *)(ix + 16 * i))
                     : left > 0 ? _mm512_maskz_loadu_epi32((__mmask16)((1u << left) - 1u),
                                                           (const void *)(ix + 16 * i))
                                : zero;
        }
        __m512i iv[3], X[3], Y[3];
        deint_tris(iw3[0], iw3[1], iw3[2], iv);
        __mmask16 spec = 0;
        /* (X, Y) pairs: one 64-bit load per vertex, by scalar loads
         * (faster than vpgatherdq on Zen 4: 0.95-0.97 of the whole draw's
         * time at 41k triangles, 0.97-0.99 at 10k, in one process). */
        _Alignas(64) uint32_t ivs[3][16];
        for (int k = 0; k < 3; k++)
            _mm512_store_si512((void *)ivs[k], iv[k]);
        for (int k = 0; k < 3; k++) {
            __m512i p[2];
            load_pairs(xyb, ivs[k], p);
            X[k] = pairs_lo(p);
            Y[k] = pairs_hi(p);
            spec |= _mm512_cmpeq_epi32_mask(X[k], mark);
        }
        const unsigned special0 = spec & L;
        /* prepare_cached_one: area sign, degenerate, culling. */
        unsigned pos, neg;
        front_area_signs(X, Y, &pos, &neg);
        const front_class c = front_classify(m->cull, L & ~special0, pos, neg);
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
        const __mmask16 sw = (__mmask16)neg;
        const __m512i x1 = _mm512_mask_blend_epi32(sw, X[1], X[2]);
        const __m512i x2 = _mm512_mask_blend_epi32(sw, X[2], X[1]);
        const __m512i y1 = _mm512_mask_blend_epi32(sw, Y[1], Y[2]);
        const __m512i y2 = _mm512_mask_blend_epi32(sw, Y[2], Y[1]);
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
        /* Record slots in submission order; special triangles through the
         * scalar path at their place. */
        __m512i slot;
        if (special) {
            _Alignas(64) int32_t sl[16] = { 0 };
            n = front_slots(v, m, ti, special, surv, out, n, &ls, sl);
            slot = _mm512_maskz_compress_epi32((__mmask16)surv,
                                               _mm512_load_si512((const void *)sl));
        } else {
            slot = _mm512_add_epi32(_mm512_set1_epi32(n), iota);
            n += __builtin_popcount(surv);
        }
        if (!surv)
            continue;
        const __mmask16 sv = (__mmask16)surv;
        const __m512i vi1 = _mm512_mask_blend_epi32(sw, iv[1], iv[2]);
        const __m512i vi2 = _mm512_mask_blend_epi32(sw, iv[2], iv[1]);
        const __m512i fld[Q_FIELDS] = { X[0], x1, x2, Y[0], y1, y2, iv[0], vi1, vi2,
                                        b.bx0, b.by0, b.bx1, b.by1, slot };
        for (int f = 0; f < Q_SLOT; f++)
            _mm512_storeu_si512((void *)(q.f[f] + q.n), _mm512_maskz_compress_epi32(sv, fld[f]));
        _mm512_storeu_si512((void *)(q.f[Q_SLOT] + q.n), slot);
        q.n += __builtin_popcount(surv);
        if (q.n >= 16) {
            flush(v, m, vb, &q, 16, out, micro);
            q.n -= 16;
            for (int f = 0; f < Q_FIELDS; f++)
                _mm512_store_si512((void *)q.f[f], _mm512_load_si512((const void *)(q.f[f] + 16)));
        }
    }
    if (q.n)
        flush(v, m, vb, &q, q.n, out, micro);
    *st = ls;
    return n;
}

#else
typedef int rast__front_avx512_unused;   /* not an x86 build */
#endif
