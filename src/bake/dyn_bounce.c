/* One bounce of the dynamic lights' light for the real-time update
 * (lx_baker_update): the static bake's final gather (gi.c) with its ray
 * hits cached, so an update is a gather over memory and traces nothing -
 * the precomputed-transfer idea of Sloan, Kautz and Snyder ("Precomputed
 * Radiance Transfer", SIGGRAPH 2002) and of Enlighten-style real-time
 * radiosity (Martin and Einarsson, "A Real-Time Radiosity Architecture
 * for Video Games", SIGGRAPH 2010 course), with the lightmaps themselves
 * as the form-factor targets.
 *
 * Built once (at the first update that needs it, again after a node
 * moves): every texel's validity (lx_gi_texel_inside) and N =
 * desc.dynamic_bounce_samples stratified cosine-weighted rays
 * (lx_gather_ray, seeded by map, texel and sample), each kept as where it
 * landed: the hit surface's lightmap and continuous texel coordinates
 * (lx_gi_hit_texel), or nothing (escaped, a back face, a surface without a
 * lightmap). Each update: the dynamic lights' direct light is in the
 * real-time buffers; the sources are albedo / pi x that light at the valid
 * texels; each valid texel adds pi / N x the sum of the sources read at its
 * cached hits (lx_gi_lookup, bilinear over valid texels, as the static
 * gather reads them); invalid texels then take their valid neighbours'
 * light (lx_gi_fill_invalid). Each texel is summed in sample order by one
 * tile, so the bytes are the same for any thread count. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* lx_random dimensions apart from the static gathers' */
#define DYN_KEY 0x6800u

/* Where a cached gather ray landed; map UINT32_MAX: it brings nothing. */
typedef struct dyn_hit {
    uint32_t map;
    float fx, fy;
} dyn_hit;

typedef struct dyn_map {
    uint8_t *valid;   /* per pixel: covered and not inside geometry */
    uint8_t *invalid; /* per texel */
    float *source;    /* per pixel RGB: albedo / pi x the dynamic direct light */
    dyn_hit *hits;    /* per texel, cells each */
} dyn_map;

struct lx_dyn_bounce {
    uint32_t sx, sy, cells;
    dyn_map *maps;
    uint32_t map_count;
    uint32_t *map_first_tile;
    uint64_t invalid_texels;
};

void lx_dyn_bounce_free(lx_baker *b)
{
    lx_dyn_bounce *d = b->dyn;
    if (!d)
        return;
    for (uint32_t m = 0; d->maps && m < d->map_count; m++) {
        free(d->maps[m].valid);
        free(d->maps[m].invalid);
        free(d->maps[m].source);
        free(d->maps[m].hits);
    }
    free(d->maps);
    free(d->map_first_tile);
    free(d);
    b->dyn = NULL;
}

static lx_status dyn_build(lx_baker *b)
{
    if (b->tiled)
        return lx_fail(LX_ERR_NOMEM,
                       "the dynamic lights' bounce keeps every lightmap's texels in memory, and "
                       "this baker bakes its lightmaps in %u tiles to fit its memory limit: give "
                       "it more memory or no dynamic bounce samples",
                       b->tile_count);
    lx_dyn_bounce *d = calloc(1, sizeof *d);
    if (!d)
        return lx_fail(LX_ERR_NOMEM, "out of memory for the dynamic lights' bounce");
    b->dyn = d;
    lx_cosine_strata(b->desc.dynamic_bounce_samples, &d->sx, &d->sy);
    d->cells = d->sx * d->sy;
    d->map_count = b->map_count;
    uint64_t bytes = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        uint64_t pixels = (uint64_t)map->info.width * (uint64_t)map->info.height;
        bytes += pixels * 13 + (uint64_t)map->info.used_texels * (1 + sizeof(dyn_hit) * d->cells);
    }
    lx_status st = lx_check_memory(bytes, "the dynamic lights' bounce");
    if (st != LX_OK) {
        lx_dyn_bounce_free(b);
        return st;
    }
    d->maps = calloc(b->map_count + 1, sizeof(dyn_map));
    d->map_first_tile = malloc(sizeof(uint32_t) * (b->map_count + 1));
    if (!d->maps || !d->map_first_tile) {
        lx_dyn_bounce_free(b);
        return lx_fail(LX_ERR_NOMEM, "out of memory for the dynamic lights' bounce");
    }
    d->map_first_tile[0] = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        dyn_map *g = &d->maps[m];
        size_t pixels = (size_t)map->info.width * (size_t)map->info.height;
        size_t used = (size_t)map->info.used_texels + 1;
        g->valid = malloc(pixels);
        g->invalid = malloc(used);
        g->source = calloc(pixels * 3, sizeof(float));
        g->hits = malloc(sizeof(dyn_hit) * used * d->cells);
        if (!g->valid || !g->invalid || !g->source || !g->hits) {
            lx_status e = lx_fail(LX_ERR_NOMEM,
                                  "lightmap '%s': out of memory for the dynamic lights' bounce",
                                  map->name);
            lx_dyn_bounce_free(b);
            return e;
        }
        d->map_first_tile[m + 1] = d->map_first_tile[m] + map->tile_count;
    }
    int tiles = (int)d->map_first_tile[b->map_count];
    int threads = lx_thread_count(b->desc.threads);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int global = 0; global < tiles; global++) {
        uint32_t m = 0;
        while (d->map_first_tile[m + 1] <= (uint32_t)global)
            m++;
        const lx_lightmap *map = &b->maps[m];
        dyn_map *g = &d->maps[m];
        uint32_t tile = (uint32_t)global - d->map_first_tile[m];
        uint32_t first = map->tile_start[tile], count = map->tile_start[tile + 1] - first;
        for (uint32_t i = first; i < first + count; i++) {
            g->invalid[i] = lx_gi_texel_inside(b, m, i);
            lx_gather_frame f = lx_gather_frame_of(b, m, map, i);
            dyn_hit *out = g->hits + (size_t)i * d->cells;
            for (uint32_t k = 0; k < d->cells; k++) {
                lx_ray ray;
                lx_hit h;
                out[k].map = UINT32_MAX;
                out[k].fx = out[k].fy = 0.0f;
                if (!lx_gather_ray(&f, k, d->sx, d->sy, DYN_KEY, &ray))
                    continue;
                if (!lx_tracer_closest_kind(b->tracer, &ray, LX_RAY_GATHER, &h) ||
                    !lx_bake_hit_surface(b, ray.dir, &h))
                    continue;
                uint32_t mi;
                float fx, fy;
                if (lx_gi_hit_texel(b, h.node, h.mesh, h.triangle, h.u, h.v, &mi, &fx, &fy))
                    out[k] = (dyn_hit){mi, fx, fy};
            }
        }
    }
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        dyn_map *g = &d->maps[m];
        memcpy(g->valid, map->mask, (size_t)map->info.width * (size_t)map->info.height);
        for (uint32_t i = 0; i < map->info.used_texels; i++)
            if (g->invalid[i]) {
                g->valid[map->texels[i].pixel] = 0;
                d->invalid_texels++;
            }
    }
    return LX_OK;
}

lx_status lx_dyn_bounce_update(lx_baker *b)
{
    if (b->dyn && b->dyn_stale)
        lx_dyn_bounce_free(b);
    b->dyn_stale = false;
    lx_status st = LX_OK;
    if (!b->dyn && (st = dyn_build(b)) != LX_OK)
        return st;
    lx_dyn_bounce *d = b->dyn;
    int tiles = (int)d->map_first_tile[b->map_count];
    int threads = lx_thread_count(b->desc.threads);
    const float inv_pi = 1.0f / LX_PI;
    const double scale = LX_PI / (double)d->cells;
#pragma omp parallel num_threads(threads)
    {
        /* the sources, then the gathers (each reads every map's sources) */
        for (uint32_t m = 0; m < b->map_count; m++) {
            const lx_lightmap *map = &b->maps[m];
            const dyn_map *g = &d->maps[m];
#pragma omp for schedule(static)
            for (int64_t i = 0; i < (int64_t)map->info.used_texels; i++) {
                if (g->invalid[i])
                    continue;
                size_t p = 3 * (size_t)map->texels[i].pixel;
                lx_vec3 a = map->albedo[i];
                g->source[p] = a.x * inv_pi * map->realtime[p];
                g->source[p + 1] = a.y * inv_pi * map->realtime[p + 1];
                g->source[p + 2] = a.z * inv_pi * map->realtime[p + 2];
            }
        }
#pragma omp for schedule(dynamic, 4)
        for (int global = 0; global < tiles; global++) {
            uint32_t m = 0;
            while (d->map_first_tile[m + 1] <= (uint32_t)global)
                m++;
            lx_lightmap *map = &b->maps[m];
            const dyn_map *g = &d->maps[m];
            uint32_t tile = (uint32_t)global - d->map_first_tile[m];
            uint32_t first = map->tile_start[tile], count = map->tile_start[tile + 1] - first;
            for (uint32_t i = first; i < first + count; i++) {
                if (g->invalid[i])
                    continue;
                const dyn_hit *h = g->hits + (size_t)i * d->cells;
                double sum[3] = {0.0, 0.0, 0.0};
                for (uint32_t k = 0; k < d->cells; k++) {
                    if (h[k].map == UINT32_MAX)
                        continue;
                    lx_vec3 l = lx_gi_lookup(&b->maps[h[k].map], d->maps[h[k].map].valid,
                                             d->maps[h[k].map].source, h[k].fx, h[k].fy);
                    sum[0] += l.x, sum[1] += l.y, sum[2] += l.z;
                }
                float *px = map->realtime + 3 * (size_t)map->texels[i].pixel;
                px[0] += (float)(sum[0] * scale);
                px[1] += (float)(sum[1] * scale);
                px[2] += (float)(sum[2] * scale);
            }
        }
    }
    for (uint32_t m = 0; m < b->map_count && st == LX_OK && d->invalid_texels; m++)
        st = lx_gi_fill_invalid(&b->maps[m], d->maps[m].valid, d->maps[m].invalid,
                                b->maps[m].realtime, 3);
    return st;
}
