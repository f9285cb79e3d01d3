/* raster_avx2.c - the AVX2 kernels: the scan (raster_simd.inl, 8 lanes),
 * the batched set-up (raster_planes.inl, 4 double lanes) and the sample
 * scan (raster_aa.inl), on the vector layer's AVX2 implementation
 * (src/cpu/simd_avx2.h), the vertex transforms (raster_xform.inl); the
 * vector front end is raster_front_avx2.c.
 * Built with -mavx2 -mf16c (Makefile); called only when cpuid reports
 * AVX2 (raster_context.c). Bytes equal the reference's. */
#include "raster_internal.h"

#if defined(__x86_64__) || defined(__i386__)
#include <float.h>
#include <immintrin.h>
#include <string.h>

#include "../cpu/simd_avx2.h"

/* Three attributes (the normals) of a row computed in the interleaved
 * layout, as raster_avx512.c does with 16 lanes: lane f of output vector
 * o (24 floats for 8 pixels) is attribute (8*o + f) % 3 of pixel
 * (8*o + f) / 3; its barycentrics are lanes of the pixels' b1, b2
 * (vpermps copies bits) and its constants a0, d1, d2 those of its
 * attribute, so each float gets the reference's (a0 + b1 * d1) + b2 * d2
 * (simd_attr_store's expression), with no transposition through the stack
 * and no scalar store per float (vf_store3_bits: 3 stores and a bit scan
 * per pixel, the AVX2 scan's largest cost per covered pixel, issue 17).
 * An output vector whose eight floats all belong to written pixels is one
 * plain store, else one vmaskmovps (only the pixels' floats are written);
 * a row reaches (3 * lanes + 7) / 8 of the three. */
static const int32_t pix3_8[3][8] __attribute__((aligned(32))) = {
    { 0, 0, 0, 1, 1, 1, 2, 2 },
    { 2, 3, 3, 3, 4, 4, 4, 5 },
    { 5, 5, 6, 6, 6, 7, 7, 7 },
};
static const int32_t att3_8[3][8] __attribute__((aligned(32))) = {
    { 0, 1, 2, 0, 1, 2, 0, 1 },
    { 2, 0, 1, 2, 0, 1, 2, 0 },
    { 1, 2, 0, 1, 2, 0, 1, 2 },
};
/* the pixel bit of each float of output vector o */
static const int32_t sel3_8[3][8] __attribute__((aligned(32))) = {
    { 1, 1, 1, 2, 2, 2, 4, 4 },
    { 4, 8, 8, 8, 16, 16, 16, 32 },
    { 32, 32, 64, 64, 64, 128, 128, 128 },
};
/* the pixels an output vector's floats belong to, as bits */
static const unsigned pix3_bits[3] = { 0x07u, 0x3Cu, 0xE0u };

typedef struct attr3_state {
    __m256 a0[3], d1[3], d2[3];   /* per output vector, its lanes' constants */
    int nout;                     /* output vectors a row needs (1..3) */
} attr3_state;

static inline __attribute__((always_inline)) void attr3_prep(attr3_state *st,
                                                             const rast__tri *tri, int lanes)
{
    /* the three floats of each (no byte past them is read) */
    const __m256 a0 = _mm256_setr_ps(tri->a0[0], tri->a0[1], tri->a0[2], 0, 0, 0, 0, 0);
    const __m256 d1 = _mm256_setr_ps(tri->d1[0], tri->d1[1], tri->d1[2], 0, 0, 0, 0, 0);
    const __m256 d2 = _mm256_setr_ps(tri->d2[0], tri->d2[1], tri->d2[2], 0, 0, 0, 0, 0);
    st->nout = lanes >= 8 ? 3 : (3 * lanes + 7) >> 3;
#pragma GCC unroll 3
    for (int o = 0; o < 3; o++) {
        const __m256i k = _mm256_load_si256((const __m256i *)(const void *)att3_8[o]);
        st->a0[o] = _mm256_permutevar8x32_ps(a0, k);
        st->d1[o] = _mm256_permutevar8x32_ps(d1, k);
        st->d2[o] = _mm256_permutevar8x32_ps(d2, k);
    }
}

static inline __attribute__((always_inline)) void attr3_out(float *p, unsigned bits,
                                                            const attr3_state *st, int o,
                                                            __m256 b1, __m256 b2, int in)
{
    const __m256i pix = _mm256_load_si256((const __m256i *)(const void *)pix3_8[o]);
    const __m256 b1o = _mm256_permutevar8x32_ps(b1, pix);
    const __m256 b2o = _mm256_permutevar8x32_ps(b2, pix);
    const __m256 a = _mm256_add_ps(_mm256_add_ps(st->a0[o], _mm256_mul_ps(b1o, st->d1[o])),
                                   _mm256_mul_ps(b2o, st->d2[o]));
    const unsigned need = pix3_bits[o];
    if ((bits & need) == need) {
        _mm256_storeu_ps(p + 8 * o, a);
        return;
    }
    if (!(bits & need))
        return;
    const __m256i sel = _mm256_load_si256((const __m256i *)(const void *)sel3_8[o]);
    const __m256i k = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)bits), sel), sel);
    if (in) {   /* the floats not written get back the bits read */
        const __m256 old = _mm256_loadu_ps(p + 8 * o);
        _mm256_storeu_ps(p + 8 * o, _mm256_blendv_ps(old, a, _mm256_castsi256_ps(k)));
        return;
    }
    _mm256_maskstore_ps(p + 8 * o, k, a);
}

static inline __attribute__((always_inline)) void attr3_store_p(float *p, unsigned bits,
                                                                const attr3_state *st,
                                                                __m256 b1, __m256 b2, int in)
{
    attr3_out(p, bits, st, 0, b1, b2, in);
    if (st->nout > 1) {
        attr3_out(p, bits, st, 1, b1, b2, in);
        if (st->nout > 2)
            attr3_out(p, bits, st, 2, b1, b2, in);
    }
}

/* As attr3_store_p for a vector of `lanes` pixels (bits within them) of a
 * wider row. */
static inline __attribute__((always_inline)) void attr3_store_pl(float *p, unsigned bits,
                                                                 int lanes,
                                                                 const attr3_state *st,
                                                                 __m256 b1, __m256 b2, int in)
{
    attr3_out(p, bits, st, 0, b1, b2, in);
    if (lanes > 2) {
        attr3_out(p, bits, st, 1, b1, b2, in);
        if (lanes > 5)
            attr3_out(p, bits, st, 2, b1, b2, in);
    }
}
/* The depth test of a run vector (DEPTH_RUN, raster_simd.inl) on lane
 * masks: the run's lanes by one compare, the loaded and stored lanes
 * masked by vectors, not rebuilt from bits. Inside the row (in) the eight
 * depths are read and written whole, the lanes that do not pass getting
 * back the bits read: a masked store (vmaskmovps) costs about 12 cycles on
 * AMD Zen 4, a load, a blend and a store about 1. */
static inline __attribute__((always_inline)) unsigned depth_run(float *p, int rem, __m256 z,
                                                                int in)
{
    const __m256i run = _mm256_cmpgt_epi32(_mm256_set1_epi32(rem),
                                           _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    const __m256 d = in ? _mm256_loadu_ps(p) : _mm256_maskload_ps(p, run);
    const __m256 pass = _mm256_and_ps(_mm256_cmp_ps(z, d, _CMP_LT_OQ), _mm256_castsi256_ps(run));
    const unsigned bits = (unsigned)_mm256_movemask_ps(pass);
    if (bits) {
        if (in)
            _mm256_storeu_ps(p, _mm256_blendv_ps(d, z, pass));
        else
            _mm256_maskstore_ps(p, _mm256_castps_si256(pass), z);
    }
    return bits;
}
#define DEPTH_RUN(p, rem, z, in) depth_run(p, rem, z, in)

#define ATTR3_STATE attr3_state
#define ATTR3_PREP(st, tri, lanes) attr3_prep(st, tri, lanes)
#define ATTR3_STORE_P(p, bits, st, b1, b2, in) attr3_store_p(p, bits, st, b1, b2, in)
#define ATTR3_STORE_PL(p, bits, lanes, st, b1, b2, in) attr3_store_pl(p, bits, lanes, st, b1, b2, in)

/* The n10 plane's store (N10_STORE, raster_simd.inl): the packed lanes of
 * the pixels in bits; one plain store for a full vector, inside the row a
 * load, a blend and a store, else one vpmaskmovd. */
static inline __attribute__((always_inline)) void n10_store(uint32_t *p, unsigned bits,
                                                            __m256i v, int in)
{
    if (bits == 0xFFu) {
        _mm256_storeu_si256((__m256i *)(void *)p, v);
        return;
    }
    const __m256i k = simd__lanes_of(bits);
    if (in) {
        const __m256i old = _mm256_loadu_si256((const __m256i *)(const void *)p);
        _mm256_storeu_si256((__m256i *)(void *)p, _mm256_blendv_epi8(old, v, k));
        return;
    }
    _mm256_maskstore_epi32((int *)(void *)p, k, v);
}
#define N10_STORE(p, bits, v, in) n10_store(p, bits, v, in)

#include "raster_simd.inl"

/* The vertex transforms (raster_xform.inl): four component vectors
 * interleaved as 8 xyzw vertices, by 4x4 transposes of each 128-bit half
 * (vf_tr4) and 128-bit lane joins. */
SIMD_INL void xf_store4(float *p, vfloat c0, vfloat c1, vfloat c2, vfloat c3)
{
    vfloat o[4];   /* o[k]: vertex k (low half), vertex 4 + k (high half) */
    vf_tr4(c0, c1, c2, c3, o);
    _mm256_storeu_ps(p, _mm256_permute2f128_ps(o[0], o[1], 0x20));
    _mm256_storeu_ps(p + 8, _mm256_permute2f128_ps(o[2], o[3], 0x20));
    _mm256_storeu_ps(p + 16, _mm256_permute2f128_ps(o[0], o[1], 0x31));
    _mm256_storeu_ps(p + 24, _mm256_permute2f128_ps(o[2], o[3], 0x31));
}
#include "raster_xform.inl"

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
