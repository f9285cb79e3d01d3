/* test_io_png.c - the built-in PNG and PPM/PGM reader and writer (io_image.c)
 * against an independent producer and consumer (ffmpeg's PNG and PNM
 * codecs) and against the OpenImageIO plugin it replaced for these formats
 * (same pixel values, bit for bit, in every conversion). */
#include "support/testutil.h"

#include <cmocka.h>
#include "support/files.h"
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"
#include "support/io_images.h"

static int have_ffmpeg(void)
{
    return system("command -v ffmpeg >/dev/null 2>&1") == 0;
}

static int sh(const char *cmd)
{
    int rc = system(cmd);
    if (rc != 0) fprintf(stderr, "failed (%d): %s\n", rc, cmd);
    return rc;
}

/* Ours against the OpenImageIO plugin on one file, every conversion. */
static void same_as_oiio(const char *path)
{
    for (int t = 0; t < 2; t++)
        for (int ch = 0; ch <= 4; ch++) {
            io_image a, b;
            io_error err;
            io_type type = t ? IO_F32 : IO_U8;
            unsetenv("EGOFUSE_IMAGE");
            assert_int_equal(io_image_load(path, type, ch, &a, &err), IO_OK);
            setenv("EGOFUSE_IMAGE", "oiio", 1);
            io_result r = io_image_load(path, type, ch, &b, &err);
            unsetenv("EGOFUSE_IMAGE");
            if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
            assert_int_equal(r, IO_OK);
            tu_same_image(&a, &b);
            io_image_free(&a);
            io_image_free(&b);
        }
}

/* ffmpeg writes PNGs of every kind; ffmpeg's own decode of each (RGBA,
 * 8 or 16 bits) is the expected value of ours. */
static void reads_what_ffmpeg_writes(void **state)
{
    (void)state;
    if (!have_ffmpeg()) {
        printf("SKIP: ffmpeg missing: PNG reader not checked against an independent writer\n");
        skip();
    }
    static const struct { const char *fmt; int bits; } kinds[] = {
        {"gray", 8}, {"monob", 8}, {"ya8", 8}, {"rgb24", 8}, {"rgba", 8}, {"pal8", 8},
        {"gray16be", 16}, {"ya16be", 16}, {"rgb48be", 16}, {"rgba64be", 16},
    };
    char dir[1024], png[1200], raw[1200], cmd[4096];
    tu_tmp_path("png_ffmpeg", dir, sizeof dir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(sh(cmd), 0);
    const int W = 37, H = 23;
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        snprintf(png, sizeof png, "%s/%s.png", dir, kinds[k].fmt);
        snprintf(raw, sizeof raw, "%s/%s.raw", dir, kinds[k].fmt);
        /* a test pattern with an alpha ramp */
        const char *src = "-f lavfi -i testsrc2=s=38x24:d=1 -vf \"format=rgba,scale=37:23,"
                          "geq=r='r(X,Y)':g='g(X,Y)':b='b(X,Y)':a='mod(X*7+Y*13,256)'\"";
        if (!strcmp(kinds[k].fmt, "pal8"))
            snprintf(cmd, sizeof cmd, "ffmpeg -v error -y -f lavfi -i testsrc2=s=38x24:d=1 "
                     "-filter_complex \"[0]scale=37:23,split[a][b];[a]palettegen=max_colors=40[p];"
                     "[b][p]paletteuse\" -frames:v 1 '%s'", png);
        else
            snprintf(cmd, sizeof cmd, "ffmpeg -v error -y %s -pix_fmt %s -frames:v 1 '%s'", src,
                     kinds[k].fmt, png);
        assert_int_equal(sh(cmd), 0);
        snprintf(cmd, sizeof cmd, "ffmpeg -v error -y -i '%s' -f rawvideo -pix_fmt %s '%s'", png,
                 kinds[k].bits == 16 ? "rgba64le" : "rgba", raw);
        assert_int_equal(sh(cmd), 0);
        size_t n;
        unsigned char *want = tu_read_file(raw, &n);
        assert_int_equal(n, (size_t)W * H * 4 * (kinds[k].bits / 8));
        io_image img;
        io_error err;
        if (kinds[k].bits == 8) {
            assert_int_equal(io_image_load(png, IO_U8, 4, &img, &err), IO_OK);
            for (int y = 0; y < H; y++)
                assert_memory_equal((unsigned char *)img.data + (size_t)y * img.stride,
                                    want + (size_t)y * W * 4, (size_t)W * 4);
        } else {
            assert_int_equal(io_image_load(png, IO_F32, 4, &img, &err), IO_OK);
            const uint16_t *w16 = (const uint16_t *)want;
            for (int y = 0; y < H; y++)
                for (int i = 0; i < W * 4; i++) {
                    float v = ((const float *)((unsigned char *)img.data +
                                               (size_t)y * img.stride))[i];
                    assert_true(v == (float)w16[(size_t)y * W * 4 + (size_t)i] *
                                         (1.0f / 65535.0f));
                }
        }
        io_image_free(&img);
        free(want);
        same_as_oiio(png);
    }
}

/* What we write, ffmpeg (an independent decoder) reads as written. */
static void ffmpeg_reads_what_we_write(void **state)
{
    (void)state;
    if (!have_ffmpeg()) {
        printf("SKIP: ffmpeg missing: PNG writer not checked against an independent reader\n");
        skip();
    }
    static const char *const ext[] = {"png", "ppm", "pgm"};
    char dir[1024], path[1200], raw[1200], cmd[4096];
    tu_tmp_path("png_write", dir, sizeof dir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(sh(cmd), 0);
    tu_rng rng = {2026};
    for (int e = 0; e < 3; e++)
        for (int ch = 1; ch <= 4; ch++) {
            if (e == 1 && ch != 3) continue;
            if (e == 2 && ch != 1) continue;
            for (int t = 0; t < 2; t++) {
                int W = 1 + tu_int(&rng, 300), H = 1 + tu_int(&rng, 60);
                io_image img;
                io_error err;
                io_type type = t ? IO_F32 : IO_U8;
                assert_int_equal(io_image_alloc(&img, W, H, ch, type, &err), IO_OK);
                size_t n = (size_t)W * H * ch;
                unsigned char *expect = malloc(n);
                for (size_t i = 0; i < n; i++) {
                    /* smooth areas and noise, so the filters all get used */
                    unsigned v = (i / 97) % 3 ? (unsigned)tu_int(&rng, 256) : (unsigned)(i & 255);
                    if (type == IO_U8) {
                        ((unsigned char *)img.data)[i] = (unsigned char)v;
                    } else {
                        ((float *)img.data)[i] = (float)v / 255.0f;
                    }
                    expect[i] = (unsigned char)v;
                }
                snprintf(path, sizeof path, "%s/w_%d_%d.%s", dir, ch, t, ext[e]);
                snprintf(raw, sizeof raw, "%s/w_%d_%d.raw", dir, ch, t);
                assert_int_equal(io_image_save(path, &img, &err), IO_OK);
                static const char *const fmts[5] = {"", "gray", "ya8", "rgb24", "rgba"};
                snprintf(cmd, sizeof cmd, "ffmpeg -v error -y -i '%s' -f rawvideo -pix_fmt %s '%s'",
                         path, fmts[ch], raw);
                assert_int_equal(sh(cmd), 0);
                size_t got;
                unsigned char *r = tu_read_file(raw, &got);
                assert_int_equal(got, n);
                assert_memory_equal(r, expect, n);
                free(r);
                free(expect);
                io_image_free(&img);
                same_as_oiio(path);
            }
        }
}

/* img saved as the scratch file name by our writer, or (oiio 1) by the
 * OpenImageIO plugin; loaded back by ours as 8 bits into back. */
static void save_with(int oiio, const char *name, const io_image *img, io_image *back)
{
    char path[1024];
    tu_tmp_path(name, path, sizeof path);
    io_error err;
    if (oiio) setenv("EGOFUSE_IMAGE", "oiio", 1);
    io_result r = io_image_save(path, img, &err);
    unsetenv("EGOFUSE_IMAGE"); /* ours reads it back */
    assert_int_equal(r, IO_OK);
    assert_int_equal(io_image_load(path, IO_U8, 0, back, &err), IO_OK);
}

/* float -> 8 bits gives what OpenImageIO gave (round, clamp, NaN 0). */
static void float_conversion_matches_oiio(void **state)
{
    (void)state;
    io_image img;
    io_error err;
    const int W = 1024;
    assert_int_equal(io_image_alloc(&img, W, 3, 1, IO_F32, &err), IO_OK);
    float *v = img.data;
    tu_rng rng = {5};
    for (int i = 0; i < W; i++) {
        v[i] = (float)(i % 512) / 510.0f - 0.001f;  /* ramp across [0,1] and beyond */
        v[W + i] = tu_range(&rng, -0.2f, 1.2f);
        v[2 * W + i] = ((float)(i % 256) + 0.25f * (float)(i / 256)) / 255.0f;
    }
    v[0] = -1.0f / 0.0f;
    v[1] = 1.0f / 0.0f;
    io_image x, y;
    save_with(0, "fconv_ours.png", &img, &x);
    save_with(1, "fconv_oiio.png", &img, &y);
    tu_same_image(&x, &y);
    io_image_free(&x);
    io_image_free(&y);
    io_image_free(&img);
}

static void truncated_png_says_so(void **state)
{
    (void)state;
    char path[1024];
    tu_tmp_path("cut.png", path, sizeof path);
    io_image img;
    io_error err;
    assert_int_equal(io_image_alloc(&img, 64, 64, 3, IO_U8, &err), IO_OK);
    tu_rng rng = {9};
    for (size_t i = 0; i < 64 * 64 * 3; i++) ((unsigned char *)img.data)[i] = (unsigned char)tu_int(&rng, 256);
    assert_int_equal(io_image_save(path, &img, &err), IO_OK);
    io_image_free(&img);
    size_t n;
    unsigned char *b = tu_read_file(path, &n);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n / 2, f), n / 2);
    fclose(f);
    free(b);
    assert_int_equal(io_image_load(path, IO_U8, 3, &img, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "cut.png"));
    assert_non_null(strstr(err.msg, "truncated"));
    assert_null(img.data);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(reads_what_ffmpeg_writes),
        cmocka_unit_test(ffmpeg_reads_what_we_write),
        cmocka_unit_test(float_conversion_matches_oiio),
        cmocka_unit_test(truncated_png_says_so))
