/* luxel probes: the scene baked as luxel bake bakes it (the same scene and
 * lighting options, bake_setup.c), then L2 spherical-harmonic light
 * probes (lx_baker_probes) on a grid over the scene's bounds or at the
 * points of a JSON file, written as one JSON file through a staging
 * folder: an error or Ctrl-C leaves no partial file. docs/probes.md
 * describes the file. */
#define _POSIX_C_SOURCE 200809L
#include "bake_setup.h"
#include "cli.h"
#include "maps_cli.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *probes_usage =
    "usage: luxel probes SCENE [options]\n"
    "\n"
    "Bakes SCENE as luxel bake does (lightmaps with --bounces of indirect\n"
    "light, kept in memory), then computes light probes for dynamic objects:\n"
    "at each point, the light arriving from every direction (the lit and\n"
    "bounced surfaces, the sky, the lights) as order-2 spherical harmonics,\n"
    "9 RGB radiance coefficients (docs/probes.md says how engines evaluate\n"
    "them). Probes inside geometry are written with \"valid\": false.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE       the probes' JSON file (default probes.json)\n"
    "  --grid NX,NY,NZ         probes at the cell centres of an NX x NY x NZ grid\n"
    "                          over the scene's bounding box (default %d,%d,%d)\n"
    "  --points FILE           probes at the points of FILE instead:\n"
    "                          {\"points\": [[x, y, z], ...]} in metres\n"
    "  --samples N             rays per probe (default %u)\n"
    "  --threads N             worker threads (default: all cores)\n"
    "  -v, --verbose           the time of each phase, and notes\n"
    "  -q, --quiet             no progress bar or summary\n"
    "  --allow-any-path        read files the inputs name outside their folders\n"
    "  -h, --help              show this help\n"
    "\n"
    "scene and lighting, as luxel bake (luxel bake --help): --lights, --ambient,\n"
    "--sky, --sky-intensity, --sky-shadows, --no-sky-shadows, --sky-samples,\n"
    "--bounces, --gi-samples, --emissive-scale, --denoise, --resolution,\n"
    "--texel-density, --max-resolution, --padding, --unwrap, --uv-set, --atlas,\n"
    "--no-atlas, --atlas-size, --memory-limit, --strict\n";

enum { OPT_GRID = BAKE_OPT_OWN, OPT_POINTS, OPT_SAMPLES };

/* The grid when neither --grid nor --points is given: the CLI's choice. */
#define CLI_PROBE_GRID 4

typedef struct probes_args {
    bake_args bake;
    const char *output;
    int grid[3];        /* 0: not given */
    const char *points; /* --points FILE */
    uint32_t samples;   /* 0: the library's default */
} probes_args;

/* "NX,NY,NZ", each 1..LX_MAX_PROBE_GRID, at most LX_MAX_PROBES in all. */
static bool parse_grid(const char *s, int out[3])
{
    char buf[96];
    if (strlen(s) >= sizeof buf)
        return false;
    strcpy(buf, s);
    char *save = NULL, *tok = strtok_r(buf, ",", &save);
    int k = 0;
    for (; tok && k < 3; k++, tok = strtok_r(NULL, ",", &save)) {
        long n;
        if (!cli_parse_int(tok, 1, LX_MAX_PROBE_GRID, &n))
            return false;
        out[k] = (int)n;
    }
    if (k != 3 || tok || s[strlen(s) - 1] == ',' || strstr(s, ",,") || s[0] == ',')
        return false;
    return (uint64_t)out[0] * (uint64_t)out[1] * (uint64_t)out[2] <= LX_MAX_PROBES;
}

static int parse_args(int argc, char **argv, probes_args *a)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            BAKE_SETUP_OPTIONS,
                                            {"grid", required_argument, NULL, OPT_GRID},
                                            {"points", required_argument, NULL, OPT_POINTS},
                                            {"samples", required_argument, NULL, OPT_SAMPLES},
                                            {"threads", required_argument, NULL, CLI_OPT_THREADS},
                                            {"quiet", no_argument, NULL, 'q'},
                                            {"verbose", no_argument, NULL, 'v'},
                                            CLI_ANY_PATH_OPTION,
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    cli_bake_args_init(&a->bake, "probes");
    a->bake.desc.probes = true;
    a->output = "probes.json";
    opterr = 0;
    optind = 1;
    int c;
    long n;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg)
                return cli_usage_error("probes", "-o needs a file name");
            a->output = optarg;
            break;
        case OPT_GRID:
            if (!parse_grid(optarg, a->grid))
                return cli_usage_error("probes",
                                       "--grid must be NX,NY,NZ with integers in 1..%d and at "
                                       "most %u probes, not '%s'",
                                       LX_MAX_PROBE_GRID, LX_MAX_PROBES, optarg);
            break;
        case OPT_POINTS:
            if (!*optarg)
                return cli_usage_error("probes", "--points needs a file name");
            a->points = optarg;
            break;
        case OPT_SAMPLES:
            if (!cli_parse_int(optarg, 1, (long)LX_MAX_PROBE_SAMPLES, &n))
                return cli_usage_error("probes", "--samples must be an integer in 1..%u, not '%s'",
                                       LX_MAX_PROBE_SAMPLES, optarg);
            a->samples = (uint32_t)n;
            break;
        case 'h':
            printf(probes_usage, CLI_PROBE_GRID, CLI_PROBE_GRID, CLI_PROBE_GRID,
                   lx_probe_desc_defaults(NULL).samples);
            return -1;
        default: {
            int rc = cli_bake_option(&a->bake, c, optarg);
            if (rc == CLI_BAKE_NOT_MINE)
                rc = cli_common_option("probes", c, argv, &a->bake.desc.threads, &a->bake.quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    int one = cli_one_scene("probes", argc, argv, &a->bake.scene);
    if (one != 0)
        return one;
    if (a->grid[0] && a->points)
        return cli_usage_error("probes", "--grid and --points both place the probes: give one");
    const char *slash = strrchr(a->output, '/');
    if (!(slash ? slash[1] : a->output[0]))
        return cli_usage_error("probes", "-o must name a file, not a folder ('%s')", a->output);
    if (!a->grid[0] && !a->points)
        a->grid[0] = a->grid[1] = a->grid[2] = CLI_PROBE_GRID;
    return cli_bake_check_args(&a->bake);
}

/* The points of a --points file: {"points": [[x, y, z], ...]}, finite
 * numbers, at least one, at most LX_MAX_PROBES. EXIT_OK, or EXIT_USAGE with
 * the error printed. */
static int read_points(const char *path, lx_vec3 **out, uint32_t *count)
{
    *out = NULL;
    *count = 0;
    size_t size = 0;
    char *text = cli_read_text(path, &size);
    if (!text) {
        cli_error("%s: cannot read the points file: %s", path, strerror(errno ? errno : EIO));
        return EXIT_USAGE;
    }
    char err[512];
    cJSON *root = cli_json_parse(path, text, size, err, sizeof err);
    free(text);
    if (!root) {
        cli_error("%s", err);
        return EXIT_USAGE;
    }
    int status = EXIT_USAGE;
    const cJSON *list =
        cJSON_IsObject(root) ? cJSON_GetObjectItemCaseSensitive(root, "points") : NULL;
    int n = cJSON_IsArray(list) ? cJSON_GetArraySize(list) : -1;
    if (n < 0) {
        cli_error("%s: expected an object with an array \"points\": [[x, y, z], ...]", path);
    } else if (n == 0) {
        cli_error("%s: \"points\" is empty: no probe to compute", path);
    } else if ((uint64_t)n > LX_MAX_PROBES) {
        cli_error("%s: %d points, at most %u", path, n, LX_MAX_PROBES);
    } else if (!(*out = malloc(sizeof(lx_vec3) * (size_t)n))) {
        cli_error("out of memory");
        status = EXIT_FAILED;
    } else {
        int i = 0;
        const cJSON *p;
        cJSON_ArrayForEach(p, list)
        {
            float v[3];
            int k = 0;
            bool ok = cJSON_IsArray(p) && cJSON_GetArraySize(p) == 3;
            const cJSON *x;
            cJSON_ArrayForEach(x, p)
            {
                if (!ok || k >= 3 || !cJSON_IsNumber(x) || !isfinite(x->valuedouble) ||
                    fabs(x->valuedouble) > 3.0e38) {
                    ok = false;
                    break;
                }
                v[k++] = (float)x->valuedouble;
            }
            if (!ok || k != 3) {
                cli_error("%s: points[%d]: expected [x, y, z], three finite numbers (metres)", path,
                          i);
                break;
            }
            (*out)[i++] = lx_v3(v[0], v[1], v[2]);
        }
        if (i == n) {
            *count = (uint32_t)n;
            status = EXIT_OK;
        }
    }
    cJSON_Delete(root);
    if (status != EXIT_OK) {
        free(*out);
        *out = NULL;
    }
    return status;
}

/* A JSON array of three numbers; floats printed as the shortest decimal
 * that reads back as the same float (cJSON prints doubles to 17 digits). */
static cJSON *number(float v)
{
    char buf[32];
    snprintf(buf, sizeof buf, "%.9g", (double)v);
    /* the double nearest 9 digits: cJSON prints it back in at most 15 */
    return cJSON_CreateNumber(strtod(buf, NULL));
}

static cJSON *triple(float x, float y, float z)
{
    cJSON *a = cJSON_CreateArray();
    cJSON_AddItemToArray(a, number(x));
    cJSON_AddItemToArray(a, number(y));
    cJSON_AddItemToArray(a, number(z));
    return a;
}

static char *probes_json(const probes_args *a, const lx_bake_desc *desc, uint32_t samples,
                         const lx_vec3 *points, const lx_probe *probes, uint32_t count,
                         const lx_vec3 *lo, const lx_vec3 *hi)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", a->bake.scene);
    cJSON_AddStringToObject(root, "coefficients", "radiance");
    cJSON_AddStringToObject(root, "unit", "nt");
    cJSON_AddStringToObject(root, "basis",
                            "real spherical harmonics, order 2: Y00 = 0.282095, Y1-1 = 0.488603 y, "
                            "Y10 = 0.488603 z, Y11 = 0.488603 x, Y2-2 = 1.092548 xy, Y2-1 = "
                            "1.092548 yz, Y20 = 0.315392 (3z^2 - 1), Y21 = 1.092548 xz, Y22 = "
                            "0.546274 (x^2 - y^2); x, y, z world axes, +Y up");
    cJSON_AddStringToObject(root, "irradiance",
                            "E(n) = sum A_l L_lm Y_lm(n) lux, A_0 = pi, A_1 = 2 pi / 3, A_2 = "
                            "pi / 4 (Ramamoorthi and Hanrahan 2001)");
    cJSON_AddNumberToObject(root, "samples", samples);
    cJSON_AddNumberToObject(root, "bounces", desc->bounces);
    if (lo) {
        cJSON *g = cJSON_AddObjectToObject(root, "grid");
        cJSON *n = cJSON_AddArrayToObject(g, "counts");
        for (int k = 0; k < 3; k++)
            cJSON_AddItemToArray(n, cJSON_CreateNumber(a->grid[k]));
        cJSON_AddItemToObject(g, "min", triple(lo->x, lo->y, lo->z));
        cJSON_AddItemToObject(g, "max", triple(hi->x, hi->y, hi->z));
        cJSON_AddStringToObject(g, "placement", "cell centres");
        cJSON_AddStringToObject(g, "order", "x fastest, then y, then z");
    } else {
        cJSON_AddStringToObject(root, "points", a->points);
    }
    cJSON *list = cJSON_AddArrayToObject(root, "probes");
    for (uint32_t i = 0; i < count; i++) {
        cJSON *p = cJSON_CreateObject();
        cJSON_AddItemToObject(p, "position", triple(points[i].x, points[i].y, points[i].z));
        cJSON_AddBoolToObject(p, "valid", probes[i].valid);
        cJSON *sh = cJSON_AddArrayToObject(p, "sh");
        for (int j = 0; j < 9; j++)
            cJSON_AddItemToArray(
                sh, triple(probes[i].sh.c[j][0], probes[i].sh.c[j][1], probes[i].sh.c[j][2]));
        cJSON_AddItemToArray(list, p);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}

int cmd_probes(int argc, char **argv)
{
    probes_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;

    lx_scene *scene = NULL;
    lx_baker *baker = NULL;
    lx_unwrap *unwrap = NULL;
    lx_vec3 *points = NULL;
    lx_probe *probes = NULL;
    uint32_t count = 0;
    cli_stage stage = {0};
    cli_progress progress;
    lx_scene_sky sky;
    bool atlas = false;
    int status = EXIT_FAILED;
    maps_output out = {.path = a.output};

    /* the points before anything long, then the output's folder */
    if (a.points && (status = read_points(a.points, &points, &count)) != EXIT_OK)
        return status;
    status = EXIT_FAILED;
    if (!maps_output_begin(&out, &stage))
        goto done;
    int prepared = cli_bake_prepare(&a.bake, &progress, &scene, &sky, &unwrap, &atlas, &baker);
    if (prepared != EXIT_OK) {
        status = prepared;
        goto done;
    }
    lx_vec3 lo, hi;
    if (!a.points) {
        if (!lx_scene_bounds(scene, &lo, &hi)) {
            cli_error("%s: the scene has no geometry to place a probe grid over", a.bake.scene);
            goto done;
        }
        count = (uint32_t)a.grid[0] * (uint32_t)a.grid[1] * (uint32_t)a.grid[2];
        points = malloc(sizeof(lx_vec3) * count);
        if (!points) {
            cli_error("out of memory for %u probes", count);
            goto done;
        }
        if (lx_probe_grid(lo, hi, a.grid[0], a.grid[1], a.grid[2], points) != LX_OK) {
            cli_error("%s", lx_last_error());
            goto done;
        }
    }
    probes = calloc(count, sizeof *probes);
    if (!probes) {
        cli_error("out of memory for %u probes", count);
        goto done;
    }
    cli_progress_init(&progress, "bake", a.bake.quiet);
    lx_status st = lx_baker_bake(baker);
    cli_progress_finish(&progress);
    if (st == LX_OK) {
        cli_progress_init(&progress, "probes", a.bake.quiet);
        lx_probe_desc pd = {.samples = a.samples,
                            .threads = a.bake.desc.threads,
                            .progress = cli_progress_update,
                            .progress_user = &progress};
        st = lx_baker_probes(baker, points, count, &pd, probes);
        cli_progress_finish(&progress);
    }
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        goto done;
    }
    uint32_t invalid = 0;
    for (uint32_t i = 0; i < count; i++)
        invalid += !probes[i].valid;
    if (invalid)
        lx_log(LX_LOG_INFO, "%s: %u of %u probes sit inside geometry (\"valid\": false)",
               a.bake.scene, invalid, count);
    if (cli_interrupted()) {
        cli_report_interrupt(false);
        goto done;
    }
    if (cli_bake_strict_failed(&a.bake))
        goto done;
    lx_probe_desc given = {.samples = a.samples};
    uint32_t samples = lx_probe_desc_defaults(&given).samples;
    char *text = probes_json(&a, &a.bake.desc, samples, points, probes, count,
                             a.points ? NULL : &lo, a.points ? NULL : &hi);
    if (!text) {
        cli_error("out of memory");
        goto done;
    }
    bool ok = cli_stage_text(&stage, maps_output_name(&out), text) && cli_stage_publish(&stage);
    free(text);
    if (!ok)
        goto done;
    cli_phase("write");
    if (!a.bake.quiet) {
        fprintf(stderr, "luxel: %u %s (%u inside geometry) in %s s\n", count,
                cli_plural(count, "probe", "probes"), invalid, cli_num_digits(cli_elapsed(), 3));
        printf("%s\n", a.output);
    }
    status = EXIT_OK;
done:
    cli_stage_clear(&stage);
    free(points);
    free(probes);
    lx_baker_destroy(baker);
    lx_unwrap_destroy(unwrap);
    lx_scene_destroy(scene);
    return status;
}
