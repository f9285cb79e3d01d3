/* test_cli_output.c - every output of egofuse complete or absent, and the
 * messages of bad paths (issue: reliability).
 *
 * A full disk is simulated without root by RLIMIT_FSIZE in the child (as
 * `ulimit -f` does) with SIGXFSZ ignored: a write past the limit then fails
 * with EFBIG part way through the file, exactly where a full disk fails
 * with ENOSPC. With SIGXFSZ left at its default the process is killed in
 * the middle of the write instead: nothing may be left behind either. */
#include "support/testutil.h"

#include <cmocka.h>
#include "support/files.h"
#include "support/tu_bin_main.h"
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../src/io/io.h"

static char out[65536];

enum { XFSZ_IGNORE = 0, XFSZ_KILL = 1 };

/* Runs egofuse with argv (NULL-terminated, argv[0] is set here) under a
 * file size limit of `limit` bytes (< 0: none). Returns the exit status,
 * or -signal when killed. Output (both streams) in out. */
static int run_limited(long limit, int xfsz, const char **args)
{
    char *argv[40];
    int n = 0;
    argv[n++] = (char *)tu_bin();
    for (int i = 0; args[i] && n < 39; i++) argv[n++] = (char *)args[i];
    argv[n] = NULL;
    return tu_run_limited(argv, out, sizeof out, limit, xfsz);
}

static void make_dir(const char *name, char *dir, size_t n)
{
    tu_tmp_path(name, dir, n);
    char cmd[2200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
    assert_int_equal(system(cmd), 0);
}

/* Names in dir containing ".tmp." (temporaries left behind); 0 when
 * there is no dir. */
static int temps_in(const char *dir)
{
    const int n = tu_names_in(dir, ".tmp.", NULL);
    return n < 0 ? 0 : n;
}

/* Files in dir ending in ext; 0 when there is no dir. */
static int files_in(const char *dir, const char *ext)
{
    const int n = tu_names_in(dir, NULL, ext);
    return n < 0 ? 0 : n;
}

/* The size of the file at path, which exists. */
static long file_size(const char *path)
{
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    return (long)st.st_size;
}

/* args with no file size limit: exit 0 (else its output on stderr). */
static void expect_ok(const char **args)
{
    int rc = run_limited(-1, XFSZ_IGNORE, args);
    if (rc) fprintf(stderr, "%s\n", out);
    assert_int_equal(rc, 0);
}

/* args under a file size limit of `limit` bytes: exit 1 with the EFBIG
 * message naming what. */
static void expect_too_big(long limit, const char **args, const char *what)
{
    assert_int_equal(run_limited(limit, XFSZ_IGNORE, args), 1);
    assert_non_null(strstr(out, what));
    assert_non_null(strstr(out, strerror(EFBIG)));
}

/* A binary glTF (.glb) of one square [-1,1]^2 at z = 0 facing +Z, with a
 * node "head"; returns its size. */
static size_t make_glb(unsigned char *glb, size_t cap)
{
    static const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    char json[1024];
    int jn = snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
        "\"nodes\":[{\"name\":\"head\"},{\"name\":\"quad\",\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
        "\"buffers\":[{\"byteLength\":60}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
        "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
        "\"min\":[-1,-1,0],\"max\":[1,1,0]},"
        "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}");
    while (jn % 4) json[jn++] = ' ';
    size_t total = 12 + 8 + (size_t)jn + 8 + 60;
    assert_true(total <= cap);
    uint32_t h[3] = {0x46546C67u, 2, (uint32_t)total};  /* "glTF" little-endian */
    memcpy(glb, h, 12);
    uint32_t c0[2] = {(uint32_t)jn, 0x4E4F534Au};
    memcpy(glb + 12, c0, 8);
    memcpy(glb + 20, json, (size_t)jn);
    uint32_t c1[2] = {60, 0x004E4942u};
    memcpy(glb + 20 + jn, c1, 8);
    memcpy(glb + 28 + jn, pos, 48);
    memcpy(glb + 28 + jn + 48, idx, 12);
    return total;
}

static void write_glb(const char *path)
{
    unsigned char glb[2048];
    size_t n = make_glb(glb, sizeof glb);
    tu_write_bytes(path, glb, n);
}

/* A fresh folder tmp/NAME (dir) holding the quad model (model: its
 * quad.glb); mask: DIR/mask.png, not written. */
static void quad_files(const char *name, char dir[1024], char model[1100], char mask[1100])
{
    make_dir(name, dir, 1024);
    snprintf(model, 1100, "%s/quad.glb", dir);
    snprintf(mask, 1100, "%s/mask.png", dir);
    write_glb(model);
}

/* ------------------------------------------------------------- mask */

/* The mask command of the quad into mask, with --normals nrm and --depth
 * depth unless NULL. */
static void mask_args(const char **a, const char *model, const char *mask, const char *nrm,
                      const char *depth)
{
    int n = 0;
    a[n++] = "mask"; a[n++] = model;
    a[n++] = "--width"; a[n++] = "300"; a[n++] = "--height"; a[n++] = "200";
    a[n++] = "--fov-y"; a[n++] = "50"; a[n++] = "--eye"; a[n++] = "0.3,0.2,3";
    a[n++] = "--target"; a[n++] = "0,0,0"; a[n++] = "--out"; a[n++] = mask;
    if (nrm) { a[n++] = "--normals"; a[n++] = nrm; }
    if (depth) { a[n++] = "--depth"; a[n++] = depth; }
    a[n] = NULL;
}

/* quad_files of name and, in a[40], the mask command of its quad into
 * mask (mask_args, no normals or depth). */
static void quad_mask(const char *name, char dir[1024], char model[1100], char mask[1100],
                      const char **a)
{
    quad_files(name, dir, model, mask);
    mask_args(a, model, mask, NULL, NULL);
}

static void mask_write_fails_cleanly(void **state)
{
    (void)state;
    char dir[1024], model[1100], mask[1100], nrm[1100];
    quad_files("out_mask", dir, model, mask);
    snprintf(nrm, sizeof nrm, "%s/normals.png", dir);
    const char *a[40];
    mask_args(a, model, mask, nrm, NULL);

    /* no limit: both written, whole */
    expect_ok(a);
    io_image img;
    io_error err;
    assert_int_equal(io_image_load(nrm, IO_U8, 0, &img, &err), IO_OK);
    long nrm_size = file_size(nrm);
    io_image_free(&img);
    assert_int_equal(remove(nrm), 0);

    /* the mask fits under the limit, the normals image does not: the mask
     * is written, the normals are absent, the message says why */
    long limit = file_size(mask) + 64;
    assert_true(limit < nrm_size);
    assert_int_equal(remove(mask), 0);
    expect_too_big(limit, a, "normals.png");
    assert_true(tu_exists(mask));
    assert_false(tu_exists(nrm));
    assert_int_equal(temps_in(dir), 0);

    /* an existing file is not touched by a failed overwrite */
    tu_write_text(nrm, "precious");
    assert_int_equal(run_limited(limit, XFSZ_IGNORE, a), 1);
    assert_true(tu_file_is(nrm, "precious"));
    assert_int_equal(temps_in(dir), 0);

    /* the same with named temporaries (file systems without O_TMPFILE) */
    setenv("EGOFUSE_NO_TMPFILE", "1", 1);
    int rc = run_limited(limit, XFSZ_IGNORE, a);
    unsetenv("EGOFUSE_NO_TMPFILE");
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, strerror(EFBIG)));
    assert_true(tu_file_is(nrm, "precious"));
    assert_int_equal(temps_in(dir), 0);
}

/* The formats written through the OpenImageIO plugin (EXR depth, TIFF
 * normals) fail the same way: exit 1, the reason, nothing left. */
static void plugin_write_fails_cleanly(void **state)
{
    (void)state;
    char dir[1024], model[1100], mask[1100], depth[1100], tif[1100];
    quad_files("out_plugin", dir, model, mask);
    snprintf(depth, sizeof depth, "%s/depth.exr", dir);
    snprintf(tif, sizeof tif, "%s/normals.tif", dir);
    const char *a[40];
    mask_args(a, model, mask, tif, depth);
    expect_ok(a);
    long limit = file_size(mask) + 64;
    assert_true(file_size(tif) > limit);
    assert_true(file_size(depth) > limit);
    assert_int_equal(remove(tif), 0);
    assert_int_equal(remove(depth), 0);
    expect_too_big(limit, a, "normals.tif");
    assert_false(tu_exists(tif));
    assert_false(tu_exists(depth));
    /* without the normals, the depth is the one that fails */
    mask_args(a, model, mask, NULL, depth);
    expect_too_big(limit, a, "depth.exr");
    assert_false(tu_exists(depth));
    assert_int_equal(temps_in(dir), 0);
}

/* Killed in the middle of a write (SIGXFSZ at its default): the unnamed
 * file dies with the process, nothing is left. */
static void mask_killed_leaves_nothing(void **state)
{
    (void)state;
    char dir[1024], model[1100], mask[1100];
    const char *a[40];
    quad_mask("out_kill", dir, model, mask, a);
    int rc = run_limited(100, XFSZ_KILL, a);
    assert_int_equal(rc, -SIGXFSZ);
    assert_false(tu_exists(mask));
    assert_int_equal(temps_in(dir), 0);
}

/* ----------------------------------------------------------- render */

static void write_solid_png(const char *path, int w, int h, int r, int g, int b)
{
    io_image img;
    io_error err;
    assert_int_equal(io_image_alloc(&img, w, h, 3, IO_U8, &err), IO_OK);
    unsigned char *p = img.data;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
        p[3 * i] = (unsigned char)r;
        p[3 * i + 1] = (unsigned char)g;
        p[3 * i + 2] = (unsigned char)(b + (int)(i % 7));
    }
    assert_int_equal(io_image_save(path, &img, &err), IO_OK);
    io_image_free(&img);
}

static void render_write_fails_cleanly(void **state)
{
    (void)state;
    char dir[1024], p[1200], odir[1200];
    make_dir("out_render", dir, sizeof dir);
    snprintf(p, sizeof p, "%s/quad.glb", dir);
    write_glb(p);
    snprintf(p, sizeof p, "%s/cam_0.png", dir);
    write_solid_png(p, 640, 480, 200, 150, 120);
    snprintf(p, sizeof p, "%s/virt_0.png", dir);
    write_solid_png(p, 1280, 800, 10, 40, 90);
    snprintf(p, sizeof p, "%s/scene.txt", dir);
    tu_write_text(p, "egofuse-scene 1\nmodel = quad.glb\nhead_node = head\nframes = 1\n"
                  "fps = 60\ncamera_left = cam_%d.png\ncamera_right = cam_%d.png\n"
                  "virtual_left = virt_%d.png\nvirtual_right = virt_%d.png\n");
    snprintf(odir, sizeof odir, "%s/out", dir);
    const char *a[] = {"render", "--scene", p, "--out", odir, "--quiet", NULL};
    expect_too_big(4096, a, "left_0000.png");
    assert_int_equal(files_in(odir, ".png"), 0);
    assert_int_equal(temps_in(odir), 0);
    /* and without the limit it works */
    expect_ok(a);
    assert_int_equal(files_in(odir, ".png"), 2);
}

/* ------------------------------------------------------------- eval */

/* Lines of a text file, -1 if it does not end with a newline. */
static int lines_of(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -2;
    int n = 0, c, last = '\n';
    while ((c = fgetc(f)) != EOF) {
        if (c == '\n') n++;
        last = c;
    }
    fclose(f);
    return last == '\n' ? n : -1;
}

/* The data files fit under the limit, the charts do not: the data is
 * written whole, every chart absent, exit 1 with the file named. */
static void eval_report_write_fails_cleanly(void **state)
{
    (void)state;
    char dir[1024], p[1200];
    make_dir("out_eval", dir, sizeof dir);
    const char *a[] = {"eval", "--frames", "2", "--sweep-frames", "1", "--seq-frames", "1",
                       "--quiet", "--report", dir, NULL};
    int rc = run_limited(15000, XFSZ_IGNORE, a); /* charts.gp ~13 KB fits, no PNG does */
    snprintf(p, sizeof p, "%s/summary.csv", dir);
    int csv_lines = lines_of(p);
    assert_true(csv_lines > 10);
    FILE *f = fopen(p, "r");
    assert_non_null(f);
    char line[512];
    while (fgets(line, sizeof line, f)) {
        int commas = 0;
        for (char *c = line; *c; c++) commas += *c == ',';
        assert_int_equal(commas, 10);
    }
    fclose(f);
    snprintf(p, sizeof p, "%s/table.md", dir);
    assert_true(lines_of(p) > 10);
    assert_int_equal(temps_in(dir), 0);
    if (system("command -v gnuplot >/dev/null 2>&1") != 0) {
        printf("SKIP: gnuplot missing: the charts of eval --report are not drawn\n");
        skip();
        return;
    }
    /* the chart step fails on its first PNG, or already on charts.gp: its
     * size moves with the labels' leader lines, which follow the timings
     * (a slow sanitizer build's went past the limit); either way the
     * message names the file, and no chart is left */
    const int named = strstr(out, ".png") != NULL ||
                      (strstr(out, "charts.gp") != NULL && strstr(out, strerror(EFBIG)) != NULL);
    if (rc != 1 || !named) printf("eval --report said (exit %d):\n%s\n", rc, out);
    assert_int_equal(rc, 1);
    assert_true(named);
    assert_int_equal(files_in(dir, ".png"), 0);
}

/* --------------------------------------------------------- messages */

static void eye_overflow_names_eye(void **state)
{
    (void)state;
    char dir[1024], model[1100], mask[1100];
    const char *a[40];
    quad_mask("msg_eye", dir, model, mask, a);
    a[9] = "1e30,1,0";  /* --eye */
    assert_string_equal(a[8], "--eye");
    assert_int_equal(run_limited(-1, XFSZ_IGNORE, a), 2);
    assert_non_null(strstr(out, "--eye"));
    assert_null(strstr(out, "--up"));
    assert_false(tu_exists(mask));
}

static void truncated_glb_says_where(void **state)
{
    (void)state;
    char dir[1024], model[1100], mask[1100];
    make_dir("msg_glb", dir, sizeof dir);
    snprintf(model, sizeof model, "%s/cut.glb", dir);
    snprintf(mask, sizeof mask, "%s/mask.png", dir);
    unsigned char glb[2048];
    size_t n = make_glb(glb, sizeof glb);
    FILE *f = fopen(model, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(glb, 1, n - 30, f), n - 30);  /* inside the BIN chunk */
    fclose(f);
    const char *a[40];
    mask_args(a, model, mask, NULL, NULL);
    assert_int_equal(run_limited(-1, XFSZ_IGNORE, a), 1);
    assert_non_null(strstr(out, "cut.glb"));
    assert_non_null(strstr(out, "truncated"));
    assert_non_null(strstr(out, "30 bytes early"));
    assert_false(tu_exists(mask));

    /* the same through the library: a cut inside chunk 0's header */
    io_error err;
    char where[64];
    assert_int_equal(io_glb_check("x.glb", glb, n, &err), IO_OK);
    uint32_t total = 16;
    unsigned char head[16];
    memcpy(head, glb, 16);
    memcpy(head + 8, &total, 4);
    assert_int_equal(io_glb_check("x.glb", head, 16, &err), IO_ERR_FORMAT);
    snprintf(where, sizeof where, "at byte 12");
    assert_non_null(strstr(err.msg, where));
    assert_non_null(strstr(err.msg, "truncated"));
}

static void folder_as_input_says_so(void **state)
{
    (void)state;
    char dir[1024], odir[1100];
    make_dir("msg_folder", dir, sizeof dir);
    snprintf(odir, sizeof odir, "%s/o", dir);
    const char *a[] = {"render", "--scene", dir, "--out", odir, "--quiet", NULL};
    assert_int_equal(run_limited(-1, XFSZ_IGNORE, a), 1);
    assert_non_null(strstr(out, "is a directory"));

    io_error err;
    kin_track_sample *s = NULL;
    int count = 0;
    assert_int_not_equal(io_track_load(dir, &s, &count, &err), IO_OK);
    assert_non_null(strstr(err.msg, "is a directory"));
    assert_non_null(strstr(err.msg, dir));
    kin_user_calib c;
    assert_int_not_equal(io_user_calib_load(dir, &c, &err), IO_OK);
    assert_non_null(strstr(err.msg, "is a directory"));
}

static void unwritable_folder_says_why(void **state)
{
    (void)state;
    char dir[1024], model[1100], mask[1200], file[1100];
    make_dir("msg_outdir", dir, sizeof dir);
    snprintf(model, sizeof model, "%s/quad.glb", dir);
    write_glb(model);
    const char *a[40];

    snprintf(mask, sizeof mask, "%s/no_such_folder/mask.png", dir);
    mask_args(a, model, mask, NULL, NULL);
    assert_int_equal(run_limited(-1, XFSZ_IGNORE, a), 1);
    assert_non_null(strstr(out, "mask.png"));
    assert_non_null(strstr(out, "does not exist"));

    snprintf(file, sizeof file, "%s/plain_file", dir);
    tu_write_text(file, "x");
    snprintf(mask, sizeof mask, "%s/mask.png", file);
    mask_args(a, model, mask, NULL, NULL);
    assert_int_equal(run_limited(-1, XFSZ_IGNORE, a), 1);
    assert_non_null(strstr(out, "is not a folder"));

    /* a folder without write permission: errno's text (root may write
     * anywhere, so only checked as another user) */
    if (geteuid() != 0) {
        char ro[1100];
        snprintf(ro, sizeof ro, "%s/read_only", dir);
        assert_int_equal(mkdir(ro, 0555), 0);
        snprintf(mask, sizeof mask, "%s/mask.png", ro);
        mask_args(a, model, mask, NULL, NULL);
        assert_int_equal(run_limited(-1, XFSZ_IGNORE, a), 1);
        assert_non_null(strstr(out, strerror(EACCES)));
    }
}

TU_MAIN_NEEDS_BIN(NULL, NULL,
                  cmocka_unit_test(mask_write_fails_cleanly),
                  cmocka_unit_test(plugin_write_fails_cleanly),
                  cmocka_unit_test(mask_killed_leaves_nothing),
                  cmocka_unit_test(render_write_fails_cleanly),
                  cmocka_unit_test(eval_report_write_fails_cleanly),
                  cmocka_unit_test(eye_overflow_names_eye),
                  cmocka_unit_test(truncated_glb_says_where),
                  cmocka_unit_test(folder_as_input_says_so),
                  cmocka_unit_test(unwritable_folder_says_why))
