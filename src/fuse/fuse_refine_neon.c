/* fuse_refine_neon.c - NEON row kernels of the band-only refinement
 * (fuse_refine_kern.h), AArch64 Advanced SIMD (the baseline there: no
 * flag). Same bytes as the reference (tests/test_fuse_refine.c under
 * qemu-aarch64, .ci/run part arm64). The float decision is written on the
 * vector layer (src/cpu/simd_neon.h, 4 lanes); the byte and 16-bit work
 * (edges, chamfer minimum, ring skip, binarising) uses NEON's own 8 x u16 /
 * 16 x u8 lanes, as the AVX2 file does with its epi8/epi16 instructions
 * (the layer has no unsigned 16-bit min or saturating add,
 * docs/portability.md). The scores' table look-ups have no gather on NEON:
 * they go through the portable kernel, as do the row ends, the histogram
 * and the chamfer passes' running minimum:
 *   edges      16 mask pixels per step (any edge: vmaxvq, then the rule);
 *   chamfer    the vertical minimum 8 distances per step;
 *   decision   4 per step, the window sum in the AVX2 file's order.
 * On other targets fuse__refine_kern_neon() returns NULL. */
#include "fuse_refine_kern.h"

#if defined(__aarch64__) && defined(__ARM_NEON)

#include "../cpu/simd_neon.h"

#define KC fuse__refine_kern_c

/* 0xFF where the mask byte is inside (>= 128) */
static inline uint8x16_t in16(const uint8_t *p)
{
    return vcgeq_u8(vld1q_u8(p), vdupq_n_u8(128));
}

/* 0xFF for the edge pixels of the 16 at x; needs 1 <= x and x + 16 < w. */
static inline uint8x16_t edge16(const uint8_t *up, const uint8_t *row, const uint8_t *dn,
                                int x)
{
    const uint8x16_t m = in16(row + x), l = in16(row + x - 1), r = in16(row + x + 1);
    const uint8x16_t u = in16(up + x), d = in16(dn + x);
    return vorrq_u8(vorrq_u8(veorq_u8(m, l), veorq_u8(m, r)),
                    vorrq_u8(veorq_u8(m, u), veorq_u8(m, d)));
}

static int edge_span_neon(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                          int *x0, int *x1)
{
    int a = -1, b = -1;
    for (int x = 0; x < w;) {
        if (x >= 1 && x + 16 < w) {
            if (vmaxvq_u8(edge16(up, row, dn, x))) {
                for (int j = 0; j < 16; j++)
                    if (fuse__refine_edge_at(up, row, dn, w, x + j)) { a = x + j; break; }
                break;
            }
            x += 16;
        } else {
            if (fuse__refine_edge_at(up, row, dn, w, x)) { a = x; break; }
            x++;
        }
    }
    if (a < 0) return 0;
    for (int x = w - 1; x >= a;) {
        if (x - 15 >= 1 && x + 1 < w) {
            if (vmaxvq_u8(edge16(up, row, dn, x - 15))) {
                for (int j = 0; j < 16; j++)
                    if (fuse__refine_edge_at(up, row, dn, w, x - j)) { b = x - j; break; }
                break;
            }
            x -= 16;
        } else {
            if (fuse__refine_edge_at(up, row, dn, w, x)) { b = x; break; }
            x--;
        }
    }
    *x0 = a;
    *x1 = b;
    return 1;
}

static void dt_init_neon(const uint8_t *up, const uint8_t *row, const uint8_t *dn, int w,
                         int a, int b, uint16_t cap, uint16_t *d)
{
    const uint16x8_t vcap = vdupq_n_u16(cap), v3 = vdupq_n_u16(3);
    int x = a;
    if (x < 1) {   /* pixel 0: no left neighbour */
        KC.dt_init(up, row, dn, w, 0, 0, cap, d);
        x = 1;
    }
    for (; x + 15 <= b && x + 16 < w; x += 16) {
        const int8x16_t e = vreinterpretq_s8_u8(edge16(up, row, dn, x));
        const uint16x8_t lo = vreinterpretq_u16_s16(vmovl_s8(vget_low_s8(e)));
        const uint16x8_t hi = vreinterpretq_u16_s16(vmovl_s8(vget_high_s8(e)));
        vst1q_u16(d + x, vbslq_u16(lo, v3, vcap));
        vst1q_u16(d + x + 8, vbslq_u16(hi, v3, vcap));
    }
    if (x <= b) KC.dt_init(up, row, dn, w, x, b, cap, d);
}

/* min(r, v + 3, v[-1] + 4, v[+1] + 4) of 8 lanes at x (1 <= x, x + 8 < w);
 * the saturating add gives the reference's minimum (v + k > 65535 never
 * wins against r <= 65535, nor does 65535) */
static inline void vert8(uint16_t *r, const uint16_t *v, int x)
{
    const uint16x8_t three = vdupq_n_u16(3), four = vdupq_n_u16(4);
    uint16x8_t m = vld1q_u16(r + x);
    m = vminq_u16(m, vqaddq_u16(vld1q_u16(v + x), three));
    m = vminq_u16(m, vqaddq_u16(vld1q_u16(v + x - 1), four));
    m = vminq_u16(m, vqaddq_u16(vld1q_u16(v + x + 1), four));
    vst1q_u16(r + x, m);
}

static void vert_row(uint16_t *r, const uint16_t *v, int w, int a, int b)
{
    int x = a;
    for (; x <= b && x < 1; x++) r[x] = fuse__refine_vert_px(r, v, w, x);
    for (; x + 7 <= b && x + 8 < w; x += 8) vert8(r, v, x);
    for (; x <= b; x++) r[x] = fuse__refine_vert_px(r, v, w, x);
}

static void dt_fwd_neon(uint16_t *r, const uint16_t *u, int w, int a, int b)
{
    if (u) vert_row(r, u, w, a, b);
    KC.dt_fwd(r, NULL, w, a, b);   /* the running minimum */
}

static void dt_bwd_neon(uint16_t *r, const uint16_t *dn, int w, int a, int b)
{
    if (dn) vert_row(r, dn, w, a, b);
    KC.dt_bwd(r, NULL, w, a, b);
}

static void hist_row_neon(const uint8_t *px, const uint8_t *m, const uint16_t *d, int a,
                          int b, unsigned band3, unsigned outer3, int bits, uint32_t *hf,
                          uint32_t *hb, long *nf, long *nb)
{
    /* skip 8 distances at a time that hold no ring pixel:
     * band3 < d <= outer3  <=>  (uint16)(d - band3 - 1) <= outer3 - band3 - 1 */
    const uint16x8_t lo = vdupq_n_u16((uint16_t)(band3 + 1u));
    const uint16x8_t span = vdupq_n_u16((uint16_t)(outer3 - band3 - 1u));
    int x = a;
    while (x <= b) {
        if (x + 7 <= b) {
            const uint16x8_t t = vsubq_u16(vld1q_u16(d + x), lo);
            if (!vmaxvq_u16(vcleq_u16(t, span))) { x += 8; continue; }
            KC.hist_row(px, m, d, x, x + 7, band3, outer3, bits, hf, hb, nf, nb);
            x += 8;
        } else {
            KC.hist_row(px, m, d, x, b, band3, outer3, bits, hf, hb, nf, nb);
            break;
        }
    }
}

static void decide_row_neon(const float *s, ptrdiff_t ss, int rad, const uint8_t *m,
                            const uint16_t *d, unsigned band3, uint8_t *out, int a, int b,
                            long cnt[3])
{
    long nb = 0, fi = 0, fo = 0;
    int x = a;
    for (; x + SIMD_W - 1 <= b; x += SIMD_W) {
        unsigned band = 0, in = 0;
        for (int j = 0; j < SIMD_W; j++) {
            band |= (unsigned)(d[x + j] <= band3) << j;
            in |= (unsigned)(m[x + j] >= 128) << j;
        }
        unsigned v = in;
        if (band) {
            vfloat sum = vf_zero();
            for (int dy = -rad; dy <= rad; dy++) {
                const float *r = s + dy * ss + x;
                for (int dx = -rad; dx <= rad; dx++) sum = vf_add(sum, vf_loadu(r + dx));
            }
            const unsigned pos = vm_bits(vf_gt(sum, vf_zero()));
            v = (in & ~band) | (pos & band);
            nb += __builtin_popcount(band);
            fi += __builtin_popcount(band & pos & ~in);
            fo += __builtin_popcount(band & ~pos & in & SIMD_FULL);
        }
        for (int j = 0; j < SIMD_W; j++) out[x + j] = (v >> j) & 1u ? 255 : 0;
    }
    cnt[0] += nb;
    cnt[1] += fi;
    cnt[2] += fo;
    if (x <= b) KC.decide_row(s, ss, rad, m, d, band3, out, x, b, cnt);
}

static void binarise_neon(const uint8_t *m, uint8_t *out, int a, int b)
{
    int x = a;
    for (; x + 15 <= b; x += 16) vst1q_u8(out + x, in16(m + x));
    if (x <= b) KC.binarise(m, out, x, b);
}

/* the scores: the portable kernel (NEON has no gather for the look-ups) */
static void score_row_neon(const fuse__refine_tabs *t, const uint8_t *px, const uint8_t *m,
                           const uint16_t *d, float *s, int a, int b)
{
    KC.score_row(t, px, m, d, s, a, b);
}

static const fuse__refine_kern kern = {
    edge_span_neon, dt_init_neon, dt_fwd_neon, dt_bwd_neon, hist_row_neon,
    score_row_neon, decide_row_neon, binarise_neon,
};

const fuse__refine_kern *fuse__refine_kern_neon(void) { return &kern; }

#else
const fuse__refine_kern *fuse__refine_kern_neon(void) { return NULL; }
#endif
