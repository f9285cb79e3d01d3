/* test_cli_hmd.c - the named HMDs end to end through the programs
 * (docs/kin.md "Named HMDs"): a one-frame sequence of the consumer HMD
 * (gen_samples --hmd consumer: 1280x1024 cameras, 2064x2208 per eye),
 *   - its scene names the HMD (hmd = consumer) and its images have its
 *     sizes;
 *   - `egofuse render` composites it at 2064x2208 per eye with masks of
 *     the eq. 1 crop (957x1024: the width cut), the virtual image outside
 *     the eq. 4 viewport (1539x1647 at (262, 280)) and the hand inside;
 *   - `egofuse run --hmd-preset consumer` (and [hmd] preset = consumer in
 *     a cockpit file) on the recorded frames writes frames of that size,
 *     its --dump names the HMD and renders again to its frame; an option
 *     of its own overrides a field of the preset;
 *   - an unknown HMD name (scene key, --hmd-preset, gen_samples --hmd) is
 *     refused naming it, nothing written. */
#include "support/testutil.h"
#include <cmocka.h>

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"
#include "support/files.h"

static char out[1 << 16];
static char seq[512];       /* the generated sequence's folder */
static char bin_path[600];  /* egofuse */
static char gen_path[700];  /* gen_samples next to it */

static int setup(void **st)
{
    (void)st;
    snprintf(bin_path, sizeof bin_path, "%s", tu_bin());
    tu_gen_path(gen_path, sizeof gen_path);
    return tu_gen_seq("seq_consumer", 1, "consumer", seq, sizeof seq);
}

/* Runs egofuse with a NULL-terminated argument list; output in out. */
#define ego(...) tu_runl(out, sizeof out, bin_path, __VA_ARGS__)

static io_image load(const char *path)
{
    io_image im;
    io_error err;
    if (io_image_load(path, IO_U8, 4, &im, &err) != IO_OK) fail_msg("%s", err.msg);
    return im;
}

/* The largest difference of the R, G, B of pixel (x, y) of two RGBA
 * images (load). */
static int rgb_diff(const io_image *a, const io_image *b, int x, int y)
{
    const uint8_t *u = (const uint8_t *)a->data + (size_t)y * a->stride + 4 * (size_t)x;
    const uint8_t *v = (const uint8_t *)b->data + (size_t)y * b->stride + 4 * (size_t)x;
    int m = 0;
    for (int k = 0; k < 3; k++) m = abs(u[k] - v[k]) > m ? abs(u[k] - v[k]) : m;
    return m;
}

/* Pixels of two RGBA images that differ (rgb_diff): n[k] of them by more
 * than k (k = 0, 1), in[k] of those inside a rectangle. */
typedef struct image_diff { long n[2], in[2]; } image_diff;

/* The image at a (asserted of the consumer display's 2064 x 2208) against
 * the one at b, the rectangle r = x, y, width, height (NULL: none). */
static image_diff display_diff(const char *a, const char *b, const int *r)
{
    io_image A = load(a), B = load(b);
    assert_int_equal(A.width, 2064);
    assert_int_equal(A.height, 2208);
    assert_int_equal(B.width, A.width);
    assert_int_equal(B.height, A.height);
    image_diff d = {{0, 0}, {0, 0}};
    for (int y = 0; y < A.height; y++)
        for (int x = 0; x < A.width; x++) {
            const int m = rgb_diff(&A, &B, x, y);
            const int inside = r && x >= r[0] && x < r[0] + r[2] && y >= r[1] && y < r[1] + r[3];
            for (int k = 0; k < 2; k++) {
                d.n[k] += m > k;
                d.in[k] += inside && m > k;
            }
        }
    io_image_free(&A);
    io_image_free(&B);
    return d;
}

static void check_size(const char *path, int w, int h)
{
    io_image im = load(path);
    if (im.width != w || im.height != h)
        fail_msg("%s is %dx%d, expected %dx%d", path, im.width, im.height, w, h);
    io_image_free(&im);
}

static int file_has(const char *path, const char *text)
{
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    static char buf[1 << 14];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return strstr(buf, text) != NULL;
}

/* The generated sequence: the HMD named, its sizes. */
static void sequence(void **st)
{
    (void)st;
    char p[700];
    snprintf(p, sizeof p, "%s/scene.txt", seq);
    assert_true(file_has(p, "\nhmd = consumer\n"));
    assert_true(file_has(p, "1280x1024 sensor (the pipeline crops columns 161..1117)"));
    io_scene sc;
    io_error err;
    if (io_scene_load(p, &sc, &err) != IO_OK) fail_msg("%s", err.msg);
    assert_string_equal(sc.hmd, "consumer");
    snprintf(p, sizeof p, "%s/cam/left_0000.png", seq);
    check_size(p, 1280, 1024);
    snprintf(p, sizeof p, "%s/virt/right_0000.png", seq);
    check_size(p, 2064, 2208);
}

/* render at the consumer HMD: outputs of its display, masks of its crop,
 * V outside the viewport, the hand inside. */
static void render(void **st)
{
    (void)st;
    char scene[600], o[600];
    snprintf(scene, sizeof scene, "%s/scene.txt", seq);
    tu_tmp_path("render_consumer", o, sizeof o);
    int rc = ego("render", "--scene", scene, "--out", o, "--masks", NULL);
    if (rc != 0) fail_msg("render: exit %d: %s", rc, out);
    assert_non_null(strstr(out, "2064x2208 per eye"));
    const int vp[4] = {262, 280, 1539, 1647}; /* the viewport */
    for (int e = 0; e < 2; e++) {
        const char *eye = e ? "right" : "left";
        char p[700], v[700], m[700];
        snprintf(p, sizeof p, "%s/%s_0000.png", o, eye);
        snprintf(v, sizeof v, "%s/virt/%s_0000.png", seq, eye);
        snprintf(m, sizeof m, "%s/mask_%s_0000.png", o, eye);
        check_size(m, 957, 1024);
        const image_diff d = display_diff(p, v, vp);
        const long inside_diff = d.in[0], outside_diff = d.n[0] - d.in[0];
        if (outside_diff) fail_msg("%s: %ld pixels outside the viewport are not V's", eye, outside_diff);
        /* the arms: several percent of the viewport (about 15% of the crop) */
        if (inside_diff < (long)vp[2] * vp[3] / 50)
            fail_msg("%s: only %ld pixels of the viewport show the camera", eye, inside_diff);
    }
}

/* run on the recorded frames with the preset, from the command line and
 * from a cockpit file; an own option overrides a field. */
static void run(void **st)
{
    (void)st;
    char scene[600], left[600], right[600], o[600], o2[600], conf[600], p[700];
    snprintf(scene, sizeof scene, "%s/scene.txt", seq);
    snprintf(left, sizeof left, "file:%s/cam/left_%%04d.png", seq);
    snprintf(right, sizeof right, "file:%s/cam/right_%%04d.png", seq);
    tu_tmp_path("run_consumer", o, sizeof o);
    char d[600], rd[600], ds[700];
    tu_tmp_path("run_consumer_dump", d, sizeof d);
    tu_tmp_path("run_consumer_dump_render", rd, sizeof rd);
    int rc = ego("run", "--hmd-preset", "consumer", "--scene", scene, "--left", left, "--right",
                 right, "--frames", "1", "--loop", "--out", o, "--dump", d, "--quiet", NULL);
    if (rc != 0) fail_msg("run --hmd-preset consumer: exit %d: %s", rc, out);
    for (int e = 0; e < 2; e++) {
        snprintf(p, sizeof p, "%s/%s_0000.png", o, e ? "right" : "left");
        check_size(p, 2064, 2208);
    }
    /* the dump names the HMD and the animation time; rendered again it
     * gives run's frame, byte for byte */
    snprintf(ds, sizeof ds, "%s/scene.txt", d);
    assert_true(file_has(ds, "\nhmd = consumer\n"));
    rc = ego("render", "--scene", ds, "--out", rd, "--quiet", NULL);
    if (rc != 0) fail_msg("render of the dump: exit %d: %s", rc, out);
    for (int e = 0; e < 2; e++) {
        char a[700], b[700];
        snprintf(a, sizeof a, "%s/%s_0000.png", o, e ? "right" : "left");
        snprintf(b, sizeof b, "%s/%s_0000.png", rd, e ? "right" : "left");
        const image_diff d = display_diff(b, a, NULL);
        if (d.n[0])
            fail_msg("%s eye: run and the render of its dump differ at %ld pixels (%ld by > 1)",
                     e ? "right" : "left", d.n[0], d.n[1]);
    }
    /* without the preset: the paper's sizes, which the images do not have */
    char o3[600];
    tu_tmp_path("run_paper", o3, sizeof o3);
    rc = ego("run", "--scene", scene, "--left", left, "--right", right, "--frames", "1", "--loop",
             "--out", o3, "--quiet", NULL);
    assert_int_equal(rc, 1);
    if (!strstr(out, "virtual image is 2064x2208, expected 1280x800")) fail_msg("got: %s", out);
    snprintf(p, sizeof p, "%s/left_0000.png", o3);
    assert_false(tu_exists(p));
    /* an own option wins over the preset's field, before or after it:
     * the display 1280x800 against the scene's 2064x2208 virtual images */
    rc = ego("run", "--hmd-display", "1280x800", "--hmd-preset", "consumer", "--scene", scene,
             "--left", left, "--right", right, "--frames", "1", "--loop", "--out", o, "--quiet",
             NULL);
    assert_int_equal(rc, 1);
    if (!strstr(out, "virtual image is 2064x2208, expected 1280x800")) fail_msg("got: %s", out);
    /* a cockpit file */
    tu_tmp_path("hmd_cockpit.conf", conf, sizeof conf);
    tu_tmp_path("run_consumer_conf", o2, sizeof o2);
    tu_write_fmt(conf, "scene = %s\n[cameras]\nleft = %s\nright = %s\nloop = yes\n[hmd]\n"
               "preset = consumer\n[output]\nout = %s\nframes = 1\nquiet = yes\n", scene, left,
            right, o2);
    rc = ego("run", "--config", conf, NULL);
    if (rc != 0) fail_msg("run --config ([hmd] preset = consumer): exit %d: %s", rc, out);
    snprintf(p, sizeof p, "%s/right_0000.png", o2);
    check_size(p, 2064, 2208);
}

/* Unknown names: refused, named, nothing written. */
static void unknown_names(void **st)
{
    (void)st;
    char scene[600], left[600], right[600], o[600], bad[600];
    snprintf(scene, sizeof scene, "%s/scene.txt", seq);
    snprintf(left, sizeof left, "file:%s/cam/left_%%04d.png", seq);
    snprintf(right, sizeof right, "file:%s/cam/right_%%04d.png", seq);
    tu_tmp_path("unknown_out", o, sizeof o);
    int rc = ego("run", "--hmd-preset", "quest9", "--scene", scene, "--left", left, "--right",
                 right, "--frames", "1", "--out", o, NULL);
    assert_int_equal(rc, 2);
    if (!strstr(out, "--hmd-preset 'quest9'") || !strstr(out, "consumer")) fail_msg("got: %s", out);
    char png[700];
    snprintf(png, sizeof png, "%s/left_0000.png", o);
    assert_false(tu_exists(png));
    /* a scene naming an unknown HMD: file, line, name and the known ones */
    snprintf(bad, sizeof bad, "%s/bad_hmd_scene.txt", seq); /* beside the images */
    FILE *in = fopen(scene, "r"), *f = fopen(bad, "w");
    assert_non_null(in);
    assert_non_null(f);
    char line[1024];
    int n = 0, hmd_line = 0;
    while (fgets(line, sizeof line, in)) {
        n++;
        if (!strncmp(line, "hmd = ", 6)) {
            fputs("hmd = vive\n", f);
            hmd_line = n;
        } else {
            fputs(line, f);
        }
    }
    fclose(in);
    fclose(f);
    assert_true(hmd_line > 0);
    rc = ego("render", "--scene", bad, "--out", o, NULL);
    assert_int_equal(rc, 1);
    char want[700];
    snprintf(want, sizeof want, "%s:%d: hmd: unknown HMD 'vive' (known: paper, consumer, highend)",
             bad, hmd_line);
    if (!strstr(out, want)) fail_msg("got: %s", out);
    assert_false(tu_exists(png));
    /* gen_samples */
    char *argv[] = {gen_path, "--out", o, "--hmd", "vive", NULL};
    rc = tu_run(argv, out, sizeof out);
    assert_int_equal(rc, 2);
    if (!strstr(out, "--hmd vive") || !strstr(out, "highend")) fail_msg("got: %s", out);
    char sc[700];
    snprintf(sc, sizeof sc, "%s/scene.txt", o);
    assert_false(tu_exists(sc));
}

TU_MAIN(setup, NULL,
        cmocka_unit_test(sequence),
        cmocka_unit_test(render),
        cmocka_unit_test(run),
        cmocka_unit_test(unknown_names))
