/* luxel: the command-line tool. Dispatches to one file per subcommand and
 * holds the pieces they share: error printing, strict number parsing, the
 * progress bar, interrupts (blocked signals polled as a flag) and the test
 * hooks. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"
#include "maps_cli.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
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
    "  probes SCENE  L2 spherical-harmonic light probes (direct + indirect) on a\n"
    "                grid over the scene or at given points (JSON)\n"
    "  info SCENE    list a scene's meshes, materials, lights and bounds\n"
    "  ies FILE      show an IES photometric file: header, lumens, beam; --plot\n"
    "  ibl ENV       image-based lighting from an environment map: irradiance,\n"
    "                SH, prefiltered specular mips, DFG table; faces/cross/KTX\n"
    "  render SCENE  a camera view of a scene with its baked lightmaps (PNG)\n"
    "  unwrap SCENE  make lightmap UVs and write the scene with them (.glb)\n"
    "  normalmap HEIGHT\n"
    "                tangent-space normal map of a height image;\n"
    "                --blend BASE DETAIL blends two normal maps\n"
    "  heightmap NORMALS\n"
    "                heights integrated from a normal map (its inverse)\n"
    "  parallaxmap HEIGHT\n"
    "                the parallax map n.z h of a height image\n"
    "  horizonmap HEIGHT\n"
    "                horizon maps of a height image (bumps that shadow\n"
    "                themselves) and their weight cube\n"
    "  aomap HEIGHT  ambient-occlusion map of a height image\n"
    "  shade --height H | --normal N\n"
    "                material preview: a quad or sphere lit, with parallax\n"
    "                and horizon shadows\n"
    "  tangents SCENE\n"
    "                write the scene with MikkTSpace (or Lengyel) tangents (.glb)\n"
    "  light2d       shadowed 2D lights over a caster image (--casters, --lights)\n"
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

int cli_one_scene(const char *command, int argc, char **argv, const char **scene)
{
    if (optind >= argc)
        return cli_usage_error(command, "no scene given");
    if (optind + 1 < argc)
        return cli_usage_error(command, "one scene at a time ('%s' is extra)", argv[optind + 1]);
    *scene = argv[optind];
    return 0;
}

bool cli_parse_size(const char *s, uint64_t *out)
{
    /* digits (a decimal point allowed), then K, M, G or T (powers of 1024,
     * an optional trailing B or iB), or bytes */
    char *end;
    errno = 0;
    if (!s || !((s[0] >= '0' && s[0] <= '9') || s[0] == '.'))
        return false;
    double v = strtod(s, &end);
    if (errno || end == s || !isfinite(v) || v < 0.0)
        return false;
    double scale = 1.0;
    switch (*end) {
    case 'k': case 'K': scale = 1024.0; end++; break;
    case 'm': case 'M': scale = 1024.0 * 1024.0; end++; break;
    case 'g': case 'G': scale = 1024.0 * 1024.0 * 1024.0; end++; break;
    case 't': case 'T': scale = 1024.0 * 1024.0 * 1024.0 * 1024.0; end++; break;
    default: break;
    }
    if (scale > 1.0 && *end == 'i')
        end++;
    if (*end == 'B' || *end == 'b')
        end++;
    if (*end)
        return false;
    double bytes = v * scale;
    if (!(bytes >= 1.0) || bytes >= 18446744073709549568.0)
        return false;
    *out = (uint64_t)bytes;
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

static double main_start, phase_end;
static bool verbose;

double cli_elapsed(void)
{
    return cli_now() - main_start;
}

void cli_set_verbose(bool v)
{
    verbose = v;
}

bool cli_verbose(void)
{
    return verbose;
}

void cli_phase(const char *name)
{
    double now = cli_now();
    if (verbose)
        fprintf(stderr, "luxel: %-24s %8.3f s\n", name, now - phase_end);
    phase_end = now;
}

void cli_phase_part(const char *name, double seconds)
{
    if (verbose)
        fprintf(stderr, "luxel:   %-22s %8.3f s\n", name, seconds);
}

char *cli_strdup(const char *s)
{
    return strdup(s);
}

char *cli_path_join(const char *a, const char *b)
{
    if (b[0] == '/' || !a[0])
        return strdup(b);
    size_t na = strlen(a), nb = strlen(b);
    bool slash = a[na - 1] != '/';
    char *r = malloc(na + nb + 2);
    if (!r)
        return NULL;
    memcpy(r, a, na);
    if (slash)
        r[na++] = '/';
    memcpy(r + na, b, nb + 1);
    return r;
}

/* ---- interrupts ---------------------------------------------------------- */

static _Atomic int interrupt_signal;

static void interrupt_set(sigset_t *set)
{
    sigemptyset(set);
    sigaddset(set, SIGINT);
    sigaddset(set, SIGTERM);
    sigaddset(set, SIGHUP);
}

void cli_block_signals(void)
{
    sigset_t set;
    interrupt_set(&set);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
}

/* Takes a pending signal, waiting up to `seconds`; 0 when none came. */
static int take_signal(double seconds)
{
    sigset_t set;
    interrupt_set(&set);
    struct timespec wait = {(time_t)seconds, (long)((seconds - (double)(time_t)seconds) * 1e9)};
    int sig;
    do
        sig = sigtimedwait(&set, NULL, &wait);
    while (sig < 0 && errno == EINTR);
    return sig > 0 ? sig : 0;
}

bool cli_interrupted(void)
{
    if (atomic_load(&interrupt_signal))
        return true;
    sigset_t pending;
    if (sigpending(&pending) != 0 ||
        !(sigismember(&pending, SIGINT) || sigismember(&pending, SIGTERM) ||
          sigismember(&pending, SIGHUP)))
        return false;
    int sig = take_signal(0.0);
    if (sig) {
        int none = 0;
        atomic_compare_exchange_strong(&interrupt_signal, &none, sig);
    }
    return atomic_load(&interrupt_signal) != 0;
}

int cli_interrupt_signal(void)
{
    return atomic_load(&interrupt_signal);
}

void cli_report_interrupt(bool removed_outputs)
{
    cli_error("interrupted; %s", removed_outputs ? "outputs removed" : "nothing written");
}

/* Ends an interrupted run the way the signal would have: default action,
 * unblocked, raised. Returns only if the signal does not end the process. */
static int end_interrupted(int sig)
{
    fflush(stdout);
    signal(sig, SIG_DFL);
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, sig);
    raise(sig);
    pthread_sigmask(SIG_UNBLOCK, &set, NULL);
    return 128 + sig;
}

/* cli_scene_load's watcher: takes the interrupting signals while the scene
 * loads, and on one ends the run as the signal would. */
static _Atomic bool scene_loading;

static void *watch_scene_load(void *arg)
{
    (void)arg;
    while (atomic_load(&scene_loading)) {
        int sig = take_signal(0.02);
        if (!sig)
            continue;
        atomic_store(&interrupt_signal, sig);
        cli_stage_clear_active();
        cli_report_interrupt(false);
        end_interrupted(sig);
        _exit(128 + sig); /* a signal whose default action is not to end */
    }
    return NULL;
}

bool cli_scene_load(const char *path, const lx_scene_load_desc *desc, lx_scene **out)
{
    *out = NULL;
    pthread_attr_t attr;
    pthread_t watcher;
    bool watching = false;
    atomic_store(&scene_loading, true);
    if (pthread_attr_init(&attr) == 0) {
        pthread_attr_setstacksize(&attr, 256 * 1024);
        watching = pthread_create(&watcher, &attr, watch_scene_load, NULL) == 0;
        pthread_attr_destroy(&attr);
    }
    /* without a watcher the load is not interruptible, as before */
    lx_status st = lx_scene_load(path, desc, out);
    atomic_store(&scene_loading, false);
    if (watching)
        pthread_join(watcher, NULL);
    if (st != LX_OK)
        cli_error("%s", lx_last_error());
    return st == LX_OK;
}

void cli_test_pause(const char *phase)
{
    static _Atomic bool paused;
    const char *want = getenv("LUXEL_TEST_PAUSE");
    if (!want || strcmp(want, phase) != 0 || atomic_exchange(&paused, true))
        return;
    fprintf(stderr, "luxel: test: paused at %s\n", phase);
    fflush(stderr);
    int sig = take_signal(60.0);
    if (sig) {
        int none = 0;
        atomic_compare_exchange_strong(&interrupt_signal, &none, sig);
    }
}

bool cli_test_fail_rename(void)
{
    static _Atomic long renames;
    const char *nth = getenv("LUXEL_TEST_FAIL_RENAME");
    return nth && atol(nth) == ++renames;
}

bool cli_test_fail_link(void)
{
    const char *on = getenv("LUXEL_TEST_FAIL_LINK");
    return on && strcmp(on, "1") == 0;
}

bool cli_test_fail_restore(void)
{
    static _Atomic long restores;
    const char *nth = getenv("LUXEL_TEST_FAIL_RESTORE");
    return nth && atol(nth) == ++restores;
}

/* ---- progress bar -------------------------------------------------------- */

void cli_progress_init(cli_progress *p, const char *label, bool quiet)
{
    p->label = label;
    p->phase = NULL;
    p->base = 0.0f;
    p->span = 1.0f;
    p->enabled = !quiet && isatty(2);
    p->drawn = false;
    p->start = cli_now();
    p->last_draw = 0.0;
}

void cli_progress_part(cli_progress *p, int part, int parts)
{
    p->base = parts > 0 ? (float)part / (float)parts : 0.0f;
    p->span = parts > 0 ? 1.0f / (float)parts : 1.0f;
}

bool cli_progress_update(void *user, float fraction)
{
    cli_progress *p = user;
    cli_test_pause(p->label);
    if (cli_interrupted())
        return false;
    if (!p->enabled)
        return true;
    fraction = p->base + p->span * fraction;
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

void cli_progress_clear(cli_progress *p)
{
    if (p->drawn)
        fprintf(stderr, "\r%*s\r", 70, "");
    p->drawn = false;
}

void cli_progress_finish(cli_progress *p)
{
    cli_progress_clear(p);
    cli_phase(p->phase ? p->phase : p->label);
}

/* ---- logging and dispatch ----------------------------------------------- */

static bool quiet, strict;
static unsigned warnings; /* the log callback is never called concurrently */

unsigned cli_warning_count(void)
{
    return warnings;
}

void cli_set_quiet(bool q)
{
    quiet = q;
}

void cli_set_strict(bool s)
{
    strict = s;
}

bool cli_quiet(void)
{
    return quiet;
}

bool cli_strict(void)
{
    return strict;
}

static bool any_path;

void cli_set_allow_any_path(bool any)
{
    any_path = any;
}

bool cli_allow_any_path(void)
{
    return any_path;
}

static void print_log(void *user, lx_log_level level, const char *message)
{
    (void)user;
    warnings += level >= LX_LOG_WARN;
    if (level < (verbose ? LX_LOG_INFO : LX_LOG_WARN))
        return;
    /* --quiet silences warnings too, unless --strict makes them matter */
    if (level == LX_LOG_WARN && quiet && !strict)
        return;
    fprintf(stderr, "luxel: %s%s\n", level == LX_LOG_WARN ? "warning: " : "", message);
}

int main(int argc, char **argv)
{
    /* before any thread exists, so every thread inherits the mask */
    cli_block_signals();
    main_start = phase_end = cli_now();
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
    static const struct {
        const char *name;
        int (*run)(int argc, char **argv);
    } commands[] = {{"bake", cmd_bake},     {"info", cmd_info},     {"ies", cmd_ies},
                    {"ibl", cmd_ibl},       {"render", cmd_render}, {"unwrap", cmd_unwrap},
                    {"normalmap", cmd_normalmap}, {"heightmap", cmd_heightmap},
                    {"parallaxmap", cmd_parallaxmap},
                    {"horizonmap", cmd_horizonmap}, {"aomap", cmd_aomap},
                    {"tangents", cmd_tangents}, {"shade", cmd_shade},
                    {"light2d", cmd_light2d}, {"probes", cmd_probes}};
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(cmd, commands[i].name) == 0) {
            lx_set_log_callback(print_log, NULL);
            int status = commands[i].run(argc - 1, argv + 1);
            /* a run that finished anyway (the signal came while its outputs
             * were moved into place) keeps its status */
            if (status != EXIT_OK && cli_interrupt_signal())
                return end_interrupted(cli_interrupt_signal());
            return status;
        }
    if (cmd[0] == '-')
        return cli_usage_error(NULL, "unknown option '%s'", cmd);
    return cli_usage_error(NULL, "unknown command '%s'", cmd);
}
