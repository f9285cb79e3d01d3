/* tu_simd_pcheck_avx2: simd_pcheck.inl on src/cpu/simd_avx2.h (a stub without it) */
#define PC_NAME tu_simd_pcheck_avx2
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx2.h"
#endif
#include "simd_pcheck.inl"
