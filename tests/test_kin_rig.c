/* test_kin_rig.c - the arm rig (kin_arm_rig_init, kin_arm_rig_pose)
 * against the project's generated model build/samples/model/arms.glb
 * (made by build/gen_samples; generated into a scratch folder when the
 * samples are missing, SKIP when the generator is missing too):
 *   - the rig finds every joint, with the bone lengths of the rest pose,
 *     and names every joint a damaged model lacks;
 *   - seeded tracking samples within reach: after kin_arm_rig_pose + FK
 *     the hand nodes sit on the wrist targets (1 mm) with the sample's hand
 *     rotation, the elbows where the IK put them, the shoulders and head
 *     on the tracked points; out of reach: the wrist on the shoulder-target
 *     line with reach_error = the remaining distance;
 *   - the model's own animation, re-targeted through tracking samples of
 *     its true shoulders, wrists and hand rotations: wrists on target;
 *   - the skinned mesh under IK poses stays finite (SIMD dispatch);
 *   - the generator's track.txt drives the rig onto the animation. */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"
#include "../src/kin/kin.h"
#include "support/sample_model.h"

TU_SAMPLE_GROUP(g_samples, "rig_samples", 3)

#define NEED_MODEL() TU_NEED_MODEL(g_samples.loaded, g_samples.skip)

static kin_vec3 wpos(const kin_mat4 *m) { return kin_v3(m->m[12], m->m[13], m->m[14]); }

/* World rotation of a rigid matrix (columns normalised). */
static kin_quat wrot(const kin_mat4 *m)
{
    kin_vec3 x = kin_v3_norm(kin_v3(m->m[0], m->m[1], m->m[2]));
    kin_vec3 y = kin_v3_norm(kin_v3(m->m[4], m->m[5], m->m[6]));
    kin_vec3 z = kin_v3_norm(kin_v3(m->m[8], m->m[9], m->m[10]));
    return kin_quat_from_axes(x, y, z);
}

/* Angle between two rotations, radians. */
static float qangle(kin_quat a, kin_quat b)
{
    float d = fabsf(a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w);
    return 2.0f * acosf(d > 1.0f ? 1.0f : d);
}

static kin_quat rand_rot(tu_rng *r)
{
    kin_quat q = tu_quat(r, -1, 1);
    return kin_quat_normalize(q);
}

/* ------------------------------------------------------------ the rig */

static void test_rig_finds_every_joint(void **state)
{
    (void)state;
    NEED_MODEL();
    kin_arm_rig rig;
    char why[512];
    int rc = kin_arm_rig_init(&rig, &g_samples.model, why, sizeof why);
    if (rc) fail_msg("kin_arm_rig_init: %s", why);
    assert_int_equal(g_samples.model.names[rig.body][0], 'b');
    assert_string_equal(g_samples.model.names[rig.body], "body");
    assert_string_equal(g_samples.model.names[rig.head], "head");
    char name[KIN_NAME_MAX];
    for (int s = 0; s < 2; s++)
        for (int j = 0; j < KIN_RIG_SIDE_JOINTS; j++) {
            int n = rig.joint[s][j];
            assert_true(n >= 0 && n < g_samples.model.node_count);
            assert_string_equal(g_samples.model.names[n],
                                kin_arm_rig_joint_name((kin_side)s, j, name, sizeof name));
        }
    /* bone lengths: the rest-pose distances of the joint nodes */
    kin_transform *loc = malloc(sizeof *loc * (size_t)g_samples.model.node_count);
    kin_mat4 *world = malloc(sizeof *world * (size_t)g_samples.model.node_count);
    kin_pose_rest(&g_samples.model, loc);
    kin_fk(g_samples.model.parents, g_samples.model.node_count, loc, NULL, world);
    for (int s = 0; s < 2; s++) {
        kin_vec3 u = wpos(&world[rig.joint[s][KIN_RIG_UPPER_ARM]]);
        kin_vec3 e = wpos(&world[rig.joint[s][KIN_RIG_FOREARM]]);
        kin_vec3 h = wpos(&world[rig.joint[s][KIN_RIG_HAND]]);
        assert_true(fabsf(kin_v3_len(kin_v3_sub(e, u)) - rig.upper_len[s]) < 1e-5f);
        assert_true(fabsf(kin_v3_len(kin_v3_sub(h, e)) - rig.fore_len[s]) < 1e-5f);
        assert_true(rig.upper_len[s] > 0.2f && rig.upper_len[s] < 0.45f);
        assert_true(rig.fore_len[s] > 0.2f && rig.fore_len[s] < 0.4f);
    }
    float sw = kin_v3_len(kin_v3_sub(wpos(&world[rig.joint[1][KIN_RIG_UPPER_ARM]]),
                                     wpos(&world[rig.joint[0][KIN_RIG_UPPER_ARM]])));
    assert_true(fabsf(sw - rig.shoulder_width) < 1e-5f);
    free(loc);
    free(world);
}

/* A copy of the model with some nodes renamed: the rig lists them all. */
static void test_rig_names_missing_joints(void **state)
{
    (void)state;
    NEED_MODEL();
    int n = g_samples.model.node_count;
    char (*names)[KIN_NAME_MAX] = malloc(sizeof *names * (size_t)n);
    memcpy(names, g_samples.model.names, sizeof *names * (size_t)n);
    static const char *const gone[] = { "R_palm", "L_thumb_3", "head" };
    for (int k = 0; k < 3; k++) {
        int i = kin_model_find_node(&g_samples.model, gone[k]);
        assert_true(i >= 0);
        snprintf(names[i], KIN_NAME_MAX, "renamed_%d", k);
    }
    kin_model m = g_samples.model;
    m.names = (const char(*)[KIN_NAME_MAX])names;
    m.block = NULL;
    kin_arm_rig rig;
    char why[512];
    assert_int_equal(kin_arm_rig_init(&rig, &m, why, sizeof why), -1);
    for (int k = 0; k < 3; k++)
        if (!strstr(why, gone[k])) fail_msg("'%s' does not name %s", why, gone[k]);
    assert_non_null(strstr(why, "missing joints (3)"));
    free(names);
}

/* ------------------------------------------------------- IK-driven poses */

typedef struct poser {
    kin_arm_rig rig;
    kin_transform *loc;
    kin_mat4 *world;
    kin_vec3 shoulder[2], head;  /* rest-pose upper_arm positions, head */
} poser;

static void poser_init(poser *p)
{
    char why[512];
    if (kin_arm_rig_init(&p->rig, &g_samples.model, why, sizeof why)) fail_msg("%s", why);
    p->loc = malloc(sizeof *p->loc * (size_t)g_samples.model.node_count);
    p->world = malloc(sizeof *p->world * (size_t)g_samples.model.node_count);
    kin_pose_rest(&g_samples.model, p->loc);
    kin_fk(g_samples.model.parents, g_samples.model.node_count, p->loc, NULL, p->world);
    for (int s = 0; s < 2; s++) p->shoulder[s] = wpos(&p->world[p->rig.joint[s][KIN_RIG_UPPER_ARM]]);
    p->head = wpos(&p->world[p->rig.head]);
}

static void poser_free(poser *p)
{
    free(p->loc);
    free(p->world);
}

static kin_track_sample base_sample(const poser *p)
{
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.valid = KIN_TRACK_ALL;
    s.head_pos = p->head;
    s.head_rot = kin_quat_identity();
    for (int k = 0; k < 2; k++) {
        s.shoulder[k] = p->shoulder[k];
        s.hand_rot[k] = kin_quat_identity();
        for (int g = 0; g < KIN_GLOVE_SENSORS; g++) s.glove[k][g] = 0.3f;
    }
    return s;
}

/* Poses from s, runs FK; returns the IK jobs. */
static void pose(poser *p, const kin_track_sample *s, kin_arm_ik_job ik[2])
{
    kin_pose_rest(&g_samples.model, p->loc);
    assert_int_equal(kin_arm_rig_pose(&p->rig, &g_samples.model, NULL, NULL, s, p->loc, ik), 1);
    kin_fk(g_samples.model.parents, g_samples.model.node_count, p->loc, NULL, p->world);
}

static void test_ik_wrists_on_targets(void **state)
{
    (void)state;
    NEED_MODEL();
    poser p;
    poser_init(&p);
    tu_rng r = { 0x726967 };
    int reached = 0, beyond = 0;
    double worst = 0, worst_rot = 0;
    for (int it = 0; it < 400; it++) {
        kin_track_sample s = base_sample(&p);
        /* the body turned and moved a little, as a seated user does */
        kin_quat turn = kin_quat_axis_angle(kin_v3(0, 1, 0), tu_range(&r, -0.5f, 0.5f));
        kin_vec3 shift = tu_v3b(&r, -0.1f, 0.1f, -0.05f, 0.05f, -0.1f, 0.1f);
        kin_vec3 mid = kin_v3_scale(kin_v3_add(p.shoulder[0], p.shoulder[1]), 0.5f);
        for (int k = 0; k < 2; k++)
            s.shoulder[k] = kin_v3_add(kin_v3_add(mid, shift),
                                       kin_quat_rotate(turn, kin_v3_sub(p.shoulder[k], mid)));
        s.head_pos = kin_v3_add(kin_v3_add(mid, shift), kin_quat_rotate(turn, kin_v3_sub(p.head, mid)));
        s.head_rot = turn;
        float dmax[2], frac[2];
        for (int k = 0; k < 2; k++) {
            dmax[k] = p.rig.upper_len[k] + p.rig.fore_len[k];
            /* in reach (0.45 .. 0.9 of the arm) or beyond it (1.05 .. 1.5) */
            frac[k] = it % 4 == 3 ? tu_range(&r, 1.05f, 1.5f) : tu_range(&r, 0.45f, 0.9f);
            kin_vec3 dir = kin_v3_norm(tu_v3b(&r, -1, 1, -1, 0.8f, -1, 0.3f));
            if (dir.x == 0 && dir.y == 0 && dir.z == 0) dir = kin_v3(0, 0, -1);
            s.hand_pos[k] = kin_v3_add(s.shoulder[k], kin_v3_scale(dir, frac[k] * dmax[k]));
            s.hand_rot[k] = rand_rot(&r);
            for (int g = 0; g < KIN_GLOVE_SENSORS; g++) s.glove[k][g] = tu_unit(&r);
        }
        kin_arm_ik_job ik[2];
        pose(&p, &s, ik);
        /* the body chain puts the shoulders and the head on the tracked points */
        for (int k = 0; k < 2; k++) {
            kin_vec3 sh = wpos(&p.world[p.rig.joint[k][KIN_RIG_UPPER_ARM]]);
            assert_true(kin_v3_len(kin_v3_sub(sh, s.shoulder[k])) < 1e-4f);
        }
        assert_true(kin_v3_len(kin_v3_sub(wpos(&p.world[p.rig.head]), s.head_pos)) < 1e-4f);
        for (int k = 0; k < 2; k++) {
            const int *J = p.rig.joint[k];
            kin_vec3 hand = wpos(&p.world[J[KIN_RIG_HAND]]);
            kin_vec3 elbow = wpos(&p.world[J[KIN_RIG_FOREARM]]);
            float err = kin_v3_len(kin_v3_sub(hand, s.hand_pos[k]));
            /* the elbow node is where the IK put it; bones keep their length */
            assert_true(kin_v3_len(kin_v3_sub(elbow, ik[k].elbow)) < 1e-4f);
            assert_true(fabsf(kin_v3_len(kin_v3_sub(hand, elbow)) - p.rig.fore_len[k]) < 1e-4f);
            /* the hand node turns as the tracked hand */
            float rerr = qangle(wrot(&p.world[J[KIN_RIG_HAND]]), s.hand_rot[k]);
            if (rerr > worst_rot) worst_rot = rerr;
            assert_true(rerr < 2e-3f);
            if (frac[k] < 1.0f) {
                if (err > worst) worst = err;
                if (!(err < 1e-3f))
                    fail_msg("sample %d side %d: wrist %.2f mm off the target at %.2f of the "
                             "reach", it, k, (double)err * 1e3, (double)frac[k]);
                reached++;
            } else {
                /* out of reach: on the shoulder-target line, short of the
                 * straight arm, and reach_error tells the distance left */
                kin_vec3 sw = kin_v3_sub(s.hand_pos[k], s.shoulder[k]);
                kin_vec3 sh_hand = kin_v3_sub(hand, s.shoulder[k]);
                float off = kin_v3_len(kin_v3_cross(kin_v3_norm(sw), sh_hand));
                assert_true(off < 1e-3f);
                assert_true(kin_v3_len(sh_hand) <= dmax[k] + 1e-4f);
                assert_true(kin_v3_len(sh_hand) > 0.95f * dmax[k]);
                assert_true(fabsf(ik[k].reach_error - err) < 1e-3f);
                beyond++;
            }
        }
    }
    print_message("NOTE rig IK on arms.glb: %d targets in reach (worst wrist error %.3f mm, "
                  "hand rotation %.3f mrad), %d beyond reach\n", reached, worst * 1e3,
                  worst_rot * 1e3, beyond);
    assert_true(reached > 500 && beyond > 150);
    poser_free(&p);
}

/* The model's own animation as tracking input: its true shoulder, wrist
 * and hand rotations drive the rig; the wrists land where the animation
 * put them, and the elbows near the animation's (the IK's swivel rule is
 * not the animation's pole vector: a bound, not equality). */
static void test_ik_retargets_the_animation(void **state)
{
    (void)state;
    NEED_MODEL();
    assert_true(g_samples.model.anim_count >= 1);
    poser p;
    poser_init(&p);
    int n = g_samples.model.node_count;
    kin_transform *aloc = malloc(sizeof *aloc * (size_t)n);
    kin_mat4 *aw = malloc(sizeof *aw * (size_t)n);
    const kin_animation *an = &g_samples.model.anims[0];
    double worst_w = 0, sum_e = 0, worst_e = 0;
    int count = 0;
    for (int f = 0; f <= 60; f++) {
        float t = an->duration * (float)f / 60.0f;
        kin_pose_rest(&g_samples.model, aloc);
        kin_anim_sample(an, n, t, aloc);
        kin_fk(g_samples.model.parents, n, aloc, NULL, aw);
        kin_track_sample s = base_sample(&p);
        s.head_pos = wpos(&aw[p.rig.head]);
        s.head_rot = wrot(&aw[p.rig.head]);
        for (int k = 0; k < 2; k++) {
            const int *J = p.rig.joint[k];
            s.shoulder[k] = wpos(&aw[J[KIN_RIG_UPPER_ARM]]);
            s.hand_pos[k] = wpos(&aw[J[KIN_RIG_HAND]]);
            s.hand_rot[k] = wrot(&aw[J[KIN_RIG_HAND]]);
        }
        kin_arm_ik_job ik[2];
        pose(&p, &s, ik);
        for (int k = 0; k < 2; k++) {
            const int *J = p.rig.joint[k];
            float ew = kin_v3_len(kin_v3_sub(wpos(&p.world[J[KIN_RIG_HAND]]), s.hand_pos[k]));
            float d = kin_v3_len(kin_v3_sub(s.hand_pos[k], s.shoulder[k]));
            float dmax = p.rig.upper_len[k] + p.rig.fore_len[k];
            /* in the soft-reach band the IK keeps the arm short of
             * straight on purpose: reach_error says by how much */
            float allow = d < 0.96f * dmax ? 1e-3f : ik[k].reach_error + 1e-3f;
            if (!(ew <= allow))
                fail_msg("t %.3f side %d: wrist %.2f mm off (reach %.3f)", (double)t, k,
                         (double)ew * 1e3, (double)(d / dmax));
            if (ew > worst_w) worst_w = ew;
            float ee = kin_v3_len(kin_v3_sub(wpos(&p.world[J[KIN_RIG_FOREARM]]),
                                             wpos(&aw[J[KIN_RIG_FOREARM]])));
            sum_e += ee;
            if (ee > worst_e) worst_e = ee;
            count++;
        }
    }
    print_message("NOTE animation re-targeted through the IK: worst wrist error %.3f mm, "
                  "elbow vs the animation's: mean %.1f mm, worst %.1f mm\n", worst_w * 1e3,
                  sum_e / count * 1e3, worst_e * 1e3);
    assert_true(worst_e < 0.12);
    free(aloc);
    free(aw);
    poser_free(&p);
}

/* The skinned mesh of IK poses (LBS and DQS through the dispatching entry
 * points) is finite and near the body. */
static void test_skin_under_ik_finite(void **state)
{
    (void)state;
    NEED_MODEL();
    poser p;
    poser_init(&p);
    const kin_mesh *me = &g_samples.model.meshes[0];
    assert_true(me->skin >= 0);
    const kin_skin *sk = &g_samples.model.skins[me->skin];
    kin_mat4 *jm = malloc(sizeof *jm * (size_t)sk->joint_count);
    kin_dualquat *dq = malloc(sizeof *dq * (size_t)sk->joint_count);
    size_t n3 = (size_t)me->vertex_count * 3;
    float *pl = malloc(n3 * 4), *nl = malloc(n3 * 4), *pd = malloc(n3 * 4), *nd = malloc(n3 * 4);
    tu_rng r = { 4242 };
    for (int it = 0; it < 20; it++) {
        kin_track_sample s = base_sample(&p);
        for (int k = 0; k < 2; k++) {
            float dmax = p.rig.upper_len[k] + p.rig.fore_len[k];
            const float dx = tu_range(&r, -1, 1);   /* drawn in order (tu_kin.h) */
            const float dy = tu_range(&r, -1, 0.5f);
            kin_vec3 dir = kin_v3_norm(kin_v3(dx, dy, -0.7f));
            s.hand_pos[k] = kin_v3_add(s.shoulder[k], kin_v3_scale(dir, tu_range(&r, 0.4f, 1.3f) * dmax));
            s.hand_rot[k] = rand_rot(&r);
        }
        kin_arm_ik_job ik[2];
        pose(&p, &s, ik);
        kin_skin_joint_matrices(sk, p.world, jm);
        kin_skin_dq_from_matrices(jm, sk->joint_count, dq);
        kin_skin_lbs(me, jm, pl, nl);
        kin_skin_dqs(me, dq, pd, nd);
        for (size_t i = 0; i < n3; i++) {
            assert_true(isfinite(pl[i]) && isfinite(pd[i]));
            assert_true(isfinite(nl[i]) && isfinite(nd[i]));
            assert_true(fabsf(pl[i]) < 10.0f && fabsf(pd[i]) < 10.0f);
        }
    }
    free(jm); free(dq); free(pl); free(nl); free(pd); free(nd);
    poser_free(&p);
}

/* The generator's recorded tracking (track.txt) of the animation: it
 * parses, has one sample per frame at f / 60 s, and drives the rig so
 * that the wrists and shoulders land on the animation's. */
static void test_generated_tracking_drives_the_rig(void **state)
{
    (void)state;
    NEED_MODEL();
    char track[1200];
    snprintf(track, sizeof track, "%s/track.txt", g_samples.dir);
    kin_track_sample *s = NULL;
    int n = 0;
    io_error err;
    if (io_track_load(track, &s, &n, &err) != IO_OK) fail_msg("%s", err.msg);
    assert_true(n >= 1);
    poser p;
    poser_init(&p);
    int nn = g_samples.model.node_count;
    kin_transform *aloc = malloc(sizeof *aloc * (size_t)nn);
    kin_mat4 *aw = malloc(sizeof *aw * (size_t)nn);
    double worst = 0;
    for (int f = 0; f < n; f++) {
        assert_true(fabs(s[f].t - f / 60.0) < 1e-9);
        assert_int_equal(s[f].valid, KIN_TRACK_ALL);
        kin_pose_rest(&g_samples.model, aloc);
        kin_anim_sample(&g_samples.model.anims[0], nn, (float)s[f].t, aloc);
        kin_fk(g_samples.model.parents, nn, aloc, NULL, aw);
        kin_arm_ik_job ik[2];
        pose(&p, &s[f], ik);
        for (int k = 0; k < 2; k++) {
            const int *J = p.rig.joint[k];
            float e = kin_v3_len(kin_v3_sub(wpos(&p.world[J[KIN_RIG_HAND]]), wpos(&aw[J[KIN_RIG_HAND]])));
            float d = kin_v3_len(kin_v3_sub(wpos(&p.world[J[KIN_RIG_UPPER_ARM]]),
                                            wpos(&aw[J[KIN_RIG_UPPER_ARM]])));
            if (e > worst) worst = e;
            assert_true(d < 1e-4f);
            assert_true(e < 1e-3f + ik[k].reach_error);
        }
    }
    print_message("NOTE %s: %d samples, worst wrist distance to the animation %.3f mm\n",
                  track, n, worst * 1e3);
    free(aloc);
    free(aw);
    io_track_free(s);
    poser_free(&p);
}

TU_MAIN(group_setup, group_teardown,
        cmocka_unit_test(test_rig_finds_every_joint),
        cmocka_unit_test(test_rig_names_missing_joints),
        cmocka_unit_test(test_ik_wrists_on_targets),
        cmocka_unit_test(test_ik_retargets_the_animation),
        cmocka_unit_test(test_skin_under_ik_finite),
        cmocka_unit_test(test_generated_tracking_drives_the_rig))
