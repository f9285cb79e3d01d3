/* fuse_refine_fast.c - the band-only path of the edge-band refinement
 * (fuse_refine.h), and its portable C row kernels. The result is the
 * scalar reference's (fuse_refine.c), byte for byte, stats included; only
 * the work is restricted to where it can change a byte:
 *
 *   1. the first and last edge pixel of every row (one pass over M);
 *   2. per row a column range that holds every pixel within band + margin
 *      (Chebyshev) of an edge: the chamfer 3-4 distance is >= 3 per pixel
 *      of Chebyshev distance, so every pixel outside these ranges has the
 *      reference's capped distance (band + margin + 1) * 3, and a chamfer
 *      pass restricted to the ranges (reading the cap outside them) gives
 *      the reference's distance inside them (the same minima in the same
 *      order); each chamfer row pass is a vertical minimum (vectorisable)
 *      then a horizontal running minimum (a scan);
 *   3. integer histograms of the learning ring, the log-likelihood table
 *      computed only for the bins that were seen (an empty bin's ratio is
 *      logf(a / a) = 0 exactly, so its entry is the offset), the prior as
 *      a table over the distance (the reference's expression per entry)
 *      and, when g has the same bits, g mixed into the table per bin (the
 *      reference's expression per bin instead of per pixel);
 *   4. scores only around the ranges, in a zero-padded buffer: adding a
 *      zero where the reference's clipped window leaves a term out changes
 *      no sum but the sign of a zero, and the decision is "sum > 0";
 *   5. the window sum per band pixel in the reference's order (rows top
 *      down, columns left to right), so the SIMD lanes give the same
 *      float sums.
 * No allocation: the caller's scratch (fuse_refine_scratch_size) holds the
 * ranges, the distances, the histograms, the tables and the scores. */
#include "fuse_refine_kern.h"

#include <math.h>
#include <string.h>

/* ---------------------------------------------------- portable kernels */

static int edge_span_c(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                       int *x0, int *x1)
{
    int a = -1, b = -1;
    for (int x = 0; x < w; x++)
        if (fuse__refine_edge_at(up, row, dn, w, x)) {
            a = x;
            break;
        }
    if (a < 0) return 0;
    for (int x = w - 1; x >= a; x--)
        if (fuse__refine_edge_at(up, row, dn, w, x)) {
            b = x;
            break;
        }
    *x0 = a;
    *x1 = b;
    return 1;
}

static void dt_init_c(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w, int a,
                      int b, uint16_t cap, uint16_t *d)
{
    for (int x = a; x <= b; x++) d[x] = fuse__refine_edge_at(up, row, dn, w, x) ? 3 : cap;
}

static void dt_fwd_c(uint16_t *r, const uint16_t *u, int w, int a, int b)
{
    if (u)
        for (int x = a; x <= b; x++) r[x] = fuse__refine_vert_px(r, u, w, x);
    for (int x = a > 0 ? a : 1; x <= b; x++)
        r[x] = fuse__refine_min16(r[x], (unsigned)r[x - 1] + 3u);
}

static void dt_bwd_c(uint16_t *r, const uint16_t *dn, int w, int a, int b)
{
    if (dn)
        for (int x = a; x <= b; x++) r[x] = fuse__refine_vert_px(r, dn, w, x);
    for (int x = b + 1 < w ? b : w - 2; x >= a; x--)
        r[x] = fuse__refine_min16(r[x], (unsigned)r[x + 1] + 3u);
}

static unsigned bin_of(const uint8_t *px, int bits)
{
    int s = 8 - bits;
    return ((unsigned)(px[0] >> s) << (2 * bits)) | ((unsigned)(px[1] >> s) << bits) |
           (unsigned)(px[2] >> s);
}

static void hist_row_c(const uint8_t *px, const uint8_t *m, const uint16_t *d, int a, int b,
                       unsigned band3, unsigned outer3, int bits, uint32_t *hf, uint32_t *hb,
                       long *nf, long *nb)
{
    long f = 0, g = 0;
    for (int x = a; x <= b; x++) {
        if (d[x] <= band3 || d[x] > outer3) continue;
        unsigned bin = bin_of(px + 4 * x, bits);
        if (fuse__refine_in(m[x])) { hf[bin]++; f++; }
        else { hb[bin]++; g++; }
    }
    *nf += f;
    *nb += g;
}

static void score_row_c(const fuse__refine_tabs *t, const uint8_t *px, const uint8_t *m,
                        const uint16_t *d, float *s, int a, int b)
{
    for (int x = a; x <= b; x++) {
        const int in = fuse__refine_in(m[x]);
        if (d[x] > t->band3) {
            s[x] = in ? 4.0f : -4.0f;
            continue;
        }
        float c = t->llr[bin_of(px + 4 * x, t->bits)];
        if (t->gllr) c = t->w0 * c + t->gw * t->gllr[bin_of(px + 4 * x, t->gbits)];
        s[x] = c + (in ? t->pr_in[d[x]] : t->pr_out[d[x]]);
    }
}

static void decide_row_c(const float *s, ptrdiff_t ss, int rad, const uint8_t *m,
                         const uint16_t *d, unsigned band3, uint8_t *out, int a, int b,
                         long cnt[3])
{
    for (int x = a; x <= b; x++) {
        const int in = fuse__refine_in(m[x]);
        uint8_t v;
        if (d[x] > band3) {
            v = in ? 255 : 0;
        } else {
            float sum = 0.0f;
            for (int dy = -rad; dy <= rad; dy++) {
                const float *r = s + dy * ss;
                for (int dx = -rad; dx <= rad; dx++) sum += r[x + dx];
            }
            v = sum > 0.0f ? 255 : 0;
            cnt[0]++;
            if (v && !in) cnt[1]++;
            if (!v && in) cnt[2]++;
        }
        out[x] = v;
    }
}

static void binarise_c(const uint8_t *m, uint8_t *out, int a, int b)
{
    for (int x = a; x <= b; x++) out[x] = fuse__refine_in(m[x]) ? 255 : 0;
}

const fuse__refine_kern fuse__refine_kern_c = {
    edge_span_c, dt_init_c, dt_fwd_c, dt_bwd_c, hist_row_c, score_row_c, decide_row_c,
    binarise_c,
};

/* ------------------------------------------------------------- driver */

enum {
    SPY = 3,   /* zero rows above and below the scores (smooth <= 3) */
    SPX = 16,  /* floats left of column 0 (>= 3; keeps column 0 aligned) */
    VPAD = 4   /* the score / valid range: the own range +-4 columns */
};

static size_t align64(size_t n) { return (n + 63u) & ~(size_t)63u; }

typedef struct fast_layout {
    size_t rows, dist, hist, llr, prior, score, total;
    int bins, sstride;
} fast_layout;

static int fast_layout_of(const fuse_refine_params *p, int w, int h, fast_layout *L)
{
    if (!p || w < 1 || h < 1 || w > FUSE_MAX_DIM || h > FUSE_MAX_DIM || p->band < 1 ||
        p->band > 64 || p->bits < 2 || p->bits > 6)
        return 0;
    L->bins = 1 << (3 * p->bits);
    L->sstride = (int)(((size_t)w + 2 * SPX + 15u) & ~(size_t)15u);
    L->rows = 0;   /* 8 ints per row: edge span, own range, valid range, 2 spare */
    L->dist = L->rows + align64((size_t)h * 8u * sizeof(int));
    L->hist = L->dist + align64((size_t)w * (size_t)h * sizeof(uint16_t) + 64u);
    L->llr = L->hist + align64(2u * (size_t)L->bins * sizeof(uint32_t));
    L->prior = L->llr + align64((size_t)L->bins * sizeof(float));
    L->score = L->prior + align64(2u * (3u * 64u + 1u) * sizeof(float));
    L->total = L->score +
               align64((size_t)L->sstride * ((size_t)h + 2u * SPY) * sizeof(float)) + 64u;
    return 1;
}

size_t fuse__refine_fast_scratch(const fuse_refine_params *p, int w, int h)
{
    fast_layout L;
    return fast_layout_of(p, w, h, &L) ? L.total : 0;
}

static int imin(int a, int b) { return a < b ? a : b; }
static int imax(int a, int b) { return a > b ? a : b; }

/* o_lo[y] / o_hi[y] = min / max of lo / hi over rows within r of y, a
 * superset window (blocks of B rows) is fine: a wider range is only more
 * work. Empty rows have lo > hi. blk: 2 * ceil(h / B) ints. */
static void window_span(const int *lo, const int *hi, int h, int r, int *o_lo, int *o_hi,
                        int *blk, int empty_lo)
{
    const int B = r / 4 > 1 ? r / 4 : 1, nb = (h + B - 1) / B;
    int *blo = blk, *bhi = blk + nb;
    for (int j = 0; j < nb; j++) {
        int a = empty_lo, b = -1;
        for (int y = j * B; y < imin(h, (j + 1) * B); y++) {
            a = imin(a, lo[y]);
            b = imax(b, hi[y]);
        }
        blo[j] = a;
        bhi[j] = b;
    }
    for (int y = 0; y < h; y++) {
        int a = empty_lo, b = -1;
        const int j0 = imax(0, y - r) / B, j1 = imin(h - 1, y + r) / B;
        for (int j = j0; j <= j1; j++) {
            a = imin(a, blo[j]);
            b = imax(b, bhi[j]);
        }
        o_lo[y] = a;
        o_hi[y] = b;
    }
}

fuse_result fuse__refine_fast(const fuse__refine_kern *k, const fuse_refine_params *p,
                              const fuse_colour_model *g, float gw, const fuse_image *P,
                              const uint8_t *mask, int mask_stride, uint8_t *out,
                              int out_stride, void *scratch, fuse_refine_stats *stats)
{
    fast_layout L;
    const int w = P->width, h = P->height;
    if (!fast_layout_of(p, w, h, &L)) return FUSE_ERR_ARGS;
    uint8_t *base = scratch;
    int *elo = (int *)(void *)(base + L.rows), *ehi = elo + h;   /* edge span */
    int *lo = ehi + h, *hi = lo + h;                             /* own range */
    int *vlo = hi + h, *vhi = vlo + h;                           /* valid range */
    int *blk = vhi + h;                                          /* 2 h spare */
    uint16_t *dist = (uint16_t *)(void *)(base + L.dist);
    uint32_t *hf = (uint32_t *)(void *)(base + L.hist), *hb = hf + L.bins;
    float *llr = (float *)(void *)(base + L.llr);
    float *pr_in = (float *)(void *)(base + L.prior), *pr_out = pr_in + 3 * 64 + 1;
    float *score = (float *)(void *)(base + L.score);
    const ptrdiff_t ss = L.sstride;
    fuse_refine_stats st;
    memset(&st, 0, sizeof st);

    const int K = p->band + p->margin;
    const unsigned band3 = 3u * (unsigned)p->band;
    const unsigned outer3 = 3u * (unsigned)K;
    const uint16_t cap = (uint16_t)(outer3 + 3u);
#define MROW(y) (mask + (size_t)(y) * (size_t)mask_stride)
#define DROW(y) (dist + (size_t)(y) * (size_t)w)
#define PROW(y) (P->pixels + (size_t)(y) * (size_t)P->stride)
#define OROW(y) (out + (size_t)(y) * (size_t)out_stride)
#define SROW(y) (score + ((size_t)(y) + SPY) * (size_t)ss + SPX)

    /* 1. edge spans */
    int any = 0;
    for (int y = 0; y < h; y++) {
        const uint8_t *row = MROW(y);
        const uint8_t *up = y > 0 ? MROW(y - 1) : row, *dn = y + 1 < h ? MROW(y + 1) : row;
        if (k->edge_span(up, row, dn, w, &elo[y], &ehi[y])) any = 1;
        else { elo[y] = w; ehi[y] = -1; }
    }
    /* 2. own ranges (every pixel within K - 1 of an edge) and valid ranges
     * (own +-VPAD over +-SPY rows: distances initialised, scores made) */
    int y0 = h, y1 = -1;   /* rows with an own range */
    if (any) {
        window_span(elo, ehi, h, K - 1, lo, hi, blk, w);
        for (int y = 0; y < h; y++) {
            if (lo[y] > hi[y]) continue;
            lo[y] = imax(0, lo[y] - (K - 1));
            hi[y] = imin(w - 1, hi[y] + (K - 1));
            y0 = imin(y0, y);
            y1 = y;
        }
        for (int y = 0; y < h; y++) {
            int a = w, b = -1;
            for (int j = imax(0, y - SPY); j <= imin(h - 1, y + SPY); j++)
                if (lo[j] <= hi[j]) {
                    a = imin(a, lo[j] - VPAD);
                    b = imax(b, hi[j] + VPAD);
                }
            vlo[y] = imax(0, a);
            vhi[y] = imin(w - 1, b);
        }
    } else {
        for (int y = 0; y < h; y++) {
            lo[y] = vlo[y] = w;
            hi[y] = vhi[y] = -1;
        }
    }

    /* 3. distances: initialised on the valid ranges, passes on the own */
    for (int y = imax(0, y0 - SPY); y <= imin(h - 1, y1 + SPY); y++) {
        if (vlo[y] > vhi[y]) continue;
        const uint8_t *row = MROW(y);
        const uint8_t *up = y > 0 ? MROW(y - 1) : row, *dn = y + 1 < h ? MROW(y + 1) : row;
        k->dt_init(up, row, dn, w, vlo[y], vhi[y], cap, DROW(y));
    }
    for (int y = y0; y <= y1; y++)
        if (lo[y] <= hi[y]) k->dt_fwd(DROW(y), y > 0 ? DROW(y - 1) : NULL, w, lo[y], hi[y]);
    for (int y = y1; y >= y0; y--)
        if (lo[y] <= hi[y])
            k->dt_bwd(DROW(y), y + 1 < h ? DROW(y + 1) : NULL, w, lo[y], hi[y]);

    /* 4. histograms of the learning ring */
    memset(hf, 0, 2u * (size_t)L.bins * sizeof(uint32_t));
    for (int y = y0; y <= y1; y++)
        if (lo[y] <= hi[y])
            k->hist_row(PROW(y), MROW(y), DROW(y), lo[y], hi[y], band3, outer3, p->bits, hf, hb,
                        &st.fg_samples, &st.bg_samples);
    st.used_colour = st.fg_samples >= p->min_samples && st.bg_samples >= p->min_samples;

    if (!st.used_colour) {
        for (int y = 0; y < h; y++) k->binarise(MROW(y), OROW(y), 0, w - 1);
        if (stats) *stats = st;
        return FUSE_OK;
    }

    /* 5. tables: colour term per bin (the reference's expressions) */
    {
        const float a = 4.0f / (float)L.bins;
        float nf = (float)st.fg_samples + a * (float)L.bins;
        float nb = (float)st.bg_samples + a * (float)L.bins;
        float off = logf(nb) - logf(nf);
        for (int b = 0; b < L.bins; b++)
            llr[b] = (hf[b] | hb[b]) ? logf(((float)hf[b] + a) / ((float)hb[b] + a)) + off
                                     : off;
    }
    fuse__refine_tabs t;
    t.llr = llr;
    t.gllr = NULL;
    t.w0 = 1.0f - gw;
    t.gw = gw;
    t.bits = p->bits;
    t.gbits = g ? g->bits : p->bits;
    if (g && g->bits == p->bits) {
        for (int b = 0; b < L.bins; b++) llr[b] = t.w0 * llr[b] + gw * g->llr[b];
    } else if (g) {
        t.gllr = g->llr;
    }
    for (unsigned dd = 0; dd <= band3; dd++) {
        pr_in[dd] = p->prior * (1.0f - 0.75f * ((float)dd - 3.0f) / (float)band3);
        pr_out[dd] = -pr_in[dd];
    }
    t.pr_in = pr_in;
    t.pr_out = pr_out;
    t.band3 = band3;

    /* 6. scores on the valid ranges, zeros around the image */
    const int rad = p->smooth;
    const int sy0 = imax(0, y0 - SPY), sy1 = imin(h - 1, y1 + SPY);
    if (y0 - rad < 0) memset(score, 0, (size_t)ss * SPY * sizeof(float));
    if (y1 + rad >= h) memset(SROW(h) - SPX, 0, (size_t)ss * SPY * sizeof(float));
    for (int y = sy0; y <= sy1; y++) {
        if (vlo[y] > vhi[y]) continue;
        float *s = SROW(y);
        if (vlo[y] == 0) memset(s - SPY, 0, SPY * sizeof(float));
        if (vhi[y] == w - 1) memset(s + w, 0, SPY * sizeof(float));
        k->score_row(&t, PROW(y), MROW(y), DROW(y), s, vlo[y], vhi[y]);
    }

    /* 7. decision in the own ranges, M elsewhere */
    long cnt[3] = { 0, 0, 0 };
    for (int y = 0; y < h; y++) {
        if (lo[y] > hi[y]) {
            k->binarise(MROW(y), OROW(y), 0, w - 1);
            continue;
        }
        if (lo[y] > 0) k->binarise(MROW(y), OROW(y), 0, lo[y] - 1);
        k->decide_row(SROW(y), ss, rad, MROW(y), DROW(y), band3, OROW(y), lo[y], hi[y], cnt);
        if (hi[y] < w - 1) k->binarise(MROW(y), OROW(y), hi[y] + 1, w - 1);
    }
#undef MROW
#undef DROW
#undef PROW
#undef OROW
#undef SROW
    st.band_pixels = cnt[0];
    st.flipped_in = cnt[1];
    st.flipped_out = cnt[2];
    if (stats) *stats = st;
    return FUSE_OK;
}
