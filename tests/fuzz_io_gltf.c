/* fuzz_io_gltf.c - libFuzzer entry for io_gltf_load (not built by make).
 *
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -D_GNU_SOURCE \
 *       tests/fuzz_io_gltf.c src/io/io_common.c src/kin/kin_model.c \
 *       src/io/io_gltf.cpp -ltinygltf -lstdc++ -lm -o fuzz_io_gltf
 *   ./fuzz_io_gltf corpus/      # seed corpus: ../shared/gltf/ (.gltf, .glb)
 *
 * io_gltf_load reads a path, so each input is written to one scratch file
 * per process first. Every input must give IO_OK and a model that passes
 * kin_model_validate(), or an error with a message; never a crash or leak.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/io/io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/fuzz_io_gltf.%ld.glb", (long)getpid());
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    if (size && fwrite(data, 1, size, f) != size) {
        fclose(f);
        return 0;
    }
    fclose(f);
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
