/* kin_lens.h - camera lens models: pinhole, Brown-Conrady (OpenCV's
 * cv::projectPoints) and Kannala-Brandt fisheye (OpenCV's cv::fisheye).
 *
 * WHAT IT DOES
 *   A kin_lens holds a camera's intrinsics and distortion exactly as an
 *   OpenCV calibration gives them (camera_matrix, distortion_coefficients,
 *   the image size they are for). kin_lens_project() images a view-space
 *   point to a pixel position through the lens (distortion included);
 *   kin_lens_unproject() turns a pixel position back into the unit ray it
 *   images (iterative undistortion). Both work in egofuse's conventions
 *   (below); the OpenCV-convention building blocks, kin_lens_distort()
 *   and kin_lens_undistort(), are public for tests and tools.
 *
 * THE MODELS (OpenCV's formulas; x, y the normalized coordinates X/Z, Y/Z
 * of a point in OpenCV's camera frame: +X right, +Y down, +Z forward)
 *   KIN_LENS_PINHOLE   x'' = x, y'' = y.
 *   KIN_LENS_BROWN     r^2 = x^2 + y^2,
 *     x'' = x (1+k1 r^2+k2 r^4+k3 r^6)/(1+k4 r^2+k5 r^4+k6 r^6)
 *           + 2 p1 x y + p2 (r^2 + 2 x^2) + s1 r^2 + s2 r^4
 *     y'' = y (same radial factor) + p1 (r^2 + 2 y^2) + 2 p2 x y
 *           + s3 r^2 + s4 r^4
 *     coefficients in OpenCV's order: k[] = k1 k2 p1 p2 k3 k4 k5 k6 s1 s2
 *     s3 s4 (4, 5, 8 or 12 of them; the rest zero). The tilted-sensor
 *     model (14 coefficients, tauX tauY) is not supported.
 *   KIN_LENS_FISHEYE   r = sqrt(x^2 + y^2), theta = atan(r),
 *     theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)
 *     x'' = (theta_d / r) x, y'' = (theta_d / r) y;  k[] = k1 k2 k3 k4.
 *     theta is computed as atan2(sqrt(X^2+Y^2), Z) from the 3D point, which
 *     equals OpenCV's atan(r) in front of the camera and extends the model
 *     to rays more than 90 degrees off the axis (a lens that sees them).
 *   then u = fx x'' + skew y'' + cx, v = fy y'' + cy (OpenCV pixels: the
 *   centre of the top-left pixel at (0, 0)). skew is camera_matrix(0,1)
 *   (zero from cv::calibrateCamera; fx * alpha of cv::fisheye).
 *
 * EGOFUSE CONVENTIONS (kin_lens_project / kin_lens_unproject)
 *   View space as kin_camera: the camera looks down -Z, +Y up, +X right; so
 *   OpenCV's (X, Y, Z) = (X, -Y, -Z). Pixel positions are egofuse's: pixel
 *   (x, y) covers [x, x+1) x [y, y+1), its centre at (x + 0.5, y + 0.5),
 *   so u_egofuse = u_opencv + 0.5 (same for v). A pinhole lens thus gives
 *   exactly kin_camera's u = cx + fx X/-Z, v = cy - fy Y/-Z with
 *   kin_camera.cx = lens.cx + 0.5.
 *
 * THE VALID REGION (where the model folds over)
 *   A polynomial lens model stops being a lens beyond some angle: its
 *   radial map r -> r_d (Brown: r R(r^2); fisheye: theta -> theta_d) stops
 *   increasing and folds back, so two rays would image to one pixel.
 *   kin_lens_check() finds the first radius where the derivative of that map
 *   is no longer positive (and, for the rational model, where the
 *   denominator reaches zero), scanning up to r = KIN_LENS_R_SCAN (87
 *   degrees off the axis; fisheye: theta up to pi) and stores it in
 *   r_max / theta_max. Points beyond it are not projected (return 0), pixels
 *   whose distorted radius lies beyond the fold's image are not unprojected
 *   (return 0). A Brown lens also needs Z in front of the camera.
 *   Tangential and thin-prism terms can fold the map by themselves: the
 *   unprojection also requires the Jacobian of the distortion to have a
 *   positive determinant at its solution.
 *
 * CONVERGENCE (kin_lens_undistort / kin_lens_unproject)
 *   Newton's method on the exact distortion map (analytic Jacobian), from
 *   the distorted point, with steps halved while they do not reduce the
 *   residual and radii clamped into the valid region. It stops when the
 *   re-distorted point is within KIN_LENS_TOL (1e-12 in normalized
 *   coordinates, ~1e-9 px for a 640-pixel camera) of the input, and fails
 *   (returns 0) if that is not reached in KIN_LENS_MAX_ITER (50) steps.
 *   The fisheye's radial equation is one-dimensional: Newton's method with
 *   a bisection safeguard on [0, theta_max].
 *
 * WHAT IT DOES NOT
 *   No I/O (src/io/io_calib.h reads OpenCV calibration files), no
 *   allocation, no global state. Every call is reentrant.
 */
#ifndef EGOFUSE_KIN_LENS_H
#define EGOFUSE_KIN_LENS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum kin_lens_model {
    KIN_LENS_PINHOLE = 0,   /* no distortion */
    KIN_LENS_BROWN = 1,     /* cv::projectPoints: k1 k2 p1 p2 k3 [k4 k5 k6 [s1 s2 s3 s4]] */
    KIN_LENS_FISHEYE = 2    /* cv::fisheye: k1 k2 k3 k4 (Kannala-Brandt) */
} kin_lens_model;

#define KIN_LENS_NCOEF 12
#define KIN_LENS_R_SCAN 19.08113668772821 /* tan(87 degrees) */
#define KIN_LENS_TOL 1e-12
#define KIN_LENS_MAX_ITER 50

typedef struct kin_lens {
    kin_lens_model model;
    int width, height;          /* image size the intrinsics are for */
    double fx, fy, cx, cy;      /* camera_matrix, OpenCV pixels */
    double skew;                /* camera_matrix(0,1), usually 0 */
    double k[KIN_LENS_NCOEF];   /* distortion, OpenCV's order (above) */
    /* filled by kin_lens_check: */
    double r_max;               /* Brown/pinhole: valid normalized radius */
    double theta_max;           /* valid angle off the axis, radians */
    double rd_max;              /* the distorted radius at r_max / theta_max */
} kin_lens;

/* Checks a lens (finite values, fx, fy > 0, size > 0 when given, a
 * valid region) and fills r_max, theta_max, rd_max. Returns 1 if usable;
 * 0 with a sentence in why (naming the field) otherwise. Every other call
 * expects a checked lens. */
int kin_lens_check(kin_lens *lens, char *why, int why_size);

/* The paper's lens: a pinhole of horizontal field of view hfov_deg on a
 * width x height sensor, principal point at the centre, checked. */
kin_lens kin_lens_pinhole(int width, int height, double hfov_deg);

/* 1 if the lens distorts (not a pinhole, or all coefficients zero). */
int kin_lens_distorts(const kin_lens *lens);

/* The same lens for an image of another size (calibrated at one
 * resolution, used at another, e.g. a binned mode): fx, skew, cx scale by
 * sx = width / lens->width, fy, cy by sy (cx about the pixel edge:
 * (cx + 0.5) sx - 0.5); the distortion (in normalized coordinates) is
 * unchanged. And the lens for a crop whose top-left pixel is (x0, y0) of
 * the image: cx - x0, cy - y0, size width x height. The valid region is
 * kept from a checked lens (cheap enough per frame), found for another. */
kin_lens kin_lens_scaled(const kin_lens *lens, int width, int height);
kin_lens kin_lens_cropped(const kin_lens *lens, int x0, int y0, int width, int height);

/* OpenCV convention, normalized coordinates (x, y) = (X/Z, Y/Z) of a
 * point in front of the camera (so, for the fisheye, rays less than 90
 * degrees off the axis; kin_lens_project takes any ray). Output: the
 * distorted normalized point (before the camera matrix), exactly OpenCV's
 * formula. Return 1, or 0 outside the valid region. */
int kin_lens_distort(const kin_lens *lens, double x, double y, double *xd, double *yd);
/* The inverse: distorted normalized (xd, yd) -> undistorted (x, y)
 * (fisheye: tan(theta) * dir, so only for theta < 90 degrees; use
 * kin_lens_unproject for wider rays). 1 on convergence, else 0. */
int kin_lens_undistort(const kin_lens *lens, double xd, double yd, double *x, double *y);

/* egofuse convention (above): a view-space point p (camera looks down -Z)
 * to the pixel position (u, v), centres at +0.5. 1, or 0 when the point
 * is outside the valid region (behind a Brown/pinhole camera, beyond the
 * fold), leaving u, v untouched. */
int kin_lens_project(const kin_lens *lens, const double p[3], double *u, double *v);
/* The unit view-space ray imaged at pixel position (u, v) (egofuse
 * convention, so ray[2] < 0 in front of the camera). 1, or 0 when no ray of
 * the valid region images there (the Newton iteration did not converge, or
 * (u, v) lies beyond the fold's image). */
int kin_lens_unproject(const kin_lens *lens, double u, double v, double ray[3]);

#ifdef __cplusplus
}
#endif

#endif
