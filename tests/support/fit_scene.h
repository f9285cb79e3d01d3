/* fit_scene.h - the small synthetic scene of the fit tests (test_fit_band,
 * test_fit_shift): a pinhole camera at the origin looking down -Z (view =
 * identity), a rig whose every hand joint of side s is node s, world
 * matrices that only translate, the camera image painted from the true
 * mask, and the IoU of two masks. Header-only (static inline); include
 * after support/testutil.h. */
#ifndef EGOFUSE_TEST_FIT_SCENE_H
#define EGOFUSE_TEST_FIT_SCENE_H

#include <stdint.h>
#include <string.h>

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
