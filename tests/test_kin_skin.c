/* test_kin_skin.c - joint matrices and linear blend skinning (kin_skin.c),
 * against hand-worked answers: a 50/50 blend, normals under non-uniform
 * scale and mirroring, bind pose, and a 2-bone cylinder bent 90 degrees. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

#define TOL 1e-5f

#define NEAR3P(p, X, Y, Z, tol) \
    do { NEAR((p)[0], X, tol); NEAR((p)[1], Y, tol); NEAR((p)[2], Z, tol); } while (0)

static kin_mesh mesh_of(int n, const float *pos, const float *nrm,
                        const uint16_t *joints, const float *weights)
{
    kin_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = n; m.positions = pos; m.normals = nrm;
    m.joints = joints; m.weights = weights; m.node = 0; m.skin = 0;
    return m;
}

static kin_mat4 scale_m(float x, float y, float z)
{
    kin_mat4 m = kin_mat4_identity();
    m.m[0] = x; m.m[5] = y; m.m[10] = z;
    return m;
}

/* ------------------------------------------------------------ validity */

static void validity_identity_joints_bind_pose(void **state)
{
    (void)state;
    tu_rng g = { 0x6b696e05 };
    enum { N = 64, J = 5 };
    float pos[N * 3], nrm[N * 3], w[N * 4], po[N * 3], no[N * 3];
    uint16_t jt[N * 4];
    for (int v = 0; v < N; v++) {
        const float nx = tu_range(&g, -1, 1);   /* drawn in order (see tu_kin.h) */
        const float ny = tu_range(&g, -1, 1);
        kin_vec3 n = kin_v3_norm(kin_v3(nx, ny, 0.5f));
        nrm[v * 3] = n.x; nrm[v * 3 + 1] = n.y; nrm[v * 3 + 2] = n.z;
        float s = 0;
        for (int i = 0; i < 4; i++) {
            jt[v * 4 + i] = (uint16_t)tu_int(&g, J);
            w[v * 4 + i] = tu_unit(&g);
            s += w[v * 4 + i];
        }
        for (int i = 0; i < 4; i++) w[v * 4 + i] /= s;
        for (int c = 0; c < 3; c++) pos[v * 3 + c] = tu_range(&g, -2, 2);
    }
    kin_mat4 jm[J];
    for (int j = 0; j < J; j++) jm[j] = kin_mat4_identity();
    kin_mesh m = mesh_of(N, pos, nrm, jt, w);
    kin_skin_lbs(&m, jm, po, no);
    for (int k = 0; k < N * 3; k++) {
        NEAR(po[k], pos[k], TOL);
        NEAR(no[k], nrm[k], TOL);
    }
}

static void validity_zero_weights_keep_bind(void **state)
{
    (void)state;
    float pos[6] = { 1, 2, 3, 4, 5, 6 };
    float nrm[6] = { 0, 1, 0, 0.6f, 0, 0.8f };
    uint16_t jt[8] = { 0, 0, 0, 0, 1, 0, 0, 0 };
    float w[8] = { 0, 0, 0, 0, 1, 0, 0, 0 };
    kin_mat4 jm[2] = { kin_mat4_identity(), kin_mat4_identity() };
    jm[0].m[12] = 100; jm[1].m[12] = 100;          /* moves everything skinned */
    jm[0].m[0] = 3; jm[1].m[0] = 3;
    kin_mesh m = mesh_of(2, pos, nrm, jt, w);
    float po[6], no[6];
    kin_skin_lbs(&m, jm, po, no);
    NEAR3P(po, 1, 2, 3, 0);                          /* vertex 0: bind */
    NEAR3P(no, 0, 1, 0, 0);
    NEAR3P(po + 3, 4 * 3 + 100, 5, 6, TOL);          /* vertex 1: skinned */
}

static void validity_no_normals(void **state)
{
    (void)state;
    float pos[3] = { 1, 0, 0 };
    uint16_t jt[4] = { 0, 0, 0, 0 };
    float w[4] = { 1, 0, 0, 0 };
    kin_mat4 jm = kin_mat4_identity();
    jm.m[13] = 2;
    float po[3], no[3] = { 7, 7, 7 };
    kin_mesh m = mesh_of(1, pos, NULL, jt, w);
    kin_skin_lbs(&m, &jm, po, no);     /* mesh has no normals: no[] untouched */
    NEAR3P(po, 1, 2, 0, 0);
    NEAR3P(no, 7, 7, 7, 0);
    m.normals = pos;
    kin_skin_lbs(&m, &jm, po, NULL);   /* no output for normals */
    NEAR3P(po, 1, 2, 0, 0);
}

/* -------------------------------------------------------------- result */

static void result_joint_matrices(void **state)
{
    (void)state;
    kin_mat4 world[3];
    world[0] = kin_mat4_identity();
    world[1] = kin_mat4_from_tr(kin_v3(0, 1, 0), kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2));
    world[2] = kin_mat4_from_tr(kin_v3(5, 0, 0), kin_quat_identity());
    int joints[2] = { 2, 1 };
    kin_mat4 ibm[2];
    kin_mat4_inverse(&world[2], &ibm[0]);
    ibm[1] = kin_mat4_identity();
    ibm[1].m[13] = -1;                              /* bind of joint 1 at (0,1,0) */
    kin_skin sk = { 2, joints, ibm };
    kin_mat4 jm[2];
    kin_skin_joint_matrices(&sk, world, jm);
    for (int k = 0; k < 16; k++) NEAR(jm[0].m[k], (k % 5 == 0) ? 1 : 0, TOL);
    /* jm[1] p = R90 (p - (0,1,0)) + (0,1,0): (1,1,0) -> (0,2,0) */
    kin_vec3 q = kin_mat4_mul_point(&jm[1], kin_v3(1, 1, 0));
    NEAR(q.x, 0, TOL); NEAR(q.y, 2, TOL); NEAR(q.z, 0, TOL);
}

static void result_two_joint_blend(void **state)
{
    (void)state;
    /* jm0 = identity, jm1 = 90 degrees about Z. Vertex (1,0,0), 0.5/0.5:
     * p = 0.5 (1,0,0) + 0.5 (0,1,0) = (0.5, 0.5, 0). The blended 3x3 is
     * A = 0.5 (I + Rz90) = (sqrt2/2) Rz45 in xy, 1 in z; A^-T n for
     * n = (1,0,0) is along Rz45 (1,0,0) = (1,1,0)/sqrt2. A second vertex
     * with a translation joint: jm2 = T(0,0,4), weights 0.25/0.75 on
     * jm0/jm2: p = (0,1,0) + 0.75 (0,0,4) = (0,1,3), normal unchanged. */
    float pos[6] = { 1, 0, 0, 0, 1, 0 };
    float nrm[6] = { 1, 0, 0, 0, 0, 1 };
    uint16_t jt[8] = { 0, 1, 0, 0, 2, 0, 0, 0 };
    float w[8] = { 0.5f, 0.5f, 0, 0, 0.75f, 0.25f, 0, 0 };
    kin_mat4 jm[3];
    jm[0] = kin_mat4_identity();
    jm[1] = kin_mat4_from_tr(kin_v3(0, 0, 0), kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2));
    jm[2] = kin_mat4_identity();
    jm[2].m[14] = 4;
    kin_mesh m = mesh_of(2, pos, nrm, jt, w);
    float po[6], no[6];
    kin_skin_lbs(&m, jm, po, no);
    NEAR3P(po, 0.5, 0.5, 0, TOL);
    NEAR3P(no, sqrt(0.5), sqrt(0.5), 0, TOL);
    NEAR3P(po + 3, 0, 1, 3, TOL);
    NEAR3P(no + 3, 0, 0, 1, TOL);
}

static void result_normals_nonuniform_scale(void **state)
{
    (void)state;
    /* Plane x + y = 1, normal (1,1,0)/sqrt2. Scaling x by 2 gives the plane
     * x/2 + y = 1, whose normal is (1/2, 1, 0) ~ (1,2,0)/sqrt5 = the
     * inverse transpose diag(1/2, 1, 1) (1,1,0). Mirroring x by -1 flips
     * the normal (1,0,0) to (-1,0,0) (inverse transpose diag(-1,1,1)). */
    float s2 = (float)sqrt(0.5);
    float pos[6] = { 1, 0, 0, 0.5f, 0.5f, 0 };
    float nrm[6] = { s2, s2, 0, s2, s2, 0 };
    uint16_t jt[8] = { 0 };
    float w[8] = { 1, 0, 0, 0, 1, 0, 0, 0 };
    kin_mat4 jm = scale_m(2, 1, 1);
    jm.m[12] = 1;
    kin_mesh m = mesh_of(2, pos, nrm, jt, w);
    float po[6], no[6];
    kin_skin_lbs(&m, &jm, po, no);
    NEAR3P(po, 3, 0, 0, TOL);
    NEAR3P(no, 1 / sqrt(5), 2 / sqrt(5), 0, TOL);
    /* the transformed normal is perpendicular to the transformed plane */
    double tx = po[3] - po[0], ty = po[4] - po[1];
    NEAR(tx * no[0] + ty * no[1], 0, TOL);

    float nx[6] = { 1, 0, 0, 0, 0, -1 };
    m.normals = nx;
    jm = scale_m(-1, 1, 3);
    kin_skin_lbs(&m, &jm, po, no);
    NEAR3P(no, -1, 0, 0, TOL);
    NEAR3P(no + 3, 0, 0, -1, TOL);
    NEAR3P(po, -1, 0, 0, TOL);
}

static void result_mesh_transform(void **state)
{
    (void)state;
    /* unskinned mesh under T(1,2,3) * Rz90 * S(1,3,1) */
    float pos[6] = { 1, 0, 0, 0, 1, 0 };
    float s2 = (float)sqrt(0.5);
    float nrm[6] = { 1, 0, 0, s2, s2, 0 };
    kin_mesh m = mesh_of(2, pos, nrm, NULL, NULL);
    m.skin = -1;
    kin_transform t = kin_transform_identity();
    t.t = kin_v3(1, 2, 3);
    t.r = kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2);
    t.s = kin_v3(1, 3, 1);
    kin_mat4 M = kin_mat4_from_transform(&t);
    float po[6], no[6];
    kin_mesh_transform(&m, &M, po, no);
    NEAR3P(po, 1, 3, 3, TOL);        /* (1,0,0) -> (0,1,0) + t */
    NEAR3P(po + 3, -2, 2, 3, TOL);   /* (0,3,0) -> (-3,0,0) + t */
    NEAR3P(no, 0, 1, 0, TOL);
    /* (1,1,0) -> S^-1 (1, 1/3, 0) ~ (3,1,0)/sqrt10 -> Rz90 (-1,3,0)/sqrt10 */
    NEAR3P(no + 3, -1 / sqrt(10), 3 / sqrt(10), 0, TOL);
}

/* A 2-bone cylinder along +Y (radius 0.1, bones [0,1] and [1,2]), rings at
 * y = 0, 0.5, 1, 1.5, 2; ring y < 1 is bone 0, y > 1 bone 1, y = 1 half
 * and half. Bending joint 1 by 90 degrees about Z (through FK, joint
 * matrices and LBS) maps a bone-1 vertex (r c, 1 + h, r s) to
 * (-h, 1 + r c, r s), its normal (c, 0, s) to (0, c, s), and a y = 1
 * vertex (r c, 1, r s) to the mean of itself and (0, 1 + r c, r s), its
 * normal to (c, c, s) renormalised. */
static void result_bent_cylinder(void **state)
{
    (void)state;
    enum { SEG = 12, RINGS = 5, N = SEG * RINGS };
    const float r = 0.1f;
    float pos[N * 3], nrm[N * 3], w[N * 4], po[N * 3], no[N * 3];
    uint16_t jt[N * 4];
    memset(w, 0, sizeof w);
    memset(jt, 0, sizeof jt);
    for (int k = 0; k < RINGS; k++) {
        float y = 0.5f * (float)k;
        for (int s = 0; s < SEG; s++) {
            int v = k * SEG + s;
            float a = 2.0f * PI_F * (float)s / SEG;
            pos[v * 3] = r * cosf(a); pos[v * 3 + 1] = y; pos[v * 3 + 2] = r * sinf(a);
            nrm[v * 3] = cosf(a); nrm[v * 3 + 1] = 0; nrm[v * 3 + 2] = sinf(a);
            jt[v * 4] = 0; jt[v * 4 + 1] = 1;
            if (k < 2) w[v * 4] = 1;
            else if (k > 2) w[v * 4 + 1] = 1;
            else w[v * 4] = w[v * 4 + 1] = 0.5f;
        }
    }
    int16_t parents[2] = { KIN_NO_PARENT, 0 };
    kin_transform loc[2] = { kin_transform_identity(), kin_transform_identity() };
    loc[1].t = kin_v3(0, 1, 0);
    kin_mat4 world[2], ibm[2], jm[2];
    kin_fk(parents, 2, loc, NULL, world);          /* bind pose */
    for (int j = 0; j < 2; j++) assert_int_equal(kin_mat4_inverse(&world[j], &ibm[j]), 1);
    int joints[2] = { 0, 1 };
    kin_skin sk = { 2, joints, ibm };

    loc[1].r = kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2);
    kin_fk(parents, 2, loc, NULL, world);
    kin_skin_joint_matrices(&sk, world, jm);
    kin_mesh m = mesh_of(N, pos, nrm, jt, w);
    kin_skin_lbs(&m, jm, po, no);

    for (int k = 0; k < RINGS; k++) {
        for (int s = 0; s < SEG; s++) {
            int v = k * SEG + s;
            double a = 2.0 * 3.14159265358979323846 * s / SEG;
            double c = r * cos(a), sn = r * sin(a), y = 0.5 * k;
            const float *p = po + v * 3, *n = no + v * 3;
            if (k < 2) {
                NEAR3P(p, c, y, sn, TOL);
                NEAR3P(n, cos(a), 0, sin(a), TOL);
            } else if (k > 2) {
                double h = y - 1.0;
                NEAR3P(p, -h, 1 + c, sn, TOL);
                NEAR3P(n, 0, cos(a), sin(a), TOL);
                /* rigid: the distance to the bent bone axis stays r */
                NEAR(hypot(p[1] - 1.0, p[2]), r, TOL);
            } else {
                NEAR3P(p, c / 2, 1 + c / 2, sn, TOL);
                /* A = 0.5 (I + Rz90): A^-T (ca, 0, sa) ~ (ca, ca, sa) */
                double ca = cos(a), sa = sin(a), l = sqrt(2 * ca * ca + sa * sa);
                NEAR3P(n, ca / l, ca / l, sa / l, TOL);
            }
        }
    }
}

TU_MAIN_NAMED("kin_skin", NULL, NULL,
              cmocka_unit_test(validity_identity_joints_bind_pose),
              cmocka_unit_test(validity_zero_weights_keep_bind),
              cmocka_unit_test(validity_no_normals),
              cmocka_unit_test(result_joint_matrices),
              cmocka_unit_test(result_two_joint_blend),
              cmocka_unit_test(result_normals_nonuniform_scale),
              cmocka_unit_test(result_mesh_transform),
              cmocka_unit_test(result_bent_cylinder))
