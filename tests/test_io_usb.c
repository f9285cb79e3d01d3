/* test_io_usb.c - USB discovery without USB: a fake sysfs tree (devices,
 * interfaces, video4linux nodes linked the way the kernel links them),
 * selectors, left/right assignment and its errors, hotplug diffs. The
 * libusb path runs against qemu's devices in tests/vm. */
#include "support/testutil.h"
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../src/io/io_dev.h"

static char root[512];

static void put(const char *rel, const char *text)
{
    char p[1024];
    snprintf(p, sizeof p, "%s/%s", root, rel);
    FILE *fp = fopen(p, "w");
    assert_non_null(fp);
    fprintf(fp, "%s\n", text);
    fclose(fp);
}

static void mk(const char *rel)
{
    char p[1024], cmd[1100];
    snprintf(p, sizeof p, "%s/%s", root, rel);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", p);
    assert_int_equal(system(cmd), 0);
}

static void device(const char *name, const char *vid, const char *pid, const char *serial,
                   const char *product, const char *iface_class)
{
    char d[256], f[300];
    snprintf(d, sizeof d, "bus/usb/devices/%s", name);
    mk(d);
#define PUT(attr, v) do { snprintf(f, sizeof f, "%s/" attr, d); put(f, v); } while (0)
    PUT("idVendor", vid);
    PUT("idProduct", pid);
    PUT("bDeviceClass", "ef");
    PUT("devnum", "3");
    if (serial) PUT("serial", serial);
    PUT("product", product);
    PUT("manufacturer", "ACME");
    snprintf(d, sizeof d, "bus/usb/devices/%s:1.0", name);
    mk(d);
    PUT("bInterfaceClass", iface_class);
#undef PUT
}

/* /sys/class/video4linux/videoN/device -> the interface folder */
static void video_node(int n, const char *iface, int index)
{
    char d[256], target[1024], link[1024], v[16];
    snprintf(d, sizeof d, "class/video4linux/video%d", n);
    mk(d);
    snprintf(target, sizeof target, "%s/bus/usb/devices/%s", root, iface);
    snprintf(link, sizeof link, "%s/%s/device", root, d);
    unlink(link);
    assert_int_equal(symlink(target, link), 0);
    snprintf(v, sizeof v, "%d", index);
    snprintf(d, sizeof d, "class/video4linux/video%d/index", n);
    put(d, v);
}

static int setup(void **st)
{
    (void)st;
    tu_tmp_path("fake_sysfs", root, sizeof root);
    if (tu_rm_rf(root) != 0) return -1;
    /* two UVC cameras (each with a metadata node of index 1), a glove, a hub */
    device("1-2.3", "046d", "0825", "CAMR42", "Webcam R", "0e");
    device("1-2.1", "046d", "0825", "CAML17", "Webcam L", "0e");
    device("3-1", "5d70", "0011", "GLOVEL", "Data Glove 5 Ultra", "03");
    device("1-2", "05e3", "0610", NULL, "Hub", "09");
    mk("bus/usb/devices/usb1"); /* root hub: not listed */
    video_node(0, "1-2.3:1.0", 0);
    video_node(1, "1-2.3:1.0", 1);
    video_node(4, "1-2.1:1.0", 1);
    video_node(3, "1-2.1:1.0", 0);
    return 0;
}

static int teardown(void **st)
{
    (void)st;
    return tu_rm_rf(root);
}

static void test_port_path(void **st)
{
    (void)st;
    char b[32];
    uint8_t p[3] = {2, 3, 14};
    io_usb_port_path(1, p, 3, b, sizeof b);
    assert_string_equal(b, "1-2.3.14");
    io_usb_port_path(4, p, 1, b, sizeof b);
    assert_string_equal(b, "4-2");
    io_usb_port_path(2, p, 0, b, sizeof b);
    assert_string_equal(b, "usb2");
}

static void test_list_sysfs(void **st)
{
    (void)st;
    io_usb_dev d[8];
    int n = 0;
    io_error err;
    assert_int_equal(io_usb_list_sysfs(root, d, 8, &n, &err), IO_OK);
    assert_int_equal(n, 4);
    /* sorted by port path */
    assert_string_equal(d[0].port_path, "1-2");
    assert_string_equal(d[1].port_path, "1-2.1");
    assert_string_equal(d[2].port_path, "1-2.3");
    assert_string_equal(d[3].port_path, "3-1");
    assert_int_equal(d[0].kind, IO_USB_KIND_OTHER);
    assert_int_equal(d[1].kind, IO_USB_KIND_CAMERA);
    assert_int_equal(d[3].kind, IO_USB_KIND_GLOVE);
    assert_int_equal(d[1].vid, 0x046d);
    assert_int_equal(d[1].pid, 0x0825);
    assert_string_equal(d[1].serial, "CAML17");
    assert_string_equal(d[1].product, "Webcam L");
    assert_int_equal(d[2].depth, 2);
    assert_int_equal(d[2].ports[1], 3);
    /* the capture node (index 0), not the metadata node */
    assert_string_equal(d[1].video, "/dev/video3");
    assert_string_equal(d[2].video, "/dev/video0");
    assert_string_equal(d[3].video, "");
    /* a smaller array still counts everything */
    assert_int_equal(io_usb_list_sysfs(root, d, 2, &n, &err), IO_OK);
    assert_int_equal(n, 4);
    char bad[600];
    snprintf(bad, sizeof bad, "%s/nothing", root);
    assert_int_equal(io_usb_list_sysfs(bad, d, 8, &n, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "nothing/bus/usb/devices"));
}

static void test_video_node(void **st)
{
    (void)st;
    char v[64];
    io_error err;
    assert_int_equal(io_usb_video_node(root, "1-2.1", v, sizeof v, &err), IO_OK);
    assert_string_equal(v, "/dev/video3");
    /* "1-2" is a prefix of "1-2.1" but not the same device */
    assert_int_equal(io_usb_video_node(root, "1-2", v, sizeof v, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "1-2 has no video node"));
    /* replugged into another port: the node follows the port, not N */
    video_node(7, "3-1:1.0", 0);
    assert_int_equal(io_usb_video_node(root, "3-1", v, sizeof v, &err), IO_OK);
    assert_string_equal(v, "/dev/video7");
    char p[1024];
    snprintf(p, sizeof p, "rm -rf '%s/class/video4linux/video7'", root);
    assert_int_equal(system(p), 0);
}

static void test_selectors(void **st)
{
    (void)st;
    io_usb_dev d;
    io_error err;
    memset(&d, 0, sizeof d);
    strcpy(d.port_path, "1-2.3");
    strcpy(d.serial, "CAMR42");
    strcpy(d.video, "/dev/video0");
    d.vid = 0x046d;
    d.pid = 0x0825;
    assert_true(io_usb_match(&d, "serial:CAMR42"));
    assert_false(io_usb_match(&d, "serial:CAMR4"));
    assert_true(io_usb_match(&d, "port:1-2.3"));
    assert_false(io_usb_match(&d, "port:1-2"));
    assert_true(io_usb_match(&d, "id:046d:0825"));
    assert_false(io_usb_match(&d, "id:046d:0826"));
    assert_true(io_usb_match(&d, "/dev/video0"));
    assert_false(io_usb_match(&d, "/dev/video1"));
    static const char *const bad[] = {"", "serial:", "port:1-", "port:x-1", "port:1-2..3",
                                      "id:46d", "id:046d:0825x", "camera0"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(io_usb_selector_check(bad[i], &err), IO_ERR_ARGS);
        assert_false(io_usb_match(&d, bad[i]));
    }
    assert_non_null(strstr(err.msg, "camera0"));
    /* a device without serial never matches a serial selector */
    d.serial[0] = '\0';
    assert_false(io_usb_match(&d, "serial:"));
}

static void test_assign(void **st)
{
    (void)st;
    io_usb_dev d[8];
    int n, l, r;
    io_error err;
    assert_int_equal(io_usb_list_sysfs(root, d, 8, &n, &err), IO_OK);
    /* by serial: the order of the selectors decides, not the ports */
    assert_int_equal(io_usb_assign(d, n, "serial:CAMR42", "serial:CAML17", &l, &r, &err), IO_OK);
    assert_string_equal(d[l].port_path, "1-2.3");
    assert_string_equal(d[r].port_path, "1-2.1");
    assert_int_equal(io_usb_assign(d, n, "port:1-2.1", "port:1-2.3", &l, &r, &err), IO_OK);
    assert_string_equal(d[l].serial, "CAML17");
    /* default: the first two cameras by port path */
    assert_int_equal(io_usb_assign(d, n, NULL, NULL, &l, &r, &err), IO_OK);
    assert_string_equal(d[l].port_path, "1-2.1");
    assert_string_equal(d[r].port_path, "1-2.3");
    /* errors */
    assert_int_equal(io_usb_assign(d, n, "serial:NOPE", "serial:CAML17", &l, &r, &err),
                     IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "left camera"));
    assert_non_null(strstr(err.msg, "serial:NOPE"));
    assert_int_equal(l, -1);
    assert_int_equal(io_usb_assign(d, n, "serial:CAML17", "port:1-2.1", &l, &r, &err),
                     IO_ERR_VALUE);
    assert_non_null(strstr(err.msg, "both name the device at port 1-2.1"));
    assert_int_equal(io_usb_assign(d, n, "serial:CAML17", NULL, &l, &r, &err), IO_ERR_ARGS);
    assert_int_equal(io_usb_assign(d, n, "serial:CAML17", "bogus", &l, &r, &err), IO_ERR_ARGS);
    d[2].kind = IO_USB_KIND_OTHER; /* one camera left */
    assert_int_equal(io_usb_assign(d, n, NULL, NULL, &l, &r, &err), IO_ERR_NOT_FOUND);
    assert_non_null(strstr(err.msg, "1 USB camera found"));
    /* two devices with the same serial (cheap cameras do that) */
    assert_int_equal(io_usb_list_sysfs(root, d, 8, &n, &err), IO_OK);
    strcpy(d[2].serial, "CAML17");
    assert_int_equal(io_usb_assign(d, n, "serial:CAML17", "port:3-1", &l, &r, &err), IO_ERR_VALUE);
    assert_non_null(strstr(err.msg, "2 devices match"));
}

static void test_diff(void **st)
{
    (void)st;
    io_usb_dev a[8], b[8];
    int na, nb, add[8], rem[8], nadd, nrem;
    io_error err;
    assert_int_equal(io_usb_list_sysfs(root, a, 8, &na, &err), IO_OK);
    memcpy(b, a, sizeof a);
    nb = na;
    io_usb_diff(a, na, b, nb, add, &nadd, rem, &nrem);
    assert_int_equal(nadd + nrem, 0);
    /* the right camera moves from 1-2.3 to 3-2: one left, one arrived */
    strcpy(b[2].port_path, "3-2");
    io_usb_diff(a, na, b, nb, add, &nadd, rem, &nrem);
    assert_int_equal(nadd, 1);
    assert_int_equal(nrem, 1);
    assert_int_equal(add[0], 2);
    assert_int_equal(rem[0], 2);
    /* unplugged */
    io_usb_diff(a, na, b, 2, add, &nadd, rem, &nrem);
    assert_int_equal(nadd, 0);
    assert_int_equal(nrem, 2);
}

TU_MAIN(setup, teardown,
        cmocka_unit_test(test_port_path),  cmocka_unit_test(test_list_sysfs),
        cmocka_unit_test(test_video_node), cmocka_unit_test(test_selectors),
        cmocka_unit_test(test_assign),     cmocka_unit_test(test_diff))
