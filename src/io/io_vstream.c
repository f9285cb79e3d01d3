/* io_vstream.c - the frame stream reader (io_vstream.h): a growing byte
 * buffer fed from a descriptor, the parsers of the egofuse framing, of
 * YUV4MPEG2 and of headerless raw frames, and the eye scalers. The byte
 * layouts are those of docs/vstream.md. */
#include "io_vstream.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void vs_init(vs_reader *r, const char *name)
{
    memset(r, 0, sizeof *r);
    snprintf(r->name, sizeof r->name, "%s", name ? name : "stream");
}

void vs_free(vs_reader *r)
{
    free(r->buf);
    r->buf = NULL;
    r->cap = r->len = r->pos = 0;
}

void vs_restart(vs_reader *r)
{
    if (r->framing != VS_RAW) r->framing = VS_UNKNOWN;
    r->y4m_have = 0;
    r->len = r->pos = r->need = 0;
    r->offset = 0;
    r->eof = 0;
}

void vs_drop(vs_reader *r, size_t keep)
{
    if (keep > r->len) keep = r->len;
    if (!keep) return;
    memmove(r->buf, r->buf + keep, r->len - keep);
    r->len -= keep;
    r->pos = r->pos > keep ? r->pos - keep : 0;
    r->offset += keep;
}

long vs_fill(vs_reader *r, int fd, size_t max_bytes)
{
    size_t want = r->pos + (r->need ? r->need : 0);
    size_t room = want > r->len ? want - r->len : 0;
    if (room < 65536) room = 65536;
    if (r->len + room > r->cap) {
        size_t nc = r->cap ? r->cap : 65536;
        while (nc < r->len + room) nc *= 2;
        uint8_t *nb = realloc(r->buf, nc);
        if (!nb) {
            snprintf(r->msg, sizeof r->msg, "%s: out of memory for a %zu-byte buffer", r->name, nc);
            return -2;
        }
        r->buf = nb;
        r->cap = nc;
    }
    size_t n = r->cap - r->len;
    if (max_bytes && n > max_bytes) n = max_bytes;
    ssize_t k;
    do k = read(fd, r->buf + r->len, n);
    while (k < 0 && errno == EINTR);
    if (k < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK) return -1;
        snprintf(r->msg, sizeof r->msg, "%s: read: %s", r->name, strerror(errno));
        return -2;
    }
    if (k == 0) {
        r->eof = 1;
        return 0;
    }
    r->len += (size_t)k;
    return (long)k;
}

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static uint64_t rd64(const uint8_t *p) { return (uint64_t)rd32(p) | (uint64_t)rd32(p + 4) << 32; }

static int bad(vs_reader *r, int code, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int bad(vs_reader *r, int code, const char *fmt, ...)
{
    int n = snprintf(r->msg, sizeof r->msg, "%s: ", r->name);
    if (n < 0 || (size_t)n >= sizeof r->msg) n = 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(r->msg + n, sizeof r->msg - (size_t)n, fmt, ap);
    va_end(ap);
    return code;
}

/* Formats a stream may carry (egofuse framing, raw). */
static int stream_format_ok(uint32_t f)
{
    switch (f) {
    case IO_FMT_RGB3: case IO_FMT_BGR3: case IO_FMT_AB24: case IO_FMT_AR24: case IO_FMT_XB24:
    case IO_FMT_XR24: case IO_FMT_YUYV: case IO_FMT_UYVY: case IO_FMT_NV12: case IO_FMT_YU12:
    case IO_FMT_GREY: return 1;
    default: return 0;
    }
}

/* 4:2:x formats need an even width in a stream (tight rows). */
static int needs_even_width(uint32_t f)
{
    return f == IO_FMT_YUYV || f == IO_FMT_UYVY || f == IO_FMT_NV12 || f == IO_FMT_YU12;
}

uint32_t vs_raw_format(const char *n)
{
    static const struct { const char *name; uint32_t f; } t[] = {
        {"rgb24", IO_FMT_RGB3}, {"bgr24", IO_FMT_BGR3}, {"rgba", IO_FMT_AB24},
        {"bgra", IO_FMT_AR24},  {"rgb0", IO_FMT_XB24},  {"bgr0", IO_FMT_XR24},
        {"yuyv", IO_FMT_YUYV},  {"yuyv422", IO_FMT_YUYV}, {"uyvy", IO_FMT_UYVY},
        {"uyvy422", IO_FMT_UYVY}, {"nv12", IO_FMT_NV12}, {"i420", IO_FMT_YU12},
        {"yuv420p", IO_FMT_YU12}, {"gray", IO_FMT_GREY}, {"grey", IO_FMT_GREY}};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        if (!strcmp(n, t[i].name)) return t[i].f;
    return 0;
}

static size_t tight_bytes(uint32_t f, int w, int h)
{
    return io_fmt_image_bytes(f, io_fmt_min_stride(f, w), w, h);
}

/* The size lock: the first frame (or the config) fixes the size. */
static int check_lock(vs_reader *r, int w, int h)
{
    if (!r->lock_w) {
        r->lock_w = w;
        r->lock_h = h;
        return 1;
    }
    return w == r->lock_w && h == r->lock_h;
}

/* ------------------------------------------------------------ egofuse */

static const uint8_t egfv_magic[6] = {'E', 'G', 'F', 'V', 1, 0};

static int parse_egfv(vs_reader *r, vs_frame *f)
{
    const uint8_t *p = r->buf + r->pos;
    size_t avail = r->len - r->pos;
    if (avail < 8) {
        r->need = VS_EGFV_HEADER;
        if (r->eof && avail)
            return bad(r, VS_FATAL, "truncated frame header at the end of the stream (%zu of %d "
                       "bytes) after frame %llu", avail, VS_EGFV_HEADER,
                       (unsigned long long)r->parsed);
        return VS_MORE;
    }
    if (memcmp(p, "EGFV", 4)) {
        /* lost sync: look for the next header */
        size_t q = r->pos + 1;
        for (; q + 6 <= r->len; q++)
            if (!memcmp(r->buf + q, egfv_magic, 6)) break;
        unsigned long long at = (unsigned long long)(r->offset + r->pos);
        size_t skip = (q + 6 <= r->len) ? q - r->pos : (r->len - r->pos > 5 ? r->len - r->pos - 5 : 0);
        if (!skip) {
            r->need = 6;
            return VS_MORE;
        }
        r->pos += skip;
        r->parsed++;
        return bad(r, VS_BAD, "no frame header at byte %llu (expected \"EGFV\", got %02x %02x %02x "
                   "%02x): %zu bytes skipped to the next header", at, p[0], p[1], p[2], p[3], skip);
    }
    unsigned ver = rd16(p + 4), hs = rd16(p + 6);
    if (ver != 1)
        return bad(r, VS_FATAL, "frame %llu: unknown egofuse framing version %u (this egofuse "
                   "reads version 1)", (unsigned long long)r->parsed, ver);
    if (hs < VS_EGFV_HEADER || hs > 4096)
        return bad(r, VS_FATAL, "frame %llu: header size %u is not valid (64..4096)",
                   (unsigned long long)r->parsed, hs);
    if (avail < hs) {
        r->need = hs;
        if (r->eof)
            return bad(r, VS_FATAL, "truncated frame header at the end of the stream (%zu of %u "
                       "bytes) after frame %llu", avail, hs, (unsigned long long)r->parsed);
        return VS_MORE;
    }
    uint32_t w = rd32(p + 8), h = rd32(p + 12), fmt = rd32(p + 16);
    unsigned layout = p[20], dfmt = p[21], flags = rd16(p + 22);
    uint64_t t = rd64(p + 24), seq = rd64(p + 32);
    uint32_t cb = rd32(p + 40), db = rd32(p + 44);
    float dscale;
    uint32_t sb = rd32(p + 48);
    memcpy(&dscale, &sb, 4);
    uint64_t total = (uint64_t)hs + cb + db;
    if (total > ((uint64_t)1 << 31))
        return bad(r, VS_FATAL, "frame %llu: %llu bytes of payload is not plausible (header "
                   "corrupt?)", (unsigned long long)r->parsed, (unsigned long long)(cb + (uint64_t)db));
    if (avail < total) {
        r->need = (size_t)total;
        if (r->eof)
            return bad(r, VS_FATAL, "truncated frame %llu at the end of the stream (%zu of %llu "
                       "bytes)", (unsigned long long)r->parsed, avail, (unsigned long long)total);
        return VS_MORE;
    }
    /* the whole frame is here: from now on a bad frame is skipped */
    uint64_t k = r->parsed++;
    r->pos += (size_t)total;
    r->need = 0;
    char fs[5];
    if (w == 0 || h == 0 || w > VS_MAX_DIM || h > VS_MAX_DIM)
        return bad(r, VS_BAD, "frame %llu: size %ux%u is not valid: skipped",
                   (unsigned long long)k, w, h);
    if (!stream_format_ok(fmt))
        return bad(r, VS_BAD, "frame %llu: unknown pixel format '%s' (0x%08x): skipped",
                   (unsigned long long)k, io_fourcc_str(fmt, fs), fmt);
    if (needs_even_width(fmt) && (w & 1))
        return bad(r, VS_BAD, "frame %llu: %s needs an even width, got %u: skipped",
                   (unsigned long long)k, io_fourcc_str(fmt, fs), w);
    if (layout > 3)
        return bad(r, VS_BAD, "frame %llu: unknown layout %u (0..3): skipped",
                   (unsigned long long)k, layout);
    size_t want = tight_bytes(fmt, (int)w, (int)h);
    if (cb != want)
        return bad(r, VS_BAD, "frame %llu: %u colour bytes, %ux%u %s needs %zu: skipped",
                   (unsigned long long)k, cb, w, h, io_fourcc_str(fmt, fs), want);
    if (dfmt > 2)
        return bad(r, VS_BAD, "frame %llu: unknown depth format %u (0 none, 1 float32, 2 "
                   "uint16): skipped", (unsigned long long)k, dfmt);
    size_t dwant = dfmt == 0 ? 0 : (size_t)w * h * (dfmt == 1 ? 4u : 2u);
    if (db != dwant)
        return bad(r, VS_BAD, "frame %llu: %u depth bytes, depth format %u at %ux%u needs %zu: "
                   "skipped", (unsigned long long)k, db, dfmt, w, h, dwant);
    if (dfmt == 2 && !(dscale > 0 && isfinite(dscale)))
        return bad(r, VS_BAD, "frame %llu: uint16 depth needs a scale > 0, got %g: skipped",
                   (unsigned long long)k, (double)dscale);
    if (!check_lock(r, (int)w, (int)h))
        return bad(r, VS_BAD, "frame %llu is %ux%u, the stream's frames are %dx%d: skipped",
                   (unsigned long long)k, w, h, r->lock_w, r->lock_h);
    memset(f, 0, sizeof *f);
    f->off = r->pos - (size_t)total + hs;
    f->bytes = cb;
    f->width = (int)w;
    f->height = (int)h;
    f->fourcc = fmt;
    f->full_range = (flags & 1u) != 0;
    f->layout = (int)layout;
    f->depth_fmt = (int)dfmt;
    f->depth_scale = dfmt == 2 ? dscale : 1.0f;
    f->depth_off = f->off + cb;
    f->t_ns = t;
    f->sequence = seq;
    return VS_FRAME;
}

/* ---------------------------------------------------------------- y4m */

/* A line of at most VS_LINE_MAX bytes at r->pos: its length without the
 * '\n' in *n, 1 when complete, 0 when more is needed, -1 when too long. */
static int line_at(vs_reader *r, size_t *n)
{
    const uint8_t *p = r->buf + r->pos;
    size_t avail = r->len - r->pos, lim = avail < VS_LINE_MAX ? avail : VS_LINE_MAX;
    const uint8_t *nl = memchr(p, '\n', lim);
    if (nl) {
        *n = (size_t)(nl - p);
        return 1;
    }
    return avail >= VS_LINE_MAX ? -1 : 0;
}

/* A Y4M or raw frame in hand: f is the colour payload at r->buf + off
 * (bytes long, w x h fourcc, full range or not, nothing else said), the
 * next frame's number; the read position moves `advance` bytes on.
 * VS_FRAME. */
static int give_frame(vs_reader *r, vs_frame *f, size_t off, size_t bytes, int w, int h,
                      uint32_t fourcc, int full, size_t advance)
{
    *f = (vs_frame){ .off = off, .bytes = bytes, .width = w, .height = h, .fourcc = fourcc,
                     .full_range = full, .sequence = r->parsed++ };
    r->pos += advance;
    r->need = 0;
    return VS_FRAME;
}

/* line_at for a Y4M line (`what`, `cut`: its names in the messages): 1
 * with its length in *n; else 0 and in *ret what the parser returns:
 * VS_MORE (its end not read yet), or VS_FATAL when it is longer than
 * VS_LINE_MAX or the stream ends inside it. */
static int y4m_line(vs_reader *r, const char *what, const char *cut, size_t *n, int *ret)
{
    int lr = line_at(r, n);
    if (lr > 0) return 1;
    if (lr < 0) *ret = bad(r, VS_FATAL, "%s longer than %d bytes", what, VS_LINE_MAX);
    else {
        r->need = 0;
        *ret = r->eof ? bad(r, VS_FATAL, "truncated %s at the end of the stream", cut) : VS_MORE;
    }
    return 0;
}

static int parse_y4m_header(vs_reader *r)
{
    size_t n;
    int ret;
    if (!y4m_line(r, "YUV4MPEG2 header line", "YUV4MPEG2 header", &n, &ret)) return ret;
    char line[VS_LINE_MAX + 1];
    memcpy(line, r->buf + r->pos, n);
    line[n] = '\0';
    int w = 0, h = 0, full = 0;
    uint32_t fmt = IO_FMT_YU12; /* no C tag: 4:2:0 (jpeg siting) */
    r->fps_num = r->fps_den = 0;
    char *save = NULL;
    for (char *tok = strtok_r(line + 9, " ", &save); tok; tok = strtok_r(NULL, " ", &save)) {
        switch (tok[0]) {
        case 'W': w = atoi(tok + 1); break;
        case 'H': h = atoi(tok + 1); break;
        case 'F': {
            int a = 0, b = 0;
            if (sscanf(tok + 1, "%d:%d", &a, &b) == 2 && a > 0 && b > 0) {
                r->fps_num = a;
                r->fps_den = b;
            }
            break;
        }
        case 'C':
            if (!strcmp(tok + 1, "420jpeg") || !strcmp(tok + 1, "420paldv") ||
                !strcmp(tok + 1, "420mpeg2") || !strcmp(tok + 1, "420"))
                fmt = IO_FMT_YU12;
            else if (!strcmp(tok + 1, "422"))
                fmt = IO_FMT_422P;
            else if (!strcmp(tok + 1, "444"))
                fmt = IO_FMT_444P;
            else if (!strcmp(tok + 1, "mono"))
                fmt = IO_FMT_GREY;
            else
                return bad(r, VS_FATAL, "YUV4MPEG2 colourspace C%.40s is not supported (8-bit "
                           "420jpeg, 420paldv, 420mpeg2, 420, 422, 444 and mono are; e.g. "
                           "ffmpeg -pix_fmt yuv420p)", tok + 1);
            break;
        case 'X':
            if (!strcmp(tok, "XCOLORRANGE=FULL")) full = 1;
            break;
        default: break; /* I (interlacing), A (aspect), unknown tags: ignored */
        }
    }
    if (w <= 0 || h <= 0 || w > VS_MAX_DIM || h > VS_MAX_DIM)
        return bad(r, VS_FATAL, "YUV4MPEG2 header without a valid size (W%d H%d)", w, h);
    if (r->lock_w && (w != r->lock_w || h != r->lock_h))
        return bad(r, VS_FATAL, "the YUV4MPEG2 stream is %dx%d, %dx%d expected", w, h, r->lock_w,
                   r->lock_h);
    r->lock_w = w;
    r->lock_h = h;
    r->y4m_w = w;
    r->y4m_h = h;
    r->y4m_fmt = fmt;
    r->y4m_full = full;
    r->y4m_have = 1;
    r->pos += n + 1;
    return VS_FRAME; /* header taken; the caller goes on */
}

static int parse_y4m(vs_reader *r, vs_frame *f)
{
    if (!r->y4m_have) {
        int h = parse_y4m_header(r);
        if (h != VS_FRAME) return h;
    }
    size_t avail = r->len - r->pos;
    if (avail < 6) {
        r->need = 6;
        if (r->eof && avail)
            return bad(r, VS_FATAL, "truncated frame header at the end of the stream after frame "
                       "%llu", (unsigned long long)r->parsed);
        return VS_MORE;
    }
    const uint8_t *p = r->buf + r->pos;
    if (avail >= 10 && !memcmp(p, "YUV4MPEG2 ", 10)) {
        /* a second stream header (concatenated streams): read it again */
        r->y4m_have = 0;
        return parse_y4m(r, f);
    }
    if (memcmp(p, "FRAME", 5) || (p[5] != '\n' && p[5] != ' '))
        return bad(r, VS_FATAL, "frame %llu: expected \"FRAME\" at byte %llu, got %02x %02x %02x "
                   "%02x %02x (stream out of step)", (unsigned long long)r->parsed,
                   (unsigned long long)(r->offset + r->pos), p[0], p[1], p[2], p[3], p[4]);
    size_t n;
    int ret;
    if (!y4m_line(r, "FRAME line", "FRAME line", &n, &ret)) return ret;
    size_t pb = tight_bytes(r->y4m_fmt, r->y4m_w, r->y4m_h);
    size_t total = n + 1 + pb;
    if (avail < total) {
        r->need = total;
        if (r->eof)
            return bad(r, VS_FATAL, "truncated frame %llu at the end of the stream (%zu of %zu "
                       "bytes)", (unsigned long long)r->parsed, avail, total);
        return VS_MORE;
    }
    return give_frame(r, f, r->pos + n + 1, pb, r->y4m_w, r->y4m_h, r->y4m_fmt, r->y4m_full,
                      total);
}

/* ---------------------------------------------------------------- raw */

static int parse_raw(vs_reader *r, vs_frame *f)
{
    size_t pb = tight_bytes(r->raw_fmt, r->raw_w, r->raw_h);
    size_t avail = r->len - r->pos;
    if (avail < pb) {
        r->need = pb;
        if (r->eof && avail)
            return bad(r, VS_FATAL, "truncated frame %llu at the end of the stream (%zu of %zu "
                       "bytes)", (unsigned long long)r->parsed, avail, pb);
        return VS_MORE;
    }
    return give_frame(r, f, r->pos, pb, r->raw_w, r->raw_h, r->raw_fmt, 0, pb);
}

int vs_parse(vs_reader *r, vs_frame *f)
{
    if (r->framing == VS_UNKNOWN) {
        size_t avail = r->len - r->pos;
        if (!avail) {   /* nothing read yet (r->buf may be NULL) */
            r->need = 10;
            if (r->eof) return bad(r, VS_FATAL, "the stream ended after 0 bytes, before a frame header");
            return VS_MORE;
        }
        const uint8_t *p = r->buf + r->pos;
        if (avail >= 4 && !memcmp(p, "EGFV", 4)) {
            r->framing = VS_EGFV;
        } else if (avail >= 10 && !memcmp(p, "YUV4MPEG2 ", 10)) {
            r->framing = VS_Y4M;
        } else if ((avail < 4 || memcmp(p, "EGFV", avail < 4 ? avail : 4)) &&
                   memcmp(p, "YUV4MPEG2 ", avail < 10 ? avail : 10)) {
            char hex[64] = "";
            for (size_t i = 0; i < avail && i < 8; i++)
                snprintf(hex + 3 * i, sizeof hex - 3 * i, "%02x ", p[i]);
            return bad(r, VS_FATAL, "unknown framing (first bytes %s): expected the egofuse "
                       "framing (\"EGFV\"), YUV4MPEG2, or say raw:WxH:FORMAT:PATH",
                       hex[0] ? hex : "none");
        } else {
            r->need = 10;
            if (r->eof)
                return bad(r, VS_FATAL, "the stream ended after %zu bytes, before a frame header",
                           avail);
            return VS_MORE;
        }
    }
    switch (r->framing) {
    case VS_EGFV: return parse_egfv(r, f);
    case VS_Y4M: return parse_y4m(r, f);
    case VS_RAW: return parse_raw(r, f);
    default: return bad(r, VS_FATAL, "no framing");
    }
}

/* ------------------------------------------------------------ scaling */

/* Source coordinate of destination pixel centre i, in 1/256 pixel:
 * ((2i + 1) * s * 256) / (2 d) - 128, clamped to [0, (s - 1) * 256]. */
static void bilinear_table(int s, int d, int *t)
{
    for (int i = 0; i < d; i++) {
        int64_t c = ((int64_t)(2 * i + 1) * s * 256) / (2 * (int64_t)d) - 128;
        if (c < 0) c = 0;
        if (c > (int64_t)(s - 1) * 256) c = (int64_t)(s - 1) * 256;
        t[2 * i] = (int)(c >> 8);
        t[2 * i + 1] = (int)(c & 255);
    }
}

/* Horizontal pass of one source row: top[x] = a (256 - wx) + b wx per
 * channel (at most 65280: 16 bits), the first factor of the rule. */
static void hrow(const uint8_t *r, int sw, int dw, const int *xt, uint16_t *o)
{
    for (int x = 0; x < dw; x++) {
        int x0 = xt[2 * x], wx = xt[2 * x + 1];
        const uint8_t *a = r + 4 * x0, *b = r + 4 * (x0 + 1 < sw ? x0 + 1 : x0);
        o[3 * x] = (uint16_t)(a[0] * (256 - wx) + b[0] * wx);
        o[3 * x + 1] = (uint16_t)(a[1] * (256 - wx) + b[1] * wx);
        o[3 * x + 2] = (uint16_t)(a[2] * (256 - wx) + b[2] * wx);
    }
}

void vs_scale_rgba(const uint8_t *s, int sw, int sh, size_t ss, uint8_t *d, int dw, int dh,
                   size_t ds, int *xt, int *yt, uint16_t *rows)
{
    /* separable and exact: the horizontal blends of the two source rows an
     * output row needs are kept (rows: 2 x 3 dw) and reused by the next
     * output rows while they need the same source rows */
    bilinear_table(sw, dw, xt);
    bilinear_table(sh, dh, yt);
    uint16_t *h[2] = {rows, rows + 3 * (size_t)dw};
    int have[2] = {-1, -1};
    for (int y = 0; y < dh; y++) {
        int y0 = yt[2 * y], wy = yt[2 * y + 1];
        int y1 = y0 + 1 < sh ? y0 + 1 : y0;
        int want[2] = {y0, y1};
        for (int k = 0; k < 2; k++) {
            if (have[k] == want[k]) continue;
            if (k == 0 && have[1] == y0) { /* slide down: row 1 becomes row 0 */
                uint16_t *t = h[0];
                h[0] = h[1];
                h[1] = t;
                have[0] = y0;
                have[1] = -1;
                continue;
            }
            hrow(s + (size_t)want[k] * ss, sw, dw, xt, h[k]);
            have[k] = want[k];
        }
        const uint16_t *t0 = h[0], *t1 = h[1];
        uint8_t *o = d + (size_t)y * ds;
        uint32_t iy = (uint32_t)(256 - wy), fy = (uint32_t)wy;
        for (int x = 0; x < dw; x++) {
            o[4 * x] = (uint8_t)((t0[3 * x] * iy + t1[3 * x] * fy + 32768u) >> 16);
            o[4 * x + 1] = (uint8_t)((t0[3 * x + 1] * iy + t1[3 * x + 1] * fy + 32768u) >> 16);
            o[4 * x + 2] = (uint8_t)((t0[3 * x + 2] * iy + t1[3 * x + 2] * fy + 32768u) >> 16);
            o[4 * x + 3] = 255;
        }
    }
}

void vs_scale_depth(const uint8_t *s, int fmt, float scale, int sw, int sh, size_t ss, float *d,
                    int dw, int dh, size_t dsf)
{
    for (int y = 0; y < dh; y++) {
        int sy = (int)(((int64_t)(2 * y + 1) * sh) / (2 * (int64_t)dh));
        const uint8_t *row = s + (size_t)sy * ss;
        float *o = d + (size_t)y * dsf;
        for (int x = 0; x < dw; x++) {
            int sx = (int)(((int64_t)(2 * x + 1) * sw) / (2 * (int64_t)dw));
            float v;
            if (fmt == VS_DEPTH_F32) {
                memcpy(&v, row + 4 * (size_t)sx, 4);
                if (!isfinite(v) || v < 0) v = 0; /* nothing there */
            } else {
                uint16_t u = (uint16_t)(row[2 * sx] | row[2 * sx + 1] << 8);
                v = (float)u * scale;
            }
            o[x] = v;
        }
    }
}
