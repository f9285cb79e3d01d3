/* eval_report.c - the evaluation's tables (stdout, table.md), summary.csv,
 * the per-group and per-sequence data files and the gnuplot charts of the
 * report folder (see eval.h, docs/accuracy.md). */
#include "eval_internal.h"
#include "../io/io.h"
#include "../io/io_term.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---------------------------------------------------------- reporting */

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

int eval__write_csv(const char *path, const method_run *R, int n)
{
    io_out of;
    FILE *f = eval__out_open(&of, NULL, "%s", path);
    if (!f) return IO_EXIT_FAIL;
    fprintf(f, "method,setting,iou,bf1,bf3,fp_area,fn_area,psnr,ms_per_frame,flicker,group\n");
    for (int i = 0; i < n; i++) {
        eval_summary s = eval__summarise(&R[i]);
        fprintf(f, "%s,%s,%.5f,%.5f,%.5f,%.1f,%.1f,%.3f,%.3f,%.4f,%s\n",
                kind_name[R[i].cfg.kind], R[i].cfg.setting, s.iou, s.bf1, s.bf3, s.fp, s.fn,
                s.psnr, s.ms, s.flicker, R[i].cfg.group);
    }
    return eval__out_commit(&of);
}

void eval__print_error_area(FILE *f, const method_run *R, int n)
{
    for (int i = 0; i < n; i++) {
        if (R[i].n_err < 1) continue;
        fprintf(f, "%-13s %-9s %-16s error area per eye and frame (FP + FN px): mean %.0f, p95 "
                   "%.0f, max %.0f; pooled IoU %.4f\n",
                kind_name[R[i].cfg.kind], R[i].cfg.group, R[i].cfg.setting, R[i].err_mean,
                R[i].err_p95, R[i].err_max,
                R[i].union_sum > 0.0 ? R[i].tp_sum / R[i].union_sum : 1.0);
    }
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
        if (R[i].cfg.band_auto && R[i].n_band > 0)
            fprintf(f, "refine's band from the projected uncertainty: mean %.1f px\n",
                    R[i].band_sum / (double)R[i].n_band);
        if (R[i].cfg.stereo && R[i].n_band > 0)
            fprintf(f, "refine's stereo depth test (fit_stereo.h): per eye and frame %.0f "
                       "patches compared, %.0f px cleared, %.0f px added\n",
                    (double)R[i].stereo_tested / (double)R[i].n_band,
                    (double)R[i].stereo_cleared / (double)R[i].n_band,
                    (double)R[i].stereo_added / (double)R[i].n_band);
        return;
    }
}

void eval__print_table(FILE *f, const method_run *R, int n, int markdown)
{
    if (markdown)
        fprintf(f, "| method | group | setting | IoU | BF 1px | BF 3px | FP px | FN px | PSNR dB | "
                   "flicker px | ms/stereo frame | CPU ms |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    else
        fprintf(f, "%-13s %-9s %-16s %7s %6s %6s %8s %8s %6s %7s %8s %7s\n", "method", "group",
                "setting", "IoU", "BF1", "BF3", "FP px", "FN px", "PSNR", "flicker", "ms/frame",
                "CPU ms");
    for (int i = 0; i < n; i++) {
        /* the lighting and Fresnel sweeps have tables of their own
         * (light.md, kf.md: eval_light.c, eval_kf.c) */
        if (markdown && (!strcmp(R[i].cfg.group, "light") || !strcmp(R[i].cfg.group, "kf")))
            continue;
        eval_summary s = eval__summarise(&R[i]);
        /* the method's own thread's CPU time (ms/frame is the wall clock,
         * which a shared machine inflates) */
        const double cpu_ms = 1e3 * R[i].cpu_secs / (R[i].n_frames > 0 ? (double)R[i].n_frames : 1.0);
        if (markdown)
            fprintf(f, "| %s | %s | %s | %.4f | %.3f | %.3f | %.0f | %.0f | %.2f | %.3f | %.2f | %.2f |\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.group, R[i].cfg.setting, s.iou, s.bf1,
                    s.bf3, s.fp, s.fn, s.psnr, s.flicker, s.ms, cpu_ms);
        else
            fprintf(f, "%-13s %-9s %-16s %7.4f %6.3f %6.3f %8.0f %8.0f %6.2f %7.3f %8.2f %7.2f\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.group, R[i].cfg.setting, s.iou, s.bf1,
                    s.bf3, s.fp, s.fn, s.psnr, s.flicker, s.ms, cpu_ms);
    }
}

/* DIR/<group>.dat: one block per method (gnuplot index), x y columns,
 * sorted by x; the method at the given tracking (group "track") is the
 * point at the given value of a tracking curve, the default refine (group
 * "knobs") the default band's point. */
/* Per method of a sweep chart: whether it has points, the swept range,
 * and every value where its IoU crosses 0.9 (linear between the points),
 * with the side it starts on: the ranges at or above 0.9 follow. */
enum { SW_MAXX = 16 };
typedef struct sweep_info {
    int has[4];
    double x0[4], x1[4];          /* the first and last swept value */
    int start_ok[4];              /* IoU >= 0.9 at x0 */
    int ncross[4];
    double cross[4][SW_MAXX];     /* ascending */
} sweep_info;

static int write_group(const char *dir, const char *group, const method_run *R, int n,
                       const eval_opts *o, sweep_info *si)
{
    memset(si, 0, sizeof *si);
    io_out of;
    FILE *f = eval__out_open(&of, dir, "%s.dat", group);
    if (!f) return IO_EXIT_FAIL;
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
            else if (!strcmp(c->group, "track") && !strcmp(group, "dropout"))
                x = 100.0f * o->dropout;
            else if (!strcmp(c->group, "track") && !strcmp(group, "handspeed")) x = o->speed;
            else continue;
            int j = m++;
            while (j > 0 && xs[j - 1] > x) { xs[j] = xs[j - 1]; idx[j] = idx[j - 1]; j--; }
            xs[j] = x;
            idx[j] = i;
        }
        si->has[k] = m > 0;
        double px = 0.0, piou = 0.0;
        for (int j = 0; j < m; j++) {
            eval_summary s = eval__summarise(&R[idx[j]]);
            fprintf(f, "%g %.5f %.5f %.3f %.3f\n", (double)xs[j], s.iou, s.bf3, s.ms, s.psnr);
            if (j == 0) {
                si->x0[k] = (double)xs[j];
                si->start_ok[k] = s.iou >= 0.9;
            } else if ((s.iou >= 0.9) != (piou >= 0.9) && si->ncross[k] < SW_MAXX) {
                si->cross[k][si->ncross[k]++] =
                    px + (0.9 - piou) * ((double)xs[j] - px) / (s.iou - piou);
            }
            si->x1[k] = (double)xs[j];
            px = (double)xs[j];
            piou = s.iou;
        }
        if (!m) fprintf(f, "nan nan nan nan nan\n");
        fprintf(f, "\n\n");
    }
    return eval__out_commit(&of);
}

/* DIR/sequences.dat: per sequence, IoU then BF(3 px) of the four methods. */
static int write_sequences(const char *dir, const method_run *R, int n, const eval_opts *o,
                           int has[4])
{
    memset(has, 0, 4 * sizeof has[0]);
    io_out of;
    FILE *f = eval__out_open(&of, dir, "sequences.dat");
    if (!f) return IO_EXIT_FAIL;
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
                eval_summary s = eval__summarise(&R[i]);
                iou[k] = s.iou;
                bf3[k] = s.bf3;
                any = has[k] = 1;
            }
        }
        if (!any) continue;
        fprintf(f, "%s", name);
        for (int k = 0; k < 4; k++) fprintf(f, " %.5f", iou[k]);
        for (int k = 0; k < 4; k++) fprintf(f, " %.5f", bf3[k]);
        fprintf(f, "\n");
    }
    return eval__out_commit(&of);
}

/* Runs gnuplot on DIR/charts.gp with its outputs named "<chart>.tmp.<pid>",
 * then checks each chart decodes whole before giving it its name: gnuplot
 * does not report a failed write, so a full disk would leave truncated
 * charts. gnuplot missing or failing: a warning (the data is written);
 * a chart written incomplete: removed, an error. */
static int write_charts(const char *dir)
{
    static const char *const charts[] = {"speed_iou", "speed_bf", "noise",  "latency",
                                         "calib",     "dropout",  "handspeed", "band",
                                         "sequences", "lod"};
    return eval__gnuplot(dir, "charts.gp", charts, (int)(sizeof charts / sizeof charts[0]));
}

int eval__gnuplot(const char *dir, const char *script, const char *const *charts, int NCHART)
{
    char cmd[3 * IO_PATH_MAX], tmp[IO_PATH_MAX + 96], path[IO_PATH_MAX + 64];
    long pid = (long)getpid();
    snprintf(cmd, sizeof cmd, "gnuplot -e \"sfx='.tmp.%ld'\" '%s/%s'", pid, dir, script);
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
                        "%s/%s are written, the charts (%s/%s.png and %d more) are not\n", rc,
                dir, script, dir, charts[0], NCHART - 1);
    return bad ? IO_EXIT_FAIL : IO_EXIT_OK;
}

/* A chart with no points (none of --methods runs it): gnuplot fails on a
 * plot whose every point is undefined and then draws no chart at all, so
 * the chart gets fixed ranges, a note and an empty plot. */
static void empty_plot(FILE *f, const char *what)
{
    fprintf(f, "set xrange [0:1]\nset yrange [0:1]\nset key off\nset label 98 'no points: "
               "%s' at graph 0.5, graph 0.5 center\nplot NaN notitle\nunset label 98\n"
               "set key on\nset autoscale\n", what);
}

/* ---- the speed-accuracy charts: labels that do not overlap ----------
 *
 * The chart's geometry is fixed here (size, margins, ranges), so every
 * point's pixel position is known: each label goes to the first of a list
 * of places around its point (right, left, above, below, then farther up
 * and down with a thin leader line) where its box overlaps no label
 * placed before and no point; failing all, to the right. Text boxes are
 * estimated at 8.4 px per character and 16 px high (font size 10). */
enum { SPW = 900, SPH = 640 };
#define SP_L 0.08
#define SP_R 0.97
#define SP_B 0.10
#define SP_T 0.92

typedef struct sp_pt { double x, y; int kind; const char *label; } sp_pt;

static void sp_to_px(double x, double y, const double rg[4], double *px, double *py)
{
    const double pw = (SP_R - SP_L) * SPW, ph = (SP_T - SP_B) * SPH;
    *px = SP_L * SPW + (log10(x) - log10(rg[0])) / (log10(rg[1]) - log10(rg[0])) * pw;
    *py = (1.0 - SP_B) * SPH - (y - rg[2]) / (rg[3] - rg[2]) * ph;   /* down */
}

static void sp_from_px(double px, double py, const double rg[4], double *x, double *y)
{
    const double pw = (SP_R - SP_L) * SPW, ph = (SP_T - SP_B) * SPH;
    *x = pow(10.0, log10(rg[0]) + (px - SP_L * SPW) / pw * (log10(rg[1]) - log10(rg[0])));
    *y = rg[2] + ((1.0 - SP_B) * SPH - py) / ph * (rg[3] - rg[2]);
}

static int box_hit(const double a[4], const double b[4])
{
    return a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
}

/* "set label" (and "set arrow") lines for the points p[0..np). */
static void sp_labels(FILE *f, const sp_pt *p, int np, const double rg[4])
{
    static const double cand[][2] = {{10, 0}, {-10, 0}, {0, -15}, {0, 15}, {10, -14}, {10, 14},
                                     {-10, -14}, {-10, 14}, {0, -30}, {0, 30}, {30, -22},
                                     {30, 20}, {-30, -20}, {-30, 20}, {0, -44}, {0, 44},
                                     {50, 0}, {-50, 0}, {40, -36}, {40, 36}, {-40, -36},
                                     {-40, 36}, {0, -60}, {0, 60}, {60, -60}, {60, 60},
                                     {-60, -60}, {-60, 60}, {0, -80}, {0, 80}, {90, -40},
                                     {90, 40}, {-90, -40}, {-90, 40}, {80, -85}, {80, 85},
                                     {-80, -85}, {-80, 85}, {0, -105}, {0, 105}};
    enum { NC = sizeof cand / sizeof cand[0] };
    double (*placed)[4] = malloc(sizeof *placed * (size_t)(np > 0 ? np : 1));
    if (!placed) return;
    int nplaced = 0;
    for (int i = 0; i < np; i++) {
        double px, py;
        sp_to_px(p[i].x, p[i].y, rg, &px, &py);
        const double w = 8.4 * (double)strlen(p[i].label) + 6.0, h = 16.0;
        int best = 0;
        double bx[4] = {0, 0, 0, 0};
        for (int c = 0; c < NC; c++) {
            const double dx = cand[c][0], dy = cand[c][1];
            /* anchored left of the box when dx >= 0, right when dx < 0 */
            const double x0 = dx > 0 ? px + dx : dx < 0 ? px + dx - w : px - w / 2;
            double b[4] = {x0, py + dy - h / 2, x0 + w, py + dy + h / 2};
            int ok = b[0] >= SP_L * SPW && b[2] <= SP_R * SPW && b[1] >= (1.0 - SP_T) * SPH &&
                     b[3] <= (1.0 - SP_B) * SPH;
            for (int j = 0; ok && j < nplaced; j++) ok = !box_hit(b, placed[j]);
            for (int j = 0; ok && j < np; j++) {
                double qx, qy;
                sp_to_px(p[j].x, p[j].y, rg, &qx, &qy);
                const double pb[4] = {qx - 7, qy - 7, qx + 7, qy + 7};
                ok = !box_hit(b, pb);
            }
            if (ok) {
                best = c;
                memcpy(bx, b, sizeof bx);
                break;
            }
            if (c == NC - 1) {
                best = 0;
                const double b0[4] = {px + 9, py - h / 2, px + 9 + w, py + h / 2};
                memcpy(bx, b0, sizeof bx);
            }
        }
        memcpy(placed[nplaced++], bx, sizeof bx);
        double lx, ly;
        sp_from_px(bx[0] + 2.0, (bx[1] + bx[3]) / 2, rg, &lx, &ly);
        fprintf(f, "set label %d \"%s\" at %.6g,%.6g left font ',10' tc lt %d front\n", i + 1,
                p[i].label, lx, ly, p[i].kind + 1);
        if (fabs(cand[best][0]) > 11 || fabs(cand[best][1]) > 16) {
            /* a leader from the box's nearer side to the point */
            const double ex = cand[best][0] >= 0 ? bx[0] : bx[2], ey = (bx[1] + bx[3]) / 2;
            double ax, ay;
            sp_from_px(ex, ey, rg, &ax, &ay);
            fprintf(f, "set arrow %d from %.6g,%.6g to %.6g,%.6g nohead lw 0.5 lc rgb '#909090' "
                       "back\n", i + 1, ax, ay, p[i].x, p[i].y);
        }
    }
    free(placed);
}

/* One speed chart (ycol: 2 IoU, 3 BF) with its labels. */
static void sp_chart(FILE *f, const char *dir, const char *name, const char *title,
                     const char *ylabel, int ycol, const sp_pt *p, int np)
{
    double rg[4] = {1e30, -1e30, 1e30, -1e30};
    for (int i = 0; i < np; i++) {
        if (p[i].x < rg[0]) rg[0] = p[i].x;
        if (p[i].x > rg[1]) rg[1] = p[i].x;
        if (p[i].y < rg[2]) rg[2] = p[i].y;
        if (p[i].y > rg[3]) rg[3] = p[i].y;
    }
    if (np == 0 || !(rg[0] > 0.0)) {
        rg[0] = 1.0, rg[1] = 10.0, rg[2] = 0.0, rg[3] = 1.0;
    }
    rg[0] /= 1.35;
    rg[1] *= 1.6;
    const double span = rg[3] - rg[2] > 0.05 ? rg[3] - rg[2] : 0.05;
    rg[2] -= 0.06 * span;
    rg[3] += 0.08 * span;
    fprintf(f, "set terminal pngcairo noenhanced size %d,%d font ',11'\n", SPW, SPH);
    fprintf(f, "set lmargin at screen %.2f\nset rmargin at screen %.2f\n"
               "set bmargin at screen %.2f\nset tmargin at screen %.2f\n",
            SP_L, SP_R, SP_B, SP_T);
    fprintf(f, "set logscale x\nset xrange [%.6g:%.6g]\nset yrange [%.6g:%.6g]\n", rg[0], rg[1],
            rg[2], rg[3]);
    fprintf(f, "set output '%s/%s.png'.sfx\nset title '%s'\nset ylabel '%s'\n", dir, name, title,
            ylabel);
    fprintf(f, "set xlabel 'CPU ms per stereo frame (pose, skin, raster, refine, light, "
               "composite; 1 thread)'\nset key bottom right box opaque\n");
    /* a log axis has tics at the decades only: 1, 2, 5 x 10^k in range */
    char tics[512];
    size_t tu = 0;
    for (double d = 0.1; d < 1e5; d *= 10.0)
        for (int m = 0; m < 3; m++) {
            const double v = d * (m == 0 ? 1.0 : m == 1 ? 2.0 : 5.0);
            if (v < rg[0] || v > rg[1] || tu >= sizeof tics - 40) continue;
            tu += (size_t)snprintf(tics + tu, sizeof tics - tu, "%s'%g' %g", tu ? ", " : "", v,
                                   v);
        }
    if (tu) fprintf(f, "set xtics (%s)\n", tics);
    sp_labels(f, p, np, rg);
    /* the kinds with points only: an empty block would be a legend entry
     * with no point, and all empty a failed plot */
    int first = 1;
    for (int k = 0; k < 4; k++) {
        int has = 0;
        for (int i = 0; i < np && !has; i++) has = p[i].kind == k;
        if (!has) continue;
        fprintf(f, "%s'%s/speed.dat' index %d using 1:%d with points pt 7 ps 1.4 lc %d "
                   "title word(titles, %d)", first ? "plot " : ", \\\n     ", dir, k, ycol,
                k + 1, k + 1);
        first = 0;
    }
    fprintf(f, "%s\n", first ? "plot NaN notitle" : "");
    fprintf(f, "unset label\nunset arrow\nunset logscale x\nset autoscale\nset xtics autofreq\n"
               "set lmargin\nset rmargin\nset bmargin\nset tmargin\n");
}

/* "%.3g" with a sign when the axis is signed (calibration error) */
static void sw_num(char *b, size_t n, double v, int sign)
{
    snprintf(b, n, sign && v > 0.0 ? "+%.3g" : "%.3g", v);
}

/* The legend text of method k of a sweep: where its IoU is at or above
 * 0.9, e.g. "kin-cal-pred: IoU >= 0.9 up to 12.4 mm", "refine: IoU >= 0.9
 * throughout", "kin: IoU < 0.9 throughout", "... >= 0.9 from +1.6 to +7.3 %". */
static void sw_title(char *t, size_t n, const char *name, const sweep_info *si, int k,
                     const char *unit, int sign)
{
    const int nc = si->ncross[k];
    if (nc == 0) {
        snprintf(t, n, "%s: IoU %s 0.9 throughout", name, si->start_ok[k] ? ">=" : "<");
        return;
    }
    size_t u = (size_t)snprintf(t, n, "%s: IoU >= 0.9", name);
    /* the ranges at or above: [x0 or a crossing, the next crossing or x1] */
    int ok = si->start_ok[k], first = 1;
    double from = si->x0[k];
    for (int c = 0; c <= nc && u < n; c++) {
        const double at = c < nc ? si->cross[k][c] : si->x1[k];
        if (ok) {
            char a[32], b[32];
            sw_num(a, sizeof a, from, sign);
            sw_num(b, sizeof b, at, sign);
            if (from == si->x0[k] && c < nc)
                u += (size_t)snprintf(t + u, n - u, "%s up to %s", first ? "" : ",", b);
            else if (c == nc)
                u += (size_t)snprintf(t + u, n - u, "%s from %s", first ? "" : ",", a);
            else
                u += (size_t)snprintf(t + u, n - u, "%s from %s to %s", first ? "" : ",", a, b);
            first = 0;
        }
        from = at;
        ok = !ok;
    }
    if (u < n) snprintf(t + u, n - u, " %s", unit);
}

/* A sweep chart of the methods that have points, with the IoU 0.9 line,
 * a circle where each method's IoU crosses it, and the ranges at or above
 * 0.9 in the legend, which sits below the plot and its axis label (it
 * never hides a point; gnuplot's own "key below" overlaps the label). */
static void sweep_chart(FILE *f, const char *dir, const char *group, const char *title,
                        const char *xlabel, const char *unit, const sweep_info *si)
{
    static const char *const tn[4] = {"kin", "kin-cal-pred", "skin", "refine"};
    const int sign = !strcmp(group, "calib");
    fprintf(f, "set terminal pngcairo noenhanced size 900,600 font ',12'\n");
    fprintf(f, "set output '%s/%s.png'.sfx\nset title '%s'\nset xlabel '%s'\n"
               "set ylabel 'mask IoU'\nset bmargin 8\n"
               "set key at screen 0.5, screen 0.012 center bottom vertical Left reverse box\n",
            dir, group, title, xlabel);
    int obj = 1;
    for (int k = 0; k < 4; k++) {
        if (!si->has[k]) continue;
        for (int c = 0; c < si->ncross[k]; c++)
            fprintf(f, "set object %d circle at first %.6g, first 0.9 size screen 0.012 front "
                       "fs empty border lc lt %d lw 2\n", obj++, si->cross[k][c], k + 1);
    }
    fprintf(f, "set arrow 90 from graph 0, first 0.9 to graph 1, first 0.9 nohead dt 2 "
               "lc rgb '#808080'\n");
    int first = 1;
    for (int k = 0; k < 4; k++) {
        if (!si->has[k]) continue;
        char t[200];
        sw_title(t, sizeof t, tn[k], si, k, unit, sign);
        fprintf(f, "%s'%s/%s.dat' index %d using 1:2 with linespoints lw 2 pt 7 lc %d title '%s'",
                first ? "plot " : ", \\\n     ", dir, group, k, k + 1, t);
        first = 0;
    }
    fprintf(f, "\n");
    if (first) empty_plot(f, "no method of --methods runs this sweep");
    fprintf(f, "unset label\nunset arrow\nunset object\nset key default\nset bmargin\n");
}

int eval__write_report(const char *dir, const method_run *R, int n, const eval_opts *o,
                       const eval_ctx *c)
{
    char path[IO_PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/summary.csv", dir);
    if (eval__write_csv(path, R, n)) return IO_EXIT_FAIL;
    io_out of;
    FILE *f = eval__out_open(&of, dir, "table.md");
    if (!f) return IO_EXIT_FAIL;
    fprintf(f, "Ground truth: sequence %s, tracking noise %g mm, latency %g ms, dropout %g, "
               "calibration error %g, speed %g, seed %d. Frames: %d for the methods (group "
               "methods), %d for the speed knobs (groups knobs, band, fit, global, lagcomp, "
               "res, aa, tris, dqs) and the tracking sweeps (groups track, noise, latency, calib), "
               "%d per other sequence (group sequence). The lighting-mismatch and Fresnel sweeps "
               "(groups light, kf; summary.csv) have their tables in light.md and kf.md.\n\n",
            o->sequence, (double)o->noise, (double)o->latency, (double)o->dropout,
            (double)o->calib_error, (double)o->speed, o->seed, o->frames, o->sweep_frames,
            o->seq_frames);
    eval__print_calib(f, c);
    eval__print_thickness(f, c, R, n);
    fprintf(f, "\n");
    eval__print_table(f, R, n, 1);
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    /* speed-accuracy points: label, ms, iou, bf3 */
    f = eval__out_open(&of, dir, "speed.dat");
    if (!f) return IO_EXIT_FAIL;
    sp_pt *piou = malloc(sizeof *piou * (size_t)(n > 0 ? n : 1));
    sp_pt *pbf = malloc(sizeof *pbf * (size_t)(n > 0 ? n : 1));
    int np = 0;
    if (!piou || !pbf) {
        free(piou);
        free(pbf);
        io_out_abort(&of);
        return io_term_fail("out of memory");
    }
    for (int k = 0; k < 4; k++) {
        fprintf(f, "# %s\n", kind_name[k]);
        const int np0 = np;
        for (int i = 0; i < n; i++) {
            const method_cfg *cf = &R[i].cfg;
            if ((int)cf->kind != k) continue;
            if (strcmp(cf->group, "knobs") && strcmp(cf->group, "band") &&
                strcmp(cf->group, "res") && strcmp(cf->group, "tris") &&
                strcmp(cf->group, "dqs") && strcmp(cf->group, "fit") && strcmp(cf->group, "aa") &&
                strcmp(cf->group, "global") && strcmp(cf->group, "lagcomp"))
                continue;
            eval_summary s = eval__summarise(&R[i]);
            /* the method's own thread's CPU time: the wall clock of a
             * batch of knobs run side by side on a shared machine is
             * 2-3x the CPU time and moves with the load */
            const double cpu_ms =
                1e3 * R[i].cpu_secs / (R[i].n_frames > 0 ? (double)R[i].n_frames : 1.0);
            fprintf(f, "%.3f %.5f %.5f \"%s\"\n", cpu_ms, s.iou, s.bf3, cf->setting);
            piou[np] = (sp_pt){cpu_ms, s.iou, k, cf->setting};
            pbf[np++] = (sp_pt){cpu_ms, s.bf3, k, cf->setting};
        }
        /* an empty block is no gnuplot index: the next kind's would
         * take its number */
        if (np == np0) fprintf(f, "nan nan nan \"\"\n");
        fprintf(f, "\n\n");
    }
    if (eval__out_commit(&of)) {
        free(piou);
        free(pbf);
        return IO_EXIT_FAIL;
    }
    static const char *groups[] = { "noise", "latency", "calib", "band", "dropout", "handspeed" };
    enum { NG = sizeof groups / sizeof groups[0] };
    sweep_info si[NG];
    for (int g = 0; g < NG; g++)
        if (write_group(dir, groups[g], R, n, o, &si[g])) {
            free(piou);
            free(pbf);
            return IO_EXIT_FAIL;
        }
    int seq_has[4];
    if (write_sequences(dir, R, n, o, seq_has) || eval__write_lod(dir, R, n)) {
        free(piou);
        free(pbf);
        return IO_EXIT_FAIL;
    }
    f = eval__out_open(&of, dir, "charts.gp");
    if (!f) {
        free(piou);
        free(pbf);
        return IO_EXIT_FAIL;
    }
    fprintf(f, "if (!exists('sfx')) sfx = ''\nset grid\n"
               "titles = 'kin kin-cal-pred skin refine'\n");
    sp_chart(f, dir, "speed_iou", "Speed against accuracy: mask IoU (labels: setting)",
             "mask IoU", 2, piou, np);
    sp_chart(f, dir, "speed_bf", "Speed against accuracy: boundary F-score within 3 px",
             "BF (3 px)", 3, pbf, np);
    free(piou);
    free(pbf);
    char t[160];
    snprintf(t, sizeof t, "Accuracy against tracking noise (latency %g ms)", (double)o->latency);
    sweep_chart(f, dir, "noise", t, "RMS position noise, mm", "mm", &si[0]);
    snprintf(t, sizeof t, "Accuracy against tracking latency (noise %g mm)", (double)o->noise);
    sweep_chart(f, dir, "latency", t, "latency, ms", "ms", &si[1]);
    sweep_chart(f, dir, "calib", "Accuracy against calibration error (on top of the estimate)",
                "error of the arm, hand and shoulder scales, %", "%", &si[2]);
    sweep_chart(f, dir, "dropout", "Accuracy against tracking dropouts (hands lost)",
                "samples that lose the hands, %", "%", &si[4]);
    sweep_chart(f, dir, "handspeed", "Accuracy against hand speed (the motion played faster)",
                "speed, x the recorded motion", "x", &si[5]);
    fprintf(f,
        "set terminal pngcairo noenhanced size 900,600 font ',11'\n"
        "set key bottom right box opaque\n"
        "set output '%s/band.png'.sfx\nset title 'Refinement band width'\n"
        "set xlabel 'band half width, px'\nset ylabel 'IoU, BF(3 px)'\n", dir);
    if (si[3].has[M_REFINE])
        fprintf(f,
            "plot '%s/band.dat' index 3 using 1:2 with linespoints lw 2 title 'IoU', \\\n"
            "     '%s/band.dat' index 3 using 1:3 with linespoints lw 2 title 'BF 3px'\n",
            dir, dir);
    else
        empty_plot(f, "refine did not run");
    /* lod.dat: index 0 kin-cal-pred, 1 refine (eval_lod.c); only the
     * methods of --methods run it */
    int lod_has[2] = {0, 0};
    for (int i = 0; i < n; i++)
        if (!strcmp(R[i].cfg.group, "lod"))
            lod_has[R[i].cfg.kind == M_REFINE] |= R[i].cfg.kind == M_KIN_CAL ||
                                                  R[i].cfg.kind == M_REFINE;
    const int lab = lod_has[0] ? 0 : 1;   /* the labels' block */
    fprintf(f,
        "set key bottom right\n"
        "set terminal pngcairo noenhanced size 1400,600 font ',12'\n"
        "set output '%s/lod.png'.sfx\n"
        "set multiplot layout 1,2 title 'Levels of detail of the mask model (labels: level, "
        "or the rule at a target in px)'\n"
        "set title 'Mask accuracy against the triangles drawn'\n"
        "set xlabel 'triangles drawn per eye (mean)'\nset ylabel 'IoU'\n", dir);
    if (!lod_has[0] && !lod_has[1]) {
        empty_plot(f, "neither kin-cal-pred nor refine ran");
    } else {
        fprintf(f, "set logscale x\nplot ");
        if (lod_has[0])
            fprintf(f, "'%s/lod.dat' index 0 using 1:3 with points pt 7 ps 1.3 title 'kin-cal-pred: kinematic mask vs the full model', \\\n"
                       "     '%s/lod.dat' index 0 using 1:4 with points pt 5 ps 1.3 title 'kin-cal-pred: vs the ground truth', \\\n     ",
                    dir, dir);
        else
            fprintf(f, "'%s/lod.dat' index 1 using 1:3 with points pt 7 ps 1.3 title 'refine: kinematic mask vs the full model', \\\n     ",
                    dir);
        if (lod_has[1])
            fprintf(f, "'%s/lod.dat' index 1 using 1:4 with points pt 9 ps 1.3 title 'refine: vs the ground truth', \\\n     ",
                    dir);
        fprintf(f, "'%s/lod.dat' index %d using 1:3:7 with labels offset 0,0.9 font ',10' notitle\n",
                dir, lab);
    }
    fprintf(f, "set title 'Raster time against the triangles drawn'\n"
               "set ylabel 'raster ms per eye (transforms + draw, thread CPU time)'\n");
    if (!lod_has[0] && !lod_has[1]) {
        empty_plot(f, "neither kin-cal-pred nor refine ran");
    } else {
        fprintf(f, "plot ");
        if (lod_has[0])
            fprintf(f, "'%s/lod.dat' index 0 using 1:2 with points pt 7 ps 1.3 title 'kin-cal-pred', \\\n     ",
                    dir);
        if (lod_has[1])
            fprintf(f, "'%s/lod.dat' index 1 using 1:2 with points pt 9 ps 1.3 title 'refine', \\\n     ",
                    dir);
        fprintf(f, "'%s/lod.dat' index %d using 1:2:7 with labels offset 0,0.9 font ',10' notitle\n",
                dir, lab);
    }
    fprintf(f,
        "unset multiplot\nunset logscale x\n"
        "set terminal pngcairo noenhanced size 900,600 font ',12'\n"
        "set output '%s/sequences.png'.sfx\nset title 'Mask IoU per sequence and method'\n"
        "set xlabel 'sequence'\nset ylabel 'mask IoU'\n", dir);
    /* the columns of the methods that ran (sequences.dat: IoU of kin,
     * kin-cal-pred, skin, refine in columns 2-5): a column of NaN fails
     * the histogram */
    int first = 1;
    for (int k = 0; k < 4; k++) {
        if (!seq_has[k]) continue;
        if (first)
            fprintf(f, "set style data histograms\nset style histogram clustered gap 1\n"
                       "set style fill solid 0.8 border -1\nset yrange [0:1.15]\n"
                       "set key top center horizontal\n"
                       "plot '%s/sequences.dat' using %d:xtic(1) lc %d title '%s'", dir,
                    k + 2, k + 1, kind_name[k]);
        else
            fprintf(f, ", '' using %d lc %d title '%s'", k + 2, k + 1, kind_name[k]);
        first = 0;
    }
    if (first) empty_plot(f, "no sequence ran");
    else fprintf(f, "\n");
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    return write_charts(dir);
}

