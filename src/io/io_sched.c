/* io_sched.c - the repaint-window scheduler (io_sched.h): pure arithmetic
 * on nanosecond time stamps. */
#include "io_sched.h"

#include <string.h>

void io_sched_init(io_sched *s, uint64_t period_ns)
{
    memset(s, 0, sizeof *s);
    s->period_ns = period_ns;
    s->margin_ns = 1000000;
    s->percentile = 90;
    s->initial_est_ns = period_ns / 2;
    s->floor_decay_ns = 250000;
    s->refine_period = 1;
}

static uint64_t percentile(const io_sched *s)
{
    uint64_t v[IO_SCHED_WINDOW];
    int n = s->ndur;
    memcpy(v, s->dur, (size_t)n * sizeof v[0]);
    for (int i = 1; i < n; i++) {          /* insertion sort, n <= 60 */
        uint64_t x = v[i];
        int j = i - 1;
        while (j >= 0 && v[j] > x) {
            v[j + 1] = v[j];
            j--;
        }
        v[j + 1] = x;
    }
    int pct = s->percentile < 1 ? 1 : s->percentile > 100 ? 100 : s->percentile;
    int idx = (pct * n + 99) / 100 - 1;     /* nearest rank */
    if (idx < 0) idx = 0;
    if (idx >= n) idx = n - 1;
    return v[idx];
}

uint64_t io_sched_estimate(const io_sched *s)
{
    uint64_t est = s->ndur ? percentile(s) + s->margin_ns : s->initial_est_ns;
    return est > s->floor_ns ? est : s->floor_ns;
}

/* The first vblank of the grid last_flip + k * period at or after t. */
static uint64_t grid_at_or_after(const io_sched *s, uint64_t t)
{
    uint64_t p = s->period_ns, f = s->last_flip_ns;
    if (t <= f) return f;
    uint64_t k = (t - f + p - 1) / p;
    return f + k * p;
}

uint64_t io_sched_next_vblank(const io_sched *s, uint64_t now_ns)
{
    if (!s->period_ns || !s->have_flip) return 0;
    return grid_at_or_after(s, now_ns);
}

io_sched_plan io_sched_next(const io_sched *s, uint64_t now_ns)
{
    io_sched_plan p;
    p.est_ns = io_sched_estimate(s);
    if (!s->period_ns || !s->have_flip) {        /* free-running */
        p.start_ns = now_ns;
        p.target_ns = 0;
        return p;
    }
    uint64_t lo = now_ns + p.est_ns;
    /* one flip in flight: the next frame can only flip a vblank later */
    if (s->pending && s->pending_expect_ns) {
        uint64_t after = s->pending_expect_ns + s->period_ns / 2;
        if (after > lo) lo = after;
    }
    p.target_ns = grid_at_or_after(s, lo);
    p.start_ns = p.target_ns - p.est_ns;
    return p;
}

void io_sched_presented(io_sched *s, const io_sched_plan *p, uint64_t started_ns,
                        uint64_t presented_ns)
{
    uint64_t d = presented_ns > started_ns ? presented_ns - started_ns : 0;
    s->dur[s->idur] = d;
    s->idur = (s->idur + 1) % IO_SCHED_WINDOW;
    if (s->ndur < IO_SCHED_WINDOW) s->ndur++;
    s->floor_ns = s->floor_ns > s->floor_decay_ns ? s->floor_ns - s->floor_decay_ns : 0;
    /* what this frame needed, counted from its planned start (a late
     * wake-up eats into the window too) */
    uint64_t from = p->start_ns < started_ns ? p->start_ns : started_ns;
    s->pending_need_ns = (presented_ns > from ? presented_ns - from : 0) + s->margin_ns;
    s->pending = 1;
    s->pending_target_ns = p->target_ns;
    /* presented after its vblank: it flips on a later one, and the next
     * frame must not aim at that one too */
    s->pending_expect_ns = p->target_ns;
    if (p->target_ns && s->period_ns && presented_ns >= p->target_ns)
        s->pending_expect_ns = grid_at_or_after(s, presented_ns + 1);
    s->frames++;
}

int io_sched_flipped(io_sched *s, uint64_t t_ns, uint32_t seq)
{
    int miss = 0;
    s->flips++;
    if (s->have_flip && s->refine_period && s->period_ns && t_ns > s->last_flip_ns) {
        uint32_t n = seq - s->last_seq;
        if (n >= 1 && n <= 8) {
            uint64_t meas = (t_ns - s->last_flip_ns) / n;
            uint64_t p = s->period_ns;
            /* only counts that agree with the mode within 5 % */
            if (meas > p - p / 20 && meas < p + p / 20)
                s->period_ns = (uint64_t)((int64_t)p + ((int64_t)meas - (int64_t)p) / 16);
        }
    }
    if (s->pending && s->pending_target_ns) {
        s->last_late_ns = (int64_t)(t_ns - s->pending_target_ns);
        if (t_ns > s->pending_target_ns + s->period_ns / 2) {
            miss = 1;
            s->misses++;
            /* what it needed plus another margin: the frames after a
             * step in the load jitter around the new level */
            uint64_t f = s->pending_need_ns + s->margin_ns;
            if (f > s->floor_ns) s->floor_ns = f;
        }
    }
    s->pending = 0;
    s->have_flip = 1;
    s->last_flip_ns = t_ns;
    s->last_seq = seq;
    return miss;
}
