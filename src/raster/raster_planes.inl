/* raster_planes.inl - the batched plane set-up (rast__planes_fn) and the
 * vertex cache block fill (rast__vfill_fn) shared by raster_sse2.c and
 * raster_neon.c (2 double lanes), raster_avx2.c (4) and raster_avx512.c (8):
 * one triangle per lane, every lane running the IEEE double operations of
 * the scalar set-up (planes_one in raster_setup.c) in its order, so each
 * plane gets the bits of rast__planes_ref (no contraction into FMA:
 * -ffp-contract=off).
 *
 * Written on the vector layer (src/cpu/simd.h; vdouble: VD_W = SIMD_W / 2
 * double lanes, vd_max the x86 max, NaN cannot occur here, vd_store_f the
 * rounding of the scalar conversion). The including file includes one
 * implementation and then this file, which defines SIMD_FN(rast__planes),
 * SIMD_FN(rast__vfill) and the table SIMD_FN(rast__setup_isa) (with
 * FRONT_FN, VPASS_FN, FRONTV_FN when the file defines them).
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

static inline void planes_lane(vdouble f0, vdouble f1, vdouble f2, vdouble ex1, vdouble ey1, vdouble ex2, vdouble ey2,
                               vdouble ox, vdouble oy, vdouble area, float *c, float *gxo, float *gyo)
{
    const vdouble df1 = vd_sub(f1, f0), df2 = vd_sub(f2, f0);
    const vdouble gx = vd_div(vd_sub(vd_mul(df1, ey2), vd_mul(df2, ey1)), area);
    const vdouble gy = vd_div(vd_sub(vd_mul(df2, ex1), vd_mul(df1, ex2)), area);
    const vdouble cc = vd_add(vd_add(f0, vd_mul(gx, ox)), vd_mul(gy, oy));
    vd_store_f(c, cc);
    vd_store_f(gxo, gx);
    vd_store_f(gyo, gy);
}

void SIMD_FN(rast__planes)(rast__pbatch *b)
{
    const int n = b->n;
    const int ng = (n + VD_W - 1) / VD_W * VD_W;
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
    const vdouble zero = vd_set1(0.0);
    for (int i = 0; i < ng; i += VD_W) {
        const vdouble X0 = vd_loadu(b->X[0] + i), X1 = vd_loadu(b->X[1] + i), X2 = vd_loadu(b->X[2] + i);
        const vdouble Y0 = vd_loadu(b->Y[0] + i), Y1 = vd_loadu(b->Y[1] + i), Y2 = vd_loadu(b->Y[2] + i);
        const vdouble iw0 = vd_loadu(b->iw[0] + i), iw1 = vd_loadu(b->iw[1] + i),
                 iw2 = vd_loadu(b->iw[2] + i);
        const vdouble area = vd_loadu(b->area + i);
        const vdouble qmax = vd_max(iw2, vd_max(iw1, vd_max(iw0, zero)));
        const vdouble q0 = vd_div(iw0, qmax), q1 = vd_div(iw1, qmax), q2 = vd_div(iw2, qmax);
        const vdouble ex1 = vd_sub(X1, X0), ey1 = vd_sub(Y1, Y0);
        const vdouble ex2 = vd_sub(X2, X0), ey2 = vd_sub(Y2, Y0);
        const vdouble ox = vd_sub(vd_loadu(b->cx + i), X0), oy = vd_sub(vd_loadu(b->cy + i), Y0);
        planes_lane(vd_loadu(b->zw[0] + i), vd_loadu(b->zw[1] + i), vd_loadu(b->zw[2] + i), ex1,
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
 * Float lanes: vfloat of the layer (vf_max / vf_min the x86 ones).
 * Optional:
 *   LOAD_BLOCK_XYZW(c, x, y, z, w)  de-interleave 16 vertices (x, y, z, w
 *                          each) at c into the aligned arrays x, y, z, w
 */
void SIMD_FN(rast__vfill)(const rast__view *v, const float *clip, uint32_t base, int count,
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
    const vfloat zero = vf_set1(0.0f), half = vf_set1(0.5f), fix = vf_set1((float)RAST__FIX_ONE);
    const vfloat big = vf_set1(FLT_MAX), nbig = vf_set1(-FLT_MAX);
    const vfloat gx = vf_set1(v->gx), gy = vf_set1(v->gy);
    const vfloat fw = vf_set1((float)v->width), fh = vf_set1((float)v->height);
    const vfloat lox = vf_set1((float)v->min_x), hix = vf_set1((float)v->max_x);
    const vfloat loy = vf_set1((float)v->min_y), hiy = vf_set1((float)v->max_y);
    for (int i = 0; i < RAST__VBLOCK; i += SIMD_W) {
        const vfloat vx = vf_load(x + i), vy = vf_load(y + i), vz = vf_load(z + i),
                 vw = vf_load(w + i);
        fin |= (vm_bits(vf_le(vx, big)) & vm_bits(vf_le(nbig, vx)) & vm_bits(vf_le(vy, big)) &
                vm_bits(vf_le(nbig, vy)) & vm_bits(vf_le(vz, big)) & vm_bits(vf_le(nbig, vz)) &
                vm_bits(vf_le(vw, big)) & vm_bits(vf_le(nbig, vw))) << i;
        const vfloat gxw = vf_mul(gx, vw), gyw = vf_mul(gy, vw);
        ob[RAST__PLANE_NEAR] |= vm_bits(vf_lt(vf_add(vz, vw), zero)) << i;
        ob[RAST__PLANE_FAR] |= vm_bits(vf_lt(vf_sub(vw, vz), zero)) << i;
        ob[RAST__PLANE_LEFT] |= vm_bits(vf_lt(vf_add(gxw, vx), zero)) << i;
        ob[RAST__PLANE_RIGHT] |= vm_bits(vf_lt(vf_sub(gxw, vx), zero)) << i;
        ob[RAST__PLANE_BOTTOM] |= vm_bits(vf_lt(vf_add(gyw, vy), zero)) << i;
        ob[RAST__PLANE_TOP] |= vm_bits(vf_lt(vf_sub(gyw, vy), zero)) << i;
        wpos |= vm_bits(vf_gt(vw, zero)) << i;
        const vfloat nx = vf_div(vx, vw), ny = vf_div(vy, vw);
        const vfloat sx = vf_mul(vf_add(vf_mul(nx, half), half), fw);
        const vfloat sy = vf_mul(vf_sub(half, vf_mul(ny, half)), fh);
        vi_store(X + i, vi_from_vf_round(vf_min(vf_max(vf_mul(sx, fix), lox), hix)));
        vi_store(Y + i, vi_from_vf_round(vf_min(vf_max(vf_mul(sy, fix), loy), hiy)));
    }
    const vdouble dhalf = vd_set1(0.5), done = vd_set1(1.0);
    for (int i = 0; i < RAST__VBLOCK; i += VD_W) {
        const vdouble dz = vd_load_f(z + i), dw = vd_load_f(w + i);
        vd_storeu(zw + i, vd_add(vd_mul(vd_div(dz, dw), dhalf), dhalf));
        vd_storeu(iw + i, vd_div(done, dw));
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
/* SETUP_PLANES: the planes function of the table (default: the one above;
 * raster_sse2.c and raster_neon.c keep the scalar one, see there). */
#ifndef SETUP_PLANES
#define SETUP_PLANES SIMD_FN(rast__planes)
#endif
const rast__setup_isa SIMD_FN(rast__setup_isa) = { SETUP_PLANES, SIMD_FN(rast__vfill), FRONT_FN,
                                                   VPASS_FN, FRONTV_FN };
