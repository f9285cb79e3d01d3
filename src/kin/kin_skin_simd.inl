/* kin_skin_simd.inl - the one body of the SIMD skinning kernels, included
 * by kin_skin_sse2.c, kin_skin_avx2.c and kin_skin_avx512.c.
 *
 * A vector holds W vertices (structure of arrays). Per block of W
 * vertices the ISA file blends each vertex's joint matrices (LBS) or dual
 * quaternions (DQS) in vector registers, one vertex at a time, exactly as
 * the reference does (skipping zero weights, adding in influence order
 * onto zero), and transposes the W blended results into SoA vectors; the
 * rest is the reference's arithmetic, operation for operation, in lanes:
 * the same IEEE results, so the output bytes equal kin__skin_*_ref.
 *
 * The ISA file defines: W, V (float vector), M (lane mask), VSET1, VADD,
 * VSUB, VMUL, VDIV, VSQRT, M_NE (unordered or not equal), M_GT, M_LT
 * (ordered), M_AND, M_ALL (every lane set), SEL(m, t, f) (t where m),
 * SELZ(m, t) (t where m, else +0), VMAX / VMIN (maxps / minps: the
 * second operand when either is NaN), VABS (sign bit cleared), VEXP2
 * (only the exponent bits kept: 2^floor(log2 x) for a normal x > 0),
 * NEG_IF(m, x) (sign flipped where m:
 * the reference's x * -1; they differ only for a NaN, whose normal is 0
 * either way), SIMD_LBS / SIMD_DQS (the
 * kernel names), the type skin_tab (per-call state of the blend, e.g. a
 * transposed joint table) and the static functions
 *   tab_init(skin_tab *)
 *   lbs_block(tab, mesh, jm, v, V a[12], V *wsum)  a[c*3+r]: column c, row r
 *   dqs_block(tab, mesh, dq, v, V b[8], V *wsum)   b: r.xyzw, d.xyzw
 *   lay3_init(lay3 *), deint3(const lay3 *, const float *, V o[3]),
 *   int3(const lay3 *, float *, const V i[3])  (x y z x y z ... <-> SoA)
 */

/* cross(a, b), componentwise as kin_v3_cross. */
#define CROSS(o, a, b)                                                   \
    do {                                                                 \
        o[0] = VSUB(VMUL(a[1], b[2]), VMUL(a[2], b[1]));                 \
        o[1] = VSUB(VMUL(a[2], b[0]), VMUL(a[0], b[2]));                 \
        o[2] = VSUB(VMUL(a[0], b[1]), VMUL(a[1], b[0]));                 \
    } while (0)

/* kin_v3_norm: r / |r|, or 0 when |r| is 0 or not finite. */
static inline __attribute__((always_inline)) void norm3(V r[3], V zero, V inf)
{
    V l = VSQRT(VADD(VADD(VMUL(r[0], r[0]), VMUL(r[1], r[1])), VMUL(r[2], r[2])));
    M ok = M_AND(M_GT(l, zero), M_LT(l, inf));
    V inv = VDIV(VSET1(1.0f), l);
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) r[k] = SELZ(ok, VMUL(r[k], inv));
}

/* LBS of W lanes, the reference's operations (kin_skin.c): p' = A p + t
 * with a[c*3+r] column c, row r of the blended matrix; the normal
 * n' = normalize(sign(det A) cof(A) n). Forced inline with unrolled
 * loops: a call or a loop over a small array would pass the vectors
 * through memory. */
static inline __attribute__((always_inline)) void lbs_pos(const V a[12], const V p[3], V o[3])
{
#pragma GCC unroll 3
    for (int r = 0; r < 3; r++)
        o[r] = VADD(VADD(VADD(VMUL(a[r], p[0]), VMUL(a[3 + r], p[1])),
                         VMUL(a[6 + r], p[2])), a[9 + r]);
}

static inline __attribute__((always_inline)) void lbs_nrm(const V a[12], const V n[3], V x[3])
{
    const V zero = VSET1(0.0f), inf = VSET1(INFINITY);
    V c0[3], c1[3], c2[3];
    const V a0[3] = { a[0], a[1], a[2] }, a1[3] = { a[3], a[4], a[5] },
            a2[3] = { a[6], a[7], a[8] };
    CROSS(c0, a1, a2);
    CROSS(c1, a2, a0);
    CROSS(c2, a0, a1);
    V det = VADD(VADD(VMUL(a0[0], c0[0]), VMUL(a0[1], c0[1])), VMUL(a0[2], c0[2]));
    M flip = M_LT(det, zero);
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
        x[k] = VADD(VADD(VMUL(c0[k], n[0]), VMUL(c1[k], n[1])), VMUL(c2[k], n[2]));
        x[k] = NEG_IF(flip, x[k]);
    }
    norm3(x, zero, inf);
}

int SIMD_LBS(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
             float *nrm_out, int v0, int v1)
{
    const int do_n = mesh->normals && nrm_out;
    const V zero = VSET1(0.0f);
    lay3 L;
    lay3_init(&L);
    skin_tab T;
    tab_init(&T);
    int v = v0;
    for (; v1 - v >= W; v += W) {
        V a[12], ws, p[3], o[3];
        lbs_block(&T, mesh, jm, v, a, &ws);
        M ok = M_NE(ws, zero);
        const int all = M_ALL(ok);   /* no bind-pose lane: no selects */
        deint3(&L, mesh->positions + (size_t)v * 3, p);
        lbs_pos(a, p, o);
        if (!all) {
#pragma GCC unroll 3
            for (int r = 0; r < 3; r++) o[r] = SEL(ok, o[r], p[r]);
        }
        int3(&L, pos_out + (size_t)v * 3, o);
        if (!do_n) continue;
        V n[3];
        deint3(&L, mesh->normals + (size_t)v * 3, n);
        lbs_nrm(a, n, o);
        if (!all) {
#pragma GCC unroll 3
            for (int k = 0; k < 3; k++) o[k] = SEL(ok, o[k], n[k]);
        }
        int3(&L, nrm_out + (size_t)v * 3, o);
    }
    return v;
}

/* The DQS of W lanes (kin_dqs.c): q the blended dual quaternion (r.xyzw,
 * d.xyzw), k = 2 / |q.r|^2, u = q.r.xyz:
 *   p' = p + k (w e + u x e - d.w u),  e = u x p + d.v
 *   n' = n + k (w f + u x f),          f = u x n
 * in the reference's order of operations. */
static inline __attribute__((always_inline)) void dqs_pos(const V q[8], V k, const V p[3],
                                                          V o[3])
{
    const V u[3] = { q[0], q[1], q[2] };
    V e[3], g[3];
    CROSS(e, u, p);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) e[c] = VADD(e[c], q[4 + c]);
    CROSS(g, u, e);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++)
        o[c] = VADD(p[c], VMUL(k, VSUB(VADD(VMUL(q[3], e[c]), g[c]), VMUL(q[7], u[c]))));
}

static inline __attribute__((always_inline)) void dqs_nrm(const V q[8], V k, const V n[3],
                                                          V o[3])
{
    const V u[3] = { q[0], q[1], q[2] };
    V f[3], g[3];
    CROSS(f, u, n);
    CROSS(g, u, f);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) o[c] = VADD(n[c], VMUL(k, VADD(VMUL(q[3], f[c]), g[c])));
}

/* |q.r|^2 in the reference's order. */
static inline __attribute__((always_inline)) V dqs_sq(const V q[8])
{
    return VADD(VADD(VADD(VMUL(q[0], q[0]), VMUL(q[1], q[1])), VMUL(q[2], q[2])),
                VMUL(q[3], q[3]));
}

/* The range rule of kin_dqs.c (dq_fit): lanes whose |q.r|^2 is outside
 * (KIN__DQS_SQ_MIN, KIN__DQS_SQ_MAX) are scaled by 2^-E, 2^E the power of
 * two (exponent bits, VEXP2) of their largest |q.r| component clamped to
 * [KIN__DQS_FIT_LO, KIN__DQS_FIT_HI]; the other lanes keep their bits.
 * Updates *sq. Branch-free per lane; a vector with every lane in range
 * (the normal case) skips it. */
static inline __attribute__((always_inline)) void dqs_fit(V q[8], V *sq)
{
    const M in = M_AND(M_GT(*sq, VSET1(KIN__DQS_SQ_MIN)), M_LT(*sq, VSET1(KIN__DQS_SQ_MAX)));
    if (M_ALL(in)) return;
    V m = VMAX(VMAX(VMAX(VABS(q[0]), VABS(q[1])), VABS(q[2])), VABS(q[3]));
    m = VMIN(VMAX(m, VSET1(KIN__DQS_FIT_LO)), VSET1(KIN__DQS_FIT_HI));
    const V s = VDIV(VSET1(1.0f), VEXP2(m));
#pragma GCC unroll 8
    for (int e = 0; e < 8; e++) q[e] = SEL(in, q[e], VMUL(q[e], s));
    *sq = dqs_sq(q);
}

int SIMD_DQS(const kin_mesh *mesh, const kin_dualquat *dq, float *pos_out,
             float *nrm_out, int v0, int v1)
{
    const int do_n = mesh->normals && nrm_out;
    const V zero = VSET1(0.0f), two = VSET1(2.0f);
    lay3 L;
    lay3_init(&L);
    skin_tab T;
    tab_init(&T);
    int v = v0;
    for (; v1 - v >= W; v += W) {
        V b[8], ws, p[3], o[3];
        dqs_block(&T, mesh, dq, v, b, &ws);
        V sq = dqs_sq(b);
        dqs_fit(b, &sq);
        M ok = M_AND(M_NE(ws, zero), M_GT(sq, zero));
        const int all = M_ALL(ok);
        V k = VDIV(two, sq);
        deint3(&L, mesh->positions + (size_t)v * 3, p);
        dqs_pos(b, k, p, o);
        if (!all) {
#pragma GCC unroll 3
            for (int c = 0; c < 3; c++) o[c] = SEL(ok, o[c], p[c]);
        }
        int3(&L, pos_out + (size_t)v * 3, o);
        if (!do_n) continue;
        V n[3];
        deint3(&L, mesh->normals + (size_t)v * 3, n);
        dqs_nrm(b, k, n, o);
        if (!all) {
#pragma GCC unroll 3
            for (int c = 0; c < 3; c++) o[c] = SEL(ok, o[c], n[c]);
        }
        int3(&L, nrm_out + (size_t)v * 3, o);
    }
    return v;
}

/* ---- skin plan kernels (kin_skin_plan.c) ----------------------------
 * A batch of KIN__PLAN_W vertices reads the same joints: each element of
 * a joint's matrix (dual quaternion) is broadcast and multiplied by the
 * lanes' weights, summed onto +0 in influence order like the reference.
 * Inputs are SoA in the batch (aligned loads); outputs go to the vertices'
 * places: int3 when the batch is contiguous, else scat3 (the ISA file's
 * scatter of three SoA vectors to the lanes' dest indices). The ISA file
 * also defines VLOAD (aligned load), VNEG (sign flip, the reference's
 * -w), SIMD_LBS_PLAN and SIMD_DQS_PLAN. */

static inline __attribute__((always_inline)) void plan_store(const lay3 *L, const kin__plan_batch *B, int h, float *out,
                              const V o[3])
{
    if (B->contiguous) int3(L, out + 3 * (size_t)(B->first + h), o);
    else scat3(out, B->dest + h, o);
}

/* n == 0: the bind pose. */
static inline __attribute__((always_inline)) void plan_copy(const lay3 *L, const kin__plan_batch *B, float *pos_out,
                             float *nrm_out)
{
    for (int h = 0; h < KIN__PLAN_W; h += W) {
        V o[3];
        for (int k = 0; k < 3; k++) o[k] = VLOAD(B->p[k] + h);
        plan_store(L, B, h, pos_out, o);
        if (!nrm_out) continue;
        for (int k = 0; k < 3; k++) o[k] = VLOAD(B->nrm[k] + h);
        plan_store(L, B, h, nrm_out, o);
    }
}

/* Lanes [h, h + W) of an LBS batch with n influences (n a constant
 * where it is inlined, so the loops unroll and a[] stays in registers;
 * forced inline: a call would pass the vectors through memory). */
static inline __attribute__((always_inline)) void lbs_plan_lanes(const kin__plan_batch *B, const int n, int h,
                                  const kin_mat4 *jm, const lay3 *L, float *pos_out,
                                  float *nrm_out)
{
    const V zero = VSET1(0.0f);
    V a[12], p[3], o[3];
    {
        const float *m = jm[B->joint[0]].m;
        const V w = VLOAD(B->w[0] + h);
#pragma GCC unroll 12
        for (int e = 0; e < 12; e++)
            a[e] = VADD(zero, VMUL(w, VSET1(m[(e / 3) * 4 + e % 3])));
    }
#pragma GCC unroll 4
    for (int i = 1; i < n; i++) {
        const float *m = jm[B->joint[i]].m;
        const V w = VLOAD(B->w[i] + h);
#pragma GCC unroll 12
        for (int e = 0; e < 12; e++)
            a[e] = VADD(a[e], VMUL(w, VSET1(m[(e / 3) * 4 + e % 3])));
    }
    /* the normal first: its square root and division are the longest
     * chain, and the position's work and stores fill their latency */
    V x[3];
    if (nrm_out) {
#pragma GCC unroll 3
        for (int k = 0; k < 3; k++) p[k] = VLOAD(B->nrm[k] + h);
        lbs_nrm(a, p, x);
    }
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) p[k] = VLOAD(B->p[k] + h);
    lbs_pos(a, p, o);
    plan_store(L, B, h, pos_out, o);
    if (nrm_out) plan_store(L, B, h, nrm_out, x);
}

void SIMD_LBS_PLAN(const kin__plan_batch *bt, int b0, int b1, const void *xf,
                   float *pos_out, float *nrm_out)
{
    const kin_mat4 *jm = xf;
    lay3 L;
    lay3_init(&L);
    for (int b = b0; b < b1; b++) {
        const kin__plan_batch *B = &bt[b];
        switch (B->n) {
        case 1: for (int h = 0; h < KIN__PLAN_W; h += W) lbs_plan_lanes(B, 1, h, jm, &L, pos_out, nrm_out); break;
        case 2: for (int h = 0; h < KIN__PLAN_W; h += W) lbs_plan_lanes(B, 2, h, jm, &L, pos_out, nrm_out); break;
        case 3: for (int h = 0; h < KIN__PLAN_W; h += W) lbs_plan_lanes(B, 3, h, jm, &L, pos_out, nrm_out); break;
        case 4: for (int h = 0; h < KIN__PLAN_W; h += W) lbs_plan_lanes(B, 4, h, jm, &L, pos_out, nrm_out); break;
        default: plan_copy(&L, B, pos_out, nrm_out); break;
        }
    }
}

/* Lanes [h, h + W) of a DQS batch with n influences, neg[i]: the sign
 * flip of influence i (inlined with a constant n, like lbs_plan_lanes). */
static inline __attribute__((always_inline)) void dqs_plan_lanes(
    const kin__plan_batch *B, const int n, const int neg[4], int h, const kin_dualquat *dq,
    const lay3 *L, float *pos_out, float *nrm_out)
{
    const V zero = VSET1(0.0f);
    V q[8], p[3], o[3];
#pragma GCC unroll 8
    for (int e = 0; e < 8; e++) q[e] = zero;
#pragma GCC unroll 4
    for (int i = 0; i < n; i++) {
        const float *d = &dq[B->joint[i]].r.x;
        V w = VLOAD(B->w[i] + h);
        if (neg[i]) w = VNEG(w);
#pragma GCC unroll 8
        for (int e = 0; e < 8; e++) q[e] = VADD(q[e], VMUL(w, VSET1(d[e])));
    }
    V sq = dqs_sq(q);
    dqs_fit(q, &sq);
    M ok = M_GT(sq, zero);
    const int all = M_ALL(ok);
    V k = VDIV(VSET1(2.0f), sq);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) p[c] = VLOAD(B->p[c] + h);
    dqs_pos(q, k, p, o);
    if (!all) {
#pragma GCC unroll 3
        for (int c = 0; c < 3; c++) o[c] = SEL(ok, o[c], p[c]);
    }
    plan_store(L, B, h, pos_out, o);
    if (!nrm_out) return;
    V nn[3];
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) nn[c] = VLOAD(B->nrm[c] + h);
    dqs_nrm(q, k, nn, o);
    if (!all) {
#pragma GCC unroll 3
        for (int c = 0; c < 3; c++) o[c] = SEL(ok, o[c], nn[c]);
    }
    plan_store(L, B, h, nrm_out, o);
}

void SIMD_DQS_PLAN(const kin__plan_batch *bt, int b0, int b1, const void *xf,
                   float *pos_out, float *nrm_out)
{
    const kin_dualquat *dq = xf;
    lay3 L;
    lay3_init(&L);
    for (int b = b0; b < b1; b++) {
        const kin__plan_batch *B = &bt[b];
        const int n = B->n;
        if (n == 0) { plan_copy(&L, B, pos_out, nrm_out); continue; }
        /* the reference's signs: s_i = -w_i when r_i . r_first < 0 (the
         * same for every lane: the same joints) */
        int neg[4] = { 0, 0, 0, 0 };
        const kin_quat *r0 = &dq[B->joint[0]].r;
        for (int i = 0; i < n; i++) {
            const kin_quat *q = &dq[B->joint[i]].r;
            float dot = q->x * r0->x + q->y * r0->y + q->z * r0->z + q->w * r0->w;
            neg[i] = dot < 0.0f;
        }
        switch (n) {
        case 1: for (int h = 0; h < KIN__PLAN_W; h += W) dqs_plan_lanes(B, 1, neg, h, dq, &L, pos_out, nrm_out); break;
        case 2: for (int h = 0; h < KIN__PLAN_W; h += W) dqs_plan_lanes(B, 2, neg, h, dq, &L, pos_out, nrm_out); break;
        case 3: for (int h = 0; h < KIN__PLAN_W; h += W) dqs_plan_lanes(B, 3, neg, h, dq, &L, pos_out, nrm_out); break;
        default: for (int h = 0; h < KIN__PLAN_W; h += W) dqs_plan_lanes(B, 4, neg, h, dq, &L, pos_out, nrm_out); break;
        }
    }
}

#undef CROSS
