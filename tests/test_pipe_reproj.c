/* test_pipe_reproj.c - the hands reprojected to the eye
 * (pipe_desc.eye_view = PIPE_VIEW_REPROJECT, src/pipe/pipe_reproj.h), on
 * generated scenes whose geometry is known (the paper's HMD, the head at
 * the origin looking down -Z, quads facing the eyes):
 *   - the eye-view mask equals the model drawn directly from the eye
 *     (kin_sthmd_eye_camera) pixel for pixel, 255 inside (the paper's HMD
 *     and the consumer preset's portrait display and column crop);
 *   - a point at a known depth lands where the geometry says: the camera
 *     image is a ramp of its own pixel position, so the colour each eye
 *     pixel took names the camera position it was sampled at, checked
 *     against the ray from the eye to the plane and on into the camera
 *     (the paper's pinhole, and a distorting Brown lens: no undistort
 *     pass, the lens applied where the image is sampled);
 *   - disocclusion: a small quad in front of a large one; the ring of the
 *     back quad the eye sees around the front one but the camera does not
 *     is filled from the back quad (green), never the front one's red;
 *     the fill against its rule written plainly (seeded layers: the
 *     nearest sampled pixel on the same surface in the row or column,
 *     else from the nearest row that has some);
 *   - the border of the camera's view fades over PIPE_REPROJ_FADE_PX;
 *   - soft silhouettes (pipe_desc.soft_edge) soften the eye view's mask,
 *     byte for byte pipe__soft_edge of the hard one;
 *   - the same bytes with 1 and 2 threads and every ISA cap (a recorded
 *     CRC); the crop method's bytes do not depend on the new code;
 *   - bad input: IPD and D out of range, reprojection with AA, an unknown
 *     view: pipe_create NULL and pipe_view_check names the field; the
 *     eye inside the model: the crop for that frame, counted, also
 *     alternating with reprojected frames (each frame a fresh pipe's
 *     bytes); NaN depths
 *     of the virtual scene: no crash, the hand kept there. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/cpu/ef_mem.h"
#include "../src/cpu/ef_n10.h"
#include "../src/pipe/pipe.h"
#include "../src/pipe/pipe_soft.h"
#include "support/pipe_frames.h"

enum { CAMW = 640, CAMH = 480, CW = 640, CH = 400, LCDW = 1280, LCDH = 800, CROP_Y0 = 40 };

/* Lighting that passes the camera colour through: ambient 1, nothing
 * else, so the lit layer is the sampled image times the mask. */
static pipe_lighting pass_through(void)
{
    pipe_lighting l;
    memset(&l, 0, sizeof l);
    l.light.light_count = 0;
    for (int k = 0; k < 3; k++) {
        l.light.ambient[k] = 1.0f;
        l.light.tone[k] = 1.0f;
    }
    l.light.shininess = 1.0f;
    return l;
}

/* Quads facing +Z (towards the head), centred on the view axis: quad k
 * is [-s_k, s_k]^2 at depth z_k. */
static void quads_model(kin_model *m, int n, const float *s, const float *z)
{
    tu_mesh_parts t = tu_mesh_model(m, "head", "quads", 4 * n, 6 * n, 1);
    for (int k = 0; k < n; k++) {
        const float p[12] = {-s[k], -s[k], z[k], s[k], -s[k], z[k],
                             s[k],  s[k],  z[k], -s[k], s[k], z[k]};
        memcpy(t.pos + 12 * k, p, sizeof p);
        for (int i = 0; i < 4; i++) t.nrm[12 * k + 3 * i + 2] = 1.0f;
        const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
        for (int i = 0; i < 6; i++) t.idx[6 * k + i] = ix[i] + 4u * (uint32_t)k;
    }
    char why[200];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
}

/* The six faces of a closed cube of half size s around the origin,
 * normals outward: vertices 0..23 and indices 0..35 of t. */
static void cube_faces(tu_mesh_parts t, float s)
{
    for (int f = 0; f < 6; f++) {
        int ax = f / 2;
        float sg = (f & 1) ? 1.0f : -1.0f;
        int u = (ax + 1) % 3, v = (ax + 2) % 3;
        const float cu[4] = {-1, 1, 1, -1}, cv[4] = {-1, -1, 1, 1};
        for (int i = 0; i < 4; i++) {
            float *p = t.pos + 3 * (4 * f + i);
            p[ax] = sg * s;
            p[u] = cu[i] * s;
            p[v] = cv[i] * s;
            t.nrm[3 * (4 * f + i) + ax] = sg;
        }
        const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
        for (int i = 0; i < 6; i++) t.idx[6 * f + i] = ix[i] + 4u * (uint32_t)f;
    }
}

/* A closed cube of half size s around the origin, normals outward. */
static void cube_model(kin_model *m, float s)
{
    tu_mesh_parts t = tu_mesh_model(m, "head", "cube", 24, 36, 1);
    cube_faces(t, s);
    char why[200];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
}

/* A pipe on a model with the frame buffers of one seeded frame at the
 * HMD's sizes (pipe_hmd: the paper's 640x480 cameras and 1280x800 display
 * unless the desc says else); rig_frame runs the frame into st. */
typedef struct reproj_rig {
    kin_model m;
    pipe_ctx *p;
    tu_frame_bufs b;
    pipe_frame_in in;
    pipe_frame_stats st;
    char why[200];
} reproj_rig;

static pipe_desc reproj_desc(int view, int threads, int isa)
{
    pipe_desc d;
    memset(&d, 0, sizeof d);
    d.eye_view = view;
    d.threads = threads;
    d.max_isa = isa;
    return d;
}

/* r->m already built: its pipe of d and the frame of seed. */
static void rig_start(reproj_rig *r, const pipe_desc *d, uint64_t seed)
{
    r->p = pipe_create(d, &r->m);
    assert_non_null(r->p);
    const kin_sthmd_desc hd = pipe_hmd(r->p);
    tu_frame_make(&r->b, &r->in, seed, hd.cam_width, hd.cam_height, hd.lcd_width, hd.lcd_height);
}

/* One quad of half size s at depth z, reprojected with 2 threads. */
static void rig_quad(reproj_rig *r, float s, float z, uint64_t seed)
{
    quads_model(&r->m, 1, &s, &z);
    const pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 2, 0);
    rig_start(r, &d, seed);
}

static void rig_frame(reproj_rig *r)
{
    assert_int_equal(pipe_frame(r->p, &r->in, &r->st, r->why, sizeof r->why), PIPE_OK);
}

/* rig_quad, and its frame run (rig_frame). */
static void rig_quad_frame(reproj_rig *r, float s, float z, uint64_t seed)
{
    rig_quad(r, s, z, seed);
    rig_frame(r);
}

static void rig_end(reproj_rig *r)
{
    tu_frame_free(&r->b);
    pipe_destroy(r->p);
    kin_model_free(&r->m);
}

/* The eye camera at the layer's size, as pipe_frame makes it. */
static kin_camera eye_cam(int e)
{
    return kin_sthmd_eye_camera(NULL, NULL, (kin_eye)e, CW, CH);
}

/* The model drawn from the eye into mask (CW x CH). */
static long draw_from_eye(const kin_model *m, int e, uint8_t *mask)
{
    const kin_mesh *me = &m->meshes[0];
    float *depth = malloc(sizeof(float) * CW * CH);
    float *clip = malloc(sizeof(float) * 4 * (size_t)me->vertex_count);
    assert_non_null(depth);
    assert_non_null(clip);
    rast_target t = {CW, CH, depth, CW, mask, CW, NULL, 0, 0, NULL, 0};
    rast_target_clear(&t);
    kin_camera c = eye_cam(e);
    rast_transform_points(c.view_proj.m, me->positions, me->vertex_count, clip);
    rast_mesh_desc md = {clip, me->vertex_count, NULL, 0, me->indices, me->index_count / 3,
                         RAST_CULL_NONE};
    assert_int_equal(rast_draw(&t, &md, NULL), RAST_OK);
    long n = 0;
    for (int i = 0; i < CW * CH; i++) n += mask[i] != 0;
    free(depth);
    free(clip);
    return n;
}

/* The eye-view mask M against the model drawn from the eye (ref), both
 * of n pixels: the pixels ref covers, those where M and ref disagree on
 * covered or not (*diff) and those of M at 255 (*full). */
static long mask_vs_ref(const uint8_t *M, const uint8_t *ref, size_t n, long *diff, long *full)
{
    long covered = 0;
    *diff = *full = 0;
    for (size_t i = 0; i < n; i++) {
        covered += ref[i] != 0;
        *diff += (M[i] != 0) != (ref[i] != 0);
        *full += M[i] == 255;
    }
    return covered;
}

/* Eye pixel (x, y) of the eye camera ec (CW x CH) when the mask M is 255
 * there: 1, with (*X, *Y) where the eye ray through the pixel's centre
 * meets the plane z = -d; else 0. */
static int eye_hit(const uint8_t *M, const kin_camera *ec, int x, int y, double d, double *X,
                   double *Y)
{
    if (M[(size_t)y * CW + (size_t)x] != 255) return 0;
    double rx = (x + 0.5 - ec->cx) / ec->fx, ry = -(y + 0.5 - ec->cy) / ec->fy;
    *X = ec->world_from_cam.m[12] + d * rx;
    *Y = d * ry;
    return 1;
}

/* A virtual depth of both eyes (LCDW x LCDH, freed by the caller) set in
 * in: left on the left half of the display, right on the right half. */
static float *virt_depth_halves(pipe_frame_in *in, float left, float right)
{
    float *vd = malloc(sizeof(float) * LCDW * LCDH);
    assert_non_null(vd);
    for (int y = 0; y < LCDH; y++)
        for (int x = 0; x < LCDW; x++) vd[(size_t)y * LCDW + x] = x < LCDW / 2 ? left : right;
    for (int e = 0; e < 2; e++) {
        in->virt_depth[e] = vd;
        in->virt_depth_stride[e] = LCDW;
    }
    return vd;
}

/* Two frames of the same seed at the paper's HMD sizes: (a, ia) for the
 * pipe under test, (b, ib) for the one it is compared with. */
static void twin_frames(tu_frame_bufs *a, pipe_frame_in *ia, tu_frame_bufs *b, pipe_frame_in *ib,
                        uint64_t seed)
{
    tu_frame_make(a, ia, seed, CAMW, CAMH, LCDW, LCDH);
    tu_frame_make(b, ib, seed, CAMW, CAMH, LCDW, LCDH);
}

/* The same on the "consumer" HMD (kin_sthmd_preset: 1280x1024 cameras
 * cropped to 957x1024 columns, a 2064x2208 portrait display of 96 x 100
 * degrees): the eye's layer has the crop's size and covers the display;
 * its mask equals the quad drawn from kin_sthmd_eye_camera at that size. */
static void result_mask_other_hmd(void **state)
{
    (void)state;
    reproj_rig r;
    const float s[1] = {0.05f}, z[1] = {-0.3f};
    quads_model(&r.m, 1, s, z);
    pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 0, 0);
    assert_int_equal(kin_sthmd_preset("consumer", &d.hmd), 0);
    rig_start(&r, &d, 17);
    const kin_sthmd_desc hd = pipe_hmd(r.p);
    const kin_sthmd_geometry g = pipe_geometry(r.p);
    rig_frame(&r);
    const int w = g.crop_width, h = g.crop_height;
    uint8_t *ref = malloc((size_t)w * h);
    float *depth = malloc(sizeof(float) * (size_t)w * h);
    float clip[16];
    assert_non_null(ref);
    assert_non_null(depth);
    for (int e = 0; e < 2; e++) {
        assert_int_equal(r.st.view[e], PIPE_VIEW_REPROJECT);
        int mw, mh;
        const uint8_t *M = pipe_view_mask(r.p, e, &mw, &mh);
        assert_int_equal(mw, w);
        assert_int_equal(mh, h);
        kin_camera c = kin_sthmd_eye_camera(&hd, NULL, (kin_eye)e, w, h);
        rast_target t = {w, h, depth, w, ref, w, NULL, 0, 0, NULL, 0};
        rast_target_clear(&t);
        rast_transform_points(c.view_proj.m, r.m.meshes[0].positions, 4, clip);
        rast_mesh_desc md = {clip, 4, NULL, 0, r.m.meshes[0].indices, 2, RAST_CULL_NONE};
        assert_int_equal(rast_draw(&t, &md, NULL), RAST_OK);
        long diff, full;
        const long n = mask_vs_ref(M, ref, (size_t)w * h, &diff, &full);
        print_message("NOTE consumer HMD, eye %d: layer %dx%d, %ld eye pixels, %ld differ, "
                      "%ld filled\n", e, w, h, n, diff, r.st.view_filled[e]);
        assert_true(n > 20000);
        assert_int_equal(diff, 0);
        assert_int_equal(full, n);
    }
    EF_FREE_ALL(ref, depth);
    rig_end(&r);
}

/* The eye-view mask of a quad in full view of the camera equals the quad
 * drawn from the eye: every pixel, 255 inside (no border fade, nothing
 * hidden); and it is not the crop method's mask. */
static void result_mask_equals_eye_draw(void **state)
{
    (void)state;
    reproj_rig r;
    rig_quad_frame(&r, 0.06f, -0.35f, 11);
    uint8_t *ref = malloc(CW * CH);
    assert_non_null(ref);
    for (int e = 0; e < 2; e++) {
        assert_int_equal(r.st.view[e], PIPE_VIEW_REPROJECT);
        int w, h;
        const uint8_t *M = pipe_view_mask(r.p, e, &w, &h);
        assert_non_null(M);
        assert_int_equal(w, CW);
        assert_int_equal(h, CH);
        long diff, full;
        const long n = draw_from_eye(&r.m, e, ref);
        mask_vs_ref(M, ref, (size_t)CW * CH, &diff, &full);
        print_message("NOTE eye %d: %ld eye pixels, %ld differ from the direct draw, %ld sampled, "
                      "%ld filled, %ld outside\n", e, n, diff, r.st.view_sampled[e],
                      r.st.view_filled[e], r.st.view_outside[e]);
        assert_true(n > 5000);
        assert_int_equal(diff, 0);
        assert_int_equal(full, n);
        assert_int_equal(r.st.view_outside[e], 0);
        assert_int_equal(r.st.view_sampled[e] + r.st.view_filled[e], n);
        /* the crop method's mask (the camera's, in the viewport) differs */
        const uint8_t *cm = pipe_mask(r.p, e, NULL, NULL);
        long cn = 0;
        for (int i = 0; i < CW * CH; i++) cn += cm[i] != 0;
        assert_true(cn > n + n / 4); /* the camera is D nearer: larger */
        kin_camera vc = pipe_view_camera(r.p, e);
        assert_int_equal(vc.width, CW);
        NEAR(vc.world_from_cam.m[12], e ? 0.0325f : -0.0325f, 1e-6);
        NEAR(vc.world_from_cam.m[14], 0.0f, 0);
    }
    assert_int_equal(r.st.view_fallbacks, 0);
    free(ref);
    rig_end(&r);
}

/* Soft silhouettes in the eye view (pipe_desc.soft_edge): the mask
 * composited (pipe_view_mask) is pipe__soft_edge of the same frame's eye
 * mask without them, byte for byte, in both eyes: the same pixels set, a
 * ramp at the quad's edges (values between 0 and 255 where the hard mask
 * is 255), 255 inside; the layer is lit under it. */
static void result_soft_edges(void **state)
{
    (void)state;
    reproj_rig h, s;
    rig_quad_frame(&h, 0.06f, -0.35f, 11);
    const float qs[1] = {0.06f}, qz[1] = {-0.35f};
    quads_model(&s.m, 1, qs, qz);
    pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 2, 0);
    d.soft_edge = 1;
    rig_start(&s, &d, 11);
    rig_frame(&s);
    uint8_t *ref = malloc(CW * CH);
    assert_non_null(ref);
    for (int e = 0; e < 2; e++) {
        assert_int_equal(s.st.view[e], PIPE_VIEW_REPROJECT);
        const uint8_t *Mh = pipe_view_mask(h.p, e, NULL, NULL);
        const uint8_t *Ms = pipe_view_mask(s.p, e, NULL, NULL);
        assert_non_null(Mh);
        assert_non_null(Ms);
        pipe__soft_edge(Mh, ref, CW, CH, NULL);
        assert_memory_equal(Ms, ref, (size_t)CW * CH);
        long set_h = 0, set_s = 0, ramp = 0, inside = 0;
        for (int i = 0; i < CW * CH; i++) {
            set_h += Mh[i] != 0;
            set_s += Ms[i] != 0;
            ramp += Mh[i] == 255 && Ms[i] > 0 && Ms[i] < 255;
            inside += Ms[i] == 255;
        }
        print_message("NOTE eye %d: %ld pixels set, %ld on the ramp, %ld inside\n", e, set_s,
                      ramp, inside);
        assert_int_equal(set_s, set_h);
        assert_true(ramp > 200);
        assert_true(inside > set_s / 2);
        /* the layer's alpha follows the softened mask */
        const uint8_t *L = pipe_layer(s.p, e, NULL, NULL);
        long lit_partial = 0;
        for (int i = 0; i < CW * CH; i++) lit_partial += L[4 * i + 3] > 0 && L[4 * i + 3] < 255;
        assert_true(lit_partial >= ramp / 2);
    }
    free(ref);
    rig_end(&s);
    rig_end(&h);
}

/* A camera image whose colour names its pixel: R = x - xoff, G = y - yoff
 * (sensor rows), B = 77, linear inside the quad's view. */
static void ramp_image(uint8_t *img, int xoff, int yoff)
{
    for (int y = 0; y < CAMH; y++)
        for (int x = 0; x < CAMW; x++) {
            uint8_t *q = img + ((size_t)y * CAMW + (size_t)x) * 4;
            int r = x - xoff, g = y - yoff;
            q[0] = (uint8_t)(r < 0 ? 0 : r > 255 ? 255 : r);
            q[1] = (uint8_t)(g < 0 ? 0 : g > 255 ? 255 : g);
            q[2] = 77;
            q[3] = 255;
        }
}

/* Each eye pixel of the quad at depth 0.35 m took the camera colour at
 * the point the geometry gives: eye ray -> plane -> camera (its lens:
 * kin_lens_project of the camera's view-space point; for the paper's
 * pinhole u = cx + fx X / -Z). k1 != 0: both cameras through a Brown
 * lens, the camera images then in its distorted pixels. */
static void point_lands(double k1)
{
    reproj_rig r;
    const float s[1] = {0.05f}, z[1] = {-0.35f};
    quads_model(&r.m, 1, s, z);
    pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 1, 0);
    if (k1 != 0.0) {
        for (int e = 0; e < 2; e++) {
            kin_lens *l = &d.hmd.lens[e];
            l->model = KIN_LENS_BROWN;
            l->width = CAMW;
            l->height = CAMH;
            l->fx = l->fy = 540.0;
            l->cx = 319.5;
            l->cy = 239.5;
            l->k[0] = k1;
            assert_int_equal(kin_lens_check(l, NULL, 0), 1);
        }
    }
    rig_start(&r, &d, 12);
    r.in.lighting = pass_through();
    const kin_sthmd_desc hd = pipe_hmd(r.p);
    /* the ramps centred on where each camera sees the quad's centre */
    int xoff[2];
    for (int e = 0; e < 2; e++) {
        kin_camera c = kin_sthmd_camera(&hd, NULL, (kin_eye)e);
        double pc[3] = {-c.world_from_cam.m[12], 0.0, -0.35 - c.world_from_cam.m[14]}, u, v;
        assert_int_equal(kin_lens_project(&c.lens, pc, &u, &v), 1);
        xoff[e] = (int)lround(u) - 128;
        ramp_image(r.b.cam[e], xoff[e], 112);
    }
    rig_frame(&r);
    for (int e = 0; e < 2; e++) {
        const uint8_t *Q = pipe_layer(r.p, e, NULL, NULL);
        const uint8_t *M = pipe_view_mask(r.p, e, NULL, NULL);
        kin_camera ec = eye_cam(e), cc = pipe_camera(r.p, e);
        assert_int_equal(kin_lens_distorts(&cc.lens), k1 != 0.0);
        const double cx = cc.world_from_cam.m[12], cz = cc.world_from_cam.m[14];
        long checked = 0;
        double worst = 0.0;
        for (int y = 0; y < CH; y++)
            for (int x = 0; x < CW; x++) {
                size_t i = (size_t)y * CW + (size_t)x;
                double X, Y; /* the eye ray to the plane z = -0.35 */
                if (!eye_hit(M, &ec, x, y, 0.35, &X, &Y)) continue;
                if (fabs(X) > 0.048 || fabs(Y) > 0.048) continue; /* away from the edge */
                /* into the camera (same orientation) and through its lens */
                double pc[3] = {X - cx, Y, -0.35 - cz}, u, v;
                assert_int_equal(kin_lens_project(&cc.lens, pc, &u, &v), 1);
                if (k1 == 0.0) { /* the pinhole by hand */
                    NEAR(u, cc.cx + cc.fx * (X - cx) / (0.35 + cz), 1e-3);
                    NEAR(v, cc.cy - cc.fy * Y / (0.35 + cz), 1e-3);
                }
                double eu = u - 0.5 - xoff[e], ev = v - 0.5 + CROP_Y0 - 112.0;
                if (eu < 1.0 || eu > 254.0 || ev < 1.0 || ev > 254.0) continue; /* the ramp */
                double du = fabs(Q[4 * i] - eu), dv = fabs(Q[4 * i + 1] - ev);
                if (du > worst) worst = du;
                if (dv > worst) worst = dv;
                assert_true(du <= 0.6);
                assert_true(dv <= 0.6);
                assert_int_equal(Q[4 * i + 2], 77);
                checked++;
            }
        print_message("NOTE k1 %.2f, eye %d: %ld pixels checked, worst %.3f camera px off the "
                      "geometry (D %.3f m, IPD %.3f m)\n", k1, e, checked, worst,
                      (double)hd.cam_offset_m, (double)hd.ipd_m);
        assert_true(checked > 5000);
    }
    rig_end(&r);
}

static void result_point_lands_by_geometry(void **state)
{
    (void)state;
    point_lands(0.0);
}

static void result_point_lands_through_lens(void **state)
{
    (void)state;
    point_lands(-0.2);
}

/* Front quad (red in the camera) before a back quad (green): the ring of
 * the back quad that only the eye sees is filled, and filled green. */
static void result_disocclusion_fill(void **state)
{
    (void)state;
    reproj_rig r;
    const float s[2] = {0.15f, 0.03f}, z[2] = {-0.5f, -0.3f};
    quads_model(&r.m, 2, s, z);
    const pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 2, 0);
    rig_start(&r, &d, 13);
    r.in.lighting = pass_through();
    for (int e = 0; e < 2; e++) {
        /* red where the camera's ray meets the front quad, green elsewhere */
        kin_camera c = kin_sthmd_camera(NULL, NULL, (kin_eye)e);
        double cx = c.world_from_cam.m[12], d = 0.3 + (double)c.world_from_cam.m[14];
        for (int y = 0; y < CAMH; y++)
            for (int x = 0; x < CAMW; x++) {
                double X = cx + d * (x + 0.5 - c.cx) / c.fx;
                double Y = -d * (y - CROP_Y0 + 0.5 - c.cy) / c.fy;
                int front = fabs(X) < 0.03 && fabs(Y) < 0.03;
                uint8_t *q = r.b.cam[e] + ((size_t)y * CAMW + (size_t)x) * 4;
                q[0] = front ? 255 : 0;
                q[1] = front ? 0 : 255;
                q[2] = 0;
                q[3] = 255;
            }
    }
    rig_frame(&r);
    for (int e = 0; e < 2; e++) {
        const uint8_t *Q = pipe_layer(r.p, e, NULL, NULL);
        const uint8_t *M = pipe_view_mask(r.p, e, NULL, NULL);
        kin_camera ec = eye_cam(e);
        long back = 0, red = 0, front = 0, front_red = 0;
        for (int y = 0; y < CH; y++)
            for (int x = 0; x < CW; x++) {
                size_t i = (size_t)y * CW + (size_t)x;
                double fX, fY;
                if (!eye_hit(M, &ec, x, y, 0.3, &fX, &fY)) continue;
                /* 2 eye px clear of the front quad's silhouette either way */
                double margin = 2.0 * 0.3 / ec.fx;
                if (fabs(fX) < 0.03 - margin && fabs(fY) < 0.03 - margin) {
                    front++;
                    front_red += Q[4 * i] > 200 && Q[4 * i + 1] < 55;
                } else if (fabs(fX) > 0.03 + margin || fabs(fY) > 0.03 + margin) {
                    back++;
                    red += Q[4 * i] > 100; /* any of the front's red */
                }
            }
        print_message("NOTE eye %d: back quad %ld px (%ld with red), front %ld (%ld red); "
                      "%ld filled, %ld sampled\n", e, back, red, front, front_red,
                      r.st.view_filled[e], r.st.view_sampled[e]);
        /* the ring: about 8 eye px wide on each side of a 108 px square */
        assert_true(r.st.view_filled[e] > 2000);
        assert_int_equal(red, 0);
        assert_true(front > 5000);
        assert_int_equal(front_red, front);
    }
    rig_end(&r);
}

/* A band below the crop of eq. 1: at z = -0.3 m, y from -0.092 to -0.082
 * m, the eye sees it 15-17 degrees below its axis (inside its 20), the
 * camera, 85 mm nearer, 21-23 degrees below (sensor rows about 443-468:
 * below the crop's 400 rows, 40..439, inside the 480 of the sensor). Those
 * rows of the camera image are one colour: every eye pixel of the band is
 * sampled (none filled, none outside) and takes it; the same from raw
 * RGB24 frames. */
static void result_full_sensor(void **state)
{
    (void)state;
    reproj_rig r;
    tu_mesh_parts t = tu_mesh_model(&r.m, "head", "band", 4, 6, 1);
    const float x0 = -0.05f, x1 = 0.05f, y0 = -0.092f, y1 = -0.082f, z = -0.3f;
    const float pos[12] = {x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z};
    memcpy(t.pos, pos, sizeof pos);
    for (int i = 0; i < 4; i++) t.nrm[3 * i + 2] = 1.0f;
    const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    memcpy(t.idx, ix, sizeof ix);
    assert_int_equal(kin_model_validate(&r.m, r.why, sizeof r.why), 0);
    const pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 2, 0);
    rig_start(&r, &d, 15);
    r.in.lighting = pass_through();
    for (int e = 0; e < 2; e++)
        for (int y = CROP_Y0 + CH; y < CAMH; y++)
            for (int x = 0; x < CAMW; x++) {
                uint8_t *q = r.b.cam[e] + 4 * ((size_t)y * CAMW + (size_t)x);
                q[0] = 200, q[1] = 30, q[2] = 90, q[3] = 255;
            }
    rig_frame(&r);
    uint8_t *ref = malloc(CW * CH);
    assert_non_null(ref);
    for (int e = 0; e < 2; e++) {
        assert_int_equal(r.st.view[e], PIPE_VIEW_REPROJECT);
        const long n = draw_from_eye(&r.m, e, ref);
        const uint8_t *M = pipe_view_mask(r.p, e, NULL, NULL);
        const uint8_t *Q = pipe_layer(r.p, e, NULL, NULL);
        long full = 0, colour = 0;
        for (size_t i = 0; i < (size_t)CW * CH; i++) {
            if (!M[i]) continue;
            full += M[i] == 255;
            colour += abs(Q[4 * i] - 200) <= 1 && abs(Q[4 * i + 1] - 30) <= 1 &&
                      abs(Q[4 * i + 2] - 90) <= 1;
        }
        print_message("NOTE full sensor, eye %d: %ld eye pixels of the band, %ld sampled, %ld "
                      "filled, %ld outside; %ld at 255, %ld of the sensor rows' colour\n", e, n,
                      r.st.view_sampled[e], r.st.view_filled[e], r.st.view_outside[e], full, colour);
        assert_true(n > 1000);
        assert_int_equal(r.st.view_sampled[e], n);
        assert_int_equal(r.st.view_filled[e], 0);
        assert_int_equal(r.st.view_outside[e], 0);
        assert_int_equal(full, n);
        assert_int_equal(colour, n);
    }
    /* the same frame from raw RGB24 camera frames (the pipe converts the
     * rows beyond the crop itself): the same layers */
    uint8_t *layer0 = malloc((size_t)CW * CH * 4 * 2);
    uint8_t *rgb = malloc((size_t)CAMW * CAMH * 3 * 2);
    assert_non_null(layer0);
    assert_non_null(rgb);
    for (int e = 0; e < 2; e++) {
        memcpy(layer0 + (size_t)e * CW * CH * 4, pipe_layer(r.p, e, NULL, NULL), (size_t)CW * CH * 4);
        uint8_t *r3 = rgb + (size_t)e * CAMW * CAMH * 3;
        for (size_t i = 0; i < (size_t)CAMW * CAMH; i++)
            for (int k = 0; k < 3; k++) r3[3 * i + k] = r.b.cam[e][4 * i + k];
        r.in.camera_raw[e] = (fuse_frame){r3, (size_t)CAMW * CAMH * 3, CAMW, CAMH, 3 * CAMW,
                                         FUSE_FMT_RGB24};
    }
    rig_frame(&r);
    for (int e = 0; e < 2; e++) {
        assert_int_equal(r.st.view_outside[e], 0);
        assert_memory_equal(pipe_layer(r.p, e, NULL, NULL), layer0 + (size_t)e * CW * CH * 4,
                            (size_t)CW * CH * 4);
    }
    EF_FREE_ALL(layer0, rgb, ref);
    rig_end(&r);
}

/* A quad wider than the camera's view at 0.25 m: the eye's mask is 0
 * where the camera does not see, 255 well inside, and ramps between. */
static void result_border_fade(void **state)
{
    (void)state;
    reproj_rig r;
    rig_quad_frame(&r, 0.4f, -0.25f, 14);
    for (int e = 0; e < 2; e++) {
        const uint8_t *M = pipe_view_mask(r.p, e, NULL, NULL);
        /* the middle row: 0 at both ends, 255 in the middle, and between
         * them a ramp of at most 2 * FADE / (camera px per eye px) + 2
         * pixels of each partial value run */
        const uint8_t *row = M + (size_t)(CH / 2) * CW;
        assert_int_equal(row[0], 0);
        assert_int_equal(row[CW - 1], 0);
        assert_int_equal(row[CW / 2], 255);
        int partial = 0, rising = 1;
        for (int x = 1; x < CW / 2; x++) {
            if (row[x] > 0 && row[x] < 255) partial++;
            if (row[x] < row[x - 1]) rising = 0;
        }
        print_message("NOTE eye %d: %d partial pixels on the left half of the middle row; "
                      "%ld outside\n", e, partial, r.st.view_outside[e]);
        assert_true(rising);
        assert_true(partial >= 2 && partial <= 8);
        assert_true(r.st.view_outside[e] > 1000);
    }
    rig_end(&r);
}

/* The bytes of both outputs, the layers and the masks of a random frame
 * of the two quads, with a virtual depth in front of part of them. */
static uint32_t frame_crc(const kin_model *m, int view, int threads, int isa)
{
    const pipe_desc d = reproj_desc(view, threads, isa);
    pipe_ctx *p = pipe_create(&d, m);
    assert_non_null(p);
    tu_frame_bufs b;
    pipe_frame_in in;
    tu_frame_make(&b, &in, 21, CAMW, CAMH, LCDW, LCDH);
    float *vd = virt_depth_halves(&in, 0.4f, 60.0f);
    pipe_frame_stats st;
    char why[200];
    assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
    uint32_t crc = 0;
    for (int e = 0; e < 2; e++) {
        crc = tu_crc32(crc, b.out[e], (size_t)LCDW * LCDH * 4);
        crc = tu_crc32(crc, pipe_layer(p, e, NULL, NULL), (size_t)CW * CH * 4);
        const uint8_t *M = pipe_view_mask(p, e, NULL, NULL);
        if (M) crc = tu_crc32(crc, M, (size_t)CW * CH);
    }
    free(vd);
    tu_frame_free(&b);
    pipe_destroy(p);
    return crc;
}

/* issue 18: the filled pixels from the nearest sampled one on their surface
 * in their row or column, else from the nearest row with some (was
 * 0x3ca5d031: the row's only, else the eye's mean colour) */
#define REPROJ_CRC 0x87fe27eau

static void determinism_isa_threads(void **state)
{
    (void)state;
    kin_model m;
    const float s[2] = {0.15f, 0.03f}, z[2] = {-0.5f, -0.3f};
    quads_model(&m, 2, s, z);
    const uint32_t ref = frame_crc(&m, PIPE_VIEW_REPROJECT, 1, EF_ISA_REF);
    static const int isa[] = {EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, 0};
    for (int t = 1; t <= 2; t++)
        for (size_t k = 0; k < sizeof isa / sizeof isa[0]; k++)
            assert_int_equal(frame_crc(&m, PIPE_VIEW_REPROJECT, t, isa[k]), ref);
    print_message("NOTE reprojection CRC %08x (every ISA cap, 1 and 2 threads)\n", ref);
    assert_int_equal(ref, REPROJ_CRC);
    /* the crop method is another image */
    assert_int_not_equal(frame_crc(&m, PIPE_VIEW_CROP, 2, 0), ref);
    kin_model_free(&m);
}

static void validity_bad_desc(void **state)
{
    (void)state;
    kin_model m;
    const float s[1] = {0.05f}, z[1] = {-0.35f};
    quads_model(&m, 1, s, z);
    pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, 0, 0);
    char why[200];
    assert_int_equal(pipe_view_check(&d.hmd, why, sizeof why), 0);
    d.hmd.ipd_m = 0.2f;
    assert_null(pipe_create(&d, &m));
    assert_int_equal(pipe_view_check(&d.hmd, why, sizeof why), -1);
    assert_non_null(strstr(why, "ipd_m"));
    assert_non_null(strstr(why, "0.04..0.09"));
    d.hmd.ipd_m = NAN;
    assert_null(pipe_create(&d, &m));
    d.hmd.ipd_m = 0.0f;
    d.hmd.cam_offset_m = 0.4f;
    assert_null(pipe_create(&d, &m));
    assert_int_equal(pipe_view_check(&d.hmd, why, sizeof why), -1);
    assert_non_null(strstr(why, "cam_offset_m"));
    d.hmd.cam_offset_m = -0.01f;
    assert_int_equal(pipe_view_check(&d.hmd, why, sizeof why), -1);
    d.hmd.cam_offset_m = 0.0f;
    d.aa_samples = 4;
    assert_null(pipe_create(&d, &m));
    d.aa_samples = 0;
    d.eye_view = 7;
    assert_null(pipe_create(&d, &m));
    /* the crop method does not check them (its numbers as before) */
    d.eye_view = PIPE_VIEW_CROP;
    d.hmd.ipd_m = 0.2f;
    pipe_ctx *p = pipe_create(&d, &m);
    assert_non_null(p);
    pipe_destroy(p);
    int v = -1;
    assert_int_equal(pipe_view_parse("reproject", &v), 0);
    assert_int_equal(v, PIPE_VIEW_REPROJECT);
    assert_int_equal(pipe_view_parse("crop", &v), 0);
    assert_int_equal(v, PIPE_VIEW_CROP);
    assert_int_equal(pipe_view_parse("eye", &v), -1);
    assert_string_equal(pipe_view_name(PIPE_VIEW_REPROJECT), "reproject");
    kin_model_free(&m);
}

/* The eye inside a closed cube around the head: the crop method for the
 * frame (its very bytes), counted; the next frame outside reprojects. */
static void validity_eye_inside_model(void **state)
{
    (void)state;
    kin_model m;
    cube_model(&m, 0.3f);
    const pipe_desc dr = reproj_desc(PIPE_VIEW_REPROJECT, 2, 0);
    const pipe_desc dc = reproj_desc(PIPE_VIEW_CROP, 2, 0);
    pipe_ctx *p = pipe_create(&dr, &m), *c = pipe_create(&dc, &m);
    assert_non_null(p);
    assert_non_null(c);
    tu_frame_bufs b, bc;
    pipe_frame_in in, ic;
    twin_frames(&b, &in, &bc, &ic, 15);
    pipe_frame_stats st;
    char why[200];
    assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
    assert_int_equal(pipe_frame(c, &ic, NULL, why, sizeof why), PIPE_OK);
    for (int e = 0; e < 2; e++) {
        assert_int_equal(st.view[e], PIPE_VIEW_CROP);
        assert_null(pipe_view_mask(p, e, NULL, NULL));
        assert_memory_equal(b.out[e], bc.out[e], (size_t)LCDW * LCDH * 4);
    }
    assert_int_equal(st.view_fallbacks, 2);
    /* the head 1 m back: the cube is in front, reprojected */
    kin_mat4 head = kin_mat4_from_tr(kin_v3(0, 0, 1.0f), kin_quat_identity());
    in.head_node = -1;
    in.world_from_head = &head;
    assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
    for (int e = 0; e < 2; e++) assert_int_equal(st.view[e], PIPE_VIEW_REPROJECT);
    assert_int_equal(st.view_fallbacks, 2);
    tu_frame_free(&b);
    tu_frame_free(&bc);
    pipe_destroy(p);
    pipe_destroy(c);
    kin_model_free(&m);
}

/* The fill (pipe__reproj_fill) against its rule written plainly: seeded
 * layers of sampled (kind 1) and filled (kind 2) pixels on runs of the
 * mask, their eye depths from two surfaces (near and far, a little noise),
 * random colours; each filled pixel of a flagged row takes the colour of
 * the nearest of its row's and column's nearest sampled pixels (left,
 * right, above, below; a pixel of mask 0 ends each search) among those
 * within the slack of the nearest in eye distance, or gets kind 3 when it
 * has none (its row keeps bit 0). */
static float ref_lin(float z, float n, float f)
{
    float zn = 2.0f * z - 1.0f;
    return 2.0f * f * n / ((f + n) - zn * (f - n));
}

static void result_fill_rule(void **state)
{
    (void)state;
    tu_rng g = {0x5eed18u};
    const float n = 0.05f, f = 100.0f;
    enum { FW = 41, FH = 27 };
    uint8_t rows[FH], erows[FH], M[FW * FH], P[4 * FW * FH], E[4 * FW * FH];
    float ed[FW * FH];
    long filled = 0, unresolved = 0, vertical = 0, far_skipped = 0;
    for (int it = 0; it < 1500; it++) {
        const int w = 1 + tu_int(&g, FW), h = 1 + tu_int(&g, FH);
        const int psamp = 1 + tu_int(&g, 8); /* in 10: sampled among the set pixels */
        for (int i = 0; i < w * h; i++) {
            M[i] = (uint8_t)(tu_int(&g, 4) ? 1 + tu_int(&g, 255) : 0);
            const int farp = (i / w + i % w / 7) % 3 == 0;   /* patches of the far surface */
            ed[i] = (farp ? 0.999f : 0.99f) + tu_range(&g, -0.0002f, 0.0002f);
            for (int j = 0; j < 4; j++) P[4 * i + j] = (uint8_t)tu_int(&g, 256);
            P[4 * i + 3] = (uint8_t)(M[i] ? (tu_int(&g, 10) < psamp ? 1 : 2) : tu_int(&g, 4));
        }
        for (int y = 0; y < h; y++) {
            int s2 = 0, s1 = 0;
            for (int x = 0; x < w; x++) {
                s2 |= M[y * w + x] && P[4 * (y * w + x) + 3] == 1;
                s1 |= M[y * w + x] && P[4 * (y * w + x) + 3] == 2;
            }
            rows[y] = (uint8_t)((s2 ? 2 : 0) | (s1 && tu_int(&g, 8) ? 1 : 0));
        }
        memcpy(E, P, (size_t)(4 * w * h));
        memcpy(erows, rows, (size_t)h);
#define SAMP(i) (M[i] && P[4 * (i) + 3] == 1)
        for (int y = 0; y < h; y++) {
            if (!(rows[y] & 1)) continue;
            int unres = 0;
            for (int x = 0; x < w; x++) {
                const int i = y * w + x;
                if (!M[i] || P[4 * i + 3] != 2) continue;
                int c[4], dist[4], nc = 0;
                /* each search ends at a pixel of mask 0 */
                for (int k = x - 1; k >= 0 && M[y * w + k]; k--)
                    if (SAMP(y * w + k)) { c[nc] = y * w + k, dist[nc++] = x - k; break; }
                for (int k = x + 1; k < w && M[y * w + k]; k++)
                    if (SAMP(y * w + k)) { c[nc] = y * w + k, dist[nc++] = k - x; break; }
                for (int k = y - 1; k >= 0 && M[k * w + x]; k--)
                    if (SAMP(k * w + x)) { c[nc] = k * w + x, dist[nc++] = y - k; break; }
                for (int k = y + 1; k < h && M[k * w + x]; k++)
                    if (SAMP(k * w + x)) { c[nc] = k * w + x, dist[nc++] = k - y; break; }
                if (!nc) {
                    E[4 * i + 3] = 3;
                    unres = 1;
                    unresolved++;
                    continue;
                }
                const float d0 = ref_lin(ed[i], n, f);
                float dd[4], dmin = INFINITY;
                for (int k = 0; k < nc; k++) {
                    dd[k] = fabsf(ref_lin(ed[c[k]], n, f) - d0);
                    if (dd[k] < dmin) dmin = dd[k];
                }
                const float lim = dmin + (PIPE_REPROJ_TOL_M + PIPE_REPROJ_TOL_REL * d0);
                int best = -1, nearest = -1;
                for (int k = 0; k < nc; k++) {
                    if (dd[k] <= lim && (best < 0 || dist[k] < dist[best])) best = k;
                    if (nearest < 0 || dist[k] < dist[nearest]) nearest = k;
                }
                far_skipped += dd[nearest] > lim;
                vertical += c[best] % w == x && c[best] / w != y;
                for (int j = 0; j < 3; j++) E[4 * i + j] = P[4 * c[best] + j];
                filled++;
            }
            erows[y] = (uint8_t)((rows[y] & 2) | unres);
        }
#undef SAMP
        pipe__reproj_fill(rows, w, h, M, P, ed, n, f);
        assert_memory_equal(P, E, (size_t)(4 * w * h));
        assert_memory_equal(rows, erows, (size_t)h);
    }
    print_message("NOTE %ld filled (%ld from above or below, %ld where the nearest candidate lay "
                  "on another surface), %ld without a candidate\n",
                  filled, vertical, far_skipped, unresolved);
    assert_true(filled > 20000);
    assert_true(vertical > 3000);
    assert_true(far_skipped > 1000);
    assert_true(unresolved > 50);
}

/* The pixels the fill found no candidate for (pipe__reproj_fill_cols)
 * against the rule written plainly: seeded layers of rows flagged 0, 1
 * (pixels of kind 3 to fill, none sampled), 2 (sampled pixels, at least
 * one pixel of M set) and 3 (both: kind 3 in one run, sampled ones in
 * another), P's alpha marking kinds 1-3 among the set pixels; each pixel
 * of kind 3 in a row with bit 0 takes the RGB of the nearest coloured
 * pixel (M != 0, not kind 3; the left on a tie) of the nearest other row
 * with bit 1 (above on a tie); with no such row its M becomes 0; every
 * kind 3 of those rows becomes 2. Nothing else changes. */
static void result_fill_cols_rule(void **state)
{
    (void)state;
    tu_rng g = {0xf111c015u};
    enum { FW = 37, FH = 23 };
    uint8_t rows[FH], M[FW * FH], P[4 * FW * FH], EM[FW * FH], EP[4 * FW * FH];
    int32_t near[FW];
    long from_row = 0, hidden = 0, both = 0;
    for (int it = 0; it < 2000; it++) {
        const int w = 1 + tu_int(&g, FW), h = 1 + tu_int(&g, FH);
        const int p2 = it % 7 == 0 ? 0 : 1 + tu_int(&g, 4); /* weight of sampled rows */
        for (int y = 0; y < h; y++) {
            int k = tu_int(&g, p2 + 5);
            rows[y] = (uint8_t)(k < p2 ? 2 : k < p2 + 3 ? 1 : k < p2 + 4 ? 3 : 0);
            for (int x = 0; x < w; x++) {
                const int i = y * w + x;
                M[i] = (uint8_t)(tu_int(&g, 3) ? 0 : 1 + tu_int(&g, 255));
                for (int j = 0; j < 3; j++) P[4 * i + j] = (uint8_t)tu_int(&g, 256);
                /* kinds: 3 only in rows with bit 0, 1 only in rows with bit 1 */
                const int kk = tu_int(&g, 4);
                P[4 * i + 3] = (uint8_t)(!M[i] ? 0 : (rows[y] & 1) && kk < 2 ? 3
                                                   : (rows[y] & 2) && kk < 3 ? 1 : 2);
            }
            if (rows[y] & 2) {
                const int i = y * w + tu_int(&g, w);
                M[i] = 200;
                P[4 * i + 3] = 1;
            }
            both += rows[y] == 3;
        }
        memcpy(EM, M, (size_t)(w * h));
        memcpy(EP, P, (size_t)(4 * w * h));
        for (int y = 0; y < h; y++) {
            if (!(rows[y] & 1)) continue;
            int src = -1;
            for (int d = 1; d < h && src < 0; d++) {
                if (y - d >= 0 && (rows[y - d] & 2)) src = y - d;
                else if (y + d < h && (rows[y + d] & 2)) src = y + d;
            }
            for (int x = 0; x < w; x++) {
                const int i = y * w + x;
                if (P[4 * i + 3] != 3) continue;
                EP[4 * i + 3] = 2;
                if (!M[i]) continue;
                if (src < 0) {
                    EM[i] = 0;
                    hidden++;
                    continue;
                }
                int xs = -1;
                for (int d = 0; d < w && xs < 0; d++) {
                    const int l = src * w + x - d, r = src * w + x + d;
                    if (x - d >= 0 && M[l] && P[4 * l + 3] != 3) xs = x - d;
                    else if (x + d < w && M[r] && P[4 * r + 3] != 3) xs = x + d;
                }
                for (int j = 0; j < 3; j++) EP[4 * i + j] = P[4 * (src * w + xs) + j];
                from_row++;
            }
        }
        pipe__reproj_fill_cols(rows, w, h, M, P, near);
        assert_memory_equal(M, EM, (size_t)(w * h));
        assert_memory_equal(P, EP, (size_t)(4 * w * h));
    }
    print_message("NOTE %ld pixels filled from another row, %ld hidden; %ld rows with both "
                  "kinds\n", from_row, hidden, both);
    assert_true(from_row > 20000);
    assert_true(hidden > 500);
    assert_true(both > 1000);
}

/* The sampling pass (pipe__reproj_sample) alone on every ISA against the
 * scalar reference, on seeded eye and camera G-buffers (most eye pixels
 * covered, a tenth of the camera's mask empty, the camera's depths around
 * the eye's so that both kinds occur) with the G-buffer's columns inside
 * a wider camera image (ox > 0, as the consumer preset's crop by columns,
 * but on every row): bilinear taps with one column inside the G-buffer
 * and the other beyond it (the vector taps' pair test has its own path
 * for them), at both sides. P, M and the counts equal. */
static void determinism_sample_isa(void **state)
{
    (void)state;
    tu_rng g = {0x7a95u};
    kin_sthmd_desc d = {0};
    d = kin_sthmd_desc_resolved(&d);
    const kin_mat4 I = kin_mat4_identity();
    const kin_camera cam = kin_sthmd_camera(&d, &I, KIN_EYE_LEFT);
    const int w = 640, h = 400, gw = cam.width, gh = cam.height;
    const float n = d.znear, f = d.zfar;
    const ef_isa caps[4] = {EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_DEFAULT};
    pipe__reproj r[2];
    assert_int_equal(pipe__reproj_init(&r[0], w, h, 0), 0);
    assert_int_equal(pipe__reproj_init(&r[1], w, h, 0), 0);
    long sampled = 0, filled = 0;
    for (int it = 0; it < 3; it++) {
        const int ox = 1 + tu_int(&g, 40), oy = tu_int(&g, 41);
        const int pw = gw + ox + 1 + tu_int(&g, 40), ph = gh + oy + tu_int(&g, 40);
        uint8_t *P = malloc((size_t)pw * (size_t)ph * 4), *cm = malloc((size_t)gw * (size_t)gh);
        float *cd = malloc(sizeof(float) * (size_t)gw * (size_t)gh);
        assert_non_null(P);
        assert_non_null(cm);
        assert_non_null(cd);
        const float dm = tu_range(&g, 0.15f, 0.6f);
        for (long i = 0; i < (long)pw * ph * 4; i++) P[i] = (uint8_t)tu_int(&g, 256);
        for (long i = 0; i < (long)gw * gh; i++) {
            cm[i] = tu_int(&g, 10) ? 255 : 0;
            const float z = dm * tu_range(&g, 0.9f, 1.1f);
            cd[i] = 0.5f * ((f + n) - 2.0f * f * n / z) / (f - n) + 0.5f;
        }
        for (long i = 0; i < (long)w * h; i++) {
            r[0].mask[i] = tu_int(&g, 10) ? 255 : 0;
            const float z = dm * tu_range(&g, 0.9f, 1.1f);
            r[0].depth[i] = 0.5f * ((f + n) - 2.0f * f * n / z) / (f - n) + 0.5f;
            float nv[3];
            for (int j = 0; j < 3; j++) nv[j] = tu_range(&g, -0.5f, 0.5f);
            r[0].n10[i] = ef_n10_pack(nv[0], nv[1], nv[2] + 0.5f);
        }
        memcpy(r[1].mask, r[0].mask, (size_t)w * (size_t)h);
        memcpy(r[1].depth, r[0].depth, sizeof(float) * (size_t)w * (size_t)h);
        memcpy(r[1].n10, r[0].n10, sizeof(uint32_t) * (size_t)w * (size_t)h);
        const fuse_image im = {P, pw, ph, 4 * pw};
        for (int k = -1; k < 4; k++) {
            pipe__reproj *q = &r[k < 0 ? 0 : 1];
            q->cam = kin_sthmd_eye_camera(&d, &I, KIN_EYE_LEFT, w, h);
            q->isa = k < 0 ? EF_ISA_REF : ef_isa_choose(caps[k]);
            memset(q->P, 0, (size_t)w * (size_t)h * 4);
            assert_int_equal(
                pipe__reproj_sample(q, &cam, &im, ox, oy, cm, gw, cd, gw, gw, gh, n, f), 0);
            if (k < 0) continue;
            assert_memory_equal(r[1].P, r[0].P, (size_t)w * (size_t)h * 4);
            assert_memory_equal(r[1].M, r[0].M, (size_t)w * (size_t)h);
            assert_int_equal(r[1].sampled, r[0].sampled);
            assert_int_equal(r[1].filled, r[0].filled);
            assert_int_equal(r[1].outside, r[0].outside);
        }
        sampled += r[0].sampled, filled += r[0].filled;
        free(P);
        free(cm);
        free(cd);
    }
    assert_true(sampled > 100000);
    assert_true(filled > 20000);
    pipe__reproj_free(&r[0]);
    pipe__reproj_free(&r[1]);
}

/* A closed cube of half size s around the origin (normals outward) and a
 * quad of half size q facing +Z at depth z, one mesh: from inside the
 * cube an eye falls back while its camera, D in front and outside the
 * cube, sees the quad. */
static void cube_quad_model(kin_model *m, float s, float q, float z)
{
    tu_mesh_parts t = tu_mesh_model(m, "head", "cubequad", 28, 42, 1);
    cube_faces(t, s);
    const float p[12] = {-q, -q, z, q, -q, z, q, q, z, -q, q, z};
    memcpy(t.pos + 72, p, sizeof p);
    for (int i = 0; i < 4; i++) t.nrm[72 + 3 * i + 2] = 1.0f;
    const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; i++) t.idx[36 + i] = ix[i] + 24u;
    char why[200];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
}

/* Frames alternating outside and inside the cube (the head moved between
 * the inside ones, so the camera's view of the quad moves), with culling
 * and without: every frame's bytes equal a fresh pipe's. Reprojecting,
 * the camera is drawn without normals and a fallback draws it again with
 * them into the same depth and mask planes: what the raster context
 * keeps as clear must hold across the switch. */
static void validity_fallback_alternating(void **state)
{
    (void)state;
    kin_model m;
    cube_quad_model(&m, 0.05f, 0.06f, -0.3f);
    const float hx[7] = {0.0f, 0.0f, 0.0f, 0.012f, -0.01f, 0.0f, 0.0f};
    const float hz[7] = {1.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.8f, 0.0f};
    for (int cull = 0; cull < 2; cull++) {
        pipe_desc dr = reproj_desc(PIPE_VIEW_REPROJECT, 2, 0);
        dr.cull = cull ? RAST_CULL_BACK : RAST_CULL_NONE;
        pipe_ctx *p = pipe_create(&dr, &m);
        assert_non_null(p);
        tu_frame_bufs b, bf;
        pipe_frame_in in, inf;
        twin_frames(&b, &in, &bf, &inf, 21);
        pipe_frame_stats st;
        char why[200];
        long fallbacks = 0;
        for (int k = 0; k < 7; k++) {
            const int inside = hz[k] == 0.0f;
            kin_mat4 head = kin_mat4_from_tr(kin_v3(hx[k], 0, hz[k]), kin_quat_identity());
            in.head_node = inf.head_node = -1;
            in.world_from_head = inf.world_from_head = &head;
            pipe_ctx *f = pipe_create(&dr, &m);
            assert_non_null(f);
            assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
            assert_int_equal(pipe_frame(f, &inf, NULL, why, sizeof why), PIPE_OK);
            for (int e = 0; e < 2; e++) {
                /* not culled: inside falls back (culled, the cube's
                 * faces wound inwards may still be drawn) */
                if (!cull) {
                    assert_int_equal(st.view[e], inside ? PIPE_VIEW_CROP : PIPE_VIEW_REPROJECT);
                    fallbacks += inside;
                } else {
                    fallbacks += st.view[e] == PIPE_VIEW_CROP;
                }
                assert_memory_equal(b.out[e], bf.out[e], (size_t)LCDW * LCDH * 4);
                assert_memory_equal(pipe_layer(p, e, NULL, NULL), pipe_layer(f, e, NULL, NULL),
                                    (size_t)CW * CH * 4);
            }
            assert_int_equal(st.view_fallbacks, fallbacks);
            pipe_destroy(f);
        }
        tu_frame_free(&b);
        tu_frame_free(&bf);
        pipe_destroy(p);
    }
    kin_model_free(&m);
}

/* The eye's normals are packed (ef_n10); with normal_smooth the pipe
 * unpacks them for fuse_normal_smooth. A cube seen on its edge from
 * outside (the faces' normals summed across the edges): the smoothed
 * frame is the same on every ISA cap and thread count, every eye is
 * reprojected, and its layer differs from the unsmoothed one's near the
 * edges only (inside a face the window's normals are the face's). The
 * left eye's layer is copied to layer when not NULL. */
static uint32_t smooth_crc(const kin_model *m, int smooth, int threads, int isa, uint8_t *layer)
{
    pipe_desc d = reproj_desc(PIPE_VIEW_REPROJECT, threads, isa);
    d.normal_smooth = smooth;
    pipe_ctx *p = pipe_create(&d, m);
    assert_non_null(p);
    tu_frame_bufs b;
    pipe_frame_in in;
    tu_frame_make(&b, &in, 23, CAMW, CAMH, LCDW, LCDH);
    const kin_mat4 head = kin_mat4_from_tr(kin_v3(0.09f, 0.08f, 0.2f), kin_quat_identity());
    in.head_node = -1;
    in.world_from_head = &head;
    pipe_frame_stats st;
    char why[200];
    assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
    uint32_t crc = 0;
    for (int e = 0; e < 2; e++) {
        assert_int_equal(st.view[e], PIPE_VIEW_REPROJECT);
        crc = tu_crc32(crc, b.out[e], (size_t)LCDW * LCDH * 4);
        crc = tu_crc32(crc, pipe_layer(p, e, NULL, NULL), (size_t)CW * CH * 4);
    }
    if (layer) memcpy(layer, pipe_layer(p, 0, NULL, NULL), (size_t)CW * CH * 4);
    tu_frame_free(&b);
    pipe_destroy(p);
    return crc;
}

static void determinism_smooth_normals(void **state)
{
    (void)state;
    kin_model m;
    cube_quad_model(&m, 0.05f, 0.06f, -0.3f);
    uint8_t *ls = malloc((size_t)CW * CH * 4), *l0 = malloc((size_t)CW * CH * 4);
    assert_non_null(ls);
    assert_non_null(l0);
    const uint32_t ref = smooth_crc(&m, 2, 1, EF_ISA_REF, ls);
    static const int isa[] = {EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, 0};
    for (int t = 1; t <= 2; t++)
        for (size_t k = 0; k < sizeof isa / sizeof isa[0]; k++)
            assert_int_equal(smooth_crc(&m, 2, t, isa[k], NULL), ref);
    assert_int_not_equal(smooth_crc(&m, 0, 2, 0, l0), ref);
    long lit = 0, diff = 0;
    for (size_t i = 0; i < (size_t)CW * CH; i++) {
        lit += l0[4 * i + 3] != 0;
        diff += memcmp(ls + 4 * i, l0 + 4 * i, 4) != 0;
    }
    print_message("NOTE smoothed eye layer: %ld of %ld lit pixels changed\n", diff, lit);
    assert_true(lit > 1000);
    assert_true(diff > 0 && diff < lit / 4);
    free(ls);
    free(l0);
    kin_model_free(&m);
}

/* NaN depths of the virtual scene: nothing there, the hand is kept; an
 * object in front (0.2 m) hides it; no crash, the same bytes twice. */
static void validity_nan_virtual_depth(void **state)
{
    (void)state;
    reproj_rig r;
    rig_quad(&r, 0.05f, -0.35f, 16);
    tu_frame_bufs b0;
    pipe_frame_in i0;
    tu_frame_make(&b0, &i0, 16, CAMW, CAMH, LCDW, LCDH);
    /* NaN on the left half, 0.2 m (in front of the hand) on the right */
    float *vd = virt_depth_halves(&r.in, NAN, 0.2f);
    assert_int_equal(pipe_frame(r.p, &r.in, NULL, r.why, sizeof r.why), PIPE_OK);
    assert_int_equal(pipe_frame(r.p, &i0, NULL, r.why, sizeof r.why), PIPE_OK);
    for (int e = 0; e < 2; e++) {
        long same_left = 0, left = 0, virt_right = 0, right = 0;
        for (int y = 0; y < LCDH; y++)
            for (int x = 0; x < LCDW; x++) {
                size_t i = ((size_t)y * LCDW + (size_t)x) * 4;
                int hand = memcmp(b0.out[e] + i, b0.virt[e] + i, 3) != 0;
                if (!hand) continue;
                if (x < LCDW / 2 - 2) {
                    left++;
                    same_left += !memcmp(r.b.out[e] + i, b0.out[e] + i, 4);
                } else if (x > LCDW / 2 + 2) {
                    right++;
                    virt_right += !memcmp(r.b.out[e] + i, r.b.virt[e] + i, 3);
                }
            }
        print_message("NOTE eye %d: hand %ld px left (NaN: %ld kept), %ld right (hidden %ld)\n",
                      e, left, same_left, right, virt_right);
        assert_true(left > 1000 && right > 1000);
        assert_int_equal(same_left, left);
        assert_int_equal(virt_right, right);
    }
    free(vd);
    tu_frame_free(&b0);
    rig_end(&r);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(result_mask_equals_eye_draw),
        cmocka_unit_test(result_mask_other_hmd),
        cmocka_unit_test(result_point_lands_by_geometry),
        cmocka_unit_test(result_point_lands_through_lens),
        cmocka_unit_test(result_disocclusion_fill),
        cmocka_unit_test(result_fill_rule),
        cmocka_unit_test(result_fill_cols_rule),
        cmocka_unit_test(result_border_fade),
        cmocka_unit_test(result_soft_edges),
        cmocka_unit_test(result_full_sensor),
        cmocka_unit_test(determinism_isa_threads),
        cmocka_unit_test(determinism_sample_isa),
        cmocka_unit_test(determinism_smooth_normals),
        cmocka_unit_test(validity_bad_desc),
        cmocka_unit_test(validity_eye_inside_model),
        cmocka_unit_test(validity_fallback_alternating),
        cmocka_unit_test(validity_nan_virtual_depth))
