/* tu_simd_rcheck_sse2: simd_rcheck.inl on src/cpu/simd_sse2.h (a stub without it) */
#define RC_NAME tu_simd_rcheck_sse2
#if defined(__x86_64__)
#include "../../src/cpu/simd_sse2.h"
#endif
#include "simd_rcheck.inl"
