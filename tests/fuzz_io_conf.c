/* fuzz_io_conf.c - libFuzzer target of io_conf_load, the cockpit
 * configuration file (docs/cockpit.md). `make fuzz`, seeds in
 * tests/fuzz/corpus/io_conf/; docs/fuzzing.md. IO_OK with argc options
 * "--key=value" each with its origin, or an error with a message. */
#include <string.h>

#include "../src/io/io.h"
#include "../src/io/io_live.h"
#include "fuzz/fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[512];
    if (fuzz_to_file("io_conf", "conf", data, size, path, sizeof path)) return 0;
    io_conf_args a;
    io_error err;
    memset(&a, 0, sizeof a);
    memset(&err, 0, sizeof err);
    if (io_conf_load(path, &a, &err) == IO_OK) {
        if (a.argc < 0) abort();
        for (int i = 0; i < a.argc; i++)
            if (!a.argv[i] || strncmp(a.argv[i], "--", 2) || !a.origin[i]) abort();
        io_conf_free(&a);
    } else if (err.msg[0] == '\0') {
        abort();
    }
    return 0;
}
