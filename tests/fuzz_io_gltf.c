/* fuzz_io_gltf.c - libFuzzer target of io_gltf_load (glTF and GLB,
 * io_glb_check included). Built by `make fuzz` into build-fuzz/fuzz/,
 * seeds in tests/fuzz/corpus/io_gltf/; docs/fuzzing.md.
 *
 * io_gltf_load reads a path, so each input is written to one scratch file
 * per process first. Every input must give IO_OK and a model that passes
 * kin_model_validate(), or an error with a message; never a crash or leak.
 */
#include <string.h>

#include "../src/io/io.h"
#include "fuzz/fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[512];
    if (fuzz_to_file("io_gltf", "glb", data, size, path, sizeof path)) return 0;
    kin_model m;
    io_error err;
    if (io_gltf_load(path, &m, &err) == IO_OK) {
        char why[256];
        if (kin_model_validate(&m, why, sizeof why) != 0) abort();
        kin_model_free(&m);
    } else if (err.msg[0] == '\0') {
        abort();
    }
    return 0;
}
