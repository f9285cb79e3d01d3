/* eval_light.c - the lighting-mismatch sweep of `egofuse eval` (issue 14,
 * item 4; docs/accuracy.md, "Lighting mismatch").
 *
 * The camera images show the operator's arms under the cockpit's light;
 * egofuse relights them for the virtual scene. When the cockpit's light
 * changes (brighter or darker, warmer or colder, from another direction)
 * and nothing else does, the ideal composite stays the same (the hand as
 * the virtual scene lights it, made from the camera images under the
 * cockpit's own light, as in every other batch) while the methods get the
 * images under the changed light. Three axes, each from the matched level:
 *   gain    the cockpit's lights and ambient x0.5, x0.7, x1.4, x2
 *   kelvin  tinted to 3000, 4500 or 10000 K (6500 K: no tint), the luma
 *           of the tint kept at 1, so only the colour changes
 *   roll    the lights turned 30, 60, 90 degrees about the world's forward
 *           axis (from above, as built, towards the side)
 * Methods: kin-cal-pred (geometry only: its mask does not depend on the
 * light, its composite does), skin (a fixed YCbCr key: its mask does),
 * refine (colour models learned from the images), and refine with the
 * gray-world tone matching of the pipeline (pipe_desc.tone_match 1,
 * fuse_tone_match), which scales the camera's colours by the ratio of the
 * virtual scene's mean colour to the cockpit's.
 * The chart marks where each method's IoU falls below 0.9 and where its
 * composite's PSNR falls more than LIGHT_PSNR_DROP dB below its own PSNR
 * at the matched light (IoU does not depend on the light for the
 * geometric methods; PSNR does for all). */
#include "eval_internal.h"
#include "../io/io.h"
#include "../io/io_term.h"
#include "../io/io.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define LIGHT_PSNR_DROP 1.0

static const eval_light levels[] = {
    {0, 1.0f, 6500.0f, 0.0f, 0},   /* matched: the images as rendered */
    {1, 0.5f, 6500.0f, 0.0f, 0}, {1, 0.7f, 6500.0f, 0.0f, 0},
    {1, 1.4f, 6500.0f, 0.0f, 0}, {1, 2.0f, 6500.0f, 0.0f, 0},
    {1, 1.0f, 3000.0f, 0.0f, 0}, {1, 1.0f, 4500.0f, 0.0f, 0}, {1, 1.0f, 10000.0f, 0.0f, 0},
    {1, 1.0f, 6500.0f, 30.0f, 0}, {1, 1.0f, 6500.0f, 60.0f, 0}, {1, 1.0f, 6500.0f, 90.0f, 0},
};
enum { NLEV = sizeof levels / sizeof levels[0] };

static const char *const axes[3] = {"gain", "kelvin", "roll"};

int eval__light_levels(eval_light *L, int cap)
{
    int n = 0;
    (void)kind_name;   /* eval_internal.h's, not used here */
    for (int i = 0; i < NLEV && n < cap; i++) L[n++] = levels[i];
    return n;
}

float eval__light_x(const eval_light *l, const char *axis)
{
    const int g = l->gain != 1.0f, k = l->kelvin != 6500.0f, r = l->roll_deg != 0.0f;
    if (!strcmp(axis, "gain") && !k && !r) return l->gain;
    if (!strcmp(axis, "kelvin") && !g && !r) return l->kelvin;
    if (!strcmp(axis, "roll") && !g && !k) return l->roll_deg;
    return NAN;
}

/* RGB of a black body at kelvin (Tanner Helland's fit of the CIE colour
 * matching), 0..255 per channel. */
static void blackbody(double kelvin, double rgb[3])
{
    const double t = kelvin / 100.0;
    rgb[0] = t <= 66.0 ? 255.0 : 329.698727446 * pow(t - 60.0, -0.1332047592);
    rgb[1] = t <= 66.0 ? 99.4708025861 * log(t) - 161.1195681661
                       : 288.1221695283 * pow(t - 60.0, -0.0755148492);
    rgb[2] = t >= 66.0 ? 255.0 : t <= 19.0 ? 0.0 : 138.5177312231 * log(t - 10.0) - 305.0447927307;
    for (int c = 0; c < 3; c++) rgb[c] = rgb[c] < 0.0 ? 0.0 : rgb[c] > 255.0 ? 255.0 : rgb[c];
}

/* The tint that takes 6500 K to kelvin, its luma (BT.709) 1. */
static void tint_of(float kelvin, float m[3])
{
    double a[3], b[3];
    blackbody(kelvin, a);
    blackbody(6500.0, b);
    double t[3], y;
    for (int c = 0; c < 3; c++) t[c] = a[c] / b[c];
    y = 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
    for (int c = 0; c < 3; c++) m[c] = (float)(t[c] / y);
}

int eval__light_render(eval_ctx *c, const kin_mat4 *world_from_head, int e, int frame)
{
    gen_scene *s = &c->cockpit;
    float dir[4][3], col[4][3], amb[3], m[3];
    memcpy(dir, s->light_dir, sizeof dir);
    memcpy(col, s->light_color, sizeof col);
    memcpy(amb, s->ambient, sizeof amb);
    tint_of(c->light.kelvin, m);
    const float a = c->light.roll_deg * 0.017453292519943f, ca = cosf(a), sa = sinf(a);
    for (int i = 0; i < s->light_count && i < 4; i++) {
        /* about the world's forward axis (z): y (up) turns towards +x */
        const float x = dir[i][0], y = dir[i][1];
        s->light_dir[i][0] = ca * x + sa * y;
        s->light_dir[i][1] = -sa * x + ca * y;
        for (int k = 0; k < 3; k++) s->light_color[i][k] = col[i][k] * c->light.gain * m[k];
    }
    for (int k = 0; k < 3; k++) s->ambient[k] = amb[k] * c->light.gain * m[k];
    /* the same silhouette and normals as the matched image (the geometry
     * and the camera noise's seed do not change) */
    gt_render_eye(&c->gctx, world_from_head, (kin_eye)e, frame, c->ps.cam_rgb, c->sil[e],
                  c->tnrm[e], c->ps.gt_depth, c->ps.gt_mask);
    memcpy(s->light_dir, dir, sizeof dir);
    memcpy(s->light_color, col, sizeof col);
    memcpy(s->ambient, amb, sizeof amb);
    const uint8_t *src = c->ps.cam_rgb + (size_t)c->g.crop_y0 * GEN_CAM_W * 3;
    fuse_image P = {c->P[e], CW, CH, 4 * CW};
    return fuse_rgb24_to_rgba(src, GEN_CAM_W * 3, CW, CH, &P) == FUSE_OK ? 0 : -1;
}

/* the level's name: "matched", "gain=0.5x", "kelvin=3000K", "roll=30deg" */
static void level_name(const eval_light *l, char *out, size_t n)
{
    if (l->gain != 1.0f) snprintf(out, n, "gain=%gx", (double)l->gain);
    else if (l->kelvin != 6500.0f) snprintf(out, n, "kelvin=%gK", (double)l->kelvin);
    else if (l->roll_deg != 0.0f) snprintf(out, n, "roll=%gdeg", (double)l->roll_deg);
    else snprintf(out, n, "matched");
}

/* the level's index in levels[] (x of its configurations) */
static int level_index(const eval_light *l)
{
    for (int i = 0; i < NLEV; i++)
        if (levels[i].gain == l->gain && levels[i].kelvin == l->kelvin &&
            levels[i].roll_deg == l->roll_deg)
            return i;
    return -1;
}

/* the curves: kin-cal-pred, skin, refine, refine+tone */
enum { NCURVE = 4 };
static const char *const curve_name[NCURVE] = {"kin-cal-pred", "skin", "refine", "refine+tone"};

static int curve_of(const method_cfg *c)
{
    switch (c->kind) {
    case M_KIN_CAL: return 0;
    case M_SKIN: return 1;
    case M_REFINE: return c->tone > 0.0f ? 3 : 2;
    default: return -1;
    }
}

int eval__light_configs(const method_cfg base[4], const eval_light *l, method_cfg *L, int cap)
{
    char name[48];
    int n = 0;
    level_name(l, name, sizeof name);
    for (int q = 0; q < NCURVE; q++) {
        const method_kind k = q == 0 ? M_KIN_CAL : q == 1 ? M_SKIN : M_REFINE;
        method_cfg c = base[k];
        snprintf(c.group, sizeof c.group, "light");
        snprintf(c.setting, sizeof c.setting, "%s%s", name, q == 3 ? "+tone" : "");
        c.x = (float)level_index(l);
        c.tone = q == 3 ? 1.0f : 0.0f;
        if (n < cap) L[n] = c;
        n++;
    }
    return n;
}

/* ---- report -------------------------------------------------------- */

typedef struct lsum { double iou, bf3, psnr; int have; } lsum;

static lsum sum_of(const method_run *r)
{
    const eval_summary m = eval__summarise(r);
    lsum s = {m.iou, m.bf3, m.psnr, 1};
    return s;
}

/* Where y first falls below thr going out from the matched point x0 (the
 * points in x order; linear between them): NAN never, -INFINITY at x0
 * already. Both sides of x0 are searched (the gain and the colour
 * temperature go both ways); the crossing nearer x0 is reported (by
 * |log(x / x0)|, or |x - x0| when x0 is 0). */
static double cross_below(const double *x, const double *y, int m, double thr, double x0)
{
    double best = NAN, bestd = INFINITY;
    for (int dirn = -1; dirn <= 1; dirn += 2) {
        int j0 = -1;
        for (int j = 0; j < m; j++)
            if (x[j] == x0) j0 = j;
        if (j0 < 0) continue;
        if (y[j0] < thr) return -INFINITY;
        for (int j = j0 + dirn; j >= 0 && j < m; j += dirn) {
            if (y[j] < thr) {
                const double xp = x[j - dirn], yp = y[j - dirn];
                const double xc = xp + (thr - yp) * (x[j] - xp) / (y[j] - yp);
                const double d = x0 > 0 && xc > 0 ? fabs(log(xc / x0)) : fabs(xc - x0);
                if (d < bestd) { bestd = d; best = xc; }
                break;
            }
        }
    }
    return best;
}

int eval__write_light(const char *dir, const method_run *R, int n)
{
    lsum S[NCURVE][NLEV];
    memset(S, 0, sizeof S);
    for (int i = 0; i < n; i++) {
        const method_cfg *c = &R[i].cfg;
        if (strcmp(c->group, "light")) continue;
        const int q = curve_of(c), l = (int)c->x;
        if (q < 0 || l < 0 || l >= NLEV) continue;
        S[q][l] = sum_of(&R[i]);
    }
    /* the table */
    io_out of;
    io_error err;
    FILE *f;
    char path[IO_PATH_MAX + 64];
    int go;
    for (int pass = 0; (go = eval__table_pass(pass, dir, "light.md", &of, &f)) > 0; pass++) {
        fprintf(f, "%sLighting mismatch between the cockpit and the virtual scene (the ideal "
                   "composite made under the cockpit's own light): IoU / BF(3 px) / PSNR dB%s\n%s",
                pass ? "" : "egofuse eval: ", pass ? "\n" : "", pass ? "\n" : "");
        fprintf(f, pass ? "| cockpit light |" : "%-14s", pass ? "" : "cockpit light");
        for (int q = 0; q < NCURVE; q++)
            fprintf(f, pass ? " %s |" : " %-22s", curve_name[q]);
        fprintf(f, "\n");
        if (pass) {
            fprintf(f, "|---|");
            for (int q = 0; q < NCURVE; q++) fprintf(f, "---|");
            fprintf(f, "\n");
        }
        for (int l = 0; l < NLEV; l++) {
            char name[48];
            int any = 0;
            for (int q = 0; q < NCURVE; q++) any |= S[q][l].have;
            if (!any) continue;
            level_name(&levels[l], name, sizeof name);
            fprintf(f, pass ? "| %s |" : "%-14s", name);
            for (int q = 0; q < NCURVE; q++) {
                if (!S[q][l].have) fprintf(f, pass ? " - |" : " %-22s", "-");
                else if (pass)
                    fprintf(f, " %.4f / %.3f / %.2f |", S[q][l].iou, S[q][l].bf3, S[q][l].psnr);
                else
                    fprintf(f, " %.4f %.3f %6.2f    ", S[q][l].iou, S[q][l].bf3, S[q][l].psnr);
            }
            fprintf(f, "\n");
        }
    }
    if (go < 0) return IO_EXIT_FAIL;
    if (!dir) return IO_EXIT_OK;
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;   /* light.md */
    /* where each curve falls below IoU 0.9 / its matched PSNR - drop */
    double below_iou[3][NCURVE], below_psnr[3][NCURVE];
    for (int a = 0; a < 3; a++)
        for (int q = 0; q < NCURVE; q++) {
            double xs[NLEV], yi[NLEV], yp[NLEV];
            int m = 0;
            for (int l = 0; l < NLEV; l++) {
                const double x = eval__light_x(&levels[l], axes[a]);
                if (isnan(x) || !S[q][l].have) continue;
                int j = m++;
                while (j > 0 && xs[j - 1] > x) {
                    xs[j] = xs[j - 1]; yi[j] = yi[j - 1]; yp[j] = yp[j - 1];
                    j--;
                }
                xs[j] = x;
                yi[j] = S[q][l].iou;
                yp[j] = S[q][l].psnr;
            }
            const double x0 = eval__light_x(&levels[0], axes[a]);
            below_iou[a][q] = m ? cross_below(xs, yi, m, 0.9, x0) : NAN;
            below_psnr[a][q] = m && S[q][0].have
                                   ? cross_below(xs, yp, m, S[q][0].psnr - LIGHT_PSNR_DROP, x0)
                                   : NAN;
        }
    /* light_<axis>.dat: per curve a block of x iou bf3 psnr */
    for (int a = 0; a < 3; a++) {
        if (!eval__out_open(&of, dir, "light_%s.dat", axes[a])) return IO_EXIT_FAIL;
        for (int q = 0; q < NCURVE; q++) {
            fprintf(of.f, "# %s: %s iou bf3 psnr\n", curve_name[q], axes[a]);
            int any = 0;
            double xs[NLEV];
            int ls[NLEV], m = 0;
            for (int l = 0; l < NLEV; l++) {
                const double x = eval__light_x(&levels[l], axes[a]);
                if (isnan(x) || !S[q][l].have) continue;
                int j = m++;
                while (j > 0 && xs[j - 1] > x) { xs[j] = xs[j - 1]; ls[j] = ls[j - 1]; j--; }
                xs[j] = x;
                ls[j] = l;
            }
            for (int j = 0; j < m; j++) {
                fprintf(of.f, "%g %.5f %.5f %.3f\n", xs[j], S[q][ls[j]].iou, S[q][ls[j]].bf3,
                        S[q][ls[j]].psnr);
                any = 1;
            }
            if (!any) fprintf(of.f, "nan nan nan nan\n");
            fprintf(of.f, "\n\n");
        }
        if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    }
    /* the chart: IoU (top) and PSNR (bottom) per axis */
    if (!eval__out_open(&of, dir, "light.gp")) return IO_EXIT_FAIL;
    f = of.f;
    static const char *const xlab[3] = {"cockpit light intensity, x the matched",
                                        "cockpit light colour temperature, K (matched: 6500)",
                                        "cockpit light direction, degrees to the side"};
    /* one legend for the six panels, below them (a box inside a panel hid
     * skin's points); the crossings under each panel's axis label, not
     * over its curves; the IoU panels without refine+tone, whose masks are
     * refine's (its line hid refine's) */
    fprintf(f, "if (!exists('sfx')) sfx = ''\nset grid\n"
               "set terminal pngcairo noenhanced size 1500,980 font ',12'\n"
               "set output '%s/light.png'.sfx\n"
               "set multiplot title 'Lighting mismatch between the cockpit (camera images) and the "
               "virtual scene: circles where IoU falls below 0.9 (top) or PSNR %.0f dB below the "
               "matched light (bottom)'\n",
            dir, LIGHT_PSNR_DROP);
    for (int row = 0; row < 2; row++)
        for (int a = 0; a < 3; a++) {
            /* "below 0.9 at: refine 0.969, kin-cal-pred 0.948; skin throughout" */
            char cr[320];
            size_t u = (size_t)snprintf(cr, sizeof cr, "%s", row ? "1 dB down at:" : "below 0.9 at:");
            int listed = 0, line = 0;
            for (int q = 0; q < NCURVE; q++) {
                if (row == 0 && q == 3) continue;
                const double b = row ? below_psnr[a][q] : below_iou[a][q];
                if (isnan(b) || u >= sizeof cr - 48) continue;
                if (listed == 2 && !line) {
                    u += (size_t)snprintf(cr + u, sizeof cr - u, ",\\n");
                    line = 1;
                } else if (listed) {
                    u += (size_t)snprintf(cr + u, sizeof cr - u, ",");
                }
                if (isinf(b))
                    u += (size_t)snprintf(cr + u, sizeof cr - u, " %s from the start", curve_name[q]);
                else
                    u += (size_t)snprintf(cr + u, sizeof cr - u, fabs(b) >= 1000.0 ? " %s %.0f"
                                                                               : " %s %.3g",
                                          curve_name[q], b);
                listed++;
            }
            if (!listed) snprintf(cr + u, sizeof cr - u, " none");
            fprintf(f, "unset label\nunset arrow\nunset object\nset xlabel \"%s\\n%s\"\n"
                       "set ylabel '%s'\n%s\n",
                    xlab[a], cr, row ? "composite PSNR, dB" : "mask IoU",
                    a == 0 ? "set logscale x 2\nset xtics (0.5, 0.7, 1, 1.4, 2)" : "unset logscale x\nset xtics autofreq");
            /* panels placed by hand: the legend's strip below them */
            fprintf(f, "unset key\nset origin %.4f, %.4f\nset size 0.3333, 0.445\n",
                    a / 3.0, row ? 0.065 : 0.51);
            if (row == 0)
                fprintf(f, "set arrow 90 from graph 0, first 0.9 to graph 1, first 0.9 nohead dt 2 "
                           "lc rgb '#808080'\n");
            int obj = 1;
            for (int q = 0; q < NCURVE; q++) {
                if (row == 0 && q == 3) continue;
                const double b = row ? below_psnr[a][q] : below_iou[a][q];
                const double yv = row ? S[q][0].psnr - LIGHT_PSNR_DROP : 0.9;
                if (isnan(b) || isinf(b)) continue;
                fprintf(f, "set object %d circle at first %.6g, first %.6g size screen 0.01 "
                           "front fs empty border lc lt %d lw 2\n", obj++, b, yv, q + 1);
            }
            fprintf(f, "plot ");
            for (int q = 0; q < NCURVE; q++) {
                if (row == 0 && q == 3) continue;
                fprintf(f, "%s'%s/light_%s.dat' index %d using 1:%d with linespoints lw 2 pt 7 "
                           "lc %d title '%s'",
                        q ? ", \\\n     " : "", dir, axes[a], q, row ? 4 : 2, q + 1,
                        q == 2 ? "refine (refine+tone: the same masks)" : curve_name[q]);
            }
            fprintf(f, "\n");
        }
    /* the legend: lines with no point in range, in a strip of its own */
    fprintf(f, "set origin 0, 0\nset size 1, 0.06\nunset border\nunset tics\nunset xlabel\n"
               "unset ylabel\nunset grid\nunset arrow\nunset object\nunset logscale x\n"
               "set xrange [0:1]\nset yrange [0:1]\n"
               "set key center center horizontal maxrows 1 box\nplot ");
    for (int q = 0; q < NCURVE; q++)
        fprintf(f, "%s2 with linespoints lw 2 pt 7 lc %d title '%s'", q ? ", " : "", q + 1,
                q == 2 ? "refine (refine+tone: the same masks)" : curve_name[q]);
    fprintf(f, "\nunset multiplot\nset border\nset tics\nset grid\nset autoscale\n"
               "set origin 0, 0\nset size 1, 1\n");
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    /* gnuplot, then the chart named only once it decodes whole */
    char cmd[3 * IO_PATH_MAX], tmp[IO_PATH_MAX + 96];
    const long pid = (long)getpid();
    snprintf(cmd, sizeof cmd, "gnuplot -e \"sfx='.tmp.%ld'\" '%s/light.gp'", pid, dir);
    const int rc = system(cmd);
    snprintf(path, sizeof path, "%s/light.png", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, pid);
    if (rc != 0) {
        remove(tmp);
        fprintf(stderr, "egofuse eval: gnuplot failed (status %d): %s/light_*.dat and light.gp "
                        "are written, light.png is not\n", rc, dir);
        return IO_EXIT_OK;
    }
    io_image img;
    if (io_image_load(tmp, IO_U8, 0, &img, &err) != IO_OK) {
        remove(tmp);
        return io_term_fail("%s: gnuplot wrote it incomplete or not at all (%s); removed", path,
                        err.msg);
    }
    io_image_free(&img);
    if (rename(tmp, path) != 0) {
        const int e = errno;
        remove(tmp);
        return io_term_fail("%s: cannot name it (rename from %s): %s", path, tmp, strerror(e));
    }
    return IO_EXIT_OK;
}
