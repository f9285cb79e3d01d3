/* pipe_reproj_neon.c - the reprojection's geometry pass (pipe_reproj_simd.inl)
 * on the vector layer's AArch64 NEON implementation. Bytes equal the scalar
 * reference (pipe_reproj.c). Elsewhere it compiles to nothing. */
#include "pipe_reproj.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../cpu/simd_neon.h"
#include "pipe_reproj_simd.inl"
#endif
