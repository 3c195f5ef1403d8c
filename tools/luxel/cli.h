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

/* "luxel: error: <message>" on stderr. */
void cli_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Usage error: the message, a hint to --help, returns EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* Strict number parsing: the whole string, finite, within [lo, hi]. */
bool cli_parse_int(const char *s, long lo, long hi, long *out);
bool cli_parse_float(const char *s, double lo, double hi, double *out);
/* "R,G,B" with finite components >= 0. */
bool cli_parse_rgb(const char *s, lx_vec3 *out);

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
/* Registers a completed output so an interrupt can remove it. */
void cli_track_output(const char *path);
void cli_remove_tracked_outputs(void);
/* Stops tracking outputs without removing them (they were published). */
void cli_forget_outputs(void);
/* A folder an interrupt removes after the tracked files (NULL: none). */
void cli_track_dir(const char *dir);
void cli_set_writing(bool writing);

/* Monotonic seconds. */
double cli_now(void);

#endif
