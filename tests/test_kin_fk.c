/* test_kin_fk.c - forward kinematics (kin_fk.c) and model validation
 * (kin_model.c). World positions are worked by hand for 90 degree turns. */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

#define TOL 1e-5f

static kin_vec3 origin_of(const kin_mat4 *m) { return kin_v3(m->m[12], m->m[13], m->m[14]); }

/* A chain 0 -> 1 -> 2: each joint turns 90 degrees about Z, the children
 * sit 1 m along their parent's X. */
static void chain3(int16_t *parents, kin_transform *loc)
{
    parents[0] = KIN_NO_PARENT; parents[1] = 0; parents[2] = 1;
    for (int i = 0; i < 3; i++) {
        loc[i] = kin_transform_identity();
        loc[i].r = kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2);
        if (i > 0) loc[i].t = kin_v3(1, 0, 0);
    }
}

/* ------------------------------------------------------------ validity */

static void validity_empty_and_bad_parent(void **state)
{
    (void)state;
    kin_mat4 world[2];
    kin_transform loc[2] = { kin_transform_identity(), kin_transform_identity() };
    memset(world, 0x5a, sizeof world);
    kin_mat4 guard = world[0];
    kin_fk(NULL, 0, loc, NULL, world);   /* zero nodes: nothing written */
    assert_memory_equal(&world[0], &guard, sizeof guard);

    /* a parent index that does not come first hangs off the root */
    int16_t parents[2] = { 1, 5 };
    loc[0].t = kin_v3(1, 0, 0);
    loc[1].t = kin_v3(0, 2, 0);
    kin_mat4 root = kin_mat4_identity();
    root.m[14] = 3;
    kin_fk(parents, 2, loc, &root, world);
    NEAR3(origin_of(&world[0]), 1, 0, 3, 0);
    NEAR3(origin_of(&world[1]), 0, 2, 3, 0);
}

/* Builds a small valid model in one block: 3 nodes, one skinned mesh with
 * one triangle, one skin, one animation with one channel. */
typedef struct test_model {
    kin_model m;
    int16_t *parents;
    kin_transform *rest;
    kin_mesh *mesh;
    kin_skin *skin;
    kin_channel *ch;
    float *times;
    float *positions, *weights;
    uint16_t *joints;
    uint32_t *indices;
} test_model;

static void build(test_model *t)
{
    memset(t, 0, sizeof *t);
    void *blk = NULL;
    t->parents = kin_block_alloc(&blk, 3 * sizeof *t->parents);
    t->rest = kin_block_alloc(&blk, 3 * sizeof *t->rest);
    t->mesh = kin_block_alloc(&blk, sizeof *t->mesh);
    t->skin = kin_block_alloc(&blk, sizeof *t->skin);
    int *sj = kin_block_alloc(&blk, 2 * sizeof *sj);
    kin_mat4 *ibm = kin_block_alloc(&blk, 2 * sizeof *ibm);
    t->positions = kin_block_alloc(&blk, 9 * sizeof(float));
    t->weights = kin_block_alloc(&blk, 12 * sizeof(float));
    t->joints = kin_block_alloc(&blk, 12 * sizeof(uint16_t));
    t->indices = kin_block_alloc(&blk, 3 * sizeof(uint32_t));
    t->ch = kin_block_alloc(&blk, sizeof *t->ch);
    t->times = kin_block_alloc(&blk, 2 * sizeof(float));
    float *vals = kin_block_alloc(&blk, 6 * sizeof(float));
    kin_animation *an = kin_block_alloc(&blk, sizeof *an);
    assert_non_null(an);
    assert_true(((uintptr_t)ibm & 15) == 0);

    t->parents[0] = KIN_NO_PARENT; t->parents[1] = 0; t->parents[2] = 1;
    for (int i = 0; i < 3; i++) t->rest[i] = kin_transform_identity();
    sj[0] = 1; sj[1] = 2;
    ibm[0] = ibm[1] = kin_mat4_identity();
    t->skin->joint_count = 2; t->skin->joints = sj; t->skin->inverse_bind = ibm;
    for (int v = 0; v < 3; v++) {
        t->positions[v * 3 + v] = 1.0f;
        t->weights[v * 4] = 1.0f;
        t->joints[v * 4] = (uint16_t)(v & 1);
        t->indices[v] = (uint32_t)v;
    }
    t->mesh->vertex_count = 3; t->mesh->positions = t->positions;
    t->mesh->joints = t->joints; t->mesh->weights = t->weights;
    t->mesh->index_count = 3; t->mesh->indices = t->indices;
    t->mesh->node = 0; t->mesh->skin = 0;
    t->times[0] = 0; t->times[1] = 1;
    t->ch->node = 2; t->ch->path = KIN_PATH_TRANSLATION; t->ch->interp = KIN_INTERP_LINEAR;
    t->ch->key_count = 2; t->ch->comps = 3; t->ch->times = t->times; t->ch->values = vals;
    an->channel_count = 1; an->channels = t->ch; an->duration = 1;

    t->m.node_count = 3; t->m.parents = t->parents; t->m.rest = t->rest;
    t->m.mesh_count = 1; t->m.meshes = t->mesh;
    t->m.skin_count = 1; t->m.skins = t->skin;
    t->m.anim_count = 1; t->m.anims = an;
    t->m.block = blk;
}

static void expect_invalid(test_model *t, const char *what)
{
    char why[128] = "";
    int rc = kin_model_validate(&t->m, why, sizeof why);
    if (rc >= 0) fail_msg("model with %s was accepted", what);
    assert_true(why[0] != '\0');
    kin_model_free(&t->m);
    assert_null(t->m.block);
}

static void validity_model_validate(void **state)
{
    (void)state;
    test_model t;
    char why[128];

    build(&t);
    assert_int_equal(kin_model_validate(&t.m, why, sizeof why), 0);
    kin_model_free(&t.m);

    build(&t); t.parents[1] = 2;                 /* parent after child */
    expect_invalid(&t, "a parent after its child");
    build(&t); t.parents[2] = 2;                 /* own parent */
    expect_invalid(&t, "a node its own parent");
    build(&t); t.rest[1].r.w = NAN;
    expect_invalid(&t, "a NaN rotation");
    build(&t); t.indices[2] = 3;
    expect_invalid(&t, "an index past the vertices");
    build(&t); t.mesh->index_count = 2;
    expect_invalid(&t, "2 indices");
    build(&t); t.mesh->weights = NULL;
    expect_invalid(&t, "a skinned mesh without weights");
    build(&t); t.joints[4] = 2;                  /* skin has 2 joints */
    expect_invalid(&t, "a joint index past the skin");
    build(&t); t.weights[1] = -0.5f;
    expect_invalid(&t, "a negative weight");
    build(&t); t.mesh->skin = 1;
    expect_invalid(&t, "a mesh using a missing skin");
    build(&t); ((int *)t.skin->joints)[1] = 3;
    expect_invalid(&t, "a skin joint past the nodes");
    build(&t); t.times[1] = 0;
    expect_invalid(&t, "key times not increasing");
    build(&t); t.ch->node = 3;
    expect_invalid(&t, "a channel on a missing node");
    build(&t); t.ch->key_count = 0;
    expect_invalid(&t, "a channel without keys");
    build(&t); t.positions[4] = INFINITY;
    expect_invalid(&t, "an infinite position");
    build(&t); t.m.node_count = KIN_MAX_NODES + 1;
    expect_invalid(&t, "too many nodes");
    assert_true(kin_model_validate(NULL, why, sizeof why) < 0);

    /* a joint index past the skin is fine when its weight is 0 */
    build(&t); t.joints[5] = 40;
    assert_int_equal(kin_model_validate(&t.m, why, sizeof why), 0);
    kin_model_free(&t.m);
}

static void validity_find_node(void **state)
{
    (void)state;
    char names[2][KIN_NAME_MAX] = { "arm", "hand" };
    kin_model m;
    memset(&m, 0, sizeof m);
    m.node_count = 2;
    m.names = (const char (*)[KIN_NAME_MAX])names;
    assert_int_equal(kin_model_find_node(&m, "hand"), 1);
    assert_int_equal(kin_model_find_node(&m, "arm"), 0);
    assert_int_equal(kin_model_find_node(&m, "leg"), -1);
    assert_int_equal(kin_model_find_node(NULL, "arm"), -1);
}

/* -------------------------------------------------------------- result */

static void result_chain_90(void **state)
{
    (void)state;
    int16_t parents[3];
    kin_transform loc[3];
    kin_mat4 world[3];
    chain3(parents, loc);
    kin_fk(parents, 3, loc, NULL, world);
    /* node 1 = R90 (1,0,0) = (0,1,0); node 2 = R90 ((0,1,0) + (1,0,0)) = (-1,1,0) */
    NEAR3(origin_of(&world[0]), 0, 0, 0, TOL);
    NEAR3(origin_of(&world[1]), 0, 1, 0, TOL);
    NEAR3(origin_of(&world[2]), -1, 1, 0, TOL);
    /* accumulated turns: node 2 is at 270 degrees, its X axis points -Y */
    NEAR3(kin_mat4_mul_dir(&world[2], kin_v3(1, 0, 0)), 0, -1, 0, TOL);
    NEAR3(kin_mat4_mul_dir(&world[1], kin_v3(1, 0, 0)), -1, 0, 0, TOL);
    /* a point 0.5 along node 2's X */
    NEAR3(kin_mat4_mul_point(&world[2], kin_v3(0.5f, 0, 0)), -1, 0.5, 0, TOL);
}

static void result_root_and_scale(void **state)
{
    (void)state;
    int16_t parents[3];
    kin_transform loc[3];
    kin_mat4 world[3];
    chain3(parents, loc);
    /* root: move to (10, 0, -2) and turn 90 degrees about X (Y -> Z) */
    kin_mat4 root = kin_mat4_from_tr(kin_v3(10, 0, -2),
                                     kin_quat_axis_angle(kin_v3(1, 0, 0), PI_F / 2));
    kin_fk(parents, 3, loc, &root, world);
    NEAR3(origin_of(&world[0]), 10, 0, -2, TOL);
    NEAR3(origin_of(&world[1]), 10, 0, -1, TOL);
    NEAR3(origin_of(&world[2]), 9, 0, -1, TOL);
    /* a parent scale of 2 doubles the children's offsets */
    loc[0].s = kin_v3(2, 2, 2);
    kin_fk(parents, 3, loc, NULL, world);
    NEAR3(origin_of(&world[1]), 0, 2, 0, TOL);
    NEAR3(origin_of(&world[2]), -2, 2, 0, TOL);
}

static void result_branching_tree(void **state)
{
    (void)state;
    /* 0 root at (0,1,0); 1 and 2 children of 0; 3 child of 1; 4 child of 2 */
    int16_t parents[5] = { KIN_NO_PARENT, 0, 0, 1, 2 };
    kin_transform loc[5];
    for (int i = 0; i < 5; i++) loc[i] = kin_transform_identity();
    loc[0].t = kin_v3(0, 1, 0);
    loc[1].t = kin_v3(1, 0, 0);
    loc[1].r = kin_quat_axis_angle(kin_v3(0, 1, 0), PI_F / 2); /* X -> -Z */
    loc[2].t = kin_v3(-1, 0, 0);
    loc[3].t = kin_v3(2, 0, 0);
    loc[4].t = kin_v3(0, 0, 3);
    kin_mat4 world[5];
    kin_fk(parents, 5, loc, NULL, world);
    NEAR3(origin_of(&world[1]), 1, 1, 0, TOL);
    NEAR3(origin_of(&world[2]), -1, 1, 0, TOL);
    NEAR3(origin_of(&world[3]), 1, 1, -2, TOL);
    NEAR3(origin_of(&world[4]), -1, 1, 3, TOL);
}

static void result_fk_mat_agrees(void **state)
{
    (void)state;
    tu_rng g = { 0x6b696e04 };
    enum { N = 40 };
    int16_t parents[N];
    kin_transform loc[N];
    kin_mat4 lm[N], w1[N], w2[N];
    for (int i = 0; i < N; i++) {
        parents[i] = (int16_t)(i == 0 ? KIN_NO_PARENT : tu_int(&g, i));
        loc[i].t = tu_v3(&g, -0.3f, 0.3f);
        const float ax = tu_range(&g, -1, 1);   /* drawn in order (tu_kin.h) */
        const float ay = tu_range(&g, -1, 1);
        const float angle = tu_range(&g, -PI_F, PI_F);
        loc[i].r = kin_quat_axis_angle(kin_v3(ax, ay, 1), angle);
        loc[i].s = kin_v3(1, 1, 1);
        lm[i] = kin_mat4_from_transform(&loc[i]);
    }
    kin_mat4 root = kin_mat4_from_tr(kin_v3(1, 2, 3), kin_quat_axis_angle(kin_v3(0, 1, 0), 0.7f));
    kin_fk(parents, N, loc, &root, w1);
    kin_fk_mat(parents, N, lm, &root, w2);
    assert_memory_equal(w1, w2, sizeof w1);
    /* and against the definition, node by node */
    for (int i = 0; i < N; i++) {
        const kin_mat4 *p = parents[i] < 0 ? &root : &w1[parents[i]];
        kin_mat4 e = kin_mat4_mul(p, &lm[i]);
        for (int k = 0; k < 16; k++) NEAR(w1[i].m[k], e.m[k], 0);
        /* rigid chains keep the distance to the parent */
        kin_vec3 d = kin_v3_sub(origin_of(&w1[i]), origin_of(p));
        NEAR(kin_v3_len(d), kin_v3_len(loc[i].t), 1e-5);
    }
}

TU_MAIN_NAMED("kin_fk", NULL, NULL,
              cmocka_unit_test(validity_empty_and_bad_parent),
              cmocka_unit_test(validity_model_validate),
              cmocka_unit_test(validity_find_node),
              cmocka_unit_test(result_chain_90),
              cmocka_unit_test(result_root_and_scale),
              cmocka_unit_test(result_branching_tree),
              cmocka_unit_test(result_fk_mat_agrees))
