/* kin_skin_avx2.c - skinning kernels, AVX2 (8 vertices per vector) with
 * kin_skin_simd.inl. A vertex's joint matrix is two ymm (columns 0-1 and
 * 2-3), its dual quaternion one ymm; 8 blended vertices are transposed
 * with in-lane 4x4 transposes and 128-bit lane permutes. Bytes equal the
 * reference (kin_skin.c, kin_dqs.c). Built with -mavx2 (no FMA: the
 * build has -ffp-contract=off and no -mfma). */
#include "kin_skin_internal.h"

#if defined(__x86_64__)
#include <immintrin.h>
#include <math.h>

#define W 8
#define V __m256
#define M __m256
#define SIMD_LBS kin__skin_lbs_avx2
#define SIMD_LBS_PLAN kin__skin_lbs_plan_avx2
#define SIMD_DQS_PLAN kin__skin_dqs_plan_avx2
#define VLOAD(p) _mm256_load_ps(p)
#define VNEG(x) _mm256_xor_ps(x, _mm256_set1_ps(-0.0f))
#define SIMD_DQS kin__skin_dqs_avx2
#define VSET1(x) _mm256_set1_ps(x)
#define VADD(a, b) _mm256_add_ps(a, b)
#define VSUB(a, b) _mm256_sub_ps(a, b)
#define VMUL(a, b) _mm256_mul_ps(a, b)
#define VDIV(a, b) _mm256_div_ps(a, b)
#define VSQRT(a) _mm256_sqrt_ps(a)
#define M_NE(a, b) _mm256_cmp_ps(a, b, _CMP_NEQ_UQ)
#define M_GT(a, b) _mm256_cmp_ps(a, b, _CMP_GT_OQ)
#define M_LT(a, b) _mm256_cmp_ps(a, b, _CMP_LT_OQ)
#define M_AND(a, b) _mm256_and_ps(a, b)
#define SEL(m, t, f) _mm256_blendv_ps(f, t, m)
#define SELZ(m, t) _mm256_and_ps(m, t)
#define NEG_IF(m, x) _mm256_xor_ps(x, _mm256_and_ps(m, _mm256_set1_ps(-0.0f)))
#define M_ALL(m) (_mm256_movemask_ps(m) == 0xFF)
#define VMAX(a, b) _mm256_max_ps(a, b)
#define VMIN(a, b) _mm256_min_ps(a, b)
#define VABS(x) _mm256_and_ps(x, _mm256_castsi256_ps(_mm256_set1_epi32(0x7FFFFFFF)))
#define VEXP2(x) _mm256_and_ps(x, _mm256_castsi256_ps(_mm256_set1_epi32(0x7F800000)))

/* In-lane 4x4 transposes (per 128-bit lane) of r0..r3. */
static inline void tr4(__m256 r0, __m256 r1, __m256 r2, __m256 r3, __m256 o[4])
{
    __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(r0, r1));
    __m256d t1 = _mm256_castps_pd(_mm256_unpacklo_ps(r2, r3));
    __m256d t2 = _mm256_castps_pd(_mm256_unpackhi_ps(r0, r1));
    __m256d t3 = _mm256_castps_pd(_mm256_unpackhi_ps(r2, r3));
    o[0] = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t1));
    o[1] = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t1));
    o[2] = _mm256_castpd_ps(_mm256_unpacklo_pd(t2, t3));
    o[3] = _mm256_castpd_ps(_mm256_unpackhi_pd(t2, t3));
}

/* No per-call state here. */
typedef struct skin_tab { int unused; } skin_tab;
static inline void tab_init(skin_tab *t) { t->unused = 0; }

static inline void lbs_block(skin_tab *tab, const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             __m256 a[12], __m256 *wsum)
{
    _Alignas(32) float ws[8];
    __m256 r[2][8];
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 8; l++, j += 4, w += 4) {
        __m256 lo = _mm256_setzero_ps(), hi = _mm256_setzero_ps();
        float s = 0.0f;
        for (unsigned bits = kin__nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            __m256 wv = _mm256_set1_ps(w[i]);
            lo = _mm256_add_ps(lo, _mm256_mul_ps(wv, _mm256_loadu_ps(jm[j[i]].m)));
            hi = _mm256_add_ps(hi, _mm256_mul_ps(wv, _mm256_loadu_ps(jm[j[i]].m + 8)));
            s += w[i];
        }
        r[0][l] = lo;
        r[1][l] = hi;
        ws[l] = s;
    }
    *wsum = _mm256_load_ps(ws);
    for (int h = 0; h < 2; h++) {
        /* s[I][rho], lane L: column 2h+L, row rho of vertices 4I..4I+3 */
        __m256 s[2][4];
        for (int I = 0; I < 2; I++)
            tr4(r[h][4 * I], r[h][4 * I + 1], r[h][4 * I + 2], r[h][4 * I + 3], s[I]);
        for (int rho = 0; rho < 3; rho++) {
            a[(2 * h) * 3 + rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x20);
            a[(2 * h + 1) * 3 + rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x31);
        }
    }
}

static inline void dqs_block(skin_tab *tab, const kin_mesh *mesh, const kin_dualquat *dq, int v,
                             __m256 b[8], __m256 *wsum)
{
    _Alignas(32) float ws[8];
    __m256 r[8];
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 8; l++, j += 4, w += 4) {
        __m256 acc = _mm256_setzero_ps();
        float s = 0.0f;
        const kin_quat *r0 = NULL;
        for (unsigned bits = kin__nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            const kin_dualquat *q = &dq[j[i]];
            float sw = w[i];
            if (!r0) {
                r0 = &q->r;
            } else {
                float dot = q->r.x * r0->x + q->r.y * r0->y + q->r.z * r0->z + q->r.w * r0->w;
                if (dot < 0.0f) sw = -w[i];
            }
            acc = _mm256_add_ps(acc, _mm256_mul_ps(_mm256_set1_ps(sw),
                                                   _mm256_loadu_ps(&q->r.x)));
            s += w[i];
        }
        r[l] = acc;
        ws[l] = s;
    }
    *wsum = _mm256_load_ps(ws);
    __m256 s[2][4];
    for (int I = 0; I < 2; I++) tr4(r[4 * I], r[4 * I + 1], r[4 * I + 2], r[4 * I + 3], s[I]);
    for (int rho = 0; rho < 4; rho++) {
        b[rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x20);
        b[4 + rho] = _mm256_permute2f128_ps(s[0][rho], s[1][rho], 0x31);
    }
}

/* x y z x y z ... (24 floats) <-> three SoA vectors: component k of
 * vertex v is float 3v + k, in lane (3v+k)%8 of register (3v+k)/8. The
 * lanes of one component are distinct, so two blends gather them into one
 * register and one permute puts them in vertex order (the blend
 * immediates below are those lane sets; the test compares every lane). */
typedef struct lay3 { __m256i gidx[3], sidx[3]; } lay3;

static inline void lay3_init(lay3 *L)
{
    for (int k = 0; k < 3; k++) {
        _Alignas(32) int gi[8], si[8];
        for (int v = 0; v < 8; v++) {
            gi[v] = (3 * v + k) % 8;
            si[(3 * v + k) % 8] = v;
        }
        L->gidx[k] = _mm256_load_si256((const __m256i *)gi);
        L->sidx[k] = _mm256_load_si256((const __m256i *)si);
    }
}

static inline void deint3(const lay3 *L, const float *p, __m256 o[3])
{
    __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
    /* lanes of x in b: 1 4 7, in c: 2 5; y: b 2 5, c 0 3 6; z: b 0 3 6, c 1 4 7 */
    o[0] = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(a, b, 0x92), c, 0x24), L->gidx[0]);
    o[1] = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(a, b, 0x24), c, 0x49), L->gidx[1]);
    o[2] = _mm256_permutevar8x32_ps(_mm256_blend_ps(_mm256_blend_ps(a, b, 0x49), c, 0x92), L->gidx[2]);
}

static inline void int3(const lay3 *L, float *p, const __m256 in[3])
{
    __m256 x = _mm256_permutevar8x32_ps(in[0], L->sidx[0]);
    __m256 y = _mm256_permutevar8x32_ps(in[1], L->sidx[1]);
    __m256 z = _mm256_permutevar8x32_ps(in[2], L->sidx[2]);
    /* register 0: y in lanes 1 4 7, z in 2 5; 1: y 2 5, z 0 3 6; 2: y 0 3 6, z 1 4 7 */
    _mm256_storeu_ps(p, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x92), z, 0x24));
    _mm256_storeu_ps(p + 8, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x24), z, 0x49));
    _mm256_storeu_ps(p + 16, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x49), z, 0x92));
}

/* One vertex's x y z (lanes 0-2 of x) to p: 8 bytes and 4 bytes. */
static inline __attribute__((always_inline)) void store3(float *p, __m128 x)
{
    _mm_storel_pi((__m64 *)p, x);
    _mm_store_ss(p + 2, _mm_movehl_ps(x, x));
}

/* Three SoA vectors (8 lanes) to out + 3 dest[l], via in-lane transposes. */
static inline __attribute__((always_inline)) void scat3(float *out, const int32_t *dest, const __m256 o[3])
{
    __m256 t[4];
    tr4(o[0], o[1], o[2], o[2], t);   /* t[k], lane J: vertex 4J + k */
#pragma GCC unroll 4
    for (int k = 0; k < 4; k++) {
        store3(out + 3 * (size_t)dest[k], _mm256_castps256_ps128(t[k]));
        store3(out + 3 * (size_t)dest[4 + k], _mm256_extractf128_ps(t[k], 1));
    }
}

#include "kin_skin_simd.inl"

#endif
