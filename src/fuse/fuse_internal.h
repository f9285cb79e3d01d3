/* fuse_internal.h - what the fuse kernels share: the arithmetic rules of
 * docs/fuse.md written once (div255, the reproducible power, the exact
 * source positions), the prepared lighting parameters and the scalar row
 * kernels that define every output byte. A SIMD path includes this header,
 * uses the same constants in the same operation order and must give the
 * same bytes as the row kernels below (docs/fuse.md, "Rounding rules").
 *
 * Names shared across files use the fuse__ prefix; nothing here is public
 * API. */
#ifndef EGOFUSE_FUSE_INTERNAL_H
#define EGOFUSE_FUSE_INTERNAL_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "fuse.h"

/* ---- 8-bit integer rules -------------------------------------------- */

/* round(t / 255) for 0 <= t <= 255 * 255, exact (no ties exist: 255 is
 * odd). The pixman MUL_UN8 trick. */
#define FUSE__DIV255(t) ((((t) + 128u) + (((t) + 128u) >> 8)) >> 8)
/* round(a * b / 255) for 8-bit a, b. */
#define FUSE__MUL_UN8(a, b) FUSE__DIV255((uint32_t)(a) * (uint32_t)(b))

/* Bilinear blend of four 8-bit taps with 8-bit weights fx, fy in 0..255:
 * a b on the upper row, c d on the lower one. Exact, rounds half up. The
 * largest intermediate is 255 * 256 * 256 + 32768 < 2^25. */
static inline uint32_t fuse__bilerp8(uint32_t a, uint32_t b, uint32_t c,
                                     uint32_t d, uint32_t fx, uint32_t fy)
{
    uint32_t top = a * (256u - fx) + b * fx;
    uint32_t bot = c * (256u - fx) + d * fx;
    return (top * (256u - fy) + bot * fy + 32768u) >> 16;
}

/* ---- exact source positions ----------------------------------------- */

/* Source coordinate of the centre of destination pixel i (0 <= i < dst)
 * when src pixels are stretched over dst pixels, in 16.16 fixed point:
 *   pos(i) = floor(((2i + 1) * src - dst) * 65536 / (2 * dst))
 * which is floor(65536 * ((i + 0.5) * src / dst - 0.5)), exactly, then
 * clamped to [0, (src - 1) * 65536]. fuse__axis walks i = 0, 1, 2, ...
 * with an exact quotient/remainder step (no drift, no division per
 * pixel). Needs src, dst in 1..FUSE_MAX_DIM. */
typedef struct fuse__axis {
    int64_t q, r;          /* floor quotient and remainder (0 <= r < den) */
    int64_t den;           /* 2 * dst */
    int64_t step_q, step_r;/* 2 * src * 65536 = step_q * den + step_r */
    int32_t max;           /* (src - 1) << 16 */
} fuse__axis;

static inline void fuse__axis_init(fuse__axis *a, int src, int dst)
{
    int64_t num = ((int64_t)src - dst) * 65536;
    a->den = 2 * (int64_t)dst;
    a->q = num / a->den;
    a->r = num % a->den;
    if (a->r < 0) { a->r += a->den; a->q -= 1; }   /* floor, not trunc */
    a->step_q = (2 * (int64_t)src * 65536) / a->den;
    a->step_r = (2 * (int64_t)src * 65536) % a->den;
    a->max = (int32_t)(src - 1) << 16;
}

/* Clamped 16.16 position of the current pixel. */
static inline int32_t fuse__axis_pos(const fuse__axis *a)
{
    if (a->q < 0) return 0;
    if (a->q > a->max) return a->max;
    return (int32_t)a->q;
}

static inline void fuse__axis_next(fuse__axis *a)
{
    a->q += a->step_q;
    a->r += a->step_r;
    if (a->r >= a->den) { a->r -= a->den; a->q += 1; }
}

/* Direct form of the same position (one int64 division). */
static inline int32_t fuse__src_pos(int i, int src, int dst)
{
    int64_t num = ((int64_t)2 * i + 1) * src - dst;
    int64_t den = 2 * (int64_t)dst;
    int64_t q, r;
    num *= 65536;
    q = num / den;
    r = num % den;
    if (r < 0) q -= 1;
    if (q < 0) return 0;
    if (q > ((int64_t)(src - 1) << 16)) return (int32_t)(src - 1) << 16;
    return (int32_t)q;
}

/* ---- float rules ---------------------------------------------------- */

static inline uint32_t fuse__f2u(float f) { uint32_t u; memcpy(&u, &f, 4); return u; }
static inline float fuse__u2f(uint32_t u) { float f; memcpy(&f, &u, 4); return f; }

/* max(0, v) and clamp to [0, 1]; written with ordered compares, so a NaN
 * gives 0 (none can occur with validated parameters). */
static inline float fuse__max0(float v) { return v > 0.0f ? v : 0.0f; }
static inline float fuse__clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

/* 1/255 as a float (0x3B808081); u8 to [0, 1] is u * FUSE__INV255, a
 * multiplication, not a division (255 * FUSE__INV255 rounds to 1.0f). */
#define FUSE__INV255 (1.0f / 255.0f)

/* t in [0, 255] rounded to the nearest integer, ties to even, as the low 8
 * bits of the float t + 2^23 (whose unit in the last place is 1): one
 * addition, no conversion; the bits are 0x4B000000 | round(t). */
#define FUSE__MAGIC 8388608.0f   /* 2^23 */
static inline uint8_t fuse__round8(float t) { return (uint8_t)fuse__f2u(t + FUSE__MAGIC); }

/* float in [0, 1] to u8: (int)(v * 255 + 0.5), truncation. */
static inline uint8_t fuse__unorm8(float v) { return (uint8_t)(int)(v * 255.0f + 0.5f); }

/* log2 polynomial: log2(m) = t * (L1 + t2 (L3 + t2 (L5 + t2 (L7 + t2 L9))))
 * with t = (m - 1) / (m + 1), m in [sqrt(1/2), sqrt(2)), Lk = 2 / (k ln 2)
 * (the atanh series; |t| <= 0.1716, truncation error < 1e-9). */
#define FUSE__LOG2_C1 2.88539008177792681472f
#define FUSE__LOG2_C3 0.96179669392597560491f
#define FUSE__LOG2_C5 0.57707801635558536294f
#define FUSE__LOG2_C7 0.41219858311113240210f
#define FUSE__LOG2_C9 0.32059889797532520163f
#define FUSE__SQRT2   1.41421356237309504880f
/* exp2 polynomial: 2^f = sum_{n=0..7} En f^n, En = ln2^n / n!, for f in
 * [-0.5, 0.5] (truncation error < 3e-9), evaluated by Horner. */
#define FUSE__EXP2_C0 1.0f
#define FUSE__EXP2_C1 0.69314718055994530942f
#define FUSE__EXP2_C2 0.24022650695910071233f
#define FUSE__EXP2_C3 0.05550410866482157995f
#define FUSE__EXP2_C4 0.00961812910762847716f
#define FUSE__EXP2_C5 0.00133335581464284434f
#define FUSE__EXP2_C6 0.00015403530393381609f
#define FUSE__EXP2_C7 0.00001525273380405984f
/* Below this N.H the specular term is 0 (x^s < 2^-100 for s >= 1). */
#define FUSE__POW_MIN 7.88860905221011805412e-31f   /* 2^-100 */

/* Integer exponents up to this are powers by squaring (fuse__powi01). */
#define FUSE__POW_INT_MAX 64

/* s as the integer exponent of fuse__powi01 when s is an integer in
 * [1, FUSE__POW_INT_MAX], else 0 (the exp2/log2 path). */
static inline int fuse__pow_int(float s)
{
    return s >= 1.0f && s <= (float)FUSE__POW_INT_MAX && s == floorf(s) ? (int)s : 0;
}

/* x^n, n >= 1, by squaring from the lowest bit of n up, in this order:
 *   r = 1, b = x; for each bit of n: if set, r = r * b; b = b * b
 * (the last squaring is not done). IEEE single, correctly rounded
 * multiplies (subnormal results included), so every ISA repeats it. The
 * relative error is below (n - 1) 2^-24 (first order). */
static inline float fuse__powi01(float x, int n)
{
    float r = 1.0f, b = x;
    for (;;) {
        if (n & 1) r = r * b;
        n >>= 1;
        if (n == 0) return r;
        b = b * b;
    }
}

/* x^s for x in [0, 1] (larger x count as 1), s >= 1, in a fixed sequence
 * of IEEE float operations and integer bit operations that every ISA can
 * repeat exactly: an integer s in [1, FUSE__POW_INT_MAX] by squaring
 * (fuse__powi01), any other s as x^s = exp2(s * log2(x)).
 *   x <= 2^-100            -> 0
 *   x >= 1                 -> 1
 *   integer s <= 64        -> fuse__powi01(x, s)
 *   x = 2^e * m, m in [sqrt(1/2), sqrt(2)), e and m from the float's bits
 *   l = (float)e + log2poly(m)          (log2poly above)
 *   y = s * l;  y < -126   -> 0
 *   k = floorf(y + 0.5f);  f = y - k    (exact, |f| <= 0.5)
 *   result = exp2poly(f) * 2^k          (2^k built from bits)
 * Relative error about 1e-6 against pow() for the s in use (the
 * exp2/log2 path: 1.3e-7 (1 + |s log2 x|); squaring: (s - 1) 2^-24). */
static inline float fuse__pow01(float x, float s)
{
    uint32_t bits;
    int e;
    float m, t, t2, p, l, y, k, f;
    if (!(x > FUSE__POW_MIN)) return 0.0f;
    if (x >= 1.0f) return 1.0f;
    if (fuse__pow_int(s)) return fuse__powi01(x, fuse__pow_int(s));
    bits = fuse__f2u(x);
    e = (int)(bits >> 23) - 127;
    m = fuse__u2f((bits & 0x007fffffu) | 0x3f800000u);
    if (m > FUSE__SQRT2) { m = m * 0.5f; e += 1; }
    t = (m - 1.0f) / (m + 1.0f);
    t2 = t * t;
    p = FUSE__LOG2_C9;
    p = p * t2 + FUSE__LOG2_C7;
    p = p * t2 + FUSE__LOG2_C5;
    p = p * t2 + FUSE__LOG2_C3;
    p = p * t2 + FUSE__LOG2_C1;
    l = (float)e + p * t;
    y = s * l;
    if (y < -126.0f) return 0.0f;
    k = floorf(y + 0.5f);
    f = y - k;
    p = FUSE__EXP2_C7;
    p = p * f + FUSE__EXP2_C6;
    p = p * f + FUSE__EXP2_C5;
    p = p * f + FUSE__EXP2_C4;
    p = p * f + FUSE__EXP2_C3;
    p = p * f + FUSE__EXP2_C2;
    p = p * f + FUSE__EXP2_C1;
    p = p * f + FUSE__EXP2_C0;
    return p * fuse__u2f((uint32_t)((int)k + 127) << 23);
}

/* The specular power from the square of the cosine (issue 17): x2 =
 * (N.H)^2 = (N.(L + V))^2 / |L + V|^2 needs no square root and no
 * division of its own, and x^s = (x^2)^(s/2):
 *   x2 <= 2^-100           -> 0
 *   x2 >= 1                -> 1
 *   integer s = n in [1, FUSE__POW_INT_MAX]:
 *       r = n >= 2 ? fuse__powi01(x2, n >> 1) : 1.0f
 *       odd n: r = r * sqrtf(x2)          (1.0f * sqrtf(x2) when n == 1)
 *   any other s: fuse__pow01(x2, s * 0.5f)  (its own rules, exponent s / 2,
 *       which is exact: a halving)
 * n is fuse__pow_int(s). Relative error about (n / 2) 2^-24 plus that of
 * x2 times s / 2 (tested against pow()). */
static inline float fuse__spec01(float x2, float s, int n)
{
    float r;
    if (!(x2 > FUSE__POW_MIN)) return 0.0f;
    if (x2 >= 1.0f) return 1.0f;
    if (n == 0) return fuse__pow01(x2, s * 0.5f);
    r = n >= 2 ? fuse__powi01(x2, n >> 1) : 1.0f;
    if (n & 1) r = r * sqrtf(x2);
    return r;
}

/* ---- prepared lighting ---------------------------------------------- */

/* Lighting parameters after validation: light directions normalised once
 * per call (dir / sqrtf(dot(dir, dir))), the tone and 1/255 folded into
 * the colours (kt_c = tone_c * FUSE__INV255; ambient_t = ambient * kt,
 * color_t = color * kt), everything else copied. */
typedef struct fuse__light_prep {
    int light_count;
    float dir[FUSE_MAX_LIGHTS][3];
    float color[FUSE_MAX_LIGHTS][3];
    float color_t[FUSE_MAX_LIGHTS][3];   /* color[i][c] * kt[c] */
    float ambient[3];
    float ambient_t[3];                  /* ambient[c] * kt[c] */
    float kd, ks, shininess, kf;
    int ipow;                 /* fuse__pow_int(shininess) */
    int c_nonneg;             /* kd, ks, every ambient_t and color_t >= 0 (-0
                               * included): every C[c] >= -0, so the max0 of
                               * clamp01(P_c C[c]) changes no output byte (the
                               * vector kernels skip it; fuse_simd.inl) */
    float tone[3];
    float kt[3];              /* tone[c] * FUSE__INV255 */
    float ifx, ify, cx, cy;   /* 1.0f / fx, 1.0f / fy (one IEEE division) */
    float nifx;               /* -ifx (exact): the view ray's x is -px */
    float mo;                 /* (0.5f - cx) * nifx: -px = (float)x * nifx + mo */
} fuse__light_prep;

/* Validates L and K (docs/fuse.md) and fills *p. FUSE_OK or
 * FUSE_ERR_ARGS. */
fuse_result fuse__light_prepare(const fuse_lighting *L,
                                const fuse_intrinsics *K,
                                fuse__light_prep *p);

/* ---- scalar row kernels (the reference) ------------------------------ */

/* Lights row y of the image: width pixels of P (RGBA8), mask (u8),
 * normal (3 floats each) into out (RGBA8, premultiplied). */
void fuse__light_row_ref(const fuse__light_prep *p, int y, int width,
                         const uint8_t *P, const uint8_t *mask,
                         const float *normal, uint8_t *out);
/* The same for pixels x0 <= x < x1 of the row only (P, mask, normal and
 * out still point at the row's pixel 0). The SIMD paths finish their
 * rows with it. */
void fuse__light_span_ref(const fuse__light_prep *p, int y, int x0, int x1,
                          const uint8_t *P, const uint8_t *mask,
                          const float *normal, uint8_t *out);
/* The same with the normals packed as ef_n10 (src/cpu/ef_n10.h; one
 * uint32_t per pixel, normal at the row's pixel 0): the bytes of
 * fuse__light_span_ref fed the floats ef_n10_unpack gives (bits 30-31
 * ignored, as ef_n10_k does). */
void fuse__light_span_n10_ref(const fuse__light_prep *p, int y, int x0, int x1,
                              const uint8_t *P, const uint8_t *mask,
                              const uint32_t *normal, uint8_t *out);

/* Resamples and composites one output row inside the viewport: q0/q1 are
 * the two source rows (already chosen and clamped), fy the 8-bit row
 * weight, ax the column walk positioned at viewport column 0, sw the
 * source width; v and out point at the viewport's first pixel of the row
 * (out may equal v). */
void fuse__composite_row_ref(const uint8_t *q0, const uint8_t *q1,
                             uint32_t fy, fuse__axis ax, int sw,
                             const uint8_t *v, uint8_t *out, int vw);

/* ---- table-driven composite (the SIMD paths) ------------------------- */

/* Columns per tile of the column table: a viewport wider than this is done
 * in column tiles (the bytes do not depend on the tiling). */
#define FUSE__TILE 2048

/* The column walk of fuse__axis written out for n columns: ix = pos >> 16,
 * fx = (pos >> 8) & 255 of columns c0 .. c0 + n - 1. */
typedef struct fuse__cols {
    int32_t ix[FUSE__TILE];
    int32_t fx[FUSE__TILE];
    /* What fuse__hprep_<isa> adds for that ISA's fuse__hrow (hprep_w its
     * SIMD_W; 0: not prepared, then fuse__hrow goes pixel by pixel), per
     * step of SIMD_W columns from column 0: hbase[k] the first layer pixel
     * of the window of SIMD_W pixels that holds every tap of step k, -1
     * when none does (a gather); hidx0/hidx1 the taps ix, min(ix + 1,
     * sw - 1) of each column, relative to hbase (absolute for a gather);
     * hw the column weights fx as two 16-bit copies per int32, in the
     * layer's block order (2 SIMD_W int32 per step: the low then the high
     * halves of the blocks, as vh_from_u8_lo / hi widen the pixels); hwc
     * the same for the other tap's weight 256 - fx (read as a multiply's
     * operand instead of a subtraction per step). */
    int hprep_w;
    int32_t hbase[FUSE__TILE / 4];
    int32_t hidx0[FUSE__TILE], hidx1[FUSE__TILE];
    int32_t hw[2 * FUSE__TILE], hwc[2 * FUSE__TILE];
} fuse__cols;

/* Fills cols for viewport columns [c0, c0 + n), n <= FUSE__TILE. */
static inline void fuse__cols_fill(fuse__cols *cols, int sw, int vw, int c0, int n)
{
    fuse__axis ax;
    int64_t num;
    int i;
    fuse__axis_init(&ax, sw, vw);
    /* start the walk at column c0: q = floor(((2 c0 + 1) sw - vw) 65536 / (2 vw)) */
    num = (((int64_t)2 * c0 + 1) * sw - vw) * 65536;
    ax.q = num / ax.den;
    ax.r = num % ax.den;
    if (ax.r < 0) { ax.r += ax.den; ax.q -= 1; }
    for (i = 0; i < n; i++, fuse__axis_next(&ax)) {
        const int32_t p = fuse__axis_pos(&ax);
        cols->ix[i] = p >> 16;
        cols->fx[i] = (int32_t)(((uint32_t)p >> 8) & 255u);
    }
    cols->hprep_w = 0;
}

/* One output pixel of fuse__composite_row_ref from the table: the same
 * bytes (the all-zero shortcut gives what the formula gives). */
static inline void fuse__composite_px(const uint8_t *q0, const uint8_t *q1,
                                      uint32_t fy, int ix, uint32_t fx, int sw,
                                      const uint8_t *v, uint8_t *out)
{
    const int ix1 = ix + 1 < sw ? ix + 1 : sw - 1;
    const uint8_t *a = q0 + 4 * ix, *b = q0 + 4 * ix1;
    const uint8_t *c = q1 + 4 * ix, *d = q1 + 4 * ix1;
    const uint32_t inv = 255u - fuse__bilerp8(a[3], b[3], c[3], d[3], fx, fy);
    int k;
    for (k = 0; k < 3; k++) {
        uint32_t r = fuse__bilerp8(a[k], b[k], c[k], d[k], fx, fy) +
                     FUSE__DIV255(inv * v[k]);
        out[k] = (uint8_t)(r < 255u ? r : 255u);
    }
    out[3] = 255;
}

/* Composites n output pixels of one row from the table (columns c .. c+n-1
 * of cols, i.e. cols->ix[c..]); v and out point at the first of them. */
typedef void (*fuse__composite_fn)(const uint8_t *q0, const uint8_t *q1,
                                   uint32_t fy, const fuse__cols *cols, int c,
                                   int n, int sw, const uint8_t *v,
                                   uint8_t *out);
/* A row's lighting (fuse__light_row_ref); the ISA paths below are declared
 * by this function type. */
typedef void fuse__light_f(const fuse__light_prep *p, int y, int width, const uint8_t *P,
                           const uint8_t *mask, const float *normal, uint8_t *out);
typedef fuse__light_f *fuse__light_fn;

/* The lighting of pixels x0 <= x < x1 of a row only (pointers at pixel 0),
 * the bytes of fuse__light_span_ref. */
typedef void fuse__light_span_f(const fuse__light_prep *p, int y, int x0, int x1,
                                const uint8_t *P, const uint8_t *mask, const float *normal,
                                uint8_t *out);
typedef fuse__light_span_f *fuse__light_span_fn;
fuse__light_span_f fuse__light_span_sse2, fuse__light_span_avx2, fuse__light_span_avx512,
    fuse__light_span_neon;
/* The same with n10 normals (fuse__light_span_n10_ref's bytes): the
 * lighting kernel of fuse_simd.inl compiled once more per ISA with the
 * n10 loader in place of the float normals' deinterleave. */
typedef void fuse__light_span_n10_f(const fuse__light_prep *p, int y, int x0, int x1,
                                    const uint8_t *P, const uint8_t *mask,
                                    const uint32_t *normal, uint8_t *out);
typedef fuse__light_span_n10_f *fuse__light_span_n10_fn;
fuse__light_span_n10_f fuse__light_span_n10_sse2, fuse__light_span_n10_avx2,
    fuse__light_span_n10_avx512, fuse__light_span_n10_neon;

void fuse__composite_cols_ref(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                              const fuse__cols *cols, int c, int n, int sw,
                              const uint8_t *v, uint8_t *out);

/* The ISA paths (fuse_sse2.c, fuse_avx2.c, fuse_avx512.c). Each gives the
 * bytes of the reference kernels. The table-driven composite per output
 * row is SSE2's; AVX2 and AVX-512 composite through the row cache below. */
fuse__light_f fuse__light_row_sse2, fuse__light_row_avx2, fuse__light_row_avx512;
void fuse__composite_cols_sse2(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                               const fuse__cols *cols, int c, int n, int sw,
                               const uint8_t *v, uint8_t *out);

/* ---- row-cached composite (AVX2, AVX-512) ----------------------------- */

/* The bilinear sum regrouped by rows: with the horizontal taps of layer row
 * r at output column i, h_r = a (256 - fx) + b fx (per channel, <= 65280),
 * the reference's q is (h_iy (256 - fy) + h_iy1 fy + 32768) >> 16, the same
 * exact integer sum. A layer row is read by ~1.9 output rows when the
 * layer is enlarged, so the driver computes h once per layer row (only for
 * the groups that its coverage can reach) and keeps the last two.
 * Stored: h - 32768 as an int16 (h ^ FUSE__H_BIAS as a u16), so that the
 * vertical sum is one signed 16x16 -> 32-bit multiply-add per pair
 * (pmaddwd): (h0 - 32768) w0 + (h1 - 32768) w1 + 32768 * 256 + 32768, with
 * w0 + w1 = 256; every term fits an int32. 4 values per output column in
 * the pixel's channel order (r, g, b, a); the columns of each step of
 * SIMD_W (from a multiple of 16 of the tile: both kernels start every call
 * there) in the vector layer's block order (fuse_simd.inl), the scalar tail
 * too (fuse__hslot: vrow reads it as one more step). Only the hrow and vrow
 * of one ISA read and write it. A layer row without taps there (h = 0)
 * holds FUSE__H_BIAS. */
#define FUSE__H_BIAS 0x8000u

/* Where column i of a call keeps its 4 values (w = SIMD_W, a power of 2):
 * in its step, the block order of vh_from_u8_lo / hi (pixels 4B, 4B + 1 of
 * block B in the step's first 2 w values, 4B + 2, 4B + 3 in the next 2 w). */
static inline int fuse__hslot(int i, int w)
{
    const int k = i & (w - 1);
    return 4 * (i - k) + ((k & 2) ? 2 * w : 0) + 8 * (k >> 2) + 4 * (k & 1);
}

/* h of columns c .. c + n - 1 of cols from layer row q (h points at column
 * c's entry). */
typedef void (*fuse__hrow_fn)(const uint8_t *q, const fuse__cols *cols, int c,
                              int n, int sw, uint16_t *h);
/* The vertical blend of h0 (upper row) and h1 (lower row) with weight fy
 * and the over onto n pixels of V: the bytes of fuse__composite_px. h0 and
 * h1 are read to the end of the last step of SIMD_W columns, past n when n
 * is not a multiple of SIMD_W (the driver's tile arrays hold whole steps). */
typedef void (*fuse__vrow_fn)(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                              const uint8_t *v, uint8_t *out, int n);

/* One column of fuse__hrow_fn. */
static inline void fuse__hpx(const uint8_t *q, int ix, uint32_t fx, int sw, uint16_t *h)
{
    const int ix1 = ix + 1 < sw ? ix + 1 : sw - 1;
    int k;
    for (k = 0; k < 4; k++)
        h[k] = (uint16_t)((q[4 * ix + k] * (256u - fx) + q[4 * ix1 + k] * fx) ^ FUSE__H_BIAS);
}

/* One pixel of fuse__vrow_fn. */
static inline void fuse__vpx(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                             const uint8_t *v, uint8_t *out)
{
    const uint32_t inv = 255u - (((h0[3] ^ FUSE__H_BIAS) * (256u - fy) +
                                  (h1[3] ^ FUSE__H_BIAS) * fy + 32768u) >> 16);
    int k;
    for (k = 0; k < 3; k++) {
        const uint32_t r = (((h0[k] ^ FUSE__H_BIAS) * (256u - fy) +
                             (h1[k] ^ FUSE__H_BIAS) * fy + 32768u) >> 16) +
                           FUSE__DIV255(inv * v[k]);
        out[k] = (uint8_t)(r < 255u ? r : 255u);
    }
    out[3] = 255;
}

/* The ISA's per-step tables of cols (n columns of the tile, layer width
 * sw), once per tile, before its fuse__hrow calls. */
typedef void (*fuse__hprep_fn)(fuse__cols *cols, int n, int sw);
void fuse__hprep_avx2(fuse__cols *cols, int n, int sw);
void fuse__hprep_avx512(fuse__cols *cols, int n, int sw);
void fuse__hrow_avx2(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                     uint16_t *h);
void fuse__hrow_avx512(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                       uint16_t *h);
void fuse__vrow_avx2(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                     const uint8_t *v, uint8_t *out, int n);
void fuse__vrow_avx512(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                       const uint8_t *v, uint8_t *out, int n);

/* ---- coverage and opaque copies (the composite driver, fuse_ctx.c) ---- */

/* Source pixels per coverage bit. fuse__cover_row_* sets bit b of bits
 * (bit b & 63 of word b >> 6) iff a byte of the pixels [8b, min(8b + 8, w))
 * of the layer row q is non-zero, and clears the other bits of the
 * (w + 511) / 512 words. A group of output pixels whose taps all lie in
 * blocks without a bit is fully transparent: R = V with alpha 255, the
 * reference's all-zero shortcut (docs/fuse.md, "Cost model"). */
#define FUSE__COV_BLOCK 8
#define FUSE__COV_WORDS ((FUSE_MAX_DIM / FUSE__COV_BLOCK + 63) / 64)
typedef void (*fuse__cover_fn)(const uint8_t *q, int w, uint64_t *bits);
/* out[i] = v[i] | 0xFF000000 (as RGBA8 pixels: alpha 255) for n pixels.
 * out == v is allowed (in place): then only vectors holding an alpha other
 * than 255 are stored, so an opaque V costs a read and no write. Otherwise
 * out and v do not overlap. */
typedef void (*fuse__opaque_fn)(const uint8_t *v, uint8_t *out, int n);

/* The same when the caller knows that every pixel outside [x0, x1)
 * (0 <= x0, x1 <= w) is 0: only the blocks that meet [x0, x1) are read
 * (the lit rows' mask spans, fuse_ctx.c). Same bits. */
typedef void (*fuse__cover_span_fn)(const uint8_t *q, int w, int x0, int x1, uint64_t *bits);
void fuse__cover_span_ref(const uint8_t *q, int w, int x0, int x1, uint64_t *bits);
void fuse__cover_span_sse2(const uint8_t *q, int w, int x0, int x1, uint64_t *bits);
void fuse__cover_span_avx2(const uint8_t *q, int w, int x0, int x1, uint64_t *bits);
void fuse__cover_span_avx512(const uint8_t *q, int w, int x0, int x1, uint64_t *bits);
void fuse__cover_span_neon(const uint8_t *q, int w, int x0, int x1, uint64_t *bits);
void fuse__cover_row_ref(const uint8_t *q, int w, uint64_t *bits);
void fuse__cover_row_sse2(const uint8_t *q, int w, uint64_t *bits);
void fuse__cover_row_avx2(const uint8_t *q, int w, uint64_t *bits);
void fuse__cover_row_avx512(const uint8_t *q, int w, uint64_t *bits);
void fuse__opaque_ref(const uint8_t *v, uint8_t *out, int n);
void fuse__opaque_sse2(const uint8_t *v, uint8_t *out, int n);
void fuse__opaque_avx2(const uint8_t *v, uint8_t *out, int n);
void fuse__opaque_avx512(const uint8_t *v, uint8_t *out, int n);

/* fuse__pow01 of the ISA paths over an array (for the tests):
 * out[i] = pow01(x[i], s) computed in that path's lanes. */
void fuse__pow01_row_sse2(const float *x, int n, float s, float *out);
void fuse__pow01_row_avx2(const float *x, int n, float s, float *out);
void fuse__pow01_row_avx512(const float *x, int n, float s, float *out);

/* ---- depth test (fuse_depth.c; the rule in fuse.h, "depth test") ----- */

/* The depth test's constants and the exact walk of the scene column
 *   ox(x) = floor((2x + 1) vw / (2 sw))        (from the viewport's left)
 * as quotient and remainder: ox(x + 1) = ox(x) + step_q, rem += step_r,
 * one more when rem reaches den. Every value fits an int32 (vw, sw <=
 * FUSE_MAX_DIM, so (2x + 1) vw < 2^30). */
typedef struct fuse__depth_prep {
    float two_fn, fpn, fmn, offset;   /* (2 zfar) znear, zfar + znear, zfar - znear */
    int32_t vw, den;                  /* vp_w, 2 Q.width */
    int32_t step_q, step_r;           /* 2 vp_w = step_q den + step_r */
} fuse__depth_prep;

void fuse__depth_prepare(const fuse_depth *d, int qw, int vp_w, fuse__depth_prep *p);

/* Column of pixel x: *ox = ox(x), *rem the remainder. */
static inline void fuse__depth_col(const fuse__depth_prep *p, int x, int32_t *ox, int32_t *rem)
{
    const int64_t num = ((int64_t)2 * x + 1) * p->vw;
    *ox = (int32_t)(num / p->den);
    *rem = (int32_t)(num % p->den);
}

/* The depth test of one layer row: q its w RGBA8 pixels (zeroed where the
 * scene is in front), hz the hand's window depths of the row, sc the
 * scene row's distances from the viewport's left edge (scene + oy stride
 * + vp_x0). The ISA paths give the bytes of fuse__depth_row_ref: the same
 * IEEE operations in the same order, ordered compares. */
typedef void fuse__depth_row_f(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                               const float *sc, int w);
typedef fuse__depth_row_f *fuse__depth_fn;
fuse__depth_row_f fuse__depth_row_ref, fuse__depth_row_sse2, fuse__depth_row_avx2,
    fuse__depth_row_avx512;
/* Pixels x0 <= x < x1 of the row only (q, hz, sc still at pixel 0). */
typedef void fuse__depth_span_f(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                                const float *sc, int x0, int x1);
fuse__depth_span_f fuse__depth_span_ref;

/* The same test on a row of the coverage mask before lighting (what
 * fuse_context_frame runs): m holds the w mask bytes of a layer row (a
 * copy: it is written), and every pixel with m != 0 that the scene hides
 * by the rule above gets m = 0. Lighting the result gives the bytes of
 * lighting the mask and then running fuse__depth_row_* on the layer: a
 * hidden pixel is 0 either way, a pixel with M = 0 is 0 and not looked at
 * either way, and the others are lit the same (docs/fuse.md, "Depth"). The
 * ISA paths give the bytes of fuse__depth_mrow_ref. */
typedef fuse__depth_row_f *fuse__depth_mask_fn;     /* q is the mask row m */
fuse__depth_row_f fuse__depth_mrow_ref, fuse__depth_mrow_sse2, fuse__depth_mrow_avx2,
    fuse__depth_mrow_avx512;
/* Pixels x0 <= x < x1 of the mask row only (m, hz, sc at pixel 0): the
 * bytes of fuse__depth_mspan_ref. */
typedef fuse__depth_span_f *fuse__depth_mspan_fn;   /* q is the mask row m */
fuse__depth_span_f fuse__depth_mspan_ref, fuse__depth_mspan_sse2, fuse__depth_mspan_avx2,
    fuse__depth_mspan_avx512, fuse__depth_mspan_neon;

/* The scene row (from the viewport's left edge) that layer row y of a
 * layer sh rows high reads: oy = vp_y0 + floor((2y + 1) vp_h / (2 sh)). */
static inline const float *fuse__depth_scene_row(const fuse_depth *d, int y, int sh, int vp_x0,
                                                 int vp_y0, int vp_h)
{
    const int oy = vp_y0 + (int)(((int64_t)2 * y + 1) * vp_h / (2 * (int64_t)sh));
    return d->scene + (size_t)oy * (size_t)d->scene_stride + vp_x0;
}

/* The depth test's checks, and its rows [y0, y1) with the row kernel fn. */
fuse_result fuse__depth_check(const fuse_depth *d, const fuse_image *Q, int vp_x0,
                              int vp_y0, int vp_w, int vp_h);
void fuse__depth_rows(const fuse_depth *d, const fuse_image *Q, int vp_x0,
                      int vp_y0, int vp_w, int vp_h, int y0, int y1, fuse__depth_fn fn);

/* ---- validation shared by the drivers (fuse_ref.c) ------------------- */

int fuse__image_ok(const fuse_image *im);
int fuse__overlap(const fuse_image *a, const fuse_image *b);
int fuse__same_image(const fuse_image *a, const fuse_image *b);
/* Checks of fuse_light / fuse_composite (fuse.h ERRORS), prep filled.
 * The normals: exactly one of normal (3 floats a pixel, normal_stride
 * floats a row >= 3 width) and normal_n10 (ef_n10, normal_n10_stride
 * uint32_t a row >= width) is not NULL, else FUSE_ERR_ARGS; the stride of
 * the NULL one is not looked at. */
fuse_result fuse__light_check(const fuse_lighting *L, const fuse_intrinsics *K,
                              const fuse_image *P, const uint8_t *mask,
                              int mask_stride, const float *normal,
                              int normal_stride, const uint32_t *normal_n10,
                              int normal_n10_stride, const fuse_image *out,
                              fuse__light_prep *prep);
fuse_result fuse__composite_check(const fuse_image *Q, const fuse_image *V,
                                  int vp_x0, int vp_y0, int vp_w, int vp_h,
                                  const fuse_image *out);

/* Camera formats (fuse_formats.c): converts the first pixels of a YUYV
 * (uyvy 0) or UYVY (uyvy 1) row of width pixels to RGBA8, byte-exact with
 * the reference, and returns how many it did (a multiple of 16); the
 * caller converts the rest. */
int fuse__yuv422_row_avx2(const uint8_t *src, int width, int uyvy, uint8_t *dst);
/* the same written once on the vector layer (fuse_simd.inl, int32 lanes:
 * one pixel pair per lane), for SSE2 and NEON; AVX2 keeps its 16-bit one
 * (16 pixels per madd step), which AVX-512 runs too */
int fuse__yuv422_row_sse2(const uint8_t *src, int width, int uyvy, uint8_t *dst);
int fuse__yuv422_row_neon(const uint8_t *src, int width, int uyvy, uint8_t *dst);

/* NEON (fuse_neon.c: fuse_simd.inl on src/cpu/simd_neon.h; on other
 * targets the reference under these names). The composite: per output
 * row, as SSE2 (no row cache). */
fuse__light_f fuse__light_row_neon;
void fuse__pow01_row_neon(const float *x, int n, float s, float *out);
void fuse__depth_row_neon(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                          const float *sc, int w);
void fuse__depth_mrow_neon(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                           const float *sc, int w);
void fuse__cover_row_neon(const uint8_t *q, int w, uint64_t *bits);
void fuse__composite_cols_neon(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                               const fuse__cols *cols, int c, int n, int sw,
                               const uint8_t *v, uint8_t *out);
void fuse__opaque_neon(const uint8_t *v, uint8_t *out, int n);

#endif
