/* eval_lod.c - levels of detail in `egofuse eval` (eval_internal.h): the
 * chain of the mask model (io_lod_build, the defaults of `egofuse
 * render/run --lod`), the level each configuration draws, and the "lod"
 * group's table and data: per configuration the accuracy against the
 * ground truth (the method's final mask, as every group), the kinematic
 * mask's IoU and boundary F (1 px) against the full model's kinematic
 * mask in the same pose, the mean level and triangles drawn, and the
 * raster's time per eye (transforms + draw of the method's mask, the
 * thread's CPU time: the machine may be shared; bench/bench_lod measures
 * it over a cold cache, as in a frame). */
#include "eval_internal.h"

#include <stdlib.h>
#include <string.h>

#include "../io/io.h"
#include "../io/io_term.h"
#include "../io/io_lod.h"

int eval__lod_init(eval_ctx *c)
{
    if (c->lod.level_count > 0) return 0;
    io_error err;
    if (io_lod_build("the mask model", &c->mask.model, NULL, &c->lod, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        return -1;
    }
    c->full_mask = malloc((size_t)CW * CH);
    c->full_depth = malloc(sizeof(float) * (size_t)CW * CH);
    if (!c->full_mask || !c->full_depth) {
        eval__lod_free(c);
        io_term_fail("out of memory");
        return -1;
    }
    return 0;
}

void eval__lod_free(eval_ctx *c)
{
    io_lod_free(&c->lod);
    free(c->full_mask);
    free(c->full_depth);
    c->full_mask = NULL;
    c->full_depth = NULL;
}

int eval__lod_level(const eval_ctx *c, const method_cfg *cfg, const float *clip, int n,
                    const kin_camera *cam)
{
    if (cfg->lod == 0 || cfg->fine || c->lod.level_count < 2) return 0;
    if (cfg->lod > 0) return cfg->lod < c->lod.level_count ? cfg->lod : c->lod.level_count - 1;
    float f = cam->fx > cam->fy ? cam->fx : cam->fy;
    return pipe_lod_choose(&c->lod, pipe_lod_px_per_m(clip, n, f), cfg->lod_px);
}

typedef struct lod_sum {
    double iou, bf1, bf3, iou_full, bf1_full, level, tris, ms_raster;
} lod_sum;

static lod_sum lod_summary(const method_run *r)
{
    lod_sum s;
    const eval_summary m = eval__summarise(r);
    double nf = r->n_full > 0 ? (double)r->n_full : 1.0;
    double nr = r->n_raster > 0 ? (double)r->n_raster : 1.0;
    s.iou = m.iou;
    s.bf1 = m.bf1;
    s.bf3 = m.bf3;
    s.iou_full = r->n_full ? r->iou_full / nf : 1.0;
    s.bf1_full = r->n_full ? r->bf1_full / nf : 1.0;
    s.level = r->lod_sum / nr;
    s.tris = r->tris_sum / nr;
    s.ms_raster = 1e3 * r->raster_secs / nr;
    return s;
}

void eval__print_lod(FILE *f, const method_run *R, int n, int markdown)
{
    if (markdown)
        fprintf(f, "| method | setting | level | triangles | raster ms/eye | IoU vs full | "
                   "BF1 vs full | IoU | BF 1px | BF 3px |\n"
                   "|---|---|---|---|---|---|---|---|---|---|\n");
    else
        fprintf(f, "%-13s %-12s %6s %9s %10s %9s %9s %7s %6s %6s\n", "method", "setting",
                "level", "tris", "raster ms", "IoU full", "BF1 full", "IoU", "BF1", "BF3");
    for (int i = 0; i < n; i++) {
        if (strcmp(R[i].cfg.group, "lod")) continue;
        lod_sum s = lod_summary(&R[i]);
        if (markdown)
            fprintf(f, "| %s | %s | %.2f | %.0f | %.3f | %.4f | %.4f | %.4f | %.3f | %.3f |\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.setting, s.level, s.tris, s.ms_raster,
                    s.iou_full, s.bf1_full, s.iou, s.bf1, s.bf3);
        else
            fprintf(f, "%-13s %-12s %6.2f %9.0f %10.3f %9.4f %9.4f %7.4f %6.3f %6.3f\n",
                    kind_name[R[i].cfg.kind], R[i].cfg.setting, s.level, s.tris, s.ms_raster,
                    s.iou_full, s.bf1_full, s.iou, s.bf1, s.bf3);
    }
}

int eval__write_lod(const char *dir, const method_run *R, int n)
{
    io_out of;
    if (!eval__out_open(&of, dir, "lod.csv")) return IO_EXIT_FAIL;
    fprintf(of.f, "method,setting,level_mean,tris_mean,ms_raster_per_eye,iou_vs_full,"
                  "bf1_vs_full,iou,bf1,bf3\n");
    for (int i = 0; i < n; i++) {
        if (strcmp(R[i].cfg.group, "lod")) continue;
        lod_sum s = lod_summary(&R[i]);
        fprintf(of.f, "%s,%s,%.3f,%.0f,%.4f,%.5f,%.5f,%.5f,%.5f,%.5f\n",
                kind_name[R[i].cfg.kind], R[i].cfg.setting, s.level, s.tris, s.ms_raster,
                s.iou_full, s.bf1_full, s.iou, s.bf1, s.bf3);
    }
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    /* DIR/lod.dat: per method a block (gnuplot index 0 kin-cal-pred, 1
     * refine) of: triangles, raster ms, IoU vs full, IoU, BF1 vs full,
     * BF1, "setting" */
    if (!eval__out_open(&of, dir, "lod.dat")) return IO_EXIT_FAIL;
    static const method_kind kinds[2] = {M_KIN_CAL, M_REFINE};
    for (int k = 0; k < 2; k++) {
        fprintf(of.f, "# %s\n", kind_name[kinds[k]]);
        int rows = 0;
        for (int i = 0; i < n; i++) {
            if (strcmp(R[i].cfg.group, "lod") || R[i].cfg.kind != kinds[k]) continue;
            rows++;
            lod_sum s = lod_summary(&R[i]);
            /* settings that draw the same level share one point: one label
             * "L2, auto@4px, auto@8px" on the first, none on the others
             * (they were printed over each other) */
            char lab[160];
            size_t u = 0;
            int dup = 0;
            lab[0] = '\0';
            for (int j = 0; j < n && !dup; j++) {
                if (strcmp(R[j].cfg.group, "lod") || R[j].cfg.kind != kinds[k]) continue;
                lod_sum t = lod_summary(&R[j]);
                if ((long)(t.tris + 0.5) != (long)(s.tris + 0.5)) continue;
                if (j < i) dup = 1;
                else if (u + strlen(R[j].cfg.setting) + 3 < sizeof lab)
                    u += (size_t)snprintf(lab + u, sizeof lab - u, "%s%s", u ? ", " : "",
                                          R[j].cfg.setting);
            }
            fprintf(of.f, "%.0f %.4f %.5f %.5f %.5f %.5f \"%s\"\n", s.tris, s.ms_raster,
                    s.iou_full, s.iou, s.bf1_full, s.bf1, dup ? "" : lab);
        }
        /* an empty block is no gnuplot index (refine's would become 0) */
        if (!rows) fprintf(of.f, "nan nan nan nan nan nan \"\"\n");
        fprintf(of.f, "\n\n");
    }
    if (eval__out_commit(&of)) return IO_EXIT_FAIL;
    return IO_EXIT_OK;
}
