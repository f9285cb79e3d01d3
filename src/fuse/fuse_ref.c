/* fuse_ref.c - scalar reference of the fuse module: lighting layer,
 * bilinear resampling into the viewport, "over" compositing, RGB24 to
 * RGBA8. These loops define every output byte; the rules they follow are
 * written in docs/fuse.md and the arithmetic itself sits in
 * fuse_internal.h so that other paths share it. */
#include "fuse_internal.h"

#include "../cpu/ef_n10.h"

#include <stddef.h>

/* Every float parameter of fuse_lighting must lie in [-FUSE_PARAM_MAX,
 * FUSE_PARAM_MAX] (fuse.h): with that bound no float in fuse_light can
 * overflow, so no inf or NaN ever reaches a clamp. */
#define PARAM_MAX FUSE_PARAM_MAX

static int in_range(float v, float lo, float hi) { return v >= lo && v <= hi; }  /* NaN -> 0 */

int fuse__image_ok(const fuse_image *im)
{
    return im->pixels != NULL && im->width >= 1 && im->height >= 1 &&
           im->width <= FUSE_MAX_DIM && im->height <= FUSE_MAX_DIM &&
           im->stride >= 4 * im->width;
}

/* Bytes spanned by an image: [pixels, pixels + extent). */
static size_t image_extent(const fuse_image *im)
{
    return (size_t)(im->height - 1) * (size_t)im->stride + 4u * (size_t)im->width;
}

int fuse__overlap(const fuse_image *a, const fuse_image *b)
{
    uintptr_t a0 = (uintptr_t)a->pixels, a1 = a0 + image_extent(a);
    uintptr_t b0 = (uintptr_t)b->pixels, b1 = b0 + image_extent(b);
    return a0 < b1 && b0 < a1;
}

/* Same memory, same layout: processing pixel by pixel is safe in place. */
int fuse__same_image(const fuse_image *a, const fuse_image *b)
{
    return a->pixels == b->pixels && a->stride == b->stride &&
           a->width == b->width && a->height == b->height;
}

static uint8_t *row_ptr(const fuse_image *im, int y)
{
    return im->pixels + (size_t)y * (size_t)im->stride;
}

fuse_lighting fuse_lighting_default(void)
{
    /* one light above (+y) and in front (+z, towards the viewer) of the
     * surface */
    return (fuse_lighting){ .light_count = 1,
                            .lights = { { .dir = { 0.0f, 0.6f, 0.8f },
                                          .color = { 1.0f, 1.0f, 1.0f } } },
                            .ambient = { 0.35f, 0.35f, 0.35f },
                            .kd = 0.75f, .ks = 0.15f, .shininess = 16.0f, .kf = 0.6f,
                            .tone = { 1.0f, 1.0f, 1.0f } };
}

fuse_image fuse_image_rows(const fuse_image *img, int y0, int h)
{
    fuse_image v;
    memset(&v, 0, sizeof v);
    if (img == NULL || img->pixels == NULL || img->stride < 0 || y0 < 0 ||
        h < 1 || y0 > img->height - h)
        return v;
    v.pixels = row_ptr(img, y0);
    v.width = img->width;
    v.height = h;
    v.stride = img->stride;
    return v;
}

/* ---- lighting -------------------------------------------------------- */

fuse_result fuse__light_prepare(const fuse_lighting *L,
                                const fuse_intrinsics *K,
                                fuse__light_prep *p)
{
    int i, c;
    if (L->light_count < 0 || L->light_count > FUSE_MAX_LIGHTS)
        return FUSE_ERR_ARGS;
    if (!in_range(L->shininess, 1.0f, PARAM_MAX) ||
        !in_range(L->kd, -PARAM_MAX, PARAM_MAX) ||
        !in_range(L->ks, -PARAM_MAX, PARAM_MAX) ||
        !in_range(L->kf, -PARAM_MAX, PARAM_MAX))
        return FUSE_ERR_ARGS;
    for (c = 0; c < 3; c++)
        if (!in_range(L->ambient[c], -PARAM_MAX, PARAM_MAX) ||
            !in_range(L->tone[c], -PARAM_MAX, PARAM_MAX))
            return FUSE_ERR_ARGS;
    if (!in_range(K->fx, 1.0e-3f, 1.0e7f) || !in_range(K->fy, 1.0e-3f, 1.0e7f) ||
        !in_range(K->cx, -1.0e7f, 1.0e7f) || !in_range(K->cy, -1.0e7f, 1.0e7f))
        return FUSE_ERR_ARGS;
    memset(p, 0, sizeof *p);
    for (i = 0; i < L->light_count; i++) {
        const fuse_light_src *s = &L->lights[i];
        float dd, inv;
        for (c = 0; c < 3; c++)
            if (!in_range(s->dir[c], -PARAM_MAX, PARAM_MAX) ||
                !in_range(s->color[c], -PARAM_MAX, PARAM_MAX))
                return FUSE_ERR_ARGS;
        dd = (s->dir[0] * s->dir[0] + s->dir[1] * s->dir[1]) + s->dir[2] * s->dir[2];
        if (!(dd > 1.0e-12f)) return FUSE_ERR_ARGS;   /* no direction */
        inv = 1.0f / sqrtf(dd);
        for (c = 0; c < 3; c++) {
            p->dir[i][c] = s->dir[c] * inv;
            p->color[i][c] = s->color[c];
        }
    }
    p->light_count = L->light_count;
    for (c = 0; c < 3; c++) {
        p->ambient[c] = L->ambient[c];
        p->tone[c] = L->tone[c];
        p->kt[c] = L->tone[c] * FUSE__INV255;
        p->ambient_t[c] = L->ambient[c] * p->kt[c];
        for (i = 0; i < L->light_count; i++)
            p->color_t[i][c] = p->color[i][c] * p->kt[c];
    }
    p->kd = L->kd;
    p->ks = L->ks;
    p->shininess = L->shininess;
    p->ipow = fuse__pow_int(L->shininess);
    p->kf = L->kf;
    p->c_nonneg = p->kd >= 0.0f && p->ks >= 0.0f;
    for (c = 0; c < 3; c++) {
        p->c_nonneg = p->c_nonneg && p->ambient_t[c] >= 0.0f;
        for (i = 0; i < L->light_count; i++)
            p->c_nonneg = p->c_nonneg && p->color_t[i][c] >= 0.0f;
    }
    p->ifx = 1.0f / K->fx;
    p->nifx = -p->ifx;
    p->mo = (0.5f - K->cx) * p->nifx;
    p->ify = 1.0f / K->fy;
    p->cx = K->cx;
    p->cy = K->cy;
    return FUSE_OK;
}

void fuse__light_row_ref(const fuse__light_prep *p, int y, int width,
                         const uint8_t *P, const uint8_t *mask,
                         const float *normal, uint8_t *out)
{
    fuse__light_span_ref(p, y, 0, width, P, mask, normal, out);
}

/* One light's diffuse weight, and what its specular term needs: nl =
 * N.L_i, hh = |L_i + V|^2 (docs/fuse.md, "Lighting"). */
static void light_terms(const fuse__light_prep *p, int i, float nx, float ny, float nz,
                        float inv, float vx, float vy, float vz, float *w, float *nl, float *hh)
{
    const float lx = p->dir[i][0], ly = p->dir[i][1], lz = p->dir[i][2];
    const float hx = lx + vx, hy = ly + vy, hz = lz + vz;
    *nl = ((nx * lx + ny * ly) + nz * lz) * inv;
    *w = p->kd * fuse__max0(*nl);
    *hh = (hx * hx + hy * hy) + hz * hz;
}

/* fuse__light_span_ref on float normals (n10 0: normal, 3 floats a pixel)
 * or ef_n10 ones (n10 1: nq, one uint32_t a pixel, unpacked exactly as
 * ef_n10_unpack: (float)k * EF_N10_INV); n10 is a constant at each call,
 * so each function below is compiled with one form only. */
static inline __attribute__((always_inline)) void light_span_body(
    const fuse__light_prep *p, int y, int x0, int x1, const uint8_t *P, const uint8_t *mask,
    const float *normal, const uint32_t *nq, uint8_t *out, int n10)
{
    /* View ray of the row; the image's y axis points down, view y up. */
    const float py = (((float)y + 0.5f) - p->cy) * p->ify;
    const float pyy = py * py + 1.0f;
    int x, i, c;
    P += 4 * (size_t)x0;
    out += 4 * (size_t)x0;
    for (x = x0; x < x1; x++, P += 4, out += 4) {
        const unsigned M = mask[x];
        float mpx, vv, sv, sn, r, il, inv, vx, vy, vz, nx, ny, nz, nn, ndv, t, t2, fade, m;
        float C[3];
        if (M == 0) {
            out[0] = out[1] = out[2] = out[3] = 0;
            continue;
        }
        /* The view ray v = (-px, py, 1), V = v / |v|; mpx = -px. */
        mpx = (float)x * p->nifx + p->mo;
        vv = mpx * mpx + pyy;
        sv = sqrtf(vv);
        /* n as given, or v when it has no usable length (N = V). */
        if (n10) {   /* ef_n10_unpack's floats */
            nx = (float)ef_n10_k(nq[x], 0) * EF_N10_INV;
            ny = (float)ef_n10_k(nq[x], 1) * EF_N10_INV;
            nz = (float)ef_n10_k(nq[x], 2) * EF_N10_INV;
        } else {
            nx = normal[3 * (size_t)x];
            ny = normal[3 * (size_t)x + 1];
            nz = normal[3 * (size_t)x + 2];
        }
        nn = (nx * nx + ny * ny) + nz * nz;
        if (nn > 1.0e-30f && nn < 1.0e30f) {
            sn = sqrtf(nn);
        } else {
            nx = mpx;
            ny = py;
            nz = 1.0f;
            sn = sv;
        }
        /* One division for both lengths: 1/|n| and 1/|v|. */
        r = 1.0f / (sn * sv);
        il = sn * r;
        inv = sv * r;
        vx = mpx * il;
        vy = py * il;
        vz = il;
        ndv = ((nx * mpx + ny * py) + nz) * r;
        C[0] = p->ambient_t[0];
        C[1] = p->ambient_t[1];
        C[2] = p->ambient_t[2];
        /* Lights in pairs: one division gives both 1 / hh. */
        for (i = 0; i < p->light_count; i += 2) {
            const int two = i + 1 < p->light_count;
            float w0, w1 = 0.0f, nl0, nl1 = 0.0f, hh0, hh1 = 1.0f;
            light_terms(p, i, nx, ny, nz, inv, vx, vy, vz, &w0, &nl0, &hh0);
            if (two) light_terms(p, i + 1, nx, ny, nz, inv, vx, vy, vz, &w1, &nl1, &hh1);
            if (p->ks != 0.0f) {           /* ks == 0: the term is +0 */
                /* hh <= 1e-12 (L == -V): no half vector, no specular */
                const int g0 = hh0 > 1.0e-12f, g1 = hh1 > 1.0e-12f;
                const float n0 = fuse__max0(nl0 + ndv), n1 = fuse__max0(nl1 + ndv);
                float x0s, x1s;
                if (two) {
                    const float a0 = g0 ? hh0 : 1.0f, a1 = g1 ? hh1 : 1.0f;
                    const float d = 1.0f / (a0 * a1);
                    x0s = (n0 * n0) * (a1 * d);
                    x1s = (n1 * n1) * (a0 * d);
                    if (g1) w1 = w1 + p->ks * fuse__spec01(x1s, p->shininess, p->ipow);
                } else {
                    x0s = g0 ? (n0 * n0) / hh0 : 0.0f;
                }
                if (g0) w0 = w0 + p->ks * fuse__spec01(x0s, p->shininess, p->ipow);
            }
            C[0] = C[0] + p->color_t[i][0] * w0;
            C[1] = C[1] + p->color_t[i][1] * w0;
            C[2] = C[2] + p->color_t[i][2] * w0;
            if (two) {
                C[0] = C[0] + p->color_t[i + 1][0] * w1;
                C[1] = C[1] + p->color_t[i + 1][1] * w1;
                C[2] = C[2] + p->color_t[i + 1][2] * w1;
            }
        }
        t = fuse__clamp01(1.0f - ndv);      /* Schlick's (1 - cos)^5 */
        t2 = t * t;
        fade = fuse__clamp01(1.0f - p->kf * ((t2 * t2) * t));
        m = (float)M * fade;                /* 255 m' */
        for (c = 0; c < 3; c++) {
            const float v = fuse__clamp01((float)P[c] * C[c]);
            out[c] = fuse__round8(m * v);
        }
        out[3] = fuse__round8(m);
    }
}

void fuse__light_span_ref(const fuse__light_prep *p, int y, int x0, int x1,
                          const uint8_t *P, const uint8_t *mask,
                          const float *normal, uint8_t *out)
{
    light_span_body(p, y, x0, x1, P, mask, normal, NULL, out, 0);
}

void fuse__light_span_n10_ref(const fuse__light_prep *p, int y, int x0, int x1,
                              const uint8_t *P, const uint8_t *mask,
                              const uint32_t *normal, uint8_t *out)
{
    light_span_body(p, y, x0, x1, P, mask, NULL, normal, out, 1);
}

fuse_result fuse__light_check(const fuse_lighting *L, const fuse_intrinsics *K,
                              const fuse_image *P, const uint8_t *mask,
                              int mask_stride, const float *normal,
                              int normal_stride, const uint32_t *normal_n10,
                              int normal_n10_stride, const fuse_image *out,
                              fuse__light_prep *prep)
{
    fuse_result r;
    if (L == NULL || K == NULL || P == NULL || mask == NULL ||
        (normal == NULL) == (normal_n10 == NULL) || out == NULL)
        return FUSE_ERR_ARGS;
    if (!fuse__image_ok(P) || !fuse__image_ok(out) || mask_stride < P->width ||
        (normal != NULL ? normal_stride < 3 * P->width : normal_n10_stride < P->width))
        return FUSE_ERR_ARGS;
    r = fuse__light_prepare(L, K, prep);
    if (r != FUSE_OK) return r;
    if (out->width != P->width || out->height != P->height)
        return FUSE_ERR_SIZE;
    if (fuse__overlap(P, out) && !fuse__same_image(P, out))
        return FUSE_ERR_ARGS;
    return FUSE_OK;
}

/* ---- resampling and compositing -------------------------------------- */

void fuse__composite_row_ref(const uint8_t *q0, const uint8_t *q1,
                             uint32_t fy, fuse__axis ax, int sw,
                             const uint8_t *v, uint8_t *out, int vw)
{
    int i, c;
    for (i = 0; i < vw; i++, v += 4, out += 4, fuse__axis_next(&ax)) {
        const int32_t pos = fuse__axis_pos(&ax);
        const int ix = pos >> 16;
        const int ix1 = ix + 1 < sw ? ix + 1 : sw - 1;   /* edge replicates */
        const uint32_t fx = ((uint32_t)pos >> 8) & 255u;
        const uint8_t *a = q0 + 4 * ix, *b = q0 + 4 * ix1;
        const uint8_t *cc = q1 + 4 * ix, *d = q1 + 4 * ix1;
        uint32_t ta, tb, tc, td, inv;
        memcpy(&ta, a, 4);
        memcpy(&tb, b, 4);
        memcpy(&tc, cc, 4);
        memcpy(&td, d, 4);
        if ((ta | tb | tc | td) == 0) {
            /* All four taps zero: Q = 0 and R = div255(255 V) = V exactly. */
            out[0] = v[0];
            out[1] = v[1];
            out[2] = v[2];
            out[3] = 255;
            continue;
        }
        inv = 255u - fuse__bilerp8(a[3], b[3], cc[3], d[3], fx, fy);
        for (c = 0; c < 3; c++) {
            uint32_t r = fuse__bilerp8(a[c], b[c], cc[c], d[c], fx, fy) +
                         FUSE__DIV255(inv * v[c]);
            out[c] = (uint8_t)(r < 255u ? r : 255u);
        }
        out[3] = 255;
    }
}

void fuse__composite_cols_ref(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                              const fuse__cols *cols, int c, int n, int sw,
                              const uint8_t *v, uint8_t *out)
{
    int i;
    for (i = 0; i < n; i++)
        fuse__composite_px(q0, q1, fy, cols->ix[c + i], (uint32_t)cols->fx[c + i],
                           sw, v + 4 * i, out + 4 * i);
}

/* Coverage bits of a layer row (fuse_internal.h), reading only the blocks
 * that meet [x0, x1) (the others are 0). */
void fuse__cover_span_ref(const uint8_t *q, int w, int x0, int x1, uint64_t *bits)
{
    const int nb = (w + FUSE__COV_BLOCK - 1) / FUSE__COV_BLOCK;
    int b;
    memset(bits, 0, 8u * (size_t)((nb + 63) / 64));
    if (x0 >= x1) return;
    for (b = x0 / FUSE__COV_BLOCK; b < nb && b * FUSE__COV_BLOCK < x1; b++) {
        const int xb = 8 * b + 8 < w ? 8 * b + 8 : w;
        uint32_t acc = 0, t;
        int x;
        for (x = 8 * b; x < xb; x++) {
            memcpy(&t, q + 4 * (size_t)x, 4);
            acc |= t;
        }
        if (acc != 0) bits[b >> 6] |= (uint64_t)1 << (b & 63);
    }
}

/* The whole row: the span [0, w). */
void fuse__cover_row_ref(const uint8_t *q, int w, uint64_t *bits)
{
    fuse__cover_span_ref(q, w, 0, w, bits);
}

void fuse__opaque_ref(const uint8_t *v, uint8_t *out, int n)
{
    int i;
    for (i = 0; i < n; i++) {
        out[4 * i] = v[4 * i];
        out[4 * i + 1] = v[4 * i + 1];
        out[4 * i + 2] = v[4 * i + 2];
        out[4 * i + 3] = 255;
    }
}

fuse_result fuse__composite_check(const fuse_image *Q, const fuse_image *V,
                                  int vp_x0, int vp_y0, int vp_w, int vp_h,
                                  const fuse_image *out)
{
    if (Q == NULL || V == NULL || out == NULL)
        return FUSE_ERR_ARGS;
    if (!fuse__image_ok(Q) || !fuse__image_ok(V) || !fuse__image_ok(out) || vp_w < 1 || vp_h < 1)
        return FUSE_ERR_ARGS;
    if (out->width != V->width || out->height != V->height ||
        vp_x0 < 0 || vp_y0 < 0 || vp_x0 > V->width - vp_w ||
        vp_y0 > V->height - vp_h)
        return FUSE_ERR_SIZE;
    if ((!fuse__same_image(out, V) && fuse__overlap(out, V)) || fuse__overlap(out, Q))
        return FUSE_ERR_ARGS;
    return FUSE_OK;
}

/* ---- conversion, messages -------------------------------------------- */

fuse_result fuse_rgb24_to_rgba(const uint8_t *rgb, int stride, int width,
                               int height, fuse_image *out)
{
    int x, y;
    if (rgb == NULL || out == NULL || width < 1 || height < 1 ||
        width > FUSE_MAX_DIM || height > FUSE_MAX_DIM || stride < 3 * width ||
        !fuse__image_ok(out))
        return FUSE_ERR_ARGS;
    if (out->width != width || out->height != height)
        return FUSE_ERR_SIZE;
    for (y = 0; y < height; y++) {
        const uint8_t *s = rgb + (size_t)y * (size_t)stride;
        uint8_t *d = row_ptr(out, y);
        for (x = 0; x < width; x++, s += 3, d += 4) {
            d[0] = s[0];
            d[1] = s[1];
            d[2] = s[2];
            d[3] = 255;
        }
    }
    return FUSE_OK;
}

const char *fuse_result_str(fuse_result r)
{
    switch (r) {
    case FUSE_OK:       return "ok";
    case FUSE_ERR_ARGS: return "invalid argument (NULL pointer, bad stride or parameter)";
    case FUSE_ERR_SIZE: return "image sizes do not fit together";
    }
    return "unknown fuse_result";
}
