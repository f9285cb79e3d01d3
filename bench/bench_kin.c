/* bench_kin.c - figures and timing of the tracking kinematics (issue 4).
 *
 *   build/bench/bench_kin [--out DIR]
 *
 * Writes into DIR (default bench/out/) CSV files and, when gnuplot is
 * installed, PNG charts:
 *   ik_noise.csv/.png      elbow error of the IK vs tracking noise (raw
 *                          samples and One Euro filtered)
 *   ik_latency.csv/.png    elbow error vs tracking latency, with and
 *                          without prediction to the display time
 *   twist.csv/.png         wrist ring radius error, LBS vs DQS, -180..180
 *   predict.csv/.png       hand position error vs prediction horizon
 * and prints the time of filter + IK + FK + skinning of a 10k-vertex arm
 * per frame: LBS and DQS, each straight from the mesh and through a skin
 * plan built once, side by side on every ISA the CPU runs, for two meshes
 * (joints drawn at random per vertex, the plan's worst case, and a
 * rig-like mesh with vertices in rings along the bones), all in the same
 * run; medians of batches.
 * `--timing-only` (last argument) prints only the timing. Ground truth:
 * an arm of other proportions than the model's, driven by joint angles
 * (not by this IK), seeded noise.
 * Benchmarks report; they never pass or fail. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "../src/cpu/cpu.h"
#include "../src/kin/kin.h"
#include "bench_util.h"

#define PI_F 3.14159265358979f

/* ------------------------------------------------------------ helpers */

typedef struct rng { uint64_t s; } rng;
static double unit(rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return ((double)(z >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}
static float gauss(rng *r)
{
    return (float)(sqrt(-2.0 * log(unit(r))) * cos(2.0 * M_PI * unit(r)));
}
static kin_vec3 noise3(rng *r, float sigma)
{
    return kin_v3(sigma * gauss(r), sigma * gauss(r), sigma * gauss(r));
}
static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The true arm (right side): 0.32 m + 0.28 m, shoulder at S, driven by
 * joint-angle sinusoids: shoulder elevation/azimuth, elbow flexion and a
 * swivel of its own (+-25 deg about a down-and-back pole), the hand along
 * the forearm with some wrist flexion. */
#define TRUE_UPPER 0.32f
#define TRUE_FORE 0.28f
typedef struct truth { kin_vec3 s, e, w; kin_quat hand; } truth;

static truth true_arm(double t)
{
    truth a;
    a.s = kin_v3(0.2f, 1.0f, 0.0f);
    float az = (float)(0.35 * sin(2 * M_PI * 0.31 * t) + 0.15);       /* about Y */
    float el = (float)(-0.25 + 0.45 * sin(2 * M_PI * 0.23 * t + 1));  /* up/down */
    float flex = (float)(1.1 + 0.6 * sin(2 * M_PI * 0.41 * t + 2));
    float sw = (float)(0.45 * sin(2 * M_PI * 0.17 * t + 0.5));
    kin_vec3 du = kin_v3(sinf(az) * cosf(el), sinf(el), -cosf(az) * cosf(el));
    a.e = kin_v3_add(a.s, kin_v3_scale(du, TRUE_UPPER));
    /* the forearm leaves the upper arm's line towards the hinge plane:
     * start with the plane containing "up", swivel it about du */
    kin_vec3 up = kin_v3_norm(kin_v3_sub(kin_v3(0, 1, 0), kin_v3_scale(du, du.y)));
    up = kin_quat_rotate(kin_quat_axis_angle(du, sw), up);
    kin_vec3 df = kin_v3_add(kin_v3_scale(du, cosf(flex)), kin_v3_scale(up, sinf(flex)));
    a.w = kin_v3_add(a.e, kin_v3_scale(df, TRUE_FORE));
    /* hand frame: -Z along the forearm bent by 15 deg towards up, +Y ~ up */
    kin_vec3 fz = kin_v3_norm(kin_v3_add(df, kin_v3_scale(up, 0.27f)));
    kin_vec3 z = kin_v3_scale(fz, -1.0f);
    kin_vec3 y = kin_v3_norm(kin_v3_sub(up, kin_v3_scale(z, kin_v3_dot(up, z))));
    kin_vec3 x = kin_v3_cross(y, z);
    a.hand = kin_quat_from_axes(x, y, z);
    return a;
}

static kin_track_sample sample_of(const truth *a, double t)
{
    kin_track_sample s;
    memset(&s, 0, sizeof s);
    s.t = t;
    s.valid = KIN_TRACK_SHOULDER_R | KIN_TRACK_HAND_R;
    s.head_rot = s.hand_rot[0] = kin_quat_identity();
    s.shoulder[1] = a->s;
    s.hand_pos[1] = a->w;
    s.hand_rot[1] = a->hand;
    return s;
}

static kin_arm_ik_job ik_of(kin_vec3 s, kin_vec3 w, kin_quat hand)
{
    kin_arm_ik_job j;
    memset(&j, 0, sizeof j);
    j.shoulder = s; j.wrist = w; j.hand_rot = hand; j.body_rot = kin_quat_identity();
    j.side = KIN_SIDE_RIGHT; j.upper_len = TRUE_UPPER; j.fore_len = TRUE_FORE;
    return j;
}

/* Mean elbow error (m) over 20 s at 90 Hz: noise sigma (m), latency (s),
 * filter on/off, prediction on/off. */
static double elbow_error(float sigma, double latency, int filter, int predict, uint64_t seed)
{
    rng r = { seed };
    kin_filter f;
    kin_filter_init(&f, NULL);
    double sum = 0;
    int n = 0;
    const double dt = 1.0 / 90.0;
    for (int i = 0; i < 1800; i++) {
        double t = i * dt;                   /* display time */
        double ts = t - latency;             /* what the tracker measured */
        truth a = true_arm(ts);
        kin_track_sample s = sample_of(&a, ts);
        s.hand_pos[1] = kin_v3_add(s.hand_pos[1], noise3(&r, sigma));
        s.shoulder[1] = kin_v3_add(s.shoulder[1], noise3(&r, sigma));
        kin_vec3 ax = kin_v3_norm(noise3(&r, 1.0f));
        s.hand_rot[1] = kin_quat_normalize(
            kin_quat_mul(kin_quat_axis_angle(ax, sigma * 2.0f * gauss(&r)), s.hand_rot[1]));
        kin_track_sample use = s;
        if (filter) {
            kin_filter_push(&f, &s);
            kin_filter_output(&f, predict ? t : ts, &use, NULL);
        }
        kin_arm_ik_job j = ik_of(use.shoulder[1], use.hand_pos[1], use.hand_rot[1]);
        if (!kin_arm_ik_run(&j)) continue;
        if (i < 90) continue;                /* filter warm-up */
        truth now = true_arm(t);
        sum += kin_v3_len(kin_v3_sub(j.elbow, now.e));
        n++;
    }
    return n ? sum / n : NAN;
}

static void gnuplot(const char *dir, const char *name, const char *script)
{
    char path[1024], cmd[2200];
    snprintf(path, sizeof path, "%s/%s.gp", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) return;
    fprintf(f, "cd '%s'\nset terminal pngcairo size 800,500\nset output '%s.png'\nset grid\n"
               "set datafile separator ','\nset key top left\n%s\n", dir, name, script);
    fclose(f);
    snprintf(cmd, sizeof cmd, "gnuplot '%s'", path);
    if (system(cmd) != 0) printf("  (gnuplot failed for %s; CSV written)\n", name);
}

/* The chart DIR/NAME.png of DIR/NAME.csv (gnuplot): the title, the axes'
 * labels, and one curve a column after the first (the x), drawn with
 * style and titled by titles (a list ending in NULL). */
static void plot_csv(const char *dir, const char *name, const char *title, const char *xlabel,
                     const char *ylabel, const char *style, const char *const *titles)
{
    char script[2048];
    size_t n = (size_t)snprintf(script, sizeof script,
                                "set title '%s'\nset xlabel '%s'\nset ylabel '%s'\nplot '%s.csv'",
                                title, xlabel, ylabel, name);
    for (int i = 0; titles[i] && n < sizeof script; i++) /* after the first, '' is the file */
        n += (size_t)snprintf(script + n, sizeof script - n,
                              "%s every ::1 using 1:%d with %s title '%s'", i ? ", ''" : "", i + 2,
                              style, titles[i]);
    gnuplot(dir, name, script);
}

static FILE *csv(const char *dir, const char *name, const char *header)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) { fprintf(stderr, "bench_kin: cannot write %s\n", path); exit(1); }
    fprintf(f, "%s\n", header);
    return f;
}

/* ------------------------------------------------------------- figures */

static void fig_noise(const char *dir)
{
    FILE *f = csv(dir, "ik_noise.csv", "noise_mm,raw_elbow_mm,filtered_elbow_mm");
    printf("elbow error vs tracking noise (no latency), mean mm:\n  noise   raw  filtered\n");
    for (int k = 0; k <= 10; k++) {
        float s = 0.001f * (float)k;
        double raw = elbow_error(s, 0, 0, 0, 11), fil = elbow_error(s, 0, 1, 1, 11);
        fprintf(f, "%d,%.3f,%.3f\n", k, raw * 1e3, fil * 1e3);
        printf("  %3d %7.2f %7.2f\n", k, raw * 1e3, fil * 1e3);
    }
    fclose(f);
    plot_csv(dir, "ik_noise", "Elbow error of the IK vs tracking noise (true arm 0.32+0.28 m)",
             "noise sigma per axis (mm; rotations 2x in mrad)", "mean elbow error (mm)",
             "linespoints", (const char *const[]){"raw samples", "One Euro + prediction", NULL});
}

static void fig_latency(const char *dir)
{
    FILE *f = csv(dir, "ik_latency.csv", "latency_ms,no_prediction_mm,prediction_mm");
    printf("elbow error vs latency (noise 1 mm), mean mm:\n  ms   no pred  pred\n");
    for (int ms = 0; ms <= 100; ms += 10) {
        double a = elbow_error(0.001f, ms * 1e-3, 1, 0, 12), b = elbow_error(0.001f, ms * 1e-3, 1, 1, 12);
        fprintf(f, "%d,%.3f,%.3f\n", ms, a * 1e3, b * 1e3);
        printf("  %3d %8.2f %6.2f\n", ms, a * 1e3, b * 1e3);
    }
    fclose(f);
    plot_csv(dir, "ik_latency", "Elbow error vs tracking latency (noise 1 mm)", "latency (ms)",
             "mean elbow error (mm)", "linespoints",
             (const char *const[]){"filtered, no prediction",
                                   "filtered + prediction to display time", NULL});
}

static void fig_twist(const char *dir)
{
    /* the wrist ring (radius 3 cm) at w = 0.5 between forearm and hand */
    enum { K = 64 };
    float pos[K * 3], w[K * 4], pl[K * 3], pd[K * 3];
    uint16_t jt[K * 4];
    for (int k = 0; k < K; k++) {
        float a = 2.0f * PI_F * (float)k / K;
        pos[3 * k] = 0.03f * cosf(a); pos[3 * k + 1] = 0.03f * sinf(a); pos[3 * k + 2] = 0;
        jt[4 * k] = 0; jt[4 * k + 1] = 1; jt[4 * k + 2] = jt[4 * k + 3] = 0;
        w[4 * k] = w[4 * k + 1] = 0.5f; w[4 * k + 2] = w[4 * k + 3] = 0;
    }
    kin_mesh m;
    memset(&m, 0, sizeof m);
    m.vertex_count = K; m.positions = pos; m.joints = jt; m.weights = w;
    FILE *f = csv(dir, "twist.csv", "twist_deg,lbs_radius_err_mm,dqs_radius_err_mm");
    double worst = 0;
    for (int deg = -180; deg <= 180; deg += 5) {
        kin_mat4 jm[2] = { kin_mat4_identity(),
                           kin_mat4_from_tr(kin_v3(0, 0, 0),
                                            kin_quat_axis_angle(kin_v3(0, 0, 1), (float)deg * PI_F / 180)) };
        kin_dualquat dq[2];
        kin_skin_dq_from_matrices(jm, 2, dq);
        kin_skin_lbs(&m, jm, pl, NULL);
        kin_skin_dqs(&m, dq, pd, NULL);
        double el = 0, ed = 0;
        for (int k = 0; k < K; k++) {
            el = fmax(el, fabs(0.03 - hypot(pl[3 * k], pl[3 * k + 1])));
            ed = fmax(ed, fabs(0.03 - hypot(pd[3 * k], pd[3 * k + 1])));
        }
        worst = fmax(worst, el);
        fprintf(f, "%d,%.4f,%.4f\n", deg, el * 1e3, ed * 1e3);
    }
    fclose(f);
    printf("wrist twist: LBS ring radius error up to %.1f mm (radius 30 mm), DQS 0\n", worst * 1e3);
    plot_csv(dir, "twist", "Wrist ring (r = 30 mm, weights 50/50) under twist: LBS vs DQS",
             "wrist twist (deg)", "radius error (mm)", "lines lw 2",
             (const char *const[]){"LBS", "DQS", NULL});
}

static void fig_predict(const char *dir)
{
    FILE *f = csv(dir, "predict.csv", "horizon_ms,filtered_mm,predict_mm,predict_no_lagcomp_mm");
    printf("hand position error vs prediction horizon (noise 1 mm), mean mm:\n"
           "   ms  filtered  predict  predict(no lag comp)\n");
    for (int hms = 0; hms <= 150; hms += 10) {
        double e[3] = { 0, 0, 0 };
        for (int mode = 0; mode < 3; mode++) {
            rng r = { 99 };
            kin_filter fl;
            /* 0: filtered output at the sample time; 1: predicted with lag
             * compensation; 2: predicted without */
            kin_filter_desc d = { .max_predict_s = 0.2f, .no_lag_comp = mode != 1 };
            kin_filter_init(&fl, &d);
            int n = 0;
            for (int i = 0; i < 1800; i++) {
                double t = i / 90.0;
                truth a = true_arm(t);
                kin_track_sample s = sample_of(&a, t);
                s.hand_pos[1] = kin_v3_add(s.hand_pos[1], noise3(&r, 0.001f));
                kin_filter_push(&fl, &s);
                if (i < 90) continue;
                kin_track_sample o;
                kin_filter_output(&fl, mode == 0 ? t : t + hms * 1e-3, &o, NULL);
                truth b = true_arm(t + hms * 1e-3);
                e[mode] += kin_v3_len(kin_v3_sub(o.hand_pos[1], b.w));
                n++;
            }
            e[mode] /= n;
        }
        fprintf(f, "%d,%.3f,%.3f,%.3f\n", hms, e[0] * 1e3, e[1] * 1e3, e[2] * 1e3);
        printf("  %3d %8.2f %7.2f %7.2f\n", hms, e[0] * 1e3, e[1] * 1e3, e[2] * 1e3);
    }
    fclose(f);
    plot_csv(dir, "predict", "Hand position error vs prediction horizon (90 Hz, noise 1 mm)",
             "horizon (ms)", "mean error (mm)", "linespoints",
             (const char *const[]){"One Euro output, no prediction",
                                   "prediction + lag compensation", "prediction only", NULL});
}

/* -------------------------------------------------------------- timing */

/* A 10k-vertex two-arm skin on a 48-node rig of the generated model's
 * layout; per frame: filter push + output, rig pose (2 IK, 2 hands), FK,
 * joint matrices, skinning. */
typedef struct bench_model {
    kin_model m;
    int16_t parents[48];
    kin_transform rest[48];
    char names[48][KIN_NAME_MAX];
    int src[48], joints[48];
    kin_mat4 ibind[48];
    kin_skin skin;
    kin_mesh mesh;
} bench_model;

static int add_node(bench_model *b, const char *name, int parent, kin_vec3 t)
{
    int i = b->m.node_count++;
    snprintf(b->names[i], KIN_NAME_MAX, "%s", name);
    b->parents[i] = (int16_t)parent;
    b->rest[i] = kin_transform_identity();
    b->rest[i].t = t;
    b->src[i] = i;
    return i;
}

/* The two timed meshes of NV vertices on the bench rig (world: its rest
 * pose). m[0] "random": each vertex 2 cm around a joint drawn at random,
 * influences (joint, parent) with a random split: the skin plan's worst
 * case (every batch scattered). m[1] "rig": as a real rig, the vertices
 * of each bone in rings along it, in vertex order (bone by bone), radius
 * 2-3 cm, weights by the position t along the bone: (parent 1-t, joint t)
 * listed by decreasing weight, the parent alone over the first 10%. */
static void bench_meshes(const bench_model *b, const kin_mat4 *world, float *pos, float *nrm,
                         uint16_t *jt, float *wt, float *pos2, float *nrm2, uint16_t *jt2,
                         float *wt2, int nv, kin_mesh m[2])
{
    const int nn = b->m.node_count;
    rng r = { 5 };
    for (int v = 0; v < nv; v++) {
        int j = 2 + (int)(unit(&r) * (nn - 2));
        int p = b->parents[j] >= 0 ? b->parents[j] : j;
        kin_vec3 c = kin_v3(world[j].m[12], world[j].m[13], world[j].m[14]);
        kin_vec3 n = kin_v3_norm(noise3(&r, 1.0f));
        kin_vec3 x = kin_v3_add(c, kin_v3_scale(n, 0.02f));
        memcpy(pos + 3 * v, &x, 12);
        memcpy(nrm + 3 * v, &n, 12);
        float a = (float)unit(&r);
        jt[4 * v] = (uint16_t)j; jt[4 * v + 1] = (uint16_t)p; jt[4 * v + 2] = jt[4 * v + 3] = 0;
        wt[4 * v] = a; wt[4 * v + 1] = 1 - a; wt[4 * v + 2] = wt[4 * v + 3] = 0;
    }
    /* bones: nodes 2.. with a parent (the arm and finger joints) */
    const int bones = nn - 2;
    for (int v = 0; v < nv; v++) {
        int bi = (int)((long long)v * bones / nv);
        int v0 = (int)(((long long)bi * nv + bones - 1) / bones);
        int v1 = (int)(((long long)(bi + 1) * nv + bones - 1) / bones);
        int j = 2 + bi, p = b->parents[j] >= 0 ? b->parents[j] : j;
        float t = (float)(v - v0) / (float)(v1 - v0);
        kin_vec3 P = kin_v3(world[p].m[12], world[p].m[13], world[p].m[14]);
        kin_vec3 C = kin_v3(world[j].m[12], world[j].m[13], world[j].m[14]);
        kin_vec3 ax = kin_v3_sub(C, P);
        if (kin_v3_len(ax) == 0.0f) ax = kin_v3(0, 0, -1);
        kin_vec3 e1 = kin_v3_norm(kin_v3_cross(ax, fabsf(ax.y) < 0.9f * kin_v3_len(ax)
                                                       ? kin_v3(0, 1, 0) : kin_v3(1, 0, 0)));
        kin_vec3 e2 = kin_v3_norm(kin_v3_cross(ax, e1));
        float ang = 2.0f * PI_F * (float)((v - v0) % 16) / 16.0f;
        kin_vec3 n = kin_v3_add(kin_v3_scale(e1, cosf(ang)), kin_v3_scale(e2, sinf(ang)));
        float rad = 0.02f + 0.01f * (float)unit(&r);
        kin_vec3 x = kin_v3_add(kin_v3_add(P, kin_v3_scale(ax, t)), kin_v3_scale(n, rad));
        memcpy(pos2 + 3 * v, &x, 12);
        memcpy(nrm2 + 3 * v, &n, 12);
        uint16_t *J = jt2 + 4 * v;
        float *w = wt2 + 4 * v;
        J[2] = J[3] = 0; w[2] = w[3] = 0;
        if (t < 0.1f) {
            J[0] = (uint16_t)p; J[1] = (uint16_t)j; w[0] = 1; w[1] = 0;
        } else if (t < 0.5f) {
            J[0] = (uint16_t)p; J[1] = (uint16_t)j; w[0] = 1 - t; w[1] = t;
        } else {
            J[0] = (uint16_t)j; J[1] = (uint16_t)p; w[0] = t; w[1] = 1 - t;
        }
    }
    for (int k = 0; k < 2; k++) {
        memset(&m[k], 0, sizeof m[k]);
        m[k].vertex_count = nv;
        m[k].positions = k ? pos2 : pos;
        m[k].normals = k ? nrm2 : nrm;
        m[k].joints = k ? jt2 : jt;
        m[k].weights = k ? wt2 : wt;
    }
}

static void timing(void)
{
    static bench_model b;
    memset(&b, 0, sizeof b);
    b.m.parents = b.parents; b.m.rest = b.rest; b.m.node_src = b.src;
    b.m.names = (const char(*)[KIN_NAME_MAX])b.names;
    int body = add_node(&b, "body", -1, kin_v3(0, 1, 0));
    add_node(&b, "head", body, kin_v3(0, 0.25f, -0.08f));
    char nm[KIN_NAME_MAX];
    for (int s = 0; s < 2; s++) {
        float sx = s ? 1.0f : -1.0f;
        kin_vec3 off[5] = { kin_v3(0.035f * sx, -0.015f, 0), kin_v3(0.155f * sx, -0.015f, 0),
                            kin_v3(0, 0, -0.3f), kin_v3(0, 0, -0.26f), kin_v3(0, 0, -0.03f) };
        int J[KIN_RIG_SIDE_JOINTS];
        for (int j = 0; j < 5; j++)
            J[j] = add_node(&b, kin_arm_rig_joint_name((kin_side)s, j, nm, sizeof nm),
                            j ? J[j - 1] : body, off[j]);
        for (int fi = 0; fi < 5; fi++)
            for (int q = 0; q < 3; q++) {
                int j = KIN_RIG_FINGER0 + 3 * fi + q;
                J[j] = add_node(&b, kin_arm_rig_joint_name((kin_side)s, j, nm, sizeof nm),
                                q ? J[j - 1] : J[KIN_RIG_PALM],
                                q ? kin_v3(0, 0, -0.03f) : kin_v3(0.02f * (float)(fi - 2), 0, -0.07f));
            }
    }
    kin_arm_rig rig;
    char why[256];
    if (kin_arm_rig_init(&rig, &b.m, why, sizeof why)) { printf("rig: %s\n", why); return; }
    int nn = b.m.node_count;
    kin_transform loc[48];
    kin_mat4 world[48], jm[48];
    kin_dualquat dq[48];
    kin_pose_rest(&b.m, loc);
    kin_fk(b.m.parents, nn, loc, NULL, world);
    for (int i = 0; i < nn; i++) { b.joints[i] = i; kin_mat4_inverse(&world[i], &b.ibind[i]); }
    b.skin.joint_count = nn; b.skin.joints = b.joints; b.skin.inverse_bind = b.ibind;
    enum { NV = 10000 };
    static float pos[NV * 3], nrm[NV * 3], wt[NV * 4], po[NV * 3], no[NV * 3];
    static uint16_t jt[NV * 4];
    /* the skin plans: built once per mesh (not timed) */
    kin_skin_plan plan[2];
    void *plan_mem[2] = { NULL, NULL };
    kin_mesh m[2];
    static float pos2[NV * 3], nrm2[NV * 3], wt2[NV * 4];
    static uint16_t jt2[NV * 4];
    bench_meshes(&b, world, pos, nrm, jt, wt, pos2, nrm2, jt2, wt2, NV, m);
    static const char *const mesh_name[2] = {
        "random: each vertex near a random joint, 2 influences drawn per vertex",
        "rig: vertices in rings along the bones in vertex order, weights by position"
    };
    for (int k = 0; k < 2; k++) {
        size_t ns = kin_skin_plan_scratch_size(&m[k]);
        void *scratch = malloc(ns);
        size_t plan_bytes = scratch ? kin_skin_plan_size(&m[k], scratch) : 0;
        plan_mem[k] = plan_bytes ? aligned_alloc(64, (plan_bytes + 63) & ~(size_t)63) : NULL;
        int rc = plan_mem[k] ? kin_skin_plan_init(&plan[k], &m[k], scratch, plan_mem[k], plan_bytes) : -1;
        free(scratch);
        if (rc) {
            printf("skin plan: out of memory\n");
            free(plan_mem[0]);
            free(plan_mem[1]);
            return;
        }
        printf("mesh %s:\n  skin plan: %d joint lists, %d batches of 16 (%.0f%% lanes used, "
               "%d contiguous), %zu bytes\n", mesh_name[k], plan[k].group_count,
               plan[k].batch_count, 100.0 * NV / (16.0 * plan[k].batch_count),
               kin_skin_plan_contiguous(&plan[k]), plan_bytes);
    }
    kin_filter f;
    kin_filter_init(&f, NULL);
    /* per configuration: 21 batches of 100 frames (10 for the scalar
     * reference), the median batch (the machine is shared: medians, not
     * means); every configuration in the same run */
    enum { BATCHES = 21, FRAMES = 100 };
    printf("per frame, filter + rig IK + hands + FK + joint matrices + skinning, %d vertices "
           "with normals, %d nodes; ms, median (min) of %d batches:\n", NV, nn, BATCHES);
    int frame_no = 0;
    static const char *const what[5] = { "no skinning", "LBS from the mesh", "LBS plan",
                                         "DQS from the mesh", "DQS plan" };
    for (int k = 0; k < 2; k++) {
        printf("  %-24s", k ? "rig mesh" : "random mesh");
        for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++)
            if (ef_cpu_has((ef_isa)isa)) printf(" %-17s", ef_isa_name((ef_isa)isa));
        printf("\n");
        /* modes: no skinning, LBS, LBS with the plan, DQS, DQS with the plan */
        for (int mode = k ? 1 : 0; mode < 5; mode++) {
            printf("    %-22s", what[mode]);
            for (int isa = EF_ISA_REF; isa < EF_ISA_COUNT; isa++) {
                if (mode == 0 && isa > EF_ISA_REF) break;
                if (!ef_cpu_has((ef_isa)isa)) continue;
                const int frames = isa == EF_ISA_REF && mode ? FRAMES / 10 : FRAMES;
                double batch[BATCHES];
                for (int bi = 0; bi < BATCHES; bi++) {
                    double t0 = now_s();
                    for (int i = 0; i < frames; i++, frame_no++) {
                        double t = frame_no / 90.0;
                        truth a = true_arm(t);
                        kin_track_sample s = sample_of(&a, t);
                        s.valid = KIN_TRACK_ALL;
                        s.shoulder[0] = kin_v3(-0.2f, 1.0f, 0.0f);
                        s.hand_pos[0] = kin_v3(-0.25f, 0.9f, -0.35f);
                        s.hand_rot[0] = kin_quat_identity();
                        s.head_pos = kin_v3(0, 1.25f, -0.08f);
                        s.head_rot = kin_quat_identity();
                        for (int g = 0; g < 5; g++) s.glove[0][g] = s.glove[1][g] = 0.5f;
                        kin_filter_push(&f, &s);
                        kin_track_sample o;
                        kin_filter_output(&f, t + 0.02, &o, NULL);
                        kin_arm_rig_pose(&rig, &b.m, NULL, NULL, &o, loc, NULL);
                        kin_fk(b.m.parents, nn, loc, NULL, world);
                        kin_skin_joint_matrices(&b.skin, world, jm);
                        if (mode == 1) kin_skin_lbs_isa(&m[k], jm, po, no, isa);
                        else if (mode == 2) kin_skin_lbs_plan_part(&plan[k], jm, po, no, 0, 1, isa);
                        else if (mode >= 3) {
                            kin_skin_dq_from_matrices(jm, nn, dq);
                            if (mode == 3) kin_skin_dqs_isa(&m[k], dq, po, no, isa);
                            else kin_skin_dqs_plan_part(&plan[k], dq, po, no, 0, 1, isa);
                        }
                    }
                    batch[bi] = (now_s() - t0) * 1e3 / frames;
                }
                qsort(batch, BATCHES, sizeof batch[0], bench_cmp_double);
                char cell[40];
                snprintf(cell, sizeof cell, "%.4f (%.4f)", batch[BATCHES / 2], batch[0]);
                printf(" %-17s", cell);
                fflush(stdout);
            }
            printf("\n");
        }
    }
    printf("  skinning uses %s by default (kin_skin_isa)\n", ef_isa_name((ef_isa)kin_skin_isa()));
    free(plan_mem[0]);
    free(plan_mem[1]);
}

int main(int argc, char **argv)
{
    const char *dir = "bench/out";
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--out") && i + 1 < argc) dir = argv[++i];
    mkdir(dir, 0755);
#if defined(__clang__)
    printf("compiler: clang %s\n", __clang_version__);
#elif defined(__GNUC__)
    printf("compiler: gcc %s\n", __VERSION__);
#endif
    printf("flags: -ffp-contract=off; output: %s/\n", dir);
    if (argc > 1 && !strcmp(argv[argc - 1], "--timing-only")) { timing(); return 0; }
    fig_noise(dir);
    fig_latency(dir);
    fig_twist(dir);
    fig_predict(dir);
    timing();
    return 0;
}
