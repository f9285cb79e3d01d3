/* raster_avx2.c - the AVX2 kernels: the scan (raster_simd.inl, 8 lanes),
 * the batched set-up (raster_planes.inl, 4 double lanes) and the sample
 * scan (raster_aa.inl), on the vector layer's AVX2 implementation
 * (src/cpu/simd_avx2.h); the vector front end is raster_front_avx2.c.
 * Built with -mavx2 -mf16c (Makefile); called only when cpuid reports
 * AVX2 (raster_context.c). Bytes equal the reference's. */
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

/* The vector front end: raster_front_avx2.c. */
#define VPASS_FN rast__vpass_avx2
#define FRONTV_FN rast__frontv_avx2
#include "raster_planes.inl"

#else
typedef int rast__avx2_unused;   /* not an x86 build: the dispatcher skips it */
#endif
