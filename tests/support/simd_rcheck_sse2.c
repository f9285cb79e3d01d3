/* simd_rcheck_sse2.c - tu_simd_rcheck_sse2: simd_rcheck.inl on the vector
 * layer's sse2 implementation (src/cpu/simd_sse2.h). */
#include "simd_rcheck.h"

#if defined(__x86_64__)
#include "../../src/cpu/simd_sse2.h"
#include "simd_rcheck.inl"
#else
int tu_simd_rcheck_sse2(int op, const uint32_t *a, unsigned k, int n, void *out)
{
    (void)op, (void)a, (void)k, (void)n, (void)out;
    return 0;
}
#endif
