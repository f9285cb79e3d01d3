/* test_fuse_isa.c - every ISA path of fuse_light and fuse_composite (SSE2,
 * AVX2, AVX-512, with 1 and several threads) against the scalar reference,
 * byte for byte (memcmp, padding included), over thousands of seeded cases:
 * odd widths, padded strides, soft and empty masks, garbage normals,
 * 0..8 lights, enlarging and reducing viewports, in-place composites,
 * layers that are not premultiplied; and the depth test (test_depth_isa:
 * NaN, inf, equal depths). The reference outputs of all cases fold into
 * CRC32 constants. An ISA the CPU (or EGOFUSE_ISA) does not
 * allow is reported as SKIP, never as passed.
 *
 *   test_fuse_isa        the cmocka tests
 *   test_fuse_isa N      reruns case N on every available ISA and prints
 *                        the first differing pixel, if any */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/fuse/fuse.h"
#include "../src/fuse/fuse_internal.h"
#include "../src/cpu/ef_mem.h"

/* CRC32 of the reference outputs of cases 0 .. CASES-1 (light, then
 * composite, per case). Changes only with the rules of docs/fuse.md. */
#define ISA_CRC 0x3BDF1779u   /* issue 17: the cheaper lighting rule (was 0x47B82A91; issue 14: 0x372C936A) */
#define CASES 3000

static const ef_isa simd_isas[] = { EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON };
#define N_SIMD 4

/* ---- one case ------------------------------------------------------------ */

typedef struct buf { uint8_t *p; size_t n; } buf;

static buf buf_new(size_t n, uint8_t fill)
{
    buf b;
    b.n = n ? n : 1;
    b.p = malloc(b.n);
    assert_non_null(b.p);
    memset(b.p, fill, b.n);
    return b;
}

typedef struct light_case {
    fuse_lighting L;
    fuse_intrinsics K;
    int w, h, pstride, mstride, nstride;
    buf P, M, N;
} light_case;

typedef struct comp_case {
    int qw, qh, qstride, vw_, vh_, vstride, x0, y0, w, h, in_place;
    buf Q, V;
} comp_case;

static void make_lighting(tu_rng *r, fuse_lighting *L)
{
    static const float shin[] = { 1.0f, 1.37f, 2.0f, 5.5f, 16.0f, 64.0f, 200.0f, 1000.0f };
    int i, c;
    *L = fuse_lighting_default();
    L->light_count = tu_int(r, FUSE_MAX_LIGHTS + 1);
    for (i = 0; i < L->light_count; i++) {
        const float sc = tu_range(r, 0.3f, 3.0f);
        for (c = 0; c < 3; c++) {
            L->lights[i].dir[c] = tu_range(r, -1, 1) * sc;
            L->lights[i].color[c] = tu_range(r, -0.2f, 1.5f);
        }
        if (tu_int(r, 6) == 0) {   /* towards the camera's back: L = -V on axis */
            L->lights[i].dir[0] = L->lights[i].dir[1] = 0.0f;
            L->lights[i].dir[2] = -1.0f;
        }
    }
    for (c = 0; c < 3; c++) {
        L->ambient[c] = tu_range(r, -0.1f, 0.7f);
        L->tone[c] = tu_range(r, 0.3f, 2.0f);
    }
    L->kd = tu_range(r, 0, 1.2f);
    L->ks = tu_int(r, 5) == 0 ? 0.0f : tu_range(r, 0, 1.5f);
    L->shininess = tu_int(r, 2) ? shin[tu_int(r, 8)] : tu_range(r, 1.0f, 300.0f);
    L->kf = tu_range(r, -0.2f, 1.3f);
}

static void light_case_make(tu_rng *r, light_case *c)
{
    int x, y, style = tu_int(r, 5);
    make_lighting(r, &c->L);
    c->w = 1 + tu_int(r, tu_int(r, 4) ? 80 : 300);
    c->h = 1 + tu_int(r, 6);
    c->pstride = 4 * c->w + 4 * tu_int(r, 3);
    c->mstride = c->w + tu_int(r, 9);
    c->nstride = 3 * c->w + tu_int(r, 5);
    /* odd w: the centre column has px = 0 exactly (V on the axis) */
    c->K.fx = tu_range(r, 0.3f, 2.0f) * (float)c->w;
    c->K.fy = c->K.fx * tu_range(r, 0.9f, 1.1f);
    c->K.cx = tu_int(r, 2) ? 0.5f * (float)c->w : tu_range(r, -0.5f, 1.5f) * (float)c->w;
    c->K.cy = tu_int(r, 2) ? 0.5f * (float)c->h : tu_range(r, -0.5f, 1.5f) * (float)c->h;
    c->P = buf_new((size_t)c->pstride * c->h, 0);
    c->M = buf_new((size_t)c->mstride * c->h, 0);
    c->N = buf_new(sizeof(float) * (size_t)c->nstride * c->h, 0);
    for (size_t i = 0; i < c->P.n; i++) c->P.p[i] = (uint8_t)tu_int(r, 256);
    for (y = 0; y < c->h; y++)
        for (x = 0; x < c->w; x++) {
            uint8_t *m = c->M.p + (size_t)y * c->mstride + x;
            float *n = (float *)(void *)c->N.p + (size_t)y * c->nstride + 3 * x;
            int k = tu_int(r, 100);
            /* mask styles: empty, sparse, runs, soft, full */
            switch (style) {
            case 0: *m = 0; break;
            case 1: *m = k < 90 ? 0 : (uint8_t)(1 + tu_int(r, 255)); break;
            case 2: *m = ((x / 13 + y) & 1) ? 255 : 0; break;
            case 3: *m = (uint8_t)tu_int(r, 256); break;
            default: *m = 255; break;
            }
            k = tu_int(r, 100);
            if (k < 40) {            /* unit */
                float a = tu_range(r, -1, 1), b = tu_range(r, -1, 1), cc = tu_range(r, 0, 1);
                float l = sqrtf(a * a + b * b + cc * cc);
                if (l < 1e-3f) l = 1.0f, a = 0, b = 0, cc = 1;
                n[0] = a / l; n[1] = b / l; n[2] = cc / l;
            } else if (k < 80) {     /* any length */
                float s = tu_range(r, 0.01f, 100.0f);
                n[0] = tu_range(r, -1, 1) * s;
                n[1] = tu_range(r, -1, 1) * s;
                n[2] = tu_range(r, -1, 1) * s;
            } else if (k < 86) {     /* facing the camera exactly */
                n[0] = 0; n[1] = 0; n[2] = 1;
            } else if (k < 90) {
                n[0] = n[1] = n[2] = 0;
            } else if (k < 93) {
                n[0] = NAN; n[1] = 0; n[2] = 1;
            } else if (k < 96) {
                n[0] = 0; n[1] = INFINITY; n[2] = 1;
            } else if (k < 98) {     /* beyond the accepted length range */
                n[0] = 1e20f; n[1] = 0; n[2] = 0;
            } else {
                n[0] = 1e-20f; n[1] = 0; n[2] = 0;
            }
        }
    /* garbage in the normal padding: never read */
    for (y = 0; y < c->h; y++)
        for (x = 3 * c->w; x < c->nstride; x++)
            ((float *)(void *)c->N.p)[(size_t)y * c->nstride + x] = NAN;
}

static void comp_case_make(tu_rng *r, comp_case *c)
{
    int style = tu_int(r, 4);
    c->qw = 1 + tu_int(r, tu_int(r, 4) ? 70 : 300);
    c->qh = 1 + tu_int(r, 12);
    c->qstride = 4 * c->qw + 4 * tu_int(r, 3);
    c->vw_ = 1 + tu_int(r, tu_int(r, 4) ? 120 : 400);
    c->vh_ = 1 + tu_int(r, 16);
    c->vstride = 4 * c->vw_ + 4 * tu_int(r, 3);
    switch (tu_int(r, 4)) {
    case 0: c->w = c->vw_; break;
    case 1: c->w = c->qw <= c->vw_ ? c->qw : c->vw_; break;    /* 1:1 */
    default: c->w = 1 + tu_int(r, c->vw_); break;
    }
    c->h = 1 + tu_int(r, c->vh_);
    c->x0 = tu_int(r, c->vw_ - c->w + 1);
    c->y0 = tu_int(r, c->vh_ - c->h + 1);
    c->in_place = tu_int(r, 2);
    c->Q = buf_new((size_t)c->qstride * c->qh, 0);
    c->V = buf_new((size_t)c->vstride * c->vh_, 0);
    for (size_t i = 0; i < c->V.n; i++) c->V.p[i] = (uint8_t)tu_int(r, 256);
    for (int y = 0; y < c->qh; y++)
        for (int x = 0; x < c->qw; x++) {
            uint8_t *q = c->Q.p + (size_t)y * c->qstride + 4 * x;
            int k = tu_int(r, 100), a;
            if (style == 0 && k < 97) continue;               /* mostly empty */
            if (style == 1 && ((x / 9 + y / 3) & 1)) continue; /* blocks */
            a = k < 30 ? 255 : tu_int(r, 256);
            if (style == 3) {                                  /* not premultiplied */
                q[0] = (uint8_t)tu_int(r, 256); q[1] = (uint8_t)tu_int(r, 256);
                q[2] = (uint8_t)tu_int(r, 256); q[3] = (uint8_t)a;
            } else {
                q[0] = (uint8_t)tu_int(r, a + 1); q[1] = (uint8_t)tu_int(r, a + 1);
                q[2] = (uint8_t)tu_int(r, a + 1); q[3] = (uint8_t)a;
            }
        }
}

static uint64_t case_seed(int n) { return 0x15A0000000000000ull ^ ((uint64_t)n * 0x9E3779B97F4A7Cull); }

/* Runs the light part of a case on ctx into a fresh output (filled 0xA5). */
static buf run_light(fuse_context *ctx, const light_case *c)
{
    buf o = buf_new((size_t)c->pstride * c->h, 0xA5);
    fuse_image P = { c->P.p, c->w, c->h, c->pstride }, O = { o.p, c->w, c->h, c->pstride };
    assert_int_equal(fuse_context_light(ctx, &c->L, &c->K, &P, c->M.p, c->mstride,
                                        (const float *)(const void *)c->N.p, c->nstride, &O),
                     FUSE_OK);
    return o;
}

static buf run_comp(fuse_context *ctx, const comp_case *c)
{
    buf o = buf_new(c->V.n, 0xA5);
    fuse_image Q = { c->Q.p, c->qw, c->qh, c->qstride };
    fuse_image V = { c->V.p, c->vw_, c->vh_, c->vstride };
    fuse_image O = { o.p, c->vw_, c->vh_, c->vstride };
    if (c->in_place) {
        memcpy(o.p, c->V.p, c->V.n);
        V.pixels = o.p;
    }
    assert_int_equal(fuse_context_composite(ctx, &Q, &V, c->x0, c->y0, c->w, c->h, &O), FUSE_OK);
    return o;
}

/* First differing byte as a pixel; 0 if equal. */
static int report_diff(const char *what, const char *isa, int n, const buf *ref,
                       const buf *got, int stride)
{
    size_t i;
    for (i = 0; i < ref->n; i++)
        if (ref->p[i] != got->p[i]) {
            size_t y = i / (size_t)stride, x = (i % (size_t)stride) / 4, b = i - i % 4;
            printf("case %d %s %s: first difference at pixel (%zu, %zu) byte %zu: "
                   "ref %u %u %u %u, got %u %u %u %u\n", n, what, isa, x, y, i % 4,
                   ref->p[b], ref->p[b + 1], ref->p[b + 2], ref->p[b + 3],
                   got->p[b], got->p[b + 1], got->p[b + 2], got->p[b + 3]);
            return 1;
        }
    return 0;
}

typedef struct ctxs {
    fuse_context *ref;
    fuse_context *isa[N_SIMD][2];   /* 1 thread, 3 threads; NULL: missing */
} ctxs;

static void ctxs_make(ctxs *c)
{
    fuse_context_desc d = { EF_ISA_REF, 1 };
    int i;
    c->ref = fuse_context_create(&d);
    assert_non_null(c->ref);
    assert_int_equal(fuse_context_isa(c->ref), EF_ISA_REF);
    for (i = 0; i < N_SIMD; i++) {
        d.max_isa = simd_isas[i];
        d.threads = 1;
        c->isa[i][0] = fuse_context_create(&d);
        d.threads = 3;
        c->isa[i][1] = fuse_context_create(&d);
        assert_non_null(c->isa[i][0]);
        assert_non_null(c->isa[i][1]);
        assert_int_equal(fuse_context_threads(c->isa[i][1]), 3);
        if (fuse_context_isa(c->isa[i][0]) != simd_isas[i]) {
            fuse_context_destroy(c->isa[i][0]);
            fuse_context_destroy(c->isa[i][1]);
            c->isa[i][0] = c->isa[i][1] = NULL;
        }
    }
}

static void ctxs_free(ctxs *c)
{
    int i;
    fuse_context_destroy(c->ref);
    for (i = 0; i < N_SIMD; i++) {
        fuse_context_destroy(c->isa[i][0]);
        fuse_context_destroy(c->isa[i][1]);
    }
}

/* Runs case n on every available ISA; folds the reference into *crc.
 * Returns the number of mismatches (each one printed). */
static int run_case(const ctxs *cx, int n, uint32_t *crc)
{
    tu_rng r = { case_seed(n) };
    light_case lc;
    comp_case cc;
    buf lref, cref;
    int i, bad = 0;
    light_case_make(&r, &lc);
    comp_case_make(&r, &cc);
    lref = run_light(cx->ref, &lc);
    cref = run_comp(cx->ref, &cc);
    if (crc) {
        *crc = tu_crc32(*crc, lref.p, lref.n);
        *crc = tu_crc32(*crc, cref.p, cref.n);
    }
    for (i = 0; i < N_SIMD; i++) {
        fuse_context *ctx = cx->isa[i][n % 4 == 3];
        buf lo, co;
        if (ctx == NULL) continue;
        lo = run_light(ctx, &lc);
        co = run_comp(ctx, &cc);
        bad += report_diff("light", ef_isa_name(simd_isas[i]), n, &lref, &lo, lc.pstride);
        bad += report_diff("composite", ef_isa_name(simd_isas[i]), n, &cref, &co, cc.vstride);
        free(lo.p);
        free(co.p);
    }
    EF_FREE_ALL(lref.p, cref.p, lc.P.p, lc.M.p, lc.N.p, cc.Q.p, cc.V.p);
    return bad;
}

/* 1 for a path of another architecture (NEON on x86, the x86 paths on
 * aarch64): never there to test, so not a reason to skip the test; the
 * cross build runs them (.ci/run part arm64, qemu-aarch64). */
static int other_arch(ef_isa isa)
{
#if defined(__aarch64__)
    return isa != EF_ISA_NEON;
#elif defined(__x86_64__) || defined(__i386__)
    return isa == EF_ISA_NEON;
#else
    (void)isa;
    return 1;
#endif
}

/* 1 when path i is missing on this architecture (the test then skips) */
static int skip_missing(const ctxs *cx, int i)
{
    if (cx->isa[i][0] != NULL) return 0;
    if (other_arch(simd_isas[i])) {
        printf("NOTE %s: another architecture's path, not run here\n", ef_isa_name(simd_isas[i]));
        return 0;
    }
    printf("SKIP %s: not available (cpu best %s, EGOFUSE_ISA %s); untested: "
           "src/fuse/fuse_%s.c\n", ef_isa_name(simd_isas[i]), ef_isa_name(ef_cpu_best()),
           getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "unset", ef_isa_name(simd_isas[i]));
    return 1;
}

static int skip_missing_isa(ef_isa isa)
{
    if (other_arch(isa)) {
        printf("NOTE %s: another architecture's path, not run here\n", ef_isa_name(isa));
        return 0;
    }
    printf("SKIP %s: not available (cpu best %s, EGOFUSE_ISA %s); untested: "
           "src/fuse/fuse_%s.c\n", ef_isa_name(isa), ef_isa_name(ef_cpu_best()),
           getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "unset", ef_isa_name(isa));
    return 1;
}

/* ---- tests ---------------------------------------------------------------- */

static void test_cases(void **state)
{
    ctxs cx;
    uint32_t crc = 0;
    int n, bad = 0, missing = 0, i;
    (void)state;
    ctxs_make(&cx);
    for (i = 0; i < N_SIMD; i++) missing += skip_missing(&cx, i);
    for (n = 0; n < CASES; n++) {
        bad += run_case(&cx, n, &crc);
        if (bad > 10) break;
    }
    ctxs_free(&cx);
    printf("NOTE fuse ISA cases: %d, mismatches %d, reference CRC32 0x%08X (expected 0x%08X)\n",
           n, bad, crc, ISA_CRC);
    assert_int_equal(bad, 0);
    assert_int_equal(crc, ISA_CRC);
    if (missing) skip();
}

/* A soft elliptical "hand" mask with garbage normals outside it. */
static void hand_scene(tu_rng *r, int w, int h, uint8_t *P, uint8_t *M, float *N, double cover)
{
    const double ax = 0.5 * w * sqrt(cover * 4 / 3.14159265), ay = 0.5 * h * sqrt(cover * 4 / 3.14159265);
    int x, y;
    for (y = 0; y < h; y++)
        for (x = 0; x < w; x++) {
            const double dx = (x + 0.5 - 0.5 * w) / ax, dy = (y + 0.5 - 0.55 * h) / ay;
            const double d = sqrt(dx * dx + dy * dy);
            const size_t i = (size_t)y * w + x;
            P[4 * i] = (uint8_t)tu_int(r, 256);
            P[4 * i + 1] = (uint8_t)(x & 255);
            P[4 * i + 2] = (uint8_t)(y & 255);
            P[4 * i + 3] = 0;
            M[i] = d < 0.97 ? 255 : d < 1.0 ? (uint8_t)(255 * (1.0 - d) / 0.03) : 0;
            if (M[i]) {
                N[3 * i] = (float)(dx * 0.8);
                N[3 * i + 1] = (float)(-dy * 0.8);
                N[3 * i + 2] = (float)sqrt(fmax(0.05, 1.0 - 0.64 * d * d));
            } else {
                N[3 * i] = N[3 * i + 1] = N[3 * i + 2] = NAN;
            }
        }
}

/* The paper's frame: 640x400 lit, composited into 1194x746 at (43, 27) of
 * 1280x800, in place; every ISA with 1 and 2 threads. */
static void test_paper_frame(void **state)
{
    enum { CW = 640, CH = 400, W = 1280, H = 800 };
    ctxs cx;
    tu_rng r = { 0xF00D5u };
    uint8_t *P = malloc(CW * CH * 4), *M = malloc(CW * CH);
    float *N = malloc(sizeof(float) * CW * CH * 3);
    uint8_t *V0 = malloc(W * H * 4), *Qr = malloc(CW * CH * 4), *Vr = malloc(W * H * 4);
    uint8_t *Q = malloc(CW * CH * 4), *Vo = malloc(W * H * 4);
    fuse_lighting L = fuse_lighting_default();
    fuse_intrinsics K = { 532.0f, 532.0f, 320.0f, 200.0f };
    int i, t, missing = 0;
    (void)state;
    assert_true(P && M && N && V0 && Qr && Vr && Q && Vo);
    hand_scene(&r, CW, CH, P, M, N, 0.3);
    for (i = 0; i < W * H * 4; i++) V0[i] = (uint8_t)tu_int(&r, 256);
    L.light_count = 2;
    L.lights[1] = (fuse_light_src){ { -0.5f, 0.2f, 0.6f }, { 0.4f, 0.3f, 0.2f } };
    ctxs_make(&cx);
    {
        fuse_image Pi = { P, CW, CH, 4 * CW }, Qi = { Qr, CW, CH, 4 * CW }, Vi = { Vr, W, H, 4 * W };
        memcpy(Vr, V0, W * H * 4);
        assert_int_equal(fuse_context_light(cx.ref, &L, &K, &Pi, M, CW, N, 3 * CW, &Qi), FUSE_OK);
        assert_int_equal(fuse_context_composite(cx.ref, &Qi, &Vi, 43, 27, 1194, 746, &Vi), FUSE_OK);
    }
    for (i = 0; i < N_SIMD; i++) {
        if (cx.isa[i][0] == NULL) { missing += skip_missing(&cx, i); continue; }
        for (t = 0; t < 2; t++) {
            fuse_context_desc d = { simd_isas[i], t + 1 };
            fuse_context *ctx = fuse_context_create(&d);
            fuse_image Pi = { P, CW, CH, 4 * CW }, Qi = { Q, CW, CH, 4 * CW }, Vi = { Vo, W, H, 4 * W };
            buf a = { Qr, CW * CH * 4 }, b = { Q, CW * CH * 4 }, c = { Vr, W * H * 4 }, e = { Vo, W * H * 4 };
            assert_non_null(ctx);
            memcpy(Vo, V0, W * H * 4);
            memset(Q, 0x77, CW * CH * 4);
            assert_int_equal(fuse_context_light(ctx, &L, &K, &Pi, M, CW, N, 3 * CW, &Qi), FUSE_OK);
            assert_int_equal(fuse_context_composite(ctx, &Qi, &Vi, 43, 27, 1194, 746, &Vi), FUSE_OK);
            assert_int_equal(report_diff("paper light", ef_isa_name(simd_isas[i]), -1, &a, &b, 4 * CW), 0);
            assert_int_equal(report_diff("paper composite", ef_isa_name(simd_isas[i]), -1, &c, &e, 4 * W), 0);
            fuse_context_destroy(ctx);
        }
    }
    ctxs_free(&cx);
    free(P); free(M); free(N); free(V0); free(Qr); free(Vr); free(Q); free(Vo);
    if (missing) skip();
}

/* The public fuse_light / fuse_composite dispatch (EGOFUSE_ISA respected)
 * and give the reference bytes; contexts report their ISA and reject NULL. */
static void test_dispatch(void **state)
{
    ctxs cx;
    tu_rng r = { case_seed(7) };
    light_case lc;
    comp_case cc;
    buf lref, cref, lo, co;
    fuse_context_desc d = { EF_ISA_DEFAULT, 0 };
    fuse_context *ctx = fuse_context_create(&d);
    (void)state;
    assert_non_null(ctx);
    assert_int_equal(fuse_context_isa(ctx), ef_isa_choose(EF_ISA_DEFAULT));
    assert_int_equal(fuse_context_threads(ctx), 1);
    fuse_context_destroy(ctx);
    d.threads = 1000;
    ctx = fuse_context_create(&d);
    assert_int_equal(fuse_context_threads(ctx), FUSE_MAX_THREADS);
    fuse_context_destroy(ctx);
    fuse_context_destroy(NULL);
    assert_int_equal(fuse_context_light(NULL, NULL, NULL, NULL, NULL, 0, NULL, 0, NULL), FUSE_ERR_ARGS);
    assert_int_equal(fuse_context_composite(NULL, NULL, NULL, 0, 0, 1, 1, NULL), FUSE_ERR_ARGS);

    ctxs_make(&cx);
    light_case_make(&r, &lc);
    comp_case_make(&r, &cc);
    lref = run_light(cx.ref, &lc);
    cref = run_comp(cx.ref, &cc);
    lo = buf_new(lref.n, 0xA5);
    co = buf_new(cref.n, 0xA5);
    {
        fuse_image P = { lc.P.p, lc.w, lc.h, lc.pstride }, O = { lo.p, lc.w, lc.h, lc.pstride };
        fuse_image Q = { cc.Q.p, cc.qw, cc.qh, cc.qstride }, V = { cc.V.p, cc.vw_, cc.vh_, cc.vstride };
        fuse_image VO = { co.p, cc.vw_, cc.vh_, cc.vstride };
        assert_int_equal(fuse_light(&lc.L, &lc.K, &P, lc.M.p, lc.mstride,
                                    (const float *)(const void *)lc.N.p, lc.nstride, &O), FUSE_OK);
        if (cc.in_place) {
            memcpy(co.p, cc.V.p, cc.V.n);
            V.pixels = co.p;
        }
        assert_int_equal(fuse_composite(&Q, &V, cc.x0, cc.y0, cc.w, cc.h, &VO), FUSE_OK);
    }
    assert_memory_equal(lref.p, lo.p, lref.n);
    assert_memory_equal(cref.p, co.p, cref.n);
    free(lref.p); free(cref.p); free(lo.p); free(co.p);
    free(lc.P.p); free(lc.M.p); free(lc.N.p); free(cc.Q.p); free(cc.V.p);
    ctxs_free(&cx);
}

/* The lane power of every path against fuse__pow01, float bits, on
 * boundary values (2^-k, the log2 reduction's sqrt(2) split, 1 - ulp,
 * 2^-100, subnormals, rounding ties of y + 0.5) and random ones. Output
 * bytes hide ulp differences of the power, so this checks it directly. */
static void test_pow_bits(void **state)
{
    typedef void (*pow_fn)(const float *, int, float, float *);
    static const pow_fn fns[N_SIMD] = { fuse__pow01_row_sse2, fuse__pow01_row_avx2,
                                        fuse__pow01_row_avx512, fuse__pow01_row_neon };
    static const float shin[] = { 1.0f, 1.5f, 2.0f, 2.5f, 3.0f, 7.3f, 16.0f, 64.0f,
                                  200.0f, 1000.0f, 123456.7f, 1.0e6f };
    enum { NX = 4096 };
    float *x = malloc(NX * sizeof(float)), *ref = malloc(NX * sizeof(float)),
          *got = malloc(NX * sizeof(float));
    tu_rng r = { 0x9057u };
    int i, n = 0, si, missing = 0;
    (void)state;
    assert_true(x && ref && got);
    for (i = 0; i <= 130; i++) {
        float p2 = ldexpf(1.0f, -i);
        x[n++] = p2;
        x[n++] = nextafterf(p2, 0.0f);
        x[n++] = nextafterf(p2, 2.0f);
        x[n++] = p2 * 0.70710678f;
        x[n++] = p2 * 1.41421356f * 0.5f;
    }
    x[n++] = 0.0f; x[n++] = -0.0f; x[n++] = 1.0f; x[n++] = 1.5f; x[n++] = -0.5f;
    x[n++] = FUSE__POW_MIN; x[n++] = nextafterf(FUSE__POW_MIN, 1.0f);
    x[n++] = nextafterf(1.0f, 0.0f); x[n++] = NAN; x[n++] = 0.70710677f; x[n++] = 0.70710683f;
    while (n < NX) {   /* log-uniform in (2^-40, 1), and near 1 */
        float u = tu_unit(&r);
        x[n++] = tu_int(&r, 4) ? exp2f(-40.0f * u) : 1.0f - 1e-4f * u;
    }
    for (i = 0; i < N_SIMD; i++) {
        if (ef_isa_choose(simd_isas[i]) != simd_isas[i]) {
            printf("SKIP pow01 %s: not available\n", ef_isa_name(simd_isas[i]));
            missing += !other_arch(simd_isas[i]);
            continue;
        }
        for (si = 0; si < (int)(sizeof shin / sizeof shin[0]); si++) {
            int k;
            for (k = 0; k < NX; k++) ref[k] = fuse__pow01(x[k], shin[si]);
            fns[i](x, NX, shin[si], got);
            for (k = 0; k < NX; k++)
                if (memcmp(&ref[k], &got[k], 4) != 0) {
                    print_error("pow01 %s: x %a s %g: ref %a got %a\n", ef_isa_name(simd_isas[i]),
                                (double)x[k], (double)shin[si], (double)ref[k], (double)got[k]);
                    fail();
                }
        }
    }
    free(x); free(ref); free(got);
    if (missing) skip();
}

/* ---- fuse_context_frame: the interleaved stages --------------------------- */

/* One eye of a random frame: layer cw x ch, output W x H with a viewport
 * (enlarging, reducing or 1:1), in place or not, with or without a depth
 * test; all buffers owned here. */
typedef struct frame_eye {
    light_case lc;
    int W, H, vx, vy, vw, vh, in_place, depth;
    buf V, out, Q, hand, scene;
    fuse_depth d;
} frame_eye;

static int in_viewport(const frame_eye *e, int x, int y)
{
    return x >= e->vx && x < e->vx + e->vw && y >= e->vy && y < e->vy + e->vh;
}

/* 1: every pixel of V inside the viewport has alpha 255 (fuse_eye.v_opaque's
 * promise); 2: moreover some pixel outside it has not. */
static int v_opaque_kind(const frame_eye *e)
{
    int i, outside = 0;
    for (i = 0; i < e->W * e->H; i++) {
        const int a = e->V.p[4 * i + 3];
        if (!in_viewport(e, i % e->W, i / e->W)) outside |= a != 255;
        else if (a != 255) return 0;
    }
    return 1 + outside;
}

static void frame_eye_make(tu_rng *r, frame_eye *e)
{
    int i;
    light_case_make(r, &e->lc);
    e->W = 1 + tu_int(r, tu_int(r, 3) ? 150 : 400);
    e->H = 1 + tu_int(r, 50);
    e->vw = tu_int(r, 3) == 0 ? (e->lc.w < e->W ? e->lc.w : e->W) : 1 + tu_int(r, e->W);
    e->vh = 1 + tu_int(r, e->H);
    e->vx = tu_int(r, e->W - e->vw + 1);
    e->vy = tu_int(r, e->H - e->vh + 1);
    e->in_place = tu_int(r, 2);
    e->depth = tu_int(r, 3) == 0;
    e->V = buf_new((size_t)e->W * e->H * 4, 0);
    e->out = buf_new((size_t)e->W * e->H * 4, 0);
    e->Q = buf_new((size_t)e->lc.pstride * e->lc.h, 0);
    for (i = 0; i < (int)e->V.n; i++) e->V.p[i] = (uint8_t)tu_int(r, 256);
    switch (tu_int(r, 3)) {
    case 0:   /* random alpha: the v_opaque promise broken */
        break;
    case 1:   /* an opaque scene (in place: no alpha to fix) */
        for (i = 3; i < (int)e->V.n; i += 4) e->V.p[i] = 255;
        break;
    default:  /* opaque inside the viewport only: the promise kept */
        for (i = 0; i < e->W * e->H; i++)
            if (in_viewport(e, i % e->W, i / e->W)) e->V.p[4 * i + 3] = 255;
            else if (e->V.p[4 * i + 3] == 255) e->V.p[4 * i + 3] = 254;
        break;
    }
    e->hand = buf_new(sizeof(float) * (size_t)e->lc.w * e->lc.h, 0);
    e->scene = buf_new(sizeof(float) * (size_t)e->W * e->H, 0);
    for (i = 0; i < e->lc.w * e->lc.h; i++)
        ((float *)(void *)e->hand.p)[i] = tu_range(r, 0.0f, 1.2f);
    for (i = 0; i < e->W * e->H; i++)
        ((float *)(void *)e->scene.p)[i] = tu_int(r, 2) ? tu_range(r, 0.0f, 3.0f) : 0.0f;
    e->d = (fuse_depth){ (const float *)(const void *)e->hand.p, e->lc.w, 0.1f, 10.0f, 0.0f,
                         (const float *)(const void *)e->scene.p, e->W, e->W, e->H };
}

static void frame_eye_free(frame_eye *e)
{
    free(e->lc.P.p); free(e->lc.M.p); free(e->lc.N.p);
    free(e->V.p); free(e->out.p); free(e->Q.p); free(e->hand.p); free(e->scene.p);
}

/* The eye as fuse_context_frame takes it; out (and V in place) reset. */
static fuse_eye frame_eye_bind(frame_eye *e)
{
    fuse_eye f;
    memset(&f, 0, sizeof f);
    if (e->in_place) memcpy(e->out.p, e->V.p, e->V.n);
    else memset(e->out.p, 0x77, e->out.n);   /* every byte must be written */
    memset(e->Q.p, 0x5A, e->Q.n);
    f.lighting = &e->lc.L;
    f.intrinsics = &e->lc.K;
    f.P = (fuse_image){ e->lc.P.p, e->lc.w, e->lc.h, e->lc.pstride };
    f.mask = e->lc.M.p;
    f.mask_stride = e->lc.mstride;
    f.normal = (const float *)(const void *)e->lc.N.p;
    f.normal_stride = e->lc.nstride;
    f.Q = (fuse_image){ e->Q.p, e->lc.w, e->lc.h, e->lc.pstride };
    f.depth = e->depth ? &e->d : NULL;
    f.V = (fuse_image){ e->in_place ? e->out.p : e->V.p, e->W, e->H, 4 * e->W };
    f.vp_x0 = e->vx;
    f.vp_y0 = e->vy;
    f.vp_w = e->vw;
    f.vp_h = e->vh;
    f.out = (fuse_image){ e->out.p, e->W, e->H, 4 * e->W };
    return f;
}

/* The stages one by one on the reference: *Q and *out (fresh buffers). */
static void frame_eye_expect(fuse_context *ref, frame_eye *e, buf *Q, buf *out)
{
    fuse_eye f = frame_eye_bind(e);
    *Q = buf_new(e->Q.n, 0);
    *out = buf_new(e->out.n, 0);
    assert_int_equal(fuse_context_light(ref, f.lighting, f.intrinsics, &f.P, f.mask, f.mask_stride,
                                        f.normal, f.normal_stride, &f.Q), FUSE_OK);
    if (f.depth)
        assert_int_equal(fuse_context_depth_test(ref, f.depth, &f.Q, f.vp_x0, f.vp_y0, f.vp_w, f.vp_h),
                         FUSE_OK);
    assert_int_equal(fuse_context_composite(ref, &f.Q, &f.V, f.vp_x0, f.vp_y0, f.vp_w, f.vp_h,
                                            &f.out), FUSE_OK);
    memcpy(Q->p, e->Q.p, e->Q.n);
    memcpy(out->p, e->out.p, e->out.n);
}

/* The output with fuse_eye.v_opaque = 1 against the reference stages
 * (want): V opaque inside the viewport (the promise kept, whatever the
 * alpha outside), the same bytes over the whole image; otherwise (the
 * promise broken) the same rgb, and an alpha that is the reference's or,
 * where the reference has 255, V's own. Returns 1 (and prints) on a
 * difference. */
static int opaque_diff(const char *what, const char *isa, int n, const frame_eye *e,
                       const buf *want, const buf *got)
{
    size_t i;
    if (v_opaque_kind(e)) return report_diff(what, isa, n, want, got, 4 * e->W);
    for (i = 0; i < want->n; i++) {
        const int ok = i % 4 != 3 ? got->p[i] == want->p[i]
                                  : got->p[i] == want->p[i] || (want->p[i] == 255 && got->p[i] == e->V.p[i]);
        if (!ok) {
            print_error("%s %s case %d: byte %zu (pixel %zu, %zu channel %zu) is %d, want %d (V %d)\n",
                        what, isa, n, i, (i / 4) % (size_t)e->W, (i / 4) / (size_t)e->W, i % 4,
                        got->p[i], want->p[i], e->V.p[i]);
            return 1;
        }
    }
    return 0;
}

/* fuse_context_frame on every ISA and 1..3 threads with 1..3 eyes equals
 * the reference stages one by one: the composite and the layer Q; also with
 * v_opaque = 1 (opaque_diff: a third of the cases have V opaque everywhere,
 * a third opaque inside the viewport and not outside, a third not), where
 * every ISA also gives the bytes of the reference with v_opaque = 1, alpha
 * included when the promise is broken (issue 20: the reference used to
 * ignore the flag). */
static void test_frame_cases(void **state)
{
    enum { FRAMES = 150 };
    fuse_context *ref, *ctx[N_SIMD + 1][3];
    int n, i, t, op, missing = 0, bad = 0, kinds[3] = { 0, 0, 0 };
    fuse_context_desc d = { EF_ISA_REF, 1 };
    (void)state;
    ref = fuse_context_create(&d);
    assert_non_null(ref);
    for (i = 0; i <= N_SIMD; i++)
        for (t = 0; t < 3; t++) {
            d.max_isa = i < N_SIMD ? simd_isas[i] : EF_ISA_REF;
            d.threads = t + 1;
            ctx[i][t] = fuse_context_create(&d);
            assert_non_null(ctx[i][t]);
        }
    for (i = 0; i < N_SIMD; i++)
        if (fuse_context_isa(ctx[i][0]) != simd_isas[i]) {
            missing += skip_missing_isa(simd_isas[i]);
            for (t = 0; t < 3; t++) {
                fuse_context_destroy(ctx[i][t]);
                ctx[i][t] = NULL;
            }
        }
    for (n = 0; n < FRAMES && !bad; n++) {
        tu_rng r = { case_seed(100000 + n) };
        const int count = 1 + tu_int(&r, 3);
        frame_eye e[3];
        buf wq[3], wo[3];
        fuse_eye f[3];
        int k;
        buf wp[3];
        for (k = 0; k < count; k++) {
            frame_eye_make(&r, &e[k]);
            frame_eye_expect(ref, &e[k], &wq[k], &wo[k]);
            kinds[v_opaque_kind(&e[k])]++;
        }
        /* The reference with v_opaque = 1 (wp): every ISA gives its bytes,
         * with the promise broken too. */
        for (k = 0; k < count; k++) {
            f[k] = frame_eye_bind(&e[k]);
            f[k].v_opaque = 1;
        }
        assert_int_equal(fuse_context_frame(ctx[N_SIMD][0], f, count), FUSE_OK);
        for (k = 0; k < count; k++) {
            wp[k] = buf_new(e[k].out.n, 0);
            memcpy(wp[k].p, e[k].out.p, e[k].out.n);
        }
        for (i = 0; i <= N_SIMD; i++)
            for (t = 0; t < 3; t++)
            for (op = 0; op < 2; op++) {
                if (ctx[i][t] == NULL) continue;
                for (k = 0; k < count; k++) {
                    f[k] = frame_eye_bind(&e[k]);
                    f[k].v_opaque = op;
                }
                assert_int_equal(fuse_context_frame(ctx[i][t], f, count), FUSE_OK);
                for (k = 0; k < count; k++) {
                    char what[80];
                    snprintf(what, sizeof what, "frame %d eye %d threads %d v_opaque %d out", n, k,
                             t + 1, op);
                    if (op)
                        bad += opaque_diff(what, ef_isa_name(fuse_context_isa(ctx[i][t])), n, &e[k],
                                           &wo[k], &e[k].out) ||
                               report_diff(what, ef_isa_name(fuse_context_isa(ctx[i][t])), n,
                                           &wp[k], &e[k].out, 4 * e[k].W);
                    else
                        bad += report_diff(what, ef_isa_name(fuse_context_isa(ctx[i][t])), n,
                                           &wo[k], &e[k].out, 4 * e[k].W);
                    snprintf(what, sizeof what, "frame %d eye %d threads %d v_opaque %d Q", n, k,
                             t + 1, op);
                    bad += report_diff(what, ef_isa_name(fuse_context_isa(ctx[i][t])), n,
                                       &wq[k], &e[k].Q, e[k].lc.pstride);
                }
            }
        for (k = 0; k < count; k++) {
            free(wq[k].p);
            free(wo[k].p);
            free(wp[k].p);
            frame_eye_free(&e[k]);
        }
    }
    assert_int_equal(bad, 0);
    /* each v_opaque case seen: promise broken, V opaque everywhere, V
     * opaque in the viewport only (byte-exact over the whole image) */
    assert_true(kinds[0] >= 20 && kinds[1] >= 20 && kinds[2] >= 20);
    fuse_context_destroy(ref);
    for (i = 0; i <= N_SIMD; i++)
        for (t = 0; t < 3; t++) fuse_context_destroy(ctx[i][t]);
    if (missing) skip();
}

/* The camera image P inside the viewport of the in-place output: the
 * stages one by one read all of P before the composite writes over it;
 * fuse_context_frame must give the same bytes (it does not interleave). */
static void test_frame_aliasing(void **state)
{
    enum { CW = 40, CH = 20, W = 100, H = 60 };
    tu_rng r = { 0xA11A5u };
    uint8_t *img = malloc(W * H * 4), *img0 = malloc(W * H * 4), *want = malloc(W * H * 4);
    uint8_t *M = malloc(CW * CH), *Q = malloc(CW * CH * 4);
    float *N = malloc(sizeof(float) * CW * CH * 3);
    const fuse_lighting L = fuse_lighting_default();
    const fuse_intrinsics K = { 40.0f, 40.0f, CW / 2.0f, CH / 2.0f };
    fuse_context_desc d = { EF_ISA_REF, 1 };
    fuse_context *ref = fuse_context_create(&d);
    int i, t;
    (void)state;
    assert_true(img && img0 && want && M && Q && N && ref);
    for (i = 0; i < W * H * 4; i++) img0[i] = (uint8_t)tu_int(&r, 256);
    for (i = 0; i < CW * CH; i++) {
        M[i] = (uint8_t)(tu_int(&r, 3) ? 255 : 0);
        N[3 * i] = tu_range(&r, -1, 1);
        N[3 * i + 1] = tu_range(&r, -1, 1);
        N[3 * i + 2] = 1.0f;
    }
    {   /* P: rows 6..25 of the image, at the top of the viewport (rows 5..54) */
        fuse_image I = { img, W, H, 4 * W };
        fuse_image P = { img + 4 * (6 * W + 10), CW, CH, 4 * W }, Qi = { Q, CW, CH, 4 * CW };
        memcpy(img, img0, W * H * 4);
        assert_int_equal(fuse_context_light(ref, &L, &K, &P, M, CW, N, 3 * CW, &Qi), FUSE_OK);
        assert_int_equal(fuse_context_composite(ref, &Qi, &I, 2, 5, 96, 50, &I), FUSE_OK);
        memcpy(want, img, W * H * 4);
    }
    for (i = 0; i <= N_SIMD; i++)
        for (t = 1; t <= 2; t++) {
            fuse_context_desc cd = { i < N_SIMD ? simd_isas[i] : EF_ISA_REF, t };
            fuse_context *ctx = fuse_context_create(&cd);
            fuse_eye f;
            assert_non_null(ctx);
            memset(&f, 0, sizeof f);
            memcpy(img, img0, W * H * 4);
            f.lighting = &L;
            f.intrinsics = &K;
            f.P = (fuse_image){ img + 4 * (6 * W + 10), CW, CH, 4 * W };
            f.mask = M;
            f.mask_stride = CW;
            f.normal = N;
            f.normal_stride = 3 * CW;
            f.Q = (fuse_image){ Q, CW, CH, 4 * CW };
            f.V = f.out = (fuse_image){ img, W, H, 4 * W };
            f.vp_x0 = 2;
            f.vp_y0 = 5;
            f.vp_w = 96;
            f.vp_h = 50;
            assert_int_equal(fuse_context_frame(ctx, &f, 1), FUSE_OK);
            assert_memory_equal(img, want, W * H * 4);
            fuse_context_destroy(ctx);
        }
    fuse_context_destroy(ref);
    free(img); free(img0); free(want); free(M); free(Q); free(N);
}

/* ---- the depth test -------------------------------------------------------- */

/* CRC32 of the reference's layers of depth cases 0 .. DEPTH_CASES-1. */
#define DEPTH_CRC 0xA0E7730Au
#define DEPTH_CASES 400

static float depth_special(tu_rng *r)
{
    static const float v[] = { NAN, -NAN, INFINITY, -INFINITY, 0.0f, -0.0f, 1.0f,
                               0.99999994f, -1e-30f, 1e-45f, 2.0f, -3.0f };
    return v[tu_int(r, (int)(sizeof v / sizeof v[0]))];
}

typedef struct depth_case {
    int qw, qh, qstride, hstride, W, H, sstride, vx, vy, vw, vh;
    buf Q, hand, scene;
    fuse_depth d;
} depth_case;

/* A random layer (40% of the pixels 0), hand depths (30% special: NaN,
 * +-inf, +-0, 1, 1 - ulp, negative, subnormal, beyond 1), a scene with
 * "nothing there" values (0, negative, NaN, inf) and, at about a third
 * of the layer pixels, the scene pixel they read set to exactly the
 * hand's distance (an equal depth keeps the hand) or one ulp either side. */
static void depth_case_make(tu_rng *r, depth_case *c, int *ties)
{
    float *hz, *sc;
    int x, y, i;
    c->qw = 1 + tu_int(r, tu_int(r, 3) ? 70 : 700);
    c->qh = 1 + tu_int(r, 12);
    c->qstride = 4 * c->qw + 4 * tu_int(r, 3);
    c->hstride = c->qw + tu_int(r, 5);
    c->vw = tu_int(r, 3) == 0 ? c->qw : 1 + tu_int(r, 3 * c->qw);   /* 1:1, enlarge, reduce */
    c->vh = 1 + tu_int(r, 3 * c->qh);
    c->W = c->vw + tu_int(r, 20);
    c->H = c->vh + tu_int(r, 5);
    c->sstride = c->W + tu_int(r, 4);
    c->vx = tu_int(r, c->W - c->vw + 1);
    c->vy = tu_int(r, c->H - c->vh + 1);
    c->Q = buf_new((size_t)c->qstride * c->qh, 0);
    c->hand = buf_new(sizeof(float) * (size_t)c->hstride * c->qh, 0);
    c->scene = buf_new(sizeof(float) * (size_t)c->sstride * c->H, 0);
    hz = (float *)(void *)c->hand.p;
    sc = (float *)(void *)c->scene.p;
    c->d.znear = tu_range(r, 0.001f, 1.0f);
    c->d.zfar = c->d.znear * tu_range(r, 1.5f, 1e4f);
    c->d.offset = tu_int(r, 2) ? 0.0f : tu_range(r, -0.2f, 0.2f);
    for (i = 0; i < (int)c->Q.n; i++) c->Q.p[i] = (uint8_t)tu_int(r, 256);
    for (y = 0; y < c->qh; y++)
        for (x = 0; x < c->qw; x++)
            if (tu_int(r, 5) < 2) memset(c->Q.p + (size_t)y * c->qstride + 4 * x, 0, 4);
    for (i = 0; i < c->hstride * c->qh; i++)
        hz[i] = tu_int(r, 10) < 3 ? depth_special(r) : tu_unit(r);
    for (i = 0; i < c->sstride * c->H; i++)
        sc[i] = tu_int(r, 4) == 0 ? depth_special(r)
                                  : tu_range(r, 0.0f, 1.2f) * (c->d.zfar + c->d.offset);
    {
        const float two_fn = (2.0f * c->d.zfar) * c->d.znear;
        const float fpn = c->d.zfar + c->d.znear, fmn = c->d.zfar - c->d.znear;
        for (y = 0; y < c->qh; y++)
            for (x = 0; x < c->qw; x++) {
                const int ox = c->vx + (int)(((int64_t)2 * x + 1) * c->vw / (2 * (int64_t)c->qw));
                const int oy = c->vy + (int)(((int64_t)2 * y + 1) * c->vh / (2 * (int64_t)c->qh));
                const float z = hz[(size_t)y * c->hstride + x];
                float dist;
                const int k = tu_int(r, 9);
                if (k >= 3 || !(z >= 0.0f && z < 1.0f)) continue;
                dist = two_fn / (fpn - ((2.0f * z) - 1.0f) * fmn) + c->d.offset;
                sc[(size_t)oy * c->sstride + ox] =
                    k == 0 ? dist : nextafterf(dist, k == 1 ? INFINITY : -INFINITY);
                *ties += k == 0;
            }
    }
    c->d.hand = hz;
    c->d.hand_stride = c->hstride;
    c->d.scene = sc;
    c->d.scene_stride = c->sstride;
    c->d.scene_width = c->W;
    c->d.scene_height = c->H;
}

/* Every ISA's depth test, 1 and 3 threads, and the public dispatch, byte
 * for byte against the reference (padding included); the reference's
 * layers fold into DEPTH_CRC. The cases must hide some pixels, keep some
 * and hold exact ties. */
/* The depth test on mask bytes (fuse__depth_mrow_*, what fuse_context_frame
 * runs before lighting) against the layer's test: a mask byte (non-zero
 * where the layer pixel is) must become 0 exactly where the pixel was
 * hidden and keep its value elsewhere. want: the layer after the
 * reference's test. Returns the number of kernels that differ. */
static int depth_mask_check(const depth_case *c, const buf *want, int n)
{
    static const fuse__depth_mask_fn fns[N_SIMD + 1] = { fuse__depth_mrow_sse2, fuse__depth_mrow_avx2,
                                                         fuse__depth_mrow_avx512, fuse__depth_mrow_neon,
                                                         fuse__depth_mrow_ref };
    uint8_t *m0 = malloc((size_t)c->qw * c->qh), *m = malloc((size_t)c->qw * c->qh);
    fuse__depth_prep p;
    int i, x, y, bad = 0;
    assert_true(m0 && m);
    for (y = 0; y < c->qh; y++)
        for (x = 0; x < c->qw; x++) {
            uint32_t a;
            memcpy(&a, c->Q.p + (size_t)y * c->qstride + 4 * (size_t)x, 4);
            m0[(size_t)y * c->qw + x] = (uint8_t)(a ? 1 + a % 255 : 0);
        }
    fuse__depth_prepare(&c->d, c->qw, c->vw, &p);
    for (i = 0; i <= N_SIMD; i++) {
        if (i < N_SIMD && ef_isa_choose(simd_isas[i]) != simd_isas[i]) continue;
        memcpy(m, m0, (size_t)c->qw * c->qh);
        for (y = 0; y < c->qh; y++)
            fns[i](&p, m + (size_t)y * c->qw, c->d.hand + (size_t)y * c->d.hand_stride,
                   fuse__depth_scene_row(&c->d, y, c->qh, c->vx, c->vy, c->vh), c->qw);
        for (y = 0; y < c->qh; y++)
            for (x = 0; x < c->qw; x++) {
                const size_t k = (size_t)y * c->qw + x;
                uint32_t a;
                memcpy(&a, want->p + (size_t)y * c->qstride + 4 * (size_t)x, 4);
                if (m[k] != (a ? m0[k] : 0)) {
                    printf("case %d depth on the mask %s: pixel (%d, %d) mask %d -> %d, layer %08X\n",
                           n, i < N_SIMD ? ef_isa_name(simd_isas[i]) : "ref", x, y, m0[k], m[k], a);
                    bad++;
                    x = c->qw;
                    y = c->qh;
                }
            }
    }
    free(m0);
    free(m);
    return bad;
}

static void test_depth_isa(void **state)
{
    ctxs cx;
    uint32_t crc = 0;
    long hidden = 0, kept = 0;
    int n, i, t, bad = 0, missing = 0, ties = 0;
    (void)state;
    ctxs_make(&cx);
    for (i = 0; i < N_SIMD; i++) missing += skip_missing(&cx, i);
    for (n = 0; n < DEPTH_CASES && !bad; n++) {
        tu_rng r = { case_seed(200000 + n) };
        depth_case c;
        buf want, got;
        fuse_image Q;
        size_t k;
        depth_case_make(&r, &c, &ties);
        want = buf_new(c.Q.n, 0);
        got = buf_new(c.Q.n, 0);
        memcpy(want.p, c.Q.p, c.Q.n);
        Q = (fuse_image){ want.p, c.qw, c.qh, c.qstride };
        assert_int_equal(fuse_context_depth_test(cx.ref, &c.d, &Q, c.vx, c.vy, c.vw, c.vh), FUSE_OK);
        crc = tu_crc32(crc, want.p, want.n);
        bad += depth_mask_check(&c, &want, n);
        for (k = 0; k + 4 <= c.Q.n; k += 4) {
            uint32_t a, b;
            memcpy(&a, c.Q.p + k, 4);
            memcpy(&b, want.p + k, 4);
            hidden += a != 0 && b == 0;
            kept += a != 0 && b != 0;
        }
        for (i = 0; i <= N_SIMD; i++)
            for (t = 0; t < 2; t++) {
                fuse_context *ctx = i < N_SIMD ? cx.isa[i][t] : NULL;
                char what[64];
                if (i < N_SIMD && ctx == NULL) continue;
                if (i == N_SIMD && t == 1) continue;
                memcpy(got.p, c.Q.p, c.Q.n);
                Q.pixels = got.p;
                if (ctx != NULL)
                    assert_int_equal(fuse_context_depth_test(ctx, &c.d, &Q, c.vx, c.vy, c.vw, c.vh),
                                     FUSE_OK);
                else   /* the public entry: the best ISA allowed */
                    assert_int_equal(fuse_depth_test(&c.d, &Q, c.vx, c.vy, c.vw, c.vh), FUSE_OK);
                snprintf(what, sizeof what, "depth (threads %d)", t ? 3 : 1);
                bad += report_diff(what, ctx ? ef_isa_name(fuse_context_isa(ctx)) : "dispatch", n,
                                   &want, &got, c.qstride);
            }
        free(want.p); free(got.p); free(c.Q.p); free(c.hand.p); free(c.scene.p);
    }
    ctxs_free(&cx);
    printf("NOTE fuse depth cases: %d, hidden %ld, kept %ld, exact ties %d, mismatches %d, "
           "reference CRC32 0x%08X (expected 0x%08X)\n", n, hidden, kept, ties, bad, crc, DEPTH_CRC);
    assert_int_equal(bad, 0);
    assert_true(hidden > 1000 && kept > 1000 && ties > 100);
    assert_int_equal(crc, DEPTH_CRC);
    assert_int_equal(fuse_context_depth_test(NULL, NULL, NULL, 0, 0, 1, 1), FUSE_ERR_ARGS);
    if (missing) skip();
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cases),
        cmocka_unit_test(test_pow_bits),
        cmocka_unit_test(test_paper_frame),
        cmocka_unit_test(test_dispatch),
        cmocka_unit_test(test_frame_cases),
        cmocka_unit_test(test_frame_aliasing),
        cmocka_unit_test(test_depth_isa),
    };
    if (argc > 1) {   /* rerun one case, print differences */
        ctxs cx;
        int n = atoi(argv[1]), bad;
        ctxs_make(&cx);
        for (int i = 0; i < N_SIMD; i++) skip_missing(&cx, i);
        bad = run_case(&cx, n, NULL);
        ctxs_free(&cx);
        printf("case %d: %s\n", n, bad ? "DIFFERENT" : "identical on every available ISA");
        return bad != 0;
    }
    return cmocka_run_group_tests(tests, NULL, NULL);
}
