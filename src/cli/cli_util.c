/* cli_util.c - what the subcommands of the egofuse program share (cli.h):
 * messages and exit codes, strict number parsers, option tables, folders,
 * a clock and terminal progress. Calls no subcommand. */
#include "cli.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

int cli_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "egofuse %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(run 'egofuse %s --help' for the options)\n", cmd);
    va_end(ap);
    return EXIT_USAGE;
}

int cli_option_error(const char *cmd, int c, char *const *argv)
{
    if (c == ':') return cli_usage_error(cmd, "option %s needs a value", argv[optind - 1]);
    return cli_usage_error(cmd, "unknown option '%s'", argv[optind - 1]);
}

void cli_getopt_begin(void)
{
    optind = 1;
    opterr = 0;
}

int cli_getopt(const char *cmd, const char *usage, int argc, char **argv,
               const struct option *opts, int *rc)
{
    int c = getopt_long(argc, argv, "h", opts, NULL);
    if (c == -1) return 0;
    if (c == 'h') {
        fputs(usage, stdout);
        *rc = EXIT_OK;
        return -1;
    }
    if (c == '?' || c == ':') {
        *rc = cli_option_error(cmd, c, argv);
        return -1;
    }
    return c;
}

int cli_parse_int(const char *s, int lo, int hi, int *out)
{
    return io_parse_int(s, lo, hi, out);
}

int cli_parse_float(const char *s, float *out)
{
    if (!s || !*s) return 0;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || *end || !isfinite(v) || fabs(v) > 3.0e38) return 0;
    *out = (float)v;
    return 1;
}

int cli_pick(const char *s, const char *const *words)
{
    for (int i = 0; words[i]; i++)
        if (!strcmp(s, words[i])) return i;
    return -1;
}

const cli_float_opt *cli_float_opt_find(const cli_float_opt *t, int n, int id)
{
    for (int i = 0; i < n; i++)
        if (t[i].id == id) return &t[i];
    return NULL;
}

int cli_float_opt_parse(const cli_float_opt *e, const char *arg)
{
    float v;
    if (!cli_parse_float(arg, &v) || !(v >= e->lo && v <= e->hi)) return 0;
    *e->dst = v;
    return 1;
}

int cli_parse_vec3(const char *s, float out[3])
{
    if (!s) return 0;
    char buf[256];
    if (strlen(s) >= sizeof buf) return 0;
    strcpy(buf, s);
    char *parts[3];
    char *p = buf;
    for (int i = 0; i < 3; i++) {
        parts[i] = p;
        char *c = strchr(p, ',');
        if (i < 2) {
            if (!c) return 0;
            *c = 0;
            p = c + 1;
        } else if (c) {
            return 0;
        }
    }
    for (int i = 0; i < 3; i++)
        if (!cli_parse_float(parts[i], &out[i])) return 0;
    return 1;
}
