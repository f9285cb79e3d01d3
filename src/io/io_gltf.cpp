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
 */
#include <tiny_gltf.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
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

namespace {

/* Largest element count accepted for one accessor: keeps every size
 * computation below far from overflow and vertex counts within int. */
const size_t MAX_COUNT = (size_t)1 << 26;

/* The state of one load: the source model, the output and the error. */
struct Loader {
    const char *path;
    const tinygltf::Model *g;
    kin_model *out;
    io_error *err;
    std::vector<int> sorted_of_src;  /* source node index -> sorted index */
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
struct Want {
    const char *what;      /* for messages, e.g. "JOINTS_0 of mesh 0 primitive 1" */
    int type;              /* TINYGLTF_TYPE_* */
    unsigned ctypes;       /* bit (ct - 5120) for each accepted component type */
    bool need_normalized;  /* integer component types must be normalized */
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
    if (ct != TINYGLTF_COMPONENT_TYPE_FLOAT && w.need_normalized &&
        !a.normalized)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) is %s but not normalized", L.path,
                       acc, w.what, ctype_name(ct));
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

    kin_model *m = L.out;
    int16_t *parents = alloc_n<int16_t>(L, count);
    kin_transform *rest = alloc_n<kin_transform>(L, count);
    char(*names)[KIN_NAME_MAX] =
        static_cast<char(*)[KIN_NAME_MAX]>(kin_block_alloc(
            &m->block, count * KIN_NAME_MAX));
    if (!names) throw std::bad_alloc();
    int *node_src = alloc_n<int>(L, count);
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
    m->node_count = (int)count;
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

/* Converts one TRIANGLES primitive (arrays only; node and skin are set by
 * the caller). `skinned` requires JOINTS_0 and WEIGHTS_0. */
io_result load_primitive(Loader &L, int mi, int pi, bool skinned,
                         kin_mesh *km)
{
    const tinygltf::Mesh &mesh = L.g->meshes[(size_t)mi];
    const tinygltf::Primitive &prim = mesh.primitives[(size_t)pi];
    char label[160];
    char what[200];
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
    r = decode(L, pos, Want{what, TINYGLTF_TYPE_VEC3, CT_FLOAT, false}, v, &n);
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
        r = decode(L, nrm, Want{what, TINYGLTF_TYPE_VEC3, CT_FLOAT, false}, v, &k);
        if (r != IO_OK) return r;
        if (k != n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s) has %zu elements for %zu "
                           "vertices", L.path, nrm, what, k, n);
        if ((r = check_finite(L, v, nrm, what)) != IO_OK) return r;
        km->normals = to_floats(L, v);
    }

    int jnt = find_attr(prim, "JOINTS_0");
    int wgt = find_attr(prim, "WEIGHTS_0");
    if (skinned && jnt < 0)
        return io_fail(L.err, IO_ERR_MISSING,
                       "%s: %s is skinned but has no JOINTS_0", L.path, label);
    if (skinned && wgt < 0)
        return io_fail(L.err, IO_ERR_MISSING,
                       "%s: %s is skinned but has no WEIGHTS_0", L.path, label);
    if (jnt >= 0 && wgt >= 0) {
        snprintf(what, sizeof what, "JOINTS_0 of %s", label);
        r = decode(L, jnt, Want{what, TINYGLTF_TYPE_VEC4,
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT),
                                false}, v, &k);
        if (r != IO_OK) return r;
        if (k != n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s) has %zu elements for %zu "
                           "vertices", L.path, jnt, what, k, n);
        uint16_t *j = alloc_n<uint16_t>(L, v.size());
        for (size_t i = 0; i < v.size(); i++) j[i] = (uint16_t)v[i];
        km->joints = j;

        snprintf(what, sizeof what, "WEIGHTS_0 of %s", label);
        r = decode(L, wgt, Want{what, TINYGLTF_TYPE_VEC4,
                                CT_FLOAT |
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                                ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT),
                                true}, v, &k);
        if (r != IO_OK) return r;
        if (k != n)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: accessor %d (%s) has %zu elements for %zu "
                           "vertices", L.path, wgt, what, k, n);
        if ((r = check_finite(L, v, wgt, what)) != IO_OK) return r;
        float *w = alloc_n<float>(L, v.size());
        for (size_t i = 0; i < n; i++) {
            double sum = v[i * 4] + v[i * 4 + 1] + v[i * 4 + 2] + v[i * 4 + 3];
            for (size_t c = 0; c < 4; c++)
                w[i * 4 + c] = (float)(sum > 0.0 ? v[i * 4 + c] / sum
                                                 : v[i * 4 + c]);
        }
        km->weights = w;
    }

    if (prim.indices >= 0) {
        snprintf(what, sizeof what, "indices of %s", label);
        r = decode(L, prim.indices,
                   Want{what, TINYGLTF_TYPE_SCALAR,
                        ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                        ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) |
                        ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT), false},
                   v, &k);
        if (r != IO_OK) return r;
        if (k % 3 != 0)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: %s has %zu indices, not a multiple of 3",
                           L.path, label, k);
        uint32_t *idx = alloc_n<uint32_t>(L, k);
        for (size_t i = 0; i < k; i++) {
            if (!(v[i] < (double)n))
                return io_fail(L.err, IO_ERR_FORMAT,
                               "%s: accessor %d (%s): index %zu is %.0f, past "
                               "the %zu vertices", L.path, prim.indices, what,
                               i, v[i], n);
            idx[i] = (uint32_t)v[i];
        }
        km->index_count = (int)k;
        km->indices = idx;
    } else {
        if (n % 3 != 0)
            return io_fail(L.err, IO_ERR_FORMAT,
                           "%s: %s is not indexed and has %zu vertices, not a "
                           "multiple of 3", L.path, label, n);
        uint32_t *idx = alloc_n<uint32_t>(L, n);
        for (size_t i = 0; i < n; i++) idx[i] = (uint32_t)i;
        km->index_count = (int)n;
        km->indices = idx;
    }
    return IO_OK;
}

io_result load_meshes(Loader &L)
{
    const tinygltf::Model &g = *L.g;
    kin_model *m = L.out;
    std::vector<kin_mesh> meshes;
    /* primitives instanced by several nodes share their arrays */
    std::map<std::pair<int, int>, kin_mesh> done;
    for (int i = 0; i < m->node_count; i++) {
        const tinygltf::Node &n = g.nodes[(size_t)m->node_src[i]];
        if (n.mesh < 0) continue;
        if ((size_t)n.mesh >= g.meshes.size())
            return io_fail(L.err, IO_ERR_FORMAT, "%s: node %d names mesh %d of %zu",
                           L.path, m->node_src[i], n.mesh, g.meshes.size());
        if (n.skin >= 0 && (size_t)n.skin >= g.skins.size())
            return io_fail(L.err, IO_ERR_FORMAT, "%s: node %d names skin %d of %zu",
                           L.path, m->node_src[i], n.skin, g.skins.size());
        const tinygltf::Mesh &mesh = g.meshes[(size_t)n.mesh];
        for (size_t p = 0; p < mesh.primitives.size(); p++) {
            int mode = mesh.primitives[p].mode;
            if (mode != -1 && mode != TINYGLTF_MODE_TRIANGLES) continue;
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
            km.node = i;
            km.skin = n.skin;
            meshes.push_back(km);
        }
    }
    if (meshes.empty())
        return io_fail(L.err, IO_ERR_MISSING, "%s: no triangle primitives",
                       L.path);
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
std::string one_line(std::string s)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    for (char &c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s.empty() ? std::string("unknown error") : s;
}

io_result load(const char *path, kin_model *out, io_error *err)
{
    std::vector<unsigned char> bytes;
    io_result r = read_file(path, bytes, err);
    if (r != IO_OK) return r;
    if ((r = io_glb_check(path, bytes.data(), bytes.size(), err)) != IO_OK) return r;

    tinygltf::Model g;
    tinygltf::TinyGLTF parser;
    parser.SetImageLoader(skip_image, nullptr);
    std::string terr, twarn;
    std::string base = dir_of(path);
    bool ok;
    if (bytes.size() >= 4 && memcmp(bytes.data(), "glTF", 4) == 0)
        ok = parser.LoadBinaryFromMemory(&g, &terr, &twarn, bytes.data(),
                                         (unsigned)bytes.size(), base);
    else if (bytes.empty())
        return io_fail(err, IO_ERR_FORMAT, "%s: empty file", path);
    else
        ok = parser.LoadASCIIFromString(
            &g, &terr, &twarn, reinterpret_cast<const char *>(bytes.data()),
            (unsigned)bytes.size(), base);
    if (!ok)
        return io_fail(err, IO_ERR_FORMAT, "%s: %s", path,
                       one_line(terr).c_str());
    std::vector<unsigned char>().swap(bytes);

    Loader L;
    L.path = path;
    L.g = &g;
    L.out = out;
    L.err = err;
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

extern "C" io_result io_gltf_load(const char *path, kin_model *out,
                                  io_error *err)
{
    if (!out) return io_fail(err, IO_ERR_ARGS, "io_gltf_load: no output model");
    memset(out, 0, sizeof *out);
    if (!path || !*path)
        return io_fail(err, IO_ERR_ARGS, "io_gltf_load: no path");
    io_result r;
    try {
        r = load(path, out, err);
    } catch (const std::bad_alloc &) {
        r = io_fail(err, IO_ERR_NOMEM, "%s: out of memory", path);
    } catch (const std::exception &e) {
        r = io_fail(err, IO_ERR_FORMAT, "%s: %s", path, e.what());
    } catch (...) {
        r = io_fail(err, IO_ERR_FORMAT, "%s: unexpected exception", path);
    }
    if (r != IO_OK) kin_model_free(out);  /* frees and zeroes */
    else if (err) io_fail(err, IO_OK, "%s", "ok");
    return r;
}
