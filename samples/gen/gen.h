/* gen.h - internals of the sample-data generator (build/gen_samples).
 *
 * WHAT IT DOES
 *   Builds, without downloading anything, everything `egofuse demo` needs:
 *     gen_arms_build()   a skinned model of both arms and hands (skeleton,
 *                        generalized-cylinder surfaces, smooth weights) and
 *                        its "reach_grasp" animation, as a kin_model;
 *     gen_glb_write()    that model as a binary glTF 2.0 file;
 *     gen_scene_*()      the cockpit around the operator and the remote
 *                        workshop, as flat-shaded triangle lists;
 *     gen_render_*()     the stereo camera frames (640x480 sensor) and the
 *                        virtual frames (1280x800 colour + depth) of one
 *                        time step, through kin (FK, LBS, cameras) and
 *                        raster (rast_draw).
 *   samples/README.md describes the data; gen_main.c is the program.
 *
 * CONVENTIONS
 *   World: metres, +Y up, the operator faces -Z, seated; the "body" node
 *   (between the shoulders) is at GEN_BODY_POS. Everything is deterministic
 *   for a given seed: no global state, no time, no rand().
 */
#ifndef EGOFUSE_GEN_H
#define EGOFUSE_GEN_H

#include <stddef.h>
#include <stdint.h>

#include "../../src/kin/kin.h"
#include "../../src/raster/raster.h"

#define GEN_FPS 60
#define GEN_ANIM_KEYS 181               /* 0 .. 3 s every 1/60 s */
#define GEN_ANIM_NAME "reach_grasp"
#define GEN_CAM_W 640
#define GEN_CAM_H 480
#define GEN_VIRT_W 1280
#define GEN_VIRT_H 800
#define GEN_EYE_HALF_BASELINE 0.0325f
#define GEN_HMD_HFOV_DEG 61.0f
#define GEN_HMD_VFOV_DEG 40.0f
#define GEN_VIRT_ZNEAR 0.05f
#define GEN_VIRT_ZFAR 60.0f
#define GEN_CAM_ZNEAR 0.02f
#define GEN_CAM_ZFAR 30.0f

/* Interpolated attributes of every rasterized vertex (both scenes and the
 * arms share one layout so they can be drawn into one target). */
enum {
    GEN_A_NX, GEN_A_NY, GEN_A_NZ,   /* world-space normal */
    GEN_A_R, GEN_A_G, GEN_A_B,      /* albedo, display space 0..1 */
    GEN_A_U,                        /* pattern * GEN_PATTERN_STRIDE + u */
    GEN_A_V,                        /* v, metres along the surface */
    GEN_ATTRS
};
#define GEN_PATTERN_STRIDE 100.0f

/* Surface patterns (procedural detail, see gen_render.c). The arms' two
 * come first and next to each other: across a triangle where skin meets
 * sleeve (the cuff) the code interpolates between theirs, and a pattern
 * numbered between them would show as coloured specks on the cuff. */
typedef enum gen_pattern {
    GEN_PAT_SKIN = 0,      /* arms: fine skin mottling */
    GEN_PAT_FABRIC,        /* arms: sleeve weave */
    GEN_PAT_PLAIN,         /* painted metal / plastic */
    GEN_PAT_TILES,         /* floor tiles */
    GEN_PAT_SCREEN,        /* console display with bars */
    GEN_PAT_WOOD,          /* wood grain */
    GEN_PAT_BUTTONS,       /* panel with a grid of buttons */
    GEN_PAT_WINDOW,        /* bright window panes */
    GEN_PAT_COUNT
} gen_pattern;

/* ------------------------------------------------------------------ arms */

/* Joints of one side, in skeleton order after the side's shoulder. */
typedef enum gen_side_joint {
    GEN_J_SHOULDER = 0, GEN_J_UPPER_ARM, GEN_J_FOREARM, GEN_J_HAND, GEN_J_PALM,
    GEN_J_THUMB_1, GEN_J_THUMB_2, GEN_J_THUMB_3,
    GEN_J_INDEX_1, GEN_J_INDEX_2, GEN_J_INDEX_3,
    GEN_J_MIDDLE_1, GEN_J_MIDDLE_2, GEN_J_MIDDLE_3,
    GEN_J_RING_1, GEN_J_RING_2, GEN_J_RING_3,
    GEN_J_LITTLE_1, GEN_J_LITTLE_2, GEN_J_LITTLE_3,
    GEN_SIDE_JOINTS                    /* 20 */
} gen_side_joint;

/* The generated model. Everything is owned by model.block. */
typedef struct gen_arms {
    kin_model model;        /* nodes, one mesh, one skin, one animation */
    const float *albedo;    /* 3 per vertex (skin or sleeve colour) */
    const float *uv;        /* 2 per vertex: pattern-coded u, v (GEN_A_U/V) */
    int body, head, mesh_node;
    int joint[2][GEN_SIDE_JOINTS];  /* node index, [0] = L_, [1] = R_ */
    kin_vec3 grasp_point;   /* world point the right hand closes around */
    float grasp_time;       /* seconds, when the grasp is complete */
} gen_arms;

/* Builds the model and its animation. Returns 0, or -1 when out of memory
 * (the partial model is freed). */
int  gen_arms_build(gen_arms *arms);
void gen_arms_free(gen_arms *arms);

/* The one skin of a generated model m (memory from m's block): joint j
 * is node joints[j] (NULL: node j), its inverse bind matrix the inverse
 * of bind[that node]; -1 when out of memory or a bind matrix is
 * singular. The generator's model and the ground truth's (gt.c). */
int  gen_model_skin(kin_model *m, int joint_count, const int *joints, const kin_mat4 *bind);
/* The one mesh of m, skin 0, on node `node`, over arrays the caller
 * allocated from m's block (nt triangles); -1 when out of memory. */
int  gen_model_mesh(kin_model *m, int nv, float *pos, float *nrm, uint16_t *jnt, float *w,
                    int nt, uint32_t *idx, int node);
/* Name of joint j of side (0 = "L_", 1 = "R_") into buf. */
const char *gen_joint_name(int side, int j, char *buf, size_t n);

/* Fills the animation channels of arms->model (called by gen_arms_build). */
int  gen_anim_build(gen_arms *arms);
/* The nodes the animation turns, in channel order: the head, then per
 * side (left first) the upper arm, forearm, hand and the 15 finger
 * joints. Fills nodes and returns their count, GEN_ANIM_NODES. */
#define GEN_ANIM_NODES (1 + 2 * (3 + GEN_SIDE_JOINTS - GEN_J_THUMB_1))
int  gen_anim_nodes(const gen_arms *arms, int nodes[GEN_ANIM_NODES]);

/* An animation `name` of m (memory from m's block, not attached: the
 * caller sets m->anims when the keys are in) with one LINEAR rotation
 * channel per node of nodes[nch], `keys` keys at GEN_FPS from time 0;
 * the values are set by gen_rot_anim_key. NULL when out of memory. The
 * generator's animation and the ground truth's sequences (gt.c). */
kin_animation *gen_rot_anim(kin_model *m, const char *name, const int *nodes, int nch,
                            int keys);
/* Key k of every channel of an from q (the rotations of all nodes), each
 * negated where needed to stay in the hemisphere of key k-1 (so LINEAR
 * blends the short way). */
void gen_rot_anim_key(kin_animation *an, int k, const kin_quat *q);

/* Writes the recorded tracking of the first `frames` frames (t = f /
 * GEN_FPS) of the animation to path ("egofuse-track 1", docs/tracking.md):
 * head, shoulders, hands and glove values of the true motion
 * (gen_track.c). Returns 0, or -1 with a message in why. */
int  gen_track_write(const char *path, const gen_arms *arms, int frames,
                     char *why, size_t why_size);

/* Writes the model as binary glTF to path (atomically: path.tmp.<pid>,
 * then rename). Returns 0, or -1 with a message naming the path in why. */
int  gen_glb_write(const char *path, const gen_arms *arms, char *why,
                   size_t why_size);

/* ----------------------------------------------------------------- scenes */

/* A static, flat-shaded triangle list with per-vertex attributes. */
typedef struct gen_scene {
    int vertex_count, vertex_cap;
    float *pos;             /* 3 per vertex, world */
    float *attr;            /* GEN_ATTRS per vertex */
    int tri_count, tri_cap;
    uint32_t *idx;
    int failed;             /* an allocation failed */
    /* lighting (world directions towards the lights) */
    int light_count;
    float light_dir[4][3], light_color[4][3];
    float ambient[3];
    float sky[3];           /* colour of anything not covered */
} gen_scene;

/* The operator's cockpit (seen by the cameras) and the remote workshop (the
 * virtual scene, seen by the eyes). The workshop puts a cup at the arms'
 * grasp point and a lamp post between the eyes and the reaching hand.
 * Return 0, or -1 when out of memory. */
int  gen_scene_cockpit(gen_scene *s);
int  gen_scene_workshop(gen_scene *s, const gen_arms *arms);
void gen_scene_free(gen_scene *s);

/* ----------------------------------------------------------------- frames */

/* Per-thread buffers for rendering one frame at a time. */
typedef struct gen_frame_ctx {
    const gen_arms *arms;
    const gen_scene *cockpit, *workshop;
    uint64_t seed;
    /* pose */
    kin_transform *locals;
    kin_mat4 *world, *jm;
    float *skin_pos, *skin_nrm, *arm_attr, *clip;
    /* targets, sized for the larger of the two images */
    float *depth, *tattr;
    uint8_t *mask;
    size_t clip_cap;
    kin_sthmd_desc hmd;       /* resolved: the paper's after init */
    size_t px_cap;            /* pixels of the targets */
} gen_frame_ctx;

int  gen_frame_ctx_init(gen_frame_ctx *c, const gen_arms *arms,
                        const gen_scene *cockpit, const gen_scene *workshop,
                        uint64_t seed);
void gen_frame_ctx_free(gen_frame_ctx *c);
/* Renders for the HMD hd from now on (resolved; e.g. kin_sthmd_preset):
 * camera images of its sensor (cam_width x cam_height, its FOV, the
 * cameras at +-baseline/2 and D in front), virtual images of its display
 * (lcd_width x lcd_height at its FOVs, the eyes at +-ipd/2). After
 * gen_frame_ctx_init the context renders the paper's HMD (GEN_CAM_W x
 * GEN_CAM_H, GEN_VIRT_W x GEN_VIRT_H), the same bytes as before. Returns
 * -1 when the larger targets cannot be allocated (c keeps its old ones). */
int  gen_frame_ctx_set_hmd(gen_frame_ctx *c, const kin_sthmd_desc *hd);

/* Poses the arms at time t (seconds): FK, LBS into c->skin_pos/skin_nrm;
 * returns the head's world matrix in *world_from_head. */
void gen_pose(gen_frame_ctx *c, float t, kin_mat4 *world_from_head);

/* Renders the full 640x480 RGB sensor image of one camera (rgb: 3 bytes per
 * pixel, 640*3 per row; the context's HMD's sensor size with
 * gen_frame_ctx_set_hmd) for frame `frame`; *coverage gets the fraction of
 * the cropped 640x400 part (eq. 1's crop) covered by the arms. Call
 * gen_pose() first. */
void gen_render_camera(gen_frame_ctx *c, const kin_mat4 *world_from_head,
                       kin_eye eye, int frame, uint8_t *rgb, float *coverage);

/* Renders the 1280x800 virtual image of one eye (rgb; the context's HMD's
 * display size) and its depth (view-space depth -z in metres, 1 float per
 * pixel). */
void gen_render_virtual(gen_frame_ctx *c, const kin_mat4 *world_from_head,
                        kin_eye eye, int frame, uint8_t *rgb, float *depth);

/* The colour (display values 0..1, unclamped) of a surface point with
 * the interpolated attributes attr (GEN_ATTRS) under the lights of sc: the
 * shading of gen_render_camera and gen_render_virtual, for renders from
 * other viewpoints (samples/gt/gt_eye.c). */
void gen_shade(const gen_scene *sc, const float *attr, float out[3]);

/* Projection for a pinhole camera with intrinsics (pixels, the ray of pixel
 * centre (x+.5, y+.5) is ((x+.5-cx)/fx, -(y+.5-cy)/fy, -1)) rendering a
 * width x height image through rast_draw (OpenGL clip space). */
kin_mat4 gen_proj_from_intrinsics(float fx, float fy, float cx, float cy,
                                  int width, int height, float znear,
                                  float zfar);

#endif
