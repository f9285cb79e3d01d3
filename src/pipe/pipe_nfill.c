/* pipe_nfill.c - the normals a refined mask is lit with (pipe_nfill.h). */
#include "pipe_nfill.h"
#include "../cpu/mask_rows.h"

#include <string.h>

#define NFILL_FAR 0xFFFFu

/* scratch: horizontal sums (3 w h floats; a ring of 2 r + 2 rows of them
 * is used), the vertical accumulator (3 w floats), the window counts (w
 * ints vertically, w h bytes per row), the fill's spans (2 h ints) and
 * distances (w h uint16) */
size_t pipe__nfill_scratch_size(int w, int h)
{
    const size_t px = (size_t)w * (size_t)h;
    return sizeof(float) * 3 * px + sizeof(float) * 3 * (size_t)w + sizeof(int) * (size_t)w +
           sizeof(uint16_t) * px + px + sizeof(int) * 2 * (size_t)h;
}

static void bbox(const uint8_t *m, int w, int h, int b[4])
{
    for (int y = 0; y < h; y++) {
        const uint8_t *r = m + (size_t)y * (size_t)w;
        const int x0 = ef_row_first_set(r, 0, w);
        if (x0 == w) continue;
        const int x1 = ef_row_last_set(r, x0, w) - 1;
        if (b[0] > x0) b[0] = x0;
        if (b[2] < x1 + 1) b[2] = x1 + 1;
        if (b[1] > y) b[1] = y;
        b[3] = y + 1;
    }
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

/* The horizontal window sums of row y (hs: 3 floats, hc: counts per
 * column of the box's, b[0] .. b[2] - 1), the model's pixels within r of
 * each column: running sums in the columns' order (the bytes' definition). */
static void window_hrow(const float *restrict n, const uint8_t *restrict k, float *restrict o,
                        uint8_t *restrict c, int w, int r, const int b[4])
{
    float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
    int cnt = 0;
    for (int x = b[0] - r < 0 ? 0 : b[0] - r; x <= b[0] + r && x < w; x++)
        if (k[x]) {
            s0 = s0 + n[3 * x];
            s1 = s1 + n[3 * x + 1];
            s2 = s2 + n[3 * x + 2];
            cnt++;
        }
    /* b[0], then the columns whose window enters and leaves the row
     * (xa .. xb - 1: no bound checks), then the rest */
    int xa = r + 1 > b[0] + 1 ? r + 1 : b[0] + 1, xb = w - r < b[2] ? w - r : b[2];
    if (xb < xa) xb = xa;
    for (int x = b[0]; x < b[2]; x++) {
        if (x == xa) {
            for (; x < xb; x++) {
                const int xi = x + r, xo = x - r - 1;
                if (k[xi]) {
                    s0 = s0 + n[3 * xi];
                    s1 = s1 + n[3 * xi + 1];
                    s2 = s2 + n[3 * xi + 2];
                    cnt++;
                }
                if (k[xo]) {
                    s0 = s0 - n[3 * xo];
                    s1 = s1 - n[3 * xo + 1];
                    s2 = s2 - n[3 * xo + 2];
                    cnt--;
                }
                if (cnt == 0) s0 = s1 = s2 = 0.0f;
                o[3 * x] = s0;
                o[3 * x + 1] = s1;
                o[3 * x + 2] = s2;
                c[x] = (uint8_t)cnt;
            }
            if (x >= b[2]) break;
        }
        if (x > b[0]) {
            const int xi = x + r, xo = x - r - 1;
            if (xi < w && k[xi]) {
                s0 = s0 + n[3 * xi];
                s1 = s1 + n[3 * xi + 1];
                s2 = s2 + n[3 * xi + 2];
                cnt++;
            }
            if (xo >= 0 && k[xo]) {
                s0 = s0 - n[3 * xo];
                s1 = s1 - n[3 * xo + 1];
                s2 = s2 - n[3 * xo + 2];
                cnt--;
            }
        }
        /* an empty window is exactly 0, not a running sum's residue */
        if (cnt == 0) s0 = s1 = s2 = 0.0f;
        o[3 * x] = s0;
        o[3 * x + 1] = s1;
        o[3 * x + 2] = s2;
        c[x] = (uint8_t)cnt;
    }
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

/* counts: accc[x] + ci[x] - co[x] (either may be NULL) */
static void cnt_row(int *restrict accc, const uint8_t *restrict ci, const uint8_t *restrict co,
                    int x0, int x1)
{
    if (ci && co) {
        int x = x0;
        for (; x + 4 <= x1; x += 4) {
            accc[x] += (int)ci[x] - (int)co[x];
            accc[x + 1] += (int)ci[x + 1] - (int)co[x + 1];
            accc[x + 2] += (int)ci[x + 2] - (int)co[x + 2];
            accc[x + 3] += (int)ci[x + 3] - (int)co[x + 3];
        }
        for (; x < x1; x++) accc[x] += (int)ci[x] - (int)co[x];
    }
    else if (ci)
        for (int x = x0; x < x1; x++) accc[x] += (int)ci[x];
    else if (co)
        for (int x = x0; x < x1; x++) accc[x] -= (int)co[x];
}

void pipe__nfill_refined(const uint8_t *mask, const uint8_t *kmask, const float *nrm,
                         float *out, int w, int h, int r, void *scratch)
{
    int b[4] = {w, h, 0, 0};
    bbox(mask, w, h, b);
    if (b[2] <= b[0]) return;
    const size_t px = (size_t)w * (size_t)h;
    float *hs = (float *)scratch;
    float *acc = hs + 3 * px;
    int *accc = (int *)(acc + 3 * (size_t)w);
    int *span = accc + w; /* per row: the fill's candidates' x0, x1 */
    uint16_t *dist = (uint16_t *)(span + 2 * (size_t)h);
    uint8_t *hc = (uint8_t *)(dist + px);
    const int ya = b[1] - r < 0 ? 0 : b[1] - r;
    /* the horizontal sums live in a ring of the 2 r + 2 rows the vertical
     * window reads (the row coming in and the one going out): written just
     * before they are added, still in the caches when taken out */
    const int ring = 2 * r + 2 < h ? 2 * r + 2 : h;
#define HS(y) (hs + 3 * (size_t)((y) % ring) * (size_t)w)
#define HC(y) (hc + (size_t)((y) % ring) * (size_t)w)
#define HROW(y)                                                                                    \
    window_hrow(nrm + 3 * (size_t)(y) * (size_t)w, kmask + (size_t)(y) * (size_t)w, HS(y), HC(y), w, \
                r, b)
    const size_t i0 = 3 * (size_t)b[0], i1 = 3 * (size_t)b[2];
    /* vertical window sums of the horizontal ones, row by row */
    memset(acc, 0, sizeof(float) * 3 * (size_t)w);
    memset(accc, 0, sizeof(int) * (size_t)w);
    for (int y = ya; y <= b[1] + r && y < h; y++) {
        HROW(y);
        acc_add(acc, HS(y), i0, i1);
        cnt_row(accc, HC(y), NULL, b[0], b[2]);
    }
    for (int y = b[1]; y < b[3]; y++) {
        if (y > b[1]) {
            const int yi = y + r, yo = y - r - 1;
            if (yi < h) HROW(yi);
            if (yi < h && yo >= 0)
                acc_addsub(acc, HS(yi), HS(yo), i0, i1);
            else if (yi < h)
                acc_add(acc, HS(yi), i0, i1);
            else if (yo >= 0)
                acc_sub(acc, HS(yo), i0, i1);
            cnt_row(accc, yi < h ? HC(yi) : NULL, yo >= 0 ? HC(yo) : NULL, b[0], b[2]);
        }
        float *o = out + 3 * (size_t)y * (size_t)w;
        uint16_t *d = dist + (size_t)y * (size_t)w;
        const uint8_t *m = mask + (size_t)y * (size_t)w;
        int s0 = b[2], s1 = b[0];
        for (int x = b[0]; x < b[2]; x++) {
            if (accc[x] == 0) {
                acc[3 * x] = acc[3 * x + 1] = acc[3 * x + 2] = 0.0f;
                o[3 * x] = o[3 * x + 1] = o[3 * x + 2] = 0.0f;
                d[x] = NFILL_FAR;
                if (m[x]) {
                    if (s0 > x) s0 = x;
                    s1 = x + 1;
                }
            } else {
                o[3 * x] = acc[3 * x];
                o[3 * x + 1] = acc[3 * x + 1];
                o[3 * x + 2] = acc[3 * x + 2];
                d[x] = 0;
            }
        }
        span[2 * y] = s0;
        span[2 * y + 1] = s1;
    }
#undef HROW
#undef HC
#undef HS
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
