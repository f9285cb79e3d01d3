/* raster_avx2.c - the AVX2 scan (8 lanes): raster_simd.inl on the vector
 * layer's AVX2 implementation (src/cpu/simd_avx2.h); the batched set-up
 * (raster_planes.inl) with its AVX2 lane macros. Built with -mavx2 -mf16c (Makefile); called only when cpuid
 * reports AVX2 (raster_context.c). Bytes equal rast__scan_rows_ref. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <string.h>

#include "../cpu/simd_avx2.h"
#include "raster_simd.inl"

/* Anti-aliased coverage: 4 double lanes. */
#define AA_V 4
#define AA_FN rast__scan_aa_avx2
#include "raster_aa.inl"

/* Batched set-up (raster_planes.inl): planes in 4 double lanes, vertex fills. */
#define PD_V 4
#define PLANES_FN rast__planes_avx2
typedef __m256d vd;
#define PD_LOAD(p) _mm256_load_pd(p)
#define PD_SET1(x) _mm256_set1_pd(x)
#define PD_ADD(a, b) _mm256_add_pd(a, b)
#define PD_SUB(a, b) _mm256_sub_pd(a, b)
#define PD_MUL(a, b) _mm256_mul_pd(a, b)
#define PD_DIV(a, b) _mm256_div_pd(a, b)
#define PD_MAX(a, b) _mm256_max_pd(a, b)
#define PD_STORE_F(p, v) _mm_storeu_ps(p, _mm256_cvtpd_ps(v))
#define PS_V 8
#define VFILL_FN rast__vfill_avx2
#define SETUP_ISA rast__setup_isa_avx2
typedef __m256 vs;
#define PS_LOAD(p) _mm256_load_ps(p)
#define PS_SET1(x) _mm256_set1_ps(x)
#define PS_ADD(a, b) _mm256_add_ps(a, b)
#define PS_SUB(a, b) _mm256_sub_ps(a, b)
#define PS_MUL(a, b) _mm256_mul_ps(a, b)
#define PS_DIV(a, b) _mm256_div_ps(a, b)
#define PS_MAX(a, b) _mm256_max_ps(a, b)
#define PS_MIN(a, b) _mm256_min_ps(a, b)
#define PS_LT_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LT_OQ)))
#define PS_LE_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ)))
#define PS_GT_BITS(a, b) ((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_GT_OQ)))
#define PS_CVT_STORE(p, v) _mm256_store_si256((__m256i *)(void *)(p), _mm256_cvtps_epi32(v))
#define PD_LOAD_F(p) _mm256_cvtps_pd(_mm_load_ps(p))
#define PD_STORE(p, v) _mm256_store_pd(p, v)
/* The vector front end: raster_front_avx2.c. */
#define VPASS_FN rast__vpass_avx2
#define FRONTV_FN rast__frontv_avx2
#include "raster_planes.inl"

#else
typedef int rast__avx2_unused;   /* not an x86 build: the dispatcher skips it */
#endif
