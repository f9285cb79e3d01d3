/* fuzz_io_natnet.c - libFuzzer target of the NatNet decoders
 * (src/io/io_natnet.c, docs/io.md): the frame of data
 * (io_natnet_parse_frame) and the model definitions (parse_modeldef, a
 * static function: this file includes io_natnet.c to reach it).
 *
 * Input: byte 0 picks the NatNet version (3.0, 3.1, 4.0, 4.1, 4.2) and,
 * with bit 4, the model definitions instead of a frame; the rest is the
 * payload after the 4-byte message header. `make fuzz`, seeds in
 * tests/fuzz/corpus/io_natnet/; docs/fuzzing.md. */
#include "../src/io/io_natnet.c"
#include "fuzz/fuzz_util.h"

static const int vers[][2] = { { 3, 0 }, { 3, 1 }, { 4, 0 }, { 4, 1 }, { 4, 2 } };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    int v = (data[0] & 15) % 5, major = vers[v][0], minor = vers[v][1];
    const uint8_t *pl = data + 1;
    size_t len = size - 1;
    /* a copy of exactly len bytes, so ASan sees a read past the payload */
    uint8_t *copy = malloc(len ? len : 1);
    if (!copy) return 0;
    if (len) memcpy(copy, pl, len);
    if (data[0] & 16) {
        static io_natnet_desc d[IO_NATNET_MAX_BODIES];
        int cnt = -1;
        rd r = { copy, len, 0, 4, 0, "" };
        if (parse_modeldef(&r, major, minor, d, IO_NATNET_MAX_BODIES, &cnt) != 0) {
            if (!r.why[0]) abort();
        } else if (cnt < 0 || cnt > IO_NATNET_MAX_BODIES) {
            abort();
        }
    } else {
        static io_natnet_body_pose b[IO_NATNET_MAX_BODIES];
        int32_t frame = 0;
        double ts = 0;
        int count = -1;
        char why[256] = "";
        if (io_natnet_parse_frame(copy, len, major, minor, &frame, &ts, b, IO_NATNET_MAX_BODIES,
                                  &count, why, sizeof why) != 0) {
            if (!why[0]) abort();
        } else if (count < 0 || !isfinite(ts)) {
            abort();
        }
    }
    free(copy);
    return 0;
}
