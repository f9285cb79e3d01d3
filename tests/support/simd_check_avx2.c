/* tu_simd_check_avx2: simd_check.inl on src/cpu/simd_avx2.h (a stub without it) */
#define CK_NAME tu_simd_check_avx2
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx2.h"
#endif
#include "simd_check.inl"
