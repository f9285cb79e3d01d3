/* pipe_reproj_sse2.c - the reprojection's geometry pass (pipe_reproj_simd.inl)
 * on the vector layer's sse2 implementation. Bytes equal the scalar
 * reference (pipe_reproj.c). On other architectures it compiles to nothing. */
#include "pipe_reproj.h"

#if defined(__x86_64__)
#include "../cpu/simd_sse2.h"
#include "pipe_reproj_simd.inl"
#endif
