#include "testutil.h"
#include "fd_count.h"

#include <dirent.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>

const char *tu_shared_path(const char *rel, char *buf, size_t n)
{
    const char *s = getenv("EGOFUSE_SHARED");
    snprintf(buf, n, "%s/%s", s && *s ? s : "../shared", rel);
    return buf;
}

const char *tu_tmp_path(const char *name, char *buf, size_t n)
{
    const char *s = getenv("EGOFUSE_TMP");
    char dir[512];
    snprintf(dir, sizeof dir, "%s/t%ld", s && *s ? s : "/tmp", (long)getpid());
    mkdir(dir, 0777);
    snprintf(buf, n, "%s/%s", dir, name);
    return buf;
}

const char *tu_root_path(const char *rel, char *buf, size_t n)
{
    const char *s = getenv("EGOFUSE_ROOT");
    snprintf(buf, n, "%s/%s", s && *s ? s : ".", rel);
    return buf;
}

int tu_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

int tu_rm_rf(const char *path)
{
    char cmd[4200];
    if ((size_t)snprintf(cmd, sizeof cmd, "rm -rf '%s'", path) >= sizeof cmd) return -1;
    return system(cmd) == 0 ? 0 : -1;
}

uint32_t tu_crc32(uint32_t crc, const void *data, size_t n)
{
    const uint8_t *p = data;
    crc = ~crc;
    for (size_t i = 0; i < n; i++) {
        crc ^= p[i];
        for (int k = 0; k < 8; k++)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

/* Runs argv with stdout+stderr captured into out[out_size]; limited: no
 * core file, a file size limit of `limit` bytes (< 0: none) and SIGXFSZ
 * ignored or default (xfsz_kill). 0 with the wait status in *st, -1 when
 * it could not start. */
static int run_capture(char *const argv[], char *out, size_t out_size, int limited, long limit,
                       int xfsz_kill, int *st)
{
    int fd[2];
    if (pipe(fd) != 0) return -1;
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        if (limited) {
            struct rlimit core = {0, 0};
            setrlimit(RLIMIT_CORE, &core);
            if (limit >= 0) {
                struct rlimit r = {(rlim_t)limit, (rlim_t)limit};
                setrlimit(RLIMIT_FSIZE, &r);
            }
            signal(SIGXFSZ, xfsz_kill ? SIG_DFL : SIG_IGN); /* kept by exec */
        }
        dup2(fd[1], 1); dup2(fd[1], 2);
        close(fd[0]); close(fd[1]);
        execv(argv[0], argv);
        _exit(127);
    }
    close(fd[1]);
    size_t len = 0;
    ssize_t r;
    char tmp[4096];
    while ((r = read(fd[0], tmp, sizeof tmp)) > 0) {
        size_t k = (size_t)r;
        if (out_size && len + k >= out_size) k = out_size - 1 - len;
        if (out_size) { memcpy(out + len, tmp, k); len += k; }
    }
    if (out_size) out[len] = 0;
    close(fd[0]);
    return waitpid(pid, st, 0) < 0 ? -1 : 0;
}

int tu_run(char *const argv[], char *out, size_t out_size)
{
    int st;
    if (run_capture(argv, out, out_size, 0, -1, 0, &st) != 0) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

int tu_run_limited(char *const argv[], char *out, size_t out_size, long limit, int xfsz_kill)
{
    int st;
    if (run_capture(argv, out, out_size, 1, limit, xfsz_kill, &st) != 0) return -1000;
    return WIFEXITED(st) ? WEXITSTATUS(st) : WIFSIGNALED(st) ? -WTERMSIG(st) : -1000;
}

const char *tu_bin(void)
{
    const char *b = getenv("EGOFUSE_BIN");
    return b && *b ? b : "build/egofuse";
}

void tu_gen_path(char *out, size_t n)
{
    const char *bin = tu_bin();
    const char *slash = strrchr(bin, '/');
    snprintf(out, n, "%.*s/gen_samples", slash ? (int)(slash - bin) : 1, slash ? bin : ".");
}

int tu_gen_seq(const char *name, int frames, const char *hmd, char *dir, size_t n)
{
    char gen[1024], nf[16], log[8192];
    tu_gen_path(gen, sizeof gen);
    tu_tmp_path(name, dir, n);
    snprintf(nf, sizeof nf, "%d", frames);
    char *argv[] = {gen, "--out", dir, "--frames", nf, hmd ? "--hmd" : NULL, (char *)hmd, NULL};
    int rc = tu_run(argv, log, sizeof log);
    if (rc != 0) {
        fprintf(stderr, "%s --out %s --frames %d%s%s: exit %d: %s\n", gen, dir, frames,
                hmd ? " --hmd " : "", hmd ? hmd : "", rc, log);
        return -1;
    }
    return 0;
}

int tu_runl(char *out, size_t out_size, const char *prog, const char *a0, ...)
{
    char *argv[48];
    int n = 0;
    argv[n++] = (char *)prog;
    va_list ap;
    va_start(ap, a0);
    for (const char *a = a0; a && n < 47; a = va_arg(ap, const char *)) argv[n++] = (char *)a;
    va_end(ap);
    argv[n] = NULL;
    return tu_run(argv, out, out_size);
}

int tu_count_fds(void) { return tu_fd_count(); }

int tu_file_is(const char *path, const char *text)
{
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    char buf[256] = {0};
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return n == strlen(text) && memcmp(buf, text, n) == 0;
}

int tu_samples_dir(const char *name, int frames, char *dir, size_t n, char *why, size_t why_n)
{
    char gen[1024], own[1100], scene[1200], log[4096], nf[16];
    const char *bin = getenv("EGOFUSE_BIN");
    const char *slash = bin ? strrchr(bin, '/') : NULL;
    if (slash) snprintf(gen, sizeof gen, "%.*s/gen_samples", (int)(slash - bin), bin);
    else tu_root_path("build/gen_samples", gen, sizeof gen);
    tu_root_path("build/samples", own, sizeof own);
    snprintf(scene, sizeof scene, "%s/scene.txt", own);
    struct stat sg, ss;
    int have_gen = stat(gen, &sg) == 0;
    if (stat(scene, &ss) == 0 && (!have_gen || ss.st_mtime >= sg.st_mtime)) {
        snprintf(dir, n, "%s", own);
        return 1;
    }
    if (!have_gen) {
        snprintf(why, why_n, "SKIP: no generated samples (%s) and no generator %s (make build/gen_samples)",
                 own, gen);
        return 0;
    }
    tu_tmp_path(name, dir, n);
    snprintf(nf, sizeof nf, "%d", frames);
    char *argv[] = {gen, "--out", dir, "--frames", nf, NULL};
    if (tu_run(argv, log, sizeof log) != 0) {
        fprintf(stderr, "%s failed:\n%s\n", gen, log);
        return -1;
    }
    return 1;
}

void tu_samples_remove(const char *name)
{
    char dir[1024], log[256];
    tu_tmp_path(name, dir, sizeof dir);
    char *argv[] = {"/bin/rm", "-rf", dir, NULL};
    tu_run(argv, log, sizeof log);
}

void tu_b64(const void *inp, size_t n, char *o)
{
    const uint8_t *in = inp;
    static const char *t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t j = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) |
                     (i + 2 < n ? in[i + 2] : 0);
        o[j++] = t[v >> 18 & 63];
        o[j++] = t[v >> 12 & 63];
        o[j++] = i + 1 < n ? t[v >> 6 & 63] : '=';
        o[j++] = i + 2 < n ? t[v & 63] : '=';
    }
    o[j] = '\0';
}
