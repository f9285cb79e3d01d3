/* test_cli_run.c - `egofuse run` on this machine, without cameras or a
 * display: a dry run from recorded camera frames (a short generated
 * sequence) posed by NatNet frames that `egofuse replay-track` serves on
 * the loopback; the frame it dumps (--dump) composites to the same bytes
 * in `egofuse render`; the same run from a cockpit configuration file;
 * the per-frame CSV; bad sources and options with their messages; and, on
 * a machine without cameras, the message that says what to use instead. */
#include "support/testutil.h"
#include <cmocka.h>

#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../src/io/io.h"
#include "support/files.h"

static char out[1 << 16];
static char seq[512];       /* the generated sequence's folder */
static char bin_path[600];  /* egofuse */

static int setup(void **st)
{
    (void)st;
    snprintf(bin_path, sizeof bin_path, "%s", tu_bin());
    return tu_gen_seq("seq", 3, NULL, seq, sizeof seq);
}

/* Runs egofuse with a NULL-terminated argument list; output in out. */
#define ego(...) tu_runl(out, sizeof out, bin_path, __VA_ARGS__)

/* `egofuse replay-track` as a NatNet server on 127.0.0.1:port, looping. */
static pid_t start_replay(int port)
{
    char track[600], to[64];
    snprintf(track, sizeof track, "%s/track.txt", seq);
    snprintf(to, sizeof to, "natnet:127.0.0.1:%d", port);
    pid_t pid = fork();
    if (pid == 0) {
        int dn = open("/dev/null", 1);
        dup2(dn, 1);
        dup2(dn, 2);
        execl(bin_path, bin_path, "replay-track", track, "--to", to, "--loop", (char *)NULL);
        _exit(127);
    }
    return pid;
}

static void stop(pid_t pid)
{
    if (pid <= 0) return;
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
}

/* Bytes that differ between two images of the same size (RGB of RGBA). */
static long image_diff(const char *a, const char *b)
{
    io_image x, y;
    io_error err;
    if (io_image_load(a, IO_U8, 4, &x, &err) != IO_OK) fail_msg("%s", err.msg);
    if (io_image_load(b, IO_U8, 4, &y, &err) != IO_OK) fail_msg("%s", err.msg);
    assert_int_equal(x.width, y.width);
    assert_int_equal(x.height, y.height);
    long bad = 0;
    for (int r = 0; r < x.height; r++)
        for (int c = 0; c < x.width; c++)
            for (int k = 0; k < 3; k++)
                bad += ((uint8_t *)x.data)[(size_t)r * x.stride + 4 * (size_t)c + (size_t)k] !=
                       ((uint8_t *)y.data)[(size_t)r * y.stride + 4 * (size_t)c + (size_t)k];
    io_image_free(&x);
    io_image_free(&y);
    return bad;
}

static int count_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    int n = 0, c;
    while ((c = fgetc(f)) != EOF) n += c == '\n';
    fclose(f);
    return n;
}

/* The dry run posed by NatNet, its last frame dumped and rendered again:
 * run's output and render's are the same bytes, both eyes. */
static void dry_run_equals_render(void **st)
{
    (void)st;
    char scene[600], left[600], right[600], o[600], d[600], csv[600], r[600], port[16];
    snprintf(scene, sizeof scene, "%s/scene.txt", seq);
    snprintf(left, sizeof left, "file:%s/cam/left_%%04d.png", seq);
    snprintf(right, sizeof right, "file:%s/cam/right_%%04d.png", seq);
    tu_tmp_path("run_out", o, sizeof o);
    tu_tmp_path("run_dump", d, sizeof d);
    tu_tmp_path("run_frames.csv", csv, sizeof csv);
    tu_tmp_path("run_render", r, sizeof r);
    int p = 20000 + (int)(getpid() % 20000);
    snprintf(port, sizeof port, "%d", p);
    pid_t rp = start_replay(p);
    int rc = ego("run", "--scene", scene, "--left", left, "--right", right, "--fps", "10", "--loop",
                 "--natnet", "127.0.0.1", "--natnet-command-port", port, "--frames", "3", "--out",
                 o, "--dump", d, "--stats", csv, "--quiet", NULL);
    stop(rp);
    if (rc != 0) fail_msg("run: exit %d: %s", rc, out);
    assert_non_null(strstr(out, "egofuse run: 3 stereo frames"));
    assert_null(strstr(out, "no pose yet"));
    assert_int_equal(count_lines(csv), 4); /* the header and 3 frames */
    char tr[700];
    snprintf(tr, sizeof tr, "%s/track.txt", d);
    assert_true(tu_exists(tr)); /* the pose came from the tracker */
    char ds[700];
    snprintf(ds, sizeof ds, "%s/scene.txt", d);
    rc = ego("render", "--scene", ds, "--out", r, "--pose", "tracking", "--no-filter", "--quiet",
             NULL);
    if (rc != 0) fail_msg("render of the dump: exit %d: %s", rc, out);
    for (int e = 0; e < 2; e++) {
        char a[700], b[700];
        snprintf(a, sizeof a, "%s/%s_0002.png", o, e ? "right" : "left");
        snprintf(b, sizeof b, "%s/%s_0000.png", r, e ? "right" : "left");
        long bad = image_diff(a, b);
        if (bad) fail_msg("%s and %s: %ld bytes differ", a, b, bad);
    }
}

/* The same cockpit from a configuration file; the command line wins. */
static void config_file(void **st)
{
    (void)st;
    char conf[600], o[600];
    tu_tmp_path("cockpit.conf", conf, sizeof conf);
    tu_tmp_path("conf_out", o, sizeof o);
    /* relative to the file's folder: seq/ is beside it */
    tu_write_fmt(conf, "# a dry-run cockpit\nscene = seq/scene.txt\nhide = left-arm\n[cameras]\n"
               "left = file:seq/cam/left_%%04d.png\nright = file:seq/cam/right_%%04d.png\n"
               "fps = 10\nloop = yes\n[hmd]\nipd = 0.062\n[output]\nout = conf_out\n"
               "frames = 5   ; the command line says 2\nquiet = yes\n");
    int rc = ego("run", "--config", conf, "--frames", "2", NULL);
    if (rc != 0) fail_msg("run --config: exit %d: %s", rc, out);
    assert_non_null(strstr(out, "egofuse run: 2 stereo frames"));
    char png[700];
    snprintf(png, sizeof png, "%s/right_0001.png", o);
    assert_true(tu_exists(png));
    snprintf(png, sizeof png, "%s/right_0002.png", o);
    assert_false(tu_exists(png));

    /* an unknown key names the file and the line */
    tu_write_fmt(conf, "scene = seq/scene.txt\n[natnet]\nserver = 127.0.0.1\nbogus = 1\n");
    rc = ego("run", "--config", conf, NULL);
    assert_int_equal(rc, 2);
    char want[700];
    snprintf(want, sizeof want, "%s:4: unknown option '--natnet-bogus=1'", conf);
    if (!strstr(out, want)) fail_msg("got: %s", out);
}

/* Bad sources, outputs and options: a message naming the input and the
 * reason, exit 1 (2 for the command line), nothing written. */
static void bad_inputs(void **st)
{
    (void)st;
    char scene[600], left[600], right[600], o[600];
    snprintf(scene, sizeof scene, "%s/scene.txt", seq);
    snprintf(left, sizeof left, "file:%s/cam/left_%%04d.png", seq);
    snprintf(right, sizeof right, "file:%s/cam/right_%%04d.png", seq);
    tu_tmp_path("bad_out", o, sizeof o);
    static const struct {
        const char *opt, *val;
        int rc;
        const char *msg;
    } cases[] = {
        {"--virt-source", "stream:/nonexistent/v.y4m", 1, "/nonexistent/v.y4m"},
        {"--virt-source", "bogus:x", 1, "bogus:x"},
        {"--display", "kms:/dev/null", 1, "/dev/null"},
        {"--display", "vga", 2, "vga"},
        {"--natnet-up", "x", 2, "up 'x'"},
        {"--hide", "left-foot", 2, "left-foot"},
        {"--prop", "@1,2,3", 2, "--prop"},
        {"--hmd-ipd", "0.3", 2, "--hmd-ipd"},
        {"--virt-layout", "diagonal", 2, "diagonal"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        int disp = !strcmp(cases[i].opt, "--display");
        int rc = ego("run", "--scene", scene, "--left", left, "--right", right, "--frames", "1",
                     disp ? "--quiet" : "--out", disp ? "--quiet" : o, cases[i].opt, cases[i].val,
                     NULL);
        if (rc != cases[i].rc || !strstr(out, cases[i].msg))
            fail_msg("%s %s: exit %d (want %d), message: %s", cases[i].opt, cases[i].val, rc,
                     cases[i].rc, out);
        char png[700];
        snprintf(png, sizeof png, "%s/left_0000.png", o);
        if (tu_exists(png)) fail_msg("%s %s: wrote %s", cases[i].opt, cases[i].val, png);
    }
    /* a prop posed by a rigid body needs NatNet */
    int rc = ego("run", "--scene", scene, "--prop", "stick.glb#Joystick", NULL);
    assert_int_equal(rc, 2);
    assert_non_null(strstr(out, "needs --natnet"));
}

/* Without cameras (this machine's kernel has no V4L2): what is missing
 * and what to use instead. */
static void no_cameras(void **st)
{
    (void)st;
    if (tu_exists("/dev/video0")) {
        printf("SKIP: this machine has /dev/video0\n");
        skip();
    }
    char scene[600];
    snprintf(scene, sizeof scene, "%s/scene.txt", seq);
    int rc = ego("run", "--scene", scene, NULL);
    assert_int_equal(rc, 1);
    assert_non_null(strstr(out, "no cameras found"));
    assert_non_null(strstr(out, "--left file:"));
    assert_non_null(strstr(out, "egofuse render"));
}

TU_MAIN(setup, NULL,
        cmocka_unit_test(dry_run_equals_render),
        cmocka_unit_test(config_file),
        cmocka_unit_test(bad_inputs),
        cmocka_unit_test(no_cameras))
