/* fuse_ctx.c - the drivers of the fuse kernels: ISA choice, row bands on a
 * small thread pool, fuse_light / fuse_composite (which dispatch), and the
 * per-frame entry fuse_context_frame. The row kernels are in fuse_ref.c
 * (the reference) and fuse_{sse2,avx2,avx512}.c; every row is independent,
 * so the bytes do not depend on the ISA, the thread count or the banding. */
#include "fuse_internal.h"

#include <pthread.h>
#include <stdatomic.h>
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

typedef struct kernels {
    ef_isa isa;
    fuse__light_fn light;
    fuse__composite_fn comp;   /* NULL: the reference axis walk */
} kernels;

static kernels kernels_for(ef_isa isa)
{
    kernels k;
    k.isa = isa;
    switch (isa) {
    case EF_ISA_AVX512:
        k.light = fuse__light_row_avx512;
        k.comp = fuse__composite_cols_avx512;
        break;
    case EF_ISA_AVX2:
        k.light = fuse__light_row_avx2;
        k.comp = fuse__composite_cols_avx2;
        break;
    case EF_ISA_SSE2:
        k.light = fuse__light_row_sse2;
        k.comp = fuse__composite_cols_sse2;
        break;
    default:
        k.isa = EF_ISA_REF;
        k.light = fuse__light_row_ref;
        k.comp = NULL;
        break;
    }
    return k;
}

/* ---- the thread pool --------------------------------------------------- */

typedef void (*task_fn)(void *arg, int t, int n);

struct fuse_context {
    kernels k;
    int threads;
    pthread_t th[FUSE_MAX_THREADS];
    int started;                 /* worker threads running */
    int spin;                    /* pause rounds before blocking */
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    atomic_uint gen;             /* task generation, bumped per run */
    atomic_int pending;          /* workers still on the current task */
    int quit;
    task_fn task;
    void *arg;
};

typedef struct worker_arg { fuse_context *ctx; int t; } worker_arg;

static void *worker(void *p)
{
    fuse_context *ctx = ((worker_arg *)p)->ctx;
    const int t = ((worker_arg *)p)->t;
    unsigned seen = 0;
    free(p);
    for (;;) {
        task_fn fn;
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
static void run(fuse_context *ctx, task_fn fn, void *arg)
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

static void stop_workers(fuse_context *ctx)
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

fuse_context *fuse_context_create(const fuse_context_desc *desc)
{
    fuse_context_desc d = {EF_ISA_DEFAULT, 1};
    fuse_context *ctx;
    int i;
    if (desc != NULL) d = *desc;
    if (d.threads < 1) d.threads = 1;
    if (d.threads > FUSE_MAX_THREADS) d.threads = FUSE_MAX_THREADS;
    if ((unsigned)d.max_isa >= EF_ISA_COUNT) d.max_isa = EF_ISA_DEFAULT;
    ctx = calloc(1, sizeof *ctx);
    if (ctx == NULL) return NULL;
    ctx->k = kernels_for(ef_isa_choose(d.max_isa));
    ctx->threads = d.threads;
    {
        const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        ctx->spin = cpus > 0 && d.threads <= cpus ? SPIN_ROUNDS : 0;
    }
    atomic_init(&ctx->gen, 0u);
    atomic_init(&ctx->pending, 0);
    if (pthread_mutex_init(&ctx->mu, NULL) != 0) {
        free(ctx);
        return NULL;
    }
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
        fuse_context_destroy(ctx);
        return NULL;
    }
    return ctx;
}

void fuse_context_destroy(fuse_context *ctx)
{
    if (ctx == NULL) return;
    stop_workers(ctx);
    pthread_cond_destroy(&ctx->go);
    pthread_cond_destroy(&ctx->done);
    pthread_mutex_destroy(&ctx->mu);
    free(ctx);
}

ef_isa fuse_context_isa(const fuse_context *ctx)
{
    return ctx != NULL ? ctx->k.isa : EF_ISA_DEFAULT;
}

int fuse_context_threads(const fuse_context *ctx)
{
    return ctx != NULL ? ctx->threads : 0;
}

/* ---- stage bodies ------------------------------------------------------ */

static uint8_t *row_of(const fuse_image *im, int y)
{
    return im->pixels + (size_t)y * (size_t)im->stride;
}

typedef struct light_job {
    const kernels *k;
    fuse__light_prep prep;
    fuse_image P, out;
    const uint8_t *mask;
    const float *normal;
    int mask_stride, normal_stride;
} light_job;

static int mask_row_empty(const uint8_t *m, int w)
{
    uint64_t acc = 0;
    int x = 0;
    for (; x + 8 <= w; x += 8) {
        uint64_t t;
        memcpy(&t, m + x, 8);
        acc |= t;
    }
    for (; x < w; x++) acc |= m[x];
    return acc == 0;
}

static void light_rows(const light_job *j, int y0, int y1)
{
    const int w = j->P.width;
    int y;
    for (y = y0; y < y1; y++) {
        const uint8_t *m = j->mask + (size_t)y * (size_t)j->mask_stride;
        uint8_t *o = row_of(&j->out, y);
        if (mask_row_empty(m, w)) {     /* the rows above and below the hand */
            memset(o, 0, 4u * (size_t)w);
            continue;
        }
        j->k->light(&j->prep, y, w, row_of(&j->P, y), m,
                    j->normal + (size_t)y * (size_t)j->normal_stride, o);
    }
}

typedef struct comp_job {
    const kernels *k;
    fuse_image Q, V, out;
    int vx, vy, vw, vh;
    int in_place;
} comp_job;

/* Rows [y0, y1) of the output. The ISA paths go through column tables of
 * FUSE__TILE columns; the reference walks fuse__axis as fuse_ref.c does. */
static void comp_rows(const comp_job *j, int y0, int y1)
{
    const size_t row_bytes = 4u * (size_t)j->V.width;
    const int sw = j->Q.width, sh = j->Q.height;
    fuse__cols cols;
    int y, c0;
    /* rows outside the viewport and the columns left and right of it */
    if (!j->in_place)
        for (y = y0; y < y1; y++) {
            const uint8_t *v = row_of(&j->V, y);
            uint8_t *o = row_of(&j->out, y);
            if (y < j->vy || y >= j->vy + j->vh) {
                memcpy(o, v, row_bytes);
                continue;
            }
            memcpy(o, v, 4u * (size_t)j->vx);
            memcpy(o + 4 * (size_t)(j->vx + j->vw), v + 4 * (size_t)(j->vx + j->vw),
                   4u * (size_t)(j->V.width - j->vx - j->vw));
        }
    if (y0 < j->vy) y0 = j->vy;
    if (y1 > j->vy + j->vh) y1 = j->vy + j->vh;
    if (j->k->comp == NULL) {
        fuse__axis ax;
        fuse__axis_init(&ax, sw, j->vw);
        for (y = y0; y < y1; y++) {
            const int32_t pos = fuse__src_pos(y - j->vy, sh, j->vh);
            const int iy = pos >> 16, iy1 = iy + 1 < sh ? iy + 1 : sh - 1;
            fuse__composite_row_ref(row_of(&j->Q, iy), row_of(&j->Q, iy1),
                                    ((uint32_t)pos >> 8) & 255u, ax, sw,
                                    row_of(&j->V, y) + 4 * (size_t)j->vx,
                                    row_of(&j->out, y) + 4 * (size_t)j->vx, j->vw);
        }
        return;
    }
    for (c0 = 0; c0 < j->vw; c0 += FUSE__TILE) {
        const int n = j->vw - c0 < FUSE__TILE ? j->vw - c0 : FUSE__TILE;
        const size_t off = 4 * ((size_t)j->vx + (size_t)c0);
        fuse__cols_fill(&cols, sw, j->vw, c0, n);
        for (y = y0; y < y1; y++) {
            const int32_t pos = fuse__src_pos(y - j->vy, sh, j->vh);
            const int iy = pos >> 16, iy1 = iy + 1 < sh ? iy + 1 : sh - 1;
            j->k->comp(row_of(&j->Q, iy), row_of(&j->Q, iy1),
                       ((uint32_t)pos >> 8) & 255u, &cols, 0, n, sw,
                       row_of(&j->V, y) + off, row_of(&j->out, y) + off);
        }
    }
}

/* Band t of n over h rows: [h t / n, h (t + 1) / n). */
static void band(int h, int t, int n, int *y0, int *y1)
{
    *y0 = (int)((int64_t)h * t / n);
    *y1 = (int)((int64_t)h * (t + 1) / n);
}

static void light_task(void *arg, int t, int n)
{
    const light_job *j = arg;
    int y0, y1;
    band(j->P.height, t, n, &y0, &y1);
    light_rows(j, y0, y1);
}

static void comp_task(void *arg, int t, int n)
{
    const comp_job *j = arg;
    int y0, y1;
    band(j->V.height, t, n, &y0, &y1);
    comp_rows(j, y0, y1);
}

/* ---- public entries ---------------------------------------------------- */

static fuse_result light_with(fuse_context *ctx, const kernels *k,
                              const fuse_lighting *L, const fuse_intrinsics *K,
                              const fuse_image *P, const uint8_t *mask,
                              int mask_stride, const float *normal,
                              int normal_stride, fuse_image *out)
{
    light_job j;
    fuse_result r = fuse__light_check(L, K, P, mask, mask_stride, normal,
                                      normal_stride, out, &j.prep);
    if (r != FUSE_OK) return r;
    j.k = k;
    j.P = *P;
    j.out = *out;
    j.mask = mask;
    j.normal = normal;
    j.mask_stride = mask_stride;
    j.normal_stride = normal_stride;
    run(ctx, light_task, &j);
    return FUSE_OK;
}

static fuse_result comp_with(fuse_context *ctx, const kernels *k,
                             const fuse_image *Q, const fuse_image *V,
                             int vp_x0, int vp_y0, int vp_w, int vp_h,
                             fuse_image *out)
{
    comp_job j;
    fuse_result r = fuse__composite_check(Q, V, vp_x0, vp_y0, vp_w, vp_h, out);
    if (r != FUSE_OK) return r;
    j.k = k;
    j.Q = *Q;
    j.V = *V;
    j.out = *out;
    j.vx = vp_x0;
    j.vy = vp_y0;
    j.vw = vp_w;
    j.vh = vp_h;
    j.in_place = fuse__same_image(out, V);
    run(ctx, comp_task, &j);
    return FUSE_OK;
}

fuse_result fuse_light(const fuse_lighting *L, const fuse_intrinsics *K,
                       const fuse_image *P, const uint8_t *mask,
                       int mask_stride, const float *normal,
                       int normal_stride, fuse_image *out)
{
    const kernels k = kernels_for(ef_isa_choose(EF_ISA_DEFAULT));
    return light_with(NULL, &k, L, K, P, mask, mask_stride, normal,
                      normal_stride, out);
}

fuse_result fuse_composite(const fuse_image *Q, const fuse_image *V,
                           int vp_x0, int vp_y0, int vp_w, int vp_h,
                           fuse_image *out)
{
    const kernels k = kernels_for(ef_isa_choose(EF_ISA_DEFAULT));
    return comp_with(NULL, &k, Q, V, vp_x0, vp_y0, vp_w, vp_h, out);
}

fuse_result fuse_context_light(fuse_context *ctx, const fuse_lighting *L,
                               const fuse_intrinsics *K, const fuse_image *P,
                               const uint8_t *mask, int mask_stride,
                               const float *normal, int normal_stride,
                               fuse_image *out)
{
    if (ctx == NULL) return FUSE_ERR_ARGS;
    return light_with(ctx, &ctx->k, L, K, P, mask, mask_stride, normal,
                      normal_stride, out);
}

fuse_result fuse_context_composite(fuse_context *ctx, const fuse_image *Q,
                                   const fuse_image *V, int vp_x0, int vp_y0,
                                   int vp_w, int vp_h, fuse_image *out)
{
    if (ctx == NULL) return FUSE_ERR_ARGS;
    return comp_with(ctx, &ctx->k, Q, V, vp_x0, vp_y0, vp_w, vp_h, out);
}

/* ---- a whole frame ------------------------------------------------------- */

typedef struct eye_job {
    light_job light;
    comp_job comp;
    const fuse_depth *depth;
} eye_job;

typedef struct frame_job {
    eye_job eyes[FUSE_MAX_THREADS];
    int count;
} frame_job;

static void eye_light_depth(const eye_job *e, int y0, int y1)
{
    light_rows(&e->light, y0, y1);
    if (e->depth != NULL)
        fuse__depth_rows(e->depth, &e->light.out, e->comp.vx, e->comp.vy,
                         e->comp.vw, e->comp.vh, y0, y1);
}

/* count a multiple of n: thread t takes eyes t, t + n, ... whole */
static void frame_whole_task(void *arg, int t, int n)
{
    const frame_job *f = arg;
    int e;
    for (e = t; e < f->count; e += n) {
        eye_light_depth(&f->eyes[e], 0, f->eyes[e].light.P.height);
        comp_rows(&f->eyes[e].comp, 0, f->eyes[e].comp.V.height);
    }
}

static void frame_light_task(void *arg, int t, int n)
{
    const frame_job *f = arg;
    int e, y0, y1;
    for (e = 0; e < f->count; e++) {
        band(f->eyes[e].light.P.height, t, n, &y0, &y1);
        eye_light_depth(&f->eyes[e], y0, y1);
    }
}

static void frame_comp_task(void *arg, int t, int n)
{
    const frame_job *f = arg;
    int e, y0, y1;
    for (e = 0; e < f->count; e++) {
        band(f->eyes[e].comp.V.height, t, n, &y0, &y1);
        comp_rows(&f->eyes[e].comp, y0, y1);
    }
}

fuse_result fuse_context_frame(fuse_context *ctx, const fuse_eye *eyes, int count)
{
    frame_job f;
    int e;
    if (ctx == NULL || eyes == NULL || count < 1 || count > FUSE_MAX_THREADS)
        return FUSE_ERR_ARGS;
    f.count = count;
    for (e = 0; e < count; e++) {
        const fuse_eye *s = &eyes[e];
        eye_job *j = &f.eyes[e];
        fuse_result r = fuse__light_check(s->lighting, s->intrinsics, &s->P, s->mask,
                                          s->mask_stride, s->normal, s->normal_stride,
                                          &s->Q, &j->light.prep);
        if (r == FUSE_OK && s->depth != NULL)
            r = fuse__depth_check(s->depth, &s->Q, s->vp_x0, s->vp_y0, s->vp_w, s->vp_h);
        if (r == FUSE_OK)
            r = fuse__composite_check(&s->Q, &s->V, s->vp_x0, s->vp_y0, s->vp_w,
                                      s->vp_h, &s->out);
        if (r == FUSE_OK && s->depth != NULL &&
            (s->depth->scene_width != s->V.width || s->depth->scene_height != s->V.height))
            r = FUSE_ERR_SIZE;
        if (r == FUSE_OK && fuse__same_image(&s->P, &s->Q))
            r = FUSE_ERR_ARGS;   /* Q is a scratch layer of its own */
        if (r != FUSE_OK) return r;
        j->light.k = &ctx->k;
        j->light.P = s->P;
        j->light.out = s->Q;
        j->light.mask = s->mask;
        j->light.normal = s->normal;
        j->light.mask_stride = s->mask_stride;
        j->light.normal_stride = s->normal_stride;
        j->comp.k = &ctx->k;
        j->comp.Q = s->Q;
        j->comp.V = s->V;
        j->comp.out = s->out;
        j->comp.vx = s->vp_x0;
        j->comp.vy = s->vp_y0;
        j->comp.vw = s->vp_w;
        j->comp.vh = s->vp_h;
        j->comp.in_place = fuse__same_image(&s->out, &s->V);
        j->depth = s->depth;
    }
    /* one eye's writes must not land in another eye's inputs */
    for (e = 0; e < count; e++) {
        int o;
        for (o = 0; o < count; o++) {
            if (o == e) continue;
            if (fuse__overlap(&eyes[e].Q, &eyes[o].Q) || fuse__overlap(&eyes[e].out, &eyes[o].out) ||
                fuse__overlap(&eyes[e].out, &eyes[o].V) || fuse__overlap(&eyes[e].Q, &eyes[o].V) ||
                fuse__overlap(&eyes[e].Q, &eyes[o].P) || fuse__overlap(&eyes[e].out, &eyes[o].Q))
                return FUSE_ERR_ARGS;
        }
    }
    if (count % ctx->threads == 0) {
        run(ctx, frame_whole_task, &f);
    } else {
        run(ctx, frame_light_task, &f);
        run(ctx, frame_comp_task, &f);
    }
    return FUSE_OK;
}
