/* io_gltf.cpp - glTF 2.0 loading (tinygltf) into a kin_model.
 *
 * The C entry points of the glTF side: tinygltf parses the file, this shim
 * copies what egofuse needs into plain kin_ structs (memory from
 * kin_block_alloc), validates the result with kin_model_validate() and lets
 * the tinygltf model go out of scope before returning. Every exception is
 * caught here and turned into an io_result (see docs/io.md).
 *
 * DEPENDENCIES
 *   Debian's libtinygltf 2.7 (-ltinygltf): the implementation lives in the
 *   shared library, built with its defaults (nlohmann json, stb_image, file
 *   system callbacks), so this file includes <tiny_gltf.h> WITHOUT
 *   TINYGLTF_IMPLEMENTATION and without any TINYGLTF_NO_* / _USE_* macro:
 *   those change the layout of tinygltf::TinyGLTF and must match the
 *   library's build.
 *   Debian's libmeshoptimizer (-lmeshoptimizer, 0.18) decodes the buffer
 *   views of EXT_meshopt_compression (meshopt_decodeVertexBuffer,
 *   meshopt_decodeIndexBuffer / IndexSequence and the filters) into the
 *   fallback buffer tinygltf allocated, before anything reads them.
 * FILES (one job each, sharing io_gltf_int.hpp)
 *   io_gltf.cpp         this file: the C API, reading the file, the
 *                       EXT_meshopt_compression decoding, confined URIs,
 *                       and the steps of one load in order
 *   io_gltf_access.cpp  accessors (bounds-checked, sparse, quantized)
 *   io_gltf_nodes.cpp   nodes, scenes, instances, skins
 *   io_gltf_mesh.cpp    primitives (strips, fans), weights, morph targets
 *   io_gltf_anim.cpp    animations
 */
#include "io_gltf_int.hpp"
#include "io_cxx.hpp"
#include <meshoptimizer.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <sys/stat.h>

namespace io_gltf_impl {
namespace {

/* Skips embedded and external images: egofuse only needs geometry, and
 * decoding a JPEG/PNG texture would only cost time. */
bool skip_image(tinygltf::Image *, const int, std::string *, std::string *,
                int, int, const unsigned char *, int, void *)
{
    return true;
}

/* ------------------------------------------------------------- files */

io_result read_file(const char *path, std::vector<unsigned char> &bytes,
                    io_error *err)
{
    io_result r0 = io_check_file(path, err);
    if (r0 != IO_OK) return r0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        int e = errno;
        return io_fail(err, e == ENOENT ? IO_ERR_NOT_FOUND : IO_ERR_READ,
                       "%s: %s", path, strerror(e));
    }
    bytes.clear();
    unsigned char chunk[65536];
    size_t got;
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (bytes.size() + got > 0xFFFFFFFFu) {
            fclose(f);
            return io_fail(err, IO_ERR_SIZE, "%s: larger than 4 GiB", path);
        }
        bytes.insert(bytes.end(), chunk, chunk + got);
    }
    bool bad = ferror(f) != 0;
    int e = errno;
    fclose(f);
    if (bad) return io_fail(err, IO_ERR_READ, "%s: %s", path, strerror(e));
    return IO_OK;
}

std::string dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return std::string();
    if (slash == path) return std::string("/");
    return std::string(path, (size_t)(slash - path));
}

/* tinygltf messages end with a newline and may span lines: keep one line. */
std::string one_line(std::string s) { return io_cxx::one_line(s, "unknown error"); }

/* Extensions egofuse implements (geometry), and those that change only
 * materials, textures or lights, which a coverage mask and normals do not
 * depend on: a file requiring them is drawn right. */
bool extension_implemented(const std::string &e)
{
    static const char *const geometry[] = {
        "KHR_mesh_quantization", "EXT_mesh_gpu_instancing",
        "EXT_meshopt_compression",
    };
    static const char *const neutral[] = {
        "KHR_texture_transform", "KHR_texture_basisu", "EXT_texture_webp",
        "EXT_texture_avif", "KHR_lights_punctual", "KHR_materials_",
    };
    for (const char *g : geometry)
        if (e == g) return true;
    for (const char *n : neutral) {
        size_t len = strlen(n);
        if (n[len - 1] == '_' ? e.compare(0, len, n) == 0 : e == n) return true;
    }
    return false;
}

/* EXT_meshopt_compression: decodes every buffer view that has it into
 * the view's own bytes (its buffer is the fallback buffer, which tinygltf
 * allocated, zeroed, when it has no uri), checking every range first. */
io_result decode_meshopt(const char *path, tinygltf::Model &g, io_error *err)
{
    for (size_t vi = 0; vi < g.bufferViews.size(); vi++) {
        tinygltf::BufferView &bv = g.bufferViews[vi];
        tinygltf::ExtensionMap::const_iterator it =
            bv.extensions.find("EXT_meshopt_compression");
        if (it == bv.extensions.end()) continue;
        const tinygltf::Value &e = it->second;
        auto num = [&](const char *k, long long dflt, long long *out) -> bool {
            if (!e.Has(k)) { *out = dflt; return dflt >= 0; }
            const tinygltf::Value &v = e.Get(k);
            if (!v.IsNumber() && !v.IsInt()) return false;
            double d = v.GetNumberAsDouble();
            if (!(d >= 0.0 && d <= 9.0e15) || d != std::floor(d)) return false;
            *out = (long long)d;
            return true;
        };
        long long src_buf, src_off, src_len, stride, count;
        if (!num("buffer", -1, &src_buf) || !num("byteOffset", 0, &src_off) ||
            !num("byteLength", -1, &src_len) || !num("byteStride", -1, &stride) ||
            !num("count", -1, &count))
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu: EXT_meshopt_compression needs "
                           "buffer, byteLength, byteStride and count as "
                           "non-negative integers", path, vi);
        std::string mode = e.Has("mode") ? e.Get("mode").Get<std::string>() : "";
        std::string filter = e.Has("filter") ? e.Get("filter").Get<std::string>() : "NONE";
        if ((size_t)src_buf >= g.buffers.size() ||
            (size_t)src_off > g.buffers[(size_t)src_buf].data.size() ||
            (size_t)src_len > g.buffers[(size_t)src_buf].data.size() - (size_t)src_off)
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu: EXT_meshopt_compression data "
                           "(buffer %lld, bytes %lld..%lld) lies outside its "
                           "buffer", path, vi, src_buf, src_off, src_off + src_len);
        if (count > (long long)MAX_COUNT || stride < 1 || stride > 256 ||
            (size_t)(count * stride) != bv.byteLength)
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu: EXT_meshopt_compression count "
                           "%lld x byteStride %lld does not give its byteLength "
                           "%zu", path, vi, count, stride, bv.byteLength);
        if (bv.buffer < 0 || (size_t)bv.buffer >= g.buffers.size() ||
            bv.byteOffset > g.buffers[(size_t)bv.buffer].data.size() ||
            bv.byteLength > g.buffers[(size_t)bv.buffer].data.size() - bv.byteOffset)
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu (the output of "
                           "EXT_meshopt_compression) lies outside its buffer",
                           path, vi);
        if (bv.buffer == (int)src_buf)
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu: EXT_meshopt_compression "
                           "decodes into the buffer it reads", path, vi);
        unsigned char *dst = g.buffers[(size_t)bv.buffer].data.data() + bv.byteOffset;
        const unsigned char *src = g.buffers[(size_t)src_buf].data.data() + src_off;
        int rc = -1;
        if (mode == "ATTRIBUTES") {
            if (stride % 4 != 0)
                return io_fail(err, IO_ERR_FORMAT,
                               "%s: buffer view %zu: EXT_meshopt_compression "
                               "ATTRIBUTES with byteStride %lld (a multiple of 4 "
                               "is required)", path, vi, stride);
            rc = meshopt_decodeVertexBuffer(dst, (size_t)count, (size_t)stride, src,
                                            (size_t)src_len);
            if (rc == 0 && filter == "OCTAHEDRAL" && (stride == 4 || stride == 8))
                meshopt_decodeFilterOct(dst, (size_t)count, (size_t)stride);
            else if (rc == 0 && filter == "QUATERNION" && stride == 8)
                meshopt_decodeFilterQuat(dst, (size_t)count, (size_t)stride);
            else if (rc == 0 && filter == "EXPONENTIAL")
                meshopt_decodeFilterExp(dst, (size_t)count, (size_t)stride);
            else if (rc == 0 && filter != "NONE")
                return io_fail(err, IO_ERR_FORMAT,
                               "%s: buffer view %zu: EXT_meshopt_compression "
                               "filter '%.20s' with byteStride %lld is not "
                               "defined", path, vi, filter.c_str(), stride);
        } else if (mode == "TRIANGLES" || mode == "INDICES") {
            if ((stride != 2 && stride != 4) || filter != "NONE" ||
                (mode == "TRIANGLES" && count % 3 != 0))
                return io_fail(err, IO_ERR_FORMAT,
                               "%s: buffer view %zu: EXT_meshopt_compression %s "
                               "with byteStride %lld, count %lld, filter %.20s",
                               path, vi, mode.c_str(), stride, count,
                               filter.c_str());
            rc = mode == "TRIANGLES"
                     ? meshopt_decodeIndexBuffer(dst, (size_t)count, (size_t)stride,
                                                 src, (size_t)src_len)
                     : meshopt_decodeIndexSequence(dst, (size_t)count, (size_t)stride,
                                                   src, (size_t)src_len);
        } else {
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu: EXT_meshopt_compression mode "
                           "'%.20s' (ATTRIBUTES, TRIANGLES or INDICES)", path,
                           vi, mode.c_str());
        }
        if (rc != 0)
            return io_fail(err, IO_ERR_FORMAT,
                           "%s: buffer view %zu: EXT_meshopt_compression data "
                           "does not decode (meshoptimizer error %d)", path, vi,
                           rc);
    }
    return IO_OK;
}

/* tinygltf 2.7 gives every buffer of a .glb without a uri the first
 * byteLength bytes of the BIN chunk, and refuses the file when byteLength
 * is larger than the chunk: the fallback buffers of EXT_meshopt_compression
 * (no uri, often larger than the compressed BIN) then fail to load. For a
 * .glb that names EXT_meshopt_compression, the BIN chunk is padded with
 * zeros to the largest byteLength written in the JSON (at most 1 GiB):
 * buffer 0 keeps its bytes, and the fallback buffers get room that
 * decode_meshopt overwrites. */
void pad_glb_for_meshopt(std::vector<unsigned char> &b)
{
    auto u32 = [&](size_t off) {
        uint32_t v;
        memcpy(&v, b.data() + off, 4);
        return v;
    };
    if (b.size() < 20 || memcmp(b.data(), "glTF", 4) != 0) return;
    uint32_t json_len = u32(12);
    if (u32(16) != 0x4E4F534Au || json_len > b.size() - 20) return;
    std::string json(reinterpret_cast<const char *>(b.data() + 20), json_len);
    if (json.find("EXT_meshopt_compression") == std::string::npos) return;
    unsigned long long need = 0;
    for (size_t at = json.find("\"byteLength\""); at != std::string::npos;
         at = json.find("\"byteLength\"", at + 1)) {
        size_t k = at + 12;
        while (k < json.size() && (json[k] == ' ' || json[k] == ':' ||
                                   json[k] == '\t' || json[k] == '\n' ||
                                   json[k] == '\r'))
            k++;
        unsigned long long v = 0;
        while (k < json.size() && json[k] >= '0' && json[k] <= '9' && v < (1ull << 40))
            v = v * 10 + (unsigned long long)(json[k++] - '0');
        need = std::max(need, v);
    }
    if (need > (1ull << 30)) return;
    size_t bin_at = 20 + (size_t)json_len;
    size_t bin_len = 0;
    if (b.size() >= bin_at + 8 && u32(bin_at + 4) == 0x004E4942u) {
        bin_len = u32(bin_at);
        if (bin_len > b.size() - bin_at - 8) return;
    } else if (b.size() != bin_at) {
        return;  /* another chunk: left to tinygltf */
    }
    if (need <= bin_len) return;
    size_t padded = ((size_t)need + 3) & ~(size_t)3;
    std::vector<unsigned char> out(b.begin(), b.begin() + (long)bin_at);
    out.resize(bin_at + 8 + padded, 0);
    if (bin_len) memcpy(out.data() + bin_at + 8, b.data() + bin_at + 8, bin_len);
    uint32_t v = (uint32_t)padded, type = 0x004E4942u, total = (uint32_t)out.size();
    memcpy(out.data() + bin_at, &v, 4);
    memcpy(out.data() + bin_at + 4, &type, 4);
    memcpy(out.data() + 8, &total, 4);
    b.swap(out);
}

/* The first extension of extensionsRequired egofuse does not implement,
 * or "". */
std::string unimplemented_required(const tinygltf::Model &g)
{
    for (const std::string &e : g.extensionsRequired)
        if (!extension_implemented(e)) return e;
    return std::string();
}

/* ------------------------------------------------- confined URIs */

/* External buffer and image URIs resolve only inside the model's folder
 * unless io_gltf_allow_outside(1) (docs/io.md): tinygltf percent-decodes
 * the URI, joins it to the base folder we give it (the model folder's
 * realpath) and passes the result to ExpandFilePath, which we replace:
 * an absolute URI, or one whose realpath (`..`, symlinks) is not under the
 * folder, is recorded and expanded to "" so that nothing is opened.
 * tinygltf's fallback of the current folder (a path not under the base)
 * is always refused. */
int g_allow_outside = 0;

struct Confine {
    std::string base;                 /* realpath of the model's folder */
    bool allow;
    std::vector<std::string> refused; /* decoded URIs refused, in order */
    std::vector<std::string> why;
};

std::string confine_expand(const std::string &joined, void *ud)
{
    Confine &c = *static_cast<Confine *>(ud);
    const std::string prefix = c.base == "/" ? c.base : c.base + "/";
    if (joined.compare(0, prefix.size(), prefix) != 0)
        return std::string();  /* tinygltf's "./uri" fallback */
    std::string rel = joined.substr(prefix.size());
    if (rel.empty()) return std::string();
    std::string cand = rel[0] == '/' ? rel : joined;
    if (c.allow) return cand;
    if (rel[0] == '/' && c.base != "/") {
        c.refused.push_back(rel);
        c.why.push_back("is an absolute path");
        return std::string();
    }
    char *rp = realpath(cand.c_str(), nullptr);
    if (!rp) return cand;  /* missing: tinygltf says "File not found" */
    std::string real(rp);
    free(rp);
    if (c.base != "/" && real.compare(0, prefix.size(), prefix) != 0) {
        c.refused.push_back(rel);
        c.why.push_back("leads outside the model's folder (to " + real +
                        ")");
        return std::string();
    }
    return real;
}

/* RFC 3986 percent-decoding as tinygltf does it (also '+' as a space). */
std::string uri_decode(const std::string &s)
{
    std::string r;
    for (size_t i = 0; i < s.size(); i++) {
        if (s[i] == '+') {
            r += ' ';
        } else if (s[i] == '%' && i + 2 < s.size()) {
            auto hex = [](char ch) -> int {
                if (ch >= '0' && ch <= '9') return ch - '0';
                if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
                if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
                return 0;
            };
            r += (char)((hex(s[i + 1]) << 4) | hex(s[i + 2]));
            i += 2;
        } else {
            r += s[i];
        }
    }
    return r;
}

/* The message for the first refused URI: an image still listed in the
 * model by its uri (tinygltf keeps going), else the buffer that stopped
 * the parse (buffers are parsed before images, one by one). */
io_result confine_fail(const char *path, const Confine &c,
                       const tinygltf::Model &g, io_error *err)
{
    const std::string &rel = c.refused[0];
    for (size_t i = 0; i < g.images.size(); i++)
        if (uri_decode(g.images[i].uri) == rel)
            return io_fail(err, IO_ERR_VALUE,
                           "%s: image %zu: uri '%.200s' %s; the model's folder "
                           "is %s; the "
                           "option --allow-outside allows it",
                           path, i, g.images[i].uri.c_str(), c.why[0].c_str(),
                           c.base.c_str());
    return io_fail(err, IO_ERR_VALUE,
                   "%s: buffer %zu: uri '%.200s' %s; the model's folder "
                   "is %s; the "
                   "option --allow-outside allows it",
                   path, g.buffers.size(), rel.c_str(), c.why[0].c_str(),
                   c.base.c_str());
}

io_result load(const char *path, int scene, kin_model *out, io_gltf_info *info,
               io_error *err)
{
    std::vector<unsigned char> bytes;
    io_result r = read_file(path, bytes, err);
    if (r != IO_OK) return r;
    if ((r = io_glb_check(path, bytes.data(), bytes.size(), err)) != IO_OK) return r;

    tinygltf::Model g;
    tinygltf::TinyGLTF parser;
    parser.SetImageLoader(skip_image, nullptr);
    std::string terr, twarn;
    Confine confine;
    {
        std::string dir = dir_of(path);
        char *rp = realpath(dir.empty() ? "." : dir.c_str(), nullptr);
        if (!rp)
            return io_fail(err, IO_ERR_READ, "%s: its folder: %s", path,
                           strerror(errno));
        confine.base = rp;
        free(rp);
    }
    confine.allow = g_allow_outside != 0;
    tinygltf::FsCallbacks fs = {&tinygltf::FileExists, &confine_expand,
                                &tinygltf::ReadWholeFile,
                                &tinygltf::WriteWholeFile, &confine};
    parser.SetFsCallbacks(fs);
    const std::string &base = confine.base;
    bool ok;
    const bool glb = bytes.size() >= 4 && memcmp(bytes.data(), "glTF", 4) == 0;
    if (glb) pad_glb_for_meshopt(bytes);
    if (bytes.size() >= 4 && memcmp(bytes.data(), "glTF", 4) == 0)
        ok = parser.LoadBinaryFromMemory(&g, &terr, &twarn, bytes.data(),
                                         (unsigned)bytes.size(), base);
    else if (bytes.empty())
        return io_fail(err, IO_ERR_FORMAT, "%s: empty file", path);
    else
        ok = parser.LoadASCIIFromString(
            &g, &terr, &twarn, reinterpret_cast<const char *>(bytes.data()),
            (unsigned)bytes.size(), base);
    if (!confine.refused.empty()) return confine_fail(path, confine, g, err);
    /* tinygltf reads extensionsRequired before the buffers, so a file it
     * cannot load (Draco, meshopt) is still refused by name. */
    std::string missing = unimplemented_required(g);
    if (!missing.empty())
        return io_fail(err, IO_ERR_FORMAT,
                       "%s: requires extension %.80s, which egofuse does not "
                       "implement", path, missing.c_str());
    if (!ok) {
        const char *hint = "";
        for (const std::string &e : g.extensionsUsed)
            if (e == "EXT_meshopt_compression" && !glb)
                hint = " (EXT_meshopt_compression in a .gltf: tinygltf 2.7 "
                       "cannot load its fallback buffer without a uri; egofuse "
                       "decodes meshopt in .glb files, e.g. gltfpack -c -o "
                       "file.glb)";
            else if (e == "KHR_meshopt_compression")
                hint = " (the file uses meshopt compression, which egofuse "
                       "does not implement)";
            else if (e == "KHR_draco_mesh_compression")
                hint = " (the file uses KHR_draco_mesh_compression, which "
                       "egofuse does not implement)";
        return io_fail(err, IO_ERR_FORMAT, "%s: %s%s", path,
                       one_line(terr).c_str(), hint);
    }
    std::vector<unsigned char>().swap(bytes);
    bool meshopt = false;
    for (const std::string &e : g.extensionsUsed)
        if (e == "EXT_meshopt_compression") meshopt = true;
    if (meshopt && (r = decode_meshopt(path, g, err)) != IO_OK) return r;

    Loader L;
    L.path = path;
    L.g = &g;
    L.out = out;
    L.err = err;
    L.info = info;
    L.scene_request = scene;
    L.quantization = false;
    for (const std::string &e : g.extensionsUsed)
        if (e == "KHR_mesh_quantization") L.quantization = true;
    if ((r = load_nodes(L)) != IO_OK) return r;
    if ((r = load_skins(L)) != IO_OK) return r;
    if ((r = load_meshes(L)) != IO_OK) return r;
    if ((r = load_animations(L)) != IO_OK) return r;

    char why[512];
    if (kin_model_validate(out, why, sizeof why) != 0)
        return io_fail(err, IO_ERR_FORMAT, "%s: %s", path, why);
    return IO_OK;
}

}  // namespace
}  // namespace io_gltf_impl

using io_gltf_impl::g_allow_outside;
using io_gltf_impl::load;

extern "C" void io_gltf_allow_outside(int allow)
{
    g_allow_outside = allow != 0;
}

extern "C" io_result io_gltf_load(const char *path, kin_model *out,
                                  io_error *err)
{
    return io_gltf_load_ex(path, -1, out, NULL, err);
}

extern "C" io_result io_gltf_load_ex(const char *path, int scene,
                                     kin_model *out, io_gltf_info *info,
                                     io_error *err)
{
    io_gltf_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    info->scene = -1;
    if (!out) return io_fail(err, IO_ERR_ARGS, "io_gltf_load: no output model");
    memset(out, 0, sizeof *out);
    if (!path || !*path)
        return io_fail(err, IO_ERR_ARGS, "io_gltf_load: no path");
    io_result r = io_cxx::guard(path, err, IO_ERR_FORMAT, nullptr,
                                [&] { return load(path, scene < 0 ? -1 : scene, out, info, err); });
    if (r != IO_OK) kin_model_free(out);  /* frees and zeroes */
    else if (err) io_fail(err, IO_OK, "%s", "ok");
    return r;
}
