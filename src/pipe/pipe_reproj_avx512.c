/* pipe_reproj_avx512.c - the reprojection's geometry pass (pipe_reproj_simd.inl)
 * on the vector layer's avx512 implementation. Bytes equal the scalar
 * reference (pipe_reproj.c). On other architectures it compiles to nothing. */
#include "pipe_reproj.h"

#if defined(__x86_64__)
#include "../cpu/simd_avx512.h"
#include "pipe_reproj_simd.inl"
#endif
