/* bench_sample.h - the sample model the benchmarks pose (header only):
 * DIR/scene.txt of samples/gen (build/gen_samples --out DIR) and the glTF
 * of its first frame (bench_raster.c, bench_lod.c); the posed model, the
 * sequence's timing, HMD and lighting, and the images of one eye of a
 * sample frame as the frame benchmarks feed them (bench_frame.c,
 * llvmpipe/llvmpipe_frame.c). */
#ifndef EGOFUSE_BENCH_SAMPLE_H
#define EGOFUSE_BENCH_SAMPLE_H

#include "../src/io/io.h"
#include "bench_util.h"

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

/* DIR/scene.txt into sc, the glTF of its first frame into model, the
 * scene's animation into *anim (NULL when the model has none) and its head
 * node (default "head") into *head (-1 when none): what the frame
 * benchmarks pose. 1 when loaded; else 0 after a line "<who>: why" on
 * stderr (with gen_hint, for a missing scene, how to generate the
 * samples), nothing held. */
static inline int bench_sample_posed(const char *dir, const char *who, int gen_hint, io_scene *sc,
                                     kin_model *model, const kin_animation **anim, int *head)
{
    char path[IO_PATH_MAX + 64];
    io_error err;
    snprintf(path, sizeof path, "%s/scene.txt", dir);
    if (io_scene_load(path, sc, &err) != IO_OK) {
        if (gen_hint)
            fprintf(stderr, "%s: %s (make build/gen_samples && build/gen_samples --out %s)\n", who,
                    err.msg, dir);
        else
            fprintf(stderr, "%s: %s\n", who, err.msg);
        return 0;
    }
    io_scene_frame_path(sc, sc->model, 0, path, sizeof path);
    if (io_gltf_load(path, model, &err) != IO_OK) {
        fprintf(stderr, "%s: %s\n", who, err.msg);
        return 0;
    }
    *anim = kin_model_find_anim(model, sc->animation);
    *head = kin_model_find_node(model, sc->head_node[0] ? sc->head_node : "head");
    return 1;
}

/* How the frame benchmarks play the sequence of sc: its frame rate (60
 * when it gives none) and number of frames, on the paper's HMD (its
 * description and geometry), under the scene's lighting. */
static inline void bench_sample_play(const io_scene *sc, float *fps, int *frames,
                                     kin_sthmd_desc *hmd, kin_sthmd_geometry *geo,
                                     fuse_lighting *light)
{
    *fps = sc->fps > 0 ? sc->fps : 60.0f;
    *frames = sc->frames;
    *hmd = kin_sthmd_desc_resolved(NULL);
    *geo = kin_sthmd_geometry_of(hmd);
    *light = io_scene_lighting(sc);
}

/* The image at path as w x h pixels of `channels` of `type` into img: 1
 * when it is; else 0 after a line "<who>: ..." on stderr, nothing held. */
static inline int bench_load_image(const char *path, io_type type, int channels, int w, int h,
                                   io_image *img, const char *who)
{
    io_error err;
    if (io_image_load(path, type, channels, img, &err) != IO_OK) {
        fprintf(stderr, "%s: %s\n", who, err.msg);
        return 0;
    }
    if (img->width != w || img->height != h) {
        fprintf(stderr, "%s: %s is %dx%d, expected %dx%d\n", who, path, img->width,
                img->height, w, h);
        io_image_free(img);
        return 0;
    }
    return 1;
}

/* Eye e of sequence frame fr of the scene, each image packed (no row
 * padding): the camera image (cw x ch) as YUYV into *yuyv, the virtual
 * image (lw x lh RGBA) into *virt and its depth (float) into *depth, NULL
 * when the scene has none. 1 when loaded; else 0 after a line "<who>: ..."
 * on stderr. */
static inline int bench_sample_eye(const io_scene *sc, int fr, int e, int cw, int ch, int lw,
                                   int lh, const char *who, uint8_t **yuyv, uint8_t **virt,
                                   float **depth)
{
    char path[IO_PATH_MAX + 64];
    io_image img = {0};
    io_scene_frame_path(sc, sc->camera[e], fr, path, sizeof path);
    if (!bench_load_image(path, IO_U8, 4, cw, ch, &img, who)) return 0;
    *yuyv = bench_xmalloc((size_t)cw * ch * 2, who);
    bench_rgba_to_yuyv(img.data, cw, ch, img.stride, *yuyv);
    io_image_free(&img);
    io_scene_frame_path(sc, sc->virt[e], fr, path, sizeof path);
    if (!bench_load_image(path, IO_U8, 4, lw, lh, &img, who)) return 0;
    *virt = bench_xmalloc((size_t)lw * lh * 4, who);
    for (int y = 0; y < lh; y++)
        memcpy(*virt + (size_t)y * lw * 4, (uint8_t *)img.data + (size_t)y * img.stride,
               (size_t)lw * 4);
    io_image_free(&img);
    *depth = NULL;
    if (sc->virt_depth[e][0]) {
        io_scene_frame_path(sc, sc->virt_depth[e], fr, path, sizeof path);
        if (!bench_load_image(path, IO_F32, 1, lw, lh, &img, who)) return 0;
        *depth = bench_xmalloc(sizeof(float) * lw * lh, who);
        for (int y = 0; y < lh; y++)
            memcpy(*depth + (size_t)y * lw, (uint8_t *)img.data + (size_t)y * img.stride,
                   sizeof(float) * lw);
        io_image_free(&img);
    }
    return 1;
}

#endif
