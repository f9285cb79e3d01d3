/* io_live.c - cockpit configuration file, latency quantiles, per-frame CSV
 * log (io_live.h, docs/cockpit.md). */
#include "io_live.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ================================================ cockpit configuration */

typedef struct conf_builder {
    io_conf_args *a;
    int cap;
    const char *file;
    char dir[IO_PATH_MAX];
} conf_builder;

static int conf_push(conf_builder *b, const char *opt, int line)
{
    io_conf_args *a = b->a;
    if (a->argc == b->cap) {
        int cap = b->cap ? 2 * b->cap : 32;
        char **nv = realloc(a->argv, sizeof(char *) * (size_t)(cap + 1));
        if (!nv) return -1;
        a->argv = nv;
        char **no = realloc(a->origin, sizeof(char *) * (size_t)(cap + 1));
        if (!no) return -1;
        a->origin = no;
        b->cap = cap;
    }
    size_t on = strlen(b->file) + 16;
    char *o = malloc(on);
    char *v = strdup(opt);
    if (!o || !v) {
        free(o);
        free(v);
        return -1;
    }
    snprintf(o, on, "%s:%d", b->file, line);
    a->argv[a->argc] = v;
    a->origin[a->argc] = o;
    a->argc++;
    a->argv[a->argc] = NULL;
    a->origin[a->argc] = NULL;
    return 0;
}

/* dir + "/" + rel for a relative path (absolute paths, "-" and empty
 * values stay as they are). */
static void conf_resolve(const conf_builder *b, const char *v, char *out, size_t n)
{
    if (!*v || v[0] == '/' || !strcmp(v, "-") || !b->dir[0])
        snprintf(out, n, "%s", v);
    else
        snprintf(out, n, "%s/%s", b->dir, v);
}

/* Options whose values are paths relative to the configuration file. */
static int conf_is_path_key(const char *opt)
{
    static const char *const k[] = {"scene", "model", "calib", "stats", "out", "dump",
                                    "hmd-calibration", "hmd-calibration-left",
                                    "hmd-calibration-right", NULL};
    for (int i = 0; k[i]; i++)
        if (!strcmp(opt, k[i])) return 1;
    return 0;
}

/* A prefixed source spec ("stream:PATH", "file:PATTERN", "raw:WxH:F:PATH")
 * with a relative path: resolved. Device and other specs unchanged. */
static void conf_resolve_spec(const conf_builder *b, const char *v, char *out, size_t n)
{
    static const char *const pre[] = {"stream:", "file:", NULL};
    for (int i = 0; pre[i]; i++) {
        size_t l = strlen(pre[i]);
        if (!strncmp(v, pre[i], l)) {
            char r[IO_PATH_MAX + 64];
            conf_resolve(b, v + l, r, sizeof r);
            snprintf(out, n, "%s%s", pre[i], r);
            return;
        }
    }
    if (!strncmp(v, "raw:", 4)) {
        /* raw:WxH:FMT:PATH */
        const char *p = strchr(v + 4, ':');
        if (p) p = strchr(p + 1, ':');
        if (p) {
            char r[IO_PATH_MAX + 64];
            conf_resolve(b, p + 1, r, sizeof r);
            snprintf(out, n, "%.*s%s", (int)(p + 1 - v), v, r);
            return;
        }
    }
    snprintf(out, n, "%s", v);
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = '\0';
    return s;
}

/* The sections and the prefix they give their keys. */
static const char *section_prefix(const char *name)
{
    static const char *const map[][2] = {
        {"run", ""},         {"cameras", ""},       {"output", ""},  {"model", ""},
        {"hmd", "hmd-"},     {"natnet", "natnet-"}, {"virtual", "virt-"},
        {"tracking", "track-"}, {"gloves", "glove-"}, {NULL, NULL}};
    for (int i = 0; map[i][0]; i++)
        if (!strcmp(name, map[i][0])) return map[i][1];
    return NULL;
}

typedef struct conf_prop {
    int open, line;
    char name[64];
    char model[IO_PATH_MAX + 64], at[128], rotate[128], body[128];
} conf_prop;

static io_result prop_flush(conf_builder *b, conf_prop *p, io_error *err)
{
    if (!p->open) return IO_OK;
    p->open = 0;
    if (!p->model[0])
        return io_fail(err, IO_ERR_VALUE, "%s:%d: [prop %s] has no model", b->file, p->line,
                       p->name);
    char opt[IO_PATH_MAX + 512];
    int n = snprintf(opt, sizeof opt, "--prop=%s=%s", p->name, p->model);
    if (p->at[0] || p->rotate[0])
        n += snprintf(opt + n, sizeof opt - (size_t)n, "@%s%s%s", p->at[0] ? p->at : "0,0,0",
                      p->rotate[0] ? "," : "", p->rotate);
    if (p->body[0]) snprintf(opt + n, sizeof opt - (size_t)n, "#%s", p->body);
    if (conf_push(b, opt, p->line)) return io_fail(err, IO_ERR_NOMEM, "out of memory");
    return IO_OK;
}

static int parse_bool(const char *v, int *out)
{
    static const char *const yes[] = {"1", "yes", "true", "on", NULL};
    static const char *const no[] = {"0", "no", "false", "off", NULL};
    for (int i = 0; yes[i]; i++)
        if (!strcasecmp(v, yes[i])) return *out = 1, 1;
    for (int i = 0; no[i]; i++)
        if (!strcasecmp(v, no[i])) return *out = 0, 1;
    return 0;
}

/* Flags: options that take no value (a boolean in the file). */
static int conf_is_flag(const char *opt)
{
    static const char *const k[] = {"raw", "quiet", "dv", "loop", "hold", "allow-outside", NULL};
    for (int i = 0; k[i]; i++)
        if (!strcmp(opt, k[i])) return 1;
    return 0;
}

io_result io_conf_load(const char *path, io_conf_args *out, io_error *err)
{
    memset(out, 0, sizeof *out);
    io_result r = io_check_file(path, err);
    if (r != IO_OK) return r;
    FILE *f = fopen(path, "r");
    if (!f) return io_fail(err, IO_ERR_READ, "%s: %s", path, strerror(errno));
    conf_builder b;
    memset(&b, 0, sizeof b);
    b.a = out;
    b.file = path;
    const char *slash = strrchr(path, '/');
    if (slash) snprintf(b.dir, sizeof b.dir, "%.*s", (int)(slash - path), path);
    if (slash == path) snprintf(b.dir, sizeof b.dir, "/");
    const char *prefix = "";
    conf_prop prop;
    memset(&prop, 0, sizeof prop);
    char line[4096];
    int ln = 0;
    r = IO_OK;
    while (fgets(line, sizeof line, f)) {
        ln++;
        size_t len = strlen(line);
        if (len == sizeof line - 1 && line[len - 1] != '\n') {
            r = io_fail(err, IO_ERR_FORMAT, "%s:%d: line longer than %d characters", path, ln,
                        (int)sizeof line - 2);
            break;
        }
        /* comments: '#' or ';' outside quotes, at the start of the line or
         * after a space or tab (so "hand_l=#7" keeps its '#') */
        int inq = 0;
        for (char *c = line; *c; c++) {
            if (*c == '"') inq = !inq;
            else if (!inq && (*c == '#' || *c == ';') &&
                     (c == line || c[-1] == ' ' || c[-1] == '\t')) {
                *c = '\0';
                break;
            }
        }
        if (inq) {
            r = io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated quote", path, ln);
            break;
        }
        char *s = trim(line);
        if (!*s) continue;
        if (*s == '[') {
            char *e = strchr(s, ']');
            if (!e || *trim(e + 1)) {
                r = io_fail(err, IO_ERR_FORMAT, "%s:%d: a section is '[name]' alone on its line",
                            path, ln);
                break;
            }
            *e = '\0';
            char *name = trim(s + 1);
            if ((r = prop_flush(&b, &prop, err)) != IO_OK) break;
            if (!strncmp(name, "prop", 4) && (name[4] == ' ' || name[4] == '\t')) {
                char *pn = trim(name + 5);
                if (!*pn || strlen(pn) >= sizeof prop.name || strpbrk(pn, "=@#, ")) {
                    r = io_fail(err, IO_ERR_FORMAT,
                                "%s:%d: a prop's name is one word without '=@#,' (up to %d "
                                "characters)",
                                path, ln, (int)sizeof prop.name - 1);
                    break;
                }
                memset(&prop, 0, sizeof prop);
                prop.open = 1;
                prop.line = ln;
                snprintf(prop.name, sizeof prop.name, "%s", pn);
                continue;
            }
            prefix = section_prefix(name);
            if (!prefix) {
                r = io_fail(err, IO_ERR_FORMAT,
                            "%s:%d: unknown section [%s] (known: run, cameras, output, model, "
                            "hmd, natnet, virtual, tracking, gloves, prop NAME)",
                            path, ln, name);
                break;
            }
            continue;
        }
        char *eq = strchr(s, '=');
        if (!eq) {
            r = io_fail(err, IO_ERR_FORMAT, "%s:%d: expected 'key = value', got '%.60s'", path, ln,
                        s);
            break;
        }
        *eq = '\0';
        char *key = trim(s), *val = trim(eq + 1);
        if (!*key) {
            r = io_fail(err, IO_ERR_FORMAT, "%s:%d: a key is missing before '='", path, ln);
            break;
        }
        for (char *c = key; *c; c++) {
            if (*c == '_') *c = '-';
            if (!isalnum((unsigned char)*c) && *c != '-') {
                r = io_fail(err, IO_ERR_FORMAT, "%s:%d: key '%s': letters, digits and '-' only",
                            path, ln, key);
                goto done;
            }
            *c = (char)tolower((unsigned char)*c);
        }
        size_t vl = strlen(val);
        if (vl >= 2 && val[0] == '"' && val[vl - 1] == '"') {
            val[vl - 1] = '\0';
            val++;
        }
        if (prop.open) {
            char *dst = NULL;
            size_t dn = 0;
            if (!strcmp(key, "model")) {
                conf_resolve(&b, val, prop.model, sizeof prop.model);
                continue;
            }
            if (!strcmp(key, "at")) dst = prop.at, dn = sizeof prop.at;
            else if (!strcmp(key, "rotate")) dst = prop.rotate, dn = sizeof prop.rotate;
            else if (!strcmp(key, "body")) dst = prop.body, dn = sizeof prop.body;
            if (!dst) {
                r = io_fail(err, IO_ERR_FORMAT,
                            "%s:%d: [prop %s]: unknown key '%s' (model, at, rotate, body)", path,
                            ln, prop.name, key);
                break;
            }
            if (strlen(val) >= dn || strpbrk(val, "@#")) {
                r = io_fail(err, IO_ERR_FORMAT, "%s:%d: [prop %s] %s: '%.60s' is not a value",
                            path, ln, prop.name, key, val);
                break;
            }
            snprintf(dst, dn, "%s", val);
            continue;
        }
        char opt[128];
        snprintf(opt, sizeof opt, "%s%s", prefix, key);
        char arg[IO_PATH_MAX * 2 + 256];
        if (conf_is_flag(opt)) {
            int on;
            if (!parse_bool(val, &on)) {
                r = io_fail(err, IO_ERR_VALUE, "%s:%d: %s = '%s': yes or no", path, ln, key, val);
                break;
            }
            if (!on) continue;
            snprintf(arg, sizeof arg, "--%s", opt);
        } else {
            char v2[IO_PATH_MAX * 2 + 64];
            if (conf_is_path_key(opt)) {
                conf_resolve(&b, val, v2, sizeof v2);
            } else if (!strcmp(opt, "virt")) { /* LEFT,RIGHT */
                char *comma = strchr(val, ',');
                if (comma) {
                    *comma = '\0';
                    char l[IO_PATH_MAX + 8], rr[IO_PATH_MAX + 8];
                    conf_resolve(&b, val, l, sizeof l);
                    conf_resolve(&b, comma + 1, rr, sizeof rr);
                    snprintf(v2, sizeof v2, "%s,%s", l, rr);
                } else {
                    conf_resolve(&b, val, v2, sizeof v2);
                }
            } else if (!strcmp(opt, "virt-source") || !strcmp(opt, "left") ||
                       !strcmp(opt, "right")) {
                conf_resolve_spec(&b, val, v2, sizeof v2);
            } else {
                snprintf(v2, sizeof v2, "%s", val);
            }
            snprintf(arg, sizeof arg, "--%s=%s", opt, v2);
        }
        if (conf_push(&b, arg, ln)) {
            r = io_fail(err, IO_ERR_NOMEM, "out of memory");
            break;
        }
    }
    if (r == IO_OK && ferror(f)) r = io_fail(err, IO_ERR_READ, "%s: %s", path, strerror(errno));
    if (r == IO_OK) r = prop_flush(&b, &prop, err);
done:
    fclose(f);
    if (r != IO_OK) io_conf_free(out);
    return r;
}

void io_conf_free(io_conf_args *a)
{
    if (!a) return;
    for (int i = 0; i < a->argc; i++) {
        free(a->argv[i]);
        free(a->origin[i]);
    }
    free(a->argv);
    free(a->origin);
    memset(a, 0, sizeof *a);
}

/* ======================================================= latency figures */

void io_lat_reset(io_lat *l) { memset(l, 0, sizeof *l); }

void io_lat_push(io_lat *l, double ms)
{
    l->v[l->head] = ms;
    l->head = (l->head + 1) % IO_LAT_WINDOW;
    if (l->n < IO_LAT_WINDOW) l->n++;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double io_lat_quantile(const io_lat *l, double q)
{
    if (l->n == 0) return NAN;
    double s[IO_LAT_WINDOW];
    memcpy(s, l->v, sizeof(double) * (size_t)l->n); /* the first n slots hold the window */
    qsort(s, (size_t)l->n, sizeof(double), cmp_double);
    if (q <= 0) return s[0];
    double r = ceil(q * (double)l->n);
    int k = (int)r - 1;
    if (k < 0) k = 0;
    if (k >= l->n) k = l->n - 1;
    return s[k];
}

/* ======================================================== per-frame log */

static const char stats_header[] =
    "frame,t_cam_l_ns,t_cam_r_ns,t_dequeue_ns,t_start_ns,t_done_ns,t_present_ns,t_shown_ns,"
    "cam_to_done_ms,dequeue_to_shown_ms,cam_to_shown_ms,ms_pose,ms_raster_l,ms_raster_r,"
    "ms_fuse_l,ms_fuse_r,ms_total,v_age_ms,v_state,skew_ms,track_age_ms\n";

io_result io_stats_open(io_stats_log *s, const char *path, io_error *err)
{
    memset(s, 0, sizeof *s);
    if (strlen(path) >= sizeof s->path)
        return io_fail(err, IO_ERR_ARGS, "%.64s...: path too long", path);
    snprintf(s->path, sizeof s->path, "%s", path);
    snprintf(s->tmp, sizeof s->tmp, "%s.tmp.%ld", path, (long)getpid());
    s->f = fopen(s->tmp, "w");
    if (!s->f) return io_fail(err, IO_ERR_WRITE, "%s: %s", path, strerror(errno));
    if (fputs(stats_header, s->f) == EOF) {
        s->failed = 1;
        s->err_no = errno;
    }
    return IO_OK;
}

static double span_ms(uint64_t a, uint64_t b)
{
    if (!a || !b) return NAN;
    return 1e-6 * ((double)b - (double)a);
}

void io_stats_row(io_stats_log *s, const io_frame_log *r)
{
    if (!s->f || s->failed) return;
    uint64_t tc = r->t_cam_l > r->t_cam_r ? r->t_cam_l : r->t_cam_r;
    int n = fprintf(s->f,
                    "%llu,%llu,%llu,%llu,%llu,%llu,%llu,%llu,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,"
                    "%.3f,%.3f,%.3f,%d,%.3f,%.3f\n",
                    (unsigned long long)r->frame, (unsigned long long)r->t_cam_l,
                    (unsigned long long)r->t_cam_r, (unsigned long long)r->t_dequeue,
                    (unsigned long long)r->t_start, (unsigned long long)r->t_done,
                    (unsigned long long)r->t_present, (unsigned long long)r->t_shown,
                    span_ms(tc, r->t_done), span_ms(r->t_dequeue, r->t_shown),
                    span_ms(tc, r->t_shown), r->ms_pose, r->ms_raster[0], r->ms_raster[1],
                    r->ms_fuse[0], r->ms_fuse[1], r->ms_total, r->v_age_ms, r->v_state,
                    r->skew_ms, r->track_age_ms);
    if (n < 0) {
        s->failed = 1;
        s->err_no = errno;
    }
    s->rows++;
}

io_result io_stats_close(io_stats_log *s, io_error *err)
{
    if (!s->f) return IO_OK;
    if (fflush(s->f) != 0 && !s->failed) {
        s->failed = 1;
        s->err_no = errno;
    }
    if (fclose(s->f) != 0 && !s->failed) {
        s->failed = 1;
        s->err_no = errno;
    }
    s->f = NULL;
    if (s->failed) {
        unlink(s->tmp);
        return io_fail(err, IO_ERR_WRITE, "%s: %s (the log is not kept)", s->path,
                       strerror(s->err_no ? s->err_no : EIO));
    }
    if (rename(s->tmp, s->path) != 0) {
        int e = errno;
        unlink(s->tmp);
        return io_fail(err, IO_ERR_WRITE, "%s: %s", s->path, strerror(e));
    }
    return IO_OK;
}

void io_stats_abandon(io_stats_log *s)
{
    if (!s->f) return;
    fclose(s->f);
    s->f = NULL;
    unlink(s->tmp);
}
