/* cli_lens.c - the calibration-file options of the commands
 * (`--hmd-calibration FILE` of run and render, `--calibration FILE` of
 * mask): OpenCV calibration files into the HMD description's lenses.
 * docs/lens.md. */
#include "cli.h"

#include "../io/io_calib.h"

int cli_lens_load(const char *both, const char *left, const char *right, kin_sthmd_desc *hmd)
{
    const char *path[2] = {left ? left : both, right ? right : both};
    kin_lens L[2];
    for (int e = 0; e < 2; e++) {
        if (!path[e]) continue;
        io_error err;
        /* one file for both cameras: a stereo file's second camera for the right */
        if (io_calib_load(path[e], e, &L[e], &err) != IO_OK) return io_term_fail("%s", err.msg);
    }
    for (int e = 0; e < 2; e++) {
        if (!path[e]) continue;
        const kin_lens *l = &L[e];
        if (l->width > 0 && hmd->cam_width > 0 &&
            (long)l->width * hmd->cam_height != (long)l->height * hmd->cam_width)
            return io_term_fail("%s: calibrated for %dx%d images, the camera is %dx%d (another aspect "
                            "ratio: not the same sensor mode)",
                            path[e], l->width, l->height, hmd->cam_width, hmd->cam_height);
        if (e == 1 && path[0] && hmd->cam_width <= 0 && l->width > 0 && L[0].width > 0 &&
            (l->width != L[0].width || l->height != L[0].height))
            return io_term_fail("%s: calibrated for %dx%d images, %s for %dx%d: give the camera's size "
                            "(--hmd-camera WxH)",
                            path[1], l->width, l->height, path[0], L[0].width, L[0].height);
        hmd->lens[e] = *l;
    }
    return EXIT_OK;
}

int cli_lens_fits(const kin_sthmd_desc *hmd, char *why, size_t why_size)
{
    for (int e = 0; e < 2; e++) {
        const kin_lens *l = &hmd->lens[e];
        if (!(l->fx > 0) || l->width <= 0 || hmd->cam_width <= 0) continue;
        if ((long)l->width * hmd->cam_height != (long)l->height * hmd->cam_width) {
            snprintf(why, why_size, "the %s camera's calibration is for %dx%d images, the HMD's "
                     "camera is %dx%d (another aspect ratio)", e ? "right" : "left", l->width,
                     l->height, hmd->cam_width, hmd->cam_height);
            return 0;
        }
    }
    return 1;
}
