/* pipe_mask.h - the coverage mask of a model as a library call: model and
 * camera in; mask, view-space normals and depth buffers out; no files.
 *
 * WHAT IT DOES
 *   pipe_mask_render() poses a kin_model (its rest pose, or time t of one
 *   of its animations), skins and morphs it, and rasterizes every mesh
 *   through a look-at perspective camera: exactly what `egofuse mask` does
 *   (src/cli/cmd_mask.c calls this function), so the buffers hold the same
 *   bytes as the files that command writes:
 *     mask     width*height bytes, 255 where a triangle covers the pixel
 *              centre (top-left fill rule, both faces drawn), 0 elsewhere;
 *     normals  width*height*3 bytes, RGB of the view-space unit normal of
 *              the nearest surface encoded n*0.5+0.5 (0 where nothing is
 *              drawn), as `--normals`;
 *     depth    width*height floats, window depth z_ndc*0.5+0.5 in [0,1]
 *              (1 where nothing is drawn), as `--depth`.
 *   Row 0 is the top of the view; pixel centres at (x+0.5, y+0.5). Camera:
 *   right-handed look-at from eye to target with up; OpenGL-style
 *   symmetric perspective, vertical field of view fov_y, aspect W/H.
 *
 * WHAT IT DOES NOT
 *   No file I/O (load a model with io_gltf_load of the io library, or fill
 *   a kin_model yourself), no threads. It allocates its scratch buffers
 *   per call and frees them before returning. Thread-safe for distinct
 *   output buffers (the model is only read).
 *
 * ERRORS
 *   Returns 0 on success. On a bad description (size out of 1..8192, a
 *   field of view outside (0, 180), eye == target, up zero or parallel to
 *   the view direction, near <= 0, far <= near, a non-finite value) or out
 *   of memory: returns -1, writes a message naming the field into why
 *   (when why_size > 0) and leaves the output buffers untouched.
 *
 * EXAMPLE (examples/mask_example.c; built against the installed library by
 * tests/test_install.c):
 *
 *   // cc mask_example.c $(pkg-config --cflags --static --libs egofuse-io)
 *   #include <egofuse/io.h>
 *   #include <egofuse/pipe_mask.h>
 *   #include <stdio.h>
 *   #include <stdlib.h>
 *
 *   int main(int argc, char **argv)
 *   {
 *       if (argc != 3) { fprintf(stderr, "usage: %s MODEL.gltf OUT.pgm\n", argv[0]); return 2; }
 *       kin_model model;
 *       io_error err;
 *       if (io_gltf_load(argv[1], &model, &err) != IO_OK) {
 *           fprintf(stderr, "%s\n", err.msg);
 *           return 1;
 *       }
 *       pipe_mask_desc d = {0};
 *       d.width = 160; d.height = 120; d.fov_y = 60.0f;
 *       d.eye[2] = 3.0f;                  // at (0,0,3) looking at the origin
 *       d.anim = NULL;                     // rest pose; or &model.anims[0], d.time = 0.5f
 *       uint8_t *mask = malloc((size_t)d.width * d.height);
 *       char why[256];
 *       int rc = 1;
 *       if (mask && pipe_mask_render(&model, &d, mask, NULL, NULL, why, sizeof why) == 0) {
 *           FILE *f = fopen(argv[2], "wb");
 *           if (f) {
 *               fprintf(f, "P5\n%d %d\n255\n", d.width, d.height);
 *               size_t n = (size_t)d.width * d.height;
 *               rc = fwrite(mask, 1, n, f) == n ? 0 : 1;
 *               if (fclose(f) != 0) rc = 1;
 *           }
 *       } else if (mask) {
 *           fprintf(stderr, "%s: %s\n", argv[1], why);
 *       }
 *       free(mask);
 *       kin_model_free(&model);
 *       return rc;
 *   }
 *
 *   The same mask: egofuse mask MODEL.gltf --width 160 --height 120
 *                  --fov-y 60 --eye 0,0,3 --target 0,0,0 --out mask.pgm
 */
#ifndef EGOFUSE_PIPE_MASK_H
#define EGOFUSE_PIPE_MASK_H

#include <stdint.h>

#include "../kin/kin.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pipe_mask_desc {
    int width, height;        /* pixels, 1..8192 */
    float fov_y;              /* vertical field of view, degrees, (0, 180) */
    float eye[3];             /* camera position (model units) */
    float target[3];          /* point looked at */
    float up[3];              /* up direction; all zero = 0,1,0 */
    float znear, zfar;        /* clip planes; 0 = 0.01 and 100 */
    const kin_animation *anim;/* NULL: rest pose; else one of model->anims */
    float time;               /* seconds into anim (clamped to it) */
    const kin_lens *lens;     /* NULL: the symmetric perspective of fov_y.
                                 Else a checked lens (kin_lens.h, e.g. from
                                 io_calib_load) replaces it: its intrinsics
                                 and distortion, scaled to width x height
                                 when it has another size (fov_y unused);
                                 a distorting lens is applied exactly as
                                 the pipeline does (pipe_lens.h) */
} pipe_mask_desc;

/* Renders model through the camera of d into mask (required, width*height
 * bytes), normals (NULL or width*height*3 bytes) and depth (NULL or
 * width*height floats). 0 on success; -1 with a message in why. */
int pipe_mask_render(const kin_model *model, const pipe_mask_desc *d,
                     uint8_t *mask, uint8_t *normals, float *depth,
                     char *why, int why_size);

#ifdef __cplusplus
}
#endif

#endif
