/* fuse_sse2.c - the SSE2 path of the fuse kernels: the x86-64 baseline
 * (no flags needed). The bytes are the reference's (docs/fuse.md,
 * "Rounding rules"); tests/test_fuse_isa.c checks it.
 * Lighting, depth test, coverage bits, opaque copies: fuse_simd.inl on the
 * vector layer (src/cpu/simd_sse2.h, 4 lanes; the scene values of the
 * depth test lane by lane: SSE2 has no gather).
 * Composite per output row (fuse__composite_cols_sse2): also fuse_simd.inl,
 * 4 output pixels per step, blend and over in the layer's 16-bit lanes.
 * On a machine without SSE2 (ARM) the reference kernels stand in. */
#include "fuse_internal.h"

#if defined(__SSE2__)
#include <emmintrin.h>

#include "../cpu/simd_sse2.h"

/* 4 interleaved xyz normals -> x, y, z, each vector built from its four
 * scalars in registers (no store and reload through a buffer) */
#define FUSE_LOAD_NORMALS(p, x, y, z) do { const float *q_ = (p); \
        (x) = _mm_setr_ps(q_[0], q_[3], q_[6], q_[9]); \
        (y) = _mm_setr_ps(q_[1], q_[4], q_[7], q_[10]); \
        (z) = _mm_setr_ps(q_[2], q_[5], q_[8], q_[11]); } while (0)

#define FUSE_YUV_ON_LAYER 1
#define FUSE_COLS_ON_LAYER 1
#include "fuse_simd.inl"


#else  /* no SSE2 (e.g. ARM): the reference kernels */

#define FUSE_STUB(name) name##_sse2
#define FUSE_YUV_ON_LAYER 1
#define FUSE_COLS_ON_LAYER 1
#include "fuse_stub.inl"

#endif
