/* raster_aa.c - anti-aliased coverage: the sample positions, the scalar
 * reference sample scan, the draw driver with a given sample scan
 * (rast_draw_aa in raster_context.c chooses it), clear and resolve. The
 * SIMD sample scans (raster_aa.inl) give the bits of rast__scan_aa_ref;
 * the sample patterns are in raster_setup.c, which the set-up and the
 * scans share. */
#include "raster_internal.h"

#include <stddef.h>
#include <string.h>

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

static rast_result validate_aa(const rast_aa_target *t, const rast_mesh_desc *m)
{
    if (!t || !m || !t->samples || !rast__aa_pattern(t->count))
        return RAST_ERR_ARGS;
    /* The checks of rast_draw, with the sample plane in the mask's place
     * and no attribute plane. */
    rast_target v = { t->width, t->height, NULL, 0, (uint8_t *)(void *)t->samples,
                      t->stride, NULL, 0, m->attr_count, NULL, 0 };
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
