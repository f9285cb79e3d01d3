/* cmd_run.c - `egofuse run`: the live cockpit. Two cameras (V4L2, paired
 * by time stamp, or recorded frames for a dry run), the pose from a
 * tracker (egofuse's UDP stream or OptiTrack NatNet, through the One Euro
 * filter, posed at the cameras' time stamp) or the model's animation, the
 * data gloves, the virtual scene (a still image or a live source), then
 * pipe_frame per stereo pair; output to the HMD's displays (KMS), a
 * window, PNG files or raw frames on stdout. Every frame's stage times and
 * latencies go to the status line (median, p99) and to --stats FILE.
 * A camera that fails is reopened once a second (found again by its
 * selector); meanwhile its eye holds its last image. docs/cockpit.md,
 * docs/devices.md. */
#include "run.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../io/io_dev.h"
#include "../io/io_live.h"
#include "../pipe/pipe.h"

static volatile sig_atomic_t stop_flag;
static void on_signal(int s)
{
    (void)s;
    stop_flag = 1;
}

static uint64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

/* Resolves a camera selector to a /dev/videoN path. */
static int resolve(const char *sel, char *path, size_t n, io_error *err)
{
    if (!strncmp(sel, "/dev/", 5)) {
        snprintf(path, n, "%s", sel);
        return 0;
    }
    if (io_usb_selector_check(sel, err) != IO_OK) return -1;
    io_usb_dev d[64];
    int nd = 0;
    if (io_usb_list(d, 64, &nd, err) != IO_OK) return -1;
    if (nd > 64) nd = 64;
    for (int i = 0; i < nd; i++)
        if (io_usb_match(&d[i], sel)) {
            if (!d[i].video[0]) {
                io_fail(err, IO_ERR_NOT_FOUND, "%s: USB device %s (%04x:%04x) has no video node",
                        sel, d[i].port_path, d[i].vid, d[i].pid);
                return -1;
            }
            snprintf(path, n, "%s", d[i].video);
            return 0;
        }
    io_fail(err, IO_ERR_NOT_FOUND, "%s: no USB device matches ('egofuse devices' lists them)", sel);
    return -1;
}

static int no_cameras(const char *why)
{
    fprintf(stderr,
            "egofuse run: no cameras found%s%s.\n"
            "  Plug in the HMD's two cameras ('egofuse devices' lists what is seen), or\n"
            "  make a dry run from recorded camera frames or a video:\n"
            "    egofuse run --scene FILE --left file:cam_left_%%04d.png --right "
            "file:cam_right_%%04d.png\n"
            "  or composite recorded input offline:\n"
            "    egofuse render --scene FILE --out DIR   (docs/scene.md)\n"
            "    egofuse demo                            (the bundled samples)\n",
            why ? ": " : "", why ? why : "");
    return EXIT_FAIL;
}

static int load_virt(const char *path, int w, int h, io_image *img)
{
    io_error err;
    if (io_image_load(path, IO_U8, 4, img, &err) != IO_OK) return cli_fail("%s", err.msg);
    if (img->width != w || img->height != h) {
        io_image_free(img);
        return cli_fail("%s: virtual image is %dx%d, expected %dx%d", path, img->width, img->height,
                        w, h);
    }
    return EXIT_OK;
}

/* The tracker's clock mapped onto CLOCK_MONOTONIC: offset = the smallest
 * (arrival - sample time) seen (the fastest delivery), re-learned when the
 * filter restarts. */
typedef struct track_clock {
    int have;
    double offset_s;
} track_clock;

static double track_local_time(track_clock *c, double t_sample, double t_arrival, int restart)
{
    double off = t_arrival - t_sample;
    if (!c->have || restart || off < c->offset_s) {
        c->offset_s = off;
        c->have = 1;
    }
    return t_sample + c->offset_s;
}

/* Everything a run holds, released by run_close. */
typedef struct run_state {
    io_scene sc;
    int have_scene;
    kin_model model;
    int have_model;
    pipe_ctx *pipe;
    io_image virt[2], outimg[2], camimg[2];
    io_image vdepth[2];       /* the still virtual images' depth, if any */
    char vdepth_path[2][IO_PATH_MAX + 64];
    io_cam cam[2];
    io_glove glove[2];
    int have_glove[2];
    io_track_udp udp;
    kin_arm_rig rig;
    kin_transform *locals;
    kin_user_calib ucal;
    kin_filter filter;
    track_clock tclock;
    uint8_t *rawbuf;
    io_stats_log stats;
    char model_path[IO_PATH_MAX + 64];
} run_state;

static void run_close(run_state *r)
{
    for (int e = 0; e < 2; e++) {
        io_cam_close(&r->cam[e]);
        io_glove_close(&r->glove[e]);
        io_image_free(&r->virt[e]);
        io_image_free(&r->outimg[e]);
        io_image_free(&r->camimg[e]);
        io_image_free(&r->vdepth[e]);
    }
    if (r->udp.fd >= 0) io_track_udp_close(&r->udp);
    io_stats_abandon(&r->stats);
    free(r->locals);
    free(r->rawbuf);
    if (r->pipe) pipe_destroy(r->pipe);
    if (r->have_model) kin_model_free(&r->model);
}

static int write_outputs(const run_opts *o, run_state *r, int frame, int W, int H)
{
    io_error err;
    if (o->out) {
        static const char *const eye[2] = {"left", "right"};
        for (int e = 0; e < 2; e++) {
            char p[IO_PATH_MAX + 64];
            snprintf(p, sizeof p, "%s/%s_%04d.png", o->out, eye[e], frame);
            if (io_image_save(p, &r->outimg[e], &err) != IO_OK) return cli_fail("%s", err.msg);
        }
    }
    if (o->raw) {
        uint8_t *d = r->rawbuf;
        for (int e = 0; e < 2; e++)
            for (int y = 0; y < H; y++) {
                const uint8_t *s = (const uint8_t *)r->outimg[e].data + (size_t)y * r->outimg[e].stride;
                for (int x = 0; x < W; x++, d += 3) {
                    d[0] = s[4 * x];
                    d[1] = s[4 * x + 1];
                    d[2] = s[4 * x + 2];
                }
            }
        size_t n = (size_t)W * (size_t)H * 6;
        if (fwrite(r->rawbuf, 1, n, stdout) != n || fflush(stdout) != 0)
            return cli_fail("stdout: write error: %s (reader gone?)", strerror(errno));
    }
    return EXIT_OK;
}

/* --dump DIR: the inputs of the last frame as a one-frame scene that
 * `egofuse render` composites to the same bytes (camera images as
 * converted, the virtual images used, the pose sample used; the scene's
 * lighting lines copied verbatim). With --refine the elbow fit's learned
 * state is not part of it, so render differs there. */
static int dump_frame(const run_opts *o, run_state *r, const kin_track_sample *sample,
                      int tracked, int W, int H)
{
    io_error err;
    if (cli_mkdirs(o->dump) != 0)
        return cli_fail("%s: cannot create the dump folder: %s", o->dump, strerror(errno));
    static const char *const eye[2] = {"left", "right"};
    for (int e = 0; e < 2; e++) {
        char p[IO_PATH_MAX + 64];
        snprintf(p, sizeof p, "%s/cam_%s_0000.png", o->dump, eye[e]);
        if (io_image_save(p, &r->camimg[e], &err) != IO_OK) return cli_fail("%s", err.msg);
        io_image v = r->virt[e];
        v.width = W;
        v.height = H;
        snprintf(p, sizeof p, "%s/virt_%s_0000.png", o->dump, eye[e]);
        if (io_image_save(p, &v, &err) != IO_OK) return cli_fail("%s", err.msg);
    }
    char path[IO_PATH_MAX + 64], tmp[IO_PATH_MAX + 96];
    if (tracked) {
        kin_track_sample s = *sample;
        s.t = 0;
        snprintf(path, sizeof path, "%s/track.txt", o->dump);
        if (io_track_save(path, &s, 1, &err) != IO_OK) return cli_fail("%s", err.msg);
    }
    char model_abs[IO_PATH_MAX + 64];
    if (!realpath(r->model_path, model_abs)) snprintf(model_abs, sizeof model_abs, "%s", r->model_path);
    snprintf(path, sizeof path, "%s/scene.txt", o->dump);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) return cli_fail("%s: %s", path, strerror(errno));
    int bad = fprintf(f,
                      "egofuse-scene 1\n# the last frame of egofuse run (--dump)\nmodel = %s\n"
                      "frames = 1\nfps = 60\ncamera_left = cam_left_%%04d.png\n"
                      "camera_right = cam_right_%%04d.png\nvirtual_left = virt_left_%%04d.png\n"
                      "virtual_right = virt_right_%%04d.png\n%s",
                      model_abs, tracked ? "tracking = track.txt\n" : "") < 0;
    for (int e = 0; e < 2; e++) {
        char dabs[IO_PATH_MAX + 64];
        if (!r->vdepth[e].data) continue;
        if (!realpath(r->vdepth_path[e], dabs)) snprintf(dabs, sizeof dabs, "%s", r->vdepth_path[e]);
        bad |= fprintf(f, "virtual_depth_%s = %s\n", eye[e], dabs) < 0;
    }
    if (r->have_scene && r->sc.head_node[0]) bad |= fprintf(f, "head_node = %s\n", r->sc.head_node) < 0;
    if (r->have_scene && r->sc.animation[0]) bad |= fprintf(f, "animation = %s\n", r->sc.animation) < 0;
    if (r->have_scene && r->sc.has_lighting) {
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
        return cli_fail("%s: %s", path, strerror(e ? e : EIO));
    }
    snprintf(path, sizeof path, "%s/command.txt", o->dump);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    f = fopen(tmp, "w");
    if (!f) return cli_fail("%s: %s", path, strerror(errno));
    bad = fprintf(f, "egofuse render --scene %s/scene.txt --out OUT%s%s%s%s%s\n", o->dump,
                  tracked ? " --pose tracking --no-filter" : "", o->calib ? " --calib " : "",
                  o->calib ? o->calib : "", o->hide ? " --hide " : "", o->hide ? "(as run)" : "") < 0;
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return cli_fail("%s: %s", path, strerror(e ? e : EIO));
    }
    return EXIT_OK;
}

static int run(const run_opts *o)
{
    io_error err;
    int rc = EXIT_FAIL;
    /* ---- cameras first: without them nothing else matters */
    char path[2][IO_CAM_NAME_MAX];
    if (o->sel[0]) {
        for (int e = 0; e < 2; e++) {
            if (!strncmp(o->sel[e], "file:", 5)) {
                snprintf(path[e], sizeof path[e], "%s", o->sel[e]);
                continue;
            }
            if (resolve(o->sel[e], path[e], sizeof path[e], &err) != 0) return no_cameras(err.msg);
        }
    } else {
        io_cam_info ci[64];
        int n = 0, k = 0;
        io_cam_list(NULL, ci, 64, &n, &err);
        for (int i = 0; i < n && i < 64 && k < 2; i++)
            if (ci[i].capture) snprintf(path[k++], sizeof path[0], "%.63s", ci[i].path);
        if (k < 2) {
            char why[128];
            snprintf(why, sizeof why, "%d video capture node%s in /dev, 2 needed", k,
                     k == 1 ? "" : "s");
            return no_cameras(why);
        }
    }

    if (!o->scene && !o->model)
        return cli_usage_error("run", "--scene or --model is required (the arm model to mask)");

    run_state *r = calloc(1, sizeof *r);
    if (!r) return cli_fail("out of memory");
    r->cam[0].fd = r->cam[1].fd = -1;
    r->udp.fd = -1;
    r->ucal = kin_user_calib_identity();

    /* ---- model, scene, virtual images */
    char model_path[IO_PATH_MAX + 64];
    if (o->scene) {
        if (io_scene_load(o->scene, &r->sc, &err) != IO_OK) {
            cli_fail("%s", err.msg);
            goto done;
        }
        r->have_scene = 1;
        io_scene_frame_path(&r->sc, r->sc.model, 0, model_path, sizeof model_path);
    }
    if (o->model) snprintf(model_path, sizeof model_path, "%s", o->model);
    if (io_gltf_load(model_path, &r->model, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        goto done;
    }
    r->have_model = 1;
    snprintf(r->model_path, sizeof r->model_path, "%s", model_path);
    kin_model *model = &r->model;
    const kin_animation *anim = model->anim_count ? &model->anims[0] : NULL;
    if (r->have_scene && r->sc.animation[0])
        for (int i = 0; i < model->anim_count; i++)
            if (!strcmp(model->anims[i].name, r->sc.animation)) anim = &model->anims[i];
    int head = kin_model_find_node(model, r->have_scene && r->sc.head_node[0] ? r->sc.head_node
                                                                             : "head");

    pipe_desc pd;
    memset(&pd, 0, sizeof pd);
    pd.hmd = o->hmd;
    kin_sthmd_desc hd = kin_sthmd_desc_resolved(&o->hmd);
    const int W = hd.lcd_width, H = hd.lcd_height;
    for (int e = 0; e < 2; e++) {
        char vp[IO_PATH_MAX + 64];
        const char *vpath = o->virt[e];
        if (!vpath && r->have_scene && !o->virt_source) {
            io_scene_frame_path(&r->sc, r->sc.virt[e], 0, vp, sizeof vp);
            vpath = vp;
        }
        if (vpath) {
            if (load_virt(vpath, W, H, &r->virt[e])) goto done;
            if (!o->virt[e] && r->sc.virt_depth[e][0]) {
                /* the scene's depth of that image: virtual objects in front
                 * of the hands hide them */
                io_scene_frame_path(&r->sc, r->sc.virt_depth[e], 0, r->vdepth_path[e],
                                    sizeof r->vdepth_path[e]);
                if (io_image_load(r->vdepth_path[e], IO_F32, 1, &r->vdepth[e], &err) != IO_OK) {
                    cli_fail("%s", err.msg);
                    goto done;
                }
                if (r->vdepth[e].width != W || r->vdepth[e].height != H) {
                    cli_fail("%s: virtual depth image is %dx%d, expected %dx%d", r->vdepth_path[e],
                             r->vdepth[e].width, r->vdepth[e].height, W, H);
                    goto done;
                }
            }
        } else if (io_image_alloc(&r->virt[e], W, H, 4, IO_U8, &err) == IO_OK) {
            /* plain grey, opaque (until a live source delivers) */
            for (int y = 0; y < H; y++) {
                uint8_t *row = (uint8_t *)r->virt[e].data + (size_t)y * r->virt[e].stride;
                for (int x = 0; x < W; x++) {
                    row[4 * x + 0] = row[4 * x + 1] = row[4 * x + 2] = 96;
                    row[4 * x + 3] = 255;
                }
            }
        } else {
            cli_fail("%s", err.msg);
            goto done;
        }
        if (io_image_alloc(&r->outimg[e], W, H, 4, IO_U8, &err) != IO_OK ||
            io_image_alloc(&r->camimg[e], hd.cam_width, hd.cam_height, 4, IO_U8, &err) != IO_OK) {
            cli_fail("%s", err.msg);
            goto done;
        }
    }
    if (o->raw && !(r->rawbuf = malloc((size_t)W * (size_t)H * 6))) {
        cli_fail("out of memory");
        goto done;
    }
    int tracked = o->track_port != 0;
    if (tracked) {
        char why[256];
        if (kin_arm_rig_init(&r->rig, model, why, sizeof why) != 0) {
            cli_fail("%s: cannot follow the tracking stream: %s", model_path, why);
            goto done;
        }
        if (!(r->locals = malloc(sizeof(kin_transform) * (size_t)model->node_count))) {
            cli_fail("out of memory");
            goto done;
        }
        kin_filter_init(&r->filter, NULL);
    }
    if (o->track_port &&
        io_track_udp_listen(&r->udp, o->track_addr, o->track_port, &err) != IO_OK) {
        cli_fail("tracking stream: %s", err.msg);
        goto done;
    }
    if (o->calib && io_user_calib_load(o->calib, &r->ucal, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        goto done;
    }
    for (int e = 0; e < 2; e++) {
        if (!o->glove_sel[e]) continue;
        const char *gs = strcmp(o->glove_sel[e], "any") ? o->glove_sel[e] : NULL;
        if (io_glove_open(&r->glove[e], gs, &err) != IO_OK) {
            cli_fail("%s glove: %s", e ? "right" : "left", err.msg);
            goto done;
        }
        r->have_glove[e] = 1;
        r->glove[e].side = e;
        if (r->ucal.has_glove[e]) io_glove_set_calib(&r->glove[e], &r->ucal.glove[e]);
    }

    /* ---- cameras */
    for (int e = 0; e < 2; e++) {
        io_cam_config c = io_cam_config_default(path[e]);
        c.width = hd.cam_width;
        c.height = hd.cam_height;
        c.fourcc = o->fourcc;
        c.fps = o->fps;
        c.input = o->input;
        c.dv_timings = o->dv;
        c.buffers = o->buffers;
        if (io_cam_open(&r->cam[e], &io_cam_v4l2, &c, &err) != IO_OK ||
            io_cam_start(&r->cam[e], &err) != IO_OK) {
            cli_fail("%s camera: %s", e ? "right" : "left", err.msg);
            goto done;
        }
    }
    pd.refine_band = o->refine;
    pd.fit_rig = o->refine && tracked ? &r->rig : NULL;
    if (!(r->pipe = pipe_create(&pd, model))) {
        cli_fail(pd.fit_rig ? "cannot start the pipeline (out of memory, no thread, or the elbow "
                              "fit cannot use the model: mesh 0's skin, the arms' node chains)"
                            : "cannot start the pipeline (out of memory or no thread)");
        goto done;
    }
    if (o->out && cli_mkdirs(o->out) != 0) {
        cli_fail("%s: cannot create the output folder: %s", o->out, strerror(errno));
        goto done;
    }
    if (o->stats && io_stats_open(&r->stats, o->stats, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        goto done;
    }
    if (!o->quiet) {
        char fs[5];
        fprintf(stderr, "egofuse run: left %s (%s), right %s (%s), %s %dx%d at %d/%d s\n",
                r->cam[0].cfg.path, r->cam[0].card, r->cam[1].cfg.path, r->cam[1].card,
                io_fourcc_str(r->cam[0].fourcc, fs), r->cam[0].width, r->cam[0].height,
                r->cam[0].fps_den, r->cam[0].fps_num);
    }

    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN); /* a reader gone is a write error, reported */
    io_stereo st;
    io_stereo_init(&st, &r->cam[0], &r->cam[1], 0);
    pipe_frame_in in;
    memset(&in, 0, sizeof in);
    in.lighting = pipe_lighting_default();
    if (r->have_scene) in.lighting.light = io_scene_lighting(&r->sc); /* the scene's lights */
    in.head_node = head;
    kin_mat4 ident = kin_mat4_identity();
    in.world_from_head = &ident;
    for (int e = 0; e < 2; e++) {
        in.camera[e] = (fuse_image){r->camimg[e].data, r->camimg[e].width, r->camimg[e].height,
                                    (int)r->camimg[e].stride};
        in.virt[e] = (fuse_image){r->virt[e].data, W, H, (int)r->virt[e].stride};
        in.out[e] = (fuse_image){r->outimg[e].data, W, H, (int)r->outimg[e].stride};
        if (r->vdepth[e].data) {
            in.virt_depth[e] = r->vdepth[e].data;
            in.virt_depth_stride[e] = (int)(r->vdepth[e].stride / sizeof(float));
        }
    }
    /* Still virtual images: checked once. Opaque (the grey fallback is),
     * the composite copies V where the hand is not without reading its
     * alpha. */
    const kin_sthmd_geometry geo = pipe_geometry(r->pipe);
    in.virt_opaque = pipe_image_opaque(&in.virt[0], geo.vp_x0, geo.vp_y0, geo.vp_width,
                                       geo.vp_height) &&
                     pipe_image_opaque(&in.virt[1], geo.vp_x0, geo.vp_y0, geo.vp_width,
                                       geo.vp_height);
    kin_track_sample sample;
    memset(&sample, 0, sizeof sample);
    int have_pose = 0, have_img[2] = {0, 0};
    uint64_t t_start = mono_ns(), t_status = t_start, t_retry[2] = {0, 0}, t_track = 0;
    io_lat lat_cam, lat_pipe;
    io_lat_reset(&lat_cam);
    io_lat_reset(&lat_pipe);
    int frames = 0, frames_status = 0;
    uint64_t track_bad = 0;
    while (!stop_flag && (o->frames == 0 || frames < o->frames)) {
        io_frame fr[2];
        int got = 0;
        io_result gr = io_stereo_grab(&st, 200, fr, &got, &err);
        uint64_t now = mono_ns();
        /* a failed camera: reopen once a second, found again by its selector */
        for (int e = 0; e < 2; e++) {
            if (r->cam[e].state != IO_CAM_FAILED || now - t_retry[e] < 1000000000ull) continue;
            t_retry[e] = now;
            char np[IO_CAM_NAME_MAX];
            io_error e2;
            const char *where = NULL;
            if (o->sel[e] && resolve(o->sel[e], np, sizeof np, &e2) == 0) where = np;
            if (io_cam_reopen(&r->cam[e], where, &e2) == IO_OK && !o->quiet)
                fprintf(stderr, "\negofuse run: %s camera back (%s)\n", e ? "right" : "left",
                        r->cam[e].cfg.path);
        }
        if (gr != IO_OK) {
            if (!o->quiet) fprintf(stderr, "\regofuse run: %s (retrying)   ", err.msg);
            struct timespec ts = {0, 200000000};
            nanosleep(&ts, NULL);
            continue;
        }
        if (!got) continue;
        io_frame_log lg;
        memset(&lg, 0, sizeof lg);
        lg.frame = (uint64_t)frames;
        lg.t_dequeue = now;
        lg.v_age_ms = -1;
        lg.track_age_ms = -1;
        for (int e = 0; e < 2; e++) {
            if (!(got & (1 << e))) continue;
            if (io_frame_to_rgba(&fr[e], r->camimg[e].data, r->camimg[e].stride, &err) == IO_OK)
                have_img[e] = 1;
            else if (!o->quiet)
                fprintf(stderr, "\regofuse run: %s   ", err.msg);
            if (e == 0) lg.t_cam_l = fr[e].t_ns;
            else lg.t_cam_r = fr[e].t_ns;
        }
        if (got == 3) io_stereo_release(&st, fr, NULL);
        else
            for (int e = 0; e < 2; e++)
                if (got & (1 << e)) io_cam_release(&r->cam[e], &fr[e], NULL);
        if (!have_img[0] || !have_img[1]) continue; /* the other eye holds its last image */
        if (got == 3) lg.skew_ms = 1e-6 * ((double)lg.t_cam_r - (double)lg.t_cam_l);
        uint64_t t_cam = lg.t_cam_l > lg.t_cam_r ? lg.t_cam_l : lg.t_cam_r;

        /* ---- pose: tracking stream (+ gloves) through the filter, posed
         * at the cameras' time; else the animation */
        for (int e = 0; e < 2; e++) {
            int fresh;
            if (r->have_glove[e] && io_glove_poll(&r->glove[e], 0, &fresh, &err) != IO_OK) {
                if (!o->quiet) fprintf(stderr, "\regofuse run: %s   ", err.msg);
                r->have_glove[e] = 0;
            }
        }
        in.locals = NULL;
        in.anim = anim;
        in.time = 1e-9f * (float)(now - t_start);
        if (tracked) {
            kin_track_sample s;
            int fresh = 0;
            double t_arr = 1e-9 * (double)mono_ns();
            if (r->udp.fd >= 0) {
                if (io_track_udp_poll(&r->udp, 0, &s, &fresh, &err) != IO_OK) track_bad++;
            }
            if (fresh && s.valid) {
                int fr_bits = kin_filter_push(&r->filter, &s);
                double tl = track_local_time(&r->tclock, s.t, t_arr, fr_bits & KIN_FILTER_RESTART);
                (void)tl;
                t_track = (uint64_t)((s.t + r->tclock.offset_s) * 1e9);
                have_pose = 1;
            }
            if (have_pose) {
                /* the pose when the cameras took their pictures */
                double t_pose = 1e-9 * (double)t_cam + 1e-3 * o->predict_ms - r->tclock.offset_s;
                kin_filter_output(&r->filter, t_pose, &sample, NULL);
                for (int e = 0; e < 2; e++)
                    if (r->have_glove[e]) io_glove_to_sample(&r->glove[e], &sample);
                kin_pose_rest(model, r->locals);
                if (kin_arm_rig_pose(&r->rig, model, &r->ucal, NULL, &sample, r->locals, NULL))
                    in.locals = r->locals;
                in.fit_skip = ((sample.valid & KIN_TRACK_HAND_L) ? 0u : 1u) |
                              ((sample.valid & KIN_TRACK_HAND_R) ? 0u : 2u);
                lg.track_age_ms = t_track ? 1e-6 * ((double)t_cam - (double)t_track) : -1;
            }
        }
        char why[256];
        pipe_frame_stats ps;
        lg.t_start = mono_ns();
        pipe_result pr = pipe_frame(r->pipe, &in, &ps, why, (int)sizeof why);
        lg.t_done = mono_ns();
        if (pr != PIPE_OK) {
            cli_fail("frame %d: %s", frames, why);
            goto done;
        }
        lg.ms_pose = ps.ms_pose;
        for (int e = 0; e < 2; e++) {
            lg.ms_raster[e] = ps.ms_raster[e];
            lg.ms_fuse[e] = ps.ms_fuse[e];
        }
        lg.ms_total = ps.ms_total;
        /* ---- output */
        lg.t_present = mono_ns();
        if (write_outputs(o, r, frames, W, H) != EXIT_OK) goto done;
        lg.t_shown = mono_ns();
        io_stats_row(&r->stats, &lg);
        if (o->dump && frames + 1 == o->frames &&
            dump_frame(o, r, &sample, tracked && have_pose, W, H) != EXIT_OK)
            goto done;
        io_lat_push(&lat_cam, 1e-6 * ((double)lg.t_shown - (double)t_cam));
        io_lat_push(&lat_pipe, ps.ms_total);
        frames++;
        frames_status++;
        now = mono_ns();
        if (!o->quiet && (now - t_status >= 1000000000ull || frames == o->frames)) {
            fprintf(stderr,
                    "\regofuse run: %d frames, %.1f FPS, camera to output %.1f / %.1f ms (median "
                    "/ p99), pipe %.1f / %.1f ms, dropped %llu/%llu, unpaired %llu/%llu, skew "
                    "%.2f ms%s%s   ",
                    frames, frames_status / (1e-9 * (double)(now - t_status)),
                    io_lat_quantile(&lat_cam, 0.5), io_lat_quantile(&lat_cam, 0.99),
                    io_lat_quantile(&lat_pipe, 0.5), io_lat_quantile(&lat_pipe, 0.99),
                    (unsigned long long)r->cam[0].stats.dropped,
                    (unsigned long long)r->cam[1].stats.dropped,
                    (unsigned long long)st.unpaired[0], (unsigned long long)st.unpaired[1],
                    1e-6 * (double)st.last_skew_ns,
                    st.failed[0] || st.failed[1] ? ", one eye held" : "",
                    tracked && !have_pose ? ", no pose yet" : "");
            t_status = now;
            frames_status = 0;
        }
    }
    if (!o->quiet) fputc('\n', stderr);
    if (io_stats_close(&r->stats, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        goto done;
    }
    /* stdout carries the frames with --raw */
    fprintf(o->raw ? stderr : stdout,
            "egofuse run: %d stereo frames, %llu pairs, dropped %llu/%llu, unpaired %llu/%llu, "
            "max skew %.2f ms, reopens %llu/%llu, camera to output %.2f / %.2f ms (median / p99)\n",
            frames, (unsigned long long)st.pairs, (unsigned long long)r->cam[0].stats.dropped,
            (unsigned long long)r->cam[1].stats.dropped, (unsigned long long)st.unpaired[0],
            (unsigned long long)st.unpaired[1], 1e-6 * (double)st.max_abs_skew_ns,
            (unsigned long long)r->cam[0].stats.reopens, (unsigned long long)r->cam[1].stats.reopens,
            io_lat_quantile(&lat_cam, 0.5), io_lat_quantile(&lat_cam, 0.99));
    io_stereo_flush(&st);
    rc = EXIT_OK;
done:
    run_close(r);
    free(r);
    return rc;
}

int cmd_run(int argc, char **argv)
{
    run_opts o;
    int rc = run_parse(argc, argv, &o);
    if (rc >= 0) return rc;
    rc = run(&o);
    run_opts_free(&o);
    return rc;
}
