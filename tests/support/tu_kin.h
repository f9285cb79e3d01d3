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

#endif
