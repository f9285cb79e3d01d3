/* fuzz_io_vstream.c - libFuzzer target of the raw V stream reader
 * (src/io/io_vstream.c: vs_fill + vs_parse, the "EGFV", YUV4MPEG2 and
 * headerless raw framings, docs/vstream.md), fed as io_vsrc.c feeds it.
 *
 * Input: byte 0 picks the read size (bits 0-2: 1, 7, 64, 4096, 65536 ...
 * bytes per read, so headers and frames arrive split) and, with bit 3,
 * the raw framing: then bytes 1-4 are width-1, height-1 (1..256 each)
 * and a format index, as "raw:WxH:FMT:" would set them. The rest is the
 * stream, read from a memfd. Every frame must lie inside the buffer; a
 * bad frame or a fatal error comes with a message. A frame larger than
 * 64 MiB is not read (see the loop). `make fuzz`, seeds in
 * tests/fuzz/corpus/io_vstream/; docs/fuzzing.md. */
#include <string.h>
#include <sys/mman.h>

#include "../src/io/io_vstream.h"
#include "fuzz/fuzz_util.h"

static const char *const raw_fmts[] = { "rgb24", "bgr24", "rgba", "bgra", "rgb0", "bgr0",
                                        "yuyv",  "uyvy",  "nv12", "i420", "gray" };
static const size_t reads[] = { 1, 7, 64, 333, 4096, 65536, 1 << 20, 0 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int fd = -1;
    if (fd < 0) fd = memfd_create("fuzz_io_vstream", 0);
    if (fd < 0 || size < 1) return 0;
    vs_reader r;
    vs_init(&r, "fuzz");
    size_t skip = 1;
    size_t chunk = reads[data[0] & 7];
    if (data[0] & 8) {
        if (size < 5) return 0;
        uint32_t f = vs_raw_format(raw_fmts[data[4] % (sizeof raw_fmts / sizeof raw_fmts[0])]);
        if (!f) abort();
        r.framing = VS_RAW;
        r.raw_w = data[1] + 1;
        r.raw_h = data[2] + 1;
        if (f == IO_FMT_YUYV || f == IO_FMT_UYVY || f == IO_FMT_NV12 || f == IO_FMT_YU12)
            r.raw_w += r.raw_w & 1;   /* io_vsrc.c refuses odd widths there */
        r.raw_fmt = f;
        r.lock_w = r.raw_w;
        r.lock_h = r.raw_h;
        skip = 5;
    }
    if (ftruncate(fd, 0) || lseek(fd, 0, SEEK_SET) < 0) abort();
    size_t n = size - skip;
    if (n && write(fd, data + skip, n) != (ssize_t)n) abort();
    if (lseek(fd, 0, SEEK_SET) < 0) abort();
    for (;;) {
        vs_frame f;
        int rc = vs_parse(&r, &f);
        if (rc == VS_FRAME) {
            if (f.width <= 0 || f.height <= 0 || f.width > VS_MAX_DIM || f.height > VS_MAX_DIM)
                abort();
            if (f.off > r.len || f.bytes > r.len - f.off) abort();
            if (f.depth_fmt && f.depth_off > r.len) abort();
            vs_drop(&r, r.pos);
        } else if (rc == VS_BAD) {
            if (!r.msg[0]) abort();
        } else if (rc == VS_FATAL) {
            if (!r.msg[0]) abort();
            break;
        } else {   /* VS_MORE */
            if (r.eof) break;
            /* a header may ask for up to 16384 x 16384 colour + depth
             * (2 GiB, VS_MAX_DIM): the input is at most 64 KiB, so such
             * a frame can only end truncated; stop before the buffer
             * would grow past libFuzzer's malloc limit */
            if (r.pos + r.need > ((size_t)64 << 20)) break;
            long k = vs_fill(&r, fd, chunk);
            if (k < -1) break;
            if (k == -1) abort();   /* a memfd never says EAGAIN */
        }
    }
    vs_free(&r);
    return 0;
}
