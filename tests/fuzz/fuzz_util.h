/* fuzz_util.h - shared by the libFuzzer targets tests/fuzz_*.c
 * (docs/fuzzing.md): the input written to one scratch file per process,
 * for the parsers that take a path. */
#ifndef EGOFUSE_FUZZ_UTIL_H
#define EGOFUSE_FUZZ_UTIL_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Writes data to $TMPDIR/fuzz_NAME.PID.EXT into path; 0, or -1. */
static inline int fuzz_to_file(const char *name, const char *ext, const uint8_t *data,
                               size_t size, char *path, size_t path_size)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(path, path_size, "%s/fuzz_%s.%ld.%s", tmp && tmp[0] ? tmp : "/tmp", name,
             (long)getpid(), ext);
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    if (size && fwrite(data, 1, size, f) != size) {
        fclose(f);
        return -1;
    }
    return fclose(f) == 0 ? 0 : -1;
}
#endif
