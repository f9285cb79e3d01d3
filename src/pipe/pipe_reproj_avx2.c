/* pipe_reproj_avx2.c - the reprojection's geometry pass (pipe_reproj_simd.inl)
 * on the vector layer's avx2 implementation. Bytes equal the scalar
 * reference (pipe_reproj.c). On other architectures it compiles to nothing. */
#include "pipe_reproj.h"

#if defined(__x86_64__)
#include "../cpu/simd_avx2.h"
#include "pipe_reproj_simd.inl"
#endif
