/* files.h - whole files written and read back by the tests, failing the
 * test (cmocka) on any error. Header-only (static inline); include after
 * support/testutil.h and <cmocka.h>. */
#ifndef EGOFUSE_TU_FILES_H
#define EGOFUSE_TU_FILES_H

#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h" /* tu_b64 */

/* path := text. */
static inline void tu_write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f) fail_msg("%s: cannot create", path);
    assert_true(fputs(text, f) >= 0);
    assert_int_equal(fclose(f), 0);
}

/* path := printf(fmt, ...). */
static inline void tu_write_fmt(const char *path, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static inline void tu_write_fmt(const char *path, const char *fmt, ...)
{
    FILE *f = fopen(path, "wb");
    if (!f) fail_msg("%s: cannot create", path);
    va_list ap;
    va_start(ap, fmt);
    assert_true(vfprintf(f, fmt, ap) >= 0);
    va_end(ap);
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

/* The names in dir that contain part and end in ext (NULL: any); -1 when
 * dir cannot be read. */
static inline int tu_names_in(const char *dir, const char *part, const char *ext)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    struct dirent *e;
    size_t el = ext ? strlen(ext) : 0;
    while ((e = readdir(d)) != NULL) {
        size_t l = strlen(e->d_name);
        if (part && !strstr(e->d_name, part)) continue;
        if (ext && !(l > el && strcmp(e->d_name + l - el, ext) == 0)) continue;
        n++;
    }
    closedir(d);
    return n;
}

/* tu_b64 (base64 of glTF data: URIs): testutil.h. */

/* A finite value as itself, NaN or infinity as 0 (for a glTF's min/max
 * that must stay valid JSON while the vertex data carries the bad value). */
static inline double tu_fin0(float v) { return isfinite(v) ? v : 0.0; }

/* A glTF with an empty "head" node and one unskinned quad [x0,x1]x[y0,y1]
 * at depth z facing +Z (normals given), its buffer as a data: URI. */
static inline void tu_write_quad_gltf(const char *path, float x0, float x1, float y0, float y1, float z)
{
    uint8_t buf[108];
    float pos[12] = {x0, y0, z, x1, y0, z, x1, y1, z, x0, y1, z};
    float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(buf, pos, 48);
    memcpy(buf + 48, nrm, 48);
    memcpy(buf + 96, idx, 12);
    char enc[200];
    tu_b64(buf, sizeof buf, enc);
    tu_write_fmt(path,
            "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
            "\"nodes\":[{\"name\":\"head\"},{\"name\":\"quad\",\"mesh\":0}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2}]}],"
            "\"buffers\":[{\"byteLength\":108,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
            "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
            "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":12}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
            "\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]},"
            "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
            "{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}\n",
            enc, tu_fin0(x0), tu_fin0(y0), tu_fin0(z), tu_fin0(x1), tu_fin0(y1), tu_fin0(z));
}

#endif
