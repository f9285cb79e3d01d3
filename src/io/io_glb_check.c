/* io_glb_check.c - the container of a binary glTF (.glb) checked before
 * tinygltf parses it, so a truncated or damaged file is named with where
 * it ends (glTF 2.0 specification, section "GLB File Format
 * Specification": a 12-byte header magic "glTF", version 2, total length;
 * then chunks of 8-byte header (length, type) and data, the first JSON
 * (0x4E4F534A), an optional second BIN (0x004E4942), all little-endian). */
#include "io.h"

#include <string.h>

#define GLB_JSON 0x4E4F534Au
#define GLB_BIN 0x004E4942u

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static const char *chunk_name(uint32_t type)
{
    return type == GLB_JSON ? "JSON" : type == GLB_BIN ? "BIN" : "unknown type";
}

io_result io_glb_check(const char *path, const void *data, size_t len, io_error *err)
{
    const unsigned char *b = data;
    if (len < 4 || memcmp(b, "glTF", 4) != 0) return IO_OK;  /* not binary glTF */
    if (len < 12)
        return io_fail(err, IO_ERR_FORMAT, "%s: truncated GLB: %zu bytes, the header alone "
                       "is 12", path, len);
    uint32_t version = le32(b + 4), total = le32(b + 8);
    if (version != 2)
        return io_fail(err, IO_ERR_FORMAT, "%s: GLB version %u (only version 2 is glTF 2.0)",
                       path, version);
    if (total > len)
        return io_fail(err, IO_ERR_FORMAT, "%s: truncated GLB: the header gives %u bytes, "
                       "the file has %zu (it ends %zu bytes early)", path, total, len,
                       (size_t)total - len);
    /* bytes after the declared length are ignored, as tinygltf does */
    size_t at = 12;
    for (int i = 0; at < total; i++) {
        if (total - at < 8)
            return io_fail(err, IO_ERR_FORMAT, "%s: truncated GLB: chunk %d header at byte "
                           "%zu needs 8 bytes, %zu remain", path, i, at, (size_t)total - at);
        uint32_t clen = le32(b + at), type = le32(b + at + 4);
        if (i == 0 && type != GLB_JSON)
            return io_fail(err, IO_ERR_FORMAT, "%s: GLB chunk 0 at byte %zu is not JSON "
                           "(type 0x%08X)", path, at, type);
        if ((uint64_t)clen > (uint64_t)(total - at - 8))
            return io_fail(err, IO_ERR_FORMAT, "%s: truncated GLB: chunk %d (%s) at byte %zu "
                           "holds %u bytes, the file ends %zu bytes after its header", path,
                           i, chunk_name(type), at, clen, (size_t)total - at - 8);
        at += 8 + (size_t)clen;
    }
    return IO_OK;
}
