/* tu_simd_fcheck_sse2: simd_fcheck.inl on src/cpu/simd_sse2.h (a stub without it) */
#define FC_NAME tu_simd_fcheck_sse2
#if defined(__x86_64__)
#include "../../src/cpu/simd_sse2.h"
#endif
#include "simd_fcheck.inl"
