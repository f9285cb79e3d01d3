/* test_cli_lens.c - calibrated lenses in the program: `egofuse mask
 * --calibration FILE` draws a glTF quad through the hand-written OpenCV
 * calibration of samples/calib (a barrel lens): every pixel of the mask
 * file agrees with the exact silhouette (the ray of the pixel centre,
 * kin_lens_unproject, against the quad) except within the documented
 * 0.71 pinhole px of its outline; a zero-distortion calibration gives the
 * pinhole mask; bad files and options fail with the file and the reason
 * and leave no output; `egofuse run --hmd-calibration` and the cockpit
 * file's `[hmd] calibration` (relative to the file) report a bad
 * calibration before opening anything. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"
#include "support/files.h"
#include "support/io_images.h"
#include "../src/io/io_calib.h"

static char out[65536];

/* egofuse with the arguments (NULL-terminated), its output in out */
#define run(...) tu_runl(out, sizeof out, tu_bin(), __VA_ARGS__)

/* The quad [-0.45,0.38]x[-0.3,0.33] at z = -1 seen from the origin along
 * -Z: its edges reach far into the barrel's periphery. */
#define QX0 -0.45
#define QX1 0.38
#define QY0 -0.3
#define QY1 0.33

static void result_mask_through_barrel(void **state)
{
    (void)state;
    char quad[512], cal[512], png[512], png0[512];
    tu_tmp_path("lens_quad.gltf", quad, sizeof quad);
    tu_tmp_path("lens_mask.png", png, sizeof png);
    tu_tmp_path("lens_mask0.png", png0, sizeof png0);
    tu_root_path("samples/calib/hmd_left.yml", cal, sizeof cal);
    tu_write_quad_gltf(quad, (float)QX0, (float)QX1, (float)QY0, (float)QY1, -1.0f);
    int rc = run("mask", quad, "--calibration", cal, "--eye", "0,0,0", "--target", "0,0,-1",
                 "--out", png, NULL);
    if (rc != 0) fail_msg("rc %d: %s", rc, out);
    kin_lens L;
    io_error err;
    assert_int_equal(io_calib_load(cal, 0, &L, &err), IO_OK);
    io_image m;
    assert_int_equal(io_image_load(png, IO_U8, 1, &m, &err), IO_OK);
    assert_int_equal(m.width, 640);
    assert_int_equal(m.height, 480);
    long truth_n = 0, differ = 0, set = 0;
    double worst = 0;
    for (int y = 0; y < 480; y++)
        for (int x = 0; x < 640; x++) {
            double r[3];
            assert_true(kin_lens_unproject(&L, x + 0.5, y + 0.5, r));
            double a = r[0] / -r[2], b = r[1] / -r[2]; /* the hit on z = -1 */
            int truth = a >= QX0 && a <= QX1 && b >= QY0 && b <= QY1;
            /* distance to the outline in the pinhole render (fx, fy px) */
            double dx = fmin(fabs(a - QX0), fabs(a - QX1)) * L.fx;
            double dy = fmin(fabs(b - QY0), fabs(b - QY1)) * L.fy;
            double d = fmin(dx, dy);
            int got = ((uint8_t *)m.data)[(size_t)y * m.stride + x] != 0;
            truth_n += truth;
            set += got;
            if (got != truth) {
                differ++;
                worst = fmax(worst, d);
                if (!(d <= 0.5 * sqrt(2.0) + 1.0 / 128))
                    fail_msg("pixel (%d, %d) differs %.3f px from the quad's outline", x, y, d);
            }
        }
    print_message("egofuse mask through samples/calib/hmd_left.yml: quad %ld px, %ld differ "
                  "(farthest %.3f pinhole px from the outline)\n", truth_n, differ, worst);
    assert_true(truth_n > 50000);
    assert_true(differ < truth_n / 100);
    io_image_free(&m);

    /* a zero-distortion calibration: the lens's pinhole part; drawn straight,
     * the quad covers more (the barrel pulls the periphery in) */
    char cal0[512];
    tu_tmp_path("lens_zero.yml", cal0, sizeof cal0);
    tu_write_text(cal0, "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                     "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                     "   data: [ 5.3182147638291553e+02, 0., 3.1820911370453001e+02, 0.,\n"
                     "       5.3244081209177625e+02, 2.4167300942111271e+02, 0., 0., 1. ]\n"
                     "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
                     "   data: [ 0., 0., 0., 0., 0. ]\n");
    rc = run("mask", quad, "--calibration", cal0, "--eye", "0,0,0", "--target", "0,0,-1", "--out",
             png0, NULL);
    if (rc != 0) fail_msg("rc %d: %s", rc, out);
    assert_int_equal(io_image_load(png0, IO_U8, 1, &m, &err), IO_OK);
    long set0 = 0, d0 = 0;
    for (int y = 0; y < 480; y++)
        for (int x = 0; x < 640; x++) {
            double a = (x + 0.5 - (L.cx + 0.5)) / L.fx, b = -(y + 0.5 - (L.cy + 0.5)) / L.fy;
            int truth = a >= QX0 && a <= QX1 && b >= QY0 && b <= QY1;
            int got = ((uint8_t *)m.data)[(size_t)y * m.stride + x] != 0;
            set0 += got;
            d0 += got != truth;
        }
    io_image_free(&m);
    print_message("zero distortion: %ld px set, %ld differ from the pinhole quad\n", set0, d0);
    assert_true(d0 <= 4); /* float rounding of the projection at exact edges at most */
    assert_true(set0 > set + 5000);
    remove(png);
    remove(png0);
    remove(cal0);
    remove(quad);
}

static void validity_mask_bad_calibration(void **state)
{
    (void)state;
    char quad[512], cal[512], png[512];
    tu_tmp_path("lens_quad2.gltf", quad, sizeof quad);
    tu_tmp_path("lens_bad.yml", cal, sizeof cal);
    tu_tmp_path("lens_none.png", png, sizeof png);
    tu_write_quad_gltf(quad, -0.5f, 0.5f, -0.5f, 0.5f, -1.0f);
    tu_write_text(cal, "%YAML:1.0\nimage_width: 640\nimage_height: 480\n"
                    "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                    "   data: [ 500., 0., 320., 0., .Nan, 240., 0., 0., 1. ]\n"
                    "distortion_coefficients: [ -0.2, 0.05, 0., 0., 0. ]\n");
    assert_int_equal(run("mask", quad, "--calibration", cal, "--eye", "0,0,0", "--target",
                         "0,0,-1", "--out", png, NULL), 1);
    assert_non_null(strstr(out, "lens_bad.yml:8: camera_matrix: '.Nan' is not a number"));
    assert_false(tu_exists(png));
    assert_int_equal(run("mask", quad, "--calibration", "/nonexistent/c.yml", "--eye", "0,0,0",
                         "--target", "0,0,-1", "--out", png, NULL), 1);
    assert_non_null(strstr(out, "/nonexistent/c.yml: No such file"));
    assert_false(tu_exists(png));
    /* no size in the file and none given */
    tu_write_text(cal, "%YAML:1.0\nK: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]\n"
                    "D: [ -0.2, 0.05, 0., 0., 0. ]\n");
    assert_int_equal(run("mask", quad, "--calibration", cal, "--eye", "0,0,0", "--target",
                         "0,0,-1", "--out", png, NULL), 1);
    assert_non_null(strstr(out, "no image size"));
    assert_false(tu_exists(png));
    /* ... with a size given it works (the calibration is taken at that size) */
    assert_int_equal(run("mask", quad, "--calibration", cal, "--width", "64", "--height", "48",
                         "--eye", "0,0,0", "--target", "0,0,-1", "--out", png, NULL), 0);
    assert_true(tu_exists(png));
    remove(png);
    assert_int_equal(run("mask", quad, "--calibration", cal, "--fov-y", "50", "--eye", "0,0,0",
                         "--target", "0,0,-1", "--out", png, NULL), 2);
    assert_non_null(strstr(out, "exclude each other"));
    assert_false(tu_exists(png));
    remove(cal);
    remove(quad);
}

static void validity_run_bad_calibration(void **state)
{
    (void)state;
    char dir[512], sub[600], cal[700], conf[700];
    tu_tmp_path("lens_cockpit", dir, sizeof dir);
    snprintf(sub, sizeof sub, "mkdir -p '%s/calib'", dir);
    assert_int_equal(system(sub), 0);
    snprintf(cal, sizeof cal, "%s/calib/left.yml", dir);
    tu_write_text(cal, "%YAML:1.0\nimage_width: 1280\nimage_height: 720\n"
                    "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
                    "   data: [ 900., 0., 640., 0., 900., 360., 0., 0., 1. ]\n"
                    "distortion_coefficients: [ -0.2, 0.05, 0., 0., 0. ]\n");
    /* a 16:9 calibration for the paper's 640x480 camera */
    assert_int_equal(run("run", "--scene", "nowhere.txt", "--hmd-camera", "640x480",
                         "--hmd-calibration-left", cal, NULL), 1);
    assert_non_null(strstr(out, "left.yml: calibrated for 1280x720 images, the camera is 640x480"));
    /* the cockpit file: relative to its folder */
    snprintf(conf, sizeof conf, "%s/cockpit.conf", dir);
    tu_write_text(conf, "scene = nowhere.txt\n[hmd]\ncamera = 640x480\ncalibration = calib/missing.yml\n");
    assert_int_equal(run("run", "--config", conf, NULL), 1);
    snprintf(sub, sizeof sub, "%s/calib/missing.yml: No such file", dir);
    if (!strstr(out, sub)) fail_msg("'%s' lacks '%s'", out, sub);
    assert_int_equal(tu_rm_rf(dir), 0);
}

/* render on a scene of a named HMD (hmd = consumer: 1280x1024 cameras):
 * the sample 640x480 calibration is refused with the scene and the sizes
 * named, nothing written; a 1280x1024 one of the same lens renders. */
static void validity_render_named_hmd(void **state)
{
    (void)state;
    char dir[512], p[1200], cmd[1200], out_dir[700];
    tu_tmp_path("lens_named", dir, sizeof dir);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s/cam' '%s/v'", dir, dir);
    assert_int_equal(system(cmd), 0);
    snprintf(p, sizeof p, "%s/quad.gltf", dir);
    tu_write_quad_gltf(p, -0.2f, 0.2f, -0.2f, 0.2f, -0.6f);
    snprintf(p, sizeof p, "%s/cam/l_0000.png", dir);
    tu_write_solid(p, 1280, 1024, 90, 90, 90);
    snprintf(p, sizeof p, "%s/cam/r_0000.png", dir);
    tu_write_solid(p, 1280, 1024, 90, 90, 90);
    snprintf(p, sizeof p, "%s/v/l_0000.png", dir);
    tu_write_solid(p, 2064, 2208, 90, 90, 90);
    snprintf(p, sizeof p, "%s/v/r_0000.png", dir);
    tu_write_solid(p, 2064, 2208, 90, 90, 90);
    char scene[700];
    snprintf(scene, sizeof scene, "%s/scene.txt", dir);
    tu_write_text(scene, "egofuse-scene 1\nmodel = quad.gltf\nframes = 1\nfps = 60\nhmd = consumer\n"
                      "camera_left = cam/l_%04d.png\ncamera_right = cam/r_%04d.png\n"
                      "virtual_left = v/l_%04d.png\nvirtual_right = v/r_%04d.png\n");
    char cal[512];
    tu_root_path("samples/calib/hmd_left.yml", cal, sizeof cal);
    snprintf(out_dir, sizeof out_dir, "%s/out", dir);
    assert_int_equal(run("render", "--scene", scene, "--out", out_dir, "--quiet",
                         "--hmd-calibration", cal, NULL), 1);
    assert_non_null(strstr(out, "scene.txt: the left camera's calibration is for 640x480 images, "
                                "the HMD's camera is 1280x1024"));
    snprintf(p, sizeof p, "%s/left_0000.png", out_dir);
    assert_false(tu_exists(p));
    /* the same lens calibrated at 1280x1024 (a 5:4 sensor) */
    char cal2[700];
    snprintf(cal2, sizeof cal2, "%s/c.yml", dir);
    tu_write_text(cal2, "%YAML:1.0\nimage_width: 1280\nimage_height: 1024\n"
                     "camera_matrix: [ 540., 0., 639.5, 0., 540., 511.5, 0., 0., 1. ]\n"
                     "distortion_coefficients: [ -0.25, 0.07, 0., 0., -0.01 ]\n");
    int rc = run("render", "--scene", scene, "--out", out_dir, "--quiet", "--masks",
                 "--hmd-calibration", cal2, NULL);
    if (rc != 0) fail_msg("rc %d: %s", rc, out);
    assert_true(tu_exists(p));
    /* anti-aliased edges are drawn through the pinhole: refused with a
     * distorting lens, nothing written */
    char out2[760], p2[800];
    snprintf(out2, sizeof out2, "%s/out_aa", dir);
    assert_int_equal(run("render", "--scene", scene, "--out", out2, "--quiet", "--aa", "4",
                         "--hmd-calibration", cal2, NULL), 1);
    assert_non_null(strstr(out, "--aa 4: anti-aliased edges are drawn through the pinhole"));
    snprintf(p2, sizeof p2, "%s/left_0000.png", out2);
    assert_false(tu_exists(p2));
    assert_int_equal(tu_rm_rf(dir), 0);
}

TU_MAIN_NAMED("cli_lens", NULL, NULL,
              cmocka_unit_test(result_mask_through_barrel),
              cmocka_unit_test(validity_mask_bad_calibration),
              cmocka_unit_test(validity_run_bad_calibration),
              cmocka_unit_test(validity_render_named_hmd))
