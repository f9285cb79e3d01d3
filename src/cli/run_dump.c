/* run_dump.c - `egofuse run --dump DIR`: the inputs of the last frame
 * written as a one-frame scene for `egofuse render` (run.h). Split from
 * cmd_run.c: a job of its own (files out, after the frame) that reads the
 * run's state only through run_dump_src. */
#include "run.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Copies a file byte for byte (to a temporary, renamed when complete). */
static int copy_file(const char *from, const char *to)
{
    char tmp[IO_PATH_MAX + 96];
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", to, (long)getpid());
    FILE *in = fopen(from, "rb");
    if (!in) return -1;
    FILE *o = fopen(tmp, "wb");
    if (!o) {
        fclose(in);
        return -1;
    }
    char buf[65536];
    size_t n;
    int bad = 0;
    while (!bad && (n = fread(buf, 1, sizeof buf, in)) > 0) bad = fwrite(buf, 1, n, o) != n;
    bad |= ferror(in);
    fclose(in);
    bad |= fclose(o) != 0;
    if (bad || rename(tmp, to) != 0) {
        int e = errno;
        unlink(tmp);
        errno = e ? e : EIO;
        return -1;
    }
    return 0;
}

int run_dump_frame(const run_opts *o, const run_dump_src *r, const pipe_frame_in *in,
                   const kin_track_sample *sample, int tracked, int W, int H)
{
    io_error err;
    if (io_mkdirs(o->dump) != 0)
        return io_term_fail("%s: cannot create the dump folder: %s", o->dump, strerror(errno));
    static const char *const eye[2] = {"left", "right"};
    for (int e = 0; e < 2; e++) {
        char p[IO_PATH_MAX + 64];
        snprintf(p, sizeof p, "%s/cam_%s_0000.png", o->dump, eye[e]);
        if (io_image_save(p, &r->camimg[e], &err) != IO_OK) return io_term_fail("%s", err.msg);
        io_image v = {in->virt[e].pixels, W, H, 4, IO_U8, (size_t)in->virt[e].stride};
        snprintf(p, sizeof p, "%s/virt_%s_0000.png", o->dump, eye[e]);
        if (io_image_save(p, &v, &err) != IO_OK) return io_term_fail("%s", err.msg);
        if (in->virt_depth[e] && in->virt_depth[e] != r->vdepth[e].data) {
            /* a live source's depth, as float EXR */
            io_image d = {(void *)in->virt_depth[e], W, H, 1, IO_F32,
                          (size_t)in->virt_depth_stride[e] * sizeof(float)};
            snprintf(p, sizeof p, "%s/virt_depth_%s_0000.exr", o->dump, eye[e]);
            if (io_image_save(p, &d, &err) != IO_OK) return io_term_fail("%s", err.msg);
        }
    }
    char path[IO_PATH_MAX + 64], tmp[IO_PATH_MAX + 96];
    if (tracked) {
        kin_track_sample s = *sample;
        s.t = 0;
        snprintf(path, sizeof path, "%s/track.txt", o->dump);
        if (io_track_save(path, &s, 1, &err) != IO_OK) return io_term_fail("%s", err.msg);
    }
    char model_abs[IO_PATH_MAX + 64];
    if (!realpath(r->model_path, model_abs)) snprintf(model_abs, sizeof model_abs, "%s", r->model_path);
    snprintf(path, sizeof path, "%s/scene.txt", o->dump);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) return io_term_fail("%s: %s", path, strerror(errno));
    int bad = fprintf(f,
                      "egofuse-scene 1\n# the last frame of egofuse run (--dump)\nmodel = %s\n"
                      "frames = 1\nfps = 60\ncamera_left = cam_left_%%04d.png\n"
                      "camera_right = cam_right_%%04d.png\nvirtual_left = virt_left_%%04d.png\n"
                      "virtual_right = virt_right_%%04d.png\n%s",
                      model_abs, tracked ? "tracking = track.txt\n" : "") < 0;
    for (int e = 0; e < 2; e++) {
        char dabs[IO_PATH_MAX + 64];
        if (in->virt_depth[e] && in->virt_depth[e] != r->vdepth[e].data) {
            bad |= fprintf(f, "virtual_depth_%s = virt_depth_%s_%%04d.exr\n", eye[e], eye[e]) < 0;
            continue;
        }
        if (!r->vdepth[e].data || !in->virt_depth[e]) continue;
        /* the still image's depth file, copied as it is (a frame pattern) */
        snprintf(dabs, sizeof dabs, "%s/virt_depth_%s_0000%s", o->dump, eye[e],
                 strrchr(r->vdepth_path[e], '.') ? strrchr(r->vdepth_path[e], '.') : "");
        if (copy_file(r->vdepth_path[e], dabs) != 0) {
            fclose(f);
            unlink(tmp);
            return io_term_fail("%s: cannot copy %s: %s", dabs, r->vdepth_path[e], strerror(errno));
        }
        bad |= fprintf(f, "virtual_depth_%s = virt_depth_%s_%%04d%s\n", eye[e], eye[e],
                       strrchr(dabs, '.') ? strrchr(dabs, '.') : "") < 0;
    }
    if (r->sc && r->sc->head_node[0]) bad |= fprintf(f, "head_node = %s\n", r->sc->head_node) < 0;
    {
        /* a named HMD other than the paper's (render follows the key; an
         * HMD of other numbers has no scene key yet) */
        const kin_sthmd_desc hd = kin_sthmd_desc_resolved(&o->hmd);
        kin_sthmd_desc nd;
        for (int k = 1; kin_sthmd_preset_name(k); k++)
            if (kin_sthmd_preset(kin_sthmd_preset_name(k), &nd) == 0 && !memcmp(&hd, &nd, sizeof hd))
                bad |= fprintf(f, "hmd = %s\n", kin_sthmd_preset_name(k)) < 0;
    }
    if (r->sc && r->sc->animation[0]) bad |= fprintf(f, "animation = %s\n", r->sc->animation) < 0;
    /* posed by the animation at the run's clock: that time (%.9g gives the
     * float back exactly; render poses frame 0 at it) */
    if (!tracked && in->anim) bad |= fprintf(f, "animation_start = %.9g\n", (double)in->time) < 0;
    if (r->sc && r->sc->has_lighting) {
        /* the lighting lines as written, so render parses the same floats */
        FILE *in = fopen(o->scene, "r");
        char line[4096];
        static const char *const keys[] = {"ambient", "light", "kd", "ks", "shininess", "kf", "tone", NULL};
        while (in && fgets(line, sizeof line, in)) {
            const char *t = line + strspn(line, " \t");
            for (int k = 0; keys[k]; k++) {
                size_t n = strlen(keys[k]);
                if (!strncmp(t, keys[k], n) && strchr(" \t=", t[n])) {
                    bad |= fputs(line, f) == EOF;
                    break;
                }
            }
        }
        if (in) fclose(in);
        else bad = 1;
    }
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return io_term_fail("%s: %s", path, strerror(e ? e : EIO));
    }
    snprintf(path, sizeof path, "%s/command.txt", o->dump);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    f = fopen(tmp, "w");
    if (!f) return io_term_fail("%s: %s", path, strerror(errno));
    bad = fprintf(f, "egofuse render --scene %s/scene.txt --out OUT%s%s%s", o->dump,
                  tracked ? " --pose tracking --no-filter" : "", o->calib ? " --calib " : "",
                  o->calib ? o->calib : "") < 0;
    /* the lenses: render draws the masks through the same ones */
    static const char *const calib_opt[3] = {"", "-left", "-right"};
    for (int k = 0; k < 3; k++)
        if (o->hmd_calib[k]) bad |= fprintf(f, " --hmd-calibration%s %s", calib_opt[k], o->hmd_calib[k]) < 0;
    if (o->hide) {
        static const char *const part[4] = {"left-hand", "left-arm", "right-hand", "right-arm"};
        int first = 1;
        bad |= fputs(" --hide ", f) == EOF;
        for (int k = 0; k < 4; k++)
            if (o->hide & (1u << k)) {
                bad |= fprintf(f, "%s%s", first ? "" : ",", part[k]) < 0;
                first = 0;
            }
    }
    for (int k = 0; k < o->prop_count; k++) {
        const run_prop *p = &o->prop[k];
        if (p->body[0] || p->rot_deg[1] != 0 || p->rot_deg[2] != 0)
            bad |= fprintf(f, " # prop %s is tracked or tilted: render cannot place it", p->name) < 0;
        else
            bad |= fprintf(f, " --prop %s@%.9g,%.9g,%.9g,%.9g", p->model, (double)p->at[0],
                           (double)p->at[1], (double)p->at[2], (double)p->rot_deg[0]) < 0;
    }
    if (o->lod == PIPE_LOD_AUTO)
        bad |= fprintf(f, " --lod auto --lod-px %.9g", (double)o->lod_px) < 0;
    else if (o->lod) bad |= fprintf(f, " --lod %d", o->lod) < 0;
    if (o->aa) bad |= fprintf(f, " --aa %d", o->aa) < 0;
    if (o->edge_fade) bad |= fprintf(f, " --edge-fade %d", o->edge_fade < 0 ? 0 : o->edge_fade) < 0;
    bad |= fprintf(f, o->soft_edge ? " --soft-edges" : " --hard-edges") < 0;
    if (o->refine) bad |= fprintf(f, " --refine %d # the elbow fit's learned state differs", o->refine) < 0;
    bad |= fputc('\n', f) == EOF;
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return io_term_fail("%s: %s", path, strerror(e ? e : EIO));
    }
    return EXIT_OK;
}

