/* io_gltf_access.cpp - glTF accessors read into doubles, every byte
 * bounds-checked: buffer views and strides, sparse accessors, normalized
 * integers, the component types KHR_mesh_quantization allows; names of
 * the types for messages. Part of the glTF loader (io_gltf_int.hpp).
 */
#include "io_gltf_int.hpp"

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
#include <type_traits>
#include <utility>
#include <vector>

namespace io_gltf_impl {

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

static size_t ctype_size(int ct)
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

static int type_comps(int type)
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

/* One component of type T at p (little-endian, as glTF stores it); an
 * integer one normalised to [0,1] / [-1,1] by the glTF rules when
 * `normalized` (v / max, at least -1). */
template <typename T>
static double read_as(const unsigned char *p, bool normalized)
{
    T v;
    memcpy(&v, p, sizeof v);
    if (!normalized || !std::is_integral<T>::value) return (double)v;
    const double q = v / (double)std::numeric_limits<T>::max();
    return std::is_signed<T>::value ? std::max(q, -1.0) : q;
}

/* One component of component type ct at p (read_as). */
static double read_comp(const unsigned char *p, int ct, bool normalized)
{
    switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return read_as<int8_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return read_as<uint8_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_SHORT: return read_as<int16_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return read_as<uint16_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return read_as<uint32_t>(p, normalized);
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return read_as<float>(p, normalized);
    default: return 0.0;
    }
}

/* Checks that [offset, offset + size) of buffer view `bv` lies inside the
 * view and the view inside its buffer; returns the first byte. */
static io_result view_span(Loader &L, int acc, const char *what, int bv_index,
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

}  // namespace io_gltf_impl
