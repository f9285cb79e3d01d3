/* ef_n10.h - three attributes in [-1, 1] (a normal) packed in 32 bits.
 *
 * WHAT IT DOES: one normal per uint32_t, 10 bits per component: bits 0-9
 * hold x, 10-19 y, 20-29 z, each a 10-bit two's complement integer k in
 * -511..511 standing for k / 511; bits 30-31 are 0. The raster can write
 * its three attributes in this form (rast_target.attr_n10) and the fuse
 * stage lights from it (fuse_eye.normal_n10): a third of the bytes of
 * three floats, and one 32-bit lane per pixel, so neither side shuffles
 * three interleaved floats.
 * WHAT IT DOES NOT: normalise (the lighting does; an interpolated normal
 * is shorter than 1 between diverging vertex normals, and the packing
 * keeps its length), or keep more than 1/1022 of precision per component
 * (about 0.1 degree: a lit 8-bit pixel moves by at most about one level).
 *
 * The packing of a float a, which every SIMD path of the raster follows
 * exactly (a multiply, two compares, a conversion to nearest, ties to
 * even: cvtps2dq, NEON's vcvtnq):
 *   v = a * 511.0f; v = v > -511 ? v : -511 (NaN too); v = v > 511 ? 511 : v;
 *   k = v rounded to the nearest integer, ties to even.
 * The unpacking: (float)k * (1.0f / 511.0f), the constant rounded once.
 *
 * USAGE:
 *   uint32_t p = ef_n10_pack(nx, ny, nz);
 *   float n[3]; ef_n10_unpack(p, n);
 */
#ifndef EGOFUSE_EF_N10_H
#define EGOFUSE_EF_N10_H

#include <math.h>
#include <stdint.h>

#define EF_N10_SCALE 511.0f
#define EF_N10_INV (1.0f / 511.0f)

/* One component: the integer k of a (see above). */
static inline int32_t ef_n10_quant(float a)
{
    float v = a * EF_N10_SCALE;
    if (!(v > -EF_N10_SCALE)) v = -EF_N10_SCALE;
    if (v > EF_N10_SCALE) v = EF_N10_SCALE;
    return (int32_t)lrintf(v);
}

static inline uint32_t ef_n10_pack(float x, float y, float z)
{
    return ((uint32_t)ef_n10_quant(x) & 0x3ffu) | (((uint32_t)ef_n10_quant(y) & 0x3ffu) << 10) |
           (((uint32_t)ef_n10_quant(z) & 0x3ffu) << 20);
}

/* Component c (0, 1, 2) of p as its integer k. */
static inline int32_t ef_n10_k(uint32_t p, int c)
{
    int32_t k = (int32_t)((p >> (10 * c)) & 0x3ffu);
    return k >= 512 ? k - 1024 : k;
}

static inline void ef_n10_unpack(uint32_t p, float n[3])
{
    for (int c = 0; c < 3; c++) n[c] = (float)ef_n10_k(p, c) * EF_N10_INV;
}

#endif
