/* raster_neon.c - the NEON scan (AArch64 Advanced SIMD, 4 lanes):
 * raster_simd.inl on the vector layer's NEON implementation
 * (src/cpu/simd_neon.h), the anti-aliased sample scan (raster_aa.inl,
 * 2 double lanes in vector extensions) and the batched set-up
 * (raster_planes.inl, 2 double lanes). Bytes equal rast__scan_rows_ref
 * and rast__scan_aa_ref (checked under qemu-aarch64 by the raster tests).
 * Compiles to nothing off aarch64. */
#include "raster_internal.h"

#if defined(__aarch64__) && defined(__ARM_NEON)
#include <stddef.h>
#include <string.h>

#include "../cpu/simd_neon.h"
#include "raster_simd.inl"

/* Anti-aliased coverage: 2 double lanes. */
#define AA_V 2
#define AA_FN rast__scan_aa_neon
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
typedef int rast__neon_unused;   /* not aarch64: the dispatcher never names it */
#endif
