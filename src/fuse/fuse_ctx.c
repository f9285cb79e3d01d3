/* fuse_ctx.c - the drivers of the fuse kernels: ISA choice, row bands on a
 * small thread pool (fuse_pool.c), fuse_light / fuse_composite (which dispatch), and the
 * per-frame entry fuse_context_frame. The row kernels are in fuse_ref.c
 * (the reference), fuse_simd.inl (written once on the vector layer) and
 * fuse_{sse2,avx2,avx512,neon}.c; every row is independent,
 * so the bytes do not depend on the ISA, the thread count or the banding.
 * The kernel table and the context are declared in fuse_ctx.h; the depth
 * test's job is fuse_depth_job.c.
 *
 * WHY ONE FILE OF ABOUT 1150 LINES: one job, driving the row kernels over an
 * eye's rows. The single-stage entries, the interleaved whole frame and the
 * row bands that pipe_frame hands to either thread (fuse_context_frame_prepare
 * / _band / _finish) all run the same static row machinery (the lit spans,
 * the composite's scratch, tiles and row cache, the border rows), which the
 * compiler inlines into each; a split would turn about twenty of these into
 * cross-file internals of fuse_ctx.h. */
#include "fuse_internal.h"

#include <stdlib.h>

#include "fuse_ctx.h"
#include "fuse_edge.h"

/* Layer rows whose mask span the interleaved frame keeps (comp_scratch.span):
 * more than the rows lit ahead of the composite (FUSE_CHUNK + 2). */
#define SPAN_RING 64

/* The ISA's kernels, one row per ISA (the one dispatch table of the room):
 * the ones of fuse_simd.inl (written once on the vector layer: light,
 * depth, depth on the mask, cover, opaque) by ISA suffix, then the
 * composite: SSE2 and NEON per output row (fuse_simd.inl too), AVX2 /
 * AVX-512 through the row cache (hrow, vrow, per ISA). */
#define SIMD_KERNELS(sfx) fuse__light_row_##sfx, fuse__depth_row_##sfx, fuse__depth_mrow_##sfx
#define SIMD_COVER(sfx) fuse__cover_row_##sfx, fuse__opaque_##sfx
#define SIMD_SPANS(sfx) fuse__light_span_##sfx, fuse__depth_mspan_##sfx, fuse__cover_span_##sfx, \
    fuse__light_span_n10_##sfx

kernels fuse__kernels_for(ef_isa isa)
{
    static const kernels ref = {EF_ISA_REF, 1, SIMD_KERNELS(ref), NULL, SIMD_COVER(ref), NULL, NULL,
                                NULL, SIMD_SPANS(ref)};
    static const kernels sse2 = {EF_ISA_SSE2, 0, SIMD_KERNELS(sse2), fuse__composite_cols_sse2,
                                 SIMD_COVER(sse2), NULL, NULL, NULL, SIMD_SPANS(sse2)};
    static const kernels avx2 = {EF_ISA_AVX2, 0, SIMD_KERNELS(avx2), NULL, SIMD_COVER(avx2),
                                 fuse__hrow_avx2, fuse__vrow_avx2, fuse__hprep_avx2, SIMD_SPANS(avx2)};
    static const kernels avx512 = {EF_ISA_AVX512, 0, SIMD_KERNELS(avx512), NULL, SIMD_COVER(avx512),
                                   fuse__hrow_avx512, fuse__vrow_avx512, fuse__hprep_avx512,
                                   SIMD_SPANS(avx512)};
    static const kernels neon = {EF_ISA_NEON, 0, SIMD_KERNELS(neon), fuse__composite_cols_neon,
                                 SIMD_COVER(neon), NULL, NULL, NULL, SIMD_SPANS(neon)};
    switch (isa) {
    case EF_ISA_AVX512: return avx512;
    case EF_ISA_AVX2: return avx2;
    case EF_ISA_SSE2: return sse2;
    case EF_ISA_NEON: return neon;
    default: return ref;
    }
}

/* fn(arg, t, n) for t = 0 .. n-1, t = 0 on the calling thread. */
void fuse__ctx_run(fuse_context *ctx, fuse__task_fn fn, void *arg)
{
    fuse__pool_run(ctx != NULL ? &ctx->pool : NULL, fn, arg);
}

/* The state of fuse_context_frame_prepare (below). */
static struct fuse__banded *banded_new(void);

fuse_context *fuse_context_create(const fuse_context_desc *desc)
{
    fuse_context_desc d = {EF_ISA_DEFAULT, 1};
    fuse_context *ctx;
    if (desc != NULL) d = *desc;
    if ((unsigned)d.max_isa >= EF_ISA_COUNT) d.max_isa = EF_ISA_DEFAULT;
    ctx = calloc(1, sizeof *ctx);
    if (ctx == NULL) return NULL;
    ctx->k = fuse__kernels_for(ef_isa_choose(d.max_isa));
    ctx->banded = banded_new();
    if (ctx->banded == NULL || !fuse__pool_init(&ctx->pool, d.threads)) {
        free(ctx->banded);
        free(ctx);
        return NULL;
    }
    return ctx;
}

void fuse_context_destroy(fuse_context *ctx)
{
    if (ctx == NULL) return;
    fuse__pool_destroy(&ctx->pool);
    free(ctx->banded);
    free(ctx);
}

ef_isa fuse_context_isa(const fuse_context *ctx)
{
    return ctx != NULL ? ctx->k.isa : EF_ISA_DEFAULT;
}

int fuse_context_threads(const fuse_context *ctx)
{
    return ctx != NULL ? ctx->pool.threads : 0;
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
    /* the normals: floats (n10 0: 3 a pixel) or ef_n10 (n10 1: one
     * uint32_t a pixel); normal_stride in those units */
    const void *normal;
    int n10;
    int mask_stride, normal_stride;
    uint8_t *zero_rows;   /* fuse_eye.q_zero_rows (NULL: none) */
} light_job;

/* Where row y's pixel x of j's normals starts, and a pixel's bytes. */
static const void *normal_at(const light_job *j, int y, int x)
{
    const size_t i = (size_t)y * (size_t)j->normal_stride;
    if (j->n10) return (const uint32_t *)j->normal + i + (size_t)x;
    return (const float *)j->normal + i + 3 * (size_t)x;
}

static size_t normal_px_bytes(int n10)
{
    return n10 ? sizeof(uint32_t) : 3 * sizeof(float);
}

/* Asks for the bytes [p, p + n) in cache (a hint: no fault, no effect on
 * the result). The lit and blended spans of a row start in its middle, where
 * the hardware prefetcher has not yet seen a stream; asking for the next
 * row's span while this one is computed hides the memory latency. */
static void prefetch(const void *p, size_t n, int write)
{
    const uintptr_t a = (uintptr_t)p & ~(uintptr_t)63, e = (uintptr_t)p + n;
    uintptr_t q;
    /* unrolled: a span is tens of lines, and the loop's own test and step
     * were three of the four instructions per line */
    if (write) {
#pragma GCC unroll 4
        for (q = a; q < e; q += 64) __builtin_prefetch((const void *)q, 1, 3);
    } else {
#pragma GCC unroll 4
        for (q = a; q < e; q += 64) __builtin_prefetch((const void *)q, 0, 3);
    }
}

/* [*x0, *x1): a span of the mask row (w bytes) that holds every non-zero
 * byte (found 8 bytes at a time, so it may reach up to 7 zero bytes beyond
 * them); *x0 == *x1 == 0 when every byte is 0. */
static void mask_span(const uint8_t *m, int w, int *x0, int *x1)
{
    int a = 0, b = w;
    uint64_t t, q[4];
    /* 32 bytes a step over the clear run (the rows above and below the
     * hand, its margins), then 8: the same words found */
    for (; a + 32 <= w; a += 32) {
        memcpy(q, m + a, 32);
        if (q[0] | q[1] | q[2] | q[3]) break;
    }
    for (; a + 8 <= w; a += 8) {
        memcpy(&t, m + a, 8);
        if (t) break;
    }
    if (a + 8 > w)   /* no word set: the last w % 8 bytes */
        while (a < w && m[a] == 0) a++;
    if (a >= w) {
        *x0 = *x1 = 0;
        return;
    }
    for (; b - 32 >= a; b -= 32) {
        memcpy(q, m + b - 32, 32);
        if (q[0] | q[1] | q[2] | q[3]) break;
    }
    for (; b - 8 >= a; b -= 8) {   /* every byte at b and beyond is 0 */
        memcpy(&t, m + b - 8, 8);
        if (t) break;
    }
    *x0 = a;
    *x1 = b;
}

/* The lit span [*x0, *x1) of a mask row (w bytes) widened to a whole number
 * of SPAN_VEC pixels where the row has room (to the right, else to the
 * left; unchanged when the row is narrower): the kernels of every ISA then
 * run whole vectors only, without the scalar tail of the reference on the
 * last x1 - x0 mod SIMD_W pixels (mask_span's x1 is w - 8 k, so at an odd
 * width every row had one). The added pixels have mask byte 0: lit, depth-
 * tested and written as 0, the bytes of the narrower span. */
#define SPAN_VEC 16
static void span_widen(int w, int *x0, int *x1)
{
    const int n = (*x1 - *x0 + SPAN_VEC - 1) / SPAN_VEC * SPAN_VEC;
    if (*x0 + n <= w) *x1 = *x0 + n;
    else if (*x1 - n >= 0) *x0 = *x1 - n;
}

/* Prefetches the inputs of layer row y over [x0, x1) (the span of the row
 * before it: the hand moves little from row to row). */
static void light_prefetch(const light_job *j, int y, int x0, int x1)
{
    if (y >= j->P.height || x0 >= x1) return;
    prefetch(normal_at(j, y, x0), normal_px_bytes(j->n10) * (size_t)(x1 - x0), 0);
    prefetch(row_of(&j->P, y) + 4 * (size_t)x0, 4u * (size_t)(x1 - x0), 0);
}

/* Layer row y: the pixels [x0, x1) lit (mask row m), the rest 0 (their
 * mask bytes are 0: the reference writes 0 there). */
static void light_span(const light_job *j, int y, int x0, int x1, const uint8_t *m, uint8_t *o)
{
    const int w = j->P.width;
    if (x0 > 0) memset(o, 0, 4u * (size_t)x0);
    if (x1 < w) memset(o + 4 * (size_t)x1, 0, 4u * (size_t)(w - x1));
    if (j->n10)
        j->k->light_span_n10(&j->prep, y, x0, x1, row_of(&j->P, y), m,
                             (const uint32_t *)normal_at(j, y, 0), o);
    else
        j->k->light_span(&j->prep, y, x0, x1, row_of(&j->P, y), m,
                         (const float *)normal_at(j, y, 0), o);
}

/* Row y of a light job: its mask row *m, output row *o and the mask's
 * span x0..x1, recorded in span (NULL: none); prefetches the next row's
 * inputs. Returns 0, the output row cleared, for a row without hand
 * (above and below the hand). */
static inline int row_begin(const light_job *j, int y, int32_t (*span)[3], const uint8_t **m,
                            uint8_t **o, int *x0, int *x1)
{
    const int w = j->P.width;
    *m = j->mask + (size_t)y * (size_t)j->mask_stride;
    *o = row_of(&j->out, y);
    mask_span(*m, w, x0, x1);
    if (span != NULL) {
        span[y % SPAN_RING][0] = y;
        span[y % SPAN_RING][1] = *x0;
        span[y % SPAN_RING][2] = *x1;
    }
    if (*x0 >= *x1) {
        /* a row that was all 0 when the last frame left it stays so */
        if (j->zero_rows == NULL || !j->zero_rows[y]) memset(*o, 0, 4u * (size_t)w);
        if (j->zero_rows != NULL) j->zero_rows[y] = 1;
        return 0;
    }
    if (j->zero_rows != NULL) j->zero_rows[y] = 0;
    light_prefetch(j, y + 1, *x0, *x1);
    return 1;
}

/* span: as eye_light_depth_rows (NULL: none) */
static void light_rows(const light_job *j, int y0, int y1, int32_t (*span)[3])
{
    const int w = j->P.width;
    int y;
    for (y = y0; y < y1; y++) {
        const uint8_t *m;
        uint8_t *o;
        int x0, x1;
        if (!row_begin(j, y, span, &m, &o, &x0, &x1)) continue;
        span_widen(w, &x0, &x1);
        light_span(j, y, x0, x1, m, o);
    }
}

typedef struct comp_job {
    const kernels *k;
    fuse_image Q, V, out;
    int vx, vy, vw, vh;
    int in_place;
    int v_opaque;       /* fuse_eye.v_opaque: transparent spans are out = V */
} comp_job;

/* The jobs' inputs (fuse_light, fuse_composite, fuse_context_frame). */
/* The normals are normal's (floats) or, with normal NULL, normal_n10's
 * (checked by fuse__light_check: exactly one is set). */
static void light_job_set(light_job *j, const kernels *k, const fuse_image *P,
                          const uint8_t *mask, int mask_stride, const float *normal,
                          int normal_stride, const uint32_t *normal_n10, int normal_n10_stride,
                          const fuse_image *out)
{
    j->k = k;
    j->P = *P;
    j->out = *out;
    j->mask = mask;
    j->n10 = normal == NULL;
    j->normal = j->n10 ? (const void *)normal_n10 : (const void *)normal;
    j->mask_stride = mask_stride;
    j->normal_stride = j->n10 ? normal_n10_stride : normal_stride;
    j->zero_rows = NULL;
}

static void comp_job_set(comp_job *j, const kernels *k, const fuse_image *Q, const fuse_image *V,
                         int vp_x0, int vp_y0, int vp_w, int vp_h, const fuse_image *out,
                         int v_opaque)
{
    *j = (comp_job){k, *Q, *V, *out, vp_x0, vp_y0, vp_w, vp_h, fuse__same_image(out, V), v_opaque};
}

/* memcpy called through a pointer: gcc expands a memcpy of 4 n bytes
 * inline as rep movsq, which costs more than libc's on the spans of a row
 * (a few hundred bytes to a few KB, unaligned) and on a whole image. */
static void *(*volatile copy_fn)(void *, const void *, size_t) = memcpy;

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* out = V over n bytes that nothing reads before the frame is done: with
 * n large, stored around the caches (x86: movntdq), which spares the read
 * of each output line before its write (a third of the copy's traffic). */
static void copy_stream(uint8_t *o, const uint8_t *v, size_t n)
{
#if defined(__SSE2__)
    if (n >= 4096) {
        const size_t head = (16 - ((uintptr_t)o & 15)) & 15;
        size_t i;
        if (head) memcpy(o, v, head);
        for (i = head; i + 64 <= n; i += 64) {
            const __m128i a = _mm_loadu_si128((const __m128i *)(v + i));
            const __m128i b = _mm_loadu_si128((const __m128i *)(v + i + 16));
            const __m128i c = _mm_loadu_si128((const __m128i *)(v + i + 32));
            const __m128i d = _mm_loadu_si128((const __m128i *)(v + i + 48));
            _mm_stream_si128((__m128i *)(o + i), a);
            _mm_stream_si128((__m128i *)(o + i + 16), b);
            _mm_stream_si128((__m128i *)(o + i + 32), c);
            _mm_stream_si128((__m128i *)(o + i + 48), d);
        }
        if (i < n) memcpy(o + i, v + i, n - i);
        return;
    }
#endif
    copy_fn(o, v, n);
}

/* Orders copy_stream's stores before whatever follows (the hand-off of
 * the band to the other thread, the caller reading out). */
static void copy_stream_done(void)
{
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

/* n pixels that the layer does not reach: out = V with alpha 255. With the
 * caller's promise that V is opaque that is V itself: nothing to do in
 * place, a copy otherwise. */
static inline void transparent(const comp_job *j, const uint8_t *v, uint8_t *o, int n)
{
    if (!j->v_opaque) j->k->opaque(v, o, n);
    else if (!j->in_place) copy_fn(o, v, 4u * (size_t)n);
}

/* Output pixels per transparency group: a group whose taps all lie in
 * coverage blocks without a bit (both source rows) is a copy of V. */
#define GROUP 16
_Static_assert(FUSE__TILE % GROUP == 0, "a tile holds whole groups (comp_row_ref_opaque)");

/* What the table-driven composite keeps between rows: the column table of
 * one tile; for every coverage block b of the layer, the first and the
 * last group of the tile whose taps can read it (gfirst[b] .. glast[b],
 * empty when gfirst > glast); and the coverage bits of the last two layer
 * rows. With a row cache (kernels.hrow), also the horizontal taps h of
 * those two rows (fuse_internal.h) over the groups their coverage reaches
 * (bit g of grp; a group without its bit has all taps of that row zero).
 * On the stack of the caller (about 75 KB); nothing is allocated. */
#define NBLOCKS (FUSE_MAX_DIM / FUSE__COV_BLOCK)
#define GWORDS ((FUSE__TILE / GROUP + 63) / 64)
typedef struct comp_scratch {
    fuse__cols cols;
    int16_t gfirst[NBLOCKS], glast[NBLOCKS];
    int tile_c0, tile_n;            /* the tile in cols; tile_n 0: none */
    int cov_row[2];                 /* layer rows in cov, -1: none */
    uint64_t cov[2][FUSE__COV_WORDS];
    uint64_t grp[2][GWORDS];        /* groups with h computed */
    uint16_t h[2][4 * FUSE__TILE];  /* 4 channels per tile column */
    uint16_t h_zero[4 * FUSE__TILE];/* h = 0 (stored FUSE__H_BIAS), set with the tile */
    /* The spans of the layer rows lit last (eye_whole): layer row r is 0
     * outside [span[r % SPAN_RING][1], span[r % SPAN_RING][2]) when
     * span[r % SPAN_RING][0] == r, so its coverage reads only that span. */
    int32_t span[SPAN_RING][3];
    /* defer (eye_whole: out of place, V opaque, both images without row
     * padding): the transparent pixels are not copied one span at a time;
     * out = V over [pend, start of a blended run) in one call before the
     * run (defer_flush), so everything between two runs, across rows and
     * the viewport's border, is one copy: the rows above the hand are one
     * libc call (its large-copy path), not one call per row. */
    int defer;
    size_t pend;          /* out's bytes before pend are final */
} comp_scratch;

static void scratch_init(comp_scratch *s)
{
    int i;
    s->tile_c0 = 0;
    s->tile_n = 0;
    s->cov_row[0] = s->cov_row[1] = -1;
    for (i = 0; i < SPAN_RING; i++) s->span[i][0] = -1;
    s->defer = 0;
    s->pend = 0;
}

/* comp_scratch.defer: out = V over [pend, o), then pend = o_end (the end
 * of the run blended at o). */
static void defer_flush(const comp_job *j, comp_scratch *s, const uint8_t *o, const uint8_t *o_end)
{
    const size_t at = (size_t)(o - j->out.pixels);
    if (at > s->pend) copy_stream(j->out.pixels + s->pend, j->V.pixels + s->pend, at - s->pend);
    s->pend = (size_t)(o_end - j->out.pixels);
}

/* Group g (output columns [g GROUP, g GROUP + GROUP) of the tile) reads the
 * source columns ix[first] .. min(ix[last] + 1, sw - 1), i.e. the blocks
 * blo(g) .. bhi(g); both grow with g. */
static void scratch_tile(comp_scratch *s, const kernels *k, int sw, int vw, int c0, int n)
{
    int ng, nb, g, b;
    if (s->tile_n == n && s->tile_c0 == c0) return;   /* every row but the first */
    ng = (n + GROUP - 1) / GROUP;
    nb = (sw + FUSE__COV_BLOCK - 1) / FUSE__COV_BLOCK;
    s->cov_row[0] = s->cov_row[1] = -1;   /* h depends on the tile */
    if (s->tile_n == 0) {
        int i;
        for (i = 0; i < 4 * FUSE__TILE; i++) s->h_zero[i] = (uint16_t)FUSE__H_BIAS;
    }
    fuse__cols_fill(&s->cols, sw, vw, c0, n);
    if (k->hprep != NULL) k->hprep(&s->cols, n, sw);
    for (g = 0, b = 0; b < nb; b++) {    /* first g with bhi(g) >= b */
        while (g < ng) {
            const int last = g * GROUP + GROUP - 1 < n ? g * GROUP + GROUP - 1 : n - 1;
            const int hi = s->cols.ix[last] + 1 < sw ? s->cols.ix[last] + 1 : sw - 1;
            if (hi / FUSE__COV_BLOCK >= b) break;
            g++;
        }
        s->gfirst[b] = (int16_t)g;
    }
    for (g = -1, b = 0; b < nb; b++) {   /* last g with blo(g) <= b */
        while (g + 1 < ng && s->cols.ix[(g + 1) * GROUP] / FUSE__COV_BLOCK <= b) g++;
        s->glast[b] = (int16_t)g;
    }
    s->tile_c0 = c0;
    s->tile_n = n;
}

/* Coverage bits of layer row r, computed into the slot that does not hold
 * row keep. */
static int next_bit(const uint64_t *a, const uint64_t *c, int nb, int b, int want);

/* h of layer row r into slot (kernels.hrow): over the groups that the runs
 * of its coverage bits reach (gfirst/glast), each group once. Any group
 * with a non-zero tap in row r reads a covered block, so it is one of
 * them; the others keep no bit in grp and count as h = 0. */
static void scratch_hrow(comp_scratch *s, const comp_job *j, int r, int slot)
{
    const int sw = j->Q.width, n = s->tile_n;
    const int nb = (sw + FUSE__COV_BLOCK - 1) / FUSE__COV_BLOCK;
    const uint64_t *bits = s->cov[slot];
    const uint8_t *q = row_of(&j->Q, r);
    int b = 0, done = 0;   /* groups [0, done) handled */
    memset(s->grp[slot], 0, sizeof s->grp[slot]);
    for (;;) {
        const int first = next_bit(bits, bits, nb, b, 1);
        int last, g0, g1, c, e, g;
        if (first >= nb) break;
        last = next_bit(bits, bits, nb, first, 0) - 1;
        b = last + 1;
        g0 = s->gfirst[first] > done ? s->gfirst[first] : done;
        g1 = s->glast[last];
        if (g0 > g1) continue;
        c = g0 * GROUP;
        e = (g1 + 1) * GROUP < n ? (g1 + 1) * GROUP : n;
        j->k->hrow(q, &s->cols, c, e - c, sw, s->h[slot] + 4 * (size_t)c);
        for (g = g0; g <= g1;) {   /* bits g0 .. g1, a word's share at a time */
            const int top = (g | 63) < g1 ? (g | 63) : g1;
            s->grp[slot][g >> 6] |= (~(uint64_t)0 >> (63 - (top - g))) << (g & 63);
            g = top + 1;
        }
        done = g1 + 1;
    }
}

/* Coverage bits (and with a row cache, h) of layer row r into the slot
 * that does not hold row keep; returns the slot. */
static int scratch_fill(comp_scratch *s, const comp_job *j, int r, int keep)
{
    const int32_t *sp = s->span[r % SPAN_RING];
    const int slot = s->cov_row[0] == keep ? 1 : 0;
    if (sp[0] == r)
        j->k->cover_span(row_of(&j->Q, r), j->Q.width, sp[1], sp[2], s->cov[slot]);
    else
        j->k->cover(row_of(&j->Q, r), j->Q.width, s->cov[slot]);
    if (j->k->hrow != NULL) scratch_hrow(s, j, r, slot);
    s->cov_row[slot] = r;
    return slot;
}

/* Coverage bits (and with a row cache, h) of layer row r, computed into
 * the slot that does not hold row keep; *slot_out: the slot. Inline: a
 * layer row is read by about two output rows, so most calls find it and
 * only scratch_fill's are a call. */
static inline const uint64_t *scratch_cover(comp_scratch *s, const comp_job *j, int r, int keep,
                                            int *slot_out)
{
    const int slot = s->cov_row[0] == r ? 0 : s->cov_row[1] == r ? 1 : scratch_fill(s, j, r, keep);
    *slot_out = slot;
    return s->cov[slot];
}

/* The first bit >= b that is set (want 1) or clear (want 0) in the nb bits
 * of a | c; nb if none. The bits at nb and above are 0. */
static int next_bit(const uint64_t *a, const uint64_t *c, int nb, int b, int want)
{
    while (b < nb) {
        uint64_t w = a[b >> 6] | c[b >> 6];
        if (!want) w = ~w;
        w &= ~(uint64_t)0 << (b & 63);
        if (w) {
            b = (b & ~63) + __builtin_ctzll(w);
            return b < nb ? b : nb;
        }
        b = (b & ~63) + 64;
    }
    return nb;
}

/* The rows [y0, y1) outside the viewport and the columns left and right of
 * it: a copy of V (nothing to do in place). */
static void comp_border_rows(const comp_job *j, int y0, int y1)
{
    const size_t row_bytes = 4u * (size_t)j->V.width;
    int y;
    if (j->in_place) return;
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
}

/* n pixels from tile column c of row y: blended, or (transparent) V with
 * alpha 255. */
static void comp_span(const comp_job *j, comp_scratch *s, const uint8_t *q0,
                      const uint8_t *q1, uint32_t fy, const uint8_t *v, uint8_t *o, int c,
                      int n, int covered)
{
    if (n <= 0) return;
    if (covered) {
        if (s->defer) defer_flush(j, s, o + 4 * (size_t)c, o + 4 * (size_t)(c + n));
        j->k->comp(q0, q1, fy, &s->cols, c, n, j->Q.width, v + 4 * (size_t)c, o + 4 * (size_t)c);
    } else if (!s->defer) {
        transparent(j, v + 4 * (size_t)c, o + 4 * (size_t)c, n);
    }
}

/* Bits of the groups whose class (1: h only in the upper row, 2: only in
 * the lower one, 3: in both) is cls, word w. */
static uint64_t class_word(const uint64_t *g0, const uint64_t *g1, int w, int cls)
{
    return cls == 3 ? g0[w] & g1[w] : cls == 1 ? g0[w] & ~g1[w] : ~g0[w] & g1[w];
}

/* The first group >= g (of ng) whose class is not cls; ng if none. */
static int class_end(const uint64_t *g0, const uint64_t *g1, int ng, int g, int cls)
{
    while (g < ng) {
        const uint64_t w = ~class_word(g0, g1, g >> 6, cls) & (~(uint64_t)0 << (g & 63));
        if (w) {
            g = (g & ~63) + __builtin_ctzll(w);
            return g < ng ? g : ng;
        }
        g = (g & ~63) + 64;
    }
    return ng;
}

/* An output row from the row cache: slots r0 (upper layer row) and r1
 * (lower). Groups with h in either row go through kernels.vrow in runs of
 * one class, a row without h reading h_zero (its taps there are all 0);
 * the other groups have four zero taps at every pixel: V, alpha 255.
 * next: prefetch the next output row's pixels over the blended runs (in
 * place with an opaque V, where nothing else reads the row: otherwise the
 * rows are read from end to end and the hardware prefetcher streams them). */
static void comp_row_cached(const comp_job *j, comp_scratch *s, int r0, int r1,
                            uint32_t fy, const uint8_t *v, uint8_t *o, int n, int next)
{
    const int ng = (n + GROUP - 1) / GROUP;
    const uint64_t *g0 = s->grp[r0], *g1 = s->grp[r1];
    const uint16_t *h0 = s->h[r0], *h1 = s->h[r1];
    int g = 0, done = 0;   /* columns [0, done) written */
    for (;;) {
        const int gs = next_bit(g0, g1, ng, g, 1);
        int cls, ge, c, e;
        if (gs >= ng) break;
        cls = (int)((g0[gs >> 6] >> (gs & 63)) & 1u) | (int)(((g1[gs >> 6] >> (gs & 63)) & 1u) << 1);
        ge = class_end(g0, g1, ng, gs, cls);
        c = gs * GROUP;
        e = ge * GROUP < n ? ge * GROUP : n;
        if (s->defer) defer_flush(j, s, o + 4 * (size_t)c, o + 4 * (size_t)e);
        else if (c > done) transparent(j, v + 4 * (size_t)done, o + 4 * (size_t)done, c - done);
        if (next)   /* the same span of the next output row (prefetch above) */
            prefetch(v + (size_t)j->V.stride + 4 * (size_t)c, 4u * (size_t)(e - c), 1);
        j->k->vrow((cls & 1) ? h0 + 4 * (size_t)c : s->h_zero, (cls & 2) ? h1 + 4 * (size_t)c : s->h_zero,
                   fy, v + 4 * (size_t)c, o + 4 * (size_t)c, e - c);
        done = e;
        g = ge;
    }
    if (n > done && !s->defer) transparent(j, v + 4 * (size_t)done, o + 4 * (size_t)done, n - done);
}

/* One output row y of the viewport, columns [c0, c0 + n) of the tile in s.
 * The runs of covered blocks of the two layer rows give the groups that
 * need the blend; every other group has four zero taps at every pixel and
 * is a copy of V with alpha 255 (in place: a read, and a write only where
 * V's alpha is not 255), the reference's bytes either way. */
static void comp_row_tiled(const comp_job *j, comp_scratch *s, int y, int c0, int n)
{
    const int sw = j->Q.width, sh = j->Q.height;
    const int nb = (sw + FUSE__COV_BLOCK - 1) / FUSE__COV_BLOCK;
    const int32_t pos = fuse__src_pos(y - j->vy, sh, j->vh);
    const int iy = pos >> 16, iy1 = iy + 1 < sh ? iy + 1 : sh - 1;
    int s0, s1 = -1;
    const uint64_t *b0 = scratch_cover(s, j, iy, -1, &s0);
    const uint64_t *b1 = iy1 == iy ? b0 : scratch_cover(s, j, iy1, iy, &s1);
    const size_t off = 4 * ((size_t)j->vx + (size_t)c0);
    const uint8_t *q0 = row_of(&j->Q, iy), *q1 = row_of(&j->Q, iy1);
    const uint8_t *v = row_of(&j->V, y) + off;
    uint8_t *o = row_of(&j->out, y) + off;
    const uint32_t fy = ((uint32_t)pos >> 8) & 255u;
    int done = 0, b = 0;   /* columns [0, done) written */
    if (iy1 == iy) s1 = s0;
    if (j->k->vrow != NULL) {
        comp_row_cached(j, s, s0, s1, fy, v, o, n,
                        j->in_place && j->v_opaque && y + 1 < j->vy + j->vh);
        return;
    }
    for (;;) {
        int first, last, g0, g1, c;
        first = next_bit(b0, b1, nb, b, 1);
        if (first >= nb) break;
        last = next_bit(b0, b1, nb, first, 0) - 1;
        b = last + 1;
        g0 = s->gfirst[first];
        g1 = s->glast[last];
        c = g0 * GROUP;
        if (g0 > g1 || (g1 + 1) * GROUP <= done) continue;
        if (c < done) c = done;
        comp_span(j, s, q0, q1, fy, v, o, done, c - done, 0);
        done = (g1 + 1) * GROUP < n ? (g1 + 1) * GROUP : n;
        comp_span(j, s, q0, q1, fy, v, o, c, done - c, 1);
    }
    comp_span(j, s, q0, q1, fy, v, o, done, n - done, 0);
}

/* 1 if a pixel of layer row q (width sw) in the coverage blocks
 * [b0, b1] is not zero. */
static int blocks_covered(const uint8_t *q, int sw, int b0, int b1)
{
    const int x1 = (b1 + 1) * FUSE__COV_BLOCK < sw ? (b1 + 1) * FUSE__COV_BLOCK : sw;
    uint32_t acc = 0, t;
    int x;
    for (x = b0 * FUSE__COV_BLOCK; x < x1; x++) {
        memcpy(&t, q + 4 * (size_t)x, 4);
        acc |= t;
    }
    return acc != 0;
}

/* Output row y of the viewport by the reference with the caller's promise
 * of an opaque V (fuse_eye.v_opaque): the same choice as the table-driven
 * paths, written out. Per group of GROUP viewport columns (the tiles hold
 * a whole number of groups), a group whose taps all lie in coverage blocks
 * without a non-zero pixel (both layer rows) is transparent (out = V),
 * every other group is blended by the reference. With an opaque V that is
 * the bytes of no promise; with a broken promise (alpha below 255) it is
 * still the bytes of every ISA, alpha included. */
static void comp_row_ref_opaque(const comp_job *j, int y)
{
    const int sw = j->Q.width, sh = j->Q.height;
    const int32_t pos = fuse__src_pos(y - j->vy, sh, j->vh);
    const int iy = pos >> 16, iy1 = iy + 1 < sh ? iy + 1 : sh - 1;
    const uint8_t *q0 = row_of(&j->Q, iy), *q1 = row_of(&j->Q, iy1);
    const uint8_t *v = row_of(&j->V, y) + 4 * (size_t)j->vx;
    uint8_t *o = row_of(&j->out, y) + 4 * (size_t)j->vx;
    fuse__axis ax;
    int c;
    fuse__axis_init(&ax, sw, j->vw);
    for (c = 0; c < j->vw; c += GROUP) {
        const int n = j->vw - c < GROUP ? j->vw - c : GROUP;
        const fuse__axis at = ax;   /* the walk at the group's first column */
        const int lo = fuse__axis_pos(&ax) >> 16;
        int i, hi, b0, b1;
        for (i = 0; i < n - 1; i++) fuse__axis_next(&ax);
        hi = fuse__axis_pos(&ax) >> 16;
        fuse__axis_next(&ax);
        hi = hi + 1 < sw ? hi + 1 : sw - 1;
        b0 = lo / FUSE__COV_BLOCK;
        b1 = hi / FUSE__COV_BLOCK;
        if (blocks_covered(q0, sw, b0, b1) || blocks_covered(q1, sw, b0, b1))
            fuse__composite_row_ref(q0, q1, ((uint32_t)pos >> 8) & 255u, at, sw,
                                    v + 4 * (size_t)c, o + 4 * (size_t)c, n);
        else
            transparent(j, v + 4 * (size_t)c, o + 4 * (size_t)c, n);
    }
}

/* Viewport rows [y0, y1) (already clipped to the viewport). The ISA paths
 * go through column tables of FUSE__TILE columns; the reference walks
 * fuse__axis as fuse_ref.c does. */
static void comp_vp_rows(const comp_job *j, comp_scratch *s, int y0, int y1)
{
    const int sw = j->Q.width, sh = j->Q.height;
    int y, c0;
    if (j->k->ref && j->v_opaque) {
        for (y = y0; y < y1; y++) comp_row_ref_opaque(j, y);
        return;
    }
    if (j->k->ref) {
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
        scratch_tile(s, j->k, sw, j->vw, c0, n);
        for (y = y0; y < y1; y++)
            comp_row_tiled(j, s, y, c0, n);
    }
}

/* Rows [y0, y1) of the output. */
static void comp_rows(const comp_job *j, int y0, int y1)
{
    comp_scratch s;
    comp_border_rows(j, y0, y1);
    if (y0 < j->vy) y0 = j->vy;
    if (y1 > j->vy + j->vh) y1 = j->vy + j->vh;
    if (y0 >= y1) return;
    scratch_init(&s);
    comp_vp_rows(j, &s, y0, y1);
}

static void light_task(void *arg, int t, int n)
{
    const light_job *j = arg;
    int y0, y1;
    fuse__band(j->P.height, t, n, &y0, &y1);
    light_rows(j, y0, y1, NULL);
}

static void comp_task(void *arg, int t, int n)
{
    const comp_job *j = arg;
    int y0, y1;
    fuse__band(j->V.height, t, n, &y0, &y1);
    comp_rows(j, y0, y1);
}

/* ---- public entries ---------------------------------------------------- */

/* normal or normal_n10 (the other NULL), as fuse__light_check */
static fuse_result light_with(fuse_context *ctx, const kernels *k,
                              const fuse_lighting *L, const fuse_intrinsics *K,
                              const fuse_image *P, const uint8_t *mask,
                              int mask_stride, const float *normal,
                              int normal_stride, const uint32_t *normal_n10,
                              int normal_n10_stride, fuse_image *out)
{
    light_job j;
    fuse_result r = fuse__light_check(L, K, P, mask, mask_stride, normal, normal_stride,
                                      normal_n10, normal_n10_stride, out, &j.prep);
    if (r != FUSE_OK) return r;
    light_job_set(&j, k, P, mask, mask_stride, normal, normal_stride, normal_n10,
                  normal_n10_stride, out);
    fuse__ctx_run(ctx, light_task, &j);
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
    comp_job_set(&j, k, Q, V, vp_x0, vp_y0, vp_w, vp_h, out, 0);
    fuse__ctx_run(ctx, comp_task, &j);
    return FUSE_OK;
}

fuse_result fuse_light(const fuse_lighting *L, const fuse_intrinsics *K,
                       const fuse_image *P, const uint8_t *mask,
                       int mask_stride, const float *normal,
                       int normal_stride, fuse_image *out)
{
    const kernels k = fuse__kernels_for(ef_isa_choose(EF_ISA_DEFAULT));
    return light_with(NULL, &k, L, K, P, mask, mask_stride, normal,
                      normal_stride, NULL, 0, out);
}

fuse_result fuse_light_n10(const fuse_lighting *L, const fuse_intrinsics *K,
                           const fuse_image *P, const uint8_t *mask,
                           int mask_stride, const uint32_t *normal_n10,
                           int normal_n10_stride, fuse_image *out)
{
    const kernels k = fuse__kernels_for(ef_isa_choose(EF_ISA_DEFAULT));
    return light_with(NULL, &k, L, K, P, mask, mask_stride, NULL, 0, normal_n10,
                      normal_n10_stride, out);
}

fuse_result fuse_composite(const fuse_image *Q, const fuse_image *V,
                           int vp_x0, int vp_y0, int vp_w, int vp_h,
                           fuse_image *out)
{
    const kernels k = fuse__kernels_for(ef_isa_choose(EF_ISA_DEFAULT));
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
                      normal_stride, NULL, 0, out);
}

fuse_result fuse_context_light_n10(fuse_context *ctx, const fuse_lighting *L,
                                   const fuse_intrinsics *K, const fuse_image *P,
                                   const uint8_t *mask, int mask_stride,
                                   const uint32_t *normal_n10, int normal_n10_stride,
                                   fuse_image *out)
{
    if (ctx == NULL) return FUSE_ERR_ARGS;
    return light_with(ctx, &ctx->k, L, K, P, mask, mask_stride, NULL, 0, normal_n10,
                      normal_n10_stride, out);
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
    int edge_fade;            /* fuse_eye.edge_fade, edge_sides */
    unsigned edge_sides;
} eye_job;

typedef struct frame_job {
    eye_job eyes[FUSE_MAX_THREADS];
    int interleave[FUSE_MAX_THREADS];   /* eye_whole may interleave */
    int count;
} frame_job;

/* Layer rows [y0, y1) of an eye: lit, and with a depth test hidden where
 * the scene is in front. The ISA paths test the mask (a copy of each row)
 * before lighting, so hidden pixels are never lit; the bytes are those of
 * lighting and then testing the layer (fuse_internal.h,
 * fuse__depth_mask_fn), which the reference does. */
static void eye_light_depth_rows(const eye_job *e, int y0, int y1, int32_t (*span)[3]);

/* ... and faded towards the sides that end inside the display (fuse_edge.h:
 * one scalar pass over the border strips, once a row is final). */
static void eye_light_depth(const eye_job *e, int y0, int y1, int32_t (*span)[3])
{
    const int k = e->edge_fade, w = e->light.out.width, h = e->light.out.height;
    int32_t own[SPAN_RING][3];
    int y, c, c1;
    if (k < 1 || e->edge_sides == 0) {
        eye_light_depth_rows(e, y0, y1, span);
        return;
    }
    /* the fade visits only each row's mask span (the row is 0 outside it,
     * and all of a row without hand): the spans come from the ring, the
     * caller's or this one, SPAN_RING rows at a time */
    if (span == NULL) span = own;
    for (c = y0; c < y1; c = c1) {
        c1 = y1 - c < SPAN_RING ? y1 : c + SPAN_RING;
        eye_light_depth_rows(e, c, c1, span);
        for (y = c; y < c1; y++) {
            const int32_t *sp = span[y % SPAN_RING];
            if (!(e->edge_sides & (FUSE_EDGE_LEFT | FUSE_EDGE_RIGHT)) && y >= k && h - 1 - y >= k)
                continue;
            if (sp[0] != y)
                fuse_edge_fade_row(row_of(&e->light.out, y), y, w, h, k, e->edge_sides);
            else if (sp[1] < sp[2])
                fuse__edge_fade_cols(row_of(&e->light.out, y), y, w, h, k, e->edge_sides, sp[1],
                                     sp[2]);
        }
    }
}

/* span (NULL: none): a ring of SPAN_RING (row, x0, x1) where each lit row
 * records the span outside which it is 0 (comp_scratch.span). The edge
 * fade keeps a zero pixel zero. */
static void eye_light_depth_rows(const eye_job *e, int y0, int y1, int32_t (*span)[3])
{
    const light_job *j = &e->light;
    const int w = j->P.width, sh = j->P.height;
    const fuse_depth *d = e->depth;
    fuse__depth_prep dp;
    uint8_t m[FUSE_MAX_DIM];
    int y;
    if (d == NULL || j->k->ref) {
        light_rows(j, y0, y1, span);
        if (d != NULL)
            fuse__depth_rows(d, &j->out, e->comp.vx, e->comp.vy, e->comp.vw, e->comp.vh, y0, y1,
                             j->k->depth);
        return;
    }
    fuse__depth_prepare(d, w, e->comp.vw, &dp);
    for (y = y0; y < y1; y++) {
        const uint8_t *m0;
        uint8_t *o;
        int x0, x1;
        if (!row_begin(j, y, span, &m0, &o, &x0, &x1)) continue;
        if (y + 1 < sh) {   /* and the next row's depths, hand and scene */
            const int32_t c0 = (int32_t)(((int64_t)2 * x0 + 1) * dp.vw / dp.den);
            const int32_t c1 = (int32_t)(((int64_t)2 * (x1 - 1) + 1) * dp.vw / dp.den);
            prefetch(d->hand + (size_t)(y + 1) * (size_t)d->hand_stride + x0,
                     sizeof(float) * (size_t)(x1 - x0), 0);
            prefetch(fuse__depth_scene_row(d, y + 1, sh, e->comp.vx, e->comp.vy, e->comp.vh) + c0,
                     sizeof(float) * (size_t)(c1 - c0 + 1), 0);
        }
        span_widen(w, &x0, &x1);
        memcpy(m + x0, m0 + x0, (size_t)(x1 - x0));   /* the mask is 0 outside the span */
        j->k->depth_mspan(&dp, m, d->hand + (size_t)y * (size_t)d->hand_stride,
                          fuse__depth_scene_row(d, y, sh, e->comp.vx, e->comp.vy, e->comp.vh),
                          x0, x1);
        light_span(j, y, x0, x1, m, o);
    }
}

/* Layer rows lit per step of the fused order: small enough that the rows
 * (and their P, mask and normals) are still in L1/L2 when the composite
 * reads them. */
#define FUSE_CHUNK 8

/* One whole eye on one thread. The ISA paths interleave the stages: layer
 * rows are lit (and depth-tested) in chunks just before the output rows
 * that read them are composited, so the layer is read back from cache,
 * not from memory. Every row of the layer is final before any output row
 * reads it, so the bytes are those of the stages one after the other. The
 * reference path (and the rare cases where the interleaving does not
 * apply: a viewport wider than one column tile, or inputs of the lighting
 * that share memory with the output) runs the stages one after the other. */
static void eye_whole(const eye_job *e, int interleave)
{
    const comp_job *j = &e->comp;
    const int sh = e->light.P.height;
    comp_scratch s;
    int lit = 0, y;
    if (!interleave || j->k->ref || j->vw > FUSE__TILE) {
        eye_light_depth(e, 0, sh, NULL);
        comp_rows(j, 0, j->V.height);
        return;
    }
    scratch_init(&s);
    s.defer = !j->in_place && j->v_opaque && j->out.stride == 4 * j->out.width &&
              j->V.stride == j->out.stride;
    if (!s.defer) comp_border_rows(j, 0, j->V.height);
    for (y = j->vy; y < j->vy + j->vh; y++) {
        const int32_t pos = fuse__src_pos(y - j->vy, sh, j->vh);
        const int iy = pos >> 16, need = iy + 1 < sh ? iy + 1 : sh - 1;
        while (lit <= need) {
            const int n = sh - lit < FUSE_CHUNK ? sh - lit : FUSE_CHUNK;
            eye_light_depth(e, lit, lit + n, s.span);
            lit += n;
        }
        comp_vp_rows(j, &s, y, y + 1);
    }
    if (s.defer) {   /* the rest of out: after the last blended run */
        uint8_t *end = j->out.pixels + (size_t)j->out.height * (size_t)j->out.stride;
        defer_flush(j, &s, end, end);
        copy_stream_done();
    }
    if (lit < sh) eye_light_depth(e, lit, sh, NULL);
}

/* count a multiple of n: thread t takes eyes t, t + n, ... whole */
static void frame_whole_task(void *arg, int t, int n)
{
    const frame_job *f = arg;
    int e;
    for (e = t; e < f->count; e += n)
        eye_whole(&f->eyes[e], f->interleave[e]);
}

static void frame_light_task(void *arg, int t, int n)
{
    const frame_job *f = arg;
    int e, y0, y1;
    for (e = 0; e < f->count; e++) {
        fuse__band(f->eyes[e].light.P.height, t, n, &y0, &y1);
        eye_light_depth(&f->eyes[e], y0, y1, NULL);
    }
}

static void frame_comp_task(void *arg, int t, int n)
{
    const frame_job *f = arg;
    int e, y0, y1;
    for (e = 0; e < f->count; e++) {
        fuse__band(f->eyes[e].comp.V.height, t, n, &y0, &y1);
        comp_rows(&f->eyes[e].comp, y0, y1);
    }
}

/* [p, p + n) and [q, q + m) share a byte. */
static int bytes_overlap(const void *p, size_t n, const void *q, size_t m)
{
    const uintptr_t a = (uintptr_t)p, b = (uintptr_t)q;
    return a < b + m && b < a + n;
}

static size_t image_bytes(const fuse_image *im)
{
    return (size_t)(im->height - 1) * (size_t)im->stride + 4u * (size_t)im->width;
}

/* The interleaved order of eye_whole reads V and the lighting's inputs
 * while out is being written and writes Q while V is being read; it gives
 * the stages' bytes when none of these share memory (the checks already
 * keep out apart from Q, and V either equal to out or apart from it). */
static int may_interleave(const fuse_eye *s)
{
    const size_t ob = image_bytes(&s->out);
    const size_t mb = (size_t)(s->P.height - 1) * (size_t)s->mask_stride + (size_t)s->P.width;
    /* the normals' bytes, of the form in use (fuse__light_check: one) */
    const size_t nb = s->normal != NULL
                          ? sizeof(float) * ((size_t)(s->P.height - 1) * (size_t)s->normal_stride +
                                             3u * (size_t)s->P.width)
                          : sizeof(uint32_t) * ((size_t)(s->P.height - 1) *
                                                    (size_t)s->normal_n10_stride +
                                                (size_t)s->P.width);
    const void *np = s->normal != NULL ? (const void *)s->normal : (const void *)s->normal_n10;
    if (bytes_overlap(s->out.pixels, ob, s->P.pixels, image_bytes(&s->P)) ||
        bytes_overlap(s->out.pixels, ob, s->mask, mb) ||
        bytes_overlap(s->out.pixels, ob, np, nb) ||
        bytes_overlap(s->V.pixels, image_bytes(&s->V), s->Q.pixels, image_bytes(&s->Q)))
        return 0;
    if (s->depth != NULL) {
        const fuse_depth *d = s->depth;
        const size_t hb = sizeof(float) * ((size_t)(s->Q.height - 1) * (size_t)d->hand_stride +
                                           (size_t)s->Q.width);
        const size_t sb = sizeof(float) * ((size_t)(d->scene_height - 1) * (size_t)d->scene_stride +
                                           (size_t)d->scene_width);
        if (bytes_overlap(s->out.pixels, ob, d->hand, hb) ||
            bytes_overlap(s->out.pixels, ob, d->scene, sb))
            return 0;
    }
    return 1;
}

/* Checks one eye's inputs (fuse_context_frame) and fills *j. */
static fuse_result eye_prepare(fuse_context *ctx, const fuse_eye *s, eye_job *j)
{
    fuse_result r = fuse__light_check(s->lighting, s->intrinsics, &s->P, s->mask,
                                      s->mask_stride, s->normal, s->normal_stride,
                                      s->normal_n10, s->normal_n10_stride, &s->Q,
                                      &j->light.prep);
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
    if (r == FUSE_OK && (s->edge_fade < 0 || s->edge_fade > FUSE_EDGE_FADE_MAX ||
                         (s->edge_sides & ~FUSE_EDGE_ALL) != 0))
        r = FUSE_ERR_ARGS;
    if (r != FUSE_OK) return r;
    light_job_set(&j->light, &ctx->k, &s->P, s->mask, s->mask_stride, s->normal,
                  s->normal_stride, s->normal_n10, s->normal_n10_stride, &s->Q);
    j->light.zero_rows = s->q_zero_rows;
    comp_job_set(&j->comp, &ctx->k, &s->Q, &s->V, s->vp_x0, s->vp_y0, s->vp_w, s->vp_h,
                 &s->out, s->v_opaque != 0);
    j->depth = s->depth;
    j->edge_fade = s->edge_fade;
    j->edge_sides = s->edge_sides;
    return FUSE_OK;
}

fuse_result fuse_context_frame(fuse_context *ctx, const fuse_eye *eyes, int count)
{
    frame_job f;
    int e;
    if (ctx == NULL || eyes == NULL || count < 1 || count > FUSE_MAX_THREADS)
        return FUSE_ERR_ARGS;
    f.count = count;
    for (e = 0; e < count; e++) {
        fuse_result r = eye_prepare(ctx, &eyes[e], &f.eyes[e]);
        if (r != FUSE_OK) return r;
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
    for (e = 0; e < count; e++)
        f.interleave[e] = may_interleave(&eyes[e]);
    if (count % ctx->pool.threads == 0) {
        fuse__ctx_run(ctx, frame_whole_task, &f);
    } else {
        fuse__ctx_run(ctx, frame_light_task, &f);
        fuse__ctx_run(ctx, frame_comp_task, &f);
    }
    return FUSE_OK;
}

/* ---- one eye in row bands ------------------------------------------------
 *
 * fuse_context_frame_prepare / _band / _finish (fuse.h). Band b holds the
 * output rows [o0, o1) = [b R, (b + 1) R) and lights the layer rows
 * [l0, l1): l0 the first layer row its first viewport row reads (0 for
 * band 0), l1 the next band's l0 (sh for the last band). So every layer
 * row is lit by exactly one band. An output row reads layer rows iy and
 * iy + 1 (fuse__src_pos): the last rows of a band may read l1, which the
 * next band lights; those rows ([st, o1), at most a few per border) wait
 * for the finish, which composites them once every band is done. No two
 * bands write the same byte: each writes its own layer rows and its own
 * output rows [o0, st). */
struct fuse__banded {
    eye_job e;
    fuse_depth depth;   /* a copy of the caller's (it may be gone) */
    int interleave, rows, bands;
    /* per layer row r, as comp_scratch.span: (r, x0, x1) once a band lit
     * it with its span known, else r's entry -1 (each band writes its own
     * rows; the finish reads them, so its composite reads only the spans) */
    int32_t span[FUSE_MAX_DIM][3];
};

static struct fuse__banded *banded_new(void)
{
    return malloc(sizeof(struct fuse__banded));
}

/* The spans of layer rows [y0, y1) into B->span: from the ring (NULL:
 * unknown). */
static void band_spans(struct fuse__banded *B, int y0, int y1, int32_t (*ring)[3])
{
    int r;
    for (r = y0; r < y1; r++) {
        if (ring != NULL && ring[r % SPAN_RING][0] == r) {
            B->span[r][0] = r;
            B->span[r][1] = ring[r % SPAN_RING][1];
            B->span[r][2] = ring[r % SPAN_RING][2];
        } else {
            B->span[r][0] = -1;
        }
    }
}

/* The first layer row output row y reads (0 above the viewport, sh below). */
static int band_layer(const comp_job *j, int sh, int y)
{
    if (y <= j->vy) return 0;
    if (y >= j->vy + j->vh) return sh;
    return fuse__src_pos(y - j->vy, sh, j->vh) >> 16;
}

/* Band b's output rows [*o0, *o1), layer rows [*l0, *l1) and the first of
 * its rows left to the finish, *st (*o1: none). */
static void band_bounds(const struct fuse__banded *B, int b, int *o0, int *o1, int *l0, int *l1,
                        int *st)
{
    const comp_job *j = &B->e.comp;
    const int sh = B->e.light.P.height, H = j->out.height;
    int y;
    *o0 = (int)((int64_t)b * B->rows < H ? (int64_t)b * B->rows : H);
    *o1 = (int)((int64_t)(b + 1) * B->rows < H ? (int64_t)(b + 1) * B->rows : H);
    if (b == B->bands - 1) *o1 = H;
    *l0 = b == 0 ? 0 : band_layer(j, sh, *o0);
    *l1 = b == B->bands - 1 ? sh : band_layer(j, sh, *o1);
    *st = *o1;
    for (y = *o1 - 1; y >= *o0 && y >= j->vy && y < j->vy + j->vh; y--) {
        const int iy = fuse__src_pos(y - j->vy, sh, j->vh) >> 16;
        const int need = iy + 1 < sh ? iy + 1 : sh - 1;
        if (need < *l1) break;
        *st = y;
    }
}

fuse_result fuse_context_frame_prepare(fuse_context *ctx, const fuse_eye *eye, int band_rows,
                                       int *bands)
{
    struct fuse__banded *B;
    fuse_result r;
    int H;
    if (ctx == NULL || eye == NULL || bands == NULL || band_rows < 1) return FUSE_ERR_ARGS;
    B = ctx->banded;
    r = eye_prepare(ctx, eye, &B->e);
    if (r != FUSE_OK) return r;
    if (eye->depth != NULL) {
        B->depth = *eye->depth;
        B->e.depth = &B->depth;
    }
    B->interleave = may_interleave(eye);
    H = eye->out.height;
    B->rows = band_rows < H ? band_rows : H;
    B->bands = (H + B->rows - 1) / B->rows;
    *bands = B->bands;
    return FUSE_OK;
}

void fuse_context_frame_band(const fuse_context *ctx, int band)
{
    struct fuse__banded *B = ctx->banded;
    const eye_job *e = &B->e;
    const comp_job *j = &e->comp;
    const int sh = e->light.P.height;
    comp_scratch s;
    int o0, o1, l0, l1, st, lit, y, ya, yb;
    if (band < 0 || band >= B->bands) return;
    band_bounds(B, band, &o0, &o1, &l0, &l1, &st);
    if (!B->interleave || j->k->ref || j->vw > FUSE__TILE) {   /* as eye_whole */
        eye_light_depth(e, l0, l1, NULL);
        band_spans(B, l0, l1, NULL);
        if (o0 < st) comp_rows(j, o0, st);
        return;
    }
    scratch_init(&s);
    s.defer = !j->in_place && j->v_opaque && j->out.stride == 4 * j->out.width &&
              j->V.stride == j->out.stride;
    s.pend = (size_t)o0 * (size_t)j->out.stride;
    if (!s.defer) comp_border_rows(j, o0, st);
    ya = o0 > j->vy ? o0 : j->vy;
    yb = st < j->vy + j->vh ? st : j->vy + j->vh;
    lit = l0;
    for (y = ya; y < yb; y++) {
        const int32_t pos = fuse__src_pos(y - j->vy, sh, j->vh);
        const int iy = pos >> 16, need = iy + 1 < sh ? iy + 1 : sh - 1;
        while (lit <= need) {
            const int n = l1 - lit < FUSE_CHUNK ? l1 - lit : FUSE_CHUNK;
            eye_light_depth(e, lit, lit + n, s.span);
            band_spans(B, lit, lit + n, s.span);
            lit += n;
        }
        comp_vp_rows(j, &s, y, y + 1);
    }
    if (s.defer) {   /* the rest of the band's rows: after its last blended run */
        uint8_t *end = j->out.pixels + (size_t)st * (size_t)j->out.stride;
        defer_flush(j, &s, end, end);
        copy_stream_done();
    }
    if (lit < l1) {
        eye_light_depth(e, lit, l1, NULL);
        band_spans(B, lit, l1, NULL);
    }
}

void fuse_context_frame_finish(fuse_context *ctx)
{
    const struct fuse__banded *B = ctx->banded;
    const comp_job *j = &B->e.comp;
    const int sh = B->e.light.P.height;
    comp_scratch s;
    int b, o0, o1, l0, l1, st, y;
    /* the rows at the band borders: one scratch for all (the tile's
     * tables once), the layer rows' spans from the bands */
    scratch_init(&s);
    for (b = 0; b < B->bands; b++) {
        band_bounds(B, b, &o0, &o1, &l0, &l1, &st);
        if (st >= o1) continue;
        comp_border_rows(j, st, o1);
        for (y = st > j->vy ? st : j->vy; y < o1 && y < j->vy + j->vh; y++) {
            const int iy = fuse__src_pos(y - j->vy, sh, j->vh) >> 16;
            const int need = iy + 1 < sh ? iy + 1 : sh - 1;
            int r;
            for (r = iy; r <= need; r++)
                if (s.cov_row[0] != r && s.cov_row[1] != r) {
                    s.span[r % SPAN_RING][0] = B->span[r][0];
                    s.span[r % SPAN_RING][1] = B->span[r][1];
                    s.span[r % SPAN_RING][2] = B->span[r][2];
                }
            comp_vp_rows(j, &s, y, y + 1);
        }
    }
}
