/* simd_isa_fns.c - the per-ISA check functions of the vector layer's
 * tests in the order of tu_simd_isas (support/simd_isa_test.h): sse2,
 * avx2, avx512, neon. Each is defined on every architecture (a stub
 * returning 0 where its ISA is not built). */
#include "simd_check.h"
#include "simd_fcheck.h"
#include "simd_qcheck.h"
#include "simd_rcheck.h"

tu_simd_check_fn *const tu_simd_check_isa[4] = {tu_simd_check_sse2, tu_simd_check_avx2,
                                                 tu_simd_check_avx512, tu_simd_check_neon};
tu_simd_fcheck_fn *const tu_simd_fcheck_isa[4] = {tu_simd_fcheck_sse2, tu_simd_fcheck_avx2,
                                                   tu_simd_fcheck_avx512, tu_simd_fcheck_neon};
tu_simd_qcheck_fn *const tu_simd_qcheck_isa[4] = {tu_simd_qcheck_sse2, tu_simd_qcheck_avx2,
                                                   tu_simd_qcheck_avx512, tu_simd_qcheck_neon};
tu_simd_rcheck_fn *const tu_simd_rcheck_isa[4] = {tu_simd_rcheck_sse2, tu_simd_rcheck_avx2,
                                                   tu_simd_rcheck_avx512, tu_simd_rcheck_neon};
