/* pipe_testrig.h - the synthetic skinned arms of tests/test_pipe.c and
 * tests/test_pipe_fit.c: a tube of rings around a bone, bound rigidly to
 * its joint, and the one-mesh, one-skin model around the tubes.
 * Header-only (static inline); include after support/testutil.h,
 * <cmocka.h> and src/kin/kin.h (or src/pipe/pipe.h). The vertices and
 * triangles are in the order both tests built them before, so their
 * images are unchanged. */
#ifndef EGOFUSE_PIPE_TESTRIG_H
#define EGOFUSE_PIPE_TESTRIG_H

#include <math.h>
#include <stdint.h>

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

#endif
