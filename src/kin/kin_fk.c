/* kin_fk.c - forward kinematics: local transforms to model (world) matrices.
 *
 * world[i] = world[parents[i]] * local[i], with the root matrix as the
 * parent of roots. One pass in index order, since parents come first. */
#include "kin.h"

/* Parent matrix of node i: a node whose parent index is not a valid earlier
 * node (KIN_NO_PARENT, or a broken index) hangs off the root. */
static const kin_mat4 *parent_of(const int16_t *parents, int i,
                                 const kin_mat4 *root, const kin_mat4 *world)
{
    int p = parents ? parents[i] : KIN_NO_PARENT;
    if (p >= 0 && p < i) return &world[p];
    return root;
}

void kin_fk(const int16_t *parents, int count, const kin_transform *locals,
            const kin_mat4 *root_or_null, kin_mat4 *world)
{
    if (!locals || !world) return;
    for (int i = 0; i < count; i++) {
        kin_mat4 l = kin_mat4_from_transform(&locals[i]);
        const kin_mat4 *p = parent_of(parents, i, root_or_null, world);
        world[i] = p ? kin_mat4_mul(p, &l) : l;
    }
}

void kin_fk_mat(const int16_t *parents, int count, const kin_mat4 *locals,
                const kin_mat4 *root_or_null, kin_mat4 *world)
{
    if (!locals || !world) return;
    for (int i = 0; i < count; i++) {
        const kin_mat4 *p = parent_of(parents, i, root_or_null, world);
        world[i] = p ? kin_mat4_mul(p, &locals[i]) : locals[i];
    }
}
