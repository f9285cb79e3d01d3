/* fuse_eye_data.h - the buffers of one eye for fuse_context_frame in the
 * tests (test_fuse_depth.c, test_fuse_bands.c): camera crop P, mask M,
 * scratch layer Q, normals N and hand depth (crop size), virtual image V,
 * output and scene depth (output size). Each test fills them its own way.
 * Header-only; include after support/testutil.h and <cmocka.h>. */
#ifndef EGOFUSE_TU_FUSE_EYE_DATA_H
#define EGOFUSE_TU_FUSE_EYE_DATA_H

#include <stdint.h>
#include <stdlib.h>

typedef struct tu_eye_data {
    uint8_t *P, *M, *Q, *V, *out;
    float *N, *hand, *scene;
} tu_eye_data;

/* Allocates e's buffers for a crop cw x ch and an output ow x oh (their
 * contents undefined); fails the test when out of memory. */
static inline void tu_eye_alloc(tu_eye_data *e, int cw, int ch, int ow, int oh)
{
    const size_t c = (size_t)cw * (size_t)ch, o = (size_t)ow * (size_t)oh;
    e->P = malloc(c * 4);
    e->M = malloc(c);
    e->Q = malloc(c * 4);
    e->V = malloc(o * 4);
    e->out = malloc(o * 4);
    e->N = malloc(sizeof(float) * c * 3);
    e->hand = malloc(sizeof(float) * c);
    e->scene = malloc(sizeof(float) * o);
    assert_true(e->P && e->M && e->Q && e->V && e->out && e->N && e->hand && e->scene);
}

static inline void tu_eye_free(tu_eye_data *e)
{
    free(e->P); free(e->M); free(e->Q); free(e->V); free(e->out);
    free(e->N); free(e->hand); free(e->scene);
}

#endif
