/* test_kin_camera.c - the STHMD camera model (kin_camera.c): the paper's
 * numbers (eq. 1-4), the per-eye camera placement, and the projection
 * against the pinhole formula u = cx + fx X/-Z, v = cy - fy Y/-Z with the
 * rasterizer's viewport (u = (x_ndc/2 + 1/2) W, v = (1/2 - y_ndc/2) H). */
#include "support/testutil.h"
#include "support/tu_kin.h"
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "../src/kin/kin.h"

#define TOL 1e-5f
#define PI_D 3.14159265358979323846
/* Pixel positions are ~600 px computed through float matrices: float
 * rounding alone (2^-24 relative, a few operations) reaches ~1e-4 px. */
#define PX_TOL 2e-3

/* Projects a world point with view_proj and the viewport transform. */
static void project(const kin_camera *c, kin_vec3 p, double *u, double *v, double *zndc)
{
    const float *m = c->view_proj.m;
    double x = m[0] * (double)p.x + m[4] * (double)p.y + m[8] * (double)p.z + m[12];
    double y = m[1] * (double)p.x + m[5] * (double)p.y + m[9] * (double)p.z + m[13];
    double z = m[2] * (double)p.x + m[6] * (double)p.y + m[10] * (double)p.z + m[14];
    double w = m[3] * (double)p.x + m[7] * (double)p.y + m[11] * (double)p.z + m[15];
    *u = (x / w * 0.5 + 0.5) * c->width;
    *v = (0.5 - y / w * 0.5) * c->height;
    if (zndc) *zndc = z / w;
}

static double fx_paper(void) { return 320.0 / tan(31.0 * PI_D / 180.0); }

static kin_vec3 origin_of(const kin_mat4 *m) { return kin_v3(m->m[12], m->m[13], m->m[14]); }

/* ------------------------------------------------------------ validity */

static void validity_desc_defaults(void **state)
{
    (void)state;
    kin_sthmd_desc z;
    memset(&z, 0, sizeof z);
    kin_sthmd_desc r = kin_sthmd_desc_resolved(&z);
    assert_int_equal(r.cam_width, 640);
    assert_int_equal(r.cam_height, 480);
    NEAR(r.cam_hfov_deg, 62, 0);
    NEAR(r.baseline_m, 0.065f, 0);
    NEAR(r.cam_offset_m, 0.085f, 0);
    assert_int_equal(r.lcd_width, 1280);
    assert_int_equal(r.lcd_height, 800);
    NEAR(r.hmd_hfov_deg, 61, 0);
    NEAR(r.hmd_vfov_deg, 40, 0);
    NEAR(r.focal_m, 1.0, 0);
    NEAR(r.znear, 0.01f, 0);
    NEAR(r.zfar, 100, 0);
    kin_sthmd_desc rn = kin_sthmd_desc_resolved(NULL);
    assert_memory_equal(&rn, &r, sizeof r);
    /* set fields are kept */
    z.cam_width = 800; z.baseline_m = 0.06f; z.zfar = 10;
    r = kin_sthmd_desc_resolved(&z);
    assert_int_equal(r.cam_width, 800);
    NEAR(r.baseline_m, 0.06f, 0);
    NEAR(r.zfar, 10, 0);
    assert_int_equal(r.cam_height, 480);
}

/* The geometry of the paper's HMD with a camera of w x h pixels. */
static kin_sthmd_geometry sensor_geometry(int w, int h)
{
    kin_sthmd_desc d;
    memset(&d, 0, sizeof d);
    d.cam_width = w;
    d.cam_height = h;
    return kin_sthmd_geometry_of(&d);
}

static void validity_wide_camera_crop(void **state)
{
    (void)state;
    /* a 16:9 camera is wider than the 1.6 LCD: the crop keeps all rows */
    kin_sthmd_geometry g = sensor_geometry(640, 360);
    assert_int_equal(g.crop_height, 360);
    assert_int_equal(g.crop_y0, 0);
    /* a 4:3 sensor of another size still crops to 1.6 */
    g = sensor_geometry(1280, 960);
    assert_int_equal(g.crop_width, 1280);
    assert_int_equal(g.crop_height, 800);
    assert_int_equal(g.crop_y0, 80);
}

/* -------------------------------------------------------------- result */

static void result_paper_numbers(void **state)
{
    (void)state;
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    assert_int_equal(g.crop_width, 640);          /* eq. 1 */
    assert_int_equal(g.crop_height, 400);
    assert_int_equal(g.crop_y0, 40);
    /* eq. 2: the paper quotes whole millimetres, truncated: W1 = 1178.09,
     * W2 = 1830 tan(31 deg) = 1099.58 (which would round to 1100). */
    assert_int_equal((int)floor(g.w1_mm), 1178);
    assert_int_equal((int)floor(g.w2_mm), 1099);
    assert_true(g.w2_mm > 1099.5 && g.w2_mm < 1099.6);
    assert_int_equal((int)lround(g.ratio * 1000), 933); /* eq. 3 */
    assert_int_equal(g.vp_width, 1194);           /* eq. 4 */
    assert_int_equal(g.vp_height, 746);
    assert_int_equal(g.vp_x0, 43);
    assert_int_equal(g.vp_y0, 27);
    NEAR(g.w1_mm, 2000.0 * tan(30.5 * PI_D / 180), TOL);
    NEAR(g.w2_mm, 1830.0 * tan(31.0 * PI_D / 180), TOL); /* D is a float */
    NEAR(g.ratio, g.w2_mm / g.w1_mm, 1e-15);
    NEAR(g.crop_vfov_deg, 2 * atan(200 / fx_paper()) * 180 / PI_D, TOL);
    /* the paper's values in the geometry of a zeroed desc, too */
    kin_sthmd_desc z;
    memset(&z, 0, sizeof z);
    kin_sthmd_geometry g2 = kin_sthmd_geometry_of(&z);
    assert_memory_equal(&g, &g2, sizeof g);
}

static void result_camera_intrinsics(void **state)
{
    (void)state;
    kin_camera c = kin_sthmd_camera(NULL, NULL, KIN_EYE_LEFT);
    assert_int_equal(c.width, 640);
    assert_int_equal(c.height, 400);
    NEAR(c.fx, fx_paper(), 1e-4);
    NEAR(c.fy, fx_paper(), 1e-4);
    NEAR(c.cx, 320, 0);
    NEAR(c.cy, 200, 0);
    /* view_proj = proj * view, world_from_cam * view = I */
    kin_mat4 vp = kin_mat4_mul(&c.proj, &c.view), id = kin_mat4_mul(&c.world_from_cam, &c.view);
    for (int k = 0; k < 16; k++) {
        NEAR(vp.m[k], c.view_proj.m[k], 0);
        NEAR(id.m[k], (k % 5 == 0) ? 1 : 0, TOL);
    }
}

static void result_camera_centres(void **state)
{
    (void)state;
    kin_camera l = kin_sthmd_camera(NULL, NULL, KIN_EYE_LEFT);
    kin_camera r = kin_sthmd_camera(NULL, NULL, KIN_EYE_RIGHT);
    NEAR3(origin_of(&l.world_from_cam), -0.0325, 0, -0.085, TOL);
    NEAR3(origin_of(&r.world_from_cam), 0.0325, 0, -0.085, TOL);
    NEAR3(kin_mat4_mul_point(&l.view, kin_v3(-0.0325f, 0, -0.085f)), 0, 0, 0, TOL);
    NEAR3(kin_mat4_mul_dir(&l.world_from_cam, kin_v3(0, 0, -1)), 0, 0, -1, TOL);
    kin_mat4 id = kin_mat4_identity();
    kin_camera l2 = kin_sthmd_camera(NULL, &id, KIN_EYE_LEFT);
    assert_memory_equal(&l2, &l, sizeof l);

    /* head at (1,2,3) turned 90 degrees about Y: (x,y,z) -> (z,y,-x) */
    kin_mat4 head = kin_mat4_from_tr(kin_v3(1, 2, 3),
                                     kin_quat_axis_angle(kin_v3(0, 1, 0), (float)(PI_D / 2)));
    l = kin_sthmd_camera(NULL, &head, KIN_EYE_LEFT);
    r = kin_sthmd_camera(NULL, &head, KIN_EYE_RIGHT);
    NEAR3(origin_of(&l.world_from_cam), 1 - 0.085, 2, 3 + 0.0325, TOL);
    NEAR3(origin_of(&r.world_from_cam), 1 - 0.085, 2, 3 - 0.0325, TOL);
    NEAR3(kin_mat4_mul_dir(&l.world_from_cam, kin_v3(0, 0, -1)), -1, 0, 0, TOL);
    NEAR3(kin_mat4_mul_dir(&r.world_from_cam, kin_v3(0, 1, 0)), 0, 1, 0, TOL);
    NEAR3(kin_mat4_mul_point(&r.view, kin_v3(1 - 0.085f, 2, 3 - 0.0325f)), 0, 0, 0, TOL);
    /* a custom baseline and offset */
    kin_sthmd_desc d;
    memset(&d, 0, sizeof d);
    d.baseline_m = 0.07f; d.cam_offset_m = 0.05f;
    r = kin_sthmd_camera(&d, NULL, KIN_EYE_RIGHT);
    NEAR3(origin_of(&r.world_from_cam), 0.035, 0, -0.05, TOL);
}

static void result_projection_pinhole(void **state)
{
    (void)state;
    const double fx = fx_paper();
    /* straight ahead of the left camera: the optical axis hits (320, 200) */
    kin_camera c = kin_sthmd_camera(NULL, NULL, KIN_EYE_LEFT);
    double u, v, z;
    project(&c, kin_v3(-0.0325f, 0, -0.085f - 1.0f), &u, &v, NULL);
    NEAR(u, 320, PX_TOL);
    NEAR(v, 200, PX_TOL);
    /* a known point 1 m ahead, 0.5 right and 0.25 up of the camera */
    project(&c, kin_v3(-0.0325f + 0.5f, 0.25f, -1.085f), &u, &v, NULL);
    NEAR(u, 320 + fx * 0.5, PX_TOL);
    NEAR(v, 200 - fx * 0.25, PX_TOL);
    /* near and far planes */
    project(&c, kin_v3(-0.0325f, 0, -0.085f - 0.01f), &u, &v, &z);
    NEAR(z, -1, 1e-4);
    project(&c, kin_v3(-0.0325f, 0, -0.085f - 100.0f), &u, &v, &z);
    NEAR(z, 1, 1e-4);

    /* seeded points in front of a moved head, both eyes */
    tu_rng g = { 0x6b696e06 };
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0.3f, 1.6f, -0.2f),
                                     kin_quat_axis_angle(kin_v3(0.2f, 1, 0.1f), 0.6f));
    for (int e = 0; e < 2; e++) {
        c = kin_sthmd_camera(NULL, &head, (kin_eye)e);
        for (int i = 0; i < 200; i++) {
            kin_vec3 pv = tu_v3b(&g, -0.3f, 0.3f, -0.2f, 0.2f, -1.0f, -0.15f);
            kin_vec3 pw = kin_mat4_mul_point(&c.world_from_cam, pv);
            kin_vec3 q = kin_mat4_mul_point(&c.view, pw);
            project(&c, pw, &u, &v, NULL);
            NEAR(u, c.cx + fx * q.x / -q.z, PX_TOL);
            NEAR(v, c.cy - fx * q.y / -q.z, PX_TOL);
        }
    }
}

static void result_pixel_ray_round_trip(void **state)
{
    (void)state;
    /* the ray of pixel centre (x+.5, y+.5) given by kin_camera lands back on
     * that pixel centre through view_proj and the viewport */
    kin_camera c = kin_sthmd_camera(NULL, NULL, KIN_EYE_RIGHT);
    const int px[][2] = { { 0, 0 }, { 639, 399 }, { 319, 199 }, { 320, 200 }, { 17, 350 }, { 600, 3 } };
    for (size_t i = 0; i < sizeof px / sizeof px[0]; i++) {
        double x = px[i][0] + 0.5, y = px[i][1] + 0.5;
        for (double depth = 0.2; depth < 3; depth *= 3) {
            kin_vec3 rv = kin_v3((float)((x - c.cx) / c.fx * depth),
                                 (float)(-(y - c.cy) / c.fy * depth), (float)-depth);
            kin_vec3 pw = kin_mat4_mul_point(&c.world_from_cam, rv);
            double u, v;
            project(&c, pw, &u, &v, NULL);
            NEAR(u, x, PX_TOL);
            NEAR(v, y, PX_TOL);
        }
    }
    /* the image edges are the FOV edges: the sensor's hfov is 62 degrees */
    double t = tan(31.0 * PI_D / 180);
    double u, v;
    project(&c, kin_v3((float)(0.0325 + t), 0, -1.085f), &u, &v, NULL);
    NEAR(u, 640, PX_TOL);
    double tv = tan(0.5 * kin_sthmd_geometry_of(NULL).crop_vfov_deg * PI_D / 180);
    project(&c, kin_v3(0.0325f, (float)tv, -1.085f), &u, &v, NULL);
    NEAR(v, 0, PX_TOL);
}

static void result_look_at_camera(void **state)
{
    (void)state;
    kin_vec3 eye = kin_v3(0.5f, 1.7f, 2.0f), target = kin_v3(-0.2f, 1.0f, 0.1f);
    kin_camera c = kin_camera_look_at(eye, target, kin_v3(0, 1, 0), 50.0f, 800, 600, 0.05f, 20.0f);
    assert_int_equal(c.width, 800);
    assert_int_equal(c.height, 600);
    double fy = 300.0 / tan(25.0 * PI_D / 180);
    NEAR(c.fy, fy, 1e-3);
    NEAR(c.fx, c.fy, 0);
    NEAR(c.cx, 400, 0);
    NEAR(c.cy, 300, 0);
    double u, v;
    project(&c, target, &u, &v, NULL);
    NEAR(u, 400, PX_TOL);
    NEAR(v, 300, PX_TOL);
    NEAR3(origin_of(&c.world_from_cam), eye.x, eye.y, eye.z, 0);
    kin_mat4 id = kin_mat4_mul(&c.world_from_cam, &c.view);
    for (int k = 0; k < 16; k++) NEAR(id.m[k], (k % 5 == 0) ? 1 : 0, TOL);
    /* a point at the top edge of the vertical FOV lands on v = 0 */
    kin_vec3 up_edge = kin_v3(0, (float)tan(25.0 * PI_D / 180), -1);
    project(&c, kin_mat4_mul_point(&c.world_from_cam, up_edge), &u, &v, NULL);
    NEAR(u, 400, PX_TOL);
    NEAR(v, 0, PX_TOL);
    /* and the pinhole formula for seeded view-space points */
    tu_rng g = { 0x6b696e07 };
    for (int i = 0; i < 100; i++) {
        kin_vec3 pv = tu_v3b(&g, -1, 1, -1, 1, -5, -0.5f);
        project(&c, kin_mat4_mul_point(&c.world_from_cam, pv), &u, &v, NULL);
        NEAR(u, 400 + fy * pv.x / -pv.z, PX_TOL);
        NEAR(v, 300 - fy * pv.y / -pv.z, PX_TOL);
    }
}

TU_MAIN_NAMED("kin_camera", NULL, NULL,
              cmocka_unit_test(validity_desc_defaults),
              cmocka_unit_test(validity_wide_camera_crop),
              cmocka_unit_test(result_paper_numbers),
              cmocka_unit_test(result_camera_intrinsics),
              cmocka_unit_test(result_camera_centres),
              cmocka_unit_test(result_projection_pinhole),
              cmocka_unit_test(result_pixel_ray_round_trip),
              cmocka_unit_test(result_look_at_camera))
