/* test_cli_view.c - `--view crop|reproject` of `egofuse render` and
 * `egofuse run` (docs/eyeview.md): a generated scene (a glTF quad 0.35 m
 * in front of the head, a camera image of a ramp, a grey virtual scene)
 * renders with either view, the reprojected hand smaller than the
 * cropped one (the eye is D behind the camera) and the output of the
 * display's size; bad options (an unknown view, an IPD or a camera offset
 * out of range, reprojection with --aa), on the command line or in the
 * cockpit file ([run] view, [hmd] ipd / camera-offset), exit 2 with the
 * option and the range named and write nothing. Soft silhouettes are
 * render's default in both views, --hard-edges the binary mask, and
 * --soft-edges with --aa a usage error. */
#include "support/testutil.h"
#include <cmocka.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"
#include "support/files.h"

static char out[65536];

/* egofuse with the arguments (NULL-terminated), its output in out */
#define run(...) tu_runl(out, sizeof out, tu_bin(), __VA_ARGS__)


static void write_image(const char *path, int w, int h, int ramp)
{
    io_image img;
    io_error err;
    assert_int_equal(io_image_alloc(&img, w, h, 3, IO_U8, &err), IO_OK);
    uint8_t *d = img.data;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            uint8_t *q = d + (size_t)y * img.stride + 3 * (size_t)x;
            q[0] = ramp ? (uint8_t)(x * 255 / w) : 60;
            q[1] = ramp ? (uint8_t)(y * 255 / h) : 60;
            q[2] = ramp ? 200 : 60;
        }
    assert_int_equal(io_image_save(path, &img, &err), IO_OK);
    io_image_free(&img);
}

static char dir[512], scene[700];

static int setup(void **state)
{
    (void)state;
    char cmd[1800], p[1200];
    tu_tmp_path("cli_view", dir, sizeof dir);
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s/cam' '%s/v'", dir, dir, dir);
    assert_int_equal(system(cmd), 0);
    snprintf(p, sizeof p, "%s/quad.gltf", dir);
    tu_write_quad_gltf(p, -0.05f, 0.05f, -0.05f, 0.05f, -0.35f);
    const char *img[4][2] = {{"cam/l_0000.png", "c"}, {"cam/r_0000.png", "c"},
                             {"v/l_0000.png", "v"}, {"v/r_0000.png", "v"}};
    for (int i = 0; i < 4; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, img[i][0]);
        if (img[i][1][0] == 'c') write_image(p, 640, 480, 1);
        else write_image(p, 1280, 800, 0);
    }
    snprintf(scene, sizeof scene, "%s/scene.txt", dir);
    tu_write_text(scene, "egofuse-scene 1\nmodel = quad.gltf\nframes = 1\nfps = 60\n"
          "camera_left = cam/l_%04d.png\ncamera_right = cam/r_%04d.png\n"
          "virtual_left = v/l_%04d.png\nvirtual_right = v/r_%04d.png\n");
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    return tu_rm_rf(dir);
}

/* Pixels of an output that are not the grey virtual scene. */
static long hand_pixels(const char *path)
{
    io_image img;
    io_error err;
    assert_int_equal(io_image_load(path, IO_U8, 3, &img, &err), IO_OK);
    assert_int_equal(img.width, 1280);
    assert_int_equal(img.height, 800);
    long n = 0;
    const uint8_t *d = img.data;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            const uint8_t *q = d + (size_t)y * img.stride + 3 * (size_t)x;
            n += q[0] != 60 || q[1] != 60 || q[2] != 60;
        }
    io_image_free(&img);
    return n;
}

static void result_render_both_views(void **state)
{
    (void)state;
    char o1[800], o2[800], p[900];
    snprintf(o1, sizeof o1, "%s/crop", dir);
    snprintf(o2, sizeof o2, "%s/reproject", dir);
    int rc = run("render", "--scene", scene, "--out", o1, "--quiet", "--view", "crop", NULL);
    if (rc != 0) fail_msg("rc %d: %s", rc, out);
    rc = run("render", "--scene", scene, "--out", o2, "--quiet", "--view", "reproject", NULL);
    if (rc != 0) fail_msg("rc %d: %s", rc, out);
    snprintf(p, sizeof p, "%s/left_0000.png", o1);
    long nc = hand_pixels(p);
    snprintf(p, sizeof p, "%s/left_0000.png", o2);
    long nr = hand_pixels(p);
    /* the eye sees the quad from 0.35 m, the camera from 0.265 m: in the
     * display the crop's quad is (0.35 / 0.265)^2 * ratio^2 ~ 1.5 times as
     * large; the reprojection's is the eye's own */
    print_message("NOTE quad in the left output: crop %ld px, reproject %ld px\n", nc, nr);
    assert_true(nr > 20000);
    assert_true(nc > nr + nr / 4);
    /* a wider IPD moves the eyes, the same sizes */
    char o3[800];
    snprintf(o3, sizeof o3, "%s/ipd", dir);
    rc = run("render", "--scene", scene, "--out", o3, "--quiet", "--view", "reproject",
             "--hmd-ipd", "0.07", NULL);
    if (rc != 0) fail_msg("rc %d: %s", rc, out);
    snprintf(p, sizeof p, "%s/left_0000.png", o3);
    assert_true(tu_exists(p));
}

/* Bytes of two outputs that differ (both 1280x800 RGB). */
static long differing(const char *a, const char *b)
{
    io_image x, y;
    io_error err;
    assert_int_equal(io_image_load(a, IO_U8, 3, &x, &err), IO_OK);
    assert_int_equal(io_image_load(b, IO_U8, 3, &y, &err), IO_OK);
    long n = 0;
    for (int r = 0; r < x.height; r++)
        for (int i = 0; i < 3 * x.width; i++)
            n += ((const uint8_t *)x.data)[(size_t)r * x.stride + (size_t)i] !=
                 ((const uint8_t *)y.data)[(size_t)r * y.stride + (size_t)i];
    io_image_free(&x);
    io_image_free(&y);
    return n;
}

/* Soft silhouettes are render's default in both views (--soft-edges
 * gives the same bytes), --hard-edges the binary mask: the two differ only
 * along the quad's outline, a band of a few thousand bytes, not its inside. */
static void result_soft_edges_default(void **state)
{
    (void)state;
    static const char *view[2] = {"crop", "reproject"};
    for (int v = 0; v < 2; v++) {
        char o[3][800], p[3][900];
        const char *flag[3] = {NULL, "--soft-edges", "--hard-edges"};
        for (int k = 0; k < 3; k++) {
            snprintf(o[k], sizeof o[k], "%s/edges_%s%d", dir, view[v], k);
            int rc = run("render", "--scene", scene, "--out", o[k], "--quiet", "--view", view[v],
                         flag[k] ? flag[k] : NULL, NULL);
            if (rc != 0) fail_msg("rc %d: %s", rc, out);
            snprintf(p[k], sizeof p[k], "%.780s/left_0000.png", o[k]);
        }
        assert_int_equal(differing(p[0], p[1]), 0);
        long d = differing(p[0], p[2]);
        print_message("NOTE %s view, soft against hard edges: %ld bytes differ\n", view[v], d);
        assert_true(d > 500);
        assert_true(d < 3 * 40000);
    }
}

static void expect_usage(const char *what, const char *dir_out, const char *const *args, int n)
{
    char *argv[24];
    int k = 0;
    argv[k++] = (char *)tu_bin();
    for (int i = 0; i < n; i++) argv[k++] = (char *)args[i];
    argv[k] = NULL;
    int rc = tu_run(argv, out, sizeof out);
    if (rc != 2 || !strstr(out, what))
        fail_msg("rc %d (expected 2), output without '%s': %s", rc, what, out);
    char p[900];
    snprintf(p, sizeof p, "%s/left_0000.png", dir_out);
    assert_false(tu_exists(p));
}

static void validity_bad_options(void **state)
{
    (void)state;
    char o[800];
    snprintf(o, sizeof o, "%s/bad", dir);
    const char *a1[] = {"render", "--scene", scene, "--out", o, "--view", "eye"};
    expect_usage("--view 'eye': crop", o, a1, 7);
    const char *a2[] = {"render", "--scene", scene, "--out", o, "--view", "reproject",
                        "--hmd-ipd", "0.2"};
    expect_usage("--hmd-ipd '0.2': 0.04..0.09 m", o, a2, 9);
    const char *a3[] = {"render", "--scene", scene, "--out", o, "--view", "reproject",
                        "--hmd-camera-offset", "0.3"};
    expect_usage("--hmd-camera-offset '0.3': 0..0.25 m", o, a3, 9);
    const char *a4[] = {"render", "--scene", scene, "--out", o, "--view", "reproject",
                        "--aa", "4"};
    expect_usage("--view reproject: not with --aa 4", o, a4, 9);
    const char *a5[] = {"render", "--scene", scene, "--out", o, "--hmd-ipd", "nan"};
    expect_usage("--hmd-ipd 'nan'", o, a5, 7);
    /* run: D within its own 0..1 m, but not the reprojection's range */
    const char *a6[] = {"run", "--view", "reproject", "--hmd-camera-offset", "0.5"};
    expect_usage("the camera offset D (--hmd-camera-offset) 0.5 m is outside 0..0.25 m", o, a6,
                 5);
    const char *a9[] = {"render", "--scene", scene, "--out", o, "--soft-edges", "--aa", "4"};
    expect_usage("--soft-edges: not with --aa", o, a9, 8);
    const char *a10[] = {"run", "--soft-edges", "--aa", "8"};
    expect_usage("--soft-edges: not with --aa", o, a10, 4);
    const char *a7[] = {"run", "--view", "sideways"};
    expect_usage("--view 'sideways'", o, a7, 3);
    /* the cockpit file's key: [run] view = ... is --view */
    char conf[700];
    snprintf(conf, sizeof conf, "%s/cockpit.conf", dir);
    tu_write_text(conf, "[run]\nview = sideways\n");
    const char *a8[] = {"run", "--config", conf};
    expect_usage("--view 'sideways'", o, a8, 3);
    tu_write_text(conf, "[run]\nview = reproject\n[hmd]\nipd = 0.1\n");
    expect_usage("--hmd-ipd '0.1': 0.04..0.09 m", o, a8, 3);
    tu_write_text(conf, "[run]\nview = reproject\n[hmd]\ncamera-offset = 0.3\n");
    expect_usage("(--hmd-camera-offset) 0.3 m is outside 0..0.25 m", o, a8, 3);
}

TU_MAIN_NAMED("cli_view", setup, teardown,
              cmocka_unit_test(result_render_both_views),
              cmocka_unit_test(result_soft_edges_default),
              cmocka_unit_test(validity_bad_options))
