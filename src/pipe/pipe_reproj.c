/* pipe_reproj.c - the eye's view of the hands from the camera images by
 * the model's depth (see pipe_reproj.h). */
#include "pipe_reproj.h"

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

int pipe__reproj_init(pipe__reproj *r, int width, int height)
{
    memset(r, 0, sizeof *r);
    size_t px = (size_t)width * (size_t)height;
    r->width = width;
    r->height = height;
    r->depth = malloc(sizeof(float) * px);
    r->nrm = malloc(sizeof(float) * 3 * px);
    r->mask = malloc(px);
    r->P = calloc(px, 4);
    r->M = calloc(px, 1);
    r->row = malloc(sizeof(int32_t) * 3 * (size_t)width + (size_t)height);
    if (!r->depth || !r->nrm || !r->mask || !r->P || !r->M || !r->row) {
        pipe__reproj_free(r);
        return -1;
    }
    return 0;
}

void pipe__reproj_free(pipe__reproj *r)
{
    free(r->depth);
    free(r->nrm);
    free(r->mask);
    free(r->P);
    free(r->M);
    free(r->row);
    memset(r, 0, sizeof *r);
}

/* Metric distance along the view axis of window depth z (docs/fuse.md). */
static float lin_depth(float z, float n, float f)
{
    float zn = 2.0f * z - 1.0f;
    return 2.0f * f * n / ((f + n) - zn * (f - n));
}

enum { ST_NONE = 0, ST_SAMPLED = 1, ST_FILL = 2 };

int pipe__reproj_sample(pipe__reproj *r, const kin_camera *cam, const fuse_image *P,
                        const uint8_t *cmask, int cmask_stride, const float *cdepth,
                        int cdepth_stride, float n, float f)
{
    const int w = r->width, h = r->height;
    const int cw = P->width, ch = P->height;
    const kin_camera *ec = &r->cam;
    /* eye view -> camera view */
    kin_mat4 m = kin_mat4_mul(&cam->view, &ec->world_from_cam);
    const float *a = m.m; /* column-major: x' = a0 x + a4 y + a8 z + a12 */
    const int pinhole = !kin_lens_distorts(&cam->lens) && cam->lens.skew == 0.0;
    const float cfx = cam->fx, cfy = cam->fy, ccx = cam->cx, ccy = cam->cy;
    const float efx = ec->fx, efy = ec->fy, ecx = ec->cx, ecy = ec->cy;
    const float fade = PIPE_REPROJ_FADE_PX;
    long covered = 0, back = 0, sampled = 0, filled = 0, outside = 0;
    float mind = INFINITY;
    uint64_t sum[3] = {0, 0, 0};
    /* the eye rays' x per column, and per row: a fill pixel in it */
    float *rxs = (float *)(r->row + 2 * w);
    uint8_t *row_fill = (uint8_t *)(r->row + 3 * w);
    for (int x = 0; x < w; x++) rxs[x] = ((float)x + 0.5f - ecx) / efx;
    for (int y = 0; y < h; y++) {
        const uint8_t *em = r->mask + (size_t)y * (size_t)w;
        uint8_t *M = r->M + (size_t)y * (size_t)w;
        uint8_t *Po = r->P + (size_t)y * (size_t)w * 4;
        const float *ed = r->depth + (size_t)y * (size_t)w;
        const float *en = r->nrm + (size_t)y * (size_t)w * 3;
        const float ry = -((float)y + 0.5f - ecy) / efy;
        const long filled0 = filled;
        memset(M, 0, (size_t)w);
        for (int x = 0; x < w; x++) {
            if (!em[x]) {
                /* 8 empty mask bytes at a time */
                uint64_t word;
                while (x + 9 <= w && (memcpy(&word, em + x + 1, 8), word == 0)) x += 8;
                continue;
            }
            covered++;
            const float rx = rxs[x];
            const float *nv = en + 3 * x;
            if (nv[0] * rx + nv[1] * ry - nv[2] > 0.0f) back++;
            float dist = lin_depth(ed[x], n, f);
            if (dist < mind) mind = dist;
            /* the eye-view point (rx, ry, -1) * dist in the camera's view */
            float ex = rx * dist, ey = ry * dist, ez = -dist;
            float px = a[0] * ex + a[4] * ey + a[8] * ez + a[12];
            float py = a[1] * ex + a[5] * ey + a[9] * ez + a[13];
            float pz = a[2] * ex + a[6] * ey + a[10] * ez + a[14];
            float fu = 0.0f, fv = 0.0f;
            int ok;
            if (pinhole) {
                ok = pz < -1e-6f;
                if (ok) {
                    float iz = 1.0f / -pz;
                    fu = ccx + cfx * px * iz;
                    fv = ccy - cfy * py * iz;
                }
            } else {
                double pc[3] = {px, py, pz}, u, v;
                ok = kin_lens_project(&cam->lens, pc, &u, &v);
                fu = (float)u;
                fv = (float)v;
            }
            /* distance to the camera image's border, camera pixels */
            float b = 0.0f;
            if (ok) {
                b = fu;
                if ((float)cw - fu < b) b = (float)cw - fu;
                if (fv < b) b = fv;
                if ((float)ch - fv < b) b = (float)ch - fv;
            }
            if (!ok || !(b > 0.0f)) {
                outside++;
                continue;
            }
            M[x] = b >= fade ? 255 : (uint8_t)(255.0f * (b / fade) + 0.5f);
            if (M[x] == 0) {
                outside++;
                continue;
            }
            /* a camera pixel shows this point when the camera's model is
             * there no nearer than the point minus the slack: as a window
             * depth of the camera's projection, zmin */
            const float dp = -pz, dmin = dp - (PIPE_REPROJ_TOL_M + PIPE_REPROJ_TOL_REL * dp);
            const float zmin = dmin > n ? 0.5f * ((f + n) - 2.0f * f * n / dmin) / (f - n) + 0.5f
                                        : 0.0f;
            /* the nearest camera pixel: does the camera see this point? */
            int iu = (int)fu, iv = (int)fv;
            if (iu > cw - 1) iu = cw - 1;
            if (iv > ch - 1) iv = ch - 1;
            int seen = cmask[(size_t)iv * (size_t)cmask_stride + (size_t)iu] != 0 &&
                       !(cdepth[(size_t)iv * (size_t)cdepth_stride + (size_t)iu] < zmin);
            if (!seen) {
                Po[4 * x + 3] = ST_FILL;
                filled++;
                continue;
            }
            /* bilinear, the taps that show the point (the camera's mask,
             * the same surface), renormalised */
            float sx = fu - 0.5f, sy = fv - 0.5f;
            if (sx < 0.0f) sx = 0.0f;
            if (sy < 0.0f) sy = 0.0f;
            if (sx > (float)(cw - 1)) sx = (float)(cw - 1);
            if (sy > (float)(ch - 1)) sy = (float)(ch - 1);
            const int x0 = (int)sx, y0 = (int)sy;
            const int fx8 = (int)((sx - (float)x0) * 256.0f), fy8 = (int)((sy - (float)y0) * 256.0f);
            const int dx = x0 + 1 < cw ? 1 : 0, y1 = y0 + 1 < ch ? y0 + 1 : y0;
            const uint8_t *m0 = cmask + (size_t)y0 * (size_t)cmask_stride + (size_t)x0;
            const uint8_t *m1 = cmask + (size_t)y1 * (size_t)cmask_stride + (size_t)x0;
            const float *d0 = cdepth + (size_t)y0 * (size_t)cdepth_stride + (size_t)x0;
            const float *d1 = cdepth + (size_t)y1 * (size_t)cdepth_stride + (size_t)x0;
            /* a tap counts with its weight when it shows the point */
            const uint32_t w00 = (m0[0] != 0 && !(d0[0] < zmin)) ? (uint32_t)((256 - fx8) * (256 - fy8)) : 0u;
            const uint32_t w01 = (m0[dx] != 0 && !(d0[dx] < zmin)) ? (uint32_t)(fx8 * (256 - fy8)) : 0u;
            const uint32_t w10 = (m1[0] != 0 && !(d1[0] < zmin)) ? (uint32_t)((256 - fx8) * fy8) : 0u;
            const uint32_t w11 = (m1[dx] != 0 && !(d1[dx] < zmin)) ? (uint32_t)(fx8 * fy8) : 0u;
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
                sum[j] += c;
            }
            Po[4 * x + 3] = ST_SAMPLED;
            sampled++;
        }
        row_fill[y] = filled != filled0;
    }
    r->sampled = sampled;
    r->outside = outside;
    r->inside = covered > 0 && (2 * back > covered || mind < PIPE_REPROJ_MIN_DIST_M);
    if (r->inside) {
        r->filled = 0;
        return 1;
    }
    /* the fill: the nearest sampled pixel of the row, else the mean */
    uint8_t mean[3] = {0, 0, 0};
    if (sampled)
        for (int j = 0; j < 3; j++)
            mean[j] = (uint8_t)((sum[j] + (uint64_t)sampled / 2) / (uint64_t)sampled);
    long done = 0;
    for (int y = 0; y < h && done < filled; y++) {
        if (!row_fill[y]) continue;
        const uint8_t *em = r->mask + (size_t)y * (size_t)w;
        uint8_t *M = r->M + (size_t)y * (size_t)w;
        uint8_t *Po = r->P + (size_t)y * (size_t)w * 4;
        int32_t *left = r->row, *right = r->row + w;
        int any = 0, last = -1;
        for (int x = 0; x < w; x++) {
            int st = em[x] && M[x] ? Po[4 * x + 3] : ST_NONE;
            if (st == ST_SAMPLED) last = x;
            else if (st == ST_FILL) any = 1;
            left[x] = last;
        }
        if (!any) continue;
        last = -1;
        for (int x = w - 1; x >= 0; x--) {
            int st = em[x] && M[x] ? Po[4 * x + 3] : ST_NONE;
            if (st == ST_SAMPLED) last = x;
            right[x] = last;
        }
        for (int x = 0; x < w; x++) {
            if (!em[x] || !M[x] || Po[4 * x + 3] != ST_FILL) continue;
            done++;
            /* of the nearest sampled pixels left and right, the one on
             * the same surface: its eye distance nearer to this pixel's */
            int l = left[x], rr = right[x], src = l >= 0 ? l : rr;
            if (l >= 0 && rr >= 0) {
                const float *ed = r->depth + (size_t)y * (size_t)w;
                float d0 = lin_depth(ed[x], n, f);
                float dl = fabsf(lin_depth(ed[l], n, f) - d0);
                float dr = fabsf(lin_depth(ed[rr], n, f) - d0);
                if (dr < dl) src = rr;
            }
            if (src >= 0) {
                for (int j = 0; j < 3; j++) Po[4 * x + j] = Po[4 * src + j];
            } else if (sampled) {
                for (int j = 0; j < 3; j++) Po[4 * x + j] = mean[j];
            } else {
                M[x] = 0; /* nothing seen at all: not shown */
            }
        }
    }
    r->filled = filled; /* P's alpha keeps the markers: fuse_light ignores it */
    return 0;
}
