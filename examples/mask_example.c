/* mask_example.c - the coverage mask of a glTF model with the installed
 * egofuse library (the example of src/pipe/pipe_mask.h):
 *
 *   cc mask_example.c -o mask_example $(pkg-config --cflags --static --libs egofuse-io)
 *   ./mask_example MODEL.gltf mask.pgm
 *
 * writes the same bytes as
 *   egofuse mask MODEL.gltf --width 160 --height 120 --fov-y 60 \
 *       --eye 0,0,3 --target 0,0,0 --out mask.pgm
 */
#include <egofuse/io.h>
#include <egofuse/pipe_mask.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc != 3) { fprintf(stderr, "usage: %s MODEL.gltf OUT.pgm\n", argv[0]); return 2; }
    kin_model model;
    io_error err;
    if (io_gltf_load(argv[1], &model, &err) != IO_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    pipe_mask_desc d = {0};
    d.width = 160; d.height = 120; d.fov_y = 60.0f;
    d.eye[2] = 3.0f;                  // at (0,0,3) looking at the origin
    d.anim = NULL;                     // rest pose; or &model.anims[0], d.time = 0.5f
    uint8_t *mask = malloc((size_t)d.width * d.height);
    char why[256];
    int rc = 1;
    if (mask && pipe_mask_render(&model, &d, mask, NULL, NULL, why, sizeof why) == 0) {
        FILE *f = fopen(argv[2], "wb");
        if (f) {
            fprintf(f, "P5\n%d %d\n255\n", d.width, d.height);
            size_t n = (size_t)d.width * d.height;
            rc = fwrite(mask, 1, n, f) == n ? 0 : 1;
            if (fclose(f) != 0) rc = 1;
        }
    } else if (mask) {
        fprintf(stderr, "%s: %s\n", argv[1], why);
    }
    free(mask);
    kin_model_free(&model);
    return rc;
}
