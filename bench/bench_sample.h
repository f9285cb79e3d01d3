/* bench_sample.h - the sample model the benchmarks pose (header only):
 * DIR/scene.txt of samples/gen (build/gen_samples --out DIR) and the glTF
 * of its first frame. Shared by bench_raster.c and bench_lod.c. */
#ifndef EGOFUSE_BENCH_SAMPLE_H
#define EGOFUSE_BENCH_SAMPLE_H

#include "../src/io/io.h"

#include <stdio.h>

/* DIR/scene.txt into sc, the glTF of its first frame into model and its
 * file name into path (path_size bytes). 1 when loaded; else 0 after a
 * line "<pfx>sample model: skipped (why)" on stdout, nothing held. */
static inline int bench_sample_model(const char *dir, const char *pfx, io_scene *sc,
                                     kin_model *model, char *path, size_t path_size)
{
    io_error err;
    snprintf(path, path_size, "%s/scene.txt", dir);
    if (io_scene_load(path, sc, &err) != IO_OK) {
        printf("%ssample model: skipped (%s; build/gen_samples --out %s)\n", pfx, err.msg, dir);
        return 0;
    }
    io_scene_frame_path(sc, sc->model, 0, path, path_size);
    if (io_gltf_load(path, model, &err) != IO_OK) {
        printf("%ssample model: skipped (%s)\n", pfx, err.msg);
        return 0;
    }
    return 1;
}

#endif
