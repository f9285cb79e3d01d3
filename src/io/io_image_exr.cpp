/* io_image_exr.cpp - the image plugin (io_image_plugin.h) built with
 * OpenEXR alone, where OpenImageIO is not installed: build/libegofuse_oiio.so
 * then reads and writes EXR only, so that `make demo` (whose samples keep
 * their depth in EXR) needs the small OpenEXR library instead of
 * OpenImageIO and the ~230 packages behind it (scripts/deps.sh). Every
 * other format gets a message that names the missing OpenImageIO. The
 * Makefile builds this file as the plugin only when pkg-config finds no
 * OpenImageIO, and rebuilds the plugin with OpenImageIO once it is there.
 *
 * The pixels are those of the OpenImageIO plugin (io_image_oiio.cpp, the
 * tests compare the two, tests/test_io_exr_plugin.c):
 *
 * READ  one part, scanline or tiled, any pixel type (OpenEXR converts to
 *       float). The channels in OpenImageIO's order (R G B Y A Z ... first,
 *       then the others by name), alpha the first A or Alpha; channel
 *       adaptation and float to 8-bit as io_image_oiio.cpp: v * 255
 *       rounded to nearest (ties away from zero), clamped, NaN 0.
 * WRITE ZIP compression; 1 channel Y, 2 Y A, 3 R G B, 4 R G B A; float
 *       images as FLOAT, 8-bit ones as HALF of v / 255 (as OpenImageIO).
 *       The file is encoded in memory and handed to the caller's io_out
 *       stream, which checks every write.
 *
 * No exception or C++ type leaves this file. */
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImathBox.h>
#include <half.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include <strings.h>

extern "C" {
#include "io.h"
#include "io_image_plugin.h"
}
#include "io_cxx.hpp"

namespace {

const char *const EXR_UNKNOWN = "unknown OpenEXR error";

const char *const no_oiio =
    "this format needs OpenImageIO: this egofuse's image plugin was built with "
    "OpenEXR only (EXR files); install OpenImageIO (Debian: libopenimageio-dev, "
    "which make test installs) and run make again";


bool is_exr_name(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && strcasecmp(path + n - 4, ".exr") == 0;
}

/* 1 if the file starts with the OpenEXR magic number 20000630 (LE). */
int has_exr_magic(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    unsigned char m[4] = {0, 0, 0, 0};
    size_t n = fread(m, 1, 4, f);
    fclose(f);
    return n == 4 && m[0] == 0x76 && m[1] == 0x2f && m[2] == 0x31 && m[3] == 0x01;
}

/* OpenImageIO's order of the channel names it knows (its EXR reader);
 * every other name after them. */
int special_rank(const std::string &n)
{
    static const char *const special[] = {"R", "Red", "G", "Green", "B", "Blue", "Y", "real", "imag",
                                          "A", "Alpha", "AR", "RA", "AG", "GA", "AB", "BA", "Z",
                                          "Depth", "Zback"};
    int i = 0;
    for (const char *sp : special) {
        if (n == sp) return i;
        i++;
    }
    return i;
}

unsigned char float_to_u8(float v)
{
    float s = roundf(v * 255.0f);  /* ties away from zero, as OpenImageIO */
    if (!(s > 0.0f)) return 0;     /* also NaN */
    return s >= 255.0f ? 255 : (unsigned char)s;
}

io_result load(const char *path, io_type type, int want, io_image *out, io_error *err)
{
    io_result r0 = io_check_file(path, err);
    if (r0 != IO_OK) return r0;
    if (!has_exr_magic(path)) return io_fail(err, IO_ERR_FORMAT, "%s: %s", path, no_oiio);

    Imf::InputFile in(path);
    const Imf::Header &hd = in.header();
    const Imath::Box2i dw = hd.dataWindow();
    long long lw = (long long)dw.max.x - dw.min.x + 1, lh = (long long)dw.max.y - dw.min.y + 1;
    if (lw <= 0 || lh <= 0 || lw > INT32_MAX || lh > INT32_MAX)
        return io_fail(err, IO_ERR_FORMAT, "%s: unsupported data window (%lld x %lld)", path, lw, lh);
    int w = (int)lw, h = (int)lh;

    /* the channels in OpenImageIO's order (colour, luminance, alpha and
     * depth names first, then the others by name: OpenEXR lists them by
     * name), alpha the first A or Alpha */
    std::vector<std::string> names;
    const Imf::ChannelList &cl = hd.channels();
    for (Imf::ChannelList::ConstIterator i = cl.begin(); i != cl.end(); ++i) {
        if (i.channel().xSampling != 1 || i.channel().ySampling != 1)
            return io_fail(err, IO_ERR_FORMAT, "%s: channel %s is subsampled (%d x %d): not supported",
                           path, i.name(), i.channel().xSampling, i.channel().ySampling);
        names.push_back(i.name());
    }
    std::stable_sort(names.begin(), names.end(), [](const std::string &a, const std::string &b) {
        return special_rank(a) < special_rank(b);
    });
    int fc = (int)names.size();
    if (fc <= 0) return io_fail(err, IO_ERR_FORMAT, "%s: no channels", path);
    int alpha = -1;
    for (int c = 0; c < fc && alpha < 0; c++)
        if (names[(size_t)c] == "A" || names[(size_t)c] == "Alpha") alpha = c;
    if (want == 0) want = fc < 4 ? fc : 4;

    /* the whole file as float, fc interleaved channels */
    std::vector<float> px((size_t)w * (size_t)h * (size_t)fc);
    Imf::FrameBuffer fb;
    for (int c = 0; c < fc; c++)
        fb.insert(names[(size_t)c].c_str(),
                  Imf::Slice::Make(Imf::FLOAT, px.data() + c, dw, sizeof(float) * (size_t)fc,
                                   sizeof(float) * (size_t)fc * (size_t)w));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);

    io_result r = io_image_alloc(out, w, h, want, type, err);
    if (r != IO_OK) {
        if (err) {
            std::string m = std::string(path) + ": " + err->msg;
            io_fail(err, r, "%s", m.c_str());
        }
        return r;
    }
    /* as the OpenImageIO plugin: the file's channels as they are when
     * their count is the one wanted, else colour (up to 3) and alpha */
    int src[4];  /* file channel of each output channel, -1 = opaque, -2 = 0 */
    if (want == fc) {
        for (int c = 0; c < want; c++) src[c] = c;
    } else {
        io_cxx::channel_map(fc, alpha, want, src);
    }
    for (int y = 0; y < h; y++) {
        unsigned char *row = static_cast<unsigned char *>(out->data) + (size_t)y * out->stride;
        for (int x = 0; x < w; x++) {
            const float *s = px.data() + ((size_t)y * (size_t)w + (size_t)x) * (size_t)fc;
            for (int c = 0; c < want; c++) {
                float v = src[c] >= 0 ? s[src[c]] : (src[c] == -1 ? 1.0f : 0.0f);
                if (type == IO_F32)
                    reinterpret_cast<float *>(row)[(size_t)x * (size_t)want + (size_t)c] = v;
                else
                    row[(size_t)x * (size_t)want + (size_t)c] = float_to_u8(v);
            }
        }
    }
    return IO_OK;
}

/* An OpenEXR output stream into memory. */
class MemOut : public Imf::OStream {
public:
    MemOut() : Imf::OStream("memory") {}
    void write(const char c[], int n) override
    {
        if (n <= 0) return;
        if (pos + (uint64_t)n > buf.size()) buf.resize(pos + (uint64_t)n);
        memcpy(buf.data() + pos, c, (size_t)n);
        pos += (uint64_t)n;
    }
    uint64_t tellp() override { return pos; }
    void seekp(uint64_t p) override { pos = p; }
    std::vector<char> buf;
    uint64_t pos = 0;
};

io_result save(const char *path, FILE *f, int fd, const io_image *img, io_error *err)
{
    (void)fd;
    if (!is_exr_name(path)) return io_fail(err, IO_ERR_ARGS, "%s: %s", path, no_oiio);
    static const char *const chan[4][4] = {
        {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
    int ch = img->channels, w = img->width, h = img->height;
    Imf::PixelType file_type = img->type == IO_F32 ? Imf::FLOAT : Imf::HALF;
    Imf::Header hd(w, h);
    hd.compression() = Imf::ZIP_COMPRESSION;
    for (int c = 0; c < ch; c++) hd.channels().insert(chan[ch - 1][c], Imf::Channel(file_type));

    /* float pixels as given; 8-bit ones as halves of v / 255 (the
     * frame buffer must have the file's pixel type) */
    std::vector<Imath::half> conv;
    const char *base = static_cast<const char *>(img->data);
    size_t ystride = img->stride, size = sizeof(float);
    if (img->type == IO_U8) {
        conv.resize((size_t)w * (size_t)h * (size_t)ch);
        for (int y = 0; y < h; y++) {
            const unsigned char *s = static_cast<const unsigned char *>(img->data) + (size_t)y * img->stride;
            for (size_t i = 0; i < (size_t)w * (size_t)ch; i++)
                conv[(size_t)y * (size_t)w * (size_t)ch + i] = Imath::half((float)s[i] / 255.0f);
        }
        base = reinterpret_cast<const char *>(conv.data());
        size = sizeof(Imath::half);
        ystride = size * (size_t)w * (size_t)ch;
    }
    Imf::FrameBuffer fb;
    for (int c = 0; c < ch; c++)
        fb.insert(chan[ch - 1][c], Imf::Slice(file_type, const_cast<char *>(base) + size * (size_t)c,
                                              size * (size_t)ch, ystride));
    MemOut mem;
    {
        Imf::OutputFile out(mem, hd);
        out.setFrameBuffer(fb);
        out.writePixels(h);
    }
    if (!mem.buf.empty()) fwrite(mem.buf.data(), 1, mem.buf.size(), f); /* checked by the commit */
    return IO_OK;
}

io_result plugin_load(const char *path, io_type type, int channels, io_image *out, io_error *err)
{
    io_result r = io_cxx::guard(path, err, IO_ERR_FORMAT, EXR_UNKNOWN,
                                [&] { return load(path, type, channels, out, err); });
    if (r != IO_OK) io_image_free(out);
    return r;
}

io_result plugin_save(const char *path, FILE *f, int fd, const io_image *img, io_error *err)
{
    return io_cxx::guard(path, err, IO_ERR_WRITE, EXR_UNKNOWN,
                         [&] { return save(path, f, fd, img, err); });
}

const io_oiio_plugin the_plugin = {IO_OIIO_PLUGIN_ABI, plugin_load, plugin_save};

}  // namespace

extern "C" __attribute__((visibility("default"))) const io_oiio_plugin *egofuse_oiio_plugin(void)
{
    return &the_plugin;
}
