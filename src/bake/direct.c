/* Direct lighting of texels: the per-texel lighting article's DynamicLight
 * kernel (every texel, every light, shadow test toward the light, the
 * "dynamic blur" from the nearest occluder) with Filament's physical light
 * model, and Embree occlusion queries in place of the article's
 * every-triangle loop.
 * Work is split into fixed tiles, so the sums are the same for any number
 * of threads. */
#include "bake_internal.h"
#include "core/internal.h"
#include "direct_fast.h"

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
                             uint32_t texel, uint32_t light_index, const lx_light *light,
                             float *variance)
{
    uint32_t want = lx_light_sample_count(light);
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
    double total = 0.0, visible = 0.0, squares = 0.0, visible_squares = 0.0;
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
            rays[m] = lx_lift_shadow_ray(lx_shadow_ray(b, p, ng, &e), ng, map->lift, texel);
            weight[m] = w;
            m++;
        }
        if (m == 0)
            continue;
        lx_tracer_occluded_batch(b->tracer, rays, m, true, occluded);
        for (uint32_t j = 0; j < m; j++) {
            total += weight[j];
            squares += (double)weight[j] * weight[j];
            if (!occluded[j]) {
                visible += weight[j];
                visible_squares += (double)weight[j] * weight[j];
            }
        }
    }
    if (!(total > 0.0)) {
        *variance = 0.0f;
        return 0.0f;
    }
    /* the self-normalized mean's variance, sum (w_j / W)^2 (v_j - vis)^2 */
    double vis = visible / total;
    double spread = visible_squares * (1.0 - vis) * (1.0 - vis) +
                    (squares - visible_squares) * vis * vis;
    *variance = (float)(spread / (total * total));
    return (float)vis;
}

/* What a light adds to a texel's shadow record when it is blocked there
 * (edge supersampling compares neighbours' records): the bit of its place
 * in the pass's light list, modulo 64. With up to 64 lights a record says
 * exactly which hard-shadowed lights are blocked; beyond, lights 64 apart
 * share a bit (re-shaded together, and an edge of two of them that cancel
 * goes unseen). */
static uint64_t shadow_bit(uint32_t place)
{
    return (uint64_t)1 << (place & 63u);
}

/* The part of a texel's direct light estimated by sampling, and the
 * variance of its luminance's estimate. */
typedef struct sampled_light {
    lx_vec3 e;
    float variance;
} sampled_light;

/* sh (NULL: no directional data) gets what accum gets, with its
 * direction (lx_sh4_add_lit_floor); shadows (NULL: none) each texel's
 * shadow record (shadow_bit of the hard-shadowed lights blocked there);
 * sampled (NULL: not kept) what accum gets from soft shadows' samples. */
static void light_tile(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                       uint32_t first, uint32_t count, uint32_t light_index, lx_vec3 *accum,
                       lx_sh4 *sh, uint64_t *shadows, uint64_t bit, sampled_light *sampled)
{
    const lx_light *light = &b->lights[light_index];
    const float floor_c = lx_light_is_area(light) ? 0.1f : 1e-3f; /* lx_sh4_add_lit_floor */
    lx_ray rays[LX_TILE * LX_TILE];
    pending_ray pending[LX_TILE * LX_TILE];
    uint8_t occluded[LX_TILE * LX_TILE];
    uint32_t n = 0;
    for (uint32_t k = 0; k < count; k++) {
        uint32_t i = first + k;
        lx_light_eval e;
        bool direct = lx_light_evaluate(light, map->world_position[i], map->world_normal[i], &e);
        /* a texel with a height (horizon.c): ambient times its AO, the
         * direct term times its horizon factor (both 1 on a flat height,
         * and a product by 1 changes no bit) */
        const lx_texel_horizon *h = map->horizon && map->horizon[i].flags ? &map->horizon[i] : NULL;
        accum[k] = lx_add(accum[k], h ? lx_scale(e.ambient, h->ao) : e.ambient);
        if (sh)
            lx_sh4_add_uniform(&sh[k], h ? lx_scale(e.ambient, h->ao) : e.ambient);
        if (!direct)
            continue;
        if (h)
            e.illuminance = lx_scale(e.illuminance, lx_texel_horizon_factor(h, e.to_light));
        lx_vec3 nn = map->world_normal[i];
        if (light->shadow == LX_SHADOW_NONE) {
            accum[k] = lx_add(accum[k], e.illuminance);
            if (sh)
                lx_sh4_add_lit_floor(&sh[k], e.illuminance, nn, e.to_light, floor_c);
            continue;
        }
        if (light->shadow == LX_SHADOW_SOFT) {
            float var;
            float vis = soft_visibility(b, map_index, map, i, light_index, light, &var);
            accum[k] = lx_add(accum[k], lx_scale(e.illuminance, vis));
            if (sampled) {
                float y = (float)lx_luminance3(e.illuminance);
                sampled[k].e = lx_add(sampled[k].e, lx_scale(e.illuminance, vis));
                sampled[k].variance += y * y * var;
            }
            if (sh)
                lx_sh4_add_lit_floor(&sh[k], lx_scale(e.illuminance, vis), nn, e.to_light, floor_c);
            continue;
        }
        lx_vec3 ng = map->world_geometric_normal[i];
        rays[n] = lx_lift_shadow_ray(lx_shadow_ray(b, map->world_position[i], ng, &e), ng,
                                     map->lift, i);
        pending[n] = (pending_ray){k, e.illuminance};
        if (light->shadow == LX_SHADOW_BLUR) {
            /* the article's blur = nearest occluder distance / light distance */
            float d_occ = lx_tracer_nearest_distance(b->tracer, &rays[n]);
            float d_light = isfinite(e.distance) ? e.distance : b->scene_diagonal;
            float vis = isfinite(d_occ) ? lx_light_blur_visibility(light, d_occ, d_light) : 1.0f;
            accum[k] = lx_add(accum[k], lx_scale(e.illuminance, vis));
            if (sh)
                lx_sh4_add_lit_floor(&sh[k], lx_scale(e.illuminance, vis), nn, e.to_light, floor_c);
            continue;
        }
        n++;
    }
    if (n == 0)
        return;
    lx_tracer_occluded_batch(b->tracer, rays, n, true, occluded);
    for (uint32_t j = 0; shadows && j < n; j++)
        if (occluded[j])
            shadows[pending[j].texel] |= bit;
    for (uint32_t j = 0; j < n; j++)
        if (!occluded[j]) {
            uint32_t k = pending[j].texel;
            accum[k] = lx_add(accum[k], pending[j].illuminance);
            if (sh)
                lx_sh4_add_lit_floor(&sh[k], pending[j].illuminance,
                                     map->world_normal[first + k], rays[j].dir, floor_c);
        }
}

/* ---- the lean loop (direct_fast.h): punctual lights with hard or no shadows */

/* false when the light needs the general path. */
static bool fast_light_init(const lx_light *l, fast_light *f)
{
    memset(f, 0, sizeof *f);
    if (l->profile || (l->shadow != LX_SHADOW_HARD && l->shadow != LX_SHADOW_NONE))
        return false;
    if (l->type != LX_LIGHT_POINT && l->type != LX_LIGHT_SPOT && l->type != LX_LIGHT_DIRECTIONAL)
        return false;
    f->directional = l->type == LX_LIGHT_DIRECTIONAL;
    f->classic = l->model == LX_MODEL_CLASSIC;
    f->shadowed = l->shadow == LX_SHADOW_HARD;
    if (f->directional) {
        lx_vec3 t = lx_neg(l->direction);
        f->px = t.x, f->py = t.y, f->pz = t.z;
    } else {
        f->px = l->position.x, f->py = l->position.y, f->pz = l->position.z;
    }
    f->ax = l->direction.x, f->ay = l->direction.y, f->az = l->direction.z;
    f->intensity = l->intensity;
    f->range = l->range;
    f->range_sq = l->range * l->range;
    if (l->type == LX_LIGHT_SPOT) {
        /* lx_light_spot_attenuation's constants */
        f->spot = true;
        f->cos_outer = cosf(l->outer_angle);
        float cos_inner = cosf(l->inner_angle);
        f->spot_hard = !(l->inner_angle < l->outer_angle);
        float delta = cos_inner - f->cos_outer;
        f->spot_scale = 1.0f / (delta > 1e-4f ? delta : 1e-4f);
        f->spot_offset = -f->cos_outer * f->spot_scale;
    }
    f->cr = l->color.x, f->cg = l->color.y, f->cb = l->color.z;
    f->mr = l->ambient.x, f->mg = l->ambient.y, f->mb = l->ambient.z;
    return true;
}

static void lane_set(tile_soa *t, int k, lx_vec3 p, lx_vec3 n, lx_vec3 g, float bias)
{
    t->px[k] = p.x, t->py[k] = p.y, t->pz[k] = p.z;
    t->nx[k] = n.x, t->ny[k] = n.y, t->nz[k] = n.z;
    t->gx[k] = g.x, t->gy[k] = g.y, t->gz[k] = g.z;
    t->bias[k] = bias;
}

static void tile_load(const lx_baker *b, const lx_lightmap *map, uint32_t first, uint32_t count,
                      tile_soa *t)
{
    uint32_t width = (uint32_t)map->info.width;
    for (int q = 0; q < TILE_TEXELS / LX_RAY_PACKET; q++)
        t->lanes[q] = 0;
    for (int k = 0; k < TILE_TEXELS; k++)
        t->texel[k] = -1;
    for (uint32_t j = 0; j < count; j++) {
        uint32_t i = first + j, pixel = map->texels[i].pixel;
        uint32_t x = pixel % width % LX_TILE, y = pixel / width % LX_TILE;
        int block = (int)(y / 4 * 2 + x / 4), lane = (int)(y % 4 * 4 + x % 4);
        int k = block * LX_RAY_PACKET + lane;
        lx_vec3 p = map->world_position[i];
        lane_set(t, k, p, map->world_normal[i], map->world_geometric_normal[i],
                 b->bias + 4e-6f * lx_max_abs_component(p));
        t->texel[k] = (int32_t)j;
        t->lanes[block] |= 1u << lane;
        if (map->lift)
            t->lfx[k] = map->lift[i].x, t->lfy[k] = map->lift[i].y, t->lfz[k] = map->lift[i].z;
    }
    t->lifted = map->lift != NULL;
    for (int k = 0; k < TILE_TEXELS && t->lifted; k++)
        if (t->texel[k] < 0)
            t->lfx[k] = t->lfy[k] = t->lfz[k] = 0.0f;
    /* empty places copy a texel so every lane computes on real numbers */
    int any = 0;
    while (t->texel[any] < 0)
        any++;
    for (int k = 0; k < TILE_TEXELS; k++)
        if (t->texel[k] < 0)
            lane_set(t, k, lx_v3(t->px[any], t->py[any], t->pz[any]),
                     lx_v3(t->nx[any], t->ny[any], t->nz[any]),
                     lx_v3(t->gx[any], t->gy[any], t->gz[any]), t->bias[any]);
}

/* The sums between the lanes and texel order (the general path's). */
static void acc_to_vec3(const tile_soa *t, lx_vec3 *accum)
{
    for (int k = 0; k < TILE_TEXELS; k++)
        if (t->texel[k] >= 0)
            accum[t->texel[k]] = lx_v3(t->acc[0][k], t->acc[1][k], t->acc[2][k]);
}

static void vec3_to_acc(const lx_vec3 *accum, tile_soa *t)
{
    for (int k = 0; k < TILE_TEXELS; k++)
        if (t->texel[k] >= 0) {
            lx_vec3 a = accum[t->texel[k]];
            t->acc[0][k] = a.x, t->acc[1][k] = a.y, t->acc[2][k] = a.z;
        }
}

/* A tile's direct light, ambient, lights and (for the baked buffers) the
 * sky, into t->acc lane by lane, and with sh (TILE_TEXELS, by texel of
 * the tile) their directions; seed keys its random numbers (the map's
 * index, or a supersampling point's). sampled (NULL: not kept; by texel
 * of the tile) gets the part of it estimated by sampling: soft shadows
 * and the shadowed sky. */
static void shade_tile(const lx_baker *b, uint32_t seed, const lx_lightmap *map, uint32_t first,
                       uint32_t count, const uint32_t *lights, uint32_t light_count,
                       const fast_light *fast, const bool *is_fast, lx_vec3 ambient,
                       bool to_realtime, tile_soa *t, lx_sh4 *sh, uint64_t *shadows,
                       sampled_light *sampled)
{
    lx_vec3 accum[TILE_TEXELS];
    tile_load(b, map, first, count, t);
    if (sampled)
        memset(sampled, 0, sizeof(sampled_light) * count);
    if (shadows)
        memset(shadows, 0, sizeof(uint64_t) * count);
    if (sh) {
        memset(sh, 0, sizeof(lx_sh4) * TILE_TEXELS);
        for (uint32_t k = 0; k < count; k++) {
            const lx_texel_horizon *h =
                map->horizon && map->horizon[first + k].flags ? &map->horizon[first + k] : NULL;
            lx_sh4_add_uniform(&sh[k], h ? lx_scale(ambient, h->ao) : ambient);
        }
    }
    for (uint32_t k = 0; k < TILE_TEXELS; k++)
        t->acc[0][k] = ambient.x, t->acc[1][k] = ambient.y, t->acc[2][k] = ambient.z;
    /* a tile with texels under a height takes the general path,
     * which scales their terms (light_tile) */
    bool horizon = lx_tile_has_horizon(map, first, count);
    if (horizon)
        for (int k = 0; k < TILE_TEXELS; k++) {
            const lx_texel_horizon *h =
                t->texel[k] >= 0 ? &map->horizon[first + (uint32_t)t->texel[k]] : NULL;
            if (h && h->flags) {
                lx_vec3 a = lx_scale(ambient, h->ao);
                t->acc[0][k] = a.x, t->acc[1][k] = a.y, t->acc[2][k] = a.z;
            }
        }
    for (uint32_t l = 0; l < light_count; l++) {
        if (is_fast[l] && !horizon) {
            lx_fast_light_tile(b->tracer, &fast[l], t, sh, shadows, shadow_bit(l));
            continue;
        }
        acc_to_vec3(t, accum);
        light_tile(b, seed, map, first, count, lights[l], accum, sh, shadows, shadow_bit(l),
                   sampled);
        vec3_to_acc(accum, t);
    }
    bool sampled_sky = sampled && b->sky_shadows;
    if (!to_realtime && b->has_sky && !horizon && !sampled_sky) {
        acc_to_vec3(t, accum);
        lx_sky_tile(b, seed, map, first, count, accum, sh, NULL);
        vec3_to_acc(accum, t);
    } else if (!to_realtime && b->has_sky) {
        /* the sky alone, then added as lx_sky_tile adds it (times
         * the AO under a height), and to sampled */
        lx_vec3 sky[TILE_TEXELS];
        lx_sh4 sky_sh[TILE_TEXELS];
        float sky_var[TILE_TEXELS];
        for (uint32_t k = 0; k < count; k++)
            sky[k] = lx_v3(0.0f, 0.0f, 0.0f), sky_var[k] = 0.0f;
        if (sh)
            memset(sky_sh, 0, sizeof sky_sh);
        lx_sky_tile(b, seed, map, first, count, sky, sh ? sky_sh : NULL, sky_var);
        acc_to_vec3(t, accum);
        for (uint32_t k = 0; k < count; k++) {
            const lx_texel_horizon *h =
                map->horizon && map->horizon[first + k].flags ? &map->horizon[first + k] : NULL;
            lx_vec3 add = h ? lx_scale(sky[k], h->ao) : sky[k];
            accum[k] = lx_add(accum[k], add);
            if (sampled_sky) {
                float ao = h ? h->ao : 1.0f;
                sampled[k].e = lx_add(sampled[k].e, add);
                sampled[k].variance += ao * ao * sky_var[k];
            }
            if (sh) {
                if (h)
                    lx_sh4_scale(&sky_sh[k], h->ao);
                for (int c = 0; c < LX_SH_FLOATS; c++)
                    sh[k].c[c] += sky_sh[k].c[c];
            }
        }
        vec3_to_acc(accum, t);
    }
}

/* Texel supersampling: the tile shaded at each of its points s (a view
 * of the map whose samples are point s's, random numbers keyed apart),
 * each texel the mean over its covered points, summed in double in point
 * order (the same light at every point gives back its exact value); a
 * texel no point covers keeps its own sample's light. */
static void shade_supersampled(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                               uint32_t first, uint32_t count, const uint32_t *lights,
                               uint32_t light_count, const fast_light *fast, const bool *is_fast,
                               lx_vec3 ambient, tile_soa *t, lx_sh4 *sh, sampled_light *sampled)
{
    double sum[TILE_TEXELS][3], sh_sum[TILE_TEXELS][LX_SH_FLOATS], sampled_sum[TILE_TEXELS][4];
    uint32_t covered[TILE_TEXELS];
    lx_sh4 point_sh[TILE_TEXELS];
    sampled_light point_sampled[TILE_TEXELS];
    memset(sum, 0, sizeof sum);
    memset(sh_sum, 0, sizeof sh_sum);
    memset(sampled_sum, 0, sizeof sampled_sum);
    memset(covered, 0, sizeof covered);
    size_t used = map->info.used_texels;
    for (uint32_t s = 0; s < map->sub_count; s++) {
        lx_lightmap view = *map;
        view.world_position = map->sub_position + s * used;
        view.world_normal = map->sub_normal + s * used;
        view.world_geometric_normal = map->sub_geometric_normal + s * used;
        const uint8_t *on = map->sub_covered + s * used + first;
        bool any = false;
        for (uint32_t j = 0; j < count && !any; j++)
            any = on[j] != 0;
        if (!any)
            continue;
        shade_tile(b, map_index ^ (s << 16), &view, first, count, lights, light_count, fast,
                   is_fast, ambient, false, t, sh ? point_sh : NULL, NULL,
                   sampled ? point_sampled : NULL);
        for (int k = 0; k < TILE_TEXELS; k++) {
            int32_t j = t->texel[k];
            if (j < 0 || !on[j])
                continue;
            for (int c = 0; c < 3; c++)
                sum[j][c] += (double)t->acc[c][k];
            if (sampled) {
                sampled_sum[j][0] += (double)point_sampled[j].e.x;
                sampled_sum[j][1] += (double)point_sampled[j].e.y;
                sampled_sum[j][2] += (double)point_sampled[j].e.z;
                sampled_sum[j][3] += (double)point_sampled[j].variance;
            }
            for (int c = 0; sh && c < LX_SH_FLOATS; c++)
                sh_sum[j][c] += (double)point_sh[j].c[c];
            covered[j]++;
        }
    }
    bool missing = false;
    for (uint32_t j = 0; j < count; j++)
        missing |= covered[j] == 0;
    if (missing)
        shade_tile(b, map_index, map, first, count, lights, light_count, fast, is_fast, ambient,
                   false, t, sh, NULL, sampled);
    for (int k = 0; k < TILE_TEXELS; k++) {
        int32_t j = t->texel[k];
        if (j < 0 || covered[j] == 0)
            continue;
        for (int c = 0; c < 3; c++)
            t->acc[c][k] = (float)(sum[j][c] / (double)covered[j]);
        if (sampled) { /* the mean of the points, their variances over covered^2 */
            double c = (double)covered[j];
            sampled[j].e = lx_v3((float)(sampled_sum[j][0] / c), (float)(sampled_sum[j][1] / c),
                                 (float)(sampled_sum[j][2] / c));
            sampled[j].variance = (float)(sampled_sum[j][3] / (c * c));
        }
        for (int c = 0; sh && c < LX_SH_FLOATS; c++)
            sh[j].c[c] = (float)(sh_sum[j][c] / (double)covered[j]);
    }
}

/* ---- edge supersampling ----------------------------------------------------
 * After the direct pass each texel has a shadow record (shadow_bit of the
 * hard-shadowed lights blocked at it). A texel whose record differs from
 * a neighbour's on the same node has a shadow edge within a texel of it:
 * each light whose bit differs is shaded again at n x n stratified
 * points of its footprint (its centre plus the footprint axes), and its
 * mean replaces its light at the centre; the other lights keep theirs
 * (a texel under 16 lights on one light's edge shades that light n^2
 * times, not all 16). A point the centre cannot see along the surface (a wall stands
 * between) is left out, as straddle.c leaves out supersampling points
 * under walls. */

/* Each texel of map: the bits in which its shadow record differs from an
 * 8-neighbour's (same node), 0 off edges; returns how many are on edges,
 * or -1 out of memory. */
static int64_t mark_edges(const lx_lightmap *map, const uint64_t *records, uint64_t *edge,
                          int threads)
{
    int w = map->info.width, h = map->info.height;
    int32_t *at = malloc(sizeof(int32_t) * (size_t)w * (size_t)h);
    if (!at)
        return -1;
    memset(at, 0xFF, sizeof(int32_t) * (size_t)w * (size_t)h);
    int64_t used = map->info.used_texels, marked = 0;
    for (int64_t i = 0; i < used; i++)
        at[map->texels[i].pixel] = (int32_t)i;
#pragma omp parallel for schedule(static) reduction(+ : marked) num_threads(threads)
    for (int64_t i = 0; i < used; i++) {
        int x = (int)(map->texels[i].pixel % (uint32_t)w), y = (int)(map->texels[i].pixel / (uint32_t)w);
        uint64_t differs = 0;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int nx = x + dx, ny = y + dy;
                if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h)
                    continue;
                int32_t j = at[(size_t)ny * (size_t)w + (size_t)nx];
                if (j >= 0 && map->texels[j].node == map->texels[i].node)
                    differs |= records[j] ^ records[i];
            }
        edge[i] = differs;
        marked += differs != 0;

    }
    free(at);
    return marked;
}

/* One edge tile's marked texels: their records and frames (a view of
 * the map's arrays for shade_tile), and per footprint point where it
 * lies and whether the centre sees it. */
typedef struct edge_set {
    uint32_t marked, points;
    uint32_t orig[TILE_TEXELS];
    uint64_t mask[TILE_TEXELS];
    lx_vec3 *at;      /* points x marked: the point's position */
    uint8_t *hidden;  /* points x marked: a wall stands between it and the centre */
    uint32_t seen[TILE_TEXELS];
} edge_set;

/* The footprint points of the set's texels (n-rooks within the n x n
 * cells, the canonical multi-jittered pattern: every point its own column
 * and row of n^2, so an edge along either axis of the texel is resolved
 * n^2 ways), and which the centre sees along the surface (lifted by the
 * shadow bias; no rays when nothing but the surface itself is near the
 * tile: no wall stands on it there). */
static void edge_points(const lx_baker *b, const lx_lightmap *map, int n, bool near_walls,
                        edge_set *e)
{
    lx_ray rays[TILE_TEXELS];
    for (int s = 0; s < n * n; s++) {
        int col = s % n, row = s / n;
        float du = ((float)col + ((float)row + 0.5f) / (float)n) / (float)n - 0.5f;
        float dv = ((float)row + ((float)col + 0.5f) / (float)n) / (float)n - 0.5f;
        lx_vec3 *at = e->at + (size_t)s * e->marked;
        for (uint32_t j = 0; j < e->marked; j++) {
            uint32_t i = e->orig[j];
            lx_vec3 p = map->world_position[i], g = map->world_geometric_normal[i];
            const lx_vec3 *axes = lx_texel_axes(map->footprints, &map->texels[i]);
            lx_vec3 step = lx_add(lx_scale(axes[0], du), lx_scale(axes[1], dv));
            at[j] = lx_add(p, step);
            if (!near_walls)
                continue;
            float lifted = b->bias + 4e-6f * lx_max_abs_component(p), len = lx_length(step);
            rays[j] = (lx_ray){.origin = lx_madd(p, g, lifted),
                               .dir = len > 0.0f ? lx_scale(step, 1.0f / len) : g,
                               .tmin = 0.0f,
                               .tmax = len};
        }
        uint8_t *hidden = e->hidden + (size_t)s * e->marked;
        if (near_walls)
            lx_tracer_occluded_batch(b->tracer, rays, e->marked, true, hidden);
        else
            memset(hidden, 0, e->marked);
        for (uint32_t j = 0; j < e->marked; j++)
            e->seen[j] += !hidden[j];
    }
}

/* Light `place` of the pass (lights[place], fast[place]) over the set's
 * texels whose mask has its bit: its mean over their seen points less its
 * light at their centres, added to delta (and sh_delta). */
static void edge_light(const lx_baker *b, uint32_t m, const edge_set *e, uint32_t place,
                       const uint32_t *lights, const fast_light *fast, const bool *is_fast,
                       double (*delta)[3], double (*sh_delta)[LX_SH_FLOATS])
{
    const lx_lightmap *map = &b->maps[m];
    lx_texel rec[TILE_TEXELS];
    lx_vec3 pos[TILE_TEXELS], nrm[TILE_TEXELS], geo[TILE_TEXELS], lift[TILE_TEXELS];
    lx_texel_horizon hor[TILE_TEXELS];
    uint32_t which[TILE_TEXELS], k = 0;
    for (uint32_t j = 0; j < e->marked; j++) {
        if (!(e->mask[j] & shadow_bit(place)) || !e->seen[j])
            continue;
        uint32_t i = e->orig[j];
        which[k] = j;
        rec[k] = map->texels[i];
        pos[k] = map->world_position[i];
        nrm[k] = map->world_normal[i];
        geo[k] = map->world_geometric_normal[i];
        if (map->lift)
            lift[k] = map->lift[i];
        if (map->horizon)
            hor[k] = map->horizon[i];
        k++;
    }
    if (!k)
        return;
    lx_lightmap view = *map;
    view.texels = rec;
    view.world_position = pos;
    view.world_normal = nrm;
    view.world_geometric_normal = geo;
    view.lift = map->lift ? lift : NULL;
    view.horizon = map->horizon ? hor : NULL;
    view.sub_count = 0;
    /* one hard-shadowed light: no random numbers, sky or ambient */
    lx_vec3 none = lx_v3(0.0f, 0.0f, 0.0f);
    tile_soa t;
    lx_sh4 psh[TILE_TEXELS];
    lx_sh4 *sh = sh_delta ? psh : NULL;
    double sum[TILE_TEXELS][3], sh_sum[TILE_TEXELS][LX_SH_FLOATS];
    memset(sum, 0, sizeof(sum[0]) * k);
    memset(sh_sum, 0, sizeof(sh_sum[0]) * k);
    for (int s = -1; s < (int)e->points; s++) {
        /* s = -1: the centres, taken off; then each point, its mean added */
        const uint8_t *hidden = s < 0 ? NULL : e->hidden + (size_t)s * e->marked;
        for (uint32_t q = 0; q < k; q++)
            pos[q] = s < 0 || hidden[which[q]]
                         ? map->world_position[e->orig[which[q]]]
                         : e->at[(size_t)s * e->marked + which[q]];
        shade_tile(b, m, &view, 0, k, &lights[place], 1, &fast[place], &is_fast[place], none,
                   true, &t, sh, NULL, NULL);
        for (int lane = 0; lane < TILE_TEXELS; lane++) {
            int32_t q = t.texel[lane];
            if (q < 0 || (s >= 0 && hidden[which[q]]))
                continue;
            double w = s < 0 ? -(double)e->seen[which[q]] : 1.0;
            for (int c = 0; c < 3; c++)
                sum[q][c] += w * (double)t.acc[c][lane];
            for (int c = 0; sh && c < LX_SH_FLOATS; c++)
                sh_sum[q][c] += w * (double)psh[q].c[c];
        }
    }
    for (uint32_t q = 0; q < k; q++) {
        uint32_t j = which[q];
        double seen = (double)e->seen[j];
        for (int c = 0; c < 3; c++)
            delta[j][c] += sum[q][c] / seen;
        for (int c = 0; sh && c < LX_SH_FLOATS; c++)
            sh_delta[j][c] += sh_sum[q][c] / seen;
    }
}

/* The marked texels of one tile of map m: each light whose shadow differs
 * around a texel shaded again over its footprint, into the baked buffer
 * (and the directional data); false out of memory. */
static bool edge_tile(const lx_baker *b, uint32_t m, uint32_t first, uint32_t count,
                      const uint64_t *edge, int n, const uint32_t *lights, uint32_t light_count,
                      const fast_light *fast, const bool *is_fast, bool directional)
{
    const lx_lightmap *map = &b->maps[m];
    edge_set e = {.points = (uint32_t)(n * n)};
    uint64_t bits = 0;
    for (uint32_t i = first; i < first + count; i++)
        if (edge[i]) {
            e.orig[e.marked] = i;
            e.mask[e.marked] = edge[i];
            e.seen[e.marked] = 0;
            bits |= edge[i];
            e.marked++;
        }
    if (!e.marked)
        return true;
    e.at = malloc(sizeof(lx_vec3) * e.points * e.marked);
    e.hidden = malloc((size_t)e.points * e.marked);
    if (!e.at || !e.hidden) {
        free(e.at);
        free(e.hidden);
        return false;
    }
    edge_points(b, map, n, lx_bake_tile_may_straddle(b, map, first, count), &e);
    double delta[TILE_TEXELS][3], sh_delta[TILE_TEXELS][LX_SH_FLOATS];
    memset(delta, 0, sizeof(delta[0]) * e.marked);
    memset(sh_delta, 0, sizeof(sh_delta[0]) * e.marked);
    for (uint32_t l = 0; l < light_count; l++)
        if (bits & shadow_bit(l))
            edge_light(b, m, &e, l, lights, fast, is_fast, delta, directional ? sh_delta : NULL);
    for (uint32_t j = 0; j < e.marked; j++) {
        if (!e.seen[j])
            continue; /* no point seen: the centre's light stays */
        size_t pixel = map->texels[e.orig[j]].pixel;
        for (int c = 0; c < 3; c++) {
            /* at least 0: where those lights were all of the centre's light
             * the difference leaves a rounding residue of either sign */
            float *px = &map->baked[3 * pixel + (size_t)c];
            *px = (float)fmax((double)*px + delta[j][c], 0.0);
        }
        for (int c = 0; directional && c < LX_SH_FLOATS; c++)
            map->sh[LX_SH_FLOATS * pixel + (size_t)c] += (float)sh_delta[j][c];
    }
    free(e.at);
    free(e.hidden);
    return true;
}

/* Edge supersampling of every map with shadow records (records[m]). */
static lx_status edge_supersample(const lx_baker *b, uint64_t *const *records, int n,
                                  const uint32_t *lights, uint32_t light_count,
                                  const fast_light *fast, const bool *is_fast, bool directional)
{
    int threads = lx_thread_count(b->desc.threads);
    int64_t total = 0;
    for (uint32_t m = 0; m < b->map_count; m++) {
        const lx_lightmap *map = &b->maps[m];
        if (!records[m])
            continue;
        uint64_t *edge = malloc(sizeof(uint64_t) * (map->info.used_texels + 1));
        int64_t marked = edge ? mark_edges(map, records[m], edge, threads) : -1;
        if (marked < 0) {
            free(edge);
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for edge supersampling",
                           map->name);
        }
        total += marked;
        int tiles = (int)map->tile_count, failed = 0;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) reduction(| : failed)
        for (int tile = 0; tile < tiles; tile++)
            failed |= !edge_tile(b, m, map->tile_start[tile],
                                 map->tile_start[tile + 1] - map->tile_start[tile], edge, n, lights,
                                 light_count, fast, is_fast, directional);
        free(edge);
        if (failed)
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for edge supersampling",
                           map->name);
    }
    if (total)
        lx_log(LX_LOG_INFO, "%lld texels on hard shadow edges supersampled (%dx%d points)",
               (long long)total, n, n);
    return LX_OK;
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
    lx_tile_walk w;
    lx_status st = lx_tile_walk_begin(b, progress_base, progress_span, 16, &w);
    if (st != LX_OK)
        return st;
    fast_light *fast = malloc(sizeof(fast_light) * (light_count + 1));
    bool *is_fast = malloc(sizeof(bool) * (light_count + 1));
    if (!fast || !is_fast) {
        free(fast);
        free(is_fast);
        lx_tile_walk_end(&w);
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    }
    /* directional data of the baked buffers only; a fast light's ambient
     * would need its lanes' range window: such lights take the general
     * path then */
    bool directional = !to_realtime && b->desc.directional != LX_DIRECTIONAL_OFF;
    for (uint32_t l = 0; l < light_count; l++) {
        is_fast[l] = fast_light_init(&b->lights[lights[l]], &fast[l]);
        if (directional && (fast[l].mr != 0.0f || fast[l].mg != 0.0f || fast[l].mb != 0.0f))
            is_fast[l] = false;
    }
    int threads = lx_thread_count(b->desc.threads);
    /* edge supersampling: the maps in memory that keep their footprints
     * record each texel's shadows */
    int edge_n = to_realtime ? 0 : lx_bake_edge_supersample(&b->desc);
    uint64_t **records = edge_n ? calloc(b->map_count + 1, sizeof(uint64_t *)) : NULL;
    bool out_of_memory = edge_n && !records;
    for (uint32_t m = 0; records && m < b->map_count && !out_of_memory; m++) {
        const lx_lightmap *map = &b->maps[m];
        if (map->loaded && map->footprints && map->info.used_texels)
            out_of_memory = !(records[m] = malloc(sizeof(uint64_t) * map->info.used_texels));
    }
    if (out_of_memory) {
        for (uint32_t m = 0; records && m < b->map_count; m++)
            free(records[m]);
        free(records);
        free(fast);
        free(is_fast);
        lx_tile_walk_end(&w);
        return lx_fail(LX_ERR_NOMEM, "out of memory for edge supersampling");
    }

#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int global = 0; global < w.tiles; global++) {
        if (w.cancelled)
            continue;
        uint32_t m, first, count;
        lx_tile_walk_at(&w, global, &m, &first, &count);
        const lx_lightmap *map = &b->maps[m];
        float *target = to_realtime ? map->realtime : map->baked;
        if (count) {
            tile_soa t;
            lx_sh4 shs[TILE_TEXELS];
            lx_sh4 *sh = directional ? shs : NULL;
            sampled_light sampled_buf[TILE_TEXELS];
            sampled_light *sampled = !to_realtime && map->sampled ? sampled_buf : NULL;
            if (map->sub_count > 1 && !to_realtime)
                shade_supersampled(b, m, map, first, count, lights, light_count, fast, is_fast,
                                   ambient, &t, sh, sampled);
            else
                shade_tile(b, m, map, first, count, lights, light_count, fast, is_fast, ambient,
                           to_realtime, &t, sh, records && records[m] ? records[m] + first : NULL,
                           sampled);
            /* every texel belongs to one tile: plain stores, no clearing */
            for (int k = 0; k < TILE_TEXELS; k++) {
                if (t.texel[k] < 0)
                    continue;
                float *px = target + (size_t)map->texels[first + (uint32_t)t.texel[k]].pixel * 3;
                px[0] = t.acc[0][k];
                px[1] = t.acc[1][k];
                px[2] = t.acc[2][k];
                if (sampled) { /* the emitters add theirs after */
                    const sampled_light *sl = &sampled[t.texel[k]];
                    size_t pixel = (size_t)(px - target) / 3;
                    memcpy(map->sampled + 3 * pixel, &sl->e, sizeof(lx_vec3));
                    map->sampled_variance[pixel] = sl->variance;
                }
                if (sh)
                    memcpy(map->sh + (size_t)map->texels[first + (uint32_t)t.texel[k]].pixel *
                                         LX_SH_FLOATS,
                           &shs[t.texel[k]], sizeof(lx_sh4));
            }
        }
        lx_tile_walk_done(&w, global, count);
    }
    st = lx_tile_walk_end(&w);
    if (st == LX_OK && records)
        st = edge_supersample(b, records, edge_n, lights, light_count, fast, is_fast,
                              directional);
    for (uint32_t m = 0; records && m < b->map_count; m++)
        free(records[m]);
    free(records);
    free(fast);
    free(is_fast);
    if (st != LX_OK)
        return st;
    if (b->desc.progress && !b->desc.progress(b->desc.progress_user, progress_base + progress_span))
        return lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    return LX_OK;
}
