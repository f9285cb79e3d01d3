/* run_opts.c - the options of `egofuse run`: the command line, after the
 * cockpit configuration file of --config (io_conf_load turns its lines
 * into options), so that one file starts a cockpit and every option still
 * works on the command line. docs/cockpit.md. */
#include "run.h"
#include "cli_lod.h"

#include <getopt.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "../io/io_dev.h"
#include "../io/io_display.h"
#include "../io/io_live.h"
#include "../io/io_natnet.h"
#include "../io/io_vsrc.h"

const char *run_usage =
    "usage: egofuse run [--config FILE] (--scene FILE | --model FILE)\n"
    "                   [--left SEL --right SEL] [--virt-source SPEC]\n"
    "                   [--display SPEC | --out DIR | --raw] [options]\n"
    "\n"
    "The live cockpit: each pair of camera frames (matched by kernel time\n"
    "stamp) is lit inside the mask of the posed arm model and composited over\n"
    "the virtual scene (a still image or a live stream), per eye 1280x800 by\n"
    "default, and shown on the HMD's displays, a window, files or stdout.\n"
    "\n"
    "  --config FILE    cockpit configuration (docs/cockpit.md): its keys are\n"
    "                   these options; the command line wins over it\n"
    "model and pose:\n"
    "  --scene FILE     model, animation, head node, lighting and virtual\n"
    "                   images (frame 0) from a scene file (docs/scene.md)\n"
    "  --model FILE     glTF model (head node 'head' if it has one)\n"
    "  --track-port P   pose from egofuse's UDP tracking stream on port P\n"
    "  --track-addr A   address to receive it on (default 127.0.0.1; 0.0.0.0\n"
    "                   = every interface, for a tracking PC on the network)\n"
    "  --natnet SERVER  pose from an OptiTrack NatNet server (docs/tracking.md)\n"
    "  --natnet-local A, --natnet-multicast GROUP, --natnet-up y|z,\n"
    "  --natnet-units m|mm, --natnet-version MAJOR.MINOR, --natnet-command-port P,\n"
    "  --natnet-data-port P, --natnet-body POINT=NAME|#ID, --natnet-offset\n"
    "  POINT=X,Y,Z[,QX,QY,QZ,QW] (POINT: head, shoulder-left, shoulder-right,\n"
    "  hand-left, hand-right; default bodies Head, ShoulderL, ShoulderR, HandL, HandR)\n"
    "                   (without --track-port / --natnet: the model's animation)\n"
    "  --predict-ms MS  pose the mask at the camera's time stamp + MS (default 0)\n"
    "  --glove-left SEL, --glove-right SEL   5DT gloves (SEL as below, or any)\n"
    "  --calib FILE     user calibration (egofuse-calib 1, egofuse calibrate)\n"
    "  --allow-outside  let the models read files outside their folder\n"
    "  --hide PARTS     parts not shown: left-hand,left-arm,right-hand,right-arm\n"
    "  --prop [NAME=]MODEL[@X,Y,Z[,YAW,PITCH,ROLL]][#BODY]\n"
    "                   a real object cut in like the hands (joystick, armrest):\n"
    "                   fixed in the world (metres, degrees), or posed by the\n"
    "                   NatNet rigid body BODY (name or #id); repeatable\n"
    "cameras:\n"
    "  --left SEL       left camera: /dev/videoN, serial:SN, port:1-2.3 or\n"
    "  --right SEL      id:VVVV:PPPP ('egofuse devices' shows them), or\n"
    "                   file:PATTERN / file:VIDEO for a dry run from recorded\n"
    "                   frames; default: the first two capture nodes\n"
    "  --format F       YUYV (default), GREY, BA81, RGGB, GBRG, GRBG\n"
    "  --fps N          frame rate asked (default 60)\n"
    "  --input N        V4L2 input to select\n"
    "  --dv             the input takes DV timings (HDMI) at --fps\n"
    "  --loop           recorded frames: start again at the end\n"
    "  --buffers N      mmap buffers per camera (default 4)\n"
    "the HMD (default: the paper's):\n"
    "  --hmd-preset NAME  a named HMD (docs/kin.md): paper, consumer (1280x1024\n"
    "                   cameras, 2064x2208 per eye), highend (1920x1080,\n"
    "                   2880x2720); the other --hmd-* options override its fields\n"
    "  --hmd-camera WxH, --hmd-camera-hfov DEG, --hmd-baseline M (camera\n"
    "  separation), --hmd-camera-offset M (D), --hmd-display WxH (per eye),\n"
    "  --hmd-hfov DEG, --hmd-vfov DEG, --hmd-focal M, --hmd-ipd M\n"
    "  --view V         crop (default: the paper's crop and scale, eq. 1-4) or\n"
    "                   reproject: the hands as the eye sees them, reprojected\n"
    "                   from the cameras by the model's depth (docs/eyeview.md;\n"
    "                   IPD 0.04..0.09 m, D 0..0.25 m, not with --aa)\n"
    "  --hmd-calibration FILE   the cameras' lenses from an OpenCV calibration\n"
    "                   file (YAML/XML; a stereo file: M1/D1 left, M2/D2 right);\n"
    "  --hmd-calibration-left FILE, --hmd-calibration-right FILE  one each\n"
    "                   (docs/lens.md; the masks are drawn through the lens)\n"
    "virtual scene:\n"
    "  --virt L,R       still virtual images (default: the scene's, or grey)\n"
    "  --virt-source SPEC  live: v4l2:/dev/videoN[,/dev/videoM], stream:PATH|-\n"
    "                   (egofuse framing or YUV4MPEG2), raw:WxH:FMT:PATH\n"
    "                   (docs/vstream.md)\n"
    "  --virt-layout L  sbs (default), tb, mono: how one frame holds both eyes\n"
    "  --virt-fps N     frame rate asked of a V4L2 source (default: keep)\n"
    "  --virt-stale MS  a V older than this is reported stale (default 200)\n"
    "output:\n"
    "  --display SPEC   kms[:/dev/dri/cardN][,connector=NAME[+NAME2]][,mode=WxH]\n"
    "                   or sdl[:WxH] (a window); docs/devices.md\n"
    "  --out DIR        write DIR/left_NNNN.png and DIR/right_NNNN.png\n"
    "  --raw            write rgb24 frames, left above right, on stdout:\n"
    "                   | ffplay -f rawvideo -pixel_format rgb24\n"
    "                   -video_size 1280x1600 -\n"
    "  --stats FILE     CSV of every frame's times, V age and skew\n"
    "  --frames N       stop after N stereo frames (default: until Ctrl-C)\n"
    "  --hold           with --display: keep the last frame shown until Ctrl-C\n"
    "  --dump DIR       with --frames: the last frame's inputs as a scene that\n"
    "                   egofuse render composites to the same bytes\n"
    "  --refine BAND    refine the masks by colour in a band of BAND px (1..64)\n"
    "  --lod MODE       levels of detail of the mask model: off (default), a\n"
    "                   level 1..7, or auto (per frame and eye, the coarsest\n"
    "                   level whose error is <= --lod-px px; docs/bench.md)\n"
    "  --lod-px PX      the error auto allows, pixels (default 2)\n"
    "  --aa N           anti-aliased silhouettes: N coverage samples per pixel\n"
    "                   (4, 8 or 16; 0: off, the binary mask); default 0\n"
    "  --soft-edges     soft silhouettes: the mask's edge pixels fade by the\n"
    "                   share of their 3x3 window inside it (the default,\n"
    "                   except with --aa; in either --view; docs/antialias.md)\n"
    "  --hard-edges     the binary mask's stair-stepped silhouettes\n"
    "  --edge-fade K    soft viewport edges: the hands fade over the last K\n"
    "                   camera pixels (1..64; 0: off, a hard cut); default 4\n"
    "  --quiet          no status line\n"
    "  -h, --help       this text\n"
    "\n"
    "Without cameras: a dry run from recorded frames (--left file:... --right\n"
    "file:...), or composite recorded input: egofuse render --scene FILE.\n";

enum {
    O_SCENE = 256, O_MODEL, O_VIRT, O_LEFT, O_RIGHT, O_FORMAT, O_FPS, O_INPUT, O_DV, O_BUFFERS,
    O_TRACK, O_TRACK_ADDR, O_GLOVE_L, O_GLOVE_R, O_CALIB, O_OUT, O_RAW, O_FRAMES, O_QUIET,
    O_REFINE, O_CONFIG, O_STATS, O_PREDICT, O_HIDE, O_PROP, O_VSRC, O_VLAYOUT, O_VFPS, O_VSTALE,
    O_DISPLAY, O_NATNET, O_NN_LOCAL, O_NN_MCAST, O_NN_BODY, O_NN_UP, O_NN_UNITS, O_NN_VERSION,
    O_NN_OFFSET, O_NN_CMDPORT, O_NN_DATAPORT, O_LOOP, O_HOLD, O_ALLOW_OUTSIDE, O_AA,
    O_HMD_CAM, O_HMD_CAM_HFOV, O_HMD_BASE, O_HMD_OFFSET, O_HMD_DISP, O_HMD_HFOV, O_HMD_VFOV,
    O_HMD_FOCAL, O_HMD_IPD, O_HMD_PRESET, O_DUMP, O_LOD, O_LOD_PX, O_HMD_CALIB, O_HMD_CALIB_L,
    O_HMD_CALIB_R, O_VIEW, O_EDGE_FADE, O_SOFT, O_HARD
};

static const struct option run_long_opts[] = {
    {"scene", required_argument, 0, O_SCENE},
    {"model", required_argument, 0, O_MODEL},
    {"virt", required_argument, 0, O_VIRT},
    {"left", required_argument, 0, O_LEFT},
    {"right", required_argument, 0, O_RIGHT},
    {"format", required_argument, 0, O_FORMAT},
    {"fps", required_argument, 0, O_FPS},
    {"input", required_argument, 0, O_INPUT},
    {"dv", no_argument, 0, O_DV},
    {"buffers", required_argument, 0, O_BUFFERS},
    {"track-port", required_argument, 0, O_TRACK},
    {"track-addr", required_argument, 0, O_TRACK_ADDR},
    {"glove-left", required_argument, 0, O_GLOVE_L},
    {"glove-right", required_argument, 0, O_GLOVE_R},
    {"calib", required_argument, 0, O_CALIB},
    {"out", required_argument, 0, O_OUT},
    {"raw", no_argument, 0, O_RAW},
    {"frames", required_argument, 0, O_FRAMES},
    {"quiet", no_argument, 0, O_QUIET},
    {"help", no_argument, 0, 'h'},
    {"refine", required_argument, 0, O_REFINE},
    {"lod", required_argument, 0, O_LOD},
    {"lod-px", required_argument, 0, O_LOD_PX},
    {"aa", required_argument, 0, O_AA},
    {"edge-fade", required_argument, 0, O_EDGE_FADE},
    {"soft-edges", no_argument, 0, O_SOFT},
    {"hard-edges", no_argument, 0, O_HARD},
    {"config", required_argument, 0, O_CONFIG},
    {"stats", required_argument, 0, O_STATS},
    {"predict-ms", required_argument, 0, O_PREDICT},
    {"hide", required_argument, 0, O_HIDE},
    {"prop", required_argument, 0, O_PROP},
    {"virt-source", required_argument, 0, O_VSRC},
    {"virt-layout", required_argument, 0, O_VLAYOUT},
    {"virt-fps", required_argument, 0, O_VFPS},
    {"virt-stale", required_argument, 0, O_VSTALE},
    {"display", required_argument, 0, O_DISPLAY},
    {"natnet", required_argument, 0, O_NATNET},
    {"natnet-server", required_argument, 0, O_NATNET},
    {"natnet-local", required_argument, 0, O_NN_LOCAL},
    {"natnet-multicast", required_argument, 0, O_NN_MCAST},
    {"natnet-body", required_argument, 0, O_NN_BODY},
    {"natnet-up", required_argument, 0, O_NN_UP},
    {"natnet-units", required_argument, 0, O_NN_UNITS},
    {"natnet-version", required_argument, 0, O_NN_VERSION},
    {"natnet-offset", required_argument, 0, O_NN_OFFSET},
    {"natnet-command-port", required_argument, 0, O_NN_CMDPORT},
    {"natnet-data-port", required_argument, 0, O_NN_DATAPORT},
    {"loop", no_argument, 0, O_LOOP},
    {"hold", no_argument, 0, O_HOLD},
    {"allow-outside", no_argument, 0, O_ALLOW_OUTSIDE},
    {"hmd-camera", required_argument, 0, O_HMD_CAM},
    {"hmd-camera-hfov", required_argument, 0, O_HMD_CAM_HFOV},
    {"hmd-baseline", required_argument, 0, O_HMD_BASE},
    {"hmd-camera-offset", required_argument, 0, O_HMD_OFFSET},
    {"hmd-display", required_argument, 0, O_HMD_DISP},
    {"hmd-hfov", required_argument, 0, O_HMD_HFOV},
    {"hmd-vfov", required_argument, 0, O_HMD_VFOV},
    {"hmd-focal", required_argument, 0, O_HMD_FOCAL},
    {"hmd-ipd", required_argument, 0, O_HMD_IPD},
    {"hmd-preset", required_argument, 0, O_HMD_PRESET},
    {"hmd-calibration", required_argument, 0, O_HMD_CALIB},
    {"hmd-calibration-left", required_argument, 0, O_HMD_CALIB_L},
    {"hmd-calibration-right", required_argument, 0, O_HMD_CALIB_R},
    {"dump", required_argument, 0, O_DUMP},
    {"view", required_argument, 0, O_VIEW},
    {0, 0, 0, 0},
};

static int parse_size(const char *s, int *w, int *h)
{
    char a[32];
    const char *x = strchr(s, 'x');
    if (!x || (size_t)(x - s) >= sizeof a) return 0;
    memcpy(a, s, (size_t)(x - s));
    a[x - s] = '\0';
    return cli_parse_int(a, 16, 16384, w) && cli_parse_int(x + 1, 16, 16384, h);
}

/* [NAME=]MODEL[@X,Y,Z[,YAW,PITCH,ROLL]][#BODY] */
static int parse_prop(const char *s, run_prop *p, char *why, size_t why_n)
{
    memset(p, 0, sizeof *p);
    char buf[IO_PATH_MAX + 256];
    if (strlen(s) >= sizeof buf) return snprintf(why, why_n, "too long"), 0;
    snprintf(buf, sizeof buf, "%s", s);
    char *body = strrchr(buf, '#');
    if (body) {
        *body++ = '\0';
        if (!*body || strlen(body) >= sizeof p->body)
            return snprintf(why, why_n, "'#' needs a rigid body name or id"), 0;
        snprintf(p->body, sizeof p->body, "%s", body);
    }
    char *at = strrchr(buf, '@');
    if (at) {
        *at++ = '\0';
        float v[6] = {0, 0, 0, 0, 0, 0};
        int n = 0;
        for (char *t = strtok(at, ","); t; t = strtok(NULL, ",")) {
            if (n == 6 || !cli_parse_float(t, &v[n]))
                return snprintf(why, why_n, "'@' takes X,Y,Z or X,Y,Z,YAW,PITCH,ROLL"), 0;
            n++;
        }
        if (n != 3 && n != 6)
            return snprintf(why, why_n, "'@' takes X,Y,Z or X,Y,Z,YAW,PITCH,ROLL"), 0;
        memcpy(p->at, v, sizeof p->at);
        memcpy(p->rot_deg, v + 3, sizeof p->rot_deg);
    }
    char *model = buf, *eq = strchr(buf, '=');
    if (eq) {
        *eq = '\0';
        if (!*buf || strlen(buf) >= sizeof p->name)
            return snprintf(why, why_n, "the name before '=' is empty or too long"), 0;
        snprintf(p->name, sizeof p->name, "%s", buf);
        model = eq + 1;
    }
    if (!*model) return snprintf(why, why_n, "no model file"), 0;
    snprintf(p->model, sizeof p->model, "%s", model);
    if (!p->name[0]) {
        const char *b = strrchr(model, '/');
        snprintf(p->name, sizeof p->name, "%s", b ? b + 1 : model);
    }
    return 1;
}

void run_opts_free(run_opts *o) { (void)o; }

/* A usage error; an option that came from the configuration file names
 * its line. */
static int run_bad(const char *const *origin, int optind_now, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int run_bad(const char *const *origin, int optind_now, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const char *from = optind_now > 0 ? origin[optind_now - 1] : NULL;
    if (from) return cli_usage_error("run", "%s: %s", from, msg);
    return cli_usage_error("run", "%s", msg);
}

int run_parse(int argc, char **argv, run_opts *o)
{
    memset(o, 0, sizeof *o);
    o->fourcc = IO_FMT_YUYV;
    o->fps = 60;
    o->input = -1;
    o->buffers = 4;
    o->virt_stale_ms = 200;
    o->lod = CLI_LOD_DEFAULT;
    o->lod_px = CLI_LOD_PX_DEFAULT;
    o->soft_edge = -1; /* the default: cli_soft_edges */

    /* ---- --config first: its options go before the command line's */
    const char *config = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--")) break;
        if (!strcmp(argv[i], "--config") && i + 1 < argc) config = argv[i + 1];
        else if (!strncmp(argv[i], "--config=", 9)) config = argv[i] + 9;
    }
    static io_conf_args conf; /* lives as long as the options point into it */
    io_conf_free(&conf);
    if (config) {
        io_error err;
        if (io_conf_load(config, &conf, &err) != IO_OK) return io_term_fail("%s", err.msg);
    }
    static char **av;
    static const char **origin;
    free(av);
    free(origin);
    int ac = argc + conf.argc;
    av = calloc((size_t)ac + 1, sizeof *av);
    origin = calloc((size_t)ac + 1, sizeof *origin);
    if (!av || !origin) return io_term_fail("out of memory");
    av[0] = argv[0];
    for (int i = 0; i < conf.argc; i++) {
        av[1 + i] = conf.argv[i];
        origin[1 + i] = conf.origin[i];
    }
    for (int i = 1; i < argc; i++) av[conf.argc + i] = argv[i];

    const cli_float_opt fl[] = {
        {O_PREDICT, "--predict-ms", -200, 200, "-200..200 ms", &o->predict_ms},
        {O_HMD_CAM_HFOV, "--hmd-camera-hfov", 1, 179, "1..179 degrees", &o->hmd.cam_hfov_deg},
        {O_HMD_HFOV, "--hmd-hfov", 1, 179, "1..179 degrees", &o->hmd.hmd_hfov_deg},
        {O_HMD_VFOV, "--hmd-vfov", 1, 179, "1..179 degrees", &o->hmd.hmd_vfov_deg},
        {O_HMD_BASE, "--hmd-baseline", 0.001f, 1, "0.001..1 m", &o->hmd.baseline_m},
        {O_HMD_OFFSET, "--hmd-camera-offset", 0, 1, "0..1 m", &o->hmd.cam_offset_m},
        {O_HMD_FOCAL, "--hmd-focal", 0.05f, 100, "0.05..100 m", &o->hmd.focal_m},
        {O_HMD_IPD, "--hmd-ipd", 0.04f, 0.09f, "0.04..0.09 m", &o->hmd.ipd_m},
    };
    enum { NFL = (int)(sizeof fl / sizeof fl[0]) };
#define BAD(...) return run_bad(origin, optind, __VA_ARGS__)
    optind = 1;
    opterr = 0;
    int c;
    static char virt_buf[2 * IO_PATH_MAX];
    kin_sthmd_desc preset;
    int have_preset = 0;
    while ((c = getopt_long(ac, av, "h", run_long_opts, NULL)) != -1) {
        switch (c) {
        case 'h': fputs(run_usage, stdout); return EXIT_OK;
        case O_CONFIG: break; /* read above */
        case O_SCENE: o->scene = optarg; break;
        case O_MODEL: o->model = optarg; break;
        case O_VIRT: {
            snprintf(virt_buf, sizeof virt_buf, "%s", optarg);
            char *comma = strchr(virt_buf, ',');
            if (!comma) BAD("--virt needs LEFT,RIGHT");
            *comma = '\0';
            o->virt[0] = virt_buf;
            o->virt[1] = comma + 1;
            break;
        }
        case O_LEFT: o->sel[0] = optarg; break;
        case O_RIGHT: o->sel[1] = optarg; break;
        case O_FORMAT:
            if (strlen(optarg) != 4) BAD("--format '%s': 4 letters", optarg);
            o->fourcc = IO_FOURCC(optarg[0], optarg[1], optarg[2], optarg[3]);
            o->format_set = 1;
            break;
        case O_FPS:
            if (!cli_parse_int(optarg, 1, 1000, &o->fps)) BAD("--fps '%s': not a frame rate", optarg);
            break;
        case O_INPUT:
            if (!cli_parse_int(optarg, 0, 255, &o->input))
                BAD("--input '%s': not an input number", optarg);
            break;
        case O_DV: o->dv = 1; break;
        case O_LOOP: o->loop = 1; break;
        case O_HOLD: o->hold = 1; break;
        case O_ALLOW_OUTSIDE: io_gltf_allow_outside(1); break;
        case O_BUFFERS:
            if (!cli_parse_int(optarg, 2, IO_CAM_MAX_BUFFERS, &o->buffers))
                BAD("--buffers '%s': 2..%d", optarg, IO_CAM_MAX_BUFFERS);
            break;
        case O_TRACK:
            if (!cli_parse_int(optarg, 1, 65535, &o->track_port))
                BAD("--track-port '%s': not a port", optarg);
            break;
        case O_TRACK_ADDR: o->track_addr = optarg; break;
        case O_GLOVE_L: o->glove_sel[0] = optarg; break;
        case O_GLOVE_R: o->glove_sel[1] = optarg; break;
        case O_CALIB: o->calib = optarg; break;
        case O_OUT: o->out = optarg; break;
        case O_RAW: o->raw = 1; break;
        case O_FRAMES:
            if (!cli_parse_int(optarg, 1, 1 << 30, &o->frames))
                BAD("--frames '%s': not a positive count", optarg);
            break;
        case O_QUIET: o->quiet = 1; break;
        case O_REFINE:
            if (!cli_parse_int(optarg, 1, 64, &o->refine))
                BAD("--refine '%s': a band of 1..64 px", optarg);
            break;
        case O_LOD:
            if (!cli_lod_parse(optarg, &o->lod))
                BAD("--lod '%s': off, auto or a level 0..%d", optarg, PIPE_LOD_MAX - 1);
            break;
        case O_LOD_PX:
            if (!cli_lod_parse_px(optarg, &o->lod_px))
                BAD("--lod-px '%s': pixels, > 0 and <= 1000", optarg);
            break;
        case O_AA: {
            int v;
            if (!cli_parse_int(optarg, 0, 16, &v) || (v != 0 && v != 4 && v != 8 && v != 16))
                BAD("--aa '%s': 0 (off), 4, 8 or 16 samples per pixel", optarg);
            o->aa = v;
            break;
        }
        case O_EDGE_FADE: {
            int v;
            if (!cli_parse_int(optarg, 0, FUSE_EDGE_FADE_MAX, &v))
                BAD("--edge-fade '%s': 0 (off) or a width of 1..%d px", optarg,
                    FUSE_EDGE_FADE_MAX);
            o->edge_fade = v == 0 ? -1 : v;
            break;
        }
        case O_SOFT: o->soft_edge = 1; break;
        case O_HARD: o->soft_edge = 0; break;
        case O_STATS: o->stats = optarg; break;
        case O_DUMP: o->dump = optarg; break;
        case O_HIDE: {
            char why[256];
            if (pipe_parts_parse(optarg, &o->hide, why, (int)sizeof why) != 0)
                BAD("--hide '%s': %s", optarg, why);
            break;
        }
        case O_PROP: {
            char why[128];
            if (o->prop_count == RUN_MAX_PROPS) BAD("--prop: at most %d props", RUN_MAX_PROPS);
            if (!parse_prop(optarg, &o->prop[o->prop_count], why, sizeof why))
                BAD("--prop '%s': %s", optarg, why);
            for (int i = 0; i < o->prop_count; i++)
                if (!strcmp(o->prop[i].name, o->prop[o->prop_count].name))
                    BAD("--prop '%s': a prop named '%s' is already given", optarg,
                        o->prop[i].name);
            o->prop_count++;
            break;
        }
        case O_VSRC: o->virt_source = optarg; break;
        case O_VLAYOUT:
            if (io_vsrc_layout_parse(optarg) < 0) BAD("--virt-layout '%s': sbs, tb or mono", optarg);
            o->virt_layout = optarg;
            break;
        case O_VFPS:
            if (!cli_parse_int(optarg, 1, 1000, &o->virt_fps))
                BAD("--virt-fps '%s': not a frame rate", optarg);
            break;
        case O_VSTALE:
            if (!cli_parse_int(optarg, 1, 60000, &o->virt_stale_ms))
                BAD("--virt-stale '%s': 1..60000 ms", optarg);
            break;
        case O_DISPLAY: {
            io_display_spec ds;
            io_error err;
            if (io_display_parse(optarg, &ds, &err) != IO_OK) BAD("--display: %s", err.msg);
            o->display = optarg;
            break;
        }
        case O_NATNET: case O_NN_LOCAL: case O_NN_MCAST: case O_NN_BODY: case O_NN_UP:
        case O_NN_UNITS: case O_NN_VERSION: case O_NN_OFFSET: case O_NN_CMDPORT:
        case O_NN_DATAPORT: {
            static const char *const key[] = {"server", "local", "multicast", "body", "up",
                                              "units", "version", "offset", "command-port",
                                              "data-port"};
            const char *k = key[c == O_NATNET ? 0 : c - O_NN_LOCAL + 1];
            io_natnet_config scratch;
            io_error err;
            io_natnet_config_default(&scratch);
            if (io_natnet_config_set(&scratch, k, optarg, &err) != IO_OK) BAD("%s", err.msg);
            if (o->natnet_kv_count == RUN_MAX_NATNET) BAD("at most %d NatNet options", RUN_MAX_NATNET);
            o->natnet_kv[o->natnet_kv_count][0] = k;
            o->natnet_kv[o->natnet_kv_count++][1] = optarg;
            if (c == O_NATNET) o->natnet = 1;
            break;
        }
        case O_HMD_CAM:
            if (!parse_size(optarg, &o->hmd.cam_width, &o->hmd.cam_height))
                BAD("--hmd-camera '%s': WIDTHxHEIGHT", optarg);
            break;
        case O_HMD_DISP:
            if (!parse_size(optarg, &o->hmd.lcd_width, &o->hmd.lcd_height))
                BAD("--hmd-display '%s': WIDTHxHEIGHT per eye", optarg);
            break;
        case O_HMD_PRESET:
            if (kin_sthmd_preset(optarg, &preset) != 0)
                BAD("--hmd-preset '%s': one of paper, consumer, highend", optarg);
            have_preset = 1;
            break;
        case O_HMD_CALIB: o->hmd_calib[0] = optarg; break;
        case O_HMD_CALIB_L: o->hmd_calib[1] = optarg; break;
        case O_HMD_CALIB_R: o->hmd_calib[2] = optarg; break;
        case O_VIEW:
            if (pipe_view_parse(optarg, &o->view) != 0)
                BAD("--view '%s': crop (the paper's crop and scale, the default) or reproject "
                    "(to the eye by depth)", optarg);
            break;
        case ':': BAD("option %s needs a value", av[optind - 1]);
        default: {
            const cli_float_opt *e = cli_float_opt_find(fl, NFL, c);
            if (!e) BAD("unknown option '%s'", av[optind - 1]);
            if (!cli_float_opt_parse(e, optarg)) BAD("%s '%s': %s", e->name, optarg, e->range);
            break;
        }
        }
    }
    if (optind < ac) BAD("unexpected argument '%s'", av[optind]);
#undef BAD
    if (have_preset) {
        /* the preset's fields, but for those given by their own option
         * (in the file or on the command line, before or after it) */
        kin_sthmd_desc *h = &o->hmd;
#define TAKE(f) \
    if (!(h->f > 0)) h->f = preset.f
        TAKE(cam_width);
        TAKE(cam_height);
        TAKE(cam_hfov_deg);
        TAKE(baseline_m);
        TAKE(cam_offset_m);
        TAKE(lcd_width);
        TAKE(lcd_height);
        TAKE(hmd_hfov_deg);
        TAKE(hmd_vfov_deg);
        TAKE(focal_m);
        TAKE(znear);
        TAKE(zfar);
        TAKE(ipd_m);
#undef TAKE
    }
    {
        int vr = cli_view_check("run", o->view, o->aa, &o->hmd);
        if (vr != EXIT_OK) return vr;
        vr = cli_soft_edges("run", &o->soft_edge, o->aa);
        if (vr != EXIT_OK) return vr;
    }
    if (!o->sel[0] != !o->sel[1]) return cli_usage_error("run", "give both --left and --right");
    for (int e = 0; e < 2; e++) {
        io_error err;
        if (o->sel[e] && strncmp(o->sel[e], "/dev/", 5) && !io_cam_file_selector(o->sel[e]) &&
            io_usb_selector_check(o->sel[e], &err) != IO_OK)
            return cli_usage_error("run", "--%s: %s", e ? "right" : "left", err.msg);
    }
    int outs = !!o->out + !!o->raw + !!o->display;
    if (outs > 1) return cli_usage_error("run", "--display, --out and --raw exclude each other");
    if (o->dump && !o->frames) return cli_usage_error("run", "--dump needs --frames N");
    if (o->hold && !o->display) return cli_usage_error("run", "--hold needs --display");
    if (o->natnet_kv_count && !o->natnet)
        return cli_usage_error("run", "--natnet-* options need --natnet SERVER");
    if (o->track_port && o->natnet)
        return cli_usage_error("run", "--track-port and --natnet exclude each other");
    if (o->virt_source && o->virt[0])
        return cli_usage_error("run", "--virt-source and --virt exclude each other");
    for (int i = 0; i < o->prop_count; i++)
        if (o->prop[i].body[0] && !o->natnet)
            return cli_usage_error("run", "--prop %s#%s: a prop posed by a rigid body needs --natnet",
                                   o->prop[i].name, o->prop[i].body);
    if (o->hmd_calib[0] || o->hmd_calib[1] || o->hmd_calib[2]) {
        int rc = cli_lens_load(o->hmd_calib[0], o->hmd_calib[1], o->hmd_calib[2], &o->hmd);
        if (rc != EXIT_OK) return rc;
    }
    return -1;
}
