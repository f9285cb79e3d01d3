/* raster_sse2.c - the SSE2 scan (x86-64 baseline, 4 lanes): raster_simd.inl
 * on the vector layer's SSE2 implementation (src/cpu/simd_sse2.h), whose
 * partial vectors go through scalar lane loops, so no access ever leaves
 * the scanned pixels. Bytes equal rast__scan_rows_ref. */
#include "raster_internal.h"

#if defined(__x86_64__) || (defined(__i386__) && defined(__SSE2__))
#include "../cpu/simd_sse2.h"
#include "raster_simd.inl"

/* Anti-aliased coverage: 2 double lanes. */
#define AA_V 2
#define AA_FN rast__scan_aa_sse2
#include "raster_aa.inl"

#else
typedef int rast__sse2_unused;   /* not x86: the dispatcher uses the reference */
#endif
