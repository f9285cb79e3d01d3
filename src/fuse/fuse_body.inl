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

/* fuse__pow01 in lanes; s broadcast. */
static inline VF pow01_lanes(VF x, VF s)
{
    const VI bits = FBITS(x);
    VI e = ISUB(ISRL(bits, 23), I1(127));
    VF m = IBITS(IOR(IAND(bits, I1(0x007fffff)), I1(0x3f800000)));
    const VM big = FGT(m, F1(FUSE__SQRT2));
    VF ef, t, t2, p, l, y, k, f, r;
    m = FSEL(big, FMUL(m, F1(0.5f)), m);
    ef = I2F(e);
    ef = FSEL(big, FADD(ef, F1(1.0f)), ef);      /* (float)(e + 1), exact */
    t = FDIV(FSUB(m, F1(1.0f)), FADD(m, F1(1.0f)));
    t2 = FMUL(t, t);
    p = F1(FUSE__LOG2_C9);
    p = FADD(FMUL(p, t2), F1(FUSE__LOG2_C7));
    p = FADD(FMUL(p, t2), F1(FUSE__LOG2_C5));
    p = FADD(FMUL(p, t2), F1(FUSE__LOG2_C3));
    p = FADD(FMUL(p, t2), F1(FUSE__LOG2_C1));
    l = FADD(ef, FMUL(p, t));
    y = FMUL(s, l);
    k = FFLOOR(FADD(y, F1(0.5f)));
    f = FSUB(y, k);
    p = F1(FUSE__EXP2_C7);
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C6));
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C5));
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C4));
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C3));
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C2));
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C1));
    p = FADD(FMUL(p, f), F1(FUSE__EXP2_C0));
    r = FMUL(p, IBITS(ISLL(IADD(F2I_TRUNC(k), I1(127)), 23)));
    /* the early returns of fuse__pow01, last one first */
    r = FSEL(FLT(y, F1(-126.0f)), F1(0.0f), r);
    r = FSEL(FGE(x, F1(1.0f)), F1(1.0f), r);
    r = FZERO_UNLESS(FGT(x, F1(FUSE__POW_MIN)), r);
    return r;
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

void LIGHT_ROW_NAME(const fuse__light_prep *p, int y, int width,
                    const uint8_t *P, const uint8_t *mask,
                    const float *normal, uint8_t *out)
{
    const float pys = (((float)y + 0.5f) - p->cy) * p->ify;
    const VF py = F1(pys), one = F1(1.0f), inv255 = F1(FUSE__INV255);
    const VF cx = F1(p->cx), ifx = F1(p->ifx);
    const VF kd = F1(p->kd), ks = F1(p->ks), sh = F1(p->shininess), kf = F1(p->kf);
    const int spec = p->ks != 0.0f;
    int x = 0;
    for (; x + LANES <= width; x += LANES) {
        VI Mi, pix, rgba;
        VF px, il, vx, vy, vz, nx, ny, nz, nn, ndv, t, fade, mp, inv;
        VF C0, C1, C2, v0, v1, v2;
        VM ok;
        int i;
        if (MASK_ZERO(mask + x)) {
            STORE_ZERO(out + 4 * (size_t)x);
            continue;
        }
        Mi = LOAD_MASK(mask + x);
        px = FMUL(FSUB(FADD(I2F(IADD(I1(x), LANE_INDEX)), F1(0.5f)), cx), ifx);
        il = FDIV(one, FSQRT(FADD(FADD(FMUL(px, px), FMUL(py, py)), one)));
        vx = FNEG(FMUL(px, il));
        vy = FMUL(py, il);
        vz = il;
        LOAD_NORMALS(normal + 3 * (size_t)x, nx, ny, nz);
        nn = FADD(FADD(FMUL(nx, nx), FMUL(ny, ny)), FMUL(nz, nz));
        ok = MAND(FGT(nn, F1(1.0e-30f)), FLT(nn, F1(1.0e30f)));
        inv = FDIV(one, FSQRT(nn));
        nx = FSEL(ok, FMUL(nx, inv), vx);
        ny = FSEL(ok, FMUL(ny, inv), vy);
        nz = FSEL(ok, FMUL(nz, inv), vz);
        ndv = FADD(FADD(FMUL(nx, vx), FMUL(ny, vy)), FMUL(nz, vz));
        C0 = F1(p->ambient[0]);
        C1 = F1(p->ambient[1]);
        C2 = F1(p->ambient[2]);
        for (i = 0; i < p->light_count; i++) {
            const VF lx = F1(p->dir[i][0]), ly = F1(p->dir[i][1]), lz = F1(p->dir[i][2]);
            VF w = FMUL(kd, FMAX0(FADD(FADD(FMUL(nx, lx), FMUL(ny, ly)), FMUL(nz, lz))));
            if (spec) {
                const VF hx = FADD(lx, vx), hy = FADD(ly, vy), hz = FADD(lz, vz);
                const VF hh = FADD(FADD(FMUL(hx, hx), FMUL(hy, hy)), FMUL(hz, hz));
                const VF ndh = FDIV(FADD(FADD(FMUL(nx, hx), FMUL(ny, hy)), FMUL(nz, hz)),
                                    FSQRT(hh));
                w = FSEL(FGT(hh, F1(1.0e-12f)), FADD(w, FMUL(ks, pow01_lanes(ndh, sh))), w);
            }
            C0 = FADD(C0, FMUL(F1(p->color[i][0]), w));
            C1 = FADD(C1, FMUL(F1(p->color[i][1]), w));
            C2 = FADD(C2, FMUL(F1(p->color[i][2]), w));
        }
        t = FMAX0(FSUB(one, ndv));
        fade = clamp01_lanes(FSUB(one, FMUL(kf, FMUL(t, t))));
        mp = FMUL(FMUL(I2F(Mi), inv255), fade);
        pix = LOAD_RGBA(P + 4 * (size_t)x);
        v0 = clamp01_lanes(FMUL(FMUL(FMUL(I2F(IAND(pix, I1(255))), inv255), C0), F1(p->tone[0])));
        v1 = clamp01_lanes(FMUL(FMUL(FMUL(I2F(IAND(ISRL(pix, 8), I1(255))), inv255), C1), F1(p->tone[1])));
        v2 = clamp01_lanes(FMUL(FMUL(FMUL(I2F(IAND(ISRL(pix, 16), I1(255))), inv255), C2), F1(p->tone[2])));
        rgba = IOR(IOR(unorm8_lanes(FMUL(mp, v0)), ISLL(unorm8_lanes(FMUL(mp, v1)), 8)),
                   IOR(ISLL(unorm8_lanes(FMUL(mp, v2)), 16), ISLL(unorm8_lanes(mp), 24)));
        STORE_RGBA(out + 4 * (size_t)x, IZERO_IF_EQ0(Mi, rgba));
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
        memcpy(tmp, x + i, sizeof tmp);
        r = pow01_lanes(LOADF(tmp), F1(s));
        STOREF(tmp, r);
        memcpy(out + i, tmp, sizeof tmp);
    }
    for (; i < n; i++) out[i] = fuse__pow01(x[i], s);
}
