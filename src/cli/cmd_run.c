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
 * docs/devices.md.
 *
 * Why one file of this length: one job, the live loop of `egofuse run`
 * (run(), about 550 lines: open, then per frame wait, grab, track, pipe,
 * show, account). Its options are parsed in run_opts.c, the cameras found
 * in run_cams.c and --dump's files written in run_dump.c (run.h); what is
 * left here are that loop and the helpers that read and write its
 * run_state (tracking service, flips, outputs, the status words), which
 * nothing else uses. */
#include "run.h"
#include "cli_lod.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../io/io_dev.h"
#include "../io/io_display.h"
#include "../io/io_live.h"
#include "../io/io_natnet.h"
#include "../io/io_sched.h"
#include "../io/io_vsrc.h"
#include "../pipe/pipe.h"

static volatile sig_atomic_t stop_flag;
static void on_signal(int s)
{
    (void)s;
    stop_flag = 1;
}

static int load_virt(const char *path, int w, int h, io_image *img)
{
    io_error err;
    if (io_image_load(path, IO_U8, 4, img, &err) != IO_OK) return io_term_fail("%s", err.msg);
    if (img->width != w || img->height != h) {
        /* the sizes before the image is freed (which zeroes them) */
        io_term_fail("%s: virtual image is %dx%d, expected %dx%d", path, img->width, img->height, w,
                 h);
        io_image_free(img);
        return EXIT_FAIL;
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
    char model_path[IO_PATH_MAX + 64];
    pipe_ctx *pipe;
    pipe_lod lod;             /* --lod: the model's levels of detail */
    io_image virt[2], outimg[2], camimg[2];
    io_image vdepth[2];       /* the still virtual images' depth, if any */
    char vdepth_path[2][IO_PATH_MAX + 64];
    io_cam cam[2];
    int file_cams;            /* the cameras are recorded frames */
    io_glove glove[2];
    int have_glove[2];
    io_track_udp udp;
    io_natnet natnet;
    int have_natnet;
    kin_arm_rig rig;
    kin_transform *locals;
    kin_user_calib ucal;
    kin_filter filter;
    pipe_desc track_pd;       /* the refine method's tracking (pipe_track_output) */
    float hand_speed[2];      /* pipe_frame_in.hand_speed: wrists, m/s */
    track_clock tclock;
    uint64_t track_samples;   /* samples taken into the filter */
    uint64_t t_track;         /* CLOCK_MONOTONIC time of the newest one */
    io_vsrc *vsrc;
    io_display *disp;
    io_sched sched;
    kin_model props[RUN_MAX_PROPS];
    int props_loaded;
    kin_mat4 prop_world[RUN_MAX_PROPS];
    const kin_mat4 *prop_ptr[RUN_MAX_PROPS];
    uint8_t *rawbuf;
    io_stats_log stats;
    /* the frames presented and not yet shown (display): their log rows */
    io_frame_log pending[4];
    int npending;
} run_state;

static void run_close(run_state *r)
{
    io_display_close(&r->disp); /* first: the previous mode comes back */
    io_vsrc_close(r->vsrc);
    r->vsrc = NULL;
    for (int e = 0; e < 2; e++) {
        io_cam_close(&r->cam[e]);
        io_glove_close(&r->glove[e]);
        io_image_free(&r->virt[e]);
        io_image_free(&r->outimg[e]);
        io_image_free(&r->camimg[e]);
        io_image_free(&r->vdepth[e]);
    }
    if (r->udp.fd >= 0) io_track_udp_close(&r->udp);
    if (r->have_natnet) io_natnet_close(&r->natnet);
    io_stats_abandon(&r->stats);
    free(r->locals);
    free(r->rawbuf);
    if (r->pipe) pipe_destroy(r->pipe);
    io_lod_free(&r->lod);
    for (int k = 0; k < r->props_loaded; k++) kin_model_free(&r->props[k]);
    if (r->have_model) kin_model_free(&r->model);
}

/* Every NatNet frame accepted goes into the filter (a poll may accept
 * several and hand out only the newest). */
static void natnet_sample(void *user, const kin_track_sample *s, const io_natnet *n)
{
    (void)n;
    run_state *r = user;
    if (!s->valid) return;
    if (kin_filter_push(&r->filter, s) & KIN_FILTER_ACCEPTED) {
        r->track_samples++;
        r->t_track = (uint64_t)(s->t * 1e9); /* NatNet's times are CLOCK_MONOTONIC */
    }
    r->tclock.have = 1;
    r->tclock.offset_s = 0;
}

/* The tracking file's parser normalises the rotations it reads: the pose
 * is made from the normalised sample, and --dump writes the one before,
 * so that render reads back exactly the pose run used. */
static void sample_normalised(const kin_track_sample *in, kin_track_sample *out)
{
    *out = *in;
    if (out->valid & KIN_TRACK_HEAD) out->head_rot = kin_quat_normalize(out->head_rot);
    for (int k = 0; k < 2; k++)
        if (out->valid & (KIN_TRACK_HAND_L << k))
            out->hand_rot[k] = kin_quat_normalize(out->hand_rot[k]);
}

/* The tracker: the pending samples into the filter (called whenever the
 * loop waits, so the filter sees each sample near its arrival). */
static void track_service(run_state *r)
{
    io_error err;
    kin_track_sample s;
    int fresh = 0;
    double t_arr = 1e-9 * (double)io_now_ns();
    if (r->udp.fd >= 0) {
        if (io_track_udp_poll(&r->udp, 0, &s, &fresh, &err) != IO_OK) return;
    } else if (r->have_natnet) {
        io_natnet_poll(&r->natnet, 0, &s, &fresh, &err); /* natnet_sample takes each frame */
        return;
    } else {
        return;
    }
    if (!fresh || !s.valid) return; /* the newest of the datagrams read */
    int bits = kin_filter_push(&r->filter, &s);
    track_local_time(&r->tclock, s.t, t_arr, bits & KIN_FILTER_RESTART);
    if (bits & KIN_FILTER_ACCEPTED) {
        r->track_samples++;
        r->t_track = (uint64_t)((s.t + r->tclock.offset_s) * 1e9);
    }
}

/* One flip event: the frame it shows is logged with its time. */
static void on_flip(const run_opts *o, run_state *r, const io_display_flip *ev, io_lat *lat_shown,
                    io_lat *lat_deq)
{
    (void)o;
    io_sched_flipped(&r->sched, ev->t_ns, ev->seq);
    for (int i = 0; i < r->npending; i++) {
        if (r->pending[i].frame != ev->frame_id) continue;
        io_frame_log *lg = &r->pending[i];
        lg->t_shown = ev->t_ns;
        uint64_t tc = lg->t_cam_l > lg->t_cam_r ? lg->t_cam_l : lg->t_cam_r;
        io_lat_push(lat_shown, 1e-6 * ((double)lg->t_shown - (double)tc));
        io_lat_push(lat_deq, 1e-6 * ((double)lg->t_shown - (double)lg->t_dequeue));
        io_stats_row(&r->stats, lg);
        r->pending[i] = r->pending[--r->npending];
        return;
    }
}

/* The flip events that came, without waiting. */
static void drain_flips(const run_opts *o, run_state *r, io_lat *lat_shown, io_lat *lat_deq)
{
    io_display_flip ev;
    int got = 0;
    io_error err;
    while (io_display_poll(r->disp, 0, &ev, &got, &err) == IO_OK && got)
        on_flip(o, r, &ev, lat_shown, lat_deq);
}

/* Waits until deadline_ns (or, with want_cams, until a camera has a
 * frame), serving the display's flip events, the tracker and the V source
 * meanwhile. Returns 1 when a camera became readable. */
static int wait_until(const run_opts *o, run_state *r, uint64_t deadline_ns, int want_cams,
                      io_lat *lat_shown, io_lat *lat_deq)
{
    for (;;) {
        struct pollfd pf[16];
        int n = 0, cam0 = -1, ncam = 0, disp_i = -1;
        if (r->disp && io_display_fd(r->disp) >= 0) {
            disp_i = n;
            pf[n++] = (struct pollfd){io_display_fd(r->disp), POLLIN, 0};
        }
        if (r->udp.fd >= 0) pf[n++] = (struct pollfd){r->udp.fd, POLLIN, 0};
        if (r->have_natnet && io_natnet_fd(&r->natnet) >= 0)
            pf[n++] = (struct pollfd){io_natnet_fd(&r->natnet), POLLIN, 0};
        if (r->vsrc) n += io_vsrc_pollfds(r->vsrc, pf + n, 4);
        if (want_cams) {
            cam0 = n;
            for (int e = 0; e < 2; e++)
                if (r->cam[e].state == IO_CAM_STREAMING && io_cam_fd(&r->cam[e]) >= 0) {
                    pf[n++] = (struct pollfd){io_cam_fd(&r->cam[e]), POLLIN, 0};
                    ncam++;
                }
        }
        uint64_t now = io_now_ns();
        int ms = now >= deadline_ns ? 0 : (int)((deadline_ns - now + 999999) / 1000000);
        if (ms > 100) ms = 100;
        int k = poll(pf, (nfds_t)n, ms);
        if (k < 0 && errno != EINTR) return 0;
        if (stop_flag) return 0;
        io_error err;
        /* flip events (SDL has no descriptor: its come by polling) */
        if (r->disp && (disp_i < 0 || (pf[disp_i].revents & POLLIN)))
            drain_flips(o, r, lat_shown, lat_deq);
        track_service(r);
        if (r->vsrc) {
            int fresh;
            io_vsrc_poll(r->vsrc, 0, &fresh, &err);
        }
        if (want_cams)
            for (int i = 0; i < ncam; i++)
                if (pf[cam0 + i].revents) return 1;
        if (io_now_ns() >= deadline_ns) return 0;
    }
}

/* World matrix of a prop this frame; NULL when its rigid body is not
 * seen. */
static const kin_mat4 *prop_pose(const run_opts *o, run_state *r, int k)
{
    const run_prop *p = &o->prop[k];
    const float d2r = 0.017453292519943295f;
    kin_quat q = kin_quat_mul(kin_quat_axis_angle(kin_v3(0, 1, 0), p->rot_deg[0] * d2r),
                              kin_quat_mul(kin_quat_axis_angle(kin_v3(1, 0, 0), p->rot_deg[1] * d2r),
                                           kin_quat_axis_angle(kin_v3(0, 0, 1), p->rot_deg[2] * d2r)));
    kin_mat4 local = kin_mat4_from_tr(kin_v3(p->at[0], p->at[1], p->at[2]), q);
    if (!p->body[0]) {
        r->prop_world[k] = local;
        return &r->prop_world[k];
    }
    kin_mat4 body;
    int valid = 0, id = -1;
    if (p->body[0] == '#') id = atoi(p->body + 1);
    if (!r->have_natnet || io_natnet_body(&r->natnet, id, id >= 0 ? NULL : p->body, &body, &valid) != 0 ||
        !valid)
        return NULL;
    r->prop_world[k] = kin_mat4_mul(&body, &local);
    return &r->prop_world[k];
}


static int write_outputs(const run_opts *o, run_state *r, int frame, int W, int H)
{
    io_error err;
    if (o->out) {
        static const char *const eye[2] = {"left", "right"};
        for (int e = 0; e < 2; e++) {
            char p[IO_PATH_MAX + 64];
            snprintf(p, sizeof p, "%s/%s_%04d.png", o->out, eye[e], frame);
            if (io_image_save(p, &r->outimg[e], &err) != IO_OK) return io_term_fail("%s", err.msg);
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
            return io_term_fail("stdout: write error: %s (reader gone?)", strerror(errno));
    }
    return EXIT_OK;
}

static const char *vstate_word(const run_state *r, uint64_t now, char *buf, size_t n)
{
    if (!r->vsrc) return "";
    io_vsrc_stat vs;
    io_vsrc_status(r->vsrc, now, &vs);
    if (vs.state == IO_VSRC_LIVE)
        snprintf(buf, n, ", V live %.0f ms old", 1e-6 * (double)vs.age_ns);
    else if (vs.t_ns)
        snprintf(buf, n, ", V %s (last good held, %.1f s old)%s%.120s", io_vsrc_state_name(vs.state),
                 1e-9 * (double)vs.age_ns, vs.msg[0] ? ": " : "", vs.msg);
    else
        snprintf(buf, n, ", V %s%s%.120s", io_vsrc_state_name(vs.state), vs.msg[0] ? ": " : "",
                 vs.msg);
    return buf;
}

static const char *track_word(const run_opts *o, const run_state *r, uint64_t now, char *buf,
                              size_t n)
{
    if (!o->track_port && !o->natnet) return "";
    if (!r->t_track) {
        snprintf(buf, n, ", tracker: no pose yet%s%.160s", r->have_natnet ? " (" : "",
                 r->have_natnet ? r->natnet.status : "");
        if (r->have_natnet) strncat(buf, ")", n - strlen(buf) - 1);
        return buf;
    }
    double age = 1e-9 * ((double)now - (double)r->t_track);
    if (age > 0.5)
        snprintf(buf, n, ", tracker stale (last pose %.1f s old, held then faded)", age);
    else
        snprintf(buf, n, ", tracker %.0f ms", 1e3 * age);
    return buf;
}

static int run(const run_opts *o)
{
    io_error err;
    int rc = EXIT_FAIL;
    /* ---- cameras first: without them nothing else matters */
    char path[2][IO_CAM_NAME_MAX];
    int file_cams = 0;
    int crc = run_find_cameras(o, path, &file_cams);
    if (crc != EXIT_OK) return crc;

    if (!o->scene && !o->model)
        return cli_usage_error("run", "--scene or --model is required (the arm model to mask)");

    run_state *r = calloc(1, sizeof *r);
    if (!r) return io_term_fail("out of memory");
    r->cam[0].fd = r->cam[1].fd = -1;
    r->udp.fd = -1;
    r->ucal = kin_user_calib_identity();
    r->file_cams = file_cams;

    /* ---- model, scene, virtual images */
    char model_path[IO_PATH_MAX + 64];
    if (o->scene) {
        if (io_scene_load(o->scene, &r->sc, &err) != IO_OK) {
            io_term_fail("%s", err.msg);
            goto done;
        }
        r->have_scene = 1;
        io_scene_frame_path(&r->sc, r->sc.model, 0, model_path, sizeof model_path);
    }
    if (o->model) snprintf(model_path, sizeof model_path, "%s", o->model);
    if (io_gltf_load(model_path, &r->model, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
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
                    io_term_fail("%s", err.msg);
                    goto done;
                }
                if (r->vdepth[e].width != W || r->vdepth[e].height != H) {
                    io_term_fail("%s: virtual depth image is %dx%d, expected %dx%d", r->vdepth_path[e],
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
            io_term_fail("%s", err.msg);
            goto done;
        }
        if (io_image_alloc(&r->outimg[e], W, H, 4, IO_U8, &err) != IO_OK ||
            io_image_alloc(&r->camimg[e], hd.cam_width, hd.cam_height, 4, IO_U8, &err) != IO_OK) {
            io_term_fail("%s", err.msg);
            goto done;
        }
    }
    if (o->raw && !(r->rawbuf = malloc((size_t)W * (size_t)H * 6))) {
        io_term_fail("out of memory");
        goto done;
    }
    /* ---- the pose */
    int tracked = o->track_port != 0 || o->natnet;
    if (tracked) {
        char why[256];
        if (kin_arm_rig_init(&r->rig, model, why, sizeof why) != 0) {
            io_term_fail("%s: cannot follow the tracker: %s", model_path, why);
            goto done;
        }
        if (!(r->locals = malloc(sizeof(kin_transform) * (size_t)model->node_count))) {
            io_term_fail("out of memory");
            goto done;
        }
        /* with --refine: the refine method's filter (pipe_track_filter_desc) */
        r->track_pd.refine_band = o->refine;
        kin_filter_desc fd = pipe_track_filter_desc(&r->track_pd);
        kin_filter_init(&r->filter, &fd);
    }
    if (o->track_port &&
        io_track_udp_listen(&r->udp, o->track_addr, o->track_port, &err) != IO_OK) {
        io_term_fail("tracking stream: %s", err.msg);
        goto done;
    }
    if (o->natnet) {
        io_natnet_config nc;
        io_natnet_config_default(&nc);
        for (int i = 0; i < o->natnet_kv_count; i++)
            if (io_natnet_config_set(&nc, o->natnet_kv[i][0], o->natnet_kv[i][1], &err) != IO_OK) {
                io_term_fail("%s", err.msg);
                goto done;
            }
        if (io_natnet_open(&r->natnet, &nc, &err) != IO_OK) {
            io_term_fail("%s", err.msg);
            goto done;
        }
        r->have_natnet = 1;
        r->natnet.on_sample = natnet_sample;
        r->natnet.user = r;
        /* The names are resolved once the server answers; the cameras do
         * not wait for it: a short wait for a clear message at start. */
        if (io_natnet_wait_ready(&r->natnet, 1000, &err) != IO_OK && !o->quiet)
            fprintf(stderr, "egofuse run: NatNet: %s (the cameras run on; the pose comes when "
                            "it does)\n", err.msg);
    }
    if (o->calib && io_user_calib_load(o->calib, &r->ucal, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        goto done;
    }
    for (int e = 0; e < 2; e++) {
        if (!o->glove_sel[e]) continue;
        const char *gs = strcmp(o->glove_sel[e], "any") ? o->glove_sel[e] : NULL;
        if (io_glove_open(&r->glove[e], gs, &err) != IO_OK) {
            io_term_fail("%s glove: %s", e ? "right" : "left", err.msg);
            goto done;
        }
        r->have_glove[e] = 1;
        r->glove[e].side = e;
        if (r->ucal.has_glove[e]) io_glove_set_calib(&r->glove[e], &r->ucal.glove[e]);
    }

    /* ---- the virtual scene as a live source */
    if (o->virt_source) {
        io_vsrc_config vc = io_vsrc_config_default(o->virt_source);
        vc.eye_width = W;
        vc.eye_height = H;
        if (o->virt_layout) vc.layout = io_vsrc_layout_parse(o->virt_layout);
        vc.fps = o->virt_fps;
        vc.stale_ms = o->virt_stale_ms;
        vc.loop = o->loop;
        if (io_vsrc_open(&r->vsrc, &vc, &err) != IO_OK) {
            io_term_fail("virtual scene: %s", err.msg);
            goto done;
        }
    }

    /* ---- cameras */
    io_file_cam_opts fco;
    memset(&fco, 0, sizeof fco);
    fco.loop = o->loop;
    /* recordings decoded once at open (up to 1 GiB for both): decoding a
     * frame when it is due takes long enough that the two eyes would pick
     * different frames */
    fco.cache_bytes = (size_t)512 << 20;
    for (int e = 0; e < 2; e++) {
        io_cam_config c = io_cam_config_default(path[e]);
        c.width = hd.cam_width;
        c.height = hd.cam_height;
        c.fourcc = file_cams && !o->format_set ? 0 : o->fourcc;
        c.fps = o->fps;
        c.input = o->input;
        c.dv_timings = o->dv;
        c.buffers = o->buffers;
        if (file_cams) c.backend_opts = &fco;
        if (io_cam_open(&r->cam[e], file_cams ? &io_cam_file : &io_cam_v4l2, &c, &err) != IO_OK) {
            io_term_fail("%s camera: %s", e ? "right" : "left", err.msg);
            goto done;
        }
    }
    for (int e = 0; e < 2; e++) /* both opened: start together */
        if (io_cam_start(&r->cam[e], &err) != IO_OK) {
            io_term_fail("%s camera: %s", e ? "right" : "left", err.msg);
            goto done;
        }
    pd.refine_band = o->refine;
    pd.aa_samples = o->aa;
    pd.eye_view = o->view;
    pd.edge_fade = o->edge_fade;
    pd.soft_edge = o->soft_edge;
    pd.fit_rig = o->refine && tracked ? &r->rig : NULL;
    if (!(r->pipe = pipe_create(&pd, model))) {
        if (o->aa && (kin_lens_distorts(&pd.hmd.lens[0]) || kin_lens_distorts(&pd.hmd.lens[1])))
            io_term_fail("--aa %d: anti-aliased edges are drawn through the pinhole and cannot be used "
                     "with a distorting lens (the calibration of the cockpit's HMD)", o->aa);
        else io_term_fail(pd.fit_rig ? "cannot start the pipeline (out of memory, no thread, or the elbow "
                              "fit cannot use the model: mesh 0's skin, the arms' node chains)"
                            : "cannot start the pipeline (out of memory or no thread)");
        goto done;
    }
    if (cli_lod_setup(model_path, model, o->lod, o->lod_px, r->pipe, &r->lod) != EXIT_OK)
        goto done;
    unsigned parts = pipe_parts_present(r->pipe);
    if ((o->hide & ~parts) && !o->quiet)
        fprintf(stderr, "egofuse run: --hide: %s has no such part (its parts: %s%s%s%s)\n",
                model_path, parts & PIPE_PART_HAND_L ? "left-hand " : "",
                parts & PIPE_PART_ARM_L ? "left-arm " : "", parts & PIPE_PART_HAND_R ? "right-hand " : "",
                parts & PIPE_PART_ARM_R ? "right-arm" : "");
    for (int k = 0; k < o->prop_count; k++) {
        if (io_gltf_load(o->prop[k].model, &r->props[k], &err) != IO_OK) {
            io_term_fail("--prop %s: %s", o->prop[k].name, err.msg);
            goto done;
        }
        r->props_loaded++;
        if (pipe_add_prop(r->pipe, &r->props[k]) != k) {
            io_term_fail("--prop %s: %s has no triangles (or out of memory)", o->prop[k].name,
                     o->prop[k].model);
            goto done;
        }
    }
    if (o->out && io_mkdirs(o->out) != 0) {
        io_term_fail("%s: cannot create the output folder: %s", o->out, strerror(errno));
        goto done;
    }
    /* ---- the display last: the screen changes only once all else is up */
    if (o->display) {
        io_display_config dc = {o->display, W, H, 0};
        if (io_display_open(&r->disp, &dc, &err) != IO_OK) {
            io_term_fail("display: %s", err.msg);
            goto done;
        }
        io_sched_init(&r->sched, io_display_refresh_ns(r->disp));
    }
    if (o->stats && io_stats_open(&r->stats, o->stats, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        goto done;
    }
    if (!o->quiet) {
        char fs[5];
        fprintf(stderr, "egofuse run: left %s (%s), right %s (%s), %s %dx%d at %d/%d s%s%s\n",
                r->cam[0].cfg.path, r->cam[0].card, r->cam[1].cfg.path, r->cam[1].card,
                io_fourcc_str(r->cam[0].fourcc, fs), r->cam[0].width, r->cam[0].height,
                r->cam[0].fps_den, r->cam[0].fps_num, r->disp ? "; display " : "",
                r->disp ? io_display_describe(r->disp) : "");
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
    in.hide = o->hide;
    in.prop_world = r->props_loaded ? r->prop_ptr : NULL;
    in.prop_count = r->props_loaded;
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
     * alpha. A live source's eyes are opaque by construction. */
    kin_sthmd_geometry geo = pipe_geometry(r->pipe);
    if (o->view == PIPE_VIEW_REPROJECT) { /* the eye's view: the whole display */
        geo.vp_x0 = geo.vp_y0 = 0;
        geo.vp_width = W;
        geo.vp_height = H;
    }
    const int still_opaque =
        pipe_image_opaque(&in.virt[0], geo.vp_x0, geo.vp_y0, geo.vp_width, geo.vp_height) &&
        pipe_image_opaque(&in.virt[1], geo.vp_x0, geo.vp_y0, geo.vp_width, geo.vp_height);
    kin_track_sample sample;
    memset(&sample, 0, sizeof sample);
    int have_img[2] = {0, 0}, cam_lost[2] = {0, 0};
    char reopen_msg[2][sizeof err.msg] = {"", ""};
    uint64_t t_start = io_now_ns(), t_status = t_start, t_retry[2] = {0, 0};
    io_lat lat_cam, lat_pipe, lat_deq;
    io_lat_reset(&lat_cam);
    io_lat_reset(&lat_pipe);
    io_lat_reset(&lat_deq);
    int frames = 0, frames_status = 0, ended = 0;
    uint64_t v_used = 0;
    while (!stop_flag && (o->frames == 0 || frames < o->frames)) {
        if (r->disp && io_display_quit_requested(r->disp)) break;
        uint64_t now = io_now_ns();
        /* ---- the repaint window: start so as to finish just before the
         * vblank that shows the frame (free-running without a display) */
        io_sched_plan plan = {now, 0, 0};
        if (r->disp) {
            drain_flips(o, r, &lat_cam, &lat_deq);
            plan = io_sched_next(&r->sched, now);
            if (plan.start_ns > now) wait_until(o, r, plan.start_ns, 0, &lat_cam, &lat_deq);
            if (stop_flag) break;
        }
        io_frame fr[2];
        int got = 0;
        io_result gr = io_stereo_grab(&st, 0, fr, &got, &err);
        now = io_now_ns();
        /* a failed camera: said once, then reopened once a second, found
         * again by its selector */
        for (int e = 0; e < 2; e++) {
            if (r->cam[e].state == IO_CAM_FAILED && !cam_lost[e] &&
                !(file_cams && io_cam_file_ended(&r->cam[e]))) {
                cam_lost[e] = 1;
                if (!o->quiet)
                    fprintf(stderr, "\negofuse run: %s camera lost (%s); %s, reopening it once a second\n",
                            e ? "right" : "left", r->cam[e].status[0] ? r->cam[e].status : "failed",
                            have_img[e] ? "its eye holds its last image" : "no image of it yet");
            }
            if (r->cam[e].state != IO_CAM_FAILED || now - t_retry[e] < 1000000000ull) continue;
            if (file_cams && io_cam_file_ended(&r->cam[e])) continue;
            t_retry[e] = now;
            char np[IO_CAM_NAME_MAX];
            io_error e2;
            const char *where = NULL;
            if (o->sel[e] && !file_cams && run_resolve_camera(o->sel[e], np, sizeof np, &e2) == 0) where = np;
            if (io_cam_reopen(&r->cam[e], where, &e2) == IO_OK) {
                cam_lost[e] = 0;
                reopen_msg[e][0] = '\0';
                if (!o->quiet)
                    fprintf(stderr, "\negofuse run: %s camera back (%s)\n", e ? "right" : "left",
                            r->cam[e].cfg.path);
            } else if (strcmp(e2.msg, reopen_msg[e])) { /* each new reason once */
                snprintf(reopen_msg[e], sizeof reopen_msg[e], "%s", e2.msg);
                if (!o->quiet)
                    fprintf(stderr, "\negofuse run: %s camera not back: %s\n", e ? "right" : "left",
                            e2.msg);
            }
        }
        if (file_cams && (io_cam_file_ended(&r->cam[0]) || io_cam_file_ended(&r->cam[1]))) {
            ended = 1;
            break;
        }
        if (gr != IO_OK) {
            if (!o->quiet) fprintf(stderr, "\regofuse run: %s (retrying)   ", err.msg);
            wait_until(o, r, now + 200000000ull, 0, &lat_cam, &lat_deq);
            continue;
        }
        if (!got) { /* no new pair yet: wait for the cameras, then plan again */
            wait_until(o, r, now + 200000000ull, 1, &lat_cam, &lat_deq);
            continue;
        }
        io_frame_log lg;
        memset(&lg, 0, sizeof lg);
        lg.frame = (uint64_t)frames;
        lg.t_dequeue = now;
        lg.v_age_ms = -1;
        lg.v_state = -1;
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
        if (!t_cam) t_cam = now;

        /* ---- the newest virtual frame (its own rate; the last good one is
         * held when it is late or gone) */
        in.virt_opaque = still_opaque;
        if (r->vsrc) {
            int fresh;
            io_vsrc_poll(r->vsrc, 0, &fresh, &err);
            io_vsrc_stat vs;
            io_vsrc_status(r->vsrc, now, &vs);
            lg.v_state = (int)vs.state;
            for (int e = 0; e < 2 && vs.frames; e++) {
                size_t stride = 0, dstride = 0;
                const uint8_t *im = io_vsrc_eye(r->vsrc, e, &stride);
                const float *dp = io_vsrc_depth(r->vsrc, e, &dstride);
                if (!im) continue;
                in.virt[e] = (fuse_image){(void *)im, W, H, (int)stride};
                in.virt_depth[e] = dp;
                in.virt_depth_stride[e] = dp ? (int)(dstride / sizeof(float)) : 0;
            }
            if (vs.frames) {
                in.virt_opaque = 1;
                lg.v_age_ms = vs.t_ns ? 1e-6 * ((double)t_cam - (double)vs.t_ns) : -1;
                v_used = vs.frames;
            }
        }

        /* ---- pose: the tracker (+ gloves) through the filter, posed at the
         * cameras' time; else the animation */
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
            track_service(r);
            if (r->track_samples) {
                double t_pose = 1e-9 * (double)t_cam + 1e-3 * o->predict_ms - r->tclock.offset_s;
                pipe_track_output(&r->track_pd, &r->filter, t_pose, &sample, r->hand_speed);
                in.hand_speed = r->hand_speed;
                for (int e = 0; e < 2; e++)
                    if (r->have_glove[e]) io_glove_to_sample(&r->glove[e], &sample);
                kin_track_sample posed;
                sample_normalised(&sample, &posed);
                kin_pose_rest(model, r->locals);
                if (kin_arm_rig_pose(&r->rig, model, &r->ucal, NULL, &posed, r->locals, NULL))
                    in.locals = r->locals;
                in.fit_skip = ((posed.valid & KIN_TRACK_HAND_L) ? 0u : 1u) |
                              ((posed.valid & KIN_TRACK_HAND_R) ? 0u : 2u);
                lg.track_age_ms = 1e-6 * ((double)t_cam - (double)r->t_track);
            }
        }
        for (int k = 0; k < r->props_loaded; k++) r->prop_ptr[k] = prop_pose(o, r, k);

        char why[256];
        pipe_frame_stats ps;
        lg.t_start = io_now_ns();
        pipe_result pr = pipe_frame(r->pipe, &in, &ps, why, (int)sizeof why);
        lg.t_done = io_now_ns();
        if (pr != PIPE_OK) {
            io_term_fail("frame %d: %s", frames, why);
            goto done;
        }
        lg.ms_pose = ps.ms_pose;
        for (int e = 0; e < 2; e++) {
            lg.ms_raster[e] = ps.ms_raster[e];
            lg.ms_fuse[e] = ps.ms_fuse[e];
        }
        lg.ms_total = ps.ms_total;
        io_lat_push(&lat_pipe, ps.ms_total);
        if (o->dump && frames + 1 == o->frames) {
            const run_dump_src src = {r->camimg, r->vdepth, r->vdepth_path, r->model_path,
                                      r->have_scene ? &r->sc : NULL};
            if (run_dump_frame(o, &src, &in, &sample, tracked && r->track_samples, W, H) != EXIT_OK)
                goto done;
        }
        /* ---- output */
        lg.t_present = io_now_ns();
        if (r->disp) {
            const uint8_t *eyes[2] = {r->outimg[0].data, r->outimg[1].data};
            size_t stride[2] = {r->outimg[0].stride, r->outimg[1].stride};
            if (io_display_present(r->disp, eyes, stride, lg.frame, &err) != IO_OK) {
                io_term_fail("display: %s", err.msg);
                goto done;
            }
            io_sched_presented(&r->sched, &plan, lg.t_dequeue, io_now_ns());
            if (r->npending == (int)(sizeof r->pending / sizeof r->pending[0])) {
                io_stats_row(&r->stats, &r->pending[0]); /* never shown */
                r->pending[0] = r->pending[--r->npending];
            }
            r->pending[r->npending++] = lg;
            drain_flips(o, r, &lat_cam, &lat_deq); /* SDL's come with the present */
        } else {
            if (write_outputs(o, r, frames, W, H) != EXIT_OK) goto done;
            lg.t_shown = io_now_ns();
            io_stats_row(&r->stats, &lg);
            io_lat_push(&lat_cam, 1e-6 * ((double)lg.t_shown - (double)t_cam));
            io_lat_push(&lat_deq, 1e-6 * ((double)lg.t_shown - (double)lg.t_dequeue));
        }
        frames++;
        frames_status++;
        now = io_now_ns();
        if (!o->quiet && (now - t_status >= 1000000000ull || frames == o->frames)) {
            char vw[256], tw[256];
            fprintf(stderr,
                    "\regofuse run: %d frames, %.1f FPS, camera to %s %.1f / %.1f ms, dequeue to "
                    "%s %.1f / %.1f ms, pipe %.1f / %.1f ms (median / p99), dropped %llu/%llu, "
                    "unpaired %llu/%llu, skew %.2f ms%s%s%s   ",
                    frames, frames_status / (1e-9 * (double)(now - t_status)),
                    r->disp ? "flip" : "output", io_lat_quantile(&lat_cam, 0.5),
                    io_lat_quantile(&lat_cam, 0.99), r->disp ? "flip" : "output",
                    io_lat_quantile(&lat_deq, 0.5), io_lat_quantile(&lat_deq, 0.99),
                    io_lat_quantile(&lat_pipe, 0.5), io_lat_quantile(&lat_pipe, 0.99),
                    (unsigned long long)r->cam[0].stats.dropped,
                    (unsigned long long)r->cam[1].stats.dropped,
                    (unsigned long long)st.unpaired[0], (unsigned long long)st.unpaired[1],
                    1e-6 * (double)st.last_skew_ns,
                    st.failed[0] || st.failed[1] ? ", one eye held" : "",
                    vstate_word(r, now, vw, sizeof vw), track_word(o, r, now, tw, sizeof tw));
            t_status = now;
            frames_status = 0;
        }
    }
    /* the last flips, then (--hold) the last frame stays on until Ctrl-C */
    if (r->disp) {
        uint64_t until = io_now_ns() + 1000000000ull;
        while (r->npending && !stop_flag && io_now_ns() < until)
            wait_until(o, r, until, 0, &lat_cam, &lat_deq);
        if (o->hold && !stop_flag) {
            fprintf(stderr, "\negofuse run: holding frame %d on %s (Ctrl-C ends)\n", frames - 1,
                    io_display_describe(r->disp));
            while (!stop_flag && !io_display_quit_requested(r->disp))
                wait_until(o, r, io_now_ns() + 100000000ull, 0, &lat_cam, &lat_deq);
        }
    }
    for (int i = 0; i < r->npending; i++) io_stats_row(&r->stats, &r->pending[i]);
    r->npending = 0;
    if (!o->quiet) fputc('\n', stderr);
    if (io_stats_close(&r->stats, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        goto done;
    }
    {
        char vw[256], tw[256];
        uint64_t now = io_now_ns();
        /* stdout carries the frames with --raw */
        fprintf(o->raw ? stderr : stdout,
                "egofuse run: %d stereo frames%s, %llu pairs, dropped %llu/%llu, unpaired "
                "%llu/%llu, max skew %.2f ms, reopens %llu/%llu, camera to %s %.2f / %.2f ms, "
                "dequeue to %s %.2f / %.2f ms, pipe %.2f / %.2f ms (median / p99)%s%s%s\n",
                frames, ended ? " (end of the recording)" : "", (unsigned long long)st.pairs,
                (unsigned long long)r->cam[0].stats.dropped,
                (unsigned long long)r->cam[1].stats.dropped, (unsigned long long)st.unpaired[0],
                (unsigned long long)st.unpaired[1], 1e-6 * (double)st.max_abs_skew_ns,
                (unsigned long long)r->cam[0].stats.reopens,
                (unsigned long long)r->cam[1].stats.reopens, r->disp ? "flip" : "output",
                io_lat_quantile(&lat_cam, 0.5), io_lat_quantile(&lat_cam, 0.99),
                r->disp ? "flip" : "output", io_lat_quantile(&lat_deq, 0.5),
                io_lat_quantile(&lat_deq, 0.99), io_lat_quantile(&lat_pipe, 0.5),
                io_lat_quantile(&lat_pipe, 0.99), vstate_word(r, now, vw, sizeof vw),
                track_word(o, r, now, tw, sizeof tw),
                r->disp ? "" : "");
        if (r->disp)
            fprintf(o->raw ? stderr : stdout,
                    "egofuse run: display %s: %llu flips, %llu missed vblanks\n",
                    io_display_describe(r->disp), (unsigned long long)r->sched.flips,
                    (unsigned long long)r->sched.misses);
        (void)v_used;
    }
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
