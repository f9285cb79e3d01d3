/* tu_simd_pcheck_neon: simd_pcheck.inl on src/cpu/simd_neon.h (a stub without it) */
#define PC_NAME tu_simd_pcheck_neon
#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#endif
#include "simd_pcheck.inl"
