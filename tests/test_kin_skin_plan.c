/* test_kin_skin_plan.c - the skin plan (kin_skin_plan.c) against the
 * reference: over seeded random meshes (1..4 influences, zero weights
 * inside the list, weights summing to zero, all-zero, negative and
 * unnormalised weights, a NaN joint and an out-of-range joint read only
 * with weight 0, scaled, sheared, mirrored and singular joints, antipodal
 * dual quaternions; runs of vertices sharing joints, so batches are
 * contiguous, and joints drawn per vertex, so they are scattered; vertex
 * counts that are and are not multiples of 16; with and without normals)
 * kin_skin_lbs_plan / kin_skin_dqs_plan on every ISA give the bytes of
 * kin_skin_lbs / kin_skin_dqs (EF_ISA_REF), and no NaN where the
 * reference has none. Also: the plan's structure on a hand-built mesh
 * with hand-worked positions, parts for threads (disjoint, together the
 * whole), and rejected inputs. An ISA this CPU lacks is reported as SKIP. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/kin/kin.h"

#define NCASES 40
#define NJOINTS 80

typedef struct pcase {
    kin_mesh mesh;
    float *pos, *nrm, *w;
    uint16_t *jt;
    kin_mat4 jm[NJOINTS];
    kin_dualquat dq[NJOINTS];
    int nj;
} pcase;

static kin_quat rand_quat(tu_rng *r)
{
    kin_quat q = { tu_range(r, -1, 1), tu_range(r, -1, 1), tu_range(r, -1, 1),
                   tu_range(r, -1, 1) };
    return kin_quat_normalize(q);
}

static void make_case(int n, pcase *k)
{
    tu_rng r = { 0x706c616e0000ull + (uint64_t)n };
    static const int counts[] = { 1, 5, 15, 16, 17, 32, 33, 100, 257, 1000 };
    int nv = counts[n % (int)(sizeof counts / sizeof counts[0])];
    if (n >= 20) nv = 1 + tu_int(&r, 4000);
    k->pos = malloc((size_t)nv * 3 * sizeof(float));
    k->nrm = malloc((size_t)nv * 3 * sizeof(float));
    k->w = malloc((size_t)nv * 4 * sizeof(float));
    k->jt = malloc((size_t)nv * 4 * sizeof(uint16_t));
    const int nj = k->nj = n % 3 == 0 ? 24 : n % 3 == 1 ? 48 : NJOINTS;
    for (int j = 0; j < nj; j++) {
        kin_vec3 t = kin_v3(tu_range(&r, -2, 2), tu_range(&r, -2, 2), tu_range(&r, -2, 2));
        k->jm[j] = kin_mat4_from_tr(t, rand_quat(&r));
        k->dq[j] = kin_dualquat_from_mat4(&k->jm[j]);
        if (j % 3 == 1) { /* the other sign of the same transform */
            kin_quat *q = &k->dq[j].r, *d = &k->dq[j].d;
            *q = (kin_quat){ -q->x, -q->y, -q->z, -q->w };
            *d = (kin_quat){ -d->x, -d->y, -d->z, -d->w };
        }
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
    /* grouped cases: runs of vertices share a joint list (contiguous
     * batches); the others draw joints per vertex (scattered batches) */
    const int grouped = n % 2 == 0;
    uint16_t run_j[4] = { 0, 0, 0, 0 };
    int run_n = 1;
    for (int v = 0; v < nv; v++) {
        for (int c = 0; c < 3; c++) k->pos[3 * v + c] = tu_range(&r, -1, 1);
        kin_vec3 nn = kin_v3_norm(kin_v3(tu_range(&r, -1, 1), tu_range(&r, -1, 1), tu_range(&r, -1, 1)));
        memcpy(k->nrm + 3 * v, &nn, sizeof nn);
        if (!grouped || v % 40 == 0) {
            run_n = 1 + tu_int(&r, 4);
            for (int i = 0; i < 4; i++) run_j[i] = (uint16_t)tu_int(&r, nj - 1);
        }
        int kind = tu_int(&r, 12);
        float s = 0;
        for (int i = 0; i < 4; i++) {
            k->jt[4 * v + i] = run_j[i];
            float x = i < run_n ? 0.05f + tu_unit(&r) : 0.0f;
            if (kind == 0 && i > 0) x = 0.0f;                 /* one influence */
            if (kind == 1 && i == 1) x = 0.0f;                /* a zero inside */
            k->w[4 * v + i] = x;
            s += x;
        }
        if (kind != 2)
            for (int i = 0; i < 4; i++) k->w[4 * v + i] /= s;  /* kind 2: unnormalised */
        if (kind == 3) { k->w[4 * v] = 0.5f; k->w[4 * v + 1] = -0.5f; k->w[4 * v + 2] = k->w[4 * v + 3] = 0; }
        if (kind == 4) for (int i = 0; i < 4; i++) k->w[4 * v + i] = 0.0f;
        if (kind == 5) k->w[4 * v + 3] = -0.25f;               /* negative */
        if (kind == 6) { k->jt[4 * v + 3] = (uint16_t)(nj - 1); k->w[4 * v + 3] = 0.0f; }
        if (kind == 8) { k->jt[4 * v + 2] = 60000; k->w[4 * v + 2] = 0.0f; } /* never read */
        if (kind == 7 && !grouped) k->jt[4 * v] = (uint16_t)(nj - 2);       /* singular */
    }
    memset(&k->mesh, 0, sizeof k->mesh);
    k->mesh.vertex_count = nv;
    k->mesh.positions = k->pos;
    k->mesh.normals = (n % 7 == 6) ? NULL : k->nrm;
    k->mesh.joints = k->jt;
    k->mesh.weights = k->w;
    k->mesh.skin = 0;
    k->mesh.node = -1;
}

static void free_case(pcase *k)
{
    free(k->pos); free(k->nrm); free(k->w); free(k->jt);
}

/* A plan of k's mesh in fresh memory (*mem to free). */
static void build_plan(const kin_mesh *m, kin_skin_plan *plan, void **mem)
{
    size_t ns = kin_skin_plan_scratch_size(m);
    void *scratch = malloc(ns ? ns : 1);
    assert_non_null(scratch);
    size_t bytes = kin_skin_plan_size(m, scratch);
    assert_true(bytes > 0);
    *mem = aligned_alloc(64, (bytes + 63) & ~(size_t)63);
    assert_non_null(*mem);
    assert_int_equal(kin_skin_plan_init(plan, m, scratch, *mem, bytes), 0);
    free(scratch);
}

static void first_diff(const float *ref, const float *got, int n, const char *what, int c,
                       const char *isa)
{
    for (int i = 0; i < n; i++)
        if (memcmp(&ref[i], &got[i], sizeof(float)))
            fail_msg("case %d: %s %s vertex %d comp %d: %.9g (ref %.9g)", c, isa, what,
                     i / 3, i % 3, (double)got[i], (double)ref[i]);
}

static void plan_equal(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP kin skin plan %s: this CPU does not run it\n",
                      ef_isa_name((ef_isa)isa));
        skip();
    }
    long verts = 0, contiguous = 0, batches = 0, kept = 0;
    for (int c = 0; c < NCASES; c++) {
        pcase k;
        make_case(c, &k);
        kin_skin_plan plan;
        void *mem;
        build_plan(&k.mesh, &plan, &mem);
        assert_int_equal(plan.vertex_count, k.mesh.vertex_count);
        assert_int_equal(plan.normals, k.mesh.normals != NULL);
        assert_true(plan.max_joint < k.nj);   /* 60000 (weight 0) is never read */
        const int n3 = k.mesh.vertex_count * 3;
        const size_t bytes = (size_t)n3 * sizeof(float);
        float *rp = malloc(bytes), *rn = malloc(bytes), *sp = malloc(bytes), *sn = malloc(bytes);
        for (int dqs = 0; dqs < 2; dqs++) {
            memset(rp, 0xA5, bytes);
            memset(rn, 0xA5, bytes);
            memset(sp, 0x5A, bytes);
            memset(sn, 0xA5, bytes);   /* no normals: both untouched */
            if (dqs) {
                kin_skin_dqs_isa(&k.mesh, k.dq, rp, rn, EF_ISA_REF);
                kin_skin_dqs_plan_part(&plan, k.dq, sp, sn, 0, 1, isa);
            } else {
                kin_skin_lbs_isa(&k.mesh, k.jm, rp, rn, EF_ISA_REF);
                kin_skin_lbs_plan_part(&plan, k.jm, sp, sn, 0, 1, isa);
            }
            const char *nm = ef_isa_name((ef_isa)isa);
            first_diff(rp, sp, n3, dqs ? "DQS plan position" : "LBS plan position", c, nm);
            first_diff(rn, sn, n3, dqs ? "DQS plan normal" : "LBS plan normal", c, nm);
            /* NaN-free: the NaN joint is only read with weight 0 */
            for (int i = 0; i < n3; i++) {
                if (!isfinite(sp[i])) fail_msg("case %d: position %d not finite", c, i / 3);
                if (k.mesh.normals && !isfinite(sn[i])) fail_msg("case %d: normal %d not finite", c, i / 3);
                kept += sp[i] == k.pos[i];
            }
            verts += k.mesh.vertex_count;
        }
        batches += plan.batch_count;
        /* contiguous batches: counted through their effect, a plan of the
         * grouped cases has fewer batches than vertices / 8 */
        if (c % 2 == 0 && k.mesh.vertex_count >= 1000)
            contiguous += plan.batch_count < k.mesh.vertex_count / 8;
        free(rp); free(rn); free(sp); free(sn);
        free(mem);
        free_case(&k);
    }
    print_message("NOTE kin skin plan %s: %d cases, %ld vertex skins equal to the reference, "
                  "%ld batches\n", ef_isa_name((ef_isa)isa), NCASES, verts, batches);
    assert_true(kept > 300);        /* the bind-pose group really ran */
    assert_true(contiguous >= 2);   /* the grouped cases really grouped */
}

static void test_ref(void **state) { (void)state; plan_equal(EF_ISA_REF); }
static void test_sse2(void **state) { (void)state; plan_equal(EF_ISA_SSE2); }
static void test_avx2(void **state) { (void)state; plan_equal(EF_ISA_AVX2); }
static void test_avx512(void **state) { (void)state; plan_equal(EF_ISA_AVX512); }

/* A hand-built mesh: 20 vertices on joint 3 alone (weight 1), 20 on joints
 * 1 then 2 (0.25, 0.75), 5 on 2 then 1 (another order: another group), 3
 * with weights (0.5, -0.5) (sum 0: bind pose). Joint j translates by
 * (j, 0, 0): positions move by 3, by 0.25 + 1.5 = 1.75, or not at all. */
static void test_structure(void **state)
{
    (void)state;
    enum { NV = 48 };
    float pos[NV * 3], w[NV * 4];
    uint16_t jt[NV * 4];
    for (int v = 0; v < NV; v++) {
        pos[3 * v] = 0.5f * (float)v; pos[3 * v + 1] = 1; pos[3 * v + 2] = -2;
        memset(&jt[4 * v], 0, 4 * sizeof jt[0]);
        memset(&w[4 * v], 0, 4 * sizeof w[0]);
        if (v < 20) { jt[4 * v] = 3; w[4 * v] = 1; }
        else if (v < 40) { jt[4 * v] = 1; jt[4 * v + 1] = 2; w[4 * v] = 0.25f; w[4 * v + 1] = 0.75f; }
        else if (v < 45) { jt[4 * v + 2] = 2; jt[4 * v + 3] = 1; w[4 * v + 2] = 0.75f; w[4 * v + 3] = 0.25f; }
        else { jt[4 * v] = 7; jt[4 * v + 1] = 9; w[4 * v] = 0.5f; w[4 * v + 1] = -0.5f; }
    }
    kin_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = NV; m.positions = pos; m.joints = jt; m.weights = w;
    kin_skin_plan plan;
    void *mem;
    build_plan(&m, &plan, &mem);
    /* groups: sum 0 (3 vertices, 1 batch), {3} (20: 2 batches), {1,2}
     * (20: 2), {2,1} (5: 1) */
    assert_int_equal(plan.group_count, 4);
    assert_int_equal(plan.batch_count, 6);
    assert_int_equal(plan.max_joint, 3);   /* 7 and 9 are in a zero-sum vertex */
    assert_int_equal(plan.normals, 0);
    /* 16 consecutive vertices: the first batch of {3} and of {1,2} */
    assert_int_equal(kin_skin_plan_contiguous(&plan), 2);
    assert_int_equal(kin_skin_plan_contiguous(NULL), 0);
    kin_mat4 jm[4];
    for (int j = 0; j < 4; j++) jm[j] = kin_mat4_from_tr(kin_v3((float)j, 0, 0), kin_quat_identity());
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa)) continue;
        float out[NV * 3], nrm[NV * 3];
        memset(out, 0, sizeof out);
        memset(nrm, 0x7F, sizeof nrm);
        kin_skin_lbs_plan_part(&plan, jm, out, nrm, 0, 1, isa);
        for (int v = 0; v < NV; v++) {
            float dx = v < 20 ? 3.0f : v < 45 ? 1.75f : 0.0f;
            assert_true(out[3 * v] == 0.5f * (float)v + dx);
            assert_true(out[3 * v + 1] == 1.0f && out[3 * v + 2] == -2.0f);
            assert_true(nrm[3 * v] != 0);   /* no normals in the plan: untouched */
        }
    }
    free(mem);
}

/* Parts write disjoint vertices and together all of them, and the bytes
 * do not depend on the split. */
static void test_parts(void **state)
{
    (void)state;
    pcase k;
    make_case(21, &k);
    kin_skin_plan plan;
    void *mem;
    build_plan(&k.mesh, &plan, &mem);
    const int n3 = k.mesh.vertex_count * 3;
    const size_t bytes = (size_t)n3 * sizeof(float);
    float *whole = malloc(bytes), *wn = malloc(bytes), *acc = malloc(bytes), *an = malloc(bytes),
          *one = malloc(bytes), *on = malloc(bytes);
    kin_skin_lbs_plan(&plan, k.jm, whole, wn);
    for (int parts = 1; parts <= 5; parts++) {
        memset(acc, 0xFF, bytes);     /* NaN pattern: never a result here */
        memset(an, 0xFF, bytes);
        long written = 0;
        for (int part = 0; part < parts; part++) {
            memset(one, 0xFF, bytes);
            memset(on, 0xFF, bytes);
            kin_skin_lbs_plan_part(&plan, k.jm, one, on, part, parts, 0);
            for (int v = 0; v < k.mesh.vertex_count; v++) {
                uint32_t u;
                memcpy(&u, &one[3 * v], 4);
                if (u == 0xFFFFFFFFu) continue;
                uint32_t prev;
                memcpy(&prev, &acc[3 * v], 4);
                if (prev != 0xFFFFFFFFu) fail_msg("vertex %d written by two parts", v);
                memcpy(&acc[3 * v], &one[3 * v], 12);
                memcpy(&an[3 * v], &on[3 * v], 12);
                written++;
            }
        }
        assert_int_equal(written, k.mesh.vertex_count);
        first_diff(whole, acc, n3, "parts position", 21, "default");
        first_diff(wn, an, n3, "parts normal", 21, "default");
    }
    /* a part outside [0, parts) writes nothing */
    memset(one, 0xFF, bytes);
    kin_skin_lbs_plan_part(&plan, k.jm, one, NULL, 3, 3, 0);
    kin_skin_lbs_plan_part(&plan, k.jm, one, NULL, -1, 3, 0);
    for (int i = 0; i < n3; i++) {
        uint32_t u;
        memcpy(&u, &one[i], 4);
        assert_true(u == 0xFFFFFFFFu);
    }
    free(whole); free(wn); free(acc); free(an); free(one); free(on);
    free(mem);
    free_case(&k);
}

/* NULL joint matrices / dual quaternions: the bind pose, as the reference;
 * a mesh without joints: the bind pose too. */
static void test_bind_pose(void **state)
{
    (void)state;
    pcase k;
    make_case(7, &k);   /* 100 vertices */
    kin_skin_plan plan;
    void *mem;
    build_plan(&k.mesh, &plan, &mem);
    const int n3 = k.mesh.vertex_count * 3;
    float po[300], no[300];
    kin_skin_lbs_plan(&plan, NULL, po, no);
    first_diff(k.pos, po, n3, "LBS without matrices", 7, "default");
    first_diff(k.nrm, no, n3, "LBS normals without matrices", 7, "default");
    memset(po, 0, sizeof po);
    kin_skin_dqs_plan(&plan, NULL, po, no);
    first_diff(k.pos, po, n3, "DQS without dual quaternions", 7, "default");
    free(mem);
    kin_mesh bare = k.mesh;
    bare.joints = NULL;
    bare.weights = NULL;
    build_plan(&bare, &plan, &mem);
    assert_int_equal(plan.max_joint, -1);
    assert_int_equal(plan.group_count, 1);
    memset(po, 0, sizeof po);
    kin_skin_lbs_plan(&plan, k.jm, po, no);
    first_diff(k.pos, po, n3, "unskinned mesh", 7, "default");
    free(mem);
    free_case(&k);
}

static void test_invalid(void **state)
{
    (void)state;
    kin_skin_plan plan;
    assert_int_equal(kin_skin_plan_scratch_size(NULL), 0);
    assert_int_equal(kin_skin_plan_size(NULL, NULL), 0);
    assert_int_equal(kin_skin_plan_init(&plan, NULL, NULL, NULL, 0), -1);
    assert_null(plan.batches);
    pcase k;
    make_case(5, &k);   /* 32 vertices: 2..32 batches */
    void *scratch = malloc(kin_skin_plan_scratch_size(&k.mesh));
    size_t bytes = kin_skin_plan_size(&k.mesh, scratch);
    assert_true(bytes > 0);
    unsigned char *mem = aligned_alloc(64, bytes + 64);
    assert_int_equal(kin_skin_plan_init(&plan, &k.mesh, scratch, mem + 4, bytes), -1);
    assert_int_equal(kin_skin_plan_init(&plan, &k.mesh, scratch, mem, bytes - 1), -1);
    assert_int_equal(kin_skin_plan_init(&plan, &k.mesh, NULL, mem, bytes), -1);
    assert_int_equal(plan.batch_count, 0);
    kin_mesh bad = k.mesh;
    bad.positions = NULL;
    assert_int_equal(kin_skin_plan_size(&bad, scratch), 0);
    bad = k.mesh;
    bad.vertex_count = -1;
    assert_int_equal(kin_skin_plan_init(&plan, &bad, scratch, mem, bytes), -1);
    assert_int_equal(kin_skin_plan_init(&plan, &k.mesh, scratch, mem, bytes), 0);
    /* calls with NULL arguments do nothing (and do not crash) */
    kin_skin_lbs_plan(NULL, k.jm, NULL, NULL);
    kin_skin_lbs_plan(&plan, k.jm, NULL, NULL);
    kin_skin_dqs_plan(NULL, k.dq, NULL, NULL);
    free(mem);
    free(scratch);
    free_case(&k);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ref),
        cmocka_unit_test(test_sse2),
        cmocka_unit_test(test_avx2),
        cmocka_unit_test(test_avx512),
        cmocka_unit_test(test_structure),
        cmocka_unit_test(test_parts),
        cmocka_unit_test(test_bind_pose),
        cmocka_unit_test(test_invalid),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
