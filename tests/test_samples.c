/* test_samples.c - the sample-data generator (build/gen_samples): runs it
 * for a short sequence into a scratch folder, then checks what it wrote
 * through the libraries: the model (skeleton names and proportions, mesh
 * size, unit normals, normalised weights, the 3 s animation without
 * quaternion flips), the image sizes and depth values, the scene file, and
 * that the arms drawn by kin + raster at frame 0 line up with the skin in
 * the camera images. */
#include "support/testutil.h"
#include <cmocka.h>

#include "../src/io/io.h"
#include "../src/kin/kin.h"
#include "../src/raster/raster.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static char g_dir[1024];
static char g_log[16384];
static int g_rc = -1;

static const char *const side_joints[20] = {
    "shoulder", "upper_arm", "forearm", "hand", "palm",
    "thumb_1", "thumb_2", "thumb_3", "index_1", "index_2", "index_3",
    "middle_1", "middle_2", "middle_3", "ring_1", "ring_2", "ring_3",
    "little_1", "little_2", "little_3",
};

static const char *sub(const char *rel, char *buf, size_t n)
{
    snprintf(buf, n, "%s/%s", g_dir, rel);
    return buf;
}

/* The generator next to the egofuse program under test (EGOFUSE_BIN, set
 * by tests/run_tests.sh for build/ and build-debug/), else build/. */
static const char *gen_path(char *buf, size_t n)
{
    const char *bin = getenv("EGOFUSE_BIN");
    const char *slash = bin ? strrchr(bin, '/') : NULL;
    if (slash) snprintf(buf, n, "%.*s/gen_samples", (int)(slash - bin), bin);
    else tu_root_path("build/gen_samples", buf, n);
    return buf;
}

static int run_gen(const char *dir, const char *frames, const char *seed,
                   const char *threads, char *log, size_t log_size)
{
    char prog[1024];
    gen_path(prog, sizeof prog);
    char *argv[] = { prog, "--out", (char *)dir, "--frames", (char *)frames,
                     "--seed", (char *)seed, "--threads", (char *)threads, NULL };
    return tu_run(argv, log, log_size);
}

static int group_setup(void **state)
{
    (void)state;
    tu_tmp_path("samples", g_dir, sizeof g_dir);
    g_rc = run_gen(g_dir, "3", "7", "2", g_log, sizeof g_log);
    return 0;
}

static int group_teardown(void **state)
{
    (void)state;
    char again[1024];
    tu_tmp_path("samples_again", again, sizeof again);
    char *argv[] = { "/bin/rm", "-rf", g_dir, again, NULL };
    char log[256];
    tu_run(argv, log, sizeof log);
    return 0;
}

static void test_generator_runs(void **state)
{
    (void)state;
    if (g_rc != 0) fprintf(stderr, "gen_samples output:\n%s\n", g_log);
    assert_int_equal(g_rc, 0);
    char p[1200];
    assert_true(tu_exists(sub("model/arms.glb", p, sizeof p)));
    assert_true(tu_exists(sub("scene.txt", p, sizeof p)));
    for (int f = 0; f < 3; f++) {
        char rel[64];
        snprintf(rel, sizeof rel, "cam/right_%04d.png", f);
        assert_true(tu_exists(sub(rel, p, sizeof p)));
        snprintf(rel, sizeof rel, "virt/left_depth_%04d.exr", f);
        assert_true(tu_exists(sub(rel, p, sizeof p)));
    }
    assert_false(tu_exists(sub("cam/right_0003.png", p, sizeof p)));
}

static void load_model(kin_model *m)
{
    char p[1200];
    io_error err;
    io_result r = io_gltf_load(sub("model/arms.glb", p, sizeof p), m, &err);
    if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(r, IO_OK);
}

static void test_model_skeleton(void **state)
{
    (void)state;
    kin_model m;
    load_model(&m);
    assert_true(kin_model_find_node(&m, "body") >= 0);
    assert_true(kin_model_find_node(&m, "head") >= 0);
    assert_int_equal(m.skin_count, 1);
    const kin_skin *sk = &m.skins[0];
    int arm_joints = 0;
    for (int side = 0; side < 2; side++)
        for (int j = 0; j < 20; j++) {
            char name[64];
            snprintf(name, sizeof name, "%s%s", side ? "R_" : "L_", side_joints[j]);
            int n = kin_model_find_node(&m, name);
            if (n < 0) fprintf(stderr, "missing node %s\n", name);
            assert_true(n >= 0);
            int in_skin = 0;
            for (int k = 0; k < sk->joint_count; k++) in_skin |= sk->joints[k] == n;
            assert_true(in_skin);
            arm_joints++;
        }
    assert_int_equal(arm_joints, 40);
    /* hierarchy: each finger chain hangs off the palm, the palm off the hand */
    int palm = kin_model_find_node(&m, "R_palm");
    assert_int_equal(m.parents[kin_model_find_node(&m, "R_index_1")], palm);
    assert_int_equal(m.parents[kin_model_find_node(&m, "R_thumb_1")], palm);
    assert_int_equal(m.parents[palm], kin_model_find_node(&m, "R_hand"));
    assert_int_equal(m.parents[kin_model_find_node(&m, "L_shoulder")],
                     kin_model_find_node(&m, "body"));
    kin_model_free(&m);
}

static kin_vec3 node_pos(const kin_mat4 *w, int n)
{
    return kin_v3(w[n].m[12], w[n].m[13], w[n].m[14]);
}

static float dist(const kin_model *m, const kin_mat4 *w, const char *a,
                  const char *b)
{
    return kin_v3_len(kin_v3_sub(node_pos(w, kin_model_find_node(m, a)),
                                 node_pos(w, kin_model_find_node(m, b))));
}

static void test_model_proportions(void **state)
{
    (void)state;
    kin_model m;
    load_model(&m);
    kin_transform *loc = malloc(sizeof *loc * (size_t)m.node_count);
    kin_mat4 *w = malloc(sizeof *w * (size_t)m.node_count);
    assert_non_null(loc);
    assert_non_null(w);
    kin_pose_rest(&m, loc);
    kin_fk(m.parents, m.node_count, loc, NULL, w);
    for (int side = 0; side < 2; side++) {
        char a[32], b[32], c[32], d[32];
        const char *p = side ? "R_" : "L_";
        snprintf(a, sizeof a, "%supper_arm", p);
        snprintf(b, sizeof b, "%sforearm", p);
        snprintf(c, sizeof c, "%shand", p);
        snprintf(d, sizeof d, "%smiddle_3", p);
        assert_float_equal(dist(&m, w, a, b), 0.30f, 0.03f);
        assert_float_equal(dist(&m, w, b, c), 0.26f, 0.03f);
        /* wrist to the last middle joint: the hand minus the distal phalanx */
        float h = dist(&m, w, c, d);
        assert_true(h > 0.14f && h < 0.19f);
    }
    /* shoulders ~0.19 m either side, ~0.25 m below the eyes */
    float sw = dist(&m, w, "L_upper_arm", "R_upper_arm");
    assert_float_equal(sw, 0.38f, 0.04f);
    kin_vec3 head = node_pos(w, kin_model_find_node(&m, "head"));
    kin_vec3 sh = node_pos(w, kin_model_find_node(&m, "R_upper_arm"));
    assert_float_equal(head.y - sh.y, 0.25f, 0.04f);
    free(loc);
    free(w);
    kin_model_free(&m);
}

static void test_model_mesh(void **state)
{
    (void)state;
    kin_model m;
    load_model(&m);
    int tris = 0;
    for (int k = 0; k < m.mesh_count; k++) {
        const kin_mesh *me = &m.meshes[k];
        tris += me->index_count / 3;
        assert_non_null(me->normals);
        assert_non_null(me->weights);
        assert_non_null(me->joints);
        assert_true(me->skin >= 0);
        for (int v = 0; v < me->vertex_count; v++) {
            const float *n = &me->normals[v * 3];
            float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            assert_float_equal(len, 1.0f, 1e-3f);
            float s = 0.0f;
            for (int c = 0; c < 4; c++) {
                assert_true(me->weights[v * 4 + c] >= 0.0f);
                s += me->weights[v * 4 + c];
            }
            assert_float_equal(s, 1.0f, 1e-5f);
        }
    }
    assert_true(tris >= 5000 && tris <= 20000);
    kin_model_free(&m);
}

static void test_model_animation(void **state)
{
    (void)state;
    kin_model m;
    load_model(&m);
    int a = -1;
    for (int i = 0; i < m.anim_count; i++)
        if (strcmp(m.anims[i].name, "reach_grasp") == 0) a = i;
    assert_true(a >= 0);
    const kin_animation *an = &m.anims[a];
    assert_float_equal(an->duration, 3.0f, 0.1f);
    assert_true(an->channel_count >= 30);
    int head_animated = 0, head = kin_model_find_node(&m, "head");
    for (int c = 0; c < an->channel_count; c++) {
        const kin_channel *ch = &an->channels[c];
        if (ch->path != KIN_PATH_ROTATION) continue;
        head_animated |= ch->node == head;
        for (int k = 0; k < ch->key_count; k++) {
            const float *q = &ch->values[k * 4];
            assert_float_equal(sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]),
                               1.0f, 1e-4f);
            if (k > 0) {   /* same hemisphere, small steps: no flips */
                const float *p = q - 4;
                float d = p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3];
                assert_true(d > 0.98f);
            }
        }
    }
    assert_true(head_animated);
    /* the right wrist travels forward (reach) and comes back */
    kin_transform *loc = malloc(sizeof *loc * (size_t)m.node_count);
    kin_mat4 *w = malloc(sizeof *w * (size_t)m.node_count);
    assert_non_null(loc);
    assert_non_null(w);
    float z[3];
    const float t[3] = { 0.0f, 1.4f, 3.0f };
    int wrist = kin_model_find_node(&m, "R_hand");
    for (int i = 0; i < 3; i++) {
        kin_pose_rest(&m, loc);
        kin_anim_sample(an, m.node_count, t[i], loc);
        kin_fk(m.parents, m.node_count, loc, NULL, w);
        z[i] = w[wrist].m[14];
    }
    assert_true(z[1] < z[0] - 0.12f);
    assert_true(fabsf(z[2] - z[0]) < 0.05f);
    free(loc);
    free(w);
    kin_model_free(&m);
}

static void test_images_and_scene(void **state)
{
    (void)state;
    char p[1200];
    io_error err;
    io_image img;
    assert_int_equal(io_image_load(sub("cam/left_0001.png", p, sizeof p), IO_U8, 0, &img, &err), IO_OK);
    assert_int_equal(img.width, 640);
    assert_int_equal(img.height, 480);
    assert_int_equal(img.channels, 3);
    io_image_free(&img);
    assert_int_equal(io_image_load(sub("virt/right_0002.png", p, sizeof p), IO_U8, 0, &img, &err), IO_OK);
    assert_int_equal(img.width, 1280);
    assert_int_equal(img.height, 800);
    assert_int_equal(img.channels, 3);
    io_image_free(&img);
    assert_int_equal(io_image_load(sub("virt/left_depth_0000.exr", p, sizeof p), IO_F32, 1, &img, &err), IO_OK);
    assert_int_equal(img.width, 1280);
    assert_int_equal(img.height, 800);
    const float *d = img.data;
    float mn = 1e9f, mx = 0.0f;
    for (int i = 0; i < img.width * img.height; i++) {
        assert_true(isfinite(d[i]) && d[i] > 0.0f);
        if (d[i] < mn) mn = d[i];
        if (d[i] > mx) mx = d[i];
    }
    /* the nearest thing (the table edge or the bottle) is within a metre,
     * the walls several metres away */
    assert_true(mn > 0.05f && mn < 1.0f);
    assert_true(mx > 2.0f && mx < 20.0f);
    io_image_free(&img);

    io_scene sc;
    io_result r = io_scene_load(sub("scene.txt", p, sizeof p), &sc, &err);
    if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(r, IO_OK);
    assert_int_equal(sc.frames, 3);
    assert_float_equal(sc.fps, 60.0f, 1e-6f);
    assert_string_equal(sc.animation, "reach_grasp");
    assert_string_equal(sc.head_node, "head");
    assert_true(sc.has_lighting);
    assert_true(sc.light_count >= 1);
    char fp[2048];
    io_scene_frame_path(&sc, sc.camera[1], 2, fp, sizeof fp);
    assert_true(tu_exists(fp));
    io_scene_frame_path(&sc, sc.virt_depth[0], 2, fp, sizeof fp);
    assert_true(tu_exists(fp));
}

static int skin_like(const uint8_t *px)
{
    int r = px[0], g = px[1], b = px[2];
    return r > 60 && r > g && g > b && g * 100 > r * 55 && g * 100 < r * 90 &&
           b * 100 > r * 42;
}

/* Draws the arms of frame 0 with the library into the cropped camera view
 * and compares with the skin in the generated camera image. */
static void test_mask_matches_camera_images(void **state)
{
    (void)state;
    kin_model m;
    load_model(&m);
    const kin_mesh *me = &m.meshes[0];
    kin_transform *loc = malloc(sizeof *loc * (size_t)m.node_count);
    kin_mat4 *w = malloc(sizeof *w * (size_t)m.node_count);
    kin_mat4 *jm = malloc(sizeof *jm * (size_t)m.skins[0].joint_count);
    float *pos = malloc(sizeof(float) * 3 * (size_t)me->vertex_count);
    float *clip = malloc(sizeof(float) * 4 * (size_t)me->vertex_count);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    int W = g.crop_width, H = g.crop_height;
    uint8_t *mask = malloc((size_t)W * (size_t)H);
    float *depth = malloc(sizeof(float) * (size_t)W * (size_t)H);
    assert_true(loc && w && jm && pos && clip && mask && depth);
    kin_pose_rest(&m, loc);
    kin_anim_sample(&m.anims[0], m.node_count, 0.0f, loc);
    kin_fk(m.parents, m.node_count, loc, NULL, w);
    kin_skin_joint_matrices(&m.skins[0], w, jm);
    kin_skin_lbs(me, jm, pos, NULL);
    int head = kin_model_find_node(&m, "head");
    /* coverage reported by the generator for frame 0 */
    const char *cov = strstr(g_log, "frame 0 left ");
    assert_non_null(cov);
    float rep[2];
    assert_int_equal(sscanf(cov, "frame 0 left %f right %f", &rep[0], &rep[1]), 2);
    for (int eye = 0; eye < 2; eye++) {
        kin_camera cam = kin_sthmd_camera(NULL, &w[head], (kin_eye)eye);
        assert_int_equal(cam.width, W);
        assert_int_equal(cam.height, H);
        rast_transform_points(cam.view_proj.m, pos, me->vertex_count, clip);
        rast_target t = { W, H, depth, W, mask, W, NULL, 0, 0, NULL, 0 };
        rast_target_clear(&t);
        rast_mesh_desc d = { clip, me->vertex_count, NULL, 0, me->indices,
                             me->index_count / 3, RAST_CULL_NONE };
        assert_int_equal(rast_draw(&t, &d, NULL), RAST_OK);
        long covered = 0;
        for (int i = 0; i < W * H; i++) covered += mask[i] != 0;
        float frac = (float)covered / (float)(W * H);
        /* both hands in view at the start, not filling it */
        assert_true(frac > 0.03f && frac < 0.6f);
        /* the generator's count (arms not hidden by the cockpit) agrees */
        assert_true(rep[eye] <= frac + 0.005f && rep[eye] > 0.8f * frac);

        char rel[64], p[1200];
        io_error err;
        io_image img;
        snprintf(rel, sizeof rel, "cam/%s_0000.png", eye ? "right" : "left");
        assert_int_equal(io_image_load(sub(rel, p, sizeof p), IO_U8, 3, &img, &err), IO_OK);
        long in = 0, in_skin = 0, out = 0, out_skin = 0;
        for (int y = 3; y < H - 3; y++)
            for (int x = 3; x < W - 3; x++) {
                int all = 1, none = 1;
                for (int dy = -3; dy <= 3; dy++)
                    for (int dx = -3; dx <= 3; dx++) {
                        int on = mask[(y + dy) * W + x + dx] != 0;
                        all &= on;
                        none &= !on;
                    }
                const uint8_t *px = (const uint8_t *)img.data +
                                    (size_t)(y + g.crop_y0) * img.stride + (size_t)x * 3;
                if (all) { in++; in_skin += skin_like(px); }
                if (none) { out++; out_skin += skin_like(px); }
            }
        io_image_free(&img);
        /* frame 0 shows hands (skin) inside the mask, almost none outside */
        assert_true(in > 1000);
        assert_true((double)in_skin > 0.6 * (double)in);
        assert_true((double)out_skin < 0.01 * (double)out);
    }
    free(loc); free(w); free(jm); free(pos); free(clip); free(mask); free(depth);
    kin_model_free(&m);
}

/* Frame 0 does not depend on the sequence length or the thread count. */
static void test_deterministic(void **state)
{
    (void)state;
    char dir[1024], log[4096], a[1200], b[1200];
    tu_tmp_path("samples_again", dir, sizeof dir);
    assert_int_equal(run_gen(dir, "1", "7", "1", log, sizeof log), 0);
    const char *files[] = { "cam/left_0000.png", "virt/right_0000.png", "model/arms.glb" };
    for (int i = 0; i < 3; i++) {
        snprintf(a, sizeof a, "%s/%s", g_dir, files[i]);
        snprintf(b, sizeof b, "%s/%s", dir, files[i]);
        FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
        assert_non_null(fa);
        assert_non_null(fb);
        uint32_t ca = 0, cb = 0;
        long na = 0, nb = 0;
        char buf[65536];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, fa)) > 0) { ca = tu_crc32(ca, buf, n); na += (long)n; }
        while ((n = fread(buf, 1, sizeof buf, fb)) > 0) { cb = tu_crc32(cb, buf, n); nb += (long)n; }
        fclose(fa);
        fclose(fb);
        assert_true(na > 0);
        assert_int_equal(na, nb);
        assert_int_equal(ca, cb);
    }
}

static void test_bad_output_dir(void **state)
{
    (void)state;
    char prog[1024], log[4096], file[1024], dir[1100];
    gen_path(prog, sizeof prog);
    /* a regular file where the folder should go */
    tu_tmp_path("samples_not_a_dir", file, sizeof file);
    FILE *f = fopen(file, "w");
    assert_non_null(f);
    fclose(f);
    snprintf(dir, sizeof dir, "%s/sub", file);
    char *argv[] = { prog, "--out", dir, "--frames", "1", NULL };
    int rc = tu_run(argv, log, sizeof log);
    assert_true(rc != 0);
    assert_non_null(strstr(log, file));
    char *argv2[] = { prog, "--frames", "0", "--out", dir, NULL };
    assert_true(tu_run(argv2, log, sizeof log) != 0);
    remove(file);
}

TU_MAIN(group_setup, group_teardown,
        cmocka_unit_test(test_generator_runs),
        cmocka_unit_test(test_model_skeleton),
        cmocka_unit_test(test_model_proportions),
        cmocka_unit_test(test_model_mesh),
        cmocka_unit_test(test_model_animation),
        cmocka_unit_test(test_images_and_scene),
        cmocka_unit_test(test_mask_matches_camera_images),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_bad_output_dir))
