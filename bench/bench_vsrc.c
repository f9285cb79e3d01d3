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
 *
 *   ffmpeg -re -f lavfi -i testsrc2=size=2560x800:rate=60 -f yuv4mpegpipe - |
 *       build/bench/bench_vsrc stream:- --seconds 5
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../src/io/io_vsrc.h"

static uint64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
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
        if (st.state == IO_VSRC_ENDED || st.state == IO_VSRC_FAILED) break;
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
        qsort(poll_ms, n, sizeof *poll_ms, cmp_d);
        qsort(age_ms, n, sizeof *age_ms, cmp_d);
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
