/* fit.c - the fit of the arm model to the camera images: elbow swivel,
 * colour learning, limb thickness (see fit.h). */
#include "fit.h"
#include "../cpu/ef_mem.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


/* ------------------------------------------------------- elbow fit */

#define FIT_DEG2RAD 0.01745329252f
#define FIT_STATIONS 6            /* width stations per segment and eye */
#define FIT_MAX_WALK 160          /* px: longest half width measured */
#define FIT_MIN_SAMPLES 12        /* widths before a thickness is used */
#define FIT_WINDOW_GEOS 14        /* poses checking the points in view: every
                                     30 deg over up to 360 deg, and its end */

struct pipe_fit {
    pipe_fit_desc d;
    const kin_model *model;
    kin_arm_rig rig;
    int width, height;
    int *v[2];                /* fit vertex indices per side */
    uint8_t *use[2];          /* per side, eye-major: 1 = the point is in
                                 view in every candidate of this search */
    int n[2];
    float swivel[2];
    int have_prev;
    float *llr[2];            /* colour model per eye */
    fuse_colour_model cm[2];
    int learned[2];           /* 1: cm[eye] holds a model */
    uint8_t *learn[2];        /* width x height per eye (the eyes may
                                 learn on two threads) */
    void *scratch[2];
    float *acc[2];            /* per eye (learn_memory > 0): the arm and
                                 the background histograms over frames */
    double accn[2][2];        /* per eye: their sums (arm, background) */
    size_t scratch_size;
    /* limb thickness (self-calibration from the masks) */
    int *sv[2];               /* per side: vertices weighted to its arm */
    float *sw[2];             /* per side: 2 weights (upper arm, forearm) */
    int sn[2];
    float thick[2][2];        /* [side][segment]: factor in use */
    float radius[2][2];       /* [side][segment]: the model's mean limb
                                 radius (bind pose), metres */
    float *samples[2][2][2];  /* [eye][side][segment]: measured factors */
    int ns[2][2][2];
    int cap;                  /* capacity of each samples array */
    int done[2][2];           /* [side][segment]: frozen */
    int frozen;               /* all four are */
    float *sort;              /* 2 cap floats: medians */
};

/* Vertices bound (weight >= 0.9) to the upper arm or forearm of a side,
 * at most d.points, evenly picked, and every vertex with any weight on
 * them (for pipe_fit_shape). -1 when a side has none. */
static int fit_vertices(pipe_fit *f)
{
    const kin_mesh *me = &f->model->meshes[0];
    const kin_skin *sk = &f->model->skins[me->skin];
    const int P = f->d.points;
    for (int s = 0; s < 2; s++) {
        int ua = f->rig.joint[s][KIN_RIG_UPPER_ARM], fa = f->rig.joint[s][KIN_RIG_FOREARM];
        int count = 0;
        f->n[s] = 0;
        f->sn[s] = 0;
        for (int pass = 0; pass < 2; pass++) {
            int k = 0;
            for (int v = 0; v < me->vertex_count; v++) {
                float wu = 0.0f, wf = 0.0f;
                for (int j = 0; j < 4; j++) {
                    int node = sk->joints[me->joints[v * 4 + j]];
                    if (node == ua) wu += me->weights[v * 4 + j];
                    if (node == fa) wf += me->weights[v * 4 + j];
                }
                if (pass == 1 && wu + wf > 0.0f) {
                    f->sv[s][f->sn[s]] = v;
                    f->sw[s][2 * f->sn[s]] = wu;
                    f->sw[s][2 * f->sn[s] + 1] = wf;
                    f->sn[s]++;
                }
                if (wu + wf < 0.9f) continue;
                if (pass == 1) {
                    long lo = (long)k * P / count, hi = (long)(k + 1) * P / count;
                    if (hi > lo && f->n[s] < P) f->v[s][f->n[s]++] = v;
                }
                k++;
            }
            if (pass == 0) {
                count = k;
                if (count == 0) return -1;
            }
        }
    }
    return 0;
}

/* The model's mean limb radius per side and segment: the mean distance
 * of the vertices bound to the bone (weight >= 0.9) from its axis segment
 * (bone to child joint) in the bind pose; 0 when there are none. */
static void fit_radii(pipe_fit *f)
{
    const kin_mesh *me = &f->model->meshes[0];
    const kin_skin *sk = &f->model->skins[me->skin];
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            int j0 = f->rig.joint[s][g ? KIN_RIG_FOREARM : KIN_RIG_UPPER_ARM];
            int j1 = f->rig.joint[s][g ? KIN_RIG_HAND : KIN_RIG_FOREARM];
            int k0 = -1, k1 = -1;
            for (int k = 0; k < sk->joint_count; k++) {
                if (sk->joints[k] == j0) k0 = k;
                if (sk->joints[k] == j1) k1 = k;
            }
            f->radius[s][g] = 0.0f;
            kin_mat4 b0, b1;
            if (k0 < 0 || k1 < 0 || !sk->inverse_bind ||
                !kin_mat4_inverse(&sk->inverse_bind[k0], &b0) ||
                !kin_mat4_inverse(&sk->inverse_bind[k1], &b1))
                continue;
            kin_vec3 A = kin_mat4_translation(&b0), B = kin_mat4_translation(&b1);
            kin_vec3 d = kin_v3_sub(B, A);
            float dd = kin_v3_dot(d, d);
            if (!(dd > 0.0f)) continue;
            double sum = 0.0;
            long n = 0;
            for (int v = 0; v < me->vertex_count; v++) {
                float w = 0.0f;
                for (int j = 0; j < 4; j++)
                    if (me->joints[v * 4 + j] == k0) w += me->weights[v * 4 + j];
                if (w < 0.9f) continue;
                const float *p = &me->positions[(size_t)v * 3];
                kin_vec3 P = kin_v3(p[0], p[1], p[2]);
                float a = kin_v3_dot(kin_v3_sub(P, A), d) / dd;
                a = a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a;
                sum += kin_v3_len(kin_v3_sub(P, kin_v3_add(A, kin_v3_scale(d, a))));
                n++;
            }
            f->radius[s][g] = n ? (float)(sum / (double)n) : 0.0f;
        }
}

/* One setting of pipe_fit_desc: 0 = def, else it must lie in (0, hi] and
 * be >= lo (NaN fails). */
static int fit_setting(float *v, float def, float lo, float hi)
{
    if (*v == 0.0f) {
        *v = def;
        return 1;
    }
    return *v > 0.0f && *v >= lo && *v <= hi;
}

/* The settings with defaults filled in; 0 when one is out of bounds. */
static int fit_settings(pipe_fit_desc *d)
{
    if (!fit_setting(&d->range_deg, 60.0f, 0.0f, PIPE_FIT_MAX_RANGE_DEG) ||
        !fit_setting(&d->step_deg, 5.0f, PIPE_FIT_MIN_STEP_DEG, PIPE_FIT_MAX_STEP_DEG) ||
        !fit_setting(&d->rate_deg, 12.0f, 0.0f, PIPE_FIT_MAX_RANGE_DEG) ||
        !fit_setting(&d->prior, 0.05f, 0.0f, PIPE_FIT_MAX_PRIOR))
        return 0;
    if (d->points == 0) d->points = 400;
    if (d->shape_samples == 0) d->shape_samples = 48;
    if (d->learn_memory == 0.0f) d->learn_memory = PIPE_FIT_LEARN_MEMORY;
    if (!(d->learn_memory < 0.0f || (d->learn_memory > 0.0f && d->learn_memory < 1.0f)))
        return 0;   /* NaN, >= 1 */
    return d->points >= 1 && d->points <= PIPE_FIT_MAX_POINTS &&
           d->shape_samples <= PIPE_FIT_MAX_SHAPE_SAMPLES;
}

/* 1 when mesh 0 is skinned by one of the model's skins, whose joints are
 * nodes, and every joint index of its vertices names one of them. */
static int fit_mesh_ok(const kin_model *m)
{
    const kin_mesh *me = &m->meshes[0];
    if (me->skin < 0 || me->skin >= m->skin_count || !me->joints || !me->weights ||
        !me->positions || me->vertex_count < 1)
        return 0;
    const kin_skin *sk = &m->skins[me->skin];
    if (sk->joint_count < 1 || !sk->joints) return 0;
    for (int k = 0; k < sk->joint_count; k++)
        if (sk->joints[k] < 0 || sk->joints[k] >= m->node_count) return 0;
    for (size_t i = 0; i < 4 * (size_t)me->vertex_count; i++)
        if (me->joints[i] >= sk->joint_count) return 0;
    return 1;
}

/* 1 when node a is a proper ancestor of node d. */
static int fit_ancestor(const kin_model *m, int a, int d)
{
    for (int k = 0, n = d; k < m->node_count; k++) {
        n = m->parents[n];
        if (n < 0 || n >= m->node_count) return 0;
        if (n == a) return 1;
    }
    return 0;
}

/* 1 when each side's upper arm, forearm and hand are nodes, each a proper
 * descendant of the one before: turning the upper arm then moves the
 * forearm and the hand, and the hand's correction (fit_apply) is taken in
 * its parent's frame, whichever node that is. */
static int fit_rig_ok(const kin_model *m, const kin_arm_rig *rig)
{
    if (!m->parents) return 0;
    for (int s = 0; s < 2; s++) {
        const int j[3] = { rig->joint[s][KIN_RIG_UPPER_ARM], rig->joint[s][KIN_RIG_FOREARM],
                           rig->joint[s][KIN_RIG_HAND] };
        for (int k = 0; k < 3; k++)
            if (j[k] < 0 || j[k] >= m->node_count) return 0;
        if (!fit_ancestor(m, j[0], j[1]) || !fit_ancestor(m, j[1], j[2])) return 0;
    }
    /* the arms apart: two chains that share a node (or one hanging below
     * the other's upper arm) have one upper arm at or below the other's,
     * and would turn and thicken the same limb twice */
    const int a = rig->joint[0][KIN_RIG_UPPER_ARM], b = rig->joint[1][KIN_RIG_UPPER_ARM];
    return a != b && !fit_ancestor(m, a, b) && !fit_ancestor(m, b, a);
}

pipe_fit *pipe_fit_create(const pipe_fit_desc *desc, const kin_model *model,
                          const kin_arm_rig *rig, int width, int height)
{
    if (!model || !rig || width < 1 || height < 1 || model->mesh_count < 1 ||
        !model->meshes || !model->skins || !fit_mesh_ok(model) || !fit_rig_ok(model, rig))
        return NULL;
    pipe_fit_desc d = {0};
    if (desc) d = *desc;
    if (!fit_settings(&d)) return NULL;
    pipe_fit *f = calloc(1, sizeof *f);
    if (!f) return NULL;
    f->d = d;
    f->model = model;
    f->rig = *rig;
    f->width = width;
    f->height = height;
    f->scratch_size = fuse_colour_model_scratch_size(PIPE_FIT_BITS);
    const size_t nv = (size_t)model->meshes[0].vertex_count;
    f->cap = f->d.shape_samples > 0 ? f->d.shape_samples : 1;
    f->sort = malloc(sizeof(float) * 2 * (size_t)f->cap);
    int ok = f->sort != NULL;
    for (int e = 0; e < 2; e++) {
        f->llr[e] = calloc((size_t)1 << (3 * PIPE_FIT_BITS), sizeof(float));
        f->cm[e] = (fuse_colour_model){ PIPE_FIT_BITS, 0, 0, f->llr[e] };
        f->v[e] = malloc(sizeof(int) * (size_t)f->d.points);
        f->use[e] = malloc(2 * (size_t)f->d.points);
        f->sv[e] = malloc(sizeof(int) * nv);
        f->sw[e] = malloc(sizeof(float) * 2 * nv);
        f->scratch[e] = malloc(f->scratch_size);
        f->acc[e] = calloc((size_t)2 << (3 * PIPE_FIT_BITS), sizeof(float));
        f->learn[e] = malloc((size_t)width * (size_t)height);
        ok = ok && f->acc[e] && f->llr[e] && f->v[e] && f->use[e] && f->sv[e] && f->sw[e] && f->scratch[e] && f->learn[e];
        for (int s = 0; s < 2; s++)
            for (int g = 0; g < 2; g++) {
                f->samples[e][s][g] = malloc(sizeof(float) * (size_t)f->cap);
                ok = ok && f->samples[e][s][g];
            }
    }
    if (!ok || fit_vertices(f) < 0) {
        pipe_fit_destroy(f);
        return NULL;
    }
    fit_radii(f);
    pipe_fit_reset(f);
    pipe_fit_reset_shape(f);
    return f;
}

void pipe_fit_destroy(pipe_fit *f)
{
    if (!f) return;
    for (int e = 0; e < 2; e++) {
        EF_FREE_ALL(f->llr[e], f->v[e], f->use[e], f->sv[e], f->sw[e], f->scratch[e], f->acc[e],
                    f->learn[e]);
        for (int s = 0; s < 2; s++)
            for (int g = 0; g < 2; g++) free(f->samples[e][s][g]);
    }
    free(f->sort);
    free(f);
}

void pipe_fit_reset(pipe_fit *f)
{
    if (!f) return;
    f->have_prev = 0;
    f->swivel[0] = f->swivel[1] = 0.0f;
}

void pipe_fit_reset_shape(pipe_fit *f)
{
    if (!f) return;
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            f->thick[s][g] = 1.0f;
            f->ns[0][s][g] = f->ns[1][s][g] = 0;
            f->done[s][g] = f->d.shape_samples < 0;
        }
    f->frozen = f->d.shape_samples < 0;
}

void pipe_fit_forget(pipe_fit *f)
{
    if (!f) return;
    pipe_fit_reset(f);
    pipe_fit_reset_shape(f);
    for (int e = 0; e < 2; e++) {
        f->learned[e] = 0;
        f->cm[e].fg_samples = f->cm[e].bg_samples = 0;
        memset(f->llr[e], 0, sizeof(float) << (3 * PIPE_FIT_BITS));
        memset(f->acc[e], 0, sizeof(float) << (3 * PIPE_FIT_BITS + 1));
        f->accn[e][0] = f->accn[e][1] = 0.0;
    }
}

const fuse_colour_model *pipe_fit_colour(const pipe_fit *f, int eye)
{
    return f ? &f->cm[eye ? 1 : 0] : NULL;
}

int pipe_fit_learned(const pipe_fit *f, int eye)
{
    return f ? f->learned[eye ? 1 : 0] : 0;
}

/* The colour model of eye from histograms kept over frames (learn_memory
 * m > 0): each bin of both classes is multiplied by m, then this frame's
 * pixels of f->learn[eye] (255 arm, 0 background, else not learned) are
 * added, with fuse_colour_model_learn's margin (4 px), step (2), pseudo
 * counts and clamp (3 nats); the model is the log ratio of the kept
 * histograms, and needs >= 64 kept samples per class (fg_samples and
 * bg_samples: the kept sums, rounded down). A pixel learned wrongly in one
 * frame (the desk pad under a kinematic arm that is off) weighs against
 * every frame that saw it right, instead of making the whole model. */
/* The bin of an RGBA pixel (fuse_colour_bin, inlined: it runs per
 * sampled pixel). */
static inline unsigned fit_bin(const uint8_t *px, int bits)
{
    const int s = 8 - bits;
    return ((unsigned)(px[0] >> s) << (2 * bits)) | ((unsigned)(px[1] >> s) << bits) |
           (unsigned)(px[2] >> s);
}

/* The learning mask's rows, 8 pixels a step as bytes of a 64-bit word
 * (the same bytes as the per-pixel expressions in pipe_fit_learn and
 * fit_learn_memory). */
static uint64_t fit_ld8(const uint8_t *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

static void fit_learn_memory(pipe_fit *f, int eye, const fuse_image *P)
{
    const int w = f->width, h = f->height, bits = PIPE_FIT_BITS, bins = 1 << (3 * bits);
    const int margin = 4;   /* even: pipe_fit_learn builds only the even rows (and the last) */
    const float m = f->d.learn_memory;
    float *af = f->acc[eye], *ab = af + bins;
    const uint8_t *mask = f->learn[eye];
    /* an arm sample whose bin the model so far calls clearly background
     * (llr < -PIPE_FIT_LEARN_REJECT) is not counted: where the kinematic
     * mask lies beside the hand over a skin-coloured prop, the refined mask
     * and the kinematic one agree on the prop, and without this it is
     * learned as arm frame after frame (edge: the folder) */
    const float *old = f->learned[eye] ? f->cm[eye].llr : NULL;
    const float rej = -PIPE_FIT_LEARN_REJECT;
    /* a count decayed below PIPE_FIT_COUNT_FLOOR is set to 0: the floor
     * lies far below half an ulp of a (the llr's pseudo-count below), so
     * a + count rounds to a either way and every llr keeps its bytes, and
     * a later sample's +1 absorbs it either way; in a long run the
     * histograms then hold no subnormal floats, and a colour sampled once
     * and not again for 590 frames (about 10 s at 60 Hz: 0.95^590 < 2^-43,
     * the floor) drops out of the per-bin logf below */
    for (int b = 0; b < 2 * bins; b++) {
        const float v = af[b] * m;
        af[b] = v < PIPE_FIT_COUNT_FLOOR ? 0.0f : v;
    }
    long nf = 0, nb = 0;
    for (int y = 0; y < h; y += 2) {
        const uint8_t *row = mask + (size_t)y * (size_t)w;
        const int yu = y - margin < 0 ? 0 : y - margin, yd = y + margin >= h ? h - 1 : y + margin;
        const uint8_t *up = mask + (size_t)yu * (size_t)w, *dn = mask + (size_t)yd * (size_t)w;
        const uint8_t *src = P->pixels + (size_t)y * (size_t)P->stride;
        for (int x = 0; x < w; x += 2) {
            /* 8 columns x .. x + 7 whose margins are inside the row: when
             * they and the bytes at +-margin, above and below are all 0
             * or all 255, each of the 4 sampled columns passes the test
             * below (the same samples in the same order: the same sums) */
            if (x >= margin && x + 8 + margin <= w) {
                const uint64_t c = fit_ld8(row + x);
                if ((c == 0 || c == ~0ull) &&
                    ((c ^ fit_ld8(row + x - margin)) | (c ^ fit_ld8(row + x + margin)) |
                     (c ^ fit_ld8(up + x)) | (c ^ fit_ld8(dn + x))) == 0) {
                    if (!c || !old) {
                        float *hist = c ? af : ab;
                        for (int k = 0; k < 8; k += 2) hist[fit_bin(src + 4 * (x + k), bits)] += 1.0f;
                        if (c) nf += 4;
                        else nb += 4;
                    } else {
                        for (int k = 0; k < 8; k += 2) {
                            const unsigned bb = fit_bin(src + 4 * (x + k), bits);
                            if (old[bb] < rej) continue;
                            af[bb] += 1.0f;
                            nf++;
                        }
                    }
                    x += 6;
                    continue;
                }
            }
            const uint8_t v = row[x];
            if (v != 0 && v != 255) continue;
            int xl = x - margin < 0 ? 0 : x - margin, xr = x + margin >= w ? w - 1 : x + margin;
            if (row[xl] != v || row[xr] != v || up[x] != v || dn[x] != v) continue;
            unsigned b = fit_bin(src + 4 * x, bits);
            if (v == 255) {
                if (old && old[b] < rej) continue;
                af[b] += 1.0f;
                nf++;
            }
            else { ab[b] += 1.0f; nb++; }
        }
    }
    f->accn[eye][0] = f->accn[eye][0] * m + (double)nf;
    f->accn[eye][1] = f->accn[eye][1] * m + (double)nb;
    fuse_colour_model *cm = &f->cm[eye];
    cm->fg_samples = (long)f->accn[eye][0];
    cm->bg_samples = (long)f->accn[eye][1];
    f->learned[eye] = cm->fg_samples >= 64 && cm->bg_samples >= 64;
    if (!f->learned[eye]) {
        memset(cm->llr, 0, (size_t)bins * sizeof(float));
        return;
    }
    const float a = PIPE_FIT_PSEUDO_COUNT;
    const float off = logf((float)f->accn[eye][1] + 4.0f) - logf((float)f->accn[eye][0] + 4.0f);
    /* a bin never seen by either class (both 0) has the ratio a / a = 1
     * exactly, logf 0: its entry is the offset, clamped */
    const float off_c = off > 3.0f ? 3.0f : off < -3.0f ? -3.0f : off;
    for (int b = 0; b < bins; b++) {
        /* 8 bins (bins is a multiple of 8) all +0 in both classes (most
         * are): the offset, as below */
        if ((b & 7) == 0) {
            uint32_t z = 0;
            for (int k = 0; k < 8; k++) {
                uint32_t u, v;
                memcpy(&u, &af[b + k], 4);
                memcpy(&v, &ab[b + k], 4);
                z |= u | v;
            }
            if (z == 0) {
                for (int k = 0; k < 8; k++) cm->llr[b + k] = off_c;
                b += 7;
                continue;
            }
        }
        if (af[b] == 0.0f && ab[b] == 0.0f) {
            cm->llr[b] = off_c;
            continue;
        }
        float v = logf((af[b] + a) / (ab[b] + a)) + off;
        cm->llr[b] = v > 3.0f ? 3.0f : v < -3.0f ? -3.0f : v;
    }
}

#define FIT_B01 0x0101010101010101ull
typedef uint64_t fit_v2 __attribute__((vector_size(16)));

fuse_result pipe_fit_learn(pipe_fit *f, int eye, const fuse_image *P, const uint8_t *mask,
                           int mask_stride, const uint8_t *prev, int prev_stride)
{
    if (!f || !P || !P->pixels || !mask || eye < 0 || eye > 1 || P->width != f->width ||
        P->height != f->height || mask_stride < f->width || (prev && prev_stride < f->width))
        return FUSE_ERR_ARGS;
    const uint8_t *learn = f->learn[eye];
    const int stride = f->width;
    /* fit_learn_memory samples the even rows and reads the rows 4 above
     * and below, clamped to 0 and height - 1: only those rows are built
     * (fuse_colour_model_learn, without memory, gets every row) */
    const int odd_skip = f->d.learn_memory > 0.0f;
#define FIT_LEARN_ROW_SKIPPED(y) (odd_skip && ((y) & 1) && (y) != f->height - 1)
    if (!prev) {
        /* inside = >= 128: 255 or 0 (fuse_colour_model_learn leaves any
         * other value out) */
        for (int y = 0; y < f->height; y++) {
            if (FIT_LEARN_ROW_SKIPPED(y)) continue;
            const uint8_t *a = mask + (size_t)y * (size_t)mask_stride;
            uint8_t *L = f->learn[eye] + (size_t)y * (size_t)f->width;
            int x = 0;
            for (; x + 8 <= f->width; x += 8) {
                const uint64_t r = ((fit_ld8(a + x) >> 7) & FIT_B01) * 0xFFu;
                memcpy(L + x, &r, 8);
            }
            for (; x < f->width; x++) L[x] = (uint8_t)(0u - (unsigned)(a[x] >> 7));
        }
    } else {
        /* 255 where both hold the pixel, 0 where neither does, else 128
         * (branch-free, so that the compiler vectorises the rows) */
        for (int y = 0; y < f->height; y++) {
            if (FIT_LEARN_ROW_SKIPPED(y)) continue;
            const uint8_t *a = mask + (size_t)y * (size_t)mask_stride;
            const uint8_t *b = prev + (size_t)y * (size_t)prev_stride;
            uint8_t *L = f->learn[eye] + (size_t)y * (size_t)f->width;
            int x = 0;
            /* 16 bytes a step (GCC/Clang vector extension, two 64-bit
             * lanes: the same bitwise expression as the 8-byte step) */
            for (; x + 16 <= f->width; x += 16) {
                fit_v2 va, vb;
                memcpy(&va, a + x, 16);
                memcpy(&vb, b + x, 16);
                const fit_v2 b01 = {FIT_B01, FIT_B01}, ones = {~0ull, ~0ull};
                const fit_v2 ia = (va >> 7) & b01, ib = (vb >> 7) & b01;
                const fit_v2 r = ((0x80u * b01) | ((ia & ib) * 0x7Fu)) &
                                 (((ia | ib) ^ b01) * 0xFFu ^ ones);
                memcpy(L + x, &r, 16);
            }
            for (; x + 8 <= f->width; x += 8) {
                /* per byte: 0x80, + 0x7f where both, 0 where neither */
                const uint64_t ia = (fit_ld8(a + x) >> 7) & FIT_B01, ib = (fit_ld8(b + x) >> 7) & FIT_B01;
                const uint64_t r = ((0x80u * FIT_B01) | ((ia & ib) * 0x7Fu)) &
                                   ~(((ia | ib) ^ FIT_B01) * 0xFFu);
                memcpy(L + x, &r, 8);
            }
            for (; x < f->width; x++) {
                unsigned ia = a[x] >> 7, ib = b[x] >> 7;
                L[x] = (uint8_t)(128u + 127u * (ia & ib) - 128u * ((ia | ib) ^ 1u));
            }
        }
    }
#undef FIT_LEARN_ROW_SKIPPED
    if (f->d.learn_memory > 0.0f) {
        fit_learn_memory(f, eye, P);
        return FUSE_OK;
    }
    fuse_result r = fuse_colour_model_learn(&f->cm[eye], P, learn, stride, 4, 2, 3.0f, 64,
                                            f->scratch[eye], f->scratch_size);
    if (r != FUSE_OK) return r;
    f->learned[eye] = f->cm[eye].fg_samples >= 64 && f->cm[eye].bg_samples >= 64;
    return FUSE_OK;
}

/* Swivel phi of side s's arm: its points turned about the
 * shoulder-wrist line through S (unit u). */
typedef struct fit_geo {
    kin_vec3 S;
    float R[9];               /* row-major rotation */
} fit_geo;

static void fit_geo_of(kin_vec3 S, kin_vec3 u, float phi, fit_geo *g)
{
    kin_quat q = kin_quat_axis_angle(u, phi);
    kin_vec3 ex = kin_quat_rotate(q, kin_v3(1, 0, 0)), ey = kin_quat_rotate(q, kin_v3(0, 1, 0)),
             ez = kin_quat_rotate(q, kin_v3(0, 0, 1));
    const float R[9] = { ex.x, ey.x, ez.x, ex.y, ey.y, ez.y, ex.z, ey.z, ez.z };
    memcpy(g->R, R, sizeof R);
    g->S = S;
}

/* Pixel of fit point i of side s moved by g, seen by eye e; 0 when it
 * falls outside the image or behind the camera. */
static int fit_pixel(const pipe_fit *f, int s, int i, const float *pos, const fit_geo *g,
                     const kin_camera *cam, int *px, int *py)
{
    const float *M = cam->view_proj.m;
    const float *p = &pos[(size_t)f->v[s][i] * 3], *R = g->R;
    const float dx = p[0] - g->S.x, dy = p[1] - g->S.y, dz = p[2] - g->S.z;
    kin_vec3 r = kin_v3(g->S.x + R[0] * dx + R[1] * dy + R[2] * dz,
                        g->S.y + R[3] * dx + R[4] * dy + R[5] * dz,
                        g->S.z + R[6] * dx + R[7] * dy + R[8] * dz);
    float w = M[3] * r.x + M[7] * r.y + M[11] * r.z + M[15];
    if (!(w > 1e-3f)) return 0;
    float x = (M[0] * r.x + M[4] * r.y + M[8] * r.z + M[12]) / w;
    float y = (M[1] * r.x + M[5] * r.y + M[9] * r.z + M[13]) / w;
    float fx = (x * 0.5f + 0.5f) * (float)f->width, fy = (0.5f - y * 0.5f) * (float)f->height;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)f->width && fy < (float)f->height)) return 0;
    *px = (int)fx;
    *py = (int)fy;
    return 1;
}

/* The points of side s that are in view of each eye in all n candidate
 * poses g (f->use[s]); returns their number. Only they are scored: a
 * point that leaves the image for some candidate is unknown there, and
 * scoring it in the others would favour or penalise candidates by what
 * leaves the view (dropping it where unseen, i.e. scoring it 0 there,
 * rewards pushing the arm out of view wherever the visible part scores
 * below 0; scoring it as an average arm pixel rewards it wherever the
 * visible part scores below that). */
static int fit_common(pipe_fit *f, int s, const float *pos, const fit_geo *g, int n,
                      const kin_camera cam[2])
{
    int count = 0;
    for (int e = 0; e < 2; e++)
        for (int i = 0; i < f->n[s]; i++) {
            int ok = 1, px, py;
            for (int k = 0; k < n && ok; k++) ok = fit_pixel(f, s, i, pos, &g[k], &cam[e], &px, &py);
            f->use[s][e * f->n[s] + i] = (uint8_t)ok;
            count += ok;
        }
    return count;
}

/* Colour score of side s's arm moved by g: the sum over both eyes of the
 * ratio at the pixel of each point in use (fit_common); a point that
 * still falls outside scores 0. */
static float fit_score(const pipe_fit *f, int s, const float *pos, const fit_geo *g,
                       const kin_camera cam[2], const fuse_image P[2])
{
    float score = 0.0f;
    for (int e = 0; e < 2; e++) {
        const float *llr = f->llr[e];
        const uint8_t *use = &f->use[s][e * f->n[s]];
        for (int i = 0; i < f->n[s]; i++) {
            int px, py;
            if (!use[i] || !fit_pixel(f, s, i, pos, g, &cam[e], &px, &py)) continue;
            const uint8_t *rgb = P[e].pixels + (size_t)py * (size_t)P[e].stride + (size_t)px * 4;
            score += llr[fuse_colour_bin(rgb, PIPE_FIT_BITS)];
        }
    }
    return score;
}

/* Turns the arm of side s by phi about its shoulder-wrist line in locals
 * (world = FK of locals; the hand keeps its world rotation). Turning the
 * upper arm's local by phi about u turns every node below it, the hand's
 * parent hp included, by phi about u in world space; the hand's local
 * then turns by -phi about u seen in hp's frame (the forearm, or a wrist
 * or twist node between them: pipe_fit_create checked the chain). */
static void fit_apply(const pipe_fit *f, const kin_mat4 *world, int s, float phi,
                      kin_transform *locals)
{
    const kin_model *m = f->model;
    int ua = f->rig.joint[s][KIN_RIG_UPPER_ARM], hd = f->rig.joint[s][KIN_RIG_HAND];
    kin_vec3 u = kin_v3_norm(kin_v3_sub(kin_mat4_translation(&world[hd]), kin_mat4_translation(&world[ua])));
    int par = m->parents[ua], hp = m->parents[hd];
    kin_quat qp = par >= 0 ? kin_mat4_rotation(&world[par]) : kin_quat_identity();
    kin_quat qf = kin_mat4_rotation(&world[hp]);
    kin_vec3 ap = kin_quat_rotate(kin_quat_conjugate(qp), u);
    kin_vec3 af = kin_quat_rotate(kin_quat_conjugate(qf), u);
    locals[ua].r = kin_quat_normalize(kin_quat_mul(kin_quat_axis_angle(ap, phi), locals[ua].r));
    locals[hd].r = kin_quat_normalize(kin_quat_mul(kin_quat_axis_angle(af, -phi), locals[hd].r));
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

/* The thickness factors from the widths measured so far: per side and
 * segment the median over both eyes once there are FIT_MIN_SAMPLES of
 * them; a segment is frozen once it has shape_samples (each eye keeps at
 * most that many: the eyes measure on their own threads), and measuring
 * stops when all four are. Runs while no eye measures. */
static void fit_update_shape(pipe_fit *f)
{
    if (f->frozen) return;
    int done = 0;
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            if (f->done[s][g]) { done++; continue; }
            int n = 0;
            for (int e = 0; e < 2; e++) {
                memcpy(f->sort + n, f->samples[e][s][g], sizeof(float) * (size_t)f->ns[e][s][g]);
                n += f->ns[e][s][g];
            }
            if (n < FIT_MIN_SAMPLES) continue;
            qsort(f->sort, (size_t)n, sizeof(float), cmp_float);
            f->thick[s][g] = n & 1 ? f->sort[n / 2] : 0.5f * (f->sort[n / 2 - 1] + f->sort[n / 2]);
            if (n >= f->d.shape_samples) {
                f->done[s][g] = 1;
                done++;
            }
        }
    f->frozen = done == 4;
}

void pipe_fit_elbows(pipe_fit *f, const kin_mat4 *world, const float *pos,
                     const kin_camera cam[2], const fuse_image P[2], unsigned sides,
                     kin_transform *locals, float swivel[2])
{
    const float D = FIT_DEG2RAD;
    float best[2];
    for (int s = 0; s < 2; s++) {
        int ua = f->rig.joint[s][KIN_RIG_UPPER_ARM], hd = f->rig.joint[s][KIN_RIG_HAND];
        kin_vec3 S = kin_mat4_translation(&world[ua]);
        kin_vec3 u = kin_v3_norm(kin_v3_sub(kin_mat4_translation(&world[hd]), S));
        const float range = f->d.range_deg * D, rate = f->d.rate_deg * D;
        float p0 = f->have_prev ? f->swivel[s] : 0.0f;
        float lo = f->have_prev ? p0 - rate : -range, hi = f->have_prev ? p0 + rate : range;
        if (lo < -range) lo = -range;
        if (hi > range) hi = range;
        float bphi = p0 < lo ? lo : p0 > hi ? hi : p0;
        const float pk = f->d.prior * 2.0f * (float)f->n[s] / (30.0f * 30.0f * D * D);
        /* the points in view over the whole window: at its ends and every
         * 30 degrees between (the projections move smoothly with phi) */
        fit_geo gw[FIT_WINDOW_GEOS];
        int nw = 0;
        for (float phi = lo; nw < FIT_WINDOW_GEOS - 1 && phi < hi; phi += 30.0f * D)
            fit_geo_of(S, u, phi, &gw[nw++]);
        fit_geo_of(S, u, hi, &gw[nw++]);
        fit_common(f, s, pos, gw, nw, cam);
        fit_geo g;
        fit_geo_of(S, u, bphi, &g);
        float bsc = fit_score(f, s, pos, &g, cam, P) - pk * bphi * bphi;
        for (int pass = 0; pass < 2; pass++) {
            float step = (pass ? 1.0f : f->d.step_deg) * D;
            float lo2 = pass ? bphi - 0.5f * f->d.step_deg * D : lo;
            float hi2 = pass ? bphi + 0.5f * f->d.step_deg * D : hi;
            /* The candidates of phi += step (bit for bit those of the
             * first version: `egofuse eval` and render --refine keep their
             * bytes), bounded by an index: phi += step alone never ended
             * for a step too small to move phi; with the desc's bounds
             * (step >= 0.1 deg) every addition moves it and at most
             * 2 * 180 / 0.1 + 2 candidates run. */
            const float span = (hi2 + 1e-6f - lo2) / step;
            const int nc = span >= 0.0f && span < 8192.0f ? (int)span + 1 : -1;
            float phi = lo2;
            for (int i = 0; i <= nc && phi <= hi2 + 1e-6f; i++, phi += step) {
                if (phi < lo || phi > hi) continue;
                fit_geo_of(S, u, phi, &g);
                float sc = fit_score(f, s, pos, &g, cam, P) - pk * phi * phi;
                if (sc > bsc) { bsc = sc; bphi = phi; }
            }
        }
        best[s] = bphi;
    }
    for (int s = 0; s < 2; s++) {
        if (!(sides & (1u << s))) continue;
        fit_apply(f, world, s, best[s], locals);
        f->swivel[s] = best[s];
    }
    f->have_prev = 1;
    fit_update_shape(f);
    if (swivel) {
        swivel[0] = best[0];
        swivel[1] = best[1];
    }
}

/* ------------------------------------------- limb thickness */

/* Pixel position of world point p through cam (width x height image);
 * 0 when behind the camera. */
static int fit_project(const kin_camera *cam, int W, int H, kin_vec3 p, float *x, float *y)
{
    const float *M = cam->view_proj.m;
    float w = M[3] * p.x + M[7] * p.y + M[11] * p.z + M[15];
    if (!(w > 1e-3f)) return 0;
    *x = ((M[0] * p.x + M[4] * p.y + M[8] * p.z + M[12]) / w * 0.5f + 0.5f) * (float)W;
    *y = (0.5f - (M[1] * p.x + M[5] * p.y + M[9] * p.z + M[13]) / w * 0.5f) * (float)H;
    return 1;
}

/* Steps from (x, y) along (dx, dy) while m is inside (>= 128); the
 * number of inside steps, or -1 when the walk reaches the image's
 * border or FIT_MAX_WALK (the edge is not seen). */
static int fit_walk(const uint8_t *m, int stride, int W, int H, float x, float y, float dx,
                    float dy)
{
    for (int k = 1; k <= FIT_MAX_WALK; k++) {
        float fx = x + dx * (float)k, fy = y + dy * (float)k;
        if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)W && fy < (float)H)) return -1;
        if (m[(size_t)(int)fy * (size_t)stride + (size_t)(int)fx] < 128) return k - 1;
    }
    return -1;
}

void pipe_fit_measure(pipe_fit *f, int eye, const kin_camera *cam, const kin_mat4 *world,
                      const uint8_t *mask, int mask_stride, const uint8_t *refined,
                      int refined_stride)
{
    if (!f || eye < 0 || eye > 1 || !cam || !world || !mask || !refined || f->frozen ||
        mask_stride < f->width || refined_stride < f->width)
        return;
    const int W = f->width, H = f->height;
    for (int s = 0; s < 2; s++)
        for (int g = 0; g < 2; g++) {
            if (f->done[s][g]) continue;
            int j0 = f->rig.joint[s][g ? KIN_RIG_FOREARM : KIN_RIG_UPPER_ARM];
            int j1 = f->rig.joint[s][g ? KIN_RIG_HAND : KIN_RIG_FOREARM];
            kin_vec3 A = kin_mat4_translation(&world[j0]), B = kin_mat4_translation(&world[j1]);
            float ax, ay, bx, by;
            if (!fit_project(cam, W, H, A, &ax, &ay) || !fit_project(cam, W, H, B, &bx, &by))
                continue;
            float len = sqrtf((bx - ax) * (bx - ax) + (by - ay) * (by - ay));
            if (len < 16.0f) continue;        /* seen end-on: no direction */
            float nx = -(by - ay) / len, ny = (bx - ax) / len;
            /* stations on the projected axis, over the part of its
             * [0.2, 0.9] (away from the joints where the limbs blend)
             * that is in view 8 px in from the borders; none when less
             * than 12 px of it is */
            float t0 = 0.2f, t1 = 0.9f;
            const float lim[2][2] = { { 8.0f, (float)W - 8.0f }, { 8.0f, (float)H - 8.0f } };
            const float a2[2] = { ax, ay }, d2[2] = { bx - ax, by - ay };
            for (int c = 0; c < 2 && t0 < t1; c++) {
                if (d2[c] == 0.0f) {
                    if (a2[c] < lim[c][0] || a2[c] > lim[c][1]) t1 = t0;
                    continue;
                }
                float u0 = (lim[c][0] - a2[c]) / d2[c], u1 = (lim[c][1] - a2[c]) / d2[c];
                if (u0 > u1) { float tmp = u0; u0 = u1; u1 = tmp; }
                if (u0 > t0) t0 = u0;
                if (u1 < t1) t1 = u1;
            }
            if ((t1 - t0) * len < 12.0f) continue;
            for (int k = 0; k < FIT_STATIONS; k++) {
                if (f->ns[eye][s][g] >= f->cap) break;
                float t = t0 + (t1 - t0) * ((float)k + 0.5f) / (float)FIT_STATIONS;
                float qx = ax + t * (bx - ax), qy = ay + t * (by - ay);
                if (!(qx >= 0.0f && qy >= 0.0f && qx < (float)W && qy < (float)H)) continue;
                size_t o = (size_t)(int)qy;
                if (mask[o * (size_t)mask_stride + (size_t)(int)qx] < 128 ||
                    refined[o * (size_t)refined_stride + (size_t)(int)qx] < 128)
                    continue;
                int k0 = fit_walk(mask, mask_stride, W, H, qx, qy, nx, ny);
                int k1 = fit_walk(mask, mask_stride, W, H, qx, qy, -nx, -ny);
                int r0 = fit_walk(refined, refined_stride, W, H, qx, qy, nx, ny);
                int r1 = fit_walk(refined, refined_stride, W, H, qx, qy, -nx, -ny);
                if (k0 < 0 || k1 < 0 || r0 < 0 || r1 < 0 || k0 + k1 < 6) continue;
                /* the kinematic width must be the limb's own: the model's
                 * radius (times the factor in use) projected at the
                 * station's depth, within 0.7-1.4x; wider walks ran into
                 * a hand or the other arm in front of or behind it */
                kin_vec3 Q = kin_v3_add(A, kin_v3_scale(kin_v3_sub(B, A), t));
                float z = -kin_mat4_mul_point(&cam->view, Q).z;
                if (!(z > 1e-3f) || !(f->radius[s][g] > 0.0f)) continue;
                float expect = 2.0f * f->radius[s][g] * f->thick[s][g] * cam->fx / z;
                float kw = (float)(k0 + k1 + 1);
                if (kw < 0.7f * expect || kw > 1.4f * expect) continue;
                /* only thinner counts: a refined mask narrower than the
                 * model's took pixels that look like background, a wider
                 * one may have taken a skin-coloured object beside the
                 * arm (egofuse eval's cross: the desk pad made a forearm
                 * 1.48x, IoU 0.893 -> 0.845). Clamped, not dropped, so
                 * that the median stays unbiased for a limb that fits. */
                float sample = f->thick[s][g] * (float)(r0 + r1 + 1) / kw;
                if (sample < 0.6f) continue;
                f->samples[eye][s][g][f->ns[eye][s][g]++] = sample < 1.0f ? sample : 1.0f;
            }
        }
}

void pipe_fit_shape(const pipe_fit *f, const kin_mat4 *world, float *pos)
{
    if (!f || !world || !pos) return;
    for (int s = 0; s < 2; s++) {
        float t0 = f->thick[s][0] - 1.0f, t1 = f->thick[s][1] - 1.0f;
        if (t0 == 0.0f && t1 == 0.0f) continue;
        kin_vec3 J[3];
        J[0] = kin_mat4_translation(&world[f->rig.joint[s][KIN_RIG_UPPER_ARM]]);
        J[1] = kin_mat4_translation(&world[f->rig.joint[s][KIN_RIG_FOREARM]]);
        J[2] = kin_mat4_translation(&world[f->rig.joint[s][KIN_RIG_HAND]]);
        kin_vec3 d[2] = { kin_v3_sub(J[1], J[0]), kin_v3_sub(J[2], J[1]) };
        float dd[2] = { kin_v3_dot(d[0], d[0]), kin_v3_dot(d[1], d[1]) };
        const float tk[2] = { t0, t1 };
        for (int i = 0; i < f->sn[s]; i++) {
            float *p = &pos[(size_t)f->sv[s][i] * 3];
            kin_vec3 P0 = kin_v3(p[0], p[1], p[2]), P1 = P0;
            for (int g = 0; g < 2; g++) {
                float w = f->sw[s][2 * i + g];
                if (w == 0.0f || tk[g] == 0.0f || !(dd[g] > 0.0f)) continue;
                /* radially away from the closest point of the bone */
                float a = kin_v3_dot(kin_v3_sub(P0, J[g]), d[g]) / dd[g];
                a = a < 0.0f ? 0.0f : a > 1.0f ? 1.0f : a;
                kin_vec3 c = kin_v3_add(J[g], kin_v3_scale(d[g], a));
                P1 = kin_v3_add(P1, kin_v3_scale(kin_v3_sub(P0, c), w * tk[g]));
            }
            p[0] = P1.x;
            p[1] = P1.y;
            p[2] = P1.z;
        }
    }
}

void pipe_fit_thickness(const pipe_fit *f, float thick[2][2], int *frozen)
{
    if (thick)
        for (int s = 0; s < 2; s++)
            for (int g = 0; g < 2; g++) thick[s][g] = f ? f->thick[s][g] : 1.0f;
    if (frozen) *frozen = f ? f->frozen : 0;
}
