/* pipe_nfill.c - the normals a refined mask is lit with (pipe_nfill.h). */
#include "pipe_nfill.h"
#include "../cpu/mask_rows.h"

#include <string.h>

#define NFILL_FAR 0xFFFFu

/* scratch: the vertical window sums of the current row (3 w floats),
 * their model pixel counts (w bytes), the fill's spans (2 h ints) and
 * distances (w h uint16) */
size_t pipe__nfill_scratch_size(int w, int h)
{
    const size_t px = (size_t)w * (size_t)h;
    return sizeof(float) * 3 * (size_t)w + sizeof(int) * 2 * (size_t)h + sizeof(uint16_t) * px +
           (size_t)w + 16;
}

#define NFILL_B01 0x0101010101010101ull

/* the end of the run of set bytes of r that starts at x (x1 at most) */
static int run_end(const uint8_t *r, int x, int x1)
{
    while (x + 8 <= x1 && !ef_has_zero8(ef_ld8(r + x))) x += 8;
    while (x < x1 && r[x]) x++;
    return x;
}

/* the neighbour (x + dx, y + dy) of a fill candidate: a shorter path */
static int relax(uint16_t *dist, float *out, int w, const int b[4], int x,
                  int y, int dx, int dy, unsigned cost)
{
    const int nx = x + dx, ny = y + dy;
    if (nx < b[0] || nx >= b[2] || ny < b[1] || ny >= b[3]) return 0;
    const size_t i = (size_t)y * (size_t)w + (size_t)x, j = (size_t)ny * (size_t)w + (size_t)nx;
    if (dist[j] == NFILL_FAR) return 0;
    const unsigned d = dist[j] + cost;
    if (d >= dist[i] || d >= NFILL_FAR) return 0;
    dist[i] = (uint16_t)d;
    memcpy(out + 3 * i, out + 3 * j, 3 * sizeof(float));
    return 1;
}

/* 4 floats in one register (GCC/Clang vector extension): the same IEEE
 * single additions per element as the scalar loop, no reassociation */
typedef float nfill_v4 __attribute__((vector_size(16)));

static nfill_v4 ldv(const float *p)
{
    nfill_v4 v;
    memcpy(&v, p, sizeof v);
    return v;
}

static void stv(float *p, nfill_v4 v) { memcpy(p, &v, sizeof v); }

/* acc[i] + s[i] over i0 .. i1 - 1 (flat: the 3 components of a column are
 * 3 independent sums, each in its own order) */
static void acc_add(float *restrict acc, const float *restrict s, size_t i0, size_t i1)
{
    size_t i = i0;
    for (; i + 4 <= i1; i += 4) stv(acc + i, ldv(acc + i) + ldv(s + i));
    for (; i < i1; i++) acc[i] = acc[i] + s[i];
}

static void acc_sub(float *restrict acc, const float *restrict s, size_t i0, size_t i1)
{
    size_t i = i0;
    for (; i + 4 <= i1; i += 4) stv(acc + i, ldv(acc + i) - ldv(s + i));
    for (; i < i1; i++) acc[i] = acc[i] - s[i];
}

/* (acc[i] + si[i]) - so[i]: the row coming in and the one going out in
 * one pass, in that order */
static void acc_addsub(float *restrict acc, const float *restrict si, const float *restrict so,
                       size_t i0, size_t i1)
{
    size_t i = i0;
    for (; i + 4 <= i1; i += 4) stv(acc + i, (ldv(acc + i) + ldv(si + i)) - ldv(so + i));
    for (; i < i1; i++) acc[i] = (acc[i] + si[i]) - so[i];
}

/* 1 in each byte of v that is not 0, else 0 */
static uint64_t nz8(uint64_t v)
{
    const uint64_t l7 = 0x7F7F7F7F7F7F7F7Full;
    return ((((v & l7) + l7) | v) >> 7) & NFILL_B01;
}

/* counts: c[x] + (ci[x] != 0) - (co[x] != 0) (either may be NULL), 8
 * bytes a step (a count stays in 0 .. 2 r + 1: no carry between bytes) */
static void cnt_row(uint8_t *restrict c, const uint8_t *restrict ci, const uint8_t *restrict co,
                    int x0, int x1)
{
    int x = x0;
    for (; x + 8 <= x1; x += 8) {
        uint64_t v = ef_ld8(c + x);
        if (ci) v += nz8(ef_ld8(ci + x));
        if (co) v -= nz8(ef_ld8(co + x));
        memcpy(c + x, &v, 8);
    }
    for (; x < x1; x++) c[x] = (uint8_t)(c[x] + (ci && ci[x] != 0) - (co && co[x] != 0));
}

void pipe__nfill_refined(const uint8_t *mask, const uint8_t *kmask, const float *nrm,
                         float *out, int w, int h, int r, void *scratch)
{
    int b[4];
    ef_mask_box(mask, w, h, b);
    if (b[2] <= b[0]) return;
    float *acc = (float *)scratch;
    int *span = (int *)(acc + 3 * (size_t)w); /* per row: the fill's candidates' x0, x1 */
    uint16_t *dist = (uint16_t *)(span + 2 * (size_t)h);
    uint8_t *vc = (uint8_t *)(dist + (size_t)w * (size_t)h);
    /* the columns the windows of the box's pixels read */
    const int c0 = b[0] - r < 0 ? 0 : b[0] - r, c1 = b[2] + r > w ? w : b[2] + r;
    const size_t i0 = 3 * (size_t)c0, i1 = 3 * (size_t)c1;
    const int ya = b[1] - r < 0 ? 0 : b[1] - r;
#define NROW(y) (nrm + 3 * (size_t)(y) * (size_t)w)
#define KROW(y) (kmask + (size_t)(y) * (size_t)w)
    /* vertical window sums of the normals (0 outside the model), row by
     * row: the row coming in added, the one going out taken */
    memset(acc + i0, 0, sizeof(float) * (i1 - i0));
    memset(vc + c0, 0, (size_t)(c1 - c0));
    for (int y = ya; y <= b[1] + r && y < h; y++) {
        acc_add(acc, NROW(y), i0, i1);
        cnt_row(vc, KROW(y), NULL, c0, c1);
    }
    /* only the refined mask's pixels are sources of the fill */
    memset(dist + (size_t)b[1] * (size_t)w, 0xFF, sizeof(uint16_t) * (size_t)w * (size_t)(b[3] - b[1]));
    for (int y = b[1]; y < b[3]; y++) {
        if (y > b[1]) {
            const int yi = y + r, yo = y - r - 1;
            if (yi < h && yo >= 0)
                acc_addsub(acc, NROW(yi), NROW(yo), i0, i1);
            else if (yi < h)
                acc_add(acc, NROW(yi), i0, i1);
            else if (yo >= 0)
                acc_sub(acc, NROW(yo), i0, i1);
            cnt_row(vc, yi < h ? KROW(yi) : NULL, yo >= 0 ? KROW(yo) : NULL, c0, c1);
        }
        float *o = out + 3 * (size_t)y * (size_t)w;
        uint16_t *d = dist + (size_t)y * (size_t)w;
        const uint8_t *m = mask + (size_t)y * (size_t)w;
        int s0 = b[2], s1 = b[0];
        /* the horizontal window sums over the refined mask's runs only */
        for (int a = ef_row_first_set(m, b[0], b[2]); a < b[2];
             a = ef_row_first_set(m, a, b[2])) {
            const int e = run_end(m, a, b[2]);
            float t0 = 0.0f, t1 = 0.0f, t2 = 0.0f;
            int cnt = 0;
            for (int x = a - r < 0 ? 0 : a - r; x <= a + r && x < w; x++) {
                t0 = t0 + acc[3 * x];
                t1 = t1 + acc[3 * x + 1];
                t2 = t2 + acc[3 * x + 2];
                cnt += vc[x];
            }
            for (int x = a; x < e; x++) {
                if (x > a) {
                    const int xi = x + r, xo = x - r - 1;
                    if (xi < w && xo >= 0) {
                        t0 = (t0 + acc[3 * xi]) - acc[3 * xo];
                        t1 = (t1 + acc[3 * xi + 1]) - acc[3 * xo + 1];
                        t2 = (t2 + acc[3 * xi + 2]) - acc[3 * xo + 2];
                        cnt += vc[xi] - vc[xo];
                    } else if (xi < w) {
                        t0 = t0 + acc[3 * xi];
                        t1 = t1 + acc[3 * xi + 1];
                        t2 = t2 + acc[3 * xi + 2];
                        cnt += vc[xi];
                    } else if (xo >= 0) {
                        t0 = t0 - acc[3 * xo];
                        t1 = t1 - acc[3 * xo + 1];
                        t2 = t2 - acc[3 * xo + 2];
                        cnt -= vc[xo];
                    }
                }
                if (cnt == 0) {
                    /* an empty window is exactly 0, not a running sum's
                     * residue */
                    t0 = t1 = t2 = 0.0f;
                    o[3 * x] = o[3 * x + 1] = o[3 * x + 2] = 0.0f;
                    if (s0 > x) s0 = x;
                    s1 = x + 1;
                } else {
                    o[3 * x] = t0;
                    o[3 * x + 1] = t1;
                    o[3 * x + 2] = t2;
                    d[x] = 0;
                }
            }
            a = e;
        }
        span[2 * y] = s0;
        span[2 * y + 1] = s1;
    }
#undef KROW
#undef NROW
    /* the mask's pixels with no model pixel in their window: the normal
     * of the nearest that has one (3-4 chamfer, through the mask) */
    /* forward and backward until nothing changes (two passes for a
     * convex hand; a path that turns back needs more). Only those pixels
     * change (dist FAR and mask set above, never 0 after), so each row is
     * swept over their span only: the same visits in the same order. */
    for (int changed = 1; changed;) {
        changed = 0;
        for (int y = b[1]; y < b[3]; y++)
            for (int x = span[2 * y]; x < span[2 * y + 1]; x++) {
                const size_t i = (size_t)y * (size_t)w + (size_t)x;
                if (dist[i] == 0 || mask[i] == 0) continue;
                changed |= relax(dist, out, w, b, x, y, -1, 0, 3);
                changed |= relax(dist, out, w, b, x, y, -1, -1, 4);
                changed |= relax(dist, out, w, b, x, y, 0, -1, 3);
                changed |= relax(dist, out, w, b, x, y, 1, -1, 4);
            }
        for (int y = b[3] - 1; y >= b[1]; y--)
            for (int x = span[2 * y + 1] - 1; x >= span[2 * y]; x--) {
                const size_t i = (size_t)y * (size_t)w + (size_t)x;
                if (dist[i] == 0 || mask[i] == 0) continue;
                changed |= relax(dist, out, w, b, x, y, 1, 0, 3);
                changed |= relax(dist, out, w, b, x, y, 1, 1, 4);
                changed |= relax(dist, out, w, b, x, y, 0, 1, 3);
                changed |= relax(dist, out, w, b, x, y, -1, 1, 4);
            }
    }
}
