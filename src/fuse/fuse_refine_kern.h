/* fuse_refine_kern.h - the row kernels of the band-only refinement path
 * (fuse_refine_fast.c), shared by the portable C kernels and the SIMD
 * files fuse_refine_avx2.c / fuse_refine_avx512.c. Not public API.
 *
 * Every kernel gives the bytes of the scalar reference in fuse_refine.c
 * (the same integer rules, the same float operations in the same order):
 * tests/test_fuse_refine.c compares each path with the reference.
 *
 * Conventions: a row range [a, b] is inclusive, 0 <= a <= b < w. The
 * mask rows are bytes, inside = >= 128. `up` / `dn` are the rows above and
 * below (the row itself at the image border: no neighbour, no edge). */
#ifndef EGOFUSE_FUSE_REFINE_KERN_H
#define EGOFUSE_FUSE_REFINE_KERN_H

#include <stddef.h>
#include <stdint.h>

#include "fuse_refine.h"

/* What the score kernel reads (fuse_refine_fast.c fills it per call). */
typedef struct fuse__refine_tabs {
    const float *llr;     /* per bin of `bits`: colour term (with g mixed in
                           * already when g has the same bits) */
    const float *gllr;    /* NULL, or g's table when g->bits != bits */
    float w0, gw;         /* c = w0 * llr + gw * gllr (gllr only) */
    int bits, gbits;
    const float *pr_in;   /* prior inside M by distance d (0..band3) */
    const float *pr_out;  /* the negative: outside M */
    unsigned band3;       /* band pixels: d <= band3 */
} fuse__refine_tabs;

typedef struct fuse__refine_kern {
    /* The first and last edge pixel of a row (a pixel with a 4-neighbour
     * of the other class); 0 when the row has none. */
    int (*edge_span)(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                     int w, int *x0, int *x1);
    /* d[x] = edge ? 3 : cap on [a, b]. */
    void (*dt_init)(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                    int w, int a, int b, uint16_t cap, uint16_t *d);
    /* Forward chamfer pass on [a, b] of row r (u: the row above, NULL on
     * the first row); r[a - 1] (when a > 0) and u[a - 1 .. b + 1] hold
     * valid values (the AVX-512 kernel does not read r[a - 1] / r[b + 1]:
     * right where they hold the cap, as the driver's rows do outside
     * [a, b]; the others read them). */
    void (*dt_fwd)(uint16_t *r, const uint16_t *u, int w, int a, int b);
    /* Backward pass, dn the row below (NULL on the last row). */
    void (*dt_bwd)(uint16_t *r, const uint16_t *dn, int w, int a, int b);
    /* Colour histograms of the pixels with band3 < d <= outer3 on [a, b];
     * adds the counts to *nf, *nb. */
    void (*hist_row)(const uint8_t *px, const uint8_t *m, const uint16_t *d,
                     int a, int b, unsigned band3, unsigned outer3, int bits,
                     uint32_t *hf, uint32_t *hb, long *nf, long *nb);
    /* Scores on [a, b]: d <= band3: colour + prior, else +-4. */
    void (*score_row)(const fuse__refine_tabs *t, const uint8_t *px,
                      const uint8_t *m, const uint16_t *d, float *s, int a, int b);
    /* Decision on [a, b]: band pixels by the sign of the window sum of the
     * scores (s: the score row of this row, sstride floats per row, zero
     * padded around the image), the others keep M. cnt[0] += band pixels,
     * cnt[1] += flipped in, cnt[2] += flipped out. */
    void (*decide_row)(const float *s, ptrdiff_t sstride, int rad, const uint8_t *m,
                       const uint16_t *d, unsigned band3, uint8_t *out, int a, int b,
                       long cnt[3]);
    /* out[x] = m[x] >= 128 ? 255 : 0 on [a, b]. */
    void (*binarise)(const uint8_t *m, uint8_t *out, int a, int b);
} fuse__refine_kern;

/* Scalar rules shared by the portable kernels and the SIMD files' row
 * ends (the reference's, fuse_refine.c). */

/* A mask byte is inside when >= 128. */
static inline int fuse__refine_in(uint8_t v) { return v >= 128; }

/* Pixel x is an edge pixel: a 4-neighbour of the other class (none left
 * of x = 0 or right of x = w - 1; up / dn are the row itself at the
 * image border). */
static inline int fuse__refine_edge_at(const uint8_t *up, const uint8_t *row,
                                       const uint8_t *dn, int w, int x)
{
    const int in = fuse__refine_in(row[x]);
    return (x > 0 && fuse__refine_in(row[x - 1]) != in) ||
           (x + 1 < w && fuse__refine_in(row[x + 1]) != in) ||
           fuse__refine_in(up[x]) != in || fuse__refine_in(dn[x]) != in;
}

static inline uint16_t fuse__refine_min16(uint16_t a, unsigned b)
{
    return b < a ? (uint16_t)b : a;
}

/* The vertical part of a chamfer row pass at x: min(r[x], v[x] + 3,
 * v[x - 1] + 4, v[x + 1] + 4), v the row above (forward) or below
 * (backward), the neighbours only inside [0, w). */
static inline uint16_t fuse__refine_vert_px(const uint16_t *r, const uint16_t *v, int w, int x)
{
    uint16_t m = fuse__refine_min16(r[x], (unsigned)v[x] + 3u);
    if (x > 0) m = fuse__refine_min16(m, (unsigned)v[x - 1] + 4u);
    if (x + 1 < w) m = fuse__refine_min16(m, (unsigned)v[x + 1] + 4u);
    return m;
}

/* The portable C kernels (every machine); the SIMD files call them for
 * the parts of a row their vectors do not cover. */
extern const fuse__refine_kern fuse__refine_kern_c;
/* The SIMD kernels; NULL when this build has no such path. */
const fuse__refine_kern *fuse__refine_kern_avx2(void);
const fuse__refine_kern *fuse__refine_kern_avx512(void);
const fuse__refine_kern *fuse__refine_kern_neon(void);   /* aarch64 */

/* The band-only path with kernels k. Arguments checked by the caller. */
fuse_result fuse__refine_fast(const fuse__refine_kern *k, const fuse_refine_params *p,
                              const fuse_colour_model *g, float gw, const fuse_image *P,
                              const uint8_t *mask, int mask_stride, uint8_t *out,
                              int out_stride, void *scratch, fuse_refine_stats *stats);

/* Bytes of scratch the band-only path needs (0 when invalid). */
size_t fuse__refine_fast_scratch(const fuse_refine_params *p, int w, int h);

#endif
