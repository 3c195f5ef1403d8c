/* The bake's denoising step (lx_bake_desc.denoise): each lightmap's
 * baked buffer filtered by lx_denoise_combine with the guides of
 * lx_baker_denoise_guides, before lx_baker_apply converts and pads it
 * (padding texels are not valid guides). For INDIRECT the direct part is
 * what the buffer held before the bounces (kept by lx_bake_denoise_keep). */
#include "bake_internal.h"
#include "core/internal.h"
#include "luxel/denoise.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

float **lx_bake_denoise_keep(const lx_baker *b, lx_status *st)
{
    *st = LX_OK;
    if (b->desc.denoise != LX_DENOISE_INDIRECT || b->desc.bounces == 0)
        return NULL;
    float **direct = calloc(b->map_count + 1, sizeof *direct);
    if (!direct) {
        *st = lx_fail(LX_ERR_NOMEM, "out of memory keeping the direct light for denoising");
        return NULL;
    }
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        size_t n = (size_t)map->info.width * map->info.height * 3;
        if (!(direct[m] = malloc(sizeof(float) * n))) {
            lx_bake_denoise_free(b, direct);
            *st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory keeping its direct light "
                                        "for denoising",
                          map->name);
            return NULL;
        }
        memcpy(direct[m], map->baked, sizeof(float) * n);
    }
    return direct;
}

void lx_bake_denoise_free(const lx_baker *b, float **direct)
{
    if (!direct)
        return;
    for (uint32_t m = 0; m < b->map_count; m++)
        free(direct[m]);
    free(direct);
}

typedef struct share {
    const lx_baker *b;
    float from, span;
} share;

static bool share_progress(void *user, float fraction)
{
    const share *s = user;
    return s->b->desc.progress(s->b->desc.progress_user, s->from + s->span * fraction);
}

lx_status lx_bake_denoise(lx_baker *b, float **direct, float progress_base, float progress_span)
{
    lx_denoise_mode mode = b->desc.denoise;
    if (mode == LX_DENOISE_OFF || (mode == LX_DENOISE_INDIRECT && !direct))
        return LX_OK;
    lx_status st = LX_OK;
    /* the maps in memory (a tiled baker's tile), each its share */
    uint32_t first = UINT32_MAX, last = 0;
    for (uint32_t m = 0; m < b->map_count; m++)
        if (b->maps[m].loaded) {
            first = first == UINT32_MAX ? m : first;
            last = m + 1;
        }
    uint32_t span_maps = first == UINT32_MAX ? 1 : last - first;
    for (uint32_t m = first; m < last && st == LX_OK; m++) {
        lx_lightmap *map = &b->maps[m];
        size_t n = (size_t)map->info.width * map->info.height * 3;
        lx_denoise_guides g;
        st = lx_baker_denoise_guides(b, m, &g);
        if (st != LX_OK)
            break;
        share sh = {b, progress_base + progress_span * (float)(m - first) / (float)span_maps,
                    progress_span / (float)span_maps};
        lx_denoise_desc dd = {.threads = b->desc.threads,
                              .progress = b->desc.progress ? share_progress : NULL,
                              .progress_user = &sh};
        if (mode == LX_DENOISE_INDIRECT) {
            /* the bounces' part, in place of the buffer's copy of it */
            float *indirect = malloc(sizeof(float) * n);
            if (!indirect) {
                st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for denoising",
                             map->name);
            } else {
                for (size_t i = 0; i < n; i++)
                    indirect[i] = map->baked[i] - direct[m][i];
                st = lx_denoise_combine(mode, &g, direct[m], indirect, map->baked, &dd);
                free(indirect);
            }
        } else {
            st = lx_denoise(&g, map->baked, map->baked, &dd);
        }
        lx_denoise_guides_free(&g);
        if (st != LX_OK && st != LX_ERR_CANCELLED) {
            char what[300];
            snprintf(what, sizeof what, "lightmap '%s'", map->name);
            lx_error_prefix(what);
        }
    }
    return st;
}
