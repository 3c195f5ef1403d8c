/* The baker: builds a texel map per node and the ray structures once, bakes
 * static lights, re-evaluates dynamic lights per update and combines the
 * two (the per-texel lighting article's initial frame / update frame /
 * Apply kernel). */
#include "bake_internal.h"
#include "core/internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lx_sky_desc lx_sky_desc_defaults(const lx_sky_desc *desc)
{
    lx_sky_desc d = {0};
    if (desc)
        d = *desc;
    if (d.intensity == 0.0f)
        d.intensity = 1.0f;
    if (d.samples == 0)
        d.samples = 64;
    return d;
}

lx_bake_desc lx_bake_desc_defaults(const lx_bake_desc *desc)
{
    lx_bake_desc d = {0};
    if (desc)
        d = *desc;
    if (d.resolution == 0)
        d.resolution = 256;
    if (d.max_resolution == 0)
        d.max_resolution = 4096;
    d.sky = lx_sky_desc_defaults(&d.sky);
    if (d.gi_samples == 0)
        d.gi_samples = LX_GI_SAMPLES_DEFAULT;
    if (d.emissive_scale == 0.0f)
        d.emissive_scale = 1.0f;
    if (d.supersample == 0)
        d.supersample = 1;
    return d;
}

static lx_status validate_desc(const lx_bake_desc *d)
{
    if (d->resolution < 1 || d->resolution > LX_MAX_LIGHTMAP_SIZE)
        return lx_fail(LX_ERR_INVALID, "resolution %d is outside 1..%d", d->resolution,
                       LX_MAX_LIGHTMAP_SIZE);
    if (d->max_resolution < 4 || d->max_resolution > LX_MAX_LIGHTMAP_SIZE)
        return lx_fail(LX_ERR_INVALID, "max resolution %d is outside 4..%d", d->max_resolution,
                       LX_MAX_LIGHTMAP_SIZE);
    if (!(d->texel_density >= 0.0f) || !isfinite(d->texel_density))
        return lx_fail(LX_ERR_INVALID, "texel density must be a finite positive number");
    if (d->padding < 0 || d->padding > 64)
        return lx_fail(LX_ERR_INVALID, "padding %d is outside 0..64", d->padding);
    if (d->threads < 0 || d->threads > 1024)
        return lx_fail(LX_ERR_INVALID, "thread count %d is outside 0..1024", d->threads);
    if (!(d->shadow_bias >= 0.0f) || !isfinite(d->shadow_bias))
        return lx_fail(LX_ERR_INVALID, "shadow bias must be finite and >= 0");
    if (d->bounces < 0 || d->bounces > LX_MAX_BOUNCES)
        return lx_fail(LX_ERR_INVALID, "bounces %d is outside 0..%d", d->bounces, LX_MAX_BOUNCES);
    if ((unsigned)d->directional > (unsigned)LX_DIRECTIONAL_DOMINANT)
        return lx_fail(LX_ERR_INVALID, "unknown directional mode %d", (int)d->directional);
    if ((unsigned)d->double_sided > (unsigned)LX_DOUBLE_SIDED_FRONT)
        return lx_fail(LX_ERR_INVALID, "unknown double-sided mode %d", (int)d->double_sided);
    if ((unsigned)d->denoise > (unsigned)LX_DENOISE_ALL)
        return lx_fail(LX_ERR_INVALID, "unknown denoise mode %d", (int)d->denoise);
    if (d->gi_samples < 1 || d->gi_samples > LX_MAX_GI_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "gi samples %u is outside 1..%u", d->gi_samples,
                       LX_MAX_GI_SAMPLES);
    if (d->edge_supersample < 0 || d->edge_supersample > LX_MAX_SUPERSAMPLE)
        return lx_fail(LX_ERR_INVALID, "edge supersample %d is outside 0..%d",
                       d->edge_supersample, LX_MAX_SUPERSAMPLE);
    if (d->supersample < 1 || d->supersample > LX_MAX_SUPERSAMPLE)
        return lx_fail(LX_ERR_INVALID, "supersample %d is outside 1..%d", d->supersample,
                       LX_MAX_SUPERSAMPLE);
    if (!(d->emissive_scale > 0.0f) || !isfinite(d->emissive_scale))
        return lx_fail(LX_ERR_INVALID, "emissive scale must be a finite number > 0");
    if (d->dynamic_bounce_samples > LX_MAX_DYNAMIC_BOUNCE_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "dynamic bounce samples %u is outside 0..%u",
                       d->dynamic_bounce_samples, LX_MAX_DYNAMIC_BOUNCE_SAMPLES);
    if (d->quantity != LX_QUANTITY_IRRADIANCE && d->quantity != LX_QUANTITY_RADIANCE)
        return lx_fail(LX_ERR_INVALID, "unknown quantity %d", (int)d->quantity);
    if (d->uv_set != LX_UV_SET_AUTO && d->uv_set != LX_UV_SET_0 && d->uv_set != LX_UV_SET_1)
        return lx_fail(LX_ERR_INVALID, "unknown UV set choice %d", (int)d->uv_set);
    return LX_OK;
}

/* lx_baker_create's progress: the materials' horizon maps (when any
 * material has a height: up to HORIZON_SHARE), the texel maps (up to
 * TEXEL_MAPS_SHARE), the BVH build (up to BVH_SHARE), then the samples
 * moved out of walls (straddle.c). */
#define TEXEL_MAPS_SHARE 0.8f
#define BVH_SHARE 0.9f
#define HORIZON_SHARE 0.3f

/* Where the texel maps' progress starts. */
static float maps_from(const lx_baker *b)
{
    return b->horizon_materials ? HORIZON_SHARE : 0.0f;
}

static bool bvh_progress(void *user, float fraction)
{
    const lx_bake_desc *d = user;
    float f = TEXEL_MAPS_SHARE + (BVH_SHARE - TEXEL_MAPS_SHARE) * fraction;
    return d->progress(d->progress_user, f);
}

static void candidates_free(lx_tile_candidate *c, uint32_t count)
{
    for (uint32_t i = 0; c && i < count; i++) {
        free(c[i].name);
        free(c[i].page.nodes);
    }
    free(c);
}

/* One warning for every node whose lightmap the automatic choice sent to
 * TEXCOORD_0 because a mesh of it has no TEXCOORD_1 (fallback[n] set):
 * the first named with its mesh, the rest counted. */
static void warn_texcoord0(const lx_scene *scene, const uint8_t *fallback)
{
    uint32_t count = 0, first = UINT32_MAX;
    for (uint32_t n = 0; n < scene->node_count; n++)
        if (fallback[n]) {
            count++;
            first = first == UINT32_MAX ? n : first;
        }
    if (count == 0)
        return;
    const lx_node *node = &scene->nodes[first];
    const char *without = "?";
    uint32_t unused = 0; /* meshes whose TEXCOORD_1 goes unused */
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *m = &scene->meshes[node->meshes[k]];
        if (m->uv[0] && !m->uv[1] && strcmp(without, "?") == 0)
            without = m->name;
        unused += m->uv[1] != NULL;
    }
    char others[160] = "";
    if (unused > 0)
        snprintf(others, sizeof others, " (the TEXCOORD_1 of its %u other %s goes unused)", unused,
                 unused == 1 ? "mesh" : "meshes");
    char more[96] = "";
    if (count > 1)
        snprintf(more, sizeof more, "; so do %u more nodes with such a mesh", count - 1);
    lx_log(LX_LOG_WARN, "%s: node '%s': mesh '%s' has no TEXCOORD_1; its lightmap uses TEXCOORD_0%s%s",
           scene->path, node->name, without, others, more);
}

/* One warning for the meshes without their node's lightmap UV set
 * (uvless[n]: the first of node n, UINT32_MAX: none): the first named,
 * the other nodes counted (-v names every mesh, texel_map.c). */
static void warn_no_uvs(const lx_scene *scene, const uint32_t *uvless)
{
    uint32_t count = 0, first = UINT32_MAX;
    for (uint32_t n = 0; n < scene->node_count; n++)
        if (uvless[n] != UINT32_MAX) {
            count++;
            first = first == UINT32_MAX ? n : first;
        }
    if (count == 0)
        return;
    char more[128] = "";
    if (count > 1)
        snprintf(more, sizeof more, "; so do meshes of %u more nodes (-v names them)", count - 1);
    lx_log(LX_LOG_WARN,
           "%s: node '%s': mesh '%s' has no UVs; it gets no lightmap texels (it still casts "
           "shadows)%s",
           scene->path, scene->nodes[first].name, scene->meshes[uvless[first]].name, more);
}

/* The UV set a page's node bakes with. */
static int page_node_uv_set(const lx_scene *scene, const lx_bake_desc *desc,
                            const lx_tile_candidate *c, const lx_page_node *pn)
{
    if (pn->uv_set >= 0)
        return pn->uv_set;
    return lx_bake_uv_set(scene, pn->node, c->page.width ? LX_UV_SET_AUTO : desc->uv_set);
}

/* Builds the candidates' texel maps (a tiled baker lets each go once
 * built, keeping what stays resident), marking the nodes that cover a
 * texel in hit. */
static lx_status build_maps(lx_baker *b, const lx_scene *scene, const lx_bake_desc *desc,
                            lx_tile_candidate *c, uint32_t count, uint8_t *hit)
{
    uint32_t needs = lx_bake_scene_needs(scene);
    lx_status st = lx_bake_plan_memory(b, scene, c, count, needs);
    if (st == LX_OK && b->tiled) {
        st = lx_bake_scene_copy(scene, &b->tile_scene);
        b->pages = calloc(count + 1, sizeof *b->pages);
        if (st == LX_OK && !b->pages)
            st = lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    }
    /* a tiled baker builds from its copy, as it will build again */
    const lx_scene *from_scene = b->tiled ? b->tile_scene : scene;
    uint8_t *fallback = calloc(scene->node_count + 1, 1);
    uint32_t *uvless = malloc(sizeof(uint32_t) * (scene->node_count + 1));
    if (st == LX_OK && (!fallback || !uvless))
        st = lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    for (uint32_t n = 0; uvless && n < scene->node_count; n++)
        uvless[n] = UINT32_MAX;
    for (uint32_t i = 0; i < count && st == LX_OK; i++)
        for (uint32_t k = 0; k < c[i].page.node_count; k++) {
            const lx_page_node *pn = &c[i].page.nodes[k];
            /* the set lx_texel_map_build reads (collect_slots) */
            int set = pn->uv_set >= 0 ? pn->uv_set
                                      : lx_bake_uv_set(scene, pn->node, LX_UV_SET_AUTO);
            const lx_node *node = &scene->nodes[pn->node];
            for (uint32_t q = 0; q < node->mesh_count && uvless[pn->node] == UINT32_MAX; q++)
                if (set >= 0 && set < LX_MAX_UV_SETS && !scene->meshes[node->meshes[q]].uv[set])
                    uvless[pn->node] = node->meshes[q];
        }
    for (uint32_t i = 0; i < count && st == LX_OK; i++) {
        lx_lightmap *map = &b->maps[b->map_count];
        float from = maps_from(b), span = TEXEL_MAPS_SHARE - from;
        lx_texel_progress share = {from + span * (float)i / (float)count,
                                   from + span * (float)(i + 1) / (float)count};
        lx_page_spec page = {c[i].name, c[i].page.width, c[i].page.height, c[i].page.nodes,
                             c[i].page.node_count};
        st = lx_texel_map_build(from_scene, &page, desc, share, b->horizon_materials, map);
        if (st != LX_OK) {
            lx_texel_map_free(map);
            break;
        }
        if (map->info.width == 0) {
            lx_texel_map_free(map); /* no UVs: nothing to bake */
            continue;
        }
        map->loaded = true;
        map->horizon_page = c[i].horizon;
        for (uint32_t t = 0; t < map->info.used_texels; t++)
            hit[map->texels[t].node] = 1;
        for (uint32_t k = 0; k < c[i].page.node_count; k++) {
            const lx_page_node *pn = &c[i].page.nodes[k];
            b->node_map[pn->node] = b->map_count;
            if (pn->uv_set < 0 && lx_bake_uv_set(scene, pn->node, LX_UV_SET_AUTO) == 0)
                for (uint32_t q = 0; q < scene->nodes[pn->node].mesh_count; q++) {
                    const lx_mesh *m = &scene->meshes[scene->nodes[pn->node].meshes[q]];
                    fallback[pn->node] |= m->uv[0] && !m->uv[1];
                }
            if (b->node_uv_set)
                b->node_uv_set[pn->node] = (int8_t)page_node_uv_set(scene, desc, &c[i], pn);
            memcpy(b->node_scale_offset[pn->node], pn->scale_offset, sizeof pn->scale_offset);
        }
        if (b->tiled) {
            b->pages[b->map_count] = c[i].page; /* the nodes move to the baker */
            c[i].page.nodes = NULL;
            lx_bake_map_unload(map);
        }
        b->map_count++;
        /* building large texel maps takes long enough to report and stop */
        if (desc->progress && !desc->progress(desc->progress_user, share.to))
            st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    }
    if (st == LX_OK) {
        warn_no_uvs(scene, uvless);
        warn_texcoord0(scene, fallback);
    }
    free(fallback);
    free(uvless);
    if (st == LX_OK)
        st = lx_bake_plan_tiles(b, scene, needs);
    b->loaded_tile = b->tiled ? UINT32_MAX : 0;
    return st;
}

static bool page_has_horizon(const lx_baker *b, const lx_scene *scene, const lx_page_node *nodes,
                             uint32_t count)
{
    for (uint32_t k = 0; k < count; k++)
        if (lx_bake_node_has_horizon(scene, b->horizon_materials, nodes[k].node))
            return true;
    return false;
}

/* A lightmap per node with UVs, sized by the resolution or the density. */
static lx_status build_node_maps(lx_baker *b, const lx_scene *scene, const lx_bake_desc *desc,
                                 uint8_t *hit)
{
    lx_tile_candidate *c = calloc(scene->node_count + 1, sizeof *c);
    if (!c)
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    uint32_t count = 0;
    lx_status st = LX_OK;
    for (uint32_t n = 0; n < scene->node_count && st == LX_OK; n++) {
        if (scene->nodes[n].bake.no_lightmap)
            continue; /* baked for its shadows and bounces only */
        int w, h;
        lx_texel_map_size(scene, n, desc, &w, &h);
        lx_tile_candidate *k = &c[count++];
        k->name = lx_strdup(scene->nodes[n].name);
        k->page.nodes = malloc(sizeof *k->page.nodes);
        if (!k->name || !k->page.nodes) {
            st = lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
            break;
        }
        *k->page.nodes = (lx_page_node){n, (int)desc->uv_set - 1, {1.0f, 1.0f, 0.0f, 0.0f}};
        k->page.node_count = 1;
        k->pixels = (uint64_t)w * (uint64_t)h;
        k->horizon = page_has_horizon(b, scene, k->page.nodes, 1);
    }
    if (st == LX_OK)
        st = build_maps(b, scene, desc, c, count, hit);
    candidates_free(c, count);
    return st;
}

/* A lightmap per page of the atlas, holding the nodes placed on it. */
static lx_status build_pages(lx_baker *b, const lx_scene *scene, const lx_bake_desc *desc,
                             uint8_t *hit)
{
    const lx_unwrap *atlas = desc->atlas;
    if (atlas->node_count != scene->node_count)
        return lx_fail(LX_ERR_INVALID, "%s: the atlas places %u nodes, the scene has %u",
                       scene->path, atlas->node_count, scene->node_count);
    for (uint32_t p = 0; p < atlas->page_count; p++) {
        const lx_unwrap_page *pg = &atlas->pages[p];
        if (pg->width < 1 || pg->height < 1 || pg->width > LX_MAX_LIGHTMAP_SIZE ||
            pg->height > LX_MAX_LIGHTMAP_SIZE)
            return lx_fail(LX_ERR_INVALID, "%s: atlas page %u is %dx%d (1..%d a side)", scene->path,
                           p, pg->width, pg->height, LX_MAX_LIGHTMAP_SIZE);
    }
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_unwrap_node *un = &atlas->nodes[n];
        if (un->page != UINT32_MAX && un->page >= atlas->page_count)
            return lx_fail(LX_ERR_INVALID, "%s: node '%s': atlas page %u out of range (count %u)",
                           scene->path, scene->nodes[n].name, un->page, atlas->page_count);
    }
    lx_tile_candidate *c = calloc(atlas->page_count + 1, sizeof *c);
    if (!c)
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    lx_status st = LX_OK;
    uint32_t count = 0;
    for (uint32_t p = 0; p < atlas->page_count && st == LX_OK; p++) {
        lx_tile_candidate *k = &c[count++];
        char name[32];
        snprintf(name, sizeof name, "lightmap-%u", p);
        k->name = lx_strdup(name);
        k->page.nodes = malloc(sizeof *k->page.nodes * (scene->node_count + 1));
        if (!k->name || !k->page.nodes) {
            st = lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
            break;
        }
        for (uint32_t n = 0; n < scene->node_count; n++) {
            const lx_unwrap_node *un = &atlas->nodes[n];
            if (un->page != p || scene->nodes[n].bake.no_lightmap)
                continue;
            lx_page_node *pn = &k->page.nodes[k->page.node_count++];
            pn->node = n;
            /* generated UVs are in the node's lightmap set once applied,
             * in page coordinates */
            pn->uv_set = un->mode == LX_UNWRAP_KEEP ? un->uv_set : lx_scene_lightmap_set(scene, n);
            memcpy(pn->scale_offset, un->scale_offset, sizeof pn->scale_offset);
        }
        k->page.width = atlas->pages[p].width;
        k->page.height = atlas->pages[p].height;
        k->pixels = (uint64_t)k->page.width * (uint64_t)k->page.height;
        k->horizon = page_has_horizon(b, scene, k->page.nodes, k->page.node_count);
    }
    if (st == LX_OK)
        st = build_maps(b, scene, desc, c, count, hit);
    candidates_free(c, count);
    return st;
}

/* A lightmap with no covered texel bakes to a black file: when no node
 * covers a texel the bake fails; a node that covers none while others do
 * is a warning naming it. hit: the nodes that cover a texel. */
static lx_status check_coverage(const lx_baker *b, const lx_scene *scene, const uint8_t *hit)
{
    uint64_t total = 0;
    for (uint32_t m = 0; m < b->map_count; m++)
        total += b->maps[m].info.used_texels;
    uint32_t empty = 0, first = UINT32_MAX;
    for (uint32_t n = 0; n < scene->node_count; n++)
        if (b->node_map[n] != UINT32_MAX && !hit[n]) {
            empty++;
            first = first == UINT32_MAX ? n : first;
        }
    if (empty == 0)
        return LX_OK;
    const lx_lightmap_info *info = &b->maps[b->node_map[first]].info;
    if (total == 0)
        return lx_fail(LX_ERR_INVALID,
                       "%s: node '%s'%s: its lightmap UVs (TEXCOORD_%d) cover no texel of the "
                       "%dx%d lightmap (are they outside [0,1]?): it would be black",
                       scene->path, scene->nodes[first].name,
                       empty > 1 ? " and every other node" : "",
                       info->uv_set == LX_UV_SET_MIXED ? 1 : info->uv_set, info->width,
                       info->height);
    for (uint32_t n = 0; n < scene->node_count; n++)
        if (b->node_map[n] != UINT32_MAX && !hit[n]) {
            const lx_lightmap *map = &b->maps[b->node_map[n]];
            lx_log(LX_LOG_WARN,
                   "%s: node '%s': its lightmap UVs cover no texel of lightmap '%s' "
                   "(%dx%d; are they outside [0,1]?): the node stays black",
                   scene->path, scene->nodes[n].name, map->name, map->info.width,
                   map->info.height);
        }
    return LX_OK;
}

lx_status lx_baker_create(const lx_scene *scene, const lx_bake_desc *in, lx_baker **out)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!out)
        return lx_fail_null(__func__, "out");
    *out = NULL;
    lx_bake_desc desc = lx_bake_desc_defaults(in);
    lx_status st = validate_desc(&desc);
    if (st != LX_OK)
        return st;
    for (uint32_t l = 0; l < scene->light_count; l++)
        if ((st = lx_light_validate(&scene->lights[l])) != LX_OK) {
            /* lights added through the API are checked here too: name the scene */
            if (scene->path)
                lx_error_prefix(scene->path);
            return st;
        }
    if (!lx_vec3_finite(scene->ambient) || scene->ambient.x < 0 || scene->ambient.y < 0 ||
        scene->ambient.z < 0)
        return lx_fail(LX_ERR_INVALID, "%s: ambient must be finite and >= 0", scene->path);

    lx_baker *b = calloc(1, sizeof *b);
    if (!b)
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    b->desc = desc;
    b->ambient = scene->ambient;
    b->node_count = scene->node_count;
    b->node_map = malloc(sizeof(uint32_t) * (scene->node_count + 1));
    b->node_world = malloc(sizeof(lx_mat4) * (scene->node_count + 1));
    uint32_t max_maps = scene->node_count;
    if (desc.atlas && desc.atlas->page_count > max_maps)
        max_maps = desc.atlas->page_count;
    b->maps = calloc(max_maps + 1, sizeof(lx_lightmap));
    b->light_count = scene->light_count;
    b->lights = malloc(sizeof(lx_light) * (scene->light_count + 1));
    if (!b->node_map || !b->node_world || !b->maps || !b->lights) {
        lx_baker_destroy(b);
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    }
    if (scene->light_count)
        memcpy(b->lights, scene->lights, sizeof(lx_light) * scene->light_count);
    /* the baker outlives the scene: it keeps its own hold on profiles */
    for (uint32_t l = 0; l < b->light_count; l++)
        lx_ies_retain(b->lights[l].profile);
    /* the sky's environment is borrowed for this call only */
    st = lx_sky_prepare(b, &desc.sky);
    b->desc.sky.environment = NULL;
    if (st != LX_OK) {
        lx_baker_destroy(b);
        return st;
    }

    lx_vec3 lo, hi;
    b->scene_diagonal = lx_scene_bounds(scene, &lo, &hi) ? lx_length(lx_sub(hi, lo)) : 1.0f;
    if (!(b->scene_diagonal > 0.0f))
        b->scene_diagonal = 1.0f;
    b->bias = desc.shadow_bias > 0.0f ? desc.shadow_bias : 1e-5f * b->scene_diagonal;

    b->node_scale_offset = malloc(sizeof *b->node_scale_offset * (scene->node_count + 1));
    if (!b->node_scale_offset) {
        lx_baker_destroy(b);
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    }
    for (uint32_t n = 0; n < scene->node_count; n++) {
        b->node_world[n] = scene->nodes[n].world;
        b->node_map[n] = UINT32_MAX;
        b->node_scale_offset[n][0] = b->node_scale_offset[n][1] = 1.0f;
        b->node_scale_offset[n][2] = b->node_scale_offset[n][3] = 0.0f;
    }
    /* the emitters are direct light at any bounce count */
    bool emission = (lx_bake_scene_needs(scene) & LX_SCENE_NEEDS_EMISSION) != 0;
    if ((lx_bake_keeps_surfaces(&desc) || emission) &&
        (st = lx_gi_prepare(b, scene, !lx_bake_keeps_surfaces(&desc))) != LX_OK) {
        lx_baker_destroy(b);
        return st;
    }
    /* heights named by the lights JSON: horizon layers and AO, made once */
    b->horizon_material_count = scene->material_count;
    st = lx_bake_horizon_load(scene, &desc, (lx_texel_progress){0.0f, HORIZON_SHARE},
                              &b->horizon_materials);
    uint8_t *hit = calloc(scene->node_count + 1, 1);
    if (st == LX_OK && !hit)
        st = lx_fail(LX_ERR_NOMEM, "out of memory creating a baker");
    if (st == LX_OK)
        st = desc.atlas ? build_pages(b, scene, &desc, hit) : build_node_maps(b, scene, &desc, hit);
    /* the texels keep what they need of them; a tiled baker builds again */
    if (!b->tiled) {
        lx_bake_horizon_free(b->horizon_materials, b->horizon_material_count);
        b->horizon_materials = NULL;
    }
    if (st == LX_OK)
        st = check_coverage(b, scene, hit);
    free(hit);
    if (st != LX_OK) {
        lx_baker_destroy(b);
        return st;
    }
    if (b->tiled)
        lx_log(LX_LOG_INFO,
               "%s: the lightmaps do not fit the memory together: baking them in %u tiles",
               scene->path, b->tile_count);
    lx_tracer_desc td = {.threads = desc.threads,
                         .progress = desc.progress ? bvh_progress : NULL,
                         .progress_user = &desc};
    st = lx_tracer_create(scene, &td, &b->tracer);
    /* the face each double-sided triangle bakes (sides.c) */
    if (st == LX_OK)
        st = lx_bake_sides(b, scene);
    for (uint32_t m = 0; m < b->map_count && st == LX_OK; m++)
        lx_bake_sides_apply(b, &b->maps[m]);
    /* samples inside geometry move out (straddle.c) */
    if (st == LX_OK)
        st = lx_bake_straddle(b, BVH_SHARE, 1.0f - BVH_SHARE, true);
    if (st != LX_OK) {
        lx_baker_destroy(b);
        return st;
    }
    *out = b;
    return LX_OK;
}

void lx_baker_destroy(lx_baker *b)
{
    if (!b)
        return;
    for (uint32_t m = 0; m < b->map_count; m++)
        lx_texel_map_free(&b->maps[m]);
    lx_tracer_destroy(b->tracer);
    lx_sky_free(b);
    lx_dyn_bounce_free(b);
    lx_gi_free(b);
    lx_bake_sides_free(b);
    lx_bake_horizon_free(b->horizon_materials, b->horizon_material_count);
    lx_scene_destroy(b->tile_scene);
    for (uint32_t m = 0; b->pages && m < b->map_count; m++)
        free(b->pages[m].nodes);
    free(b->pages);
    free(b->tile_first_map);
    free(b->maps);
    free(b->node_map);
    free(b->node_scale_offset);
    free(b->node_world);
    for (uint32_t l = 0; b->lights && l < b->light_count; l++)
        lx_ies_free((lx_ies_profile *)b->lights[l].profile);
    free(b->lights);
    free(b);
}

uint32_t lx_baker_tile_count(const lx_baker *b)
{
    return b->tile_count;
}

uint32_t lx_baker_lightmap_count(const lx_baker *b)
{
    return b->map_count;
}

const lx_lightmap_info *lx_baker_lightmap_info(const lx_baker *b, uint32_t map)
{
    return map < b->map_count ? &b->maps[map].info : NULL;
}

bool lx_baker_node_lightmap(const lx_baker *b, uint32_t node, uint32_t *map, float scale_offset[4])
{
    if (node >= b->node_count || b->node_map[node] == UINT32_MAX)
        return false;
    *map = b->node_map[node];
    memcpy(scale_offset, b->node_scale_offset[node], sizeof(float) * 4);
    return true;
}

const uint8_t *lx_baker_mask(const lx_baker *b, uint32_t map)
{
    return map < b->map_count ? b->maps[map].mask : NULL;
}

uint32_t lx_baker_light_count(const lx_baker *b)
{
    return b->light_count;
}

const lx_light *lx_baker_light(const lx_baker *b, uint32_t light)
{
    return light < b->light_count ? &b->lights[light] : NULL;
}

lx_status lx_baker_set_light(lx_baker *b, uint32_t light, const lx_light *value)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    if (!value)
        return lx_fail_null(__func__, "value");
    if (light >= b->light_count)
        return lx_fail(LX_ERR_INVALID, "light %u out of range (count %u)", light, b->light_count);
    lx_status st = lx_light_validate(value);
    if (st != LX_OK)
        return st;
    lx_ies_retain(value->profile);
    lx_ies_free((lx_ies_profile *)b->lights[light].profile);
    b->lights[light] = *value;
    return LX_OK;
}

lx_status lx_baker_set_node_transform(lx_baker *b, uint32_t node, const lx_mat4 *world)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    if (!world)
        return lx_fail_null(__func__, "world");
    if (node >= b->node_count)
        return lx_fail(LX_ERR_INVALID, "node %u out of range (count %u)", node, b->node_count);
    /* the object space a move needs, before anything changes */
    lx_status st = LX_OK;
    /* a tiled baker builds its maps again from its copy: there the node
     * moves too */
    if (b->tile_scene)
        b->tile_scene->nodes[node].world = *world;
    if (b->node_map[node] != UINT32_MAX && b->maps[b->node_map[node]].loaded &&
        (st = lx_texel_map_keep_object_space(&b->maps[b->node_map[node]])) != LX_OK)
        return st;
    st = lx_tracer_set_node_transform(b->tracer, node, world);
    if (st != LX_OK)
        return st;
    b->node_world[node] = *world;
    b->tracer_dirty = true;
    b->dyn_stale = true; /* the dynamic bounce's cached hits */
    if (b->node_map[node] != UINT32_MAX && b->maps[b->node_map[node]].loaded)
        lx_texel_map_transform(&b->maps[b->node_map[node]], node, world);
    return LX_OK;
}

/* Indices of the lights with dynamic == want. */
static uint32_t select_lights(const lx_baker *b, bool want, uint32_t *out)
{
    uint32_t n = 0;
    for (uint32_t l = 0; l < b->light_count; l++)
        if (b->lights[l].dynamic == want)
            out[n++] = l;
    return n;
}

static void clear_buffers(lx_baker *b, bool realtime)
{
    for (uint32_t m = 0; m < b->map_count; m++) {
        lx_lightmap *map = &b->maps[m];
        size_t n = (size_t)map->info.width * map->info.height * 3;
        float *buf = realtime ? map->realtime : map->baked;
        if (buf)
            memset(buf, 0, n * sizeof(float));
        if (!realtime && map->sh)
            memset(map->sh, 0, n / 3 * LX_SH_FLOATS * sizeof(float));
    }
}

/* The static lights, then the emitters, into every map's
 * baked buffer, tile by tile, within [from, to] of the progress. */
static lx_status bake_direct(lx_baker *b, const uint32_t *idx, uint32_t n, float from, float to)
{
    lx_emitter_set *emitters = NULL;
    lx_status st = lx_emitter_set_create(b, &emitters);
    for (uint32_t t = 0; t < b->tile_count && st == LX_OK; t++) {
        float tf, tt;
        lx_bake_tile_share(b, t, from, to, &tf, &tt);
        if (!lx_bake_report(b, tf)) {
            st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
            break;
        }
        float lights_end = emitters ? 0.5f * (tf + tt) : tt;
        st = lx_bake_tile_need(b, b->tile_first_map[t]);
        if (st == LX_OK)
            st = lx_bake_lights(b, idx, n, b->ambient, false, tf, lights_end - tf);
        if (st == LX_OK && emitters)
            st = lx_bake_emitters(b, emitters, lights_end, tt - lights_end);
    }
    lx_emitter_set_destroy(b, emitters);
    return st;
}

lx_status lx_baker_bake(lx_baker *b)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    uint32_t *idx = malloc(sizeof(uint32_t) * (b->light_count + 1));
    if (!idx)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    uint32_t n = select_lights(b, false, idx);
    /* the directional data: made by the first bake that asks (48 bytes a
     * texel), every texel written by the direct pass */
    uint64_t sh_bytes = 0;
    for (uint32_t m = 0; m < b->map_count && b->desc.directional; m++)
        if (!b->maps[m].sh)
            sh_bytes += (uint64_t)b->maps[m].info.width * (uint64_t)b->maps[m].info.height *
                        LX_SH_FLOATS * sizeof(float);
    if (sh_bytes && lx_check_memory(sh_bytes, "the directional lightmaps") != LX_OK) {
        free(idx);
        return LX_ERR_NOMEM;
    }
    for (uint32_t m = 0; m < b->map_count && b->desc.directional; m++) {
        lx_lightmap *map = &b->maps[m];
        size_t count = (size_t)map->info.width * map->info.height * LX_SH_FLOATS;
        if (!map->sh && !(map->sh = calloc(count, sizeof(float)))) {
            free(idx);
            return lx_fail(LX_ERR_NOMEM,
                           "lightmap '%s': out of memory for its directional data (%zu bytes)",
                           map->name, count * sizeof(float));
        }
    }
    /* progress: the direct pass, then the indirect one's gathers (a
     * validity pass and a gather a bounce, each about as long) */
    bool sampled = false;
    lx_status st = lx_bake_sampled_begin(b, &sampled);
    bool denoise = b->desc.denoise == LX_DENOISE_ALL ||
                   (b->desc.denoise == LX_DENOISE_INDIRECT && (b->desc.bounces > 0 || sampled));
    float end = denoise ? 0.9f : 1.0f; /* the last tenth denoises */
    float direct = b->desc.bounces > 0 ? end / (float)(b->desc.bounces + 2) : end;
    float **kept = NULL;
    if (st == LX_OK)
        st = bake_direct(b, idx, n, 0.0f, direct);
    if (st == LX_OK)
        kept = lx_bake_denoise_keep(b, &st);
    if (st == LX_OK && b->desc.bounces > 0)
        st = lx_bake_indirect(b, direct, end - direct);
    for (uint32_t t = 0; t < b->tile_count && st == LX_OK && denoise; t++) {
        float tf, tt;
        lx_bake_tile_share(b, t, end, 1.0f, &tf, &tt);
        st = lx_bake_tile_need(b, b->tile_first_map[t]);
        if (st == LX_OK)
            st = lx_bake_denoise(b, kept, tf, tt - tf);
    }
    lx_bake_denoise_free(b, kept);
    lx_bake_sampled_end(b);
    if (st != LX_OK)
        clear_buffers(b, false);
    free(idx);
    return st;
}

lx_status lx_baker_update(lx_baker *b)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    uint32_t idx_buf[64] = {0};
    uint32_t *idx = b->light_count <= 64 ? idx_buf : malloc(sizeof(uint32_t) * b->light_count);
    if (!idx)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    uint32_t n = select_lights(b, true, idx);
    lx_status st = LX_OK;
    /* The real-time buffers are made on the first update that has dynamic
     * lights: a static bake never touches their memory (12 bytes a texel,
     * and fresh pages cost as much as the work on them). Until then they
     * read as zero. */
    if (n == 0) {
        clear_buffers(b, true); /* no dynamic light: zero where they exist */
        if (b->desc.progress && !b->desc.progress(b->desc.progress_user, 1.0f))
            st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    } else {
        for (uint32_t m = 0; m < b->map_count && st == LX_OK; m++) {
            lx_lightmap *map = &b->maps[m];
            size_t count = (size_t)map->info.width * map->info.height * 3;
            if (!map->realtime && !(map->realtime = calloc(count, sizeof(float))))
                st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for the real-time buffer",
                             map->name);
        }
        bool bounce = b->desc.dynamic_bounce_samples > 0;
        float lights_end = bounce ? 0.5f : 1.0f;
        for (uint32_t t = 0; t < b->tile_count && st == LX_OK; t++) {
            float tf, tt;
            lx_bake_tile_share(b, t, 0.0f, lights_end, &tf, &tt);
            st = lx_bake_tile_need(b, b->tile_first_map[t]);
            if (st == LX_OK)
                st = lx_bake_lights(b, idx, n, lx_v3(0, 0, 0), true, tf, tt - tf);
        }
        if (st == LX_OK && bounce) {
            st = lx_dyn_bounce_update(b);
            if (st == LX_OK && b->desc.progress && !b->desc.progress(b->desc.progress_user, 1.0f))
                st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
        }
        if (st != LX_OK)
            clear_buffers(b, true);
    }
    if (idx != idx_buf)
        free(idx);
    return st;
}

lx_status lx_baker_apply(const lx_baker *b, uint32_t map_index, lx_image *out)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    if (map_index >= b->map_count)
        return lx_fail(LX_ERR_INVALID, "lightmap %u out of range (count %u)", map_index,
                       b->map_count);
    /* a tiled baker builds the map's tile again (the baker is used from
     * one thread at a time: its cache of texel maps may change here) */
    lx_status need = lx_bake_tile_need((lx_baker *)b, map_index);
    if (need != LX_OK)
        return need;
    const lx_lightmap *map = &b->maps[map_index];
    int w = map->info.width, h = map->info.height;
    if (!out || out->width != w || out->height != h || out->channels != 3 || !out->data)
        return lx_fail(LX_ERR_INVALID, "lightmap '%s': output must be a %dx%d RGB image", map->name,
                       w, h);
    size_t pixels = (size_t)w * h;
    const float *rt = map->realtime; /* NULL: no dynamic light yet, zero */
    int threads = lx_thread_count(b->desc.threads);
    /* lx_dilate writes the mask it grows: a copy, made before out is */
    uint8_t *mask = NULL;
    if (b->desc.padding > 0) {
        if (!(mask = malloc(pixels)))
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for the %dx%d padding mask",
                           map->name, w, h);
        memcpy(mask, map->mask, pixels);
    }
    /* rows, then tiles, in parallel: each pixel is written by one
     * iteration */
#pragma omp parallel num_threads(threads)
    {
#pragma omp for schedule(static)
        for (int y = 0; y < h; y++)
            memset(out->data + (size_t)y * w * 3, 0, (size_t)w * 3 * sizeof(float));
#pragma omp for schedule(static)
        for (int tile = 0; tile < (int)map->tile_count; tile++)
            for (uint32_t i = map->tile_start[tile]; i < map->tile_start[tile + 1]; i++) {
                const lx_texel *t = &map->texels[i];
                size_t p = t->pixel;
                lx_vec3 e = lx_v3(map->baked[3 * p] + (rt ? rt[3 * p] : 0.0f),
                                  map->baked[3 * p + 1] + (rt ? rt[3 * p + 1] : 0.0f),
                                  map->baked[3 * p + 2] + (rt ? rt[3 * p + 2] : 0.0f));
                if (b->desc.quantity == LX_QUANTITY_RADIANCE)
                    e = lx_scale(lx_mul(e, map->albedo[i]), 1.0f / LX_PI);
                out->data[3 * p] = e.x;
                out->data[3 * p + 1] = e.y;
                out->data[3 * p + 2] = e.z;
            }
    }
    lx_status st = LX_OK;
    if (mask) {
        lx_dilate_desc dd = {.threads = b->desc.threads,
                             .progress = b->desc.progress,
                             .progress_user = b->desc.progress_user};
        st = lx_dilate(out->data, mask, w, h, 3, b->desc.padding, &dd);
        free(mask);
    } else if (b->desc.progress && !b->desc.progress(b->desc.progress_user, 1.0f)) {
        st = lx_fail(LX_ERR_CANCELLED, "apply cancelled");
    }
    /* after the padding: bilinear lookups at a seam read padding texels */
    if (st == LX_OK && map->stitch)
        st = lx_seam_stitch_apply(map->stitch, out->data, 3, map->name);
    if (st != LX_OK) {
        if (st != LX_ERR_CANCELLED) {
            char what[300];
            snprintf(what, sizeof what, "lightmap '%s'", map->name);
            lx_error_prefix(what);
        }
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int y = 0; y < h; y++)
            memset(out->data + (size_t)y * w * 3, 0, (size_t)w * 3 * sizeof(float));
    }
    return st;
}

lx_status lx_baker_apply_alloc(const lx_baker *b, uint32_t map, lx_image *out)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    if (map >= b->map_count)
        return lx_fail(LX_ERR_INVALID, "lightmap %u out of range (count %u)", map, b->map_count);
    lx_status st = lx_image_alloc(out, b->maps[map].info.width, b->maps[map].info.height, 3);
    if (st != LX_OK)
        return st;
    st = lx_baker_apply(b, map, out);
    if (st != LX_OK)
        lx_image_free(out);
    return st;
}

lx_status lx_baker_apply_rgba8(const lx_baker *b, uint32_t map, float exposure, bool srgb,
                               uint8_t *out)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    lx_image img;
    lx_status st = lx_baker_apply_alloc(b, map, &img);
    if (st != LX_OK)
        return st;
    size_t pixels = (size_t)img.width * img.height;
    for (size_t p = 0; p < pixels; p++) {
        for (int c = 0; c < 3; c++) {
            float v = lx_saturate(img.data[3 * p + c] * exposure);
            if (srgb)
                v = lx_linear_to_srgb(v);
            out[4 * p + c] = (uint8_t)(v * 255.0f + 0.5f);
        }
        out[4 * p + 3] = b->maps[map].mask[p] ? 255 : 0;
    }
    lx_image_free(&img);
    return LX_OK;
}

void lx_baker_meter_ev100(const lx_baker *b, float *ev100, bool *lit)
{
    /* what a preview shows: radiance E * albedo / pi, or for irradiance
     * the radiance of a white Lambertian surface, E / pi */
    const double scale = 1.0 / LX_PI;
    double sum = 0.0;
    uint64_t n = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        if (lx_bake_tile_need((lx_baker *)b, m) != LX_OK) {
            /* a tiled baker that cannot build the map again: meter
             * nothing rather than part of the scene */
            *lit = false;
            *ev100 = 0.0f;
            return;
        }
        for (uint32_t i = 0; i < map->info.used_texels; i++) {
            const lx_texel *t = &map->texels[i];
            size_t p = (size_t)t->pixel * 3;
            const float *rt = map->realtime; /* NULL reads as zero */
            float e[3] = {map->baked[p] + (rt ? rt[p] : 0.0f),
                          map->baked[p + 1] + (rt ? rt[p + 1] : 0.0f),
                          map->baked[p + 2] + (rt ? rt[p + 2] : 0.0f)};
            if (b->desc.quantity == LX_QUANTITY_RADIANCE) {
                e[0] *= map->albedo[i].x;
                e[1] *= map->albedo[i].y;
                e[2] *= map->albedo[i].z;
            }
            sum += lx_luminance(e) * scale;
            n++;
        }
    }
    double mean = n ? sum / (double)n : 0.0;
    *lit = mean > 0.0 && isfinite(mean);
    *ev100 = *lit ? lx_ev100_from_luminance(mean) : 0.0f;
}

bool lx_baker_texel(const lx_baker *b, uint32_t map_index, int x, int y, lx_texel_sample *out)
{
    if (map_index >= b->map_count)
        return false;
    const lx_lightmap *map = &b->maps[map_index];
    if (x < 0 || y < 0 || x >= map->info.width || y >= map->info.height)
        return false;
    uint32_t pixel = (uint32_t)y * (uint32_t)map->info.width + (uint32_t)x;
    if (!map->mask[pixel] || lx_bake_tile_need((lx_baker *)b, map_index) != LX_OK)
        return false;
    /* texels are stored by tile; find the tile, then scan its few texels */
    int tiles_x = (map->info.width + LX_TILE - 1) / LX_TILE;
    uint32_t tile = (uint32_t)(y / LX_TILE) * (uint32_t)tiles_x + (uint32_t)(x / LX_TILE);
    for (uint32_t i = map->tile_start[tile]; i < map->tile_start[tile + 1]; i++)
        if (map->texels[i].pixel == pixel) {
            out->position = map->world_position[i];
            out->normal = map->world_normal[i];
            out->geometric_normal = map->world_geometric_normal[i];
            out->mesh = map->texels[i].mesh;
            out->triangle = map->texels[i].triangle;
            out->node = map->texels[i].node;
            return true;
        }
    return false;
}
