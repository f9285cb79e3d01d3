/* tu_simd_check_neon: simd_check.inl on src/cpu/simd_neon.h (a stub without it) */
#define CK_NAME tu_simd_check_neon
#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#endif
#include "simd_check.inl"
