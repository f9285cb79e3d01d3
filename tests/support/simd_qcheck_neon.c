/* tu_simd_qcheck_neon: simd_qcheck.inl on src/cpu/simd_neon.h (a stub without it) */
#define QC_NAME tu_simd_qcheck_neon
#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#endif
#include "simd_qcheck.inl"
