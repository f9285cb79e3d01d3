/* test_kin_math.c - vectors, quaternions and matrices of kin (kin_math.c).
 * Validity: degenerate inputs (singular inverse, zero vectors). Result:
 * analytic answers within 1e-5, seeded random matrices for the inverse. */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

#define TOL 1e-5f

static void near_identity(const kin_mat4 *m, float tol)
{
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) NEAR(m->m[c * 4 + r], c == r ? 1.0 : 0.0, tol);
}

static kin_quat random_quat(tu_rng *g)
{
    kin_vec3 axis;
    do {
        axis = tu_v3(g, -1, 1);
    } while (kin_v3_len(axis) < 0.1f);
    return kin_quat_axis_angle(axis, tu_range(g, -PI_F, PI_F));
}

/* ------------------------------------------------------------ validity */

static void validity_zero_vectors(void **state)
{
    (void)state;
    kin_vec3 n = kin_v3_norm(kin_v3(0, 0, 0));
    NEAR3(n, 0, 0, 0, 0);
    n = kin_v3_norm(kin_v3(INFINITY, 0, 0));
    NEAR3(n, 0, 0, 0, 0);
    kin_quat q = kin_quat_normalize((kin_quat){ 0, 0, 0, 0 });
    NEAR(q.x, 0, 0); NEAR(q.y, 0, 0); NEAR(q.z, 0, 0); NEAR(q.w, 1, 0);
    q = kin_quat_axis_angle(kin_v3(0, 0, 0), 1.0f);
    NEAR(q.w, 1, 0);
}

static void validity_singular_inverse(void **state)
{
    (void)state;
    kin_mat4 out, m;
    memset(&m, 0, sizeof m);
    memset(&out, 0x7f, sizeof out);
    assert_int_equal(kin_mat4_inverse(&m, &out), 0);
    near_identity(&out, 0);

    /* rank 3: the third column is the sum of the first two */
    m = kin_mat4_identity();
    m.m[0] = 1.5f; m.m[1] = 2.0f; m.m[2] = -0.5f;
    m.m[4] = 0.25f; m.m[5] = 3.0f; m.m[6] = 1.0f;
    for (int r = 0; r < 3; r++) m.m[8 + r] = m.m[r] + m.m[4 + r];
    m.m[12] = 7.0f;
    memset(&out, 0x7f, sizeof out);
    assert_int_equal(kin_mat4_inverse(&m, &out), 0);
    near_identity(&out, 0);

    /* scale 0 along one axis */
    kin_transform t = kin_transform_identity();
    t.s = kin_v3(1, 0, 1);
    m = kin_mat4_from_transform(&t);
    assert_int_equal(kin_mat4_inverse(&m, &out), 0);

    /* non-finite */
    m = kin_mat4_identity();
    m.m[5] = NAN;
    assert_int_equal(kin_mat4_inverse(&m, &out), 0);
}

/* A small but regular matrix is not singular: the test is relative. */
static void validity_small_scale_inverse(void **state)
{
    (void)state;
    kin_transform t = kin_transform_identity();
    t.s = kin_v3(1e-3f, 1e-3f, 1e-3f);
    kin_mat4 m = kin_mat4_from_transform(&t), inv;
    assert_int_equal(kin_mat4_inverse(&m, &inv), 1);
    NEAR(inv.m[0], 1000.0, 1e-2);
    NEAR(inv.m[15], 1.0, 0);
}

/* -------------------------------------------------------------- result */

static void result_vectors(void **state)
{
    (void)state;
    kin_vec3 a = kin_v3(1, 2, 3), b = kin_v3(-4, 5, 0.5f);
    NEAR3(kin_v3_add(a, b), -3, 7, 3.5, 0);
    NEAR3(kin_v3_sub(a, b), 5, -3, 2.5, 0);
    NEAR3(kin_v3_scale(a, 2), 2, 4, 6, 0);
    NEAR(kin_v3_dot(a, b), -4 + 10 + 1.5, 0);
    NEAR3(kin_v3_cross(kin_v3(1, 0, 0), kin_v3(0, 1, 0)), 0, 0, 1, 0);
    NEAR3(kin_v3_cross(a, b), 2 * 0.5 - 3 * 5, 3 * -4 - 1 * 0.5, 1 * 5 - 2 * -4, TOL);
    NEAR(kin_v3_len(kin_v3(3, 4, 12)), 13, TOL);
    NEAR3(kin_v3_norm(kin_v3(0, 3, 4)), 0, 0.6, 0.8, TOL);
}

static void result_quat_rotate_analytic(void **state)
{
    (void)state;
    kin_quat qz = kin_quat_axis_angle(kin_v3(0, 0, 2), PI_F / 2);
    NEAR3(kin_quat_rotate(qz, kin_v3(1, 0, 0)), 0, 1, 0, TOL);
    kin_quat qy = kin_quat_axis_angle(kin_v3(0, 1, 0), PI_F / 2);
    NEAR3(kin_quat_rotate(qy, kin_v3(1, 0, 0)), 0, 0, -1, TOL);
    kin_quat qx = kin_quat_axis_angle(kin_v3(1, 0, 0), PI_F / 2);
    NEAR3(kin_quat_rotate(qx, kin_v3(0, 1, 0)), 0, 0, 1, TOL);
    /* a*b rotates by b first: Z then Y maps X -> Y -> Y */
    kin_quat ab = kin_quat_mul(qy, qz);
    NEAR3(kin_quat_rotate(ab, kin_v3(1, 0, 0)), 0, 1, 0, TOL);
    /* and Y then Z: X -> -Z -> -Z */
    kin_quat ba = kin_quat_mul(qz, qy);
    NEAR3(kin_quat_rotate(ba, kin_v3(1, 0, 0)), 0, 0, -1, TOL);
    kin_quat id = kin_quat_mul(kin_quat_identity(), qz);
    NEAR(id.z, qz.z, 0); NEAR(id.w, qz.w, 0);
}

static void result_quat_vs_matrix(void **state)
{
    (void)state;
    tu_rng g = { 0x6b696e01 };
    for (int i = 0; i < 200; i++) {
        kin_quat q = random_quat(&g), q2 = random_quat(&g);
        kin_vec3 v = tu_v3(&g, -2, 2);
        kin_mat4 m = kin_mat4_from_tr(kin_v3(0, 0, 0), q);
        kin_vec3 a = kin_quat_rotate(q, v), b = kin_mat4_mul_dir(&m, v);
        NEAR3(a, b.x, b.y, b.z, TOL);
        /* composition: matrix of q*q2 equals product of matrices */
        kin_mat4 m2 = kin_mat4_from_tr(kin_v3(0, 0, 0), q2);
        kin_mat4 mm = kin_mat4_mul(&m, &m2);
        kin_mat4 mq = kin_mat4_from_tr(kin_v3(0, 0, 0), kin_quat_mul(q, q2));
        for (int k = 0; k < 16; k++) NEAR(mq.m[k], mm.m[k], TOL);
        /* the rotation keeps lengths */
        NEAR(kin_v3_len(a), kin_v3_len(v), 4 * TOL);
    }
}

static void result_transform_order(void **state)
{
    (void)state;
    /* T * R * S: scale x by 2, rotate 90 about Z, translate z by 5 */
    kin_transform t = kin_transform_identity();
    t.s = kin_v3(2, 1, 1);
    t.r = kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2);
    t.t = kin_v3(0, 0, 5);
    kin_mat4 m = kin_mat4_from_transform(&t);
    NEAR3(kin_mat4_mul_point(&m, kin_v3(1, 0, 0)), 0, 2, 5, TOL);
    NEAR3(kin_mat4_mul_point(&m, kin_v3(0, 1, 0)), -1, 0, 5, TOL);
    NEAR3(kin_mat4_mul_dir(&m, kin_v3(1, 0, 0)), 0, 2, 0, TOL);
    /* column-major: translation in m[12..14], bottom row 0 0 0 1 */
    NEAR(m.m[12], 0, 0); NEAR(m.m[13], 0, 0); NEAR(m.m[14], 5, 0);
    NEAR(m.m[3], 0, 0); NEAR(m.m[7], 0, 0); NEAR(m.m[11], 0, 0); NEAR(m.m[15], 1, 0);
    /* mul: translate * scale applies the scale first */
    kin_mat4 tr = kin_mat4_identity(), sc = kin_mat4_identity();
    tr.m[12] = 1; sc.m[0] = 3;
    kin_mat4 ts = kin_mat4_mul(&tr, &sc), st = kin_mat4_mul(&sc, &tr);
    NEAR3(kin_mat4_mul_point(&ts, kin_v3(1, 0, 0)), 4, 0, 0, 0);
    NEAR3(kin_mat4_mul_point(&st, kin_v3(1, 0, 0)), 6, 0, 0, 0);
}

static void result_inverse_random(void **state)
{
    (void)state;
    tu_rng g = { 0x6b696e02 };
    for (int i = 0; i < 500; i++) {
        kin_mat4 m;
        if (i & 1) { /* an affine TRS */
            kin_transform t;
            t.t = tu_v3(&g, -3, 3);
            t.r = random_quat(&g);
            t.s = tu_v3(&g, 0.5f, 2);
            m = kin_mat4_from_transform(&t);
        } else { /* a general, diagonally dominant (so well-conditioned) one */
            for (int k = 0; k < 16; k++) m.m[k] = tu_range(&g, -1, 1);
            for (int k = 0; k < 4; k++) m.m[k * 5] += (tu_unit(&g) < 0.5f ? -4.0f : 4.0f);
        }
        kin_mat4 inv;
        assert_int_equal(kin_mat4_inverse(&m, &inv), 1);
        kin_mat4 a = kin_mat4_mul(&inv, &m), b = kin_mat4_mul(&m, &inv);
        near_identity(&a, TOL);
        near_identity(&b, TOL);
    }
}

static void result_slerp(void **state)
{
    (void)state;
    kin_quat a = kin_quat_identity();
    kin_quat b = kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2);
    kin_quat q0 = kin_quat_slerp(a, b, 0), q1 = kin_quat_slerp(a, b, 1);
    NEAR(q0.x, 0, TOL); NEAR(q0.y, 0, TOL); NEAR(q0.z, 0, TOL); NEAR(q0.w, 1, TOL);
    NEAR(q1.z, b.z, TOL); NEAR(q1.w, b.w, TOL);
    kin_quat h = kin_quat_slerp(a, b, 0.5f);
    NEAR(h.z, sin(PI_F / 8), TOL); NEAR(h.w, cos(PI_F / 8), TOL);
    /* a quarter of the way: constant angular speed gives 22.5 degrees */
    kin_quat qq = kin_quat_slerp(a, b, 0.25f);
    NEAR(qq.z, sin(PI_F / 16), TOL); NEAR(qq.w, cos(PI_F / 16), TOL);
    NEAR3(kin_quat_rotate(h, kin_v3(1, 0, 0)), cos(PI_F / 4), sin(PI_F / 4), 0, TOL);

    /* shortest path: -b is the same rotation; the halfway stays at 45 deg */
    kin_quat nb = { -b.x, -b.y, -b.z, -b.w };
    kin_quat hn = kin_quat_slerp(a, nb, 0.5f);
    NEAR3(kin_quat_rotate(hn, kin_v3(1, 0, 0)), cos(PI_F / 4), sin(PI_F / 4), 0, TOL);
    /* 0 -> 270 degrees goes the short way, through -45 */
    kin_quat c = kin_quat_axis_angle(kin_v3(0, 0, 1), 3 * PI_F / 2);
    kin_quat hc = kin_quat_slerp(a, c, 0.5f);
    NEAR3(kin_quat_rotate(hc, kin_v3(1, 0, 0)), cos(PI_F / 4), -sin(PI_F / 4), 0, TOL);

    /* nearly parallel: the nlerp fallback is unit length and in between */
    kin_quat d = kin_quat_axis_angle(kin_v3(0, 0, 1), 2e-4f);
    kin_quat hd = kin_quat_slerp(a, d, 0.5f);
    NEAR(hd.x * hd.x + hd.y * hd.y + hd.z * hd.z + hd.w * hd.w, 1, TOL);
    NEAR(hd.z, sin(0.5e-4), 1e-7);
    /* identical inputs */
    kin_quat s = kin_quat_slerp(b, b, 0.3f);
    NEAR(s.z, b.z, TOL); NEAR(s.w, b.w, TOL);
}

static void result_look_at(void **state)
{
    (void)state;
    tu_rng g = { 0x6b696e03 };
    for (int i = 0; i < 100; i++) {
        kin_vec3 eye = tu_v3(&g, -5, 5);
        kin_vec3 dir = tu_v3(&g, -1, 1);
        if (kin_v3_len(dir) < 0.1f) continue;
        kin_vec3 target = kin_v3_add(eye, dir);
        kin_mat4 v = kin_mat4_look_at(eye, target, kin_v3(0, 1, 0));
        NEAR3(kin_mat4_mul_point(&v, eye), 0, 0, 0, 1e-4);
        NEAR3(kin_mat4_mul_point(&v, target), 0, 0, -kin_v3_len(dir), 1e-4);
        /* rigid: the inverse is the transpose of the rotation */
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double d = 0;
                for (int k = 0; k < 3; k++) d += v.m[k * 4 + a] * v.m[k * 4 + b];
                NEAR(d, a == b ? 1.0 : 0.0, TOL);
            }
        /* up stays in the upper half of the view */
        kin_vec3 up = kin_mat4_mul_dir(&v, kin_v3(0, 1, 0));
        assert_true(up.y >= 0.0f);
        NEAR(up.x, 0, TOL);
    }
    /* the gluLookAt example: eye on +Z looking at the origin is identity + shift */
    kin_mat4 v = kin_mat4_look_at(kin_v3(0, 0, 3), kin_v3(0, 0, 0), kin_v3(0, 1, 0));
    kin_mat4 e = kin_mat4_identity();
    e.m[14] = -3;
    for (int k = 0; k < 16; k++) NEAR(v.m[k], e.m[k], TOL);
    /* up parallel to the view direction still gives a rotation */
    v = kin_mat4_look_at(kin_v3(0, 0, 0), kin_v3(0, 2, 0), kin_v3(0, 1, 0));
    NEAR3(kin_mat4_mul_point(&v, kin_v3(0, 2, 0)), 0, 0, -2, TOL);
}

static void result_perspective(void **state)
{
    (void)state;
    float n = 0.1f, f = 50.0f, fovy = 1.0f, aspect = 1.5f;
    kin_mat4 p = kin_mat4_perspective(fovy, aspect, n, f);
    /* clip = p * (x, y, z, 1) */
    float z = -n;
    float cz = p.m[10] * z + p.m[14], cw = p.m[11] * z + p.m[15];
    NEAR(cz / cw, -1, TOL);
    z = -f;
    cz = p.m[10] * z + p.m[14]; cw = p.m[11] * z + p.m[15];
    NEAR(cz / cw, 1, 1e-4);
    /* the top edge of the FOV maps to y_ndc = 1, the right edge to x_ndc = 1 */
    z = -2.0f;
    float y = 2.0f * tanf(fovy / 2), x = y * aspect;
    NEAR(p.m[5] * y / (-z), 1, TOL);
    NEAR(p.m[0] * x / (-z), 1, TOL);
    NEAR(p.m[1], 0, 0); NEAR(p.m[4], 0, 0); NEAR(p.m[8], 0, 0); NEAR(p.m[9], 0, 0);
}

/* One cmocka group (tests/run_tests.sh counts the last summary line);
 * the validity_ and result_ prefixes name the two kinds of test. */
TU_MAIN_NAMED("kin_math", NULL, NULL,
              cmocka_unit_test(validity_zero_vectors),
              cmocka_unit_test(validity_singular_inverse),
              cmocka_unit_test(validity_small_scale_inverse),
              cmocka_unit_test(result_vectors),
              cmocka_unit_test(result_quat_rotate_analytic),
              cmocka_unit_test(result_quat_vs_matrix),
              cmocka_unit_test(result_transform_order),
              cmocka_unit_test(result_inverse_random),
              cmocka_unit_test(result_slerp),
              cmocka_unit_test(result_look_at),
              cmocka_unit_test(result_perspective))
