/* raster_ref.c - the scalar reference kernels: per-pixel scan of a set-up
 * triangle, vertex transforms; and target clear. The output of this file
 * defines the rasterizer's bytes; SIMD scans must match it (the per-pixel
 * op order is in raster_internal.h and docs/raster.md). */
#include "raster_internal.h"

#include "../cpu/ef_n10.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

long rast__scan_ref(const rast_target *t, const rast__tri *tri)
{
    return rast__scan_rows_ref(t, tri, tri->y0, tri->y1);
}

long rast__scan_rows_ref(const rast_target *t, const rast__tri *tri, int ya,
                         int yb)
{
    const int na = (t->attr || t->attr_n10) ? tri->attr_count : 0;
    long written = 0;
    const int ys = ya > tri->y0 ? ya : tri->y0;
    const int ye = yb < tri->y1 ? yb : tri->y1;
    if (ys > ye)
        return 0;
    int64_t er[3];
    for (int k = 0; k < 3; k++)     /* exact: the same integers as stepping */
        er[k] = tri->e_c[k] + (int64_t)(ys - tri->y0) * tri->e_dy[k];
    for (int y = ys; y <= ye; y++) {
        const float fj = (float)(y - tri->y0);
        /* Row bases of every plane: c + dy * j. */
        const float zr = tri->z.c + tri->z.dy * fj;
        const float qr = tri->q.c + tri->q.dy * fj;
        const float b1r = tri->b1.c + tri->b1.dy * fj;
        const float b2r = tri->b2.c + tri->b2.dy * fj;
        uint8_t *mrow = t->mask + (size_t)y * (size_t)t->mask_stride;
        float *drow = t->depth ? t->depth + (size_t)y * (size_t)t->depth_stride
                               : NULL;
        float *arow = na && t->attr ? t->attr + (size_t)y * (size_t)t->attr_stride : NULL;
        uint32_t *nrow = na && t->attr_n10
                             ? t->attr_n10 + (size_t)y * (size_t)t->attr_n10_stride
                             : NULL;
        int64_t e0 = er[0], e1 = er[1], e2 = er[2];
        for (int x = tri->x0; x <= tri->x1; x++) {
            if ((e0 | e1 | e2) >= 0) {   /* all sign bits clear */
                const float fi = (float)(x - tri->x0);
                float z = zr + tri->z.dx * fi;
                z = z < 0.0f ? 0.0f : z;
                z = z > 1.0f ? 1.0f : z;
                if (!drow || z < drow[x]) {
                    if (drow)
                        drow[x] = z;
                    mrow[x] = 255;
                    if (na) {
                        const float r = 1.0f / (qr + tri->q.dx * fi);
                        const float b1 = (b1r + tri->b1.dx * fi) * r;
                        const float b2 = (b2r + tri->b2.dx * fi) * r;
                        float a3[RAST_MAX_ATTRS];
                        float *a = arow ? arow + (size_t)x * (size_t)na : a3;
                        for (int k = 0; k < na; k++)
                            a[k] = (tri->a0[k] + b1 * tri->d1[k]) + b2 * tri->d2[k];
                        if (nrow)   /* na == 3 (validated) */
                            nrow[x] = ef_n10_pack(a[0], a[1], a[2]);
                    }
                    written++;
                }
            }
            e0 += tri->e_dx[0];
            e1 += tri->e_dx[1];
            e2 += tri->e_dx[2];
        }
        for (int k = 0; k < 3; k++)
            er[k] += tri->e_dy[k];
    }
    return written;
}

void rast_target_clear(const rast_target *t)
{
    if (!t || t->width <= 0 || t->height <= 0)
        return;
    for (int y = 0; y < t->height; y++) {
        if (t->depth)
            rast__fill_depth(t->depth + (size_t)y * (size_t)t->depth_stride,
                             (size_t)t->width);
        if (t->mask)
            memset(t->mask + (size_t)y * (size_t)t->mask_stride, 0, (size_t)t->width);
        if (t->attr && t->attr_count > 0)   /* all-zero bytes are 0.0f */
            memset(t->attr + (size_t)y * (size_t)t->attr_stride, 0,
                   (size_t)t->width * (size_t)t->attr_count * sizeof(float));
        if (t->attr_n10)   /* 0 is ef_n10_pack(0, 0, 0) */
            memset(t->attr_n10 + (size_t)y * (size_t)t->attr_n10_stride, 0,
                   (size_t)t->width * sizeof(uint32_t));
    }
}

void rast__transform_points_ref(const float mvp[16], const float *pos, int n,
                                float *clip)
{
    for (int i = 0; i < n; i++) {
        const float x = pos[3 * i], y = pos[3 * i + 1], z = pos[3 * i + 2];
        for (int r = 0; r < 4; r++)
            clip[4 * i + r] = ((mvp[r] * x + mvp[4 + r] * y) + mvp[8 + r] * z) +
                              mvp[12 + r];
    }
}

void rast__transform_dirs_ref(const float m[16], const float *v, int n, float *out)
{
    for (int i = 0; i < n; i++) {
        const float x = v[3 * i], y = v[3 * i + 1], z = v[3 * i + 2];
        float r[3];
        for (int k = 0; k < 3; k++)
            r[k] = (m[k] * x + m[4 + k] * y) + m[8 + k] * z;
        /* Length in double: no underflow for tiny vectors, no overflow for
         * huge ones; a zero vector stays zero. */
        const double len = sqrt(((double)r[0] * r[0] + (double)r[1] * r[1]) +
                                (double)r[2] * r[2]);
        for (int k = 0; k < 3; k++)
            out[3 * i + k] = len > 0.0 ? (float)((double)r[k] / len) : 0.0f;
    }
}

const char *rast_result_str(rast_result r)
{
    switch (r) {
    case RAST_OK:        return "ok";
    case RAST_ERR_ARGS:  return "invalid arguments (NULL pointer, count, stride or attribute count)";
    case RAST_ERR_SIZE:  return "target size out of range (1..RAST_MAX_DIM)";
    case RAST_ERR_INDEX: return "vertex index out of range";
    }
    return "unknown rast_result";
}
