/* cmd_calibrate.c - `egofuse calibrate`: writes the user calibration file
 * (egofuse-calib 1) from a calibration recording (an egofuse-track 1 file
 * of the calibration poses) and, optionally, raw glove readings; the
 * estimate is kin_user_calib_estimate_tips (docs/tracking.md, "Per-user
 * calibration" and "The calibrate command"). */
#include "cli.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *calib_usage =
    "usage: egofuse calibrate (--model FILE | --scene FILE) --recording FILE\n"
    "                         --out FILE [--glove-left RAW] [--glove-right RAW]\n"
    "\n"
    "Writes the user calibration file (egofuse-calib 1) from a recording of\n"
    "the calibration poses: the arms stretched forward, sideways and up for\n"
    "a few seconds, then the fingertip gesture (fingers straight, the tips of\n"
    "both middle fingers pressed together in front of the chest, a second or\n"
    "two). docs/tracking.md.\n"
    "\n"
    "  --model FILE       the glTF arm model whose bones are scaled\n"
    "  --scene FILE       or the model of a scene file\n"
    "  --recording FILE   the poses as a tracking file (egofuse-track 1):\n"
    "                     shoulders and hands (position and rotation);\n"
    "                     `egofuse run` or any tracker driver records it\n"
    "  --glove-left RAW   raw readings of the left glove while the hand opens\n"
    "  --glove-right RAW  and closes: one line of 5 numbers per reading (thumb\n"
    "                     .. little, as the glove reports them), '#' comments\n"
    "  --glove-invert MASK  sensors (bit 0 thumb .. 4 little) that read lower\n"
    "                     when bent\n"
    "  --out FILE         the calibration file, written atomically\n"
    "  -h, --help         this text\n";

#define GLOVE_MIN_RANGE 0.05f

/* Reads a raw glove file: n lines of 5 numbers. */
static int read_glove(const char *path, float **out, int *count)
{
    FILE *f = fopen(path, "r");
    if (!f) return io_term_fail("%s: %s", path, strerror(errno));
    int cap = 256, n = 0, line = 0;
    float *v = malloc(sizeof(float) * 5 * (size_t)cap);
    char buf[1024];
    while (v && fgets(buf, sizeof buf, f)) {
        line++;
        char *hash = strchr(buf, '#');
        if (hash) *hash = 0;
        char *p = buf;
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
        if (!*p) continue;
        if (n == cap) {
            float *nv = realloc(v, sizeof(float) * 5 * (size_t)cap * 2);
            if (!nv) break;
            v = nv;
            cap *= 2;
        }
        for (int k = 0; k < 5; k++) {
            char *e;
            errno = 0;
            double d = strtod(p, &e);
            if (e == p || errno || !isfinite(d)) {
                fclose(f);
                free(v);
                return io_term_fail("%s:%d: reading %d: needs 5 numbers (thumb .. little)", path,
                                line, k + 1);
            }
            v[5 * n + k] = (float)d;
            p = e;
        }
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n') p++;
        if (*p) {
            fclose(f);
            free(v);
            return io_term_fail("%s:%d: more than 5 numbers", path, line);
        }
        n++;
    }
    fclose(f);
    if (!v) return io_term_fail("%s: out of memory", path);
    *out = v;
    *count = n;
    return EXIT_OK;
}

int cmd_calibrate(int argc, char **argv)
{
    enum { O_MODEL = 256, O_SCENE, O_REC, O_OUT, O_GL, O_GR, O_INV };
    static const struct option opts[] = {
        {"model", required_argument, 0, O_MODEL}, {"scene", required_argument, 0, O_SCENE},
        {"recording", required_argument, 0, O_REC}, {"out", required_argument, 0, O_OUT},
        {"glove-left", required_argument, 0, O_GL}, {"glove-right", required_argument, 0, O_GR},
        {"glove-invert", required_argument, 0, O_INV}, {"help", no_argument, 0, 'h'},
        {0, 0, 0, 0},
    };
    const char *model_arg = NULL, *scene = NULL, *rec = NULL, *out = NULL, *glove[2] = {0, 0};
    int invert = 0;
    int c, rc;
    cli_getopt_begin();
    while ((c = cli_getopt("calibrate", calib_usage, argc, argv, opts, &rc)) > 0) {
        switch (c) {
        case O_MODEL: model_arg = optarg; break;
        case O_SCENE: scene = optarg; break;
        case O_REC: rec = optarg; break;
        case O_OUT: out = optarg; break;
        case O_GL: glove[0] = optarg; break;
        case O_GR: glove[1] = optarg; break;
        case O_INV:
            if (!cli_parse_int(optarg, 0, 31, &invert))
                return cli_usage_error("calibrate", "--glove-invert '%s': a mask 0..31", optarg);
            break;
        }
    }
    if (c < 0) return rc;
    if (optind < argc) return cli_usage_error("calibrate", "unexpected argument '%s'", argv[optind]);
    if (!model_arg == !scene) return cli_usage_error("calibrate", "give --model or --scene (one)");
    if (!rec) return cli_usage_error("calibrate", "--recording FILE is required");
    if (!out) return cli_usage_error("calibrate", "--out FILE is required");

    io_error err;
    char model_path[IO_PATH_MAX + 64];
    if (scene) {
        io_scene sc;
        if (io_scene_load(scene, &sc, &err) != IO_OK) return io_term_fail("%s", err.msg);
        io_scene_frame_path(&sc, sc.model, 0, model_path, sizeof model_path);
    } else {
        snprintf(model_path, sizeof model_path, "%s", model_arg);
    }
    kin_model model;
    if (io_gltf_load(model_path, &model, &err) != IO_OK) return io_term_fail("%s", err.msg);
    rc = EXIT_FAIL;
    kin_track_sample *smp = NULL;
    float *scratch = NULL, *raw = NULL;
    int count = 0;
    char why[512];
    kin_arm_rig rig;
    if (kin_arm_rig_init(&rig, &model, why, sizeof why) != 0) {
        io_term_fail("%s: cannot calibrate this model: %s", model_path, why);
        goto done;
    }
    kin_vec3 tip[2];
    char tip_why[256] = "";
    int have_tips = kin_user_calib_hand_tips(&rig, &model, tip, tip_why, sizeof tip_why) == 0;
    if (io_track_load(rec, &smp, &count, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        goto done;
    }
    if (!(scratch = malloc(sizeof(float) * (size_t)(count > 0 ? count : 1)))) {
        io_term_fail("out of memory");
        goto done;
    }
    kin_user_calib cal;
    int er = kin_user_calib_estimate_tips(smp, count, &rig, have_tips ? tip : NULL, scratch, &cal,
                                          why, sizeof why);
    if (er < 0) {
        io_term_fail("%s: %s", rec, why);
        goto done;
    }
    for (int s = 0; s < 2; s++) {
        if (!glove[s]) continue;
        int n = 0;
        free(raw);
        raw = NULL;
        if (read_glove(glove[s], &raw, &n) != EXIT_OK) goto done;
        float *sc2 = malloc(sizeof(float) * (size_t)(n > 0 ? n : 1));
        if (!sc2) {
            io_term_fail("out of memory");
            goto done;
        }
        char gw[256];
        int gr = kin_glove_calib_fit(raw, n, (unsigned)invert, GLOVE_MIN_RANGE, sc2, &cal.glove[s],
                                     gw, sizeof gw);
        free(sc2);
        if (gr != 0) {
            io_term_fail("%s: %s glove: %s", glove[s], s ? "right" : "left", gw);
            goto done;
        }
        cal.has_glove[s] = 1;
    }
    if (io_user_calib_save(out, &cal, &err) != IO_OK) {
        io_term_fail("%s", err.msg);
        goto done;
    }
    printf("egofuse calibrate: %s: arm scale %.3f %.3f (arms %.3f %.3f m), shoulder scale %.3f "
           "(%.3f m), hand scale %.3f %.3f%s%s; wrote %s\n",
           rec, (double)cal.arm_scale[0], (double)cal.arm_scale[1], (double)cal.arm_length[0],
           (double)cal.arm_length[1], (double)cal.shoulder_scale, (double)cal.shoulder_width,
           (double)cal.hand_scale[0], (double)cal.hand_scale[1],
           cal.has_glove[0] || cal.has_glove[1] ? ", gloves" : "",
           er == 1 ? " (from the arms: no fingertip gesture found)" : " (fingertip gesture)", out);
    for (int k = 0; k < 2; k++)
        if (fabsf(cal.arm_scale[k] - 1.0f) > 0.2f)
            fprintf(stderr, "egofuse calibrate: warning: %s arm scale %.3f is far from the model's: "
                    "were the arms stretched straight during the recording?\n", k ? "right" : "left",
                    (double)cal.arm_scale[k]);
    if (er == 1)
        fprintf(stderr, "egofuse calibrate: hand scale from the arms: %s%s%s\n", why,
                have_tips ? "" : "; ", have_tips ? "" : tip_why);
    rc = EXIT_OK;
done:
    free(raw);
    free(scratch);
    io_track_free(smp);
    kin_model_free(&model);
    return rc;
}
