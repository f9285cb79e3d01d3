/* test_kin_lens.c - the lens models of kin_lens.c against OpenCV's
 * published formulas (cv::projectPoints for Brown-Conrady, cv::fisheye for
 * Kannala-Brandt), written here a second time, independently and
 * literally, from OpenCV's documentation; against constants computed by
 * hand (python, the same documented formulas); the round trips
 * unproject(project(p)) on a generated checkerboard and over every pixel
 * grid point; the fold (valid region); the pinhole against kin_camera; bad
 * lenses. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"
#include "../src/kin/kin_lens.h"

#define PI_D 3.14159265358979323846

/* --------------------------------------- OpenCV's formulas, literally */

/* cv::projectPoints (calib3d docs, "Detailed Description"), a point in
 * OpenCV's camera frame, distCoeffs (k1,k2,p1,p2[,k3[,k4,k5,k6[,s1..s4]]]). */
static void cv_project(const double K[4], const double *d, int nd, const double P[3],
                       double *u, double *v)
{
    double c[12] = {0};
    for (int i = 0; i < nd; i++) c[i] = d[i];
    double k1 = c[0], k2 = c[1], p1 = c[2], p2 = c[3], k3 = c[4], k4 = c[5], k5 = c[6],
           k6 = c[7], s1 = c[8], s2 = c[9], s3 = c[10], s4 = c[11];
    double xp = P[0] / P[2], yp = P[1] / P[2];
    double r2 = xp * xp + yp * yp, r4 = r2 * r2, r6 = r4 * r2;
    double rad = (1 + k1 * r2 + k2 * r4 + k3 * r6) / (1 + k4 * r2 + k5 * r4 + k6 * r6);
    double xpp = xp * rad + 2 * p1 * xp * yp + p2 * (r2 + 2 * xp * xp) + s1 * r2 + s2 * r4;
    double ypp = yp * rad + p1 * (r2 + 2 * yp * yp) + 2 * p2 * xp * yp + s3 * r2 + s4 * r4;
    *u = K[0] * xpp + K[2];
    *v = K[1] * ypp + K[3];
}

/* cv::fisheye (calib3d "Fisheye camera model"): a = x/z, b = y/z,
 * r^2 = a^2 + b^2, theta = atan(r), theta_d = theta (1 + k1 theta^2 + k2
 * theta^4 + k3 theta^6 + k4 theta^8), x' = (theta_d / r) a, y' likewise,
 * u = fx (x' + alpha y') + cx, v = fy y' + cy. */
static void cv_fisheye(const double K[4], double alpha, const double k[4], const double P[3],
                       double *u, double *v)
{
    double a = P[0] / P[2], b = P[1] / P[2];
    double r = sqrt(a * a + b * b), th = atan(r);
    double th2 = th * th, th4 = th2 * th2, th6 = th4 * th2, th8 = th4 * th4;
    double thd = th * (1 + k[0] * th2 + k[1] * th4 + k[2] * th6 + k[3] * th8);
    double xp = (thd / r) * a, yp = (thd / r) * b;
    *u = K[0] * (xp + alpha * yp) + K[2];
    *v = K[1] * yp + K[3];
}

/* OpenCV camera frame -> egofuse view space. */
static void to_ego(const double P[3], double p[3])
{
    p[0] = P[0];
    p[1] = -P[1];
    p[2] = -P[2];
}

/* A lens of the model with K = {fx, fy, cx, cy}, skew, nk coefficients
 * k and the image size; kin_lens_check must accept it. */
static kin_lens make_lens(kin_lens_model model, const double K[4], double skew,
                          const double *k, int nk, int w, int h)
{
    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = model;
    L.width = w;
    L.height = h;
    L.fx = K[0];
    L.fy = K[1];
    L.cx = K[2];
    L.cy = K[3];
    L.skew = skew;
    for (int i = 0; i < nk; i++) L.k[i] = k[i];
    char why[200];
    if (!kin_lens_check(&L, why, sizeof why)) fail_msg("lens refused: %s", why);
    return L;
}

static kin_lens brown_lens(const double K[4], const double *d, int nd, int w, int h)
{
    return make_lens(KIN_LENS_BROWN, K, 0.0, d, nd, w, h);
}

static kin_lens fisheye_lens(const double K[4], double alpha, const double *k, int w, int h)
{
    return make_lens(KIN_LENS_FISHEYE, K, alpha * K[0], k, 4, w, h);
}

/* A realistic narrow lens (Brown, 5 coefficients, VGA). */
static const double K_B[4] = {600.0, 610.0, 319.5, 239.5};
static const double D_B[5] = {-0.28, 0.07, 0.001, -0.002, -0.01};
/* The rational model with thin prism (12 coefficients). */
static const double K_R[4] = {820.0, 818.0, 640.3, 401.7};
static const double D_R[12] = {0.9, -0.2, 0.0012, -0.0007, 0.05, 1.2, 0.1, 0.01,
                               0.0005, -0.0002, 0.0003, 0.0001};
/* A wide fisheye (about 165 degrees), coefficients of the size a
 * tracking camera's calibration has. */
static const double K_F[4] = {285.7, 285.9, 420.1, 403.9};
static const double D_F[4] = {-0.0077, 0.0437, -0.0413, 0.0072};

/* ------------------------------------------------------------ results */

/* A checkerboard 9x6, 40 mm squares, tilted in front of the camera, in
 * OpenCV's frame: its corners. */
static int checkerboard(double pts[][3], double tilt_deg, double dist)
{
    int n = 0;
    double a = tilt_deg * PI_D / 180.0;
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 9; i++) {
            double x = (i - 4) * 0.04, y = (j - 2.5) * 0.04;
            pts[n][0] = x * cos(a);
            pts[n][1] = y;
            pts[n][2] = dist + x * sin(a);
            n++;
        }
    return n;
}

/* The corners of three checkerboards (checkerboard()), board k tilted
 * tilt0 + k dtilt degrees at the distance dist0 + k ddist, into pts (in
 * OpenCV's frame, 3 x 54 at most); returns their number. */
static int three_boards(double pts[][3], double tilt0, double dtilt, double dist0, double ddist)
{
    int n = 0;
    for (int pose = 0; pose < 3; pose++)
        n += checkerboard(pts + n, tilt0 + dtilt * pose, dist0 + ddist * pose);
    return n;
}

/* L projects the point P (OpenCV's frame) to OpenCV's pixel (eu, ev) moved
 * to the pixel centre (+ 0.5), within 1e-9 px. */
static void expect_pixel(const kin_lens *L, const double P[3], double eu, double ev)
{
    double p[3], u, v;
    to_ego(P, p);
    assert_true(kin_lens_project(L, p, &u, &v));
    NEAR(u, eu + 0.5, 1e-9);
    NEAR(v, ev + 0.5, 1e-9);
}

static void result_brown_matches_opencv_formula(void **state)
{
    (void)state;
    /* the 5- and the 12-coefficient models */
    static const struct { const double *K, *D; int nd, w, h; } lens[2] = {
        { K_B, D_B, 5, 640, 480 },
        { K_R, D_R, 12, 1280, 800 },
    };
    kin_lens L[2];
    for (int c = 0; c < 2; c++)
        L[c] = brown_lens(lens[c].K, lens[c].D, lens[c].nd, lens[c].w, lens[c].h);
    double pts[3 * 54][3];
    const int n = three_boards(pts, -30.0, 30.0, 0.35, 0.1);
    for (int i = 0; i < n; i++)
        for (int c = 0; c < 2; c++) {
            double eu, ev;
            cv_project(lens[c].K, lens[c].D, lens[c].nd, pts[i], &eu, &ev);
            expect_pixel(&L[c], pts[i], eu, ev);
        }
}

static void result_fisheye_matches_opencv_formula(void **state)
{
    (void)state;
    const double alpha = 0.002;
    kin_lens L = fisheye_lens(K_F, alpha, D_F, 848, 800);
    double pts[3 * 54][3];
    const int n = three_boards(pts, -50.0, 50.0, 0.2, 0.05);
    for (int i = 0; i < n; i++) {
        double eu, ev;
        cv_fisheye(K_F, alpha, D_F, pts[i], &eu, &ev);
        expect_pixel(&L, pts[i], eu, ev);
        /* and the normalized building block */
        double xd, yd;
        assert_true(kin_lens_distort(&L, pts[i][0] / pts[i][2], pts[i][1] / pts[i][2], &xd, &yd));
        NEAR(L.fx * xd + L.skew * yd + L.cx, eu, 1e-9);
    }
}

/* Each of the three cases {x, y, z, u, v}: the point projects to pixel
 * centre (u, v) within 1e-9 px. */
static void check_projections(const kin_lens *L, const double cases[3][5])
{
    for (int i = 0; i < 3; i++) {
        double p[3], u, v;
        to_ego(cases[i], p);
        assert_true(kin_lens_project(L, p, &u, &v));
        NEAR(u - 0.5, cases[i][3], 1e-9);
        NEAR(v - 0.5, cases[i][4], 1e-9);
    }
}

/* Constants computed by hand (python, from the documented formulas), and
 * one that fits on paper: k1 = -0.3 at x = 0.5: 0.5 (1 - 0.3 * 0.25) = 0.4625. */
static void result_hand_computed_values(void **state)
{
    (void)state;
    kin_lens L = brown_lens(K_B, D_B, 5, 640, 480);
    static const double cases[3][5] = {
        {0.1, 0.05, 1.0, 379.257655078125, 269.8920579980469},
        {-0.3, 0.2, 0.8, 105.97214069366456, 384.18313589096067},
        {0.25, -0.4, 1.5, 416.5599304951989, 81.48313750558759},
    };
    check_projections(&L, cases);
    kin_lens F = fisheye_lens(K_F, 0.0, D_F, 848, 800);
    static const double fe[3][5] = {
        {0.1, 0.05, 1.0, 448.54931621034063, 418.1346158637318},
        {-1.0, 0.5, 0.6, 145.01457943669863, 541.5389949930834},
        {0.7, -0.9, 0.3, 643.2334219984975, 116.8133415949128},
    };
    check_projections(&F, fe);
    const double K1[4] = {100, 100, 0, 0}, d1[1] = {-0.3};
    kin_lens S = brown_lens(K1, d1, 1, 0, 0);
    double xd, yd;
    assert_true(kin_lens_distort(&S, 0.5, 0.0, &xd, &yd));
    NEAR(xd, 0.4625, 1e-15);
    NEAR(yd, 0.0, 0);
}

/* unproject(project(p)) is p's direction, and project(unproject(u, v)) is
 * (u, v) within 1e-4 px, for every lens, on the checkerboards and on a
 * grid over the whole image. */
static void check_round_trips(const kin_lens *L, double depth0, double tilt)
{
    double pts[54][3];
    int n = checkerboard(pts, tilt, depth0);
    for (int i = 0; i < n; i++) {
        double p[3], u, v, ray[3], u2, v2;
        to_ego(pts[i], p);
        assert_true(kin_lens_project(L, p, &u, &v));
        assert_true(kin_lens_unproject(L, u, v, ray));
        double np = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        for (int k = 0; k < 3; k++) NEAR(ray[k], p[k] / np, 1e-9);
        assert_true(kin_lens_project(L, ray, &u2, &v2));
        NEAR(u2, u, 1e-4);
        NEAR(v2, v, 1e-4);
    }
    int misses = 0;
    for (int y = 0; y <= L->height; y += 8)
        for (int x = 0; x <= L->width; x += 8) {
            double ray[3], u, v;
            if (!kin_lens_unproject(L, x, y, ray)) {
                misses++;
                continue;
            }
            NEAR(ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2], 1.0, 1e-12);
            assert_true(kin_lens_project(L, ray, &u, &v));
            NEAR(u, x, 1e-4);
            NEAR(v, y, 1e-4);
        }
    assert_int_equal(misses, 0); /* every lens here is valid over its image */
}

static void result_round_trips(void **state)
{
    (void)state;
    kin_lens B = brown_lens(K_B, D_B, 5, 640, 480);
    kin_lens R = brown_lens(K_R, D_R, 12, 1280, 800);
    kin_lens F = fisheye_lens(K_F, 0.002, D_F, 848, 800);
    kin_lens P = kin_lens_pinhole(640, 480, 62.0);
    check_round_trips(&B, 0.4, 20.0);
    check_round_trips(&R, 0.5, -20.0);
    check_round_trips(&F, 0.15, 45.0);
    check_round_trips(&P, 0.5, 10.0);
    /* the fisheye beyond 90 degrees: a ray 100 degrees off the axis */
    double a = 100.0 * PI_D / 180.0, p[3] = {sin(a), 0.0, -cos(a)}, u, v, ray[3];
    assert_true(F.theta_max > a);
    assert_true(kin_lens_project(&F, p, &u, &v));
    assert_true(kin_lens_unproject(&F, u, v, ray));
    for (int k = 0; k < 3; k++) NEAR(ray[k], p[k], 1e-9);
    /* seeded random pixels of the fisheye's image circle */
    tu_rng g = {0x6c656e73};
    for (int i = 0; i < 2000; i++) {
        double uu = tu_range(&g, 0, 848), vv = tu_range(&g, 0, 800), u2, v2;
        assert_true(kin_lens_unproject(&F, uu, vv, ray));
        assert_true(kin_lens_project(&F, ray, &u2, &v2));
        NEAR(u2, uu, 1e-4);
        NEAR(v2, vv, 1e-4);
    }
}

/* The pinhole lens is kin_camera's model: u = cx + fx X/-Z with
 * kin_camera's cx = lens cx + 0.5. */
static void result_pinhole_is_kin_camera(void **state)
{
    (void)state;
    kin_lens P = kin_lens_pinhole(640, 480, 62.0);
    kin_camera c = kin_sthmd_camera(NULL, NULL, KIN_EYE_LEFT);
    NEAR(P.fx, c.fx, 1e-4);
    NEAR(P.cx + 0.5, c.cx, 0);
    NEAR(P.cy + 0.5 - 40.0, c.cy, 0); /* the crop of eq. 1 keeps rows 40.. */
    kin_lens C = kin_lens_cropped(&P, 0, 40, 640, 400);
    tu_rng g = {0x70696e68};
    for (int i = 0; i < 200; i++) {
        double p[3], u, v; /* drawn in a defined order */
        p[0] = tu_range(&g, -1, 1);
        p[1] = tu_range(&g, -1, 1);
        p[2] = tu_range(&g, -5, -0.3f);
        assert_true(kin_lens_project(&C, p, &u, &v));
        NEAR(u, c.cx + c.fx * p[0] / -p[2], 2e-3);
        NEAR(v, c.cy - c.fy * p[1] / -p[2], 2e-3);
    }
    assert_false(kin_lens_distorts(&P));
    double p[3] = {0, 0, 1}, u = 7, v = 7;
    assert_false(kin_lens_project(&P, p, &u, &v)); /* behind */
    NEAR(u, 7, 0);
}

/* A crop and a scale move pixels as they should. */
static void result_scaled_and_cropped(void **state)
{
    (void)state;
    kin_lens B = brown_lens(K_B, D_B, 5, 640, 480);
    kin_lens H = kin_lens_scaled(&B, 1280, 960);
    kin_lens C = kin_lens_cropped(&B, 0, 40, 640, 400);
    tu_rng g = {0x7363616c};
    for (int i = 0; i < 200; i++) {
        double p[3]; /* drawn in a defined order */
        p[0] = tu_range(&g, -0.3f, 0.3f);
        p[1] = tu_range(&g, -0.3f, 0.3f);
        p[2] = tu_range(&g, -2, -0.5f);
        double u, v, uh, vh, uc, vc;
        assert_true(kin_lens_project(&B, p, &u, &v));
        assert_true(kin_lens_project(&H, p, &uh, &vh));
        assert_true(kin_lens_project(&C, p, &uc, &vc));
        NEAR(uh, 2 * u, 1e-9); /* edges scale: the pixel-edge positions double */
        NEAR(vh, 2 * v, 1e-9);
        NEAR(uc, u, 1e-9);
        NEAR(vc, v - 40, 1e-9);
    }
}

/* Where the model folds: k1 = -0.5 alone: d/dr (r - 0.5 r^3) = 0 at
 * r = sqrt(2/3); the fisheye with k1 = -0.2: 1 - 0.6 theta^2 = 0 at
 * theta = sqrt(1/0.6). Nothing beyond is projected or unprojected. */
static void result_fold(void **state)
{
    (void)state;
    const double K[4] = {500, 500, 319.5, 239.5}, d[1] = {-0.5}, f[4] = {-0.2, 0, 0, 0};
    kin_lens B = brown_lens(K, d, 1, 640, 480);
    NEAR(B.r_max, sqrt(2.0 / 3.0), 1e-9);
    NEAR(B.rd_max, sqrt(2.0 / 3.0) * (1 - 0.5 * 2.0 / 3.0), 1e-9);
    double u, v, ray[3], x, y;
    double in[3] = {0.8, 0, -1}, out[3] = {0.83, 0, -1};
    assert_true(kin_lens_project(&B, in, &u, &v));
    assert_false(kin_lens_project(&B, out, &u, &v));
    /* a pixel whose distorted radius exceeds the fold's image */
    assert_false(kin_lens_unproject(&B, 319.5 + 0.5 + 500 * 0.546, 240, ray));
    assert_true(kin_lens_unproject(&B, 319.5 + 0.5 + 500 * 0.54, 240, ray));
    assert_true(ray[0] / -ray[2] < sqrt(2.0 / 3.0)); /* the inner sheet */
    assert_false(kin_lens_undistort(&B, 0.6, 0.0, &x, &y));
    kin_lens F = fisheye_lens(K, 0.0, f, 640, 480);
    NEAR(F.theta_max, sqrt(1.0 / 0.6), 1e-9);
    double a = 1.2, b = 1.35;
    double pa[3] = {sin(a), 0, -cos(a)}, pb[3] = {sin(b), 0, -cos(b)};
    assert_true(kin_lens_project(&F, pa, &u, &v));
    assert_false(kin_lens_project(&F, pb, &u, &v));
}

static void validity_bad_lenses(void **state)
{
    (void)state;
    char why[200];
    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = KIN_LENS_BROWN;
    L.fx = 0;
    L.fy = 500;
    assert_false(kin_lens_check(&L, why, sizeof why));
    assert_non_null(strstr(why, "fx"));
    L.fx = 500;
    L.cx = NAN;
    assert_false(kin_lens_check(&L, why, sizeof why));
    assert_non_null(strstr(why, "cx"));
    L.cx = 100;
    L.k[3] = INFINITY;
    assert_false(kin_lens_check(&L, why, sizeof why));
    assert_non_null(strstr(why, "coefficient 3"));
    L.k[3] = 0;
    L.k[0] = 5.0;
    L.k[5] = -20.0; /* the rational denominator reaches zero near r = 0.22 */
    if (!kin_lens_check(&L, why, sizeof why)) fail_msg("%s", why);
    assert_true(L.r_max < sqrt(1.0 / 20.0) + 1e-9);
    L.model = KIN_LENS_FISHEYE;
    assert_false(kin_lens_check(&L, why, sizeof why));
    assert_non_null(strstr(why, "4 distortion"));
    memset(L.k, 0, sizeof L.k);
    L.k[0] = -1e7;
    assert_false(kin_lens_check(&L, why, sizeof why));
    assert_non_null(strstr(why, "folds"));
    L.k[0] = 0;
    L.width = 640;
    assert_false(kin_lens_check(&L, why, sizeof why));
    assert_non_null(strstr(why, "size"));
    L.model = (kin_lens_model)7;
    assert_false(kin_lens_check(&L, why, sizeof why));
}

TU_MAIN_NAMED("kin_lens", NULL, NULL,
              cmocka_unit_test(result_brown_matches_opencv_formula),
              cmocka_unit_test(result_fisheye_matches_opencv_formula),
              cmocka_unit_test(result_hand_computed_values),
              cmocka_unit_test(result_round_trips),
              cmocka_unit_test(result_pinhole_is_kin_camera),
              cmocka_unit_test(result_scaled_and_cropped),
              cmocka_unit_test(result_fold),
              cmocka_unit_test(validity_bad_lenses))
