/* test_fuse_normals.c - fuse_normal_smooth (src/fuse/fuse_normals.h):
 * the window sum over every pixel of the lit mask, pixels outside the mask
 * left alone, the rasterizer's zero normals adding nothing; a seam between
 * two parts' normals becomes a ramp in the lighting layer (the largest
 * jump of alpha-free diffuse lighting between neighbours shrinks); bad
 * arguments refused; pipe_create refuses an out-of-range radius. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse_normals.h"
#include "../src/pipe/pipe.h"

enum { W = 23, H = 17 };

static void window_sum(void **state)
{
    (void)state;
    static float n[W * H * 3], out[W * H * 3];
    static uint8_t m[W * H];
    tu_rng r = {7};
    for (int i = 0; i < W * H; i++) {
        m[i] = tu_int(&r, 4) ? 255 : 0;
        for (int c = 0; c < 3; c++) n[3 * i + c] = m[i] ? tu_range(&r, -1, 1) : 0.0f;
        if (tu_int(&r, 9) == 0) m[i] = 0;   /* covered, but not lit */
    }
    for (int i = 0; i < W * H * 3; i++) out[i] = -99.0f;
    for (int rad = 1; rad <= FUSE_NORMAL_SMOOTH_MAX; rad++) {
        assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, out, 3 * W, W, H, rad), FUSE_OK);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const float *o = &out[3 * (y * W + x)];
                if (!m[y * W + x]) {
                    assert_true(o[0] == -99.0f && o[1] == -99.0f && o[2] == -99.0f);
                    continue;
                }
                for (int c = 0; c < 3; c++) {
                    double s = 0.0;
                    for (int yy = y - rad; yy <= y + rad; yy++)
                        for (int xx = x - rad; xx <= x + rad; xx++)
                            if (xx >= 0 && yy >= 0 && xx < W && yy < H)
                                s += n[3 * (yy * W + xx) + c];
                    assert_true(fabs(s - o[c]) < 1e-5);
                }
            }
    }
}

/* Two parts meet at column 12: normals (0, 0, 1) left, tilted 60 degrees
 * right. Lit by a light along the view axis with no specular or Fresnel,
 * the lighting layer's alpha-free colour jumps at the seam; with radius 1
 * the largest jump between neighbours is half of it or less (a ramp over
 * three columns, uneven because the sums are normalised: 100 -> 51). */
static int max_jump(const float *nrm)
{
    static uint8_t P[W * H * 4], m[W * H], Q[W * H * 4];
    for (int i = 0; i < W * H; i++) {
        P[4 * i] = P[4 * i + 1] = P[4 * i + 2] = 200;
        P[4 * i + 3] = 255;
        m[i] = 255;
    }
    fuse_lighting L = fuse_lighting_default();
    L.light_count = 1;
    L.lights[0].dir[0] = 0.0f;
    L.lights[0].dir[1] = 0.0f;
    L.lights[0].dir[2] = 1.0f;
    for (int c = 0; c < 3; c++) {
        L.lights[0].color[c] = 1.0f;
        L.ambient[c] = 0.0f;
        L.tone[c] = 1.0f;
    }
    L.kd = 1.0f;
    L.ks = 0.0f;
    L.kf = 0.0f;
    fuse_intrinsics K = {1e6f, 1e6f, W / 2.0f, H / 2.0f};
    fuse_image Pi = {P, W, H, 4 * W}, Qi = {Q, W, H, 4 * W};
    assert_int_equal(fuse_light(&L, &K, &Pi, m, W, nrm, 3 * W, &Qi), FUSE_OK);
    int jump = 0;
    for (int x = 0; x + 1 < W; x++) {
        int d = abs((int)Q[4 * (8 * W + x)] - (int)Q[4 * (8 * W + x + 1)]);
        if (d > jump) jump = d;
    }
    return jump;
}

static void seam_becomes_ramp(void **state)
{
    (void)state;
    static float n[W * H * 3], s[W * H * 3];
    static uint8_t m[W * H];
    for (int i = 0; i < W * H; i++) {
        int right = i % W >= 12;
        n[3 * i + 0] = right ? 0.8660254f : 0.0f;
        n[3 * i + 1] = 0.0f;
        n[3 * i + 2] = right ? 0.5f : 1.0f;
        m[i] = 255;
    }
    int j0 = max_jump(n);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, s, 3 * W, W, H, 1), FUSE_OK);
    int j1 = max_jump(s);
    printf("seam: largest jump %d -> %d (of 255)\n", j0, j1);
    assert_true(j0 >= 90);
    assert_true(j1 * 2 <= j0 + 2);
}

static void bad_arguments(void **state)
{
    (void)state;
    static float n[W * H * 3], o[W * H * 3];
    static uint8_t m[W * H];
    assert_int_equal(fuse_normal_smooth(NULL, W, n, 3 * W, o, 3 * W, W, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, NULL, 3 * W, o, 3 * W, W, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, NULL, 3 * W, W, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W - 1, n, 3 * W, o, 3 * W, W, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W - 1, o, 3 * W, W, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, o, 3 * W - 1, W, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, o, 3 * W, 0, H, 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, o, 3 * W, W, H, 0), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, o, 3 * W, W, H,
                                        FUSE_NORMAL_SMOOTH_MAX + 1), FUSE_ERR_ARGS);
    assert_int_equal(fuse_normal_smooth(m, W, n, 3 * W, n + 3, 3 * W, W, H, 1), FUSE_ERR_ARGS);
    /* pipe_create refuses a radius out of range */
    kin_model km;
    memset(&km, 0, sizeof km);
    pipe_desc d = {0};
    d.normal_smooth = FUSE_NORMAL_SMOOTH_MAX + 1;
    assert_null(pipe_create(&d, &km));
    d.normal_smooth = -2; /* -1: refine's raw normals (pipe.h) */
    assert_null(pipe_create(&d, &km));
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(window_sum),
        cmocka_unit_test(seam_becomes_ramp),
        cmocka_unit_test(bad_arguments))
