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
 *                 double, culling, clamped box, empty one-pixel boxes);
 *   set-up        setup_edges (int64 edges by vpmuldq), planes_one (the
 *                 double plane set-up, as raster_planes.inl), setup_attrs.
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

/* ---- rejection ---------------------------------------------------------- */

/* lane l = element idx[l] of the 48 indices a | b | c (idx < 48). */
static inline __m512i deint(__m512i a, __m512i b, __m512i c, __m512i idx)
{
    const __mmask16 hi = _mm512_cmpge_epi32_mask(idx, _mm512_set1_epi32(32));
    return _mm512_mask_permutexvar_epi32(_mm512_permutex2var_epi32(a, idx, b), hi, idx, c);
}

/* Lanes with a*b > c*d (gt) or a*b < c*d (!gt), exact in double
 * (|a|, |b|, |c|, |d| < 2^23). */
static inline unsigned prod_cmp(__m512i a, __m512i b, __m512i c, __m512i d, int gt)
{
    unsigned r = 0;
    for (int h = 0; h < 2; h++) {
        const __m256i ah = h ? _mm512_extracti32x8_epi32(a, 1) : _mm512_castsi512_si256(a);
        const __m256i bh = h ? _mm512_extracti32x8_epi32(b, 1) : _mm512_castsi512_si256(b);
        const __m256i ch = h ? _mm512_extracti32x8_epi32(c, 1) : _mm512_castsi512_si256(c);
        const __m256i dh = h ? _mm512_extracti32x8_epi32(d, 1) : _mm512_castsi512_si256(d);
        const __m512d p1 = _mm512_mul_pd(_mm512_cvtepi32_pd(ah), _mm512_cvtepi32_pd(bh));
        const __m512d p2 = _mm512_mul_pd(_mm512_cvtepi32_pd(ch), _mm512_cvtepi32_pd(dh));
        r |= (unsigned)_mm512_cmp_pd_mask(p1, p2, gt ? _CMP_GT_OQ : _CMP_LT_OQ) << (8 * h);
    }
    return r;
}

/* Top-left bias mask of the edges with deltas dx, dy: lanes that keep
 * E == 0 (dy < 0, or dy == 0 and dx > 0). */
static inline __mmask16 top_left(__m512i dx, __m512i dy)
{
    const __m512i zero = _mm512_setzero_si512();
    return _mm512_cmplt_epi32_mask(dy, zero) |
           (_mm512_cmpeq_epi32_mask(dy, zero) & _mm512_cmpgt_epi32_mask(dx, zero));
}

/* Biased edge value from a to b at (cx, cy) in int32 (one-pixel boxes:
 * differences below 512, products below 2^18). */
static inline __m512i edge32(__m512i xa, __m512i ya, __m512i xb, __m512i yb, __m512i cx,
                             __m512i cy)
{
    const __m512i dx = _mm512_sub_epi32(xb, xa), dy = _mm512_sub_epi32(yb, ya);
    const __m512i e = _mm512_sub_epi32(_mm512_mullo_epi32(dx, _mm512_sub_epi32(cy, ya)),
                                       _mm512_mullo_epi32(dy, _mm512_sub_epi32(cx, xa)));
    return _mm512_mask_sub_epi32(e, (__mmask16)~top_left(dx, dy), e, _mm512_set1_epi32(1));
}

/* ---- survivor queue and set-up ------------------------------------------ */

/* Survivors waiting for their set-up, one int32 per lane and field:
 * oriented (area > 0) snapped positions and vertex indices, the clamped
 * pixel box and the record's index in out. */
enum { Q_X0, Q_X1, Q_X2, Q_Y0, Q_Y1, Q_Y2, Q_V0, Q_V1, Q_V2, Q_BX0, Q_BY0, Q_BX1, Q_BY1,
       Q_SLOT, Q_FIELDS };
typedef struct squeue {
    int n;
    _Alignas(64) int32_t f[Q_FIELDS][32];
} squeue;

static inline __m256i half_i(__m512i v, int h)
{
    return h ? _mm512_extracti32x8_epi32(v, 1) : _mm512_castsi512_si256(v);
}

/* The double operations of planes_one for one plane, 8 lanes
 * (raster_planes.inl, planes_lane). */
static inline void plane8(__m512d f0, __m512d f1, __m512d f2, __m512d ex1, __m512d ey1,
                          __m512d ex2, __m512d ey2, __m512d ox, __m512d oy, __m512d area,
                          float *c, float *gxo, float *gyo)
{
    const __m512d df1 = _mm512_sub_pd(f1, f0), df2 = _mm512_sub_pd(f2, f0);
    const __m512d gx = _mm512_div_pd(
        _mm512_sub_pd(_mm512_mul_pd(df1, ey2), _mm512_mul_pd(df2, ey1)), area);
    const __m512d gy = _mm512_div_pd(
        _mm512_sub_pd(_mm512_mul_pd(df2, ex1), _mm512_mul_pd(df1, ex2)), area);
    const __m512d cc = _mm512_add_pd(_mm512_add_pd(f0, _mm512_mul_pd(gx, ox)),
                                     _mm512_mul_pd(gy, oy));
    _mm256_store_ps(c, _mm512_cvtpd_ps(cc));
    _mm256_store_ps(gxo, _mm512_cvtpd_ps(gx));
    _mm256_store_ps(gyo, _mm512_cvtpd_ps(gy));
}

/* Sets up queue lanes 0 .. k-1 (k = 1..16) into their records. */
static void flush(const rast__view *v, const rast_mesh_desc *m, const rast__vbuf *vb,
                  const squeue *q, int k, rast__tri *out)
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
    const __m512d inv256 = _mm512_set1_pd(1.0 / RAST__FIX_ONE), dzero = _mm512_setzero_pd();
    const __m512d dhalf = _mm512_set1_pd(0.5), done = _mm512_set1_pd(1.0);
    for (int h = 0; h < 2; h++) {
        const __mmask8 lh = (__mmask8)(L >> (8 * h));
        __m512d Xd[3], Yd[3], zw[3], iw[3];
        for (int i = 0; i < 3; i++) {
            /* (double)X / 256: exact, as a multiplication by 2^-8 */
            Xd[i] = _mm512_mul_pd(_mm512_cvtepi32_pd(half_i(X[i], h)), inv256);
            Yd[i] = _mm512_mul_pd(_mm512_cvtepi32_pd(half_i(Y[i], h)), inv256);
            const __m256i vi = half_i(V[i], h);
            zw[i] = _mm512_mask_i32gather_pd(dzero, lh, vi, vb->zw, 8);
            iw[i] = _mm512_mask_i32gather_pd(done, lh, vi, vb->iw, 8);
        }
        const __m512d ex1 = _mm512_sub_pd(Xd[1], Xd[0]), ey1 = _mm512_sub_pd(Yd[1], Yd[0]);
        const __m512d ex2 = _mm512_sub_pd(Xd[2], Xd[0]), ey2 = _mm512_sub_pd(Yd[2], Yd[0]);
        /* |snapped area| / 65536: both products and the difference are
         * exact (below 2^46 and 2^47 in 1/65536 units), so this is the
         * scalar (double)area / 65536. Unused lanes: 1. */
        const __m512d area = _mm512_mask_blend_pd(
            lh, done, _mm512_sub_pd(_mm512_mul_pd(ex1, ey2), _mm512_mul_pd(ey1, ex2)));
        const __m512d ocx = _mm512_add_pd(_mm512_cvtepi32_pd(half_i(bx0, h)), dhalf);
        const __m512d ocy = _mm512_add_pd(_mm512_cvtepi32_pd(half_i(by0, h)), dhalf);
        const __m512d ox = _mm512_sub_pd(ocx, Xd[0]), oy = _mm512_sub_pd(ocy, Yd[0]);
        const __m512d qmax =
            _mm512_max_pd(iw[2], _mm512_max_pd(iw[1], _mm512_max_pd(iw[0], dzero)));
        const __m512d q0 = _mm512_div_pd(iw[0], qmax), q1 = _mm512_div_pd(iw[1], qmax),
                      q2 = _mm512_div_pd(iw[2], qmax);
        const int o = 8 * h;
        plane8(zw[0], zw[1], zw[2], ex1, ey1, ex2, ey2, ox, oy, area, pl[0] + o, pl[1] + o,
               pl[2] + o);
        plane8(q0, q1, q2, ex1, ey1, ex2, ey2, ox, oy, area, pl[3] + o, pl[4] + o, pl[5] + o);
        plane8(dzero, q1, dzero, ex1, ey1, ex2, ey2, ox, oy, area, pl[6] + o, pl[7] + o,
               pl[8] + o);
        plane8(dzero, dzero, q2, ex1, ey1, ex2, ey2, ox, oy, area, pl[9] + o, pl[10] + o,
               pl[11] + o);
    }

    /* The records: lane l -> out[slot l]. */
    const int ac = v->attr_count;
    const __mmask8 AM = (__mmask8)((1u << ac) - 1u);
    for (int l = 0; l < k; l++) {
        rast__tri *t = out + q->f[Q_SLOT][l];
        t->x0 = q->f[Q_BX0][l];
        t->y0 = q->f[Q_BY0][l];
        t->x1 = q->f[Q_BX1][l];
        t->y1 = q->f[Q_BY1][l];
        for (int e = 0; e < 3; e++) {
            t->e_c[e] = ec[e][l];
            t->e_dx[e] = edx[e][l];
            t->e_dy[e] = edy[e][l];
        }
        t->z.c = pl[0][l];
        t->z.dx = pl[1][l];
        t->z.dy = pl[2][l];
        t->q.c = pl[3][l];
        t->q.dx = pl[4][l];
        t->q.dy = pl[5][l];
        t->b1.c = pl[6][l];
        t->b1.dx = pl[7][l];
        t->b1.dy = pl[8][l];
        t->b2.c = pl[9][l];
        t->b2.dx = pl[10][l];
        t->b2.dy = pl[11][l];
        t->attr_count = ac;
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
                        int ti0, int ti1, rast__tri *out, rast_stats *st)
{
    rast_stats ls = *st;
    squeue q;
    q.n = 0;
    int n = 0;
    const long long *xyb = (const long long *)(const void *)vb->xy;
    const __m512i l3 = _mm512_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33, 36, 39,
                                         42, 45);
    const __m512i one = _mm512_set1_epi32(1), two = _mm512_set1_epi32(2);
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26,
                                           28, 30);
    const __m512i odd = _mm512_add_epi32(even, one);
    const __m512i mark = _mm512_set1_epi32(RAST__VX_SPECIAL);
    const __m512i zero = _mm512_setzero_si512();
    const __m512i c127 = _mm512_set1_epi32(RAST__FIX_ONE - 1 - RAST__FIX_HALF);
    const __m512i c128 = _mm512_set1_epi32(RAST__FIX_HALF);
    const __m512i wmax = _mm512_set1_epi32(v->width - 1), hmax = _mm512_set1_epi32(v->height - 1);
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
        iv[0] = deint(iw3[0], iw3[1], iw3[2], l3);
        iv[1] = deint(iw3[0], iw3[1], iw3[2], _mm512_add_epi32(l3, one));
        iv[2] = deint(iw3[0], iw3[1], iw3[2], _mm512_add_epi32(l3, two));
        /* (X, Y) pairs: one 64-bit gather element per vertex. */
        __mmask16 spec = 0;
        for (int k = 0; k < 3; k++) {
            const __m512i p0 = _mm512_i32gather_epi64(half_i(iv[k], 0), xyb, 8);
            const __m512i p1 = _mm512_i32gather_epi64(half_i(iv[k], 1), xyb, 8);
            X[k] = _mm512_permutex2var_epi32(p0, even, p1);
            Y[k] = _mm512_permutex2var_epi32(p0, odd, p1);
            spec |= _mm512_cmpeq_epi32_mask(X[k], mark);
        }
        const unsigned special0 = spec & L;
        const unsigned valid = L & ~special0;
        /* prepare_cached_one: area sign, degenerate, culling. */
        const __m512i dx1 = _mm512_sub_epi32(X[1], X[0]), dy1 = _mm512_sub_epi32(Y[1], Y[0]);
        const __m512i dx2 = _mm512_sub_epi32(X[2], X[0]), dy2 = _mm512_sub_epi32(Y[2], Y[0]);
        const unsigned pos = prod_cmp(dx1, dy2, dy1, dx2, 1);
        const unsigned neg = prod_cmp(dx1, dy2, dy1, dx2, 0);
        const unsigned cullm =
            m->cull == RAST_CULL_BACK ? pos : m->cull == RAST_CULL_FRONT ? neg : 0u;
        const unsigned degen = valid & ~(pos | neg);
        const unsigned culled = valid & cullm & (pos | neg);
        const unsigned live = valid & (pos | neg) & ~cullm;
        /* setup_box_edges: the clamped pixel box, off screen, empty. */
        const __m512i xmin = _mm512_min_epi32(X[0], _mm512_min_epi32(X[1], X[2]));
        const __m512i xmax = _mm512_max_epi32(X[0], _mm512_max_epi32(X[1], X[2]));
        const __m512i ymin = _mm512_min_epi32(Y[0], _mm512_min_epi32(Y[1], Y[2]));
        const __m512i ymax = _mm512_max_epi32(Y[0], _mm512_max_epi32(Y[1], Y[2]));
        const __m512i rx0 = _mm512_srai_epi32(_mm512_add_epi32(xmin, c127), RAST_SUBPIXEL_BITS);
        const __m512i rx1 = _mm512_srai_epi32(_mm512_sub_epi32(xmax, c128), RAST_SUBPIXEL_BITS);
        const __m512i ry0 = _mm512_srai_epi32(_mm512_add_epi32(ymin, c127), RAST_SUBPIXEL_BITS);
        const __m512i ry1 = _mm512_srai_epi32(_mm512_sub_epi32(ymax, c128), RAST_SUBPIXEL_BITS);
        const __m512i bx0 = _mm512_max_epi32(rx0, zero), by0 = _mm512_max_epi32(ry0, zero);
        const __m512i bx1 = _mm512_min_epi32(rx1, wmax), by1 = _mm512_min_epi32(ry1, hmax);
        const unsigned off =
            _mm512_cmpgt_epi32_mask(bx0, bx1) | _mm512_cmpgt_epi32_mask(by0, by1);
        /* A box of one pixel after clamping but not before (a triangle
         * across the border): the empty test needs int64 edges there, so
         * the (rare) lane takes the scalar path, which counts it. */
        const unsigned csingle = live & ~off & _mm512_cmpeq_epi32_mask(bx0, bx1) &
                                 _mm512_cmpeq_epi32_mask(by0, by1);
        const unsigned usingle =
            _mm512_cmpeq_epi32_mask(rx0, rx1) & _mm512_cmpeq_epi32_mask(ry0, ry1);
        const unsigned odd = csingle & ~usingle;
        const unsigned special = special0 | odd;
        const unsigned live2 = live & ~off & ~odd;
        /* Winding normalised (vertices 1 and 2 swapped where area < 0). */
        const __mmask16 sw = (__mmask16)neg;
        const __m512i x1 = _mm512_mask_blend_epi32(sw, X[1], X[2]);
        const __m512i x2 = _mm512_mask_blend_epi32(sw, X[2], X[1]);
        const __m512i y1 = _mm512_mask_blend_epi32(sw, Y[1], Y[2]);
        const __m512i y2 = _mm512_mask_blend_epi32(sw, Y[2], Y[1]);
        unsigned empty = 0;
        /* one pixel before clamping: differences below 512, int32 edges */
        const unsigned single = csingle & usingle;
        if (single) {
            const __m512i cx = _mm512_add_epi32(_mm512_slli_epi32(bx0, RAST_SUBPIXEL_BITS), c128);
            const __m512i cy = _mm512_add_epi32(_mm512_slli_epi32(by0, RAST_SUBPIXEL_BITS), c128);
            const __m512i e0 = edge32(x1, y1, x2, y2, cx, cy);
            const __m512i e1 = edge32(x2, y2, X[0], Y[0], cx, cy);
            const __m512i e2 = edge32(X[0], Y[0], x1, y1, cx, cy);
            empty = single & _mm512_movepi32_mask(_mm512_or_si512(_mm512_or_si512(e0, e1), e2));
        }
        const unsigned surv = live2 & ~empty;
        ls.tris_degenerate += __builtin_popcount(degen);
        ls.tris_culled += __builtin_popcount(culled);
        ls.tris_clipped_away += __builtin_popcount(live & off);
        ls.tris_drawn += __builtin_popcount(live2);   /* survivors and empty ones */
        if (!surv && !special)
            continue;
        /* Record slots in submission order; special triangles through the
         * scalar path at their place. */
        __m512i slot;
        if (special) {
            _Alignas(64) int32_t sl[16] = { 0 };
            for (unsigned bits = special | surv; bits; bits &= bits - 1) {
                const int l = __builtin_ctz(bits);
                if ((special >> l) & 1u)
                    n += rast__prepare(v, m, ti + l, out + n, &ls);
                else
                    sl[l] = n++;
            }
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
                                        bx0, by0, bx1, by1, slot };
        for (int f = 0; f < Q_SLOT; f++)
            _mm512_storeu_si512((void *)(q.f[f] + q.n), _mm512_maskz_compress_epi32(sv, fld[f]));
        _mm512_storeu_si512((void *)(q.f[Q_SLOT] + q.n), slot);
        q.n += __builtin_popcount(surv);
        if (q.n >= 16) {
            flush(v, m, vb, &q, 16, out);
            q.n -= 16;
            for (int f = 0; f < Q_FIELDS; f++)
                _mm512_store_si512((void *)q.f[f], _mm512_load_si512((const void *)(q.f[f] + 16)));
        }
    }
    if (q.n)
        flush(v, m, vb, &q, q.n, out);
    *st = ls;
    return n;
}

#else
typedef int rast__front_avx512_unused;   /* not an x86 build */
#endif
