/* tu_simd_pcheck_avx512: simd_pcheck.inl on src/cpu/simd_avx512.h (a stub without it) */
#define PC_NAME tu_simd_pcheck_avx512
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx512.h"
#endif
#include "simd_pcheck.inl"
