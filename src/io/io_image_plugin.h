/* io_image_plugin.h - between io_image.c and the OpenImageIO plugin
 * (build/libegofuse_oiio.so, built from io_image_oiio.cpp + io_common.c +
 * io_image_mem.c). Private to src/io.
 *
 * io_image.c loads the plugin with dlopen() the first time an image is not
 * PNG or binary PPM/PGM (docs/io.md, Images), and looks up one symbol,
 * egofuse_oiio_plugin, which returns the table below. The ABI number
 * changes whenever the table or io_image changes. */
#ifndef EGOFUSE_IO_IMAGE_PLUGIN_H
#define EGOFUSE_IO_IMAGE_PLUGIN_H

#include <stdio.h>
#include "io.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IO_OIIO_PLUGIN_ABI 1
#define IO_OIIO_PLUGIN_NAME "libegofuse_oiio.so"
#define IO_OIIO_PLUGIN_SYMBOL "egofuse_oiio_plugin"

typedef struct io_oiio_plugin {
    int abi;  /* IO_OIIO_PLUGIN_ABI */
    /* io_image_load() for any format OpenImageIO reads (arguments checked
     * by the caller, *out zeroed). */
    io_result (*load)(const char *path, io_type type, int channels,
                      io_image *out, io_error *err);
    /* Encodes img in the format of path's extension and writes the bytes
     * to f (an io_out stream: the caller checks and commits), or, for a
     * format OpenImageIO cannot write to memory, to the file open on fd
     * (through /proc/self/fd), reading it back to check it is whole. */
    io_result (*save)(const char *path, FILE *f, int fd, const io_image *img,
                      io_error *err);
} io_oiio_plugin;

typedef const io_oiio_plugin *(*io_oiio_plugin_fn)(void);

#ifdef __cplusplus
}
#endif
#endif
