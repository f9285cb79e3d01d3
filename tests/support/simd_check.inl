/* simd_check.inl - the body of tu_simd_check_<isa> (simd_check.h), on
 * the vector layer included before it (named CK_NAME); without one (the ISA
 * is not this target's) a stub that returns 0. */
#include <string.h>

#include "simd_check.h"

#ifndef SIMD_W
int CK_NAME(int op, const uint32_t *a, const uint32_t *b, int k, int n, uint32_t *out)
{
    (void)op, (void)a, (void)b, (void)k, (void)n, (void)out;
    return 0;
}
#else
SIMD_INL vfloat ld(const uint32_t *p) { return vf_loadu((const float *)(const void *)p); }
SIMD_INL vint ldi(const uint32_t *p) { return vi_loadu((const int32_t *)(const void *)p); }
SIMD_INL void st(uint32_t *p, vfloat v) { vf_storeu((float *)(void *)p, v); }
SIMD_INL void sti(uint32_t *p, vint v) { vi_storeu((int32_t *)(void *)p, v); }
SIMD_INL void stm(uint32_t *p, vmask m) { sti(p, vi_sel(m, vi_set1(-1), vi_zero())); }

int CK_NAME(int op, const uint32_t *a, const uint32_t *b, int k, int n, uint32_t *out)
{
    const int W = SIMD_W;
    if (op == SC_LOAD3 || op == SC_STORE3 || op == SC_SCATTER3) {
        for (int g = 0; g + 3 * W <= n; g += 3 * W) {
            float *o = (float *)(void *)(out + g);
            const float *p = (const float *)(const void *)(a + g);
            vfloat x, y, z;
            if (op == SC_LOAD3) {
                vf_load3(p, &x, &y, &z);
                vf_storeu(o, x); vf_storeu(o + W, y); vf_storeu(o + 2 * W, z);
            } else if (op == SC_STORE3) {
                vf_store3(o, vf_loadu(p), vf_loadu(p + W), vf_loadu(p + 2 * W));
            } else {
                int32_t dest[SIMD_W];
                for (int l = 0; l < W; l++) dest[l] = (l * 5 + 3) % W;
                vf_scatter3(o, dest, vf_loadu(p), vf_loadu(p + W), vf_loadu(p + 2 * W));
            }
        }
        return W;
    }
    if (op == SC_STORE2) {
        for (int g = 0; g + 2 * W <= n; g += 2 * W)
            vi_store2((int32_t *)(void *)(out + g), ldi(a + g), ldi(a + g + W));
        return W;
    }
    if (op == SC_TRB) {
        enum { NB = SIMD_W / 4 };
        for (int g = 0; g + NB * W <= n; g += NB * W) {
            vfloat in[NB], o[NB];
            for (int q = 0; q < NB; q++) in[q] = ld(a + g + q * W);
            vf_tr_blocks(in, o);
            for (int q = 0; q < NB; q++) st(out + g + q * W, o[q]);
        }
        return W;
    }
    if (op == SC_TR4) {
        for (int g = 0; g + 4 * W <= n; g += 4 * W) {
            vfloat t[4];
            vf_tr4(ld(a + g), ld(a + g + W), ld(a + g + 2 * W), ld(a + g + 3 * W), t);
            for (int q = 0; q < 4; q++) st(out + g + q * W, t[q]);
        }
        return W;
    }
    for (int v = 0; v + W <= n; v += W) {
        const vfloat fa = ld(a + v), fb = ld(b + v);
        const vint ia = ldi(a + v), ib = ldi(b + v);
        const vmask lt = vf_lt(fa, fb), gt = vf_gt(fa, fb);
        uint32_t *o = out + v;
        switch (op) {
        case SC_ADD: st(o, vf_add(fa, fb)); break;
        case SC_SUB: st(o, vf_sub(fa, fb)); break;
        case SC_MUL: st(o, vf_mul(fa, fb)); break;
        case SC_DIV: st(o, vf_div(fa, fb)); break;
        case SC_MIN: st(o, vf_min(fa, fb)); break;
        case SC_MAX: st(o, vf_max(fa, fb)); break;
        case SC_SQRT: st(o, vf_sqrt(fa)); break;
        case SC_NEG: st(o, vf_neg(fa)); break;
        case SC_ABS: st(o, vf_abs(fa)); break;
        case SC_FLOOR: st(o, vf_floor(fa)); break;
        case SC_EQ: stm(o, vf_eq(fa, fb)); break;
        case SC_NE: stm(o, vf_ne(fa, fb)); break;
        case SC_LT: stm(o, lt); break;
        case SC_LE: stm(o, vf_le(fa, fb)); break;
        case SC_GT: stm(o, gt); break;
        case SC_GE: stm(o, vf_ge(fa, fb)); break;
        case SC_BITS_LT: {
            const unsigned bits = vm_bits(lt);
            for (int l = 0; l < W; l++) o[l] = (bits >> l) & 1u;
            if (bits >> W) o[0] = 0xBAD;   /* no bit above the lanes */
            break;
        }
        case SC_ALL_LT: for (int l = 0; l < W; l++) o[l] = (uint32_t)vm_all(lt); break;
        case SC_ANY_LT: for (int l = 0; l < W; l++) o[l] = (uint32_t)vm_any(lt); break;
        case SC_SEL: st(o, vf_sel(lt, fa, fb)); break;
        case SC_SELZ: st(o, vf_selz(lt, fa)); break;
        case SC_NEG_IF: st(o, vf_neg_if(lt, fa)); break;
        case SC_FAND: st(o, vf_and(fa, fb)); break;
        case SC_FOR: st(o, vf_or(fa, fb)); break;
        case SC_FXOR: st(o, vf_xor(fa, fb)); break;
        case SC_FANDNOT: st(o, vf_andnot(fa, fb)); break;
        case SC_IADD: sti(o, vi_add(ia, ib)); break;
        case SC_ISUB: sti(o, vi_sub(ia, ib)); break;
        case SC_IMULLO: sti(o, vi_mullo(ia, ib)); break;
        case SC_IAND: sti(o, vi_and(ia, ib)); break;
        case SC_IOR: sti(o, vi_or(ia, ib)); break;
        case SC_IXOR: sti(o, vi_xor(ia, ib)); break;
        case SC_IANDNOT: sti(o, vi_andnot(ia, ib)); break;
        case SC_IEQ: stm(o, vi_eq(ia, ib)); break;
        case SC_IGT: stm(o, vi_gt(ia, ib)); break;
        case SC_ISEL: sti(o, vi_sel(vi_gt(ia, ib), ia, ib)); break;
        case SC_SLLI3: sti(o, vi_slli(ia, 3)); break;
        case SC_SRLI5: sti(o, vi_srli(ia, 5)); break;
        case SC_SRAI7: sti(o, vi_srai(ia, 7)); break;
        case SC_SLL: sti(o, vi_sll(ia, k)); break;
        case SC_SRL: sti(o, vi_srl(ia, k)); break;
        case SC_CVT_I2F: st(o, vf_from_vi(ia)); break;
        case SC_CVT_TRUNC: sti(o, vi_from_vf_trunc(fa)); break;
        case SC_CVT_ROUND: sti(o, vi_from_vf_round(fa)); break;
        case SC_MAND: stm(o, vm_and(lt, gt)); break;
        case SC_MOR: stm(o, vm_or(lt, gt)); break;
        case SC_MANDNOT: stm(o, vm_andnot(lt, vm_not(gt))); break;
        case SC_MNOT: stm(o, vm_not(lt)); break;
        case SC_FROM_BITS: stm(o, vm_from_bits((unsigned)k)); break;
        case SC_LANES: sti(o, vi_lanes()); break;
        case SC_LOAD: {
            _Alignas(64) float t[SIMD_W];
            memcpy(t, a + v, sizeof t);
            vf_store((float *)t, vf_load(t));
            st(o, vf_load(t));
            break;
        }
        case SC_ZIPLO: sti(o, vi_zip_lo(ia, ib)); break;
        case SC_ZIPHI: sti(o, vi_zip_hi(ia, ib)); break;
        case SC_HADD: sti(o, vh_add(ia, ib)); break;
        case SC_HSUB: sti(o, vh_sub(ia, ib)); break;
        case SC_HMUL: sti(o, vh_mullo(ia, ib)); break;
        case SC_HSRLI5: sti(o, vh_srli(ia, 5)); break;
        case SC_HSET1: sti(o, vh_set1(k)); break;
        case SC_HLO8: sti(o, vh_from_u8_lo(ia)); break;
        case SC_HHI8: sti(o, vh_from_u8_hi(ia)); break;
        case SC_HPACKUS: sti(o, vh_packus(ia, ib)); break;
        case SC_HBCAST3: sti(o, vh_bcast3(ia)); break;
        case SC_LOAD_U8: sti(o, vi_load_u8((const uint8_t *)(const void *)a + v)); break;
        case SC_LOAD_BITS: st(o, vf_load_bits((const float *)(const void *)(a + v), (unsigned)k)); break;
        case SC_STORE_BITS: vf_store_bits((float *)(void *)o, (unsigned)k, fa); break;
        default: return -1;
        }
    }
    return W;
}
#endif
