/* test_eval_report.c - the charts of `egofuse eval --report DIR` with a
 * subset of the methods (issue 14, src/eval/eval_report.c).
 *
 *   subset_kin_refine  `--methods kin,refine`: every chart of the report
 *                      (the speed charts, the tracking sweeps, the band,
 *                      the levels of detail, the sequences, the lighting)
 *                      is drawn. Before, gnuplot failed on the histogram
 *                      of sequences.dat (a column of NaN for skin and
 *                      kin-cal-pred) and on lod.dat (kin-cal-pred's empty
 *                      block was no gnuplot index, so refine's index 1 did
 *                      not exist), and a failed gnuplot run draws no chart
 *                      at all; empty blocks of speed.dat were legend entries
 *                      with no point.
 *   subset_skin        `--methods skin`: no tracking sweep and no level of
 *                      detail has a point; their charts are still drawn
 *                      (empty, with a note), the others as usual.
 * Both check that no ".tmp." file is left and that gnuplot did not fail,
 * and that every method of a tracking sweep has the range where its IoU is
 * at or above 0.9 in its legend entry (below the plot).
 * gnuplot missing: SKIP. Seeded (the generator's fixed seed), 1 frame per
 * batch, no timings. */
#include "support/testutil.h"

#include <cmocka.h>
#include "support/tu_bin_main.h"
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char out[1 << 16];

static const char *const charts[] = {"speed_iou", "speed_bf", "noise",     "latency",
                                     "calib",     "dropout",  "handspeed", "band",
                                     "sequences", "lod",      "light"};

static int have_gnuplot(void)
{
    return system("command -v gnuplot >/dev/null 2>&1") == 0;
}

/* swept: how many of methods run the tracking sweeps (not skin); titled:
 * their legend entries over the five sweeps (kin has no calibration) */
static void run_subset(const char *name, const char *methods, int swept, int want_titled)
{
    if (!have_gnuplot()) {
        printf("SKIP: gnuplot missing: the charts of eval --report are not drawn\n");
        skip();
        return;
    }
    char dir[1024], p[1200];
    tu_tmp_path(name, dir, sizeof dir);
    assert_int_equal(tu_rm_rf(dir), 0);
    int rc = tu_runl(out, sizeof out, tu_bin(), "eval", "--methods", methods, "--frames", "1",
                     "--sweep-frames", "1", "--seq-frames", "1", "--quiet", "--report", dir,
                     NULL);
    if (rc != 0 || strstr(out, "gnuplot failed")) printf("%s\n", out);
    assert_int_equal(rc, 0);
    assert_null(strstr(out, "gnuplot failed"));
    /* gnuplot's errors and warnings: "DIR/charts.gp" line N: ... */
    assert_null(strstr(out, ".gp\" line"));
    for (size_t i = 0; i < sizeof charts / sizeof charts[0]; i++) {
        snprintf(p, sizeof p, "%s/%s.png", dir, charts[i]);
        if (!tu_exists(p)) printf("missing: %s\n", p);
        assert_true(tu_exists(p));
    }
    /* the tables table.md's header names (light.md and kf.md: their own) */
    static const char *const tables[] = {"table.md", "summary.csv", "light.md", "kf.md"};
    for (size_t i = 0; i < sizeof tables / sizeof tables[0]; i++) {
        snprintf(p, sizeof p, "%s/%s", dir, tables[i]);
        if (!tu_exists(p)) printf("missing: %s\n", p);
        assert_true(tu_exists(p));
    }
    /* every method of a sweep chart says in its legend entry where its
     * IoU is at or above 0.9 (issue 14 item 5), the legend sits below the
     * plot; the speed charts have tics between the decades */
    snprintf(p, sizeof p, "%s/charts.gp", dir);
    FILE *gp = fopen(p, "rb");
    assert_non_null(gp);
    static char gps[1 << 17];
    const size_t gn = fread(gps, 1, sizeof gps - 1, gp);
    gps[gn] = '\0';
    fclose(gp);
    int titled = 0, keys = 0;
    for (const char *q = gps; (q = strstr(q, ": IoU ")); q++) titled++;
    for (const char *q = gps; (q = strstr(q, "set key at screen 0.5")); q++) keys++;
    assert_int_equal(keys, 5);
    if (titled != want_titled) printf("%d sweep legend entries with the 0.9 ranges\n", titled);
    assert_int_equal(titled, want_titled);
    assert_null(strstr(gps, "below 0.9 throughout"));   /* the old in-plot notes */
    if (swept) assert_non_null(strstr(gps, "set xtics ('"));
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *e;
    while ((e = readdir(d))) assert_null(strstr(e->d_name, ".tmp."));
    closedir(d);
    assert_int_equal(tu_rm_rf(dir), 0);   /* the report */
}

static void subset_kin_refine(void **state)
{
    (void)state;
    run_subset("report_kin_refine", "kin,refine", 2, 9);
}

static void subset_skin(void **state)
{
    (void)state;
    run_subset("report_skin", "skin", 0, 0);
}

TU_MAIN_NEEDS_BIN(NULL, NULL,
                  cmocka_unit_test(subset_kin_refine),
                  cmocka_unit_test(subset_skin))
