/* kin_lens.c - pinhole, Brown-Conrady and Kannala-Brandt fisheye lenses
 * (kin_lens.h: the formulas, the conventions, the valid region and the
 * convergence criterion). */
#include "kin_lens.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define PI_D 3.14159265358979323846
/* Scan step of the fold search: fine enough that a fold cannot hide
 * between two samples for any lens a calibration produces. */
#define FOLD_STEPS 20000

static int fail(char *why, int why_size, const char *fmt, ...)
{
    if (why && why_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(why, (size_t)why_size, fmt, ap);
        va_end(ap);
    }
    return 0;
}

/* ------------------------------------------------------------ Brown */

/* Radial factor R(s) = num/den at s = r^2, its derivative dR/ds, and the
 * denominator (the caller checks it stays positive). */
static void brown_radial(const double *k, double s, double *R, double *dR, double *den_out)
{
    double num = 1.0 + s * (k[0] + s * (k[1] + s * k[4]));
    double den = 1.0 + s * (k[5] + s * (k[6] + s * k[7]));
    double dnum = k[0] + s * (2.0 * k[1] + s * 3.0 * k[4]);
    double dden = k[5] + s * (2.0 * k[6] + s * 3.0 * k[7]);
    *R = num / den;
    if (dR) *dR = (dnum * den - num * dden) / (den * den);
    if (den_out) *den_out = den;
}

/* The distortion map and (if J) its Jacobian J = [dxd/dx dxd/dy; dyd/dx dyd/dy]. */
static void brown_map(const double *k, double x, double y, double *xd, double *yd, double J[4])
{
    const double p1 = k[2], p2 = k[3], s1 = k[8], s2 = k[9], s3 = k[10], s4 = k[11];
    double s = x * x + y * y, R, dR;
    brown_radial(k, s, &R, &dR, NULL);
    *xd = x * R + 2.0 * p1 * x * y + p2 * (s + 2.0 * x * x) + s1 * s + s2 * s * s;
    *yd = y * R + p1 * (s + 2.0 * y * y) + 2.0 * p2 * x * y + s3 * s + s4 * s * s;
    if (J) {
        double px = s1 + 2.0 * s2 * s, py = s3 + 2.0 * s4 * s;
        J[0] = R + 2.0 * x * x * dR + 2.0 * p1 * y + 6.0 * p2 * x + 2.0 * x * px;
        J[1] = 2.0 * x * y * dR + 2.0 * p1 * x + 2.0 * p2 * y + 2.0 * y * px;
        J[2] = 2.0 * x * y * dR + 2.0 * p1 * x + 2.0 * p2 * y + 2.0 * x * py;
        J[3] = R + 2.0 * y * y * dR + 6.0 * p1 * y + 2.0 * p2 * x + 2.0 * y * py;
    }
}

/* d/dr of r R(r^2), and whether the denominator is positive at r. */
static int brown_radial_ok(const double *k, double r)
{
    double s = r * r, R, dR, den;
    brown_radial(k, s, &R, &dR, &den);
    return den > 0.0 && R + 2.0 * s * dR > 0.0 && isfinite(R) && isfinite(dR);
}

/* ------------------------------------------------------------ fisheye */

static double fe_h(const double *k, double t)
{
    double t2 = t * t;
    return t * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

static double fe_dh(const double *k, double t)
{
    double t2 = t * t;
    return 1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
}

/* ------------------------------------------------------------ checks */

/* The first point of (0, hi] where ok() fails, refined by bisection; hi
 * if it never fails on the scan. */
static double first_fold(const double *k, int fisheye, double hi)
{
    double prev = 0.0;
    for (int i = 1; i <= FOLD_STEPS; i++) {
        double t = hi * (double)i / FOLD_STEPS;
        int ok = fisheye ? fe_dh(k, t) > 0.0 && isfinite(fe_dh(k, t)) : brown_radial_ok(k, t);
        if (!ok) {
            double a = prev, b = t;
            for (int j = 0; j < 80; j++) {
                double m = 0.5 * (a + b);
                int okm = fisheye ? fe_dh(k, m) > 0.0 : brown_radial_ok(k, m);
                if (okm) a = m;
                else b = m;
            }
            return a;
        }
        prev = t;
    }
    return hi;
}

int kin_lens_check(kin_lens *L, char *why, int why_size)
{
    if (!L) return fail(why, why_size, "no lens");
    if (L->model != KIN_LENS_PINHOLE && L->model != KIN_LENS_BROWN && L->model != KIN_LENS_FISHEYE)
        return fail(why, why_size, "unknown lens model %d", (int)L->model);
    if (L->width < 0 || L->height < 0 || (L->width == 0) != (L->height == 0))
        return fail(why, why_size, "image size %dx%d: both positive (or both 0, unknown)",
                    L->width, L->height);
    const double vals[5] = {L->fx, L->fy, L->cx, L->cy, L->skew};
    static const char *const names[5] = {"fx", "fy", "cx", "cy", "skew"};
    for (int i = 0; i < 5; i++)
        if (!isfinite(vals[i]))
            return fail(why, why_size, "camera matrix: %s is not a finite number", names[i]);
    if (!(L->fx > 0.0) || !(L->fy > 0.0))
        return fail(why, why_size, "camera matrix: fx = %g, fy = %g, both must be positive",
                    L->fx, L->fy);
    for (int i = 0; i < KIN_LENS_NCOEF; i++) {
        if (!isfinite(L->k[i]))
            return fail(why, why_size, "distortion coefficient %d is not a finite number", i);
        if (L->model == KIN_LENS_FISHEYE && i >= 4 && L->k[i] != 0.0)
            return fail(why, why_size, "a fisheye lens has 4 distortion coefficients (k1..k4)");
        if (L->model == KIN_LENS_PINHOLE && L->k[i] != 0.0)
            return fail(why, why_size, "a pinhole lens has no distortion coefficients");
    }
    if (L->model == KIN_LENS_FISHEYE) {
        L->theta_max = first_fold(L->k, 1, PI_D);
        if (L->theta_max <= 1e-3)
            return fail(why, why_size, "the fisheye model folds over at the image centre "
                                       "(theta_d decreases from theta = 0)");
        L->rd_max = fe_h(L->k, L->theta_max);
        L->r_max = L->theta_max < 0.5 * PI_D ? tan(L->theta_max) : INFINITY;
    } else {
        L->r_max = L->model == KIN_LENS_PINHOLE ? KIN_LENS_R_SCAN
                                                : first_fold(L->k, 0, KIN_LENS_R_SCAN);
        if (L->r_max <= 1e-3)
            return fail(why, why_size, "the distortion folds over at the image centre "
                                       "(r (1+k1 r^2+...) decreases from r = 0)");
        double R;
        brown_radial(L->k, L->r_max * L->r_max, &R, NULL, NULL);
        L->rd_max = L->r_max * R;
        L->theta_max = atan(L->r_max);
    }
    return 1;
}

kin_lens kin_lens_pinhole(int width, int height, double hfov_deg)
{
    kin_lens L;
    memset(&L, 0, sizeof L);
    L.model = KIN_LENS_PINHOLE;
    L.width = width;
    L.height = height;
    L.fx = L.fy = 0.5 * width / tan(0.5 * hfov_deg * (PI_D / 180.0));
    L.cx = 0.5 * width - 0.5;
    L.cy = 0.5 * height - 0.5;
    kin_lens_check(&L, NULL, 0);
    return L;
}

int kin_lens_distorts(const kin_lens *L)
{
    if (L->model == KIN_LENS_PINHOLE) return 0;
    for (int i = 0; i < KIN_LENS_NCOEF; i++)
        if (L->k[i] != 0.0) return 1;
    return 0;
}

/* The valid region depends on the model and the distortion only: kept
 * from a checked lens (no new scan: these run per frame), found for one
 * that was not. */
static void recheck(kin_lens *L, const kin_lens *src)
{
    if (src->r_max > 0.0 && src->theta_max > 0.0 && src->rd_max > 0.0) return;
    kin_lens_check(L, NULL, 0);
}

kin_lens kin_lens_scaled(const kin_lens *lens, int width, int height)
{
    kin_lens L = *lens;
    if (lens->width > 0 && lens->height > 0 && width > 0 && height > 0 &&
        (width != lens->width || height != lens->height)) {
        double sx = (double)width / lens->width, sy = (double)height / lens->height;
        L.fx *= sx;
        L.skew *= sx;
        L.cx = (L.cx + 0.5) * sx - 0.5;
        L.fy *= sy;
        L.cy = (L.cy + 0.5) * sy - 0.5;
        L.width = width;
        L.height = height;
    }
    recheck(&L, lens);
    return L;
}

kin_lens kin_lens_cropped(const kin_lens *lens, int x0, int y0, int width, int height)
{
    kin_lens L = *lens;
    L.cx -= x0;
    L.cy -= y0;
    L.width = width;
    L.height = height;
    recheck(&L, lens);
    return L;
}

/* ------------------------------------------------ normalized coordinates */

int kin_lens_distort(const kin_lens *L, double x, double y, double *xd, double *yd)
{
    double r = sqrt(x * x + y * y);
    if (!isfinite(r)) return 0;
    switch (L->model) {
    case KIN_LENS_FISHEYE: {
        double th = atan(r);
        if (th > L->theta_max) return 0;
        double sc = r > 0.0 ? fe_h(L->k, th) / r : 1.0;
        *xd = sc * x;
        *yd = sc * y;
        return 1;
    }
    case KIN_LENS_BROWN:
        if (r > L->r_max) return 0;
        brown_map(L->k, x, y, xd, yd, NULL);
        return 1;
    default:
        if (r > L->r_max) return 0;
        *xd = x;
        *yd = y;
        return 1;
    }
}

/* theta in [0, theta_max] with h(theta) = td (td in [0, rd_max]):
 * Newton's method kept inside a shrinking bracket (bisection when a step
 * leaves it). */
static int fe_solve(const kin_lens *L, double td, double *theta)
{
    if (!(td >= 0.0)) return 0;
    if (td > L->rd_max * (1.0 + 1e-12)) return 0;
    double a = 0.0, b = L->theta_max, t = td < b ? td : 0.5 * b;
    for (int it = 0; it < 200; it++) {
        double f = fe_h(L->k, t) - td;
        if (fabs(f) <= KIN_LENS_TOL * (td > 1.0 ? td : 1.0)) {
            *theta = t;
            return 1;
        }
        if (f > 0.0) b = t;
        else a = t;
        double d = fe_dh(L->k, t), tn = d > 0.0 ? t - f / d : -1.0;
        t = (tn > a && tn < b) ? tn : 0.5 * (a + b);
        if (b - a <= 0.0) break;
    }
    /* the bracket closed below the tolerance's resolution */
    if (fabs(fe_h(L->k, t) - td) <= 1e-9 * (td > 1.0 ? td : 1.0)) {
        *theta = t;
        return 1;
    }
    return 0;
}

static double clamp_r(double *x, double *y, double rmax)
{
    double r = sqrt(*x * *x + *y * *y);
    if (r > rmax) {
        *x *= rmax / r;
        *y *= rmax / r;
        r = rmax;
    }
    return r;
}

static int brown_solve(const kin_lens *L, double xd, double yd, double *xo, double *yo)
{
    const double tol = KIN_LENS_TOL * fmax(1.0, sqrt(xd * xd + yd * yd));
    const double rlim = L->r_max * (1.0 - 1e-12);
    double x = xd, y = yd, fx, fy, J[4];
    clamp_r(&x, &y, rlim);
    brown_map(L->k, x, y, &fx, &fy, J);
    fx -= xd;
    fy -= yd;
    double e = hypot(fx, fy);
    for (int it = 0; it < KIN_LENS_MAX_ITER; it++) {
        if (e <= tol) {
            if (J[0] * J[3] - J[1] * J[2] <= 0.0) return 0; /* a folded sheet */
            *xo = x;
            *yo = y;
            return 1;
        }
        double det = J[0] * J[3] - J[1] * J[2];
        if (det == 0.0 || !isfinite(det)) return 0;
        double sx = (J[3] * fx - J[1] * fy) / det, sy = (J[0] * fy - J[2] * fx) / det;
        double t = 1.0;
        int moved = 0;
        for (int h = 0; h < 40; h++, t *= 0.5) {
            double nx = x - t * sx, ny = y - t * sy, gx, gy, JN[4];
            clamp_r(&nx, &ny, rlim);
            brown_map(L->k, nx, ny, &gx, &gy, JN);
            gx -= xd;
            gy -= yd;
            double en = hypot(gx, gy);
            if (en < e) {
                x = nx;
                y = ny;
                fx = gx;
                fy = gy;
                e = en;
                memcpy(J, JN, sizeof JN);
                moved = 1;
                break;
            }
        }
        if (!moved) break;
    }
    if (e <= tol && J[0] * J[3] - J[1] * J[2] > 0.0) {
        *xo = x;
        *yo = y;
        return 1;
    }
    return 0;
}

int kin_lens_undistort(const kin_lens *L, double xd, double yd, double *x, double *y)
{
    if (!isfinite(xd) || !isfinite(yd)) return 0;
    switch (L->model) {
    case KIN_LENS_FISHEYE: {
        double td = sqrt(xd * xd + yd * yd), th;
        if (!fe_solve(L, td, &th) || th >= 0.5 * PI_D) return 0;
        double sc = td > 0.0 ? tan(th) / td : 1.0;
        *x = sc * xd;
        *y = sc * yd;
        return 1;
    }
    case KIN_LENS_BROWN:
        return brown_solve(L, xd, yd, x, y);
    default:
        if (sqrt(xd * xd + yd * yd) > L->r_max) return 0;
        *x = xd;
        *y = yd;
        return 1;
    }
}

/* ---------------------------------------------------- egofuse convention */

int kin_lens_project(const kin_lens *L, const double p[3], double *u, double *v)
{
    /* OpenCV's camera frame: (X, -Y, -Z) */
    double X = p[0], Y = -p[1], Z = -p[2], xd, yd;
    if (!isfinite(X) || !isfinite(Y) || !isfinite(Z)) return 0;
    if (L->model == KIN_LENS_FISHEYE) {
        double rho = sqrt(X * X + Y * Y);
        double th = atan2(rho, Z);
        if (th > L->theta_max || (rho == 0.0 && Z <= 0.0)) return 0;
        double td = fe_h(L->k, th);
        xd = rho > 0.0 ? td * X / rho : 0.0;
        yd = rho > 0.0 ? td * Y / rho : 0.0;
    } else {
        if (!(Z > 0.0)) return 0;
        if (!kin_lens_distort(L, X / Z, Y / Z, &xd, &yd)) return 0;
    }
    *u = L->fx * xd + L->skew * yd + L->cx + 0.5;
    *v = L->fy * yd + L->cy + 0.5;
    return 1;
}

int kin_lens_unproject(const kin_lens *L, double u, double v, double ray[3])
{
    double yd = (v - 0.5 - L->cy) / L->fy;
    double xd = (u - 0.5 - L->cx - L->skew * yd) / L->fx;
    double d[3];
    if (L->model == KIN_LENS_FISHEYE) {
        double td = sqrt(xd * xd + yd * yd), th;
        if (!fe_solve(L, td, &th)) return 0;
        double s = sin(th);
        d[0] = td > 0.0 ? s * xd / td : 0.0;
        d[1] = td > 0.0 ? s * yd / td : 0.0;
        d[2] = cos(th);
    } else {
        double x, y;
        if (!kin_lens_undistort(L, xd, yd, &x, &y)) return 0;
        double n = sqrt(x * x + y * y + 1.0);
        d[0] = x / n;
        d[1] = y / n;
        d[2] = 1.0 / n;
    }
    ray[0] = d[0];
    ray[1] = -d[1];
    ray[2] = -d[2];
    return 1;
}
