/* cmd_render.c - `egofuse render` and `egofuse demo`: composite a recorded
 * stereo sequence: pose -> skin -> raster per eye -> lighting layer ->
 * resample into the viewport -> composite over the virtual scene. */
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *render_usage =
    "usage: egofuse render --scene FILE --out DIR [--first K] [--frames N]\n"
    "                      [--masks] [--quiet]\n"
    "\n"
    "Composites a recorded sequence (docs/scene.md): for each frame, poses the\n"
    "mask model at t = frame / fps, renders its mask and normals from both\n"
    "HMD cameras (640x400 after the crop of eq. 1), lights the camera images\n"
    "inside the mask (Blinn-Phong + Fresnel), resamples them into the\n"
    "1194x746 viewport (eq. 2-4) and composites them over the virtual scene:\n"
    "DIR/left_NNNN.png and DIR/right_NNNN.png, 1280x800 RGB.\n"
    "\n"
    "  --scene FILE   the scene file\n"
    "  --out DIR      output folder (created if missing)\n"
    "  --first K      first frame (default 0)\n"
    "  --frames N     number of frames (default: all of the scene)\n"
    "  --masks        also write the masks, DIR/mask_left_NNNN.png ...\n"
    "  --quiet        no progress line\n"
    "  -h, --help     this text\n";

static const char *demo_usage =
    "usage: egofuse demo [--samples DIR] [--out DIR] [--frames N]\n"
    "\n"
    "Runs `egofuse render` on the bundled samples, which `make demo` generates\n"
    "into build/samples (build/gen_samples --out DIR makes them by hand).\n"
    "\n"
    "  --samples DIR  folder holding scene.txt (default build/samples)\n"
    "  --out DIR      output folder (default out/demo)\n"
    "  --frames N     number of frames (default: all)\n"
    "  -h, --help     this text\n";

typedef struct render_opts {
    const char *scene;
    const char *out;
    int first, frames;
    int masks, quiet;
} render_opts;

/* Buffers of one eye. */
typedef struct eye_buf {
    float *depth, *nrm;
    uint8_t *mask;
    uint8_t *layer;          /* premultiplied lighting layer, RGBA8 */
    io_image cam, virt, rgb; /* camera (RGBA8), virtual (RGBA8), output */
} eye_buf;

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static fuse_lighting scene_lighting(const io_scene *s, const kin_camera *cam)
{
    fuse_lighting L = fuse_lighting_default();
    if (s->has_lighting) {
        L.light_count = s->light_count;
        for (int i = 0; i < 3; i++) {
            L.ambient[i] = s->ambient[i];
            L.tone[i] = s->tone[i];
        }
        L.kd = s->kd;
        L.ks = s->ks;
        L.shininess = s->shininess;
        L.kf = s->kf;
        for (int i = 0; i < s->light_count && i < FUSE_MAX_LIGHTS; i++) {
            for (int k = 0; k < 3; k++) L.lights[i].color[k] = s->light_color[i][k];
            kin_vec3 d = kin_v3(s->light_dir[i][0], s->light_dir[i][1], s->light_dir[i][2]);
            d = kin_v3_norm(kin_mat4_mul_dir(&cam->view, d));
            L.lights[i].dir[0] = d.x;
            L.lights[i].dir[1] = d.y;
            L.lights[i].dir[2] = d.z;
        }
    } else {
        /* The default light is given in view space already. */
    }
    return L;
}

static int load_rgba(const char *path, int w, int h, const char *what,
                     io_image *img)
{
    io_error err;
    io_image_free(img);
    if (io_image_load(path, IO_U8, 4, img, &err) != IO_OK)
        return cli_fail("%s", err.msg);
    if (img->width != w || img->height != h) {
        cli_fail("%s: %s image is %dx%d, expected %dx%d", path, what,
                 img->width, img->height, w, h);
        io_image_free(img);
        return EXIT_FAIL;
    }
    return EXIT_OK;
}

static int save_rgb(const char *path, const io_image *rgba, io_image *rgb)
{
    io_error err;
    const uint8_t *s = rgba->data;
    uint8_t *d = rgb->data;
    for (int y = 0; y < rgba->height; y++)
        for (int x = 0; x < rgba->width; x++)
            for (int k = 0; k < 3; k++)
                d[(size_t)y * rgb->stride + 3 * x + k] = s[(size_t)y * rgba->stride + 4 * x + k];
    if (io_image_save(path, rgb, &err) != IO_OK) return cli_fail("%s", err.msg);
    return EXIT_OK;
}

static int save_mask(const char *path, const uint8_t *mask, int w, int h)
{
    io_image img = {(void *)mask, w, h, 1, IO_U8, (size_t)w};
    io_error err;
    if (io_image_save(path, &img, &err) != IO_OK) return cli_fail("%s", err.msg);
    return EXIT_OK;
}

static int render(const render_opts *o)
{
    io_error err;
    io_scene sc;
    if (io_scene_load(o->scene, &sc, &err) != IO_OK) return cli_fail("%s", err.msg);
    int first = o->first, count = o->frames > 0 ? o->frames : sc.frames - first;
    if (first >= sc.frames)
        return cli_fail("%s: --first %d, but the scene has %d frames", o->scene, first, sc.frames);
    if (first + count > sc.frames)
        return cli_fail("%s: frames %d..%d asked, but the scene has %d frames", o->scene, first,
                        first + count - 1, sc.frames);

    /* Every input must be there before anything is written. */
    char path[IO_PATH_MAX + 64];
    for (int f = first; f < first + count; f++)
        for (int e = 0; e < 2; e++) {
            const char *pat[2] = {sc.camera[e], sc.virt[e]};
            for (int k = 0; k < 2; k++) {
                io_scene_frame_path(&sc, pat[k], f, path, sizeof path);
                if (!file_exists(path))
                    return cli_fail("%s: frame %d: %s is missing", o->scene, f, path);
            }
        }

    kin_model model;
    char model_path[IO_PATH_MAX + 64];
    io_scene_frame_path(&sc, sc.model, 0, model_path, sizeof model_path);
    if (io_gltf_load(model_path, &model, &err) != IO_OK) return cli_fail("%s", err.msg);

    int rc = EXIT_FAIL;
    const kin_animation *anim = NULL;
    if (sc.animation[0]) {
        for (int i = 0; i < model.anim_count; i++)
            if (!strcmp(model.anims[i].name, sc.animation)) anim = &model.anims[i];
        if (!anim) {
            cli_fail("%s: the scene's animation '%s' is not in %s", o->scene, sc.animation, model_path);
            kin_model_free(&model);
            return EXIT_FAIL;
        }
    } else if (model.anim_count > 0) {
        anim = &model.anims[0];
    }
    int head = -1;
    if (sc.head_node[0]) {
        head = kin_model_find_node(&model, sc.head_node);
        if (head < 0) {
            cli_fail("%s: the scene's head node '%s' is not in %s", o->scene, sc.head_node, model_path);
            kin_model_free(&model);
            return EXIT_FAIL;
        }
    }

    kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
    kin_sthmd_geometry g = kin_sthmd_geometry_of(NULL);
    const int cw = g.crop_width, ch = g.crop_height;
    const size_t cpx = (size_t)cw * (size_t)ch;

    pose_state ps;
    eye_buf eb[2];
    memset(eb, 0, sizeof eb);
    int ok = pose_init(&ps, &model) == 0;
    for (int e = 0; e < 2 && ok; e++) {
        eb[e].depth = malloc(sizeof(float) * cpx);
        eb[e].nrm = malloc(sizeof(float) * 3 * cpx);
        eb[e].mask = malloc(cpx);
        eb[e].layer = malloc(4 * cpx);
        ok = eb[e].depth && eb[e].nrm && eb[e].mask && eb[e].layer &&
             io_image_alloc(&eb[e].rgb, hd.lcd_width, hd.lcd_height, 3, IO_U8, &err) == IO_OK;
    }
    if (!ok) {
        cli_fail("out of memory");
        goto done;
    }
    if (cli_mkdirs(o->out) != 0) {
        cli_fail("%s: cannot create the output folder", o->out);
        goto done;
    }

    progress pr;
    progress_start(&pr, count);
    if (o->quiet) pr.enabled = 0;
    static const char *eye_name[2] = {"left", "right"};
    /* Seconds spent in each stage, summed over the frames. */
    double t_pose = 0.0, t_raster = 0.0, t_fuse = 0.0, t0;
    for (int f = first; f < first + count; f++) {
        float t = (float)f / sc.fps;
        t0 = cli_now();
        pose_eval(&ps, anim, t);
        t_pose += cli_now() - t0;
        kin_mat4 head_m = head >= 0 ? ps.world[head] : kin_mat4_identity();
        for (int e = 0; e < 2; e++) {
            eye_buf *b = &eb[e];
            kin_camera cam = kin_sthmd_camera(&hd, &head_m, (kin_eye)e);
            rast_target tg = {cw, ch, b->depth, cw, b->mask, cw, b->nrm, 3 * cw, 3};
            t0 = cli_now();
            rast_target_clear(&tg);
            rast_result rr = pose_draw(&ps, &cam, &tg, NULL);
            t_raster += cli_now() - t0;
            if (rr != RAST_OK) {
                cli_fail("%s: frame %d: cannot draw the model: %s", model_path, f, rast_result_str(rr));
                goto done;
            }

            io_scene_frame_path(&sc, sc.camera[e], f, path, sizeof path);
            if (load_rgba(path, hd.cam_width, hd.cam_height, "camera", &b->cam)) goto done;
            io_scene_frame_path(&sc, sc.virt[e], f, path, sizeof path);
            if (load_rgba(path, hd.lcd_width, hd.lcd_height, "virtual scene", &b->virt)) goto done;

            fuse_image full = {b->cam.data, b->cam.width, b->cam.height, (int)b->cam.stride};
            fuse_image P = fuse_image_rows(&full, g.crop_y0, ch);
            fuse_image Q = {b->layer, cw, ch, 4 * cw};
            fuse_image V = {b->virt.data, b->virt.width, b->virt.height, (int)b->virt.stride};
            fuse_lighting L = scene_lighting(&sc, &cam);
            fuse_intrinsics K = {cam.fx, cam.fy, cam.cx, cam.cy};
            t0 = cli_now();
            fuse_result fr = fuse_light(&L, &K, &P, b->mask, cw, b->nrm, 3 * cw, &Q);
            if (fr == FUSE_OK) fr = fuse_composite(&Q, &V, g.vp_x0, g.vp_y0, g.vp_width, g.vp_height, &V);
            t_fuse += cli_now() - t0;
            if (fr != FUSE_OK) {
                cli_fail("%s: frame %d: %s", o->scene, f, fuse_result_str(fr));
                goto done;
            }
            snprintf(path, sizeof path, "%s/%s_%04d.png", o->out, eye_name[e], f);
            if (save_rgb(path, &b->virt, &b->rgb)) goto done;
            if (o->masks) {
                snprintf(path, sizeof path, "%s/mask_%s_%04d.png", o->out, eye_name[e], f);
                if (save_mask(path, b->mask, cw, ch)) goto done;
            }
        }
        progress_step(&pr, f - first + 1, "frame");
    }
    progress_end(&pr);
    if (!o->quiet) {
        double wall = cli_now() - pr.t0;
        printf("egofuse: wrote %d stereo frames (1280x800 per eye) to %s\n", count, o->out);
        printf("egofuse: per stereo frame: pose+skin %.3f ms, raster %.3f ms, "
               "lighting+composite %.3f ms (scalar reference, 1 thread); "
               "with image files %.1f ms\n",
               1e3 * t_pose / count, 1e3 * t_raster / count, 1e3 * t_fuse / count,
               1e3 * wall / count);
    }
    rc = EXIT_OK;
done:
    for (int e = 0; e < 2; e++) {
        free(eb[e].depth);
        free(eb[e].nrm);
        free(eb[e].mask);
        free(eb[e].layer);
        io_image_free(&eb[e].cam);
        io_image_free(&eb[e].virt);
        io_image_free(&eb[e].rgb);
    }
    pose_free(&ps);
    kin_model_free(&model);
    return rc;
}

enum { O_SCENE = 256, O_OUT, O_FIRST, O_FRAMES, O_MASKS, O_QUIET, O_SAMPLES };

int cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"scene", required_argument, 0, O_SCENE},
        {"out", required_argument, 0, O_OUT},
        {"first", required_argument, 0, O_FIRST},
        {"frames", required_argument, 0, O_FRAMES},
        {"masks", no_argument, 0, O_MASKS},
        {"quiet", no_argument, 0, O_QUIET},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    render_opts o = {0};
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'h': fputs(render_usage, stdout); return EXIT_OK;
        case O_SCENE: o.scene = optarg; break;
        case O_OUT: o.out = optarg; break;
        case O_FIRST:
            if (!cli_parse_int(optarg, 0, 1 << 24, &o.first))
                return cli_usage_error("render", "--first '%s': not a frame number", optarg);
            break;
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 1 << 24, &o.frames))
                return cli_usage_error("render", "--frames '%s': not a positive count", optarg);
            break;
        case O_MASKS: o.masks = 1; break;
        case O_QUIET: o.quiet = 1; break;
        case ':': return cli_usage_error("render", "option %s needs a value", argv[optind - 1]);
        default: return cli_usage_error("render", "unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind < argc) return cli_usage_error("render", "unexpected argument '%s'", argv[optind]);
    if (!o.scene) return cli_usage_error("render", "--scene is required");
    if (!o.out) return cli_usage_error("render", "--out is required");
    return render(&o);
}

int cmd_demo(int argc, char **argv)
{
    static const struct option opts[] = {
        {"samples", required_argument, 0, O_SAMPLES},
        {"out", required_argument, 0, O_OUT},
        {"frames", required_argument, 0, O_FRAMES},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    const char *samples = "build/samples";
    render_opts o = {0};
    o.out = "out/demo";
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
        switch (c) {
        case 'h': fputs(demo_usage, stdout); return EXIT_OK;
        case O_SAMPLES: samples = optarg; break;
        case O_OUT: o.out = optarg; break;
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 1 << 24, &o.frames))
                return cli_usage_error("demo", "--frames '%s': not a positive count", optarg);
            break;
        case ':': return cli_usage_error("demo", "option %s needs a value", argv[optind - 1]);
        default: return cli_usage_error("demo", "unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind < argc) return cli_usage_error("demo", "unexpected argument '%s'", argv[optind]);
    char scene[IO_PATH_MAX + 32];
    snprintf(scene, sizeof scene, "%s/scene.txt", samples);
    if (!file_exists(scene))
        return cli_fail("%s is missing: run 'make demo' (it generates the samples), or "
                        "'build/gen_samples --out %s'", scene, samples);
    o.scene = scene;
    return render(&o);
}
