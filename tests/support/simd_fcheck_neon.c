/* simd_fcheck_neon.c - tu_simd_fcheck_neon: simd_fcheck.inl on the vector
 * layer's neon implementation (src/cpu/simd_neon.h). */
#include "simd_fcheck.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#include "simd_fcheck.inl"
#else
int tu_simd_fcheck_neon(int op, const uint32_t *a, const uint32_t *b, int n, uint32_t *out)
{
    (void)op, (void)a, (void)b, (void)n, (void)out;
    return 0;
}
#endif
