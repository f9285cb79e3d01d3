/* cli_lod.c - the --lod options (cli_lod.h). */
#include "cli_lod.h"

#include <string.h>

#include "cli.h"

int cli_lod_parse(const char *mode, int *level)
{
    if (!mode || !level) return 0;
    if (!strcmp(mode, "off")) { *level = 0; return 1; }
    if (!strcmp(mode, "auto")) { *level = PIPE_LOD_AUTO; return 1; }
    return cli_parse_int(mode, 0, PIPE_LOD_MAX - 1, level);
}

int cli_lod_parse_px(const char *s, float *px)
{
    float v;
    if (!cli_parse_float(s, &v) || !(v > 0.0f) || v > 1000.0f) return 0;
    *px = v;
    return 1;
}

int cli_lod_setup(const char *name, const kin_model *model, int level, float px, pipe_ctx *p,
                  pipe_lod *lod)
{
    memset(lod, 0, sizeof *lod);
    if (level == 0) return EXIT_OK;
    io_error err;
    if (io_lod_build(name, model, NULL, lod, &err) != IO_OK) return io_term_fail("%s", err.msg);
    if (p && pipe_set_lod(p, lod, level, px) != 0) {
        io_lod_free(lod);
        return io_term_fail("%s: the levels of detail do not fit the pipe's model", name);
    }
    return EXIT_OK;
}

const char *cli_lod_name(int level, float px, char *buf, size_t n)
{
    if (level == PIPE_LOD_AUTO) snprintf(buf, n, "auto@%gpx", (double)px);
    else if (level == 0) snprintf(buf, n, "off");
    else snprintf(buf, n, "L%d", level);
    return buf;
}
