/* test_io_vsrc.c - the V source (io_vsrc.h) and the file cameras on the
 * host, without devices: the egofuse framing parsed from bytes written by
 * tests/support/vstream_gen.py (written from docs/vstream.md, not from
 * egofuse's code), YUV4MPEG2 and raw frames from real producers
 * (gst-launch-1.0, ffmpeg) compared with ffmpeg's own conversion of the
 * same frames to rgb24, scaling, bad input (truncated header, wrong size
 * mid-stream, garbage, unknown version / format / framing / colourspace),
 * a stalled producer (injected clock: no sleeps), a writer that goes away,
 * paced regular files, and the file camera backend. V4L2 sources run in
 * the VM (tests/vm, vm_devices vsrc). */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/files.h"

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../src/io/io.h"
#include "../src/io/io_vsrc.h"

#define MS 1000000ull

/* ------------------------------------------------------------ helpers */

static const char *tmp(const char *name, char *buf, size_t n);

static int have_tool(const char *name)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "command -v %s >/dev/null 2>&1", name);
    return system(cmd) == 0;
}

#define NEED_TOOL(t)                                                       \
    do {                                                                   \
        if (!have_tool(t)) {                                               \
            printf("SKIP: %s is not installed (apt-get install %s)\n", t, \
                   !strcmp(t, "ffmpeg") ? "ffmpeg" : "gstreamer1.0-tools"); \
            skip();                                                        \
        }                                                                  \
    } while (0)

/* Runs a shell command, returns its whole stdout (malloc'd). */
static uint8_t *run_out(const char *cmd, size_t *n)
{
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t cap = 1 << 16, len = 0;
    uint8_t *b = malloc(cap);
    assert_non_null(b);
    for (;;) {
        if (len == cap) {
            cap *= 2;
            b = realloc(b, cap);
            assert_non_null(b);
        }
        size_t k = fread(b + len, 1, cap - len, p);
        if (!k) break;
        len += k;
    }
    int rc = pclose(p);
    if (rc != 0) fail_msg("'%s' failed (status %d)", cmd, rc);
    *n = len;
    return b;
}

static uint8_t *gen(const char *scenario, size_t *n)
{
    char script[1024], cmd[1200];
    tu_root_path("tests/support/vstream_gen.py", script, sizeof script);
    snprintf(cmd, sizeof cmd, "python3 '%s' %s", script, scenario);
    return run_out(cmd, n);
}

/* A pipe: *wfd is the writer; the spec names the reader by /dev/fd. */
typedef struct tpipe {
    int rfd, wfd;
    char spec[64];
} tpipe;

static void tpipe_open(tpipe *t, const char *prefix)
{
    int fds[2];
    assert_int_equal(pipe(fds), 0);
    fcntl(fds[0], F_SETPIPE_SZ, 1 << 20);
    t->rfd = fds[0];
    t->wfd = fds[1];
    snprintf(t->spec, sizeof t->spec, "%s/dev/fd/%d", prefix, t->rfd);
}

static void tpipe_write(tpipe *t, const void *d, size_t n)
{
    const uint8_t *p = d;
    while (n) {
        ssize_t k = write(t->wfd, p, n);
        if (k <= 0) fail_msg("pipe write failed (more than the pipe holds?)");
        p += k;
        n -= (size_t)k;
    }
}

static void tpipe_close_writer(tpipe *t)
{
    if (t->wfd >= 0) close(t->wfd);
    t->wfd = -1;
}

static void tpipe_close(tpipe *t)
{
    tpipe_close_writer(t);
    if (t->rfd >= 0) close(t->rfd);
    t->rfd = -1;
}

static io_vsrc *open_src(const char *spec, int ew, int eh, int layout, const uint64_t *clock)
{
    io_vsrc_config c = io_vsrc_config_default(spec);
    c.eye_width = ew;
    c.eye_height = eh;
    c.layout = layout;
    c.clock_ns = clock;
    io_vsrc *v = NULL;
    io_error err;
    if (io_vsrc_open(&v, &c, &err) != IO_OK) fail_msg("%s", err.msg);
    return v;
}

static int poll_fresh(io_vsrc *v, int timeout_ms)
{
    int fresh = -1;
    io_error err;
    assert_int_equal(io_vsrc_poll(v, timeout_ms, &fresh, &err), IO_OK);
    return fresh;
}

static void gen_rgb(int i, int x, int y, uint8_t c[3])
{
    c[0] = (uint8_t)((4 * x + i) & 255);
    c[1] = (uint8_t)((8 * y) & 255);
    c[2] = (uint8_t)((x + y + 50 * i) & 255);
}

/* -------------------------------------------------- egofuse framing */

static void test_egfv_basic_sbs_depth(void **st)
{
    (void)st;
    size_t n;
    uint8_t *bytes = gen("basic", &n);
    uint64_t clock = 5000 * MS;
    tpipe t;
    tpipe_open(&t, "stream:");
    io_vsrc *v = open_src(t.spec, 32, 32, IO_VSRC_AUTO, &clock);
    io_vsrc_stat s;
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_WAITING);
    assert_null(io_vsrc_eye(v, 0, NULL));
    tpipe_write(&t, bytes, n);
    assert_int_equal(poll_fresh(v, 0), 1);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_LIVE);
    assert_string_equal(s.kind, "egofuse");
    assert_int_equal(s.frames, 1);
    assert_int_equal(s.skipped, 2); /* latest wins */
    assert_int_equal(s.bad, 0);
    assert_int_equal(s.src_width, 64);
    assert_int_equal(s.layout, IO_VSRC_SBS);
    assert_int_equal(s.t_ns, 1000 * MS + 2 * MS); /* the header's */
    assert_int_equal(s.age_ns, (int64_t)(clock - s.t_ns));
    assert_int_equal(s.has_depth, 1);
    for (int e = 0; e < 2; e++) {
        size_t stride, dstride;
        const uint8_t *im = io_vsrc_eye(v, e, &stride);
        const float *d = io_vsrc_depth(v, e, &dstride);
        assert_non_null(im);
        assert_non_null(d);
        assert_int_equal(dstride, 32);
        for (int y = 0; y < 32; y++)
            for (int x = 0; x < 32; x++) {
                uint8_t c[3];
                gen_rgb(2, x + 32 * e, y, c);
                const uint8_t *p = im + (size_t)y * stride + 4 * (size_t)x;
                if (p[0] != c[0] || p[1] != c[1] || p[2] != c[2] || p[3] != 255)
                    fail_msg("eye %d (%d,%d): %d %d %d %d, expected %d %d %d 255", e, x, y, p[0],
                             p[1], p[2], p[3], c[0], c[1], c[2]);
                float want = (float)(3 + (x + 32 * e) / 100.0 + y / 1000.0);
                if (d[(size_t)y * dstride + (size_t)x] != want)
                    fail_msg("depth eye %d (%d,%d): %.9g, expected %.9g", e, x, y,
                             (double)d[(size_t)y * dstride + (size_t)x], (double)want);
            }
    }
    /* the writer goes: ended, the last V held */
    const uint8_t *before = io_vsrc_eye(v, 1, NULL);
    uint8_t keep[16];
    memcpy(keep, before, 16);
    tpipe_close_writer(&t);
    assert_int_equal(poll_fresh(v, 0), 0);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_ENDED);
    assert_non_null(strstr(s.msg, "end of stream"));
    assert_non_null(strstr(s.msg, t.spec));
    assert_non_null(io_vsrc_eye(v, 1, NULL));
    assert_memory_equal(io_vsrc_eye(v, 1, NULL), keep, 16);
    io_vsrc_close(v);
    tpipe_close(&t);
    free(bytes);
}

static void test_egfv_tb_u16_depth(void **st)
{
    (void)st;
    size_t n;
    uint8_t *bytes = gen("u16", &n);
    tpipe t;
    tpipe_open(&t, "stream:");
    io_vsrc *v = open_src(t.spec, 32, 32, IO_VSRC_AUTO, NULL);
    tpipe_write(&t, bytes, n);
    assert_int_equal(poll_fresh(v, 0), 1);
    io_vsrc_stat s;
    io_vsrc_status(v, 0, &s);
    assert_int_equal(s.layout, IO_VSRC_TB);
    for (int e = 0; e < 2; e++) {
        size_t stride, ds;
        const uint8_t *im = io_vsrc_eye(v, e, &stride);
        const float *d = io_vsrc_depth(v, e, &ds);
        for (int y = 0; y < 32; y += 3)
            for (int x = 0; x < 32; x += 5) {
                uint8_t c[3];
                gen_rgb(0, x, y + 32 * e, c);
                assert_memory_equal(im + (size_t)y * stride + 4 * (size_t)x, c, 3);
                float want = (float)(1000 + 10 * x + (y + 32 * e)) * 0.001f;
                assert_true(d[(size_t)y * ds + (size_t)x] == want);
            }
    }
    io_vsrc_close(v);
    tpipe_close(&t);
    free(bytes);
}

/* The documented bilinear rule, computed here independently in double:
 * must agree with the integer scaler within 1 (8-bit weights). */
static void scaled_case(int EW, int EH)
{
    size_t n;
    uint8_t *bytes = gen("basic", &n);
    tpipe t;
    tpipe_open(&t, "stream:");
    io_vsrc *v = open_src(t.spec, EW, EH, IO_VSRC_SBS, NULL);
    tpipe_write(&t, bytes, n);
    assert_int_equal(poll_fresh(v, 0), 1);
    int maxd = 0;
    for (int e = 0; e < 2; e++) {
        size_t stride, ds;
        const uint8_t *im = io_vsrc_eye(v, e, &stride);
        const float *d = io_vsrc_depth(v, e, &ds);
        assert_int_equal(stride, 4 * EW);
        for (int y = 0; y < EH; y++)
            for (int x = 0; x < EW; x++) {
                double sx = (x + 0.5) * 32 / EW - 0.5, sy = (y + 0.5) * 32 / EH - 0.5;
                if (sx < 0) sx = 0;
                if (sy < 0) sy = 0;
                int x0 = (int)sx, y0 = (int)sy;
                int x1 = x0 + 1 < 32 ? x0 + 1 : x0, y1 = y0 + 1 < 32 ? y0 + 1 : y0;
                double fx = sx - x0, fy = sy - y0;
                for (int k = 0; k < 3; k++) {
                    uint8_t a[3], b[3], c[3], dd[3];
                    gen_rgb(2, x0 + 32 * e, y0, a);
                    gen_rgb(2, x1 + 32 * e, y0, b);
                    gen_rgb(2, x0 + 32 * e, y1, c);
                    gen_rgb(2, x1 + 32 * e, y1, dd);
                    double ref = (a[k] * (1 - fx) + b[k] * fx) * (1 - fy) +
                                 (c[k] * (1 - fx) + dd[k] * fx) * fy;
                    int got = im[(size_t)y * stride + 4 * (size_t)x + (size_t)k];
                    int diff = abs(got - (int)lround(ref));
                    if (diff > maxd) maxd = diff;
                    /* and exactly the rule of docs/vstream.md (1/256 steps,
                     * rounded half up), evaluated in double */
                    long cx = (long)floor((2.0 * x + 1) * 32 * 256 / (2.0 * EW)) - 128;
                    long cy = (long)floor((2.0 * y + 1) * 32 * 256 / (2.0 * EH)) - 128;
                    cx = cx < 0 ? 0 : cx > 31 * 256 ? 31 * 256 : cx;
                    cy = cy < 0 ? 0 : cy > 31 * 256 ? 31 * 256 : cy;
                    if (cx >> 8 == x0 && cy >> 8 == y0) {
                        double wx = (double)(cx & 255), wy = (double)(cy & 255);
                        double rule = ((a[k] * (256 - wx) + b[k] * wx) * (256 - wy) +
                                       (c[k] * (256 - wx) + dd[k] * wx) * wy) / 65536.0;
                        if (got != (int)floor(rule + 0.5))
                            fail_msg("eye %d (%d,%d) channel %d: %d, the documented rule gives %.4f",
                                     e, x, y, k, got, rule);
                    }
                }
                assert_int_equal(im[(size_t)y * stride + 4 * (size_t)x + 3], 255);
                /* depth: nearest, never blended */
                int nx = ((2 * x + 1) * 32) / (2 * EW), ny = ((2 * y + 1) * 32) / (2 * EH);
                float want = (float)(3 + (nx + 32 * e) / 100.0 + ny / 1000.0);
                assert_true(d[(size_t)y * ds + (size_t)x] == want);
            }
    }
    printf("NOTE scaled 32x32 -> %dx%d: max |integer - double bilinear| = %d\n", EW, EH, maxd);
    assert_true(maxd <= 1);
    io_vsrc_close(v);
    tpipe_close(&t);
    free(bytes);
}

static void test_egfv_scaled(void **st)
{
    (void)st;
    scaled_case(20, 12); /* down */
    scaled_case(45, 70); /* up: rows reused */
    scaled_case(32, 33);
}

/* Runs a generator scenario through a pipe (writer closed), one poll. */
static io_vsrc *run_scenario(const char *sc, tpipe *t, io_vsrc_stat *s)
{
    size_t n;
    uint8_t *bytes = gen(sc, &n);
    tpipe_open(t, "stream:");
    io_vsrc *v = open_src(t->spec, 32, 32, IO_VSRC_AUTO, NULL);
    tpipe_write(t, bytes, n);
    tpipe_close_writer(t);
    poll_fresh(v, 0);
    poll_fresh(v, 0);
    io_vsrc_status(v, 0, s);
    printf("NOTE %s: %s, frames %llu, bad %llu: %s\n", sc, io_vsrc_state_name(s->state),
           (unsigned long long)s->frames, (unsigned long long)s->bad, s->msg);
    free(bytes);
    return v;
}

static void check_eye_frame(io_vsrc *v, int i)
{
    size_t stride;
    const uint8_t *im = io_vsrc_eye(v, 0, &stride);
    assert_non_null(im);
    uint8_t c[3];
    gen_rgb(i, 5, 7, c);
    assert_memory_equal(im + 7 * stride + 4 * 5, c, 3);
}

static void test_egfv_bad_input(void **st)
{
    (void)st;
    tpipe t;
    io_vsrc_stat s;
    int fds0 = tu_count_fds();

    /* another size mid-stream: skipped, named; the next good one taken */
    io_vsrc *v = run_scenario("badsize", &t, &s);
    assert_int_equal(s.bad, 1);
    assert_int_equal(s.frames, 1);
    check_eye_frame(v, 2);
    io_vsrc_close(v);
    tpipe_close(&t);
    /* the message of the bad frame (it is replaced by "end of stream" on
     * the second poll): one poll only */
    {
        size_t n;
        uint8_t *bytes = gen("badsize", &n);
        tpipe_open(&t, "stream:");
        v = open_src(t.spec, 32, 32, IO_VSRC_AUTO, NULL);
        tpipe_write(&t, bytes, n);
        poll_fresh(v, 0);
        io_vsrc_status(v, 0, &s);
        assert_non_null(strstr(s.msg, "is 32x32, the stream's frames are 64x32: skipped"));
        assert_non_null(strstr(s.msg, t.spec));
        io_vsrc_close(v);
        tpipe_close(&t);
        free(bytes);
    }

    v = run_scenario("garbage", &t, &s);
    assert_int_equal(s.bad, 1);
    check_eye_frame(v, 1);
    io_vsrc_close(v);
    tpipe_close(&t);

    v = run_scenario("badfmt", &t, &s);
    assert_int_equal(s.bad, 1);
    assert_int_equal(s.frames, 1);
    check_eye_frame(v, 1);
    io_vsrc_close(v);
    tpipe_close(&t);

    v = run_scenario("truncated", &t, &s);
    assert_int_equal(s.state, IO_VSRC_ENDED);
    assert_non_null(strstr(s.msg, "truncated frame header"));
    check_eye_frame(v, 0); /* the last good V is held */
    io_vsrc_close(v);
    tpipe_close(&t);

    v = run_scenario("version", &t, &s);
    assert_int_equal(s.state, IO_VSRC_FAILED);
    assert_non_null(strstr(s.msg, "unknown egofuse framing version 2"));
    assert_null(io_vsrc_eye(v, 0, NULL));
    io_vsrc_close(v);
    tpipe_close(&t);

    /* not a known framing at all */
    tpipe_open(&t, "stream:");
    v = open_src(t.spec, 32, 32, IO_VSRC_AUTO, NULL);
    tpipe_write(&t, "hello, world", 12);
    poll_fresh(v, 0);
    io_vsrc_status(v, 0, &s);
    assert_int_equal(s.state, IO_VSRC_FAILED);
    assert_non_null(strstr(s.msg, "unknown framing (first bytes 68 65 6c 6c"));
    io_vsrc_close(v);
    tpipe_close(&t);

    /* bad specs */
    io_vsrc_config c = io_vsrc_config_default("nonsense:x");
    io_error err;
    assert_int_equal(io_vsrc_open(&v, &c, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "nonsense:x"));
    c.spec = "raw:64x48:xyz:-";
    assert_int_equal(io_vsrc_open(&v, &c, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "'xyz' is not known"));
    c.spec = "raw:63x48:nv12:-";
    assert_int_equal(io_vsrc_open(&v, &c, &err), IO_ERR_ARGS);
    c.spec = "stream:/nonexistent/v.fifo";
    assert_int_equal(io_vsrc_open(&v, &c, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "/nonexistent/v.fifo"));
    c.spec = "v4l2:/dev/video99";
    assert_int_not_equal(io_vsrc_open(&v, &c, &err), IO_OK);
    assert_non_null(strstr(err.msg, "/dev/video99"));
    printf("NOTE v4l2 missing: %s\n", err.msg);
    assert_int_equal(tu_count_fds(), fds0);
}

/* A producer that stays connected but silent: poll returns within its
 * timeout, the state goes stale by the clock given; a partial frame
 * waits; then the writer closes. */
static void test_stalled_producer(void **st)
{
    (void)st;
    size_t n;
    uint8_t *bytes = gen("basic", &n);
    size_t fl = n / 3;
    uint64_t clock = 7000 * MS;
    tpipe t;
    tpipe_open(&t, "stream:");
    io_vsrc *v = open_src(t.spec, 32, 32, IO_VSRC_SBS, &clock);
    tpipe_write(&t, bytes, fl);
    assert_int_equal(poll_fresh(v, 0), 1);
    /* nothing more: returns (after its timeout) with nothing fresh */
    assert_int_equal(poll_fresh(v, 20), 0);
    io_vsrc_stat s;
    io_vsrc_status(v, clock + 150 * MS, &s);
    assert_int_equal(s.state, IO_VSRC_LIVE);
    io_vsrc_status(v, clock + 250 * MS, &s);
    assert_int_equal(s.state, IO_VSRC_STALE);
    assert_non_null(strstr(s.msg, "no frame for 250 ms"));
    assert_non_null(io_vsrc_eye(v, 0, NULL));
    /* half of the next frame: held back, the old V stays */
    clock += 300 * MS;
    tpipe_write(&t, bytes + fl, fl / 2);
    assert_int_equal(poll_fresh(v, 0), 0);
    check_eye_frame(v, 0);
    tpipe_write(&t, bytes + fl + fl / 2, fl - fl / 2);
    assert_int_equal(poll_fresh(v, 0), 1);
    check_eye_frame(v, 1);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_LIVE);
    assert_int_equal(s.arrival_ns, clock);
    tpipe_close_writer(&t);
    poll_fresh(v, 0);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_ENDED);
    check_eye_frame(v, 1);
    struct pollfd pf[2];
    assert_int_equal(io_vsrc_pollfds(v, pf, 2), 0); /* nothing left to wait on */
    io_vsrc_close(v);
    tpipe_close(&t);
    free(bytes);
}

/* A FIFO: no writer yet is not an end; the writer goes (ended, V held)
 * and a new one comes back (reopened once a second, by the clock given). */
static void test_fifo_writers(void **st)
{
    (void)st;
    char fifo[600], spec[700];
    tmp("v.fifo", fifo, sizeof fifo);
    unlink(fifo);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    snprintf(spec, sizeof spec, "stream:%s", fifo);
    size_t n;
    uint8_t *bytes = gen("basic", &n);
    size_t fl = n / 3;
    uint64_t clock = 10000 * MS;
    int fds0 = tu_count_fds();
    io_vsrc *v = open_src(spec, 32, 32, IO_VSRC_SBS, &clock);
    io_vsrc_stat s;
    assert_int_equal(poll_fresh(v, 0), 0);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_WAITING);
    assert_non_null(strstr(s.msg, "no writer on the FIFO yet"));
    /* a writer (O_RDWR: opens without blocking), looked for a second later */
    int w = open(fifo, O_RDWR);
    assert_true(w >= 0);
    assert_int_equal(write(w, bytes, fl), (ssize_t)fl);
    clock += 500 * MS;
    assert_int_equal(poll_fresh(v, 0), 0); /* not yet a second */
    clock += 600 * MS;
    assert_int_equal(poll_fresh(v, 0), 1);
    check_eye_frame(v, 0);
    close(w);
    poll_fresh(v, 0);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_ENDED);
    assert_non_null(strstr(s.msg, "waiting for a new writer"));
    check_eye_frame(v, 0);
    w = open(fifo, O_RDWR);
    assert_true(w >= 0);
    assert_int_equal(write(w, bytes + fl, fl), (ssize_t)fl);
    clock += 1100 * MS;
    assert_int_equal(poll_fresh(v, 0), 1);
    check_eye_frame(v, 1);
    io_vsrc_status(v, clock, &s);
    assert_int_equal(s.state, IO_VSRC_LIVE);
    assert_int_equal(s.reopens, 1);
    assert_non_null(strstr(s.msg, "a new writer"));
    close(w);
    io_vsrc_close(v);
    assert_int_equal(tu_count_fds(), fds0);
    unlink(fifo);
    free(bytes);
}

/* ------------------------------------------------ real producers */

static char tmpd[512];

static const char *tmp(const char *name, char *buf, size_t n)
{
    if (!tmpd[0]) {
        tu_tmp_path("vsrc", tmpd, sizeof tmpd);
        mkdir(tmpd, 0755);
    }
    snprintf(buf, n, "%s/%s", tmpd, name);
    return buf;
}

/* path[n] := the scratch file name: `frames` frames of ffmpeg's testsrc2
 * at w x h and 30 FPS in the pixel format pix (and any output options
 * after it), as YUV4MPEG2. */
static void testsrc_y4m(const char *name, int w, int h, int frames, const char *pix, char *path,
                        size_t n)
{
    char cmd[2048];
    tmp(name, path, n);
    snprintf(cmd, sizeof cmd, "ffmpeg -loglevel error -y -f lavfi -i testsrc2=size=%dx%d:rate=30 "
             "-frames:v %d -pix_fmt %s -f yuv4mpegpipe '%s'", w, h, frames, pix, path);
    assert_int_equal(system(cmd), 0);
}

/* out[n] := the scratch file name, the file in converted by ffmpeg with
 * the output options opts. */
static void ffmpeg_convert(const char *in, const char *opts, const char *name, char *out, size_t n)
{
    char cmd[2048];
    tmp(name, out, n);
    snprintf(cmd, sizeof cmd, "ffmpeg -loglevel error -y -i '%s' %s '%s'", in, opts, out);
    assert_int_equal(system(cmd), 0);
}

/* Feeds a file's bytes through a pipe in chunks (partial frames), polling
 * after each; returns the source after the writer closed. */
static io_vsrc *feed(const char *prefix, const char *path, int ew, int eh, int layout,
                     size_t chunk, io_vsrc_stat *s)
{
    size_t n;
    uint8_t *b = tu_read_file(path, &n);
    tpipe t;
    tpipe_open(&t, prefix);
    io_vsrc *v = open_src(t.spec, ew, eh, layout, NULL);
    for (size_t o = 0; o < n; o += chunk) {
        tpipe_write(&t, b + o, o + chunk <= n ? chunk : n - o);
        poll_fresh(v, 0);
    }
    tpipe_close_writer(&t);
    poll_fresh(v, 0);
    io_vsrc_status(v, 0, s);
    tpipe_close(&t);
    free(b);
    return v;
}

/* Compares the eye (mono, source size) with frame `k` of an rgb24 file;
 * returns the largest difference, counts those above tol. */
static int compare_rgb(io_vsrc *v, const char *ref, int w, int h, int k, int tol, int *over)
{
    size_t n, stride;
    uint8_t *r = tu_read_file(ref, &n);
    assert_true(n >= (size_t)(k + 1) * (size_t)w * (size_t)h * 3);
    const uint8_t *im = io_vsrc_eye(v, 0, &stride);
    assert_non_null(im);
    const uint8_t *fr = r + (size_t)k * (size_t)w * (size_t)h * 3;
    int maxd = 0;
    *over = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                int d = abs(im[(size_t)y * stride + 4 * (size_t)x + (size_t)c] -
                            fr[((size_t)y * (size_t)w + (size_t)x) * 3 + (size_t)c]);
                if (d > maxd) maxd = d;
                if (d > tol) (*over)++;
            }
    free(r);
    return maxd;
}

/* YUV -> RGB: BT.601 (limited, or full for yuvj / XCOLORRANGE=FULL) in
 * both, but ffmpeg's swscale rounds its fixed-point coefficients
 * differently: every value within 4 (measured: at most 3). */
#define YUV_TOL 4
#define YUV_OVER_FRAC 0.0

static void test_y4m_gstreamer(void **st)
{
    (void)st;
    NEED_TOOL("gst-launch-1.0");
    NEED_TOOL("ffmpeg");
    char y4m[600], ref[600], cmd[2048];
    tmp("gst.y4m", y4m, sizeof y4m);
    snprintf(cmd, sizeof cmd, "gst-launch-1.0 -q videotestsrc num-buffers=3 pattern=smpte ! "
             "video/x-raw,format=I420,width=96,height=64 ! y4menc ! fdsink fd=1 > '%s'", y4m);
    assert_int_equal(system(cmd), 0);
    ffmpeg_convert(y4m, "-f rawvideo -pix_fmt rgb24", "gst.rgb", ref, sizeof ref);
    io_vsrc_stat s;
    io_vsrc *v = feed("stream:", y4m, 96, 64, IO_VSRC_MONO, 1000, &s);
    assert_string_equal(s.kind, "y4m");
    assert_int_equal(s.frames + s.skipped, 3);
    assert_int_equal(s.bad, 0);
    assert_int_equal(s.state, IO_VSRC_ENDED);
    int over, maxd = compare_rgb(v, ref, 96, 64, 2, YUV_TOL, &over);
    printf("NOTE gst y4m I420 96x64 vs ffmpeg rgb24: max diff %d, %d of %d values > %d\n", maxd,
           over, 96 * 64 * 3, YUV_TOL);
    assert_true(over <= (int)(YUV_OVER_FRAC * 96 * 64 * 3));
    io_vsrc_close(v);
}

static void test_y4m_ffmpeg(void **st)
{
    (void)st;
    NEED_TOOL("ffmpeg");
    static const char *const pix[] = {"yuv420p", "yuv422p", "yuv444p", "yuvj420p", "gray"};
    for (int p = 0; p < 5; p++) {
        char y4m[600], ref[600];
        testsrc_y4m("ff.y4m", 80, 48, 3, pix[p], y4m, sizeof y4m);
        ffmpeg_convert(y4m, "-f rawvideo -pix_fmt rgb24", "ff.rgb", ref, sizeof ref);
        io_vsrc_stat s;
        io_vsrc *v = feed("stream:", y4m, 80, 48, IO_VSRC_MONO, 777, &s);
        assert_int_equal(s.frames + s.skipped, 3);
        int over, maxd = compare_rgb(v, ref, 80, 48, 2, YUV_TOL, &over);
        printf("NOTE ffmpeg y4m %s 80x48 vs ffmpeg rgb24: max diff %d, %d of %d values > %d\n",
               pix[p], maxd, over, 80 * 48 * 3, YUV_TOL);
        assert_true(over <= (int)(YUV_OVER_FRAC * 80 * 48 * 3));
        io_vsrc_close(v);
    }
    /* 10-bit: refused with the reason */
    char y4m[600];
    testsrc_y4m("ff10.y4m", 64, 48, 1, "yuv420p10le -strict -1", y4m, sizeof y4m);
    io_vsrc_stat s;
    io_vsrc *v = feed("stream:", y4m, 64, 48, IO_VSRC_MONO, 100000, &s);
    assert_int_equal(s.state, IO_VSRC_FAILED);
    assert_non_null(strstr(s.msg, "colourspace C420p10 is not supported"));
    printf("NOTE %s\n", s.msg);
    io_vsrc_close(v);
}

static void test_raw_ffmpeg(void **st)
{
    (void)st;
    NEED_TOOL("ffmpeg");
    static const char *const pix[] = {"rgb24", "bgra", "bgr24", "rgba", "nv12", "yuyv422", "uyvy422",
                                      "yuv420p", "gray"};
    static const int exact[] = {1, 1, 1, 1, 0, 0, 0, 0, 0};
    /* ffmpeg's nv12 / yuyv422 / uyvy422 -> rgb24 paths interpolate chroma
     * (up to 57 apart from its own yuv420p -> rgb24 of the same samples):
     * the reference repacks them losslessly to the planar format of the
     * same subsampling first, then converts that to rgb24 */
    static const char *const planar[] = {"", "", "", "", "yuv420p", "yuv422p", "yuv422p",
                                         "yuv420p", "gray"};
    for (int p = 0; p < 9; p++) {
        char raw[600], ref[600], cmd[3072], spec[700], conv[1600];
        tmp("ff.raw", raw, sizeof raw);
        tmp("ff_ref.rgb", ref, sizeof ref);
        if (planar[p][0])
            snprintf(conv, sizeof conv, "ffmpeg -loglevel error -f rawvideo -pix_fmt %s -s 128x48 "
                     "-i '%s' -f rawvideo -pix_fmt %s - | ffmpeg -loglevel error -y -f rawvideo "
                     "-pix_fmt %s -s 128x48 -i - -f rawvideo -pix_fmt rgb24 '%s'", pix[p], raw,
                     planar[p], planar[p], ref);
        else
            snprintf(conv, sizeof conv, "ffmpeg -loglevel error -y -f rawvideo -pix_fmt %s -s "
                     "128x48 -i '%s' -f rawvideo -pix_fmt rgb24 '%s'", pix[p], raw, ref);
        /* the frames as the producer writes them, and ffmpeg's own rgb24 of
         * the same bytes */
        snprintf(cmd, sizeof cmd, "ffmpeg -loglevel error -y -f lavfi -i testsrc2=size=128x48:rate=30 "
                 "-frames:v 3 -f rawvideo -pix_fmt %s '%s' && %s", pix[p], raw, conv);
        assert_int_equal(system(cmd), 0);
        snprintf(spec, sizeof spec, "raw:128x48:%s:", pix[p]);
        io_vsrc_stat s;
        /* side by side: each eye is 64x48 */
        io_vsrc *v = feed(spec, raw, 64, 48, IO_VSRC_SBS, 3000, &s);
        assert_string_equal(s.kind, "raw");
        assert_int_equal(s.frames + s.skipped, 3);
        /* compare both eyes with the reference's halves */
        size_t n, stride;
        uint8_t *r = tu_read_file(ref, &n);
        const uint8_t *fr = r + 2 * 128 * 48 * 3;
        int maxd = 0, over = 0;
        for (int e = 0; e < 2; e++) {
            const uint8_t *im = io_vsrc_eye(v, e, &stride);
            for (int y = 0; y < 48; y++)
                for (int x = 0; x < 64; x++)
                    for (int c = 0; c < 3; c++) {
                        int d = abs(im[(size_t)y * stride + 4 * (size_t)x + (size_t)c] -
                                    fr[((size_t)y * 128 + (size_t)(x + 64 * e)) * 3 + (size_t)c]);
                        if (d > maxd) maxd = d;
                        if (d > YUV_TOL) over++;
                    }
        }
        printf("NOTE raw %s 128x48 sbs vs ffmpeg rgb24: max diff %d, %d of %d values > %d\n", pix[p],
               maxd, over, 128 * 48 * 3, YUV_TOL);
        if (exact[p]) assert_int_equal(maxd, 0);
        else assert_true(over <= (int)(YUV_OVER_FRAC * 128 * 48 * 3));
        free(r);
        io_vsrc_close(v);
    }
}

/* A regular file is paced at the y4m header's rate (here 30 FPS) by the
 * clock given, and starts again with loop. */
static void test_regular_file_paced(void **st)
{
    (void)st;
    NEED_TOOL("ffmpeg");
    char y4m[600], spec[700];
    testsrc_y4m("paced.y4m", 64, 48, 3, "yuv420p", y4m, sizeof y4m);
    snprintf(spec, sizeof spec, "stream:%s", y4m);
    for (int loop = 0; loop < 2; loop++) {
        uint64_t clock = 1000 * MS;
        io_vsrc_config c = io_vsrc_config_default(spec);
        c.eye_width = 64;
        c.eye_height = 48;
        c.layout = IO_VSRC_MONO;
        c.clock_ns = &clock;
        c.loop = loop;
        io_vsrc *v;
        io_error err;
        assert_int_equal(io_vsrc_open(&v, &c, &err), IO_OK);
        io_vsrc_stat s;
        assert_int_equal(poll_fresh(v, 0), 1); /* frame 0 at once */
        clock += 10 * MS;
        assert_int_equal(poll_fresh(v, 0), 0); /* frame 1 is due at +33 ms */
        clock += 30 * MS;
        assert_int_equal(poll_fresh(v, 0), 1);
        clock += 34 * MS;
        assert_int_equal(poll_fresh(v, 0), 1); /* frame 2 */
        io_vsrc_status(v, clock, &s);
        assert_int_equal(s.frames, 3);
        assert_int_equal(s.skipped, 0);
        clock += 34 * MS;
        int f = poll_fresh(v, 0);
        io_vsrc_status(v, clock, &s);
        if (loop) {
            assert_int_equal(f, 1); /* frame 0 again */
            assert_int_equal(s.frames, 4);
            assert_int_not_equal(s.state, IO_VSRC_ENDED);
        } else {
            assert_int_equal(f, 0);
            assert_int_equal(s.state, IO_VSRC_ENDED);
        }
        /* far behind: one frame, the rest skipped (no burst) */
        if (loop) {
            clock += 1000 * MS;
            assert_int_equal(poll_fresh(v, 0), 1);
            io_vsrc_status(v, clock, &s);
            assert_int_equal(s.frames, 5);
            clock += 10 * MS;
            assert_int_equal(poll_fresh(v, 0), 0);
        }
        io_vsrc_close(v);
    }
}

/* ------------------------------------------------------ file cameras */

static void write_pngs(const char *pattern, int count, int w, int h, int salt)
{
    for (int k = 0; k < count; k++) {
        io_image im;
        io_error err;
        assert_int_equal(io_image_alloc(&im, w, h, 3, IO_U8, &err), IO_OK);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                uint8_t *p = (uint8_t *)im.data + (size_t)y * im.stride + 3 * (size_t)x;
                p[0] = (uint8_t)(x * 3 + k * 40 + salt);
                p[1] = (uint8_t)(y * 5);
                p[2] = (uint8_t)(k * 60);
            }
        char path[700];
        snprintf(path, sizeof path, pattern, k);
        assert_int_equal(io_image_save(path, &im, &err), IO_OK);
        io_image_free(&im);
    }
}

/* Opens the file camera of selector sel as the tests record it (64x48 at
 * 30 Hz, the format the file offers) with the backend options o; a
 * failure fails the test with the camera's message. */
static void file_cam_open(io_cam *cam, const char *sel, io_file_cam_opts *o)
{
    io_error err;
    io_cam_config c = io_cam_config_default(sel);
    c.width = 64;
    c.height = 48;
    c.fourcc = 0;
    c.fps = 30;
    c.backend_opts = o;
    if (io_cam_open(cam, &io_cam_file, &c, &err) != IO_OK) fail_msg("%s", err.msg);
}

static void test_file_cam_sequence(void **st)
{
    (void)st;
    char pat[2][600], sel[2][1300];
    tmp("camL_%04d.png", pat[0], sizeof pat[0]);
    tmp("camR_%04d.png", pat[1], sizeof pat[1]);
    write_pngs(pat[0], 4, 64, 48, 0);
    write_pngs(pat[1], 4, 64, 48, 7);
    int fds0 = tu_count_fds();
    uint64_t clock = 2000 * MS;
    const uint64_t P = 1000000000ull / 30;
    for (int loop = 0; loop < 2; loop++) {
        io_cam cam[2];
        io_file_cam_opts o = {0};
        o.loop = loop;
        o.cache_bytes = loop ? 1 : 0; /* with loop: each frame decoded when due */
        o.t0_ns = clock;
        o.clock_ns = &clock;
        io_error err;
        for (int e = 0; e < 2; e++) {
            snprintf(sel[e], sizeof sel[e], "file:%s", pat[e]);
            assert_true(io_cam_file_selector(sel[e]));
            file_cam_open(&cam[e], sel[e], &o);
            assert_int_equal(cam[e].fourcc, IO_FMT_RGB3);
            assert_int_equal(io_cam_start(&cam[e], &err), IO_OK);
        }
        io_stereo s;
        io_stereo_init(&s, &cam[0], &cam[1], 0);
        io_frame f[2];
        int got;
        uint64_t t0 = clock;
        assert_int_equal(io_stereo_grab(&s, 0, f, &got, &err), IO_OK);
        assert_int_equal(got, 3);
        assert_int_equal(f[0].t_ns, t0);
        assert_int_equal(f[1].t_ns, t0);
        assert_int_equal(f[0].sequence, 0);
        /* the pixels are the PNG's */
        assert_int_equal(f[1].data[3 * 10 + 0], (uint8_t)(10 * 3 + 7));
        assert_int_equal(f[1].data[64 * 3 * 2 + 1], 10);
        io_stereo_release(&s, f, &err);
        /* nothing new before the next frame time */
        clock = t0 + P / 2;
        assert_int_equal(io_stereo_grab(&s, 0, f, &got, &err), IO_OK);
        assert_int_equal(got, 0);
        /* 2.5 periods on: frame 2 (frame 1 dropped, as a camera would) */
        clock = t0 + 2 * P + P / 2;
        assert_int_equal(io_stereo_grab(&s, 0, f, &got, &err), IO_OK);
        assert_int_equal(got, 3);
        assert_int_equal(f[0].sequence, 2);
        assert_int_equal(f[0].t_ns, t0 + 2 * P);
        assert_int_equal(f[0].data[2], 120);
        io_stereo_release(&s, f, &err);
        assert_int_equal(cam[0].stats.dropped, 1);
        /* past the end */
        clock = t0 + 4 * P + 10;
        io_result r = io_stereo_grab(&s, 0, f, &got, &err);
        if (loop) {
            assert_int_equal(r, IO_OK);
            assert_int_equal(got, 3);
            assert_int_equal(f[0].sequence, 4);
            assert_int_equal(f[0].data[2], 0); /* image 0 again */
            io_stereo_release(&s, f, &err);
        } else {
            clock = t0 + 5 * P;
            r = io_stereo_grab(&s, 0, f, &got, &err);
            assert_int_equal(r, IO_ERR_DEVICE);
            assert_true(io_cam_file_ended(&cam[0]));
            assert_non_null(strstr(cam[0].status, "end of the recording after 4 frames"));
        }
        for (int e = 0; e < 2; e++) io_cam_close(&cam[e]);
    }
    /* bad input */
    io_cam cam;
    io_error err;
    io_cam_config c = io_cam_config_default("file:/nonexistent/left_%04d.png");
    assert_int_equal(io_cam_open(&cam, &io_cam_file, &c, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "/nonexistent/left_0000.png"));
    c = io_cam_config_default(sel[0]); /* 640x480 asked, 64x48 recorded */
    c.fourcc = 0;
    assert_int_equal(io_cam_open(&cam, &io_cam_file, &c, &err), IO_ERR_FORMAT);
    assert_non_null(strstr(err.msg, "64x48"));
    printf("NOTE %s\n", err.msg);
    c = io_cam_config_default("file:a_%d_%d.png");
    assert_int_equal(io_cam_open(&cam, &io_cam_file, &c, &err), IO_ERR_ARGS);
    assert_int_equal(tu_count_fds(), fds0);
}

/* A video: a .y4m read directly and the same frames in a lossless .mkv
 * decoded by ffmpeg give the same pixels; paced in real time. */
static void test_file_cam_video(void **st)
{
    (void)st;
    NEED_TOOL("ffmpeg");
    char y4m[600], mkv[600];
    testsrc_y4m("vid.y4m", 64, 48, 5, "yuv420p", y4m, sizeof y4m);
    ffmpeg_convert(y4m, "-c:v ffv1", "vid.mkv", mkv, sizeof mkv);
    int fds0 = tu_count_fds();
    uint8_t first[2][64 * 48 * 3];
    for (int m = 0; m < 2; m++) {
        char sel[700];
        snprintf(sel, sizeof sel, "file:%s", m ? mkv : y4m);
        uint64_t clock = 3000 * MS;
        io_file_cam_opts o = {0};
        o.clock_ns = &clock;
        o.t0_ns = clock;
        io_cam cam;
        io_error err;
        file_cam_open(&cam, sel, &o);
        assert_int_equal(io_cam_start(&cam, &err), IO_OK);
        io_frame f;
        int got = 0;
        /* ffmpeg decodes asynchronously: the first frame was read at open */
        assert_int_equal(io_cam_grab(&cam, 0, &f, &got, &err), IO_OK);
        assert_int_equal(got, 1);
        assert_int_equal(f.sequence, 0);
        memcpy(first[m], f.data, sizeof first[m]);
        io_cam_release(&cam, &f, &err);
        /* to the end: frames 1..4, then the end of the recording */
        uint32_t last = 0;
        for (int k = 1; k < 40 && !io_cam_file_ended(&cam); k++) {
            clock += 1000000000ull / 30;
            io_result r = io_cam_grab(&cam, 50, &f, &got, &err);
            if (r != IO_OK) break;
            if (got) {
                last = f.sequence;
                io_cam_release(&cam, &f, &err);
            }
        }
        assert_int_equal(last, 4);
        assert_true(io_cam_file_ended(&cam));
        io_cam_close(&cam);
    }
    assert_memory_equal(first[0], first[1], sizeof first[0]);
    assert_int_equal(tu_count_fds(), fds0);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_egfv_basic_sbs_depth),
        cmocka_unit_test(test_egfv_tb_u16_depth),
        cmocka_unit_test(test_egfv_scaled),
        cmocka_unit_test(test_egfv_bad_input),
        cmocka_unit_test(test_stalled_producer),
        cmocka_unit_test(test_fifo_writers),
        cmocka_unit_test(test_y4m_gstreamer),
        cmocka_unit_test(test_y4m_ffmpeg),
        cmocka_unit_test(test_raw_ffmpeg),
        cmocka_unit_test(test_regular_file_paced),
        cmocka_unit_test(test_file_cam_sequence),
        cmocka_unit_test(test_file_cam_video))
