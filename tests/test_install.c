/* test_install.c - `make install` gives a library people can link: runs
 * tests/install_check.sh, which installs into a temporary DESTDIR, builds
 * examples/mask_example.c with pkg-config against the staged copy (the
 * shared core libegofuse.so.0 and the static io library of src/io/), runs
 * it on a model written here and compares its mask, byte for byte, with
 * `egofuse mask` of the same camera. The mask must also cover pixels. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>
#include "support/files.h"

static void test_installed_example_matches_cli(void **state)
{
    (void)state;
#if defined(__SANITIZE_ADDRESS__)
    /* make debug: the build's libraries need the sanitizer runtimes, which
     * a program built with only pkg-config's flags does not link. */
    printf("SKIP: a sanitizer build (make debug) is not installed for linking\n");
    skip();
#endif
    const char *bin = getenv("EGOFUSE_BIN");
    char build[512] = "build";
    if (bin && *bin) {
        snprintf(build, sizeof build, "%s", bin);
        char *s = strrchr(build, '/');
        if (s) *s = '\0'; else snprintf(build, sizeof build, ".");
    }
    char dir[] = "/tmp/egofuse_install_XXXXXX";
    assert_non_null(mkdtemp(dir));
    /* a triangle, not symmetric, in front of the camera at (0,0,3) */
    const float pos[9] = {-1.0f, -0.7f, 0.0f, 1.0f, -0.7f, 0.0f, 0.2f, 0.9f, 0.3f};
    char p[600], model[600], cmd[2048];
    snprintf(p, sizeof p, "%s/tri.bin", dir);
    tu_write_bytes(p, pos, sizeof pos);
    const char *gltf =
        "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"tri.bin\",\"byteLength\":36}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
        "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[-1,-0.7,0],\"max\":[1,0.9,0.3]}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}],"
        "\"scenes\":[{\"nodes\":[0]}],\"scene\":0}";
    snprintf(model, sizeof model, "%s/tri.gltf", dir);
    tu_write_bytes(model, gltf, strlen(gltf));
    snprintf(cmd, sizeof cmd, "sh tests/install_check.sh '%s' '%s' '%s'", build, model, dir);
    int st = system(cmd);
    int rc = WIFEXITED(st) ? WEXITSTATUS(st) : 255;
    int covered = -1;
    if (rc == 0) {
        snprintf(p, sizeof p, "%s/lib.pgm", dir);
        FILE *f = fopen(p, "rb");
        if (f) {
            int w = 0, h = 0, mx = 0;
            if (fscanf(f, "P5 %d %d %d", &w, &h, &mx) == 3 && fgetc(f) == '\n' && w == 160 && h == 120) {
                covered = 0;
                for (int i = 0; i < w * h; i++) covered += fgetc(f) == 255;
            }
            fclose(f);
        }
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) print_message("could not remove %s\n", dir);
    if (rc == 77) skip();
    assert_int_equal(rc, 0);
    /* the triangle covers about 2020 of 19200 pixels */
    assert_in_range(covered, 1500, 2600);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_installed_example_matches_cli),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
