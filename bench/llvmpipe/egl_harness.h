/* egl_harness.h - the one Mesa llvmpipe harness of bench/ (header only,
 * static): an EGL surfaceless display with an OpenGL ES 3 context on
 * llvmpipe, shader helpers and timing. Used by llvmpipe_raster.c (the
 * rasterizer's coverage agreement and speed) and llvmpipe_frame.c (the
 * whole stereo frame as a GPU pipeline would run it).
 *
 *   eh_gl gl;
 *   int rc = eh_open(&gl, 2);     // LP_NUM_THREADS=2; 0 ok, 3 no llvmpipe
 *   GLuint prog = eh_program(vs_src, fs_src);
 *   ...
 *   eh_close(&gl);
 *
 * Packages (Debian): libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri.
 * Exit status convention of the programs: 0 ok, 1 a result is out of its
 * tolerance, 2 usage, 3 llvmpipe unavailable (or a shader does not
 * compile). */
#ifndef EGOFUSE_EGL_HARNESS_H
#define EGOFUSE_EGL_HARNESS_H

#define EGL_EGLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static inline double eh_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

static inline int eh_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of n values (sorts v). */
static inline double eh_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, eh_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* 99th percentile of n sorted values. */
static inline double eh_p99_sorted(const double *v, int n)
{
    int k = (int)(0.99 * n + 0.999999) - 1;
    return v[k < 0 ? 0 : k];
}

/* Exits with status 3, the GL log printed after `what`, unless the
 * object's status (GL_COMPILE_STATUS of a shader, GL_LINK_STATUS of a
 * program) is set: one check for the shader and the program, whose
 * query and log functions have the same signatures. */
static inline void eh_check(GLuint obj, GLenum status, const char *what,
                            void (*getiv)(GLuint, GLenum, GLint *),
                            void (*getlog)(GLuint, GLsizei, GLsizei *, GLchar *))
{
    GLint ok = 0;
    getiv(obj, status, &ok);
    if (!ok) {
        char log[2048];
        getlog(obj, sizeof log, NULL, log);
        fprintf(stderr, "%s: %s\n", what, log);
        exit(3);
    }
}

/* Compiles a shader; on error prints the log and exits with status 3. */
static inline GLuint eh_compile(GLenum type, const char *src)
{
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    eh_check(s, GL_COMPILE_STATUS, "shader", glGetShaderiv, glGetShaderInfoLog);
    return s;
}

/* Links a vertex + fragment program (exit 3 on error). */
static inline GLuint eh_program(const char *vs, const char *fs)
{
    GLuint p = glCreateProgram();
    glAttachShader(p, eh_compile(GL_VERTEX_SHADER, vs));
    glAttachShader(p, eh_compile(GL_FRAGMENT_SHADER, fs));
    glLinkProgram(p);
    eh_check(p, GL_LINK_STATUS, "program", glGetProgramiv, glGetProgramInfoLog);
    return p;
}

typedef struct eh_gl {
    EGLDisplay dpy;
    EGLContext ctx;
    const char *renderer, *version;
} eh_gl;

/* Opens the surfaceless display, makes a GLES 3 context current and
 * checks that GL_RENDERER names llvmpipe. lp_threads >= 0 sets
 * LP_NUM_THREADS (llvmpipe's rasterizer threads; read when the display
 * is created), < 0 leaves the environment alone. Prints GL_RENDERER and
 * GL_VERSION. Returns 0, or 3 (with a message) when llvmpipe is not
 * there. */
static inline int eh_open(eh_gl *g, int lp_threads)
{
    memset(g, 0, sizeof *g);
    if (lp_threads >= 0) {
        char v[16];
        snprintf(v, sizeof v, "%d", lp_threads);
        setenv("LP_NUM_THREADS", v, 1);
    }
    setenv("EGL_PLATFORM", "surfaceless", 0);
    setenv("GALLIUM_DRIVER", "llvmpipe", 0);
    setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0);
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    g->dpy = get_display ? get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL)
                         : eglGetDisplay(EGL_DEFAULT_DISPLAY);
    EGLint major, minor;
    if (g->dpy == EGL_NO_DISPLAY || !eglInitialize(g->dpy, &major, &minor)) {
        fprintf(stderr, "no surfaceless EGL display\n");
        return 3;
    }
    eglBindAPI(EGL_OPENGL_ES_API);
    const EGLint cattr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_NONE};
    g->ctx = eglCreateContext(g->dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, cattr);
    if (g->ctx == EGL_NO_CONTEXT ||
        !eglMakeCurrent(g->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, g->ctx)) {
        fprintf(stderr, "cannot make a surfaceless GLES 3 context current\n");
        return 3;
    }
    g->renderer = (const char *)glGetString(GL_RENDERER);
    g->version = (const char *)glGetString(GL_VERSION);
    printf("GL_RENDERER: %s\nGL_VERSION: %s\n", g->renderer ? g->renderer : "?",
           g->version ? g->version : "?");
    if (!g->renderer || !strstr(g->renderer, "llvmpipe")) {
        fprintf(stderr, "the renderer is not llvmpipe\n");
        return 3;
    }
    return 0;
}

static inline void eh_close(eh_gl *g)
{
    if (g->dpy == EGL_NO_DISPLAY) return;
    eglMakeCurrent(g->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (g->ctx != EGL_NO_CONTEXT) eglDestroyContext(g->dpy, g->ctx);
    eglTerminate(g->dpy);
    g->dpy = EGL_NO_DISPLAY;
}

#endif
