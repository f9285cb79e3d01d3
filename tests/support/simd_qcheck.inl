/* simd_qcheck.inl - the body of tu_simd_qcheck_<isa> (simd_qcheck.h), named
 * QC_NAME, on the vector layer included before it; without one (the ISA
 * is not this target's) a stub that returns 0. */
#include "simd_qcheck.h"

#ifndef SIMD_W
int QC_NAME(int op, const uint16_t *a, const uint16_t *b, int n, uint32_t *out)
{
    (void)op, (void)a, (void)b, (void)n, (void)out;
    return 0;
}
#else
int QC_NAME(int op, const uint16_t *a, const uint16_t *b, int n, uint32_t *out)
{
    const uint8_t *ab = (const uint8_t *)(const void *)a;
    uint8_t *ob = (uint8_t *)(void *)out;
    uint16_t *oh = (uint16_t *)(void *)out;
    switch (op) {
    case QC_SIGN_BITS:
        for (int v = 0; v + VB_W <= n; v += VB_W) {
            const uint64_t bits = vb_sign_bits(vb_loadu(ab + v));
            for (int l = 0; l < VB_W; l++) ob[v + l] = (uint8_t)((bits >> l) & 1u);
            if (VB_W < 64 && (bits >> (VB_W % 64))) ob[v] = 0xEE;   /* stray bits */
        }
        break;
    case QC_SIGN_FILL:
        for (int v = 0; v + VB_W <= n; v += VB_W) vb_storeu(ob + v, vb_sign_fill(vb_loadu(ab + v)));
        break;
    case QC_H_LOAD_U8:
        for (int v = 0; v + VH_W <= n; v += VH_W) vh_storeu(oh + v, vh_load_u8(ab + v));
        break;
    case QC_H_MIN_U:
        for (int v = 0; v + VH_W <= n; v += VH_W)
            vh_storeu(oh + v, vh_min_u(vh_loadu(a + v), vh_loadu(b + v)));
        break;
    case QC_H_ADDS_U:
        for (int v = 0; v + VH_W <= n; v += VH_W)
            vh_storeu(oh + v, vh_adds_u(vh_loadu(a + v), vh_loadu(b + v)));
        break;
    case QC_H_ANY_LEU:
        for (int v = 0; v + VH_W <= n; v += VH_W) {
            for (int l = 0; l < VH_W; l++) oh[v + l] = 0;
            oh[v] = (uint16_t)vh_any_leu(vh_loadu(a + v), vh_loadu(b + v));
        }
        break;
    case QC_LOAD_U16:
        for (int v = 0; v + SIMD_W <= n; v += SIMD_W)
            vi_storeu((int32_t *)(void *)(out + v), vi_load_u16(a + v));
        break;
    case QC_H_RUNMIN3_UP:
        for (int v = 0; v + VH_W <= n; v += VH_W) vh_storeu(oh + v, vh_runmin3_up(vh_loadu(a + v), b[v]));
        break;
    case QC_H_RUNMIN3_DN:
        for (int v = 0; v + VH_W <= n; v += VH_W) vh_storeu(oh + v, vh_runmin3_dn(vh_loadu(a + v), b[v]));
        break;
    default: return -1;
    }
    return SIMD_W;
}
#endif
