/* test_pipe_fit.c - the elbow fit of the refine method (pipe_fit in
 * src/pipe): on a synthetic pair of images of two bent arms whose elbows
 * are turned about the shoulder-wrist line by known angles (+20 and -15
 * degrees) from where the model puts them, the fit finds those angles
 * within 3 degrees (1 degree moves the elbow 0.8 px in these 320x240
 * images; the surface points on the silhouette's edge fall on either
 * side of it, so the score is flat over a couple of pixels), moves the elbows there and leaves the wrists
 * and hands where they were; with the arms where the images have them it
 * stays at 0; bad arguments are refused. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe.h"

enum { W = 320, H = 240, RINGS = 12, AROUND = 10 };
#define D2R 0.01745329252f

/* Nodes: 0 body; per side s: 1 + 3 s upper arm (at the shoulder), 2 + 3 s
 * forearm (the elbow), 3 + 3 s hand (the wrist). Shoulder (-+0.2, 0, 0),
 * elbow 0.15 below and 0.25 in front of it, wrist 0.5 in front of the
 * shoulder: the elbow is 0.15 m off the shoulder-wrist line. */
typedef struct arms {
    kin_model m;
    kin_arm_rig rig;
    int16_t parents[7];
    kin_transform rest[7];
    kin_mat4 ibm[7];
    int joints[7];
    kin_skin skin;
    kin_mesh mesh;
    float *pos;
    uint16_t *jnt;
    float *wgt;
    uint32_t *idx;
    int nv, nt;
} arms;

/* A tube of RINGS x AROUND vertices from a to b, radius r, bound to joint
 * j; appended to A's arrays. */
static void tube(arms *A, kin_vec3 a, kin_vec3 b, float r, int j)
{
    kin_vec3 d = kin_v3_norm(kin_v3_sub(b, a));
    kin_vec3 e1 = kin_v3_norm(kin_v3_cross(d, fabsf(d.y) < 0.9f ? kin_v3(0, 1, 0) : kin_v3(1, 0, 0)));
    kin_vec3 e2 = kin_v3_cross(d, e1);
    int v0 = A->nv;
    for (int i = 0; i < RINGS; i++) {
        kin_vec3 c = kin_v3_add(a, kin_v3_scale(kin_v3_sub(b, a), (float)i / (RINGS - 1)));
        for (int k = 0; k < AROUND; k++) {
            float t = 6.2831853f * (float)k / AROUND;
            kin_vec3 p = kin_v3_add(c, kin_v3_add(kin_v3_scale(e1, r * cosf(t)),
                                                  kin_v3_scale(e2, r * sinf(t))));
            float *o = &A->pos[A->nv * 3];
            o[0] = p.x; o[1] = p.y; o[2] = p.z;
            A->jnt[A->nv * 4] = (uint16_t)j;
            A->wgt[A->nv * 4] = 1.0f;
            A->nv++;
        }
    }
    for (int i = 0; i + 1 < RINGS; i++)
        for (int k = 0; k < AROUND; k++) {
            uint32_t a0 = (uint32_t)(v0 + i * AROUND + k), a1 = (uint32_t)(v0 + i * AROUND + (k + 1) % AROUND);
            uint32_t b0 = a0 + AROUND, b1 = a1 + AROUND;
            uint32_t *t = &A->idx[A->nt * 3];
            t[0] = a0; t[1] = b0; t[2] = a1;
            t[3] = a1; t[4] = b0; t[5] = b1;
            A->nt += 2;
        }
}

static void arms_build(arms *A)
{
    memset(A, 0, sizeof *A);
    const int nv = 6 * RINGS * AROUND, nt = 6 * (RINGS - 1) * AROUND * 2;
    A->pos = calloc((size_t)nv * 3, sizeof(float));
    A->jnt = calloc((size_t)nv * 4, sizeof(uint16_t));
    A->wgt = calloc((size_t)nv * 4, sizeof(float));
    A->idx = calloc((size_t)nt * 3, sizeof(uint32_t));
    assert_true(A->pos && A->jnt && A->wgt && A->idx);
    A->parents[0] = KIN_NO_PARENT;
    A->rest[0] = kin_transform_identity();
    for (int s = 0; s < 2; s++) {
        float x = s ? 0.2f : -0.2f;
        int u = 1 + 3 * s;
        A->parents[u] = 0;
        A->parents[u + 1] = (int16_t)u;
        A->parents[u + 2] = (int16_t)(u + 1);
        for (int k = 0; k < 3; k++) A->rest[u + k] = kin_transform_identity();
        A->rest[u].t = kin_v3(x, 0, 0);
        A->rest[u + 1].t = kin_v3(0, -0.15f, -0.25f);
        A->rest[u + 2].t = kin_v3(0, 0.15f, -0.25f);
        kin_vec3 S = kin_v3(x, 0, 0), E = kin_v3(x, -0.15f, -0.25f), Wr = kin_v3(x, 0, -0.5f);
        tube(A, S, E, 0.035f, u);
        tube(A, E, Wr, 0.03f, u + 1);
        tube(A, Wr, kin_v3(x + (s ? -0.03f : 0.03f), 0, -0.65f), 0.025f, u + 2);
        A->rig.joint[s][KIN_RIG_UPPER_ARM] = u;
        A->rig.joint[s][KIN_RIG_FOREARM] = u + 1;
        A->rig.joint[s][KIN_RIG_HAND] = u + 2;
    }
    kin_mat4 world[7];
    kin_fk(A->parents, 7, A->rest, NULL, world);
    for (int j = 0; j < 7; j++) {
        A->joints[j] = j;
        assert_true(kin_mat4_inverse(&world[j], &A->ibm[j]));
    }
    A->skin = (kin_skin){ 7, A->joints, A->ibm };
    A->mesh.vertex_count = A->nv;
    A->mesh.positions = A->pos;
    A->mesh.joints = A->jnt;
    A->mesh.weights = A->wgt;
    A->mesh.index_count = A->nt * 3;
    A->mesh.indices = A->idx;
    A->mesh.node = -1;
    A->mesh.skin = 0;
    A->m.node_count = 7;
    A->m.parents = A->parents;
    A->m.rest = A->rest;
    A->m.mesh_count = 1;
    A->m.meshes = &A->mesh;
    A->m.skin_count = 1;
    A->m.skins = &A->skin;
}

static void arms_free(arms *A)
{
    free(A->pos);
    free(A->jnt);
    free(A->wgt);
    free(A->idx);
}

/* pos with the upper arm and forearm vertices of side s turned by phi[s]
 * about the shoulder-wrist line (the hand's stay). */
static void turned(const arms *A, const float phi[2], float *out)
{
    memcpy(out, A->pos, sizeof(float) * 3 * (size_t)A->nv);
    for (int v = 0; v < A->nv; v++) {
        int j = A->jnt[v * 4], s = j >= 4, k = j - 1 - 3 * s;
        if (k > 1) continue;
        float x = s ? 0.2f : -0.2f;
        kin_vec3 S = kin_v3(x, 0, 0), u = kin_v3(0, 0, -1);
        kin_quat q = kin_quat_axis_angle(u, phi[s]);
        float *p = &out[v * 3];
        kin_vec3 r = kin_v3_add(S, kin_quat_rotate(q, kin_v3_sub(kin_v3(p[0], p[1], p[2]), S)));
        p[0] = r.x; p[1] = r.y; p[2] = r.z;
    }
}

/* Mask of the vertices pos (A's triangles) through cam. */
static void draw(const arms *A, const float *pos, const kin_camera *cam, uint8_t *mask)
{
    float *clip = malloc(sizeof(float) * 4 * (size_t)A->nv);
    float *depth = malloc(sizeof(float) * W * H);
    assert_true(clip && depth);
    rast_target t = { W, H, depth, W, mask, W, NULL, 0, 0 };
    rast_target_clear(&t);
    rast_transform_points(cam->view_proj.m, pos, A->nv, clip);
    rast_mesh_desc d = { clip, A->nv, NULL, 0, A->idx, A->nt, RAST_CULL_NONE };
    assert_int_equal(rast_draw(&t, &d, NULL), RAST_OK);
    free(clip);
    free(depth);
}

/* Camera images of the arms posed by true_phi: skin-red arms over a
 * blue-grey background with a little noise; the fit from the model's
 * pose; returns the swivels found and checks the pose it leaves. */
static void fit_case(const float true_phi[2], float found[2], uint64_t seed)
{
    arms A;
    arms_build(&A);
    tu_rng g = { seed };
    kin_camera cam[2];
    for (int e = 0; e < 2; e++)
        cam[e] = kin_camera_look_at(kin_v3(e ? 0.03f : -0.03f, 0.25f, 0.25f), kin_v3(0, -0.1f, -0.35f),
                                    kin_v3(0, 1, 0), 75.0f, W, H, 0.05f, 10.0f);
    float *tpos = malloc(sizeof(float) * 3 * (size_t)A.nv);
    uint8_t *rgba[2], *mask = malloc(W * H), *kin_mask[2];
    assert_true(tpos && mask);
    turned(&A, true_phi, tpos);
    fuse_image P[2];
    for (int e = 0; e < 2; e++) {
        rgba[e] = malloc(4 * W * H);
        kin_mask[e] = malloc(W * H);
        assert_true(rgba[e] && kin_mask[e]);
        draw(&A, tpos, &cam[e], mask);
        for (int i = 0; i < W * H; i++) {
            int n = (int)(tu_next(&g) % 9) - 4;
            uint8_t *p = &rgba[e][i * 4];
            p[0] = (uint8_t)((mask[i] ? 200 : 70) + n);
            p[1] = (uint8_t)((mask[i] ? 120 : 90) + n);
            p[2] = (uint8_t)((mask[i] ? 100 : 150) + n);
            p[3] = 255;
        }
        P[e] = (fuse_image){ rgba[e], W, H, 4 * W };
        draw(&A, A.pos, &cam[e], kin_mask[e]);
    }
    pipe_fit *f = pipe_fit_create(NULL, &A.m, &A.rig, W, H);
    assert_non_null(f);
    for (int e = 0; e < 2; e++)
        assert_int_equal(pipe_fit_learn(f, e, &P[e], kin_mask[e], W, NULL, 0), FUSE_OK);
    assert_true(pipe_fit_colour(f, 0)->fg_samples >= 64);
    kin_transform locals[7];
    memcpy(locals, A.rest, sizeof locals);
    kin_mat4 w0[7], w1[7];
    kin_fk(A.parents, 7, locals, NULL, w0);
    pipe_fit_elbows(f, w0, A.pos, cam, P, 3u, locals, found);
    kin_fk(A.parents, 7, locals, NULL, w1);
    for (int s = 0; s < 2; s++) {
        /* the elbow where the found swivel puts it, the wrist and the
         * hand's world pose unchanged */
        float x = s ? 0.2f : -0.2f;
        kin_quat q = kin_quat_axis_angle(kin_v3(0, 0, -1), found[s]);
        kin_vec3 E = kin_v3_add(kin_v3(x, 0, 0), kin_quat_rotate(q, kin_v3(0, -0.15f, -0.25f)));
        const float *el = &w1[2 + 3 * s].m[12], *wr = &w1[3 + 3 * s].m[12];
        NEAR3(*(const kin_vec3 *)el, E.x, E.y, E.z, 1e-4);
        NEAR3(*(const kin_vec3 *)wr, x, 0.0, -0.5, 1e-4);
        for (int k = 0; k < 12; k++) NEAR(w1[3 + 3 * s].m[k], w0[3 + 3 * s].m[k], 1e-4);
    }
    pipe_fit_destroy(f);
    for (int e = 0; e < 2; e++) {
        free(rgba[e]);
        free(kin_mask[e]);
    }
    free(mask);
    free(tpos);
    arms_free(&A);
}

static void finds_turned_elbows(void **state)
{
    (void)state;
    const float phi[2] = { 20.0f * D2R, -15.0f * D2R };
    float found[2];
    fit_case(phi, found, 0x666974);
    NEAR(found[0] / D2R, 20.0, 3.0);
    NEAR(found[1] / D2R, -15.0, 3.0);
}

static void stays_when_right(void **state)
{
    (void)state;
    const float phi[2] = { 0.0f, 0.0f };
    float found[2];
    fit_case(phi, found, 0x666975);
    NEAR(found[0] / D2R, 0.0, 3.0);
    NEAR(found[1] / D2R, 0.0, 3.0);
}

static void bad_arguments(void **state)
{
    (void)state;
    arms A;
    arms_build(&A);
    assert_null(pipe_fit_create(NULL, NULL, &A.rig, W, H));
    assert_null(pipe_fit_create(NULL, &A.m, &A.rig, 0, H));
    kin_arm_rig none = A.rig;
    none.joint[1][KIN_RIG_UPPER_ARM] = none.joint[1][KIN_RIG_FOREARM] = 0; /* no vertex on it */
    assert_null(pipe_fit_create(NULL, &A.m, &none, W, H));
    pipe_fit *f = pipe_fit_create(NULL, &A.m, &A.rig, W, H);
    assert_non_null(f);
    uint8_t px[4 * 8] = { 0 }, m[8] = { 0 };
    fuse_image small = { px, 8, 1, 32 };
    assert_int_equal(pipe_fit_learn(f, 0, &small, m, 8, NULL, 0), FUSE_ERR_ARGS);
    assert_int_equal(pipe_fit_learn(f, 2, &small, m, 8, NULL, 0), FUSE_ERR_ARGS);
    pipe_fit_destroy(f);
    pipe_fit_destroy(NULL);
    arms_free(&A);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(finds_turned_elbows),
        cmocka_unit_test(stays_when_right),
        cmocka_unit_test(bad_arguments),
    };
    return cmocka_run_group_tests_name("pipe_fit", tests, NULL, NULL);
}
