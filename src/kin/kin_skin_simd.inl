/* kin_skin_simd.inl - the one body of the SIMD skinning kernels, written
 * on the vector layer (src/cpu/simd.h) and included after one of its
 * implementations by kin_skin_sse2.c, kin_skin_avx2.c, kin_skin_avx512.c
 * and kin_skin_neon.c.
 *
 * A vector holds SIMD_W vertices (structure of arrays). Per block of
 * SIMD_W vertices the blend (lbs_block, dqs_block) builds each vertex's
 * blended joint matrix (LBS) or dual quaternion (DQS) exactly as the
 * reference does (skipping zero weights, adding in influence order onto
 * zero) and transposes the results into SoA vectors; the rest is the
 * reference's arithmetic, operation for operation, in lanes: the same
 * IEEE results, so the output bytes equal kin__skin_*_ref.
 *
 * The blend is the one part that differs by ISA. With 4 lanes (SSE2,
 * NEON) it is written below on the layer (a joint matrix is four column
 * vectors, four vertices are one vf_tr4). An ISA file of more lanes
 * defines KIN_SKIN_OWN_BLOCK and, before including this file,
 *   skin_tab (per-call state, e.g. AVX-512's transposed joint table),
 *   tab_init(skin_tab *),
 *   lbs_block(tab, mesh, jm, v, vfloat a[12], vfloat *wsum)  a[c*3+r]:
 *                                                 column c, row r
 *   dqs_block(tab, mesh, dq, v, vfloat b[8], vfloat *wsum)  r.xyzw, d.xyzw
 * (kin_skin_avx2.c: two columns per ymm; kin_skin_avx512.c: a joint
 * table looked up with vpermt2ps).
 *
 * Exported (SIMD_FN: the layer's suffix): kin__skin_lbs_<isa>,
 * kin__skin_dqs_<isa>, kin__skin_lbs_plan_<isa>, kin__skin_dqs_plan_<isa>
 * (kin_skin_internal.h).
 */

#if !defined(KIN_SKIN_OWN_BLOCK)
#if SIMD_W != 4
#error "kin_skin_simd.inl: an ISA of more than 4 lanes brings its own blend (KIN_SKIN_OWN_BLOCK)"
#endif
/* No per-call state with 4 lanes. */
typedef struct skin_tab { int unused; } skin_tab;
SIMD_INL void tab_init(skin_tab *t) { t->unused = 0; }

/* Bit i set when weight i is not 0 (NaN counts as not 0: the reference's
 * "w == 0: skip"). */
SIMD_INL unsigned nonzero4(const float *w)
{
    return vm_bits(vf_ne(vf_loadu(w), vf_zero()));
}

static inline void lbs_block(skin_tab *tab, const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             vfloat a[12], vfloat *wsum)
{
    _Alignas(16) float ws[4];
    vfloat r[4][4];   /* [vertex][column] */
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 4; l++, j += 4, w += 4) {
        vfloat c[4] = { vf_zero(), vf_zero(), vf_zero(), vf_zero() };
        float s = 0.0f;
        for (unsigned bits = nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            const vfloat wv = vf_set1(w[i]);
            const float *m = jm[j[i]].m;
            for (int k = 0; k < 4; k++) c[k] = vf_add(c[k], vf_mul(wv, vf_loadu(m + 4 * k)));
            s += w[i];
        }
        for (int k = 0; k < 4; k++) r[l][k] = c[k];
        ws[l] = s;
    }
    *wsum = vf_load(ws);
    for (int k = 0; k < 4; k++) {
        vfloat t[4];
        vf_tr4(r[0][k], r[1][k], r[2][k], r[3][k], t);
        a[k * 3] = t[0]; a[k * 3 + 1] = t[1]; a[k * 3 + 2] = t[2];
    }
}

static inline void dqs_block(skin_tab *tab, const kin_mesh *mesh, const kin_dualquat *dq, int v,
                             vfloat b[8], vfloat *wsum)
{
    _Alignas(16) float ws[4];
    vfloat r[4][2];
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 4; l++, j += 4, w += 4) {
        vfloat qr = vf_zero(), qd = vf_zero();
        float s = 0.0f;
        const kin_quat *r0 = NULL;
        for (unsigned bits = nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            const kin_dualquat *q = &dq[j[i]];
            float sw = w[i];
            if (!r0) {
                r0 = &q->r;
            } else {
                float dot = q->r.x * r0->x + q->r.y * r0->y + q->r.z * r0->z + q->r.w * r0->w;
                if (dot < 0.0f) sw = -w[i];
            }
            const vfloat wv = vf_set1(sw);
            qr = vf_add(qr, vf_mul(wv, vf_loadu(&q->r.x)));
            qd = vf_add(qd, vf_mul(wv, vf_loadu(&q->d.x)));
            s += w[i];
        }
        r[l][0] = qr;
        r[l][1] = qd;
        ws[l] = s;
    }
    *wsum = vf_load(ws);
    for (int k = 0; k < 2; k++) vf_tr4(r[0][k], r[1][k], r[2][k], r[3][k], b + 4 * k);
}
#endif

/* x y z x y z ... <-> SoA: the layer's vf_load3 / vf_store3 /
 * vf_scatter3 (lay3: no state left; kept so the body reads as before). */
typedef struct lay3 { int unused; } lay3;
SIMD_INL void lay3_init(lay3 *L) { L->unused = 0; }
SIMD_INL void deint3(const lay3 *L, const float *p, vfloat o[3])
{
    (void)L;
    vf_load3(p, &o[0], &o[1], &o[2]);
}
SIMD_INL void int3(const lay3 *L, float *p, const vfloat in[3])
{
    (void)L;
    vf_store3(p, in[0], in[1], in[2]);
}
SIMD_INL void scat3(float *out, const int32_t *dest, const vfloat o[3])
{
    vf_scatter3(out, dest, o[0], o[1], o[2]);
}

/* The exponent bits of x alone: 2^floor(log2 x) for a normal x > 0. */
SIMD_INL vfloat exp2_bits(vfloat x)
{
    return vi_as_vf(vi_and(vf_as_vi(x), vi_set1(0x7F800000)));
}

/* cross(a, b), componentwise as kin_v3_cross. */
#define CROSS(o, a, b)                                                   \
    do {                                                                 \
        o[0] = vf_sub(vf_mul(a[1], b[2]), vf_mul(a[2], b[1]));                 \
        o[1] = vf_sub(vf_mul(a[2], b[0]), vf_mul(a[0], b[2]));                 \
        o[2] = vf_sub(vf_mul(a[0], b[1]), vf_mul(a[1], b[0]));                 \
    } while (0)

/* kin_v3_norm: r / |r|, or 0 when |r| is 0 or not finite. */
SIMD_INL void norm3(vfloat r[3], vfloat zero, vfloat inf)
{
    vfloat l = vf_sqrt(vf_add(vf_add(vf_mul(r[0], r[0]), vf_mul(r[1], r[1])), vf_mul(r[2], r[2])));
    vmask ok = vm_and(vf_gt(l, zero), vf_lt(l, inf));
    vfloat inv = vf_div(vf_set1(1.0f), l);
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) r[k] = vf_selz(ok, vf_mul(r[k], inv));
}

/* LBS of SIMD_W lanes, the reference's operations (kin_skin.c): p' = A p + t
 * with a[c*3+r] column c, row r of the blended matrix; the normal
 * n' = normalize(sign(det A) cof(A) n). Forced inline with unrolled
 * loops: a call or a loop over a small array would pass the vectors
 * through memory. */
SIMD_INL void lbs_pos(const vfloat a[12], const vfloat p[3], vfloat o[3])
{
#pragma GCC unroll 3
    for (int r = 0; r < 3; r++)
        o[r] = vf_add(vf_add(vf_add(vf_mul(a[r], p[0]), vf_mul(a[3 + r], p[1])),
                         vf_mul(a[6 + r], p[2])), a[9 + r]);
}

SIMD_INL void lbs_nrm(const vfloat a[12], const vfloat n[3], vfloat x[3])
{
    const vfloat zero = vf_set1(0.0f), inf = vf_set1(INFINITY);
    vfloat c0[3], c1[3], c2[3];
    const vfloat a0[3] = { a[0], a[1], a[2] }, a1[3] = { a[3], a[4], a[5] },
            a2[3] = { a[6], a[7], a[8] };
    CROSS(c0, a1, a2);
    CROSS(c1, a2, a0);
    CROSS(c2, a0, a1);
    vfloat det = vf_add(vf_add(vf_mul(a0[0], c0[0]), vf_mul(a0[1], c0[1])), vf_mul(a0[2], c0[2]));
    vmask flip = vf_lt(det, zero);
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
        x[k] = vf_add(vf_add(vf_mul(c0[k], n[0]), vf_mul(c1[k], n[1])), vf_mul(c2[k], n[2]));
        x[k] = vf_neg_if(flip, x[k]);
    }
    norm3(x, zero, inf);
}

int SIMD_FN(kin__skin_lbs)(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
             float *nrm_out, int v0, int v1)
{
    const int do_n = mesh->normals && nrm_out;
    const vfloat zero = vf_set1(0.0f);
    lay3 L;
    lay3_init(&L);
    skin_tab T;
    tab_init(&T);
    int v = v0;
    for (; v1 - v >= SIMD_W; v += SIMD_W) {
        vfloat a[12], ws, p[3], o[3];
        lbs_block(&T, mesh, jm, v, a, &ws);
        vmask ok = vf_ne(ws, zero);
        const int all = vm_all(ok);   /* no bind-pose lane: no selects */
        deint3(&L, mesh->positions + (size_t)v * 3, p);
        lbs_pos(a, p, o);
        if (!all) {
#pragma GCC unroll 3
            for (int r = 0; r < 3; r++) o[r] = vf_sel(ok, o[r], p[r]);
        }
        int3(&L, pos_out + (size_t)v * 3, o);
        if (!do_n) continue;
        vfloat n[3];
        deint3(&L, mesh->normals + (size_t)v * 3, n);
        lbs_nrm(a, n, o);
        if (!all) {
#pragma GCC unroll 3
            for (int k = 0; k < 3; k++) o[k] = vf_sel(ok, o[k], n[k]);
        }
        int3(&L, nrm_out + (size_t)v * 3, o);
    }
    return v;
}

/* The DQS of SIMD_W lanes (kin_dqs.c): q the blended dual quaternion (r.xyzw,
 * d.xyzw), k = 2 / |q.r|^2, u = q.r.xyz:
 *   p' = p + k (w e + u x e - d.w u),  e = u x p + d.v
 *   n' = n + k (w f + u x f),          f = u x n
 * in the reference's order of operations. */
SIMD_INL void dqs_pos(const vfloat q[8], vfloat k, const vfloat p[3],
                                                          vfloat o[3])
{
    const vfloat u[3] = { q[0], q[1], q[2] };
    vfloat e[3], g[3];
    CROSS(e, u, p);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) e[c] = vf_add(e[c], q[4 + c]);
    CROSS(g, u, e);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++)
        o[c] = vf_add(p[c], vf_mul(k, vf_sub(vf_add(vf_mul(q[3], e[c]), g[c]), vf_mul(q[7], u[c]))));
}

SIMD_INL void dqs_nrm(const vfloat q[8], vfloat k, const vfloat n[3],
                                                          vfloat o[3])
{
    const vfloat u[3] = { q[0], q[1], q[2] };
    vfloat f[3], g[3];
    CROSS(f, u, n);
    CROSS(g, u, f);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) o[c] = vf_add(n[c], vf_mul(k, vf_add(vf_mul(q[3], f[c]), g[c])));
}

/* |q.r|^2 in the reference's order. */
SIMD_INL vfloat dqs_sq(const vfloat q[8])
{
    return vf_add(vf_add(vf_add(vf_mul(q[0], q[0]), vf_mul(q[1], q[1])), vf_mul(q[2], q[2])),
                vf_mul(q[3], q[3]));
}

/* The range rule of kin_dqs.c (dq_fit): lanes whose |q.r|^2 is outside
 * (KIN__DQS_SQ_MIN, KIN__DQS_SQ_MAX) are scaled by 2^-E, 2^E the power of
 * two (exponent bits, exp2_bits) of their largest |q.r| component clamped to
 * [KIN__DQS_FIT_LO, KIN__DQS_FIT_HI]; the other lanes keep their bits.
 * Updates *sq. Branch-free per lane; a vector with every lane in range
 * (the normal case) skips it. */
SIMD_INL void dqs_fit(vfloat q[8], vfloat *sq)
{
    const vmask in = vm_and(vf_gt(*sq, vf_set1(KIN__DQS_SQ_MIN)), vf_lt(*sq, vf_set1(KIN__DQS_SQ_MAX)));
    if (vm_all(in)) return;
    vfloat m = vf_max(vf_max(vf_max(vf_abs(q[0]), vf_abs(q[1])), vf_abs(q[2])), vf_abs(q[3]));
    m = vf_min(vf_max(m, vf_set1(KIN__DQS_FIT_LO)), vf_set1(KIN__DQS_FIT_HI));
    const vfloat s = vf_div(vf_set1(1.0f), exp2_bits(m));
#pragma GCC unroll 8
    for (int e = 0; e < 8; e++) q[e] = vf_sel(in, q[e], vf_mul(q[e], s));
    *sq = dqs_sq(q);
}

int SIMD_FN(kin__skin_dqs)(const kin_mesh *mesh, const kin_dualquat *dq, float *pos_out,
             float *nrm_out, int v0, int v1)
{
    const int do_n = mesh->normals && nrm_out;
    const vfloat zero = vf_set1(0.0f), two = vf_set1(2.0f);
    lay3 L;
    lay3_init(&L);
    skin_tab T;
    tab_init(&T);
    int v = v0;
    for (; v1 - v >= SIMD_W; v += SIMD_W) {
        vfloat b[8], ws, p[3], o[3];
        dqs_block(&T, mesh, dq, v, b, &ws);
        vfloat sq = dqs_sq(b);
        dqs_fit(b, &sq);
        vmask ok = vm_and(vf_ne(ws, zero), vf_gt(sq, zero));
        const int all = vm_all(ok);
        vfloat k = vf_div(two, sq);
        deint3(&L, mesh->positions + (size_t)v * 3, p);
        dqs_pos(b, k, p, o);
        if (!all) {
#pragma GCC unroll 3
            for (int c = 0; c < 3; c++) o[c] = vf_sel(ok, o[c], p[c]);
        }
        int3(&L, pos_out + (size_t)v * 3, o);
        if (!do_n) continue;
        vfloat n[3];
        deint3(&L, mesh->normals + (size_t)v * 3, n);
        dqs_nrm(b, k, n, o);
        if (!all) {
#pragma GCC unroll 3
            for (int c = 0; c < 3; c++) o[c] = vf_sel(ok, o[c], n[c]);
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
 * places: int3 when the batch is contiguous, else scat3 (the layer's
 * vf_scatter3 to the lanes' dest indices). */

SIMD_INL void plan_store(const lay3 *L, const kin__plan_batch *B, int h, float *out,
                              const vfloat o[3])
{
    if (B->contiguous) int3(L, out + 3 * (size_t)(B->first + h), o);
    else scat3(out, B->dest + h, o);
}

/* n == 0: the bind pose. */
SIMD_INL void plan_copy(const lay3 *L, const kin__plan_batch *B, float *pos_out,
                             float *nrm_out)
{
    for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) {
        vfloat o[3];
        for (int k = 0; k < 3; k++) o[k] = vf_load(B->p[k] + h);
        plan_store(L, B, h, pos_out, o);
        if (!nrm_out) continue;
        for (int k = 0; k < 3; k++) o[k] = vf_load(B->nrm[k] + h);
        plan_store(L, B, h, nrm_out, o);
    }
}

/* Lanes [h, h + SIMD_W) of an LBS batch with n influences (n a constant
 * where it is inlined, so the loops unroll and a[] stays in registers;
 * forced inline: a call would pass the vectors through memory). */
SIMD_INL void lbs_plan_lanes(const kin__plan_batch *B, const int n, int h,
                                  const kin_mat4 *jm, const lay3 *L, float *pos_out,
                                  float *nrm_out)
{
    const vfloat zero = vf_set1(0.0f);
    vfloat a[12], p[3], o[3];
    {
        const float *m = jm[B->joint[0]].m;
        const vfloat w = vf_load(B->w[0] + h);
#pragma GCC unroll 12
        for (int e = 0; e < 12; e++)
            a[e] = vf_add(zero, vf_mul(w, vf_set1(m[(e / 3) * 4 + e % 3])));
    }
#pragma GCC unroll 4
    for (int i = 1; i < n; i++) {
        const float *m = jm[B->joint[i]].m;
        const vfloat w = vf_load(B->w[i] + h);
#pragma GCC unroll 12
        for (int e = 0; e < 12; e++)
            a[e] = vf_add(a[e], vf_mul(w, vf_set1(m[(e / 3) * 4 + e % 3])));
    }
    /* the normal first: its square root and division are the longest
     * chain, and the position's work and stores fill their latency */
    vfloat x[3];
    if (nrm_out) {
#pragma GCC unroll 3
        for (int k = 0; k < 3; k++) p[k] = vf_load(B->nrm[k] + h);
        lbs_nrm(a, p, x);
    }
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) p[k] = vf_load(B->p[k] + h);
    lbs_pos(a, p, o);
    plan_store(L, B, h, pos_out, o);
    if (nrm_out) plan_store(L, B, h, nrm_out, x);
}

void SIMD_FN(kin__skin_lbs_plan)(const kin__plan_batch *bt, int b0, int b1, const void *xf,
                   float *pos_out, float *nrm_out)
{
    const kin_mat4 *jm = xf;
    lay3 L;
    lay3_init(&L);
    for (int b = b0; b < b1; b++) {
        const kin__plan_batch *B = &bt[b];
        switch (B->n) {
        case 1: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) lbs_plan_lanes(B, 1, h, jm, &L, pos_out, nrm_out); break;
        case 2: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) lbs_plan_lanes(B, 2, h, jm, &L, pos_out, nrm_out); break;
        case 3: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) lbs_plan_lanes(B, 3, h, jm, &L, pos_out, nrm_out); break;
        case 4: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) lbs_plan_lanes(B, 4, h, jm, &L, pos_out, nrm_out); break;
        default: plan_copy(&L, B, pos_out, nrm_out); break;
        }
    }
}

/* Lanes [h, h + SIMD_W) of a DQS batch with n influences, neg[i]: the sign
 * flip of influence i (inlined with a constant n, like lbs_plan_lanes). */
SIMD_INL void dqs_plan_lanes(
    const kin__plan_batch *B, const int n, const int neg[4], int h, const kin_dualquat *dq,
    const lay3 *L, float *pos_out, float *nrm_out)
{
    const vfloat zero = vf_set1(0.0f);
    vfloat q[8], p[3], o[3];
#pragma GCC unroll 8
    for (int e = 0; e < 8; e++) q[e] = zero;
#pragma GCC unroll 4
    for (int i = 0; i < n; i++) {
        const float *d = &dq[B->joint[i]].r.x;
        vfloat w = vf_load(B->w[i] + h);
        if (neg[i]) w = vf_neg(w);
#pragma GCC unroll 8
        for (int e = 0; e < 8; e++) q[e] = vf_add(q[e], vf_mul(w, vf_set1(d[e])));
    }
    vfloat sq = dqs_sq(q);
    dqs_fit(q, &sq);
    vmask ok = vf_gt(sq, zero);
    const int all = vm_all(ok);
    vfloat k = vf_div(vf_set1(2.0f), sq);
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) p[c] = vf_load(B->p[c] + h);
    dqs_pos(q, k, p, o);
    if (!all) {
#pragma GCC unroll 3
        for (int c = 0; c < 3; c++) o[c] = vf_sel(ok, o[c], p[c]);
    }
    plan_store(L, B, h, pos_out, o);
    if (!nrm_out) return;
    vfloat nn[3];
#pragma GCC unroll 3
    for (int c = 0; c < 3; c++) nn[c] = vf_load(B->nrm[c] + h);
    dqs_nrm(q, k, nn, o);
    if (!all) {
#pragma GCC unroll 3
        for (int c = 0; c < 3; c++) o[c] = vf_sel(ok, o[c], nn[c]);
    }
    plan_store(L, B, h, nrm_out, o);
}

void SIMD_FN(kin__skin_dqs_plan)(const kin__plan_batch *bt, int b0, int b1, const void *xf,
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
        case 1: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) dqs_plan_lanes(B, 1, neg, h, dq, &L, pos_out, nrm_out); break;
        case 2: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) dqs_plan_lanes(B, 2, neg, h, dq, &L, pos_out, nrm_out); break;
        case 3: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) dqs_plan_lanes(B, 3, neg, h, dq, &L, pos_out, nrm_out); break;
        default: for (int h = 0; h < KIN__PLAN_W; h += SIMD_W) dqs_plan_lanes(B, 4, neg, h, dq, &L, pos_out, nrm_out); break;
        }
    }
}

#undef CROSS
