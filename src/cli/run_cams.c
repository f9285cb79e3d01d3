/* run_cams.c - `egofuse run`: which two cameras (run.h). Split from
 * cmd_run.c: a job of its own, before the run holds anything: the
 * selectors of --left / --right (a /dev path, a USB selector matched to
 * its video node, or recorded frames), else the first two capture nodes
 * in /dev, else the message that says how to make a dry run. */
#include "run.h"

#include <stdio.h>
#include <string.h>

#include "../io/io_vsrc.h"

/* Resolves a camera selector to a /dev/videoN path. */
int run_resolve_camera(const char *sel, char *path, size_t n, io_error *err)
{
    if (!strncmp(sel, "/dev/", 5)) {
        snprintf(path, n, "%s", sel);
        return 0;
    }
    if (io_usb_selector_check(sel, err) != IO_OK) return -1;
    io_usb_dev d[64];
    int nd = 0;
    if (io_usb_list(d, 64, &nd, err) != IO_OK) return -1;
    if (nd > 64) nd = 64;
    for (int i = 0; i < nd; i++)
        if (io_usb_match(&d[i], sel)) {
            if (!d[i].video[0]) {
                io_fail(err, IO_ERR_NOT_FOUND, "%s: USB device %s (%04x:%04x) has no video node",
                        sel, d[i].port_path, d[i].vid, d[i].pid);
                return -1;
            }
            snprintf(path, n, "%s", d[i].video);
            return 0;
        }
    io_fail(err, IO_ERR_NOT_FOUND, "%s: no USB device matches ('egofuse devices' lists them)", sel);
    return -1;
}

static int no_cameras(const char *why)
{
    fprintf(stderr,
            "egofuse run: no cameras found%s%s.\n"
            "  Plug in the HMD's two cameras ('egofuse devices' lists what is seen), or\n"
            "  make a dry run from recorded camera frames or a video:\n"
            "    egofuse run --scene FILE --left file:cam_left_%%04d.png --right "
            "file:cam_right_%%04d.png\n"
            "  or composite recorded input offline:\n"
            "    egofuse render --scene FILE --out DIR   (docs/scene.md)\n"
            "    egofuse demo                            (the bundled samples)\n",
            why ? ": " : "", why ? why : "");
    return EXIT_FAIL;
}

int run_find_cameras(const run_opts *o, char path[2][IO_CAM_NAME_MAX], int *file_cams_out)
{
    io_error err;
    int file_cams = o->sel[0] && io_cam_file_selector(o->sel[0]);
    *file_cams_out = file_cams;
    if (o->sel[0]) {
        if (io_cam_file_selector(o->sel[0]) != io_cam_file_selector(o->sel[1]))
            return cli_usage_error("run", "--left and --right: both cameras or both recorded");
        for (int e = 0; e < 2; e++) {
            if (file_cams) {
                snprintf(path[e], sizeof path[e], "%s", o->sel[e]);
                continue;
            }
            if (run_resolve_camera(o->sel[e], path[e], sizeof path[e], &err) != 0)
                return no_cameras(err.msg);
        }
    } else {
        io_cam_info ci[64];
        int n = 0, k = 0;
        io_cam_list(NULL, ci, 64, &n, &err);
        for (int i = 0; i < n && i < 64 && k < 2; i++)
            if (ci[i].capture) snprintf(path[k++], sizeof path[0], "%.63s", ci[i].path);
        if (k < 2) {
            char why[128];
            snprintf(why, sizeof why, "%d video capture node%s in /dev, 2 needed", k,
                     k == 1 ? "" : "s");
            return no_cameras(why);
        }
    }
    return EXIT_OK;
}
