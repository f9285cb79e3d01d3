/* bench_display.c - what io_display_present costs on the CPU before the
 * page flip: converting two RGBA eyes into an XRGB8888 scan-out buffer
 * (io_display_blit_xrgb, the KMS backend's conversion), 2 x 1280x800 into
 * 2560x800 and 2 x 1440x1600 into 2880x1600. The buffer here is ordinary
 * memory; a real dumb buffer may be write-combined (similar for these
 * sequential writes) or uncached. Reports; never passes or fails.
 *
 *   build/bench/bench_display [RUNS]       (default 51) */
#include "bench_util.h"

#include "../src/io/io_display_impl.h"
#include "../src/cpu/ef_mem.h"

static void run(int ew, int eh, int runs)
{
    size_t pitch = (size_t)2 * ew * 4;
    uint8_t *dst = calloc((size_t)eh, pitch);
    uint8_t *eye[2] = {malloc((size_t)ew * eh * 4), malloc((size_t)ew * eh * 4)};
    double *t = malloc((size_t)runs * sizeof *t), *c = malloc((size_t)runs * sizeof *c);
    uint64_t seed = 1;
    if (!dst || !eye[0] || !eye[1] || !t || !c) exit(1);
    for (size_t i = 0; i < (size_t)ew * eh * 4; i++) {
        eye[0][i] = (uint8_t)bench_rand(&seed);
        eye[1][i] = (uint8_t)bench_rand(&seed);
    }
    uint32_t sum = 0;
    for (int r = 0; r < runs; r++) {
        double t0 = bench_now_ms(CLOCK_MONOTONIC), c0 = bench_now_ms(CLOCK_THREAD_CPUTIME_ID);
        for (int e = 0; e < 2; e++)
            io_display_blit_xrgb(dst, pitch, e * ew, 0, eye[e], (size_t)ew * 4, ew, eh);
        t[r] = bench_now_ms(CLOCK_MONOTONIC) - t0;
        c[r] = bench_now_ms(CLOCK_THREAD_CPUTIME_ID) - c0;
        sum += dst[(size_t)r % pitch];
    }
    double med = bench_median(t, runs), cmed = bench_median(c, runs);
    printf("present conversion 2 x %dx%d RGBA -> %dx%d XRGB8888: median %.3f ms wall (min %.3f), %.3f ms CPU "
           "(min %.3f), %d runs [%u]\n", ew, eh, 2 * ew, eh, med, t[0], cmed, c[0], runs, sum & 1);
    EF_FREE_ALL(dst, eye[0], eye[1], t, c);
}

int main(int argc, char **argv)
{
    int runs = 51; /* bench_display [--runs N] (or the count alone, as before) */
    if (argc == 3 && !strcmp(argv[1], "--runs")) runs = atoi(argv[2]);
    else if (argc == 2) runs = atoi(argv[1]);
    else if (argc != 1) {
        fprintf(stderr, "bench_display: usage: bench_display [--runs N]\n");
        return 2;
    }
    if (runs < 1) runs = 1;
    run(1280, 800, runs);
    run(1440, 1600, runs);
    return 0;
}
