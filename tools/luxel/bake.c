/* luxel bake: lightmaps for every node of a scene, with previews and a
 * manifest. Everything is computed before the first file is written; if a
 * write fails or the run is interrupted, this run's files are removed. */
#define _XOPEN_SOURCE 700 /* realpath */
#include "bake_names.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <getopt.h>
#include <stdio.h>
#include <limits.h>
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
    "Per node (docs/bake.md, \"Per-node bake control\"): whether it casts\n"
    "shadows, gets a lightmap, takes part in bounces, and its lightmap scale,\n"
    "from glTF node extras (luxel_cast_shadows, luxel_lightmap,\n"
    "luxel_contribute_gi, luxel_lightmap_scale, luxel_sky) and the --lights\n"
    "file's \"nodes\" (by name or glob), which overrides them. An unlit mesh\n"
    "enclosing the scene is a sky dome: no shadows, no lightmap (a warning).\n"
    "\n"
    "options:\n"
    "  -o, --output DIR        output folder (default ./lightmaps)\n"
    "  --resolution N          texels per side of every lightmap, or of the atlas\n"
    "                          page to fill\n"
    "  --texel-density T       texels per metre instead: each lightmap sized from\n"
    "                          its world and UV areas, a multiple of 4 (default\n"
    "                          without either: 2^20 texels over the scene's area,\n"
    "                          at most 40 texels/m, a warning under 4; nodes\n"
    "                          without a lightmap and sky domes not counted, a\n"
    "                          backdrop at a tenth of the texels)\n"
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
    "  --gi-sampling MODE      guided (default: a quarter of the rays learn where\n"
    "                          each 8x8 texel tile's light comes from, half the\n"
    "                          rest go there) or cosine (all cosine-weighted)\n"
    "  --gi-adaptive           gather in rounds of a quarter of --gi-samples until\n"
    "                          each texel's estimate is within 2.5%% (2 to 16\n"
    "                          rounds): fewer blotches, 2-4x the bounces' time\n"
    "  --supersample N         direct light of each texel averaged over N x N\n"
    "                          points of its footprint, 1..%d (default 1): thin\n"
    "                          features, smooth hard-shadow edges; N^2 times the\n"
    "                          direct light's rays and about 37 N^2 bytes a texel\n"
    "  --edge-supersample N    only the texels a hard shadow's edge crosses get\n"
    "                          N x N points of their footprint, 0..%d; 0 or 1:\n"
    "                          off (default %d; ignored with --supersample)\n"
    "  --double-sided MODE     auto (default): a double-sided material's triangle\n"
    "                          bakes its back face when its front is closed in\n"
    "                          within a metre and its back open (a surface\n"
    "                          modelled facing away from where it is seen);\n"
    "                          front: always the front (Unity, Bakery)\n"
    "  --emissive-scale X      multiplier on emissive materials' radiance (nits),\n"
    "                          for files not authored in physical units\n"
    "                          (default 1); emitters are lights at any --bounces\n"
    "  --denoise M             indirect (default): the bounces' light and the\n"
    "                          sampled direct light (shadowed sky, soft shadows,\n"
    "                          emitters) filtered apart by an edge-aware denoiser\n"
    "                          (docs/denoise.md), exact lights untouched; all: the\n"
    "                          whole lightmap at once; off\n"
    "  --no-stitch             leave UV seams as baked (default: the texels on both\n"
    "                          sides of a seam are solved to agree, so no line\n"
    "                          shows where a surface crosses charts)\n"
    "  --ao                    also an ambient-occlusion map per lightmap,\n"
    "                          DIR/<name>_ao.png (grey, linear: 1 open, 0 closed)\n"
    "  --ao-distance D         metres within which surfaces occlude (default %g)\n"
    "  --ao-samples N          AO rays per texel (default %u)\n"
    "  --directional M         off (default); sh: L1 spherical harmonics per\n"
    "                          texel, DIR/<name>_sh0..3.<ext>; dominant: Unity's\n"
    "                          dominant direction, DIR/<name>_dir.png (normal maps\n"
    "                          are then applied at run time: docs/directional.md)\n"
    "  --exposure EV100        exposure of the PNG preview (default: automatic)\n"
    "  --tonemap C             tone curve of the PNG preview: filmic (default),\n"
    "                          aces or clamp\n"
    "  --clean                 remove the files an earlier bake left in DIR that\n"
    "                          this one does not write (only those its manifest\n"
    "                          lists), and the staging folders (.luxel-*)\n"
    "                          of runs that were killed or crashed\n"
    "  --padding N             texels of dilation around charts, 0 for none\n"
    "                          (default %d); charts luxel packs own as many\n"
    "  --unwrap MODE           auto (default): make lightmap UVs for the nodes\n"
    "                          whose UVs are missing, outside [0,1], have\n"
    "                          zero-area triangles, overlap on more than 1%%\n"
    "                          of their texels, cover under 1/8 of the square,\n"
    "                          or are pieces of a square other nodes share (a\n"
    "                          texture atlas; see luxel info); always; or never\n"
    "  --uv-set S              the lightmap UV set: 0, 1 or auto (default: 1 when\n"
    "                          every mesh of a node has TEXCOORD_1, else 0; a\n"
    "                          set above 1 luxel wrote its UVs to comes first)\n"
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
    "  --allow-any-path        read files the inputs name outside their folders\n"
    "  -h, --help              show this help\n";

/* bake's own options' codes, after the shared ones (bake_setup.h) */
enum {
    OPT_FORMAT = BAKE_OPT_OWN,
    OPT_HALF,
    OPT_PRE_EXPOSE,
    OPT_QUANTITY,
    OPT_EXPOSURE,
    OPT_RENDER,
    OPT_TONEMAP,
    OPT_CLEAN,
    OPT_SUPERSAMPLE,
    OPT_EDGE_SUPERSAMPLE,
    OPT_GI_ADAPTIVE,
    OPT_GI_SAMPLING,
    OPT_DOUBLE_SIDED,
    OPT_NO_STITCH,
    OPT_AO,
    OPT_AO_DISTANCE,
    OPT_AO_SAMPLES,
    OPT_DIRECTIONAL
};

static int parse_args(int argc, char **argv, bake_args *a)
{
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'},
        BAKE_SETUP_OPTIONS,
        {"format", required_argument, NULL, OPT_FORMAT},
        {"half", no_argument, NULL, OPT_HALF},
        {"pre-expose", no_argument, NULL, OPT_PRE_EXPOSE},
        {"quantity", required_argument, NULL, OPT_QUANTITY},
        {"exposure", required_argument, NULL, OPT_EXPOSURE},
        {"threads", required_argument, NULL, CLI_OPT_THREADS},
        {"render", no_argument, NULL, OPT_RENDER},
        {"tonemap", required_argument, NULL, OPT_TONEMAP},
        {"clean", no_argument, NULL, OPT_CLEAN},
        {"supersample", required_argument, NULL, OPT_SUPERSAMPLE},
        {"edge-supersample", required_argument, NULL, OPT_EDGE_SUPERSAMPLE},
        {"gi-adaptive", no_argument, NULL, OPT_GI_ADAPTIVE},
        {"gi-sampling", required_argument, NULL, OPT_GI_SAMPLING},
        {"double-sided", required_argument, NULL, OPT_DOUBLE_SIDED},
        {"no-stitch", no_argument, NULL, OPT_NO_STITCH},
        {"ao", no_argument, NULL, OPT_AO},
        {"ao-distance", required_argument, NULL, OPT_AO_DISTANCE},
        {"ao-samples", required_argument, NULL, OPT_AO_SAMPLES},
        {"directional", required_argument, NULL, OPT_DIRECTIONAL},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        CLI_ANY_PATH_OPTION,
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    cli_bake_args_init(a, "bake");
    a->desc.stitch_seams = true;
    a->output = "lightmaps";
    a->format = LX_IMAGE_EXR;
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
        case OPT_EXPOSURE:
            if (!cli_parse_float(optarg, -64, 64, &f))
                return cli_usage_error("bake", "--exposure must be an EV100 in -64..64, not '%s'",
                                       optarg);
            a->exposure_ev100 = f;
            a->has_exposure = true;
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
        case OPT_NO_STITCH:
            a->desc.stitch_seams = false;
            break;
        case OPT_DIRECTIONAL:
            if (strcmp(optarg, "off") == 0)
                a->desc.directional = LX_DIRECTIONAL_OFF;
            else if (strcmp(optarg, "sh") == 0)
                a->desc.directional = LX_DIRECTIONAL_SH;
            else if (strcmp(optarg, "dominant") == 0)
                a->desc.directional = LX_DIRECTIONAL_DOMINANT;
            else
                return cli_usage_error("bake",
                                       "--directional must be off, sh or dominant, not '%s'",
                                       optarg);
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
        case OPT_SUPERSAMPLE:
            if (!cli_parse_int(optarg, 1, LX_MAX_SUPERSAMPLE, &n))
                return cli_usage_error("bake", "--supersample must be an integer in 1..%d, not '%s'",
                                       LX_MAX_SUPERSAMPLE, optarg);
            a->desc.supersample = (int)n;
            break;
        case OPT_GI_ADAPTIVE:
            a->desc.gi_adaptive = true;
            break;
        case OPT_GI_SAMPLING:
            if (!strcmp(optarg, "guided"))
                a->desc.gi_sampling = LX_GI_SAMPLING_GUIDED;
            else if (!strcmp(optarg, "cosine"))
                a->desc.gi_sampling = LX_GI_SAMPLING_COSINE;
            else
                return cli_usage_error("bake", "--gi-sampling must be guided or cosine, not '%s'",
                                       optarg);
            break;
        case OPT_DOUBLE_SIDED:
            if (!strcmp(optarg, "auto"))
                a->desc.double_sided = LX_DOUBLE_SIDED_AUTO;
            else if (!strcmp(optarg, "front"))
                a->desc.double_sided = LX_DOUBLE_SIDED_FRONT;
            else
                return cli_usage_error("bake", "--double-sided must be auto or front, not '%s'",
                                       optarg);
            break;
        case OPT_EDGE_SUPERSAMPLE:
            if (!cli_parse_int(optarg, 0, LX_MAX_SUPERSAMPLE, &n))
                return cli_usage_error("bake",
                                       "--edge-supersample must be an integer in 0..%d, not '%s'",
                                       LX_MAX_SUPERSAMPLE, optarg);
            a->desc.edge_supersample = (int)n;
            break;
        case 'h': {
            /* the defaults shown are the library's */
            lx_bake_desc d = lx_bake_desc_defaults(NULL);
            lx_unwrap_desc u = lx_unwrap_desc_defaults(NULL);
            printf(bake_usage, d.max_resolution,
                   d.quantity == LX_QUANTITY_RADIANCE ? "radiance" : "irradiance",
                   (double)d.sky.intensity, d.sky.samples, LX_MAX_BOUNCES,
                   LX_BOUNCES_RECOMMENDED, d.gi_samples, LX_MAX_SUPERSAMPLE,
                   LX_MAX_SUPERSAMPLE, LX_EDGE_SUPERSAMPLE_RECOMMENDED,
                   (double)LX_AO_DISTANCE_DEFAULT,
                   LX_AO_SAMPLES_DEFAULT, LX_PADDING_RECOMMENDED, u.atlas_size);
            return -1;
        }
        default: {
            int rc = cli_bake_option(a, c, optarg);
            if (rc == CLI_BAKE_NOT_MINE)
                rc = cli_common_option("bake", c, argv, &a->desc.threads, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    int one = cli_one_scene("bake", argc, argv, &a->scene);
    if (one != 0)
        return one;
    if (a->half && a->format != LX_IMAGE_EXR)
        return cli_usage_error("bake", "--half applies to --format exr only");
    int checked = cli_bake_check_args(a);
    if (checked != 0)
        return checked;
    if (a->pre_expose && a->format == LX_IMAGE_PNG)
        return cli_usage_error("bake", "--pre-expose applies to float formats, not png");
    if (a->ao_option && !a->ao)
        return cli_usage_error("bake", "%s needs --ao", a->ao_option);
    if (a->desc.directional && a->desc.quantity == LX_QUANTITY_RADIANCE)
        return cli_usage_error("bake", "--directional keeps irradiance: it needs --quantity "
                                       "irradiance");
    return 0;
}

/* The preview shows luminance: radiance as is, irradiance as the radiance of
 * a white Lambertian surface (E / pi). */
static float preview_scale(const bake_args *a)
{
    return a->desc.quantity == LX_QUANTITY_RADIANCE ? 1.0f : 1.0f / LX_PI;
}

static cJSON *page_entry(const lx_lightmap_info *info, const char *file, const char *preview,
                         const char *ao, char sh[4][300], const char *dir)
{
    cJSON *e = cJSON_CreateObject();
    cJSON_AddStringToObject(e, "file", file);
    if (preview)
        cJSON_AddStringToObject(e, "preview", preview);
    if (ao)
        cJSON_AddStringToObject(e, "ao", ao);
    if (sh) {
        cJSON *list = cJSON_AddArrayToObject(e, "sh");
        for (int c = 0; c < 4; c++)
            cJSON_AddItemToArray(list, cJSON_CreateString(sh[c]));
    }
    if (dir)
        cJSON_AddStringToObject(e, "dir", dir);
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
        /* the set the lightmap UVs are in, as in the scene_with_uvs file */
        int set = generated ? lx_scene_lightmap_set(scene, n)
                  : unwrap  ? unwrap->nodes[n].uv_set
                            : lx_bake_uv_set(scene, n, a->desc.uv_set);
        char set_name[16];
        snprintf(set_name, sizeof set_name, "TEXCOORD_%d", set);
        cJSON_AddStringToObject(e, "uv_set", set_name);
        cJSON_AddStringToObject(e, "uvs", generated ? "generated" : "own");
        float scale = lx_node_lightmap_scale(&node->bake);
        if (scale != 1.0f)
            cJSON_AddNumberToObject(e, "lightmap_scale", scale);
        cJSON_AddItemToArray(list, e);
    }
    return list;
}

/* True when every mesh of node n has UV set `set`. */
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

/* ---- directional lightmaps (docs/directional.md) ---------------------- */

/* sh: L1 in the files as the irradiance it adds along each axis, or
 * normalized by L0 for 8-bit files */
#define SH_E0 0.886227f /* pi Y00 = sqrt(pi) / 2 */
#define SH_E1 1.023327f /* 2 pi / 3 Y1 = sqrt(pi / 3) */

/* Whether the files hold L1 normalized by L0 in [0, 1] (8-bit and RGBE
 * files, which keep no negative values) rather than as irradiance. */
static bool sh_normalized(const bake_args *a)
{
    return a->format != LX_IMAGE_EXR && a->format != LX_IMAGE_PFM;
}

/* The library's coefficients (nits) as the files hold them: sh[0] E0 =
 * pi Y00 L00 (lux), sh[1..3] either E1 = 2 pi / 3 Y1 L1 (lux, signed) or
 * r = L1 / (sqrt 3 L00) as r / 2 + 1/2 (normalized), in place. */
static void sh_encode(lx_image sh[4], bool normalized)
{
    size_t n = (size_t)sh[0].width * sh[0].height * 3;
    for (size_t i = 0; i < n; i++) {
        float l0 = sh[0].data[i];
        for (int c = 1; c < 4; c++) {
            float v = sh[c].data[i];
            if (!normalized) {
                sh[c].data[i] = v * SH_E1;
            } else {
                float r = l0 > 0.0f ? v / (1.7320508f * l0) : 0.0f;
                r = r < -1.0f ? -1.0f : (r > 1.0f ? 1.0f : r);
                sh[c].data[i] = 0.5f * r + 0.5f;
            }
        }
        sh[0].data[i] = l0 > 0.0f ? l0 * SH_E0 : 0.0f;
    }
}

int cmd_bake(int argc, char **argv)
{
    bake_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;

    lx_scene *scene = NULL;
    lx_baker *baker = NULL;
    lx_image *images = NULL, *ao_images = NULL, *dir_images = NULL;
    char **stems = NULL;
    uint32_t maps = 0;
    cli_stage stage = {0};
    cli_stale stale = {0};
    output_names names = {0};
    char uvs_name[300] = "";
    cli_progress progress;
    lx_scene_sky sky;
    lx_unwrap *unwrap = NULL;
    bool atlas = false;
    int status = EXIT_FAILED;

    /* the output folder is checked (and made) before any long work: the
     * import, the sky, the texel maps */
    if (!cli_stage_begin_set(&stage, a.output, a.clean))
        goto done;

    /* the applied lightmaps (RGB float), AO maps (grey float) and
     * directional maps (four RGB or one RGBA float) stay until written */
    a.desc.caller_bytes_per_texel = 12 + (a.ao ? 4 : 0) +
                                    (a.desc.directional == LX_DIRECTIONAL_SH        ? 48
                                     : a.desc.directional == LX_DIRECTIONAL_DOMINANT ? 16
                                                                                     : 0);
    int prepared = cli_bake_prepare(&a, &progress, &scene, &sky, &unwrap, &atlas, &baker);
    if (prepared != EXIT_OK) {
        status = prepared;
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
    dir_images = calloc((size_t)maps * DIR_FILES, sizeof *dir_images);
    stems = calloc(maps, sizeof *stems);
    if (!images || !ao_images || !dir_images || !stems) {
        cli_error("out of memory");
        goto done;
    }
    /* the scene with luxel's UVs: DIR/<scene's name>.glb */
    if (unwrap && unwrap->mesh_count && !cli_scene_glb_name(a.scene, uvs_name, sizeof uvs_name))
        goto done;
    if (!bake_plan_outputs(&a, scene, baker, atlas, uvs_name, maps, stems, &names))
        goto done;
    for (uint32_t i = 0; i < names.count; i++)
        if ((a.render || strcmp(names.names[i], "view.png") != 0) &&
            !cli_stage_check(&stage, names.names[i]))
            goto done;
    /* an earlier bake's files that this one will not replace */
    if (!bake_find_stale(&a, &names, &stale))
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
    for (uint32_t m = 0; m < maps && a.desc.directional; m++) {
        st = a.desc.directional == LX_DIRECTIONAL_SH
                 ? lx_baker_sh(baker, m, &dir_images[(size_t)m * DIR_FILES])
                 : lx_baker_dominant(baker, m, &dir_images[(size_t)m * DIR_FILES]);
        if (st != LX_OK) {
            cli_error("%s", lx_last_error());
            goto done;
        }
        if (a.desc.directional == LX_DIRECTIONAL_SH)
            sh_encode(&dir_images[(size_t)m * DIR_FILES], sh_normalized(&a));
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
    if (cli_bake_strict_failed(&a))
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
        /* absolute, so `luxel render` finds it from any directory (the
         * lights JSON's path was relative to where the bake ran) */
        char where[PATH_MAX];
        bool file = strncmp(sky.environment, "const:", 6) != 0;
        cJSON_AddStringToObject(sk, "environment",
                                file && realpath(sky.environment, where) ? where : sky.environment);
        cJSON_AddNumberToObject(sk, "intensity", a.desc.sky.intensity);
        cJSON_AddBoolToObject(sk, "shadows", sky.shadows);
        if (sky.shadows)
            cJSON_AddNumberToObject(sk, "samples", a.desc.sky.samples);
    }
    if (a.desc.bounces > 0) {
        cJSON *gi = cJSON_AddObjectToObject(manifest, "indirect");
        cJSON_AddNumberToObject(gi, "bounces", a.desc.bounces);
        cJSON_AddNumberToObject(gi, "gi_samples", a.desc.gi_samples);
        if (a.desc.gi_adaptive)
            cJSON_AddBoolToObject(gi, "gi_adaptive", true);
        cJSON_AddStringToObject(gi, "gi_sampling",
                                a.desc.gi_sampling == LX_GI_SAMPLING_COSINE ? "cosine" : "guided");
        cJSON_AddNumberToObject(gi, "emissive_scale", a.desc.emissive_scale);
    }
    if (a.desc.texel_density > 0.0f || unwrap)
        cJSON_AddNumberToObject(manifest, "texel_density",
                                unwrap ? unwrap->texel_density : a.desc.texel_density);
    if (a.ao) {
        lx_ao_desc ad = lx_ao_desc_defaults(&a.ao_desc);
        cJSON_AddNumberToObject(manifest, "ao_distance", ad.distance);
    }
    if (a.desc.supersample > 1)
        cJSON_AddNumberToObject(manifest, "supersample", a.desc.supersample);
    else if (a.desc.edge_supersample > 1)
        cJSON_AddNumberToObject(manifest, "edge_supersample", a.desc.edge_supersample);
    cJSON_AddBoolToObject(manifest, "seams_stitched", a.desc.stitch_seams);
    cJSON_AddStringToObject(manifest, "double_sided",
                            a.desc.double_sided == LX_DOUBLE_SIDED_FRONT ? "front" : "auto");
    cJSON_AddStringToObject(manifest, "denoise", lx_denoise_mode_name(a.desc.denoise));
    if (a.desc.directional) {
        cJSON *dj = cJSON_AddObjectToObject(manifest, "directional");
        bool sh = a.desc.directional == LX_DIRECTIONAL_SH;
        cJSON_AddStringToObject(dj, "mode", sh ? "sh" : "dominant");
        if (sh)
            cJSON_AddStringToObject(dj, "encoding",
                                    sh_normalized(&a) ? "normalized" : "irradiance");
    }
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
        char dn[DIR_FILES][300];
        int dk = bake_directional_names(&a, stems[m], dn);
        lx_image *di = &dir_images[(size_t)m * DIR_FILES];
        for (int j = 0; j < dk && !failed; j++) {
            /* sh0 is written as the lightmap is (its units, exposure and
             * pre-exposure); L1 as values (irradiance) or linear codes
             * (normalized); the dominant direction as linear codes */
            lx_image_write_desc dd = wd;
            dd.progress = NULL;
            if (a.desc.directional == LX_DIRECTIONAL_DOMINANT) {
                dd = (lx_image_write_desc){.format = LX_IMAGE_PNG, .linear = true,
                                           .threads = a.desc.threads};
            } else if (j > 0 && sh_normalized(&a)) {
                dd = (lx_image_write_desc){.format = a.format, .linear = true,
                                           .threads = a.desc.threads};
            }
            failed = !cli_stage_image(&stage, dn[j], &di[j], &dd);
        }
        cJSON_AddItemToArray(list,
                             page_entry(info, file, want_preview ? preview : NULL,
                                        a.ao ? ao_file : NULL,
                                        a.desc.directional == LX_DIRECTIONAL_SH ? dn : NULL,
                                        a.desc.directional == LX_DIRECTIONAL_DOMINANT ? dn[0]
                                                                                      : NULL));
    }
    cJSON_AddItemToObject(manifest, "nodes", node_entries(scene, baker, unwrap, &a));
    /* the nodes left without a lightmap by their settings: a renderer
     * binding these lightmaps to the scene file expects none for them */
    cJSON *unbaked = NULL;
    for (uint32_t n = 0; n < scene->node_count; n++)
        if (scene->nodes[n].bake.no_lightmap && scene->nodes[n].mesh_count) {
            if (!unbaked)
                unbaked = cJSON_AddArrayToObject(manifest, "nodes_without_lightmap");
            cJSON_AddItemToArray(unbaked, cJSON_CreateString(scene->nodes[n].name));
        }
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
    if (a.render)
        cJSON_AddStringToObject(manifest, "render", "view.png");
    if (!failed) {
        char *text = cJSON_Print(manifest);
        failed = !text || !cli_stage_text(&stage, "manifest.json", text);
        if (!text)
            cli_error("out of memory");
        free(text);
    }
    cli_progress_clear(&progress);
    cJSON_Delete(manifest);
    /* --render: the view of the staged lightmaps, staged with them, so that
     * view.png and the manifest are published together or not at all */
    if (!failed && a.render) {
        char *view = cli_stage_path(&stage, "view.png");
        char *shown = cli_path_join(a.output, "view.png");
        failed = !view || !shown ||
                 cli_render_bake(stage.dir, view, shown, scene, a.desc.threads, a.quiet) != EXIT_OK;
        if (view && !shown)
            cli_error("out of memory");
        free(view);
        free(shown);
    }
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
    if (!a.quiet) {
        /* the density the lightmaps were sized by, when the scene chose it */
        char density_note[64] = "";
        if (a.density_from_scene)
            snprintf(density_note, sizeof density_note, " at %s texels/m",
                     cli_num((double)(unwrap ? unwrap->texel_density : a.desc.texel_density)));
        uint64_t texels = 0;
        for (uint32_t m = 0; m < maps; m++)
            texels += lx_baker_lightmap_info(baker, m)->used_texels;
        fprintf(
            stderr, "luxel: baked %u %s (%llu %s%s, %u %s) in %s s; preview EV100 %s%s, %s\n",
            maps,
            atlas ? cli_plural(maps, "atlas page", "atlas pages")
                  : cli_plural(maps, "lightmap", "lightmaps"),
            (unsigned long long)texels, cli_plural(texels, "texel", "texels"), density_note,
            scene->light_count,
            cli_plural(scene->light_count, "light", "lights"), cli_num_digits(cli_elapsed(), 3),
            cli_num_digits(ev, 3), a.has_exposure ? "" : " (auto)", lx_tonemap_name(a.tonemap));
        if (a.render)
            printf("%s/view.png\n", a.output);
        printf("%s/manifest.json\n", a.output);
    }
    status = EXIT_OK;
done:
    cli_stage_clear(&stage);
    cli_stale_free(&stale);
    bake_output_names_free(&names);
    if (images)
        for (uint32_t m = 0; m < maps; m++)
            lx_image_free(&images[m]);
    if (ao_images)
        for (uint32_t m = 0; m < maps; m++)
            lx_image_free(&ao_images[m]);
    free(ao_images);
    if (dir_images)
        for (size_t k = 0; k < (size_t)maps * DIR_FILES; k++)
            lx_image_free(&dir_images[k]);
    free(dir_images);
    if (stems)
        for (uint32_t m = 0; m < maps; m++)
            free(stems[m]);
    free(images);
    free(stems);
    lx_baker_destroy(baker);
    lx_unwrap_destroy(unwrap);
    lx_scene_destroy(scene);
    return status;
}
