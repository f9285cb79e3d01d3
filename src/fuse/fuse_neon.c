/* fuse_neon.c - the NEON path of the fuse kernels (AArch64 Advanced SIMD,
 * the baseline there: no flag): fuse_simd.inl on the vector layer
 * (src/cpu/simd_neon.h, 4 lanes; the depth test's scene values lane by
 * lane), as fuse_sse2.c does for SSE2, the per-row composite
 * (fuse__composite_cols_neon, 16-bit lanes) and the YUYV conversion
 * included. The bytes are the reference's: tests/test_fuse_isa.c and
 * test_fuse_formats.c under qemu-aarch64 (.ci/run part arm64). On other
 * targets the reference stands in under these names. */
#include "fuse_internal.h"

#if defined(__aarch64__) && defined(__ARM_NEON)

#include "../cpu/simd_neon.h"

#define FUSE_YUV_ON_LAYER 1
#define FUSE_COLS_ON_LAYER 1
#include "fuse_simd.inl"

#else

#define FUSE_STUB(name) name##_neon
#define FUSE_YUV_ON_LAYER 1
#define FUSE_COLS_ON_LAYER 1
#include "fuse_stub.inl"

#endif
