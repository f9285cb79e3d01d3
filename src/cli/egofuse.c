/* egofuse.c - the egofuse program: subcommand dispatch (the helpers the
 * subcommands share are in cli_util.c). */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char *main_usage =
    "usage: egofuse COMMAND [OPTIONS]\n"
    "\n"
    "Superimposes the operator's own arms and hands, filmed by the stereo\n"
    "cameras of a see-through HMD, on a virtual scene, on the CPU.\n"
    "\n"
    "commands:\n"
    "  demo     composite the bundled sample sequence (make demo runs it)\n"
    "  render   composite a recorded sequence described by a scene file\n"
    "  mask     render the coverage mask (and normals, depth) of a glTF model\n"
    "  eval     measure the accuracy of each method against generated ground truth\n"
    "  run      composite the live stereo cameras (V4L2), tracking and gloves\n"
    "  devices  list the cameras, USB devices and data gloves found\n"
    "  replay-track  replay a tracking recording over UDP or as a NatNet server\n"
    "  calibrate     write the user calibration file from a calibration recording\n"
    "\n"
    "Run 'egofuse COMMAND --help' for the options of a command.\n";

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(main_usage, stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        fputs(main_usage, stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        puts("egofuse 0.1");
        return EXIT_OK;
    }
    /* Each subcommand sees argv[0] = its name, as getopt expects. */
    if (!strcmp(cmd, "mask")) return cmd_mask(argc - 1, argv + 1);
    if (!strcmp(cmd, "render")) return cmd_render(argc - 1, argv + 1);
    if (!strcmp(cmd, "demo")) return cmd_demo(argc - 1, argv + 1);
    if (!strcmp(cmd, "eval")) return cmd_eval(argc - 1, argv + 1);
    if (!strcmp(cmd, "run")) return cmd_run(argc - 1, argv + 1);
    if (!strcmp(cmd, "devices")) return cmd_devices(argc - 1, argv + 1);
    if (!strcmp(cmd, "replay-track")) return cmd_replay(argc - 1, argv + 1);
    if (!strcmp(cmd, "calibrate")) return cmd_calibrate(argc - 1, argv + 1);
    fprintf(stderr, "egofuse: unknown command '%s'\n\n%s", cmd, main_usage);
    return EXIT_USAGE;
}
