/* pipe_aa.c - the anti-aliased coverage mask of an eye (pipe_aa.h). */
#include "pipe_aa.h"
#include "../cpu/mask_rows.h"
#include "../cpu/ef_mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void box_empty(int b[4])
{
    b[0] = b[1] = b[2] = b[3] = 0;
}

static int box_is_empty(const int b[4])
{
    return b[0] >= b[2] || b[1] >= b[3];
}

/* b grown by the rectangle x0, y0, x1, y1 (exclusive), clamped to w x h. */
static void box_add(int b[4], int x0, int y0, int x1, int y1, int w, int h)
{
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > w) x1 = w;
    if (y1 > h) y1 = h;
    if (x0 >= x1 || y0 >= y1) return;
    if (box_is_empty(b)) {
        b[0] = x0, b[1] = y0, b[2] = x1, b[3] = y1;
        return;
    }
    if (x0 < b[0]) b[0] = x0;
    if (y0 < b[1]) b[1] = y0;
    if (x1 > b[2]) b[2] = x1;
    if (y1 > b[3]) b[3] = y1;
}

int pipe__aa_init(pipe__aa *a, int count, int width, int height, int with_soft)
{
    memset(a, 0, sizeof *a);
    if ((count != 4 && count != 8 && count != 16) || width < 1 || height < 1) return -1;
    const size_t px = (size_t)width * (size_t)height;
    a->count = count;
    a->width = width;
    a->height = height;
    a->samples = calloc(px, sizeof *a->samples);
    a->cov = calloc(px, 1);
    a->colsum = calloc((size_t)width + 2, sizeof *a->colsum);
    a->colflip = calloc((size_t)width + 2, 1);
    if (with_soft) a->soft = calloc(px, 1);
    a->tw = (width + PIPE__AA_TILE - 1) / PIPE__AA_TILE;
    a->th = (height + PIPE__AA_TILE - 1) / PIPE__AA_TILE;
    a->tile = calloc((size_t)a->tw * (size_t)a->th, 1);
    a->tsat = calloc((size_t)(a->tw + 1) * (size_t)(a->th + 1), sizeof *a->tsat);
    if (!a->samples || !a->cov || !a->colsum || !a->colflip || (with_soft && !a->soft) ||
        !a->tile || !a->tsat)
        return -1;
    return 0;
}

void pipe__aa_free(pipe__aa *a)
{
    EF_FREE_ALL(a->samples, a->cov, a->soft, a->colsum, a->colflip, a->tile, a->tsat, a->idx,
                a->sxy);
    memset(a, 0, sizeof *a);
}

void pipe__aa_begin(pipe__aa *a)
{
    const int *b = a->box;
    for (int y = b[1]; y < b[3]; y++) {
        memset(a->samples + (size_t)y * (size_t)a->width + b[0], 0,
               sizeof *a->samples * (size_t)(b[2] - b[0]));
        memset(a->cov + (size_t)y * (size_t)a->width + b[0], 0, (size_t)(b[2] - b[0]));
    }
    box_empty(a->box);
    b = a->soft_box;
    for (int y = b[1]; a->soft && y < b[3]; y++)
        memset(a->soft + (size_t)y * (size_t)a->width + b[0], 0, (size_t)(b[2] - b[0]));
    box_empty(a->soft_box);
    a->gmask = NULL;
}

/* tiles of the pixel rectangle x0..x1, y0..y1 (inclusive, clamped) set */
static void tiles_mark(pipe__aa *a, int x0, int y0, int x1, int y1)
{
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > a->width - 1) x1 = a->width - 1;
    if (y1 > a->height - 1) y1 = a->height - 1;
    for (int ty = y0 / PIPE__AA_TILE; ty <= y1 / PIPE__AA_TILE; ty++)
        for (int tx = x0 / PIPE__AA_TILE; tx <= x1 / PIPE__AA_TILE; tx++)
            a->tile[(size_t)ty * (size_t)a->tw + (size_t)tx] = 1;
}

/* first and last non-zero byte of r[0..n-1]: *lo > *hi when none */
static void row_span(const uint8_t *r, int n, int *lo, int *hi)
{
    const int i = ef_row_first_set(r, 0, n);
    if (i >= n) {
        *lo = 1, *hi = 0;
        return;
    }
    *lo = i, *hi = ef_row_last_set(r, i, n) - 1;
}

void pipe__aa_band(pipe__aa *a, const uint8_t *mask)
{
    const int W = a->width, H = a->height, tw = a->tw, th = a->th;
    memset(a->tile, 0, (size_t)tw * (size_t)th);
    /* A 3x3 window is not uniform iff two 4-neighbours in it differ: for
     * each differing pair, the tiles of every pixel whose window holds
     * both (a superset: the pair's box grown by 1). Rows of zeros have no
     * pair inside; a vertical pair needs a non-zero pixel in one row. */
    int lo, hi;
    row_span(mask, W, &lo, &hi);
    for (int y = 0; y < H; y++) {
        const uint8_t *r = mask + (size_t)y * (size_t)W;
        int nlo = 1, nhi = 0;
        if (y + 1 < H) row_span(r + W, W, &nlo, &nhi);
        if (lo <= hi) {
            /* horizontal pairs (x, x + 1) */
            const int x0 = lo > 0 ? lo - 1 : 0;
            for (int x = x0; x <= hi && x + 1 < W; x++)
                if ((r[x] != 0) != (r[x + 1] != 0)) tiles_mark(a, x - 1, y - 1, x + 2, y + 1);
        }
        if (y + 1 < H && (lo <= hi || nlo <= nhi)) {
            /* vertical pairs (y, y + 1) where either row is non-zero */
            int x0 = lo <= hi ? lo : nlo, x1 = lo <= hi ? hi : nhi;
            if (nlo <= nhi && nlo < x0) x0 = nlo;
            if (nlo <= nhi && nhi > x1) x1 = nhi;
            for (int x = x0; x <= x1; x++)
                if ((r[x] != 0) != (r[x + W] != 0)) tiles_mark(a, x - 1, y - 1, x + 1, y + 2);
        }
        lo = nlo, hi = nhi;
    }
    /* summed-area table: tsat[(ty) * (tw + 1) + tx] = tiles above-left */
    int *S = a->tsat;
    const size_t sw = (size_t)tw + 1;
    memset(S, 0, sizeof *S * sw);
    for (int ty = 0; ty < th; ty++) {
        int run = 0;
        S[(size_t)(ty + 1) * sw] = 0;
        for (int tx = 0; tx < tw; tx++) {
            run += a->tile[(size_t)ty * (size_t)tw + (size_t)tx];
            S[(size_t)(ty + 1) * sw + (size_t)tx + 1] = S[(size_t)ty * sw + (size_t)tx + 1] + run;
        }
    }
    a->gmask = mask;
}

/* 1 when a band tile meets the pixel rectangle x0..x1, y0..y1 (inclusive;
 * clamped, an empty rectangle meets none) */
static int band_meets(const pipe__aa *a, int x0, int y0, int x1, int y1)
{
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > a->width - 1) x1 = a->width - 1;
    if (y1 > a->height - 1) y1 = a->height - 1;
    if (x0 > x1 || y0 > y1) return 0;
    const int tx0 = x0 / PIPE__AA_TILE, ty0 = y0 / PIPE__AA_TILE;
    const int tx1 = x1 / PIPE__AA_TILE + 1, ty1 = y1 / PIPE__AA_TILE + 1;
    const size_t sw = (size_t)a->tw + 1;
    const int *S = a->tsat;
    return S[(size_t)ty1 * sw + (size_t)tx1] - S[(size_t)ty0 * sw + (size_t)tx1] -
               S[(size_t)ty1 * sw + (size_t)tx0] + S[(size_t)ty0 * sw + (size_t)tx0] >
           0;
}

/* buf grown to n items of size bytes when it holds fewer (*cap): the
 * buffer, or NULL (out of memory; buf is kept and still held). */
static void *grow(void *buf, int *cap, int n, size_t size)
{
    if (n <= *cap) return buf;
    void *b = realloc(buf, size * (size_t)n);
    if (b) *cap = n;
    return b;
}

/* a->sxy: the pixel x, y of each vertex of clip (NaN at or behind the eye
 * plane, w <= 1e-6, or from a NaN), once per mesh for both the mesh's box
 * and the band filter. 0, or -1 (out of memory). */
static int project_vertices(pipe__aa *a, const float *clip, int vertex_count)
{
    float *n = grow(a->sxy, &a->sxy_cap, vertex_count, 2 * sizeof *n);
    if (!n) return -1;
    a->sxy = n;
    const float W = (float)a->width, H = (float)a->height;
    for (int i = 0; i < vertex_count; i++) {
        const float *v = clip + 4 * (size_t)i;
        float sx = NAN, sy = NAN;
        if (v[3] > 1e-6f) {
            sx = (v[0] / v[3] * 0.5f + 0.5f) * W;
            sy = (0.5f - v[1] / v[3] * 0.5f) * H;
        }
        a->sxy[2 * i] = sx;
        a->sxy[2 * i + 1] = sy;
    }
    return 0;
}

/* The box x0, y0, x1, y1 (b; x0 > x1 when n is 0) of the n projected
 * points sxy[ix[k]] (ix NULL: sxy[k]); 1 (b unfinished) when an index is
 * not below vertex_count or a point is a NaN (at or behind the eye). */
static int sxy_box(const float *sxy, const uint32_t *ix, int n, int vertex_count, float b[4])
{
    b[0] = b[1] = 1e30f;
    b[2] = b[3] = -1e30f;
    for (int k = 0; k < n; k++) {
        const uint32_t i = ix ? ix[k] : (uint32_t)k;
        if (i >= (uint32_t)vertex_count) return 1;
        const float sx = sxy[2 * (size_t)i], sy = sxy[2 * (size_t)i + 1];
        if (!(sx == sx) || !(sy == sy)) return 1;
        if (sx < b[0]) b[0] = sx;
        if (sx > b[2]) b[2] = sx;
        if (sy < b[1]) b[1] = sy;
        if (sy > b[3]) b[3] = sy;
    }
    return 0;
}

/* b clamped to 4 px around the W x H target */
static void box_clamp(float b[4], float W, float H)
{
    for (int k = 0; k < 4; k++) {
        const float hi = (k & 1 ? H : W) + 4.0f;
        b[k] = b[k] < -4.0f ? -4.0f : b[k] > hi ? hi : b[k];
    }
}

/* The triangles of indices that may cover a sample of a band tile, into
 * a->idx (the vertices' pixel positions in a->sxy: project_vertices): a
 * triangle with a vertex at or behind the eye plane, a NaN or
 * a bad index is kept (rast_draw_aa clips it, or refuses the mesh). */
static int band_filter(pipe__aa *a, int vertex_count, const uint32_t *indices, int tri_count)
{
    uint32_t *n = grow(a->idx, &a->idx_cap, tri_count, 3 * sizeof *n);
    if (!n) return -1;
    a->idx = n;
    const float W = (float)a->width, H = (float)a->height;
    const float *sxy = a->sxy;
    int kept = 0;
    for (int t = 0; t < tri_count; t++) {
        const uint32_t *ix = indices + 3 * (size_t)t;
        float b[4];
        int keep = sxy_box(sxy, ix, 3, vertex_count, b);
        if (!keep) {
            /* off the target entirely: nothing to draw; else the pixels
             * whose samples the triangle may reach (a sample is at most
             * half a pixel from its centre; 1 px covers that and the
             * snapping) */
            if (b[2] < -4.0f || b[3] < -4.0f || b[0] > W + 4.0f || b[1] > H + 4.0f) continue;
            box_clamp(b, W, H);
            keep = band_meets(a, (int)b[0] - 1, (int)b[1] - 1, (int)b[2] + 1, (int)b[3] + 1);
        }
        if (keep) {
            uint32_t *o = a->idx + 3 * (size_t)kept++;
            o[0] = ix[0], o[1] = ix[1], o[2] = ix[2];
        }
    }
    return kept;
}

rast_result pipe__aa_draw(pipe__aa *a, rast_context *ctx, const float *clip, int vertex_count,
                          const uint32_t *indices, int tri_count, rast_cull cull)
{
    if (tri_count <= 0) return RAST_OK;
    /* the vertices' pixel box: every covered sample lies in the convex
     * hull of the projected vertices when all are in front of the eye
     * (clipping only cuts the triangles); 2 px for the snapping */
    if (project_vertices(a, clip, vertex_count)) return RAST_ERR_ARGS; /* out of memory */
    float b[4];
    if (sxy_box(a->sxy, NULL, vertex_count, vertex_count, b))
        box_add(a->box, 0, 0, a->width, a->height, a->width, a->height);
    else if (b[0] <= b[2]) {
        /* clamped in float first: huge values do not overflow an int */
        box_clamp(b, (float)a->width, (float)a->height);
        box_add(a->box, (int)b[0] - 2, (int)b[1] - 2, (int)b[2] + 3, (int)b[3] + 3, a->width,
                a->height);
    }
    if (a->gmask) {
        const int kept = band_filter(a, vertex_count, indices, tri_count);
        if (kept < 0) return RAST_ERR_ARGS; /* out of memory */
        if (kept == 0) return RAST_OK;
        indices = a->idx;
        tri_count = kept;
    }
    rast_aa_target t = {a->width, a->height, a->samples, a->width, a->count};
    rast_mesh_desc d = {
        .clip = clip,
        .vertex_count = vertex_count,
        .attr = NULL,
        .attr_count = 0,
        .indices = indices,
        .tri_count = tri_count,
        .cull = cull,
    };
    return ctx ? rast_context_draw_aa(ctx, &t, &d, NULL) : rast_draw_aa(&t, &d, NULL);
}

rast_result pipe__aa_draw_pose(pipe__aa *a, const pipe_pose *ps, rast_context *ctx,
                               const kin_camera *cam, rast_cull cull, float *clip)
{
    for (int i = 0; i < ps->model->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        rast_transform_points(cam->view_proj.m, ps->pos[i], me->vertex_count, clip);
        rast_result r = pipe__aa_draw(a, ctx, clip, me->vertex_count, me->indices,
                                      me->index_count / 3, cull);
        if (r != RAST_OK) return r;
    }
    return RAST_OK;
}

/* Bits set in a byte (a table: the portable builds have no popcnt
 * instruction and __builtin_popcount becomes a library call). */
#define B2(k) k, k + 1, k + 1, k + 2
#define B4(k) B2(k), B2(k + 1), B2(k + 1), B2(k + 2)
#define B6(k) B4(k), B4(k + 1), B4(k + 1), B4(k + 2)
static const uint8_t bits8[256] = {B6(0), B6(1), B6(1), B6(2)};

void pipe__aa_resolve(pipe__aa *a)
{
    const int *b = a->box;
    if (box_is_empty(b)) return;
    /* rast_aa_resolve's rule: round(255 covered / n), halves up */
    const unsigned n = (unsigned)a->count, mask = (1u << n) - 1u;
    uint8_t lut[17];
    for (unsigned c = 0; c <= n; c++) lut[c] = (uint8_t)((510u * c + n) / (2u * n));
    for (int y = b[1]; y < b[3]; y++) {
        const uint32_t *s = a->samples + (size_t)y * (size_t)a->width;
        uint8_t *o = a->cov + (size_t)y * (size_t)a->width;
        if (!a->gmask) {
            for (int x = b[0]; x < b[2]; x++) {
                const uint32_t v = s[x] & mask;
                o[x] = v ? lut[bits8[v & 255u] + bits8[v >> 8]] : 0;
            }
            continue;
        }
        const uint8_t *g = a->gmask + (size_t)y * (size_t)a->width;
        const uint8_t *trow = a->tile + (size_t)(y / PIPE__AA_TILE) * (size_t)a->tw;
        for (int x = b[0]; x < b[2];) {
            const int t = x / PIPE__AA_TILE;
            int xe = (t + 1) * PIPE__AA_TILE;
            if (xe > b[2]) xe = b[2];
            if (trow[t]) {
                for (; x < xe; x++) {
                    const uint32_t v = s[x] & mask;
                    o[x] = v ? lut[bits8[v & 255u] + bits8[v >> 8]] : 0;
                }
            } else {
                /* rast_draw's mask: 0 or 255 */
                int xr = xe;
                while (xr < b[2] && !trow[xr / PIPE__AA_TILE]) {
                    xr += PIPE__AA_TILE;
                    if (xr > b[2]) xr = b[2];
                }
                memcpy(o + x, g + x, (size_t)(xr - x));
                x = xr;
            }
        }
    }
}

void pipe__aa_refined(pipe__aa *a, const uint8_t *mask, const uint8_t *refined, int band)
{
    const int W = a->width, H = a->height;
    int b[4] = {0, 0, 0, 0};
    if (box_is_empty(a->box)) return;
    box_add(b, a->box[0] - band - 2, a->box[1] - band - 2, a->box[2] + band + 2,
            a->box[3] + band + 2, W, H);
    memcpy(a->soft_box, b, sizeof b);
    /* colsum[x + 1] = refined pixels (>= 128) of rows y-1..y+1 in column x,
     * colflip[x + 1] = 1 when one of them differs from the mask; columns
     * outside the image count 0 (colsum[0], colsum[W + 1]). */
    int *cs = a->colsum;
    uint8_t *cf = a->colflip;
    const int x0 = b[0] > 0 ? b[0] - 1 : 0, x1 = b[2] < W ? b[2] + 1 : W;
    for (int y = b[1]; y < b[3]; y++) {
        memset(cs + x0, 0, sizeof *cs * (size_t)(x1 - x0 + 2));
        memset(cf + x0, 0, (size_t)(x1 - x0 + 2));
        for (int yy = y - 1; yy <= y + 1; yy++) {
            if (yy < 0 || yy >= H) continue;
            const uint8_t *r = refined + (size_t)yy * (size_t)W;
            const uint8_t *m = mask + (size_t)yy * (size_t)W;
            for (int x = x0; x < x1; x++) {
                const int in = r[x] >= 128;
                cs[x + 1] += in;
                cf[x + 1] |= (uint8_t)(in != (m[x] >= 128));
            }
        }
        const uint8_t *cov = a->cov + (size_t)y * (size_t)W;
        uint8_t *o = a->soft + (size_t)y * (size_t)W;
        for (int x = b[0]; x < b[2]; x++) {
            if (cf[x] | cf[x + 1] | cf[x + 2]) {
                /* round(255 n / 9) */
                const int n = cs[x] + cs[x + 1] + cs[x + 2];
                o[x] = (uint8_t)((510 * n + 9) / 18);
            } else {
                o[x] = cov[x];
            }
        }
    }
}

/* 0x80 in each byte of the 8 at p that is not 0 */
static uint64_t nz8(const uint8_t *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    const uint64_t lo7 = 0x7f7f7f7f7f7f7f7full;
    return (((v & lo7) + lo7) | v) & ~lo7;
}

/* 1 when one of the 8 pixels at x has m > 0 and mask 0 */
static int fill_cand8(const uint8_t *m, const uint8_t *k)
{
    return (nz8(m) & ~nz8(k)) != 0;
}

/* The first x of x..x1-1 that m covers and mask does not (mr[x] != 0,
 * kr[x] == 0: a pixel the normals' fill writes), else x1. */
static int next_fill(const uint8_t *mr, const uint8_t *kr, int x, int x1)
{
    for (; x < x1; x++) {
        if (x + 8 <= x1 && !fill_cand8(mr + x, kr + x)) {
            x += 7;
            continue;
        }
        if (mr[x] != 0 && kr[x] == 0) return x;
    }
    return x1;
}

void pipe__aa_fill_normals(pipe__aa *a, const uint8_t *m, const uint8_t *mask, float *nrm)
{
    const int W = a->width, H = a->height;
    const int *b = a->soft && m == a->soft ? a->soft_box : a->box;
    box_empty(a->nbox);
    a->nsrc = m;
    for (int y = b[1]; y < b[3]; y++) {
        const uint8_t *mr = m + (size_t)y * (size_t)W;
        const uint8_t *kr = mask + (size_t)y * (size_t)W;
        for (int x = next_fill(mr, kr, b[0], b[2]); x < b[2]; x = next_fill(mr, kr, x + 1, b[2])) {
            float s[3] = {0.0f, 0.0f, 0.0f};
            for (int yy = y - 1; yy <= y + 1; yy++) {
                if (yy < 0 || yy >= H) continue;
                for (int xx = x - 1; xx <= x + 1; xx++) {
                    if (xx < 0 || xx >= W || mask[(size_t)yy * (size_t)W + (size_t)xx] == 0)
                        continue;
                    const float *n = nrm + 3 * ((size_t)yy * (size_t)W + (size_t)xx);
                    s[0] = s[0] + n[0];
                    s[1] = s[1] + n[1];
                    s[2] = s[2] + n[2];
                }
            }
            float *o = nrm + 3 * ((size_t)y * (size_t)W + (size_t)x);
            o[0] = s[0];
            o[1] = s[1];
            o[2] = s[2];
            box_add(a->nbox, x, y, x + 1, y + 1, W, H);
        }
    }
}

void pipe__aa_unfill(pipe__aa *a, const uint8_t *mask, float *nrm)
{
    const int W = a->width;
    const int *b = a->nbox;
    const uint8_t *m = a->nsrc;
    /* the pixels pipe__aa_fill_normals wrote: m > 0 and mask 0 (m is
     * unchanged since) */
    for (int y = b[1]; m && y < b[3]; y++) {
        const uint8_t *mr = m + (size_t)y * (size_t)W;
        const uint8_t *kr = mask + (size_t)y * (size_t)W;
        for (int x = next_fill(mr, kr, b[0], b[2]); x < b[2]; x = next_fill(mr, kr, x + 1, b[2])) {
            float *o = nrm + 3 * ((size_t)y * (size_t)W + (size_t)x);
            o[0] = o[1] = o[2] = 0.0f;
        }
    }
    box_empty(a->nbox);
    a->nsrc = NULL;
}
