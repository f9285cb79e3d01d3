/* fit_stereo.c - depth from the stereo pair in the refinement
 * (fit_stereo.h). */
#include "fit_stereo.h"

#include <math.h>
#include <string.h>

#include "../fuse/fuse_refine.h"

pipe_fit_stereo_desc pipe_fit_stereo_desc_default(void)
{
    return (pipe_fit_stereo_desc){.radius = 2, .step = 2, .hand_dz = 0.04f, .gap = 0.06f,
                                  .far_m = 3.0f, .min_texture = 4.0f, .margin = 2.0f,
                                  .match = 1.0f, .ratio = 1.0f, .fill_radius = 32, .accept = 0,
                                  .connected = 1};
}

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

size_t pipe_fit_stereo_scratch_size(int width, int height)
{
    if (width < 1 || height < 1 || width > FUSE_MAX_DIM || height > FUSE_MAX_DIM) return 0;
    const size_t n = (size_t)width * (size_t)height;
    /* grey P, grey Q, the filled depth, the test mask, the classes, out
     * as given, the decisions; the depths' plane is then the stack */
    return align16(n) * 2 + align16(n * sizeof(float)) + align16(n) * 4;
}

static void to_grey(const fuse_image *I, uint8_t *g)
{
    for (int y = 0; y < I->height; y++) {
        const uint8_t *s = I->pixels + (size_t)y * (size_t)I->stride;
        uint8_t *o = g + (size_t)y * (size_t)I->width;
        for (int x = 0; x < I->width; x++)
            o[x] = (uint8_t)((77u * s[4 * x] + 150u * s[4 * x + 1] + 29u * s[4 * x + 2]) >> 8);
    }
}

typedef struct st_ctx {
    pipe_fit_stereo_desc d;
    int w, h;
    const uint8_t *gp, *gq;      /* grey images */
    const uint8_t *in;           /* out as given (0/255), w per row */
    const float *dep;            /* filled window depths, w per row */
    float p10, p14;              /* cam's projection: window depth -> distance */
    float fx, fy, cx, cy;        /* cam */
    float ofx, ofy, ocx, ocy;    /* other */
    float M[16];                 /* other.view * cam.world_from_cam */
    long tested, textureless;
} st_ctx;

enum { C_NONE = 0, C_HAND = 1, C_BACK = 2, C_AMBIG = 3 };

/* The other image's position (pixel index, centre at +0) of the point at
 * distance z on pixel (x, y)'s ray; 0 when behind the other camera. */
static int other_px(const st_ctx *c, int x, int y, float z, float *ox, float *oy)
{
    const float a = ((float)x + 0.5f - c->cx) / c->fx * z;
    const float b = -((float)y + 0.5f - c->cy) / c->fy * z;
    const float *M = c->M;
    const float qx = M[0] * a + M[4] * b - M[8] * z + M[12];
    const float qy = M[1] * a + M[5] * b - M[9] * z + M[13];
    const float qz = M[2] * a + M[6] * b - M[10] * z + M[14];
    if (!(-qz > 1e-3f)) return 0;
    *ox = c->ocx + c->ofx * qx / -qz - 0.5f;
    *oy = c->ocy - c->ofy * qy / -qz - 0.5f;
    return 1;
}

/* The smallest mean absolute difference of the patch ref (n x n) along
 * the segment of the other image from the points at distances z0 and z1;
 * -1 when no candidate lies inside the image. */
static float best_cost(const st_ctx *c, const uint8_t *ref, const uint8_t *sup, int cnt, int x,
                       int y, float z0, float z1)
{
    float x0, y0, x1, y1;
    if (!(z0 > 0.0f) || !(z1 > z0)) return -1.0f;
    if (!other_px(c, x, y, z0, &x0, &y0) || !other_px(c, x, y, z1, &x1, &y1)) return -1.0f;
    const int r = c->d.radius, n = 2 * r + 1;
    float len = fmaxf(fabsf(x1 - x0), fabsf(y1 - y0));
    if (len > 4096.0f) len = 4096.0f;
    const int steps = (int)ceilf(len) + 1;
    int best = -1, lx = -99999, ly = -99999;
    for (int k = 0; k < steps; k++) {
        const float t = steps > 1 ? (float)k / (float)(steps - 1) : 0.0f;
        const int qx = (int)floorf(x0 + t * (x1 - x0) + 0.5f);
        const int qy = (int)floorf(y0 + t * (y1 - y0) + 0.5f);
        if (qx == lx && qy == ly) continue;
        lx = qx;
        ly = qy;
        if (qx < r || qy < r || qx >= c->w - r || qy >= c->h - r) continue;
        int s = 0;
        for (int j = 0; j < n; j++) {
            const uint8_t *o = c->gq + (size_t)(qy - r + j) * (size_t)c->w + (qx - r);
            const uint8_t *p = ref + j * n;
            const uint8_t *m = sup + j * n;
            for (int i = 0; i < n; i++) s += (o[i] > p[i] ? o[i] - p[i] : p[i] - o[i]) & m[i];
        }
        if (best < 0 || s < best) best = s;
    }
    return best < 0 ? -1.0f : (float)best / (float)cnt;
}

static int classify(st_ctx *c, int x, int y)
{
    const int r = c->d.radius, n = 2 * r + 1;
    if (x < r || y < r || x >= c->w - r || y >= c->h - r) return C_AMBIG;
    const float wd = c->dep[(size_t)y * (size_t)c->w + x];
    if (!(wd >= 0.0f) || !(wd < 0.99999994f)) return C_AMBIG;   /* no model near */
    const float den = -(2.0f * wd - 1.0f) - c->p10;
    if (den == 0.0f) return C_AMBIG;
    const float z = -(c->p14 / den);
    if (!(z > 0.0f)) return C_AMBIG;
    /* the patch's support: its pixels on the same side of out as the
     * pixel (an edge pixel's patch straddles the hand and what is behind
     * it, which match at different disparities) */
    uint8_t ref[81], sup[81];
    const uint8_t side = c->in[(size_t)y * (size_t)c->w + x];
    int sum = 0, cnt = 0;
    for (int j = 0; j < n; j++) {
        const uint8_t *p = c->gp + (size_t)(y - r + j) * (size_t)c->w + (x - r);
        const uint8_t *m = c->in + (size_t)(y - r + j) * (size_t)c->w + (x - r);
        for (int i = 0; i < n; i++) {
            ref[j * n + i] = p[i];
            sup[j * n + i] = m[i] == side ? 0xff : 0;
            if (m[i] == side) {
                sum += p[i];
                cnt++;
            }
        }
    }
    if (cnt * 2 < n * n) return C_AMBIG;
    const float mean = (float)sum / (float)cnt;
    float tex = 0.0f;
    for (int i = 0; i < n * n; i++)
        if (sup[i]) tex += fabsf((float)ref[i] - mean);
    tex /= (float)cnt;
    c->tested++;
    if (tex < c->d.min_texture) {
        c->textureless++;
        return C_AMBIG;
    }
    const float zn = fmaxf(z - c->d.hand_dz, 0.02f);
    const float ch = best_cost(c, ref, sup, cnt, x, y, zn, z + c->d.hand_dz);
    const float cb = best_cost(c, ref, sup, cnt, x, y, z + c->d.gap,
                               fmaxf(c->d.far_m, z + c->d.gap + 0.01f));
    if (ch < 0.0f || cb < 0.0f) return C_AMBIG;
    if (cb + c->d.margin < ch && cb <= c->d.match * tex && cb <= c->d.ratio * ch) return C_BACK;
    if (ch + c->d.margin < cb && ch <= c->d.match * tex && ch <= c->d.ratio * cb) return C_HAND;
    return C_AMBIG;
}

int pipe_fit_stereo(const pipe_fit_stereo_desc *dp, const kin_camera *cam, const fuse_image *P,
                    const kin_camera *other, const fuse_image *Q, const float *depth,
                    int depth_stride, uint8_t *out, int stride, void *scratch,
                    size_t scratch_size, pipe_fit_stereo_stats *stats)
{
    pipe_fit_stereo_desc d = dp ? *dp : pipe_fit_stereo_desc_default();
    if (stats) memset(stats, 0, sizeof *stats);
    if (!cam || !P || !other || !Q || !depth || !out || !scratch || !P->pixels || !Q->pixels)
        return -1;
    const int w = P->width, h = P->height;
    if (w < 1 || h < 1 || Q->width != w || Q->height != h || P->stride < 4 * w ||
        Q->stride < 4 * w || stride < w || depth_stride < w ||
        scratch_size < pipe_fit_stereo_scratch_size(w, h) || ((uintptr_t)scratch & 15u))
        return -1;
    if (d.radius < 1 || d.radius > 4 || d.step < 1 || d.step > 8 || !(d.hand_dz > 0.0f) ||
        !(d.gap >= d.hand_dz) || !(d.far_m > 0.0f) || !(d.min_texture >= 0.0f) ||
        !(d.margin >= 0.0f) || !(d.match > 0.0f) || !(d.ratio > 0.0f) || d.fill_radius < 1 ||
        d.fill_radius > FUSE_DEPTH_FILL_MAX_RADIUS || d.accept < 0 || d.accept > 64 ||
        !(cam->fx > 0.0f) || !(cam->fy > 0.0f) || !(other->fx > 0.0f) || !(other->fy > 0.0f))
        return -1;
    const size_t n = (size_t)w * (size_t)h;
    uint8_t *gp = (uint8_t *)scratch;
    uint8_t *gq = gp + align16(n);
    float *dep = (float *)(gq + align16(n));
    uint8_t *test = (uint8_t *)dep + align16(n * sizeof(float));
    uint8_t *cls = test + align16(n);
    uint8_t *in = cls + align16(n);
    uint8_t *dec = in + align16(n);

    /* the pixels to test: out, and within accept of it */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            in[(size_t)y * w + x] = test[(size_t)y * w + x] =
                out[(size_t)y * stride + x] >= 128 ? 255 : 0;
    if (d.accept > 0) {
        /* chamfer 1/1 distance to out, capped at accept + 1, in cls */
        const int cap = d.accept + 1;
        for (size_t i = 0; i < n; i++) cls[i] = test[i] ? 0 : (uint8_t)cap;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                int v = cls[(size_t)y * w + x];
                if (x > 0 && cls[(size_t)y * w + x - 1] + 1 < v) v = cls[(size_t)y * w + x - 1] + 1;
                if (y > 0 && cls[(size_t)(y - 1) * w + x] + 1 < v) v = cls[(size_t)(y - 1) * w + x] + 1;
                cls[(size_t)y * w + x] = (uint8_t)v;
            }
        for (int y = h - 1; y >= 0; y--)
            for (int x = w - 1; x >= 0; x--) {
                int v = cls[(size_t)y * w + x];
                if (x < w - 1 && cls[(size_t)y * w + x + 1] + 1 < v) v = cls[(size_t)y * w + x + 1] + 1;
                if (y < h - 1 && cls[(size_t)(y + 1) * w + x] + 1 < v) v = cls[(size_t)(y + 1) * w + x] + 1;
                cls[(size_t)y * w + x] = (uint8_t)v;
                if (v <= d.accept) test[(size_t)y * w + x] = 255;
            }
    }
    for (int y = 0; y < h; y++) memcpy(dep + (size_t)y * w, depth + (size_t)y * depth_stride, sizeof(float) * (size_t)w);
    if (fuse_depth_fill(test, w, dep, w, w, h, d.fill_radius, NULL) < 0) return -1;
    to_grey(P, gp);
    to_grey(Q, gq);

    st_ctx c = { .d = d, .w = w, .h = h, .gp = gp, .gq = gq, .in = in, .dep = dep,
                 .p10 = cam->proj.m[10], .p14 = cam->proj.m[14],
                 .fx = cam->fx, .fy = cam->fy, .cx = cam->cx, .cy = cam->cy,
                 .ofx = other->fx, .ofy = other->fy, .ocx = other->cx, .ocy = other->cy };
    kin_mat4 M = kin_mat4_mul(&other->view, &cam->world_from_cam);
    memcpy(c.M, M.m, sizeof c.M);

    memset(cls, C_NONE, n);
    memset(dec, C_NONE, n);
    const int s = d.step;
    for (int y = 0; y < h; y += s)
        for (int x = 0; x < w; x += s)
            if (test[(size_t)y * w + x]) cls[(size_t)y * w + x] = (uint8_t)classify(&c, x, y);
    /* every pixel's decision: its cell's sample's; the cells beside a cell
     * of another decision are tested at every pixel */
    for (int y0 = 0; y0 < h; y0 += s)
        for (int x0 = 0; x0 < w; x0 += s) {
            const uint8_t k = cls[(size_t)y0 * w + x0];
            if (k != C_BACK && k != C_HAND) continue;
            int border = 0;
            for (int dy = -s; dy <= s && !border && s > 1; dy += s)
                for (int dx = -s; dx <= s; dx += s) {
                    const int xx = x0 + dx, yy = y0 + dy;
                    if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
                    if (cls[(size_t)yy * w + xx] != k) { border = 1; break; }
                }
            const int x1 = x0 + s < w ? x0 + s : w, y1 = y0 + s < h ? y0 + s : h;
            for (int y = y0; y < y1; y++)
                for (int x = x0; x < x1; x++)
                    if (test[(size_t)y * w + x])
                        dec[(size_t)y * w + x] =
                            (uint8_t)(border && (x != x0 || y != y0) ? classify(&c, x, y) : k);
        }
    /* background only where it reaches the outside of out through
     * background (a depth edge inside the hand, a finger over the palm,
     * is not the desk) */
    const uint8_t BACK_OUT = C_BACK | 0x80;
    if (d.connected) {
        int32_t *stack = (int32_t *)dep;   /* the depths are no longer used */
        size_t top = 0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                const size_t i = (size_t)y * w + x;
                if (dec[i] != C_BACK) continue;
                if (x == 0 || y == 0 || x == w - 1 || y == h - 1 || !in[i - 1] || !in[i + 1] ||
                    !in[i - (size_t)w] || !in[i + (size_t)w]) {
                    dec[i] = BACK_OUT;
                    stack[top++] = (int32_t)i;
                }
            }
        while (top > 0) {
            const size_t i = (size_t)stack[--top];
            const int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
            const size_t nb[4] = { i - 1, i + 1, i - (size_t)w, i + (size_t)w };
            const int ok[4] = { x > 0, x < w - 1, y > 0, y < h - 1 };
            for (int k = 0; k < 4; k++)
                if (ok[k] && dec[nb[k]] == C_BACK) {
                    dec[nb[k]] = BACK_OUT;
                    stack[top++] = (int32_t)nb[k];
                }
        }
    } else {
        for (size_t i = 0; i < n; i++)
            if (dec[i] == C_BACK) dec[i] = BACK_OUT;
    }
    long cleared = 0, added = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const uint8_t k = dec[(size_t)y * w + x];
            uint8_t *o = &out[(size_t)y * stride + x];
            if (k == BACK_OUT && *o >= 128) { *o = 0; cleared++; }
            else if (k == C_HAND && *o < 128 && d.accept > 0) { *o = 255; added++; }
        }
    if (stats) {
        stats->tested = c.tested;
        stats->textureless = c.textureless;
        stats->cleared = cleared;
        stats->added = added;
    }
    return 0;
}
