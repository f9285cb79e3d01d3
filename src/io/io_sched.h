/* io_sched.h - the repaint-window scheduler of the live output: when to
 * start the next composite so that it is finished just before the vblank
 * that shows it (Weston's repaint window, Mutter's frame clock), instead of
 * compositing as soon as a camera pair arrives and then waiting up to a
 * whole refresh for the flip. Pure arithmetic on nanosecond time stamps
 * (CLOCK_MONOTONIC, as the display's flip events and the cameras' kernel
 * time stamps): no I/O, no clock reads, no allocation, so it is tested
 * against a simulated vblank clock (tests/test_io_sched.c).
 *
 * MODEL
 *   Vblanks come at last_flip + k * period. The composite (dequeue the
 *   newest camera pair, composite, present) is estimated to take
 *       est = max(p90 of the last IO_SCHED_WINDOW composite times + margin,
 *                 floor)
 *   where floor is raised after a missed vblank to what that frame needed
 *   (its time from the planned start to the present, plus twice the margin) and
 *   then decays by floor_decay_ns per composite, so a spike or a step in
 *   the processing time costs one miss, not a run of them. The next start
 *   is target - est for the first vblank target that is later than the
 *   pending flip (one flip in flight per CRTC) and leaves est before it.
 *   The period is the mode's nominal one, refined from the flip events'
 *   sequence numbers when they count real vblanks (qemu's do not: seq 0).
 *   Without time stamps (period 0, or no flip seen yet) the scheduler is
 *   free-running: start at once.
 *
 * USAGE (one display; see docs/devices.md "Displays" for the run loop)
 *   io_sched s;
 *   io_sched_init(&s, io_display_refresh_ns(d));
 *   for (;;) {
 *       io_sched_plan p = io_sched_next(&s, now());
 *       ... wait until p.start_ns, handling flip events meanwhile
 *           (io_sched_flipped) ...
 *       uint64_t t0 = now();  grab the newest camera pair, composite,
 *       io_display_present(...);
 *       io_sched_presented(&s, &p, t0, now());
 *   }
 */
#ifndef EGOFUSE_IO_SCHED_H
#define EGOFUSE_IO_SCHED_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define IO_SCHED_WINDOW 60

typedef struct io_sched {
    /* configuration (io_sched_init sets the defaults; change freely) */
    uint64_t period_ns;        /* refresh period; 0 = free-running */
    uint64_t margin_ns;        /* safety margin added to the estimate: 1 ms */
    int percentile;            /* of the recent composite times: 90 */
    uint64_t initial_est_ns;   /* estimate before any sample: period / 2 */
    uint64_t floor_decay_ns;   /* per composite after a miss: 0.25 ms */
    int refine_period;         /* 1: refine period_ns from flip sequences */
    /* state */
    uint64_t dur[IO_SCHED_WINDOW];  /* recent composite times, a ring */
    int ndur, idur;
    uint64_t floor_ns;
    int have_flip;
    uint64_t last_flip_ns;     /* time stamp of the newest flip */
    uint32_t last_seq;
    int pending;               /* a presented frame has not flipped yet */
    uint64_t pending_target_ns;/* the vblank it was meant for */
    uint64_t pending_expect_ns;/* the vblank it will flip on: the target,
                                  or a later one when presented too late */
    uint64_t pending_need_ns;  /* its planned start to present, + margin */
    /* statistics */
    uint64_t frames;           /* presents */
    uint64_t flips;            /* flip events */
    uint64_t misses;           /* flips later than the targeted vblank */
    int64_t last_late_ns;      /* flip time - target of the last flip */
} io_sched;

/* A plan for the next frame. */
typedef struct io_sched_plan {
    uint64_t start_ns;         /* start the composite (dequeue) then */
    uint64_t target_ns;        /* the vblank it should flip on; 0 when
                                  free-running */
    uint64_t est_ns;           /* the composite time it assumed */
} io_sched_plan;

/* Defaults for a display with this refresh period (0 = unknown). */
void io_sched_init(io_sched *s, uint64_t period_ns);
/* The current composite-time estimate: max(percentile + margin, floor). */
uint64_t io_sched_estimate(const io_sched *s);
/* The earliest vblank after now_ns predicted from the last flip (0 when
 * unknown). */
uint64_t io_sched_next_vblank(const io_sched *s, uint64_t now_ns);
/* Plans the next composite at time now_ns. start_ns >= now_ns. */
io_sched_plan io_sched_next(const io_sched *s, uint64_t now_ns);
/* The frame planned by p was presented: the composite started at
 * started_ns and the present returned at presented_ns. Records the
 * composite time and the flip it waits for. */
void io_sched_presented(io_sched *s, const io_sched_plan *p,
                        uint64_t started_ns, uint64_t presented_ns);
/* A flip event (time stamp of the vblank it happened on, the driver's
 * vblank sequence). Returns 1 when it came after the vblank the frame was
 * planned for (a miss: the estimate is raised), else 0. */
int io_sched_flipped(io_sched *s, uint64_t t_ns, uint32_t seq);

#ifdef __cplusplus
}
#endif

#endif
