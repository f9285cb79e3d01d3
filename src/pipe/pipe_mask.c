/* pipe_mask.c - the coverage mask of a model as a library call
 * (pipe_mask.h); `egofuse mask` is this function plus file I/O. */
#include "pipe_mask.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pipe.h"
#include "pipe_lens.h"
#include "pipe_internal.h"
#include "../cpu/ef_mem.h"

static int finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

int pipe_mask_render(const kin_model *model, const pipe_mask_desc *d,
                     uint8_t *mask, uint8_t *normals, float *depth,
                     char *why, int why_size)
{
    if (!model || !d || !mask) return pipe__fail(why, why_size, "model, description and mask must not be NULL");
    int width = d->width, height = d->height;
    if (width < 1 || width > RAST_MAX_DIM || height < 1 || height > RAST_MAX_DIM)
        return pipe__fail(why, why_size, "size %dx%d: width and height must be in 1..%d", width, height, RAST_MAX_DIM);
    if (!d->lens && !(d->fov_y > 0.0f && d->fov_y < 180.0f))
        return pipe__fail(why, why_size, "fov_y %g: not a number of degrees in (0, 180)", (double)d->fov_y);
    float znear = d->znear == 0.0f ? 0.01f : d->znear;
    float zfar = d->zfar == 0.0f ? 100.0f : d->zfar;
    if (!(znear > 0.0f) || !isfinite(znear)) return pipe__fail(why, why_size, "znear %g: not a positive number", (double)znear);
    if (!(zfar > znear) || !isfinite(zfar))
        return pipe__fail(why, why_size, "zfar (%g) must be a number greater than znear (%g)", (double)zfar, (double)znear);
    if (!finite3(d->eye) || !finite3(d->target) || !finite3(d->up) || !isfinite(d->time))
        return pipe__fail(why, why_size, "eye, target, up and time must be finite numbers");
    float u0 = d->up[0], u1 = d->up[1], u2 = d->up[2];
    if (u0 == 0.0f && u1 == 0.0f && u2 == 0.0f) u1 = 1.0f;
    kin_vec3 ve = kin_v3(d->eye[0], d->eye[1], d->eye[2]);
    kin_vec3 vt = kin_v3(d->target[0], d->target[1], d->target[2]);
    kin_vec3 vu = kin_v3(u0, u1, u2);
    kin_vec3 fwd = kin_v3_sub(vt, ve);
    if (kin_v3_len(fwd) == 0.0f) return pipe__fail(why, why_size, "eye and target are the same point");
    if (!isfinite(kin_v3_len(fwd)))
        return pipe__fail(why, why_size, "eye and target are too far apart (the view direction overflows "
                    "float arithmetic; keep coordinates below 1e18)");
    if (!isfinite(kin_v3_len(vu)))
        return pipe__fail(why, why_size, "up is too large (overflows float arithmetic; its length does not matter)");
    if (kin_v3_len(kin_v3_cross(fwd, vu)) <= 1e-6f * kin_v3_len(fwd) * kin_v3_len(vu))
        return pipe__fail(why, why_size, "up is parallel to the view direction");
    if (d->anim && (d->anim < model->anims || d->anim >= model->anims + model->anim_count))
        return pipe__fail(why, why_size, "anim is not one of the model's %d animations", model->anim_count);

    size_t npx = (size_t)width * (size_t)height;
    pipe_pose ps;
    if (pipe_pose_init(&ps, model) != 0) return pipe__fail(why, why_size, "out of memory for the model");
    int rc = -1;
    pipe_lens_map lm;
    memset(&lm, 0, sizeof lm);
    float *dep = malloc(sizeof(float) * npx);
    float *nrm = malloc(sizeof(float) * 3 * npx);
    uint8_t *msk = malloc(npx);
    float *clip = malloc(sizeof(float) * 4 * (size_t)(ps.max_vertices > 0 ? ps.max_vertices : 1));
    float *vnrm = malloc(sizeof(float) * 3 * (size_t)(ps.max_vertices > 0 ? ps.max_vertices : 1));
    if (!dep || !nrm || !msk || !clip || !vnrm) {
        pipe__fail(why, why_size, "out of memory for a %dx%d image", width, height);
        goto done;
    }
    kin_camera cam = kin_camera_look_at(ve, vt, vu, d->lens ? 60.0f : d->fov_y, width, height,
                                        znear, zfar);
    if (d->lens) {
        /* the calibrated lens at this size: its pinhole part draws, a
         * distortion is applied by the gather of pipe_lens */
        kin_lens l = *d->lens;
        char lw[160];
        if (!kin_lens_check(&l, lw, sizeof lw)) {
            pipe__fail(why, why_size, "lens: %s", lw);
            goto done;
        }
        if (l.width <= 0) l.width = width, l.height = height;
        cam.lens = kin_lens_scaled(&l, width, height);
        cam.fx = (float)cam.lens.fx, cam.fy = (float)cam.lens.fy;
        cam.cx = (float)(cam.lens.cx + 0.5), cam.cy = (float)(cam.lens.cy + 0.5);
        cam.proj = kin_proj_from_intrinsics(cam.lens.fx, cam.lens.fy, cam.lens.cx + 0.5,
                                            cam.lens.cy + 0.5, cam.lens.skew, width, height,
                                            znear, zfar);
        cam.view_proj = kin_mat4_mul(&cam.proj, &cam.view);
        if (kin_lens_distorts(&cam.lens) &&
            pipe_lens_map_init(&lm, &cam.lens, 1, 3, lw, sizeof lw) != 0) {
            pipe__fail(why, why_size, "lens: %s", lw);
            goto done;
        }
    }
    rast_target tg = {width, height, dep, width, msk, width, nrm, 3 * width, 3, NULL, 0};
    rast_target_clear(&tg);
    pipe_pose_anim(&ps, d->anim, d->time);
    rast_result rr;
    if (lm.src) {
        kin_camera pc = pipe_lens_pinhole(&lm, &cam);
        rast_target it = pipe_lens_target(&lm);
        rr = pipe_pose_draw(&ps, NULL, &pc, &it, RAST_CULL_NONE, clip, vnrm, NULL);
        if (rr == RAST_OK) pipe_lens_warp(&lm, &tg);
    } else {
        rr = pipe_pose_draw(&ps, NULL, &cam, &tg, RAST_CULL_NONE, clip, vnrm, NULL);
    }
    if (rr != RAST_OK) {
        pipe__fail(why, why_size, "cannot draw the model: %s", rast_result_str(rr));
        goto done;
    }
    /* Every output is written only once everything has been computed. */
    memcpy(mask, msk, npx);
    if (normals) {
        for (size_t i = 0; i < npx; i++) {
            for (int k = 0; k < 3; k++) {
                float v = 0.0f;
                if (msk[i]) {
                    kin_vec3 n = kin_v3_norm(kin_v3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]));
                    float comp = k == 0 ? n.x : k == 1 ? n.y : n.z;
                    v = comp * 0.5f + 0.5f;
                }
                normals[3 * i + k] = (uint8_t)lrintf(v * 255.0f);
            }
        }
    }
    if (depth) memcpy(depth, dep, sizeof(float) * npx);
    rc = 0;
done:
    EF_FREE_ALL(dep, nrm, msk, clip, vnrm);
    pipe_lens_map_free(&lm);
    pipe_pose_free(&ps);
    return rc;
}
