/* simd_check_neon.c - tu_simd_check_neon: simd_check.inl on the vector
 * layer's neon implementation (src/cpu/simd_neon.h). */
#include "simd_check.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#include "../../src/cpu/simd_neon.h"
#include "simd_check.inl"
#else
int tu_simd_check_neon(int op, const uint32_t *a, const uint32_t *b, int k, int n, uint32_t *out)
{
    (void)op, (void)a, (void)b, (void)k, (void)n, (void)out;
    return 0;
}
#endif
