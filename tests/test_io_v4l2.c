/* test_io_v4l2.c - cameras without devices: the bookkeeping of io_cam
 * (newest frame, sequence gaps, short / corrupt buffers, unplug and
 * reopen, controls, format negotiation) over the dummy backend, stereo
 * pairing by time stamp, pixel conversion against exact values, and the
 * V4L2 backend's failure messages on things that are not cameras. The
 * real driver (vivid) is exercised by tests/vm. */
#include "support/testutil.h"
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "../src/io/io_dev.h"

#define MS 1000000ull
static const uint64_t PERIOD = 16666667ull; /* 60 FPS */

static io_cam_config dummy_cfg(const char *name, const io_dummy_cam_opts *o)
{
    io_cam_config c = io_cam_config_default(name);
    c.width = 64;
    c.height = 48;
    c.backend_opts = o;
    return c;
}

/* The options of a dummy camera at 60 FPS on the clock *clock. */
static io_dummy_cam_opts clocked(uint64_t *clock)
{
    io_dummy_cam_opts o = {0};
    o.period_ns = PERIOD;
    o.clock_ns = clock;
    return o;
}

/* io_cam_grab of cam: IO_OK and `want` frames (0 or 1), the frame in f. */
static void grab_expect(io_cam *cam, io_frame *f, int want)
{
    io_error err;
    int got;
    assert_int_equal(io_cam_grab(cam, 0, f, &got, &err), IO_OK);
    assert_int_equal(got, want);
}

/* A dummy camera under test: its options o (clocked: 60 FPS on clock),
 * its config c (dummy_cfg of o), the camera and the error of the calls. */
typedef struct dummy_cam {
    uint64_t clock;
    io_dummy_cam_opts o;
    io_cam_config c;
    io_cam cam;
    io_error err;
} dummy_cam;

/* A dummy camera of the name: its clock at 0, its options clocked (or
 * all defaults), its config dummy_cfg of them; nothing opened. */
static dummy_cam *dummy_new(const char *name, int is_clocked)
{
    dummy_cam *d = calloc(1, sizeof *d);
    assert_non_null(d);
    if (is_clocked) d->o = clocked(&d->clock);
    d->c = dummy_cfg(name, &d->o);
    return d;
}

/* Closes d's camera (closing again is fine) and frees d. */
static void dummy_done(dummy_cam *d)
{
    io_cam_close(&d->cam);
    free(d);
}

static void open_start(io_cam *cam, const io_cam_config *c)
{
    io_error err;
    assert_int_equal(io_cam_open(cam, &io_cam_dummy, c, &err), IO_OK);
    assert_int_equal(io_cam_start(cam, &err), IO_OK);
    assert_int_equal(cam->state, IO_CAM_STREAMING);
}

static void test_grab_newest_and_pixels(void **st)
{
    (void)st;
    dummy_cam *d = dummy_new("dummy0", 1);
    d->o.t0_ns = 1000 * MS;
    io_frame f;
    int got;
    open_start(&d->cam, &d->c);
    assert_int_equal(d->cam.fourcc, IO_FMT_YUYV);
    assert_int_equal(d->cam.stride, 128);

    /* nothing before the first frame time */
    grab_expect(&d->cam, &f, 0);

    /* 3 frames ready: the newest comes out, 2 are skipped */
    d->clock = d->o.t0_ns + 2 * PERIOD;
    grab_expect(&d->cam, &f, 1);
    assert_int_equal(f.sequence, 2);
    assert_true(f.t_ns == d->o.t0_ns + 2 * PERIOD);
    assert_int_equal(d->cam.stats.skipped, 2);
    assert_int_equal(d->cam.stats.frames, 3);
    assert_int_equal(f.width, 64);
    for (int y = 0; y < 48; y += 7)
        for (int x = 0; x < 64; x += 5) {
            assert_int_equal(f.data[y * f.stride + 2 * x], io_dummy_pixel(x, y, 2));
            assert_int_equal(f.data[y * f.stride + 2 * x + 1], 128);
        }
    /* while held, the buffer is ours */
    assert_int_equal(d->cam.queued[f.index], 0);
    int idx = f.index;
    assert_int_equal(io_cam_release(&d->cam, &f, &d->err), IO_OK);
    assert_int_equal(d->cam.queued[idx], 1);
    assert_int_equal(f.index, -1);
    /* releasing twice is harmless */
    assert_int_equal(io_cam_release(&d->cam, &f, &d->err), IO_OK);

    /* every buffer held by the caller: frames are lost, counted as gaps */
    io_frame held[4];
    d->clock += PERIOD;
    int n = 0;
    for (int i = 0; i < 4; i++) {
        assert_int_equal(io_cam_dequeue(&d->cam, &held[n], &got, &d->err), IO_OK);
        if (got) n++;
        d->clock += PERIOD;
    }
    assert_int_equal(n, 4);
    d->clock += 3 * PERIOD; /* 4 more frames pass with no buffer queued */
    for (int i = 0; i < n; i++) assert_int_equal(io_cam_release(&d->cam, &held[i], &d->err), IO_OK);
    d->clock += PERIOD;
    grab_expect(&d->cam, &f, 1);
    assert_true(d->cam.stats.dropped >= 3);
    io_cam_release(&d->cam, &f, &d->err);
    io_cam_close(&d->cam);
    assert_int_equal(d->cam.state, IO_CAM_CLOSED);
    assert_int_equal(d->cam.nbuf, 0);
    dummy_done(d); /* twice is fine */
}

static void test_gaps_short_corrupt(void **st)
{
    (void)st;
    dummy_cam *d = dummy_new("dummy1", 1);
    d->o.drop_every = 4;   /* frames 3, 7, 11 ... lost */
    d->o.short_at = 5;
    d->o.corrupt_at = 6;
    io_frame f;
    int got;
    open_start(&d->cam, &d->c);
    uint32_t seen[32];
    int n = 0;
    for (int k = 0; k < 12; k++) {
        d->clock = (uint64_t)k * PERIOD;
        assert_int_equal(io_cam_dequeue(&d->cam, &f, &got, &d->err), IO_OK);
        if (got) {
            seen[n++] = f.sequence;
            assert_true(f.bytes >= d->cam.image_bytes);
            io_cam_release(&d->cam, &f, &d->err);
        }
    }
    /* 0 1 2 4 8 9 10: 3, 7, 11 lost; 5 short; 6 corrupt */
    static const uint32_t want[] = {0, 1, 2, 4, 8, 9, 10};
    assert_int_equal(n, 7);
    for (int i = 0; i < n; i++) assert_int_equal(seen[i], want[i]);
    assert_int_equal(d->cam.stats.dropped, 2); /* the gaps 2->4 and 6->8; 11 not yet seen */
    assert_int_equal(d->cam.stats.short_frames, 1);
    assert_int_equal(d->cam.stats.corrupt, 1);
    assert_int_equal(d->cam.stats.frames, 9);
    assert_non_null(strstr(d->cam.status, "dummy1"));
    assert_non_null(strstr(d->cam.status, "frame 6"));
    /* every buffer came back to the driver */
    for (int i = 0; i < d->cam.nbuf; i++) assert_int_equal(d->cam.queued[i], 1);
    dummy_done(d);
}

static void test_unplug_and_reopen(void **st)
{
    (void)st;
    dummy_cam *d = dummy_new("dummy2", 1);
    d->o.unplug_at = 3;
    io_frame f;
    int got;
    open_start(&d->cam, &d->c);
    d->clock = 2 * PERIOD;
    grab_expect(&d->cam, &f, 1);
    assert_int_equal(io_cam_release(&d->cam, &f, &d->err), IO_OK);
    d->clock = 3 * PERIOD;
    memset(&d->err, 0, sizeof d->err);
    assert_int_equal(io_cam_grab(&d->cam, 0, &f, &got, &d->err), IO_ERR_DEVICE);
    assert_int_equal(got, 0);
    assert_int_equal(d->cam.state, IO_CAM_FAILED);
    assert_non_null(strstr(d->err.msg, "dummy2"));
    assert_non_null(strstr(d->err.msg, "No such device"));
    /* further calls report it again, no crash */
    assert_int_equal(io_cam_grab(&d->cam, 0, &f, &got, &d->err), IO_ERR_DEVICE);
    assert_non_null(strstr(d->err.msg, "not streaming"));

    /* still gone: reopen fails and keeps the camera ready for another try */
    d->o.fail_open = 1;
    assert_int_equal(io_cam_reopen(&d->cam, NULL, &d->err), IO_ERR_NOT_FOUND);
    assert_int_equal(d->cam.state, IO_CAM_FAILED);
    assert_int_equal(d->cam.nbuf, 0);
    /* back, under another name (its /dev/videoN changed) */
    d->o.fail_open = 0;
    d->o.unplug_at = 0;
    d->clock = 10 * PERIOD;
    assert_int_equal(io_cam_reopen(&d->cam, "dummy7", &d->err), IO_OK);
    assert_int_equal(d->cam.state, IO_CAM_STREAMING);
    assert_string_equal(d->cam.cfg.path, "dummy7");
    assert_int_equal(d->cam.stats.reopens, 1);
    assert_int_equal(d->cam.stats.errors, 1);
    d->clock = 11 * PERIOD;
    grab_expect(&d->cam, &f, 1);
    assert_int_equal(f.sequence, 11);
    io_cam_release(&d->cam, &f, &d->err);
    dummy_done(d);
}

static void test_open_failures(void **st)
{
    (void)st;
    dummy_cam *d = dummy_new("dummy3", 0);
    d->o.fail_open = 2;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_ERR_DEVICE);
    assert_non_null(strstr(d->err.msg, "dummy3"));
    assert_non_null(strstr(d->err.msg, "busy"));
    assert_int_equal(d->cam.state, IO_CAM_CLOSED);
    d->o.fail_open = 0;

    d->o.formats_mask = 2; /* GREY only */
    d->c.fourcc = IO_FMT_YUYV;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_ERR_FORMAT);
    assert_non_null(strstr(d->err.msg, "YUYV not offered"));
    assert_non_null(strstr(d->err.msg, "GREY"));
    assert_int_equal(d->cam.nbuf, 0);
    d->c.fourcc = 0; /* first offered */
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_OK);
    assert_int_equal(d->cam.fourcc, IO_FMT_GREY);
    assert_int_equal(d->cam.stride, 64);
    io_cam_close(&d->cam);

    d->c.buffers = 1;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_ERR_ARGS);
    assert_non_null(strstr(d->err.msg, "buffers"));
    d->c.buffers = 4;
    d->c.width = 0;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_ERR_ARGS);
    /* not streaming: grab says so */
    d->c.width = 64;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_OK);
    io_frame f;
    int got;
    assert_int_equal(io_cam_grab(&d->cam, 0, &f, &got, &d->err), IO_ERR_DEVICE);
    assert_non_null(strstr(d->err.msg, "not streaming"));
    dummy_done(d);
}

static void test_controls(void **st)
{
    (void)st;
    dummy_cam *d = dummy_new("dummy4", 0);
    int v = -1;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_OK);
    assert_int_equal(io_cam_set_ctrl(&d->cam, IO_CTRL_GAIN, 77, &d->err), IO_OK);
    assert_int_equal(io_cam_get_ctrl(&d->cam, IO_CTRL_GAIN, &v, &d->err), IO_OK);
    assert_int_equal(v, 77);
    assert_int_equal(io_cam_set_ctrl(&d->cam, IO_CTRL_WHITE_BALANCE, 99999, &d->err), IO_OK);
    assert_int_equal(io_cam_get_ctrl(&d->cam, IO_CTRL_WHITE_BALANCE, &v, &d->err), IO_OK);
    assert_int_equal(v, 6500); /* clamped to the range */
    assert_int_equal(io_cam_set_ctrl(&d->cam, (io_cam_ctrl)99, 1, &d->err), IO_ERR_ARGS);
    io_cam_close(&d->cam);
    d->o.lacks_ctrls = 1;
    assert_int_equal(io_cam_open(&d->cam, &io_cam_dummy, &d->c, &d->err), IO_OK);
    assert_int_equal(io_cam_set_ctrl(&d->cam, IO_CTRL_EXPOSURE, 10, &d->err), IO_ERR_VALUE);
    assert_non_null(strstr(d->err.msg, "dummy4"));
    assert_non_null(strstr(d->err.msg, "exposure"));
    io_cam_close(&d->cam);
    assert_int_equal(io_cam_set_ctrl(&d->cam, IO_CTRL_GAIN, 1, &d->err), IO_ERR_ARGS);
    dummy_done(d);
}

static void test_match_rule(void **st)
{
    (void)st;
    int drop;
    assert_int_equal(io_stereo_match(1, 100, 1, 104, 5, &drop), 1);
    assert_int_equal(io_stereo_match(1, 104, 1, 100, 5, &drop), 1);
    assert_int_equal(io_stereo_match(1, 100, 1, 105, 5, &drop), 1);
    assert_int_equal(io_stereo_match(1, 100, 1, 106, 5, &drop), 0);
    assert_int_equal(drop, 0);
    assert_int_equal(io_stereo_match(1, 206, 1, 100, 5, &drop), 0);
    assert_int_equal(drop, 1);
    assert_int_equal(io_stereo_match(0, 0, 1, 100, 5, &drop), 0);
    assert_int_equal(drop, -1);
    assert_int_equal(io_stereo_match(1, 100, 0, 0, 5, &drop), 0);
    assert_int_equal(drop, -1);
}

/* steps grabs of s, *clock a frame period on before each, every frame
 * released: n[got] counts the grabs of each outcome (1 the left eye
 * alone, 2 the right one alone, 3 a pair). */
static void stereo_steps(io_stereo *s, int steps, uint64_t *clock, int n[4])
{
    io_error err;
    io_frame out[2];
    int got;
    for (int k = 0; k < 4; k++) n[k] = 0;
    for (int step = 0; step < steps; step++) {
        *clock += PERIOD;
        assert_int_equal(io_stereo_grab(s, 0, out, &got, &err), IO_OK);
        assert_true(got >= 0 && got <= 3);
        n[got]++;
        if (got == 1) io_cam_release(s->cam[0], &out[0], &err);
        else if (got == 2) io_cam_release(s->cam[1], &out[1], &err);
        else if (got == 3) io_stereo_release(s, out, &err);
    }
}

static void test_stereo_pairs(void **st)
{
    (void)st;
    tu_rng rng = {606};
    uint64_t clock = 0;
    io_dummy_cam_opts ol = clocked(&clock), orr = clocked(&clock);
    ol.t0_ns = orr.t0_ns = 5000 * MS;
    orr.offset_ns = 3 * MS; /* right exposes 3 ms later */
    orr.drop_every = 7;     /* right loses every 7th frame */
    io_cam_config cl = dummy_cfg("dummyL", &ol), cr = dummy_cfg("dummyR", &orr);
    io_cam L, R;
    io_error err;
    open_start(&L, &cl);
    open_start(&R, &cr);
    io_stereo s;
    io_stereo_init(&s, &L, &R, 0);
    assert_true(s.max_skew_ns == PERIOD / 2);
    io_frame out[2];
    int got, pairs = 0;
    clock = ol.t0_ns;
    for (int step = 0; step < 200; step++) {
        /* the pipeline runs at an uneven pace: 0.5 .. 2.5 frame periods */
        clock += (uint64_t)(tu_range(&rng, 0.5f, 2.5f) * (float)PERIOD);
        assert_int_equal(io_stereo_grab(&s, 0, out, &got, &err), IO_OK);
        if (!got) continue;
        assert_int_equal(got, 3);
        pairs++;
        assert_true(out[1].t_ns - out[0].t_ns == 3 * MS);
        assert_int_equal(out[0].sequence, out[1].sequence);
        assert_int_not_equal((out[1].sequence + 1) % 7, 0);
        assert_int_equal(io_stereo_release(&s, out, &err), IO_OK);
    }
    assert_true(pairs > 100);
    assert_int_equal((int)s.pairs, pairs);
    assert_true(s.last_skew_ns == (int64_t)(3 * MS));
    assert_true(s.max_abs_skew_ns == 3 * MS);
    assert_true(R.stats.dropped > 0);
    /* the left frames whose partner was lost were counted */
    assert_true(s.unpaired[0] > 0);

    /* right camera unplugged: the left eye keeps going alone */
    orr.unplug_at = (int)((clock - orr.t0_ns) / PERIOD) + 2;
    int n[4];
    stereo_steps(&s, 20, &clock, n);
    assert_true(n[1] >= 15); /* the left eye alone */
    assert_int_equal(s.failed[1], 1);
    assert_int_equal(s.failed[0], 0);
    assert_non_null(strstr(s.status, "right"));
    assert_non_null(strstr(s.status, "dummyR"));
    /* replugged: pairs again */
    orr.unplug_at = 0;
    io_stereo_flush(&s);
    assert_int_equal(io_cam_reopen(&R, NULL, &err), IO_OK);
    clock += PERIOD;
    stereo_steps(&s, 10, &clock, n);
    if (n[1] || n[2]) fail_msg("single-eye frame after the reopen");
    assert_true(n[3] >= 8); /* pairs */
    assert_int_equal(s.failed[1], 0);
    /* both gone */
    ol.unplug_at = orr.unplug_at = 1;
    clock += PERIOD;
    assert_int_equal(io_stereo_grab(&s, 0, out, &got, &err), IO_ERR_DEVICE);
    assert_non_null(strstr(err.msg, "both cameras"));
    io_stereo_flush(&s);
    io_cam_close(&L);
    io_cam_close(&R);
}

static void test_convert(void **st)
{
    (void)st;
    uint8_t src[4 * 8 * 4], dst[4 * 4 * 8];
    io_error err;
    io_frame f = {src, sizeof src, 4, 4, 8, IO_FMT_YUYV, 0, 0, -1};
    /* YUYV: black, white, and saturated red (Y 81 U 90 V 240 in BT.601) */
    static const uint8_t px[3][3] = {{16, 128, 128}, {235, 128, 128}, {81, 90, 240}};
    static const uint8_t want[3][3] = {{0, 0, 0}, {255, 255, 255}, {255, 0, 0}};
    for (int k = 0; k < 3; k++) {
        for (int i = 0; i < 8; i++) {
            src[4 * i] = src[4 * i + 2] = px[k][0];
            src[4 * i + 1] = px[k][1];
            src[4 * i + 3] = px[k][2];
        }
        assert_int_equal(io_frame_to_rgba(&f, dst, 16, &err), IO_OK);
        for (int i = 0; i < 16; i++) {
            assert_true(abs(dst[4 * i] - want[k][0]) <= 1);
            assert_true(abs(dst[4 * i + 1] - want[k][1]) <= 1);
            assert_true(abs(dst[4 * i + 2] - want[k][2]) <= 1);
            assert_int_equal(dst[4 * i + 3], 255);
        }
    }
    /* Bayer of a flat colour gives that colour everywhere, whatever the
     * pattern (borders included). */
    static const uint32_t pats[4] = {IO_FMT_RGGB, IO_FMT_BGGR, IO_FMT_GBRG, IO_FMT_GRBG};
    static const int site[4][4] = {{0, 1, 1, 2}, {2, 1, 1, 0}, {1, 2, 0, 1}, {1, 0, 2, 1}};
    static const uint8_t rgb[3] = {200, 100, 50};
    for (int p = 0; p < 4; p++) {
        uint8_t b[6 * 5];
        for (int y = 0; y < 5; y++)
            for (int x = 0; x < 6; x++) b[y * 6 + x] = rgb[site[p][(y & 1) * 2 + (x & 1)]];
        io_frame fb = {b, sizeof b, 6, 5, 6, pats[p], 0, 0, -1};
        uint8_t o[6 * 5 * 4];
        assert_int_equal(io_frame_to_rgba(&fb, o, 24, &err), IO_OK);
        for (int i = 0; i < 30; i++) {
            assert_int_equal(o[4 * i], 200);
            assert_int_equal(o[4 * i + 1], 100);
            assert_int_equal(o[4 * i + 2], 50);
        }
    }
    /* GREY replicates */
    uint8_t g[3] = {0, 77, 255}, go[12];
    io_frame fg = {g, 3, 3, 1, 3, IO_FMT_GREY, 0, 0, -1};
    assert_int_equal(io_frame_to_rgba(&fg, go, 12, &err), IO_OK);
    assert_int_equal(go[4], 77);
    assert_int_equal(go[6], 77);
    /* short frame and unknown format are refused with the reason */
    fg.bytes = 2;
    assert_int_equal(io_frame_to_rgba(&fg, go, 12, &err), IO_ERR_SIZE);
    assert_non_null(strstr(err.msg, "too small"));
    fg.bytes = 3;
    fg.fourcc = IO_FOURCC('M', 'J', 'P', 'G');
    assert_int_equal(io_frame_to_rgba(&fg, go, 12, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "MJPG"));
}

static void test_v4l2_not_cameras(void **st)
{
    (void)st;
    io_cam cam;
    io_error err;
    io_cam_config c = io_cam_config_default("/dev/video-egofuse-missing");
    assert_int_equal(io_cam_open(&cam, &io_cam_v4l2, &c, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "/dev/video-egofuse-missing"));
    assert_non_null(strstr(err.msg, "no such camera"));
    c = io_cam_config_default("/dev/null");
    assert_int_equal(io_cam_open(&cam, &io_cam_v4l2, &c, &err), IO_ERR_DEVICE);
    assert_non_null(strstr(err.msg, "/dev/null: VIDIOC_QUERYCAP"));
    assert_int_equal(cam.fd, -1); /* the descriptor was closed */
    char path[512];
    tu_tmp_path("not_a_camera", path, sizeof path);
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs("x", fp);
    fclose(fp);
    c = io_cam_config_default(path);
    assert_int_equal(io_cam_open(&cam, &io_cam_v4l2, &c, &err), IO_ERR_DEVICE);
    assert_non_null(strstr(err.msg, "not a device node"));
    remove(path);
    char fs[5];
    assert_string_equal(io_fourcc_str(IO_FMT_BGGR, fs), "BA81");
}

/* the template backend (io_backend_template.c) compiles against the
 * contract and fails the way the contract says */
const io_cam_backend *io__cam_template(void);
static void test_template_backend(void **st)
{
    (void)st;
    io_cam cam;
    io_error err;
    io_cam_config c = io_cam_config_default("tmpl0");
    assert_int_equal(io_cam_open(&cam, io__cam_template(), &c, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "tmpl0"));
    assert_int_equal(cam.state, IO_CAM_CLOSED);
    assert_int_equal(cam.nbuf, 0);
}

/* bin with the one argument cmd: the exit status rc, and w1 and w2 in its
 * output. */
static void egofuse_says(const char *bin, const char *cmd, int rc, const char *w1, const char *w2)
{
    char out[8192];
    char *argv[] = {(char *)bin, (char *)cmd, NULL};
    assert_int_equal(tu_run(argv, out, sizeof out), rc);
    assert_non_null(strstr(out, w1));
    assert_non_null(strstr(out, w2));
}

/* `egofuse run` on a machine without cameras says so and points at the
 * recorded-input commands (skipped where cameras exist). */
static void test_run_without_cameras(void **st)
{
    (void)st;
    io_cam_info ci[16];
    int n = 0, capture = 0;
    io_error err;
    io_cam_list(NULL, ci, 16, &n, &err);
    for (int i = 0; i < n && i < 16; i++) capture += ci[i].capture;
    const char *bin = getenv("EGOFUSE_BIN");
    if (capture >= 2 || !bin || !tu_exists(bin)) {
        printf("SKIP: %s\n", capture >= 2 ? "this machine has cameras" : "EGOFUSE_BIN not built");
        skip();
    }
    egofuse_says(bin, "run", 1, "no cameras found", "egofuse render --scene");
    egofuse_says(bin, "devices", 0, "video nodes:", "USB devices:");
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_grab_newest_and_pixels),
        cmocka_unit_test(test_gaps_short_corrupt),
        cmocka_unit_test(test_unplug_and_reopen),
        cmocka_unit_test(test_open_failures),
        cmocka_unit_test(test_controls),
        cmocka_unit_test(test_match_rule),
        cmocka_unit_test(test_stereo_pairs),
        cmocka_unit_test(test_convert),
        cmocka_unit_test(test_v4l2_not_cameras),
        cmocka_unit_test(test_template_backend),
        cmocka_unit_test(test_run_without_cameras))
