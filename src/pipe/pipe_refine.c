/* pipe_refine.c - an eye's colour refinement inside pipe_frame (the
 * refine steps of run_eye, pipe.c): the mask made to follow the camera
 * image's hand colour. The steps' kernels live in src/fit and
 * fuse_refine.h; this file only orders them for one eye, as eval's refine
 * does (docs/accuracy.md). */
#include "pipe_ctx.h"
#include "pipe_internal.h"
#include "pipe_parts.h"
#include "pipe_aa.h"
#include "../fit/fit_band.h"
#include "../fit/fit_holes.h"
#include "../fit/fit_narrow.h"
#include "../fit/fit_shift.h"
#include "../fit/fit_smooth.h"
#include "../fuse/fuse_refine.h"

#include <stdio.h>
#include <string.h>

/* The colour refinement of eye e's mask (pipe_desc.refine_band > 0), run
 * by run_eye after the raster: the prior and the shift of its input, the
 * band refinement, the colour checks, holes and islands, the cockpit clamp,
 * the smoothed shown mask, and the fit's learning for the next frame.
 * Sets fe->mask to the mask to light (the refined one, or its anti-aliased
 * coverage). 0, or -1 with e->result and e->why set. */
int pipe__refine_eye(pipe_ctx *p, eye_state *e, fuse_eye *fe)
{
    const pipe_frame_in *in = e->in;
    const int cw = p->geo.crop_width, ch = p->geo.crop_height;
    fuse_refine_params rp = fuse_refine_params_default();
    rp.band = p->desc.refine_band;
    /* the elbow fit's colour model as the global term only once it
     * has one: before that (or when the last learning found too few
     * samples) its all-zero model would only halve the local term; the
     * colour checks of the prior, the shift and the refined pixels need
     * it too (NULL: none of them runs) */
    const fuse_colour_model *g =
        p->fit && pipe_fit_learned(p->fit, e->eye) ? pipe_fit_colour(p->fit, e->eye) : NULL;
    /* The refinement's input: the kinematic mask, or on tracked frames
     * (the fit's) around the slow hands the last refined mask moved
     * with the hand (pipe_fit_prior; e->refined still holds it until
     * the refinement below) */
    const uint8_t *rin = e->mask;
    const unsigned sides = 3u & ~in->fit_skip;
    if (e->prior) {
        if (in->locals && e->have_refined && !p->fit_no_prev) {
            pipe_fit_band_desc bd = pipe_fit_band_desc_default();
            bd.hand_radius = PIPE_PRIOR_RADIUS;
            const float zero[2] = {0.0f, 0.0f};
            /* moved with the hand: its image motion since the last
             * frame (the drawn pose's) */
            float shift[2][2] = {{0, 0}, {0, 0}};
            for (int k = 0; k < 2; k++)
                if (e->have_hand_px[k] &&
                    pipe_fit_hand_px(&e->cam, p->pose.world, &p->fit_rig, k, shift[k])) {
                    shift[k][0] -= e->hand_px[k][0];
                    shift[k][1] -= e->hand_px[k][1];
                } else {
                    shift[k][0] = shift[k][1] = 0.0f;
                }
            rin = pipe_fit_prior(&bd, &e->cam, p->pose.world, &p->fit_rig, sides,
                                 in->hand_speed ? in->hand_speed : zero, PIPE_PRIOR_SPEED,
                                 shift, e->mask,
                                 e->have_unsmoothed ? e->unsmoothed : e->refined, e->prior,
                                 cw);
            /* its rim must look like the hand (last frame's edge a
             * pixel off: fit_band.h) */
            if (rin == e->prior && g) pipe_fit_prior_colour(g, &fe->P, e->prior, cw);
        }
    }
    const int from_prior = rin == e->prior;
    /* the hands that did not take the prior moved to where the colour
     * says they are (fit_shift.h: the tracking's error beyond the
     * band, docs/accuracy.md); eval's refine does the same */
    if (e->shifted && in->locals && g) {
        unsigned ss = sides;
        if (from_prior)
            for (int k = 0; k < 2; k++)
                if (!in->hand_speed || in->hand_speed[k] < PIPE_PRIOR_SPEED) ss &= ~(1u << k);
        if (ss) {
            const pipe_fit_shift_desc sd = pipe_fit_shift_desc_default();
            rin = pipe_fit_shift(&sd, g, &fe->P, &e->cam, p->pose.world, &p->fit_rig, ss, rin,
                                 e->shifted, cw, e->refine_scratch, e->refine_scratch_size,
                                 NULL);
        }
    }
    /* the hands' image motion since the last frame (the regrow's trail
     * below) */
    float hmot[2][2] = {{0, 0}, {0, 0}};
    unsigned hseen = 0;
    if (e->prior) {
        /* where the hands are in this frame's refined mask */
        for (int k = 0; k < 2; k++) {
            const int had = e->have_hand_px[k];
            const float ox = e->hand_px[k][0], oy = e->hand_px[k][1];
            e->have_hand_px[k] =
                pipe_fit_hand_px(&e->cam, p->pose.world, &p->fit_rig, k, e->hand_px[k]);
            if (e->have_hand_px[k]) hseen |= 1u << k;
            if (had && e->have_hand_px[k]) {
                hmot[k][0] = e->hand_px[k][0] - ox;
                hmot[k][1] = e->hand_px[k][1] - oy;
            }
        }
    }
    fuse_refine_stats rs;
    /* the band halved where the hand is too thin for its learning ring
     * (fit_narrow.h; eval's refine does the same) */
    fuse_result rr2 = pipe_fit_refine_narrow(&rp, g, PIPE_GLOBAL_WEIGHT, PIPE_NARROW_MIN_BAND,
                                             &fe->P, rin, cw, e->refined, cw, e->refine_scratch,
                                             e->refine_scratch_size, &rs, NULL);
    if (rr2 != FUSE_OK)
        return pipe__eye_fail(e, PIPE_ERR_FUSE, "mask refinement", fuse_result_str(rr2));
    /* once more from its own edge where it let in much: the hand beyond
     * the band (fit_narrow.h; eval's refine does the same) */
    const int regrown = pipe_fit_refine_regrow(&rp, g, PIPE_GLOBAL_WEIGHT, &fe->P, e->refined, cw,
                                               e->regrow, e->refine_scratch,
                                               e->refine_scratch_size, &rs);
    if (regrown < 0)
        return pipe__eye_fail(e, PIPE_ERR_FUSE, "mask refinement", fuse_result_str(FUSE_ERR_ARGS));
    /* what the regrow added behind a fast hand taken back: where the
     * hand was, not where it is (fit_narrow.h; eval's refine does the
     * same); e->regrow holds the refinement before it */
    if (regrown > 0 && in->locals && in->hand_speed)
        pipe_fit_regrow_trail(e->regrow, cw, e->refined, cw, cw, ch, sides & hseen, e->hand_px,
                              hmot, in->hand_speed, PIPE_TRAIL_STEPS);
    /* the pixels the vote let in beyond a prior must look like the
     * hand too (fit_band.h) */
    if (from_prior && rs.used_colour && g)
        pipe_fit_refined_colour(g, &fe->P, rin, e->refined, cw);
    /* its small islands cleared (and holes filled, PIPE_FILL_HOLE:
     * fit_holes.h); the refinement's scratch is free again */
    if (rs.used_colour && p->fit && p->desc.refine_fill == 0)
        pipe_fit_fill_small(e->refined, cw, cw, ch, PIPE_FILL_HOLE, PIPE_FILL_ISLAND, e->mask, cw,
                            e->refine_scratch, e->refine_scratch_size);
    pipe__cockpit_clamp(p->ck, &p->pose, e->eye, e->rast, &e->cam, e->mask, cw, e->refined,
                        cw, p->desc.refine_band, e->clip);
    /* the mask shown smoothed (fit_smooth.h: 1-2 px notches filled,
     * spurs cut); the fit learns from the mask before it and the next
     * frame's prior is that one (as eval's refine: smoothing what is
     * fed back lost on edge). The scratch is free and larger than it
     * needs (the fill's); the cockpit clamp again after it, so the
     * closing brings nothing back behind the cockpit. Tracked frames
     * only (as the fit): an animation-posed frame gives the bytes of
     * a pipe without fit */
    e->have_unsmoothed = 0;
    if (e->unsmoothed && rs.used_colour && p->fit && in->locals) {
        memcpy(e->unsmoothed, e->refined, (size_t)cw * (size_t)ch);
        if (pipe_fit_smooth(e->refined, cw, cw, ch, NULL, 0, e->refine_scratch,
                            e->refine_scratch_size) == 0) {
            e->have_unsmoothed = 1;
            pipe__cockpit_clamp(p->ck, &p->pose, e->eye, e->rast, &e->cam, e->mask, cw,
                                e->refined, cw, p->desc.refine_band, e->clip);
        }
    }
    const uint8_t *learned = e->have_unsmoothed ? e->unsmoothed : e->refined;
    e->have_refined = 1;
    fe->mask = e->refined;
    if (e->aa.count) {
        pipe__aa_refined(&e->aa, e->mask, e->refined, p->desc.refine_band);
        fe->mask = e->aa.soft;
    }
    if (p->fit && in->locals && rs.used_colour) {
        /* the next frame's fit: its colour model from this frame's
         * kinematic and refined masks, and the limb widths; not when
         * the refinement fell back to the kinematic mask (out = M):
         * its widths would be the model's own, samples equal to the
         * factor in use */
        if (pipe_fit_learn(p->fit, e->eye, &fe->P, e->mask, cw, learned, cw) != FUSE_OK)
            return pipe__eye_fail(e, PIPE_ERR_FUSE, "elbow fit: colour model", NULL);
        pipe_fit_measure(p->fit, e->eye, &e->cam, p->pose.world, e->mask, cw, learned, cw);
    }
    return 0;
}
