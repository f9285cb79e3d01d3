/* tu_simd_rcheck_avx512: simd_rcheck.inl on src/cpu/simd_avx512.h (a stub without it) */
#define RC_NAME tu_simd_rcheck_avx512
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx512.h"
#endif
#include "simd_rcheck.inl"
