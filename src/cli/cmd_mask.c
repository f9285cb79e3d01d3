/* cmd_mask.c - `egofuse mask`: the coverage mask of any glTF model. */
#include "cli.h"
#include "../io/io_calib.h"
#include "../pipe/pipe_mask.h"

#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *usage =
    "usage: egofuse mask MODEL.gltf|MODEL.glb --width W --height H --fov-y DEG\n"
    "                    --eye X,Y,Z --target X,Y,Z [--up X,Y,Z]\n"
    "                    [--anim I --time T] [--scene S] [--near N --far F]\n"
    "                    --out mask.png [--normals n.png] [--depth d.exr]\n"
    "                    [--allow-outside] [--calibration FILE]\n"
    "\n"
    "Renders the coverage mask of a skinned or unskinned glTF 2.0 model, at\n"
    "its rest pose or at time T (seconds) of animation I, exactly and\n"
    "deterministically: a reference for GPU pipelines' unit tests.\n"
    "\n"
    "Drawn as a GPU draws it: the default scene (`scene`, else scene 0; all\n"
    "nodes when the file has no scenes), triangle primitives of mode\n"
    "TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN (POINTS and LINES are not\n"
    "drawn: a note says so), morph targets (POSITION and NORMAL; weights of\n"
    "the animation, else the node, else the mesh) before skinning, every\n"
    "JOINTS_n/WEIGHTS_n set with the weights as stored, KHR_mesh_quantization,\n"
    "EXT_mesh_gpu_instancing and EXT_meshopt_compression (.glb; gltfpack -c).\n"
    "A file whose extensionsRequired names anything else that changes the\n"
    "geometry (KHR_draco_mesh_compression, ...) is refused with the\n"
    "extension's name; material, texture and light extensions are ignored\n"
    "(docs/io.md lists what is supported and refused).\n"
    "\n"
    "Camera: right-handed look-at from --eye to --target with --up (default\n"
    "0,1,0); OpenGL-style symmetric perspective with vertical FOV --fov-y,\n"
    "aspect W/H, --near 0.01 and --far 100 by default. Row 0 of the image is\n"
    "the top of the view; pixel centres are at (x+0.5, y+0.5).\n"
    "\n"
    "Output: --out, 8-bit grey: 255 where a triangle covers the pixel centre\n"
    "(top-left fill rule, both faces drawn), 0 elsewhere. --normals: RGB\n"
    "view-space unit normal of the nearest surface, encoded n*0.5+0.5 (0 where\n"
    "nothing is drawn). --depth: one float channel of window depth\n"
    "z_ndc*0.5+0.5 in [0,1] (1 where nothing is drawn), e.g. EXR.\n"
    "Files are written whole or not at all.\n"
    "\n"
    "  --width W, --height H   image size in pixels (1..8192)\n"
    "  --fov-y DEG             vertical field of view, (0, 180)\n"
    "  --anim I                animation index (default: rest pose)\n"
    "  --time T                time in seconds (clamped to the animation)\n"
    "  --scene S               draw scene S instead of the default scene\n"
    "  --calibration FILE      an OpenCV calibration file (YAML/XML, docs/lens.md):\n"
    "                          the camera's intrinsics and lens distortion instead\n"
    "                          of --fov-y; the size defaults to the file's (a\n"
    "                          --width/--height of another size scales it)\n"
    "  --allow-outside         let buffer and image URIs name files outside\n"
    "                          the model's folder (absolute, `..`, symlinks\n"
    "                          out); refused by default (docs/io.md)\n"
    "  -h, --help              this text\n";

enum { O_WIDTH = 256, O_HEIGHT, O_FOVY, O_EYE, O_TARGET, O_UP, O_ANIM, O_TIME,
       O_NEAR, O_FAR, O_OUT, O_NORMALS, O_DEPTH, O_SCENE, O_ALLOW_OUTSIDE, O_CALIBRATION };

static const struct option opts[] = {
    {"width", required_argument, 0, O_WIDTH},
    {"height", required_argument, 0, O_HEIGHT},
    {"fov-y", required_argument, 0, O_FOVY},
    {"eye", required_argument, 0, O_EYE},
    {"target", required_argument, 0, O_TARGET},
    {"up", required_argument, 0, O_UP},
    {"anim", required_argument, 0, O_ANIM},
    {"time", required_argument, 0, O_TIME},
    {"near", required_argument, 0, O_NEAR},
    {"far", required_argument, 0, O_FAR},
    {"out", required_argument, 0, O_OUT},
    {"normals", required_argument, 0, O_NORMALS},
    {"depth", required_argument, 0, O_DEPTH},
    {"scene", required_argument, 0, O_SCENE},
    {"allow-outside", no_argument, 0, O_ALLOW_OUTSIDE},
    {"calibration", required_argument, 0, O_CALIBRATION},
    {"help", no_argument, 0, 'h'},
    {0, 0, 0, 0},
};

int cmd_mask(int argc, char **argv)
{
    int width = 0, height = 0, anim = -1, have_time = 0, scene = -1;
    float fovy = 0.0f, tsec = 0.0f, znear = 0.01f, zfar = 100.0f;
    float eye[3], target[3], up[3] = {0.0f, 1.0f, 0.0f};
    int have_eye = 0, have_target = 0;
    const char *out = NULL, *out_n = NULL, *out_d = NULL, *calib = NULL;

    int c, rc;
    cli_getopt_begin();
    while ((c = cli_getopt("mask", usage, argc, argv, opts, &rc)) > 0) {
        const char *a = optarg;
        switch (c) {
        case O_WIDTH:
            if (!cli_parse_int(a, 1, RAST_MAX_DIM, &width))
                return cli_usage_error("mask", "--width '%s': not an integer in 1..%d", a, RAST_MAX_DIM);
            break;
        case O_HEIGHT:
            if (!cli_parse_int(a, 1, RAST_MAX_DIM, &height))
                return cli_usage_error("mask", "--height '%s': not an integer in 1..%d", a, RAST_MAX_DIM);
            break;
        case O_FOVY:
            if (!cli_parse_float(a, &fovy) || !(fovy > 0.0f && fovy < 180.0f))
                return cli_usage_error("mask", "--fov-y '%s': not a number of degrees in (0, 180)", a);
            break;
        case O_EYE:
            if (!cli_parse_vec3(a, eye)) return cli_usage_error("mask", "--eye '%s': expected X,Y,Z", a);
            have_eye = 1;
            break;
        case O_TARGET:
            if (!cli_parse_vec3(a, target)) return cli_usage_error("mask", "--target '%s': expected X,Y,Z", a);
            have_target = 1;
            break;
        case O_UP:
            if (!cli_parse_vec3(a, up)) return cli_usage_error("mask", "--up '%s': expected X,Y,Z", a);
            break;
        case O_ANIM:
            if (!cli_parse_int(a, 0, 1 << 20, &anim))
                return cli_usage_error("mask", "--anim '%s': not an animation index", a);
            break;
        case O_TIME:
            if (!cli_parse_float(a, &tsec)) return cli_usage_error("mask", "--time '%s': not a number", a);
            have_time = 1;
            break;
        case O_NEAR:
            if (!cli_parse_float(a, &znear) || !(znear > 0.0f))
                return cli_usage_error("mask", "--near '%s': not a positive number", a);
            break;
        case O_FAR:
            if (!cli_parse_float(a, &zfar)) return cli_usage_error("mask", "--far '%s': not a number", a);
            break;
        case O_ALLOW_OUTSIDE: io_gltf_allow_outside(1); break;
        case O_SCENE:
            if (!cli_parse_int(a, 0, 1 << 20, &scene))
                return cli_usage_error("mask", "--scene '%s': not a scene index", a);
            break;
        case O_CALIBRATION: calib = a; break;
        case O_OUT: out = a; break;
        case O_NORMALS: out_n = a; break;
        case O_DEPTH: out_d = a; break;
        }
    }
    if (c < 0) return rc;
    if (optind >= argc) return cli_usage_error("mask", "no model file given");
    if (optind + 1 < argc) return cli_usage_error("mask", "unexpected argument '%s'", argv[optind + 1]);
    const char *model_path = argv[optind];
    if (calib && fovy != 0.0f)
        return cli_usage_error("mask", "--calibration and --fov-y exclude each other (the file "
                               "gives the camera's intrinsics)");
    if (!width != !height) return cli_usage_error("mask", "give both --width and --height");
    if (!calib && !width) return cli_usage_error("mask", "--width and --height are required");
    if (!calib && fovy == 0.0f) return cli_usage_error("mask", "--fov-y is required");
    if (!have_eye || !have_target) return cli_usage_error("mask", "--eye and --target are required");
    if (!out) return cli_usage_error("mask", "--out is required");
    if (!(zfar > znear)) return cli_usage_error("mask", "--far (%g) must be greater than --near (%g)", zfar, znear);
    if (have_time && anim < 0) anim = 0;

    kin_vec3 ve = kin_v3(eye[0], eye[1], eye[2]);
    kin_vec3 vt = kin_v3(target[0], target[1], target[2]);
    kin_vec3 vu = kin_v3(up[0], up[1], up[2]);
    kin_vec3 fwd = kin_v3_sub(vt, ve);
    if (kin_v3_len(fwd) == 0.0f)
        return cli_usage_error("mask", "--eye and --target are the same point");
    /* Coordinates whose squares overflow a float (|v| > ~1.8e19) are not
     * the --up vector's fault: say which vector is out of range. */
    if (!isfinite(kin_v3_len(fwd)))
        return cli_usage_error("mask", "--eye and --target are too far apart (the view direction "
                               "%g,%g,%g overflows float arithmetic; keep coordinates below 1e18)",
                               (double)fwd.x, (double)fwd.y, (double)fwd.z);
    if (!isfinite(kin_v3_len(vu)))
        return cli_usage_error("mask", "--up is too large (overflows float arithmetic; its length "
                               "does not matter, e.g. 0,1,0)");
    if (kin_v3_len(kin_v3_cross(fwd, vu)) <= 1e-6f * kin_v3_len(fwd) * kin_v3_len(vu))
        return cli_usage_error("mask", "--up is zero or parallel to the view direction");

    io_error err;
    kin_lens lens;
    if (calib) {
        if (io_calib_load(calib, 0, &lens, &err) != IO_OK) return io_term_fail("%s", err.msg);
        if (!width && !lens.width)
            return io_term_fail("%s: no image size in the file (image_width, image_height): give "
                            "--width and --height", calib);
        if (!width) width = lens.width, height = lens.height;
        if (lens.width > RAST_MAX_DIM || lens.height > RAST_MAX_DIM)
            return io_term_fail("%s: image size %dx%d above %d", calib, lens.width, lens.height,
                            RAST_MAX_DIM);
    }
    kin_model model;
    io_gltf_info info;
    if (io_gltf_load_ex(model_path, scene, &model, &info, &err) != IO_OK) return io_term_fail("%s", err.msg);
    if (info.skipped_points || info.skipped_lines)
        fprintf(stderr, "egofuse: note: %s: %d POINTS and %d LINES/LINE_LOOP/LINE_STRIP "
                "primitive%s not drawn (a mask holds triangles only)\n", model_path,
                info.skipped_points, info.skipped_lines,
                info.skipped_points + info.skipped_lines == 1 ? "" : "s");
    const kin_animation *an = NULL;
    if (anim >= 0) {
        if (anim >= model.anim_count) {
            int n = model.anim_count;
            kin_model_free(&model);
            return io_term_fail("%s: --anim %d: the model has %d animation%s", model_path, anim, n, n == 1 ? "" : "s");
        }
        an = &model.anims[anim];
    }

    rc = EXIT_FAIL;
    io_image mask = {0}, nimg = {0}, dimg = {0};
    if (io_image_alloc(&mask, width, height, 1, IO_U8, &err) != IO_OK) { io_term_fail("%s", err.msg); goto done; }
    if (out_n && io_image_alloc(&nimg, width, height, 3, IO_U8, &err) != IO_OK) { io_term_fail("%s", err.msg); goto done; }
    if (out_d && io_image_alloc(&dimg, width, height, 1, IO_F32, &err) != IO_OK) { io_term_fail("%s", err.msg); goto done; }
    /* The rendering itself is the library call pipe_mask_render (pipe_mask.h). */
    pipe_mask_desc md = {0};
    md.width = width;
    md.height = height;
    md.fov_y = fovy;
    memcpy(md.eye, eye, sizeof eye);
    memcpy(md.target, target, sizeof target);
    memcpy(md.up, up, sizeof up);
    md.znear = znear;
    md.zfar = zfar;
    md.anim = an;
    md.time = tsec;
    md.lens = calib ? &lens : NULL;
    char why[256];
    if (pipe_mask_render(&model, &md, mask.data, out_n ? nimg.data : NULL, out_d ? dimg.data : NULL,
                         why, sizeof why) != 0) {
        io_term_fail("%s: cannot draw the model: %s", model_path, why);
        goto done;
    }
    /* Write every output only after everything has been computed. */
    if (io_image_save(out, &mask, &err) != IO_OK) { io_term_fail("%s", err.msg); goto done; }
    if (out_n && io_image_save(out_n, &nimg, &err) != IO_OK) { io_term_fail("%s", err.msg); goto done; }
    if (out_d && io_image_save(out_d, &dimg, &err) != IO_OK) { io_term_fail("%s", err.msg); goto done; }
    rc = EXIT_OK;
done:
    io_image_free(&mask);
    io_image_free(&nimg);
    io_image_free(&dimg);
    kin_model_free(&model);
    return rc;
}
