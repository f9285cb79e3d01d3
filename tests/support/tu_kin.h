/* tu_kin.h - seeded kin vectors and quaternions, drawn in a defined order.
 *
 * C leaves the order in which a call's arguments (or an initializer
 * list's values) are evaluated unspecified: kin_v3(tu_range(r, ..),
 * tu_range(r, ..), tu_range(r, ..)) gives other inputs with gcc than
 * with clang, and recorded CRCs then hold for one compiler only (issue
 * 20). These draw x, then y, then z (then w), one statement each;
 * scripts/rng_order.py finds draws left in one expression. */
#ifndef EGOFUSE_TU_KIN_H
#define EGOFUSE_TU_KIN_H

#include "testutil.h"
#include "../../src/kin/kin.h"

#include <math.h>

/* x, y, z uniform in [x0, x1), [y0, y1), [z0, z1), drawn in that order. */
static inline kin_vec3 tu_v3b(tu_rng *r, float x0, float x1, float y0, float y1, float z0,
                              float z1)
{
    kin_vec3 v;
    v.x = tu_range(r, x0, x1);
    v.y = tu_range(r, y0, y1);
    v.z = tu_range(r, z0, z1);
    return v;
}

/* x, y, z uniform in [lo, hi), drawn in that order. */
static inline kin_vec3 tu_v3(tu_rng *r, float lo, float hi)
{
    return tu_v3b(r, lo, hi, lo, hi, lo, hi);
}

/* x, y, z, w uniform in [lo, hi), drawn in that order (not normalized). */
static inline kin_quat tu_quat(tu_rng *r, float lo, float hi)
{
    kin_quat q;
    q.x = tu_range(r, lo, hi);
    q.y = tu_range(r, lo, hi);
    q.z = tu_range(r, lo, hi);
    q.w = tu_range(r, lo, hi);
    return q;
}

/* The fingertip gesture of the user calibration at sample i (no noise):
 * the middle fingertips, tip_l and tip_r in the hand frames (scaled to
 * the user's hands), pressed together at C = (0.01, 1.02, -0.38) and
 * `gap` metres apart along the fingers (0: touching); the left hand's
 * fingers (-Z) pointing to +X, the right hand's to -X, the pair turning
 * up to 25 deg about Y and tilting 15 deg about Z over i. Sets
 * s->hand_rot and s->hand_pos; no draws. */
static inline void tu_fingertip_gesture(kin_track_sample *s, int i, kin_vec3 tip_l,
                                        kin_vec3 tip_r, float gap)
{
    float yaw = 0.44f * sinf(0.05f * (float)i), tilt = 0.26f * cosf(0.03f * (float)i);
    kin_quat pair = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 1, 0), yaw),
                                 kin_quat_axis_angle(kin_v3(0, 0, 1), tilt));
    s->hand_rot[0] = kin_quat_mul(pair, kin_quat_axis_angle(kin_v3(0, 1, 0), -1.5707963f));
    s->hand_rot[1] = kin_quat_mul(pair, kin_quat_axis_angle(kin_v3(0, 1, 0), 1.5707963f));
    kin_vec3 C = kin_v3(0.01f, 1.02f, -0.38f);
    kin_vec3 x = kin_quat_rotate(pair, kin_v3(1, 0, 0));
    kin_vec3 tl = kin_quat_rotate(s->hand_rot[0], tip_l);
    kin_vec3 tr = kin_quat_rotate(s->hand_rot[1], tip_r);
    s->hand_pos[0] = kin_v3_sub(kin_v3_sub(C, tl), kin_v3_scale(x, 0.5f * gap));
    s->hand_pos[1] = kin_v3_add(kin_v3_sub(C, tr), kin_v3_scale(x, 0.5f * gap));
}

#endif
