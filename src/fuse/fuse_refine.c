/* fuse_refine.c - skin-colour key and edge-band colour refinement of the
 * kinematic mask (fuse_refine.h). */
#include "fuse_refine.h"
#include "fuse_refine_kern.h"

#include <math.h>
#include <string.h>

/* ------------------------------------------------------- skin-colour key */

fuse_skin_params fuse_skin_params_default(void)
{
    return (fuse_skin_params){ .mean_cb = 117.4316f, .mean_cr = 156.5599f,
                               .cov = { 160.1301f, 12.1430f, 299.4574f },
                               .max_dist2 = 2.5f, .min_luma = 40.0f, .max_luma = 250.0f };
}

static int image_ok(const fuse_image *P)
{
    return P && P->pixels && P->width > 0 && P->height > 0 &&
           P->width <= FUSE_MAX_DIM && P->height <= FUSE_MAX_DIM &&
           P->stride >= 4 * P->width;
}

fuse_result fuse_skin_key(const fuse_skin_params *p, const fuse_image *P,
                          uint8_t *out, int out_stride)
{
    if (!p || !image_ok(P) || !out || out_stride < P->width) return FUSE_ERR_ARGS;
    double a = p->cov[0], b = p->cov[1], c = p->cov[2];
    double det = a * c - b * b;
    if (!(a > 0.0) || !(det > 0.0) || !(p->max_dist2 > 0.0f) ||
        !isfinite(p->mean_cb) || !isfinite(p->mean_cr) || !isfinite(det))
        return FUSE_ERR_ARGS;
    /* inverse covariance */
    float ia = (float)(c / det), ib = (float)(-b / det), ic = (float)(a / det);
    for (int y = 0; y < P->height; y++) {
        const uint8_t *s = P->pixels + (size_t)y * (size_t)P->stride;
        uint8_t *o = out + (size_t)y * (size_t)out_stride;
        for (int x = 0; x < P->width; x++) {
            float r = s[4 * x], g = s[4 * x + 1], bl = s[4 * x + 2];
            float Y = 0.299f * r + 0.587f * g + 0.114f * bl;
            float cb = 128.0f - 0.168736f * r - 0.331264f * g + 0.5f * bl;
            float cr = 128.0f + 0.5f * r - 0.418688f * g - 0.081312f * bl;
            float u = cb - p->mean_cb, v = cr - p->mean_cr;
            float d2 = ia * u * u + 2.0f * ib * u * v + ic * v * v;
            o[x] = (d2 <= p->max_dist2 && Y >= p->min_luma && Y <= p->max_luma)
                       ? 255 : 0;
        }
    }
    return FUSE_OK;
}

/* ------------------------------------------------- edge-band refinement */

fuse_refine_params fuse_refine_params_default(void)
{
    return (fuse_refine_params){.band = 16, .margin = 8, .bits = 4, .prior = 1.0f, .smooth = 1,
                                .min_samples = 64};
}

static int params_ok(const fuse_refine_params *p)
{
    return p && p->band >= 1 && p->band <= 64 && p->margin >= 1 &&
           p->margin <= 64 && p->bits >= 2 && p->bits <= 6 &&
           p->prior >= 0.0f && p->prior <= 1.0e3f && p->min_samples >= 1 &&
           p->smooth >= 0 && p->smooth <= 3;
}

static size_t align16(size_t n) { return (n + 15u) & ~(size_t)15u; }

/* Layout of the scratch memory. */
typedef struct layout {
    size_t dist, hist, llr, score, total;
    int bins;
} layout;

static int layout_of(const fuse_refine_params *p, int w, int h, layout *L)
{
    if (!params_ok(p) || w < 1 || h < 1 || w > FUSE_MAX_DIM || h > FUSE_MAX_DIM)
        return 0;
    size_t px = (size_t)w * (size_t)h;
    L->bins = 1 << (3 * p->bits);
    L->dist = 0;
    L->hist = L->dist + align16(px * sizeof(uint16_t));
    L->llr = L->hist + align16(2u * (size_t)L->bins * sizeof(uint32_t));
    L->score = L->llr + align16((size_t)L->bins * sizeof(float));
    L->total = L->score + align16(px * sizeof(float));
    return 1;
}

size_t fuse_refine_scratch_size(const fuse_refine_params *p, int width,
                                int height)
{
    layout L;
    if (!layout_of(p, width, height, &L)) return 0;
    size_t f = fuse__refine_fast_scratch(p, width, height);
    return f > L.total ? f : L.total;
}

static uint16_t min16(uint16_t a, unsigned b)
{
    return b < a ? (uint16_t)b : a;
}

/* Chamfer 3-4 distance (thirds of a pixel) to the mask's edge, capped. */
static void edge_distance(const uint8_t *m, int ms, int w, int h, uint16_t *d,
                          uint16_t cap)
{
    for (int y = 0; y < h; y++) {
        const uint8_t *row = m + (size_t)y * (size_t)ms;
        for (int x = 0; x < w; x++) {
            int in = row[x] >= 128;
            int edge = (x > 0 && (row[x - 1] >= 128) != in) ||
                       (x + 1 < w && (row[x + 1] >= 128) != in) ||
                       (y > 0 && (row[x - (ptrdiff_t)ms] >= 128) != in) ||
                       (y + 1 < h && (row[x + (ptrdiff_t)ms] >= 128) != in);
            d[(size_t)y * (size_t)w + (size_t)x] = edge ? 3 : cap;
        }
    }
    for (int y = 0; y < h; y++) {
        uint16_t *r = d + (size_t)y * (size_t)w, *u = r - w;
        for (int x = 0; x < w; x++) {
            uint16_t v = r[x];
            if (x > 0) v = min16(v, (unsigned)r[x - 1] + 3u);
            if (y > 0) {
                v = min16(v, (unsigned)u[x] + 3u);
                if (x > 0) v = min16(v, (unsigned)u[x - 1] + 4u);
                if (x + 1 < w) v = min16(v, (unsigned)u[x + 1] + 4u);
            }
            r[x] = v;
        }
    }
    for (int y = h - 1; y >= 0; y--) {
        uint16_t *r = d + (size_t)y * (size_t)w, *dn = r + w;
        for (int x = w - 1; x >= 0; x--) {
            uint16_t v = r[x];
            if (x + 1 < w) v = min16(v, (unsigned)r[x + 1] + 3u);
            if (y + 1 < h) {
                v = min16(v, (unsigned)dn[x] + 3u);
                if (x + 1 < w) v = min16(v, (unsigned)dn[x + 1] + 4u);
                if (x > 0) v = min16(v, (unsigned)dn[x - 1] + 4u);
            }
            r[x] = v;
        }
    }
}

static unsigned bin_of(const uint8_t *px, int bits)
{
    int s = 8 - bits;
    return ((unsigned)(px[0] >> s) << (2 * bits)) |
           ((unsigned)(px[1] >> s) << bits) | (unsigned)(px[2] >> s);
}

/* The argument checks of every path. */
static int refine_args_ok(const fuse_refine_params *p, const fuse_colour_model *g, float gw,
                          const fuse_image *P, const uint8_t *mask, int mask_stride,
                          const uint8_t *out, int out_stride, const void *scratch,
                          size_t scratch_size)
{
    if (g && (!g->llr || g->bits < 2 || g->bits > 6 || !(gw >= 0.0f) || !(gw <= 1.0f)))
        return 0;
    return image_ok(P) && mask && out && scratch && mask_stride >= P->width &&
           out_stride >= P->width && ((uintptr_t)scratch & 15u) == 0 && params_ok(p) &&
           scratch_size >= fuse_refine_scratch_size(p, P->width, P->height);
}

/* The scalar reference: whole-image passes, the definition of the result
 * (arguments checked by the caller). */
static fuse_result refine(const fuse_refine_params *p, const fuse_colour_model *g, float gw,
                          const fuse_image *P, const uint8_t *mask, int mask_stride,
                          uint8_t *out, int out_stride, void *scratch,
                          fuse_refine_stats *stats)
{
    layout L;
    if (!layout_of(p, P->width, P->height, &L)) return FUSE_ERR_ARGS;
    const int w = P->width, h = P->height;
    uint8_t *base = scratch;
    uint16_t *dist = (uint16_t *)(void *)(base + L.dist);
    uint32_t *hf = (uint32_t *)(void *)(base + L.hist), *hb = hf + L.bins;
    float *llr = (float *)(void *)(base + L.llr);
    float *score = (float *)(void *)(base + L.score);
    fuse_refine_stats st;
    memset(&st, 0, sizeof st);

    const unsigned band3 = 3u * (unsigned)p->band;
    const unsigned outer3 = 3u * (unsigned)(p->band + p->margin);
    edge_distance(mask, mask_stride, w, h, dist, (uint16_t)(outer3 + 3u));

    /* 2. histograms of the certain inside and outside, near the edge */
    memset(hf, 0, 2u * (size_t)L.bins * sizeof(uint32_t));
    for (int y = 0; y < h; y++) {
        const uint8_t *s = P->pixels + (size_t)y * (size_t)P->stride;
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        const uint16_t *d = dist + (size_t)y * (size_t)w;
        for (int x = 0; x < w; x++) {
            if (d[x] <= band3 || d[x] > outer3) continue;
            unsigned b = bin_of(s + 4 * x, p->bits);
            if (m[x] >= 128) { hf[b]++; st.fg_samples++; }
            else { hb[b]++; st.bg_samples++; }
        }
    }
    st.used_colour = st.fg_samples >= p->min_samples &&
                     st.bg_samples >= p->min_samples;

    /* 3. log-likelihood ratio per bin */
    if (st.used_colour) {
        const float a = 4.0f / (float)L.bins;   /* 4 pseudo-samples in all */
        float nf = (float)st.fg_samples + a * (float)L.bins;
        float nb = (float)st.bg_samples + a * (float)L.bins;
        float off = logf(nb) - logf(nf);
        for (int b = 0; b < L.bins; b++)
            llr[b] = logf(((float)hf[b] + a) / ((float)hb[b] + a)) + off;
    }

    /* scores: colour + prior in the band, the model's side (+-4 nats)
     * outside it */
    for (int y = 0; y < h; y++) {
        const uint8_t *s = P->pixels + (size_t)y * (size_t)P->stride;
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        const uint16_t *d = dist + (size_t)y * (size_t)w;
        float *o = score + (size_t)y * (size_t)w;
        for (int x = 0; x < w; x++) {
            int in = m[x] >= 128;
            if (!st.used_colour || d[x] > band3) {
                o[x] = in ? 4.0f : -4.0f;
                continue;
            }
            st.band_pixels++;
            float pr = p->prior *
                       (1.0f - 0.75f * ((float)d[x] - 3.0f) / (float)band3);
            float c = llr[bin_of(s + 4 * x, p->bits)];
            if (g) c = (1.0f - gw) * c + gw * g->llr[bin_of(s + 4 * x, g->bits)];
            o[x] = c + (in ? pr : -pr);
        }
    }
    /* 4. decision: the sign of the score summed over a (2r+1)^2 window,
     * in the band only */
    const int rad = p->smooth;
    for (int y = 0; y < h; y++) {
        const uint16_t *d = dist + (size_t)y * (size_t)w;
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        uint8_t *r = out + (size_t)y * (size_t)out_stride;
        for (int x = 0; x < w; x++) {
            int in = m[x] >= 128;
            uint8_t v;
            if (!st.used_colour || d[x] > band3) {
                v = in ? 255 : 0;
            } else {
                float sum = 0.0f;
                int y0 = y - rad < 0 ? 0 : y - rad, y1 = y + rad >= h ? h - 1 : y + rad;
                int x0 = x - rad < 0 ? 0 : x - rad, x1 = x + rad >= w ? w - 1 : x + rad;
                for (int yy = y0; yy <= y1; yy++) {
                    const float *sr = score + (size_t)yy * (size_t)w;
                    for (int xx = x0; xx <= x1; xx++) sum += sr[xx];
                }
                v = sum > 0.0f ? 255 : 0;
            }
            r[x] = v;
            if (v && !in) st.flipped_in++;
            if (!v && in) st.flipped_out++;
        }
    }
    if (stats) *stats = st;
    return FUSE_OK;
}

ef_isa fuse_refine_isa(ef_isa isa)
{
    if (isa == EF_ISA_REF) return EF_ISA_REF;
    if ((unsigned)isa >= EF_ISA_COUNT) isa = EF_ISA_DEFAULT;
    ef_isa c = ef_isa_choose(isa);
    if (c == EF_ISA_AVX512 && !fuse__refine_kern_avx512()) c = EF_ISA_AVX2;
    if (c == EF_ISA_AVX2 && !fuse__refine_kern_avx2()) c = EF_ISA_SSE2;
    if (c == EF_ISA_NEON && !fuse__refine_kern_neon()) c = EF_ISA_SSE2;
    return c;
}

fuse_result fuse_refine_mask_isa(const fuse_refine_params *p, const fuse_colour_model *g,
                                 float weight, const fuse_image *P, const uint8_t *mask,
                                 int mask_stride, uint8_t *out, int out_stride, void *scratch,
                                 size_t scratch_size, fuse_refine_stats *stats, ef_isa isa)
{
    if (!refine_args_ok(p, g, weight, P, mask, mask_stride, out, out_stride, scratch,
                        scratch_size))
        return FUSE_ERR_ARGS;
    if (!g) weight = 0.0f;
    const fuse__refine_kern *k;
    switch (fuse_refine_isa(isa)) {
    case EF_ISA_REF:
        return refine(p, g, weight, P, mask, mask_stride, out, out_stride, scratch, stats);
    case EF_ISA_AVX512: k = fuse__refine_kern_avx512(); break;
    case EF_ISA_AVX2: k = fuse__refine_kern_avx2(); break;
    case EF_ISA_NEON: k = fuse__refine_kern_neon(); break;
    default: k = &fuse__refine_kern_c; break;
    }
    return fuse__refine_fast(k, p, g, weight, P, mask, mask_stride, out, out_stride, scratch,
                             stats);
}

fuse_result fuse_refine_mask(const fuse_refine_params *p, const fuse_image *P,
                             const uint8_t *mask, int mask_stride,
                             uint8_t *out, int out_stride, void *scratch,
                             size_t scratch_size, fuse_refine_stats *stats)
{
    return fuse_refine_mask_isa(p, NULL, 0.0f, P, mask, mask_stride, out, out_stride, scratch,
                                scratch_size, stats, EF_ISA_DEFAULT);
}

fuse_result fuse_refine_mask_global(const fuse_refine_params *p, const fuse_colour_model *g,
                                    float weight, const fuse_image *P, const uint8_t *mask,
                                    int mask_stride, uint8_t *out, int out_stride,
                                    void *scratch, size_t scratch_size,
                                    fuse_refine_stats *stats)
{
    if (!g) return FUSE_ERR_ARGS;
    return fuse_refine_mask_isa(p, g, weight, P, mask, mask_stride, out, out_stride, scratch,
                                scratch_size, stats, EF_ISA_DEFAULT);
}

/* ----------------------------------------------- global colour model */

size_t fuse_colour_model_scratch_size(int bits)
{
    if (bits < 2 || bits > 6) return 0;
    return 2u * ((size_t)1 << (3 * bits)) * sizeof(uint32_t);
}

unsigned fuse_colour_bin(const uint8_t *rgb, int bits)
{
    return bin_of(rgb, bits);
}

fuse_result fuse_colour_model_learn(fuse_colour_model *cm, const fuse_image *P,
                                    const uint8_t *mask, int mask_stride,
                                    int margin, int step, float clamp,
                                    long min_samples, void *scratch,
                                    size_t scratch_size)
{
    if (!cm || !cm->llr || cm->bits < 2 || cm->bits > 6 || !image_ok(P) || !mask ||
        mask_stride < P->width || margin < 0 || margin > 64 || step < 1 || step > 8 ||
        !(clamp > 0.0f) || min_samples < 1 || !scratch ||
        ((uintptr_t)scratch & 3u) != 0 || scratch_size < fuse_colour_model_scratch_size(cm->bits))
        return FUSE_ERR_ARGS;
    const int w = P->width, h = P->height, bins = 1 << (3 * cm->bits);
    uint32_t *hf = scratch, *hb = hf + bins;
    memset(hf, 0, 2u * (size_t)bins * sizeof(uint32_t));
    long nf = 0, nb = 0;
    for (int y = 0; y < h; y += step) {
        const uint8_t *m = mask + (size_t)y * (size_t)mask_stride;
        const uint8_t *s = P->pixels + (size_t)y * (size_t)P->stride;
        for (int x = 0; x < w; x += step) {
            const uint8_t v = m[x];
            if (v != 0 && v != 255) continue;
            int in = v == 255;
            /* the four neighbours at the margin (clipped to the image) */
            int xl = x - margin < 0 ? 0 : x - margin, xr = x + margin >= w ? w - 1 : x + margin;
            int yu = y - margin < 0 ? 0 : y - margin, yd = y + margin >= h ? h - 1 : y + margin;
            if (m[xl] != v || m[xr] != v || mask[(size_t)yu * (size_t)mask_stride + (size_t)x] != v ||
                mask[(size_t)yd * (size_t)mask_stride + (size_t)x] != v)
                continue;
            unsigned b = bin_of(s + 4 * x, cm->bits);
            if (in) { hf[b]++; nf++; }
            else { hb[b]++; nb++; }
        }
    }
    cm->fg_samples = nf;
    cm->bg_samples = nb;
    if (nf < min_samples || nb < min_samples) {
        memset(cm->llr, 0, (size_t)bins * sizeof(float));
        return FUSE_OK;
    }
    const float a = 4.0f / (float)bins;
    float off = logf((float)nb + 4.0f) - logf((float)nf + 4.0f);
    for (int b = 0; b < bins; b++) {
        float v = logf(((float)hf[b] + a) / ((float)hb[b] + a)) + off;
        cm->llr[b] = v > clamp ? clamp : v < -clamp ? -clamp : v;
    }
    return FUSE_OK;
}
