/* test_fuse_light.c - fuse_light (the lighting layer, eq. 6 of the paper)
 * against a double-precision reference written here from the formulas of
 * fuse.h, hand-worked single pixels, parameter validation and a CRC32 of
 * seeded cases that pins the exact bytes (docs/fuse.md). */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/fuse/fuse.h"
#include "../src/fuse/fuse_internal.h"
#include "../src/cpu/ef_mem.h"

/* CRC32 over the outputs of crc_cases(). It changes only when the rules
 * of docs/fuse.md change on purpose; then record the printed value. */
#define LIGHT_CRC 0xEF99B600u   /* issue 14: Schlick Fresnel (was 0x9D72228B) */

/* ---- test images ---------------------------------------------------- */

typedef struct scene {
    int w, h;
    uint8_t *P, *mask, *out;
    float *nrm;
    fuse_image Pi, Oi;
} scene;

static void scene_alloc(scene *s, int w, int h)
{
    s->w = w;
    s->h = h;
    s->P = malloc((size_t)w * h * 4);
    s->out = malloc((size_t)w * h * 4);
    s->mask = malloc((size_t)w * h);
    s->nrm = malloc((size_t)w * h * 3 * sizeof(float));
    assert_non_null(s->P);
    assert_non_null(s->out);
    assert_non_null(s->mask);
    assert_non_null(s->nrm);
    s->Pi = (fuse_image){ s->P, w, h, 4 * w };
    s->Oi = (fuse_image){ s->out, w, h, 4 * w };
}

static void scene_free(scene *s)
{
    EF_FREE_ALL(s->P, s->out, s->mask, s->nrm);
}

/* Random P, a mask with 0, 255 and soft values, normals: unit, scaled
 * (0.1..10), a few zero and non-finite ones. */
static void scene_random(scene *s, tu_rng *r)
{
    int i, n = s->w * s->h;
    for (i = 0; i < 4 * n; i++) s->P[i] = (uint8_t)tu_int(r, 256);
    for (i = 0; i < n; i++) {
        int k = tu_int(r, 8);
        s->mask[i] = k < 2 ? 0 : k < 5 ? 255 : (uint8_t)(1 + tu_int(r, 254));
    }
    for (i = 0; i < n; i++) {
        float *v = s->nrm + 3 * i, len;
        int k = tu_int(r, 64);
        do {
            v[0] = tu_range(r, -1, 1);
            v[1] = tu_range(r, -1, 1);
            v[2] = tu_range(r, -1, 1);
            len = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        } while (len < 0.05f || len > 1.0f);
        if (k < 32) {                         /* unit */
            v[0] /= len; v[1] /= len; v[2] /= len;
        } else if (k < 60) {                  /* not unit */
            float sc = tu_range(r, 0.1f, 10.0f);
            v[0] *= sc; v[1] *= sc; v[2] *= sc;
        } else if (k < 62) {
            v[0] = v[1] = v[2] = 0.0f;        /* zero: N = V */
        } else {
            v[tu_int(r, 3)] = k == 62 ? NAN : INFINITY;
        }
    }
}

/* ---- double-precision reference -------------------------------------- */

static void norm3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= l; v[1] /= l; v[2] /= l;
}
static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static double clamp01d(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

/* Unrounded 255 * M' * P' (rgb) and 255 * M' (alpha) of one pixel. */
static void ref_pixel(const fuse_lighting *L, const fuse_intrinsics *K,
                      int x, int y, const uint8_t *p, int m, const float *n,
                      double res[4])
{
    double V[3], N[3], C[3], nn, F, mp;
    int i, c;
    if (m == 0) { res[0] = res[1] = res[2] = res[3] = 0; return; }
    V[0] = -((x + 0.5 - K->cx) / K->fx);
    V[1] = (y + 0.5 - K->cy) / K->fy;
    V[2] = 1.0;
    norm3(V);
    nn = (double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2];
    if (isfinite(nn) && nn > 1e-30 && nn < 1e30) {
        N[0] = n[0]; N[1] = n[1]; N[2] = n[2];
        norm3(N);
    } else {
        memcpy(N, V, sizeof N);
    }
    for (c = 0; c < 3; c++) C[c] = L->ambient[c];
    for (i = 0; i < L->light_count; i++) {
        double Ld[3] = { L->lights[i].dir[0], L->lights[i].dir[1], L->lights[i].dir[2] };
        double H[3], w;
        norm3(Ld);
        H[0] = Ld[0] + V[0]; H[1] = Ld[1] + V[1]; H[2] = Ld[2] + V[2];
        norm3(H);
        w = L->kd * fmax(0.0, dot3(N, Ld)) +
            L->ks * pow(fmin(1.0, fmax(0.0, dot3(N, H))), L->shininess);
        for (c = 0; c < 3; c++) C[c] += L->lights[i].color[c] * w;
    }
    F = fmin(1.0, fmax(0.0, 1.0 - dot3(N, V)));
    F = F * F * F * F * F;
    mp = m / 255.0 * clamp01d(1.0 - L->kf * F);
    for (c = 0; c < 3; c++)
        res[c] = 255.0 * mp * clamp01d(p[c] / 255.0 * C[c] * L->tone[c]);
    res[3] = 255.0 * mp;
}

/* ---- lighting sets --------------------------------------------------- */

static fuse_intrinsics intrinsics_for(int w, int h)
{
    /* 62 deg horizontal field of view, as the paper's cameras. */
    float f = (float)(0.5 * w / tan(31.0 * 3.14159265358979 / 180.0));
    fuse_intrinsics K = { f, f, 0.5f * (float)w, 0.5f * (float)h };
    return K;
}

static fuse_lighting random_lighting(tu_rng *r, int count)
{
    fuse_lighting L = fuse_lighting_default();
    static const float shin[] = { 1.0f, 2.0f, 2.5f, 7.3f, 16.0f, 64.0f, 200.0f };
    int i, c;
    L.light_count = count;
    for (i = 0; i < count; i++) {
        float sc = tu_range(r, 0.3f, 3.0f);   /* directions need not be unit */
        for (c = 0; c < 3; c++) {
            L.lights[i].dir[c] = tu_range(r, -1, 1) * sc;
            L.lights[i].color[c] = tu_range(r, 0, 1.2f);
        }
        if (L.lights[i].dir[2] < 0) L.lights[i].dir[2] = -L.lights[i].dir[2];
    }
    for (c = 0; c < 3; c++) {
        L.ambient[c] = tu_range(r, 0, 0.6f);
        L.tone[c] = tu_range(r, 0.5f, 1.5f);
    }
    L.kd = tu_range(r, 0, 1);
    L.ks = tu_range(r, 0, 1);
    L.shininess = shin[tu_int(r, 7)];
    L.kf = tu_range(r, 0, 1);
    return L;
}

/* Lights the scene and compares every channel with the reference. Returns
 * the number of channels that differ by one from the rounded reference;
 * fails on any larger difference. */
static long check_scene(const fuse_lighting *L, const fuse_intrinsics *K,
                        scene *s, double *max_err)
{
    long ones = 0;
    int x, y, c;
    memset(s->out, 0xA5, (size_t)s->w * s->h * 4);
    assert_int_equal(fuse_light(L, K, &s->Pi, s->mask, s->w, s->nrm, 3 * s->w, &s->Oi),
                     FUSE_OK);
    for (y = 0; y < s->h; y++)
        for (x = 0; x < s->w; x++) {
            int i = y * s->w + x;
            const uint8_t *o = s->out + 4 * i;
            double ref[4];
            ref_pixel(L, K, x, y, s->P + 4 * i, s->mask[i], s->nrm + 3 * i, ref);
            for (c = 0; c < 4; c++) {
                double e = fabs((double)o[c] - ref[c]);
                long d = labs((long)o[c] - (long)floor(ref[c] + 0.5));
                if (e > *max_err) *max_err = e;
                if (d > 1) {
                    print_error("pixel (%d,%d) ch %d: got %d, reference %.6f\n",
                                x, y, c, o[c], ref[c]);
                    fail();
                }
                ones += d;
            }
            for (c = 0; c < 3; c++) assert_true(o[c] <= o[3]);   /* premultiplied */
            if (s->mask[i] == 0) assert_int_equal(o[0] | o[1] | o[2] | o[3], 0);
        }
    return ones;
}

/* What the lighting-vs-double tests count: the largest error (LSB), and
 * how many of the channels checked are off by one. */
typedef struct err_tally {
    double max_err;
    long ones, channels;
} err_tally;

/* A random scene s (drawn from r) lit by L, checked against double and
 * counted into t. */
static void check_random_scene(const fuse_lighting *L, const fuse_intrinsics *K, scene *s,
                               tu_rng *r, err_tally *t)
{
    scene_random(s, r);
    t->ones += check_scene(L, K, s, &t->max_err);
    t->channels += 4L * s->w * s->h;
}

/* Prints the tally (`what` names the cases) and fails unless every channel
 * is within one LSB. */
static void tally_end(const char *what, const err_tally *t)
{
    printf("NOTE lighting vs double%s: max error %.4f LSB, %ld of %ld channels off by 1\n", what,
           t->max_err, t->ones, t->channels);
    assert_true(t->max_err < 1.0);
}

static void test_light_vs_double(void **state)
{
    static const int sizes[][2] = { { 160, 100 }, { 37, 23 }, { 640, 400 } };
    tu_rng r = { 0x5EED0001u };
    err_tally t = { 0, 0, 0 };
    int si, k;
    (void)state;
    for (si = 0; si < 3; si++) {
        scene s;
        fuse_intrinsics K = intrinsics_for(sizes[si][0], sizes[si][1]);
        scene_alloc(&s, sizes[si][0], sizes[si][1]);
        for (k = 0; k < (si == 2 ? 2 : 6); k++) {
            static const int counts[] = { 1, 0, 3, 8, 2, 5 };
            fuse_lighting L = k == 0 ? fuse_lighting_default()
                                     : random_lighting(&r, counts[k]);
            check_random_scene(&L, &K, &s, &r, &t);
        }
        scene_free(&s);
    }
    tally_end("", &t);
}

/* x^s of fuse__pow01 against pow(): the reproducible power is accurate.
 * Integer s up to FUSE__POW_INT_MAX go by squaring (relative error below
 * (s - 1) 2^-24), the others by exp2/log2 (1.3e-7 (1 + |s log2 x|)). */
static void test_pow01(void **state)
{
    static const float shin[] = { 1.0f, 1.5f, 2.0f, 3.7f, 5.0f, 16.0f, 63.0f, 64.0f, 65.0f,
                                  128.0f, 1000.0f };
    enum { NS = sizeof shin / sizeof shin[0] };
    tu_rng r = { 0x5EED0002u };
    double worst = 0, worst_int = 0;
    int i, k, ints = 0;
    (void)state;
    assert_true(fuse__pow01(1.0f, 16.0f) == 1.0f);
    assert_true(fuse__pow01(1.5f, 16.0f) == 1.0f);
    assert_true(fuse__pow01(0.0f, 1.0f) == 0.0f);
    assert_true(fuse__pow01(-0.5f, 2.0f) == 0.0f);
    assert_true(fuse__pow01(0.5f, 1.0f) == 0.5f);
    assert_true(fuse__pow01(0.25f, 2.0f) == 0.0625f);
    assert_true(fuse__pow01(0.5f, 16.0f) == 1.0f / 65536.0f);   /* squarings of a power of 2: exact */
    assert_true(fuse__pow01(0.75f, 3.0f) == 0.421875f);          /* 27/64, exact in float */
    assert_int_equal(fuse__pow_int(16.0f), 16);
    assert_int_equal(fuse__pow_int(64.0f), 64);
    assert_int_equal(fuse__pow_int(65.0f), 0);
    assert_int_equal(fuse__pow_int(2.5f), 0);
    assert_int_equal(fuse__pow_int(1.0f), 1);
    /* the order is fixed: x^3 = x * (x * x), x^5 = x * ((x x)(x x)) */
    {
        const float x = 0.9f, x2 = x * x, x4 = x2 * x2;
        assert_true(fuse__pow01(x, 3.0f) == x * x2);
        assert_true(fuse__pow01(x, 5.0f) == x * x4);
    }
    for (k = 0; k < NS; k++)
        for (i = 0; i < 20000; i++) {
            float x = i < 10000 ? tu_unit(&r) : 1.0f - tu_unit(&r) * 0.01f;
            double ref = pow(x, shin[k]);
            double got = fuse__pow01(x, shin[k]);
            if (ref > 1e-30) {
                if (fuse__pow_int(shin[k])) {
                    /* (s - 1) roundings, each at most 2^-24 relative */
                    double e = fabs(got - ref) / ref / ((shin[k] - 1.0) * 0x1p-24 + 0x1p-40);
                    if (e > worst_int) worst_int = e;
                    ints++;
                } else {
                    /* The float y = s log2(x) alone carries a relative error
                     * of 2^-24 |y| ln 2 into the result: scale by 1 + |y|. */
                    double y = fabs(shin[k] * log2((double)x));
                    double e = fabs(got - ref) / ref / (1.0 + y);
                    if (e > worst) worst = e;
                }
            } else {
                assert_true(got < 1e-30);
            }
        }
    printf("NOTE pow01: max relative error / (1 + |s log2 x|) %.3g (exp2/log2); "
           "/ ((s - 1) 2^-24) %.3g (squaring, %d values)\n", worst, worst_int, ints);
    assert_true(worst < 1e-6);
    assert_true(worst_int <= 1.0);
    assert_true(ints > 50000);
}

/* fuse__spec01 (the specular power from the squared cosine, issue 17)
 * against pow(): x2 = x * x rounded, result x^s. Integer s by squaring x2
 * (and one square root for odd s): relative error below about
 * (s / 2 + 1) 2^-24 for the squarings plus s / 2 times that of x2 (2^-24);
 * other s through fuse__pow01(x2, s / 2). */
static void test_spec01(void **state)
{
    static const float shin[] = { 1.0f, 1.5f, 2.0f, 3.0f, 3.7f, 5.0f, 16.0f, 20.0f, 63.0f,
                                  64.0f, 65.0f, 128.0f, 1000.0f };
    enum { NS = sizeof shin / sizeof shin[0] };
    tu_rng r = { 0x5EED0006u };
    double worst_int = 0, worst = 0;
    int i, k;
    (void)state;
    assert_true(fuse__spec01(1.0f, 16.0f, 16) == 1.0f);
    assert_true(fuse__spec01(2.0f, 3.0f, 3) == 1.0f);
    assert_true(fuse__spec01(0.0f, 1.0f, 1) == 0.0f);
    assert_true(fuse__spec01(0x1p-100f, 2.5f, 0) == 0.0f);
    assert_true(fuse__spec01(0.25f, 1.0f, 1) == 0.5f);          /* sqrt, exact */
    assert_true(fuse__spec01(0.25f, 2.0f, 2) == 0.25f);
    assert_true(fuse__spec01(0.25f, 3.0f, 3) == 0.125f);        /* x2 * sqrt(x2) */
    assert_true(fuse__spec01(0.25f, 20.0f, 20) == 0x1p-20f);    /* (x2^2)^2 * x2^8 */
    for (k = 0; k < NS; k++) {
        const int n = fuse__pow_int(shin[k]);
        for (i = 0; i < 20000; i++) {
            const float x = i < 10000 ? tu_unit(&r) : 1.0f - tu_unit(&r) * 0.01f;
            const double ref = pow(x, shin[k]);
            const double got = fuse__spec01(x * x, shin[k], n);
            if (ref > 1e-25) {
                const double e = fabs(got - ref) / ref;
                if (n) {
                    const double b = (shin[k] / 2.0 + 1.0) * 0x1p-24 + shin[k] * 0x1p-25;
                    if (e / b > worst_int) worst_int = e / b;
                } else {
                    /* pow01's bound, plus s/2 times the rounding of x2 */
                    const double y = fabs(shin[k] * log2((double)x));
                    const double b = 1.3e-7 * (1.0 + y) + shin[k] * 0x1p-25;
                    if (e / b > worst) worst = e / b;
                }
            } else {
                assert_true(got < 1e-20);
            }
        }
    }
    printf("NOTE spec01: max relative error / ((s/2 + 1) 2^-24 + s 2^-25) %.3g (integer s), "
           "/ (1.3e-7 (1 + |s log2 x|) + s 2^-25) %.3g (other s)\n", worst_int, worst);
    assert_true(worst_int <= 1.0);
    assert_true(worst <= 1.0);
}

/* The lighting against double where the specular term carries the output:
 * lights from every side (behind the surface, near -V, grazing), ks up to
 * 1, odd and large exponents. */
static void test_light_vs_double_spec(void **state)
{
    static const float shin[] = { 1.0f, 3.0f, 5.0f, 20.0f, 63.0f, 64.0f, 65.0f, 130.5f, 2.5f };
    tu_rng r = { 0x5EED0007u };
    fuse_intrinsics K = intrinsics_for(160, 100);
    err_tally t = { 0, 0, 0 };
    int k, i, c;
    scene s;
    (void)state;
    scene_alloc(&s, 160, 100);
    for (k = 0; k < 18; k++) {
        fuse_lighting L = fuse_lighting_default();
        L.light_count = 1 + k % 4;
        for (i = 0; i < L.light_count; i++) {
            for (c = 0; c < 3; c++) {
                L.lights[i].dir[c] = tu_range(&r, -1, 1);
                L.lights[i].color[c] = tu_range(&r, 0.5f, 1.0f);
            }
            if (k % 3 == 0 && i == 0) {   /* about -V of the image centre */
                L.lights[i].dir[0] = tu_range(&r, -0.05f, 0.05f);
                L.lights[i].dir[1] = tu_range(&r, -0.05f, 0.05f);
                L.lights[i].dir[2] = -1.0f;
            }
        }
        for (c = 0; c < 3; c++) {
            L.ambient[c] = tu_range(&r, 0, 0.2f);
            L.tone[c] = 1.0f;
        }
        L.kd = tu_range(&r, 0, 0.3f);
        L.ks = tu_range(&r, 0.5f, 1.0f);
        L.shininess = shin[k % 9];
        L.kf = tu_range(&r, 0, 1);
        check_random_scene(&L, &K, &s, &r, &t);
    }
    scene_free(&s);
    tally_end(", specular cases", &t);
}

/* The vector kernels' shortcuts for common parameters (fuse_simd.inl): kf
 * == 0 (+0 or -0) computes no fade, kd, ks, ambient and colours >= 0 no
 * max0 in the output clamp, an integer s >= 4 no 2^-100 test of the
 * power, and x2 >= 1 is min(x2, 1) before it. Each ISA of this machine
 * (EGOFUSE_ISA caps it) gives the reference's bytes on scenes made for
 * them: the sample scene's two lights, one to four lights with lights
 * near -V, large colours (P C > 1), every s from 1 to 9 and 20, 64. */
static void test_light_shortcuts_isa(void **state)
{
    static const ef_isa isas[] = { EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON };
    static const float shin[] = { 1, 2, 3, 4, 5, 6, 7, 8, 9, 20, 64, 2.5f };
    tu_rng r = { 0x5EED0017u };
    fuse_intrinsics K = intrinsics_for(77, 41);
    fuse_context_desc d = { EF_ISA_REF, 1 };
    fuse_context *ref = fuse_context_create(&d), *ctx[4];
    uint8_t *want = malloc((size_t)77 * 41 * 4);
    int k, i, c, j, tested = 0, bad = 0;
    scene s;
    (void)state;
    assert_non_null(ref);
    assert_non_null(want);
    for (j = 0; j < 4; j++) {
        d.max_isa = isas[j];
        ctx[j] = fuse_context_create(&d);
        assert_non_null(ctx[j]);
        if (fuse_context_isa(ctx[j]) != isas[j]) {   /* not here, or capped */
            fuse_context_destroy(ctx[j]);
            ctx[j] = NULL;
        }
    }
    scene_alloc(&s, 77, 41);
    for (k = 0; k < 96; k++) {
        fuse_lighting L = fuse_lighting_default();
        L.light_count = k % 8 == 0 ? 2 : 1 + k % 4;
        for (i = 0; i < L.light_count; i++)
            for (c = 0; c < 3; c++) {
                L.lights[i].dir[c] = tu_range(&r, -1, 1);
                L.lights[i].color[c] = tu_range(&r, 0, k % 3 == 0 ? 4.0f : 1.0f);
            }
        if (k % 5 == 0) {   /* about -V of the image centre */
            L.lights[0].dir[0] = tu_range(&r, -0.05f, 0.05f);
            L.lights[0].dir[1] = tu_range(&r, -0.05f, 0.05f);
            L.lights[0].dir[2] = -1.0f;
        }
        for (c = 0; c < 3; c++) {
            L.ambient[c] = tu_range(&r, 0, 0.4f);
            L.tone[c] = tu_range(&r, 0.5f, 1.5f);
        }
        L.kd = tu_range(&r, 0, 1);
        L.ks = tu_range(&r, 0, 1);
        L.shininess = shin[k % 12];
        L.kf = k % 4 == 3 ? tu_range(&r, 0, 1) : k % 4 == 2 ? -0.0f : 0.0f;
        if (k % 8 == 7) L.lights[0].color[k / 8 % 3] = -0.0f;   /* -0: still >= 0 */
        if (k % 16 == 5) L.ambient[1] = -0.25f;                 /* a negative: the clamp */
        if (k % 8 == 0) {   /* the sample scene's two lights, as its scene file gives them */
            static const float dir[2][3] = { { -0.7884f, 0.5781f, 0.2102f },
                                             { 0.3271f, 0.9345f, 0.1402f } };
            static const float col[2][3] = { { 0.620f, 0.700f, 0.820f },
                                             { 0.450f, 0.380f, 0.280f } };
            for (i = 0; i < 2; i++)
                for (c = 0; c < 3; c++) {
                    L.lights[i].dir[c] = dir[i][c];
                    L.lights[i].color[c] = col[i][c];
                }
            L.ambient[0] = 0.28f;
            L.ambient[1] = 0.30f;
            L.ambient[2] = 0.32f;
            L.kd = 0.8f;
            L.ks = 0.12f;
            L.shininess = 20.0f;
            L.kf = 0.0f;
            L.tone[0] = 1.0f;
            L.tone[1] = 0.98f;
            L.tone[2] = 0.96f;
        }
        scene_random(&s, &r);
        assert_int_equal(fuse_context_light(ref, &L, &K, &s.Pi, s.mask, s.w, s.nrm, 3 * s.w, &s.Oi),
                         FUSE_OK);
        memcpy(want, s.out, (size_t)77 * 41 * 4);
        for (j = 0; j < 4; j++) {
            if (ctx[j] == NULL) continue;
            memset(s.out, 0xA5, (size_t)77 * 41 * 4);
            assert_int_equal(fuse_context_light(ctx[j], &L, &K, &s.Pi, s.mask, s.w, s.nrm,
                                                3 * s.w, &s.Oi), FUSE_OK);
            tested++;
            if (memcmp(want, s.out, (size_t)77 * 41 * 4) != 0) {
                printf("case %d (lights %d, s %g, kf %g) %s: bytes differ from the reference\n",
                       k, L.light_count, L.shininess, L.kf, ef_isa_name(isas[j]));
                bad++;
            }
        }
    }
    printf("NOTE lighting shortcuts: %d case-ISA pairs against the reference, %d differ\n",
           tested, bad);
    for (j = 0; j < 4; j++) fuse_context_destroy(ctx[j]);
    fuse_context_destroy(ref);
    scene_free(&s);
    free(want);
    assert_int_equal(bad, 0);
}

/* ---- hand-worked single pixels --------------------------------------- */

typedef struct px1 {
    uint8_t P[4], out[4], mask;
    float n[3];
    fuse_image Pi, Oi;
} px1;

/* A 1x1 image whose pixel centre lies on the optical axis: V = (0,0,1). */
static fuse_result light1(const fuse_lighting *L, px1 *p)
{
    fuse_intrinsics K = { 500.0f, 500.0f, 0.5f, 0.5f };
    p->Pi = (fuse_image){ p->P, 1, 1, 4 };
    p->Oi = (fuse_image){ p->out, 1, 1, 4 };
    return fuse_light(L, &K, &p->Pi, &p->mask, 1, p->n, 3, &p->Oi);
}

static fuse_lighting one_light(float x, float y, float z, float c)
{
    fuse_lighting L = fuse_lighting_default();
    L.light_count = 1;
    L.lights[0] = (fuse_light_src){ { x, y, z }, { c, c, c } };
    L.ambient[0] = L.ambient[1] = L.ambient[2] = 0.2f;
    L.kd = 0.6f;
    L.ks = 0.4f;
    L.shininess = 16.0f;
    L.kf = 0.6f;
    L.tone[0] = L.tone[1] = L.tone[2] = 1.0f;
    return L;
}

/* No light, ambient 1: P' = P times the tone. */
static fuse_lighting ambient_only(void)
{
    fuse_lighting L = one_light(0, 0, 1, 0);
    L.light_count = 0;
    L.ambient[0] = L.ambient[1] = L.ambient[2] = 1.0f;
    return L;
}

/* light1 of p is FUSE_OK and writes (r, g, b, a). */
static void expect_out(const fuse_lighting *L, px1 *p, int r, int g, int b, int a)
{
    assert_int_equal(light1(L, p), FUSE_OK);
    assert_int_equal(p->out[0], r);
    assert_int_equal(p->out[1], g);
    assert_int_equal(p->out[2], b);
    assert_int_equal(p->out[3], a);
}

static void test_facing_viewer(void **state)
{
    /* N = V = L: N.L = N.H = 1, F = 0: C = a + c (kd + ks) = 0.2 + 0.5. */
    fuse_lighting L = one_light(0, 0, 1, 0.5f);
    px1 p = { { 100, 50, 200, 7 }, { 0 }, 255, { 0, 0, 1 }, { 0 }, { 0 } };
    (void)state;
    expect_out(&L, &p, 70, 35, 140, 255);
    /* Half coverage: everything scales by 128/255, F = 0 still. */
    p.mask = 128;
    p.n[2] = 3.0f;                       /* length does not matter */
    expect_out(&L, &p, 35, 18, 70, 128); /* 70 * 128/255 = 35.14, 17.57, 70.27 */
}

static void test_grazing(void **state)
{
    /* N perpendicular to V: F = 1, alpha = M (1 - kf). No light, ambient 1:
     * P' = P, rgb = M' P. */
    fuse_lighting L = ambient_only();
    px1 p = { { 100, 20, 255, 0 }, { 0 }, 255, { 1, 0, 0 }, { 0 }, { 0 } };
    (void)state;
    L.kf = 0.6f;
    expect_out(&L, &p, 40, 8, 102, 102); /* alpha 255 * 0.4 */
    /* kf = 1: a grazing pixel vanishes entirely. */
    L.kf = 1.0f;
    expect_out(&L, &p, 0, 0, 0, 0);
    /* A back-facing normal: 1 - N.V = 2 is clamped to 1, F = 1, as at a
     * grazing edge (the squared term without that clamp gave F = 4). */
    L.kf = 0.6f;
    p.n[0] = 0; p.n[2] = -1;
    assert_int_equal(light1(&L, &p), FUSE_OK);
    assert_int_equal(p.out[3], 102);
    /* A zero, NaN or infinite normal is replaced by V: F = 0. */
    p.n[2] = 0;
    assert_int_equal(light1(&L, &p), FUSE_OK);
    assert_int_equal(p.out[3], 255);
    assert_int_equal(p.out[0], 100);
    p.n[0] = NAN;
    assert_int_equal(light1(&L, &p), FUSE_OK);
    assert_int_equal(p.out[3], 255);
    p.n[0] = INFINITY;
    assert_int_equal(light1(&L, &p), FUSE_OK);
    assert_int_equal(p.out[3], 255);
}

static void test_mask_zero(void **state)
{
    /* M == 0 gives (0,0,0,0) even with bright ambient and NaN normals, and
     * the pixel is written. */
    fuse_lighting L = one_light(0, 0, 1, 1);
    px1 p = { { 255, 255, 255, 255 }, { 9, 9, 9, 9 }, 0, { NAN, 0, 1 }, { 0 }, { 0 } };
    (void)state;
    L.ambient[0] = 5.0f;
    expect_out(&L, &p, 0, 0, 0, 0);
}

static void test_tone_and_clamp(void **state)
{
    /* Only ambient 1: P' = P * tone. */
    fuse_lighting L = ambient_only();
    px1 p = { { 200, 200, 200, 0 }, { 0 }, 255, { 0, 0, 1 }, { 0 }, { 0 } };
    (void)state;
    L.tone[0] = 0.5f; L.tone[1] = 1.0f; L.tone[2] = 0.25f;
    expect_out(&L, &p, 100, 200, 50, 255);
    /* Above 1 clamps: P' = 1, so rgb = alpha. */
    L.tone[0] = 2.0f; L.tone[1] = 1.3f; L.tone[2] = 100.0f;
    p.mask = 200;
    expect_out(&L, &p, 200, 200, 200, 200);
    /* Negative light clamps at 0. */
    L.ambient[0] = L.ambient[1] = L.ambient[2] = -1.0f;
    expect_out(&L, &p, 0, 0, 0, 200);
}

static void test_view_vector(void **state)
{
    /* Off-axis pixel (x, y) = (3, 1) of a 4x2 image, cx = 0.5, cy = 1.5,
     * fx = fy = 1: V = -normalize((3, 1, -1))... (x+.5-cx)/fx = 3,
     * -(y+.5-cy)/fy = -0 -> V = (-3, 0, 1)/sqrt(10). N = (-3, 0, 1) gives
     * F = 0 and a light along V a full diffuse and specular term. */
    fuse_lighting L = one_light(-3, 0, 1, 0.5f);
    fuse_intrinsics K = { 1.0f, 1.0f, 0.5f, 1.5f };
    uint8_t P[32], out[32], mask[8];
    float n[24];
    fuse_image Pi = { P, 4, 2, 16 }, Oi = { out, 4, 2, 16 };
    int i;
    (void)state;
    for (i = 0; i < 32; i++) P[i] = 100;
    for (i = 0; i < 8; i++) mask[i] = 255;
    for (i = 0; i < 8; i++) { n[3 * i] = -3; n[3 * i + 1] = 0; n[3 * i + 2] = 1; }
    assert_int_equal(fuse_light(&L, &K, &Pi, mask, 4, n, 12, &Oi), FUSE_OK);
    i = 4 * (1 * 4 + 3);
    assert_int_equal(out[i + 3], 255);       /* F = 0 */
    assert_int_equal(out[i], 70);            /* C = 0.2 + 0.5 (0.6 + 0.4) */
    /* Pixel (0, 1): V = (0, 0, 1) there; N.V = 1/sqrt(10), F =
     * (1 - 0.316228)^5 = 0.149470, M' = 1 - 0.6 F = 0.910318: 232.13. */
    i = 4 * (1 * 4 + 0);
    assert_int_equal(out[i + 3], 232);
}

/* ---- validation -------------------------------------------------------- */

static void test_bad_input(void **state)
{
    fuse_lighting L = fuse_lighting_default(), B;
    fuse_intrinsics K = { 100, 100, 4, 2 }, KB;
    uint8_t P[64], out[64], big[128], mask[16];
    float n[48];
    fuse_image Pi = { P, 4, 4, 16 }, Oi = { out, 4, 4, 16 }, X;
    int i;
    (void)state;
    memset(P, 100, sizeof P);
    memset(mask, 255, sizeof mask);
    for (i = 0; i < 48; i++) n[i] = i % 3 == 2 ? 1.0f : 0.0f;
    memset(out, 0xEE, sizeof out);
#define BAD(code, call) do { \
        assert_int_equal((call), (code)); \
        for (i = 0; i < 64; i++) assert_int_equal(out[i], 0xEE); \
    } while (0)
    BAD(FUSE_ERR_ARGS, fuse_light(NULL, &K, &Pi, mask, 4, n, 12, &Oi));
    BAD(FUSE_ERR_ARGS, fuse_light(&L, NULL, &Pi, mask, 4, n, 12, &Oi));
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, NULL, mask, 4, n, 12, &Oi));
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &Pi, NULL, 4, n, 12, &Oi));
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &Pi, mask, 4, NULL, 12, &Oi));
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &Pi, mask, 4, n, 12, NULL));
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &Pi, mask, 3, n, 12, &Oi));   /* mask stride */
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &Pi, mask, 4, n, 11, &Oi));   /* normal stride */
    X = Pi; X.stride = 15;
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &X, mask, 4, n, 12, &Oi));
    X = Pi; X.pixels = NULL;
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &X, mask, 4, n, 12, &Oi));
    X = Pi; X.width = 0;
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &X, mask, 4, n, 12, &Oi));
    X = Oi; X.stride = 12;
    BAD(FUSE_ERR_ARGS, fuse_light(&L, &K, &Pi, mask, 4, n, 12, &X));
    X = Oi; X.height = 3;                                             /* size */
    BAD(FUSE_ERR_SIZE, fuse_light(&L, &K, &Pi, mask, 4, n, 12, &X));
    X = Oi; X.width = 3;
    BAD(FUSE_ERR_SIZE, fuse_light(&L, &K, &Pi, mask, 4, n, 12, &X));
    /* out overlapping P other than exactly. */
    memcpy(big, P, sizeof P);
    {
        fuse_image Pb = { big, 4, 4, 16 }, Ob = { big + 4, 4, 4, 16 };
        uint8_t keep[128];
        memcpy(keep, big, sizeof keep);
        assert_int_equal(fuse_light(&L, &K, &Pb, mask, 4, n, 12, &Ob), FUSE_ERR_ARGS);
        assert_memory_equal(keep, big, sizeof keep);
    }
    /* Parameters: L or K with one field changed (BAD_L, BAD_K). */
#define BAD_L(change) do { B = L; change; \
        BAD(FUSE_ERR_ARGS, fuse_light(&B, &K, &Pi, mask, 4, n, 12, &Oi)); } while (0)
#define BAD_K(change) do { KB = K; change; \
        BAD(FUSE_ERR_ARGS, fuse_light(&L, &KB, &Pi, mask, 4, n, 12, &Oi)); } while (0)
    BAD_L(B.light_count = -1);
    BAD_L(B.light_count = FUSE_MAX_LIGHTS + 1);
    BAD_L(B.shininess = 0.99f);
    BAD_L(B.shininess = NAN);
    BAD_L(B.kd = INFINITY);
    BAD_L(B.ks = NAN);
    BAD_L(B.kf = -INFINITY);
    BAD_L(B.ambient[1] = NAN);
    BAD_L(B.tone[2] = 2e6f);
    BAD_L(B.lights[0].color[0] = NAN);
    BAD_L(B.lights[0].dir[0] = B.lights[0].dir[1] = B.lights[0].dir[2] = 0);
    BAD_L(B.lights[0].dir[1] = INFINITY);
    /* An unused light slot is not looked at. */
    B = L; B.lights[3].dir[0] = NAN;
    assert_int_equal(fuse_light(&B, &K, &Pi, mask, 4, n, 12, &Oi), FUSE_OK);
    memset(out, 0xEE, sizeof out);
    BAD_K(KB.fx = 0);
    BAD_K(KB.fy = NAN);
    BAD_K(KB.cx = INFINITY);
    BAD_K(KB.cy = NAN);
#undef BAD_K
#undef BAD_L
#undef BAD
    assert_string_not_equal(fuse_result_str(FUSE_ERR_ARGS), fuse_result_str(FUSE_ERR_SIZE));
    assert_non_null(fuse_result_str((fuse_result)99));
}

/* In place (out == P) gives the same bytes as out of place. */
static void test_in_place(void **state)
{
    tu_rng r = { 0x5EED0003u };
    fuse_lighting L = random_lighting(&r, 3);
    fuse_intrinsics K = intrinsics_for(48, 30);
    scene s;
    (void)state;
    scene_alloc(&s, 48, 30);
    scene_random(&s, &r);
    assert_int_equal(fuse_light(&L, &K, &s.Pi, s.mask, s.w, s.nrm, 3 * s.w, &s.Oi), FUSE_OK);
    assert_int_equal(fuse_light(&L, &K, &s.Pi, s.mask, s.w, s.nrm, 3 * s.w, &s.Pi), FUSE_OK);
    assert_memory_equal(s.P, s.out, (size_t)s.w * s.h * 4);
    scene_free(&s);
}

/* A view of rows (the eq. 1 crop) with strides wider than the image. */
static void test_strided_views(void **state)
{
    tu_rng r = { 0x5EED0004u };
    fuse_lighting L = random_lighting(&r, 2);
    fuse_intrinsics K = intrinsics_for(20, 10);
    scene s;
    uint8_t big[24 * 4 * 16], mbig[30 * 10], obig[22 * 4 * 10];
    float nbig[70 * 10];
    fuse_image B = { big, 20, 16, 24 * 4 }, V, O = { obig, 20, 10, 22 * 4 };
    int x, y, c;
    (void)state;
    scene_alloc(&s, 20, 10);
    scene_random(&s, &r);
    assert_int_equal(fuse_light(&L, &K, &s.Pi, s.mask, s.w, s.nrm, 3 * s.w, &s.Oi), FUSE_OK);
    memset(big, 7, sizeof big);
    for (y = 0; y < 10; y++)
        for (x = 0; x < 20; x++) {
            for (c = 0; c < 4; c++) big[(y + 3) * 96 + 4 * x + c] = s.P[4 * (y * 20 + x) + c];
            mbig[y * 30 + x] = s.mask[y * 20 + x];
            for (c = 0; c < 3; c++) nbig[y * 70 + 3 * x + c] = s.nrm[3 * (y * 20 + x) + c];
        }
    V = fuse_image_rows(&B, 3, 10);
    assert_ptr_equal(V.pixels, big + 3 * 96);
    assert_int_equal(V.height, 10);
    assert_int_equal(fuse_light(&L, &K, &V, mbig, 30, nbig, 70, &O), FUSE_OK);
    for (y = 0; y < 10; y++)
        assert_memory_equal(obig + y * 88, s.out + y * 80, 80);
    /* Views outside the image are empty and rejected. */
    V = fuse_image_rows(&B, 7, 10);
    assert_null(V.pixels);
    assert_int_equal(fuse_light(&L, &K, &V, mbig, 30, nbig, 70, &O), FUSE_ERR_ARGS);
    assert_null(fuse_image_rows(&B, -1, 2).pixels);
    assert_null(fuse_image_rows(&B, 0, 0).pixels);
    assert_null(fuse_image_rows(NULL, 0, 1).pixels);
    assert_int_equal(fuse_image_rows(&B, 0, 16).height, 16);
    scene_free(&s);
}

/* ---- checksum ----------------------------------------------------------- */

static void test_crc(void **state)
{
    tu_rng r = { 0x5EED0005u };
    uint32_t crc = 0;
    int k;
    (void)state;
    for (k = 0; k < 40; k++) {
        int w = 1 + tu_int(&r, 64), h = 1 + tu_int(&r, 40);
        fuse_lighting L = random_lighting(&r, tu_int(&r, FUSE_MAX_LIGHTS + 1));
        fuse_intrinsics K = intrinsics_for(w, h);
        scene s;
        scene_alloc(&s, w, h);
        scene_random(&s, &r);
        assert_int_equal(fuse_light(&L, &K, &s.Pi, s.mask, w, s.nrm, 3 * w, &s.Oi), FUSE_OK);
        crc = tu_crc32(crc, s.out, (size_t)w * h * 4);
        scene_free(&s);
    }
    printf("NOTE fuse_light CRC32 0x%08X (expected 0x%08X)\n", crc, LIGHT_CRC);
    assert_int_equal(crc, LIGHT_CRC);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_light_vs_double),
        cmocka_unit_test(test_pow01),
        cmocka_unit_test(test_spec01),
        cmocka_unit_test(test_light_vs_double_spec),
        cmocka_unit_test(test_light_shortcuts_isa),
        cmocka_unit_test(test_facing_viewer),
        cmocka_unit_test(test_grazing),
        cmocka_unit_test(test_mask_zero),
        cmocka_unit_test(test_tone_and_clamp),
        cmocka_unit_test(test_view_vector),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_in_place),
        cmocka_unit_test(test_strided_views),
        cmocka_unit_test(test_crc))
