/* test_cli_cockpit.c - `egofuse render --hide PARTS --prop MODEL@X,Y,Z[,YAW]`
 * on a scene the test writes itself (a quad named R_hand in front of the
 * head, solid camera and virtual images, a box prop as glTF):
 *   - bad values: an unknown part, a malformed or missing prop, too many
 *     props: exit 2 (usage) or 1 (the file) with a message naming it, and
 *     no output folder;
 *   - --hide right-hand: nothing of the quad is drawn, the output is the
 *     virtual image; hiding a part the model lacks says so and changes
 *     nothing;
 *   - --prop: the box is cut in like the hands; the mask with the quad and
 *     the box is the union of their masks. */
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

/* A glTF of one unskinned mesh: nv positions (no normals) and nt
 * triangles, under a node "head" (a root) and a node `name`. */
static void write_mesh_gltf(const char *path, const char *name, const float *pos, int nv,
                            const uint16_t *idx, int nt)
{
    size_t pb = sizeof(float) * 3 * (size_t)nv, ib = sizeof(uint16_t) * 3 * (size_t)nt;
    uint8_t *buf = calloc(pb + ib + 4, 1);
    char *enc = malloc(2 * (pb + ib) + 16);
    assert_non_null(enc);
    memcpy(buf, pos, pb);
    memcpy(buf + pb, idx, ib);
    tu_b64(buf, pb + ib, enc);
    float mn[3] = {1e9f, 1e9f, 1e9f}, mx[3] = {-1e9f, -1e9f, -1e9f};
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 3; k++) {
            mn[k] = fminf(mn[k], pos[3 * i + k]);
            mx[k] = fmaxf(mx[k], pos[3 * i + k]);
        }
    tu_write_fmt(path,
            "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
            "\"nodes\":[{\"name\":\"head\"},{\"name\":\"%s\",\"mesh\":0}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
            "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
            "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},"
            "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
            "\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},"
            "{\"bufferView\":1,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}]}\n",
            name, pb + ib, enc, pb, pb, ib, nv, mn[0], mn[1], mn[2], mx[0], mx[1], mx[2], 3 * nt);
    free(enc);
    free(buf);
}

static char g_dir[512], g_scene[600], g_box[600];

/* The scene: a 0.16 m quad "R_hand" 0.6 m in front of the head, a little
 * to the left; a 0.1 m box prop (its own frame centred). */
static int group_setup(void **state)
{
    (void)state;
    tu_tmp_path("cli_cockpit", g_dir, sizeof g_dir);
    char cmd[700], p[700];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", g_dir);
    if (system(cmd) != 0) return -1;
    static const float quad[12] = {-0.14f, -0.08f, -0.6f, 0.02f, -0.08f, -0.6f,
                                   0.02f, 0.08f, -0.6f, -0.14f, 0.08f, -0.6f};
    static const uint16_t qi[6] = {0, 1, 2, 0, 2, 3};
    snprintf(p, sizeof p, "%s/hand.gltf", g_dir);
    write_mesh_gltf(p, "R_hand", quad, 4, qi, 2);
    float box[24];
    for (int i = 0; i < 8; i++) {
        box[3 * i] = (i & 1) ? 0.05f : -0.05f;
        box[3 * i + 1] = (i & 2) ? 0.05f : -0.05f;
        box[3 * i + 2] = (i & 4) ? 0.05f : -0.05f;
    }
    static const uint16_t bi[36] = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
                                    2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    snprintf(g_box, sizeof g_box, "%s/box.gltf", g_dir);
    write_mesh_gltf(g_box, "box", box, 8, bi, 12);
    tu_write_scene_images(g_dir, 640, 480, 1280, 800);
    snprintf(g_scene, sizeof g_scene, "%s/scene.txt", g_dir);
    tu_write_text(g_scene, "egofuse-scene 1\n"
                        "model = hand.gltf\n"
                        "head_node = head\n"
                        "frames = 1\n"
                        "fps = 60\n"
                        "camera_left = cam_l_%d.png\n"
                        "camera_right = cam_r_%d.png\n"
                        "virtual_left = virt_l_%d.png\n"
                        "virtual_right = virt_r_%d.png\n");
    return 0;
}

static int group_teardown(void **state)
{
    (void)state;
    char *argv[] = {"/bin/rm", "-rf", g_dir, NULL};
    char log[256];
    tu_run(argv, log, sizeof log);
    return 0;
}

static int exists(const char *p) { return tu_exists(p); }

static void bad_values(void **state)
{
    (void)state;
    char odir[700], spec[800];
    snprintf(odir, sizeof odir, "%s/bad_out", g_dir);
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--hide", "elbow", NULL), 2);
    assert_non_null(strstr(out, "--hide 'elbow': 'elbow' is not a part"));
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--hide", "left-hand,",
                         NULL), 2);
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--prop", "box.gltf@1,2",
                         NULL), 2);
    assert_non_null(strstr(out, "--prop 'box.gltf@1,2': MODEL@X,Y,Z"));
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--prop", "@1,2,3", NULL), 2);
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--prop", "b.gltf@1,2,3,x",
                         NULL), 2);
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--prop", "b.gltf@1,2,3,4,5",
                         NULL), 2);
    snprintf(spec, sizeof spec, "%s@0,0,-1", g_box);
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--prop", spec, "--prop",
                         spec, "--prop", spec, "--prop", spec, "--prop", spec, "--prop", spec,
                         "--prop", spec, "--prop", spec, "--prop", spec, NULL), 2);
    assert_non_null(strstr(out, "at most 8 props"));
    /* a missing model: named, exit 1, nothing written */
    snprintf(spec, sizeof spec, "%s/none.gltf@0,0,-1", g_dir);
    assert_int_equal(run("render", "--scene", g_scene, "--out", odir, "--quiet", "--prop", spec,
                         NULL), 1);
    assert_non_null(strstr(out, "--prop "));
    assert_non_null(strstr(out, "none.gltf"));
    assert_false(exists(odir));
}

/* One eye's output and mask after a render into sub. */
typedef struct shot {
    io_image rgb[2], mask[2];
} shot;

static void render_shot(const char *sub, shot *s, const char *a, const char *b, const char *c,
                        const char *d)
{
    char odir[700], png[800];
    snprintf(odir, sizeof odir, "%s/%s", g_dir, sub);
    int rc = run("render", "--scene", g_scene, "--out", odir, "--quiet", "--masks", a, b, c, d,
                 NULL);
    if (rc != 0) fail_msg("render %s: exit %d: %s", sub, rc, out);
    for (int e = 0; e < 2; e++) {
        io_error err;
        snprintf(png, sizeof png, "%s/%s_0000.png", odir, e ? "right" : "left");
        assert_int_equal(io_image_load(png, IO_U8, 3, &s->rgb[e], &err), IO_OK);
        snprintf(png, sizeof png, "%s/mask_%s_0000.png", odir, e ? "right" : "left");
        assert_int_equal(io_image_load(png, IO_U8, 1, &s->mask[e], &err), IO_OK);
        assert_int_equal(s->mask[e].width, 640);
        assert_int_equal(s->mask[e].height, 400);
    }
}

static void shot_free(shot *s)
{
    for (int e = 0; e < 2; e++) {
        io_image_free(&s->rgb[e]);
        io_image_free(&s->mask[e]);
    }
}

static long mask_on(const io_image *m)
{
    long n = 0;
    const uint8_t *p = m->data;
    for (int i = 0; i < m->width * m->height; i++) n += p[i] != 0;
    return n;
}

static void hide_and_props(void **state)
{
    (void)state;
    shot base, hid, lack, boxonly, both;
    char spec[800];
    render_shot("base", &base, NULL, NULL, NULL, NULL);
    render_shot("hid", &hid, "--hide", "right-hand", NULL, NULL);
    render_shot("lack", &lack, "--hide", "left-arm", NULL, NULL);
    assert_non_null(strstr(out, "has no triangles of some of these parts (found: right-hand"));
    snprintf(spec, sizeof spec, "%s@0.06,0.02,-0.5,30", g_box);
    render_shot("boxonly", &boxonly, "--hide", "right-hand", "--prop", spec);
    render_shot("both", &both, "--prop", spec, NULL, NULL);
    for (int e = 0; e < 2; e++) {
        const size_t n = (size_t)1280 * 800 * 3;
        assert_true(mask_on(&base.mask[e]) > 3000);
        /* hidden: no mask, the output is the virtual image */
        assert_int_equal(mask_on(&hid.mask[e]), 0);
        const uint8_t *h = hid.rgb[e].data;
        for (size_t i = 0; i < n; i += 3)
            if (h[i] != 10 || h[i + 1] != 40 || h[i + 2] != 90)
                fail_msg("eye %d: --hide right-hand left pixel %zu not the virtual image", e, i / 3);
        /* a part the model lacks: nothing changes */
        assert_memory_equal(lack.rgb[e].data, base.rgb[e].data, n);
        /* the box alone, cut in with the camera's colour */
        long nb = mask_on(&boxonly.mask[e]);
        assert_true(nb > 1500);
        assert_memory_not_equal(boxonly.rgb[e].data, hid.rgb[e].data, n);
        /* the quad and the box: the union of their masks, and both seen */
        const uint8_t *a = base.mask[e].data, *b = boxonly.mask[e].data, *c = both.mask[e].data;
        long over = 0;
        for (int i = 0; i < 640 * 400; i++) {
            if (c[i] != (a[i] | b[i])) fail_msg("eye %d mask pixel %d: %d, %d | %d", e, i, c[i], a[i], b[i]);
            over += a[i] && b[i];
        }
        assert_true(over > 100); /* they overlap: the depth order matters there */
    }
    shot_free(&base);
    shot_free(&hid);
    shot_free(&lack);
    shot_free(&boxonly);
    shot_free(&both);
}

TU_MAIN(group_setup, group_teardown,
        cmocka_unit_test(bad_values),
        cmocka_unit_test(hide_and_props))
