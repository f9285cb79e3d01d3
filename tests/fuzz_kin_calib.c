/* fuzz_kin_calib.c - libFuzzer target of kin_user_calib_parse, the user
 * calibration file "egofuse-calib 1" (docs/tracking.md). A file that
 * parses formats again and parses to the same values. `make fuzz`, seeds
 * in tests/fuzz/corpus/kin_calib/; docs/fuzzing.md. */
#include <string.h>

#include "../src/kin/kin.h"
#include "fuzz/fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    kin_user_calib c;
    int line = -1;
    char why[256] = "";
    if (kin_user_calib_parse((const char *)data, size, &c, &line, why, sizeof why) != 0) {
        if (!why[0]) abort();
        return 0;
    }
    char buf[4096];
    int n = kin_user_calib_format(&c, buf, sizeof buf);
    if (n < 0 || n >= (int)sizeof buf) abort();
    kin_user_calib c2;
    if (kin_user_calib_parse(buf, (size_t)n, &c2, &line, why, sizeof why) != 0) abort();
    return 0;
}
