/* Direct lighting of texels: seed 000's DynamicLight kernel (every texel,
 * every light, shadow test toward the light, the "dynamic blur" from the
 * nearest occluder) with Filament's physical light model (seed 001), and
 * Embree occlusion queries in place of the seed's every-triangle loop.
 * Work is split into fixed tiles, so the sums are the same for any number
 * of threads. */
#include "bake_internal.h"
#include "core/internal.h"

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
lx_ray lx_shadow_ray(const lx_baker *b, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e)
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

/* Soft shadows from an area light: rays to stratified points on its
 * surface (jittered by a hash of map, texel, sample and light, so any
 * thread count gives the same points). The exact unshadowed illuminance is
 * scaled by the visible share of the points, each weighted by what it
 * contributes (cos at the texel x cos at the light / d^2): unoccluded, the
 * result is exactly the closed form. */
static float soft_visibility(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                             uint32_t texel, uint32_t light_index, const lx_light *light)
{
    uint32_t want = light->samples ? light->samples : 16u;
    uint32_t sx = (uint32_t)sqrtf((float)want);
    sx = sx ? sx : 1u;
    uint32_t sy = (want + sx - 1) / sx;
    lx_vec3 p = map->world_position[texel], n = map->world_normal[texel];
    lx_vec3 ng = map->world_geometric_normal[texel];
    uint32_t pixel = map->texels[texel].pixel;
    enum { BATCH = 64 };
    lx_ray rays[BATCH];
    float weight[BATCH];
    uint8_t occluded[BATCH];
    double total = 0.0, visible = 0.0;
    uint32_t k = 0, cells = sx * sy;
    while (k < cells) {
        uint32_t m = 0;
        for (; m < BATCH && k < cells; k++) {
            float u = ((float)(k % sx) + lx_random(map_index, pixel, k, 2 * light_index)) / sx;
            float v = ((float)(k / sx) + lx_random(map_index, pixel, k, 2 * light_index + 1)) / sy;
            lx_vec3 nq;
            lx_vec3 q = lx_area_light_point(light, u, v, &nq);
            lx_vec3 d = lx_sub(q, p);
            float d2 = lx_dot(d, d);
            /* cos at the texel times cos at the light over d^2 (d is not
             * unit); a linear tube's zero normal stands for its element's
             * sin(alpha), |axis x d| / |d| */
            float facing = lx_dot(nq, nq) > 0.0f ? fmaxf(-lx_dot(nq, d), 0.0f)
                                                 : lx_length(lx_cross(light->direction, d));
            float w = fmaxf(lx_dot(n, d), 0.0f) * facing / (d2 * d2);
            if (!(w > 0.0f) || !isfinite(w))
                continue;
            float dist = sqrtf(d2);
            lx_light_eval e = {.to_light = lx_scale(d, 1.0f / dist), .distance = dist};
            rays[m] = lx_shadow_ray(b, p, ng, &e);
            weight[m] = w;
            m++;
        }
        if (m == 0)
            continue;
        lx_tracer_occluded_batch(b->tracer, rays, m, true, occluded);
        for (uint32_t j = 0; j < m; j++) {
            total += weight[j];
            if (!occluded[j])
                visible += weight[j];
        }
    }
    return total > 0.0 ? (float)(visible / total) : 0.0f;
}

static void light_tile(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                       uint32_t first, uint32_t count, uint32_t light_index, lx_vec3 *accum)
{
    const lx_light *light = &b->lights[light_index];
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
        if (light->shadow == LX_SHADOW_SOFT) {
            float vis = soft_visibility(b, map_index, map, i, light_index, light);
            accum[k] = lx_add(accum[k], lx_scale(e.illuminance, vis));
            continue;
        }
        rays[n] = lx_shadow_ray(b, map->world_position[i], map->world_geometric_normal[i], &e);
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
                light_tile(b, m, map, first, count, lights[l], accum);
            if (!to_realtime && b->has_sky)
                lx_sky_tile(b, m, map, first, count, accum);
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
