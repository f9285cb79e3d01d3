/* fuse_body.inl - the lighting row kernel written once against lane
 * macros (the MaskedOcclusionCulling way) and included by fuse_sse2.c,
 * fuse_avx2.c and fuse_avx512.c. It repeats fuse__light_span_ref (in
 * fuse_ref.c) operation for operation, in the same order, with the same
 * constants, so every lane gives the reference's bits: IEEE +, -, *, /,
 * sqrt, an exact floor, compares and selects, integer bit operations. No
 * FMA (the files are compiled with -ffp-contract=off and every operation is
 * an explicit intrinsic), no rcp/rsqrt.
 *
 * The including file defines:
 *   LANES            lanes per vector
 *   VF, VI, VM       float vector, int32 vector, lane mask
 *   F1(c), I1(c)     broadcasts
 *   FADD FSUB FMUL FDIV(a, b), FSQRT(a), FNEG(a) (sign flip)
 *   FMAX0(a)         a > 0 ? a : +0 (x86 max(a, 0) semantics)
 *   FMIN1(a)         a < 1 ? a : 1
 *   FGT FGE FLT(a, b) -> VM (ordered)
 *   MAND(m, n)
 *   FSEL(m, a, b)    m ? a : b;    FZERO_UNLESS(m, a)  m ? a : 0
 *   FFLOOR(a)        exact floorf
 *   I2F(i)  F2I_TRUNC(f)  (cvtt)  FBITS(f) (as int)  IBITS(i) (as float)
 *   IADD ISUB IAND IOR(a, b), ISRL(a, k), ISLL(a, k)
 *   LANE_INDEX       I vector 0, 1, 2, ...
 *   MASK_ZERO(p)     1 if the LANES mask bytes at p are all 0
 *   LOAD_MASK(p)     LANES mask bytes -> VI
 *   LOAD_RGBA(p)     LANES RGBA8 pixels -> VI (one pixel per lane)
 *   LOAD_NORMALS(p, x, y, z)  3 LANES floats, interleaved -> three VF
 *   STORE_RGBA(p, v) VI -> LANES pixels
 *   STORE_ZERO(p)    LANES zero pixels
 *   IZERO_IF_EQ0(m, v)  m == 0 (int lanes) ? 0 : v
 *   LIGHT_ROW_NAME   the function's name
 */

/* The kernels below work on nu = 1 or 2 vectors at once (U_MAX at most):
 * every step is written as a loop over the vectors (EACH), which the
 * compiler unrolls completely, so the two vectors' long dependency chains
 * (rsqrt, the power's polynomials) interleave and the core has independent
 * work while one chain waits. The operations per lane are the same either
 * way: the bytes do not depend on nu. */
#define U_MAX 2
#define EACH _Pragma("GCC unroll 2") for (u = 0; u < nu; u++)

/* fuse__pow01 in lanes, for nu vectors x[u]; s broadcast, n =
 * fuse__pow_int(s) (uniform: the squarings of fuse__powi01 when n > 0). */
static inline __attribute__((always_inline)) void pow01_lanes(const VF *x, VF s, int n, int nu, VF *r)
{
    VI e[U_MAX];
    VF m[U_MAX], ef[U_MAX], t[U_MAX], t2[U_MAX], p[U_MAX], y[U_MAX], k[U_MAX], f[U_MAX];
    VM big[U_MAX];
    int u;
    if (n > 0) {
        VF b[U_MAX];
        int k = n;
        EACH {
            b[u] = x[u];
            p[u] = F1(1.0f);
        }
        for (;;) {
            if (k & 1) EACH p[u] = FMUL(p[u], b[u]);
            k >>= 1;
            if (k == 0) break;
            EACH b[u] = FMUL(b[u], b[u]);
        }
        EACH {   /* the early returns of fuse__pow01 */
            const VF q = FSEL(FGE(x[u], F1(1.0f)), F1(1.0f), p[u]);
            r[u] = FZERO_UNLESS(FGT(x[u], F1(FUSE__POW_MIN)), q);
        }
        return;
    }
    EACH {
        const VI bits = FBITS(x[u]);
        e[u] = ISUB(ISRL(bits, 23), I1(127));
        m[u] = IBITS(IOR(IAND(bits, I1(0x007fffff)), I1(0x3f800000)));
        big[u] = FGT(m[u], F1(FUSE__SQRT2));
        m[u] = FSEL(big[u], FMUL(m[u], F1(0.5f)), m[u]);
        ef[u] = I2F(e[u]);
        ef[u] = FSEL(big[u], FADD(ef[u], F1(1.0f)), ef[u]);      /* (float)(e + 1), exact */
    }
    EACH t[u] = FDIV(FSUB(m[u], F1(1.0f)), FADD(m[u], F1(1.0f)));
    EACH t2[u] = FMUL(t[u], t[u]);
    EACH p[u] = F1(FUSE__LOG2_C9);
    EACH p[u] = FADD(FMUL(p[u], t2[u]), F1(FUSE__LOG2_C7));
    EACH p[u] = FADD(FMUL(p[u], t2[u]), F1(FUSE__LOG2_C5));
    EACH p[u] = FADD(FMUL(p[u], t2[u]), F1(FUSE__LOG2_C3));
    EACH p[u] = FADD(FMUL(p[u], t2[u]), F1(FUSE__LOG2_C1));
    EACH y[u] = FMUL(s, FADD(ef[u], FMUL(p[u], t[u])));
    EACH k[u] = FFLOOR(FADD(y[u], F1(0.5f)));
    EACH f[u] = FSUB(y[u], k[u]);
    EACH p[u] = F1(FUSE__EXP2_C7);
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C6));
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C5));
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C4));
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C3));
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C2));
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C1));
    EACH p[u] = FADD(FMUL(p[u], f[u]), F1(FUSE__EXP2_C0));
    EACH {
        VF q = FMUL(p[u], IBITS(ISLL(IADD(F2I_TRUNC(k[u]), I1(127)), 23)));
        /* the early returns of fuse__pow01, last one first */
        q = FSEL(FLT(y[u], F1(-126.0f)), F1(0.0f), q);
        q = FSEL(FGE(x[u], F1(1.0f)), F1(1.0f), q);
        r[u] = FZERO_UNLESS(FGT(x[u], F1(FUSE__POW_MIN)), q);
    }
}

static inline VF clamp01_lanes(VF v)
{
    return FZERO_UNLESS(FGT(v, F1(0.0f)), FMIN1(v));
}

/* (int)(v * 255 + 0.5), v in [0, 1] */
static inline VI unorm8_lanes(VF v)
{
    return F2I_TRUNC(FADD(FMUL(v, F1(255.0f)), F1(0.5f)));
}

/* The pixels x .. x + nu LANES - 1 of the row (fuse__light_span_ref lane
 * by lane), stored to out. */
static inline __attribute__((always_inline)) void light_lanes(const fuse__light_prep *p, VF py,
                                                              int x, int nu, const uint8_t *P,
                                                              const uint8_t *mask,
                                                              const float *normal, uint8_t *out)
{
    const VF one = F1(1.0f), inv255 = F1(FUSE__INV255);
    VI Mi[U_MAX], pix;
    VF px[U_MAX], il[U_MAX], vx[U_MAX], vy[U_MAX], vz[U_MAX], nx[U_MAX], ny[U_MAX], nz[U_MAX];
    VF nn[U_MAX], inv[U_MAX], ndv[U_MAX], C0[U_MAX], C1[U_MAX], C2[U_MAX];
    VM ok[U_MAX];
    int u, i;
    EACH {
        Mi[u] = LOAD_MASK(mask + x + u * LANES);
        px[u] = FMUL(FSUB(FADD(I2F(IADD(I1(x + u * LANES), LANE_INDEX)), F1(0.5f)), F1(p->cx)),
                     F1(p->ifx));
    }
    EACH il[u] = FDIV(one, FSQRT(FADD(FADD(FMUL(px[u], px[u]), FMUL(py, py)), one)));
    EACH {
        vx[u] = FNEG(FMUL(px[u], il[u]));
        vy[u] = FMUL(py, il[u]);
        vz[u] = il[u];
    }
    EACH {
        LOAD_NORMALS(normal + 3 * (size_t)(x + u * LANES), nx[u], ny[u], nz[u]);
        nn[u] = FADD(FADD(FMUL(nx[u], nx[u]), FMUL(ny[u], ny[u])), FMUL(nz[u], nz[u]));
        ok[u] = MAND(FGT(nn[u], F1(1.0e-30f)), FLT(nn[u], F1(1.0e30f)));
    }
    EACH inv[u] = FDIV(one, FSQRT(nn[u]));
    EACH {
        nx[u] = FSEL(ok[u], FMUL(nx[u], inv[u]), vx[u]);
        ny[u] = FSEL(ok[u], FMUL(ny[u], inv[u]), vy[u]);
        nz[u] = FSEL(ok[u], FMUL(nz[u], inv[u]), vz[u]);
        ndv[u] = FADD(FADD(FMUL(nx[u], vx[u]), FMUL(ny[u], vy[u])), FMUL(nz[u], vz[u]));
        C0[u] = F1(p->ambient[0]);
        C1[u] = F1(p->ambient[1]);
        C2[u] = F1(p->ambient[2]);
    }
    for (i = 0; i < p->light_count; i++) {
        const VF lx = F1(p->dir[i][0]), ly = F1(p->dir[i][1]), lz = F1(p->dir[i][2]);
        VF w[U_MAX];
        EACH w[u] = FMUL(F1(p->kd), FMAX0(FADD(FADD(FMUL(nx[u], lx), FMUL(ny[u], ly)), FMUL(nz[u], lz))));
        if (p->ks != 0.0f) {
            VF hh[U_MAX], ndh[U_MAX], sp[U_MAX];
            EACH {
                const VF hx = FADD(lx, vx[u]), hy = FADD(ly, vy[u]), hz = FADD(lz, vz[u]);
                hh[u] = FADD(FADD(FMUL(hx, hx), FMUL(hy, hy)), FMUL(hz, hz));
                ndh[u] = FADD(FADD(FMUL(nx[u], hx), FMUL(ny[u], hy)), FMUL(nz[u], hz));
            }
            EACH ndh[u] = FDIV(ndh[u], FSQRT(hh[u]));
            pow01_lanes(ndh, F1(p->shininess), p->ipow, nu, sp);
            EACH w[u] = FSEL(FGT(hh[u], F1(1.0e-12f)), FADD(w[u], FMUL(F1(p->ks), sp[u])), w[u]);
        }
        EACH {
            C0[u] = FADD(C0[u], FMUL(F1(p->color[i][0]), w[u]));
            C1[u] = FADD(C1[u], FMUL(F1(p->color[i][1]), w[u]));
            C2[u] = FADD(C2[u], FMUL(F1(p->color[i][2]), w[u]));
        }
    }
    EACH {
        const VF t = clamp01_lanes(FSUB(one, ndv[u]));
        const VF t2 = FMUL(t, t);
        const VF fade = clamp01_lanes(FSUB(one, FMUL(F1(p->kf), FMUL(FMUL(t2, t2), t))));
        const VF mp = FMUL(FMUL(I2F(Mi[u]), inv255), fade);
        VF v0, v1, v2;
        VI rgba;
        pix = LOAD_RGBA(P + 4 * (size_t)(x + u * LANES));
        v0 = clamp01_lanes(FMUL(FMUL(FMUL(I2F(IAND(pix, I1(255))), inv255), C0[u]), F1(p->tone[0])));
        v1 = clamp01_lanes(FMUL(FMUL(FMUL(I2F(IAND(ISRL(pix, 8), I1(255))), inv255), C1[u]), F1(p->tone[1])));
        v2 = clamp01_lanes(FMUL(FMUL(FMUL(I2F(IAND(ISRL(pix, 16), I1(255))), inv255), C2[u]), F1(p->tone[2])));
        rgba = IOR(IOR(unorm8_lanes(FMUL(mp, v0)), ISLL(unorm8_lanes(FMUL(mp, v1)), 8)),
                   IOR(ISLL(unorm8_lanes(FMUL(mp, v2)), 16), ISLL(unorm8_lanes(mp), 24)));
        STORE_RGBA(out + 4 * (size_t)(x + u * LANES), IZERO_IF_EQ0(Mi[u], rgba));
    }
}

/* Two vectors a step where both have mask bytes, one where only one has,
 * a zero store where neither has (the reference's M == 0 pixels). */
void LIGHT_ROW_NAME(const fuse__light_prep *p, int y, int width,
                    const uint8_t *P, const uint8_t *mask,
                    const float *normal, uint8_t *out)
{
    const VF py = F1((((float)y + 0.5f) - p->cy) * p->ify);
    int x = 0;
    for (; x + 2 * LANES <= width; x += 2 * LANES) {
        const int z0 = MASK_ZERO(mask + x), z1 = MASK_ZERO(mask + x + LANES);
        if (!z0 && !z1) {
            light_lanes(p, py, x, 2, P, mask, normal, out);
            continue;
        }
        if (z0) STORE_ZERO(out + 4 * (size_t)x);
        else light_lanes(p, py, x, 1, P, mask, normal, out);
        if (z1) STORE_ZERO(out + 4 * (size_t)(x + LANES));
        else light_lanes(p, py, x + LANES, 1, P, mask, normal, out);
    }
    for (; x + LANES <= width; x += LANES) {
        if (MASK_ZERO(mask + x)) STORE_ZERO(out + 4 * (size_t)x);
        else light_lanes(p, py, x, 1, P, mask, normal, out);
    }
    if (x < width)
        fuse__light_span_ref(p, y, x, width, P, mask, normal, out);
}

/* pow01_lanes over an array (tests compare its float bits with
 * fuse__pow01): out[i] = pow01(x[i], s). */
void POW_ROW_NAME(const float *x, int n, float s, float *out)
{
    int i = 0;
    for (; i + LANES <= n; i += LANES) {
        float tmp[LANES];
        VF r;
        VF v;
        memcpy(tmp, x + i, sizeof tmp);
        v = LOADF(tmp);
        pow01_lanes(&v, F1(s), fuse__pow_int(s), 1, &r);
        STOREF(tmp, r);
        memcpy(out + i, tmp, sizeof tmp);
    }
    for (; i < n; i++) out[i] = fuse__pow01(x[i], s);
}
