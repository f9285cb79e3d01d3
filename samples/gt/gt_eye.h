/* gt_eye.h - ground truth from the eyes' true viewpoint, for the eye-view
 * evaluation of `egofuse eval --eyeview` (docs/accuracy.md, issue 18).
 *
 * WHAT IT DOES
 *   The HMD's cameras sit D = cam_offset_m in front of the eyes; the eyes
 *   are at kin_sthmd_eye (+-ipd/2 in the head frame). This file renders
 *   the true operator (posed by gen_pose) as the EYE sees it, through the
 *   display's pinhole, the projection the virtual scene is rendered with
 *   (gen_render_virtual: lcd_width x lcd_height, fx = w / 2 tan(hfov/2),
 *   fy = h / 2 tan(vfov/2), centre (w/2, h/2)):
 *     gt_eye_camera()      that pinhole as a kin_camera;
 *     gt_part_triangles()  the triangles of a part (a hand, a fingertip);
 *     gt_render_view()     from any kin_camera: the arms' colour (the
 *                          cockpit's lighting, no camera noise, no
 *                          vignetting), their silhouette (pixel centres, the
 *                          rasterizer's rule), the hands' silhouette, the
 *                          view-space normals and the hands' mean depth.
 *   Deterministic: no global state.
 */
#ifndef EGOFUSE_GT_EYE_H
#define EGOFUSE_GT_EYE_H

#include <stdint.h>

#include "../gen/gen.h"

/* The eye's pinhole for display hd (NULL = the paper's): view from
 * kin_sthmd_eye(hd, world_from_head, eye), width x height = lcd size,
 * proj = gen_proj_from_intrinsics(..., GEN_VIRT_ZNEAR, GEN_VIRT_ZFAR),
 * lens zero (a pinhole). */
kin_camera gt_eye_camera(const kin_sthmd_desc *hd, const kin_mat4 *world_from_head,
                         kin_eye eye);

/* The triangles of arms' mesh whose three vertices are each bound with
 * weight >= 0.5 to joints first..last (gen_side_joint: GEN_J_HAND ..
 * GEN_SIDE_JOINTS - 1 the hand, GEN_J_MIDDLE_3 alone the middle
 * fingertip) of a side in sides (bit 0 left, bit 1 right): a malloc'd
 * index list (3 per triangle, free()), *tri_count set; NULL when out of
 * memory or no such triangle. */
uint32_t *gt_part_triangles(const gen_arms *arms, unsigned sides, int first, int last,
                            int *tri_count);

/* Renders the arms posed by gen_pose(c, ...) through cam (cam->width x
 * cam->height pixels, at most the context's targets: GEN_VIRT_W x
 * GEN_VIRT_H for the paper's HMD):
 *   rgba  cam->width * 4 bytes per row: the arms' colour, alpha 255 on the
 *         silhouette, (0,0,0,0) elsewhere; NULL: not written;
 *   sil   255 where the arms cover the pixel centre, else 0;
 *   hand  255 where a triangle of the part hand_idx (hand_tris triangles,
 *         gt_part_triangles) covers it (the rest of the arms in front is
 *         not removed); NULL: not drawn;
 *   nrm   3 floats per pixel, view-space unit normals of the arms (0
 *         elsewhere); NULL: not written;
 *   *hand_depth  mean view-space depth (metres along -Z) of the part's
 *         vertices in front of the camera; NULL: not computed.
 * scratch_depth: cam->width x cam->height floats. */
void gt_render_view(gen_frame_ctx *c, const kin_camera *cam, const uint32_t *hand_idx,
                    int hand_tris, uint8_t *rgba, uint8_t *sil, uint8_t *hand, float *nrm,
                    float *scratch_depth, double *hand_depth);

/* The pixels of sil (the silhouette of the last gt_render_view through
 * eye, whose depths the context still holds; the projection's near and far
 * znear, zfar: GEN_VIRT_ZNEAR, GEN_VIRT_ZFAR for gt_eye_camera) whose
 * surface point projects inside cam's image (in front of it; occlusion
 * not considered): 255 there, 0 elsewhere, into out (eye's size). What a
 * method showing the camera's pixels can show at best. */
void gt_view_seen_by(const gen_frame_ctx *c, const kin_camera *eye, float znear, float zfar,
                     const kin_camera *cam, const uint8_t *sil, uint8_t *out);

#endif
