/* fuzz_io_scene.c - libFuzzer target of io_scene_load, the scene file
 * (docs/scene.md). `make fuzz`, seeds in tests/fuzz/corpus/io_scene/;
 * docs/fuzzing.md. IO_OK, or an error with a message; never a crash. */
#include <string.h>

#include "../src/io/io.h"
#include "fuzz/fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[512];
    if (fuzz_to_file("io_scene", "txt", data, size, path, sizeof path)) return 0;
    io_scene s;
    io_error err;
    memset(&err, 0, sizeof err);
    if (io_scene_load(path, &s, &err) == IO_OK) {
        if (s.frames <= 0 || s.light_count < 0 || s.light_count > 8) abort();
        (void)io_scene_lighting(&s);
        char frame[IO_PATH_MAX + 64];
        io_scene_frame_path(&s, s.camera[0], s.frames - 1, frame, sizeof frame);
    } else if (err.msg[0] == '\0') {
        abort();
    }
    return 0;
}
