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
