/* io_out.c - output files that are complete or absent (see io.h, OUTPUT
 * FILES).
 *
 * HOW
 *   io_out_open() creates an unnamed file in the target's folder
 *   (O_TMPFILE) and hands out a stdio stream over it whose every write goes
 *   through write_cb(): the first failure (ENOSPC, EFBIG, EIO ...) is kept
 *   with its errno, so the message can say why. io_out_commit() flushes,
 *   checks that nothing failed, then gives the file its name: linkat() of
 *   /proc/self/fd/N straight to <path> when <path> does not exist yet, else
 *   to "<path>.tmp.<pid>" followed by rename() over <path> (atomic
 *   replacement). A process killed before the commit leaves nothing behind:
 *   the kernel frees an unnamed file with its last descriptor.
 *
 *   Where O_TMPFILE is not available (some file systems, no /proc), the
 *   file is created as "<path>.tmp.<pid>" at once and renamed at the end;
 *   then a killed run can leave that name behind. egofuse never reads such
 *   names; they can be deleted (docs/io.md, Output files).
 *
 *   No fsync: "complete" means every byte reached the kernel without an
 *   error; a power cut is not covered.
 */
#include "io.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static ssize_t write_cb(void *cookie, const char *buf, size_t size)
{
    io_out *o = cookie;
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(o->fd, buf + done, size - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            if (!o->error) o->error = w < 0 ? errno : EIO;
            return done > 0 ? (ssize_t)done : -1;
        }
        done += (size_t)w;
    }
    return (ssize_t)done;
}

static int seek_cb(void *cookie, off64_t *pos, int whence)
{
    io_out *o = cookie;
    off64_t r = lseek(o->fd, *pos, whence);
    if (r < 0) return -1;
    *pos = r;
    return 0;
}

static int close_cb(void *cookie)
{
    (void)cookie;  /* the descriptor is closed by commit / abort */
    return 0;
}

/* The folder of path, for O_TMPFILE ("." when there is no slash). */
static void folder_of(const char *path, char *dir, size_t size)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        snprintf(dir, size, ".");
    } else if (slash == path) {
        snprintf(dir, size, "/");
    } else {
        size_t n = (size_t)(slash - path);
        if (n >= size) n = size - 1;
        memcpy(dir, path, n);
        dir[n] = '\0';
    }
}

static io_result open_failed(io_out *o, const char *path, const char *dir, int e,
                             io_error *err)
{
    if (o->fd >= 0) close(o->fd);
    o->fd = -1;
    struct stat st;
    if (e == ENOENT && stat(dir, &st) != 0)
        return io_fail(err, IO_ERR_WRITE, "%s: cannot create the file: folder %s does not "
                       "exist", path, dir);
    if (e == ENOTDIR)
        return io_fail(err, IO_ERR_WRITE, "%s: cannot create the file: %s is not a folder",
                       path, dir);
    return io_fail(err, IO_ERR_WRITE, "%s: cannot create the file in folder %s: %s", path,
                   dir, strerror(e));
}

io_result io_out_open(io_out *o, const char *path, io_error *err)
{
    if (!o) return io_fail(err, IO_ERR_ARGS, "io_out_open: no output");
    memset(o, 0, sizeof *o);
    o->fd = -1;
    if (!path || !*path) return io_fail(err, IO_ERR_ARGS, "io_out_open: no path");
    size_t n = strlen(path);
    if (n >= sizeof o->path || path[n - 1] == '/')
        return io_fail(err, IO_ERR_ARGS, "%s: not a file name (too long or a folder)", path);
    memcpy(o->path, path, n + 1);
    snprintf(o->tmp, sizeof o->tmp, "%s.tmp.%ld", path, (long)getpid());
    char dir[IO_PATH_MAX];
    folder_of(path, dir, sizeof dir);

    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return io_fail(err, IO_ERR_WRITE, "%s: is a folder, not a file", path);

#ifdef O_TMPFILE
    if (getenv("EGOFUSE_NO_TMPFILE") == NULL) {
        o->fd = open(dir, O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
        if (o->fd >= 0) {
            char proc[64];
            snprintf(proc, sizeof proc, "/proc/self/fd/%d", o->fd);
            if (access(proc, F_OK) == 0) {
                o->unnamed = 1;
            } else {  /* no /proc: the file could never be named */
                close(o->fd);
                o->fd = -1;
            }
        } else if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) {
            return open_failed(o, path, dir, errno, err);
        }
    }
#endif
    if (o->fd < 0) {
        o->fd = open(o->tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
        if (o->fd < 0) return open_failed(o, path, dir, errno, err);
    }
    cookie_io_functions_t fns = {NULL, write_cb, seek_cb, close_cb};
    o->f = fopencookie(o, "w", fns);
    if (!o->f) {
        int e = errno;
        io_out_abort(o);
        return io_fail(err, IO_ERR_NOMEM, "%s: %s", path, strerror(e));
    }
    return IO_OK;
}

void io_out_abort(io_out *o)
{
    if (!o) return;
    if (o->f) fclose(o->f);
    o->f = NULL;
    if (o->fd >= 0) {
        close(o->fd);
        if (!o->unnamed) unlink(o->tmp);
    }
    o->fd = -1;
}

/* Fails the commit: the file is discarded, the message says why. */
static io_result commit_failed(io_out *o, const char *what, int e, io_error *err)
{
    char path[IO_PATH_MAX];
    snprintf(path, sizeof path, "%s", o->path);
    io_out_abort(o);
    if (e == EFBIG)
        return io_fail(err, IO_ERR_WRITE, "%s: %s: %s (the file size limit, ulimit -f); "
                       "nothing written", path, what, strerror(e));
    return io_fail(err, IO_ERR_WRITE, "%s: %s: %s; nothing written", path, what,
                   strerror(e));
}

io_result io_out_commit(io_out *o, io_error *err)
{
    if (!o || !o->f) return io_fail(err, IO_ERR_ARGS, "io_out_commit: not open");
    if (fflush(o->f) != 0 || ferror(o->f) || o->error)
        return commit_failed(o, "write failed", o->error ? o->error : EIO, err);
    fclose(o->f);
    o->f = NULL;
    int named_tmp = !o->unnamed;
    if (o->unnamed) {
        char proc[64];
        snprintf(proc, sizeof proc, "/proc/self/fd/%d", o->fd);
        if (linkat(AT_FDCWD, proc, AT_FDCWD, o->path, AT_SYMLINK_FOLLOW) != 0) {
            if (errno != EEXIST) return commit_failed(o, "cannot name the file", errno, err);
            /* replace atomically: a name of ours first, then rename */
            if (linkat(AT_FDCWD, proc, AT_FDCWD, o->tmp, AT_SYMLINK_FOLLOW) != 0) {
                struct stat st;
                /* a stale temporary of an earlier process with our pid */
                if (errno != EEXIST || lstat(o->tmp, &st) != 0 || S_ISDIR(st.st_mode) ||
                    unlink(o->tmp) != 0 ||
                    linkat(AT_FDCWD, proc, AT_FDCWD, o->tmp, AT_SYMLINK_FOLLOW) != 0)
                    return commit_failed(o, "cannot create the temporary file", errno, err);
            }
            o->unnamed = 0;
            named_tmp = 1;
        }
    }
    int fd = o->fd;
    o->fd = -1;
    if (close(fd) != 0) {
        int e = errno;
        unlink(named_tmp ? o->tmp : o->path);
        return io_fail(err, IO_ERR_WRITE, "%s: write failed (on close): %s; nothing written",
                       o->path, strerror(e));
    }
    if (named_tmp && rename(o->tmp, o->path) != 0) {
        int e = errno;
        unlink(o->tmp);
        return io_fail(err, IO_ERR_WRITE, "%s: cannot replace it (rename from %s): %s",
                       o->path, o->tmp, strerror(e));
    }
    return IO_OK;
}

io_result io_write_file(const char *path, const void *data, size_t len, io_error *err)
{
    io_out o;
    io_result r = io_out_open(&o, path, err);
    if (r != IO_OK) return r;
    if (len && fwrite(data, 1, len, o.f) != len) {
        /* the reason is in o.error; commit reports it */
    }
    return io_out_commit(&o, err);
}
