/* test_io_gltf.c - io_gltf_load: the shared Khronos sample models (counts
 * from /work/shared/gltf/PROVENANCE.md, values read from their JSON by
 * hand), a synthetic model written here in three containers (.gltf with a
 * data URI, .gltf + .bin, .glb) and broken files. */
#include "support/testutil.h"
#include <cmocka.h>
#include "support/files.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/io/io.h"

/* ----------------------------------------------------------- helpers */

static int shared_model(const char *rel, char *buf, size_t n)
{
    tu_shared_path(rel, buf, n);
    if (!tu_exists(buf)) {
        printf("SKIP: shared model %s is missing (set EGOFUSE_SHARED)\n", buf);
        return 0;
    }
    return 1;
}

/* m := the shared model rel, which must load: 1; 0 (said) when the file
 * is missing. */
static int load_shared(const char *rel, kin_model *m)
{
    char path[1024];
    if (!shared_model(rel, path, sizeof path)) return 0;
    io_error err;
    assert_int_equal(io_gltf_load(path, m, &err), IO_OK);
    return 1;
}

static int all_zero(const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++)
        if (b[i]) return 0;
    return 1;
}

static const char *base_name(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

/* Loads a file expected to fail: checks the code, that the message names
 * the file, and that the output was zeroed. */
static void expect_fail(const char *path, io_result want, const char *needle)
{
    kin_model m;
    io_error err;
    memset(&m, 0xAB, sizeof m);
    memset(&err, 0, sizeof err);
    io_result r = io_gltf_load(path, &m, &err);
    if (r != want)
        fprintf(stderr, "%s: got %s (%s), want %s\n", path, io_result_str(r),
                err.msg, io_result_str(want));
    assert_int_equal(r, want);
    assert_int_equal(err.code, want);
    if (!strstr(err.msg, base_name(path)))
        fprintf(stderr, "message without the file name: %s\n", err.msg);
    assert_non_null(strstr(err.msg, base_name(path)));
    if (needle && !strstr(err.msg, needle))
        fprintf(stderr, "message without '%s': %s\n", needle, err.msg);
    if (needle) assert_non_null(strstr(err.msg, needle));
    assert_true(all_zero(&m, sizeof m));
}

static double det3(const float *m)  /* upper 3x3 of a column-major 4x4 */
{
    return (double)m[0] * ((double)m[5] * m[10] - (double)m[9] * m[6]) -
           (double)m[4] * ((double)m[1] * m[10] - (double)m[9] * m[2]) +
           (double)m[8] * ((double)m[1] * m[6] - (double)m[5] * m[2]);
}

/* Invariants every loaded model must satisfy. */
static void check_model(const kin_model *m)
{
    char why[256];
    assert_int_equal(kin_model_validate(m, why, sizeof why), 0);
    for (int i = 0; i < m->node_count; i++) {
        assert_true(m->parents[i] == KIN_NO_PARENT || m->parents[i] < i);
        assert_true(m->names[i][0] != '\0');
        assert_true(m->node_src[i] >= 0 && m->node_src[i] < m->node_count);
    }
    for (int s = 0; s < m->skin_count; s++) {
        const kin_skin *sk = &m->skins[s];
        for (int j = 0; j < sk->joint_count; j++) {
            const float *ib = sk->inverse_bind[j].m;
            for (int e = 0; e < 16; e++) assert_true(isfinite(ib[e]));
            /* affine, invertible */
            assert_true(fabsf(ib[3]) < 1e-6f && fabsf(ib[7]) < 1e-6f &&
                        fabsf(ib[11]) < 1e-6f && fabsf(ib[15] - 1.0f) < 1e-6f);
            assert_true(fabs(det3(ib)) > 1e-6);
        }
    }
    for (int k = 0; k < m->mesh_count; k++) {
        const kin_mesh *me = &m->meshes[k];
        if (me->weights) {
            for (int v = 0; v < me->vertex_count; v++) {
                /* as stored (a GPU does not renormalise) */
                const float *w = me->weights + v * 4;
                for (int c = 0; c < 4; c++) assert_true(isfinite(w[c]) && w[c] >= 0.0f);
            }
        }
    }
    for (int a = 0; a < m->anim_count; a++) {
        const kin_animation *an = &m->anims[a];
        float last = 0.0f;
        for (int c = 0; c < an->channel_count; c++) {
            const kin_channel *ch = &an->channels[c];
            for (int i = 1; i < ch->key_count; i++)
                assert_true(ch->times[i] > ch->times[i - 1]);
            if (ch->times[ch->key_count - 1] > last)
                last = ch->times[ch->key_count - 1];
            assert_int_equal(ch->comps, ch->path == KIN_PATH_ROTATION ? 4 : 3);
        }
        assert_true(an->duration == last);
    }
}

typedef struct counts {
    const char *rel;
    int verts, tris, joints, anims, channels; /* channels of anim 0, or -1 */
    int normals;
} counts;

static const counts shared_counts[] = {
    {"gltf/SimpleSkin/SimpleSkin.gltf", 10, 8, 2, 1, 1, 0},
    {"gltf/RiggedSimple/RiggedSimple.glb", 160, 188, 2, 1, 3, 1},
    {"gltf/RiggedFigure/RiggedFigure.glb", 370, 256, 19, 1, 57, 1},
    {"gltf/CesiumMan/CesiumMan.glb", 3273, 4672, 19, 1, 57, 1},
    {"gltf/Fox/Fox.glb", 1728, 576, 24, 3, 21, 0},
};

/* ------------------------------------------------- the shared models */

static void shared_models_load_with_counts(void **state)
{
    (void)state;
    int found = 0;
    for (size_t i = 0; i < sizeof shared_counts / sizeof shared_counts[0]; i++) {
        const counts *c = &shared_counts[i];
        char path[1024];
        if (!shared_model(c->rel, path, sizeof path)) continue;
        found++;
        kin_model m;
        io_error err;
        io_result r = io_gltf_load(path, &m, &err);
        if (r != IO_OK) fprintf(stderr, "%s\n", err.msg);
        assert_int_equal(r, IO_OK);
        check_model(&m);
        int verts = 0, tris = 0;
        for (int k = 0; k < m.mesh_count; k++) {
            verts += m.meshes[k].vertex_count;
            tris += m.meshes[k].index_count / 3;
            assert_int_equal(m.meshes[k].normals != NULL, c->normals);
            assert_int_equal(m.meshes[k].skin, 0);
            assert_non_null(m.meshes[k].joints);
        }
        assert_int_equal(verts, c->verts);
        assert_int_equal(tris, c->tris);
        assert_int_equal(m.skin_count, 1);
        assert_int_equal(m.skins[0].joint_count, c->joints);
        assert_int_equal(m.anim_count, c->anims);
        assert_int_equal(m.anims[0].channel_count, c->channels);
        for (int a = 0; a < m.anim_count; a++)
            for (int k = 0; k < m.anims[a].channel_count; k++)
                assert_int_equal(m.anims[a].channels[k].interp, KIN_INTERP_LINEAR);
        kin_model_free(&m);
        assert_null(m.block);
    }
    if (!found) skip();
}

static void fox_is_not_indexed_and_names_animations(void **state)
{
    (void)state;
    kin_model m;
    if (!load_shared("gltf/Fox/Fox.glb", &m)) skip();
    const kin_mesh *me = &m.meshes[0];
    assert_int_equal(me->index_count, me->vertex_count);
    for (int i = 0; i < me->index_count; i++)
        assert_int_equal(me->indices[i], (uint32_t)i);
    assert_string_equal(m.anims[0].name, "Survey");
    assert_string_equal(m.anims[1].name, "Walk");
    assert_string_equal(m.anims[2].name, "Run");
    /* node 4 "b_Hip_01" is a child of "b_Root_00" */
    int hip = kin_model_find_node(&m, "b_Hip_01");
    int root = kin_model_find_node(&m, "b_Root_00");
    assert_true(hip > 0 && root >= 0);
    assert_int_equal(m.parents[hip], root);
    assert_int_equal(m.node_src[hip], 4);
    kin_model_free(&m);
}

/* Values read by hand from RiggedSimple's JSON and binary chunk. */
static void rigged_simple_known_values(void **state)
{
    (void)state;
    kin_model m;
    if (!load_shared("gltf/RiggedSimple/RiggedSimple.glb", &m)) skip();
    /* source order Z_UP, Armature, Cylinder, Bone, Bone.001; Armature's
     * children are [Bone, Cylinder], so depth first gives: */
    static const int src[5] = {0, 1, 3, 4, 2};
    static const int16_t par[5] = {-1, 0, 1, 2, 1};
    static const char *const names[5] = {"Z_UP", "Armature", "Bone",
                                         "Bone.001", "Cylinder"};
    assert_int_equal(m.node_count, 5);
    for (int i = 0; i < 5; i++) {
        assert_int_equal(m.node_src[i], src[i]);
        assert_int_equal(m.parents[i], par[i]);
        assert_string_equal(m.names[i], names[i]);
    }
    /* Z_UP: matrix columns (1,0,0) (0,0,-1) (0,1,0): -90 deg about X */
    const kin_transform *z = &m.rest[0];
    float h = sqrtf(0.5f);
    assert_float_equal(z->r.x, -h, 1e-6f);
    assert_float_equal(z->r.y, 0.0f, 1e-6f);
    assert_float_equal(z->r.z, 0.0f, 1e-6f);
    assert_float_equal(z->r.w, h, 1e-6f);
    for (int k = 0; k < 3; k++) assert_float_equal((&z->s.x)[k], 1.0f, 1e-6f);
    /* Bone: matrix with translation (0, -1.3597e-7, -4.18033) */
    assert_float_equal(m.rest[2].t.z, -4.1803298f, 1e-6f);
    assert_float_equal(m.rest[2].r.w, 1.0f, 1e-6f);
    /* Bone.001: translation and rotation given as TRS */
    assert_float_equal(m.rest[3].t.y, 0.02797747f, 1e-7f);
    assert_float_equal(m.rest[3].t.z, 4.187077f, 1e-6f);
    assert_float_equal(m.rest[3].r.y, 0.00028992252f, 1e-9f);
    assert_float_equal(m.rest[3].r.w, -0.99999994f, 1e-7f);
    /* skin: joints [Bone, Bone.001] = sorted [2, 3]; IBM 0 translates by
     * (0, 1.3597e-7, 4.18033); IBM 1 row 0 = (0, -0.99999982, 0.00057984) */
    assert_int_equal(m.skins[0].joints[0], 2);
    assert_int_equal(m.skins[0].joints[1], 3);
    const float *ib0 = m.skins[0].inverse_bind[0].m;
    const float *ib1 = m.skins[0].inverse_bind[1].m;
    assert_true(ib0[1] == 1.0f && ib0[4] == -1.0f && ib0[10] == 1.0f);
    assert_true(ib0[14] == 4.1803297996521f);
    assert_true(ib1[4] == -0.9999998211860657f);
    assert_true(ib1[6] == 0.0005798449856229126f);
    assert_true(ib1[13] == -0.02797728031873703f);
    assert_int_equal(m.meshes[0].node, 4);
    /* animation: 3 channels on Bone.001 (T, R, S), first key 1/24 s */
    const kin_animation *an = &m.anims[0];
    assert_int_equal(an->channel_count, 3);
    assert_int_equal(an->channels[0].path, KIN_PATH_TRANSLATION);
    assert_int_equal(an->channels[1].path, KIN_PATH_ROTATION);
    assert_int_equal(an->channels[2].path, KIN_PATH_SCALE);
    for (int c = 0; c < 3; c++) assert_int_equal(an->channels[c].node, 3);
    assert_true(an->channels[0].times[0] == 0.04166661947965622f);
    assert_true(an->duration == 2.0833330154418945f);
    kin_model_free(&m);
}

static void simple_skin_known_values(void **state)
{
    (void)state;
    kin_model m;
    if (!load_shared("gltf/SimpleSkin/SimpleSkin.gltf", &m)) skip();
    assert_int_equal(m.node_count, 3);
    assert_string_equal(m.names[0], "node0");  /* unnamed nodes */
    assert_string_equal(m.names[2], "node2");
    assert_true(m.rest[1].t.x == 0.0f && m.rest[1].t.y == 1.0f);
    for (int j = 0; j < 2; j++) {
        const float *ib = m.skins[0].inverse_bind[j].m;
        assert_true(ib[12] == -0.5f && ib[13] == -1.0f && ib[14] == 0.0f);
    }
    assert_int_equal(m.anims[0].channels[0].node, 2);
    assert_int_equal(m.anims[0].channels[0].key_count, 12);
    assert_int_equal(m.anims[0].channels[0].path, KIN_PATH_ROTATION);
    kin_model_free(&m);
}

/* --------------------------------------------- a synthetic model */

enum {
    S_NO_POSITION = 1 << 0, S_NO_WEIGHTS = 1 << 1, S_BAD_INDEX = 1 << 2,
    S_PAST_BUFFER = 1 << 3, S_CYCLE = 1 << 4, S_SPARSE = 1 << 5,
    S_UBYTE_WEIGHTS = 1 << 6, S_STRIDED = 1 << 7, S_MIRROR = 1 << 8,
    S_TWO_PARENTS = 1 << 9, S_LINES_ONLY = 1 << 10, S_CUBIC = 1 << 11,
};

#define SYN_BYTES 428

static void put_f(unsigned char *b, size_t off, float v) { memcpy(b + off, &v, 4); }
static void put_u16(unsigned char *b, size_t off, uint16_t v) { memcpy(b + off, &v, 2); }

/* The binary buffer: a quad (4 vertices, 2 triangles), skinned to two
 * joints, and one animation with 3 keys (see the view table below). */
static void syn_buffer(unsigned char *b, unsigned flags)
{
    memset(b, 0, SYN_BYTES);
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (int i = 0; i < 12; i++) put_f(b, (size_t)(i * 4), pos[i]);
    static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; i++)
        put_u16(b, 48 + (size_t)i * 2, (flags & S_BAD_INDEX) && i == 4 ? 9 : idx[i]);
    for (int v = 0; v < 4; v++) {
        put_u16(b, 60 + (size_t)v * 8, 0);
        put_u16(b, 60 + (size_t)v * 8 + 2, 1);
        put_f(b, 92 + (size_t)v * 16, 0.5f);       /* sum 0.75: kept as stored */
        put_f(b, 92 + (size_t)v * 16 + 4, 0.25f);
    }
    for (int j = 0; j < 2; j++)
        for (int e = 0; e < 16; e++)
            put_f(b, 156 + (size_t)(j * 64 + e * 4), e % 5 == 0 ? 1.0f : 0.0f);
    put_f(b, 156 + 64 + 13 * 4, -1.0f);            /* IBM 1: translate(0,-1,0) */
    static const float times[3] = {0.0f, 0.5f, 1.25f};
    for (int i = 0; i < 3; i++) put_f(b, 284 + (size_t)i * 4, times[i]);
    for (int i = 0; i < 9; i++) put_f(b, 296 + (size_t)i * 4, (float)(i + 1));
    b[332] = 2;                                    /* sparse: vertex 2 ... */
    put_f(b, 336, 7.0f); put_f(b, 340, 8.0f); put_f(b, 344, 9.0f); /* := (7,8,9) */
    for (int v = 0; v < 4; v++) { b[348 + v * 4] = 128; b[348 + v * 4 + 1] = 64; }
    for (int v = 0; v < 4; v++)                    /* positions, stride 16 */
        for (int c = 0; c < 3; c++) put_f(b, 364 + (size_t)(v * 16 + c * 4), pos[v * 3 + c]);
}

/* The JSON of the synthetic model. Source nodes are listed children
 * first, so sorting has work to do:
 *   0 (unnamed) translation (0,1,0); 1 "j0" children [0], matrix;
 *   2 "skinned" mesh 0 skin 0; 3 "root" children [2, 1].
 * uri: "data:..." or a file name, or NULL for a .glb (buffer without uri). */
static char *syn_json(unsigned flags, const char *uri)
{
    char *j = malloc(16384);
    assert_non_null(j);
    const char *attrs =
        (flags & S_NO_POSITION) ? "\"JOINTS_0\":2,\"WEIGHTS_0\":3"
        : (flags & S_NO_WEIGHTS) ? "\"POSITION\":0,\"JOINTS_0\":2"
        : (flags & S_UBYTE_WEIGHTS) ? "\"POSITION\":0,\"JOINTS_0\":2,\"WEIGHTS_0\":7"
        : (flags & S_STRIDED) ? "\"POSITION\":8,\"JOINTS_0\":2,\"WEIGHTS_0\":3"
        : "\"POSITION\":0,\"JOINTS_0\":2,\"WEIGHTS_0\":3";
    const char *matrix = (flags & S_MIRROR)
        ? "[-2,0,0,0, 0,2,0,0, 0,0,2,0, 4,5,6,1]"
        : "[0,2,0,0, -2,0,0,0, 0,0,2,0, 4,5,6,1]";  /* 90 deg about Z, scale 2 */
    const char *root_children = (flags & S_CYCLE) ? "[2]"
                              : (flags & S_TWO_PARENTS) ? "[2,1,0]" : "[2,1]";
    const char *leaf_children = (flags & S_CYCLE) ? ",\"children\":[1]" : "";
    char buffer[1200];
    if (uri)
        snprintf(buffer, sizeof buffer, "{\"byteLength\":%d,\"uri\":\"%s\"}",
                 SYN_BYTES, uri);
    else
        snprintf(buffer, sizeof buffer, "{\"byteLength\":%d}", SYN_BYTES);
    snprintf(j, 16384,
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,"
        "\"scenes\":[{\"nodes\":[3]}],"
        "\"nodes\":["
          "{\"translation\":[0,1,0]%s},"
          "{\"name\":\"j0\",\"children\":[0],\"matrix\":%s},"
          "{\"name\":\"skinned\",\"mesh\":0,\"skin\":0},"
          "{\"name\":\"root\",\"children\":%s,\"translation\":[1,2,3]}],"
        "\"meshes\":[{\"name\":\"quad\",\"primitives\":["
          "{\"attributes\":{\"POSITION\":0},\"mode\":1},"
          "{\"attributes\":{%s},\"indices\":1%s}]}],"
        "\"skins\":[{\"joints\":[1,0],\"inverseBindMatrices\":4}],"
        "\"animations\":[{\"name\":\"move\",\"channels\":["
          "{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}},"
          "{\"sampler\":0,\"target\":{\"path\":\"translation\"}}],"
          "\"samplers\":[{\"input\":5,\"output\":6,\"interpolation\":\"%s\"}]}],"
        "\"buffers\":[%s],"
        "\"bufferViews\":["
          "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
          "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12},"
          "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":32},"
          "{\"buffer\":0,\"byteOffset\":92,\"byteLength\":64},"
          "{\"buffer\":0,\"byteOffset\":156,\"byteLength\":128},"
          "{\"buffer\":0,\"byteOffset\":284,\"byteLength\":12},"
          "{\"buffer\":0,\"byteOffset\":296,\"byteLength\":36},"
          "{\"buffer\":0,\"byteOffset\":332,\"byteLength\":1},"
          "{\"buffer\":0,\"byteOffset\":336,\"byteLength\":12},"
          "{\"buffer\":0,\"byteOffset\":348,\"byteLength\":16},"
          "{\"buffer\":0,\"byteOffset\":364,\"byteLength\":64,\"byteStride\":16}],"
        "\"accessors\":["
          "{\"bufferView\":0,\"byteOffset\":%d,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"%s},"
          "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
          "{\"bufferView\":2,\"componentType\":5123,\"count\":4,\"type\":\"VEC4\"},"
          "{\"bufferView\":3,\"componentType\":5126,\"count\":4,\"type\":\"VEC4\"},"
          "{\"bufferView\":4,\"componentType\":5126,\"count\":2,\"type\":\"MAT4\"},"
          "{\"bufferView\":5,\"componentType\":5126,\"count\":%d,\"type\":\"SCALAR\"},"
          "{\"bufferView\":6,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
          "{\"bufferView\":9,\"componentType\":5121,\"normalized\":true,\"count\":4,\"type\":\"VEC4\"},"
          "{\"bufferView\":10,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}]}",
        leaf_children, matrix, root_children, attrs,
        (flags & S_LINES_ONLY) ? ",\"mode\":3" : "",
        (flags & S_CUBIC) ? "CUBICSPLINE" : "STEP", buffer,
        (flags & S_PAST_BUFFER) ? 24 : 0,
        (flags & S_SPARSE) ? ",\"sparse\":{\"count\":1,"
            "\"indices\":{\"bufferView\":7,\"componentType\":5121},"
            "\"values\":{\"bufferView\":8}}" : "",
        (flags & S_CUBIC) ? 1 : 3);  /* CUBICSPLINE: 1 key, 3 outputs */
    return j;
}

/* Writes the synthetic model as name (.gltf with a data URI). */
static void write_syn_gltf(const char *path, unsigned flags)
{
    unsigned char bin[SYN_BYTES];
    syn_buffer(bin, flags);
    char uri[1024];
    strcpy(uri, "data:application/octet-stream;base64,");
    tu_b64(bin, SYN_BYTES, uri + strlen(uri));
    char *j = syn_json(flags, uri);
    tu_write_bytes(path, j, strlen(j));
    free(j);
}

static void put_u32(unsigned char *b, size_t off, uint32_t v) { memcpy(b + off, &v, 4); }

static void write_syn_glb(const char *path, unsigned flags)
{
    unsigned char bin[SYN_BYTES];
    syn_buffer(bin, flags);
    char *j = syn_json(flags, NULL);
    size_t jl = strlen(j), jp = (jl + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jp + 8 + SYN_BYTES;
    unsigned char *g = calloc(1, total);
    assert_non_null(g);
    memcpy(g, "glTF", 4);
    put_u32(g, 4, 2);
    put_u32(g, 8, (uint32_t)total);
    put_u32(g, 12, (uint32_t)jp);
    memcpy(g + 16, "JSON", 4);
    memcpy(g + 20, j, jl);
    memset(g + 20 + jl, ' ', jp - jl);
    put_u32(g, 20 + jp, SYN_BYTES);
    memcpy(g + 24 + jp, "BIN\0", 4);
    memcpy(g + 28 + jp, bin, SYN_BYTES);
    tu_write_bytes(path, g, total);
    free(g);
    free(j);
}

static void check_syn(const kin_model *m, unsigned flags)
{
    check_model(m);
    assert_int_equal(m->node_count, 4);
    static const int src[4] = {3, 2, 1, 0};
    static const int16_t par[4] = {-1, 0, 0, 2};
    static const char *const names[4] = {"root", "skinned", "j0", "node0"};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(m->node_src[i], src[i]);
        assert_int_equal(m->parents[i], par[i]);
        assert_string_equal(m->names[i], names[i]);
    }
    assert_true(m->rest[0].t.x == 1.0f && m->rest[0].t.y == 2.0f && m->rest[0].t.z == 3.0f);
    assert_true(m->rest[3].t.y == 1.0f && m->rest[3].r.w == 1.0f && m->rest[3].s.z == 1.0f);
    /* j0: the matrix decomposed */
    const kin_transform *t = &m->rest[2];
    assert_true(t->t.x == 4.0f && t->t.y == 5.0f && t->t.z == 6.0f);
    if (flags & S_MIRROR) {
        assert_float_equal(t->s.x, -2.0f, 1e-6f);
        assert_float_equal(t->r.w, 1.0f, 1e-6f);
    } else {
        assert_float_equal(t->s.x, 2.0f, 1e-6f);
        assert_float_equal(t->r.x, 0.0f, 1e-6f);
        assert_float_equal(t->r.y, 0.0f, 1e-6f);
        assert_float_equal(t->r.z, sqrtf(0.5f), 1e-6f);
        assert_float_equal(t->r.w, sqrtf(0.5f), 1e-6f);
    }
    assert_float_equal(t->s.y, 2.0f, 1e-6f);
    assert_float_equal(t->s.z, 2.0f, 1e-6f);
    /* the LINES primitive is skipped: one mesh */
    assert_int_equal(m->mesh_count, 1);
    const kin_mesh *me = &m->meshes[0];
    assert_int_equal(me->node, 1);
    assert_int_equal(me->skin, 0);
    assert_int_equal(me->vertex_count, 4);
    assert_int_equal(me->index_count, 6);
    assert_null(me->normals);
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; i++) assert_int_equal(me->indices[i], idx[i]);
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (int i = 0; i < 12; i++) {
        float want = pos[i];
        if ((flags & S_SPARSE) && i >= 6 && i < 9) want = (float)(i + 1);
        assert_true(me->positions[i] == want);
    }
    for (int v = 0; v < 4; v++) {
        assert_int_equal(me->joints[v * 4], 0);
        assert_int_equal(me->joints[v * 4 + 1], 1);
        /* weights as stored: 0.5, 0.25 (float) or 128/255, 64/255 (ubyte) */
        float w0 = (flags & S_UBYTE_WEIGHTS) ? 128.0f / 255.0f : 0.5f;
        float w1 = (flags & S_UBYTE_WEIGHTS) ? 64.0f / 255.0f : 0.25f;
        assert_float_equal(me->weights[v * 4], w0, 1e-6f);
        assert_float_equal(me->weights[v * 4 + 1], w1, 1e-6f);
        assert_true(me->weights[v * 4 + 2] == 0.0f);
    }
    /* skin joints: source [1, 0] = sorted [2, 3] */
    assert_int_equal(m->skins[0].joint_count, 2);
    assert_int_equal(m->skins[0].joints[0], 2);
    assert_int_equal(m->skins[0].joints[1], 3);
    assert_true(m->skins[0].inverse_bind[1].m[13] == -1.0f);
    assert_true(m->skins[0].inverse_bind[1].m[0] == 1.0f);
    /* one animation, its target-less channel skipped */
    assert_int_equal(m->anim_count, 1);
    assert_string_equal(m->anims[0].name, "move");
    assert_int_equal(m->anims[0].channel_count, 1);
    const kin_channel *ch = &m->anims[0].channels[0];
    assert_int_equal(ch->node, 3);
    assert_int_equal(ch->path, KIN_PATH_TRANSLATION);
    assert_int_equal(ch->interp, (flags & S_CUBIC) ? KIN_INTERP_CUBICSPLINE : KIN_INTERP_STEP);
    int keys = (flags & S_CUBIC) ? 1 : 3;  /* 9 floats either way */
    assert_int_equal(ch->key_count, keys);
    assert_int_equal(ch->comps, 3);
    assert_true(ch->times[keys - 1] == (keys == 3 ? 1.25f : 0.0f));
    for (int i = 0; i < 9; i++) assert_true(ch->values[i] == (float)(i + 1));
    assert_true(m->anims[0].duration == ch->times[keys - 1]);
}

static void synthetic_loads_in_every_container(void **state)
{
    (void)state;
    char path[1024], bin[1024];
    kin_model m;
    io_error err;

    tu_tmp_path("syn_embedded.gltf", path, sizeof path);
    write_syn_gltf(path, 0);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    check_syn(&m, 0);
    kin_model_free(&m);

    tu_tmp_path("syn.glb", path, sizeof path);
    write_syn_glb(path, 0);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    check_syn(&m, 0);
    kin_model_free(&m);

    /* .gltf with the buffer in a .bin next to it */
    unsigned char data[SYN_BYTES];
    syn_buffer(data, 0);
    tu_tmp_path("syn_ext.bin", bin, sizeof bin);
    tu_write_bytes(bin, data, SYN_BYTES);
    tu_tmp_path("syn_ext.gltf", path, sizeof path);
    char *j = syn_json(0, "syn_ext.bin");
    tu_write_bytes(path, j, strlen(j));
    free(j);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    check_syn(&m, 0);
    kin_model_free(&m);

    /* the .bin missing: a format error naming the file */
    remove(bin);
    expect_fail(path, IO_ERR_FORMAT, NULL);
}

static void synthetic_variants(void **state)
{
    (void)state;
    static const unsigned ok[] = {S_SPARSE, S_UBYTE_WEIGHTS, S_STRIDED,
                                  S_MIRROR, S_CUBIC};
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        char path[1024];
        tu_tmp_path("syn_variant.glb", path, sizeof path);
        write_syn_glb(path, ok[i]);
        kin_model m;
        io_error err;
        io_result r = io_gltf_load(path, &m, &err);
        if (r != IO_OK) fprintf(stderr, "variant %u: %s\n", ok[i], err.msg);
        assert_int_equal(r, IO_OK);
        check_syn(&m, ok[i]);
        kin_model_free(&m);
    }
}

/* ------------------------------------------------------- bad files */

static void missing_and_empty_files(void **state)
{
    (void)state;
    char path[1024];
    tu_tmp_path("does_not_exist.glb", path, sizeof path);
    expect_fail(path, IO_ERR_NOT_FOUND, NULL);
    tu_tmp_path("empty.gltf", path, sizeof path);
    tu_write_bytes(path, "", 0);
    expect_fail(path, IO_ERR_FORMAT, NULL);
    tu_tmp_path("empty.glb", path, sizeof path);
    tu_write_bytes(path, "", 0);
    expect_fail(path, IO_ERR_FORMAT, NULL);

    kin_model m;
    io_error err;
    assert_int_equal(io_gltf_load(NULL, &m, &err), IO_ERR_ARGS);
    assert_int_equal(io_gltf_load(path, NULL, &err), IO_ERR_ARGS);
}

static void truncated_glb(void **state)
{
    (void)state;
    char path[1024], cut[1024];
    size_t n;
    tu_tmp_path("whole.glb", path, sizeof path);
    write_syn_glb(path, 0);
    unsigned char *b = tu_read_file(path, &n);
    tu_tmp_path("half_syn.glb", cut, sizeof cut);
    tu_write_bytes(cut, b, n / 2);
    free(b);
    expect_fail(cut, IO_ERR_FORMAT, NULL);

    if (!shared_model("gltf/RiggedSimple/RiggedSimple.glb", path, sizeof path))
        return;
    b = tu_read_file(path, &n);
    tu_tmp_path("half_rigged.glb", cut, sizeof cut);
    tu_write_bytes(cut, b, n / 2);
    free(b);
    expect_fail(cut, IO_ERR_FORMAT, NULL);
}

static void corrupt_json(void **state)
{
    (void)state;
    char path[1024];
    char *j = syn_json(0, "x.bin");
    j[strlen(j) * 2 / 3] = '\0';
    tu_tmp_path("corrupt.gltf", path, sizeof path);
    tu_write_bytes(path, j, strlen(j));
    free(j);
    expect_fail(path, IO_ERR_FORMAT, NULL);

    tu_tmp_path("garbage.gltf", path, sizeof path);
    tu_write_bytes(path, "\x01\x02garbage{{", 11);
    expect_fail(path, IO_ERR_FORMAT, NULL);
}

static void json_without_meshes(void **state)
{
    (void)state;
    char path[1024];
    tu_tmp_path("nomesh.gltf", path, sizeof path);
    const char *j = "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"name\":\"a\"}],"
                    "\"scenes\":[{\"nodes\":[0]}]}";
    tu_write_bytes(path, j, strlen(j));
    expect_fail(path, IO_ERR_MISSING, "no triangle primitives");

    /* only a LINES primitive: nothing drawable */
    tu_tmp_path("lines_only.gltf", path, sizeof path);
    write_syn_gltf(path, S_LINES_ONLY);
    expect_fail(path, IO_ERR_MISSING, "no triangle primitives");
}

static void broken_synthetic_models(void **state)
{
    (void)state;
    static const struct { unsigned flags; io_result code; const char *needle; } cases[] = {
        {S_NO_POSITION, IO_ERR_MISSING, "POSITION"},
        {S_NO_WEIGHTS, IO_ERR_MISSING, "WEIGHTS_0"},
        {S_BAD_INDEX, IO_ERR_FORMAT, "index"},
        {S_PAST_BUFFER, IO_ERR_FORMAT, "reads past the end"},
        {S_CYCLE, IO_ERR_FORMAT, "cycle"},
        {S_TWO_PARENTS, IO_ERR_FORMAT, "two parents"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[1024], name[64];
        snprintf(name, sizeof name, "broken_%zu.gltf", i);
        tu_tmp_path(name, path, sizeof path);
        write_syn_gltf(path, cases[i].flags);
        expect_fail(path, cases[i].code, cases[i].needle);
        snprintf(name, sizeof name, "broken_%zu.glb", i);
        tu_tmp_path(name, path, sizeof path);
        write_syn_glb(path, cases[i].flags);
        expect_fail(path, cases[i].code, cases[i].needle);
    }
}

/* Seeded byte flips of the synthetic .glb: every result is either a valid
 * model or an error with a message naming the file (and no leak, under
 * ASan). */
static void flipped_bytes_never_crash(void **state)
{
    (void)state;
    char path[1024];
    size_t n;
    tu_tmp_path("flip_src.glb", path, sizeof path);
    write_syn_glb(path, 0);
    unsigned char *orig = tu_read_file(path, &n);
    unsigned char *b = malloc(n);
    assert_non_null(b);
    tu_rng rng = {0x5eedf11bull};
    tu_tmp_path("flip.glb", path, sizeof path);
    int ok = 0, bad = 0;
    for (int it = 0; it < 200; it++) {
        memcpy(b, orig, n);
        int flips = 1 + tu_int(&rng, 4);
        for (int k = 0; k < flips; k++) {
            const int at = tu_int(&rng, (int)n);   /* drawn in order (tu_kin.h) */
            b[at] ^= (unsigned char)(1 + tu_int(&rng, 255));
        }
        tu_write_bytes(path, b, n);
        kin_model m;
        io_error err;
        if (io_gltf_load(path, &m, &err) == IO_OK) {
            char why[256];
            assert_int_equal(kin_model_validate(&m, why, sizeof why), 0);
            kin_model_free(&m);
            ok++;
        } else {
            assert_non_null(strstr(err.msg, "flip.glb"));
            assert_true(all_zero(&m, sizeof m));
            bad++;
        }
    }
    assert_true(bad > 0);
    free(b);
    free(orig);
}

TU_MAIN_NAMED("io_gltf", NULL, NULL,
              cmocka_unit_test(shared_models_load_with_counts),
              cmocka_unit_test(fox_is_not_indexed_and_names_animations),
              cmocka_unit_test(rigged_simple_known_values),
              cmocka_unit_test(simple_skin_known_values),
              cmocka_unit_test(synthetic_loads_in_every_container),
              cmocka_unit_test(synthetic_variants),
              cmocka_unit_test(missing_and_empty_files),
              cmocka_unit_test(truncated_glb),
              cmocka_unit_test(corrupt_json),
              cmocka_unit_test(json_without_meshes),
              cmocka_unit_test(broken_synthetic_models),
              cmocka_unit_test(flipped_bytes_never_crash))
