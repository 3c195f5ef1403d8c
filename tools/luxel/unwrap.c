/* luxel unwrap: lightmap UVs for every node of a scene, written with the
 * scene as a .glb (in each node's lightmap set, lx_scene_lightmap_set),
 * and a one-line summary. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static const char *unwrap_usage =
    "usage: luxel unwrap SCENE -o OUT.glb [options]\n"
    "\n"
    "Makes lightmap UVs for every node that carries a mesh of SCENE (glTF 2.0\n"
    ".gltf/.glb or OBJ), packs them into atlas pages and writes the scene as a\n"
    "glTF binary with the UVs, in page coordinates, in TEXCOORD_1 (or, when a\n"
    "material of the node reads a texture through TEXCOORD_1, the lowest set\n"
    "above it that none reads). A glTF scene keeps everything else as it was;\n"
    "a mesh several nodes share is copied per node (each instance has its own\n"
    "region of a page).\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      the .glb to write (required)\n"
    "  --texel-density T      texels per metre of world space\n"
    "  --resolution N         without --texel-density: the density at which the\n"
    "                         scene about fills one page of N x N (default %d)\n"
    "  --padding N            texel rings each chart owns, 0..%d (default %d)\n"
    "  --atlas-size N         largest page side in texels (default %d)\n"
    "  --strict               refuse zero-area triangles instead of leaving them out\n"
    "  --threads N            threads to use (default: all cores)\n"
    "  -q, --quiet            no progress bar and no summary\n"
    "  -v, --verbose          phase times and the unwrapper's figures\n"
    "  --allow-any-path       read files the inputs name outside their folders\n"
    "  -h, --help             show this help\n";

enum {
    OPT_TEXEL_DENSITY = 256,
    OPT_RESOLUTION,
    OPT_PADDING,
    OPT_ATLAS_SIZE,
    OPT_STRICT,
};

typedef struct unwrap_args {
    const char *scene, *output;
    lx_unwrap_desc desc;
    bool has_resolution;
    bool strict;
    bool quiet;
} unwrap_args;

static bool ends_with_glb(const char *s)
{
    size_t n = strlen(s);
    return n > 4 && strcasecmp(s + n - 4, ".glb") == 0;
}

static int parse_args(int argc, char **argv, unwrap_args *a)
{
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'},
        {"texel-density", required_argument, NULL, OPT_TEXEL_DENSITY},
        {"resolution", required_argument, NULL, OPT_RESOLUTION},
        {"padding", required_argument, NULL, OPT_PADDING},
        {"atlas-size", required_argument, NULL, OPT_ATLAS_SIZE},
        {"strict", no_argument, NULL, OPT_STRICT},
        {"threads", required_argument, NULL, CLI_OPT_THREADS},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        CLI_ANY_PATH_OPTION,
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->desc = lx_unwrap_desc_defaults(NULL);
    a->desc.padding = LX_UNWRAP_PADDING_RECOMMENDED;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case 'o':
            a->output = optarg;
            break;
        case OPT_TEXEL_DENSITY:
            if (!cli_parse_float(optarg, 1e-6, 1e6, &f))
                return cli_usage_error("unwrap",
                                       "--texel-density must be a positive number of texels per "
                                       "metre, not '%s'",
                                       optarg);
            a->desc.texel_density = (float)f;
            break;
        case OPT_RESOLUTION:
            if (!cli_parse_int(optarg, 4, LX_UNWRAP_MAX_ATLAS_SIZE, &n))
                return cli_usage_error("unwrap", "--resolution must be an integer in 4..%d, not '%s'",
                                       LX_UNWRAP_MAX_ATLAS_SIZE, optarg);
            a->desc.resolution = (int)n;
            a->has_resolution = true;
            break;
        case OPT_PADDING:
            if (!cli_parse_int(optarg, 0, LX_UNWRAP_MAX_PADDING, &n))
                return cli_usage_error("unwrap", "--padding must be an integer in 0..%d, not '%s'",
                                       LX_UNWRAP_MAX_PADDING, optarg);
            a->desc.padding = (int)n;
            break;
        case OPT_ATLAS_SIZE:
            if (!cli_parse_int(optarg, 4, LX_UNWRAP_MAX_ATLAS_SIZE, &n))
                return cli_usage_error("unwrap", "--atlas-size must be an integer in 4..%d, not '%s'",
                                       LX_UNWRAP_MAX_ATLAS_SIZE, optarg);
            a->desc.atlas_size = (int)n;
            break;
        case OPT_STRICT:
            a->strict = true;
            break;
        case 'h': {
            lx_unwrap_desc d = lx_unwrap_desc_defaults(NULL);
            printf(unwrap_usage, d.resolution, LX_UNWRAP_MAX_PADDING,
                   LX_UNWRAP_PADDING_RECOMMENDED, d.atlas_size);
            return -1;
        }
        default: {
            int rc = cli_common_option("unwrap", c, argv, &a->desc.threads, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    int one = cli_one_scene("unwrap", argc, argv, &a->scene);
    if (one != 0)
        return one;
    if (!a->output)
        return cli_usage_error("unwrap", "no output given (-o OUT.glb)");
    if (!ends_with_glb(a->output))
        return cli_usage_error("unwrap", "the output is a glTF binary: its name ends in .glb, "
                                         "not '%s'",
                               a->output);
    if (a->has_resolution && a->desc.texel_density > 0.0f)
        return cli_usage_error("unwrap", "--resolution and --texel-density both size the pages: "
                                         "give one");
    return 0;
}

lx_status cli_write_scene_with_uvs(const lx_scene *scene, const lx_unwrap *u, const char *path)
{
    lx_scene_uvs *uvs = calloc(u->mesh_count ? u->mesh_count : 1, sizeof *uvs);
    if (!uvs)
        return LX_ERR_NOMEM;
    for (uint32_t k = 0; k < u->mesh_count; k++) {
        const lx_unwrap_mesh *m = &u->meshes[k];
        uvs[k] = (lx_scene_uvs){.node = m->node,
                                .mesh = m->mesh,
                                .vertex_count = m->vertex_count,
                                .vertex_source = m->vertex_source,
                                .uv = m->uv,
                                .indices = m->indices};
    }
    lx_glb_write_desc d = {.uvs = uvs, .uv_count = u->mesh_count};
    lx_status st = lx_scene_write_glb(scene, path, &d);
    free(uvs);
    return st;
}

bool cli_scene_glb_name(const char *scene, char *out, size_t size)
{
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    const char *dot = strrchr(base, '.');
    size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (n == 0 || n + 5 > size) {
        cli_error("%s: cannot name the scene's .glb after it", scene);
        return false;
    }
    snprintf(out, size, "%.*s.glb", (int)n, base);
    return true;
}

int cli_stage_scene_with_uvs(cli_stage *st, const char *name, const lx_scene *scene,
                             const lx_unwrap *u)
{
    char *path = cli_stage_path(st, name);
    if (!path)
        return -1;
    lx_status s = cli_write_scene_with_uvs(scene, u, path);
    free(path);
    if (s == LX_ERR_UNSUPPORTED) {
        lx_log(LX_LOG_WARN, "%s; the lightmaps are written without it", lx_last_error());
        free(st->names[--st->count]); /* nothing was staged under the name */
        return 0;
    }
    return cli_stage_finish(st, name, s) ? 1 : -1;
}

/* The output can be made: its folder exists, nothing but a file is in the
 * way. Checked before the long work. */
static bool output_ok(const char *path)
{
    struct stat sb;
    if (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode)) {
        cli_error("%s: cannot write: something that is not a file is in the way", path);
        return false;
    }
    char *dir = cli_strdup(path);
    if (!dir) {
        cli_error("out of memory");
        return false;
    }
    char *slash = strrchr(dir, '/');
    const char *folder = slash ? (slash == dir ? "/" : (*slash = '\0', dir)) : ".";
    bool ok = stat(folder, &sb) == 0 && S_ISDIR(sb.st_mode);
    if (!ok)
        cli_error("%s: cannot write: the folder '%s' does not exist", path, folder);
    free(dir);
    return ok;
}

int cmd_unwrap(int argc, char **argv)
{
    unwrap_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    if (!output_ok(a.output))
        return EXIT_FAILED;
    lx_scene *scene = NULL;
    lx_unwrap *u = NULL;
    int status = EXIT_FAILED;
    lx_scene_load_desc ld = {.strict = a.strict, .allow_any_path = cli_allow_any_path()};
    if (!cli_scene_load(a.scene, &ld, &scene))
        goto done;
    cli_phase("import");
    if (scene->node_count == 0) {
        cli_error("%s: the scene has no meshes to unwrap", a.scene);
        goto done;
    }
    cli_progress progress;
    cli_progress_init(&progress, "unwrap", a.quiet);
    a.desc.progress = cli_progress_update;
    a.desc.progress_user = &progress;
    lx_status st = lx_unwrap_scene(scene, &a.desc, &u);
    cli_progress_finish(&progress);
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s: %s", a.scene, lx_last_error());
        goto done;
    }
    if (u->mesh_count == 0) {
        cli_error("%s: no node has triangles to unwrap", a.scene);
        goto done;
    }
    cli_test_pause("write");
    if (cli_interrupted()) {
        cli_report_interrupt(false);
        goto done;
    }
    if (cli_write_scene_with_uvs(scene, u, a.output) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    cli_phase("write");
    if (!a.quiet) {
        int w = u->page_count ? u->pages[0].width : 0, h = u->page_count ? u->pages[0].height : 0;
        printf("%s: %u charts on %u page%s (%dx%d%s), %.1f%% of the texels covered, %g texels/m\n",
               a.output, u->stats.charts, u->page_count, u->page_count == 1 ? "" : "s", w, h,
               u->page_count > 1 ? " the first" : "", 100.0 * u->stats.efficiency,
               (double)u->texel_density);
    }
    status = EXIT_OK;
done:
    lx_unwrap_destroy(u);
    lx_scene_destroy(scene);
    return status;
}
