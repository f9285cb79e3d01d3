/* gen_main.c - build/gen_samples: writes the sample data of egofuse.
 *
 *   gen_samples --out DIR [--frames N] [--seed S] [--threads T] [--hmd NAME]
 *
 * DIR/model/arms.glb, DIR/cam/{left,right}_%04d.png (640x480 sensor),
 * DIR/virt/{left,right}_%04d.png (1280x800), DIR/virt/{left,right}_depth_
 * %04d.exr (view-space depth in metres), DIR/track.txt (the recorded
 * tracking of the true motion) and DIR/scene.txt. See
 * samples/README.md. The output depends only on N and S (not on T).
 * --hmd NAME (kin_sthmd_preset: paper, consumer, highend) renders the
 * camera and virtual images at that HMD's sizes and FOVs and names it in
 * scene.txt (`hmd = NAME`, docs/scene.md). */
#include "gen.h"
#include "../../src/io/io.h"

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define MAX_THREADS 8

typedef struct job {
    const char *out;
    int frames, threads, only;
    uint64_t seed;
    const gen_arms *arms;
    const gen_scene *cockpit, *workshop;
    const char *hmd_name;     /* --hmd, or NULL: the paper's */
    kin_sthmd_desc hmd;       /* resolved */
    float (*coverage)[2];
    pthread_mutex_t lock;
    int done, failed;
    char why[3 * PATH_MAX];
} job;

typedef struct worker { job *j; int index; } worker;

static int make_dir(const char *path)
{
    if (mkdir(path, 0777) == 0 || errno == EEXIST) {
        struct stat st;
        if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return 0;
        errno = ENOTDIR;
    }
    return -1;
}

/* mkdir -p */
static int make_dirs(const char *path)
{
    char buf[PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/') continue;
        *p = 0;
        if (make_dir(buf) < 0) return -1;
        *p = '/';
    }
    return make_dir(buf);
}

static void fail(job *j, const char *msg)
{
    pthread_mutex_lock(&j->lock);
    if (!j->failed) snprintf(j->why, sizeof j->why, "%s", msg);
    j->failed = 1;
    pthread_mutex_unlock(&j->lock);
}

static int save(job *j, const char *path, const io_image *img)
{
    io_error err;
    if (io_image_save(path, img, &err) != IO_OK) {
        char msg[3 * PATH_MAX];
        snprintf(msg, sizeof msg, "%s", err.msg);
        if (!strstr(msg, path)) snprintf(msg, sizeof msg, "%s: %s", path, err.msg);
        fail(j, msg);
        return -1;
    }
    return 0;
}

static void *run_worker(void *arg)
{
    worker *w = arg;
    job *j = w->j;
    gen_frame_ctx ctx;
    io_image cam = { 0 }, virt = { 0 }, dep = { 0 };
    io_error err;
    if (gen_frame_ctx_init(&ctx, j->arms, j->cockpit, j->workshop, j->seed) < 0) {
        fail(j, "out of memory");
        return NULL;
    }
    if (j->hmd_name && gen_frame_ctx_set_hmd(&ctx, &j->hmd) < 0) {
        fail(j, "out of memory");
        goto done;
    }
    const int cw = j->hmd.cam_width, ch = j->hmd.cam_height;
    const int vw = j->hmd.lcd_width, vh = j->hmd.lcd_height;
    if (io_image_alloc(&cam, cw, ch, 3, IO_U8, &err) != IO_OK ||
        io_image_alloc(&virt, vw, vh, 3, IO_U8, &err) != IO_OK ||
        io_image_alloc(&dep, vw, vh, 1, IO_F32, &err) != IO_OK) {
        fail(j, "out of memory");
        goto done;
    }
    static const char *const eye_name[2] = { "left", "right" };
    for (int f = w->index; f < j->frames; f += j->threads) {
        if (j->failed) break;
        if (j->only >= 0 && f != j->only) continue;
        kin_mat4 head;
        gen_pose(&ctx, (float)f / (float)GEN_FPS, &head);
        for (int e = 0; e < 2; e++) {
            char path[PATH_MAX + 64];
            gen_render_camera(&ctx, &head, (kin_eye)e, f, cam.data, &j->coverage[f][e]);
            snprintf(path, sizeof path, "%s/cam/%s_%04d.png", j->out, eye_name[e], f);
            if (save(j, path, &cam) < 0) goto done;
            gen_render_virtual(&ctx, &head, (kin_eye)e, f, virt.data, dep.data);
            snprintf(path, sizeof path, "%s/virt/%s_%04d.png", j->out, eye_name[e], f);
            if (save(j, path, &virt) < 0) goto done;
            snprintf(path, sizeof path, "%s/virt/%s_depth_%04d.exr", j->out, eye_name[e], f);
            if (save(j, path, &dep) < 0) goto done;
        }
        pthread_mutex_lock(&j->lock);
        int d = ++j->done;
        if (d % 20 == 0 || d == j->frames)
            printf("gen_samples: %d/%d frames\n", d, j->frames), fflush(stdout);
        pthread_mutex_unlock(&j->lock);
    }
done:
    io_image_free(&cam);
    io_image_free(&virt);
    io_image_free(&dep);
    gen_frame_ctx_free(&ctx);
    return NULL;
}

static int write_scene(const char *dir, int frames, const gen_scene *ws, const job *j,
                       char *why, size_t why_size)
{
    /* the crop of eq. 1, for the comment */
    const kin_sthmd_geometry g = kin_sthmd_geometry_of(&j->hmd);
    char crop[96];
    if (g.crop_width < j->hmd.cam_width)
        snprintf(crop, sizeof crop, "columns %d..%d", g.crop_x0, g.crop_x0 + g.crop_width - 1);
    else
        snprintf(crop, sizeof crop, "rows %d..%d", g.crop_y0, g.crop_y0 + g.crop_height - 1);
    char path[PATH_MAX + 32], tmp[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/scene.txt", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        snprintf(why, why_size, "%s: cannot create: %s", tmp, strerror(errno));
        return -1;
    }
    fprintf(f, "egofuse-scene 1\n"
               "# Generated by build/gen_samples (samples/README.md).\n"
               "# Camera images: %dx%d sensor (the pipeline crops %s).\n"
               "# Virtual depth: view-space depth -z of the eye in metres (EXR, 1 channel),\n"
               "# %g where nothing was drawn.\n"
               "model = model/arms.glb\n"
               "animation = %s\n"
               "head_node = head\n"
               "frames = %d\n"
               "fps = %d\n"
               "camera_left = cam/left_%%04d.png\n"
               "camera_right = cam/right_%%04d.png\n"
               "virtual_left = virt/left_%%04d.png\n"
               "virtual_right = virt/right_%%04d.png\n"
               "virtual_depth_left = virt/left_depth_%%04d.exr\n"
               "virtual_depth_right = virt/right_depth_%%04d.exr\n"
               "# the true motion as a tracker and data gloves would record it\n"
               "# (egofuse render --pose tracking)\n"
               "tracking = track.txt\n"
               "# lighting layer: the workshop's own lights (world directions towards them)\n"
               "ambient = %.3f %.3f %.3f\n",
            j->hmd.cam_width, j->hmd.cam_height, crop,
            (double)GEN_VIRT_ZFAR, GEN_ANIM_NAME, frames, GEN_FPS,
            (double)ws->ambient[0], (double)ws->ambient[1], (double)ws->ambient[2]);
    for (int i = 0; i < ws->light_count; i++)
        fprintf(f, "light = %.4f %.4f %.4f %.3f %.3f %.3f\n",
                (double)ws->light_dir[i][0], (double)ws->light_dir[i][1],
                (double)ws->light_dir[i][2], (double)ws->light_color[i][0],
                (double)ws->light_color[i][1], (double)ws->light_color[i][2]);
    /* kf 0: the Fresnel fade measured against the opaque ideal composite
     * (egofuse eval --kf-sweep, docs/fuse.md): every fade costs PSNR */
    fprintf(f, "kd = 0.80\nks = 0.12\nshininess = 20\n"
               "# no Fresnel edge fade: the best against the ideal composite (egofuse eval --kf-sweep)\n"
               "kf = 0.00\ntone = 1.00 0.98 0.96\n");
    if (j->hmd_name)
        fprintf(f, "# the HMD (docs/kin.md, named HMDs): camera %dx%d, display %dx%d per eye\n"
                   "hmd = %s\n",
                j->hmd.cam_width, j->hmd.cam_height, j->hmd.lcd_width, j->hmd.lcd_height,
                j->hmd_name);
    int bad = ferror(f);
    if (fclose(f) != 0) bad = 1;
    if (bad) {
        snprintf(why, why_size, "%s: write error", tmp);
        remove(tmp);
        return -1;
    }
    if (rename(tmp, path) != 0) {
        snprintf(why, why_size, "%s: cannot rename into place: %s", path, strerror(errno));
        remove(tmp);
        return -1;
    }
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: gen_samples --out DIR [--frames N] [--seed S] [--threads T] [--only F]\n"
               "                   [--hmd NAME]\n"
               "  writes the sample data of egofuse into DIR (samples/README.md):\n"
               "  model/arms.glb, cam/, virt/, track.txt, scene.txt. Defaults: 180 frames\n"
               "  (3 s at 60 Hz), seed 1, 2 threads (the output does not depend\n"
               "  on the thread count). --only F renders frame F alone (previews).\n"
               "  --hmd NAME: the images at a named HMD's sizes and FOVs (paper,\n"
               "  consumer: 1280x1024 cameras, 2064x2208 per eye; highend: 1920x1080,\n"
               "  2880x2720; docs/kin.md), named in scene.txt (hmd = NAME).\n");
}

static int parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return -1;
    *out = v;
    return 0;
}

int main(int argc, char **argv)
{
    const char *out = NULL;
    long frames = 180, seed = 1, threads = 2, only = -1;
    const char *hmd_name = NULL;
    kin_sthmd_desc hmd = kin_sthmd_desc_resolved(NULL);
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) { usage(stdout); return 0; }
        if (i + 1 >= argc) {
            fprintf(stderr, "gen_samples: %s needs a value\n", a);
            usage(stderr);
            return 2;
        }
        const char *v = argv[++i];
        if (!strcmp(a, "--out")) out = v;
        else if (!strcmp(a, "--frames")) {
            if (parse_int(v, 1, 100000, &frames) < 0) {
                fprintf(stderr, "gen_samples: --frames %s: expected 1..100000\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--seed")) {
            if (parse_int(v, 0, LONG_MAX, &seed) < 0) {
                fprintf(stderr, "gen_samples: --seed %s: expected a non-negative integer\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--threads")) {
            if (parse_int(v, 1, MAX_THREADS, &threads) < 0) {
                fprintf(stderr, "gen_samples: --threads %s: expected 1..%d\n", v, MAX_THREADS);
                return 2;
            }
        } else if (!strcmp(a, "--only")) {
            if (parse_int(v, 0, 100000, &only) < 0) {
                fprintf(stderr, "gen_samples: --only %s: expected a frame number\n", v);
                return 2;
            }
        } else if (!strcmp(a, "--hmd")) {
            if (kin_sthmd_preset(v, &hmd) != 0) {
                fprintf(stderr, "gen_samples: --hmd %s: expected one of", v);
                for (int k = 0; kin_sthmd_preset_name(k); k++)
                    fprintf(stderr, "%s %s", k ? "," : "", kin_sthmd_preset_name(k));
                fprintf(stderr, "\n");
                return 2;
            }
            hmd_name = v;
        } else {
            fprintf(stderr, "gen_samples: unknown option %s\n", a);
            usage(stderr);
            return 2;
        }
    }
    if (!out) {
        fprintf(stderr, "gen_samples: --out DIR is required\n");
        usage(stderr);
        return 2;
    }
    static const char *const sub[3] = { "model", "cam", "virt" };
    char path[PATH_MAX + 64], why[3 * PATH_MAX];
    if (make_dirs(out) < 0) {
        fprintf(stderr, "gen_samples: cannot create %s: %s\n", out, strerror(errno));
        return 1;
    }
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", out, sub[i]);
        if (make_dir(path) < 0) {
            fprintf(stderr, "gen_samples: cannot create %s: %s\n", path, strerror(errno));
            return 1;
        }
    }

    gen_arms arms;
    gen_scene cockpit, workshop;
    if (gen_arms_build(&arms) < 0) {
        fprintf(stderr, "gen_samples: out of memory building the model\n");
        return 1;
    }
    char vwhy[256];
    if (kin_model_validate(&arms.model, vwhy, sizeof vwhy) != 0) {
        fprintf(stderr, "gen_samples: internal error, invalid model: %s\n", vwhy);
        gen_arms_free(&arms);
        return 1;
    }
    const kin_mesh *me = &arms.model.meshes[0];
    printf("gen_samples: model: %d nodes, %d joints, %d vertices, %d triangles, "
           "animation %s %.2f s\n", arms.model.node_count, arms.model.skins[0].joint_count,
           me->vertex_count, me->index_count / 3, arms.model.anims[0].name,
           (double)arms.model.anims[0].duration);
    snprintf(path, sizeof path, "%s/model/arms.glb", out);
    int rc = 1;
    if (gen_glb_write(path, &arms, why, sizeof why) < 0) {
        fprintf(stderr, "gen_samples: %s\n", why);
        gen_arms_free(&arms);
        return 1;
    }
    if (gen_scene_cockpit(&cockpit) < 0 || gen_scene_workshop(&workshop, &arms) < 0) {
        fprintf(stderr, "gen_samples: out of memory building the scenes\n");
        gen_scene_free(&cockpit);
        gen_scene_free(&workshop);
        gen_arms_free(&arms);
        return 1;
    }

    job j;
    memset(&j, 0, sizeof j);
    j.out = out;
    j.frames = (int)frames;
    j.threads = (int)threads;
    j.only = (int)only;
    j.seed = (uint64_t)seed;
    j.arms = &arms;
    j.cockpit = &cockpit;
    j.workshop = &workshop;
    j.hmd_name = hmd_name;
    j.hmd = kin_sthmd_desc_resolved(&hmd);
    j.coverage = calloc((size_t)frames, sizeof *j.coverage);
    pthread_mutex_init(&j.lock, NULL);
    if (!j.coverage) {
        fprintf(stderr, "gen_samples: out of memory\n");
        goto out;
    }
    pthread_t tid[MAX_THREADS];
    worker wk[MAX_THREADS];
    int started = 0;
    for (int i = 0; i < j.threads; i++) {
        wk[i].j = &j;
        wk[i].index = i;
        /* a worker whose thread cannot start runs after worker 0 */
        if (i > 0 && pthread_create(&tid[i], NULL, run_worker, &wk[i]) == 0)
            started |= 1 << i;
    }
    run_worker(&wk[0]);
    for (int i = 1; i < j.threads; i++) {
        if (started & (1 << i)) pthread_join(tid[i], NULL);
        else run_worker(&wk[i]);
    }
    if (j.failed) {
        fprintf(stderr, "gen_samples: %s\n", j.why);
        goto out;
    }
    snprintf(path, sizeof path, "%s/track.txt", out);
    if (gen_track_write(path, &arms, (int)frames, why, sizeof why) < 0) {
        fprintf(stderr, "gen_samples: %s\n", why);
        goto out;
    }
    if (write_scene(out, (int)frames, &workshop, &j, why, sizeof why) < 0) {
        fprintf(stderr, "gen_samples: %s\n", why);
        goto out;
    }
    double sum = 0, mn = 1, mx = 0;
    for (long f = 0; f < frames; f++)
        for (int e = 0; e < 2; e++) {
            double c = j.coverage[f][e];
            sum += c;
            if (c < mn) mn = c;
            if (c > mx) mx = c;
        }
    printf("gen_samples: arm coverage of the cropped camera images: frame 0 "
           "left %.4f right %.4f; min %.4f mean %.4f max %.4f\n",
           (double)j.coverage[0][0], (double)j.coverage[0][1], mn,
           sum / (2.0 * (double)frames), mx);
    printf("gen_samples: wrote %s/scene.txt and %s/track.txt (%ld frames, seed %ld)\n", out,
           out, frames, seed);
    rc = 0;
out:
    free(j.coverage);
    pthread_mutex_destroy(&j.lock);
    gen_scene_free(&cockpit);
    gen_scene_free(&workshop);
    gen_arms_free(&arms);
    return rc;
}
