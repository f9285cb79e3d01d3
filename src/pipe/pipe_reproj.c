/* pipe_reproj.c - the eye's view of the hands from the camera images by
 * the model's depth (see pipe_reproj.h). */
#include "pipe_reproj.h"

#include "../cpu/cpu.h"
#include "../cpu/ef_mem.h"
#include "../cpu/ef_n10.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int pipe_view_parse(const char *name, int *view)
{
    if (!name) return -1;
    if (!strcmp(name, "crop")) *view = PIPE_VIEW_CROP;
    else if (!strcmp(name, "reproject")) *view = PIPE_VIEW_REPROJECT;
    else return -1;
    return 0;
}

const char *pipe_view_name(int view)
{
    return view == PIPE_VIEW_CROP ? "crop" : view == PIPE_VIEW_REPROJECT ? "reproject" : "?";
}

int pipe_view_check(const kin_sthmd_desc *hmd, char *why, int why_size)
{
    /* the raw values first: a NaN or a negative one would resolve to the
     * default and hide the mistake */
    kin_sthmd_desc r = kin_sthmd_desc_resolved(hmd);
    float ipd = hmd && hmd->ipd_m != 0.0f ? hmd->ipd_m : r.ipd_m;
    float d = hmd && hmd->cam_offset_m != 0.0f ? hmd->cam_offset_m : r.cam_offset_m;
    if (!(ipd >= PIPE_IPD_MIN_M && ipd <= PIPE_IPD_MAX_M)) {
        if (why && why_size > 0)
            snprintf(why, (size_t)why_size, "the IPD (ipd_m) %g m is outside %g..%g m", (double)ipd,
                     (double)PIPE_IPD_MIN_M, (double)PIPE_IPD_MAX_M);
        return -1;
    }
    if (!(d >= 0.0f && d <= PIPE_CAM_OFFSET_MAX_M)) {
        if (why && why_size > 0)
            snprintf(why, (size_t)why_size,
                     "the camera offset D (cam_offset_m) %g m is outside 0..%g m", (double)d,
                     (double)PIPE_CAM_OFFSET_MAX_M);
        return -1;
    }
    return 0;
}

int pipe__reproj_init(pipe__reproj *r, int width, int height, int float_normals)
{
    memset(r, 0, sizeof *r);
    size_t px = (size_t)width * (size_t)height;
    r->width = width;
    r->height = height;
    r->depth = malloc(sizeof(float) * px);
    r->n10 = malloc(sizeof(uint32_t) * px);
    if (float_normals) r->nrm = malloc(sizeof(float) * 3 * px);
    r->mask = malloc(px);
    r->P = calloc(px, 4);
    r->M = calloc(px, 1);
    r->row = malloc(sizeof(int32_t) * (size_t)width + (size_t)height);
    r->lanes = malloc(sizeof(int32_t) * 8 * ((size_t)width + 16));
    if (!r->depth || !r->n10 || (float_normals && !r->nrm) || !r->mask || !r->P || !r->M ||
        !r->row || !r->lanes) {
        pipe__reproj_free(r);
        return -1;
    }
    return 0;
}

void pipe__reproj_free(pipe__reproj *r)
{
    EF_FREE_ALL(r->depth, r->n10, r->nrm, r->mask, r->P, r->M, r->row, r->lanes);
    memset(r, 0, sizeof *r);
}

/* Metric distance along the view axis of window depth z (docs/fuse.md). */
static float lin_depth(float z, float n, float f)
{
    float zn = 2.0f * z - 1.0f;
    return 2.0f * f * n / ((f + n) - zn * (f - n));
}

enum { ST_NONE = 0, ST_SAMPLED = 1, ST_FILL = 2, ST_UNRESOLVED = 3 };

/* The scalar reference of the geometry pass (pipe_reproj_simd.inl is
 * this, lane by lane): columns [x, w) of one eye row, the covered ones. */
static void row_ref(const pipe__reproj_geo *g, const uint8_t *em, const float *ed,
                    const uint32_t *en, float ry, int x, int w, const pipe__reproj_lanes *o,
                    long *back, float *mind)
{
    const float *a = g->a; /* column-major: x' = a0 x + a4 y + a8 z + a12 */
    const float fade = PIPE_REPROJ_FADE_PX, n = g->n;
    for (; x < w; x++) {
        if (!em[x]) continue;
        const float rx = g->rxs[x];
        float nv[3];
        ef_n10_unpack(en[x], nv);
        if (nv[0] * rx + nv[1] * ry - nv[2] > 0.0f) (*back)++;
        const float zn = 2.0f * ed[x] - 1.0f;
        const float dist = g->two_fn / (g->fpn - zn * g->fmn);
        if (dist < *mind) *mind = dist;
        /* the eye-view point (rx, ry, -1) * dist in the camera's view */
        float ex = rx * dist, ey = ry * dist, ez = -dist;
        float px = a[0] * ex + a[4] * ey + a[8] * ez + a[12];
        float py = a[1] * ex + a[5] * ey + a[9] * ez + a[13];
        float pz = a[2] * ex + a[6] * ey + a[10] * ez + a[14];
        float fu = 0.0f, fv = 0.0f;
        int ok;
        if (g->pinhole) {
            ok = pz < -1e-6f;
            if (ok) {
                float iz = 1.0f / -pz;
                fu = g->ccx + g->cfx * px * iz;
                fv = g->ccy - g->cfy * py * iz;
            }
        } else {
            double pc[3] = {px, py, pz}, u, v;
            ok = kin_lens_project(g->lens, pc, &u, &v);
            fu = (float)u + g->ox;
            fv = (float)v + g->oy;
        }
        /* distance to the camera image's border, camera pixels */
        float b = 0.0f;
        if (ok) {
            b = fu;
            if (g->cw - fu < b) b = g->cw - fu;
            if (fv < b) b = fv;
            if (g->ch - fv < b) b = g->ch - fv;
        }
        if (!ok || !(b > 0.0f)) {
            o->mv[x] = 0;
            continue;
        }
        o->mv[x] = b >= fade ? 255 : (int32_t)(255.0f * (b / fade) + 0.5f);
        /* a camera pixel shows this point when the camera's model is
         * there no nearer than the point minus the slack: as a window
         * depth of the camera's projection, zmin */
        const float dp = -pz, dmin = dp - (PIPE_REPROJ_TOL_M + PIPE_REPROJ_TOL_REL * dp);
        o->zmin[x] = dmin > n ? 0.5f * (g->fpn - g->two_fn / dmin) / g->fmn + 0.5f : 0.0f;
        int iu = (int)fu, iv = (int)fv;
        o->iu[x] = iu > g->icw1 ? g->icw1 : iu;
        o->iv[x] = iv > g->ich1 ? g->ich1 : iv;
        float sx = fu - 0.5f, sy = fv - 0.5f;
        if (sx < 0.0f) sx = 0.0f;
        if (sy < 0.0f) sy = 0.0f;
        if (sx > g->cw1) sx = g->cw1;
        if (sy > g->ch1) sy = g->ch1;
        const int x0 = (int)sx, y0 = (int)sy;
        o->tx[x] = x0;
        o->ty[x] = y0;
        o->fx[x] = (int)((sx - (float)x0) * 256.0f);
        o->fy[x] = (int)((sy - (float)y0) * 256.0f);
    }
}

static pipe__reproj_row_fn row_kernel(int isa)
{
    switch ((ef_isa)isa) {
#if defined(__x86_64__)
    case EF_ISA_AVX512: return pipe__reproj_row_avx512;
    case EF_ISA_AVX2: return pipe__reproj_row_avx2;
    case EF_ISA_SSE2: return pipe__reproj_row_sse2;
#elif defined(__aarch64__) && defined(__ARM_NEON)
    case EF_ISA_NEON: return pipe__reproj_row_neon;
#endif
    default: return NULL;
    }
}

static pipe__reproj_taps_fn taps_kernel(int isa)
{
    switch ((ef_isa)isa) {
#if defined(__x86_64__)
    case EF_ISA_AVX512: return pipe__reproj_taps_avx512;
    case EF_ISA_AVX2: return pipe__reproj_taps_avx2;
    case EF_ISA_SSE2: return pipe__reproj_taps_sse2;
#elif defined(__aarch64__) && defined(__ARM_NEON)
    case EF_ISA_NEON: return pipe__reproj_taps_neon;
#endif
    default: return NULL;
    }
}

/* Does the camera's G-buffer show the point (window depth bound zmin) at
 * image pixel (x, y)? Outside the G-buffer (the sensor beyond the crop)
 * there is nothing to test against: yes. */
static inline int shows(const uint8_t *cmask, int cms, const float *cdepth, int cds, int gx,
                        int gy, int gw, int gh, float zmin)
{
    if ((unsigned)gx >= (unsigned)gw || (unsigned)gy >= (unsigned)gh) return 1;
    return cmask[(size_t)gy * (size_t)cms + (size_t)gx] != 0 &&
           !(cdepth[(size_t)gy * (size_t)cds + (size_t)gx] < zmin);
}

/* The 32 mask bytes from p are all 0. */
static inline int empty32(const uint8_t *p)
{
    uint64_t v[4];
    memcpy(v, p, sizeof v);
    return (v[0] | v[1] | v[2] | v[3]) == 0;
}

/* The first covered column of the eye mask row em (w columns), w when
 * there is none; *xe: one past the last. 32, then 8 bytes at a time. */
static int covered_span(const uint8_t *em, int w, int *xe)
{
    uint64_t word;
    int a = 0, b = w;
    while (a + 32 <= w && empty32(em + a)) a += 32;
    while (a + 8 <= w && (memcpy(&word, em + a, 8), word == 0)) a += 8;
    while (a < w && !em[a]) a++;
    if (a == w) {
        *xe = w;
        return w;
    }
    while (b - 32 >= a && empty32(em + b - 32)) b -= 32;
    while (b - 8 >= a && (memcpy(&word, em + b - 8, 8), word == 0)) b -= 8;
    while (!em[b - 1]) b--;
    *xe = b;
    return a;
}

/* 8 mask bytes from p. */
static inline uint64_t ld8(const uint8_t *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

/* (pipe_reproj.h) One pass over each flagged row's span of set mask bytes
 * (8 clear ones at a time skipped) keeps the last sampled pixel of the
 * run; the next one is searched when the pass has gone beyond the one
 * found before, so a row costs O(span) plus the column walks from its
 * filled pixels, each within its run. Fills write colours but keep the
 * filled kind, so no filled pixel is the source of another: the result
 * does not depend on the order. */
void pipe__reproj_fill(uint8_t *rows, int w, int h, uint8_t *M, uint8_t *P, const float *ed,
                       float n, float f)
{
    for (int y = 0; y < h; y++) {
        if (!(rows[y] & 1)) continue;
        const size_t r0 = (size_t)y * (size_t)w;
        const uint8_t *My = M + r0;
        int a = 0, b = w;
        while (a + 8 <= b && ld8(My + a) == 0) a += 8;
        while (a < b && !My[a]) a++;
        while (b - 8 >= a && ld8(My + b - 8) == 0) b -= 8;
        while (b > a && !My[b - 1]) b--;
        int last = -1, nxt = -2, unresolved = 0; /* nxt -2: not searched yet */
        for (int x = a; x < b; x++) {
            if (!My[x]) { /* a run ends: its sampled pixels are no candidates */
                last = -1, nxt = -2;
                while (x + 9 <= b && ld8(My + x + 1) == 0) x += 8;
                continue;
            }
            const size_t i = r0 + (size_t)x;
            if (P[4 * i + 3] == ST_SAMPLED) {
                last = x;
                continue;
            }
            if (P[4 * i + 3] != ST_FILL) continue;
            if (nxt != -1 && nxt <= x) {
                nxt = -1;
                for (int k = x + 1; k < b && My[k]; k++)
                    if (P[4 * (r0 + (size_t)k) + 3] == ST_SAMPLED) {
                        nxt = k;
                        break;
                    }
            }
            /* the candidates: left, right, above, below */
            size_t c[4];
            int dist[4], nc = 0;
            if (last >= 0) c[nc] = r0 + (size_t)last, dist[nc++] = x - last;
            if (nxt >= 0) c[nc] = r0 + (size_t)nxt, dist[nc++] = nxt - x;
            for (size_t yy = (size_t)y, k = i; yy-- > 0 && M[k -= (size_t)w];)
                if (P[4 * k + 3] == ST_SAMPLED) {
                    c[nc] = k, dist[nc++] = y - (int)yy;
                    break;
                }
            for (size_t yy = (size_t)y, k = i; ++yy < (size_t)h && M[k += (size_t)w];)
                if (P[4 * k + 3] == ST_SAMPLED) {
                    c[nc] = k, dist[nc++] = (int)yy - y;
                    break;
                }
            if (nc == 0) {
                P[4 * i + 3] = ST_UNRESOLVED;
                unresolved = 1;
                continue;
            }
            /* of those on the pixel's surface (eye distance within the
             * occlusion test's slack of the nearest in depth), the nearest */
            const float d0 = lin_depth(ed[i], n, f);
            float dd[4], dmin = INFINITY;
            for (int k = 0; k < nc; k++) {
                dd[k] = fabsf(lin_depth(ed[c[k]], n, f) - d0);
                if (dd[k] < dmin) dmin = dd[k];
            }
            const float lim = dmin + (PIPE_REPROJ_TOL_M + PIPE_REPROJ_TOL_REL * d0);
            int best = -1;
            for (int k = 0; k < nc; k++)
                if (dd[k] <= lim && (best < 0 || dist[k] < dist[best])) best = k;
            for (int j = 0; j < 3; j++) P[4 * i + j] = P[4 * c[best] + j];
        }
        rows[y] = (uint8_t)((rows[y] & 2) | unresolved);
    }
}

/* (pipe_reproj.h) The nearest coloured pixel of the source row per
 * column is built once per source row (two passes), so a row to fill
 * costs O(w + h) (the search for its source row) however many pixels it
 * fills; such pixels are few (none of the four searches of
 * pipe__reproj_fill found a sampled one). The pixels filled keep kind 3
 * until every row is done, so none is the source of another. */
void pipe__reproj_fill_cols(const uint8_t *rows, int w, int h, uint8_t *M, uint8_t *P,
                            int32_t *near)
{
#define RP_COLOURED(m, p) ((m) && (p)[3] != ST_UNRESOLVED)
    int built = -1;
    for (int y = 0; y < h; y++) {
        if (!(rows[y] & 1)) continue;
        int ya = y - 1, yb = y + 1;
        while (ya >= 0 && !(rows[ya] & 2)) ya--;
        while (yb < h && !(rows[yb] & 2)) yb++;
        uint8_t *My = M + (size_t)y * (size_t)w;
        uint8_t *Py = P + (size_t)y * (size_t)w * 4;
        const int src = ya >= 0 && (yb >= h || y - ya <= yb - y) ? ya : yb < h ? yb : -1;
        if (src < 0) {
            for (int x = 0; x < w; x++)
                if (My[x] && Py[4 * x + 3] == ST_UNRESOLVED) My[x] = 0; /* nothing seen at all */
            continue;
        }
        const uint8_t *Ms = M + (size_t)src * (size_t)w;
        const uint8_t *Ps = P + (size_t)src * (size_t)w * 4;
        if (src != built) {
            /* near[x]: the nearest coloured column (M != 0, not kind 3;
             * the left on a tie); the row has at least one (its sampled
             * pixels) */
            int last = -1;
            for (int x = 0; x < w; x++) {
                if (RP_COLOURED(Ms[x], Ps + 4 * x)) last = x;
                near[x] = last;
            }
            int next = -1;
            for (int x = w - 1; x >= 0; x--) {
                if (RP_COLOURED(Ms[x], Ps + 4 * x)) next = x;
                if (next >= 0 && (near[x] < 0 || next - x < x - near[x])) near[x] = next;
            }
            built = src;
        }
        for (int x = 0; x < w; x++) {
            if (!My[x] || Py[4 * x + 3] != ST_UNRESOLVED) continue;
            const uint8_t *c = Ps + 4 * (size_t)near[x];
            for (int j = 0; j < 3; j++) Py[4 * x + j] = c[j];
        }
    }
#undef RP_COLOURED
    /* the kind of the pixels filled (and hidden) back to filled */
    for (int y = 0; y < h; y++) {
        if (!(rows[y] & 1)) continue;
        uint8_t *Py = P + (size_t)y * (size_t)w * 4;
        for (int x = 0; x < w; x++)
            if (Py[4 * x + 3] == ST_UNRESOLVED) Py[4 * x + 3] = ST_FILL;
    }
}

int pipe__reproj_sample(pipe__reproj *r, const kin_camera *cam, const fuse_image *P, int ox,
                        int oy, const uint8_t *cmask, int cmask_stride, const float *cdepth,
                        int cdepth_stride, int gw, int gh, float n, float f)
{
    const int w = r->width, h = r->height;
    const int cw = P->width, ch = P->height;
    const kin_camera *ec = &r->cam;
    /* eye view -> camera view */
    kin_mat4 m = kin_mat4_mul(&cam->view, &ec->world_from_cam);
    pipe__reproj_geo g;
    memcpy(g.a, m.m, sizeof g.a);
    g.pinhole = !kin_lens_distorts(&cam->lens) && cam->lens.skew == 0.0;
    g.lens = &cam->lens;
    /* the camera's intrinsics are the crop's: the image's pixels are
     * (ox, oy) further (0, 0 when the image is the crop) */
    g.ox = (float)ox, g.oy = (float)oy;
    g.cfx = cam->fx, g.cfy = cam->fy;
    g.ccx = (float)cam->cx + g.ox, g.ccy = (float)cam->cy + g.oy;
    g.cw = (float)cw, g.ch = (float)ch, g.cw1 = (float)(cw - 1), g.ch1 = (float)(ch - 1);
    g.icw1 = cw - 1, g.ich1 = ch - 1;
    g.n = n, g.f = f, g.fpn = f + n, g.fmn = f - n, g.two_fn = 2.0f * f * n;
    const float efx = ec->fx, efy = ec->fy, ecx = ec->cx, ecy = ec->cy;
    const pipe__reproj_row_fn kernel = g.pinhole ? row_kernel(r->isa) : NULL;
    /* the taps on the vector layer: the image's rows whole int32 pixels,
     * the mask at least 4 bytes */
    const long mlim = (long)(gh - 1) * cmask_stride + gw - 4;
    const pipe__reproj_taps_fn taps =
        P->stride % 4 == 0 && mlim >= 0 && gw > 0 && gh > 0 ? taps_kernel(r->isa) : NULL;
    const pipe__reproj_tapd td = {cmask, cdepth, P->pixels, cmask_stride, cdepth_stride,
                                  gw, gh, ox, oy, P->stride / 4, cw - 1, ch - 1, (int)mlim};
    const size_t lw = (size_t)w + 16;
    const pipe__reproj_lanes o = {r->lanes,          r->lanes + lw,     r->lanes + 2 * lw,
                                  r->lanes + 3 * lw, r->lanes + 4 * lw, r->lanes + 5 * lw,
                                  r->lanes + 6 * lw, (float *)(r->lanes + 7 * lw)};
    long covered = 0, back = 0, sampled = 0, filled = 0, outside = 0;
    float mind = INFINITY;
    /* the eye rays' x per column, and per row: bit 1 sampled pixels, bit 0
     * filled ones (pipe__reproj_fill, pipe__reproj_fill_cols) */
    float *rxs = (float *)r->row;
    uint8_t *row_fill = (uint8_t *)(r->row + w);
    for (int x = 0; x < w; x++) rxs[x] = ((float)x + 0.5f - ecx) / efx;
    g.rxs = rxs;
    for (int y = 0; y < h; y++) {
        const uint8_t *em = r->mask + (size_t)y * (size_t)w;
        uint8_t *M = r->M + (size_t)y * (size_t)w;
        uint8_t *Po = r->P + (size_t)y * (size_t)w * 4;
        const float *ed = r->depth + (size_t)y * (size_t)w;
        const uint32_t *en = r->n10 + (size_t)y * (size_t)w;
        const float ry = -((float)y + 0.5f - ecy) / efy;
        const long filled0 = filled, sampled0 = sampled;
        memset(M, 0, (size_t)w);
        /* only the row's span of covered pixels, its ends out to
         * multiples of 16 (of every SIMD_W) so that the vector kernels
         * do it whole: [xs, xe); their blocks outside it would each test
         * 4 to 16 empty mask bytes */
        int xe;
        int xs = covered_span(em, w, &xe);
        row_fill[y] = 0;
        if (xs == xe) continue;
        xs &= ~15;
        xe = xe + 15 < w ? (xe + 15) & ~15 : w;
        /* the geometry of the row's covered pixels (vector, then the tail) */
        int x1 = kernel ? kernel(&g, em, ed, en, ry, xs, xe, &o, &back, &mind) : xs;
        row_ref(&g, em, ed, en, ry, x1, xe, &o, &back, &mind);
        /* the taps (vector, then the tail) */
        int xt = xs;
        if (taps) {
            long cnt[4] = {0, 0, 0, 0};
            xt = taps(&td, em, &o, xs, xe, M, Po, cnt);
            covered += cnt[0], outside += cnt[1], filled += cnt[2], sampled += cnt[3];
        }
        for (int x = xt; x < xe; x++) {
            if (!em[x]) {
                /* 8 empty mask bytes at a time */
                uint64_t word;
                while (x + 9 <= xe && (memcpy(&word, em + x + 1, 8), word == 0)) x += 8;
                continue;
            }
            covered++;
            if (!o.mv[x]) {
                outside++;
                continue;
            }
            M[x] = (uint8_t)o.mv[x];
            const float zmin = o.zmin[x];
            /* the nearest camera pixel: does the camera see this point? */
            const int iu = o.iu[x], iv = o.iv[x];
            int seen = shows(cmask, cmask_stride, cdepth, cdepth_stride, iu - ox, iv - oy, gw, gh,
                             zmin);
            if (!seen) {
                Po[4 * x + 3] = ST_FILL;
                filled++;
                continue;
            }
            /* bilinear, the taps that show the point (the camera's mask,
             * the same surface), renormalised */
            const int x0 = o.tx[x], y0 = o.ty[x], fx8 = o.fx[x], fy8 = o.fy[x];
            const int dx = x0 + 1 < cw ? 1 : 0, y1 = y0 + 1 < ch ? y0 + 1 : y0;
            /* a tap counts with its weight when it shows the point */
            const int gx = x0 - ox, gy0 = y0 - oy, gy1 = y1 - oy;
            int s00, s01, s10, s11;
            if (gx >= 0 && gx + dx < gw && gy0 >= 0 && gy1 < gh) {
                /* all four taps inside the G-buffer (the common case) */
                const uint8_t *m0 = cmask + (size_t)gy0 * (size_t)cmask_stride + (size_t)gx;
                const uint8_t *m1 = cmask + (size_t)gy1 * (size_t)cmask_stride + (size_t)gx;
                const float *d0 = cdepth + (size_t)gy0 * (size_t)cdepth_stride + (size_t)gx;
                const float *d1 = cdepth + (size_t)gy1 * (size_t)cdepth_stride + (size_t)gx;
                s00 = m0[0] != 0 && !(d0[0] < zmin);
                s01 = m0[dx] != 0 && !(d0[dx] < zmin);
                s10 = m1[0] != 0 && !(d1[0] < zmin);
                s11 = m1[dx] != 0 && !(d1[dx] < zmin);
            } else {
                s00 = shows(cmask, cmask_stride, cdepth, cdepth_stride, gx, gy0, gw, gh, zmin);
                s01 = shows(cmask, cmask_stride, cdepth, cdepth_stride, gx + dx, gy0, gw, gh, zmin);
                s10 = shows(cmask, cmask_stride, cdepth, cdepth_stride, gx, gy1, gw, gh, zmin);
                s11 = shows(cmask, cmask_stride, cdepth, cdepth_stride, gx + dx, gy1, gw, gh, zmin);
            }
            const uint32_t w00 = s00 ? (uint32_t)((256 - fx8) * (256 - fy8)) : 0u;
            const uint32_t w01 = s01 ? (uint32_t)(fx8 * (256 - fy8)) : 0u;
            const uint32_t w10 = s10 ? (uint32_t)((256 - fx8) * fy8) : 0u;
            const uint32_t w11 = s11 ? (uint32_t)(fx8 * fy8) : 0u;
            const uint8_t *p0 = P->pixels + (size_t)y0 * (size_t)P->stride + 4 * (size_t)x0;
            const uint8_t *p1 = P->pixels + (size_t)y1 * (size_t)P->stride + 4 * (size_t)x0;
            const int d4 = 4 * dx;
            uint32_t acc[3], ws = w00 + w01 + w10 + w11;
            for (int j = 0; j < 3; j++)
                acc[j] = w00 * p0[j] + w01 * p0[d4 + j] + w10 * p1[j] + w11 * p1[d4 + j];
            if (ws == 0) { /* only the nearest pixel is the model's */
                const uint8_t *c = P->pixels + (size_t)iv * (size_t)P->stride + 4 * (size_t)iu;
                for (int j = 0; j < 3; j++) acc[j] = c[j];
                ws = 1;
            }
            for (int j = 0; j < 3; j++) {
                uint8_t c = ws == 65536u ? (uint8_t)((acc[j] + 32768u) >> 16)
                                         : (uint8_t)((acc[j] + ws / 2) / ws);
                Po[4 * x + j] = c;
            }
            Po[4 * x + 3] = ST_SAMPLED;
            sampled++;
        }
        row_fill[y] = (uint8_t)((sampled != sampled0 ? 2 : 0) | (filled != filled0 ? 1 : 0));
    }
    r->sampled = sampled;
    r->outside = outside;
    r->inside = covered > 0 && (2 * back > covered || mind < PIPE_REPROJ_MIN_DIST_M);
    if (r->inside) {
        r->filled = 0;
        return 1;
    }
    /* the filled pixels from the nearest sampled ones on their surface in
     * their row and column; those with none there from the nearest row
     * that has some, or (none at all) not shown */
    pipe__reproj_fill(row_fill, w, h, r->M, r->P, r->depth, n, f);
    pipe__reproj_fill_cols(row_fill, w, h, r->M, r->P, r->lanes);
    r->filled = filled; /* P's alpha keeps the markers: fuse_light ignores it */
    return 0;
}
