/* testutil.h - shared helpers for the cmocka tests: a seeded PRNG (never
 * rand()), paths of the shared glTF models and of a scratch folder, CRC32.
 * Every test binary includes <cmocka.h> after this header. */
#ifndef EGOFUSE_TESTUTIL_H
#define EGOFUSE_TESTUTIL_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>

/* splitmix64: deterministic on every machine. */
typedef struct tu_rng { uint64_t s; } tu_rng;
static inline uint64_t tu_next(tu_rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
/* Uniform in [0, 1) with 24 bits. */
static inline float tu_unit(tu_rng *r) { return (float)(tu_next(r) >> 40) * (1.0f / 16777216.0f); }
static inline float tu_range(tu_rng *r, float lo, float hi) { return lo + (hi - lo) * tu_unit(r); }
static inline int tu_int(tu_rng *r, int n) { return (int)(tu_next(r) % (uint64_t)n); }

/* The sample generator next to the egofuse under test (tu_bin()). */
void tu_gen_path(char *out, size_t n);
/* A sequence of FRAMES frames from that generator in the scratch folder
 * NAME (tu_tmp_path; its path in dir), of the HMD preset hmd (--hmd)
 * unless hmd is NULL. 0 when the generator ran; else -1, with its exit
 * status and output on stderr. */
int tu_gen_seq(const char *name, int frames, const char *hmd, char *dir, size_t n);

/* Folder of the shared glTF models (EGOFUSE_SHARED/gltf); path of a file. */
const char *tu_shared_path(const char *rel, char *buf, size_t n);
/* A scratch path (EGOFUSE_TMP or /tmp) unique to this process. */
const char *tu_tmp_path(const char *name, char *buf, size_t n);
/* Root of the source tree (EGOFUSE_ROOT or "."). */
const char *tu_root_path(const char *rel, char *buf, size_t n);
/* 1 if the file exists. */
int tu_exists(const char *path);
/* Removes the file or folder tree at path (rm -rf; nothing there is
 * fine): 0, or -1 when rm failed. */
int tu_rm_rf(const char *path);
/* CRC-32 (IEEE), chainable: start with crc = 0. */
uint32_t tu_crc32(uint32_t crc, const void *data, size_t n);
/* Runs argv (argv[0] = program path) with stdout+stderr captured into
 * out[out_size]; returns the exit status, or -1 if it could not start or
 * died from a signal. */
int tu_run(char *const argv[], char *out, size_t out_size);
/* tu_run with no core file, a file size limit of `limit` bytes (< 0:
 * none) and SIGXFSZ ignored (xfsz_kill 0) or default (1). Returns the exit
 * status, -signal when killed, or -1000 when it could not start. */
int tu_run_limited(char *const argv[], char *out, size_t out_size, long limit, int xfsz_kill);
/* The egofuse binary: EGOFUSE_BIN, else build/egofuse. */
const char *tu_bin(void);
/* tu_run of prog with the arguments a0, ... (NULL-terminated, at most
 * 46 are passed). */
int tu_runl(char *out, size_t out_size, const char *prog, const char *a0, ...);
/* Base64 (RFC 4648, padded) of in[0..n) into o (4 ceil(n / 3) + 1 bytes). */
void tu_b64(const void *in, size_t n, char *o);
/* Open descriptors of this process (entries of /proc/self/fd, its own
 * listing's included), -1 when it cannot be read: compare before and after. */
int tu_count_fds(void);
/* 1 when the file holds exactly text (under 256 bytes), else 0 (also
 * when it cannot be read). */
int tu_file_is(const char *path, const char *text);
/* The generated samples (gen_samples' output) for a test: the build's own
 * build/samples when it is at least as new as the generator next to
 * EGOFUSE_BIN (a stale folder from an older generator is not used), else
 * FRAMES frames generated into the test's tmp/NAME. 1 with dir set; 0
 * when there is no generator (why says so, for a skip); -1 when it
 * failed. tu_samples_remove(NAME) deletes what it generated. */
int tu_samples_dir(const char *name, int frames, char *dir, size_t n, char *why, size_t why_n);
void tu_samples_remove(const char *name);

/* Float checks against analytic answers (cmocka's fail_msg at the use
 * site): |a - b| <= tol, with both values in the message. */
#define NEAR(a, b, tol)                                                       \
    do {                                                                      \
        double a_ = (a), b_ = (b);                                            \
        if (!(fabs(a_ - b_) <= (tol)))                                        \
            fail_msg("%s = %.9g, expected %s = %.9g (tol %g)", #a, a_, #b, b_, \
                     (double)(tol));                                          \
    } while (0)
#define NEAR3(v, X, Y, Z, tol) \
    do { NEAR((v).x, X, tol); NEAR((v).y, Y, tol); NEAR((v).z, Z, tol); } while (0)
#define PI_F 3.14159265358979f

/* The test binary's main: one group of cmocka entries, run with the group's
 * setup and teardown (NULL for none), as cmocka_run_group_tests would with
 * an array named tests; TU_MAIN_NAMED names the group in cmocka's output.
 *     TU_MAIN(setup, NULL,
 *             cmocka_unit_test(first),
 *             cmocka_unit_test(second))
 * A binary with several groups runs each with TU_GROUP, adding the group's
 * failures to failed:
 *     int f = 0;
 *     TU_GROUP(f, "validity", cmocka_unit_test(bad_input));
 *     TU_GROUP(f, "results", cmocka_unit_test(first), cmocka_unit_test(second));
 *     return f ? 1 : 0; */
#define TU_MAIN(setup, teardown, ...)                                         \
    int main(void)                                                            \
    {                                                                         \
        const struct CMUnitTest tests[] = {__VA_ARGS__};                      \
        return cmocka_run_group_tests(tests, setup, teardown);                \
    }
#define TU_MAIN_NAMED(name, setup, teardown, ...)                             \
    int main(void)                                                            \
    {                                                                         \
        const struct CMUnitTest tests[] = {__VA_ARGS__};                      \
        return cmocka_run_group_tests_name(name, tests, setup, teardown);     \
    }
#define TU_GROUP(failed, name, ...)                                           \
    do {                                                                      \
        const struct CMUnitTest group_[] = {__VA_ARGS__};                     \
        (failed) += cmocka_run_group_tests_name(name, group_, NULL, NULL);    \
    } while (0)

#endif
