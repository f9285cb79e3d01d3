/* io_common.c - error helpers of the io module (see io.h, ERRORS). */
#include "io.h"
#include "io_dev.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

const char *io_result_str(io_result r)
{
    static const char *const text[IO_RESULT_COUNT] = {
#define IO__TEXT(name, str) str,
        IO_RESULT_LIST(IO__TEXT)
#undef IO__TEXT
    };
    if ((int)r < 0 || (int)r >= IO_RESULT_COUNT) return "unknown io result";
    return text[r];
}

io_result io_fail(io_error *err, io_result code, const char *fmt, ...)
{
    if (err) {
        err->code = code;
        err->msg[0] = '\0';
        if (fmt) {
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(err->msg, sizeof err->msg, fmt, ap);
            va_end(ap);
        }
    }
    return code;
}

uint64_t io_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

int io_parse_int(const char *s, int lo, int hi, int *out)
{
    if (!s || !*s) return 0;
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || v < lo || v > hi) return 0;
    *out = (int)v;
    return 1;
}

io_result io_check_file(const char *path, io_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        int e = errno;
        return io_fail(err, e == ENOENT || e == ENOTDIR ? IO_ERR_NOT_FOUND
                                                        : IO_ERR_READ,
                       "%s: %s", path, strerror(e));
    }
    if (S_ISDIR(st.st_mode))
        return io_fail(err, IO_ERR_READ, "%s: is a directory", path);
    return IO_OK;
}

void io__status(char *dst, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(dst, n, fmt, ap);
    va_end(ap);
}
