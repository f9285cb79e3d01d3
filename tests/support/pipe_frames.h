/* pipe_frames.h - the pieces the pipe tests (test_pipe.c, test_pipe_hmd.c,
 * test_pipe_parts.c, test_kin_hmd.c) built each for themselves: a
 * two-node model with one unskinned quad, a stereo frame of seeded
 * random camera and virtual images, and the stages of one eye called by
 * hand (raster of the quad, lighting, composite) to compare pipe_frame's
 * bytes with. Header-only (static inline); include after
 * support/testutil.h, <cmocka.h> and src/pipe/pipe.h. The random bytes
 * are drawn in the order the tests drew them before (per eye: the camera
 * image, then the virtual one), so their images are unchanged. */
#ifndef EGOFUSE_PIPE_FRAMES_H
#define EGOFUSE_PIPE_FRAMES_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The arrays of a tu_mesh_model, for the caller to fill. */
typedef struct tu_mesh_parts {
    kin_transform *rest;  /* 2 rest poses, both the identity */
    float *pos, *nrm;     /* 3 floats per vertex, zeroed; nrm NULL without normals */
    uint32_t *idx;        /* the indices, zeroed */
    kin_mesh *mesh;
} tu_mesh_parts;

/* A model of two nodes (`root`, node 0, a root, and `name`, node 1, its
 * child) and one unskinned mesh on node 1 of nv vertices (with normals
 * when `normals`) and ni indices: the caller fills the vertices and the
 * indices (and may move the rest poses). */
static inline tu_mesh_parts tu_mesh_model(kin_model *m, const char *root, const char *name,
                                          int nv, int ni, int normals)
{
    tu_mesh_parts t;
    memset(m, 0, sizeof *m);
    int16_t *parents = kin_block_alloc(&m->block, 2 * sizeof(int16_t));
    t.rest = kin_block_alloc(&m->block, 2 * sizeof(kin_transform));
    char(*names)[KIN_NAME_MAX] = kin_block_alloc(&m->block, 2 * KIN_NAME_MAX);
    t.pos = kin_block_alloc(&m->block, 3 * sizeof(float) * (size_t)nv);
    t.nrm = normals ? kin_block_alloc(&m->block, 3 * sizeof(float) * (size_t)nv) : NULL;
    t.idx = kin_block_alloc(&m->block, sizeof(uint32_t) * (size_t)ni);
    t.mesh = kin_block_alloc(&m->block, sizeof(kin_mesh));
    assert_non_null(t.mesh);
    parents[0] = KIN_NO_PARENT;
    parents[1] = 0;
    t.rest[0] = t.rest[1] = kin_transform_identity();
    strcpy(names[0], root);
    strcpy(names[1], name);
    *t.mesh = (kin_mesh){.vertex_count = nv, .positions = t.pos, .normals = t.nrm,
                         .index_count = ni, .indices = t.idx, .node = 1, .skin = -1};
    m->node_count = 2;
    m->parents = parents;
    m->rest = t.rest;
    m->names = (const char(*)[KIN_NAME_MAX])names;
    m->mesh_count = 1;
    m->meshes = t.mesh;
    return t;
}

/* A model of two nodes ("head" at the origin, node 0, and `name`, node 1,
 * turned by yaw radians about +Y; yaw 0: the identity) and one unskinned
 * quad [-s,s]^2 at depth z on node 1, normals +Z, triangles (0,1,2),
 * (0,2,3). Validated. */
static inline void tu_quad_model(kin_model *m, float s, float z, float yaw, const char *name)
{
    tu_mesh_parts t = tu_mesh_model(m, "head", name, 4, 6, 1);
    if (yaw != 0.0f) t.rest[1].r = kin_quat_axis_angle(kin_v3(0, 1, 0), yaw);
    const float p[12] = {-s, -s, z, s, -s, z, s, s, z, -s, s, z};
    memcpy(t.pos, p, sizeof p);
    for (int i = 0; i < 4; i++) t.nrm[3 * i + 2] = 1.0f;
    const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    memcpy(t.idx, ix, sizeof ix);
    char why[200];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
}

/* The images of one stereo frame. */
typedef struct tu_frame_bufs {
    uint8_t *cam[2], *virt[2], *out[2];
} tu_frame_bufs;

/* Camera images cw x ch and virtual images lw x lh of random bytes from
 * seed (per eye: camera, then virtual), outputs lw x lh filled with 0xAB,
 * and `in` zeroed and pointed at them, with the default lighting (head
 * node 0). */
static inline void tu_frame_make(tu_frame_bufs *b, pipe_frame_in *in, uint64_t seed, int cw,
                                 int ch, int lw, int lh)
{
    tu_rng r = {seed};
    const size_t nc = (size_t)cw * ch * 4, nl = (size_t)lw * lh * 4;
    memset(in, 0, sizeof *in);
    for (int e = 0; e < 2; e++) {
        b->cam[e] = malloc(nc);
        b->virt[e] = malloc(nl);
        b->out[e] = malloc(nl);
        assert_non_null(b->cam[e]);
        assert_non_null(b->virt[e]);
        assert_non_null(b->out[e]);
        for (size_t i = 0; i < nc; i++) b->cam[e][i] = (uint8_t)tu_next(&r);
        for (size_t i = 0; i < nl; i++) b->virt[e][i] = (uint8_t)tu_next(&r);
        memset(b->out[e], 0xAB, nl);
        in->camera[e] = (fuse_image){b->cam[e], cw, ch, cw * 4};
        in->virt[e] = (fuse_image){b->virt[e], lw, lh, lw * 4};
        in->out[e] = (fuse_image){b->out[e], lw, lh, lw * 4};
    }
    in->head_node = 0;
    in->lighting = pipe_lighting_default();
}

static inline void tu_frame_free(tu_frame_bufs *b)
{
    for (int e = 0; e < 2; e++) {
        free(b->cam[e]);
        free(b->virt[e]);
        free(b->out[e]);
    }
}

/* Scratch of the stages by hand for a crop of w x h. */
typedef struct tu_stages {
    int w, h;
    float *depth;
    uint32_t *n10;            /* the normals, packed as the pipe's (ef_n10.h) */
    uint8_t *mask, *layer;
} tu_stages;

static inline void tu_stages_make(tu_stages *s, int w, int h)
{
    s->w = w;
    s->h = h;
    s->depth = malloc(sizeof(float) * (size_t)w * h);
    s->n10 = malloc(sizeof(uint32_t) * (size_t)w * h);
    s->mask = malloc((size_t)w * h);
    s->layer = malloc((size_t)4 * w * h);
    assert_non_null(s->depth);
    assert_non_null(s->n10);
    assert_non_null(s->mask);
    assert_non_null(s->layer);
}

static inline void tu_stages_free(tu_stages *s)
{
    free(s->depth);
    free(s->n10);
    free(s->mask);
    free(s->layer);
}

/* One eye of a tu_quad_model frame by hand: the quad (posed by node 1's
 * rest transform) rastered by cam into s->mask and packed normals (the
 * crop's size, no culling; the pipe packs them when only the lighting
 * reads them), the default lighting's first light turned into cam's view,
 * the crop P lit into s->layer, faded at the viewport's sides inside V as
 * the pipeline does by default (fuse_edge_fade, PIPE_EDGE_FADE_DEFAULT)
 * and composited over V into R at the viewport (vx, vy, vw, vh). */
static inline void tu_quad_stages(const kin_model *m, const kin_camera *cam, tu_stages *s,
                                  const fuse_image *P, const fuse_image *V, int vx, int vy,
                                  int vw, int vh, fuse_image *R)
{
    const int cw = s->w, ch = s->h;
    rast_target t = {cw, ch, s->depth, cw, s->mask, cw, NULL, 0, 3, s->n10, cw};
    rast_target_clear(&t);
    float clip[16], vn[12], wpos[12], wn[12];
    kin_mat4 qw = kin_mat4_from_transform(&m->rest[1]);
    kin_mesh_transform(&m->meshes[0], &qw, wpos, wn);
    rast_transform_points(cam->view_proj.m, wpos, 4, clip);
    rast_transform_dirs(cam->view.m, wn, 4, vn);
    rast_mesh_desc md = {clip, 4, vn, 3, m->meshes[0].indices, 2, RAST_CULL_NONE};
    assert_int_equal(rast_draw(&t, &md, NULL), RAST_OK);
    fuse_lighting L = fuse_lighting_default();
    kin_vec3 ld = kin_v3_norm(kin_mat4_mul_dir(
        &cam->view, kin_v3(L.lights[0].dir[0], L.lights[0].dir[1], L.lights[0].dir[2])));
    L.lights[0].dir[0] = ld.x;
    L.lights[0].dir[1] = ld.y;
    L.lights[0].dir[2] = ld.z;
    fuse_intrinsics K = {cam->fx, cam->fy, cam->cx, cam->cy};
    fuse_image Q = {s->layer, cw, ch, cw * 4};
    assert_int_equal(fuse_light_n10(&L, &K, P, s->mask, cw, s->n10, cw, &Q), FUSE_OK);
    /* the pipeline's default soft edges (pipe_desc.edge_fade 0): the sides
     * of the viewport inside V */
    const unsigned sides = (vx > 0 ? FUSE_EDGE_LEFT : 0u) | (vx + vw < V->width ? FUSE_EDGE_RIGHT : 0u) |
                           (vy > 0 ? FUSE_EDGE_TOP : 0u) | (vy + vh < V->height ? FUSE_EDGE_BOTTOM : 0u);
    assert_int_equal(fuse_edge_fade(&Q, PIPE_EDGE_FADE_DEFAULT, sides), FUSE_OK);
    assert_int_equal(fuse_composite(&Q, V, vx, vy, vw, vh, R), FUSE_OK);
}

#endif
