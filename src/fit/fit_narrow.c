/* fit_narrow.c - the band refinement, narrower where the hand is thin
 * (fit_narrow.h). */
#include "fit_narrow.h"

#include <math.h>
#include <string.h>

static fuse_result run(const fuse_refine_params *p, const fuse_colour_model *g, float weight,
                       const fuse_image *P, const uint8_t *mask, int mask_stride, uint8_t *out,
                       int out_stride, void *scratch, size_t scratch_size,
                       fuse_refine_stats *stats)
{
    return g ? fuse_refine_mask_global(p, g, weight, P, mask, mask_stride, out, out_stride,
                                       scratch, scratch_size, stats)
             : fuse_refine_mask(p, P, mask, mask_stride, out, out_stride, scratch, scratch_size,
                                stats);
}

fuse_result pipe_fit_refine_narrow(const fuse_refine_params *p, const fuse_colour_model *g,
                                   float weight, int min_band, const fuse_image *P,
                                   const uint8_t *mask, int mask_stride, uint8_t *out,
                                   int out_stride, void *scratch, size_t scratch_size,
                                   fuse_refine_stats *stats, int *band_used)
{
    if (!p || !P || !stats) return FUSE_ERR_ARGS;
    fuse_refine_params q = *p;
    /* the global model alone: the ring's histograms decide nothing, any
     * hand and background pixel in it let the global model decide */
    if (g && weight >= 1.0f && q.min_samples > PIPE_GLOBAL_MIN_SAMPLES)
        q.min_samples = PIPE_GLOBAL_MIN_SAMPLES;
    fuse_result r = run(&q, g, weight, P, mask, mask_stride, out, out_stride, scratch,
                        scratch_size, stats);
    while (r == FUSE_OK && !stats->used_colour && min_band > 0 && q.band / 2 >= min_band) {
        fuse_refine_params n = q;
        n.band = q.band / 2;
        const size_t need = fuse_refine_scratch_size(&n, P->width, P->height);
        if (!need || need > scratch_size) break;
        q = n;
        r = run(&q, g, weight, P, mask, mask_stride, out, out_stride, scratch, scratch_size,
                stats);
    }
    if (band_used) *band_used = q.band;
    return r;
}

int pipe_fit_refine_regrow(const fuse_refine_params *p, const fuse_colour_model *g,
                           float weight, const fuse_image *P, uint8_t *refined, int stride,
                           uint8_t *tmp, void *scratch, size_t scratch_size,
                           const fuse_refine_stats *first)
{
    if (!p || !P || !refined || !tmp || !first || stride < P->width) return -1;
    const double limit = PIPE_REGROW_PER_MILLE / 1000.0 * (double)P->width * (double)P->height;
    if (!first->used_colour || (double)first->flipped_in <= limit) return 0;
    for (int y = 0; y < P->height; y++)
        memcpy(tmp + (size_t)y * (size_t)P->width, refined + (size_t)y * (size_t)stride,
               (size_t)P->width);
    fuse_refine_stats st;
    fuse_result r = pipe_fit_refine_narrow(p, g, weight, PIPE_NARROW_MIN_BAND, P, tmp, P->width,
                                           refined, stride, scratch, scratch_size, &st, NULL);
    return r == FUSE_OK ? 1 : -1;
}

static int set_at(const uint8_t *m, int stride, int w, int h, int x, int y)
{
    return x >= 0 && y >= 0 && x < w && y < h && m[(size_t)y * (size_t)stride + (size_t)x] >= 128;
}

long pipe_fit_regrow_trail(const uint8_t *first, int first_stride, uint8_t *refined, int stride,
                           int w, int h, unsigned sides, const float hand_px[2][2],
                           const float motion[2][2], const float *speed, int steps)
{
    if (!first || !refined || !hand_px || !motion || w <= 0 || h <= 0 || first_stride < w ||
        stride < w || steps < 1)
        return -1;
    int dx[2], dy[2];
    unsigned moving = 0;
    for (int k = 0; k < 2; k++) {
        dx[k] = (int)lrintf(motion[k][0]);
        dy[k] = (int)lrintf(motion[k][1]);
        if ((sides >> k & 1u) && (dx[k] || dy[k]) && (!speed || speed[k] >= PIPE_TRAIL_SPEED))
            moving |= 1u << k;
    }
    if (!moving) return 0;
    long cleared = 0;
    for (int y = 0; y < h; y++) {
        uint8_t *row = refined + (size_t)y * (size_t)stride;
        const uint8_t *frow = first + (size_t)y * (size_t)first_stride;
        for (int x = 0; x < w; x++) {
            if (row[x] < 128 || frow[x] >= 128) continue;
            /* the nearest tracked hand */
            int k = -1;
            float best = 0.0f;
            for (int j = 0; j < 2; j++)
                if (sides >> j & 1u) {
                    const float ex = (float)x - hand_px[j][0], ey = (float)y - hand_px[j][1];
                    const float d2 = ex * ex + ey * ey;
                    if (k < 0 || d2 < best) { k = j; best = d2; }
                }
            if (k < 0 || !(moving >> k & 1u)) continue;
            int ahead = 0, behind = 0;
            for (int j = 1; j <= steps; j++) {
                behind |= set_at(first, first_stride, w, h, x + j * dx[k], y + j * dy[k]);
                ahead |= set_at(first, first_stride, w, h, x - j * dx[k], y - j * dy[k]);
            }
            if (behind && !ahead) {
                row[x] = 0;
                cleared++;
            }
        }
    }
    return cleared;
}
