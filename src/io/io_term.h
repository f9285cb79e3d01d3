/* io_term.h - what a command-line program built on egofuse prints and
 * makes: a failure message with the program's name and its exit code,
 * a progress line on a terminal, folders, a monotonic clock.
 *
 * WHAT IT DOES
 *   The egofuse program's commands (src/cli) and the accuracy evaluation
 *   (src/eval) report through these, so neither room calls the other for
 *   them: the evaluation sits below the command that parses its options.
 *
 * WHAT IT DOES NOT
 *   No option parsing (src/cli/cli.h) and no io_error: a library call of
 *   src/io reports into its caller's io_error (io.h); these print.
 *
 * USAGE
 *   if (io_mkdirs(dir)) return io_term_fail("cannot create folder '%s'", dir);
 *   io_progress pr;
 *   io_progress_start(&pr, n);
 *   for (...) io_progress_step(&pr, i + 1, "frame");
 *   io_progress_end(&pr);
 */
#ifndef EGOFUSE_IO_TERM_H
#define EGOFUSE_IO_TERM_H

#ifdef __cplusplus
extern "C" {
#endif

/* Exit codes of every egofuse command. */
enum {
    IO_EXIT_OK = 0,
    IO_EXIT_FAIL = 1,    /* a bad input or a failed step: message on stderr */
    IO_EXIT_USAGE = 2    /* bad command line */
};

/* Prints "egofuse: " + message + newline to stderr; returns IO_EXIT_FAIL. */
int io_term_fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* Creates a folder and its parents (like mkdir -p). 0 on success. */
int io_mkdirs(const char *path);

/* Seconds on the monotonic clock. */
double io_now_s(void);

/* A progress line on a terminal (stderr), nothing when stderr is not one. */
typedef struct io_progress {
    int enabled;
    int total;
    double t0;
} io_progress;
void io_progress_start(io_progress *p, int total);
/* "\rWHAT DONE/TOTAL  X ms/frame " */
void io_progress_step(io_progress *p, int done, const char *what);
void io_progress_end(io_progress *p);

#ifdef __cplusplus
}
#endif

#endif
