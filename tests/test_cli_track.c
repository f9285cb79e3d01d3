/* test_cli_track.c - `egofuse replay-track` and `egofuse calibrate`, run
 * as the program (EGOFUSE_BIN):
 *  - a generated recording replayed at 20x as a NatNet server (3.1 and 4.1,
 *    Y-up metres and Z-up millimetres) into the NatNet client, and as UDP
 *    packets into io_track_udp, on 127.0.0.1: every sample arrives with
 *    its values;
 *  - a calibration recording of a user of known proportions (arms 1.1x,
 *    shoulders 1.05x, hands 1.08x the model's) turned into a calibration
 *    file whose values match and which loads back; bad inputs named.
 * No sleeps: bounded polls. */
#include "support/testutil.h"
#include <cmocka.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "../src/io/io_natnet.h"
#include "support/sample_model.h"
#include "support/tu_kin.h"

static char out[65536];

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int free_port(void)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in sa = { .sin_family = AF_INET };
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(fd, (struct sockaddr *)&sa, sizeof sa);
    socklen_t sl = sizeof sa;
    getsockname(fd, (struct sockaddr *)&sa, &sl);
    close(fd);
    return ntohs(sa.sin_port);
}

/* A recording: n samples at 100 Hz, every part moving; the left hand
 * missing in samples 10..14 (a dropout the stream must carry), saved in
 * the scratch file name (its path in path[512]). */
#define NS 40
static void make_recording(const char *name, char *path, kin_track_sample *s)
{
    tu_tmp_path(name, path, 512);
    for (int i = 0; i < NS; i++) {
        memset(&s[i], 0, sizeof s[i]);
        s[i].t = 2.0 + 0.01 * i;
        s[i].valid = KIN_TRACK_ALL & ~(uint32_t)(KIN_TRACK_GLOVE_L | KIN_TRACK_GLOVE_R);
        if (i >= 10 && i < 15) s[i].valid &= ~(uint32_t)KIN_TRACK_HAND_L;
        float a = 0.05f * (float)i;
        s[i].head_pos = kin_v3(0.01f * a, 1.25f, -0.08f + 0.02f * a);
        s[i].head_rot = kin_quat_axis_angle(kin_v3(0, 1, 0), 0.3f * a);
        s[i].shoulder[0] = kin_v3(-0.19f, 0.97f + 0.01f * a, 0);
        s[i].shoulder[1] = kin_v3(0.19f, 0.97f - 0.01f * a, 0);
        s[i].hand_pos[0] = kin_v3(-0.12f - 0.1f * a, 1.07f, -0.31f - 0.05f * a);
        s[i].hand_pos[1] = kin_v3(0.13f + 0.1f * a, 1.075f, -0.32f);
        s[i].hand_rot[0] = kin_quat_axis_angle(kin_v3_norm(kin_v3(1, 2, 3)), a);
        s[i].hand_rot[1] = kin_quat_axis_angle(kin_v3_norm(kin_v3(-1, 2, 1)), -a);
        s[i].glove[0][2] = 0.5f;   /* not part of the stream: gloves are not sent */
    }
    io_error err;
    if (io_track_save(path, s, NS, &err) != IO_OK) fail_msg("%s", err.msg);
    /* what the file holds (9 significant digits: exact floats) */
    kin_track_sample *back;
    int n;
    if (io_track_load(path, &back, &n, &err) != IO_OK) fail_msg("%s", err.msg);
    assert_int_equal(n, NS);
    memcpy(s, back, sizeof *s * NS);
    io_track_free(back);
}

typedef struct rec { int n; double ts[4 * NS]; kin_track_sample s[4 * NS]; int models; } rec;
static void on_sample(void *user, const kin_track_sample *s, const io_natnet *n)
{
    rec *r = user;
    if (r->n < 4 * NS) {
        r->ts[r->n] = n->server_time;
        r->models = n->have_models;
        r->s[r->n++] = *s;
    }
}

static pid_t spawn(char *const argv[], const char *log)
{
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) { dup2(fd, 1); dup2(fd, 2); close(fd); }
        execv(argv[0], argv);
        _exit(127);
    }
    return pid;
}

static void replay_natnet(const char *version, int z_mm)
{
    char path[512], log[512];
    tu_tmp_path("replay_natnet.log", log, sizeof log);
    kin_track_sample s[NS];
    make_recording("replay_track.txt", path, s);
    int port = free_port();
    char to[64], ps[16];
    snprintf(to, sizeof to, "natnet:127.0.0.1:%d", port);
    snprintf(ps, sizeof ps, "%d", port);
    io_natnet_config c;
    io_natnet_config_default(&c);
    io_error err;
    assert_int_equal(io_natnet_config_set(&c, "command-port", ps, &err), IO_OK);
    assert_int_equal(io_natnet_config_set(&c, "local", "127.0.0.1", &err), IO_OK);
    if (z_mm) {
        assert_int_equal(io_natnet_config_set(&c, "up", "z", &err), IO_OK);
        assert_int_equal(io_natnet_config_set(&c, "units", "mm", &err), IO_OK);
    }
    c.resend_ms = 100;
    io_natnet n;
    assert_int_equal(io_natnet_open(&n, &c, &err), IO_OK);
    static rec r;
    memset(&r, 0, sizeof r);
    n.on_sample = on_sample;
    n.user = &r;
    char *argv[] = { (char *)tu_bin(), "replay-track", path, "--to", to, "--speed", "20",
                     "--natnet-version", (char *)version, "--natnet-up", z_mm ? "z" : "y",
                     "--natnet-units", z_mm ? "mm" : "m", "--wait", "10", NULL };
    pid_t pid = spawn(argv, log);
    assert_true(pid > 0);
    int status = -1, done = 0;
    double end = now_s() + 15.0;
    while (now_s() < end) {
        assert_int_equal(io_natnet_poll(&n, 50, NULL, NULL, &err), IO_OK);
        if (done) break;   /* one more drain after the replay ended */
        if (waitpid(pid, &status, WNOHANG) == pid) done = 1;
    }
    if (!done) {
        kill(pid, SIGTERM);
        waitpid(pid, &status, 0);
        fail_msg("replay-track did not finish within 15 s (%s)", n.status);
    }
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    /* every frame arrived, in order, none bad */
    if (r.n != NS) fail_msg("%d frames of %d arrived (%s)", r.n, NS, n.status);
    assert_int_equal(n.bad, 0);
    assert_int_equal(n.dropped_order, 0);
    assert_int_equal(n.version_major * 10 + n.version_minor, version[0] == '3' ? 31 : 41);
    int checked = 0;
    double tol = z_mm ? 2e-6 : 1e-6;
    for (int i = 0; i < r.n; i++) {
        assert_true(r.ts[i] == s[i].t);   /* the server's time stamp is the file's */
        if (i > 0) assert_true(r.s[i].t > r.s[i - 1].t);
        if (!r.models && !(r.s[i].valid & KIN_TRACK_SHOULDER_L)) continue; /* names not known yet */
        const kin_track_sample *a = &r.s[i], *b = &s[i];
        assert_int_equal(a->valid, b->valid & 0x1F);
        NEAR3(a->head_pos, b->head_pos.x, b->head_pos.y, b->head_pos.z, tol);
        NEAR(a->head_rot.x, b->head_rot.x, 1e-6);
        NEAR(a->head_rot.w, b->head_rot.w, 1e-6);
        NEAR3(a->shoulder[0], b->shoulder[0].x, b->shoulder[0].y, b->shoulder[0].z, tol);
        NEAR3(a->shoulder[1], b->shoulder[1].x, b->shoulder[1].y, b->shoulder[1].z, tol);
        if (b->valid & KIN_TRACK_HAND_L) {
            NEAR3(a->hand_pos[0], b->hand_pos[0].x, b->hand_pos[0].y, b->hand_pos[0].z, tol);
            NEAR(a->hand_rot[0].z, b->hand_rot[0].z, 1e-6);
        }
        NEAR3(a->hand_pos[1], b->hand_pos[1].x, b->hand_pos[1].y, b->hand_pos[1].z, tol);
        NEAR(a->hand_rot[1].y, b->hand_rot[1].y, 1e-6);
        checked++;
    }
    /* the replay starts once the client asked for the model definitions:
     * every frame carries the names */
    if (checked != NS) fail_msg("only %d of %d samples had the model definitions", checked, NS);
    io_natnet_close(&n);
}

static void result_replay_natnet_4_1(void **state) { (void)state; replay_natnet("4.1", 0); }
static void result_replay_natnet_3_1_zup_mm(void **state) { (void)state; replay_natnet("3.1", 1); }

static void result_replay_udp(void **state)
{
    (void)state;
    char path[512];
    kin_track_sample s[NS];
    make_recording("replay_udp.txt", path, s);
    io_track_udp u;
    io_error err;
    assert_int_equal(io_track_udp_listen(&u, "127.0.0.1", 0, &err), IO_OK);
    char to[64];
    snprintf(to, sizeof to, "udp:127.0.0.1:%d", u.port);
    char *argv[] = { (char *)tu_bin(), "replay-track", path, "--to", to, "--speed", "50", NULL };
    if (tu_run(argv, out, sizeof out) != 0) fail_msg("%s", out);
    assert_non_null(strstr(out, "sent 40 samples (1 pass) to udp 127.0.0.1:"));
    kin_track_sample got;
    int fresh = 0;
    assert_int_equal(io_track_udp_poll(&u, 1000, &got, &fresh, &err), IO_OK);
    assert_int_equal(u.accepted, NS);
    assert_int_equal(u.rejected + u.stale, 0);
    assert_int_equal(u.last_seq, NS);
    /* positions bit for bit; rotations up to the receiver's renormalisation */
    const kin_track_sample *b = &s[NS - 1];
    assert_true(got.t == b->t);
    assert_int_equal(got.valid, b->valid);
    assert_memory_equal(&got.hand_pos, &b->hand_pos, sizeof got.hand_pos);
    assert_memory_equal(&got.head_pos, &b->head_pos, sizeof got.head_pos);
    NEAR(got.head_rot.y, b->head_rot.y, 1e-6);
    NEAR(got.hand_rot[1].x, b->hand_rot[1].x, 1e-6);
    io_track_udp_close(&u);
}

/* egofuse replay-track with the arguments given (NULL-terminated, at most
 * 12): the exit status rc and, unless msg is NULL, msg in its output. */
static void replay_says(int rc, const char *msg, ...)
{
    char *argv[16] = { (char *)tu_bin(), "replay-track" };
    int n = 2;
    va_list ap;
    va_start(ap, msg);
    for (const char *a; n < 14 && (a = va_arg(ap, const char *)) != NULL;) argv[n++] = (char *)a;
    va_end(ap);
    argv[n] = NULL;
    int got = tu_run(argv, out, sizeof out);
    if (got != rc || (msg && !strstr(out, msg)))
        fail_msg("replay-track %s %s: exit %d (want %d), output: %s", argv[2], argv[3], got, rc,
                 out);
}

static void validity_replay_args(void **state)
{
    (void)state;
    char path[512];
    kin_track_sample s[NS];
    make_recording("replay_args.txt", path, s);
    replay_says(2, "--to 'tcp:x:1': udp:HOST:PORT or natnet:ADDR[:PORT]", path, "--to", "tcp:x:1",
                NULL);
    replay_says(1, "/nonexistent/track.txt: No such file", "/nonexistent/track.txt", "--to",
                "udp:127.0.0.1:9", NULL);
    replay_says(1, "'no-such-host.invalid' is neither an IPv4 address nor a known host", path,
                "--to", "natnet:no-such-host.invalid", NULL);
    int port = free_port();
    char to[64];
    snprintf(to, sizeof to, "natnet:127.0.0.1:%d", port);
    replay_says(1, "no NatNet client connected within 0.2 s", path, "--to", to, "--wait", "0.2",
                NULL);
    replay_says(2, NULL, path, "--to", "udp:127.0.0.1:9", "--speed", "0", NULL);
    /* a malformed HOST:PORT is a command-line error (2), found before the file is read */
    replay_says(2, "--to '127.0.0.1': needs HOST:PORT", "/nonexistent/track.txt", "--to",
                "udp:127.0.0.1", NULL);
    replay_says(2, "'99999' is not a port", path, "--to", "natnet:127.0.0.1:99999", NULL);
    replay_says(2, "no host", path, "--to", "udp::9", NULL);
}

/* ---------------------------------------------------------- calibrate */

TU_SAMPLE_GROUP(g_samples, "calib_samples", 3)

#define TRUE_ARM 1.10f
#define TRUE_SHOULDER 1.05f
#define TRUE_HAND 1.08f

/* The calibration poses of a user TRUE_* times the model: 500 samples of
 * arms stretched forward and sideways or bent (2 mm noise), then 300 of
 * the fingertip gesture (1 mm noise), 100 Hz. */
static int calib_recording(kin_track_sample *s, const kin_arm_rig *rig, const kin_vec3 tip[2])
{
    tu_rng g = { 0x63616c69 };
    int n = 0;
    float width = TRUE_SHOULDER * rig->shoulder_width;
    for (int i = 0; i < 500; i++, n++) {
        memset(&s[n], 0, sizeof s[n]);
        s[n].t = 0.01 * n;
        s[n].valid = KIN_TRACK_HEAD | KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R |
                     KIN_TRACK_HAND_L | KIN_TRACK_HAND_R;
        s[n].head_rot = s[n].hand_rot[0] = s[n].hand_rot[1] = kin_quat_identity();
        s[n].head_pos = kin_v3(0, 1.3f, -0.08f);
        for (int k = 0; k < 2; k++) {
            float sx = k ? 1.0f : -1.0f;
            float len = TRUE_ARM * (rig->upper_len[k] + rig->fore_len[k]);
            float shx = 0.002f * tu_range(&g, -1, 1); /* draws in a defined order */
            float shz = 0.002f * tu_range(&g, -1, 1);
            kin_vec3 sh = kin_v3(0.5f * width * sx + shx, 1.0f, shz);
            int phase = (i / 50) % 5;
            kin_vec3 dir = phase == 0 ? kin_v3(0, 0, -1)
                         : phase == 1 ? kin_v3(sx, 0, 0) : kin_v3_norm(kin_v3(0.3f * sx, -0.5f, -1));
            float l = phase <= 1 ? len : len * tu_range(&g, 0.4f, 0.85f);
            s[n].shoulder[k] = sh;
            float nx = 0.002f * tu_range(&g, -1, 1);
            float ny = 0.002f * tu_range(&g, -1, 1);
            float nz = 0.002f * tu_range(&g, -1, 1);
            s[n].hand_pos[k] = kin_v3_add(kin_v3_add(sh, kin_v3_scale(dir, l)), kin_v3(nx, ny, nz));
        }
    }
    for (int i = 0; i < 300; i++, n++) {
        memset(&s[n], 0, sizeof s[n]);
        s[n].t = 0.01 * n;
        s[n].valid = KIN_TRACK_HEAD | KIN_TRACK_SHOULDER_L | KIN_TRACK_SHOULDER_R |
                     KIN_TRACK_HAND_L | KIN_TRACK_HAND_R;
        s[n].head_rot = kin_quat_identity();
        s[n].head_pos = kin_v3(0, 1.3f, -0.08f);
        s[n].shoulder[0] = kin_v3(-0.5f * width, 1.0f, 0);
        s[n].shoulder[1] = kin_v3(0.5f * width, 1.0f, 0);
        /* the fingertip gesture, touching */
        tu_fingertip_gesture(&s[n], i, kin_v3_scale(tip[0], TRUE_HAND),
                             kin_v3_scale(tip[1], TRUE_HAND), 0.0f);
        for (int k = 0; k < 2; k++) {
            float nx = 0.001f * tu_range(&g, -1, 1);
            float ny = 0.001f * tu_range(&g, -1, 1);
            float nz = 0.001f * tu_range(&g, -1, 1);
            s[n].hand_pos[k] = kin_v3_add(s[n].hand_pos[k], kin_v3(nx, ny, nz));
        }
    }
    return n;
}

/* The sample model's arm rig and hand tips (the test skipped without
 * the model) and the calibration recording of them in s (800 samples):
 * calib_recording's count. */
static int calib_setup(kin_arm_rig *rig, kin_vec3 tip[2], kin_track_sample *s)
{
    if (g_samples.skip[0]) {
        printf("%s\n", g_samples.skip);
        skip();
    }
    char why[256];
    if (kin_arm_rig_init(rig, &g_samples.model, why, sizeof why)) fail_msg("%s", why);
    if (kin_user_calib_hand_tips(rig, &g_samples.model, tip, why, sizeof why)) fail_msg("%s", why);
    return calib_recording(s, rig, tip);
}

static void result_calibrate(void **state)
{
    (void)state;
    kin_arm_rig rig;
    kin_vec3 tip[2];
    static kin_track_sample s[800];
    int n = calib_setup(&rig, tip, s);
    char rec[512], cal[512], glove[512];
    tu_tmp_path("calib_rec.txt", rec, sizeof rec);
    tu_tmp_path("calib_out.txt", cal, sizeof cal);
    tu_tmp_path("calib_glove.txt", glove, sizeof glove);
    io_error err;
    assert_int_equal(io_track_save(rec, s, n, &err), IO_OK);
    FILE *f = fopen(glove, "w");
    assert_non_null(f);
    fprintf(f, "# raw readings, left glove, opening and closing\n");
    for (int i = 0; i < 100; i++) {
        float v = 0.2f + 0.6f * (float)(i % 50) / 49.0f;
        fprintf(f, "%.4f %.4f %.4f %.4f %.4f\n", v, v, v, v, 0.1f + v);
    }
    fclose(f);
    remove(cal);
    char *argv[] = { (char *)tu_bin(), "calibrate", "--model", g_samples.path, "--recording", rec,
                     "--glove-left", glove, "--out", cal, NULL };
    if (tu_run(argv, out, sizeof out) != 0) fail_msg("%s", out);
    assert_non_null(strstr(out, "(fingertip gesture)"));
    printf("NOTE: %s", out);
    kin_user_calib c;
    if (io_user_calib_load(cal, &c, &err) != IO_OK) fail_msg("%s", err.msg);
    /* tolerances: arms 1% (95th percentile within the 2 mm noise), the
     * shoulders 1%, the hands 1% (1 mm noise on 0.2 m) */
    for (int k = 0; k < 2; k++) {
        NEAR(c.arm_scale[k], TRUE_ARM, 0.01);
        NEAR(c.hand_scale[k], TRUE_HAND, 0.01);
        NEAR(c.arm_length[k], TRUE_ARM * (rig.upper_len[k] + rig.fore_len[k]), 0.006);
        NEAR(c.hand_length[k], TRUE_HAND * kin_v3_len(tip[k]), 0.003);
    }
    NEAR(c.shoulder_scale, TRUE_SHOULDER, 0.01);
    assert_true(c.has_glove[0]);
    assert_false(c.has_glove[1]);
    NEAR(c.glove[0].raw_open[0], 0.2, 0.02);
    NEAR(c.glove[0].raw_fist[0], 0.8, 0.02);
    NEAR(c.glove[0].raw_fist[4], 0.9, 0.02);
}

static void validity_calibrate(void **state)
{
    (void)state;
    kin_arm_rig rig;
    kin_vec3 tip[2];
    static kin_track_sample s[800];
    calib_setup(&rig, tip, s);
    char rec[512], cal[512], glove[512];
    tu_tmp_path("calib_short.txt", rec, sizeof rec);
    tu_tmp_path("calib_bad_out.txt", cal, sizeof cal);
    io_error err;
    /* too few samples: named, nothing written */
    assert_int_equal(io_track_save(rec, s, 10, &err), IO_OK);
    remove(cal);
    char *a1[] = { (char *)tu_bin(), "calibrate", "--model", g_samples.path, "--recording", rec,
                   "--out", cal, NULL };
    assert_int_equal(tu_run(a1, out, sizeof out), 1);
    assert_non_null(strstr(out, "calib_short.txt: left arm: 10 samples with shoulder and hand, "
                                "need 20"));
    assert_false(tu_exists(cal));
    /* a folder that does not exist: the write fails, named */
    tu_tmp_path("calib_rec_ok.txt", rec, sizeof rec);
    assert_int_equal(io_track_save(rec, s, 800, &err), IO_OK);
    char *a2[] = { (char *)tu_bin(), "calibrate", "--model", g_samples.path, "--recording", rec,
                   "--out", "/nonexistent-dir/calib.txt", NULL };
    assert_int_equal(tu_run(a2, out, sizeof out), 1);
    assert_non_null(strstr(out, "/nonexistent-dir/calib.txt"));
    /* a bad glove file: file and line named */
    tu_tmp_path("calib_glove_bad.txt", glove, sizeof glove);
    FILE *f = fopen(glove, "w");
    fprintf(f, "0.1 0.2 0.3 0.4 0.5\n0.1 0.2 x\n");
    fclose(f);
    char *a3[] = { (char *)tu_bin(), "calibrate", "--model", g_samples.path, "--recording", rec,
                   "--glove-right", glove, "--out", cal, NULL };
    assert_int_equal(tu_run(a3, out, sizeof out), 1);
    assert_non_null(strstr(out, "calib_glove_bad.txt:2: reading 3: needs 5 numbers"));
    assert_false(tu_exists(cal));
    /* missing options */
    char *a4[] = { (char *)tu_bin(), "calibrate", "--recording", rec, "--out", cal, NULL };
    assert_int_equal(tu_run(a4, out, sizeof out), 2);
    assert_non_null(strstr(out, "give --model or --scene"));
}

TU_MAIN(group_setup, group_teardown,
        cmocka_unit_test(validity_replay_args),
        cmocka_unit_test(result_replay_udp),
        cmocka_unit_test(result_replay_natnet_4_1),
        cmocka_unit_test(result_replay_natnet_3_1_zup_mm),
        cmocka_unit_test(result_calibrate),
        cmocka_unit_test(validity_calibrate))
