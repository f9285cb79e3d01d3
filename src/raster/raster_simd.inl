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
 *   VI_LANES()             the vector 0, 1, ..., SIMD_V-1
 *   VI_LANE_MUL(lanes, s)  lane l = l * s (int32; |l*s| < 2^27 here)
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
 *   ATTR3_STORE_M(p, bits, lanes, a0, a1, a2)  the same for the pixels in
 *                          bits only (no other float is accessed); bits lie
 *                          in the first `lanes` lanes (the box width of a
 *                          one-vector row, the lanes left in a wider one),
 *                          so the outputs needed are known per triangle.
 *   ATTR3_STATE, ATTR3_PREP(st, tri, lanes), ATTR3_STORE_P(p, bits, st, b1, b2)
 *                          three attributes of a one-vector row from the
 *                          pixels' barycentrics b1, b2: PREP fills the
 *                          per-triangle state *st (rows at most `lanes`
 *                          pixels), STORE_P writes the pixels in bits of
 *                          p[3*lanes] as (a0 + b1*d1) + b2*d2 per float.
 *   ATTR3_STORE_PL(p, bits, lanes, st, b1, b2)  as ATTR3_STORE_P for a run
 *                          vector of `lanes` pixels of a wider row (bits
 *                          within them; st prepared with SIMD_V lanes).
 *   VF_DIV_LANES(a, b, lanes)  a / b in the first `lanes` lanes (the
 *                          others: any value; nothing derived from them is
 *                          stored).
 *
 * COVERAGE. The reference tests E >= 0 with int64 E stepped by multiples of
 * 256 (e_dx = -dy*256, e_dy = dx*256). Since floor((E + 256k)/256) =
 * floor(E/256) + k and E >= 0 <=> floor(E/256) >= 0, the body tests the
 * reduced value E' = floor(E/256) stepped by -dy and dx, the same sign for
 * every pixel. Bounds: |dx|, |dy| < 2^23 (docs/raster.md section 2).
 *   * Fast path (int32 throughout): when the bound |c| + rows*|sy| +
 *     cols*|sx| of |E'| over the scanned rows x [0, nvec*SIMD_V) (at least
 *     the largest corner value, E' being affine) lies below 2^30, every
 *     value and every step difference fits int32: int32 adds give the
 *     exact integers. Triangles one vector wide (most of a fine mesh)
 *     take their own loop (simd_scan_vec1, with its own short prologue):
 *     coverage first, the float row values only for rows with covered
 *     pixels, the attribute set-up only from the first row that writes a
 *     pixel. Wider ones test a row's
 *     coverage vectors first (from the left, up to the end of the row's
 *     one run of covered pixels) and then do the float work on vectors
 *     that start at the run's first pixel: a run of at most SIMD_V
 *     pixels costs one vector wherever it lies (long thin slivers).
 *   * Otherwise (huge triangles, vertices far in the guard band): E' of the
 *     first lane of each vector is computed in int64 and clamped to
 *     [-2^29, 2^29] before adding the lane offsets l*(-dy), |l*dy| <
 *     15 * 2^23 < 2^27. A clamped value keeps its sign, and so does every
 *     lane: 2^29 - 2^27 > 0. Lanes with an unclamped start are exact.
 */

#define SIMD_FULL ((1u << SIMD_V) - 1u)
#define SIMD_LIM30 ((int64_t)(1 << 30) - 1)
#define SIMD_LIM29 ((int64_t)1 << 29)

/* floor(a / 256) for any sign: an arithmetic shift (gcc, clang and msvc
 * shift signed values arithmetically; checked by the soup test, where
 * half of the edge values are negative). */
static inline int64_t simd_floor256(int64_t a)
{
    return a >> 8;
}

static inline int32_t simd_clamp29(int64_t a)
{
    return (int32_t)(a < -SIMD_LIM29 ? -SIMD_LIM29 : a > SIMD_LIM29 ? SIMD_LIM29 : a);
}

static inline int64_t simd_abs64(int64_t a)
{
    return a < 0 ? -a : a;
}

/* Set bits of a lane mask. Without the popcnt instruction (the SSE2
 * build) __builtin_popcount is a libgcc call, around which every live
 * vector register is spilled: a few integer operations instead. */
static inline int simd_popcount(unsigned v)
{
#ifdef __POPCNT__
    return __builtin_popcount(v);
#else
    v = v - ((v >> 1) & 0x55555555u);
    v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
    v = (v + (v >> 4)) & 0x0F0F0F0Fu;
    return (int)((v * 0x01010101u) >> 24);
#endif
}

/* The attributes of the lanes in pass, written interleaved to dst. */
static inline void simd_attr_store(float *dst, int na, unsigned pass, int lanes, vf b1,
                                   vf b2, const vf *av0, const vf *av1, const vf *av2)
{
    (void)lanes;
#ifdef ATTR3_STORE_M
    if (na == 3) {
        ATTR3_STORE_M(dst, pass, lanes,
            VF_ADD(VF_ADD(av0[0], VF_MUL(b1, av1[0])), VF_MUL(b2, av2[0])),
            VF_ADD(VF_ADD(av0[1], VF_MUL(b1, av1[1])), VF_MUL(b2, av2[1])),
            VF_ADD(VF_ADD(av0[2], VF_MUL(b1, av1[2])), VF_MUL(b2, av2[2])));
        return;
    }
#endif
    _Alignas(64) float a[RAST_MAX_ATTRS][SIMD_V];
    for (int k = 0; k < na; k++)
        VF_STOREA(a[k], VF_ADD(VF_ADD(av0[k], VF_MUL(b1, av1[k])), VF_MUL(b2, av2[k])));
    for (unsigned bits = pass; bits; bits &= bits - 1) {
        const int l = __builtin_ctz(bits);
        float *p = dst + (size_t)l * (size_t)na;
        for (int k = 0; k < na; k++)
            p[k] = a[k][l];
    }
}

/* One pixel (x, y) of the box: the reference's scalar expressions for
 * that pixel (fi, fj are the same floats, every op the same IEEE op),
 * without the vector set-up of SIMD_FN. Used for boxes of one or two
 * pixels (1x1, 2x1, 1x2), whose vector set-up costs more than their
 * pixels. (Drawn through a context with the vector front end, such boxes
 * come as micro records instead and are not scanned.) */
static inline long simd_scan_pixel(const rast_target *t, const rast__tri *tri, int x, int y)
{
    const int64_t i = x - tri->x0, j = y - tri->y0;
    if (((tri->e_c[0] + j * tri->e_dy[0] + i * tri->e_dx[0]) |
         (tri->e_c[1] + j * tri->e_dy[1] + i * tri->e_dx[1]) |
         (tri->e_c[2] + j * tri->e_dy[2] + i * tri->e_dx[2])) < 0)
        return 0;
    const float fj = (float)j, fi = (float)i;
    float z = (tri->z.c + tri->z.dy * fj) + tri->z.dx * fi;
    z = z < 0.0f ? 0.0f : z;
    z = z > 1.0f ? 1.0f : z;
    if (t->depth) {
        float *d = t->depth + (size_t)y * (size_t)t->depth_stride + x;
        if (!(z < *d))
            return 0;
        *d = z;
    }
    t->mask[(size_t)y * (size_t)t->mask_stride + x] = 255;
    const int na = t->attr ? tri->attr_count : 0;
    if (na) {
        const float r = 1.0f / ((tri->q.c + tri->q.dy * fj) + tri->q.dx * fi);
        const float b1 = ((tri->b1.c + tri->b1.dy * fj) + tri->b1.dx * fi) * r;
        const float b2 = ((tri->b2.c + tri->b2.dy * fj) + tri->b2.dx * fi) * r;
        float *a = t->attr + (size_t)y * (size_t)t->attr_stride + (size_t)x * (size_t)na;
        for (int k = 0; k < na; k++)
            a[k] = (tri->a0[k] + b1 * tri->d1[k]) + b2 * tri->d2[k];
    }
    return 1;
}

/* Row state of the one-vector loop. */
typedef struct simd_vec1 {
    vi e0, e1, e2;                /* reduced edges of the current row */
    uint8_t *mrow;
    float *drow, *arow;           /* NULL without depth / attributes */
    long written;
} simd_vec1;

/* Coverage, depth and mask of row y (the reference's z per lane), the
 * edges stepped to the next row; returns the lanes written. */
static inline unsigned simd_vec1_row(simd_vec1 *s, const rast__tri *tri, int y,
                                     unsigned valid, vi dy0, vi dy1, vi dy2, vf zfi)
{
    const unsigned cov = ~VI_NEG_BITS(VI_OR(VI_OR(s->e0, s->e1), s->e2)) & valid;
    s->e0 = VI_ADD(s->e0, dy0);
    s->e1 = VI_ADD(s->e1, dy1);
    s->e2 = VI_ADD(s->e2, dy2);
    if (!cov)
        return 0;
    const float fj = (float)(y - tri->y0);
    vf z = VF_ADD(VF_SET1(tri->z.c + tri->z.dy * fj), zfi);
    z = VF_MAX(VF_SET1(0.0f), z);
    z = VF_MIN(VF_SET1(1.0f), z);
    unsigned pass = cov;
    if (s->drow) {
        const vf d = VF_LOAD_M(s->drow, cov, cov == SIMD_FULL);
        pass = cov & VF_LT_BITS(z, d);
        if (!pass)
            return 0;
        VF_STORE_M(s->drow, pass, pass == SIMD_FULL, z);
    }
    MASK_STORE_M(s->mrow, pass, pass == SIMD_FULL);
    s->written += simd_popcount(pass);
    return pass;
}

static inline void simd_vec1_next(simd_vec1 *s, const rast_target *t)
{
    s->mrow += t->mask_stride;
    if (s->drow)
        s->drow += t->depth_stride;
    if (s->arow)
        s->arow += t->attr_stride;
}

/* Triangles one vector wide (nx <= SIMD_V; most of a fine mesh), int32
 * coverage (the caller checked the bound, see COVERAGE): c, sx, sy are the
 * reduced edge values at (x0, ys) and their steps. Coverage first, the
 * float work only for rows with covered pixels, and nothing is set up for
 * the attributes before the first row that writes a pixel (many scanned
 * triangles are hidden). Every row-invariant product (dx * fi) is computed
 * once: the same IEEE product in every row. */
static long simd_scan_vec1(const rast_target *t, const rast__tri *tri, int ys, int ye,
                           int nx, int na, int32_t c0, int32_t c1, int32_t c2,
                           int32_t sx0, int32_t sx1, int32_t sx2, int32_t sy0,
                           int32_t sy1, int32_t sy2)
{
    const unsigned valid = nx >= SIMD_V ? SIMD_FULL : (1u << nx) - 1u;
    const vi lanev = VI_LANES();
    simd_vec1 s;
    s.e0 = VI_ADD(VI_SET1(c0), VI_LANE_MUL(lanev, sx0));
    s.e1 = VI_ADD(VI_SET1(c1), VI_LANE_MUL(lanev, sx1));
    s.e2 = VI_ADD(VI_SET1(c2), VI_LANE_MUL(lanev, sx2));
    s.written = 0;
    s.mrow = t->mask + (size_t)ys * (size_t)t->mask_stride + tri->x0;
    s.drow = t->depth ? t->depth + (size_t)ys * (size_t)t->depth_stride + tri->x0 : NULL;
    s.arow = na ? t->attr + (size_t)ys * (size_t)t->attr_stride + (size_t)tri->x0 * (size_t)na
                : NULL;
    const vi dy0 = VI_SET1(sy0), dy1 = VI_SET1(sy1), dy2 = VI_SET1(sy2);
    const vf fi = VF_CVT(lanev);
    const vf zfi = VF_MUL(VF_SET1(tri->z.dx), fi);
    int y = ys;
    unsigned pass = 0;
    for (; y <= ye; y++, simd_vec1_next(&s, t))
        if ((pass = simd_vec1_row(&s, tri, y, valid, dy0, dy1, dy2, zfi)) && na)
            break;
    if (y > ye)
        return s.written;

    /* Row y wrote pixels (pass) and there are attributes. */
    const vf one = VF_SET1(1.0f);
    const vf qfi = VF_MUL(VF_SET1(tri->q.dx), fi);
    const vf b1fi = VF_MUL(VF_SET1(tri->b1.dx), fi);
    const vf b2fi = VF_MUL(VF_SET1(tri->b2.dx), fi);
    vf av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
#ifdef ATTR3_PREP
    ATTR3_STATE a3;
    if (na == 3)
        ATTR3_PREP(&a3, tri, nx);
    else
#endif
        for (int k = 0; k < na; k++) {
            av0[k] = VF_SET1(tri->a0[k]);
            av1[k] = VF_SET1(tri->d1[k]);
            av2[k] = VF_SET1(tri->d2[k]);
        }
    for (;;) {
        const float fj = (float)(y - tri->y0);
        const float qr = tri->q.c + tri->q.dy * fj;
        const float b1r = tri->b1.c + tri->b1.dy * fj;
        const float b2r = tri->b2.c + tri->b2.dy * fj;
#ifdef VF_DIV_LANES
        const vf r = VF_DIV_LANES(one, VF_ADD(VF_SET1(qr), qfi), nx);
#else
        const vf r = VF_DIV(one, VF_ADD(VF_SET1(qr), qfi));
#endif
        const vf b1 = VF_MUL(VF_ADD(VF_SET1(b1r), b1fi), r);
        const vf b2 = VF_MUL(VF_ADD(VF_SET1(b2r), b2fi), r);
#ifdef ATTR3_PREP
        if (na == 3)
            ATTR3_STORE_P(s.arow, pass, &a3, b1, b2);
        else
#endif
            simd_attr_store(s.arow, na, pass, nx, b1, b2, av0, av1, av2);
        do {
            if (++y > ye)
                return s.written;
            simd_vec1_next(&s, t);
        } while (!(pass = simd_vec1_row(&s, tri, y, valid, dy0, dy1, dy2, zfi)));
    }
}

/* Rows wider than one vector, int32 coverage (the caller checked the
 * bound over rows ys..ye x [0, nvec*SIMD_V), see COVERAGE): c, sx, sy are
 * the reduced edge values at (x0, ys) and their steps. The covered pixels
 * of a row are one run: each E'_k is affine in i, so E'_k >= 0 holds on a
 * half-line of i and the three intersect in an interval (the box one too).
 * The row's coverage vectors (aligned at x0) are tested first, from the
 * left: leading empty vectors are skipped and the run ends in the first
 * vector whose last lane is not covered. Then the float work runs on
 * vectors starting at the run's first pixel (lane l = pixel xf + l,
 * fi = (float)(xf + l): the same ops per pixel), so a run of at most
 * SIMD_V pixels takes one vector however it straddles the aligned ones
 * (the slivers of capsule sides: runs of 4-10 pixels in boxes up to
 * hundreds wide). Loads and stores are masked to the run; no other pixel
 * is accessed. As in simd_scan_vec1, the attribute set-up waits for the
 * first pixel written and a row's attribute bases for its first vector
 * that writes (hidden rows and triangles never pay for them); a run
 * vector of at most half the lanes divides on half a vector where the
 * lane macros allow it (VF_DIV_LANES). */
static long simd_scan_wide(const rast_target *t, const rast__tri *tri, int ys, int ye,
                           int nx, int nvec, int na, const int64_t *c, const int32_t *sx,
                           const int32_t *sy)
{
    const vi lanev = VI_LANES();
    const unsigned lastvalid = SIMD_FULL >> (nvec * SIMD_V - nx);
    const vi st0 = VI_SET1((int32_t)(SIMD_V * sx[0]));
    const vi st1 = VI_SET1((int32_t)(SIMD_V * sx[1]));
    const vi st2 = VI_SET1((int32_t)(SIMD_V * sx[2]));
    const vi sy0 = VI_SET1(sy[0]), sy1 = VI_SET1(sy[1]), sy2 = VI_SET1(sy[2]);
    vi r0 = VI_ADD(VI_SET1((int32_t)c[0]), VI_LANE_MUL(lanev, sx[0]));
    vi r1 = VI_ADD(VI_SET1((int32_t)c[1]), VI_LANE_MUL(lanev, sx[1]));
    vi r2 = VI_ADD(VI_SET1((int32_t)c[2]), VI_LANE_MUL(lanev, sx[2]));
    const vf zdx = VF_SET1(tri->z.dx);
    long written = 0;
    uint8_t *mrow = t->mask + (size_t)ys * (size_t)t->mask_stride + tri->x0;
    float *drow = t->depth ? t->depth + (size_t)ys * (size_t)t->depth_stride + tri->x0
                           : NULL;
    float *arow = na ? t->attr + (size_t)ys * (size_t)t->attr_stride +
                           (size_t)tri->x0 * (size_t)na
                     : NULL;
    /* Attribute state, set up at the first pixel written (aset). */
    int aset = 0;
    vf qdx = VF_SET1(0.0f), b1dx = qdx, b2dx = qdx;
    vf av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
#if defined(ATTR3_PREP) && defined(ATTR3_STORE_PL)
    ATTR3_STATE a3;
    /* Set at the first written pixel (aset) before any use; zeroed here
     * as well, which gcc -O3 cannot see (-Wmaybe-uninitialized). */
    memset(&a3, 0, sizeof a3);
#endif
    for (int y = ys; y <= ye; y++, mrow += t->mask_stride,
             drow = drow ? drow + t->depth_stride : NULL,
             arow = arow ? arow + t->attr_stride : NULL) {
        vi e0 = r0, e1 = r1, e2 = r2;
        r0 = VI_ADD(r0, sy0);
        r1 = VI_ADD(r1, sy1);
        r2 = VI_ADD(r2, sy2);
        int v = 0;
        unsigned cov;
        for (;;) {
            cov = ~VI_NEG_BITS(VI_OR(VI_OR(e0, e1), e2)) &
                  (v == nvec - 1 ? lastvalid : SIMD_FULL);
            if (cov || v == nvec - 1)
                break;
            v++;
            e0 = VI_ADD(e0, st0);
            e1 = VI_ADD(e1, st1);
            e2 = VI_ADD(e2, st2);
        }
        if (!cov)
            continue;
        const int xf = v * SIMD_V + __builtin_ctz(cov);
        while ((cov >> (SIMD_V - 1)) && v < nvec - 1) {
            e0 = VI_ADD(e0, st0);
            e1 = VI_ADD(e1, st1);
            e2 = VI_ADD(e2, st2);
            const unsigned nc = ~VI_NEG_BITS(VI_OR(VI_OR(e0, e1), e2)) &
                                (v + 1 == nvec - 1 ? lastvalid : SIMD_FULL);
            if (!nc)
                break;
            cov = nc;
            v++;
        }
        const int xe = v * SIMD_V + 32 - __builtin_clz(cov);   /* last + 1 */

        /* Row bases: the reference's scalar expressions (the attribute
         * ones at the row's first vector that writes). */
        const float fj = (float)(y - tri->y0);
        const vf zrv = VF_SET1(tri->z.c + tri->z.dy * fj);
        vf qrv = zrv, b1rv = zrv, b2rv = zrv;
        int rowset = 0;
        for (int i0 = xf; i0 < xe; i0 += SIMD_V) {
            const int rem = xe - i0;
            const int lanes = rem < SIMD_V ? rem : SIMD_V;
            const unsigned run = rem >= SIMD_V ? SIMD_FULL : (1u << rem) - 1u;
            const vf fi = VF_CVT(VI_ADD(VI_SET1(i0), lanev));
            vf z = VF_ADD(zrv, VF_MUL(zdx, fi));
            z = VF_MAX(VF_SET1(0.0f), z);
            z = VF_MIN(VF_SET1(1.0f), z);
            unsigned pass = run;
            if (drow) {
                const vf d = VF_LOAD_M(drow + i0, run, run == SIMD_FULL);
                pass = run & VF_LT_BITS(z, d);
                if (!pass)
                    continue;
                VF_STORE_M(drow + i0, pass, pass == SIMD_FULL, z);
            }
            MASK_STORE_M(mrow + i0, pass, pass == SIMD_FULL);
            written += simd_popcount(pass);
            if (!na)
                continue;
            if (!aset) {
                aset = 1;
                qdx = VF_SET1(tri->q.dx);
                b1dx = VF_SET1(tri->b1.dx);
                b2dx = VF_SET1(tri->b2.dx);
#if defined(ATTR3_PREP) && defined(ATTR3_STORE_PL)
                if (na == 3)
                    ATTR3_PREP(&a3, tri, SIMD_V);
                else
#endif
                    for (int k = 0; k < na; k++) {
                        av0[k] = VF_SET1(tri->a0[k]);
                        av1[k] = VF_SET1(tri->d1[k]);
                        av2[k] = VF_SET1(tri->d2[k]);
                    }
            }
            if (!rowset) {
                rowset = 1;
                qrv = VF_SET1(tri->q.c + tri->q.dy * fj);
                b1rv = VF_SET1(tri->b1.c + tri->b1.dy * fj);
                b2rv = VF_SET1(tri->b2.c + tri->b2.dy * fj);
            }
#ifdef VF_DIV_LANES
            const vf r = VF_DIV_LANES(VF_SET1(1.0f), VF_ADD(qrv, VF_MUL(qdx, fi)), lanes);
#else
            const vf r = VF_DIV(VF_SET1(1.0f), VF_ADD(qrv, VF_MUL(qdx, fi)));
#endif
            const vf b1 = VF_MUL(VF_ADD(b1rv, VF_MUL(b1dx, fi)), r);
            const vf b2 = VF_MUL(VF_ADD(b2rv, VF_MUL(b2dx, fi)), r);
            float *dst = arow + (size_t)i0 * (size_t)na;
#if defined(ATTR3_PREP) && defined(ATTR3_STORE_PL)
            if (na == 3) {
                ATTR3_STORE_PL(dst, pass, lanes, &a3, b1, b2);
                continue;
            }
#elif defined(ATTR3_STORE_FULL)
            if (na == 3 && pass == SIMD_FULL) {
                ATTR3_STORE_FULL(dst,
                    VF_ADD(VF_ADD(av0[0], VF_MUL(b1, av1[0])), VF_MUL(b2, av2[0])),
                    VF_ADD(VF_ADD(av0[1], VF_MUL(b1, av1[1])), VF_MUL(b2, av2[1])),
                    VF_ADD(VF_ADD(av0[2], VF_MUL(b1, av1[2])), VF_MUL(b2, av2[2])));
                continue;
            }
#endif
            simd_attr_store(dst, na, pass, lanes, b1, b2, av0, av1, av2);
        }
    }
    return written;
}

long SIMD_FN(const rast_target *t, const rast__tri *tri, int ya, int yb)
{
    const int ys = ya > tri->y0 ? ya : tri->y0;
    const int ye = yb < tri->y1 ? yb : tri->y1;
    if (ys > ye)
        return 0;
    if (tri->x0 == tri->x1) {
        if (ys == ye)
            return simd_scan_pixel(t, tri, tri->x0, ys);
        if (ys + 1 == ye)
            return simd_scan_pixel(t, tri, tri->x0, ys) + simd_scan_pixel(t, tri, tri->x0, ye);
    } else if (tri->x0 + 1 == tri->x1 && ys == ye) {
        return simd_scan_pixel(t, tri, tri->x0, ys) + simd_scan_pixel(t, tri, tri->x1, ys);
    }
    const int na = t->attr ? tri->attr_count : 0;
    const int nx = tri->x1 - tri->x0 + 1;
    if (nx <= SIMD_V) {
        /* One vector wide: the int32 bound over rows ys..ye and the
         * SIMD_V lanes (as below with nvec = 1); when it fails, the int64
         * loop below. */
        const int64_t dj = ys - tri->y0, rows = ye - ys;
        const int64_t c0 = simd_floor256(tri->e_c[0] + dj * tri->e_dy[0]);
        const int64_t c1 = simd_floor256(tri->e_c[1] + dj * tri->e_dy[1]);
        const int64_t c2 = simd_floor256(tri->e_c[2] + dj * tri->e_dy[2]);
        const int32_t sx0 = (int32_t)(tri->e_dx[0] >> 8), sy0 = (int32_t)(tri->e_dy[0] >> 8);
        const int32_t sx1 = (int32_t)(tri->e_dx[1] >> 8), sy1 = (int32_t)(tri->e_dy[1] >> 8);
        const int32_t sx2 = (int32_t)(tri->e_dx[2] >> 8), sy2 = (int32_t)(tri->e_dy[2] >> 8);
        const int64_t cols = SIMD_V - 1;
        if (simd_abs64(c0) + rows * simd_abs64(sy0) + cols * simd_abs64(sx0) <= SIMD_LIM30 &&
            simd_abs64(c1) + rows * simd_abs64(sy1) + cols * simd_abs64(sx1) <= SIMD_LIM30 &&
            simd_abs64(c2) + rows * simd_abs64(sy2) + cols * simd_abs64(sx2) <= SIMD_LIM30)
            return simd_scan_vec1(t, tri, ys, ye, nx, na, (int32_t)c0, (int32_t)c1,
                                  (int32_t)c2, sx0, sx1, sx2, sy0, sy1, sy2);
    }
    const int nvec = (nx + SIMD_V - 1) / SIMD_V;
    const int64_t rows = ye - ys;

    /* Reduced edges, relative to (x0, ys). sx, sy are the snapped edge
     * deltas (|dx|, |dy| < 2^23). The int32 path is taken when a bound
     * of |E'| over the scanned rectangle (|c| + rows*|sy| + cols*|sx|,
     * at least the largest corner value) stays below 2^30 (always fails
     * for nvec == 1: such boxes that fit took simd_scan_vec1). */
    int64_t c[3];
    int32_t sx[3], sy[3];
    int fits = 1;
    const int64_t cols = (int64_t)nvec * SIMD_V - 1;
    for (int k = 0; k < 3; k++) {
        c[k] = simd_floor256(tri->e_c[k] + (int64_t)(ys - tri->y0) * tri->e_dy[k]);
        sx[k] = (int32_t)(tri->e_dx[k] >> 8);      /* exact: multiples of 256 */
        sy[k] = (int32_t)(tri->e_dy[k] >> 8);
        fits &= simd_abs64(c[k]) + rows * simd_abs64(sy[k]) + cols * simd_abs64(sx[k]) <=
                SIMD_LIM30;
    }
    if (fits)
        return simd_scan_wide(t, tri, ys, ye, nx, nvec, na, c, sx, sy);
    const vi lanev = VI_LANES();
    const vi off0 = VI_LANE_MUL(lanev, sx[0]), off1 = VI_LANE_MUL(lanev, sx[1]),
             off2 = VI_LANE_MUL(lanev, sx[2]);

    const vf zero = VF_SET1(0.0f), one = VF_SET1(1.0f);
    const vf zdx = VF_SET1(tri->z.dx);
    vf av0[RAST_MAX_ATTRS], av1[RAST_MAX_ATTRS], av2[RAST_MAX_ATTRS];
    for (int k = 0; k < na; k++) {
        av0[k] = VF_SET1(tri->a0[k]);
        av1[k] = VF_SET1(tri->d1[k]);
        av2[k] = VF_SET1(tri->d2[k]);
    }

    long written = 0;
    uint8_t *mrow = t->mask + (size_t)ys * (size_t)t->mask_stride + tri->x0;
    float *drow = t->depth ? t->depth + (size_t)ys * (size_t)t->depth_stride + tri->x0
                           : NULL;
    float *arow = na ? t->attr + (size_t)ys * (size_t)t->attr_stride +
                           (size_t)tri->x0 * (size_t)na
                     : NULL;
    const vf qdx = VF_SET1(tri->q.dx);
    const vf b1dx = VF_SET1(tri->b1.dx), b2dx = VF_SET1(tri->b2.dx);

    /* Int64 coverage (clamped starts, see COVERAGE): vectors aligned at
     * x0, every vector of every row tested. */
    int64_t rb[3] = { c[0], c[1], c[2] };
    for (int y = ys; y <= ye; y++, mrow += t->mask_stride,
             drow = drow ? drow + t->depth_stride : NULL,
             arow = arow ? arow + t->attr_stride : NULL) {
        /* Row bases: the reference's scalar expressions. */
        const float fj = (float)(y - tri->y0);
        const float zr = tri->z.c + tri->z.dy * fj;
        const float qr = tri->q.c + tri->q.dy * fj;
        const float b1r = tri->b1.c + tri->b1.dy * fj;
        const float b2r = tri->b2.c + tri->b2.dy * fj;
        const vf zrv = VF_SET1(zr);
        int64_t eb0 = rb[0], eb1 = rb[1], eb2 = rb[2];
        for (int v = 0; v < nvec; v++) {
            const int i0 = v * SIMD_V;
            const int rem = nx - i0;
            const unsigned valid = rem >= SIMD_V ? SIMD_FULL : (1u << rem) - 1u;
            const vi t0 = VI_ADD(VI_SET1(simd_clamp29(eb0)), off0);
            const vi t1 = VI_ADD(VI_SET1(simd_clamp29(eb1)), off1);
            const vi t2 = VI_ADD(VI_SET1(simd_clamp29(eb2)), off2);
            const unsigned neg = VI_NEG_BITS(VI_OR(VI_OR(t0, t1), t2));
            eb0 += SIMD_V * (int64_t)sx[0];
            eb1 += SIMD_V * (int64_t)sx[1];
            eb2 += SIMD_V * (int64_t)sx[2];
            const unsigned cov = ~neg & valid;
            if (!cov)
                continue;
            const vf fi = VF_CVT(VI_ADD(VI_SET1(i0), lanev));
            vf z = VF_ADD(zrv, VF_MUL(zdx, fi));
            z = VF_MAX(zero, z);
            z = VF_MIN(one, z);
            unsigned pass = cov;
            if (drow) {
                const vf d = VF_LOAD_M(drow + i0, cov, cov == SIMD_FULL);
                pass = cov & VF_LT_BITS(z, d);
                if (!pass)
                    continue;
                VF_STORE_M(drow + i0, pass, pass == SIMD_FULL, z);
            }
            MASK_STORE_M(mrow + i0, pass, pass == SIMD_FULL);
            written += simd_popcount(pass);
            if (!na)
                continue;
            const vf r = VF_DIV(one, VF_ADD(VF_SET1(qr), VF_MUL(qdx, fi)));
            const vf b1 = VF_MUL(VF_ADD(VF_SET1(b1r), VF_MUL(b1dx, fi)), r);
            const vf b2 = VF_MUL(VF_ADD(VF_SET1(b2r), VF_MUL(b2dx, fi)), r);
            float *dst = arow + (size_t)i0 * (size_t)na;
#ifdef ATTR3_STORE_FULL
            if (na == 3 && pass == SIMD_FULL) {
                ATTR3_STORE_FULL(dst,
                    VF_ADD(VF_ADD(av0[0], VF_MUL(b1, av1[0])), VF_MUL(b2, av2[0])),
                    VF_ADD(VF_ADD(av0[1], VF_MUL(b1, av1[1])), VF_MUL(b2, av2[1])),
                    VF_ADD(VF_ADD(av0[2], VF_MUL(b1, av1[2])), VF_MUL(b2, av2[2])));
                continue;
            }
#endif
            simd_attr_store(dst, na, pass, rem, b1, b2, av0, av1, av2);
        }
        rb[0] += sy[0];
        rb[1] += sy[1];
        rb[2] += sy[2];
    }
    return written;
}
