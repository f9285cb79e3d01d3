/* test_gltf_samples.c - every model of ../shared/gltf/ (PROVENANCE.md there)
 * drawn as `egofuse mask` draws it, at two cameras and at rest and two
 * animation times, against checked-in CRCs of the masks; gltfpack's
 * quantized and meshopt variants made at run time; bad input.
 *
 * The CRCs were recorded only after each mask was compared with an
 * independent renderer, tests/tools/gltf_ref.py (numpy, written from the
 * glTF 2.0 specification: its own accessor, scene, morph, skin, primitive
 * mode and animation code, exact pixel-centre coverage in double
 * precision): all 56 masks (and the 4 of the synthetic instancing and
 * two-influence-set models below) agreed except 9 pixels, each with its
 * centre within 0.002 px of an edge (egofuse snaps vertices to 1/256 px).
 * To redo that:
 *   EGOFUSE_GLTF_DUMP=/tmp/d build/tests/test_gltf_samples   (PGM + camera)
 *   python3 tests/tools/gltf_ref.py /tmp/d
 * and EGOFUSE_GLTF_RECORD=1 prints the CRC table below.
 *
 * The camera of a model frames the union of its bounding boxes at rest and
 * at the animation times tested: two views, 40 degrees vertical FOV,
 * 128x96 pixels. Missing models or a missing gltfpack: SKIP. */
#include "support/testutil.h"

#include <cmocka.h>
#include "support/files.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../src/cpu/ef_mem.h"
#include "../src/io/io.h"
#include "../src/kin/kin.h"
#include "../src/pipe/pipe.h"
#include "../src/raster/raster.h"

#define W 128
#define H 96
#define FOVY 40.0f
#define VIEWS 2

typedef struct model_case {
    const char *rel;     /* under EGOFUSE_SHARED */
    int scene;           /* -1: default */
    int anim;            /* -1: rest only */
} model_case;

static const model_case models[] = {
    {"gltf/SimpleSkin/SimpleSkin.gltf", -1, 0},
    {"gltf/RiggedSimple/RiggedSimple.glb", -1, 0},
    {"gltf/RiggedFigure/RiggedFigure.glb", -1, 0},
    {"gltf/CesiumMan/CesiumMan.glb", -1, 0},
    {"gltf/Fox/Fox.glb", -1, 2},
    {"gltf/SimpleMorph/glTF/SimpleMorph.gltf", -1, 0},
    {"gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb", -1, 0},
    {"gltf/AnimatedMorphCube/glTF-Quantized/AnimatedMorphCube.gltf", -1, 0},
    {"gltf/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", -1, -1},
    {"gltf/MultipleScenes/glTF/MultipleScenes.gltf", -1, -1},
    {"gltf/MultipleScenes/glTF/MultipleScenes.gltf", 0, -1},
    {"gltf/SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf", -1, -1},
};
#define MODELS (sizeof models / sizeof models[0])
/* times: rest, then 0.3 and 0.7 of the animation's duration */
#define TIMES 3
static const float time_frac[TIMES] = {-1.0f, 0.3f, 0.7f};

/* Expected CRC-32 of each mask: [model][time][view] (0 where a time does
 * not apply: models without animation have the rest pose only).
 * EGOFUSE_GLTF_RECORD=1 prints this table. */
static const uint32_t expected[MODELS][TIMES][VIEWS] = {
#include "test_gltf_samples.crc"
};

/* ---------------------------------------------------------- drawing */

typedef struct shot {
    kin_vec3 eye, target;
    float znear, zfar;
} shot;

typedef struct loaded {
    kin_model model;
    pipe_pose ps;
    float *clip, *vnrm;
    int ok;
} loaded;

static int load(const char *path, int scene, loaded *l, char *msg, size_t msg_size)
{
    memset(l, 0, sizeof *l);
    io_error err;
    if (io_gltf_load_ex(path, scene, &l->model, NULL, &err) != IO_OK) {
        snprintf(msg, msg_size, "%s", err.msg);
        return 0;
    }
    if (pipe_pose_init(&l->ps, &l->model) != 0) {
        kin_model_free(&l->model);
        snprintf(msg, msg_size, "out of memory");
        return 0;
    }
    l->clip = malloc(sizeof(float) * 4 * (size_t)l->ps.max_vertices);
    l->vnrm = malloc(sizeof(float) * 3 * (size_t)l->ps.max_vertices);
    l->ok = 1;
    return 1;
}

static void unload(loaded *l)
{
    if (!l->ok) return;
    free(l->clip);
    free(l->vnrm);
    pipe_pose_free(&l->ps);
    kin_model_free(&l->model);
    memset(l, 0, sizeof *l);
}

static const kin_animation *anim_of(const loaded *l, int anim)
{
    return anim >= 0 && anim < l->model.anim_count ? &l->model.anims[anim] : NULL;
}

static float time_of(const loaded *l, int anim, int ti)
{
    const kin_animation *a = anim_of(l, anim);
    return a && time_frac[ti] >= 0.0f ? time_frac[ti] * a->duration : 0.0f;
}

/* Poses at time index ti (rest when the model has no such animation). */
static void pose(loaded *l, int anim, int ti)
{
    const kin_animation *a = time_frac[ti] >= 0.0f ? anim_of(l, anim) : NULL;
    pipe_pose_anim(&l->ps, a, time_of(l, anim, ti));
}

static void grow_bounds(const loaded *l, float lo[3], float hi[3])
{
    for (int i = 0; i < l->model.mesh_count; i++)
        for (int v = 0; v < l->model.meshes[i].vertex_count; v++)
            for (int c = 0; c < 3; c++) {
                float x = l->ps.pos[i][3 * v + c];
                if (x < lo[c]) lo[c] = x;
                if (x > hi[c]) hi[c] = x;
            }
}

/* The two cameras of a model: the bounds over rest and the times tested. */
static void cameras(loaded *l, int anim, shot out[VIEWS])
{
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (int ti = 0; ti < TIMES; ti++) {
        pose(l, anim, ti);
        grow_bounds(l, lo, hi);
    }
    kin_vec3 c = kin_v3(0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2]));
    float r = 0.5f * kin_v3_len(kin_v3(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
    if (!(r > 0.0f)) r = 1.0f;
    float dist = r / sinf(0.5f * FOVY * PI_F / 180.0f) * 1.1f;
    static const float dirs[VIEWS][3] = {{0.35f, 0.3f, 1.0f}, {-0.9f, 0.45f, -0.5f}};
    for (int v = 0; v < VIEWS; v++) {
        kin_vec3 d = kin_v3_norm(kin_v3(dirs[v][0], dirs[v][1], dirs[v][2]));
        out[v].eye = kin_v3_add(c, kin_v3_scale(d, dist));
        out[v].target = c;
        out[v].znear = 0.5f * (dist - r);
        out[v].zfar = dist + 2.0f * r;
    }
}

static void draw(const loaded *l, const shot *s, uint8_t *mask, float *depth)
{
    kin_camera cam = kin_camera_look_at(s->eye, s->target, kin_v3(0.0f, 1.0f, 0.0f), FOVY, W, H,
                                        s->znear, s->zfar);
    rast_target tg = {W, H, depth, W, mask, W, NULL, 0, 0, NULL, 0};
    rast_target_clear(&tg);
    assert_int_equal(pipe_pose_draw(&l->ps, NULL, &cam, &tg, RAST_CULL_NONE, l->clip, l->vnrm, NULL),
                     RAST_OK);
}

static int count_set(const uint8_t *m)
{
    int n = 0;
    for (int i = 0; i < W * H; i++) n += m[i] != 0;
    return n;
}

/* Writes mask i as PGM and its camera as text into dir. */
static void dump(const char *dir, int idx, const char *path, int scene, int anim, float t,
                 const shot *s, const uint8_t *mask)
{
    char p[1200];
    snprintf(p, sizeof p, "%s/%03d.pgm", dir, idx);
    FILE *f = fopen(p, "wb");
    if (!f) return;
    fprintf(f, "P5\n%d %d\n255\n", W, H);
    fwrite(mask, 1, (size_t)W * H, f);
    fclose(f);
    snprintf(p, sizeof p, "%s/%03d.txt", dir, idx);
    f = fopen(p, "w");
    if (!f) return;
    fprintf(f, "model %s\nscene %d\nanim %d\ntime %.9g\nsize %d %d\nfovy %.9g\n", path, scene,
            anim, (double)t, W, H, (double)FOVY);
    fprintf(f, "eye %.9g %.9g %.9g\ntarget %.9g %.9g %.9g\nnear %.9g\nfar %.9g\n",
            (double)s->eye.x, (double)s->eye.y, (double)s->eye.z, (double)s->target.x,
            (double)s->target.y, (double)s->target.z, (double)s->znear, (double)s->zfar);
    fclose(f);
}

static int shared_ok(const char *rel, char *buf, size_t n)
{
    tu_shared_path(rel, buf, n);
    if (tu_exists(buf)) return 1;
    printf("SKIP: %s is missing (set EGOFUSE_SHARED)\n", buf);
    return 0;
}

/* The shared sample rel (its path in path) loaded with its default scene
 * into m and info; the test skipped when the file is missing. */
static void load_shared(const char *rel, char *path, size_t n, kin_model *m, io_gltf_info *info)
{
    if (!shared_ok(rel, path, n)) skip();
    io_error err;
    if (io_gltf_load_ex(path, -1, m, info, &err) != IO_OK) fail_msg("%s", err.msg);
}

/* ------------------------------------------- every model, every shot */

static void every_model_matches_its_crcs(void **state)
{
    (void)state;
    const char *dump_dir = getenv("EGOFUSE_GLTF_DUMP");
    const int record = getenv("EGOFUSE_GLTF_RECORD") != NULL;
    uint8_t *mask = malloc(W * H);
    float *depth = malloc(sizeof(float) * W * H);
    assert_non_null(mask);
    assert_non_null(depth);
    int ran = 0, bad = 0, idx = 0;
    if (record) printf("/* generated by EGOFUSE_GLTF_RECORD=1 build/tests/test_gltf_samples */\n");
    for (size_t mi = 0; mi < MODELS; mi++) {
        const model_case *mc = &models[mi];
        char path[1024], msg[1200];
        if (!shared_ok(mc->rel, path, sizeof path)) {
            idx += TIMES * VIEWS;
            continue;
        }
        loaded l;
        if (!load(path, mc->scene, &l, msg, sizeof msg)) fail_msg("%s", msg);
        shot s[VIEWS];
        cameras(&l, mc->anim, s);
        if (record) printf("    /* %s scene %d anim %d */ {", mc->rel + 5, mc->scene, mc->anim);
        for (int ti = 0; ti < TIMES; ti++) {
            const int applies = ti == 0 || anim_of(&l, mc->anim) != NULL;
            if (record) printf("%s{", ti ? ", " : "");
            for (int v = 0; v < VIEWS; v++, idx++) {
                uint32_t crc = 0;
                if (applies) {
                    pose(&l, mc->anim, ti);
                    draw(&l, &s[v], mask, depth);
                    crc = tu_crc32(0, mask, W * H);
                    ran++;
                    if (count_set(mask) == 0) {
                        printf("empty mask: %s time %d view %d\n", mc->rel, ti, v);
                        bad++;
                    }
                    if (dump_dir)
                        dump(dump_dir, idx, path, mc->scene,
                             time_frac[ti] >= 0.0f ? mc->anim : -1, time_of(&l, mc->anim, ti),
                             &s[v], mask);
                }
                if (record) printf("%s0x%08xu", v ? ", " : "", crc);
                if (!record && crc != expected[mi][ti][v]) {
                    printf("%s scene %d anim %d time %.4g view %d: CRC 0x%08x, expected 0x%08x\n",
                           mc->rel, mc->scene, mc->anim, (double)time_of(&l, mc->anim, ti), v, crc,
                           expected[mi][ti][v]);
                    bad++;
                }
            }
            if (record) printf("}");
        }
        if (record) printf("},\n");
        unload(&l);
    }
    free(mask);
    free(depth);
    printf("NOTE: %d masks of %zu models checked\n", ran, MODELS);
    if (ran == 0) skip();
    if (!record) assert_int_equal(bad, 0);
}

/* ------------------------------------- features, checked by value */

/* SimpleMorph: the posed positions are base + sum w_k d_k with the mesh's
 * default weights (0.5, 0.5) at rest (not zeros) and the `weights`
 * channel's values at each of its keys; a node or count the channel does
 * not match leaves the weights untouched. */
static void morph_weights_drive_the_geometry(void **state)
{
    (void)state;
    char path[1024], msg[1200];
    if (!shared_ok("gltf/SimpleMorph/glTF/SimpleMorph.gltf", path, sizeof path)) skip();
    loaded l;
    if (!load(path, -1, &l, msg, sizeof msg)) fail_msg("%s", msg);
    assert_int_equal(l.model.mesh_count, 1);
    const kin_mesh *me = &l.model.meshes[0];
    assert_int_equal(me->target_count, 2);
    assert_non_null(me->target_weights);
    NEAR(me->target_weights[0], 0.5, 0.0);
    NEAR(me->target_weights[1], 0.5, 0.0);
    /* rest: base + 0.5 d0 + 0.5 d1, computed here from the arrays */
    pipe_pose_anim(&l.ps, NULL, 0.0f);
    for (int v = 0; v < 3; v++)
        for (int c = 0; c < 3; c++) {
            float want = me->positions[3 * v + c] + 0.5f * me->target_positions[3 * v + c];
            want += 0.5f * me->target_positions[9 + 3 * v + c];
            NEAR(l.ps.pos[0][3 * v + c], want, 1e-6);
        }
    /* animated: the weights channel's values at its keys */
    const kin_animation *a = &l.model.anims[0];
    const kin_channel *ch = NULL;
    for (int c = 0; c < a->channel_count; c++)
        if (a->channels[c].path == KIN_PATH_WEIGHTS) ch = &a->channels[c];
    assert_non_null(ch);
    assert_int_equal(ch->comps, 2);
    for (int k = 0; k < ch->key_count; k++) {
        float w[2] = {-1.0f, -1.0f};
        assert_int_equal(kin_anim_sample_weights(a, me->node, ch->times[k], w, 2), 1);
        NEAR(w[0], ch->values[2 * k], 0.0);
        NEAR(w[1], ch->values[2 * k + 1], 0.0);
        pipe_pose_anim(&l.ps, a, ch->times[k]);
        for (int v = 0; v < 3; v++)
            for (int c = 0; c < 3; c++) {
                float want = me->positions[3 * v + c];
                if (w[0] != 0.0f) want += w[0] * me->target_positions[3 * v + c];
                if (w[1] != 0.0f) want += w[1] * me->target_positions[9 + 3 * v + c];
                NEAR(l.ps.pos[0][3 * v + c], want, 1e-6);
            }
    }
    /* a node without a weights channel: untouched, 0 */
    float w[2] = {7.0f, 7.0f};
    assert_int_equal(kin_anim_sample_weights(a, me->node + 1, 0.5f, w, 2), 0);
    assert_int_equal(kin_anim_sample_weights(a, me->node, 0.5f, w, 3), 0);
    NEAR(w[0], 7.0, 0.0);
    unload(&l);
}

/* MeshPrimitiveModes: the TRIANGLE_STRIP and TRIANGLE_FAN meshes give the
 * spec's triangles of their index lists; POINTS and LINES are counted and
 * not drawn. */
static void primitive_modes_in_spec_order(void **state)
{
    (void)state;
    char path[1024];
    kin_model m;
    io_gltf_info info;
    load_shared("gltf/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", path, sizeof path, &m,
                &info);
    assert_int_equal(info.skipped_points, 1);
    assert_int_equal(info.skipped_lines, 3);
    assert_int_equal(info.strips, 1);
    assert_int_equal(info.fans, 1);
    assert_int_equal(m.mesh_count, 3);
    /* read from the file's buffer.bin with python: strip indices
     * 2 3 1 4 6 5 (6), fan 0 1 2 3 4 5 6 1 (8) */
    static const uint32_t strip[6] = {2, 3, 1, 4, 6, 5};
    static const uint32_t fan[8] = {0, 1, 2, 3, 4, 5, 6, 1};
    const kin_mesh *ms = &m.meshes[1], *mf = &m.meshes[2];
    assert_int_equal(ms->index_count, 3 * 4);
    assert_int_equal(mf->index_count, 3 * 6);
    for (int i = 0; i < 4; i++) {
        assert_int_equal(ms->indices[3 * i + 0], strip[i]);
        assert_int_equal(ms->indices[3 * i + 1], strip[i + 1 + i % 2]);
        assert_int_equal(ms->indices[3 * i + 2], strip[i + 2 - i % 2]);
    }
    for (int i = 0; i < 6; i++) {
        assert_int_equal(mf->indices[3 * i + 0], fan[i + 1]);
        assert_int_equal(mf->indices[3 * i + 1], fan[i + 2]);
        assert_int_equal(mf->indices[3 * i + 2], fan[0]);
    }
    kin_model_free(&m);
}

/* MultipleScenes: the default scene (1, the square) only; --scene 0 the
 * triangle only; a scene past the end is refused. */
static void scenes_pick_their_nodes(void **state)
{
    (void)state;
    char path[1024];
    kin_model m;
    io_gltf_info info;
    io_error err;
    load_shared("gltf/MultipleScenes/glTF/MultipleScenes.gltf", path, sizeof path, &m, &info);
    assert_int_equal(info.scene, 1);
    assert_int_equal(info.scene_count, 2);
    assert_int_equal(m.mesh_count, 1);
    assert_int_equal(m.meshes[0].vertex_count, 4);
    kin_model_free(&m);
    assert_int_equal(io_gltf_load_ex(path, 0, &m, &info, &err), IO_OK);
    assert_int_equal(info.scene, 0);
    assert_int_equal(m.mesh_count, 1);
    assert_int_equal(m.meshes[0].vertex_count, 3);
    kin_model_free(&m);
    assert_int_equal(io_gltf_load_ex(path, 2, &m, &info, &err), IO_ERR_ARGS);
    assert_non_null(strstr(err.msg, "MultipleScenes.gltf"));
    assert_non_null(strstr(err.msg, "scene 2"));
}

/* ------------------------------------ the pipeline (render / run) */

/* pipe_frame (what `egofuse render` and `run` call per frame, both eyes
 * on two threads) draws morphed and strip/fan models like pipe_pose_draw
 * of the same pose through the same eye camera, and the masks change
 * with the animation's morph weights; a frame posed by locals uses the
 * default weights again. */
static void pipeline_draws_morphs_and_strips(void **state)
{
    (void)state;
    static const struct { const char *rel; float head[3]; } cases[] = {
        {"gltf/SimpleMorph/glTF/SimpleMorph.gltf", {0.5f, 0.5f, 2.0f}},
        {"gltf/AnimatedMorphCube/glTF-Quantized/AnimatedMorphCube.gltf", {0.0f, 0.0f, 4.0f}},
        {"gltf/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", {0.0f, -1.5f, 8.0f}},
    };
    int ran = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        char path[1024], msg[1200];
        if (!shared_ok(cases[c].rel, path, sizeof path)) continue;
        loaded l;
        if (!load(path, -1, &l, msg, sizeof msg)) fail_msg("%s", msg);
        pipe_desc d = {0};
        d.threads = 2;
        pipe_ctx *p = pipe_create(&d, &l.model);
        assert_non_null(p);
        kin_sthmd_geometry g = pipe_geometry(p);
        const kin_sthmd_desc hd = kin_sthmd_desc_resolved(NULL);
        uint8_t *cam = calloc((size_t)hd.cam_width * hd.cam_height * 4, 1);
        uint8_t *virt = calloc((size_t)hd.lcd_width * hd.lcd_height * 4, 1);
        uint8_t *out[2] = {calloc((size_t)hd.lcd_width * hd.lcd_height * 4, 1),
                           calloc((size_t)hd.lcd_width * hd.lcd_height * 4, 1)};
        const int cw = g.crop_width, ch = g.crop_height;
        uint8_t *mask = malloc((size_t)cw * ch), *prev = calloc((size_t)cw * ch, 1);
        float *depth = malloc(sizeof(float) * (size_t)cw * ch);
        kin_mat4 head = kin_mat4_from_tr(kin_v3(cases[c].head[0], cases[c].head[1], cases[c].head[2]),
                                         kin_quat_identity());
        pipe_frame_in in;
        memset(&in, 0, sizeof in);
        in.head_node = -1;
        in.world_from_head = &head;
        for (int e = 0; e < 2; e++) {
            in.camera[e] = (fuse_image){cam, hd.cam_width, hd.cam_height, 4 * hd.cam_width};
            in.virt[e] = (fuse_image){virt, hd.lcd_width, hd.lcd_height, 4 * hd.lcd_width};
            in.out[e] = (fuse_image){out[e], hd.lcd_width, hd.lcd_height, 4 * hd.lcd_width};
        }
        in.lighting = pipe_lighting_default();
        const kin_animation *an = l.model.anim_count ? &l.model.anims[0] : NULL;
        int changed = 0;
        for (int ti = 0; ti < TIMES + 1; ti++) {
            /* the last frame: posed by locals (the rest transforms) */
            kin_transform *loc = NULL;
            if (ti == TIMES) {
                loc = malloc(sizeof *loc * (size_t)l.model.node_count);
                kin_pose_rest(&l.model, loc);
            }
            in.locals = loc;
            in.anim = ti > 0 && ti < TIMES ? an : NULL;
            in.time = an && ti > 0 && ti < TIMES ? time_frac[ti] * an->duration : 0.0f;
            char why[256] = "";
            assert_int_equal(pipe_frame(p, &in, NULL, why, sizeof why), PIPE_OK);
            /* the same pose drawn directly */
            if (loc) pipe_pose_locals(&l.ps, loc);
            else pipe_pose_anim(&l.ps, in.anim, in.time);
            for (int e = 0; e < 2; e++) {
                int mw = 0, mh = 0;
                const uint8_t *pm = pipe_mask(p, e, &mw, &mh);
                assert_int_equal(mw, cw);
                assert_int_equal(mh, ch);
                kin_camera kc = pipe_camera(p, e);
                rast_target tg = {cw, ch, depth, cw, mask, cw, NULL, 0, 0, NULL, 0};
                rast_target_clear(&tg);
                assert_int_equal(pipe_pose_draw(&l.ps, NULL, &kc, &tg, RAST_CULL_NONE, l.clip,
                                                l.vnrm, NULL), RAST_OK);
                int set = 0, diff = 0;
                for (int i = 0; i < cw * ch; i++) {
                    set += pm[i] != 0;
                    diff += (pm[i] != 0) != (mask[i] != 0);
                }
                if (set == 0 || diff != 0)
                    fail_msg("%s frame %d eye %d: %d px set, %d differ from pipe_pose_draw",
                             cases[c].rel, ti, e, set, diff);
                if (e == 0) {
                    if (ti > 0 && memcmp(prev, pm, (size_t)cw * ch) != 0) changed++;
                    memcpy(prev, pm, (size_t)cw * ch);
                }
            }
            free(loc);
        }
        /* morphs: the weights move the mask (frames 1, 2, and back to the
         * defaults in frame 3) */
        if (an) assert_true(changed >= 2);
        printf("NOTE: %s through pipe_frame: %d of %d frames changed the left mask\n",
               cases[c].rel + 5, changed, TIMES);
        pipe_destroy(p);
        EF_FREE_ALL(cam, virt, out[0], out[1], mask, prev, depth);
        unload(&l);
        ran++;
    }
    if (!ran) skip();
}

/* ----------------------------------------------- gltfpack variants */

static int find_gltfpack(char *buf, size_t n)
{
    const char *e = getenv("EGOFUSE_GLTFPACK");
    if (e && *e) {
        snprintf(buf, n, "%s", e);
        return access(buf, X_OK) == 0;
    }
    const char *path = getenv("PATH");
    if (!path) path = "/usr/bin:/bin";
    char dirs[4096];
    snprintf(dirs, sizeof dirs, "%s", path);
    for (char *save = NULL, *d = strtok_r(dirs, ":", &save); d; d = strtok_r(NULL, ":", &save)) {
        snprintf(buf, n, "%s/gltfpack", d);
        if (access(buf, X_OK) == 0) return 1;
    }
    return 0;
}

static void gltfpack_variants(void **state)
{
    (void)state;
    char gp[1024];
    if (!find_gltfpack(gp, sizeof gp)) {
        printf("SKIP: gltfpack not found (Debian package gltfpack, or EGOFUSE_GLTFPACK)\n");
        skip();
    }
    static const model_case packed[] = {
        {"gltf/CesiumMan/CesiumMan.glb", -1, 0},
        {"gltf/AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb", -1, 0},
        {"gltf/SimpleMorph/glTF/SimpleMorph.gltf", -1, 0},
        {"gltf/RiggedFigure/RiggedFigure.glb", -1, 0},
    };
    uint8_t *a = malloc(W * H), *b = malloc(W * H);
    float *depth = malloc(sizeof(float) * W * H);
    int tried = 0;
    for (size_t i = 0; i < sizeof packed / sizeof packed[0]; i++) {
        char path[1024], q[1024], c[1024], msg[1200], out[4096];
        if (!shared_ok(packed[i].rel, path, sizeof path)) continue;
        char name[64];
        snprintf(name, sizeof name, "gp%zu.q.glb", i);
        tu_tmp_path(name, q, sizeof q);
        snprintf(name, sizeof name, "gp%zu.c.glb", i);
        tu_tmp_path(name, c, sizeof c);
        char *argq[] = {gp, "-i", path, "-o", q, NULL};
        char *argc_[] = {gp, "-c", "-i", path, "-o", c, NULL};
        int rq = tu_run(argq, out, sizeof out);
        if (rq != 0) fail_msg("gltfpack -i %s: exit %d: %s", path, rq, out);
        int rc = tu_run(argc_, out, sizeof out);
        if (rc != 0) fail_msg("gltfpack -c -i %s: exit %d: %s", path, rc, out);
        tried++;

        /* the quantized (KHR_mesh_quantization) and the meshopt
         * (EXT_meshopt_compression, decoded by libmeshoptimizer) variants:
         * the same masks up to quantization (gltfpack also resamples the
         * animations at 30 Hz) */
        loaded lo, lv;
        if (!load(path, -1, &lo, msg, sizeof msg)) fail_msg("%s", msg);
        shot s[VIEWS];
        cameras(&lo, packed[i].anim, s);
        for (int var = 0; var < 2; var++) {
            const char *vp = var ? c : q;
            if (!load(vp, -1, &lv, msg, sizeof msg)) fail_msg("%s: %s", vp, msg);
            double worst = 1.0;
            int worst_px = 0;
            for (int ti = 0; ti < TIMES; ti++)
                for (int v = 0; v < VIEWS; v++) {
                    pose(&lo, packed[i].anim, ti);
                    pose(&lv, packed[i].anim, ti);
                    draw(&lo, &s[v], a, depth);
                    draw(&lv, &s[v], b, depth);
                    int both = 0, either = 0;
                    for (int p = 0; p < W * H; p++) {
                        both += a[p] && b[p];
                        either += a[p] || b[p];
                    }
                    double iou = either ? (double)both / either : 1.0;
                    if (iou < worst) {
                        worst = iou;
                        worst_px = either - both;
                    }
                    if (!(iou >= 0.95))
                        fail_msg("%s: time %d view %d: IoU %.4f against the original", vp, ti, v,
                                 iou);
                }
            printf("NOTE: %s, gltfpack %s: lowest IoU %.4f of %d masks (%d px differ)\n",
                   packed[i].rel + 5, var ? "-c (meshopt)" : "(quantized)", worst, TIMES * VIEWS,
                   worst_px);
            unload(&lv);
        }
        unload(&lo);
        remove(q);
        remove(c);
    }
    free(a);
    free(b);
    free(depth);
    if (!tried) skip();
}

/* ------------------------------------------------------ bad input */

/* A small buffer: 4 float positions (48 B) at 0, 4 int16 positions
 * (4 x 8 B, padded) at 48, 4 int8 normals (4 x 4 B) at 80, 6 u16
 * indices at 96, 2 u16 indices at 108; 112 bytes. Accessors:
 *   0 POSITION float VEC3 x4      1 POSITION short VEC3 x4 (stride 8)
 *   2 NORMAL byte VEC3 x4 (stride 4, normalized unless said)
 *   3 indices u16 x6               4 indices u16 x2
 *   5 POSITION float VEC3 x3 (a target of the wrong count)
 *   6 indices u16 x6, normalized (which indices must not be)
 *   7 sparse VEC3 x4 without a buffer view: zeros, and element 0 (the
 *     first u16 at byte 108) := (1, 0, 0) (the floats at byte 12) */
static void write_model(const char *path, const char *extra_json, const char *meshes,
                        const char *scenes, int normal_normalized)
{
    unsigned char buf[112];
    memset(buf, 0, sizeof buf);
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    memcpy(buf, pos, sizeof pos);
    for (int v = 0; v < 4; v++) {
        int16_t q[3] = {(int16_t)(pos[3 * v] * 100), (int16_t)(pos[3 * v + 1] * 100), 0};
        memcpy(buf + 48 + 8 * v, q, sizeof q);
        buf[80 + 4 * v + 2] = 127;
    }
    static const uint16_t idx[8] = {0, 1, 2, 0, 2, 3, 0, 1};
    memcpy(buf + 96, idx, sizeof idx);
    char data[200];
    tu_b64(buf, sizeof buf, data);
    /* extra_json "\"@views\":0," (dropped from the file) adds buffer 1
     * (48 zero bytes) and view 4, an EXT_meshopt_compression view into it
     * that reads buffer 0's first 48 bytes as its meshopt stream */
    const char *mv = strstr(extra_json, "\"@views\":0,");
    char extra[512];
    snprintf(extra, sizeof extra, "%.*s%s", mv ? (int)(mv - extra_json) : (int)strlen(extra_json),
             extra_json, mv ? mv + 11 : "");
    tu_write_fmt(path,
            "{\"asset\":{\"version\":\"2.0\"},%s"
            "\"buffers\":[{\"byteLength\":112,\"uri\":\"data:application/octet-stream;base64,%s\"}%s],"
            "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
            "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":32,\"byteStride\":8},"
            "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":16,\"byteStride\":4},"
            "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":16}%s],"
            "\"accessors\":["
            "{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
            "{\"bufferView\":1,\"componentType\":5122,\"count\":4,\"type\":\"VEC3\"},"
            "{\"bufferView\":2,\"componentType\":5120,\"count\":4,\"type\":\"VEC3\",\"normalized\":%s},"
            "{\"bufferView\":3,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
            "{\"bufferView\":3,\"byteOffset\":12,\"componentType\":5123,\"count\":2,\"type\":\"SCALAR\"},"
            "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
            "{\"bufferView\":3,\"componentType\":5123,\"normalized\":true,\"count\":6,"
            "\"type\":\"SCALAR\"},"
            "{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"sparse\":{\"count\":1,"
            "\"indices\":{\"bufferView\":3,\"byteOffset\":12,\"componentType\":5123},"
            "\"values\":{\"bufferView\":0,\"byteOffset\":12}}}],"
            "\"meshes\":[%s],\"nodes\":[{\"mesh\":0}],%s}\n",
            extra, data,
            mv ? ",{\"byteLength\":48,\"uri\":\"data:application/octet-stream;base64,"
                 "AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA\"}" : "",
            mv ? ",{\"buffer\":1,\"byteLength\":48,\"byteStride\":12,\"extensions\":"
                 "{\"EXT_meshopt_compression\":{\"buffer\":0,\"byteLength\":48,"
                 "\"byteStride\":12,\"count\":4,\"mode\":\"ATTRIBUTES\"}}}" : "",
            normal_normalized ? "true" : "false", meshes,
            scenes ? scenes : "\"scenes\":[{\"nodes\":[0]}],\"scene\":0");
}

static void expect_refused(const char *name, const char *extra, const char *meshes,
                           const char *scenes, int nn, const char *needle)
{
    char path[1024];
    tu_tmp_path(name, path, sizeof path);
    write_model(path, extra, meshes, scenes, nn);
    kin_model m;
    memset(&m, 0xAB, sizeof m);
    io_error err;
    io_result r = io_gltf_load(path, &m, &err);
    if (r == IO_OK || !strstr(err.msg, name) || !strstr(err.msg, needle))
        fail_msg("%s: result %s, message '%s' (wanted '%s')", name, io_result_str(r), err.msg,
                 needle);
    if (getenv("EGOFUSE_GLTF_VERBOSE")) printf("refused: %s\n", err.msg);
    static const kin_model zero;
    assert_memory_equal(&m, &zero, sizeof m);
    remove(path);
}

#define TRI "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3}]}"

static void bad_input_named(void **state)
{
    (void)state;
    char path[1024];
    /* the good model loads (so the refusals below are about their change) */
    tu_tmp_path("good.gltf", path, sizeof path);
    write_model(path, "", TRI, NULL, 1);
    kin_model m;
    io_error err;
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    kin_model_free(&m);
    write_model(path, "\"extensionsUsed\":[\"KHR_mesh_quantization\"],",
                "{\"primitives\":[{\"attributes\":{\"POSITION\":1,\"NORMAL\":2},\"indices\":3}]}",
                NULL, 1);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    assert_true(m.meshes[0].positions[3] == 100.0f);  /* SHORT, not normalized */
    NEAR(m.meshes[0].normals[2], 1.0, 0.0);           /* BYTE 127 normalized */
    kin_model_free(&m);
    /* a morph target given by a sparse accessor: vertex 0 moves by half
     * of (1, 0, 0), the others stay */
    write_model(path, "",
                "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,"
                "\"targets\":[{\"POSITION\":7}]}],\"weights\":[0.5]}",
                NULL, 1);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    {
        pipe_pose ps;
        assert_int_equal(pipe_pose_init(&ps, &m), 0);
        pipe_pose_anim(&ps, NULL, 0.0f);
        static const float want[12] = {0.5f, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
        for (int i = 0; i < 12; i++) NEAR(ps.pos[0][i], want[i], 0.0);
        pipe_pose_free(&ps);
    }
    kin_model_free(&m);
    /* required extensions that change only materials and textures */
    write_model(path,
                "\"extensionsUsed\":[\"KHR_materials_emissive_strength\",\"KHR_texture_transform\"],"
                "\"extensionsRequired\":[\"KHR_materials_emissive_strength\","
                "\"KHR_texture_transform\"],",
                TRI, NULL, 1);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    kin_model_free(&m);
    /* Draco used but not required: drawn from the uncompressed accessors */
    write_model(path, "\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],",
                "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,"
                "\"extensions\":{\"KHR_draco_mesh_compression\":{\"bufferView\":3,"
                "\"attributes\":{\"POSITION\":0}}}}]}",
                NULL, 1);
    assert_int_equal(io_gltf_load(path, &m, &err), IO_OK);
    assert_int_equal(m.meshes[0].index_count, 6);
    assert_true(m.meshes[0].positions[3] == 1.0f);
    kin_model_free(&m);
    remove(path);

    expect_refused("req_khr_meshopt.gltf",
                   "\"extensionsUsed\":[\"KHR_meshopt_compression\"],"
                   "\"extensionsRequired\":[\"KHR_meshopt_compression\"],",
                   TRI, NULL, 1, "requires extension KHR_meshopt_compression, which egofuse "
                                 "does not implement");
    /* EXT_meshopt_compression is decoded: a view whose data is not a
     * meshopt stream (the float positions) is refused */
    expect_refused("meshopt_garbage.gltf",
                   "\"extensionsUsed\":[\"EXT_meshopt_compression\"],"
                   "\"extensionsRequired\":[\"EXT_meshopt_compression\"],"
                   "\"@views\":0,",
                   TRI, NULL, 1, "buffer view 4: EXT_meshopt_compression data does not decode");
    expect_refused("req_draco.gltf",
                   "\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
                   "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],",
                   TRI, NULL, 1, "KHR_draco_mesh_compression");
    expect_refused("req_other.gltf", "\"extensionsRequired\":[\"EXT_unknown_thing\"],", TRI,
                   NULL, 1, "EXT_unknown_thing");
    expect_refused("target_count.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,"
                   "\"targets\":[{\"POSITION\":0},{\"POSITION\":5}]}]}",
                   NULL, 1, "mesh 0 primitive 0 target 1: POSITION has 3 elements, the primitive 4");
    expect_refused("target_weights.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":3,"
                   "\"targets\":[{\"POSITION\":0}]}],\"weights\":[0.5,0.5]}",
                   NULL, 1, "mesh 0 has 2 weights for 1 morph targets");
    expect_refused("strip2.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":4,\"mode\":5}]}",
                   NULL, 1, "mesh 0 primitive 0 is a TRIANGLE_STRIP of 2 indices (at least 3)");
    expect_refused("fan2.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":4,\"mode\":6}]}",
                   NULL, 1, "TRIANGLE_FAN of 2 indices");
    expect_refused("mode9.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":9}]}", NULL, 1,
                   "mode 9");
    expect_refused("scene_past.gltf", "", TRI, "\"scenes\":[{\"nodes\":[0]}],\"scene\":3", 1,
                   "scene");
    expect_refused("quant_undeclared.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":1},\"indices\":3}]}", NULL, 1,
                   "needs KHR_mesh_quantization");
    expect_refused("normal_unnormalized.gltf", "\"extensionsUsed\":[\"KHR_mesh_quantization\"],",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":2},\"indices\":3}]}",
                   NULL, 0, "NORMAL of mesh 0 primitive 0) is BYTE but not normalized");
    expect_refused("indices_normalized.gltf", "\"extensionsUsed\":[\"KHR_mesh_quantization\"],",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":6}]}", NULL, 1,
                   "accessor 6 (indices of mesh 0 primitive 0) is UNSIGNED_SHORT and normalized, "
                   "which it must not be");
    expect_refused("points_only.gltf", "",
                   "{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":0}]}", NULL, 1,
                   "POINTS and LINES are not drawn");
    /* counts that overflow: 2^27 elements */
    tu_tmp_path("huge.gltf", path, sizeof path);
    tu_write_fmt(path, "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":4,\"uri\":"
               "\"data:application/octet-stream;base64,AAAAAA==\"}],\"bufferViews\":[{\"buffer\":0,"
               "\"byteLength\":4}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
               "\"count\":134217728,\"type\":\"VEC3\"}],\"meshes\":[{\"primitives\":[{\"attributes\":"
               "{\"POSITION\":0}}]}],\"nodes\":[{\"mesh\":0}]}\n");
    assert_int_not_equal(io_gltf_load(path, &m, &err), IO_OK);
    if (!strstr(err.msg, "huge.gltf") || !strstr(err.msg, "POSITION of mesh 0 primitive 0"))
        fail_msg("%s", err.msg);
    remove(path);
}

/* The CLI: a refused file exits 1 with the message and writes nothing;
 * --scene past the end the same; a POINTS/LINES file prints a note. */
static void cli_refuses_without_output(void **state)
{
    (void)state;
    const char *bin = getenv("EGOFUSE_BIN");
    if (!bin || access(bin, X_OK) != 0) {
        printf("SKIP: EGOFUSE_BIN not set (run through tests/run_tests.sh)\n");
        skip();
    }
    char path[1024], out[1024], msg[4096];
    tu_tmp_path("cli_draco.gltf", path, sizeof path);
    write_model(path,
                "\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
                "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],",
                TRI, NULL, 1);
    tu_tmp_path("cli_mask.png", out, sizeof out);
    remove(out);
    char *argv[] = {(char *)bin, "mask", path, "--width", "8", "--height", "8", "--fov-y", "40",
                    "--eye", "0,0,3", "--target", "0,0,0", "--out", out, NULL};
    int rc = tu_run(argv, msg, sizeof msg);
    assert_int_equal(rc, 1);
    if (!strstr(msg, "cli_draco.gltf: requires extension KHR_draco_mesh_compression, which "
                     "egofuse does not implement"))
        fail_msg("%s", msg);
    assert_false(tu_exists(out));
    remove(path);

    char sp[1024];
    if (!shared_ok("gltf/MultipleScenes/glTF/MultipleScenes.gltf", sp, sizeof sp)) return;
    char *argv2[] = {(char *)bin, "mask", sp, "--width", "8", "--height", "8", "--fov-y", "40",
                     "--eye", "0,0,3", "--target", "0,0,0", "--scene", "5", "--out", out, NULL};
    assert_int_equal(tu_run(argv2, msg, sizeof msg), 1);
    if (!strstr(msg, "scene 5 requested")) fail_msg("%s", msg);
    assert_false(tu_exists(out));

    if (!shared_ok("gltf/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", sp, sizeof sp)) return;
    char *argv3[] = {(char *)bin, "mask", sp, "--width", "8", "--height", "8", "--fov-y", "40",
                     "--eye", "0,0,3", "--target", "0,0,0", "--out", out, NULL};
    assert_int_equal(tu_run(argv3, msg, sizeof msg), 0);
    if (!strstr(msg, "note:") || !strstr(msg, "not drawn")) fail_msg("%s", msg);
    assert_true(tu_exists(out));
    remove(out);
}

/* ------------------------- synthetic models of the other features */

static void put32(unsigned char *b, size_t off, float v) { memcpy(b + off, &v, 4); }

/* EXT_mesh_gpu_instancing (3 instances; ROTATION as normalized SHORT under
 * KHR_mesh_quantization) on a node that also has its own transform, and
 * the same mesh on a plain node. */
static void write_instanced(const char *path)
{
    unsigned char b[156];
    memset(b, 0, sizeof b);
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (int i = 0; i < 12; i++) put32(b, (size_t)i * 4, pos[i]);
    static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(b + 48, idx, sizeof idx);
    static const float t[9] = {0, 0, 0, 1.5f, 0, 0, 0, 1.5f, -0.5f};
    for (int i = 0; i < 9; i++) put32(b, 60 + (size_t)i * 4, t[i]);
    const float h45 = 0.38268343f, c45 = 0.92387953f, h30 = 0.25881905f, c30 = 0.96592583f;
    const float q[12] = {0, 0, 0, 1, 0, 0, h45, c45, h30, 0, 0, c30};
    for (int i = 0; i < 12; i++) {
        int16_t v = (int16_t)lrintf(q[i] * 32767.0f);
        memcpy(b + 96 + (size_t)i * 2, &v, 2);
    }
    static const float sc[9] = {1, 1, 1, 0.5f, 0.5f, 0.5f, 1, 2, 1};
    for (int i = 0; i < 9; i++) put32(b, 120 + (size_t)i * 4, sc[i]);
    char data[260];
    tu_b64(b, sizeof b, data);
    tu_write_fmt(path,
            "{\"asset\":{\"version\":\"2.0\"},"
            "\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\",\"KHR_mesh_quantization\"],"
            "\"extensionsRequired\":[\"EXT_mesh_gpu_instancing\",\"KHR_mesh_quantization\"],"
            "\"buffers\":[{\"byteLength\":156,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
            "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,"
            "\"byteLength\":12},{\"buffer\":0,\"byteOffset\":60,\"byteLength\":36},"
            "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":24},{\"buffer\":0,\"byteOffset\":120,"
            "\"byteLength\":36}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
            "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
            "{\"bufferView\":2,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
            "{\"bufferView\":3,\"componentType\":5122,\"normalized\":true,\"count\":3,\"type\":\"VEC4\"},"
            "{\"bufferView\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
            "\"nodes\":[{\"mesh\":0,\"translation\":[-0.5,-0.5,0],\"rotation\":[0,0.0871557,0,0.9961947],"
            "\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":{\"TRANSLATION\":2,"
            "\"ROTATION\":3,\"SCALE\":4}}}},{\"mesh\":0,\"translation\":[2,-1,0]}],"
            "\"scenes\":[{\"nodes\":[0,1]}],\"scene\":0}\n",
            data);
}

/* A strip of 4 quads skinned with two influence sets (JOINTS_0/WEIGHTS_0
 * and JOINTS_1/WEIGHTS_1, UNSIGNED_BYTE joints, float weights); odd
 * vertices' weights sum to 0.9 (kept as stored: a GPU pulls them towards
 * the joints' origin). Joints: a chain of three nodes with rotations,
 * no inverse bind matrices (identity). */
static void write_two_sets(const char *path)
{
    unsigned char b[568];
    memset(b, 0, sizeof b);
    for (int i = 0; i < 5; i++) {
        put32(b, (size_t)(i * 2) * 12 + 0, 0.5f * (float)i);
        put32(b, (size_t)(i * 2 + 1) * 12 + 0, 0.5f * (float)i);
        put32(b, (size_t)(i * 2 + 1) * 12 + 4, 0.4f);
    }
    uint16_t idx[24];
    for (int qd = 0; qd < 4; qd++) {
        uint16_t a = (uint16_t)(2 * qd), c = (uint16_t)(2 * qd + 2);
        uint16_t t6[6] = {a, c, (uint16_t)(a + 1), (uint16_t)(a + 1), c, (uint16_t)(c + 1)};
        memcpy(idx + qd * 6, t6, sizeof t6);
    }
    memcpy(b + 120, idx, sizeof idx);
    for (int v = 0; v < 10; v++) {
        float k = (float)v, sum = v % 2 ? 0.9f : 1.0f;
        b[168 + v * 4] = 0;                       /* set 0: joint 0 */
        put32(b, 208 + (size_t)v * 16, (1.0f - k / 10.0f) * sum);
        b[368 + v * 4] = 1;                       /* set 1: joints 1, 2 */
        b[368 + v * 4 + 1] = 2;
        put32(b, 408 + (size_t)v * 16, k / 20.0f * sum);
        put32(b, 408 + (size_t)v * 16 + 4, k / 20.0f * sum);
    }
    char data[800];
    tu_b64(b, sizeof b, data);
    tu_write_fmt(path,
            "{\"asset\":{\"version\":\"2.0\"},"
            "\"buffers\":[{\"byteLength\":568,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
            "\"bufferViews\":[{\"buffer\":0,\"byteLength\":120},{\"buffer\":0,\"byteOffset\":120,"
            "\"byteLength\":48},{\"buffer\":0,\"byteOffset\":168,\"byteLength\":40},"
            "{\"buffer\":0,\"byteOffset\":208,\"byteLength\":160},{\"buffer\":0,\"byteOffset\":368,"
            "\"byteLength\":40},{\"buffer\":0,\"byteOffset\":408,\"byteLength\":160}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":10,\"type\":\"VEC3\"},"
            "{\"bufferView\":1,\"componentType\":5123,\"count\":24,\"type\":\"SCALAR\"},"
            "{\"bufferView\":2,\"componentType\":5121,\"count\":10,\"type\":\"VEC4\"},"
            "{\"bufferView\":3,\"componentType\":5126,\"count\":10,\"type\":\"VEC4\"},"
            "{\"bufferView\":4,\"componentType\":5121,\"count\":10,\"type\":\"VEC4\"},"
            "{\"bufferView\":5,\"componentType\":5126,\"count\":10,\"type\":\"VEC4\"}],"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"JOINTS_0\":2,"
            "\"WEIGHTS_0\":3,\"JOINTS_1\":4,\"WEIGHTS_1\":5},\"indices\":1}]}],"
            "\"skins\":[{\"joints\":[1,2,3]}],"
            "\"nodes\":[{\"mesh\":0,\"skin\":0},{\"children\":[2],\"translation\":[0,0.1,0]},"
            "{\"children\":[3],\"translation\":[0,0.3,0],\"rotation\":[0,0,0.17364818,0.98480775]},"
            "{\"translation\":[0.2,0,0.1],\"rotation\":[0,-0.25881905,0,0.96592583]}],"
            "\"scenes\":[{\"nodes\":[0,1]}],\"scene\":0}\n",
            data);
}

/* Expected CRC-32 of the synthetic masks [model][view], recorded after
 * tests/tools/gltf_ref.py agreed (EGOFUSE_GLTF_DUMP: files 9NN). */
static const uint32_t synthetic_expected[2][VIEWS] = {
    {0x96e2f3c8u, 0xe2d4a8fdu},  /* instanced.gltf */
    {0xe70f69dau, 0x7fe7c9e4u},  /* two_sets.gltf */
};

static void synthetic_features_match_their_crcs(void **state)
{
    (void)state;
    const char *dump_dir = getenv("EGOFUSE_GLTF_DUMP");
    const int record = getenv("EGOFUSE_GLTF_RECORD") != NULL;
    static const char *const names[2] = {"instanced.gltf", "two_sets.gltf"};
    uint8_t *mask = malloc(W * H);
    float *depth = malloc(sizeof(float) * W * H);
    int bad = 0;
    for (int mi = 0; mi < 2; mi++) {
        char path[1024], msg[1200];
        tu_tmp_path(names[mi], path, sizeof path);
        if (mi == 0) write_instanced(path);
        else write_two_sets(path);
        loaded l;
        if (!load(path, -1, &l, msg, sizeof msg)) fail_msg("%s", msg);
        if (mi == 0) {
            assert_int_equal(l.model.mesh_count, 4);  /* 3 instances + 1 */
            assert_int_equal(l.model.node_count, 2 + 3);
        } else {
            assert_int_equal(l.model.meshes[0].extra_sets, 1);
            /* the pipe skins it (no plan) as kin_skin_lbs does: by hand
             * for vertex 9, the last: B = sum of w_i jm_i over both sets */
            pose(&l, -1, 0);
            const kin_mesh *me = &l.model.meshes[0];
            const kin_mat4 *jm = l.ps.joint_mats[0];
            double want[3] = {0, 0, 0};
            const float *p = me->positions + 27;
            for (int k = 0; k < 8; k++) {
                const float w = k < 4 ? me->weights[36 + k] : me->weights_extra[36 + k - 4];
                const int j = k < 4 ? me->joints[36 + k] : me->joints_extra[36 + k - 4];
                if (w == 0.0f) continue;
                for (int r = 0; r < 3; r++)
                    want[r] += w * ((double)jm[j].m[r] * p[0] + (double)jm[j].m[4 + r] * p[1] +
                                    (double)jm[j].m[8 + r] * p[2] + jm[j].m[12 + r]);
            }
            for (int r = 0; r < 3; r++) NEAR(l.ps.pos[0][27 + r], want[r], 1e-5);
        }
        shot s[VIEWS];
        cameras(&l, -1, s);
        for (int v = 0; v < VIEWS; v++) {
            pose(&l, -1, 0);
            draw(&l, &s[v], mask, depth);
            uint32_t crc = tu_crc32(0, mask, W * H);
            if (dump_dir) dump(dump_dir, 900 + mi * VIEWS + v, path, -1, -1, 0.0f, &s[v], mask);
            if (record) printf("synthetic %s view %d: 0x%08xu\n", names[mi], v, crc);
            if (!record && crc != synthetic_expected[mi][v]) {
                printf("%s view %d: CRC 0x%08x, expected 0x%08x\n", names[mi], v, crc,
                       synthetic_expected[mi][v]);
                bad++;
            }
            if (count_set(mask) == 0) bad++;
        }
        unload(&l);
        if (!dump_dir) remove(path);
    }
    free(mask);
    free(depth);
    if (!record) assert_int_equal(bad, 0);
}

TU_MAIN(NULL, NULL,
        cmocka_unit_test(every_model_matches_its_crcs),
        cmocka_unit_test(morph_weights_drive_the_geometry),
        cmocka_unit_test(primitive_modes_in_spec_order),
        cmocka_unit_test(scenes_pick_their_nodes),
        cmocka_unit_test(pipeline_draws_morphs_and_strips),
        cmocka_unit_test(gltfpack_variants),
        cmocka_unit_test(synthetic_features_match_their_crcs),
        cmocka_unit_test(bad_input_named),
        cmocka_unit_test(cli_refuses_without_output))
