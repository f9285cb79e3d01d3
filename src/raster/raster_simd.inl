/* raster_simd.inl - the SIMD scan body shared by raster_sse2.c,
 * raster_avx2.c and raster_avx512.c. Each includes this file once after
 * defining the lane macros below; the body then gives exactly the bytes of
 * rast__scan_rows_ref (raster_ref.c): the same integer coverage test and,
 * per lane, the same IEEE float operations in the same order.
 *
 * Lane macros (bits = unsigned, bit l for lane l):
 *   SIMD_V                 lanes (4, 8 or 16)
 *   SIMD_FN                name of the exported row scan
 *   vf, vi                 float and int32 vector types
 *   VF_SET1 VF_ADD VF_MUL VF_DIV   one IEEE op per lane
 *   VF_MAX(a, b), VF_MIN(a, b)     a > b ? a : b and a < b ? a : b (the
 *                          x86 semantics; used as max(0, z), min(1, z),
 *                          which equal the reference's selects, -0.0 and
 *                          NaN included)
 *   VF_CVT(vi)             int32 -> float (exact here: |i| < 2^24)
 *   VI_SET1 VI_ADD VI_OR VI_LOADU(p)
 *   VI_NEG_BITS(v)         lanes whose sign bit is set
 *   VF_LT_BITS(a, b)       lanes with a < b (ordered)
 *   VF_LOAD_M(p, bits, full)       load the lanes in bits (full: all);
 *                          other lanes are not accessed (value: anything)
 *   VF_STORE_M(p, bits, full, v)   store the lanes in bits
 *   MASK_STORE_M(p, bits, full)    write 255 to the bytes in bits
 *   VF_STOREA(p, v)        store to a SIMD_V-float aligned array
 * Optional:
 *   ATTR3_STORE_FULL(p, a0, a1, a2)  interleave three attribute vectors of
 *                          SIMD_V pixels into p[3*SIMD_V] (all lanes).
 *
 * COVERAGE. The reference tests E >= 0 with int64 E stepped by multiples of
 * 256 (e_dx = -dy*256, e_dy = dx*256). Since floor((E + 256k)/256) =
 * floor(E/256) + k and E >= 0 <=> floor(E/256) >= 0, the body tests the
 * reduced value E' = floor(E/256) stepped by -dy and dx, the same sign for
 * every pixel. Bounds: |dx|, |dy| < 2^23 (docs/raster.md section 2).
 *   * Fast path (int32 throughout): when E' at the four corners of the
 *     scanned rows x [0, nvec*SIMD_V) lies in (-2^30, 2^30), every value
 *     in that rectangle does (E' is affine), and so does every difference
 *     used as a step (< 2^31): int32 adds give the exact integers.
 *   * Otherwise (huge triangles, vertices far in the guard band): E' of the
 *     first lane of each vector is computed in int64 and clamped to
 *     [-2^29, 2^29] before adding the lane offsets l*(-dy), |l*dy| <
 *     15 * 2^23 < 2^27. A clamped value keeps its sign, and so does every
 *     lane: 2^29 - 2^27 > 0. Lanes with an unclamped start are exact.
 */

#define SIMD_FULL ((1u << SIMD_V) - 1u)
#define SIMD_LIM30 ((int64_t)(1 << 30) - 1)
#define SIMD_LIM29 ((int64_t)1 << 29)

/* floor(a / 256) for any sign (no reliance on >> of negative values). */
static inline int64_t simd_floor256(int64_t a)
{
    int64_t q = a / 256;
    return (a % 256 != 0 && a < 0) ? q - 1 : q;
}

static inline int32_t simd_clamp29(int64_t a)
{
    return (int32_t)(a < -SIMD_LIM29 ? -SIMD_LIM29 : a > SIMD_LIM29 ? SIMD_LIM29 : a);
}

long SIMD_FN(const rast_target *t, const rast__tri *tri, int ya, int yb)
{
    const int ys = ya > tri->y0 ? ya : tri->y0;
    const int ye = yb < tri->y1 ? yb : tri->y1;
    if (ys > ye)
        return 0;
    const int na = t->attr ? tri->attr_count : 0;
    const int nx = tri->x1 - tri->x0 + 1;
    const int nvec = (nx + SIMD_V - 1) / SIMD_V;
    const int64_t rows = ye - ys;

    /* Reduced edges, relative to (x0, ys). */
    int64_t c[3], sx[3], sy[3];
    int fits = 1;
    for (int k = 0; k < 3; k++) {
        c[k] = simd_floor256(tri->e_c[k] + (int64_t)(ys - tri->y0) * tri->e_dy[k]);
        sx[k] = tri->e_dx[k] / 256;     /* exact: multiples of 256 */
        sy[k] = tri->e_dy[k] / 256;
        for (int cj = 0; cj < 2; cj++)
            for (int ci = 0; ci < 2; ci++) {
                int64_t v = c[k] + cj * rows * sy[k] +
                            ci * ((int64_t)nvec * SIMD_V - 1) * sx[k];
                if (v < -SIMD_LIM30 || v > SIMD_LIM30)
                    fits = 0;
            }
    }
    _Alignas(64) int32_t off[3][SIMD_V], lane[SIMD_V];
    for (int l = 0; l < SIMD_V; l++) {
        lane[l] = l;
        for (int k = 0; k < 3; k++)
            off[k][l] = (int32_t)(l * sx[k]);
    }
    const vi lanev = VI_LOADU(lane);
    const vi off0 = VI_LOADU(off[0]), off1 = VI_LOADU(off[1]), off2 = VI_LOADU(off[2]);
    /* Vector step; only used (and only in range) when nvec > 1. */
    const vi st0 = VI_SET1(fits && nvec > 1 ? (int32_t)(SIMD_V * sx[0]) : 0);
    const vi st1 = VI_SET1(fits && nvec > 1 ? (int32_t)(SIMD_V * sx[1]) : 0);
    const vi st2 = VI_SET1(fits && nvec > 1 ? (int32_t)(SIMD_V * sx[2]) : 0);

    const vf zero = VF_SET1(0.0f), one = VF_SET1(1.0f);
    const vf zdx = VF_SET1(tri->z.dx), qdx = VF_SET1(tri->q.dx);
    const vf b1dx = VF_SET1(tri->b1.dx), b2dx = VF_SET1(tri->b2.dx);
    vf av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
    for (int k = 0; k < na; k++) {
        av0[k] = VF_SET1(tri->a0[k]);
        av1[k] = VF_SET1(tri->d1[k]);
        av2[k] = VF_SET1(tri->d2[k]);
    }

    long written = 0;
    int64_t rb[3] = { c[0], c[1], c[2] };
    for (int y = ys; y <= ye; y++) {
        /* Row bases: the reference's scalar expressions. */
        const float fj = (float)(y - tri->y0);
        const float zr = tri->z.c + tri->z.dy * fj;
        const float qr = tri->q.c + tri->q.dy * fj;
        const float b1r = tri->b1.c + tri->b1.dy * fj;
        const float b2r = tri->b2.c + tri->b2.dy * fj;
        const vf zrv = VF_SET1(zr);
        uint8_t *mrow = t->mask + (size_t)y * (size_t)t->mask_stride;
        float *drow = t->depth ? t->depth + (size_t)y * (size_t)t->depth_stride
                               : NULL;
        float *arow = na ? t->attr + (size_t)y * (size_t)t->attr_stride : NULL;
        vi e0 = lanev, e1 = lanev, e2 = lanev;
        if (fits) {
            e0 = VI_ADD(VI_SET1((int32_t)rb[0]), off0);
            e1 = VI_ADD(VI_SET1((int32_t)rb[1]), off1);
            e2 = VI_ADD(VI_SET1((int32_t)rb[2]), off2);
        }
        int64_t eb0 = rb[0], eb1 = rb[1], eb2 = rb[2];
        for (int v = 0; v < nvec; v++) {
            const int i0 = v * SIMD_V;
            const int x = tri->x0 + i0;
            const int rem = nx - i0;
            const unsigned valid = rem >= SIMD_V ? SIMD_FULL : (1u << rem) - 1u;
            unsigned neg;
            if (fits) {
                neg = VI_NEG_BITS(VI_OR(VI_OR(e0, e1), e2));
                e0 = VI_ADD(e0, st0);
                e1 = VI_ADD(e1, st1);
                e2 = VI_ADD(e2, st2);
            } else {
                const vi t0 = VI_ADD(VI_SET1(simd_clamp29(eb0)), off0);
                const vi t1 = VI_ADD(VI_SET1(simd_clamp29(eb1)), off1);
                const vi t2 = VI_ADD(VI_SET1(simd_clamp29(eb2)), off2);
                neg = VI_NEG_BITS(VI_OR(VI_OR(t0, t1), t2));
                eb0 += SIMD_V * sx[0];
                eb1 += SIMD_V * sx[1];
                eb2 += SIMD_V * sx[2];
            }
            const unsigned cov = ~neg & valid;
            if (!cov)
                continue;
            const vf fi = VF_CVT(VI_ADD(VI_SET1(i0), lanev));
            vf z = VF_ADD(zrv, VF_MUL(zdx, fi));
            z = VF_MAX(zero, z);
            z = VF_MIN(one, z);
            unsigned pass = cov;
            if (drow) {
                const vf d = VF_LOAD_M(drow + x, cov, cov == SIMD_FULL);
                pass = cov & VF_LT_BITS(z, d);
                if (!pass)
                    continue;
                VF_STORE_M(drow + x, pass, pass == SIMD_FULL, z);
            }
            MASK_STORE_M(mrow + x, pass, pass == SIMD_FULL);
            written += __builtin_popcount(pass);
            if (!na)
                continue;
            const vf r = VF_DIV(one, VF_ADD(VF_SET1(qr), VF_MUL(qdx, fi)));
            const vf b1 = VF_MUL(VF_ADD(VF_SET1(b1r), VF_MUL(b1dx, fi)), r);
            const vf b2 = VF_MUL(VF_ADD(VF_SET1(b2r), VF_MUL(b2dx, fi)), r);
            float *dst = arow + (size_t)x * (size_t)na;
#ifdef ATTR3_STORE_FULL
            if (na == 3 && pass == SIMD_FULL) {
                ATTR3_STORE_FULL(dst,
                    VF_ADD(VF_ADD(av0[0], VF_MUL(b1, av1[0])), VF_MUL(b2, av2[0])),
                    VF_ADD(VF_ADD(av0[1], VF_MUL(b1, av1[1])), VF_MUL(b2, av2[1])),
                    VF_ADD(VF_ADD(av0[2], VF_MUL(b1, av1[2])), VF_MUL(b2, av2[2])));
                continue;
            }
#endif
            _Alignas(64) float a[RAST_MAX_ATTRS][SIMD_V];
            for (int k = 0; k < na; k++)
                VF_STOREA(a[k], VF_ADD(VF_ADD(av0[k], VF_MUL(b1, av1[k])),
                                       VF_MUL(b2, av2[k])));
            for (unsigned bits = pass; bits; bits &= bits - 1) {
                const int l = __builtin_ctz(bits);
                float *p = dst + (size_t)l * (size_t)na;
                for (int k = 0; k < na; k++)
                    p[k] = a[k][l];
            }
        }
        rb[0] += sy[0];
        rb[1] += sy[1];
        rb[2] += sy[2];
    }
    return written;
}
