/* raster_aa.c - anti-aliased coverage: the standard sample patterns, the
 * scalar reference sample scan, rast_draw_aa, clear and resolve. The SIMD
 * sample scans (raster_aa.inl) give the bits of rast__scan_aa_ref. */
#include "raster_internal.h"

#include "../cpu/cpu.h"

#include <stddef.h>
#include <string.h>

/* Direct3D standard multisample positions, 1/16 px from the pixel centre
 * (x right, y down). */
static const int8_t pattern4[4][2] = { { -2, -6 }, { 6, -2 }, { -6, 2 }, { 2, 6 } };
static const int8_t pattern8[8][2] = { { 1, -3 }, { -1, 3 }, { 5, 1 },  { -3, -5 },
                                       { -5, 5 }, { -7, -1 }, { 3, 7 }, { 7, -7 } };
static const int8_t pattern16[16][2] = {
    { 1, 1 },   { -1, -3 }, { -3, 2 },  { 4, -1 }, { -5, -2 }, { 2, 5 },  { 5, 3 },   { 3, -5 },
    { -2, 6 },  { 0, -7 },  { -4, -6 }, { -6, 4 }, { -8, 0 },  { 7, -4 }, { 6, 7 },   { -7, -8 },
};

const int8_t (*rast__aa_pattern(int count))[2]
{
    switch (count) {
    case 4:  return pattern4;
    case 8:  return pattern8;
    case 16: return pattern16;
    default: return NULL;
    }
}

int rast_aa_positions(int count, int xy[2 * RAST_AA_MAX_SAMPLES])
{
    const int8_t (*p)[2] = rast__aa_pattern(count);
    if (!p || !xy)
        return 0;
    for (int s = 0; s < count; s++) {
        xy[2 * s] = p[s][0];
        xy[2 * s + 1] = p[s][1];
    }
    return count;
}

long rast__scan_aa_ref(const rast_aa_target *t, const rast__tri *tri, int ya, int yb)
{
    const int ys = ya > tri->y0 ? ya : tri->y0;
    const int ye = yb < tri->y1 ? yb : tri->y1;
    if (ys > ye)
        return 0;
    const int n = t->count;
    const int8_t (*pat)[2] = rast__aa_pattern(n);
    /* Edge offset of each sample from the centre: E(c + d) - E(c) =
     * dx * d_y - dy * d_x with d = 16 * offset (1/256 px). */
    int64_t off[3][RAST_AA_MAX_SAMPLES];
    for (int k = 0; k < 3; k++) {
        const int64_t dx = tri->e_dy[k] / RAST__FIX_ONE, dy = -tri->e_dx[k] / RAST__FIX_ONE;
        for (int s = 0; s < n; s++)
            off[k][s] = dx * (16 * pat[s][1]) - dy * (16 * pat[s][0]);
    }
    long touched = 0;
    for (int y = ys; y <= ye; y++) {
        uint32_t *row = t->samples + (size_t)y * (size_t)t->stride;
        for (int x = tri->x0; x <= tri->x1; x++) {
            int64_t e[3];
            for (int k = 0; k < 3; k++)
                e[k] = tri->e_c[k] + (int64_t)(y - tri->y0) * tri->e_dy[k] +
                       (int64_t)(x - tri->x0) * tri->e_dx[k];
            uint32_t bits = 0;
            for (int s = 0; s < n; s++)
                if (e[0] + off[0][s] >= 0 && e[1] + off[1][s] >= 0 && e[2] + off[2][s] >= 0)
                    bits |= 1u << s;
            if (bits) {
                row[x] |= bits;
                touched++;
            }
        }
    }
    return touched;
}

rast__scan_aa_fn rast__scan_aa_for_isa(int isa)
{
#if defined(__x86_64__)
    switch (isa) {
    case EF_ISA_AVX512: return rast__scan_aa_avx512;
    case EF_ISA_AVX2:   return rast__scan_aa_avx2;
    case EF_ISA_SSE2:   return rast__scan_aa_sse2;
    default:            break;
    }
#else
    (void)isa;
#endif
    return rast__scan_aa_ref;
}

static rast_result validate_aa(const rast_aa_target *t, const rast_mesh_desc *m)
{
    if (!t || !m || !t->samples || !rast__aa_pattern(t->count))
        return RAST_ERR_ARGS;
    /* The checks of rast_draw, with the sample plane in the mask's place
     * and no attribute plane. */
    rast_target v = { t->width, t->height, NULL, 0, (uint8_t *)(void *)t->samples,
                      t->stride, NULL, 0, m->attr_count };
    return rast__validate(&v, m);
}

rast_result rast__draw_aa_with(const rast_aa_target *t, const rast_mesh_desc *m,
                               rast_stats *stats, rast__scan_aa_fn scan)
{
    rast_result r = validate_aa(t, m);
    if (r != RAST_OK)
        return r;
    rast__view view;
    rast__view_init(&view, t->width, t->height, 0);
    rast_stats st = { 0 };
    st.tris_in = m->tri_count;
    rast__tri tri[RAST__MAX_FAN];
    for (int ti = 0; ti < m->tri_count; ti++) {
        const int n = rast__prepare_aa(&view, m, ti, tri, &st);
        for (int i = 0; i < n; i++)
            st.pixels_written += scan(t, &tri[i], tri[i].y0, tri[i].y1);
    }
    if (stats)
        rast__stats_add(stats, &st);
    return RAST_OK;
}

rast_result rast_draw_aa(const rast_aa_target *t, const rast_mesh_desc *m,
                         rast_stats *stats)
{
    return rast__draw_aa_with(t, m, stats, rast__scan_aa_for_isa(rast_draw_isa()));
}

void rast_aa_clear(const rast_aa_target *t)
{
    if (!t || !t->samples || t->width <= 0 || t->height <= 0 || t->stride < t->width)
        return;
    for (int y = 0; y < t->height; y++)
        memset(t->samples + (size_t)y * (size_t)t->stride, 0,
               (size_t)t->width * sizeof(uint32_t));
}

rast_result rast_aa_resolve(const rast_aa_target *t, uint8_t *mask, int mask_stride)
{
    if (!t || !t->samples || !mask || !rast__aa_pattern(t->count))
        return RAST_ERR_ARGS;
    if (t->width <= 0 || t->height <= 0 || t->width > RAST_MAX_DIM ||
        t->height > RAST_MAX_DIM)
        return RAST_ERR_SIZE;
    if (t->stride < t->width || mask_stride < t->width)
        return RAST_ERR_ARGS;
    const unsigned n = (unsigned)t->count;
    for (int y = 0; y < t->height; y++) {
        const uint32_t *s = t->samples + (size_t)y * (size_t)t->stride;
        uint8_t *o = mask + (size_t)y * (size_t)mask_stride;
        for (int x = 0; x < t->width; x++) {
            const unsigned c = (unsigned)__builtin_popcount(s[x] & ((1u << n) - 1u));
            o[x] = (uint8_t)((510u * c + n) / (2u * n));
        }
    }
    return RAST_OK;
}
