/* fuse_refine_avx2.c - AVX2 row kernels of the band-only refinement
 * (fuse_refine_kern.h), built with the flags of *_avx2.c and chosen only
 * when cpuid reports AVX2. Same bytes as the reference
 * (tests/test_fuse_refine.c). Every kernel is fuse_refine_simd.inl on the
 * vector layer (src/cpu/simd_avx2.h), the score look-ups by its vf_gather_m
 * (vgatherdps); nothing here is AVX2's own. */
#include "fuse_refine_kern.h"

#if defined(__AVX2__)
#include "../cpu/simd_avx2.h"

#include "fuse_refine_simd.inl"

#else
const fuse__refine_kern *fuse__refine_kern_avx2(void) { return NULL; }
#endif
