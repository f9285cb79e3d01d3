/* io_image_oiio.cpp - image files through OpenImageIO (see io.h, images).
 *
 * The only C++ of the image side. Every OpenImageIO call sits inside a
 * try/catch, and its messages are copied into the caller's io_error, so no
 * exception or C++ type leaves this file.
 *
 * CHANNEL ADAPTATION (io_image_load with channels != 0)
 *   The file's channels split into colour (up to 3, in file order, skipping
 *   the alpha channel OpenImageIO reports) and alpha. The output has alpha
 *   when it has 2 or 4 channels (grey+alpha, RGBA); its colour channels are
 *   the file's colour channels in order, a single grey channel replicated,
 *   extra ones dropped (RGB -> 1 channel keeps R); a missing alpha is opaque
 *   (255 or 1.0f).
 *
 * ALPHA
 *   Pixels go through exactly as stored: alpha is never premultiplied on
 *   load nor divided out on save ("oiio:UnassociatedAlpha"), so an 8-bit
 *   RGBA PNG round-trips bit for bit.
 */
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

extern "C" {
#include "io.h"
}

namespace {

size_t type_size(io_type t) { return t == IO_F32 ? sizeof(float) : 1; }

OIIO::TypeDesc oiio_type(io_type t)
{
    return t == IO_F32 ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
}

/* OpenImageIO messages may span lines: keep one. */
std::string one_line(std::string s)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    for (char &c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s.empty() ? std::string("unknown OpenImageIO error") : s;
}

/* The pending global OpenImageIO error (cleared), or `fallback`. */
std::string global_error(const char *fallback)
{
    std::string e = OIIO::geterror();
    return e.empty() ? std::string(fallback) : one_line(e);
}

io_result load(const char *path, io_type type, int want, io_image *out,
               io_error *err)
{
    io_result r0 = io_check_file(path, err);
    if (r0 != IO_OK) return r0;

    /* pixels exactly as stored: no premultiplication of PNG/TIFF alpha */
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in)
        return io_fail(err, IO_ERR_FORMAT, "%s: %s", path,
                       global_error("cannot read this file").c_str());
    const OIIO::ImageSpec spec = in->spec();
    int w = spec.width, h = spec.height, fc = spec.nchannels;
    if (w <= 0 || h <= 0 || fc <= 0 || spec.depth > 1) {
        in->close();
        return io_fail(err, IO_ERR_FORMAT,
                       "%s: unsupported image (%d x %d, %d channels, depth %d)",
                       path, w, h, fc, spec.depth);
    }
    if (want == 0) want = fc < 4 ? fc : 4;

    io_result r = io_image_alloc(out, w, h, want, type, err);
    if (r != IO_OK) {
        in->close();
        if (err) {
            std::string m = std::string(path) + ": " + err->msg;
            io_fail(err, r, "%s", m.c_str());
        }
        return r;
    }
    size_t ts = type_size(type);
    bool direct = want == fc;
    std::vector<unsigned char> tmp;
    void *dst = out->data;
    if (!direct) {
        tmp.resize((size_t)w * (size_t)h * (size_t)fc * ts);
        dst = tmp.data();
    }
    if (!in->read_image(0, 0, 0, fc, oiio_type(type), dst)) {
        std::string e = one_line(in->geterror());
        in->close();
        io_image_free(out);
        return io_fail(err, IO_ERR_FORMAT, "%s: %s", path, e.c_str());
    }
    in->close();
    if (direct) return IO_OK;

    /* colour channels of the file (up to 3) and its alpha */
    int alpha = spec.alpha_channel;
    if (alpha < 0 || alpha >= fc) alpha = -1;
    int col[3], ncol = 0;
    for (int c = 0; c < fc && ncol < 3; c++)
        if (c != alpha) col[ncol++] = c;
    if (ncol == 0) col[ncol++] = 0;  /* alpha-only file: read it as grey */
    bool out_alpha = want == 2 || want == 4;
    int out_col = out_alpha ? want - 1 : want;
    int src[4];  /* file channel of each output channel, -1 = opaque, -2 = 0 */
    for (int c = 0; c < out_col; c++)
        src[c] = ncol == 1 ? col[0] : (c < ncol ? col[c] : -2);
    if (out_alpha) src[want - 1] = alpha;

    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            size_t si = ((size_t)y * (size_t)w + (size_t)x) * (size_t)fc;
            size_t di = (size_t)x * (size_t)want;
            if (type == IO_F32) {
                const float *s = reinterpret_cast<const float *>(tmp.data()) + si;
                float *d = reinterpret_cast<float *>(
                    static_cast<unsigned char *>(out->data) + (size_t)y * out->stride) + di;
                for (int c = 0; c < want; c++)
                    d[c] = src[c] >= 0 ? s[src[c]] : (src[c] == -1 ? 1.0f : 0.0f);
            } else {
                const unsigned char *s = tmp.data() + si;
                unsigned char *d = static_cast<unsigned char *>(out->data) +
                                   (size_t)y * out->stride + di;
                for (int c = 0; c < want; c++)
                    d[c] = src[c] >= 0 ? s[src[c]] : (src[c] == -1 ? 255 : 0);
            }
        }
    }
    return IO_OK;
}

/* Formats that store 32-bit float pixels; others get 8-bit. */
bool stores_float(const char *format_name)
{
    static const char *const names[] = {"openexr", "tiff", "hdr", "pfm",
                                        "fits", "ptex"};
    for (const char *n : names)
        if (strcmp(format_name, n) == 0) return true;
    return false;
}

io_result save(const char *path, const char *tmp, const io_image *img,
               io_error *err)
{
    auto out = OIIO::ImageOutput::create(path);
    if (!out)
        return io_fail(err, IO_ERR_ARGS, "%s: no image format for this file "
                       "name extension (%s)", path,
                       global_error("unknown extension").c_str());
    OIIO::TypeDesc file_type =
        img->type == IO_F32 && stores_float(out->format_name())
            ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
    OIIO::ImageSpec spec(img->width, img->height, img->channels, file_type);
    if (img->channels == 2) spec.alpha_channel = 1;
    else if (img->channels == 4) spec.alpha_channel = 3;
    else spec.alpha_channel = -1;
    /* the data is written as given: no un-premultiplication */
    spec.attribute("oiio:UnassociatedAlpha", 1);
    /* zlib level 1: 7x faster than the default 6 for ~10% larger files;
     * egofuse writes many frames and PNG encoding dominated that time. */
    spec.attribute("png:compressionLevel", 1);

    if (!out->open(tmp, spec)) {
        std::string e = one_line(out->geterror());
        remove(tmp);
        return io_fail(err, IO_ERR_WRITE, "%s: %s", path, e.c_str());
    }
    bool ok = out->write_image(oiio_type(img->type), img->data,
                               OIIO::AutoStride, (OIIO::stride_t)img->stride);
    std::string e = ok ? std::string() : one_line(out->geterror());
    if (!out->close() && ok) {
        ok = false;
        e = one_line(out->geterror());
    }
    out.reset();
    if (!ok) {
        remove(tmp);
        return io_fail(err, IO_ERR_WRITE, "%s: %s", path, e.c_str());
    }
    if (rename(tmp, path) != 0) {
        int en = errno;
        remove(tmp);
        return io_fail(err, IO_ERR_WRITE, "%s: rename from %s: %s", path, tmp,
                       strerror(en));
    }
    return IO_OK;
}

}  // namespace

extern "C" io_result io_image_alloc(io_image *img, int width, int height,
                                    int channels, io_type type, io_error *err)
{
    if (!img) return io_fail(err, IO_ERR_ARGS, "io_image_alloc: no image");
    memset(img, 0, sizeof *img);
    if (width <= 0 || height <= 0 || channels < 1 || channels > 4 ||
        (type != IO_U8 && type != IO_F32))
        return io_fail(err, IO_ERR_ARGS,
                       "io_image_alloc: bad size %d x %d x %d or type %d",
                       width, height, channels, (int)type);
    size_t stride = (size_t)width * (size_t)channels * type_size(type);
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

extern "C" io_result io_image_load(const char *path, io_type type,
                                   int channels, io_image *out, io_error *err)
{
    if (!out) return io_fail(err, IO_ERR_ARGS, "io_image_load: no output image");
    memset(out, 0, sizeof *out);
    if (!path || !*path)
        return io_fail(err, IO_ERR_ARGS, "io_image_load: no path");
    if (channels < 0 || channels > 4 || (type != IO_U8 && type != IO_F32))
        return io_fail(err, IO_ERR_ARGS, "%s: bad channel count %d or type %d",
                       path, channels, (int)type);
    io_result r;
    try {
        r = load(path, type, channels, out, err);
    } catch (const std::bad_alloc &) {
        r = io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        r = io_fail(err, IO_ERR_FORMAT, "%s: %s", path, e.what());
    } catch (...) {
        r = io_fail(err, IO_ERR_FORMAT, "%s: unexpected exception", path);
    }
    if (r != IO_OK) io_image_free(out);
    return r;
}

extern "C" io_result io_image_save(const char *path, const io_image *img,
                                   io_error *err)
{
    if (!path || !*path)
        return io_fail(err, IO_ERR_ARGS, "io_image_save: no path");
    if (!img || !img->data || img->width <= 0 || img->height <= 0 ||
        img->channels < 1 || img->channels > 4 ||
        (img->type != IO_U8 && img->type != IO_F32) ||
        img->stride < (size_t)img->width * (size_t)img->channels *
                          type_size(img->type))
        return io_fail(err, IO_ERR_ARGS,
                       "%s: invalid image (size, channels, type or stride)",
                       path);
    char tmp[IO_PATH_MAX + 32];
    int n = snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    if (n < 0 || (size_t)n >= sizeof tmp)
        return io_fail(err, IO_ERR_ARGS, "%s: path too long", path);
    io_result r;
    try {
        return save(path, tmp, img, err);
    } catch (const std::bad_alloc &) {
        r = io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        r = io_fail(err, IO_ERR_WRITE, "%s: %s", path, e.what());
    } catch (...) {
        r = io_fail(err, IO_ERR_WRITE, "%s: unexpected exception", path);
    }
    remove(tmp);  /* never leave a half-written file behind */
    return r;
}

extern "C" void io_image_free(io_image *img)
{
    if (!img) return;
    free(img->data);
    memset(img, 0, sizeof *img);
}
