/* simd_fcheck_sse2.c - tu_simd_fcheck_sse2: simd_fcheck.inl on the vector
 * layer's sse2 implementation (src/cpu/simd_sse2.h). */
#include "simd_fcheck.h"

#if defined(__x86_64__)
#include "../../src/cpu/simd_sse2.h"
#include "simd_fcheck.inl"
#else
int tu_simd_fcheck_sse2(int op, const uint32_t *a, const uint32_t *b, int n, uint32_t *out)
{
    (void)op, (void)a, (void)b, (void)n, (void)out;
    return 0;
}
#endif
