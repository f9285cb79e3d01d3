/* bench_mesh.h - the benchmark scene shared by bench/bench_raster.c and
 * bench/llvmpipe/llvmpipe_raster.c (header only, static): two arms with
 * hands, each made of 18 capsules (upper arm, forearm, palm, 5 fingers x 3
 * phalanges), tessellated to a requested triangle count, seen by the two
 * eyes of a see-through HMD (640x400 per eye, 100 degrees horizontal field
 * of view, 64 mm between the eyes). Deterministic: no random numbers. */
#ifndef EGOFUSE_BENCH_MESH_H
#define EGOFUSE_BENCH_MESH_H

#include "../src/raster/raster.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct bm_mesh {
    int vertex_count, tri_count;
    float *pos, *nrm;          /* 3 floats per vertex (metres, view of the
                                  head; unit normals) */
    uint32_t *idx;
} bm_mesh;

/* One capsule from a to b, radius r (flattened by `flat` along the second
 * axis), S segments around, R rings along (R >= 2): 2*S*(R-1) triangles. */
static void bm_capsule(bm_mesh *m, const float a[3], const float b[3], float r,
                       float flat, int S, int R)
{
    float ax[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    float len = sqrtf(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    for (int k = 0; k < 3; k++) ax[k] /= len;
    float up[3] = { 0, 1, 0 };
    if (fabsf(ax[1]) > 0.9f) { up[0] = 1; up[1] = 0; }
    float e1[3] = { ax[1] * up[2] - ax[2] * up[1], ax[2] * up[0] - ax[0] * up[2],
                    ax[0] * up[1] - ax[1] * up[0] };
    float l1 = sqrtf(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
    for (int k = 0; k < 3; k++) e1[k] /= l1;
    float e2[3] = { ax[1] * e1[2] - ax[2] * e1[1], ax[2] * e1[0] - ax[0] * e1[2],
                    ax[0] * e1[1] - ax[1] * e1[0] };
    const int v0 = m->vertex_count;
    float ext = len + 2.0f * r;   /* the caps extend r beyond a and b */
    for (int i = 0; i <= R; i++) {
        float t = (float)i / (float)R;
        float s = 0.5f - 0.5f * cosf(3.14159265f * t);       /* along */
        /* profile; sinf(3.14159265f) < 0 (the float is above pi): clamp,
         * or the far pole of every capsule would be NaN */
        float pr = sqrtf(fmaxf(0.0f, sinf(3.14159265f * t)));
        int ring = (i == 0 || i == R) ? 1 : S;
        for (int j = 0; j < ring; j++) {
            float ph = 6.2831853f * (float)j / (float)S;
            float c = cosf(ph), sn = sinf(ph) * flat;
            float *p = m->pos + 3 * m->vertex_count, *n = m->nrm + 3 * m->vertex_count;
            for (int k = 0; k < 3; k++) {
                p[k] = a[k] - r * ax[k] + ext * s * ax[k] + r * pr * (c * e1[k] + sn * e2[k]);
                n[k] = (i == 0) ? -ax[k] : (i == R) ? ax[k] : c * e1[k] + sinf(ph) * e2[k];
            }
            m->vertex_count++;
        }
    }
    /* vertex index of ring i (1..R-1), segment j */
#define BM_V(i, j) (uint32_t)(v0 + 1 + ((i) - 1) * S + ((j) % S))
    uint32_t *q = m->idx + 3 * m->tri_count;
    const uint32_t top = (uint32_t)v0, bot = (uint32_t)(v0 + 1 + (R - 1) * S);
    for (int j = 0; j < S; j++) {
        *q++ = top; *q++ = BM_V(1, j + 1); *q++ = BM_V(1, j);
        *q++ = bot; *q++ = BM_V(R - 1, j); *q++ = BM_V(R - 1, j + 1);
    }
    for (int i = 1; i < R - 1; i++)
        for (int j = 0; j < S; j++) {
            *q++ = BM_V(i, j); *q++ = BM_V(i, j + 1); *q++ = BM_V(i + 1, j + 1);
            *q++ = BM_V(i, j); *q++ = BM_V(i + 1, j + 1); *q++ = BM_V(i + 1, j);
        }
#undef BM_V
    m->tri_count += 2 * S + 2 * S * (R - 2);
}

/* Two arms, about `tris` triangles in all (the exact count is in the
 * mesh). Returns 0 on allocation failure. */
static int bm_arms(bm_mesh *m, int tris)
{
    /* 36 capsules, each 2*S*(R-1) triangles with R - 1 = S: 2*S^2 each. */
    int S = (int)(sqrt((double)tris / 72.0) + 0.5);
    if (S < 3) S = 3;
    int R = S + 1;
    int nv = 36 * (S * (R - 1) + 2), nt = 36 * 2 * S * (R - 1);
    memset(m, 0, sizeof *m);
    m->pos = malloc((size_t)nv * 3 * sizeof(float));
    m->nrm = malloc((size_t)nv * 3 * sizeof(float));
    m->idx = malloc((size_t)nt * 3 * sizeof(uint32_t));
    if (!m->pos || !m->nrm || !m->idx)
        return 0;
    for (int side = -1; side <= 1; side += 2) {
        const float sx = (float)side;
        const float sh[3] = { 0.20f * sx, -0.38f, 0.05f }, el[3] = { 0.17f * sx, -0.28f, -0.22f };
        const float wr[3] = { 0.09f * sx, -0.14f, -0.42f }, pa[3] = { 0.06f * sx, -0.10f, -0.50f };
        bm_capsule(m, sh, el, 0.050f, 1.0f, S, R);
        bm_capsule(m, el, wr, 0.040f, 1.0f, S, R);
        bm_capsule(m, wr, pa, 0.038f, 0.45f, S, R);
        for (int f = 0; f < 5; f++) {
            float fx = pa[0] + sx * (-0.030f + 0.015f * f), fy = pa[1] + 0.005f * f;
            float p0[3] = { fx, fy, pa[2] - 0.01f };
            for (int ph = 0; ph < 3; ph++) {
                float l = 0.028f - 0.005f * ph;
                float p1[3] = { p0[0] + sx * 0.003f * (f - 2), p0[1] - 0.004f * ph, p0[2] - l };
                bm_capsule(m, p0, p1, 0.0085f - 0.001f * ph, 1.0f, S, R);
                memcpy(p0, p1, sizeof p0);
            }
        }
    }
    return 1;
}

static void bm_free(bm_mesh *m)
{
    free(m->pos);
    free(m->nrm);
    free(m->idx);
    memset(m, 0, sizeof *m);
}

/* Column-major view-projection of eye e (0 left, 1 right): perspective
 * (100 degrees horizontal, near 0.05 m, far 10 m) times a translation by
 * -/+ 32 mm along x. */
static void bm_eye_mvp(int eye, int width, int height, float mvp[16])
{
    const double aspect = (double)width / height, n = 0.05, f = 10.0;
    const double tx = 1.0 / tan(100.0 * 3.14159265358979 / 360.0), ty = tx * aspect;
    memset(mvp, 0, 16 * sizeof(float));
    double ex = eye ? 0.032 : -0.032;
    mvp[0] = (float)tx;
    mvp[5] = (float)ty;
    mvp[10] = (float)((f + n) / (n - f));
    mvp[11] = -1.0f;
    mvp[14] = (float)(2.0 * f * n / (n - f));
    mvp[12] = (float)(-tx * ex);    /* P * T(-ex): x' = tx*(x - ex) */
}

/* The two eyes' targets: W x H depth, coverage and 3 normal floats a
 * pixel, each plane one allocation (eye 1 after eye 0). */
typedef struct bm_eyes {
    float *depth;
    uint8_t *mask;
    float *nrm;
    rast_target tg[2];
} bm_eyes;

static inline void bm_eyes_free(bm_eyes *b)
{
    free(b->depth);
    free(b->mask);
    free(b->nrm);
    memset(b, 0, sizeof *b);
}

/* 1, or 0 (nothing held) when out of memory. */
static inline int bm_eyes_init(bm_eyes *b, int W, int H)
{
    b->depth = malloc((size_t)W * H * 2 * sizeof(float));
    b->mask = malloc((size_t)W * H * 2);
    b->nrm = malloc((size_t)W * H * 2 * 3 * sizeof(float));
    if (!b->depth || !b->mask || !b->nrm) {
        bm_eyes_free(b);
        return 0;
    }
    for (int e = 0; e < 2; e++) {
        rast_target t = { W, H, b->depth + (size_t)e * W * H, W, b->mask + (size_t)e * W * H, W,
                          b->nrm + (size_t)e * W * H * 3, 3 * W, 3, NULL, 0 };
        b->tg[e] = t;
    }
    return 1;
}

#endif
