/* vm_check.h - what the VM programs (vm_devices.c, vm_display.c) share:
 * check() prints one "VMTEST name PASS|FAIL reason" line (tests/test_vm.c
 * reads them from the guest's console) and counts the failures in
 * failures; count_fds() is tu_fd_count (tests/support/fd_count.h).
 * Header only: each program is one file compiled by tests/vm/prepare.sh. */
#ifndef EGOFUSE_VM_CHECK_H
#define EGOFUSE_VM_CHECK_H

#include <stdarg.h>
#include <stdio.h>

#include "../support/fd_count.h"

static int failures;

static void check(int ok, const char *name, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void check(int ok, const char *name, const char *fmt, ...)
{
    char buf[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    printf("VMTEST %s %s %s\n", name, ok ? "PASS" : "FAIL", buf);
    fflush(stdout);
    if (!ok) failures++;
}

static inline int count_fds(void) { return tu_fd_count(); }

#endif
