/* raster_aa.inl - the SIMD sample scan of anti-aliased coverage, shared by
 * raster_sse2.c (2 lanes), raster_avx2.c (4) and raster_avx512.c (8): one
 * body in GCC/Clang vector extensions over doubles, compiled for each ISA.
 * Define AA_V (lanes) and AA_FN (name) before including.
 *
 * SAME BITS. The reference tests int64 edge values E + off_s >= 0. Every
 * value here is an integer below 2^48 in magnitude (|E| < 2^47 at any
 * pixel of the box, docs/raster.md section 2; |off_s| <= 2 * 2^23 * 128):
 * converting, adding and the lane products l * e_dx (< 8 * 2^31) are exact
 * in double, so each comparison has the reference's answer. */
#if !defined(__GNUC__) && !defined(__clang__)
#error "raster_aa.inl needs GCC or Clang vector extensions"
#endif

typedef double aa_vd __attribute__((vector_size(8 * AA_V)));
typedef long long aa_vl __attribute__((vector_size(8 * AA_V)));

long AA_FN(const rast_aa_target *t, const rast__tri *tri, int ya, int yb)
{
    const int ys = ya > tri->y0 ? ya : tri->y0;
    const int ye = yb < tri->y1 ? yb : tri->y1;
    if (ys > ye)
        return 0;
    const int n = t->count;
    const int8_t (*pat)[2] = rast__aa_pattern(n);
    double off[3][RAST_AA_MAX_SAMPLES];
    aa_vd ldx[3];
    aa_vd lane;
    for (int l = 0; l < AA_V; l++)
        lane[l] = (double)l;
    for (int k = 0; k < 3; k++) {
        const int64_t dx = tri->e_dy[k] / RAST__FIX_ONE, dy = -tri->e_dx[k] / RAST__FIX_ONE;
        for (int s = 0; s < n; s++)
            off[k][s] = (double)(dx * (16 * pat[s][1]) - dy * (16 * pat[s][0]));
        ldx[k] = lane * (double)tri->e_dx[k];
    }
    long touched = 0;
    for (int y = ys; y <= ye; y++) {
        uint32_t *row = t->samples + (size_t)y * (size_t)t->stride;
        int64_t er[3];
        for (int k = 0; k < 3; k++)
            er[k] = tri->e_c[k] + (int64_t)(y - tri->y0) * tri->e_dy[k];
        for (int x = tri->x0; x <= tri->x1; x += AA_V) {
            const int64_t i = x - tri->x0;
            const aa_vd e0 = (double)(er[0] + i * tri->e_dx[0]) + ldx[0];
            const aa_vd e1 = (double)(er[1] + i * tri->e_dx[1]) + ldx[1];
            const aa_vd e2 = (double)(er[2] + i * tri->e_dx[2]) + ldx[2];
            aa_vl bits = { 0 };
            for (int s = 0; s < n; s++) {
                const aa_vl in = (e0 + off[0][s] >= 0.0) & (e1 + off[1][s] >= 0.0) &
                                 (e2 + off[2][s] >= 0.0);
                bits |= in & (long long)(1u << s);
            }
            const int lanes = tri->x1 - x + 1 < AA_V ? tri->x1 - x + 1 : AA_V;
            for (int l = 0; l < lanes; l++)
                if (bits[l]) {
                    row[x + l] |= (uint32_t)bits[l];
                    touched++;
                }
        }
    }
    return touched;
}
