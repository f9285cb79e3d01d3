/* kin_skin_sse2.c - skinning kernels, SSE2 (the x86-64 baseline, 4
 * vertices per vector) with kin_skin_simd.inl. A vertex's joint matrix is
 * four xmm columns, its dual quaternion two xmm; 4 blended vertices are
 * transposed with _MM_TRANSPOSE4_PS. Positions and normals go through a
 * small aligned buffer (SSE2 has no variable permute). Bytes equal the
 * reference (kin_skin.c, kin_dqs.c). On other architectures the
 * dispatcher uses the reference. */
#include "kin_skin_internal.h"

#if defined(__x86_64__)
#include <emmintrin.h>
#include <math.h>

#define W 4
#define V __m128
#define M __m128
#define SIMD_LBS kin__skin_lbs_sse2
#define SIMD_LBS_PLAN kin__skin_lbs_plan_sse2
#define SIMD_DQS_PLAN kin__skin_dqs_plan_sse2
#define VLOAD(p) _mm_load_ps(p)
#define VNEG(x) _mm_xor_ps(x, _mm_set1_ps(-0.0f))
#define SIMD_DQS kin__skin_dqs_sse2
#define VSET1(x) _mm_set1_ps(x)
#define VADD(a, b) _mm_add_ps(a, b)
#define VSUB(a, b) _mm_sub_ps(a, b)
#define VMUL(a, b) _mm_mul_ps(a, b)
#define VDIV(a, b) _mm_div_ps(a, b)
#define VSQRT(a) _mm_sqrt_ps(a)
#define M_NE(a, b) _mm_cmpneq_ps(a, b)      /* unordered or not equal */
#define M_GT(a, b) _mm_cmpgt_ps(a, b)
#define M_LT(a, b) _mm_cmplt_ps(a, b)
#define M_AND(a, b) _mm_and_ps(a, b)
#define SEL(m, t, f) _mm_or_ps(_mm_and_ps(m, t), _mm_andnot_ps(m, f))
#define SELZ(m, t) _mm_and_ps(m, t)
#define NEG_IF(m, x) _mm_xor_ps(x, _mm_and_ps(m, _mm_set1_ps(-0.0f)))
#define M_ALL(m) (_mm_movemask_ps(m) == 0xF)
#define VMAX(a, b) _mm_max_ps(a, b)
#define VMIN(a, b) _mm_min_ps(a, b)
#define VABS(x) _mm_and_ps(x, _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)))
#define VEXP2(x) _mm_and_ps(x, _mm_castsi128_ps(_mm_set1_epi32(0x7F800000)))

/* No per-call state here. */
typedef struct skin_tab { int unused; } skin_tab;
static inline void tab_init(skin_tab *t) { t->unused = 0; }

static inline void lbs_block(skin_tab *tab, const kin_mesh *mesh, const kin_mat4 *jm, int v,
                             __m128 a[12], __m128 *wsum)
{
    _Alignas(16) float ws[4];
    __m128 r[4][4];   /* [vertex][column] */
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 4; l++, j += 4, w += 4) {
        __m128 c[4] = { _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps() };
        float s = 0.0f;
        for (unsigned bits = kin__nonzero4(w); bits; bits &= bits - 1) {
            int i = __builtin_ctz(bits);
            __m128 wv = _mm_set1_ps(w[i]);
            const float *m = jm[j[i]].m;
            for (int k = 0; k < 4; k++)
                c[k] = _mm_add_ps(c[k], _mm_mul_ps(wv, _mm_loadu_ps(m + 4 * k)));
            s += w[i];
        }
        for (int k = 0; k < 4; k++) r[l][k] = c[k];
        ws[l] = s;
    }
    *wsum = _mm_load_ps(ws);
    for (int k = 0; k < 4; k++) {
        __m128 r0 = r[0][k], r1 = r[1][k], r2 = r[2][k], r3 = r[3][k];
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        a[k * 3] = r0; a[k * 3 + 1] = r1; a[k * 3 + 2] = r2;
    }
}

static inline void dqs_block(skin_tab *tab, const kin_mesh *mesh, const kin_dualquat *dq, int v,
                             __m128 b[8], __m128 *wsum)
{
    _Alignas(16) float ws[4];
    __m128 r[4][2];
    (void)tab;
    const uint16_t *j = mesh->joints + (size_t)v * 4;
    const float *w = mesh->weights + (size_t)v * 4;
    for (int l = 0; l < 4; l++, j += 4, w += 4) {
        __m128 qr = _mm_setzero_ps(), qd = _mm_setzero_ps();
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
            __m128 wv = _mm_set1_ps(sw);
            qr = _mm_add_ps(qr, _mm_mul_ps(wv, _mm_loadu_ps(&q->r.x)));
            qd = _mm_add_ps(qd, _mm_mul_ps(wv, _mm_loadu_ps(&q->d.x)));
            s += w[i];
        }
        r[l][0] = qr;
        r[l][1] = qd;
        ws[l] = s;
    }
    *wsum = _mm_load_ps(ws);
    for (int k = 0; k < 2; k++) {
        __m128 r0 = r[0][k], r1 = r[1][k], r2 = r[2][k], r3 = r[3][k];
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        b[4 * k] = r0; b[4 * k + 1] = r1; b[4 * k + 2] = r2; b[4 * k + 3] = r3;
    }
}

typedef struct lay3 { int unused; } lay3;

static inline void lay3_init(lay3 *L) { L->unused = 0; }

static inline void deint3(const lay3 *L, const float *p, __m128 o[3])
{
    (void)L;
    _Alignas(16) float t[3][4];
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++) t[k][v] = p[3 * v + k];
    for (int k = 0; k < 3; k++) o[k] = _mm_load_ps(t[k]);
}

static inline void int3(const lay3 *L, float *p, const __m128 in[3])
{
    (void)L;
    _Alignas(16) float t[3][4];
    for (int k = 0; k < 3; k++) _mm_store_ps(t[k], in[k]);
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++) p[3 * v + k] = t[k][v];
}

/* Three SoA vectors (4 lanes) to out + 3 dest[l]. */
static inline __attribute__((always_inline)) void scat3(float *out, const int32_t *dest, const __m128 o[3])
{
    __m128 x = o[0], y = o[1], z = o[2], w = o[2];
    _MM_TRANSPOSE4_PS(x, y, z, w);
    const __m128 r[4] = { x, y, z, w };
#pragma GCC unroll 4
    for (int k = 0; k < 4; k++) {
        float *p = out + 3 * (size_t)dest[k];
        _mm_storel_pi((__m64 *)p, r[k]);
        _mm_store_ss(p + 2, _mm_movehl_ps(r[k], r[k]));
    }
}

#include "kin_skin_simd.inl"

#endif
