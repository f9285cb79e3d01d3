/* cmd_devices.c - `egofuse devices`: the cameras (V4L2 nodes) and USB
 * devices (cameras, 5DT gloves, others) this machine has, with the
 * selectors that name them in `egofuse run`. */
#include "cli.h"

#include <getopt.h>
#include <string.h>

#include "../io/io_dev.h"

static const char *devices_usage =
    "usage: egofuse devices [--all]\n"
    "\n"
    "Lists the V4L2 video nodes (/dev/video*) and the USB devices (libusb)\n"
    "with vendor:product, serial and port path. Use the selectors shown in\n"
    "brackets with `egofuse run --left SEL --right SEL --glove-left SEL`:\n"
    "serial:SN and port:B-P.P survive reboots and replugs, /dev/videoN does\n"
    "not. docs/devices.md has the details.\n"
    "\n"
    "  --all        also USB devices that are neither cameras nor gloves\n"
    "  -h, --help   this text\n";

static const char *kind_name(int k)
{
    return k == IO_USB_KIND_CAMERA ? "camera" : k == IO_USB_KIND_GLOVE ? "glove" : "other";
}

int cmd_devices(int argc, char **argv)
{
    static const struct option opts[] = {
        {"all", no_argument, 0, 'a'}, {"help", no_argument, 0, 'h'}, {0, 0, 0, 0}};
    int all = 0, c, rc;
    cli_getopt_begin();
    while ((c = cli_getopt("devices", devices_usage, argc, argv, opts, &rc)) > 0)
        if (c == 'a') all = 1;
    if (c < 0) return rc;
    if (optind < argc) return cli_usage_error("devices", "unexpected argument '%s'", argv[optind]);

    io_error err;
    io_cam_info cams[64];
    int nc = 0, capture = 0;
    printf("video nodes:\n");
    if (io_cam_list(NULL, cams, 64, &nc, &err) != IO_OK) {
        printf("  cannot list: %s\n", err.msg);
    } else if (nc == 0) {
        printf("  none (no /dev/video* node: no camera plugged in, or no V4L2 in this kernel)\n");
    }
    for (int i = 0; i < nc && i < 64; i++) {
        printf("  %-14s %-10s %-32s %s%s\n", cams[i].path, cams[i].driver[0] ? cams[i].driver : "-",
               cams[i].card, cams[i].bus_info, cams[i].capture ? "  [capture]" : "");
        capture += cams[i].capture;
    }

    io_usb_dev usb[64];
    int nu = 0;
    printf("USB devices:\n");
    if (io_usb_list(usb, 64, &nu, &err) != IO_OK) {
        printf("  cannot list: %s\n", err.msg);
    } else {
        int shown = 0;
        for (int i = 0; i < nu && i < 64; i++) {
            const io_usb_dev *d = &usb[i];
            if (!all && d->kind == IO_USB_KIND_OTHER) continue;
            shown++;
            printf("  %-10s %04x:%04x %-6s %-28s serial %-16s [port:%s%s%s]%s%s\n", d->port_path,
                   d->vid, d->pid, kind_name(d->kind), d->product[0] ? d->product : "-",
                   d->serial[0] ? d->serial : "-", d->port_path, d->serial[0] ? " or serial:" : "",
                   d->serial, d->video[0] ? " -> " : "", d->video);
        }
        if (!shown)
            printf("  %s\n", nu ? "no cameras or gloves (--all lists the others)"
                                : "none");
    }
    printf("%d capture node%s, %d USB device%s\n", capture, capture == 1 ? "" : "s", nu,
           nu == 1 ? "" : "s");
    return EXIT_OK;
}
