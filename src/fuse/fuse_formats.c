/* fuse_formats.c - camera formats to RGBA8 with the eq. 1 crop: YUYV,
 * UYVY (BT.601 limited range, integer), GREY, raw Bayer (bilinear
 * demosaic, mirrored borders), RGB24, BGR24. The rules are in fuse.h and
 * docs/fuse.md ("Camera formats"). Scalar and integer: the conversion runs
 * once per camera frame at 640x480 and is far from the per-output-pixel
 * cost of the composite. */
#include "fuse_internal.h"

#include <stddef.h>

int fuse_format_row_bytes(fuse_format f, int width)
{
    switch (f) {
    case FUSE_FMT_YUYV:
    case FUSE_FMT_UYVY:       return 2 * width;
    case FUSE_FMT_GREY:
    case FUSE_FMT_BAYER_RGGB:
    case FUSE_FMT_BAYER_GRBG:
    case FUSE_FMT_BAYER_GBRG:
    case FUSE_FMT_BAYER_BGGR: return width;
    case FUSE_FMT_RGB24:
    case FUSE_FMT_BGR24:      return 3 * width;
    }
    return 0;
}

static uint8_t clamp255(int v)
{
    /* v >= 0 here is floor(v / 256) >= 0, so the clamp comes first */
    if (v < 0) return 0;
    v >>= 8;
    return (uint8_t)(v > 255 ? 255 : v);
}

static void yuv_px(int Y, int U, int V, uint8_t *d)
{
    const int C = Y - 16, D = U - 128, E = V - 128;
    d[0] = clamp255(298 * C + 409 * E + 128);
    d[1] = clamp255(298 * C - 100 * D - 208 * E + 128);
    d[2] = clamp255(298 * C + 516 * D + 128);
    d[3] = 255;
}

/* Colour (0 R, 1 G, 2 B) of frame pixel (x, y) for a pattern whose
 * top-left 2x2 is p[0] p[1] / p[2] p[3]. */
static int bayer_colour(const int p[4], int x, int y)
{
    return p[((y & 1) << 1) | (x & 1)];
}

static int mirror(int i, int n)
{
    if (i < 0) return -i;
    if (i >= n) return 2 * (n - 1) - i;
    return i;
}

static void demosaic_row(const fuse_frame *s, const int pat[4], int y, uint8_t *d)
{
    const int w = s->width, h = s->height;
    const uint8_t *rm = s->data + (size_t)mirror(y - 1, h) * (size_t)s->stride;
    const uint8_t *r0 = s->data + (size_t)y * (size_t)s->stride;
    const uint8_t *rp = s->data + (size_t)mirror(y + 1, h) * (size_t)s->stride;
    int x;
    for (x = 0; x < w; x++, d += 4) {
        const int xm = mirror(x - 1, w), xp = mirror(x + 1, w);
        const int c = bayer_colour(pat, x, y);
        const int cross = (rm[x] + rp[x] + r0[xm] + r0[xp] + 2) >> 2;
        const int diag = (rm[xm] + rm[xp] + rp[xm] + rp[xp] + 2) >> 2;
        const int horiz = (r0[xm] + r0[xp] + 1) >> 1;
        const int vert = (rm[x] + rp[x] + 1) >> 1;
        d[3] = 255;
        if (c == 1) {
            /* green: the row's other colour left/right, the column's up/down */
            const int hc = bayer_colour(pat, x + 1, y);
            d[1] = r0[x];
            d[hc] = (uint8_t)horiz;
            d[2 - hc] = (uint8_t)vert;
        } else {
            d[c] = r0[x];
            d[1] = (uint8_t)cross;
            d[2 - c] = (uint8_t)diag;
        }
    }
}

/* The SIMD part of a YUYV/UYVY row on the chosen path (AVX2's 16-bit
 * kernel from AVX2 up; SSE2 and NEON: fuse_simd.inl on the vector layer);
 * returns the pixels done (the scalar loop does the rest). */
static int yuv_row_fast(ef_isa isa, const uint8_t *r, int width, int uyvy, uint8_t *d)
{
    switch (isa) {
#if defined(__x86_64__) || defined(__i386__)
    case EF_ISA_AVX512:
    case EF_ISA_AVX2: return fuse__yuv422_row_avx2(r, width, uyvy, d);
#endif
    case EF_ISA_SSE2: return fuse__yuv422_row_sse2(r, width, uyvy, d);
    case EF_ISA_NEON: return fuse__yuv422_row_neon(r, width, uyvy, d);
    default: return 0;
    }
}

/* Pixels x .. w-1 (x even) of a YUYV row r (Y0 U Y1 V), or (uy 1) UYVY
 * (U Y0 V Y1): the lumas at uy and 2 + uy; d at pixel 0. */
static inline void yuv422_px(const uint8_t *r, int x, int w, int uy, uint8_t *d)
{
    for (r += 2 * x, d += 4 * x; x < w; x += 2, r += 4, d += 8) {
        yuv_px(r[uy], r[1 - uy], r[3 - uy], d);
        yuv_px(r[2 + uy], r[1 - uy], r[3 - uy], d + 4);
    }
}

fuse_result fuse_frame_to_rgba(const fuse_frame *s, int y0, fuse_image *out)
{
    return fuse_frame_to_rgba_isa(s, y0, out, EF_ISA_DEFAULT);
}

fuse_result fuse_frame_to_rgba_isa(const fuse_frame *s, int y0, fuse_image *out, ef_isa cap)
{
    const ef_isa isa = ef_isa_choose(cap);
    static const int pats[4][4] = {
        { 0, 1, 1, 2 },   /* RGGB */
        { 1, 0, 2, 1 },   /* GRBG */
        { 1, 2, 0, 1 },   /* GBRG */
        { 2, 1, 1, 0 },   /* BGGR */
    };
    int rb, x, y, h;
    if (s == NULL || out == NULL || s->data == NULL || !fuse__image_ok(out))
        return FUSE_ERR_ARGS;
    rb = fuse_format_row_bytes(s->format, s->width);
    if (rb == 0 || s->width < 1 || s->height < 1 || s->width > FUSE_MAX_DIM ||
        s->height > FUSE_MAX_DIM || s->stride < rb)
        return FUSE_ERR_ARGS;
    if ((s->format == FUSE_FMT_YUYV || s->format == FUSE_FMT_UYVY) && (s->width & 1))
        return FUSE_ERR_ARGS;
    if (s->format >= FUSE_FMT_BAYER_RGGB && s->format <= FUSE_FMT_BAYER_BGGR &&
        (s->width < 2 || s->height < 2))
        return FUSE_ERR_ARGS;
    if (s->size < (size_t)(s->height - 1) * (size_t)s->stride + (size_t)rb ||
        out->width != s->width || y0 < 0 || y0 > s->height - out->height)
        return FUSE_ERR_SIZE;
    {
        /* out must not overlap the frame */
        const uintptr_t a0 = (uintptr_t)s->data, a1 = a0 + (size_t)(s->height - 1) * (size_t)s->stride + (size_t)rb;
        const uintptr_t b0 = (uintptr_t)out->pixels,
                        b1 = b0 + (size_t)(out->height - 1) * (size_t)out->stride + 4u * (size_t)out->width;
        if (a0 < b1 && b0 < a1) return FUSE_ERR_ARGS;
    }
    h = out->height;
    for (y = 0; y < h; y++) {
        const uint8_t *r = s->data + (size_t)(y + y0) * (size_t)s->stride;
        uint8_t *d = out->pixels + (size_t)y * (size_t)out->stride;
        switch (s->format) {
        case FUSE_FMT_YUYV:
        case FUSE_FMT_UYVY: {
            const int uy = s->format == FUSE_FMT_UYVY;
            x = yuv_row_fast(isa, r, s->width, uy, d);
            /* a constant uy in each call: the offsets stay immediates */
            if (uy) yuv422_px(r, x, s->width, 1, d);
            else yuv422_px(r, x, s->width, 0, d);
            break;
        }
        case FUSE_FMT_GREY:
            for (x = 0; x < s->width; x++, d += 4) {
                d[0] = d[1] = d[2] = r[x];
                d[3] = 255;
            }
            break;
        case FUSE_FMT_RGB24:
        case FUSE_FMT_BGR24: {
            const int sw = s->format == FUSE_FMT_BGR24 ? 2 : 0;
            for (x = 0; x < s->width; x++, r += 3, d += 4) {
                d[0] = r[sw];
                d[1] = r[1];
                d[2] = r[2 - sw];
                d[3] = 255;
            }
            break;
        }
        default:
            demosaic_row(s, pats[s->format - FUSE_FMT_BAYER_RGGB], y + y0, d);
            break;
        }
    }
    return FUSE_OK;
}
