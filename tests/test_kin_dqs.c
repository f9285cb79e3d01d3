/* test_kin_dqs.c - dual-quaternion skinning (kin_dqs.c) against
 * hand-worked answers: matrix <-> dual quaternion, agreement with LBS for
 * rigid single-joint vertices, antipodal quaternions, a pure translation
 * blend, and the wrist-twist sweep -180..180 degrees where the LBS
 * cross-section shrinks by |1 - w + w e^(i theta)|^2 and DQS keeps it;
 * the reference's division-only formula against Kavan's normalised dual
 * quaternion evaluated in double (positions, normals, their lengths) on
 * every ISA, with weight sums from 1e-30 to 1e30; b.r = 0 with a nonzero
 * weight sum keeps the bind pose. */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/kin/kin.h"

static kin_quat rand_q(tu_rng *g)
{
    return kin_quat_normalize(tu_quat(g, -1, 1));
}

static kin_mesh mesh_of(int n, const float *pos, const float *nrm, const uint16_t *j,
                        const float *w)
{
    kin_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = n; m.positions = pos; m.normals = nrm; m.joints = j; m.weights = w;
    return m;
}

/* ------------------------------------------------------------ validity */

static void validity_zero_weights_and_no_skin(void **state)
{
    (void)state;
    float pos[6] = { 1, 2, 3, 4, 5, 6 }, nrm[6] = { 0, 1, 0, 1, 0, 0 }, po[6], no[6];
    uint16_t jt[8] = { 0 };
    float w[8] = { 0 };
    w[4] = 1.0f;
    kin_mat4 jm[1] = { kin_mat4_from_tr(kin_v3(1, 1, 1), kin_quat_identity()) };
    kin_dualquat dq[1];
    kin_skin_dq_from_matrices(jm, 1, dq);
    kin_mesh m = mesh_of(2, pos, nrm, jt, w);
    kin_skin_dqs(&m, dq, po, no);
    NEAR(po[0], 1, 0); NEAR(po[1], 2, 0); NEAR(po[2], 3, 0);     /* bind pose */
    NEAR(po[3], 5, 1e-6); NEAR(po[4], 6, 1e-6); NEAR(po[5], 7, 1e-6);
    kin_skin_dqs(&m, NULL, po, no);                              /* no joints */
    assert_memory_equal(po, pos, sizeof pos);
}

/* b.r exactly 0 with a nonzero weight sum: r1 = (0,0,0,1), r2 =
 * (0,0,1,0), r3 = (0,0,0.25,0.25) (not unit: the blend does not care),
 * weights 0.25, 0.25, -1 (sum -0.5; no sign flips, r2.r1 = 0 and
 * r3.r1 > 0) give b.r = 0 in exact float arithmetic: the bind pose, on
 * every ISA, from the mesh and with a skin plan, also with the weights
 * scaled by 1e-30 (b.r stays 0 through the range rescaling). 37 vertices:
 * whole vectors and a tail on every ISA. */
static void validity_zero_real_part_keeps_bind_pose(void **state)
{
    (void)state;
    enum { N = 37 };
    float pos[N * 3], nrm[N * 3], w[N * 4], po[N * 3], no[N * 3];
    uint16_t jt[N * 4];
    for (int v = 0; v < N; v++) {
        const float s = v % 2 ? 1e-30f : 1.0f;
        for (int c = 0; c < 3; c++) { pos[3 * v + c] = (float)(v + c); nrm[3 * v + c] = c == 1; }
        jt[4 * v] = 0; jt[4 * v + 1] = 1; jt[4 * v + 2] = 2; jt[4 * v + 3] = 0;
        w[4 * v] = 0.25f * s; w[4 * v + 1] = 0.25f * s; w[4 * v + 2] = -s; w[4 * v + 3] = 0;
    }
    kin_dualquat dq[3] = { { { 0, 0, 0, 1 }, { 0.5f, 0, 0, 0 } },
                           { { 0, 0, 1, 0 }, { 0, 0.5f, 0, 0 } },
                           { { 0, 0, 0.25f, 0.25f }, { 0, 0, 0.5f, 0 } } };
    kin_mesh m = mesh_of(N, pos, nrm, jt, w);
    size_t ns = kin_skin_plan_scratch_size(&m);
    void *scratch = malloc(ns);
    size_t bytes = kin_skin_plan_size(&m, scratch);
    void *mem = aligned_alloc(64, (bytes + 63) & ~(size_t)63);
    kin_skin_plan plan;
    assert_int_equal(kin_skin_plan_init(&plan, &m, scratch, mem, bytes), 0);
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa)) continue;
        for (int with_plan = 0; with_plan < 2; with_plan++) {
            memset(po, 0xFF, sizeof po);
            memset(no, 0xFF, sizeof no);
            if (with_plan) kin_skin_dqs_plan_part(&plan, dq, po, no, 0, 1, isa);
            else kin_skin_dqs_isa(&m, dq, po, no, isa);
            assert_memory_equal(po, pos, sizeof pos);
            assert_memory_equal(no, nrm, sizeof nrm);
        }
    }
    /* the same joints with weights 0.25, 0.25, -0.75 move the vertex */
    w[2] = -0.75f;
    kin_skin_dqs_isa(&m, dq, po, no, EF_ISA_REF);
    assert_true(memcmp(po, pos, 3 * sizeof(float)) != 0);
    free(mem);
    free(scratch);
}

/* -------------------------------------------------------------- results */

static void result_dualquat_matches_matrix(void **state)
{
    (void)state;
    tu_rng g = { 0x64717331 };
    for (int i = 0; i < 200; i++) {
        kin_quat r = rand_q(&g);
        kin_vec3 t = tu_v3(&g, -2, 2);
        kin_mat4 m = kin_mat4_from_tr(t, r);
        kin_dualquat q = kin_dualquat_from_mat4(&m);
        kin_vec3 p = tu_v3(&g, -1, 1);
        kin_vec3 a = kin_mat4_mul_point(&m, p), b = kin_dualquat_transform(&q, p);
        NEAR(a.x, b.x, 2e-6); NEAR(a.y, b.y, 2e-6); NEAR(a.z, b.z, 2e-6);
        /* a uniform scale in the matrix is removed */
        kin_transform tr = { t, r, kin_v3(2, 2, 2) };
        kin_mat4 ms = kin_mat4_from_transform(&tr);
        kin_dualquat qs = kin_dualquat_from_mat4(&ms);
        NEAR(fabs(qs.r.x * q.r.x + qs.r.y * q.r.y + qs.r.z * q.r.z + qs.r.w * q.r.w), 1.0, 1e-5);
    }
}

static void result_rigid_vertices_equal_lbs(void **state)
{
    (void)state;
    tu_rng g = { 0x64717332 };
    enum { N = 100, J = 4 };
    float pos[N * 3], nrm[N * 3], w[N * 4], pl[N * 3], nl[N * 3], pd[N * 3], nd[N * 3];
    uint16_t jt[N * 4];
    for (int v = 0; v < N; v++) {
        const float nx = tu_range(&g, -1, 1);   /* drawn in order (tu_kin.h) */
        const float ny = tu_range(&g, -1, 1);
        kin_vec3 n = kin_v3_norm(kin_v3(nx, ny, 0.3f));
        memcpy(nrm + 3 * v, &n, sizeof n);
        for (int c = 0; c < 3; c++) pos[3 * v + c] = tu_range(&g, -1, 1);
        for (int i = 0; i < 4; i++) { jt[4 * v + i] = (uint16_t)tu_int(&g, J); w[4 * v + i] = 0; }
        w[4 * v + tu_int(&g, 4)] = 1.0f;        /* one influence */
    }
    kin_mat4 jm[J];
    kin_dualquat dq[J];
    for (int j = 0; j < J; j++) {
        const float tx = tu_range(&g, -1, 1);   /* drawn in order (tu_kin.h) */
        const float ty = tu_range(&g, -1, 1);
        const kin_quat q = rand_q(&g);
        jm[j] = kin_mat4_from_tr(kin_v3(tx, ty, 0), q);
    }
    kin_skin_dq_from_matrices(jm, J, dq);
    /* antipodal quaternions describe the same joint */
    dq[2].r = (kin_quat){ -dq[2].r.x, -dq[2].r.y, -dq[2].r.z, -dq[2].r.w };
    dq[2].d = (kin_quat){ -dq[2].d.x, -dq[2].d.y, -dq[2].d.z, -dq[2].d.w };
    kin_mesh m = mesh_of(N, pos, nrm, jt, w);
    kin_skin_lbs(&m, jm, pl, nl);
    kin_skin_dqs(&m, dq, pd, nd);
    for (int k = 0; k < N * 3; k++) {
        NEAR(pd[k], pl[k], 3e-6);
        NEAR(nd[k], nl[k], 3e-6);
    }
}

static void result_translation_blend(void **state)
{
    (void)state;
    /* joints: identity and translate(0,0,1); 50/50 gives (0,0,0.5) */
    float pos[3] = { 1, 2, 3 }, po[3];
    uint16_t jt[4] = { 0, 1, 0, 0 };
    float w[4] = { 0.5f, 0.5f, 0, 0 };
    kin_mat4 jm[2] = { kin_mat4_identity(), kin_mat4_from_tr(kin_v3(0, 0, 1), kin_quat_identity()) };
    kin_dualquat dq[2];
    kin_skin_dq_from_matrices(jm, 2, dq);
    kin_mesh m = mesh_of(1, pos, NULL, jt, w);
    kin_skin_dqs(&m, dq, po, NULL);
    NEAR(po[0], 1, 1e-6); NEAR(po[1], 2, 1e-6); NEAR(po[2], 3.5, 1e-6);
    /* a 90-degree blend about Z through the origin: DQS rotates by 45 */
    jm[1] = kin_mat4_from_tr(kin_v3(0, 0, 0), kin_quat_axis_angle(kin_v3(0, 0, 1), PI_F / 2));
    kin_skin_dq_from_matrices(jm, 2, dq);
    pos[0] = 1; pos[1] = 0; pos[2] = 0;
    kin_skin_dqs(&m, dq, po, NULL);
    NEAR(po[0], sqrtf(0.5f), 1e-6); NEAR(po[1], sqrtf(0.5f), 1e-6);
    /* the same joint given by the antipodal quaternion: the shorter path
     * is still taken (without the sign rule this blend would turn by
     * 45 - 180 degrees) */
    dq[1].r = (kin_quat){ -dq[1].r.x, -dq[1].r.y, -dq[1].r.z, -dq[1].r.w };
    dq[1].d = (kin_quat){ -dq[1].d.x, -dq[1].d.y, -dq[1].d.z, -dq[1].d.w };
    kin_skin_dqs(&m, dq, po, NULL);
    NEAR(po[0], sqrtf(0.5f), 1e-6); NEAR(po[1], sqrtf(0.5f), 1e-6);
}

/* po, no (n vertices) against Kavan's normalised blend in double. */
static void check_kavan(int n, const float *pos, const float *nrm, const uint16_t *jt,
                        const float *w, const kin_dualquat *dq, const float *po,
                        const float *no)
{
    for (int v = 0; v < n; v++) {
        double b[8] = { 0 };
        const float *r0 = NULL;
        for (int i = 0; i < 4; i++) {
            if (w[4 * v + i] == 0.0f) continue;
            const float *q = &dq[jt[4 * v + i]].r.x;
            if (!r0) r0 = q;
            double dot = 0, s = w[4 * v + i];
            for (int e = 0; e < 4; e++) dot += (double)q[e] * r0[e];
            if (dot < 0) s = -s;
            for (int e = 0; e < 8; e++) b[e] += s * q[e];
        }
        double l = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
        for (int e = 0; e < 8; e++) b[e] /= l;
        /* R v = v + 2w (u x v) + 2 u x (u x v); t = 2 (w d.v - d.w u + u x d.v) */
        double u[3] = { b[0], b[1], b[2] }, dv[3] = { b[4], b[5], b[6] }, wr = b[3], dw = b[7];
        double in[2][3], out[2][3];
        for (int c = 0; c < 3; c++) { in[0][c] = pos[3 * v + c]; in[1][c] = nrm[3 * v + c]; }
        for (int s = 0; s < 2; s++) {
            const double *x = in[s];
            double t[3] = { 2 * (u[1] * x[2] - u[2] * x[1]), 2 * (u[2] * x[0] - u[0] * x[2]),
                            2 * (u[0] * x[1] - u[1] * x[0]) };
            double c2[3] = { u[1] * t[2] - u[2] * t[1], u[2] * t[0] - u[0] * t[2],
                             u[0] * t[1] - u[1] * t[0] };
            for (int c = 0; c < 3; c++) out[s][c] = x[c] + wr * t[c] + c2[c];
        }
        double cr[3] = { u[1] * dv[2] - u[2] * dv[1], u[2] * dv[0] - u[0] * dv[2],
                         u[0] * dv[1] - u[1] * dv[0] };
        double nl = 0, nw = 0;
        for (int c = 0; c < 3; c++) {
            double want = out[0][c] + 2 * (wr * dv[c] - dw * u[c] + cr[c]);
            NEAR(po[3 * v + c], want, 4e-6);
            NEAR(no[3 * v + c], out[1][c], 4e-6);
            nl += (double)no[3 * v + c] * no[3 * v + c];
            nw += (double)nrm[3 * v + c] * nrm[3 * v + c];
        }
        NEAR(sqrt(nl), sqrt(nw), 2e-6 * sqrt(nw));   /* rotated, length kept */
    }
}

/* kin_dqs.c skips Kavan's b / |b.r| and the normal's renormalisation
 * (one division per vertex): over seeded blends of 1..4 joints (antipodal
 * signs, unnormalised weights, non-unit normals) the result equals
 * R(b^) p + t(b^) and R(b^) n, b^ = b / |b.r|, evaluated in double from
 * the same blend, and a unit normal stays unit. The weights of a vertex
 * are scaled by one of 1, 1e-10, 1e-19, 3e-20, 1e-21, 1e-23, 1e-30, 2e19,
 * 1e30: k = 2 / |b.r|^2 overflows (or |b.r|^2 under- or overflows) at the
 * ends of that range unless b is rescaled first, and the result must still
 * be the rigid one. On every ISA (the reference and the SIMD kernels). */
static void result_matches_normalised_kavan_in_double(void **state)
{
    (void)state;
    tu_rng g = { 0x64717333 };
    enum { N = 500, J = 6 };
    static float pos[N * 3], nrm[N * 3], w[N * 4], po[N * 3], no[N * 3];
    static uint16_t jt[N * 4];
    kin_dualquat dq[J];
    for (int j = 0; j < J; j++) {
        const kin_vec3 t = tu_v3(&g, -1, 1);   /* drawn in order (tu_kin.h) */
        const kin_quat q = rand_q(&g);
        kin_mat4 m = kin_mat4_from_tr(t, q);
        dq[j] = kin_dualquat_from_mat4(&m);
        if (j % 2) { /* the antipodal form of the same transform */
            float *f = &dq[j].r.x;
            for (int e = 0; e < 8; e++) f[e] = -f[e];
        }
    }
    for (int v = 0; v < N; v++) {
        float len = v % 5 == 0 ? 2.5f : 1.0f;      /* some non-unit normals */
        kin_vec3 n = kin_v3_scale(kin_v3_norm(tu_v3(&g, -1, 1)), len);
        memcpy(nrm + 3 * v, &n, sizeof n);
        for (int c = 0; c < 3; c++) pos[3 * v + c] = tu_range(&g, -1, 1);
        int k = 1 + tu_int(&g, 4);
        for (int i = 0; i < 4; i++) {
            jt[4 * v + i] = (uint16_t)tu_int(&g, J);
            w[4 * v + i] = i < k ? tu_range(&g, 0.1f, 1.0f) : 0.0f;  /* unnormalised */
        }
    }
    static const float scale[] = { 1.0f, 1e-10f, 1e-19f, 3e-20f, 1e-21f, 1e-23f, 1e-30f,
                                   2e19f, 1e30f };
    enum { NS = (int)(sizeof scale / sizeof scale[0]) };
    for (int v = 0; v < N; v++)
        for (int i = 0; i < 4; i++) w[4 * v + i] *= scale[(v / 2) % NS];
    kin_mesh m = mesh_of(N, pos, nrm, jt, w);
    for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
        if (!ef_cpu_has((ef_isa)isa)) continue;
        memset(po, 0xFF, sizeof po);
        memset(no, 0xFF, sizeof no);
        kin_skin_dqs_isa(&m, dq, po, no, isa);
        check_kavan(N, pos, nrm, jt, w, dq, po, no);
    }
}


/* Ring area (shoelace, in its z plane) of K points. */
static double ring_area(const float *p, int k)
{
    double a = 0;
    for (int i = 0; i < k; i++) {
        int j = (i + 1) % k;
        a += (double)p[3 * i] * p[3 * j + 1] - (double)p[3 * j] * p[3 * i + 1];
    }
    return 0.5 * fabs(a);
}

/* A forearm-to-hand tube along -Z, radius 3 cm: 21 rings across the wrist
 * (z = 0) with the hand weight w rising linearly from 0 to 1 over
 * z in [0.05, -0.05]; the hand joint twisted by theta about the bone axis.
 * Each ring's area relative to the bind: LBS |1 - w + w e^(i theta)|^2,
 * DQS 1. The "volume" is the sum over rings. */
static void sweep_wrist_twist_volume(void **state)
{
    (void)state;
    enum { RINGS = 21, K = 64, N = RINGS * K };
    static float pos[N * 3], w[N * 4], pl[N * 3], pd[N * 3];
    static uint16_t jt[N * 4];
    float wr[RINGS];
    for (int r = 0; r < RINGS; r++) {
        float z = 0.05f - 0.1f * (float)r / (RINGS - 1);
        wr[r] = (float)r / (RINGS - 1);
        for (int k = 0; k < K; k++) {
            int v = r * K + k;
            float a = 2.0f * PI_F * (float)k / K;
            pos[3 * v] = 0.03f * cosf(a); pos[3 * v + 1] = 0.03f * sinf(a); pos[3 * v + 2] = z;
            jt[4 * v] = 0; jt[4 * v + 1] = 1; jt[4 * v + 2] = jt[4 * v + 3] = 0;
            w[4 * v] = 1.0f - wr[r]; w[4 * v + 1] = wr[r]; w[4 * v + 2] = w[4 * v + 3] = 0;
        }
    }
    kin_mesh m = mesh_of(N, pos, NULL, jt, w);
    double bind = M_PI * 0.03 * 0.03 * (K / (2.0 * M_PI)) * sin(2.0 * M_PI / K);  /* polygon */
    double worst_lbs = 1.0;
    for (int deg = -180; deg <= 180; deg += 5) {
        float th = (float)deg * PI_F / 180.0f;
        kin_mat4 jm[2] = { kin_mat4_identity(),
                           kin_mat4_from_tr(kin_v3(0, 0, 0), kin_quat_axis_angle(kin_v3(0, 0, 1), th)) };
        kin_dualquat dq[2];
        kin_skin_dq_from_matrices(jm, 2, dq);
        kin_skin_lbs(&m, jm, pl, NULL);
        kin_skin_dqs(&m, dq, pd, NULL);
        double vl = 0, vd = 0, vw = 0;
        for (int r = 0; r < RINGS; r++) {
            double al = ring_area(pl + 3 * r * K, K) / bind, ad = ring_area(pd + 3 * r * K, K) / bind;
            double ww = wr[r];
            double want = 1.0 - 2.0 * ww * (1.0 - ww) * (1.0 - cos((double)th));
            NEAR(al, want, 1e-4);
            NEAR(ad, 1.0, 1e-4);
            vl += al; vd += ad; vw += want;
            for (int k = 0; k < K; k++) {
                assert_true(isfinite(pd[3 * (r * K + k)]));
                NEAR(pd[3 * (r * K + k) + 2], pos[3 * (r * K + k) + 2], 1e-6); /* stays in plane */
            }
        }
        vl /= RINGS; vd /= RINGS; vw /= RINGS;
        NEAR(vl, vw, 1e-4);
        NEAR(vd, 1.0, 1e-4);
        if (vl < worst_lbs) worst_lbs = vl;
        if (deg == 180 || deg == -180) {
            double mid = ring_area(pl + 3 * (RINGS / 2) * K, K) / bind;
            NEAR(mid, 0.0, 1e-4);                      /* LBS collapses at 180 */
        }
    }
    print_message("NOTE wrist twist: LBS keeps %.1f%% of the volume at worst, DQS 100%%\n",
                  100.0 * worst_lbs);
}

int main(void)
{
    int f = 0;
    TU_GROUP(f, "kin_dqs validity",
             cmocka_unit_test(validity_zero_weights_and_no_skin),
             cmocka_unit_test(validity_zero_real_part_keeps_bind_pose));
    TU_GROUP(f, "kin_dqs results",
             cmocka_unit_test(result_dualquat_matches_matrix),
             cmocka_unit_test(result_rigid_vertices_equal_lbs),
             cmocka_unit_test(result_translation_blend),
             cmocka_unit_test(result_matches_normalised_kavan_in_double),
             cmocka_unit_test(sweep_wrist_twist_volume));
    return f ? 1 : 0;
}
