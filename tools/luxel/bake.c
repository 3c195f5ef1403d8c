/* luxel bake: lightmaps for every node of a scene, with previews and a
 * manifest. Everything is computed before the first file is written; if a
 * write fails or the run is interrupted, this run's files are removed. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <cjson/cJSON.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *bake_usage =
    "usage: luxel bake SCENE [options]\n"
    "\n"
    "Bakes a lightmap for every node that carries a mesh of SCENE (glTF 2.0\n"
    ".gltf/.glb or OBJ), lit by the scene's KHR_lights_punctual lights and\n"
    "those of --lights. Nodes whose lightmap UVs are missing or unusable get\n"
    "UVs made by luxel, packed with the others into shared atlas pages:\n"
    "DIR/lightmap-<k>.<format>; a scene whose own UVs all serve keeps a\n"
    "lightmap per node, DIR/<node>.<format>. Each has a PNG preview, and\n"
    "DIR/manifest.json says where every node's lightmap is (docs/manifest.md).\n"
    "Something must emit light: lights in the file or --lights, --sky or\n"
    "--ambient; a bake without, or whose lightmaps cover no texel, fails.\n"
    "\n"
    "options:\n"
    "  -o, --output DIR        output folder (default ./lightmaps)\n"
    "  --resolution N          texels per side of every lightmap (default %d), or\n"
    "                          of the atlas page to fill (default %d)\n"
    "  --texel-density T       texels per metre instead: each lightmap sized from\n"
    "                          its world and UV areas, a multiple of 4\n"
    "  --max-resolution N      cap for --texel-density sizes (default %d)\n"
    "  --lights FILE.json      lights and settings added to or overriding the\n"
    "                          scene's (docs/lights-json.md)\n"
    "  --format F              exr (default), hdr, pfm or png\n"
    "  --half                  EXR with 16-bit half floats\n"
    "  --pre-expose            store values times the exposure of --exposure, or\n"
    "                          of the metered EV100 without it (Filament's\n"
    "                          pre-exposure: sun-lit scenes fit in half floats);\n"
    "                          the manifest records the factor\n"
    "  --quantity Q            irradiance (lux) or radiance (nits: irradiance x\n"
    "                          base colour / pi); default %s\n"
    "  --ambient L|R,G,B       constant ambient illuminance in lux: one value for\n"
    "                          white, or a colour (const:L and const:R,G,B too)\n"
    "  --sky ENV               light by an environment (equirect, cross or\n"
    "                          <name>_px.<ext> faces, radiance in nits, or\n"
    "                          const:R,G,B; see docs/ibl.md), unshadowed through\n"
    "                          its spherical harmonics\n"
    "  --sky-intensity X       multiplier on the sky, above 0 (default %g)\n"
    "  --sky-shadows           sky visibility: cosine-weighted rays that escape\n"
    "                          the scene bring the environment they see\n"
    "  --no-sky-shadows        unshadowed sky even when the lights file asks\n"
    "                          for shadows\n"
    "  --sky-samples N         rays per texel with sky shadows (default %u)\n"
    "  --bounces N             indirect diffuse bounces, 0..%d; 0 bakes direct\n"
    "                          light only (default %d)\n"
    "  --gi-samples N          gather rays per texel per bounce (default %u)\n"
    "  --emissive-scale X      multiplier on emissive materials' radiance (nits),\n"
    "                          for files not authored in physical units\n"
    "                          (default 1); emitters light through the bounces\n"
    "  --denoise M             indirect (default): the bounces' light filtered by\n"
    "                          an edge-aware denoiser (docs/denoise.md); all: the\n"
    "                          whole lightmap (area-light and sky noise too); off\n"
    "  --no-stitch             leave UV seams as baked (default: the texels on both\n"
    "                          sides of a seam are solved to agree, so no line\n"
    "                          shows where a surface crosses charts)\n"
    "  --ao                    also an ambient-occlusion map per lightmap,\n"
    "                          DIR/<name>_ao.png (grey, linear: 1 open, 0 closed)\n"
    "  --ao-distance D         metres within which surfaces occlude (default %g)\n"
    "  --ao-samples N          AO rays per texel (default %u)\n"
    "  --exposure EV100        exposure of the PNG preview (default: automatic)\n"
    "  --tonemap C             tone curve of the PNG preview: filmic (default),\n"
    "                          aces or clamp\n"
    "  --clean                 remove the files an earlier bake left in DIR that\n"
    "                          this one does not write (only those its manifest\n"
    "                          lists)\n"
    "  --padding N             texels of dilation around charts, 0 for none\n"
    "                          (default %d); charts luxel packs own as many\n"
    "  --unwrap MODE           auto (default): make lightmap UVs for the nodes\n"
    "                          whose UVs are missing, outside [0,1], have\n"
    "                          zero-area triangles or overlap on more than 1%%\n"
    "                          of their texels (see luxel info); always; or never\n"
    "  --uv-set S              the lightmap UV set: 0, 1 or auto (default: 1 when\n"
    "                          every mesh of a node has TEXCOORD_1, else 0)\n"
    "  --atlas, --no-atlas     share pages between nodes, or a lightmap per node\n"
    "                          (default: pages whenever luxel makes UVs)\n"
    "  --atlas-size N          largest atlas page side (default %d)\n"
    "  --render                also DIR/view.png: the scene with its lightmaps from\n"
    "                          the default camera (luxel render)\n"
    "  --threads N             worker threads (default: all cores)\n"
    "  --memory-limit SIZE     memory the bake may take, e.g. 512M or 4G (default:\n"
    "                          what the machine has: RAM, control group, ulimit);\n"
    "                          lightmaps that do not fit together are baked in\n"
    "                          tiles, to the same bytes (docs/bake.md)\n"
    "  --skip-degenerate       accepted for old scripts: zero-area triangles are\n"
    "                          always left out with a warning\n"
    "  --strict                fail on any warning (suspect units, tiny spot\n"
    "                          cones, unusable UVs...) instead of baking\n"
    "  -v, --verbose           the time of each phase, and notes\n"
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
    OPT_RENDER,
    OPT_TONEMAP,
    OPT_CLEAN,
    OPT_STRICT,
    OPT_BOUNCES,
    OPT_GI_SAMPLES,
    OPT_EMISSIVE_SCALE,
    OPT_NO_STITCH,
    OPT_DENOISE,
    OPT_AO,
    OPT_AO_DISTANCE,
    OPT_AO_SAMPLES,
    OPT_MEMORY_LIMIT
};

typedef enum unwrap_choice { UNWRAP_AUTO, UNWRAP_ALWAYS, UNWRAP_NEVER } unwrap_choice;

/* The page an atlas fills when neither --resolution nor --texel-density
 * sizes it: the CLI's own choice (a lightmap per node keeps the library's
 * resolution). */
#define CLI_ATLAS_RESOLUTION 1024

/* The largest bitmap a node's own UVs are checked on (lx_uv_health): the
 * overlapped share hardly changes with the size, the time grows with it. */
#define CLI_HEALTH_SIZE 256

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
    bool strict;          /* warnings fail the run */
    const char *sky;      /* --sky, else the lights JSON's */
    double sky_intensity; /* < 0: not given */
    int sky_shadows;      /* 1 on, 0 off, -1 not given */
    long sky_samples;     /* 0: not given */
    bool has_resolution;
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

/* --ambient: lux as L (white) or R,G,B, optionally written const:... as an
 * environment's constant is. */
static bool parse_ambient(const char *s, lx_vec3 *out)
{
    double l;
    if (strncmp(s, "const:", 6) == 0)
        s += 6;
    if (cli_parse_rgb(s, out))
        return true;
    if (!cli_parse_float(s, 0.0, 3.4e38, &l))
        return false;
    *out = lx_v3((float)l, (float)l, (float)l);
    return true;
}

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
        {"threads", required_argument, NULL, CLI_OPT_THREADS},
        {"skip-degenerate", no_argument, NULL, OPT_SKIP_DEGENERATE},
        {"sky", required_argument, NULL, OPT_SKY},
        {"sky-intensity", required_argument, NULL, OPT_SKY_INTENSITY},
        {"sky-shadows", no_argument, NULL, OPT_SKY_SHADOWS},
        {"no-sky-shadows", no_argument, NULL, OPT_NO_SKY_SHADOWS},
        {"sky-samples", required_argument, NULL, OPT_SKY_SAMPLES},
        {"unwrap", required_argument, NULL, OPT_UNWRAP},
        {"uv-set", required_argument, NULL, OPT_UV_SET},
        {"atlas", no_argument, NULL, OPT_ATLAS},
        {"no-atlas", no_argument, NULL, OPT_NO_ATLAS},
        {"atlas-size", required_argument, NULL, OPT_ATLAS_SIZE},
        {"render", no_argument, NULL, OPT_RENDER},
        {"tonemap", required_argument, NULL, OPT_TONEMAP},
        {"clean", no_argument, NULL, OPT_CLEAN},
        {"strict", no_argument, NULL, OPT_STRICT},
        {"bounces", required_argument, NULL, OPT_BOUNCES},
        {"gi-samples", required_argument, NULL, OPT_GI_SAMPLES},
        {"emissive-scale", required_argument, NULL, OPT_EMISSIVE_SCALE},
        {"no-stitch", no_argument, NULL, OPT_NO_STITCH},
        {"denoise", required_argument, NULL, OPT_DENOISE},
        {"ao", no_argument, NULL, OPT_AO},
        {"ao-distance", required_argument, NULL, OPT_AO_DISTANCE},
        {"ao-samples", required_argument, NULL, OPT_AO_SAMPLES},
        {"memory-limit", required_argument, NULL, OPT_MEMORY_LIMIT},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->desc = lx_bake_desc_defaults(NULL);
    a->desc.padding = LX_PADDING_RECOMMENDED;
    a->desc.stitch_seams = true;
    a->desc.denoise = LX_DENOISE_INDIRECT;
    a->desc.bounces = LX_BOUNCES_RECOMMENDED;
    a->output = "lightmaps";
    a->format = LX_IMAGE_EXR;
    a->sky_intensity = -1.0;
    a->sky_shadows = -1;
    a->atlas = -1;
    a->tonemap = CLI_PREVIEW_TONEMAP;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case 'o':
            if (!*optarg)
                return cli_usage_error("bake", "-o needs a folder name");
            a->output = optarg;
            break;
        case OPT_RESOLUTION:
            if (!cli_parse_int(optarg, 1, LX_MAX_LIGHTMAP_SIZE, &n))
                return cli_usage_error("bake", "--resolution must be an integer in 1..%d, not '%s'",
                                       LX_MAX_LIGHTMAP_SIZE, optarg);
            a->desc.resolution = (int)n;
            a->has_resolution = true;
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
            if (!cli_parse_format(optarg, &a->format))
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
            if (!parse_ambient(optarg, &a->ambient))
                return cli_usage_error("bake",
                                       "--ambient must be lux as L or R,G,B (or const:L, "
                                       "const:R,G,B) with finite values >= 0, not '%s'",
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
            a->desc.padding = (int)n;
            break;
        case OPT_SKIP_DEGENERATE: /* the default now */
            break;
        case OPT_SKY:
            a->sky = optarg;
            break;
        case OPT_SKY_INTENSITY:
            if (!cli_parse_float(optarg, 1e-30, 1e30, &f))
                return cli_usage_error("bake", "--sky-intensity must be a number above 0, not '%s'",
                                       optarg);
            a->sky_intensity = f;
            break;
        case OPT_SKY_SHADOWS:
        case OPT_NO_SKY_SHADOWS:
            if (a->sky_shadows >= 0 && a->sky_shadows != (c == OPT_SKY_SHADOWS))
                return cli_usage_error("bake", "--sky-shadows and --no-sky-shadows contradict");
            a->sky_shadows = c == OPT_SKY_SHADOWS;
            break;
        case OPT_SKY_SAMPLES:
            if (!cli_parse_int(optarg, 1, (long)LX_MAX_SKY_SAMPLES, &n))
                return cli_usage_error("bake",
                                       "--sky-samples must be an integer in 1..%u, not '%s'",
                                       LX_MAX_SKY_SAMPLES, optarg);
            a->sky_samples = n;
            break;
        case OPT_UNWRAP:
            if (strcmp(optarg, "auto") == 0)
                a->unwrap = UNWRAP_AUTO;
            else if (strcmp(optarg, "always") == 0)
                a->unwrap = UNWRAP_ALWAYS;
            else if (strcmp(optarg, "never") == 0)
                a->unwrap = UNWRAP_NEVER;
            else
                return cli_usage_error("bake", "--unwrap must be auto, always or never, not '%s'",
                                       optarg);
            break;
        case OPT_UV_SET:
            if (strcmp(optarg, "auto") == 0)
                a->desc.uv_set = LX_UV_SET_AUTO;
            else if (strcmp(optarg, "0") == 0)
                a->desc.uv_set = LX_UV_SET_0;
            else if (strcmp(optarg, "1") == 0)
                a->desc.uv_set = LX_UV_SET_1;
            else
                return cli_usage_error("bake", "--uv-set must be 0, 1 or auto, not '%s'", optarg);
            break;
        case OPT_ATLAS:
        case OPT_NO_ATLAS:
            if (a->atlas >= 0 && a->atlas != (c == OPT_ATLAS))
                return cli_usage_error("bake", "--atlas and --no-atlas contradict");
            a->atlas = c == OPT_ATLAS;
            break;
        case OPT_ATLAS_SIZE:
            if (!cli_parse_int(optarg, 4, LX_UNWRAP_MAX_ATLAS_SIZE, &n))
                return cli_usage_error("bake", "--atlas-size must be an integer in 4..%d, not '%s'",
                                       LX_UNWRAP_MAX_ATLAS_SIZE, optarg);
            a->atlas_size = (int)n;
            break;
        case OPT_RENDER:
            a->render = true;
            break;
        case OPT_TONEMAP:
            if (!lx_tonemap_parse(optarg, &a->tonemap))
                return cli_usage_error("bake", "--tonemap must be filmic, aces or clamp, not '%s'",
                                       optarg);
            break;
        case OPT_CLEAN:
            a->clean = true;
            break;
        case OPT_BOUNCES:
            if (!cli_parse_int(optarg, 0, LX_MAX_BOUNCES, &n))
                return cli_usage_error("bake", "--bounces must be an integer in 0..%d, not '%s'",
                                       LX_MAX_BOUNCES, optarg);
            a->desc.bounces = (int)n;
            break;
        case OPT_DENOISE:
            if (!lx_denoise_mode_parse(optarg, &a->desc.denoise))
                return cli_usage_error("bake", "--denoise must be off, indirect or all, not '%s'",
                                       optarg);
            break;
        case OPT_NO_STITCH:
            a->desc.stitch_seams = false;
            break;
        case OPT_AO:
            a->ao = true;
            break;
        case OPT_AO_DISTANCE:
            if (!cli_parse_float(optarg, 1e-6, 1e6, &f))
                return cli_usage_error("bake", "--ao-distance must be metres in 1e-6..1e6, not '%s'",
                                       optarg);
            a->ao_desc.distance = (float)f;
            a->ao_option = "--ao-distance";
            break;
        case OPT_AO_SAMPLES:
            if (!cli_parse_int(optarg, 1, (long)LX_MAX_AO_SAMPLES, &n))
                return cli_usage_error("bake", "--ao-samples must be an integer in 1..%u, not '%s'",
                                       LX_MAX_AO_SAMPLES, optarg);
            a->ao_desc.samples = (uint32_t)n;
            a->ao_option = "--ao-samples";
            break;
        case OPT_MEMORY_LIMIT:
            if (!cli_parse_size(optarg, &a->desc.memory_limit))
                return cli_usage_error("bake",
                                       "--memory-limit must be a size such as 512M or 4G, not '%s'",
                                       optarg);
            break;
        case OPT_GI_SAMPLES:
            if (!cli_parse_int(optarg, 1, (long)LX_MAX_GI_SAMPLES, &n))
                return cli_usage_error("bake", "--gi-samples must be an integer in 1..%u, not '%s'",
                                       LX_MAX_GI_SAMPLES, optarg);
            a->desc.gi_samples = (uint32_t)n;
            break;
        case OPT_EMISSIVE_SCALE:
            if (!cli_parse_float(optarg, 1e-30, 1e30, &f))
                return cli_usage_error("bake",
                                       "--emissive-scale must be a number above 0, not '%s'",
                                       optarg);
            a->desc.emissive_scale = (float)f;
            break;
        case OPT_STRICT:
            a->strict = true;
            a->desc.strict = true; /* zero-area triangles refused, in space and in UV */
            cli_set_strict(true);
            break;
        case 'h': {
            /* the defaults shown are the library's */
            lx_bake_desc d = lx_bake_desc_defaults(NULL);
            lx_unwrap_desc u = lx_unwrap_desc_defaults(NULL);
            printf(bake_usage, d.resolution, CLI_ATLAS_RESOLUTION, d.max_resolution,
                   d.quantity == LX_QUANTITY_RADIANCE ? "radiance" : "irradiance",
                   (double)d.sky.intensity, d.sky.samples, LX_MAX_BOUNCES,
                   LX_BOUNCES_RECOMMENDED, d.gi_samples, (double)LX_AO_DISTANCE_DEFAULT,
                   LX_AO_SAMPLES_DEFAULT, LX_PADDING_RECOMMENDED, u.atlas_size);
            return -1;
        }
        default: {
            int rc = cli_common_option("bake", c, argv, &a->desc.threads, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    if (optind >= argc)
        return cli_usage_error("bake", "no scene given");
    if (optind + 1 < argc)
        return cli_usage_error("bake", "one scene at a time ('%s' is extra)", argv[optind + 1]);
    a->scene = argv[optind];
    if (a->half && a->format != LX_IMAGE_EXR)
        return cli_usage_error("bake", "--half applies to --format exr only");
    if (a->has_resolution && a->desc.texel_density > 0.0f)
        return cli_usage_error("bake", "--resolution and --texel-density both size the "
                                       "lightmaps: give one");
    if (a->atlas_size && a->atlas == 0)
        return cli_usage_error("bake", "--atlas-size needs atlas pages, not --no-atlas");
    if (a->pre_expose && a->format == LX_IMAGE_PNG)
        return cli_usage_error("bake", "--pre-expose applies to float formats, not png");
    if (a->ao_option && !a->ao)
        return cli_usage_error("bake", "%s needs --ao", a->ao_option);
    return 0;
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

/* The preview shows luminance: radiance as is, irradiance as the radiance of
 * a white Lambertian surface (E / pi). */
static float preview_scale(const bake_args *a)
{
    return a->desc.quantity == LX_QUANTITY_RADIANCE ? 1.0f : 1.0f / LX_PI;
}

static cJSON *page_entry(const lx_lightmap_info *info, const char *file, const char *preview,
                         const char *ao)
{
    cJSON *e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "file", file);
    if (preview)
        cJSON_AddStringToObject(e, "preview", preview);
    if (ao)
        cJSON_AddStringToObject(e, "ao", ao);
    cJSON_AddNumberToObject(e, "width", info->width);
    cJSON_AddNumberToObject(e, "height", info->height);
    cJSON_AddNumberToObject(e, "used_texels", info->used_texels);
    cJSON_AddNumberToObject(e, "overlap_texels", info->overlap_texels);
    return e;
}

/* Every node with a lightmap: its meshes, page, scale/offset, UV set and
 * whose UVs they are (docs/manifest.md). */
static cJSON *node_entries(const lx_scene *scene, const lx_baker *baker, const lx_unwrap *unwrap,
                           const bake_args *a)
{
    cJSON *list = cJSON_CreateArray();
    for (uint32_t n = 0; n < scene->node_count; n++) {
        uint32_t page;
        float so[4];
        if (!lx_baker_node_lightmap(baker, n, &page, so))
            continue;
        const lx_node *node = &scene->nodes[n];
        cJSON *e = cJSON_CreateObject();
        cJSON_AddStringToObject(e, "node", node->name);
        cJSON *meshes = cJSON_AddArrayToObject(e, "meshes");
        for (uint32_t k = 0; k < node->mesh_count; k++)
            cJSON_AddItemToArray(meshes, cJSON_CreateString(scene->meshes[node->meshes[k]].name));
        cJSON_AddNumberToObject(e, "page", page);
        cJSON *sov = cJSON_AddArrayToObject(e, "scale_offset");
        for (int k = 0; k < 4; k++)
            cJSON_AddItemToArray(sov, cJSON_CreateNumber(so[k]));
        bool generated = unwrap && unwrap->nodes[n].mode == LX_UNWRAP_GENERATE;
        int set = generated ? 1
                  : unwrap  ? unwrap->nodes[n].uv_set
                            : lx_bake_uv_set(scene, n, a->desc.uv_set);
        cJSON_AddStringToObject(e, "uv_set", set == 1 ? "TEXCOORD_1" : "TEXCOORD_0");
        cJSON_AddStringToObject(e, "uvs", generated ? "generated" : "own");
        cJSON_AddItemToArray(list, e);
    }
    return list;
}

/* True when every mesh of node n has UV set `set`. */
static bool has_uv_set(const lx_scene *scene, uint32_t n, int set)
{
    const lx_node *node = &scene->nodes[n];
    for (uint32_t k = 0; k < node->mesh_count; k++)
        if (!scene->meshes[node->meshes[k]].uv[set])
            return false;
    return true;
}

/* World-space surface area of node n. */
static double node_area(const lx_scene *scene, uint32_t n)
{
    const lx_node *node = &scene->nodes[n];
    double area = 0.0;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *m = &scene->meshes[node->meshes[k]];
        for (uint32_t t = 0; t < m->triangle_count; t++) {
            const uint32_t *i = &m->indices[3 * t];
            lx_vec3 p = lx_mat4_point(&node->world, m->positions[i[0]]);
            lx_vec3 q = lx_mat4_point(&node->world, m->positions[i[1]]);
            lx_vec3 r = lx_mat4_point(&node->world, m->positions[i[2]]);
            area += 0.5 * lx_length(lx_cross(lx_sub(q, p), lx_sub(r, p)));
        }
    }
    return area;
}

/* Warnings for units that look wrong: a scene smaller than 5 cm or larger
 * than 10 km, a node that gets fewer than 8x8 texels at --texel-density,
 * a scene only a few texels across at the unwrapper's density. */
static void check_scale(const bake_args *a, const lx_scene *scene, const lx_unwrap *unwrap)
{
    lx_vec3 lo, hi;
    if (!lx_scene_bounds(scene, &lo, &hi))
        return;
    lx_vec3 e = lx_sub(hi, lo);
    double size = fmax(e.x, fmax(e.y, e.z)), total = 0.0, smallest = INFINITY;
    uint32_t small = 0, which = 0;
    float density = a->desc.texel_density;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        double area = node_area(scene, n);
        total += area;
        if (density > 0.0f && area > 0.0 && area * density * density < 64.0) {
            small++;
            if (area < smallest) {
                smallest = area;
                which = n;
            }
        }
    }
    bool warned = false;
    if (size < 0.05 || size > 1e4) {
        lx_log(LX_LOG_WARN,
               "%s: the scene spans %.3g x %.3g x %.3g m, bounds (%.4g, %.4g, %.4g) .. (%.4g, "
               "%.4g, %.4g): %s than %s; are its units metres? (--texel-density %.3g gives it "
               "about a 1024x1024 page)",
               a->scene, (double)e.x, (double)e.y, (double)e.z, (double)lo.x, (double)lo.y,
               (double)lo.z, (double)hi.x, (double)hi.y, (double)hi.z,
               size < 0.05 ? "smaller" : "larger", size < 0.05 ? "5 cm" : "10 km",
               total > 0.0 ? 1024.0 / sqrt(total) : 1.0);
        warned = true;
    }
    if (small) {
        double side = sqrt(smallest) * density;
        lx_log(LX_LOG_WARN,
               "%s: at %g texels/m node '%s' gets about %.2g x %.2g texels (%u node%s under "
               "8x8): are the scene's units metres? --texel-density %.3g would give it 8x8",
               a->scene, (double)density, scene->nodes[which].name, side, side, small,
               small == 1 ? "" : "s", 8.0 / sqrt(smallest));
        warned = true;
    }
    if (!warned && unwrap && density <= 0.0f) {
        double across = lx_length(e) * unwrap->texel_density;
        if (across < 16.0)
            lx_log(LX_LOG_WARN,
                   "%s: the scene is %.3g m across: at %g texels/m it gets about %.0f "
                   "texels across; are its units metres?",
                   a->scene, (double)lx_length(e), (double)unwrap->texel_density, across);
    }
}

/* Something must emit light, or every lightmap is black: returns the
 * error's reason, or NULL when a light, the sky or an ambient does. */
static const char *nothing_emits(const lx_scene *scene, const lx_scene_sky *sky, int bounces)
{
    if (sky->environment)
        return NULL;
    /* emissive materials light through the bounces */
    for (uint32_t m = 0; m < scene->material_count && bounces > 0; m++) {
        lx_vec3 e = scene->materials[m].emissive;
        if (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f)
            return NULL;
    }
    if (scene->ambient.x > 0.0f || scene->ambient.y > 0.0f || scene->ambient.z > 0.0f)
        return NULL;
    for (uint32_t l = 0; l < scene->light_count; l++) {
        const lx_light *li = &scene->lights[l];
        bool colour = li->color.x > 0.0f || li->color.y > 0.0f || li->color.z > 0.0f;
        bool ambient = li->ambient.x > 0.0f || li->ambient.y > 0.0f || li->ambient.z > 0.0f;
        if ((li->intensity > 0.0f && colour) || ambient)
            return NULL;
    }
    return scene->light_count ? "every light has zero intensity or colour, and there is no sky "
                                "or ambient"
                              : bounces > 0 ? "the scene has no lights, no sky, no ambient and "
                                              "no emissive material"
                                            : "the scene has no lights, no sky and no ambient "
                                              "(emissive materials light through --bounces "
                                              "only)";
}

/* A spot cone under a degree is almost surely radians typed as degrees. */
static void check_spots(const bake_args *a, const lx_scene *scene)
{
    for (uint32_t l = 0; l < scene->light_count; l++) {
        const lx_light *li = &scene->lights[l];
        if (li->type == LX_LIGHT_SPOT && li->outer_angle < LX_DEG2RAD(1.0f))
            lx_log(LX_LOG_WARN,
                   "%s: spot light '%s' has a cone of %.3g degrees from its axis: radians typed "
                   "as degrees? (lights files give angles in degrees)",
                   a->scene, li->name[0] ? li->name : "-", LX_RAD2DEG(li->outer_angle));
    }
}

/* --strict: any warning so far fails the run before anything is written. */
static bool strict_failed(const bake_args *a)
{
    unsigned w = cli_warning_count();
    if (!a->strict || w == 0)
        return false;
    cli_error("%s: %u %s with --strict: nothing written", a->scene, w, cli_plural(w, "warning", "warnings"));
    return true;
}

/* Decides which nodes keep their lightmap UVs and which get luxel's, and
 * when the lightmaps share atlas pages; makes the UVs and puts them into
 * the scene. *out stays NULL when every node keeps its own lightmap. */
static int plan_lightmaps(bake_args *a, lx_scene *scene, lx_unwrap **out, bool *atlas)
{
    *out = NULL;
    uint32_t nn = scene->node_count;
    lx_unwrap_mode *modes = calloc(nn ? nn : 1, sizeof *modes);
    int *sets = calloc(nn ? nn : 1, sizeof *sets);
    if (!modes || !sets) {
        free(modes);
        free(sets);
        cli_error("out of memory");
        return EXIT_FAILED;
    }
    /* the file's UVs are judged at the size the node's lightmap would have,
     * at most CLI_HEALTH_SIZE a side */
    cli_progress progress;
    cli_progress_init(&progress, "uv health", a->quiet);
    lx_uv_health_desc hd = {
        .resolution = a->desc.resolution < CLI_HEALTH_SIZE ? a->desc.resolution : CLI_HEALTH_SIZE,
        .texel_density = a->desc.texel_density,
        .max_resolution =
            a->desc.max_resolution < CLI_HEALTH_SIZE ? a->desc.max_resolution : CLI_HEALTH_SIZE,
        .threads = a->desc.threads,
        .progress = cli_progress_update,
        .progress_user = &progress};
    uint32_t count[LX_UV_OVERLAP + 1] = {0}, generate = 0, skipped = 0;
    for (uint32_t n = 0; n < nn; n++) {
        sets[n] = lx_bake_uv_set(scene, n, a->desc.uv_set);
        lx_uv_problem why = LX_UV_OK;
        if (scene->nodes[n].mesh_count == 0) {
            modes[n] = LX_UNWRAP_SKIP;
            continue;
        }
        if (a->unwrap == UNWRAP_AUTO) {
            lx_uv_health h;
            cli_progress_part(&progress, (int)n, (int)nn);
            lx_status hs = lx_uv_health_node(scene, n, sets[n], &hd, &h);
            if (hs != LX_OK) {
                cli_progress_clear(&progress);
                free(modes);
                free(sets);
                if (hs == LX_ERR_CANCELLED)
                    cli_report_interrupt(false);
                else
                    cli_error("%s: %s", a->scene, lx_last_error());
                return EXIT_FAILED;
            }
            why = h.problem;
            if (why != LX_UV_OK)
                lx_log(LX_LOG_INFO, "%s: node '%s': TEXCOORD_%d %s", a->scene,
                       scene->nodes[n].name, sets[n], h.reason);
        } else if (!has_uv_set(scene, n, sets[n])) {
            why = LX_UV_MISSING;
        }
        if (a->unwrap == UNWRAP_ALWAYS || why != LX_UV_OK) {
            if (a->unwrap == UNWRAP_NEVER) {
                modes[n] = LX_UNWRAP_SKIP; /* missing: no lightmap */
                skipped++;
                continue;
            }
            modes[n] = LX_UNWRAP_GENERATE;
            generate++;
            count[why]++;
        } else {
            modes[n] = LX_UNWRAP_KEEP;
        }
    }
    cli_progress_finish(&progress);
    *atlas = a->atlas == 1 || (a->atlas < 0 && generate > 0);
    if (generate && a->unwrap == UNWRAP_AUTO) {
        char detail[200] = "";
        for (int r = LX_UV_MISSING, first = 1; r <= LX_UV_OVERLAP; r++)
            if (count[r]) {
                size_t len = strlen(detail);
                snprintf(detail + len, sizeof detail - len, "%s%s %u", first ? "" : ", ",
                         lx_uv_problem_name((lx_uv_problem)r), count[r]);
                first = 0;
            }
        lx_log(LX_LOG_WARN,
               "%s: %u of %u nodes have no usable TEXCOORD lightmap UVs (%s): luxel makes "
               "theirs%s (--unwrap never keeps the file's; -v names the nodes)",
               a->scene, generate, nn, detail, *atlas ? " and packs every node into atlas pages" : "");
    }
    if (skipped)
        lx_log(LX_LOG_WARN,
               "%s: %u nodes have no lightmap UVs and get no lightmap (--unwrap auto makes them)",
               a->scene, skipped);
    int status = EXIT_OK;
    if (*atlas || generate) {
        lx_unwrap_desc ud = lx_unwrap_desc_defaults(NULL);
        ud.padding = a->desc.padding;
        ud.threads = a->desc.threads;
        if (a->atlas_size)
            ud.atlas_size = a->atlas_size;
        ud.modes = modes;
        ud.keep_uv_sets = sets;
        ud.page_per_node = !*atlas;
        if (a->desc.texel_density > 0.0f)
            ud.texel_density = a->desc.texel_density;
        else
            ud.resolution = *atlas && !a->has_resolution ? CLI_ATLAS_RESOLUTION : a->desc.resolution;
        cli_progress_init(&progress, "unwrap", a->quiet);
        ud.progress = cli_progress_update;
        ud.progress_user = &progress;
        lx_status st = lx_unwrap_scene(scene, &ud, out);
        cli_progress_finish(&progress);
        if (st == LX_OK && (st = lx_unwrap_apply(scene, *out)) != LX_OK) {
            lx_unwrap_destroy(*out);
            *out = NULL;
        }
        if (st != LX_OK) {
            if (st == LX_ERR_CANCELLED)
                cli_report_interrupt(false);
            else
                cli_error("%s: %s", a->scene, lx_last_error());
            status = EXIT_FAILED;
        } else {
            const lx_unwrap *u = *out;
            lx_log(LX_LOG_INFO,
                   "unwrap: %u %s (%u cut again), %u %s, %s%% of their texels covered, "
                   "stretch %s (worst %s), %s texels/m",
                   u->stats.charts, cli_plural(u->stats.charts, "chart", "charts"),
                   u->stats.recut_charts, u->page_count, cli_plural(u->page_count, "page", "pages"),
                   cli_num_digits(100.0 * u->stats.efficiency, 3),
                   cli_num_digits(u->stats.stretch_mean, 4),
                   cli_num_digits(u->stats.stretch_max, 4), cli_num((double)u->texel_density));
            a->desc.atlas = u;
        }
    }
    free(modes);
    free(sets);
    return status;
}

/* Half floats end at 65504: a lightmap beyond it (sun-lit scenes in lux)
 * fails, saying what would fit. */
static bool half_fits(const bake_args *a, const lx_image *images, uint32_t maps, char **stems,
                      float scale)
{
    for (uint32_t m = 0; m < maps; m++) {
        const lx_image *img = &images[m];
        size_t n = (size_t)img->width * img->height * img->channels;
        float peak = 0.0f;
        for (size_t i = 0; i < n; i++)
            peak = img->data[i] * scale > peak ? img->data[i] * scale : peak;
        if (peak > 65504.0f) {
            const char *unit = a->desc.quantity == LX_QUANTITY_RADIANCE ? "nt" : "lx";
            if (a->pre_expose)
                cli_error("%s.exr: pre-exposed values reach %s, beyond the half-float range "
                          "(65504): "
                          "give a higher --exposure, or leave out --half",
                          stems[m], cli_num_digits(peak, 3));
            else
                cli_error("%s.exr: values reach %s %s, beyond the half-float range (65504): "
                          "--pre-expose "
                          "stores them times the exposure (the manifest records it), or leave "
                          "out --half for 32-bit floats",
                          stems[m], cli_num_digits(peak, 3), unit);
            return false;
        }
    }
    return true;
}

/* The earlier bake's files in the output folder that this one does not
 * write (cli_stale_find), from the stems of this bake's outputs. */
static bool find_stale(const bake_args *a, char **stems, uint32_t maps, const char *uvs_name,
                       cli_stale *out)
{
    uint32_t n = 0;
    char **names = calloc(3 * (size_t)maps + 2, sizeof *names);
    bool ok = names != NULL;
    if (ok && uvs_name[0]) /* the scene with luxel's UVs, written again */
        ok = (names[n++] = cli_strdup(uvs_name)) != NULL;
    for (uint32_t m = 0; ok && m < maps; m++) {
        char name[300];
        snprintf(name, sizeof name, "%s.%s", stems[m], lx_image_format_extension(a->format));
        ok = (names[n++] = cli_strdup(name)) != NULL;
        snprintf(name, sizeof name, "%s.png", stems[m]);
        ok = ok && (names[n++] = cli_strdup(name)) != NULL;
        snprintf(name, sizeof name, "%s_ao.png", stems[m]);
        ok = ok && (!a->ao || (names[n++] = cli_strdup(name)) != NULL);
    }
    if (!ok)
        cli_error("out of memory");
    else
        ok = cli_stale_find(a->output, a->scene, (const char *const *)names, n, out);
    for (uint32_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
    return ok;
}

int cmd_bake(int argc, char **argv)
{
    bake_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;

    lx_scene *scene = NULL;
    lx_baker *baker = NULL;
    lx_image *images = NULL, *ao_images = NULL;
    char **stems = NULL;
    uint32_t maps = 0;
    cli_stage stage = {0};
    cli_stale stale = {0};
    lx_cubemap sky_env = {0};
    lx_unwrap *unwrap = NULL;
    bool atlas = false;
    int status = EXIT_FAILED;

    /* the output folder is checked (and made) before any long work: the
     * import, the sky, the texel maps */
    if (!cli_stage_begin(&stage, a.output))
        goto done;

    lx_scene_load_desc ld = {.strict = a.desc.strict};
    if (lx_scene_load(a.scene, &ld, &scene) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    cli_phase("import");
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
    /* the sky: --sky and its options over the lights JSON's "sky" */
    lx_scene_sky sky = scene->sky;
    if (a.sky)
        sky.environment = (char *)a.sky;
    if (!sky.environment && (a.sky_shadows >= 0 || a.sky_intensity >= 0.0 || a.sky_samples)) {
        status = cli_usage_error("bake", "--sky-intensity, --sky-shadows, --no-sky-shadows and "
                                         "--sky-samples need --sky ENV (or a \"sky\" in --lights)");
        goto done;
    }
    if (sky.environment) {
        if (a.sky_intensity >= 0.0)
            sky.intensity = (float)a.sky_intensity;
        if (a.sky_shadows >= 0)
            sky.shadows = a.sky_shadows;
        if (a.sky_samples && !sky.shadows) {
            /* rays are only cast with shadows: the count would do nothing */
            status = cli_usage_error("bake", "--sky-samples needs sky shadows (--sky-shadows, or "
                                             "\"shadows\": true in the lights file)");
            goto done;
        }
        if (a.sky_samples)
            sky.samples = (uint32_t)a.sky_samples;
        /* the sky's own intensity is the baker's (lx_sky_desc): loaded as is */
        int loaded =
            cli_load_environment_run("bake", sky.environment, 0.0f, LX_SKY_ENVIRONMENT_SIZE,
                                     a.desc.threads, a.quiet, &sky_env);
        if (loaded != EXIT_OK) {
            status = loaded;
            goto done;
        }
        lx_sky_desc given = {&sky_env, sky.intensity, sky.shadows, sky.samples};
        a.desc.sky = lx_sky_desc_defaults(&given);
    }
    cli_phase(sky.environment ? "lights and sky" : "lights");
    const char *dark = nothing_emits(scene, &sky, a.desc.bounces);
    if (dark) {
        cli_error("%s: nothing emits light: %s; give lights with --lights FILE.json, a sky with "
                  "--sky ENV or an ambient with --ambient R,G,B",
                  a.scene, dark);
        goto done;
    }
    check_spots(&a, scene);
    /* lightmap UVs: the file's, or luxel's where those do not serve */
    int planned = plan_lightmaps(&a, scene, &unwrap, &atlas);
    if (planned != EXIT_OK) {
        status = planned;
        goto done;
    }
    if (unwrap)
        cli_phase("unwrap");
    check_scale(&a, scene, unwrap);
    if (strict_failed(&a))
        goto done;

    /* the applied lightmaps (RGB float) and AO maps stay until written */
    a.desc.caller_bytes_per_texel = 12 + (a.ao ? 4 : 0);
    cli_progress progress;
    cli_progress_init(&progress, "texel maps", a.quiet);
    a.desc.progress = cli_progress_update;
    a.desc.progress_user = &progress;
    lx_status created = lx_baker_create(scene, &a.desc, &baker);
    cli_progress_finish(&progress); /* the texel maps and the BVH */
    lx_cubemap_free(&sky_env);
    if (created != LX_OK) {
        if (created == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        goto done;
    }
    maps = lx_baker_lightmap_count(baker);
    if (maps == 0) {
        cli_error("%s: no mesh has UVs to bake a lightmap on", a.scene);
        goto done;
    }
    /* every output's name, checked before the bake: a folder in the way of
     * one fails now, not after minutes of work */
    images = calloc(maps, sizeof *images);
    ao_images = calloc(maps, sizeof *ao_images);
    stems = calloc(maps, sizeof *stems);
    if (!images || !ao_images || !stems) {
        cli_error("out of memory");
        goto done;
    }
    for (uint32_t m = 0; m < maps; m++) {
        char stem[256], name[300];
        /* atlas pages are lightmap-<k>; a lightmap of one node is named
         * after it */
        const lx_lightmap_info *info = lx_baker_lightmap_info(baker, m);
        const char *base = !atlas && info->node != UINT32_MAX ? scene->nodes[info->node].name
                                                               : info->name;
        file_stem(base, stems, m, stem, sizeof stem);
        if (!(stems[m] = cli_strdup(stem))) {
            cli_error("out of memory");
            goto done;
        }
        snprintf(name, sizeof name, "%s.%s", stem, lx_image_format_extension(a.format));
        if (!cli_stage_check(&stage, name))
            goto done;
        snprintf(name, sizeof name, "%s.png", stem);
        if (a.format != LX_IMAGE_PNG && !cli_stage_check(&stage, name))
            goto done;
        snprintf(name, sizeof name, "%s_ao.png", stem);
        if (a.ao && !cli_stage_check(&stage, name))
            goto done;
    }
    if (!cli_stage_check(&stage, "manifest.json"))
        goto done;
    /* the scene with luxel's UVs: DIR/<scene's name>.glb */
    char uvs_name[300] = "";
    if (unwrap && unwrap->mesh_count &&
        (!cli_scene_glb_name(a.scene, uvs_name, sizeof uvs_name) ||
         !cli_stage_check(&stage, uvs_name)))
        goto done;
    /* an earlier bake's files that this one will not replace */
    if (!find_stale(&a, stems, maps, uvs_name, &stale))
        goto done;
    cli_stale_warn(&stale, a.output, a.clean);

    cli_progress_init(&progress, "bake", a.quiet);
    lx_status st = lx_baker_bake(baker);
    cli_progress_finish(&progress);
    /* a scene's dynamic lights are part of its look: evaluate them once too */
    if (st == LX_OK) {
        cli_progress_init(&progress, "dynamic lights", a.quiet);
        st = lx_baker_update(baker);
        cli_progress_finish(&progress);
    }
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        goto done;
    }

    /* the padding is long work on large maps: one bar over every map, and
     * an interrupt stops it */
    cli_progress_init(&progress, "apply", a.quiet);
    progress.phase = "apply and meter";
    for (uint32_t m = 0; m < maps; m++) {
        cli_progress_part(&progress, (int)m, (int)maps);
        if ((st = lx_baker_apply_alloc(baker, m, &images[m])) != LX_OK) {
            cli_progress_finish(&progress);
            if (st == LX_ERR_CANCELLED)
                cli_report_interrupt(false);
            else
                cli_error("%s", lx_last_error());
            goto done;
        }
    }
    if (a.ao) {
        cli_progress_init(&progress, "ambient occlusion", a.quiet);
        lx_ao_desc ad = a.ao_desc;
        ad.threads = a.desc.threads;
        ad.progress = cli_progress_update;
        ad.progress_user = &progress;
        for (uint32_t m = 0; m < maps; m++) {
            cli_progress_part(&progress, (int)m, (int)maps);
            if ((st = lx_baker_ao(baker, m, &ad, &ao_images[m])) != LX_OK) {
                cli_progress_finish(&progress);
                if (st == LX_ERR_CANCELLED)
                    cli_report_interrupt(false);
                else
                    cli_error("%s", lx_last_error());
                goto done;
            }
        }
        cli_progress_finish(&progress);
    }
    float metered;
    bool lit;
    lx_baker_meter_ev100(baker, &metered, &lit);
    if (!lit)
        lx_log(LX_LOG_WARN, "%s: every lightmap is black: nothing lights the scene%s", a.scene,
               scene->light_count ? " where it has texels" : " (it has no lights)");
    double ev = a.has_exposure ? a.exposure_ev100 : metered;
    float exposure = lx_exposure_from_ev100((float)ev) * preview_scale(&a);
    cli_progress_finish(&progress); /* the phase "apply and meter" */
    /* Filament: pre-exposed values are the quantity times 1/(1.2 * 2^EV100) */
    float pre_exposure = lx_exposure_from_ev100((float)ev);

    if (cli_interrupted()) {
        cli_report_interrupt(false);
        goto done;
    }
    if (strict_failed(&a))
        goto done;
    /* Everything goes to the staging folder first and is moved into place
     * only when every file is written: a failure leaves the folder as it
     * was, old lightmaps included. */
    cJSON *manifest = cJSON_CreateObject();
    cJSON_AddStringToObject(manifest, "scene", a.scene);
    cJSON_AddStringToObject(manifest, "quantity",
                            a.desc.quantity == LX_QUANTITY_RADIANCE ? "radiance" : "irradiance");
    cJSON_AddStringToObject(manifest, "unit",
                            a.desc.quantity == LX_QUANTITY_RADIANCE ? "nt" : "lx");
    cJSON_AddStringToObject(manifest, "format", lx_image_format_extension(a.format));
    cJSON_AddNumberToObject(manifest, "preview_ev100", ev);
    cJSON_AddStringToObject(manifest, "preview_tonemap", lx_tonemap_name(a.tonemap));
    /* values in the files are (quantity) x pre_exposure */
    cJSON_AddNumberToObject(manifest, "pre_exposure", a.pre_expose ? pre_exposure : 1.0);
    if (sky.environment) {
        cJSON *sk = cJSON_AddObjectToObject(manifest, "sky");
        cJSON_AddStringToObject(sk, "environment", sky.environment);
        cJSON_AddNumberToObject(sk, "intensity", a.desc.sky.intensity);
        cJSON_AddBoolToObject(sk, "shadows", sky.shadows);
        if (sky.shadows)
            cJSON_AddNumberToObject(sk, "samples", a.desc.sky.samples);
    }
    if (a.desc.bounces > 0) {
        cJSON *gi = cJSON_AddObjectToObject(manifest, "indirect");
        cJSON_AddNumberToObject(gi, "bounces", a.desc.bounces);
        cJSON_AddNumberToObject(gi, "gi_samples", a.desc.gi_samples);
        cJSON_AddNumberToObject(gi, "emissive_scale", a.desc.emissive_scale);
    }
    if (a.desc.texel_density > 0.0f || unwrap)
        cJSON_AddNumberToObject(manifest, "texel_density",
                                unwrap ? unwrap->texel_density : a.desc.texel_density);
    if (a.ao) {
        lx_ao_desc ad = lx_ao_desc_defaults(&a.ao_desc);
        cJSON_AddNumberToObject(manifest, "ao_distance", ad.distance);
    }
    cJSON_AddBoolToObject(manifest, "seams_stitched", a.desc.stitch_seams);
    cJSON_AddStringToObject(manifest, "denoise", lx_denoise_mode_name(a.desc.denoise));
    if (unwrap) { /* what luxel render needs to make the same UVs again */
        cJSON_AddNumberToObject(manifest, "padding", a.desc.padding);
        cJSON_AddNumberToObject(manifest, "atlas_size",
                                a.atlas_size ? a.atlas_size : lx_unwrap_desc_defaults(NULL).atlas_size);
    }
    cJSON *list = cJSON_AddArrayToObject(manifest, "pages");
    bool failed = false;
    double t_maps = 0.0, t_previews = 0.0;
    /* one bar over every file; Ctrl-C stops the file being written */
    cli_progress_init(&progress, "write", a.quiet);
    int parts = (int)maps * (a.format != LX_IMAGE_PNG ? 2 : 1), part = 0;
    for (uint32_t m = 0; m < maps && !failed; m++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(baker, m);
        char file[300], preview[300];
        snprintf(file, sizeof file, "%s.%s", stems[m], lx_image_format_extension(a.format));
        snprintf(preview, sizeof preview, "%s.png", stems[m]);
        /* a PNG lightmap is its own preview; float files hold the values
         * as they are (exposure 0, the default), or pre-exposed */
        lx_image_write_desc wd = {.format = a.format,
                                  .half = a.half,
                                  .tonemap = a.tonemap,
                                  .exposure = a.format == LX_IMAGE_PNG ? exposure
                                              : a.pre_expose           ? pre_exposure
                                                                       : 0.0f,
                                  .threads = a.desc.threads,
                                  .progress = cli_progress_update,
                                  .progress_user = &progress};
        double t = cli_now();
        cli_progress_part(&progress, part++, parts);
        /* where the library would fail on the file: the same place, with
         * what would fit named */
        failed = a.half && !half_fits(&a, &images[m], 1, &stems[m],
                                      a.pre_expose ? pre_exposure : 1.0f);
        failed = failed || !cli_stage_image(&stage, file, &images[m], &wd);
        t_maps += cli_now() - t;
        bool want_preview = a.format != LX_IMAGE_PNG;
        if (!failed && want_preview) {
            lx_image_write_desc pd = {.format = LX_IMAGE_PNG,
                                      .exposure = exposure,
                                      .tonemap = a.tonemap,
                                      .threads = a.desc.threads,
                                      .progress = cli_progress_update,
                                      .progress_user = &progress};
            t = cli_now();
            cli_progress_part(&progress, part++, parts);
            failed = !cli_stage_image(&stage, preview, &images[m], &pd);
            t_previews += cli_now() - t;
        }
        char ao_file[300];
        snprintf(ao_file, sizeof ao_file, "%s_ao.png", stems[m]);
        if (!failed && a.ao) {
            /* linear codes: occlusion is a factor, not a colour */
            lx_image_write_desc ad = {.format = LX_IMAGE_PNG, .linear = true,
                                      .threads = a.desc.threads};
            failed = !cli_stage_image(&stage, ao_file, &ao_images[m], &ad);
        }
        cJSON_AddItemToArray(list, page_entry(info, file, want_preview ? preview : NULL,
                                              a.ao ? ao_file : NULL));
    }
    cJSON_AddItemToObject(manifest, "nodes", node_entries(scene, baker, unwrap, &a));
    int with_uvs = !failed && uvs_name[0] ? cli_stage_scene_with_uvs(&stage, uvs_name, scene, unwrap)
                                          : 0;
    if (with_uvs > 0)
        cJSON_AddStringToObject(manifest, "scene_with_uvs", uvs_name);
    failed = failed || with_uvs < 0;
    /* files of earlier bakes left in place: a later --clean still finds them */
    if (stale.count && !a.clean) {
        cJSON *earlier = cJSON_AddArrayToObject(manifest, "earlier_files");
        for (uint32_t i = 0; i < stale.count; i++)
            cJSON_AddItemToArray(earlier, cJSON_CreateString(stale.names[i]));
    }
    if (!failed) {
        char *text = cJSON_Print(manifest);
        failed = !text || !cli_stage_text(&stage, "manifest.json", text);
        if (!text)
            cli_error("out of memory");
        free(text);
    }
    cli_progress_clear(&progress);
    cJSON_Delete(manifest);
    if (!failed && !cli_stage_publish(&stage))
        failed = true;
    if (failed)
        goto done;
    if (a.clean && !cli_stale_remove(&stale, a.output))
        goto done;
    char what[64];
    snprintf(what, sizeof what, "%u %s (%s)", maps,
             atlas ? cli_plural(maps, "page", "pages") : cli_plural(maps, "lightmap", "lightmaps"),
             lx_image_format_extension(a.format));
    cli_phase_part(what, t_maps);
    if (a.format != LX_IMAGE_PNG) {
        snprintf(what, sizeof what, "%u %s (png)", maps, cli_plural(maps, "preview", "previews"));
        cli_phase_part(what, t_previews);
    }
    cli_phase("write and publish");
    if (a.render && cli_render_bake(a.output, scene, a.desc.threads, a.quiet) != EXIT_OK)
        goto done;
    if (!a.quiet) {
        uint64_t texels = 0;
        for (uint32_t m = 0; m < maps; m++)
            texels += lx_baker_lightmap_info(baker, m)->used_texels;
        fprintf(
            stderr, "luxel: baked %u %s (%llu %s, %u %s) in %s s; preview EV100 %s%s, %s\n", maps,
            atlas ? cli_plural(maps, "atlas page", "atlas pages")
                  : cli_plural(maps, "lightmap", "lightmaps"),
            (unsigned long long)texels, cli_plural(texels, "texel", "texels"), scene->light_count,
            cli_plural(scene->light_count, "light", "lights"), cli_num_digits(cli_elapsed(), 3),
            cli_num_digits(ev, 3), a.has_exposure ? "" : " (auto)", lx_tonemap_name(a.tonemap));
        printf("%s/manifest.json\n", a.output);
    }
    status = EXIT_OK;
done:
    cli_stage_clear(&stage);
    cli_stale_free(&stale);
    if (images)
        for (uint32_t m = 0; m < maps; m++)
            lx_image_free(&images[m]);
    if (ao_images)
        for (uint32_t m = 0; m < maps; m++)
            lx_image_free(&ao_images[m]);
    free(ao_images);
    if (stems)
        for (uint32_t m = 0; m < maps; m++)
            free(stems[m]);
    free(images);
    free(stems);
    lx_baker_destroy(baker);
    lx_unwrap_destroy(unwrap);
    lx_cubemap_free(&sky_env);
    lx_scene_destroy(scene);
    return status;
}
