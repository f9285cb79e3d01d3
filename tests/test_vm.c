/* test_vm.c - the device tests against the real kernel drivers: boots
 * Debian's kernel under qemu (tests/vm/prepare.sh builds what it needs
 * under build/vm), runs tests/vm/guest.sh inside, drives USB hotplug from
 * the host over QMP (device_del / device_add) when the guest asks, and
 * turns the guest's VMTEST lines into test results. When qemu or the
 * kernel cannot be had, or EGOFUSE_VM=0, every test is SKIPPED with the
 * reason, never passed. The guest's output is kept in build/vm/last_run.log. */
#include "support/testutil.h"
#include <cmocka.h>

#include "../src/io/io.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define LOG_MAX (1 << 20)
#define VM_TIMEOUT_S 900

static char skip_reason[512];
static char *vm_log;      /* guest output */
static size_t vm_log_len;
static int vm_exit = -1;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One QMP command on a fresh connection (capabilities first). */
static int qmp(const char *sock, const char *cmd)
{
    int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0) return -1;
    struct sockaddr_un a;
    memset(&a, 0, sizeof a);
    a.sun_family = AF_UNIX;
    snprintf(a.sun_path, sizeof a.sun_path, "%s", sock);
    if (connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        close(fd);
        return -1;
    }
    char buf[4096];
    const char *caps = "{\"execute\":\"qmp_capabilities\"}\n";
    struct pollfd pf = {fd, POLLIN, 0};
    int ok = 0;
    if (poll(&pf, 1, 5000) > 0 && read(fd, buf, sizeof buf) > 0 &&    /* greeting */
        write(fd, caps, strlen(caps)) == (ssize_t)strlen(caps) && poll(&pf, 1, 5000) > 0 &&
        read(fd, buf, sizeof buf) > 0 && write(fd, cmd, strlen(cmd)) == (ssize_t)strlen(cmd) &&
        poll(&pf, 1, 5000) > 0) {
        ssize_t n = read(fd, buf, sizeof buf - 1);
        if (n > 0) {
            buf[n] = '\0';
            ok = strstr(buf, "\"return\"") != NULL;
            printf("NOTE qmp %.*s -> %.*s\n", (int)strcspn(cmd, "\n"), cmd, (int)strcspn(buf, "\n"), buf);
        }
    }
    close(fd);
    return ok ? 0 : -1;
}

static void log_append(const char *s, size_t n)
{
    if (vm_log_len + n >= LOG_MAX) n = LOG_MAX - 1 - vm_log_len;
    memcpy(vm_log + vm_log_len, s, n);
    vm_log_len += n;
    vm_log[vm_log_len] = '\0';
}

/* ---- display (KMS on -device bochs-display): the guest asks for a
 * screendump of what is on screen, the host takes it and answers with
 * FILE.ack; test_vm_display compares FILE with the expected image. */
#include "vm/display_pattern.h"
/* The guest's "VMSYNC ...-dump PATH": qemu's screendump of a device (and
 * head, -1 for none) to PATH (heads: PATH.N.ppm), then PATH.ack with the
 * result, which the guest waits for. The path is kept in *keep, the result
 * in *rc. */
static void screendump_ack(const char *path, const char *device, int heads, char *keep,
                           size_t keep_n, int *rc, const char *qmp_sock)
{
    char cmd[1400], ack[1100];
    snprintf(keep, keep_n, "%.*s", (int)strcspn(path, " \r\n"), path);
    *rc = 0;
    for (int head = 0; head < (heads > 0 ? heads : 1); head++) {
        if (heads > 0)
            snprintf(cmd, sizeof cmd, "{\"execute\":\"screendump\",\"arguments\":{\"filename\":"
                     "\"%s.%d.ppm\",\"device\":\"%s\",\"head\":%d}}\n", keep, head, device, head);
        else
            snprintf(cmd, sizeof cmd, "{\"execute\":\"screendump\",\"arguments\":{\"filename\":"
                     "\"%s\",\"device\":\"%s\"}}\n", keep, device);
        if (qmp(qmp_sock, cmd) != 0) *rc = -1;
    }
    snprintf(ack, sizeof ack, "%s.ack", keep);
    FILE *f = fopen(ack, "w");
    if (f) {
        fprintf(f, "%d\n", *rc);
        fclose(f);
    }
}

static char display_dump[1024];  /* bochs-display, side by side */
static int display_dump_rc = -1;
static char display_two[1024];   /* virtio-gpu, heads 0 and 1: PREFIX.0.ppm, PREFIX.1.ppm */
static int display_two_rc = -1;
/* ---- end display */

/* ---- cockpit: `egofuse run` on the KMS display holds its last frame;
 * the host takes its screendump (test_vm_cockpit compares it with
 * `egofuse render` of the inputs run dumped). */
static char cockpit_dump[1024];
static int cockpit_dump_rc = -1;

static void on_line(const char *line, const char *qmp_sock)
{
    if (!strncmp(line, "VMSYNC display-dump ", 20))
        screendump_ack(line + 20, "display0", 0, display_dump, sizeof display_dump,
                       &display_dump_rc, qmp_sock);
    if (!strncmp(line, "VMSYNC cockpit-dump ", 20))
        screendump_ack(line + 20, "display0", 0, cockpit_dump, sizeof cockpit_dump,
                       &cockpit_dump_rc, qmp_sock);
    if (!strncmp(line, "VMSYNC display-two-dump ", 24))
        screendump_ack(line + 24, "vgpu", 2, display_two, sizeof display_two, &display_two_rc,
                       qmp_sock);
    if (!strncmp(line, "VMSYNC usb-unplug", 17))
        qmp(qmp_sock, "{\"execute\":\"device_del\",\"arguments\":{\"id\":\"camr\"}}\n");
    else if (!strncmp(line, "VMSYNC usb-replug", 17))
        qmp(qmp_sock, "{\"execute\":\"device_add\",\"arguments\":{\"driver\":\"usb-kbd\","
                      "\"id\":\"camr\",\"bus\":\"xhci.0\",\"port\":\"3\",\"serial\":\"CAM-R-0002\"}}\n");
}

static int boot_vm(void)
{
    char root[1024], build[1100], vm[1200], out[1300], cmd[4096], sock[256], logp[1300];
    char rel[1024];
    tu_root_path(".", rel, sizeof rel);
    if (!realpath(rel, root)) fail_msg("%s: %s", rel, strerror(errno));
    const char *b = getenv("EGOFUSE_BUILD") ? getenv("EGOFUSE_BUILD") : "build";
    snprintf(build, sizeof build, "%s/%s", root, b);
    snprintf(vm, sizeof vm, "%s/vm", build);
    snprintf(out, sizeof out, "%s/out", vm);
    const char *env = getenv("EGOFUSE_VM");
    if (env && !strcmp(env, "0")) {
        snprintf(skip_reason, sizeof skip_reason, "EGOFUSE_VM=0: the VM tests are switched off");
        return -1;
    }
    /* prepare: kernel, initramfs, guest program */
    snprintf(cmd, sizeof cmd, "%s/tests/vm/prepare.sh", root);
    char *argv_p[] = {"/bin/sh", cmd, (char *)b, NULL};
    static char pout[65536];
    int rc = tu_run(argv_p, pout, sizeof pout);
    if (rc == 3) {
        char *s = strstr(pout, "SKIP: ");
        snprintf(skip_reason, sizeof skip_reason, "%.*s", (int)strcspn(s ? s + 6 : pout, "\n"),
                 s ? s + 6 : pout);
        return -1;
    }
    if (rc != 0) {
        printf("%s", pout);
        fail_msg("tests/vm/prepare.sh failed (exit %d)", rc);
    }
    mkdir(out, 0755);
    snprintf(sock, sizeof sock, "/tmp/egofuse-qmp.%d", (int)getpid());
    unlink(sock);

    /* KVM where it is a real one, TCG otherwise (a paravirtual kvm_pvm
     * cannot boot a stock kernel). */
    int kvm = access("/sys/module/kvm_pvm", F_OK) != 0 && access("/dev/kvm", R_OK | W_OK) == 0;
    char kernel[1300], initrd[1300], append[3000], fs_root[160], fs_repo[1400], fs_out[1400],
        qmp_arg[300];
    snprintf(kernel, sizeof kernel, "%s/vmlinux", vm);
    snprintf(initrd, sizeof initrd, "%s/initramfs.cpio.gz", vm);
    /* the egofuse binary to run inside (run_tests.sh exports EGOFUSE_BIN) */
    const char *bin = getenv("EGOFUSE_BIN");
    char binarg[600] = "";
    if (bin && bin[0] == '/' && !strchr(bin, ' ')) snprintf(binarg, sizeof binarg, " egofuse.bin=%.500s", bin);
    /* video=Virtual-3:e: virtio-gpu's second output counts as connected
     * (qemu enables only the first without a UI); connector names count
     * across cards: bochs's is Virtual-1, virtio-gpu's Virtual-2 and -3;
     * vt.global_cursor_default=0: no blinking cursor redrawn on the
     * consoles' framebuffers all along */
    snprintf(append, sizeof append, "console=ttyS0 quiet panic=-1 video=Virtual-3:e vt.global_cursor_default=0 "
             "egofuse.out=%s egofuse.root=%s%s",
             out, root, binarg);
    snprintf(fs_root, sizeof fs_root, "local,path=/,mount_tag=hostroot,security_model=none,"
             "readonly=on,multidevs=remap");
    snprintf(fs_repo, sizeof fs_repo, "local,path=%s,mount_tag=repo,security_model=none,"
             "readonly=on,multidevs=remap", root);
    snprintf(fs_out, sizeof fs_out, "local,path=%s,mount_tag=out,security_model=none,"
             "multidevs=remap", out);
    snprintf(qmp_arg, sizeof qmp_arg, "unix:%s,server=on,wait=off", sock);
    char *qa[] = {"qemu-system-x86_64", "-accel", kvm ? "kvm" : "tcg", "-cpu", kvm ? "host" : "max",
                  "-m", "1024", "-smp", "2", "-kernel", kernel, "-initrd", initrd,
                  "-append", append, "-virtfs", fs_root, "-virtfs", fs_repo, "-virtfs", fs_out,
                  "-device", "qemu-xhci,id=xhci",
                  "-device", "usb-hub,bus=xhci.0,port=1,id=hub",
                  "-device", "usb-tablet,bus=xhci.0,port=1.2,serial=CAM-L-0001,id=caml",
                  "-device", "usb-kbd,bus=xhci.0,port=2,serial=CAM-R-0002,id=camr",
                  "-device", "isa-debug-exit,iobase=0xf4,iosize=0x04",
                  "-vga", "none", "-device",
                  /* 2560x800 preferred: the cockpit step shows two 1280x800 eyes side by side */
                  "bochs-display,id=display0,xres=2560,yres=800,xmax=2560,ymax=1600,vgamem=67108864",
                  "-device", "virtio-gpu-pci,max_outputs=2,id=vgpu",
                  "-qmp", qmp_arg, "-serial", "stdio", "-display", "none", "-monitor", "none",
                  "-no-reboot", NULL};
    int pfd[2];
    if (pipe(pfd) != 0) fail_msg("pipe: %s", strerror(errno));
    double t0 = now_s();
    pid_t pid = fork();
    if (pid == 0) {
        int devnull = open("/dev/null", O_RDONLY);
        dup2(devnull, 0);
        dup2(pfd[1], 1);
        dup2(pfd[1], 2);
        close(pfd[0]);
        execvp(qa[0], qa);
        _exit(127);
    }
    close(pfd[1]);
    char line[4096];
    size_t ll = 0;
    int timed_out = 0;
    for (;;) {
        struct pollfd pf = {pfd[0], POLLIN, 0};
        int left_ms = (int)((VM_TIMEOUT_S - (now_s() - t0)) * 1000);
        if (left_ms <= 0) {
            timed_out = 1;
            break;
        }
        if (poll(&pf, 1, left_ms) <= 0) continue;
        char buf[4096];
        ssize_t n = read(pfd[0], buf, sizeof buf);
        if (n <= 0) break;
        log_append(buf, (size_t)n);
        for (ssize_t i = 0; i < n; i++) {
            if (buf[i] == '\n' || ll == sizeof line - 1) {
                line[ll] = '\0';
                if (ll && line[ll - 1] == '\r') line[ll - 1] = '\0';
                on_line(line, sock);
                ll = 0;
            } else {
                line[ll++] = buf[i];
            }
        }
    }
    close(pfd[0]);
    if (timed_out) kill(pid, SIGKILL);
    int st = 0;
    waitpid(pid, &st, 0);
    unlink(sock);
    double dt = now_s() - t0;
    snprintf(logp, sizeof logp, "%s/last_run.log", vm);
    FILE *fp = fopen(logp, "w");
    if (fp) {
        fwrite(vm_log, 1, vm_log_len, fp);
        fclose(fp);
    }
    if (WIFEXITED(st) && WEXITSTATUS(st) == 127 && !strstr(vm_log, "VMSYNC booted")) {
        snprintf(skip_reason, sizeof skip_reason, "qemu-system-x86_64 could not start");
        return -1;
    }
    if (!strstr(vm_log, "VMSYNC booted")) {
        snprintf(skip_reason, sizeof skip_reason, "the VM did not boot (%s, %.0f s; see %.200s)",
                 kvm ? "kvm" : "tcg", dt, logp);
        return -1;
    }
    /* isa-debug-exit: status (rc << 1) | 1 */
    vm_exit = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    printf("NOTE VM run: %s, %.1f s, qemu exit %d%s (log %s)\n", kvm ? "kvm" : "tcg", dt, vm_exit,
           timed_out ? ", TIMED OUT" : "", logp);
    const char *m = vm_log;
    while ((m = strstr(m, "VMMEASURE ")) != NULL) {
        printf("NOTE %.*s\n", (int)strcspn(m, "\r\n"), m);
        m += 10;
    }
    return 0;
}

static int setup(void **st)
{
    (void)st;
    vm_log = calloc(1, LOG_MAX);
    if (!vm_log) return -1;
    if (boot_vm() != 0) printf("SKIP: %s\n", skip_reason);
    return 0;
}

static int teardown(void **st)
{
    (void)st;
    free(vm_log);
    return 0;
}

/* Every named check must be there and PASS; prints the details. */
static void expect(const char *const *names, int n)
{
    if (skip_reason[0]) skip();
    int bad = 0;
    for (int i = 0; i < n; i++) {
        char key[128];
        snprintf(key, sizeof key, "VMTEST %s ", names[i]);
        const char *p = vm_log;
        int seen = 0;
        while ((p = strstr(p, key)) != NULL) {
            seen++;
            int len = (int)strcspn(p, "\r\n");
            printf("    %.*s\n", len, p);
            if (strncmp(p + strlen(key), "PASS", 4)) bad++;
            p += len;
        }
        if (!seen) {
            printf("    %s: missing from the guest's output\n", names[i]);
            bad++;
        }
    }
    assert_int_equal(bad, 0);
}

static void test_vm_capture(void **st)
{
    (void)st;
    static const char *const names[] = {
        "capture_format", "capture_webcam", "capture_busy", "capture_ctrl_brightness",
        "capture_ctrl_gain", "capture_ctrl_wb", "capture_reopen", "capture_hdmi60",
        "capture_bad_format", "capture_missing", "capture_no_fd_leak"};
    expect(names, (int)(sizeof names / sizeof names[0]));
}

static void test_vm_usb(void **st)
{
    (void)st;
    static const char *const names[] = {"usb_list", "usb_assign", "usb_assign_port",
                                        "usb_hotplug", "usb_assign_missing"};
    expect(names, (int)(sizeof names / sizeof names[0]));
}

static void test_vm_glove(void **st)
{
    (void)st;
    static const char *const names[] = {"glove_open", "glove_values", "glove_short_report"};
    expect(names, (int)(sizeof names / sizeof names[0]));
}

static void test_vm_run(void **st)
{
    (void)st;
    static const char *const names[] = {"run_pipeline"};
    expect(names, 1);
}

/* Reads a binary PPM (P6, maxval 255); NULL with *w = 0 on failure. */
static uint8_t *read_ppm(const char *path, int *w, int *h)
{
    *w = *h = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    int pw = 0, ph = 0, maxv = 0;
    uint8_t *px = NULL;
    if (fscanf(f, "P6 %d %d %d", &pw, &ph, &maxv) == 3 && maxv == 255 && pw > 0 && ph > 0 && fgetc(f) != EOF) {
        size_t bytes = (size_t)pw * (size_t)ph * 3;
        px = malloc(bytes);
        if (px && fread(px, 1, bytes, f) != bytes) {
            free(px);
            px = NULL;
        }
    }
    fclose(f);
    if (px) {
        *w = pw;
        *h = ph;
    }
    return px;
}

/* Bytes of got that differ from want (both w x h RGB), with the first. */
static size_t compare_rgb(const uint8_t *got, const uint8_t *want, int w, int h, const char *what)
{
    size_t bytes = (size_t)w * (size_t)h * 3, bad = 0, first = 0;
    for (size_t i = 0; i < bytes; i++)
        if (got[i] != want[i] && !bad++) first = i;
    if (bad)
        printf("    %s: %zu of %zu bytes differ; first at pixel (%zu, %zu): got %u, want %u\n", what, bad, bytes,
               (first / 3) % (size_t)w, (first / 3) / (size_t)w, got[first], want[first]);
    else
        printf("    %s = expected image, all %zu bytes\n", what, bytes);
    return bad;
}

/* ---- display, layout two: virtio-gpu's two heads, one eye each */
static void test_vm_display_two(void **st)
{
    (void)st;
    static const char *const names[] = {"display_two_open", "display_two_flip", "display_two_shown",
                                        "display_two_dump_ack", "display_two_restore", "display_two_no_fd_leak"};
    expect(names, (int)(sizeof names / sizeof names[0]));
    const char *m = strstr(vm_log, "VMINFO display two modes ");
    int w[2] = {0, 0}, h[2] = {0, 0};
    if (!m || sscanf(m + 25, "%dx%d %dx%d", &w[0], &h[0], &w[1], &h[1]) != 4)
        fail_msg("the guest did not print the two modes");
    assert_int_equal(display_two_rc, 0);
    size_t bad = 0;
    for (int e = 0; e < 2; e++) {
        char path[1100], what[64];
        snprintf(path, sizeof path, "%s.%d.ppm", display_two, e);
        int pw, ph;
        uint8_t *got = read_ppm(path, &pw, &ph);
        printf("    head %d: %s %dx%d, the mode %dx%d\n", e, path, pw, ph, w[e], h[e]);
        if (!got || pw != w[e] || ph != h[e]) {
            free(got);
            fail_msg("%s: not a %dx%d PPM", path, w[e], h[e]);
        }
        uint8_t *want = malloc((size_t)pw * (size_t)ph * 3);
        assert_non_null(want);
        vmd_expected_eye(pw, ph, e, 0, want);
        snprintf(what, sizeof what, "head %d (%s eye)", e, e ? "right" : "left");
        bad += compare_rgb(got, want, pw, ph, what);
        free(got);
        free(want);
    }
    assert_int_equal(bad, 0);
}

/* ---- display: the guest's checks, then qemu's screendump of the
 * bochs-display compared exactly with the test image as io_display lays
 * it out (each eye centred in its half of the mode, black around). */
static void test_vm_display(void **st)
{
    (void)st;
    static const char *const names[] = {"display_no_connector", "display_no_mode", "display_missing",
                                        "display_not_kms", "display_open", "display_busy", "display_flip",
                                        "display_queue", "display_shown", "display_dump_ack", "display_default",
                                        "display_restore", "display_reopen", "display_sigint_restore",
                                        "display_kill_restore", "display_no_fd_leak"};
    expect(names, (int)(sizeof names / sizeof names[0]));
    const char *m = strstr(vm_log, "VMINFO display mode ");
    int w = 0, h = 0;
    if (!m || sscanf(m + 20, "%dx%d", &w, &h) != 2) fail_msg("the guest did not print its display mode");
    assert_int_equal(display_dump_rc, 0);
    FILE *f = fopen(display_dump, "rb");
    if (!f) fail_msg("%s: %s", display_dump, strerror(errno));
    int pw = 0, ph = 0, maxv = 0;
    int n = fscanf(f, "P6 %d %d %d", &pw, &ph, &maxv);
    fgetc(f);
    size_t bytes = (size_t)pw * (size_t)ph * 3;
    uint8_t *got = n == 3 && pw > 0 && ph > 0 ? malloc(bytes) : NULL;
    uint8_t *want = malloc((size_t)w * (size_t)h * 3);
    size_t rd = got ? fread(got, 1, bytes, f) : 0;
    fclose(f);
    printf("    screendump %s: %dx%d (max %d), the mode %dx%d\n", display_dump, pw, ph, maxv, w, h);
    assert_non_null(want);
    assert_int_equal(n, 3);
    assert_int_equal(pw, w);
    assert_int_equal(ph, h);
    assert_int_equal(maxv, 255);
    assert_true(rd == bytes);
    vmd_expected(w, h, 0, want);
    size_t bad = 0, first = (size_t)-1;
    for (size_t i = 0; i < bytes; i++)
        if (got[i] != want[i]) {
            if (first == (size_t)-1) first = i;
            bad++;
        }
    if (bad)
        printf("    %zu of %zu bytes differ; first at pixel (%zu, %zu): got %u, want %u\n", bad, bytes,
               (first / 3) % (size_t)w, (first / 3) / (size_t)w, got[first], want[first]);
    else
        printf("    screendump = expected image, all %zu bytes\n", bytes);
    free(got);
    free(want);
    assert_int_equal(bad, 0);
}
/* ---- end display */

/* The live cockpit in the VM: what the KMS display showed (qemu's
 * screendump of the held last frame) is byte for byte what `egofuse
 * render` composites from the inputs that `run --dump` wrote for that
 * frame: the camera pair, the V pair from vivid, the NatNet pose. */
static void test_vm_cockpit(void **st)
{
    (void)st;
    static const char *const names[] = {"cockpit_dump_ack", "cockpit_kms", "cockpit_sources_end"};
    expect(names, (int)(sizeof names / sizeof names[0]));
    assert_int_equal(cockpit_dump_rc, 0);
    char dir[1100], scene[1200], out[1200];
    snprintf(dir, sizeof dir, "%.*s", (int)(strrchr(cockpit_dump, '/') - cockpit_dump), cockpit_dump);
    snprintf(scene, sizeof scene, "%s/dump/scene.txt", dir);
    snprintf(out, sizeof out, "%s/render", dir);
    const char *bin = getenv("EGOFUSE_BIN") ? getenv("EGOFUSE_BIN") : "build/egofuse";
    char *argv[] = {(char *)bin, "render", "--scene", scene, "--out", out, "--pose", "tracking",
                    "--no-filter", NULL};
    static char rout[65536];
    int rc = tu_run(argv, rout, sizeof rout);
    if (rc != 0) fail_msg("egofuse render of the dump: exit %d: %s", rc, rout);
    int pw = 0, ph = 0;
    uint8_t *got = read_ppm(cockpit_dump, &pw, &ph);
    if (!got) fail_msg("%s: not a P6 PPM", cockpit_dump);
    printf("    screendump %s: %dx%d\n", cockpit_dump, pw, ph);
    assert_true(pw >= 2 * 1280 && ph >= 800);
    size_t bad = 0, total = 0;
    for (int e = 0; e < 2; e++) {
        char png[1300];
        snprintf(png, sizeof png, "%s/%s_0000.png", out, e ? "right" : "left");
        io_image im;
        io_error err;
        if (io_image_load(png, IO_U8, 3, &im, &err) != IO_OK) fail_msg("%s", err.msg);
        assert_int_equal(im.width, 1280);
        assert_int_equal(im.height, 800);
        /* each eye centred in its half of the mode (io_display's rule) */
        int half = pw / 2, x0 = e * half + (half - 1280) / 2, y0 = (ph - 800) / 2;
        size_t first = (size_t)-1;
        for (int y = 0; y < 800; y++)
            for (int x = 0; x < 1280 * 3; x++) {
                uint8_t a = got[((size_t)(y0 + y) * (size_t)pw + (size_t)x0) * 3 + (size_t)x];
                uint8_t b = ((const uint8_t *)im.data)[(size_t)y * im.stride + (size_t)x];
                total++;
                if (a != b && !bad++) first = (size_t)y * 1280 * 3 + (size_t)x;
            }
        if (first != (size_t)-1)
            printf("    %s eye: first difference at (%zu, %zu)\n", e ? "right" : "left",
                   (first / 3) % 1280, first / 3840);
        io_image_free(&im);
    }
    free(got);
    printf("    %zu of %zu bytes differ between the display and egofuse render of the dump\n", bad,
           total);
    assert_int_equal(bad, 0);
}

static void test_vm_vsrc(void **st)
{
    (void)st;
    static const char *const names[] = {"vsrc_format", "vsrc_sbs", "vsrc_unplug",
                                        "vsrc_no_fd_leak"};
    expect(names, (int)(sizeof names / sizeof names[0]));
}

static void test_vm_all_passed(void **st)
{
    (void)st;
    if (skip_reason[0]) skip();
    /* no FAIL line anywhere, and the guest script reported success */
    const char *f = strstr(vm_log, " FAIL ");
    if (f) {
        const char *s = f;
        while (s > vm_log && s[-1] != '\n') s--;
        printf("    %.*s\n", (int)strcspn(s, "\r\n"), s);
    }
    assert_null(f);
    assert_non_null(strstr(vm_log, "VMDONE 0"));
    assert_int_equal(vm_exit, 1); /* (0 << 1) | 1 */
}

TU_MAIN(setup, teardown,
        cmocka_unit_test(test_vm_capture),
        cmocka_unit_test(test_vm_usb),
        cmocka_unit_test(test_vm_glove),
        cmocka_unit_test(test_vm_run),
        cmocka_unit_test(test_vm_display),
        cmocka_unit_test(test_vm_display_two),
        cmocka_unit_test(test_vm_vsrc),
        cmocka_unit_test(test_vm_cockpit),
        cmocka_unit_test(test_vm_all_passed))
