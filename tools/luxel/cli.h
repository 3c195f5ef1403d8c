/* Shared pieces of the luxel command-line tool (private to tools/luxel). */
#ifndef LUXEL_CLI_H
#define LUXEL_CLI_H

#include "luxel/luxel.h"

#include <cjson/cJSON.h>

#include <stdbool.h>

/* Exit statuses: 0 every output written, 1 a failed run, 2 a usage error. */
enum { EXIT_OK = 0, EXIT_FAILED = 1, EXIT_USAGE = 2 };

int cmd_bake(int argc, char **argv);
int cmd_info(int argc, char **argv);
int cmd_ies(int argc, char **argv);
int cmd_ibl(int argc, char **argv);
int cmd_render(int argc, char **argv);
/* bake --render: the image `out` (a PNG) of DIR's lightmaps on scene from
 * the default camera, named `shown` in warnings. DIR is the bake's staging
 * folder: the view is published with the lightmaps. */
int cli_render_bake(const char *dir, const char *out, const char *shown, const lx_scene *scene,
                    int threads, bool quiet);
int cmd_unwrap(int argc, char **argv);
int cmd_tangents(int argc, char **argv);
int cmd_horizonmap(int argc, char **argv);
int cmd_aomap(int argc, char **argv);
int cmd_probes(int argc, char **argv);

/* Options luxel horizonmap and aomap share (horizonmap.c). */
typedef struct cli_horizon_opts {
    const char *input, *output;
    lx_horizon_desc desc;
    int bits;
    bool quiet;
} cli_horizon_opts;
/* Parses argv of `command` ("horizonmap" or "aomap", which alone takes
 * --power and --cosine): 0 when fine, -1 for --help, else the usage
 * error's exit status (message printed). */
int cli_horizon_args(const char *command, int argc, char **argv, cli_horizon_opts *o);
/* Loads o->input (error printed on failure) into *hf. */
int cli_horizon_load(const cli_horizon_opts *o, lx_image *hf);
/* lx_horizon_map of hf with a progress bar; EXIT_OK or EXIT_FAILED (error
 * printed). */
int cli_horizon_run(const cli_horizon_opts *o, const lx_image *hf, lx_image *l0, lx_image *l1,
                    lx_image *ao);
int cmd_light2d(int argc, char **argv);

/* Writes scene as a .glb at path with u's generated UVs in TEXCOORD_1
 * (lx_scene_write_glb; unwrap.c). The scene is the one u was made from,
 * before or after lx_unwrap_apply. */
lx_status cli_write_scene_with_uvs(const lx_scene *scene, const lx_unwrap *u, const char *path);
/* "<scene's file name without its extension>.glb" into out; false (error
 * printed) when it does not fit. */
bool cli_scene_glb_name(const char *scene, char *out, size_t size);
struct cli_stage;
/* Stages the scene with u's UVs as `name` (bake's scene_with_uvs): 1 when
 * written, 0 when the scene cannot be written again (a warning says why:
 * compressed glTF, meshes not matched to the file), -1 on failure (error
 * printed). */
int cli_stage_scene_with_uvs(struct cli_stage *st, const char *name, const lx_scene *scene,
                             const lx_unwrap *u);

/* "luxel: error: <message>" on stderr. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Usage error: the message, a hint to --help, returns EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* ---- options every command shares (options.c) --------------------------
 * getopt_long's code for --threads in every command's table (beyond any
 * character), and the largest worker count a command accepts. */
#define CLI_OPT_THREADS 0x1000
#define CLI_MAX_THREADS 1024
/* --allow-any-path, for the commands that read a scene, a lights JSON or
 * a manifest: the files these name may lie outside their folders
 * (cli_allow_any_path). */
#define CLI_OPT_ANY_PATH 0x1001
#define CLI_ANY_PATH_OPTION                                                                        \
    {                                                                                              \
        "allow-any-path", no_argument, NULL, CLI_OPT_ANY_PATH                                      \
    }
/* The end of every command's option switch: --threads N into *threads,
 * -q into *quiet (and cli_set_quiet), -v (cli_set_verbose); getopt's ':'
 * (a missing value) and anything else (an unknown option, or --threads
 * or -q where threads or quiet is NULL) are usage errors. Returns 0 when
 * handled, else EXIT_USAGE with the error printed. Call it from the
 * switch's default case with getopt's optarg/optind state current. */
int cli_common_option(const char *command, int c, char **argv, int *threads, bool *quiet);

/* The one scene operand after getopt (argv[optind]) into *scene: 0, or
 * the usage error (none given, or more than one). */
int cli_one_scene(const char *command, int argc, char **argv, const char **scene);
/* Strict number parsing: the whole string, finite, within [lo, hi]. */
bool cli_parse_int(const char *s, long lo, long hi, long *out);
bool cli_parse_float(const char *s, double lo, double hi, double *out);
/* A memory size: 512M, 4G, 1.5G, 64KiB, 1000000 (bytes); K, M, G, T are
 * powers of 1024. At least one byte. */
bool cli_parse_size(const char *s, uint64_t *out);
/* The float image formats and PNG: "exr", "hdr", "pfm" or "png". */
bool cli_parse_format(const char *s, lx_image_format *out);
/* "R,G,B" with finite components >= 0. */
bool cli_parse_rgb(const char *s, lx_vec3 *out);

/* ---- numbers for humans (text.c) -----------------------------------------
 * v with at most `digits` significant digits (the integer part always
 * whole), fixed notation from 1e-4 to 1e15 with trailing zeros cut, %g
 * beyond; |v| below CLI_NUM_ZERO is float noise around zero and prints as
 * "0". The string lives in one of 16 rotating thread-local buffers: a
 * printf may hold up to 16 of them. cli_num: 6 digits. */
#define CLI_NUM_ZERO 1e-6
const char *cli_num_digits(double v, int digits);
const char *cli_num(double v);
/* one when n == 1, else many: "%u %s", n, cli_plural(n, "map", "maps"). */
const char *cli_plural(uint64_t n, const char *one, const char *many);

/* ---- quiet and strict (main.c) --------------------------------------------
 * Warnings print unless --quiet is given without --strict (with --strict a
 * warning matters, so it is always shown); errors always print. Each
 * command sets these from its own options before any work. */
void cli_set_quiet(bool quiet);
void cli_set_strict(bool strict);
bool cli_quiet(void);
bool cli_strict(void);
/* --allow-any-path was given (cli_common_option sets it). */
void cli_set_allow_any_path(bool any);
bool cli_allow_any_path(void);

/* The tone curve of 8-bit previews and outputs (bake's PNG previews, ibl's
 * PNG files) when --tonemap does not choose: Hable's filmic curve keeps a
 * metered mid grey near where a clamp puts it (code 78 against 91 for the
 * meter's 0.104) and rolls highlights off up to 5.6 instead of clipping
 * at 1; Hill's ACES fit darkens mid grey more (code 60). */
#define CLI_PREVIEW_TONEMAP LX_TONEMAP_FILMIC

/* Face size of a constant environment when none is asked for: it is the
 * same everywhere, so small is exact (the CLI's choice: lx_env_constant
 * takes a size). */
#define CLI_CONSTANT_ENV_SIZE 64

/* Loads the environment argument ENV of `command` (ibl, bake --sky): an
 * image (lx_env_load, at face size `size`, 0 = the input's) or a constant
 * colour const:R,G,B / const:L in nits (at CLI_CONSTANT_ENV_SIZE unless
 * size is given), times intensity (0 = lx_env_load_desc's default, as
 * lx_env_load reads it). Prints the error
 * and returns EXIT_FAILED (a bad file) or EXIT_USAGE (a bad const:); *out
 * is zeroed on failure. */
int cli_load_environment(const char *command, const char *env, float intensity, int size,
                         lx_cubemap *out);
/* The same with the library's threads bounded (0 = all cores) and a
 * progress bar labelled "environment" (none when quiet). */
int cli_load_environment_run(const char *command, const char *env, float intensity, int size,
                             int threads, bool quiet, lx_cubemap *out);
/* The face size cli_load_environment gives ENV at `size` when it is known
 * before loading (size itself, or a constant's default), else 0. */
int cli_environment_size(const char *env, int size);

/* Progress bar on stderr: drawn only when stderr is a terminal, not quiet,
 * and the work has run for more than a second. Returns false once the run
 * is interrupted, which cancels the library call it reports for. */
typedef struct cli_progress {
    const char *label; /* also the phase name of LUXEL_TEST_PAUSE */
    const char *phase; /* what --verbose calls the phase; NULL = the label */
    float base, span;  /* the bar shows base + span * fraction (0 and 1 from
                          init): one bar over several library calls */
    bool enabled;
    bool drawn;
    double start;
    double last_draw;
} cli_progress;
void cli_progress_init(cli_progress *p, const char *label, bool quiet);
/* The bar's next library call is call `part` of `parts` (one bar over
 * several calls). */
void cli_progress_part(cli_progress *p, int part, int parts);
bool cli_progress_update(void *user, float fraction);
/* Clears the bar (without ending a phase). */
void cli_progress_clear(cli_progress *p);
/* Clears the bar and ends the phase named by the label (cli_phase). */
void cli_progress_finish(cli_progress *p);

/* ---- interrupts (main.c) -------------------------------------------------
 * SIGINT, SIGTERM and SIGHUP are blocked in every thread from the first
 * line of main (threads made later inherit the mask), so no handler ever
 * runs: a signal waits, pending, until cli_interrupted() takes it, and the
 * command then winds down through its ordinary error path, removing what
 * it staged. main ends an interrupted run by re-raising the signal. */
void cli_block_signals(void);
/* True once a signal has come (takes a pending one). Any thread. */
bool cli_interrupted(void);
/* The signal that interrupted the run, 0 when none. */
int cli_interrupt_signal(void);
/* Prints the one error line of an interrupted run. */
void cli_report_interrupt(bool removed_outputs);
/* lx_scene_load, interruptible. assimp's import has no way to stop, and
 * some files keep it busy for minutes (its normal generation is quadratic
 * in vertices at one position), so a watcher thread (it allocates nothing:
 * no malloc arena of its own) takes signals while the scene loads; on one
 * it reports the interrupt, clears the active stage (cli_stage_clear_active)
 * and ends the process on the signal. False, with the error printed, when
 * the load fails. */
bool cli_scene_load(const char *path, const lx_scene_load_desc *desc, lx_scene **out);

/* Test hooks, read from the environment (never set outside tests):
 * LUXEL_TEST_PAUSE=PHASE stops the run the first time it reaches PHASE (a
 * progress label such as "bake", or "write": the first progress report
 * while an output is written, or the first output staged), says
 * "luxel: test: paused at PHASE" on stderr and waits up to a
 * minute for a signal, so a test can interrupt a run at a known point. */
void cli_test_pause(const char *phase);
/* LUXEL_TEST_FAIL_RENAME=N: true for the Nth rename cli_stage_publish
 * makes (1 = the first), which then fails as if the disk had. */
bool cli_test_fail_rename(void);
/* LUXEL_TEST_FAIL_LINK=1: true for every hard link cli_stage_publish asks
 * for, which is then refused as on a file system without links. */
bool cli_test_fail_link(void);
/* LUXEL_TEST_FAIL_RESTORE=N: true for the Nth rename that puts a replaced
 * file back after a failed publish (1 = the first), which then fails. */
bool cli_test_fail_restore(void);

/* Monotonic seconds. */
double cli_now(void);
/* Seconds since main started. */
double cli_elapsed(void);

/* --verbose: log lines of level INFO are shown (warnings always are), and
 * cli_phase prints "luxel: <name>  <seconds> s", the time since the
 * previous phase ended (or since main started). */
void cli_set_verbose(bool verbose);
bool cli_verbose(void);
void cli_phase(const char *name);
/* Under --verbose, one part of the phase that is running: "luxel:   <name>
 * <seconds> s" (the clock is not reset). */
void cli_phase_part(const char *name, double seconds);

/* Warnings printed so far (library and CLI, through lx_log): --strict
 * turns any into a failed run. */
unsigned cli_warning_count(void);

/* strdup and a/b joined, malloc'd; NULL when out of memory. */
char *cli_strdup(const char *s);
char *cli_path_join(const char *a, const char *b);

/* ---- staged output (stage.c) ---------------------------------------------
 * The commands that write several files (bake, ibl) stage them in
 * OUTPUT/.luxel-<random> and move them into OUTPUT together once all are
 * written. cli_stage_begin runs before the long work, so a folder that
 * cannot be written is reported before anything is computed; a failed or
 * interrupted run leaves OUTPUT as it was (and removes it, and any parent,
 * when the run created them). Publishing keeps a hard link (or the file
 * itself) of every output it replaces until all are in place, and puts the
 * old files back if a rename fails half-way. Every function prints its own
 * "luxel: error:" line and returns false on failure. Usage:
 *   cli_stage st;
 *   if (!cli_stage_begin(&st, dir)) return EXIT_FAILED;
 *   ... compute ...
 *   bool ok = cli_stage_image(&st, "a.exr", &img, NULL) && cli_stage_publish(&st);
 *   cli_stage_clear(&st);
 */
typedef struct cli_stage {
    char *output; /* the final folder */
    char *dir;    /* OUTPUT/.luxel-<random> (made by mkdtemp) */
    char **names; /* files staged in dir, in the order they were named */
    uint32_t count, capacity;
    char **made; /* folders this run created, deepest first */
    uint32_t made_count;
    bool published; /* the outputs are in place: nothing is undone */
    int dir_fd;     /* dir, open while dir_locked: its flock marks it in use */
    bool dir_locked;
    int output_fd; /* OUTPUT, open while output_locked (cli_stage_begin_set) */
    bool output_locked;
} cli_stage;

/* Creates dir and its parents. */
bool cli_make_dirs(const char *dir);
/* Creates the output folder (and parents) and the staging folder in it,
 * locked (flock) for as long as the run lives. Staging folders in OUTPUT
 * that no run holds (left by a run that was killed or crashed) are
 * reported in one warning. For outputs that stand alone (one file). */
bool cli_stage_begin(cli_stage *st, const char *output);
/* The same for files that belong together (bake's lightmaps and manifest,
 * ibl's cube maps): the output folder itself is locked too until
 * cli_stage_clear, and a second such run into it fails at once ("another
 * luxel run is writing OUTPUT"). clean (--clean) removes the leftover
 * staging folders instead of warning about them. */
bool cli_stage_begin_set(cli_stage *st, const char *output, bool clean);
/* Checks that OUTPUT/name can be replaced: nothing but a regular file (or
 * nothing) is in the way. For checking every name before the long work. */
bool cli_stage_check(const cli_stage *st, const char *name);
/* The staging path of output `name` (malloc'd) for writers other than
 * images and text; end with cli_stage_finish and the writer's status.
 * NULL (error printed) when out of memory or interrupted. */
char *cli_stage_path(cli_stage *st, const char *name);
bool cli_stage_finish(cli_stage *st, const char *name, lx_status status);
bool cli_stage_image(cli_stage *st, const char *name, const lx_image *img,
                     const lx_image_write_desc *desc);
bool cli_stage_text(cli_stage *st, const char *name, const char *text);
/* Moves every staged file into the output folder (see above). */
bool cli_stage_publish(cli_stage *st);
/* Removes whatever is still staged, the staging folder, and, unless the
 * outputs were published, the folders the run created. */
void cli_stage_clear(cli_stage *st);
/* cli_stage_clear of the stage begun last and not yet cleared, if any:
 * for a run ending on a signal while its thread is busy elsewhere. */
void cli_stage_clear_active(void);

/* ---- JSON and stale outputs (stale.c) -------------------------------------
 * cJSON reports only where it stopped: true when that place is a '}' or
 * ']' right after a ',' (white space between), with the comma's line and
 * the closer. */
bool cli_json_trailing_comma(const char *text, size_t size, size_t error_at, size_t *line,
                             char *closer);
/* Parses size bytes of JSON named `name`; NULL with "<name>: line L: ..."
 * in err (a trailing comma named as such) on failure. */
cJSON *cli_json_parse(const char *name, const char *text, size_t size, char *err,
                             size_t err_size);
/* A whole file (at most 64 MiB) into a malloc'd buffer; NULL with errno
 * set when it cannot be read (or is larger). */
char *cli_read_text(const char *path, size_t *size);

/* Files of an earlier bake in the output folder that this bake does not
 * write: the names its DIR/manifest.json lists (pages' files, previews,
 * AO and directional maps, scene_with_uvs, render) that are not among
 * `outputs` and are still regular
 * files. other_scene: the earlier bake's scene when it is another. */
typedef struct cli_stale {
    char **names;
    uint32_t count;
    char *other_scene;
} cli_stale;
/* Warns (and finds nothing) when the old manifest cannot be read; false
 * only when out of memory (error printed). */
bool cli_stale_find(const char *dir, const char *scene, const char *const *outputs,
                    uint32_t output_count, cli_stale *out);
/* One warning naming them, when there are any (with clean, an INFO line
 * saying they are being removed). */
void cli_stale_warn(const cli_stale *s, const char *dir, bool clean);
/* Removes them (regular files only); prints an error per failure. */
bool cli_stale_remove(const cli_stale *s, const char *dir);
void cli_stale_free(cli_stale *s);

#endif
