/* Directional lightmaps: the baked light's order-1 spherical harmonics
 * per texel (as Godot's LightmapGI and Bakery's SH mode keep them) and
 * Unity's dominant direction made from them. The coefficients are the
 * projections L_lm = int L(w) Y_lm(w) dw of the incoming radiance
 * (Sloan, "Stupid Spherical Harmonics Tricks", GDC 2008); the irradiance
 * of a normal is their convolution with the clamped cosine, pi and 2 pi /
 * 3 for bands 0 and 1 (Ramamoorthi & Hanrahan, "An Efficient
 * Representation for Irradiance Environment Maps", SIGGRAPH 2001).
 *
 * What the passes add (bake_internal.h's lx_sh4_*):
 * - a light whose irradiance at the texel is e from direction d (the
 *   texel's normal n): a delta of e / (n . d), its illuminance facing it
 *   (an area light from its centre, n . d at least 0.1; emitters from
 *   their mean direction, emitters.c);
 * - ambient terms (an irradiance for every normal): a uniform radiance
 *   a / pi over the sphere, L00 = 4 Y00 a;
 * - an unshadowed sky: the sky's own L0 and L1 (nothing blocks it);
 * - sky and gather rays, cosine-distributed over the hemisphere: L Y / pdf
 *   with pdf = cos / pi has a variance without bound toward the horizon
 *   (Y / cos), 13% per texel at 256 rays under a constant sky. The rays
 *   are stratified in u = 1 - cos^2 (Malley's method, sx strata), so each
 *   ray takes the means over its stratum instead (lx_sh_ray_weight): for
 *   L00 the mean of pi / cos, for L1 along the normal pi (the irradiance's
 *   own cosine estimator), across it the mean of pi sin / cos over the
 *   mean of sin. Bounded weights, L0 and normal L1 exact for a constant
 *   sky, and unbiased for radiance that does not change with elevation
 *   within a stratum (1/16 of u at 256 rays);
 * - the sky's bright part (its peak), sampled by importance: L Y / pdf with
 *   pdf = luminance x solid angle / P. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static lx_status check(const lx_baker *b, uint32_t map_index, const char *what)
{
    if (map_index >= b->map_count)
        return lx_fail(LX_ERR_INVALID, "lightmap %u out of range (count %u)", map_index,
                       b->map_count);
    const lx_lightmap *map = &b->maps[map_index];
    if (b->desc.directional == LX_DIRECTIONAL_OFF || !map->sh)
        return lx_fail(LX_ERR_INVALID,
                       "lightmap '%s': no directional data for %s (bake with desc.directional)",
                       map->name, what);
    /* a tiled baker builds the map's tile again (one thread at a time uses
     * a baker: its cache of texel maps may change here) */
    return lx_bake_tile_need((lx_baker *)b, map_index);
}

/* Pads and stitches img (channels per texel) as lx_baker_apply does. */
static lx_status pad(const lx_baker *b, const lx_lightmap *map, lx_image *img)
{
    size_t pixels = (size_t)map->info.width * map->info.height;
    lx_status st = LX_OK;
    if (b->desc.padding > 0) {
        uint8_t *mask = malloc(pixels);
        if (!mask)
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for the padding mask",
                           map->name);
        memcpy(mask, map->mask, pixels);
        lx_dilate_desc dd = {.threads = b->desc.threads};
        st = lx_dilate(img->data, mask, img->width, img->height, img->channels, b->desc.padding,
                       &dd);
        free(mask);
    }
    if (st == LX_OK && map->stitch)
        st = lx_seam_stitch_apply(map->stitch, img->data, img->channels, map->name);
    return st;
}

lx_status lx_baker_sh(const lx_baker *b, uint32_t map_index, lx_image out[4])
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof(lx_image) * 4);
    lx_status st = check(b, map_index, "its spherical harmonics");
    if (st != LX_OK)
        return st;
    const lx_lightmap *map = &b->maps[map_index];
    int w = map->info.width, h = map->info.height;
    for (int c = 0; c < 4 && st == LX_OK; c++)
        st = lx_image_alloc(&out[c], w, h, 3);
    for (int c = 0; c < 4 && st == LX_OK; c++) {
        memset(out[c].data, 0, sizeof(float) * 3 * (size_t)w * h);
        for (uint32_t i = 0; i < map->info.used_texels; i++) {
            size_t p = map->texels[i].pixel;
            memcpy(out[c].data + 3 * p, map->sh + p * LX_SH_FLOATS + 3 * c, sizeof(float) * 3);
        }
        st = pad(b, map, &out[c]);
    }
    if (st != LX_OK) {
        if (st != LX_ERR_CANCELLED) {
            char what[300];
            snprintf(what, sizeof what, "lightmap '%s'", map->name);
            lx_error_prefix(what);
        }
        for (int c = 0; c < 4; c++)
            lx_image_free(&out[c]);
        memset(out, 0, sizeof(lx_image) * 4);
    }
    return st;
}

lx_status lx_baker_dominant(const lx_baker *b, uint32_t map_index, lx_image *out)
{
    if (!b)
        return lx_fail_null(__func__, "baker");
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    lx_status st = check(b, map_index, "its dominant direction");
    if (st != LX_OK)
        return st;
    const lx_lightmap *map = &b->maps[map_index];
    int w = map->info.width, h = map->info.height;
    if ((st = lx_image_alloc(out, w, h, 4)) != LX_OK)
        return st;
    memset(out->data, 0, sizeof(float) * 4 * (size_t)w * h);
    for (uint32_t i = 0; i < map->info.used_texels; i++) {
        size_t p = map->texels[i].pixel;
        const float *c = map->sh + p * LX_SH_FLOATS;
        /* luminance-weighted: int lum(L) w dw / int lum(L) dw, from L1 / Y1
         * over L00 / Y00 (the luminance of each coefficient: linear) */
        double l0 = lx_luminance(c);
        lx_vec3 d = lx_v3(0.0f, 0.0f, 0.0f);
        if (l0 > 0.0) {
            double k = (double)LX_SH_Y0 / ((double)LX_SH_Y1 * l0);
            d = lx_v3((float)(lx_luminance(c + 9) * k), (float)(lx_luminance(c + 3) * k),
                      (float)(lx_luminance(c + 6) * k));
            float len = lx_length(d);
            if (len > 1.0f) /* noise: a mean direction is at most unit */
                d = lx_scale(d, 1.0f / len);
        }
        float *o = out->data + 4 * p;
        o[0] = 0.5f * d.x + 0.5f;
        o[1] = 0.5f * d.y + 0.5f;
        o[2] = 0.5f * d.z + 0.5f;
        o[3] = 0.5f * lx_dot(map->world_normal[i], d) + 0.5f;
    }
    st = pad(b, map, out);
    if (st != LX_OK) {
        char what[300];
        snprintf(what, sizeof what, "lightmap '%s'", map->name);
        lx_error_prefix(what);
        lx_image_free(out);
        memset(out, 0, sizeof *out);
    }
    return st;
}
