/* fuse_pool.c - the thread pool of a fuse_context (fuse_pool.h). */
#include "fuse_pool.h"

#include <stdlib.h>
#include <unistd.h>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define cpu_relax() _mm_pause()
#else
#define cpu_relax() ((void)0)
#endif

/* Pause rounds a worker (or the caller) spins before it blocks on a
 * condition variable: a frame's stages follow each other within
 * microseconds. No spinning when there are more threads than CPUs. */
#define SPIN_ROUNDS 2000

typedef struct worker_arg { fuse__pool *ctx; int t; } worker_arg;

static void *worker(void *p)
{
    fuse__pool *ctx = ((worker_arg *)p)->ctx;
    const int t = ((worker_arg *)p)->t;
    unsigned seen = 0;
    free(p);
    for (;;) {
        fuse__task_fn fn;
        void *arg;
        int i;
        for (i = 0; i < ctx->spin && atomic_load(&ctx->gen) == seen; i++)
            cpu_relax();
        pthread_mutex_lock(&ctx->mu);
        while (atomic_load(&ctx->gen) == seen && !ctx->quit)
            pthread_cond_wait(&ctx->go, &ctx->mu);
        if (ctx->quit) {
            pthread_mutex_unlock(&ctx->mu);
            break;
        }
        seen = atomic_load(&ctx->gen);
        fn = ctx->task;
        arg = ctx->arg;
        pthread_mutex_unlock(&ctx->mu);
        fn(arg, t, ctx->threads);
        pthread_mutex_lock(&ctx->mu);
        if (atomic_fetch_sub(&ctx->pending, 1) == 1)
            pthread_cond_signal(&ctx->done);
        pthread_mutex_unlock(&ctx->mu);
    }
    return NULL;
}

/* fn(arg, t, n) for t = 0 .. n-1, t = 0 on the calling thread. */
void fuse__pool_run(fuse__pool *ctx, fuse__task_fn fn, void *arg)
{
    int i;
    if (ctx == NULL || ctx->threads <= 1) {
        fn(arg, 0, 1);
        return;
    }
    pthread_mutex_lock(&ctx->mu);
    ctx->task = fn;
    ctx->arg = arg;
    atomic_store(&ctx->pending, ctx->threads - 1);
    atomic_fetch_add(&ctx->gen, 1u);
    pthread_cond_broadcast(&ctx->go);
    pthread_mutex_unlock(&ctx->mu);
    fn(arg, 0, ctx->threads);
    for (i = 0; i < ctx->spin && atomic_load(&ctx->pending) > 0; i++)
        cpu_relax();
    pthread_mutex_lock(&ctx->mu);
    while (atomic_load(&ctx->pending) > 0)
        pthread_cond_wait(&ctx->done, &ctx->mu);
    pthread_mutex_unlock(&ctx->mu);
}

static void stop_workers(fuse__pool *ctx)
{
    int i;
    pthread_mutex_lock(&ctx->mu);
    ctx->quit = 1;
    pthread_cond_broadcast(&ctx->go);
    pthread_mutex_unlock(&ctx->mu);
    for (i = 0; i < ctx->started; i++)
        pthread_join(ctx->th[i], NULL);
    ctx->started = 0;
}

int fuse__pool_init(fuse__pool *ctx, int threads)
{
    int i;
    if (threads < 1) threads = 1;
    if (threads > FUSE_MAX_THREADS) threads = FUSE_MAX_THREADS;
    ctx->threads = threads;
    ctx->started = 0;
    ctx->quit = 0;
    {
        const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        ctx->spin = cpus > 0 && threads <= cpus ? SPIN_ROUNDS : 0;
    }
    atomic_init(&ctx->gen, 0u);
    atomic_init(&ctx->pending, 0);
    if (pthread_mutex_init(&ctx->mu, NULL) != 0) return 0;
    pthread_cond_init(&ctx->go, NULL);
    pthread_cond_init(&ctx->done, NULL);
    for (i = 1; i < ctx->threads; i++) {
        worker_arg *a = malloc(sizeof *a);
        if (a == NULL) break;
        a->ctx = ctx;
        a->t = i;
        if (pthread_create(&ctx->th[ctx->started], NULL, worker, a) != 0) {
            free(a);
            break;
        }
        ctx->started++;
    }
    if (ctx->started != ctx->threads - 1) {
        fuse__pool_destroy(ctx);
        return 0;
    }
    return 1;
}

void fuse__pool_destroy(fuse__pool *ctx)
{
    stop_workers(ctx);
    pthread_cond_destroy(&ctx->go);
    pthread_cond_destroy(&ctx->done);
    pthread_mutex_destroy(&ctx->mu);
}
