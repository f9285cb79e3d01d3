/* test_raster_records.c - the vector front ends (rast__frontv_avx2,
 * rast__frontv_avx512) write exactly the bytes of the scalar set-up into
 * records that hold other bytes before: test_raster_isa compares records
 * in zeroed memory, where a store of one attribute float too many (a
 * zero from a masked load) would not show. Here every record is filled
 * with a pattern first, so any byte written that the scalar set-up does
 * not write (a0, d1, d2 past attr_count included) differs.
 *
 * Seeded meshes: jittered grids of 0.3..8 pixel cells (micro boxes, small
 * and one-vector triangles) on random targets, random windings and cull
 * modes, a few vertices behind the eye, far in the guard band or NaN (the
 * scalar path inside the groups), 0..8 attributes, front-end calls over
 * random chunk lengths (partial groups of every size). The attributes
 * and the indices end at a page followed by an inaccessible one, so a
 * read past the last vertex's attributes or the last triangle's indices
 * faults. */
#define _DEFAULT_SOURCE
#include "support/testutil.h"
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "../src/cpu/cpu.h"
#include "../src/raster/raster_internal.h"
#include "support/isa_tests.h"
#include "support/x86_only.h"

#if EF_TEST_X86

#define PATTERN 0xA5

/* n bytes (n > 0) ending where an inaccessible page begins. */
typedef struct guarded {
    void *base;
    size_t len;
    uint8_t *p;
} guarded;

static guarded guard_alloc(size_t n)
{
    const size_t pg = (size_t)sysconf(_SC_PAGESIZE);
    const size_t data = (n + pg - 1) / pg * pg;
    guarded g;
    g.len = data + pg;
    g.base = mmap(NULL, g.len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    assert_true(g.base != MAP_FAILED);
    assert_int_equal(mprotect((uint8_t *)g.base + data, pg, PROT_NONE), 0);
    g.p = (uint8_t *)g.base + data - n;
    return g;
}

typedef struct mesh {
    int w, h, nv, nt, ac;
    float *clip, *attr;
    uint32_t *idx;
    guarded gattr, gidx;
    rast_mesh_desc m;
} mesh;

static void make_mesh(tu_rng *r, int n, mesh *k)
{
    k->w = 16 + tu_int(r, 300);
    k->h = 16 + tu_int(r, 200);
    k->ac = n % (RAST_MAX_ATTRS + 1);
    const int gx = 2 + tu_int(r, 24), gy = 2 + tu_int(r, 14);
    const float cell = tu_range(r, 0.3f, 8.0f);
    const float ox = tu_range(r, -10.0f, (float)k->w), oy = tu_range(r, -10.0f, (float)k->h);
    k->nv = gx * gy;
    k->clip = malloc((size_t)k->nv * 4 * sizeof(float));
    k->attr = malloc(((size_t)k->nv * (size_t)k->ac + 1) * sizeof(float));
    k->idx = malloc(((size_t)(gx - 1) * (size_t)(gy - 1) * 6 + 3 * 40) * sizeof(uint32_t));
    assert_true(k->clip && k->attr && k->idx);
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            float *c = k->clip + 4 * (size_t)(j * gx + i);
            const float px = ox + cell * ((float)i + tu_range(r, -0.3f, 0.3f));
            const float py = oy + cell * ((float)j + tu_range(r, -0.3f, 0.3f));
            const float w = tu_range(r, 0.5f, 4.0f);
            c[0] = (px / (float)k->w * 2.0f - 1.0f) * w;
            c[1] = (1.0f - py / (float)k->h * 2.0f) * w;
            c[2] = tu_range(r, -0.9f, 0.9f) * w;
            c[3] = w;
            const int odd = tu_int(r, 100);
            if (odd == 0)
                c[3] = -w;                      /* behind the eye */
            else if (odd == 1)
                c[0] = 3000.0f * w;             /* far in the guard band */
            else if (odd == 2)
                c[1] = NAN;
        }
    for (int i = 0; i < k->nv * k->ac; i++)
        k->attr[i] = tu_range(r, -2.0f, 2.0f);
    int nt = 0;
    for (int j = 0; j + 1 < gy; j++)
        for (int i = 0; i + 1 < gx; i++) {
            const uint32_t a = (uint32_t)(j * gx + i), b = a + 1, c = a + (uint32_t)gx,
                           d = c + 1;
            const int flip = tu_int(r, 4) == 0;
            const uint32_t t[6] = { a, flip ? c : b, flip ? b : c, b, flip ? c : d, flip ? d : c };
            memcpy(k->idx + 3 * (size_t)nt, t, sizeof t);
            nt += 2;
        }
    for (int e = tu_int(r, 40); e > 0; e--, nt++)   /* larger random triangles */
        for (int v = 0; v < 3; v++)
            k->idx[3 * (size_t)nt + v] = (uint32_t)tu_int(r, k->nv);
    k->nt = nt;
    /* the guarded copies */
    const size_t abytes = (size_t)k->nv * (size_t)k->ac * sizeof(float);
    k->gattr = guard_alloc(abytes ? abytes : 4);
    if (abytes)
        memcpy(k->gattr.p, k->attr, abytes);
    k->gidx = guard_alloc(3 * (size_t)nt * sizeof(uint32_t));
    memcpy(k->gidx.p, k->idx, 3 * (size_t)nt * sizeof(uint32_t));
    const rast_cull culls[3] = { RAST_CULL_NONE, RAST_CULL_BACK, RAST_CULL_FRONT };
    rast_mesh_desc m = { k->clip, k->nv, k->ac ? (const float *)(void *)k->gattr.p : NULL,
                         k->ac, (const uint32_t *)(void *)k->gidx.p, nt, culls[tu_int(r, 3)] };
    k->m = m;
}

static void free_mesh(mesh *k)
{
    free(k->clip);
    free(k->attr);
    free(k->idx);
    munmap(k->gattr.base, k->gattr.len);
    munmap(k->gidx.base, k->gidx.len);
}

/* The front end over random chunks into records filled with PATTERN. */
static int front(const rast__setup_isa *isa, const rast__view *v, const mesh *k,
                 const rast__vbuf *vb, tu_rng *r, rast__tri *out, rast_stats *st, int micro)
{
    int n = 0;
    for (int ti = 0; ti < k->nt;) {
        const int len = 1 + tu_int(r, tu_int(r, 2) ? 9 : 40);
        const int te = k->nt - ti > len ? ti + len : k->nt;
        n += isa->frontv(v, &k->m, vb, ti, te, out + n, st, micro);
        ti = te;
    }
    return n;
}

static int untouched(const float *p, int from)
{
    const uint8_t *b = (const uint8_t *)(const void *)(p + from);
    for (size_t i = 0; i < (size_t)(RAST_MAX_ATTRS - from) * sizeof(float); i++)
        if (b[i] != PATTERN)
            return 0;
    return 1;
}

static void check_isa(ef_isa which, const rast__setup_isa *isa)
{
    if (!ef_cpu_has(which) || !isa->vpass) {
        print_message("SKIP %s: this CPU does not run it\n", ef_isa_name(which));
        return;
    }
    tu_rng r = { 0xA2A2u + (uint64_t)which };
    long recs = 0, micro_recs = 0, attr_recs = 0;
    for (int n = 0; n < 1200; n++) {
        mesh k;
        make_mesh(&r, n, &k);
        rast__view v;
        rast__view_init(&v, k.w, k.h, k.ac);
        rast__vbuf *vb = rast__vbuf_alloc(k.nv);
        assert_non_null(vb);
        isa->vpass(&v, k.clip, k.nv, vb);
        const size_t cap = (size_t)k.nt * RAST__MAX_FAN + 1;
        rast__tri *a = malloc(cap * sizeof *a), *b = malloc(cap * sizeof *b),
                  *c = malloc(cap * sizeof *c);
        assert_true(a && b && c);
        memset(a, PATTERN, cap * sizeof *a);
        memset(b, PATTERN, cap * sizeof *b);
        memset(c, PATTERN, cap * sizeof *c);
        rast_stats sa, sb, sc;
        memset(&sa, 0, sizeof sa);
        memset(&sb, 0, sizeof sb);
        memset(&sc, 0, sizeof sc);
        rast__vcache vc;
        rast__vcache_reset(&vc);
        const int na = rast__prepare_range(&v, &k.m, 0, k.nt, &vc, a, &sa, &rast__setup_isa_ref);
        const int nb = front(isa, &v, &k, vb, &r, b, &sb, 0);
        const int nc = front(isa, &v, &k, vb, &r, c, &sc, 1);
        assert_int_equal(nb, na);
        assert_int_equal(nc, na);
        assert_memory_equal(&sb, &sa, sizeof sa);
        assert_memory_equal(&sc, &sa, sizeof sa);
        for (int i = 0; i < na; i++) {
            if (memcmp(&a[i], &b[i], sizeof a[i]))
                fail_msg("%s mesh %d (%d attributes): record %d of %d differs from the "
                         "scalar set-up's in memory filled with 0x%02X", ef_isa_name(which), n,
                         k.ac, i, na, PATTERN);
            /* micro records: the attributes as the scalar set-up's, not
             * one byte more */
            if (!c[i].micro) {
                if (memcmp(&a[i], &c[i], sizeof a[i]))
                    fail_msg("%s mesh %d: record %d differs with micro records on",
                             ef_isa_name(which), n, i);
                continue;
            }
            micro_recs++;
            if (!(c[i].micro & 15))
                continue;
            attr_recs += k.ac > 0;
            if (memcmp(c[i].a0, a[i].a0, (size_t)k.ac * sizeof(float)) ||
                memcmp(c[i].d1, a[i].d1, (size_t)k.ac * sizeof(float)) ||
                memcmp(c[i].d2, a[i].d2, (size_t)k.ac * sizeof(float)) ||
                !untouched(c[i].a0, k.ac) || !untouched(c[i].d1, k.ac) ||
                !untouched(c[i].d2, k.ac))
                fail_msg("%s mesh %d (%d attributes): micro record %d: attributes differ "
                         "or a float past them was written", ef_isa_name(which), n, k.ac, i);
        }
        recs += na;
        free(a);
        free(b);
        free(c);
        rast__vbuf_free(vb);
        free_mesh(&k);
    }
    print_message("NOTE %s: %ld records, %ld micro (%ld with attributes), equal to the "
                  "scalar set-up in patterned memory\n", ef_isa_name(which), recs, micro_recs,
                  attr_recs);
    assert_true(recs > 80000 && micro_recs > 10000 && attr_recs > 9000);
}

static void test_frontv_patterned_avx2(void **state)
{
    (void)state;
    tu_skip_unless_isa(EF_ISA_AVX2, "the patterned vector front end of "
                                    "src/raster/raster_front_avx2.c");
    check_isa(EF_ISA_AVX2, &rast__setup_isa_avx2);
}

static void test_frontv_patterned_avx512(void **state)
{
    (void)state;
    tu_skip_unless_isa(EF_ISA_AVX512, "the patterned vector front end of "
                                      "src/raster/raster_front_avx512.c");
    check_isa(EF_ISA_AVX512, &rast__setup_isa_avx512);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_frontv_patterned_avx2),
        cmocka_unit_test(test_frontv_patterned_avx512))

#else
EF_TEST_X86_SKIP("the vector front ends' records")
#endif
