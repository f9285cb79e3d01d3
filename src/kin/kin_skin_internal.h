/* kin_skin_internal.h - the skinning kernels behind kin_skin_lbs and
 * kin_skin_dqs (not a public header).
 *
 * The scalar reference (kin_skin.c, kin_dqs.c) defines every byte; the
 * SIMD kernels (kin_skin_sse2.c, kin_skin_avx2.c, kin_skin_avx512.c, one
 * body in kin_skin_simd.inl) compute the same operations in the same
 * order lane by lane (no FMA, exact sqrt and division), so they are
 * memcmp-equal. A kernel skins the vertices [v0, v1) of a skinned mesh
 * (joints, weights and matrices present) and returns the first vertex it
 * did not do (it only does whole vectors); the dispatcher finishes the
 * rest with the reference. */
#ifndef EGOFUSE_KIN_SKIN_INTERNAL_H
#define EGOFUSE_KIN_SKIN_INTERNAL_H

#include "kin.h"

void kin__skin_lbs_ref(const kin_mesh *mesh, const kin_mat4 *jm, float *pos_out,
                       float *nrm_out, int v0, int v1);
void kin__skin_dqs_ref(const kin_mesh *mesh, const kin_dualquat *dq,
                       float *pos_out, float *nrm_out, int v0, int v1);

int kin__skin_lbs_sse2(const kin_mesh *mesh, const kin_mat4 *jm,
                       float *pos_out, float *nrm_out, int v0, int v1);
int kin__skin_lbs_avx2(const kin_mesh *mesh, const kin_mat4 *jm,
                       float *pos_out, float *nrm_out, int v0, int v1);
int kin__skin_lbs_avx512(const kin_mesh *mesh, const kin_mat4 *jm,
                         float *pos_out, float *nrm_out, int v0, int v1);
int kin__skin_dqs_sse2(const kin_mesh *mesh, const kin_dualquat *dq,
                       float *pos_out, float *nrm_out, int v0, int v1);
int kin__skin_dqs_avx2(const kin_mesh *mesh, const kin_dualquat *dq,
                       float *pos_out, float *nrm_out, int v0, int v1);
int kin__skin_dqs_avx512(const kin_mesh *mesh, const kin_dualquat *dq,
                         float *pos_out, float *nrm_out, int v0, int v1);

#endif
