/* tu_simd_check_avx512: simd_check.inl on src/cpu/simd_avx512.h (a stub without it) */
#define CK_NAME tu_simd_check_avx512
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx512.h"
#endif
#include "simd_check.inl"
