/* io_image.c - io_image_load / io_image_save (see io.h, images).
 *
 * PNG (libpng) and binary PPM/PGM (P6/P5, maxval 255) are read and written
 * here; every other format goes to OpenImageIO through the plugin
 * libegofuse_oiio.so (io_image_plugin.h), loaded with dlopen() the first
 * time it is needed, so a command that only touches PNG never maps
 * OpenImageIO and its ~260 libraries.
 *
 * Pixel values are the ones the OpenImageIO path gave (docs/io.md, Images):
 * 8-bit to float is v * (1/255), 16-bit to 8-bit is
 * (uint8)(v * (255/65535) + 0.5), float to 8-bit is v * 255 rounded to
 * nearest (ties away from zero) and clamped to [0, 255] (NaN -> 0); channel adaptation as documented
 * in io.h.
 *
 * Every write goes through io_out (io_out.c): complete or absent.
 *
 * EGOFUSE_IMAGE=oiio sends every format to the plugin (tests compare the
 * two); EGOFUSE_OIIO_PLUGIN=/path/libegofuse_oiio.so names the plugin.
 */
#include "io.h"
#include "io_image_plugin.h"

#include <ctype.h>
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <png.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

/* ------------------------------------------------------------- plugin */

static pthread_once_t plugin_once = PTHREAD_ONCE_INIT;
static const io_oiio_plugin *plugin;
static char plugin_why[768];

static void try_plugin(const char *path, char *tried, size_t tsize)
{
    if (plugin) return;
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *e = dlerror();
        size_t n = strlen(tried);
        snprintf(tried + n, tsize - n, "%s%s", n ? "; " : "", e ? e : path);
        return;
    }
    io_oiio_plugin_fn fn = (io_oiio_plugin_fn)dlsym(h, IO_OIIO_PLUGIN_SYMBOL);
    const io_oiio_plugin *p = fn ? fn() : NULL;
    if (!p || p->abi != IO_OIIO_PLUGIN_ABI) {
        size_t n = strlen(tried);
        snprintf(tried + n, tsize - n, "%s%s: not an egofuse plugin of this version",
                 n ? "; " : "", path);
        dlclose(h);
        return;
    }
    plugin = p;  /* kept loaded until exit */
}

static void load_plugin(void)
{
    char tried[sizeof plugin_why - 128] = "";
    const char *env = getenv("EGOFUSE_OIIO_PLUGIN");
    if (env && *env) {
        try_plugin(env, tried, sizeof tried);
    } else {
        /* next to the executable, then its parent folder (build/tests,
         * build/bench), then the installed folder */
        char exe[PATH_MAX], path[PATH_MAX + 64];
        ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (n > 0) {
            exe[n] = '\0';
            char *slash = strrchr(exe, '/');
            if (slash) {
                *slash = '\0';
                snprintf(path, sizeof path, "%s/%s", exe, IO_OIIO_PLUGIN_NAME);
                try_plugin(path, tried, sizeof tried);
                snprintf(path, sizeof path, "%s/../%s", exe, IO_OIIO_PLUGIN_NAME);
                try_plugin(path, tried, sizeof tried);
            }
        }
#ifdef EGOFUSE_PLUGIN_DIR
        snprintf(path, sizeof path, "%s/%s", EGOFUSE_PLUGIN_DIR, IO_OIIO_PLUGIN_NAME);
        try_plugin(path, tried, sizeof tried);
#endif
    }
    if (!plugin)
        snprintf(plugin_why, sizeof plugin_why,
                 "this format needs OpenImageIO, through the plugin " IO_OIIO_PLUGIN_NAME
                 " (build it with make; EGOFUSE_OIIO_PLUGIN=PATH names it), which "
                 "cannot be loaded: %s", tried);
}

static const io_oiio_plugin *get_plugin(const char *path, io_error *err)
{
    pthread_once(&plugin_once, load_plugin);
    if (!plugin) io_fail(err, IO_ERR_FORMAT, "%s: %s", path, plugin_why);
    return plugin;
}

static int force_plugin(void)
{
    const char *e = getenv("EGOFUSE_IMAGE");
    return e && strcmp(e, "oiio") == 0;
}

/* ----------------------------------------------------- pixel conversion */

/* Decoded file pixels: w x h x fc samples of 8 or 16 bits (native
 * order), rows packed. */
typedef struct raw_image {
    unsigned char *data;
    int w, h, fc, bits;
    int alpha;  /* channel index of alpha, or -1 */
} raw_image;

static unsigned sample(const raw_image *r, size_t i)
{
    return r->bits == 16 ? ((const uint16_t *)r->data)[i] : r->data[i];
}

/* raw -> out (allocated) with `want` channels (0 = the file's) of type. */
static io_result adapt(const char *path, const raw_image *r, io_type type, int want,
                       io_image *out, io_error *err)
{
    if (want == 0) want = r->fc < 4 ? r->fc : 4;
    io_result res = io_image_alloc(out, r->w, r->h, want, type, err);
    if (res != IO_OK) {
        if (err) {
            char m[sizeof err->msg];
            snprintf(m, sizeof m, "%s", err->msg);
            io_fail(err, res, "%s: %s", path, m);
        }
        return res;
    }
    /* colour channels of the file (up to 3) and its alpha */
    int col[3], ncol = 0;
    for (int c = 0; c < r->fc && ncol < 3; c++)
        if (c != r->alpha) col[ncol++] = c;
    if (ncol == 0) col[ncol++] = 0;
    int out_alpha = want == 2 || want == 4;
    int out_col = out_alpha ? want - 1 : want;
    int src[4];  /* file channel of each output channel, -1 = opaque, -2 = 0 */
    if (want == r->fc) {
        for (int c = 0; c < want; c++) src[c] = c;
    } else {
        for (int c = 0; c < out_col; c++)
            src[c] = ncol == 1 ? col[0] : (c < ncol ? col[c] : -2);
        if (out_alpha) src[want - 1] = r->alpha;
    }
    const float k8 = 1.0f / 255.0f, k16 = 1.0f / 65535.0f;
    float s16to8 = 1.0f / 65535.0f;
    s16to8 *= 255.0f;
    for (int y = 0; y < r->h; y++) {
        unsigned char *row = (unsigned char *)out->data + (size_t)y * out->stride;
        for (int x = 0; x < r->w; x++) {
            size_t si = ((size_t)y * (size_t)r->w + (size_t)x) * (size_t)r->fc;
            for (int c = 0; c < want; c++) {
                size_t di = (size_t)x * (size_t)want + (size_t)c;
                if (type == IO_F32) {
                    float v = src[c] == -1 ? 1.0f : 0.0f;
                    if (src[c] >= 0) {
                        unsigned s = sample(r, si + (size_t)src[c]);
                        v = r->bits == 16 ? (float)s * k16 : (float)s * k8;
                    }
                    ((float *)row)[di] = v;
                } else {
                    unsigned v = src[c] == -1 ? 255 : 0;
                    if (src[c] >= 0) {
                        unsigned s = sample(r, si + (size_t)src[c]);
                        if (r->bits == 16) {
                            float f = (float)s * s16to8 + 0.5f;
                            v = f >= 255.0f ? 255 : (unsigned)f;
                        } else {
                            v = s;
                        }
                    }
                    row[di] = (unsigned char)v;
                }
            }
        }
    }
    return IO_OK;
}

static unsigned char float_to_u8(float v)
{
    float s = roundf(v * 255.0f);  /* ties away from zero, as OpenImageIO */
    if (!(s > 0.0f)) return 0;  /* also NaN */
    return s >= 255.0f ? 255 : (unsigned char)s;
}

/* Row y of img as 8-bit samples (buf when converting from float). */
static const unsigned char *row_u8(const io_image *img, int y, unsigned char *buf)
{
    const unsigned char *row = (const unsigned char *)img->data + (size_t)y * img->stride;
    if (img->type == IO_U8) return row;
    size_t n = (size_t)img->width * (size_t)img->channels;
    for (size_t i = 0; i < n; i++) buf[i] = float_to_u8(((const float *)row)[i]);
    return buf;
}

/* ---------------------------------------------------------------- PNG */

typedef struct png_ctx {
    jmp_buf jmp;
    char msg[512];
    const char *path;
    FILE *f;
    io_out *out;
    size_t offset;   /* bytes read so far */
    int truncated;
} png_ctx;

static void png_err_cb(png_structp png, png_const_charp msg)
{
    png_ctx *c = png_get_error_ptr(png);
    if (!c->msg[0]) snprintf(c->msg, sizeof c->msg, "%s", msg);
    longjmp(c->jmp, 1);
}

static void png_warn_cb(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static void png_read_cb(png_structp png, png_bytep data, size_t n)
{
    png_ctx *c = png_get_io_ptr(png);
    size_t got = fread(data, 1, n, c->f);
    if (got != n) {
        if (ferror(c->f))
            snprintf(c->msg, sizeof c->msg, "read error at byte %zu: %s", c->offset + got,
                     strerror(errno));
        else
            snprintf(c->msg, sizeof c->msg, "truncated: the file ends at byte %zu, inside "
                     "a chunk", c->offset + got);
        c->truncated = 1;
        png_error(png, c->msg);
    }
    c->offset += n;
}

static void png_write_cb(png_structp png, png_bytep data, size_t n)
{
    png_ctx *c = png_get_io_ptr(png);
    if (fwrite(data, 1, n, c->out->f) != n || c->out->error) {
        snprintf(c->msg, sizeof c->msg, "write failed");
        png_error(png, c->msg);
    }
}

static void png_flush_cb(png_structp png)
{
    (void)png;
}

static io_result png_load(const char *path, FILE *f, io_type type, int want, io_image *out,
                          io_error *err)
{
    png_ctx c;
    memset(&c, 0, sizeof c);
    c.path = path;
    c.f = f;
    raw_image r;
    memset(&r, 0, sizeof r);
    png_bytep *rows = NULL;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &c, png_err_cb, png_warn_cb);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_read_struct(&png, NULL, NULL);
        return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    }
    /* volatile: changed after setjmp, read after a longjmp */
    unsigned char *volatile data = NULL;
    png_bytep *volatile vrows = NULL;
    if (setjmp(c.jmp)) {
        free(data);
        free(vrows);
        png_destroy_read_struct(&png, &info, NULL);
        return io_fail(err, IO_ERR_FORMAT, "%s: %s", path, c.msg[0] ? c.msg : "bad PNG");
    }
    png_set_read_fn(png, &c, png_read_cb);
    png_set_user_limits(png, 1u << 20, 1u << 20);
    png_read_info(png, info);
    int ct = png_get_color_type(png, info);
    int depth = png_get_bit_depth(png, info);
    if (ct == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (ct == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    const uint16_t one = 1;
    if (depth == 16 && *(const unsigned char *)&one == 1)
        png_set_swap(png);  /* PNG is big-endian: 16-bit samples in host order */
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    r.w = (int)png_get_image_width(png, info);
    r.h = (int)png_get_image_height(png, info);
    r.fc = png_get_channels(png, info);
    r.bits = png_get_bit_depth(png, info) == 16 ? 16 : 8;
    ct = png_get_color_type(png, info);
    r.alpha = (ct & PNG_COLOR_MASK_ALPHA) ? r.fc - 1 : -1;
    size_t rowbytes = png_get_rowbytes(png, info);
    if (rowbytes != (size_t)r.w * (size_t)r.fc * (size_t)(r.bits / 8)) {
        snprintf(c.msg, sizeof c.msg, "unsupported PNG layout");
        longjmp(c.jmp, 1);
    }
    if ((size_t)r.h > ((size_t)1 << 40) / (rowbytes ? rowbytes : 1)) {
        snprintf(c.msg, sizeof c.msg, "image too large");
        longjmp(c.jmp, 1);
    }
    data = malloc(rowbytes * (size_t)r.h);
    vrows = malloc(sizeof *rows * (size_t)r.h);
    if (!data || !vrows) {
        snprintf(c.msg, sizeof c.msg, "out of memory (%d x %d)", r.w, r.h);
        longjmp(c.jmp, 1);
    }
    rows = vrows;
    for (int y = 0; y < r.h; y++) rows[y] = data + (size_t)y * rowbytes;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    png_destroy_read_struct(&png, &info, NULL);
    free(vrows);
    r.data = data;
    io_result res = adapt(path, &r, type, want, out, err);
    free(data);
    return res;
}

static io_result png_save(const char *path, io_out *o, const io_image *img, io_error *err)
{
    png_ctx c;
    memset(&c, 0, sizeof c);
    c.path = path;
    c.out = o;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &c, png_err_cb, png_warn_cb);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_write_struct(&png, NULL);
        return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    }
    unsigned char *volatile buf = NULL;
    if (setjmp(c.jmp)) {
        free(buf);
        png_destroy_write_struct(&png, &info);
        if (o->error) return IO_ERR_WRITE;  /* the caller's commit says why */
        return io_fail(err, IO_ERR_WRITE, "%s: %s", path, c.msg[0] ? c.msg : "PNG error");
    }
    static const int types[5] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA,
                                 PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA};
    png_set_write_fn(png, &c, png_write_cb, png_flush_cb);
    /* zlib level 1: 7x faster than the default 6 for ~10% larger files */
    png_set_compression_level(png, 1);
    png_set_IHDR(png, info, (png_uint_32)img->width, (png_uint_32)img->height, 8,
                 types[img->channels], PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    if (img->type == IO_F32) {
        buf = malloc((size_t)img->width * (size_t)img->channels);
        if (!buf) {
            snprintf(c.msg, sizeof c.msg, "out of memory");
            longjmp(c.jmp, 1);
        }
    }
    for (int y = 0; y < img->height; y++)
        png_write_row(png, (png_const_bytep)row_u8(img, y, buf));
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(buf);
    return IO_OK;
}

/* ------------------------------------------------------------ PPM/PGM */

/* Reads the header of a binary PNM: returns 1 and fills w, h, fc, maxval
 * with the file positioned at the pixels, 0 if malformed. */
static int pnm_header(FILE *f, int *w, int *h, int *fc, int *maxval)
{
    char m[2];
    if (fread(m, 1, 2, f) != 2 || m[0] != 'P' || (m[1] != '5' && m[1] != '6')) return 0;
    *fc = m[1] == '5' ? 1 : 3;
    long v[3];
    for (int i = 0; i < 3; i++) {
        int ch = fgetc(f);
        for (;;) {  /* white space and comments */
            if (ch == '#') {
                while (ch != EOF && ch != '\n') ch = fgetc(f);
            } else if (ch != EOF && isspace(ch)) {
                ch = fgetc(f);
            } else {
                break;
            }
        }
        if (ch == EOF || !isdigit(ch)) return 0;
        long x = 0;
        while (ch != EOF && isdigit(ch)) {
            x = x * 10 + (ch - '0');
            if (x > (1 << 20)) return 0;
            ch = fgetc(f);
        }
        if (ch == EOF || !isspace(ch)) return 0;  /* one white space ends the header */
        v[i] = x;
    }
    *w = (int)v[0];
    *h = (int)v[1];
    *maxval = (int)v[2];
    return *w > 0 && *h > 0;
}

static io_result pnm_load(const char *path, FILE *f, int w, int h, int fc, io_type type,
                          int want, io_image *out, io_error *err)
{
    raw_image r = {NULL, w, h, fc, 8, -1};
    size_t n = (size_t)w * (size_t)h * (size_t)fc;
    r.data = malloc(n);
    if (!r.data) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory (%d x %d)", path, w, h);
    size_t got = fread(r.data, 1, n, f);
    if (got != n) {
        int bad = ferror(f);
        free(r.data);
        if (bad) return io_fail(err, IO_ERR_READ, "%s: %s", path, strerror(errno));
        return io_fail(err, IO_ERR_FORMAT, "%s: truncated: %zu of the %zu bytes of "
                       "pixels", path, got, n);
    }
    io_result res = adapt(path, &r, type, want, out, err);
    free(r.data);
    return res;
}

static io_result pnm_save(io_out *o, const io_image *img, io_error *err)
{
    (void)err;
    fprintf(o->f, "P%c\n%d %d\n255\n", img->channels == 1 ? '5' : '6', img->width,
            img->height);
    unsigned char *buf = NULL;
    if (img->type == IO_F32) {
        buf = malloc((size_t)img->width * (size_t)img->channels);
        if (!buf) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", o->path);
    }
    size_t n = (size_t)img->width * (size_t)img->channels;
    for (int y = 0; y < img->height && !o->error; y++)
        fwrite(row_u8(img, y, buf), 1, n, o->f);
    free(buf);
    return IO_OK;  /* the commit checks every write */
}

/* ---------------------------------------------------------------- API */

static size_t type_size(io_type t) { return t == IO_F32 ? sizeof(float) : 1; }

io_result io_image_load(const char *path, io_type type, int channels, io_image *out,
                        io_error *err)
{
    if (!out) return io_fail(err, IO_ERR_ARGS, "io_image_load: no output image");
    memset(out, 0, sizeof *out);
    if (!path || !*path) return io_fail(err, IO_ERR_ARGS, "io_image_load: no path");
    if (channels < 0 || channels > 4 || (type != IO_U8 && type != IO_F32))
        return io_fail(err, IO_ERR_ARGS, "%s: bad channel count %d or type %d", path,
                       channels, (int)type);
    io_result r = io_check_file(path, err);
    if (r != IO_OK) return r;
    if (!force_plugin()) {
        FILE *f = fopen(path, "rb");
        if (!f)
            return io_fail(err, errno == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_READ, "%s: %s",
                           path, strerror(errno));
        unsigned char sig[8];
        size_t n = fread(sig, 1, sizeof sig, f);
        int w, h, fc, maxval;
        if (n == 8 && png_sig_cmp(sig, 0, 8) == 0) {
            rewind(f);
            r = png_load(path, f, type, channels, out, err);
            fclose(f);
            return r;
        }
        rewind(f);
        if (n >= 2 && pnm_header(f, &w, &h, &fc, &maxval) && maxval == 255) {
            r = pnm_load(path, f, w, h, fc, type, channels, out, err);
            fclose(f);
            return r;
        }
        fclose(f);
    }
    const io_oiio_plugin *p = get_plugin(path, err);
    if (!p) return IO_ERR_FORMAT;
    r = p->load(path, type, channels, out, err);
    if (r != IO_OK) io_image_free(out);
    return r;
}

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    const char *slash = strrchr(path, '/');
    return n > e && strcasecmp(path + n - e, ext) == 0 &&
           (!slash || path + n - e > slash + 1);
}

io_result io_image_save(const char *path, const io_image *img, io_error *err)
{
    if (!path || !*path) return io_fail(err, IO_ERR_ARGS, "io_image_save: no path");
    if (!img || !img->data || img->width <= 0 || img->height <= 0 || img->channels < 1 ||
        img->channels > 4 || (img->type != IO_U8 && img->type != IO_F32) ||
        img->stride < (size_t)img->width * (size_t)img->channels * type_size(img->type))
        return io_fail(err, IO_ERR_ARGS, "%s: invalid image (size, channels, type or stride)",
                       path);
    enum { NATIVE_PNG, NATIVE_PNM, OIIO } how = OIIO;
    if (!force_plugin()) {
        if (has_ext(path, ".png"))
            how = NATIVE_PNG;
        else if ((has_ext(path, ".ppm") || has_ext(path, ".pgm") || has_ext(path, ".pnm")) &&
                 (img->channels == 1 || img->channels == 3))
            how = NATIVE_PNM;
    }
    const io_oiio_plugin *p = NULL;
    if (how == OIIO && !(p = get_plugin(path, err))) return IO_ERR_FORMAT;
    io_out o;
    io_result r = io_out_open(&o, path, err);
    if (r != IO_OK) return r;
    if (how == NATIVE_PNG) r = png_save(path, &o, img, err);
    else if (how == NATIVE_PNM) r = pnm_save(&o, img, err);
    else r = p->save(path, o.f, o.fd, img, err);
    if (r != IO_OK && !o.error) {
        io_out_abort(&o);
        return r;
    }
    return io_out_commit(&o, err);  /* reports a failed write with its reason */
}
