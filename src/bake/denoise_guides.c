/* The denoiser's guides for a baker lightmap (lx_baker_denoise_guides):
 * the texel map's per-texel records (texel_map.c, stored by tile) laid out
 * as pixel-indexed buffers, so denoising a bake is one call more. The
 * chart id is the scene node: nodes packed on one atlas page are separate
 * objects and never share light, wherever they stand. */
#include "bake_internal.h"
#include "core/internal.h"
#include "luxel/denoise.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lx_denoise_guides_free(lx_denoise_guides *g)
{
    if (!g)
        return;
    free((void *)g->valid);
    free((void *)g->position);
    free((void *)g->normal);
    free((void *)g->albedo);
    free((void *)g->chart);
    free((void *)g->texel_size);
    free((void *)g->variance);
    memset(g, 0, sizeof *g);
}

lx_status lx_baker_denoise_guides(const lx_baker *b, uint32_t map_index, lx_denoise_guides *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "denoise guides: no output");
    memset(out, 0, sizeof *out);
    if (!b)
        return lx_fail(LX_ERR_INVALID, "denoise guides: no baker");
    if (map_index >= b->map_count)
        return lx_fail(LX_ERR_INVALID, "denoise guides: lightmap %u out of range (count %u)",
                       map_index, b->map_count);
    /* a tiled baker builds the map's tile again */
    lx_status need = lx_bake_tile_need((lx_baker *)b, map_index);
    if (need != LX_OK)
        return need;
    const lx_lightmap *map = &b->maps[map_index];
    int w = map->info.width, h = map->info.height;
    size_t n = (size_t)w * h;
    char what[300];
    snprintf(what, sizeof what, "lightmap '%s': denoise guides", map->name);
    /* valid, position, normal, chart */
    lx_status st = lx_check_memory((uint64_t)n * (1 + 12 + 12 + 4), what);
    if (st != LX_OK)
        return st;
    uint8_t *valid = calloc(n ? n : 1, 1);
    lx_vec3 *position = calloc(n ? n : 1, sizeof(lx_vec3));
    lx_vec3 *normal = calloc(n ? n : 1, sizeof(lx_vec3));
    uint32_t *chart = calloc(n ? n : 1, sizeof(uint32_t));
    if (!valid || !position || !normal || !chart) {
        free(valid);
        free(position);
        free(normal);
        free(chart);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    }
    int threads = lx_thread_count(b->desc.threads);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int tile = 0; tile < (int)map->tile_count; tile++)
        for (uint32_t i = map->tile_start[tile]; i < map->tile_start[tile + 1]; i++) {
            const lx_texel *t = &map->texels[i];
            /* a texel inside geometry keeps the light its neighbours gave it */
            valid[t->pixel] = !map->gi_valid || map->gi_valid[t->pixel];
            position[t->pixel] = map->world_position[i];
            normal[t->pixel] = map->world_normal[i];
            chart[t->pixel] = t->node;
        }
    out->width = w;
    out->height = h;
    out->valid = valid;
    out->position = position;
    out->normal = normal;
    out->chart = chart;
    return LX_OK;
}
