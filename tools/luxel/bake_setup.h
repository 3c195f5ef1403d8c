/* The scene and lighting options luxel bake and luxel probes share, and
 * the baked scene they both start from (bake_setup.c; private to
 * tools/luxel). */
#ifndef LUXEL_BAKE_SETUP_H
#define LUXEL_BAKE_SETUP_H

#include "cli.h"

#include <getopt.h>

typedef enum unwrap_choice { UNWRAP_AUTO, UNWRAP_ALWAYS, UNWRAP_NEVER } unwrap_choice;

/* The page an atlas fills when neither --resolution nor --texel-density
 * sizes it: the CLI's own choice (a lightmap per node keeps the library's
 * resolution). */
#define CLI_ATLAS_RESOLUTION 1024

/* The default texel density (cli_default_density): the texels a bake
 * spends on the scene's area, the density under which it warns, and the
 * most it gives. */
#define CLI_DENSITY_BUDGET (1024.0 * 1024.0)
#define CLI_DENSITY_MIN 4.0
#define CLI_DENSITY_MAX 40.0

/* The largest bitmap a node's own UVs are checked on (lx_uv_health): the
 * overlapped share hardly changes with the size, the time grows with it. */
#define CLI_HEALTH_SIZE 256

/* getopt_long codes of the shared options; a command's own start at
 * BAKE_OPT_OWN. */
enum {
    OPT_RESOLUTION = 256,
    OPT_TEXEL_DENSITY,
    OPT_MAX_RESOLUTION,
    OPT_LIGHTS,
    OPT_AMBIENT,
    OPT_PADDING,
    OPT_SKIP_DEGENERATE,
    OPT_SKY,
    OPT_SKY_INTENSITY,
    OPT_SKY_SHADOWS,
    OPT_NO_SKY_SHADOWS,
    OPT_SKY_SAMPLES,
    OPT_UNWRAP,
    OPT_UV_SET,
    OPT_ATLAS,
    OPT_NO_ATLAS,
    OPT_ATLAS_SIZE,
    OPT_STRICT,
    OPT_BOUNCES,
    OPT_GI_SAMPLES,
    OPT_EMISSIVE_SCALE,
    OPT_DENOISE,
    OPT_MEMORY_LIMIT,
    BAKE_OPT_OWN
};

/* The shared entries of a getopt_long table (--threads, -q, -v and -h are
 * each command's). */
#define BAKE_SETUP_OPTIONS                                                                         \
    {"resolution", required_argument, NULL, OPT_RESOLUTION},                                       \
        {"texel-density", required_argument, NULL, OPT_TEXEL_DENSITY},                             \
        {"max-resolution", required_argument, NULL, OPT_MAX_RESOLUTION},                           \
        {"lights", required_argument, NULL, OPT_LIGHTS},                                           \
        {"ambient", required_argument, NULL, OPT_AMBIENT},                                         \
        {"padding", required_argument, NULL, OPT_PADDING},                                         \
        {"skip-degenerate", no_argument, NULL, OPT_SKIP_DEGENERATE},                               \
        {"sky", required_argument, NULL, OPT_SKY},                                                 \
        {"sky-intensity", required_argument, NULL, OPT_SKY_INTENSITY},                             \
        {"sky-shadows", no_argument, NULL, OPT_SKY_SHADOWS},                                       \
        {"no-sky-shadows", no_argument, NULL, OPT_NO_SKY_SHADOWS},                                 \
        {"sky-samples", required_argument, NULL, OPT_SKY_SAMPLES},                                 \
        {"unwrap", required_argument, NULL, OPT_UNWRAP},                                           \
        {"uv-set", required_argument, NULL, OPT_UV_SET},                                           \
        {"atlas", no_argument, NULL, OPT_ATLAS}, {"no-atlas", no_argument, NULL, OPT_NO_ATLAS},    \
        {"atlas-size", required_argument, NULL, OPT_ATLAS_SIZE},                                   \
        {"strict", no_argument, NULL, OPT_STRICT},                                                 \
        {"bounces", required_argument, NULL, OPT_BOUNCES},                                         \
        {"gi-samples", required_argument, NULL, OPT_GI_SAMPLES},                                   \
        {"emissive-scale", required_argument, NULL, OPT_EMISSIVE_SCALE},                           \
        {"denoise", required_argument, NULL, OPT_DENOISE},                                         \
    {                                                                                              \
        "memory-limit", required_argument, NULL, OPT_MEMORY_LIMIT                                  \
    }

/* The options of a bake (bake's own fields are read by bake.c only). */
typedef struct bake_args {
    const char *command; /* "bake" or "probes", for messages */
    const char *scene;
    const char *output;
    const char *lights;
    lx_image_format format;
    bool half;
    bool pre_expose;
    bool has_ambient;
    lx_vec3 ambient;
    bool has_exposure;
    double exposure_ev100;
    bool quiet;
    bool strict;          /* warnings fail the run */
    const char *sky;      /* --sky, else the lights JSON's */
    double sky_intensity; /* < 0: not given */
    int sky_shadows;      /* 1 on, 0 off, -1 not given */
    long sky_samples;     /* 0: not given */
    bool has_resolution;
    bool density_from_scene; /* neither --resolution nor --texel-density: the
                                density came from the scene (cli_default_density) */
    unwrap_choice unwrap;
    int atlas;      /* 1 --atlas, 0 --no-atlas, -1 not given */
    int atlas_size; /* 0: the unwrapper's default */
    bool render;    /* --render: DIR/view.png after the bake */
    lx_tonemap tonemap;
    bool clean;
    bool ao;                /* --ao: DIR/<name>_ao.png per lightmap */
    lx_ao_desc ao_desc;
    const char *ao_option;  /* the last --ao-* given, for the error without --ao */
    lx_bake_desc desc;
} bake_args;

/* Zeros a and sets the shared defaults (the CLI's bounces, padding and
 * denoising; nothing given). */
void cli_bake_args_init(bake_args *a, const char *command);
/* One shared option (getopt's c and optarg): 0 when taken,
 * CLI_BAKE_NOT_MINE when c is not a shared option, else the usage error's
 * exit status (message printed). */
#define CLI_BAKE_NOT_MINE (-100)
int cli_bake_option(bake_args *a, int c, const char *arg);
/* The checks between shared options once all are read: 0 or a usage
 * error's status. */
int cli_bake_check_args(const bake_args *a);

/* From the scene to a baker ready to bake: loads a->scene, applies
 * --lights and --ambient, loads the sky, checks that something emits
 * light, plans the lightmap UVs (luxel's where the file's do not serve),
 * warns about suspect units and creates the baker (progress bar "texel
 * maps", on *progress, which the baker reports to in its later calls
 * too: it must outlive the baker). *sky gets the sky used (its environment borrowed from a or the
 * scene). EXIT_OK, or the status of the failure (error printed); the
 * caller destroys what was made either way. */
int cli_bake_prepare(bake_args *a, cli_progress *progress, lx_scene **scene, lx_scene_sky *sky,
                     lx_unwrap **unwrap, bool *atlas, lx_baker **baker);
/* --strict: true (error printed) when any warning so far fails the run. */
bool cli_bake_strict_failed(const bake_args *a);

/* The texel density (texels a metre) a bake gets when neither
 * --resolution nor --texel-density is given (bake_setup.c). */
double cli_default_density(const lx_scene *scene);

#endif
