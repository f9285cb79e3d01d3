/* pipe_parts.c - what the operator sees of the real cockpit: the parts of
 * the arm model a frame hides and the props (pipe.h, "the operator's
 * cockpit"; internal interface in pipe_parts.h). */
#include "pipe_parts.h"
#include "../cpu/ef_mem.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------- node names */

enum { ROLE_NONE = 0, ROLE_SHOULDER, ROLE_UPPER, ROLE_FORE, ROLE_HAND };

static int ends_with(const char *s, size_t n, const char *suffix)
{
    size_t k = strlen(suffix);
    return n >= k && memcmp(s + n - k, suffix, k) == 0;
}

/* Side (0 left, 1 right, -1 none) and role of a node name. The name is cut
 * into words at non-alphanumerics, lower-to-upper case changes ("LeftArm"),
 * an upper-case run before a capitalised word ("LUpArm") and letter/digit
 * changes ("Bip01"); a word "l"/"left" or "r"/"right" gives the side; the
 * other words without the all-digit ones, joined, give the role by their
 * ending: "forearm"/"lowerarm" forearm, "upperarm"/"uparm"/"arm" upper arm,
 * "hand"/"wrist" hand, "shoulder"/"clavicle"/"collar" shoulder.
 * arm_word: one of the words is "arm" (for numbered chains, see below). */
static void name_role(const char *name, int *side, int *role, int *arm_word)
{
    char joined[KIN_NAME_MAX * 2];
    size_t jn = 0;
    int left = 0, right = 0;
    *arm_word = 0;
    size_t n = strnlen(name, KIN_NAME_MAX);
    size_t i = 0;
    while (i < n) {
        while (i < n && !isalnum((unsigned char)name[i])) i++;
        if (i >= n) break;
        size_t b = i;
        i++;
        while (i < n && isalnum((unsigned char)name[i])) {
            unsigned char p = (unsigned char)name[i - 1], c = (unsigned char)name[i];
            if (isdigit(p) != isdigit(c)) break;                 /* Bip|01 */
            if (islower(p) && isupper(c)) break;                 /* Left|Arm */
            if (isupper(p) && isupper(c) && i + 1 < n && islower((unsigned char)name[i + 1]))
                break;                                           /* L|UpArm */
            i++;
        }
        char w[KIN_NAME_MAX];
        size_t wl = i - b;
        int digits = 1;
        for (size_t k = 0; k < wl; k++) {
            w[k] = (char)tolower((unsigned char)name[b + k]);
            if (!isdigit((unsigned char)w[k])) digits = 0;
        }
        w[wl] = '\0';
        if (!strcmp(w, "l") || !strcmp(w, "left")) { left = 1; continue; }
        if (!strcmp(w, "r") || !strcmp(w, "right")) { right = 1; continue; }
        if (digits) continue;
        if (!strcmp(w, "arm")) *arm_word = 1;
        if (jn + wl < sizeof joined) {
            memcpy(joined + jn, w, wl);
            jn += wl;
        }
    }
    *side = left == right ? -1 : left ? 0 : 1;
    if (ends_with(joined, jn, "forearm") || ends_with(joined, jn, "lowerarm")) *role = ROLE_FORE;
    else if (ends_with(joined, jn, "arm")) *role = ROLE_UPPER; /* upperarm, uparm, arm */
    else if (ends_with(joined, jn, "hand") || ends_with(joined, jn, "wrist")) *role = ROLE_HAND;
    else if (ends_with(joined, jn, "shoulder") || ends_with(joined, jn, "clavicle") ||
             ends_with(joined, jn, "collar"))
        *role = ROLE_SHOULDER;
    else *role = ROLE_NONE;
}

unsigned pipe_parts_of_nodes(const kin_model *model, const kin_arm_rig *rig,
                             unsigned char *part)
{
    if (!model || !part || model->node_count < 1) return 0;
    const int n = model->node_count;
    /* role per node: 0 none, else ROLE_* | side << 3 */
    unsigned char *role = calloc((size_t)n, 1);
    if (!role) return 0;
    unsigned char *armw = calloc((size_t)n, 1);
    if (!armw) {
        free(role);
        return 0;
    }
    int named[2] = {0, 0};
    for (int i = 0; i < n && model->names; i++) {
        int side, r, aw;
        name_role(model->names[i], &side, &r, &aw);
        if (side >= 0 && r != ROLE_NONE) {
            role[i] = (unsigned char)(r | side << 3);
            if (r != ROLE_SHOULDER) named[side] = 1;
        }
        if (side >= 0 && aw) armw[i] = (unsigned char)(1 + side);
    }
    /* A side without named roles but a chain of numbered "arm" nodes
     * ("arm_joint_L_1" .. "_3", as in Khronos' RiggedFigure and
     * CesiumMan): the nodes of the chain that have no "arm" node of the
     * side below them are the hand (the wrist), the others the arm. */
    for (int i = n - 1; i >= 0; i--) {
        if (!armw[i] || named[armw[i] - 1] || role[i]) continue;
        int side = armw[i] - 1, below = 0;
        for (int j = i + 1; j < n && !below; j++)
            for (int a = model->parents[j]; a >= 0 && a < j; a = model->parents[a])
                if (a == i) {
                    below = armw[j] == armw[i];
                    break;
                }
        role[i] = (unsigned char)((below ? ROLE_UPPER : ROLE_HAND) | side << 3);
    }
    free(armw);
    if (rig) {
        static const int rj[4] = {KIN_RIG_SHOULDER, KIN_RIG_UPPER_ARM, KIN_RIG_FOREARM,
                                  KIN_RIG_HAND};
        static const int rr[4] = {ROLE_SHOULDER, ROLE_UPPER, ROLE_FORE, ROLE_HAND};
        for (int s = 0; s < 2; s++)
            for (int k = 0; k < 4; k++) {
                int j = rig->joint[s][rj[k]];
                if (j >= 0 && j < n) role[j] = (unsigned char)(rr[k] | s << 3);
            }
    }
    /* Parents come first: a node takes its own role's part, else its
     * parent's when that passes down (a shoulder's does not). */
    unsigned char *down = calloc((size_t)n, 1);
    unsigned found = 0;
    if (!down) {
        free(role);
        return 0;
    }
    for (int i = 0; i < n; i++) {
        int r = role[i] & 7, s = role[i] >> 3;
        unsigned bit = 0;
        int passes = 0;
        if (r == ROLE_HAND) bit = s ? PIPE_PART_HAND_R : PIPE_PART_HAND_L, passes = 1;
        else if (r == ROLE_UPPER || r == ROLE_FORE) {
            int pa = model->parents[i];
            /* an arm joint below a hand stays in the hand */
            if (pa >= 0 && pa < i && down[pa] && (part[pa] & (PIPE_PART_HAND_L | PIPE_PART_HAND_R)))
                bit = part[pa];
            else bit = s ? PIPE_PART_ARM_R : PIPE_PART_ARM_L;
            passes = 1;
        } else if (r == ROLE_SHOULDER) {
            bit = s ? PIPE_PART_ARM_R : PIPE_PART_ARM_L;
        } else {
            int pa = model->parents[i];
            if (pa >= 0 && pa < i && down[pa]) bit = part[pa], passes = 1;
        }
        part[i] = (unsigned char)bit;
        down[i] = (unsigned char)passes;
        found |= bit;
    }
    free(down);
    free(role);
    return found;
}

int pipe_parts_parse(const char *list, unsigned *bits, char *why, int why_size)
{
    static const struct { const char *name; unsigned bits; } names[] = {
        {"left-hand", PIPE_PART_HAND_L}, {"left-arm", PIPE_PART_ARM_L},
        {"right-hand", PIPE_PART_HAND_R}, {"right-arm", PIPE_PART_ARM_R},
        {"hands", PIPE_PART_HAND_L | PIPE_PART_HAND_R},
        {"arms", PIPE_PART_ARM_L | PIPE_PART_ARM_R}, {"all", PIPE_PART_ALL}, {"none", 0},
    };
    unsigned b = 0;
    if (!list || !bits) return -1;
    const char *p = list;
    while (*p) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        int ok = 0;
        for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
            if (strlen(names[k].name) == len && !strncmp(names[k].name, p, len)) {
                b |= names[k].bits;
                ok = 1;
            }
        if (!ok) {
            if (why && why_size > 0)
                snprintf(why, (size_t)why_size,
                         "'%.*s' is not a part (left-hand, left-arm, right-hand, right-arm, "
                         "hands, arms, all, none)", (int)(len > 40 ? 40 : len), p);
            return -1;
        }
        if (!e) break;
        p = e + 1;
        if (!*p) { /* a trailing comma */
            if (why && why_size > 0) snprintf(why, (size_t)why_size, "empty part name after ','");
            return -1;
        }
    }
    *bits = b;
    return 0;
}

/* ------------------------------------------------------- the state */

#define NSETS 16
#define TRI_NONE 4 /* tri_part value: in no part */

typedef struct prop {
    const kin_model *model;
    pipe_pose pose;           /* rest pose: pos / nrm in the prop's frame */
    float **pos, **nrm;       /* per mesh: world space this frame */
    int visible;              /* this frame */
} prop;

struct pipe__cockpit {
    const kin_model *model;
    int mesh_count;
    unsigned char **tri_part; /* per mesh, per triangle: part index 0..3 or TRI_NONE */
    int *tri_count;           /* per mesh */
    unsigned present;         /* parts that own a triangle */
    /* per visibility set: per mesh the visible triangles' indices, then
     * the hidden ones'; NULL until first used */
    uint32_t **lists[NSETS];
    int *nvis[NSETS];
    /* the frame */
    unsigned set;             /* hide & present */
    int active;
    /* props */
    prop *props;
    int nprops, cap;
    int prop_max_vertices;
    float *pclip[2], *pvnrm[2];
    /* clamp scratch per eye (refine_band > 0 and parts present) */
    int width, height;
    uint8_t *hmask[2], *htmp[2], *hgrow[2];
    int *hsum[2];
};

/* Part index of a node (0..3) or TRI_NONE. */
static int part_index(unsigned bit)
{
    switch (bit) {
    case PIPE_PART_HAND_L: return 0;
    case PIPE_PART_ARM_L: return 1;
    case PIPE_PART_HAND_R: return 2;
    case PIPE_PART_ARM_R: return 3;
    }
    return TRI_NONE;
}

/* The rule of pipe.h: largest total weight over the three vertices; ties
 * with no part go to no part, ties between parts to the lower bit. */
static void classify_mesh(const kin_model *m, const kin_mesh *me, const unsigned char *node_part,
                          unsigned char *out)
{
    const int nt = me->index_count / 3;
    const kin_skin *sk = me->skin >= 0 && me->skin < m->skin_count ? &m->skins[me->skin] : NULL;
    const int rigid = !sk || !me->joints || !me->weights;
    const int mesh_part = me->node >= 0 && me->node < m->node_count
                              ? part_index(node_part[me->node]) : TRI_NONE;
    for (int t = 0; t < nt; t++) {
        double w[5] = {0, 0, 0, 0, 0};
        for (int k = 0; k < 3; k++) {
            uint32_t v = me->indices[3 * t + k];
            if (rigid) {
                w[mesh_part] += 1.0;
                continue;
            }
            for (int i = 0; i < 4; i++) {
                float wt = me->weights[4 * (size_t)v + (size_t)i];
                if (!(wt != 0.0f)) continue;
                int j = me->joints[4 * (size_t)v + (size_t)i];
                int node = j < sk->joint_count ? sk->joints[j] : -1;
                int pi = node >= 0 && node < m->node_count ? part_index(node_part[node]) : TRI_NONE;
                w[pi] += (double)wt;
            }
        }
        int best = TRI_NONE;
        for (int pi = 0; pi < 4; pi++)
            if (w[pi] > w[best]) best = pi;
        out[t] = (unsigned char)best;
    }
}

pipe__cockpit *pipe__cockpit_create(const kin_model *m, const kin_arm_rig *rig, int width,
                                    int height, int refine_band)
{
    pipe__cockpit *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->model = m;
    c->mesh_count = m->mesh_count;
    c->width = width;
    c->height = height;
    unsigned char *node_part = calloc((size_t)(m->node_count > 0 ? m->node_count : 1), 1);
    c->tri_part = calloc((size_t)m->mesh_count + 1, sizeof *c->tri_part);
    c->tri_count = calloc((size_t)m->mesh_count + 1, sizeof *c->tri_count);
    if (!node_part || !c->tri_part || !c->tri_count) goto oom;
    if (pipe_parts_of_nodes(m, rig, node_part)) {
        for (int i = 0; i < m->mesh_count; i++) {
            const kin_mesh *me = &m->meshes[i];
            c->tri_count[i] = me->index_count / 3;
            c->tri_part[i] = malloc((size_t)c->tri_count[i] + 1);
            if (!c->tri_part[i]) goto oom;
            classify_mesh(m, me, node_part, c->tri_part[i]);
            for (int t = 0; t < c->tri_count[i]; t++)
                if (c->tri_part[i][t] != TRI_NONE) c->present |= 1u << c->tri_part[i][t];
        }
    }
    free(node_part);
    node_part = NULL;
    if (c->present && refine_band > 0) {
        size_t px = (size_t)width * (size_t)height;
        int longest = width > height ? width : height;
        for (int e = 0; e < 2; e++) {
            c->hmask[e] = malloc(px);
            c->htmp[e] = malloc(px);
            c->hgrow[e] = malloc(px);
            c->hsum[e] = malloc(sizeof(int) * ((size_t)longest + 1));
            if (!c->hmask[e] || !c->htmp[e] || !c->hgrow[e] || !c->hsum[e]) goto oom;
        }
    }
    return c;
oom:
    free(node_part);
    pipe__cockpit_destroy(c);
    return NULL;
}

static void prop_free(prop *pr)
{
    const int nm = pr->model ? pr->model->mesh_count : 0;
    for (int i = 0; i < nm; i++) {
        if (pr->pos) free(pr->pos[i]);
        if (pr->nrm) free(pr->nrm[i]);
    }
    free(pr->pos);
    free(pr->nrm);
    pipe_pose_free(&pr->pose);
}

void pipe__cockpit_destroy(pipe__cockpit *c)
{
    if (!c) return;
    for (int s = 0; s < NSETS; s++) {
        for (int i = 0; c->lists[s] && i < c->mesh_count; i++) free(c->lists[s][i]);
        free(c->lists[s]);
        free(c->nvis[s]);
    }
    for (int i = 0; c->tri_part && i < c->mesh_count; i++) free(c->tri_part[i]);
    free(c->tri_part);
    free(c->tri_count);
    for (int k = 0; k < c->nprops; k++) prop_free(&c->props[k]);
    free(c->props);
    for (int e = 0; e < 2; e++) {
        EF_FREE_ALL(c->pclip[e], c->pvnrm[e], c->hmask[e], c->htmp[e], c->hgrow[e], c->hsum[e]);
    }
    free(c);
}

unsigned pipe__cockpit_present(const pipe__cockpit *c) { return c ? c->present : 0; }
int pipe__cockpit_prop_count(const pipe__cockpit *c) { return c ? c->nprops : 0; }
int pipe__cockpit_active(const pipe__cockpit *c) { return c && c->active; }

int pipe__cockpit_add_prop(pipe__cockpit *c, const kin_model *m)
{
    char why[160];
    if (!c || !m || kin_model_validate(m, why, sizeof why) != 0) return -1;
    int tris = 0;
    for (int i = 0; i < m->mesh_count; i++) tris += m->meshes[i].index_count / 3;
    if (tris < 1) return -1;
    if (c->nprops == c->cap) {
        int cap = c->cap ? 2 * c->cap : 4;
        prop *np = realloc(c->props, sizeof *np * (size_t)cap);
        if (!np) return -1;
        c->props = np;
        c->cap = cap;
    }
    prop *pr = &c->props[c->nprops];
    memset(pr, 0, sizeof *pr);
    pr->model = m;
    if (pipe_pose_init(&pr->pose, m) != 0) return -1;
    pipe_pose_anim(&pr->pose, NULL, 0.0f); /* the rest pose, in the prop's frame */
    pr->pos = calloc((size_t)m->mesh_count + 1, sizeof *pr->pos);
    pr->nrm = calloc((size_t)m->mesh_count + 1, sizeof *pr->nrm);
    int ok = pr->pos && pr->nrm;
    for (int i = 0; ok && i < m->mesh_count; i++) {
        size_t nv = (size_t)m->meshes[i].vertex_count;
        pr->pos[i] = malloc(sizeof(float) * 3 * nv + 1);
        pr->nrm[i] = malloc(sizeof(float) * 3 * nv + 1);
        ok = pr->pos[i] && pr->nrm[i];
    }
    if (ok && pr->pose.max_vertices > c->prop_max_vertices) {
        size_t nv = (size_t)pr->pose.max_vertices;
        for (int e = 0; ok && e < 2; e++) {
            float *a = malloc(sizeof(float) * 4 * nv), *b = malloc(sizeof(float) * 3 * nv);
            if (!a || !b) {
                free(a);
                free(b);
                ok = 0;
                break;
            }
            free(c->pclip[e]);
            free(c->pvnrm[e]);
            c->pclip[e] = a;
            c->pvnrm[e] = b;
        }
        if (ok) c->prop_max_vertices = pr->pose.max_vertices;
    }
    if (!ok) {
        prop_free(pr);
        return -1;
    }
    return c->nprops++;
}

/* The index lists of visibility set s, built once: per mesh the visible
 * triangles, then the hidden ones, each in the model's order. 0, or -1
 * when out of memory. */
static int build_set(pipe__cockpit *c, unsigned s)
{
    if (c->lists[s]) return 0;
    uint32_t **lists = calloc((size_t)c->mesh_count + 1, sizeof *lists);
    int *nvis = calloc((size_t)c->mesh_count + 1, sizeof *nvis);
    if (!lists || !nvis) goto oom;
    for (int i = 0; i < c->mesh_count; i++) {
        const uint32_t *ix = c->model->meshes[i].indices;
        const unsigned char *tp = c->tri_part[i];
        uint32_t *out = lists[i] = malloc(sizeof(uint32_t) * 3 * (size_t)c->tri_count[i] + 1);
        if (!out) goto oom;
        int k = 0;
        for (int pass = 0; pass < 2; pass++) {
            for (int t = 0; t < c->tri_count[i]; t++) {
                int hidden = tp[t] != TRI_NONE && (s >> tp[t] & 1u);
                if (hidden != pass) continue;
                memcpy(out + 3 * k, ix + 3 * t, 3 * sizeof(uint32_t));
                k++;
            }
            if (pass == 0) nvis[i] = k;
        }
    }
    c->lists[s] = lists;
    c->nvis[s] = nvis;
    return 0;
oom:
    for (int i = 0; lists && i < c->mesh_count; i++) free(lists[i]);
    free(lists);
    free(nvis);
    return -1;
}

pipe_result pipe__cockpit_frame(pipe__cockpit *c, const pipe_frame_in *in, char *why,
                                int why_size)
{
    c->active = 0;
    c->set = in->hide & c->present;
    int nprop = in->prop_world ? in->prop_count : 0;
    if (nprop < 0 || nprop > c->nprops) {
        if (why && why_size > 0)
            snprintf(why, (size_t)why_size, "prop_count %d, but %d prop%s added", in->prop_count,
                     c->nprops, c->nprops == 1 ? " was" : "s were");
        return PIPE_ERR_ARGS;
    }
    int any_prop = 0;
    for (int k = 0; k < c->nprops; k++) {
        prop *pr = &c->props[k];
        const kin_mat4 *w = k < nprop ? in->prop_world[k] : NULL;
        pr->visible = w != NULL;
        if (!w) continue;
        any_prop = 1;
        for (int i = 0; i < pr->model->mesh_count; i++) {
            kin_mesh rest = pr->pose.meshes[i];
            rest.positions = pr->pose.pos[i];
            rest.normals = pr->pose.nrm[i];
            kin_mesh_transform(&rest, w, pr->pos[i], pr->nrm[i]);
        }
    }
    if (c->set) {
        if (build_set(c, c->set) != 0) {
            if (why && why_size > 0)
                snprintf(why, (size_t)why_size, "hiding parts 0x%x: out of memory", c->set);
            return PIPE_ERR_ARGS;
        }
    }
    c->active = c->set != 0 || any_prop;
    return PIPE_OK;
}

/* One mesh through cam: positions / normals (world) -> clip / view. */
static rast_result draw_mesh(rast_context *ctx, const kin_camera *cam, const rast_target *tg,
                             rast_cull cull, const float *pos, const float *nrm, int nv,
                             const uint32_t *ix, int nt, float *clip, float *vnrm)
{
    if (nt <= 0) return RAST_OK;
    const int with_n = tg->attr_count == 3;
    rast_transform_points(cam->view_proj.m, pos, nv, clip);
    if (with_n) rast_transform_dirs(cam->view.m, nrm, nv, vnrm);
    rast_mesh_desc d = {
        .clip = clip,
        .vertex_count = nv,
        .attr = with_n ? vnrm : NULL,
        .attr_count = with_n ? 3 : 0,
        .indices = ix,
        .tri_count = nt,
        .cull = cull,
    };
    return ctx ? rast_context_draw(ctx, tg, &d, NULL) : rast_draw(tg, &d, NULL);
}

/* The triangles of the operator's mesh i (me) the current visibility
 * set draws: its index list in *ix, the triangle count returned. */
static int mesh_tris(const pipe__cockpit *c, const kin_mesh *me, int i, const uint32_t **ix)
{
    if (c->set) {
        *ix = c->lists[c->set][i];
        return c->nvis[c->set][i];
    }
    *ix = me->indices;
    return me->index_count / 3;
}

/* One mesh an eye draws: the model's (its level's triangles, the caller's
 * cull) or a visible prop's (every triangle, no cull). */
typedef struct draw_item {
    const float *pos, *nrm;
    int nv;
    const uint32_t *ix;
    int nt;
    rast_cull cull;
    int is_prop;
} draw_item;

/* The next non-empty mesh in drawing order, the model's meshes first, then
 * each visible prop's; 0 after the last. Start with *k = -1, *i = 0. */
static int next_item(const pipe__cockpit *c, const pipe_pose *ps, rast_cull cull, int *k,
                     int *i, draw_item *d)
{
    while (*k < c->nprops) {
        if (*k < 0 && *i < ps->model->mesh_count) {
            const kin_mesh *me = &ps->meshes[*i];
            *d = (draw_item){ .pos = ps->pos[*i], .nrm = ps->nrm[*i], .nv = me->vertex_count,
                              .cull = cull };
            d->nt = mesh_tris(c, me, (*i)++, &d->ix);
        } else if (*k >= 0 && c->props[*k].visible &&
                   *i < c->props[*k].model->mesh_count) {
            const prop *pr = &c->props[*k];
            const kin_mesh *me = &pr->pose.meshes[*i];
            *d = (draw_item){ .pos = pr->pos[*i], .nrm = pr->nrm[*i], .nv = me->vertex_count,
                              .ix = me->indices, .nt = me->index_count / 3,
                              .cull = RAST_CULL_NONE, .is_prop = 1 };
            (*i)++;
        } else {
            (*k)++;
            *i = 0;
            continue;
        }
        if (d->nt > 0) return 1;
    }
    return 0;
}

rast_result pipe__cockpit_draw(pipe__cockpit *c, const pipe_pose *ps, int eye,
                               rast_context *ctx, const kin_camera *cam,
                               const rast_target *target, rast_cull cull, float *clip,
                               float *vnrm)
{
    draw_item d;
    for (int k = -1, i = 0; next_item(c, ps, cull, &k, &i, &d);) {
        rast_result r = draw_mesh(ctx, cam, target, d.cull, d.pos, d.nrm, d.nv, d.ix, d.nt,
                                  d.is_prop ? c->pclip[eye] : clip,
                                  d.is_prop ? c->pvnrm[eye] : vnrm);
        if (r != RAST_OK) return r;
    }
    return RAST_OK;
}

rast_result pipe__cockpit_draw_aa(pipe__cockpit *c, const pipe_pose *ps, int eye,
                                  rast_context *ctx, const kin_camera *cam, pipe__aa *aa,
                                  rast_cull cull, float *clip)
{
    draw_item d;
    for (int k = -1, i = 0; next_item(c, ps, cull, &k, &i, &d);) {
        float *cl = d.is_prop ? c->pclip[eye] : clip;
        rast_transform_points(cam->view_proj.m, d.pos, d.nv, cl);
        rast_result r = pipe__aa_draw(aa, ctx, cl, d.nv, d.ix, d.nt, d.cull);
        if (r != RAST_OK) return r;
    }
    return RAST_OK;
}

/* dst = 1 where src (w x h, >= 128 inside) has a set pixel within b px
 * along the rows; sum: w + 1 ints. Transposed access by strides. */
static void dilate_line(const uint8_t *src, long sstep, uint8_t *dst, long dstep, int n, int b,
                        int *sum)
{
    sum[0] = 0;
    for (int i = 0; i < n; i++) sum[i + 1] = sum[i] + (src[(long)i * sstep] >= 128);
    for (int i = 0; i < n; i++) {
        int lo = i - b < 0 ? 0 : i - b, hi = i + b + 1 > n ? n : i + b + 1;
        dst[(long)i * dstep] = (uint8_t)(sum[hi] - sum[lo] > 0 ? 255 : 0);
    }
}

void pipe__cockpit_clamp(pipe__cockpit *c, const pipe_pose *ps, int eye, rast_context *ctx,
                         const kin_camera *cam, const uint8_t *mask, int mask_stride,
                         uint8_t *refined, int refined_stride, int band, float *clip)
{
    if (!c || !c->active || !c->set || !c->hmask[eye]) return;
    const int W = c->width, H = c->height;
    const kin_model *m = ps->model;
    /* the hidden triangles' silhouette: no depth, no normals */
    rast_target tg = {W, H, NULL, 0, c->hmask[eye], W, NULL, 0, 0, NULL, 0};
    rast_context_clear(ctx, &tg);
    int any = 0;
    for (int i = 0; i < m->mesh_count; i++) {
        const kin_mesh *me = &ps->meshes[i];
        const int nv = c->nvis[c->set][i], nt = c->tri_count[i] - nv;
        if (nt <= 0) continue;
        any = 1;
        if (draw_mesh(ctx, cam, &tg, RAST_CULL_NONE, ps->pos[i], ps->nrm[i], me->vertex_count,
                      c->lists[c->set][i] + 3 * (size_t)nv, nt, clip, NULL) != RAST_OK)
            return;
    }
    if (!any || rast_context_count(ctx, &tg) == 0) return;
    /* grown by band px: rows, then columns */
    const uint8_t *hm = c->hmask[eye];
    uint8_t *tmp = c->htmp[eye], *gr = c->hgrow[eye];
    int *sum = c->hsum[eye];
    for (int y = 0; y < H; y++)
        dilate_line(hm + (size_t)y * (size_t)W, 1, tmp + (size_t)y * (size_t)W, 1, W, band, sum);
    for (int x = 0; x < W; x++) dilate_line(tmp + x, W, gr + x, W, H, band, sum);
    for (int y = 0; y < H; y++) {
        const uint8_t *g = gr + (size_t)y * (size_t)W, *k = mask + (size_t)y * (size_t)mask_stride;
        uint8_t *r = refined + (size_t)y * (size_t)refined_stride;
        for (int x = 0; x < W; x++)
            if (g[x] && k[x] < 128) r[x] = 0;
    }
}
