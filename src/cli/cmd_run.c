/* cmd_run.c - `egofuse run`: the live pipeline. Two V4L2 cameras (paired
 * by time stamp), the pose from the tracking stream (UDP) or the model's
 * animation, the data gloves, then pipe_frame per stereo pair; output to
 * PNG files or a raw RGB24 stream on stdout, a status line on stderr.
 * A camera that fails is reopened once a second (found again by its
 * selector, so a replug onto another /dev/videoN is followed); meanwhile
 * its eye holds its last image. docs/devices.md. */
#include "cli.h"

#include <getopt.h>
#include <signal.h>
#include <stdlib.h>
#include <errno.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../io/io_dev.h"
#include "../pipe/pipe.h"

static const char *run_usage =
    "usage: egofuse run (--scene FILE | --model FILE) [--left SEL --right SEL]\n"
    "                   [--out DIR | --raw] [--frames N] [options]\n"
    "\n"
    "Composites the live stereo cameras: each pair of frames (matched by\n"
    "kernel time stamp) is lit inside the mask of the posed arm model and\n"
    "composited over the virtual scene, per eye 1280x800.\n"
    "\n"
    "  --scene FILE     model, animation, head node, lighting and virtual\n"
    "                   images (frame 0) from a scene file (docs/scene.md)\n"
    "  --model FILE     glTF model (head node 'head' if it has one)\n"
    "  --virt L,R       virtual scene images (default: the scene's, or grey)\n"
    "  --left SEL       left camera: /dev/videoN, serial:SN, port:1-2.3 or\n"
    "  --right SEL      id:VVVV:PPPP ('egofuse devices' shows them); default:\n"
    "                   the first two capture nodes\n"
    "  --format F       YUYV (default), GREY, BA81, RGGB, GBRG, GRBG\n"
    "  --fps N          frame rate asked (default 60)\n"
    "  --input N        V4L2 input to select\n"
    "  --dv             the input takes DV timings (HDMI): 640x480 at --fps\n"
    "  --buffers N      mmap buffers per camera (default 4)\n"
    "  --track-port P   pose from the UDP tracking stream on 127.0.0.1:P\n"
    "                   (docs/tracking.md); default: the model's animation\n"
    "  --glove-left SEL, --glove-right SEL   5DT gloves (SEL as above, or any)\n"
    "  --calib FILE     user calibration (egofuse-calib 1) for the gloves\n"
    "  --out DIR        write DIR/left_NNNN.png and DIR/right_NNNN.png\n"
    "  --raw            write rgb24 frames, left above right (1280x1600), on\n"
    "                   stdout: | ffplay -f rawvideo -pixel_format rgb24\n"
    "                   -video_size 1280x1600 -\n"
    "  --frames N       stop after N stereo frames (default: until Ctrl-C)\n"
    "  --refine BAND    refine the masks by colour in a band of BAND px (1..64,\n"
    "                   16 in `egofuse eval`) around their edges; with\n"
    "                   --track-port the elbows are first fitted to the\n"
    "                   camera images (eval's method refine)\n"
    "  --quiet          no status line\n"
    "  -h, --help       this text\n"
    "\n"
    "Without cameras, composite recorded input instead:\n"
    "  egofuse render --scene FILE --out DIR   (egofuse demo for the samples)\n";

typedef struct run_opts {
    const char *scene, *model, *virt[2], *sel[2], *glove_sel[2], *calib, *out;
    uint32_t fourcc;
    int fps, input, dv, buffers, track_port, raw, frames, quiet;
    int refine;             /* refinement band, px; 0 = off */
} run_opts;

static volatile sig_atomic_t stop_flag;
static void on_signal(int s)
{
    (void)s;
    stop_flag = 1;
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
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
            "  Plug in the HMD's two cameras (egofuse devices lists what is seen), or\n"
            "  composite recorded input instead:\n"
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

static int run(const run_opts *o)
{
    io_error err;
    int rc = EXIT_FAIL;
    /* ---- cameras first: without them nothing else matters */
    char path[2][IO_CAM_NAME_MAX];
    if (o->sel[0]) {
        for (int e = 0; e < 2; e++)
            if (resolve(o->sel[e], path[e], sizeof path[e], &err) != 0)
                return no_cameras(err.msg);
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

    /* ---- model, scene, virtual images */
    io_scene sc;
    int have_scene = 0;
    char model_path[IO_PATH_MAX + 64];
    if (o->scene) {
        if (io_scene_load(o->scene, &sc, &err) != IO_OK) return cli_fail("%s", err.msg);
        have_scene = 1;
        io_scene_frame_path(&sc, sc.model, 0, model_path, sizeof model_path);
    } else {
        snprintf(model_path, sizeof model_path, "%s", o->model);
    }
    kin_model model;
    if (io_gltf_load(model_path, &model, &err) != IO_OK) return cli_fail("%s", err.msg);
    const kin_animation *anim = model.anim_count ? &model.anims[0] : NULL;
    if (have_scene && sc.animation[0])
        for (int i = 0; i < model.anim_count; i++)
            if (!strcmp(model.anims[i].name, sc.animation)) anim = &model.anims[i];
    int head = kin_model_find_node(&model, have_scene && sc.head_node[0] ? sc.head_node : "head");

    pipe_desc pd;
    memset(&pd, 0, sizeof pd);
    pipe_ctx *pipe = NULL;
    io_image virt[2], outimg[2], camimg[2];
    memset(virt, 0, sizeof virt);
    memset(outimg, 0, sizeof outimg);
    memset(camimg, 0, sizeof camimg);
    io_cam cam[2];
    memset(cam, 0, sizeof cam);
    cam[0].fd = cam[1].fd = -1;
    io_glove glove[2];
    memset(glove, 0, sizeof glove);
    int have_glove[2] = {0, 0};
    io_track_udp udp;
    memset(&udp, 0, sizeof udp);
    udp.fd = -1;
    kin_arm_rig rig;
    kin_transform *locals = NULL;
    kin_user_calib ucal = kin_user_calib_identity();
    uint8_t *rawbuf = NULL;

    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    const int W = hd.lcd_width, H = hd.lcd_height;
    for (int e = 0; e < 2; e++) {
        char vp[IO_PATH_MAX + 64];
        const char *vpath = o->virt[e];
        if (!vpath && have_scene) {
            io_scene_frame_path(&sc, sc.virt[e], 0, vp, sizeof vp);
            vpath = vp;
        }
        if (vpath) {
            if (load_virt(vpath, W, H, &virt[e])) goto done;
        } else if (io_image_alloc(&virt[e], W, H, 4, IO_U8, &err) == IO_OK) {
            /* plain grey, opaque */
            for (int y = 0; y < H; y++) {
                uint8_t *row = (uint8_t *)virt[e].data + (size_t)y * virt[e].stride;
                for (int x = 0; x < W; x++) {
                    row[4 * x + 0] = row[4 * x + 1] = row[4 * x + 2] = 96;
                    row[4 * x + 3] = 255;
                }
            }
        } else {
            cli_fail("%s", err.msg);
            goto done;
        }
        if (io_image_alloc(&outimg[e], W, H, 4, IO_U8, &err) != IO_OK ||
            io_image_alloc(&camimg[e], hd.cam_width, hd.cam_height, 4, IO_U8, &err) != IO_OK) {
            cli_fail("%s", err.msg);
            goto done;
        }
    }
    if (o->raw && !(rawbuf = malloc((size_t)W * (size_t)H * 6))) {
        cli_fail("out of memory");
        goto done;
    }
    if (o->track_port) {
        char why[256];
        if (kin_arm_rig_init(&rig, &model, why, sizeof why) != 0) {
            cli_fail("%s: cannot follow the tracking stream: %s", model_path, why);
            goto done;
        }
        if (!(locals = malloc(sizeof(kin_transform) * (size_t)model.node_count))) {
            cli_fail("out of memory");
            goto done;
        }
        if (io_track_udp_listen(&udp, NULL, o->track_port, &err) != IO_OK) {
            cli_fail("%s", err.msg);
            goto done;
        }
    }
    if (o->calib && io_user_calib_load(o->calib, &ucal, &err) != IO_OK) {
        cli_fail("%s", err.msg);
        goto done;
    }
    for (int e = 0; e < 2; e++) {
        if (!o->glove_sel[e]) continue;
        const char *gs = strcmp(o->glove_sel[e], "any") ? o->glove_sel[e] : NULL;
        if (io_glove_open(&glove[e], gs, &err) != IO_OK) {
            cli_fail("%s glove: %s", e ? "right" : "left", err.msg);
            goto done;
        }
        have_glove[e] = 1;
        glove[e].side = e;
        if (ucal.has_glove[e]) io_glove_set_calib(&glove[e], &ucal.glove[e]);
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
        if (io_cam_open(&cam[e], &io_cam_v4l2, &c, &err) != IO_OK ||
            io_cam_start(&cam[e], &err) != IO_OK) {
            cli_fail("%s camera: %s", e ? "right" : "left", err.msg);
            goto done;
        }
    }
    pd.refine_band = o->refine;
    pd.fit_rig = o->refine && o->track_port ? &rig : NULL;
    if (!(pipe = pipe_create(&pd, &model))) {
        cli_fail(pd.fit_rig ? "cannot start the pipeline (out of memory, no thread, or the elbow "
                              "fit cannot use the model: mesh 0's skin, the arms' node chains)"
                            : "cannot start the pipeline (out of memory or no thread)");
        goto done;
    }
    if (o->out && cli_mkdirs(o->out) != 0) {
        cli_fail("%s: cannot create the output folder", o->out);
        goto done;
    }
    if (!o->quiet) {
        char fs[5];
        fprintf(stderr, "egofuse run: left %s (%s), right %s (%s), %s %dx%d at %d/%d s\n",
                cam[0].cfg.path, cam[0].card, cam[1].cfg.path, cam[1].card,
                io_fourcc_str(cam[0].fourcc, fs), cam[0].width, cam[0].height, cam[0].fps_den,
                cam[0].fps_num);
    }

    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    io_stereo st;
    io_stereo_init(&st, &cam[0], &cam[1], 0);
    pipe_frame_in in;
    memset(&in, 0, sizeof in);
    in.lighting = pipe_lighting_default();
    if (have_scene) in.lighting.light = io_scene_lighting(&sc); /* the scene's lights */
    in.head_node = head;
    kin_mat4 ident = kin_mat4_identity();
    in.world_from_head = &ident;
    for (int e = 0; e < 2; e++) {
        in.camera[e] = (fuse_image){camimg[e].data, camimg[e].width, camimg[e].height,
                                    (int)camimg[e].stride};
        in.virt[e] = (fuse_image){virt[e].data, W, H, (int)virt[e].stride};
        in.out[e] = (fuse_image){outimg[e].data, W, H, (int)outimg[e].stride};
    }
    /* The virtual images do not change: checked once. Opaque (the grey
     * fallback is), the composite copies V where the hand is not without
     * looking at its alpha. */
    const kin_sthmd_geometry geo = pipe_geometry(pipe);
    in.virt_opaque = pipe_image_opaque(&in.virt[0], geo.vp_x0, geo.vp_y0, geo.vp_width,
                                       geo.vp_height) &&
                     pipe_image_opaque(&in.virt[1], geo.vp_x0, geo.vp_y0, geo.vp_width,
                                       geo.vp_height);
    kin_track_sample sample;
    memset(&sample, 0, sizeof sample);
    int have_pose = 0, have_img[2] = {0, 0};
    double t_start = mono_s(), t_status = t_start, t_retry[2] = {0, 0};
    double lat_sum = 0;
    int frames = 0, frames_status = 0;
    while (!stop_flag && (o->frames == 0 || frames < o->frames)) {
        io_frame fr[2];
        int got = 0;
        io_result gr = io_stereo_grab(&st, 200, fr, &got, &err);
        double now = mono_s();
        /* a failed camera: reopen once a second, found again by its selector */
        for (int e = 0; e < 2; e++) {
            if (cam[e].state != IO_CAM_FAILED || now - t_retry[e] < 1.0) continue;
            t_retry[e] = now;
            char np[IO_CAM_NAME_MAX];
            io_error e2;
            const char *where = NULL;
            if (o->sel[e] && resolve(o->sel[e], np, sizeof np, &e2) == 0) where = np;
            if (io_cam_reopen(&cam[e], where, &e2) == IO_OK && !o->quiet)
                fprintf(stderr, "\negofuse run: %s camera back (%s)\n", e ? "right" : "left",
                        cam[e].cfg.path);
        }
        if (gr != IO_OK) {
            if (!o->quiet) fprintf(stderr, "\regofuse run: %s (retrying)   ", err.msg);
            struct timespec ts = {0, 200000000};
            nanosleep(&ts, NULL);
            continue;
        }
        if (!got) continue;
        uint64_t t_cap = 0;
        for (int e = 0; e < 2; e++) {
            if (!(got & (1 << e))) continue;
            if (io_frame_to_rgba(&fr[e], camimg[e].data, camimg[e].stride, &err) == IO_OK)
                have_img[e] = 1;
            else if (!o->quiet)
                fprintf(stderr, "\regofuse run: %s   ", err.msg);
            if (fr[e].t_ns > t_cap) t_cap = fr[e].t_ns;
        }
        if (got == 3) io_stereo_release(&st, fr, NULL);
        else
            for (int e = 0; e < 2; e++)
                if (got & (1 << e)) io_cam_release(&cam[e], &fr[e], NULL);
        if (!have_img[0] || !have_img[1]) continue; /* the other eye holds its last image */

        /* ---- pose: tracking stream (+ gloves), else the animation */
        for (int e = 0; e < 2; e++) {
            int fresh;
            if (have_glove[e] && io_glove_poll(&glove[e], 0, &fresh, &err) != IO_OK) {
                if (!o->quiet) fprintf(stderr, "\regofuse run: %s   ", err.msg);
                have_glove[e] = 0;
            }
        }
        in.locals = NULL;
        in.anim = anim;
        in.time = (float)(now - t_start);
        if (udp.fd >= 0) {
            kin_track_sample s;
            int fresh = 0;
            if (io_track_udp_poll(&udp, 0, &s, &fresh, &err) == IO_OK && s.valid) {
                sample = s;
                have_pose = 1;
            }
            for (int e = 0; e < 2; e++)
                if (have_glove[e]) io_glove_to_sample(&glove[e], &sample);
            if (have_pose) {
                kin_pose_rest(&model, locals);
                if (kin_arm_rig_pose(&rig, &model, &ucal, NULL, &sample, locals, NULL))
                    in.locals = locals;
                in.fit_skip = ((sample.valid & KIN_TRACK_HAND_L) ? 0u : 1u) |
                              ((sample.valid & KIN_TRACK_HAND_R) ? 0u : 2u);
            }
        }
        char why[256];
        pipe_frame_stats ps;
        pipe_result pr = pipe_frame(pipe, &in, &ps, why, (int)sizeof why);
        if (pr != PIPE_OK) {
            cli_fail("frame %d: %s", frames, why);
            goto done;
        }
        /* ---- output */
        if (o->out) {
            static const char *const eye[2] = {"left", "right"};
            for (int e = 0; e < 2; e++) {
                char p[IO_PATH_MAX + 64];
                snprintf(p, sizeof p, "%s/%s_%04d.png", o->out, eye[e], frames);
                if (io_image_save(p, &outimg[e], &err) != IO_OK) {
                    cli_fail("%s", err.msg);
                    goto done;
                }
            }
        }
        if (o->raw) {
            uint8_t *d = rawbuf;
            for (int e = 0; e < 2; e++)
                for (int y = 0; y < H; y++) {
                    const uint8_t *s = (const uint8_t *)outimg[e].data + (size_t)y * outimg[e].stride;
                    for (int x = 0; x < W; x++, d += 3) {
                        d[0] = s[4 * x];
                        d[1] = s[4 * x + 1];
                        d[2] = s[4 * x + 2];
                    }
                }
            if (fwrite(rawbuf, 1, (size_t)W * (size_t)H * 6, stdout) != (size_t)W * (size_t)H * 6) {
                cli_fail("stdout: write error: %s (reader gone?)", strerror(errno));
                goto done;
            }
            fflush(stdout);
        }
        frames++;
        frames_status++;
        struct timespec ts;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        uint64_t t_out = (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
        lat_sum += t_out > t_cap ? 1e-6 * (double)(t_out - t_cap) : 0;
        now = mono_s();
        if (!o->quiet && (now - t_status >= 1.0 || frames == o->frames)) {
            fprintf(stderr, "\regofuse run: %d frames, %.1f FPS, latency %.1f ms, dropped %llu/%llu, "
                    "unpaired %llu/%llu, skew %.2f ms, pipe %.1f ms%s   ",
                    frames, frames_status / (now - t_status), lat_sum / frames_status,
                    (unsigned long long)cam[0].stats.dropped, (unsigned long long)cam[1].stats.dropped,
                    (unsigned long long)st.unpaired[0], (unsigned long long)st.unpaired[1],
                    1e-6 * (double)st.last_skew_ns, ps.ms_total,
                    st.failed[0] || st.failed[1] ? ", one eye held" : "");
            t_status = now;
            frames_status = 0;
            lat_sum = 0;
        }
    }
    if (!o->quiet) fputc('\n', stderr);
    /* stdout carries the frames with --raw */
    fprintf(o->raw ? stderr : stdout, "egofuse run: %d stereo frames, %llu pairs, dropped %llu/%llu, unpaired %llu/%llu, "
           "max skew %.2f ms, reopens %llu/%llu\n", frames, (unsigned long long)st.pairs,
           (unsigned long long)cam[0].stats.dropped, (unsigned long long)cam[1].stats.dropped,
           (unsigned long long)st.unpaired[0], (unsigned long long)st.unpaired[1],
           1e-6 * (double)st.max_abs_skew_ns, (unsigned long long)cam[0].stats.reopens,
           (unsigned long long)cam[1].stats.reopens);
    io_stereo_flush(&st);
    rc = EXIT_OK;
done:
    for (int e = 0; e < 2; e++) {
        io_cam_close(&cam[e]);
        io_glove_close(&glove[e]);
        io_image_free(&virt[e]);
        io_image_free(&outimg[e]);
        io_image_free(&camimg[e]);
    }
    if (udp.fd >= 0) io_track_udp_close(&udp);
    free(locals);
    free(rawbuf);
    if (pipe) pipe_destroy(pipe);
    kin_model_free(&model);
    return rc;
}

enum { O_SCENE = 256, O_MODEL, O_VIRT, O_LEFT, O_RIGHT, O_FORMAT, O_FPS, O_INPUT, O_DV, O_BUFFERS,
       O_TRACK, O_GLOVE_L, O_GLOVE_R, O_CALIB, O_OUT, O_RAW, O_FRAMES, O_QUIET, O_REFINE };

int cmd_run(int argc, char **argv)
{
    static const struct option opts[] = {
        {"scene", required_argument, 0, O_SCENE},   {"model", required_argument, 0, O_MODEL},
        {"virt", required_argument, 0, O_VIRT},     {"left", required_argument, 0, O_LEFT},
        {"right", required_argument, 0, O_RIGHT},   {"format", required_argument, 0, O_FORMAT},
        {"fps", required_argument, 0, O_FPS},       {"input", required_argument, 0, O_INPUT},
        {"dv", no_argument, 0, O_DV},               {"buffers", required_argument, 0, O_BUFFERS},
        {"track-port", required_argument, 0, O_TRACK},
        {"glove-left", required_argument, 0, O_GLOVE_L},
        {"glove-right", required_argument, 0, O_GLOVE_R},
        {"calib", required_argument, 0, O_CALIB},   {"out", required_argument, 0, O_OUT},
        {"raw", no_argument, 0, O_RAW},             {"frames", required_argument, 0, O_FRAMES},
        {"quiet", no_argument, 0, O_QUIET},         {"help", no_argument, 0, 'h'},
        {"refine", required_argument, 0, O_REFINE},
        {0, 0, 0, 0},
    };
    run_opts o;
    memset(&o, 0, sizeof o);
    o.fourcc = IO_FMT_YUYV;
    o.fps = 60;
    o.input = -1;
    o.buffers = 4;
    static char virt_buf[2 * IO_PATH_MAX];
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'h': fputs(run_usage, stdout); return EXIT_OK;
        case O_SCENE: o.scene = optarg; break;
        case O_MODEL: o.model = optarg; break;
        case O_VIRT: {
            snprintf(virt_buf, sizeof virt_buf, "%s", optarg);
            char *comma = strchr(virt_buf, ',');
            if (!comma) return cli_usage_error("run", "--virt needs LEFT,RIGHT");
            *comma = '\0';
            o.virt[0] = virt_buf;
            o.virt[1] = comma + 1;
            break;
        }
        case O_LEFT: o.sel[0] = optarg; break;
        case O_RIGHT: o.sel[1] = optarg; break;
        case O_FORMAT:
            if (strlen(optarg) != 4) return cli_usage_error("run", "--format '%s': 4 letters", optarg);
            o.fourcc = IO_FOURCC(optarg[0], optarg[1], optarg[2], optarg[3]);
            break;
        case O_FPS:
            if (!cli_parse_int(optarg, 1, 1000, &o.fps))
                return cli_usage_error("run", "--fps '%s': not a frame rate", optarg);
            break;
        case O_INPUT:
            if (!cli_parse_int(optarg, 0, 255, &o.input))
                return cli_usage_error("run", "--input '%s': not an input number", optarg);
            break;
        case O_DV: o.dv = 1; break;
        case O_BUFFERS:
            if (!cli_parse_int(optarg, 2, IO_CAM_MAX_BUFFERS, &o.buffers))
                return cli_usage_error("run", "--buffers '%s': 2..%d", optarg, IO_CAM_MAX_BUFFERS);
            break;
        case O_TRACK:
            if (!cli_parse_int(optarg, 1, 65535, &o.track_port))
                return cli_usage_error("run", "--track-port '%s': not a port", optarg);
            break;
        case O_GLOVE_L: o.glove_sel[0] = optarg; break;
        case O_GLOVE_R: o.glove_sel[1] = optarg; break;
        case O_CALIB: o.calib = optarg; break;
        case O_OUT: o.out = optarg; break;
        case O_RAW: o.raw = 1; break;
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 1 << 30, &o.frames))
                return cli_usage_error("run", "--frames '%s': not a positive count", optarg);
            break;
        case O_QUIET: o.quiet = 1; break;
        case O_REFINE:
            if (!cli_parse_int(optarg, 1, 64, &o.refine))
                return cli_usage_error("run", "--refine '%s': a band of 1..64 px", optarg);
            break;
        case ':': return cli_usage_error("run", "option %s needs a value", argv[optind - 1]);
        default: return cli_usage_error("run", "unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind < argc) return cli_usage_error("run", "unexpected argument '%s'", argv[optind]);
    if (!o.sel[0] != !o.sel[1]) return cli_usage_error("run", "give both --left and --right");
    for (int e = 0; e < 2; e++) {
        io_error err;
        if (o.sel[e] && strncmp(o.sel[e], "/dev/", 5) &&
            io_usb_selector_check(o.sel[e], &err) != IO_OK)
            return cli_usage_error("run", "--%s: %s", e ? "right" : "left", err.msg);
    }
    if (o.out && o.raw) return cli_usage_error("run", "--out and --raw exclude each other");
    return run(&o);
}
