/* fuse_simd.inl - the fuse kernels written once on the vector layer
 * (src/cpu/simd.h) and compiled once per ISA: fuse_sse2.c, fuse_avx2.c,
 * fuse_avx512.c and fuse_neon.c each include their ISA's simd_<isa>.h,
 * define what that ISA does its own way (below), and include this file,
 * which defines, with SIMD_FN's suffix (_sse2, _avx2, _avx512, _neon):
 *
 *   fuse__light_row     the lighting of one layer row (fuse__light_fn)
 *   fuse__light_span    the same on a span of the row (fuse__light_span_fn)
 *   fuse__light_span_n10  the same with ef_n10 normals (fuse__light_span_n10_fn)
 *   fuse__pow01_row     the lane power over an array (for the tests)
 *   fuse__depth_row     the depth test on a layer row (fuse__depth_fn)
 *   fuse__depth_mrow    the same on mask bytes (fuse__depth_mask_fn)
 *   fuse__depth_mspan   the same on a span of the mask row (fuse__depth_mspan_fn)
 *   fuse__cover_row     coverage bits of a layer row (fuse__cover_fn)
 *   fuse__cover_span    the same reading a span only (fuse__cover_span_fn)
 *   fuse__opaque        R = V | alpha 255 (fuse__opaque_fn)
 *   fuse__hprep, fuse__hrow, fuse__vrow  the row cache (FUSE_ROWCACHE_ON_LAYER)
 *
 * Each repeats the reference (fuse_ref.c, fuse_depth.c) operation for
 * operation, in the same order, with the same constants, so every lane
 * gives the reference's bits: IEEE +, -, *, /, sqrt, an exact floor,
 * compares and selects, integer bit operations (the layer's contract). No
 * FMA (-ffp-contract=off and explicit operations), no rcp/rsqrt.
 *
 * What an ISA file may define before including this one (defaults here):
 *   FUSE_SCENE_LANES(p, sc, ox, has)  the scene depths sc[ox[l]] of the
 *       lanes in has (others: anything finite or 0, never used). Default:
 *       a lane loop; AVX2/AVX-512 load a window of the row and permute
 *       when the lanes' columns lie close together, else gather.
 *   FUSE_LOAD_NORMALS(p, x, y, z)  SIMD_W interleaved normals into three
 *       vfloat lvalues; default vf_load3. SSE2 builds each vector from
 *       scalar loads (the layer's vf_load3 goes through a stack buffer,
 *       which made the SSE2 lighting about 20% slower); AVX2 from 128-bit
 *       loads and shufps (fewer instructions than its vf_load3).
 *   FUSE_LOAD_N10(p, x, y, z)  SIMD_W normals packed as ef_n10 into three
 *       vfloat lvalues; default load_n10 (one load, three shift pairs,
 *       conversions and multiplies on the layer), which every ISA uses.
 *   FUSE_ALPHA4(q)  (the row cache's vrow) each pixel's alpha, 16-bit
 *       lane 3 of its 4, in all 4 lanes; default vh_bcast3 (two word
 *       shuffles). AVX2 and AVX-512 use one pshufb.
 *   FUSE_ALPHA255(q0, q1)  (vrow) 1 when every alpha lane of q0 and q1 is
 *       255; default FUSE_ALPHA4 and a compare. AVX2: one vptest;
 *       AVX-512: one masked word compare.
 *   FUSE_ZERO(v)  (hrow) 1 when v is all zero bits; default vi_eq and
 *       vm_all (compare, movemask, compare). AVX2: vptest; AVX-512:
 *       vptestmd. */
#include <string.h>

#include "../cpu/ef_n10.h"

/* 1 if the SIMD_W mask bytes at p are all 0 */
SIMD_INL int mask_zero(const uint8_t *p)
{
#if SIMD_W == 4
    uint32_t a;
    memcpy(&a, p, 4);
    return a == 0;
#elif SIMD_W == 8
    uint64_t a;
    memcpy(&a, p, 8);
    return a == 0;
#else
    uint64_t a, b;
    memcpy(&a, p, 8);
    memcpy(&b, p + 8, 8);
    return (a | b) == 0;
#endif
}

#define LANES SIMD_W
#define VF vfloat
#define VI vint
#define VM vmask
#define F1(c) vf_set1(c)
#define I1(c) vi_set1(c)
#define FADD(a, b) vf_add(a, b)
#define FSUB(a, b) vf_sub(a, b)
#define FMUL(a, b) vf_mul(a, b)
#define FDIV(a, b) vf_div(a, b)
#define FSQRT(a) vf_sqrt(a)
#define FNEG(a) vf_neg(a)
#define FMAX0(a) vf_max(a, vf_zero())        /* a > 0 ? a : +0 */
#define FMIN1(a) vf_min(a, vf_set1(1.0f))    /* a < 1 ? a : 1 */
#define FGT(a, b) vf_gt(a, b)
#define FGE(a, b) vf_ge(a, b)
#define FLT(a, b) vf_lt(a, b)
#define MAND(a, b) vm_and(a, b)
#define FSEL(m, a, b) vf_sel(m, a, b)
#define FZERO_UNLESS(m, a) vf_selz(m, a)
#define FFLOOR(a) vf_floor(a)
#define I2F(i) vf_from_vi(i)
#define F2I_TRUNC(f) vi_from_vf_trunc(f)
#define FBITS(f) vf_as_vi(f)
#define IBITS(i) vi_as_vf(i)
#define IADD(a, b) vi_add(a, b)
#define ISUB(a, b) vi_sub(a, b)
#define IAND(a, b) vi_and(a, b)
#define IOR(a, b) vi_or(a, b)
#define ISRL(a, k) vi_srli(a, k)
#define ISLL(a, k) vi_slli(a, k)
#define LANE_INDEX vi_lanes()
#define MASK_ZERO(p) mask_zero(p)
#define LOAD_MASK(p) vi_load_u8(p)
#define LOAD_RGBA(p) vi_loadu((const int32_t *)(const void *)(p))
#ifdef FUSE_LOAD_NORMALS
#define LOAD_NORMALS(p, x, y, z) FUSE_LOAD_NORMALS(p, x, y, z)
#else
#define LOAD_NORMALS(p, x, y, z) vf_load3(p, &(x), &(y), &(z))
#endif
/* SIMD_W normals packed as ef_n10 (src/cpu/ef_n10.h), one int32 lane a
 * pixel, into three vfloat lvalues: each 10-bit field shifted to the top
 * of the lane and back down arithmetically (its sign extended; bits 30-31
 * fall off the top, ignored as ef_n10_k ignores them), converted (exact:
 * |k| <= 512) and multiplied by EF_N10_INV: ef_n10_unpack's floats, lane
 * by lane. Written once, on the layer, for every ISA. */
#ifndef FUSE_LOAD_N10
SIMD_INL void load_n10(const uint32_t *p, VF *x, VF *y, VF *z)
{
    const VI v = vi_loadu((const int32_t *)(const void *)p);
    const VF s = F1(EF_N10_INV);
    *x = FMUL(I2F(vi_srai(ISLL(v, 22), 22)), s);
    *y = FMUL(I2F(vi_srai(ISLL(v, 12), 22)), s);
    *z = FMUL(I2F(vi_srai(ISLL(v, 2), 22)), s);
}
#define FUSE_LOAD_N10(p, x, y, z) load_n10(p, &(x), &(y), &(z))
#endif
#define STORE_RGBA(p, v) vi_storeu((int32_t *)(void *)(p), v)
#define STORE_ZERO(p) vi_storeu((int32_t *)(void *)(p), vi_zero())
#define LIGHT_ROW_NAME SIMD_FN(fuse__light_row)
#define POW_ROW_NAME SIMD_FN(fuse__pow01_row)
#define LOADF(p) vf_loadu(p)
#define STOREF(p, v) vf_storeu(p, v)

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

/* fuse__clamp01: v > 0 ? (v < 1 ? v : 1) : +0. As max(min(v, 1), +0) with
 * the layer's vf_min / vf_max (a < b ? a : b, a > b ? a : b): the same value
 * for every v but NaN (-0 gives +0 either way), one operation fewer; no NaN
 * reaches it (validated parameters, normals without a usable length
 * replaced: fuse_internal.h). */
static inline VF clamp01_lanes(VF v)
{
    return FMAX0(FMIN1(v));
}

/* fuse__spec01 in lanes, for nl lights (1 or 2, a constant at each call)
 * of nu vectors x2[j][u] (the squared cosines); n = fuse__pow_int(s)
 * (uniform). The squarings of the lights and vectors interleave. */
static inline __attribute__((always_inline)) void spec01_lanes(int nl, VF (*x2)[U_MAX], float s,
                                                               int n, int nu, VF (*r)[U_MAX])
{
    VF p[2][U_MAX];
    int j, u;
    if (n == 0) {
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++)
            pow01_lanes(x2[j], F1(s * 0.5f), fuse__pow_int(s * 0.5f), nu, r[j]);
        return;
    }
    /* x2 >= 1 -> 1: x2 = min(x2, 1) first (1^k = sqrtf(1) = 1), one
     * operation instead of a compare and a select */
    _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH x2[j][u] = FMIN1(x2[j][u]);
    if (n >= 2) {
        VF b[2][U_MAX];
        int k = n >> 1;
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH b[j][u] = x2[j][u];
        /* fuse__powi01's first product, 1 * b at the lowest set bit of k,
         * is b itself (the same bits): the squarings up to that bit, then
         * p = b, then the reference's loop from the next bit on */
        while (!(k & 1)) {
            k >>= 1;
            _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH b[j][u] = FMUL(b[j][u], b[j][u]);
        }
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH p[j][u] = b[j][u];
        for (k >>= 1; k != 0; k >>= 1) {
            _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH b[j][u] = FMUL(b[j][u], b[j][u]);
            if (k & 1) _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH p[j][u] = FMUL(p[j][u], b[j][u]);
        }
    } else {
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH p[j][u] = F1(1.0f);
    }
    if (n & 1) _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH p[j][u] = FMUL(p[j][u], FSQRT(x2[j][u]));
    /* x2 <= 2^-100 -> 0: with n >= 4 (n >> 1 >= 2) every product holds a
     * factor x2^(2^j), j >= 1, <= 2^-200, which rounds to +0: the result
     * is +0 without the test (x2 >= +0: a square times a positive). */
    if (n < 4) _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH
        r[j][u] = FZERO_UNLESS(FGT(x2[j][u], F1(FUSE__POW_MIN)), p[j][u]);
    else _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH r[j][u] = p[j][u];
}

/* The lighting's parameters for one span call, the floats broadcast once
 * into vectors in memory. The steps read them from here (as memory
 * operands where the registers run out) instead of broadcasting p's
 * floats again at every step, which the compiler must do while they are
 * read through p: a store to out (a byte pointer) may change *p. */
typedef struct light_vk {
    VF nifx, mo, kd, ks, kf;
    VF lanes;                     /* 0, 1, .. LANES - 1 */
    VF nn_min, nn_max, hh_min, magic;   /* the rule's constants */
    VI b255;
    VF amb[3];
    VF dir[FUSE_MAX_LIGHTS][3];   /* the first nl only */
    VF col[FUSE_MAX_LIGHTS][3];   /* color_t */
    float ks_s, shininess;
    int nl, ipow;
} light_vk;

static inline void light_vk_fill(light_vk *k, const fuse__light_prep *p)
{
    int i, c;
    k->nifx = F1(p->nifx);
    k->lanes = I2F(LANE_INDEX);
    k->nn_min = F1(1.0e-30f);
    k->nn_max = F1(1.0e30f);
    k->hh_min = F1(1.0e-12f);
    k->magic = F1(FUSE__MAGIC);
    k->b255 = I1(255);
    k->mo = F1(p->mo);
    k->kd = F1(p->kd);
    k->ks = F1(p->ks);
    k->kf = F1(p->kf);
    for (c = 0; c < 3; c++) k->amb[c] = F1(p->ambient_t[c]);
    for (i = 0; i < p->light_count; i++)
        for (c = 0; c < 3; c++) {
            k->dir[i][c] = F1(p->dir[i][c]);
            k->col[i][c] = F1(p->color_t[i][c]);
        }
    k->ks_s = p->ks;
    k->shininess = p->shininess;
    k->nl = p->light_count;
    k->ipow = p->ipow;
}

/* fuse__round8 before its last step: the bits of v + 2^23 (v in [0, 255]),
 * 0x4B000000 | round(v); the byte is the low 8 bits. */
static inline VI round_lanes(const light_vk *k, VF v)
{
    return FBITS(FADD(v, k->magic));
}

/* What lights i .. i + nl - 1 (nl = 1 or 2, a constant at each call) take
 * from V and N, for one vector (fuse__light_span_ref's light_terms):
 * hh_j = |L_j + V|^2, then nd_j = N.L_j / |n|. */
static inline __attribute__((always_inline)) void light_geom(const light_vk *k, int i, int nl,
                                                             VF vx, VF vy, VF vz, VF nx, VF ny,
                                                             VF nz, VF inv, VF *nd, VF *hh)
{
    int j;
    _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) {
        const VF hx = FADD(k->dir[i + j][0], vx), hy = FADD(k->dir[i + j][1], vy);
        const VF hz = FADD(k->dir[i + j][2], vz);
        hh[j] = FADD(FADD(FMUL(hx, hx), FMUL(hy, hy)), FMUL(hz, hz));
    }
    _Pragma("GCC unroll 2") for (j = 0; j < nl; j++)
        nd[j] = FMUL(FADD(FADD(FMUL(nx, k->dir[i + j][0]), FMUL(ny, k->dir[i + j][1])),
                          FMUL(nz, k->dir[i + j][2])), inv);
}

/* Lights i .. i + nl - 1 (nl = 1 or 2, a constant at each call) added to
 * C0..C2 from their nd and hh (light_geom): the diffuse weights, the
 * specular terms with one division for both 1 / hh of a pair
 * (fuse__light_span_ref). */
static inline __attribute__((always_inline)) void light_pair_lanes(
    const light_vk *k, int i, int nl, int nu, VF (*nd)[U_MAX], VF (*hh)[U_MAX], const VF *ndv,
    VF *C0, VF *C1, VF *C2)
{
    const VF one = F1(1.0f);
    VF w[2][U_MAX];
    int j, u;
    if (k->ks_s != 0.0f) {
        VF x2[2][U_MAX], sp[2][U_MAX];
        VM g[2][U_MAX];
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++)
            EACH {
                const VF n0 = FMAX0(FADD(nd[j][u], ndv[u]));
                g[j][u] = FGT(hh[j][u], k->hh_min);
                x2[j][u] = FMUL(n0, n0);
            }
        if (nl == 2) {
            EACH {
                const VF a0 = FSEL(g[0][u], hh[0][u], one), a1 = FSEL(g[1][u], hh[1][u], one);
                const VF d = FDIV(one, FMUL(a0, a1));
                x2[0][u] = FMUL(x2[0][u], FMUL(a1, d));
                x2[1][u] = FMUL(x2[1][u], FMUL(a0, d));
            }
        } else {
            EACH x2[0][u] = FDIV(x2[0][u], hh[0][u]);
        }
        spec01_lanes(nl, x2, k->shininess, k->ipow, nu, sp);
        /* g ? wd + ks sp : wd as wd + (g ? ks sp : +0): the same float
         * but where wd is -0 (kd <= -0), which becomes +0; C's sign of
         * zero never reaches a byte (round8 writes +-0 as 0). One select
         * on g fewer: with two, the compiler builds a second mask (AVX2) */
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++)
            EACH w[j][u] = FADD(FMUL(k->kd, FMAX0(nd[j][u])), FZERO_UNLESS(g[j][u], FMUL(k->ks, sp[j][u])));
    } else {
        _Pragma("GCC unroll 2") for (j = 0; j < nl; j++) EACH w[j][u] = FMUL(k->kd, FMAX0(nd[j][u]));
    }
    _Pragma("GCC unroll 2") for (j = 0; j < nl; j++)
        EACH {
            C0[u] = FADD(C0[u], FMUL(k->col[i + j][0], w[j][u]));
            C1[u] = FADD(C1[u], FMUL(k->col[i + j][1], w[j][u]));
            C2[u] = FADD(C2[u], FMUL(k->col[i + j][2], w[j][u]));
        }
}

/* The pixels x .. x + nu LANES - 1 of the row (fuse__light_span_ref lane
 * by lane), stored to out. pyy = py * py + 1 of the row. two: k->nl == 2;
 * n10: the normals are nq's (ef_n10), else normal's (3 floats a pixel);
 * constants at each call. */
static inline __attribute__((always_inline)) void light_lanes(const light_vk *k, VF py, VF pyy,
                                                              int x, int nu, const uint8_t *P,
                                                              const uint8_t *mask,
                                                              const float *normal,
                                                              const uint32_t *nq, uint8_t *out,
                                                              int fres, int nonneg, int two,
                                                              int n10)
{
    const VF one = F1(1.0f);
    VF mpx[U_MAX], vv[U_MAX], sv[U_MAX], sn[U_MAX], r[U_MAX], il[U_MAX], inv[U_MAX];
    VF nx[U_MAX], ny[U_MAX], nz[U_MAX], nn[U_MAX], ndv[U_MAX], C0[U_MAX], C1[U_MAX], C2[U_MAX];
    VF nd[2][U_MAX], hh[2][U_MAX], xf[U_MAX];
    VM ok[U_MAX];
    int u, i;
    /* (float)(x + l) of lane l, as (float)x + l: exact (integers below
     * 2^24), one conversion a step */
    xf[0] = FADD(F1((float)x), k->lanes);
    if (nu == 2) xf[1] = FADD(xf[0], F1((float)LANES));
    EACH {
        mpx[u] = FADD(FMUL(xf[u], k->nifx), k->mo);
        vv[u] = FADD(FMUL(mpx[u], mpx[u]), pyy);
    }
    EACH {
        if (n10) FUSE_LOAD_N10(nq + x + u * LANES, nx[u], ny[u], nz[u]);
        else LOAD_NORMALS(normal + 3 * (size_t)(x + u * LANES), nx[u], ny[u], nz[u]);
        nn[u] = FADD(FADD(FMUL(nx[u], nx[u]), FMUL(ny[u], ny[u])), FMUL(nz[u], nz[u]));
        ok[u] = MAND(FGT(nn[u], k->nn_min), FLT(nn[u], k->nn_max));
    }
    EACH {
        sv[u] = FSQRT(vv[u]);
        sn[u] = FSQRT(nn[u]);
    }
    EACH {
        nx[u] = FSEL(ok[u], nx[u], mpx[u]);
        ny[u] = FSEL(ok[u], ny[u], py);
        nz[u] = FSEL(ok[u], nz[u], one);
        sn[u] = FSEL(ok[u], sn[u], sv[u]);
    }
    EACH r[u] = FDIV(one, FMUL(sn[u], sv[u]));
    EACH {
        il[u] = FMUL(sn[u], r[u]);
        inv[u] = FMUL(sv[u], r[u]);
        ndv[u] = FMUL(FADD(FADD(FMUL(nx[u], mpx[u]), FMUL(ny[u], py)), nz[u]), r[u]);
        C0[u] = k->amb[0];
        C1[u] = k->amb[1];
        C2[u] = k->amb[2];
    }
    if (two) {
        /* the two lights in one pass: V's and N's terms are used up here
         * (fewer live vectors during the rest) */
        EACH {
            VF ndj[2], hhj[2];
            light_geom(k, 0, 2, FMUL(mpx[u], il[u]), FMUL(py, il[u]), il[u], nx[u], ny[u], nz[u],
                       inv[u], ndj, hhj);
            nd[0][u] = ndj[0];
            nd[1][u] = ndj[1];
            hh[0][u] = hhj[0];
            hh[1][u] = hhj[1];
        }
        light_pair_lanes(k, 0, 2, nu, nd, hh, ndv, C0, C1, C2);
    } else {
        VF vx[U_MAX], vy[U_MAX];
        EACH {
            vx[u] = FMUL(mpx[u], il[u]);
            vy[u] = FMUL(py, il[u]);
        }
        for (i = 0; i < k->nl; i += 2) {
            const int nl = i + 2 <= k->nl ? 2 : 1;
            EACH {
                VF ndj[2], hhj[2];
                if (nl == 2)
                    light_geom(k, i, 2, vx[u], vy[u], il[u], nx[u], ny[u], nz[u], inv[u], ndj, hhj);
                else
                    light_geom(k, i, 1, vx[u], vy[u], il[u], nx[u], ny[u], nz[u], inv[u], ndj, hhj);
                nd[0][u] = ndj[0];
                hh[0][u] = hhj[0];
                if (nl == 2) {
                    nd[1][u] = ndj[1];
                    hh[1][u] = hhj[1];
                }
            }
            if (nl == 2) light_pair_lanes(k, i, 2, nu, nd, hh, ndv, C0, C1, C2);
            else light_pair_lanes(k, i, 1, nu, nd, hh, ndv, C0, C1, C2);
        }
    }
    EACH {
        VF m = I2F(LOAD_MASK(mask + x + u * LANES));
        VF v0, v1, v2;
        VI pix, rgba;
        /* kf == 0: fade = clamp01(1 - (+-0)) = 1 and M * 1 = M exactly */
        if (fres) {
            const VF t = clamp01_lanes(FSUB(one, ndv[u]));
            const VF t2 = FMUL(t, t);
            m = FMUL(m, clamp01_lanes(FSUB(one, FMUL(k->kf, FMUL(FMUL(t2, t2), t)))));
        }
        pix = LOAD_RGBA(P + 4 * (size_t)(x + u * LANES));
        v0 = FMUL(I2F(IAND(pix, k->b255)), C0[u]);
        v1 = FMUL(I2F(IAND(ISRL(pix, 8), k->b255)), C1[u]);
        v2 = FMUL(I2F(IAND(ISRL(pix, 16), k->b255)), C2[u]);
        /* c_nonneg: P_c C[c] >= -0, and max0 would only turn -0 into +0,
         * which round8 writes as 0 either way (m >= +0: m v is +-0) */
        if (nonneg) {
            v0 = FMIN1(v0);
            v1 = FMIN1(v1);
            v2 = FMIN1(v2);
        } else {
            v0 = clamp01_lanes(v0);
            v1 = clamp01_lanes(v1);
            v2 = clamp01_lanes(v2);
        }
        /* the shifts left by 8, 16, 24 drop the 0x4B of the upper bytes */
        rgba = IOR(IOR(IAND(round_lanes(k, FMUL(m, v0)), k->b255), ISLL(round_lanes(k, FMUL(m, v1)), 8)),
                   IOR(ISLL(round_lanes(k, FMUL(m, v2)), 16), ISLL(round_lanes(k, m), 24)));
        /* A lane with M == 0 is (0, 0, 0, 0) without a select: every value
         * above is finite there (a normal without a usable length is
         * replaced by v, P is a byte, the parameters are bounded), fade and
         * v lie in [0, 1], so m = 0 * fade = +0 and every channel rounds
         * +0 to 0, as the reference writes. */
        STORE_RGBA(out + 4 * (size_t)(x + u * LANES), rgba);
    }
}

/* Two vectors a step where both have mask bytes, one where only one has,
 * a zero store where neither has (the reference's M == 0 pixels). Pixels
 * x0 <= x of the row (fuse__light_span_ref; the pointers at pixel 0) in
 * whole vectors: returns the first pixel not done (x1 - x0 mod LANES are
 * left, which the caller's reference does). fres: p->kf != 0 (else the
 * fade, exactly 1, is not computed); nonneg: p->c_nonneg (the output clamp
 * without max0); two: p->light_count == 2; n10: the normals' form;
 * constants at each call, so each of the bodies is compiled without the
 * other cases' work. (The tail is the callers', one call each: a tail
 * choosing its reference by n10 in here made gcc lay out the float path's
 * code differently.) */
static inline __attribute__((always_inline)) int light_span_body(
    const light_vk *k, VF py, VF pyy, int x, int width,
    const uint8_t *P, const uint8_t *mask, const float *normal, const uint32_t *nq, uint8_t *out,
    int fres, int nonneg, int two, int n10)
{
    for (; x + 2 * LANES <= width; x += 2 * LANES) {
        const int z0 = MASK_ZERO(mask + x), z1 = MASK_ZERO(mask + x + LANES);
        if (!z0 && !z1) {
            light_lanes(k, py, pyy, x, 2, P, mask, normal, nq, out, fres, nonneg, two, n10);
            continue;
        }
        if (z0) STORE_ZERO(out + 4 * (size_t)x);
        else light_lanes(k, py, pyy, x, 1, P, mask, normal, nq, out, fres, nonneg, two, n10);
        if (z1) STORE_ZERO(out + 4 * (size_t)(x + LANES));
        else light_lanes(k, py, pyy, x + LANES, 1, P, mask, normal, nq, out, fres, nonneg, two, n10);
    }
    for (; x + LANES <= width; x += LANES) {
        if (MASK_ZERO(mask + x)) STORE_ZERO(out + 4 * (size_t)x);
        else light_lanes(k, py, pyy, x, 1, P, mask, normal, nq, out, fres, nonneg, two, n10);
    }
    return x;
}

/* one body per (fres, nonneg) pair, for two lights or any number */
static inline __attribute__((always_inline)) int light_span_lights(
    const light_vk *k, VF py, VF pyy, int x, int width,
    const uint8_t *P, const uint8_t *mask, const float *normal, const uint32_t *nq, uint8_t *out,
    int fres, int nonneg, int n10)
{
    if (k->nl == 2)
        return light_span_body(k, py, pyy, x, width, P, mask, normal, nq, out, fres, nonneg, 1, n10);
    return light_span_body(k, py, pyy, x, width, P, mask, normal, nq, out, fres, nonneg, 0, n10);
}

/* The span of a row with the normals' form n10 (a constant at each call:
 * the float and the n10 entry below each get their own eight bodies). */
static inline __attribute__((always_inline)) int light_span_form(
    const fuse__light_prep *p, int y, int x0, int width, const uint8_t *P, const uint8_t *mask,
    const float *normal, const uint32_t *nq, uint8_t *out, int n10)
{
    const float pys = (((float)y + 0.5f) - p->cy) * p->ify;
    const VF py = F1(pys), pyy = F1(pys * pys + 1.0f);
    light_vk k;
    light_vk_fill(&k, p);
    if (p->kf != 0.0f) {
        if (p->c_nonneg)
            return light_span_lights(&k, py, pyy, x0, width, P, mask, normal, nq, out, 1, 1, n10);
        else
            return light_span_lights(&k, py, pyy, x0, width, P, mask, normal, nq, out, 1, 0, n10);
    } else {
        if (p->c_nonneg)
            return light_span_lights(&k, py, pyy, x0, width, P, mask, normal, nq, out, 0, 1, n10);
        else
            return light_span_lights(&k, py, pyy, x0, width, P, mask, normal, nq, out, 0, 0, n10);
    }
}

void SIMD_FN(fuse__light_span)(const fuse__light_prep *p, int y, int x0, int width,
                               const uint8_t *P, const uint8_t *mask,
                               const float *normal, uint8_t *out)
{
    const int x = light_span_form(p, y, x0, width, P, mask, normal, NULL, out, 0);
    if (x < width) fuse__light_span_ref(p, y, x, width, P, mask, normal, out);
}

/* fuse__light_span_n10_fn: the normals packed as ef_n10 */
void SIMD_FN(fuse__light_span_n10)(const fuse__light_prep *p, int y, int x0, int width,
                                   const uint8_t *P, const uint8_t *mask,
                                   const uint32_t *normal, uint8_t *out)
{
    const int x = light_span_form(p, y, x0, width, P, mask, NULL, normal, out, 1);
    if (x < width) fuse__light_span_n10_ref(p, y, x, width, P, mask, normal, out);
}

void LIGHT_ROW_NAME(const fuse__light_prep *p, int y, int width,
                    const uint8_t *P, const uint8_t *mask,
                    const float *normal, uint8_t *out)
{
    SIMD_FN(fuse__light_span)(p, y, 0, width, P, mask, normal, out);
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

/* ---- depth test (fuse__depth_span_ref, SIMD_W pixels a step) ------------ */

#ifndef FUSE_SCENE_LANES
/* the scene's distances of the lanes in has, lane by lane (0 elsewhere) */
SIMD_INL vfloat fuse_scene_lanes(const fuse__depth_prep *p, const float *sc, vint ox, vmask has)
{
    _Alignas(64) int32_t c[SIMD_W];
    _Alignas(64) float s[SIMD_W];
    const unsigned hm = vm_bits(has);
    int l;
    (void)p;
    vi_store(c, ox);
    for (l = 0; l < SIMD_W; l++) s[l] = (hm >> l) & 1u ? sc[c[l]] : 0.0f;
    return vf_load(s);
}
#define FUSE_SCENE_LANES(p, sc, ox, has) fuse_scene_lanes(p, sc, ox, has)
#endif

/* The row on the layer (bpp 4: a pixel is looked at when it is not 0) or
 * on mask bytes (bpp 1: when its byte is not 0); hidden pixels are zeroed.
 * The column of each lane walks as fuse__depth_col's exact quotient and
 * remainder: stepped by SIMD_W pixels, 2 SIMD_W vw = sq den + sr. */
SIMD_INL void depth_row(const fuse__depth_prep *p, uint8_t *q, const float *hz, const float *sc,
                        int x0, int w, int bpp)
{
    const vfloat zero = vf_zero(), one = vf_set1(1.0f), two = vf_set1(2.0f);
    const vfloat two_fn = vf_set1(p->two_fn), fpn = vf_set1(p->fpn);
    const vfloat fmn = vf_set1(p->fmn), off = vf_set1(p->offset);
    const int32_t step = 2 * SIMD_W * p->vw;
    const vint den = vi_set1(p->den), den1 = vi_set1(p->den - 1);
    const vint sq = vi_set1(step / p->den), sr = vi_set1(step % p->den), one_i = vi_set1(1);
    _Alignas(64) int32_t ox0[SIMD_W], rem0[SIMD_W];
    vint ox, rem;
    int x, k;
    if (w - x0 < SIMD_W) {
        if (bpp == 4) fuse__depth_span_ref(p, q, hz, sc, x0, w);
        else fuse__depth_mspan_ref(p, q, hz, sc, x0, w);
        return;
    }
    for (k = 0; k < SIMD_W; k++) fuse__depth_col(p, x0 + k, &ox0[k], &rem0[k]);
    ox = vi_load(ox0);
    rem = vi_load(rem0);
    for (x = x0; x + SIMD_W <= w; x += SIMD_W) {
        vint qq;
        int any;
        if (bpp == 4) {
            qq = vi_loadu((const int32_t *)(const void *)(q + 4 * (size_t)x));
            any = !vm_all(vi_eq(qq, vi_zero()));
        } else {
            any = !mask_zero(q + x);
            qq = any ? vi_load_u8(q + x) : vi_zero();
        }
        if (any) {
            const vfloat z = vf_loadu(hz + x);
            /* qq != 0 as ~(qq == 0) inside the andnot (no all-ones
             * constant, one operation fewer) */
            const vmask has = vm_andnot(vi_eq(qq, vi_zero()), vm_and(vf_ge(z, zero), vf_lt(z, one)));
            if (vm_any(has)) {
                const vfloat s = FUSE_SCENE_LANES(p, sc, ox, has);
                const vfloat dist = vf_add(
                    vf_div(two_fn, vf_sub(fpn, vf_mul(vf_sub(vf_mul(two, z), one), fmn))), off);
                const vmask kill = vm_and(has, vm_and(vf_gt(s, zero), vf_lt(s, dist)));
                if (vm_any(kill)) {
                    if (bpp == 4) {   /* the row is this thread's: rewrite the rest */
                        vi_storeu((int32_t *)(void *)(q + 4 * (size_t)x), vi_sel(kill, vi_zero(), qq));
                    } else {
                        const unsigned km = vm_bits(kill);
                        for (k = 0; k < SIMD_W; k++)
                            if (km >> k & 1u) q[x + k] = 0;
                    }
                }
            }
        }
        rem = vi_add(rem, sr);
        {   /* the next SIMD_W columns: rem + sr carries at most once */
            const vmask carry = vi_gt(rem, den1);
            rem = vi_sel(carry, vi_sub(rem, den), rem);
            ox = vi_add(vi_add(ox, sq), vi_sel(carry, one_i, vi_zero()));
        }
    }
    if (bpp == 4) fuse__depth_span_ref(p, q, hz, sc, x, w);
    else fuse__depth_mspan_ref(p, q, hz, sc, x, w);
}

void SIMD_FN(fuse__depth_row)(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                              const float *sc, int w)
{
    depth_row(p, q, hz, sc, 0, w, 4);
}

void SIMD_FN(fuse__depth_mrow)(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                               const float *sc, int w)
{
    depth_row(p, m, hz, sc, 0, w, 1);
}

/* pixels x0 <= x < x1 of the mask row only (m, hz, sc at pixel 0) */
void SIMD_FN(fuse__depth_mspan)(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                                const float *sc, int x0, int x1)
{
    depth_row(p, m, hz, sc, x0, x1, 1);
}

/* ---- coverage bits and opaque copies (fuse_internal.h) ----------------- */

/* bit b set iff a byte of pixels [8b, 8b + 8) is not 0; only the pixels
 * [x0, x1) are read (the caller knows the others are 0: their bits are
 * 0), fuse__cover_span_fn */
void SIMD_FN(fuse__cover_span)(const uint8_t *q, int w, int x0, int x1, uint64_t *bits)
{
    const int nb = (w + 7) / 8;
    const int xa = x0 & ~(SIMD_W >= 8 ? SIMD_W - 1 : 7);   /* whole vectors (W >= 8) or blocks */
    const int xe = ((x1 + 7) & ~7) < w ? ((x1 + 7) & ~7) : w;
    const int ne = (xe + 7) / 8;
    int b = xa / 8, x;
    memset(bits, 0, 8u * (size_t)((nb + 63) / 64));
    if (x0 >= x1) return;
#if SIMD_W >= 8
    /* SIMD_W / 8 blocks per vector: the lanes' non-zero bits, 8 a block;
     * the 64 blocks (512 pixels) of one word of bits at a time, the word in
     * a register (b = x / 8 throughout: x is a multiple of SIMD_W) */
    x = xa;
    while (x + SIMD_W <= xe) {
        const int wi = b >> 6, xw = 512 * (wi + 1) < xe ? 512 * (wi + 1) : xe;
        uint64_t word = 0;
        for (; x + SIMD_W <= xw; x += SIMD_W, b += SIMD_W / 8) {
            const vint t = vi_loadu((const int32_t *)(const void *)(q + 4 * (size_t)x));
            const unsigned nzb = vm_bits(vi_eq(t, vi_zero())) ^ SIMD_FULL;
            unsigned pat = 0;
            int j;
            for (j = 0; j < SIMD_W / 8; j++) pat |= (unsigned)(((nzb >> (8 * j)) & 0xFFu) != 0) << j;
            /* b is a multiple of SIMD_W / 8, which divides 64: one word */
            word |= (uint64_t)pat << (b & 63);
        }
        bits[wi] |= word;
    }
#else
    /* 8 / SIMD_W vectors per block, or-ed */
    for (x = xa; x + 8 <= xe; x += 8, b++) {
        vint t = vi_loadu((const int32_t *)(const void *)(q + 4 * (size_t)x));
        int j;
        for (j = SIMD_W; j < 8; j += SIMD_W)
            t = vi_or(t, vi_loadu((const int32_t *)(const void *)(q + 4 * (size_t)(x + j))));
        bits[b >> 6] |= (uint64_t)!vm_all(vi_eq(t, vi_zero())) << (b & 63);
    }
#endif
    if (b < ne) {   /* the last blocks (xe % SIMD_W pixels) */
        for (; b < ne; b++) {
            const int xb = 8 * b + 8 < w ? 8 * b + 8 : w;
            uint32_t acc = 0, t;
            for (x = 8 * b; x < xb; x++) {
                memcpy(&t, q + 4 * (size_t)x, 4);
                acc |= t;
            }
            if (acc) bits[b >> 6] |= (uint64_t)1 << (b & 63);
        }
    }
}

void SIMD_FN(fuse__cover_row)(const uint8_t *q, int w, uint64_t *bits)
{
    SIMD_FN(fuse__cover_span)(q, w, 0, w, bits);
}

/* out = v | alpha 255; in place (v == out) only the vectors with an alpha
 * below 255 are stored */
void SIMD_FN(fuse__opaque)(const uint8_t *v, uint8_t *out, int n)
{
    const vint a = vi_set1((int32_t)0xFF000000u);
    int i = 0;
    if (v == out) {
        for (; i + SIMD_W <= n; i += SIMD_W) {
            const vint x = vi_loadu((const int32_t *)(const void *)(v + 4 * (size_t)i));
            const vint y = vi_or(x, a);
            if (!vm_all(vi_eq(x, y)))
                vi_storeu((int32_t *)(void *)(out + 4 * (size_t)i), y);
        }
    } else {
        for (; i + 2 * SIMD_W <= n; i += 2 * SIMD_W) {
            const vint x0 = vi_loadu((const int32_t *)(const void *)(v + 4 * (size_t)i));
            const vint x1 = vi_loadu((const int32_t *)(const void *)(v + 4 * (size_t)(i + SIMD_W)));
            vi_storeu((int32_t *)(void *)(out + 4 * (size_t)i), vi_or(x0, a));
            vi_storeu((int32_t *)(void *)(out + 4 * (size_t)(i + SIMD_W)), vi_or(x1, a));
        }
        if (i + SIMD_W <= n) {
            vi_storeu((int32_t *)(void *)(out + 4 * (size_t)i),
                      vi_or(vi_loadu((const int32_t *)(const void *)(v + 4 * (size_t)i)), a));
            i += SIMD_W;
        }
    }
    if (i < n) {   /* the last n - i < SIMD_W pixels: nothing beyond them is read or written,
                    * and in place only when an alpha is below 255 (as above) */
        const unsigned bits = (1u << (n - i)) - 1u;
        const vint x = vf_as_vi(vf_load_bits((const float *)(const void *)(v + 4 * (size_t)i), bits));
        const vint y = vi_or(x, a);
        if (v != out || (vm_bits(vi_eq(x, y)) & bits) != bits)
            vf_store_bits((float *)(void *)(out + 4 * (size_t)i), bits, vi_as_vf(y));
    }
}

#ifdef FUSE_YUV_ON_LAYER
/* ---- camera formats: YUYV / UYVY rows (fuse_formats.c, yuv_px) ---------
 *
 * SIMD_W pixel pairs a step, one pair (Y0 U Y1 V, or U Y0 V Y1) per int32
 * lane, the reference's integer formula exactly: C = Y - 16, D = U - 128,
 * E = V - 128; R = 298 C + 409 E + 128, G = 298 C - 100 D - 208 E + 128,
 * B = 298 C + 516 D + 128 in int32 (no overflow: |v| < 2^18), then
 * clamp255: 0 for v < 0, else min(255, v >> 8). The two pixels of the lanes
 * are interleaved back into memory order by vi_store2. Returns the pixels
 * done (a multiple of 2 SIMD_W); the caller converts the rest. */
SIMD_INL vint yuv_clamp(vint v)
{
    const vint t = vi_srai(v, 8);   /* v < 0 <=> t < 0 */
    const vint k255 = vi_set1(255);
    return vi_sel(vi_gt(vi_zero(), t), vi_zero(), vi_sel(vi_gt(t, k255), k255, t));
}

SIMD_INL vint yuv_pixel(vint c, vint rd, vint gd, vint bd)
{
    const vint base = vi_add(vi_mullo(c, vi_set1(298)), vi_set1(128));
    return vi_or(vi_or(yuv_clamp(vi_add(base, rd)), vi_slli(yuv_clamp(vi_add(base, gd)), 8)),
                 vi_or(vi_slli(yuv_clamp(vi_add(base, bd)), 16), vi_set1((int32_t)0xFF000000u)));
}

int SIMD_FN(fuse__yuv422_row)(const uint8_t *src, int width, int uyvy, uint8_t *dst)
{
    const vint m8 = vi_set1(255);
    /* byte positions of Y0, U, Y1, V in the pair's word */
    const int sy0 = uyvy ? 8 : 0, su = uyvy ? 0 : 8, sy1 = uyvy ? 24 : 16, sv = uyvy ? 16 : 24;
    int x = 0;
    for (; x + 2 * SIMD_W <= width; x += 2 * SIMD_W) {
        const vint w = vi_loadu((const int32_t *)(const void *)(src + 2 * (size_t)x));
        const vint y0 = vi_and(vi_srl(w, sy0), m8), y1 = vi_and(vi_srl(w, sy1), m8);
        const vint d = vi_sub(vi_and(vi_srl(w, su), m8), vi_set1(128));
        const vint e = vi_sub(vi_and(vi_srl(w, sv), m8), vi_set1(128));
        const vint rd = vi_mullo(e, vi_set1(409));
        const vint gd = vi_sub(vi_mullo(d, vi_set1(-100)), vi_mullo(e, vi_set1(208)));
        const vint bd = vi_mullo(d, vi_set1(516));
        vi_store2((int32_t *)(void *)(dst + 4 * (size_t)x),
                  yuv_pixel(vi_sub(y0, vi_set1(16)), rd, gd, bd),
                  yuv_pixel(vi_sub(y1, vi_set1(16)), rd, gd, bd));
    }
    return x;
}
#endif

#ifdef FUSE_COLS_ON_LAYER
/* ---- composite per output row (fuse__composite_fn), 16-bit lanes ---------
 *
 * SIMD_W output pixels a step, their four taps loaded one by one. Bilinear
 * blend + over of the pixels widened to 16-bit lanes, two pixels per
 * half-block (a, b, c, d, v: the taps and V; wx0/wx1: 256 - fx and fx per
 * channel; wy0/wy1 the same for the row). The reference's
 *   q = ((a wx0 + b wx1) wy0 + (c wx0 + d wx1) wy1 + 32768) >> 16
 * is a sum of exact integer products, so it may be grouped by columns:
 *   col0 = a wy0 + c wy1,  col1 = b wy0 + d wy1      (<= 65280: u16)
 *   S = col0 wx0 + col1 wx1 = 256 H + Lo with
 *   H = hi0 wx0 + hi1 wx1, Lo = lo0 wx0 + lo1 wx1 (hi = col >> 8, lo = col & 255)
 *   q = floor((S + 32768) / 65536) = (H + (Lo >> 8) + 128) >> 8
 * where H + (Lo >> 8) <= S / 256 <= 65280, so every step fits in u16. Over:
 *   r = q + div255((255 - qa) v),  div255(t) = (t + 128 + ((t + 128) >> 8)) >> 8
 * with t <= 65025; the final min(255, .) is the saturating pack. */
SIMD_INL vint blend16(vint a, vint b, vint c, vint d, vint v, vint wx0, vint wx1, vint wy0, vint wy1)
{
    const vint lo8 = vh_set1(255);
    const vint col0 = vh_add(vh_mullo(a, wy0), vh_mullo(c, wy1));
    const vint col1 = vh_add(vh_mullo(b, wy0), vh_mullo(d, wy1));
    const vint H = vh_add(vh_mullo(vh_srli(col0, 8), wx0), vh_mullo(vh_srli(col1, 8), wx1));
    const vint L = vh_add(vh_mullo(vi_and(col0, lo8), wx0), vh_mullo(vi_and(col1, lo8), wx1));
    const vint q = vh_srli(vh_add(vh_add(H, vh_srli(L, 8)), vh_set1(128)), 8);
    vint t = vh_mullo(vh_sub(lo8, vh_bcast3(q)), v);
    t = vh_add(t, vh_set1(128));
    t = vh_srli(vh_add(t, vh_srli(t, 8)), 8);
    return vh_add(q, t);
}

void SIMD_FN(fuse__composite_cols)(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                                   const fuse__cols *cols, int c, int n, int sw,
                                   const uint8_t *v, uint8_t *out)
{
    const vint wy0 = vh_set1((int)(256 - fy)), wy1 = vh_set1((int)fy), w256 = vh_set1(256);
    const vint opaque = vi_set1((int32_t)0xFF000000u);
    const int32_t *ixs = cols->ix + c, *fxs = cols->fx + c;
    int i = 0;
    for (; i + SIMD_W <= n; i += SIMD_W) {
        _Alignas(64) uint32_t ta[SIMD_W], tb[SIMD_W], tc[SIMD_W], td[SIMD_W];
        vint a, b, cc, d, vv, wl, wh;
        int k;
        for (k = 0; k < SIMD_W; k++) {
            const int ix = ixs[i + k], ix1 = ix + 1 < sw ? ix + 1 : sw - 1;
            memcpy(&ta[k], q0 + 4 * ix, 4);
            memcpy(&tb[k], q0 + 4 * ix1, 4);
            memcpy(&tc[k], q1 + 4 * ix, 4);
            memcpy(&td[k], q1 + 4 * ix1, 4);
        }
        a = vi_load((const int32_t *)(const void *)ta);
        b = vi_load((const int32_t *)(const void *)tb);
        cc = vi_load((const int32_t *)(const void *)tc);
        d = vi_load((const int32_t *)(const void *)td);
        vv = vi_loadu((const int32_t *)(const void *)(v + 4 * (size_t)i));
        if (vm_all(vi_eq(vi_or(vi_or(a, b), vi_or(cc, d)), vi_zero()))) {
            vi_storeu((int32_t *)(void *)(out + 4 * (size_t)i), vi_or(vv, opaque));
            continue;
        }
        {   /* fx of each pixel in its four 16-bit lanes, in the order the
             * blocks' low (pixels 4B, 4B + 1) and high halves (4B + 2,
             * 4B + 3) widen to */
            const vint fx = vi_loadu(fxs + i);
            wl = vi_zip_lo(fx, fx);
            wh = vi_zip_hi(fx, fx);
            wl = vi_or(wl, vi_slli(wl, 16));
            wh = vi_or(wh, vi_slli(wh, 16));
        }
        vi_storeu((int32_t *)(void *)(out + 4 * (size_t)i),
                  vi_or(vh_packus(blend16(vh_from_u8_lo(a), vh_from_u8_lo(b), vh_from_u8_lo(cc),
                                          vh_from_u8_lo(d), vh_from_u8_lo(vv), vh_sub(w256, wl), wl,
                                          wy0, wy1),
                                  blend16(vh_from_u8_hi(a), vh_from_u8_hi(b), vh_from_u8_hi(cc),
                                          vh_from_u8_hi(d), vh_from_u8_hi(vv), vh_sub(w256, wh), wh,
                                          wy0, wy1)),
                        opaque));
    }
    for (; i < n; i++)
        fuse__composite_px(q0, q1, fy, ixs[i], (uint32_t)fxs[i], sw, v + 4 * i, out + 4 * i);
}
#endif

#ifdef FUSE_ROWCACHE_ON_LAYER
/* ---- row-cached composite (fuse_internal.h, fuse__hrow_fn / vrow_fn) ----
 *
 * fuse__hrow once per layer row, fuse__vrow per output row. The taps of
 * SIMD_W consecutive output pixels lie in a window of SIMD_W source pixels
 * when the layer is enlarged (640 -> 1194: at most 5 for 8), so one load
 * and vi_permute give them; otherwise (reductions, narrow layers)
 * vi_gather. h of a step of SIMD_W pixels is kept in the layer's block
 * order (fuse_internal.h, "Stored"): the 16-bit lanes of vh_from_u8_lo
 * (pixels 4B, 4B + 1 of each block B) then of vh_from_u8_hi (4B + 2,
 * 4B + 3), so neither kernel reorders across blocks; vh_packus puts the
 * pixels back in memory order. */
/* The per-step tables of fuse__cols for this ISA's hrow (fuse_internal.h):
 * the window test, the taps' indices and the weights of each step, once
 * per tile instead of once per layer row. */
void SIMD_FN(fuse__hprep)(fuse__cols *cols, int n, int sw)
{
    const vint one = vi_set1(1), last = vi_set1(sw - 1), w256 = vh_set1(256);
    int i;
    for (i = 0; i + SIMD_W <= n; i += SIMD_W) {
        const vint ix = vi_loadu(cols->ix + i);
        const vint ix1 = vi_min(vi_add(ix, one), last);
        const vint fx = vi_loadu(cols->fx + i);
        vint wl = vi_zip_lo(fx, fx), wh = vi_zip_hi(fx, fx);
        int base = cols->ix[i];
        const int hi = cols->ix[i + SIMD_W - 1] + 1 < sw ? cols->ix[i + SIMD_W - 1] + 1 : sw - 1;
        if (base > sw - SIMD_W) base = sw - SIMD_W;
        /* fx of each pixel in its four 16-bit lanes, in the blocks' order */
        wl = vi_or(wl, vi_slli(wl, 16));
        wh = vi_or(wh, vi_slli(wh, 16));
        vi_storeu(cols->hw + 2 * i, wl);
        vi_storeu(cols->hw + 2 * i + SIMD_W, wh);
        vi_storeu(cols->hwc + 2 * i, vh_sub(w256, wl));
        vi_storeu(cols->hwc + 2 * i + SIMD_W, vh_sub(w256, wh));
        if (base >= 0 && hi - base < SIMD_W) {
            const vint bb = vi_set1(base);
            cols->hbase[i / SIMD_W] = base;
            vi_storeu(cols->hidx0 + i, vi_sub(ix, bb));
            vi_storeu(cols->hidx1 + i, vi_sub(ix1, bb));
        } else {
            cols->hbase[i / SIMD_W] = -1;
            vi_storeu(cols->hidx0 + i, ix);
            vi_storeu(cols->hidx1 + i, ix1);
        }
    }
    cols->hprep_w = SIMD_W;
}

/* 1 when every bit of v is 0 (hrow's empty window) */
#ifndef FUSE_ZERO
#define FUSE_ZERO(v) vm_all(vi_eq(v, vi_zero()))
#endif
void SIMD_FN(fuse__hrow)(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                         uint16_t *h)
{
    const vint bias = vh_set1((int)FUSE__H_BIAS);
    const int32_t *ixs = cols->ix + c, *fxs = cols->fx + c;
    int i = 0;
    if (cols->hprep_w == SIMD_W && c % SIMD_W == 0) {
        const int32_t *base = cols->hbase + c / SIMD_W;
        const int32_t *i0s = cols->hidx0 + c, *i1s = cols->hidx1 + c, *ws = cols->hw + 2 * c,
                      *wcs = cols->hwc + 2 * c;
        for (; i + SIMD_W <= n; i += SIMD_W, base++, ws += 2 * SIMD_W, wcs += 2 * SIMD_W) {
            const vint i0 = vi_loadu(i0s + i), i1 = vi_loadu(i1s + i);
            vint a, b;
            if (*base >= 0) {
                const vint s0 = vi_loadu((const int32_t *)(const void *)(q + 4 * (size_t)*base));
                if (FUSE_ZERO(s0)) {   /* every tap 0: h = 0 */
                    vi_storeu((int32_t *)(void *)(h + 4 * i), bias);
                    vi_storeu((int32_t *)(void *)(h + 4 * i + 2 * SIMD_W), bias);
                    continue;
                }
                a = vi_permute(s0, i0);
                b = vi_permute(s0, i1);
            } else {
                a = vi_gather((const int32_t *)(const void *)q, i0);
                b = vi_gather((const int32_t *)(const void *)q, i1);
            }
            /* the weights only here: loaded as the multiplies' operands,
             * not before the all-zero test */
            vi_storeu((int32_t *)(void *)(h + 4 * i),
                      vi_xor(vh_add(vh_mullo(vh_from_u8_lo(a), vi_loadu(wcs)),
                                    vh_mullo(vh_from_u8_lo(b), vi_loadu(ws))), bias));
            vi_storeu((int32_t *)(void *)(h + 4 * i + 2 * SIMD_W),
                      vi_xor(vh_add(vh_mullo(vh_from_u8_hi(a), vi_loadu(wcs + SIMD_W)),
                                    vh_mullo(vh_from_u8_hi(b), vi_loadu(ws + SIMD_W))),
                             bias));
        }
    }
    /* the last n % SIMD_W columns (all of them without the tables: the
     * same bytes, pixel by pixel), each in its step's block order */
    for (; i < n; i++) fuse__hpx(q, ixs[i], (uint32_t)fxs[i], sw, h + fuse__hslot(i, SIMD_W));
}

/* Two pixels per block: q = ((h0 - 32768) w0 + (h1 - 32768) w1 + 32768 *
 * 257) >> 16 per channel (fuse_internal.h: the stored values are h - 32768;
 * w holds the pairs (w0, w1)), in 16-bit lanes. vh_zip_lo/hi pair the
 * channels of the block's first and second pixel; vh_packus32 puts them
 * back in order. */
#ifndef FUSE_ALPHA4
#define FUSE_ALPHA4(q) vh_bcast3(q)
#endif
/* 1 when every pixel of the two vectors of q (vsum_rc) has alpha 255
 * (lanes 0..255); default: the alphas of q0 & q1 compared with 255. */
#ifndef FUSE_ALPHA255
#define FUSE_ALPHA255(q0, q1) vm_all(vi_eq(FUSE_ALPHA4(vi_and(q0, q1)), vh_set1(255)))
#endif
SIMD_INL vint vsum_rc(vint a, vint b, vint w)
{
    const vint k = vi_set1(32768 * 257);
    const vint sl = vi_srli(vi_add(vh_madd(vh_zip_lo(a, b), w), k), 16);
    const vint sh = vi_srli(vi_add(vh_madd(vh_zip_hi(a, b), w), k), 16);
    return vh_packus32(sl, sh);
}

/* q over V's two pixels per block in vw (16-bit lanes). */
SIMD_INL vint vover_rc(vint qq, vint vw)
{
    const vint lo8 = vh_set1(255), r128 = vh_set1(128);
    vint t = vh_mullo(vh_sub(lo8, FUSE_ALPHA4(qq)), vw);
    /* div255: ((t + 128) + ((t + 128) >> 8)) >> 8 is ((t + 128) 257) >> 16 (the
     * inner floor cannot move the outer one: an integer plus a fraction
     * below 1 never crosses a multiple of 256), one pmulhuw */
    t = vh_mulhi(vh_add(t, r128), vh_set1(257));
    return vh_add(qq, t);
}

/* A step whose pixels all have alpha 255 (the inside of an opaque layer:
 * most steps of a hand) is q itself: the over adds div255(0 v) = 0 and
 * the alpha is already 255, so V is not read. */
void SIMD_FN(fuse__vrow)(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                         const uint8_t *v, uint8_t *out, int n)
{
    const vint w = vi_set1((int32_t)((fy << 16) | (256u - fy)));
    const vint opaque = vi_set1((int32_t)0xFF000000u);
    int i = 0;
    for (; i + SIMD_W <= n; i += SIMD_W) {
        const vint q0 = vsum_rc(vi_loadu((const int32_t *)(const void *)(h0 + 4 * i)),
                                vi_loadu((const int32_t *)(const void *)(h1 + 4 * i)), w);
        const vint q1 = vsum_rc(vi_loadu((const int32_t *)(const void *)(h0 + 4 * i + 2 * SIMD_W)),
                                vi_loadu((const int32_t *)(const void *)(h1 + 4 * i + 2 * SIMD_W)), w);
        vint r;
        if (FUSE_ALPHA255(q0, q1)) {
            r = vh_packus(q0, q1);
        } else {
            const vint vv = vi_loadu((const int32_t *)(const void *)(v + 4 * (size_t)i));
            r = vi_or(vh_packus(vover_rc(q0, vh_from_u8_lo(vv)), vover_rc(q1, vh_from_u8_hi(vv))),
                      opaque);
        }
        vi_storeu((int32_t *)(void *)(out + 4 * (size_t)i), r);
    }
    if (i < n) {
        /* the last n - i columns (the tile's end) as one step: h holds them
         * in block order (fuse__hslot) and the step's other values lie
         * inside the tile's h arrays (their lanes are computed, never
         * stored, and take no part in a branch); V and out through the
         * lane mask */
        const unsigned bits = (1u << (n - i)) - 1u;
        const vint vv = vf_as_vi(vf_load_bits((const float *)(const void *)(v + 4 * (size_t)i), bits));
        const vint q0 = vsum_rc(vi_loadu((const int32_t *)(const void *)(h0 + 4 * i)),
                                vi_loadu((const int32_t *)(const void *)(h1 + 4 * i)), w);
        const vint q1 = vsum_rc(vi_loadu((const int32_t *)(const void *)(h0 + 4 * i + 2 * SIMD_W)),
                                vi_loadu((const int32_t *)(const void *)(h1 + 4 * i + 2 * SIMD_W)), w);
        vf_store_bits((float *)(void *)(out + 4 * (size_t)i), bits,
                      vi_as_vf(vi_or(vh_packus(vover_rc(q0, vh_from_u8_lo(vv)),
                                               vover_rc(q1, vh_from_u8_hi(vv))),
                                     opaque)));
    }
}
#endif
