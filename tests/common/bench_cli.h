/* Helpers of bench_bake's whole-process case ([3]): running the luxel CLI
 * as a child process, the library calls `luxel bake` makes timed phase by
 * phase in a fresh process, and the image writers luxel had before (the
 * baselines of the writers' figures). Errors end the process with a
 * message (these are benchmark tools). */
#ifndef LX_BENCH_CLI_H
#define LX_BENCH_CLI_H

#include "luxel/luxel.h"

/* The path of program `name` in this program's folder (build/bin). */
void lx_bench_sibling(const char *name, char *out, size_t size);

/* The scene at *path, or when *path is NULL gen_scenes' room.glb, made in
 * a fresh folder /tmp/<program>.XXXXXX that is removed once loaded (*path
 * then names it "room (gen_scenes)"). Ends the bench when it fails. */
lx_scene *lx_bench_load_room(const char *program, const char **path);

/* qsort's comparison of doubles, ascending. */
int lx_bench_cmp_double(const void *a, const void *b);

/* Runs argv (argv[0] a path) as a child process with its stderr in file
 * log; returns its wall time from fork to exit, ending the bench when it
 * fails. */
double lx_bench_run_child(char *const argv[], const char *log);

/* The phases of `luxel bake`, in seconds. */
typedef struct lx_bench_phases {
    double import, texel_maps, bvh, bake, dynamic, apply, exr, png;
} lx_bench_phases;

#define LX_BENCH_PHASES 8
extern const char *const lx_bench_phase_names[LX_BENCH_PHASES];

/* Keeps in best the smaller of each phase. */
void lx_bench_phases_min(lx_bench_phases *best, const lx_bench_phases *p);

/* The calls `luxel bake` makes (import with the lights JSON, lx_baker_create
 * with its padding, bake, update, apply and meter, the EXR and the PNG
 * preview into dir) on `threads`, timed: run in a fresh process, this
 * program with argv[1] = "--phases-child" (lx_bench_phases_child ends it),
 * so fresh memory costs what it costs the CLI. */
void lx_bench_phases_run(const char *glb, const char *json, const char *dir, int res, int threads,
                         lx_bench_phases *out);
/* The child's side: when argv[1] is "--phases-child", runs, prints the
 * times on stdout and exits; otherwise returns. */
void lx_bench_phases_child(int argc, char **argv);

/* The writers luxel had, for the figures' baselines: a float RGB EXR with
 * ZIP at zlib's default level, chunks encoded one after another on one
 * thread; a preview PNG of RGB img x exposure with sRGB codes by binary
 * search and stb_image_write's own deflate (level 8, each row's filter
 * chosen from all five). Both fsync their file as lx_image_write does.
 * Return seconds. */
double lx_bench_old_exr(const lx_image *img, const char *path);
double lx_bench_old_png(const lx_image *img, float exposure, const char *path);

/* A file's size in bytes, -1 when it cannot be read. */
long lx_bench_file_size(const char *path);

#endif
