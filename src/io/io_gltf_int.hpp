/* io_gltf_int.hpp - what the files of the glTF loader share (C++ only,
 * not a public header; C callers see io.h).
 *
 * WHAT IT DOES. The state of one load (Loader: the tinygltf model, the
 * kin_model being filled, the io_error), the accessor readers' request
 * (Want) and the functions one file of the loader calls in another:
 *   io_gltf.cpp         the C API, file reading, EXT_meshopt_compression,
 *                       confined URIs; runs the steps below in order
 *   io_gltf_access.cpp  accessors: bounds-checked decoding (strides,
 *                       sparse, normalized and quantized integers)
 *   io_gltf_nodes.cpp   nodes, scenes, EXT_mesh_gpu_instancing, skins
 *   io_gltf_mesh.cpp    meshes: primitives (triangles, strips, fans),
 *                       skin weights, morph targets
 *   io_gltf_anim.cpp    animations: channels and samplers
 * WHAT IT DOES NOT. Catch exceptions (io_gltf.cpp's C entry points do, via
 * io_cxx::guard) or free on failure (io_gltf_load_ex frees the model).
 * DEPENDENCIES. <tiny_gltf.h> as Debian's libtinygltf 2.7 builds it:
 * WITHOUT TINYGLTF_IMPLEMENTATION and without any TINYGLTF_NO_* / _USE_*
 * macro (they change the layout of tinygltf::TinyGLTF; see io_gltf.cpp).
 * USAGE.
 *   std::vector<double> v; size_t n;
 *   Want w = {"POSITION of mesh 0", TINYGLTF_TYPE_VEC3, CT_FLOAT, NORM_ANY};
 *   if ((r = decode(L, acc, w, v, &n)) != IO_OK) return r;
 */
#ifndef EGOFUSE_IO_GLTF_INT_HPP
#define EGOFUSE_IO_GLTF_INT_HPP

#include <tiny_gltf.h>

#include <cstddef>
#include <new>
#include <string>
#include <vector>

extern "C" {
#include "io.h"
}

namespace io_gltf_impl {

/* Largest element count accepted for one accessor: keeps every size
 * computation below far from overflow and vertex counts within int. */
const size_t MAX_COUNT = (size_t)1 << 26;

/* Largest number of floats of all morph target deltas of one primitive. */
const size_t MAX_TARGET_FLOATS = (size_t)1 << 28;

/* One instance of EXT_mesh_gpu_instancing: a node added as a child of the
 * instancing node, with the instance's TRS as its rest transform. */
struct Instance {
    int src;               /* source node that has the extension */
    kin_transform trs;
};

/* The state of one load: the source model, the output and the error. */
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

/* Component types of quantized attributes (KHR_mesh_quantization). */
const unsigned CT_INT8_16 = (1u << (TINYGLTF_COMPONENT_TYPE_BYTE - 5120)) |
                            (1u << (TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE - 5120)) |
                            (1u << (TINYGLTF_COMPONENT_TYPE_SHORT - 5120)) |
                            (1u << (TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT - 5120));
const unsigned CT_SIGNED8_16 = (1u << (TINYGLTF_COMPONENT_TYPE_BYTE - 5120)) |
                               (1u << (TINYGLTF_COMPONENT_TYPE_SHORT - 5120));

/* io_gltf_access.cpp */
void copy_name(char *dst, const std::string &src);
const char *type_name(int type);
const char *ctype_name(int ct);
/* Decodes accessor `acc` into out (count * comps doubles, normalised
 * integers converted), with every read bounds-checked. Sparse accessors
 * are applied on top of their base (zeros without a buffer view). */
io_result decode(Loader &L, int acc, const Want &w, std::vector<double> &out,
                 size_t *count_out);
io_result check_finite(Loader &L, const std::vector<double> &v, int acc,
                       const char *what);
float *to_floats(Loader &L, const std::vector<double> &v);
/* Before decoding an attribute of a component type that only
 * KHR_mesh_quantization allows: refuses it, naming the extension, when
 * the file does not declare it. */
io_result need_quantization(Loader &L, int acc, const char *what);

/* io_gltf_nodes.cpp: parents, the drawn scene's depth-first order, rest
 * transforms and instances; then the skins (after load_nodes). */
io_result load_nodes(Loader &L);
io_result load_skins(Loader &L);

/* io_gltf_mesh.cpp: every drawn mesh node's primitives (after load_skins). */
io_result load_meshes(Loader &L);

/* io_gltf_anim.cpp: the animations' channels (after load_meshes). */
io_result load_animations(Loader &L);

}  // namespace io_gltf_impl

#endif
