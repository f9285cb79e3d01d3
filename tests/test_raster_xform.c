/* test_raster_xform.c - the vertex transforms of raster.h
 * (rast_transform_points, rast_transform_dirs): the AVX2 and AVX-512
 * versions (raster_xform.inl: 8 or 16 vertices per step, the rest by the
 * reference) against the scalar
 * reference, byte for byte, and the public entry points against the
 * reference.
 *
 * Seeded cases: vertex counts 0..80 (every tail length, several whole
 * steps) and a few of 1000..3000; matrices of a camera (rotation,
 * translation, perspective), random ones over magnitudes 2^-30..2^30 with
 * exact zeros and signed zeros; vertices on and around the unit sphere,
 * tiny (down to subnormal results), huge (products overflowing to
 * infinity, inf - inf giving NaN), zero vectors (length 0: output 0),
 * infinities and NaN. Every NaN in play is the x86 default NaN
 * (0xFFC00000), so NaN results have one bit pattern whatever the operand
 * order and memcmp stays exact. The outputs are written into buffers with
 * a guard pattern after the last vertex (must stay untouched). A CRC of
 * the reference output over all cases is checked against a recorded
 * constant. The AVX-512 test prints SKIP and is skipped on a CPU
 * without AVX-512.
 */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "support/isa_tests.h"
#include "support/x86_only.h"

#if EF_TEST_X86

#define NCASES 3000
#define MAXN 3000
#define GUARD 16
#define XFORM_CRC 0x002EBE01u   /* recorded: reference output of all cases
                                  * (issue 20: drawn in a defined order; 0x52552AD5 before) */

static float default_nan(void)
{
    const uint32_t b = 0xFFC00000u;
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

/* A value of magnitude 2^-30..2^30, random sign, sometimes 0 or -0. */
static float wide(tu_rng *r)
{
    const int k = tu_int(r, 20);
    if (k == 0)
        return 0.0f;
    if (k == 1)
        return -0.0f;
    const float m = tu_range(r, 0.5f, 1.0f);   /* drawn in order */
    const float v = ldexpf(m, tu_int(r, 61) - 30);
    return tu_int(r, 2) ? v : -v;
}

static void make_matrix(tu_rng *r, float m[16])
{
    const int kind = tu_int(r, 3);
    if (kind == 0) {
        /* A view-projection: rotation about a random axis, translation,
         * perspective (as the pipe's cameras). */
        const float a = tu_range(r, -3.2f, 3.2f), c = cosf(a), s = sinf(a);
        float ax[3];
        for (int k = 0; k < 3; k++) ax[k] = tu_range(r, -1, 1);   /* in order */
        const float l = sqrtf(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]) + 1e-3f;
        for (int k = 0; k < 3; k++)
            ax[k] /= l;
        float R[9];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                R[3 * i + j] = (i == j ? c : 0.0f) + (1.0f - c) * ax[i] * ax[j] +
                               s * (i == (j + 1) % 3 ? ax[(j + 2) % 3]
                                    : j == (i + 1) % 3 ? -ax[(i + 2) % 3] : 0.0f);
        const float f = tu_range(r, 0.5f, 3.0f), n = 0.01f, fa = 100.0f;
        const float P[4] = { f * tu_range(r, 0.6f, 1.0f), f, (fa + n) / (n - fa),
                             2 * fa * n / (n - fa) };
        memset(m, 0, 16 * sizeof(float));
        for (int col = 0; col < 3; col++) {
            m[4 * col + 0] = P[0] * R[3 * 0 + col];
            m[4 * col + 1] = P[1] * R[3 * 1 + col];
            m[4 * col + 2] = P[2] * R[3 * 2 + col];
            m[4 * col + 3] = -R[3 * 2 + col];
        }
        float t[3];
        t[0] = tu_range(r, -2, 2);   /* drawn in order */
        t[1] = tu_range(r, -2, 2);
        t[2] = tu_range(r, -3, 0);
        m[12] = P[0] * t[0];
        m[13] = P[1] * t[1];
        m[14] = P[2] * t[2] + P[3];
        m[15] = -t[2];
    } else if (kind == 1) {
        for (int i = 0; i < 16; i++)
            m[i] = wide(r);
    } else {
        for (int i = 0; i < 16; i++)
            m[i] = tu_range(r, -2, 2);
    }
}

static float coord(tu_rng *r, int special)
{
    if (special) {
        switch (tu_int(r, 8)) {
        case 0: return INFINITY;
        case 1: return -INFINITY;
        case 2: return default_nan();
        case 3: return 0.0f;
        case 4: return -0.0f;
        case 5: return ldexpf(tu_range(r, -1, 1), 120);    /* overflows */
        case 6: return ldexpf(tu_range(r, -1, 1), -140);   /* subnormal */
        default: return wide(r);
        }
    }
    return tu_range(r, -1.5f, 1.5f);
}

static void make_vectors(tu_rng *r, float *v, int n)
{
    const int mode = tu_int(r, 4);
    for (int i = 0; i < n; i++) {
        const int special = mode == 3 ? tu_int(r, 3) == 0 : tu_int(r, 40) == 0;
        float *p = v + 3 * i;
        if (mode == 0) {            /* unit vectors, as skinned normals */
            float x = tu_range(r, -1, 1), y = tu_range(r, -1, 1), z = tu_range(r, -1, 1);
            const float l = sqrtf(x * x + y * y + z * z) + 1e-6f;
            p[0] = x / l;
            p[1] = y / l;
            p[2] = z / l;
        } else {
            for (int k = 0; k < 3; k++)
                p[k] = coord(r, special);
        }
        if (tu_int(r, 50) == 0)
            p[0] = p[1] = p[2] = 0.0f;   /* zero vector */
    }
}

static int case_count(tu_rng *r, int c)
{
    if (c % 100 == 99)
        return 1000 + tu_int(r, 2001);
    return c % 81;     /* 0..80: every tail length */
}

typedef void (*xform_fn)(const float *, const float *, int, float *);

/* Runs fn into a guarded buffer (comps floats per vertex) and checks the
 * bytes against ref (already computed, same layout) and the guard. */
static void check(xform_fn fn, const float *m, const float *in, int n, int comps,
                  const float *ref, float *buf, const char *what, int c)
{
    const size_t nf = (size_t)n * (size_t)comps;
    memset(buf, 0xA5, (nf + GUARD) * sizeof(float));
    fn(m, in, n, buf);
    if (memcmp(buf, ref, nf * sizeof(float)) != 0) {
        size_t i = 0;
        while (memcmp(&buf[i], &ref[i], sizeof(float)) == 0)
            i++;
        fail_msg("%s, case %d (n %d): float %zu (vertex %zu) is %.9g, reference %.9g", what,
                 c, n, i, i / (size_t)comps, (double)buf[i], (double)ref[i]);
    }
    for (size_t i = nf; i < nf + GUARD; i++) {
        uint32_t b;
        memcpy(&b, &buf[i], sizeof b);
        if (b != 0xA5A5A5A5u)
            fail_msg("%s, case %d (n %d): wrote past the last vertex (float %zu)", what, c, n, i);
    }
}

/* All cases; with pts and drs set, those versions (AVX2, AVX-512) are
 * checked too. Returns the CRC of the reference outputs. */
static uint32_t run_cases(xform_fn pts, xform_fn drs, const char *isa)
{
    tu_rng r = { 0x7F0A11CEull };
    float *in = malloc(3 * (size_t)MAXN * sizeof(float));
    float *ref = malloc((4 * (size_t)MAXN + GUARD) * sizeof(float));
    float *buf = malloc((4 * (size_t)MAXN + GUARD) * sizeof(float));
    assert_non_null(in);
    assert_non_null(ref);
    assert_non_null(buf);
    uint32_t crc = 0;
    for (int c = 0; c < NCASES; c++) {
        float m[16];
        make_matrix(&r, m);
        const int n = case_count(&r, c);
        make_vectors(&r, in, n);
        rast__transform_points_ref(m, in, n, ref);
        crc = tu_crc32(crc, ref, 4 * (size_t)n * sizeof(float));
        check(rast_transform_points, m, in, n, 4, ref, buf, "rast_transform_points", c);
        if (pts)
            check(pts, m, in, n, 4, ref, buf, isa, c);
        rast__transform_dirs_ref(m, in, n, ref);
        crc = tu_crc32(crc, ref, 3 * (size_t)n * sizeof(float));
        check(rast_transform_dirs, m, in, n, 3, ref, buf, "rast_transform_dirs", c);
        if (drs)
            check(drs, m, in, n, 3, ref, buf, isa, c);
    }
    free(in);
    free(ref);
    free(buf);
    return crc;
}

/* The public entry points (whatever ISA they pick) equal the reference,
 * and the reference output is the recorded one. */
static void test_xform_public(void **state)
{
    (void)state;
    const uint32_t crc = run_cases(NULL, NULL, NULL);
    if (crc != XFORM_CRC)
        fail_msg("reference CRC 0x%08X, recorded 0x%08X", crc, XFORM_CRC);
}

static void test_xform_avx512(void **state)
{
    (void)state;
    tu_skip_unless_isa(EF_ISA_AVX512, "the AVX-512 vertex transforms (src/raster/raster_avx512.c)");
    run_cases(rast__transform_points_avx512, rast__transform_dirs_avx512,
              "rast__transform_*_avx512");
}

static void test_xform_avx2(void **state)
{
    (void)state;
    tu_skip_unless_isa(EF_ISA_AVX2, "the AVX2 vertex transforms (src/raster/raster_xform.inl)");
    run_cases(rast__transform_points_avx2, rast__transform_dirs_avx2, "rast__transform_*_avx2");
}

/* Directions: unit length within float rounding, and a zero vector stays
 * zero (the documented contract, on the dispatching entry point). */
static void test_dirs_contract(void **state)
{
    (void)state;
    tu_rng r = { 99 };
    enum { N = 37 };
    float v[3 * N], out[3 * N], m[16];
    for (int i = 0; i < 16; i++)
        m[i] = 0.0f;
    const float a = 0.7f;   /* rotation about z, scale 2 */
    m[0] = 2 * cosf(a);
    m[1] = 2 * sinf(a);
    m[4] = -2 * sinf(a);
    m[5] = 2 * cosf(a);
    m[10] = 2.0f;
    m[15] = 1.0f;
    for (int i = 0; i < N; i++)
        for (int k = 0; k < 3; k++)
            v[3 * i + k] = i == 5 ? 0.0f : tu_range(&r, -3, 3);
    rast_transform_dirs(m, v, N, out);
    for (int i = 0; i < N; i++) {
        const double l = sqrt((double)out[3 * i] * out[3 * i] +
                              (double)out[3 * i + 1] * out[3 * i + 1] +
                              (double)out[3 * i + 2] * out[3 * i + 2]);
        if (i == 5)
            NEAR(l, 0.0, 0.0);
        else
            NEAR(l, 1.0, 3e-7);
    }
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_xform_public),
        cmocka_unit_test(test_xform_avx512),
        cmocka_unit_test(test_xform_avx2),
        cmocka_unit_test(test_dirs_contract))

#else
EF_TEST_X86_SKIP("the AVX-512 vertex transforms")
#endif
