/* test_io_scene.c - io_scene_load and io_scene_frame_path: a full file,
 * defaults, every class of error with its line number, path handling, the
 * optional `tracking` key. */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/files.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../src/io/io.h"

/* Writes text to the scratch file name and loads it as a scene into s:
 * io_scene_load's result. */
static io_result scene_text(const char *name, const char *text, io_scene *s, io_error *err)
{
    char path[1024];
    tu_tmp_path(name, path, sizeof path);
    tu_write_text(path, text);
    return io_scene_load(path, s, err);
}

static const char *full_scene =
    "egofuse-scene 1\n"
    "# a recorded sequence\n"
    "\n"
    "model = models/arms.glb   # the mask model\n"
    "animation = wave\n"
    "head_node = head\n"
    "frames = 120\n"
    "fps = 59.94\n"
    "animation_start = 1.25\n"
    "camera_left  = cam/left_%04d.png\n"
    "camera_right = cam/right_%04d.png\n"
    "virtual_left = /abs/virt/l_%d.png\n"
    "virtual_right = virt/r_%d.png\n"
    "virtual_depth_left = virt/dl_%03d.exr\n"
    "virtual_depth_right = virt/dr_%03d.exr\n"
    "ambient = 0.1 0.2 0.3\n"
    "light = 0 3 4   1 0.9 0.8\n"
    "light = -2 0 0  0.5 0.5 0.5\r\n"
    "kd = 0.7\n"
    "ks = 0.2\n"
    "shininess = 32\n"
    "kf = 0.5\n"
    "tone = 1 0.95 0.9\n";

static void full_file_parses(void **state)
{
    (void)state;
    char dir[1024], path[1100];
    tu_tmp_path("scene_full", dir, sizeof dir);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", dir);
    assert_int_equal(system(cmd), 0);
    snprintf(path, sizeof path, "%s/scene.txt", dir);
    tu_write_text(path, full_scene);

    io_scene s;
    io_error err;
    io_result r = io_scene_load(path, &s, &err);
    if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(r, IO_OK);
    assert_string_equal(s.dir, dir);
    assert_string_equal(s.model, "models/arms.glb");
    assert_string_equal(s.animation, "wave");
    assert_string_equal(s.head_node, "head");
    assert_int_equal(s.frames, 120);
    assert_true(s.fps == 59.94f);
    assert_true(s.anim_start == 1.25f);
    assert_string_equal(s.camera[0], "cam/left_%04d.png");
    assert_string_equal(s.camera[1], "cam/right_%04d.png");
    assert_string_equal(s.virt[0], "/abs/virt/l_%d.png");
    assert_string_equal(s.virt[1], "virt/r_%d.png");
    assert_string_equal(s.virt_depth[0], "virt/dl_%03d.exr");
    assert_string_equal(s.virt_depth[1], "virt/dr_%03d.exr");
    assert_int_equal(s.has_lighting, 1);
    assert_int_equal(s.light_count, 2);
    /* directions normalised: (0,3,4)/5 and (-1,0,0) */
    assert_float_equal(s.light_dir[0][0], 0.0f, 1e-7f);
    assert_float_equal(s.light_dir[0][1], 0.6f, 1e-7f);
    assert_float_equal(s.light_dir[0][2], 0.8f, 1e-7f);
    assert_true(s.light_dir[1][0] == -1.0f && s.light_dir[1][1] == 0.0f);
    assert_true(s.light_color[0][0] == 1.0f && s.light_color[0][1] == 0.9f &&
                s.light_color[0][2] == 0.8f);
    assert_true(s.light_color[1][2] == 0.5f);
    assert_true(s.ambient[0] == 0.1f && s.ambient[1] == 0.2f && s.ambient[2] == 0.3f);
    assert_true(s.kd == 0.7f && s.ks == 0.2f && s.shininess == 32.0f && s.kf == 0.5f);
    assert_true(s.tone[0] == 1.0f && s.tone[1] == 0.95f && s.tone[2] == 0.9f);

    /* frame paths: joined to the scene's folder, absolute ones kept */
    char out[2048], want[2048];
    io_scene_frame_path(&s, s.camera[0], 7, out, sizeof out);
    snprintf(want, sizeof want, "%s/cam/left_0007.png", dir);
    assert_string_equal(out, want);
    io_scene_frame_path(&s, s.virt[0], 123, out, sizeof out);
    assert_string_equal(out, "/abs/virt/l_123.png");
    io_scene_frame_path(&s, s.virt_depth[1], 12345, out, sizeof out);
    snprintf(want, sizeof want, "%s/virt/dr_12345.exr", dir);
    assert_string_equal(out, want);
    io_scene_frame_path(&s, s.model, 0, out, sizeof out);
    snprintf(want, sizeof want, "%s/models/arms.glb", dir);
    assert_string_equal(out, want);
}

static void minimal_file_and_lighting_defaults(void **state)
{
    (void)state;
    io_scene s;
    io_error err;
    const char *base =
        "egofuse-scene 1\n"
        "model=m.gltf\n"
        "frames=1\n"
        "fps=30\n"
        "camera_left=l%d.png\n"
        "camera_right=r%d.png\n"
        "virtual_left=vl%d.png\n"
        "virtual_right=vr%d.png\n";
    assert_int_equal(scene_text("scene_min.txt", base, &s, &err), IO_OK);
    assert_int_equal(s.has_lighting, 0);
    assert_int_equal(s.light_count, 0);
    assert_string_equal(s.animation, "");
    assert_true(s.anim_start == 0.0f);
    assert_string_equal(s.virt_depth[0], "");

    /* one lighting key: the rest takes fuse_lighting_default()'s values */
    char text[1024];
    snprintf(text, sizeof text, "%sks = 0.5\n", base);
    assert_int_equal(scene_text("scene_min.txt", text, &s, &err), IO_OK);
    assert_int_equal(s.has_lighting, 1);
    assert_true(s.ks == 0.5f);
    assert_true(s.kd == 0.75f && s.shininess == 16.0f && s.kf == 0.6f);
    for (int k = 0; k < 3; k++) {
        assert_true(s.ambient[k] == 0.35f);
        assert_true(s.tone[k] == 1.0f);
        assert_true(s.light_color[0][k] == 1.0f);
    }
    assert_int_equal(s.light_count, 1);
    assert_true(s.light_dir[0][0] == 0.0f && s.light_dir[0][1] == 0.6f &&
                s.light_dir[0][2] == 0.8f);
}

static void relative_scene_path(void **state)
{
    (void)state;
    char path[1024];
    io_scene s;
    io_error err;
    /* a scene file named without a folder resolves against "." */
    char cwd[1024];
    assert_non_null(getcwd(cwd, sizeof cwd));
    tu_tmp_path("", path, sizeof path);
    assert_int_equal(chdir(path), 0);
    tu_write_text("local_scene.txt",
               "egofuse-scene 1\nmodel = a.glb\nframes = 2\nfps = 1e1\n"
               "camera_left = x/%d.png\ncamera_right = y/%d.png\n"
               "virtual_left = %%_%d.png\nvirtual_right = v%d.png\n");
    io_result r = io_scene_load("local_scene.txt", &s, &err);
    assert_int_equal(chdir(cwd), 0);
    assert_int_equal(r, IO_OK);
    assert_string_equal(s.dir, ".");
    assert_true(s.fps == 10.0f);
    char out[256];
    io_scene_frame_path(&s, s.camera[0], 3, out, sizeof out);
    assert_string_equal(out, "./x/3.png");
    io_scene_frame_path(&s, s.virt[0], 3, out, sizeof out);
    assert_string_equal(out, "./%_3.png");  /* %% is a literal percent */
    /* truncated, always terminated */
    io_scene_frame_path(&s, s.camera[0], 3, out, 5);
    assert_string_equal(out, "./x/");
}

typedef struct bad_case {
    const char *line;     /* replaces or adds one line (line 9) */
    io_result code;
    int line_no;          /* expected in "FILE:LINE:" */
    const char *needle;
} bad_case;

static void errors_name_file_and_line(void **state)
{
    (void)state;
    static const char *head =
        "egofuse-scene 1\n"
        "model = m.glb\n"
        "frames = 10\n"
        "fps = 30\n"
        "camera_left = l%d.png\n"
        "camera_right = r%d.png\n"
        "virtual_left = vl%d.png\n"
        "# comment\n";
    static const bad_case cases[] = {
        {"virtual_right = vr%d.png\nfsp = 3\n", IO_ERR_FORMAT, 10, "unknown key 'fsp'"},
        {"virtual_right = vr%d.png\nframes = 3\n", IO_ERR_FORMAT, 10, "duplicate key 'frames'"},
        {"virtual_right = vr%d.png\nkd = 0.5x\n", IO_ERR_FORMAT, 10, "not a number"},
        {"virtual_right = vr%d.png\nkd = nan\n", IO_ERR_FORMAT, 10, "finite"},
        {"virtual_right = vr%d.png\nks = inf\n", IO_ERR_FORMAT, 10, "finite"},
        {"virtual_right = vr%d.png\nkd = 1e400\n", IO_ERR_FORMAT, 10, "finite"},
        {"virtual_right = vr%d.png\nambient = 1 2\n", IO_ERR_FORMAT, 10, "expected 3 numbers, got 2"},
        {"virtual_right = vr%d.png\ntone = 1 2 3 4\n", IO_ERR_FORMAT, 10, "got more"},
        {"virtual_right = vr%d.png\nlight = 0 0 0 1 1 1\n", IO_ERR_VALUE, 10, "zero direction"},
        {"virtual_right = vr%d.png\nshininess = 0.5\n", IO_ERR_VALUE, 10, "shininess"},
        {"virtual_right = vr%d.png\nkf = 1.5\n", IO_ERR_VALUE, 10, "kf"},
        {"virtual_right = vr%d.png\nmodel\n", IO_ERR_FORMAT, 10, "key = value"},
        {"virtual_right = vr%d.png\nhead_node =\n", IO_ERR_FORMAT, 10, "empty value"},
        {"virtual_right = vr.png\n", IO_ERR_FORMAT, 9, "exactly one"},
        {"virtual_right = vr%d_%d.png\n", IO_ERR_FORMAT, 9, "exactly one"},
        {"virtual_right = vr%s.png\n", IO_ERR_FORMAT, 9, "only %d"},
        {"virtual_right = vr%5d.png\n", IO_ERR_FORMAT, 9, "only %d"},
        {"virtual_right = vr%0d.png\n", IO_ERR_FORMAT, 9, "only %d"},
        {"virtual_right = vr%ld.png\n", IO_ERR_FORMAT, 9, "only %d"},
        {"virtual_right = vr%\n", IO_ERR_FORMAT, 9, "only %d"},
        {"virtual_right = vr%d.png\nvirtual_depth_left = d%x.exr\n", IO_ERR_FORMAT, 10, "only %d"},
        {"frames = 5\n", IO_ERR_FORMAT, 9, "duplicate key 'frames' (first on line 3)"},
        {"", IO_ERR_MISSING, 8, "missing required key 'virtual_right'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char text[2048], want[64];
        snprintf(text, sizeof text, "%s%s", head, cases[i].line);
        io_scene s;
        io_error err;
        memset(&s, 0x33, sizeof s);
        io_result r = scene_text("bad_scene.txt", text, &s, &err);
        snprintf(want, sizeof want, "bad_scene.txt:%d: ", cases[i].line_no);
        if (r != cases[i].code || !strstr(err.msg, want) ||
            !strstr(err.msg, cases[i].needle))
            fprintf(stderr, "case %zu: %s: %s\n", i, io_result_str(r), err.msg);
        assert_int_equal(r, cases[i].code);
        assert_non_null(strstr(err.msg, want));
        assert_non_null(strstr(err.msg, cases[i].needle));
        assert_string_equal(s.model, "");  /* zeroed on failure */
    }
}

static void frames_and_fps_checks(void **state)
{
    (void)state;
    static const char *const bad_values[] = {
        "frames = 0", "frames = -3", "frames = 1.5", "frames = 99999999999",
        "frames = ", "fps = 0", "fps = -1", "fps = 3O",
        "animation_start = -1", "animation_start = nan", "animation_start = 2e6",
    };
    for (size_t i = 0; i < sizeof bad_values / sizeof bad_values[0]; i++) {
        char text[1024];
        int is_frames = strncmp(bad_values[i], "frames", 6) == 0;
        snprintf(text, sizeof text,
                 "egofuse-scene 1\nmodel = m.glb\n%s\n%s\n"
                 "camera_left = l%%d.png\ncamera_right = r%%d.png\n"
                 "virtual_left = vl%%d.png\nvirtual_right = vr%%d.png\n",
                 bad_values[i], is_frames ? "fps = 30" : "frames = 3");
        io_scene s;
        io_error err;
        io_result r = scene_text("bad_numbers.txt", text, &s, &err);
        assert_true(r == IO_ERR_FORMAT || r == IO_ERR_VALUE);
        assert_non_null(strstr(err.msg, "bad_numbers.txt:3: "));
    }
}

static void header_and_file_errors(void **state)
{
    (void)state;
    io_scene s;
    io_error err;
    static const char *const headers[] = {
        "egofuse-scene 2\n", "egofuse-scene 1 \n", "# egofuse-scene 1\n",
        "\negofuse-scene 1\n", "",
    };
    for (size_t i = 0; i < sizeof headers / sizeof headers[0]; i++) {
        assert_int_equal(scene_text("hdr.txt", headers[i], &s, &err), IO_ERR_FORMAT);
        assert_non_null(strstr(err.msg, "hdr.txt:1: "));
    }
    /* nine lights */
    char text[2048] = "egofuse-scene 1\n";
    for (int i = 0; i < 9; i++) strcat(text, "light = 0 1 0 1 1 1\n");
    assert_int_equal(scene_text("hdr.txt", text, &s, &err), IO_ERR_VALUE);
    assert_non_null(strstr(err.msg, "hdr.txt:10: "));

    char path[1024];
    tu_tmp_path("no_such_scene.txt", path, sizeof path);
    assert_int_equal(io_scene_load(path, &s, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "no_such_scene.txt"));
    assert_int_equal(io_scene_load(NULL, &s, &err), IO_ERR_ARGS);
}

/* The optional `tracking` key: a plain path, resolved like the model,
 * absent = "", strictly parsed (once, not empty, no frame conversion). */
static void tracking_key(void **state)
{
    (void)state;
    char text[2048], out[2200];
    io_scene s;
    io_error err;
    const char *base =
        "egofuse-scene 1\n"
        "model = m.glb\n"
        "frames = 2\n"
        "fps = 60\n"
        "camera_left = l%d.png\n"
        "camera_right = r%d.png\n"
        "virtual_left = vl%d.png\n"
        "virtual_right = vr%d.png\n";
    assert_int_equal(scene_text("scene_track.txt", base, &s, &err), IO_OK);
    assert_string_equal(s.tracking, "");

    snprintf(text, sizeof text, "%stracking = rec/track.txt   # the true motion\n", base);
    io_result r = scene_text("scene_track.txt", text, &s, &err);
    if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
    assert_int_equal(r, IO_OK);
    assert_string_equal(s.tracking, "rec/track.txt");
    io_scene_frame_path(&s, s.tracking, 0, out, sizeof out);
    char want[2200];
    snprintf(want, sizeof want, "%s/rec/track.txt", s.dir);
    assert_string_equal(out, want);

    /* a literal percent sign */
    snprintf(text, sizeof text, "%stracking = /abs/100%%%%.txt\n", base);
    assert_int_equal(scene_text("scene_track.txt", text, &s, &err), IO_OK);
    assert_string_equal(s.tracking, "/abs/100%%.txt");
    io_scene_frame_path(&s, s.tracking, 7, out, sizeof out);
    assert_string_equal(out, "/abs/100%.txt");

    static const struct { const char *line, *needle; io_result code; int line_no; } bad[] = {
        { "tracking = a.txt\ntracking = b.txt\n", "duplicate key 'tracking' (first on line 9)", IO_ERR_FORMAT, 10 },
        { "tracking =\n", "empty value", IO_ERR_FORMAT, 9 },
        { "tracking = t_%04d.txt\n", "not a frame pattern", IO_ERR_FORMAT, 9 },
        { "tracking = t%.txt\n", "not a frame pattern", IO_ERR_FORMAT, 9 },
        { "tracking = t%\n", "not a frame pattern", IO_ERR_FORMAT, 9 },
        { "Tracking = t.txt\n", "unknown key 'Tracking'", IO_ERR_FORMAT, 9 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(text, sizeof text, "%s%s", base, bad[i].line);
        r = scene_text("scene_track.txt", text, &s, &err);
        if (r != bad[i].code || !strstr(err.msg, bad[i].needle))
            fprintf(stderr, "case %zu: %s: %s\n", i, io_result_str(r), err.msg);
        assert_int_equal(r, bad[i].code);
        assert_non_null(strstr(err.msg, bad[i].needle));
        snprintf(want, sizeof want, "scene_track.txt:%d: ", bad[i].line_no);
        if (!strstr(err.msg, want)) fail_msg("case %zu: '%s' lacks '%s'", i, err.msg, want);
    }
}

TU_MAIN_NAMED("io_scene", NULL, NULL,
              cmocka_unit_test(full_file_parses),
              cmocka_unit_test(minimal_file_and_lighting_defaults),
              cmocka_unit_test(relative_scene_path),
              cmocka_unit_test(errors_name_file_and_line),
              cmocka_unit_test(frames_and_fps_checks),
              cmocka_unit_test(header_and_file_errors),
              cmocka_unit_test(tracking_key))
