/* gen_track.c - the recorded tracking of the sample sequence (track.txt,
 * "egofuse-track 1", docs/tracking.md): what a tracker and a pair of data
 * gloves would have measured of the true motion, frame by frame.
 *
 * Per frame f at t = f / GEN_FPS (the camera frames' clock): the
 * animation is sampled and run through FK; the head sample is the "head"
 * node (eye midpoint, -Z forward), the shoulders the upper_arm joints, the
 * hands the hand joints (wrist centre and hand frame, as the model's hand
 * joint), and each glove value the finger's curl: the flexion of its
 * middle joint (PIP; the thumb's MCP) mapped through the open and fist
 * angles of kin_hand_params_default(), clamped to [0, 1]. No noise: the
 * file is the ground truth that `egofuse render --pose tracking` solves
 * back with IK and the glove mapping. */
#include "gen.h"
#include "../../src/io/io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static kin_quat rot_of(const kin_mat4 *m)
{
    kin_vec3 x = kin_v3_norm(kin_v3(m->m[0], m->m[1], m->m[2]));
    kin_vec3 y = kin_v3_norm(kin_v3(m->m[4], m->m[5], m->m[6]));
    kin_vec3 z = kin_v3_cross(x, y);
    y = kin_v3_cross(z, x);
    return kin_quat_normalize(kin_quat_from_axes(x, y, z));
}

/* Rotation angle of a unit quaternion, degrees in [0, 180]. */
static float angle_deg(kin_quat q)
{
    float v = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z);
    return 2.0f * atan2f(v, fabsf(q.w)) * (180.0f / 3.14159265358979f);
}

int gen_track_write(const char *path, const gen_arms *arms, int frames, char *why,
                    size_t why_size)
{
    const kin_model *m = &arms->model;
    int n = m->node_count;
    kin_transform *loc = malloc(sizeof *loc * (size_t)n);
    kin_mat4 *world = malloc(sizeof *world * (size_t)n);
    kin_track_sample *s = calloc((size_t)frames, sizeof *s);
    int rc = -1;
    if (!loc || !world || !s) {
        snprintf(why, why_size, "out of memory writing %s", path);
        goto done;
    }
    const kin_hand_params hp = kin_hand_params_default();
    for (int f = 0; f < frames; f++) {
        double t = (double)f / (double)GEN_FPS;
        kin_pose_rest(m, loc);
        kin_anim_sample(&m->anims[0], n, (float)t, loc);
        kin_fk(m->parents, n, loc, NULL, world);
        kin_track_sample *o = &s[f];
        o->t = t;
        o->valid = KIN_TRACK_ALL;
        o->head_pos = kin_mat4_translation(&world[arms->head]);
        o->head_rot = rot_of(&world[arms->head]);
        for (int side = 0; side < 2; side++) {
            const int *J = arms->joint[side];
            o->shoulder[side] = kin_mat4_translation(&world[J[GEN_J_UPPER_ARM]]);
            o->hand_pos[side] = kin_mat4_translation(&world[J[GEN_J_HAND]]);
            o->hand_rot[side] = rot_of(&world[J[GEN_J_HAND]]);
            for (int fi = 0; fi < KIN_GLOVE_SENSORS; fi++) {
                float a = angle_deg(loc[J[GEN_J_THUMB_1 + 3 * fi + 1]].r);
                float lo = hp.open_deg[fi][1], hi = hp.fist_deg[fi][1];
                float g = (a - lo) / (hi - lo);
                o->glove[side][fi] = g < 0.0f ? 0.0f : g > 1.0f ? 1.0f : g;
            }
        }
        char vwhy[200];
        if (kin_track_sample_validate(o, vwhy, sizeof vwhy) < 0) {
            snprintf(why, why_size, "internal error: tracking sample %d: %s", f, vwhy);
            goto done;
        }
    }
    io_error err;
    if (io_track_save(path, s, frames, &err) != IO_OK) {
        snprintf(why, why_size, "%s", err.msg);
        goto done;
    }
    rc = 0;
done:
    free(loc);
    free(world);
    free(s);
    return rc;
}
