/* sample_model.h - the generated sample model (gen_samples' model/arms.glb)
 * loaded once per test group (tu_sample_group), as test_kin_rig.c,
 * test_pipe_parts.c and test_cli_track.c load it; skipped (not failed) without a generator.
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

/* One test group's samples and model: name and frames as for
 * tu_samples_dir, the rest filled by tu_sample_group_setup. */
typedef struct tu_sample_group {
    const char *name;
    int frames;
    kin_model model;
    int loaded;          /* 1: model loaded (tu_sample_model_load) */
    char dir[1024];      /* the samples' folder */
    char path[1200];     /* their model/arms.glb */
    char skip[3000];     /* why not loaded, for TU_NEED_MODEL */
} tu_sample_group;

/* The body of a cmocka group setup: loads g's samples and model; 0 (also
 * when there is no generator: g->loaded 0, the tests skip) or -1. */
static inline int tu_sample_group_setup(tu_sample_group *g)
{
    const int r = tu_sample_model_load(g->name, g->frames, &g->model, g->dir, sizeof g->dir,
                                       g->path, sizeof g->path, g->skip, sizeof g->skip);
    g->loaded = r > 0;
    return r < 0 ? r : 0;
}

/* The body of the matching group teardown. */
static inline void tu_sample_group_teardown(tu_sample_group *g)
{
    tu_sample_model_free(g->name, &g->model, g->loaded);
}

/* Defines the file's group `static tu_sample_group var` of the samples
 * named samples (nframes frames) and its cmocka group fixtures
 * group_setup and group_teardown, which load and free it. */
#define TU_SAMPLE_GROUP(var, samples, nframes)                              \
    static tu_sample_group var = { .name = samples, .frames = nframes };    \
    static int group_setup(void **state)                                    \
    {                                                                       \
        (void)state;                                                        \
        return tu_sample_group_setup(&var);                                 \
    }                                                                       \
    static int group_teardown(void **state)                                 \
    {                                                                       \
        (void)state;                                                        \
        tu_sample_group_teardown(&var);                                     \
        return 0;                                                           \
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
