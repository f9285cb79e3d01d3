/* eval_kf.c - the Fresnel fade against the opaque ideal composite
 * (issue 14, item 3; docs/fuse.md, "The Fresnel term").
 *
 * The lighting layer fades the rim of the hand into V by kf F, F =
 * clamp01(1 - N.V)^5 (Schlick). A real hand is opaque: its ideal
 * composite is the true silhouette lit without any fade. The fade pays
 * where the method's silhouette is off by a pixel or two (a soft rim shows
 * less of a wrong edge) and costs where the hand's body turns away from
 * the camera (V shows through). This batch measures the composite's PSNR
 * against that opaque ideal (make_truth with eval_light.opaque_ideal) for
 * kf = 0, 0.25, 0.5, 0.75, 1 with kin-cal-pred and refine: the kf with the
 * highest PSNR is the one to use. */
#include "eval_internal.h"
#include "../io/io.h"
#include "../io/io_term.h"
#include "../io/io.h"

#include <string.h>

static const float kfs[] = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f};
enum { NKF = sizeof kfs / sizeof kfs[0] };

int eval__kf_configs(const method_cfg base[4], method_cfg *L, int cap)
{
    int n = 0;
    (void)kind_name;
    for (int k = M_KIN_CAL; k <= M_REFINE; k += 2)
        for (int i = 0; i < NKF; i++) {
            method_cfg c = base[k];
            snprintf(c.group, sizeof c.group, "kf");
            snprintf(c.setting, sizeof c.setting, "kf=%g", (double)kfs[i]);
            c.x = kfs[i];
            c.kf_set = 1;
            c.kf = kfs[i];
            if (n < cap) L[n] = c;
            n++;
        }
    return n;
}

int eval__write_kf(const char *dir, const method_run *R, int n)
{
    io_out of;
    FILE *f;
    int go;
    for (int pass = 0; (go = eval__table_pass(pass, dir, "kf.md", &of, &f)) > 0; pass++) {
        fprintf(f, "%sThe Fresnel fade kf against the opaque ideal composite (the true "
                   "silhouette, no fade): composite PSNR dB (IoU)%s\n",
                pass ? "" : "egofuse eval: ", pass ? "\n" : "");
        fprintf(f, pass ? "| method |" : "%-13s", pass ? "" : "method");
        for (int i = 0; i < NKF; i++) fprintf(f, pass ? " kf %g |" : "  kf %-12g", (double)kfs[i]);
        fprintf(f, pass ? " best |\n|---|" : "  best\n");
        if (pass) {
            for (int i = 0; i <= NKF; i++) fprintf(f, "---|");
            fprintf(f, "\n");
        }
        for (int k = M_KIN_CAL; k <= M_REFINE; k += 2) {
            double best = -1.0, bkf = 0.0;
            int any = 0;
            char row[512];
            int len = snprintf(row, sizeof row, pass ? "| %s |" : "%-13s", kind_name[k]);
            for (int i = 0; i < NKF; i++) {
                int hit = -1;
                for (int j = 0; j < n; j++)
                    if (!strcmp(R[j].cfg.group, "kf") && (int)R[j].cfg.kind == k &&
                        R[j].cfg.kf == kfs[i])
                        hit = j;
                if (hit < 0) {
                    len += snprintf(row + len, sizeof row - (size_t)len, pass ? " - |" : "  %-15s", "-");
                    continue;
                }
                const eval_summary m = eval__summarise(&R[hit]);
                const double psnr = m.psnr, iou = m.iou;
                len += snprintf(row + len, sizeof row - (size_t)len,
                                pass ? " %.2f (%.4f) |" : "  %6.2f (%.4f)", psnr, iou);
                if (psnr > best) { best = psnr; bkf = kfs[i]; }
                any = 1;
            }
            if (!any) continue;
            fprintf(f, "%s%s%g%s\n", row, pass ? " " : "  ", bkf, pass ? " |" : "");
        }
    }
    if (go < 0) return IO_EXIT_FAIL;
    if (dir && eval__out_commit(&of)) return IO_EXIT_FAIL;
    return IO_EXIT_OK;
}
