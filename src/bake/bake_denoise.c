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

lx_status lx_bake_sampled_begin(lx_baker *b, bool *made)
{
    *made = false;
    lx_bake_sampled_end(b);
    if (b->desc.denoise != LX_DENOISE_INDIRECT)
        return LX_OK;
    bool sampled = (b->has_sky && b->sky_shadows) || b->emitter_count > 0;
    for (uint32_t l = 0; l < b->light_count && !sampled; l++)
        sampled = !b->lights[l].dynamic && b->lights[l].shadow == LX_SHADOW_SOFT;
    if (!sampled)
        return LX_OK;
    for (uint32_t m = 0; m < b->map_count; m++) {
        lx_lightmap *map = &b->maps[m];
        size_t n = (size_t)map->info.width * map->info.height * 3;
        map->sampled = calloc(n ? n : 1, sizeof(float));
        map->sampled_variance = calloc(n / 3 ? n / 3 : 1, sizeof(float));
        if (!map->sampled || !map->sampled_variance) {
            lx_bake_sampled_end(b);
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory keeping its sampled "
                                         "direct light for denoising",
                           map->name);
        }
    }
    *made = true;
    return LX_OK;
}

void lx_bake_sampled_end(lx_baker *b)
{
    for (uint32_t m = 0; m < b->map_count; m++) {
        free(b->maps[m].sampled);
        free(b->maps[m].sampled_variance);
        b->maps[m].sampled = NULL;
        b->maps[m].sampled_variance = NULL;
    }
}

float **lx_bake_denoise_keep(const lx_baker *b, lx_status *st)
{
    *st = LX_OK;
    if (b->desc.denoise != LX_DENOISE_INDIRECT || b->desc.bounces == 0)
        return NULL;
    /* [m]: map m's baked buffer, [map_count + m]: its directional data */
    float **direct = calloc(2 * (size_t)b->map_count + 1, sizeof *direct);
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
        for (size_t i = 0; map->sampled && i < n; i++) /* the exact part */
            direct[m][i] -= map->sampled[i];
        if (!map->sh)
            continue;
        size_t k = n / 3 * LX_SH_FLOATS;
        if (!(direct[b->map_count + m] = malloc(sizeof(float) * k))) {
            lx_bake_denoise_free(b, direct);
            *st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory keeping its direct light "
                                        "for denoising",
                          map->name);
            return NULL;
        }
        memcpy(direct[b->map_count + m], map->sh, sizeof(float) * k);
    }
    return direct;
}

void lx_bake_denoise_free(const lx_baker *b, float **direct)
{
    if (!direct)
        return;
    for (uint32_t m = 0; m < 2 * b->map_count; m++)
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

/* The directional data of a map, filtered as its irradiance is (the same
 * mode, guides and settings) but without the luminance weight: the four
 * coefficient planes then get the same weights, set by the guides alone,
 * so the direction and its share survive the filter (a weight that
 * followed each plane's values would filter L0 and L1 apart and bend the
 * directions). sh_direct: the directional data before the bounces
 * (INDIRECT), else NULL. */
static lx_status denoise_sh(const lx_baker *b, lx_lightmap *map, const lx_denoise_guides *g,
                            const float *sh_direct)
{
    size_t pixels = (size_t)map->info.width * map->info.height;
    float *plane = malloc(sizeof(float) * 3 * pixels);
    float *part = sh_direct ? malloc(sizeof(float) * 3 * pixels) : NULL;
    if (!plane || (sh_direct && !part)) {
        free(plane);
        free(part);
        return lx_fail(LX_ERR_NOMEM, "out of memory for denoising the directional data");
    }
    lx_denoise_desc dd = {.threads = b->desc.threads, .ignore_luminance = true};
    lx_status st = LX_OK;
    for (int c = 0; c < 4 && st == LX_OK; c++) {
        for (size_t p = 0; p < pixels; p++)
            for (int k = 0; k < 3; k++) {
                float v = map->sh[p * LX_SH_FLOATS + (size_t)(3 * c + k)];
                if (sh_direct) {
                    float d = sh_direct[p * LX_SH_FLOATS + (size_t)(3 * c + k)];
                    part[3 * p + (size_t)k] = d;
                    v -= d;
                }
                plane[3 * p + (size_t)k] = v;
            }
        st = sh_direct ? lx_denoise_combine(LX_DENOISE_INDIRECT, g, part, plane, plane, &dd)
                       : lx_denoise(g, plane, plane, &dd);
        for (size_t p = 0; p < pixels && st == LX_OK; p++)
            for (int k = 0; k < 3; k++)
                map->sh[p * LX_SH_FLOATS + (size_t)(3 * c + k)] = plane[3 * p + (size_t)k];
    }
    free(plane);
    free(part);
    return st;
}

/* The sampled direct light of map m (--denoise indirect), filtered apart
 * and added back: baked = exact + F(sampled) (+ the bounces, already
 * filtered), guided by its samples' own variance: the exact lights'
 * edges never enter it, and real gradients (a box's foot in the sky's
 * shadow) are not taken for noise. */
static lx_status denoise_sampled(lx_lightmap *map, lx_denoise_guides *g, bool bounces_done,
                                 const lx_denoise_desc *dd)
{
    size_t n = (size_t)map->info.width * map->info.height * 3;
    /* without bounces the buffer still holds the sampled part */
    for (size_t i = 0; !bounces_done && i < n; i++)
        map->baked[i] -= map->sampled[i];
    const float *variance = g->variance;
    g->variance = map->sampled_variance;
    lx_status st = lx_denoise(g, map->sampled, map->sampled, dd);
    g->variance = variance;
    for (size_t i = 0; i < n; i++) /* on failure: the sampled part as it was */
        map->baked[i] += map->sampled[i];
    return st;
}

lx_status lx_bake_denoise(lx_baker *b, float **direct, float progress_base, float progress_span)
{
    lx_denoise_mode mode = b->desc.denoise;
    bool sampled = false;
    for (uint32_t m = 0; m < b->map_count; m++)
        sampled |= b->maps[m].sampled != NULL;
    if (mode == LX_DENOISE_OFF || (mode == LX_DENOISE_INDIRECT && !direct && !sampled))
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
        /* the bounces' own variance guides the filter's luminance weight
         * (the guides' spatial estimate otherwise) */
        size_t pixels = n / 3;
        if (mode == LX_DENOISE_INDIRECT && map->gi_variance && !g.variance) {
            float *v = malloc(sizeof(float) * (pixels ? pixels : 1));
            if (v)
                memcpy(v, map->gi_variance, sizeof(float) * pixels);
            g.variance = v;
            if (!v)
                st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for denoising",
                             map->name);
        }
        if (st != LX_OK) {
        } else if (mode == LX_DENOISE_INDIRECT) {
            /* the bounces' part, in place of the buffer's copy of it
             * (without the sampled direct part: that is filtered next) */
            float *indirect = direct ? malloc(sizeof(float) * n) : NULL;
            if (direct && !indirect) {
                st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for denoising",
                             map->name);
            } else if (direct) {
                if (map->sampled)
                    sh.span *= 0.5f; /* two runs, each half the map's share */
                for (size_t i = 0; i < n; i++)
                    indirect[i] = map->baked[i] - direct[m][i] -
                                  (map->sampled ? map->sampled[i] : 0.0f);
                st = lx_denoise_combine(mode, &g, direct[m], indirect, map->baked, &dd);
                free(indirect);
            }
            if (st == LX_OK && map->sampled) {
                if (direct)
                    sh.from += sh.span;
                st = denoise_sampled(map, &g, direct != NULL, &dd);
            }
        } else {
            st = lx_denoise(&g, map->baked, map->baked, &dd);
        }
        if (st == LX_OK && map->sh && (mode != LX_DENOISE_INDIRECT || direct))
            st = denoise_sh(b, map, &g,
                            mode == LX_DENOISE_INDIRECT ? direct[b->map_count + m] : NULL);
        lx_denoise_guides_free(&g);
        if (st != LX_OK && st != LX_ERR_CANCELLED) {
            char what[300];
            snprintf(what, sizeof what, "lightmap '%s'", map->name);
            lx_error_prefix(what);
        }
    }
    return st;
}
