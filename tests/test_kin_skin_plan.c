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
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/kin/kin.h"
#include "support/isa_tests.h"
#include "support/kin_testmesh.h"

#define NCASES 40

static void make_case(int n, tu_skin_case *k)
{
    tu_rng r = { 0x706c616e0000ull + (uint64_t)n };
    static const int counts[] = { 1, 5, 15, 16, 17, 32, 33, 100, 257, 1000 };
    int nv = counts[n % (int)(sizeof counts / sizeof counts[0])];
    if (n >= 20) nv = 1 + tu_int(&r, 4000);
    const int nj = n % 3 == 0 ? 24 : n % 3 == 1 ? 48 : TU_SKIN_JOINTS;
    tu_skin_case_begin(k, &r, nv, nj);
    /* grouped cases: runs of vertices share a joint list (contiguous
     * batches); the others draw joints per vertex (scattered batches) */
    const int grouped = n % 2 == 0;
    uint16_t run_j[4] = { 0, 0, 0, 0 };
    int run_n = 1;
    for (int v = 0; v < nv; v++) {
        for (int c = 0; c < 3; c++) k->pos[3 * v + c] = tu_range(&r, -1, 1);
        kin_vec3 nn = kin_v3_norm(tu_v3(&r, -1, 1));
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
        /* the special kinds; the singular joint only where joints are
         * drawn per vertex */
        tu_skin_weight_kind(k, v, kind == 7 && grouped ? -1 : kind);
    }
    tu_skin_case_end(k, nv, n % 7 != 6);
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

static void plan_equal(int isa)
{
    if (!ef_cpu_has((ef_isa)isa)) {
        print_message("SKIP kin skin plan %s: this CPU does not run it; untested: planned "
                      "skinning of src/kin/kin_skin_%s.c\n", ef_isa_name((ef_isa)isa), ef_isa_name((ef_isa)isa));
        skip();
    }
    long verts = 0, contiguous = 0, batches = 0, kept = 0;
    for (int c = 0; c < NCASES; c++) {
        tu_skin_case k;
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
            tu_skin_first_diff(rp, sp, n3, dqs ? "DQS plan position" : "LBS plan position", c, nm);
            tu_skin_first_diff(rn, sn, n3, dqs ? "DQS plan normal" : "LBS plan normal", c, nm);
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
        tu_skin_case_free(&k);
    }
    print_message("NOTE kin skin plan %s: %d cases, %ld vertex skins equal to the reference, "
                  "%ld batches\n", ef_isa_name((ef_isa)isa), NCASES, verts, batches);
    assert_true(kept > 300);        /* the bind-pose group really ran */
    assert_true(contiguous >= 2);   /* the grouped cases really grouped */
}

static void test_ref(void **state) { (void)state; plan_equal(EF_ISA_REF); }
TU_ISA_TESTS(test_, plan_equal)

/* DQS with the weight sums at the ends of the float range (vertex v's
 * weights scaled by tu_skin_weight_scale(v), mixed within every batch):
 * the plan on every ISA gives the bytes of kin_skin_dqs (EF_ISA_REF) of
 * the same weights, and every coordinate that moves without the scaling
 * moves the same with it (within 1e-5: not the bind pose, inf or NaN). */
static void test_dqs_weight_scale(void **state)
{
    (void)state;
    long runs = 0, moved = 0;
    for (int c = 0; c < NCASES; c += 3) {
        tu_skin_case k;
        make_case(c, &k);
        float *w = tu_skin_scaled_weights(&k);
        kin_mesh m = k.mesh;
        m.weights = w;
        kin_skin_plan plan;
        void *mem;
        build_plan(&m, &plan, &mem);
        const int n3 = m.vertex_count * 3;
        const size_t bytes = (size_t)n3 * sizeof(float);
        float *up = malloc(bytes), *un = malloc(bytes), *rp = malloc(bytes), *rn = malloc(bytes),
              *sp = malloc(bytes), *sn = malloc(bytes);
        memset(rn, 0xA5, bytes);
        kin_skin_dqs_isa(&k.mesh, k.dq, up, un, EF_ISA_REF);
        kin_skin_dqs_isa(&m, k.dq, rp, rn, EF_ISA_REF);
        for (int i = 0; i < n3; i++) {
            if (up[i] == k.pos[i]) continue;
            if (!(fabsf(rp[i] - up[i]) <= 1e-5f))
                fail_msg("case %d vertex %d (weights x %g): %.9g, unscaled %.9g", c, i / 3,
                         (double)tu_skin_weight_scale(i / 3), (double)rp[i], (double)up[i]);
            moved++;
        }
        for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
            if (!ef_cpu_has((ef_isa)isa)) continue;
            memset(sp, 0x5A, bytes);
            memset(sn, 0xA5, bytes);
            kin_skin_dqs_plan_part(&plan, k.dq, sp, sn, 0, 1, isa);
            const char *nm = ef_isa_name((ef_isa)isa);
            tu_skin_first_diff(rp, sp, n3, "DQS plan position, scaled weights", c, nm);
            tu_skin_first_diff(rn, sn, n3, "DQS plan normal, scaled weights", c, nm);
            runs++;
        }
        free(up); free(un); free(rp); free(rn); free(sp); free(sn);
        free(mem);
        free(w);
        tu_skin_case_free(&k);
    }
    print_message("NOTE kin dqs plan, scaled weights: %ld ISA runs equal to the reference, "
                  "%ld moved coordinates still moved\n", runs, moved);
    assert_true(moved > 10000);
}

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
    tu_skin_case k;
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
        tu_skin_first_diff(whole, acc, n3, "parts position", 21, "default");
        tu_skin_first_diff(wn, an, n3, "parts normal", 21, "default");
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
    tu_skin_case_free(&k);
}

/* NULL joint matrices / dual quaternions: the bind pose, as the reference;
 * a mesh without joints: the bind pose too. */
static void test_bind_pose(void **state)
{
    (void)state;
    tu_skin_case k;
    make_case(7, &k);   /* 100 vertices */
    kin_skin_plan plan;
    void *mem;
    build_plan(&k.mesh, &plan, &mem);
    const int n3 = k.mesh.vertex_count * 3;
    float po[300], no[300];
    kin_skin_lbs_plan(&plan, NULL, po, no);
    tu_skin_first_diff(k.pos, po, n3, "LBS without matrices", 7, "default");
    tu_skin_first_diff(k.nrm, no, n3, "LBS normals without matrices", 7, "default");
    memset(po, 0, sizeof po);
    kin_skin_dqs_plan(&plan, NULL, po, no);
    tu_skin_first_diff(k.pos, po, n3, "DQS without dual quaternions", 7, "default");
    free(mem);
    kin_mesh bare = k.mesh;
    bare.joints = NULL;
    bare.weights = NULL;
    build_plan(&bare, &plan, &mem);
    assert_int_equal(plan.max_joint, -1);
    assert_int_equal(plan.group_count, 1);
    memset(po, 0, sizeof po);
    kin_skin_lbs_plan(&plan, k.jm, po, no);
    tu_skin_first_diff(k.pos, po, n3, "unskinned mesh", 7, "default");
    free(mem);
    tu_skin_case_free(&k);
}

static void test_invalid(void **state)
{
    (void)state;
    kin_skin_plan plan;
    assert_int_equal(kin_skin_plan_scratch_size(NULL), 0);
    assert_int_equal(kin_skin_plan_size(NULL, NULL), 0);
    assert_int_equal(kin_skin_plan_init(&plan, NULL, NULL, NULL, 0), -1);
    assert_null(plan.batches);
    tu_skin_case k;
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
    tu_skin_case_free(&k);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_ref),
        TU_ISA_UNIT_TESTS(test_),
        cmocka_unit_test(test_dqs_weight_scale),
        cmocka_unit_test(test_structure),
        cmocka_unit_test(test_parts),
        cmocka_unit_test(test_bind_pose),
        cmocka_unit_test(test_invalid))
