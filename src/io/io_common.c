/* io_common.c - error helpers of the io module (see io.h, ERRORS). */
#include "io.h"

#include <stdarg.h>
#include <stdio.h>

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
