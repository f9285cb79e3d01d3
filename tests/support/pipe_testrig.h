/* pipe_testrig.h - the synthetic skinned arms of tests/test_pipe.c,
 * tests/test_pipe_prior.c and tests/test_pipe_fit.c: a tube of rings
 * around a bone, bound rigidly to its joint, the one-mesh, one-skin model
 * around the tubes; the two arms below the head (tu_arms_build) of
 * test_pipe and test_pipe_prior, their silhouette from an eye and the
 * noisy camera image of it. Header-only (static inline); include after
 * support/testutil.h, <cmocka.h> and src/pipe/pipe.h. The vertices,
 * triangles and seeded draws are in the order the tests made them
 * before, so their images are unchanged. */
#ifndef EGOFUSE_PIPE_TESTRIG_H
#define EGOFUSE_PIPE_TESTRIG_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* Rings along a tube and vertices around each ring. */
enum { TU_TUBE_RINGS = 12, TU_TUBE_AROUND = 10 };
/* Vertices and triangles one tube appends. */
#define TU_TUBE_VERTS (TU_TUBE_RINGS * TU_TUBE_AROUND)
#define TU_TUBE_TRIS ((TU_TUBE_RINGS - 1) * TU_TUBE_AROUND * 2)

/* Appends a tube from a to b of radius r at vertex *nv and triangle *nt
 * (advancing both): TU_TUBE_RINGS rings of TU_TUBE_AROUND vertices, each
 * vertex bound to joint j alone (joint slot 0, weight 1; slots 1..3 left
 * as they are, zero in a zeroed array), two triangles per quad between
 * neighbouring rings. pos: 3 floats, jnt and wgt: 4 per vertex; idx: 3
 * per triangle. The ring's frame is d x Y (d x X when d is nearly Y). */
static inline void tu_tube(float *pos, uint16_t *jnt, float *wgt, uint32_t *idx, int *nv,
                           int *nt, kin_vec3 a, kin_vec3 b, float r, int j)
{
    const int R = TU_TUBE_RINGS, N = TU_TUBE_AROUND;
    kin_vec3 d = kin_v3_norm(kin_v3_sub(b, a));
    kin_vec3 e1 = kin_v3_norm(kin_v3_cross(d, fabsf(d.y) < 0.9f ? kin_v3(0, 1, 0) : kin_v3(1, 0, 0)));
    kin_vec3 e2 = kin_v3_cross(d, e1);
    int v = *nv;
    const int v0 = v;
    for (int i = 0; i < R; i++) {
        kin_vec3 c = kin_v3_add(a, kin_v3_scale(kin_v3_sub(b, a), (float)i / (R - 1)));
        for (int k = 0; k < N; k++) {
            float t = 6.2831853f * (float)k / N;
            kin_vec3 p = kin_v3_add(c, kin_v3_add(kin_v3_scale(e1, r * cosf(t)),
                                                  kin_v3_scale(e2, r * sinf(t))));
            float *o = &pos[v * 3];
            o[0] = p.x; o[1] = p.y; o[2] = p.z;
            jnt[v * 4] = (uint16_t)j;
            wgt[v * 4] = 1.0f;
            v++;
        }
    }
    int n = *nt;
    for (int i = 0; i + 1 < R; i++)
        for (int k = 0; k < N; k++) {
            uint32_t a0 = (uint32_t)(v0 + i * N + k), a1 = (uint32_t)(v0 + i * N + (k + 1) % N);
            uint32_t b0 = a0 + (uint32_t)N, b1 = a1 + (uint32_t)N;
            uint32_t *t = &idx[n * 3];
            t[0] = a0; t[1] = b0; t[2] = a1;
            t[3] = a1; t[4] = b0; t[5] = b1;
            n += 2;
        }
    *nv = v;
    *nt = n;
}

/* Makes *m the model of `nodes` nodes (parents, rest) with the one mesh
 * *mesh skinned by *skin, skin joint j = node j, the inverse bind
 * matrices (ibm, joints: `nodes` each, filled here) those of the rest
 * pose (asserted invertible). m, skin and the arrays must outlive the
 * model. */
static inline void tu_rig_bind(kin_model *m, kin_skin *skin, const kin_mesh *mesh, int nodes,
                               const int16_t *parents, const kin_transform *rest,
                               kin_mat4 *ibm, int *joints)
{
    kin_mat4 world[64];
    assert_true(nodes >= 1 && nodes <= 64);
    kin_fk(parents, nodes, rest, NULL, world);
    for (int j = 0; j < nodes; j++) {
        joints[j] = j;
        assert_true(kin_mat4_inverse(&world[j], &ibm[j]));
    }
    *skin = (kin_skin){ nodes, joints, ibm };
    m->node_count = nodes;
    m->parents = parents;
    m->rest = rest;
    m->mesh_count = 1;
    m->meshes = mesh;
    m->skin_count = 1;
    m->skins = skin;
}

/* Two arms below the head (world_from_head = identity, the cameras look
 * down -Z), each of three tubes: upper arm from the shoulder (-+0.2,
 * -0.1, 0) to the elbow 12 cm towards the middle and 30 cm in front of
 * it, forearm to the wrist (-+0.2, -0.05, -0.6), hand 15 cm on; radii
 * 3.5, 3 and 2.5 cm, each bound to its bone. Nodes: 0 body; per side s
 * (per = 3, or 4 with fingers): 1 + per s upper arm at the shoulder,
 * + 1 forearm at the elbow, + 2 hand at the wrist; with fingers, + 3 a
 * fingers node 7.5 cm beyond the wrist on the tube's outer side (2.5 cm
 * up), bound to no vertex, at fingers[s], and every other joint of the
 * rig's side on it but the shoulder (node 0). */
enum { TU_ARMS_MAX_NODES = 9 };
typedef struct tu_arms {
    kin_model m;
    kin_arm_rig rig;
    int nodes;
    int16_t parents[TU_ARMS_MAX_NODES];
    kin_transform rest[TU_ARMS_MAX_NODES];
    kin_mat4 ibm[TU_ARMS_MAX_NODES];
    int joints[TU_ARMS_MAX_NODES];
    kin_skin skin;
    kin_mesh mesh;
    float pos[6 * TU_TUBE_VERTS * 3];
    uint16_t jnt[6 * TU_TUBE_VERTS * 4];
    float wgt[6 * TU_TUBE_VERTS * 4];
    uint32_t idx[6 * TU_TUBE_TRIS * 3];
    int nv, nt;
    kin_vec3 fingers[2]; /* world position of each fingers node */
} tu_arms;

static inline void tu_arms_build(tu_arms *A, int fingers)
{
    memset(A, 0, sizeof *A);
    const int per = fingers ? 4 : 3;
    A->nodes = 1 + 2 * per;
    A->parents[0] = KIN_NO_PARENT;
    for (int j = 0; j < A->nodes; j++) A->rest[j] = kin_transform_identity();
    for (int s = 0; s < 2; s++) {
        float x = s ? 0.2f : -0.2f;
        int u = 1 + per * s;
        A->parents[u] = 0;
        for (int k = 1; k < per; k++) A->parents[u + k] = (int16_t)(u + k - 1);
        float in = s ? -0.12f : 0.12f; /* towards the middle */
        A->rest[u].t = kin_v3(x, -0.1f, 0);
        A->rest[u + 1].t = kin_v3(in, 0, -0.3f);
        A->rest[u + 2].t = kin_v3(-in, 0.05f, -0.3f);
        kin_vec3 S = kin_v3(x, -0.1f, 0), E = kin_v3(x + in, -0.1f, -0.3f),
                 Wr = kin_v3(x, -0.05f, -0.6f);
        tu_tube(A->pos, A->jnt, A->wgt, A->idx, &A->nv, &A->nt, S, E, 0.035f, u);
        tu_tube(A->pos, A->jnt, A->wgt, A->idx, &A->nv, &A->nt, E, Wr, 0.03f, u + 1);
        tu_tube(A->pos, A->jnt, A->wgt, A->idx, &A->nv, &A->nt, Wr, kin_v3(x, -0.05f, -0.75f),
                0.025f, u + 2);
        if (fingers) {
            A->rest[u + 3].t = kin_v3(0, 0.025f, -0.075f);
            A->fingers[s] = kin_v3(x, -0.025f, -0.675f);
            for (int j = 0; j < KIN_RIG_SIDE_JOINTS; j++) A->rig.joint[s][j] = u + 3;
            A->rig.joint[s][KIN_RIG_SHOULDER] = 0;
        }
        A->rig.joint[s][KIN_RIG_UPPER_ARM] = u;
        A->rig.joint[s][KIN_RIG_FOREARM] = u + 1;
        A->rig.joint[s][KIN_RIG_HAND] = u + 2;
    }
    A->mesh = (kin_mesh){.vertex_count = A->nv, .positions = A->pos, .joints = A->jnt,
                         .weights = A->wgt, .index_count = A->nt * 3, .indices = A->idx,
                         .node = -1, .skin = 0};
    tu_rig_bind(&A->m, &A->skin, &A->mesh, A->nodes, A->parents, A->rest, A->ibm, A->joints);
}

/* The silhouette of A seen from eye e of the paper's HMD at head into sil
 * (640x400, the crop), drawn with depth (640x400 floats) and clip (4
 * floats a vertex of A) as scratch; returns the eye's camera. */
static inline kin_camera tu_arms_silhouette(const tu_arms *A, const kin_mat4 *head, int e,
                                            uint8_t *sil, float *depth, float *clip)
{
    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    kin_camera cam = kin_sthmd_camera(&hd, head, (kin_eye)e);
    rast_target t = {640, 400, depth, 640, sil, 640, NULL, 0, 0, NULL, 0};
    rast_target_clear(&t);
    rast_transform_points(cam.view_proj.m, A->pos, A->nv, clip);
    rast_mesh_desc md = {clip, A->nv, NULL, 0, A->idx, A->nt, RAST_CULL_NONE};
    assert_int_equal(rast_draw(&t, &md, NULL), RAST_OK);
    return cam;
}

/* The camera image cam (640x480 RGBA) of the silhouette sil (640x400,
 * the crop from row crop_y0): skin-red (200, 120, 100) inside, blue-grey
 * (70, 90, 150) outside, a darker rim (66, 86, 146) where sil is 1 (an
 * edge's shading: neither skin nor background), plus a noise of -4..4 a
 * pixel (one draw of r a pixel, row by row). */
static inline void tu_paint_camera(uint8_t *cam, const uint8_t *sil, int crop_y0, tu_rng *r)
{
    for (int y = 0; y < 480; y++)
        for (int x = 0; x < 640; x++) {
            int yy = y - crop_y0;
            const uint8_t v = yy >= 0 && yy < 400 ? sil[yy * 640 + x] : 0;
            const int in_arm = v > 1, rim = v == 1;
            uint8_t *px = &cam[(y * 640 + x) * 4];
            int n = (int)(tu_next(r) % 9) - 4;
            px[0] = (uint8_t)((in_arm ? 200 : rim ? 66 : 70) + n);
            px[1] = (uint8_t)((in_arm ? 120 : rim ? 86 : 90) + n);
            px[2] = (uint8_t)((in_arm ? 100 : rim ? 146 : 150) + n);
            px[3] = 255;
        }
}

#endif
