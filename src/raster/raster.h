/* raster.h - the triangle rasterizer of egofuse (scalar reference).
 *
 * WHAT IT DOES
 *   Draws indexed triangles given in homogeneous clip space (OpenGL
 *   convention: visible when -w <= x, y, z <= w) into a target made of
 *   a depth plane, an 8-bit coverage mask and optional interpolated
 *   attributes (e.g. view-space normals), at any resolution up to
 *   RAST_MAX_DIM. Per triangle:
 *     1. drop triangles with a NaN or infinite coordinate;
 *     2. clip in homogeneous space against near (z >= -w), far (z <= w) and
 *        a guard band (|x|, |y| <= w * guard) so that screen coordinates stay
 *        within RAST_GUARD_PX pixels of the target;
 *     3. perspective divide, viewport: sx = (x/w*0.5+0.5)*width,
 *        sy = (0.5-y/w*0.5)*height (row 0 is the top of the view);
 *     4. snap to RAST_SUBPIXEL_BITS sub-pixel fixed point, round half to
 *        even; drop zero-area triangles; optional back/front culling
 *        (front = counter-clockwise in NDC, as OpenGL);
 *     5. exact int64 edge functions at pixel centres (x+0.5, y+0.5) with the
 *        top-left fill rule, so a pixel centre on an edge shared by two
 *        triangles is drawn exactly once;
 *     6. depth: window z = z/w*0.5+0.5 interpolated linearly in screen space,
 *        test LESS against the depth plane (if any), then write depth,
 *        mask = 255 and the perspective-correct attributes.
 *   Plane equations are evaluated in float with one fixed order of
 *   operations (docs/raster.md, summarised in docs/rounding.md), so SIMD
 *   paths can reproduce every byte. Attributes use perspective-correct
 *   barycentrics, so a constant attribute comes out exactly constant.
 *   One exception: where an output attribute is NaN (a NaN attribute in
 *   the mesh, or inf - inf), every path writes a NaN, but its sign and
 *   payload are not specified and may differ between paths (x86 returns
 *   one operand's NaN, and C does not fix the operand order of a
 *   commutative addition). Every other output value, depth and mask are
 *   the same bytes on every path.
 *   Facing is decided per triangle after clipping and snapping, from the
 *   sign of its snapped screen area (as GPUs do).
 *
 * SPEED
 *   The per-pixel scan has SSE2, AVX2 and AVX-512 versions giving the same
 *   bytes as the scalar reference (docs/raster.md section 9). rast_draw
 *   uses the best one the CPU runs, capped by EGOFUSE_ISA (src/cpu/cpu.h).
 *   A rast_context lets the caller cap the ISA, ask which one is used,
 *   draw one target with several threads (row bands) or several targets
 *   at once (e.g. one eye per thread; the bytes do not depend on the
 *   thread count), and clear only what its draws touched.
 *
 * WHAT IT DOES NOT
 *   rast_draw: no allocation, no threads, no global state: a target may be
 *   drawn by one thread at a time; different targets on different threads.
 *   A context allocates and starts its threads once, in
 *   rast_context_create; its draws allocate nothing.
 *   No textures, no blending. Anti-aliased coverage (4/8/16 samples per
 *   pixel, a fractional mask) is a separate, optional draw (below).
 *
 * USAGE
 *   float depth[W*H], nrm[W*H*3]; uint8_t mask[W*H];
 *   rast_target t = { W, H, depth, W, mask, W, nrm, W*3, 3, NULL, 0 };
 *   rast_target_clear(&t);
 *   rast_mesh_desc d = { clip, nverts, normals, 3, indices, ntris };
 *   rast_stats st;
 *   if (rast_draw(&t, &d, &st) != RAST_OK) ...;
 * or with the normals packed (src/cpu/ef_n10.h), uint32_t n10[W*H]:
 *   rast_target t = { W, H, depth, W, mask, W, NULL, 0, 3, n10, W };
 */
#ifndef EGOFUSE_RASTER_H
#define EGOFUSE_RASTER_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define RAST_SUBPIXEL_BITS 8              /* 1/256 pixel */
#define RAST_MAX_DIM 8192                 /* width and height limit */
#define RAST_GUARD_PX 8192                /* guard band around the target */
#define RAST_MAX_ATTRS 8                  /* interpolated floats per vertex */

typedef enum rast_result {
    RAST_OK = 0,
    RAST_ERR_ARGS,       /* NULL pointers, negative counts, bad strides */
    RAST_ERR_SIZE,       /* target size 0 or above RAST_MAX_DIM */
    RAST_ERR_INDEX       /* an index >= vertex_count (nothing drawn) */
} rast_result;

typedef enum rast_cull {
    RAST_CULL_NONE = 0,  /* default: both faces drawn */
    RAST_CULL_BACK,
    RAST_CULL_FRONT
} rast_cull;

/* The render target: caller-owned planes. depth and attr may be NULL.
 * The attributes go to at most one plane: attr (attr_count floats per
 * pixel) or attr_n10 (attr_count 3 only: a normal packed in one uint32_t
 * per pixel, a third of the bytes). The value written to attr_n10 for a
 * pixel is exactly ef_n10_pack(a0, a1, a2) of the three floats the same
 * draw writes to attr (so it is the same on every ISA, a NaN attribute
 * included: it packs as -511). The fields are last, so positional
 * initialisers of the earlier ones stay valid (the later are zero). */
typedef struct rast_target {
    int width, height;        /* 1..RAST_MAX_DIM */
    float *depth;             /* window depth in [0,1], cleared to 1; NULL =
                                 no depth test (later triangles win) */
    int depth_stride;         /* floats per row, >= width */
    uint8_t *mask;            /* 255 where drawn, 0 elsewhere; required */
    int mask_stride;          /* bytes per row, >= width */
    float *attr;              /* attr_count floats per pixel, or NULL */
    int attr_stride;          /* floats per row, >= width * attr_count */
    int attr_count;           /* 0..RAST_MAX_ATTRS, must match the mesh */
    uint32_t *attr_n10;       /* with attr NULL and attr_count 3: the three
                                 attributes of each pixel packed as
                                 ef_n10_pack (src/cpu/ef_n10.h), one
                                 uint32_t per pixel (cleared to 0, the
                                 packed zero); NULL = not used */
    int attr_n10_stride;      /* uint32_t per row, >= width */
} rast_target;

typedef struct rast_mesh_desc {
    const float *clip;        /* 4 floats (x, y, z, w) per vertex */
    int vertex_count;
    const float *attr;        /* attr_count floats per vertex, or NULL */
    int attr_count;           /* 0..RAST_MAX_ATTRS */
    const uint32_t *indices;  /* 3 per triangle */
    int tri_count;
    rast_cull cull;
} rast_mesh_desc;

/* Counters. tris_in and tris_nonfinite count submitted triangles; after
 * clipping a triangle becomes a fan of up to 7, and the other counters
 * count those fan triangles. */
typedef struct rast_stats {
    long tris_in;             /* triangles submitted */
    long tris_nonfinite;      /* dropped: NaN or infinite vertex (also an
                                 overflow to infinity inside the clipper) */
    long tris_clipped_away;   /* entirely outside the clip volume, or a fan
                                 triangle whose pixel box misses the target,
                                 or touching the clip-space origin (w = 0) */
    long tris_degenerate;     /* zero area after snapping */
    long tris_culled;         /* removed by the cull mode */
    long tris_drawn;          /* set up and scanned (after clipping a
                                 triangle may become several) */
    long pixels_written;      /* depth-test passes */
} rast_stats;

/* Sets depth to 1.0, mask to 0 and attributes to 0 (the first width
 * elements of each row; padding is left alone). NULL planes are skipped. */
void rast_target_clear(const rast_target *t);   /* attr_n10: to 0 */

/* Draws the mesh (see the steps above) on the calling thread with the ISA
 * of rast_draw_isa(). Stats are added to *stats when it
 * is not NULL (zero it first). Validates everything before drawing; on an
 * error nothing is drawn and *stats is untouched:
 *   RAST_ERR_ARGS  t, mesh or t->mask NULL; mask/depth stride < width;
 *                  attr stride < width*attr_count (when t->attr is set);
 *                  t->attr_n10 set with t->attr also set, with attr_count
 *                  other than 3 or with attr_n10_stride < width;
 *                  attr_count outside 0..RAST_MAX_ATTRS or different in
 *                  target and mesh; negative counts; clip/indices NULL with
 *                  a count > 0; mesh->attr NULL with attr_count > 0; a cull
 *                  value out of range.
 *   RAST_ERR_SIZE  width or height <= 0 or > RAST_MAX_DIM.
 *   RAST_ERR_INDEX an index >= vertex_count.
 * With t->attr and t->attr_n10 NULL the mesh attributes are ignored
 * (attr_count must still match). */
rast_result rast_draw(const rast_target *t, const rast_mesh_desc *mesh,
                      rast_stats *stats);

/* The ISA rast_draw uses now (an ef_isa value of src/cpu/cpu.h: the best
 * the CPU runs, capped by EGOFUSE_ISA). */
int rast_draw_isa(void);

/* ---- contexts: ISA cap, threads ---------------------------------------- */

#define RAST_MAX_THREADS 16

typedef struct rast_context rast_context;

typedef struct rast_context_desc {
    int max_isa;   /* cap: an ef_isa value (src/cpu/cpu.h), 0 = no cap; the
                      EGOFUSE_ISA variable caps further */
    int threads;   /* 0 or 1: draw on the calling thread only;
                      2..RAST_MAX_THREADS: the caller and threads-1 workers */
} rast_context_desc;

/* Creates a context (desc NULL: defaults). Chooses the ISA once and starts
 * the workers. NULL on a bad desc (threads or max_isa out of range) or when
 * memory or threads are not available. */
rast_context *rast_context_create(const rast_context_desc *desc);
/* Stops the workers and frees the context (NULL is fine). */
void rast_context_destroy(rast_context *ctx);
/* The ISA the context uses (an ef_isa value) and its thread count. */
int rast_context_isa(const rast_context *ctx);
int rast_context_threads(const rast_context *ctx);
/* rast_draw through the context: same validation, errors, stats and bytes
 * as rast_draw, for any ISA and any thread count. With threads > 1 the
 * triangles are set up in parallel batches, then every thread scans all of
 * them in submission order into its own interleaved 16-row bands. One
 * draw per context at a time (ctx NULL: RAST_ERR_ARGS). Allocates nothing. */
rast_result rast_context_draw(rast_context *ctx, const rast_target *t,
                              const rast_mesh_desc *mesh, rast_stats *stats);

/* Several independent draws at once: job i draws mesh[i] into t[i]. With
 * threads >= 2 and n >= 2 every job is drawn whole by one thread (job i
 * by thread i % threads; e.g. the two eyes of a frame, one per thread,
 * meeting only at the end); otherwise the jobs are drawn one after the
 * other as by rast_context_draw. Bytes and stats (summed over the jobs)
 * equal rast_draw of each job. Every job is validated first; on an error
 * (the first job's in order) nothing is drawn and *stats is untouched.
 * Errors: those of rast_draw, and RAST_ERR_ARGS for ctx, t or mesh NULL,
 * n outside 0..RAST_MAX_JOBS, or two jobs whose target planes share
 * memory. Allocates nothing. */
#define RAST_MAX_JOBS 16
rast_result rast_context_draw_jobs(rast_context *ctx, int n,
                                   const rast_target *const t[],
                                   const rast_mesh_desc *const mesh[],
                                   rast_stats *stats);

/* rast_target_clear that skips what is known to be clear. After a
 * rast_context_clear of a target, the draws of that target through ctx
 * (rast_context_draw, rast_context_draw_jobs) record the pixel box they
 * may write, and the next rast_context_clear of the same target (same
 * planes, size, strides and attribute count) clears only that box. A
 * target the context does not know (it remembers the last
 * RAST_CONTEXT_TARGETS) is cleared whole. The result equals
 * rast_target_clear provided nothing else writes the planes in between
 * (rast_draw, another context or the caller: then call rast_target_clear
 * or rast_context_forget). ctx NULL: rast_target_clear. */
#define RAST_CONTEXT_TARGETS 4
void rast_context_clear(rast_context *ctx, const rast_target *t);
/* rast_context_clear without the attribute plane (attr or attr_n10):
 * depth and mask as above; the attributes are cleared only where the target is unknown
 * (cleared whole), elsewhere they keep what earlier draws wrote. After
 * the next draws (all with the target's attributes), every pixel whose
 * mask is nonzero holds this frame's attributes, the others may hold an
 * earlier frame's: for callers whose every attribute reader skips the
 * pixels of mask 0 (the pipe's lighting, docs/raster.md section 13). A
 * later rast_context_clear of the same target clears it whole once. */
void rast_context_clear_keep_attr(rast_context *ctx, const rast_target *t);
/* Forgets every target: the next rast_context_clear clears whole. */
void rast_context_forget(rast_context *ctx);
/* The number of nonzero bytes of t's mask (the first width bytes of each
 * row). For a target the context knows (rast_context_clear above), only
 * the tiles its draws marked since that clear are read: the rest is clear
 * under the same condition (nothing else wrote the planes). Otherwise, or
 * with ctx NULL, every row. 16 bytes per SSE2 step. 0 for a target
 * without a mask, with a size out of range or a mask stride below the
 * width. */
long rast_context_count(rast_context *ctx, const rast_target *t);

/* ---- anti-aliased coverage ---------------------------------------------
 *
 * Optional soft edges for the mask: every pixel holds `count` samples at
 * the standard Direct3D positions (4, 8 or 16 per pixel; offsets from the
 * centre in 1/16 px, rast_aa_positions) and a bit per sample. A draw ORs
 * in the samples each triangle covers, with the same clipping, snapping,
 * culling and top-left rule as rast_draw (applied at the sample instead
 * of the centre), so triangles sharing an edge cover each sample once.
 * Depth: none. The coverage is the union of the drawn triangles (the
 * silhouette of the mesh, independent of the order), which is what a soft
 * hand mask needs; depth and normals come from rast_draw at the centres.
 * rast_aa_resolve turns the bits into the 8-bit fractional mask
 * round(255 * covered / count) (halves up). Error bound against the exact
 * area of a pixel inside a straight edge: docs/raster.md section 12. */
#define RAST_AA_MAX_SAMPLES 16

typedef struct rast_aa_target {
    int width, height;      /* 1..RAST_MAX_DIM */
    uint32_t *samples;      /* per pixel: bit s set = sample s covered */
    int stride;             /* elements per row, >= width */
    int count;              /* samples per pixel: 4, 8 or 16 */
} rast_aa_target;

/* The offsets of the count samples (4, 8 or 16) from the pixel centre in
 * 1/16 px (x right, y down), xy[2*s], xy[2*s+1]; 0 for another count. */
int rast_aa_positions(int count, int xy[2 * RAST_AA_MAX_SAMPLES]);
/* Clears the sample bits (first width elements of each row). */
void rast_aa_clear(const rast_aa_target *t);
/* ORs the samples covered by the mesh into t (mesh attributes are
 * ignored; attr_count need not be 0). Validation and errors as rast_draw
 * (RAST_ERR_ARGS also for a count other than 4, 8, 16 or samples NULL);
 * stats count pixels with at least one covered sample per fan triangle in
 * pixels_written. The ISA of rast_draw_isa(); same bits on every ISA. */
rast_result rast_draw_aa(const rast_aa_target *t, const rast_mesh_desc *mesh,
                         rast_stats *stats);
/* The same with the context's ISA (on the calling thread). */
rast_result rast_context_draw_aa(rast_context *ctx, const rast_aa_target *t,
                                 const rast_mesh_desc *mesh, rast_stats *stats);
/* mask[y*mask_stride + x] = (510 * covered + count) / (2 * count), i.e.
 * round(255 * covered / count), halves up. RAST_ERR_ARGS / _SIZE as for
 * a draw (mask NULL, mask_stride < width). */
rast_result rast_aa_resolve(const rast_aa_target *t, uint8_t *mask, int mask_stride);

/* clip[i] = mvp * (pos[i], 1) for n points (pos: 3 floats each, mvp a
 * column-major 4x4 matrix), each row as ((m0*x + m4*y) + m8*z) + m12.
 * Both transforms run 16 vertices per step with AVX-512 when
 * rast_draw_isa() allows it (EGOFUSE_ISA caps it; a context's cap does
 * not apply), with the same bytes as the scalar code on every ISA. */
void rast_transform_points(const float mvp[16], const float *pos, int n,
                           float *clip);
/* out[i] = normalize(m3x3 * v[i]) where m3x3 is the upper 3x3 of the
 * column-major 4x4 m: for rotating normals into view space. The length is
 * taken in double (no underflow for tiny vectors); a zero vector stays
 * zero. For non-uniform scale pass the inverse transpose. */
void rast_transform_dirs(const float m[16], const float *v, int n, float *out);

const char *rast_result_str(rast_result r);

#ifdef __cplusplus
}
#endif
#endif
