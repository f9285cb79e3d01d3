/* fuzz_kin_track.c - libFuzzer target of kin_track_parse, the recorded
 * tracking file "egofuse-track 1" (docs/tracking.md): the counting pass,
 * then the filling pass must agree. `make fuzz`, seeds in
 * tests/fuzz/corpus/kin_track/; docs/fuzzing.md. */
#include <string.h>

#include "../src/kin/kin.h"
#include "fuzz/fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *text = (const char *)data;
    int count = -1, line = -1;
    char why[256] = "";
    if (kin_track_parse(text, size, NULL, 0, &count, &line, why, sizeof why) != 0) {
        if (!why[0]) abort();
        return 0;
    }
    if (count < 0 || (size_t)count > size) abort();
    kin_track_sample *s = malloc(sizeof *s * (size_t)(count ? count : 1));
    if (!s) return 0;
    int count2 = -1;
    why[0] = 0;
    if (kin_track_parse(text, size, s, count, &count2, &line, why, sizeof why) != 0 ||
        count2 != count)
        abort();
    for (int i = 0; i < count; i++) {
        char buf[1024];
        if (kin_track_format_line(&s[i], buf, sizeof buf) >= (int)sizeof buf) abort();
    }
    free(s);
    return 0;
}
