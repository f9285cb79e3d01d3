/* sample_model.h - the generated sample model (gen_samples' model/arms.glb)
 * loaded once per test group, as test_kin_rig.c, test_pipe_parts.c and
 * test_cli_track.c load it; skipped (not failed) without a generator.
 * Header-only (static inline); include after support/testutil.h,
 * <cmocka.h> and src/io/io.h. */
#ifndef EGOFUSE_SAMPLE_MODEL_H
#define EGOFUSE_SAMPLE_MODEL_H

#include <stdio.h>

/* The samples of tu_samples_dir(name, frames) into dir[dir_n], their
 * model/arms.glb into path[path_n] and loaded into *m. 1 when loaded; 0
 * when there is no generator (why says so, for a skip); -1 when the
 * samples or the model failed (the loader's message on stderr). */
static inline int tu_sample_model_load(const char *name, int frames, kin_model *m, char *dir,
                                       size_t dir_n, char *path, size_t path_n, char *why,
                                       size_t why_n)
{
    int r = tu_samples_dir(name, frames, dir, dir_n, why, why_n);
    if (r <= 0) return r;
    snprintf(path, path_n, "%s/model/arms.glb", dir);
    io_error err;
    if (io_gltf_load(path, m, &err) != IO_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return -1;
    }
    return 1;
}

/* Frees the model when it was loaded and removes what the samples'
 * name generated. */
static inline void tu_sample_model_free(const char *name, kin_model *m, int loaded)
{
    if (loaded) kin_model_free(m);
    tu_samples_remove(name);
}

/* Skips the test (printing why) when the group could not load the model. */
#define TU_NEED_MODEL(loaded, why)                                          \
    do {                                                                    \
        if (!(loaded)) {                                                    \
            print_message("%s\n", why);                                    \
            skip();                                                         \
        }                                                                   \
    } while (0)

#endif
