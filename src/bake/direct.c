/* Direct lighting of texels: seed 000's DynamicLight kernel (every texel,
 * every light, shadow test toward the light, the "dynamic blur" from the
 * nearest occluder) with Filament's physical light model (seed 001), and
 * Embree occlusion queries in place of the seed's every-triangle loop.
 * Work is split into fixed tiles, so the sums are the same for any number
 * of threads. */
#include "bake_internal.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

typedef struct pending_ray {
    uint32_t texel; /* index within the tile */
    lx_vec3 illuminance;
} pending_ray;

/* Shadow ray from texel position p toward a light: the origin is lifted off
 * the surface along the geometric normal, on the light's side, by a
 * scale-aware bias, so the ray neither re-hits its own triangle (acne) nor
 * starts behind a wall it touches (leaks). */
static lx_ray shadow_ray(const lx_baker *b, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e)
{
    lx_vec3 side = lx_dot(ng, e->to_light) >= 0.0f ? ng : lx_neg(ng);
    float bias = b->bias + 4e-6f * lx_max_abs_component(p);
    lx_ray r;
    r.origin = lx_madd(p, side, bias);
    r.dir = e->to_light;
    r.tmin = 0.0f;
    r.tmax = isfinite(e->distance) ? e->distance - 2.0f * bias : INFINITY;
    if (r.tmax < 0.0f)
        r.tmax = 0.0f;
    return r;
}

static void light_tile(const lx_baker *b, const lx_lightmap *map, uint32_t first, uint32_t count,
                       const lx_light *light, lx_vec3 *accum)
{
    lx_ray rays[LX_TILE * LX_TILE];
    pending_ray pending[LX_TILE * LX_TILE];
    uint8_t occluded[LX_TILE * LX_TILE];
    uint32_t n = 0;
    for (uint32_t k = 0; k < count; k++) {
        uint32_t i = first + k;
        lx_light_eval e;
        bool direct = lx_light_evaluate(light, map->world_position[i], map->world_normal[i], &e);
        accum[k] = lx_add(accum[k], e.ambient);
        if (!direct)
            continue;
        if (light->shadow == LX_SHADOW_NONE) {
            accum[k] = lx_add(accum[k], e.illuminance);
            continue;
        }
        rays[n] = shadow_ray(b, map->world_position[i], map->world_geometric_normal[i], &e);
        pending[n] = (pending_ray){k, e.illuminance};
        if (light->shadow == LX_SHADOW_BLUR) {
            /* seed 000: blur = nearest occluder distance / light distance */
            float d_occ = lx_tracer_nearest_distance(b->tracer, &rays[n]);
            float d_light = isfinite(e.distance) ? e.distance : b->scene_diagonal;
            float vis = isfinite(d_occ) ? lx_light_blur_visibility(light, d_occ, d_light) : 1.0f;
            accum[k] = lx_add(accum[k], lx_scale(e.illuminance, vis));
            continue;
        }
        n++;
    }
    if (n == 0)
        return;
    lx_tracer_occluded_batch(b->tracer, rays, n, true, occluded);
    for (uint32_t j = 0; j < n; j++)
        if (!occluded[j])
            accum[pending[j].texel] = lx_add(accum[pending[j].texel], pending[j].illuminance);
}

lx_status lx_bake_lights(lx_baker *b, const uint32_t *lights, uint32_t light_count, lx_vec3 ambient,
                         bool to_realtime, float progress_base, float progress_span)
{
    if (b->tracer_dirty) {
        lx_status st = lx_tracer_commit(b->tracer);
        if (st != LX_OK)
            return st;
        b->tracer_dirty = false;
    }
    /* One parallel loop over every tile of every map: fork and join once
     * per pass, which matters for the per-frame update. */
    uint32_t *map_first_tile = malloc(sizeof(uint32_t) * (b->map_count + 1));
    if (!map_first_tile)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    uint64_t total_work = 0;
    map_first_tile[0] = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        map_first_tile[m + 1] = map_first_tile[m] + b->maps[m].tile_count;
        /* progress counts texels, plus one per tile so empty tiles count */
        total_work += b->maps[m].info.used_texels + b->maps[m].tile_count;
    }
    int tiles = (int)map_first_tile[b->map_count];
    int threads = lx_thread_count(b->desc.threads);
    bool report = b->desc.progress != NULL;
    volatile int cancelled = 0;
    uint64_t done_work = 0;

#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int global = 0; global < tiles; global++) {
        if (cancelled)
            continue;
        uint32_t m = 0;
        while (map_first_tile[m + 1] <= (uint32_t)global)
            m++;
        const lx_lightmap *map = &b->maps[m];
        uint32_t tile = (uint32_t)global - map_first_tile[m];
        float *target = to_realtime ? map->realtime : map->baked;
        uint32_t first = map->tile_start[tile];
        uint32_t count = map->tile_start[tile + 1] - first;
        if (count) {
            lx_vec3 accum[LX_TILE * LX_TILE];
            for (uint32_t k = 0; k < count; k++)
                accum[k] = ambient;
            for (uint32_t l = 0; l < light_count; l++)
                light_tile(b, map, first, count, &b->lights[lights[l]], accum);
            /* every texel belongs to one tile: plain stores, no clearing */
            for (uint32_t k = 0; k < count; k++) {
                float *px = target + (size_t)map->texels[first + k].pixel * 3;
                px[0] = accum[k].x;
                px[1] = accum[k].y;
                px[2] = accum[k].z;
            }
        }
        if (report) {
            uint64_t done;
#pragma omp atomic capture
            done = done_work += count + 1;
            if (omp_get_thread_num() == 0 && (global & 15) == 0) {
                double f = (double)done / (double)total_work;
                if (!b->desc.progress(b->desc.progress_user,
                                      progress_base + progress_span * (float)f))
                    cancelled = 1;
            }
        }
    }
    free(map_first_tile);
    if (cancelled)
        return lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    if (report && !b->desc.progress(b->desc.progress_user, progress_base + progress_span))
        return lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    return LX_OK;
}
