/* io_gltf_nodes.cpp - the glTF node tree into kin_model joints: the
 * drawn scene, parents and a depth-first order, rest transforms (TRS or a
 * matrix decomposed), EXT_mesh_gpu_instancing's instances as child nodes,
 * and the skins (joints, inverse bind matrices). Part of the glTF loader
 * (io_gltf_int.hpp).
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

/* ------------------------------------------------------------- nodes */

/* Quaternion (x, y, z, w) of a rotation matrix r[col][row] (Shepperd). */
static kin_quat quat_from_rot(const double r[3][3])
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
static io_result decompose(Loader &L, int src, const std::vector<double> &m,
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

static io_result node_transform(Loader &L, int src, kin_transform *t)
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

/* EXT_mesh_gpu_instancing of the drawn mesh nodes, in sorted node order:
 * TRANSLATION / ROTATION / SCALE per instance (each optional, the same
 * count). */
static io_result load_instances(Loader &L, const std::vector<int> &order)
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

}  // namespace io_gltf_impl
