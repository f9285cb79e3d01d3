/* fuzz_io_calib.c - libFuzzer target of io_calib_parse, OpenCV calibration
 * files (YAML and XML, docs/lens.md). `make fuzz`, seeds in
 * tests/fuzz/corpus/io_calib/; docs/fuzzing.md. IO_OK with a lens that
 * kin_lens_check accepts and that projects its principal point's ray back
 * to the principal point; or an error with a message. Both cameras (a
 * stereo file's second) are read. */
#include <math.h>
#include <string.h>

#include "../src/io/io_calib.h"
#include "fuzz/fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    for (int cam = 0; cam < 2; cam++) {
        kin_lens L;
        io_error err;
        memset(&err, 0, sizeof err);
        if (io_calib_parse("fuzz.yml", (const char *)data, size, cam, &L, &err) == IO_OK) {
            kin_lens c = L;
            if (!kin_lens_check(&c, NULL, 0) || !(L.fx > 0) || !(L.fy > 0)) abort();
            double ray[3] = {0, 0, -1}, u, v;
            if (kin_lens_project(&L, ray, &u, &v) &&
                (fabs(u - (L.cx + 0.5)) > 1e-6 * (1 + fabs(L.cx)) ||
                 fabs(v - (L.cy + 0.5)) > 1e-6 * (1 + fabs(L.cy))))
                abort();
        } else if (err.msg[0] == '\0') {
            abort();
        }
    }
    return 0;
}
