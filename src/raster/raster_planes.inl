/* raster_planes.inl - the batched plane set-up (rast__planes_fn) shared by
 * raster_avx2.c (4 double lanes) and raster_avx512.c (8 double lanes):
 * one triangle per lane, every lane running the IEEE double operations of
 * the scalar set-up (planes_one in raster_setup.c) in its order, so each
 * plane gets the bits of rast__planes_ref (no contraction into FMA:
 * -ffp-contract=off).
 *
 * Lane macros:
 *   PD_V                   double lanes
 *   PLANES_FN              name of the exported function
 *   vd                     the double vector type
 *   PD_LOAD(p)             aligned load of PD_V doubles
 *   PD_SET1(x)
 *   PD_ADD PD_SUB PD_MUL PD_DIV   one IEEE op per lane
 *   PD_MAX(a, b)           a > b ? a : b (the x86 max; NaN cannot occur)
 *   PD_STORE_F(p, v)       the lanes converted to float (round to
 *                          nearest, as the scalar conversion), stored to
 *                          PD_V floats at p
 *
 * Per lane (scalar reference: planes_one, docs/raster.md section 6.1):
 *   qmax = max(iw2, max(iw1, max(iw0, 0)))     (the loop "if (iw > qmax)")
 *   q_i = iw_i / qmax
 *   ex1 = X1 - X0, ey1 = Y1 - Y0, ex2 = X2 - X0, ey2 = Y2 - Y0,
 *   ox = cx - X0, oy = cy - Y0
 *   per plane with vertex values (f0, f1, f2) = z: (zw0, zw1, zw2),
 *   q: (q0, q1, q2), b1: (0, q1, 0), b2: (0, 0, q2):
 *     df1 = f1 - f0, df2 = f2 - f0
 *     gx = (df1*ey2 - df2*ey1) / area, gy = (df2*ex1 - df1*ex2) / area
 *     c = (f0 + gx*ox) + gy*oy;   stored as float c, dx = gx, dy = gy.
 */

static inline void planes_lane(vd f0, vd f1, vd f2, vd ex1, vd ey1, vd ex2, vd ey2,
                               vd ox, vd oy, vd area, float *c, float *gxo, float *gyo)
{
    const vd df1 = PD_SUB(f1, f0), df2 = PD_SUB(f2, f0);
    const vd gx = PD_DIV(PD_SUB(PD_MUL(df1, ey2), PD_MUL(df2, ey1)), area);
    const vd gy = PD_DIV(PD_SUB(PD_MUL(df2, ex1), PD_MUL(df1, ex2)), area);
    const vd cc = PD_ADD(PD_ADD(f0, PD_MUL(gx, ox)), PD_MUL(gy, oy));
    PD_STORE_F(c, cc);
    PD_STORE_F(gxo, gx);
    PD_STORE_F(gyo, gy);
}

void PLANES_FN(rast__pbatch *b)
{
    const int n = b->n;
    const int ng = (n + PD_V - 1) / PD_V * PD_V;
    /* Harmless values in the unused lanes of the last group. */
    for (int i = n; i < ng; i++) {
        for (int k = 0; k < 3; k++) {
            b->X[k][i] = b->Y[k][i] = b->zw[k][i] = 0.0;
            b->iw[k][i] = 1.0;
        }
        b->area[i] = 1.0;
        b->cx[i] = b->cy[i] = 0.0;
    }
    /* out[plane * 3 + {c, dx, dy}][lane]: the floats of rast__plane z, q,
     * b1, b2 in struct order. */
    _Alignas(64) float out[12][RAST__PBATCH];
    const vd zero = PD_SET1(0.0);
    for (int i = 0; i < ng; i += PD_V) {
        const vd X0 = PD_LOAD(b->X[0] + i), X1 = PD_LOAD(b->X[1] + i), X2 = PD_LOAD(b->X[2] + i);
        const vd Y0 = PD_LOAD(b->Y[0] + i), Y1 = PD_LOAD(b->Y[1] + i), Y2 = PD_LOAD(b->Y[2] + i);
        const vd iw0 = PD_LOAD(b->iw[0] + i), iw1 = PD_LOAD(b->iw[1] + i),
                 iw2 = PD_LOAD(b->iw[2] + i);
        const vd area = PD_LOAD(b->area + i);
        const vd qmax = PD_MAX(iw2, PD_MAX(iw1, PD_MAX(iw0, zero)));
        const vd q0 = PD_DIV(iw0, qmax), q1 = PD_DIV(iw1, qmax), q2 = PD_DIV(iw2, qmax);
        const vd ex1 = PD_SUB(X1, X0), ey1 = PD_SUB(Y1, Y0);
        const vd ex2 = PD_SUB(X2, X0), ey2 = PD_SUB(Y2, Y0);
        const vd ox = PD_SUB(PD_LOAD(b->cx + i), X0), oy = PD_SUB(PD_LOAD(b->cy + i), Y0);
        planes_lane(PD_LOAD(b->zw[0] + i), PD_LOAD(b->zw[1] + i), PD_LOAD(b->zw[2] + i), ex1,
                    ey1, ex2, ey2, ox, oy, area, out[0] + i, out[1] + i, out[2] + i);
        planes_lane(q0, q1, q2, ex1, ey1, ex2, ey2, ox, oy, area, out[3] + i, out[4] + i,
                    out[5] + i);
        planes_lane(zero, q1, zero, ex1, ey1, ex2, ey2, ox, oy, area, out[6] + i, out[7] + i,
                    out[8] + i);
        planes_lane(zero, zero, q2, ex1, ey1, ex2, ey2, ox, oy, area, out[9] + i,
                    out[10] + i, out[11] + i);
    }
    for (int i = 0; i < n; i++) {
        rast__tri *t = b->tri[i];
        rast__plane *pl[4] = { &t->z, &t->q, &t->b1, &t->b2 };
        for (int p = 0; p < 4; p++) {
            pl[p]->c = out[3 * p][i];
            pl[p]->dx = out[3 * p + 1][i];
            pl[p]->dy = out[3 * p + 2][i];
        }
    }
    b->n = 0;
}

/* ---- vertex cache block fill (rast__vfill_fn) ----------------------------
 *
 * The scalar fill (vc_fill_one in raster_setup.c) per lane: finiteness
 * (|c| <= FLT_MAX as two ordered compares), the six outcode distances
 * (z + w, w - z, gx*w + x, gx*w - x, gy*w + y, gy*w - y) < 0, w > 0, the
 * snap (x / w, (nx*0.5f + 0.5f) * width, * 256, clamped, rounded to
 * nearest even by the conversion) and in double zw = (z / w)*0.5 + 0.5,
 * iw = 1 / w. Lanes of vertices that are not finite or need clipping
 * compute garbage that is never stored as valid (flags say so).
 *
 * More lane macros:
 *   PS_V                   float lanes; vs the float vector type
 *   PS_LOAD(p) PS_SET1(x) PS_ADD PS_SUB PS_MUL PS_DIV
 *   PS_MAX(a, b), PS_MIN(a, b)   the x86 max / min (a > b ? a : b, ...)
 *   PS_LT_BITS(a, b), PS_LE_BITS(a, b), PS_GT_BITS(a, b)  ordered compares
 *   PS_CVT_STORE(p, v)     round to int32 (nearest even) and store PS_V
 *   PD_LOAD_F(p)           PD_V floats from p converted to double
 *   PD_STORE(p, v)
 * Optional:
 *   LOAD_BLOCK_XYZW(c, x, y, z, w)  de-interleave 16 vertices (x, y, z, w
 *                          each) at c into the aligned arrays x, y, z, w
 */
void VFILL_FN(const rast__view *v, const float *clip, uint32_t base, int count,
              rast__vc_entry *e)
{
    _Alignas(64) float x[RAST__VBLOCK], y[RAST__VBLOCK], z[RAST__VBLOCK], w[RAST__VBLOCK];
    _Alignas(64) int32_t X[RAST__VBLOCK], Y[RAST__VBLOCK];
    _Alignas(64) double zw[RAST__VBLOCK], iw[RAST__VBLOCK];
    const float *c = clip + 4 * (size_t)base;
#ifdef LOAD_BLOCK_XYZW
    if (count == RAST__VBLOCK) {
        LOAD_BLOCK_XYZW(c, x, y, z, w);
    } else
#endif
    {
        /* One loop over the block's bounds (two, from count on, made gcc
         * -O3 warn of a memset past the arrays). */
        for (int l = 0; l < RAST__VBLOCK; l++) {
            const int in = l < count;
            x[l] = in ? c[4 * l] : 0.0f;
            y[l] = in ? c[4 * l + 1] : 0.0f;
            z[l] = in ? c[4 * l + 2] : 0.0f;
            w[l] = in ? c[4 * l + 3] : 1.0f;
        }
    }
    unsigned fin = 0, wpos = 0, ob[RAST__PLANE_COUNT] = { 0, 0, 0, 0, 0, 0 };
    const vs zero = PS_SET1(0.0f), half = PS_SET1(0.5f), fix = PS_SET1((float)RAST__FIX_ONE);
    const vs big = PS_SET1(FLT_MAX), nbig = PS_SET1(-FLT_MAX);
    const vs gx = PS_SET1(v->gx), gy = PS_SET1(v->gy);
    const vs fw = PS_SET1((float)v->width), fh = PS_SET1((float)v->height);
    const vs lox = PS_SET1((float)v->min_x), hix = PS_SET1((float)v->max_x);
    const vs loy = PS_SET1((float)v->min_y), hiy = PS_SET1((float)v->max_y);
    for (int i = 0; i < RAST__VBLOCK; i += PS_V) {
        const vs vx = PS_LOAD(x + i), vy = PS_LOAD(y + i), vz = PS_LOAD(z + i),
                 vw = PS_LOAD(w + i);
        fin |= (PS_LE_BITS(vx, big) & PS_LE_BITS(nbig, vx) & PS_LE_BITS(vy, big) &
                PS_LE_BITS(nbig, vy) & PS_LE_BITS(vz, big) & PS_LE_BITS(nbig, vz) &
                PS_LE_BITS(vw, big) & PS_LE_BITS(nbig, vw)) << i;
        const vs gxw = PS_MUL(gx, vw), gyw = PS_MUL(gy, vw);
        ob[RAST__PLANE_NEAR] |= PS_LT_BITS(PS_ADD(vz, vw), zero) << i;
        ob[RAST__PLANE_FAR] |= PS_LT_BITS(PS_SUB(vw, vz), zero) << i;
        ob[RAST__PLANE_LEFT] |= PS_LT_BITS(PS_ADD(gxw, vx), zero) << i;
        ob[RAST__PLANE_RIGHT] |= PS_LT_BITS(PS_SUB(gxw, vx), zero) << i;
        ob[RAST__PLANE_BOTTOM] |= PS_LT_BITS(PS_ADD(gyw, vy), zero) << i;
        ob[RAST__PLANE_TOP] |= PS_LT_BITS(PS_SUB(gyw, vy), zero) << i;
        wpos |= PS_GT_BITS(vw, zero) << i;
        const vs nx = PS_DIV(vx, vw), ny = PS_DIV(vy, vw);
        const vs sx = PS_MUL(PS_ADD(PS_MUL(nx, half), half), fw);
        const vs sy = PS_MUL(PS_SUB(half, PS_MUL(ny, half)), fh);
        PS_CVT_STORE(X + i, PS_MIN(PS_MAX(PS_MUL(sx, fix), lox), hix));
        PS_CVT_STORE(Y + i, PS_MIN(PS_MAX(PS_MUL(sy, fix), loy), hiy));
    }
    const vd dhalf = PD_SET1(0.5), done = PD_SET1(1.0);
    for (int i = 0; i < RAST__VBLOCK; i += PD_V) {
        const vd dz = PD_LOAD_F(z + i), dw = PD_LOAD_F(w + i);
        PD_STORE(zw + i, PD_ADD(PD_MUL(PD_DIV(dz, dw), dhalf), dhalf));
        PD_STORE(iw + i, PD_DIV(done, dw));
    }
    /* Outcodes per lane from the per-plane lane bits (mostly all zero). */
    uint8_t oc[RAST__VBLOCK] = { 0 };
    for (int p = 0; p < RAST__PLANE_COUNT; p++)
        for (unsigned bits = ob[p]; bits; bits &= bits - 1)
            oc[__builtin_ctz(bits)] |= (uint8_t)(1u << p);
    for (int l = 0; l < count; l++) {
        rast__vc_entry *o = &e[l];
        o->tag = base + (uint32_t)l;
        if (!((fin >> l) & 1u)) {
            o->flags = RAST__VF_NONFINITE;
            continue;
        }
        if (oc[l] || !((wpos >> l) & 1u)) {
            o->flags = oc[l] | RAST__VF_SLOW;
            continue;
        }
        o->flags = 0;
        o->X = X[l];
        o->Y = Y[l];
        o->zw = zw[l];
        o->iw = iw[l];
    }
}

#ifndef FRONT_FN
#define FRONT_FN NULL
#endif
#ifndef VPASS_FN
#define VPASS_FN NULL
#define FRONTV_FN NULL
#endif
const rast__setup_isa SETUP_ISA = { PLANES_FN, VFILL_FN, FRONT_FN, VPASS_FN, FRONTV_FN };
