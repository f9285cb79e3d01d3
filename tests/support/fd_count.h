/* fd_count.h - the number of open file descriptors of this process (the
 * entries of /proc/self/fd, the directory's own fd included), -1 when it
 * cannot be read: testutil.c's tu_count_fds and the VM programs
 * (tests/vm/vm_check.h), which do not link testutil.c. Header only. */
#ifndef EGOFUSE_TEST_FD_COUNT_H
#define EGOFUSE_TEST_FD_COUNT_H

#include <dirent.h>

static inline int tu_fd_count(void)
{
    DIR *d = opendir("/proc/self/fd");
    int n = 0;
    if (!d) return -1;
    while (readdir(d)) n++;
    closedir(d);
    return n;
}

#endif
