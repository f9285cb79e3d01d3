/* test_raster_basic.c - the rasterizer's contract outside coverage itself:
 * argument validation (nothing drawn on error), target clear with strides,
 * result strings, vertex transforms, non-finite vertices, culling and
 * winding, degenerate triangles, stats, and a seeded determinism check
 * against a recorded CRC32. */
#include "support/testutil.h"
#include <cmocka.h>

#include "test_raster_util.h"
#include "support/fixture.h"

/* CRC32 of depth, mask and attributes of the seeded soup below. Update it
 * (the test prints the new value) only when the rasterization rules change
 * on purpose, and say so in docs/raster.md's change log. */
#define SOUP_CRC 0x1A837D19u

static uint32_t target_crc(const rast_target *t)
{
    uint32_t c = 0;
    for (int y = 0; y < t->height; y++) {
        c = tu_crc32(c, t->mask + (size_t)y * t->mask_stride, (size_t)t->width);
        if (t->depth)
            c = tu_crc32(c, t->depth + (size_t)y * t->depth_stride,
                         (size_t)t->width * sizeof(float));
        if (t->attr)
            c = tu_crc32(c, t->attr + (size_t)y * t->attr_stride,
                         (size_t)t->width * t->attr_count * sizeof(float));
    }
    return c;
}

/* Whole buffers including padding. */
static uint32_t buffer_crc(const rast_target *t)
{
    uint32_t c = tu_crc32(0, t->mask, (size_t)t->mask_stride * t->height);
    if (t->depth)
        c = tu_crc32(c, t->depth, (size_t)t->depth_stride * t->height * sizeof(float));
    if (t->attr)
        c = tu_crc32(c, t->attr, (size_t)t->attr_stride * t->height * sizeof(float));
    return c;
}

/* A mesh of two on-screen triangles with 2 attributes. */
static const float k_clip[] = {
    -0.5f, -0.5f, 0.0f, 1.0f,   0.5f, -0.5f, 0.0f, 1.0f,
     0.0f,  0.5f, 0.0f, 1.0f,  -0.9f,  0.9f, 0.5f, 1.0f,
};
static const float k_attr[] = { 0, 1, 1, 0, 0.5f, 0.5f, 1, 1 };
static const uint32_t k_idx[] = { 0, 1, 2, 0, 2, 3 };

static rast_mesh_desc valid_mesh(void)
{
    rast_mesh_desc d = { k_clip, 4, k_attr, 2, k_idx, 2, RAST_CULL_NONE };
    return d;
}

static void test_validation(void **state)
{
    (void)state;
    rast_target t = rt_make(16, 16, 1, 2, 3);
    rast_mesh_desc d = valid_mesh();
    uint32_t crc0 = buffer_crc(&t);
    rast_stats st;
    memset(&st, 0, sizeof st);

    assert_int_equal(rast_draw(NULL, &d, &st), RAST_ERR_ARGS);
    assert_int_equal(rast_draw(&t, NULL, &st), RAST_ERR_ARGS);

    rast_target b = t;
    b.mask = NULL;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_ARGS);
    b = t; b.mask_stride = 15;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_ARGS);
    b = t; b.depth_stride = 15;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_ARGS);
    b = t; b.attr_stride = 16 * 2 - 1;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_ARGS);
    b = t; b.attr_count = 1;          /* mismatch with the mesh */
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_ARGS);
    b = t; b.width = 0;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_SIZE);
    b = t; b.height = -3;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_SIZE);
    b = t; b.width = RAST_MAX_DIM + 1;
    assert_int_equal(rast_draw(&b, &d, &st), RAST_ERR_SIZE);

    rast_mesh_desc e = d;
    e.attr_count = 3;
    assert_int_equal(rast_draw(&t, &e, &st), RAST_ERR_ARGS);
    e = d; e.clip = NULL;
    assert_int_equal(rast_draw(&t, &e, &st), RAST_ERR_ARGS);
    e = d; e.indices = NULL;
    assert_int_equal(rast_draw(&t, &e, &st), RAST_ERR_ARGS);
    e = d; e.attr = NULL;
    assert_int_equal(rast_draw(&t, &e, &st), RAST_ERR_ARGS);
    e = d; e.tri_count = -1;
    assert_int_equal(rast_draw(&t, &e, &st), RAST_ERR_ARGS);
    e = d; e.cull = (rast_cull)7;
    assert_int_equal(rast_draw(&t, &e, &st), RAST_ERR_ARGS);

    /* Both at RAST_MAX_ATTRS + 1. */
    b = t; b.attr_count = RAST_MAX_ATTRS + 1; b.attr = NULL;
    e = d; e.attr_count = RAST_MAX_ATTRS + 1;
    assert_int_equal(rast_draw(&b, &e, &st), RAST_ERR_ARGS);

    /* Nothing drawn, no stats touched. */
    assert_int_equal(buffer_crc(&t), crc0);
    assert_int_equal(st.tris_in, 0);

    /* The valid call works; without attributes in the target too. */
    assert_int_equal(rast_draw(&t, &d, &st), RAST_OK);
    assert_int_equal(st.tris_in, 2);
    assert_true(st.pixels_written > 0);
    b = t; b.attr = NULL;
    assert_int_equal(rast_draw(&b, &d, NULL), RAST_OK);
    rt_free(&t);
}

/* The index tests' fixture: a 16 x 16 target with depth, 2 attributes
 * and 1 byte of padding as the test's state. */
TU_FIXTURE(index, rast_target, t, *t = rt_make(16, 16, 1, 2, 1), rt_free(t))

/* One bad index at every position of a longer index list (the check
 * runs 4 indices at a time plus a scalar tail), for the smallest bad
 * value, one with the top bit set and the largest. */
static void test_index_every_position(void **state)
{
    rast_target *t = *state;
    rast_mesh_desc d = valid_mesh();
    enum { NT = 11 };
    uint32_t idx[3 * NT];
    const uint32_t bad[3] = { 4, 0x80000000u, 0xFFFFFFFFu };
    d.indices = idx;
    d.tri_count = NT;
    for (int pos = 0; pos < 3 * NT; pos++)
        for (int b = 0; b < 3; b++) {
            for (int i = 0; i < 3 * NT; i++)
                idx[i] = (uint32_t)(i % 4);
            assert_int_equal(rast_draw(t, &d, NULL), RAST_OK);
            idx[pos] = bad[b];
            assert_int_equal(rast_draw(t, &d, NULL), RAST_ERR_INDEX);
        }
    d.vertex_count = 0;   /* no vertex: every index is out of range */
    idx[0] = 0;
    assert_int_equal(rast_draw(t, &d, NULL), RAST_ERR_INDEX);
    d.tri_count = 0;
    assert_int_equal(rast_draw(t, &d, NULL), RAST_OK);
}

static void test_index_out_of_range(void **state)
{
    rast_target *t = *state;
    rast_mesh_desc d = valid_mesh();
    uint32_t idx[6] = { 0, 1, 2, 0, 2, 4 };   /* 4 == vertex_count */
    d.indices = idx;
    uint32_t crc0 = buffer_crc(t);
    rast_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_draw(t, &d, &st), RAST_ERR_INDEX);
    assert_int_equal(buffer_crc(t), crc0);   /* first triangle not drawn */
    assert_int_equal(st.tris_in, 0);
    idx[5] = 0xFFFFFFFFu;
    assert_int_equal(rast_draw(t, &d, &st), RAST_ERR_INDEX);
    idx[5] = 3;
    assert_int_equal(rast_draw(t, &d, &st), RAST_OK);
    assert_int_not_equal(buffer_crc(t), crc0);
}

static void test_zero_size_and_empty(void **state)
{
    (void)state;
    rast_target t = rt_make(8, 8, 1, 0, 0);
    rast_mesh_desc d;
    memset(&d, 0, sizeof d);             /* no vertices, no triangles */
    rast_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(rast_draw(&t, &d, &st), RAST_OK);
    assert_int_equal(st.tris_in, 0);
    rast_target z = t;
    z.width = 0;
    z.height = 0;
    assert_int_equal(rast_draw(&z, &d, &st), RAST_ERR_SIZE);
    rast_target_clear(&z);               /* a no-op, must not crash */
    rt_free(&t);
}

static void test_clear_keeps_padding(void **state)
{
    (void)state;
    rast_target t = rt_make(5, 4, 1, 3, 2);
    memset(t.mask, 0x5A, (size_t)t.mask_stride * t.height);
    for (int i = 0; i < t.depth_stride * t.height; i++) t.depth[i] = -7.0f;
    for (int i = 0; i < t.attr_stride * t.height; i++) t.attr[i] = -7.0f;
    rast_target_clear(&t);
    for (int y = 0; y < t.height; y++) {
        for (int x = 0; x < t.mask_stride; x++)
            assert_int_equal(t.mask[y * t.mask_stride + x], x < 5 ? 0 : 0x5A);
        for (int x = 0; x < t.depth_stride; x++)
            assert_true(t.depth[y * t.depth_stride + x] == (x < 5 ? 1.0f : -7.0f));
        for (int x = 0; x < t.attr_stride; x++)
            assert_true(t.attr[y * t.attr_stride + x] == (x < 15 ? 0.0f : -7.0f));
    }
    rt_free(&t);
}

static void test_result_str(void **state)
{
    (void)state;
    const char *s[4] = { rast_result_str(RAST_OK), rast_result_str(RAST_ERR_ARGS),
                         rast_result_str(RAST_ERR_SIZE), rast_result_str(RAST_ERR_INDEX) };
    for (int i = 0; i < 4; i++) {
        assert_non_null(s[i]);
        assert_true(strlen(s[i]) > 0);
        for (int j = 0; j < i; j++)
            assert_string_not_equal(s[i], s[j]);
    }
    assert_non_null(rast_result_str((rast_result)99));
}

static void test_transform_points(void **state)
{
    (void)state;
    /* Column-major: translation in m[12..14], row 3 = (0, 0, -1, 0). */
    const float m[16] = { 2, 0, 0, 0,   0, 3, 0, 0,   1, 1, -2, -1,   5, -4, 7, 0 };
    const float p[6] = { 1, 2, 3,  -1, 0.5f, -2 };
    float c[8];
    rast_transform_points(m, p, 2, c);
    const float want[8] = { 2 + 3 + 5, 6 + 3 - 4, -6 + 7, -3,
                            -2 - 2 + 5, 1.5f - 2 - 4, 4 + 7, 2 };
    for (int i = 0; i < 8; i++)
        assert_true(c[i] == want[i]);
}

static void test_transform_dirs(void **state)
{
    (void)state;
    tu_rng r = { 11 };
    /* Rotation about z by 30 deg, scaled by 3 (the scale must vanish). */
    const double a = 30.0 * 3.14159265358979323846 / 180.0;
    const float m[16] = { (float)(3 * cos(a)), (float)(3 * sin(a)), 0, 0,
                          (float)(-3 * sin(a)), (float)(3 * cos(a)), 0, 0,
                          0, 0, 3, 0,  9, 9, 9, 1 };
    for (int i = 0; i < 50; i++) {
        float v[3];
        for (int k = 0; k < 3; k++) v[k] = tu_range(&r, -2, 2);   /* in order */
        float o[3];
        rast_transform_dirs(m, v, 1, o);
        double len = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
        double ex = (cos(a) * v[0] - sin(a) * v[1]) / len;
        double ey = (sin(a) * v[0] + cos(a) * v[1]) / len;
        double ez = v[2] / len;
        assert_true(fabs(o[0] - ex) < 1e-6 && fabs(o[1] - ey) < 1e-6 &&
                    fabs(o[2] - ez) < 1e-6);
    }
    float z[6] = { 0, 0, 0, 1e-30f, 0, 0 }, o[6];
    rast_transform_dirs(m, z, 2, o);
    assert_true(o[0] == 0.0f && o[1] == 0.0f && o[2] == 0.0f);
    /* A tiny vector is still normalised (no underflow to zero). */
    assert_true(fabs(o[3] - cos(a)) < 1e-6 && fabs(o[4] - sin(a)) < 1e-6);
}

static void test_nonfinite_dropped(void **state)
{
    (void)state;
    rast_target t = rt_make(16, 16, 1, 0, 0);
    const float bad[4] = { NAN, INFINITY, -INFINITY, NAN };
    for (int which = 0; which < 4; which++) {
        for (int comp = 0; comp < 4; comp++) {
            float clip[12] = { -1, -1, 0, 1,   1, -1, 0, 1,   0, 1, 0, 1 };
            clip[4 * (which % 3) + comp] = bad[(which + comp) % 4];
            rast_stats st;
            memset(&st, 0, sizeof st);
            rast_target_clear(&t);
            assert_int_equal(rt_draw_tri(&t, clip, NULL, RAST_CULL_NONE, &st), RAST_OK);
            assert_int_equal(st.tris_in, 1);
            assert_int_equal(st.tris_nonfinite, 1);
            assert_int_equal(st.tris_drawn, 0);
            assert_int_equal(st.pixels_written, 0);
            assert_int_equal(rt_count_mask(&t, NULL), 0);
        }
    }
    /* Finite but near FLT_MAX: must not produce NaN pixels or crash. */
    float huge[12] = { -3e38f, -3e38f, 0, 1,   3e38f, -3e38f, 0, 1,
                       0, 3e38f, 3e38f, 3e38f };
    rast_stats st;
    memset(&st, 0, sizeof st);
    rast_target_clear(&t);
    assert_int_equal(rt_draw_tri(&t, huge, NULL, RAST_CULL_NONE, &st), RAST_OK);
    for (int i = 0; i < 16 * 16; i++)
        assert_true(t.depth[i] >= 0.0f && t.depth[i] <= 1.0f);
    rt_free(&t);
}

static void test_culling_and_winding(void **state)
{
    (void)state;
    rast_target t = rt_make(32, 32, 0, 0, 0);
    /* Counter-clockwise in NDC (y up): front. */
    const float ccw[12] = { -0.8f, -0.7f, 0, 1,   0.9f, -0.6f, 0, 1,   0.1f, 0.8f, 0, 1 };
    const float cw[12] = { -0.8f, -0.7f, 0, 1,   0.1f, 0.8f, 0, 1,   0.9f, -0.6f, 0, 1 };
    rast_stats st;
    uint32_t ref;
    long n;

    memset(&st, 0, sizeof st);
    rast_target_clear(&t);
    rt_draw_tri(&t, ccw, NULL, RAST_CULL_NONE, &st);
    n = rt_count_mask(&t, NULL);
    ref = tu_crc32(0, t.mask, 32 * 32);
    assert_true(n > 100);

    rast_target_clear(&t);
    rt_draw_tri(&t, cw, NULL, RAST_CULL_NONE, &st);
    assert_int_equal(tu_crc32(0, t.mask, 32 * 32), ref);   /* same pixels */

    rast_target_clear(&t);
    rt_draw_tri(&t, ccw, NULL, RAST_CULL_BACK, &st);
    assert_int_equal(tu_crc32(0, t.mask, 32 * 32), ref);
    rast_target_clear(&t);
    rt_draw_tri(&t, cw, NULL, RAST_CULL_FRONT, &st);
    assert_int_equal(tu_crc32(0, t.mask, 32 * 32), ref);
    assert_int_equal(st.tris_culled, 0);

    rast_target_clear(&t);
    rt_draw_tri(&t, cw, NULL, RAST_CULL_BACK, &st);
    rt_draw_tri(&t, ccw, NULL, RAST_CULL_FRONT, &st);
    assert_int_equal(rt_count_mask(&t, NULL), 0);
    assert_int_equal(st.tris_culled, 2);
    assert_int_equal(st.tris_drawn, 4);
    assert_int_equal(st.tris_in, 6);
    assert_int_equal(st.pixels_written, 4 * n);

    /* A mirrored projection (negative w) keeps the facing of the
     * projected triangle: scaling all of x, y, z, w by -1 puts it behind
     * the eye, where it is clipped away entirely. */
    float neg[12];
    for (int i = 0; i < 12; i++) neg[i] = -ccw[i];
    rt_expect_clipped_away(&t, neg);
    rt_free(&t);
}

static void test_degenerate(void **state)
{
    (void)state;
    rast_target t = rt_make(64, 32, 1, 0, 0);
    rast_stats st;
    memset(&st, 0, sizeof st);
    float clip[12];
    /* Collinear in fixed point. */
    rt_clip_at(100, 100, 64, 32, 0.1f, 1, clip);
    rt_clip_at(3000, 1000, 64, 32, 0.1f, 1, clip + 4);
    rt_clip_at(5900, 1900, 64, 32, 0.1f, 1, clip + 8);
    rt_draw_tri(&t, clip, NULL, RAST_CULL_NONE, &st);
    assert_int_equal(st.tris_degenerate, 1);
    /* Three distinct float positions within half a sub-pixel: one snap. */
    const float tiny[12] = { 0.0f, 0.0f, 0, 1,   1e-5f, 0.0f, 0, 1,   0.0f, 1e-5f, 0, 1 };
    rt_draw_tri(&t, tiny, NULL, RAST_CULL_NONE, &st);
    assert_int_equal(st.tris_degenerate, 2);
    assert_int_equal(st.tris_drawn, 0);
    assert_int_equal(rt_count_mask(&t, NULL), 0);
    rt_free(&t);
}

/* A seeded soup: some triangles cross the near plane, some are behind the
 * eye, a few are huge, three attributes, depth test on. */
static void draw_soup(rast_target *t, rast_stats *st)
{
    enum { NV = 600, NT = 400 };
    static float clip[NV * 4], attr[NV * 3];
    static uint32_t idx[NT * 3];
    tu_rng r = { 0xC0FFEE };
    for (int i = 0; i < NV; i++) {
        float w = tu_range(&r, -0.3f, 3.0f);
        float s = tu_int(&r, 20) == 0 ? 50.0f : 1.3f;
        clip[4 * i + 0] = tu_range(&r, -s, s) * fabsf(w);
        clip[4 * i + 1] = tu_range(&r, -s, s) * fabsf(w);
        clip[4 * i + 2] = tu_range(&r, -1.2f, 1.2f) * fabsf(w);
        clip[4 * i + 3] = w;
        for (int k = 0; k < 3; k++)
            attr[3 * i + k] = tu_range(&r, -1, 1);
    }
    for (int i = 0; i < NT * 3; i++)
        idx[i] = (uint32_t)tu_int(&r, NV);
    rast_mesh_desc d = { clip, NV, attr, 3, idx, NT, RAST_CULL_NONE };
    assert_int_equal(rast_draw(t, &d, st), RAST_OK);
}

static void test_determinism_crc(void **state)
{
    (void)state;
    rast_target a = rt_make(96, 64, 1, 3, 4), b = rt_make(96, 64, 1, 3, 4);
    rast_stats sa, sb;
    memset(&sa, 0, sizeof sa);
    memset(&sb, 0, sizeof sb);
    draw_soup(&a, &sa);
    draw_soup(&b, &sb);
    assert_memory_equal(a.mask, b.mask, (size_t)a.mask_stride * a.height);
    assert_memory_equal(a.depth, b.depth, (size_t)a.depth_stride * a.height * sizeof(float));
    assert_memory_equal(a.attr, b.attr, (size_t)a.attr_stride * a.height * sizeof(float));
    assert_memory_equal(&sa, &sb, sizeof sa);
    /* The soup exercises every path. */
    assert_int_equal(sa.tris_in, 400);
    assert_true(sa.tris_clipped_away > 0 && sa.tris_drawn > 100 &&
                sa.pixels_written > 1000 && sa.tris_degenerate >= 0);
    uint32_t crc = target_crc(&a);
    print_message("NOTE raster soup CRC32 = 0x%08X (recorded 0x%08X), drawn %ld, "
                  "clipped %ld, pixels %ld\n", crc, SOUP_CRC, sa.tris_drawn,
                  sa.tris_clipped_away, sa.pixels_written);
    assert_int_equal(crc, SOUP_CRC);
    rt_free(&a);
    rt_free(&b);
}

static void test_stats_accumulate(void **state)
{
    (void)state;
    rast_target t = rt_make(16, 16, 0, 0, 0);
    const float clip[12] = { -1, -1, 0, 1,   3, -1, 0, 1,   -1, 3, 0, 1 };
    rast_stats st;
    memset(&st, 0, sizeof st);
    rt_draw_tri(&t, clip, NULL, RAST_CULL_NONE, &st);
    rt_draw_tri(&t, clip, NULL, RAST_CULL_NONE, &st);
    assert_int_equal(st.tris_in, 2);
    assert_int_equal(st.tris_drawn, 2);
    assert_int_equal(st.pixels_written, 2 * 16 * 16);   /* no depth: both write */
    rt_free(&t);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_validation),
        cmocka_unit_test_setup_teardown(test_index_out_of_range, index_setup, index_teardown),
        cmocka_unit_test_setup_teardown(test_index_every_position, index_setup, index_teardown),
        cmocka_unit_test(test_zero_size_and_empty),
        cmocka_unit_test(test_clear_keeps_padding),
        cmocka_unit_test(test_result_str),
        cmocka_unit_test(test_transform_points),
        cmocka_unit_test(test_transform_dirs),
        cmocka_unit_test(test_nonfinite_dropped),
        cmocka_unit_test(test_culling_and_winding),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_determinism_crc),
        cmocka_unit_test(test_stats_accumulate))
