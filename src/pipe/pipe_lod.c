/* pipe_lod.c - the level-of-detail rule (pipe_lod.h). */
#include "pipe_lod.h"
#include "pipe.h"

#include <math.h>
#include <stdio.h>

int pipe_lod_choose(const pipe_lod *lod, float px_per_m, float target_px)
{
    if (!lod || lod->level_count < 2) return 0;
    if (!(px_per_m > 0.0f) || !isfinite(px_per_m)) return 0;
    if (!(target_px > 0.0f) || !isfinite(target_px)) return 0;
    int n = lod->level_count < PIPE_LOD_MAX ? lod->level_count : PIPE_LOD_MAX;
    int best = 0;
    for (int l = 1; l < n; l++) {
        float e = lod->level[l].error_m;
        if (!(e >= 0.0f) || !isfinite(e)) break;
        /* in double: the product of two floats is exact, so the boundary
         * e * px_per_m == target_px is decided without rounding */
        if ((double)e * (double)px_per_m > (double)target_px) break;
        best = l;
    }
    return best;
}

float pipe_lod_px_per_m(const float *clip, int n, float focal_px)
{
    if (!clip || n <= 0 || !(focal_px > 0.0f) || !isfinite(focal_px)) return 0.0f;
    float wmin = INFINITY;
    for (int i = 0; i < n; i++) {
        const float *c = clip + 4 * (size_t)i;
        float w = c[3];
        if (!(w > 0.0f)) continue;
        if (!(fabsf(c[0]) <= w) || !(fabsf(c[1]) <= w)) continue;
        if (w < wmin) wmin = w;
    }
    if (wmin == INFINITY) return 0.0f;
    if (wmin <= 1e-6f) return INFINITY;
    return focal_px / wmin;
}

int pipe_lod_check(const pipe_lod *lod, const kin_model *model, char *why, int why_size)
{
#define LOD_FAIL(...)                                                       \
    do {                                                                    \
        if (why && why_size > 0) snprintf(why, (size_t)why_size, __VA_ARGS__); \
        return 0;                                                           \
    } while (0)
    if (!lod || !model) LOD_FAIL("no level chain or no model");
    if (lod->mesh_count != model->mesh_count)
        LOD_FAIL("the level chain has %d meshes, the model %d", lod->mesh_count,
                 model->mesh_count);
    if (lod->level_count < 1 || lod->level_count > PIPE_LOD_MAX)
        LOD_FAIL("%d levels (1..%d)", lod->level_count, PIPE_LOD_MAX);
    for (int l = 0; l < lod->level_count; l++) {
        const pipe_lod_level *L = &lod->level[l];
        if (!L->meshes) LOD_FAIL("level %d has no meshes", l);
        if (!(L->error_m >= 0.0f) || !isfinite(L->error_m))
            LOD_FAIL("level %d: error %g is not a distance", l, (double)L->error_m);
        if (l > 0 && L->error_m < lod->level[l - 1].error_m)
            LOD_FAIL("level %d: error %g below level %d's %g", l, (double)L->error_m,
                     l - 1, (double)lod->level[l - 1].error_m);
        long tris = 0;
        for (int i = 0; i < model->mesh_count; i++) {
            const kin_mesh *a = &model->meshes[i], *b = &L->meshes[i];
            if (b->vertex_count != a->vertex_count || b->positions != a->positions ||
                b->normals != a->normals || b->joints != a->joints ||
                b->weights != a->weights || b->node != a->node || b->skin != a->skin ||
                b->target_count != a->target_count ||
                b->target_positions != a->target_positions ||
                b->target_normals != a->target_normals ||
                b->target_weights != a->target_weights || b->extra_sets != a->extra_sets ||
                b->joints_extra != a->joints_extra || b->weights_extra != a->weights_extra)
                LOD_FAIL("level %d, mesh %d: does not share the model's vertices", l, i);
            if (l == 0 && (b->indices != a->indices || b->index_count != a->index_count))
                LOD_FAIL("level 0, mesh %d: not the model's index list", i);
            if (b->index_count < 0 || b->index_count % 3 || (b->index_count && !b->indices))
                LOD_FAIL("level %d, mesh %d: %d indices", l, i, b->index_count);
            for (int k = 0; k < b->index_count; k++)
                if (b->indices[k] >= (uint32_t)b->vertex_count)
                    LOD_FAIL("level %d, mesh %d: index %d is %u, the mesh has %d vertices", l,
                             i, k, (unsigned)b->indices[k], b->vertex_count);
            tris += b->index_count / 3;
        }
        if (tris != L->triangles)
            LOD_FAIL("level %d: %ld triangles, its meshes hold %ld", l, L->triangles, tris);
    }
    return 1;
#undef LOD_FAIL
}

rast_result pipe_lod_draw(const pipe_pose *ps, const pipe_lod *lod, int level, float target_px,
                          rast_context *ctx, const kin_camera *cam, const rast_target *target,
                          rast_cull cull, float *clip, float *vnrm, rast_stats *stats,
                          int *drawn)
{
    if (drawn) *drawn = 0;
    if (!lod || lod->level_count < 1)
        return pipe_pose_draw(ps, ctx, cam, target, cull, clip, vnrm, stats);
    const int with_n = target->attr_count == 3;
    const float focal = cam->fx > cam->fy ? cam->fx : cam->fy;
    int finest = -1;
    for (int i = 0; i < ps->model->mesh_count && i < lod->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        rast_transform_points(cam->view_proj.m, ps->pos[i], me->vertex_count, clip);
        if (with_n) rast_transform_dirs(cam->view.m, ps->nrm[i], me->vertex_count, vnrm);
        int l = level;
        if (l < 0)
            l = pipe_lod_choose(lod, pipe_lod_px_per_m(clip, me->vertex_count, focal), target_px);
        if (l >= lod->level_count) l = lod->level_count - 1;
        const kin_mesh *lm = &lod->level[l].meshes[i];
        if (lm->index_count > 0 && (finest < 0 || l < finest)) finest = l;
        rast_mesh_desc d = {
            .clip = clip,
            .vertex_count = me->vertex_count,
            .attr = with_n ? vnrm : NULL,
            .attr_count = with_n ? 3 : 0,
            .indices = l ? lm->indices : me->indices,
            .tri_count = (l ? lm->index_count : me->index_count) / 3,
            .cull = cull,
        };
        rast_result r = ctx ? rast_context_draw(ctx, target, &d, stats)
                            : rast_draw(target, &d, stats);
        if (r != RAST_OK) return r;
    }
    if (drawn) *drawn = finest < 0 ? 0 : finest;
    return RAST_OK;
}
