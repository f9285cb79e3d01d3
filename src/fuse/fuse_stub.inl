/* fuse_stub.inl - the kernels of fuse_simd.inl for an ISA file compiled
 * where its ISA is not enabled (an x86 file on ARM, a NEON file on x86):
 * the reference stands in under the ISA's names, so the dispatch table
 * and the tests link on every target. cpuid never chooses them there.
 * The including file defines FUSE_STUB(name) (name##_avx2, ...). */

void FUSE_STUB(fuse__light_row)(const fuse__light_prep *p, int y, int width,
                                const uint8_t *P, const uint8_t *mask,
                                const float *normal, uint8_t *out)
{
    fuse__light_row_ref(p, y, width, P, mask, normal, out);
}

void FUSE_STUB(fuse__light_span)(const fuse__light_prep *p, int y, int x0, int x1,
                                 const uint8_t *P, const uint8_t *mask,
                                 const float *normal, uint8_t *out)
{
    fuse__light_span_ref(p, y, x0, x1, P, mask, normal, out);
}

void FUSE_STUB(fuse__light_span_n10)(const fuse__light_prep *p, int y, int x0, int x1,
                                     const uint8_t *P, const uint8_t *mask,
                                     const uint32_t *normal, uint8_t *out)
{
    fuse__light_span_n10_ref(p, y, x0, x1, P, mask, normal, out);
}

void FUSE_STUB(fuse__pow01_row)(const float *x, int n, float s, float *out)
{
    int i;
    for (i = 0; i < n; i++) out[i] = fuse__pow01(x[i], s);
}

void FUSE_STUB(fuse__depth_row)(const fuse__depth_prep *p, uint8_t *q, const float *hz,
                                const float *sc, int w)
{
    fuse__depth_row_ref(p, q, hz, sc, w);
}

void FUSE_STUB(fuse__depth_mrow)(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                                 const float *sc, int w)
{
    fuse__depth_mrow_ref(p, m, hz, sc, w);
}

void FUSE_STUB(fuse__depth_mspan)(const fuse__depth_prep *p, uint8_t *m, const float *hz,
                                  const float *sc, int x0, int x1)
{
    fuse__depth_mspan_ref(p, m, hz, sc, x0, x1);
}

void FUSE_STUB(fuse__cover_span)(const uint8_t *q, int w, int x0, int x1, uint64_t *bits)
{
    fuse__cover_span_ref(q, w, x0, x1, bits);
}

void FUSE_STUB(fuse__cover_row)(const uint8_t *q, int w, uint64_t *bits)
{
    fuse__cover_row_ref(q, w, bits);
}

#ifdef FUSE_COLS_ON_LAYER
void FUSE_STUB(fuse__composite_cols)(const uint8_t *q0, const uint8_t *q1, uint32_t fy,
                                     const fuse__cols *cols, int c, int n, int sw,
                                     const uint8_t *v, uint8_t *out)
{
    fuse__composite_cols_ref(q0, q1, fy, cols, c, n, sw, v, out);
}
#endif

#ifdef FUSE_YUV_ON_LAYER
int FUSE_STUB(fuse__yuv422_row)(const uint8_t *src, int width, int uyvy, uint8_t *dst)
{
    (void)src, (void)width, (void)uyvy, (void)dst;
    return 0;   /* none: the caller's scalar loop converts the row */
}
#endif

void FUSE_STUB(fuse__opaque)(const uint8_t *v, uint8_t *out, int n)
{
    fuse__opaque_ref(v, out, n);
}

#ifdef FUSE_ROWCACHE_ON_LAYER
void FUSE_STUB(fuse__hprep)(fuse__cols *cols, int n, int sw)
{
    (void)cols, (void)n, (void)sw;   /* the stub's hrow needs no tables */
}

void FUSE_STUB(fuse__hrow)(const uint8_t *q, const fuse__cols *cols, int c, int n, int sw,
                           uint16_t *h)
{
    int i;
    for (i = 0; i < n; i++) fuse__hpx(q, cols->ix[c + i], (uint32_t)cols->fx[c + i], sw, h + 4 * i);
}

void FUSE_STUB(fuse__vrow)(const uint16_t *h0, const uint16_t *h1, uint32_t fy,
                           const uint8_t *v, uint8_t *out, int n)
{
    int i;
    for (i = 0; i < n; i++) fuse__vpx(h0 + 4 * i, h1 + 4 * i, fy, v + 4 * i, out + 4 * i);
}
#endif
