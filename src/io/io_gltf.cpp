/* io_gltf.cpp - glTF 2.0 loading (tinygltf) into a kin_model.
 *
 * The only C++ of the glTF side: tinygltf parses the file, this shim
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
 *
 * WHY ONE FILE OF THIS LENGTH
 *   One job: one tinygltf::Model turned into one kin_model. Nodes, meshes,
 *   skins, animations, files and confined URIs (the sections below) all
 *   read the same tinygltf model through the same bounds-checked accessor
 *   readers and fail through the same io_error path; split, each part would
 *   need those C++ types in a shared header and every file would compile
 *   <tiny_gltf.h> (nlohmann json, stb_image), the slowest header of the
 *   build, once more.
 */
#include <tiny_gltf.h>
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

extern "C" {
#include "io.h"
}
#include "io_cxx.hpp"

namespace {

/* Largest element count accepted for one accessor: keeps every size
 * computation below far from overflow and vertex counts within int. */
const size_t MAX_COUNT = (size_t)1 << 26;

/* The state of one load: the source model, the output and the error. */
/* Largest number of floats of all morph target deltas of one primitive. */
const size_t MAX_TARGET_FLOATS = (size_t)1 << 28;

/* One instance of EXT_mesh_gpu_instancing: a node added as a child of the
 * instancing node, with the instance's TRS as its rest transform. */
struct Instance {
    int src;               /* source node that has the extension */
    kin_transform trs;
};

struct Loader {
    const char *path;
    const tinygltf::Model *g;
    kin_model *out;
    io_error *err;
    io_gltf_info *info;
    int scene_request;               /* -1: the default scene */
    bool quantization;               /* KHR_mesh_quantization declared */
    std::vector<int> sorted_of_src;  /* source node index -> sorted index */
    std::vector<char> in_scene;      /* source node is drawn */
    std::vector<Instance> instances; /* appended after the source nodes */
    std::vector<int> first_instance; /* source node -> index in instances, or -1 */
    std::vector<int> instance_count; /* source node -> its instances */
};

template <typename T>
T *alloc_n(Loader &L, size_t n)
{
    void *p = kin_block_alloc(&L.out->block, n * sizeof(T));
    if (!p) throw std::bad_alloc();
    return static_cast<T *>(p);
}

/* Skips embedded and external images: egofuse only needs geometry, and
 * decoding a JPEG/PNG texture would only cost time. */
bool skip_image(tinygltf::Image *, const int, std::string *, std::string *,
                int, int, const unsigned char *, int, void *)
{
    return true;
}

void copy_name(char *dst, const std::string &src)
{
    size_t n = std::min(src.size(), (size_t)KIN_NAME_MAX - 1);
    memcpy(dst, src.data(), n);
    dst[n] = '\0';
}

const char *type_name(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown type";
    }
}

const char *ctype_name(int ct)
{
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    default: return "unknown component type";
    }
}

size_t ctype_size(int ct)
{
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

int type_comps(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

/* One component at p (little-endian, as glTF stores it), normalised to
 * [0,1] / [-1,1] by the glTF rules when `normalized`. */
double read_comp(const unsigned char *p, int ct, bool normalized)
{
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t v; memcpy(&v, p, 1);
        return normalized ? std::max(v / 127.0, -1.0) : (double)v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        uint8_t v; memcpy(&v, p, 1);
        return normalized ? v / 255.0 : (double)v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v; memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : (double)v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v; memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : (double)v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v; memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : (double)v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v; memcpy(&v, p, 4);
        return (double)v;
    }
    default: return 0.0;
    }
}

/* What a caller expects of an accessor. */
enum { NORM_ANY = 0, NORM_REQUIRED = 1, NORM_FORBIDDEN = 2 };

struct Want {
    const char *what;      /* for messages, e.g. "JOINTS_0 of mesh 0 primitive 1" */
    int type;              /* TINYGLTF_TYPE_* */
    unsigned ctypes;       /* bit (ct - 5120) for each accepted component type */
    int norm;              /* NORM_*: integer types must (not) be normalized */
};

inline unsigned ct_bit(int ct) { return 1u << (unsigned)(ct - 5120); }

const unsigned CT_FLOAT = 1u << (TINYGLTF_COMPONENT_TYPE_FLOAT - 5120);

/* Checks that [offset, offset + size) of buffer view `bv` lies inside the
 * view and the view inside its buffer; returns the first byte. */
io_result view_span(Loader &L, int acc, const char *what, int bv_index,
                    size_t offset, size_t size, const unsigned char **first)
{
    const tinygltf::Model &g = *L.g;
    if (bv_index < 0 || (size_t)bv_index >= g.bufferViews.size())
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) names buffer view %d of %zu",
                       L.path, acc, what, bv_index, g.bufferViews.size());
    const tinygltf::BufferView &bv = g.bufferViews[(size_t)bv_index];
    if (bv.buffer < 0 || (size_t)bv.buffer >= g.buffers.size())
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: buffer view %d names buffer %d of %zu", L.path,
                       bv_index, bv.buffer, g.buffers.size());
    const tinygltf::Buffer &buf = g.buffers[(size_t)bv.buffer];
    if (bv.byteOffset > buf.data.size() ||
        bv.byteLength > buf.data.size() - bv.byteOffset)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: buffer view %d (offset %zu, length %zu) lies past "
                       "the end of buffer %d (%zu bytes)", L.path, bv_index,
                       bv.byteOffset, bv.byteLength, bv.buffer, buf.data.size());
    if (offset > bv.byteLength || size > bv.byteLength - offset)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) reads past the end of buffer "
                       "view %d (bytes %zu..%zu of %zu)", L.path, acc, what,
                       bv_index, offset, offset + size, bv.byteLength);
    *first = buf.data.data() + bv.byteOffset + offset;
    return IO_OK;
}

/* Decodes accessor `acc` into out (count * comps doubles, normalised
 * integers converted), with every read bounds-checked. Sparse accessors
 * are applied on top of their base (zeros without a buffer view). */
io_result decode(Loader &L, int acc, const Want &w, std::vector<double> &out,
                 size_t *count_out)
{
    const tinygltf::Model &g = *L.g;
    if (acc < 0 || (size_t)acc >= g.accessors.size())
        return io_fail(L.err, IO_ERR_FORMAT, "%s: %s names accessor %d of %zu",
                       L.path, w.what, acc, g.accessors.size());
    const tinygltf::Accessor &a = g.accessors[(size_t)acc];
    int ct = a.componentType;
    size_t csize = ctype_size(ct);
    if (a.type != w.type || csize == 0 || !(ct_bit(ct) & w.ctypes))
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) is %s %s, which is not supported "
                       "here", L.path, acc, w.what, ctype_name(ct),
                       type_name(a.type));
    if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT && w.norm == NORM_REQUIRED &&
        !a.normalized)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) is %s but not normalized", L.path,
                       acc, w.what, ctype_name(ct));
    if (a.normalized && (ct == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                         ct == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT ||
                         w.norm == NORM_FORBIDDEN))
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) is %s and normalized, which it "
                       "must not be", L.path, acc, w.what, ctype_name(ct));
    if (a.count > MAX_COUNT)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) has %zu elements (at most %zu)",
                       L.path, acc, w.what, a.count, MAX_COUNT);
    int comps = type_comps(a.type);
    size_t elem = csize * (size_t)comps;
    size_t n = a.count;
    out.assign(n * (size_t)comps, 0.0);
    bool norm = a.normalized;

    if (a.bufferView >= 0 && n > 0) {
        const tinygltf::BufferView &bv =
            (size_t)a.bufferView < g.bufferViews.size()
                ? g.bufferViews[(size_t)a.bufferView] : tinygltf::BufferView();
        size_t stride = bv.byteStride ? bv.byteStride : elem;
        if (stride < elem)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s): byteStride %zu of buffer "
                           "view %d is smaller than its %zu-byte elements",
                           L.path, acc, w.what, stride, a.bufferView, elem);
        const unsigned char *p = nullptr;
        io_result r = view_span(L, acc, w.what, a.bufferView, a.byteOffset,
                                (n - 1) * stride + elem, &p);
        if (r != IO_OK) return r;
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < comps; c++)
                out[i * (size_t)comps + (size_t)c] =
                    read_comp(p + i * stride + (size_t)c * csize, ct, norm);
    } else if (a.bufferView < 0 && !a.sparse.isSparse && n > 0) {
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) has neither a buffer view nor "
                       "sparse data", L.path, acc, w.what);
    }

    if (a.sparse.isSparse) {
        int sc = a.sparse.count;
        int ict = a.sparse.indices.componentType;
        size_t isize = ctype_size(ict);
        if (sc < 1 || (size_t)sc > n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: sparse accessor %d (%s) has %d sparse values "
                           "for %zu elements", L.path, acc, w.what, sc, n);
        if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: sparse accessor %d (%s) has indices of type "
                           "%s", L.path, acc, w.what, ctype_name(ict));
        if (a.sparse.indices.byteOffset < 0 || a.sparse.values.byteOffset < 0)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: sparse accessor %d (%s) has a negative offset",
                           L.path, acc, w.what);
        const unsigned char *ip = nullptr, *vp = nullptr;
        io_result r = view_span(L, acc, w.what, a.sparse.indices.bufferView,
                                (size_t)a.sparse.indices.byteOffset,
                                (size_t)sc * isize, &ip);
        if (r != IO_OK) return r;
        r = view_span(L, acc, w.what, a.sparse.values.bufferView,
                      (size_t)a.sparse.values.byteOffset, (size_t)sc * elem, &vp);
        if (r != IO_OK) return r;
        for (size_t k = 0; k < (size_t)sc; k++) {
            double di = read_comp(ip + k * isize, ict, false);
            if (!(di < (double)n))
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: sparse accessor %d (%s): index %.0f is "
                               "past its %zu elements", L.path, acc, w.what,
                               di, n);
            size_t i = (size_t)di;
            for (int c = 0; c < comps; c++)
                out[i * (size_t)comps + (size_t)c] =
                    read_comp(vp + k * elem + (size_t)c * csize, ct, norm);
        }
    }
    *count_out = n;
    return IO_OK;
}

io_result check_finite(Loader &L, const std::vector<double> &v, int acc,
                       const char *what)
{
    for (size_t i = 0; i < v.size(); i++)
        if (!std::isfinite(v[i]) ||
            std::fabs(v[i]) > (double)std::numeric_limits<float>::max())
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s) holds a non-finite value",
                           L.path, acc, what);
    return IO_OK;
}

float *to_floats(Loader &L, const std::vector<double> &v)
{
    float *f = alloc_n<float>(L, v.size());
    for (size_t i = 0; i < v.size(); i++) f[i] = (float)v[i];
    return f;
}

/* ------------------------------------------------------------- nodes */

/* Quaternion (x, y, z, w) of a rotation matrix r[col][row] (Shepperd). */
kin_quat quat_from_rot(const double r[3][3])
{
    /* element (row i, col j) */
#define R_(i, j) r[j][i]
    double tr = R_(0, 0) + R_(1, 1) + R_(2, 2);
    double x, y, z, w;
    if (tr > 0.0) {
        double s = std::sqrt(tr + 1.0) * 2.0;
        w = 0.25 * s;
        x = (R_(2, 1) - R_(1, 2)) / s;
        y = (R_(0, 2) - R_(2, 0)) / s;
        z = (R_(1, 0) - R_(0, 1)) / s;
    } else if (R_(0, 0) > R_(1, 1) && R_(0, 0) > R_(2, 2)) {
        double s = std::sqrt(1.0 + R_(0, 0) - R_(1, 1) - R_(2, 2)) * 2.0;
        w = (R_(2, 1) - R_(1, 2)) / s;
        x = 0.25 * s;
        y = (R_(0, 1) + R_(1, 0)) / s;
        z = (R_(0, 2) + R_(2, 0)) / s;
    } else if (R_(1, 1) > R_(2, 2)) {
        double s = std::sqrt(1.0 + R_(1, 1) - R_(0, 0) - R_(2, 2)) * 2.0;
        w = (R_(0, 2) - R_(2, 0)) / s;
        x = (R_(0, 1) + R_(1, 0)) / s;
        y = 0.25 * s;
        z = (R_(1, 2) + R_(2, 1)) / s;
    } else {
        double s = std::sqrt(1.0 + R_(2, 2) - R_(0, 0) - R_(1, 1)) * 2.0;
        w = (R_(1, 0) - R_(0, 1)) / s;
        x = (R_(0, 2) + R_(2, 0)) / s;
        y = (R_(1, 2) + R_(2, 1)) / s;
        z = 0.25 * s;
    }
#undef R_
    double len = std::sqrt(x * x + y * y + z * z + w * w);
    kin_quat q = {0.0f, 0.0f, 0.0f, 1.0f};
    if (len > 0.0 && std::isfinite(len)) {
        if (w < 0.0) len = -len;  /* canonical: w >= 0 */
        q.x = (float)(x / len); q.y = (float)(y / len);
        q.z = (float)(z / len); q.w = (float)(w / len);
    }
    return q;
}

/* TRS of a column-major 4x4 matrix: translation from column 3, scale =
 * column lengths (one axis negated when the determinant is negative),
 * rotation from the normalised columns. */
io_result decompose(Loader &L, int src, const std::vector<double> &m,
                    kin_transform *t)
{
    for (double v : m)
        if (!std::isfinite(v))
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d has a non-finite matrix", L.path, src);
    t->t = kin_vec3{(float)m[12], (float)m[13], (float)m[14]};
    double c[3][3], s[3];
    for (int j = 0; j < 3; j++) {
        for (int i = 0; i < 3; i++) c[j][i] = m[(size_t)(j * 4 + i)];
        s[j] = std::sqrt(c[j][0] * c[j][0] + c[j][1] * c[j][1] +
                         c[j][2] * c[j][2]);
    }
    double det = c[0][0] * (c[1][1] * c[2][2] - c[2][1] * c[1][2]) -
                 c[1][0] * (c[0][1] * c[2][2] - c[2][1] * c[0][2]) +
                 c[2][0] * (c[0][1] * c[1][2] - c[1][1] * c[0][2]);
    if (det < 0.0) s[0] = -s[0];
    t->s = kin_vec3{(float)s[0], (float)s[1], (float)s[2]};
    if (s[0] == 0.0 || s[1] == 0.0 || s[2] == 0.0) {
        t->r = kin_quat{0.0f, 0.0f, 0.0f, 1.0f};  /* degenerate: no rotation */
        return IO_OK;
    }
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < 3; i++) c[j][i] /= s[j];
    t->r = quat_from_rot(c);
    return IO_OK;
}

io_result node_transform(Loader &L, int src, kin_transform *t)
{
    const tinygltf::Node &n = L.g->nodes[(size_t)src];
    *t = kin_transform{{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f},
                       {1.0f, 1.0f, 1.0f}};
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d has a matrix of %zu numbers", L.path,
                           src, n.matrix.size());
        return decompose(L, src, n.matrix, t);
    }
    if ((!n.translation.empty() && n.translation.size() != 3) ||
        (!n.rotation.empty() && n.rotation.size() != 4) ||
        (!n.scale.empty() && n.scale.size() != 3))
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: node %d has a translation, rotation or scale of "
                       "the wrong size", L.path, src);
    bool finite = true;
    for (double v : n.translation) finite = finite && std::isfinite(v);
    for (double v : n.rotation) finite = finite && std::isfinite(v);
    for (double v : n.scale) finite = finite && std::isfinite(v);
    if (!finite)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: node %d has a non-finite transform", L.path, src);
    if (!n.translation.empty())
        t->t = kin_vec3{(float)n.translation[0], (float)n.translation[1],
                        (float)n.translation[2]};
    if (!n.scale.empty())
        t->s = kin_vec3{(float)n.scale[0], (float)n.scale[1],
                        (float)n.scale[2]};
    if (!n.rotation.empty()) {
        const std::vector<double> &q = n.rotation;
        double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] +
                               q[3] * q[3]);
        if (!(len > 0.0) || !std::isfinite(len))
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d has a zero rotation quaternion",
                           L.path, src);
        t->r = kin_quat{(float)(q[0] / len), (float)(q[1] / len),
                        (float)(q[2] / len), (float)(q[3] / len)};
    }
    return IO_OK;
}

/* Component types of quantized attributes (KHR_mesh_quantization). */
const unsigned CT_INT8_16 = (1u << (TINYGLTF_COMPONENT_TYPE_BYTE - 5120)) |
                            (1u << (TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE - 5120)) |
                            (1u << (TINYGLTF_COMPONENT_TYPE_SHORT - 5120)) |
                            (1u << (TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT - 5120));
const unsigned CT_SIGNED8_16 = (1u << (TINYGLTF_COMPONENT_TYPE_BYTE - 5120)) |
                               (1u << (TINYGLTF_COMPONENT_TYPE_SHORT - 5120));

/* Before decoding an attribute of a component type that only
 * KHR_mesh_quantization allows: refuses it, naming the extension, when
 * the file does not declare it. */
io_result need_quantization(Loader &L, int acc, const char *what)
{
    const tinygltf::Model &g = *L.g;
    if (L.quantization || acc < 0 || (size_t)acc >= g.accessors.size())
        return IO_OK;
    const tinygltf::Accessor &a = g.accessors[(size_t)acc];
    if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) return IO_OK;
    return io_fail(L.err, IO_ERR_FORMAT,
                   "%s: accessor %d (%s) is %s%s %s, which needs "
                   "KHR_mesh_quantization, not in the file's extensionsUsed",
                   L.path, acc, what, a.normalized ? "normalized " : "",
                   ctype_name(a.componentType), type_name(a.type));
}

/* EXT_mesh_gpu_instancing of the drawn mesh nodes, in sorted node order:
 * TRANSLATION / ROTATION / SCALE per instance (each optional, the same
 * count). */
io_result load_instances(Loader &L, const std::vector<int> &order)
{
    const tinygltf::Model &g = *L.g;
    L.first_instance.assign(g.nodes.size(), -1);
    L.instance_count.assign(g.nodes.size(), 0);
    for (int src : order) {
        const tinygltf::Node &n = g.nodes[(size_t)src];
        if (!L.in_scene[(size_t)src] || n.mesh < 0) continue;
        tinygltf::ExtensionMap::const_iterator it =
            n.extensions.find("EXT_mesh_gpu_instancing");
        if (it == n.extensions.end()) continue;
        if (n.skin >= 0)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d: EXT_mesh_gpu_instancing of a skinned "
                           "mesh, which egofuse does not implement", L.path, src);
        const tinygltf::Value &attrs = it->second.Get("attributes");
        if (!attrs.IsObject())
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d: EXT_mesh_gpu_instancing without "
                           "attributes", L.path, src);
        static const char *const names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
        std::vector<double> v[3];
        size_t cnt[3] = {0, 0, 0};
        bool have[3] = {false, false, false};
        size_t count = 0;
        for (int k = 0; k < 3; k++) {
            if (!attrs.Has(names[k])) continue;
            const tinygltf::Value &ix = attrs.Get(names[k]);
            if (!ix.IsNumber() && !ix.IsInt())
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: node %d: EXT_mesh_gpu_instancing %s is not "
                               "an accessor index", L.path, src, names[k]);
            int acc = ix.GetNumberAsInt();
            char what[96];
            snprintf(what, sizeof what, "EXT_mesh_gpu_instancing %s of node %d",
                     names[k], src);
            io_result r = need_quantization(L, acc, what);
            if (r != IO_OK) return r;
            Want w = {what, k == 1 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                      k == 1 ? (CT_FLOAT | CT_SIGNED8_16) : (CT_FLOAT | CT_INT8_16),
                      k == 1 ? NORM_REQUIRED : NORM_ANY};
            if ((r = decode(L, acc, w, v[k], &cnt[k])) != IO_OK) return r;
            if ((r = check_finite(L, v[k], acc, what)) != IO_OK) return r;
            if (count && cnt[k] != count)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: node %d: EXT_mesh_gpu_instancing %s has %zu "
                               "elements, the other attributes %zu", L.path,
                               src, names[k], cnt[k], count);
            count = cnt[k];
            have[k] = true;
        }
        if (!have[0] && !have[1] && !have[2])
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d: EXT_mesh_gpu_instancing without "
                           "TRANSLATION, ROTATION or SCALE", L.path, src);
        if (count > KIN_MAX_NODES)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d: %zu EXT_mesh_gpu_instancing instances "
                           "(at most %d nodes in all)", L.path, src, count,
                           KIN_MAX_NODES);
        L.first_instance[(size_t)src] = (int)L.instances.size();
        L.instance_count[(size_t)src] = (int)count;
        for (size_t i = 0; i < count; i++) {
            Instance in;
            in.src = src;
            in.trs = kin_transform{{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f, 1.0f},
                                   {1.0f, 1.0f, 1.0f}};
            if (have[0])
                in.trs.t = kin_vec3{(float)v[0][i * 3], (float)v[0][i * 3 + 1],
                                    (float)v[0][i * 3 + 2]};
            if (have[2])
                in.trs.s = kin_vec3{(float)v[2][i * 3], (float)v[2][i * 3 + 1],
                                    (float)v[2][i * 3 + 2]};
            if (have[1]) {
                const double *q = &v[1][i * 4];
                double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] +
                                       q[3] * q[3]);
                if (!(len > 0.0))
                    return io_fail(L.err, IO_ERR_FORMAT,
                                   "%s: node %d: EXT_mesh_gpu_instancing "
                                   "instance %zu has a zero rotation", L.path,
                                   src, i);
                in.trs.r = kin_quat{(float)(q[0] / len), (float)(q[1] / len),
                                    (float)(q[2] / len), (float)(q[3] / len)};
            }
            L.instances.push_back(in);
            if (L.instances.size() > KIN_MAX_NODES)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: more than %d EXT_mesh_gpu_instancing "
                               "instances", L.path, KIN_MAX_NODES);
        }
    }
    return IO_OK;
}

/* Parents from the children lists, then a depth-first order from the
 * roots of the default scene (or scene 0), then the other roots. */
io_result load_nodes(Loader &L)
{
    const tinygltf::Model &g = *L.g;
    size_t count = g.nodes.size();
    if (count > KIN_MAX_NODES)
        return io_fail(L.err, IO_ERR_FORMAT, "%s: %zu nodes (at most %d)",
                       L.path, count, KIN_MAX_NODES);
    std::vector<int> parent(count, -1);
    for (size_t i = 0; i < count; i++) {
        for (int c : g.nodes[i].children) {
            if (c < 0 || (size_t)c >= count)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: node %zu has child %d of %zu nodes",
                               L.path, i, c, count);
            if ((size_t)c == i)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: node %zu is its own child (cycle)",
                               L.path, i);
            if (parent[(size_t)c] >= 0)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: node %d has two parents (%d and %zu)",
                               L.path, c, parent[(size_t)c], i);
            parent[(size_t)c] = (int)i;
        }
    }
    std::vector<int> roots;
    std::vector<char> queued(count, 0);
    int scene = g.defaultScene >= 0 ? g.defaultScene : (g.scenes.empty() ? -1 : 0);
    if (L.scene_request >= 0) {
        if ((size_t)L.scene_request >= g.scenes.size())
            return io_fail(L.err, IO_ERR_ARGS,
                           "%s: scene %d requested, but the file has %zu "
                           "scene%s", L.path, L.scene_request, g.scenes.size(),
                           g.scenes.size() == 1 ? "" : "s");
        scene = L.scene_request;
    } else if (scene >= 0 && (size_t)scene >= g.scenes.size()) {
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: the default scene is %d, but the file has %zu "
                       "scene%s", L.path, scene, g.scenes.size(),
                       g.scenes.size() == 1 ? "" : "s");
    }
    if (L.info) {
        L.info->scene = scene;
        L.info->scene_count = (int)g.scenes.size();
    }
    if (scene >= 0 && (size_t)scene < g.scenes.size()) {
        for (int r : g.scenes[(size_t)scene].nodes) {
            if (r < 0 || (size_t)r >= count)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: scene %d names node %d of %zu", L.path,
                               scene, r, count);
            /* a non-root listed in a scene is reached through its parent */
            if (parent[(size_t)r] < 0 && !queued[(size_t)r]) {
                roots.push_back(r);
                queued[(size_t)r] = 1;
            }
        }
    }
    for (size_t i = 0; i < count; i++)
        if (parent[i] < 0 && !queued[i]) roots.push_back((int)i);

    std::vector<int> order;
    order.reserve(count);
    L.sorted_of_src.assign(count, -1);
    std::vector<int> stack;
    for (int r : roots) {
        stack.push_back(r);
        while (!stack.empty()) {
            int n = stack.back();
            stack.pop_back();
            L.sorted_of_src[(size_t)n] = (int)order.size();
            order.push_back(n);
            const std::vector<int> &ch = g.nodes[(size_t)n].children;
            for (size_t k = ch.size(); k-- > 0;) stack.push_back(ch[k]);
        }
    }
    if (order.size() != count) {
        for (size_t i = 0; i < count; i++)
            if (L.sorted_of_src[i] < 0)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: node %zu is part of a cycle", L.path, i);
    }

    /* The nodes drawn: those of the scene and their descendants (every
     * node when the file has no scene). */
    L.in_scene.assign(count, scene < 0 ? 1 : 0);
    if (scene >= 0) {
        for (int r : g.scenes[(size_t)scene].nodes) stack.push_back(r);
        while (!stack.empty()) {
            int n = stack.back();
            stack.pop_back();
            if (L.in_scene[(size_t)n]) continue;
            L.in_scene[(size_t)n] = 1;
            for (int c : g.nodes[(size_t)n].children) stack.push_back(c);
        }
    }
    io_result ri = load_instances(L, order);
    if (ri != IO_OK) return ri;
    size_t total = count + L.instances.size();
    if (total > KIN_MAX_NODES)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: %zu nodes and %zu EXT_mesh_gpu_instancing "
                       "instances (at most %d together)", L.path, count,
                       L.instances.size(), KIN_MAX_NODES);

    kin_model *m = L.out;
    int16_t *parents = alloc_n<int16_t>(L, total);
    kin_transform *rest = alloc_n<kin_transform>(L, total);
    char(*names)[KIN_NAME_MAX] =
        static_cast<char(*)[KIN_NAME_MAX]>(kin_block_alloc(
            &m->block, total * KIN_NAME_MAX));
    if (!names) throw std::bad_alloc();
    int *node_src = alloc_n<int>(L, total);
    for (size_t i = 0; i < count; i++) {
        int src = order[i];
        int p = parent[(size_t)src];
        parents[i] = (int16_t)(p < 0 ? KIN_NO_PARENT : L.sorted_of_src[(size_t)p]);
        node_src[i] = src;
        const std::string &nm = g.nodes[(size_t)src].name;
        if (nm.empty())
            snprintf(names[i], KIN_NAME_MAX, "node%d", src);
        else
            copy_name(names[i], nm);
        io_result r = node_transform(L, src, &rest[i]);
        if (r != IO_OK) return r;
    }
    /* instances: children of their node, after every source node */
    for (size_t k = 0; k < L.instances.size(); k++) {
        const Instance &in = L.instances[k];
        size_t i = count + k;
        parents[i] = (int16_t)L.sorted_of_src[(size_t)in.src];
        node_src[i] = in.src;
        rest[i] = in.trs;
        snprintf(names[i], KIN_NAME_MAX, "%.40s#%zu",
                 names[L.sorted_of_src[(size_t)in.src]],
                 k - (size_t)L.first_instance[(size_t)in.src]);
    }
    m->node_count = (int)total;
    m->parents = parents;
    m->rest = rest;
    m->names = names;
    m->node_src = node_src;
    return IO_OK;
}

/* ------------------------------------------------------------ meshes */

int find_attr(const tinygltf::Primitive &p, const char *name)
{
    std::map<std::string, int>::const_iterator it = p.attributes.find(name);
    return it == p.attributes.end() ? -1 : it->second;
}

/* Decodes one VEC3 attribute of n elements (POSITION, NORMAL, or one of a
 * morph target): float, or with KHR_mesh_quantization the integer types
 * `ints` (normalized as `norm` says); checks count and finiteness. */
io_result load_vec3(Loader &L, int acc, const char *what, unsigned ints,
                    int norm, size_t n, const char *count_label,
                    std::vector<double> &v)
{
    io_result r = need_quantization(L, acc, what);
    if (r != IO_OK) return r;
    size_t k = 0;
    r = decode(L, acc, Want{what, TINYGLTF_TYPE_VEC3, CT_FLOAT | ints, norm}, v, &k);
    if (r != IO_OK) return r;
    if (count_label && k != n)
        return io_fail(L.err, IO_ERR_FORMAT, "%s: %s has %zu elements, the "
                       "primitive %zu", L.path, count_label, k, n);
    return check_finite(L, v, acc, what);
}

/* Converts one primitive of mode TRIANGLES, TRIANGLE_STRIP or
 * TRIANGLE_FAN (arrays only; node, skin and morph weights are set by the
 * caller). `skinned` requires JOINTS_0 and WEIGHTS_0. */
io_result load_primitive(Loader &L, int mi, int pi, bool skinned,
                         kin_mesh *km)
{
    const tinygltf::Mesh &mesh = L.g->meshes[(size_t)mi];
    const tinygltf::Primitive &prim = mesh.primitives[(size_t)pi];
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    char label[160];
    char what[200];
    char clabel[240];
    if (mesh.name.empty())
        snprintf(label, sizeof label, "mesh %d primitive %d", mi, pi);
    else
        snprintf(label, sizeof label, "mesh %d '%.60s' primitive %d", mi,
                 mesh.name.c_str(), pi);
    std::vector<double> v;
    size_t n = 0, k = 0;
    io_result r;

    int pos = find_attr(prim, "POSITION");
    if (pos < 0)
        return io_fail(L.err, IO_ERR_MISSING, "%s: %s has no POSITION",
                       L.path, label);
    snprintf(what, sizeof what, "POSITION of %s", label);
    if ((r = need_quantization(L, pos, what)) != IO_OK) return r;
    r = decode(L, pos, Want{what, TINYGLTF_TYPE_VEC3, CT_FLOAT | CT_INT8_16,
                            NORM_ANY}, v, &n);
    if (r != IO_OK) return r;
    if (n == 0)
        return io_fail(L.err, IO_ERR_MISSING, "%s: %s has no vertices",
                       L.path, label);
    if ((r = check_finite(L, v, pos, what)) != IO_OK) return r;
    km->vertex_count = (int)n;
    km->positions = to_floats(L, v);

    int nrm = find_attr(prim, "NORMAL");
    if (nrm >= 0) {
        snprintf(what, sizeof what, "NORMAL of %s", label);
        snprintf(clabel, sizeof clabel, "%s: NORMAL", label);
        r = load_vec3(L, nrm, what, CT_SIGNED8_16, NORM_REQUIRED, n, clabel, v);
        if (r != IO_OK) return r;
        km->normals = to_floats(L, v);
    }

    /* Skin influences: every JOINTS_n / WEIGHTS_n pair, weights as stored
     * (a GPU sums them without renormalising). */
    std::vector<uint16_t> xj;
    std::vector<float> xw;
    int sets = 0;
    for (int set = 0; set < 64; set++) {
        char jn[16], wn[16];
        snprintf(jn, sizeof jn, "JOINTS_%d", set);
        snprintf(wn, sizeof wn, "WEIGHTS_%d", set);
        int jnt = find_attr(prim, jn);
        int wgt = find_attr(prim, wn);
        if (skinned && set == 0 && jnt < 0)
            return io_fail(L.err, IO_ERR_MISSING,
                           "%s: %s is skinned but has no JOINTS_0", L.path, label);
        if (skinned && set == 0 && wgt < 0)
            return io_fail(L.err, IO_ERR_MISSING,
                           "%s: %s is skinned but has no WEIGHTS_0", L.path, label);
        if (jnt < 0 && wgt < 0) break;
        if (jnt < 0 || wgt < 0) {
            if (set == 0 && !skinned) break;  /* unused: not read */
            return io_fail(L.err, IO_ERR_FORMAT, "%s: %s has %s without %s",
                           L.path, label, jnt < 0 ? wn : jn, jnt < 0 ? jn : wn);
        }
        if (set > 0 && !skinned) break;  /* only set 0 is kept unskinned */
        snprintf(what, sizeof what, "%s of %s", jn, label);
        r = decode(L, jnt, Want{what, TINYGLTF_TYPE_VEC4,
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT),
                                NORM_FORBIDDEN}, v, &k);
        if (r != IO_OK) return r;
        if (k != n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s) has %zu elements for %zu "
                           "vertices", L.path, jnt, what, k, n);
        std::vector<uint16_t> js(v.size());
        for (size_t i = 0; i < v.size(); i++) js[i] = (uint16_t)v[i];

        snprintf(what, sizeof what, "%s of %s", wn, label);
        r = decode(L, wgt, Want{what, TINYGLTF_TYPE_VEC4,
                                CT_FLOAT |
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT),
                                NORM_REQUIRED}, v, &k);
        if (r != IO_OK) return r;
        if (k != n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s) has %zu elements for %zu "
                           "vertices", L.path, wgt, what, k, n);
        if ((r = check_finite(L, v, wgt, what)) != IO_OK) return r;
        if (set == 0) {
            uint16_t *j = alloc_n<uint16_t>(L, js.size());
            std::copy(js.begin(), js.end(), j);
            km->joints = j;
            float *w = alloc_n<float>(L, v.size());
            for (size_t i = 0; i < v.size(); i++) w[i] = (float)v[i];
            km->weights = w;
        } else {
            xj.insert(xj.end(), js.begin(), js.end());
            for (size_t i = 0; i < v.size(); i++) xw.push_back((float)v[i]);
            sets = set;
        }
    }
    if (sets > 0) {
        /* per vertex: the extra sets one after the other */
        uint16_t *j = alloc_n<uint16_t>(L, xj.size());
        float *w = alloc_n<float>(L, xw.size());
        for (size_t vi = 0; vi < n; vi++)
            for (int e = 0; e < sets; e++)
                for (size_t c = 0; c < 4; c++) {
                    size_t from = ((size_t)e * n + vi) * 4 + c;
                    size_t to = (vi * (size_t)sets + (size_t)e) * 4 + c;
                    j[to] = xj[from];
                    w[to] = xw[from];
                }
        km->extra_sets = sets;
        km->joints_extra = j;
        km->weights_extra = w;
    }

    /* Morph targets: POSITION and NORMAL deltas (TANGENT is not used). */
    size_t nt = prim.targets.size();
    if (nt > 0) {
        if (nt > MAX_TARGET_FLOATS / 3 / n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: %s has %zu morph targets of %zu vertices: "
                           "more than %zu values", L.path, label, nt, n,
                           MAX_TARGET_FLOATS);
        float *tp = alloc_n<float>(L, nt * n * 3);
        float *tn = nullptr;
        bool any_n = false;
        for (size_t t = 0; t < nt; t++)
            if (prim.targets[t].count("NORMAL")) any_n = true;
        if (any_n && km->normals) tn = alloc_n<float>(L, nt * n * 3);
        for (size_t t = 0; t < nt; t++) {
            const std::map<std::string, int> &tg = prim.targets[t];
            std::map<std::string, int>::const_iterator it = tg.find("POSITION");
            if (it != tg.end()) {
                snprintf(what, sizeof what, "POSITION of %s target %zu", label, t);
                snprintf(clabel, sizeof clabel, "%s target %zu: POSITION", label, t);
                r = load_vec3(L, it->second, what, CT_SIGNED8_16, NORM_ANY, n,
                              clabel, v);
                if (r != IO_OK) return r;
                for (size_t i = 0; i < n * 3; i++) tp[t * n * 3 + i] = (float)v[i];
            }
            it = tg.find("NORMAL");
            if (it != tg.end()) {
                snprintf(what, sizeof what, "NORMAL of %s target %zu", label, t);
                snprintf(clabel, sizeof clabel, "%s target %zu: NORMAL", label, t);
                r = load_vec3(L, it->second, what, CT_SIGNED8_16, NORM_REQUIRED,
                              n, clabel, v);
                if (r != IO_OK) return r;
                if (tn)
                    for (size_t i = 0; i < n * 3; i++) tn[t * n * 3 + i] = (float)v[i];
            }
        }
        km->target_count = (int)nt;
        km->target_positions = tp;
        km->target_normals = tn;
    }

    /* Indices, then the triangles of the mode in the spec's vertex order. */
    std::vector<uint32_t> src;
    if (prim.indices >= 0) {
        snprintf(what, sizeof what, "indices of %s", label);
        r = decode(L, prim.indices,
                   Want{what, TINYGLTF_TYPE_SCALAR,
                        ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                        ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) |
                        ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT),
                        NORM_FORBIDDEN},
                   v, &k);
        if (r != IO_OK) return r;
        src.resize(k);
        for (size_t i = 0; i < k; i++) {
            if (!(v[i] < (double)n))
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: accessor %d (%s): index %zu is %.0f, past "
                               "the %zu vertices", L.path, prim.indices, what,
                               i, v[i], n);
            src[i] = (uint32_t)v[i];
        }
    } else {
        k = n;
        src.resize(n);
        for (size_t i = 0; i < n; i++) src[i] = (uint32_t)i;
    }
    const char *idx_what = prim.indices >= 0 ? "indices" : "vertices";
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (k % 3 != 0)
            return io_fail(L.err, IO_ERR_FORMAT,
                           prim.indices >= 0
                               ? "%s: %s has %zu indices, not a multiple of 3"
                               : "%s: %s is not indexed and has %zu vertices, "
                                 "not a multiple of 3",
                           L.path, label, k);
        uint32_t *idx = alloc_n<uint32_t>(L, k);
        std::copy(src.begin(), src.end(), idx);
        km->index_count = (int)k;
        km->indices = idx;
        return IO_OK;
    }
    const char *mname = mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "TRIANGLE_STRIP"
                                                             : "TRIANGLE_FAN";
    if (k < 3)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: %s is a %s of %zu %s (at least 3)", L.path, label,
                       mname, k, idx_what);
    size_t tris = k - 2;
    uint32_t *idx = alloc_n<uint32_t>(L, tris * 3);
    for (size_t i = 0; i < tris; i++) {
        uint32_t *o = idx + i * 3;
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            /* p_i = {v_i, v_(i+(1+i%2)), v_(i+(2-i%2))} */
            o[0] = src[i];
            o[1] = src[i + 1 + i % 2];
            o[2] = src[i + 2 - i % 2];
        } else {
            /* p_i = {v_(i+1), v_(i+2), v_0} */
            o[0] = src[i + 1];
            o[1] = src[i + 2];
            o[2] = src[0];
        }
    }
    km->index_count = (int)(tris * 3);
    km->indices = idx;
    return IO_OK;
}

/* The morph weights of node `src` for a primitive of mesh mi with nt
 * targets: the node's `weights`, else the mesh's, else zeros. */
io_result morph_defaults(Loader &L, int src, int mi, size_t nt,
                         const float **out)
{
    const tinygltf::Node &node = L.g->nodes[(size_t)src];
    const tinygltf::Mesh &mesh = L.g->meshes[(size_t)mi];
    *out = nullptr;
    if (nt == 0) return IO_OK;
    const std::vector<double> *w = nullptr;
    if (!node.weights.empty()) {
        if (node.weights.size() != nt)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: node %d has %zu weights for the %zu morph "
                           "targets of mesh %d", L.path, src,
                           node.weights.size(), nt, mi);
        w = &node.weights;
    } else if (!mesh.weights.empty()) {
        if (mesh.weights.size() != nt)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: mesh %d has %zu weights for %zu morph targets",
                           L.path, mi, mesh.weights.size(), nt);
        w = &mesh.weights;
    }
    float *f = alloc_n<float>(L, nt);
    for (size_t i = 0; w && i < nt; i++) {
        double d = (*w)[i];
        if (!std::isfinite(d) || std::fabs(d) > 1e30)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: %s %d has a non-finite morph weight", L.path,
                           w == &node.weights ? "node" : "mesh",
                           w == &node.weights ? src : mi);
        f[i] = (float)d;
    }
    *out = f;
    return IO_OK;
}

io_result load_meshes(Loader &L)
{
    const tinygltf::Model &g = *L.g;
    kin_model *m = L.out;
    std::vector<kin_mesh> meshes;
    /* primitives instanced by several nodes share their arrays */
    std::map<std::pair<int, int>, kin_mesh> done;
    const int src_nodes = (int)g.nodes.size();
    for (int i = 0; i < src_nodes; i++) {
        const int src = m->node_src[i];
        const tinygltf::Node &n = g.nodes[(size_t)src];
        if (n.mesh < 0 || !L.in_scene[(size_t)src]) continue;
        if ((size_t)n.mesh >= g.meshes.size())
            return io_fail(L.err, IO_ERR_FORMAT, "%s: node %d names mesh %d of %zu",
                           L.path, src, n.mesh, g.meshes.size());
        if (n.skin >= 0 && (size_t)n.skin >= g.skins.size())
            return io_fail(L.err, IO_ERR_FORMAT, "%s: node %d names skin %d of %zu",
                           L.path, src, n.skin, g.skins.size());
        const tinygltf::Mesh &mesh = g.meshes[(size_t)n.mesh];
        for (size_t p = 0; p < mesh.primitives.size(); p++) {
            const tinygltf::Primitive &prim = mesh.primitives[p];
            if (prim.targets.size() != mesh.primitives[0].targets.size())
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: mesh %d primitive %zu has %zu morph targets, "
                               "primitive 0 %zu", L.path, n.mesh, p,
                               prim.targets.size(),
                               mesh.primitives[0].targets.size());
            int mode = prim.mode;
            switch (mode) {
            case -1:
            case TINYGLTF_MODE_TRIANGLES:
            case TINYGLTF_MODE_TRIANGLE_STRIP:
            case TINYGLTF_MODE_TRIANGLE_FAN:
                break;
            case TINYGLTF_MODE_POINTS:
                if (L.info) L.info->skipped_points++;
                continue;
            case TINYGLTF_MODE_LINE:
            case TINYGLTF_MODE_LINE_LOOP:
            case TINYGLTF_MODE_LINE_STRIP:
                if (L.info) L.info->skipped_lines++;
                continue;
            default:
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: mesh %d primitive %zu has mode %d, not a "
                               "glTF primitive mode (0..6)", L.path, n.mesh, p,
                               mode);
            }
            std::pair<int, int> key(n.mesh, (int)p);
            kin_mesh km;
            std::map<std::pair<int, int>, kin_mesh>::iterator it = done.find(key);
            if (it != done.end() && (n.skin < 0 || it->second.weights)) {
                km = it->second;
            } else {
                memset(&km, 0, sizeof km);
                io_result r = load_primitive(L, n.mesh, (int)p, n.skin >= 0, &km);
                if (r != IO_OK) return r;
                done[key] = km;
            }
            io_result r = morph_defaults(L, src, n.mesh, (size_t)km.target_count,
                                         &km.target_weights);
            if (r != IO_OK) return r;
            km.skin = n.skin;
            if (L.info) {
                if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) L.info->strips++;
                if (mode == TINYGLTF_MODE_TRIANGLE_FAN) L.info->fans++;
            }
            int ni = L.instance_count[(size_t)src];
            if (ni == 0) {
                km.node = i;
                meshes.push_back(km);
                if (L.info && km.target_count) L.info->morph_meshes++;
                continue;
            }
            for (int k = 0; k < ni; k++) {
                km.node = src_nodes + L.first_instance[(size_t)src] + k;
                meshes.push_back(km);
                if (L.info) {
                    L.info->instances++;
                    if (km.target_count) L.info->morph_meshes++;
                }
            }
        }
    }
    if (meshes.empty())
        return io_fail(L.err, IO_ERR_MISSING, "%s: no triangle primitives%s",
                       L.path,
                       L.info && (L.info->skipped_points || L.info->skipped_lines)
                           ? " (POINTS and LINES are not drawn)" : "");
    kin_mesh *arr = alloc_n<kin_mesh>(L, meshes.size());
    std::copy(meshes.begin(), meshes.end(), arr);
    m->mesh_count = (int)meshes.size();
    m->meshes = arr;
    return IO_OK;
}

/* ------------------------------------------------------------- skins */

io_result load_skins(Loader &L)
{
    const tinygltf::Model &g = *L.g;
    kin_model *m = L.out;
    if (g.skins.empty()) return IO_OK;
    kin_skin *skins = alloc_n<kin_skin>(L, g.skins.size());
    for (size_t s = 0; s < g.skins.size(); s++) {
        const tinygltf::Skin &sk = g.skins[s];
        size_t jc = sk.joints.size();
        if (jc == 0)
            return io_fail(L.err, IO_ERR_FORMAT, "%s: skin %zu has no joints",
                           L.path, s);
        if (jc > 65535)
            return io_fail(L.err, IO_ERR_FORMAT, "%s: skin %zu has %zu joints",
                           L.path, s, jc);
        int *joints = alloc_n<int>(L, jc);
        for (size_t j = 0; j < jc; j++) {
            int src = sk.joints[j];
            if (src < 0 || src >= m->node_count)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: skin %zu joint %zu names node %d of %d",
                               L.path, s, j, src, m->node_count);
            joints[j] = L.sorted_of_src[(size_t)src];
        }
        kin_mat4 *ibm = alloc_n<kin_mat4>(L, jc);
        if (sk.inverseBindMatrices >= 0) {
            char what[64];
            snprintf(what, sizeof what, "inverseBindMatrices of skin %zu", s);
            std::vector<double> v;
            size_t n = 0;
            io_result r = decode(L, sk.inverseBindMatrices,
                                 Want{what, TINYGLTF_TYPE_MAT4, CT_FLOAT, false},
                                 v, &n);
            if (r != IO_OK) return r;
            if (n < jc)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: accessor %d (%s) has %zu matrices for %zu "
                               "joints", L.path, sk.inverseBindMatrices, what,
                               n, jc);
            if ((r = check_finite(L, v, sk.inverseBindMatrices, what)) != IO_OK)
                return r;
            for (size_t j = 0; j < jc; j++)
                for (size_t e = 0; e < 16; e++)
                    ibm[j].m[e] = (float)v[j * 16 + e];
        } else {
            for (size_t j = 0; j < jc; j++)
                for (size_t e = 0; e < 16; e++)
                    ibm[j].m[e] = (e % 5 == 0) ? 1.0f : 0.0f;
        }
        skins[s].joint_count = (int)jc;
        skins[s].joints = joints;
        skins[s].inverse_bind = ibm;
    }
    m->skin_count = (int)g.skins.size();
    m->skins = skins;
    return IO_OK;
}

/* -------------------------------------------------------- animations */

io_result load_animations(Loader &L)
{
    const tinygltf::Model &g = *L.g;
    kin_model *m = L.out;
    if (g.animations.empty()) return IO_OK;
    /* morph target count of the meshes of each node (-1: none) */
    std::vector<int> targets_of((size_t)m->node_count, -1);
    for (int i = 0; i < m->mesh_count; i++)
        if (m->meshes[i].target_count > 0 && m->meshes[i].node >= 0)
            targets_of[(size_t)m->meshes[i].node] = m->meshes[i].target_count;
    kin_animation *anims = alloc_n<kin_animation>(L, g.animations.size());
    for (size_t a = 0; a < g.animations.size(); a++) {
        const tinygltf::Animation &an = g.animations[a];
        copy_name(anims[a].name, an.name);
        std::vector<kin_channel> chans;
        float duration = 0.0f;
        for (size_t c = 0; c < an.channels.size(); c++) {
            const tinygltf::AnimationChannel &ch = an.channels[c];
            if (ch.target_node < 0) continue;  /* no target: skipped */
            if (ch.target_node >= m->node_count)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: animation %zu channel %zu targets node %d "
                               "of %d", L.path, a, c, ch.target_node,
                               m->node_count);
            kin_path path;
            if (ch.target_path == "translation") path = KIN_PATH_TRANSLATION;
            else if (ch.target_path == "rotation") path = KIN_PATH_ROTATION;
            else if (ch.target_path == "scale") path = KIN_PATH_SCALE;
            else if (ch.target_path == "weights") path = KIN_PATH_WEIGHTS;
            else continue;  /* extension paths (e.g. "pointer"): skipped */
            if (ch.sampler < 0 || (size_t)ch.sampler >= an.samplers.size())
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: animation %zu channel %zu names sampler %d "
                               "of %zu", L.path, a, c, ch.sampler,
                               an.samplers.size());
            const tinygltf::AnimationSampler &sm = an.samplers[(size_t)ch.sampler];
            kin_interp interp;
            if (sm.interpolation.empty() || sm.interpolation == "LINEAR")
                interp = KIN_INTERP_LINEAR;
            else if (sm.interpolation == "STEP") interp = KIN_INTERP_STEP;
            else if (sm.interpolation == "CUBICSPLINE") interp = KIN_INTERP_CUBICSPLINE;
            else
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: animation %zu sampler %d has interpolation "
                               "'%.40s'", L.path, a, ch.sampler,
                               sm.interpolation.c_str());
            char what[96];
            snprintf(what, sizeof what, "input of animation %zu channel %zu", a, c);
            std::vector<double> tv, ov;
            size_t keys = 0, outs = 0;
            io_result r = decode(L, sm.input,
                                 Want{what, TINYGLTF_TYPE_SCALAR, CT_FLOAT, false},
                                 tv, &keys);
            if (r != IO_OK) return r;
            if ((r = check_finite(L, tv, sm.input, what)) != IO_OK) return r;
            if (keys == 0)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: animation %zu channel %zu has no keys",
                               L.path, a, c);
            snprintf(what, sizeof what, "output of animation %zu channel %zu", a, c);
            unsigned ints = ct_bit(TINYGLTF_COMPONENT_TYPE_BYTE) |
                            ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                            ct_bit(TINYGLTF_COMPONENT_TYPE_SHORT) |
                            ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
            Want w = {what, TINYGLTF_TYPE_VEC3, CT_FLOAT, true};
            if (path == KIN_PATH_ROTATION) w = Want{what, TINYGLTF_TYPE_VEC4, CT_FLOAT | ints, true};
            if (path == KIN_PATH_WEIGHTS) w = Want{what, TINYGLTF_TYPE_SCALAR, CT_FLOAT | ints, true};
            if ((r = decode(L, sm.output, w, ov, &outs)) != IO_OK) return r;
            if ((r = check_finite(L, ov, sm.output, what)) != IO_OK) return r;
            size_t per_key = interp == KIN_INTERP_CUBICSPLINE ? 3 : 1;
            int comps = path == KIN_PATH_ROTATION ? 4 : 3;
            if (path == KIN_PATH_WEIGHTS) {
                if (outs == 0 || outs % (keys * per_key) != 0)
                    return io_fail(L.err, IO_ERR_FORMAT,
                                   "%s: accessor %d (%s) has %zu values for "
                                   "%zu keys", L.path, sm.output, what, outs, keys);
                comps = (int)(outs / (keys * per_key));
            } else if (outs != keys * per_key) {
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: accessor %d (%s) has %zu values for %zu "
                               "keys (%s)", L.path, sm.output, what, outs, keys,
                               sm.interpolation.c_str());
            }
            kin_channel kc;
            memset(&kc, 0, sizeof kc);
            kc.node = L.sorted_of_src[(size_t)ch.target_node];
            kc.path = path;
            kc.interp = interp;
            kc.key_count = (int)keys;
            kc.comps = comps;
            kc.times = to_floats(L, tv);
            kc.values = to_floats(L, ov);
            duration = std::max(duration, kc.times[keys - 1]);
            chans.push_back(kc);
            if (path != KIN_PATH_WEIGHTS) continue;
            int src = ch.target_node;
            int ni = L.instance_count.empty() ? 0 : L.instance_count[(size_t)src];
            int node = ni ? (int)g.nodes.size() + L.first_instance[(size_t)src] : kc.node;
            int nt = targets_of[(size_t)node];
            if (nt >= 0 && nt != comps)
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: animation %zu channel %zu has %d weights "
                               "per key for the %d morph targets of node %d",
                               L.path, a, c, comps, nt, src);
            /* instances (EXT_mesh_gpu_instancing) morph with their node */
            for (int k = 0; k < ni; k++) {
                kc.node = (int)g.nodes.size() + L.first_instance[(size_t)src] + k;
                chans.push_back(kc);
            }
        }
        kin_channel *arr = nullptr;
        if (!chans.empty()) {
            arr = alloc_n<kin_channel>(L, chans.size());
            std::copy(chans.begin(), chans.end(), arr);
        }
        anims[a].channel_count = (int)chans.size();
        anims[a].channels = arr;
        anims[a].duration = duration;
    }
    m->anim_count = (int)g.animations.size();
    m->anims = anims;
    return IO_OK;
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
