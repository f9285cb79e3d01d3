/* kin_math.c - vectors, quaternions and column-major 4x4 matrices.
 *
 * Plain scalar float code (the reference). The matrix inverse works in
 * double and rounds once at the end. Conventions are in kin.h and
 * docs/kin.md: m[col*4 + row], quaternions (x, y, z, w), T * R * S. */
#include "kin.h"

#include <math.h>
#include <string.h>

/* ------------------------------------------------------------- vectors */

kin_vec3 kin_v3(float x, float y, float z)
{
    kin_vec3 v = { x, y, z };
    return v;
}

kin_vec3 kin_v3_add(kin_vec3 a, kin_vec3 b) { return kin_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
kin_vec3 kin_v3_sub(kin_vec3 a, kin_vec3 b) { return kin_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
kin_vec3 kin_v3_scale(kin_vec3 a, float s) { return kin_v3(a.x * s, a.y * s, a.z * s); }
float kin_v3_dot(kin_vec3 a, kin_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

kin_vec3 kin_v3_cross(kin_vec3 a, kin_vec3 b)
{
    return kin_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z,
                  a.x * b.y - a.y * b.x);
}

float kin_v3_len(kin_vec3 a) { return sqrtf(kin_v3_dot(a, a)); }

kin_vec3 kin_v3_norm(kin_vec3 a)
{
    float l = kin_v3_len(a);
    if (!(l > 0.0f) || !isfinite(l)) return kin_v3(0.0f, 0.0f, 0.0f);
    return kin_v3_scale(a, 1.0f / l);
}

/* --------------------------------------------------------- quaternions */

kin_quat kin_quat_identity(void)
{
    kin_quat q = { 0.0f, 0.0f, 0.0f, 1.0f };
    return q;
}

kin_quat kin_quat_mul(kin_quat a, kin_quat b)
{
    kin_quat q;
    q.x = a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y;
    q.y = a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x;
    q.z = a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w;
    q.w = a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z;
    return q;
}

kin_quat kin_quat_normalize(kin_quat q)
{
    float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (!(l > 0.0f) || !isfinite(l)) return kin_quat_identity();
    float s = 1.0f / l;
    kin_quat r = { q.x * s, q.y * s, q.z * s, q.w * s };
    return r;
}

/* The rotation whose columns are the orthonormal axes x, y, z (a
   right-handed frame), w >= 0. */
kin_quat kin_quat_from_axes(kin_vec3 x, kin_vec3 y, kin_vec3 z)
{
    float tr = x.x + y.y + z.z;
    kin_quat q;
    if (tr > 0.0f) {
        float r = sqrtf(1.0f + tr) * 2.0f;
        q.w = 0.25f * r;
        q.x = (y.z - z.y) / r;
        q.y = (z.x - x.z) / r;
        q.z = (x.y - y.x) / r;
    } else if (x.x > y.y && x.x > z.z) {
        float r = sqrtf(1.0f + x.x - y.y - z.z) * 2.0f;
        q.w = (y.z - z.y) / r;
        q.x = 0.25f * r;
        q.y = (y.x + x.y) / r;
        q.z = (z.x + x.z) / r;
    } else if (y.y > z.z) {
        float r = sqrtf(1.0f + y.y - x.x - z.z) * 2.0f;
        q.w = (z.x - x.z) / r;
        q.x = (y.x + x.y) / r;
        q.y = 0.25f * r;
        q.z = (z.y + y.z) / r;
    } else {
        float r = sqrtf(1.0f + z.z - x.x - y.y) * 2.0f;
        q.w = (x.y - y.x) / r;
        q.x = (z.x + x.z) / r;
        q.y = (z.y + y.z) / r;
        q.z = 0.25f * r;
    }
    if (q.w < 0.0f) { q.x = -q.x; q.y = -q.y; q.z = -q.z; q.w = -q.w; }
    return kin_quat_normalize(q);
}

kin_quat kin_quat_conjugate(kin_quat q) { return (kin_quat){ -q.x, -q.y, -q.z, q.w }; }

kin_quat kin_quat_axis_angle(kin_vec3 axis, float radians)
{
    kin_vec3 n = kin_v3_norm(axis);
    if (n.x == 0.0f && n.y == 0.0f && n.z == 0.0f) return kin_quat_identity();
    float s = sinf(0.5f * radians), c = cosf(0.5f * radians);
    kin_quat q = { n.x * s, n.y * s, n.z * s, c };
    return q;
}

/* v' = v + 2w (q x v) + 2 q x (q x v), for a unit q. */
kin_vec3 kin_quat_rotate(kin_quat q, kin_vec3 v)
{
    kin_vec3 u = kin_v3(q.x, q.y, q.z);
    kin_vec3 t = kin_v3_scale(kin_v3_cross(u, v), 2.0f);
    return kin_v3_add(kin_v3_add(v, kin_v3_scale(t, q.w)), kin_v3_cross(u, t));
}

/* Below this |cos| the quaternions are treated as parallel: sin(theta) is
 * then too small to divide by and nlerp is as accurate. */
#define SLERP_NLERP_COS 0.9995f

kin_quat kin_quat_slerp(kin_quat a, kin_quat b, float t)
{
    float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
    if (d < 0.0f) { /* q and -q are the same rotation: take the short arc */
        b.x = -b.x; b.y = -b.y; b.z = -b.z; b.w = -b.w;
        d = -d;
    }
    float wa, wb;
    if (d > SLERP_NLERP_COS) {
        wa = 1.0f - t;
        wb = t;
    } else {
        double th = acos((double)d), s = sin(th);
        wa = (float)(sin((1.0 - (double)t) * th) / s);
        wb = (float)(sin((double)t * th) / s);
    }
    kin_quat q = { wa * a.x + wb * b.x, wa * a.y + wb * b.y,
                   wa * a.z + wb * b.z, wa * a.w + wb * b.w };
    return kin_quat_normalize(q);
}

/* ------------------------------------------------------------ matrices */

kin_mat4 kin_mat4_identity(void)
{
    kin_mat4 r = { { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 } };
    return r;
}

kin_mat4 kin_mat4_mul(const kin_mat4 *a, const kin_mat4 *b)
{
    kin_mat4 r;
    for (int c = 0; c < 4; c++) {
        for (int row = 0; row < 4; row++) {
            r.m[c * 4 + row] = a->m[0 * 4 + row] * b->m[c * 4 + 0] +
                               a->m[1 * 4 + row] * b->m[c * 4 + 1] +
                               a->m[2 * 4 + row] * b->m[c * 4 + 2] +
                               a->m[3 * 4 + row] * b->m[c * 4 + 3];
        }
    }
    return r;
}

/* Rotation part of a quaternion into the upper 3x3 of m (columns 0..2).
 * Uses s = 2/|q|^2, so a non-unit q still gives a pure rotation. */
static void rot3(kin_quat q, float *m)
{
    float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    float s = (n > 0.0f && isfinite(n)) ? 2.0f / n : 0.0f;
    float xx = q.x * q.x * s, yy = q.y * q.y * s, zz = q.z * q.z * s;
    float xy = q.x * q.y * s, xz = q.x * q.z * s, yz = q.y * q.z * s;
    float wx = q.w * q.x * s, wy = q.w * q.y * s, wz = q.w * q.z * s;
    m[0] = 1.0f - (yy + zz); m[1] = xy + wz;          m[2] = xz - wy;
    m[4] = xy - wz;          m[5] = 1.0f - (xx + zz); m[6] = yz + wx;
    m[8] = xz + wy;          m[9] = yz - wx;          m[10] = 1.0f - (xx + yy);
}

kin_mat4 kin_mat4_from_tr(kin_vec3 t, kin_quat r)
{
    kin_mat4 m = kin_mat4_identity();
    rot3(r, m.m);
    m.m[12] = t.x; m.m[13] = t.y; m.m[14] = t.z;
    return m;
}

kin_vec3 kin_mat4_translation(const kin_mat4 *m)
{
    return kin_v3(m->m[12], m->m[13], m->m[14]);
}

kin_quat kin_mat4_rotation(const kin_mat4 *m)
{
    kin_vec3 x = kin_v3_norm(kin_v3(m->m[0], m->m[1], m->m[2]));
    kin_vec3 y = kin_v3_norm(kin_v3(m->m[4], m->m[5], m->m[6]));
    kin_vec3 z = kin_v3_norm(kin_v3_cross(x, y));
    y = kin_v3_cross(z, x);
    return kin_quat_normalize(kin_quat_from_axes(x, y, z));
}

kin_mat4 kin_mat4_from_transform(const kin_transform *t)
{
    kin_mat4 m = kin_mat4_from_tr(t->t, t->r);
    for (int r = 0; r < 3; r++) { /* R * S scales the columns */
        m.m[0 + r] *= t->s.x;
        m.m[4 + r] *= t->s.y;
        m.m[8 + r] *= t->s.z;
    }
    return m;
}

/* Relative singularity threshold: |det| / (product of the row norms),
 * which lies in [0, 1] (Hadamard) and does not depend on the scale of
 * the rows. Below 1e-9 the matrix is singular at float precision. */
#define INV_MIN_REL_DET 1e-9

int kin_mat4_inverse(const kin_mat4 *a, kin_mat4 *out)
{
    double m[16], inv[16];
    for (int i = 0; i < 16; i++) m[i] = a->m[i];

    /* Cofactors (the classic expansion, as in MESA's gluInvertMatrix). */
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] +
             m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] -
             m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] +
             m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] -
              m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] -
             m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] +
             m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] -
             m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] +
              m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] +
             m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] -
             m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] +
              m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] -
              m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] -
             m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] +
             m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] -
              m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] +
              m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];

    double det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    double rows = 1.0;
    for (int r = 0; r < 4; r++)
        rows *= sqrt(m[r] * m[r] + m[4 + r] * m[4 + r] + m[8 + r] * m[8 + r] +
                     m[12 + r] * m[12 + r]);
    if (!isfinite(det) || !(rows > 0.0) || !isfinite(rows) ||
        !(fabs(det) > INV_MIN_REL_DET * rows)) {
        *out = kin_mat4_identity();
        return 0;
    }
    double id = 1.0 / det;
    for (int i = 0; i < 16; i++) out->m[i] = (float)(inv[i] * id);
    return 1;
}

kin_vec3 kin_mat4_mul_point(const kin_mat4 *a, kin_vec3 p)
{
    const float *m = a->m;
    return kin_v3(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12],
                  m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                  m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]);
}

kin_vec3 kin_mat4_mul_dir(const kin_mat4 *a, kin_vec3 d)
{
    const float *m = a->m;
    return kin_v3(m[0] * d.x + m[4] * d.y + m[8] * d.z,
                  m[1] * d.x + m[5] * d.y + m[9] * d.z,
                  m[2] * d.x + m[6] * d.y + m[10] * d.z);
}

kin_mat4 kin_mat4_look_at(kin_vec3 eye, kin_vec3 target, kin_vec3 up)
{
    kin_vec3 f = kin_v3_norm(kin_v3_sub(target, eye));
    if (f.x == 0.0f && f.y == 0.0f && f.z == 0.0f) f = kin_v3(0.0f, 0.0f, -1.0f);
    kin_vec3 s = kin_v3_norm(kin_v3_cross(f, up));
    if (s.x == 0.0f && s.y == 0.0f && s.z == 0.0f) {
        /* up is zero or parallel to the view direction: pick the world
         * axis least aligned with f as up, so the result stays a rotation. */
        kin_vec3 alt = fabsf(f.y) < 0.9f ? kin_v3(0.0f, 1.0f, 0.0f)
                                         : kin_v3(0.0f, 0.0f, -1.0f);
        s = kin_v3_norm(kin_v3_cross(f, alt));
    }
    kin_vec3 u = kin_v3_cross(s, f);
    kin_mat4 r = kin_mat4_identity();
    r.m[0] = s.x; r.m[4] = s.y; r.m[8] = s.z;
    r.m[1] = u.x; r.m[5] = u.y; r.m[9] = u.z;
    r.m[2] = -f.x; r.m[6] = -f.y; r.m[10] = -f.z;
    r.m[12] = -kin_v3_dot(s, eye);
    r.m[13] = -kin_v3_dot(u, eye);
    r.m[14] = kin_v3_dot(f, eye);
    return r;
}

kin_mat4 kin_mat4_perspective(float fovy_rad, float aspect, float znear, float zfar)
{
    double f = 1.0 / tan(0.5 * (double)fovy_rad);
    double n = znear, fa = zfar;
    kin_mat4 r;
    memset(&r, 0, sizeof r);
    r.m[0] = (float)(f / (double)aspect);
    r.m[5] = (float)f;
    r.m[10] = (float)((fa + n) / (n - fa));
    r.m[11] = -1.0f;
    r.m[14] = (float)(2.0 * fa * n / (n - fa));
    return r;
}

kin_transform kin_transform_identity(void)
{
    kin_transform t = { { 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 0.0f, 1.0f },
                        { 1.0f, 1.0f, 1.0f } };
    return t;
}
