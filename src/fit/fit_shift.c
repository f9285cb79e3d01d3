/* fit_shift.c - the hands of the refinement's input moved in the image to
 * where the colour says they are (fit_shift.h). */
#include "fit_shift.h"

#include <math.h>
#include <string.h>

pipe_fit_shift_desc pipe_fit_shift_desc_default(void)
{
    return (pipe_fit_shift_desc){.range = 24, .max_points = 1500, .min_gain = 0.1f, .cost = 0.004f,
                                 .hand_radius = 0.04f};
}

static size_t point_cap(int stride, int height)
{
    return (size_t)(stride / 2 + 1) * (size_t)(height / 2 + 1);
}

/* the ratio table of the box around the points: (stride + 2 * 64) x
 * (height + 2 * 64) bytes at most */
static size_t box_cap(int stride, int height)
{
    return (size_t)(stride + 128) * (size_t)(height + 128);
}

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

size_t pipe_fit_shift_scratch_size(int stride, int height)
{
    if (stride < 1 || height < 1) return 0;
    return align16((size_t)stride * (size_t)height) + align16(4u * point_cap(stride, height)) +
           box_cap(stride, height);
}

/* The clamped log-likelihood ratio of every other pixel of every other
 * row of the box x0..x0+2bw-1, y0..y0+2bh-1 (the points and the shifts
 * are all even: x0 + 2i, y0 + 2j; the box may reach beyond the image: 0
 * there, unknown) as int8, LLR_Q per nat, bw x bh. */
enum { LLR_Q = 40 };

static void llr_box(const fuse_colour_model *g, const fuse_image *P, int x0, int y0, int bw,
                    int bh, int8_t *box)
{
    const int bits = g->bits, sh = 8 - bits;
    for (int y = 0; y < bh; y++) {
        int8_t *b = box + (size_t)y * (size_t)bw;
        const int iy = y0 + 2 * y;
        if (iy < 0 || iy >= P->height) {
            memset(b, 0, (size_t)bw);
            continue;
        }
        const uint8_t *row = P->pixels + (size_t)iy * (size_t)P->stride;
        for (int x = 0; x < bw; x++) {
            const int ix = x0 + 2 * x;
            if (ix < 0 || ix >= P->width) {
                b[x] = 0;
                continue;
            }
            const uint8_t *px = row + 4 * ix;
            const unsigned bin = ((unsigned)(px[0] >> sh) << (2 * bits)) |
                                 ((unsigned)(px[1] >> sh) << bits) | (unsigned)(px[2] >> sh);
            float v = g->llr[bin] * (float)LLR_Q;
            v = v > 3.0f * LLR_Q ? 3.0f * LLR_Q : v < -3.0f * LLR_Q ? -3.0f * LLR_Q : v;
            b[x] = (int8_t)(int)(v + (v >= 0.0f ? 0.5f : -0.5f));   /* to nearest */
        }
    }
}

/* the first and last set column of a region row (one span); 0 if none */
static int row_span(const uint8_t *r, int W, int *a, int *b)
{
    const uint8_t *p = memchr(r, 255, (size_t)W);
    if (!p) return 0;
    int x = (int)(p - r);
    *a = x;
    while (x + 1 < W && r[x + 1]) x++;
    *b = x;
    return 1;
}

/* pt: offsets into the box of the points at shift 0 */
static double score_at(const int8_t *box, int bw, const uint32_t *pt, long n, int dx, int dy,
                       float cost)
{
    const long off = (long)(dy / 2) * bw + dx / 2;   /* dx, dy even */
    long s = 0;
    for (long i = 0; i < n; i++) s += box[(long)pt[i] + off];
    return (double)s / LLR_Q - (double)cost * sqrt((double)(dx * dx + dy * dy)) * (double)n;
}

const uint8_t *pipe_fit_shift(const pipe_fit_shift_desc *dp, const fuse_colour_model *g,
                              const fuse_image *P, const kin_camera *cam,
                              const kin_mat4 *world, const kin_arm_rig *rig, unsigned sides,
                              const uint8_t *in, uint8_t *out, int stride, void *scratch,
                              size_t scratch_size, int shift[2][2])
{
    if (shift) memset(shift, 0, sizeof(int[2][2]));
    const pipe_fit_shift_desc d = dp ? *dp : pipe_fit_shift_desc_default();
    if (!g || !g->llr || g->fg_samples <= 0 || g->bg_samples <= 0 || g->bits < 2 ||
        g->bits > 6 || !P || !P->pixels || !cam || !world || !rig || !in || !out ||
        !scratch || cam->width != P->width || cam->height != P->height ||
        stride < P->width || P->stride < 4 * P->width || d.range < 2 || d.range > 64 || (d.range & 1) ||
        d.max_points < 16 || !(d.min_gain >= 0.0f) || !(d.cost >= 0.0f) ||
        !(d.hand_radius > 0.0f) ||
        scratch_size < pipe_fit_shift_scratch_size(stride, P->height))
        return in;
    const int W = P->width, H = P->height;
    uint8_t *region = scratch;
    uint32_t *pt = (uint32_t *)(void *)((uint8_t *)scratch + align16((size_t)stride * (size_t)H));
    int8_t *box = (int8_t *)((uint8_t *)scratch + align16((size_t)stride * (size_t)H) +
                             align16(4u * point_cap(stride, H)));
    const long cap = (long)point_cap(stride, H);
    pipe_fit_band_desc bd = pipe_fit_band_desc_default();
    bd.hand_radius = d.hand_radius;
    int moved = 0;
    for (int s = 0; s < 2; s++) {
        if (!(sides & (1u << s))) continue;
        if (pipe_fit_band_region(&bd, cam, world, rig, 1u << s, d.range, region, stride) <= 0)
            continue;
        /* the region is one span per row (pipe_fit_band_region) */
        long n1 = 0;
        int y0 = H, y1 = -1;
        for (int y = 0; y < H; y++) {
            const uint8_t *r = region + (size_t)y * (size_t)stride,
                          *m = in + (size_t)y * (size_t)stride;
            int a, b;
            if (!row_span(r, W, &a, &b)) continue;
            if (y < y0) y0 = y;
            y1 = y;
            if (y & 1) continue;   /* counted on every other row and column */
            for (int x = a + (a & 1); x <= b; x += 2) n1 += 4 * (m[x] >= 128);
        }
        if (n1 < 16) continue;
        int q = (int)ceil(sqrt((double)n1 / (double)d.max_points));
        q += q & 1;   /* even: the points on even columns and rows */
        if (q < 2) q = 2;
        long n = 0;
        for (int y = y0; y <= y1 && n < cap && n < d.max_points; y += q) {
            const uint8_t *r = region + (size_t)y * (size_t)stride,
                          *m = in + (size_t)y * (size_t)stride;
            int a, b;
            if (!row_span(r, W, &a, &b)) continue;
            for (int x = a - a % q; x <= b && n < cap && n < d.max_points; x += q)
                if (x >= a && m[x] >= 128) pt[n++] = (uint32_t)x | ((uint32_t)y << 16);
        }
        if (n < 4) continue;
        /* the ratios of the box the points reach at every shift */
        int px0 = W, px1 = -1, py0 = H, py1 = -1;
        for (long i = 0; i < n; i++) {
            const int x = (int)(pt[i] & 0xffffu), y = (int)(pt[i] >> 16);
            if (x < px0) px0 = x;
            if (x > px1) px1 = x;
            if (y < py0) py0 = y;
            if (y > py1) py1 = y;
        }
        const int bx0 = px0 - d.range, by0 = py0 - d.range;
        const int bw = (px1 - px0 + 2 * d.range) / 2 + 1, bh = (py1 - py0 + 2 * d.range) / 2 + 1;
        llr_box(g, P, bx0, by0, bw, bh, box);
        for (long i = 0; i < n; i++)
            pt[i] = (uint32_t)(((int)(pt[i] >> 16) - by0) / 2 * bw +
                               ((int)(pt[i] & 0xffffu) - bx0) / 2);
        const double s0 = score_at(box, bw, pt, n, 0, 0, d.cost);
        int bx = 0, by = 0;
        double best = s0;
        for (int dy = -d.range; dy <= d.range; dy += 8)
            for (int dx = -d.range; dx <= d.range; dx += 8) {
                const double v = score_at(box, bw, pt, n, dx, dy, d.cost);
                if (v > best) { best = v; bx = dx; by = dy; }
            }
        for (int st = 4; st >= 2; st /= 2) {
            const int cx = bx, cy = by;
            for (int dy = cy - st; dy <= cy + st; dy += st)
                for (int dx = cx - st; dx <= cx + st; dx += st) {
                    if (dx < -d.range || dx > d.range || dy < -d.range || dy > d.range ||
                        (dx == cx && dy == cy))
                        continue;
                    const double v = score_at(box, bw, pt, n, dx, dy, d.cost);
                    if (v > best) { best = v; bx = dx; by = dy; }
                }
        }
        if ((bx == 0 && by == 0) || !(best - s0 > (double)d.min_gain * (double)n)) continue;
        if (!moved) {
            for (int y = 0; y < H; y++)
                memcpy(out + (size_t)y * (size_t)stride, in + (size_t)y * (size_t)stride,
                       (size_t)W);
            moved = 1;
        }
        for (int y = y0; y <= y1; y++) {
            const uint8_t *r = region + (size_t)y * (size_t)stride;
            uint8_t *o = out + (size_t)y * (size_t)stride;
            const int sy = y - by;
            int a, b;
            if (!row_span(r, W, &a, &b)) continue;
            for (int x = a; x <= b; x++) {
                const int sx = x - bx;
                o[x] = sx < 0 || sy < 0 || sx >= W || sy >= H
                           ? 0
                           : in[(size_t)sy * (size_t)stride + (size_t)sx];
            }
        }
        if (shift) { shift[s][0] = bx; shift[s][1] = by; }
    }
    return moved ? out : in;
}
