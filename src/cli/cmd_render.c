/* cmd_render.c - `egofuse render` and `egofuse demo`: composite a recorded
 * stereo sequence: pose -> skin -> raster per eye -> lighting layer ->
 * resample into the viewport -> composite over the virtual scene. */
#include "cli.h"
#include "cli_lod.h"

#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *render_usage =
    "usage: egofuse render --scene FILE --out DIR [--first K] [--frames N]\n"
    "                      [--masks] [--quiet] [--threads 1|2] [--no-depth]\n"
    "                      [--tone-match S] [--pose animation|tracking]\n"
    "                      [--calib FILE] [--predict MS] [--no-filter]\n"
    "                      [--refine BAND] [--smooth-normals R] [--aa N] [--soft-edges|--hard-edges] [--edge-fade K] [--hide PARTS]\n"
    "                      [--prop MODEL@X,Y,Z[,YAW]]... [--allow-outside]\n"
    "                      [--lod MODE] [--lod-px PX] [--view crop|reproject]\n"
    "                      [--hmd-ipd M] [--hmd-camera-offset M]\n"
    "                      [--hmd-calibration FILE | --hmd-calibration-left FILE\n"
    "                       --hmd-calibration-right FILE]\n"
    "\n"
    "Composites a recorded sequence (docs/scene.md): for each frame, poses the\n"
    "mask model at t = frame / fps, renders its mask and normals from both\n"
    "HMD cameras (the paper's HMD: 640x400 after the crop of eq. 1), lights\n"
    "the camera images inside the mask (Blinn-Phong + Fresnel), resamples\n"
    "them into the viewport (1194x746, eq. 2-4) and composites them over the\n"
    "virtual scene: DIR/left_NNNN.png and DIR/right_NNNN.png, RGB of the\n"
    "display's size (1280x800). A scene with an `hmd` key (docs/scene.md:\n"
    "consumer, highend) is rendered with that HMD's sizes and eq. 1-4.\n"
    "\n"
    "  --scene FILE   the scene file\n"
    "  --view V       crop (default): the paper's crop and scale into the\n"
    "                 viewport (eq. 1-4); reproject: the hands as the eye sees\n"
    "                 them, the model drawn from the eye and the camera image\n"
    "                 sampled through its depth, over the whole display\n"
    "                 (docs/eyeview.md; not with --aa)\n"
    "  --hmd-ipd M    the eyes' separation, 0.04..0.09 m (default: the HMD's,\n"
    "                 65 mm for the paper's): places the eyes of --view reproject\n"
    "  --hmd-camera-offset M  D, the cameras in front of the eyes, 0..0.25 m\n"
    "                 (default: the HMD's, 85 mm for the paper's)\n"
    "  --out DIR      output folder (created if missing)\n"
    "  --first K      first frame (default 0)\n"
    "  --frames N     number of frames (default: all of the scene)\n"
    "  --masks        also write the masks, DIR/mask_left_NNNN.png ...\n"
    "  --quiet        no progress line\n"
    "  --threads T    1, or 2 (default: one eye per thread; same bytes)\n"
    "  --no-depth     ignore the virtual scene's depth images (by default a\n"
    "                 virtual object in front of the hand hides it)\n"
    "  --cull-back    skip back faces: about half the triangle setups, the same\n"
    "                 mask for closed, consistently wound models (the samples')\n"
    "  --tone-match S match the camera's colour tone to the virtual scene's,\n"
    "                 strength S in [0, 1] (default 0: off)\n"
    "  --pose P       where the pose comes from: 'animation' (default: the\n"
    "                 scene's animation at t) or 'tracking' (the scene's\n"
    "                 recorded tracking file: head, shoulders, hands, gloves\n"
    "                 -> One Euro filter + prediction -> two-bone arm IK and\n"
    "                 glove mapping; docs/tracking.md)\n"
    "  --calib FILE   with --pose tracking: per-user calibration\n"
    "                 ('egofuse-calib 1': bone scales, glove ranges)\n"
    "  --predict MS   with --pose tracking: predict the pose MS ms past the\n"
    "                 camera frame's time (processing latency), 0..100,\n"
    "                 default 0\n"
    "  --no-filter    with --pose tracking: the newest raw sample, no filter\n"
    "  --hmd-calibration FILE  the cameras' lenses from an OpenCV calibration\n"
    "                 file (YAML/XML; a stereo file: M1/D1 left, M2/D2 right), or\n"
    "                 --hmd-calibration-left / -right FILE one each: the masks are\n"
    "                 drawn through the lens (docs/lens.md); the camera images\n"
    "                 are then of the calibration's size\n"
    "\n"
    "EGOFUSE_ISA=ref|sse2|avx2|avx512 caps the instruction set (same bytes).\n"
    "  --refine BAND  refine the masks by colour in a band of BAND px (1..64,\n"
    "                 16 is `egofuse eval`'s default) around their edges; with\n"
    "                 --pose tracking the elbows are first fitted to the camera\n"
    "                 images (pipe_fit), the last refined mask is the prior\n"
    "                 around slow hands and the filter's lag compensation\n"
    "                 grows with the hand's speed, the fast hands are first\n"
    "                 moved onto their colour: eval's method refine\n"
    "  --hide PARTS   do not show these parts of the operator's arms: a comma\n"
    "                 list of left-hand, left-arm, right-hand, right-arm (or\n"
    "                 hands, arms, all); a hand is the wrist joint and below,\n"
    "                 an arm the shoulder, upper arm and forearm\n"
    "                 (docs/parts_props.md)\n"
    "  --prop MODEL@X,Y,Z[,YAW]\n"
    "                 cut in a real object like the hands: the glTF MODEL in its\n"
    "                 rest pose, placed at (X, Y, Z) metres in the world frame and\n"
    "                 turned YAW degrees about +Y (default 0); up to 8 props\n"
    "  --aa N         anti-aliased silhouettes: the mask is the coverage of N\n"
    "                 samples per pixel (4, 8 or 16; 0: off, the binary mask of\n"
    "                 the pixel centres); default 0\n"
    "  --smooth-normals R  sum the model's normals over a (2R+1)^2 window\n"
    "                 before lighting (1..4; default 0: off): for models of\n"
    "                 crossing parts whose shading shows seams. With --refine\n"
    "                 the normals are always smoothed (default R 3) and\n"
    "                 continued beyond the model's rim to the refined edge;\n"
    "                 -1: the model's own normals (the view vector beyond it)\n"
    "  --soft-edges   soft silhouettes at the cost of one pass over the mask:\n"
    "                 its edge pixels fade by the share of their 3x3 window\n"
    "                 inside it, a one-pixel ramp instead of stair-steps\n"
    "                 (the default, except with --aa), in either --view\n"
    "  --hard-edges   the binary mask's stair-stepped silhouettes\n"
    "  --edge-fade K  soft viewport edges: where the camera image ends inside\n"
    "                 the display, the hands fade over its last K pixels\n"
    "                 (1..64; 0: off, a hard cut); default 4\n"
    CLI_LOD_USAGE
    "  --allow-outside  let the models' buffer and image URIs name files\n"
    "                 outside their folder (absolute, `..`, symlinks out);\n"
    "                 refused by default (docs/io.md)\n"
    "  -h, --help     this text\n";

static const char *demo_usage =
    "usage: egofuse demo [--samples DIR] [--out DIR] [--frames N]\n"
    "\n"
    "Runs `egofuse render --cull-back --soft-edges` on the bundled samples (closed\n"
    "arm meshes: culling back faces gives the same masks; soft silhouettes instead\n"
    "of stair-steps, docs/antialias.md), which `make demo` generates into\n"
    "build/samples (build/gen_samples --out DIR makes them by hand).\n"
    "\n"
    "  --samples DIR  folder holding scene.txt (default build/samples)\n"
    "  --out DIR      output folder (default out/demo)\n"
    "  --frames N     number of frames (default: all)\n"
    "  -h, --help     this text\n";

#define RENDER_MAX_PROPS 8

typedef struct render_opts {
    const char *scene;
    const char *out;
    int first, frames;
    int masks, quiet;
    int threads;           /* 0 = 2 */
    int no_depth;          /* ignore the virtual scene's depth */
    float tone_match;      /* 0 = off */
    int pose_tracking;     /* 1: pose from the scene's tracking file */
    const char *calib;     /* per-user calibration file, or NULL */
    float predict_ms;      /* display time past the frame time */
    int no_filter;         /* raw samples instead of the One Euro filter */
    int cull_back;         /* cull back faces (closed models) */
    int soft_edge;         /* pipe_desc.soft_edge */
    int refine;            /* refinement band, px; 0 = off */
    unsigned hide;         /* PIPE_PART_* bits not shown */
    int nprops;            /* --prop: models fixed in the world frame */
    struct {
        const char *path;
        float at[3], yaw_deg;
    } props[RENDER_MAX_PROPS];
    int smooth_normals;    /* fuse_normal_smooth radius; 0 = off */
    int lod;               /* --lod: a level, PIPE_LOD_AUTO; 0 = off */
    float lod_px;          /* --lod-px */
    const char *hmd_calib[3]; /* --hmd-calibration, -left, -right */
    kin_sthmd_desc hmd;    /* zero = the paper's; lenses from hmd_calib */
    int aa;                /* coverage samples per pixel; 0 = off */
    int view;              /* --view: PIPE_VIEW_CROP (default), _REPROJECT */
    float ipd_m, cam_offset_m; /* --hmd-ipd, --hmd-camera-offset; 0 = the HMD's */
    int edge_fade;         /* pipe_desc.edge_fade: 0 default, -1 off */
} render_opts;

/* The pose from tracking: the recording, the rig, the filter and the
 * locals handed to pipe_frame (docs/tracking.md). */
typedef struct track_pose {
    kin_track_sample *samples;
    int count, next;           /* samples[next] is the first not yet used */
    kin_arm_rig rig;
    kin_user_calib calib;
    kin_filter filter;
    kin_transform *locals;
    int rejected;              /* samples kin_arm_rig_pose could not use */
    unsigned fit_skip;         /* pipe_frame_in.fit_skip: untracked hands */
    float speed[2];            /* pipe_frame_in.hand_speed: wrists, m/s */
    pipe_desc pd;              /* the refine method's tracking (pipe_track_output) */
} track_pose;

static void track_pose_free(track_pose *tp)
{
    io_track_free(tp->samples);
    free(tp->locals);
    memset(tp, 0, sizeof *tp);
}

static int track_pose_init(track_pose *tp, const render_opts *o, const io_scene *sc,
                           const kin_model *model, const char *model_path)
{
    io_error err;
    char path[IO_PATH_MAX + 64], why[512];
    memset(tp, 0, sizeof *tp);
    if (!sc->tracking[0])
        return io_term_fail("%s: --pose tracking, but the scene has no 'tracking' file "
                        "(docs/scene.md)", o->scene);
    io_scene_frame_path(sc, sc->tracking, 0, path, sizeof path);
    if (io_track_load(path, &tp->samples, &tp->count, &err) != IO_OK) return io_term_fail("%s", err.msg);
    if (tp->count < 1) {
        track_pose_free(tp);
        return io_term_fail("%s: no tracking samples", path);
    }
    tp->calib = kin_user_calib_identity();
    if (o->calib && io_user_calib_load(o->calib, &tp->calib, &err) != IO_OK) {
        track_pose_free(tp);
        return io_term_fail("%s", err.msg);
    }
    if (kin_arm_rig_init(&tp->rig, model, why, sizeof why) != 0) {
        track_pose_free(tp);
        return io_term_fail("%s: cannot pose it from tracking: %s", model_path, why);
    }
    /* with --refine: the refine method's filter (pipe_track_filter_desc) */
    tp->pd.refine_band = o->refine;
    kin_filter_desc fd = pipe_track_filter_desc(&tp->pd);
    kin_filter_init(&tp->filter, &fd);
    tp->locals = malloc(sizeof *tp->locals * (size_t)model->node_count);
    if (!tp->locals) {
        track_pose_free(tp);
        return io_term_fail("out of memory");
    }
    return EXIT_OK;
}

/* The pose at frame time t: every sample up to t goes through the filter
 * (or is taken raw), the output predicted to t + predict drives the rig. */
static void track_pose_at(track_pose *tp, const render_opts *o, const kin_model *model,
                          double t)
{
    kin_track_sample cur;
    memset(&cur, 0, sizeof cur);   /* before the first sample: rest pose */
    while (tp->next < tp->count && tp->samples[tp->next].t <= t + 1e-9) {
        if (!o->no_filter) kin_filter_push(&tp->filter, &tp->samples[tp->next]);
        tp->next++;
    }
    if (tp->next > 0) {
        if (o->no_filter) cur = tp->samples[tp->next - 1];
        else pipe_track_output(&tp->pd, &tp->filter, t + 1e-3 * o->predict_ms, &cur, tp->speed);
    }
    kin_pose_rest(model, tp->locals);
    tp->fit_skip = ((cur.valid & KIN_TRACK_HAND_L) ? 0u : 1u) | ((cur.valid & KIN_TRACK_HAND_R) ? 0u : 2u);
    if (!kin_arm_rig_pose(&tp->rig, model, &tp->calib, NULL, &cur, tp->locals, NULL)) {
        /* a sample the model cannot take: keep the rest pose, count it */
        kin_pose_rest(model, tp->locals);
        tp->rejected++;
    }
}

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static int load_rgba(const char *path, int w, int h, const char *what,
                     io_image *img)
{
    io_error err;
    io_image_free(img);
    if (io_image_load(path, IO_U8, 4, img, &err) != IO_OK)
        return io_term_fail("%s", err.msg);
    if (img->width != w || img->height != h) {
        io_term_fail("%s: %s image is %dx%d, expected %dx%d", path, what,
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
    if (io_image_save(path, rgb, &err) != IO_OK) return io_term_fail("%s", err.msg);
    return EXIT_OK;
}

static int save_mask(const char *path, const uint8_t *mask, int w, int h)
{
    io_image img = {(void *)mask, w, h, 1, IO_U8, (size_t)w};
    io_error err;
    if (io_image_save(path, &img, &err) != IO_OK) return io_term_fail("%s", err.msg);
    return EXIT_OK;
}

static fuse_image as_fuse(const io_image *img)
{
    fuse_image f = {img->data, img->width, img->height, (int)img->stride};
    return f;
}

/* Loads the --prop models, adds them to the pipe and places them:
 * world_from_prop = translate(at) * rotate_y(yaw). *loaded counts the
 * models to free (also on failure). */
static int render_props(const render_opts *o, pipe_ctx *pp, kin_model *props, int *loaded,
                        kin_mat4 *world, const kin_mat4 **ptr)
{
    io_error err;
    for (int k = 0; k < o->nprops; k++) {
        if (io_gltf_load(o->props[k].path, &props[k], &err) != IO_OK)
            return io_term_fail("--prop %s: %s", o->props[k].path, err.msg);
        (*loaded)++;
        if (pipe_add_prop(pp, &props[k]) != k)
            return io_term_fail("--prop %s: the model has no triangles (or out of memory)",
                            o->props[k].path);
        kin_vec3 t = kin_v3(o->props[k].at[0], o->props[k].at[1], o->props[k].at[2]);
        kin_quat r = kin_quat_axis_angle(kin_v3(0, 1, 0),
                                         o->props[k].yaw_deg * 0.017453292519943295f);
        world[k] = kin_mat4_from_tr(t, r);
        ptr[k] = &world[k];
    }
    return EXIT_OK;
}

static int render(const render_opts *o)
{
    io_error err;
    io_scene sc;
    if (io_scene_load(o->scene, &sc, &err) != IO_OK) return io_term_fail("%s", err.msg);
    int first = o->first, count = o->frames > 0 ? o->frames : sc.frames - first;
    if (first >= sc.frames)
        return io_term_fail("%s: --first %d, but the scene has %d frames", o->scene, first, sc.frames);
    if (first + count > sc.frames)
        return io_term_fail("%s: frames %d..%d asked, but the scene has %d frames", o->scene, first,
                        first + count - 1, sc.frames);

    /* Every input must be there before anything is written. */
    char path[IO_PATH_MAX + 64];
    for (int f = first; f < first + count; f++)
        for (int e = 0; e < 2; e++) {
            const char *pat[3] = {sc.camera[e], sc.virt[e], sc.virt_depth[e]};
            for (int k = 0; k < 3; k++) {
                if (!pat[k][0]) continue; /* no depth for this scene */
                io_scene_frame_path(&sc, pat[k], f, path, sizeof path);
                if (!file_exists(path))
                    return io_term_fail("%s: frame %d: %s is missing", o->scene, f, path);
            }
        }

    kin_model model;
    char model_path[IO_PATH_MAX + 64];
    io_scene_frame_path(&sc, sc.model, 0, model_path, sizeof model_path);
    if (io_gltf_load(model_path, &model, &err) != IO_OK) return io_term_fail("%s", err.msg);

    const kin_animation *anim = NULL;
    if (sc.animation[0]) {
        for (int i = 0; i < model.anim_count; i++)
            if (!strcmp(model.anims[i].name, sc.animation)) anim = &model.anims[i];
        if (!anim) {
            io_term_fail("%s: the scene's animation '%s' is not in %s", o->scene, sc.animation, model_path);
            kin_model_free(&model);
            return EXIT_FAIL;
        }
    } else if (model.anim_count > 0) {
        anim = &model.anims[0];
    }
    int head = -1;
    if (sc.head_node[0] && (head = kin_model_find_node(&model, sc.head_node)) < 0) {
        io_term_fail("%s: the scene's head node '%s' is not in %s", o->scene, sc.head_node, model_path);
        kin_model_free(&model);
        return EXIT_FAIL;
    }

    track_pose tp;
    memset(&tp, 0, sizeof tp);
    if (o->pose_tracking && track_pose_init(&tp, o, &sc, &model, model_path) != EXIT_OK) {
        kin_model_free(&model);
        return EXIT_FAIL;
    }

    int rc = EXIT_FAIL;
    pipe_desc pd = {0};
    pd.hmd = o->hmd;
    pd.threads = o->threads;
    pd.tone_match = o->tone_match;
    pd.cull = o->cull_back ? RAST_CULL_BACK : RAST_CULL_NONE;
    pd.refine_band = o->refine;
    pd.normal_smooth = o->smooth_normals;
    pd.aa_samples = o->aa;
    pd.soft_edge = o->soft_edge;
    pd.edge_fade = o->edge_fade;
    pd.fit_rig = o->refine && o->pose_tracking ? &tp.rig : NULL;
    /* the scene's HMD (its `hmd` key, checked on load), or the paper's */
    if (sc.hmd[0]) {
        kin_sthmd_preset(sc.hmd, &pd.hmd);
        pd.hmd.lens[0] = o->hmd.lens[0]; /* --hmd-calibration: on that HMD */
        pd.hmd.lens[1] = o->hmd.lens[1];
    }
    if (o->ipd_m > 0.0f) pd.hmd.ipd_m = o->ipd_m;
    if (o->cam_offset_m > 0.0f) pd.hmd.cam_offset_m = o->cam_offset_m;
    pd.eye_view = o->view;
    pipe_ctx *pp = pipe_create(&pd, &model);
    pipe_lod lod = {0};
    kin_sthmd_desc hd = pp ? pipe_hmd(pp) : kin_sthmd_desc_resolved(&pd.hmd);
    io_image cam[2] = {{0}}, virt[2] = {{0}}, vdepth[2] = {{0}}, rgb = {0};
    kin_model props[RENDER_MAX_PROPS];
    kin_mat4 prop_world[RENDER_MAX_PROPS];
    const kin_mat4 *prop_ptr[RENDER_MAX_PROPS];
    int props_loaded = 0;
    if (!pp) {
        if (o->aa && (kin_lens_distorts(&pd.hmd.lens[0]) || kin_lens_distorts(&pd.hmd.lens[1])))
            io_term_fail("--aa %d: anti-aliased edges are drawn through the pinhole and cannot be used "
                     "with a distorting lens (--hmd-calibration)", o->aa);
        else if (pd.fit_rig)
            io_term_fail("cannot start the pipeline: out of memory, no thread, or the elbow fit "
                     "cannot use %s (mesh 0's skin, the arms' node chains)", model_path);
        else
            io_term_fail("cannot start the pipeline: out of memory or no thread");
        goto done;
    }
    {
        char lw[300];
        if (!cli_lens_fits(&pd.hmd, lw, sizeof lw)) {
            io_term_fail("%s: %s", o->scene, lw);
            goto done;
        }
    }
    if (cli_lod_setup(model_path, &model, o->lod, o->lod_px, pp, &lod) != EXIT_OK) goto done;
    if (render_props(o, pp, props, &props_loaded, prop_world, prop_ptr) != EXIT_OK) goto done;
    if (o->hide & ~pipe_parts_present(pp))
        fprintf(stderr, "egofuse: --hide: %s has no triangles of some of these parts (found: "
                "%s%s%s%s)\n", model_path,
                pipe_parts_present(pp) & PIPE_PART_HAND_L ? "left-hand " : "",
                pipe_parts_present(pp) & PIPE_PART_ARM_L ? "left-arm " : "",
                pipe_parts_present(pp) & PIPE_PART_HAND_R ? "right-hand " : "",
                pipe_parts_present(pp) & PIPE_PART_ARM_R ? "right-arm" : "");
    if (io_image_alloc(&rgb, hd.lcd_width, hd.lcd_height, 3, IO_U8, &err) != IO_OK) {
        io_term_fail("out of memory");
        goto done;
    }
    if (io_mkdirs(o->out) != 0) {
        io_term_fail("%s: cannot create the output folder", o->out);
        goto done;
    }

    kin_sthmd_geometry geo = pipe_geometry(pp);
    if (o->view == PIPE_VIEW_REPROJECT) { /* the eye's view: the whole display */
        geo.vp_x0 = geo.vp_y0 = 0;
        geo.vp_width = hd.lcd_width;
        geo.vp_height = hd.lcd_height;
    }
    pipe_frame_in in = {0};
    in.anim = anim;
    in.head_node = head;
    in.lighting.light = io_scene_lighting(&sc);
    in.hide = o->hide;
    in.prop_world = props_loaded ? prop_ptr : NULL;
    in.prop_count = props_loaded;
    static const char *eye_name[2] = {"left", "right"};
    pipe_frame_stats st, sum = {0};
    long lod_sum = 0;
    io_progress pr;
    io_progress_start(&pr, count);
    if (o->quiet) pr.enabled = 0;
    for (int f = first; f < first + count; f++) {
        for (int e = 0; e < 2; e++) {
            io_scene_frame_path(&sc, sc.camera[e], f, path, sizeof path);
            if (load_rgba(path, hd.cam_width, hd.cam_height, "camera", &cam[e])) goto done;
            io_scene_frame_path(&sc, sc.virt[e], f, path, sizeof path);
            if (load_rgba(path, hd.lcd_width, hd.lcd_height, "virtual scene", &virt[e])) goto done;
            if (sc.virt_depth[e][0] && !o->no_depth) {
                io_scene_frame_path(&sc, sc.virt_depth[e], f, path, sizeof path);
                io_image_free(&vdepth[e]);
                if (io_image_load(path, IO_F32, 1, &vdepth[e], &err) != IO_OK) {
                    io_term_fail("%s", err.msg);
                    goto done;
                }
                if (vdepth[e].width != hd.lcd_width || vdepth[e].height != hd.lcd_height) {
                    io_term_fail("%s: virtual depth image is %dx%d, expected %dx%d", path,
                             vdepth[e].width, vdepth[e].height, hd.lcd_width, hd.lcd_height);
                    goto done;
                }
                in.virt_depth[e] = vdepth[e].data;
                in.virt_depth_stride[e] = (int)(vdepth[e].stride / sizeof(float));
            }
            in.camera[e] = as_fuse(&cam[e]);
            in.virt[e] = as_fuse(&virt[e]);
            in.out[e] = in.virt[e]; /* composite in place */
        }
        /* Opaque virtual images (checked once per frame; decoding the PNGs
         * costs far more): the in-place composite then leaves V alone
         * where the hand is not. Same bytes either way. */
        in.virt_opaque = pipe_image_opaque(&in.virt[0], geo.vp_x0, geo.vp_y0, geo.vp_width,
                                           geo.vp_height) &&
                         pipe_image_opaque(&in.virt[1], geo.vp_x0, geo.vp_y0, geo.vp_width,
                                           geo.vp_height);
        in.time = sc.anim_start + (float)f / sc.fps;
        if (o->pose_tracking) {
            track_pose_at(&tp, o, &model, (double)f / (double)sc.fps);
            in.locals = tp.locals;
            in.fit_skip = tp.fit_skip;
            in.hand_speed = tp.speed;
        }
        char why[256];
        pipe_result pr_ = pipe_frame(pp, &in, &st, why, sizeof why);
        if (pr_ != PIPE_OK) {
            io_term_fail("%s: frame %d: %s", o->scene, f, why);
            goto done;
        }
        sum.ms_pose += st.ms_pose;
        sum.ms_total += st.ms_total;
        for (int e = 0; e < 2; e++) {
            sum.ms_raster[e] += st.ms_raster[e];
            sum.ms_fuse[e] += st.ms_fuse[e];
            lod_sum += st.lod_level[e];
        }
        for (int e = 0; e < 2; e++) {
            snprintf(path, sizeof path, "%s/%s_%04d.png", o->out, eye_name[e], f);
            if (save_rgb(path, &virt[e], &rgb)) goto done;
            if (o->masks) {
                int mw, mh;
                const uint8_t *m = pipe_mask(pp, e, &mw, &mh);
                snprintf(path, sizeof path, "%s/mask_%s_%04d.png", o->out, eye_name[e], f);
                if (save_mask(path, m, mw, mh)) goto done;
            }
        }
        io_progress_step(&pr, f - first + 1, "frame");
    }
    io_progress_end(&pr);
    if (!o->quiet) {
        double wall = io_now_s() - pr.t0;
        printf("egofuse: wrote %d stereo frames (%dx%d per eye) to %s\n", count, hd.lcd_width,
               hd.lcd_height, o->out);
        printf("egofuse: per stereo frame, %s, %d thread%s: %.3f ms (pose+skin %.3f ms; "
               "per eye: raster %.3f ms, lighting+composite %.3f ms); with image files %.1f ms\n",
               ef_isa_name((ef_isa)pipe_isa(pp)),
               o->threads == 1 ? 1 : 2, o->threads == 1 ? "" : "s", sum.ms_total / count,
               sum.ms_pose / count, (sum.ms_raster[0] + sum.ms_raster[1]) / (2.0 * count),
               (sum.ms_fuse[0] + sum.ms_fuse[1]) / (2.0 * count), 1e3 * wall / count);
        if (o->lod) {
            char ln[32];
            printf("egofuse: levels of detail %s: %d levels (", cli_lod_name(o->lod, o->lod_px,
                   ln, sizeof ln), lod.level_count);
            for (int l = 0; l < lod.level_count; l++)
                printf("%s%ld", l ? ", " : "", lod.level[l].triangles);
            printf(" triangles), mean level drawn %.2f\n", (double)lod_sum / (2.0 * count));
        }
        if (o->view == PIPE_VIEW_REPROJECT)
            printf("egofuse: view reproject (docs/eyeview.md): %ld eye-frame%s fell back to the "
                   "crop (the eye inside the model)\n", st.view_fallbacks,
                   st.view_fallbacks == 1 ? "" : "s");
        if (o->pose_tracking)
            printf("egofuse: pose from tracking (%d samples, %s, prediction %.0f ms%s%s)%s\n",
                   tp.count, o->no_filter ? "raw" : "One Euro filter", (double)o->predict_ms,
                   o->calib ? ", calibration " : "", o->calib ? o->calib : "",
                   tp.rejected ? "; some samples did not fit the model (rest pose)" : "");
    }
    rc = EXIT_OK;
done:
    for (int e = 0; e < 2; e++) {
        io_image_free(&cam[e]);
        io_image_free(&virt[e]);
        io_image_free(&vdepth[e]);
    }
    io_image_free(&rgb);
    pipe_destroy(pp);
    io_lod_free(&lod);
    for (int k = 0; k < props_loaded; k++) kin_model_free(&props[k]);
    track_pose_free(&tp);
    kin_model_free(&model);
    return rc;
}

enum { O_SCENE = 256, O_OUT, O_FIRST, O_FRAMES, O_MASKS, O_QUIET, O_SAMPLES, O_THREADS,
       O_NO_DEPTH, O_TONE, O_CULL, O_POSE, O_CALIB, O_PREDICT, O_NO_FILTER, O_REFINE, O_HIDE,
       O_PROP, O_SMOOTH, O_ALLOW_OUTSIDE, O_LOD, O_LOD_PX, O_HMD_CALIB, O_HMD_CALIB_L,
       O_HMD_CALIB_R, O_AA, O_VIEW, O_HMD_IPD, O_HMD_OFFSET, O_EDGE_FADE, O_SOFT, O_HARD };

/* --aa N: 0 (off), 4, 8 or 16 samples per pixel. 1, or 0 for another. */
static int parse_aa(const char *s, int *aa)
{
    int v;
    if (!cli_parse_int(s, 0, 16, &v) || (v != 0 && v != 4 && v != 8 && v != 16)) return 0;
    *aa = v;
    return 1;
}

/* "MODEL@X,Y,Z[,YAW]" (the last '@' ends the path). 1, or 0 when it is
 * not of that form. */
static int parse_prop(char *arg, render_opts *o)
{
    char *at = strrchr(arg, '@');
    if (!at || at == arg || o->nprops >= RENDER_MAX_PROPS) return 0;
    char nums[256];
    if (strlen(at + 1) >= sizeof nums) return 0;
    strcpy(nums, at + 1);
    float yaw = 0.0f;
    char *c3 = NULL;
    int commas = 0;
    for (char *q = nums; *q; q++)
        if (*q == ',' && ++commas == 3) c3 = q;
    if (commas == 3) {
        *c3 = '\0';
        if (!cli_parse_float(c3 + 1, &yaw)) return 0;
    } else if (commas != 2) {
        return 0;
    }
    if (!cli_parse_vec3(nums, o->props[o->nprops].at)) return 0;
    o->props[o->nprops].yaw_deg = yaw;
    *at = '\0';
    o->props[o->nprops].path = arg;
    o->nprops++;
    return 1;
}

int cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"scene", required_argument, 0, O_SCENE},
        {"out", required_argument, 0, O_OUT},
        {"first", required_argument, 0, O_FIRST},
        {"frames", required_argument, 0, O_FRAMES},
        {"masks", no_argument, 0, O_MASKS},
        {"quiet", no_argument, 0, O_QUIET},
        {"threads", required_argument, 0, O_THREADS},
        {"no-depth", no_argument, 0, O_NO_DEPTH},
        {"cull-back", no_argument, 0, O_CULL},
        {"refine", required_argument, 0, O_REFINE},
        {"lod", required_argument, 0, O_LOD},
        {"lod-px", required_argument, 0, O_LOD_PX},
        {"smooth-normals", required_argument, 0, O_SMOOTH},
        {"aa", required_argument, 0, O_AA},
        {"edge-fade", required_argument, 0, O_EDGE_FADE},
        {"soft-edges", no_argument, 0, O_SOFT},
        {"hard-edges", no_argument, 0, O_HARD},
        {"tone-match", required_argument, 0, O_TONE},
        {"pose", required_argument, 0, O_POSE},
        {"calib", required_argument, 0, O_CALIB},
        {"predict", required_argument, 0, O_PREDICT},
        {"no-filter", no_argument, 0, O_NO_FILTER},
        {"hide", required_argument, 0, O_HIDE},
        {"prop", required_argument, 0, O_PROP},
        {"allow-outside", no_argument, 0, O_ALLOW_OUTSIDE},
        {"hmd-calibration", required_argument, 0, O_HMD_CALIB},
        {"hmd-calibration-left", required_argument, 0, O_HMD_CALIB_L},
        {"hmd-calibration-right", required_argument, 0, O_HMD_CALIB_R},
        {"view", required_argument, 0, O_VIEW},
        {"hmd-ipd", required_argument, 0, O_HMD_IPD},
        {"hmd-camera-offset", required_argument, 0, O_HMD_OFFSET},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    render_opts o = {0};
    o.lod = CLI_LOD_DEFAULT;
    o.lod_px = CLI_LOD_PX_DEFAULT;
    o.soft_edge = -1; /* the default: cli_soft_edges */
    char why[200];
    int tracking_only = 0;   /* an option that needs --pose tracking */
    int c, rc;
    cli_getopt_begin();
    while ((c = cli_getopt("render", render_usage, argc, argv, opts, &rc)) > 0) {
        switch (c) {
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
        case O_THREADS:
            if (!cli_parse_int(optarg, 1, 2, &o.threads))
                return cli_usage_error("render", "--threads '%s': 1 or 2", optarg);
            break;
        case O_NO_DEPTH: o.no_depth = 1; break;
        case O_CULL: o.cull_back = 1; break;
        case O_SOFT: o.soft_edge = 1; break;
        case O_HARD: o.soft_edge = 0; break;
        case O_LOD:
            if (!cli_lod_parse(optarg, &o.lod))
                return cli_usage_error("render", "--lod '%s': off, auto or a level 0..%d",
                                       optarg, PIPE_LOD_MAX - 1);
            break;
        case O_LOD_PX:
            if (!cli_lod_parse_px(optarg, &o.lod_px))
                return cli_usage_error("render", "--lod-px '%s': pixels, > 0 and <= 1000",
                                       optarg);
            break;
        case O_REFINE:
            if (!cli_parse_int(optarg, 1, 64, &o.refine))
                return cli_usage_error("render", "--refine '%s': a band of 1..64 px", optarg);
            break;
        case O_SMOOTH:
            if (!cli_parse_int(optarg, -1, FUSE_NORMAL_SMOOTH_MAX, &o.smooth_normals))
                return cli_usage_error("render", "--smooth-normals '%s': a radius of -1..%d px",
                                       optarg, FUSE_NORMAL_SMOOTH_MAX);
            break;
        case O_EDGE_FADE:
            if (!cli_parse_int(optarg, 0, FUSE_EDGE_FADE_MAX, &o.edge_fade))
                return cli_usage_error("render", "--edge-fade '%s': 0 (off) or a width of "
                                       "1..%d px", optarg, FUSE_EDGE_FADE_MAX);
            if (o.edge_fade == 0) o.edge_fade = -1;
            break;
        case O_AA:
            if (!parse_aa(optarg, &o.aa))
                return cli_usage_error("render", "--aa '%s': 0 (off), 4, 8 or 16 samples per "
                                       "pixel", optarg);
            break;
        case O_TONE:
            if (!cli_parse_float(optarg, &o.tone_match) || o.tone_match < 0.0f || o.tone_match > 1.0f)
                return cli_usage_error("render", "--tone-match '%s': a strength in [0, 1]", optarg);
            break;
        case O_POSE:
            o.pose_tracking =
                cli_pick(optarg, (const char *const[]){"animation", "tracking", NULL});
            if (o.pose_tracking < 0)
                return cli_usage_error("render", "--pose '%s': 'animation' or 'tracking'", optarg);
            break;
        case O_CALIB: o.calib = optarg; tracking_only = O_CALIB; break;
        case O_PREDICT:
            if (!cli_parse_float(optarg, &o.predict_ms) || !(o.predict_ms >= 0.0f) ||
                o.predict_ms > 100.0f)
                return cli_usage_error("render", "--predict '%s': milliseconds in [0, 100]", optarg);
            tracking_only = O_PREDICT;
            break;
        case O_NO_FILTER: o.no_filter = 1; tracking_only = O_NO_FILTER; break;
        case O_ALLOW_OUTSIDE: io_gltf_allow_outside(1); break;
        case O_HIDE:
            if (pipe_parts_parse(optarg, &o.hide, why, sizeof why) != 0)
                return cli_usage_error("render", "--hide '%s': %s", optarg, why);
            break;
        case O_PROP:
            if (o.nprops >= RENDER_MAX_PROPS)
                return cli_usage_error("render", "--prop: at most %d props", RENDER_MAX_PROPS);
            if (!parse_prop(optarg, &o))
                return cli_usage_error("render", "--prop '%s': MODEL@X,Y,Z or MODEL@X,Y,Z,YAW "
                                       "(metres, degrees)", optarg);
            break;
        case O_HMD_CALIB: o.hmd_calib[0] = optarg; break;
        case O_HMD_CALIB_L: o.hmd_calib[1] = optarg; break;
        case O_HMD_CALIB_R: o.hmd_calib[2] = optarg; break;
        case O_VIEW: {
            int vr = cli_view_parse("render", optarg, &o.view);
            if (vr != EXIT_OK) return vr;
            break;
        }
        case O_HMD_IPD: {
            int vr = cli_hmd_len_parse("render", "hmd-ipd", optarg, PIPE_IPD_MIN_M,
                                       PIPE_IPD_MAX_M, &o.ipd_m);
            if (vr != EXIT_OK) return vr;
            break;
        }
        case O_HMD_OFFSET: {
            int vr = cli_hmd_len_parse("render", "hmd-camera-offset", optarg, 0.0f,
                                       PIPE_CAM_OFFSET_MAX_M, &o.cam_offset_m);
            if (vr != EXIT_OK) return vr;
            break;
        }
        }
    }
    if (c < 0) return rc;
    if (optind < argc) return cli_usage_error("render", "unexpected argument '%s'", argv[optind]);
    if (!o.scene) return cli_usage_error("render", "--scene is required");
    if (!o.out) return cli_usage_error("render", "--out is required");
    {
        int sr = cli_soft_edges("render", &o.soft_edge, o.aa);
        if (sr != EXIT_OK) return sr;
    }
    if (tracking_only && !o.pose_tracking)
        return cli_usage_error("render", "%s needs --pose tracking",
                               tracking_only == O_CALIB ? "--calib"
                               : tracking_only == O_PREDICT ? "--predict" : "--no-filter");
    if (o.hmd_calib[0] || o.hmd_calib[1] || o.hmd_calib[2]) {
        int lr = cli_lens_load(o.hmd_calib[0], o.hmd_calib[1], o.hmd_calib[2], &o.hmd);
        if (lr != EXIT_OK) return lr;
    }
    {
        kin_sthmd_desc h = o.hmd;
        h.ipd_m = o.ipd_m;
        h.cam_offset_m = o.cam_offset_m;
        int vr = cli_view_check("render", o.view, o.aa, &h);
        if (vr != EXIT_OK) return vr;
    }
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
    o.lod = CLI_LOD_DEFAULT;
    o.lod_px = CLI_LOD_PX_DEFAULT;
    o.out = "out/demo";
    o.cull_back = 1; /* the sample arms are closed: same masks, half the setups */
    o.soft_edge = 1; /* no stair-steps (issue 14 item 3; docs/antialias.md) */
    int c, rc;
    cli_getopt_begin();
    while ((c = cli_getopt("demo", demo_usage, argc, argv, opts, &rc)) > 0) {
        switch (c) {
        case O_SAMPLES: samples = optarg; break;
        case O_OUT: o.out = optarg; break;
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 1 << 24, &o.frames))
                return cli_usage_error("demo", "--frames '%s': not a positive count", optarg);
            break;
        }
    }
    if (c < 0) return rc;
    if (optind < argc) return cli_usage_error("demo", "unexpected argument '%s'", argv[optind]);
    char scene[IO_PATH_MAX + 32];
    snprintf(scene, sizeof scene, "%s/scene.txt", samples);
    if (!file_exists(scene))
        return io_term_fail("%s is missing: run 'make demo' (it generates the samples), or "
                        "'build/gen_samples --out %s'", scene, samples);
    o.scene = scene;
    return render(&o);
}
