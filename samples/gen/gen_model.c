/* gen_model.c - the skinned arm-and-hand model of the samples: skeleton
 * with adult proportions, surfaces as generalized cylinders (elliptical or
 * super-elliptical cross sections whose radii vary smoothly along a bone,
 * rounded caps), smooth normals from the surface, skin weights blended
 * across each joint. The rest (bind) pose holds both arms straight forward
 * (-Z), palms down; the animation (gen_anim.c) bends them. */
#include "gen.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define DEG(d) ((d) * (PI_F / 180.0f))

static const char *const joint_names[GEN_SIDE_JOINTS] = {
    "shoulder", "upper_arm", "forearm", "hand", "palm",
    "thumb_1", "thumb_2", "thumb_3",
    "index_1", "index_2", "index_3",
    "middle_1", "middle_2", "middle_3",
    "ring_1", "ring_2", "ring_3",
    "little_1", "little_2", "little_3",
};

const char *gen_joint_name(int side, int j, char *buf, size_t n)
{
    snprintf(buf, n, "%s%s", side ? "R_" : "L_", joint_names[j]);
    return buf;
}

/* ------------------------------------------------------------ proportions */

/* Finger k: 0 thumb, 1 index, 2 middle, 3 ring, 4 little. Values are for
 * the right hand (thumb on -X when the palm faces down); the left hand
 * mirrors x. Positions in the palm frame, lengths in metres. */
typedef struct finger_spec {
    float base[3];        /* first joint (CMC for the thumb, else MCP) */
    float yaw_deg;        /* splay about +Y (right hand) */
    float len[3];         /* segment lengths, the last one to the tip */
    float r_base, r_tip;  /* half widths; thickness is 0.85 of them */
} finger_spec;

static const finger_spec fingers[5] = {
    { { -0.021f, -0.011f, -0.004f }, 0.0f, { 0.046f, 0.032f, 0.029f }, 0.0135f, 0.0090f },
    { { -0.027f, 0.0f, -0.067f }, 5.0f, { 0.040f, 0.024f, 0.021f }, 0.0095f, 0.0073f },
    { { -0.008f, 0.0f, -0.070f }, 0.5f, { 0.045f, 0.028f, 0.022f }, 0.0098f, 0.0076f },
    { { 0.010f, 0.0f, -0.066f }, -4.0f, { 0.042f, 0.027f, 0.021f }, 0.0092f, 0.0071f },
    { { 0.027f, -0.001f, -0.059f }, -9.0f, { 0.033f, 0.020f, 0.019f }, 0.0080f, 0.0063f },
};

#define UPPER_ARM_LEN 0.30f
#define FOREARM_LEN 0.26f
#define WRIST_TO_PALM 0.03f

/* The thumb's rest direction and nail side (right hand, palm frame). */
static kin_quat thumb_rest_rotation(float s)
{
    kin_vec3 d = kin_v3_norm(kin_v3(-0.55f * s, -0.33f, -0.77f));
    kin_vec3 z = kin_v3_scale(d, -1.0f);
    kin_vec3 yh = kin_v3_norm(kin_v3(-0.75f * s, 0.65f, 0.0f));
    kin_vec3 x = kin_v3_norm(kin_v3_cross(yh, z));
    kin_vec3 y = kin_v3_cross(z, x);
    return kin_quat_from_axes(x, y, z);
}

/* ---------------------------------------------------------------- builder */

#define MAX_NODES 48
#define MAX_VERTS 16384
#define MAX_TRIS 24576

typedef struct builder {
    int node_count;
    char names[MAX_NODES][KIN_NAME_MAX];
    int16_t parents[MAX_NODES];
    kin_transform rest[MAX_NODES];
    kin_mat4 bind[MAX_NODES];          /* world matrices of the rest pose */
    int vcount, tcount;
    float *pos, *nrm, *w, *albedo, *uv;
    uint16_t *jnt;
    uint32_t *idx;
} builder;

static int add_node(builder *b, const char *name, int parent, kin_vec3 t,
                    kin_quat r)
{
    int i = b->node_count++;
    snprintf(b->names[i], KIN_NAME_MAX, "%s", name);
    b->parents[i] = (int16_t)parent;
    b->rest[i].t = t;
    b->rest[i].r = r;
    b->rest[i].s = kin_v3(1.0f, 1.0f, 1.0f);
    return i;
}

/* Radius profile key: at axial position s (metres along the bone's -Z),
 * half width rx, half thickness ry, centre offset oy (along local +Y). */
typedef struct prof_key { float s, rx, ry, oy; } prof_key;

/* A joint span of a tube: vertices with s < until belong to joint (skin
 * index); across `until` the weight blends to the next span over +-blend. */
typedef struct span { int joint; float until, blend; } span;

typedef struct tube {
    int bone;                 /* node whose bind frame carries the tube */
    const prof_key *prof;
    int prof_count;
    const span *spans;
    int span_count;
    int around, along;        /* ring vertices; rings along the body */
    int cap_rings;            /* rings in each rounded cap */
    float cap0, cap1;         /* cap depth as a fraction of the end radius */
    float squareness;         /* super-ellipse exponent: 2 = ellipse */
    float square2, square2_from, square2_to; /* blends to square2 over
                                 [from, to] when to > from (else none) */
    float albedo[3], albedo2[3];
    float albedo2_from;       /* s from which albedo2 applies (or > length) */
    gen_pattern pat, pat2;
} tube;

static float smooth01(float x)
{
    if (x <= 0.0f) return 0.0f;
    if (x >= 1.0f) return 1.0f;
    return x * x * (3.0f - 2.0f * x);
}

static prof_key profile_at(const tube *tb, float s)
{
    const prof_key *p = tb->prof;
    int n = tb->prof_count;
    if (s <= p[0].s) return p[0];
    if (s >= p[n - 1].s) return p[n - 1];
    int i = 0;
    while (i + 1 < n && p[i + 1].s < s) i++;
    float u = smooth01((s - p[i].s) / (p[i + 1].s - p[i].s));
    prof_key k;
    k.s = s;
    k.rx = p[i].rx + (p[i + 1].rx - p[i].rx) * u;
    k.ry = p[i].ry + (p[i + 1].ry - p[i].ry) * u;
    k.oy = p[i].oy + (p[i + 1].oy - p[i].oy) * u;
    return k;
}

static void span_weights(const tube *tb, float s, int j[2], float w[2])
{
    int k = 0;
    while (k + 1 < tb->span_count && s > tb->spans[k].until + tb->spans[k].blend)
        k++;
    j[0] = tb->spans[k].joint;
    j[1] = j[0];
    w[0] = 1.0f;
    w[1] = 0.0f;
    if (k + 1 < tb->span_count) {
        float b = tb->spans[k].blend, e = tb->spans[k].until;
        float u = smooth01((s - (e - b)) / (2.0f * b));
        if (u > 0.0f) {
            j[1] = tb->spans[k + 1].joint;
            w[0] = 1.0f - u;
            w[1] = u;
        }
    }
}

static float sgnpow(float v, float e)
{
    float a = powf(fabsf(v), e);
    return v < 0.0f ? -a : a;
}

static int emit_vertex(builder *b, const tube *tb, float s, float phi,
                       float scale)
{
    if (b->vcount >= MAX_VERTS) return -1;
    prof_key k = profile_at(tb, s);
    float sq = tb->squareness;
    if (tb->square2_to > tb->square2_from)
        sq += (tb->square2 - sq) *
              smooth01((s - tb->square2_from) / (tb->square2_to - tb->square2_from));
    float e = 2.0f / sq;
    float c = sgnpow(cosf(phi), e), sn = sgnpow(sinf(phi), e);
    kin_vec3 lp = kin_v3(k.rx * scale * c, k.oy + k.ry * scale * sn, -s);
    kin_vec3 wp = kin_mat4_mul_point(&b->bind[tb->bone], lp);
    int v = b->vcount++;
    b->pos[v * 3 + 0] = wp.x;
    b->pos[v * 3 + 1] = wp.y;
    b->pos[v * 3 + 2] = wp.z;
    int j[2];
    float w[2];
    span_weights(tb, s, j, w);
    b->jnt[v * 4 + 0] = (uint16_t)j[0];
    b->jnt[v * 4 + 1] = (uint16_t)j[1];
    b->jnt[v * 4 + 2] = 0;
    b->jnt[v * 4 + 3] = 0;
    b->w[v * 4 + 0] = w[0];
    b->w[v * 4 + 1] = w[1];
    b->w[v * 4 + 2] = 0.0f;
    b->w[v * 4 + 3] = 0.0f;
    int second = s >= tb->albedo2_from;
    const float *al = second ? tb->albedo2 : tb->albedo;
    gen_pattern pat = second ? tb->pat2 : tb->pat;
    for (int i = 0; i < 3; i++) b->albedo[v * 3 + i] = al[i];
    /* surface coordinates: along the bone and around it, in metres */
    float circ = phi * 0.5f * (k.rx + k.ry);
    b->uv[v * 2 + 0] = (float)pat * GEN_PATTERN_STRIDE + s +
                         0.5f * (float)(tb->bone % 16);
    b->uv[v * 2 + 1] = circ;
    return v;
}

static int emit_tri(builder *b, int a, int c, int d)
{
    if (b->tcount >= MAX_TRIS) return -1;
    uint32_t *t = &b->idx[b->tcount++ * 3];
    t[0] = (uint32_t)a;
    t[1] = (uint32_t)c;
    t[2] = (uint32_t)d;
    return 0;
}

/* Emits a closed tube: pole, cap rings, body rings, cap rings, pole.
 * Triangles wind counter-clockwise seen from outside. */
static int emit_tube(builder *b, const tube *tb)
{
    float s0 = tb->prof[0].s, s1 = tb->prof[tb->prof_count - 1].s;
    prof_key k0 = tb->prof[0], k1 = tb->prof[tb->prof_count - 1];
    float c0 = tb->cap0 * fminf(k0.rx, k0.ry);
    float c1 = tb->cap1 * fminf(k1.rx, k1.ry);
    int n = tb->around;
    /* ring list: (s, scale) */
    int rings = 2 * tb->cap_rings + tb->along + 1;
    int first_vertex = b->vcount;
    int pole0 = emit_vertex(b, tb, s0 - c0, 0.0f, 0.0f);
    if (pole0 < 0) return -1;
    for (int r = 0; r < rings; r++) {
        float s, scale;
        if (r < tb->cap_rings) {
            float th = 0.5f * PI_F * (float)(r + 1) / (float)(tb->cap_rings + 1);
            s = s0 - c0 * cosf(th);
            scale = sinf(th);
        } else if (r < tb->cap_rings + tb->along + 1) {
            float u = (float)(r - tb->cap_rings) / (float)tb->along;
            s = s0 + (s1 - s0) * u;
            scale = 1.0f;
        } else {
            int q = r - tb->cap_rings - tb->along - 1;
            float th = 0.5f * PI_F * (float)(tb->cap_rings - q) / (float)(tb->cap_rings + 1);
            s = s1 + c1 * cosf(th);
            scale = sinf(th);
        }
        for (int i = 0; i < n; i++) {
            float phi = 2.0f * PI_F * (float)i / (float)n;
            if (emit_vertex(b, tb, s, phi, scale) < 0) return -1;
        }
    }
    int pole1 = emit_vertex(b, tb, s1 + c1, 0.0f, 0.0f);
    if (pole1 < 0) return -1;
    /* Local frame: x = width (cos), y = thickness (sin), the axis runs to
     * -Z, so increasing phi turns counter-clockwise seen from the start cap
     * (looking down -Z from +Z). */
    int ring0 = first_vertex + 1;
    for (int i = 0; i < n; i++) {
        int a = ring0 + i, c = ring0 + (i + 1) % n;
        if (emit_tri(b, pole0, c, a) < 0) return -1;
    }
    for (int r = 0; r + 1 < rings; r++) {
        int base = ring0 + r * n, next = base + n;
        for (int i = 0; i < n; i++) {
            int i1 = (i + 1) % n;
            if (emit_tri(b, base + i, base + i1, next + i) < 0) return -1;
            if (emit_tri(b, base + i1, next + i1, next + i) < 0) return -1;
        }
    }
    int last = ring0 + (rings - 1) * n;
    for (int i = 0; i < n; i++) {
        int a = last + i, c = last + (i + 1) % n;
        if (emit_tri(b, a, c, pole1) < 0) return -1;
    }
    return 0;
}

/* Area-weighted vertex normals from the faces; then flips the winding of
 * the whole mesh if it points inward (it must not, but the check keeps
 * the normals outward whatever the tube code does). */
static void compute_normals(builder *b, int t_begin, int t_end, int v_begin,
                            int v_end)
{
    for (int v = v_begin; v < v_end; v++)
        b->nrm[v * 3 + 0] = b->nrm[v * 3 + 1] = b->nrm[v * 3 + 2] = 0.0f;
    for (int t = t_begin; t < t_end; t++) {
        const uint32_t *ix = &b->idx[t * 3];
        const float *p0 = &b->pos[ix[0] * 3], *p1 = &b->pos[ix[1] * 3],
                    *p2 = &b->pos[ix[2] * 3];
        kin_vec3 e1 = kin_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
        kin_vec3 e2 = kin_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
        kin_vec3 fn = kin_v3_cross(e1, e2);   /* |fn| = 2 area */
        for (int k = 0; k < 3; k++) {
            b->nrm[ix[k] * 3 + 0] += fn.x;
            b->nrm[ix[k] * 3 + 1] += fn.y;
            b->nrm[ix[k] * 3 + 2] += fn.z;
        }
    }
    /* orientation: the normals must point away from the part's centroid */
    double cx = 0, cy = 0, cz = 0, out = 0;
    for (int v = v_begin; v < v_end; v++) {
        cx += b->pos[v * 3 + 0];
        cy += b->pos[v * 3 + 1];
        cz += b->pos[v * 3 + 2];
    }
    double inv = 1.0 / (double)(v_end - v_begin);
    cx *= inv; cy *= inv; cz *= inv;
    for (int v = v_begin; v < v_end; v++)
        out += (b->pos[v * 3 + 0] - cx) * b->nrm[v * 3 + 0] +
               (b->pos[v * 3 + 1] - cy) * b->nrm[v * 3 + 1] +
               (b->pos[v * 3 + 2] - cz) * b->nrm[v * 3 + 2];
    float sign = out < 0.0 ? -1.0f : 1.0f;
    if (sign < 0.0f)
        for (int t = t_begin; t < t_end; t++) {
            uint32_t tmp = b->idx[t * 3 + 1];
            b->idx[t * 3 + 1] = b->idx[t * 3 + 2];
            b->idx[t * 3 + 2] = tmp;
        }
    for (int v = v_begin; v < v_end; v++) {
        kin_vec3 nn = kin_v3_norm(kin_v3(sign * b->nrm[v * 3 + 0],
                                         sign * b->nrm[v * 3 + 1],
                                         sign * b->nrm[v * 3 + 2]));
        if (nn.x == 0.0f && nn.y == 0.0f && nn.z == 0.0f) nn = kin_v3(0, 1, 0);
        b->nrm[v * 3 + 0] = nn.x;
        b->nrm[v * 3 + 1] = nn.y;
        b->nrm[v * 3 + 2] = nn.z;
    }
}

static int emit_part(builder *b, const tube *tb)
{
    int t0 = b->tcount, v0 = b->vcount;
    if (emit_tube(b, tb) < 0) return -1;
    compute_normals(b, t0, b->tcount, v0, b->vcount);
    return 0;
}

static const float skin_rgb[3] = { 0.86f, 0.63f, 0.52f };
static const float sleeve_rgb[3] = { 0.20f, 0.26f, 0.38f };

/* ------------------------------------------------------------- skeleton */

static void build_skeleton(builder *b, gen_arms *a)
{
    /* body: between the shoulders, seated; head: midpoint of the eyes,
     * 0.25 m above the shoulders and 8 cm in front of them. */
    a->body = add_node(b, "body", KIN_NO_PARENT, kin_v3(0.0f, 1.0f, 0.0f),
                       kin_quat_identity());
    a->head = add_node(b, "head", a->body, kin_v3(0.0f, 0.25f, -0.08f),
                       kin_quat_identity());
    char name[KIN_NAME_MAX];
    for (int side = 0; side < 2; side++) {
        float s = side ? 1.0f : -1.0f;
        int *J = a->joint[side];
        kin_quat id = kin_quat_identity();
        J[GEN_J_SHOULDER] = add_node(b, gen_joint_name(side, GEN_J_SHOULDER, name, sizeof name),
                                     a->body, kin_v3(0.035f * s, -0.015f, 0.0f), id);
        J[GEN_J_UPPER_ARM] = add_node(b, gen_joint_name(side, GEN_J_UPPER_ARM, name, sizeof name),
                                      J[GEN_J_SHOULDER], kin_v3(0.155f * s, -0.015f, 0.0f), id);
        J[GEN_J_FOREARM] = add_node(b, gen_joint_name(side, GEN_J_FOREARM, name, sizeof name),
                                    J[GEN_J_UPPER_ARM], kin_v3(0.0f, 0.0f, -UPPER_ARM_LEN), id);
        J[GEN_J_HAND] = add_node(b, gen_joint_name(side, GEN_J_HAND, name, sizeof name),
                                 J[GEN_J_FOREARM], kin_v3(0.0f, 0.0f, -FOREARM_LEN), id);
        J[GEN_J_PALM] = add_node(b, gen_joint_name(side, GEN_J_PALM, name, sizeof name),
                                 J[GEN_J_HAND], kin_v3(0.0f, 0.0f, -WRIST_TO_PALM), id);
        for (int f = 0; f < 5; f++) {
            const finger_spec *fs = &fingers[f];
            int j1 = GEN_J_THUMB_1 + 3 * f;
            kin_quat r1 = f == 0 ? thumb_rest_rotation(s)
                                 : kin_quat_axis_angle(kin_v3(0, 1, 0), DEG(fs->yaw_deg * s));
            J[j1] = add_node(b, gen_joint_name(side, j1, name, sizeof name), J[GEN_J_PALM],
                             kin_v3(fs->base[0] * s, fs->base[1], fs->base[2]), r1);
            J[j1 + 1] = add_node(b, gen_joint_name(side, j1 + 1, name, sizeof name), J[j1],
                                 kin_v3(0.0f, 0.0f, -fs->len[0]), id);
            J[j1 + 2] = add_node(b, gen_joint_name(side, j1 + 2, name, sizeof name), J[j1 + 1],
                                 kin_v3(0.0f, 0.0f, -fs->len[1]), id);
        }
    }
    a->mesh_node = add_node(b, "arms", KIN_NO_PARENT, kin_v3(0, 0, 0),
                            kin_quat_identity());
    /* bind pose world matrices (parents come first) */
    for (int i = 0; i < b->node_count; i++) {
        kin_mat4 l = kin_mat4_from_transform(&b->rest[i]);
        b->bind[i] = b->parents[i] == KIN_NO_PARENT
                         ? l
                         : kin_mat4_mul(&b->bind[b->parents[i]], &l);
    }
}

/* Skin joint index of a node: the skin lists every node but the mesh node,
 * in node order, so it is the node index itself. */
static int emit_side(builder *b, const gen_arms *a, int side)
{
    const int *J = a->joint[side];
    /* arm and palm: one surface from the shoulder ball over the wrist to
     * the knuckles, along the upper arm's axis. (Two parts, a forearm
     * running into a palm that started inside it, gave the wrist two
     * crossing surfaces with their own normals: a shading seam with a
     * staircase boundary, issue 14.) The wrist is at s = 0.56, the palm's
     * profile follows from s = 0.58 and the cross section turns from an
     * ellipse into the palm's boxy super-ellipse between them. The
     * knuckle end is capped at 0.4 of its radius: a rounder end (0.8)
     * came out between the finger tubes' bases at a shallow angle, and
     * the depth test took one surface or the other pixel by pixel there,
     * a dotted dark line along the index finger's base (frames 0, 140
     * and 179 of the samples, both eyes). */
    static const prof_key arm_prof[] = {
        { -0.040f, 0.046f, 0.048f, 0.004f },
        { 0.000f, 0.053f, 0.055f, 0.004f },
        { 0.070f, 0.050f, 0.050f, 0.000f },
        { 0.150f, 0.045f, 0.046f, 0.002f },
        { 0.250f, 0.039f, 0.040f, 0.000f },
        { 0.300f, 0.040f, 0.038f, 0.000f },
        { 0.360f, 0.043f, 0.039f, -0.002f },
        { 0.450f, 0.035f, 0.029f, 0.000f },
        { 0.540f, 0.029f, 0.020f, 0.000f },
        { 0.565f, 0.029f, 0.0190f, -0.001f },   /* wrist */
        { 0.580f, 0.033f, 0.0190f, -0.002f },   /* the palm: its old */
        { 0.610f, 0.040f, 0.017f, -0.003f },    /* profile from 0.02 */
        { 0.645f, 0.043f, 0.0145f, -0.002f },   /* past the wrist */
        { 0.663f, 0.041f, 0.0135f, -0.001f },
    };
    const span arm_spans[] = {
        { J[GEN_J_UPPER_ARM], UPPER_ARM_LEN, 0.045f },
        { J[GEN_J_FOREARM], UPPER_ARM_LEN + FOREARM_LEN, 0.018f },
        { J[GEN_J_HAND], UPPER_ARM_LEN + FOREARM_LEN + WRIST_TO_PALM - 0.005f, 0.015f },
        { J[GEN_J_PALM], 10.0f, 0.01f },
    };
    tube arm = {
        .bone = J[GEN_J_UPPER_ARM], .prof = arm_prof, .prof_count = 14,
        .spans = arm_spans, .span_count = 4, .around = 28, .along = 84,
        .cap_rings = 5, .cap0 = 0.9f, .cap1 = 0.4f, .squareness = 2.0f,
        .square2 = 2.8f, .square2_from = 0.555f, .square2_to = 0.59f,
        .albedo = { sleeve_rgb[0], sleeve_rgb[1], sleeve_rgb[2] },
        .albedo2 = { skin_rgb[0], skin_rgb[1], skin_rgb[2] },
        .albedo2_from = 0.47f, .pat = GEN_PAT_FABRIC, .pat2 = GEN_PAT_SKIN,
    };
    if (emit_part(b, &arm) < 0) return -1;

    for (int f = 0; f < 5; f++) {
        const finger_spec *fs = &fingers[f];
        int j1 = GEN_J_THUMB_1 + 3 * f;
        float l0 = fs->len[0], l1 = l0 + fs->len[1], l2 = l1 + fs->len[2];
        float rb = fs->r_base, rt = fs->r_tip, rm = 0.5f * (rb + rt);
        float start = f == 0 ? -0.012f : -0.014f;
        prof_key fp[6] = {
            { start, rb * 1.05f, rb * 0.85f, 0.0f },
            { 0.35f * l0, rb, rb * 0.85f, 0.0f },
            { l0, rb * 0.97f, rb * 0.86f, 0.0f },       /* knuckle */
            { l1, rm * 1.02f, rm * 0.88f, 0.0f },
            { l2 - 0.6f * rt, rt, rt * 0.85f, -0.0008f }, /* pad */
            { l2 - 0.5f * rt, rt * 0.98f, rt * 0.84f, -0.0008f },
        };
        if (f == 0) {   /* thenar eminence: thick base, fading out */
            fp[0].rx = rb * 1.25f; fp[0].ry = rb * 1.15f; fp[0].oy = -0.002f;
            fp[1].rx = rb * 1.15f; fp[1].ry = rb * 1.05f; fp[1].oy = -0.002f;
        }
        const span fsp[] = {
            { J[GEN_J_PALM], f == 0 ? 0.004f : 0.0f, f == 0 ? 0.012f : 0.008f },
            { J[j1], l0, 0.007f },
            { J[j1 + 1], l1, 0.0055f },
            { J[j1 + 2], 10.0f, 0.01f },
        };
        tube ft = {
            .bone = J[j1], .prof = fp, .prof_count = 6, .spans = fsp,
            .span_count = 4, .around = 14, .along = 20, .cap_rings = 3,
            .cap0 = 0.8f, .cap1 = 0.9f, .squareness = 2.0f,
            .albedo = { skin_rgb[0], skin_rgb[1], skin_rgb[2] },
            .albedo2_from = 10.0f, .pat = GEN_PAT_SKIN,
        };
        if (emit_part(b, &ft) < 0) return -1;
    }
    return 0;
}

/* ----------------------------------------------------------------- model */

void gen_arms_free(gen_arms *a)
{
    kin_model_free(&a->model);
    memset(a, 0, sizeof *a);
}

#define ALLOC(ptr, n)                                                      \
    do {                                                                   \
        (ptr) = kin_block_alloc(&m->block, sizeof(*(ptr)) * (size_t)(n));  \
        if (!(ptr)) goto oom;                                              \
    } while (0)

int gen_model_skin(kin_model *m, int joint_count, const int *joints, const kin_mat4 *bind)
{
    kin_skin *skin;
    int *jn;
    kin_mat4 *ibm;
    ALLOC(skin, 1);
    ALLOC(jn, joint_count);
    ALLOC(ibm, joint_count);
    for (int j = 0; j < joint_count; j++) {
        jn[j] = joints ? joints[j] : j;
        if (!kin_mat4_inverse(&bind[jn[j]], &ibm[j])) return -1;
    }
    skin->joint_count = joint_count;
    skin->joints = jn;
    skin->inverse_bind = ibm;
    m->skin_count = 1;
    m->skins = skin;
    return 0;
oom:
    return -1;
}

int gen_model_mesh(kin_model *m, int nv, float *pos, float *nrm, uint16_t *jnt, float *w,
                   int nt, uint32_t *idx, int node)
{
    kin_mesh *mesh;
    ALLOC(mesh, 1);
    mesh->vertex_count = nv;
    mesh->positions = pos;
    mesh->normals = nrm;
    mesh->joints = jnt;
    mesh->weights = w;
    mesh->index_count = nt * 3;
    mesh->indices = idx;
    mesh->node = node;
    mesh->skin = 0;
    m->mesh_count = 1;
    m->meshes = mesh;
    return 0;
oom:
    return -1;
}

int gen_arms_build(gen_arms *a)
{
    memset(a, 0, sizeof *a);
    kin_model *m = &a->model;
    builder *b = calloc(1, sizeof *b);
    if (!b) return -1;
    ALLOC(b->pos, MAX_VERTS * 3);
    ALLOC(b->nrm, MAX_VERTS * 3);
    ALLOC(b->w, MAX_VERTS * 4);
    ALLOC(b->jnt, MAX_VERTS * 4);
    ALLOC(b->albedo, MAX_VERTS * 3);
    ALLOC(b->uv, MAX_VERTS * 2);
    ALLOC(b->idx, MAX_TRIS * 3);

    build_skeleton(b, a);
    for (int side = 0; side < 2; side++)
        if (emit_side(b, a, side) < 0) goto oom;

    /* nodes */
    int16_t *parents;
    kin_transform *rest;
    char (*names)[KIN_NAME_MAX];
    int *src;
    ALLOC(parents, b->node_count);
    ALLOC(rest, b->node_count);
    ALLOC(names, b->node_count);
    ALLOC(src, b->node_count);
    for (int i = 0; i < b->node_count; i++) {
        parents[i] = b->parents[i];
        rest[i] = b->rest[i];
        memcpy(names[i], b->names[i], KIN_NAME_MAX);
        src[i] = i;
    }
    m->node_count = b->node_count;
    m->parents = parents;
    m->rest = rest;
    m->names = (const char (*)[KIN_NAME_MAX])names;
    m->node_src = src;

    /* skin: every node except the mesh node (which comes last) */
    if (gen_model_skin(m, b->node_count - 1, NULL, b->bind) < 0) goto oom;

    /* mesh: trimmed copies are not needed, the builder arrays are owned by
     * the block already */
    if (gen_model_mesh(m, b->vcount, b->pos, b->nrm, b->jnt, b->w, b->tcount, b->idx,
                       a->mesh_node) < 0)
        goto oom;
    a->albedo = b->albedo;
    a->uv = b->uv;
    free(b);
    b = NULL;

    if (gen_anim_build(a) < 0) goto oom;
    return 0;
oom:
    free(b);
    gen_arms_free(a);
    return -1;
}
