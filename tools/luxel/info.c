/* luxel info: what a scene holds, as luxel sees it after import: meshes
 * with their triangles and UV sets, materials, nodes, lights with their
 * physical units, cameras, and bounds. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *info_usage =
    "usage: luxel info SCENE [options]\n"
    "\n"
    "Lists the meshes (triangles, UV sets), materials, nodes (with their bake\n"
    "settings when not the default: sky dome, no shadows, no lightmap, no\n"
    "bounces, lightmap scale), lights (type and\n"
    "physical units), cameras, the sky and bounds of a glTF 2.0 or OBJ scene,\n"
    "and the health of every mesh's UV sets as lightmap UVs: their range, the\n"
    "share of covered texels two triangles overlap at --resolution, zero-area\n"
    "and flipped triangles, and whether luxel bake would use them (--unwrap\n"
    "auto makes new ones when not). Zero-area triangles in space are dropped\n"
    "with a warning.\n"
    "\n"
    "options:\n"
    "  --lights FILE.json   apply a lights file first (docs/lights-json.md)\n"
    "  --resolution N       texels a side overlaps are counted at (default %d)\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  --strict             fail on zero-area triangles and on any warning\n"
    "  --allow-any-path     read files the inputs name outside their folders\n"
    "  -h, --help           show this help\n";

static void print_light(const lx_light *l)
{
    bool area = lx_light_is_area(l);
    bool linear = l->type == LX_LIGHT_TUBE && !(l->radius > 0.0f);
    const char *unit = l->type == LX_LIGHT_DIRECTIONAL ? "lx"
                       : linear                        ? "cd/m"
                       : area                          ? "nt"
                                                       : "cd";
    printf("  %-12s %-16s %10.6g %s", lx_light_type_name(l->type), l->name[0] ? l->name : "-",
           l->intensity, l->model == LX_MODEL_CLASSIC ? "(classic units)" : unit);
    printf("  colour (%.3g, %.3g, %.3g)", l->color.x, l->color.y, l->color.z);
    if (l->type != LX_LIGHT_DIRECTIONAL)
        printf("  at (%.3g, %.3g, %.3g)", l->position.x, l->position.y, l->position.z);
    if (l->type == LX_LIGHT_TUBE)
        printf("  axis (%.3g, %.3g, %.3g)", l->direction.x, l->direction.y, l->direction.z);
    else if (l->type != LX_LIGHT_POINT && l->type != LX_LIGHT_SPHERE)
        printf("  toward (%.3g, %.3g, %.3g)", l->direction.x, l->direction.y, l->direction.z);
    if (l->type == LX_LIGHT_SPOT)
        printf("  cone %.1f..%.1f deg", LX_RAD2DEG(l->inner_angle), LX_RAD2DEG(l->outer_angle));
    if (l->type == LX_LIGHT_SPHERE || l->type == LX_LIGHT_DISK)
        printf("  radius %.3g m", l->radius);
    if (l->type == LX_LIGHT_TUBE)
        printf("  length %.3g m  radius %.3g m%s", l->length, l->radius, linear ? " (linear)" : "");
    if (l->type == LX_LIGHT_RECT)
        printf("  %.3g x %.3g m  up (%.3g, %.3g, %.3g)", l->width, l->height, l->up.x, l->up.y,
               l->up.z);
    if (l->range > 0)
        printf("  range %.3g m", l->range);
    else if (l->type != LX_LIGHT_DIRECTIONAL)
        printf("  range unlimited");
    if (l->profile) {
        lx_ies_info ies;
        lx_ies_get_info(l->profile, &ies);
        printf("  profile %s %s, %s lm, peak %s cd x %s", ies.version,
               lx_ies_symmetry_name(ies.symmetry),
               cli_num_digits(lx_ies_total_lumens(l->profile), 4),
               cli_num_digits(lx_ies_peak_candela(l->profile), 4),
               cli_num_digits(l->profile_scale, 4));
    }
    printf("  shadow %s", lx_shadow_mode_name(l->shadow));
    if (l->shadow == LX_SHADOW_SOFT)
        printf(" (%u samples)", lx_light_sample_count(l));
    printf("%s\n", l->dynamic ? "  dynamic" : "");
}

/* assimp's DefaultMaterial that no mesh uses. */
static bool phantom_material(const lx_scene *s, uint32_t i)
{
    if (strcmp(s->materials[i].name, "DefaultMaterial") != 0)
        return false;
    for (uint32_t k = 0; k < s->mesh_count; k++)
        if (s->meshes[k].material == i)
            return false;
    return true;
}

/* Every UV set of every mesh: range, overlap, zero-area and flipped
 * triangles, usable or why not. */
static bool print_uv_health(const lx_scene *s, const lx_uv_health_desc *hd)
{
    printf("UV health (overlaps at %dx%d texels):\n", hd->resolution, hd->resolution);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const lx_mesh *m = &s->meshes[i];
        for (int k = 0; k < LX_MAX_UV_SETS; k++) {
            if (!m->uv[k])
                continue;
            lx_uv_health h;
            if (lx_uv_health_mesh(m, k, hd, &h) != LX_OK) {
                cli_error("%s: mesh '%s': %s", s->path, m->name, lx_last_error());
                return false;
            }
            printf("  %-24s TEXCOORD_%d  u %s..%s  v %s..%s  overlap %s%%  "
                   "zero-area %u  flipped %u  %s%s\n",
                   m->name, k, cli_num_digits(h.min.x, 4), cli_num_digits(h.max.x, 4),
                   cli_num_digits(h.min.y, 4), cli_num_digits(h.max.y, 4),
                   cli_num_digits(100.0 * h.overlap_share, 3), h.zero_area_triangles,
                   h.flipped_triangles, h.usable ? "usable" : "not usable: ", h.reason);
        }
    }
    return true;
}

/* Nodes whose lightmap set (as bake --uv-set auto picks it) is a piece of
 * a UV square other nodes share: bake --unwrap auto makes their UVs. */
static bool print_uv_share(const lx_scene *s)
{
    lx_uv_share *share = calloc(s->node_count ? s->node_count : 1, sizeof *share);
    if (!share) {
        cli_error("out of memory");
        return false;
    }
    if (lx_uv_share_nodes(s, NULL, NULL, share) != LX_OK) {
        cli_error("%s: %s", s->path, lx_last_error());
        free(share);
        return false;
    }
    uint32_t shared = 0;
    for (uint32_t n = 0; n < s->node_count; n++)
        shared += share[n].shared;
    if (shared)
        printf("UV squares shared: %u %s of a square other nodes share (bake --unwrap auto "
               "makes theirs):\n",
               shared,
               cli_plural(shared, "node's lightmap UVs are a piece",
                          "nodes' lightmap UVs are pieces"));
    for (uint32_t n = 0; n < s->node_count; n++) {
        const lx_uv_share *h = &share[n];
        if (h->shared)
            printf("  %-24s TEXCOORD_%d  u %s..%s  v %s..%s  %s\n", s->nodes[n].name, h->uv_set,
                   cli_num_digits(h->min.x, 4), cli_num_digits(h->max.x, 4),
                   cli_num_digits(h->min.y, 4), cli_num_digits(h->max.y, 4), h->reason);
    }
    free(share);
    return true;
}

int cmd_info(int argc, char **argv)
{
    static const struct option options[] = {{"lights", required_argument, NULL, 'l'},
                                            {"resolution", required_argument, NULL, 'r'},
                                            {"threads", required_argument, NULL, 't'},
                                            {"strict", no_argument, NULL, 's'},
                                            CLI_ANY_PATH_OPTION,
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    const char *lights = NULL;
    lx_uv_health_desc hd = lx_uv_health_desc_defaults(NULL);
    bool strict = false;
    long v;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":h", options, NULL)) != -1) {
        switch (c) {
        case 'l':
            lights = optarg;
            break;
        case 'r':
            if (!cli_parse_int(optarg, 1, LX_UNWRAP_MAX_ATLAS_SIZE, &v))
                return cli_usage_error("info", "--resolution must be an integer in 1..%d, not '%s'",
                                       LX_UNWRAP_MAX_ATLAS_SIZE, optarg);
            hd.resolution = (int)v;
            break;
        case 't':
            if (!cli_parse_int(optarg, 1, 1024, &v))
                return cli_usage_error("info", "--threads must be an integer in 1..1024, not '%s'",
                                       optarg);
            hd.threads = (int)v;
            break;
        case 's':
            strict = true;
            cli_set_strict(true);
            break;
        case 'h':
            printf(info_usage, lx_uv_health_desc_defaults(NULL).resolution);
            return EXIT_OK;
        default: {
            int rc = cli_common_option("info", c, argv, NULL, NULL);
            if (rc != 0)
                return rc;
        }
        }
    }
    const char *path = NULL;
    int one = cli_one_scene("info", argc, argv, &path);
    if (one != 0)
        return one;
    lx_scene *s;
    /* listing needs the textures' names, not their pixels; zero-area
     * triangles are dropped with a warning (--strict: refused) */
    lx_scene_load_desc ld = {
        .skip_textures = true, .strict = strict, .allow_any_path = cli_allow_any_path()};
    if (!cli_scene_load(path, &ld, &s))
        return EXIT_FAILED;
    if (lights && lx_lights_json_apply(s, lights) != LX_OK) {
        cli_error("%s", lx_last_error());
        lx_scene_destroy(s);
        return EXIT_FAILED;
    }
    printf("scene %s\n", path);
    uint64_t tris = 0;
    printf("meshes: %u\n", s->mesh_count);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const lx_mesh *m = &s->meshes[i];
        tris += m->triangle_count;
        printf("  %-24s %8u triangles %8u vertices  UV sets:", m->name, m->triangle_count,
               m->vertex_count);
        bool any = false;
        for (int k = 0; k < LX_MAX_UV_SETS; k++)
            if (m->uv[k]) {
                printf(" TEXCOORD_%d", k);
                any = true;
            }
        printf("%s%s  material '%s'", any ? "" : " none", m->tangents ? "  tangents" : "",
               s->materials[m->material].name);
        if (m->dropped_triangles)
            printf("  (%u zero-area %s left out)", m->dropped_triangles,
                   cli_plural(m->dropped_triangles, "triangle", "triangles"));
        printf("\n");
    }
    /* assimp adds a DefaultMaterial to a file that has none: not listed
     * when no mesh uses it */
    uint32_t listed = 0;
    for (uint32_t i = 0; i < s->material_count; i++)
        listed += !phantom_material(s, i);
    printf("materials: %u\n", listed);
    for (uint32_t i = 0; i < s->material_count; i++) {
        const lx_material *m = &s->materials[i];
        if (phantom_material(s, i))
            continue;
        printf("  %-24s base colour (%.3g, %.3g, %.3g)%s%s%s%s\n", m->name, m->base_color.x,
               m->base_color.y, m->base_color.z, m->base_color_map_path ? " + texture" : "",
               m->normal_map_path ? "  normal map" : "", m->unlit ? "  unlit" : "",
               m->double_sided ? "  double-sided" : "");
    }
    printf("nodes: %u\n", s->node_count);
    for (uint32_t i = 0; i < s->node_count; i++) {
        const lx_node *n = &s->nodes[i];
        printf("  %-24s at (%s, %s, %s), %u %s", n->name, cli_num_digits(n->world.m[12], 3),
               cli_num_digits(n->world.m[13], 3), cli_num_digits(n->world.m[14], 3), n->mesh_count,
               cli_plural(n->mesh_count, "mesh", "meshes"));
        /* the bake settings that are not the default */
        const lx_node_bake *b = &n->bake;
        if (b->sky)
            printf("  sky dome");
        if (b->no_cast_shadows)
            printf("  no shadows");
        if (b->no_lightmap)
            printf("  no lightmap");
        if (b->no_contribute_gi)
            printf("  no bounces");
        if (lx_node_lightmap_scale(b) != 1.0f)
            printf("  lightmap scale %s", cli_num_digits(lx_node_lightmap_scale(b), 4));
        printf("\n");
    }
    if (!print_uv_health(s, &hd) || !print_uv_share(s)) {
        lx_scene_destroy(s);
        return EXIT_FAILED;
    }
    printf("lights: %u\n", s->light_count);
    for (uint32_t i = 0; i < s->light_count; i++) {
        const lx_light *l = &s->lights[i];
        print_light(l);
        if (l->type == LX_LIGHT_SPOT && l->outer_angle < LX_DEG2RAD(1.0f))
            lx_log(LX_LOG_WARN,
                   "%s: spot light '%s' has a cone of %.3g degrees from its axis: radians "
                   "typed as degrees? (lights files give angles in degrees)",
                   path, l->name[0] ? l->name : "-", LX_RAD2DEG(l->outer_angle));
    }
    if (s->camera_count)
        printf("cameras: %u (luxel render --gltf-camera N|NAME)\n", s->camera_count);
    for (uint32_t i = 0; i < s->camera_count; i++) {
        const lx_scene_camera *cam = &s->cameras[i];
        printf("  %-3u %-20s ", i, cam->name);
        if (cam->type == LX_SCENE_CAMERA_PERSPECTIVE)
            printf("perspective, yfov %s deg", cli_num_digits(LX_RAD2DEG(cam->yfov), 4));
        else
            printf("orthographic %s x %s m",
                   cli_num_digits(2.0 * cam->xmag, 4), cli_num_digits(2.0 * cam->ymag, 4));
        printf("  at (%s, %s, %s)", cli_num_digits(cam->eye.x, 4), cli_num_digits(cam->eye.y, 4),
               cli_num_digits(cam->eye.z, 4));
        printf("  looking (%s, %s, %s)", cli_num_digits(cam->forward.x, 3),
               cli_num_digits(cam->forward.y, 3), cli_num_digits(cam->forward.z, 3));
        printf("  up (%s, %s, %s)", cli_num_digits(cam->up.x, 3), cli_num_digits(cam->up.y, 3),
               cli_num_digits(cam->up.z, 3));
        if (cam->node_name)
            printf("  node '%s'", cam->node_name);
        printf("\n");
    }
    if (s->ambient.x > 0 || s->ambient.y > 0 || s->ambient.z > 0)
        printf("ambient: (%.3g, %.3g, %.3g) lx\n", s->ambient.x, s->ambient.y, s->ambient.z);
    if (s->sky.environment) {
        printf("sky: %s x %.4g, %s", s->sky.environment, s->sky.intensity,
               s->sky.shadows ? "shadows" : "unshadowed (spherical harmonics)");
        if (s->sky.shadows)
            printf(" (%u samples)",
                   s->sky.samples ? s->sky.samples : lx_sky_desc_defaults(NULL).samples);
        printf("\n");
    }
    lx_vec3 lo, hi;
    if (lx_scene_bounds(s, &lo, &hi))
        printf("bounds: (%s, %s, %s) .. (%s, %s, %s) m, %llu triangles\n",
               cli_num_digits(lo.x, 4), cli_num_digits(lo.y, 4), cli_num_digits(lo.z, 4),
               cli_num_digits(hi.x, 4), cli_num_digits(hi.y, 4), cli_num_digits(hi.z, 4),
               (unsigned long long)tris);
    lx_scene_destroy(s);
    unsigned w = cli_warning_count();
    if (strict && w) {
        cli_error("%s: %u warning%s with --strict", path, w, w == 1 ? "" : "s");
        return EXIT_FAILED;
    }
    return EXIT_OK;
}
