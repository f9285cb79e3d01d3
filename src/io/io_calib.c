/* io_calib.c - OpenCV calibration files (cv::FileStorage YAML and XML)
 * into a kin_lens (io_calib.h). Two small readers, one per syntax, turn
 * the file's top-level entries into a flat list (key, line, scalar or
 * number list, matrix header); one interpreter takes the lens from it. */
#include "io_calib.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define CAL_MAX_ENTRIES 512
#define CAL_MAX_FILE (64u << 20)

enum { K_SCALAR = 1, K_SEQ, K_MAP, K_OTHER };

typedef struct cal_entry {
    char key[64];
    int line;
    int kind;
    int tagged;                 /* !!opencv-matrix / type_id="opencv-matrix" */
    char tag[48];               /* another tag or type_id, if any */
    const char *text;           /* scalar text, or the numbers of a sequence */
    size_t text_len;
    /* a map's members (opencv-matrix) */
    int has_rows, has_cols, has_data;
    char rows[32], cols[32], dt[16];
    const char *data;
    size_t data_len;
    int data_line;
} cal_entry;

typedef struct cal_doc {
    const char *name;
    cal_entry *e;
    int n;
} cal_doc;

static cal_entry *doc_add(cal_doc *d, const char *key, size_t klen, int line, io_error *err)
{
    if (d->n >= CAL_MAX_ENTRIES) {
        io_fail(err, IO_ERR_FORMAT, "%s:%d: more than %d top-level keys", d->name, line,
                CAL_MAX_ENTRIES);
        return NULL;
    }
    cal_entry *e = &d->e[d->n++];
    memset(e, 0, sizeof *e);
    snprintf(e->key, sizeof e->key, "%.*s", (int)(klen < 63 ? klen : 63), key);
    e->line = line;
    return e;
}

static void copy_trim(char *dst, size_t n, const char *s, size_t len)
{
    while (len && isspace((unsigned char)*s)) s++, len--;
    while (len && isspace((unsigned char)s[len - 1])) len--;
    if (len >= 2 && (s[0] == '"' || s[0] == '\'') && s[len - 1] == s[0]) s++, len -= 2;
    snprintf(dst, n, "%.*s", (int)(len < n - 1 ? len : n - 1), s);
}

/* ================================================================ YAML */

typedef struct ycur {
    const char *p, *end;
    int line;
} ycur;

/* From an opening '[' or '{' at c->p to just after its match, counting
 * lines; quoted strings skipped. */
static int y_skip_flow(ycur *c)
{
    int depth = 0;
    char q = 0;
    for (; c->p < c->end; c->p++) {
        char ch = *c->p;
        if (ch == '\n') c->line++;
        if (q) {
            if (ch == q) q = 0;
            continue;
        }
        if (ch == '"' || ch == '\'') q = ch;
        else if (ch == '[' || ch == '{') depth++;
        else if (ch == ']' || ch == '}') {
            if (--depth == 0) {
                c->p++;
                return 1;
            }
        }
    }
    return 0;
}

/* The value part of the rest of a line (up to the end of line or a
 * comment '#' after a space, outside quotes). */
static size_t y_value_len(const char *s, const char *end)
{
    size_t n = 0;
    char q = 0;
    while (s + n < end && s[n] != '\n') {
        char ch = s[n];
        if (q) {
            if (ch == q) q = 0;
        } else if (ch == '"' || ch == '\'') {
            q = ch;
        } else if (ch == '#' && (n == 0 || s[n - 1] == ' ' || s[n - 1] == '\t')) {
            break;
        }
        n++;
    }
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r')) n--;
    return n;
}

static void y_to_eol(ycur *c)
{
    while (c->p < c->end && *c->p != '\n') c->p++;
    if (c->p < c->end) {
        c->p++;
        c->line++;
    }
}

/* After a flow value: only spaces or a comment may follow on its line. */
static io_result y_after_flow(cal_doc *d, ycur *c, const char *key, io_error *err)
{
    const char *s = c->p;
    while (s < c->end && (*s == ' ' || *s == '\t' || *s == '\r')) s++;
    if (s < c->end && *s != '\n' && *s != '#')
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s: text after the closing bracket",
                       d->name, c->line, key);
    c->p = s;
    y_to_eol(c);
    return IO_OK;
}

static io_result yaml_read(cal_doc *d, const char *text, size_t len, io_error *err)
{
    ycur c = {text, text + len, 1};
    cal_entry *cur = NULL;
    int sub_indent = -1;
    if (len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3)) c.p += 3;
    while (c.p < c.end) {
        const char *ls = c.p;
        int indent = 0;
        while (c.p < c.end && (*c.p == ' ' || *c.p == '\t')) c.p++, indent++;
        if (c.p >= c.end) break;
        char ch = *c.p;
        if (ch == '\n' || ch == '\r' || ch == '#') {
            y_to_eol(&c);
            continue;
        }
        /* (the input is not NUL-terminated: compare within it) */
        int three = c.end - c.p >= 3;
        if (indent == 0 && (ch == '%' || (three && !memcmp(c.p, "---", 3)))) {
            y_to_eol(&c);
            continue;
        }
        if (indent == 0 && three && !memcmp(c.p, "...", 3)) break;
        (void)ls;
        if (indent == 0 && ch != '-') {
            /* a top-level "key: value" */
            const char *k = c.p;
            const char *colon = NULL;
            char q = 0;
            for (const char *s = c.p; s < c.end && *s != '\n'; s++) {
                if (q) {
                    if (*s == q) q = 0;
                } else if (*s == '"' || *s == '\'') {
                    q = *s;
                } else if (*s == ':' && (s + 1 >= c.end || s[1] == ' ' || s[1] == '\t' ||
                                         s[1] == '\n' || s[1] == '\r')) {
                    colon = s;
                    break;
                }
            }
            if (!colon) {
                int n = 0; /* the input is not NUL-terminated: up to the line's end */
                while (n < 40 && k + n < c.end && k[n] != '\n' && k[n] != '\r') n++;
                return io_fail(err, IO_ERR_FORMAT, "%s:%d: expected 'key: value', got '%.*s'",
                               d->name, c.line, n, k);
            }
            size_t klen = (size_t)(colon - k);
            while (klen && (k[klen - 1] == ' ' || k[klen - 1] == '\t')) klen--;
            if (klen >= 2 && (k[0] == '"' || k[0] == '\'') && k[klen - 1] == k[0]) k++, klen -= 2;
            cur = doc_add(d, k, klen, c.line, err);
            if (!cur) return err ? err->code : IO_ERR_FORMAT;
            sub_indent = -1;
            c.p = colon + 1;
            while (c.p < c.end && (*c.p == ' ' || *c.p == '\t')) c.p++;
            if (c.p < c.end && *c.p == '!') {
                const char *t = c.p;
                while (c.p < c.end && !isspace((unsigned char)*c.p)) c.p++;
                size_t tl = (size_t)(c.p - t);
                if (tl == 15 && !strncmp(t, "!!opencv-matrix", 15)) cur->tagged = 1;
                else snprintf(cur->tag, sizeof cur->tag, "%.*s", (int)(tl < 47 ? tl : 47), t);
                while (c.p < c.end && (*c.p == ' ' || *c.p == '\t')) c.p++;
            }
            size_t vl = y_value_len(c.p, c.end);
            if (vl == 0) {
                cur->kind = K_MAP; /* members (or a block sequence) follow */
                y_to_eol(&c);
            } else if (*c.p == '[') {
                cur->kind = K_SEQ;
                cur->text = c.p + 1;
                int l0 = c.line;
                const char *s0 = c.p;
                if (!y_skip_flow(&c))
                    return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s: '[' without its ']'",
                                   d->name, l0, cur->key);
                cur->text_len = (size_t)(c.p - 1 - s0 - 1);
                io_result r = y_after_flow(d, &c, cur->key, err);
                if (r != IO_OK) return r;
            } else if (*c.p == '{') {
                cur->kind = K_OTHER;
                int l0 = c.line;
                if (!y_skip_flow(&c))
                    return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s: '{' without its '}'",
                                   d->name, l0, cur->key);
                io_result r = y_after_flow(d, &c, cur->key, err);
                if (r != IO_OK) return r;
            } else {
                cur->kind = K_SCALAR;
                cur->text = c.p;
                cur->text_len = vl;
                y_to_eol(&c);
            }
            continue;
        }
        /* an indented line (or a block sequence item): a member of cur */
        if (!cur)
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: indented text before any key", d->name,
                           c.line);
        if (sub_indent < 0 && ch != '-') sub_indent = indent;
        const char *k = c.p, *colon = NULL;
        for (const char *s = c.p; s < c.end && *s != '\n'; s++) {
            if (*s == '[' || *s == '{' || *s == '"' || *s == '\'') break;
            if (*s == ':' && (s + 1 >= c.end || isspace((unsigned char)s[1]))) {
                colon = s;
                break;
            }
        }
        const char *v = colon ? colon + 1 : c.p;
        while (v < c.end && (*v == ' ' || *v == '\t')) v++;
        int member = cur->kind == K_MAP && colon && indent == sub_indent && ch != '-';
        size_t klen = colon ? (size_t)(colon - k) : 0;
        while (klen && (k[klen - 1] == ' ' || k[klen - 1] == '\t')) klen--;
        if (member && klen == 4 && !strncmp(k, "data", 4)) {
            cur->has_data = 1;
            cur->data_line = c.line;
            if (v < c.end && *v == '[') {
                c.p = v;
                int l0 = c.line;
                if (!y_skip_flow(&c))
                    return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s: data: '[' without its ']'",
                                   d->name, l0, cur->key);
                cur->data = v + 1;
                cur->data_len = (size_t)(c.p - 1 - (v + 1));
                io_result r = y_after_flow(d, &c, cur->key, err);
                if (r != IO_OK) return r;
            } else {
                /* data as a scalar (one number) */
                cur->data = v;
                cur->data_len = y_value_len(v, c.end);
                c.p = v;
                y_to_eol(&c);
            }
            continue;
        }
        if (member && ((klen == 4 && !strncmp(k, "rows", 4)) || (klen == 4 && !strncmp(k, "cols", 4)) ||
                       (klen == 2 && !strncmp(k, "dt", 2)))) {
            size_t vl = y_value_len(v, c.end);
            if (k[0] == 'r') copy_trim(cur->rows, sizeof cur->rows, v, vl), cur->has_rows = 1;
            else if (k[0] == 'c') copy_trim(cur->cols, sizeof cur->cols, v, vl), cur->has_cols = 1;
            else copy_trim(cur->dt, sizeof cur->dt, v, vl);
            c.p = v;
            y_to_eol(&c);
            continue;
        }
        /* anything else nested: skipped, flows included */
        const char *s = colon ? v : c.p;
        if (ch == '-') {
            s = c.p + 1;
            while (s < c.end && (*s == ' ' || *s == '\t')) s++;
        }
        if (s < c.end && (*s == '[' || *s == '{')) {
            c.p = s;
            int l0 = c.line;
            if (!y_skip_flow(&c))
                return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s: unclosed '%c'", d->name, l0,
                               cur->key, *s);
        }
        y_to_eol(&c);
    }
    return IO_OK;
}

/* ================================================================= XML */

typedef struct xcur {
    const char *p, *end;
    int line;
    const char *name;
} xcur;

static void x_adv(xcur *c, size_t n)
{
    for (size_t i = 0; i < n && c->p < c->end; i++, c->p++)
        if (*c->p == '\n') c->line++;
}

static int x_starts(const xcur *c, const char *s)
{
    size_t n = strlen(s);
    return (size_t)(c->end - c->p) >= n && !memcmp(c->p, s, n);
}

/* Skips whitespace, comments, the <?xml ?> declaration and <!DOCTYPE>. */
static int x_skip_misc(xcur *c)
{
    for (;;) {
        while (c->p < c->end && isspace((unsigned char)*c->p)) x_adv(c, 1);
        if (x_starts(c, "<!--")) {
            const char *e = NULL;
            for (const char *s = c->p + 4; s + 3 <= c->end; s++)
                if (!memcmp(s, "-->", 3)) {
                    e = s;
                    break;
                }
            if (!e) return 0;
            x_adv(c, (size_t)(e + 3 - c->p));
        } else if (x_starts(c, "<?") || x_starts(c, "<!")) {
            const char *e = memchr(c->p, '>', (size_t)(c->end - c->p));
            if (!e) return 0;
            x_adv(c, (size_t)(e + 1 - c->p));
        } else {
            return 1;
        }
    }
}

/* An opening tag at c->p ('<' name attrs '>' or '/>'): its name and
 * type_id. *empty for "<name/>". */
static io_result x_open_tag(xcur *c, char *name, size_t nn, char *type_id, size_t tn, int *empty,
                            io_error *err)
{
    int line = c->line;
    if (c->p >= c->end || *c->p != '<' || c->p + 1 >= c->end || c->p[1] == '/')
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: expected an element", c->name, line);
    x_adv(c, 1);
    const char *s = c->p;
    while (c->p < c->end && (isalnum((unsigned char)*c->p) || *c->p == '_' || *c->p == '-' ||
                             *c->p == '.' || *c->p == ':'))
        x_adv(c, 1);
    size_t len = (size_t)(c->p - s);
    if (len == 0)
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: expected an element name after '<'", c->name,
                       line);
    snprintf(name, nn, "%.*s", (int)(len < nn - 1 ? len : nn - 1), s);
    if (type_id) type_id[0] = '\0';
    *empty = 0;
    for (;;) {
        while (c->p < c->end && isspace((unsigned char)*c->p)) x_adv(c, 1);
        if (c->p >= c->end)
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s: the tag is not closed", c->name,
                           line, name);
        if (*c->p == '>') {
            x_adv(c, 1);
            return IO_OK;
        }
        if (x_starts(c, "/>")) {
            x_adv(c, 2);
            *empty = 1;
            return IO_OK;
        }
        const char *a = c->p;
        while (c->p < c->end && *c->p != '=' && !isspace((unsigned char)*c->p) && *c->p != '>')
            x_adv(c, 1);
        size_t al = (size_t)(c->p - a);
        while (c->p < c->end && isspace((unsigned char)*c->p)) x_adv(c, 1);
        if (c->p >= c->end || *c->p != '=')
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s>: attribute without a value", c->name,
                           line, name);
        x_adv(c, 1);
        while (c->p < c->end && isspace((unsigned char)*c->p)) x_adv(c, 1);
        if (c->p >= c->end || (*c->p != '"' && *c->p != '\''))
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s>: attribute value not quoted",
                           c->name, line, name);
        char q = *c->p;
        x_adv(c, 1);
        const char *v = c->p;
        while (c->p < c->end && *c->p != q) x_adv(c, 1);
        if (c->p >= c->end)
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s>: unterminated attribute value",
                           c->name, line, name);
        size_t vl = (size_t)(c->p - v);
        x_adv(c, 1);
        if (type_id && al == 7 && !strncmp(a, "type_id", 7))
            snprintf(type_id, tn, "%.*s", (int)(vl < tn - 1 ? vl : tn - 1), v);
    }
}

/* Text up to the next '<' (comments inside are not expected in values). */
static void x_text(xcur *c, const char **t, size_t *len)
{
    *t = c->p;
    while (c->p < c->end && *c->p != '<') x_adv(c, 1);
    *len = (size_t)(c->p - *t);
}

static io_result x_close_tag(xcur *c, const char *name, int line, io_error *err)
{
    if (!x_skip_misc(c))
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated comment", c->name, c->line);
    size_t n = strlen(name);
    if (!x_starts(c, "</") || (size_t)(c->end - c->p) < n + 3 || memcmp(c->p + 2, name, n) ||
        (c->p[2 + n] != '>' && !isspace((unsigned char)c->p[2 + n])))
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s> (opened on line %d) is not closed by </%s>",
                       c->name, c->line, name, line, name);
    const char *e = memchr(c->p, '>', (size_t)(c->end - c->p));
    if (!e)   /* "</name" and white space to the end of the file */
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: </%s> has no closing '>'", c->name, c->line,
                       name);
    x_adv(c, (size_t)(e + 1 - c->p));
    return IO_OK;
}

/* One element whose content is skipped (any depth). */
static io_result x_skip_element(xcur *c, int depth, io_error *err)
{
    char name[64];
    int empty, line = c->line;
    io_result r = x_open_tag(c, name, sizeof name, NULL, 0, &empty, err);
    if (r != IO_OK || empty) return r;
    if (depth > 64) return io_fail(err, IO_ERR_FORMAT, "%s:%d: nested too deep", c->name, line);
    for (;;) {
        const char *t;
        size_t tl;
        x_text(c, &t, &tl);
        if (!x_skip_misc(c))
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated comment", c->name, c->line);
        if (c->p >= c->end)
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s> is not closed", c->name, line, name);
        if (x_starts(c, "</")) return x_close_tag(c, name, line, err);
        if ((r = x_skip_element(c, depth + 1, err)) != IO_OK) return r;
    }
}

static io_result xml_read(cal_doc *d, const char *text, size_t len, io_error *err)
{
    xcur c = {text, text + len, 1, d->name};
    if (len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3)) c.p += 3;
    char name[64], tid[48];
    int empty;
    if (!x_skip_misc(&c))
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated comment", d->name, c.line);
    int root_line = c.line;
    io_result r = x_open_tag(&c, name, sizeof name, NULL, 0, &empty, err);
    if (r != IO_OK) return r;
    if (strcmp(name, "opencv_storage"))
        return io_fail(err, IO_ERR_FORMAT, "%s:%d: the root element is <%s>, not <opencv_storage>",
                       d->name, root_line, name);
    if (empty) return IO_OK;
    for (;;) {
        const char *t;
        size_t tl;
        x_text(&c, &t, &tl);
        if (!x_skip_misc(&c))
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated comment", d->name, c.line);
        if (c.p >= c.end)
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: <opencv_storage> is not closed", d->name,
                           root_line);
        if (x_starts(&c, "</")) return x_close_tag(&c, "opencv_storage", root_line, err);
        int line = c.line;
        r = x_open_tag(&c, name, sizeof name, tid, sizeof tid, &empty, err);
        if (r != IO_OK) return r;
        cal_entry *e = doc_add(d, name, strlen(name), line, err);
        if (!e) return err ? err->code : IO_ERR_FORMAT;
        if (!strcmp(tid, "opencv-matrix")) e->tagged = 1;
        else snprintf(e->tag, sizeof e->tag, "%s", tid);
        if (empty) {
            e->kind = K_SCALAR;
            continue;
        }
        x_text(&c, &t, &tl);
        if (!x_skip_misc(&c))
            return io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated comment", d->name, c.line);
        if (x_starts(&c, "</")) {
            /* text content: a scalar or a sequence of numbers */
            e->kind = K_SCALAR;
            e->text = t;
            e->text_len = tl;
            if ((r = x_close_tag(&c, name, line, err)) != IO_OK) return r;
            continue;
        }
        e->kind = K_MAP;
        for (;;) {
            if (!x_skip_misc(&c))
                return io_fail(err, IO_ERR_FORMAT, "%s:%d: unterminated comment", d->name, c.line);
            if (c.p >= c.end)
                return io_fail(err, IO_ERR_FORMAT, "%s:%d: <%s> is not closed", d->name, line,
                               e->key);
            if (x_starts(&c, "</")) {
                if ((r = x_close_tag(&c, e->key, line, err)) != IO_OK) return r;
                break;
            }
            const char *save = c.p;
            int save_line = c.line;
            char mn[64];
            int mempty;
            r = x_open_tag(&c, mn, sizeof mn, NULL, 0, &mempty, err);
            if (r != IO_OK) return r;
            int known = !strcmp(mn, "rows") || !strcmp(mn, "cols") || !strcmp(mn, "dt") ||
                        !strcmp(mn, "data");
            if (!known) {
                c.p = save;
                c.line = save_line;
                if ((r = x_skip_element(&c, 1, err)) != IO_OK) return r;
                x_text(&c, &t, &tl);
                continue;
            }
            const char *mt = "";
            size_t ml = 0;
            if (!mempty) {
                x_text(&c, &mt, &ml);
                if ((r = x_close_tag(&c, mn, save_line, err)) != IO_OK) return r;
            }
            if (!strcmp(mn, "rows")) copy_trim(e->rows, sizeof e->rows, mt, ml), e->has_rows = 1;
            else if (!strcmp(mn, "cols")) copy_trim(e->cols, sizeof e->cols, mt, ml), e->has_cols = 1;
            else if (!strcmp(mn, "dt")) copy_trim(e->dt, sizeof e->dt, mt, ml);
            else {
                e->has_data = 1;
                e->data = mt;
                e->data_len = ml;
                e->data_line = save_line;
            }
            x_text(&c, &t, &tl);
        }
    }
}

/* ========================================================== the lens */

static const cal_entry *find(const cal_doc *d, const char *const *keys, const char **which)
{
    for (int k = 0; keys[k]; k++)
        for (int i = 0; i < d->n; i++)
            if (!strcasecmp(d->e[i].key, keys[k])) {
                if (which) *which = keys[k];
                return &d->e[i];
            }
    return NULL;
}

/* The numbers of a list ("1., 2.e+00, 3" or space separated); the first
 * max are kept. Returns the count (all of them), or -1 with a message. */
static int parse_numbers(const cal_doc *d, const cal_entry *e, const char *s, size_t len,
                         int line, double *out, int max, io_error *err)
{
    int n = 0;
    const char *end = s + len;
    while (s < end) {
        while (s < end && (isspace((unsigned char)*s) || *s == ',')) {
            if (*s == '\n') line++;
            s++;
        }
        if (s >= end) break;
        const char *t = s;
        while (s < end && !isspace((unsigned char)*s) && *s != ',') s++;
        char tok[64];
        size_t tl = (size_t)(s - t);
        snprintf(tok, sizeof tok, "%.*s", (int)(tl < 63 ? tl : 63), t);
        char *ep;
        errno = 0;
        double v = strtod(tok, &ep);
        if (ep == tok || *ep || tl > 63) {
            io_fail(err, IO_ERR_VALUE, "%s:%d: %s: '%s' is not a number", d->name, line, e->key,
                    tok);
            return -1;
        }
        if (!isfinite(v)) {
            io_fail(err, IO_ERR_VALUE, "%s:%d: %s: '%s' is not a finite number", d->name, line,
                    e->key, tok);
            return -1;
        }
        if (n < max) out[n] = v; /* counted beyond max, not kept */
        n++;
    }
    return n;
}

static int parse_dim(const char *s, long *v)
{
    char *ep;
    errno = 0;
    long x = strtol(s, &ep, 10);
    if (ep == s || *ep || errno || x < 1 || x > 1000000) return 0;
    *v = x;
    return 1;
}

/* A matrix entry's numbers and shape; a plain sequence (allow_seq) is a
 * 1 x n row. */
static io_result read_matrix(const cal_doc *d, const cal_entry *e, int allow_seq, double *out,
                             int max, long *rows, long *cols, io_error *err)
{
    if (e->kind == K_MAP && (e->has_rows || e->has_cols || e->has_data || e->tagged)) {
        if (!e->has_rows || !e->has_cols || !e->has_data)
            return io_fail(err, IO_ERR_MISSING, "%s:%d: %s: an opencv-matrix needs rows, cols and "
                           "data (%s is missing)", d->name, e->line, e->key,
                           !e->has_rows ? "rows" : !e->has_cols ? "cols" : "data");
        if (!parse_dim(e->rows, rows))
            return io_fail(err, IO_ERR_VALUE, "%s:%d: %s: rows '%s' is not a positive integer",
                           d->name, e->line, e->key, e->rows);
        if (!parse_dim(e->cols, cols))
            return io_fail(err, IO_ERR_VALUE, "%s:%d: %s: cols '%s' is not a positive integer",
                           d->name, e->line, e->key, e->cols);
        if (e->dt[0] && strcmp(e->dt, "d") && strcmp(e->dt, "f"))
            return io_fail(err, IO_ERR_VALUE, "%s:%d: %s: dt '%s': expected d or f (a one-channel "
                           "floating-point matrix)", d->name, e->line, e->key, e->dt);
        int n = parse_numbers(d, e, e->data, e->data_len, e->data_line, out, max, err);
        if (n < 0) return err ? err->code : IO_ERR_VALUE;
        if (n != *rows * *cols)
            return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: data has %d numbers, rows x cols = %ld x "
                           "%ld needs %ld", d->name, e->data_line, e->key, n, *rows, *cols,
                           *rows * *cols);
        if (n > max)
            return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: %ld x %ld is larger than expected",
                           d->name, e->line, e->key, *rows, *cols);
        return IO_OK;
    }
    if (allow_seq && (e->kind == K_SEQ || (e->kind == K_SCALAR && e->text_len))) {
        int n = parse_numbers(d, e, e->text, e->text_len, e->line, out, max, err);
        if (n < 0) return err ? err->code : IO_ERR_VALUE;
        if (n > max)
            return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: %d numbers, more than expected", d->name,
                           e->line, e->key, n);
        *rows = 1;
        *cols = n;
        return IO_OK;
    }
    return io_fail(err, IO_ERR_FORMAT, "%s:%d: %s: not an opencv-matrix (rows, cols, dt, data)%s",
                   d->name, e->line, e->key, e->tag[0] ? " (its type is another)" : "");
}

static int scalar_int(const cal_doc *d, const cal_entry *e, long lo, long hi, long *v,
                      io_error *err)
{
    char s[64];
    if (e->kind != K_SCALAR) {
        io_fail(err, IO_ERR_VALUE, "%s:%d: %s: expected a number", d->name, e->line, e->key);
        return 0;
    }
    copy_trim(s, sizeof s, e->text ? e->text : "", e->text_len);
    char *ep;
    errno = 0;
    long x = strtol(s, &ep, 10);
    if (ep == s || *ep || errno || x < lo || x > hi) {
        io_fail(err, IO_ERR_VALUE, "%s:%d: %s: '%s' is not an integer in %ld..%ld", d->name,
                e->line, e->key, s, lo, hi);
        return 0;
    }
    *v = x;
    return 1;
}

static io_result interpret(const cal_doc *d, int camera, kin_lens *out, io_error *err)
{
    static const char *const k_single[] = {"camera_matrix", "K", "cameraMatrix", "M",
                                           "intrinsic_matrix", NULL};
    static const char *const d_single[] = {"distortion_coefficients", "D", "distCoeffs",
                                           "dist_coeffs", "distortion", NULL};
    static const char *const k_st[2][3] = {{"M1", "K1", NULL}, {"M2", "K2", NULL}};
    static const char *const d_st[2][2] = {{"D1", NULL}, {"D2", NULL}};
    const char *kname = NULL, *dname = NULL;
    const cal_entry *ke = find(d, k_single, &kname), *de = NULL;
    if (ke) {
        de = find(d, d_single, &dname);
    } else {
        int cam = camera ? 1 : 0;
        ke = find(d, k_st[cam], &kname);
        if (ke) de = find(d, d_st[cam], &dname);
    }
    if (!ke)
        return io_fail(err, IO_ERR_MISSING, "%s: no camera matrix (looked for camera_matrix, K, "
                       "cameraMatrix, M, or M%d/K%d of a stereo file)", d->name,
                       camera ? 2 : 1, camera ? 2 : 1);
    double km[9], dc[16];
    long r, c;
    io_result res = read_matrix(d, ke, 1, km, 9, &r, &c, err);
    if (res != IO_OK) return res;
    if (r * c != 9 || (ke->kind == K_MAP && (r != 3 || c != 3)))
        return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: a camera matrix is 3 x 3, not %ld x %ld",
                       d->name, ke->line, ke->key, r, c);
    if (km[3] != 0.0 || km[6] != 0.0 || km[7] != 0.0 || fabs(km[8] - 1.0) > 1e-12)
        return io_fail(err, IO_ERR_VALUE, "%s:%d: %s: not a camera matrix [fx s cx; 0 fy cy; 0 0 "
                       "1] (the last rows are %g %g %g / %g %g %g)", d->name, ke->line, ke->key,
                       km[3], km[4], km[5], km[6], km[7], km[8]);
    if (!de)
        return io_fail(err, IO_ERR_MISSING, "%s: %s is there but no distortion coefficients "
                       "(looked for %s)", d->name, ke->key,
                       strlen(kname) == 2 && isdigit((unsigned char)kname[1])
                           ? (camera ? "D2" : "D1")
                           : "distortion_coefficients, D, distCoeffs");
    res = read_matrix(d, de, 1, dc, 16, &r, &c, err);
    if (res != IO_OK) return res;
    if (r != 1 && c != 1)
        return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: distortion coefficients are 1 x N or N x 1, "
                       "not %ld x %ld", d->name, de->line, de->key, r, c);
    int nd = (int)(r * c);

    /* the model */
    int fisheye = -1;
    const char *fk[] = {"fisheye_model", NULL}, *mk[] = {"distortion_model", "model", NULL};
    const cal_entry *fe = find(d, fk, NULL), *me = find(d, mk, NULL);
    if (fe) {
        long v;
        if (!scalar_int(d, fe, 0, 1, &v, err)) return err ? err->code : IO_ERR_VALUE;
        fisheye = (int)v;
    } else if (me && me->kind == K_SCALAR) {
        char s[64];
        copy_trim(s, sizeof s, me->text ? me->text : "", me->text_len);
        if (!strcasecmp(s, "fisheye") || !strcasecmp(s, "equidistant") ||
            !strcasecmp(s, "kannala_brandt") || !strcasecmp(s, "kannala-brandt"))
            fisheye = 1;
        else if (!strcasecmp(s, "plumb_bob") || !strcasecmp(s, "rational_polynomial") ||
                 !strcasecmp(s, "radtan") || !strcasecmp(s, "brown") ||
                 !strcasecmp(s, "brown_conrady") || !strcasecmp(s, "pinhole"))
            fisheye = 0;
        else
            return io_fail(err, IO_ERR_VALUE, "%s:%d: %s: '%s' is not a lens model egofuse knows "
                           "(plumb_bob, rational_polynomial, radtan, fisheye, equidistant)",
                           d->name, me->line, me->key, s);
    }
    if (fisheye < 0) fisheye = !strcmp(kname, "K") && !strcmp(dname, "D") && nd == 4;

    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = fisheye ? KIN_LENS_FISHEYE : KIN_LENS_BROWN;
    L.fx = km[0];
    L.skew = km[1];
    L.cx = km[2];
    L.fy = km[4];
    L.cy = km[5];
    if (fisheye) {
        if (nd != 4)
            return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: a fisheye lens has 4 coefficients (k1 k2 "
                           "k3 k4), this has %d", d->name, de->line, de->key, nd);
    } else {
        if (nd == 14) {
            if (dc[12] != 0.0 || dc[13] != 0.0)
                return io_fail(err, IO_ERR_VALUE, "%s:%d: %s: the tilted-sensor model (tauX = %g, "
                               "tauY = %g) is not supported", d->name, de->line, de->key, dc[12],
                               dc[13]);
            nd = 12;
        }
        if (nd != 4 && nd != 5 && nd != 8 && nd != 12)
            return io_fail(err, IO_ERR_SIZE, "%s:%d: %s: %d coefficients; OpenCV's lens has 4, 5, "
                           "8, 12 or 14 (k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tauX tauY]]]])",
                           d->name, de->line, de->key, nd);
    }
    for (int i = 0; i < nd; i++) L.k[i] = dc[i];

    /* the size */
    const char *wk[] = {"image_width", "imageWidth", "width", NULL};
    const char *hk[] = {"image_height", "imageHeight", "height", NULL};
    const cal_entry *we = find(d, wk, NULL), *he = find(d, hk, NULL);
    if (!we != !he) {
        const cal_entry *x = we ? we : he;
        return io_fail(err, IO_ERR_MISSING, "%s:%d: %s without %s", d->name, x->line, x->key,
                       we ? "image_height" : "image_width");
    }
    if (we) {
        long w, h;
        if (!scalar_int(d, we, 1, 65535, &w, err) || !scalar_int(d, he, 1, 65535, &h, err))
            return err ? err->code : IO_ERR_VALUE;
        L.width = (int)w;
        L.height = (int)h;
    }
    char why[200];
    if (!kin_lens_check(&L, why, sizeof why))
        return io_fail(err, IO_ERR_VALUE, "%s:%d: %s / %s: %s", d->name, ke->line, ke->key,
                       de->key, why);
    *out = L;
    return IO_OK;
}

io_result io_calib_parse(const char *name, const char *text, size_t len, int camera,
                         kin_lens *out, io_error *err)
{
    if (!name) name = "(calibration)";
    if (!text || !out) return io_fail(err, IO_ERR_ARGS, "%s: no text or no output", name);
    if (memchr(text, '\0', len))
        return io_fail(err, IO_ERR_FORMAT, "%s: not a text file (a NUL byte)", name);
    cal_doc d;
    d.name = name;
    d.n = 0;
    d.e = malloc(sizeof(cal_entry) * CAL_MAX_ENTRIES);
    if (!d.e) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", name);
    size_t i = 0;
    if (len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3)) i = 3;
    while (i < len && isspace((unsigned char)text[i])) i++;
    io_result r;
    if (i >= len)
        r = io_fail(err, IO_ERR_FORMAT, "%s: empty file", name);
    else if (text[i] == '<')
        r = xml_read(&d, text, len, err);
    else
        r = yaml_read(&d, text, len, err);
    if (r == IO_OK) r = interpret(&d, camera, out, err);
    free(d.e);
    return r;
}

io_result io_calib_load(const char *path, int camera, kin_lens *out, io_error *err)
{
    if (!path || !out) return io_fail(err, IO_ERR_ARGS, "calibration: no path or no output");
    io_result r = io_check_file(path, err);
    if (r != IO_OK) return r;
    FILE *f = fopen(path, "rb");
    if (!f) return io_fail(err, IO_ERR_READ, "%s: %s", path, strerror(errno));
    char *buf = NULL;
    size_t len = 0, cap = 0;
    r = IO_OK;
    for (;;) {
        if (len + 65536 > cap) {
            if (cap >= CAL_MAX_FILE) {
                r = io_fail(err, IO_ERR_SIZE, "%s: larger than %u MiB, not a calibration file",
                            path, CAL_MAX_FILE >> 20);
                break;
            }
            size_t nc = cap ? 2 * cap : 65536 * 2;
            char *nb = realloc(buf, nc);
            if (!nb) {
                r = io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
                break;
            }
            buf = nb;
            cap = nc;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            if (ferror(f)) r = io_fail(err, IO_ERR_READ, "%s: %s", path, strerror(errno));
            break;
        }
    }
    fclose(f);
    if (r == IO_OK) r = io_calib_parse(path, buf ? buf : "", len, camera, out, err);
    free(buf);
    return r;
}
