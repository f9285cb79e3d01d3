/* gen_glb.c - a small binary glTF 2.0 writer for the sample arms.
 *
 * Layout: 12-byte header, a JSON chunk (padded with spaces) and a BIN
 * chunk (padded with zeros). The BIN chunk holds, each 4-byte aligned:
 * POSITION (VEC3 float, with min/max), NORMAL (VEC3 float), JOINTS_0
 * (VEC4 unsigned short), WEIGHTS_0 (VEC4 float), indices (unsigned int),
 * the inverse bind matrices (MAT4 float), the key times (with min/max)
 * and one VEC4 rotation output per animation channel. Nodes keep the
 * model's order (parents first) with translation/rotation/scale. */
#include "gen.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef struct sbuf {
    char *p;
    size_t len, cap;
    int oom;
} sbuf;

static void sb_printf(sbuf *s, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void sb_printf(sbuf *s, const char *fmt, ...)
{
    if (s->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int n = vsnprintf(s->p ? s->p + s->len : NULL, s->p ? s->cap - s->len : 0,
                          fmt, ap);
        va_end(ap);
        if (n < 0) { s->oom = 1; return; }
        if (s->p && s->len + (size_t)n < s->cap) { s->len += (size_t)n; return; }
        size_t nc = (s->cap ? s->cap * 2 : 4096) + (size_t)n;
        char *q = realloc(s->p, nc);
        if (!q) { s->oom = 1; return; }
        s->p = q;
        s->cap = nc;
    }
}

static void sb_bytes(sbuf *s, const void *d, size_t n)
{
    if (s->oom) return;
    if (s->len + n + 4 > s->cap) {
        size_t nc = (s->cap ? s->cap * 2 : 4096) + n;
        char *q = realloc(s->p, nc);
        if (!q) { s->oom = 1; return; }
        s->p = q;
        s->cap = nc;
    }
    memcpy(s->p + s->len, d, n);
    s->len += n;
}

static void sb_align(sbuf *s, char pad)
{
    while (!s->oom && (s->len & 3u)) sb_bytes(s, &pad, 1);
}

/* A view of the BIN chunk. */
typedef struct view { size_t off, len; int target; } view;

static view put(sbuf *bin, const void *d, size_t n, int target)
{
    sb_align(bin, 0);
    view v = { bin->len, n, target };
    sb_bytes(bin, d, n);
    return v;
}

static void put_u32(FILE *f, uint32_t v, int *bad)
{
    unsigned char b[4] = { (unsigned char)v, (unsigned char)(v >> 8),
                           (unsigned char)(v >> 16), (unsigned char)(v >> 24) };
    if (fwrite(b, 1, 4, f) != 4) *bad = 1;
}

int gen_glb_write(const char *path, const gen_arms *a, char *why,
                  size_t why_size)
{
    const kin_model *m = &a->model;
    const kin_mesh *me = &m->meshes[0];
    const kin_skin *sk = &m->skins[0];
    const kin_animation *an = &m->anims[0];
    int V = me->vertex_count;
    sbuf bin = { 0 }, js = { 0 };
    int rc = -1;

    /* ---- BIN */
    enum { BV_POS, BV_NRM, BV_JNT, BV_WGT, BV_IDX, BV_IBM, BV_TIME, BV_ANIM, BV_COUNT };
    view bv[BV_COUNT];
    bv[BV_POS] = put(&bin, me->positions, (size_t)V * 12, 34962);
    bv[BV_NRM] = put(&bin, me->normals, (size_t)V * 12, 34962);
    bv[BV_JNT] = put(&bin, me->joints, (size_t)V * 8, 34962);
    bv[BV_WGT] = put(&bin, me->weights, (size_t)V * 16, 34962);
    bv[BV_IDX] = put(&bin, me->indices, (size_t)me->index_count * 4, 34963);
    bv[BV_IBM] = put(&bin, sk->inverse_bind, (size_t)sk->joint_count * 64, 0);
    /* every channel shares the key times of channel 0 */
    int K = an->channels[0].key_count;
    bv[BV_TIME] = put(&bin, an->channels[0].times, (size_t)K * 4, 0);
    sb_align(&bin, 0);
    bv[BV_ANIM].off = bin.len;
    bv[BV_ANIM].target = 0;
    for (int c = 0; c < an->channel_count; c++)
        sb_bytes(&bin, an->channels[c].values, (size_t)K * 16);
    bv[BV_ANIM].len = bin.len - bv[BV_ANIM].off;
    sb_align(&bin, 0);

    float mn[3] = { 1e30f, 1e30f, 1e30f }, mx[3] = { -1e30f, -1e30f, -1e30f };
    for (int v = 0; v < V; v++)
        for (int k = 0; k < 3; k++) {
            float x = me->positions[v * 3 + k];
            if (x < mn[k]) mn[k] = x;
            if (x > mx[k]) mx[k] = x;
        }

    /* ---- JSON */
    sb_printf(&js, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"egofuse gen_samples\"},");
    int roots = 0;
    sb_printf(&js, "\"scene\":0,\"scenes\":[{\"name\":\"arms\",\"nodes\":[");
    for (int i = 0; i < m->node_count; i++)
        if (m->parents[i] == KIN_NO_PARENT) sb_printf(&js, "%s%d", roots++ ? "," : "", i);
    sb_printf(&js, "]}],\"nodes\":[");
    for (int i = 0; i < m->node_count; i++) {
        const kin_transform *t = &m->rest[i];
        sb_printf(&js, "%s{\"name\":\"%s\"", i ? "," : "", m->names[i]);
        int nc = 0;
        for (int c = i + 1; c < m->node_count; c++)
            if (m->parents[c] == i)
                sb_printf(&js, "%s%d", nc++ ? "," : ",\"children\":[", c);
        if (nc) sb_printf(&js, "]");
        if (i == me->node) sb_printf(&js, ",\"mesh\":0,\"skin\":0");
        else
            sb_printf(&js, ",\"translation\":[%.9g,%.9g,%.9g],"
                           "\"rotation\":[%.9g,%.9g,%.9g,%.9g]",
                      t->t.x, t->t.y, t->t.z, t->r.x, t->r.y, t->r.z, t->r.w);
        sb_printf(&js, "}");
    }
    sb_printf(&js, "],\"materials\":[{\"name\":\"skin\",\"pbrMetallicRoughness\":"
                   "{\"baseColorFactor\":[0.72,0.42,0.32,1],\"metallicFactor\":0,"
                   "\"roughnessFactor\":0.6}}],");
    sb_printf(&js, "\"meshes\":[{\"name\":\"arms\",\"primitives\":[{\"attributes\":"
                   "{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":2,\"WEIGHTS_0\":3},"
                   "\"indices\":4,\"material\":0,\"mode\":4}]}],");
    sb_printf(&js, "\"skins\":[{\"name\":\"arms\",\"inverseBindMatrices\":5,"
                   "\"skeleton\":%d,\"joints\":[", a->body);
    for (int j = 0; j < sk->joint_count; j++)
        sb_printf(&js, "%s%d", j ? "," : "", sk->joints[j]);
    sb_printf(&js, "]}],");
    sb_printf(&js, "\"animations\":[{\"name\":\"%s\",\"samplers\":[", an->name);
    for (int c = 0; c < an->channel_count; c++)
        sb_printf(&js, "%s{\"input\":6,\"output\":%d,\"interpolation\":\"LINEAR\"}",
                  c ? "," : "", 7 + c);
    sb_printf(&js, "],\"channels\":[");
    for (int c = 0; c < an->channel_count; c++)
        sb_printf(&js, "%s{\"sampler\":%d,\"target\":{\"node\":%d,\"path\":\"rotation\"}}",
                  c ? "," : "", c, an->channels[c].node);
    sb_printf(&js, "]}],");
    sb_printf(&js, "\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[", bin.len);
    for (int i = 0; i < BV_COUNT; i++) {
        sb_printf(&js, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu",
                  i ? "," : "", bv[i].off, bv[i].len);
        if (bv[i].target) sb_printf(&js, ",\"target\":%d", bv[i].target);
        sb_printf(&js, "}");
    }
    sb_printf(&js, "],\"accessors\":[");
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
                   "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},",
              BV_POS, V, mn[0], mn[1], mn[2], mx[0], mx[1], mx[2]);
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\"},",
              BV_NRM, V);
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5123,\"count\":%d,\"type\":\"VEC4\"},",
              BV_JNT, V);
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"VEC4\"},",
              BV_WGT, V);
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5125,\"count\":%d,\"type\":\"SCALAR\"},",
              BV_IDX, me->index_count);
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"MAT4\"},",
              BV_IBM, sk->joint_count);
    sb_printf(&js, "{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"SCALAR\","
                   "\"min\":[%.9g],\"max\":[%.9g]}",
              BV_TIME, K, an->channels[0].times[0], an->channels[0].times[K - 1]);
    for (int c = 0; c < an->channel_count; c++)
        sb_printf(&js, ",{\"bufferView\":%d,\"byteOffset\":%zu,\"componentType\":5126,"
                       "\"count\":%d,\"type\":\"VEC4\"}",
                  BV_ANIM, (size_t)c * (size_t)K * 16, K);
    sb_printf(&js, "]}");
    sb_align(&js, ' ');
    if (js.oom || bin.oom) {
        snprintf(why, why_size, "%s: out of memory", path);
        goto done;
    }

    /* ---- file */
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        snprintf(why, why_size, "%s: cannot create: %s", tmp, strerror(errno));
        goto done;
    }
    int bad = 0;
    size_t total = 12 + 8 + js.len + 8 + bin.len;
    put_u32(f, 0x46546C67u, &bad);            /* "glTF" */
    put_u32(f, 2, &bad);
    put_u32(f, (uint32_t)total, &bad);
    put_u32(f, (uint32_t)js.len, &bad);
    put_u32(f, 0x4E4F534Au, &bad);            /* "JSON" */
    if (fwrite(js.p, 1, js.len, f) != js.len) bad = 1;
    put_u32(f, (uint32_t)bin.len, &bad);
    put_u32(f, 0x004E4942u, &bad);            /* "BIN\0" */
    if (fwrite(bin.p, 1, bin.len, f) != bin.len) bad = 1;
    if (fclose(f) != 0) bad = 1;
    if (bad) {
        snprintf(why, why_size, "%s: write error: %s", tmp, strerror(errno));
        remove(tmp);
        goto done;
    }
    if (rename(tmp, path) != 0) {
        snprintf(why, why_size, "%s: cannot rename into place: %s", path,
                 strerror(errno));
        remove(tmp);
        goto done;
    }
    rc = 0;
done:
    free(js.p);
    free(bin.p);
    return rc;
}
