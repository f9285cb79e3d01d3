/* cli_view.c - `--view crop|reproject` of render and run, and the check
 * of the HMD numbers the reprojection needs (docs/eyeview.md). */
#include "cli.h"

#include <math.h>

int cli_view_parse(const char *cmd, const char *arg, int *view)
{
    if (pipe_view_parse(arg, view) != 0)
        return cli_usage_error(cmd, "--view '%s': crop (the paper's crop and scale, the "
                                    "default) or reproject (to the eye by depth)", arg);
    return EXIT_OK;
}

int cli_view_check(const char *cmd, int view, int aa, const kin_sthmd_desc *hmd)
{
    if (view != PIPE_VIEW_REPROJECT) return EXIT_OK;
    if (aa)
        return cli_usage_error(cmd, "--view reproject: not with --aa %d (the eye's view takes "
                                    "no coverage samples; its edges are soft by default, "
                                    "--soft-edges)", aa);
    kin_sthmd_desc r = kin_sthmd_desc_resolved(hmd);
    float ipd = hmd->ipd_m != 0.0f ? hmd->ipd_m : r.ipd_m;
    float d = hmd->cam_offset_m != 0.0f ? hmd->cam_offset_m : r.cam_offset_m;
    if (!(ipd >= PIPE_IPD_MIN_M && ipd <= PIPE_IPD_MAX_M))
        return cli_usage_error(cmd, "--view reproject: the IPD (--hmd-ipd) %g m is outside "
                                    "%g..%g m", (double)ipd, (double)PIPE_IPD_MIN_M,
                               (double)PIPE_IPD_MAX_M);
    if (!(d >= 0.0f && d <= PIPE_CAM_OFFSET_MAX_M))
        return cli_usage_error(cmd, "--view reproject: the camera offset D "
                                    "(--hmd-camera-offset) %g m is outside 0..%g m",
                               (double)d, (double)PIPE_CAM_OFFSET_MAX_M);
    return EXIT_OK;
}

int cli_soft_edges(const char *cmd, int *soft, int aa)
{
    if (*soft == 1 && aa)
        return cli_usage_error(cmd, "--soft-edges: not with --aa (its coverage samples are "
                                    "soft edges already)");
    if (*soft < 0) *soft = !aa;
    return EXIT_OK;
}

int cli_hmd_len_parse(const char *cmd, const char *opt, const char *arg, float lo, float hi,
                      float *out)
{
    float f;
    if (!cli_parse_float(arg, &f) || !(f >= lo && f <= hi))
        return cli_usage_error(cmd, "--%s '%s': %g..%g m", opt, arg, (double)lo, (double)hi);
    *out = f;
    return EXIT_OK;
}
