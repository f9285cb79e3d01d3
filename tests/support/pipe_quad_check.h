/* pipe_quad_check.h - a pipe on a tu_quad_model and its checks, shared by
 * tests/test_pipe.c (the paper's HMD) and tests/test_pipe_hmd.c (another
 * desc): the model, pipe and frame in one rig, the frame against its
 * stages called by hand, and raw YUYV camera frames against their RGBA
 * conversion. Header-only; include after support/testutil.h, <cmocka.h>,
 * src/pipe/pipe.h and support/pipe_frames.h. */
#ifndef EGOFUSE_TU_PIPE_QUAD_CHECK_H
#define EGOFUSE_TU_PIPE_QUAD_CHECK_H

#include <stdint.h>
#include <stdlib.h>

/* A pipe on a tu_quad_model with the images of one frame. */
typedef struct tu_quad_rig {
    kin_model m;
    pipe_ctx *p;
    tu_frame_bufs b;
    pipe_frame_in in;
} tu_quad_rig;

/* r := the quad of half size s at depth z turned by yaw (tu_quad_model,
 * "quad"), a pipe of d (NULL: the defaults) on it and the frame of seed
 * with cw x ch camera and lw x lh display images (tu_frame_make). */
static inline void tu_quad_rig_open(tu_quad_rig *r, float s, float z, float yaw,
                                    const pipe_desc *d, uint64_t seed, int cw, int ch, int lw,
                                    int lh)
{
    tu_quad_model(&r->m, s, z, yaw, "quad");
    r->p = pipe_create(d, &r->m);
    assert_non_null(r->p);
    tu_frame_make(&r->b, &r->in, seed, cw, ch, lw, lh);
}

/* r's frame with the head at head (no head node) run, its statistics in
 * st; a failure names the pipe's reason. */
static inline void tu_quad_rig_run(tu_quad_rig *r, const kin_mat4 *head, pipe_frame_stats *st)
{
    char why[300] = "";
    r->in.head_node = -1;
    r->in.world_from_head = head;
    if (pipe_frame(r->p, &r->in, st, why, sizeof why) != PIPE_OK) fail_msg("pipe_frame: %s", why);
}

/* Frees the frame, the pipe and the model of r. */
static inline void tu_quad_rig_close(tu_quad_rig *r)
{
    tu_frame_free(&r->b);
    pipe_destroy(r->p);
    kin_model_free(&r->m);
}

/* Both eyes of the frame b that p ran on the quad model m, the head at
 * head: the camera of desc (NULL: the paper's) is the pipe's, the pipe's
 * mask has the crop's size and equals the stages by hand (tu_quad_stages)
 * on the crop (x0, y0, width, height) of the cam_w pixels wide camera
 * images, and the output of lw x lh equals their composite at the
 * viewport vp (x, y, width, height). */
static inline void tu_quad_frame_equals_stages(pipe_ctx *p, const kin_model *m,
                                               const tu_frame_bufs *b,
                                               const kin_sthmd_desc *desc, const kin_mat4 *head,
                                               int cam_w, const int crop[4], int lw, int lh,
                                               const int vp[4])
{
    tu_stages s;
    tu_stages_make(&s, crop[2], crop[3]);
    uint8_t *expect = malloc((size_t)lw * lh * 4);
    assert_non_null(expect);
    for (int e = 0; e < 2; e++) {
        int mw, mh;
        const uint8_t *pm = pipe_mask(p, e, &mw, &mh);
        assert_int_equal(mw, crop[2]);
        assert_int_equal(mh, crop[3]);
        kin_camera cam = kin_sthmd_camera(desc, head, (kin_eye)e);
        kin_camera pc = pipe_camera(p, e);
        assert_memory_equal(&cam.view_proj, &pc.view_proj, sizeof cam.view_proj);
        fuse_image P = {b->cam[e] + ((size_t)crop[1] * cam_w + (size_t)crop[0]) * 4, crop[2],
                        crop[3], cam_w * 4};
        fuse_image V = {b->virt[e], lw, lh, lw * 4};
        fuse_image R = {expect, lw, lh, lw * 4};
        tu_quad_stages(m, &cam, &s, &P, &V, vp[0], vp[1], vp[2], vp[3], &R);
        assert_memory_equal(pm, s.mask, (size_t)s.w * s.h);
        assert_memory_equal(expect, b->out[e], (size_t)lw * lh * 4);
    }
    tu_stages_free(&s);
    free(expect);
}

/* yuyv[e] := random YUYV camera frames of cw x ch from r (left, then
 * right; freed by the caller). */
static inline void tu_yuyv_frames(uint8_t *yuyv[2], int cw, int ch, tu_rng *r)
{
    for (int e = 0; e < 2; e++) {
        yuyv[e] = malloc((size_t)cw * ch * 2);
        assert_non_null(yuyv[e]);
        for (size_t i = 0; i < (size_t)cw * ch * 2; i++) yuyv[e][i] = (uint8_t)tu_next(r);
    }
}

/* The YUYV frames yuyv (cw x ch) as in's raw camera frames, and their
 * RGBA conversion as the camera images of the frame c (cw x ch). */
static inline void tu_raw_cameras(pipe_frame_in *in, uint8_t *const yuyv[2], int cw, int ch,
                                  tu_frame_bufs *c)
{
    for (int e = 0; e < 2; e++) {
        in->camera_raw[e] = (fuse_frame){yuyv[e], (size_t)cw * ch * 2, cw, ch, cw * 2,
                                         FUSE_FMT_YUYV};
        fuse_image full = {c->cam[e], cw, ch, cw * 4};
        assert_int_equal(fuse_frame_to_rgba(&in->camera_raw[e], 0, &full), FUSE_OK);
    }
}

#endif
