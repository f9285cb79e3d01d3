/* eval_report.c - the evaluation's tables (stdout, table.md), summary.csv,
 * the per-group and per-sequence data files and the gnuplot charts of the
 * report folder (see eval.h, docs/accuracy.md). */
#include "eval_internal.h"
#include "../cli/cli.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---------------------------------------------------------- reporting */

typedef struct summary {
    double iou, bf1, bf3, fp, fn, psnr, ms, flicker;
} summary;

static summary summarise(const method_run *r)
{
    summary s;
    double n = r->n_eye > 0 ? (double)r->n_eye : 1.0;
    s.iou = r->iou / n;
    s.bf1 = r->bf1 / n;
    s.bf3 = r->bf3 / n;
    s.fp = r->fp / n;
    s.fn = r->fn / n;
    s.psnr = fuse_psnr_of_mse(r->mse / n);
    s.ms = 1e3 * r->secs / (r->n_frames > 0 ? (double)r->n_frames : 1.0);
    s.flicker = r->flicker_den > 0.0 ? r->flicker / r->flicker_den : 0.0;
    return s;
}

void eval__print_calib(FILE *f, const eval_ctx *c)
{
    float arm, hand, sh;
    eval__true_scales(c, &arm, &hand, &sh);
    fprintf(f, "calibration (kin_user_calib_estimate_tips on the calibration motion): arm "
               "x%.3f (true %.3f), hand x%.3f (true %.3f, %s), shoulders x%.3f (true %.3f)\n",
            (double)c->calib.arm_scale[1], (double)arm, (double)c->calib.hand_scale[1],
            (double)hand, c->calib_hand_fallback ? c->calib_why : "fingertip gesture",
            (double)c->calib.shoulder_scale, (double)sh);
}

/* Report files go through io_out: complete or absent, a failed write is
 * "path: write failed: reason" and exit 1 (io.h, OUTPUT FILES). */
static FILE *out_open(io_out *o, const char *path)
{
    io_error err;
    if (io_out_open(o, path, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        return NULL;
    }
    return o->f;
}

static int out_commit(io_out *o)
{
    io_error err;
    if (io_out_commit(o, &err) != IO_OK) return cli_fail("%s", err.msg);
    return EXIT_OK;
}

int eval__write_csv(const char *path, const method_run *R, int n)
{
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f, "method,setting,iou,bf1,bf3,fp_area,fn_area,psnr,ms_per_frame,flicker,group\n");
    for (int i = 0; i < n; i++) {
        summary s = summarise(&R[i]);
        fprintf(f, "%s,%s,%.5f,%.5f,%.5f,%.1f,%.1f,%.3f,%.3f,%.4f,%s\n",
                kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp, s.fn,
                s.psnr, s.ms, s.flicker, R[i].cfg.group);
    }
    return out_commit(&of);
}

/* The limb thickness the first refine run with the elbow fit measured
 * from the images (pipe_fit_measure), against the truth's. */
void eval__print_thickness(FILE *f, const eval_ctx *c, const method_run *R, int n)
{
    for (int i = 0; i < n; i++) {
        if (R[i].cfg.kind != M_REFINE || !R[i].have_thick) continue;
        fprintf(f, "refine's limb thickness from the images (pipe_fit, only thinner is "
                   "measured): forearm x%.3f x%.3f (true %.2f), upper arm x%.3f x%.3f "
                   "(true %.2f)\n",
                (double)R[i].thick[0][1], (double)R[i].thick[1][1], (double)c->op.fore_thick,
                (double)R[i].thick[0][0], (double)R[i].thick[1][0], (double)c->op.upper_thick);
        return;
    }
}

void eval__print_table(FILE *f, const method_run *R, int n, int markdown)
{
    if (markdown)
        fprintf(f, "| method | setting | IoU | BF 1px | BF 3px | FP px | FN px | PSNR dB | "
                   "flicker px | ms/stereo frame |\n|---|---|---|---|---|---|---|---|---|---|\n");
    else
        fprintf(f, "%-13s %-16s %7s %6s %6s %8s %8s %6s %7s %8s\n", "method", "setting", "IoU",
                "BF1", "BF3", "FP px", "FN px", "PSNR", "flicker", "ms/frame");
    for (int i = 0; i < n; i++) {
        summary s = summarise(&R[i]);
        if (markdown)
            fprintf(f, "| %s | %s | %.4f | %.3f | %.3f | %.0f | %.0f | %.2f | %.3f | %.2f |\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp,
                    s.fn, s.psnr, s.flicker, s.ms);
        else
            fprintf(f, "%-13s %-16s %7.4f %6.3f %6.3f %8.0f %8.0f %6.2f %7.3f %8.2f\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp,
                    s.fn, s.psnr, s.flicker, s.ms);
    }
}

/* DIR/<group>.dat: one block per method (gnuplot index), x y columns,
 * sorted by x; the method at the given tracking (group "track") is the
 * point at the given value of a tracking curve, the default refine (group
 * "knobs") the default band's point. */
static int write_group(const char *dir, const char *group, const method_run *R, int n,
                       const eval_opts *o)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/%s.dat", dir, group);
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    for (int k = 0; k < 4; k++) {
        fprintf(f, "# %s\n", kind_name[k]);
        float xs[64];
        int idx[64], m = 0;
        for (int i = 0; i < n && m < 64; i++) {
            const method_cfg *c = &R[i].cfg;
            if ((int)c->kind != k) continue;
            float x;
            if (!strcmp(c->group, group)) x = c->x;
            else if (!strcmp(c->group, "track") && !strcmp(group, "noise")) x = o->noise;
            else if (!strcmp(c->group, "track") && !strcmp(group, "latency")) x = o->latency;
            else if (!strcmp(c->group, "track") && !strcmp(group, "calib") && k != M_KIN)
                x = 100.0f * o->calib_error;
            else if (!strcmp(c->group, "knobs") && !strcmp(group, "band") && k == M_REFINE)
                x = (float)o->band;
            else continue;
            int j = m++;
            while (j > 0 && xs[j - 1] > x) { xs[j] = xs[j - 1]; idx[j] = idx[j - 1]; j--; }
            xs[j] = x;
            idx[j] = i;
        }
        for (int j = 0; j < m; j++) {
            summary s = summarise(&R[idx[j]]);
            fprintf(f, "%g %.5f %.5f %.3f %.3f\n", (double)xs[j], s.iou, s.bf3, s.ms, s.psnr);
        }
        if (!m) fprintf(f, "nan nan nan nan nan\n");
        fprintf(f, "\n\n");
    }
    return out_commit(&of);
}

/* DIR/sequences.dat: per sequence, IoU then BF(3 px) of the four methods. */
static int write_sequences(const char *dir, const method_run *R, int n, const eval_opts *o)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/sequences.dat", dir);
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f, "# sequence iou(kin kin-cal-pred skin refine) bf3(same)\n");
    for (int q = 0; gt_sequence_name(q); q++) {
        const char *name = gt_sequence_name(q);
        char want[64];
        snprintf(want, sizeof want, "seq=%s", name);
        double iou[4], bf3[4];
        int any = 0;
        for (int k = 0; k < 4; k++) {
            iou[k] = bf3[k] = NAN;
            for (int i = 0; i < n; i++) {
                const method_cfg *c = &R[i].cfg;
                if ((int)c->kind != k) continue;
                int hit = !strcmp(name, o->sequence) ? !strcmp(c->group, "methods")
                                                     : !strcmp(c->setting, want);
                if (!hit) continue;
                summary s = summarise(&R[i]);
                iou[k] = s.iou;
                bf3[k] = s.bf3;
                any = 1;
            }
        }
        if (!any) continue;
        fprintf(f, "%s", name);
        for (int k = 0; k < 4; k++) fprintf(f, " %.5f", iou[k]);
        for (int k = 0; k < 4; k++) fprintf(f, " %.5f", bf3[k]);
        fprintf(f, "\n");
    }
    return out_commit(&of);
}

/* Runs gnuplot on DIR/charts.gp with its outputs named "<chart>.tmp.<pid>",
 * then checks each chart decodes whole before giving it its name: gnuplot
 * does not report a failed write, so a full disk would leave truncated
 * charts. gnuplot missing or failing: a warning (the data is written);
 * a chart written incomplete: removed, an error. */
static int write_charts(const char *dir)
{
    static const char *const charts[] = {"speed_iou", "speed_bf", "noise", "latency",
                                         "calib", "band", "sequences", "lod"};
    enum { NCHART = sizeof charts / sizeof charts[0] };
    char cmd[3 * IO_PATH_MAX], tmp[IO_PATH_MAX + 96], path[IO_PATH_MAX + 64];
    long pid = (long)getpid();
    snprintf(cmd, sizeof cmd, "gnuplot -e \"sfx='.tmp.%ld'\" '%s/charts.gp'", pid, dir);
    int rc = system(cmd);
    int bad = 0;
    for (int i = 0; i < NCHART; i++) {
        snprintf(path, sizeof path, "%s/%s.png", dir, charts[i]);
        snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, pid);
        if (rc != 0) {
            remove(tmp);
            continue;
        }
        io_image img;
        io_error err;
        if (io_image_load(tmp, IO_U8, 0, &img, &err) != IO_OK) {
            remove(tmp);
            if (!bad) fprintf(stderr, "egofuse: %s: gnuplot wrote it incomplete or not at all "
                              "(%s); removed\n", path, err.msg);
            bad = 1;
            continue;
        }
        io_image_free(&img);
        if (rename(tmp, path) != 0) {
            fprintf(stderr, "egofuse: %s: cannot name it (rename from %s): %s\n", path, tmp,
                    strerror(errno));
            remove(tmp);
            bad = 1;
        }
    }
    if (rc != 0)
        fprintf(stderr, "egofuse eval: gnuplot failed (status %d): the data files and "
                        "%s/charts.gp are written, the PNG charts are not\n", rc, dir);
    return bad ? EXIT_FAIL : EXIT_OK;
}

int eval__write_report(const char *dir, const method_run *R, int n, const eval_opts *o,
                       const eval_ctx *c)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/summary.csv", dir);
    if (eval__write_csv(path, R, n)) return EXIT_FAIL;
    snprintf(path, sizeof path, "%s/table.md", dir);
    io_out of;
    FILE *f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f, "Ground truth: sequence %s, tracking noise %g mm, latency %g ms, dropout %g, "
               "calibration error %g, speed %g, seed %d. Frames: %d for the methods (group "
               "methods), %d for the speed knobs (groups knobs, band, fit, global, lagcomp, "
               "res, aa, tris, dqs) and the tracking sweeps (groups track, noise, latency, calib), "
               "%d per other sequence (group sequence).\n\n",
            o->sequence, (double)o->noise, (double)o->latency, (double)o->dropout,
            (double)o->calib_error, (double)o->speed, o->seed, o->frames, o->sweep_frames,
            o->seq_frames);
    eval__print_calib(f, c);
    eval__print_thickness(f, c, R, n);
    fprintf(f, "\n");
    eval__print_table(f, R, n, 1);
    if (out_commit(&of)) return EXIT_FAIL;
    /* speed-accuracy points: label, ms, iou, bf3 */
    snprintf(path, sizeof path, "%s/speed.dat", dir);
    f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    for (int k = 0; k < 4; k++) {
        fprintf(f, "# %s\n", kind_name[k]);
        for (int i = 0; i < n; i++) {
            const method_cfg *cf = &R[i].cfg;
            if ((int)cf->kind != k) continue;
            if (strcmp(cf->group, "knobs") && strcmp(cf->group, "band") &&
                strcmp(cf->group, "res") && strcmp(cf->group, "tris") &&
                strcmp(cf->group, "dqs") && strcmp(cf->group, "fit") && strcmp(cf->group, "aa") &&
                strcmp(cf->group, "global") && strcmp(cf->group, "lagcomp"))
                continue;
            summary s = summarise(&R[i]);
            fprintf(f, "%.3f %.5f %.5f \"%s\"\n", s.ms, s.iou, s.bf3, cf->setting);
        }
        fprintf(f, "\n\n");
    }
    if (out_commit(&of)) return EXIT_FAIL;
    static const char *groups[] = { "noise", "latency", "calib", "band" };
    for (int g = 0; g < 4; g++)
        if (write_group(dir, groups[g], R, n, o)) return EXIT_FAIL;
    if (write_sequences(dir, R, n, o)) return EXIT_FAIL;
    if (eval__write_lod(dir, R, n)) return EXIT_FAIL;
    snprintf(path, sizeof path, "%s/charts.gp", dir);
    f = out_open(&of, path);
    if (!f) return EXIT_FAIL;
    fprintf(f,
        "if (!exists('sfx')) sfx = ''\n"
        "set terminal pngcairo noenhanced size 900,600 font ',10'\n"
        "set grid\nset key bottom right\n"
        "titles = 'kin kin-cal-pred skin refine'\n"
        "set output '%s/speed_iou.png'.sfx\n"
        "set title 'Speed against accuracy: mask IoU (labels: setting)'\n"
        "set xlabel 'ms per stereo frame (pose, skin, raster, refine, light, composite; 1 thread)'\n"
        "set ylabel 'mask IoU'\nset logscale x\n"
        "plot for [i=0:3] '%s/speed.dat' index i using 1:2 with points pt 7 ps 1.3 title word(titles, i+1), \\\n"
        "     for [i=0:3] '%s/speed.dat' index i using 1:2:4 with labels offset 0,0.8 font ',7' notitle\n"
        "set output '%s/speed_bf.png'.sfx\n"
        "set title 'Speed against accuracy: boundary F-score within 3 px'\n"
        "set ylabel 'BF (3 px)'\n"
        "plot for [i=0:3] '%s/speed.dat' index i using 1:3 with points pt 7 ps 1.3 title word(titles, i+1), \\\n"
        "     for [i=0:3] '%s/speed.dat' index i using 1:3:4 with labels offset 0,0.8 font ',7' notitle\n"
        "unset logscale x\n"
        "set output '%s/noise.png'.sfx\nset title 'Accuracy against tracking noise (latency %g ms)'\n"
        "set xlabel 'RMS position noise, mm'\nset ylabel 'mask IoU'\n"
        "plot for [i=0:3] '%s/noise.dat' index i using 1:2 with linespoints lw 2 title word(titles, i+1)\n"
        "set output '%s/latency.png'.sfx\nset title 'Accuracy against tracking latency (noise %g mm)'\n"
        "set xlabel 'latency, ms'\n"
        "plot for [i=0:3] '%s/latency.dat' index i using 1:2 with linespoints lw 2 title word(titles, i+1)\n"
        "set output '%s/calib.png'.sfx\nset title 'Accuracy against calibration error (on top of the estimate)'\n"
        "set xlabel 'error of the arm, hand and shoulder scales, %%'\n"
        "plot for [i=0:3] '%s/calib.dat' index i using 1:2 with linespoints lw 2 title word(titles, i+1)\n"
        "set output '%s/band.png'.sfx\nset title 'Refinement band width'\n"
        "set xlabel 'band half width, px'\nset ylabel 'IoU, BF(3 px)'\n"
        "plot '%s/band.dat' index 3 using 1:2 with linespoints lw 2 title 'IoU', \\\n"
        "     '%s/band.dat' index 3 using 1:3 with linespoints lw 2 title 'BF 3px'\n"
        "set key bottom right\n"
        "set terminal pngcairo noenhanced size 1400,600 font ',10'\n"
        "set output '%s/lod.png'.sfx\n"
        "set multiplot layout 1,2 title 'Levels of detail of the mask model (labels: level, "
        "or the rule at a target in px)'\n"
        "set title 'Mask accuracy against the triangles drawn'\n"
        "set xlabel 'triangles drawn per eye (mean)'\nset ylabel 'IoU'\nset logscale x\n"
        "plot '%s/lod.dat' index 0 using 1:3 with points pt 7 ps 1.3 title 'kin-cal-pred: kinematic mask vs the full model', \\\n"
        "     '%s/lod.dat' index 0 using 1:4 with points pt 5 ps 1.3 title 'kin-cal-pred: vs the ground truth', \\\n"
        "     '%s/lod.dat' index 1 using 1:4 with points pt 9 ps 1.3 title 'refine: vs the ground truth', \\\n"
        "     '%s/lod.dat' index 0 using 1:3:7 with labels offset 0,0.8 font ',7' notitle\n"
        "set title 'Raster time against the triangles drawn'\n"
        "set ylabel 'raster ms per eye (transforms + draw, thread CPU time)'\n"
        "plot '%s/lod.dat' index 0 using 1:2 with points pt 7 ps 1.3 title 'kin-cal-pred', \\\n"
        "     '%s/lod.dat' index 1 using 1:2 with points pt 9 ps 1.3 title 'refine', \\\n"
        "     '%s/lod.dat' index 0 using 1:2:7 with labels offset 0,0.8 font ',7' notitle\n"
        "unset multiplot\nunset logscale x\n"
        "set terminal pngcairo noenhanced size 900,600 font ',10'\n"
        "set output '%s/sequences.png'.sfx\nset title 'Mask IoU per sequence and method'\n"
        "set style data histograms\nset style histogram clustered gap 1\n"
        "set style fill solid 0.8 border -1\nset yrange [0:1.15]\nset key top center horizontal\n"
        "set xlabel 'sequence'\nset ylabel 'mask IoU'\n"
        "plot '%s/sequences.dat' using 2:xtic(1) title 'kin', '' using 3 title 'kin-cal-pred', "
        "'' using 4 title 'skin', '' using 5 title 'refine'\n",
        dir, dir, dir, dir, dir, dir, dir, (double)o->latency, dir, dir, (double)o->noise, dir,
        dir, dir, dir, dir, dir, dir, dir, dir, dir, dir, dir, dir, dir, dir, dir);
    if (out_commit(&of)) return EXIT_FAIL;
    return write_charts(dir);
}

