/* raster_xform.inl - the vertex transforms of raster.h (rast_transform_points,
 * rast_transform_dirs) written once on the vector layer (src/cpu/simd.h)
 * and compiled per ISA by raster_avx2.c (8 vertices per step) and
 * raster_avx512.c (16): SIMD_FN(rast__transform_points), SIMD_FN(
 * rast__transform_dirs). Each lane runs the reference's expressions
 * (raster_ref.c, docs/raster.md section 7) in the same order with the same
 * IEEE operations (no contraction), so the bytes are the reference's; the
 * last n % SIMD_W vertices take the reference.
 *
 * Included after one layer implementation and the includer's
 *   void xf_store4(float *p, vfloat c0, vfloat c1, vfloat c2, vfloat c3)
 *        interleaves four component vectors: p[4l + k] = lane l of ck
 *        (writes exactly 4 SIMD_W floats). */

/* ((m[r]*x + m[4+r]*y) + m[8+r]*z), the reference's order. */
SIMD_INL vfloat xf_row(const float *m, int r, vfloat x, vfloat y, vfloat z)
{
    return vf_add(vf_add(vf_mul(vf_set1(m[r]), x), vf_mul(vf_set1(m[4 + r]), y)),
                  vf_mul(vf_set1(m[8 + r]), z));
}

void SIMD_FN(rast__transform_points)(const float mvp[16], const float *pos, int n, float *clip)
{
    int i = 0;
    for (; i + SIMD_W <= n; i += SIMD_W) {
        vfloat x, y, z;
        vf_load3(pos + 3 * (size_t)i, &x, &y, &z);
        vfloat c[4];
#pragma GCC unroll 4
        for (int r = 0; r < 4; r++)
            c[r] = vf_add(xf_row(mvp, r, x, y, z), vf_set1(mvp[12 + r]));
        xf_store4(clip + 4 * (size_t)i, c[0], c[1], c[2], c[3]);
    }
    if (i < n)
        rast__transform_points_ref(mvp, pos + 3 * (size_t)i, n - i, clip + 4 * (size_t)i);
}

/* len = sqrt((r0*r0 + r1*r1) + r2*r2) in double, out_k = (float)(r_k / len)
 * where len > 0, else +0 (NaN lengths included). */
void SIMD_FN(rast__transform_dirs)(const float m[16], const float *v, int n, float *out)
{
    const vdouble dzero = vd_set1(0.0);
    int i = 0;
    for (; i + SIMD_W <= n; i += SIMD_W) {
        vfloat x, y, z;
        vf_load3(v + 3 * (size_t)i, &x, &y, &z);
        const vfloat r[3] = { xf_row(m, 0, x, y, z), xf_row(m, 1, x, y, z),
                              xf_row(m, 2, x, y, z) };
        vdouble q[2][3];
        unsigned pos = 0;
#pragma GCC unroll 2
        for (int h = 0; h < 2; h++) {
            const vdouble d0 = vd_from_vf(r[0], h), d1 = vd_from_vf(r[1], h);
            const vdouble d2 = vd_from_vf(r[2], h);
            const vdouble len =
                vd_sqrt(vd_add(vd_add(vd_mul(d0, d0), vd_mul(d1, d1)), vd_mul(d2, d2)));
            pos |= vd_gt_bits(len, dzero) << (VD_W * h);
            q[h][0] = vd_div(d0, len);
            q[h][1] = vd_div(d1, len);
            q[h][2] = vd_div(d2, len);
        }
        const vmask ok = vm_from_bits(pos);
        vf_store3(out + 3 * (size_t)i, vf_selz(ok, vf_from_vd(q[0][0], q[1][0])),
                  vf_selz(ok, vf_from_vd(q[0][1], q[1][1])),
                  vf_selz(ok, vf_from_vd(q[0][2], q[1][2])));
    }
    if (i < n)
        rast__transform_dirs_ref(m, v + 3 * (size_t)i, n - i, out + 3 * (size_t)i);
}
