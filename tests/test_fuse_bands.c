/* test_fuse_bands.c - one eye's fuse in row bands (issue 17): the bands of
 * fuse_context_frame_prepare / _band / _finish give fuse_context_frame's
 * bytes (the output and the layer) on every ISA, band size and order of
 * the bands, with and without a depth test, edge fade and opaque V (the
 * interleaved path's deferred copies), and with the bands shared by two
 * threads. Then the pipe: two threads sharing the fuse of both eyes give
 * the bytes of one thread on a frame where one eye sees far more of the
 * model than the other. A band dropped or done twice, or a band border's
 * rows lost, changes the bytes. And fuse_eye.q_zero_rows (the layer's
 * empty rows not cleared again) over frames where the hand moves. */
#include "support/testutil.h"

#include <cmocka.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fuse/fuse.h"
#include "../src/pipe/pipe.h"
#include "support/fuse_eye_data.h"
#include "support/pipe_frames.h"

/* crop CW x CH, output OW x OH, viewport (OX, OY, OPW, OPH): upscaled by
 * a little under 2 (several output rows per layer row, band borders that
 * fall in the middle of a layer row's rows) */
enum { CW = 150, CH = 97, OW = 320, OH = 216, OX = 7, OY = 5, OPW = 300, OPH = 203 };

/* the ISAs each test runs on, and the camera's intrinsics */
static const ef_isa isas[] = {EF_ISA_REF, EF_ISA_SSE2, EF_ISA_AVX2, EF_ISA_DEFAULT};
static const fuse_intrinsics K = {90.0f, 90.0f, CW / 2.0f, CH / 2.0f};

static void eye_fill(tu_eye_data *e, tu_rng *r)
{
    tu_eye_alloc(e, CW, CH, OW, OH);
    for (int i = 0; i < CW * CH * 4; i++) e->P[i] = (uint8_t)tu_int(r, 256);
    for (int i = 0; i < CW * CH; i++) {
        /* a hand off the centre, over the lower left; some rows empty */
        const int x = i % CW, y = i / CW;
        const double dx = (x - CW / 3.0) / (CW / 4.0), dy = (y - CH * 0.6) / (CH / 3.0);
        const double d2 = dx * dx + dy * dy;
        e->M[i] = d2 < 0.8 ? 255 : d2 < 1.0 ? (uint8_t)(1275 * (1.0 - d2)) : 0;
        e->N[3 * i] = (float)dx;
        e->N[3 * i + 1] = (float)-dy;
        e->N[3 * i + 2] = 1.0f;
        e->hand[i] = (float)(0.3 + 0.2 * tu_unit(r));
    }
    for (int i = 0; i < OW * OH * 4; i++)
        e->V[i] = (i & 3) == 3 ? 255 : (uint8_t)tu_int(r, 256);   /* opaque */
    for (int i = 0; i < OW * OH; i++)   /* a bar in front across the middle */
        e->scene[i] = (i / OW) > OH / 2 && (i / OW) < OH / 2 + 20 ? 0.1f : 1.0f;
}

typedef struct band_share {
    fuse_context *ctx;
    pthread_mutex_t mu;
    int next, n;
} band_share;

static void *band_thread(void *arg)
{
    band_share *s = arg;
    for (;;) {
        pthread_mutex_lock(&s->mu);
        const int b = s->next++;
        pthread_mutex_unlock(&s->mu);
        if (b >= s->n) return NULL;
        fuse_context_frame_band(s->ctx, b);
    }
}

/* The n prepared bands of ctx on this thread and one more, as they come. */
static void bands_two_threads(fuse_context *ctx, int n)
{
    band_share s = {ctx, PTHREAD_MUTEX_INITIALIZER, 0, n};
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, band_thread, &s), 0);
    band_thread(&s);
    pthread_join(th, NULL);
    pthread_mutex_destroy(&s.mu);
}

static void bands_equal_frame(void **state)
{
    (void)state;
    static const int rows[] = {1, 3, 7, 32, 48, 1000};
    tu_rng r = {0xBA1A7CEu};
    fuse_lighting L = fuse_lighting_default();
    tu_eye_data e;
    eye_fill(&e, &r);
    const fuse_depth dd = {e.hand, CW, 0.05f, 10.0f, 0.0f, e.scene, OW, OW, OH};
    uint8_t *want = malloc(OW * OH * 4), *wantq = malloc(CW * CH * 4);
    assert_true(want && wantq);
    int checked = 0;
    for (int ii = 0; ii < 4; ii++) {
        fuse_context_desc d = {isas[ii], 1};
        fuse_context *ctx = fuse_context_create(&d);
        assert_non_null(ctx);
        for (int variant = 0; variant < 4; variant++) {
            /* 0 plain, 1 depth and edge fade, 2 opaque V, 3 all of them */
            fuse_eye fe = {&L, &K, {e.P, CW, CH, 4 * CW}, e.M, CW, e.N, 3 * CW,
                           {e.Q, CW, CH, 4 * CW}, (variant & 1) ? &dd : NULL,
                           {e.V, OW, OH, 4 * OW}, OX, OY, OPW, OPH,
                           {e.out, OW, OH, 4 * OW}, (variant & 2) != 0,
                           (variant & 1) ? 4 : 0, (variant & 1) ? FUSE_EDGE_ALL : 0u, NULL, NULL, 0};
            memset(e.Q, 0x55, CW * CH * 4);
            memset(e.out, 0x66, OW * OH * 4);
            assert_int_equal(fuse_context_frame(ctx, &fe, 1), FUSE_OK);
            memcpy(want, e.out, OW * OH * 4);
            memcpy(wantq, e.Q, CW * CH * 4);
            for (int ri = 0; ri < 6; ri++)
                for (int mode = 0; mode < 3; mode++) {
                    /* mode 0: bands in order, 1: reversed, 2: two threads */
                    memset(e.Q, 0x55, CW * CH * 4);
                    memset(e.out, 0x66, OW * OH * 4);
                    int n = 0;
                    assert_int_equal(fuse_context_frame_prepare(ctx, &fe, rows[ri], &n), FUSE_OK);
                    assert_int_equal(n, (OH + rows[ri] - 1) / rows[ri] < 1 ? 1
                                                                           : (OH + rows[ri] - 1) / rows[ri]);
                    if (mode == 0)
                        for (int b = 0; b < n; b++) fuse_context_frame_band(ctx, b);
                    else if (mode == 1)
                        for (int b = n - 1; b >= 0; b--) fuse_context_frame_band(ctx, b);
                    else
                        bands_two_threads(ctx, n);
                    fuse_context_frame_finish(ctx);
                    assert_memory_equal(e.out, want, OW * OH * 4);
                    assert_memory_equal(e.Q, wantq, CW * CH * 4);
                    checked++;
                }
        }
        fuse_context_destroy(ctx);
    }
    assert_int_equal(checked, 4 * 4 * 6 * 3);
    /* bad arguments: nothing prepared */
    {
        fuse_context *ctx = fuse_context_create(NULL);
        fuse_eye fe = {&L, &K, {e.P, CW, CH, 4 * CW}, e.M, CW, e.N, 3 * CW,
                       {e.P, CW, CH, 4 * CW}, NULL, {e.V, OW, OH, 4 * OW}, OX, OY, OPW, OPH,
                       {e.out, OW, OH, 4 * OW}, 0, 0, 0, NULL, NULL, 0};
        int n = 0;
        assert_int_equal(fuse_context_frame_prepare(ctx, &fe, 32, &n), FUSE_ERR_ARGS); /* P == Q */
        fe.Q.pixels = e.Q;
        assert_int_equal(fuse_context_frame_prepare(ctx, &fe, 0, &n), FUSE_ERR_ARGS);
        assert_int_equal(fuse_context_frame_prepare(NULL, &fe, 32, &n), FUSE_ERR_ARGS);
        assert_int_equal(fuse_context_frame_prepare(ctx, &fe, 32, NULL), FUSE_ERR_ARGS);
        fuse_context_destroy(ctx);
    }
    free(want);
    free(wantq);
    tu_eye_free(&e);
}

/* The mask of frame f: the hand of eye_fill moved down by 9 rows a frame
 * and back (rows empty in one frame and lit in the next, and the reverse). */
static void mask_at(uint8_t *M, int f)
{
    static const int shift[] = {0, 9, 18, 9, 0, -12};
    for (int i = 0; i < CW * CH; i++) {
        const double dx = (i % CW - CW / 3.0) / (CW / 4.0);
        const double dy = (i / CW - shift[f] - CH * 0.6) / (CH / 3.0);
        const double d2 = dx * dx + dy * dy;
        M[i] = d2 < 0.8 ? 255 : d2 < 1.0 ? (uint8_t)(1275 * (1.0 - d2)) : 0;
    }
}

/* fuse_eye.q_zero_rows over a sequence of frames whose hand moves: the
 * layer and the output are those of NULL (every row written, the layer
 * filled with garbage before each frame) on every ISA, whole and in bands
 * on two threads; byte y is 1 exactly where the mask row is empty. A row
 * left as the last frame lit it, or a byte not reset where the hand came
 * back, changes the layer. */
static void zero_rows_same_bytes(void **state)
{
    (void)state;
    tu_rng r = {0x2E50F00Du};
    fuse_lighting L = fuse_lighting_default();
    tu_eye_data e;
    eye_fill(&e, &r);
    const fuse_depth dd = {e.hand, CW, 0.05f, 10.0f, 0.0f, e.scene, OW, OW, OH};
    uint8_t *want = malloc(OW * OH * 4), *wantq = malloc(CW * CH * 4), zero[CH];
    assert_true(want && wantq);
    int kept = 0;
    for (int ii = 0; ii < 4; ii++)
        for (int mode = 0; mode < 2; mode++) {   /* 0: whole, 1: bands on two threads */
            fuse_context_desc d = {isas[ii], 1};
            fuse_context *ctx = fuse_context_create(&d);
            assert_non_null(ctx);
            memset(zero, 0, sizeof zero);
            memset(e.Q, 0x55, CW * CH * 4);   /* garbage at first: the bytes say nothing */
            for (int f = 0; f < 6; f++) {
                mask_at(e.M, f);
                fuse_eye fe = {&L, &K, {e.P, CW, CH, 4 * CW}, e.M, CW, e.N, 3 * CW,
                               {e.Q, CW, CH, 4 * CW}, (f & 1) ? &dd : NULL,
                               {e.V, OW, OH, 4 * OW}, OX, OY, OPW, OPH,
                               {e.out, OW, OH, 4 * OW}, f & 1, 0, 0u, NULL, NULL, 0};
                uint8_t *q_keep = malloc(CW * CH * 4);
                assert_non_null(q_keep);
                memcpy(q_keep, e.Q, CW * CH * 4);
                memset(e.Q, 0x55, CW * CH * 4);
                memset(e.out, 0x66, OW * OH * 4);
                assert_int_equal(fuse_context_frame(ctx, &fe, 1), FUSE_OK);
                memcpy(want, e.out, OW * OH * 4);
                memcpy(wantq, e.Q, CW * CH * 4);
                memcpy(e.Q, q_keep, CW * CH * 4);   /* the layer as the last frame left it */
                free(q_keep);
                memset(e.out, 0x66, OW * OH * 4);
                fe.q_zero_rows = zero;
                if (mode == 0) {
                    assert_int_equal(fuse_context_frame(ctx, &fe, 1), FUSE_OK);
                } else {
                    int n = 0;
                    assert_int_equal(fuse_context_frame_prepare(ctx, &fe, 16, &n), FUSE_OK);
                    bands_two_threads(ctx, n);
                    fuse_context_frame_finish(ctx);
                }
                assert_memory_equal(e.out, want, OW * OH * 4);
                assert_memory_equal(e.Q, wantq, CW * CH * 4);
                for (int y = 0; y < CH; y++) {
                    int empty = 1;
                    for (int x = 0; x < CW; x++) empty &= e.M[y * CW + x] == 0;
                    assert_int_equal(zero[y], empty);
                    kept += f > 0 && empty && zero[y];
                }
            }
            fuse_context_destroy(ctx);
        }
    assert_true(kept > 4 * 2 * 5 * 10);   /* rows that the flags spared */
    free(want);
    free(wantq);
    tu_eye_free(&e);
}

/* A quad off to the left, close: the left eye sees far more of it than
 * the right one. */
static void side_quad_model(kin_model *m)
{
    tu_mesh_parts t = tu_mesh_model(m, "head", "side", 4, 6, 1);
    const float x0 = -0.60f, x1 = -0.015f, y0 = -0.20f, y1 = 0.15f, z = -0.30f;
    const float p[12] = {x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z};
    memcpy(t.pos, p, sizeof p);
    for (int i = 0; i < 4; i++) t.nrm[3 * i + 2] = 1.0f;
    t.rest[1].r = kin_quat_axis_angle(kin_v3(0, 1, 0), 0.2f);   /* varied shading */
    const uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
    memcpy(t.idx, ix, sizeof ix);
    char why[200];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
}

static void pipe_shared_eyes_same_bytes(void **state)
{
    (void)state;
    kin_model m;
    side_quad_model(&m);
    enum { LW = 1280, LH = 800, NF = 4 };
    uint8_t *keep = malloc((size_t)NF * 2 * LW * LH * 4);
    assert_non_null(keep);
    for (int th = 1; th <= 2; th++) {
        pipe_desc d = {0};
        d.threads = th;
        pipe_ctx *p = pipe_create(&d, &m);
        assert_non_null(p);
        for (int f = 0; f < NF; f++) {
            tu_frame_bufs b;
            pipe_frame_in in;
            tu_frame_make(&b, &in, 300 + (uint64_t)f, 640, 480, LW, LH);
            kin_mat4 head = kin_mat4_from_tr(kin_v3(0.004f * f, 0.003f * f, 0),
                                             kin_quat_axis_angle(kin_v3(0, 1, 0), 0.02f * f));
            in.head_node = -1;
            in.world_from_head = &head;
            in.virt_opaque = f & 1;
            if (f & 1)
                for (int e = 0; e < 2; e++)
                    for (size_t i = 3; i < (size_t)LW * LH * 4; i += 4) b.virt[e][i] = 255;
            pipe_frame_stats st;
            char why[200] = "";
            assert_int_equal(pipe_frame(p, &in, &st, why, sizeof why), PIPE_OK);
            /* one eye with far more hand than the other */
            assert_true(st.coverage[0] > 3.0 * st.coverage[1] && st.coverage[1] > 0.005);
            for (int e = 0; e < 2; e++) {
                uint8_t *k = keep + ((size_t)f * 2 + (size_t)e) * LW * LH * 4;
                if (th == 1) memcpy(k, b.out[e], (size_t)LW * LH * 4);
                else assert_memory_equal(k, b.out[e], (size_t)LW * LH * 4);
            }
            tu_frame_free(&b);
        }
        pipe_destroy(p);
    }
    free(keep);
    kin_model_free(&m);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(bands_equal_frame),
        cmocka_unit_test(zero_rows_same_bytes),
        cmocka_unit_test(pipe_shared_eyes_same_bytes))
