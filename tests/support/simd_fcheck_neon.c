/* tu_simd_fcheck_neon: simd_fcheck.inl on src/cpu/simd_neon.h (a stub without it) */
#define FC_NAME tu_simd_fcheck_neon
#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#endif
#include "simd_fcheck.inl"
