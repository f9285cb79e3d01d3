/* test_io_exr_plugin.c - the image plugin built with OpenEXR alone
 * (src/io/io_image_exr.cpp, build/exr/libegofuse_oiio.so: the one make
 * demo builds where OpenImageIO is not installed) against the OpenImageIO
 * plugin (build/libegofuse_oiio.so): the files each writes, read by both,
 * in every conversion, and files written by an independent producer
 * (oiiotool: other compressions, tiles, half pixels, a data window off the
 * origin, unusual channel names), read by both: the same pixels bit for
 * bit. Then its refusals: other formats (named OpenImageIO), a truncated
 * or garbled file, no leaked descriptor. */
#include "support/testutil.h"

#include <cmocka.h>
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/io/io.h"
#include "../src/io/io_image_plugin.h"

static const io_oiio_plugin *exr_p, *oiio_p;
static char skip_why[2048];

static const io_oiio_plugin *open_plugin(const char *path, char *why, size_t n)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        snprintf(why, n, "%s", dlerror());
        return NULL;
    }
    io_oiio_plugin_fn fn = (io_oiio_plugin_fn)dlsym(h, IO_OIIO_PLUGIN_SYMBOL);
    const io_oiio_plugin *p = fn ? fn() : NULL;
    if (!p || p->abi != IO_OIIO_PLUGIN_ABI) {
        snprintf(why, n, "%s: not an egofuse plugin of this version", path);
        return NULL;
    }
    return p;
}

/* img into path through plugin p (as io_image_save does, minus io_out). */
static io_result save_with(const io_oiio_plugin *p, const char *path, const io_image *img,
                           io_error *err)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    io_result r = p->save(path, f, fileno(f), img, err);
    assert_int_equal(fclose(f), 0);
    return r;
}

static int setup(void **state)
{
    (void)state;
    const char *bin = getenv("EGOFUSE_BIN");
    if (!bin) {
        snprintf(skip_why, sizeof skip_why, "EGOFUSE_BIN not set (run through tests/run_tests.sh)");
        return 0;
    }
    char dir[4096], path[4200], why[1024];
    snprintf(dir, sizeof dir, "%s", bin);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = '\0';
    snprintf(path, sizeof path, "%s/exr/libegofuse_oiio.so", dir);
    exr_p = open_plugin(path, why, sizeof why);
    if (!exr_p) {
        snprintf(skip_why, sizeof skip_why,
                 "the EXR-only plugin is not built (OpenEXR's headers missing: libopenexr-dev): %s", why);
        return 0;
    }
    snprintf(path, sizeof path, "%s/libegofuse_oiio.so", dir);
    oiio_p = open_plugin(path, why, sizeof why);
    /* the build's plugin is the EXR-only one when OpenImageIO is missing */
    io_image probe = {0};
    io_error err;
    char tif[512];
    if (oiio_p && io_image_alloc(&probe, 2, 2, 3, IO_U8, &err) == IO_OK &&
        save_with(oiio_p, tu_tmp_path("probe.tif", tif, sizeof tif), &probe, &err) != IO_OK)
        oiio_p = NULL;
    io_image_free(&probe);
    if (!oiio_p)
        snprintf(skip_why, sizeof skip_why,
                 "no OpenImageIO plugin to compare with (libopenimageio-dev): %s", why);
    return 0;
}

static void need_both(void)
{
    if (!exr_p || !oiio_p) {
        printf("SKIP: %s\n", skip_why);
        skip();
    }
}

static void same_image(const io_image *a, const io_image *b, const char *what)
{
    if (a->width != b->width || a->height != b->height || a->channels != b->channels ||
        a->type != b->type)
        fail_msg("%s: %dx%dx%d type %d against %dx%dx%d type %d", what, a->width, a->height,
                 a->channels, a->type, b->width, b->height, b->channels, b->type);
    size_t row = (size_t)a->width * (size_t)a->channels * (a->type == IO_F32 ? 4 : 1);
    for (int y = 0; y < a->height; y++)
        if (memcmp((const unsigned char *)a->data + (size_t)y * a->stride,
                   (const unsigned char *)b->data + (size_t)y * b->stride, row) != 0)
            fail_msg("%s: row %d differs", what, y);
}

/* Both plugins read path alike, in every conversion (8-bit and float,
 * 0..4 channels). */
static void read_alike(const char *path)
{
    for (int t = 0; t < 2; t++)
        for (int ch = 0; ch <= 4; ch++) {
            io_image a = {0}, b = {0};
            io_error err;
            io_type type = t ? IO_F32 : IO_U8;
            char what[600];
            snprintf(what, sizeof what, "%s as %d channels %s", path, ch, t ? "float" : "8-bit");
            if (exr_p->load(path, type, ch, &a, &err) != IO_OK) fail_msg("%s: EXR plugin: %s", what, err.msg);
            if (oiio_p->load(path, type, ch, &b, &err) != IO_OK) fail_msg("%s: OpenImageIO: %s", what, err.msg);
            same_image(&a, &b, what);
            io_image_free(&a);
            io_image_free(&b);
        }
}

static void random_image(tu_rng *r, io_image *img, int w, int h, int ch, io_type type)
{
    io_error err;
    assert_int_equal(io_image_alloc(img, w, h, ch, type, &err), IO_OK);
    for (int y = 0; y < h; y++) {
        unsigned char *row = (unsigned char *)img->data + (size_t)y * img->stride;
        for (int i = 0; i < w * ch; i++) {
            if (type == IO_U8) row[i] = (unsigned char)tu_int(r, 256);
            else ((float *)row)[i] = tu_range(r, -0.5f, 40.0f); /* depth-like, some outside [0, 1] */
        }
    }
}

/* Files written by each plugin (1-4 channels, 8-bit and float) read alike
 * by both; the EXR plugin's float files give back the exact floats (the
 * samples' depth), its 8-bit ones the exact bytes. */
static void test_written_files_read_alike(void **state)
{
    (void)state;
    need_both();
    tu_rng r = {0xE7A0001u};
    const io_oiio_plugin *writer[2] = {exr_p, oiio_p};
    for (int wi = 0; wi < 2; wi++)
        for (int t = 0; t < 2; t++)
            for (int ch = 1; ch <= 4; ch++) {
                io_image img = {0}, back = {0};
                io_error err;
                io_type type = t ? IO_F32 : IO_U8;
                char path[512], name[64];
                snprintf(name, sizeof name, "w%d_%d_%d.exr", wi, t, ch);
                tu_tmp_path(name, path, sizeof path);
                random_image(&r, &img, 37 + ch, 23, ch, type);
                if (save_with(writer[wi], path, &img, &err) != IO_OK)
                    fail_msg("%s: %s", path, err.msg);
                read_alike(path);
                if (wi == 0) {
                    assert_int_equal(exr_p->load(path, type, ch, &back, &err), IO_OK);
                    same_image(&img, &back, path);
                    io_image_free(&back);
                }
                io_image_free(&img);
                unlink(path);
            }
}

/* Files of an independent writer (oiiotool): compressions, tiles, half and
 * float, a data window off the origin, channel names out of the usual. */
static void test_oiiotool_files_read_alike(void **state)
{
    (void)state;
    need_both();
    if (system("command -v oiiotool >/dev/null 2>&1") != 0) {
        printf("SKIP: oiiotool missing (Debian: openimageio-tools)\n");
        skip();
    }
    static const char *const make[] = {
        "--pattern checker:width=4:height=4:color1=0.1,0.9,0.3:color2=0.7,0.2,0.5 31x17 3 -d half "
        "--compression piz",
        "--pattern fill:topleft=0,0,0,0:topright=1,0,0,0.5:bottomleft=0,1,0,1:bottomright=0,0,1,0.25 "
        "29x19 4 -d float --tile 16 16 --compression rle",
        "--pattern noise:type=uniform:min=-1:max=4:seed=7 25x13 1 --origin +3+5 -d float --compression none",
        "--pattern constant:color=0.25,0.5,0.75 9x7 3 --chnames Z,B,Y -d float",
        "--pattern constant:color=0.6 5x5 1 --chnames A -d half",
        "--pattern noise:type=gaussian:mean=0.5:stddev=0.3:seed=3 21x11 2 --chnames Y,A -d half "
        "--compression zips",
        "--pattern noise:type=uniform:seed=5 16x16 4 -d half --compression b44",
        "--pattern noise:type=uniform:seed=9 12x10 5 --chnames R,G,B,A,Z -d float --compression pxr24",
    };
    for (size_t i = 0; i < sizeof make / sizeof make[0]; i++) {
        char path[512], name[32], cmd[1024];
        snprintf(name, sizeof name, "oiiotool%zu.exr", i);
        tu_tmp_path(name, path, sizeof path);
        snprintf(cmd, sizeof cmd, "oiiotool %s -o '%s'", make[i], path);
        if (system(cmd) != 0) fail_msg("failed: %s", cmd);
        read_alike(path);
        unlink(path);
    }
}

/* Refusals: another format (named OpenImageIO, nothing written), a
 * truncated file, a garbled one, a missing one; no descriptor left open. */
static void test_refusals(void **state)
{
    (void)state;
    if (!exr_p) {
        printf("SKIP: %s\n", skip_why);
        skip();
    }
    int fds = tu_count_fds();
    tu_rng r = {0xE7A0002u};
    io_image img = {0}, out = {0};
    io_error err;
    char good[512], bad[512], tif[512];
    tu_tmp_path("good.exr", good, sizeof good);
    tu_tmp_path("bad.exr", bad, sizeof bad);
    tu_tmp_path("x.tif", tif, sizeof tif);
    random_image(&r, &img, 64, 48, 3, IO_F32);
    assert_int_equal(save_with(exr_p, good, &img, &err), IO_OK);

    /* another format: refused on save (nothing written) and on load */
    assert_int_equal(save_with(exr_p, tif, &img, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, tif));
    assert_non_null(strstr(err.msg, "OpenImageIO"));
    FILE *f = fopen(tif, "rb");
    assert_non_null(f);
    assert_int_equal(fgetc(f), EOF);
    fclose(f);
    f = fopen(bad, "wb");
    assert_non_null(f);
    fputs("P6\n2 2\n255\n0123456789ab", f);
    fclose(f);
    assert_int_equal(exr_p->load(bad, IO_U8, 0, &out, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "OpenImageIO"));
    assert_null(out.data);

    /* the good file cut short, at several lengths */
    f = fopen(good, "rb");
    assert_non_null(f);
    unsigned char buf[1 << 16];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    assert_true(n > 400 && n < sizeof buf);
    size_t cuts[] = {4, 40, 200, n / 2, n - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        f = fopen(bad, "wb");
        assert_non_null(f);
        assert_int_equal(fwrite(buf, 1, cuts[i], f), cuts[i]);
        fclose(f);
        io_result res = exr_p->load(bad, IO_F32, 1, &out, &err);
        if (res == IO_OK) fail_msg("%zu of %zu bytes: read as whole", cuts[i], n);
        assert_int_equal(res, IO_ERR_FORMAT);
        assert_non_null(strstr(err.msg, bad));
        assert_null(out.data);
    }
    /* the magic number, then garbage */
    for (size_t i = 4; i < 300; i++) buf[i] = (unsigned char)tu_int(&r, 256);
    f = fopen(bad, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(buf, 1, 300, f), 300);
    fclose(f);
    assert_int_not_equal(exr_p->load(bad, IO_F32, 0, &out, &err), IO_OK);
    assert_non_null(strstr(err.msg, bad));
    assert_null(out.data);

    /* missing */
    unlink(bad);
    assert_int_not_equal(exr_p->load(bad, IO_F32, 0, &out, &err), IO_OK);
    assert_non_null(strstr(err.msg, bad));

    io_image_free(&img);
    unlink(good);
    unlink(tif);
    assert_int_equal(tu_count_fds(), fds);
}

TU_MAIN(setup, NULL,
        cmocka_unit_test(test_written_files_read_alike),
        cmocka_unit_test(test_oiiotool_files_read_alike),
        cmocka_unit_test(test_refusals))
