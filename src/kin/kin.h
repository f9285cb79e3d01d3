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
    KIN_PATH_WEIGHTS          /* morph weights: loaded, not applied */
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

/* One triangle mesh (a glTF primitive with mode TRIANGLES). */
typedef struct kin_mesh {
    int vertex_count;
    const float *positions;   /* 3 per vertex, in the mesh node's space */
    const float *normals;     /* 3 per vertex, or NULL if the file has none */
    const uint16_t *joints;   /* 4 per vertex (indices into the skin), or NULL */
    const float *weights;     /* 4 per vertex, summing to 1, or NULL */
    int index_count;          /* multiple of 3 */
    const uint32_t *indices;  /* < vertex_count */
    int node;                 /* node that instantiates the mesh */
    int skin;                 /* index into skins, or -1 when unskinned */
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

/* Zero means default for every field (negative values too). */
typedef struct kin_sthmd_desc {
    int   cam_width, cam_height;    /* camera sensor, default 640 x 480 */
    float cam_hfov_deg;             /* camera horizontal FOV, default 62 */
    float baseline_m;               /* camera (and eye) separation, 0.065 */
    float cam_offset_m;             /* D: cameras in front of the eyes, 0.085 */
    int   lcd_width, lcd_height;    /* per-eye display, 1280 x 800 */
    float hmd_hfov_deg;             /* display horizontal FOV, 61 */
    float hmd_vfov_deg;             /* display vertical FOV, 40 */
    float focal_m;                  /* F: eye projection plane distance, 1.0 */
    float znear, zfar;              /* clip planes, default 0.01 and 100 */
} kin_sthmd_desc;

/* The derived numbers of the paper (eq. 1-4). */
typedef struct kin_sthmd_geometry {
    int   crop_width, crop_height;  /* eq. 1: 640 x 400 */
    int   crop_y0;                  /* first camera row kept: (480-400)/2 */
    double w1_mm, w2_mm;            /* eq. 2: 1178, 1099 */
    double ratio;                   /* eq. 3: W2 / W1 = 0.933 */
    int   vp_width, vp_height;      /* eq. 4: floor(LCD * ratio) = 1194 x 746 */
    int   vp_x0, vp_y0;             /* viewport corner, centred: 43, 27 */
    float crop_vfov_deg;            /* vertical FOV of the cropped image */
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
                                 ((x+.5-cx)/fx, -(y+.5-cy)/fy, -1) */
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
/* A general look-at camera (for `egofuse mask`). */
kin_camera kin_camera_look_at(kin_vec3 eye, kin_vec3 target, kin_vec3 up,
                              float fovy_deg, int width, int height,
                              float znear, float zfar);

#ifdef __cplusplus
}
#endif
#endif
