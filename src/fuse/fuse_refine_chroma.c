/* fuse_refine_chroma.c - a shading-invariant term for the global colour
 * model (fuse_refine.h, fuse_colour_model_chroma). */
#include "fuse_refine.h"

#include <math.h>
#include <string.h>

enum { CB = 32, CBINS = CB * CB };

/* The chromaticity bin of an RGB colour: (r, g) / (r + g + b) in 32 x 32
 * bins; -1 when r + g + b < dark (no reliable chromaticity). */
static int chroma_bin(float r, float g, float b, float dark)
{
    const float s = r + g + b;
    if (s < dark) return -1;
    int i = (int)(r / s * (float)CB), j = (int)(g / s * (float)CB);
    i = i < 0 ? 0 : i >= CB ? CB - 1 : i;
    j = j < 0 ? 0 : j >= CB ? CB - 1 : j;
    return i * CB + j;
}

size_t fuse_colour_model_chroma_scratch_size(void)
{
    return 2u * CBINS * sizeof(uint32_t) + CBINS * sizeof(float);
}

fuse_result fuse_colour_model_chroma(fuse_colour_model *cm, const fuse_image *P,
                                     const uint8_t *mask, int mask_stride, int margin, int step,
                                     float clamp, long min_samples, float weight, float dark,
                                     void *scratch, size_t scratch_size)
{
    if (!cm || !cm->llr || cm->bits < 2 || cm->bits > 6 || !P || !P->pixels || P->width < 1 ||
        P->height < 1 || P->stride < 4 * P->width || !mask || mask_stride < P->width ||
        margin < 0 || margin > 64 || step < 1 || step > 8 || !(clamp > 0.0f) ||
        min_samples < 1 || !(weight >= 0.0f) || !(weight <= 1.0f) || !(dark >= 0.0f) ||
        !scratch || ((uintptr_t)scratch & 3u) != 0 ||
        scratch_size < fuse_colour_model_chroma_scratch_size())
        return FUSE_ERR_ARGS;
    const int w = P->width, h = P->height;
    uint32_t *hf = scratch, *hb = hf + CBINS;
    float *cl = (float *)(void *)(hb + CBINS);
    memset(hf, 0, 2u * CBINS * sizeof(uint32_t));
    long nf = 0, nb = 0;
    for (int y = 0; y < h; y += step) {
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        const uint8_t *s = P->pixels + (size_t)y * (size_t)P->stride;
        for (int x = 0; x < w; x += step) {
            const uint8_t v = m[x];
            if (v != 0 && v != 255) continue;
            int xl = x - margin < 0 ? 0 : x - margin, xr = x + margin >= w ? w - 1 : x + margin;
            int yu = y - margin < 0 ? 0 : y - margin, yd = y + margin >= h ? h - 1 : y + margin;
            if (m[xl] != v || m[xr] != v || mask[(size_t)yu * (size_t)mask_stride + (size_t)x] != v ||
                mask[(size_t)yd * (size_t)mask_stride + (size_t)x] != v)
                continue;
            int b = chroma_bin(s[4 * x], s[4 * x + 1], s[4 * x + 2], dark);
            if (b < 0) continue;
            if (v == 255) { hf[b]++; nf++; }
            else { hb[b]++; nb++; }
        }
    }
    if (nf < min_samples || nb < min_samples || weight == 0.0f) return FUSE_OK;
    const float a = 4.0f / (float)CBINS;
    const float off = logf((float)nb + 4.0f) - logf((float)nf + 4.0f);
    for (int b = 0; b < CBINS; b++) {
        float v = logf(((float)hf[b] + a) / ((float)hb[b] + a)) + off;
        cl[b] = v > clamp ? clamp : v < -clamp ? -clamp : v;
    }
    /* mix into every RGB bin whose centre has a chromaticity */
    const int bits = cm->bits, n = 1 << bits;
    const float q = (float)(256 >> bits);
    for (int r = 0; r < n; r++)
        for (int g = 0; g < n; g++)
            for (int bl = 0; bl < n; bl++) {
                int b = chroma_bin(((float)r + 0.5f) * q, ((float)g + 0.5f) * q,
                                   ((float)bl + 0.5f) * q, dark);
                if (b < 0) continue;
                float *o = &cm->llr[(r << (2 * bits)) | (g << bits) | bl];
                *o = (1.0f - weight) * *o + weight * cl[b];
            }
    return FUSE_OK;
}
