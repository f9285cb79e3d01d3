/* kin_skin_sse2.c - skinning kernels, SSE2 (the x86-64 baseline, 4
 * vertices per vector): the vector layer's SSE2 implementation and the one
 * body, kin_skin_simd.inl (its 4-lane blend: a joint matrix is four
 * columns, 4 blended vertices one vf_tr4). Bytes equal the reference
 * (kin_skin.c, kin_dqs.c). On other architectures it compiles to nothing
 * (aarch64 has kin_skin_neon.c). */
#include "kin_skin_internal.h"

#if defined(__x86_64__)
#include <math.h>

#include "../cpu/simd_sse2.h"
#include "kin_skin_simd.inl"

#endif
