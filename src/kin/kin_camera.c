/* kin_camera.c - the STHMD camera model of the paper (eq. 1-4) and a
 * general look-at camera.
 *
 * Pixel convention (kin.h, kin_camera): a view-space point (X, Y, Z),
 * Z < 0, images at the continuous pixel position
 *     u = cx + fx * X / -Z,   v = cy - fy * Y / -Z,
 * where pixel (x, y) covers [x, x+1) x [y, y+1) and has its centre at
 * (x + 0.5, y + 0.5), row 0 at the top. The OpenGL projection built here
 * reproduces that exactly with the rasterizer's viewport transform
 *     u = (x_ndc * 0.5 + 0.5) * width,  v = (0.5 - y_ndc * 0.5) * height.
 * Derivation in docs/kin.md. */
#include "kin.h"

#include <math.h>
#include <string.h>

#define DEG2RAD 0.017453292519943295

static float def_f(float v, float d) { return (v > 0.0f && isfinite(v)) ? v : d; }
static int def_i(int v, int d) { return v > 0 ? v : d; }
static int lens_given(const kin_lens *l) { return l->fx > 0.0 && isfinite(l->fx); }

kin_sthmd_desc kin_sthmd_desc_resolved(const kin_sthmd_desc *desc)
{
    kin_sthmd_desc z;
    memset(&z, 0, sizeof z);
    const kin_sthmd_desc *d = desc ? desc : &z;
    kin_sthmd_desc r;
    memset(&r, 0, sizeof r); /* padding too: resolved descs compare with memcmp */
    r.cam_width = def_i(d->cam_width, 640);
    r.cam_height = def_i(d->cam_height, 480);
    r.cam_hfov_deg = def_f(d->cam_hfov_deg, 62.0f);
    r.baseline_m = def_f(d->baseline_m, 0.065f);
    r.cam_offset_m = def_f(d->cam_offset_m, 0.085f);
    r.lcd_width = def_i(d->lcd_width, 1280);
    r.lcd_height = def_i(d->lcd_height, 800);
    r.hmd_hfov_deg = def_f(d->hmd_hfov_deg, 61.0f);
    r.hmd_vfov_deg = def_f(d->hmd_vfov_deg, 40.0f);
    r.focal_m = def_f(d->focal_m, 1.0f);
    r.znear = def_f(d->znear, 0.01f);
    r.zfar = def_f(d->zfar, 100.0f);
    r.ipd_m = def_f(d->ipd_m, r.baseline_m);
    /* calibrated lenses: the camera's size from the lens when not given,
     * each lens at the camera's size, the FOV of eq. 2 from the left one */
    memset(r.lens, 0, sizeof r.lens);
    if (lens_given(&d->lens[0]) && d->cam_width <= 0 && d->lens[0].width > 0) {
        r.cam_width = d->lens[0].width;
        r.cam_height = d->lens[0].height;
    }
    for (int e = 0; e < 2; e++) {
        if (!lens_given(&d->lens[e])) continue;
        kin_lens l = d->lens[e];
        if (l.width <= 0 || l.height <= 0) {
            l.width = r.cam_width;
            l.height = r.cam_height;
        }
        r.lens[e] = kin_lens_scaled(&l, r.cam_width, r.cam_height);
    }
    if (lens_given(&r.lens[0]))
        r.cam_hfov_deg = (float)(2.0 * atan(0.5 * r.cam_width / r.lens[0].fx) / DEG2RAD);
    return r;
}

/* Focal length in pixels of the camera: (cam_width / 2) / tan(hfov / 2). */
static double cam_focal_px(const kin_sthmd_desc *r)
{
    return 0.5 * r->cam_width / tan(0.5 * r->cam_hfov_deg * DEG2RAD);
}

kin_sthmd_geometry kin_sthmd_geometry_of(const kin_sthmd_desc *desc)
{
    kin_sthmd_desc r = kin_sthmd_desc_resolved(desc);
    kin_sthmd_geometry g;
    memset(&g, 0, sizeof g);

    /* eq. 1: keep the width, crop the height to the LCD aspect
     * (rounded to the nearest row). A camera wider than the LCD's aspect
     * (a 16:9 camera, a portrait display) keeps all rows and crops the
     * width to the aspect instead (nearest column), centred: both ways
     * the cropped image has the LCD's aspect, which the viewport of eq. 4
     * has too. */
    g.crop_width = r.cam_width;
    long h = ((long)r.cam_width * r.lcd_height + r.lcd_width / 2) / r.lcd_width;
    if (h > r.cam_height) {
        h = r.cam_height;
        long w = ((long)r.cam_height * r.lcd_width + r.lcd_height / 2) / r.lcd_height;
        if (w > r.cam_width) w = r.cam_width;
        if (w < 1) w = 1;
        g.crop_width = (int)w;
        g.crop_x0 = (r.cam_width - g.crop_width) / 2;
    }
    if (h < 1) h = 1;
    g.crop_height = (int)h;
    g.crop_y0 = (r.cam_height - g.crop_height) / 2;

    /* eq. 2: projected widths on the eye's projection plane at F, in mm;
     * W2 of the cropped image's horizontal FOV (the camera's own unless
     * the width is cropped: tan(hfov_crop / 2) = (crop_w / 2) / fx). */
    double f_mm = 1000.0 * r.focal_m, d_mm = 1000.0 * r.cam_offset_m;
    g.w1_mm = 2.0 * f_mm * tan(0.5 * r.hmd_hfov_deg * DEG2RAD);
    g.w2_mm = 2.0 * (f_mm - d_mm) *
              (g.crop_width == r.cam_width ? tan(0.5 * r.cam_hfov_deg * DEG2RAD)
                                           : 0.5 * g.crop_width / cam_focal_px(&r));
    /* eq. 3 and 4 */
    g.ratio = g.w2_mm / g.w1_mm;
    g.vp_width = (int)floor(r.lcd_width * g.ratio);
    g.vp_height = (int)floor(r.lcd_height * g.ratio);
    g.vp_x0 = (r.lcd_width - g.vp_width) / 2;
    g.vp_y0 = (r.lcd_height - g.vp_height) / 2;

    g.crop_vfov_deg = (float)(2.0 * atan(0.5 * g.crop_height / cam_focal_px(&r)) / DEG2RAD);
    return g;
}

/* OpenGL projection of a pinhole camera with intrinsics fx, fy, cx, cy on a
 * w x h image (see the top of the file):
 *   x_clip = 2fx/w X + (1 - 2cx/w) Z,   y_clip = 2fy/h Y + (2cy/h - 1) Z,
 *   z_clip = (f+n)/(n-f) Z + 2fn/(n-f), w_clip = -Z. */
kin_mat4 kin_proj_from_intrinsics(double fx, double fy, double cx, double cy, double skew,
                                  int w, int h, double n, double f)
{
    kin_mat4 p;
    memset(&p, 0, sizeof p);
    p.m[0] = (float)(2.0 * fx / w);
    p.m[5] = (float)(2.0 * fy / h);
    p.m[8] = (float)(1.0 - 2.0 * cx / w);
    p.m[9] = (float)(2.0 * cy / h - 1.0);
    p.m[10] = (float)((f + n) / (n - f));
    p.m[11] = -1.0f;
    p.m[14] = (float)(2.0 * f * n / (n - f));
    if (skew != 0.0) p.m[4] = (float)(-2.0 * skew / w);
    return p;
}

/* The pinhole kin_lens of kin_camera intrinsics (egofuse pixels). */
static kin_lens pinhole_lens(double fx, double fy, double cx, double cy, int w, int h)
{
    kin_lens l = { .model = KIN_LENS_PINHOLE, .width = w, .height = h,
                   .fx = fx, .fy = fy, .cx = cx - 0.5, .cy = cy - 0.5 };
    kin_lens_check(&l, NULL, 0);
    return l;
}

kin_camera kin_sthmd_camera(const kin_sthmd_desc *desc,
                            const kin_mat4 *world_from_head, kin_eye eye)
{
    kin_sthmd_desc r = kin_sthmd_desc_resolved(desc);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(&r);
    kin_camera c;
    memset(&c, 0, sizeof c);

    float side = eye == KIN_EYE_RIGHT ? 0.5f : -0.5f;
    kin_mat4 head = world_from_head ? *world_from_head : kin_mat4_identity();
    kin_mat4 t = kin_mat4_identity();
    t.m[12] = side * r.baseline_m;
    t.m[13] = 0.0f;
    t.m[14] = -r.cam_offset_m;
    c.world_from_cam = kin_mat4_mul(&head, &t);
    if (!kin_mat4_inverse(&c.world_from_cam, &c.view)) {
        /* A singular head matrix: fall back to the camera at its place in
         * the head frame with an identity head. */
        c.world_from_cam = t;
        kin_mat4_inverse(&t, &c.view);
    }

    c.width = g.crop_width;
    c.height = g.crop_height;
    double f = cam_focal_px(&r);
    c.fx = c.fy = (float)f;
    /* the principal point: the sensor's centre, in the crop */
    c.cx = g.crop_width != r.cam_width ? 0.5f * (float)r.cam_width - (float)g.crop_x0
                                       : 0.5f * (float)g.crop_width;
    c.cy = 0.5f * (float)r.cam_height - (float)g.crop_y0;
    if (lens_given(&r.lens[eye == KIN_EYE_RIGHT])) {
        /* a calibrated lens, in the crop; the projection draws its pinhole
         * part (a distorting lens is applied to the mask by the pipeline,
         * src/pipe/pipe_lens.h) */
        c.lens = kin_lens_cropped(&r.lens[eye == KIN_EYE_RIGHT], g.crop_x0, g.crop_y0, c.width,
                                  c.height);
        c.fx = (float)c.lens.fx;
        c.fy = (float)c.lens.fy;
        c.cx = (float)(c.lens.cx + 0.5);
        c.cy = (float)(c.lens.cy + 0.5);
        c.proj = kin_proj_from_intrinsics(c.lens.fx, c.lens.fy, c.lens.cx + 0.5, c.lens.cy + 0.5,
                                          c.lens.skew, c.width, c.height, r.znear, r.zfar);
    } else {
        c.proj = kin_proj_from_intrinsics(f, f, c.cx, c.cy, 0.0, c.width, c.height, r.znear,
                                          r.zfar);
        c.lens = pinhole_lens(f, f, c.cx, c.cy, c.width, c.height);
    }
    c.view_proj = kin_mat4_mul(&c.proj, &c.view);
    return c;
}

kin_mat4 kin_sthmd_eye(const kin_sthmd_desc *desc, const kin_mat4 *world_from_head,
                       kin_eye eye)
{
    kin_sthmd_desc r = kin_sthmd_desc_resolved(desc);
    kin_mat4 head = world_from_head ? *world_from_head : kin_mat4_identity();
    kin_mat4 t = kin_mat4_identity();
    t.m[12] = (eye == KIN_EYE_RIGHT ? 0.5f : -0.5f) * r.ipd_m;
    return kin_mat4_mul(&head, &t);
}

kin_camera kin_camera_look_at(kin_vec3 eye, kin_vec3 target, kin_vec3 up,
                              float fovy_deg, int width, int height,
                              float znear, float zfar)
{
    kin_camera c;
    memset(&c, 0, sizeof c);
    c.view = kin_mat4_look_at(eye, target, up);
    /* The view's rows are the camera axes: world_from_cam has them as
     * columns and the eye as origin (exact, no general inverse needed). */
    const float *v = c.view.m;
    c.world_from_cam = kin_mat4_identity();
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < 3; k++) c.world_from_cam.m[a * 4 + k] = v[k * 4 + a];
    c.world_from_cam.m[12] = eye.x;
    c.world_from_cam.m[13] = eye.y;
    c.world_from_cam.m[14] = eye.z;

    c.width = width > 0 ? width : 1;
    c.height = height > 0 ? height : 1;
    double fovy = (double)fovy_deg * DEG2RAD;
    double fy = 0.5 * c.height / tan(0.5 * fovy);
    c.fx = c.fy = (float)fy;
    c.cx = 0.5f * (float)c.width;
    c.cy = 0.5f * (float)c.height;
    c.proj = kin_mat4_perspective((float)fovy, (float)c.width / (float)c.height,
                                  znear, zfar);
    c.lens = pinhole_lens(fy, fy, c.cx, c.cy, c.width, c.height);
    c.view_proj = kin_mat4_mul(&c.proj, &c.view);
    return c;
}
