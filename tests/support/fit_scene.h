/* fit_scene.h - the small synthetic scene of the fit tests (test_fit_band,
 * test_fit_shift): a pinhole camera at the origin looking down -Z (view =
 * identity), a rig whose every hand joint of side s is node s, world
 * matrices that only translate, the camera image painted from the true
 * mask, the image-wide colour model learned from it, the refinement's
 * parameters and scratch, and the IoU of two masks. Header-only (static
 * inline); include after support/testutil.h and <cmocka.h>. */
#ifndef EGOFUSE_TEST_FIT_SCENE_H
#define EGOFUSE_TEST_FIT_SCENE_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/fuse/fuse_refine.h"
#include "../../src/kin/kin.h"

/* A w x h camera of focal length f (pixels), principal point the centre. */
static inline kin_camera fit_scene_camera(int w, int h, float f)
{
    kin_camera c;
    memset(&c, 0, sizeof c);
    for (int i = 0; i < 4; i++) {
        c.view.m[i * 5] = 1.0f;
        c.world_from_cam.m[i * 5] = 1.0f;
    }
    c.width = w;
    c.height = h;
    c.fx = c.fy = f;
    c.cx = (float)w / 2.0f;
    c.cy = (float)h / 2.0f;
    return c;
}

/* Every hand joint of side s at node s. */
static inline void fit_scene_rig(kin_arm_rig *rig)
{
    memset(rig, 0, sizeof *rig);
    for (int s = 0; s < 2; s++)
        for (int j = 0; j < KIN_RIG_SIDE_JOINTS; j++) rig->joint[s][j] = s;
}

/* The translation to (x, y, z). */
static inline kin_mat4 fit_scene_at(float x, float y, float z)
{
    kin_mat4 m;
    memset(&m, 0, sizeof m);
    m.m[0] = m.m[5] = m.m[10] = m.m[15] = 1.0f;
    m.m[12] = x;
    m.m[13] = y;
    m.m[14] = z;
    return m;
}

/* img (RGBA, n pixels): skin (200, 150, 120) where truth is set, the
 * background (30, 40, 90) elsewhere, each colour channel plus uniform
 * noise in [-10, 10) from rng (clamped to 0..255, truncated), alpha 255. */
static inline void fit_scene_paint(uint8_t *img, const uint8_t *truth, long n, tu_rng *rng)
{
    for (long k = 0; k < n; k++) {
        const int skin = truth[k] != 0;
        const float base[3] = { skin ? 200.0f : 30.0f, skin ? 150.0f : 40.0f,
                                skin ? 120.0f : 90.0f };
        for (int c = 0; c < 3; c++) {
            float v = base[c] + tu_range(rng, -10.0f, 10.0f);
            img[4 * k + c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
        }
        img[4 * k + 3] = 255;
    }
}

/* Allocates the camera image *img (w x h RGBA), the true and the kinematic
 * masks *truth and *kin and the output mask *out (w x h bytes each;
 * contents undefined); fails the test when out of memory. */
static inline void fit_scene_alloc(int w, int h, uint8_t **img, uint8_t **truth, uint8_t **kin,
                                   uint8_t **out)
{
    *img = malloc((size_t)w * h * 4);
    *truth = malloc((size_t)w * h);
    *kin = malloc((size_t)w * h);
    *out = malloc((size_t)w * h);
    assert_true(*img && *truth && *kin && *out);
}

/* img (w x h) painted from truth by fit_scene_paint (the noise seeded with
 * seed), and the image-wide colour model g (5 bits) learned from it where
 * truth is set; *llr (g's table) and *cscratch (the learning's scratch)
 * are allocated here, for the caller to free. */
static inline void fit_scene_learn(fuse_colour_model *g, uint8_t *img, const uint8_t *truth,
                                   int w, int h, uint64_t seed, float **llr, void **cscratch)
{
    tu_rng rng = { seed };
    fit_scene_paint(img, truth, (long)w * h, &rng);
    *cscratch = malloc(fuse_colour_model_scratch_size(5));
    *llr = malloc(sizeof(float) << 15);
    assert_true(*cscratch && *llr);
    g->bits = 5;
    g->llr = *llr;
    fuse_image P = { img, w, h, 4 * w };
    assert_int_equal(fuse_colour_model_learn(g, &P, truth, w, 4, 1, 3.0f, 64, *cscratch,
                                             fuse_colour_model_scratch_size(5)),
                     FUSE_OK);
}

/* The band refinement's parameters of the tests: the defaults with a
 * 16 px band and 5-bit colour bins. */
static inline fuse_refine_params fit_scene_refine_params(void)
{
    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = 16;
    rp.bits = 5;
    return rp;
}

/* size bytes of 16-byte aligned scratch (free()); fails the test when out
 * of memory. */
static inline void *fit_scene_scratch(size_t size)
{
    void *p = aligned_alloc(16, (size + 15) & ~(size_t)15);
    assert_non_null(p);
    return p;
}

/* The IoU of two masks of n bytes (set: >= 128); 1 when both are empty. */
static inline double fit_scene_iou(const uint8_t *a, const uint8_t *b, long n)
{
    long i = 0, u = 0;
    for (long k = 0; k < n; k++) {
        int x = a[k] >= 128, y = b[k] >= 128;
        i += x && y;
        u += x || y;
    }
    return u ? (double)i / (double)u : 1.0;
}

#endif
