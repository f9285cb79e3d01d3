/* kin_util.c - helpers shared by the kin sources (kin_internal.h). */
#include "kin_internal.h"

#include <stdarg.h>
#include <stdio.h>

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
