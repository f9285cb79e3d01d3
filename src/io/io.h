/* io.h - files and devices of egofuse: images (OpenImageIO), glTF models
 * (tinygltf) and scene files. The core (raster, kin, fuse) never includes
 * this header.
 *
 * ERRORS
 *   Every call returns an io_result (IO_OK = 0) and, on failure, fills the
 *   caller's io_error with the code and a message that names the input and
 *   the reason, e.g. "model.glb: accessor 3 (JOINTS_0) reads past the end of
 *   buffer view 2". No global error state; no C++ exception crosses this
 *   header (the C++ shims catch everything).
 *
 * OUTPUT FILES
 *   Writers never leave a half-written file: every write and the close are
 *   checked (io_out below), the file gets its name only when complete, and
 *   a failure (disk full, file size limit, folder not writable) is
 *   IO_ERR_WRITE "path: reason (strerror)" with nothing left behind.
 *
 * USAGE
 *   io_error err;
 *   kin_model m;
 *   if (io_gltf_load("arms.glb", &m, &err) != IO_OK) {
 *       fprintf(stderr, "egofuse: %s\n", err.msg); return 1; }
 *   io_image img;
 *   if (io_image_load("cam.png", IO_U8, 4, &img, &err) != IO_OK) ...
 *   io_image_save("out.png", &img, &err);
 *   io_image_free(&img); kin_model_free(&m);
 */
#ifndef EGOFUSE_IO_H
#define EGOFUSE_IO_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "../fuse/fuse.h"
#include "../kin/kin.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IO_RESULT_LIST(X)                                              \
    X(IO_OK,            "ok")                                          \
    X(IO_ERR_ARGS,      "invalid arguments")                           \
    X(IO_ERR_NOT_FOUND, "file not found")                              \
    X(IO_ERR_READ,      "read error")                                  \
    X(IO_ERR_WRITE,     "write error")                                 \
    X(IO_ERR_FORMAT,    "corrupt or unsupported file")                 \
    X(IO_ERR_MISSING,   "required data missing")                       \
    X(IO_ERR_SIZE,      "wrong size")                                  \
    X(IO_ERR_VALUE,     "invalid value")                               \
    X(IO_ERR_NOMEM,     "out of memory")                               \
    X(IO_ERR_DEVICE,    "device error")

typedef enum io_result {
#define IO__ENUM(name, text) name,
    IO_RESULT_LIST(IO__ENUM)
#undef IO__ENUM
    IO_RESULT_COUNT
} io_result;

typedef struct io_error {
    io_result code;
    char msg[1024];
} io_error;

const char *io_result_str(io_result r);
/* Sets err (if not NULL) with a printf-style message and returns code. */
io_result io_fail(io_error *err, io_result code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Strict decimal integer: the whole of s (leading blanks allowed, as
 * strtol) a number in lo..hi: 1 and *out; else 0, *out unchanged. io's
 * option values (io_natnet) and the command line's (cli_parse_int). */
int io_parse_int(const char *s, int lo, int hi, int *out);

/* CLOCK_MONOTONIC now, in ns: the clock of the devices' time stamps
 * (io_dev.h, io_display.h, io_vsrc.h) and of `egofuse run`'s loop. */
uint64_t io_now_ns(void);

/* IO_OK if path names an existing file that is not a folder, else
 * IO_ERR_NOT_FOUND or IO_ERR_READ with "path: reason". */
io_result io_check_file(const char *path, io_error *err);

/* --------------------------------------------------------- output files
 * io_out.c. An output file that is complete or absent: write with stdio on
 * o.f (fprintf, fwrite: no need to check each call, the first failure and
 * its errno are kept), then io_out_commit() names the file <path> when
 * every byte was written, or removes it and fails with "path: write
 * failed: No space left on device; nothing written". The file is unnamed
 * until the commit (O_TMPFILE), so a killed process leaves nothing; where
 * O_TMPFILE is missing it is "<path>.tmp.<pid>" until renamed. Do not copy
 * an open io_out (its stream points at it). */

#define IO_PATH_MAX 1024

typedef struct io_out {
    FILE *f;                      /* the stream to write; never fclose it */
    int fd;                       /* its descriptor (-1 when closed) */
    int unnamed;                  /* 1: O_TMPFILE, no name yet */
    int error;                    /* errno of the first failed write, 0 */
    char path[IO_PATH_MAX];
    char tmp[IO_PATH_MAX + 32];   /* "<path>.tmp.<pid>" */
} io_out;

io_result io_out_open(io_out *o, const char *path, io_error *err);
/* Flushes, checks, names the file; closes o in every case. */
io_result io_out_commit(io_out *o, io_error *err);
/* Discards the file (nothing is left); safe after a failed open. */
void io_out_abort(io_out *o);
/* A whole file from memory, through io_out. */
io_result io_write_file(const char *path, const void *data, size_t len,
                        io_error *err);

/* --------------------------------------------------------------- images */

typedef enum io_type { IO_U8 = 0, IO_F32 = 1 } io_type;

/* Interleaved pixels, rows top to bottom. */
typedef struct io_image {
    void *data;           /* owned: io_image_free() releases it */
    int width, height;
    int channels;         /* 1..4 */
    io_type type;
    size_t stride;        /* bytes per row */
} io_image;

/* Allocates a zeroed image (stride = width * channels * size of type). */
io_result io_image_alloc(io_image *img, int width, int height, int channels,
                         io_type type, io_error *err);
/* Loads any format OpenImageIO reads (PNG, EXR, ...), converted to `type`
 * with `channels` channels (0 = as in the file; 1 -> 3/4 replicates grey,
 * missing alpha becomes opaque, extra channels are dropped). */
io_result io_image_load(const char *path, io_type type, int channels,
                        io_image *out, io_error *err);
/* Writes by extension (.png, .exr, .tif, .jpg, .ppm ...); PNG and other
 * 8-bit formats from IO_F32 are clamped to [0,1] and scaled. */
io_result io_image_save(const char *path, const io_image *img,
                        io_error *err);
void io_image_free(io_image *img);

/* ----------------------------------------------------------------- glTF */

/* Loads a glTF 2.0 model (.gltf with embedded or external buffers, or
 * .glb): every node (sorted parent first), one kin_mesh per triangle
 * primitive (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN; POINTS and LINES*
 * are not drawn) of every mesh node of the default scene (`scene`, else
 * scenes[0]; all nodes when the file has no scenes), one per instance
 * with EXT_mesh_gpu_instancing; positions required; normals, morph
 * targets, every JOINTS_n / WEIGHTS_n set when present (quantized with
 * KHR_mesh_quantization or float); skins and animations. A file whose
 * extensionsRequired names an extension egofuse does not implement is
 * refused with its name (docs/io.md). The result is validated with
 * kin_model_validate(); free it with kin_model_free(). */
io_result io_gltf_load(const char *path, kin_model *out, io_error *err);
/* io_glb_check.c: the container of a binary glTF (header length, chunk
 * lengths) against its len bytes, so a truncated file says where it ends:
 * "arms.glb: truncated GLB: the header gives 9000 bytes, the file has 4096
 * (it ends 4904 bytes early)". IO_OK for data that is not GLB. */
io_result io_glb_check(const char *path, const void *data, size_t len,
                       io_error *err);

/* What io_gltf_load_ex drew and skipped (for notes to the user). */
typedef struct io_gltf_info {
    int scene;             /* the scene drawn, -1 when the file has none */
    int scene_count;
    int skipped_points;    /* primitives of mode POINTS (not drawn) */
    int skipped_lines;     /* LINES, LINE_LOOP, LINE_STRIP (not drawn) */
    int strips, fans;      /* TRIANGLE_STRIP / TRIANGLE_FAN primitives drawn */
    int morph_meshes;      /* kin_meshes with morph targets */
    int instances;         /* kin_meshes made by EXT_mesh_gpu_instancing */
} io_gltf_info;

/* io_gltf_load with the scene to draw: scene >= 0 picks scenes[scene]
 * (IO_ERR_ARGS when the file has fewer), -1 the default. info (or NULL)
 * receives the counts above. */
io_result io_gltf_load_ex(const char *path, int scene, kin_model *out,
                          io_gltf_info *info, io_error *err);

/* External buffer and image URIs of a model resolve only inside the
 * model's folder (data: URIs always load): an absolute URI, or one whose
 * percent-decoded path leads out of the folder (`..`, a symlink; checked
 * on its realpath), is refused with IO_ERR_VALUE "arms.gltf: buffer 0: uri
 * '../x.bin' leads outside the model's folder (/models); ...", before the
 * file is opened. io_gltf_allow_outside(1) lifts this for every later load
 * of the process (the CLI's --allow-outside); call it before loading, not
 * while another thread loads. */
void io_gltf_allow_outside(int allow);

/* ---------------------------------------------------------------- scene */

/* A recorded sequence to composite (`egofuse render --scene FILE`). The
 * text format is documented in docs/scene.md; relative paths in it are
 * resolved against the scene file's folder. */
typedef struct io_scene {
    char dir[IO_PATH_MAX];            /* folder of the scene file */
    char model[IO_PATH_MAX];          /* glTF of the mask model */
    char animation[KIN_NAME_MAX];     /* animation name, or "" for index 0 */
    char head_node[KIN_NAME_MAX];     /* node whose world matrix is the head */
    int frames;                       /* number of frames */
    float fps;                        /* frames per second */
    float anim_start;                 /* animation time of frame 0, s (default 0) */
    char camera[2][IO_PATH_MAX];      /* printf patterns (%d of the frame),
                                         left and right camera images */
    char virt[2][IO_PATH_MAX];        /* virtual scene colour, per eye */
    char virt_depth[2][IO_PATH_MAX];  /* virtual scene depth, or "" */
    /* lighting of the virtual scene, world space directions */
    int light_count;
    float light_dir[8][3];
    float light_color[8][3];
    float ambient[3];
    float kd, ks, shininess, kf;
    float tone[3];
    int has_lighting;                 /* 0 = use fuse_lighting_default() */
    char tracking[IO_PATH_MAX];       /* recorded tracking of the sequence
                                         (docs/tracking.md), or "" */
    char hmd[32];                     /* the named HMD that recorded it
                                         (kin_sthmd_preset), or "": the
                                         paper's */
} io_scene;

io_result io_scene_load(const char *path, io_scene *out, io_error *err);
/* The scene's lighting for the fuse stage, light directions in WORLD space
 * (src/pipe turns them into each camera's view space); the defaults of
 * fuse_lighting_default() when the file sets none. */
fuse_lighting io_scene_lighting(const io_scene *s);
/* Expands a frame pattern of the scene into an absolute-or-relative path. */
void io_scene_frame_path(const io_scene *s, const char *pattern, int frame,
                         char *out, size_t out_size);

/* ------------------------------------------------------------- tracking
 * io_track.c: recorded tracking files ("egofuse-track 1"), per-user
 * calibration files ("egofuse-calib 1") and the live UDP stream of
 * KIN_TRACK_PACKET_SIZE-byte packets (formats: docs/tracking.md; parsing
 * is kin's, see kin_track_parse / kin_track_packet_read). */

/* Loads a whole recording; *out is allocated (free with io_track_free).
 * Errors name the file and line: "rec.txt:12: SL needs 3 numbers, got 2". */
io_result io_track_load(const char *path, kin_track_sample **out, int *count,
                        io_error *err);
void io_track_free(kin_track_sample *samples);
/* Writes a recording (header + one line per sample), atomically. */
io_result io_track_save(const char *path, const kin_track_sample *samples,
                        int count, io_error *err);

io_result io_user_calib_load(const char *path, kin_user_calib *out,
                             io_error *err);
io_result io_user_calib_save(const char *path, const kin_user_calib *c,
                             io_error *err);

/* One UDP endpoint: a receiver (io_track_udp_listen) or a sender
 * (io_track_udp_connect). Plain data; close with io_track_udp_close. */
typedef struct io_track_udp {
    int fd;                      /* socket, -1 when closed */
    int port;                    /* bound (receiver) or destination port */
    uint32_t dest_addr;          /* sender: IPv4 address, network order */
    /* receiver state */
    uint64_t packets;            /* datagrams received */
    uint64_t accepted;           /* valid and newer than the last */
    uint64_t rejected;           /* malformed (size, magic, CRC, values) */
    uint64_t stale;              /* valid but not newer (reordered, dup) */
    uint32_t last_seq;           /* sequence of the last accepted packet */
    int have_good;               /* 1 once a packet was accepted */
    kin_track_sample last_good;  /* the newest accepted sample */
    char status[512];            /* last report, e.g. "packet 17: CRC
                                    mismatch (...); keeping the pose of
                                    seq 15 (t = 1.250 s)" */
} io_track_udp;

/* An IPv4 address: host as a dotted quad, else a host name resolved to
 * IPv4 (getaddrinfo). 0 and *addr (network order), or -1 and *why (may be
 * NULL) the resolver's reason (gai_strerror; a static string). The UDP
 * endpoints here, io_natnet and `egofuse replay` name their own input. */
int io_ipv4_resolve(const char *host, uint32_t *addr, const char **why);

/* Binds a receiver to addr (dotted IPv4 or a host name resolved to IPv4;
 * "0.0.0.0" = every interface, for a tracking PC on another machine;
 * NULL or "" = "127.0.0.1") and port (0 = any free port; read it back
 * from u->port). Non-blocking. A bad address names it and the reason. */
io_result io_track_udp_listen(io_track_udp *u, const char *addr, int port,
                              io_error *err);
/* Reads every pending datagram, waiting up to timeout_ms (0 = not at all)
 * for the first. Valid packets with a sequence newer than the last
 * (serial-number arithmetic, so it wraps) are accepted; others are
 * counted and described in u->status, never fatal. *out receives the
 * newest good sample (the last good pose when nothing new came, valid = 0
 * before the first), *fresh (may be NULL) the number accepted now.
 * Returns IO_OK, or IO_ERR_DEVICE on a socket error (state kept). */
io_result io_track_udp_poll(io_track_udp *u, int timeout_ms,
                            kin_track_sample *out, int *fresh, io_error *err);
/* A sender to addr:port. */
io_result io_track_udp_connect(io_track_udp *u, const char *addr, int port,
                               io_error *err);
io_result io_track_udp_send(io_track_udp *u, const kin_track_sample *s,
                            uint32_t seq, io_error *err);
/* Sends arbitrary bytes (tests of malformed packets). */
io_result io_track_udp_send_raw(io_track_udp *u, const void *bytes, size_t n,
                                io_error *err);
void io_track_udp_close(io_track_udp *u);

#ifdef __cplusplus
}
#endif
#endif
