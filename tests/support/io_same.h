/* io_same.h - two io_images of the same size, channels, type and pixels
 * (row by row: strides may differ). Header-only; include after
 * support/testutil.h, <cmocka.h> and src/io/io.h. */
#ifndef EGOFUSE_TU_IO_SAME_H
#define EGOFUSE_TU_IO_SAME_H

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

#endif
