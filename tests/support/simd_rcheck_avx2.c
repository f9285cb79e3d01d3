/* tu_simd_rcheck_avx2: simd_rcheck.inl on src/cpu/simd_avx2.h (a stub without it) */
#define RC_NAME tu_simd_rcheck_avx2
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx2.h"
#endif
#include "simd_rcheck.inl"
