/* fuse_depth.c - the depth test of the lit layer against the virtual
 * scene's depth, and gray-world colour tone matching. Conventions in
 * fuse.h and docs/fuse.md ("Depth", "Tone matching"). */
#include "fuse_internal.h"

#include <math.h>
#include <stddef.h>

static int finite_in(float v, float lo, float hi) { return v >= lo && v <= hi; }   /* NaN -> 0 */

fuse_result fuse__depth_check(const fuse_depth *d, const fuse_image *Q, int vp_x0,
                              int vp_y0, int vp_w, int vp_h)
{
    if (d == NULL || Q == NULL || d->hand == NULL || d->scene == NULL ||
        !fuse__image_ok(Q))
        return FUSE_ERR_ARGS;
    if (d->hand_stride < Q->width || d->scene_width < 1 || d->scene_height < 1 ||
        d->scene_width > FUSE_MAX_DIM || d->scene_height > FUSE_MAX_DIM ||
        d->scene_stride < d->scene_width || vp_w < 1 || vp_h < 1)
        return FUSE_ERR_ARGS;
    if (!finite_in(d->znear, 1.0e-7f, 1.0e7f) || !finite_in(d->zfar, 1.0e-7f, 1.0e7f) ||
        !(d->zfar > d->znear) || !finite_in(d->offset, -FUSE_PARAM_MAX, FUSE_PARAM_MAX))
        return FUSE_ERR_ARGS;
    if (vp_x0 < 0 || vp_y0 < 0 || vp_x0 > d->scene_width - vp_w ||
        vp_y0 > d->scene_height - vp_h)
        return FUSE_ERR_SIZE;
    return FUSE_OK;
}

void fuse__depth_prepare(const fuse_depth *d, int qw, int vp_w, fuse__depth_prep *p)
{
    p->two_fn = (2.0f * d->zfar) * d->znear;
    p->fpn = d->zfar + d->znear;
    p->fmn = d->zfar - d->znear;
    p->offset = d->offset;
    p->vw = vp_w;
    p->den = 2 * qw;
    p->step_q = (2 * vp_w) / p->den;
    p->step_r = (2 * vp_w) % p->den;
}

/* The reference: for every pixel that is set and has a hand depth z in
 * [0, 1), dist = two_fn / (fpn - (2z - 1) fmn) + offset (this order, IEEE
 * single), and the pixel is zeroed when 0 < scene < dist. NaN fails every
 * compare: a NaN depth keeps the pixel, a NaN scene too. bpp 4: q holds
 * RGBA8 pixels, set when not (0,0,0,0); bpp 1: mask bytes
 * (fuse_internal.h), set when not 0. Callers pass a constant bpp. */
static inline void depth_span(const fuse__depth_prep *p, uint8_t *q, int bpp,
                              const float *hz, const float *sc, int x0, int x1)
{
    int32_t ox, rem;
    int x;
    if (x0 >= x1) return;
    fuse__depth_col(p, x0, &ox, &rem);
    for (x = x0; x < x1; x++) {
        uint8_t *px = q + (size_t)bpp * (size_t)x;
        float z, dist, s;
        const int32_t cx = ox;
        ox += p->step_q;
        rem += p->step_r;
        if (rem >= p->den) {
            rem -= p->den;
            ox++;
        }
        if (bpp == 4) {
            uint32_t w;
            memcpy(&w, px, 4);
            if (w == 0) continue;
        } else if (px[0] == 0) {
            continue;
        }
        z = hz[x];
        if (!(z >= 0.0f && z < 1.0f)) continue;          /* no depth: keep */
        dist = p->two_fn / (p->fpn - ((2.0f * z) - 1.0f) * p->fmn) + p->offset;
        s = sc[cx];
        if (s > 0.0f && s < dist) memset(px, 0, (size_t)bpp);   /* scene in front */
    }
}

/* The spans and rows of the layer (bpp 4) and of mask bytes (bpp 1: the
 * same rule with m != 0 instead of a pixel that is not (0,0,0,0)). */
#define DEPTH_REF(span, row, bpp)                                                      \
    void span(const fuse__depth_prep *p, uint8_t *q, const float *hz, const float *sc, \
              int x0, int x1)                                                          \
    {                                                                                  \
        depth_span(p, q, bpp, hz, sc, x0, x1);                                         \
    }                                                                                  \
    void row(const fuse__depth_prep *p, uint8_t *q, const float *hz, const float *sc,  \
             int w)                                                                    \
    {                                                                                  \
        depth_span(p, q, bpp, hz, sc, 0, w);                                           \
    }
DEPTH_REF(fuse__depth_span_ref, fuse__depth_row_ref, 4)
DEPTH_REF(fuse__depth_mspan_ref, fuse__depth_mrow_ref, 1)

void fuse__depth_rows(const fuse_depth *d, const fuse_image *Q, int vp_x0,
                      int vp_y0, int vp_w, int vp_h, int y0, int y1, fuse__depth_fn fn)
{
    const int sh = Q->height;
    fuse__depth_prep p;
    int y;
    fuse__depth_prepare(d, Q->width, vp_w, &p);
    for (y = y0; y < y1; y++)
        fn(&p, Q->pixels + (size_t)y * (size_t)Q->stride,
           d->hand + (size_t)y * (size_t)d->hand_stride,
           fuse__depth_scene_row(d, y, sh, vp_x0, vp_y0, vp_h), Q->width);
}

/* ---- tone matching ----------------------------------------------------- */

#define TONE_STEP 4

fuse_result fuse_tone_match(const fuse_image *P, const uint8_t *mask,
                            int mask_stride, const fuse_image *V, int vp_x0,
                            int vp_y0, int vp_w, int vp_h, float strength,
                            float tone[3])
{
    uint64_t sp[3] = { 0, 0, 0 }, sv[3] = { 0, 0, 0 }, np = 0, nv = 0;
    int x, y, c;
    if (P == NULL || mask == NULL || V == NULL || tone == NULL ||
        !fuse__image_ok(P) || !fuse__image_ok(V) || mask_stride < P->width ||
        !(strength >= 0.0f && strength <= 1.0f) || vp_w < 1 || vp_h < 1)
        return FUSE_ERR_ARGS;
    if (vp_x0 < 0 || vp_y0 < 0 || vp_x0 > V->width - vp_w || vp_y0 > V->height - vp_h)
        return FUSE_ERR_SIZE;
    for (y = 0; y < P->height; y += TONE_STEP) {
        const uint8_t *p = P->pixels + (size_t)y * (size_t)P->stride;
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        for (x = 0; x < P->width; x += TONE_STEP)
            if (m[x] == 0) {
                for (c = 0; c < 3; c++) sp[c] += p[4 * x + c];
                np++;
            }
    }
    for (y = vp_y0; y < vp_y0 + vp_h; y += TONE_STEP) {
        const uint8_t *v = V->pixels + (size_t)y * (size_t)V->stride;
        for (x = vp_x0; x < vp_x0 + vp_w; x += TONE_STEP) {
            for (c = 0; c < 3; c++) sv[c] += v[4 * x + c];
            nv++;
        }
    }
    for (c = 0; c < 3; c++) {
        double t = 1.0;
        if (np > 0) {   /* nv > 0 always: the viewport is not empty */
            t = ((double)sv[c] / (double)nv + 1.0) / ((double)sp[c] / (double)np + 1.0);
            if (t < 0.25) t = 0.25;
            if (t > 4.0) t = 4.0;
        }
        tone[c] = (float)pow(t, (double)strength);
    }
    return FUSE_OK;
}
