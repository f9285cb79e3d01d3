/* llvmpipe_raster.c - the bench scene (bench_mesh.h: two arms, both eyes,
 * 640x400, depth + coverage + normals, back faces culled) rendered by Mesa
 * llvmpipe (EGL surfaceless + OpenGL ES 3) and by egofuse in the same run:
 * median times and their ratio, and the pixels where coverage differs,
 * each classified by the distance of its centre to the nearest triangle
 * edge (docs/raster.md section 10 explains the classes).
 *
 * egofuse is timed as the pipeline draws (one context per thread count,
 * workers started once: rast_context_clear of what the last frame drew +
 * rast_context_draw_jobs, both eyes, with 2 threads one eye per thread)
 * and, as an extra line, with a full rast_target_clear of both targets
 * (the figure of earlier rounds); clear and draw are also shown apart,
 * and the 2-thread dispatch of two empty jobs with the worker spinning
 * and asleep. The ratio to llvmpipe uses the better thread count of the
 * pipeline line. The pipeline's frame is checked equal (memcmp of every
 * plane) to rast_target_clear + rast_draw, which is what is compared with
 * llvmpipe.
 *
 * The EGL/GLES setup is bench/llvmpipe/egl_harness.h, shared with
 * llvmpipe_frame.c (the whole stereo frame). `make build/bench/llvmpipe_raster`
 * builds it (the Makefile links EGL and GLESv2):
 *   build/bench/llvmpipe_raster [--runs N] [--tris N,N,...]
 *
 * Exit status: 0 when llvmpipe ran and every coverage difference lies
 * within snapping distance of an edge and the pipeline's frame equals the
 * reference's, 1 otherwise (2: usage, 3: no llvmpipe). */
#include "egl_harness.h"

#include "../../src/cpu/cpu.h"
#include "../../src/raster/raster.h"
#include "../bench_mesh.h"
#include "../../src/cpu/ef_mem.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { W = 640, H = 400 };
/* A pixel centre closer than this to an edge (pixels) is "on the edge":
 * each of the two rasterizers snaps vertices to 1/256 px, which moves an
 * edge by up to sqrt(2)/512 px each. */
#define EDGE_EPS (2.0 * 1.41421356 / 512.0)

/* Distance (px) from (px, py) to segment a-b. */
static double seg_dist(double px, double py, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double ex = ax + t * dx - px, ey = ay + t * dy - py;
    return sqrt(ex * ex + ey * ey);
}

/* Smallest distance from pixel centre (x+.5, y+.5) to an edge of a
 * triangle of the mesh, after near-plane clipping (double). */
static double edge_distance(const float *clip, const uint32_t *idx, int nt, int x, int y)
{
    double px = x + 0.5, py = y + 0.5, best = 1e30;
    for (int t = 0; t < nt; t++) {
        double v[4][4], o[4][4];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 4; k++)
                v[i][k] = clip[4 * idx[3 * t + i] + k];
        int n = 0;   /* clip against z >= -w */
        for (int i = 0; i < 3; i++) {
            const double *a = v[i], *b = v[(i + 1) % 3];
            double da = a[2] + a[3], db = b[2] + b[3];
            if (da >= 0)
                memcpy(o[n++], a, sizeof o[0]);
            if ((da >= 0) != (db >= 0)) {
                double s = da / (da - db);
                for (int k = 0; k < 4; k++)
                    o[n][k] = a[k] + s * (b[k] - a[k]);
                n++;
            }
        }
        if (n < 3)
            continue;
        double sx[4], sy[4];
        for (int i = 0; i < n; i++) {
            double w = o[i][3] > 1e-12 ? o[i][3] : 1e-12;
            sx[i] = (o[i][0] / w * 0.5 + 0.5) * W;
            sy[i] = (0.5 - o[i][1] / w * 0.5) * H;
        }
        for (int i = 0; i < n; i++) {
            int j = (i + 1) % n;
            double d = seg_dist(px, py, sx[i], sy[i], sx[j], sy[j]);
            if (d < best)
                best = d;
        }
    }
    return best;
}

int main(int argc, char **argv)
{
    int runs = 101;
    int tris_list[8] = { 2000, 10000, 40000 }, ntl = 3;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--runs") && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--tris") && i + 1 < argc) {
            ntl = 0;
            for (char *s = strtok(argv[++i], ","); s && ntl < 8; s = strtok(NULL, ","))
                tris_list[ntl++] = atoi(s);
        } else {
            fprintf(stderr, "usage: %s [--runs N] [--tris N,N,...]\n", argv[0]);
            return 2;
        }
    }
    if (runs < 1)
        return 2;
    eh_gl gl;
    if (eh_open(&gl, -1) != 0)
        return 3;
    printf("egofuse ISA: %s, scene: two arms, %dx%d per eye, depth + coverage + "
           "normals, back faces culled, median of %d runs\n",
           ef_isa_name((ef_isa)rast_draw_isa()), W, H, runs);

    /* Framebuffer: RGBA8 (normal*0.5+0.5, alpha = coverage) + depth 24. */
    GLuint fbo, rb[2];
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenRenderbuffers(2, rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    glBindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, W, H);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "incomplete framebuffer\n");
        return 3;
    }
    const char *vs = "#version 300 es\n"
                     "layout(location=0) in vec4 clip; layout(location=1) in vec3 nrm;\n"
                     "out vec3 n;\n"
                     "void main() { n = nrm; gl_Position = clip; }\n";
    const char *fs = "#version 300 es\nprecision highp float;\n"
                     "in vec3 n; out vec4 o;\n"
                     "void main() { o = vec4(n * 0.5 + 0.5, 1.0); }\n";
    GLuint prog = eh_program(vs, fs);
    glUseProgram(prog);
    glViewport(0, 0, W, H);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glClearColor(0, 0, 0, 0);
    glClearDepthf(1.0f);

    int bad_total = 0;
    uint8_t *rgba = malloc((size_t)W * H * 4);
    bm_eyes eyes;
    double *tg = malloc((size_t)runs * sizeof(double)), *te = malloc((size_t)runs * sizeof(double));
    double *tc = malloc((size_t)runs * sizeof(double)), *td = malloc((size_t)runs * sizeof(double));
    if (!rgba || !bm_eyes_init(&eyes, W, H) || !tg || !te || !tc || !td)
        return 1;
    rast_target *tgt = eyes.tg;
    const float *depth = eyes.depth, *nrmp = eyes.nrm;
    const uint8_t *mask = eyes.mask;
    for (int ti = 0; ti < ntl; ti++) {
        bm_mesh m;
        if (!bm_arms(&m, tris_list[ti]))
            return 1;
        float *clip[2];
        float mvp[16];
        for (int e = 0; e < 2; e++) {
            clip[e] = malloc((size_t)m.vertex_count * 4 * sizeof(float));
            bm_eye_mvp(e, W, H, mvp);
            rast_transform_points(mvp, m.pos, m.vertex_count, clip[e]);
        }
        GLuint vbo[3], ibo;
        glGenBuffers(3, vbo);
        glGenBuffers(1, &ibo);
        for (int e = 0; e < 2; e++) {
            glBindBuffer(GL_ARRAY_BUFFER, vbo[e]);
            glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)m.vertex_count * 16, clip[e], GL_STATIC_DRAW);
        }
        glBindBuffer(GL_ARRAY_BUFFER, vbo[2]);
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)m.vertex_count * 12, m.nrm, GL_STATIC_DRAW);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, 0);
        glEnableVertexAttribArray(1);
        glEnableVertexAttribArray(0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)m.tri_count * 12, m.idx, GL_STATIC_DRAW);

        /* Timing, both eyes per run: llvmpipe clear + draw + glFinish (the
         * clip coordinates are already in buffers, as egofuse gets them). */
        for (int r = -5; r < runs; r++) {
            double t0 = eh_now_ms();
            for (int e = 0; e < 2; e++) {
                glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                glBindBuffer(GL_ARRAY_BUFFER, vbo[e]);
                glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 0, 0);
                glDrawElements(GL_TRIANGLES, m.tri_count * 3, GL_UNSIGNED_INT, 0);
                glFinish();
            }
            if (r >= 0)
                tg[r] = eh_now_ms() - t0;
        }
        /* egofuse, both eyes per run, one context per thread count (its
         * workers started once, in rast_context_create, not per call):
         *   pipe: rast_context_clear of both targets (only the tiles the
         *         previous frame drew) + rast_context_draw_jobs (with 2
         *         threads one eye per thread), as the pipeline draws;
         *   full: rast_target_clear of both targets (4.4 MB) + the same
         *         draw (the measurement of earlier rounds, kept);
         *   jobs of 0 triangles: the 2-thread dispatch alone (wake the
         *         worker, meet at the end), the worker hot (spinning) and
         *         asleep (blocked after its idle spins), to show what the
         *         second thread costs per call. */
        double best_eg = 1e30, best_full = 1e30;
        int best_th = 1, best_full_th = 1;
        for (int th = 1; th <= 2; th++) {
            rast_context_desc d = { 0, th };
            rast_context *c = rast_context_create(&d);
            if (!c)
                return 1;
            rast_mesh_desc md[2];
            for (int e = 0; e < 2; e++) {
                rast_mesh_desc m1 = { clip[e], m.vertex_count, m.nrm, 3, m.idx,
                                      m.tri_count, RAST_CULL_BACK };
                md[e] = m1;
            }
            const rast_target *tp[2] = { &tgt[0], &tgt[1] };
            const rast_mesh_desc *mp[2] = { &md[0], &md[1] };
            for (int mode = 0; mode < 2; mode++) {
                rast_context_forget(c);
                for (int r = -5; r < runs; r++) {
                    double t0 = eh_now_ms();
                    for (int e = 0; e < 2; e++) {
                        if (mode == 0)
                            rast_context_clear(c, &tgt[e]);
                        else
                            rast_target_clear(&tgt[e]);
                    }
                    double t1 = eh_now_ms();
                    rast_context_draw_jobs(c, 2, tp, mp, NULL);
                    double t2 = eh_now_ms();
                    if (r >= 0) {
                        te[r] = t2 - t0;
                        tc[r] = t1 - t0;
                        td[r] = t2 - t1;
                    }
                }
                double me = eh_median(te, runs), mc = eh_median(tc, runs),
                       md2 = eh_median(td, runs);
                if (mode == 0 && me < best_eg) {
                    best_eg = me;
                    best_th = th;
                }
                if (mode == 1 && me < best_full) {
                    best_full = me;
                    best_full_th = th;
                }
                printf("%6d tris: egofuse %d thread(s) %.4f ms both eyes (%s: clear %.4f + "
                       "draw %.4f)\n", m.tri_count, th, me,
                       mode == 0 ? "pipe, context clear + draw" : "full clear + draw", mc,
                       md2);
            }
            /* The pipe mode's last frame equals a full clear + draw. */
            {
                size_t np = (size_t)W * H;
                uint8_t *m0 = malloc(np * 2);
                float *d0 = malloc(np * 2 * sizeof(float)), *n0 = malloc(np * 6 * sizeof(float));
                if (!m0 || !d0 || !n0)
                    return 1;
                for (int e = 0; e < 2; e++)
                    rast_context_clear(c, &tgt[e]);
                rast_context_draw_jobs(c, 2, tp, mp, NULL);
                rast_context_draw_jobs(c, 2, tp, mp, NULL); /* dirty the planes twice */
                for (int e = 0; e < 2; e++)
                    rast_context_clear(c, &tgt[e]);
                rast_context_draw_jobs(c, 2, tp, mp, NULL);
                memcpy(m0, mask, np * 2);
                memcpy(d0, depth, np * 2 * sizeof(float));
                memcpy(n0, nrmp, np * 6 * sizeof(float));
                for (int e = 0; e < 2; e++)
                    rast_target_clear(&tgt[e]);
                rast_draw(&tgt[0], &md[0], NULL);
                rast_draw(&tgt[1], &md[1], NULL);
                int same = !memcmp(m0, mask, np * 2) &&
                           !memcmp(d0, depth, np * 2 * sizeof(float)) &&
                           !memcmp(n0, nrmp, np * 6 * sizeof(float));
                if (!same) {
                    printf("%6d tris: egofuse %d thread(s): context clear + draw DIFFERS from "
                           "rast_target_clear + rast_draw\n", m.tri_count, th);
                    bad_total++;
                }
                free(m0);
                free(d0);
                free(n0);
                rast_context_forget(c);
            }
            if (th == 2) {
                static const rast_target empty_t[2] = {
                    { 1, 1, NULL, 1, NULL, 1, NULL, 0, 0, NULL, 0 },
                    { 1, 1, NULL, 1, NULL, 1, NULL, 0, 0, NULL, 0 }
                };
                static uint8_t em[2];
                rast_target et[2] = { empty_t[0], empty_t[1] };
                et[0].mask = &em[0];
                et[1].mask = &em[1];
                rast_mesh_desc z = { clip[0], 0, NULL, 0, m.idx, 0, RAST_CULL_BACK };
                const rast_target *ep[2] = { &et[0], &et[1] };
                const rast_mesh_desc *zp[2] = { &z, &z };
                double hot = 0, cold = 0;
                for (int k = 0; k < 2; k++) {
                    for (int r = -5; r < runs; r++) {
                        if (k == 1) { /* let the worker block: 20 ms busy on this thread */
                            double w0 = eh_now_ms();
                            while (eh_now_ms() - w0 < 20.0)
                                ;
                        }
                        double t0 = eh_now_ms();
                        rast_context_draw_jobs(c, 2, ep, zp, NULL);
                        if (r >= 0)
                            te[r] = eh_now_ms() - t0;
                        if (k == 1 && r >= 20)
                            break;
                    }
                    if (k == 0)
                        hot = eh_median(te, runs);
                    else
                        cold = eh_median(te, runs < 21 ? runs : 21);
                }
                printf("%6d tris: egofuse 2 threads, two jobs of 0 triangles (dispatch only): "
                       "%.4f ms worker spinning, %.4f ms worker asleep\n", m.tri_count, hot,
                       cold);
            }
            rast_context_destroy(c);
        }
        double mg = eh_median(tg, runs);
        printf("%6d tris: llvmpipe %.4f ms both eyes (clear + draw + finish); "
               "llvmpipe / egofuse pipe (%d thread(s)) = %.1fx; "
               "llvmpipe / egofuse full clear (%d thread(s)) = %.1fx\n", m.tri_count, mg,
               best_th, mg / best_eg, best_full_th, mg / best_full);

        /* The planes for the comparison: a full clear + draw. */
        for (int e = 0; e < 2; e++)
            rast_target_clear(&tgt[e]);
        {
            rast_mesh_desc m0 = { clip[0], m.vertex_count, m.nrm, 3, m.idx, m.tri_count,
                                  RAST_CULL_BACK };
            rast_mesh_desc m1 = { clip[1], m.vertex_count, m.nrm, 3, m.idx, m.tri_count,
                                  RAST_CULL_BACK };
            rast_draw(&tgt[0], &m0, NULL);
            rast_draw(&tgt[1], &m1, NULL);
        }

        /* Coverage comparison per eye (the last renders of each). */
        for (int e = 0; e < 2; e++) {
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            glBindBuffer(GL_ARRAY_BUFFER, vbo[e]);
            glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 0, 0);
            glDrawElements(GL_TRIANGLES, m.tri_count * 3, GL_UNSIGNED_INT, 0);
            glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
            long both = 0, only_gl = 0, only_eg = 0, on_edge = 0, off_edge = 0;
            int maxn = 0;
            double worst = 0;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    const uint8_t *g = rgba + ((size_t)(H - 1 - y) * W + x) * 4; /* GL: bottom row first */
                    int cg = g[3] != 0, ce = tgt[e].mask[(size_t)y * W + x] != 0;
                    if (cg && ce) {
                        both++;
                        for (int k = 0; k < 3; k++) {
                            float n = tgt[e].attr[((size_t)y * W + x) * 3 + k];
                            int q = (int)lrintf((n * 0.5f + 0.5f) * 255.0f);
                            int dd = abs(q - g[k]);
                            if (dd > maxn)
                                maxn = dd;
                        }
                        continue;
                    }
                    if (cg == ce)
                        continue;
                    only_gl += cg;
                    only_eg += ce;
                    double d = edge_distance(clip[e], m.idx, m.tri_count, x, y);
                    if (d <= EDGE_EPS) {
                        on_edge++;
                    } else {
                        off_edge++;
                        if (d > worst)
                            worst = d;
                        if (off_edge <= 5)
                            printf("    eye %d pixel (%d,%d): %s only, centre %.5f px from "
                                   "the nearest edge\n", e, x, y, cg ? "llvmpipe" : "egofuse", d);
                    }
                }
            printf("%6d tris eye %d: %ld pixels covered by both, %ld llvmpipe only, %ld "
                   "egofuse only; of the %ld differences %ld lie within %.4f px of an edge, "
                   "%ld do not (farthest %.4f px); normals max diff %d/255\n",
                   m.tri_count, e, both, only_gl, only_eg, only_gl + only_eg, on_edge,
                   EDGE_EPS, off_edge, worst, maxn);
            bad_total += off_edge > 0;
        }
        glDeleteBuffers(3, vbo);
        glDeleteBuffers(1, &ibo);
        for (int e = 0; e < 2; e++)
            free(clip[e]);
        bm_free(&m);
    }
    eh_close(&gl);
    free(rgba);
    bm_eyes_free(&eyes);
    EF_FREE_ALL(tg, te, tc, td);
    return bad_total ? 1 : 0;
}
