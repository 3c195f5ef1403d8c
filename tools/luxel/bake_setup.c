/* What luxel bake and luxel probes share (bake_setup.h): the scene and
 * lighting options, and the road from a scene file to a baker ready to
 * bake: import, lights JSON, sky, lightmap UVs, checks. */
#define _POSIX_C_SOURCE 200809L
#include "bake_setup.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cli_bake_args_init(bake_args *a, const char *command)
{
    memset(a, 0, sizeof *a);
    a->command = command;
    a->desc = lx_bake_desc_defaults(NULL);
    a->desc.padding = LX_PADDING_RECOMMENDED;
    a->desc.denoise = LX_DENOISE_INDIRECT;
    a->desc.bounces = LX_BOUNCES_RECOMMENDED;
    a->desc.edge_supersample = LX_EDGE_SUPERSAMPLE_RECOMMENDED;
    a->sky_intensity = -1.0;
    a->sky_shadows = -1;
    a->atlas = -1;
}

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

static bool has_uv_set(const lx_scene *scene, uint32_t n, int set)
{
    const lx_node *node = &scene->nodes[n];
    for (uint32_t k = 0; k < node->mesh_count; k++)
        if (!scene->meshes[node->meshes[k]].uv[set])
            return false;
    return true;
}

/* The texel density a bake gets when no option sizes its lightmaps: the
 * density that spends CLI_DENSITY_BUDGET texels on the world area of every
 * node with a mesh and a lightmap (not a sky dome), each node's area
 * times its lightmap scale squared (a backdrop's lowered one included),
 * at most CLI_DENSITY_MAX texels a metre (the tens of texels per metre
 * Unity's and Bakery's defaults give rooms and levels), to two
 * significant digits. A room of 200 m^2 gets the maximum; a level of
 * 10,000 m^2 about 10. The budget holds below CLI_DENSITY_MIN too (a
 * floor would let a scene in the wrong units ask for gigabytes):
 * check_scale warns there. */
double cli_default_density(const lx_scene *scene)
{
    double total = 0.0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_node_bake *b = &scene->nodes[n].bake;
        if (b->no_lightmap || b->sky)
            continue; /* no texels: a sky dome's kilometres spend none */
        double s = lx_node_lightmap_scale(b);
        total += lx_node_world_area(scene, n) * s * s;
    }
    double d = total > 0.0 ? sqrt(CLI_DENSITY_BUDGET / total) : CLI_DENSITY_MAX;
    d = d > CLI_DENSITY_MAX ? CLI_DENSITY_MAX : d;
    double scale = pow(10.0, floor(log10(d)) - 1.0);
    return floor(d / scale + 0.5) * scale;
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
        const lx_node_bake *b = &scene->nodes[n].bake;
        if (b->no_lightmap || b->sky)
            continue;
        double s = lx_node_lightmap_scale(b);
        double area = lx_node_world_area(scene, n) * s * s; /* at the density: its texels */
        total += area;
        if (density > 0.0f && !a->density_from_scene && area > 0.0 &&
            area * density * density < 64.0) {
            small++;
            if (area < smallest) {
                smallest = area;
                which = n;
            }
        }
    }
    bool warned = false;
    if (a->density_from_scene && density < CLI_DENSITY_MIN) {
        lx_log(LX_LOG_WARN,
               "%s: %.0f m^2 of lightmapped surface: the default budget of %.0f texels gives "
               "it %g texels/m (a texel every %.2g m); are its units metres? (--texel-density "
               "sets the density, a node's lightmap scale its share)",
               a->scene, total, CLI_DENSITY_BUDGET, (double)density, 1.0 / (double)density);
        warned = true;
    }
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
static const char *nothing_emits(const lx_scene *scene, const lx_scene_sky *sky)
{
    if (sky->environment)
        return NULL;
    /* emissive materials are lights (direct light at any bounce count) */
    for (uint32_t m = 0; m < scene->material_count; m++) {
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
    return scene->light_count ? "every light has zero intensity or colour, and there is no sky, "
                                "ambient or emissive material"
                              : "the scene has no lights, no sky, no ambient and "
                                "no emissive material";
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
bool cli_bake_strict_failed(const bake_args *a)
{
    unsigned w = cli_warning_count();
    if (!a->strict || w == 0)
        return false;
    cli_error("%s: %u %s with --strict: nothing written", a->scene, w,
              cli_plural(w, "warning", "warnings"));
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
    uint32_t count[LX_UV_SHARED + 1] = {0}, generate = 0, skipped = 0;
    for (uint32_t n = 0; n < nn; n++)
        sets[n] = lx_bake_uv_set(scene, n, a->desc.uv_set);
    /* pieces of a UV square several nodes share (a texture atlas) are
     * judged across the nodes; a node's own problems, but sparse, come
     * before it */
    lx_uv_share *share = NULL;
    if (a->unwrap == UNWRAP_AUTO) {
        share = calloc(nn ? nn : 1, sizeof *share);
        lx_status ss = share ? lx_uv_share_nodes(scene, sets, NULL, share) : LX_ERR_NOMEM;
        if (ss != LX_OK) {
            if (share)
                cli_error("%s: %s", a->scene, lx_last_error());
            else
                cli_error("out of memory");
            free(share);
            free(modes);
            free(sets);
            return EXIT_FAILED;
        }
    }
    uint32_t lightmapped = 0;
    for (uint32_t n = 0; n < nn; n++) {
        lx_uv_problem why = LX_UV_OK;
        if (scene->nodes[n].mesh_count == 0 || scene->nodes[n].bake.no_lightmap) {
            modes[n] = LX_UNWRAP_SKIP; /* no lightmap: its UVs do not matter */
            continue;
        }
        lightmapped++;
        if (a->unwrap == UNWRAP_AUTO) {
            lx_uv_health h;
            cli_progress_part(&progress, (int)n, (int)nn);
            lx_status hs = lx_uv_health_node(scene, n, sets[n], &hd, &h);
            if (hs != LX_OK) {
                cli_progress_clear(&progress);
                free(share);
                free(modes);
                free(sets);
                if (hs == LX_ERR_CANCELLED)
                    cli_report_interrupt(false);
                else
                    cli_error("%s: %s", a->scene, lx_last_error());
                return EXIT_FAILED;
            }
            why = h.problem;
            const char *reason = h.reason;
            /* a shared piece says more than its small coverage */
            if ((why == LX_UV_OK || why == LX_UV_SPARSE) && share[n].shared) {
                why = LX_UV_SHARED;
                reason = share[n].reason;
            }
            if (why != LX_UV_OK)
                lx_log(LX_LOG_INFO, "%s: node '%s': TEXCOORD_%d %s", a->scene, scene->nodes[n].name,
                       sets[n], reason);
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
    free(share);
    *atlas = a->atlas == 1 || (a->atlas < 0 && generate > 0);
    if (generate && a->unwrap == UNWRAP_AUTO) {
        char detail[200] = "";
        for (int r = LX_UV_MISSING, first = 1; r <= LX_UV_SHARED; r++)
            if (count[r]) {
                size_t len = strlen(detail);
                snprintf(detail + len, sizeof detail - len, "%s%s %u", first ? "" : ", ",
                         lx_uv_problem_name((lx_uv_problem)r), count[r]);
                first = 0;
            }
        lx_log(LX_LOG_WARN,
               "%s: %u of %u nodes have no usable TEXCOORD lightmap UVs (%s): luxel makes "
               "theirs%s (--unwrap never keeps the file's; -v names the nodes)",
               a->scene, generate, lightmapped, detail,
               *atlas ? " and packs every node into atlas pages" : "");
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
            ud.resolution =
                *atlas && !a->has_resolution ? CLI_ATLAS_RESOLUTION : a->desc.resolution;
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

int cli_bake_option(bake_args *a, int c, const char *optarg)
{
    long n;
    double f;
    switch (c) {
    case OPT_RESOLUTION:
        if (!cli_parse_int(optarg, 1, LX_MAX_LIGHTMAP_SIZE, &n))
            return cli_usage_error(a->command, "--resolution must be an integer in 1..%d, not '%s'",
                                   LX_MAX_LIGHTMAP_SIZE, optarg);
        a->desc.resolution = (int)n;
        a->has_resolution = true;
        break;
    case OPT_TEXEL_DENSITY:
        if (!cli_parse_float(optarg, 1e-6, 1e6, &f))
            return cli_usage_error(a->command,
                                   "--texel-density must be a positive number of "
                                   "texels per metre, not '%s'",
                                   optarg);
        a->desc.texel_density = (float)f;
        break;
    case OPT_MAX_RESOLUTION:
        if (!cli_parse_int(optarg, 4, LX_MAX_LIGHTMAP_SIZE, &n))
            return cli_usage_error(a->command, "--max-resolution must be an integer in 4..%d",
                                   LX_MAX_LIGHTMAP_SIZE);
        a->desc.max_resolution = (int)n;
        break;
    case OPT_LIGHTS:
        a->lights = optarg;
        break;
    case OPT_AMBIENT:
        if (!parse_ambient(optarg, &a->ambient))
            return cli_usage_error(a->command,
                                   "--ambient must be lux as L or R,G,B (or const:L, "
                                   "const:R,G,B) with finite values >= 0, not '%s'",
                                   optarg);
        a->has_ambient = true;
        break;
    case OPT_PADDING:
        if (!cli_parse_int(optarg, 0, 64, &n))
            return cli_usage_error(a->command, "--padding must be an integer in 0..64, not '%s'",
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
            return cli_usage_error(a->command, "--sky-intensity must be a number above 0, not '%s'",
                                   optarg);
        a->sky_intensity = f;
        break;
    case OPT_SKY_SHADOWS:
    case OPT_NO_SKY_SHADOWS:
        if (a->sky_shadows >= 0 && a->sky_shadows != (c == OPT_SKY_SHADOWS))
            return cli_usage_error(a->command, "--sky-shadows and --no-sky-shadows contradict");
        a->sky_shadows = c == OPT_SKY_SHADOWS;
        break;
    case OPT_SKY_SAMPLES:
        if (!cli_parse_int(optarg, 1, (long)LX_MAX_SKY_SAMPLES, &n))
            return cli_usage_error(a->command,
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
            return cli_usage_error(a->command, "--unwrap must be auto, always or never, not '%s'",
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
            return cli_usage_error(a->command, "--uv-set must be 0, 1 or auto, not '%s'", optarg);
        break;
    case OPT_ATLAS:
    case OPT_NO_ATLAS:
        if (a->atlas >= 0 && a->atlas != (c == OPT_ATLAS))
            return cli_usage_error(a->command, "--atlas and --no-atlas contradict");
        a->atlas = c == OPT_ATLAS;
        break;
    case OPT_ATLAS_SIZE:
        if (!cli_parse_int(optarg, 4, LX_UNWRAP_MAX_ATLAS_SIZE, &n))
            return cli_usage_error(a->command, "--atlas-size must be an integer in 4..%d, not '%s'",
                                   LX_UNWRAP_MAX_ATLAS_SIZE, optarg);
        a->atlas_size = (int)n;
        break;
    case OPT_BOUNCES:
        if (!cli_parse_int(optarg, 0, LX_MAX_BOUNCES, &n))
            return cli_usage_error(a->command, "--bounces must be an integer in 0..%d, not '%s'",
                                   LX_MAX_BOUNCES, optarg);
        a->desc.bounces = (int)n;
        break;
    case OPT_DENOISE:
        if (!lx_denoise_mode_parse(optarg, &a->desc.denoise))
            return cli_usage_error(a->command, "--denoise must be off, indirect or all, not '%s'",
                                   optarg);
        break;
    case OPT_GI_SAMPLES:
        if (!cli_parse_int(optarg, 1, (long)LX_MAX_GI_SAMPLES, &n))
            return cli_usage_error(a->command, "--gi-samples must be an integer in 1..%u, not '%s'",
                                   LX_MAX_GI_SAMPLES, optarg);
        a->desc.gi_samples = (uint32_t)n;
        break;
    case OPT_EMISSIVE_SCALE:
        if (!cli_parse_float(optarg, 1e-30, 1e30, &f))
            return cli_usage_error(a->command,
                                   "--emissive-scale must be a number above 0, not '%s'", optarg);
        a->desc.emissive_scale = (float)f;
        break;
    case OPT_MEMORY_LIMIT:
        if (!cli_parse_size(optarg, &a->desc.memory_limit))
            return cli_usage_error(a->command,
                                   "--memory-limit must be a size such as 512M or 4G, not '%s'",
                                   optarg);
        break;
    case OPT_STRICT:
        a->strict = true;
        a->desc.strict = true; /* zero-area triangles refused, in space and in UV */
        cli_set_strict(true);
        break;
    default:
        return CLI_BAKE_NOT_MINE;
    }
    return 0;
}

int cli_bake_check_args(const bake_args *a)
{
    if (a->has_resolution && a->desc.texel_density > 0.0f)
        return cli_usage_error(a->command, "--resolution and --texel-density both size the "
                                           "lightmaps: give one");
    if (a->atlas_size && a->atlas == 0)
        return cli_usage_error(a->command, "--atlas-size needs atlas pages, not --no-atlas");
    return 0;
}

/* The lightmap density a node's textures will be read at
 * (lx_scene_load_desc's texture_density_fn, called while the scene loads,
 * its geometry known and no texture decoded): --texel-density, or the
 * density the scene gets by default, or under --resolution N at most N
 * texels across the node's world area (its lightmap, or the atlas page it
 * shares, holds N x N texels). */
typedef struct texture_density_ctx {
    const bake_args *a;
    double scene_density; /* cli_default_density, once computed */
} texture_density_ctx;

static float texture_density(void *user, const lx_scene *scene, uint32_t node)
{
    texture_density_ctx *t = user;
    /* the node's own settings from its glTF extras (the lights JSON's come
     * after the load): no lightmap reads its textures at no density worth
     * keeping (the smallest size), a lightmap scale multiplies it */
    const lx_node_bake *nb = &scene->nodes[node].bake;
    if (nb->no_lightmap)
        return 1e-6f;
    float scale = lx_node_lightmap_scale(nb);
    if (t->a->desc.texel_density > 0.0f)
        return t->a->desc.texel_density * scale;
    if (t->a->has_resolution) {
        double area = lx_node_world_area(scene, node);
        return area > 0.0 ? (float)(t->a->desc.resolution / sqrt(area)) * scale : 0.0f;
    }
    if (!(t->scene_density > 0.0))
        t->scene_density = cli_default_density(scene);
    return (float)t->scene_density * scale;
}

int cli_bake_prepare(bake_args *a, cli_progress *progress, lx_scene **scene_out, lx_scene_sky *sky,
                     lx_unwrap **unwrap, bool *atlas, lx_baker **baker)
{
    memset(sky, 0, sizeof *sky);
    lx_cubemap sky_env = {0};
    int status = EXIT_FAILED;
    lx_scene *scene = NULL;
    *scene_out = NULL;
    *unwrap = NULL;
    *baker = NULL;
    *atlas = false;
    /* textures decoded no finer than the lightmaps read them */
    texture_density_ctx density = {a, 0.0};
    lx_scene_load_desc ld = {.strict = a->desc.strict,
                             .allow_any_path = cli_allow_any_path(),
                             .texture_density_fn = texture_density,
                             .texture_density_user = &density};
    if (!cli_scene_load(a->scene, &ld, &scene))
        goto done;
    *scene_out = scene;
    cli_phase("import");
    if (a->lights && lx_lights_json_apply(scene, a->lights) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    if (a->has_ambient)
        scene->ambient = a->ambient;
    if (scene->node_count == 0) {
        cli_error("%s: the scene has no meshes to bake", a->scene);
        goto done;
    }
    uint32_t with_lightmap = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        with_lightmap += !scene->nodes[n].bake.no_lightmap;
    if (with_lightmap == 0) {
        cli_error(
            "%s: every node has its lightmap turned off (luxel_lightmap extras, \"lightmap\": "
            "false in the lights JSON's \"nodes\", or sky domes): nothing to bake",
            a->scene);
        goto done;
    }
    /* the sky: --sky and its options over the lights JSON's "sky" */
    *sky = scene->sky;
    if (a->sky)
        sky->environment = (char *)a->sky;
    if (!sky->environment && (a->sky_shadows >= 0 || a->sky_intensity >= 0.0 || a->sky_samples)) {
        status =
            cli_usage_error(a->command, "--sky-intensity, --sky-shadows, --no-sky-shadows and "
                                        "--sky-samples need --sky ENV (or a \"sky\" in --lights)");
        goto done;
    }
    if (sky->environment) {
        if (a->sky_intensity >= 0.0)
            sky->intensity = (float)a->sky_intensity;
        if (a->sky_shadows >= 0)
            sky->shadows = a->sky_shadows;
        if (a->sky_samples && !sky->shadows) {
            /* rays are only cast with shadows: the count would do nothing */
            status =
                cli_usage_error(a->command, "--sky-samples needs sky shadows (--sky-shadows, or "
                                            "\"shadows\": true in the lights file)");
            goto done;
        }
        if (a->sky_samples)
            sky->samples = (uint32_t)a->sky_samples;
        /* the sky's own intensity is the baker's (lx_sky_desc): loaded as is */
        int loaded =
            cli_load_environment_run(a->command, sky->environment, 0.0f, LX_SKY_ENVIRONMENT_SIZE,
                                     a->desc.threads, a->quiet, &sky_env);
        if (loaded != EXIT_OK) {
            status = loaded;
            goto done;
        }
        lx_sky_desc given = {&sky_env, sky->intensity, sky->shadows, sky->samples};
        a->desc.sky = lx_sky_desc_defaults(&given);
    }
    cli_phase(sky->environment ? "lights and sky" : "lights");
    const char *dark = nothing_emits(scene, sky);
    if (dark) {
        cli_error("%s: nothing emits light: %s; give lights with --lights FILE.json, a sky with "
                  "--sky ENV or an ambient with --ambient R,G,B",
                  a->scene, dark);
        goto done;
    }
    check_spots(a, scene);
    /* nothing sizes the lightmaps: a density from the scene's area */
    if (!a->has_resolution && !(a->desc.texel_density > 0.0f)) {
        a->desc.texel_density = (float)cli_default_density(scene);
        a->density_from_scene = true;
    }
    /* lightmap UVs: the file's, or luxel's where those do not serve */
    int planned = plan_lightmaps(a, scene, unwrap, atlas);
    if (planned != EXIT_OK) {
        status = planned;
        goto done;
    }
    if (*unwrap)
        cli_phase("unwrap");
    check_scale(a, scene, *unwrap);
    if (cli_bake_strict_failed(a))
        goto done;

    cli_progress_init(progress, "texel maps", a->quiet);
    a->desc.progress = cli_progress_update;
    a->desc.progress_user = progress;
    lx_status created = lx_baker_create(scene, &a->desc, baker);
    cli_progress_finish(progress); /* the texel maps and the BVH */
    lx_cubemap_free(&sky_env);
    if (created != LX_OK) {
        if (created == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        goto done;
    }
    status = EXIT_OK;
done:
    lx_cubemap_free(&sky_env);
    return status;
}
