/* gen_cockpit.c - the two static scenes of the samples, as flat-shaded
 * triangle lists: the operator's cockpit (what the HMD cameras see behind
 * the arms) and the remote workshop (the virtual scene shown in the HMD).
 * The operator sits at the origin facing -Z, eyes near (0, 1.25, -0.08). */
#include "gen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define DEG(d) ((d) * (PI_F / 180.0f))

void gen_scene_free(gen_scene *s)
{
    free(s->pos);
    free(s->attr);
    free(s->idx);
    memset(s, 0, sizeof *s);
}

static int grow(gen_scene *s, int nv, int nt)
{
    if (s->failed) return -1;
    if (s->vertex_count + nv > s->vertex_cap) {
        int cap = (s->vertex_cap ? s->vertex_cap * 2 : 1024) + nv;
        float *p = realloc(s->pos, sizeof(float) * 3 * (size_t)cap);
        if (p) s->pos = p;
        float *a = p ? realloc(s->attr, sizeof(float) * GEN_ATTRS * (size_t)cap) : NULL;
        if (a) s->attr = a;
        if (!p || !a) { s->failed = 1; return -1; }
        s->vertex_cap = cap;
    }
    if (s->tri_count + nt > s->tri_cap) {
        int cap = (s->tri_cap ? s->tri_cap * 2 : 1024) + nt;
        uint32_t *t = realloc(s->idx, sizeof(uint32_t) * 3 * (size_t)cap);
        if (!t) { s->failed = 1; return -1; }
        s->idx = t;
        s->tri_cap = cap;
    }
    return 0;
}

typedef struct surf { float rgb[3]; gen_pattern pat; } surf;

static surf S(float r, float g, float b, gen_pattern p)
{
    surf s = { { r, g, b }, p };
    return s;
}

static int vtx(gen_scene *s, kin_vec3 p, kin_vec3 n, surf m, float u, float v)
{
    int i = s->vertex_count++;
    s->pos[i * 3 + 0] = p.x;
    s->pos[i * 3 + 1] = p.y;
    s->pos[i * 3 + 2] = p.z;
    float *a = &s->attr[i * GEN_ATTRS];
    a[GEN_A_NX] = n.x;
    a[GEN_A_NY] = n.y;
    a[GEN_A_NZ] = n.z;
    a[GEN_A_R] = m.rgb[0];
    a[GEN_A_G] = m.rgb[1];
    a[GEN_A_B] = m.rgb[2];
    a[GEN_A_U] = (float)m.pat * GEN_PATTERN_STRIDE + u;
    a[GEN_A_V] = v;
    return i;
}

static void tri(gen_scene *s, int a, int b, int c)
{
    uint32_t *t = &s->idx[s->tri_count++ * 3];
    t[0] = (uint32_t)a;
    t[1] = (uint32_t)b;
    t[2] = (uint32_t)c;
}

/* A box with centre c, half extents h, rotated by q; face coordinates
 * (u, v) in metres for the patterns. */
static void box(gen_scene *s, kin_vec3 c, kin_vec3 h, kin_quat q, surf m)
{
    if (grow(s, 24, 12) < 0) return;
    static const float ax[6][3][3] = {
        /* normal, u axis, v axis */
        { { 1, 0, 0 }, { 0, 0, -1 }, { 0, 1, 0 } },
        { { -1, 0, 0 }, { 0, 0, 1 }, { 0, 1, 0 } },
        { { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, -1 } },
        { { 0, -1, 0 }, { 1, 0, 0 }, { 0, 0, 1 } },
        { { 0, 0, 1 }, { 1, 0, 0 }, { 0, 1, 0 } },
        { { 0, 0, -1 }, { -1, 0, 0 }, { 0, 1, 0 } },
    };
    float he[3] = { h.x, h.y, h.z };
    for (int f = 0; f < 6; f++) {
        float eu = 0, ev = 0, en = 0;
        for (int k = 0; k < 3; k++) {
            eu += fabsf(ax[f][1][k]) * he[k];
            ev += fabsf(ax[f][2][k]) * he[k];
            en += fabsf(ax[f][0][k]) * he[k];
        }
        kin_vec3 n = kin_quat_rotate(q, kin_v3(ax[f][0][0], ax[f][0][1], ax[f][0][2]));
        kin_vec3 u = kin_quat_rotate(q, kin_v3(ax[f][1][0], ax[f][1][1], ax[f][1][2]));
        kin_vec3 v = kin_quat_rotate(q, kin_v3(ax[f][2][0], ax[f][2][1], ax[f][2][2]));
        kin_vec3 fc = kin_v3_add(c, kin_v3_scale(n, en));
        int base = s->vertex_count;
        static const float corner[4][2] = { { -1, -1 }, { 1, -1 }, { 1, 1 }, { -1, 1 } };
        for (int k = 0; k < 4; k++) {
            float cu = corner[k][0] * eu, cv = corner[k][1] * ev;
            kin_vec3 p = kin_v3_add(fc, kin_v3_add(kin_v3_scale(u, cu), kin_v3_scale(v, cv)));
            vtx(s, p, n, m, cu + eu, cv + ev);
        }
        tri(s, base, base + 1, base + 2);
        tri(s, base, base + 2, base + 3);
    }
}

static void abox(gen_scene *s, float x0, float y0, float z0, float x1, float y1,
                 float z1, surf m)
{
    box(s, kin_v3(0.5f * (x0 + x1), 0.5f * (y0 + y1), 0.5f * (z0 + z1)),
        kin_v3(0.5f * fabsf(x1 - x0), 0.5f * fabsf(y1 - y0), 0.5f * fabsf(z1 - z0)),
        kin_quat_identity(), m);
}

/* Upright cylinder from base centre b, radius r, height h, with a top
 * disc; smooth side normals. */
static void cylinder(gen_scene *s, kin_vec3 b, float r, float h, int seg,
                     surf side, surf top)
{
    if (grow(s, 4 * seg + 2, 4 * seg) < 0) return;
    int base = s->vertex_count;
    for (int i = 0; i < seg; i++) {
        float a = 2.0f * PI_F * (float)i / (float)seg;
        kin_vec3 n = kin_v3(cosf(a), 0.0f, -sinf(a));
        kin_vec3 p0 = kin_v3(b.x + r * n.x, b.y, b.z + r * n.z);
        kin_vec3 p1 = kin_v3(p0.x, b.y + h, p0.z);
        vtx(s, p0, n, side, a * r, 0.0f);
        vtx(s, p1, n, side, a * r, h);
    }
    for (int i = 0; i < seg; i++) {
        int i1 = (i + 1) % seg;
        tri(s, base + 2 * i, base + 2 * i1, base + 2 * i1 + 1);
        tri(s, base + 2 * i, base + 2 * i1 + 1, base + 2 * i + 1);
    }
    int c = vtx(s, kin_v3(b.x, b.y + h, b.z), kin_v3(0, 1, 0), top, 0.0f, 0.0f);
    int rim = s->vertex_count;
    for (int i = 0; i < seg; i++) {
        float a = 2.0f * PI_F * (float)i / (float)seg;
        vtx(s, kin_v3(b.x + r * cosf(a), b.y + h, b.z - r * sinf(a)),
            kin_v3(0, 1, 0), top, r * cosf(a), r * sinf(a));
    }
    for (int i = 0; i < seg; i++) tri(s, c, rim + i, rim + (i + 1) % seg);
}

static void set_light(gen_scene *s, float dx, float dy, float dz, float r,
                      float g, float b)
{
    int i = s->light_count++;
    kin_vec3 d = kin_v3_norm(kin_v3(dx, dy, dz));
    s->light_dir[i][0] = d.x;
    s->light_dir[i][1] = d.y;
    s->light_dir[i][2] = d.z;
    s->light_color[i][0] = r;
    s->light_color[i][1] = g;
    s->light_color[i][2] = b;
}

/* Box placed in the frame of a tilted panel (centre pc, rotation q). */
static void panel_box(gen_scene *s, kin_vec3 pc, kin_quat q, float x, float y,
                      float z, kin_vec3 h, surf m)
{
    box(s, kin_v3_add(pc, kin_quat_rotate(q, kin_v3(x, y, z))), h, q, m);
}

int gen_scene_cockpit(gen_scene *s)
{
    memset(s, 0, sizeof *s);
    surf wall = S(0.33f, 0.36f, 0.41f, GEN_PAT_PLAIN);
    surf floor_ = S(0.22f, 0.22f, 0.24f, GEN_PAT_TILES);
    surf desk = S(0.58f, 0.59f, 0.61f, GEN_PAT_PLAIN);
    surf dark = S(0.16f, 0.17f, 0.19f, GEN_PAT_PLAIN);
    surf screen = S(0.10f, 0.22f, 0.32f, GEN_PAT_SCREEN);
    surf buttons = S(0.20f, 0.21f, 0.23f, GEN_PAT_BUTTONS);
    /* room */
    abox(s, -2.0f, -0.1f, -2.2f, 2.0f, 0.0f, 1.6f, floor_);
    abox(s, -2.0f, 2.5f, -2.2f, 2.0f, 2.6f, 1.6f, S(0.50f, 0.50f, 0.52f, GEN_PAT_PLAIN));
    abox(s, -2.0f, 0.0f, -2.3f, 2.0f, 2.5f, -2.2f, wall);
    abox(s, -2.0f, 0.0f, 1.6f, 2.0f, 2.5f, 1.7f, wall);
    abox(s, -2.1f, 0.0f, -2.2f, -2.0f, 2.5f, 1.6f, S(0.30f, 0.34f, 0.38f, GEN_PAT_PLAIN));
    abox(s, 2.0f, 0.0f, -2.2f, 2.1f, 2.5f, 1.6f, S(0.30f, 0.34f, 0.38f, GEN_PAT_PLAIN));
    /* desk and its front skirt */
    abox(s, -0.85f, 0.72f, -0.98f, 0.85f, 0.76f, -0.26f, desk);
    abox(s, -0.85f, 0.45f, -0.28f, 0.85f, 0.72f, -0.26f, dark);
    abox(s, -0.84f, 0.00f, -0.96f, -0.80f, 0.72f, -0.30f, dark);
    abox(s, 0.80f, 0.00f, -0.96f, 0.84f, 0.72f, -0.30f, dark);
    /* console leaning back behind the desk, with three displays */
    kin_quat tilt = kin_quat_axis_angle(kin_v3(1, 0, 0), DEG(18.0f));
    kin_vec3 pc = kin_v3(0.0f, 1.08f, -1.05f);
    box(s, pc, kin_v3(0.86f, 0.34f, 0.04f), tilt, dark);
    for (int i = -1; i <= 1; i++)
        panel_box(s, pc, tilt, 0.52f * (float)i, 0.06f, 0.045f,
                  kin_v3(0.22f, 0.15f, 0.008f), screen);
    panel_box(s, pc, tilt, 0.0f, -0.24f, 0.045f, kin_v3(0.70f, 0.06f, 0.008f), buttons);
    /* side consoles, angled towards the operator */
    for (int sd = -1; sd <= 1; sd += 2) {
        kin_quat yaw = kin_quat_axis_angle(kin_v3(0, 1, 0), DEG(-38.0f * (float)sd));
        kin_vec3 c = kin_v3(0.98f * (float)sd, 0.95f, -0.62f);
        box(s, c, kin_v3(0.04f, 0.40f, 0.42f), yaw, dark);
        panel_box(s, c, yaw, -0.045f * (float)sd, 0.12f, 0.0f,
                  kin_v3(0.006f, 0.14f, 0.30f), screen);
        panel_box(s, c, yaw, -0.045f * (float)sd, -0.18f, 0.0f,
                  kin_v3(0.006f, 0.08f, 0.30f), buttons);
    }
    /* things on the desk */
    abox(s, 0.40f, 0.76f, -0.86f, 0.62f, 0.86f, -0.68f, S(0.80f, 0.45f, 0.12f, GEN_PAT_PLAIN));
    abox(s, -0.66f, 0.76f, -0.80f, -0.42f, 0.80f, -0.56f, buttons);
    abox(s, -0.30f, 0.76f, -0.94f, 0.30f, 0.79f, -0.80f, buttons);
    cylinder(s, kin_v3(-0.52f, 0.76f, -0.42f), 0.045f, 0.035f, 24, dark, dark);
    cylinder(s, kin_v3(-0.52f, 0.795f, -0.42f), 0.012f, 0.13f, 12,
             S(0.10f, 0.10f, 0.11f, GEN_PAT_PLAIN), S(0.75f, 0.10f, 0.08f, GEN_PAT_PLAIN));
    cylinder(s, kin_v3(0.58f, 0.76f, -0.46f), 0.040f, 0.10f, 24,
             S(0.85f, 0.85f, 0.80f, GEN_PAT_PLAIN), S(0.30f, 0.20f, 0.12f, GEN_PAT_PLAIN));
    /* ceiling light fittings */
    for (int i = -1; i <= 1; i += 2)
        abox(s, 0.6f * (float)i - 0.3f, 2.46f, -1.2f, 0.6f * (float)i + 0.3f, 2.5f, -0.2f,
             S(1.0f, 1.0f, 0.95f, GEN_PAT_WINDOW));
    set_light(s, 0.25f, 1.0f, 0.35f, 0.72f, 0.68f, 0.60f);
    set_light(s, -0.6f, 0.35f, 0.7f, 0.22f, 0.25f, 0.30f);
    s->ambient[0] = 0.30f; s->ambient[1] = 0.30f; s->ambient[2] = 0.33f;
    s->sky[0] = 0.1f; s->sky[1] = 0.1f; s->sky[2] = 0.1f;
    return s->failed ? -1 : 0;
}

int gen_scene_workshop(gen_scene *s, const gen_arms *arms)
{
    memset(s, 0, sizeof *s);
    kin_vec3 g = arms->grasp_point;
    float cup_h = 0.11f;
    float top = g.y - 0.5f * cup_h;          /* table surface */
    surf wall = S(0.64f, 0.68f, 0.60f, GEN_PAT_PLAIN);
    surf wood = S(0.56f, 0.38f, 0.22f, GEN_PAT_WOOD);
    surf steel = S(0.42f, 0.44f, 0.46f, GEN_PAT_PLAIN);
    /* room: concrete floor, pale green walls, windows on the left */
    abox(s, -3.0f, -0.1f, -4.0f, 3.0f, 0.0f, 2.0f, S(0.55f, 0.53f, 0.49f, GEN_PAT_TILES));
    abox(s, -3.0f, 3.2f, -4.0f, 3.0f, 3.3f, 2.0f, S(0.80f, 0.80f, 0.78f, GEN_PAT_PLAIN));
    abox(s, -3.0f, 0.0f, -4.1f, 3.0f, 3.2f, -4.0f, wall);
    abox(s, -3.0f, 0.0f, 2.0f, 3.0f, 3.2f, 2.1f, wall);
    abox(s, -3.1f, 0.0f, -4.0f, -3.0f, 3.2f, 2.0f, wall);
    abox(s, 3.0f, 0.0f, -4.0f, 3.1f, 3.2f, 2.0f, S(0.70f, 0.62f, 0.50f, GEN_PAT_PLAIN));
    for (int i = 0; i < 3; i++)
        abox(s, -2.99f, 1.0f, -3.6f + 1.3f * (float)i, -2.97f, 2.6f, -2.6f + 1.3f * (float)i,
             S(0.95f, 0.97f, 1.0f, GEN_PAT_WINDOW));
    /* work table under the grasp point */
    abox(s, -0.75f, top - 0.04f, -1.15f, 0.85f, top, -0.28f, wood);
    for (int i = 0; i < 4; i++) {
        float x = i & 1 ? 0.78f : -0.68f, z = i & 2 ? -1.08f : -0.35f;
        abox(s, x - 0.03f, 0.0f, z - 0.03f, x + 0.03f, top - 0.04f, z + 0.03f, steel);
    }
    /* the cup the right hand grasps, and a bottle just in front of it
     * (nearer to the eyes), which hides part of the reaching hand */
    cylinder(s, kin_v3(g.x, top, g.z), 0.038f, cup_h, 32,
             S(0.78f, 0.16f, 0.12f, GEN_PAT_PLAIN), S(0.30f, 0.08f, 0.06f, GEN_PAT_PLAIN));
    cylinder(s, kin_v3(g.x - 0.075f, top, g.z + 0.15f), 0.026f, 0.16f, 32,
             S(0.20f, 0.45f, 0.30f, GEN_PAT_PLAIN), S(0.85f, 0.85f, 0.80f, GEN_PAT_PLAIN));
    cylinder(s, kin_v3(g.x - 0.075f, top + 0.16f, g.z + 0.15f), 0.010f, 0.035f, 16,
             S(0.85f, 0.85f, 0.80f, GEN_PAT_PLAIN), S(0.85f, 0.85f, 0.80f, GEN_PAT_PLAIN));
    /* more objects: a toolbox, parts bins, a vice, a robot base */
    abox(s, -0.55f, top, -0.95f, -0.20f, top + 0.16f, -0.72f, S(0.20f, 0.35f, 0.70f, GEN_PAT_PLAIN));
    abox(s, -0.50f, top + 0.16f, -0.90f, -0.25f, top + 0.18f, -0.77f, steel);
    for (int i = 0; i < 3; i++)
        abox(s, 0.30f + 0.15f * (float)i, top, -1.05f, 0.42f + 0.15f * (float)i, top + 0.08f,
             -0.90f, S(0.85f, 0.70f - 0.2f * (float)i, 0.10f, GEN_PAT_PLAIN));
    abox(s, -0.45f, top, -0.50f, -0.30f, top + 0.06f, -0.38f, steel);
    cylinder(s, kin_v3(0.55f, top, -0.60f), 0.09f, 0.12f, 32,
             S(0.90f, 0.55f, 0.10f, GEN_PAT_PLAIN), steel);
    cylinder(s, kin_v3(0.55f, top + 0.12f, -0.60f), 0.045f, 0.35f, 24,
             S(0.90f, 0.55f, 0.10f, GEN_PAT_PLAIN), steel);
    /* shelves on the back wall */
    for (int i = 0; i < 4; i++)
        abox(s, -1.8f, 0.4f + 0.5f * (float)i, -3.95f, 1.2f, 0.43f + 0.5f * (float)i, -3.5f, wood);
    for (int i = 0; i < 9; i++)
        abox(s, -1.7f + 0.33f * (float)i, 0.43f + 0.5f * (float)(i % 4), -3.9f,
             -1.5f + 0.33f * (float)i, 0.63f + 0.5f * (float)(i % 4), -3.6f,
             S(0.3f + 0.07f * (float)(i % 5), 0.5f, 0.75f - 0.08f * (float)(i % 6), GEN_PAT_PLAIN));
    /* cool daylight from the windows on the left, warm lamp from above right */
    set_light(s, -0.75f, 0.55f, 0.2f, 0.62f, 0.70f, 0.82f);
    set_light(s, 0.35f, 1.0f, 0.15f, 0.45f, 0.38f, 0.28f);
    s->ambient[0] = 0.28f; s->ambient[1] = 0.30f; s->ambient[2] = 0.32f;
    s->sky[0] = 0.6f; s->sky[1] = 0.7f; s->sky[2] = 0.8f;
    return s->failed ? -1 : 0;
}
