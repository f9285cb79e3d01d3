/* raster_context.c - the top of the raster room: the ISA dispatch (the
 * one place that names per-ISA kernels), the public entry points that
 * choose them (rast_draw, rast_draw_aa, rast_transform_points/dirs), and
 * the context: an ISA cap, parallel drawing with a small thread pool, and
 * clearing only what the context's draws touched.
 *
 * Layers (each calls only the ones below it; docs/raster.md section 1):
 *   raster_context.c   dispatch, threads, public draws
 *   raster_draw.c, raster_aa.c
 *                      drivers: a mesh through set-up and a given scan
 *   raster_<isa>.c, raster_front_<isa>.c, raster_ref.c
 *                      kernels: row scans, sample scans, vector set-up,
 *                      transforms (intrinsics only here, via src/cpu's
 *                      vector layer or the ISA's own header)
 *   raster_setup.c     the scalar per-triangle set-up the kernels and
 *                      drivers share (clip, snap, edges, planes, cache)
 *
 * Two parallel modes (the bytes never depend on the thread count):
 *
 * Jobs (rast_context_draw_jobs with n >= 2): job i is drawn whole by
 * thread i % threads with the single-thread driver; the targets do not
 * share memory, so the threads never meet before the end of the draw.
 *
 * Bands (rast_context_draw, or a single job). A draw is cut into rounds of
 * threads * BATCH submitted triangles. In a round, thread k sets up
 * triangles [base + k*BATCH, base + (k+1)*BATCH) into its own buffer
 * (clip, snap, setup: the shared scalar code with its own vertex cache),
 * then all threads meet at a barrier, then every thread scans ALL set-up
 * triangles of the round, in submission order, restricted to its rows:
 * 16-row bands, band b belonging to thread b % threads. Every pixel thus
 * sees the same triangles in the same order as on one thread, and a scan
 * restricted to rows writes exactly the bytes of the full scan. Buffers
 * alternate between two sets, so one barrier per round suffices: a thread
 * refills set p in round r+2 only after the barrier of round r+1, which no
 * thread passes before it has finished scanning round r.
 *
 * Waiting. Workers wait for a draw, and threads for each other at a
 * barrier, by spinning briefly (the partner is usually about to arrive)
 * and then blocking on a condition variable, so a descheduled partner on
 * a busy machine costs a wake-up, not a time slice of spinning. */
#include "raster_internal.h"

#include "../cpu/cpu.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define cpu_relax() ef_cpu_relax()

enum {
    BAND_ROWS = RAST__TILE, /* rows per band: one row of dirty tiles */
    BATCH = 256,         /* submitted triangles per thread and round */
    IDLE_SPINS = 20000,  /* pause loops before a worker blocks */
    BARRIER_SPINS = 2000 /* pause loops before a barrier blocks */
};

/* ---- dispatch ----------------------------------------------------------- */

/* The kernels of one ISA. Every function pointer of a row gives the
 * bytes of the reference row (EF_ISA_REF). */
typedef struct isa_kernels {
    rast__scan_rows_fn scan;
    rast__scan_aa_fn scan_aa;
    const rast__setup_isa *setup;
    void (*points)(const float mvp[16], const float *pos, int n, float *clip);
    void (*dirs)(const float m[16], const float *v, int n, float *out);
} isa_kernels;

static const isa_kernels kernels_ref = {
    rast__scan_rows_ref, rast__scan_aa_ref, &rast__setup_isa_ref,
    rast__transform_points_ref, rast__transform_dirs_ref
};
#if defined(__x86_64__)
static const isa_kernels kernels_sse2 = {
    rast__scan_rows_sse2, rast__scan_aa_sse2, &rast__setup_isa_sse2,
    rast__transform_points_ref, rast__transform_dirs_ref
};
/* The vector transforms take 8 (AVX2) or 16 (AVX-512) vertices per step,
 * the rest by the reference (raster_xform.inl). */
static const isa_kernels kernels_avx2 = {
    rast__scan_rows_avx2, rast__scan_aa_avx2, &rast__setup_isa_avx2,
    rast__transform_points_avx2, rast__transform_dirs_avx2
};
static const isa_kernels kernels_avx512 = {
    rast__scan_rows_avx512, rast__scan_aa_avx512, &rast__setup_isa_avx512,
    rast__transform_points_avx512, rast__transform_dirs_avx512
};
#endif
#if defined(__aarch64__) && defined(__ARM_NEON)
static const isa_kernels kernels_neon = {
    rast__scan_rows_neon, rast__scan_aa_neon, &rast__setup_isa_neon,
    rast__transform_points_ref, rast__transform_dirs_ref
};
#endif

static const isa_kernels *kernels_for(int isa)
{
    switch (isa) {
#if defined(__x86_64__)
    case EF_ISA_AVX512: return &kernels_avx512;
    case EF_ISA_AVX2:   return &kernels_avx2;
    case EF_ISA_SSE2:   return &kernels_sse2;
#endif
#if defined(__aarch64__) && defined(__ARM_NEON)
    case EF_ISA_NEON:   return &kernels_neon;
#endif
    default:            break;
    }
    return &kernels_ref;
}

rast__scan_rows_fn rast__scan_for_isa(int isa)
{
    return kernels_for(isa)->scan;
}

rast__scan_aa_fn rast__scan_aa_for_isa(int isa)
{
    return kernels_for(isa)->scan_aa;
}

const rast__setup_isa *rast__setup_for_scan(rast__scan_rows_fn scan)
{
    static const isa_kernels *const all[] = {
#if defined(__x86_64__)
        &kernels_avx512, &kernels_avx2, &kernels_sse2,
#endif
#if defined(__aarch64__) && defined(__ARM_NEON)
        &kernels_neon,
#endif
        &kernels_ref
    };
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        if (all[i]->scan == scan)
            return all[i]->setup;
    return &rast__setup_isa_ref;
}

int rast_draw_isa(void)
{
    return (int)ef_isa_choose(EF_ISA_DEFAULT);
}

rast_result rast__draw_with(const rast_target *t, const rast_mesh_desc *m,
                            rast_stats *stats, rast__scan_rows_fn scan)
{
    rast_result r = rast__validate(t, m);
    if (r != RAST_OK)
        return r;
    rast__draw_valid(t, m, stats, scan, rast__setup_for_scan(scan), NULL);
    return RAST_OK;
}

rast_result rast_draw(const rast_target *t, const rast_mesh_desc *mesh,
                      rast_stats *stats)
{
    return rast__draw_with(t, mesh, stats, rast__scan_for_isa(rast_draw_isa()));
}

rast_result rast_draw_aa(const rast_aa_target *t, const rast_mesh_desc *m,
                         rast_stats *stats)
{
    return rast__draw_aa_with(t, m, stats, rast__scan_aa_for_isa(rast_draw_isa()));
}

void rast_transform_points(const float mvp[16], const float *pos, int n,
                           float *clip)
{
    kernels_for(rast_draw_isa())->points(mvp, pos, n, clip);
}

void rast_transform_dirs(const float m[16], const float *v, int n, float *out)
{
    kernels_for(rast_draw_isa())->dirs(m, v, n, out);
}

/* ---- context ------------------------------------------------------------ */

typedef struct slot {
    rast__tri *buf[2];          /* BATCH * RAST__MAX_FAN each */
    int count[2];
    rast_stats st;
    rast__vcache vc;
    unsigned gen;               /* last draw generation run (workers) */
    _Alignas(64) char pad[64];  /* keep slots on their own cache lines */
} slot;

/* A target whose planes the context knows to be clear except in the
 * tiles marked in `dirty`. */
typedef struct known_target {
    rast_target t;
    rast__tiles *dirty;
    int used;
    int attr_stale; /* the attribute plane was left uncleared (keep_attr) */
} known_target;

struct rast_context {
    int isa, threads;
    rast__scan_rows_fn scan;
    const rast__setup_isa *setup; /* the set-up kernels of the ISA */
    /* Per thread: the vertex buffer of the vector front end (NULL when
     * the ISA has none). Whole-job draws use it. */
    rast__vbuf *vb[RAST_MAX_THREADS];
    slot *slots;
    pthread_t th[RAST_MAX_THREADS];
    int started;
    pthread_mutex_t mu;         /* draw start (gen, quit) */
    pthread_cond_t cv;
    pthread_mutex_t bar_mu;     /* barrier release */
    pthread_cond_t bar_cv;
    _Alignas(64) atomic_uint gen;
    atomic_int quit;
    _Alignas(64) atomic_uint bar_count;
    atomic_uint bar_gen;
    /* The draw being run (written by the caller before gen changes). */
    _Alignas(64) int njobs;
    const rast_target *const *jt;
    const rast_mesh_desc *const *jm;
    rast__tiles *jtiles[RAST_MAX_JOBS]; /* per job: tiles to mark, or NULL */
    known_target known[RAST_CONTEXT_TARGETS];
    int known_next;
};

typedef struct worker_arg {
    rast_context *c;
    int tid;
} worker_arg;

/* All threads meet: spin a little, then block. bar_gen changes only when
 * the last thread arrives, so reading it before arriving is safe. */
static void barrier(rast_context *c)
{
    const unsigned g = atomic_load(&c->bar_gen);
    if (atomic_fetch_add(&c->bar_count, 1u) == (unsigned)c->threads - 1u) {
        atomic_store(&c->bar_count, 0u);
        pthread_mutex_lock(&c->bar_mu);
        atomic_store(&c->bar_gen, g + 1u);
        pthread_cond_broadcast(&c->bar_cv);
        pthread_mutex_unlock(&c->bar_mu);
        return;
    }
    for (int n = 0; n < BARRIER_SPINS; n++) {
        if (atomic_load(&c->bar_gen) != g)
            return;
        cpu_relax();
    }
    pthread_mutex_lock(&c->bar_mu);
    while (atomic_load(&c->bar_gen) == g)
        pthread_cond_wait(&c->bar_cv, &c->bar_mu);
    pthread_mutex_unlock(&c->bar_mu);
}

/* Scans tri into the bands of thread tid (and marks the tiles of those
 * rows: a band is one row of tiles, which no other thread writes). */
static long scan_bands(const rast_context *c, const rast_target *t, int tid,
                       const rast__tri *tri, rast__tiles *tiles)
{
    const int n = c->threads;
    const int b0 = tri->y0 / BAND_ROWS, b1 = tri->y1 / BAND_ROWS;
    long w = 0;
    for (int b = b0 + ((tid - b0 % n) + n) % n; b <= b1; b += n) {
        const int ya = b * BAND_ROWS, yb = ya + BAND_ROWS - 1;
        w += c->scan(t, tri, ya, yb);
        if (tiles)
            rast__tiles_add(tiles, ya > tri->y0 ? ya : tri->y0, yb < tri->y1 ? yb : tri->y1,
                            tri->x0, tri->x1);
    }
    return w;
}

/* One job in band mode, run by every thread. */
static void run_bands(rast_context *c, int tid, int job)
{
    slot *me = &c->slots[tid];
    const rast_target *t = c->jt[job];
    const rast_mesh_desc *m = c->jm[job];
    const int n = c->threads;
    rast__view view;
    rast__view_init(&view, t->width, t->height, rast__draw_na(t, m));
    rast__vcache_reset(&me->vc);
    rast__tiles *tiles = c->jtiles[job];
    int par = 0;
    for (long base = 0; base < m->tri_count; base += (long)n * BATCH, par ^= 1) {
        long lo = base + (long)tid * BATCH, hi = lo + BATCH;
        if (hi > m->tri_count)
            hi = m->tri_count;
        me->count[par] = lo < hi ? rast__prepare_range(&view, m, (int)lo, (int)hi, &me->vc,
                                                       me->buf[par], &me->st, c->setup)
                                 : 0;
        barrier(c);
        for (int s = 0; s < n; s++) {
            const slot *o = &c->slots[s];
            for (int i = 0; i < o->count[par]; i++) {
                const rast__tri *r = &o->buf[par][i];
                me->st.pixels_written += scan_bands(c, t, tid, r, tiles);
            }
        }
    }
    barrier(c);
}

static void run_draw(rast_context *c, int tid)
{
    slot *me = &c->slots[tid];
    memset(&me->st, 0, sizeof me->st);
    /* The draw's fields are read before this thread's last barrier: once
     * it is passed, the caller may already be setting up the next draw. */
    const int nj = c->njobs;
    if (nj >= 2) {
        for (int j = tid; j < nj; j += c->threads)
            rast__draw_valid_vb(c->jt[j], c->jm[j], &me->st, c->scan, c->setup, c->jtiles[j],
                                c->vb[tid]);
        barrier(c);
    } else if (nj == 1) {
        run_bands(c, tid, 0);
    } else {
        barrier(c);
    }
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
        pthread_cond_destroy(&c->bar_cv);
        pthread_mutex_destroy(&c->bar_mu);
    }
    if (c->slots)
        for (int i = 0; i < c->threads; i++) {
            free(c->slots[i].buf[0]);
            free(c->slots[i].buf[1]);
        }
    free(c->slots);
    for (int i = 0; i < c->threads; i++)
        rast__vbuf_free(c->vb[i]);
    free(c->known[0].dirty);
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
    c->setup = rast__setup_for_scan(c->scan);
    /* Dirty tiles of the known targets, one block. */
    c->known[0].dirty = malloc((size_t)RAST_CONTEXT_TARGETS * sizeof(rast__tiles));
    if (!c->known[0].dirty) {
        free(c);
        return NULL;
    }
    for (int i = 1; i < RAST_CONTEXT_TARGETS; i++)
        c->known[i].dirty = c->known[0].dirty + i;
    if (c->threads > 1) {
        pthread_mutex_init(&c->mu, NULL);
        pthread_cond_init(&c->cv, NULL);
        pthread_mutex_init(&c->bar_mu, NULL);
        pthread_cond_init(&c->bar_cv, NULL);
    }
    /* Vertex buffers (address space for RAST__VX_CAP vertices; only the
     * pages a draw uses are touched). */
    if (c->setup->vpass)
        for (int i = 0; i < c->threads; i++)
            if (!(c->vb[i] = rast__vbuf_alloc(RAST__VX_CAP)))
                goto fail;
    if (c->threads == 1)
        return c;

    c->slots = calloc((size_t)(unsigned)c->threads, sizeof *c->slots);
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

/* ---- known targets (rast_context_clear) --------------------------------- */

static int same_target(const rast_target *a, const rast_target *b)
{
    return a->width == b->width && a->height == b->height && a->depth == b->depth &&
           a->mask == b->mask && a->attr == b->attr && a->attr_count == b->attr_count &&
           (!a->depth || a->depth_stride == b->depth_stride) &&
           a->mask_stride == b->mask_stride &&
           (!a->attr || a->attr_stride == b->attr_stride) && a->attr_n10 == b->attr_n10 &&
           (!a->attr_n10 || a->attr_n10_stride == b->attr_n10_stride);
}

static known_target *find_known(rast_context *c, const rast_target *t)
{
    for (int i = 0; i < RAST_CONTEXT_TARGETS; i++)
        if (c->known[i].used && same_target(&c->known[i].t, t))
            return &c->known[i];
    return NULL;
}

/* Clears columns x0..x1 of row y of every plane (as rast_target_clear
 * does for whole rows); the attribute plane only when attr. */
static void clear_span(const rast_target *t, int y, int x0, int x1, int attr)
{
    const size_t n = (size_t)(x1 - x0 + 1);
    if (t->depth)
        rast__fill_depth(t->depth + (size_t)y * (size_t)t->depth_stride + x0, n);
    memset(t->mask + (size_t)y * (size_t)t->mask_stride + x0, 0, n);
    if (attr && t->attr && t->attr_count > 0)
        memset(t->attr + (size_t)y * (size_t)t->attr_stride +
                   (size_t)x0 * (size_t)t->attr_count,
               0, n * (size_t)t->attr_count * sizeof(float));
    if (attr && t->attr_n10)
        memset(t->attr_n10 + (size_t)y * (size_t)t->attr_n10_stride + x0, 0,
               n * sizeof(uint32_t));
}

/* Asks for the lines of columns x0..x1 of row y of every plane (a hint:
 * the clear of a cold target waits on each line's fetch before the store;
 * asking one row ahead overlaps them, 0.82-0.86 of the time for the
 * sample model's ~290 tiles per eye with the planes evicted). */
static void prefetch_span(const rast_target *t, int y, int x0, int x1, int attr)
{
    const size_t n = (size_t)(x1 - x0 + 1);
    if (t->depth) {
        const char *p = (const char *)(t->depth + (size_t)y * (size_t)t->depth_stride + x0);
        for (size_t o = 0; o < n * sizeof(float); o += 64)
            __builtin_prefetch(p + o, 1, 3);
    }
    const char *m = (const char *)(t->mask + (size_t)y * (size_t)t->mask_stride + x0);
    for (size_t o = 0; o < n; o += 64)
        __builtin_prefetch(m + o, 1, 3);
    if (attr && t->attr && t->attr_count > 0) {
        const char *a = (const char *)(t->attr + (size_t)y * (size_t)t->attr_stride +
                                       (size_t)x0 * (size_t)t->attr_count);
        for (size_t o = 0; o < n * (size_t)t->attr_count * sizeof(float); o += 64)
            __builtin_prefetch(a + o, 1, 3);
    }
    if (attr && t->attr_n10) {
        const char *a = (const char *)(t->attr_n10 + (size_t)y * (size_t)t->attr_n10_stride + x0);
        for (size_t o = 0; o < n * sizeof(uint32_t); o += 64)
            __builtin_prefetch(a + o, 1, 3);
    }
}

/* The next run of marked tiles of tile row ty at or after tile *tx (of
 * tw): tiles *tx .. *te, 1; or 0 when the row has none left. */
static int next_run(const rast__tiles *d, int ty, int tw, int *tx, int *te)
{
    int a = *tx;
    while (a < tw && !((d->bits[ty][a / 64] >> (a % 64)) & 1u))
        a++;
    if (a >= tw)
        return 0;
    int e = a;
    while (e + 1 < tw && ((d->bits[ty][(e + 1) / 64] >> ((e + 1) % 64)) & 1u))
        e++;
    *tx = a;
    *te = e;
    return 1;
}

/* The last pixel row of tile row ty, the last pixel column of tile te. */
static int tile_y1(const rast_target *t, int ty)
{
    const int y = ty * RAST__TILE + RAST__TILE - 1;
    return y < t->height - 1 ? y : t->height - 1;
}

static int tile_x1(const rast_target *t, int te)
{
    const int x = (te + 1) * RAST__TILE - 1;
    return x < t->width - 1 ? x : t->width - 1;
}

/* rast_context_clear (attr 1) and rast_context_clear_keep_attr (attr 0). */
static void context_clear(rast_context *c, const rast_target *t, int attr)
{
    if (!c || !t || !t->mask || t->width <= 0 || t->height <= 0 ||
        t->width > RAST_MAX_DIM || t->height > RAST_MAX_DIM) {
        rast_target_clear(t);
        return;
    }
    const int tw = (t->width + RAST__TILE - 1) / RAST__TILE;
    const int th = (t->height + RAST__TILE - 1) / RAST__TILE;
    known_target *k = find_known(c, t);
    if (k && attr && k->attr_stale) {
        /* the attributes outside the marked tiles are not known clear */
        rast_target_clear(t);
        k->attr_stale = 0;
    } else if (k) {
        /* Runs of marked tiles of each tile row, row by row. */
        for (int ty = 0; ty < th; ty++) {
            const int ya = ty * RAST__TILE, yb = tile_y1(t, ty);
            for (int tx = 0, te; next_run(k->dirty, ty, tw, &tx, &te); tx = te + 1) {
                const int x0 = tx * RAST__TILE, x1 = tile_x1(t, te);
                for (int y = ya; y <= yb; y++) {
                    if (y < yb)
                        prefetch_span(t, y + 1, x0, x1, attr);
                    clear_span(t, y, x0, x1, attr);
                }
            }
        }
        if (!attr && ((t->attr && t->attr_count > 0) || t->attr_n10))
            k->attr_stale = 1;
    } else {
        rast_target_clear(t);
        k = &c->known[c->known_next];
        c->known_next = (c->known_next + 1) % RAST_CONTEXT_TARGETS;
        k->t = *t;
        k->used = 1;
        k->attr_stale = 0;
    }
    for (int ty = 0; ty < th; ty++)
        memset(k->dirty->bits[ty], 0, sizeof k->dirty->bits[ty]);
}

void rast_context_clear(rast_context *c, const rast_target *t)
{
    context_clear(c, t, 1);
}

void rast_context_clear_keep_attr(rast_context *c, const rast_target *t)
{
    context_clear(c, t, 0);
}

/* Nonzero bytes of m[0..n-1]. */
static long count_nonzero(const uint8_t *m, size_t n)
{
    size_t i = 0;
    long zeros = 0;
    /* 16 byte counters, at most 255 steps each, then summed: the
     * compilers make the inner loop one byte compare and subtract per 16
     * bytes (the SSE2 code this file had by hand). */
    while (i + 16 <= n) {
        const size_t end = n - i >= 255 * 16 ? i + 255 * 16 : i + ((n - i) & ~(size_t)15);
        uint8_t acc[16] = { 0 };
        for (; i < end; i += 16)
            for (int k = 0; k < 16; k++)
                acc[k] = (uint8_t)(acc[k] + (m[i + (size_t)k] == 0));
        for (int k = 0; k < 16; k++)
            zeros += acc[k];
    }
    for (; i < n; i++)
        zeros += m[i] == 0;
    return (long)n - zeros;
}

long rast_context_count(rast_context *c, const rast_target *t)
{
    if (!t || !t->mask || t->width <= 0 || t->height <= 0 || t->width > RAST_MAX_DIM ||
        t->height > RAST_MAX_DIM || t->mask_stride < t->width)
        return 0;
    const known_target *k = c ? find_known(c, t) : NULL;
    long n = 0;
    if (!k) {
        for (int y = 0; y < t->height; y++)
            n += count_nonzero(t->mask + (size_t)y * (size_t)t->mask_stride, (size_t)t->width);
        return n;
    }
    const int tw = (t->width + RAST__TILE - 1) / RAST__TILE;
    const int th = (t->height + RAST__TILE - 1) / RAST__TILE;
    for (int ty = 0; ty < th; ty++) {
        const int ya = ty * RAST__TILE, yb = tile_y1(t, ty);
        for (int tx = 0, te; next_run(k->dirty, ty, tw, &tx, &te); tx = te + 1) {
            const int x0 = tx * RAST__TILE, x1 = tile_x1(t, te);
            for (int y = ya; y <= yb; y++)
                n += count_nonzero(t->mask + (size_t)y * (size_t)t->mask_stride + x0,
                                   (size_t)(x1 - x0 + 1));
        }
    }
    return n;
}

void rast_context_forget(rast_context *c)
{
    if (!c)
        return;
    for (int i = 0; i < RAST_CONTEXT_TARGETS; i++)
        c->known[i].used = 0;
    c->known_next = 0;
}

/* ---- draws -------------------------------------------------------------- */

/* Byte range [lo, hi) of a plane of h rows. */
static int ranges_overlap(const void *a, size_t sa, const void *b, size_t sb)
{
    const char *pa = a, *pb = b;
    return a && b && pa < pb + sb && pb < pa + sa;
}

static size_t plane_bytes(int h, int stride, size_t row, size_t elem)
{
    return ((size_t)(h - 1) * (size_t)stride + row) * elem;
}

/* 1 when two valid targets share memory (any plane with any plane). */
static int targets_overlap(const rast_target *a, const rast_target *b)
{
    const void *pa[4] = { a->depth, a->mask, a->attr_count > 0 ? a->attr : NULL, a->attr_n10 };
    const void *pb[4] = { b->depth, b->mask, b->attr_count > 0 ? b->attr : NULL, b->attr_n10 };
    size_t sa[4] = { a->depth ? plane_bytes(a->height, a->depth_stride, (size_t)a->width, 4) : 0,
                     plane_bytes(a->height, a->mask_stride, (size_t)a->width, 1),
                     pa[2] ? plane_bytes(a->height, a->attr_stride,
                                         (size_t)a->width * (size_t)a->attr_count, 4) : 0,
                     pa[3] ? plane_bytes(a->height, a->attr_n10_stride, (size_t)a->width, 4) : 0 };
    size_t sb[4] = { b->depth ? plane_bytes(b->height, b->depth_stride, (size_t)b->width, 4) : 0,
                     plane_bytes(b->height, b->mask_stride, (size_t)b->width, 1),
                     pb[2] ? plane_bytes(b->height, b->attr_stride,
                                         (size_t)b->width * (size_t)b->attr_count, 4) : 0,
                     pb[3] ? plane_bytes(b->height, b->attr_n10_stride, (size_t)b->width, 4) : 0 };
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (ranges_overlap(pa[i], sa[i], pb[j], sb[j]))
                return 1;
    return 0;
}

rast_result rast_context_draw_jobs(rast_context *c, int n, const rast_target *const t[],
                                   const rast_mesh_desc *const mesh[], rast_stats *stats)
{
    if (!c || n < 0 || n > RAST_MAX_JOBS || (n > 0 && (!t || !mesh)))
        return RAST_ERR_ARGS;
    for (int i = 0; i < n; i++) {
        rast_result r = rast__validate_desc(t[i], mesh[i]);
        if (r != RAST_OK)
            return r;
        /* The index check once per index set: the eyes of a stereo frame
         * draw the same indices over their own clip coordinates. */
        int seen = 0;
        for (int j = 0; j < i && !seen; j++)
            seen = mesh[j]->indices == mesh[i]->indices &&
                   mesh[j]->tri_count == mesh[i]->tri_count &&
                   mesh[j]->vertex_count == mesh[i]->vertex_count;
        if (seen)
            continue;
        if ((r = rast__validate_indices(mesh[i])) != RAST_OK)
            return r;
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++)
            if (targets_overlap(t[i], t[j]))
                return RAST_ERR_ARGS;
    rast_stats st = { 0 };
    for (int i = 0; i < n; i++) {
        known_target *k = find_known(c, t[i]);
        c->jtiles[i] = k ? k->dirty : NULL;
    }
    if (c->threads == 1 || n == 0) {
        for (int i = 0; i < n; i++)
            rast__draw_valid_vb(t[i], mesh[i], &st, c->scan, c->setup, c->jtiles[i], c->vb[0]);
    } else {
        c->njobs = n;
        c->jt = t;
        c->jm = mesh;
        pthread_mutex_lock(&c->mu);
        atomic_fetch_add(&c->gen, 1u);
        pthread_cond_broadcast(&c->cv);
        pthread_mutex_unlock(&c->mu);
        run_draw(c, 0);
        for (int k = 0; k < c->threads; k++)
            rast__stats_add(&st, &c->slots[k].st);
        st.tris_in = 0;
        for (int i = 0; i < n; i++)
            st.tris_in += mesh[i]->tri_count;
    }
    if (stats)
        rast__stats_add(stats, &st);
    return RAST_OK;
}

rast_result rast_context_draw(rast_context *c, const rast_target *t,
                              const rast_mesh_desc *m, rast_stats *stats)
{
    if (!c)
        return RAST_ERR_ARGS;
    const rast_target *const tt[1] = { t };
    const rast_mesh_desc *const mm[1] = { m };
    return rast_context_draw_jobs(c, 1, tt, mm, stats);
}

rast_result rast_context_draw_aa(rast_context *c, const rast_aa_target *t,
                                 const rast_mesh_desc *m, rast_stats *stats)
{
    if (!c)
        return RAST_ERR_ARGS;
    return rast__draw_aa_with(t, m, stats, rast__scan_aa_for_isa(c->isa));
}
