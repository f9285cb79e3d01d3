/* test_pipe_gclear.c - the pipe's G-buffer clear leaves the normals of
 * the last frame where no reader looks (rast_context_clear_keep_attr,
 * docs/raster.md section 13): no stale normal may reach an output.
 *
 * A tilted, tessellated quad (varied normals) seen from close (a large
 * mask) and then from farther (a small one) through one pipe gives the
 * same bytes, both eyes, as a fresh pipe drawing only the second frame;
 * for the plain path (normals not cleared) and each path that keeps the
 * clear (refined mask, smoothed normals, anti-aliased edges, eye
 * reprojection), and back to the close view once more.
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe.h"
#include "support/pipe_frames.h"

static void grid_model(kin_model *m, int n, float s, float z)
{
    int nv = n * n, nt = 2 * (n - 1) * (n - 1);
    tu_mesh_parts g = tu_mesh_model(m, "head", "grid", nv, 3 * nt, 1);
    g.rest[1].r = kin_quat_axis_angle(kin_v3(1, 0, 0), 0.3f);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            float *p = g.pos + 3 * (y * n + x);
            p[0] = -s + 2 * s * x / (n - 1);
            p[1] = -s + 2 * s * y / (n - 1);
            p[2] = z + 0.02f * sinf(7.0f * p[0]) * cosf(5.0f * p[1]);
            float *q = g.nrm + 3 * (y * n + x); /* varied, unit */
            q[0] = 0.3f * sinf(5.0f * p[0]);
            q[1] = 0.3f * cosf(3.0f * p[1]);
            q[2] = sqrtf(1.0f - q[0] * q[0] - q[1] * q[1]);
        }
    int k = 0;
    for (int y = 0; y + 1 < n; y++)
        for (int x = 0; x + 1 < n; x++) {
            uint32_t a = (uint32_t)(y * n + x), b = a + 1, c = a + (uint32_t)n, d = c + 1;
            g.idx[k++] = a; g.idx[k++] = b; g.idx[k++] = d;
            g.idx[k++] = a; g.idx[k++] = d; g.idx[k++] = c;
        }
}

/* One frame with the quad scaled by k about the head (its node's local
 * pose); the outputs are copied into out[eye]. */
static void run(pipe_ctx *p, float k, uint8_t *out[2], double *coverage)
{
    tu_frame_bufs b;
    pipe_frame_in in;
    tu_frame_make(&b, &in, 11, 640, 480, 1280, 800);
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0.01f, -0.02f, 0.0f),
                                     kin_quat_axis_angle(kin_v3(0, 1, 0), 0.05f));
    in.head_node = -1;
    in.world_from_head = &head;
    kin_transform locals[2] = {kin_transform_identity(), kin_transform_identity()};
    locals[1].s = kin_v3(k, k, k);
    locals[1].t = kin_v3(0.0f, 0.0f, -0.5f);
    locals[1].r = kin_quat_axis_angle(kin_v3(1, 0, 0), 0.3f);
    in.locals = locals;
    pipe_frame_stats st;
    char why[200] = "";
    assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
    for (int e = 0; e < 2; e++) memcpy(out[e], b.out[e], 1280 * 800 * 4);
    if (coverage) *coverage = st.coverage[0];
    tu_frame_free(&b);
}

static void large_then_small(void **state)
{
    const int variant = (int)(intptr_t)*state;
    kin_model m;
    grid_model(&m, 24, 0.08f, 0.0f); /* at the node: placed by run */
    pipe_desc d = {0};
    d.threads = 1;
    if (variant == 1) d.refine_band = 6;
    if (variant == 2) d.normal_smooth = 2;
    if (variant == 3) d.aa_samples = 4;
    if (variant == 4) d.eye_view = PIPE_VIEW_REPROJECT;
    pipe_ctx *a = pipe_create(&d, &m), *f = pipe_create(&d, &m);
    assert_non_null(a);
    assert_non_null(f);
    uint8_t *oa[2], *of[2];
    for (int e = 0; e < 2; e++) {
        oa[e] = malloc(1280 * 800 * 4);
        of[e] = malloc(1280 * 800 * 4);
        assert_non_null(oa[e]);
        assert_non_null(of[e]);
    }
    double big = 0, small = 0;
    run(a, 2.5f, oa, &big);   /* close: a large mask */
    run(a, 0.6f, oa, &small);  /* farther: a small one, same context */
    assert_true(big > 4.0 * small && small > 0.005);
    run(f, 0.6f, of, NULL);    /* a fresh pipe */
    for (int e = 0; e < 2; e++) assert_memory_equal(oa[e], of[e], 1280 * 800 * 4);
    /* and the large view again after the small one */
    pipe_ctx *g = pipe_create(&d, &m);
    assert_non_null(g);
    run(a, 2.5f, oa, NULL);
    run(g, 2.5f, of, NULL);
    for (int e = 0; e < 2; e++) assert_memory_equal(oa[e], of[e], 1280 * 800 * 4);
    for (int e = 0; e < 2; e++) {
        free(oa[e]);
        free(of[e]);
    }
    pipe_destroy(g);
    pipe_destroy(f);
    pipe_destroy(a);
    kin_model_free(&m);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test_prestate(large_then_small, (void *)0),
        cmocka_unit_test_prestate(large_then_small, (void *)1),
        cmocka_unit_test_prestate(large_then_small, (void *)2),
        cmocka_unit_test_prestate(large_then_small, (void *)3),
        cmocka_unit_test_prestate(large_then_small, (void *)4))
