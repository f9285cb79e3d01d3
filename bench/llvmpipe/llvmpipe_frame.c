/* llvmpipe_frame.c - the whole stereo frame of the sample sequence run as
 * a GPU pipeline would run it, on Mesa llvmpipe (EGL surfaceless + OpenGL
 * ES 3, egl_harness.h), side by side with egofuse in the same process:
 *
 *   CPU     the pose (animation sample, FK, joint matrices) and the two
 *           cameras, as a GL application computes them.
 *   upload  per eye: the camera frame as it comes from the camera (YUYV,
 *           an RGBA8UI texture of 320x480), the virtual image (RGBA8) and
 *           its depth (R32F), 1280x800.
 *   pass 1  per eye, 640x400: the model skinned in the vertex shader
 *           (linear blend, 4 joints per vertex, joint matrices as a uniform
 *           array), depth test, into an RGBA16F target: view-space normal
 *           and view depth (0 = not covered: the mask).
 *   pass 2  per eye, full screen 640x400: YUYV -> RGB (the integer BT.601
 *           formula of docs/fuse.md), the lighting of docs/fuse.md
 *           (Blinn-Phong + Fresnel edge fade; pow() for the specular), the
 *           depth test against the virtual scene, premultiplied RGBA8.
 *   pass 3  per eye, full screen 1280x800: bilinear resampling of the lit
 *           layer into the 1194x746 viewport (GL_LINEAR, centre-aligned)
 *           and over-composite onto V (V outside the viewport).
 *   read    glReadPixels of both 1280x800 outputs (the frame is done when
 *           the bytes are in memory, as for egofuse).
 * egofuse runs the same frames (pipe_frame, the animation pose, the YUYV
 * conversion by fuse_frame_to_rgba) interleaved with llvmpipe, so the
 * ratio is measured side by side. The outputs are compared: mean and max
 * absolute difference and the share of pixels whose largest channel
 * difference exceeds 8, over the whole outputs and over the hand pixels
 * (where either output differs from V).
 *
 *   llvmpipe_frame [--samples DIR] [--threads N] [--frames N] [--window N]
 *                  [--case typical|worst|both] [--csv FILE] [--diff-csv FILE]
 *                  [--images DIR]
 *
 * --case: the typical sequence (default), bench_frame's worst case
 * (bench_worst.h: the pose of the grasp, the head moved towards the hands
 * until about 70% of the cameras' pixels are covered; the images still
 * cycle through the window), or both, one after the other.
 *
 * --threads N sets LP_NUM_THREADS=N (llvmpipe's rasterizer threads; its
 * vertex processing and setup stay on the calling thread) and gives
 * egofuse N threads. --csv appends rows (bench_frame writes the header):
 * frame_typical,llvmpipe,... and frame_anim,egofuse,... (the interleaved
 * egofuse run), frame_worst,llvmpipe and frame_worst_anim,egofuse for the
 * worst case; in llvmpipe rows skin_ms is the CPU pose, raster_ms the
 * uploads and draw calls, fuse_ms the wait for the frame and the
 * read-back. --diff-csv appends the image comparison (its last column
 * names the case). --images writes eye 0 of the last compared frame from
 * both (CASE_llvmpipe_left.png, CASE_egofuse_left.png).
 * LLVMPIPE_FRAME_PROFILE=1 finishes and times every step apart (uploads,
 * pass 1, 2, 3, read-back) to show where llvmpipe's time goes.
 * Exit status: 0 (benchmarks report, they do not judge), 1 the samples
 * cannot be read, 2 usage, 3 llvmpipe unavailable. */
#include "egl_harness.h"
#include "../bench_sample.h"
#include "../bench_util.h"
#include "../bench_worst.h"

#include "../../src/cpu/cpu.h"
#include "../../src/io/io.h"
#include "../../src/pipe/pipe.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_JOINTS 128
#define MAX_WINDOW 64
#define BUDGET_MS (1000.0 / 60.0)

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "llvmpipe_frame: out of memory\n");
        exit(1);
    }
    return p;
}

/* ------------------------------------------------------------- shaders */

static const char *vs_skin =
    "#version 300 es\n"
    "layout(location=0) in vec3 a_pos; layout(location=1) in vec3 a_nrm;\n"
    "layout(location=2) in uvec4 a_j; layout(location=3) in vec4 a_w;\n"
    "uniform mat4 u_J[128]; uniform mat4 u_vp; uniform mat4 u_view;\n"
    "out vec3 v_n; out float v_d;\n"
    "void main() {\n"
    "  mat4 M = a_w.x * u_J[a_j.x] + a_w.y * u_J[a_j.y] + a_w.z * u_J[a_j.z] + a_w.w * u_J[a_j.w];\n"
    "  vec4 p = M * vec4(a_pos, 1.0);\n"
    "  v_n = mat3(u_view) * (mat3(M) * a_nrm);\n"
    "  v_d = -(u_view * p).z;\n"
    "  vec4 c = u_vp * p;\n"
    "  c.y = -c.y;   /* framebuffer row 0 = the top image row, as egofuse */\n"
    "  gl_Position = c;\n"
    "}\n";

static const char *fs_gbuf =
    "#version 300 es\nprecision highp float;\n"
    "in vec3 v_n; in float v_d; out vec4 o;\n"
    "void main() { o = vec4(v_n, v_d); }\n";

static const char *vs_full =
    "#version 300 es\n"
    "void main() {\n"
    "  gl_Position = vec4(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1), 0.0, 1.0);\n"
    "}\n";

static const char *fs_light =
    "#version 300 es\nprecision highp float; precision highp int;\n"
    "uniform highp usampler2D u_cam; uniform highp sampler2D u_g; uniform highp sampler2D u_vd;\n"
    "uniform int u_crop_y0; uniform vec4 u_K; uniform int u_nl;\n"
    "uniform vec3 u_ldir[8]; uniform vec3 u_lcol[8]; uniform vec3 u_amb; uniform vec4 u_par;\n"
    "uniform vec3 u_tone; uniform ivec4 u_vp; uniform ivec2 u_qsize; uniform float u_offset;\n"
    "uniform int u_depth_test;\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "  vec4 g = texelFetch(u_g, p, 0);\n"
    "  if (!(g.w > 0.0)) { o = vec4(0.0); return; }\n"
    "  if (u_depth_test != 0) {\n"
    /* floor((2x + 1) vp_w / (2 Qw)) in float: exact here (the fraction is a
     * multiple of 1/(2 Qw)), and vector integer division is slow on CPUs */
    "    int ox = u_vp.x + int(floor(float((2 * p.x + 1) * u_vp.z) / float(2 * u_qsize.x)));\n"
    "    int oy = u_vp.y + int(floor(float((2 * p.y + 1) * u_vp.w) / float(2 * u_qsize.y)));\n"
    "    float sc = texelFetch(u_vd, ivec2(ox, oy), 0).r;\n"
    "    if (sc > 0.0 && !isinf(sc) && !isnan(sc) && sc < g.w + u_offset) { o = vec4(0.0); return; }\n"
    "  }\n"
    "  uvec4 c = texelFetch(u_cam, ivec2(p.x >> 1, p.y + u_crop_y0), 0);\n"
    "  int C = int((p.x & 1) == 0 ? c.r : c.b) - 16, D = int(c.g) - 128, E = int(c.a) - 128;\n"
    "  ivec3 rgb = clamp((ivec3(298 * C + 409 * E, 298 * C - 100 * D - 208 * E, 298 * C + 516 * D)\n"
    "                     + 128) >> 8, 0, 255);\n"
    "  vec3 P = vec3(rgb) * (1.0 / 255.0);\n"
    "  float px = ((float(p.x) + 0.5) - u_K.z) / u_K.x, py = ((float(p.y) + 0.5) - u_K.w) / u_K.y;\n"
    "  float il = 1.0 / sqrt(px * px + py * py + 1.0);\n"
    "  vec3 V = vec3(-px * il, py * il, il);\n"
    "  float nn = dot(g.xyz, g.xyz);\n"
    "  vec3 N = (nn > 1e-30 && nn < 1e30) ? g.xyz / sqrt(nn) : V;\n"
    "  vec3 L3 = u_amb;\n"
    "  for (int i = 0; i < u_nl; i++) {\n"
    "    vec3 L = u_ldir[i];\n"
    "    float w = u_par.x * max(dot(N, L), 0.0);\n"
    "    vec3 h = L + V; float hh = dot(h, h);\n"
    "    if (u_par.y != 0.0 && hh > 1e-12)\n"
    "      w += u_par.y * pow(clamp(dot(N, h) / sqrt(hh), 1e-30, 1.0), u_par.z);\n"
    "    L3 += u_lcol[i] * w;\n"
    "  }\n"
    "  float t = max(1.0 - dot(N, V), 0.0);\n"
    "  float m = clamp(1.0 - u_par.w * (t * t), 0.0, 1.0);\n"
    "  vec3 Pp = clamp(P * L3 * u_tone, 0.0, 1.0);\n"
    "  o = vec4(m * Pp, m);\n"
    "}\n";

static const char *fs_comp =
    "#version 300 es\nprecision highp float; precision highp int;\n"
    "uniform highp sampler2D u_q; uniform highp sampler2D u_v; uniform ivec4 u_vp;\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy);\n"
    "  vec4 V = texelFetch(u_v, p, 0);\n"
    "  ivec2 r = p - u_vp.xy;\n"
    "  if (r.x < 0 || r.y < 0 || r.x >= u_vp.z || r.y >= u_vp.w) { o = V; return; }\n"
    "  vec4 q = texture(u_q, (vec2(r) + 0.5) / vec2(u_vp.zw));\n"
    "  o = vec4(q.rgb + (1.0 - q.a) * V.rgb, 1.0);\n"
    "}\n";

/* ------------------------------------------------------------- inputs */

typedef struct inputs {
    kin_model model;
    const kin_animation *anim;
    int head;
    float fps;
    int seq_frames;
    kin_sthmd_desc hmd;
    kin_sthmd_geometry geo;
    pipe_lighting lighting;
    int window;
    int frame_of[MAX_WINDOW];          /* sequence frame of window slot */
    uint8_t *yuyv[MAX_WINDOW][2];      /* 640x480 YUYV */
    uint8_t *virt[MAX_WINDOW][2];      /* 1280x800 RGBA */
    float *depth[MAX_WINDOW][2];       /* 1280x800, or NULL */
} inputs;


static int load(inputs *in, const char *dir, int window)
{
    io_scene sc;
    if (!bench_sample_posed(dir, "llvmpipe_frame", 0, &sc, &in->model, &in->anim, &in->head))
        return 0;
    if (in->head < 0) {
        fprintf(stderr, "llvmpipe_frame: no head node\n");
        return 0;
    }
    for (int s = 0; s < in->model.skin_count; s++)
        if (in->model.skins[s].joint_count > MAX_JOINTS) {
            fprintf(stderr, "llvmpipe_frame: a skin has more than %d joints\n", MAX_JOINTS);
            return 0;
        }
    bench_sample_play(&sc, &in->fps, &in->seq_frames, &in->hmd, &in->geo, &in->lighting.light);
    const int cw = in->hmd.cam_width, ch = in->hmd.cam_height;
    const int lw = in->hmd.lcd_width, lh = in->hmd.lcd_height;
    in->window = window < sc.frames ? window : sc.frames;
    for (int f = 0; f < in->window; f++) {
        int fr = (int)((long)f * sc.frames / in->window);
        in->frame_of[f] = fr;
        for (int e = 0; e < 2; e++)
            if (!bench_sample_eye(&sc, fr, e, cw, ch, lw, lh, "llvmpipe_frame", &in->yuyv[f][e],
                                  &in->virt[f][e], &in->depth[f][e]))
                return 0;
    }
    return 1;
}

/* ------------------------------------------------------- the GL frame */

typedef struct gl_mesh {
    GLuint vao, vbo[4], ibo;
    int index_count, skin, node;
} gl_mesh;

typedef struct gl_state {
    GLuint prog_skin, prog_light, prog_comp, vao_empty;
    GLint u_J, u_vp, u_view;
    GLint l_cam, l_g, l_vd, l_crop, l_K, l_nl, l_ldir, l_lcol, l_amb, l_par, l_tone, l_vp, l_qs,
        l_off, l_dt;
    GLint c_q, c_v, c_vp;
    gl_mesh *meshes;
    int mesh_count;
    GLuint cam_tex[2], g_tex[2], depth_rb[2], q_tex[2], v_tex[2], vd_tex[2], out_rb[2];
    GLuint fb_g[2], fb_q[2], fb_out[2];
    /* CPU pose */
    kin_transform *locals;
    kin_mat4 *world, **jm;
} gl_state;

static GLuint tex2d(GLenum ifmt, int w, int h, GLenum filter)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, ifmt, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, (GLint)filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, (GLint)filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

/* Texture tex on texture unit `unit` and the sampler uniform loc of the
 * program in use reading that unit. */
static void bind_sampler(GLint loc, int unit, GLuint tex)
{
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    glBindTexture(GL_TEXTURE_2D, tex);
    glUniform1i(loc, unit);
}

static int gl_setup(gl_state *g, const inputs *in)
{
    memset(g, 0, sizeof *g);
    const kin_model *m = &in->model;
    g->prog_skin = eh_program(vs_skin, fs_gbuf);
    g->prog_light = eh_program(vs_full, fs_light);
    g->prog_comp = eh_program(vs_full, fs_comp);
    g->u_J = glGetUniformLocation(g->prog_skin, "u_J");
    g->u_vp = glGetUniformLocation(g->prog_skin, "u_vp");
    g->u_view = glGetUniformLocation(g->prog_skin, "u_view");
#define LOC(f, n) g->f = glGetUniformLocation(g->prog_light, n)
    LOC(l_cam, "u_cam"); LOC(l_g, "u_g"); LOC(l_vd, "u_vd"); LOC(l_crop, "u_crop_y0");
    LOC(l_K, "u_K"); LOC(l_nl, "u_nl"); LOC(l_ldir, "u_ldir"); LOC(l_lcol, "u_lcol");
    LOC(l_amb, "u_amb"); LOC(l_par, "u_par"); LOC(l_tone, "u_tone"); LOC(l_vp, "u_vp");
    LOC(l_qs, "u_qsize"); LOC(l_off, "u_offset"); LOC(l_dt, "u_depth_test");
#undef LOC
    g->c_q = glGetUniformLocation(g->prog_comp, "u_q");
    g->c_v = glGetUniformLocation(g->prog_comp, "u_v");
    g->c_vp = glGetUniformLocation(g->prog_comp, "u_vp");
    glGenVertexArrays(1, &g->vao_empty);

    /* meshes (normals from pipe_pose where the file has none) */
    pipe_pose ps;
    if (pipe_pose_init(&ps, m) != 0) return 0;
    g->mesh_count = m->mesh_count;
    g->meshes = xmalloc(sizeof *g->meshes * (size_t)(m->mesh_count + 1));
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &ps.meshes[i];
        gl_mesh *gm = &g->meshes[i];
        gm->index_count = me->index_count;
        gm->skin = me->skin;
        gm->node = me->node;
        glGenVertexArrays(1, &gm->vao);
        glBindVertexArray(gm->vao);
        glGenBuffers(4, gm->vbo);
        glGenBuffers(1, &gm->ibo);
        const GLsizeiptr nv = me->vertex_count;
        glBindBuffer(GL_ARRAY_BUFFER, gm->vbo[0]);
        glBufferData(GL_ARRAY_BUFFER, nv * 12, me->positions, GL_STATIC_DRAW);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, 0);
        glEnableVertexAttribArray(0);
        glBindBuffer(GL_ARRAY_BUFFER, gm->vbo[1]);
        glBufferData(GL_ARRAY_BUFFER, nv * 12, me->normals, GL_STATIC_DRAW);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, 0);
        glEnableVertexAttribArray(1);
        if (me->skin >= 0 && me->joints && me->weights) {
            glBindBuffer(GL_ARRAY_BUFFER, gm->vbo[2]);
            glBufferData(GL_ARRAY_BUFFER, nv * 8, me->joints, GL_STATIC_DRAW);
            glVertexAttribIPointer(2, 4, GL_UNSIGNED_SHORT, 0, 0);
            glEnableVertexAttribArray(2);
            glBindBuffer(GL_ARRAY_BUFFER, gm->vbo[3]);
            glBufferData(GL_ARRAY_BUFFER, nv * 16, me->weights, GL_STATIC_DRAW);
            glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, 0, 0);
            glEnableVertexAttribArray(3);
        } else {
            gm->skin = -1;   /* one matrix: the node's world matrix in u_J[0] */
            glVertexAttribI4ui(2, 0, 0, 0, 0);
            glVertexAttrib4f(3, 1, 0, 0, 0);
        }
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gm->ibo);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)me->index_count * 4, me->indices,
                     GL_STATIC_DRAW);
    }
    glBindVertexArray(0);
    pipe_pose_free(&ps);
    g->locals = xmalloc(sizeof *g->locals * (size_t)m->node_count);
    g->world = xmalloc(sizeof *g->world * (size_t)m->node_count);
    g->jm = xmalloc(sizeof *g->jm * (size_t)(m->skin_count + 1));
    for (int s = 0; s < m->skin_count; s++)
        g->jm[s] = xmalloc(sizeof(kin_mat4) * (size_t)m->skins[s].joint_count);

    const int cw = in->geo.crop_width, ch = in->geo.crop_height;
    const int lw = in->hmd.lcd_width, lh = in->hmd.lcd_height;
    for (int e = 0; e < 2; e++) {
        g->cam_tex[e] = tex2d(GL_RGBA8UI, in->hmd.cam_width / 2, in->hmd.cam_height, GL_NEAREST);
        g->g_tex[e] = tex2d(GL_RGBA16F, cw, ch, GL_NEAREST);
        g->q_tex[e] = tex2d(GL_RGBA8, cw, ch, GL_LINEAR);
        g->v_tex[e] = tex2d(GL_RGBA8, lw, lh, GL_NEAREST);
        g->vd_tex[e] = tex2d(GL_R32F, lw, lh, GL_NEAREST);
        glGenRenderbuffers(1, &g->depth_rb[e]);
        glBindRenderbuffer(GL_RENDERBUFFER, g->depth_rb[e]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, cw, ch);
        glGenRenderbuffers(1, &g->out_rb[e]);
        glBindRenderbuffer(GL_RENDERBUFFER, g->out_rb[e]);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, lw, lh);
        glGenFramebuffers(1, &g->fb_g[e]);
        glBindFramebuffer(GL_FRAMEBUFFER, g->fb_g[e]);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g->g_tex[e], 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                  g->depth_rb[e]);
        int ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
        glGenFramebuffers(1, &g->fb_q[e]);
        glBindFramebuffer(GL_FRAMEBUFFER, g->fb_q[e]);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, g->q_tex[e], 0);
        ok = ok && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
        glGenFramebuffers(1, &g->fb_out[e]);
        glBindFramebuffer(GL_FRAMEBUFFER, g->fb_out[e]);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                  g->out_rb[e]);
        ok = ok && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
        if (!ok) {
            fprintf(stderr, "llvmpipe_frame: incomplete framebuffer (RGBA16F not renderable?)\n");
            return 0;
        }
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    return glGetError() == GL_NO_ERROR;
}

typedef struct gl_times { double pose, submit, finish; } gl_times;

/* With LLVMPIPE_FRAME_PROFILE set, every step is finished and timed
 * (slower: the steps no longer overlap); the sums go to prof[]. */
static double prof[5];
static int profiling;
static double prof_t;
static void prof_mark(int k)
{
    if (!profiling) return;
    glFinish();
    double t = eh_now_ms();
    prof[k] += t - prof_t;
    prof_t = t;
}

/* One stereo frame on llvmpipe: window slot w, time t, the head node's
 * pose or *head (world_from_head) when head is not NULL; outputs into
 * out[2] (1280x800 RGBA). */
static void gl_frame(gl_state *g, const inputs *in, int w, float t, const kin_mat4 *head,
                     uint8_t *out[2], gl_times *tm)
{
    const kin_model *m = &in->model;
    const int cw = in->geo.crop_width, ch = in->geo.crop_height;
    const int lw = in->hmd.lcd_width, lh = in->hmd.lcd_height;
    double t0 = eh_now_ms();
    kin_pose_rest(m, g->locals);
    if (in->anim) kin_anim_sample(in->anim, m->node_count, t, g->locals);
    kin_fk(m->parents, m->node_count, g->locals, NULL, g->world);
    for (int s = 0; s < m->skin_count; s++)
        kin_skin_joint_matrices(&m->skins[s], g->world, g->jm[s]);
    kin_camera cam[2];
    for (int e = 0; e < 2; e++)
        cam[e] = kin_sthmd_camera(&in->hmd, head ? head : &g->world[in->head], (kin_eye)e);
    double t1 = eh_now_ms();
    const fuse_lighting *L = &in->lighting.light;
    prof_t = eh_now_ms();
    for (int e = 0; e < 2; e++) {
        /* uploads */
        glBindTexture(GL_TEXTURE_2D, g->cam_tex[e]);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, in->hmd.cam_width / 2, in->hmd.cam_height,
                        GL_RGBA_INTEGER, GL_UNSIGNED_BYTE, in->yuyv[w][e]);
        glBindTexture(GL_TEXTURE_2D, g->v_tex[e]);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, lw, lh, GL_RGBA, GL_UNSIGNED_BYTE, in->virt[w][e]);
        if (in->depth[w][e]) {
            glBindTexture(GL_TEXTURE_2D, g->vd_tex[e]);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, lw, lh, GL_RED, GL_FLOAT, in->depth[w][e]);
        }
        prof_mark(0);
        /* pass 1: skinning, depth, normals */
        glBindFramebuffer(GL_FRAMEBUFFER, g->fb_g[e]);
        glViewport(0, 0, cw, ch);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDisable(GL_CULL_FACE);
        glClearColor(0, 0, 0, 0);
        glClearDepthf(1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glUseProgram(g->prog_skin);
        glUniformMatrix4fv(g->u_vp, 1, GL_FALSE, cam[e].view_proj.m);
        glUniformMatrix4fv(g->u_view, 1, GL_FALSE, cam[e].view.m);
        for (int i = 0; i < g->mesh_count; i++) {
            const gl_mesh *gm = &g->meshes[i];
            if (gm->skin >= 0)
                glUniformMatrix4fv(g->u_J, m->skins[gm->skin].joint_count, GL_FALSE,
                                   g->jm[gm->skin][0].m);
            else {
                kin_mat4 id = kin_mat4_identity();
                glUniformMatrix4fv(g->u_J, 1, GL_FALSE, gm->node >= 0 ? g->world[gm->node].m : id.m);
            }
            glBindVertexArray(gm->vao);
            glDrawElements(GL_TRIANGLES, gm->index_count, GL_UNSIGNED_INT, 0);
        }
        glDisable(GL_DEPTH_TEST);
        prof_mark(1);
        /* pass 2: camera format, lighting, depth test against the scene */
        glBindFramebuffer(GL_FRAMEBUFFER, g->fb_q[e]);
        glUseProgram(g->prog_light);
        glBindVertexArray(g->vao_empty);
        bind_sampler(g->l_cam, 0, g->cam_tex[e]);
        bind_sampler(g->l_g, 1, g->g_tex[e]);
        bind_sampler(g->l_vd, 2, g->vd_tex[e]);
        glUniform1i(g->l_crop, in->geo.crop_y0);
        glUniform4f(g->l_K, cam[e].fx, cam[e].fy, cam[e].cx, cam[e].cy);
        float ld[8][3], lc[8][3];
        int nl = L->light_count < 8 ? L->light_count : 8;
        for (int i = 0; i < nl; i++) {
            kin_vec3 d = kin_v3(L->lights[i].dir[0], L->lights[i].dir[1], L->lights[i].dir[2]);
            d = kin_v3_norm(kin_mat4_mul_dir(&cam[e].view, d));
            ld[i][0] = d.x, ld[i][1] = d.y, ld[i][2] = d.z;
            memcpy(lc[i], L->lights[i].color, sizeof lc[i]);
        }
        glUniform1i(g->l_nl, nl);
        if (nl > 0) {
            glUniform3fv(g->l_ldir, nl, ld[0]);
            glUniform3fv(g->l_lcol, nl, lc[0]);
        }
        glUniform3fv(g->l_amb, 1, L->ambient);
        glUniform4f(g->l_par, L->kd, L->ks, L->shininess, L->kf);
        glUniform3fv(g->l_tone, 1, L->tone);
        glUniform4i(g->l_vp, in->geo.vp_x0, in->geo.vp_y0, in->geo.vp_width, in->geo.vp_height);
        glUniform2i(g->l_qs, cw, ch);
        glUniform1f(g->l_off, in->hmd.cam_offset_m);
        glUniform1i(g->l_dt, in->depth[w][e] != NULL);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        prof_mark(2);
        /* pass 3: resample + composite */
        glBindFramebuffer(GL_FRAMEBUFFER, g->fb_out[e]);
        glViewport(0, 0, lw, lh);
        glUseProgram(g->prog_comp);
        bind_sampler(g->c_q, 0, g->q_tex[e]);
        bind_sampler(g->c_v, 1, g->v_tex[e]);
        glUniform4i(g->c_vp, in->geo.vp_x0, in->geo.vp_y0, in->geo.vp_width, in->geo.vp_height);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glFlush();
        prof_mark(3);
    }
    double t2 = eh_now_ms();
    for (int e = 0; e < 2; e++) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, g->fb_out[e]);
        glReadPixels(0, 0, lw, lh, GL_RGBA, GL_UNSIGNED_BYTE, out[e]);
    }
    double t3 = eh_now_ms();
    prof[4] += profiling ? t3 - t2 : 0;
    if (tm) {
        tm->pose = t1 - t0;
        tm->submit = t2 - t1;
        tm->finish = t3 - t2;
    }
}

/* ------------------------------------------------------ the egofuse frame */

typedef struct ego_state {
    pipe_ctx *p;
    uint8_t *cam[2];   /* 640x480 RGBA (rows of the crop filled) */
} ego_state;

static double ego_frame(ego_state *s, const inputs *in, int w, float t, const kin_mat4 *head,
                        uint8_t *out[2], double *coverage)
{
    const int cw = in->hmd.cam_width, ch = in->hmd.cam_height;
    const int lw = in->hmd.lcd_width, lh = in->hmd.lcd_height;
    double t0 = eh_now_ms();
    pipe_frame_in fi = {0};
    for (int e = 0; e < 2; e++) {
        fuse_image full = {s->cam[e], cw, ch, 4 * cw};
        fuse_image rows = fuse_image_rows(&full, in->geo.crop_y0, in->geo.crop_height);
        fuse_frame fr = {in->yuyv[w][e], (size_t)cw * ch * 2, cw, ch, 2 * cw, FUSE_FMT_YUYV};
        fuse_frame_to_rgba(&fr, in->geo.crop_y0, &rows);
        fi.camera[e] = full;
        fi.virt[e] = (fuse_image){in->virt[w][e], lw, lh, 4 * lw};
        fi.out[e] = (fuse_image){out[e], lw, lh, 4 * lw};
        fi.virt_depth[e] = in->depth[w][e];
        fi.virt_depth_stride[e] = lw;
    }
    fi.anim = in->anim;
    fi.time = t;
    fi.head_node = head ? -1 : in->head;
    fi.world_from_head = head;
    fi.lighting = in->lighting;
    pipe_frame_stats st;
    char why[256];
    if (pipe_frame(s->p, &fi, &st, why, sizeof why) != PIPE_OK) {
        fprintf(stderr, "llvmpipe_frame: egofuse: %s\n", why);
        exit(1);
    }
    if (coverage) *coverage = 0.5 * (st.coverage[0] + st.coverage[1]);
    return eh_now_ms() - t0;
}

/* ------------------------------------------------------------- compare */

typedef struct diff {
    double sum;
    long n;
    int max;
    long px, px_big, hand_px, hand_big;
    double hand_sum;
} diff;

static void compare(diff *d, const uint8_t *a, const uint8_t *b, const uint8_t *v, int npx)
{
    for (int i = 0; i < npx; i++) {
        int m = 0, hand = 0;
        for (int k = 0; k < 3; k++) {
            int x = abs((int)a[4 * i + k] - (int)b[4 * i + k]);
            d->sum += x;
            if (x > m) m = x;
            hand |= a[4 * i + k] != v[4 * i + k] || b[4 * i + k] != v[4 * i + k];
        }
        d->n += 3;
        if (m > d->max) d->max = m;
        d->px++;
        d->px_big += m > 8;
        if (hand) {
            d->hand_px++;
            d->hand_big += m > 8;
            for (int k = 0; k < 3; k++) d->hand_sum += abs((int)a[4 * i + k] - (int)b[4 * i + k]);
        }
    }
}

static void save_rgba(const char *path, uint8_t *px, int w, int h)
{
    io_image img = {px, w, h, 4, IO_U8, (size_t)w * 4};
    io_error err;
    if (io_image_save(path, &img, &err) != IO_OK) fprintf(stderr, "llvmpipe_frame: %s\n", err.msg);
}

/* ---------------------------------------------------------------- main */

static int parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    long v = strtol(s, &end, 10);
    if (*s == 0 || *end != 0 || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

static void summary_of(double *v, int n, double *med, double *p99, double *max, double *mean)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += v[i];
    *mean = s / n;
    *med = eh_median(v, n);   /* sorts */
    *p99 = eh_p99_sorted(v, n);
    *max = v[n - 1];
}

/* One case, timed: frames stereo frames, llvmpipe and egofuse interleaved
 * frame by frame, the images cycling through the window. Typical (head
 * NULL): the sequence's poses at the window's frames, the recorded head.
 * Worst: the pose at time t_fixed, the head *head. Prints the medians and
 * the ratio, compares the outputs of up to 4 window frames, appends the
 * CSV rows. */
typedef struct run_ctx {
    gl_state *g;
    ego_state *es;
    const inputs *in;
    uint8_t *go[2], *eo[2];
    long tris;
    int threads, ego_threads, frames;
    const char *csv_path, *diff_path, *images;
} run_ctx;

static void run_case(run_ctx *c, const char *name, const kin_mat4 *head, float t_fixed)
{
    const inputs *in = c->in;
    gl_state *g = c->g;
    ego_state *es = c->es;
    const int frames = c->frames, threads = c->threads;
    const int lw = in->hmd.lcd_width, lh = in->hmd.lcd_height;
    uint8_t **go = c->go, **eo = c->eo;
    double *tg = xmalloc(sizeof(double) * frames), *te = xmalloc(sizeof(double) * frames);
    double *tp = xmalloc(sizeof(double) * frames), *ts = xmalloc(sizeof(double) * frames),
           *tf = xmalloc(sizeof(double) * frames);
    double cover_sum = 0, wall_g = 0, wall_e = 0;
    printf("%s:\n", name);
    for (int k = -3; k < frames; k++) {
        int i = k < 0 ? 0 : k, w = i % in->window;
        float t = head ? t_fixed : (float)in->frame_of[w] / in->fps;
        gl_times gt;
        double t0 = eh_now_ms();
        gl_frame(g, in, w, t, head, go, &gt);
        double t1 = eh_now_ms(), cov = 0;
        double te_k = ego_frame(es, in, w, t, head, eo, &cov);
        if (k < 0) continue;
        tg[k] = t1 - t0;
        te[k] = te_k;
        tp[k] = gt.pose;
        ts[k] = gt.submit;
        tf[k] = gt.finish;
        wall_g += tg[k];
        wall_e += te[k];
        cover_sum += cov;
    }
    if (glGetError() != GL_NO_ERROR) fprintf(stderr, "llvmpipe_frame: a GL error occurred\n");
    if (profiling)
        printf("  profile (LLVMPIPE_FRAME_PROFILE, each step finished; ms per frame incl. warm-up): "
               "uploads %.3f, pass 1 (skin + raster) %.3f, pass 2 (light) %.3f, pass 3 "
               "(composite) %.3f, read-back %.3f\n",
               prof[0] / (frames + 3), prof[1] / (frames + 3), prof[2] / (frames + 3),
               prof[3] / (frames + 3), prof[4] / (frames + 3));
    memset(prof, 0, sizeof prof);

    /* the outputs of the window's frames, compared */
    diff d;
    memset(&d, 0, sizeof d);
    int cmp_frames = in->window < 4 ? in->window : 4;
    for (int w = 0; w < cmp_frames; w++) {
        float t = head ? t_fixed : (float)in->frame_of[w] / in->fps;
        gl_frame(g, in, w, t, head, go, NULL);
        ego_frame(es, in, w, t, head, eo, NULL);
        for (int e = 0; e < 2; e++) compare(&d, go[e], eo[e], in->virt[w][e], lw * lh);
        if (c->images && w == cmp_frames - 1) {
            char path[1024];
            snprintf(path, sizeof path, "%s/%s_llvmpipe_left.png", c->images, name);
            save_rgba(path, go[0], lw, lh);
            snprintf(path, sizeof path, "%s/%s_egofuse_left.png", c->images, name);
            save_rgba(path, eo[0], lw, lh);
        }
    }

    double gm, g99, gmax, gmean, em, e99, emax, emean;
    summary_of(tg, frames, &gm, &g99, &gmax, &gmean);
    summary_of(te, frames, &em, &e99, &emax, &emean);
    double pose = eh_median(tp, frames), submit = eh_median(ts, frames),
           finish = eh_median(tf, frames);
    const double cov = cover_sum / frames;
    printf("  %-9s %7s %7s %7s %7s %6s %8s %6s\n", "impl", "median", "p99", "max", "mean", "fps",
           "headroom", "cover");
    printf("  %-9s %7.3f %7.3f %7.3f %7.3f %6.0f %8.2f %5.1f%%   (pose %.3f, uploads + draws %.3f, "
           "finish + read-back %.3f ms)\n",
           "llvmpipe", gm, g99, gmax, gmean, 1e3 * frames / wall_g, BUDGET_MS - g99, 100 * cov,
           pose, submit, finish);
    printf("  %-9s %7.3f %7.3f %7.3f %7.3f %6.0f %8.2f %5.1f%%   (same frames, pipe_frame + YUYV "
           "conversion)\n",
           "egofuse", em, e99, emax, emean, 1e3 * frames / wall_e, BUDGET_MS - e99, 100 * cov);
    printf("  llvmpipe / egofuse (median, side by side): %.1fx\n", gm / em);
    printf("  output difference over %d stereo frames: mean |d| %.3f, max %d, %.3f%% of all "
           "pixels differ by > 8;\n  on the %ld hand pixels (either differs from V): mean |d| "
           "%.2f, %.2f%% differ by > 8\n",
           cmp_frames, d.sum / (double)d.n, d.max, 100.0 * d.px_big / (double)d.px, d.hand_px,
           d.hand_px ? d.hand_sum / (3.0 * d.hand_px) : 0.0,
           d.hand_px ? 100.0 * d.hand_big / (double)d.hand_px : 0.0);
    if (c->csv_path) {
        FILE *f = fopen(c->csv_path, "a");
        if (f) {
            /* the llvmpipe row under the case's name (frame_typical,
             * frame_worst); the interleaved egofuse row as frame_anim /
             * frame_worst_anim: egofuse posed by the animation, not by the
             * tracking as in bench_frame's rows of the same case */
            fprintf(f, "frame_%s,llvmpipe,-,%d,%.4f,%.4f,%.4f,%.4f,%d,%.1f,%.3f,%.4f,0,0,%.4f,"
                       "%.4f,%.4f,%ld,%d,%d\n",
                    name, threads, gm, g99, gmax, gmean, frames, 1e3 * frames / wall_g,
                    BUDGET_MS - g99, cov, pose, submit, finish, c->tris, lw, lh);
            fprintf(f, "frame_%s,egofuse,%s,%d,%.4f,%.4f,%.4f,%.4f,%d,%.1f,%.3f,%.4f,0,0,0,0,0,"
                       "%ld,%d,%d\n",
                    head ? "worst_anim" : "anim", ef_isa_name((ef_isa)pipe_isa(es->p)),
                    c->ego_threads, em, e99, emax, emean, frames, 1e3 * frames / wall_e,
                    BUDGET_MS - e99, cov, c->tris, lw, lh);
            fclose(f);
        }
    }
    if (c->diff_path) {
        FILE *f = fopen(c->diff_path, "a");
        if (f) {
            fseek(f, 0, SEEK_END);
            if (ftell(f) == 0)
                fprintf(f, "threads,stereo_frames,mean_abs,max_abs,pct_px_gt8,hand_px,"
                           "hand_mean_abs,hand_pct_gt8,case\n");
            fprintf(f, "%d,%d,%.4f,%d,%.4f,%ld,%.4f,%.4f,%s\n", threads, cmp_frames,
                    d.sum / (double)d.n, d.max, 100.0 * d.px_big / (double)d.px, d.hand_px,
                    d.hand_px ? d.hand_sum / (3.0 * d.hand_px) : 0.0,
                    d.hand_px ? 100.0 * d.hand_big / (double)d.hand_px : 0.0, name);
            fclose(f);
        }
    }
    free(tg), free(te), free(tp), free(ts), free(tf);
}

/* The worst case's search renders egofuse alone (its coverage). */
typedef struct worst_ctx {
    ego_state *es;
    const inputs *in;
    uint8_t **eo;
    float t;
} worst_ctx;

static double worst_cover(void *ctx, const kin_mat4 *head)
{
    worst_ctx *w = ctx;
    double cov = 0;
    ego_frame(w->es, w->in, 0, w->t, head, w->eo, &cov);
    return cov;
}

int main(int argc, char **argv)
{
    const char *samples = "build/samples", *csv_path = NULL, *images = NULL, *diff_path = NULL;
    int threads = 2, frames = 100, window = 8, cases = 1;
    for (int a = 1; a < argc; a++) {
        const char *o = argv[a], *v = a + 1 < argc ? argv[a + 1] : NULL;
        int ok = 1;
        if (!strcmp(o, "--samples") && v) samples = v, a++;
        else if (!strcmp(o, "--threads") && v) ok = parse_int(v, 1, 16, &threads), a++;
        else if (!strcmp(o, "--frames") && v) ok = parse_int(v, 1, 100000, &frames), a++;
        else if (!strcmp(o, "--window") && v) ok = parse_int(v, 1, MAX_WINDOW, &window), a++;
        else if (!strcmp(o, "--csv") && v) csv_path = v, a++;
        else if (!strcmp(o, "--images") && v) images = v, a++;
        else if (!strcmp(o, "--diff-csv") && v) diff_path = v, a++;
        else if (!strcmp(o, "--case") && v) {
            cases = !strcmp(v, "typical") ? 1 : !strcmp(v, "worst") ? 2 : !strcmp(v, "both") ? 3 : 0;
            ok = cases != 0, a++;
        } else ok = 0;
        if (!ok) {
            fprintf(stderr, "llvmpipe_frame: %s%s%s: not a valid value, or not an option\n", o,
                    v ? " " : "", v ? v : "");
            fprintf(stderr, "usage: %s [--samples DIR] [--threads N] [--frames N] [--window N]\n"
                            "       [--case typical|worst|both] [--csv FILE] [--diff-csv FILE]\n"
                            "       [--images DIR]\n", argv[0]);
            return 2;
        }
    }
    setvbuf(stdout, NULL, _IOLBF, 0);
    profiling = getenv("LLVMPIPE_FRAME_PROFILE") != NULL;
    eh_gl gl;
    int rc = eh_open(&gl, threads);
    if (rc != 0) return rc;
    static inputs in;
    if (!load(&in, samples, window)) return 1;
    gl_state g;
    if (!gl_setup(&g, &in)) {
        fprintf(stderr, "llvmpipe_frame: GL setup failed (0x%x)\n", glGetError());
        eh_close(&gl);
        return 3;
    }
    pipe_desc pd = {0};
    pd.threads = threads >= 2 ? 2 : 1;
    ego_state es = {pipe_create(&pd, &in.model), {NULL, NULL}};
    if (!es.p) return 1;
    const int lw = in.hmd.lcd_width, lh = in.hmd.lcd_height;
    const size_t ob = (size_t)lw * lh * 4;
    uint8_t *go[2], *eo[2];
    for (int e = 0; e < 2; e++) {
        go[e] = xmalloc(ob);
        eo[e] = xmalloc(ob);
        es.cam[e] = xmalloc((size_t)in.hmd.cam_width * in.hmd.cam_height * 4);
    }
    long tris = 0;
    for (int i = 0; i < in.model.mesh_count; i++) tris += in.model.meshes[i].index_count / 3;
    printf("LP_NUM_THREADS=%d, egofuse %s with %d thread%s; %ld triangles, %d stereo frames "
           "preloaded, %d frames timed, interleaved\n",
           threads, ef_isa_name((ef_isa)pipe_isa(es.p)), pd.threads, pd.threads > 1 ? "s" : "",
           tris, in.window, frames);

    run_ctx rx = {&g, &es, &in, {go[0], go[1]}, {eo[0], eo[1]}, tris, threads, pd.threads, frames,
                  csv_path, diff_path, images};
    if (cases & 1) run_case(&rx, "typical", NULL, 0);
    if (cases & 2) {
        /* bench_frame's worst case (bench_worst.h), posed by the animation */
        kin_arm_rig rig;
        char why[256];
        bench_worst wc;
        const int wf = (int)(1.5f * in.fps) < in.seq_frames ? (int)(1.5f * in.fps) : 0;
        const float tw = (float)wf / in.fps;
        if (kin_arm_rig_init(&rig, &in.model, why, sizeof why) != 0) {
            fprintf(stderr, "llvmpipe_frame: the worst case needs the arm rig: %s\n", why);
            return 1;
        }
        if (bench_worst_init(&wc, &in.model, &rig, in.anim, tw) != 0) return 1;
        worst_ctx wx = {&es, &in, eo, tw};
        bench_worst_find(&wc, worst_cover, &wx);
        printf("worst case: the pose of frame %d, head %.3f m from %s (%.3f m recorded), looking "
               "at it: %.1f%% of the camera pixels covered\n",
               wf, wc.d, bench_worst_target_name[wc.target], bench_worst_d0(&wc), 100 * wc.cover);
        run_case(&rx, "worst", &wc.head, tw);
    }
    pipe_destroy(es.p);
    eh_close(&gl);
    return 0;
}
