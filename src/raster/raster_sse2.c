/* raster_sse2.c - the SSE2 kernels (x86-64 baseline): the scan
 * (raster_simd.inl, 4 lanes), the sample scan (raster_aa.inl) and the
 * batched set-up (raster_planes.inl, 2 double lanes) on the vector layer's
 * SSE2 implementation (src/cpu/simd_sse2.h), whose partial vectors go
 * through scalar lane loops, so no access ever leaves the scanned pixels.
 * Bytes equal the reference's. */
#include "raster_internal.h"

#if defined(__x86_64__) || (defined(__i386__) && defined(__SSE2__))
#include "../cpu/simd_sse2.h"
#include "raster_simd.inl"

/* Anti-aliased coverage: 2 double lanes. */
#define AA_V 2
#define AA_FN rast__scan_aa_sse2
#include "raster_aa.inl"

/* Batched set-up: vertex fills in 4 float lanes; planes in 2 double lanes
 * compiled (and checked against the reference by test_raster_isa on x86)
 * but the table keeps the scalar planes: with 2 double lanes, one
 * triangle per lane costs more than the scalar set-up, whose planes of one
 * triangle run in 4 double lanes of vector extensions (cachegrind, the
 * sample model and bench scene through bench_raster --isa sse2: planes
 * 234M instructions against 65M scalar; vertex fills 201M against 258M).
 * NEON has the same 2 double lanes. */
#include <float.h>
#define SETUP_PLANES rast__planes_ref
#include "raster_planes.inl"

#else
typedef int rast__sse2_unused;   /* not x86: the dispatcher uses the reference */
#endif
