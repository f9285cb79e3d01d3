/* io_pixfmt.c - camera pixel formats (io_dev.h): the fourcc names, the
 * minimum stride and image size of each format, and the conversion of a
 * frame in any of them to RGBA8 (io_frame_to_rgba). Split from io_v4l2.c,
 * which keeps the cameras, their stereo pairing and the V4L2 backend. */
#include "io_dev.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ================================================================ formats */

const char *io_fourcc_str(uint32_t f, char buf[5])
{
    for (int i = 0; i < 4; i++) {
        char c = (char)((f >> (8 * i)) & 0xff);
        buf[i] = (c >= 32 && c < 127) ? c : '?';
    }
    buf[4] = '\0';
    return buf;
}

size_t io_fmt_min_stride(uint32_t fourcc, int width)
{
    if (width <= 0) return 0;
    switch (fourcc) {
    case IO_FMT_YUYV: return (size_t)width * 2;
    case IO_FMT_GREY: case IO_FMT_RGGB: case IO_FMT_BGGR: case IO_FMT_GBRG:
    case IO_FMT_GRBG: return (size_t)width;
    case IO_FMT_UYVY: return (size_t)width * 2;
    case IO_FMT_NV12: case IO_FMT_YU12: case IO_FMT_422P: case IO_FMT_444P:
        return (size_t)width;
    case IO_FMT_RGB3: case IO_FMT_BGR3: return (size_t)width * 3;
    case IO_FMT_BGR4: case IO_FMT_RGB4: case IO_FMT_XR24: case IO_FMT_AR24:
    case IO_FMT_XB24: case IO_FMT_AB24: case IO_FMT_BX24: case IO_FMT_BA24:
        return (size_t)width * 4;
    default: return 0;
    }
}

size_t io_fmt_image_bytes(uint32_t fourcc, size_t stride, int width, int height)
{
    size_t minst = io_fmt_min_stride(fourcc, width);
    if (!minst || height <= 0 || stride < minst) return 0;
    size_t h = (size_t)height, ch = (h + 1) / 2, cs = (stride + 1) / 2;
    size_t cw = ((size_t)width + 1) / 2;
    switch (fourcc) {
    case IO_FMT_NV12: return stride * h + stride * (ch - 1) + 2 * cw;
    case IO_FMT_YU12: return stride * h + cs * ch + cs * (ch - 1) + cw;
    case IO_FMT_422P: return stride * h + cs * h + cs * (h - 1) + cw;
    case IO_FMT_444P: return stride * h * 2 + stride * (h - 1) + (size_t)width;
    default: return stride * (h - 1) + minst;
    }
}

/* ======================================================= pixel conversion */

static uint8_t clamp_u8(int v) { return (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v); }

static void yuv_to_rgb(int y, int u, int v, uint8_t *d)
{
    /* BT.601 limited range, 8-bit fixed point (x256) */
    int c = 298 * (y - 16), du = u - 128, dv = v - 128;
    d[0] = clamp_u8((c + 409 * dv + 128) >> 8);
    d[1] = clamp_u8((c - 100 * du - 208 * dv + 128) >> 8);
    d[2] = clamp_u8((c + 516 * du + 128) >> 8);
    d[3] = 255;
}

/* Planar and semi-planar YUV: chroma of pixel (x, y) at (x >> sx, y >> sy);
 * NV12 has U and V interleaved in one plane. BT.601 in 8-bit fixed point
 * (x256): limited range as yuv_to_rgb (same results), or full range (JPEG:
 * 256, 359, 88, 183, 454); the chroma terms once per chroma sample. */
static void planar_to_rgba(const io_frame *f, int sx, int sy, int nv12, int full, uint8_t *dst,
                           size_t ds)
{
    const int ky = full ? 256 : 298, y0 = full ? 0 : 16, kr = full ? 359 : 409,
              kgu = full ? 88 : 100, kgv = full ? 183 : 208, kb = full ? 454 : 516;
    int w = f->width, h = f->height;
    size_t ys = f->stride, h_sz = (size_t)h;
    const uint8_t *ybase = f->data, *ubase, *vbase;
    size_t cs, step = nv12 ? 2 : 1;
    if (nv12) {
        cs = ys;
        ubase = f->data + ys * h_sz;
        vbase = ubase + 1;
    } else {
        size_t ch = sy ? (h_sz + 1) / 2 : h_sz;
        cs = sx ? (ys + 1) / 2 : ys;
        ubase = f->data + ys * h_sz;
        vbase = ubase + cs * ch;
    }
    for (int y = 0; y < h; y++) {
        const uint8_t *yr = ybase + (size_t)y * ys;
        const uint8_t *ur = ubase + (size_t)(y >> sy) * cs, *vr = vbase + (size_t)(y >> sy) * cs;
        uint8_t *d = dst + (size_t)y * ds;
        int x = 0;
        if (sx) {
            /* two pixels per chroma sample */
            for (size_t c = 0; x + 1 < w; c++, x += 2) {
                int du = ur[c * step] - 128, dv = vr[c * step] - 128;
                int rv = kr * dv + 128, guv = kgu * du + kgv * dv - 128, bu = kb * du + 128;
                int l0 = ky * (yr[x] - y0), l1 = ky * (yr[x + 1] - y0);
                uint8_t *o = d + 4 * (size_t)x;
                o[0] = clamp_u8((l0 + rv) >> 8);
                o[1] = clamp_u8((l0 - guv) >> 8);
                o[2] = clamp_u8((l0 + bu) >> 8);
                o[3] = 255;
                o[4] = clamp_u8((l1 + rv) >> 8);
                o[5] = clamp_u8((l1 - guv) >> 8);
                o[6] = clamp_u8((l1 + bu) >> 8);
                o[7] = 255;
            }
        }
        for (; x < w; x++) { /* 4:4:4, or the last column of an odd width */
            size_t c = (size_t)(x >> sx) * step;
            int du = ur[c] - 128, dv = vr[c] - 128;
            int l = ky * (yr[x] - y0);
            uint8_t *o = d + 4 * (size_t)x;
            o[0] = clamp_u8((l + kr * dv + 128) >> 8);
            o[1] = clamp_u8((l - kgu * du - kgv * dv + 128) >> 8);
            o[2] = clamp_u8((l + kb * du + 128) >> 8);
            o[3] = 255;
        }
    }
}

/* Packed RGB: byte offsets of r, g, b in a pixel of bpp bytes. */
static void rgb_to_rgba(const io_frame *f, int bpp, int ro, int go, int bo, uint8_t *dst,
                        size_t ds)
{
    for (int y = 0; y < f->height; y++) {
        const uint8_t *s = f->data + (size_t)y * f->stride;
        uint8_t *d = dst + (size_t)y * ds;
        for (int x = 0; x < f->width; x++, s += bpp, d += 4) {
            d[0] = s[ro];
            d[1] = s[go];
            d[2] = s[bo];
            d[3] = 255;
        }
    }
}

/* Colour (0 R, 1 G, 2 B) of the Bayer site (x, y) for a pattern whose
 * top-left 2x2 block is p[0] p[1] / p[2] p[3]. */
static int bayer_site(const int p[4], int x, int y) { return p[(y & 1) * 2 + (x & 1)]; }

static int bayer_at(const uint8_t *s, size_t stride, int w, int h, int x, int y)
{
    if (x < 0) x = -x; /* mirror keeps the site colour */
    if (y < 0) y = -y;
    if (x >= w) x = 2 * w - 2 - x;
    if (y >= h) y = 2 * h - 2 - y;
    return s[(size_t)y * stride + (size_t)x];
}

static void bayer_to_rgba(const io_frame *f, const int p[4], uint8_t *dst, size_t ds)
{
    int w = f->width, h = f->height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            int rgb[3], sum[3] = {0, 0, 0}, n[3] = {0, 0, 0};
            int own = bayer_site(p, x, y);
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int c = bayer_site(p, x + dx + 2, y + dy + 2);
                    if (c == own && (dx || dy)) continue;
                    if (c == own) {
                        sum[c] += bayer_at(f->data, f->stride, w, h, x, y);
                        n[c]++;
                        continue;
                    }
                    /* green from the 4 direct neighbours only */
                    if (c == 1 && dx && dy) continue;
                    sum[c] += bayer_at(f->data, f->stride, w, h, x + dx, y + dy);
                    n[c]++;
                }
            for (int c = 0; c < 3; c++) rgb[c] = n[c] ? (sum[c] + n[c] / 2) / n[c] : 0;
            uint8_t *d = dst + (size_t)y * ds + 4 * (size_t)x;
            d[0] = (uint8_t)rgb[0];
            d[1] = (uint8_t)rgb[1];
            d[2] = (uint8_t)rgb[2];
            d[3] = 255;
        }
}

io_result io_frame_to_rgba(const io_frame *f, uint8_t *dst, size_t ds, io_error *err)
{
    return io_frame_to_rgba_range(f, dst, ds, 0, err);
}

io_result io_frame_to_rgba_range(const io_frame *f, uint8_t *dst, size_t ds, int full,
                                 io_error *err)
{
    char fs[5];
    if (!f || !f->data || !dst)
        return io_fail(err, IO_ERR_ARGS, "frame conversion: no frame or no output");
    size_t need = io_fmt_min_stride(f->fourcc, f->width);
    if (!need)
        return io_fail(err, IO_ERR_FORMAT, "frame conversion: format %s is not supported",
                       io_fourcc_str(f->fourcc, fs));
    if (f->stride < need || ds < 4 * (size_t)f->width || f->height <= 0 ||
        f->bytes < io_fmt_image_bytes(f->fourcc, f->stride, f->width, f->height))
        return io_fail(err, IO_ERR_SIZE, "frame conversion: %s %dx%d frame of %zu bytes "
                       "(stride %zu) is too small", io_fourcc_str(f->fourcc, fs), f->width,
                       f->height, f->bytes, f->stride);
    int w = f->width, h = f->height;
    static const int rggb[4] = {0, 1, 1, 2}, bggr[4] = {2, 1, 1, 0}, gbrg[4] = {1, 2, 0, 1},
                     grbg[4] = {1, 0, 2, 1};
    switch (f->fourcc) {
    case IO_FMT_YUYV:
        for (int y = 0; y < h; y++) {
            const uint8_t *s = f->data + (size_t)y * f->stride;
            uint8_t *d = dst + (size_t)y * ds;
            for (int x = 0; x + 1 < w; x += 2) {
                yuv_to_rgb(s[2 * x], s[2 * x + 1], s[2 * x + 3], d + 4 * x);
                yuv_to_rgb(s[2 * x + 2], s[2 * x + 1], s[2 * x + 3], d + 4 * x + 4);
            }
            if (w & 1) yuv_to_rgb(s[2 * (w - 1)], 128, 128, d + 4 * (w - 1));
        }
        break;
    case IO_FMT_GREY:
        for (int y = 0; y < h; y++) {
            const uint8_t *s = f->data + (size_t)y * f->stride;
            uint8_t *d = dst + (size_t)y * ds;
            for (int x = 0; x < w; x++) {
                d[4 * x] = d[4 * x + 1] = d[4 * x + 2] = s[x];
                d[4 * x + 3] = 255;
            }
        }
        break;
    case IO_FMT_UYVY:
        for (int y = 0; y < h; y++) {
            const uint8_t *s = f->data + (size_t)y * f->stride;
            uint8_t *d = dst + (size_t)y * ds;
            for (int x = 0; x + 1 < w; x += 2) {
                yuv_to_rgb(s[2 * x + 1], s[2 * x], s[2 * x + 2], d + 4 * x);
                yuv_to_rgb(s[2 * x + 3], s[2 * x], s[2 * x + 2], d + 4 * x + 4);
            }
            if (w & 1) yuv_to_rgb(s[2 * (w - 1) + 1], 128, 128, d + 4 * (w - 1));
        }
        break;
    case IO_FMT_NV12: planar_to_rgba(f, 1, 1, 1, full, dst, ds); break;
    case IO_FMT_YU12: planar_to_rgba(f, 1, 1, 0, full, dst, ds); break;
    case IO_FMT_422P: planar_to_rgba(f, 1, 0, 0, full, dst, ds); break;
    case IO_FMT_444P: planar_to_rgba(f, 0, 0, 0, full, dst, ds); break;
    case IO_FMT_RGB3: rgb_to_rgba(f, 3, 0, 1, 2, dst, ds); break;
    case IO_FMT_BGR3: rgb_to_rgba(f, 3, 2, 1, 0, dst, ds); break;
    case IO_FMT_BGR4: case IO_FMT_XR24: case IO_FMT_AR24: rgb_to_rgba(f, 4, 2, 1, 0, dst, ds); break;
    case IO_FMT_XB24: case IO_FMT_AB24: rgb_to_rgba(f, 4, 0, 1, 2, dst, ds); break;
    case IO_FMT_RGB4: case IO_FMT_BX24: case IO_FMT_BA24: rgb_to_rgba(f, 4, 1, 2, 3, dst, ds); break;
    case IO_FMT_RGGB: bayer_to_rgba(f, rggb, dst, ds); break;
    case IO_FMT_BGGR: bayer_to_rgba(f, bggr, dst, ds); break;
    case IO_FMT_GBRG: bayer_to_rgba(f, gbrg, dst, ds); break;
    case IO_FMT_GRBG: bayer_to_rgba(f, grbg, dst, ds); break;
    default:
        return io_fail(err, IO_ERR_FORMAT, "frame conversion: format %s is not supported",
                       io_fourcc_str(f->fourcc, fs));
    }
    return IO_OK;
}
