/* io_gltf_anim.cpp - glTF animations into kin_anim: channels of
 * translation, rotation, scale and morph weights, their samplers' inputs
 * and outputs (LINEAR, STEP, CUBICSPLINE). Part of the glTF loader
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

}  // namespace io_gltf_impl
