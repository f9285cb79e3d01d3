/* tu_simd_rcheck_neon: simd_rcheck.inl on src/cpu/simd_neon.h (a stub without it) */
#define RC_NAME tu_simd_rcheck_neon
#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#endif
#include "simd_rcheck.inl"
