/* test_io_live.c - io_live.c: the cockpit configuration file turned into
 * options (sections, props, paths relative to the file, flags, quotes,
 * comments, errors naming file and line), the latency quantiles, and the
 * per-frame CSV log (complete or absent: a write that fails part way
 * leaves no file). */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/files.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "../src/io/io_live.h"

static void conf_options(void **state)
{
    (void)state;
    char path[512], dir[512];
    tu_tmp_path("cockpit.conf", path, sizeof path);
    snprintf(dir, sizeof dir, "%.*s", (int)(strrchr(path, '/') - path), path);
    tu_write_text(path,
               "# a cockpit\n"
               "scene = samples/scene.txt   # relative to this file\n"
               "display = kms,connector=HDMI-A-1\n"
               "quiet = yes\n"
               "raw = no\n"
               "[cameras]\n"
               "left = serial:CAM-L\n"
               "right = file:rec/right_%04d.png\n"
               "\n"
               "[hmd]\n"
               "display = 1440x1600\n"
               "ipd = 0.063\n"
               "[virtual]\n"
               "source = stream:-\n"
               "[natnet]\n"
               "server = 10.0.0.5\n"
               "body = head=Helmet\n"
               "body = hand_l=#7\n"
               "[prop joystick]\n"
               "model = /abs/stick.glb\n"
               "at = 0.2,-0.4,-0.3\n"
               "body = Stick\n"
               "[prop armrest]\n"
               "model = rest.glb\n"
               "at = \"0.3, -0.5, 0\"  ; quoted\n");
    io_conf_args a;
    io_error err;
    assert_int_equal(io_conf_load(path, &a, &err), IO_OK);
    char want[14][1100];
    int n = 0;
    snprintf(want[n++], sizeof want[0], "--scene=%s/samples/scene.txt", dir);
    snprintf(want[n++], sizeof want[0], "--display=kms,connector=HDMI-A-1");
    snprintf(want[n++], sizeof want[0], "--quiet");
    snprintf(want[n++], sizeof want[0], "--left=serial:CAM-L");
    snprintf(want[n++], sizeof want[0], "--right=file:%s/rec/right_%%04d.png", dir);
    snprintf(want[n++], sizeof want[0], "--hmd-display=1440x1600");
    snprintf(want[n++], sizeof want[0], "--hmd-ipd=0.063");
    snprintf(want[n++], sizeof want[0], "--virt-source=stream:-");
    snprintf(want[n++], sizeof want[0], "--natnet-server=10.0.0.5");
    snprintf(want[n++], sizeof want[0], "--natnet-body=head=Helmet");
    snprintf(want[n++], sizeof want[0], "--natnet-body=hand_l=#7");
    snprintf(want[n++], sizeof want[0], "--prop=joystick=/abs/stick.glb@0.2,-0.4,-0.3#Stick");
    snprintf(want[n++], sizeof want[0], "--prop=armrest=%s/rest.glb@0.3, -0.5, 0", dir);
    assert_int_equal(a.argc, n);
    for (int i = 0; i < n; i++) assert_string_equal(a.argv[i], want[i]);
    assert_null(a.argv[n]);
    char o[600];
    snprintf(o, sizeof o, "%s:2", path);
    assert_string_equal(a.origin[0], o);
    snprintf(o, sizeof o, "%s:19", path); /* the [prop joystick] line */
    assert_string_equal(a.origin[11], o);
    io_conf_free(&a);
    assert_int_equal(a.argc, 0);
}

static void conf_errors(void **state)
{
    (void)state;
    static const struct {
        const char *text;
        int line;
        const char *reason;
    } cases[] = {
        {"scene = a\n[nowhere]\n", 2, "unknown section [nowhere]"},
        {"scene\n", 1, "expected 'key = value'"},
        {" = 3\n", 1, "a key is missing"},
        {"a b = 3\n", 1, "key 'a b'"},
        {"scene = \"open\n", 1, "unterminated quote"},
        {"[prop x]\nat = 1,2,3\n", 1, "[prop x] has no model"},
        {"[prop x]\ncolour = red\n", 2, "unknown key 'colour'"},
        {"[prop]\n", 1, "unknown section [prop]"},
        {"quiet = maybe\n", 1, "yes or no"},
        {"[hmd\n", 1, "'[name]' alone"},
    };
    char path[512];
    tu_tmp_path("bad.conf", path, sizeof path);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        tu_write_text(path, cases[i].text);
        io_conf_args a;
        io_error err;
        assert_int_not_equal(io_conf_load(path, &a, &err), IO_OK);
        char where[600];
        snprintf(where, sizeof where, "%s:%d: ", path, cases[i].line);
        if (strncmp(err.msg, where, strlen(where)) || !strstr(err.msg, cases[i].reason))
            fail_msg("case %zu: '%s' (want '%s' ... '%s')", i, err.msg, where, cases[i].reason);
        assert_int_equal(a.argc, 0);
        assert_null(a.argv);
    }
    io_conf_args a;
    io_error err;
    tu_tmp_path("missing.conf", path, sizeof path);
    assert_int_equal(io_conf_load(path, &a, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "missing.conf"));
}

static void lat_quantiles(void **state)
{
    (void)state;
    io_lat l;
    io_lat_reset(&l);
    assert_true(isnan(io_lat_quantile(&l, 0.5)));
    /* 1..100 in a scrambled order */
    for (int i = 0; i < 100; i++) io_lat_push(&l, (double)(1 + (i * 37) % 100));
    assert_true(io_lat_quantile(&l, 0.5) == 50.0);
    assert_true(io_lat_quantile(&l, 0.99) == 99.0);
    assert_true(io_lat_quantile(&l, 1.0) == 100.0);
    assert_true(io_lat_quantile(&l, 0.0) == 1.0);
    /* the window keeps the newest IO_LAT_WINDOW values */
    for (int i = 0; i < IO_LAT_WINDOW; i++) io_lat_push(&l, 1000.0 + i);
    assert_true(io_lat_quantile(&l, 0.0) == 1000.0);
    assert_true(io_lat_quantile(&l, 1.0) == 1000.0 + IO_LAT_WINDOW - 1);
}

static void stats_log(void **state)
{
    (void)state;
    char path[512];
    tu_tmp_path("frames.csv", path, sizeof path);
    io_stats_log s;
    io_error err;
    assert_int_equal(io_stats_open(&s, path, &err), IO_OK);
    assert_false(tu_exists(path)); /* only the temporary until closed */
    io_frame_log r;
    memset(&r, 0, sizeof r);
    r.frame = 3;
    r.t_cam_l = 1000000000ull;
    r.t_cam_r = 1002000000ull;
    r.t_dequeue = 1003000000ull;
    r.t_done = 1007500000ull;
    r.t_shown = 1010000000ull;
    r.ms_total = 4.25;
    r.v_age_ms = 12.5;
    io_stats_row(&s, &r);
    assert_int_equal(io_stats_close(&s, &err), IO_OK);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[1024];
    assert_non_null(fgets(line, sizeof line, f));
    assert_non_null(strstr(line, "frame,t_cam_l_ns"));
    assert_non_null(fgets(line, sizeof line, f));
    fclose(f);
    /* cam_to_done 5.5 ms (from the later camera), dequeue_to_shown 7, cam_to_shown 8 */
    assert_non_null(strstr(line, "3,1000000000,1002000000,1003000000,0,1007500000,0,1010000000,"
                                 "5.500,7.000,8.000,"));
    assert_non_null(strstr(line, ",4.250,12.500,"));
}

/* A log whose writes fail part way (RLIMIT_FSIZE, as a full disk): the
 * close reports it and neither the log nor its temporary is left. */
static void stats_log_full_disk(void **state)
{
    (void)state;
    char path[512];
    tu_tmp_path("full.csv", path, sizeof path);
    struct rlimit old, lim;
    getrlimit(RLIMIT_FSIZE, &old);
    void (*prev)(int) = signal(SIGXFSZ, SIG_IGN);
    lim = old;
    lim.rlim_cur = 4096;
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
    io_stats_log s;
    io_error err;
    assert_int_equal(io_stats_open(&s, path, &err), IO_OK);
    io_frame_log r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 200; i++) {
        r.frame = (uint64_t)i;
        io_stats_row(&s, &r);
    }
    io_result res = io_stats_close(&s, &err);
    setrlimit(RLIMIT_FSIZE, &old);
    signal(SIGXFSZ, prev);
    assert_int_equal(res, IO_ERR_WRITE);
    assert_non_null(strstr(err.msg, path));
    assert_non_null(strstr(err.msg, "not kept"));
    assert_false(tu_exists(path));
    assert_false(tu_exists(s.tmp));
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(conf_options),
        cmocka_unit_test(conf_errors),
        cmocka_unit_test(lat_quantiles),
        cmocka_unit_test(stats_log),
        cmocka_unit_test(stats_log_full_disk))
