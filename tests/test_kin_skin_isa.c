/* test_kin_skin_isa.c - the SIMD skinning kernels (kin_skin_sse2.c,
 * _avx2.c, _avx512.c) against the scalar reference: over seeded random
 * meshes (vertex counts that are and are not multiples of the vector
 * widths, 1..4 influences, zero weights, weights summing to zero, negative
 * and unnormalised weights, joints with scale, shear and mirroring, a
 * singular joint, a NaN joint read only with weight 0, antipodal dual
 * quaternions, with and without normals) every ISA's LBS and DQS output
 * is memcmp-equal to the reference, and the reference's CRC32 over all
 * cases is the recorded one (so a change of the reference is seen too).
 * An ISA this CPU does not run is reported as SKIP, never as a pass. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/kin/kin.h"

/* CRC32 of the reference's positions and normals (LBS then DQS) over all
 * NCASES cases; update it (and docs/kin.md) when the reference changes. */
#define SKIN_CRC 0x09D4160Au
#define NCASES 60
#define NJOINTS 80   /* capacity; a case uses 24, 48 or 80 */

typedef struct skcase {
    kin_mesh mesh;
    float *pos, *nrm, *w;
    uint16_t *jt;
    kin_mat4 jm[NJOINTS];
    kin_dualquat dq[NJOINTS];
    int nj;
} skcase;

static kin_quat rand_quat(tu_rng *r)
{
    kin_quat q = { tu_range(r, -1, 1), tu_range(r, -1, 1), tu_range(r, -1, 1),
                   tu_range(r, -1, 1) };
    return kin_quat_normalize(q);
}

static void make_case(int n, skcase *k)
{
    tu_rng r = { 0x736b696e0000ull + (uint64_t)n };
    static const int counts[] = { 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 32, 33, 63, 100, 257, 1000 };
    int nv = counts[n % (int)(sizeof counts / sizeof counts[0])];
    if (n >= 34) nv = 1 + tu_int(&r, 3000);
    k->pos = malloc((size_t)nv * 3 * sizeof(float));
    k->nrm = malloc((size_t)nv * 3 * sizeof(float));
    k->w = malloc((size_t)nv * 4 * sizeof(float));
    k->jt = malloc((size_t)nv * 4 * sizeof(uint16_t));
    /* joint counts below 32, below 64 and above (the AVX-512 table paths
     * and its per-vertex fallback) */
    const int nj = k->nj = n % 3 == 0 ? 24 : n % 3 == 1 ? 48 : NJOINTS;
    for (int j = 0; j < nj; j++) {
        kin_vec3 t = kin_v3(tu_range(&r, -2, 2), tu_range(&r, -2, 2), tu_range(&r, -2, 2));
        k->jm[j] = kin_mat4_from_tr(t, rand_quat(&r));
        k->dq[j] = kin_dualquat_from_mat4(&k->jm[j]);
        if (j % 3 == 1) k->dq[j].r = (kin_quat){ -k->dq[j].r.x, -k->dq[j].r.y, -k->dq[j].r.z, -k->dq[j].r.w };
        if (j % 3 == 1) k->dq[j].d = (kin_quat){ -k->dq[j].d.x, -k->dq[j].d.y, -k->dq[j].d.z, -k->dq[j].d.w };
        if (j % 4 == 2) { /* scale, shear */
            for (int e = 0; e < 12; e++) k->jm[j].m[e] *= tu_range(&r, 0.5f, 1.5f);
            k->jm[j].m[4] += tu_range(&r, -0.3f, 0.3f);
        }
        if (j % 5 == 3) /* mirrored */
            for (int e = 0; e < 3; e++) k->jm[j].m[e] = -k->jm[j].m[e];
    }
    k->jm[nj - 2] = (kin_mat4){ { 0 } };                 /* singular */
    k->jm[nj - 1].m[0] = NAN;                            /* read with w = 0 only */
    k->dq[nj - 1].r.x = NAN;
    for (int v = 0; v < nv; v++) {
        for (int c = 0; c < 3; c++) k->pos[3 * v + c] = tu_range(&r, -1, 1);
        kin_vec3 nn = kin_v3_norm(kin_v3(tu_range(&r, -1, 1), tu_range(&r, -1, 1), tu_range(&r, -1, 1)));
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
        if (kind == 3) { k->w[4 * v] = 0.5f; k->w[4 * v + 1] = -0.5f; k->w[4 * v + 2] = k->w[4 * v + 3] = 0; }
        if (kind == 4) for (int i = 0; i < 4; i++) k->w[4 * v + i] = 0.0f;
        if (kind == 5) k->w[4 * v + 3] = -0.25f;               /* negative */
        if (kind == 6) { k->jt[4 * v + 3] = (uint16_t)(nj - 1); k->w[4 * v + 3] = 0.0f; }
        if (kind == 8) { k->jt[4 * v + 2] = 60000; k->w[4 * v + 2] = 0.0f; } /* never read */
        if (kind == 7) { k->jt[4 * v] = (uint16_t)(nj - 2); }   /* singular joint */
    }
    memset(&k->mesh, 0, sizeof k->mesh);
    k->mesh.vertex_count = nv;
    k->mesh.positions = k->pos;
    k->mesh.normals = (n % 7 == 6) ? NULL : k->nrm;
    k->mesh.joints = k->jt;
    k->mesh.weights = k->w;
}

static void free_case(skcase *k)
{
    free(k->pos); free(k->nrm); free(k->w); free(k->jt);
}

/* Runs one skinning (dqs = 0 LBS, 1 DQS) on isa into fresh buffers. */
static void run(const skcase *k, int dqs, int isa, float *po, float *no)
{
    size_t n = (size_t)k->mesh.vertex_count * 3 * sizeof(float);
    memset(po, 0xA5, n);
    memset(no, 0xA5, n);
    if (dqs) kin_skin_dqs_isa(&k->mesh, k->dq, po, no, isa);
    else kin_skin_lbs_isa(&k->mesh, k->jm, po, no, isa);
}

static void first_diff(const float *a, const float *b, int n, const char *what, int c,
                       const char *isa)
{
    for (int i = 0; i < n; i++)
        if (memcmp(&a[i], &b[i], sizeof(float)))
            fail_msg("case %d: %s %s vertex %d comp %d: %.9g (ref %.9g)", c, isa, what,
                     i / 3, i % 3, (double)b[i], (double)a[i]);
}

static void isa_equal(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP kin skin isa %s: this CPU does not run it\n",
                      ef_isa_name((ef_isa)isa));
        skip();
    }
    uint32_t crc = 0;
    long verts = 0, kept = 0;
    for (int c = 0; c < NCASES; c++) {
        skcase k;
        make_case(c, &k);
        int n3 = k.mesh.vertex_count * 3;
        float *rp = malloc((size_t)n3 * 4), *rn = malloc((size_t)n3 * 4);
        float *sp = malloc((size_t)n3 * 4), *sn = malloc((size_t)n3 * 4);
        for (int dqs = 0; dqs < 2; dqs++) {
            run(&k, dqs, EF_ISA_REF, rp, rn);
            crc = tu_crc32(crc, rp, (size_t)n3 * 4);
            if (k.mesh.normals) crc = tu_crc32(crc, rn, (size_t)n3 * 4);
            for (int i = 0; i < n3; i++) kept += rp[i] == k.pos[i];
            run(&k, dqs, isa, sp, sn);
            first_diff(rp, sp, n3, dqs ? "DQS position" : "LBS position", c,
                       ef_isa_name((ef_isa)isa));
            first_diff(rn, sn, n3, dqs ? "DQS normal" : "LBS normal", c,
                       ef_isa_name((ef_isa)isa));
            verts += k.mesh.vertex_count;
        }
        free(rp); free(rn); free(sp); free(sn);
        free_case(&k);
    }
    print_message("NOTE kin skin %s: %d cases, %ld vertex skins equal to the reference, "
                  "CRC32 0x%08X (recorded 0x%08X)\n", ef_isa_name((ef_isa)isa), NCASES,
                  verts, crc, SKIN_CRC);
    /* the bind-pose branch (zero weight sum) really ran */
    assert_true(kept > 300);
    assert_int_equal(crc, SKIN_CRC);
}

static void test_sse2(void **state) { (void)state; isa_equal(EF_ISA_SSE2); }
static void test_avx2(void **state) { (void)state; isa_equal(EF_ISA_AVX2); }
static void test_avx512(void **state) { (void)state; isa_equal(EF_ISA_AVX512); }

/* kin_skin_lbs / kin_skin_dqs (the dispatching entry points) give the
 * reference's bytes, and kin_skin_isa() names a path the CPU runs. */
static void test_dispatch_equal(void **state)
{
    (void)state;
    int isa = kin_skin_isa();
    assert_true(isa >= EF_ISA_REF && isa < EF_ISA_COUNT);
    assert_true(ef_cpu_has((ef_isa)isa));
    for (int c = 0; c < 20; c++) {
        skcase k;
        make_case(c, &k);
        int n3 = k.mesh.vertex_count * 3;
        float *rp = malloc((size_t)n3 * 4), *rn = malloc((size_t)n3 * 4);
        float *sp = malloc((size_t)n3 * 4), *sn = malloc((size_t)n3 * 4);
        for (int dqs = 0; dqs < 2; dqs++) {
            run(&k, dqs, EF_ISA_REF, rp, rn);
            memset(sp, 0, (size_t)n3 * 4);
            memset(sn, 0xA5, (size_t)n3 * 4);
            if (dqs) kin_skin_dqs(&k.mesh, k.dq, sp, sn);
            else kin_skin_lbs(&k.mesh, k.jm, sp, sn);
            first_diff(rp, sp, n3, "position", c, "dispatch");
            first_diff(rn, sn, n3, "normal", c, "dispatch");
        }
        free(rp); free(rn); free(sp); free(sn);
        free_case(&k);
    }
}

/* Without normals in the output nothing is written there, on every ISA. */
static void test_no_normal_output(void **state)
{
    (void)state;
    skcase k;
    make_case(16, &k);   /* 1000 vertices */
    int n3 = k.mesh.vertex_count * 3;
    float *po = malloc((size_t)n3 * 4), *ref = malloc((size_t)n3 * 4), *tmp = malloc((size_t)n3 * 4);
    run(&k, 0, EF_ISA_REF, ref, tmp);
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa)) continue;
        memset(po, 0, (size_t)n3 * 4);
        kin_skin_lbs_isa(&k.mesh, k.jm, po, NULL, isa);
        first_diff(ref, po, n3, "LBS position without normals", 16, ef_isa_name((ef_isa)isa));
    }
    free(po); free(ref); free(tmp);
    free_case(&k);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sse2),
        cmocka_unit_test(test_avx2),
        cmocka_unit_test(test_avx512),
        cmocka_unit_test(test_dispatch_equal),
        cmocka_unit_test(test_no_normal_output),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
