/* Ambient-occlusion lightmaps (lx_baker_ao): per texel, the share of
 * stratified cosine-weighted rays (Malley's method, as sky.c) that meet
 * nothing within the AO distance. Rays start off the surface by the
 * shadow rays' bias (lx_shadow_ray) on the side of the shading normal, so
 * a texel sees what its lit side sees. Every texel's rays come from
 * (map, texel, sample), and every texel is written by one tile, so the
 * bytes do not depend on the thread count. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* lx_random dimensions apart from the lights', the sky's and GI's */
#define AO_KEY 0x4a00u

lx_ao_desc lx_ao_desc_defaults(const lx_ao_desc *desc)
{
    lx_ao_desc d;
    if (desc)
        d = *desc;
    else
        memset(&d, 0, sizeof d);
    if (d.distance == 0.0f)
        d.distance = LX_AO_DISTANCE_DEFAULT;
    if (d.samples == 0)
        d.samples = LX_AO_SAMPLES_DEFAULT;
    return d;
}

/* The open share of one texel's hemisphere. */
static float texel_ao(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                      uint32_t texel, const lx_ao_desc *d)
{
    lx_vec3 p = map->world_position[texel], n = map->world_normal[texel];
    lx_vec3 ng = map->world_geometric_normal[texel];
    lx_vec3 t = lx_perpendicular(n), bt = lx_cross(n, t);
    uint32_t pixel = map->texels[texel].pixel;
    uint32_t sx, sy;
    lx_cosine_strata(d->samples, &sx, &sy);
    uint32_t cells = sx * sy;
    enum { BATCH = 64 };
    lx_ray rays[BATCH];
    uint8_t occluded[BATCH];
    uint32_t open = 0, m = 0;
    for (uint32_t k = 0; k < cells; k++) {
        lx_vec3 dir = lx_cosine_direction(t, bt, n, map_index, pixel, k, sx, sy, AO_KEY);
        if (!(lx_dot(dir, ng) > 0.0f))
            continue; /* into the surface itself */
        lx_light_eval e = {.to_light = dir, .distance = d->distance};
        rays[m++] = lx_shadow_ray(b, p, ng, &e);
        if (m == BATCH) {
            lx_tracer_occluded_batch(b->tracer, rays, m, true, occluded);
            for (uint32_t j = 0; j < m; j++)
                open += !occluded[j];
            m = 0;
        }
    }
    if (m) {
        lx_tracer_occluded_batch(b->tracer, rays, m, true, occluded);
        for (uint32_t j = 0; j < m; j++)
            open += !occluded[j];
    }
    return (float)open / (float)cells;
}

lx_status lx_baker_ao(lx_baker *b, uint32_t map_index, const lx_ao_desc *desc, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_baker_ao: out must not be NULL");
    memset(out, 0, sizeof *out);
    if (!b || map_index >= b->map_count)
        return lx_fail(LX_ERR_INVALID, "lx_baker_ao: lightmap %u out of range (count %u)",
                       map_index, b ? b->map_count : 0u);
    lx_ao_desc d = lx_ao_desc_defaults(desc);
    lx_status need = lx_bake_tile_need(b, map_index); /* a tiled baker builds it again */
    if (need != LX_OK)
        return need;
    const lx_lightmap *map = &b->maps[map_index];
    if (!isfinite(d.distance) || !(d.distance > 0.0f))
        return lx_fail(LX_ERR_INVALID, "lightmap '%s': AO distance %g must be a number > 0",
                       map->name, (double)d.distance);
    if (d.samples > LX_MAX_AO_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "lightmap '%s': %u AO samples, at most %u", map->name,
                       d.samples, LX_MAX_AO_SAMPLES);
    if (b->tracer_dirty) {
        lx_status st = lx_tracer_commit(b->tracer);
        if (st != LX_OK)
            return st;
        b->tracer_dirty = false;
    }
    int w = map->info.width, h = map->info.height;
    lx_status st = lx_image_alloc(out, w, h, 1);
    if (st != LX_OK)
        return st;
    int threads = lx_thread_count(d.threads ? d.threads : b->desc.threads);
    volatile int cancelled = 0;
    int done = 0;
    int tiles = (int)map->tile_count;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int tile = 0; tile < tiles; tile++) {
        if (cancelled)
            continue;
        for (uint32_t i = map->tile_start[tile]; i < map->tile_start[tile + 1]; i++)
            out->data[map->texels[i].pixel] = texel_ao(b, map_index, map, i, &d);
        if (d.progress) {
            int now;
#pragma omp atomic capture
            now = ++done;
            if (omp_get_thread_num() == 0 && !d.progress(d.progress_user, (float)now / (float)tiles))
                cancelled = 1;
        }
    }
    if (!cancelled && d.progress && !d.progress(d.progress_user, 1.0f))
        cancelled = 1;
    if (!cancelled && b->desc.padding > 0) {
        uint8_t *mask = malloc((size_t)w * h);
        if (!mask) {
            lx_image_free(out);
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for the AO padding mask",
                           map->name);
        }
        memcpy(mask, map->mask, (size_t)w * h);
        lx_dilate_desc dd = {.threads = threads};
        st = lx_dilate(out->data, mask, w, h, 1, b->desc.padding, &dd);
        free(mask);
        if (st != LX_OK) {
            lx_image_free(out);
            return st;
        }
    }
    if (cancelled) {
        lx_image_free(out);
        return lx_fail(LX_ERR_CANCELLED, "lightmap '%s': AO cancelled", map->name);
    }
    return LX_OK;
}
