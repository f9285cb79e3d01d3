/* io_images.h - images of the tests through src/io: two io_images
 * compared, a solid RGB image written. Header-only; include after
 * support/testutil.h, <cmocka.h> and src/io/io.h. */
#ifndef EGOFUSE_TU_IO_IMAGES_H
#define EGOFUSE_TU_IO_IMAGES_H

/* a and b: the same size, channels, type and pixels (row by row: the
 * strides may differ). */
static inline void tu_same_image(const io_image *a, const io_image *b)
{
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    assert_int_equal(a->channels, b->channels);
    assert_int_equal(a->type, b->type);
    size_t row = (size_t)a->width * (size_t)a->channels * (a->type == IO_F32 ? 4 : 1);
    for (int y = 0; y < a->height; y++)
        assert_memory_equal((const unsigned char *)a->data + (size_t)y * a->stride,
                            (const unsigned char *)b->data + (size_t)y * b->stride, row);
}

/* path := a w x h RGB 8-bit image of the colour (r, g, b), in the format
 * its name's extension says. */
static inline void tu_write_solid(const char *path, int w, int h, uint8_t r, uint8_t g, uint8_t b)
{
    io_image img;
    io_error err;
    assert_int_equal(io_image_alloc(&img, w, h, 3, IO_U8, &err), IO_OK);
    uint8_t *p = img.data;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        p[3 * i] = r;
        p[3 * i + 1] = g;
        p[3 * i + 2] = b;
    }
    assert_int_equal(io_image_save(path, &img, &err), IO_OK);
    io_image_free(&img);
}

/* The images of a one-frame scene in dir: cam_l_0.png and cam_r_0.png,
 * cw x ch of (200, 150, 120), virt_l_0.png and virt_r_0.png, lw x lh of
 * (10, 40, 90). */
static inline void tu_write_scene_images(const char *dir, int cw, int ch, int lw, int lh)
{
    static const char *const names[4] = {"cam_l_0.png", "cam_r_0.png", "virt_l_0.png",
                                         "virt_r_0.png"};
    for (int k = 0; k < 4; k++) {
        char p[1200];
        snprintf(p, sizeof p, "%s/%s", dir, names[k]);
        if (k < 2) tu_write_solid(p, cw, ch, 200, 150, 120);
        else tu_write_solid(p, lw, lh, 10, 40, 90);
    }
}

#endif
