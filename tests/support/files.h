/* files.h - whole files written and read back by the tests, failing the
 * test (cmocka) on any error. Header-only (static inline); include after
 * support/testutil.h and <cmocka.h>. */
#ifndef EGOFUSE_TU_FILES_H
#define EGOFUSE_TU_FILES_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

/* path := text. */
static inline void tu_write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) fail_msg("%s: cannot create", path);
    assert_true(fputs(text, f) >= 0);
    assert_int_equal(fclose(f), 0);
}

/* path := the n bytes at p. */
static inline void tu_write_bytes(const char *path, const void *p, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) fail_msg("%s: cannot create", path);
    assert_int_equal(fwrite(p, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

/* The whole file in a malloc'ed buffer (one byte more than *n, for a
 * terminator the caller may write). */
static inline unsigned char *tu_read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) fail_msg("%s: cannot open", path);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    assert_true(len >= 0);
    unsigned char *b = malloc((size_t)len + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    *n = (size_t)len;
    return b;
}

/* tu_b64 (base64 of glTF data: URIs): testutil.h. */

#endif
