/* io_file_cam.c - io_cam_file (io_vsrc.h): a camera backend that plays
 * recorded frames in real time for dry runs of `egofuse run`: an image
 * sequence (printf pattern, io_image_load), a YUV4MPEG2 file, or any video
 * decoded by a spawned ffmpeg into YUV4MPEG2 (read by io_vstream.c). Frame
 * k is due at t0 + k * period on CLOCK_MONOTONIC; a timerfd on cam->fd
 * makes poll() wake when it is. The state is allocated at open (it does
 * not fit in priv_store) and freed at close. */
#include "io_vsrc.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/timerfd.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "io.h"
#include "io_vstream.h"

enum { M_SEQ = 1, M_Y4M, M_FFMPEG };

typedef struct fcam {
    io_file_cam_opts o;
    int mode;
    char src[IO_CAM_NAME_MAX];     /* pattern or video path */
    int first, count;              /* image sequence: files first.. */
    uint8_t **cache;               /* decoded RGB frames, or NULL */
    /* video */
    int vfd;
    pid_t pid;
    vs_reader r;
    uint64_t vnext;                /* index of the next video frame parsed */
    uint8_t *hold;                 /* RGB of the newest video frame parsed */
    uint64_t hold_k;
    int have_hold;
    uint8_t *rgba;                 /* conversion scratch */
    /* pacing */
    uint64_t t0, period, next_k;
    int ended, tfd;
    int order[IO_CAM_MAX_BUFFERS], nq;
} fcam;

int io_cam_file_selector(const char *sel) { return sel && !strncmp(sel, "file:", 5); }

static fcam *fc_of(const io_cam *cam) { return cam->priv ? *(fcam *const *)cam->priv : NULL; }

int io_cam_file_ended(const io_cam *cam)
{
    if (!cam || cam->be != &io_cam_file) return 0;
    fcam *p = fc_of(cam);
    return p && p->ended;
}

static uint64_t now_of(const fcam *p)
{
    if (p->o.clock_ns) return *p->o.clock_ns;
    return io_now_ns();
}

/* One %d or %0Nd (N 1..2 digits), "%%" literal: 1 if a valid pattern, 0
 * if no conversion, -1 if malformed. */
static int pattern_kind(const char *s)
{
    int n = 0;
    for (const char *p = s; *p; p++) {
        if (*p != '%') continue;
        if (p[1] == '%') {
            p++;
            continue;
        }
        const char *q = p + 1;
        if (*q == '0') {
            q++;
            if (*q < '1' || *q > '9') return -1;
            q++;
            if (*q >= '0' && *q <= '9') q++;
        }
        if (*q != 'd') return -1;
        n++;
        p = q;
    }
    return n == 0 ? 0 : n == 1 ? 1 : -1;
}

static void frame_path(const fcam *p, int i, char *out, size_t n)
{
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
    snprintf(out, n, p->src, i);
#pragma GCC diagnostic pop
}

/* RGB (w x h x 3) into the camera's format. */
static void from_rgb(io_cam *cam, const uint8_t *rgb, uint8_t *d)
{
    int w = cam->width, h = cam->height;
    for (int y = 0; y < h; y++) {
        const uint8_t *s = rgb + (size_t)y * 3 * (size_t)w;
        uint8_t *o = d + (size_t)y * cam->stride;
        if (cam->fourcc == IO_FMT_RGB3) {
            memcpy(o, s, 3 * (size_t)w);
        } else if (cam->fourcc == IO_FMT_GREY) {
            for (int x = 0; x < w; x++)
                o[x] = (uint8_t)((77 * s[3 * x] + 150 * s[3 * x + 1] + 29 * s[3 * x + 2] + 128) >> 8);
        } else { /* YUYV, BT.601 limited range; chroma of the pair's mean */
            for (int x = 0; x < w; x += 2) {
                const uint8_t *a = s + 3 * x, *b = x + 1 < w ? a + 3 : a;
                int r = a[0] + b[0], g = a[1] + b[1], bl = a[2] + b[2];
                o[2 * x] = (uint8_t)(((66 * a[0] + 129 * a[1] + 25 * a[2] + 128) >> 8) + 16);
                o[2 * x + 1] = (uint8_t)(((-38 * r - 74 * g + 112 * bl + 256) >> 9) + 128);
                if (x + 1 < w) {
                    o[2 * x + 2] = (uint8_t)(((66 * b[0] + 129 * b[1] + 25 * b[2] + 128) >> 8) + 16);
                    o[2 * x + 3] = (uint8_t)(((112 * r - 94 * g - 18 * bl + 256) >> 9) + 128);
                }
            }
        }
    }
}

static io_result load_image(io_cam *cam, fcam *p, int i, uint8_t *rgb, io_error *err)
{
    char path[IO_CAM_NAME_MAX + 32];
    frame_path(p, i, path, sizeof path);
    io_image img;
    io_result r = io_image_load(path, IO_U8, 3, &img, err);
    if (r != IO_OK) return r;
    if (img.width != cam->width || img.height != cam->height) {
        io_fail(err, IO_ERR_SIZE, "%s: %s is %dx%d, the camera is configured for %dx%d",
                cam->cfg.path, path, img.width, img.height, cam->width, cam->height);
        io_image_free(&img);
        return IO_ERR_SIZE;
    }
    for (int y = 0; y < img.height; y++)
        memcpy(rgb + (size_t)y * 3 * (size_t)img.width, (uint8_t *)img.data + (size_t)y * img.stride,
               3 * (size_t)img.width);
    io_image_free(&img);
    return IO_OK;
}

static io_result open_seq(io_cam *cam, fcam *p, io_error *err)
{
    char path[IO_CAM_NAME_MAX + 32];
    p->first = 0;
    frame_path(p, 0, path, sizeof path);
    if (access(path, R_OK) != 0) {
        p->first = 1;
        frame_path(p, 1, path, sizeof path);
        if (access(path, R_OK) != 0) {
            char p0[IO_CAM_NAME_MAX + 32];
            frame_path(p, 0, p0, sizeof p0);
            return io_fail(err, IO_ERR_NOT_FOUND, "%s: no recorded frame: neither %s nor %s can "
                           "be read", cam->cfg.path, p0, path);
        }
    }
    for (p->count = 0; p->count < 10000000; p->count++) {
        frame_path(p, p->first + p->count, path, sizeof path);
        if (access(path, R_OK) != 0) break;
    }
    /* the first frame decides the size */
    io_image img;
    frame_path(p, p->first, path, sizeof path);
    io_result r = io_image_load(path, IO_U8, 3, &img, err);
    if (r != IO_OK) return r;
    int w = img.width, h = img.height;
    io_image_free(&img);
    if (w != cam->cfg.width || h != cam->cfg.height)
        return io_fail(err, IO_ERR_FORMAT, "%s: the recorded frames are %dx%d (%s), the camera "
                       "is configured for %dx%d", cam->cfg.path, w, h, path, cam->cfg.width,
                       cam->cfg.height);
    size_t fb = 3 * (size_t)w * (size_t)h;
    size_t lim = p->o.cache_bytes ? p->o.cache_bytes : (size_t)64 << 20;
    if ((size_t)p->count * fb <= lim) {
        p->cache = calloc((size_t)p->count, sizeof *p->cache);
        if (!p->cache) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", cam->cfg.path);
        for (int i = 0; i < p->count; i++) {
            if (!(p->cache[i] = malloc(fb)))
                return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", cam->cfg.path);
            if ((r = load_image(cam, p, p->first + i, p->cache[i], err)) != IO_OK) return r;
        }
    }
    return IO_OK;
}

/* Waits up to ms for the next video frame (blocking use at open). */
static int video_next(io_cam *cam, fcam *p, int wait_ms, io_error *err)
{
    uint64_t end = io_now_ns() + (uint64_t)wait_ms * 1000000ull;
    for (;;) {
        vs_frame f;
        int st = vs_parse(&p->r, &f);
        if (st == VS_FRAME) {
            if (f.width != cam->width || f.height != cam->height) {
                io_fail(err, IO_ERR_FORMAT, "%s: the video is %dx%d, the camera is configured for "
                        "%dx%d", cam->cfg.path, f.width, f.height, cam->width, cam->height);
                return -1;
            }
            io_frame fr;
            memset(&fr, 0, sizeof fr);
            fr.data = p->r.buf + f.off;
            fr.bytes = f.bytes;
            fr.width = f.width;
            fr.height = f.height;
            fr.stride = io_fmt_min_stride(f.fourcc, f.width);
            fr.fourcc = f.fourcc;
            if (io_frame_to_rgba_range(&fr, p->rgba, 4 * (size_t)f.width, f.full_range, err) != IO_OK)
                return -1;
            size_t n = (size_t)f.width * (size_t)f.height;
            for (size_t i = 0; i < n; i++) memcpy(p->hold + 3 * i, p->rgba + 4 * i, 3);
            p->hold_k = p->vnext++;
            p->have_hold = 1;
            vs_drop(&p->r, p->r.pos);
            return 1;
        }
        if (st == VS_BAD) continue;
        if (st == VS_FATAL) {
            io_fail(err, IO_ERR_FORMAT, "%s", p->r.msg);
            return -1;
        }
        if (p->r.eof) {
            if (p->o.loop && p->mode == M_Y4M && p->vnext > 0 && lseek(p->vfd, 0, SEEK_SET) == 0) {
                vs_restart(&p->r);
                continue;
            }
            if (p->r.len == 0 && p->vnext == 0 && p->mode == M_FFMPEG) {
                io_fail(err, IO_ERR_FORMAT, "%s: ffmpeg gave no frame (not installed, or it cannot "
                        "read %s; run the same ffmpeg command to see why)", cam->cfg.path, p->src);
                return -1;
            }
            return 0; /* end of the video */
        }
        long n = vs_fill(&p->r, p->vfd, 0);
        if (n > 0 || n == 0) continue;
        if (n == -2) {
            io_fail(err, IO_ERR_READ, "%s", p->r.msg);
            return -1;
        }
        uint64_t t = io_now_ns();
        if (t >= end || wait_ms <= 0) return 2; /* not yet */
        struct pollfd pf = {p->vfd, POLLIN, 0};
        poll(&pf, 1, (int)((end - t) / 1000000ull) + 1);
    }
}

static io_result open_video(io_cam *cam, fcam *p, io_error *err)
{
    size_t l = strlen(p->src);
    vs_init(&p->r, cam->cfg.path);
    p->vfd = -1;
    if (l > 4 && !strcmp(p->src + l - 4, ".y4m")) {
        p->mode = M_Y4M;
        p->vfd = open(p->src, O_RDONLY | O_CLOEXEC);
        if (p->vfd < 0)
            return io_fail(err, errno == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_READ, "%s: cannot open "
                           "%s: %s", cam->cfg.path, p->src, strerror(errno));
    } else {
        if (access(p->src, R_OK) != 0)
            return io_fail(err, errno == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_READ, "%s: cannot read "
                           "%s: %s", cam->cfg.path, p->src, strerror(errno));
        p->mode = M_FFMPEG;
        int fds[2];
        if (pipe2(fds, O_CLOEXEC) != 0)
            return io_fail(err, IO_ERR_DEVICE, "%s: pipe: %s", cam->cfg.path, strerror(errno));
        char size[64];
        snprintf(size, sizeof size, "%dx%d", cam->width, cam->height);
        pid_t pid = fork();
        if (pid < 0) {
            close(fds[0]);
            close(fds[1]);
            return io_fail(err, IO_ERR_DEVICE, "%s: fork: %s", cam->cfg.path, strerror(errno));
        }
        if (pid == 0) {
            int nul = open("/dev/null", O_RDONLY);
            if (nul >= 0) dup2(nul, 0);
            dup2(fds[1], 1);
            if (p->o.loop)
                execlp("ffmpeg", "ffmpeg", "-nostdin", "-loglevel", "error", "-stream_loop", "-1",
                       "-i", p->src, "-f", "yuv4mpegpipe", "-pix_fmt", "yuv420p", "-s", size, "-",
                       (char *)NULL);
            else
                execlp("ffmpeg", "ffmpeg", "-nostdin", "-loglevel", "error", "-i", p->src, "-f",
                       "yuv4mpegpipe", "-pix_fmt", "yuv420p", "-s", size, "-", (char *)NULL);
            _exit(127);
        }
        close(fds[1]);
        p->pid = pid;
        p->vfd = fds[0];
        fcntl(p->vfd, F_SETFL, fcntl(p->vfd, F_GETFL) | O_NONBLOCK);
    }
    size_t n = (size_t)cam->width * (size_t)cam->height;
    p->hold = malloc(3 * n);
    p->rgba = malloc(4 * n);
    if (!p->hold || !p->rgba) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", cam->cfg.path);
    /* the first frame: checks format and size (ffmpeg may take a while) */
    int r = video_next(cam, p, 10000, err);
    if (r < 0) return err ? err->code : IO_ERR_FORMAT;
    if (r == 0) return io_fail(err, IO_ERR_FORMAT, "%s: the video has no frame", cam->cfg.path);
    if (r == 2) return io_fail(err, IO_ERR_DEVICE, "%s: no frame from ffmpeg within 10 s",
                               cam->cfg.path);
    return IO_OK;
}

static io_result file_open(io_cam *cam, io_error *err)
{
    fcam *p = calloc(1, sizeof *p);
    if (!p) return io_fail(err, IO_ERR_NOMEM, "%s: out of memory", cam->cfg.path);
    *(fcam **)cam->priv_store = p;
    cam->priv = cam->priv_store;
    p->vfd = p->tfd = -1;
    if (cam->cfg.backend_opts) p->o = *(const io_file_cam_opts *)cam->cfg.backend_opts;
    const char *src = cam->cfg.path;
    if (!strncmp(src, "file:", 5)) src += 5;
    if (!src[0]) return io_fail(err, IO_ERR_ARGS, "%s: no file named (file:PATTERN or file:VIDEO)",
                                cam->cfg.path);
    snprintf(p->src, sizeof p->src, "%s", src);
    if (cam->cfg.width == 0 && cam->cfg.height == 0) {
        cam->cfg.width = 640;
        cam->cfg.height = 480;
    }
    uint32_t want = cam->cfg.fourcc ? cam->cfg.fourcc : IO_FMT_RGB3;
    if (want != IO_FMT_RGB3 && want != IO_FMT_YUYV && want != IO_FMT_GREY) {
        char fs[5];
        return io_fail(err, IO_ERR_FORMAT, "%s: format %s not offered (the device offers: RGB3, "
                       "YUYV, GREY)", cam->cfg.path, io_fourcc_str(want, fs));
    }
    cam->fourcc = want;
    cam->width = cam->cfg.width;
    cam->height = cam->cfg.height;
    cam->stride = io_fmt_min_stride(want, cam->width);
    cam->image_bytes = cam->stride * (size_t)cam->height;
    int fps = cam->cfg.fps > 0 ? cam->cfg.fps : 30;
    cam->fps_num = 1;
    cam->fps_den = fps;
    p->period = 1000000000ull / (uint64_t)fps;
    snprintf(cam->driver, sizeof cam->driver, "file");
    snprintf(cam->card, sizeof cam->card, "recorded frames");
    snprintf(cam->bus_info, sizeof cam->bus_info, "file:%.50s", p->src);
    int pk = pattern_kind(p->src);
    io_result r;
    if (pk < 0)
        return io_fail(err, IO_ERR_ARGS, "%s: a frame pattern takes exactly one %%d or %%0Nd (and "
                       "%%%% for a percent sign)", cam->cfg.path);
    if (pk == 1) {
        p->mode = M_SEQ;
        r = open_seq(cam, p, err);
    } else {
        r = open_video(cam, p, err);
    }
    if (r != IO_OK) return r;
    for (int i = 0; i < cam->cfg.buffers; i++) {
        if (!(cam->buf[i] = malloc(cam->image_bytes)))
            return io_fail(err, IO_ERR_NOMEM, "%s: out of memory for buffer %d", cam->cfg.path, i);
        cam->buf_len[i] = cam->image_bytes;
        cam->nbuf = i + 1;
    }
    if (!p->o.clock_ns) {
        p->tfd = timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
        if (p->tfd < 0)
            return io_fail(err, IO_ERR_DEVICE, "%s: timerfd: %s", cam->cfg.path, strerror(errno));
        cam->fd = p->tfd;
    }
    return IO_OK;
}

static void arm_at(fcam *p, uint64_t t)
{
    if (p->tfd < 0) return;
    struct itimerspec it;
    memset(&it, 0, sizeof it);
    it.it_value.tv_sec = (time_t)(t / 1000000000ull);
    it.it_value.tv_nsec = (long)(t % 1000000000ull);
    if (!t) it.it_value.tv_nsec = 1;
    timerfd_settime(p->tfd, TFD_TIMER_ABSTIME, &it, NULL);
}

static void arm(fcam *p) { arm_at(p, p->t0 + p->next_k * p->period); }

static io_result file_start(io_cam *cam, io_error *err)
{
    fcam *p = fc_of(cam);
    (void)err;
    /* t0 from the caller's struct as it is now: it may be set between
     * opening both eyes and starting them */
    const io_file_cam_opts *live = (const io_file_cam_opts *)cam->cfg.backend_opts;
    uint64_t t0 = live ? live->t0_ns : 0;
    p->t0 = t0 ? t0 : now_of(p);
    p->next_k = 0;
    p->nq = 0;
    for (int i = 0; i < cam->nbuf; i++) {
        p->order[p->nq++] = i;
        cam->queued[i] = 1;
    }
    arm(p);
    return IO_OK;
}

static io_result file_queue(io_cam *cam, int index, io_error *err)
{
    fcam *p = fc_of(cam);
    if (p->nq >= IO_CAM_MAX_BUFFERS)
        return io_fail(err, IO_ERR_DEVICE, "%s: buffer %d queued twice", cam->cfg.path, index);
    p->order[p->nq++] = index;
    return IO_OK;
}

static io_result end_fail(io_cam *cam, fcam *p, io_error *err)
{
    p->ended = 1;
    return io_fail(err, IO_ERR_DEVICE, "%s: end of the recording after %llu frames (loop to play "
                   "it again)", cam->cfg.path, (unsigned long long)p->next_k);
}

static io_result file_dequeue(io_cam *cam, io_frame *f, int *got, uint32_t *flags, io_error *err)
{
    fcam *p = fc_of(cam);
    *got = 0;
    *flags = 0;
    if (p->tfd >= 0) {
        uint64_t x;
        if (read(p->tfd, &x, sizeof x) < 0) { /* not expired: fine */ }
    }
    if (p->ended) return end_fail(cam, p, err);
    uint64_t now = now_of(p);
    if (now < p->t0) return IO_OK;
    uint64_t due = (now - p->t0) / p->period;
    if (due < p->next_k) {
        arm(p);
        return IO_OK;
    }
    uint64_t k = due;
    const uint8_t *rgb = NULL;
    if (p->mode == M_SEQ) {
        if (!p->o.loop && k >= (uint64_t)p->count) {
            if (p->next_k >= (uint64_t)p->count) return end_fail(cam, p, err);
            k = (uint64_t)p->count - 1;
        }
    } else {
        /* read on until the newest frame due (or what has been decoded) */
        while (p->hold_k < k) {
            int r = video_next(cam, p, 0, err);
            if (r < 0) return IO_ERR_DEVICE;
            if (r != 1) break;
        }
        if (!p->have_hold || p->hold_k < p->next_k) {
            if (p->r.eof && !p->o.loop) return end_fail(cam, p, err);
            arm_at(p, now + 2000000ull); /* the decoder is behind: look again soon */
            return IO_OK;
        }
        k = p->hold_k;
        rgb = p->hold;
    }
    if (p->nq == 0) { /* no buffer queued: the frame is lost, as with a camera */
        p->next_k = k + 1;
        arm(p);
        return IO_OK;
    }
    int idx = p->order[0];
    memmove(p->order, p->order + 1, sizeof(int) * (size_t)(p->nq - 1));
    p->nq--;
    if (p->mode == M_SEQ) {
        int i = (int)(k % (uint64_t)p->count);
        if (p->cache) {
            rgb = p->cache[i];
        } else {
            /* decoded when due: into the frame buffer's space via scratch */
            if (!p->hold) p->hold = malloc(3 * (size_t)cam->width * (size_t)cam->height);
            io_result r = p->hold ? load_image(cam, p, p->first + i, p->hold, err)
                                  : io_fail(err, IO_ERR_NOMEM, "%s: out of memory", cam->cfg.path);
            if (r != IO_OK) {
                p->order[p->nq++] = idx;
                return IO_ERR_DEVICE;
            }
            rgb = p->hold;
        }
    }
    from_rgb(cam, rgb, cam->buf[idx]);
    f->index = idx;
    f->data = cam->buf[idx];
    f->bytes = cam->image_bytes;
    f->t_ns = p->t0 + k * p->period;
    f->sequence = (uint32_t)k;
    *got = 1;
    p->next_k = k + 1;
    arm(p);
    return IO_OK;
}

static int file_wait(io_cam *cam, int timeout_ms)
{
    fcam *p = fc_of(cam);
    if (p->ended) return -1;
    if (p->tfd < 0) return now_of(p) >= p->t0 + p->next_k * p->period;
    /* the timer is armed for the next frame (or a decoder that is behind) */
    struct pollfd pf = {p->tfd, POLLIN, 0};
    int r = poll(&pf, 1, timeout_ms > 0 ? timeout_ms : 0);
    return r > 0 ? 1 : r == 0 ? 0 : -1;
}

static io_result file_set_ctrl(io_cam *cam, io_cam_ctrl c, int value, io_error *err)
{
    (void)value;
    return io_fail(err, IO_ERR_VALUE, "%s: recorded frames have no %s control", cam->cfg.path,
                   io_cam_ctrl_name(c));
}

static io_result file_get_ctrl(io_cam *cam, io_cam_ctrl c, int *value, io_error *err)
{
    (void)value;
    return io_fail(err, IO_ERR_VALUE, "%s: recorded frames have no %s control", cam->cfg.path,
                   io_cam_ctrl_name(c));
}

static void file_stop(io_cam *cam)
{
    fcam *p = fc_of(cam);
    if (p) p->nq = 0;
}

static void file_close(io_cam *cam)
{
    for (int i = 0; i < cam->nbuf; i++) {
        free(cam->buf[i]);
        cam->buf[i] = NULL;
    }
    cam->nbuf = 0;
    cam->fd = -1;
    fcam *p = cam->priv ? fc_of(cam) : *(fcam **)cam->priv_store;
    if (!p) return;
    if (p->cache) {
        for (int i = 0; i < p->count; i++) free(p->cache[i]);
        free(p->cache);
    }
    if (p->pid > 0) { /* first, so that it does not report the closed pipe */
        kill(p->pid, SIGKILL);
        waitpid(p->pid, NULL, 0);
    }
    if (p->vfd >= 0) close(p->vfd);
    if (p->tfd >= 0) close(p->tfd);
    vs_free(&p->r);
    free(p->hold);
    free(p->rgba);
    free(p);
    *(fcam **)cam->priv_store = NULL;
    cam->priv = NULL;
}

const io_cam_backend io_cam_file = {
    "file",    file_open,     file_start,    file_dequeue, file_queue,
    file_wait, file_set_ctrl, file_get_ctrl, file_stop,    file_close,
};
