/* The bake under a memory limit: lightmaps baked tile by tile, a tile
 * being a run of whole lightmaps whose working set (texel maps, the
 * gathers' per-texel buffers, the denoiser's scratch) fits beside what
 * stays in memory for the whole bake (every map's mask and baked light,
 * the bounces' sources, the scene and its BVH). Out-of-core lightmapping
 * as production bakers do it (Bakery's and Unity's "tiled baking" bound
 * the texels in flight, not the lightmaps' total): the texel maps of a
 * tile are rebuilt from a copy of the scene whenever a pass needs them
 * again, so each pass reads every map's resident light and works on one
 * tile's texels at a time. Every texel's work is keyed by (map, texel)
 * and every sum runs in the same order whatever the tiles, so the bytes
 * equal the untiled bake's. */
#include "bake_internal.h"
#include "core/internal.h"

#include <omp.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the per-texel buffers ------------------------------------------------
 * Bytes a lightmap pixel (covered texels are at most the pixels). Each
 * line names a buffer, what it takes, how long it lives and when it
 * exists. docs/bake.md's table is this list. A new per-texel buffer is
 * one more line and, when it only exists under an option, one more flag. */
enum {
    WHEN_ALWAYS = 0,
    WHEN_ALBEDO = 1u << 0,      /* radiance output, or surfaces kept (below) */
    WHEN_GI = 1u << 1,          /* bounces > 0 */
    WHEN_HORIZON = 1u << 2,     /* a material on the map has a height */
    WHEN_DYNAMIC = 1u << 3,     /* the scene has dynamic lights */
    WHEN_DENOISE = 1u << 4,     /* the bake denoises something */
    WHEN_KEEP = 1u << 5,        /* denoise indirect: parts kept apart */
    WHEN_PADDING = 1u << 6,     /* padding > 0 */
    WHEN_SURFACES = 1u << 7,    /* bounces, the dynamic bounce or probes */
    WHEN_DIRECTIONAL = 1u << 8, /* directional lightmaps */
    WHEN_SUPERSAMPLE = 1u << 9, /* supersample > 1 */
    WHEN_DYN_BOUNCE = 1u << 10, /* dynamic_bounce_samples > 0 */
    WHEN_PROBES = 1u << 11,     /* desc.probes */
    WHEN_EMISSIVE_TEXTURE = 1u << 12, /* an emissive material has a texture */
    WHEN_TEXEL_EMISSION = 1u << 13, /* surfaces kept, or an emissive texture */
    WHEN_LIFT = 1u << 14,           /* a smooth-shaded mesh */
    WHEN_EDGE = 1u << 15,           /* edge supersampling */
    WHEN_NORMAL_MAP = 1u << 16,     /* a normal map, without directional data */
};

/* Where a buffer lives: the whole bake, a tile's texel maps (while the
 * tile is in memory), or one step's scratch beside them (the steps do not
 * overlap: a tile takes the largest). */
typedef enum buffer_life {
    LIFE_RESIDENT,
    LIFE_TEXEL_MAP,
    LIFE_BUILD,   /* rasterizing a texel map */
    LIFE_GATHER,  /* a bounce's gathers */
    LIFE_FILL,    /* filling invalid texels */
    LIFE_DENOISE, /* denoising a map */
    LIFE_APPLY,   /* padding */
    LIFE_COUNT
} buffer_life;

/* What a line's bytes are multiplied by. */
typedef enum buffer_scale {
    PER_TEXEL,
    PER_POINT,       /* supersampling's N x N points of a texel */
    PER_BOUNCE_RAY,  /* the dynamic bounce's rays of a texel */
} buffer_scale;

typedef struct texel_buffer {
    const char *name;
    uint32_t bytes;
    buffer_scale scale;
    buffer_life life;
    uint32_t when; /* every flag must hold */
} texel_buffer;

static const texel_buffer texel_buffers[] = {
    {"coverage mask", 1, PER_TEXEL, LIFE_RESIDENT, WHEN_ALWAYS},
    {"baked light (RGB float)", 12, PER_TEXEL, LIFE_RESIDENT, WHEN_ALWAYS},
    {"real-time light (RGB float)", 12, PER_TEXEL, LIFE_RESIDENT, WHEN_DYNAMIC},
    {"directional: L1 SH of the baked light (12 floats)", 48, PER_TEXEL, LIFE_RESIDENT,
     WHEN_DIRECTIONAL},
    {"bounces: validity (kept for the denoiser)", 1, PER_TEXEL, LIFE_RESIDENT, WHEN_GI},
    {"bounces: each texel's variance (the denoiser's guide)", 4, PER_TEXEL, LIFE_RESIDENT,
     WHEN_GI | WHEN_KEEP},
    {"bounces: exitant radiance of the last and the next bounce", 24, PER_TEXEL, LIFE_RESIDENT,
     WHEN_GI},
    {"emitters: textured emission", 12, PER_TEXEL, LIFE_RESIDENT, WHEN_EMISSIVE_TEXTURE},
    {"denoising: the direct light kept", 12, PER_TEXEL, LIFE_RESIDENT, WHEN_GI | WHEN_KEEP},
    {"denoising: the sampled direct light (shadowed sky, soft shadows, emitters) and its "
     "variance", 16,
     PER_TEXEL, LIFE_RESIDENT, WHEN_KEEP},
    {"denoising: the direct directional data kept", 48, PER_TEXEL, LIFE_RESIDENT,
     WHEN_GI | WHEN_KEEP | WHEN_DIRECTIONAL},
    {"dynamic bounce: valid mask and sources", 13, PER_TEXEL, LIFE_RESIDENT,
     WHEN_DYN_BOUNCE | WHEN_DYNAMIC},
    {"dynamic bounce: the inside flag", 1, PER_TEXEL, LIFE_RESIDENT,
     WHEN_DYN_BOUNCE | WHEN_DYNAMIC},
    {"dynamic bounce: each ray's cached hit", 12, PER_BOUNCE_RAY, LIFE_RESIDENT,
     WHEN_DYN_BOUNCE | WHEN_DYNAMIC},
    {"light probes: the surfaces' exitant radiance", 12, PER_TEXEL, LIFE_RESIDENT, WHEN_PROBES},
    {"texel map: texel record (pixel, mesh, triangle, node)", 16, PER_TEXEL, LIFE_TEXEL_MAP,
     WHEN_ALWAYS},
    {"texel map: world position, shading and geometric normal", 36, PER_TEXEL, LIFE_TEXEL_MAP,
     WHEN_ALWAYS},
    {"edge supersampling: shadow records, edge masks and the page's texel index", 20, PER_TEXEL,
     LIFE_TEXEL_MAP, WHEN_EDGE},
    {"texel map: tile offsets", 1, PER_TEXEL, LIFE_TEXEL_MAP, WHEN_ALWAYS},
    {"texel map: the vertex normal under a normal map (the bounces gather about it)", 12,
     PER_TEXEL, LIFE_TEXEL_MAP, WHEN_NORMAL_MAP},
    {"texel map: lift to the smooth surface (shadow terminator)", 12, PER_TEXEL, LIFE_TEXEL_MAP,
     WHEN_LIFT},
    {"texel map: albedo", 12, PER_TEXEL, LIFE_TEXEL_MAP, WHEN_ALBEDO},
    {"texel map: emission", 12, PER_TEXEL, LIFE_TEXEL_MAP, WHEN_TEXEL_EMISSION},
    {"texel map: horizon record (layers, AO, frame)", (uint32_t)sizeof(lx_texel_horizon),
     PER_TEXEL, LIFE_TEXEL_MAP, WHEN_HORIZON},
    {"supersampling: each point's position, normals and coverage", 37, PER_POINT,
     LIFE_TEXEL_MAP, WHEN_SUPERSAMPLE},
    {"building: raster scratch (12 of it becomes the baked buffer)", 17, PER_TEXEL, LIFE_BUILD,
     WHEN_ALWAYS},
    {"bounces: this bounce's irradiance and the inside flag", 13, PER_TEXEL, LIFE_GATHER,
     WHEN_GI},
    {"bounces: this bounce's directional data", 48, PER_TEXEL, LIFE_GATHER,
     WHEN_GI | WHEN_DIRECTIONAL},
    {"bounces: filling invalid texels, beside the gather's buffers", 17 + 13, PER_TEXEL,
     LIFE_FILL, WHEN_GI},
    {"denoising: guides, scratch and the indirect part", 29 + 80 + 12, PER_TEXEL, LIFE_DENOISE,
     WHEN_DENOISE},
    {"denoising: a directional plane and its direct part (beside the above)", 12, PER_TEXEL,
     LIFE_DENOISE, WHEN_DENOISE | WHEN_DIRECTIONAL},
    {"padding: the mask's copy and frontiers", 9, PER_TEXEL, LIFE_APPLY, WHEN_PADDING},
};

lx_bake_texel_bytes lx_bake_texel_bytes_of(const lx_bake_desc *d, bool horizon,
                                           uint32_t scene_needs)
{
    bool gi = d->bounces > 0;
    uint32_t have = WHEN_ALWAYS;
    have |= (lx_bake_keeps_surfaces(d) || d->quantity == LX_QUANTITY_RADIANCE) ? WHEN_ALBEDO : 0;
    have |= lx_bake_keeps_surfaces(d) ? WHEN_SURFACES : 0;
    have |= gi ? WHEN_GI : 0;
    have |= horizon ? WHEN_HORIZON : 0;
    have |= scene_needs & LX_SCENE_NEEDS_DYNAMIC ? WHEN_DYNAMIC : 0;
    have |= scene_needs & LX_SCENE_NEEDS_EMISSIVE_TEXTURE ? WHEN_EMISSIVE_TEXTURE : 0;
    have |= scene_needs & LX_SCENE_NEEDS_LIFT ? WHEN_LIFT : 0;
    have |= lx_bake_edge_supersample(d) ? WHEN_EDGE : 0;
    have |= scene_needs & LX_SCENE_NEEDS_SMOOTH_NORMAL && d->directional == LX_DIRECTIONAL_OFF
                ? WHEN_NORMAL_MAP
                : 0;
    have |= (lx_bake_keeps_surfaces(d) || (scene_needs & LX_SCENE_NEEDS_EMISSIVE_TEXTURE))
                ? WHEN_TEXEL_EMISSION
                : 0;
    /* indirect without bounces still filters a sampled direct part */
    have |= d->denoise != LX_DENOISE_OFF ? WHEN_DENOISE : 0;
    have |= d->denoise == LX_DENOISE_INDIRECT ? WHEN_KEEP : 0;
    have |= d->padding > 0 ? WHEN_PADDING : 0;
    have |= d->directional != LX_DIRECTIONAL_OFF ? WHEN_DIRECTIONAL : 0;
    have |= d->supersample > 1 ? WHEN_SUPERSAMPLE : 0;
    have |= d->dynamic_bounce_samples > 0 ? WHEN_DYN_BOUNCE : 0;
    have |= d->probes ? WHEN_PROBES : 0;
    uint32_t strata_x, strata_y;
    lx_cosine_strata(d->dynamic_bounce_samples ? d->dynamic_bounce_samples : 1, &strata_x,
                     &strata_y);
    uint32_t scale[3] = {1, d->supersample > 1 ? (uint32_t)(d->supersample * d->supersample) : 0,
                         strata_x * strata_y};
    uint32_t life[LIFE_COUNT] = {0};
    for (size_t i = 0; i < sizeof texel_buffers / sizeof texel_buffers[0]; i++) {
        const texel_buffer *t = &texel_buffers[i];
        if ((t->when & have) == t->when)
            life[t->life] += t->bytes * scale[t->scale];
    }
    uint32_t step = 0;
    for (int k = LIFE_BUILD; k < LIFE_COUNT; k++)
        step = life[k] > step ? life[k] : step;
    lx_bake_texel_bytes out = {d->caller_bytes_per_texel + life[LIFE_RESIDENT],
                               life[LIFE_TEXEL_MAP] + step};
    return out;
}

uint32_t lx_bake_scene_needs(const lx_scene *scene)
{
    uint32_t needs = 0;
    for (uint32_t l = 0; l < scene->light_count; l++)
        if (scene->lights[l].dynamic)
            needs |= LX_SCENE_NEEDS_DYNAMIC;
    for (uint32_t k = 0; k < scene->material_count; k++) {
        const lx_material *m = &scene->materials[k];
        bool emits = m->emissive.x > 0.0f || m->emissive.y > 0.0f || m->emissive.z > 0.0f;
        needs |= emits ? LX_SCENE_NEEDS_EMISSION : 0;
        needs |= emits && m->emissive_map.width > 0 ? LX_SCENE_NEEDS_EMISSIVE_TEXTURE : 0;
        needs |= m->normal_map.width > 0 ? LX_SCENE_NEEDS_SMOOTH_NORMAL : 0;
    }
    for (uint32_t m = 0; m < scene->mesh_count && !(needs & LX_SCENE_NEEDS_LIFT); m++)
        needs |= lx_mesh_is_smooth(&scene->meshes[m]) ? LX_SCENE_NEEDS_LIFT : 0;
    return needs;
}

bool lx_mesh_is_smooth(const lx_mesh *mesh)
{
    if (!mesh->normals)
        return false;
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *i = &mesh->indices[3 * (size_t)t];
        lx_vec3 a = mesh->positions[i[0]], b = mesh->positions[i[1]], c = mesh->positions[i[2]];
        lx_vec3 g = lx_cross(lx_sub(b, a), lx_sub(c, a));
        float len = lx_length(g);
        if (!(len > 0.0f))
            continue;
        for (int k = 0; k < 3; k++) {
            lx_vec3 n = mesh->normals[i[k]];
            /* more than about half a degree off the plane's normal */
            if (fabsf(lx_dot(n, g)) < 0.99996f * lx_length(n) * len)
                return true;
        }
    }
    return false;
}

uint64_t lx_bake_scene_bytes(const lx_scene *scene, bool copy)
{
    uint64_t vertices = 0, triangles = 0, vertex_bytes = 0, textures = 0;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        const lx_mesh *mesh = &scene->meshes[m];
        uint64_t per = 24 + (mesh->tangents ? 16 : 0);
        for (int s = 0; s < LX_MAX_UV_SETS; s++)
            per += mesh->uv[s] ? 8 : 0;
        vertices += mesh->vertex_count;
        vertex_bytes += per * mesh->vertex_count;
        triangles += mesh->triangle_count;
    }
    for (uint32_t k = 0; k < scene->material_count; k++) {
        const lx_material *mat = &scene->materials[k];
        const lx_image *im[3] = {&mat->normal_map, &mat->base_color_map, &mat->emissive_map};
        for (int i = 0; i < 3; i++)
            textures += (uint64_t)(im[i]->width > 0 ? im[i]->width : 0) *
                        (uint64_t)(im[i]->height > 0 ? im[i]->height : 0) *
                        (uint64_t)(im[i]->channels > 0 ? im[i]->channels : 0) * 4;
    }
    /* Embree's copy of the world vertices (16 bytes padded) and triangles
     * (12), and its BVH (about 64 bytes a triangle at high quality); the
     * gathers' copy of UVs and indices is within the scene's size; the
     * texel footprints of a page's triangles (24, texel_map.c) */
    uint64_t bvh = vertices * 16 + triangles * (12 + 64 + 24);
    uint64_t own = vertex_bytes + triangles * 12 + textures;
    return bvh + own + (copy ? own : 0);
}

/* ---- tiles ------------------------------------------------------------------ */

/* Address space the run reserves beyond its buffers, made after this plan
 * and touched little or not at all, so that only an address-space limit
 * (RLIMIT_AS, ulimit -v) counts it: Embree's device maps 128 MiB when it
 * is made (rtcNewDevice; seen with strace -k), and each worker thread
 * beyond the first, of OpenMP's pool and of Embree's, takes a stack
 * (RLIMIT_STACK, glibc's default) and a glibc malloc arena (64 MiB
 * reserved on 64-bit systems); and 16 MiB of slack for the heap's own
 * overhead and the small allocations no table lists (a bake planned to
 * the byte ran out 4 MiB short). Without it a bake under ulimit -v passed
 * the plan and failed later, in a tile's rebuild or the denoiser. */
#define EMBREE_DEVICE_RESERVE ((uint64_t)128 << 20)
#define MALLOC_ARENA_RESERVE ((uint64_t)64 << 20)
#define HEAP_SLACK ((uint64_t)16 << 20)

static uint64_t reserved_address_space(int threads)
{
    struct rlimit stack;
    uint64_t stack_bytes = (uint64_t)8 << 20;
    if (getrlimit(RLIMIT_STACK, &stack) == 0 && stack.rlim_cur != RLIM_INFINITY)
        stack_bytes = (uint64_t)stack.rlim_cur;
    uint64_t extra_threads = threads > 1 ? 2 * (uint64_t)(threads - 1) : 0;
    return EMBREE_DEVICE_RESERVE + HEAP_SLACK +
           extra_threads * (stack_bytes + MALLOC_ARENA_RESERVE);
}

/* Decides whether the lightmaps fit the memory limit together or are
 * baked in tiles (b->tiled), and fails with one line when even the part
 * that stays for the whole bake and the largest lightmap's working set do
 * not fit. */
lx_status lx_bake_plan_memory(lx_baker *b, const lx_scene *scene, const lx_tile_candidate *c,
                              uint32_t count, uint32_t needs)
{
    lx_memory_limit ml;
    uint64_t avail = lx_memory_available(&ml);
    bool asked = b->desc.memory_limit > 0 && b->desc.memory_limit < avail;
    uint64_t limit = asked ? b->desc.memory_limit : avail;
    b->memory_limit = limit;
    uint64_t together = lx_bake_scene_bytes(scene, false);
    uint64_t resident = lx_bake_scene_bytes(scene, true), largest = 0;
    if (!asked && ml.bound == LX_MEMORY_ADDRESS_SPACE) {
        uint64_t reserved = reserved_address_space(lx_thread_count(b->desc.threads));
        together += reserved;
        resident += reserved;
    }
    uint32_t largest_at = 0;
    for (uint32_t i = 0; i < count; i++) {
        lx_bake_texel_bytes tb = lx_bake_texel_bytes_of(&b->desc, c[i].horizon, needs);
        together += c[i].pixels * (tb.resident + tb.tile);
        resident += c[i].pixels * tb.resident;
        if (c[i].pixels * tb.tile > largest) {
            largest = c[i].pixels * tb.tile;
            largest_at = i;
        }
    }
    b->tiled = together > limit;
    if (!b->tiled || resident + largest <= limit)
        return LX_OK;
    char need[32], keep[32], tile[32], bound[200];
    lx_format_bytes(resident + largest, need, sizeof need);
    lx_format_bytes(resident, keep, sizeof keep);
    lx_format_bytes(largest, tile, sizeof tile);
    if (asked) {
        char lim[32];
        lx_format_bytes(limit, lim, sizeof lim);
        snprintf(bound, sizeof bound, "the memory limit asked for is %s", lim);
    } else {
        lx_memory_limit_describe(&ml, bound, sizeof bound);
    }
    return lx_fail(LX_ERR_NOMEM,
                   "%s: baking %u lightmap%s (%s kept for the whole bake, %s for lightmap '%s' "
                   "alone) needs %s of memory, %s",
                   scene->path, count, count == 1 ? "" : "s", keep, tile, c[largest_at].name, need,
                   bound);
}



static uint64_t map_pixels(const lx_lightmap *m)
{
    return (uint64_t)m->info.width * (uint64_t)m->info.height;
}

lx_status lx_bake_plan_tiles(lx_baker *b, const lx_scene *scene, uint32_t needs)
{
    uint64_t resident = lx_bake_scene_bytes(scene, b->tiled);
    for (uint32_t m = 0; m < b->map_count; m++) {
        lx_bake_texel_bytes tb = lx_bake_texel_bytes_of(&b->desc, b->maps[m].horizon_page, needs);
        resident += map_pixels(&b->maps[m]) * tb.resident;
    }
    free(b->tile_first_map);
    b->tile_first_map = malloc(sizeof(uint32_t) * (b->map_count + 2));
    if (!b->tile_first_map)
        return lx_fail(LX_ERR_NOMEM, "out of memory planning the bake's tiles");
    b->tile_count = 0;
    b->tile_first_map[0] = 0;
    if (!b->tiled) {
        b->tile_count = 1;
        b->tile_first_map[1] = b->map_count;
        return LX_OK;
    }
    uint64_t room = b->memory_limit > resident ? b->memory_limit - resident : 0, used = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        lx_bake_texel_bytes tb = lx_bake_texel_bytes_of(&b->desc, b->maps[m].horizon_page, needs);
        uint64_t need = map_pixels(&b->maps[m]) * tb.tile;
        if (m > b->tile_first_map[b->tile_count] && used + need > room) {
            b->tile_first_map[++b->tile_count] = m;
            used = 0;
        }
        used += need;
    }
    b->tile_first_map[++b->tile_count] = b->map_count;
    return LX_OK;
}

void lx_bake_tile_share(const lx_baker *b, uint32_t t, float from, float to, float *tfrom,
                        float *tto)
{
    uint64_t before = 0, in = 0, total = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        uint64_t p = map_pixels(&b->maps[m]) + 1;
        total += p;
        if (m < b->tile_first_map[t])
            before += p;
        else if (m < b->tile_first_map[t + 1])
            in += p;
    }
    double span = (double)(to - from);
    *tfrom = from + (float)(span * (double)before / (double)(total ? total : 1));
    *tto = t + 1 == b->tile_count ? to
                                  : from + (float)(span * (double)(before + in) /
                                                   (double)(total ? total : 1));
}

bool lx_bake_report(const lx_baker *b, float f)
{
    return !b->desc.progress || b->desc.progress(b->desc.progress_user, f);
}

/* ---- walking the texel tiles of the maps in memory -------------------------- */

lx_status lx_tile_walk_begin(const lx_baker *b, float base, float span, int every,
                             lx_tile_walk *w)
{
    memset(w, 0, sizeof *w);
    w->b = b;
    w->base = base;
    w->span = span;
    w->every = every > 0 ? every : 1;
    w->map_first_tile = malloc(sizeof(uint32_t) * (b->map_count + 1));
    if (!w->map_first_tile)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    w->map_first_tile[0] = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        /* a map out of memory has no tiles */
        w->map_first_tile[m + 1] = w->map_first_tile[m] + map->tile_count;
        if (map->loaded)
            w->total_work += map->info.used_texels + map->tile_count;
    }
    w->tiles = (int)w->map_first_tile[b->map_count];
    return LX_OK;
}

void lx_tile_walk_at(const lx_tile_walk *w, int global, uint32_t *map, uint32_t *first,
                     uint32_t *count)
{
    uint32_t m = 0;
    while (w->map_first_tile[m + 1] <= (uint32_t)global)
        m++;
    const lx_lightmap *lm = &w->b->maps[m];
    uint32_t tile = (uint32_t)global - w->map_first_tile[m];
    *map = m;
    *first = lm->tile_start[tile];
    *count = lm->tile_start[tile + 1] - *first;
}

void lx_tile_walk_done(lx_tile_walk *w, int global, uint32_t count)
{
    const lx_baker *b = w->b;
    if (!b->desc.progress || w->quiet)
        return;
    uint64_t done;
#pragma omp atomic capture
    done = w->done_work += count + 1;
    if (omp_get_thread_num() == 0 && global % w->every == 0) {
        double f = (double)done / (double)(w->total_work ? w->total_work : 1);
        if (!b->desc.progress(b->desc.progress_user, w->base + w->span * (float)f))
            w->cancelled = 1;
    }
}

lx_status lx_tile_walk_end(lx_tile_walk *w)
{
    free(w->map_first_tile);
    w->map_first_tile = NULL;
    if (w->cancelled)
        return lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    return LX_OK;
}

void lx_bake_map_unload(lx_lightmap *map)
{
    /* what stays resident is set aside, the rest freed as a map is */
    lx_lightmap keep = *map;
    map->name = NULL;
    map->mask = NULL;
    map->baked = map->realtime = map->sh = NULL;
    map->gi_valid = NULL;
    map->gi_variance = NULL;
    map->sampled = NULL;
    map->sampled_variance = NULL;
    lx_texel_map_free(map);
    map->name = keep.name;
    map->info = keep.info;
    map->mask = keep.mask;
    map->baked = keep.baked;
    map->realtime = keep.realtime;
    map->sh = keep.sh;
    map->gi_valid = keep.gi_valid;
    map->gi_variance = keep.gi_variance;
    map->sampled = keep.sampled;
    map->sampled_variance = keep.sampled_variance;
    map->horizon_page = keep.horizon_page;
    map->loaded = false;
}

/* Builds map m again from its page, keeping its resident buffers. */
static lx_status map_load(lx_baker *b, uint32_t m)
{
    lx_lightmap *map = &b->maps[m];
    const lx_tile_page *pg = &b->pages[m];
    lx_page_spec page = {map->name, pg->width, pg->height, pg->nodes, pg->node_count};
    lx_bake_desc d = b->desc;
    d.progress = NULL; /* the pass reports; a rebuild is part of it */
    lx_lightmap fresh;
    lx_log_mute(true); /* its warnings were given when it was first built */
    lx_status st = lx_texel_map_build(b->tile_scene, &page, &d, (lx_texel_progress){0, 0},
                                      b->horizon_materials, &fresh);
    lx_log_mute(false);
    if (st == LX_OK && (fresh.info.width != map->info.width ||
                        fresh.info.height != map->info.height ||
                        fresh.info.used_texels != map->info.used_texels))
        st = lx_fail(LX_ERR_INVALID, "lightmap '%s': rebuilt with %u texels where it had %u",
                     map->name, fresh.info.used_texels, map->info.used_texels);
    if (st != LX_OK) {
        lx_texel_map_free(&fresh);
        return st;
    }
    /* the resident parts stay where callers hold them */
    free(fresh.name);
    free(fresh.mask);
    free(fresh.baked);
    free(fresh.realtime);
    free(fresh.sh);
    free(fresh.gi_valid);
    free(fresh.gi_variance);
    free(fresh.sampled);
    free(fresh.sampled_variance);
    fresh.name = map->name;
    fresh.info = map->info;
    fresh.mask = map->mask;
    fresh.baked = map->baked;
    fresh.realtime = map->realtime;
    fresh.sh = map->sh;
    fresh.gi_valid = map->gi_valid;
    fresh.gi_variance = map->gi_variance;
    fresh.sampled = map->sampled;
    fresh.sampled_variance = map->sampled_variance;
    fresh.horizon_page = map->horizon_page;
    fresh.loaded = true;
    *map = fresh;
    /* the faces double-sided triangles bake, as when first built */
    if (b->sides_decided)
        lx_bake_sides_apply(b, map);
    return LX_OK;
}

lx_status lx_bake_tile_need(lx_baker *b, uint32_t map)
{
    if (map >= b->map_count || b->maps[map].loaded)
        return LX_OK;
    if (b->loaded_tile != UINT32_MAX) {
        for (uint32_t m = b->tile_first_map[b->loaded_tile];
             m < b->tile_first_map[b->loaded_tile + 1]; m++)
            lx_bake_map_unload(&b->maps[m]);
        b->loaded_tile = UINT32_MAX;
    }
    uint32_t t = 0;
    while (b->tile_first_map[t + 1] <= map)
        t++;
    lx_status st = LX_OK;
    for (uint32_t m = b->tile_first_map[t]; m < b->tile_first_map[t + 1] && st == LX_OK; m++)
        st = map_load(b, m);
    /* samples inside geometry move out, as when the maps were first built
     * (before the tracer exists, lx_baker_create does it) */
    if (st == LX_OK && b->tracer) {
        lx_log_mute(true);
        st = lx_bake_straddle(b, 0.0f, 0.0f, false);
        lx_log_mute(false);
    }
    if (st != LX_OK) {
        for (uint32_t m = b->tile_first_map[t]; m < b->tile_first_map[t + 1]; m++)
            lx_bake_map_unload(&b->maps[m]);
        char what[300];
        snprintf(what, sizeof what, "rebuilding lightmap '%s' for its tile", b->maps[map].name);
        lx_error_prefix(what);
        return st;
    }
    b->loaded_tile = t;
    return LX_OK;
}

lx_status lx_bake_scene_copy(const lx_scene *s, lx_scene **out)
{
    lx_scene *c;
    lx_status st = lx_scene_create(s->path, &c);
    if (st != LX_OK)
        return st;
    for (uint32_t k = 0; k < s->material_count && st == LX_OK; k++)
        st = lx_scene_add_material(c, &s->materials[k], NULL);
    for (uint32_t k = 0; k < s->mesh_count && st == LX_OK; k++) {
        st = lx_scene_add_mesh(c, &s->meshes[k], NULL);
        /* adding renormalizes the normals (a unit vector may move by an
         * ulp): the copy keeps the very floats the untiled bake reads */
        const lx_mesh *from = &s->meshes[k];
        if (st == LX_OK && from->normals)
            memcpy(c->meshes[k].normals, from->normals, sizeof(lx_vec3) * from->vertex_count);
    }
    for (uint32_t k = 0; k < s->node_count && st == LX_OK; k++) {
        st = lx_scene_add_node(c, s->nodes[k].name, &s->nodes[k].world, s->nodes[k].meshes,
                               s->nodes[k].mesh_count, NULL);
        if (st == LX_OK)
            c->nodes[k].bake = s->nodes[k].bake;
    }
    if (st != LX_OK) {
        lx_scene_destroy(c);
        char what[300];
        snprintf(what, sizeof what, "%s: keeping the scene for a tiled bake", s->path);
        lx_error_prefix(what);
        return st;
    }
    *out = c;
    return LX_OK;
}
