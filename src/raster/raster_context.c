/* raster_context.c - ISA dispatch, rast_draw, and the context: an ISA cap
 * and band-parallel drawing of one target with a small thread pool.
 *
 * Threads. A draw is cut into rounds of threads * BATCH submitted
 * triangles. In a round, thread k sets up triangles [base + k*BATCH,
 * base + (k+1)*BATCH) into its own buffer (clip, snap, setup: the shared
 * scalar code), then all threads meet at a barrier, then every thread scans
 * ALL set-up triangles of the round, in submission order, restricted to its
 * rows: 16-row bands, band b belonging to thread b % threads. Every pixel
 * thus sees the same triangles in the same order as on one thread, and a
 * scan restricted to rows writes exactly the bytes of the full scan, so the
 * result does not depend on the thread count. Buffers alternate between
 * two sets, so one barrier per round suffices: a thread refills set p in
 * round r+2 only after the barrier of round r+1, which no thread passes
 * before it has finished scanning round r.
 *
 * Workers wait for a draw by spinning briefly (back-to-back draws, e.g. the
 * two eyes, then start without a system call) and then block on a
 * condition variable. */
#include "raster_internal.h"

#include "../cpu/cpu.h"

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define cpu_relax() _mm_pause()
#else
#define cpu_relax() ((void)0)
#endif

enum {
    BAND_ROWS = 16,     /* rows per band */
    BATCH = 256,        /* submitted triangles per thread and round */
    IDLE_SPINS = 20000, /* pause loops before a worker blocks */
    BARRIER_SPINS = 4000 /* pause loops before a barrier yields */
};

/* ---- dispatch ----------------------------------------------------------- */

rast__scan_rows_fn rast__scan_for_isa(int isa)
{
#if defined(__x86_64__)
    switch (isa) {
    case EF_ISA_AVX512: return rast__scan_rows_avx512;
    case EF_ISA_AVX2:   return rast__scan_rows_avx2;
    case EF_ISA_SSE2:   return rast__scan_rows_sse2;
    default:            break;
    }
#else
    (void)isa;
#endif
    return rast__scan_rows_ref;
}

int rast_draw_isa(void)
{
    return (int)ef_isa_choose(EF_ISA_DEFAULT);
}

rast_result rast_draw(const rast_target *t, const rast_mesh_desc *mesh,
                      rast_stats *stats)
{
    return rast__draw_with(t, mesh, stats, rast__scan_for_isa(rast_draw_isa()));
}

/* ---- context ------------------------------------------------------------ */

typedef struct slot {
    rast__tri *buf[2];          /* BATCH * RAST__MAX_FAN each */
    int count[2];
    rast_stats st;
    unsigned sense;             /* barrier sense of this thread */
    unsigned gen;               /* last draw generation run (workers) */
    _Alignas(64) char pad[64];  /* keep slots on their own cache lines */
} slot;

struct rast_context {
    int isa, threads;
    rast__scan_rows_fn scan;
    slot *slots;
    pthread_t th[RAST_MAX_THREADS];
    int started;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    _Alignas(64) atomic_uint gen;
    atomic_int quit;
    _Alignas(64) atomic_uint bar_count;
    atomic_uint bar_sense;
    /* The draw being run (written by the caller before gen changes). */
    _Alignas(64) const rast_target *t;
    const rast_mesh_desc *m;
    rast__view view;
};

typedef struct worker_arg {
    rast_context *c;
    int tid;
} worker_arg;

static void barrier(rast_context *c, slot *s)
{
    const unsigned sense = s->sense ^ 1u;
    s->sense = sense;
    if (atomic_fetch_add(&c->bar_count, 1u) == (unsigned)c->threads - 1u) {
        atomic_store(&c->bar_count, 0u);
        atomic_store(&c->bar_sense, sense);
        return;
    }
    for (int n = 0; atomic_load(&c->bar_sense) != sense; n++) {
        if (n < BARRIER_SPINS)
            cpu_relax();
        else
            sched_yield();
    }
}

/* Scans tri into the bands of thread tid. */
static long scan_bands(const rast_context *c, int tid, const rast__tri *tri)
{
    const int n = c->threads;
    const int b0 = tri->y0 / BAND_ROWS, b1 = tri->y1 / BAND_ROWS;
    long w = 0;
    for (int b = b0 + ((tid - b0 % n) + n) % n; b <= b1; b += n)
        w += c->scan(c->t, tri, b * BAND_ROWS, b * BAND_ROWS + BAND_ROWS - 1);
    return w;
}

static void run_draw(rast_context *c, int tid)
{
    slot *me = &c->slots[tid];
    const rast_mesh_desc *m = c->m;
    const int n = c->threads;
    memset(&me->st, 0, sizeof me->st);
    int par = 0;
    for (long base = 0; base < m->tri_count; base += (long)n * BATCH, par ^= 1) {
        long lo = base + (long)tid * BATCH, hi = lo + BATCH;
        if (hi > m->tri_count)
            hi = m->tri_count;
        int cnt = 0;
        for (long ti = lo; ti < hi; ti++)
            cnt += rast__prepare(&c->view, m, (int)ti, me->buf[par] + cnt, &me->st);
        me->count[par] = cnt;
        barrier(c, me);
        for (int s = 0; s < n; s++) {
            const slot *o = &c->slots[s];
            for (int i = 0; i < o->count[par]; i++)
                me->st.pixels_written += scan_bands(c, tid, &o->buf[par][i]);
        }
    }
    barrier(c, me);
}

static void *worker_main(void *p)
{
    worker_arg *a = p;
    rast_context *c = a->c;
    const int tid = a->tid;
    free(a);
    slot *me = &c->slots[tid];
    for (;;) {
        int n = 0;
        while (atomic_load(&c->gen) == me->gen && !atomic_load(&c->quit) &&
               n++ < IDLE_SPINS)
            cpu_relax();
        if (atomic_load(&c->gen) == me->gen && !atomic_load(&c->quit)) {
            pthread_mutex_lock(&c->mu);
            while (atomic_load(&c->gen) == me->gen && !atomic_load(&c->quit))
                pthread_cond_wait(&c->cv, &c->mu);
            pthread_mutex_unlock(&c->mu);
        }
        if (atomic_load(&c->quit))
            break;
        me->gen = atomic_load(&c->gen);
        run_draw(c, tid);
    }
    return NULL;
}

void rast_context_destroy(rast_context *c)
{
    if (!c)
        return;
    if (c->started > 0) {
        pthread_mutex_lock(&c->mu);
        atomic_store(&c->quit, 1);
        pthread_cond_broadcast(&c->cv);
        pthread_mutex_unlock(&c->mu);
        for (int i = 0; i < c->started; i++)
            pthread_join(c->th[i], NULL);
    }
    if (c->threads > 1) {
        pthread_cond_destroy(&c->cv);
        pthread_mutex_destroy(&c->mu);
    }
    if (c->slots)
        for (int i = 0; i < c->threads; i++) {
            free(c->slots[i].buf[0]);
            free(c->slots[i].buf[1]);
        }
    free(c->slots);
    free(c);
}

rast_context *rast_context_create(const rast_context_desc *desc)
{
    rast_context_desc d = { 0, 0 };
    if (desc)
        d = *desc;
    if (d.threads < 0 || d.threads > RAST_MAX_THREADS || d.max_isa < 0 ||
        d.max_isa >= EF_ISA_COUNT)
        return NULL;
    rast_context *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->threads = d.threads > 1 ? d.threads : 1;
    c->isa = (int)ef_isa_choose((ef_isa)d.max_isa);
    c->scan = rast__scan_for_isa(c->isa);
    if (c->threads == 1)
        return c;

    pthread_mutex_init(&c->mu, NULL);
    pthread_cond_init(&c->cv, NULL);
    c->slots = calloc((size_t)c->threads, sizeof *c->slots);
    if (!c->slots)
        goto fail;
    for (int i = 0; i < c->threads; i++)
        for (int p = 0; p < 2; p++) {
            c->slots[i].buf[p] = malloc((size_t)BATCH * RAST__MAX_FAN * sizeof(rast__tri));
            if (!c->slots[i].buf[p])
                goto fail;
        }
    for (int i = 1; i < c->threads; i++) {
        worker_arg *a = malloc(sizeof *a);
        if (!a)
            goto fail;
        a->c = c;
        a->tid = i;
        if (pthread_create(&c->th[c->started], NULL, worker_main, a) != 0) {
            free(a);
            goto fail;
        }
        c->started++;
    }
    return c;
fail:
    rast_context_destroy(c);
    return NULL;
}

int rast_context_isa(const rast_context *c)
{
    return c ? c->isa : 0;
}

int rast_context_threads(const rast_context *c)
{
    return c ? c->threads : 0;
}

rast_result rast_context_draw(rast_context *c, const rast_target *t,
                              const rast_mesh_desc *m, rast_stats *stats)
{
    if (!c)
        return RAST_ERR_ARGS;
    if (c->threads == 1)
        return rast__draw_with(t, m, stats, c->scan);
    rast_result r = rast__validate(t, m);
    if (r != RAST_OK)
        return r;
    c->t = t;
    c->m = m;
    rast__view_init(&c->view, t->width, t->height, rast__draw_na(t, m));
    pthread_mutex_lock(&c->mu);
    atomic_fetch_add(&c->gen, 1u);
    pthread_cond_broadcast(&c->cv);
    pthread_mutex_unlock(&c->mu);
    run_draw(c, 0);
    if (stats) {
        rast_stats st = { 0 };
        st.tris_in = m->tri_count;
        for (int i = 0; i < c->threads; i++)
            rast__stats_add(&st, &c->slots[i].st);
        rast__stats_add(stats, &st);
    }
    return RAST_OK;
}
