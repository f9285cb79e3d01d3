/* io_image_mem.c - io_image_alloc / io_image_free (see io.h, images).
 * Shared by the io library and the OpenImageIO plugin. */
#include "io.h"

#include <stdlib.h>
#include <string.h>

io_result io_image_alloc(io_image *img, int width, int height, int channels,
                         io_type type, io_error *err)
{
    if (!img) return io_fail(err, IO_ERR_ARGS, "io_image_alloc: no image");
    memset(img, 0, sizeof *img);
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 ||
        (type != IO_U8 && type != IO_F32))
        return io_fail(err, IO_ERR_ARGS,
                       "io_image_alloc: bad size %d x %d x %d or type %d",
                       width, height, channels, (int)type);
    size_t stride = (size_t)width * (size_t)channels * (type == IO_F32 ? sizeof(float) : 1);
    if ((size_t)height > (size_t)-1 / stride || width > (1 << 20) ||
        height > (1 << 20))
        return io_fail(err, IO_ERR_SIZE, "io_image_alloc: %d x %d is too large",
                       width, height);
    void *p = calloc((size_t)height, stride);
    if (!p)
        return io_fail(err, IO_ERR_NOMEM, "io_image_alloc: out of memory "
                       "(%d x %d x %d)", width, height, channels);
    img->data = p;
    img->width = width;
    img->height = height;
    img->channels = channels;
    img->type = type;
    img->stride = stride;
    return IO_OK;
}

void io_image_free(io_image *img)
{
    if (!img) return;
    free(img->data);
    memset(img, 0, sizeof *img);
}
