/* fuse_metrics.c - mask and image accuracy metrics (fuse_metrics.h). */
#include "fuse_metrics.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

static int plane_ok(const uint8_t *p, int stride, int w, int h)
{
    return p && w > 0 && h > 0 && stride >= w;
}

static int inside(const uint8_t *m, int stride, int x, int y)
{
    return m[(size_t)y * (size_t)stride + (size_t)x] >= 128;
}

/* Inside, with a 4-neighbour in the image that is outside. */
static int is_boundary(const uint8_t *m, int stride, int w, int h, int x, int y)
{
    if (!inside(m, stride, x, y)) return 0;
    if (x > 0 && !inside(m, stride, x - 1, y)) return 1;
    if (x + 1 < w && !inside(m, stride, x + 1, y)) return 1;
    if (y > 0 && !inside(m, stride, x, y - 1)) return 1;
    if (y + 1 < h && !inside(m, stride, x, y + 1)) return 1;
    return 0;
}

int fuse_mask_confusion(const uint8_t *pred, int pred_stride,
                        const uint8_t *truth, int truth_stride, int width,
                        int height, fuse_confusion *out)
{
    fuse_confusion c = { 0, 0, 0, 0 };
    if (!out) return -1;
    *out = c;
    if (!plane_ok(pred, pred_stride, width, height) ||
        !plane_ok(truth, truth_stride, width, height))
        return -1;
    for (int y = 0; y < height; y++) {
        const uint8_t *p = pred + (size_t)y * (size_t)pred_stride;
        const uint8_t *t = truth + (size_t)y * (size_t)truth_stride;
        for (int x = 0; x < width; x++) {
            int a = p[x] >= 128, b = t[x] >= 128;
            if (a && b) c.tp++;
            else if (a) c.fp++;
            else if (b) c.fn++;
            else c.tn++;
        }
    }
    *out = c;
    return 0;
}

double fuse_confusion_iou(const fuse_confusion *c)
{
    if (!c) return NAN;
    long u = c->tp + c->fp + c->fn;
    return u == 0 ? 1.0 : (double)c->tp / (double)u;
}

long fuse_boundary_count(const uint8_t *mask, int stride, int width,
                         int height)
{
    if (!plane_ok(mask, stride, width, height)) return -1;
    long n = 0;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++)
            n += is_boundary(mask, stride, width, height, x, y);
    return n;
}

/* Boundary pixels of a that have a boundary pixel of b within d. */
static void match(const uint8_t *a, int as, const uint8_t *b, int bs, int w,
                  int h, float d, long *count, long *matched)
{
    int r = (int)floorf(d);
    double d2 = (double)d * (double)d;
    long n = 0, m = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (!is_boundary(a, as, w, h, x, y)) continue;
            n++;
            int hit = 0;
            for (int dy = -r; dy <= r && !hit; dy++) {
                int yy = y + dy;
                if (yy < 0 || yy >= h) continue;
                for (int dx = -r; dx <= r; dx++) {
                    int xx = x + dx;
                    if (xx < 0 || xx >= w) continue;
                    if ((double)(dx * dx + dy * dy) > d2) continue;
                    if (is_boundary(b, bs, w, h, xx, yy)) {
                        hit = 1;
                        break;
                    }
                }
            }
            m += hit;
        }
    *count = n;
    *matched = m;
}

double fuse_boundary_f(const uint8_t *pred, int pred_stride,
                       const uint8_t *truth, int truth_stride, int width,
                       int height, float d, double *precision,
                       double *recall)
{
    if (precision) *precision = NAN;
    if (recall) *recall = NAN;
    if (!plane_ok(pred, pred_stride, width, height) ||
        !plane_ok(truth, truth_stride, width, height) || !(d >= 0.0f) ||
        d > 1000.0f)
        return NAN;
    long np, mp, nt, mt;
    match(pred, pred_stride, truth, truth_stride, width, height, d, &np, &mp);
    match(truth, truth_stride, pred, pred_stride, width, height, d, &nt, &mt);
    double p, r;
    if (np == 0 && nt == 0) {
        p = r = 1.0;
    } else {
        p = np ? (double)mp / (double)np : 0.0;
        r = nt ? (double)mt / (double)nt : 0.0;
    }
    if (precision) *precision = p;
    if (recall) *recall = r;
    return p + r > 0.0 ? 2.0 * p * r / (p + r) : 0.0;
}

double fuse_mse(const uint8_t *a, int a_stride, const uint8_t *b,
                int b_stride, int width, int height, int bpp, int channels)
{
    if (bpp < 1 || bpp > 16 || channels < 1 || channels > bpp || !a || !b ||
        width < 1 || height < 1 || a_stride < width * bpp ||
        b_stride < width * bpp)
        return NAN;
    double sum = 0.0;
    for (int y = 0; y < height; y++) {
        const uint8_t *pa = a + (size_t)y * (size_t)a_stride;
        const uint8_t *pb = b + (size_t)y * (size_t)b_stride;
        long row = 0;
        for (int x = 0; x < width; x++)
            for (int k = 0; k < channels; k++) {
                int e = (int)pa[x * bpp + k] - (int)pb[x * bpp + k];
                row += (long)e * e;
            }
        sum += (double)row;
    }
    return sum / ((double)width * (double)height * (double)channels);
}

double fuse_psnr_of_mse(double mse)
{
    if (!(mse >= 0.0)) return NAN;
    if (mse == 0.0) return INFINITY;
    return 10.0 * log10(255.0 * 255.0 / mse);
}

double fuse_psnr(const uint8_t *a, int a_stride, const uint8_t *b,
                 int b_stride, int width, int height, int bpp, int channels)
{
    return fuse_psnr_of_mse(
        fuse_mse(a, a_stride, b, b_stride, width, height, bpp, channels));
}

double fuse_edge_flicker(const uint8_t *pred0, const uint8_t *pred1,
                         const uint8_t *truth0, const uint8_t *truth1,
                         int stride, int width, int height)
{
    if (!plane_ok(pred0, stride, width, height) ||
        !plane_ok(pred1, stride, width, height) ||
        !plane_ok(truth0, stride, width, height) ||
        !plane_ok(truth1, stride, width, height))
        return NAN;
    long dp = 0, dt = 0;
    for (int y = 0; y < height; y++) {
        size_t o = (size_t)y * (size_t)stride;
        for (int x = 0; x < width; x++) {
            dp += (pred0[o + x] >= 128) != (pred1[o + x] >= 128);
            dt += (truth0[o + x] >= 128) != (truth1[o + x] >= 128);
        }
    }
    long edge = fuse_boundary_count(truth1, stride, width, height);
    return (double)labs(dp - dt) / (double)(edge > 0 ? edge : 1);
}
