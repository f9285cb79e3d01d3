/* pipe_query.c - what a pipe tells of itself and of its last frame (the
 * masks, layers and cameras of pipe.h's queries), its settings between
 * frames (levels of detail, props, the fit's reset), and the room's small
 * helpers (pipe_image_opaque, pipe_result_str, pipe_lighting_default).
 * The frame itself is pipe.c's. */
#include "pipe_ctx.h"

#include <math.h>
#include <stdint.h>

pipe_lighting pipe_lighting_default(void)
{
    pipe_lighting l = {fuse_lighting_default()};
    return l;
}

void pipe_reset_fit(pipe_ctx *p)
{
    if (!p || !p->fit) return;
    pipe_fit_forget(p->fit);
    p->fit_no_prev = 1;
}

const uint8_t *pipe_mask(const pipe_ctx *p, int eye, int *width, int *height)
{
    if (width) *width = p->geo.crop_width;
    if (height) *height = p->geo.crop_height;
    const eye_state *e = &p->eye[eye ? 1 : 0];
    if (e->aa.count && e->shown) return e->shown;
    return e->have_refined ? e->refined : e->mask;
}

const uint8_t *pipe_layer(const pipe_ctx *p, int eye, int *width, int *height)
{
    if (width) *width = p->geo.crop_width;
    if (height) *height = p->geo.crop_height;
    return p->eye[eye ? 1 : 0].layer;
}

kin_camera pipe_camera(const pipe_ctx *p, int eye) { return p->eye[eye ? 1 : 0].cam; }

kin_camera pipe_view_camera(const pipe_ctx *p, int eye)
{
    const eye_state *e = &p->eye[eye ? 1 : 0];
    return e->view_used == PIPE_VIEW_REPROJECT ? e->rp.cam : e->cam;
}

const uint8_t *pipe_view_mask(const pipe_ctx *p, int eye, int *width, int *height)
{
    const eye_state *e = &p->eye[eye ? 1 : 0];
    if (width) *width = e->rp.width;
    if (height) *height = e->rp.height;
    /* the mask composited (run_eye sets shown in every frame that
     * reprojects): the eye view's, softened with soft_edge */
    return e->view_used == PIPE_VIEW_REPROJECT ? e->shown : NULL;
}

kin_sthmd_geometry pipe_geometry(const pipe_ctx *p) { return p->geo; }

kin_sthmd_desc pipe_hmd(const pipe_ctx *p) { return p->hmd; }

int pipe_set_lod(pipe_ctx *p, const pipe_lod *lod, int level, float target_px)
{
    if (!p || level < PIPE_LOD_AUTO) return -1;
    if (lod && !pipe_lod_check(lod, p->model, NULL, 0)) return -1;
    if (level == PIPE_LOD_AUTO && (!(target_px > 0.0f) || !isfinite(target_px))) return -1;
    p->lod = level == 0 ? NULL : lod;
    p->lod_level = level;
    p->lod_px = target_px;
    return 0;
}

unsigned pipe_parts_present(const pipe_ctx *p) { return p ? pipe__cockpit_present(p->ck) : 0; }

int pipe_add_prop(pipe_ctx *p, const kin_model *m)
{
    return p ? pipe__cockpit_add_prop(p->ck, m) : -1;
}

int pipe_prop_count(const pipe_ctx *p) { return p ? pipe__cockpit_prop_count(p->ck) : 0; }

int pipe_image_opaque(const fuse_image *im, int x0, int y0, int w, int h)
{
    if (!im || !im->pixels || w < 1 || h < 1 || x0 < 0 || y0 < 0 || x0 > im->width - w ||
        y0 > im->height - h || im->stride < 4 * im->width)
        return 0;
    for (int y = y0; y < y0 + h; y++) {
        const uint8_t *a = im->pixels + (size_t)y * (size_t)im->stride + (size_t)x0 * 4 + 3;
        unsigned all = 255;
        for (int x = 0; x < w; x++) all &= a[(size_t)x * 4];
        if (all != 255) return 0;
    }
    return 1;
}

int pipe_isa(const pipe_ctx *p) { return rast_context_isa(p->eye[0].rast); }

const char *pipe_result_str(pipe_result r)
{
    switch (r) {
    case PIPE_OK: return "ok";
    case PIPE_ERR_ARGS: return "invalid arguments";
    case PIPE_ERR_RASTER: return "rasterizer error";
    case PIPE_ERR_FUSE: return "lighting/composite error";
    }
    return "unknown error";
}
