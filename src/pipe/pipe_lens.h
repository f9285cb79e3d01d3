/* pipe_lens.h - the model's mask seen through a distorting lens.
 *
 * WHAT IT DOES
 *   The rasterizer draws straight-edged triangles: a pinhole camera. A
 *   real lens bends straight lines, so the mask of the model as the camera
 *   sees it is drawn in two steps: the model is rasterized through a
 *   pinhole camera (same pose, depth mapping and view space) covering
 *   every ray the lens images, then every pixel of the camera image takes
 *   the mask, depth and attributes (normals) of the pinhole sample nearest
 *   to where its own ray lands (nearest neighbour, so the mask stays 0/255
 *   and depths and normals are real samples, never blends):
 *       ray = kin_lens_unproject(lens, x + 0.5, y + 0.5)
 *       (u', v') = pinhole image of ray;  source = floor(u'), floor(v')
 *   The map from camera pixels to pinhole samples is computed once per
 *   lens (pipe_lens_map_init); per frame it is a gather.
 *
 * ACCURACY (measured by tests/test_pipe_lens.c)
 *   A camera pixel reads the pinhole sample whose centre is within half a
 *   pinhole pixel of its exact ray, per axis, so it can differ from the
 *   exact silhouette (the ray of its centre against the model) only where
 *   that ray lands within 0.5 sqrt(2) = 0.71 pinhole pixels of an edge,
 *   i.e. 0.71 / supersample camera pixels at the image centre's scale
 *   (less where a barrel lens compresses the periphery: the pinhole render
 *   has more pixels per degree there than the camera). Measured on a
 *   hand-sized polygon through a barrel lens (640x480, k1 = -0.29):
 *   94 of 17294 silhouette pixels differ at supersample 1 (63 at 2), the
 *   farthest 0.49 pinhole px from the edge; drawn straight (no warp),
 *   2207 differ. The default is supersample 1.
 *
 * LIMITS
 *   The pinhole render is at most PIPE_LENS_REACH times the camera's width
 *   and height (times supersample) and RAST_MAX_DIM: a lens that sees too
 *   far off its axis for that (fisheyes beyond about 75 degrees) keeps
 *   the central part; its outer pixels, like those beyond the lens model's
 *   fold (kin_lens.h), get no model: mask 0, depth 1, attributes 0
 *   (pipe_lens_map.unmapped counts them). A fisheye seeing the whole
 *   hemisphere would need several pinhole renders (a cube map) or
 *   triangles subdivided and projected through the lens: not done.
 */
#ifndef EGOFUSE_PIPE_LENS_H
#define EGOFUSE_PIPE_LENS_H

#include <stdint.h>

#include "../kin/kin.h"
#include "../raster/raster.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PIPE_LENS_REACH 3

typedef struct pipe_lens_map {
    int width, height;              /* the camera image (the lens's size) */
    int pin_width, pin_height;      /* the pinhole render */
    double pin_fx, pin_fy, pin_cx, pin_cy; /* its intrinsics (egofuse pixels) */
    int supersample;
    long unmapped;                  /* camera pixels without a source */
    int32_t *src;                   /* per camera pixel: pinhole index, -1 */
    /* the pinhole render's planes (pipe_lens_target) */
    float *depth;
    uint8_t *mask;
    float *attr;
    int attr_count;
    uint32_t *attr_n10;             /* the normals packed instead of attr
                                       (pipe_lens_map_init_n10), or NULL */
} pipe_lens_map;

/* Builds the map for a checked lens with a size (kin_lens_check;
 * kin_camera.lens is one) and allocates the pinhole planes (attr_count
 * floats per pixel: 0 or 3 for normals). supersample 1..4: pinhole pixels
 * per camera pixel at the centre, per axis. 0 on success; -1 with a
 * sentence in why (a lens without a size, out of memory). */
int pipe_lens_map_init(pipe_lens_map *m, const kin_lens *lens, int supersample, int attr_count,
                       char *why, int why_size);
/* As pipe_lens_map_init with attr_count 3, the normals packed as ef_n10
 * (src/cpu/ef_n10.h; rast_target.attr_n10): the pinhole target draws
 * them packed and pipe_lens_warp copies them into dst->attr_n10. */
int pipe_lens_map_init_n10(pipe_lens_map *m, const kin_lens *lens, int supersample, char *why,
                           int why_size);
void pipe_lens_map_free(pipe_lens_map *m);

/* The pinhole camera to draw the model with: cam's pose, view and depth
 * mapping (its projection's z row), the map's intrinsics and size. */
kin_camera pipe_lens_pinhole(const pipe_lens_map *m, const kin_camera *cam);
/* The map's pinhole planes as a raster target (clear it before drawing). */
rast_target pipe_lens_target(const pipe_lens_map *m);
/* Fills dst (m->width x m->height, the same attr_count, and attr_n10 set
 * when the map's normals are packed) from the pinhole planes: every pixel
 * equals the nearest pinhole sample's mask, depth and attributes, or is
 * clear (mask 0, depth 1, attributes 0). Pixels clear
 * before and after are not written (most of the image: the cost is the
 * model's pixels), so dst must start cleared (rast_target_clear) and hold
 * a clear pixel wherever its mask is 0 between calls, the rasterizer's
 * own contract for rast_context_clear. Returns the mask pixels set. */
long pipe_lens_warp(const pipe_lens_map *m, const rast_target *dst);

#ifdef __cplusplus
}
#endif

#endif
