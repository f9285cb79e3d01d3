/* pipe_aa.h - internal to src/pipe: the anti-aliased coverage mask of an
 * eye (pipe_desc.aa_samples, pipe.h "ANTI-ALIASED EDGES"). pipe.c keeps
 * one pipe__aa per eye and calls it on the eye's thread; nothing here is
 * public.
 *
 * Per frame: pipe__aa_begin (clears what the last frame wrote), the draws
 * of the visible meshes (pipe__aa_draw_pose, or pipe__cockpit_draw_aa),
 * pipe__aa_resolve (cov: round(255 covered / count) per pixel); with the
 * refinement pipe__aa_refined (soft: cov where the refinement kept the
 * model's decision in the pixel's 3x3 window, else the 3x3 box filter of
 * the refined mask); then pipe__aa_fill_normals for the pixels the
 * coverage reaches but the G-buffer does not (their centres are outside
 * the model: no normal) and pipe__aa_unfill after the frame, which puts
 * the G-buffer's normals back as the rasterizer left them. */
#ifndef EGOFUSE_PIPE_AA_H
#define EGOFUSE_PIPE_AA_H

#include "pipe_pose.h"

typedef struct pipe__aa {
    int count;                /* samples per pixel: 4, 8 or 16 */
    int width, height;
    uint32_t *samples;        /* width x height sample bits */
    uint8_t *cov;             /* resolved coverage, width x height */
    uint8_t *soft;            /* refined coverage (refinement only), or NULL */
    int *colsum;              /* width + 2: 3-row sums (pipe__aa_refined) */
    uint8_t *colflip;         /* width + 2: 3-row flags */
    int box[4];               /* x0, y0, x1, y1 (exclusive): samples and
                                 cov are 0 outside (this frame's draws) */
    int soft_box[4];          /* soft is 0 outside */
    int nbox[4];              /* normals written by pipe__aa_fill_normals */
    const uint8_t *nsrc;      /* the m of that call (its pixels m > 0,
                                 mask 0), or NULL */
    /* the boundary band (pipe__aa_band): tiles of PIPE__AA_TILE px */
    int tw, th;               /* tiles across, down */
    uint8_t *tile;            /* tw x th: 1 = a pixel of the tile has a 3x3
                                 window of the kinematic mask that is not
                                 uniform (or is next to one) */
    int *tsat;                /* (tw + 1) x (th + 1) summed-area table of tile */
    const uint8_t *gmask;     /* the kinematic mask of this frame, or NULL
                                 (no band: every triangle, every pixel) */
    uint32_t *idx;            /* the triangles kept, 3 indices each */
    int idx_cap;              /* triangles idx holds */
    float *sxy;               /* the vertices' pixel x, y (NaN: behind the
                                 eye, or not finite) */
    int sxy_cap;              /* vertices sxy holds */
} pipe__aa;

#define PIPE__AA_TILE 4

/* Allocates the planes for count samples (4, 8, 16) at width x height;
 * with_soft: the refined coverage too. 0, or -1 (out of memory or a bad
 * count; pipe__aa_free is safe on it). */
int pipe__aa_init(pipe__aa *a, int count, int width, int height, int with_soft);
void pipe__aa_free(pipe__aa *a);
/* Clears what the last frame wrote (samples, cov, soft in their boxes). */
void pipe__aa_begin(pipe__aa *a);
/* The boundary band of this frame (call after pipe__aa_begin, before the
 * draws): tiles of PIPE__AA_TILE px that hold a pixel whose 3x3 window of
 * the kinematic mask (0/255, G-buffer) is not uniform. Then pipe__aa_draw
 * draws only the triangles whose pixel box meets such a tile (every
 * sample of a band tile gets the bits of the full draw), and
 * pipe__aa_resolve takes the kinematic mask (0 or 255) in every other
 * tile: there the pixel and its 8 neighbours' centres agree, and the
 * coverage of a closed surface is whole or none but for slivers thinner
 * than a pixel. mask must stay unchanged until pipe__aa_resolve. */
void pipe__aa_band(pipe__aa *a, const uint8_t *mask);
/* ORs in the samples of one mesh (clip coordinates, as rast_draw) and
 * grows the box by the vertices' pixel box (the whole target when a
 * vertex is at or behind the eye plane, w <= 1e-6). */
rast_result pipe__aa_draw(pipe__aa *a, rast_context *ctx, const float *clip, int vertex_count,
                          const uint32_t *indices, int tri_count, rast_cull cull);
/* Every mesh of ps through cam (pipe_pose_draw's meshes), clip: scratch
 * of 4 floats per vertex of the largest mesh. */
rast_result pipe__aa_draw_pose(pipe__aa *a, const pipe_pose *ps, rast_context *ctx,
                               const kin_camera *cam, rast_cull cull, float *clip);
/* cov from the samples, inside the box. */
void pipe__aa_resolve(pipe__aa *a);
/* soft from cov, the kinematic mask (0/255, G-buffer) and the refined mask
 * (0/255) of the same size; band: the refinement's half width (refined
 * differs from mask only within band + 1 px of the box). */
void pipe__aa_refined(pipe__aa *a, const uint8_t *mask, const uint8_t *refined, int band);
/* For every pixel with cov (or soft, m: the mask composited) > 0 and
 * kinematic mask 0: the sum of the normals of its 3x3 neighbours inside
 * the kinematic mask (fuse_light normalises; no neighbour: 0, which
 * fuse_light lights as facing the camera). nrm: 3 floats per pixel,
 * 3 * width per row. */
void pipe__aa_fill_normals(pipe__aa *a, const uint8_t *m, const uint8_t *mask, float *nrm);
/* Sets the normals written by pipe__aa_fill_normals back to 0 (the
 * rasterizer's clear value outside the mask). */
void pipe__aa_unfill(pipe__aa *a, const uint8_t *mask, float *nrm);

#endif
