/* luxel bake: lightmaps for every node of a scene, with previews and a
 * manifest. Everything is computed before the first file is written; if a
 * write fails or the run is interrupted, this run's files are removed. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *bake_usage =
    "usage: luxel bake SCENE [options]\n"
    "\n"
    "Bakes a lightmap for every node that carries a mesh of SCENE (glTF 2.0\n"
    ".gltf/.glb or OBJ), lit by the scene's KHR_lights_punctual lights and\n"
    "those of --lights. Writes DIR/<node>.<format>, DIR/<node>.png (preview)\n"
    "and DIR/manifest.json.\n"
    "\n"
    "options:\n"
    "  -o, --output DIR        output folder (default ./lightmaps)\n"
    "  --resolution N          texels per side of every lightmap (default 256)\n"
    "  --texel-density T       texels per metre instead: each lightmap sized from\n"
    "                          its world and UV areas, a multiple of 4\n"
    "  --max-resolution N      cap for --texel-density sizes (default 4096)\n"
    "  --lights FILE.json      lights and settings added to or overriding the\n"
    "                          scene's (docs/lights-json.md)\n"
    "  --format F              exr (default), hdr, pfm or png\n"
    "  --half                  EXR with 16-bit half floats\n"
    "  --pre-expose            store values times the exposure of --exposure\n"
    "                          (seed 001's pre-exposure: sun-lit scenes fit in\n"
    "                          half floats); the manifest records the factor\n"
    "  --quantity Q            irradiance (lux, default) or radiance (nits:\n"
    "                          irradiance x base colour / pi)\n"
    "  --ambient R,G,B         constant ambient illuminance in lux\n"
    "  --exposure EV100        exposure of the PNG preview (default: automatic)\n"
    "  --padding N             texels of dilation around charts (default 2)\n"
    "  --threads N             worker threads (default: all cores)\n"
    "  --skip-degenerate       skip zero-area triangles with a warning instead of\n"
    "                          failing\n"
    "  -q, --quiet             no progress bar or summary\n"
    "  -h, --help              show this help\n";

enum {
    OPT_RESOLUTION = 256,
    OPT_TEXEL_DENSITY,
    OPT_MAX_RESOLUTION,
    OPT_LIGHTS,
    OPT_FORMAT,
    OPT_HALF,
    OPT_PRE_EXPOSE,
    OPT_QUANTITY,
    OPT_AMBIENT,
    OPT_EXPOSURE,
    OPT_PADDING,
    OPT_THREADS,
    OPT_SKIP_DEGENERATE
};

typedef struct bake_args {
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
    lx_bake_desc desc;
} bake_args;

static int parse_args(int argc, char **argv, bake_args *a)
{
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'},
        {"resolution", required_argument, NULL, OPT_RESOLUTION},
        {"texel-density", required_argument, NULL, OPT_TEXEL_DENSITY},
        {"max-resolution", required_argument, NULL, OPT_MAX_RESOLUTION},
        {"lights", required_argument, NULL, OPT_LIGHTS},
        {"format", required_argument, NULL, OPT_FORMAT},
        {"half", no_argument, NULL, OPT_HALF},
        {"pre-expose", no_argument, NULL, OPT_PRE_EXPOSE},
        {"quantity", required_argument, NULL, OPT_QUANTITY},
        {"ambient", required_argument, NULL, OPT_AMBIENT},
        {"exposure", required_argument, NULL, OPT_EXPOSURE},
        {"padding", required_argument, NULL, OPT_PADDING},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"skip-degenerate", no_argument, NULL, OPT_SKIP_DEGENERATE},
        {"quiet", no_argument, NULL, 'q'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->output = "lightmaps";
    a->format = LX_IMAGE_EXR;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qh", options, NULL)) != -1) {
        switch (c) {
        case 'o':
            a->output = optarg;
            break;
        case OPT_RESOLUTION:
            if (!cli_parse_int(optarg, 1, LX_MAX_LIGHTMAP_SIZE, &n))
                return cli_usage_error("bake", "--resolution must be an integer in 1..%d, not '%s'",
                                       LX_MAX_LIGHTMAP_SIZE, optarg);
            a->desc.resolution = (int)n;
            break;
        case OPT_TEXEL_DENSITY:
            if (!cli_parse_float(optarg, 1e-6, 1e6, &f))
                return cli_usage_error("bake",
                                       "--texel-density must be a positive number of "
                                       "texels per metre, not '%s'",
                                       optarg);
            a->desc.texel_density = (float)f;
            break;
        case OPT_MAX_RESOLUTION:
            if (!cli_parse_int(optarg, 4, LX_MAX_LIGHTMAP_SIZE, &n))
                return cli_usage_error("bake", "--max-resolution must be an integer in 4..%d",
                                       LX_MAX_LIGHTMAP_SIZE);
            a->desc.max_resolution = (int)n;
            break;
        case OPT_LIGHTS:
            a->lights = optarg;
            break;
        case OPT_FORMAT:
            if (strcmp(optarg, "exr") == 0)
                a->format = LX_IMAGE_EXR;
            else if (strcmp(optarg, "hdr") == 0)
                a->format = LX_IMAGE_HDR;
            else if (strcmp(optarg, "pfm") == 0)
                a->format = LX_IMAGE_PFM;
            else if (strcmp(optarg, "png") == 0)
                a->format = LX_IMAGE_PNG;
            else
                return cli_usage_error("bake", "--format must be exr, hdr, pfm or png, not '%s'",
                                       optarg);
            break;
        case OPT_PRE_EXPOSE:
            a->pre_expose = true;
            break;
        case OPT_HALF:
            a->half = true;
            break;
        case OPT_QUANTITY:
            if (strcmp(optarg, "irradiance") == 0)
                a->desc.quantity = LX_QUANTITY_IRRADIANCE;
            else if (strcmp(optarg, "radiance") == 0)
                a->desc.quantity = LX_QUANTITY_RADIANCE;
            else
                return cli_usage_error("bake",
                                       "--quantity must be irradiance or radiance, "
                                       "not '%s'",
                                       optarg);
            break;
        case OPT_AMBIENT:
            if (!cli_parse_rgb(optarg, &a->ambient))
                return cli_usage_error("bake",
                                       "--ambient must be R,G,B with finite values >= 0, "
                                       "not '%s'",
                                       optarg);
            a->has_ambient = true;
            break;
        case OPT_EXPOSURE:
            if (!cli_parse_float(optarg, -64, 64, &f))
                return cli_usage_error("bake", "--exposure must be an EV100 in -64..64, not '%s'",
                                       optarg);
            a->exposure_ev100 = f;
            a->has_exposure = true;
            break;
        case OPT_PADDING:
            if (!cli_parse_int(optarg, 0, 64, &n))
                return cli_usage_error("bake", "--padding must be an integer in 0..64, not '%s'",
                                       optarg);
            a->desc.padding = n == 0 ? LX_PADDING_NONE : (int)n;
            break;
        case OPT_THREADS:
            if (!cli_parse_int(optarg, 1, 1024, &n))
                return cli_usage_error("bake", "--threads must be an integer in 1..1024, not '%s'",
                                       optarg);
            a->desc.threads = (int)n;
            break;
        case OPT_SKIP_DEGENERATE:
            a->desc.skip_degenerate = true;
            break;
        case 'q':
            a->quiet = true;
            break;
        case 'h':
            fputs(bake_usage, stdout);
            return -1;
        case ':':
            return cli_usage_error("bake", "option '%s' needs a value", argv[optind - 1]);
        default:
            return cli_usage_error("bake", "unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind >= argc)
        return cli_usage_error("bake", "no scene given");
    if (optind + 1 < argc)
        return cli_usage_error("bake", "one scene at a time ('%s' is extra)", argv[optind + 1]);
    a->scene = argv[optind];
    if (a->half && a->format != LX_IMAGE_EXR)
        return cli_usage_error("bake", "--half applies to --format exr only");
    if (a->pre_expose && !a->has_exposure)
        return cli_usage_error("bake", "--pre-expose needs --exposure EV100");
    if (a->pre_expose && a->format == LX_IMAGE_PNG)
        return cli_usage_error("bake", "--pre-expose applies to float formats, not png");
    return 0;
}

/* Creates dir and its parents. */
static bool make_dirs(const char *dir)
{
    char *p = lx_strdup(dir);
    if (!p)
        return false;
    for (char *s = p + 1; *s; s++)
        if (*s == '/') {
            *s = '\0';
            if (mkdir(p, 0777) != 0 && errno != EEXIST) {
                free(p);
                return false;
            }
            *s = '/';
        }
    bool ok = mkdir(p, 0777) == 0 || errno == EEXIST;
    struct stat st;
    ok = ok && stat(p, &st) == 0 && S_ISDIR(st.st_mode);
    free(p);
    return ok;
}

/* A file name from a node name: path separators and control characters
 * become '_', unique among the names given so far. */
static void file_stem(const char *name, char **taken, uint32_t taken_count, char *out, size_t size)
{
    char base[200];
    size_t n = 0;
    for (const char *s = name; *s && n + 1 < sizeof base; s++) {
        unsigned char ch = (unsigned char)*s;
        base[n++] = (ch < 32 || ch == '/' || ch == '\\' || ch == ':' || ch == '*' || ch == '?' ||
                     ch == '"' || ch == '<' || ch == '>' || ch == '|')
                        ? '_'
                        : (char)ch;
    }
    base[n] = '\0';
    if (n == 0 || base[0] == '.')
        base[0] = '_';
    if (n == 0)
        base[1] = '\0';
    snprintf(out, size, "%s", base);
    for (int k = 2;; k++) {
        bool clash = false;
        for (uint32_t i = 0; i < taken_count && !clash; i++)
            clash = strcasecmp(taken[i], out) == 0;
        if (!clash)
            return;
        snprintf(out, size, "%s_%d", base, k);
    }
}

/* Luminance of a linear Rec.709 colour. */
static double luminance(const float *rgb)
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

/* The preview shows luminance: radiance as is, irradiance as the radiance of
 * a white Lambertian surface (E / pi). Auto exposure meters the average of
 * covered texels to middle grey. */
static float preview_scale(const bake_args *a)
{
    return a->desc.quantity == LX_QUANTITY_RADIANCE ? 1.0f : 1.0f / LX_PI;
}

static double auto_ev100(const lx_baker *b, const lx_image *images, const bake_args *a)
{
    double sum = 0;
    uint64_t n = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
        const uint8_t *mask = lx_baker_mask(b, m);
        const lx_image *img = &images[m];
        for (size_t p = 0; p < (size_t)img->width * img->height; p++)
            if (mask[p]) {
                sum += luminance(&img->data[3 * p]) * preview_scale(a);
                n++;
            }
    }
    return n ? lx_ev100_from_luminance(sum / (double)n) : 0.0;
}

static cJSON *manifest_entry(const lx_scene *scene, const lx_lightmap_info *info, const char *file,
                             const char *preview, lx_quantity quantity)
{
    cJSON *e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "node", info->name);
    const lx_node *node = &scene->nodes[info->node];
    /* the node's meshes: one name, or a list when assimp split primitives */
    if (node->mesh_count == 1) {
        cJSON_AddStringToObject(e, "mesh", scene->meshes[node->meshes[0]].name);
    } else {
        cJSON *arr = cJSON_AddArrayToObject(e, "mesh");
        for (uint32_t k = 0; k < node->mesh_count; k++)
            cJSON_AddItemToArray(arr, cJSON_CreateString(scene->meshes[node->meshes[k]].name));
    }
    cJSON_AddStringToObject(e, "file", file);
    if (preview)
        cJSON_AddStringToObject(e, "preview", preview);
    cJSON_AddNumberToObject(e, "width", info->width);
    cJSON_AddNumberToObject(e, "height", info->height);
    cJSON_AddStringToObject(e, "uv_set", info->uv_set == 1 ? "TEXCOORD_1" : "TEXCOORD_0");
    cJSON_AddStringToObject(e, "quantity",
                            quantity == LX_QUANTITY_RADIANCE ? "radiance" : "irradiance");
    cJSON_AddStringToObject(e, "unit", quantity == LX_QUANTITY_RADIANCE ? "nt" : "lx");
    cJSON_AddNumberToObject(e, "used_texels", info->used_texels);
    if (info->overlap_texels)
        cJSON_AddNumberToObject(e, "overlapping_texels", info->overlap_texels);
    return e;
}

static lx_status write_text(const char *path, const char *text)
{
    lx_out_file f;
    lx_status st = lx_out_open(&f, path);
    if (st != LX_OK)
        return st;
    fputs(text, (FILE *)f.fp);
    return lx_out_commit(&f);
}

/* ---- staged output ------------------------------------------------------ */

typedef struct staging {
    char *dir;     /* DIR/.luxel- and six random characters (mkdtemp) */
    char **names;  /* files written into it */
    uint32_t count;
} staging;

static char *make_staging(const char *output)
{
    /* mkdtemp's template: six X at the end that it replaces */
    char name[16] = ".luxel-";
    memset(name + 7, 'X', 6);
    char *dir = lx_path_join(output, name);
    if (dir && !mkdtemp(dir)) {
        free(dir);
        return NULL;
    }
    return dir;
}

/* Reports an error from a staged write under the final folder's name. */
static void stage_error(const staging *st, const char *output)
{
    const char *msg = lx_last_error();
    size_t n = strlen(st->dir);
    if (strncmp(msg, st->dir, n) == 0)
        cli_error("%s%s", output, msg + n);
    else
        cli_error("%s", msg);
}

static bool stage_add(staging *st, const char *name)
{
    char **names = realloc(st->names, sizeof(char *) * (st->count + 1));
    if (!names)
        return false;
    st->names = names;
    st->names[st->count] = lx_strdup(name);
    if (!st->names[st->count])
        return false;
    st->count++;
    return true;
}

static bool stage_image(staging *st, const char *output, const char *name, const lx_image *img,
                        const lx_image_write_desc *desc)
{
    char *path = lx_path_join(st->dir, name);
    if (!path) {
        cli_error("out of memory");
        return false;
    }
    /* tracked before it exists: an interrupt right after the rename that
     * completes the file still finds it */
    cli_track_output(path);
    lx_status s = lx_image_write(path, img, desc);
    free(path);
    if (s != LX_OK) {
        stage_error(st, output);
        return false;
    }
    return stage_add(st, name);
}

static bool stage_text(staging *st, const char *output, const char *name, const char *text)
{
    char *path = lx_path_join(st->dir, name);
    if (!path) {
        cli_error("out of memory");
        return false;
    }
    cli_track_output(path);
    lx_status s = write_text(path, text);
    free(path);
    if (s != LX_OK) {
        stage_error(st, output);
        return false;
    }
    return stage_add(st, name);
}

/* Moves every staged file into the output folder, with interrupts held
 * off so the move is not cut in half. */
static bool publish(staging *st, const char *output)
{
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigprocmask(SIG_BLOCK, &block, &old);
    bool ok = true;
    /* anything but a file in the way would fail its rename half-way through */
    for (uint32_t i = 0; i < st->count && ok; i++) {
        char *to = lx_path_join(output, st->names[i]);
        struct stat sb;
        if (!to || (lstat(to, &sb) == 0 && !S_ISREG(sb.st_mode))) {
            cli_error("%s: cannot write: something that is not a file is in the way",
                      to ? to : output);
            ok = false;
        }
        free(to);
    }
    uint32_t moved = 0;
    for (uint32_t i = 0; i < st->count && ok; i++) {
        char *from = lx_path_join(st->dir, st->names[i]);
        char *to = lx_path_join(output, st->names[i]);
        if (!from || !to || rename(from, to) != 0) {
            cli_error("%s: cannot move into place: %s", to ? to : output, strerror(errno));
            ok = false;
        }
        free(from);
        free(to);
        moved += ok;
    }
    /* a rename that failed anyway: this run's files do not stay half-published */
    for (uint32_t i = 0; i < moved && !ok; i++) {
        char *to = lx_path_join(output, st->names[i]);
        if (to)
            unlink(to);
        free(to);
    }
    if (ok) {
        /* the run is complete: a signal held off until now must not undo it */
        cli_forget_outputs();
        cli_set_writing(false);
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
    return ok;
}

/* Removes whatever is still staged and the staging folder. */
static void stage_clear(staging *st)
{
    cli_remove_tracked_outputs();
    if (st->dir)
        rmdir(st->dir);
    cli_track_dir(NULL);
    for (uint32_t i = 0; i < st->count; i++)
        free(st->names[i]);
    free(st->names);
    free(st->dir);
    memset(st, 0, sizeof *st);
}

int cmd_bake(int argc, char **argv)
{
    bake_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;

    lx_scene *scene = NULL;
    lx_baker *baker = NULL;
    lx_image *images = NULL;
    char **stems = NULL;
    uint32_t maps = 0;
    staging stage = {0};
    int status = EXIT_FAILED;
    double t0 = cli_now();

    lx_scene_load_desc ld = {.skip_degenerate = a.desc.skip_degenerate};
    if (lx_scene_load(a.scene, &ld, &scene) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    if (a.lights && lx_lights_json_apply(scene, a.lights) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    if (a.has_ambient)
        scene->ambient = a.ambient;
    if (scene->node_count == 0) {
        cli_error("%s: the scene has no meshes to bake", a.scene);
        goto done;
    }

    cli_progress progress;
    cli_progress_init(&progress, "texel maps", a.quiet);
    a.desc.progress = cli_progress_update;
    a.desc.progress_user = &progress;
    lx_status created = lx_baker_create(scene, &a.desc, &baker);
    cli_progress_finish(&progress);
    if (created != LX_OK) {
        cli_error("%s", created == LX_ERR_CANCELLED ? "interrupted; nothing written"
                                                    : lx_last_error());
        goto done;
    }
    cli_progress_init(&progress, "bake", a.quiet);
    maps = lx_baker_lightmap_count(baker);
    if (maps == 0) {
        cli_error("%s: no mesh has UVs to bake a lightmap on", a.scene);
        goto done;
    }
    lx_status st = lx_baker_bake(baker);
    /* a scene's dynamic lights are part of its look: evaluate them once too */
    if (st == LX_OK) {
        cli_progress_init(&progress, "dynamic lights", a.quiet);
        st = lx_baker_update(baker);
    }
    cli_progress_finish(&progress);
    if (st != LX_OK) {
        cli_error("%s", st == LX_ERR_CANCELLED ? "interrupted; nothing written" : lx_last_error());
        goto done;
    }
    double t_bake = cli_now() - t0;

    images = calloc(maps, sizeof *images);
    stems = calloc(maps, sizeof *stems);
    if (!images || !stems) {
        cli_error("out of memory");
        goto done;
    }
    for (uint32_t m = 0; m < maps; m++) {
        if (lx_baker_apply_alloc(baker, m, &images[m]) != LX_OK) {
            cli_error("%s", lx_last_error());
            goto done;
        }
        char stem[256];
        file_stem(lx_baker_lightmap_info(baker, m)->name, stems, m, stem, sizeof stem);
        stems[m] = lx_strdup(stem);
    }
    double ev = a.has_exposure ? a.exposure_ev100 : auto_ev100(baker, images, &a);
    float exposure = lx_exposure_from_ev100((float)ev) * preview_scale(&a);
    /* seed 001: pre-exposed values are the quantity times 1/(1.2 * 2^EV100) */
    float pre_exposure = lx_exposure_from_ev100((float)ev);

    if (cli_interrupted()) {
        cli_error("interrupted; nothing written");
        goto done;
    }
    if (!make_dirs(a.output)) {
        cli_error("%s: cannot create the output folder: %s", a.output, strerror(errno));
        goto done;
    }
    /* Everything goes to a staging folder inside the output folder first and
     * is moved into place only when every file is written: a failure leaves
     * the folder as it was, old lightmaps included. */
    cli_set_writing(true);
    stage.dir = make_staging(a.output);
    if (!stage.dir) {
        cli_error("%s: cannot write into the output folder: %s", a.output, strerror(errno));
        cli_set_writing(false);
        goto done;
    }
    cli_track_dir(stage.dir);
    cJSON *manifest = cJSON_CreateObject();
    cJSON_AddStringToObject(manifest, "scene", a.scene);
    cJSON_AddStringToObject(manifest, "quantity",
                            a.desc.quantity == LX_QUANTITY_RADIANCE ? "radiance" : "irradiance");
    cJSON_AddStringToObject(manifest, "unit",
                            a.desc.quantity == LX_QUANTITY_RADIANCE ? "nt" : "lx");
    cJSON_AddStringToObject(manifest, "format", lx_image_format_extension(a.format));
    cJSON_AddNumberToObject(manifest, "preview_ev100", ev);
    /* values in the files are (quantity) x pre_exposure */
    cJSON_AddNumberToObject(manifest, "pre_exposure", a.pre_expose ? pre_exposure : 1.0);
    cJSON *list = cJSON_AddArrayToObject(manifest, "lightmaps");
    bool failed = false;
    for (uint32_t m = 0; m < maps && !failed; m++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(baker, m);
        char file[300], preview[300];
        snprintf(file, sizeof file, "%s.%s", stems[m], lx_image_format_extension(a.format));
        snprintf(preview, sizeof preview, "%s.png", stems[m]);
        lx_image_write_desc wd = {.format = a.format,
                                  .half = a.half,
                                  .exposure = a.format == LX_IMAGE_PNG ? exposure
                                              : a.pre_expose   ? pre_exposure
                                                               : 1.0f};
        failed = !stage_image(&stage, a.output, file, &images[m], &wd);
        bool want_preview = a.format != LX_IMAGE_PNG;
        if (!failed && want_preview) {
            lx_image_write_desc pd = {.format = LX_IMAGE_PNG, .exposure = exposure};
            failed = !stage_image(&stage, a.output, preview, &images[m], &pd);
        }
        cJSON_AddItemToArray(list, manifest_entry(scene, info, file, want_preview ? preview : NULL,
                                                  a.desc.quantity));
    }
    if (!failed) {
        char *text = cJSON_Print(manifest);
        failed = !text || !stage_text(&stage, a.output, "manifest.json", text);
        if (!text)
            cli_error("out of memory");
        free(text);
    }
    cJSON_Delete(manifest);
    if (!failed && !publish(&stage, a.output)) {
        failed = true;
    }
    stage_clear(&stage);
    if (failed) {
        cli_set_writing(false);
        goto done;
    }
    cli_set_writing(false);
    if (!a.quiet) {
        uint64_t texels = 0;
        for (uint32_t m = 0; m < maps; m++)
            texels += lx_baker_lightmap_info(baker, m)->used_texels;
        fprintf(stderr,
                "luxel: baked %u lightmaps (%llu texels, %u lights) in %.2f s; preview EV100 "
                "%.2f%s\n",
                maps, (unsigned long long)texels, scene->light_count, t_bake, ev,
                a.has_exposure ? "" : " (auto)");
        printf("%s/manifest.json\n", a.output);
    }
    status = EXIT_OK;
done:
    if (images)
        for (uint32_t m = 0; m < maps; m++)
            lx_image_free(&images[m]);
    if (stems)
        for (uint32_t m = 0; m < maps; m++)
            free(stems[m]);
    free(images);
    free(stems);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
    return status;
}
