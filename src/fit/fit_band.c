/* fit_band.c - the refinement band from the projected uncertainty of the
 * hands (fit_band.h). */
#include "fit_band.h"
#include "../cpu/mask_rows.h"

#include <math.h>
#include <string.h>

pipe_fit_band_desc pipe_fit_band_desc_default(void)
{
    return (pipe_fit_band_desc){.sigma = 0.02f, .tau = 0.0f, .reach = 32.0f, .band_min = 16,
                                .band_max = 64, .hand_radius = 0.04f};
}

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

/* Image position and depth of joint n; 0 when behind the camera or
 * farther than reach outside the image. */
static int joint_px(const kin_camera *cam, const kin_mat4 *m, float reach, float *x, float *y,
                    float *z)
{
    const float *V = cam->view.m;
    const float px = m->m[12], py = m->m[13], pz = m->m[14];
    /* view space (column-major, looks down -Z) */
    float xv = V[0] * px + V[4] * py + V[8] * pz + V[12];
    float yv = V[1] * px + V[5] * py + V[9] * pz + V[13];
    float zv = V[2] * px + V[6] * py + V[10] * pz + V[14];
    *z = -zv;
    if (!(*z > 1e-3f)) return 0;
    *x = cam->cx + cam->fx * xv / *z;
    *y = cam->cy - cam->fy * yv / *z;
    return *x >= -reach && *y >= -reach && *x <= (float)cam->width + reach &&
           *y <= (float)cam->height + reach;
}

int pipe_fit_band(const pipe_fit_band_desc *dp, const kin_camera *cam, const kin_mat4 *world,
                  const kin_arm_rig *rig, unsigned sides, const float speed[2])
{
    pipe_fit_band_desc d = dp ? *dp : pipe_fit_band_desc_default();
    const int lo = clampi(d.band_min, 1, 64), hi = clampi(d.band_max, lo, 64);
    if (!cam || !world || !rig || !(d.sigma >= 0.0f) || !(d.tau >= 0.0f) || !(d.reach >= 0.0f))
        return lo;
    const float f = 0.5f * (cam->fx + cam->fy);
    float u = 0.0f;
    for (int s = 0; s < 2; s++) {
        if (!(sides & (1u << s))) continue;
        float zmin = INFINITY;
        for (int j = KIN_RIG_HAND; j < KIN_RIG_SIDE_JOINTS; j++) {
            const int n = rig->joint[s][j];
            if (n < 0) return lo;
            float x, y, z;
            if (!joint_px(cam, &world[n], d.reach, &x, &y, &z)) continue;
            if (z < zmin) zmin = z;
        }
        if (!isfinite(zmin)) continue;
        float v = speed && isfinite(speed[s]) && speed[s] > 0.0f ? speed[s] : 0.0f;
        float us = f * (d.sigma + v * d.tau) / zmin;
        if (us > u) u = us;
    }
    float b = ceilf(u);
    return b >= (float)hi ? hi : b <= (float)lo ? lo : (int)b;
}

/* The discs of side's hand joints in view: centre and radius
 * f * hand_radius / z + band, pixels; their count (at most
 * KIN_RIG_SIDE_JOINTS), -1 for a joint index < 0. */
typedef struct disc { float x, y, r; } disc;

static int side_discs(const pipe_fit_band_desc *d, const kin_camera *cam, const kin_mat4 *world,
                      const kin_arm_rig *rig, int side, int band, disc *out)
{
    const int W = cam->width, H = cam->height;
    const float f = 0.5f * (cam->fx + cam->fy);
    int n = 0;
    for (int j = KIN_RIG_HAND; j < KIN_RIG_SIDE_JOINTS; j++) {
        const int node = rig->joint[side][j];
        if (node < 0) return -1;
        float x, y, z;
        if (!joint_px(cam, &world[node], d->reach, &x, &y, &z)) continue;
        float r = f * d->hand_radius / z + (float)band;
        if (r > (float)(W + H)) r = (float)(W + H);
        out[n++] = (disc){ x, y, r };
    }
    return n;
}

/* Columns [*x0, *x1] of row y covered by the union of the discs' spans
 * from the leftmost to the rightmost (the row's hull); 0 when none. */
static int row_span(const disc *D, int n, int y, int W, int *x0, int *x1)
{
    int a = W, b = -1;
    for (int i = 0; i < n; i++) {
        const float dy = (float)y + 0.5f - D[i].y, h2 = D[i].r * D[i].r - dy * dy;
        if (h2 < 0.0f) continue;
        const float hw = sqrtf(h2);
        int l = (int)ceilf(D[i].x - hw - 0.5f), r = (int)floorf(D[i].x + hw - 0.5f);
        if (l < a) a = l;
        if (r > b) b = r;
    }
    if (a < 0) a = 0;
    if (b >= W) b = W - 1;
    *x0 = a;
    *x1 = b;
    return a <= b;
}

long pipe_fit_band_region(const pipe_fit_band_desc *dp, const kin_camera *cam,
                          const kin_mat4 *world, const kin_arm_rig *rig, unsigned sides,
                          int band, uint8_t *region, int stride)
{
    if (!region) return 0;
    pipe_fit_band_desc d = dp ? *dp : pipe_fit_band_desc_default();
    if (!cam || !world || !rig || cam->width < 1 || cam->height < 1 || stride < cam->width ||
        !(d.reach >= 0.0f) || !(d.hand_radius >= 0.0f))
        return 0;
    const int W = cam->width, H = cam->height;
    disc D[2 * KIN_RIG_SIDE_JOINTS];
    int n = 0;
    for (int s = 0; s < 2; s++) {
        if (!(sides & (1u << s))) continue;
        int m = side_discs(&d, cam, world, rig, s, band, D + n);
        if (m < 0) m = 0;
        n += m;
    }
    long n_set = 0;
    for (int y = 0; y < H; y++) {
        uint8_t *row = region + (size_t)y * (size_t)stride;
        memset(row, 0, (size_t)W);
        int x0, x1;
        if (n && row_span(D, n, y, W, &x0, &x1)) {
            memset(row + x0, 255, (size_t)(x1 - x0 + 1));
            n_set += x1 - x0 + 1;
        }
    }
    return n_set;
}

void pipe_fit_band_merge(const uint8_t *narrow, const uint8_t *wide, const uint8_t *region,
                         uint8_t *out, int stride, int width, int height)
{
    if (!narrow || !wide || !region || !out || width < 1 || height < 1 || stride < width)
        return;
    for (int y = 0; y < height; y++) {
        const size_t o = (size_t)y * (size_t)stride;
        for (int x = 0; x < width; x++)
            out[o + x] = region[o + x] ? wide[o + x] : narrow[o + x];
    }
}

const uint8_t *pipe_fit_prior(const pipe_fit_band_desc *dp, const kin_camera *cam,
                              const kin_mat4 *world, const kin_arm_rig *rig, unsigned sides,
                              const float speed[2], float max_speed, const float shift[2][2],
                              const uint8_t *kin, const uint8_t *prev, uint8_t *out,
                              int stride)
{
    if (!kin || !prev || !out || !cam || !world || !rig || !speed ||
        stride < cam->width || cam->width < 1 || cam->height < 1)
        return kin;
    pipe_fit_band_desc d = dp ? *dp : pipe_fit_band_desc_default();
    if (!(d.reach >= 0.0f) || !(d.hand_radius >= 0.0f)) return kin;
    const int W = cam->width, H = cam->height;
    int any = 0;
    for (int k = 0; k < 2; k++) {
        if (!(sides & (1u << k)) || !(speed[k] < max_speed)) continue;
        disc D[KIN_RIG_SIDE_JOINTS];
        const int n = side_discs(&d, cam, world, rig, k, 0, D);
        if (n <= 0) continue;
        int sx = 0, sy = 0;
        if (shift && isfinite(shift[k][0]) && isfinite(shift[k][1]) &&
            fabsf(shift[k][0]) < (float)W && fabsf(shift[k][1]) < (float)H) {
            sx = (int)lrintf(shift[k][0]);
            sy = (int)lrintf(shift[k][1]);
        }
        for (int y = 0; y < H; y++) {
            int x0, x1;
            if (!row_span(D, n, y, W, &x0, &x1)) continue;
            const int ys = y - sy;
            if (ys < 0 || ys >= H) continue;   /* kin stays */
            /* the source columns inside the image */
            if (x0 - sx < 0) x0 = sx;
            if (x1 - sx >= W) x1 = W - 1 + sx;
            if (x0 > x1) continue;
            if (!any) {
                for (int yy = 0; yy < H; yy++)
                    memcpy(out + (size_t)yy * (size_t)stride, kin + (size_t)yy * (size_t)stride,
                           (size_t)W);
                any = 1;
            }
            memcpy(out + (size_t)y * (size_t)stride + (size_t)x0,
                   prev + (size_t)ys * (size_t)stride + (size_t)(x0 - sx), (size_t)(x1 - x0 + 1));
        }
    }
    return any ? out : kin;
}

/* The colour check of both functions below: every pixel of out at >= 128
 * that the rule keeps a candidate (prior: on the rim, a 4-neighbour 0;
 * refined: added to in, at most 2 of its 4 neighbours set) and whose
 * colour the model calls background (llr <= 0) is cleared. Cleared pixels
 * are 1 until the end: still set for their neighbours' tests, below 128
 * for the refinement. Returns the count cleared. */

#define B01 0x0101010101010101ull
#define B80 0x8080808080808080ull

static long colour_clear(const fuse_colour_model *g, const fuse_image *P, const uint8_t *in,
                         uint8_t *out, int stride)
{
    if (!g || !g->llr || g->fg_samples <= 0 || g->bg_samples <= 0 || g->bits < 2 ||
        g->bits > 6 || !P || !P->pixels || !out || P->width < 1 || P->height < 1 ||
        stride < P->width || P->stride < 4 * P->width)
        return 0;
    const int W = P->width, H = P->height, bits = g->bits, sh = 8 - bits;
    long n = 0;
    /* the box of the cleared pixels (for the second pass) */
    int cx0 = W, cx1 = 0, cy0 = H, cy1 = 0;
    for (int y = 0; y < H; y++) {
        const uint8_t *s = P->pixels + (size_t)y * (size_t)P->stride;
        const uint8_t *i = in ? in + (size_t)y * (size_t)stride : NULL;
        uint8_t *o = out + (size_t)y * (size_t)stride;
        const uint8_t *up = y > 0 ? o - stride : NULL, *dn = y + 1 < H ? o + stride : NULL;
        /* the blocks of 8 (from column 0) that hold a set byte of out:
         * the others have nothing to test (clearing turns set bytes into
         * 1, still set, so the span holds while the row is worked) */
        const int first = ef_row_first_set(o, 0, W);
        if (first == W) continue;
        const int last = ef_row_last_set(o, first, W);
        const long n_row = n;
        for (int x0 = first & ~7; x0 < last; x0 += 8) {
            /* 8 pixels at a time past those that cannot be tested (out
             * below 128, or in at >= 128); the bytes from x0 on are not
             * written yet */
            if (x0 + 8 <= W) {
                const uint64_t t = i ? ef_ld8(o + x0) & ~ef_ld8(i + x0) : ef_ld8(o + x0);
                if (!(t & B80)) continue;
                /* prior: inside the mask, with every 4-neighbour set (no
                 * zero byte in the block, the row above and below, nor
                 * beside it), no pixel is on the rim */
                if (!i && x0 > 0 && x0 + 8 < W && up && dn && o[x0 - 1] && o[x0 + 8] &&
                    !ef_has_zero8(ef_ld8(o + x0)) && !ef_has_zero8(ef_ld8(up + x0)) && !ef_has_zero8(ef_ld8(dn + x0)))
                    continue;
            }
            const int x1 = x0 + 8 < W ? x0 + 8 : W;
            for (int x = x0; x < x1; x++) {
                if (o[x] < 128 || (i && i[x] >= 128)) continue;
                const int nb = (x > 0 && o[x - 1]) + (x + 1 < W && o[x + 1]) + (up && up[x]) +
                               (dn && dn[x]);
                const int border = (x > 0) + (x + 1 < W) + (up != NULL) + (dn != NULL);
                const int candidate = i ? nb <= 2 : nb < border;
                if (!candidate) continue;
                const uint8_t *px = s + 4 * x;
                const unsigned bin = ((unsigned)(px[0] >> sh) << (2 * bits)) |
                                     ((unsigned)(px[1] >> sh) << bits) | (unsigned)(px[2] >> sh);
                if (g->llr[bin] <= 0.0f) {
                    o[x] = 1;
                    n++;
                    if (x < cx0) cx0 = x;
                    if (x >= cx1) cx1 = x + 1;
                }
            }
        }
        if (n != n_row) {
            if (y < cy0) cy0 = y;
            cy1 = y + 1;
        }
    }
    /* the marks (1) back to 0 over their box, 8 at a time from its first
     * column */
    for (int y = cy0; y < cy1; y++) {
        uint8_t *o = out + (size_t)y * (size_t)stride;
        int x = cx0;
        for (; x + 8 <= cx1; x += 8) {
            /* no byte equal to 1: none of (v ^ 0x01..) is zero */
            if (!ef_has_zero8(ef_ld8(o + x) ^ B01)) continue;
            for (int k = x; k < x + 8; k++)
                if (o[k] == 1) o[k] = 0;
        }
        for (; x < cx1; x++)
            if (o[x] == 1) o[x] = 0;
    }
    return n;
}

long pipe_fit_prior_colour(const fuse_colour_model *g, const fuse_image *P, uint8_t *prior,
                           int stride)
{
    return colour_clear(g, P, NULL, prior, stride);
}

long pipe_fit_refined_colour(const fuse_colour_model *g, const fuse_image *P, const uint8_t *in,
                             uint8_t *out, int stride)
{
    return in ? colour_clear(g, P, in, out, stride) : 0;
}

int pipe_fit_hand_px(const kin_camera *cam, const kin_mat4 *world, const kin_arm_rig *rig,
                     int side, float xy[2])
{
    if (!cam || !world || !rig || !xy || side < 0 || side > 1) return 0;
    double sx = 0.0, sy = 0.0;
    int n = 0;
    for (int j = KIN_RIG_HAND; j < KIN_RIG_SIDE_JOINTS; j++) {
        const int node = rig->joint[side][j];
        if (node < 0) return 0;
        float x, y, z;
        if (!joint_px(cam, &world[node], INFINITY, &x, &y, &z)) continue;
        sx += x;
        sy += y;
        n++;
    }
    if (!n) return 0;
    xy[0] = (float)(sx / n);
    xy[1] = (float)(sy / n);
    return 1;
}

void pipe_fit_filter_output(const kin_filter *f, double display_t, float v0, float v1,
                            kin_track_sample *out, float speed[2])
{
    if (!f || !out) return;
    kin_filter_output(f, display_t, out, NULL);
    float sp[2];
    for (int k = 0; k < 2; k++) {
        /* the filter's parts: head, shoulder L/R, hand L/R, glove L/R */
        const kin_vec3 v = f->part[3 + k].dx;
        sp[k] = sqrtf(v.x * v.x + v.y * v.y + v.z * v.z);
        if (!isfinite(sp[k])) sp[k] = 0.0f;
        if (speed) speed[k] = sp[k];
    }
    if (!f->desc.no_lag_comp || !(v1 > v0)) return;
    kin_filter g = *f;
    g.desc.no_lag_comp = 0;
    kin_track_sample c;
    kin_filter_output(&g, display_t, &c, NULL);
    for (int k = 0; k < 2; k++) {
        const uint32_t bit = k ? KIN_TRACK_HAND_R : KIN_TRACK_HAND_L;
        if (!(out->valid & bit) || !(c.valid & bit)) continue;
        float a = (sp[k] - v0) / (v1 - v0);
        if (!(a > 0.0f)) continue;
        if (a > 1.0f) a = 1.0f;
        const kin_vec3 p = out->hand_pos[k], q = c.hand_pos[k];
        out->hand_pos[k] = kin_v3(p.x + a * (q.x - p.x), p.y + a * (q.y - p.y), p.z + a * (q.z - p.z));
        out->hand_rot[k] = kin_quat_slerp(out->hand_rot[k], c.hand_rot[k], a);
    }
}
