/* Small holes and islands of a mask by run-length labelling (fit_holes.h).
 * Each row is cut into alternating runs of set and clear pixels; runs of
 * the same value that overlap in adjacent rows are joined (union-find),
 * and each component sums its area and whether it touches a border. */
#include "fit_holes.h"

#include <string.h>

typedef struct {
    int32_t parent; /* union-find; the root's area below */
    int32_t area;
    int32_t out;      /* the root's: its pixels outside `inside` */
    uint16_t x0, x1; /* [x0, x1) */
    uint8_t val, border;
} run;

size_t pipe_fit_fill_scratch_size(int width, int height)
{
    if (width < 1 || height < 1 || width > 65535 || height > (1 << 20)) return 0;
    return (size_t)height * (size_t)(width + 1) * sizeof(run) + (size_t)(height + 1) * sizeof(int32_t) + 15;
}

static int32_t find(run *r, int32_t i)
{
    while (r[i].parent != i) {
        r[i].parent = r[r[i].parent].parent;
        i = r[i].parent;
    }
    return i;
}

static void join(run *r, int32_t a, int32_t b)
{
    a = find(r, a);
    b = find(r, b);
    if (a == b) return;
    if (a > b) { int32_t t = a; a = b; b = t; }
    r[b].parent = a;
    r[a].area += r[b].area;
    r[a].border |= r[b].border;
}

#define B80 0x8080808080808080ull

long pipe_fit_fill_small(uint8_t *mask, int stride, int width, int height, int max_hole,
                         int max_island, const uint8_t *inside, int inside_stride, void *scratch,
                         size_t scratch_size)
{
    if (!mask || !scratch || width < 1 || height < 1 || width > 65535 || stride < width ||
        max_hole < 0 || max_island < 0 || (inside && inside_stride < width))
        return -1;
    if (!max_hole && !max_island) return 0;
    const int W = width, H = height;
    const size_t used = ((size_t)(H + 1) * sizeof(int32_t) + 15) & ~(size_t)15;
    if (scratch_size < used + sizeof(run)) return -1;
    int32_t *row0 = scratch; /* first run of each row; row0[H] = the count */
    run *r = (run *)((uint8_t *)scratch + used);
    const size_t cap = (scratch_size - used) / sizeof(run);
    size_t n = 0;
    for (int y = 0; y < H; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)stride;
        row0[y] = (int32_t)n;
        int x = 0;
        while (x < W) {
            const uint8_t v = m[x] >= 128;
            int e = x + 1;
            const uint64_t want = v ? B80 : 0;
            while (e + 8 <= W) {
                uint64_t w8;
                memcpy(&w8, m + e, 8);
                if ((w8 & B80) != want) break;
                e += 8;
            }
            while (e < W && (m[e] >= 128) == v) e++;
            if (n >= cap) return -1;
            run *q = &r[n];
            q->parent = (int32_t)n;
            q->area = e - x;
            q->out = 0;
            q->x0 = (uint16_t)x;
            q->x1 = (uint16_t)e;
            q->val = v;
            q->border = (uint8_t)(y == 0 || y == H - 1 || x == 0 || e == W);
            n++;
            x = e;
        }
        if (y > 0) {
            /* join overlapping runs of the same value with the row above */
            int32_t a = row0[y - 1], ae = row0[y], b = row0[y], be = (int32_t)n;
            while (a < ae && b < be) {
                if (r[a].val == r[b].val && r[a].x0 < r[b].x1 && r[b].x0 < r[a].x1) join(r, a, b);
                if (r[a].x1 < r[b].x1) a++;
                else b++;
            }
        }
    }
    row0[H] = (int32_t)n;
    if (inside && max_hole)
        /* the candidate holes' pixels outside `inside` (only small
         * components are visited pixel by pixel) */
        for (int y = 0; y < H; y++) {
            const uint8_t *in = inside + (size_t)y * (size_t)inside_stride;
            for (int32_t i = row0[y]; i < row0[y + 1]; i++) {
                if (r[i].val) continue;
                run *root = &r[find(r, i)];
                if (root->border || root->area > max_hole) continue;
                for (int x = r[i].x0; x < r[i].x1; x++) root->out += in[x] < 128;
            }
        }
    long changed = 0;
    for (int y = 0; y < H; y++) {
        uint8_t *m = mask + (size_t)y * (size_t)stride;
        for (int32_t i = row0[y]; i < row0[y + 1]; i++) {
            const run *root = &r[find(r, i)];
            if (root->border) continue;
            const int lim = r[i].val ? max_island : max_hole;
            if (root->area > lim || (!r[i].val && root->out)) continue;
            memset(m + r[i].x0, r[i].val ? 0 : 255, (size_t)(r[i].x1 - r[i].x0));
            changed += r[i].x1 - r[i].x0;
        }
    }
    return changed;
}
