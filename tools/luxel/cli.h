/* Shared pieces of the luxel command-line tool (private to tools/luxel). */
#ifndef LUXEL_CLI_H
#define LUXEL_CLI_H

#include "luxel/luxel.h"

#include <stdbool.h>

/* Exit statuses: 0 every output written, 1 a failed run, 2 a usage error. */
enum { EXIT_OK = 0, EXIT_FAILED = 1, EXIT_USAGE = 2 };

int cmd_bake(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_ies(int argc, char **argv);
int cmd_ibl(int argc, char **argv);

/* "luxel: error: <message>" on stderr. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Usage error: the message, a hint to --help, returns EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Strict number parsing: the whole string, finite, within [lo, hi]. */
bool cli_parse_int(const char *s, long lo, long hi, long *out);
bool cli_parse_float(const char *s, double lo, double hi, double *out);
/* The float image formats and PNG: "exr", "hdr", "pfm" or "png". */
bool cli_parse_format(const char *s, lx_image_format *out);
/* "R,G,B" with finite components >= 0. */
bool cli_parse_rgb(const char *s, lx_vec3 *out);

/* Loads the environment argument ENV of `command` (ibl, bake --sky): an
 * image (lx_env_load, at face size `size`, 0 = the input's) or a constant
 * colour const:R,G,B / const:L in nits, times intensity. Prints the error
 * and returns EXIT_FAILED (a bad file) or EXIT_USAGE (a bad const:); *out
 * is zeroed on failure. */
int cli_load_environment(const char *command, const char *env, float intensity, int size,
                         lx_cubemap *out);

/* Progress bar on stderr: drawn only when stderr is a terminal, not quiet,
 * and the work has run for more than a second. Returns false after SIGINT. */
typedef struct cli_progress {
    const char *label;
    bool enabled;
    bool drawn;
    double start;
    double last_draw;
} cli_progress;
void cli_progress_init(cli_progress *p, const char *label, bool quiet);
bool cli_progress_update(void *user, float fraction);
void cli_progress_finish(cli_progress *p);

/* SIGINT/SIGTERM: cancel the running work; while outputs are being written,
 * remove this run's files and exit. */
void cli_install_signal_handlers(void);
bool cli_interrupted(void);
/* Registers a completed output so an interrupt can remove it; false when
 * out of memory (the caller must not write it then). */
bool cli_track_output(const char *path);
void cli_remove_tracked_outputs(void);
/* Stops tracking outputs without removing them (they were published). */
void cli_forget_outputs(void);
/* Folders an interrupt removes after the tracked files, if empty: the
 * staging folder, then the `count` folders this run created, deepest first
 * (the output folder and its parents that were missing). */
void cli_track_dir(const char *dir, const char *const *created, uint32_t count);
void cli_set_writing(bool writing);

/* Monotonic seconds. */
double cli_now(void);

/* ---- staged output (stage.c) ---------------------------------------------
 * Files go to OUTPUT/.luxel-<6 random characters> and are moved into
 * OUTPUT together by cli_stage_publish once all are written; interrupts remove them. Every
 * function prints its own "luxel: error:" line and returns false on
 * failure. Usage:
 *   cli_stage st;
 *   if (!cli_stage_begin(&st, dir)) return EXIT_FAILED;
 *   bool ok = cli_stage_image(&st, "a.exr", &img, NULL) && cli_stage_publish(&st);
 *   cli_stage_clear(&st); cli_set_writing(false);
 */
typedef struct cli_stage {
    char *output; /* the final folder */
    char *dir;    /* OUTPUT/.luxel- and six random characters (mkdtemp) */
    char **names; /* files written into it */
    uint32_t count;
    bool created; /* the output folder is this run's and nothing is published yet */
    char **made;  /* the folders this run created, deepest first */
    uint32_t made_count;
} cli_stage;

/* Creates dir and its parents. */
bool cli_make_dirs(const char *dir);
/* Creates the output folder and the staging folder inside it, and enters
 * the writing state (an interrupt removes this run's files). */
bool cli_stage_begin(cli_stage *st, const char *output);
/* The path of a new staged file (malloc'd; tracked so an interrupt removes
 * it), for writers other than images and text; end with cli_stage_finish
 * and the writer's status. NULL when out of memory. */
char *cli_stage_path(cli_stage *st, const char *name);
bool cli_stage_finish(cli_stage *st, const char *name, lx_status status);
bool cli_stage_image(cli_stage *st, const char *name, const lx_image *img,
                     const lx_image_write_desc *desc);
bool cli_stage_text(cli_stage *st, const char *name, const char *text);
/* Moves every staged file into the output folder, with interrupts held
 * off; on a failed rename the ones already moved are removed again. */
bool cli_stage_publish(cli_stage *st);
/* Removes whatever is still staged and the staging folder. */
void cli_stage_clear(cli_stage *st);

#endif
