/* bench_vsrc.c - reads a V source (io_vsrc.h, docs/vstream.md) for a while
 * the way `egofuse run --virt-source SPEC` does, and reports what came:
 * frames converted, skipped, bad, the final state and message, frames per
 * second, the time io_vsrc_poll took per fresh frame (read, convert,
 * scale into both eyes: median and max) and the V age at each fresh frame
 * (its time stamp to the moment it was ready, for sources that carry one).
 * Used to check the producer command lines of docs/vstream.md and to
 * measure the V path on this machine; it reports, never passes or fails.
 *
 *   bench_vsrc SPEC [--seconds S] [--eye WxH] [--layout sbs|tb|mono|auto]
 *              [--fps N] [--stale MS] [--loop]
 *   bench_vsrc --cams SEL_L SEL_R [--seconds S] [--fps N] [--size WxH] [--loop]
 *              two file cameras (io_cam_file, e.g. file:cam/left_%04d.png)
 *              paired by io_stereo in real time: pairs per second, skew,
 *              and the delay from a pair's time stamp to its hand-out
 *   bench_vsrc --convert [WxH]   conversion of one frame of each format to
 *              RGBA (io_frame_to_rgba) and the bilinear scale of one eye,
 *              median thread CPU time of 30 runs (2560x800 by default)
 *
 *   ffmpeg -re -f lavfi -i testsrc2=size=2560x800:rate=60 -f yuv4mpegpipe - |
 *       build/bench/bench_vsrc stream:- --seconds 5
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "../src/io/io_vsrc.h"
#include "../src/io/io_vstream.h"
#include "bench_util.h"
#include "../src/cpu/ef_mem.h"

static uint64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static double cpu_ms(void) { return bench_now_ms(CLOCK_THREAD_CPUTIME_ID); }

static int bench_convert(int w, int h)
{
    static const uint32_t fmts[] = {IO_FMT_YUYV, IO_FMT_NV12, IO_FMT_YU12, IO_FMT_RGB3, IO_FMT_BGR4};
    size_t maxb = (size_t)w * (size_t)h * 4;
    uint8_t *src = malloc(maxb), *dst = malloc(maxb);
    if (!src || !dst) return 1;
    /* a smooth picture (random bytes would make every clamp a branch miss) */
    for (size_t i = 0; i < maxb; i++) src[i] = (uint8_t)(64 + (i % 509) / 4 + (i / 40960) % 64);
    double t[30];
    for (size_t k = 0; k < sizeof fmts / sizeof fmts[0]; k++) {
        io_frame f;
        memset(&f, 0, sizeof f);
        f.data = src;
        f.width = w;
        f.height = h;
        f.fourcc = fmts[k];
        f.stride = io_fmt_min_stride(fmts[k], w);
        f.bytes = io_fmt_image_bytes(fmts[k], f.stride, w, h);
        io_error err;
        for (int r = 0; r < 30; r++) {
            double a = cpu_ms();
            io_frame_to_rgba(&f, dst, 4 * (size_t)w, &err);
            t[r] = cpu_ms() - a;
        }
        qsort(t, 30, sizeof t[0], bench_cmp_double);
        char fs[5];
        printf("convert    %s %dx%d -> RGBA: %.2f ms (median CPU time)\n", io_fourcc_str(fmts[k], fs),
               w, h, t[15]);
    }
    /* one eye: the left half scaled to 1280x800 */
    int *xt = malloc(sizeof(int) * 2 * 1280), *yt = malloc(sizeof(int) * 2 * 800);
    uint8_t *eye = malloc(1280 * 800 * 4);
    uint16_t *rows = malloc(sizeof(uint16_t) * 6 * 1280);
    int sw = w / 2, sh = h == 800 ? 720 : h;
    for (int r = 0; r < 30; r++) {
        double a = cpu_ms();
        vs_scale_rgba(dst, sw, sh, 4 * (size_t)w, eye, 1280, 800, 4 * 1280, xt, yt, rows);
        t[r] = cpu_ms() - a;
    }
    qsort(t, 30, sizeof t[0], bench_cmp_double);
    printf("scale      %dx%d -> 1280x800 bilinear, one eye: %.2f ms (median CPU time)\n", sw, sh,
           t[15]);
    EF_FREE_ALL(xt, yt, eye, rows, src, dst);
    return 0;
}

static int bench_cams(int argc, char **argv)
{
    double seconds = 3;
    int fps = 60, w = 640, h = 480, loop = 0;
    for (int i = 4; i < argc; i++) {
        if (!strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = atof(argv[++i]);
        else if (!strcmp(argv[i], "--fps") && i + 1 < argc) fps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) sscanf(argv[++i], "%dx%d", &w, &h);
        else if (!strcmp(argv[i], "--loop")) loop = 1;
    }
    io_file_cam_opts o;
    memset(&o, 0, sizeof o);
    o.loop = loop;
    o.t0_ns = mono_ns() + 200000000ull; /* both eyes: the same t0 */
    io_cam cam[2];
    io_error err;
    for (int e = 0; e < 2; e++) {
        io_cam_config c = io_cam_config_default(argv[2 + e]);
        c.width = w;
        c.height = h;
        c.fps = fps;
        c.fourcc = 0;
        c.backend_opts = &o;
        if (io_cam_open(&cam[e], &io_cam_file, &c, &err) != IO_OK ||
            io_cam_start(&cam[e], &err) != IO_OK) {
            fprintf(stderr, "bench_vsrc: %s\n", err.msg);
            return 1;
        }
    }
    io_stereo st;
    io_stereo_init(&st, &cam[0], &cam[1], 0);
    size_t cap = 100000, n = 0;
    double *delay = malloc(cap * sizeof *delay);
    uint64_t t_end = o.t0_ns + (uint64_t)(seconds * 1e9);
    while (mono_ns() < t_end) {
        io_frame f[2];
        int got = 0;
        if (io_stereo_grab(&st, 100, f, &got, &err) != IO_OK) {
            printf("cams       %s\n", err.msg);
            break;
        }
        if (got == 3) {
            if (n < cap) delay[n++] = 1e-6 * (double)(mono_ns() - f[0].t_ns);
            io_stereo_release(&st, f, &err);
        }
    }
    qsort(delay, n, sizeof *delay, bench_cmp_double);
    printf("cams       %s + %s, %dx%d at %d FPS: %llu pairs in %.1f s (%.1f/s), max |skew| %.3f ms, "
           "dropped %llu/%llu, unpaired %llu/%llu\n", argv[2], argv[3], w, h, fps,
           (unsigned long long)st.pairs, seconds, (double)st.pairs / seconds,
           1e-6 * (double)st.max_abs_skew_ns, (unsigned long long)cam[0].stats.dropped,
           (unsigned long long)cam[1].stats.dropped, (unsigned long long)st.unpaired[0],
           (unsigned long long)st.unpaired[1]);
    if (n)
        printf("delay      time stamp -> pair handed out: %.3f ms median, %.3f ms p99, %.3f ms max\n",
               delay[n / 2], delay[(size_t)(0.99 * (double)(n - 1))], delay[n - 1]);
    free(delay);
    io_cam_close(&cam[0]);
    io_cam_close(&cam[1]);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 4 && !strcmp(argv[1], "--cams")) return bench_cams(argc, argv);
    if (argc >= 2 && !strcmp(argv[1], "--convert")) {
        int w = 2560, h = 800;
        if (argc >= 3) sscanf(argv[2], "%dx%d", &w, &h);
        return bench_convert(w, h);
    }
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        fprintf(stderr, "usage: bench_vsrc SPEC [--seconds S] [--eye WxH] [--layout L] [--fps N] "
                        "[--stale MS] [--loop]\n");
        return 2;
    }
    io_vsrc_config c = io_vsrc_config_default(argv[1]);
    double seconds = 5;
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = atof(argv[++i]);
        else if (!strcmp(argv[i], "--eye") && i + 1 < argc)
            sscanf(argv[++i], "%dx%d", &c.eye_width, &c.eye_height);
        else if (!strcmp(argv[i], "--layout") && i + 1 < argc) c.layout = io_vsrc_layout_parse(argv[++i]);
        else if (!strcmp(argv[i], "--fps") && i + 1 < argc) c.fps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--stale") && i + 1 < argc) c.stale_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--loop")) c.loop = 1;
        else {
            fprintf(stderr, "bench_vsrc: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    if (c.layout < 0) {
        fprintf(stderr, "bench_vsrc: layout is sbs, tb, mono or auto\n");
        return 2;
    }
    io_vsrc *v;
    io_error err;
    if (io_vsrc_open(&v, &c, &err) != IO_OK) {
        fprintf(stderr, "bench_vsrc: %s\n", err.msg);
        return 1;
    }
    struct stat sb;
    const char *colon = strchr(argv[1], ':');
    int fifo = colon && stat(colon + 1, &sb) == 0 && S_ISFIFO(sb.st_mode);
    size_t cap = 1 << 16, n = 0;
    double *poll_ms = malloc(cap * sizeof *poll_ms), *age_ms = malloc(cap * sizeof *age_ms);
    if (!poll_ms || !age_ms) return 1;
    uint64_t t0 = mono_ns(), t_first = 0, t_last = 0;
    io_vsrc_stat st;
    for (;;) {
        uint64_t a = mono_ns();
        if (a - t0 > (uint64_t)(seconds * 1e9)) break;
        int fresh = 0;
        /* as the run loop does between camera pairs: a short wait */
        io_vsrc_poll(v, 5, &fresh, &err);
        uint64_t b = mono_ns();
        io_vsrc_status(v, b, &st);
        if (fresh && n < cap) {
            poll_ms[n] = 1e-6 * (double)(b - a);
            age_ms[n] = 1e-6 * (double)st.age_ns;
            n++;
            if (!t_first) t_first = b;
            t_last = b;
        }
        /* a FIFO's writer may come back: keep reading it */
        if (st.state == IO_VSRC_FAILED || (st.state == IO_VSRC_ENDED && !fifo)) break;
    }
    io_vsrc_status(v, 0, &st);
    char fs[5];
    printf("source     %s (%s), %dx%d %s, layout %s%s -> eyes %dx%d\n", argv[1], st.kind,
           st.src_width, st.src_height, io_fourcc_str(st.fourcc, fs), io_vsrc_layout_name(st.layout),
           st.has_depth ? ", depth" : "", c.eye_width, c.eye_height);
    printf("frames     %llu converted, %llu skipped, %llu bad, %llu reopens\n",
           (unsigned long long)st.frames, (unsigned long long)st.skipped,
           (unsigned long long)st.bad, (unsigned long long)st.reopens);
    if (n > 1)
        printf("rate       %.2f frames/s converted\n",
               (double)(n - 1) / (1e-9 * (double)(t_last - t_first)));
    if (n) {
        double mp = 0, ma = 0;
        for (size_t i = 0; i < n; i++) {
            if (poll_ms[i] > mp) mp = poll_ms[i];
            if (age_ms[i] > ma) ma = age_ms[i];
        }
        qsort(poll_ms, n, sizeof *poll_ms, bench_cmp_double);
        qsort(age_ms, n, sizeof *age_ms, bench_cmp_double);
        printf("poll       %.3f ms median, %.3f ms max per fresh frame (read + convert + scale)\n",
               poll_ms[n / 2], mp);
        printf("age        %.3f ms median, %.3f ms max when ready (time stamp -> eyes ready)\n",
               age_ms[n / 2], ma);
    }
    printf("state      %s%s%s\n", io_vsrc_state_name(st.state), st.msg[0] ? ": " : "", st.msg);
    free(poll_ms);
    free(age_ms);
    io_vsrc_close(v);
    return 0;
}
