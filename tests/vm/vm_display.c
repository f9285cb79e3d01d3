/* vm_display.c - the KMS display output (src/io/io_display.h) inside the
 * test VM, against the kernel's bochs DRM driver on qemu's
 * -device bochs-display (tests/vm/guest.sh runs it). Prints "VMTEST name
 * PASS|FAIL detail" lines that tests/test_vm.c reads, and
 * "VMSYNC display-dump FILE" when the test image is on screen: the host
 * then saves qemu's screendump to FILE, compares it with the image
 * (tests/vm/display_pattern.h) and writes FILE.ack, which this program
 * waits for before it closes the display.
 *
 *   vm_display OUTDIR        bochs-display: one panel, side by side
 *   vm_display two OUTDIR    virtio-gpu with two outputs: one eye each
 *
 * A second descriptor on the card (master dropped) watches the CRTCs, so
 * the state after io_display_close is what the display restored, not the
 * kernel console's own restore on the last close. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <xf86drm.h>
#include <xf86drmMode.h>

#include "../../src/io/io_display.h"
#include "display_pattern.h"
#include "vm_check.h"

static volatile sig_atomic_t sigint_seen;
static void on_sigint(int sig)
{
    (void)sig;
    sigint_seen = 1;
}

/* ------------------------------------------------------- CRTC snapshots */

#define MAX_CRTC 8
typedef struct crtc_state {
    int n;
    uint32_t id[MAX_CRTC], fb[MAX_CRTC], x[MAX_CRTC], y[MAX_CRTC];
    int valid[MAX_CRTC];
    drmModeModeInfo mode[MAX_CRTC];
} crtc_state;

static void snapshot(int fd, crtc_state *s)
{
    memset(s, 0, sizeof *s);
    drmModeRes *res = drmModeGetResources(fd);
    if (!res) return;
    for (int i = 0; i < res->count_crtcs && s->n < MAX_CRTC; i++) {
        drmModeCrtc *c = drmModeGetCrtc(fd, res->crtcs[i]);
        if (!c) continue;
        int k = s->n++;
        s->id[k] = c->crtc_id;
        s->fb[k] = c->buffer_id;
        s->x[k] = c->x;
        s->y[k] = c->y;
        s->valid[k] = c->mode_valid;
        s->mode[k] = c->mode;
        drmModeFreeCrtc(c);
    }
    drmModeFreeResources(res);
}

static void describe(const crtc_state *s, char *out, size_t n)
{
    size_t len = 0;
    out[0] = '\0';
    for (int k = 0; k < s->n; k++) {
        int w = snprintf(out + len, n - len, "%scrtc %u: fb %u %s %dx%d@%u +%u+%u", k ? "; " : "", s->id[k],
                         s->fb[k], s->valid[k] ? "mode" : "off", s->mode[k].hdisplay, s->mode[k].vdisplay,
                         s->mode[k].vrefresh, s->x[k], s->y[k]);
        if (w < 0 || (size_t)w >= n - len) return;
        len += (size_t)w;
    }
}

static int same(const crtc_state *a, const crtc_state *b)
{
    if (a->n != b->n) return 0;
    for (int k = 0; k < a->n; k++) {
        if (a->id[k] != b->id[k] || a->fb[k] != b->fb[k] || a->x[k] != b->x[k] || a->y[k] != b->y[k] ||
            a->valid[k] != b->valid[k])
            return 0;
        if (a->valid[k] && memcmp(&a->mode[k], &b->mode[k], sizeof a->mode[k])) return 0;
    }
    return 1;
}

/* ---------------------------------------------------------------- frames */

static uint8_t eye[2][VMD_EYE_W * VMD_EYE_H * 4];

static void fill(int f)
{
    for (int e = 0; e < 2; e++)
        for (int y = 0; y < VMD_EYE_H; y++)
            for (int x = 0; x < VMD_EYE_W; x++) vmd_pixel(e, x, y, f, eye[e] + ((size_t)y * VMD_EYE_W + x) * 4);
}

static io_result present(io_display *d, int f, uint64_t id, io_error *err)
{
    fill(f);
    const uint8_t *rgba[2] = {eye[0], eye[1]};
    size_t stride[2] = {VMD_EYE_W * 4, VMD_EYE_W * 4};
    return io_display_present(d, rgba, stride, id, err);
}

/* Waits (bounded) for the next flip event. */
static int wait_flip(io_display *d, io_display_flip *ev, io_error *err)
{
    for (int i = 0; i < 50; i++) {
        int got = 0;
        if (io_display_poll(d, 100, ev, &got, err) != IO_OK) return -1;
        if (got) return 0;
    }
    snprintf(err->msg, sizeof err->msg, "no flip event in 50 polls of 100 ms");
    return -1;
}

/* io_display_open of spec with ew x eh eyes and 2 buffers into *d (err
 * cleared first). */
static io_result display_open(const char *spec, int ew, int eh, io_display **d, io_error *err)
{
    io_display_config c = {spec, ew, eh, 2};
    *d = NULL;
    memset(err, 0, sizeof *err);
    return io_display_open(d, &c, err);
}

/* display_open of spec at the eyes' size: the display; or NULL when it
 * failed, the check `name` failed with the reason and cfd closed. */
static io_display *open_checked(const char *spec, const char *name, int cfd, io_error *err)
{
    io_display *d;
    if (display_open(spec, VMD_EYE_W, VMD_EYE_H, &d, err) == IO_OK) return d;
    check(0, name, "%s", err->msg);
    close(cfd);
    return NULL;
}

/* The CRTCs of cfd as found, into before and printed after `what`: the
 * first opener became master and gives it up, the watcher only reads. */
static void watch_start(int cfd, crtc_state *before, const char *what)
{
    drmDropMaster(cfd);
    snapshot(cfd, before);
    char desc[1024];
    describe(before, desc, sizeof desc);
    printf("VMINFO %s: %s\n", what, desc);
}

static void expect_fail(const char *name, const char *spec, int ew, int eh, const char *want, const crtc_state *before,
                        int cfd)
{
    io_display *d;
    io_error err;
    int fds = count_fds();
    io_result r = display_open(spec, ew, eh, &d, &err);
    crtc_state after;
    snapshot(cfd, &after);
    int ok = r != IO_OK && d == NULL && strstr(err.msg, want) && count_fds() == fds && same(before, &after);
    check(ok, name, "%s (%dx%d eyes): %s%s", spec, ew, eh, err.msg,
          same(before, &after) ? "" : " [CRTC state changed]");
    if (d) io_display_close(&d);
}

/* The first card whose driver is `driver` ("" when none). */
static void find_card(const char *driver, char *out, size_t n)
{
    out[0] = '\0';
    for (int i = 0; i < 8 && !out[0]; i++) {
        char path[64];
        snprintf(path, sizeof path, "/dev/dri/card%d", i);
        int fd = open(path, O_RDWR | O_CLOEXEC);
        if (fd < 0) continue;
        drmVersion *v = drmGetVersion(fd);
        if (v && v->name && !strcmp(v->name, driver)) snprintf(out, n, "%s", path);
        if (v) drmFreeVersion(v);
        close(fd);
    }
}

static int wait_ack(const char *ack)
{
    for (int i = 0; i < 600; i++) {     /* the host answers in well under a minute */
        struct stat sb;
        if (stat(ack, &sb) == 0) return 1;
        struct timespec ts = {0, 100000000};
        nanosleep(&ts, NULL);
    }
    return 0;
}

/* Layout two on virtio-gpu with two outputs (the second forced on with
 * video=Virtual-3:e): one eye per connector, one event per frame when
 * both CRTCs have flipped; the host dumps both heads. */
static int cmd_two(const char *outdir)
{
    int fds0 = count_fds();
    char card[64], spec[128];
    find_card("virtio_gpu", card, sizeof card);
    if (!card[0]) {
        check(0, "display_two_open", "no virtio_gpu card (is virtio-gpu loaded, -device virtio-gpu-pci given?)");
        return 1;
    }
    int cfd = open(card, O_RDWR | O_CLOEXEC);
    crtc_state before, now;
    watch_start(cfd, &before, "display two before");
    snprintf(spec, sizeof spec, "kms:%s,layout=two", card);
    io_error err;
    io_display *d = open_checked(spec, "display_two_open", cfd, &err);
    if (!d) return 1;
    char desc[1024];
    snapshot(cfd, &now);
    describe(&now, desc, sizeof desc);
    check(1, "display_two_open", "%s; %s", io_display_describe(d), desc);
    /* the panel sizes, from the CRTCs the display set (in CRTC order) */
    int ok = 1;
    char why[512] = "";
    for (int f = 1; f <= 4 && ok; f++) {
        uint64_t t0 = io_now_ns();
        io_display_flip ev;
        int got = 0;
        if (present(d, f, 300 + (uint64_t)f, &err) != IO_OK || wait_flip(d, &ev, &err) != 0) {
            ok = 0;
            snprintf(why, sizeof why, "frame %d: %s", f, err.msg);
            break;
        }
        /* exactly one event per frame, after both CRTCs flipped */
        io_display_poll(d, 0, &ev, &got, &err);
        if (ev.frame_id != 300 + (uint64_t)f || ev.t_ns < t0 || got || io_display_busy(d)) {
            ok = 0;
            snprintf(why, sizeof why, "frame %d: event id %llu, extra event %d, busy %d", f,
                     (unsigned long long)ev.frame_id, got, io_display_busy(d));
        }
    }
    check(ok, "display_two_flip", "4 frames on two CRTCs, one event each%s%s", ok ? "" : ": ", why);
    io_display_flip ev;
    ok = present(d, 0, 999, &err) == IO_OK && wait_flip(d, &ev, &err) == 0 && ev.frame_id == 999;
    check(ok, "display_two_shown", "test image presented on both%s%s", ok ? "" : ": ", ok ? "" : err.msg);
    /* the mode of each connector's CRTC, for the host's comparison */
    snapshot(cfd, &now);
    printf("VMINFO display two modes");
    for (int k = 0; k < now.n; k++)
        if (now.valid[k]) printf(" %dx%d", now.mode[k].hdisplay, now.mode[k].vdisplay);
    printf("\n");
    char ppm[1024], ack[1100];
    snprintf(ppm, sizeof ppm, "%s/display_two", outdir);
    snprintf(ack, sizeof ack, "%s.ack", ppm);
    unlink(ack);
    printf("VMSYNC display-two-dump %s\n", ppm);
    fflush(stdout);
    int acked = wait_ack(ack);
    check(acked, "display_two_dump_ack", "%s", acked ? "the host took both screendumps" : "no answer from the host");
    io_display_close(&d);
    snapshot(cfd, &now);
    describe(&now, desc, sizeof desc);
    check(same(&before, &now), "display_two_restore", "after close: %s", desc);
    close(cfd);
    check(count_fds() == fds0, "display_two_no_fd_leak", "descriptors before %d, after %d", fds0, count_fds());
    return failures ? 1 : 0;
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 2 && !strcmp(argv[1], "two")) return cmd_two(argv[2]);
    const char *outdir = argc > 1 ? argv[1] : "/tmp";
    int fds0 = count_fds();
    char card[64];
    find_card("bochs-drm", card, sizeof card);
    if (!card[0]) snprintf(card, sizeof card, "/dev/dri/card0");
    int cfd = open(card, O_RDWR | O_CLOEXEC);
    if (cfd < 0) {
        check(0, "display_open", "%s: %s (is the bochs module loaded, -device bochs-display given?)", card,
              strerror(errno));
        return 1;
    }
    crtc_state before, now;
    watch_start(cfd, &before, "display before");

    /* refusals first: nothing may change on screen. The specs name the
     * card (virtio-gpu is another card in the same VM); the default
     * device is what "kms" with no card finds: card0 (bochs, loaded first) */
    char spec[256], want[256];
    snprintf(spec, sizeof spec, "kms:%s,connector=HDMI-A-7", card);
    snprintf(want, sizeof want, "%s: no connector 'HDMI-A-7' (connectors: Virtual-1 (id ", card);
    expect_fail("display_no_connector", spec, VMD_EYE_W, VMD_EYE_H, want, &before, cfd);
    snprintf(spec, sizeof spec, "kms:%s", card);
    snprintf(want, sizeof want, "%s: Virtual-1: no mode fits 10000x3000; modes: ", card);
    expect_fail("display_no_mode", spec, 5000, 3000, want, &before, cfd);
    snprintf(spec, sizeof spec, "kms:%s,mode=1234x567", card);
    expect_fail("display_no_mode", spec, VMD_EYE_W, VMD_EYE_H, "Virtual-1: no mode 1234x567; modes: ", &before, cfd);
    snprintf(spec, sizeof spec, "kms:%s,mode=640x480", card);
    expect_fail("display_no_mode", spec, VMD_EYE_W, VMD_EYE_H,
                "Virtual-1: mode 640x480 is smaller than the 1000x380 the eyes need", &before, cfd);
    expect_fail("display_missing", "kms:/dev/dri/card7", VMD_EYE_W, VMD_EYE_H, "/dev/dri/card7: no such device",
                &before, cfd);
    expect_fail("display_not_kms", "kms:/dev/zero", VMD_EYE_W, VMD_EYE_H, "/dev/zero: not a KMS display device",
                &before, cfd);

    /* open: the default card, connector, mode and layout */
    io_error err;
    io_display *d = open_checked("kms", "display_open", cfd, &err);
    if (!d) return 1;
    char desc[1024];
    int w, h;
    io_display_size(d, &w, &h);
    uint64_t period = io_display_refresh_ns(d);
    snapshot(cfd, &now);
    describe(&now, desc, sizeof desc);
    check(w >= 2 * VMD_EYE_W && h >= VMD_EYE_H && period > 0 && io_display_fd(d) >= 0 && !io_display_busy(d),
          "display_open", "%s, refresh %.3f ms; %s", io_display_describe(d), (double)period / 1e6, desc);
    printf("VMINFO display mode %dx%d\n", w, h);
    check(!strncmp(io_display_describe(d), "kms /dev/dri/card0 Virtual-1 ", 29) && !strcmp(card, "/dev/dri/card0"),
          "display_default", "kms -> %s (bochs is %s)", io_display_describe(d), card);
    snprintf(spec, sizeof spec, "kms:%s", card);
    io_display_config c = {spec, VMD_EYE_W, VMD_EYE_H, 2}; /* the card named */

    /* busy: a second open while the first holds master */
    {
        io_display *d2 = NULL;
        io_error e2;
        memset(&e2, 0, sizeof e2);
        int fds = count_fds();
        io_result r = io_display_open(&d2, &c, &e2);
        check(r == IO_ERR_DEVICE && !d2 && strstr(e2.msg, "/dev/dri/card0: another DRM master holds it (a desktop session?)") &&
                  count_fds() == fds,
              "display_busy", "%s", e2.msg);
        if (d2) io_display_close(&d2);
    }

    /* flips: each present comes back as one event with its id, a
     * monotonic time stamp between the present and now */
    {
        int ok = 1;
        char why[512] = "";
        uint64_t last_t = 0;
        double sum_ms = 0;
        for (int f = 1; f <= 6 && ok; f++) {
            uint64_t t0 = io_now_ns();
            if (present(d, f, 100 + (uint64_t)f, &err) != IO_OK) {
                ok = 0;
                snprintf(why, sizeof why, "present %d: %s", f, err.msg);
                break;
            }
            if (!io_display_busy(d)) {
                ok = 0;
                snprintf(why, sizeof why, "present %d: not busy after the page flip", f);
                break;
            }
            io_display_flip ev;
            if (wait_flip(d, &ev, &err) != 0) {
                ok = 0;
                snprintf(why, sizeof why, "frame %d: %s", f, err.msg);
                break;
            }
            uint64_t t1 = io_now_ns();
            if (ev.frame_id != 100 + (uint64_t)f || ev.t_ns < t0 || ev.t_ns > t1 || ev.t_ns <= last_t ||
                io_display_busy(d)) {
                ok = 0;
                snprintf(why, sizeof why, "frame %d: event id %llu t %llu (present at %llu, now %llu), busy %d", f,
                         (unsigned long long)ev.frame_id, (unsigned long long)ev.t_ns, (unsigned long long)t0,
                         (unsigned long long)t1, io_display_busy(d));
            }
            sum_ms += (double)(ev.t_ns - t0) / 1e6;
            last_t = ev.t_ns;
        }
        check(ok, "display_flip", "6 presents, 6 flip events with their frame ids and CLOCK_MONOTONIC time "
              "stamps, present to flip %.2f ms mean (qemu: commit completion, not a vblank)%s%s",
              sum_ms / 6, why[0] ? ": " : "", why);
    }

    /* two presents without reading events: the second waits for the
     * first flip; both events come, in order */
    {
        io_display_flip e1, e2;
        int ok = present(d, 7, 207, &err) == IO_OK && present(d, 8, 208, &err) == IO_OK &&
                 wait_flip(d, &e1, &err) == 0 && wait_flip(d, &e2, &err) == 0 && e1.frame_id == 207 &&
                 e2.frame_id == 208 && e2.t_ns > e1.t_ns;
        check(ok, "display_queue", "present while a flip is pending: events %llu, %llu in order%s%s",
              ok ? (unsigned long long)e1.frame_id : 0ull, ok ? (unsigned long long)e2.frame_id : 0ull,
              ok ? "" : ": ", ok ? "" : err.msg);
    }

    /* the known image, then the host's screendump */
    {
        io_display_flip ev;
        int ok = present(d, 0, 999, &err) == IO_OK && wait_flip(d, &ev, &err) == 0 && ev.frame_id == 999;
        check(ok, "display_shown", "test image presented and flipped%s%s", ok ? "" : ": ", ok ? "" : err.msg);
        char ppm[1024], ack[1100];
        snprintf(ppm, sizeof ppm, "%s/display.ppm", outdir);
        snprintf(ack, sizeof ack, "%s.ack", ppm);
        unlink(ppm);
        unlink(ack);
        printf("VMSYNC display-dump %s\n", ppm);
        fflush(stdout);
        int acked = 0;
        for (int i = 0; i < 600 && !acked; i++) {     /* the host answers in well under a minute */
            struct stat sb;
            acked = stat(ack, &sb) == 0;
            if (!acked) {
                struct timespec ts = {0, 100000000};
                nanosleep(&ts, NULL);
            }
        }
        check(acked, "display_dump_ack", "%s", acked ? "the host took the screendump" : "no answer from the host");
    }

    /* close: the CRTC state from before is back */
    io_display_close(&d);
    io_display_close(&d);
    snapshot(cfd, &now);
    describe(&now, desc, sizeof desc);
    check(same(&before, &now) && before.n > 0, "display_restore", "after close: %s", desc);

    /* and the device is free again */
    {
        io_display *d3 = NULL;
        int ok = io_display_open(&d3, &c, &err) == IO_OK;
        if (ok) {
            io_display_flip ev;
            ok = present(d3, 3, 3, &err) == IO_OK && wait_flip(d3, &ev, &err) == 0 && ev.frame_id == 3;
        }
        io_display_close(&d3);
        snapshot(cfd, &now);
        check(ok && same(&before, &now), "display_reopen", "open, present, close again%s%s", ok ? "" : ": ",
              ok ? "" : err.msg);
    }
    /* Ctrl-C as egofuse run handles it: the handler sets a flag, the
     * loop (blocked in io_display_poll) sees it and closes */
    {
        int ready[2];
        int ok = pipe(ready) == 0;
        pid_t pid = ok ? fork() : -1;
        if (pid == 0) {
            close(ready[0]);
            struct sigaction sa;
            memset(&sa, 0, sizeof sa);
            sa.sa_handler = on_sigint;
            sigaction(SIGINT, &sa, NULL);
            io_display *dc = NULL;
            if (io_display_open(&dc, &c, &err) != IO_OK) _exit(2);
            uint64_t frames = 0;
            while (!sigint_seen) {
                io_display_flip ev;
                int got;
                if (present(dc, (int)(frames % 7), frames, &err) != IO_OK) break;
                if (++frames == 3 && write(ready[1], "r", 1) != 1) break;
                io_display_poll(dc, -1, &ev, &got, &err);
            }
            io_display_close(&dc);
            _exit(sigint_seen ? 0 : 3);
        }
        char r = 0;
        int st = -1;
        if (pid > 0) {
            close(ready[1]);
            ok = read(ready[0], &r, 1) == 1;
            kill(pid, SIGINT);
            waitpid(pid, &st, 0);
            close(ready[0]);
        }
        snapshot(cfd, &now);
        describe(&now, desc, sizeof desc);
        check(ok && WIFEXITED(st) && WEXITSTATUS(st) == 0 && same(&before, &now), "display_sigint_restore",
              "SIGINT during the flip loop: exit %d, %s", WIFEXITED(st) ? WEXITSTATUS(st) : -1, desc);
    }
    close(cfd);

    /* killed without closing (SIGKILL, a crash): the kernel removes the
     * buffers on the descriptor's close and, on the card's last close, its
     * console takes the display back. Nothing else may hold the card. */
    {
        int ready[2];
        int ok = pipe(ready) == 0;
        pid_t pid = ok ? fork() : -1;
        if (pid == 0) {
            close(ready[0]);
            io_display *dk = NULL;
            if (io_display_open(&dk, &c, &err) != IO_OK) _exit(2);
            io_display_flip ev;
            present(dk, 5, 5, &err);
            wait_flip(dk, &ev, &err);
            if (write(ready[1], "r", 1) != 1) _exit(3);
            for (;;) pause();
        }
        char r = 0;
        if (pid > 0) {
            close(ready[1]);
            ok = read(ready[0], &r, 1) == 1;
            kill(pid, SIGKILL);
            waitpid(pid, NULL, 0);
            close(ready[0]);
        }
        cfd = open(card, O_RDWR | O_CLOEXEC);
        drmDropMaster(cfd);
        snapshot(cfd, &now);
        describe(&now, desc, sizeof desc);
        close(cfd);
        check(ok && same(&before, &now), "display_kill_restore", "after SIGKILL: %s", desc);
    }
    int fds1 = count_fds();
    check(fds1 == fds0, "display_no_fd_leak", "descriptors before %d, after %d", fds0, fds1);
    return failures ? 1 : 0;
}
