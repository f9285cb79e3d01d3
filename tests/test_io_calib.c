/* test_io_calib.c - OpenCV calibration files (src/io/io_calib.c): the
 * samples under samples/calib (written by hand after OpenCV's published
 * FileStorage format: the calibration tutorial's out_camera_data.yml with
 * its extra keys, a two-channel "2f" matrix and comments, the XML form,
 * the K/D fisheye form), the variants calibration tools write (the old
 * sample's capitalised keys, ROS camera_info without the tag, a stereo
 * file, plain sequences, 8/12/14 coefficients), and every bad input with
 * the file, line, key and reason in the message. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/io/io_calib.h"
#include "support/files.h"

static kin_lens parse_ok(const char *text, int camera)
{
    kin_lens L;
    io_error err;
    memset(&L, 0, sizeof L);
    io_result r = io_calib_parse("t.yml", text, strlen(text), camera, &L, &err);
    if (r != IO_OK) fail_msg("refused: %s", err.msg);
    return L;
}

/* The message must hold every fragment (NULL-terminated). */
static void parse_bad(const char *text, const char *name, const char *const *frag)
{
    kin_lens L;
    memset(&L, 0x5a, sizeof L);
    kin_lens before = L;
    io_error err;
    memset(&err, 0, sizeof err);
    io_result r = io_calib_parse(name, text, strlen(text), 0, &L, &err);
    if (r == IO_OK) fail_msg("accepted: %s", text);
    for (int i = 0; frag[i]; i++)
        if (!strstr(err.msg, frag[i]))
            fail_msg("message '%s' lacks '%s'", err.msg, frag[i]);
    assert_memory_equal(&L, &before, sizeof L); /* untouched */
}

/* The calibration file `rel` of the repository, camera `camera`, loaded
 * (a refusal fails the test with its message). */
static kin_lens load_sample(const char *rel, int camera)
{
    char p[512];
    kin_lens L;
    io_error err;
    tu_root_path(rel, p, sizeof p);
    if (io_calib_load(p, camera, &L, &err) != IO_OK) fail_msg("%s", err.msg);
    return L;
}

static void result_samples(void **state)
{
    (void)state;
    kin_lens L = load_sample("samples/calib/hmd_left.yml", 0);
    assert_int_equal(L.model, KIN_LENS_BROWN);
    assert_int_equal(L.width, 640);
    assert_int_equal(L.height, 480);
    NEAR(L.fx, 5.3182147638291553e+02, 0);
    NEAR(L.fy, 5.3244081209177625e+02, 0);
    NEAR(L.cx, 3.1820911370453001e+02, 0);
    NEAR(L.cy, 2.4167300942111271e+02, 0);
    NEAR(L.skew, 0, 0);
    NEAR(L.k[0], -2.9103742911374220e-01, 0);
    NEAR(L.k[1], 1.0218663100493720e-01, 0);
    NEAR(L.k[2], 7.0311962281531006e-04, 0);
    NEAR(L.k[3], -1.0874157336118529e-03, 0);
    NEAR(L.k[4], -1.7311900478122741e-02, 0);
    NEAR(L.k[5], 0, 0);
    assert_true(kin_lens_distorts(&L));
    L = load_sample("samples/calib/hmd_right.xml", 1);
    assert_int_equal(L.model, KIN_LENS_BROWN);
    assert_int_equal(L.width, 640);
    NEAR(L.fx, 5.3310933859204113e+02, 0);
    NEAR(L.cy, 2.3891482099620541e+02, 0);
    NEAR(L.k[4], -1.4258839501221170e-02, 0);
    L = load_sample("samples/calib/fisheye_KD.yml", 0);
    assert_int_equal(L.model, KIN_LENS_FISHEYE);
    assert_int_equal(L.width, 848);
    assert_int_equal(L.height, 800);
    NEAR(L.fx, 2.8618112182617188e+02, 0);
    NEAR(L.k[3], 7.7704913914203640e-03, 0);
}

static void result_variants(void **state)
{
    (void)state;
    /* OpenCV 2's tutorial sample: capitalised keys, rows 5 cols 1 */
    kin_lens L = parse_ok("%YAML:1.0\n"
                          "calibration_Time: \"08/19/11 20:44:38\"\n"
                          "image_Width: 640\nimage_Height: 480\n"
                          "# flags:  +fix_aspectRatio\n"
                          "Camera_Matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                          "   data: [ 6.5746697810243404e+002, 0., 3.1950000000000000e+002, 0.,\n"
                          "       6.5746697810243404e+002, 2.3950000000000000e+002, 0., 0., 1. ]\n"
                          "Distortion_Coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n"
                          "   dt: d\n   data: [ -4.1802327018241026e-001, 5.0715243805833121e-001, 0., 0.,\n"
                          "       -5.7843596847939704e-001 ]\n",
                          0);
    assert_int_equal(L.model, KIN_LENS_BROWN);
    NEAR(L.fx, 657.46697810243404, 1e-12);
    NEAR(L.k[4], -0.57843596847939704, 1e-15);
    assert_int_equal(L.width, 640);
    /* ROS camera_info: no header, no tag, no dt, distortion_model */
    L = parse_ok("image_width: 1280\nimage_height: 800\ncamera_name: narrow_stereo\n"
                 "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [415.1, 0., 665.5, 0., 410.5, 460.1, 0., 0., 1.]\n"
                 "distortion_model: plumb_bob\n"
                 "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [-0.0177, -0.0073, 0.0058, -0.0001, 0.]\n"
                 "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1., 0., 0.,\n    0., 1., 0.,\n    0., 0., 1.]\n",
                 0);
    NEAR(L.cx, 665.5, 0);
    NEAR(L.k[2], 0.0058, 0);
    /* a stereo file (stereo_calib's intrinsics.yml): M1 D1 M2 D2, 8 coefficients */
    static const char st[] =
        "%YAML:1.0\n---\nM1: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., 501., 240., 0., 0., 1. ]\n"
        "D1: !!opencv-matrix\n   rows: 1\n   cols: 8\n   dt: d\n"
        "   data: [ 0.1, 0.01, 0., 0., 0.001, 0.2, 0.02, 0.002 ]\n"
        "M2: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 510., 0., 330., 0., 511., 250., 0., 0., 1. ]\n"
        "D2: !!opencv-matrix\n   rows: 1\n   cols: 8\n   dt: d\n"
        "   data: [ 0.2, 0.02, 0., 0., 0.002, 0.3, 0.03, 0.003 ]\n";
    L = parse_ok(st, 0);
    NEAR(L.fx, 500, 0);
    NEAR(L.k[7], 0.002, 0);
    assert_int_equal(L.width, 0); /* no size in the file */
    L = parse_ok(st, 1);
    NEAR(L.fx, 510, 0);
    NEAR(L.k[5], 0.3, 0);
    /* XML fisheye (the tutorial sample with fisheye_model 1), 4x1 float */
    L = parse_ok("<?xml version=\"1.0\"?>\n<opencv_storage>\n<!-- comment -->\n"
                 "<image_width>848</image_width>\n<image_height>800</image_height>\n"
                 "<fisheye_model>1</fisheye_model>\n"
                 "<camera_matrix type_id=\"opencv-matrix\">\n  <rows>3</rows>\n  <cols>3</cols>\n"
                 "  <dt>d</dt>\n  <data>\n    286. 0. 421. 0.\n    286.5 403. 0. 0. 1.</data></camera_matrix>\n"
                 "<distortion_coefficients type_id=\"opencv-matrix\">\n  <rows>4</rows>\n  <cols>1</cols>\n"
                 "  <dt>f</dt>\n  <data>\n    -8.25e-03 4.53e-02 -4.27e-02 7.77e-03</data></distortion_coefficients>\n"
                 "<extra><nested><deeper>1</deeper></nested></extra>\n"
                 "</opencv_storage>\n",
                 0);
    assert_int_equal(L.model, KIN_LENS_FISHEYE);
    NEAR(L.fy, 286.5, 0);
    NEAR(L.k[1], 4.53e-02, 0);
    /* plain sequences (std::vector written by FileStorage), 14 with zero tilt */
    L = parse_ok("%YAML:1.0\ncameraMatrix: [ 600., 0., 320., 0., 600., 240., 0., 0., 1. ]\n"
                 "distCoeffs: [ -0.2, 0.05, 0., 0., 0., 0., 0., 0., 0.001, 0., 0.002, 0., 0., 0. ]\n",
                 0);
    assert_int_equal(L.model, KIN_LENS_BROWN);
    NEAR(L.k[10], 0.002, 0);
    /* K and D with 5 coefficients: Brown; with fisheye_model 0 and 4: Brown */
    L = parse_ok("%YAML:1.0\nK: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                 "   data: [ 296., 0., 161., 0., 296., 120., 0., 0., 1. ]\n"
                 "D: !!opencv-matrix\n   rows: 1\n   cols: 4\n   dt: d\n   data: [ -0.3, 0.1, 0., 0. ]\n"
                 "fisheye_model: 0\n",
                 0);
    assert_int_equal(L.model, KIN_LENS_BROWN);
    /* skew kept (cv::fisheye's alpha * fx) */
    L = parse_ok("%YAML:1.0\nK: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                 "   data: [ 296., 0.5, 161., 0., 296., 120., 0., 0., 1. ]\n"
                 "D: !!opencv-matrix\n   rows: 4\n   cols: 1\n   dt: d\n   data: [ 0.01, 0., 0., 0. ]\n",
                 0);
    assert_int_equal(L.model, KIN_LENS_FISHEYE);
    NEAR(L.skew, 0.5, 0);
}

static const char GOOD_K[] = "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                             "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n";
static const char GOOD_D[] = "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n"
                             "   dt: d\n   data: [ -0.2, 0.05, 0., 0., 0. ]\n";

static void bad(const char *body, const char *f1, const char *f2)
{
    const char *frag[] = {"cam.yml", f1, f2, NULL};
    parse_bad(body, "cam.yml", frag);
}

/* The refused inputs of validity_bad_inputs: the file is pre, then
 * GOOD_K (K), post, then GOOD_D (D); its message names cam.yml, f1 and
 * f2. */
#define YAML "%YAML:1.0\n"
enum { K = 1, D = 1 };
static const struct bad_case {
    const char *pre;
    int k;
    const char *post;
    int d;
    const char *f1, *f2;
} BAD[] = {
    { YAML "image_width: 640\n",
      0, "", 0,
      "no camera matrix", "camera_matrix" },
    { YAML,
      K, "", 0,
      "camera_matrix", "no distortion" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., 500., 240., 0., 0. ]\n",
      0, "", 0,
      "cam.yml:6: camera_matrix", "8 numbers" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 2\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., 500., 240. ]\n",
      0, "", 0,
      "camera_matrix", "3 x 3" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: \"2f\"\n"
        "   data: [ 1, 2, 3, 4, 5, 6, 7, 8, 9 ]\n",
      0, "", D,
      "camera_matrix", "dt '2f'" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., .Nan, 240., 0., 0., 1. ]\n",
      0, "", D,
      "cam.yml:6: camera_matrix", "'.Nan' is not a number" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., 500., 240., 0.1, 0., 1. ]\n",
      0, "", D,
      "camera_matrix", "not a camera matrix" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ -500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n",
      0, "", D,
      "camera_matrix", "fx = -500" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., 500., 240.,\n  0., 0., 1.\n",
      0, "", D,
      "cam.yml:6: camera_matrix", "without its ']'" },
    { YAML "camera_matrix: !!opencv-matrix\n   rows: 3\n   dt: d\n"
        "   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n",
      0, "", D,
      "camera_matrix", "cols is missing" },
    { YAML,
      K, "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 6\n   dt: d\n"
        "   data: [ 1, 2, 3, 4, 5, 6 ]\n", 0,
      "distortion_coefficients", "6 coefficients" },
    { YAML,
      K, "distortion_coefficients: !!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n"
        "   data: [ 1, 2, 3, 4 ]\n", 0,
      "distortion_coefficients", "1 x N" },
    { YAML,
      K, "distortion_coefficients: [ 0.1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.01, 0 ]\n", 0,
      "tilted-sensor", "tauX = 0.01" },
    { YAML "fisheye_model: 1\n",
      K, "", D,
      "distortion_coefficients", "a fisheye lens has 4" },
    { YAML "fisheye_model: 2\n",
      K, "", D,
      "cam.yml:2: fisheye_model", "0..1" },
    { YAML "distortion_model: omnidir\n",
      K, "", D,
      "distortion_model", "'omnidir' is not a lens model" },
    { YAML "image_width: 640\n",
      K, "", D,
      "image_width without image_height", "cam.yml:2" },
    { YAML "image_width: 0\nimage_height: 480\n",
      K, "", D,
      "image_width", "'0' is not an integer" },
    { YAML,
      K, "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: d\n"
        "   data: [ 1 ]\n", 0,
      "distortion_coefficients", "1 coefficients" },
    { YAML,
      K, "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 4\n   dt: d\n"
        "   data: [ -1e7, 0, 0, 0 ]\n", 0,
      "distortion_coefficients", "folds over" },
    { YAML "this line has no colon\n",
      0, "", 0,
      "cam.yml:2", "expected 'key: value'" },
    { "   \n\n",
      0, "", 0,
      "cam.yml", "empty file" },
    { "<?xml version=\"1.0\"?>\n<storage></storage>\n",
      0, "", 0,
      "cam.yml:2", "not <opencv_storage>" },
    { "<?xml version=\"1.0\"?>\n<opencv_storage>\n"
        "<camera_matrix type_id=\"opencv-matrix\">\n"
        "<rows>3</rows><cols>3</cols><dt>d</dt><data>1 0 0 0 1 0 0 0 1</data>\n"
        "</opencv_storage>\n",
      0, "", 0,
      "camera_matrix", "not closed" },
    { "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n",
      0, "", 0,
      "cam.yml:2", "<opencv_storage> is not closed" },
    { "<?xml version=\"1.0\"?>\n<opencv_storage>\n"
        "<camera_matrix type_id=\"opencv-matrix\">"
        "<rows>3</rows><cols>3</cols><dt>d</dt><data>1 0 0 0 1 0 0 0 1 7</data></camera_matrix>\n"
        "<D>0 0 0 0 0</D></opencv_storage>\n",
      0, "", 0,
      "camera_matrix", "10 numbers" },
};

static void validity_bad_inputs(void **state)
{
    (void)state;
    char b[2048];
    for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; i++) {
        const struct bad_case *c = &BAD[i];
        snprintf(b, sizeof b, "%s%s%s%s", c->pre, c->k ? GOOD_K : "", c->post, c->d ? GOOD_D : "");
        bad(b, c->f1, c->f2);
    }
    /* NUL bytes */
    kin_lens L;
    io_error err;
    static const char nul[] = "%YAML:1.0\n\0camera_matrix: 1\n";
    assert_int_equal(io_calib_parse("bin.yml", nul, sizeof nul - 1, 0, &L, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "bin.yml: not a text file"));
}

static void validity_files(void **state)
{
    (void)state;
    kin_lens L;
    io_error err;
    char p[512];
    assert_int_equal(io_calib_load("/nonexistent/calib.yml", 0, &L, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "/nonexistent/calib.yml"));
    tu_root_path("samples", p, sizeof p);
    assert_int_equal(io_calib_load(p, 0, &L, &err), IO_ERR_READ);
    assert_non_null(strstr(err.msg, "directory"));
    /* a file cut in the middle of a matrix: named with its line */
    tu_tmp_path("cut.yml", p, sizeof p);
    tu_write_text(p, "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
          "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 5.3e+02, 0., 3.2e+02, 0.,\n       5.3e+02, 2.4e+");
    int fds = tu_count_fds();
    assert_int_equal(io_calib_load(p, 0, &L, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "cut.yml:9: camera_matrix"));
    assert_int_equal(tu_count_fds(), fds);
    remove(p);
}

TU_MAIN_NAMED("io_calib", NULL, NULL,
              cmocka_unit_test(result_samples),
              cmocka_unit_test(result_variants),
              cmocka_unit_test(validity_bad_inputs),
              cmocka_unit_test(validity_files))
