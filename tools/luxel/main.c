/* luxel: the command-line tool. Dispatches to one file per subcommand and
 * holds the pieces they share: error printing, strict number parsing, the
 * progress bar and interrupt handling. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static const char *main_usage =
    "usage: luxel <command> [options] inputs...\n"
    "\n"
    "luxel is a lighting toolkit: per-texel lightmaps with physically based\n"
    "lights and shadows, and image-based lighting from environment maps.\n"
    "\n"
    "commands:\n"
    "  bake SCENE    bake lightmaps for a glTF 2.0 (.gltf/.glb) or OBJ scene\n"
    "  info SCENE    list a scene's meshes, materials, lights and bounds\n"
    "  ies FILE      show an IES photometric file: header, lumens, beam; --plot\n"
    "  ibl ENV       image-based lighting from an environment map: irradiance,\n"
    "                SH, prefiltered specular mips, DFG table; faces/cross/KTX\n"
    "\n"
    "options:\n"
    "  -h, --help    show this help (luxel <command> --help for a command)\n"
    "  --version     print the version\n";

void cli_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("luxel: error: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

int cli_usage_error(const char *command, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("luxel: error: ", stderr);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, " (see 'luxel %s%s--help')\n", command ? command : "", command ? " " : "");
    return EXIT_USAGE;
}

bool cli_parse_int(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

bool cli_parse_float(const char *s, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

bool cli_parse_format(const char *s, lx_image_format *out)
{
    static const struct {
        const char *name;
        lx_image_format format;
    } formats[] = {
        {"exr", LX_IMAGE_EXR}, {"hdr", LX_IMAGE_HDR}, {"pfm", LX_IMAGE_PFM}, {"png", LX_IMAGE_PNG}};
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (strcmp(s, formats[i].name) == 0) {
            *out = formats[i].format;
            return true;
        }
    return false;
}

bool cli_parse_rgb(const char *s, lx_vec3 *out)
{
    double c[3];
    const char *p = s;
    for (int i = 0; i < 3; i++) {
        char *end;
        errno = 0;
        c[i] = strtod(p, &end);
        if (errno || end == p || !isfinite(c[i]) || c[i] < 0)
            return false;
        p = end;
        if (i < 2) {
            if (*p != ',')
                return false;
            p++;
        }
    }
    if (*p)
        return false;
    *out = lx_v3((float)c[0], (float)c[1], (float)c[2]);
    return true;
}

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* ---- interrupts ---------------------------------------------------------- */

static volatile sig_atomic_t interrupted;
static volatile sig_atomic_t writing;
/* This run's outputs: grown by copying, so the handler always sees a
 * complete array and a count of entries already in it. */
static char **volatile tracked;
static volatile sig_atomic_t tracked_count;
static size_t tracked_capacity;
static char *tracked_dir;
static char **tracked_made; /* folders this run created, deepest first */
static volatile sig_atomic_t tracked_made_count;

static pthread_t main_thread;

static void on_signal(int sig)
{
    /* Only the main thread writes files: a signal that lands on an OpenMP
     * or Embree worker goes to it, so the cleanup below never races a file
     * the main thread is creating. */
    if (!pthread_equal(pthread_self(), main_thread)) {
        pthread_kill(main_thread, sig);
        return;
    }
    interrupted = 1;
    if (writing) {
        lx_out_abort_all_signal_safe();
        for (sig_atomic_t i = 0; i < tracked_count; i++)
            unlink(tracked[i]);
        if (tracked_dir)
            rmdir(tracked_dir);
        for (sig_atomic_t i = 0; i < tracked_made_count; i++)
            rmdir(tracked_made[i]);
        static const char msg[] = "\nluxel: error: interrupted; outputs removed\n";
        ssize_t unused = write(2, msg, sizeof msg - 1);
        (void)unused;
        _exit(128 + sig);
    }
}

void cli_install_signal_handlers(void)
{
    main_thread = pthread_self();
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

bool cli_interrupted(void)
{
    return interrupted != 0;
}

bool cli_track_output(const char *path)
{
    char *copy = lx_strdup(path);
    if (!copy)
        return false;
    size_t count = (size_t)tracked_count;
    if (count == tracked_capacity) {
        size_t capacity = tracked_capacity ? 2 * tracked_capacity : 64;
        char **grown = count < INT_MAX / 2 ? malloc(sizeof(char *) * capacity) : NULL;
        if (!grown) {
            free(copy);
            return false;
        }
        if (count)
            memcpy(grown, tracked, sizeof(char *) * count);
        char **old = tracked;
        tracked = grown;
        tracked_capacity = capacity;
        free(old);
    }
    tracked[count] = copy;
    tracked_count = (sig_atomic_t)(count + 1);
    return true;
}

void cli_remove_tracked_outputs(void)
{
    sig_atomic_t count = tracked_count;
    for (sig_atomic_t i = 0; i < count; i++)
        unlink(tracked[i]);
    tracked_count = 0;
    for (sig_atomic_t i = 0; i < count; i++)
        free(tracked[i]);
}

void cli_forget_outputs(void)
{
    sig_atomic_t count = tracked_count;
    tracked_count = 0;
    for (sig_atomic_t i = 0; i < count; i++)
        free(tracked[i]);
}

void cli_track_dir(const char *dir, const char *const *created, uint32_t count)
{
    /* the handler sees no folders while the lists change */
    sig_atomic_t old_count = tracked_made_count;
    tracked_made_count = 0;
    for (sig_atomic_t i = 0; i < old_count; i++)
        free(tracked_made[i]);
    free(tracked_made);
    tracked_made = NULL;
    free(tracked_dir);
    tracked_dir = dir ? lx_strdup(dir) : NULL;
    char **made = count ? calloc(count, sizeof *made) : NULL;
    uint32_t n = 0;
    for (; made && n < count; n++)
        if (!(made[n] = lx_strdup(created[n])))
            break;
    tracked_made = made;
    tracked_made_count = (sig_atomic_t)n;
}

void cli_set_writing(bool w)
{
    writing = w;
}

/* ---- progress bar -------------------------------------------------------- */

void cli_progress_init(cli_progress *p, const char *label, bool quiet)
{
    p->label = label;
    p->enabled = !quiet && isatty(2);
    p->drawn = false;
    p->start = cli_now();
    p->last_draw = 0.0;
}

bool cli_progress_update(void *user, float fraction)
{
    cli_progress *p = user;
    if (interrupted)
        return false;
    if (!p->enabled)
        return true;
    double elapsed = cli_now() - p->start;
    /* appear after a second, redraw at most ten times a second */
    if (elapsed < 1.0 || (elapsed - p->last_draw < 0.1 && fraction < 1.0f))
        return true;
    p->last_draw = elapsed;
    const int width = 30;
    int filled = (int)(fraction * width + 0.5f);
    char bar[64];
    for (int i = 0; i < width; i++)
        bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    double eta = fraction > 0.01f ? elapsed * (1.0 - fraction) / fraction : 0.0;
    fprintf(stderr, "\r%s [%s] %3d%% ETA %4.0fs ", p->label, bar, (int)(fraction * 100.0f + 0.5f),
            eta);
    fflush(stderr);
    p->drawn = true;
    return true;
}

void cli_progress_finish(cli_progress *p)
{
    if (p->drawn)
        fprintf(stderr, "\r%*s\r", 70, "");
    p->drawn = false;
}

/* ---- logging and dispatch ----------------------------------------------- */

static void print_log(void *user, lx_log_level level, const char *message)
{
    if (level == LX_LOG_DEBUG)
        return;
    fprintf(stderr, "luxel: %s%s\n", level == LX_LOG_WARN ? "warning: " : "", message);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(main_usage, stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (strcmp(cmd, "-h") == 0 || strcmp(cmd, "--help") == 0) {
        fputs(main_usage, stdout);
        return EXIT_OK;
    }
    if (strcmp(cmd, "--version") == 0) {
        printf("luxel %s\n", lx_version());
        return EXIT_OK;
    }
    lx_set_log_callback(print_log, NULL);
    cli_install_signal_handlers();
    if (strcmp(cmd, "bake") == 0)
        return cmd_bake(argc - 1, argv + 1);
    if (strcmp(cmd, "info") == 0)
        return cmd_info(argc - 1, argv + 1);
    if (strcmp(cmd, "ies") == 0)
        return cmd_ies(argc - 1, argv + 1);
    if (strcmp(cmd, "ibl") == 0)
        return cmd_ibl(argc - 1, argv + 1);
    if (cmd[0] == '-')
        return cli_usage_error(NULL, "unknown option '%s'", cmd);
    return cli_usage_error(NULL, "unknown command '%s'", cmd);
}
