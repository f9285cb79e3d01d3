/* fuse_ctx.h - what the drivers of the fuse kernels share between their
 * files (fuse_ctx.c: ISA choice, light, composite, frame; fuse_depth_job.c:
 * the depth test on the pool). Not public API.
 *
 * WHAT IT HOLDS. The ISA's kernel table (one row per ISA, filled in
 * fuse_ctx.c), the context (that table and its thread pool), the pool's
 * run on a context (NULL: on the caller) and the row bands of a task. */
#ifndef EGOFUSE_FUSE_CTX_H
#define EGOFUSE_FUSE_CTX_H

#include "fuse_internal.h"
#include "fuse_pool.h"

typedef struct kernels {
    ef_isa isa;
    int ref;                   /* the reference: axis walk, stages in order */
    fuse__light_fn light;
    fuse__depth_fn depth;
    fuse__depth_mask_fn depth_mask;   /* the depth test on mask bytes */
    fuse__composite_fn comp;   /* SSE2: table-driven, per output row */
    fuse__cover_fn cover;      /* coverage bits of a layer row */
    fuse__opaque_fn opaque;    /* R = V, alpha 255 (transparent spans) */
    fuse__hrow_fn hrow;        /* NULL: no row cache, comp per output row */
    fuse__vrow_fn vrow;
    fuse__hprep_fn hprep;      /* the row cache's per-tile tables (with hrow) */
    fuse__light_span_fn light_span;    /* the same kernels on a span of a row */
    fuse__depth_mspan_fn depth_mspan;
    fuse__cover_span_fn cover_span;
    fuse__light_span_n10_fn light_span_n10;   /* light_span on ef_n10 normals */
} kernels;

struct fuse_context {
    kernels k;
    fuse__pool pool;
    struct fuse__banded *banded;   /* fuse_context_frame_prepare's eye (fuse_ctx.c) */
};

/* The kernels of isa (ref for an ISA this build has no kernels for). */
kernels fuse__kernels_for(ef_isa isa);

/* fn(arg, t, n) for t = 0 .. n-1, t = 0 on the calling thread (ctx NULL:
 * fn(arg, 0, 1)). */
void fuse__ctx_run(fuse_context *ctx, fuse__task_fn fn, void *arg);

/* Band t of n over h rows: [h t / n, h (t + 1) / n). */
static inline void fuse__band(int h, int t, int n, int *y0, int *y1)
{
    *y0 = (int)((int64_t)h * t / n);
    *y1 = (int)((int64_t)h * (t + 1) / n);
}

#endif
