/* io_term.c - failure messages, progress, folders and the clock of a
 * command-line program built on egofuse (io_term.h). */
#include "io_term.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io.h"

int io_term_fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("egofuse: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return IO_EXIT_FAIL;
}

int io_mkdirs(const char *path)
{
    char buf[IO_PATH_MAX];
    if (strlen(path) >= sizeof buf) return -1;
    strcpy(buf, path);
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/') continue;
        *p = 0;
        if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
    struct stat st;
    return (stat(buf, &st) == 0 && S_ISDIR(st.st_mode)) ? 0 : -1;
}

double io_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void io_progress_start(io_progress *p, int total)
{
    p->enabled = isatty(2);
    p->total = total;
    p->t0 = io_now_s();
}

void io_progress_step(io_progress *p, int done, const char *what)
{
    if (!p->enabled) return;
    double dt = io_now_s() - p->t0;
    fprintf(stderr, "\r%s %d/%d  %.1f ms/frame ", what, done, p->total,
            done > 0 ? 1000.0 * dt / done : 0.0);
    fflush(stderr);
}

void io_progress_end(io_progress *p)
{
    if (p->enabled) fputc('\n', stderr);
}
