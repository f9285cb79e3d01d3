/* display_pattern.h - the test image of the KMS display test, shared by
 * the guest (tests/vm/vm_display.c presents it) and the host
 * (tests/test_vm.c compares qemu's screendump with it). The eyes are
 * smaller than the mode on purpose: io_display centres each eye in its
 * half of the panel on black (docs/devices.md, Displays). */
#ifndef EGOFUSE_VM_DISPLAY_PATTERN_H
#define EGOFUSE_VM_DISPLAY_PATTERN_H

#include <stdint.h>
#include <string.h>

#define VMD_EYE_W 500
#define VMD_EYE_H 380

/* RGBA of eye e at (x, y) of frame f */
static inline void vmd_pixel(int e, int x, int y, int f, uint8_t px[4])
{
    px[0] = (uint8_t)(x * 3 + e * 128 + f * 17);
    px[1] = (uint8_t)(y * 5 + (x >> 4) * 9);
    px[2] = (uint8_t)((x ^ (y << 1)) + e * 64 + 1);
    px[3] = 255;
}

/* The RGB image a w x h side-by-side panel shows for frame f. */
static inline void vmd_expected(int w, int h, int f, uint8_t *rgb)
{
    memset(rgb, 0, (size_t)w * h * 3);
    int half = w / 2;
    for (int e = 0; e < 2; e++) {
        int x0 = e * half + (half - VMD_EYE_W) / 2, y0 = (h - VMD_EYE_H) / 2;
        for (int y = 0; y < VMD_EYE_H; y++)
            for (int x = 0; x < VMD_EYE_W; x++) {
                uint8_t px[4];
                vmd_pixel(e, x, y, f, px);
                memcpy(rgb + ((size_t)(y0 + y) * w + (size_t)(x0 + x)) * 3, px, 3);
            }
    }
}

/* The RGB image the w x h panel of eye e shows for frame f (layout two). */
static inline void vmd_expected_eye(int w, int h, int e, int f, uint8_t *rgb)
{
    memset(rgb, 0, (size_t)w * h * 3);
    int x0 = (w - VMD_EYE_W) / 2, y0 = (h - VMD_EYE_H) / 2;
    for (int y = 0; y < VMD_EYE_H; y++)
        for (int x = 0; x < VMD_EYE_W; x++) {
            uint8_t px[4];
            vmd_pixel(e, x, y, f, px);
            memcpy(rgb + ((size_t)(y0 + y) * w + (size_t)(x0 + x)) * 3, px, 3);
        }
}

#endif
