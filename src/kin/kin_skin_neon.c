/* kin_skin_neon.c - skinning kernels, AArch64 NEON (4 vertices per
 * vector): the vector layer's NEON implementation and the one body,
 * kin_skin_simd.inl, exactly as kin_skin_sse2.c does for SSE2. Bytes equal
 * the reference (kin_skin.c, kin_dqs.c): tests/test_kin_skin_isa.c under
 * qemu-aarch64 (.ci/run part arm64). Elsewhere it compiles to nothing. */
#include "kin_skin_internal.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#include <math.h>

#include "../cpu/simd_neon.h"
#include "kin_skin_simd.inl"

#endif
