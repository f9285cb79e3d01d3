/* test_kin_skin_isa.c - the SIMD skinning kernels (kin_skin_sse2.c,
 * _avx2.c, _avx512.c, _neon.c: the last under qemu-aarch64, .ci/run part
 * arm64) against the scalar reference: over seeded random
 * meshes (vertex counts that are and are not multiples of the vector
 * widths, 1..4 influences, zero weights, weights summing to zero, negative
 * and unnormalised weights, joints with scale, shear and mirroring, a
 * singular joint, a NaN joint read only with weight 0, antipodal dual
 * quaternions, with and without normals) every ISA's LBS and DQS output
 * is memcmp-equal to the reference, and the reference's CRC32 over all
 * cases is the recorded one (so a change of the reference is seen too).
 * An ISA this CPU does not run is reported as SKIP, never as a pass. */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/kin/kin.h"
#include "support/isa_tests.h"
#include "support/kin_testmesh.h"
#include "../src/cpu/ef_mem.h"

/* CRC32 of the reference's positions and normals (LBS then DQS) over all
 * NCASES cases; update it (and docs/kin.md) when the reference changes. */
#define SKIN_CRC 0x737C03D6u /* issue 20: inputs drawn in a defined order (before: 0x09D4160A, gcc only) */
#define NCASES 60

static void make_case(int n, tu_skin_case *k)
{
    tu_rng r = { 0x736b696e0000ull + (uint64_t)n };
    static const int counts[] = { 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 32, 33, 63, 100, 257, 1000 };
    int nv = counts[n % (int)(sizeof counts / sizeof counts[0])];
    if (n >= 34) nv = 1 + tu_int(&r, 3000);
    /* joint counts below 32, below 64 and above (the AVX-512 table paths
     * and its per-vertex fallback) */
    const int nj = n % 3 == 0 ? 24 : n % 3 == 1 ? 48 : TU_SKIN_JOINTS;
    tu_skin_case_begin(k, &r, nv, nj);
    for (int v = 0; v < nv; v++) {
        for (int c = 0; c < 3; c++) k->pos[3 * v + c] = tu_range(&r, -1, 1);
        kin_vec3 nn = kin_v3_norm(tu_v3(&r, -1, 1));
        memcpy(k->nrm + 3 * v, &nn, sizeof nn);
        int kind = tu_int(&r, 10), ninf = 1 + tu_int(&r, 4);
        float s = 0;
        for (int i = 0; i < 4; i++) {
            /* mostly nearby joints (blocks that stay below 32 or 64) */
            int base = (v / 37) % (nj - 1);
            k->jt[4 * v + i] = (uint16_t)(tu_int(&r, 4) ? (base + tu_int(&r, 6)) % (nj - 1)
                                                        : tu_int(&r, nj - 1));
            float x = i < ninf ? tu_unit(&r) : 0.0f;
            if (kind == 0 && i > 0) x = 0.0f;                 /* one influence */
            if (kind == 1 && tu_int(&r, 2)) x = 0.0f;         /* zeros inside */
            k->w[4 * v + i] = x;
            s += x;
        }
        if (kind != 2 && s > 0)
            for (int i = 0; i < 4; i++) k->w[4 * v + i] /= s;  /* kind 2: unnormalised */
        tu_skin_weight_kind(k, v, kind);
    }
    tu_skin_case_end(k, nv, n % 7 != 6);
}

/* Runs one skinning (dqs = 0 LBS, 1 DQS) on isa into fresh buffers. */
static void run(const tu_skin_case *k, int dqs, int isa, float *po, float *no)
{
    size_t n = (size_t)k->mesh.vertex_count * 3 * sizeof(float);
    memset(po, 0xA5, n);
    memset(no, 0xA5, n);
    if (dqs) kin_skin_dqs_isa(&k->mesh, k->dq, po, no, isa);
    else kin_skin_lbs_isa(&k->mesh, k->jm, po, no, isa);
}

/* Case c with the reference's outputs (rp, rn) and another path's (sp,
 * sn): 3 floats per vertex each. */
typedef struct skin_run {
    tu_skin_case k;
    int n3;
    float *rp, *rn, *sp, *sn;
} skin_run;

static void skin_run_make(skin_run *s, int c)
{
    make_case(c, &s->k);
    s->n3 = s->k.mesh.vertex_count * 3;
    const size_t n = (size_t)s->n3 * 4;
    s->rp = malloc(n);
    s->rn = malloc(n);
    s->sp = malloc(n);
    s->sn = malloc(n);
    assert_true(s->rp && s->rn && s->sp && s->sn);
}

static void skin_run_free(skin_run *s)
{
    EF_FREE_ALL(s->rp, s->rn, s->sp, s->sn);
    tu_skin_case_free(&s->k);
}

static void isa_equal(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP kin skin isa %s: this CPU does not run it; untested: LBS and DQS "
                      "skinning of src/kin/kin_skin_%s.c\n", ef_isa_name((ef_isa)isa), ef_isa_name((ef_isa)isa));
        skip();
    }
    uint32_t crc = 0;
    long verts = 0, kept = 0;
    for (int c = 0; c < NCASES; c++) {
        skin_run s;
        skin_run_make(&s, c);
        const int n3 = s.n3;
        for (int dqs = 0; dqs < 2; dqs++) {
            run(&s.k, dqs, EF_ISA_REF, s.rp, s.rn);
            crc = tu_crc32(crc, s.rp, (size_t)n3 * 4);
            if (s.k.mesh.normals) crc = tu_crc32(crc, s.rn, (size_t)n3 * 4);
            for (int i = 0; i < n3; i++) kept += s.rp[i] == s.k.pos[i];
            run(&s.k, dqs, isa, s.sp, s.sn);
            tu_skin_first_diff(s.rp, s.sp, n3, dqs ? "DQS position" : "LBS position", c,
                               ef_isa_name((ef_isa)isa));
            tu_skin_first_diff(s.rn, s.sn, n3, dqs ? "DQS normal" : "LBS normal", c,
                               ef_isa_name((ef_isa)isa));
            verts += s.k.mesh.vertex_count;
        }
        skin_run_free(&s);
    }
    print_message("NOTE kin skin %s: %d cases, %ld vertex skins equal to the reference, "
                  "CRC32 0x%08X (recorded 0x%08X)\n", ef_isa_name((ef_isa)isa), NCASES,
                  verts, crc, SKIN_CRC);
    /* the bind-pose branch (zero weight sum) really ran */
    assert_true(kept > 300);
    assert_int_equal(crc, SKIN_CRC);
}

TU_ISA_TESTS(test_, isa_equal)

/* kin_skin_lbs / kin_skin_dqs (the dispatching entry points) give the
 * reference's bytes, and kin_skin_isa() names a path the CPU runs. */
static void test_dispatch_equal(void **state)
{
    (void)state;
    int isa = kin_skin_isa();
    assert_true(isa >= EF_ISA_REF && isa < EF_ISA_COUNT);
    assert_true(ef_cpu_has((ef_isa)isa));
    for (int c = 0; c < 20; c++) {
        skin_run s;
        skin_run_make(&s, c);
        const int n3 = s.n3;
        for (int dqs = 0; dqs < 2; dqs++) {
            run(&s.k, dqs, EF_ISA_REF, s.rp, s.rn);
            memset(s.sp, 0, (size_t)n3 * 4);
            memset(s.sn, 0xA5, (size_t)n3 * 4);
            if (dqs) kin_skin_dqs(&s.k.mesh, s.k.dq, s.sp, s.sn);
            else kin_skin_lbs(&s.k.mesh, s.k.jm, s.sp, s.sn);
            tu_skin_first_diff(s.rp, s.sp, n3, "position", c, "dispatch");
            tu_skin_first_diff(s.rn, s.sn, n3, "normal", c, "dispatch");
        }
        skin_run_free(&s);
    }
}

/* Without normals in the output nothing is written there, on every ISA. */
static void test_no_normal_output(void **state)
{
    (void)state;
    tu_skin_case k;
    make_case(16, &k);   /* 1000 vertices */
    int n3 = k.mesh.vertex_count * 3;
    float *po = malloc((size_t)n3 * 4), *ref = malloc((size_t)n3 * 4), *tmp = malloc((size_t)n3 * 4);
    run(&k, 0, EF_ISA_REF, ref, tmp);
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa)) continue;
        memset(po, 0, (size_t)n3 * 4);
        kin_skin_lbs_isa(&k.mesh, k.jm, po, NULL, isa);
        tu_skin_first_diff(ref, po, n3, "LBS position without normals", 16, ef_isa_name((ef_isa)isa));
    }
    free(po); free(ref); free(tmp);
    tu_skin_case_free(&k);
}

/* DQS with the weight sums at the ends of the float range (vertex v's
 * weights scaled by tu_skin_weight_scale(v): 2^-64, 2^64, 3e-20, 1e-30,
 * 2e19, 1e30, 1e-21, 1e-23 or 1, mixed within every vector): every ISA
 * gives the reference's bytes; the reference's result does not change by
 * a byte for a power-of-two factor (the blend and the rescaling are exact
 * there, and the formula does not depend on a positive scale of b) and
 * stays within 1e-5 of the unscaled result for the others (never the bind
 * pose, inf or NaN where the unscaled vertex moved). */
static void test_dqs_weight_scale(void **state)
{
    (void)state;
    long exact = 0, near = 0, isas = 0;
    for (int c = 0; c < NCASES; c += 3) {
        tu_skin_case k;
        make_case(c, &k);
        const int nv = k.mesh.vertex_count, n3 = nv * 3, do_n = k.mesh.normals != NULL;
        float *up = malloc((size_t)n3 * 4), *un = malloc((size_t)n3 * 4);
        float *rp = malloc((size_t)n3 * 4), *rn = malloc((size_t)n3 * 4);
        float *sp = malloc((size_t)n3 * 4), *sn = malloc((size_t)n3 * 4);
        run(&k, 1, EF_ISA_REF, up, un);
        float *w = tu_skin_scaled_weights(&k);
        tu_skin_case ks = k;
        ks.mesh.weights = w;
        run(&ks, 1, EF_ISA_REF, rp, rn);
        for (int v = 0; v < nv; v++) {
            const int pow2 = v % TU_SKIN_SCALES < 3;   /* 1, 2^-64, 2^64 */
            for (int i = 3 * v; i < 3 * v + 3; i++) {
                if (pow2) {
                    if (memcmp(&rp[i], &up[i], 4) || (do_n && memcmp(&rn[i], &un[i], 4)))
                        fail_msg("case %d vertex %d (weights x %g): %.9g %.9g, unscaled %.9g %.9g",
                                 c, v, (double)tu_skin_weight_scale(v), (double)rp[i],
                                 (double)rn[i], (double)up[i], (double)un[i]);
                    exact++;
                } else {
                    if (!(fabsf(rp[i] - up[i]) <= 1e-5f) || (do_n && !(fabsf(rn[i] - un[i]) <= 1e-5f)))
                        fail_msg("case %d vertex %d (weights x %g): %.9g %.9g, unscaled %.9g %.9g",
                                 c, v, (double)tu_skin_weight_scale(v), (double)rp[i],
                                 (double)rn[i], (double)up[i], (double)un[i]);
                    near++;
                }
            }
        }
        for (int isa = EF_ISA_SSE2; isa < EF_ISA_COUNT; isa++) {
            if (!ef_cpu_has((ef_isa)isa)) continue;
            run(&ks, 1, isa, sp, sn);
            tu_skin_first_diff(rp, sp, n3, "DQS position, scaled weights", c, ef_isa_name((ef_isa)isa));
            tu_skin_first_diff(rn, sn, n3, "DQS normal, scaled weights", c, ef_isa_name((ef_isa)isa));
            isas++;
        }
        free(w); free(up); free(un); free(rp); free(rn); free(sp); free(sn);
        tu_skin_case_free(&k);
    }
    print_message("NOTE kin dqs scaled weights: %ld coordinates byte-equal to the unscaled, "
                  "%ld within 1e-5, %ld ISA runs equal to the reference\n", exact, near, isas);
    assert_true(exact > 1000 && near > 1000);
}

TU_MAIN(NULL, NULL,
        TU_ISA_UNIT_TESTS(test_),
        cmocka_unit_test(test_dispatch_equal),
        cmocka_unit_test(test_no_normal_output),
        cmocka_unit_test(test_dqs_weight_scale))
