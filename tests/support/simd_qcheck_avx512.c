/* tu_simd_qcheck_avx512: simd_qcheck.inl on src/cpu/simd_avx512.h (a stub without it) */
#define QC_NAME tu_simd_qcheck_avx512
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx512.h"
#endif
#include "simd_qcheck.inl"
