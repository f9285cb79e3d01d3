/* fuse_pool.h - the small thread pool of a fuse_context (fuse_ctx.c).
 * Not public API.
 *
 * WHAT IT DOES. Runs fn(arg, t, n) for t = 0 .. n-1 on n threads, t = 0 on
 * the calling thread, and returns when all are done. Workers spin a little
 * (a frame's stages follow each other within microseconds) and then block
 * on a condition variable; no spinning when there are more threads than
 * CPUs.
 * WHAT IT DOES NOT. No queue, no priorities: one task at a time, from one
 * caller at a time (a fuse_context is used by one thread at a time).
 * USAGE.
 *   fuse__pool p;
 *   if (!fuse__pool_init(&p, 2)) fail();     // p must not move afterwards
 *   fuse__pool_run(&p, fn, arg);
 *   fuse__pool_destroy(&p);
 * fuse__pool_run(NULL, fn, arg) runs fn(arg, 0, 1) on the caller. */
#ifndef EGOFUSE_FUSE_POOL_H
#define EGOFUSE_FUSE_POOL_H

#include <pthread.h>
#include <stdatomic.h>

#include "fuse.h"

typedef void (*fuse__task_fn)(void *arg, int t, int n);

typedef struct fuse__pool {
    int threads;
    pthread_t th[FUSE_MAX_THREADS];
    int started;                 /* worker threads running */
    int spin;                    /* pause rounds before blocking */
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    atomic_uint gen;             /* task generation, bumped per run */
    atomic_int pending;          /* workers still on the current task */
    int quit;
    fuse__task_fn task;
    void *arg;
} fuse__pool;

/* 1 on success; 0 (nothing left to destroy) when a thread or the mutex
 * cannot be made. threads is clamped to 1 .. FUSE_MAX_THREADS. */
int fuse__pool_init(fuse__pool *p, int threads);
void fuse__pool_run(fuse__pool *p, fuse__task_fn fn, void *arg);
void fuse__pool_destroy(fuse__pool *p);

#endif
