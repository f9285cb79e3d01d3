/* io_gltf_mesh.cpp - the glTF meshes of the drawn nodes into kin_mesh:
 * each primitive of mode TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN as a
 * triangle list (POINTS and LINES counted and skipped), positions,
 * normals, joints and weights (quantized too), morph targets and their
 * default weights. Part of the glTF loader (io_gltf_int.hpp).
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
#include <utility>
#include <vector>

namespace io_gltf_impl {

/* ------------------------------------------------------------ meshes */

static int find_attr(const tinygltf::Primitive &p, const char *name)
{
    std::map<std::string, int>::const_iterator it = p.attributes.find(name);
    return it == p.attributes.end() ? -1 : it->second;
}

/* Decodes one VEC3 attribute of n elements (POSITION, NORMAL, or one of a
 * morph target): float, or with KHR_mesh_quantization the integer types
 * `ints` (normalized as `norm` says); checks count and finiteness. */
static io_result load_vec3(Loader &L, int acc, const char *what, unsigned ints,
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

/* Decodes one VEC4 skinning attribute (JOINTS_n, WEIGHTS_n) of the
 * component types `types`, normalized as `norm` says; checks that it has
 * n elements. */
static io_result load_vec4(Loader &L, int acc, const char *what, unsigned types, int norm,
                           size_t n, std::vector<double> &v)
{
    size_t k = 0;
    io_result r = decode(L, acc, Want{what, TINYGLTF_TYPE_VEC4, types, norm}, v, &k);
    if (r != IO_OK) return r;
    if (k != n)
        return io_fail(L.err, IO_ERR_FORMAT,
                       "%s: accessor %d (%s) has %zu elements for %zu "
                       "vertices", L.path, acc, what, k, n);
    return IO_OK;
}

/* Converts one primitive of mode TRIANGLES, TRIANGLE_STRIP or
 * TRIANGLE_FAN (arrays only; node, skin and morph weights are set by the
 * caller). `skinned` requires JOINTS_0 and WEIGHTS_0. */
static io_result load_primitive(Loader &L, int mi, int pi, bool skinned,
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
        const unsigned u8_16 = ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) |
                               ct_bit(TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
        if ((r = load_vec4(L, jnt, what, u8_16, NORM_FORBIDDEN, n, v)) != IO_OK) return r;
        std::vector<uint16_t> js(v.size());
        for (size_t i = 0; i < v.size(); i++) js[i] = (uint16_t)v[i];

        snprintf(what, sizeof what, "%s of %s", wn, label);
        if ((r = load_vec4(L, wgt, what, CT_FLOAT | u8_16, NORM_REQUIRED, n, v)) != IO_OK)
            return r;
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
static io_result morph_defaults(Loader &L, int src, int mi, size_t nt,
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

}  // namespace io_gltf_impl
