/* io_image_oiio.cpp - image files through OpenImageIO (see io.h, images):
 * the plugin build/libegofuse_oiio.so (io_image_plugin.h), loaded by
 * io_image.c only for formats other than PNG and binary PPM/PGM.
 *
 * WRITES
 *   Formats OpenImageIO can write to memory (supports("ioproxy"): EXR,
 *   TIFF, PNG, JPEG, ...) are encoded into a buffer whose bytes go to the
 *   caller's io_out stream, which checks every write. Others are written to
 *   the caller's unnamed file through /proc/self/fd/N and read back whole,
 *   so a short write cannot pass unseen.
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
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>

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
#include "io_image_plugin.h"
}
#include "io_cxx.hpp"

namespace {

size_t type_size(io_type t) { return t == IO_F32 ? sizeof(float) : 1; }

OIIO::TypeDesc oiio_type(io_type t)
{
    return t == IO_F32 ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8;
}

/* OpenImageIO messages may span lines: keep one. */
std::string one_line(std::string s) { return io_cxx::one_line(s, "unknown OpenImageIO error"); }

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
    int src[4];  /* file channel of each output channel, -1 = opaque, -2 = 0 */
    io_cxx::channel_map(fc, alpha, want, src);

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

/* Reads the whole file back (a format written without a proxy). */
bool read_back(const char *path, const char *file, std::string &why)
{
    auto in = OIIO::ImageInput::create(path);
    OIIO::ImageSpec config;
    if (!in || !in->open(file, config)) {
        why = in ? one_line(in->geterror()) : global_error("cannot read it back");
        return false;
    }
    const OIIO::ImageSpec &spec = in->spec();
    std::vector<float> px((size_t)spec.width * (size_t)spec.height *
                          (size_t)std::max(1, spec.nchannels));
    bool ok = in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data());
    if (!ok) why = one_line(in->geterror());
    in->close();
    return ok;
}

io_result save(const char *path, FILE *f, int fd, const io_image *img, io_error *err)
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
    spec.attribute("png:compressionLevel", 1);

    bool proxy = out->supports("ioproxy") != 0;
    OIIO::Filesystem::IOVecOutput vec;
    char procpath[64];
    snprintf(procpath, sizeof procpath, "/proc/self/fd/%d", fd);
    if (proxy && !out->set_ioproxy(&vec)) proxy = false;
    if (!out->open(proxy ? std::string(path) : std::string(procpath), spec)) {
        std::string e = one_line(out->geterror());
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
    if (!ok) return io_fail(err, IO_ERR_WRITE, "%s: %s", path, e.c_str());
    if (proxy) {
        std::vector<unsigned char> &b = vec.buffer();
        if (!b.empty()) fwrite(b.data(), 1, b.size(), f);  /* checked by the commit */
        return IO_OK;
    }
    std::string why;
    if (!read_back(path, procpath, why))
        return io_fail(err, IO_ERR_WRITE, "%s: the written file is not whole (%s); "
                       "nothing written", path, why.c_str());
    return IO_OK;
}

io_result plugin_load(const char *path, io_type type, int channels, io_image *out,
                      io_error *err)
{
    io_result r = io_cxx::guard(path, err, IO_ERR_FORMAT, nullptr,
                                [&] { return load(path, type, channels, out, err); });
    if (r != IO_OK) io_image_free(out);
    return r;
}

io_result plugin_save(const char *path, FILE *f, int fd, const io_image *img,
                      io_error *err)
{
    return io_cxx::guard(path, err, IO_ERR_WRITE, nullptr,
                         [&] { return save(path, f, fd, img, err); });
}

const io_oiio_plugin the_plugin = {IO_OIIO_PLUGIN_ABI, plugin_load, plugin_save};

}  // namespace

extern "C" __attribute__((visibility("default"))) const io_oiio_plugin *
egofuse_oiio_plugin(void)
{
    return &the_plugin;
}
