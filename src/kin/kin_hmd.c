/* kin_hmd.c - named HMD descriptions (kin_sthmd_preset): the paper's STHMD
 * and two see-through headsets of today's classes, so that the tests, the
 * benchmarks, the sample generator and the cockpit configuration use one
 * set of numbers (docs/kin.md, "Named HMDs").
 *
 * The modern ones are illustrative, not a product's data sheet: the pixel
 * sizes are those of current headsets (2064x2208 per eye with 1280x1024
 * cameras; 2880x2720 per eye with 1920x1080 cameras), the FOVs, the camera
 * baseline and the offset D plausible values for that class. Each display
 * FOV has square pixels: tan(vfov/2) / tan(hfov/2) = lcd_h / lcd_w to
 * within a tenth of a degree (96 x 100 and 100 x 97 deg). */
#include "kin.h"

#include <math.h>
#include <string.h>

typedef struct hmd_preset {
    const char *name;
    kin_sthmd_desc d;
} hmd_preset;

static const hmd_preset presets[] = {
    /* the paper: every field its default (kin_sthmd_desc_resolved) */
    {"paper",
     {.cam_width = 640, .cam_height = 480, .cam_hfov_deg = 62.0f, .baseline_m = 0.065f,
      .cam_offset_m = 0.085f, .lcd_width = 1280, .lcd_height = 800, .hmd_hfov_deg = 61.0f,
      .hmd_vfov_deg = 40.0f, .focal_m = 1.0f, .znear = 0.01f, .zfar = 100.0f, .ipd_m = 0.065f}},
    /* a consumer headset: 2064x2208 per eye (taller than wide), 1280x1024
     * cameras of 100 deg, 64 mm apart, 70 mm in front of the eyes */
    {"consumer",
     {.cam_width = 1280, .cam_height = 1024, .cam_hfov_deg = 100.0f, .baseline_m = 0.064f,
      .cam_offset_m = 0.07f, .lcd_width = 2064, .lcd_height = 2208, .hmd_hfov_deg = 96.0f,
      .hmd_vfov_deg = 100.0f, .focal_m = 1.0f, .znear = 0.01f, .zfar = 100.0f, .ipd_m = 0.064f}},
    /* a high-end headset: 2880x2720 per eye, 1920x1080 cameras of
     * 110 deg, 64 mm apart, 80 mm in front of the eyes */
    {"highend",
     {.cam_width = 1920, .cam_height = 1080, .cam_hfov_deg = 110.0f, .baseline_m = 0.064f,
      .cam_offset_m = 0.08f, .lcd_width = 2880, .lcd_height = 2720, .hmd_hfov_deg = 100.0f,
      .hmd_vfov_deg = 97.0f, .focal_m = 1.0f, .znear = 0.01f, .zfar = 100.0f, .ipd_m = 0.064f}},
};

int kin_sthmd_preset(const char *name, kin_sthmd_desc *out)
{
    if (!name) return -1;
    for (size_t i = 0; i < sizeof presets / sizeof presets[0]; i++)
        if (!strcmp(name, presets[i].name)) {
            if (out) *out = presets[i].d;
            return 0;
        }
    return -1;
}

const char *kin_sthmd_preset_name(int i)
{
    if (i < 0 || (size_t)i >= sizeof presets / sizeof presets[0]) return NULL;
    return presets[i].name;
}

kin_camera kin_sthmd_eye_camera(const kin_sthmd_desc *desc, const kin_mat4 *world_from_head,
                                kin_eye eye, int width, int height)
{
    kin_sthmd_desc r = kin_sthmd_desc_resolved(desc);
    kin_camera c;
    memset(&c, 0, sizeof c);
    c.world_from_cam = kin_sthmd_eye(&r, world_from_head, eye);
    if (!kin_mat4_inverse(&c.world_from_cam, &c.view)) {
        /* a singular head matrix: the eye at its place with an identity head */
        c.world_from_cam = kin_sthmd_eye(&r, NULL, eye);
        kin_mat4_inverse(&c.world_from_cam, &c.view);
    }
    c.width = width > 0 ? width : r.lcd_width;
    c.height = height > 0 ? height : r.lcd_height;
    const double d2r = 0.017453292519943295;
    double fx = 0.5 * c.width / tan(0.5 * r.hmd_hfov_deg * d2r);
    double fy = 0.5 * c.height / tan(0.5 * r.hmd_vfov_deg * d2r);
    c.fx = (float)fx;
    c.fy = (float)fy;
    c.cx = 0.5f * (float)c.width;
    c.cy = 0.5f * (float)c.height;
    c.proj = kin_proj_from_intrinsics(fx, fy, c.cx, c.cy, 0.0, c.width, c.height, r.znear, r.zfar);
    c.view_proj = kin_mat4_mul(&c.proj, &c.view);
    c.lens.model = KIN_LENS_PINHOLE;
    c.lens.width = c.width;
    c.lens.height = c.height;
    c.lens.fx = fx;
    c.lens.fy = fy;
    c.lens.cx = c.cx - 0.5;
    c.lens.cy = c.cy - 0.5;
    kin_lens_check(&c.lens, NULL, 0);
    return c;
}
