/* simd_rcheck_neon.c - tu_simd_rcheck_neon: simd_rcheck.inl on the vector
 * layer's neon implementation (src/cpu/simd_neon.h). */
#include "simd_rcheck.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#include "simd_rcheck.inl"
#else
int tu_simd_rcheck_neon(int op, const uint32_t *a, unsigned k, int n, void *out)
{
    (void)op, (void)a, (void)k, (void)n, (void)out;
    return 0;
}
#endif
