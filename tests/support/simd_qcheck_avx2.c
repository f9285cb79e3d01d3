/* tu_simd_qcheck_avx2: simd_qcheck.inl on src/cpu/simd_avx2.h (a stub without it) */
#define QC_NAME tu_simd_qcheck_avx2
#if defined(__x86_64__)
#include "../../src/cpu/simd_avx2.h"
#endif
#include "simd_qcheck.inl"
