/* test_gltf_confine.c - a model's buffer and image URIs resolve only inside
 * its folder (issue 16, item 2; docs/io.md "Files a model may read").
 *
 * The test writes, in a scratch folder D:
 *   D/out.bin            a triangle's 36 bytes, outside the model's folder
 *   D/m/tri.bin          the same, a sibling of the models
 *   D/m/sub/tri.bin      the same, in a sub-folder
 *   D/m/link.bin         a symlink to ../out.bin (inside, pointing out)
 *   D/m/<case>.gltf      one triangle whose buffer (or image) uri is the case
 * and loads each with io_gltf_load, then runs `egofuse mask` and `egofuse
 * render` on refused ones (exit 1, the message, no output file) and with
 * --allow-outside. */
#include "support/testutil.h"

#include <cmocka.h>
#include "support/files.h"
#include <errno.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../src/io/io.h"
#include "support/io_images.h"

static char D[1024];        /* scratch folder */
static char M[1200];        /* D/m, the models' folder */
static char MREAL[PATH_MAX];/* its realpath (named in the messages) */
static char out[65536];     /* output of the CLI */

static const float TRI[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

/* D/m/<name>.gltf: one triangle read from a buffer of byte_length bytes at
 * buffer_uri; with image_uri, also an image (not drawn) at that uri. */
static const char *write_model(const char *name, const char *buffer_uri,
                               long byte_length, const char *image_uri)
{
    static char path[1400];
    char text[4096], image[1200] = "";
    if (image_uri)
        snprintf(image, sizeof image, "\"images\":[{\"uri\":\"%s\"}],", image_uri);
    snprintf(text, sizeof text,
             "{\"asset\":{\"version\":\"2.0\"},%s"
             "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":%ld}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,"
             "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"nodes\":[{\"name\":\"head\"},{\"mesh\":0}],"
             "\"scenes\":[{\"nodes\":[0,1]}],\"scene\":0}",
             image, buffer_uri, byte_length);
    snprintf(path, sizeof path, "%s/%s.gltf", M, name);
    tu_write_bytes(path, text, strlen(text));
    return path;
}

static int setup(void **state)
{
    (void)state;
    char cmd[3000], p[1400];
    tu_tmp_path("gltf_confine", D, sizeof D);
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s/m/sub'", D, D);
    if (system(cmd) != 0) return -1;
    snprintf(M, sizeof M, "%s/m", D);
    if (!realpath(M, MREAL)) return -1;
    snprintf(p, sizeof p, "%s/out.bin", D);
    tu_write_bytes(p, TRI, sizeof TRI);
    snprintf(p, sizeof p, "%s/tri.bin", M);
    tu_write_bytes(p, TRI, sizeof TRI);
    snprintf(p, sizeof p, "%s/sub/tri.bin", M);
    tu_write_bytes(p, TRI, sizeof TRI);
    snprintf(p, sizeof p, "%s/link.bin", M);
    if (symlink("../out.bin", p) != 0) return -1;
    /* an image file inside (its bytes do not matter: images are skipped) */
    snprintf(p, sizeof p, "%s/tex.png", M);
    tu_write_bytes(p, "not a png", 9);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    io_gltf_allow_outside(0);
    return 0;
}

static io_result load(const char *path, io_error *err)
{
    kin_model m;
    io_result r = io_gltf_load(path, &m, err);
    if (r == IO_OK) {
        assert_int_equal(m.mesh_count, 1);
        assert_int_equal(m.meshes[0].vertex_count, 3);
        assert_true(m.meshes[0].positions[3] == 1.0f);  /* TRI's bytes */
        kin_model_free(&m);
    }
    return r;
}

static void expect_ok(const char *path)
{
    io_error err;
    io_result r = load(path, &err);
    if (r != IO_OK) fail_msg("%s: expected to load, got: %s", path, err.msg);
}

/* Refused: IO_ERR_VALUE, the message names the model, the uri as decoded,
 * the reason, the folder and the option. */
static void expect_refused(const char *path, const char *what, const char *uri,
                           const char *reason)
{
    io_error err;
    io_result r = load(path, &err);
    if (r != IO_ERR_VALUE) fail_msg("%s: expected a refusal, got %d: %s", path, (int)r, err.msg);
    char want[2048];
    snprintf(want, sizeof want, "%s: %s: uri '%s' %s", path, what, uri, reason);
    if (!strstr(err.msg, want)) fail_msg("message '%s' lacks '%s'", err.msg, want);
    if (!strstr(err.msg, MREAL)) fail_msg("message '%s' lacks the folder %s", err.msg, MREAL);
    assert_non_null(strstr(err.msg, "--allow-outside"));
}

static void inside_loads(void **state)
{
    (void)state;
    expect_ok(write_model("sibling", "tri.bin", 36, NULL));
    expect_ok(write_model("subfolder", "sub/tri.bin", 36, NULL));
    expect_ok(write_model("subdotdot", "sub/../tri.bin", 36, NULL));  /* stays inside */
    expect_ok(write_model("pct_inside", "sub%2Ftri.bin", 36, NULL));
    /* data: URI of TRI (base64 of the 36 bytes, little-endian floats) */
    expect_ok(write_model("data", "data:application/octet-stream;base64,"
                          "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA", 36, NULL));
    expect_ok(write_model("image_inside", "tri.bin", 36, "tex.png"));
}

static void outside_refused(void **state)
{
    (void)state;
    struct stat st;
    assert_int_equal(stat("/etc/passwd", &st), 0);
    expect_refused(write_model("etc", "/etc/passwd", (long)st.st_size, NULL),
                   "buffer 0", "/etc/passwd", "is an absolute path");
    char abs[1400];
    snprintf(abs, sizeof abs, "%s/out.bin", D);
    expect_refused(write_model("abs", abs, 36, NULL), "buffer 0", abs, "is an absolute path");
    expect_refused(write_model("dotdot", "../out.bin", 36, NULL), "buffer 0", "../out.bin",
                   "leads outside the model's folder");
    expect_refused(write_model("deep", "sub/../../out.bin", 36, NULL), "buffer 0",
                   "sub/../../out.bin", "leads outside the model's folder");
    expect_refused(write_model("link", "link.bin", 36, NULL), "buffer 0", "link.bin",
                   "leads outside the model's folder");
    /* percent-encoded: decoded before the check, named decoded */
    expect_refused(write_model("pct", "%2e%2e/out.bin", 36, NULL), "buffer 0", "../out.bin",
                   "leads outside the model's folder");
    expect_refused(write_model("pct2", "..%2Fout.bin", 36, NULL), "buffer 0", "../out.bin",
                   "leads outside the model's folder");
    /* an image is refused too (even though images are never decoded) */
    expect_refused(write_model("image", "tri.bin", 36, "../out.bin"), "image 0",
                   "../out.bin", "leads outside the model's folder");
}

/* A .glb with an external buffer goes the same way. */
static void glb_external_buffer(void **state)
{
    (void)state;
    const char *uris[2] = {"tri.bin", "..%2fout.bin"};
    for (int k = 0; k < 2; k++) {
        char json[1024];
        int n = snprintf(json, sizeof json,
                         "{\"asset\":{\"version\":\"2.0\"},"
                         "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":36}],"
                         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
                         "\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}],"
                         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
                         "\"nodes\":[{\"mesh\":0}]}",
                         uris[k]);
        while (n % 4) json[n++] = ' ';
        unsigned char glb[1200];
        uint32_t h[5] = {0x46546C67u, 2, (uint32_t)(20 + n), (uint32_t)n, 0x4E4F534Au};
        memcpy(glb, h, 20);  /* little-endian host (x86, arm64) */
        memcpy(glb + 20, json, (size_t)n);
        char path[1400];
        snprintf(path, sizeof path, "%s/ext%d.glb", M, k);
        tu_write_bytes(path, glb, (size_t)(20 + n));
        if (k == 0) expect_ok(path);
        else expect_refused(path, "buffer 0", "../out.bin", "leads outside the model's folder");
    }
}

/* tinygltf also tries a uri against the current folder: never. */
static void current_folder_not_searched(void **state)
{
    (void)state;
    char old[PATH_MAX];
    assert_non_null(getcwd(old, sizeof old));
    assert_int_equal(chdir(D), 0);  /* D/out.bin exists, D/m/out.bin does not */
    io_error err;
    char p[PATH_MAX + 16];
    snprintf(p, sizeof p, "%s/cwd.gltf", MREAL);
    write_model("cwd", "out.bin", 36, NULL);
    io_result r = load(p, &err);
    assert_int_equal(chdir(old), 0);
    if (r == IO_OK) fail_msg("%s: loaded out.bin from the current folder", p);
    assert_non_null(strstr(err.msg, "out.bin"));
}

static void opt_in_allows(void **state)
{
    (void)state;
    char abs[1400], p[1400];
    snprintf(abs, sizeof abs, "%s/out.bin", D);
    io_gltf_allow_outside(1);
    expect_ok(write_model("abs", abs, 36, NULL));
    expect_ok(write_model("dotdot", "../out.bin", 36, NULL));
    expect_ok(write_model("link", "link.bin", 36, NULL));
    expect_ok(write_model("pct", "%2e%2e/out.bin", 36, NULL));
    expect_ok(write_model("image", "tri.bin", 36, "../out.bin"));
    expect_ok(write_model("sibling", "tri.bin", 36, NULL));
    io_gltf_allow_outside(0);
    snprintf(p, sizeof p, "%s/dotdot.gltf", M);
    expect_refused(p, "buffer 0", "../out.bin", "leads outside the model's folder");
}

static int run(const char **args)
{
    char *argv[40];
    int n = 0;
    argv[n++] = (char *)tu_bin();
    for (int i = 0; args[i] && n < 39; i++) argv[n++] = (char *)args[i];
    argv[n] = NULL;
    return tu_run(argv, out, sizeof out);
}

static void cli_mask(void **state)
{
    (void)state;
    char png[1400];
    snprintf(png, sizeof png, "%s/mask.png", D);
    unlink(png);
    const char *model = write_model("cli", "%2e%2e/out.bin", 36, NULL);
    const char *a[] = {"mask", model, "--width", "8", "--height", "8", "--fov-y", "60",
                       "--eye", "0.3,0.3,3", "--target", "0.3,0.3,0", "--out", png,
                       NULL, NULL};
    int rc = run(a);
    assert_int_equal(rc, 1);
    char want[2048];
    snprintf(want, sizeof want, "%s: buffer 0: uri '../out.bin' leads outside the model's "
             "folder", model);
    if (!strstr(out, want)) fail_msg("output '%s' lacks '%s'", out, want);
    assert_false(tu_exists(png));
    a[14] = "--allow-outside";
    rc = run(a);
    if (rc != 0) fail_msg("with --allow-outside: exit %d: %s", rc, out);
    assert_true(tu_exists(png));
}

static void cli_render(void **state)
{
    (void)state;
    char scene[1400], odir[1200], text[2000];
    snprintf(scene, sizeof scene, "%s/cam_0.png", M);
    tu_write_solid(scene, 640, 480, 120, 120, 120);
    snprintf(scene, sizeof scene, "%s/virt_0.png", M);
    tu_write_solid(scene, 1280, 800, 120, 120, 120);
    write_model("cli_render", "link.bin", 36, NULL);
    snprintf(scene, sizeof scene, "%s/scene.txt", M);
    snprintf(text, sizeof text,
             "egofuse-scene 1\nmodel = cli_render.gltf\nhead_node = head\nframes = 1\n"
             "fps = 60\ncamera_left = cam_%%d.png\ncamera_right = cam_%%d.png\n"
             "virtual_left = virt_%%d.png\nvirtual_right = virt_%%d.png\n");
    tu_write_bytes(scene, text, strlen(text));
    snprintf(odir, sizeof odir, "%s/render_out", D);
    const char *a[] = {"render", "--scene", scene, "--out", odir, "--quiet", NULL, NULL};
    int rc = run(a);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, "cli_render.gltf: buffer 0: uri 'link.bin' leads outside "
                                "the model's folder (to "));
    char png[1500];
    snprintf(png, sizeof png, "%s/left_0000.png", odir);
    assert_false(tu_exists(png));
    /* with the option the model loads and both frames are written */
    a[6] = "--allow-outside";
    rc = run(a);
    if (strstr(out, "leads outside")) fail_msg("with --allow-outside: %s", out);
    if (rc != 0) fail_msg("with --allow-outside: exit %d: %s", rc, out);
    assert_true(tu_exists(png));
}

TU_MAIN(setup, NULL,
        cmocka_unit_test(inside_loads),
        cmocka_unit_test(outside_refused),
        cmocka_unit_test(glb_external_buffer),
        cmocka_unit_test(current_folder_not_searched),
        cmocka_unit_test_teardown(opt_in_allows, teardown),
        cmocka_unit_test(cli_mask),
        cmocka_unit_test(cli_render))
