/* kin.h - skeleton, forward kinematics, animation sampling, skinning and the
 * STHMD camera model of egofuse.
 *
 * WHAT IT DOES
 *   - Plain data for a skinned model (kin_model): a node hierarchy sorted
 *     parent-before-child, triangle meshes with joints/weights, skins with
 *     inverse bind matrices, and glTF-style animations. io_gltf_load() fills
 *     it from a .gltf/.glb; the sample generator builds one directly.
 *   - Forward kinematics: local TRS transforms -> model (world) matrices.
 *   - Animation sampling at a time t: LINEAR (lerp; slerp for rotations),
 *     STEP and CUBICSPLINE, per the glTF 2.0 specification.
 *   - Linear blend skinning of positions and normals per the glTF spec
 *     (jointMatrix = world(joint) * inverseBindMatrix; normals by the
 *     inverse transpose of the blended matrix, renormalised).
 *   - The STHMD camera model of the paper: per-eye view and projection from
 *     the head pose, baseline, camera offset D and FOV, the crop (eq. 1) and
 *     the perspective-correcting viewport (eq. 2-4).
 *
 * WHAT IT DOES NOT
 *   - No file I/O (see src/io/io.h), no allocation in the per-frame calls
 *     (kin_fk, kin_anim_sample, kin_skin_*, kin_sthmd_*). Only
 *     kin_model_free() releases memory, and only memory a kin_model owns.
 *   - No global state: every call is reentrant; different models or outputs
 *     may be processed on different threads at once.
 *
 * CONVENTIONS
 *   Metres, right-handed, glTF axes (+Y up, a camera looks down -Z, +X is
 *   right). Matrices are 4x4 float, column-major like glTF:
 *   m[col*4 + row], so a translation sits in m[12], m[13], m[14].
 *   Quaternions are (x, y, z, w), unit length.
 *
 * USAGE
 *   kin_model m;                        // filled by io_gltf_load()
 *   kin_transform *loc = malloc(m.node_count * sizeof *loc);
 *   kin_mat4 *world = malloc(m.node_count * sizeof *world);
 *   kin_pose_rest(&m, loc);                          // start from the rest pose
 *   kin_anim_sample(&m.anims[0], m.node_count, 0.5f, loc);  // t = 0.5 s
 *   kin_fk(m.parents, m.node_count, loc, NULL, world);
 *   kin_skin_joint_matrices(&m.skins[0], world, jm); // jm: joint_count mats
 *   kin_skin_lbs(&m.meshes[0], jm, pos_out, nrm_out);
 *   kin_model_free(&m);
 */
#ifndef EGOFUSE_KIN_H
#define EGOFUSE_KIN_H

#include <stdint.h>
#include <stddef.h>

#include "kin_lens.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------- math */

typedef struct kin_vec3 { float x, y, z; } kin_vec3;
typedef struct kin_quat { float x, y, z, w; } kin_quat;
/* Column-major 4x4: m[col*4 + row]. */
typedef struct kin_mat4 { float m[16]; } kin_mat4;
/* Translation, rotation, scale; the matrix is T * R * S (glTF order). */
typedef struct kin_transform { kin_vec3 t; kin_quat r; kin_vec3 s; } kin_transform;

kin_vec3 kin_v3(float x, float y, float z);
kin_vec3 kin_v3_add(kin_vec3 a, kin_vec3 b);
kin_vec3 kin_v3_sub(kin_vec3 a, kin_vec3 b);
kin_vec3 kin_v3_scale(kin_vec3 a, float s);
float    kin_v3_dot(kin_vec3 a, kin_vec3 b);
kin_vec3 kin_v3_cross(kin_vec3 a, kin_vec3 b);
float    kin_v3_len(kin_vec3 a);
/* Unit vector; returns (0,0,0) for a zero-length (or non-finite) input. */
kin_vec3 kin_v3_norm(kin_vec3 a);

kin_quat kin_quat_identity(void);
kin_quat kin_quat_mul(kin_quat a, kin_quat b);  /* a*b: rotate by b, then by a */
kin_quat kin_quat_normalize(kin_quat q);                /* identity if |q|==0 */
kin_quat kin_quat_axis_angle(kin_vec3 axis, float radians);
kin_vec3 kin_quat_rotate(kin_quat q, kin_vec3 v);
/* Shortest-path spherical interpolation, t in [0,1]; falls back to
 * normalised lerp when the quaternions are nearly parallel. */
kin_quat kin_quat_slerp(kin_quat a, kin_quat b, float t);

kin_mat4 kin_mat4_identity(void);
kin_mat4 kin_mat4_mul(const kin_mat4 *a, const kin_mat4 *b);   /* a * b */
kin_mat4 kin_mat4_from_transform(const kin_transform *t);
/* General inverse; returns 0 (and leaves *out as identity) when singular. */
int      kin_mat4_inverse(const kin_mat4 *a, kin_mat4 *out);
/* Affine transforms: the bottom row of a is ignored (no divide by w). */
kin_vec3 kin_mat4_mul_point(const kin_mat4 *a, kin_vec3 p);     /* w = 1 */
kin_vec3 kin_mat4_mul_dir(const kin_mat4 *a, kin_vec3 d);       /* w = 0 */
/* Right-handed look-at view matrix (world -> view), like gluLookAt. */
kin_mat4 kin_mat4_look_at(kin_vec3 eye, kin_vec3 target, kin_vec3 up);
/* OpenGL-style symmetric perspective (clip z in [-w, w]), vertical FOV. */
kin_mat4 kin_mat4_perspective(float fovy_rad, float aspect, float znear, float zfar);
/* Transform from translation + rotation (scale 1). */
kin_mat4 kin_mat4_from_tr(kin_vec3 t, kin_quat r);
/* The other way, for a rigid (or nearly rigid) transform: its translation
 * (column 3), and the rotation of its columns made orthonormal (x = column 0
 * normalised, z = x cross column 1 normalised, y = z cross x), normalised. */
kin_vec3 kin_mat4_translation(const kin_mat4 *m);
kin_quat kin_mat4_rotation(const kin_mat4 *m);

kin_transform kin_transform_identity(void);

/* --------------------------------------------------------------- model */

#define KIN_NO_PARENT (-1)
#define KIN_MAX_NODES 4096
#define KIN_NAME_MAX 64

typedef enum kin_path {
    KIN_PATH_INVALID = 0,
    KIN_PATH_TRANSLATION,
    KIN_PATH_ROTATION,
    KIN_PATH_SCALE,
    KIN_PATH_WEIGHTS          /* morph weights (kin_anim_sample_weights) */
} kin_path;

typedef enum kin_interp {
    KIN_INTERP_LINEAR = 0,    /* glTF default */
    KIN_INTERP_STEP,
    KIN_INTERP_CUBICSPLINE
} kin_interp;

/* One animation channel: the keys of one path of one node.
 * values holds key_count * comps floats for LINEAR and STEP, and
 * key_count * 3 * comps (in-tangent, value, out-tangent per key, as glTF
 * stores them) for CUBICSPLINE. comps is 3 (T, S) or 4 (R, x y z w). */
typedef struct kin_channel {
    int node;                 /* index into the model's nodes */
    kin_path path;
    kin_interp interp;
    int key_count;            /* >= 1 */
    int comps;                /* 3 or 4 (or the morph target count) */
    const float *times;       /* key_count, strictly increasing, seconds */
    const float *values;
} kin_channel;

typedef struct kin_animation {
    char name[KIN_NAME_MAX];
    int channel_count;
    const kin_channel *channels;
    float duration;           /* last key time over all channels, seconds */
} kin_animation;

/* One triangle mesh (a glTF primitive with mode TRIANGLES, or a
 * TRIANGLE_STRIP / TRIANGLE_FAN turned into its triangles).
 *
 * Morph targets (glTF): a posed vertex is
 *   p = positions[v] + sum_k w_k target_positions[(k * vertex_count + v) * 3]
 * (the same for normals with target_normals), applied before skinning
 * (kin_morph_apply); w_k are the node's current morph weights:
 * target_weights unless an animation's `weights` channel drives them
 * (kin_anim_sample_weights). Without targets the last five fields are 0.
 *
 * Skin influences: joints/weights hold the first 4 (glTF JOINTS_0 /
 * WEIGHTS_0); a file with JOINTS_1/WEIGHTS_1 ... adds extra_sets more sets
 * of 4 in joints_extra / weights_extra (4 * extra_sets per vertex, set
 * after set). All are summed as stored (no renormalisation). Fields added
 * at the end: a mesh built with {...} or memset to 0 has neither. */
typedef struct kin_mesh {
    int vertex_count;
    const float *positions;   /* 3 per vertex, in the mesh node's space */
    const float *normals;     /* 3 per vertex, or NULL if the file has none */
    const uint16_t *joints;   /* 4 per vertex (indices into the skin), or NULL */
    const float *weights;     /* 4 per vertex (as stored; >= 0), or NULL */
    int index_count;          /* multiple of 3 */
    const uint32_t *indices;  /* < vertex_count */
    int node;                 /* node that instantiates the mesh */
    int skin;                 /* index into skins, or -1 when unskinned */
    int target_count;         /* morph targets, 0 if none */
    const float *target_positions; /* target_count * vertex_count * 3 deltas
                                      (zeros for a target without POSITION) */
    const float *target_normals;   /* the same for NORMAL, or NULL when no
                                      target has NORMAL (or no normals) */
    const float *target_weights;   /* target_count default weights: the
                                      node's `weights`, else the mesh's,
                                      else 0 */
    int extra_sets;           /* influence sets beyond the first, 0 if none */
    const uint16_t *joints_extra;  /* 4 * extra_sets per vertex, or NULL */
    const float *weights_extra;    /* 4 * extra_sets per vertex, or NULL */
} kin_mesh;

typedef struct kin_skin {
    int joint_count;
    const int *joints;             /* node index of each joint */
    const kin_mat4 *inverse_bind;  /* joint_count; identity when absent */
} kin_skin;

/* A whole model. Nodes are sorted so that parents[i] < i (depth first);
 * node_src[i] gives the index the node had in the source file. */
typedef struct kin_model {
    int node_count;
    const int16_t *parents;        /* KIN_NO_PARENT for roots */
    const kin_transform *rest;     /* local rest transform of each node */
    const char (*names)[KIN_NAME_MAX];
    const int *node_src;
    int mesh_count;
    const kin_mesh *meshes;
    int skin_count;
    const kin_skin *skins;
    int anim_count;
    const kin_animation *anims;
    void *block;                   /* owner of all memory above, or NULL */
} kin_model;

/* Frees the memory the model owns (model->block) and zeroes it. */
void kin_model_free(kin_model *model);
/* Allocates size zeroed bytes (16-byte aligned) owned by *block, a chain
 * that kin_model_free() releases at once: loaders and generators build a
 * model with it. Returns NULL when out of memory. */
void *kin_block_alloc(void **block, size_t size);
/* Index of the node with this name, or -1. */
int  kin_model_find_node(const kin_model *model, const char *name);
/* The first animation with this name; the first animation when name is
 * NULL or ""; NULL when there is none. */
const kin_animation *kin_model_find_anim(const kin_model *model, const char *name);
/* Checks the invariants above (parent order, index ranges, finite values,
 * key times increasing, weights present when a skin is). Returns 0 if
 * valid, else a negative code and a reason in why[why_size]. */
int  kin_model_validate(const kin_model *model, char *why, size_t why_size);

/* ------------------------------------------------- kinematics (per frame) */

/* Copies the rest transforms into locals[node_count]. */
void kin_pose_rest(const kin_model *model, kin_transform *locals);

/* Samples every channel of anim at time t (seconds; clamped to the first
 * and last key, as glTF players do) into locals, overwriting only the
 * animated paths. node_count bounds the channel node indices (channels
 * naming a node >= node_count are ignored). Rotations are renormalised. */
void kin_anim_sample(const kin_animation *anim, int node_count, float t,
                     kin_transform *locals);

/* Morph weights of `node` at time t: samples the last `weights` channel
 * of anim that targets the node with `count` values per key (STEP, LINEAR
 * per component, CUBICSPLINE; clamped like kin_anim_sample) into
 * weights[count]. Returns 1, or 0 (weights untouched) when anim has no
 * such channel. */
int kin_anim_sample_weights(const kin_animation *anim, int node, float t,
                            float *weights, int count);

/* Morph targets of vertices [v0, v1) of mesh with weights[target_count]:
 * pos_out[v] = positions[v] + sum_k weights[k] * target_positions[k][v],
 * in target order, a weight of exactly 0 skipped; normals likewise into
 * nrm_out when both mesh->normals and nrm_out are non-NULL (without
 * target_normals they are copied). Not renormalised (skinning and
 * kin_mesh_transform renormalise). pos_out / nrm_out hold the whole mesh
 * (indexed by v) and must not alias the mesh arrays. */
void kin_morph_apply(const kin_mesh *mesh, const float *weights,
                     float *pos_out, float *nrm_out, int v0, int v1);

/* Forward kinematics: world[i] = world[parent[i]] * M(locals[i]), with
 * root = root_or_null (identity if NULL) as the parent of roots.
 * Requires parents[i] < i (a node whose parent index is not an earlier node
 * is treated as a root). */
void kin_fk(const int16_t *parents, int count, const kin_transform *locals,
            const kin_mat4 *root_or_null, kin_mat4 *world);

/* Same with local matrices instead of TRS (for joint-angle drivers). */
void kin_fk_mat(const int16_t *parents, int count, const kin_mat4 *locals,
                const kin_mat4 *root_or_null, kin_mat4 *world);

/* jm[j] = world[skin->joints[j]] * skin->inverse_bind[j]. */
void kin_skin_joint_matrices(const kin_skin *skin, const kin_mat4 *world,
                             kin_mat4 *jm);

/* Linear blend skinning of mesh positions (and normals, when both
 * mesh->normals and nrm_out are non-NULL) with joint matrices jm.
 * pos_out / nrm_out: 3 floats per vertex. Normals are transformed by the
 * cofactor (inverse transpose up to scale) of the blended matrix and
 * renormalised. A vertex whose weights sum to 0 keeps its bind position.
 * Normals use sign(det) * cofactor, so mirroring keeps them outward.
 * pos_out / nrm_out must not alias the mesh arrays. */
void kin_skin_lbs(const kin_mesh *mesh, const kin_mat4 *jm,
                  float *pos_out, float *nrm_out);

/* Rigid transform of an unskinned mesh by one matrix (positions, and
 * normals by the cofactor, renormalised). */
void kin_mesh_transform(const kin_mesh *mesh, const kin_mat4 *m,
                        float *pos_out, float *nrm_out);

/* ------------------------------------------------- STHMD camera model */

/* One HMD's description (docs/kin.md, "The STHMD camera model"). Zero
 * means default for every field (negative values too). Which distance is
 * which: baseline_m places the cameras (kin_sthmd_camera: the camera
 * poses, hence the masks and everything drawn from the cameras), ipd_m
 * places the eyes (kin_sthmd_eye: the eyes' viewpoints, e.g. a virtual
 * scene rendered for the eyes or an eye reprojection). Eq. 1-4 (the crop
 * and the viewport) use neither: they depend on the sizes, the FOVs, D and
 * F only. The lighting's view vector is the camera pixel's ray (it
 * relights the camera's image; fuse_intrinsics). */
typedef struct kin_sthmd_desc {
    int   cam_width, cam_height;    /* camera sensor, default 640 x 480 */
    float cam_hfov_deg;             /* camera horizontal FOV (of the whole
                                       sensor width), default 62 */
    float baseline_m;               /* camera separation, 0.065 */
    float cam_offset_m;             /* D: cameras in front of the eyes, 0.085 */
    int   lcd_width, lcd_height;    /* per-eye display, 1280 x 800 */
    float hmd_hfov_deg;             /* display horizontal FOV, 61 */
    float hmd_vfov_deg;             /* display vertical FOV, 40 */
    float focal_m;                  /* F: eye projection plane distance, 1.0 */
    float znear, zfar;              /* clip planes, default 0.01 and 100 */
    float ipd_m;                    /* eye separation (interpupillary
                                       distance); 0 = baseline_m (so 0.065
                                       by default) */
    kin_lens lens[2];               /* per camera (KIN_EYE_LEFT, _RIGHT):
                                       a calibrated lens (kin_lens.h,
                                       io_calib.h), or all zero (fx == 0):
                                       the paper's pinhole of cam_hfov_deg.
                                       A lens without an image size is
                                       taken to be for the camera's; one
                                       for another size is scaled to it.
                                       With a lens of the left camera,
                                       cam_hfov_deg is resolved to its
                                       pinhole part 2 atan(w / 2 fx), and
                                       a zero camera size to the lens's
                                       (docs/lens.md) */
} kin_sthmd_desc;

/* The derived numbers of the paper (eq. 1-4).
 *
 * The crop (eq. 1, generalised): the cropped camera image has the LCD's
 * aspect and cuts whichever side of the sensor is too long for it, centred.
 *   H = round(cam_w * lcd_h / lcd_w);
 *   H <= cam_h: keep the width (the paper: 640 x 400, rows 40..439);
 *   H >  cam_h: keep the height, crop_w = round(cam_h * lcd_w / lcd_h)
 *               (a camera wider than the display's aspect: a 16:9 camera,
 *               a display taller than wide; 1280x1024 -> 2064x2208 keeps
 *               957 x 1024 at column 161).
 * The crop is always inside the sensor (crop_x0 + crop_width <= cam_w,
 * crop_y0 + crop_height <= cam_h). Eq. 2 then uses the crop's horizontal
 * FOV; the viewport (eq. 4) is inside the LCD when ratio <= 1 (the
 * camera's cropped FOV, seen from D in front of the eye, no wider than
 * the display's). */
typedef struct kin_sthmd_geometry {
    int   crop_width, crop_height;  /* eq. 1: 640 x 400 */
    int   crop_y0;                  /* first camera row kept: (480-400)/2 */
    double w1_mm, w2_mm;            /* eq. 2: 1178, 1099 */
    double ratio;                   /* eq. 3: W2 / W1 = 0.933 */
    int   vp_width, vp_height;      /* eq. 4: floor(LCD * ratio) = 1194 x 746 */
    int   vp_x0, vp_y0;             /* viewport corner, centred: 43, 27 */
    float crop_vfov_deg;            /* vertical FOV of the cropped image */
    int   crop_x0;                  /* first camera column kept: 0, unless
                                       the camera is wider than the LCD's
                                       aspect (then the height is kept and
                                       the width cropped, centred) */
} kin_sthmd_geometry;

typedef enum kin_eye { KIN_EYE_LEFT = 0, KIN_EYE_RIGHT = 1 } kin_eye;

/* A pinhole camera for rasterizing into the cropped camera image. */
typedef struct kin_camera {
    kin_mat4 view;            /* world -> camera (view space, looks down -Z) */
    kin_mat4 proj;            /* camera -> clip, OpenGL style */
    kin_mat4 view_proj;       /* proj * view */
    kin_mat4 world_from_cam;  /* inverse of view */
    int width, height;        /* image size (the cropped camera image) */
    float fx, fy, cx, cy;     /* pixels; ray of pixel centre (x+.5, y+.5) is
                                 ((x+.5-cx)/fx, -(y+.5-cy)/fy, -1) for a
                                 pinhole lens; with a distorting lens these
                                 are its pinhole part (proj draws it) and
                                 the true ray is kin_lens_unproject(&lens) */
    kin_lens lens;            /* the lens of this image (its size, the crop
                                 applied; OpenCV pixel convention, so
                                 lens.cx = cx - 0.5 for the pinhole of the
                                 paper): project and unproject through it
                                 (kin_lens_project, kin_lens_unproject) */
} kin_camera;

/* Fills in the defaults (zero fields) of a desc. */
kin_sthmd_desc kin_sthmd_desc_resolved(const kin_sthmd_desc *desc);
/* The paper's numbers for this desc (NULL = defaults). */
kin_sthmd_geometry kin_sthmd_geometry_of(const kin_sthmd_desc *desc);
/* Camera of one eye from the head pose (world_from_head: head frame at the
 * midpoint between the eyes, looking down -Z, +X to the right eye): the
 * camera sits at (+-baseline/2, 0, -D) in the head frame, looks along -Z,
 * and images the cropped sensor (crop_width x crop_height). */
kin_camera kin_sthmd_camera(const kin_sthmd_desc *desc,
                            const kin_mat4 *world_from_head, kin_eye eye);
/* World pose of one eye (its viewpoint, looking down -Z with the head's
 * orientation): world_from_head * translate(+-ipd/2, 0, 0), ipd the
 * resolved ipd_m (NULL world_from_head: identity). */
kin_mat4 kin_sthmd_eye(const kin_sthmd_desc *desc, const kin_mat4 *world_from_head,
                       kin_eye eye);
/* The eye's own camera (for an eye reprojection, src/pipe/pipe_reproj.h):
 * at kin_sthmd_eye (the resolved ipd_m), with the head's orientation, a
 * pinhole of the display's FOVs (hmd_hfov_deg x hmd_vfov_deg) centred on
 * a width x height image (0: the LCD's size), so that its pixel (i, j)
 * is the display's pixel area (i + 0.5) lcd_w / width (the same for j):
 *   fx = width / 2 / tan(hfov / 2), fy = height / 2 / tan(vfov / 2),
 *   cx = width / 2, cy = height / 2, near and far the desc's.
 * A virtual scene rendered for the eye (samples/gen: gen_render_virtual)
 * uses the same intrinsics at the LCD's size. (src/kin/kin_hmd.c) */
kin_camera kin_sthmd_eye_camera(const kin_sthmd_desc *desc, const kin_mat4 *world_from_head,
                                kin_eye eye, int width, int height);
/* Named HMDs (src/kin/kin_hmd.c, docs/kin.md "Named HMDs"): "paper" (the
 * defaults: 640x480 cameras, 1280x800 per eye), "consumer" (1280x1024
 * cameras, 2064x2208 per eye), "highend" (1920x1080 cameras, 2880x2720
 * per eye). Fills *out (every field set) and returns 0; -1 for an
 * unknown or NULL name (*out untouched). */
int kin_sthmd_preset(const char *name, kin_sthmd_desc *out);
/* The i-th preset's name (0, 1, ...), NULL past the last: for listings
 * and error messages. */
const char *kin_sthmd_preset_name(int i);
/* The OpenGL projection of a pinhole of intrinsics fx, fy, cx, cy (egofuse
 * pixels, kin_camera's convention) and skew (u += skew * (-Y)/(-Z), as
 * camera_matrix(0,1)) on a w x h image, near n, far f: with the
 * rasterizer's viewport it images view-space points exactly at
 * u = cx + (fx X - skew Y) / -Z, v = cy - fy Y / -Z. */
kin_mat4 kin_proj_from_intrinsics(double fx, double fy, double cx, double cy, double skew,
                                  int w, int h, double n, double f);
/* A general look-at camera (for `egofuse mask`). */
kin_camera kin_camera_look_at(kin_vec3 eye, kin_vec3 target, kin_vec3 up,
                              float fovy_deg, int width, int height,
                              float znear, float zfar);

/* =====================================================================
 * TRACKING, IK, HANDS, FILTERING, USER CALIBRATION, DQS  (issue 4)
 * Files: kin_track.c, kin_ik.c, kin_hand.c, kin_filter.c, kin_calib.c,
 * kin_dqs.c; formats and rules in docs/tracking.md.
 *
 * Per frame:  kin_filter_push(sample) -> kin_filter_output(display time)
 *   -> kin_arm_rig_pose() (body, head, two-bone IK per arm, glove ->
 *   fingers) -> kin_fk -> kin_skin_joint_matrices -> kin_skin_lbs or
 *   kin_skin_dq_from_matrices + kin_skin_dqs (or, ~2x faster with the
 *   same bytes, kin_skin_lbs_plan / kin_skin_dqs_plan with a skin plan
 *   built once per mesh). Nothing here allocates or
 *   keeps hidden state; filter state lives in the caller's kin_filter.
 * ===================================================================== */

typedef enum kin_side { KIN_SIDE_LEFT = 0, KIN_SIDE_RIGHT = 1 } kin_side;

/* Rotation whose matrix has the columns x, y, z (orthonormal,
 * right-handed; Shepperd's method, w >= 0). */
kin_quat kin_quat_from_axes(kin_vec3 x, kin_vec3 y, kin_vec3 z);
/* (-x, -y, -z, w): the inverse of a unit quaternion. */
kin_quat kin_quat_conjugate(kin_quat q);

#define KIN_GLOVE_SENSORS 5        /* thumb, index, middle, ring, little */
#define KIN_HAND_JOINTS 15         /* thumb_1..3, index_1..3, ..., little_1..3 */

/* Parts of a tracking sample; a set bit in kin_track_sample.valid says the
 * part holds a measurement (a cleared bit: the part is missing). */
enum {
    KIN_TRACK_HEAD       = 1 << 0,
    KIN_TRACK_SHOULDER_L = 1 << 1,
    KIN_TRACK_SHOULDER_R = 1 << 2,
    KIN_TRACK_HAND_L     = 1 << 3,
    KIN_TRACK_HAND_R     = 1 << 4,
    KIN_TRACK_GLOVE_L    = 1 << 5,
    KIN_TRACK_GLOVE_R    = 1 << 6,
    KIN_TRACK_ALL        = 0x7F
};

/* One measurement of the five tracking points and both gloves (world
 * space, metres). The hand pose is the wrist joint: its position is the
 * wrist centre and its rotation the hand frame (-Z towards the fingers,
 * +Y the back of the hand, as the model's hand joint). Values of a part
 * whose valid bit is clear are undefined. */
typedef struct kin_track_sample {
    double t;                      /* capture time, seconds */
    uint32_t valid;                /* KIN_TRACK_* bits */
    kin_vec3 head_pos;             /* midpoint of the eyes */
    kin_quat head_rot;             /* head frame: -Z forward, +X right eye */
    kin_vec3 shoulder[2];          /* shoulder joint centres, [KIN_SIDE_*] */
    kin_vec3 hand_pos[2];          /* wrist centres */
    kin_quat hand_rot[2];          /* hand frames */
    float glove[2][KIN_GLOVE_SENSORS]; /* flexure 0 (open) .. 1 (fist) */
} kin_track_sample;

/* Checks finiteness, unit quaternions (| |q| - 1 | <= 1e-3) and glove
 * values in [0, 1] of the valid parts. Returns 0, or -1 with a reason. */
int kin_track_sample_validate(const kin_track_sample *s, char *why,
                              size_t why_size);

/* Recorded text format "egofuse-track 1" (docs/tracking.md): a header,
 * then one sample per line, e.g.
 *   t 0.011 H 0 1.25 -0.08 0 0 0 1 SL -0.19 1 0 HR 0.2 1 -0.4 0 0 0 1 GR .1 .2 .2 .3 .3
 * Parses a whole buffer (not NUL-terminated: text_len bytes). Call once
 * with out == NULL to get the sample count in *count, then with out of
 * capacity cap. Returns 0, or -1 with *err_line (1-based, 0 when the
 * error is not on one line) and "reason" in why. Strict: unknown or
 * repeated tags, wrong counts, trailing junk, non-finite numbers, glove
 * values outside [0, 1], non-unit quaternions and time stamps that do not
 * increase are errors. */
int kin_track_parse(const char *text, size_t text_len, kin_track_sample *out,
                    int cap, int *count, int *err_line, char *why,
                    size_t why_size);
/* Parses one data line (without the newline). Returns 1 for a sample, 0
 * for a blank or comment line, -1 with a reason on error. */
int kin_track_parse_line(const char *line, size_t len, kin_track_sample *out,
                         char *why, size_t why_size);
/* Writes one sample as a data line with '\n' (9 significant digits, so a
 * float reads back exactly). Returns the length it needs (like snprintf);
 * the text is complete only when that is < size. */
int kin_track_format_line(const kin_track_sample *s, char *buf, size_t size);
/* The header line of the format, with '\n'. */
const char *kin_track_header(void);

/* Live packets (UDP), little-endian, KIN_TRACK_PACKET_SIZE bytes:
 *   0  "EGTK"  4  u16 version (1)  6  u16 valid bits  8  u32 sequence
 *   12 f64 t   20  37 x f32: head pos(3) rot(4), shoulder L(3) R(3),
 *   hand L pos(3) rot(4), hand R pos(3) rot(4), glove L(5) R(5)
 *   168 u32 CRC-32 (IEEE) of bytes 0..167. */
#define KIN_TRACK_PACKET_SIZE 172
#define KIN_TRACK_PACKET_VERSION 1
void kin_track_packet_write(const kin_track_sample *s, uint32_t seq,
                            uint8_t out[KIN_TRACK_PACKET_SIZE]);
/* Returns 0 and fills *out and *seq, or -1 with a reason (size, magic,
 * version, CRC, unknown valid bits, and kin_track_sample_validate). */
int kin_track_packet_read(const uint8_t *buf, size_t len,
                          kin_track_sample *out, uint32_t *seq, char *why,
                          size_t why_size);

/* World rotation of the body frame from the shoulders: +X from the left
 * to the right shoulder, +Y world up orthogonalised against X (the torso's
 * pitch is not observable from two points; when the shoulder line is
 * within ~6 degrees of vertical the direction to the head is used
 * instead), +Z = X x Y (backwards; the body faces -Z). */
kin_quat kin_body_frame(kin_vec3 shoulder_l, kin_vec3 shoulder_r,
                        kin_vec3 head);

/* ---------------------------------------------------------- arm IK job */

/* Analytic two-bone IK shoulder -> elbow -> wrist (kin_ik.c, rules in
 * docs/tracking.md). Zero means default for every float parameter.
 *
 * Reach: d = |wrist - shoulder| is softly limited to
 *   [d_min, d_max], d_max = L1 + L2 (straight) and d_min the distance at
 *   the maximum elbow flexion; above soft * d_max the distance follows
 *   d_s + (d_max - d_s)(1 - exp(-(d - d_s)/(d_max - d_s))), so it is C1
 *   and never reaches the straight-arm singularity; below d_min + the
 *   same margin it is mirrored. The wrist is then pulled along the
 *   shoulder-wrist line (reach_error reports by how much).
 * Swivel: the elbow lies on the circle around that line (axis u). The
 *   body's preferred direction b(u) is a dipole field on the sphere of arm
 *   directions (body frame): A = down reflected in the plane normal to
 *   u - Q, then projected: b = perp(A - 2 (A.w) w, u), w = (u-Q)/|u-Q|,
 *   perp(v, u) = v - (v.u)u, Q = (-+0.707, 0, 0.707) (medially backwards
 *   for the right / left arm). |b| = 1 everywhere but at u = Q (the arm
 *   pointing into the back of the torso, outside its range), where it is
 *   undefined. It gives "elbow down" for an arm forward, to the side or
 *   back, "elbow back" for a hanging arm, "forward and out" for a raised
 *   one. The hand turns it about u towards h = perp(-finger axis, u)
 *   (where the forearm would point along the hand, i.e. least wrist bend)
 *   by hand_gain * h.(u x b) radians:
 *   linear in the hand's direction, so no flip when the hand points
 *   against b. At the shoulder (d -> 0) u fades to the body's
 *   forward-down direction F (singular only at D = -F d_min/4, behind and
 *   above the shoulder, inside the body).
 * Limits: elbow flexion <= elbow_max; the forearm takes twist_share of
 *   the hand's roll about the forearm, clamped to +-twist_max. */
typedef struct kin_arm_ik_job {
    /* inputs */
    kin_vec3 shoulder;        /* shoulder joint centre, world */
    kin_vec3 wrist;           /* wrist target, world */
    kin_quat hand_rot;        /* hand frame, world (unit) */
    kin_quat body_rot;        /* kin_body_frame(), world (unit) */
    kin_side side;
    float upper_len, fore_len;/* bone lengths, metres, > 0 (required) */
    float elbow_max_deg;      /* max flexion, default 150 */
    float soft;               /* soft reach start, fraction of d_max,
                                 default 0.97, in (0.5, 1) */
    float hand_gain;          /* swivel towards the hand, radians per unit
                                 of h.(u x b), default 1, in (0, 2] */
    float twist_share;        /* default 0.5, in [0, 1] */
    float twist_max_deg;      /* default 85 */
    /* outputs (all written by kin_arm_ik_run) */
    kin_vec3 elbow;           /* elbow position */
    kin_vec3 wrist_out;       /* reached wrist position */
    kin_quat upper_rot;       /* world rotations in the model's bone frame: */
    kin_quat fore_rot;        /*  -Z along the bone, +X the elbow hinge */
    float flexion;            /* elbow flexion, radians, 0 = straight */
    float swivel;             /* the hand's turn of the elbow about the
                                 line from b, radians, in [-hand_gain,
                                 hand_gain] */
    float reach_error;        /* |wrist_out - wrist|, metres */
} kin_arm_ik_job;

/* 1 if the inputs are valid (finite, unit quaternions, lengths > 0,
 * parameters in range), else 0 with a reason. */
int kin_arm_ik_validate(const kin_arm_ik_job *job, char *why, size_t why_size);
/* Validates, then solves. Returns 1, or 0 (outputs untouched). */
int kin_arm_ik_run(kin_arm_ik_job *job);

/* ---------------------------------------------------------------- hands */

/* Glove calibration: raw sensor readings -> flexure 0..1 per sensor,
 * g = clamp((raw - raw_open) / (raw_fist - raw_open), 0, 1) (either order
 * of the two readings works). */
typedef struct kin_glove_calib {
    float raw_open[KIN_GLOVE_SENSORS];
    float raw_fist[KIN_GLOVE_SENSORS];
} kin_glove_calib;

/* Fits the calibration from n raw readings (5 floats each) taken while
 * the user opens the hand flat and makes a fist: per sensor the 2nd and
 * 98th percentile of the readings (robust to spikes) become open / fist
 * (the lower is "open" unless invert_mask bit k says the sensor reads
 * lower when bent). scratch: n floats. Returns 0, or -1 when n < 8, a
 * reading is not finite or a sensor's range is below min_range. */
int kin_glove_calib_fit(const float *raw, int n, unsigned invert_mask,
                        float min_range, float *scratch,
                        kin_glove_calib *out, char *why, size_t why_size);
/* Applies it: out[k] in [0, 1]; a non-finite raw reading gives -1 and
 * leaves out untouched, else 0. */
int kin_glove_calib_apply(const kin_glove_calib *c,
                          const float raw[KIN_GLOVE_SENSORS],
                          float out[KIN_GLOVE_SENSORS]);

/* Flexion (degrees) of the three joints of one finger at flexure 0 and 1.
 * Thumb: joint 0 also takes opposition (about the palm's long axis). */
typedef struct kin_hand_params {
    float open_deg[5][3];     /* default: a relaxed open hand */
    float fist_deg[5][3];     /* default: a loose fist */
    float dip_coupling;       /* DIP = coupling * PIP when > 0 (overrides
                                 the DIP table), default 2/3 */
    float thumb_opp_deg[2];   /* opposition at 0 and 1, default 12, 40 */
} kin_hand_params;

/* Default parameters (the table in docs/tracking.md). */
kin_hand_params kin_hand_params_default(void);

/* Glove -> 15 finger joint rotations of one hand (kin_hand.c).
 * Finger f (0 thumb .. 4 little), joint k (0 MCP/CMC, 1 PIP/MCP,
 * 2 DIP/IP): angle a = open + g_f (fist - open) degrees (DIP: coupling *
 * PIP), local rotation r = rest * Rx(-a) (flexion towards the palm, -Y),
 * except the thumb's joint 0: Rz(s opp) * rest * Rx(-a), s = +1 right,
 * -1 left. */
typedef struct kin_hand_job {
    const float *glove;           /* 5 values in [0, 1] (required) */
    const kin_hand_params *params;/* NULL = kin_hand_params_default() */
    const kin_quat *rest;         /* 15 rest rotations, or NULL = identity */
    kin_side side;
    kin_quat *out;                /* 15 local rotations (required) */
    float *angles_deg;            /* 15 flexion angles, or NULL */
} kin_hand_job;

int kin_hand_validate(const kin_hand_job *job, char *why, size_t why_size);
int kin_hand_run(const kin_hand_job *job);

/* ------------------------------------------------------ arm rig (model) */

/* Node names the rig needs: "body", "head" and per side ("L_", "R_")
 * shoulder, upper_arm, forearm, hand, palm, thumb_1..3, index_1..3,
 * middle_1..3, ring_1..3, little_1..3. */
#define KIN_RIG_SIDE_JOINTS 20
enum {
    KIN_RIG_SHOULDER = 0, KIN_RIG_UPPER_ARM, KIN_RIG_FOREARM, KIN_RIG_HAND,
    KIN_RIG_PALM, KIN_RIG_FINGER0    /* first of 15 finger joints */
};

typedef struct kin_arm_rig {
    int body, head;
    int joint[2][KIN_RIG_SIDE_JOINTS];   /* node indices, [side][KIN_RIG_*] */
    float upper_len[2], fore_len[2];     /* model bone lengths, metres */
    float shoulder_width;                /* model, between upper_arm nodes */
} kin_arm_rig;

/* Name of joint j (KIN_RIG_*) of a side into buf ("R_index_2"). */
const char *kin_arm_rig_joint_name(kin_side side, int j, char *buf, size_t n);
/* Finds the nodes by name. Returns 0, or -1 with every missing joint
 * listed in why ("missing joints: L_thumb_3, R_palm") or another reason
 * (parents not in chain order, zero bone length). */
int kin_arm_rig_init(kin_arm_rig *rig, const kin_model *model, char *why,
                     size_t why_size);

/* Per-user calibration (kin_calib.c). */
typedef struct kin_user_calib {
    float arm_scale[2];       /* factor on upper arm and forearm length */
    float hand_scale[2];      /* factor on palm and finger lengths */
    float shoulder_scale;     /* factor on the shoulder offsets */
    float arm_length[2];      /* measured shoulder-to-wrist, metres */
    float shoulder_width;     /* measured, metres */
    int has_glove[2];
    kin_glove_calib glove[2];
    float hand_length[2];     /* measured wrist to middle fingertip (the
                                 fingertip gesture), metres; 0 = not
                                 measured (hand_scale = arm_scale) */
} kin_user_calib;

/* Scale 1 everywhere, no glove calibration. */
kin_user_calib kin_user_calib_identity(void);

/* Poses the model from one (filtered) sample into locals (node_count,
 * start from kin_pose_rest()): places "body" (a root) at the shoulders in
 * kin_body_frame(), scales bone offsets by calib (NULL = identity), sets
 * the head node from head_pos/head_rot, solves both arms with
 * kin_arm_ik_run (ik_params: parameters only, NULL = defaults) and the
 * fingers with kin_hand_run. Parts missing from sample->valid keep their
 * locals. ik_out (2 jobs, or NULL) receives the solved jobs. Returns 1,
 * or 0 when the sample or the model do not fit (then locals are left as
 * far as they were written). */
int kin_arm_rig_pose(const kin_arm_rig *rig, const kin_model *model,
                     const kin_user_calib *calib,
                     const kin_arm_ik_job *ik_params,
                     const kin_track_sample *sample, kin_transform *locals,
                     kin_arm_ik_job ik_out[2]);

/* Estimates the calibration from a recording of the arms stretched
 * forward and sideways (and the hands opened and closed, for gloves
 * whose samples are raw readings: not done here): per side the 95th
 * percentile of |hand - shoulder| over the valid samples is the arm
 * length (the shoulder-wrist distance of the straight arm),
 * arm_scale = length / (upper_len + fore_len) of the rig; hand_scale =
 * arm_scale; shoulder width = median |R - L|. scratch: n floats. Needs
 * >= 20 valid samples per side, else -1 with a reason. Scales outside
 * [0.5, 2] are rejected as implausible. */
int kin_user_calib_estimate(const kin_track_sample *samples, int n,
                            const kin_arm_rig *rig, float *scratch,
                            kin_user_calib *out, char *why, size_t why_size);

/* The middle fingertip of each hand in its hand joint's frame (the frame
 * of kin_track_sample.hand_rot), metres, for the model's rest pose of the
 * fingers: the middle_3 joint moved along its bone (-Z) to the farthest
 * surface point of the vertices bound to it (weight >= 0.5, mesh 0 posed
 * by its skin at rest); the joint itself when no vertex is bound to it.
 * Returns 0, or -1 with a reason (no skinned mesh, bad rig). */
int kin_user_calib_hand_tips(const kin_arm_rig *rig, const kin_model *model,
                             kin_vec3 tip[2], char *why, size_t why_size);

/* kin_user_calib_estimate, and the hand scale measured on its own from the
 * fingertip gesture of the recording (docs/tracking.md): the hands held
 * with the fingers straight and the middle fingertips of both hands
 * pressed together (the hands may turn). A sample with both hands is
 * taken as the gesture when, with a = rot_L tip[0], b = rot_R tip[1],
 * d = a - b, g = hand_pos[1] - hand_pos[0] (touch: g = s d):
 *   |d| >= 0.75 (|tip[0]| + |tip[1]|)   (fingers roughly opposed),
 *   s = g.d / d.d in [0.5, 2] and |g - s d| <= 2 cm;
 * with >= 20 such samples, hand_scale (both sides) is the midpoint of the
 * shortest interval holding half of their s (robust to the approach,
 * where the gap between the fingertips makes s larger), hand_length[k] =
 * hand_scale |tip[k]|. tip == NULL or too few gesture samples: hand_scale
 * = arm_scale, hand_length 0, the reason in why, and the return value 1.
 * Returns 0 (everything measured), 1 (hand scale from the arms) or -1 as
 * kin_user_calib_estimate. scratch: n floats. */
int kin_user_calib_estimate_tips(const kin_track_sample *samples, int n,
                                 const kin_arm_rig *rig, const kin_vec3 tip[2],
                                 float *scratch, kin_user_calib *out,
                                 char *why, size_t why_size);
/* Text file "egofuse-calib 1" (docs/tracking.md) into buf; returns the
 * length needed (like snprintf). */
int kin_user_calib_format(const kin_user_calib *c, char *buf, size_t size);
/* Strict parse (missing or repeated keys, bad numbers, out-of-range
 * scales are errors). Returns 0, or -1 with *err_line and a reason. */
int kin_user_calib_parse(const char *text, size_t len, kin_user_calib *out,
                         int *err_line, char *why, size_t why_size);

/* ------------------------------------------------ filter and prediction */

/* One Euro filter (Casiez et al. 2012) per part, constant-velocity
 * prediction to the display time, and dropout handling. Zero = default. */
typedef struct kin_filter_desc {
    float min_cutoff_hz;      /* positions, default 1.5 */
    float beta;               /* positions, s/m, default 4 */
    float rot_min_cutoff_hz;  /* rotations, default 1.5 */
    float rot_beta;           /* rotations, s/rad, default 0.5 */
    float glove_min_cutoff_hz;/* gloves, default 3 */
    float d_cutoff_hz;        /* derivative, default 1 */
    float max_predict_s;      /* horizon limit, default 0.1 */
    float hold_s;             /* dropout: hold the pose, default 0.15 */
    float fade_s;             /* then fade confidence to 0, default 0.35 */
    float reset_s;            /* a time stamp older than the last by more
                                 than this restarts the filter, default 0.5 */
    int no_lag_comp;          /* 1: predict x + dx h only (the output keeps
                                 the low-pass's lag but less jitter); 0
                                 (default): add the lag, see below */
} kin_filter_desc;

#define KIN_FILTER_PARTS 7    /* head, shoulder L/R, hand L/R, glove L/R */

/* State of one part: filtered value, derivative (per second), last time. */
typedef struct kin_filter_part {
    int has;                  /* 0 until the first measurement */
    double t;                 /* time of the last measurement */
    kin_vec3 x, dx;           /* filtered position, velocity (m/s) */
    kin_quat q;               /* filtered rotation */
    kin_vec3 w;               /* angular velocity, world, rad/s */
    float g[KIN_GLOVE_SENSORS], dg[KIN_GLOVE_SENSORS];
    kin_vec3 z;               /* last raw measurement (velocities are */
    kin_quat zq;              /*  taken from raw differences, unbiased */
    float zg[KIN_GLOVE_SENSORS]; /* by the filter's lag) */
    float lag, rot_lag;       /* ramp lag of the last update, seconds:
                                 dt (1 - a) / a */
} kin_filter_part;

typedef struct kin_filter {
    kin_filter_desc desc;     /* resolved */
    double last_t;            /* newest accepted time stamp */
    int started;
    kin_filter_part part[KIN_FILTER_PARTS];
    /* counters, for reporting */
    uint32_t accepted, dropped_old, restarts, nonfinite_parts;
} kin_filter;

/* Result bits of kin_filter_push. */
enum {
    KIN_FILTER_ACCEPTED = 1,      /* the sample updated the filter */
    KIN_FILTER_OLD      = 2,      /* dropped: not newer than the last */
    KIN_FILTER_RESTART  = 4,      /* time went back by > reset_s: restarted */
    KIN_FILTER_NONFINITE= 8       /* some part was not finite: treated as
                                     missing */
};

kin_filter_desc kin_filter_desc_resolved(const kin_filter_desc *d);
void kin_filter_init(kin_filter *f, const kin_filter_desc *desc);
/* Feeds one measurement. Parts missing from valid (or not finite, or with
 * bad quaternions / glove values) are skipped. Returns KIN_FILTER_* bits. */
int kin_filter_push(kin_filter *f, const kin_track_sample *s);
/* The pose predicted for display_t (seconds, on the sample clock): per
 * part x + dx (h + lag) with h = clamp(display_t - t_part, 0,
 * max_predict_s) and lag the low-pass's delay on a ramp (so a constant
 * velocity is predicted exactly; velocity noise times lag adds jitter,
 * desc.no_lag_comp = 1 sets lag = 0), rotations advanced by
 * w (h + rot_lag). conf[part] (KIN_FILTER_PARTS, or NULL) is
 * 1 while age = display_t - t_part <= hold_s, then falls linearly to 0 at
 * hold_s + fade_s (the mask of that part fades with it); a part with
 * conf 0 is cleared from out->valid. out->t = display_t. */
void kin_filter_output(const kin_filter *f, double display_t,
                       kin_track_sample *out, float *conf);

/* --------------------------------------------- dual-quaternion skinning */

/* Unit dual quaternion: real part r (rotation), dual part d = t r / 2. */
typedef struct kin_dualquat { kin_quat r, d; } kin_dualquat;

/* From a rigid matrix (rotation + translation; a scale in the matrix is
 * removed by orthonormalising its columns). */
kin_dualquat kin_dualquat_from_mat4(const kin_mat4 *m);
kin_vec3 kin_dualquat_transform(const kin_dualquat *q, kin_vec3 p);
/* dq[j] = kin_dualquat_from_mat4(&jm[j]) for j < count. */
void kin_skin_dq_from_matrices(const kin_mat4 *jm, int count,
                               kin_dualquat *dq);
/* Dual-quaternion skinning (Kavan et al. 2008): b = sum w_i s_i dq_i with
 * s_i = sign(r_i . r_0) (shortest path); positions by b / |b.r|, normals
 * by its rotation (not renormalised: a unit normal stays unit to a few
 * ulp), computed with one division and no square root per vertex
 * (kin_dqs.c). The result does not depend on the scale of the weights:
 * a b whose |b.r|^2 is outside (2^-100, 2^100) is first scaled by an
 * exact power of two (weights summing to 1e-30 or 1e30 give the same
 * rigid transform as 1). Like kin_skin_lbs otherwise (weights summing to
 * exactly 0, or b.r = 0, keep the bind pose; outputs must not alias). */
void kin_skin_dqs(const kin_mesh *mesh, const kin_dualquat *dq,
                  float *pos_out, float *nrm_out);

/* ------------------------------------------------------ SIMD skinning */

/* kin_skin_lbs and kin_skin_dqs run SIMD kernels (SSE2, AVX2, AVX-512;
 * kin_skin_sse2.c, _avx2.c, _avx512.c) chosen at run time: the best ISA
 * the CPU has, capped by EGOFUSE_ISA (src/cpu/cpu.h ef_isa_choose). The
 * scalar reference defines the result: every path gives the same bytes
 * (same operations in the same order per vertex, no FMA, exact sqrt and
 * division; tests/test_kin_skin_isa.c). The ISA they use now (an ef_isa
 * value of src/cpu/cpu.h): */
int kin_skin_isa(void);
/* The same with an explicit ISA (an ef_isa value: 1 ref, 2 sse2, 3 avx2,
 * 4 avx512; 0 = as kin_skin_lbs). An ISA the CPU lacks runs the best one
 * it has; EGOFUSE_ISA does not cap an explicit request. For tests and
 * benchmarks. */
void kin_skin_lbs_isa(const kin_mesh *mesh, const kin_mat4 *jm,
                      float *pos_out, float *nrm_out, int isa);
void kin_skin_dqs_isa(const kin_mesh *mesh, const kin_dualquat *dq,
                      float *pos_out, float *nrm_out, int isa);

/* ------------------------------------------------------- skin plan */

/* A skin plan: a mesh's skinning data rearranged once (kin_skin_plan.c)
 * so that the per-frame skinning broadcasts joint matrices instead of
 * gathering them. Vertices are grouped by the joints they read with a
 * nonzero weight, in influence order (the reference's order of summing),
 * into batches of 16 that hold the weights, bind positions and normals
 * in SoA; vertices whose weights sum to 0 are a group that keeps the bind
 * pose. The results are the reference's bytes (kin_skin_lbs,
 * kin_skin_dqs of the same mesh), written in the mesh's vertex order, on
 * every ISA. The plan copies what it needs: after kin_skin_plan_init the
 * mesh arrays are not read again (rebuild the plan when they change).
 *
 *   size_t ns = kin_skin_plan_scratch_size(&mesh);   // 16 per vertex
 *   void *scratch = malloc(ns);
 *   size_t bytes = kin_skin_plan_size(&mesh, scratch);
 *   void *mem = aligned_alloc(64, bytes);            // 64-byte aligned
 *   kin_skin_plan plan;
 *   kin_skin_plan_init(&plan, &mesh, scratch, mem, bytes);
 *   free(scratch);
 *   per frame: kin_skin_lbs_plan(&plan, jm, pos_out, nrm_out);
 *   free(mem) when done (the plan owns nothing). */
typedef struct kin_skin_plan {
    int vertex_count;         /* of the mesh */
    int batch_count;          /* batches of 16 vertices */
    int normals;              /* 1: the mesh had normals (nrm_out is written) */
    int max_joint;            /* largest joint index read, -1 if none: jm
                                 and dq must hold max_joint + 1 entries */
    int group_count;          /* distinct joint lists (for reports) */
    const void *batches;      /* in the caller's memory */
} kin_skin_plan;

/* Bytes of scratch memory the two calls below need (16 per vertex). */
size_t kin_skin_plan_scratch_size(const kin_mesh *mesh);
/* Bytes of plan memory the mesh needs (sorts its vertices into scratch);
 * 0 for an invalid mesh (NULL, no positions, negative count). */
size_t kin_skin_plan_size(const kin_mesh *mesh, void *scratch);
/* Builds the plan into mem (64-byte aligned, size >= kin_skin_plan_size).
 * Returns 0, or -1 (plan zeroed) when the mesh is invalid, mem is not
 * aligned or too small, or the mesh has extra influence sets (extra_sets:
 * skin it with kin_skin_lbs). Not a per-frame call: it sorts. A plan
 * copies the bind positions: a morphed mesh is skinned with kin_skin_lbs
 * on the output of kin_morph_apply instead. */
int kin_skin_plan_init(kin_skin_plan *plan, const kin_mesh *mesh, void *scratch,
                       void *mem, size_t size);
/* kin_skin_lbs / kin_skin_dqs of the plan's mesh, same bytes. jm / dq
 * NULL: every vertex keeps its bind pose (as the reference). */
void kin_skin_lbs_plan(const kin_skin_plan *plan, const kin_mat4 *jm,
                       float *pos_out, float *nrm_out);
void kin_skin_dqs_plan(const kin_skin_plan *plan, const kin_dualquat *dq,
                       float *pos_out, float *nrm_out);
/* The same for part `part` of `parts` (0 <= part < parts: equal runs of
 * batches, for threads; parts write disjoint vertices) with an explicit
 * ISA as kin_skin_lbs_isa (0 = kin_skin_isa()). */
void kin_skin_lbs_plan_part(const kin_skin_plan *plan, const kin_mat4 *jm,
                            float *pos_out, float *nrm_out, int part, int parts,
                            int isa);
void kin_skin_dqs_plan_part(const kin_skin_plan *plan, const kin_dualquat *dq,
                            float *pos_out, float *nrm_out, int part, int parts,
                            int isa);
/* Batches of the plan whose 16 vertices are consecutive in the mesh
 * (stored without a scatter), for reports; 0 for NULL. */
int kin_skin_plan_contiguous(const kin_skin_plan *plan);

#ifdef __cplusplus
}
#endif
#endif
