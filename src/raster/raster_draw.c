/* raster_draw.c - the single-thread draw driver: a validated mesh in
 * chunks of submitted triangles through the set-up (raster_setup.c, with
 * the set-up kernels of an ISA) and then the row scan of that ISA, in
 * submission order; the dirty-tile marks of a context; the vertex buffer
 * of the vector front end. It calls downwards only: the set-up and the
 * kernels it is given (function pointers chosen by raster_context.c, the
 * one place of ISA dispatch). */
#include "raster_internal.h"

#include "../cpu/ef_n10.h"

#include <stddef.h>
#include <stdlib.h>

void rast__stats_add(rast_stats *dst, const rast_stats *s)
{
    dst->tris_in += s->tris_in;
    dst->tris_nonfinite += s->tris_nonfinite;
    dst->tris_clipped_away += s->tris_clipped_away;
    dst->tris_degenerate += s->tris_degenerate;
    dst->tris_culled += s->tris_culled;
    dst->tris_drawn += s->tris_drawn;
    dst->pixels_written += s->pixels_written;
}

int rast__draw_na(const rast_target *t, const rast_mesh_desc *m)
{
    /* Attributes go through clipping only if both sides have them. */
    return ((t->attr || t->attr_n10) && m->attr) ? m->attr_count : 0;
}

/* Marks tiles tx0..tx1 x ty0..ty1 (inclusive, not empty). */
static inline void tiles_mark(rast__tiles *tl, unsigned ty0, unsigned ty1, unsigned tx0,
                              unsigned tx1)
{
    if (tx0 / 64 == tx1 / 64) {   /* the usual case: one word per tile row */
        const unsigned w = tx0 / 64, lo = tx0 % 64, hi = tx1 % 64;
        const uint64_t bits = (hi == 63 ? ~(uint64_t)0 : ((uint64_t)1 << (hi + 1)) - 1u) &
                              ~(((uint64_t)1 << lo) - 1u);
        for (unsigned ty = ty0; ty <= ty1; ty++)
            tl->bits[ty][w] |= bits;
        return;
    }
    for (unsigned ty = ty0; ty <= ty1; ty++)
        for (unsigned w = tx0 / 64; w <= tx1 / 64; w++) {
            const unsigned lo = w * 64 > tx0 ? 0 : tx0 - w * 64;
            const unsigned hi = w * 64 + 63 < tx1 ? 63 : tx1 - w * 64;
            const uint64_t upto = hi == 63 ? ~(uint64_t)0 : ((uint64_t)1 << (hi + 1)) - 1u;
            tl->bits[ty][w] |= upto & ~(((uint64_t)1 << lo) - 1u);
        }
}

/* Pixel coordinates are never negative here (clamped boxes and bands):
 * the tile numbers by unsigned division, a shift. */
void rast__tiles_add(rast__tiles *tl, int ya, int yb, int x0, int x1)
{
    tiles_mark(tl, (unsigned)ya / RAST__TILE, (unsigned)yb / RAST__TILE,
               (unsigned)x0 / RAST__TILE, (unsigned)x1 / RAST__TILE);
}

/* The pixels of a micro record (r->micro != 0): the depth test and the
 * stores of the scan (rast__scan_rows_ref) for its covered pixels, from
 * the values the front end computed with the scan's operations. */
static long micro_apply(const rast_target *t, const rast__tri *r)
{
    long n = 0;
    const int na = (t->attr || t->attr_n10) ? r->attr_count : 0;
    for (unsigned bits = (unsigned)r->micro & 15u; bits; bits &= bits - 1) {
        const int p = __builtin_ctz(bits);
        const int x = r->x0 + (p & 1), y = r->y0 + (p >> 1);
        const float z = r->mz[p];
        if (t->depth) {
            float *d = t->depth + (size_t)y * (size_t)t->depth_stride + x;
            if (!(z < *d))
                continue;
            *d = z;
        }
        t->mask[(size_t)y * (size_t)t->mask_stride + x] = 255;
        n++;
        if (na) {
            const float b1 = r->mb1[p], b2 = r->mb2[p];
            if (t->attr_n10) {   /* na == 3 (validated) */
                float a[3];
                for (int k = 0; k < 3; k++)
                    a[k] = (r->a0[k] + b1 * r->d1[k]) + b2 * r->d2[k];
                t->attr_n10[(size_t)y * (size_t)t->attr_n10_stride + x] =
                    ef_n10_pack(a[0], a[1], a[2]);
                continue;
            }
            float *a = t->attr + (size_t)y * (size_t)t->attr_stride + (size_t)x * (size_t)na;
            for (int k = 0; k < na; k++)
                a[k] = (r->a0[k] + b1 * r->d1[k]) + b2 * r->d2[k];
        }
    }
    return n;
}

long rast__scan_list(const rast_target *t, const rast__tri *tri, int n,
                     rast__scan_rows_fn scan, rast__tiles *tiles, int last[4], int micro)
{
    long px = 0;
    /* the tile rectangle marked last, in locals (the scan is called
     * through a pointer: last[] would be reloaded after every call) */
    int l0 = last[0], l1 = last[1], l2 = last[2], l3 = last[3];
    for (int i = 0; i < n; i++) {
        const rast__tri *r = &tri[i];
        if (micro && r->micro) {
            if (r->micro != RAST__HIDDEN) {
                /* Defensive: the empty test drops boxes up to 2x2 with
                 * no covered centre before they get a record. */
                if (!(r->micro & 15))
                    continue;
                px += micro_apply(t, r);
            }
        } else {
            px += scan(t, r, r->y0, r->y1);
        }
        if (!tiles)
            continue;
        /* Neighbouring triangles mostly lie in the tiles just marked:
         * skip the marking when the tile rectangle is inside the last
         * one marked (those bits are set already). A record's box is
         * clamped to the target: no coordinate is negative. */
        const int tx0 = (int)((unsigned)r->x0 / RAST__TILE);
        const int tx1 = (int)((unsigned)r->x1 / RAST__TILE);
        const int ty0 = (int)((unsigned)r->y0 / RAST__TILE);
        const int ty1 = (int)((unsigned)r->y1 / RAST__TILE);
        if (tx0 >= l0 && tx1 <= l1 && ty0 >= l2 && ty1 <= l3)
            continue;
        tiles_mark(tiles, (unsigned)ty0, (unsigned)ty1, (unsigned)tx0, (unsigned)tx1);
        l0 = tx0;
        l1 = tx1;
        l2 = ty0;
        l3 = ty1;
    }
    last[0] = l0;
    last[1] = l1;
    last[2] = l2;
    last[3] = l3;
    return px;
}

void rast__draw_valid(const rast_target *t, const rast_mesh_desc *m,
                      rast_stats *stats, rast__scan_rows_fn scan,
                      const rast__setup_isa *isa, rast__tiles *tiles)
{
    rast__view view;
    rast__view_init(&view, t->width, t->height, rast__draw_na(t, m));
    rast_stats st = { 0 };
    st.tris_in = m->tri_count;
    /* Front end over chunks of submitted triangles, then the scans of
     * the chunk's triangles in submission order. */
    enum { CHUNK = 16 };
    rast__tri tri[CHUNK * RAST__MAX_FAN];
    rast__vcache vc;
    rast__vcache_reset(&vc);
    int last[4] = { 1, 0, 1, 0 };   /* tiles marked last: x0, x1, y0, y1 (none) */
    for (int ti = 0; ti < m->tri_count; ti += CHUNK) {
        const int te = m->tri_count - ti > CHUNK ? ti + CHUNK : m->tri_count;
        const int n = rast__prepare_range(&view, m, ti, te, &vc, tri, &st, isa);
        st.pixels_written += rast__scan_list(t, tri, n, scan, tiles, last, 0);
    }
    if (stats)
        rast__stats_add(stats, &st);
}

void rast__draw_valid_vb(const rast_target *t, const rast_mesh_desc *m,
                         rast_stats *stats, rast__scan_rows_fn scan,
                         const rast__setup_isa *isa, rast__tiles *tiles, rast__vbuf *vb)
{
    if (!vb || !isa->vpass || !isa->frontv || m->vertex_count > vb->cap) {
        rast__draw_valid(t, m, stats, scan, isa, tiles);
        return;
    }
    rast__view view;
    rast__view_init(&view, t->width, t->height, rast__draw_na(t, m));
    if (t->depth)
        view.hz = t;   /* hidden records (docs/raster.md section 14) */
    rast_stats st = { 0 };
    st.tris_in = m->tri_count;
    isa->vpass(&view, m->clip, m->vertex_count, vb);
    int last[4] = { 1, 0, 1, 0 };
    for (int ti = 0; ti < m->tri_count; ti += RAST__VX_CHUNK) {
        const int te = m->tri_count - ti > RAST__VX_CHUNK ? ti + RAST__VX_CHUNK : m->tri_count;
        const int n = isa->frontv(&view, m, vb, ti, te, vb->out, &st, 1);
        st.pixels_written += rast__scan_list(t, vb->out, n, scan, tiles, last, 1);
    }
    if (stats)
        rast__stats_add(stats, &st);
}

rast__vbuf *rast__vbuf_alloc(int cap)
{
    if (cap < 0 || cap > (1 << 24))
        return NULL;
    const size_t c = ((size_t)cap + 15u) & ~(size_t)15u;
    const size_t head = 64, nout = (size_t)RAST__VX_CHUNK * RAST__MAX_FAN;
    const size_t size = head + c * (2 * sizeof(int32_t) + 2 * sizeof(double)) +
                        ((nout * sizeof(rast__tri) + 63u) & ~(size_t)63u);
    char *p = aligned_alloc(64, (size + 63u) & ~(size_t)63u);
    if (!p)
        return NULL;
    rast__vbuf *vb = (rast__vbuf *)(void *)p;
    vb->cap = (int)c;
    vb->xy = (int32_t *)(void *)(p + head);
    vb->zw = (double *)(void *)(p + head + c * 2 * sizeof(int32_t));
    vb->iw = vb->zw + c;
    vb->out = (rast__tri *)(void *)(vb->iw + c);
    return vb;
}

void rast__vbuf_free(rast__vbuf *vb)
{
    free(vb);
}
