/* fuse_refine_neon.c - NEON row kernels of the band-only refinement
 * (fuse_refine_kern.h), AArch64 Advanced SIMD (the baseline there: no
 * flag). Same bytes as the reference (tests/test_fuse_refine.c under
 * qemu-aarch64, .ci/run part arm64). The kernels are fuse_refine_simd.inl
 * on the vector layer (src/cpu/simd_neon.h); what is NEON's own is the
 * score kernel: the table look-ups have no gather on NEON, so the scores
 * go through the portable kernel. On other targets
 * fuse__refine_kern_neon() returns NULL. */
#include "fuse_refine_kern.h"

#if defined(__aarch64__) && defined(__ARM_NEON)

#include "../cpu/simd_neon.h"

/* the scores: the portable kernel (NEON has no gather for the look-ups) */
#define REFINE_OWN_SCORE
static void SIMD_FN(refine_score_row)(const fuse__refine_tabs *t, const uint8_t *px,
                                      const uint8_t *m, const uint16_t *d, float *s, int a,
                                      int b)
{
    fuse__refine_kern_c.score_row(t, px, m, d, s, a, b);
}

#include "fuse_refine_simd.inl"

#else
const fuse__refine_kern *fuse__refine_kern_neon(void) { return NULL; }
#endif
