/* fuse_normals.c - fuse_normal_smooth (fuse_normals.h). */
#include "fuse_normals.h"

#include <stddef.h>

fuse_result fuse_normal_smooth(const uint8_t *mask, int mask_stride, const float *nrm,
                               int nrm_stride, float *out, int out_stride, int width,
                               int height, int radius)
{
    int x, y;
    if (!mask || !nrm || !out || width < 1 || height < 1 || width > FUSE_MAX_DIM ||
        height > FUSE_MAX_DIM || mask_stride < width || nrm_stride < 3 * width ||
        out_stride < 3 * width || radius < 1 || radius > FUSE_NORMAL_SMOOTH_MAX)
        return FUSE_ERR_ARGS;
    {   /* out must not overlap nrm */
        const char *a0 = (const char *)nrm, *b0 = (const char *)out;
        const char *a1 = a0 + sizeof(float) * ((size_t)(height - 1) * (size_t)nrm_stride + 3 * (size_t)width);
        const char *b1 = b0 + sizeof(float) * ((size_t)(height - 1) * (size_t)out_stride + 3 * (size_t)width);
        if (a0 < b1 && b0 < a1) return FUSE_ERR_ARGS;
    }
    for (y = 0; y < height; y++) {
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        float *o = out + (size_t)y * (size_t)out_stride;
        const int y0 = y - radius < 0 ? 0 : y - radius;
        const int y1 = y + radius >= height ? height - 1 : y + radius;
        for (x = 0; x < width; x++) {
            const int x0 = x - radius < 0 ? 0 : x - radius;
            const int x1 = x + radius >= width ? width - 1 : x + radius;
            float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f;
            int yy, xx;
            if (m[x] == 0) continue;
            for (yy = y0; yy <= y1; yy++) {
                const float *n = nrm + (size_t)yy * (size_t)nrm_stride + 3 * (size_t)x0;
                float r0 = 0.0f, r1 = 0.0f, r2 = 0.0f;
                for (xx = x0; xx <= x1; xx++, n += 3) {
                    r0 = r0 + n[0];
                    r1 = r1 + n[1];
                    r2 = r2 + n[2];
                }
                s0 = s0 + r0;
                s1 = s1 + r1;
                s2 = s2 + r2;
            }
            o[3 * x + 0] = s0;
            o[3 * x + 1] = s1;
            o[3 * x + 2] = s2;
        }
    }
    return FUSE_OK;
}
