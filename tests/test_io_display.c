/* test_io_display.c - display outputs (src/io/io_display.h) on the host:
 * the spec parser, the KMS backend's refusals where this machine has no
 * display (no /dev/dri, a file that is not a KMS device), and the SDL2
 * window under a real X server (Xvfb): a known pattern is presented, the
 * screen is read back with xwd (X Window Dump, parsed here from the
 * format's published layout, XWDFile.h) and compared exactly. The KMS
 * backend itself is tested against the kernel's bochs driver in the VM
 * (tests/vm/vm_display.c, driven by tests/test_vm.c). Skips with the
 * reason when Xvfb, xwd or libSDL2 is missing. */
#include "support/testutil.h"
#include <cmocka.h>

#include <dirent.h>
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <SDL.h>

#include "../src/io/io_display.h"
#include "../src/io/io_display_impl.h"

/* ------------------------------------------------------------- parser */

static void test_parse(void **st)
{
    (void)st;
    io_display_spec s;
    io_error err;
    assert_int_equal(io_display_parse("kms", &s, &err), IO_OK);
    assert_int_equal(s.kind, IO_DISPLAY_KMS);
    assert_string_equal(s.device, "");
    assert_int_equal(s.layout, IO_LAYOUT_AUTO);
    assert_int_equal(io_display_parse("kms:/dev/dri/card1,connector=HDMI-A-1+DP-2,mode=1280x800@90",
                                      &s, &err), IO_OK);
    assert_string_equal(s.device, "/dev/dri/card1");
    assert_int_equal(s.nconnectors, 2);
    assert_string_equal(s.connector[0], "HDMI-A-1");
    assert_string_equal(s.connector[1], "DP-2");
    assert_int_equal(s.layout, IO_LAYOUT_TWO);
    assert_int_equal(s.mode_w, 1280);
    assert_int_equal(s.mode_h, 800);
    assert_int_equal(s.mode_hz, 90);
    assert_int_equal(io_display_parse("kms,connector=37,layout=sbs,buffers=3", &s, &err), IO_OK);
    assert_int_equal(s.nconnectors, 1);
    assert_int_equal(s.layout, IO_LAYOUT_SBS);
    assert_int_equal(s.buffers, 3);
    assert_int_equal(io_display_parse("sdl", &s, &err), IO_OK);
    assert_int_equal(s.kind, IO_DISPLAY_SDL);
    assert_int_equal(s.win_w, 0);
    assert_int_equal(io_display_parse("sdl:1280x400", &s, &err), IO_OK);
    assert_int_equal(s.win_w, 1280);
    assert_int_equal(s.win_h, 400);

    static const struct { const char *spec, *msg; } bad[] = {
        {"", "no display given"},
        {"hdmi", "unknown kind 'hdmi'"},
        {"kms:", "the device after 'kms:' is empty"},
        {"kms,mode=1280", "mode '1280' is not WxH"},
        {"kms,mode=1280x800@", "mode '1280x800@' is not WxH"},
        {"kms,mode=0x800", "is not WxH"},
        {"kms,layout=stacked", "layout 'stacked' is not sbs or two"},
        {"kms,connector=", "option 'connector' has no value"},
        {"kms,connector", "option 'connector' is not key=value"},
        {"kms,connector=A+", "connector '' is not NAME"},
        {"kms,connector=A+B+C", "connector 'B+C' is not NAME"},
        {"kms,layout=two,connector=A", "layout=two needs two connectors"},
        {"kms,layout=sbs,connector=A+B", "layout=sbs takes one connector"},
        {"kms,colour=red", "unknown option 'colour'"},
        {"kms,buffers=5", "buffers '5' is not 2 or 3"},
        {"sdl:big", "window size 'big' is not WxH"},
        {"sdl,mode=1x1", "sdl takes no options"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        memset(&err, 0, sizeof err);
        io_result r = io_display_parse(bad[i].spec, &s, &err);
        if (r != IO_ERR_ARGS || !strstr(err.msg, bad[i].msg))
            fail_msg("'%s': got %d '%s', wanted '%s'", bad[i].spec, r, err.msg, bad[i].msg);
    }
}

/* ------------------------------------------------ the KMS conversion */

/* io_display_blit_xrgb (SSE2 groups of 4 and a scalar tail) against the
 * definition of XRGB8888: a little-endian word 0x00RRGGBB. Pixels around
 * the target rectangle stay untouched. */
static void test_blit(void **st)
{
    (void)st;
    tu_rng rng = {7};
    enum { DW = 40, DH = 9 };
    static uint8_t src[13 * 4 * 8], dst[DW * 4 * DH];
    for (int w = 1; w <= 13; w++)
        for (int x0 = 0; x0 < 3; x0++) {
            int h = 1 + w % 7;
            for (size_t i = 0; i < sizeof src; i++) src[i] = (uint8_t)tu_next(&rng);
            memset(dst, 0xa5, sizeof dst);
            io_display_blit_xrgb(dst, DW * 4, x0 + 5, 1, src, (size_t)w * 4 + 4, w, h);
            for (int y = 0; y < DH; y++)
                for (int x = 0; x < DW; x++) {
                    const uint8_t *o = dst + ((size_t)y * DW + x) * 4;
                    uint32_t got = (uint32_t)o[0] | (uint32_t)o[1] << 8 | (uint32_t)o[2] << 16 | (uint32_t)o[3] << 24;
                    uint32_t want = 0xa5a5a5a5u;
                    int sx = x - x0 - 5, sy = y - 1;
                    if (sx >= 0 && sx < w && sy >= 0 && sy < h) {
                        const uint8_t *p = src + (size_t)sy * ((size_t)w * 4 + 4) + (size_t)sx * 4;
                        want = (uint32_t)p[0] << 16 | (uint32_t)p[1] << 8 | p[2];
                    }
                    if (got != want) fail_msg("w %d x0 %d at (%d, %d): 0x%08x, want 0x%08x", w, x0, x, y, got, want);
                }
        }
}

/* ---------------------------------------------------------- KMS refusals */

static void expect_open_fails(const char *spec, const char *msg)
{
    io_display_config c = {spec, 64, 48, 2};
    io_display *d = (io_display *)1;
    io_error err;
    memset(&err, 0, sizeof err);
    int fds = tu_count_fds();
    io_result r = io_display_open(&d, &c, &err);
    printf("NOTE %s -> %s\n", spec, err.msg);
    assert_int_not_equal(r, IO_OK);
    assert_null(d);
    if (!strstr(err.msg, msg)) fail_msg("'%s': '%s' lacks '%s'", spec, err.msg, msg);
    assert_int_equal(tu_count_fds(), fds);
}

static void test_kms_refusals(void **st)
{
    (void)st;
    expect_open_fails("kms:/dev/null", "/dev/null: not a KMS display device");
    expect_open_fails("kms:/nonexistent/card0", "/nonexistent/card0: no such device");
    struct stat sb;
    if (stat("/dev/dri", &sb) != 0)
        expect_open_fails("kms", "kms: no /dev/dri/card*");
    else
        printf("NOTE this machine has /dev/dri: the no-device message is checked in the VM only\n");
    io_display_config c = {"kms", 0, 48, 2};
    io_display *d;
    io_error err;
    assert_int_equal(io_display_open(&d, &c, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "eye size 0x48 is not valid"));
    io_display_config c2 = {"kms:/dev/null", 64, 48, 4};
    assert_int_equal(io_display_open(&d, &c2, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "4 buffers asked"));
    /* closing nothing, twice */
    d = NULL;
    io_display_close(&d);
    io_display_close(&d);
    io_display_close(NULL);
}

/* --------------------------------------------------------- SDL missing */

static void test_sdl_missing(void **st)
{
    (void)st;
    setenv("EGOFUSE_SDL_LIB", "libSDL2-not-there.so.0", 1);
    expect_open_fails("sdl", "sdl: cannot load libSDL2-not-there.so.0");
    unsetenv("EGOFUSE_SDL_LIB");
}

/* ------------------------------------------------------------- X server */

static pid_t xvfb_pid = -1;
static char xdisplay[32];
static char x_skip[256];

/* Starts Xvfb on a free display number (-displayfd: the server picks it
 * and writes it when it is ready to take clients). */
static int start_xvfb(int w, int h)
{
    if (access("/usr/bin/Xvfb", X_OK) != 0) {
        snprintf(x_skip, sizeof x_skip, "Xvfb missing (apt-get install xvfb)");
        return -1;
    }
    if (access("/usr/bin/xwd", X_OK) != 0) {
        snprintf(x_skip, sizeof x_skip, "xwd missing (apt-get install x11-apps)");
        return -1;
    }
    void *h2 = dlopen("libSDL2-2.0.so.0", RTLD_NOW | RTLD_LOCAL);
    if (!h2) {
        snprintf(x_skip, sizeof x_skip, "libSDL2-2.0.so.0 missing (apt-get install libsdl2-2.0-0)");
        return -1;
    }
    int pfd[2];
    if (pipe(pfd) != 0) return -1;
    char screen[64], fdarg[16];
    snprintf(screen, sizeof screen, "%dx%dx24", w, h);
    snprintf(fdarg, sizeof fdarg, "%d", pfd[1]);
    pid_t pid = fork();
    if (pid == 0) {
        close(pfd[0]);
        int devnull = open("/dev/null", O_RDWR);
        dup2(devnull, 0);
        dup2(devnull, 1);
        dup2(devnull, 2);
        execl("/usr/bin/Xvfb", "Xvfb", "-displayfd", fdarg, "-screen", "0", screen, "-nolisten", "tcp",
              "-noreset", (char *)NULL);
        _exit(127);
    }
    close(pfd[1]);
    char buf[32] = "";
    size_t n = 0;
    struct pollfd pf = {pfd[0], POLLIN, 0};
    /* a guard, not a timing: the server writes its number when ready */
    while (n < sizeof buf - 1 && poll(&pf, 1, 30000) > 0) {
        ssize_t k = read(pfd[0], buf + n, sizeof buf - 1 - n);
        if (k <= 0) break;
        n += (size_t)k;
        if (memchr(buf, '\n', n)) break;
    }
    close(pfd[0]);
    buf[n] = '\0';
    int num = atoi(buf);
    if (!n || buf[0] < '0' || buf[0] > '9') {
        kill(pid, SIGTERM);
        waitpid(pid, NULL, 0);
        snprintf(x_skip, sizeof x_skip, "Xvfb did not start");
        return -1;
    }
    xvfb_pid = pid;
    snprintf(xdisplay, sizeof xdisplay, ":%d", num);
    setenv("DISPLAY", xdisplay, 1);
    return 0;
}

static void stop_xvfb(void)
{
    if (xvfb_pid > 0) {
        kill(xvfb_pid, SIGTERM);
        waitpid(xvfb_pid, NULL, 0);
    }
    xvfb_pid = -1;
}

/* An X Window Dump, as XWDFile.h lays it out: a header of 25 big-endian
 * CARD32 (header_size, file_version 7, pixmap_format, pixmap_depth,
 * pixmap_width, pixmap_height, xoffset, byte_order, bitmap_unit,
 * bitmap_bit_order, bitmap_pad, bits_per_pixel, bytes_per_line,
 * visual_class, red_mask, green_mask, blue_mask, bits_per_rgb,
 * colormap_entries, ncolors, window_width, window_height, window_x,
 * window_y, window_bdrwidth), the window name up to header_size, ncolors
 * 12-byte XWDColor entries, then the pixels. */
typedef struct xwd_image {
    int w, h;
    uint8_t *rgb;     /* w * h * 3 */
} xwd_image;

static uint32_t be32(const uint8_t *p)
{
    return ((uint32_t)p[0] << 24) | ((uint32_t)p[1] << 16) | ((uint32_t)p[2] << 8) | p[3];
}

static int mask_shift(uint32_t m)
{
    int s = 0;
    while (m && !(m & 1)) {
        m >>= 1;
        s++;
    }
    return s;
}

static int xwd_read(const char *path, xwd_image *img, char *why, size_t nwhy)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(why, nwhy, "%.200s: %s", path, strerror(errno));
        return -1;
    }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *b = malloc((size_t)size);
    if (!b || fread(b, 1, (size_t)size, f) != (size_t)size) {
        fclose(f);
        free(b);
        snprintf(why, nwhy, "%.200s: short read", path);
        return -1;
    }
    fclose(f);
    int rc = -1;
    if (size < 100) {
        snprintf(why, nwhy, "%.200s: %ld bytes, not an XWD file", path, size);
        goto out;
    }
    uint32_t hs = be32(b), version = be32(b + 4), format = be32(b + 8), depth = be32(b + 12);
    uint32_t w = be32(b + 16), h = be32(b + 20), byte_order = be32(b + 28), bpp = be32(b + 44);
    uint32_t bpl = be32(b + 48), rm = be32(b + 56), gm = be32(b + 60), bm = be32(b + 64), ncolors = be32(b + 76);
    size_t off = (size_t)hs + (size_t)ncolors * 12;
    if (version != 7 || format != 2 || (bpp != 32 && bpp != 24) || off + (size_t)bpl * h > (size_t)size) {
        snprintf(why, nwhy, "%.200s: version %u format %u depth %u bpp %u: not a 24/32-bit ZPixmap dump", path,
                 version, format, depth, bpp);
        goto out;
    }
    img->w = (int)w;
    img->h = (int)h;
    img->rgb = malloc((size_t)w * h * 3);
    if (!img->rgb) goto out;
    int rs = mask_shift(rm), gs = mask_shift(gm), bs = mask_shift(bm);
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            const uint8_t *p = b + off + (size_t)y * bpl + (size_t)x * (bpp / 8);
            uint32_t v = 0;
            for (uint32_t k = 0; k < bpp / 8; k++)
                v |= byte_order == 0 ? (uint32_t)p[k] << (8 * k) : (uint32_t)p[k] << (8 * (bpp / 8 - 1 - k));
            uint8_t *o = img->rgb + ((size_t)y * w + x) * 3;
            o[0] = (uint8_t)((v & rm) >> rs);
            o[1] = (uint8_t)((v & gm) >> gs);
            o[2] = (uint8_t)((v & bm) >> bs);
        }
    rc = 0;
out:
    free(b);
    return rc;
}

static int screenshot(const char *path, xwd_image *img, char *why, size_t nwhy)
{
    char *argv[] = {"/usr/bin/xwd", "-root", "-silent", "-display", xdisplay, "-out", (char *)path, NULL};
    char out[1024];
    int rc = tu_run(argv, out, sizeof out);
    if (rc != 0) {
        snprintf(why, nwhy, "xwd exit %d: %.300s", rc, out);
        return -1;
    }
    return xwd_read(path, img, why, nwhy);
}

/* the test pattern of eye e at (x, y) */
static void pattern(int e, int x, int y, int frame, uint8_t px[4])
{
    px[0] = (uint8_t)(x * 5 + e * 100 + frame);
    px[1] = (uint8_t)(y * 7 + 13);
    px[2] = (uint8_t)((x ^ y ^ (e * 0x55)) + 1);
    px[3] = 255;
}

/* Where the window's w x h image (expected rgb) is on the screen, or -1. */
static int find_image(const xwd_image *s, const uint8_t *exp, int w, int h, int *fx, int *fy)
{
    for (int y = 0; y + h <= s->h; y++)
        for (int x = 0; x + w <= s->w; x++) {
            int ok = 1;
            for (int yy = 0; yy < h && ok; yy++)
                ok = !memcmp(s->rgb + ((size_t)(y + yy) * s->w + x) * 3, exp + (size_t)yy * w * 3, (size_t)w * 3);
            if (ok) {
                *fx = x;
                *fy = y;
                return 0;
            }
        }
    return -1;
}

/* Under AddressSanitizer (make debug) the SDL window is not tested: SDL's
 * X11 and GL driver libraries, loaded and unloaded by SDL itself, leave
 * allocations LeakSanitizer reports from an unloaded (unknown) module, so
 * no suppression can name them. The plain build tests the window. */
#if defined(__SANITIZE_ADDRESS__)
#define DISPLAY_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DISPLAY_TEST_ASAN 1
#endif
#endif

static void test_sdl_window(void **st)
{
    (void)st;
#ifdef DISPLAY_TEST_ASAN
    printf("SKIP: the SDL window under AddressSanitizer (SDL's X11/GL libraries leak from an "
           "unloaded module; the build without sanitizers tests it)\n");
    skip();
#endif
    setenv("SDL_VIDEODRIVER", "x11", 1);
    setenv("SDL_RENDER_DRIVER", "software", 1);
    /* no X server: a clear message */
    unsetenv("DISPLAY");
    unsetenv("WAYLAND_DISPLAY");
    if (access("/usr/bin/Xvfb", X_OK) == 0 && dlopen("libSDL2-2.0.so.0", RTLD_NOW | RTLD_LOCAL))
        expect_open_fails("sdl", "sdl: cannot start SDL video");
    if (start_xvfb(320, 200) != 0) {
        printf("SKIP: %s\n", x_skip);
        skip();
    }
    enum { EW = 64, EH = 48 };
    static uint8_t eye[2][EW * EH * 4], exp_rgb[2 * EW * EH * 3];
    io_display_config c = {"sdl", EW, EH, 2};
    io_display *d = NULL;
    io_error err;
    int fds = tu_count_fds();
    if (io_display_open(&d, &c, &err) != IO_OK) {
        stop_xvfb();
        fail_msg("%s", err.msg);
    }
    printf("NOTE %s on Xvfb %s\n", io_display_describe(d), xdisplay);
    assert_int_equal(io_display_fd(d), -1);
    assert_int_equal(io_display_refresh_ns(d), 0);
    int ow, oh;
    io_display_size(d, &ow, &oh);
    assert_int_equal(ow, 2 * EW);
    assert_int_equal(oh, EH);
    char path[512], why[512] = "";
    tu_tmp_path("display.xwd", path, sizeof path);
    int found = 0, fx = -1, fy = -1, tries = 0;
    /* the window may need a few presents before it is mapped and shown:
     * bounded by a count */
    for (int frame = 0; frame < 20 && !found; frame++) {
        for (int e = 0; e < 2; e++)
            for (int y = 0; y < EH; y++)
                for (int x = 0; x < EW; x++) {
                    uint8_t *px = eye[e] + ((size_t)y * EW + x) * 4;
                    pattern(e, x, y, frame, px);
                    memcpy(exp_rgb + ((size_t)y * 2 * EW + (size_t)e * EW + x) * 3, px, 3);
                }
        const uint8_t *rgba[2] = {eye[0], eye[1]};
        size_t stride[2] = {EW * 4, EW * 4};
        assert_int_equal(io_display_present(d, rgba, stride, 1000 + (uint64_t)frame, &err), IO_OK);
        io_display_flip ev;
        int got = 0;
        assert_int_equal(io_display_poll(d, 0, &ev, &got, &err), IO_OK);
        assert_int_equal(got, 1);
        assert_int_equal(ev.frame_id, 1000 + (uint64_t)frame);
        assert_int_equal(ev.seq, (uint32_t)frame + 1);
        assert_int_equal(io_display_poll(d, 0, &ev, &got, &err), IO_OK);   /* one event per present */
        assert_int_equal(got, 0);
        xwd_image img = {0, 0, NULL};
        tries++;
        if (screenshot(path, &img, why, sizeof why) != 0) break;
        found = find_image(&img, exp_rgb, 2 * EW, EH, &fx, &fy) == 0;
        free(img.rgb);
    }
    unlink(path);
    printf("NOTE screenshot after %d present(s): %s at (%d, %d) %s\n", tries,
           found ? "the exact image" : "image NOT found", fx, fy, why);
    /* quit requests: Esc, then the window manager's close */
    void *h = dlopen("libSDL2-2.0.so.0", RTLD_NOW | RTLD_LOCAL | RTLD_NOLOAD);
    int (*push)(SDL_Event *) = h ? (int (*)(SDL_Event *))dlsym(h, "SDL_PushEvent") : NULL;
    int quit_esc = -1;
    if (push) {
        assert_int_equal(io_display_quit_requested(d), 0);
        SDL_Event e;
        memset(&e, 0, sizeof e);
        e.type = SDL_KEYDOWN;
        e.key.keysym.sym = SDLK_ESCAPE;
        push(&e);
        io_display_flip ev;
        int got;
        io_display_poll(d, 0, &ev, &got, &err);
        quit_esc = io_display_quit_requested(d);
    }
    io_display_close(&d);
    assert_null(d);
    io_display_close(&d);
    if (h) dlclose(h);
    /* SDL's X connection is gone again */
    int fds_after = tu_count_fds();
    stop_xvfb();
    assert_true(found);
    assert_int_equal(quit_esc, 1);
    assert_int_equal(fds_after, fds);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(test_parse),
        cmocka_unit_test(test_blit),
        cmocka_unit_test(test_kms_refusals),
        cmocka_unit_test(test_sdl_missing),
        cmocka_unit_test(test_sdl_window))
