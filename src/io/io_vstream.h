/* io_vstream.h - internal to src/io: the frame stream reader shared by the
 * V source (io_vsrc.c) and the file cameras (io_file_cam.c): a byte buffer
 * fed from a descriptor and the parsers of the three framings (egofuse
 * "EGFV", YUV4MPEG2, headerless raw), plus the eye scalers. The formats are
 * documented in docs/vstream.md. Not a public header. */
#ifndef EGOFUSE_IO_VSTREAM_H
#define EGOFUSE_IO_VSTREAM_H

#include <stddef.h>
#include <stdint.h>
#include "io_dev.h"

#define VS_EGFV_HEADER 64          /* bytes of a version 1 header */
#define VS_MAX_DIM 16384
#define VS_LINE_MAX 1024           /* y4m header / FRAME line */

enum { VS_UNKNOWN = 0, VS_EGFV, VS_Y4M, VS_RAW };
enum { VS_MORE = 0, VS_FRAME, VS_BAD, VS_FATAL };
enum { VS_DEPTH_NONE = 0, VS_DEPTH_F32 = 1, VS_DEPTH_U16 = 2 };

typedef struct vs_frame {
    size_t off;                    /* colour payload: r->buf + off */
    size_t bytes;                  /* its size */
    int width, height;
    uint32_t fourcc;
    int full_range;
    int layout;                    /* io_vsrc_layout; 0 = not said */
    int depth_fmt;                 /* VS_DEPTH_* */
    float depth_scale;             /* metres per unit (u16) */
    size_t depth_off;
    uint64_t t_ns;                 /* the header's, 0 = none */
    uint64_t sequence;
} vs_frame;

typedef struct vs_reader {
    char name[320];                /* the source, for messages */
    int framing;                   /* VS_*; VS_UNKNOWN until detected */
    int raw_w, raw_h;              /* raw: the spec's */
    uint32_t raw_fmt;
    /* y4m stream header */
    int y4m_have;
    int y4m_w, y4m_h, y4m_full;
    uint32_t y4m_fmt;
    int fps_num, fps_den;          /* y4m F, 0 when unknown */
    /* the size every frame must have (0 = set by the first) */
    int lock_w, lock_h;
    /* buffer */
    uint8_t *buf;
    size_t cap, len, pos;          /* pos: next byte to parse */
    size_t need;                   /* VS_MORE: bytes from pos still missing
                                      for the frame in hand (0 unknown) */
    uint64_t offset;               /* stream offset of buf[0] */
    uint64_t parsed;               /* frames parsed (good and bad) */
    int eof;                       /* read returned 0 */
    char msg[384];                 /* VS_BAD / VS_FATAL: why */
} vs_reader;

void vs_init(vs_reader *r, const char *name);
void vs_free(vs_reader *r);
/* Forgets the stream (a new producer, a rewound file): framing and y4m
 * header are detected again; the size lock is kept. */
void vs_restart(vs_reader *r);
/* Reads from fd (non-blocking or not) up to max_bytes (0 = what fits)
 * into the buffer, growing it to hold r->need. Returns the bytes read,
 * 0 at EOF (r->eof = 1), -1 when nothing was ready (EAGAIN), -2 on an
 * error (r->msg). */
long vs_fill(vs_reader *r, int fd, size_t max_bytes);
/* Parses the next frame at r->pos: VS_FRAME (f filled, r->pos after it),
 * VS_MORE (incomplete, r->need set), VS_BAD (a frame or bytes skipped,
 * r->pos advanced, r->msg says why), VS_FATAL (r->msg). */
int vs_parse(vs_reader *r, vs_frame *f);
/* Drops the bytes before keep (<= r->pos); frames' offsets shift by it. */
void vs_drop(vs_reader *r, size_t keep);

/* Bilinear scale of an RGBA8 region (alpha of the result 255). xt / yt:
 * scratch of 2 * dw / 2 * dh ints. docs/vstream.md gives the rule. */
void vs_scale_rgba(const uint8_t *s, int sw, int sh, size_t ss, uint8_t *d, int dw, int dh,
                   size_t ds, int *xt, int *yt);
/* Nearest-neighbour depth: src of sw x sh values (float32 or uint16 *
 * scale, row stride ss bytes) into float metres (stride dsf floats). */
void vs_scale_depth(const uint8_t *s, int fmt, float scale, int sw, int sh, size_t ss, float *d,
                    int dw, int dh, size_t dsf);
/* "rgb24" ... -> fourcc; 0 when unknown. */
uint32_t vs_raw_format(const char *name);

#endif
