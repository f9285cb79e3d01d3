/* test_io_image.c - io_image_*: exact PNG and EXR round trips, channel and
 * type conversion, errors, and the atomic write (temp file + rename). */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/files.h"

#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../src/io/io.h"
#include "support/io_images.h"

static void fill_random(io_image *img, tu_rng *rng)
{
    for (int y = 0; y < img->height; y++) {
        unsigned char *row = (unsigned char *)img->data + (size_t)y * img->stride;
        for (int x = 0; x < img->width * img->channels; x++) {
            if (img->type == IO_U8)
                row[x] = (unsigned char)tu_int(rng, 256);
            else {
                /* any finite float, depths included: mantissa and exponent */
                const float m = tu_range(rng, -4.0f, 4.0f);   /* drawn in order */
                float v = m * powf(10.0f, (float)tu_int(rng, 7) - 3.0f);
                memcpy(row + (size_t)x * 4, &v, 4);
            }
        }
    }
}

static void round_trip(const char *name, int w, int h, int ch, io_type t,
                       uint64_t seed)
{
    char path[1024];
    tu_tmp_path(name, path, sizeof path);
    io_image img, back;
    io_error err;
    tu_rng rng = {seed};
    assert_int_equal(io_image_alloc(&img, w, h, ch, t, &err), IO_OK);
    fill_random(&img, &rng);
    io_result r = io_image_save(path, &img, &err);
    if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(r, IO_OK);
    r = io_image_load(path, t, 0, &back, &err);
    if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(r, IO_OK);
    tu_same_image(&img, &back);
    io_image_free(&back);
    /* asking for the same channel count explicitly gives the same bytes */
    assert_int_equal(io_image_load(path, t, ch, &back, &err), IO_OK);
    tu_same_image(&img, &back);
    io_image_free(&back);
    io_image_free(&img);
    assert_null(img.data);
}

static void png_round_trips_exactly(void **state)
{
    (void)state;
    round_trip("rt_rgb.png", 37, 23, 3, IO_U8, 1);
    round_trip("rt_rgba.png", 16, 9, 4, IO_U8, 2);
    round_trip("rt_grey.png", 31, 17, 1, IO_U8, 3);
    round_trip("rt_grey_alpha.png", 5, 7, 2, IO_U8, 4);
}

static void exr_float_round_trips_exactly(void **state)
{
    (void)state;
    round_trip("rt_depth.exr", 29, 19, 1, IO_F32, 5);
    round_trip("rt_rgba.exr", 13, 11, 4, IO_F32, 6);
    round_trip("rt_rgb.tif", 7, 5, 3, IO_F32, 7);
}

static void alloc_is_zeroed_and_checked(void **state)
{
    (void)state;
    io_image img;
    io_error err;
    assert_int_equal(io_image_alloc(&img, 3, 2, 3, IO_F32, &err), IO_OK);
    assert_int_equal(img.stride, 3 * 3 * 4);
    for (size_t i = 0; i < img.stride * 2; i++)
        assert_int_equal(((unsigned char *)img.data)[i], 0);
    io_image_free(&img);
    assert_int_equal(io_image_alloc(&img, 0, 2, 3, IO_U8, &err), IO_ERR_ARGS);
    assert_null(img.data);
    assert_int_equal(io_image_alloc(&img, 2, 2, 5, IO_U8, &err), IO_ERR_ARGS);
    assert_int_equal(io_image_alloc(&img, 2, 2, 3, (io_type)7, &err), IO_ERR_ARGS);
    io_image_free(NULL);
}

static unsigned char px(const io_image *img, int x, int y, int c)
{
    return ((const unsigned char *)img->data)[(size_t)y * img->stride +
                                              (size_t)(x * img->channels + c)];
}

static void channel_conversion(void **state)
{
    (void)state;
    char grey[1024], rgb[1024], rgba[1024];
    io_image g, c3, c4, out;
    io_error err;
    tu_rng rng = {42};
    tu_tmp_path("conv_grey.png", grey, sizeof grey);
    tu_tmp_path("conv_rgb.png", rgb, sizeof rgb);
    tu_tmp_path("conv_rgba.png", rgba, sizeof rgba);
    assert_int_equal(io_image_alloc(&g, 6, 4, 1, IO_U8, &err), IO_OK);
    assert_int_equal(io_image_alloc(&c3, 6, 4, 3, IO_U8, &err), IO_OK);
    assert_int_equal(io_image_alloc(&c4, 6, 4, 4, IO_U8, &err), IO_OK);
    fill_random(&g, &rng);
    fill_random(&c3, &rng);
    fill_random(&c4, &rng);
    assert_int_equal(io_image_save(grey, &g, &err), IO_OK);
    assert_int_equal(io_image_save(rgb, &c3, &err), IO_OK);
    assert_int_equal(io_image_save(rgba, &c4, &err), IO_OK);

    /* grey -> RGBA: replicated, opaque */
    assert_int_equal(io_image_load(grey, IO_U8, 4, &out, &err), IO_OK);
    assert_int_equal(out.channels, 4);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 6; x++) {
            for (int k = 0; k < 3; k++) assert_int_equal(px(&out, x, y, k), px(&g, x, y, 0));
            assert_int_equal(px(&out, x, y, 3), 255);
        }
    io_image_free(&out);
    /* RGB -> RGBA: opaque alpha; RGB -> grey keeps R */
    assert_int_equal(io_image_load(rgb, IO_U8, 4, &out, &err), IO_OK);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 6; x++) {
            for (int k = 0; k < 3; k++) assert_int_equal(px(&out, x, y, k), px(&c3, x, y, k));
            assert_int_equal(px(&out, x, y, 3), 255);
        }
    io_image_free(&out);
    assert_int_equal(io_image_load(rgb, IO_U8, 1, &out, &err), IO_OK);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 6; x++) assert_int_equal(px(&out, x, y, 0), px(&c3, x, y, 0));
    io_image_free(&out);
    /* RGBA -> RGB drops alpha; RGBA -> grey+alpha keeps R and alpha */
    assert_int_equal(io_image_load(rgba, IO_U8, 3, &out, &err), IO_OK);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 6; x++)
            for (int k = 0; k < 3; k++) assert_int_equal(px(&out, x, y, k), px(&c4, x, y, k));
    io_image_free(&out);
    assert_int_equal(io_image_load(rgba, IO_U8, 2, &out, &err), IO_OK);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 6; x++) {
            assert_int_equal(px(&out, x, y, 0), px(&c4, x, y, 0));
            assert_int_equal(px(&out, x, y, 1), px(&c4, x, y, 3));
        }
    io_image_free(&out);
    /* 8-bit -> float: v / 255 */
    assert_int_equal(io_image_load(rgb, IO_F32, 4, &out, &err), IO_OK);
    assert_int_equal(out.type, IO_F32);
    for (int y = 0; y < 4; y++) {
        const float *row = (const float *)((const unsigned char *)out.data + (size_t)y * out.stride);
        for (int x = 0; x < 6; x++) {
            for (int k = 0; k < 3; k++)
                assert_float_equal(row[x * 4 + k], px(&c3, x, y, k) / 255.0f, 1e-7f);
            assert_true(row[x * 4 + 3] == 1.0f);
        }
    }
    io_image_free(&out);
    io_image_free(&g);
    io_image_free(&c3);
    io_image_free(&c4);
}

/* img saved as the scratch file name, and loaded back into back as 8 bits
 * with ch channels (0: the file's). */
static void save_load(const char *name, const io_image *img, int ch, io_image *back)
{
    char path[1024];
    tu_tmp_path(name, path, sizeof path);
    io_error err;
    assert_int_equal(io_image_save(path, img, &err), IO_OK);
    assert_int_equal(io_image_load(path, IO_U8, ch, back, &err), IO_OK);
}

static void float_to_png_is_clamped_and_scaled(void **state)
{
    (void)state;
    io_image f, back;
    io_error err;
    assert_int_equal(io_image_alloc(&f, 4, 1, 1, IO_F32, &err), IO_OK);
    float *v = f.data;
    v[0] = -0.5f; v[1] = 2.0f; v[2] = 51.0f / 255.0f; v[3] = 1.0f;
    save_load("clamp.png", &f, 0, &back);
    assert_int_equal(back.channels, 1);
    const unsigned char *b = back.data;
    assert_int_equal(b[0], 0);
    assert_int_equal(b[1], 255);
    assert_int_equal(b[2], 51);
    assert_int_equal(b[3], 255);
    io_image_free(&back);
    io_image_free(&f);
}

static void padded_stride_is_honoured(void **state)
{
    (void)state;
    io_image big, view, back;
    io_error err;
    tu_rng rng = {77};
    assert_int_equal(io_image_alloc(&big, 10, 6, 3, IO_U8, &err), IO_OK);
    fill_random(&big, &rng);
    view = big;
    view.width = 7;  /* a 7-pixel view of 10-pixel rows */
    save_load("stride.png", &view, 3, &back);
    tu_same_image(&view, &back);
    io_image_free(&back);
    io_image_free(&big);
}

static void read_errors(void **state)
{
    (void)state;
    char path[1024];
    io_image img;
    io_error err;
    tu_tmp_path("no_such_image.png", path, sizeof path);
    memset(&img, 0x5A, sizeof img);
    assert_int_equal(io_image_load(path, IO_U8, 3, &img, &err), IO_ERR_NOT_FOUND);
    assert_int_equal(err.code, IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "no_such_image.png"));
    assert_null(img.data);

    tu_tmp_path("garbage.png", path, sizeof path);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs("this is not a PNG file at all", f);
    fclose(f);
    assert_int_equal(io_image_load(path, IO_U8, 3, &img, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "garbage.png"));
    assert_null(img.data);

    assert_int_equal(io_image_load(path, IO_U8, 5, &img, &err), IO_ERR_ARGS);
    assert_int_equal(io_image_load(NULL, IO_U8, 3, &img, &err), IO_ERR_ARGS);
}

static void save_errors_leave_files_untouched(void **state)
{
    (void)state;
    char dir[1024], path[1200], tmp[1300], sub[1400];
    io_image img;
    io_error err;
    assert_int_equal(io_image_alloc(&img, 4, 4, 3, IO_U8, &err), IO_OK);

    tu_tmp_path("save_errs", dir, sizeof dir);
    mkdir(dir, 0777);

    /* unknown extension */
    snprintf(path, sizeof path, "%s/out.xyz", dir);
    assert_int_equal(io_image_save(path, &img, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "out.xyz"));
    assert_false(tu_exists(path));

    /* a folder that does not exist */
    snprintf(path, sizeof path, "%s/missing_dir/out.png", dir);
    assert_int_equal(io_image_save(path, &img, &err), IO_ERR_WRITE);
    assert_non_null(strstr(err.msg, "out.png"));
    assert_false(tu_exists(path));

    /* an existing file and a bad image: untouched */
    snprintf(path, sizeof path, "%s/keep.png", dir);
    tu_write_text(path, "precious");
    io_image bad = img;
    bad.channels = 0;
    assert_int_equal(io_image_save(path, &bad, &err), IO_ERR_ARGS);
    bad = img;
    bad.stride = 2;
    assert_int_equal(io_image_save(path, &bad, &err), IO_ERR_ARGS);
    bad = img;
    bad.data = NULL;
    assert_int_equal(io_image_save(path, &bad, &err), IO_ERR_ARGS);
    assert_true(tu_file_is(path, "precious"));

    /* the temp file cannot be created (a non-empty folder has its name):
     * the existing file stays as it was */
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    assert_int_equal(mkdir(tmp, 0777), 0);
    snprintf(sub, sizeof sub, "%s/x", tmp);
    tu_write_text(sub, "x");
    assert_int_equal(io_image_save(path, &img, &err), IO_ERR_WRITE);
    assert_true(tu_file_is(path, "precious"));
    remove(sub);
    remove(tmp);

    /* the rename fails (the target is a non-empty folder): the temp file
     * is removed */
    snprintf(path, sizeof path, "%s/folder.png", dir);
    assert_int_equal(mkdir(path, 0777), 0);
    snprintf(sub, sizeof sub, "%s/x", path);
    tu_write_text(sub, "x");
    assert_int_equal(io_image_save(path, &img, &err), IO_ERR_WRITE);
    assert_non_null(strstr(err.msg, "folder.png"));
    assert_int_equal(tu_names_in(dir, ".tmp.", NULL), 0);
    remove(sub);
    remove(path);

    /* and a good save replaces the file */
    snprintf(path, sizeof path, "%s/keep.png", dir);
    assert_int_equal(io_image_save(path, &img, &err), IO_OK);
    assert_false(tu_file_is(path, "precious"));
    assert_int_equal(tu_names_in(dir, ".tmp.", NULL), 0);
    io_image_free(&img);
}

TU_MAIN_NAMED("io_image", NULL, NULL,
              cmocka_unit_test(png_round_trips_exactly),
              cmocka_unit_test(exr_float_round_trips_exactly),
              cmocka_unit_test(alloc_is_zeroed_and_checked),
              cmocka_unit_test(channel_conversion),
              cmocka_unit_test(float_to_png_is_clamped_and_scaled),
              cmocka_unit_test(padded_stride_is_honoured),
              cmocka_unit_test(read_errors),
              cmocka_unit_test(save_errors_leave_files_untouched))
