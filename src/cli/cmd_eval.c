/* cmd_eval.c - `egofuse eval`: parses its options and runs the accuracy
 * evaluation of src/eval/ (eval.h; the report in docs/accuracy.md). */
#include "cli.h"

#include <getopt.h>
#include <stdlib.h>
#include <string.h>

#include "../eval/eval.h"
#include "../fit/fit_narrow.h"
#include "cli_lod.h"

static const char *eval_usage =
    "usage: egofuse eval [--sequence NAME] [--frames N] [--noise MM] [--latency MS]\n"
    "                    [--dropout P] [--calib-error E] [--speed S] [--seed S]\n"
    "                    [--methods LIST] [--band PX] [--global W] [--per-frame]\n"
    "                    [--csv FILE] [--report DIR] [--sweep-frames N]\n"
    "                    [--seq-frames N] [--dump DIR] [--quiet] [--stereo]\n"
    "                    [--lod MODE] [--lod-px PX] [--lod-sweep] [--light-sweep[=DIR]]\n"
    "                    [--kf-sweep]\n"
    "       egofuse eval --eyeview [--frames N] [--seed S] [--csv FILE] [--report DIR]\n"
    "\n"
    "Generates ground truth (a true operator whose bones and limbs differ from\n"
    "the mask model, filmed over a cockpit with skin-coloured objects, camera\n"
    "noise and its own lighting; exact silhouettes; the ideal composite) and\n"
    "measures the masks and composites of each method against it: mask IoU,\n"
    "boundary F within 1 and 3 px, false-positive and false-negative area,\n"
    "PSNR of the composite, temporal edge flicker, and the time per stereo\n"
    "frame. Methods: kin (the paper: fixed-size model, IK from the tracked\n"
    "hands, latest sample), kin-cal-pred (user calibration estimated from a\n"
    "calibration motion, One Euro filter and prediction to the camera frame's\n"
    "time), skin (YCbCr skin-colour key), refine (kin-cal-pred with the elbows\n"
    "fitted to the images and the limbs thinned to them, refined by colour in a\n"
    "band around its edge).\n"
    "\n"
    "  --sequence NAME  reach_grasp (default), cross (hands crossing), near\n"
    "                   (hands 15 cm from the eyes), edge (hands at the image\n"
    "                   borders), fast (0.25 s reaches)\n"
    "  --frames N       display frames at 60 Hz (default 60; sequences are 3 s)\n"
    "  --noise MM       RMS tracking position error (default 5)\n"
    "  --latency MS     tracking latency (default 20)\n"
    "  --dropout P      probability that a sample loses a hand (default 0.02)\n"
    "  --calib-error E  relative error added to the estimated user calibration\n"
    "                   (default 0)\n"
    "  --speed S        playback speed of the motion (default 1)\n"
    "  --seed S         seed of the camera and tracking noise (default 1)\n"
    "  --methods LIST   comma-separated subset of kin,kin-cal-pred,skin,refine\n"
    "                   (default: all four) and refine's variants:\n"
    "                   refine-nomc (the prior not moved with the hand),\n"
    "                   refine-noshift (the fast hands not moved to the\n"
    "                   colour before the band), refine-shiftall (every\n"
    "                   hand moved), refine-nosmooth (the refined mask's\n"
    "                   edge not smoothed; refine-smoothlate, -smoothout,\n"
    "                   -smoothin, -smoothoutin, -closeout, -openout: the\n"
    "                   smoothing's other placements, docs/accuracy.md)\n"
    "  --band PX        refinement band half width, 1..64 (default 16)\n"
    "  --global W       refine: weight of the image-wide colour model against\n"
    "                   the band's local one, 0..1 (default 1: the global\n"
    "                   model alone)\n"
    "  --stereo         refine: also the stereo pair's depth test (refined pixels\n"
    "                   that the other camera finds behind the hand are\n"
    "                   cleared; off by default: measured, it did not pay)\n"
    "  --per-frame      print every frame's figures per method\n"
    "  --csv FILE       write the summary table as CSV\n"
    "  --report DIR     also run the speed knobs (band width, elbow fit, global\n"
    "                   colour model, filter lag compensation, mask resolution,\n"
    "                   coverage samples per pixel (aa 4/8/16), triangles,\n"
    "                   LBS/DQS) and the tracking sweeps (noise, latency,\n"
    "                   calibration error) on --sweep-frames frames, and\n"
    "                   the methods on every other sequence on --seq-frames\n"
    "                   frames; write DIR/summary.csv, DIR/table.md, data files\n"
    "                   and the charts (gnuplot, PNG)\n"
    "  --sweep-frames N frames of the knobs and tracking sweeps (default 60)\n"
    "  --seq-frames N   frames of each other sequence in a report (default 90)\n"
    "  --dump DIR       write every mask: DIR/METHOD_SETTING_EYE_NNNN.png (red:\n"
    "                   true silhouette, green: the method's mask)\n"
    "  --quiet          no progress line\n"
    "  --lod MODE       the mask model's level of detail for every method:\n"
    "                   off (default), a level 1..7, or auto (per frame and eye,\n"
    "                   the coarsest level whose error is <= --lod-px px)\n"
    "  --lod-px PX      the error auto allows, pixels (default 2)\n"
    "  --lod-sweep      also run kin-cal-pred and refine at levels 0..4 and auto\n"
    "                   at 1, 2, 4, 8 px on --frames frames (group lod: level\n"
    "                   and triangles drawn, raster ms per eye, the kinematic\n"
    "                   mask's IoU and BF1 against the full model's; a report\n"
    "                   runs it on --sweep-frames and writes DIR/lod.csv)\n"
    "  --eyeview        instead: the eye's viewpoint (the cameras sit 85 mm in\n"
    "                   front of the eyes): the right hand held 15, 20, 30, 40 cm\n"
    "                   from the eyes, tracking noise 0, 5, 10, 20 mm; per view\n"
    "                   method (crop: the paper's crop and scale; reproj: the\n"
    "                   reprojection to the eye) the hand's position error (px)\n"
    "                   and size error (%) in the display, IoU and PSNR against\n"
    "                   ground truth rendered from the true eye, ms per stereo\n"
    "                   frame; --frames per distance (at most 180); the report:\n"
    "                   DIR/eyeview.csv, eyeview.md, eyeview_*.png\n"
    "  --light-sweep[=DIR]  also run the lighting mismatch between the cockpit and\n"
    "                   the virtual scene (the cockpit's light x0.5..x2, tinted\n"
    "                   3000..10000 K, turned 30..90 degrees to the side) for\n"
    "                   kin-cal-pred, skin, refine and refine with tone matching\n"
    "                   on --frames frames (group light; a report runs it on\n"
    "                   --sweep-frames and writes DIR/light.md, light_*.dat,\n"
    "                   light.png; without a report: into =DIR when given)\n"
    "  --kf-sweep       also run kin-cal-pred and refine with the Fresnel fade kf\n"
    "                   0, 0.25, 0.5, 0.75, 1 against the opaque ideal composite\n"
    "                   (a real hand has no fade) on --frames frames (group kf;\n"
    "                   a report runs it on --sweep-frames, DIR/kf.md)\n"
    "  -h, --help       this text\n";

enum { O_FRAMES = 256, O_NOISE, O_LATENCY, O_DROPOUT, O_CALIB, O_SPEED, O_SEED, O_PERFRAME,
       O_CSV, O_REPORT, O_QUIET, O_DUMP, O_METHODS, O_BAND, O_SEQUENCE, O_SWEEP_FRAMES,
       O_SEQ_FRAMES, O_GLOBAL, O_LOD, O_LOD_PX, O_LOD_SWEEP, O_EYEVIEW,
       O_LIGHT_SWEEP, O_KF_SWEEP, O_STEREO };

int cmd_eval(int argc, char **argv)
{
    static const struct option opts[] = {
        {"frames", required_argument, 0, O_FRAMES},
        {"noise", required_argument, 0, O_NOISE},
        {"latency", required_argument, 0, O_LATENCY},
        {"dropout", required_argument, 0, O_DROPOUT},
        {"calib-error", required_argument, 0, O_CALIB},
        {"speed", required_argument, 0, O_SPEED},
        {"seed", required_argument, 0, O_SEED},
        {"per-frame", no_argument, 0, O_PERFRAME},
        {"csv", required_argument, 0, O_CSV},
        {"report", required_argument, 0, O_REPORT},
        {"quiet", no_argument, 0, O_QUIET},
        {"dump", required_argument, 0, O_DUMP},
        {"methods", required_argument, 0, O_METHODS},
        {"band", required_argument, 0, O_BAND},
        {"sequence", required_argument, 0, O_SEQUENCE},
        {"sweep-frames", required_argument, 0, O_SWEEP_FRAMES},
        {"seq-frames", required_argument, 0, O_SEQ_FRAMES},
        {"global", required_argument, 0, O_GLOBAL},
        {"lod", required_argument, 0, O_LOD},
        {"lod-px", required_argument, 0, O_LOD_PX},
        {"lod-sweep", no_argument, 0, O_LOD_SWEEP},
        {"eyeview", no_argument, 0, O_EYEVIEW},
        {"light-sweep", optional_argument, 0, O_LIGHT_SWEEP},
        {"kf-sweep", no_argument, 0, O_KF_SWEEP},
        {"stereo", no_argument, 0, O_STEREO},
        {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    eval_opts o = { 60, 0, 0, 5.0f, 20.0f, 0.02f, 0.0f, 1.0f, 1, NULL, NULL, NULL, 15u,
                    GEN_ANIM_NAME, 60, 90, PIPE_GLOBAL_WEIGHT, 16, CLI_LOD_DEFAULT, CLI_LOD_PX_DEFAULT, 0, 0, 0, NULL, 0, 0 };
    const cli_float_opt fl[] = {
        {O_NOISE, "--noise", 0.0f, 200.0f, "not in 0..200 mm", &o.noise},
        {O_LATENCY, "--latency", 0.0f, 1000.0f, "not in 0..1000 ms", &o.latency},
        {O_DROPOUT, "--dropout", 0.0f, 1.0f, "not in 0..1", &o.dropout},
        {O_CALIB, "--calib-error", -0.3f, 0.3f, "not in -0.3..0.3", &o.calib_error},
        {O_SPEED, "--speed", 0.1f, 10.0f, "not in 0.1..10", &o.speed},
        {O_GLOBAL, "--global", 0.0f, 1.0f, "not in 0..1", &o.global},
    };
    enum { NFL = (int)(sizeof fl / sizeof fl[0]) };
    int ch, rc;
    cli_getopt_begin();
    while ((ch = cli_getopt("eval", eval_usage, argc, argv, opts, &rc)) > 0) {
        switch (ch) {
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 100000, &o.frames))
                return cli_usage_error("eval", "--frames '%s': not a positive count", optarg);
            break;
        case O_SEED:
            if (!cli_parse_int(optarg, 0, 1 << 30, &o.seed))
                return cli_usage_error("eval", "--seed '%s': not a number", optarg);
            break;
        case O_PERFRAME: o.per_frame = 1; break;
        case O_CSV: o.csv = optarg; break;
        case O_REPORT: o.report = optarg; break;
        case O_QUIET: o.quiet = 1; break;
        case O_DUMP: o.dump = optarg; break;
        case O_METHODS:
            o.methods = eval_parse_methods(optarg);
            if (!o.methods)
                return cli_usage_error("eval", "--methods '%s': not a list of kin, "
                                       "kin-cal-pred, skin, refine, refine-nomc, "
                                       "refine-noshift, refine-shiftall, refine-nosmooth, "
                                       "refine-smoothlate, refine-smoothout, refine-smoothin, "
                                       "refine-smoothoutin, refine-closeout, refine-openout", optarg);
            break;
        case O_SEQUENCE: {
            int known = 0;
            for (int i = 0; gt_sequence_name(i); i++)
                known |= !strcmp(optarg, gt_sequence_name(i)) && strcmp(optarg, "calib");
            if (!known)
                return cli_usage_error("eval", "--sequence '%s': not one of reach_grasp, cross, "
                                       "near, edge, fast", optarg);
            o.sequence = optarg;
            break;
        }
        case O_SWEEP_FRAMES:
            if (!cli_parse_int(optarg, 1, 100000, &o.sweep_frames))
                return cli_usage_error("eval", "--sweep-frames '%s': not a positive count", optarg);
            break;
        case O_LOD:
            if (!cli_lod_parse(optarg, &o.lod))
                return cli_usage_error("eval", "--lod '%s': off, auto or a level 0..%d", optarg,
                                       PIPE_LOD_MAX - 1);
            break;
        case O_LOD_PX:
            if (!cli_lod_parse_px(optarg, &o.lod_px))
                return cli_usage_error("eval", "--lod-px '%s': pixels, > 0 and <= 1000", optarg);
            break;
        case O_LOD_SWEEP: o.lod_sweep = 1; break;
        case O_EYEVIEW: o.eyeview = 1; break;
        case O_LIGHT_SWEEP:
            o.light_sweep = 1;
            o.light_dir = optarg;
            break;
        case O_KF_SWEEP: o.kf_sweep = 1; break;
        case O_STEREO: o.stereo = 1; break;
        case O_SEQ_FRAMES:
            if (!cli_parse_int(optarg, 1, 100000, &o.seq_frames))
                return cli_usage_error("eval", "--seq-frames '%s': not a positive count", optarg);
            break;
        case O_BAND:
            if (!cli_parse_int(optarg, 1, 64, &o.band))
                return cli_usage_error("eval", "--band '%s': not in 1..64 px", optarg);
            break;
        default: {
            const cli_float_opt *e = cli_float_opt_find(fl, NFL, ch);
            if (!e) return cli_option_error("eval", ch, argv);
            if (!cli_float_opt_parse(e, optarg))
                return cli_usage_error("eval", "%s '%s': %s", e->name, optarg, e->range);
            break;
        }
        }
    }
    if (ch < 0) return rc;
    if (optind < argc) return cli_usage_error("eval", "unexpected argument '%s'", argv[optind]);
    if (o.eyeview && o.frames > 180)
        return cli_usage_error("eval", "--eyeview --frames %d: at most 180 (the 3 s of a "
                               "sequence)", o.frames);
    return o.eyeview ? eval_eye_run(&o) : eval_run(&o);
}

