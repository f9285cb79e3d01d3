/* kin_skin_rows.inl - the per-vertex LBS blend of the skinning kernels,
 * written once on the vector layer for every SIMD_W (4, 8, 16): SIMD_W
 * vertices' blended joint matrices, each built as the reference builds it
 * (zero weights skipped, w * M added in influence order onto +0), then
 * transposed into structure-of-arrays vectors. Included after the layer by
 * kin_skin_simd.inl (the 4-lane blend of SSE2 and NEON), kin_skin_avx2.c
 * (its lbs_block) and kin_skin_avx512.c (its rows path, for blocks that
 * read joints the joint table does not hold).
 *
 * lbs_rows(mesh, jm, v, a, wsum): vertices v .. v + SIMD_W - 1; a[c*3+r]
 * lane l = column c, row r of vertex v + l's blended matrix; *wsum lane l
 * = its weight sum (the plain sum of the nonzero weights, in order).
 *
 * A matrix is NV = 16 / SIMD_W vectors (vector h: floats SIMD_W h ..,
 * block J of it column NB h + J, NB = SIMD_W / 4 blocks); vf_tr4 of
 * vector h of 4 vertices 4I .. 4I+3 gives, per row r, block J = column
 * NB h + J of those 4 vertices; vf_tr_blocks over I gathers the 4-vertex
 * groups into one vector per column. */
#ifndef KIN_SKIN_ROWS_INL
#define KIN_SKIN_ROWS_INL

/* Bit i set when weight i is not 0 (NaN counts as not 0: the reference's
 * "w == 0: skip"); with 4 lanes one layer compare, wider ISAs read the 4
 * weights with kin__nonzero4 (SSE). */
SIMD_INL unsigned kin_rows_nonzero4(const float *w)
{
#if SIMD_W == 4
    return vm_bits(vf_ne(vf_loadu(w), vf_zero()));
#else
    return kin__nonzero4(w);
#endif
}

static inline void lbs_rows(const kin_mesh *mesh, const kin_mat4 *jm, int v, vfloat a[12],
                            vfloat *wsum)
{
    enum { NV = 16 / SIMD_W, NB = SIMD_W / 4 };
    _Alignas(SIMD_ALIGN) float ws[SIMD_W];
    vfloat r[SIMD_W][NV];   /* [vertex][vector of its matrix] */
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < SIMD_W; l++, j += 4, w += 4) {
        vfloat c[NV];
        for (int h = 0; h < NV; h++) c[h] = vf_zero();
        float s = 0.0f;
        for (unsigned bits = kin_rows_nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            const vfloat wv = vf_set1(w[i]);
            const float *m = jm[j[i]].m;
            for (int h = 0; h < NV; h++) c[h] = vf_add(c[h], vf_mul(wv, vf_loadu(m + SIMD_W * h)));
            s += w[i];
        }
        for (int h = 0; h < NV; h++) r[l][h] = c[h];
        ws[l] = s;
    }
    *wsum = vf_load(ws);
    for (int h = 0; h < NV; h++) {
        /* s[rho][I], block J: column NB h + J, row rho of vertices 4I .. 4I+3 */
        vfloat s[4][NB];
        for (int I = 0; I < NB; I++) {
            vfloat t[4];
            vf_tr4(r[4 * I][h], r[4 * I + 1][h], r[4 * I + 2][h], r[4 * I + 3][h], t);
            for (int rho = 0; rho < 4; rho++) s[rho][I] = t[rho];
        }
        for (int rho = 0; rho < 3; rho++) {
            vfloat o[NB];
            vf_tr_blocks(s[rho], o);
            for (int J = 0; J < NB; J++) a[(NB * h + J) * 3 + rho] = o[J];
        }
    }
}

#endif
