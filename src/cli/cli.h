/* cli.h - internals of the egofuse program (not a library interface). */
#ifndef EGOFUSE_CLI_H
#define EGOFUSE_CLI_H

#include <stdio.h>

#include "../fuse/fuse.h"
#include "../io/io.h"
#include "../kin/kin.h"
#include "../raster/raster.h"

/* Exit codes of every subcommand. */
enum {
    EXIT_OK = 0,
    EXIT_FAIL = 1,     /* a bad input or a failed step: message on stderr */
    EXIT_USAGE = 2     /* bad command line */
};

int cmd_mask(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_demo(int argc, char **argv);

/* Prints "egofuse: " + message to stderr; returns EXIT_FAIL. */
int cli_fail(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Prints "egofuse CMD: " + message + a hint to run --help; EXIT_USAGE. */
int cli_usage_error(const char *cmd, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Strict parsers: the whole string must be the number(s); finite. */
int cli_parse_int(const char *s, int lo, int hi, int *out);
int cli_parse_float(const char *s, float *out);
int cli_parse_vec3(const char *s, float out[3]);

/* Creates a folder and its parents (like mkdir -p). 0 on success. */
int cli_mkdirs(const char *path);

/* ------------------------------------------------------------ posing */

/* Per-frame state for posing and skinning a model: all buffers allocated
 * once by pose_init. Skinned meshes end up in world space; unskinned ones
 * are moved by their node's world matrix. */
typedef struct pose_state {
    const kin_model *model;
    kin_transform *locals;    /* node_count */
    kin_mat4 *world;          /* node_count */
    kin_mat4 **joint_mats;    /* per skin, joint_count */
    float **bind_normals;     /* per mesh: the file's normals, or smooth
                                 ones computed when the file has none */
    kin_mesh *meshes;         /* copies of the model's meshes pointing at
                                 bind_normals */
    float **pos;              /* per mesh, 3 per vertex, world space */
    float **nrm;              /* per mesh, 3 per vertex, world space, unit */
    float *clip;              /* 4 per vertex of the largest mesh */
    float *vnrm;              /* 3 per vertex of the largest mesh */
} pose_state;

int  pose_init(pose_state *ps, const kin_model *m);
void pose_free(pose_state *ps);
/* Poses the model at time t of animation anim (NULL: rest pose), fills
 * world matrices and skinned world-space vertices and normals. */
void pose_eval(pose_state *ps, const kin_animation *anim, float t);
/* Draws every mesh of the posed model through the camera into target
 * (which must have attr_count 3 for view-space normals, or 0). */
rast_result pose_draw(pose_state *ps, const kin_camera *cam,
                      const rast_target *target, rast_stats *stats);

/* Progress on a terminal (stderr), nothing otherwise. */
typedef struct progress {
    int enabled;
    int total;
    double t0;
} progress;
void progress_start(progress *p, int total);
void progress_step(progress *p, int done, const char *what);
void progress_end(progress *p);
double cli_now(void);

#endif
