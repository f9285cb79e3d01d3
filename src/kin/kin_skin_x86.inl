/* kin_skin_x86.inl - the per-vertex dual-quaternion blend that the AVX2
 * and AVX-512 skinning kernels share (one vertex's r and d in one ymm);
 * included by kin_skin_avx2.c (its dqs_block) and kin_skin_avx512.c (its
 * rows path, dqs_rows) after their vector layer, so it is compiled once
 * per ISA with that file's flags. Not a kernel of its own: the 4-lane
 * blend of kin_skin_simd.inl (SSE2, NEON) keeps r and d in two vectors.
 *
 * dqs_vertex8: the weights w[0..3] of joints j[0..3], skipping zero
 * weights (kin__nonzero4), each joint's dual quaternion added onto +0 in
 * influence order with its weight, negated where its rotation points
 * away from the first influence's (r . r_first < 0), exactly as
 * kin__skin_dqs_ref does lane by lane; *wsum: the plain weight sum. */
SIMD_INL __m256 dqs_vertex8(const kin_dualquat *dq, const uint16_t *j, const float *w,
                            float *wsum)
{
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
        acc = _mm256_add_ps(acc, _mm256_mul_ps(_mm256_set1_ps(sw), _mm256_loadu_ps(&q->r.x)));
        s += w[i];
    }
    *wsum = s;
    return acc;
}
