/* kin_util.c - helpers shared by the kin sources (kin_internal.h). */
#include "kin_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

int kin__fail(char *why, size_t n, int ret, const char *fmt, ...)
{
    if (why && n) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(why, n, fmt, ap);
        va_end(ap);
    }
    return ret;
}

void kin__put(kin__sink *k, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *dst = k->len < k->size ? k->buf + k->len : NULL;
    size_t room = k->len < k->size ? k->size - k->len : 0;
    int r = vsnprintf(dst, room, fmt, ap);
    va_end(ap);
    if (r > 0) k->len += (size_t)r;
}

int kin__parse_number(const char *tok, double *out)
{
    const char *p = tok;
    if (*p == '+' || *p == '-') p++;
    int digits = 0;
    while (*p >= '0' && *p <= '9') { p++; digits++; }
    if (*p == '.') {
        p++;
        while (*p >= '0' && *p <= '9') { p++; digits++; }
    }
    if (!digits) return -1;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-') p++;
        int ed = 0;
        while (*p >= '0' && *p <= '9') { p++; ed++; }
        if (!ed) return -1;
    }
    if (*p) return -1;
    char *end = NULL;
    double v = strtod(tok, &end);
    if (!end || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

int kin__parse_float(const char *tok, float *out)
{
    double v;
    if (kin__parse_number(tok, &v) != 0) return -1;
    if (!(fabs(v) <= 2e30)) return -2;   /* then within float range */
    const float f = (float)v;
    if (!(fabsf(f) <= 1e30f)) return -2;
    *out = f;
    return 0;
}

int kin__tokens(char *buf, char **tok, int cap)
{
    int nt = 0;
    char *p = buf;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r') p++;
        if (!*p || *p == '#') return nt;
        if (nt == cap) return -1;
        tok[nt++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r') p++;
        if (*p) *p++ = '\0';
    }
}

int kin__line_tokens(const char *line, size_t len, char *buf, char **tok, int cap,
                     const char **reason)
{
    memcpy(buf, line, len);
    buf[len] = '\0';
    if (memchr(buf, '\0', len)) {
        *reason = "NUL byte in line";
        return -1;
    }
    int nt = kin__tokens(buf, tok, cap);
    if (nt < 0) *reason = "too many fields";
    return nt;
}
