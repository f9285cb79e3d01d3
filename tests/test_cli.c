/* test_cli.c - the egofuse program: error cases (message naming the input,
 * exit code, no half-written output) and small end-to-end results on
 * models and scenes that the test writes itself. */
#include "support/testutil.h"

#include <cmocka.h>
#include "support/files.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"
#include "support/io_images.h"

static char out[65536];

/* Runs egofuse with a NULL-terminated argument list; output in out. */
#define run(...) tu_runl(out, sizeof out, tu_bin(), __VA_ARGS__)

/* A number option of render and run: both show `help` in --help;
 * render refuses bad0 and bad1, run refuses 'x', each with exit 2 and a
 * message that names the option and the value. */
static void number_option(const char *opt, const char *help, const char *bad0, const char *bad1)
{
    char want[64];
    const char *bad[2] = {bad0, bad1};
    assert_int_equal(run("render", "--help", NULL), 0);
    assert_non_null(strstr(out, help));
    for (int i = 0; i < 2; i++) {
        assert_int_equal(run("render", "--scene", "s.txt", "--out", "o", opt, bad[i], NULL), 2);
        snprintf(want, sizeof want, "%s '%s'", opt, bad[i]);
        assert_non_null(strstr(out, want));
    }
    assert_int_equal(run("run", "--help", NULL), 0);
    assert_non_null(strstr(out, help));
    assert_int_equal(run("run", opt, "x", NULL), 2);
    snprintf(want, sizeof want, "%s 'x'", opt);
    assert_non_null(strstr(out, want));
}

/* A glTF with a node "head" and an unskinned quad [x0,x1]x[y0,y1] at depth
 * z facing +Z, normals +Z. */

/* The scene of one frame around quad.gltf and the solid images. */
#define QUAD_SCENE                       \
    "egofuse-scene 1\n"                  \
    "model = quad.gltf\n"                \
    "head_node = head\n"                 \
    "frames = 1\n"                       \
    "fps = 60\n"                         \
    "camera_left = cam_l_%d.png\n"       \
    "camera_right = cam_r_%d.png\n"      \
    "virtual_left = virt_l_%d.png\n"     \
    "virtual_right = virt_r_%d.png\n"

/* ------------------------------------------------------------- usage */

static void usage_errors(void **state)
{
    (void)state;
    assert_int_equal(run(NULL), 2);
    assert_non_null(strstr(out, "usage: egofuse"));
    assert_int_equal(run("frobnicate", NULL), 2);
    assert_non_null(strstr(out, "unknown command 'frobnicate'"));
    assert_int_equal(run("--help", NULL), 0);
    assert_int_equal(run("mask", "--help", NULL), 0);
    assert_non_null(strstr(out, "--fov-y"));
    assert_int_equal(run("render", "--help", NULL), 0);
    assert_int_equal(run("demo", "--help", NULL), 0);
    assert_int_equal(run("mask", "m.glb", "--width", "abc", NULL), 2);
    assert_non_null(strstr(out, "--width 'abc'"));
    assert_int_equal(run("mask", "m.glb", "--width", "64", "--height", "64", "--fov-y", "60",
                         "--eye", "0,0,1", "--target", "0,0", "--out", "x.png", NULL), 2);
    assert_non_null(strstr(out, "--target '0,0'"));
    assert_int_equal(run("mask", "m.glb", "--width", "64", "--height", "64", "--fov-y", "60",
                         "--eye", "0,0,1", "--target", "0,0,0", NULL), 2);
    assert_non_null(strstr(out, "--out is required"));
    assert_int_equal(run("mask", "m.glb", "--width", "64", "--height", "64", "--fov-y", "60",
                         "--eye", "0,0,1", "--target", "0,0,1", "--out", "x.png", NULL), 2);
    assert_non_null(strstr(out, "same point"));
    assert_int_equal(run("mask", "m.glb", "--width", "64", "--height", "64", "--fov-y", "nan",
                         "--eye", "0,0,1", "--target", "0,0,0", "--out", "x.png", NULL), 2);
    assert_int_equal(run("render", "--scene", "s.txt", NULL), 2);
    assert_non_null(strstr(out, "--out is required"));
    assert_int_equal(run("render", "--bogus", NULL), 2);
    /* --refine BAND: 1..64 px */
    number_option("--refine", "--refine BAND", "0", "65");
    /* --aa N: 0, 4, 8 or 16 samples per pixel */
    number_option("--aa", "--aa N", "3", "32");
}

/* ------------------------------------------------------------- mask */

static void mask_bad_models(void **state)
{
    (void)state;
    char model[512], png[512];
    tu_tmp_path("missing.glb", model, sizeof model);
    tu_tmp_path("bad_mask.png", png, sizeof png);
    remove(png);
    assert_int_equal(run("mask", model, "--width", "32", "--height", "32", "--fov-y", "60",
                         "--eye", "0,0,2", "--target", "0,0,0", "--out", png, NULL), 1);
    assert_non_null(strstr(out, "missing.glb"));
    assert_false(tu_exists(png));

    tu_tmp_path("corrupt.gltf", model, sizeof model);
    tu_write_text(model, "{\"asset\":{\"version\":\"2.0\"}, \"nodes\": [ {\"mesh\": 0 } ");
    assert_int_equal(run("mask", model, "--width", "32", "--height", "32", "--fov-y", "60",
                         "--eye", "0,0,2", "--target", "0,0,0", "--out", png, NULL), 1);
    assert_non_null(strstr(out, "corrupt.gltf"));
    assert_false(tu_exists(png));

    tu_tmp_path("quad.gltf", model, sizeof model);
    tu_write_quad_gltf(model, -1, 1, -1, 1, 0);
    assert_int_equal(run("mask", model, "--width", "32", "--height", "32", "--fov-y", "60",
                         "--eye", "0,0,2", "--target", "0,0,0", "--anim", "0",
                         "--out", png, NULL), 1);
    assert_non_null(strstr(out, "0 animations"));
    assert_false(tu_exists(png));
    /* A NaN in the model's data: rejected, named, nothing written. */
    tu_tmp_path("nan.gltf", model, sizeof model);
    tu_write_quad_gltf(model, -1, NAN, -1, 1, 0);
    assert_int_equal(run("mask", model, "--width", "32", "--height", "32", "--fov-y", "60",
                         "--eye", "0,0,2", "--target", "0,0,0", "--out", png, NULL), 1);
    assert_non_null(strstr(out, "nan.gltf"));
    assert_non_null(strstr(out, "non-finite"));
    assert_false(tu_exists(png));

    tu_tmp_path("quad.gltf", model, sizeof model);
    /* Output folder that does not exist: an error naming it, nothing left. */
    char bad[600];
    snprintf(bad, sizeof bad, "%s.nodir/m.png", model);
    assert_int_equal(run("mask", model, "--width", "32", "--height", "32", "--fov-y", "60",
                         "--eye", "0,0,2", "--target", "0,0,0", "--out", bad, NULL), 1);
    assert_non_null(strstr(out, "m.png"));
}

/* A quad [-1,1]^2 seen from z = 2 with a 90 degree FOV covers exactly the
 * middle half of the image: pixel centres 16.5 .. 47.5 of 64. */
static void mask_exact_quad(void **state)
{
    (void)state;
    char model[512], png[512], nrm[512], dep[512];
    tu_tmp_path("quad2.gltf", model, sizeof model);
    tu_tmp_path("quad2_mask.png", png, sizeof png);
    tu_tmp_path("quad2_n.png", nrm, sizeof nrm);
    tu_tmp_path("quad2_d.exr", dep, sizeof dep);
    tu_write_quad_gltf(model, -1, 1, -1, 1, 0);
    int rc = run("mask", model, "--width", "64", "--height", "64", "--fov-y", "90",
                 "--eye", "0,0,2", "--target", "0,0,0", "--up", "0,1,0", "--out", png,
                 "--normals", nrm, "--depth", dep, NULL);
    if (rc != 0) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
    io_image m, n, d;
    io_error err;
    assert_int_equal(io_image_load(png, IO_U8, 0, &m, &err), IO_OK);
    assert_int_equal(m.channels, 1);
    assert_int_equal(m.width, 64);
    const uint8_t *p = m.data;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            int inside = x >= 16 && x < 48 && y >= 16 && y < 48;
            assert_int_equal(p[y * 64 + x], inside ? 255 : 0);
        }
    assert_int_equal(io_image_load(nrm, IO_U8, 3, &n, &err), IO_OK);
    const uint8_t *q = n.data;
    /* Facing the camera: view-space normal (0,0,1) -> (128,128,255). */
    assert_int_equal(q[(32 * 64 + 32) * 3 + 2], 255);
    assert_int_equal(q[(32 * 64 + 32) * 3 + 0], 128);
    assert_int_equal(q[0], 0);
    assert_int_equal(io_image_load(dep, IO_F32, 1, &d, &err), IO_OK);
    const float *z = d.data;
    /* Plane at distance 2: z_ndc = (f+n)/(f-n) - 2fn/((f-n) * 2). */
    double fn = 100.0, nn = 0.01;
    double zn = (fn + nn) / (fn - nn) - 2.0 * fn * nn / ((fn - nn) * 2.0);
    assert_true(fabs(z[32 * 64 + 32] - (zn * 0.5 + 0.5)) < 1e-6);
    assert_true(z[0] == 1.0f);
    io_image_free(&m);
    io_image_free(&n);
    io_image_free(&d);
}

static void mask_shared_models(void **state)
{
    (void)state;
    char model[512], png[512];
    tu_shared_path("gltf/CesiumMan/CesiumMan.glb", model, sizeof model);
    if (!tu_exists(model)) {
        printf("SKIP shared glTF models not found at %s\n", model);
        skip();
    }
    tu_tmp_path("cesium.png", png, sizeof png);
    int rc = run("mask", model, "--width", "96", "--height", "128", "--fov-y", "50",
                 "--eye", "0,1,3", "--target", "0,0.8,0", "--anim", "0", "--time", "0.5",
                 "--out", png, NULL);
    if (rc != 0) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
    io_image m;
    io_error err;
    assert_int_equal(io_image_load(png, IO_U8, 1, &m, &err), IO_OK);
    int covered = 0;
    const uint8_t *p = m.data;
    for (int i = 0; i < 96 * 128; i++) {
        assert_true(p[i] == 0 || p[i] == 255);
        covered += p[i] == 255;
    }
    /* A standing figure fills part of the frame, not none and not all. */
    assert_true(covered > 300);
    assert_true(covered < 96 * 128 / 2);
    io_image_free(&m);
}

/* --------------------------------------------------------- render */

static void write_scene(const char *dir, int cam_w, int cam_h)
{
    char p[600];
    snprintf(p, sizeof p, "%s/quad.gltf", dir);
    /* 0.2 m square, 0.6 m in front of the head: both cameras see it. */
    tu_write_quad_gltf(p, -0.1f, 0.1f, -0.1f, 0.1f, -0.6f);
    tu_write_scene_images(dir, cam_w, cam_h, 1280, 800);
    snprintf(p, sizeof p, "%s/scene.txt", dir);
    tu_write_text(p, QUAD_SCENE);
}

/* A fresh folder tmp/name in dir[512] (created), its scene.txt in
 * scene[600] and its out folder in odir[600]. */
static void scene_dir(const char *name, char *dir, char *scene, char *odir)
{
    tu_tmp_path(name, dir, 512);
    char cmd[700];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(scene, 600, "%s/scene.txt", dir);
    snprintf(odir, 600, "%s/out", dir);
}

static void render_end_to_end(void **state)
{
    (void)state;
    char dir[512], scene[600], odir[600], png[700];
    scene_dir("scene_ok", dir, scene, odir);
    write_scene(dir, 640, 480);
    int rc = run("render", "--scene", scene, "--out", odir, "--quiet", NULL);
    if (rc != 0) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
    for (int e = 0; e < 2; e++) {
        snprintf(png, sizeof png, "%s/%s_0000.png", odir, e ? "right" : "left");
        io_image r;
        io_error err;
        assert_int_equal(io_image_load(png, IO_U8, 3, &r, &err), IO_OK);
        assert_int_equal(r.width, 1280);
        assert_int_equal(r.height, 800);
        const uint8_t *p = r.data;
        /* Corners (outside the viewport and the quad) are the virtual scene. */
        static const uint8_t virt_rgb[3] = {10, 40, 90};
        assert_memory_equal(p, virt_rgb, 3);
        assert_memory_equal(p + 3 * (1280 * 800 - 1), virt_rgb, 3);
        /* The quad is seen near the centre (shifted by the eye offset): the
         * camera's colour, lit, replaces the virtual scene there. */
        int hits = 0;
        for (int x = 560; x < 720; x++) {
            const uint8_t *c = p + 3 * (400 * 1280 + x);
            if (c[0] > 100 && c[0] > c[2]) hits++;
        }
        assert_true(hits > 40);
        io_image_free(&r);
    }
}

static void render_bad_inputs(void **state)
{
    (void)state;
    char dir[512], scene[600], odir[600], png[700];
    scene_dir("scene_bad", dir, scene, odir);

    /* Missing scene file. */
    assert_int_equal(run("render", "--scene", scene, "--out", odir, NULL), 1);
    assert_non_null(strstr(out, "scene.txt"));

    /* A camera image of the wrong size: named, and no output frame. */
    write_scene(dir, 320, 240);
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--quiet", NULL), 1);
    assert_non_null(strstr(out, "cam_l_0.png"));
    assert_non_null(strstr(out, "320x240"));
    snprintf(png, sizeof png, "%s/left_0000.png", odir);
    assert_false(tu_exists(png));

    /* A missing frame is found before anything is written. */
    write_scene(dir, 640, 480);
    snprintf(png, sizeof png, "%s/virt_r_0.png", dir);
    remove(png);
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--quiet", NULL), 1);
    assert_non_null(strstr(out, "virt_r_0.png"));
    snprintf(png, sizeof png, "%s/left_0000.png", odir);
    assert_false(tu_exists(png));

    /* The demo without generated samples says how to make them. */
    char empty[600];
    snprintf(empty, sizeof empty, "%s/no_samples", dir);
    assert_int_equal(run("demo", "--samples", empty, "--out", odir, NULL), 1);
    assert_non_null(strstr(out, "no_samples/scene.txt is missing"));
    assert_non_null(strstr(out, "make demo"));

    /* Frames beyond the scene. */
    write_scene(dir, 640, 480);
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--first", "3", NULL), 1);
    assert_non_null(strstr(out, "1 frames"));
}

/* egofuse eval on two frames: every method measured, the CSV has the
 * documented columns; bad options are refused. */
static void eval_small(void **state)
{
    (void)state;
    char csv[512];
    tu_tmp_path("eval.csv", csv, sizeof csv);
    assert_int_equal(run("eval", "--frames", "abc", NULL), 2);
    assert_int_equal(run("eval", "--noise", "-5", NULL), 2);
    int rc = run("eval", "--frames", "2", "--quiet", "--csv", csv, NULL);
    if (rc != 0) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
    FILE *f = fopen(csv, "r");
    assert_non_null(f);
    char line[1024];
    assert_non_null(fgets(line, sizeof line, f));
    static const char cols[] = "method,setting,iou,bf1,bf3,fp_area,fn_area,psnr,ms_per_frame";
    assert_true(strncmp(line, cols, strlen(cols)) == 0);
    int rows = 0, refine = 0;
    while (fgets(line, sizeof line, f)) {
        rows++;
        if (!strncmp(line, "refine,", 7)) {
            refine++;
            double iou = atof(strchr(line + 7, ',') + 1);
            assert_true(iou > 0.5 && iou <= 1.0);
        }
    }
    fclose(f);
    assert_true(rows >= 4);
    assert_true(refine >= 1);
}

/* `render --pose tracking` and its options: every error case is named,
 * and nothing is written. */
static void render_pose_options(void **state)
{
    (void)state;
    char dir[512], scene[600], odir[600], p[700], png[700];
    scene_dir("scene_pose", dir, scene, odir);
    write_scene(dir, 640, 480);

    /* usage errors (exit 2) */
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "bogus", NULL), 2);
    assert_non_null(strstr(out, "--pose 'bogus'"));
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--calib", "c.txt", NULL), 2);
    assert_non_null(strstr(out, "--calib needs --pose tracking"));
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "animation",
                         "--no-filter", NULL), 2);
    assert_non_null(strstr(out, "--no-filter needs --pose tracking"));
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--predict", "500", NULL), 2);
    assert_non_null(strstr(out, "--predict '500'"));
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--predict", "nan", NULL), 2);
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", NULL), 2);

    /* the scene names no tracking file */
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--quiet", NULL), 1);
    assert_non_null(strstr(out, "no 'tracking' file"));

    /* a tracking file that is missing, then malformed (file and line) */
    snprintf(p, sizeof p, "%s/scene.txt", dir);
    tu_write_text(p, QUAD_SCENE "tracking = track.txt\n");
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--quiet", NULL), 1);
    assert_non_null(strstr(out, "track.txt"));
    snprintf(p, sizeof p, "%s/track.txt", dir);
    tu_write_text(p, "egofuse-track 1\nt 0 SL 0 1\n");
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--quiet", NULL), 1);
    assert_non_null(strstr(out, "track.txt:2:"));

    /* a good recording, a missing calibration file */
    tu_write_text(p, "egofuse-track 1\nt 0 SL -0.2 1 0 SR 0.2 1 0\n");
    char calib[700];
    snprintf(calib, sizeof calib, "%s/no_calib.txt", dir);
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--calib", calib, "--quiet", NULL), 1);
    assert_non_null(strstr(out, "no_calib.txt"));

    /* a model without the arm rig's joints cannot be posed from tracking:
     * the missing joints are listed */
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "tracking",
                         "--quiet", NULL), 1);
    assert_non_null(strstr(out, "quad.gltf"));
    assert_non_null(strstr(out, "missing joints"));
    assert_non_null(strstr(out, "R_palm"));
    snprintf(png, sizeof png, "%s/left_0000.png", odir);
    assert_false(tu_exists(png));

    /* the same scene still renders from its animation */
    assert_int_equal(run("render", "--scene", scene, "--out", odir, "--pose", "animation",
                         "--quiet", NULL), 0);
    assert_true(tu_exists(png));
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(usage_errors),
        cmocka_unit_test(mask_bad_models),
        cmocka_unit_test(mask_exact_quad),
        cmocka_unit_test(mask_shared_models),
        cmocka_unit_test(render_end_to_end),
        cmocka_unit_test(render_bad_inputs),
        cmocka_unit_test(render_pose_options),
        cmocka_unit_test(eval_small))
