/* io_scene.c - the scene file of `egofuse render` (format: docs/scene.md).
 *
 * A strict line-based parser: the first line is "egofuse-scene 1", then
 * "key = value" lines, '#' comments and blank lines. Every error names the
 * file and the line ("scene.txt:7: unknown key 'fsp'"). Paths are stored
 * as written; io_scene_frame_path() joins them to the scene's folder and
 * expands the frame number.
 */
#include "io.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#define LINE_MAX_LEN 4096
#define MAX_LIGHTS 8

/* The keys of the format, in the order docs/scene.md lists them. */
typedef enum key_id {
    K_MODEL, K_ANIMATION, K_HEAD_NODE, K_FRAMES, K_FPS,
    K_CAMERA_LEFT, K_CAMERA_RIGHT, K_VIRTUAL_LEFT, K_VIRTUAL_RIGHT,
    K_VIRTUAL_DEPTH_LEFT, K_VIRTUAL_DEPTH_RIGHT,
    K_AMBIENT, K_LIGHT, K_KD, K_KS, K_SHININESS, K_KF, K_TONE,
    K_TRACKING, K_HMD, K_ANIM_START,
    K_COUNT
} key_id;

static const char *const key_names[K_COUNT] = {
    "model", "animation", "head_node", "frames", "fps",
    "camera_left", "camera_right", "virtual_left", "virtual_right",
    "virtual_depth_left", "virtual_depth_right",
    "ambient", "light", "kd", "ks", "shininess", "kf", "tone",
    "tracking", "hmd", "animation_start",
};

static const key_id required[] = {
    K_MODEL, K_FRAMES, K_FPS, K_CAMERA_LEFT, K_CAMERA_RIGHT,
    K_VIRTUAL_LEFT, K_VIRTUAL_RIGHT,
};

/* Where a message points: "FILE:LINE". */
typedef struct where {
    const char *path;
    int line;
    io_error *err;
} where;

static io_result bad(const where *w, io_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static io_result bad(const where *w, io_result code, const char *fmt, ...)
{
    char reason[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, sizeof reason, fmt, ap);
    va_end(ap);
    return io_fail(w->err, code, "%s:%d: %s", w->path, w->line, reason);
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1])) s[--n] = '\0';
    return s;
}

/* One finite float; the whole token must be the number. */
static io_result parse_float(const where *w, const char *key, const char *tok,
                             float *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(tok, &end);
    if (end == tok || *end != '\0')
        return bad(w, IO_ERR_FORMAT, "%s: '%s' is not a number", key, tok);
    if (errno == ERANGE || !isfinite(v) || fabs(v) > (double)FLT_MAX)
        return bad(w, IO_ERR_FORMAT, "%s: '%s' is not a finite number", key,
                   tok);
    *out = (float)v;
    return IO_OK;
}

/* Exactly n whitespace-separated floats. */
static io_result parse_floats(const where *w, const char *key, char *value,
                              float *out, int n)
{
    int got = 0;
    char *save = NULL;
    for (char *tok = strtok_r(value, " \t", &save); tok;
         tok = strtok_r(NULL, " \t", &save)) {
        if (got == n)
            return bad(w, IO_ERR_FORMAT, "%s: expected %d numbers, got more",
                       key, n);
        io_result r = parse_float(w, key, tok, &out[got]);
        if (r != IO_OK) return r;
        got++;
    }
    if (got != n)
        return bad(w, IO_ERR_FORMAT, "%s: expected %d numbers, got %d", key, n,
                   got);
    return IO_OK;
}

static io_result parse_int(const where *w, const char *key, const char *tok,
                           int *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(tok, &end, 10);
    if (end == tok || *end != '\0')
        return bad(w, IO_ERR_FORMAT, "%s: '%s' is not an integer", key, tok);
    if (errno == ERANGE || v < INT_MIN || v > INT_MAX)
        return bad(w, IO_ERR_FORMAT, "%s: '%s' is out of range", key, tok);
    *out = (int)v;
    return IO_OK;
}

/* A frame pattern: exactly one %d or %0Nd (N = 1..2 digits); "%%" is a
 * literal percent sign. */
static io_result check_pattern(const where *w, const char *key, const char *p)
{
    int conversions = 0;
    for (const char *s = p; *s; s++) {
        if (*s != '%') continue;
        s++;
        if (*s == '%') continue;
        if (*s == '0') {
            const char *d = s + 1;
            int digits = 0;
            while (isdigit((unsigned char)*d)) { d++; digits++; }
            if (digits < 1 || digits > 2 || *d != 'd')
                return bad(w, IO_ERR_FORMAT,
                           "%s: '%s': only %%d or %%0Nd (N < 100) conversions "
                           "are allowed", key, p);
            s = d;
        } else if (*s != 'd') {
            return bad(w, IO_ERR_FORMAT,
                       "%s: '%s': only %%d or %%0Nd (N < 100) conversions are "
                       "allowed", key, p);
        }
        conversions++;
    }
    if (conversions != 1)
        return bad(w, IO_ERR_FORMAT,
                   "%s: '%s' needs exactly one %%d (frame number), found %d",
                   key, p, conversions);
    return IO_OK;
}

static io_result copy_str(const where *w, const char *key, const char *v,
                          char *dst, size_t size)
{
    size_t n = strlen(v);
    if (n >= size)
        return bad(w, IO_ERR_FORMAT, "%s: value longer than %zu characters",
                   key, size - 1);
    memcpy(dst, v, n + 1);
    return IO_OK;
}

static io_result nonneg(const where *w, const char *key, const float *v, int n)
{
    for (int i = 0; i < n; i++)
        if (v[i] < 0.0f)
            return bad(w, IO_ERR_VALUE, "%s: %g must not be negative", key,
                       (double)v[i]);
    return IO_OK;
}

static io_result set_key(const where *w, key_id k, char *value, io_scene *s)
{
    const char *key = key_names[k];
    float f[6];
    io_result r = IO_OK;
    switch (k) {
    case K_MODEL: return copy_str(w, key, value, s->model, sizeof s->model);
    case K_ANIMATION:
        return copy_str(w, key, value, s->animation, sizeof s->animation);
    case K_HEAD_NODE:
        return copy_str(w, key, value, s->head_node, sizeof s->head_node);
    case K_FRAMES:
        if ((r = parse_int(w, key, value, &s->frames)) != IO_OK) return r;
        if (s->frames <= 0)
            return bad(w, IO_ERR_VALUE, "frames: %d must be > 0", s->frames);
        return IO_OK;
    case K_FPS:
        if ((r = parse_float(w, key, value, &s->fps)) != IO_OK) return r;
        if (!(s->fps > 0.0f))
            return bad(w, IO_ERR_VALUE, "fps: %g must be > 0", (double)s->fps);
        return IO_OK;
    case K_ANIM_START:
        if ((r = parse_float(w, key, value, &s->anim_start)) != IO_OK) return r;
        if (!(s->anim_start >= 0.0f && s->anim_start <= 1e6f))
            return bad(w, IO_ERR_VALUE, "animation_start: %g s must be in [0, 1e6]",
                       (double)s->anim_start);
        return IO_OK;
    case K_CAMERA_LEFT: case K_CAMERA_RIGHT:
    case K_VIRTUAL_LEFT: case K_VIRTUAL_RIGHT:
    case K_VIRTUAL_DEPTH_LEFT: case K_VIRTUAL_DEPTH_RIGHT: {
        if ((r = check_pattern(w, key, value)) != IO_OK) return r;
        char *dst = k == K_CAMERA_LEFT ? s->camera[0]
                  : k == K_CAMERA_RIGHT ? s->camera[1]
                  : k == K_VIRTUAL_LEFT ? s->virt[0]
                  : k == K_VIRTUAL_RIGHT ? s->virt[1]
                  : k == K_VIRTUAL_DEPTH_LEFT ? s->virt_depth[0]
                  : s->virt_depth[1];
        return copy_str(w, key, value, dst, IO_PATH_MAX);
    }
    case K_AMBIENT:
        if ((r = parse_floats(w, key, value, s->ambient, 3)) != IO_OK) return r;
        return nonneg(w, key, s->ambient, 3);
    case K_TONE:
        if ((r = parse_floats(w, key, value, s->tone, 3)) != IO_OK) return r;
        return nonneg(w, key, s->tone, 3);
    case K_LIGHT: {
        if (s->light_count >= MAX_LIGHTS)
            return bad(w, IO_ERR_VALUE, "light: more than %d lights",
                       MAX_LIGHTS);
        if ((r = parse_floats(w, key, value, f, 6)) != IO_OK) return r;
        double len = sqrt((double)f[0] * f[0] + (double)f[1] * f[1] +
                          (double)f[2] * f[2]);
        if (!(len > 0.0))
            return bad(w, IO_ERR_VALUE, "light: zero direction");
        if ((r = nonneg(w, "light colour", f + 3, 3)) != IO_OK) return r;
        int i = s->light_count++;
        for (int c = 0; c < 3; c++) {
            s->light_dir[i][c] = (float)(f[c] / len);
            s->light_color[i][c] = f[3 + c];
        }
        return IO_OK;
    }
    case K_KD: case K_KS: case K_SHININESS: case K_KF: {
        if ((r = parse_float(w, key, value, &f[0])) != IO_OK) return r;
        if (k == K_SHININESS && !(f[0] >= 1.0f))
            return bad(w, IO_ERR_VALUE, "shininess: %g must be >= 1",
                       (double)f[0]);
        if (k == K_KF && !(f[0] >= 0.0f && f[0] <= 1.0f))
            return bad(w, IO_ERR_VALUE, "kf: %g must be in [0, 1]",
                       (double)f[0]);
        if ((r = nonneg(w, key, f, 1)) != IO_OK) return r;
        if (k == K_KD) s->kd = f[0];
        else if (k == K_KS) s->ks = f[0];
        else if (k == K_SHININESS) s->shininess = f[0];
        else s->kf = f[0];
        return IO_OK;
    }
    case K_HMD:
        /* a named HMD (kin_sthmd_preset): the sizes of the images */
        if (kin_sthmd_preset(value, NULL) != 0) {
            char names[128] = "";
            for (int i = 0; kin_sthmd_preset_name(i); i++)
                snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s",
                         i ? ", " : "", kin_sthmd_preset_name(i));
            return bad(w, IO_ERR_VALUE, "hmd: unknown HMD '%.60s' (known: %s)", value, names);
        }
        return copy_str(w, key, value, s->hmd, sizeof s->hmd);
    case K_TRACKING:
        /* a plain path: no frame conversion (io_scene_frame_path copies
         * it unchanged, %% becoming %) */
        for (const char *c = value; *c; c++) {
            if (c[0] == '%' && c[1] == '%') { c++; continue; }
            if (c[0] == '%')
                return bad(w, IO_ERR_FORMAT, "tracking: '%s' is one file, not a frame "
                                             "pattern (write %%%% for a %%)", value);
        }
        return copy_str(w, key, value, s->tracking, sizeof s->tracking);
    case K_COUNT: break;
    }
    return bad(w, IO_ERR_FORMAT, "internal: unhandled key");
}

static int is_lighting_key(key_id k)
{
    return k == K_AMBIENT || k == K_LIGHT || k == K_KD || k == K_KS ||
           k == K_SHININESS || k == K_KF || k == K_TONE;
}

/* Lighting fields the file does not set take fuse_lighting_default(). */
static void lighting_defaults(io_scene *s, const int *seen)
{
    const fuse_lighting d = fuse_lighting_default();
    if (!seen[K_AMBIENT]) memcpy(s->ambient, d.ambient, sizeof s->ambient);
    if (!seen[K_KD]) s->kd = d.kd;
    if (!seen[K_KS]) s->ks = d.ks;
    if (!seen[K_SHININESS]) s->shininess = d.shininess;
    if (!seen[K_KF]) s->kf = d.kf;
    if (!seen[K_TONE]) memcpy(s->tone, d.tone, sizeof s->tone);
    if (!seen[K_LIGHT]) {
        s->light_count = d.light_count;
        for (int i = 0; i < d.light_count; i++) {
            memcpy(s->light_dir[i], d.lights[i].dir, sizeof s->light_dir[i]);
            memcpy(s->light_color[i], d.lights[i].color, sizeof s->light_color[i]);
        }
    }
}

fuse_lighting io_scene_lighting(const io_scene *s)
{
    fuse_lighting L = fuse_lighting_default();
    if (!s->has_lighting) return L;
    L.light_count = s->light_count < FUSE_MAX_LIGHTS ? s->light_count : FUSE_MAX_LIGHTS;
    memcpy(L.ambient, s->ambient, sizeof L.ambient);
    memcpy(L.tone, s->tone, sizeof L.tone);
    L.kd = s->kd;
    L.ks = s->ks;
    L.shininess = s->shininess;
    L.kf = s->kf;
    for (int i = 0; i < L.light_count; i++) {
        memcpy(L.lights[i].dir, s->light_dir[i], sizeof L.lights[i].dir);
        memcpy(L.lights[i].color, s->light_color[i], sizeof L.lights[i].color);
    }
    return L;
}

/* One line (without its newline) after the header. */
static io_result parse_line(const where *w, char *buf, io_scene *s,
                            int *seen, int *seen_line, int *any_lighting)
{
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    char *line = trim(buf);
    if (!*line) return IO_OK;
    char *eq = strchr(line, '=');
    if (!eq) return bad(w, IO_ERR_FORMAT, "expected 'key = value'");
    *eq = '\0';
    char *key = trim(line);
    char *value = trim(eq + 1);
    int k = -1;
    for (int i = 0; i < K_COUNT; i++)
        if (strcmp(key, key_names[i]) == 0) { k = i; break; }
    if (k < 0) return bad(w, IO_ERR_FORMAT, "unknown key '%.60s'", key);
    if (!*value) return bad(w, IO_ERR_FORMAT, "%s: empty value", key);
    if (seen[k] && k != K_LIGHT)
        return bad(w, IO_ERR_FORMAT, "duplicate key '%s' (first on line %d)",
                   key, seen_line[k]);
    io_result r = set_key(w, (key_id)k, value, s);
    if (r != IO_OK) return r;
    if (!seen[k]) seen_line[k] = w->line;
    seen[k] = 1;
    *any_lighting |= is_lighting_key((key_id)k);
    return IO_OK;
}

static io_result parse(FILE *f, const char *path, io_scene *s, io_error *err)
{
    char *buf = NULL;
    size_t cap = 0;
    ssize_t got;
    int seen[K_COUNT] = {0};
    int seen_line[K_COUNT] = {0};
    where w = {path, 0, err};
    int any_lighting = 0;
    io_result r = IO_OK;

    while (r == IO_OK && (got = getline(&buf, &cap, f)) >= 0) {
        w.line++;
        size_t n = (size_t)got;
        if (n > LINE_MAX_LEN) {
            r = bad(&w, IO_ERR_FORMAT, "line longer than %d characters",
                    LINE_MAX_LEN);
        } else if (memchr(buf, '\0', n) != NULL) {
            r = bad(&w, IO_ERR_FORMAT, "NUL byte in the line");
        } else {
            while (n > 0 && (buf[n - 1] == '\n' || buf[n - 1] == '\r'))
                buf[--n] = '\0';
            if (w.line == 1) {
                if (strcmp(buf, "egofuse-scene 1") != 0)
                    r = bad(&w, IO_ERR_FORMAT,
                            "expected the header line 'egofuse-scene 1'");
            } else {
                r = parse_line(&w, buf, s, seen, seen_line, &any_lighting);
            }
        }
    }
    free(buf);
    if (r != IO_OK) return r;
    if (ferror(f))
        return io_fail(err, IO_ERR_READ, "%s:%d: read error", path, w.line);
    if (w.line == 0)
        return io_fail(err, IO_ERR_FORMAT,
                       "%s:1: empty file (expected 'egofuse-scene 1')", path);
    for (size_t i = 0; i < sizeof required / sizeof required[0]; i++)
        if (!seen[required[i]])
            return io_fail(err, IO_ERR_MISSING,
                           "%s:%d: missing required key '%s'", path, w.line,
                           key_names[required[i]]);
    if (any_lighting) {
        s->has_lighting = 1;
        lighting_defaults(s, seen);
    }
    return IO_OK;
}

io_result io_scene_load(const char *path, io_scene *out, io_error *err)
{
    if (!out) return io_fail(err, IO_ERR_ARGS, "io_scene_load: no output");
    memset(out, 0, sizeof *out);
    if (!path || !*path) return io_fail(err, IO_ERR_ARGS, "io_scene_load: no path");

    const char *slash = strrchr(path, '/');
    if (!slash) {
        strcpy(out->dir, ".");
    } else {
        size_t n = slash == path ? 1 : (size_t)(slash - path);
        if (n >= sizeof out->dir)
            return io_fail(err, IO_ERR_ARGS, "%s: path too long", path);
        memcpy(out->dir, path, n);
        out->dir[n] = '\0';
    }

    io_result r0 = io_check_file(path, err);  /* a folder: "is a directory" */
    if (r0 != IO_OK) {
        memset(out, 0, sizeof *out);
        return r0;
    }
    FILE *f = fopen(path, "r");
    if (!f) {
        int e = errno;
        return io_fail(err, e == ENOENT || e == ENOTDIR ? IO_ERR_NOT_FOUND
                                                        : IO_ERR_READ,
                       "%s: %s", path, strerror(e));
    }
    io_result r = parse(f, path, out, err);
    fclose(f);
    if (r != IO_OK) memset(out, 0, sizeof *out);
    return r;
}

/* Appends src[0..n) to out (bounded), tracking the length. */
static void put(char *out, size_t size, size_t *len, const char *src, size_t n)
{
    if (!size) return;
    size_t room = *len < size - 1 ? size - 1 - *len : 0;
    size_t k = n < room ? n : room;
    memcpy(out + *len, src, k);
    *len += k;
    out[*len] = '\0';
}

void io_scene_frame_path(const io_scene *s, const char *pattern, int frame,
                         char *out, size_t out_size)
{
    if (!out || !out_size) return;
    out[0] = '\0';
    if (!pattern) return;
    size_t len = 0;
    if (pattern[0] != '/' && s && s->dir[0]) {
        put(out, out_size, &len, s->dir, strlen(s->dir));
        if (s->dir[strlen(s->dir) - 1] != '/') put(out, out_size, &len, "/", 1);
    }
    for (const char *p = pattern; *p; p++) {
        if (*p != '%') { put(out, out_size, &len, p, 1); continue; }
        if (p[1] == '%') { put(out, out_size, &len, "%", 1); p++; continue; }
        const char *q = p + 1;
        int width = 0;
        if (*q == '0') {
            q++;
            int digits = 0;
            while (isdigit((unsigned char)*q) && digits < 2) {
                width = width * 10 + (*q - '0');
                q++;
                digits++;
            }
            if (digits == 0) width = -1;
        }
        if (*q == 'd' && width >= 0) {
            char num[32];
            int n = snprintf(num, sizeof num, "%0*d", width, frame);
            put(out, out_size, &len, num, (size_t)n);
            p = q;
        } else {
            put(out, out_size, &len, p, 1);  /* not a conversion: literal */
        }
    }
}
