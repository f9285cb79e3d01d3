/* pipe_nfill.c - the normals a refined mask is lit with (pipe_nfill.h). */
#include "pipe_nfill.h"

#include <string.h>

#define NFILL_FAR 0xFFFFu

/* scratch: horizontal sums (3 w h floats), the vertical accumulator (3 w
 * floats), the window counts (w h bytes per row, w ints vertically), the
 * fill's distances (w h uint16) */
size_t pipe__nfill_scratch_size(int w, int h)
{
    const size_t px = (size_t)w * (size_t)h;
    return sizeof(float) * 3 * px + sizeof(float) * 3 * (size_t)w + sizeof(int) * (size_t)w +
           sizeof(uint16_t) * px + px;
}

static void bbox(const uint8_t *m, int w, int h, int b[4])
{
    for (int y = 0; y < h; y++) {
        const uint8_t *r = m + (size_t)y * (size_t)w;
        int x0 = 0, x1 = w - 1;
        while (x0 < w && r[x0] == 0) x0++;
        if (x0 == w) continue;
        while (r[x1] == 0) x1--;
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

/* Row y of the horizontal window sums (hs: 3 floats, hc: counts) added to
 * (sign 1) or taken from (sign -1) the vertical sums acc / accc over the
 * box's columns. */
static void window_row(float *acc, int *accc, const float *hs, const uint8_t *hc, int w, int y,
                       const int b[4], int sign)
{
    const float *s = hs + 3 * (size_t)y * (size_t)w;
    const uint8_t *c = hc + (size_t)y * (size_t)w;
    for (int x = b[0]; x < b[2]; x++) {
        if (sign > 0) {
            acc[3 * x] = acc[3 * x] + s[3 * x];
            acc[3 * x + 1] = acc[3 * x + 1] + s[3 * x + 1];
            acc[3 * x + 2] = acc[3 * x + 2] + s[3 * x + 2];
        } else {
            acc[3 * x] = acc[3 * x] - s[3 * x];
            acc[3 * x + 1] = acc[3 * x + 1] - s[3 * x + 1];
            acc[3 * x + 2] = acc[3 * x + 2] - s[3 * x + 2];
        }
        accc[x] += sign * (int)c[x];
    }
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
    uint16_t *dist = (uint16_t *)(accc + w);
    uint8_t *hc = (uint8_t *)(dist + px);
    const int ya = b[1] - r < 0 ? 0 : b[1] - r, yb = b[3] + r > h ? h : b[3] + r;
    /* horizontal window sums of the rows the box's windows reach */
    for (int y = ya; y < yb; y++) {
        const float *n = nrm + 3 * (size_t)y * (size_t)w;
        const uint8_t *k = kmask + (size_t)y * (size_t)w;
        float *o = hs + 3 * (size_t)y * (size_t)w;
        uint8_t *c = hc + (size_t)y * (size_t)w;
        float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
        int cnt = 0;
        for (int x = b[0] - r < 0 ? 0 : b[0] - r; x <= b[0] + r && x < w; x++)
            if (k[x]) {
                s0 = s0 + n[3 * x];
                s1 = s1 + n[3 * x + 1];
                s2 = s2 + n[3 * x + 2];
                cnt++;
            }
        for (int x = b[0]; x < b[2]; x++) {
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
    /* vertical window sums of those, row by row */
    memset(acc, 0, sizeof(float) * 3 * (size_t)w);
    memset(accc, 0, sizeof(int) * (size_t)w);
    for (int y = ya; y <= b[1] + r && y < h; y++) {
        window_row(acc, accc, hs, hc, w, y, b, 1);
    }
    for (int y = b[1]; y < b[3]; y++) {
        if (y > b[1]) {
            const int yi = y + r, yo = y - r - 1;
            if (yi < h) window_row(acc, accc, hs, hc, w, yi, b, 1);
            if (yo >= 0) window_row(acc, accc, hs, hc, w, yo, b, -1);
        }
        float *o = out + 3 * (size_t)y * (size_t)w;
        uint16_t *d = dist + (size_t)y * (size_t)w;
        for (int x = b[0]; x < b[2]; x++) {
            if (accc[x] == 0) {
                acc[3 * x] = acc[3 * x + 1] = acc[3 * x + 2] = 0.0f;
                o[3 * x] = o[3 * x + 1] = o[3 * x + 2] = 0.0f;
                d[x] = NFILL_FAR;
            } else {
                o[3 * x] = acc[3 * x];
                o[3 * x + 1] = acc[3 * x + 1];
                o[3 * x + 2] = acc[3 * x + 2];
                d[x] = 0;
            }
        }
    }
    /* the mask's pixels with no model pixel in their window: the normal
     * of the nearest that has one (3-4 chamfer, through the mask) */
    /* forward and backward until nothing changes (two passes for a
     * convex hand; a path that turns back needs more) */
    for (int changed = 1; changed;) {
        changed = 0;
        for (int y = b[1]; y < b[3]; y++)
            for (int x = b[0]; x < b[2]; x++) {
                const size_t i = (size_t)y * (size_t)w + (size_t)x;
                if (dist[i] == 0 || mask[i] == 0) continue;
                changed |= relax(dist, out, w, b, x, y, -1, 0, 3);
                changed |= relax(dist, out, w, b, x, y, -1, -1, 4);
                changed |= relax(dist, out, w, b, x, y, 0, -1, 3);
                changed |= relax(dist, out, w, b, x, y, 1, -1, 4);
            }
        for (int y = b[3] - 1; y >= b[1]; y--)
            for (int x = b[2] - 1; x >= b[0]; x--) {
                const size_t i = (size_t)y * (size_t)w + (size_t)x;
                if (dist[i] == 0 || mask[i] == 0) continue;
                changed |= relax(dist, out, w, b, x, y, 1, 0, 3);
                changed |= relax(dist, out, w, b, x, y, 1, 1, 4);
                changed |= relax(dist, out, w, b, x, y, 0, 1, 3);
                changed |= relax(dist, out, w, b, x, y, -1, 1, 4);
            }
    }
}
