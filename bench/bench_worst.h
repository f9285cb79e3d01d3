/* bench_worst.h - the worst case of the frame benchmarks (bench_frame,
 * llvmpipe_frame), written once: at the pose of the grasp, the head moved
 * from its recorded place towards a target (the right palm, the left palm
 * or their midpoint) and looking at it, at the distance where the cameras'
 * images are about 70% covered.
 *
 *   bench_worst w;
 *   bench_worst_init(&w, &model, &rig, anim, t);   // the targets at time t
 *   bench_worst_find(&w, cover_fn, ctx);           // w.head, w.d, w.cover
 *
 * cover_fn(ctx, world_from_head) renders one stereo frame of the pose with
 * that head and returns its coverage (pipe_frame_stats.coverage of an eye).
 * The search: per target, 14 distances from the recorded one down to 9 cm;
 * between the two that bracket 70%, 10 bisection steps; the distance whose
 * coverage came nearest 70% wins, and the search stops at the first target
 * that comes within 1%. */
#ifndef EGOFUSE_BENCH_WORST_H
#define EGOFUSE_BENCH_WORST_H

#include <math.h>
#include <stdio.h>

#include "../src/kin/kin.h"
#include "../src/pipe/pipe.h"

#define BENCH_WORST_COVER 0.70

typedef double (*bench_worst_cover_fn)(void *ctx, const kin_mat4 *world_from_head);

typedef struct bench_worst {
    kin_vec3 head0;           /* the recorded head at the pose */
    kin_vec3 targets[3];      /* right palm, left palm, between them */
    int target;               /* the one chosen */
    double d, cover;          /* its distance from the head (m), coverage */
    kin_mat4 head;            /* world_from_head at d, looking at the target */
} bench_worst;

static const char *const bench_worst_target_name[3] = {"the right palm", "the left palm",
                                                       "between the palms"};

/* The head at distance d from target t, on the line from the recorded
 * head, looking at the target. */
static inline kin_mat4 bench_worst_head_at(const bench_worst *w, int t, double d)
{
    const kin_vec3 c = w->targets[t];
    const kin_vec3 dir = kin_v3_norm(kin_v3_sub(c, w->head0));
    kin_mat4 v = kin_mat4_look_at(kin_v3_sub(c, kin_v3_scale(dir, (float)d)), c, kin_v3(0, 1, 0)),
             h;
    kin_mat4_inverse(&v, &h);
    return h;
}

/* The recorded head and the palms of the model's animation at time t
 * (seconds). Returns 0, or -1 (message on stderr) when the pose fails. */
static inline int bench_worst_init(bench_worst *w, const kin_model *m, const kin_arm_rig *rig,
                                   const kin_animation *anim, float t)
{
    pipe_pose ps;
    if (pipe_pose_init(&ps, m) != 0) {
        fprintf(stderr, "bench: the worst case: cannot pose the model\n");
        return -1;
    }
    pipe_pose_anim(&ps, anim, t);
    const kin_vec3 l = kin_mat4_translation(&ps.world[rig->joint[0][KIN_RIG_PALM]]);
    const kin_vec3 r = kin_mat4_translation(&ps.world[rig->joint[1][KIN_RIG_PALM]]);
    w->targets[0] = r;
    w->targets[1] = l;
    w->targets[2] = kin_v3_scale(kin_v3_add(l, r), 0.5f);
    w->head0 = kin_mat4_translation(&ps.world[rig->head]);
    pipe_pose_free(&ps);
    w->target = 0;
    w->d = kin_v3_len(kin_v3_sub(r, w->head0));
    w->cover = 0;
    w->head = bench_worst_head_at(w, 0, w->d);
    return 0;
}

/* The recorded distance of the chosen target from the recorded head. */
static inline double bench_worst_d0(const bench_worst *w)
{
    return kin_v3_len(kin_v3_sub(w->targets[w->target], w->head0));
}

/* Distance d of target t, of coverage c: kept when nearer 70% than the best. */
static inline void bench_worst_keep(bench_worst *w, double *best_err, int t, double d, double c)
{
    if (fabs(c - BENCH_WORST_COVER) < *best_err) {
        *best_err = fabs(c - BENCH_WORST_COVER);
        w->d = d;
        w->cover = c;
        w->target = t;
    }
}

static inline void bench_worst_find(bench_worst *w, bench_worst_cover_fn cover, void *ctx)
{
    enum { STEPS = 14 };
    double best_err = 1e9;
    for (int t = 0; t < 3; t++) {
        const double d0 = kin_v3_len(kin_v3_sub(w->targets[t], w->head0)), dmin = 0.09;
        kin_mat4 h = bench_worst_head_at(w, t, d0);
        double prev_d = d0, prev_c = cover(ctx, &h);
        for (int k = 1; k <= STEPS; k++) {
            const double d = d0 + (dmin - d0) * k / STEPS;
            h = bench_worst_head_at(w, t, d);
            const double c = cover(ctx, &h);
            bench_worst_keep(w, &best_err, t, d, c);
            if (prev_c < BENCH_WORST_COVER && c >= BENCH_WORST_COVER) {   /* bracketed */
                double lo = d, hi = prev_d;
                for (int it = 0; it < 10; it++) {
                    const double mid = 0.5 * (lo + hi);
                    h = bench_worst_head_at(w, t, mid);
                    const double cm = cover(ctx, &h);
                    bench_worst_keep(w, &best_err, t, mid, cm);
                    if (cm < BENCH_WORST_COVER) hi = mid;
                    else lo = mid;
                }
                break;
            }
            prev_d = d;
            prev_c = c;
        }
        if (best_err < 0.01) break;
    }
    w->head = bench_worst_head_at(w, w->target, w->d);
}

#endif
