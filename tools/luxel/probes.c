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
#include <float.h>
#include <limits.h>
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
    /* cJSON's tree takes a node (sizeof(cJSON)) for each number, and a
     * number with its comma is at least 2 bytes of text */
    if (lx_memory_check((uint64_t)size / 2 * sizeof(cJSON), "reading the points") != LX_OK) {
        cli_error("%s: %s", path, lx_last_error());
        free(text);
        return EXIT_FAILED;
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

/* ---- the file ---------------------------------------------------------------
 * Written as it is made, straight to the staged file: a cJSON tree of
 * every probe took ~45 nodes a probe (800 MB for 200k probes) and its
 * printing 11 s. The bytes are the ones cJSON_Print made (tabs, ", "
 * between array items), so readers and earlier files see no change. */

/* A float as the shortest decimal that reads back as the same float:
 * its 9 significant digits, then printed as cJSON prints a double (an
 * integer in int range as one, else 15 digits, or 17 when 15 do not
 * read back). */
static void put_number(FILE *fp, float v)
{
    char buf[32];
    if (v == 0.0f) { /* -0 too: cJSON prints integers as %d */
        fputc('0', fp);
        return;
    }
    snprintf(buf, sizeof buf, "%.9g", (double)v);
    /* Below 1e9 that is already what cJSON prints: 15 digits of the
     * nearest double give the same at most 9 digits back, and %g writes
     * an exponent at the same magnitudes. (Printing every number three
     * times took 26 s for 200k probes.) */
    if (isfinite(v) && fabsf(v) < 1e9f) {
        fputs(buf, fp);
        return;
    }
    double d = strtod(buf, NULL);
    if (isnan(d) || isinf(d)) {
        fputs("null", fp);
        return;
    }
    if (d >= INT_MIN && d <= INT_MAX && d == (double)(int)d) {
        fprintf(fp, "%d", (int)d);
        return;
    }
    snprintf(buf, sizeof buf, "%1.15g", d);
    double back = strtod(buf, NULL);
    double largest = fabs(back) > fabs(d) ? fabs(back) : fabs(d);
    if (!(fabs(back - d) <= largest * DBL_EPSILON))
        snprintf(buf, sizeof buf, "%1.17g", d);
    fputs(buf, fp);
}

static void put_triple(FILE *fp, float x, float y, float z)
{
    fputc('[', fp);
    put_number(fp, x);
    fputs(", ", fp);
    put_number(fp, y);
    fputs(", ", fp);
    put_number(fp, z);
    fputc(']', fp);
}

/* A JSON string, escaped as cJSON escapes it. */
static void put_string(FILE *fp, const char *text)
{
    fputc('"', fp);
    for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
        switch (*c) {
        case '"': fputs("\\\"", fp); break;
        case '\\': fputs("\\\\", fp); break;
        case '\b': fputs("\\b", fp); break;
        case '\f': fputs("\\f", fp); break;
        case '\n': fputs("\\n", fp); break;
        case '\r': fputs("\\r", fp); break;
        case '\t': fputs("\\t", fp); break;
        default:
            if (*c < 32)
                fprintf(fp, "\\u%04x", *c);
            else
                fputc(*c, fp);
        }
    }
    fputc('"', fp);
}

/* One "key": value line's start at the given depth of tabs. */
static void put_key(FILE *fp, int depth, const char *key)
{
    for (int i = 0; i < depth; i++)
        fputc('\t', fp);
    put_string(fp, key);
    fputs(":\t", fp);
}

static void write_probes_json(FILE *fp, const probes_args *a, const lx_bake_desc *desc,
                              uint32_t samples, const lx_vec3 *points, const lx_probe *probes,
                              uint32_t count, const lx_vec3 *lo, const lx_vec3 *hi)
{
    fputs("{\n", fp);
    put_key(fp, 1, "scene");
    put_string(fp, a->bake.scene);
    fputs(",\n", fp);
    put_key(fp, 1, "coefficients");
    fputs("\"radiance\",\n", fp);
    put_key(fp, 1, "unit");
    fputs("\"nt\",\n", fp);
    put_key(fp, 1, "basis");
    put_string(fp, "real spherical harmonics, order 2: Y00 = 0.282095, Y1-1 = 0.488603 y, "
                   "Y10 = 0.488603 z, Y11 = 0.488603 x, Y2-2 = 1.092548 xy, Y2-1 = "
                   "1.092548 yz, Y20 = 0.315392 (3z^2 - 1), Y21 = 1.092548 xz, Y22 = "
                   "0.546274 (x^2 - y^2); x, y, z world axes, +Y up");
    fputs(",\n", fp);
    put_key(fp, 1, "irradiance");
    put_string(fp, "E(n) = sum A_l L_lm Y_lm(n) lux, A_0 = pi, A_1 = 2 pi / 3, A_2 = "
                   "pi / 4 (Ramamoorthi and Hanrahan 2001)");
    fputs(",\n", fp);
    put_key(fp, 1, "samples");
    fprintf(fp, "%u,\n", samples);
    put_key(fp, 1, "bounces");
    fprintf(fp, "%d,\n", desc->bounces);
    if (lo) {
        put_key(fp, 1, "grid");
        fputs("{\n", fp);
        put_key(fp, 2, "counts");
        fprintf(fp, "[%d, %d, %d],\n", a->grid[0], a->grid[1], a->grid[2]);
        put_key(fp, 2, "min");
        put_triple(fp, lo->x, lo->y, lo->z);
        fputs(",\n", fp);
        put_key(fp, 2, "max");
        put_triple(fp, hi->x, hi->y, hi->z);
        fputs(",\n", fp);
        put_key(fp, 2, "placement");
        fputs("\"cell centres\",\n", fp);
        put_key(fp, 2, "order");
        fputs("\"x fastest, then y, then z\"\n\t},\n", fp);
    } else {
        put_key(fp, 1, "points");
        put_string(fp, a->points);
        fputs(",\n", fp);
    }
    put_key(fp, 1, "probes");
    fputc('[', fp);
    for (uint32_t i = 0; i < count; i++) {
        fputs(i ? ", {\n" : "{\n", fp);
        put_key(fp, 3, "position");
        put_triple(fp, points[i].x, points[i].y, points[i].z);
        fputs(",\n", fp);
        put_key(fp, 3, "valid");
        fputs(probes[i].valid ? "true,\n" : "false,\n", fp);
        put_key(fp, 3, "sh");
        fputc('[', fp);
        for (int j = 0; j < 9; j++) {
            if (j)
                fputs(", ", fp);
            put_triple(fp, probes[i].sh.c[j][0], probes[i].sh.c[j][1], probes[i].sh.c[j][2]);
        }
        fputs("]\n\t\t}", fp);
    }
    fputs("]\n}", fp);
}

/* Writes the file into the staging folder; false with the error printed. */
static bool stage_probes_json(cli_stage *stage, const char *name, const probes_args *a,
                              const lx_bake_desc *desc, uint32_t samples, const lx_vec3 *points,
                              const lx_probe *probes, uint32_t count, const lx_vec3 *lo,
                              const lx_vec3 *hi)
{
    char *path = cli_stage_path(stage, name);
    if (!path)
        return false;
    FILE *fp = fopen(path, "wb");
    bool ok = fp != NULL;
    if (ok) {
        write_probes_json(fp, a, desc, samples, points, probes, count, lo, hi);
        ok = !ferror(fp);
        ok = fclose(fp) == 0 && ok;
    }
    free(path);
    if (!ok) {
        cli_error("%s/%s: cannot write: %s", stage->output, name, strerror(errno ? errno : EIO));
        return false;
    }
    return cli_stage_finish(stage, name, LX_OK);
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
    /* the points and their probes stay until the file is written (which
     * streams, holding nothing per probe): checked before the bake */
    uint32_t planned = a.points ? count
                                : (uint32_t)a.grid[0] * (uint32_t)a.grid[1] * (uint32_t)a.grid[2];
    char what[64];
    snprintf(what, sizeof what, "the buffers of %u light probes", planned);
    if (lx_memory_check((uint64_t)planned * (sizeof *probes + sizeof *points), what) != LX_OK) {
        cli_error("%s: %s", a.points ? a.points : a.bake.scene, lx_last_error());
        free(points);
        return EXIT_FAILED;
    }
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
    if (!stage_probes_json(&stage, maps_output_name(&out), &a, &a.bake.desc, samples, points,
                           probes, count, a.points ? NULL : &lo, a.points ? NULL : &hi) ||
        !cli_stage_publish(&stage))
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
