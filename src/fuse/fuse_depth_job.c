/* fuse_depth_job.c - the depth test of the layer against the virtual
 * scene as a job of a fuse_context (fuse_depth_test,
 * fuse_context_depth_test): row bands of the layer on the context's pool,
 * each band through the ISA's depth kernel (fuse__depth_rows,
 * fuse_depth.c). Every row is independent, so the bytes do not depend on
 * the ISA, the thread count or the banding. */
#include "fuse_ctx.h"

typedef struct depth_job {
    const kernels *k;
    const fuse_depth *d;
    fuse_image Q;
    int vx, vy, vw, vh;
} depth_job;

static void depth_task(void *arg, int t, int n)
{
    const depth_job *j = arg;
    int y0, y1;
    fuse__band(j->Q.height, t, n, &y0, &y1);
    fuse__depth_rows(j->d, &j->Q, j->vx, j->vy, j->vw, j->vh, y0, y1, j->k->depth);
}

static fuse_result depth_with(fuse_context *ctx, const kernels *k, const fuse_depth *d,
                              fuse_image *Q, int vp_x0, int vp_y0, int vp_w, int vp_h)
{
    depth_job j;
    fuse_result r = fuse__depth_check(d, Q, vp_x0, vp_y0, vp_w, vp_h);
    if (r != FUSE_OK) return r;
    j.k = k;
    j.d = d;
    j.Q = *Q;
    j.vx = vp_x0;
    j.vy = vp_y0;
    j.vw = vp_w;
    j.vh = vp_h;
    fuse__ctx_run(ctx, depth_task, &j);
    return FUSE_OK;
}

fuse_result fuse_depth_test(const fuse_depth *d, fuse_image *Q, int vp_x0,
                            int vp_y0, int vp_w, int vp_h)
{
    const kernels k = fuse__kernels_for(ef_isa_choose(EF_ISA_DEFAULT));
    return depth_with(NULL, &k, d, Q, vp_x0, vp_y0, vp_w, vp_h);
}

fuse_result fuse_context_depth_test(fuse_context *ctx, const fuse_depth *d, fuse_image *Q,
                                    int vp_x0, int vp_y0, int vp_w, int vp_h)
{
    if (ctx == NULL) return FUSE_ERR_ARGS;
    return depth_with(ctx, &ctx->k, d, Q, vp_x0, vp_y0, vp_w, vp_h);
}
