/* test_pipe_aa.c - anti-aliased silhouettes in the pipeline
 * (pipe_desc.aa_samples, issue 14 item 3).
 *
 *   aa_area       seeded triangles through the pipe's left camera: the
 *                 coverage mask (pipe_mask) against the exact area of each
 *                 pixel inside the projected triangle (the pixel square
 *                 clipped by the triangle's three edges): the sum of the
 *                 mask matches the triangle's analytic area, every pixel is
 *                 within a bound of its exact fraction, and the error
 *                 shrinks from 4 to 16 samples; the binary mask (aa off)
 *                 is 0/255 with a per-pixel error of up to 1;
 *   aa_interior   the lit layer away from the edge is the binary
 *                 pipeline's byte for byte; at the edge its alpha is
 *                 fractional; the composite differs only near the edge;
 *   aa_state      frame 2 of a pipe (triangle moved) gives the bytes of a
 *                 fresh pipe's first frame: the coverage, the refined
 *                 coverage and the G-buffer's normals are cleared or put
 *                 back between frames;
 *   aa_refined    the refined coverage's rule (pipe__aa_refined) on a
 *                 small case: the model's coverage where the refinement
 *                 agrees in the 3x3 window, the box filter of the refined
 *                 mask elsewhere;
 *   aa_resolve    the pipe's resolve gives rast_aa_resolve's bytes;
 *   aa_band       the boundary band (pipe__aa_band) on seeded meshes of
 *                 small triangles: every pixel whose 3x3 window of the
 *                 binary mask is not uniform lies in a band tile, every
 *                 band tile has the coverage of the full sample draw byte
 *                 for byte, every other pixel the binary mask's 0 / 255;
 *   aa_args       aa_samples other than 0, 4, 8, 16: pipe_create NULL.
 * The depth test with AA on (occlusion never broken, every method) is in
 * test_occlusion.c. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/pipe/pipe.h"
#include "../src/pipe/pipe_aa.h"
#include "support/pipe_frames.h"

enum { CW = 640, CH = 400, OW = 1280, OH = 800 };

/* A model of one node ("head" at the origin) and nt unskinned triangles
 * (3 * nt vertices, view-facing normals +Z). */
static void tri_model(kin_model *m, const float *p, int nt)
{
    const int nv = 3 * nt;
    tu_mesh_parts t = tu_mesh_model(m, "head", "tri", nv, nv, 1);
    memcpy(t.pos, p, 3 * sizeof(float) * (size_t)nv);
    for (int i = 0; i < nv; i++) {
        t.nrm[3 * i + 2] = 1.0f;
        t.idx[i] = (uint32_t)i;
    }
    char why[200];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
}

/* ---- exact coverage ------------------------------------------------------ */

typedef struct pt { double x, y; } pt;

/* The part of polygon in[n] where a x + b y + c >= 0 into out; count. */
static int clip_half(const pt *in, int n, double a, double b, double c, pt *out)
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        const pt p = in[i], q = in[(i + 1) % n];
        const double dp = a * p.x + b * p.y + c, dq = a * q.x + b * q.y + c;
        if (dp >= 0) out[k++] = p;
        if ((dp >= 0) != (dq >= 0)) {
            const double t = dp / (dp - dq);
            out[k++] = (pt){p.x + t * (q.x - p.x), p.y + t * (q.y - p.y)};
        }
    }
    return k;
}

static double poly_area(const pt *p, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++) s += p[i].x * p[(i + 1) % n].y - p[(i + 1) % n].x * p[i].y;
    return fabs(s) * 0.5;
}

/* The triangle's screen vertices through cam (the rasterizer's viewport). */
static void project(const kin_camera *cam, const float *p, pt s[3])
{
    const float *m = cam->view_proj.m;
    for (int i = 0; i < 3; i++) {
        const float x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
        double c[4];
        for (int r = 0; r < 4; r++)
            c[r] = (double)m[r] * x + (double)m[4 + r] * y + (double)m[8 + r] * z + (double)m[12 + r];
        s[i].x = (c[0] / c[3] * 0.5 + 0.5) * CW;
        s[i].y = (0.5 - c[1] / c[3] * 0.5) * CH;
    }
}

/* Fraction of pixel (x, y) inside triangle s. */
static double pixel_frac(const pt s[3], int x, int y)
{
    pt a[16], b[16];
    int n = 4;
    a[0] = (pt){x, y};
    a[1] = (pt){x + 1, y};
    a[2] = (pt){x + 1, y + 1};
    a[3] = (pt){x, y + 1};
    const double orient = (s[1].x - s[0].x) * (s[2].y - s[0].y) - (s[1].y - s[0].y) * (s[2].x - s[0].x);
    for (int k = 0; k < 3 && n > 0; k++) {
        const pt p = s[k], q = s[(k + 1) % 3];
        /* inside: the side of the third vertex */
        double A = -(q.y - p.y), B = q.x - p.x, C = -(A * p.x + B * p.y);
        if (orient < 0) A = -A, B = -B, C = -C;
        n = clip_half(a, n, A, B, C, b);
        memcpy(a, b, sizeof(pt) * (size_t)n);
    }
    return n >= 3 ? poly_area(a, n) : 0.0;
}

typedef struct area_err {
    double sum, area, perimeter, max_err, mean_edge_err;
    int values_binary;
} area_err;

/* A pipe of m (threads, aa_samples aa) after one frame of the camera
 * images of seed, held in b (tu_frame_free and pipe_destroy them). */
static pipe_ctx *aa_frame(const kin_model *m, int threads, int aa, uint64_t seed, tu_frame_bufs *b)
{
    pipe_desc d = {0};
    d.threads = threads;
    d.aa_samples = aa;
    pipe_ctx *p = pipe_create(&d, m);
    assert_non_null(p);
    pipe_frame_in in;
    tu_frame_make(b, &in, seed, 640, 480, OW, OH);
    char why[200];
    assert_int_equal(pipe_frame(p, &in, NULL, why, sizeof why), PIPE_OK);
    return p;
}

/* One triangle (world = head frame: head at the origin) through a pipe
 * with aa samples: the mask of the left eye against the exact coverage. */
static area_err run_triangle(const float *tri, int aa)
{
    kin_model m;
    tri_model(&m, tri, 1);
    tu_frame_bufs b;
    pipe_ctx *p = aa_frame(&m, 1, aa, 7, &b);
    int w, h;
    const uint8_t *mask = pipe_mask(p, 0, &w, &h);
    assert_int_equal(w, CW);
    assert_int_equal(h, CH);
    kin_camera cam = pipe_camera(p, 0);
    pt s[3];
    project(&cam, tri, s);
    area_err r = {0};
    r.values_binary = 1;
    long edge = 0;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            const double f = pixel_frac(s, x, y), v = mask[(size_t)y * CW + x] / 255.0;
            r.sum += v;
            r.area += f;
            const double err = fabs(v - f);
            if (err > r.max_err) r.max_err = err;
            if (f > 0.0 && f < 1.0) {
                r.mean_edge_err += err;
                edge++;
            }
            if (mask[(size_t)y * CW + x] != 0 && mask[(size_t)y * CW + x] != 255)
                r.values_binary = 0;
        }
    r.mean_edge_err /= edge > 0 ? (double)edge : 1.0;
    for (int k = 0; k < 3; k++)
        r.perimeter += hypot(s[(k + 1) % 3].x - s[k].x, s[(k + 1) % 3].y - s[k].y);
    tu_frame_free(&b);
    pipe_destroy(p);
    kin_model_free(&m);
    return r;
}

static void aa_area(void **state)
{
    (void)state;
    tu_rng rng = {20261127};
    const int counts[4] = {0, 4, 8, 16};
    double worst_mean[4] = {0}, worst_max[4] = {0};
    for (int t = 0; t < 6; t++) {
        /* a triangle 0.5-0.7 m in front of the head, inside the view */
        float tri[9];
        for (int i = 0; i < 3; i++) {
            tri[3 * i] = tu_range(&rng, -0.12f, 0.12f);
            tri[3 * i + 1] = tu_range(&rng, -0.08f, 0.08f);
            tri[3 * i + 2] = -tu_range(&rng, 0.5f, 0.7f);
        }
        for (int c = 0; c < 4; c++) {
            area_err r = run_triangle(tri, counts[c]);
            printf("triangle %d aa %2d: area %.2f px, mask sum %.2f (%+.2f), perimeter %.1f, "
                   "edge pixels mean |err| %.4f, max |err| %.3f\n",
                   t, counts[c], r.area, r.sum, r.sum - r.area, r.perimeter, r.mean_edge_err,
                   r.max_err);
            assert_true(r.area > 500.0);
            if (counts[c] == 0) {
                assert_true(r.values_binary);
                /* centre sampling: the area within a fraction of the
                 * perimeter, pixels off by up to (almost) 1 */
                assert_true(fabs(r.sum - r.area) <= 0.25 * r.perimeter + 1.0);
            } else {
                assert_false(r.values_binary);
                /* n samples: the sum within perimeter / n of the area */
                assert_true(fabs(r.sum - r.area) <= r.perimeter / counts[c] + 1.0);
                assert_true(r.mean_edge_err < 0.5 / counts[c] + 0.04);
            }
            if (r.mean_edge_err > worst_mean[c]) worst_mean[c] = r.mean_edge_err;
            if (r.max_err > worst_max[c]) worst_max[c] = r.max_err;
        }
    }
    printf("worst mean |err| of edge pixels: binary %.3f, aa4 %.3f, aa8 %.3f, aa16 %.3f\n",
           worst_mean[0], worst_mean[1], worst_mean[2], worst_mean[3]);
    printf("worst max |err|: binary %.3f, aa4 %.3f, aa8 %.3f, aa16 %.3f\n", worst_max[0],
           worst_max[1], worst_max[2], worst_max[3]);
    /* more samples, closer to the exact coverage */
    assert_true(worst_mean[1] < 0.5 * worst_mean[0]);
    assert_true(worst_mean[3] < worst_mean[1]);
    assert_true(worst_max[3] <= 0.2);
    assert_true(worst_max[0] > 0.5);
}

/* Two triangles sharing an edge (a quad, tilted): the shared edge leaves
 * no seam in the coverage (each sample is covered once). */
static const float quad_tris[18] = {
    -0.10f, -0.07f, -0.55f, 0.11f, -0.05f, -0.60f, 0.09f, 0.08f, -0.62f,
    -0.10f, -0.07f, -0.55f, 0.09f, 0.08f, -0.62f, -0.12f, 0.06f, -0.57f,
};

static void aa_interior(void **state)
{
    (void)state;
    kin_model m;
    tri_model(&m, quad_tris, 2);
    uint8_t *layer[2], *out[2], *mask[2];
    for (int k = 0; k < 2; k++) {
        tu_frame_bufs b;
        pipe_ctx *p = aa_frame(&m, 2, k ? 16 : 0, 11, &b);
        layer[k] = malloc((size_t)CW * CH * 4);
        mask[k] = malloc((size_t)CW * CH);
        out[k] = malloc((size_t)OW * OH * 4);
        memcpy(layer[k], pipe_layer(p, 0, NULL, NULL), (size_t)CW * CH * 4);
        memcpy(mask[k], pipe_mask(p, 0, NULL, NULL), (size_t)CW * CH);
        memcpy(out[k], b.out[0], (size_t)OW * OH * 4);
        tu_frame_free(&b);
        pipe_destroy(p);
    }
    long inner = 0, frac = 0, seam = 0;
    for (int y = 1; y < CH - 1; y++)
        for (int x = 1; x < CW - 1; x++) {
            int all = 1;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    all &= mask[1][(size_t)(y + dy) * CW + x + dx] == 255 &&
                           mask[0][(size_t)(y + dy) * CW + x + dx] == 255;
            const size_t i = (size_t)y * CW + x;
            if (all) {
                inner++;
                assert_memory_equal(layer[1] + 4 * i, layer[0] + 4 * i, 4);
            }
            if (mask[1][i] > 0 && mask[1][i] < 255) {
                frac++;
                assert_true(layer[1][4 * i + 3] > 0 && layer[1][4 * i + 3] < 255);
            }
            /* the quad's diagonal: inside the binary mask, neither
             * neighbour across it may lose coverage */
            if (mask[0][i] == 255 && mask[1][i] < 255) {
                int nb = 1;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++)
                        nb &= mask[0][(size_t)(y + dy) * CW + x + dx] == 255;
                seam += nb;
            }
        }
    printf("quad: %ld interior pixels identical, %ld fractional edge pixels, %ld seam pixels\n",
           inner, frac, seam);
    assert_true(inner > 5000);
    assert_true(frac > 200);
    assert_int_equal(seam, 0);
    /* the composite differs only within 3 output pixels of a layer pixel
     * whose mask differs */
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    long diff = 0, far = 0;
    for (int y = 0; y < OH; y++)
        for (int x = 0; x < OW; x++) {
            const size_t i = ((size_t)y * OW + x) * 4;
            if (!memcmp(out[0] + i, out[1] + i, 4)) continue;
            diff++;
            int lx = (int)((x - g.vp_x0 + 0.5) * CW / g.vp_width);
            int ly = (int)((y - g.vp_y0 + 0.5) * CH / g.vp_height);
            int near = 0;
            for (int dy = -2; dy <= 2 && !near; dy++)
                for (int dx = -2; dx <= 2 && !near; dx++) {
                    int xx = lx + dx, yy = ly + dy;
                    if (xx < 0 || yy < 0 || xx >= CW || yy >= CH) continue;
                    near = mask[0][(size_t)yy * CW + xx] != mask[1][(size_t)yy * CW + xx];
                }
            far += !near;
        }
    printf("composite: %ld output pixels differ, %ld of them away from the edge\n", diff, far);
    assert_true(diff > 0);
    assert_int_equal(far, 0);
    for (int k = 0; k < 2; k++) {
        free(layer[k]);
        free(mask[k]);
        free(out[k]);
    }
    kin_model_free(&m);
}

/* Frame 2 of a pipe = frame 1 of a fresh pipe (the triangle moved). */
static void aa_state_case(int refine, int smooth)
{
    kin_model m;
    tri_model(&m, quad_tris, 2);
    kin_mat4 heads[2] = {kin_mat4_identity(), kin_mat4_identity()};
    heads[0].m[12] = 0.06f;   /* the head 6 cm right, then back */
    heads[0].m[13] = -0.03f;
    uint32_t crc_second = 0, crc_fresh = 0;
    for (int k = 0; k < 2; k++) {
        pipe_desc d = {0};
        d.threads = 1;
        d.aa_samples = 8;
        d.refine_band = refine;
        d.normal_smooth = smooth;
        pipe_ctx *p = pipe_create(&d, &m);
        assert_non_null(p);
        tu_frame_bufs b;
        pipe_frame_in in;
        tu_frame_make(&b, &in, 5, 640, 480, OW, OH);
        in.head_node = -1;
        char why[200];
        for (int f = k ? 1 : 0; f < 2; f++) {
            in.world_from_head = &heads[f];
            assert_int_equal(pipe_frame(p, &in, NULL, why, sizeof why), PIPE_OK);
        }
        uint32_t c = 0;
        for (int e = 0; e < 2; e++) {
            c = tu_crc32(c, b.out[e], (size_t)OW * OH * 4);
            c = tu_crc32(c, pipe_mask(p, e, NULL, NULL), (size_t)CW * CH);
            c = tu_crc32(c, pipe_layer(p, e, NULL, NULL), (size_t)CW * CH * 4);
        }
        if (k) crc_fresh = c;
        else crc_second = c;
        tu_frame_free(&b);
        pipe_destroy(p);
    }
    assert_int_equal(crc_second, crc_fresh);
    kin_model_free(&m);
}

static void aa_state(void **state)
{
    (void)state;
    aa_state_case(0, 0);
    aa_state_case(6, 0);
    aa_state_case(0, 1);
}

static void aa_refined(void **state)
{
    (void)state;
    enum { W = 12, H = 10 };
    pipe__aa a;
    assert_int_equal(pipe__aa_init(&a, 4, W, H, 1), 0);
    uint8_t mask[W * H], ref[W * H];
    memset(mask, 0, sizeof mask);
    for (int y = 2; y < 8; y++)
        for (int x = 2; x < 6; x++) mask[y * W + x] = 255;
    memcpy(ref, mask, sizeof ref);
    for (int y = 2; y < 8; y++) ref[y * W + 6] = ref[y * W + 7] = 255; /* grown right */
    for (int i = 0; i < W * H; i++) a.cov[i] = (uint8_t)(mask[i] ? 200 : 0);
    a.cov[1 * W + 3] = 64;                      /* a fringe pixel above */
    a.box[0] = 1, a.box[1] = 1, a.box[2] = 7, a.box[3] = 9;
    pipe__aa_refined(&a, mask, ref, 2);
    /* away from the flips: the coverage */
    assert_int_equal(a.soft[1 * W + 3], 64);
    assert_int_equal(a.soft[4 * W + 3], 200);
    assert_int_equal(a.soft[4 * W + 0], 0);
    /* next to a flip: the 3x3 box of the refined mask */
    assert_int_equal(a.soft[4 * W + 5], 255);           /* 9 of 9 */
    assert_int_equal(a.soft[4 * W + 7], 170);           /* 6 of 9 */
    assert_int_equal(a.soft[4 * W + 8], 85);            /* 3 of 9 */
    assert_int_equal(a.soft[2 * W + 8], 57);            /* 2 of 9: round(56.67) */
    assert_int_equal(a.soft[4 * W + 9], 0);             /* no flip near: cov 0 */
    /* the next frame starts clear */
    pipe__aa_begin(&a);
    for (int i = 0; i < W * H; i++) {
        assert_int_equal(a.soft[i], 0);
        assert_int_equal(a.cov[i], 0);
    }
    pipe__aa_free(&a);
}

/* pipe__aa_resolve (a byte table) gives rast_aa_resolve's bytes, inside
 * the box only, for every sample count. */
static void aa_resolve(void **state)
{
    (void)state;
    enum { W = 37, H = 23 };
    tu_rng r = {99};
    const int counts[3] = {4, 8, 16};
    for (int c = 0; c < 3; c++) {
        pipe__aa a;
        assert_int_equal(pipe__aa_init(&a, counts[c], W, H, 0), 0);
        for (int i = 0; i < W * H; i++) a.samples[i] = (uint32_t)tu_next(&r);
        a.box[0] = 3, a.box[1] = 2, a.box[2] = 30, a.box[3] = 21;
        pipe__aa_resolve(&a);
        uint8_t ref[W * H];
        rast_aa_target t = {W, H, a.samples, W, counts[c]};
        assert_int_equal(rast_aa_resolve(&t, ref, W), RAST_OK);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                const int in = x >= 3 && x < 30 && y >= 2 && y < 21;
                assert_int_equal(a.cov[y * W + x], in ? ref[y * W + x] : 0);
            }
        pipe__aa_free(&a);
    }
}

/* seeded small triangles (clip w = 1, some off the target, one through
 * the eye plane), the binary mask by rast_draw and the coverage with and
 * without the band */
static void aa_band(void **state)
{
    (void)state;
    enum { W = 160, H = 120, NT = 300 };
    const int counts[2] = {4, 16};
    for (int seed = 1; seed <= 6; seed++) {
        tu_rng r = {(uint64_t)seed * 7919u};
        float clip[4 * 3 * NT];
        uint32_t idx[3 * NT];
        for (int t = 0; t < NT; t++) {
            /* clusters: blobs with holes and slivers between them */
            const float cx = tu_range(&r, -1.1f, 1.1f), cy = tu_range(&r, -1.1f, 1.1f);
            const float sz = t % 17 == 0 ? 0.4f : 0.08f;
            for (int k = 0; k < 3; k++) {
                float *v = clip + 4 * (3 * t + k);
                v[0] = cx + tu_range(&r, -sz, sz);
                v[1] = cy + tu_range(&r, -sz, sz);
                v[2] = 0.5f;
                v[3] = 1.0f;
                idx[3 * t + k] = (uint32_t)(3 * t + k);
            }
        }
        clip[4 * 5 + 3] = -0.5f; /* triangle 1: a vertex behind the eye */
        clip[4 * 5 + 2] = -0.7f;
        uint8_t mask[W * H];
        rast_target tg = {W, H, NULL, 0, mask, W, NULL, 0, 0, NULL, 0};
        rast_target_clear(&tg);
        rast_mesh_desc d = {clip, 3 * NT, NULL, 0, idx, NT, RAST_CULL_NONE};
        assert_int_equal(rast_draw(&tg, &d, NULL), RAST_OK);
        for (int c = 0; c < 2; c++) {
            pipe__aa a;
            assert_int_equal(pipe__aa_init(&a, counts[c], W, H, 0), 0);
            pipe__aa_begin(&a);
            assert_int_equal(pipe__aa_draw(&a, NULL, clip, 3 * NT, idx, NT, RAST_CULL_NONE),
                             RAST_OK);
            pipe__aa_resolve(&a);
            uint8_t full[W * H];
            memcpy(full, a.cov, sizeof full);
            pipe__aa_begin(&a);
            pipe__aa_band(&a, mask);
            assert_int_equal(pipe__aa_draw(&a, NULL, clip, 3 * NT, idx, NT, RAST_CULL_NONE),
                             RAST_OK);
            pipe__aa_resolve(&a);
            int band_tiles = 0, band_px = 0, differ = 0;
            for (int i = 0; i < a.tw * a.th; i++) band_tiles += a.tile[i];
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    const int in =
                        a.tile[(y / PIPE__AA_TILE) * a.tw + x / PIPE__AA_TILE] != 0;
                    int uniform = 1;
                    for (int yy = y - 1; yy <= y + 1; yy++)
                        for (int xx = x - 1; xx <= x + 1; xx++)
                            if (yy >= 0 && yy < H && xx >= 0 && xx < W &&
                                (mask[yy * W + xx] != 0) != (mask[y * W + x] != 0))
                                uniform = 0;
                    if (!uniform) assert_true(in);
                    band_px += in;
                    const int want = in ? full[y * W + x] : mask[y * W + x] ? 255 : 0;
                    if (a.cov[y * W + x] != want)
                        fail_msg("seed %d aa %d: (%d, %d) %d, want %d (band %d)", seed,
                                 counts[c], x, y, a.cov[y * W + x], want, in);
                    differ += a.cov[y * W + x] != full[y * W + x];
                }
            /* the band is a part of the target, and most of the model's
             * edge pixels agree with the full draw */
            assert_true(band_tiles > 0 && band_tiles < a.tw * a.th);
            if (seed == 1)
                printf("seed %d aa %2d: %d band tiles of %d (%d px), %d px differ from the full "
                       "draw\n",
                       seed, counts[c], band_tiles, a.tw * a.th, band_px, differ);
            assert_true(differ * 20 < band_px);
            pipe__aa_free(&a);
        }
    }
}

static void aa_args(void **state)
{
    (void)state;
    kin_model m;
    tri_model(&m, quad_tris, 2);
    const int bad[] = {1, 2, 3, -1, 5, 12, 32};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pipe_desc d = {0};
        d.aa_samples = bad[i];
        assert_null(pipe_create(&d, &m));
    }
    const int good[] = {0, 4, 8, 16};
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        pipe_desc d = {0};
        d.aa_samples = good[i];
        pipe_ctx *p = pipe_create(&d, &m);
        assert_non_null(p);
        pipe_destroy(p);
    }
    kin_model_free(&m);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(aa_area),     cmocka_unit_test(aa_interior),
        cmocka_unit_test(aa_state),    cmocka_unit_test(aa_refined),
        cmocka_unit_test(aa_resolve),  cmocka_unit_test(aa_args),
        cmocka_unit_test(aa_band))
