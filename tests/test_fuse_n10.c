/* test_fuse_n10.c - the lighting on normals packed as ef_n10
 * (src/cpu/ef_n10.h): fuse_light_n10, fuse_context_light_n10 and
 * fuse_eye.normal_n10 give, byte for byte (padding included), what the
 * float path gives when fed the floats ef_n10_unpack makes of the same
 * packed normals, on every ISA this machine runs (ref, sse2, avx2, avx512;
 * neon under qemu-aarch64, .ci/run part arm64) with 1 and 2 threads.
 * Seeded cases: odd widths, padded strides (the n10 rows' padding holds
 * garbage), soft, sparse and empty masks; packed normals with every
 * component code (-512..511, so k = -511, 511 and the unused -512),
 * zero components, fully zero normals (replaced by V), and garbage in bits
 * 30-31 (fuse.h: ignored, as ef_n10_k ignores them); 0, 1, 2 and more
 * lights, with and without specular, Fresnel fade, tone, negative
 * colours. Also the span kernels of each ISA directly, fuse_context_frame
 * and the banded frame with depth tests and edge fades, and the checks
 * (both forms, neither, a short stride). An ISA the CPU (or EGOFUSE_ISA)
 * does not allow is reported as SKIP, never as passed. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/cpu/ef_n10.h"
#include "../src/fuse/fuse.h"
#include "../src/fuse/fuse_edge.h"
#include "../src/fuse/fuse_internal.h"

#define N_CTX 5   /* ref, sse2, avx2, avx512, neon */
static const ef_isa isas[N_CTX] = { EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512,
                                    EF_ISA_NEON };

/* 1 for a path of another architecture: not there to run, not a skip. */
static int other_arch(ef_isa isa)
{
#if defined(__aarch64__)
    return isa != EF_ISA_NEON && isa != EF_ISA_REF;
#elif defined(__x86_64__) || defined(__i386__)
    return isa == EF_ISA_NEON;
#else
    return isa != EF_ISA_REF;
#endif
}

typedef struct ctxs {
    fuse_context *c[N_CTX][2];   /* 1 thread, 2 threads; NULL: missing */
} ctxs;

/* Returns how many of this architecture's ISAs are missing (printed). */
static int ctxs_make(ctxs *cx)
{
    int i, t, missing = 0;
    for (i = 0; i < N_CTX; i++) {
        for (t = 0; t < 2; t++) {
            fuse_context_desc d = { isas[i], t + 1 };
            cx->c[i][t] = fuse_context_create(&d);
            assert_non_null(cx->c[i][t]);
            assert_int_equal(fuse_context_threads(cx->c[i][t]), t + 1);
        }
        if (fuse_context_isa(cx->c[i][0]) != isas[i]) {
            fuse_context_destroy(cx->c[i][0]);
            fuse_context_destroy(cx->c[i][1]);
            cx->c[i][0] = cx->c[i][1] = NULL;
            if (other_arch(isas[i])) {
                printf("NOTE %s: another architecture's path, not run here\n", ef_isa_name(isas[i]));
            } else {
                printf("SKIP %s: not available (cpu best %s, EGOFUSE_ISA %s)\n",
                       ef_isa_name(isas[i]), ef_isa_name(ef_cpu_best()),
                       getenv("EGOFUSE_ISA") ? getenv("EGOFUSE_ISA") : "unset");
                missing++;
            }
        }
    }
    return missing;
}

static void ctxs_free(ctxs *cx)
{
    int i;
    for (i = 0; i < N_CTX; i++) {
        fuse_context_destroy(cx->c[i][0]);
        fuse_context_destroy(cx->c[i][1]);
    }
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    assert_non_null(p);
    return p;
}

/* ---- one case: an image, a mask, packed normals and their floats ------- */

typedef struct n10_case {
    fuse_lighting L;
    fuse_intrinsics K;
    int w, h, pstride, mstride, qstride, fstride;
    uint8_t *P, *M;
    uint32_t *Nq;   /* qstride uint32_t a row */
    float *Nf;      /* fstride floats a row: ef_n10_unpack of Nq */
} n10_case;

/* A random 10-bit code, the edges often. */
static uint32_t code(tu_rng *r)
{
    static const int edge[] = { -512, -511, -510, -1, 0, 1, 510, 511 };
    const int k = tu_int(r, 3) == 0 ? edge[tu_int(r, 8)] : tu_int(r, 1024) - 512;
    return (uint32_t)k & 0x3ffu;
}

/* A packed normal: a packed unit vector, random codes, zero components,
 * all zero; sometimes with garbage in bits 30-31. */
static uint32_t packed(tu_rng *r)
{
    uint32_t v;
    switch (tu_int(r, 6)) {
    case 0: {
        const float a = tu_range(r, -1, 1), b = tu_range(r, -1, 1), c = tu_range(r, -0.2f, 1);
        const float l = sqrtf(a * a + b * b + c * c) + 1e-6f;
        v = ef_n10_pack(a / l, b / l, c / l);
        break;
    }
    case 1: { /* out of range: clamped (drawn x, y, z in this order) */
        const float a = tu_range(r, -1.5f, 1.5f), b = tu_range(r, -1.5f, 1.5f),
                    c = tu_range(r, -1.5f, 1.5f);
        v = ef_n10_pack(a, b, c);
        break;
    }
    case 2: v = 0; break;                                                  /* no normal */
    case 3: { /* one axis: its code, then which */
        const uint32_t k = code(r);
        v = k << (10 * tu_int(r, 3));
        break;
    }
    default: { /* random codes, x, y, z in this order */
        const uint32_t x = code(r), y = code(r), z = code(r);
        v = x | y << 10 | z << 20;
        break;
    }
    }
    if (tu_int(r, 4) == 0) v |= (uint32_t)tu_int(r, 4) << 30;              /* garbage, ignored */
    return v;
}

static void make_lighting(tu_rng *r, fuse_lighting *L)
{
    static const float shin[] = { 1.0f, 2.0f, 5.5f, 16.0f, 64.0f, 200.0f };
    static const int counts[] = { 1, 1, 1, 2, 2, 2, 0, 3, 5 };
    int i, c;
    *L = fuse_lighting_default();
    L->light_count = counts[tu_int(r, 9)];
    for (i = 0; i < L->light_count; i++) {
        const float sc = tu_range(r, 0.3f, 3.0f);
        for (c = 0; c < 3; c++) {
            L->lights[i].dir[c] = tu_range(r, -1, 1) * sc;
            L->lights[i].color[c] = tu_int(r, 4) ? tu_range(r, 0.0f, 1.5f) : tu_range(r, -0.2f, 1.5f);
        }
    }
    for (c = 0; c < 3; c++) {
        L->ambient[c] = tu_range(r, tu_int(r, 3) ? 0.0f : -0.1f, 0.7f);
        L->tone[c] = tu_int(r, 3) ? 1.0f : tu_range(r, 0.3f, 2.0f);
    }
    L->kd = tu_range(r, 0, 1.2f);
    L->ks = tu_int(r, 5) == 0 ? 0.0f : tu_range(r, 0, 1.5f);
    L->shininess = tu_int(r, 2) ? shin[tu_int(r, 6)] : tu_range(r, 1.0f, 300.0f);
    L->kf = tu_int(r, 4) == 0 ? 0.0f : tu_range(r, 0.0f, 1.0f);
}

static void case_make(tu_rng *r, n10_case *c, int wmax, int hmax)
{
    int x, y, style = tu_int(r, 5);
    make_lighting(r, &c->L);
    c->w = 1 + tu_int(r, tu_int(r, 4) ? wmax / 4 : wmax);
    c->h = 1 + tu_int(r, hmax);
    c->pstride = 4 * c->w + 4 * tu_int(r, 3);
    c->mstride = c->w + tu_int(r, 9);
    c->qstride = c->w + tu_int(r, 5);
    c->fstride = 3 * c->w + tu_int(r, 5);
    c->K.fx = tu_range(r, 0.3f, 2.0f) * (float)c->w;
    c->K.fy = c->K.fx * tu_range(r, 0.9f, 1.1f);
    c->K.cx = tu_int(r, 2) ? 0.5f * (float)c->w : tu_range(r, -0.5f, 1.5f) * (float)c->w;
    c->K.cy = tu_int(r, 2) ? 0.5f * (float)c->h : tu_range(r, -0.5f, 1.5f) * (float)c->h;
    c->P = xmalloc((size_t)c->pstride * c->h);
    c->M = xmalloc((size_t)c->mstride * c->h);
    c->Nq = xmalloc(sizeof(uint32_t) * (size_t)c->qstride * c->h);
    c->Nf = xmalloc(sizeof(float) * (size_t)c->fstride * c->h);
    for (x = 0; x < c->pstride * c->h; x++) c->P[x] = (uint8_t)tu_int(r, 256);
    for (x = 0; x < c->mstride * c->h; x++) c->M[x] = (uint8_t)tu_int(r, 256);   /* padding too */
    for (x = 0; x < c->qstride * c->h; x++) c->Nq[x] = (uint32_t)tu_next(r);     /* padding garbage */
    for (x = 0; x < c->fstride * c->h; x++) c->Nf[x] = -7.0f;
    for (y = 0; y < c->h; y++)
        for (x = 0; x < c->w; x++) {
            uint8_t *m = c->M + (size_t)y * c->mstride + x;
            const int k = tu_int(r, 100);
            switch (style) {   /* empty, sparse, runs, soft, full */
            case 0: *m = 0; break;
            case 1: *m = k < 85 ? 0 : (uint8_t)(1 + tu_int(r, 255)); break;
            case 2: *m = ((x / 13 + y) & 1) ? 255 : 0; break;
            case 3: *m = (uint8_t)tu_int(r, 256); break;
            default: *m = 255; break;
            }
            c->Nq[(size_t)y * c->qstride + x] = packed(r);
            ef_n10_unpack(c->Nq[(size_t)y * c->qstride + x], c->Nf + (size_t)y * c->fstride + 3 * x);
        }
}

static void case_free(n10_case *c)
{
    free(c->P);
    free(c->M);
    free(c->Nq);
    free(c->Nf);
}

static int report(const char *what, const char *isa, int t, int n, const uint8_t *want,
                  const uint8_t *got, size_t bytes, int stride)
{
    size_t i;
    for (i = 0; i < bytes; i++)
        if (want[i] != got[i]) {
            print_error("%s %s threads %d case %d: byte %zu (x %zu, y %zu, channel %zu) is %d, "
                        "want %d\n", what, isa, t, n, i, (i % (size_t)stride) / 4,
                        i / (size_t)stride, i % 4, got[i], want[i]);
            return 1;
        }
    return 0;
}

/* ---- fuse_light_n10, fuse_context_light_n10 ---------------------------- */

/* Every ISA, 1 and 2 threads, and fuse_light_n10 (the default ISA): the
 * float reference's bytes on ef_n10_unpack's floats. */
static void test_light_cases(void **state)
{
    enum { CASES = 1200 };
    ctxs cx;
    int n, i, t, bad = 0, missing;
    (void)state;
    missing = ctxs_make(&cx);
    for (n = 0; n < CASES && bad < 5; n++) {
        tu_rng r = { 0x6e31305fu + 7919u * (uint64_t)n };
        n10_case c;
        size_t bytes;
        uint8_t *want, *got;
        fuse_image P, out;
        case_make(&r, &c, 300, 7);
        bytes = (size_t)c.pstride * c.h;
        want = xmalloc(bytes);
        got = xmalloc(bytes);
        P = (fuse_image){ c.P, c.w, c.h, c.pstride };
        memset(want, 0xA5, bytes);
        out = (fuse_image){ want, c.w, c.h, c.pstride };
        assert_int_equal(fuse_context_light(cx.c[0][0], &c.L, &c.K, &P, c.M, c.mstride, c.Nf,
                                            c.fstride, &out), FUSE_OK);
        for (i = 0; i < N_CTX; i++)
            for (t = 0; t < 2; t++) {
                if (cx.c[i][t] == NULL) continue;
                memset(got, 0xA5, bytes);
                out.pixels = got;
                assert_int_equal(fuse_context_light_n10(cx.c[i][t], &c.L, &c.K, &P, c.M, c.mstride,
                                                        c.Nq, c.qstride, &out), FUSE_OK);
                bad += report("light_n10", ef_isa_name(isas[i]), t + 1, n, want, got, bytes,
                              c.pstride);
            }
        memset(got, 0xA5, bytes);
        out.pixels = got;
        assert_int_equal(fuse_light_n10(&c.L, &c.K, &P, c.M, c.mstride, c.Nq, c.qstride, &out),
                         FUSE_OK);
        bad += report("fuse_light_n10", "default", 1, n, want, got, bytes, c.pstride);
        /* in place: out == P */
        if (n % 8 == 0) {   /* the padding keeps P's bytes */
            int y;
            memcpy(got, c.P, bytes);
            out = (fuse_image){ got, c.w, c.h, c.pstride };
            assert_int_equal(fuse_light_n10(&c.L, &c.K, &out, c.M, c.mstride, c.Nq, c.qstride,
                                            &out), FUSE_OK);
            for (y = 0; y < c.h; y++)
                memcpy(want + (size_t)y * c.pstride + 4 * (size_t)c.w,
                       c.P + (size_t)y * c.pstride + 4 * (size_t)c.w, (size_t)(c.pstride - 4 * c.w));
            bad += report("fuse_light_n10 in place", "default", 1, n, want, got, bytes, c.pstride);
        }
        free(want);
        free(got);
        case_free(&c);
    }
    ctxs_free(&cx);
    assert_int_equal(bad, 0);
    if (missing) skip();
}

/* Every component code: rows of 1024 + 7 pixels where pixel i holds code
 * i in x, (7 i) mod 1024 in y, (13 i + 5) mod 1024 in z, lit from several
 * light setups (specular on the normal's direction, with and without
 * Fresnel); on every ISA. */
static void test_all_codes(void **state)
{
    enum { W = 1024 + 7, H = 3 };
    ctxs cx;
    int i, t, s, x, y, bad = 0, missing;
    uint32_t *Nq = xmalloc(sizeof(uint32_t) * W * H);
    float *Nf = xmalloc(sizeof(float) * 3 * W * H);
    uint8_t *P = xmalloc(4 * W * H), *M = xmalloc(W * H), *want = xmalloc(4 * W * H),
            *got = xmalloc(4 * W * H);
    tu_rng r = { 1234567 };
    fuse_intrinsics K = { 700.0f, 700.0f, 0.5f * W, 1.5f };
    (void)state;
    missing = ctxs_make(&cx);
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            const int i0 = x % 1024 + y;
            const uint32_t v = ((uint32_t)i0 & 0x3ffu) | (((uint32_t)(7 * i0) & 0x3ffu) << 10) |
                               (((uint32_t)(13 * i0 + 5) & 0x3ffu) << 20) |
                               ((uint32_t)(x & 3) << 30);
            Nq[y * W + x] = v;
            ef_n10_unpack(v, Nf + 3 * (y * W + x));
            M[y * W + x] = 255;
        }
    for (i = 0; i < 4 * W * H; i++) P[i] = (uint8_t)(40 + tu_int(&r, 216));
    for (s = 0; s < 4; s++) {
        fuse_lighting L = fuse_lighting_default();
        fuse_image Pi = { P, W, H, 4 * W }, out = { want, W, H, 4 * W };
        L.light_count = 1 + (s & 1);
        L.lights[1] = (fuse_light_src){ { -0.5f, 0.2f, 0.8f }, { 0.6f, 0.5f, 0.4f } };
        L.ks = 0.8f;
        L.shininess = s < 2 ? 16.0f : 37.5f;
        L.kf = s == 3 ? 0.0f : 0.6f;
        L.tone[0] = s == 2 ? 1.3f : 1.0f;
        assert_int_equal(fuse_context_light(cx.c[0][0], &L, &K, &Pi, M, W, Nf, 3 * W, &out), FUSE_OK);
        for (i = 0; i < N_CTX; i++)
            for (t = 0; t < 2; t++) {
                if (cx.c[i][t] == NULL) continue;
                memset(got, 0x3C, 4 * W * H);
                out.pixels = got;
                assert_int_equal(fuse_context_light_n10(cx.c[i][t], &L, &K, &Pi, M, W, Nq, W, &out),
                                 FUSE_OK);
                bad += report("all codes", ef_isa_name(isas[i]), t + 1, s, want, got, 4 * W * H, 4 * W);
                out.pixels = want;
            }
    }
    ctxs_free(&cx);
    free(Nq); free(Nf); free(P); free(M); free(want); free(got);
    assert_int_equal(bad, 0);
    if (missing) skip();
}

/* The span kernels themselves (fuse_internal.h), on spans that start and
 * end anywhere: fuse__light_span_n10_<isa> against fuse__light_span_<isa>
 * and fuse__light_span_ref on the unpacked floats; outside the span
 * nothing is written. */
static void test_span_kernels(void **state)
{
    static const struct {
        ef_isa isa;
        fuse__light_span_fn f;
        fuse__light_span_n10_fn q;
    } k[] = {
        { EF_ISA_REF, fuse__light_span_ref, fuse__light_span_n10_ref },
        { EF_ISA_SSE2, fuse__light_span_sse2, fuse__light_span_n10_sse2 },
        { EF_ISA_AVX2, fuse__light_span_avx2, fuse__light_span_n10_avx2 },
        { EF_ISA_AVX512, fuse__light_span_avx512, fuse__light_span_n10_avx512 },
        { EF_ISA_NEON, fuse__light_span_neon, fuse__light_span_n10_neon },
    };
    int n, i, bad = 0, missing = 0;
    (void)state;
    for (i = 0; i < 5; i++)
        if (ef_isa_choose(k[i].isa) != k[i].isa && !other_arch(k[i].isa)) {
            printf("SKIP %s: not available\n", ef_isa_name(k[i].isa));
            missing++;
        }
    for (n = 0; n < 600 && bad < 5; n++) {
        tu_rng r = { 0xabcdefu + 31u * (uint64_t)n };
        n10_case c;
        fuse__light_prep prep;
        int x0, x1, y;
        uint8_t *want, *got;
        case_make(&r, &c, 200, 3);
        assert_int_equal(fuse__light_prepare(&c.L, &c.K, &prep), FUSE_OK);
        y = tu_int(&r, c.h);
        x0 = tu_int(&r, c.w);
        x1 = x0 + tu_int(&r, c.w - x0 + 1);
        want = xmalloc(4 * (size_t)c.w);
        got = xmalloc(4 * (size_t)c.w);
        memset(want, 0x11, 4 * (size_t)c.w);
        fuse__light_span_ref(&prep, y, x0, x1, c.P + (size_t)y * c.pstride, c.M + (size_t)y * c.mstride,
                             c.Nf + (size_t)y * c.fstride, want);
        for (i = 0; i < 5; i++) {
            if (ef_isa_choose(k[i].isa) != k[i].isa) continue;
            memset(got, 0x11, 4 * (size_t)c.w);
            k[i].q(&prep, y, x0, x1, c.P + (size_t)y * c.pstride, c.M + (size_t)y * c.mstride,
                   c.Nq + (size_t)y * c.qstride, got);
            bad += report("span n10", ef_isa_name(k[i].isa), 1, n, want, got, 4 * (size_t)c.w, 4 * c.w);
            memset(got, 0x11, 4 * (size_t)c.w);
            k[i].f(&prep, y, x0, x1, c.P + (size_t)y * c.pstride, c.M + (size_t)y * c.mstride,
                   c.Nf + (size_t)y * c.fstride, got);
            bad += report("span float", ef_isa_name(k[i].isa), 1, n, want, got, 4 * (size_t)c.w, 4 * c.w);
        }
        free(want);
        free(got);
        case_free(&c);
    }
    assert_int_equal(bad, 0);
    if (missing) skip();
}

/* ---- fuse_context_frame and the banded frame ---------------------------- */

typedef struct frame_case {
    n10_case c;
    int W, H, vx, vy, vw, vh, v_opaque, edge, depth;
    uint8_t *V, *Q, *out;
    float *hand, *scene;
    fuse_depth d;
} frame_case;

static void frame_make(tu_rng *r, frame_case *f)
{
    int i;
    case_make(r, &f->c, 160, 40);
    f->W = 1 + tu_int(r, 300);
    f->H = 1 + tu_int(r, 60);
    f->vw = 1 + tu_int(r, f->W);
    f->vh = 1 + tu_int(r, f->H);
    f->vx = tu_int(r, f->W - f->vw + 1);
    f->vy = tu_int(r, f->H - f->vh + 1);
    f->v_opaque = tu_int(r, 2);
    f->edge = tu_int(r, 3) == 0;
    f->depth = tu_int(r, 2);
    f->V = xmalloc(4 * (size_t)f->W * f->H);
    f->out = xmalloc(4 * (size_t)f->W * f->H);
    f->Q = xmalloc((size_t)f->c.pstride * f->c.h);
    for (i = 0; i < 4 * f->W * f->H; i++) f->V[i] = (uint8_t)(i % 4 == 3 ? 255 : tu_int(r, 256));
    f->hand = xmalloc(sizeof(float) * (size_t)f->c.w * f->c.h);
    f->scene = xmalloc(sizeof(float) * (size_t)f->W * f->H);
    for (i = 0; i < f->c.w * f->c.h; i++) f->hand[i] = tu_range(r, 0.0f, 1.2f);
    for (i = 0; i < f->W * f->H; i++) f->scene[i] = tu_int(r, 2) ? tu_range(r, 0.0f, 3.0f) : 0.0f;
    f->d = (fuse_depth){ f->hand, f->c.w, 0.1f, 10.0f, 0.0f, f->scene, f->W, f->W, f->H };
}

static void frame_free(frame_case *f)
{
    case_free(&f->c);
    free(f->V); free(f->out); free(f->Q); free(f->hand); free(f->scene);
}

/* The eye with float (n10 0) or packed normals; out and Q reset. */
static fuse_eye frame_bind(frame_case *f, int n10)
{
    fuse_eye e;
    memset(&e, 0, sizeof e);
    memset(f->out, 0x77, 4 * (size_t)f->W * f->H);
    memset(f->Q, 0x5A, (size_t)f->c.pstride * f->c.h);
    e.lighting = &f->c.L;
    e.intrinsics = &f->c.K;
    e.P = (fuse_image){ f->c.P, f->c.w, f->c.h, f->c.pstride };
    e.mask = f->c.M;
    e.mask_stride = f->c.mstride;
    if (n10) {
        e.normal_n10 = f->c.Nq;
        e.normal_n10_stride = f->c.qstride;
        e.normal_stride = -1;   /* not looked at */
    } else {
        e.normal = f->c.Nf;
        e.normal_stride = f->c.fstride;
        e.normal_n10_stride = -1;
    }
    e.Q = (fuse_image){ f->Q, f->c.w, f->c.h, f->c.pstride };
    e.depth = f->depth ? &f->d : NULL;
    e.V = (fuse_image){ f->V, f->W, f->H, 4 * f->W };
    e.vp_x0 = f->vx;
    e.vp_y0 = f->vy;
    e.vp_w = f->vw;
    e.vp_h = f->vh;
    e.out = (fuse_image){ f->out, f->W, f->H, 4 * f->W };
    e.v_opaque = f->v_opaque;
    e.edge_fade = f->edge ? 3 : 0;
    e.edge_sides = f->edge ? FUSE_EDGE_ALL : 0u;
    return e;
}

/* fuse_context_frame with fuse_eye.normal_n10 (one and two eyes, 1 and 2
 * threads: whole eyes and row bands) and the banded frame
 * (fuse_context_frame_prepare / _band / _finish) on every ISA: the Q and
 * out of the float frame on the reference. */
static void test_frame_cases(void **state)
{
    enum { FRAMES = 120 };
    ctxs cx;
    int n, i, t, bad = 0, missing;
    (void)state;
    missing = ctxs_make(&cx);
    for (n = 0; n < FRAMES && bad < 5; n++) {
        tu_rng r = { 0x5eed0000u + 104729u * (uint64_t)n };
        frame_case f[2];
        uint8_t *wq[2], *wo[2];
        int e;
        for (e = 0; e < 2; e++) frame_make(&r, &f[e]);
        for (e = 0; e < 2; e++) {   /* expected: each eye alone, floats, reference */
            const fuse_eye fe = frame_bind(&f[e], 0);
            assert_int_equal(fuse_context_frame(cx.c[0][0], &fe, 1), FUSE_OK);
            wq[e] = xmalloc((size_t)f[e].c.pstride * f[e].c.h);
            wo[e] = xmalloc(4 * (size_t)f[e].W * f[e].H);
            memcpy(wq[e], f[e].Q, (size_t)f[e].c.pstride * f[e].c.h);
            memcpy(wo[e], f[e].out, 4 * (size_t)f[e].W * f[e].H);
        }
        for (i = 0; i < N_CTX; i++)
            for (t = 0; t < 2; t++) {
                fuse_context *ctx = cx.c[i][t];
                fuse_eye fe[2];
                int count = 1 + (n + t) % 2, nb = 0, b;
                if (ctx == NULL) continue;
                for (e = 0; e < count; e++) fe[e] = frame_bind(&f[e], 1);
                assert_int_equal(fuse_context_frame(ctx, fe, count), FUSE_OK);
                for (e = 0; e < count; e++) {
                    bad += report("frame Q", ef_isa_name(isas[i]), t + 1, n, wq[e], f[e].Q,
                                  (size_t)f[e].c.pstride * f[e].c.h, f[e].c.pstride);
                    bad += report("frame out", ef_isa_name(isas[i]), t + 1, n, wo[e], f[e].out,
                                  4 * (size_t)f[e].W * f[e].H, 4 * f[e].W);
                }
                /* the banded frame of eye 0 */
                fe[0] = frame_bind(&f[0], 1);
                assert_int_equal(fuse_context_frame_prepare(ctx, &fe[0], 1 + n % 23, &nb), FUSE_OK);
                for (b = nb - 1; b >= 0; b--) fuse_context_frame_band(ctx, b);
                fuse_context_frame_finish(ctx);
                bad += report("banded Q", ef_isa_name(isas[i]), t + 1, n, wq[0], f[0].Q,
                              (size_t)f[0].c.pstride * f[0].c.h, f[0].c.pstride);
                bad += report("banded out", ef_isa_name(isas[i]), t + 1, n, wo[0], f[0].out,
                              4 * (size_t)f[0].W * f[0].H, 4 * f[0].W);
            }
        for (e = 0; e < 2; e++) {
            free(wq[e]);
            free(wo[e]);
            frame_free(&f[e]);
        }
    }
    ctxs_free(&cx);
    assert_int_equal(bad, 0);
    if (missing) skip();
}

/* ---- checks ---------------------------------------------------------- */

static void test_checks(void **state)
{
    enum { W = 9, H = 4, OW = 20, OH = 12 };
    uint8_t P[4 * W * H], M[W * H], Q[4 * W * H], V[4 * OW * OH], O[4 * OW * OH], keep[4 * W * H];
    uint32_t Nq[W * H];
    float Nf[3 * W * H];
    fuse_lighting L = fuse_lighting_default();
    fuse_intrinsics K = { 10.0f, 10.0f, 4.5f, 2.0f };
    fuse_image Pi = { P, W, H, 4 * W }, Qi = { Q, W, H, 4 * W };
    fuse_context *ctx = fuse_context_create(NULL);
    fuse_eye e;
    int i, nb = -1;
    (void)state;
    assert_non_null(ctx);
    for (i = 0; i < W * H; i++) {
        Nq[i] = ef_n10_pack(0.0f, 0.6f, 0.8f);
        ef_n10_unpack(Nq[i], Nf + 3 * i);
        M[i] = 255;
    }
    memset(P, 0x80, sizeof P);
    memset(V, 0x40, sizeof V);
    memset(Q, 0xEE, sizeof Q);
    memcpy(keep, Q, sizeof Q);
    /* the n10 calls: NULL normals, stride below the width, ctx NULL */
    assert_int_equal(fuse_light_n10(&L, &K, &Pi, M, W, NULL, W, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_light_n10(&L, &K, &Pi, M, W, Nq, W - 1, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_light_n10(&L, &K, &Pi, M, W, Nq, 0, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_light_n10(&L, &K, &Pi, NULL, W, Nq, W, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_context_light_n10(NULL, &L, &K, &Pi, M, W, Nq, W, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_context_light_n10(ctx, &L, &K, &Pi, M, W, Nq, W - 1, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_context_light_n10(ctx, &L, &K, &Pi, M, W, NULL, W, &Qi), FUSE_ERR_ARGS);
    assert_memory_equal(Q, keep, sizeof Q);   /* nothing written */
    /* the float calls still reject NULL normals */
    assert_int_equal(fuse_light(&L, &K, &Pi, M, W, NULL, 3 * W, &Qi), FUSE_ERR_ARGS);
    assert_int_equal(fuse_context_light(ctx, &L, &K, &Pi, M, W, NULL, 3 * W, &Qi), FUSE_ERR_ARGS);
    /* the smallest stride is fine */
    assert_int_equal(fuse_context_light_n10(ctx, &L, &K, &Pi, M, W, Nq, W, &Qi), FUSE_OK);
    /* fuse_eye: exactly one form */
    memset(&e, 0, sizeof e);
    e.lighting = &L;
    e.intrinsics = &K;
    e.P = Pi;
    e.mask = M;
    e.mask_stride = W;
    e.Q = Qi;
    e.V = (fuse_image){ V, OW, OH, 4 * OW };
    e.vp_x0 = 1;
    e.vp_y0 = 1;
    e.vp_w = 15;
    e.vp_h = 9;
    e.out = (fuse_image){ O, OW, OH, 4 * OW };
    memset(Q, 0xEE, sizeof Q);
    memset(O, 0xDD, sizeof O);
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_ERR_ARGS);             /* neither */
    assert_int_equal(fuse_context_frame_prepare(ctx, &e, 4, &nb), FUSE_ERR_ARGS);
    e.normal = Nf;
    e.normal_stride = 3 * W;
    e.normal_n10 = Nq;
    e.normal_n10_stride = W;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_ERR_ARGS);             /* both */
    assert_int_equal(fuse_context_frame_prepare(ctx, &e, 4, &nb), FUSE_ERR_ARGS);
    e.normal = NULL;
    e.normal_n10_stride = W - 1;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_ERR_ARGS);             /* short */
    assert_int_equal(fuse_context_frame_prepare(ctx, &e, 4, &nb), FUSE_ERR_ARGS);
    assert_int_equal(nb, -1);
    for (i = 0; i < (int)sizeof Q; i++) assert_int_equal(Q[i], 0xEE);
    for (i = 0; i < (int)sizeof O; i++) assert_int_equal(O[i], 0xDD);
    /* the other form's stride is not looked at */
    e.normal_n10_stride = W;
    e.normal_stride = -5;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_OK);
    e.normal = Nf;
    e.normal_stride = 3 * W;
    e.normal_n10 = NULL;
    e.normal_n10_stride = -5;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_OK);
    e.normal_stride = 3 * W - 1;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_ERR_ARGS);
    fuse_context_destroy(ctx);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_light_cases),
        cmocka_unit_test(test_all_codes),
        cmocka_unit_test(test_span_kernels),
        cmocka_unit_test(test_frame_cases),
        cmocka_unit_test(test_checks),
    };
    (void)argc;
    (void)argv;
    return cmocka_run_group_tests(tests, NULL, NULL);
}
