/* test_fit_shift.c - the hands of the refinement's input moved to the
 * colour (src/fit/fit_shift.h), on generated data: a "hand" of skin
 * colour, a disc of radius 40 px over a dark-blue background with seeded
 * noise, whose kinematic mask is the same disc 20 px left and 12 px below
 * (beyond a 16 px band), with the hand joints at the kinematic disc's
 * centre.
 *   - the shift found is the true offset within 2 px, the input's IoU
 *     goes from below 0.6 to above 0.95, and after the band refinement
 *     the mask is nearer the truth than the refinement of the unshifted
 *     input;
 *   - a kinematic mask already on the hand is not moved (in returned);
 *   - the part of the input outside the hand's region (another arm) is
 *     unchanged;
 *   - no colour model, an untracked side, a too small scratch: in
 *     returned, shift 0.
 */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/fit_scene.h"
#include "support/fixture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/fit/fit_shift.h"
#include "../src/fuse/fuse_refine.h"

enum { W = 320, H = 240 };
static const float F = 300.0f;
enum { DX = 20, DY = -12 };   /* the true hand's offset from the model's */

/* a disc added to m (255 inside; clear = 1 clears m first) */
static void disc(uint8_t *m, float cx, float cy, float r, int clear)
{
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            float dx = (float)x + 0.5f - cx, dy = (float)y + 0.5f - cy;
            if (dx * dx + dy * dy <= r * r) m[y * W + x] = 255;
            else if (clear) m[y * W + x] = 0;
        }
}

static double iou(const uint8_t *a, const uint8_t *b) { return fit_scene_iou(a, b, (long)W * H); }

typedef struct scene {
    uint8_t *img, *truth, *kin, *out, *ref;
    float *llr;
    void *scratch, *cscratch, *rscratch;
    size_t scratch_size, rscratch_size;
    fuse_colour_model g;
    kin_camera cam;
    kin_arm_rig rig;
    kin_mat4 world[2];
    pipe_fit_shift_desc d;
} scene;

static void scene_make(scene *s)
{
    fit_scene_alloc(W, H, &s->img, &s->truth, &s->kin, &s->out);
    s->ref = malloc(W * H);
    assert_non_null(s->ref);
    /* the model's hand at the image centre, the true one offset */
    disc(s->truth, W / 2.0f + DX, H / 2.0f + DY, 40.0f, 1);
    disc(s->kin, W / 2.0f, H / 2.0f, 40.0f, 1);
    fit_scene_learn(&s->g, s->img, s->truth, W, H, 0x5eed5417ull, &s->llr, &s->cscratch);
    s->scratch_size = pipe_fit_shift_scratch_size(W, H);
    s->scratch = fit_scene_scratch(s->scratch_size);
    const fuse_refine_params rp = fit_scene_refine_params();
    s->rscratch_size = fuse_refine_scratch_size(&rp, W, H);
    s->rscratch = fit_scene_scratch(s->rscratch_size);
    s->cam = fit_scene_camera(W, H, F);
    fit_scene_rig(&s->rig);
    s->world[0] = fit_scene_at(0, 0, -0.4f);      /* the left hand: the image centre */
    s->world[1] = fit_scene_at(5.0f, 0, -0.4f);   /* the right hand out of view */
    s->d = pipe_fit_shift_desc_default();
    s->d.hand_radius = 0.05f;           /* 37.5 px at 0.4 m, + range 24 */
}

static void scene_free(scene *s)
{
    free(s->img); free(s->truth); free(s->kin); free(s->out); free(s->ref);
    free(s->llr); free(s->scratch); free(s->cscratch); free(s->rscratch);
}

/* Each test's fixture: a fresh scene (scene_make) as its state. */
TU_FIXTURE(scene, scene, s, scene_make(s), scene_free(s))

/* pipe_fit_shift of in on the scene's image with the colour model g and
 * scratch_size bytes of the scene's scratch. */
static const uint8_t *shift_with(scene *s, const fuse_colour_model *g, unsigned sides,
                                 const uint8_t *in, size_t scratch_size, int sh[2][2])
{
    fuse_image P = { s->img, W, H, 4 * W };
    return pipe_fit_shift(&s->d, g, &P, &s->cam, s->world, &s->rig, sides, in, s->out, W,
                          s->scratch, scratch_size, sh);
}

/* pipe_fit_shift of in with the scene's model and whole scratch. */
static const uint8_t *shift_of(scene *s, unsigned sides, const uint8_t *in, int sh[2][2])
{
    return shift_with(s, &s->g, sides, in, s->scratch_size, sh);
}

static double refined_iou(scene *s, const uint8_t *in)
{
    const fuse_refine_params rp = fit_scene_refine_params();
    fuse_image P = { s->img, W, H, 4 * W };
    fuse_refine_stats st;
    assert_int_equal(fuse_refine_mask_global(&rp, &s->g, 1.0f, &P, in, W, s->ref, W, s->rscratch,
                                             s->rscratch_size, &st),
                     FUSE_OK);
    return iou(s->ref, s->truth);
}

static void finds_the_offset(void **state)
{
    scene *s = *state;
    int sh[2][2];
    assert_true(iou(s->kin, s->truth) < 0.6);
    const uint8_t *m = shift_of(s, 3u, s->kin, sh);
    assert_ptr_equal(m, s->out);
    assert_true(abs(sh[0][0] - DX) <= 2 && abs(sh[0][1] - DY) <= 2);
    assert_int_equal(sh[1][0], 0);
    assert_int_equal(sh[1][1], 0);
    assert_true(iou(m, s->truth) > 0.95);
    const double before = refined_iou(s, s->kin), after = refined_iou(s, m);
    assert_true(after > before + 0.05);
    assert_true(after > 0.97);
}

static void stays_where_right(void **state)
{
    scene *s = *state;
    int sh[2][2];
    memcpy(s->kin, s->truth, W * H);
    assert_ptr_equal(shift_of(s, 3u, s->kin, sh), s->kin);
    assert_int_equal(sh[0][0], 0);
    assert_int_equal(sh[0][1], 0);
}

static void outside_the_region_unchanged(void **state)
{
    scene *s = *state;
    int sh[2][2];
    disc(s->kin, 20.0f, 200.0f, 15.0f, 0);   /* another arm, far from the hand */
    const uint8_t *m = shift_of(s, 1u, s->kin, sh);
    assert_ptr_equal(m, s->out);
    long differ = 0;
    for (int y = 180; y < H; y++)
        for (int x = 0; x < 40; x++) differ += m[y * W + x] != s->kin[y * W + x];
    assert_int_equal(differ, 0);
    assert_int_equal(m[200 * W + 20], 255);
}

static void bad_inputs(void **state)
{
    scene *s = *state;
    int sh[2][2];
    assert_ptr_equal(shift_of(s, 2u, s->kin, sh), s->kin);   /* the right hand: out of view */
    assert_ptr_equal(shift_of(s, 0u, s->kin, sh), s->kin);
    assert_ptr_equal(shift_with(s, &s->g, 1u, s->kin, s->scratch_size - 1, sh), s->kin);
    assert_int_equal(sh[0][0], 0);
    fuse_colour_model none = s->g;
    none.fg_samples = 0;
    assert_ptr_equal(shift_with(s, &none, 1u, s->kin, s->scratch_size, sh), s->kin);
    assert_ptr_equal(shift_with(s, NULL, 1u, s->kin, s->scratch_size, sh), s->kin);
    assert_int_equal(pipe_fit_shift_scratch_size(0, H), 0);
}

TU_MAIN_NAMED("fit_shift", NULL, NULL,
              cmocka_unit_test_setup_teardown(finds_the_offset, scene_setup, scene_teardown),
              cmocka_unit_test_setup_teardown(stays_where_right, scene_setup, scene_teardown),
              cmocka_unit_test_setup_teardown(outside_the_region_unchanged, scene_setup,
                                              scene_teardown),
              cmocka_unit_test_setup_teardown(bad_inputs, scene_setup, scene_teardown))
