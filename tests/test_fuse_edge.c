/* test_fuse_edge.c - soft viewport edges (src/fuse/fuse_edge.h, issue 18
 * item 4): the ramp against a double-precision reference on seeded
 * layers (every size down to 1x1, ramps wider than the layer, every side
 * set), only the border strips touched, r, g, b <= a kept; every width
 * and byte value against the integer division (exact_every_width); the float
 * weight at pixel centres; fuse_context_frame with edge_fade giving the
 * bytes of light -> fade -> depth -> composite by hand on every ISA and
 * thread count; bad arguments refused; and the pipeline's default: an
 * opaque white quad filling the camera's view, composited over black,
 * must not end in a hard cut at the viewport's edges (the test fails with
 * edge_fade -1, the old behaviour), and edge_fade -1 gives exactly the
 * bytes of the stages without a fade. */
#include "support/testutil.h"

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/cpu/cpu.h"
#include "../src/fuse/fuse_edge.h"
#include "../src/pipe/pipe.h"
#include "support/pipe_frames.h"
#include "../src/cpu/ef_mem.h"

/* the ramp by its definition, in double: clamp(d / k) at the pixel's
 * centre, d the distance to the nearest faded side; q * weight rounded
 * half up (ties exist: the weights are (2i + 1) / 2k) */
static uint8_t ref_fade(uint8_t q, int x, int y, int w, int h, int k, unsigned sides)
{
    double d = 1e30, wt;
    if (sides & FUSE_EDGE_LEFT) d = fmin(d, x + 0.5);
    if (sides & FUSE_EDGE_RIGHT) d = fmin(d, w - x - 0.5);
    if (sides & FUSE_EDGE_TOP) d = fmin(d, y + 0.5);
    if (sides & FUSE_EDGE_BOTTOM) d = fmin(d, h - y - 0.5);
    if (k < 1 || d >= k) return q;
    /* q d / k rounded half up, in exact integers: 2d is odd */
    wt = floor((q * (2.0 * d) + k) / (2.0 * k));
    return (uint8_t)wt;
}

static void premul_random(tu_rng *r, uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i += 4) {
        const uint8_t a = (uint8_t)tu_int(r, 256);
        p[i + 3] = a;
        for (int c = 0; c < 3; c++) p[i + c] = (uint8_t)tu_int(r, a + 1);
    }
}

static void against_reference(void **state)
{
    (void)state;
    tu_rng r = {18004};
    for (int n = 0; n < 600; n++) {
        const int w = 1 + tu_int(&r, n < 100 ? 9 : 70), h = 1 + tu_int(&r, n < 100 ? 9 : 50);
        const int k = tu_int(&r, 13), pad = tu_int(&r, 3) * 4;
        const unsigned sides = (unsigned)tu_int(&r, 16);
        const int stride = 4 * w + pad;
        uint8_t *q = malloc((size_t)stride * h), *q0 = malloc((size_t)stride * h);
        assert_non_null(q);
        assert_non_null(q0);
        premul_random(&r, q, (size_t)stride * h);
        memcpy(q0, q, (size_t)stride * h);
        fuse_image Q = {q, w, h, stride};
        assert_int_equal(fuse_edge_fade(&Q, k, sides), FUSE_OK);
        for (int y = 0; y < h; y++) {
            for (int x = 0; x < w; x++) {
                const uint8_t *a = q0 + (size_t)y * stride + 4 * x, *b = q + (size_t)y * stride + 4 * x;
                for (int c = 0; c < 4; c++) assert_int_equal(b[c], ref_fade(a[c], x, y, w, h, k, sides));
                assert_true(b[0] <= b[3] && b[1] <= b[3] && b[2] <= b[3]);
            }
            /* the padding is never written */
            assert_memory_equal(q + (size_t)y * stride + 4 * w, q0 + (size_t)y * stride + 4 * w, pad);
        }
        free(q);
        free(q0);
    }
}

/* Every width 1..FUSE_EDGE_FADE_MAX, every pixel distance and byte value:
 * a row of 2k pixels faded from the left holds q t / 2k rounded half up
 * at its pixel i (t = 2i + 1; the division is done by a multiplication). */
static void exact_every_width(void **state)
{
    (void)state;
    static uint8_t row[4 * 2 * FUSE_EDGE_FADE_MAX];
    for (int k = 1; k <= FUSE_EDGE_FADE_MAX; k++)
        for (int q = 0; q < 256; q++) {
            memset(row, q, sizeof row);
            fuse_edge_fade_row(row, 0, 2 * k, 1, k, FUSE_EDGE_LEFT);
            for (int i = 0; i < 2 * k; i++) {
                const int want = i < k ? (q * (2 * i + 1) + k) / (2 * k) : q;
                for (int c = 0; c < 4; c++) assert_int_equal(row[4 * i + c], want);
            }
        }
}

static void weight_at_centres(void **state)
{
    (void)state;
    for (int k = 1; k <= 8; k++)
        for (int i = 0; i < 12; i++) {
            const float want = i < k ? (2.0f * i + 1.0f) / (2.0f * k) : 1.0f;
            /* left side of a 40 x 30 image, the middle row */
            assert_true(fabsf(fuse_edge_weight(i + 0.5f, 15.0f, 40, 30, k, FUSE_EDGE_ALL) - want) < 1e-6f);
            /* bottom side */
            assert_true(fabsf(fuse_edge_weight(20.0f, 30 - i - 0.5f, 40, 30, k, FUSE_EDGE_BOTTOM) - want) <
                        1e-6f);
        }
    assert_true(fuse_edge_weight(0.0f, 5.0f, 40, 30, 4, FUSE_EDGE_ALL) == 0.0f);
    assert_true(fuse_edge_weight(-3.0f, 5.0f, 40, 30, 4, FUSE_EDGE_ALL) == 0.0f);
    assert_true(fuse_edge_weight(0.0f, 15.0f, 40, 30, 4, FUSE_EDGE_RIGHT) == 1.0f);
    assert_true(fuse_edge_weight(1.0f, 1.0f, 40, 30, 0, FUSE_EDGE_ALL) == 1.0f);
    assert_true(fuse_edge_weight(NAN, 1.0f, 40, 30, 4, FUSE_EDGE_ALL) == 0.0f);
    assert_true(fuse_edge_weight(1.0f, 1.0f, 0, 30, 4, FUSE_EDGE_ALL) == 0.0f);
}

static void bad_args(void **state)
{
    (void)state;
    uint8_t px[64];
    fuse_image Q = {px, 4, 4, 16};
    assert_int_equal(fuse_edge_fade(NULL, 4, FUSE_EDGE_ALL), FUSE_ERR_ARGS);
    assert_int_equal(fuse_edge_fade(&Q, -1, FUSE_EDGE_ALL), FUSE_ERR_ARGS);
    assert_int_equal(fuse_edge_fade(&Q, FUSE_EDGE_FADE_MAX + 1, FUSE_EDGE_ALL), FUSE_ERR_ARGS);
    assert_int_equal(fuse_edge_fade(&Q, 4, 16u), FUSE_ERR_ARGS);
    Q.stride = 15;
    assert_int_equal(fuse_edge_fade(&Q, 4, FUSE_EDGE_ALL), FUSE_ERR_ARGS);
    Q.stride = 16;
    Q.pixels = NULL;
    assert_int_equal(fuse_edge_fade(&Q, 4, FUSE_EDGE_ALL), FUSE_ERR_ARGS);
    /* fuse_context_frame refuses a bad width or side set, writes nothing */
    fuse_context *ctx = fuse_context_create(NULL);
    assert_non_null(ctx);
    static uint8_t P[8 * 8 * 4], M[8 * 8], L[8 * 8 * 4], V[16 * 16 * 4], O[16 * 16 * 4];
    static float N[8 * 8 * 3];
    memset(O, 0x5A, sizeof O);
    fuse_lighting lt = fuse_lighting_default();
    fuse_intrinsics K = {8, 8, 4, 4};
    fuse_eye e = {0};
    e.lighting = &lt;
    e.intrinsics = &K;
    e.P = (fuse_image){P, 8, 8, 32};
    e.mask = M;
    e.mask_stride = 8;
    e.normal = N;
    e.normal_stride = 24;
    e.Q = (fuse_image){L, 8, 8, 32};
    e.V = (fuse_image){V, 16, 16, 64};
    e.vp_x0 = 2;
    e.vp_y0 = 2;
    e.vp_w = 12;
    e.vp_h = 12;
    e.out = (fuse_image){O, 16, 16, 64};
    e.edge_fade = FUSE_EDGE_FADE_MAX + 1;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_ERR_ARGS);
    e.edge_fade = 4;
    e.edge_sides = 0x10;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_ERR_ARGS);
    for (size_t i = 0; i < sizeof O; i++) assert_int_equal(O[i], 0x5A);
    e.edge_sides = FUSE_EDGE_ALL;
    assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_OK);
    fuse_context_destroy(ctx);
    /* pipe_create refuses a width out of range */
    kin_model m;
    tu_quad_model(&m, 1.0f, -1.0f, 0.0f, "quad");
    pipe_desc d = {0};
    d.edge_fade = -2;
    assert_null(pipe_create(&d, &m));
    d.edge_fade = FUSE_EDGE_FADE_MAX + 1;
    assert_null(pipe_create(&d, &m));
    d.edge_fade = FUSE_EDGE_FADE_MAX;
    pipe_ctx *p = pipe_create(&d, &m);
    assert_non_null(p);
    pipe_destroy(p);
    kin_model_free(&m);
}

/* fuse_context_frame with the fade (and a depth test) on every ISA and 1, 2
 * or 3 threads: the bytes of fuse_light, fuse_edge_fade, fuse_depth_test and
 * fuse_composite called one after the other. */
static void frame_every_isa(void **state)
{
    (void)state;
    tu_rng r = {1804};
    const ef_isa isas[] = {EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_AVX512, EF_ISA_NEON};
    int ran = 0;
    for (int n = 0; n < 40; n++) {
        const int w = 16 + tu_int(&r, 90), h = 12 + tu_int(&r, 60);
        const int ow = w * 2 + tu_int(&r, 20), oh = h * 2 + tu_int(&r, 20);
        const int vx = tu_int(&r, ow - w * 2 + 1), vy = tu_int(&r, oh - h * 2 + 1);
        const int vw = w * 2, vh = h * 2, k = 1 + tu_int(&r, 8);
        const unsigned sides = (unsigned)tu_int(&r, 16);
        uint8_t *P = malloc((size_t)w * h * 4), *M = malloc((size_t)w * h);
        uint8_t *Q = malloc((size_t)w * h * 4), *V = malloc((size_t)ow * oh * 4);
        uint8_t *want = malloc((size_t)ow * oh * 4), *got = malloc((size_t)ow * oh * 4);
        float *N = malloc(sizeof(float) * 3 * (size_t)w * h);
        float *hd = malloc(sizeof(float) * (size_t)w * h), *sd = malloc(sizeof(float) * (size_t)ow * oh);
        assert_true(P && M && Q && V && want && got && N && hd && sd);
        for (int i = 0; i < w * h * 4; i++) P[i] = (uint8_t)tu_int(&r, 256);
        for (int i = 0; i < w * h; i++) {
            M[i] = tu_int(&r, 5) == 0 ? 0 : tu_int(&r, 3) == 0 ? (uint8_t)tu_int(&r, 256) : 255;
            N[3 * i] = tu_range(&r, -1, 1);
            N[3 * i + 1] = tu_range(&r, -1, 1);
            N[3 * i + 2] = tu_range(&r, 0, 1);
            hd[i] = tu_range(&r, 0.5f, 0.99f);
        }
        for (int i = 0; i < ow * oh * 4; i++) V[i] = (uint8_t)tu_int(&r, 256);
        for (int i = 0; i < ow * oh; i++) sd[i] = tu_int(&r, 4) == 0 ? tu_range(&r, 0.05f, 0.5f) : 0.0f;
        fuse_lighting L = fuse_lighting_default();
        fuse_intrinsics K = {(float)w, (float)w, w * 0.5f, h * 0.5f};
        fuse_depth dt = {hd, w, 0.05f, 10.0f, 0.0f, sd, ow, ow, oh};
        const int use_depth = n % 2;
        /* by hand, on the reference */
        fuse_context *rc;
        {
            fuse_context_desc cd = {EF_ISA_REF, 1};
            rc = fuse_context_create(&cd);
            assert_non_null(rc);
        }
        fuse_image Pi = {P, w, h, 4 * w}, Qi = {Q, w, h, 4 * w}, Vi = {V, ow, oh, 4 * ow};
        fuse_image Wi = {want, ow, oh, 4 * ow}, Gi = {got, ow, oh, 4 * ow};
        assert_int_equal(fuse_context_light(rc, &L, &K, &Pi, M, w, N, 3 * w, &Qi), FUSE_OK);
        assert_int_equal(fuse_edge_fade(&Qi, k, sides), FUSE_OK);
        if (use_depth)
            assert_int_equal(fuse_context_depth_test(rc, &dt, &Qi, vx, vy, vw, vh), FUSE_OK);
        assert_int_equal(fuse_context_composite(rc, &Qi, &Vi, vx, vy, vw, vh, &Wi), FUSE_OK);
        fuse_context_destroy(rc);
        for (int ii = 0; ii < 5; ii++) {
            if (ef_isa_choose(isas[ii]) != isas[ii]) continue;
            for (int th = 1; th <= 3; th++) {
                fuse_context_desc cd = {isas[ii], th};
                fuse_context *ctx = fuse_context_create(&cd);
                assert_non_null(ctx);
                fuse_eye e = { .lighting = &L, .intrinsics = &K, .P = Pi, .mask = M,
                               .mask_stride = w, .normal = N, .normal_stride = 3 * w, .Q = Qi,
                               .depth = use_depth ? &dt : NULL, .V = Vi, .vp_x0 = vx,
                               .vp_y0 = vy, .vp_w = vw, .vp_h = vh, .out = Gi, .edge_fade = k,
                               .edge_sides = sides };
                memset(got, 0xCD, (size_t)ow * oh * 4);
                assert_int_equal(fuse_context_frame(ctx, &e, 1), FUSE_OK);
                assert_memory_equal(got, want, (size_t)ow * oh * 4);
                fuse_context_destroy(ctx);
                ran++;
            }
        }
        EF_FREE_ALL(P, M, Q, V, want, got, N, hd, sd);
    }
    assert_true(ran >= 40 * 3);
}

/* A quad much larger than the view at 1 m fills the whole camera image:
 * mask 255 everywhere. Camera white, V black, ambient 1 and no other
 * light, no Fresnel (kf 0 through the normals facing the camera). With
 * the default, the composite's columns inside the viewport's left edge
 * rise over several display pixels from dark to white; a hard cut (the
 * old output) jumps from V to the hand at the viewport's first column. */
static void pipe_default_soft(void **state)
{
    (void)state;
    kin_model m;
    tu_quad_model(&m, 50.0f, -1.0f, 0.0f, "quad");
    uint8_t *out_fade[2] = {0}, *out_hard[2] = {0};
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    for (int pass = 0; pass < 2; pass++) {
        pipe_desc d = {0};
        d.threads = 1;
        d.edge_fade = pass == 0 ? 0 : -1;
        pipe_ctx *p = pipe_create(&d, &m);
        assert_non_null(p);
        tu_frame_bufs b;
        pipe_frame_in in;
        tu_frame_make(&b, &in, 77, 640, 480, 1280, 800);
        for (int e = 0; e < 2; e++) {
            memset(b.cam[e], 255, 640 * 480 * 4);
            for (int i = 0; i < 1280 * 800; i++) {
                b.virt[e][4 * i] = b.virt[e][4 * i + 1] = b.virt[e][4 * i + 2] = 0;
                b.virt[e][4 * i + 3] = 255;
            }
        }
        in.lighting.light.light_count = 0;
        in.lighting.light.ambient[0] = in.lighting.light.ambient[1] = in.lighting.light.ambient[2] = 1.0f;
        in.lighting.light.kf = 0.0f;
        assert_int_equal(pipe_frame(p, &in, NULL, NULL, 0), PIPE_OK);
        for (int e = 0; e < 2; e++) {
            if (pass == 0) out_fade[e] = b.out[e], b.out[e] = NULL;
            else out_hard[e] = b.out[e], b.out[e] = NULL;
        }
        tu_frame_free(&b);
        pipe_destroy(p);
    }
    const int y = g.vp_y0 + g.vp_height / 2, x = g.vp_x0 + g.vp_width / 2;
    for (int e = 0; e < 2; e++) {
        const uint8_t *f = out_fade[e], *h = out_hard[e];
        /* the middle of the viewport: white either way */
        assert_int_equal(f[4 * ((size_t)y * 1280 + x)], 255);
        assert_int_equal(h[4 * ((size_t)y * 1280 + x)], 255);
        /* outside the viewport: V */
        assert_int_equal(f[4 * ((size_t)y * 1280 + g.vp_x0 - 1)], 0);
        /* each side: the first viewport pixel dark, a ramp over at least
         * 4 display pixels (no step above 80 levels), white from about
         * 2 k display pixels in */
        for (int side = 0; side < 4; side++) {
            int prev = 0, maxstep = 0, first = -1;
            for (int i = 0; i < 16; i++) {
                int px, py;
                switch (side) {
                case 0: px = g.vp_x0 + i; py = y; break;
                case 1: px = g.vp_x0 + g.vp_width - 1 - i; py = y; break;
                case 2: px = x; py = g.vp_y0 + i; break;
                default: px = x; py = g.vp_y0 + g.vp_height - 1 - i; break;
                }
                const int v = f[4 * ((size_t)py * 1280 + px)];
                if (first < 0) first = v;
                if (v - prev > maxstep) maxstep = v - prev;
                assert_true(v >= prev);   /* monotone */
                prev = v;
            }
            assert_true(first <= 64);
            assert_true(maxstep <= 80);
            assert_int_equal(prev, 255);
        }
        /* edge_fade -1: the hard cut of before, white from the first column */
        assert_int_equal(h[4 * ((size_t)y * 1280 + g.vp_x0)], 255);
        free(out_fade[e]);
        free(out_hard[e]);
    }
    kin_model_free(&m);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(against_reference),
        cmocka_unit_test(exact_every_width),
        cmocka_unit_test(weight_at_centres),
        cmocka_unit_test(bad_args),
        cmocka_unit_test(frame_every_isa),
        cmocka_unit_test(pipe_default_soft))
