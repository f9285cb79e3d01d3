/* io_lod.c - the level-of-detail chain of a model with meshoptimizer
 * (io_lod.h). */
#include "io_lod.h"
#include "../cpu/ef_mem.h"

#include <math.h>
#include <meshoptimizer.h>
#include <stdlib.h>
#include <string.h>

int io_lod_version(void) { return MESHOPTIMIZER_VERSION; }

void io_lod_free(pipe_lod *lod)
{
    if (!lod) return;
    kin_model owner;
    memset(&owner, 0, sizeof owner);
    owner.block = lod->block;
    kin_model_free(&owner);
    memset(lod, 0, sizeof *lod);
}

/* One mesh's triangles sorted into groups (by dominant joint), each group
 * compacted: its own vertices (the meshoptimizer calls then cost the
 * group's size, not the mesh's). */
typedef struct mesh_groups {
    int count;                /* groups */
    int *start;               /* count + 1 offsets into idx (in indices) */
    uint32_t *idx;            /* the mesh's index list, grouped */
    uint32_t *lidx;           /* the same, as indices into the group's
                                 vertices */
    int *vstart;              /* count + 1 offsets into gv */
    uint32_t *gv;             /* per group, its vertices (mesh indices), in
                                 order of first use */
    float *gpos;              /* their positions, 3 per entry of gv */
    float *scale;             /* per group: meshopt_simplifyScale of its
                                 positions (metres per unit of error) */
} mesh_groups;

static void groups_free(mesh_groups *g)
{
    EF_FREE_ALL(g->start, g->idx, g->lidx, g->vstart, g->gv, g->gpos, g->scale);
    memset(g, 0, sizeof *g);
}

/* The groups' own vertices (lidx, vstart, gv, gpos, scale) from start and
 * idx. 0, or -1 when out of memory. */
static int groups_compact(const kin_mesh *me, mesh_groups *g)
{
    const size_t ni = (size_t)g->start[g->count];
    g->lidx = malloc(sizeof *g->lidx * (ni ? ni : 1));
    g->vstart = malloc(sizeof *g->vstart * (size_t)(g->count + 1));
    g->gv = malloc(sizeof *g->gv * (ni ? ni : 1));
    g->scale = malloc(sizeof *g->scale * (size_t)g->count);
    int32_t *map = malloc(sizeof *map * (size_t)(me->vertex_count ? me->vertex_count : 1));
    if (!g->lidx || !g->vstart || !g->gv || !g->scale || !map) {
        free(map);
        return -1;
    }
    for (int v = 0; v < me->vertex_count; v++) map[v] = -1;
    size_t nv = 0;
    for (int gi = 0; gi < g->count; gi++) {
        g->vstart[gi] = (int)nv;
        for (int k = g->start[gi]; k < g->start[gi + 1]; k++) {
            uint32_t v = g->idx[k];
            if (map[v] < 0) {
                map[v] = (int32_t)(nv - (size_t)g->vstart[gi]);
                g->gv[nv++] = v;
            }
            g->lidx[k] = (uint32_t)map[v];
        }
        for (size_t k = (size_t)g->vstart[gi]; k < nv; k++) map[g->gv[k]] = -1;
    }
    g->vstart[g->count] = (int)nv;
    free(map);
    g->gpos = malloc(sizeof *g->gpos * 3 * (nv ? nv : 1));
    if (!g->gpos) return -1;
    for (size_t k = 0; k < nv; k++) memcpy(g->gpos + 3 * k, me->positions + 3 * (size_t)g->gv[k],
                                           3 * sizeof(float));
    for (int gi = 0; gi < g->count; gi++) {
        size_t a = (size_t)g->vstart[gi], b = (size_t)g->vstart[gi + 1];
        g->scale[gi] = b > a ? meshopt_simplifyScale(g->gpos + 3 * a, b - a, 3 * sizeof(float))
                             : 0.0f;
    }
    return 0;
}

/* The dominant joint of triangle t: the largest summed weight (double,
 * vertex by vertex, influence by influence), ties to the lower joint. */
static int dominant_joint(const kin_mesh *me, int t, double *acc, int *touched, int jmax)
{
    int nt = 0;
    for (int k = 0; k < 3; k++) {
        uint32_t v = me->indices[3 * t + k];
        for (int s = 0; s <= me->extra_sets; s++) {
            const uint16_t *J = s ? me->joints_extra + (size_t)v * 4 * (size_t)me->extra_sets +
                                        4 * (size_t)(s - 1)
                                  : me->joints + 4 * (size_t)v;
            const float *W = s ? me->weights_extra + (size_t)v * 4 * (size_t)me->extra_sets +
                                     4 * (size_t)(s - 1)
                               : me->weights + 4 * (size_t)v;
            for (int i = 0; i < 4; i++) {
                int j = J[i];
                if (j > jmax || !(W[i] > 0.0f)) continue;
                if (acc[j] == 0.0) touched[nt++] = j;
                acc[j] += (double)W[i];
            }
        }
    }
    int best = 0;
    double bw = -1.0;
    for (int i = 0; i < nt; i++) {
        int j = touched[i];
        if (acc[j] > bw || (acc[j] == bw && j < best)) {
            bw = acc[j];
            best = j;
        }
    }
    for (int i = 0; i < nt; i++) acc[touched[i]] = 0.0;
    return best;
}

static int groups_build(const kin_mesh *me, int whole, mesh_groups *g)
{
    memset(g, 0, sizeof *g);
    const int tris = me->index_count / 3;
    g->idx = malloc(sizeof *g->idx * (size_t)(me->index_count ? me->index_count : 1));
    if (!g->idx) return -1;
    const int skinned = !whole && me->joints && me->weights &&
                        (me->extra_sets == 0 || (me->joints_extra && me->weights_extra));
    if (!skinned || tris == 0) {
        g->count = 1;
        g->start = malloc(2 * sizeof *g->start);
        if (!g->start) return -1;
        g->start[0] = 0;
        g->start[1] = me->index_count;
        if (me->index_count) memcpy(g->idx, me->indices, sizeof *g->idx * (size_t)me->index_count);
        return groups_compact(me, g);
    }
    const int jcount = 65536; /* uint16_t joint indices */
    double *acc = calloc((size_t)jcount, sizeof *acc);
    int *touched = malloc(sizeof *touched * (size_t)(12 * (me->extra_sets + 1)));
    int *tj = malloc(sizeof *tj * (size_t)tris);
    int *cnt = calloc((size_t)jcount + 1, sizeof *cnt);
    int rc = -1;
    if (!acc || !touched || !tj || !cnt) goto done;
    int jmax = 0;
    for (int t = 0; t < tris; t++) {
        tj[t] = dominant_joint(me, t, acc, touched, jcount - 1);
        cnt[tj[t] + 1]++;
        if (tj[t] > jmax) jmax = tj[t];
    }
    /* groups: the joints that own a triangle, in joint order */
    g->start = malloc(sizeof *g->start * (size_t)(jmax + 2));
    if (!g->start) goto done;
    int *at = calloc((size_t)jmax + 1, sizeof *at);
    if (!at) goto done;
    int off = 0, n = 0;
    for (int j = 0; j <= jmax; j++) {
        at[j] = off;
        if (cnt[j + 1]) g->start[n++] = 3 * off;
        off += cnt[j + 1];
    }
    g->start[n] = 3 * off;
    g->count = n;
    for (int t = 0; t < tris; t++) { /* stable: triangles keep their order */
        int d = at[tj[t]]++;
        memcpy(g->idx + 3 * (size_t)d, me->indices + 3 * (size_t)t, 3 * sizeof(uint32_t));
    }
    free(at);
    rc = groups_compact(me, g);
done:
    EF_FREE_ALL(acc, touched, tj, cnt);
    return rc;
}

static double mean_edge(const kin_mesh *meshes, int mesh_count, long *tris_out)
{
    double sum = 0.0;
    long n = 0;
    for (int i = 0; i < mesh_count; i++) {
        const kin_mesh *me = &meshes[i];
        for (int t = 0; t + 2 < me->index_count; t += 3)
            for (int k = 0; k < 3; k++) {
                const float *a = me->positions + 3 * (size_t)me->indices[t + k];
                const float *b = me->positions + 3 * (size_t)me->indices[t + (k + 1) % 3];
                double dx = (double)a[0] - b[0], dy = (double)a[1] - b[1],
                       dz = (double)a[2] - b[2];
                sum += sqrt(dx * dx + dy * dy + dz * dz);
            }
        n += me->index_count / 3;
    }
    *tris_out = n;
    return n ? sum / (3.0 * (double)n) : 0.0;
}

io_result io_lod_build(const char *name, const kin_model *model, const io_lod_desc *desc,
                       pipe_lod *lod, io_error *err)
{
    if (lod) memset(lod, 0, sizeof *lod);
    if (!name) name = "model";
    if (!model || !lod) return io_fail(err, IO_ERR_ARGS, "%s: no model or no chain", name);
    io_lod_desc d = desc ? *desc : (io_lod_desc){0};
    if (d.max_levels == 0) d.max_levels = 4;
    if (d.ratio == 0.0f) d.ratio = 0.5f;
    if (d.min_triangles == 0) d.min_triangles = 64;
    if (d.max_levels < 0 || d.max_levels > PIPE_LOD_MAX - 1)
        return io_fail(err, IO_ERR_ARGS, "%s: %d levels of detail (0..%d)", name, d.max_levels,
                       PIPE_LOD_MAX - 1);
    if (!(d.ratio > 0.0f && d.ratio < 1.0f))
        return io_fail(err, IO_ERR_ARGS, "%s: level ratio %g is not in (0, 1)", name,
                       (double)d.ratio);
    if (d.min_triangles < 0)
        return io_fail(err, IO_ERR_ARGS, "%s: min_triangles %d is negative", name,
                       d.min_triangles);
    char why[256];
    if (kin_model_validate(model, why, sizeof why) != 0)
        return io_fail(err, IO_ERR_VALUE, "%s: %s", name, why);
    if (model->mesh_count < 1 || !model->meshes)
        return io_fail(err, IO_ERR_VALUE, "%s: the model has no meshes", name);
    long tris0 = 0;
    for (int i = 0; i < model->mesh_count; i++) {
        const kin_mesh *me = &model->meshes[i];
        if (me->index_count > 0 && !me->positions)
            return io_fail(err, IO_ERR_VALUE, "%s: mesh %d has no positions", name, i);
        for (long k = 0; k < 3L * me->vertex_count && me->positions; k++)
            if (!isfinite(me->positions[k]))
                return io_fail(err, IO_ERR_VALUE,
                               "%s: mesh %d: vertex %ld has a non-finite position", name, i,
                               k / 3);
        tris0 += me->index_count / 3;
    }
    if (tris0 == 0) return io_fail(err, IO_ERR_VALUE, "%s: the model has no triangles", name);

    const int mc = model->mesh_count;
    lod->mesh_count = mc;
    lod->level_count = 1;
    lod->level[0].meshes = model->meshes;
    lod->level[0].error_m = 0.0f;
    lod->level[0].edge_m = (float)mean_edge(model->meshes, mc, &lod->level[0].triangles);

    mesh_groups *G = calloc((size_t)mc, sizeof *G);
    uint32_t *tmp = NULL, *cat = NULL;
    size_t maxi = 3;
    for (int i = 0; i < mc; i++)
        if ((size_t)model->meshes[i].index_count > maxi)
            maxi = (size_t)model->meshes[i].index_count;
    tmp = malloc(sizeof *tmp * maxi);
    cat = malloc(sizeof *cat * maxi);
    if (!G || !tmp || !cat) goto nomem;
    for (int i = 0; i < mc; i++)
        if (groups_build(&model->meshes[i], d.whole, &G[i]) < 0) goto nomem;

    double frac = 1.0;
    for (int l = 1; l <= d.max_levels; l++) {
        frac *= (double)d.ratio;
        /* into the chain's block (a level dropped below stays there until
         * io_lod_free: at most one level's index lists) */
        kin_mesh *meshes = kin_block_alloc(&lod->block, sizeof *meshes * (size_t)mc);
        if (!meshes) goto nomem;
        float lerr = lod->level[l - 1].error_m;
        long ltris = 0;
        int failed = 0;
        for (int i = 0; i < mc && !failed; i++) {
            const kin_mesh *me = &model->meshes[i];
            meshes[i] = *me;
            size_t n = 0;
            for (int gi = 0; gi < G[i].count; gi++) {
                size_t s = (size_t)G[i].start[gi], c = (size_t)G[i].start[gi + 1] - s;
                size_t target = (size_t)floor((double)(c / 3) * frac) * 3;
                float e = 0.0f;
                size_t got;
                if (target >= c) {
                    memcpy(tmp, G[i].idx + s, sizeof *tmp * c);
                    got = c;
                } else {
                    /* on the group's own vertices, mapped back */
                    const size_t v0 = (size_t)G[i].vstart[gi];
                    const size_t nv = (size_t)G[i].vstart[gi + 1] - v0;
                    got = meshopt_simplify(tmp, G[i].lidx + s, c, G[i].gpos + 3 * v0, nv,
                                           3 * sizeof(float), target, 1.0f,
                                           d.whole ? 0u : (unsigned)meshopt_SimplifyLockBorder,
                                           &e);
                    for (size_t k = 0; k < got; k++) tmp[k] = G[i].gv[v0 + tmp[k]];
                }
                memcpy(cat + n, tmp, sizeof *cat * got);
                n += got;
                float ae = e * G[i].scale[gi];
                if (ae > lerr) lerr = ae;
            }
            uint32_t *idx = kin_block_alloc(&lod->block, sizeof *idx * (n ? n : 1));
            if (!idx) {
                failed = 1;
                break;
            }
            if (n) meshopt_optimizeVertexCache(idx, cat, n, (size_t)me->vertex_count);
            meshes[i].indices = idx;
            meshes[i].index_count = (int)n;
            ltris += (long)(n / 3);
        }
        if (failed) goto nomem;
        long prev = lod->level[l - 1].triangles;
        if (ltris == 0 || (double)ltris > 0.9 * (double)prev || ltris < d.min_triangles) break;
        pipe_lod_level *L = &lod->level[l];
        L->meshes = meshes;
        L->error_m = lerr;
        long t2;
        L->edge_m = (float)mean_edge(meshes, mc, &t2);
        L->triangles = ltris;
        lod->level_count = l + 1;
    }
    for (int i = 0; i < mc; i++) groups_free(&G[i]);
    free(G);
    free(tmp);
    free(cat);
    return IO_OK;
nomem:
    if (G)
        for (int i = 0; i < mc; i++) groups_free(&G[i]);
    free(G);
    free(tmp);
    free(cat);
    io_lod_free(lod);
    return io_fail(err, IO_ERR_NOMEM, "%s: out of memory building the levels of detail", name);
}
