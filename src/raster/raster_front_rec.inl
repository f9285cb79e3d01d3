/* raster_front_rec.inl - a record of the vector front end written from
 * lane-transposed stack layouts by 16-byte copies, on the vector layer
 * (quads: vf_tr4; pairs: the int64 lanes of "RASTER EDGE OPS"); included
 * by raster_frontq.inl after raster_front.inl (FRONT_V = SIMD_W).
 * Layouts, 4 * FRONT_V floats or int32 per quad array:
 *   bq        box x0, y0, x1, y1 (quads);
 *   mq        micro values mz, mb1, mb2 (three quad arrays);
 *   pq        planes z.c .. q.c, q.dx .. b1.dx, b1.dy .. b2.dy (three);
 *   eq, e8    edge pairs (e_c[0], e_c[1]) .. (e_dy[0], e_dy[1]) (four pair
 *             arrays of 2 * FRONT_V int64) and e_dy[2] per lane.
 *
 *   quads  4 float or int32 vectors a, b, c, d: lane l's (a, b, c, d) as 16
 *          bytes at s + QUAD_AT(l) (vf_tr4, 4 vector stores);
 *   pairs  2 int64 vectors a, b of the lanes of one half: lane l's (a, b)
 *          as 16 bytes at s + PAIR_AT(l) (2 vector stores per half, the
 *          second half at s + 2 * VD_W). */
#define QUAD_AT(l) (SIMD_W * ((l) & 3) + 4 * ((l) >> 2))
#define PAIR_AT(l) \
    (2 * VD_W * ((l) / VD_W) + VD_W * ((l) & 1) + 2 * (((l) >> 1) & (VD_W / 2 - 1)))

SIMD_INL void quads(vfloat a, vfloat b, vfloat c, vfloat d, float *s)
{
    vfloat o[4];
    vf_tr4(a, b, c, d, o);   /* o[k] block J: lane 4J + k's a, b, c, d */
    vf_store(s, o[0]);
    vf_store(s + SIMD_W, o[1]);
    vf_store(s + 2 * SIMD_W, o[2]);
    vf_store(s + 3 * SIMD_W, o[3]);
}

SIMD_INL void pairs(vlong a, vlong b, int64_t *s)
{
    vl_store(s, vl_zip_lo(a, b));          /* even lanes */
    vl_store(s + VD_W, vl_zip_hi(a, b));   /* odd lanes */
}

/* 16 bytes from s to d. */
SIMD_INL void copy16(void *d, const void *s)
{
    __builtin_memcpy(d, s, 16);
}

/* The record layout the copies assume. */
_Static_assert(offsetof(rast__tri, x0) == 0 && offsetof(rast__tri, y0) == 4 &&
                   offsetof(rast__tri, x1) == 8 && offsetof(rast__tri, y1) == 12 &&
                   offsetof(rast__tri, e_c) == 16 && offsetof(rast__tri, e_dx) == 40 &&
                   offsetof(rast__tri, e_dy) == 64 && offsetof(rast__tri, z) == 88 &&
                   offsetof(rast__tri, q) == 100 && offsetof(rast__tri, b1) == 112 &&
                   offsetof(rast__tri, b2) == 124 && sizeof(rast__plane) == 12 &&
                   offsetof(rast__tri, micro) == offsetof(rast__tri, attr_count) + 4 &&
                   offsetof(rast__tri, mb1) == offsetof(rast__tri, mz) + 16 &&
                   offsetof(rast__tri, mb2) == offsetof(rast__tri, mz) + 32,
               "record layout of flush's copies");

/* Lane l's record t: a micro record (is_micro; cov: its covered pixels)
 * or a full one (box, edges, planes, attr_count and micro = 0 by one
 * 8-byte store, little-endian). Returns 0 for a micro record with no
 * covered pixel (only its micro field is written), else 1 (the caller
 * then writes the attributes). */
static inline __attribute__((always_inline)) int front_write_record(
    rast__tri *t, int l, int is_micro, unsigned cov, int ac, const int32_t *bq,
    const float *mq, const float *pq, const int64_t (*eq)[2 * FRONT_V], const int64_t *e8)
{
    char *d = (char *)(void *)t;
    const int qa = QUAD_AT(l), pa = PAIR_AT(l);
    enum { QS = 4 * FRONT_V };   /* floats per quad array */
    if (is_micro) {
        t->micro = RAST__MICRO | (int)cov;
        if (!cov)
            return 0;
        t->attr_count = ac;
        copy16(d, bq + qa);
        copy16(t->mz, mq + qa);
        copy16(t->mb1, mq + QS + qa);
        copy16(t->mb2, mq + 2 * QS + qa);
        return 1;
    }
    const uint64_t acm = (uint32_t)ac;
    copy16(d, bq + qa);
    copy16(d + 16, eq[0] + pa);
    copy16(d + 32, eq[1] + pa);
    copy16(d + 48, eq[2] + pa);
    copy16(d + 64, eq[3] + pa);
    memcpy(d + 80, &e8[l], 8);
    copy16(d + 88, pq + qa);
    copy16(d + 104, pq + QS + qa);
    copy16(d + 120, pq + 2 * QS + qa);
    memcpy(&t->attr_count, &acm, 8);
    return 1;
}

/* Lane l's hidden record t (fv_hidden): the box and micro = RAST__HIDDEN,
 * nothing else (rast__scan_list reads no other field of it). */
static inline __attribute__((always_inline)) void front_hidden_record(rast__tri *t, int l,
                                                                      const int32_t *bq)
{
    copy16(t, bq + QUAD_AT(l));
    t->micro = RAST__HIDDEN;
}
