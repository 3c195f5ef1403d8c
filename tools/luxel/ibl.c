/* luxel ibl: image-based lighting from an environment map: the diffuse
 * irradiance cube (brute force or from spherical harmonics), the nine SH
 * coefficients as JSON, the prefiltered specular mip chain (GGX or Phong)
 * and the split-sum DFG table, in the layouts engines read (six faces, a
 * cross, an equirect or one KTX 1.1 file). Everything is computed before
 * the first file is written; files are staged and moved into place
 * together (stage.c). */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *ibl_usage =
    "usage: luxel ibl ENV [options]\n"
    "\n"
    "Image-based lighting from the environment ENV (radiance in nits): an\n"
    "equirect (2:1), a horizontal (4:3) or vertical (3:4) cross, six faces\n"
    "NAME_px.EXT ... NAME_nz.EXT (give the _px file), in .hdr, .exr, .pfm or\n"
    ".png/.jpg (sRGB decoded), or a constant colour const:R,G,B (const:L for\n"
    "grey). Writes to DIR:\n"
    "  irradiance.*     diffuse irradiance cube in lux (--irradiance)\n"
    "  sh.json          order-2 spherical harmonics of the radiance (--sh)\n"
    "  specular_mL.*    prefiltered specular mip L = 0, 1, ... (--specular),\n"
    "                   or specular.ktx holding them all\n"
    "  dfg_lut.*        split-sum GGX table, %dx%d: R scale, G bias (--lut)\n"
    "  environment.*    the environment itself in the output layout (--environment)\n"
    "With none of --irradiance, --sh, --specular, --lut, --environment, the\n"
    "first four are written. Cube faces are in the OpenGL/KTX order and\n"
    "orientation, +Y up (docs/ibl.md).\n"
    "\n"
    "options:\n"
    "  -o, --output DIR         output folder (default ./ibl)\n"
    "  --irradiance[=METHOD]    irradiance cube, %dx%d faces (at most the\n"
    "                           environment's): brute (default; every source\n"
    "                           texel a light) or sh (from the 9 SH terms)\n"
    "  --sh                     write sh.json\n"
    "  --specular FILTER        ggx or phong (default %s)\n"
    "  --mips N                 specular levels (default: down to 1x1)\n"
    "  --phong-exponents A,B,.. Phong exponent per level (default %g/4^level, at\n"
    "                           least 1)\n"
    "  --samples N              GGX importance samples per texel (1..%d) of the\n"
    "                           specular levels and the DFG table (default %d and %d)\n"
    "  --lut                    write the DFG table\n"
    "  --environment            write the environment in the output layout\n"
    "  --size N                 face size the environment is resampled to (default:\n"
    "                           the input's; a constant: %d)\n"
    "  --specular-size N        face size of specular level 0 (default: the\n"
    "                           environment's, at most %d)\n"
    "  --layout L               faces (NAME_px.EXT ... NAME_nz.EXT), cross, vcross\n"
    "                           (vertical cross), equirect (4N x 2N) or ktx (one\n"
    "                           KTX 1.1 file per cube, mips included); default %s\n"
    "  --format F               exr, hdr, pfm or png; default %s\n"
    "  --exposure EV100         exposure of 8-bit (png) outputs: values times\n"
    "                           1/(1.2 x 2^EV100); default: values as they are\n"
    "  --tonemap C              tone curve of 8-bit outputs: filmic (default), aces\n"
    "                           or clamp; the DFG table is data, never tone mapped\n"
    "  --half                   16-bit floats: EXR half, KTX RGBA16F (else RGBA32F)\n"
    "  --no-seam-fix            keep cube edges as filtered (for engines that sample\n"
    "                           cube maps seamlessly); by default edge texels are\n"
    "                           averaged across faces (the seed's seam fix)\n"
    "  --intensity X            multiply the environment by X (default %g)\n"
    "  --clean                  remove the staging folders (.luxel-*) that\n"
    "                           runs killed or crashed left in DIR\n"
    "  --threads N              worker threads (default: all cores)\n"
    "  -v, --verbose            the time of each phase, and notes\n"
    "  -q, --quiet              no progress bar, no list of files\n"
    "  -h, --help               show this help\n";

enum {
    OPT_IRRADIANCE = 256,
    OPT_SH,
    OPT_SPECULAR,
    OPT_MIPS,
    OPT_PHONG,
    OPT_SAMPLES,
    OPT_LUT,
    OPT_ENVIRONMENT,
    OPT_SIZE,
    OPT_SPECULAR_SIZE,
    OPT_LAYOUT,
    OPT_FORMAT,
    OPT_HALF,
    OPT_NO_SEAM_FIX,
    OPT_INTENSITY,
    OPT_EXPOSURE,
    OPT_TONEMAP,
    OPT_CLEAN
};

/* The output layouts by their option names. */
static const struct {
    const char *name;
    lx_env_layout layout;
} layouts[] = {{"faces", LX_ENV_FACES},
               {"cross", LX_ENV_CROSS},
               {"vcross", LX_ENV_CROSS_VERTICAL},
               {"equirect", LX_ENV_EQUIRECT},
               {"ktx", LX_ENV_KTX}};

static const char *layout_name(lx_env_layout layout)
{
    for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++)
        if (layouts[i].layout == layout)
            return layouts[i].name;
    return "?";
}

/* The help, its defaults the library's. */
static void print_usage(void)
{
    lx_env_write_desc w = lx_env_write_desc_defaults(NULL);
    lx_prefilter_desc p = lx_prefilter_desc_defaults(NULL);
    printf(ibl_usage, LX_DFG_DEFAULT_SIZE, LX_DFG_DEFAULT_SIZE, LX_IRRADIANCE_DEFAULT_SIZE,
           LX_IRRADIANCE_DEFAULT_SIZE, p.filter == LX_SPECULAR_PHONG ? "phong" : "ggx",
           (double)lx_phong_level_exponent(0), LX_PREFILTER_MAX_SAMPLES, p.samples,
           LX_DFG_DEFAULT_SAMPLES, CLI_CONSTANT_ENV_SIZE, LX_PREFILTER_DEFAULT_SIZE,
           layout_name(w.layout), lx_image_format_extension(w.format),
           (double)lx_env_load_desc_defaults(NULL).intensity);
}

typedef struct ibl_args {
    const char *env;
    const char *output;
    bool irradiance, irradiance_sh, sh, specular, lut, environment;
    lx_specular_filter filter;
    bool filter_given;
    int mips;
    float phong[LX_MAX_CUBE_MIPS];
    int phong_count;
    int samples;
    int size;
    int specular_size;
    lx_env_layout layout;
    lx_image_format format;
    bool half;
    bool seam_fix;
    float intensity;
    int threads;
    bool quiet;
    bool has_exposure;
    double exposure_ev100;
    lx_tonemap tonemap;
    bool clean; /* --clean: remove staging folders killed runs left */
} ibl_args;

static bool parse_exponents(const char *s, ibl_args *a)
{
    a->phong_count = 0;
    const char *p = s;
    for (;;) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (errno || end == p || !isfinite(v) || v <= 0.0 || v > 1e6 ||
            a->phong_count == LX_MAX_CUBE_MIPS)
            return false;
        a->phong[a->phong_count++] = (float)v;
        p = end;
        if (*p == '\0')
            return true;
        if (*p != ',')
            return false;
        p++;
    }
}

static int parse_args(int argc, char **argv, ibl_args *a)
{
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'},
        {"irradiance", optional_argument, NULL, OPT_IRRADIANCE},
        {"sh", no_argument, NULL, OPT_SH},
        {"specular", required_argument, NULL, OPT_SPECULAR},
        {"mips", required_argument, NULL, OPT_MIPS},
        {"phong-exponents", required_argument, NULL, OPT_PHONG},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"lut", no_argument, NULL, OPT_LUT},
        {"environment", no_argument, NULL, OPT_ENVIRONMENT},
        {"size", required_argument, NULL, OPT_SIZE},
        {"specular-size", required_argument, NULL, OPT_SPECULAR_SIZE},
        {"layout", required_argument, NULL, OPT_LAYOUT},
        {"format", required_argument, NULL, OPT_FORMAT},
        {"half", no_argument, NULL, OPT_HALF},
        {"no-seam-fix", no_argument, NULL, OPT_NO_SEAM_FIX},
        {"intensity", required_argument, NULL, OPT_INTENSITY},
        {"threads", required_argument, NULL, CLI_OPT_THREADS},
        {"exposure", required_argument, NULL, OPT_EXPOSURE},
        {"tonemap", required_argument, NULL, OPT_TONEMAP},
        {"clean", no_argument, NULL, OPT_CLEAN},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->output = "ibl";
    /* the library's defaults, filled in so that names and checks see them */
    lx_env_write_desc w = lx_env_write_desc_defaults(NULL);
    a->format = w.format;
    a->layout = w.layout;
    a->filter = lx_prefilter_desc_defaults(NULL).filter;
    a->seam_fix = true;
    a->tonemap = CLI_PREVIEW_TONEMAP;
    bool tonemap_given = false;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg)
                return cli_usage_error("ibl", "-o needs a folder name");
            a->output = optarg;
            break;
        case OPT_IRRADIANCE:
            a->irradiance = true;
            if (!optarg || strcmp(optarg, "brute") == 0)
                a->irradiance_sh = false;
            else if (strcmp(optarg, "sh") == 0)
                a->irradiance_sh = true;
            else
                return cli_usage_error("ibl", "--irradiance takes brute or sh, not '%s'", optarg);
            break;
        case OPT_SH:
            a->sh = true;
            break;
        case OPT_SPECULAR:
            a->specular = true;
            a->filter_given = true;
            if (strcmp(optarg, "ggx") == 0)
                a->filter = LX_SPECULAR_GGX;
            else if (strcmp(optarg, "phong") == 0)
                a->filter = LX_SPECULAR_PHONG;
            else
                return cli_usage_error("ibl", "--specular must be ggx or phong, not '%s'", optarg);
            break;
        case OPT_MIPS:
            if (!cli_parse_int(optarg, 1, LX_MAX_CUBE_MIPS, &n))
                return cli_usage_error("ibl", "--mips must be an integer in 1..%d, not '%s'",
                                       LX_MAX_CUBE_MIPS, optarg);
            a->mips = (int)n;
            break;
        case OPT_PHONG:
            if (!parse_exponents(optarg, a))
                return cli_usage_error("ibl",
                                       "--phong-exponents must be 1..%d comma-separated numbers "
                                       "in (0, 1e6], not '%s'",
                                       LX_MAX_CUBE_MIPS, optarg);
            break;
        case OPT_SAMPLES:
            if (!cli_parse_int(optarg, 1, LX_PREFILTER_MAX_SAMPLES, &n))
                return cli_usage_error("ibl", "--samples must be an integer in 1..%d, not '%s'",
                                       LX_PREFILTER_MAX_SAMPLES, optarg);
            a->samples = (int)n;
            break;
        case OPT_LUT:
            a->lut = true;
            break;
        case OPT_ENVIRONMENT:
            a->environment = true;
            break;
        case OPT_SIZE:
            if (!cli_parse_int(optarg, 1, LX_MAX_CUBE_SIZE, &n))
                return cli_usage_error("ibl", "--size must be an integer in 1..%d, not '%s'",
                                       LX_MAX_CUBE_SIZE, optarg);
            a->size = (int)n;
            break;
        case OPT_SPECULAR_SIZE:
            if (!cli_parse_int(optarg, 1, LX_MAX_CUBE_SIZE, &n))
                return cli_usage_error("ibl",
                                       "--specular-size must be an integer in 1..%d, not '%s'",
                                       LX_MAX_CUBE_SIZE, optarg);
            a->specular_size = (int)n;
            break;
        case OPT_LAYOUT: {
            size_t i = 0, count = sizeof layouts / sizeof layouts[0];
            while (i < count && strcmp(optarg, layouts[i].name) != 0)
                i++;
            if (i == count)
                return cli_usage_error(
                    "ibl", "--layout must be faces, cross, vcross, equirect or ktx, not '%s'",
                    optarg);
            a->layout = layouts[i].layout;
            break;
        }
        case OPT_FORMAT:
            if (!cli_parse_format(optarg, &a->format))
                return cli_usage_error("ibl", "--format must be exr, hdr, pfm or png, not '%s'",
                                       optarg);
            break;
        case OPT_HALF:
            a->half = true;
            break;
        case OPT_NO_SEAM_FIX:
            a->seam_fix = false;
            break;
        case OPT_INTENSITY:
            if (!cli_parse_float(optarg, 0.0, 1e30, &f) || f <= 0.0)
                return cli_usage_error("ibl", "--intensity must be a finite number > 0, not '%s'",
                                       optarg);
            a->intensity = (float)f;
            break;
        case OPT_EXPOSURE:
            if (!cli_parse_float(optarg, -64, 64, &f))
                return cli_usage_error("ibl", "--exposure must be an EV100 in -64..64, not '%s'",
                                       optarg);
            a->exposure_ev100 = f;
            a->has_exposure = true;
            break;
        case OPT_TONEMAP:
            if (!lx_tonemap_parse(optarg, &a->tonemap))
                return cli_usage_error("ibl", "--tonemap must be filmic, aces or clamp, not '%s'",
                                       optarg);
            tonemap_given = true;
            break;
        case OPT_CLEAN:
            a->clean = true;
            break;
        case 'h':
            print_usage();
            return -1;
        default: {
            int rc = cli_common_option("ibl", c, argv, &a->threads, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    if (optind >= argc)
        return cli_usage_error("ibl", "no environment given");
    if (optind + 1 < argc)
        return cli_usage_error("ibl", "one environment at a time ('%s' is extra)",
                               argv[optind + 1]);
    a->env = argv[optind];
    if (!a->irradiance && !a->sh && !a->specular && !a->lut && !a->environment)
        a->irradiance = a->sh = a->specular = a->lut = true;
    if (!a->specular && (a->mips || a->phong_count || a->specular_size))
        return cli_usage_error("ibl", "--mips, --phong-exponents and --specular-size apply to "
                                      "the specular chain: add --specular");
    if (!a->specular && !a->lut && a->samples)
        return cli_usage_error("ibl", "--samples applies to --specular and --lut");
    if (a->phong_count && a->filter != LX_SPECULAR_PHONG)
        return cli_usage_error("ibl", "--phong-exponents needs --specular phong");
    if (a->phong_count && a->mips && a->mips != a->phong_count)
        return cli_usage_error("ibl", "--mips %d but %d Phong exponents", a->mips, a->phong_count);
    if (a->phong_count)
        a->mips = a->phong_count;
    if (a->half && a->format != LX_IMAGE_EXR && a->layout != LX_ENV_KTX)
        return cli_usage_error("ibl", "--half applies to --format exr and --layout ktx only");
    bool eight = a->format == LX_IMAGE_PNG && a->layout != LX_ENV_KTX;
    if (!eight && (a->has_exposure || tonemap_given))
        return cli_usage_error("ibl", "--exposure and --tonemap apply to 8-bit outputs "
                                      "(--format png)");
    return 0;
}

/* ---- writing ------------------------------------------------------------- */

typedef struct writer {
    cli_stage stage;
    const ibl_args *a;
    char **written; /* names, for the list on stdout */
    int written_count;
    bool reported; /* a callback printed why it stopped the library */
} writer;

static bool note(writer *w, const char *name)
{
    char **n = realloc(w->written, sizeof(char *) * (size_t)(w->written_count + 1));
    if (!n) {
        cli_error("out of memory");
        return false;
    }
    w->written = n;
    w->written[w->written_count] = cli_strdup(name);
    if (!w->written[w->written_count]) {
        cli_error("out of memory");
        return false;
    }
    w->written_count++;
    return true;
}

/* lx_env_write's on_file: each file is staged (tracked, so a failed or
 * interrupted run removes it) before the library creates it. */
static bool stage_file(void *user, const char *name)
{
    writer *w = user;
    char *path = cli_stage_path(&w->stage, name);
    bool ok = path && note(w, name);
    free(path);
    w->reported = w->reported || !ok;
    return ok;
}

/* The write desc of the run's layout and format. */
static lx_env_write_desc write_desc(const ibl_args *a, bool mip_names)
{
    lx_env_write_desc d = {.layout = a->layout,
                           .format = a->format,
                           .exposure = a->has_exposure
                                           ? lx_exposure_from_ev100((float)a->exposure_ev100)
                                           : 0.0f,
                           .tonemap = a->tonemap,
                           .half = a->half,
                           .mip_names = mip_names,
                           .threads = a->threads};
    return d;
}

/* One cube map (and its mips) in the run's layout, into the staging
 * folder: STEM.ktx, or per level STEM[_mL]_<face>.EXT (faces) /
 * STEM[_mL].EXT (cross, equirect). */
static bool put_cube(writer *w, const char *stem, const lx_cubemap *levels, int count,
                     bool mip_names)
{
    cli_progress progress;
    cli_progress_init(&progress, "write", w->a->quiet);
    lx_env_write_desc d = write_desc(w->a, mip_names);
    d.progress = cli_progress_update;
    d.progress_user = &progress;
    d.on_file = stage_file;
    d.on_file_user = w;
    lx_status s = lx_env_write(w->stage.dir, stem, levels, count, &d);
    char phase[64];
    snprintf(phase, sizeof phase, "write %s", stem);
    progress.phase = phase;
    cli_progress_finish(&progress);
    if (s == LX_OK)
        return true;
    if (w->reported)
        return false;
    if (s == LX_ERR_CANCELLED) {
        cli_report_interrupt(true);
        return false;
    }
    return cli_stage_finish(&w->stage, stem, s);
}

/* The DFG table's file name. */
static void lut_name(const ibl_args *a, char *name, size_t size)
{
    snprintf(name, size, "dfg_lut.%s", lx_image_format_extension(a->format));
}

/* lx_env_write_names's on_file: nothing but a file may be in the way. */
static bool check_name(void *user, const char *name)
{
    writer *w = user;
    w->reported = w->reported || !cli_stage_check(&w->stage, name);
    return !w->reported;
}

/* Checks every output name of the run (cli_stage_check) before the long
 * work, so a folder in the way fails at once. spec_count: the number of
 * specular levels, or 1 while it is not known (level 0's names are those
 * of every run: specular levels always carry _m<L>). */
static bool check_names(writer *w, int spec_count)
{
    const ibl_args *a = w->a;
    const struct {
        bool on;
        const char *stem;
        int count;
        bool mip_names;
    } cubes[] = {{a->irradiance, "irradiance", 1, false},
                 {a->specular, "specular", spec_count, true},
                 {a->environment, "environment", 1, false}};
    for (size_t i = 0; i < sizeof cubes / sizeof cubes[0]; i++) {
        if (!cubes[i].on)
            continue;
        lx_env_write_desc d = write_desc(a, cubes[i].mip_names);
        d.on_file = check_name;
        d.on_file_user = w;
        lx_status s = lx_env_write_names(cubes[i].stem, cubes[i].count, &d);
        if (s != LX_OK) {
            if (!w->reported)
                cli_error("%s: %s", cubes[i].stem, lx_last_error());
            return false;
        }
    }
    char name[32];
    lut_name(a, name, sizeof name);
    return (!a->sh || cli_stage_check(&w->stage, "sh.json")) &&
           (!a->lut || cli_stage_check(&w->stage, name));
}

/* A JSON number with the fewest digits that read back as the same float. */
static cJSON *float_number(float f)
{
    char buf[32];
    for (int digits = 6; digits <= 9; digits++) {
        snprintf(buf, sizeof buf, "%.*g", digits, (double)f);
        if ((float)strtod(buf, NULL) == f)
            break;
    }
    return cJSON_CreateNumber(strtod(buf, NULL));
}

static char *sh_json(const lx_sh9 *sh)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddNumberToObject(root, "order", 2);
    cJSON *coeffs = cJSON_AddArrayToObject(root, "coefficients");
    for (int i = 0; i < 9; i++) {
        cJSON *rgb = cJSON_CreateArray();
        for (int k = 0; k < 3; k++)
            cJSON_AddItemToArray(rgb, float_number(sh->c[i][k]));
        cJSON_AddItemToArray(coeffs, rgb);
    }
    cJSON *consts = cJSON_AddArrayToObject(root, "irradiance_constants");
    for (int i = 0; i < 5; i++)
        cJSON_AddItemToArray(consts, float_number(lx_sh_irradiance_constants[i]));
    cJSON_AddStringToObject(
        root, "convention",
        "Ramamoorthi & Hanrahan 2001: radiance coefficients L_lm in nits, order L00, L1-1, L10, "
        "L11, L2-2, L2-1, L20, L21, L22 with Y1-1 = 0.488603 y, Y10 = 0.488603 z, "
        "Y11 = 0.488603 x in luxel's axes (right-handed, +Y up); irradiance in lux at unit "
        "normal n is the paper's equation 13 with c1..c5 = irradiance_constants");
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}

/* ---- the command ----------------------------------------------------------- */

/* The run's prefilter desc: what the options say, zeros for the rest
 * (the library's defaults). */
static lx_prefilter_desc prefilter_desc(const ibl_args *a)
{
    lx_prefilter_desc d = {.filter = a->filter,
                           .size = a->specular_size,
                           .mips = a->mips,
                           .samples = a->samples,
                           .phong_exponents = a->phong_count ? a->phong : NULL,
                           .threads = a->threads};
    return d;
}

/* The face size of specular level 0 for an environment of env_size. */
static int specular_size(const ibl_args *a, int env_size)
{
    lx_prefilter_desc d = prefilter_desc(a);
    return lx_prefilter_size(env_size, &d);
}

/* The irradiance cube's size argument: the library's default, or the
 * environment's size when that is smaller (no finer than its source). */
static int irradiance_size(int env_size)
{
    return env_size < LX_IRRADIANCE_DEFAULT_SIZE ? env_size : 0;
}

/* Whether the library would take every step of the run for an environment
 * of env_size, asked before the long work (and, when the size is known
 * from the options, before the environment is made): the specular chain's
 * and each output's memory. Prints the error. */
static bool run_fits(const ibl_args *a, int env_size)
{
    lx_status st = LX_OK;
    if (a->specular) {
        lx_prefilter_desc d = prefilter_desc(a);
        st = lx_prefilter_check(env_size, &d);
        if (st == LX_OK && a->layout != LX_ENV_KTX) {
            lx_env_write_desc w = write_desc(a, true);
            int size = specular_size(a, env_size);
            st = lx_env_write_check(size, a->mips ? a->mips : lx_cube_mip_count(size), &w);
        }
    }
    if (st == LX_OK && a->environment) {
        lx_env_write_desc w = write_desc(a, false);
        st = lx_env_write_check(env_size, 1, &w);
    }
    if (st != LX_OK)
        cli_error("%s: %s", a->env, lx_last_error());
    return st == LX_OK;
}

static bool cancelled_or_failed(lx_status s, const char *what)
{
    if (s == LX_OK)
        return false;
    if (s == LX_ERR_CANCELLED)
        cli_report_interrupt(false);
    else
        cli_error("%s: %s", what, lx_last_error());
    return true;
}

int cmd_ibl(int argc, char **argv)
{
    ibl_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;

    int status = EXIT_FAILED;
    lx_cubemap env = {0}, irr = {0};
    lx_cubemap spec[LX_MAX_CUBE_MIPS];
    memset(spec, 0, sizeof spec);
    int spec_count = 0;
    lx_sh9 sh;
    lx_image lut = {0}, lut_rgb = {0};
    writer w;
    memset(&w, 0, sizeof w);
    w.a = &a;

    /* a run that cannot fit fails before its environment is made, when
     * the options tell its size */
    int known = cli_environment_size(a.env, a.size);
    if (a.specular && a.mips && known && a.mips > lx_cube_mip_count(specular_size(&a, known))) {
        status = cli_usage_error("ibl", "--mips %d: a specular cube of size %d has only %d levels",
                                 a.mips, specular_size(&a, known),
                                 lx_cube_mip_count(specular_size(&a, known)));
        goto done;
    }
    if (known && !run_fits(&a, known))
        goto done;
    /* the output folder is checked (and made) before the long work, and
     * every output name in it: the specular chain's when its length is
     * known (the environment's size or the options tell it), else its
     * level 0, and the rest once the environment is loaded */
    if (!cli_stage_begin_set(&w.stage, a.output, a.clean))
        goto done;
    int levels_known = a.mips;
    if (!levels_known && (known || a.specular_size))
        levels_known = lx_cube_mip_count(specular_size(&a, known));
    if (!check_names(&w, levels_known ? levels_known : 1))
        goto done;
    int loaded =
        cli_load_environment_run("ibl", a.env, a.intensity, a.size, a.threads, a.quiet, &env);
    if (loaded != EXIT_OK) {
        status = loaded;
        goto done;
    }
    int spec_size = specular_size(&a, env.size);
    if (a.specular && a.mips > lx_cube_mip_count(spec_size)) {
        status = cli_usage_error("ibl", "--mips %d: a specular cube of size %d has only %d levels",
                                 a.mips, spec_size, lx_cube_mip_count(spec_size));
        goto done;
    }
    if (!known && !run_fits(&a, env.size))
        goto done;
    if (a.specular && !levels_known && !check_names(&w, lx_cube_mip_count(spec_size)))
        goto done;

    cli_progress progress;
    lx_ibl_desc run = {
        .threads = a.threads, .progress = cli_progress_update, .progress_user = &progress};
    if (a.irradiance || a.sh) {
        cli_progress_init(&progress, "sh", a.quiet);
        lx_status s = lx_sh_project(&env, &run, &sh);
        cli_progress_finish(&progress);
        if (cancelled_or_failed(s, a.env))
            goto done;
    }
    if (a.irradiance) {
        cli_progress_init(&progress, "irradiance", a.quiet);
        lx_status s = a.irradiance_sh
                          ? lx_sh_irradiance_cube(&sh, irradiance_size(env.size), &run, &irr)
                          : lx_irradiance_brute(&env, irradiance_size(env.size), 0, &run, &irr);
        cli_progress_finish(&progress);
        if (cancelled_or_failed(s, a.env))
            goto done;
        if (a.seam_fix)
            lx_cubemap_fix_seams(&irr);
    }
    if (a.specular) {
        cli_progress_init(&progress, "specular", a.quiet);
        lx_prefilter_desc d = prefilter_desc(&a);
        d.progress = cli_progress_update;
        d.progress_user = &progress;
        lx_status s = lx_prefilter(&env, &d, spec, &spec_count);
        cli_progress_finish(&progress);
        if (cancelled_or_failed(s, a.env))
            goto done;
        if (a.seam_fix)
            for (int l = 0; l < spec_count; l++)
                lx_cubemap_fix_seams(&spec[l]);
    }
    if (a.lut) {
        cli_progress_init(&progress, "dfg", a.quiet);
        lx_status s = lx_dfg_lut(0, a.samples, &run, &lut);
        cli_progress_finish(&progress);
        if (cancelled_or_failed(s, "DFG table"))
            goto done;
        /* RG in an RGB image (B = 0): every format here stores RGB */
        if (lx_image_alloc(&lut_rgb, lut.width, lut.height, 3) != LX_OK) {
            cli_error("%s", lx_last_error());
            goto done;
        }
        for (size_t i = 0; i < (size_t)lut.width * lut.height; i++) {
            lut_rgb.data[3 * i] = lut.data[i * lut.channels];
            lut_rgb.data[3 * i + 1] = lut.data[i * lut.channels + 1];
        }
    }
    if (cli_interrupted()) {
        cli_report_interrupt(false);
        goto done;
    }

    /* everything is computed: stage the files, then move them into place */
    bool ok = true;
    if (ok && a.irradiance)
        ok = put_cube(&w, "irradiance", &irr, 1, false);
    if (ok && a.sh) {
        char *text = sh_json(&sh);
        ok = text && cli_stage_text(&w.stage, "sh.json", text) && note(&w, "sh.json");
        if (!text)
            cli_error("out of memory");
        free(text);
    }
    if (ok && a.specular)
        ok = put_cube(&w, "specular", spec, spec_count, true);
    if (ok && a.lut) {
        char name[32];
        lut_name(&a, name, sizeof name);
        cli_progress_init(&progress, "write", a.quiet);
        /* the table is data, not a picture: no exposure, no curve, and in
         * a PNG linear codes, not sRGB */
        lx_image_write_desc wd = {.format = a.format,
                                  .linear = true,
                                  .half = a.half && a.format == LX_IMAGE_EXR,
                                  .threads = a.threads,
                                  .progress = cli_progress_update,
                                  .progress_user = &progress};
        ok = cli_stage_image(&w.stage, name, &lut_rgb, &wd) && note(&w, name);
        cli_progress_clear(&progress);
    }
    if (ok && a.environment)
        ok = put_cube(&w, "environment", &env, 1, false);
    if (ok)
        ok = cli_stage_publish(&w.stage);
    if (!ok)
        goto done;
    cli_phase("write and publish");
    if (!a.quiet) {
        fprintf(stderr, "luxel: %d file%s from a %d x %d environment in %.2f s\n", w.written_count,
                w.written_count == 1 ? "" : "s", env.size, env.size, cli_elapsed());
        for (int i = 0; i < w.written_count; i++)
            printf("%s/%s\n", a.output, w.written[i]);
    }
    status = EXIT_OK;
done:
    cli_stage_clear(&w.stage);
    lx_cubemap_free(&env);
    lx_cubemap_free(&irr);
    for (int l = 0; l < LX_MAX_CUBE_MIPS; l++)
        lx_cubemap_free(&spec[l]);
    lx_image_free(&lut);
    lx_image_free(&lut_rgb);
    for (int i = 0; i < w.written_count; i++)
        free(w.written[i]);
    free(w.written);
    return status;
}
