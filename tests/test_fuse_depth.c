/* test_fuse_depth.c - the depth test of the lit layer against the virtual
 * scene (window depth of the project's own projection back to metres,
 * in front / behind / nothing there, the eye offset, which scene pixel a
 * camera pixel reads, random cases against double precision, bad input),
 * fuse_context_frame (equal to the calls one by one, on every thread
 * count and eye split) and gray-world tone matching. */
#include "support/testutil.h"
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse.h"
#include "../src/kin/kin.h"
#include "support/fuse_eye_data.h"

enum { QW = 16, QH = 10, VW = 40, VH = 30, VX = 3, VY = 2, VPW = 31, VPH = 25 };
static const float ZN = 0.01f, ZF = 100.0f;

/* window depth of a point at metric distance d on the axis, through the
 * project's projection (kin_mat4_perspective, column-major) */
static float window_z(double d)
{
    const kin_mat4 P = kin_mat4_perspective(1.0f, 1.6f, ZN, ZF);
    const double cz = P.m[2 * 4 + 2] * -d + P.m[3 * 4 + 2];
    const double cw = P.m[2 * 4 + 3] * -d + P.m[3 * 4 + 3];
    return (float)(cz / cw * 0.5 + 0.5);
}

typedef struct setup {
    uint8_t q[QW * QH * 4];
    float hand[QW * QH];
    float scene[VW * VH];
    fuse_image Q;
    fuse_depth d;
} setup;

static void setup_init(setup *s, double hand_d, float scene_d)
{
    int i;
    for (i = 0; i < QW * QH * 4; i++) s->q[i] = (uint8_t)(1 + i % 250);
    for (i = 0; i < QW * QH; i++) s->hand[i] = window_z(hand_d);
    for (i = 0; i < VW * VH; i++) s->scene[i] = scene_d;
    s->Q = (fuse_image){ s->q, QW, QH, 4 * QW };
    s->d = (fuse_depth){ s->hand, QW, ZN, ZF, 0.0f, s->scene, VW, VW, VH };
}

static int hidden(const setup *s, int x, int y)
{
    const uint8_t *p = s->q + 4 * (y * QW + x);
    return p[0] == 0 && p[1] == 0 && p[2] == 0 && p[3] == 0;
}

static int count_hidden(const setup *s)
{
    int x, y, n = 0;
    for (y = 0; y < QH; y++)
        for (x = 0; x < QW; x++) n += hidden(s, x, y);
    return n;
}

static void test_front_behind(void **state)
{
    setup s;
    (void)state;
    /* hand at 0.30 m, an object at 0.25 m hides it, at 0.35 m it does not */
    setup_init(&s, 0.30, 0.25f);
    assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
    assert_int_equal(count_hidden(&s), QW * QH);
    setup_init(&s, 0.30, 0.35f);
    assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
    assert_int_equal(count_hidden(&s), 0);
    /* nothing in the scene: 0, negative, inf, NaN */
    {
        static const float none[] = { 0.0f, -1.0f, INFINITY, NAN };
        int k;
        for (k = 0; k < 4; k++) {
            setup_init(&s, 0.30, none[k]);
            assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
            assert_int_equal(count_hidden(&s), 0);
        }
    }
    /* no hand depth (z = 1, the clear value, or NaN): kept */
    setup_init(&s, 0.30, 0.1f);
    s.hand[0] = 1.0f;
    s.hand[1] = NAN;
    assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
    assert_int_equal(count_hidden(&s), QW * QH - 2);
    assert_false(hidden(&s, 0, 0));
    assert_false(hidden(&s, 1, 0));
    /* scene distances from the eye, camera 0.085 m in front of it: the hand
     * at 0.30 m from the camera is 0.385 m from the eye */
    setup_init(&s, 0.30, 0.37f);
    s.d.offset = 0.085f;
    assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
    assert_int_equal(count_hidden(&s), QW * QH);
    setup_init(&s, 0.30, 0.40f);
    s.d.offset = 0.085f;
    assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
    assert_int_equal(count_hidden(&s), 0);
}

/* Which scene pixel each camera pixel reads: the one under its centre,
 * ox = VX + floor((x + 0.5) VPW / QW) (double here). One near scene pixel
 * hides exactly the camera pixels that land on it. */
static void test_mapping(void **state)
{
    int ox, oy;
    (void)state;
    for (oy = VY; oy < VY + VPH; oy += 3)
        for (ox = VX; ox < VX + VPW; ox += 2) {
            setup s;
            int x, y;
            setup_init(&s, 0.30, 0.0f);
            s.scene[oy * VW + ox] = 0.2f;
            assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
            for (y = 0; y < QH; y++)
                for (x = 0; x < QW; x++) {
                    const int mx = VX + (int)floor((x + 0.5) * VPW / QW);
                    const int my = VY + (int)floor((y + 0.5) * VPH / QH);
                    assert_int_equal(hidden(&s, x, y), mx == ox && my == oy);
                }
        }
}

/* Random hand and scene distances against the double-precision decision
 * (ties within 1e-5 relative are not judged); transparent pixels of Q
 * stay as they are. */
static void test_random_vs_double(void **state)
{
    tu_rng r = { 0xDE97Bu };
    long decided = 0, hid = 0;
    int k;
    (void)state;
    for (k = 0; k < 200; k++) {
        setup s;
        int x, y;
        setup_init(&s, 0.3, 0.0f);
        s.d.offset = tu_int(&r, 2) ? 0.0f : 0.085f;
        for (x = 0; x < QW * QH; x++) {
            s.hand[x] = window_z(0.12 + 0.5 * tu_unit(&r));
            if (tu_int(&r, 5) == 0) memset(s.q + 4 * x, 0, 4);
        }
        for (x = 0; x < VW * VH; x++) s.scene[x] = tu_range(&r, 0.05f, 0.9f);
        {
            uint8_t before[sizeof s.q];
            memcpy(before, s.q, sizeof before);
            assert_int_equal(fuse_depth_test(&s.d, &s.Q, VX, VY, VPW, VPH), FUSE_OK);
            for (y = 0; y < QH; y++)
                for (x = 0; x < QW; x++) {
                    const int mx = VX + (int)floor((x + 0.5) * VPW / QW);
                    const int my = VY + (int)floor((y + 0.5) * VPH / QH);
                    const double z = s.hand[y * QW + x], n = ZN, f = ZF;
                    const double d = 2 * f * n / ((f + n) - (2 * z - 1) * (f - n)) + s.d.offset;
                    const double sc = s.scene[my * VW + mx];
                    const uint8_t *b = before + 4 * (y * QW + x);
                    if (b[0] == 0 && b[1] == 0 && b[2] == 0 && b[3] == 0) continue;
                    if (fabs(sc - d) < 1e-5 * d) continue;
                    decided++;
                    hid += sc < d;
                    if (hidden(&s, x, y) != (sc < d)) {
                        print_error("case %d (%d,%d): hand %.6f scene %.6f hidden %d\n", k, x, y, d,
                                    sc, hidden(&s, x, y));
                        fail();
                    }
                    if (!hidden(&s, x, y)) assert_memory_equal(b, s.q + 4 * (y * QW + x), 4);
                }
        }
    }
    printf("NOTE depth: %ld decisions, %ld hidden\n", decided, hid);
    assert_true(hid > decided / 5 && hid < decided * 4 / 5);
}

static void test_bad_input(void **state)
{
    setup s;
    uint8_t copy[sizeof s.q];
    (void)state;
    setup_init(&s, 0.3, 0.1f);
    memcpy(copy, s.q, sizeof copy);
#define BAD(expr, err, ...) do { fuse_depth d = s.d; fuse_image q = s.Q; (void)d; (void)q; expr; \
        assert_int_equal(fuse_depth_test(&d, &q, __VA_ARGS__), err); \
        assert_memory_equal(copy, s.q, sizeof copy); } while (0)
    BAD(d.hand = NULL, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.scene = NULL, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.hand_stride = QW - 1, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.scene_stride = VW - 1, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.znear = 0.0f, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.zfar = d.znear, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.zfar = NAN, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.offset = INFINITY, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(q.stride = 4 * QW - 1, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD(d.scene_width = 0, FUSE_ERR_ARGS, VX, VY, VPW, VPH);
    BAD((void)0, FUSE_ERR_ARGS, VX, VY, 0, VPH);
    BAD((void)0, FUSE_ERR_SIZE, VX + 7, VY, VPW, VPH);         /* beyond the scene */
    BAD((void)0, FUSE_ERR_SIZE, -1, VY, VPW, VPH);
    BAD((void)0, FUSE_ERR_SIZE, VX, VY, VPW, VH);
    assert_int_equal(fuse_depth_test(NULL, &s.Q, VX, VY, VPW, VPH), FUSE_ERR_ARGS);
    assert_int_equal(fuse_depth_test(&s.d, NULL, VX, VY, VPW, VPH), FUSE_ERR_ARGS);
#undef BAD
}

/* ---- fuse_context_frame ------------------------------------------------- */

enum { CW = 67, CH = 41, OW = 130, OH = 84, OX = 5, OY = 3, OPW = 121, OPH = 77 };

static void eye_fill(tu_eye_data *e, tu_rng *r)
{
    int i;
    tu_eye_alloc(e, CW, CH, OW, OH);
    for (i = 0; i < CW * CH * 4; i++) e->P[i] = (uint8_t)tu_int(r, 256);
    for (i = 0; i < CW * CH; i++) {
        const int x = i % CW, y = i / CW;
        const double dx = (x - CW / 2.0) / (CW / 3.0), dy = (y - CH / 2.0) / (CH / 3.0);
        const double d2 = dx * dx + dy * dy;
        e->M[i] = d2 < 0.9 ? 255 : d2 < 1.0 ? (uint8_t)(2550 * (1.0 - d2)) : 0;
        e->N[3 * i] = (float)dx;
        e->N[3 * i + 1] = (float)-dy;
        e->N[3 * i + 2] = 1.0f;
        e->hand[i] = window_z(0.25 + 0.1 * tu_unit(r));
    }
    for (i = 0; i < OW * OH * 4; i++) e->V[i] = (uint8_t)tu_int(r, 256);
    for (i = 0; i < OW * OH; i++)   /* a virtual bar across the middle, in front */
        e->scene[i] = (i / OW) > OH / 3 && (i / OW) < OH / 2 ? 0.2f : 0.0f;
}

static void test_frame(void **state)
{
    static const ef_isa isas[] = { EF_ISA_REF, EF_ISA_DEFAULT };
    tu_rng r = { 0xF7A3Eu };
    const fuse_lighting L = fuse_lighting_default();
    const fuse_intrinsics K = { 60.0f, 60.0f, CW / 2.0f, CH / 2.0f };
    tu_eye_data e[2];
    uint8_t *want[2];
    fuse_depth dd[2];
    int i, ii, t;
    (void)state;
    for (i = 0; i < 2; i++) {
        eye_fill(&e[i], &r);
        dd[i] = (fuse_depth){ e[i].hand, CW, ZN, ZF, 0.0f, e[i].scene, OW, OW, OH };
        /* the calls one by one */
        {
            fuse_image P = { e[i].P, CW, CH, 4 * CW }, Q = { e[i].Q, CW, CH, 4 * CW };
            fuse_image V = { e[i].V, OW, OH, 4 * OW };
            want[i] = malloc(OW * OH * 4);
            assert_non_null(want[i]);
            fuse_image O = { want[i], OW, OH, 4 * OW };
            assert_int_equal(fuse_light(&L, &K, &P, e[i].M, CW, e[i].N, 3 * CW, &Q), FUSE_OK);
            assert_int_equal(fuse_depth_test(&dd[i], &Q, OX, OY, OPW, OPH), FUSE_OK);
            assert_int_equal(fuse_composite(&Q, &V, OX, OY, OPW, OPH, &O), FUSE_OK);
        }
    }
    /* the bar hides part of the hand: the output differs from no depth */
    {
        fuse_image P = { e[0].P, CW, CH, 4 * CW }, Q = { e[0].Q, CW, CH, 4 * CW };
        fuse_image V = { e[0].V, OW, OH, 4 * OW }, O = { e[0].out, OW, OH, 4 * OW };
        assert_int_equal(fuse_light(&L, &K, &P, e[0].M, CW, e[0].N, 3 * CW, &Q), FUSE_OK);
        assert_int_equal(fuse_composite(&Q, &V, OX, OY, OPW, OPH, &O), FUSE_OK);
        assert_true(memcmp(e[0].out, want[0], OW * OH * 4) != 0);
        /* inside the bar the scene shows, with the depth test */
        assert_memory_equal(want[0] + 4 * (OW * (OH / 2 - 2) + OW / 2),
                            e[0].V + 4 * (OW * (OH / 2 - 2) + OW / 2), 3);
    }
    for (ii = 0; ii < 2; ii++)
        for (t = 1; t <= 3; t++) {
            fuse_context_desc d = { isas[ii], t };
            fuse_context *ctx = fuse_context_create(&d);
            fuse_eye eyes[2];
            int count;
            assert_non_null(ctx);
            for (count = 1; count <= 2; count++) {
                for (i = 0; i < 2; i++) {
                    memset(e[i].Q, 0x55, CW * CH * 4);
                    memset(e[i].out, 0x66, OW * OH * 4);
                    eyes[i] = (fuse_eye){ &L, &K, { e[i].P, CW, CH, 4 * CW }, e[i].M, CW,
                                          e[i].N, 3 * CW, { e[i].Q, CW, CH, 4 * CW }, &dd[i],
                                          { e[i].V, OW, OH, 4 * OW }, OX, OY, OPW, OPH,
                                          { e[i].out, OW, OH, 4 * OW }, 0, 0, 0, NULL, NULL, 0 };
                }
                assert_int_equal(fuse_context_frame(ctx, eyes, count), FUSE_OK);
                for (i = 0; i < count; i++) assert_memory_equal(e[i].out, want[i], OW * OH * 4);
            }
            /* errors: nothing written */
            memset(e[0].out, 0x66, OW * OH * 4);
            eyes[1].depth = &dd[1];
            eyes[1].vp_w = OW + 1;
            assert_int_equal(fuse_context_frame(ctx, eyes, 2), FUSE_ERR_SIZE);
            eyes[1].vp_w = OPW;
            eyes[1].Q = eyes[0].Q;   /* two eyes on one scratch layer */
            assert_int_equal(fuse_context_frame(ctx, eyes, 2), FUSE_ERR_ARGS);
            assert_int_equal(fuse_context_frame(ctx, eyes, 0), FUSE_ERR_ARGS);
            assert_int_equal(fuse_context_frame(NULL, eyes, 1), FUSE_ERR_ARGS);
            for (i = 0; i < OW * OH * 4; i++) assert_int_equal(e[0].out[i], 0x66);
            fuse_context_destroy(ctx);
        }
    for (i = 0; i < 2; i++) {
        tu_eye_free(&e[i]);
        free(want[i]);
    }
}

/* ---- tone matching -------------------------------------------------------- */

static void test_tone(void **state)
{
    enum { PW = 64, PH = 40, W2 = 100, H2 = 60 };
    static uint8_t P[PW * PH * 4], M[PW * PH], V[W2 * H2 * 4];
    fuse_image Pi = { P, PW, PH, 4 * PW }, Vi = { V, W2, H2, 4 * W2 };
    float tone[3];
    int i;
    (void)state;
    /* the room (mask 0) is (200, 160, 120); the hand (mask 255) anything;
     * the scene inside the viewport is (100, 100, 100), outside black */
    for (i = 0; i < PW * PH; i++) {
        M[i] = (i % PW) > PW / 2 ? 255 : 0;
        P[4 * i] = M[i] ? 7 : 200;
        P[4 * i + 1] = M[i] ? 250 : 160;
        P[4 * i + 2] = M[i] ? 3 : 120;
        P[4 * i + 3] = 0;
    }
    memset(V, 0, sizeof V);
    for (i = 0; i < W2 * H2; i++) {
        const int x = i % W2, y = i / W2;
        if (x >= 10 && x < 90 && y >= 5 && y < 55) memset(V + 4 * i, 100, 3);
    }
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, 1.0f, tone), FUSE_OK);
    assert_float_equal(tone[0], 101.0 / 201.0, 1e-6);
    assert_float_equal(tone[1], 101.0 / 161.0, 1e-6);
    assert_float_equal(tone[2], 101.0 / 121.0, 1e-6);
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, 0.5f, tone), FUSE_OK);
    assert_float_equal(tone[0], sqrt(101.0 / 201.0), 1e-6);
    assert_float_equal(tone[2], sqrt(101.0 / 121.0), 1e-6);
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, 0.0f, tone), FUSE_OK);
    assert_true(tone[0] == 1.0f && tone[1] == 1.0f && tone[2] == 1.0f);
    /* a black scene: clamped to 1/4 */
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 0, 0, 5, 5, 1.0f, tone), FUSE_OK);
    assert_float_equal(tone[0], 0.25, 1e-7);
    assert_float_equal(tone[1], 0.25, 1e-7);
    /* no room visible: no estimate, tone 1 */
    memset(M, 255, sizeof M);
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, 1.0f, tone), FUSE_OK);
    assert_true(tone[0] == 1.0f && tone[1] == 1.0f && tone[2] == 1.0f);
    /* lighting the same P with the tone moves its mean towards V's */
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, 1.5f, tone), FUSE_ERR_ARGS);
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, NAN, tone), FUSE_ERR_ARGS);
    assert_int_equal(fuse_tone_match(&Pi, M, PW - 1, &Vi, 10, 5, 80, 50, 1.0f, tone), FUSE_ERR_ARGS);
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 30, 5, 80, 50, 1.0f, tone), FUSE_ERR_SIZE);
    assert_int_equal(fuse_tone_match(NULL, M, PW, &Vi, 10, 5, 80, 50, 1.0f, tone), FUSE_ERR_ARGS);
    assert_int_equal(fuse_tone_match(&Pi, M, PW, &Vi, 10, 5, 80, 50, 1.0f, NULL), FUSE_ERR_ARGS);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_front_behind),
        cmocka_unit_test(test_mapping),
        cmocka_unit_test(test_random_vs_double),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_frame),
        cmocka_unit_test(test_tone))
