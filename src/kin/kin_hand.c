/* kin_hand.c - 5DT Data Glove 5 Ultra style gloves: calibration of the
 * raw sensor range per user, and the mapping of 5 flexure values to the
 * 15 finger joints of one hand (MCP, PIP, DIP per finger with DIP coupled
 * to PIP; CMC with opposition, MCP and IP for the thumb). Table and rules:
 * docs/tracking.md. No allocation, no state. */
#include "kin.h"
#include "kin_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define DEG2RAD(d) ((d) * (PI_F / 180.0f))

#define fail kin__fail

/* ------------------------------------------------------------ calibration */

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int kin_glove_calib_fit(const float *raw, int n, unsigned invert_mask, float min_range,
                        float *scratch, kin_glove_calib *out, char *why, size_t why_size)
{
    if (!raw || !scratch || !out) return fail(why, why_size, -1, "no input");
    if (n < 8) return fail(why, why_size, -1, "%d readings, need at least 8", n);
    if (!(min_range >= 0.0f) || !isfinite(min_range))
        return fail(why, why_size, -1, "min_range must be finite and >= 0");
    kin_glove_calib c;
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
        for (int i = 0; i < n; i++) {
            float v = raw[(size_t)i * KIN_GLOVE_SENSORS + (size_t)k];
            if (!isfinite(v))
                return fail(why, why_size, -1, "reading %d, sensor %d is not finite", i + 1, k + 1);
            scratch[i] = v;
        }
        qsort(scratch, (size_t)n, sizeof(float), cmp_float);
        float lo = scratch[(int)lrintf(0.02f * (float)(n - 1))];
        float hi = scratch[(int)lrintf(0.98f * (float)(n - 1))];
        if (!(hi - lo > min_range))
            return fail(why, why_size, -1,
                        "sensor %d moves over %g only (need > %g): open and close the hand "
                        "fully during calibration", k + 1, (double)(hi - lo), (double)min_range);
        int inv = (invert_mask >> k) & 1u;
        c.raw_open[k] = inv ? hi : lo;
        c.raw_fist[k] = inv ? lo : hi;
    }
    *out = c;
    return 0;
}

int kin_glove_calib_apply(const kin_glove_calib *c, const float raw[KIN_GLOVE_SENSORS],
                          float out[KIN_GLOVE_SENSORS])
{
    if (!c || !raw || !out) return -1;
    float g[KIN_GLOVE_SENSORS];
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++) {
        if (!isfinite(raw[k])) return -1;
        float range = c->raw_fist[k] - c->raw_open[k];
        float v = range != 0.0f ? (raw[k] - c->raw_open[k]) / range : 0.0f;
        g[k] = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
        if (!isfinite(g[k])) return -1;
    }
    memcpy(out, g, sizeof g);
    return 0;
}

/* ---------------------------------------------------------------- mapping */

kin_hand_params kin_hand_params_default(void)
{
    kin_hand_params p = {
        .open_deg = { { 5, 5, 5 }, { 5, 8, 0 }, { 6, 10, 0 }, { 8, 12, 0 }, { 10, 14, 0 } },
        .fist_deg = { { 20, 50, 65 }, { 80, 95, 0 }, { 85, 100, 0 }, { 85, 100, 0 },
                      { 85, 95, 0 } },
        .dip_coupling = 2.0f / 3.0f,
        .thumb_opp_deg = { 12.0f, 40.0f },
    };
    return p;
}

static int unitq(kin_quat q)
{
    float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    return isfinite(l) && fabsf(l - 1.0f) <= 1e-3f;
}

int kin_hand_validate(const kin_hand_job *job, char *why, size_t why_size)
{
    if (!job) return fail(why, why_size, 0, "no job");
    if (!job->glove) return fail(why, why_size, 0, "glove is NULL");
    if (!job->out) return fail(why, why_size, 0, "out is NULL");
    if (job->side != KIN_SIDE_LEFT && job->side != KIN_SIDE_RIGHT)
        return fail(why, why_size, 0, "bad side %d", (int)job->side);
    for (int k = 0; k < KIN_GLOVE_SENSORS; k++)
        if (!(job->glove[k] >= 0.0f && job->glove[k] <= 1.0f))
            return fail(why, why_size, 0, "glove value %d is %g, not in [0, 1]", k + 1,
                        (double)job->glove[k]);
    if (job->params) {
        const kin_hand_params *p = job->params;
        for (int f = 0; f < 5; f++)
            for (int j = 0; j < 3; j++)
                if (!isfinite(p->open_deg[f][j]) || !isfinite(p->fist_deg[f][j]) ||
                    fabsf(p->open_deg[f][j]) > 180.0f || fabsf(p->fist_deg[f][j]) > 180.0f)
                    return fail(why, why_size, 0, "angle table: finger %d joint %d out of range",
                                f, j);
        if (!isfinite(p->dip_coupling) || p->dip_coupling < 0.0f || p->dip_coupling > 2.0f)
            return fail(why, why_size, 0, "dip_coupling must be in [0, 2]");
        if (!isfinite(p->thumb_opp_deg[0]) || !isfinite(p->thumb_opp_deg[1]))
            return fail(why, why_size, 0, "thumb opposition is not finite");
    }
    if (job->rest)
        for (int i = 0; i < KIN_HAND_JOINTS; i++)
            if (!unitq(job->rest[i]))
                return fail(why, why_size, 0, "rest rotation %d is not a unit quaternion", i);
    return 1;
}

int kin_hand_run(const kin_hand_job *job)
{
    if (!kin_hand_validate(job, NULL, 0)) return 0;
    kin_hand_params def = kin_hand_params_default();
    const kin_hand_params *p = job->params ? job->params : &def;
    const float s = job->side == KIN_SIDE_RIGHT ? 1.0f : -1.0f;
    const kin_vec3 X = kin_v3(1, 0, 0), Z = kin_v3(0, 0, 1);
    for (int f = 0; f < 5; f++) {
        float g = job->glove[f];
        float a[3];
        for (int j = 0; j < 3; j++)
            a[j] = p->open_deg[f][j] + g * (p->fist_deg[f][j] - p->open_deg[f][j]);
        if (f > 0 && p->dip_coupling > 0.0f) a[2] = p->dip_coupling * a[1];
        for (int j = 0; j < 3; j++) {
            int i = 3 * f + j;
            kin_quat rest = job->rest ? kin_quat_normalize(job->rest[i]) : kin_quat_identity();
            kin_quat r = kin_quat_mul(rest, kin_quat_axis_angle(X, -DEG2RAD(a[j])));
            if (f == 0 && j == 0) {
                float opp = p->thumb_opp_deg[0] + g * (p->thumb_opp_deg[1] - p->thumb_opp_deg[0]);
                r = kin_quat_mul(kin_quat_axis_angle(Z, s * DEG2RAD(opp)), r);
            }
            job->out[i] = kin_quat_normalize(r);
            if (job->angles_deg) job->angles_deg[i] = a[j];
        }
    }
    return 1;
}
