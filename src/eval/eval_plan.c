/* eval_plan.c - the plan of an accuracy evaluation (see eval.h): the
 * method configurations of each phase (methods, knobs, tracking sweeps,
 * other sequences and speeds, levels of detail, lighting, the Fresnel
 * fade), the report's batches of them, and eval_run, which runs each batch
 * (eval__run_batch, eval.c) and hands the sums to the tables and the
 * report (eval_report.c). The frames themselves: eval.c. */
#include "eval_internal.h"
#include "../io/io.h"
#include "../io/io_term.h"
#include "../io/io_lod.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------ configurations */

method_cfg eval__base_cfg(const eval_opts *o, method_kind k)
{
    method_cfg c;
    memset(&c, 0, sizeof c);
    c.kind = k;
    c.div = 1;
    c.aa = 1;
    c.band = o->band;
    c.fit = k == M_REFINE;
    c.global = o->global;
    if (k == M_REFINE) {
        /* docs/accuracy.md, issue 14 item 2: the last refined mask as the
         * prior within 3 cm of hands slower than 0.3 m/s, moved with the
         * hand's image motion; the hands' lag
         * compensated from 0.2 to 0.8 m/s; the band from the projected
         * uncertainty measured, off */
        c.prior_radius = EVAL_PRIOR_RADIUS;
        c.prior_speed = EVAL_PRIOR_SPEED;
        c.prior_mc = 1;
        c.lag_adapt_v0 = EVAL_LAG_V0;
        c.lag_adapt_v1 = EVAL_LAG_V1;
        c.stereo = o->stereo;   /* measured, off by default */
        c.fill_hole = EVAL_FILL_HOLE;
        c.fill_island = EVAL_FILL_ISLAND;
        c.shift = EVAL_SHIFT;   /* the fast hands moved to the colour (fit_shift.h) */
        c.smooth = EVAL_SMOOTH; /* the refined edge smoothed (fit_smooth.h) */
    }
    c.band_sigma = 0.007f;
    c.band_max = 64;
    c.track = gt_track_default();
    c.track.noise_mm = o->noise;
    c.track.latency_ms = o->latency;
    c.track.dropout = o->dropout;
    c.track.speed = o->speed;
    c.track.seed = (uint64_t)o->seed;
    c.calib_error = o->calib_error;
    c.lod = o->lod;
    c.lod_px = o->lod_px;
    snprintf(c.group, sizeof c.group, "methods");
    snprintf(c.setting, sizeof c.setting, "default");
    return c;
}

/* refine's variants, selectable in --methods (bits 4.. of
 * eval_opts.methods): refine with one knob changed (docs/accuracy.md) */
static const char *variant_name[EVAL_VARIANTS] = { "refine-nomc", "refine-noshift",
                                                   "refine-shiftall", "refine-nosmooth",
                                                   "refine-smoothlate", "refine-smoothout",
                                                   "refine-smoothin", "refine-smoothoutin",
                                                   "refine-closeout", "refine-openout" };

method_cfg eval__variant_cfg(const eval_opts *o, int v)
{
    method_cfg c = eval__base_cfg(o, M_REFINE);
    switch (v) {
    case 0: c.prior_mc = 0; snprintf(c.setting, sizeof c.setting, "priormc=0"); break;
    case 1: c.shift = 0; snprintf(c.setting, sizeof c.setting, "shift=0"); break;
    case 2: c.shift = 2; snprintf(c.setting, sizeof c.setting, "shift=2"); break;
    case 3: c.smooth = 0; snprintf(c.setting, sizeof c.setting, "smooth=0"); break;
    case 4: c.smooth = 2; snprintf(c.setting, sizeof c.setting, "smooth=2"); break;
    case 5: c.smooth = 3; snprintf(c.setting, sizeof c.setting, "smooth=3"); break;
    case 6: c.smooth = 4; snprintf(c.setting, sizeof c.setting, "smooth=4"); break;
    case 7: c.smooth = 5; snprintf(c.setting, sizeof c.setting, "smooth=5"); break;
    case 8: c.smooth = 6; snprintf(c.setting, sizeof c.setting, "smooth=6"); break;
    default: c.smooth = 7; snprintf(c.setting, sizeof c.setting, "smooth=7"); break;
    }
    return c;
}

static int add_cfg(method_cfg *list, int n, int cap, method_cfg c)
{
    if (n < cap) list[n] = c;
    return n + 1;
}

/* Phases of a report (each on its own ground truth and frame count). */
enum { PH_METHODS, PH_KNOBS, PH_TRACK, PH_SEQ, PH_SPEED, PH_LOD, PH_LIGHT, PH_KF };

/* A configuration of a sweep: group, swept value and setting "name=" x
 * (x as %g) followed by unit. */
static method_cfg named_cfg(const eval_opts *o, method_kind k, const char *group, float x,
                            const char *name, const char *unit)
{
    method_cfg c = eval__base_cfg(o, k);
    c.x = x;
    snprintf(c.group, sizeof c.group, "%s", group);
    snprintf(c.setting, sizeof c.setting, "%s=%g%s", name, (double)x, unit);
    return c;
}

/* One configuration of a sweep added to L: kind k with field = v, in
 * group `name` with the setting "name=" x unit (make_configs). */
#define SWEEP(k, name, x, unit, field, v) \
    do { \
        c = named_cfg(o, k, name, x, name, unit); \
        c.field = v; \
        n = add_cfg(L, n, cap, c); \
    } while (0)

/* PH_METHODS: the selected methods at the given tracking; PH_KNOBS: the
 * same (group "knobs") with every speed knob; PH_TRACK: the tracking sweeps (and the methods at the
 * given tracking, group "track"); PH_SEQ: the methods on sequence seq. */
static int make_configs(const eval_opts *o, int phase, const char *seq, float speed,
                        const eval_light *light, method_cfg *L, int cap)
{
    int n = 0;
    method_cfg c;
    if (phase == PH_LIGHT || phase == PH_KF) {   /* eval_light.c, eval_kf.c */
        method_cfg base[4];
        for (int k = 0; k < 4; k++) base[k] = eval__base_cfg(o, (method_kind)k);
        return phase == PH_KF ? eval__kf_configs(base, L, cap)
                              : eval__light_configs(base, light, L, cap);
    }
    if (phase == PH_SPEED)   /* the methods on the motion played at another speed */
        for (int k = 0; k < 4; k++) {
            if (k == M_SKIN || !(o->methods & (1u << k))) continue;
            c = named_cfg(o, (method_kind)k, "handspeed", speed, "speed", "x");
            c.track.speed = speed;
            n = add_cfg(L, n, cap, c);
        }
    if (phase == PH_METHODS || phase == PH_KNOBS || phase == PH_SEQ)
        for (int k = 0; k < 4; k++) {
            if (!(o->methods & (1u << k))) continue;
            c = eval__base_cfg(o, (method_kind)k);
            if (phase == PH_SEQ) {
                snprintf(c.group, sizeof c.group, "sequence");
                snprintf(c.setting, sizeof c.setting, "seq=%s", seq);
            } else if (phase == PH_KNOBS) {
                snprintf(c.group, sizeof c.group, "knobs");
            }
            n = add_cfg(L, n, cap, c);
        }
    if (phase == PH_METHODS || phase == PH_SEQ)   /* refine's variants (eval_parse_methods) */
        for (int v = 0; v < EVAL_VARIANTS; v++) {
            if (!(o->methods & (1u << (4 + v)))) continue;
            c = eval__variant_cfg(o, v);
            if (phase == PH_SEQ) snprintf(c.group, sizeof c.group, "sequence");
            n = add_cfg(L, n, cap, c);
        }
    if (phase == PH_KNOBS) {
        static const int bands[] = { 4, 8, 12, 24, 32 };
        for (int i = 0; i < 5; i++)
            SWEEP(M_REFINE, "band", (float)bands[i], "", band, bands[i]);
        SWEEP(M_REFINE, "fit", 0.0f, "", fit, 0);
        SWEEP(M_REFINE, "global", 0.0f, "", global, 0.0f);
        SWEEP(M_REFINE, "global", 0.5f, "", global, 0.5f);   /* the default until 2026-11-29 */
        /* issue 14 item 2: refine without the prior, without the adaptive
         * lag compensation, and with the band from the projected
         * uncertainty (docs/accuracy.md) */
        SWEEP(M_REFINE, "prior", 0.0f, "", prior_radius, 0.0f);
        SWEEP(M_REFINE, "priormc", 0.0f, "", prior_mc, 0);
        SWEEP(M_REFINE, "lagadapt", 0.0f, "", lag_adapt_v1, 0.0f);
        SWEEP(M_REFINE, "bandauto", 1.0f, "", band_auto, 1);
        for (int k = M_KIN_CAL; k <= M_REFINE; k += 2)
            SWEEP((method_kind)k, "lagcomp", 1.0f, "", lag_comp, 1);
        for (int k = M_KIN_CAL; k <= M_REFINE; k += 2) {
            for (int div = 2; div <= 4; div *= 2) {
                c = named_cfg(o, (method_kind)k, "res", (float)div, "div", "");
                snprintf(c.setting, sizeof c.setting, "mask=%dx%d", CW / div, CH / div);
                c.div = div;
                n = add_cfg(L, n, cap, c);
            }
            for (int aa = 4; aa <= 16; aa *= 2)
                SWEEP((method_kind)k, "aa", (float)aa, "", aa, aa);
            SWEEP((method_kind)k, "tris", 4.0f, "x", fine, 1);
            c = named_cfg(o, (method_kind)k, "dqs", 1.0f, "dqs", "");
            snprintf(c.setting, sizeof c.setting, "dqs");
            c.dqs = 1;
            n = add_cfg(L, n, cap, c);
        }
    }
    if (phase == PH_LOD) {
        /* kin-cal-pred and refine at every level of the mask model's chain
         * (levels past its last draw its last) and at the rule's targets */
        static const float px[] = { 1, 2, 4, 8 };
        for (int k = M_KIN_CAL; k <= M_REFINE; k += 2) {
            if (!(o->methods & (1u << k))) continue;
            for (int l = 0; l < 5; l++) {
                c = named_cfg(o, (method_kind)k, "lod", (float)l, "L", "");
                snprintf(c.setting, sizeof c.setting, "L%d", l);
                c.lod = l;
                n = add_cfg(L, n, cap, c);
            }
            for (int i = 0; i < 4; i++) {
                c = named_cfg(o, (method_kind)k, "lod", px[i], "auto", "px");
                snprintf(c.setting, sizeof c.setting, "auto@%gpx", (double)px[i]);
                c.lod = PIPE_LOD_AUTO;
                c.lod_px = px[i];
                n = add_cfg(L, n, cap, c);
            }
        }
    }
    if (phase == PH_TRACK) {
        static const float noise[] = { 0, 10, 20 };
        static const float lat[] = { 0, 50, 100 };
        static const float cal[] = { -0.10f, -0.05f, 0.05f, 0.10f };
        for (int k = 0; k < 4; k++) {
            if (k == M_SKIN || !(o->methods & (1u << k))) continue;
            c = eval__base_cfg(o, (method_kind)k);
            snprintf(c.group, sizeof c.group, "track");
            n = add_cfg(L, n, cap, c);
            for (int i = 0; i < 3; i++)
                SWEEP((method_kind)k, "noise", noise[i], "mm", track.noise_mm, noise[i]);
            for (int i = 0; i < 3; i++)
                SWEEP((method_kind)k, "latency", lat[i], "ms", track.latency_ms, lat[i]);
            static const float drop[] = { 0.0f, 0.1f, 0.3f };
            for (int i = 0; i < 3; i++)
                SWEEP((method_kind)k, "dropout", 100.0f * drop[i], "%", track.dropout, drop[i]);
            if (k == M_KIN) continue;    /* the paper's method has no calibration */
            for (int i = 0; i < 4; i++) {
                SWEEP((method_kind)k, "calib", 100.0f * (o->calib_error + cal[i]), "%", calib_error,
                      o->calib_error + cal[i]);
            }
        }
    }
    return n;
}
#undef SWEEP


/* ---------------------------------------------------------------- run */

int eval_run(const eval_opts *o)
{
    if (o->dump && io_mkdirs(o->dump) != 0)
        return io_term_fail("%s: cannot create the folder", o->dump);
    if (o->report && io_mkdirs(o->report) != 0)
        return io_term_fail("%s: cannot create the report folder", o->report);
    if (o->light_dir && io_mkdirs(o->light_dir) != 0)
        return io_term_fail("%s: cannot create the folder", o->light_dir);
    enum { CAP = 300 };
    method_cfg *cfgs = calloc(CAP, sizeof *cfgs);
    method_run *R = calloc(CAP, sizeof *R);
    eval_ctx c;
    memset(&c, 0, sizeof c);
    int n = 0, rc = IO_EXIT_FAIL;
    if (!cfgs || !R) { io_term_fail("out of memory"); goto done; }
    /* batches: (sequence, frames, phase) */
    enum { NB = 30 };
    const char *bseq[NB];
    int bframes[NB], bphase[NB], nb = 0;
    float bspeed[NB];
    eval_light blight[NB];
    memset(blight, 0, sizeof blight);
    for (int b = 0; b < NB; b++) bspeed[b] = o->speed;
    bseq[nb] = o->sequence; bframes[nb] = o->frames; bphase[nb++] = PH_METHODS;
    if (o->report) {
        bseq[nb] = o->sequence; bframes[nb] = o->sweep_frames; bphase[nb++] = PH_KNOBS;
        bseq[nb] = o->sequence; bframes[nb] = o->sweep_frames; bphase[nb++] = PH_TRACK;
        static const float speeds[] = { 0.5f, 2.0f };   /* x the given speed */
        for (int i = 0; i < 2; i++) {
            bseq[nb] = o->sequence; bframes[nb] = o->sweep_frames; bphase[nb] = PH_SPEED;
            bspeed[nb++] = o->speed * speeds[i];
        }
    }
    if (o->report || o->lod_sweep) {
        bseq[nb] = o->sequence;
        bframes[nb] = o->report ? o->sweep_frames : o->frames;
        bphase[nb++] = PH_LOD;
    }
    if (o->report) {
        for (int q = 0; gt_sequence_name(q) && nb < NB; q++) {
            const char *name = gt_sequence_name(q);
            if (!strcmp(name, o->sequence) || !strcmp(name, "calib")) continue;
            bseq[nb] = name; bframes[nb] = o->seq_frames; bphase[nb++] = PH_SEQ;
        }
    }
    if (o->report || o->light_sweep) {   /* the lighting mismatch (eval_light.c) */
        eval_light lv[16];
        const int nl = eval__light_levels(lv, 16);
        for (int i = 0; i < nl && nb < NB; i++) {
            bseq[nb] = o->sequence;
            bframes[nb] = o->report ? o->sweep_frames : o->frames;
            blight[nb] = lv[i];
            bphase[nb++] = PH_LIGHT;
        }
    }
    if ((o->report || o->kf_sweep) && nb < NB) {   /* the Fresnel fade (eval_kf.c) */
        bseq[nb] = o->sequence;
        bframes[nb] = o->report ? o->sweep_frames : o->frames;
        blight[nb].opaque_ideal = 1;
        bphase[nb++] = PH_KF;
    }
    for (int b = 0; b < nb; b++) {
        int m = make_configs(o, bphase[b], bseq[b], bspeed[b], &blight[b], cfgs + n, CAP - n);
        if (n + m > CAP) { io_term_fail("too many configurations"); goto done; }
        eval__ctx_free(&c);
        const method_cfg base = eval__base_cfg(o, M_KIN_CAL);
        if (eval__run_batch(o, &base.track, &c, bseq[b], bframes[b], bspeed[b],
                            bphase[b] == PH_LIGHT || bphase[b] == PH_KF ? &blight[b] : NULL,
                            cfgs + n, R + n, m))
            goto done;
        if (b == 0 || (!o->quiet && bphase[b] != PH_LIGHT && bphase[b] != PH_KF) ||
            bphase[b] == PH_LOD) {
            printf("egofuse eval: sequence %s, %d frames, tracking noise %g mm, latency %g ms, "
                   "dropout %g, calibration error %g, speed %g; means per eye (640x400 masks)\n",
                   bseq[b], bframes[b], (double)o->noise, (double)o->latency,
                   (double)o->dropout, (double)o->calib_error, (double)bspeed[b]);
            if (b == 0) eval__print_calib(stdout, &c);
            eval__print_table(stdout, R + n, m, 0);
            eval__print_thickness(stdout, &c, R + n, m);
            eval__print_error_area(stdout, R + n, m);
            if (bphase[b] == PH_LOD) {
                printf("levels of detail of the mask model (meshoptimizer %d):", io_lod_version());
                for (int l = 0; l < c.lod.level_count; l++)
                    printf(" L%d %ld triangles, error %.2f mm;", l, c.lod.level[l].triangles,
                           1e3 * (double)c.lod.level[l].error_m);
                printf("\n");
                eval__print_lod(stdout, R + n, m, 0);
            }
        }
        n += m;
    }
    if (o->csv && eval__write_csv(o->csv, R, n)) goto done;
    if (o->report && eval__write_report(o->report, R, n, o, &c)) goto done;
    if ((o->report || o->light_sweep) && eval__write_light(o->report ? o->report : o->light_dir, R, n)) goto done;
    if ((o->report || o->kf_sweep) && eval__write_kf(o->report, R, n)) goto done;
    if (o->report) printf("egofuse eval: report in %s (summary.csv, table.md, *.png)\n", o->report);
    rc = IO_EXIT_OK;
done:
    eval__ctx_free(&c);
    free(R);
    free(cfgs);
    return rc;
}

/* "kin,refine" -> bits of method_kind; 0 when a name is unknown. */
unsigned eval_parse_methods(const char *list)
{
    unsigned bits = 0;
    const char *p = list;
    while (*p) {
        size_t n = strcspn(p, ",");
        int found = 0;
        for (int k = 0; k < 4; k++)
            if (strlen(kind_name[k]) == n && !strncmp(p, kind_name[k], n)) {
                bits |= 1u << k;
                found = 1;
            }
        for (int v = 0; v < EVAL_VARIANTS; v++)
            if (strlen(variant_name[v]) == n && !strncmp(p, variant_name[v], n)) {
                bits |= 1u << (4 + v);
                found = 1;
            }
        if (!found) return 0;
        p += n;
        if (*p == ',') p++;
    }
    return bits;
}
