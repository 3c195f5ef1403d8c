/* Indirect diffuse light (global illumination) in the baker: a final
 * gather per bounce over the lightmaps themselves, the "irradiance
 * caching in lightmap space" production lightmappers use (Unity's and
 * Bakery's progressive lightmappers, Frostbite's Flux, as described in
 * Hillaire's and Seyb's talks; the method is Jensen's final gather, with
 * the lightmap as the cache). Bounce k: every valid texel casts N
 * stratified cosine-weighted rays (Malley's method, as sky.c); a ray that
 * hits the front face of a lightmapped surface reads that surface's bounce
 * k-1 exitant radiance, albedo / pi x E_{k-1} (emission is not picked up:
 * emitters are direct light, emitters.c, already in E_0), bilinearly over
 * the valid texels of its lightmap; the
 * texel's E_k = pi / N x sum (the cosine-weighted estimator of the
 * irradiance integral). Escaping rays and back faces bring nothing (of a
 * double-sided material: the face its texels do not bake, sides.c).
 * Validity (Unity's "backface tolerance"): a texel whose rays mostly hit
 * back faces of single-sided materials sits inside geometry; it is left out of the bounces and
 * takes its valid neighbours' average at the end. Every texel's rays are seeded by (map, texel,
 * sample, bounce), and each texel is written by one tile, so the bytes are the same for any thread
 * count. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* lx_random dimensions apart from the lights' and the sky's */
#define GI_KEY 0x6100u
#define VALIDITY_KEY 0x6000u
/* rays of the validity pass, at most */
#define VALIDITY_RAYS 64u
/* rings searched for a valid texel when none of the four bilinear ones is */
#define LOOKUP_RINGS 3
/* lx_random dimensions of the guided rays, apart from the cosine ones' */
#define GUIDE_KEY 0x4000u
/* the fewest gi_samples (a bounce's) that are guided */
#define GUIDE_MIN_SAMPLES 64u

lx_status lx_gi_prepare(lx_baker *b, const lx_scene *scene, bool emitters_only)
{
    b->mesh_count = scene->mesh_count;
    size_t m1 = scene->mesh_count + 1;
    b->node_uv_set = calloc(scene->node_count + 1, 1);
    for (int s = 0; s < LX_MAX_UV_SETS; s++)
        b->mesh_uv[s] = calloc(m1, sizeof(lx_vec2 *));
    b->mesh_indices = calloc(m1, sizeof(uint32_t *));
    b->mesh_triangles = calloc(m1, sizeof(uint32_t));
    b->mesh_emission = calloc(m1, sizeof(lx_vec3));
    b->mesh_positions = calloc(m1, sizeof(lx_vec3 *));
    b->mesh_emission_textured = calloc(m1, 1);
    bool ok = b->node_uv_set && b->mesh_indices && b->mesh_triangles && b->mesh_emission &&
              b->mesh_positions && b->mesh_emission_textured;
    for (int s = 0; s < LX_MAX_UV_SETS; s++)
        ok &= b->mesh_uv[s] != NULL;
    for (uint32_t m = 0; m < scene->mesh_count && ok; m++) {
        const lx_mesh *mesh = &scene->meshes[m];
        const lx_material *mat =
            mesh->material < scene->material_count ? &scene->materials[mesh->material] : NULL;
        if (mat)
            b->mesh_emission[m] = lx_material_emission(mat, b->desc.emissive_scale);
        lx_vec3 em = b->mesh_emission[m];
        bool emits = (em.x > 0.0f || em.y > 0.0f || em.z > 0.0f) && mesh->triangle_count > 0;
        if (emits) {
            /* an emitter (emitters.c): its triangles in object space */
            b->mesh_emission_textured[m] = mat->emissive_map.width > 0;
            b->mesh_positions[m] = malloc(sizeof(lx_vec3) * (mesh->vertex_count + 1));
            ok = b->mesh_positions[m] != NULL;
            if (ok)
                memcpy(b->mesh_positions[m], mesh->positions,
                       sizeof(lx_vec3) * mesh->vertex_count);
        }
        /* direct light only: the emitters' meshes are all it reads */
        bool any = emits;
        for (int s = 0; s < LX_MAX_UV_SETS && ok && (emits || !emitters_only); s++) {
            if (!mesh->uv[s])
                continue;
            any = true;
            b->mesh_uv[s][m] = malloc(sizeof(lx_vec2) * (mesh->vertex_count + 1));
            ok = b->mesh_uv[s][m] != NULL;
            if (ok)
                memcpy(b->mesh_uv[s][m], mesh->uv[s], sizeof(lx_vec2) * mesh->vertex_count);
        }
        if (!any || !ok)
            continue;
        b->mesh_indices[m] = malloc(sizeof(uint32_t) * 3 * ((size_t)mesh->triangle_count + 1));
        ok = b->mesh_indices[m] != NULL;
        if (ok)
            memcpy(b->mesh_indices[m], mesh->indices,
                   sizeof(uint32_t) * 3 * (size_t)mesh->triangle_count);
        b->mesh_triangles[m] = mesh->triangle_count;
    }
    /* the emitters' instances: every node's emissive meshes */
    uint32_t count = 0;
    for (int pass = 0; pass < 2 && ok; pass++) {
        count = 0;
        for (uint32_t n = 0; n < scene->node_count; n++)
            for (uint32_t k = 0; k < scene->nodes[n].mesh_count; k++) {
                uint32_t mi = scene->nodes[n].meshes[k];
                /* a node out of the bounces emits nothing into them */
                if (mi >= scene->mesh_count || !b->mesh_positions[mi] ||
                    scene->nodes[n].bake.no_contribute_gi)
                    continue;
                if (pass)
                    b->emitters[count] = (lx_emitter_instance){n, mi};
                count++;
            }
        if (!pass && count) {
            b->emitters = malloc(sizeof(lx_emitter_instance) * count);
            ok = b->emitters != NULL;
        }
    }
    b->emitter_count = ok ? count : 0;
    if (!ok)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for global illumination", scene->path);
    return LX_OK;
}

void lx_gi_free(lx_baker *b)
{
    for (uint32_t m = 0; m < b->mesh_count; m++) {
        for (int s = 0; s < LX_MAX_UV_SETS; s++)
            if (b->mesh_uv[s])
                free(b->mesh_uv[s][m]);
        if (b->mesh_indices)
            free(b->mesh_indices[m]);
        if (b->mesh_positions)
            free(b->mesh_positions[m]);
    }
    free(b->mesh_positions);
    free(b->mesh_emission_textured);
    free(b->emitters);
    b->mesh_positions = NULL;
    b->mesh_emission_textured = NULL;
    b->emitters = NULL;
    b->emitter_count = 0;
    for (int s = 0; s < LX_MAX_UV_SETS; s++) {
        free(b->mesh_uv[s]);
        b->mesh_uv[s] = NULL;
    }
    free(b->mesh_indices);
    free(b->mesh_triangles);
    free(b->mesh_emission);
    free(b->node_uv_set);
    b->mesh_indices = NULL;
    b->mesh_triangles = NULL;
    b->mesh_emission = NULL;
    b->node_uv_set = NULL;
}

/* Per map during the indirect pass: what every gather reads (resident for
 * the whole pass, every map) and what a tile of maps works with. */
typedef struct gi_map {
    uint8_t *valid;     /* width * height: covered and not inside geometry */
    float *source;      /* width * height * 3: exitant radiance of the last bounce */
    float *source_next; /* width * height * 3: the next bounce's, made as tiles finish */
    lx_vec3 *next;      /* tile: per texel, this bounce's irradiance */
    lx_sh4 *next_sh;    /* tile: per texel, this bounce's directional data
                           (NULL unless desc.directional) */
    float *next_var;    /* tile: per texel, the variance of this bounce's
                           luminance (NULL unless map->gi_variance) */
    uint8_t *invalid;   /* tile: per texel, inside geometry */
} gi_map;

typedef struct gi_run {
    lx_baker *b;
    gi_map *maps;
    lx_radiance_source *sources; /* each map's valid and source, for lx_hit_radiance */
    int threads;
    uint32_t samples; /* this bounce's gather rays a texel */
    double dark; /* adaptive gathers: the radiance luminance under which a
                    texel's noise is judged against this, not its own */
} gi_run;

/* Adaptive gathers: the rounds at least and at most. */
enum { ADAPTIVE_MIN_ROUNDS = 2, ADAPTIVE_MAX_ROUNDS = 16 };

lx_gather_frame lx_gather_frame_of(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                                   uint32_t i)
{
    lx_gather_frame f;
    lx_vec3 p = map->world_position[i];
    /* the vertex normal where a normal map bent the shading one: a
     * texel-scale bump in the map would mottle the indirect light */
    f.n = map->world_smooth_normal ? map->world_smooth_normal[i] : map->world_normal[i];
    f.ng = map->world_geometric_normal[i];
    f.t = lx_perpendicular(f.n);
    f.bt = lx_cross(f.n, f.t);
    f.origin = lx_madd(p, f.ng, b->bias + 4e-6f * lx_max_abs_component(p));
    f.map = map_index;
    f.pixel = map->texels[i].pixel;
    return f;
}

bool lx_gather_ray(const lx_gather_frame *f, uint32_t k, uint32_t sx, uint32_t sy, uint32_t key,
                   lx_ray *ray)
{
    lx_vec3 d = lx_cosine_direction(f->t, f->bt, f->n, f->map, f->pixel, k, sx, sy, key);
    if (!(lx_dot(d, f->ng) > 0.0f))
        return false;
    ray->origin = f->origin;
    ray->dir = d;
    ray->tmin = 0.0f;
    ray->tmax = INFINITY;
    return true;
}

bool lx_gi_hit_texel(const lx_baker *b, uint32_t node, uint32_t mesh, uint32_t triangle, float u,
                     float v, uint32_t *map_index, float *fx_out, float *fy_out)
{
    if (mesh >= b->mesh_count || node >= b->node_count)
        return false;
    uint32_t mi = b->node_map[node];
    int set = mi == UINT32_MAX ? 0 : b->node_uv_set[node];
    const lx_vec2 *uv = mi == UINT32_MAX ? NULL : b->mesh_uv[set][mesh];
    if (!uv || triangle >= b->mesh_triangles[mesh])
        return false;
    const uint32_t *tri = b->mesh_indices[mesh] + 3 * (size_t)triangle;
    float w0 = 1.0f - u - v;
    float s = uv[tri[0]].x * w0 + uv[tri[1]].x * u + uv[tri[2]].x * v;
    float t = uv[tri[0]].y * w0 + uv[tri[1]].y * u + uv[tri[2]].y * v;
    const float *so = b->node_scale_offset[node];
    s = s * so[0] + so[2];
    t = t * so[1] + so[3];
    const lx_lightmap *map = &b->maps[mi];
    int w = map->info.width, hgt = map->info.height;
    float fx = s * (float)w - 0.5f, fy = t * (float)hgt - 0.5f;
    if (!isfinite(fx) || !isfinite(fy))
        return false;
    *map_index = mi;
    *fx_out = fminf(fmaxf(fx, -1.0f), (float)w);
    *fy_out = fminf(fmaxf(fy, -1.0f), (float)hgt);
    return true;
}

lx_vec3 lx_gi_lookup(const lx_lightmap *map, const uint8_t *valid, const float *data, float fx,
                     float fy)
{
    int w = map->info.width, hgt = map->info.height;
    int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
    float ax = fx - (float)x0, ay = fy - (float)y0;
    float sum[3] = {0.0f, 0.0f, 0.0f}, wsum = 0.0f;
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            int x = x0 + dx, y = y0 + dy;
            if (x < 0 || y < 0 || x >= w || y >= hgt)
                continue;
            size_t p = (size_t)y * (size_t)w + (size_t)x;
            if (!valid[p])
                continue;
            float wt = (dx ? ax : 1.0f - ax) * (dy ? ay : 1.0f - ay);
            wsum += wt;
            for (int c = 0; c < 3; c++)
                sum[c] += wt * data[3 * p + c];
        }
    if (wsum > 0.0f)
        return lx_v3(sum[0] / wsum, sum[1] / wsum, sum[2] / wsum);
    /* none of the four: the valid texels of the nearest ring */
    int cx = (int)floorf(fx + 0.5f), cy = (int)floorf(fy + 0.5f);
    for (int r = 1; r <= LOOKUP_RINGS; r++) {
        int n = 0;
        for (int y = cy - r; y <= cy + r; y++)
            for (int x = cx - r; x <= cx + r; x++) {
                if (abs(x - cx) != r && abs(y - cy) != r)
                    continue;
                if (x < 0 || y < 0 || x >= w || y >= hgt)
                    continue;
                size_t p = (size_t)y * (size_t)w + (size_t)x;
                if (!valid[p])
                    continue;
                for (int c = 0; c < 3; c++)
                    sum[c] += data[3 * p + c];
                n++;
            }
        if (n)
            return lx_v3(sum[0] / (float)n, sum[1] / (float)n, sum[2] / (float)n);
    }
    return lx_v3(0.0f, 0.0f, 0.0f);
}

lx_vec3 lx_hit_radiance(const lx_baker *b, const lx_radiance_source *sources, bool emission,
                        const lx_hit *h)
{
    uint32_t mi;
    float fx, fy;
    if (!lx_gi_hit_texel(b, h->node, h->mesh, h->triangle, h->u, h->v, &mi, &fx, &fy))
        return emission && h->mesh < b->mesh_count ? b->mesh_emission[h->mesh]
                                                   : lx_v3(0.0f, 0.0f, 0.0f);
    return lx_gi_lookup(&b->maps[mi], sources[mi].valid, sources[mi].source, fx, fy);
}

bool lx_gi_texel_inside(const lx_baker *b, uint32_t map_index, uint32_t i)
{
    const lx_lightmap *map = &b->maps[map_index];
    uint32_t want = b->desc.gi_samples < VALIDITY_RAYS ? b->desc.gi_samples : VALIDITY_RAYS;
    uint32_t sx, sy;
    lx_cosine_strata(want, &sx, &sy);
    uint32_t cells = sx * sy, back = 0;
    lx_gather_frame f = lx_gather_frame_of(b, map_index, map, i);
    for (uint32_t k = 0; k < cells; k++) {
        lx_ray ray;
        lx_hit h;
        if (!lx_gather_ray(&f, k, sx, sy, VALIDITY_KEY, &ray))
            continue;
        if (lx_tracer_closest_kind(b->tracer, &ray, LX_RAY_GATHER, &h) &&
            lx_bake_hit_inside(b, ray.dir, &h))
            back++;
    }
    return 2 * back > cells;
}

uint32_t lx_gi_bounce_samples(uint32_t samples, int bounce)
{
    /* the second and later bounces bring albedo times less light than the
     * one before and read its smoother light: half the rays (at least 16)
     * keep their share of the noise small for a quarter less time (two
     * bounces) */
    if (bounce < 2 || samples <= 16)
        return samples;
    return samples / 2 > 16 ? samples / 2 : 16;
}

/* A texel's gather so far: its rays' values y (radiance over the pdf,
 * over pi: the bounce's irradiance is pi x their mean), summed, with
 * their luminance's sums for the noise and, with SH, the SH estimate. */
typedef struct gather_acc {
    double sum[3], lum, lum2, shs[LX_SH_FLOATS];
    uint32_t rays, sh_rays; /* all of them; the cosine-weighted ones */
} gather_acc;

static void acc_add(gather_acc *a, lx_vec3 y)
{
    a->sum[0] += y.x;
    a->sum[1] += y.y;
    a->sum[2] += y.z;
    const float rgb[3] = {y.x, y.y, y.z};
    double luma = lx_luminance(rgb);
    a->lum += luma;
    a->lum2 += luma * luma;
}

/* The exitant radiance a gather ray brings: false when it escapes (the
 * sky is direct light) or hits a back face. Emission is direct light
 * (emitters.c), not picked up here. */
static bool ray_radiance(const gi_run *run, lx_ray *ray, lx_vec3 *l)
{
    lx_hit h;
    if (!lx_tracer_closest_kind(run->b->tracer, ray, LX_RAY_GATHER, &h) ||
        !lx_bake_hit_surface(run->b, ray->dir, &h))
        return false;
    *l = lx_hit_radiance(run->b, run->sources, false, &h);
    return true;
}

/* One round of a texel's gather: `want` stratified cosine-weighted rays
 * (rounded up to the strata); with guide, as many again drawn from it,
 * every ray then weighed by the balance heuristic of the two pdfs. With
 * learn, each ray's luminance goes into it; with sh, the cosine-weighted
 * rays' SH estimate. */
static void gather_round(const gi_run *run, const lx_gather_frame *f, uint32_t want,
                         const lx_gi_guide *guide, uint32_t key, gather_acc *acc,
                         lx_gi_guide *learn, bool sh)
{
    uint32_t sx, sy;
    lx_cosine_strata(want, &sx, &sy);
    uint32_t cells = sx * sy;
    for (uint32_t k = 0; k < 2 * cells; k++) {
        lx_ray ray;
        lx_vec3 l;
        if (k < cells) {
            if (!lx_gather_ray(f, k, sx, sy, key, &ray))
                continue;
        } else {
            if (!guide)
                break;
            uint32_t j = k - cells;
            float u = ((float)j + lx_random(f->map, f->pixel, j, key + GUIDE_KEY)) / (float)cells;
            ray.dir = lx_gi_guide_sample(guide, fminf(u, 0x1.fffffep-1f),
                                         lx_random(f->map, f->pixel, j, key + GUIDE_KEY + 1),
                                         lx_random(f->map, f->pixel, j, key + GUIDE_KEY + 2));
            if (!(lx_dot(ray.dir, f->ng) > 0.0f) || !(lx_dot(ray.dir, f->n) > 0.0f))
                continue;
            ray.origin = f->origin;
            ray.tmin = 0.0f;
            ray.tmax = INFINITY;
        }
        if (!ray_radiance(run, &ray, &l))
            continue;
        if (sh && k < cells) {
            /* the SH estimate from the cosine-weighted rays alone, with
             * their stratum weights (directional.c) */
            float w0;
            lx_vec3 v;
            lx_sh_ray_weight(k, sx, ray.dir, f->n, &w0, &v);
            double y[4] = {LX_SH_Y0 * w0, LX_SH_Y1 * v.y, LX_SH_Y1 * v.z, LX_SH_Y1 * v.x};
            for (int c = 0; c < 4; c++) {
                acc->shs[3 * c] += l.x * y[c];
                acc->shs[3 * c + 1] += l.y * y[c];
                acc->shs[3 * c + 2] += l.z * y[c];
            }
        }
        if (guide) {
            /* L cos / (pi x the mixture's pdf), the mixture (cos / pi + pdf_guide) / 2 */
            float c = lx_dot(ray.dir, f->n);
            float w = 2.0f * c / (c + LX_PI * lx_gi_guide_pdf(guide, ray.dir));
            l = lx_scale(l, w > 0.0f && isfinite(w) ? w : 0.0f);
        }
        acc_add(acc, l);
        if (learn) {
            const float rgb[3] = {l.x, l.y, l.z};
            lx_gi_guide_add(learn, ray.dir, lx_luminance(rgb));
        }
    }
    acc->rays += guide ? 2 * cells : cells;
    acc->sh_rays += cells;
}

/* Adaptive gathers: the rounds of `per_round` rays a tile's texels take
 * in all, from their first round: as many as the tile's mean relative
 * variance a ray asks for the standard error to reach
 * LX_GI_ADAPTIVE_NOISE (of a texel's mean, or of run->dark where darker),
 * within [ADAPTIVE_MIN_ROUNDS, ADAPTIVE_MAX_ROUNDS]. One count for the
 * tile: a texel judged by its own rays would stop early exactly when they
 * missed the bright part (a low estimate with a low spread), and leave
 * dark blotches. */
static uint32_t tile_rounds(const gi_run *run, const gather_acc *acc, const uint8_t *invalid,
                            uint32_t count, uint32_t per_round)
{
    double cv2 = 0.0;
    uint32_t judged = 0;
    for (uint32_t j = 0; j < count; j++) {
        if (invalid[j] || acc[j].rays < 2)
            continue;
        double n = (double)acc[j].rays, mean = acc[j].lum / n;
        double spread = fmax((acc[j].lum2 - acc[j].lum * mean) / (n - 1.0), 0.0);
        double ref = fmax(mean, run->dark);
        if (ref > 0.0) {
            cv2 += spread / (ref * ref);
            judged++;
        }
    }
    double need =
        judged ? cv2 / (double)judged / (LX_GI_ADAPTIVE_NOISE * LX_GI_ADAPTIVE_NOISE) : 0.0;
    double rounds = ceil(need / (double)per_round);
    return rounds <= ADAPTIVE_MIN_ROUNDS   ? ADAPTIVE_MIN_ROUNDS
           : rounds >= ADAPTIVE_MAX_ROUNDS ? ADAPTIVE_MAX_ROUNDS
                                           : (uint32_t)rounds;
}

/* A texel's result from its gather: pi / N x the sum into next; the SH
 * estimate; the estimate's luminance variance (the rays' sample variance
 * over N, stratification ignored: an upper bound). */
static void gather_finish(const gather_acc *a, lx_vec3 *next, lx_sh4 *sh, float *variance)
{
    double n = a->rays ? (double)a->rays : 1.0;
    if (sh)
        for (int c = 0; c < LX_SH_FLOATS; c++)
            sh->c[c] = (float)(a->shs[c] / (a->sh_rays ? (double)a->sh_rays : 1.0));
    if (variance) {
        double spread = a->rays > 1 ? (a->lum2 - a->lum * a->lum / n) / (n - 1.0) : 0.0;
        *variance = (float)(LX_PI * LX_PI * fmax(spread, 0.0) / n);
    }
    double scale = LX_PI / n;
    *next = lx_v3((float)(a->sum[0] * scale), (float)(a->sum[1] * scale),
                  (float)(a->sum[2] * scale));
}

/* The gathers of texels [first, first + count) of map m (one tile, at most
 * LX_TILE^2 texels) into g->next. Plain: gi_samples cosine-weighted rays
 * each. Guided (lx_bake_desc.gi_sampling): a first round of
 * a quarter of the rays for every texel teaches the tile's guide, the rest
 * come half from it. Adaptive: rounds of a quarter go on per texel until
 * its noise is low (the guided rounds after the first). */
static void tile_gather(const gi_run *run, gi_map *g, uint32_t m, uint32_t first, uint32_t count,
                        uint32_t key)
{
    const lx_baker *b = run->b;
    const lx_lightmap *map = &b->maps[m];
    bool sh = g->next_sh != NULL, adaptive = b->desc.gi_adaptive;
    /* a guide learns from a quarter of the rays: at least 16 a texel, a
     * ray a cell over the tile; fewer leave it too spiky to help */
    uint32_t n = run->samples, quarter = (n + 3) / 4 < 4 ? 4 : (n + 3) / 4;
    bool guided = b->desc.gi_sampling == LX_GI_SAMPLING_GUIDED && n >= GUIDE_MIN_SAMPLES;
    uint32_t round0 = adaptive || guided ? quarter : n;
    gather_acc acc[LX_TILE * LX_TILE];
    lx_gather_frame frame[LX_TILE * LX_TILE];
    lx_gi_guide guide;
    if (count > LX_TILE * LX_TILE)
        count = LX_TILE * LX_TILE; /* tiles are LX_TILE x LX_TILE texels */
    memset(acc, 0, sizeof(gather_acc) * count);
    lx_gi_guide_clear(&guide);
    for (uint32_t j = 0; j < count; j++) {
        if (g->invalid[first + j])
            continue;
        frame[j] = lx_gather_frame_of(b, m, map, first + j);
        gather_round(run, &frame[j], round0, NULL, key, &acc[j], guided ? &guide : NULL, sh);
    }
    const lx_gi_guide *use = guided && lx_gi_guide_build(&guide) ? &guide : NULL;
    uint32_t rounds = adaptive ? tile_rounds(run, acc, g->invalid + first, count, quarter) : 1;
    for (uint32_t j = 0; j < count; j++) {
        uint32_t i = first + j;
        if (g->invalid[i]) {
            g->next[i] = lx_v3(0.0f, 0.0f, 0.0f);
            if (g->next_sh)
                memset(&g->next_sh[i], 0, sizeof(lx_sh4));
            if (g->next_var)
                g->next_var[i] = 0.0f;
            continue;
        }
        const lx_gather_frame *f = &frame[j];
        /* a guided round casts twice its cosine-weighted rays */
        uint32_t per_round = use ? (quarter + 1) / 2 : quarter;
        if (adaptive) {
            for (uint32_t r = 1; r < rounds; r++)
                gather_round(run, f, per_round, use, key + (r << 16), &acc[j], NULL, sh);
        } else if (guided) {
            uint32_t rest = n > acc[j].rays ? n - acc[j].rays : 0;
            if (rest)
                gather_round(run, f, use ? (rest + 1) / 2 : rest, use, key + (1u << 16),
                             &acc[j], NULL, sh);
        }
        gather_finish(&acc[j], &g->next[i], g->next_sh ? &g->next_sh[i] : NULL,
                      g->next_var ? &g->next_var[i] : NULL);
    }
}

/* One pass over every tile of every map in memory: the validity pass
 * (validity) or a gather into gi_map.next (keyed by key), within [from,
 * to] of the progress. */
static lx_status run_pass(gi_run *run, bool validity, uint32_t key, float from, float to)
{
    lx_baker *b = run->b;
    lx_tile_walk w;
    lx_status st = lx_tile_walk_begin(b, from, to - from, 1, &w);
    if (st != LX_OK)
        return st;
#pragma omp parallel for schedule(dynamic, 1) num_threads(run->threads)
    for (int global = 0; global < w.tiles; global++) {
        if (w.cancelled)
            continue;
        uint32_t m, first, count;
        lx_tile_walk_at(&w, global, &m, &first, &count);
        gi_map *g = &run->maps[m];
        if (validity)
            for (uint32_t i = first; i < first + count; i++)
                g->invalid[i] = lx_gi_texel_inside(b, m, i);
        else
            tile_gather(run, g, m, first, count, key);
        lx_tile_walk_done(&w, global, count);
    }
    return lx_tile_walk_end(&w);
}

/* Gives invalid texels the average of their valid (or already filled)
 * 8-neighbours among the covered texels, ring by ring, each pass reading
 * what the previous one left; texels no valid texel reaches keep their
 * value. Sequential: invalid texels are few. */
lx_status lx_gi_fill_invalid(const lx_lightmap *map, const uint8_t *valid, const uint8_t *invalid,
                             float *buf, int channels)
{
    int w = map->info.width, h = map->info.height;
    uint32_t n = map->info.used_texels, open = 0;
    uint32_t *todo = malloc(sizeof(uint32_t) * (n + 1));
    float *vals = malloc(sizeof(float) * (size_t)channels * (n + 1));
    uint8_t *filled = malloc((size_t)w * (size_t)h);
    if (!todo || !vals || !filled) {
        free(todo);
        free(vals);
        free(filled);
        return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory", map->name);
    }
    memcpy(filled, valid, (size_t)w * (size_t)h);
    for (uint32_t i = 0; i < n; i++)
        if (invalid[i])
            todo[open++] = map->texels[i].pixel;
    while (open) {
        uint32_t got = 0;
        for (uint32_t k = 0; k < open; k++) {
            uint32_t p = todo[k];
            int x = (int)(p % (uint32_t)w), y = (int)(p / (uint32_t)w);
            float s[LX_SH_FLOATS] = {0};
            int c = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int xx = x + dx, yy = y + dy;
                    if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h)
                        continue;
                    size_t q = (size_t)yy * (size_t)w + (size_t)xx;
                    if (filled[q] != 1)
                        continue;
                    for (int ch = 0; ch < channels; ch++)
                        s[ch] += buf[(size_t)channels * q + (size_t)ch];
                    c++;
                }
            if (c) {
                for (int ch = 0; ch < channels; ch++)
                    vals[(size_t)channels * k + (size_t)ch] = s[ch] / (float)c;
                filled[p] = 2; /* this pass: not read until it ends */
                got++;
            }
        }
        if (!got)
            break;
        uint32_t left = 0;
        for (uint32_t k = 0; k < open; k++) {
            uint32_t p = todo[k];
            if (filled[p] == 2) {
                memcpy(buf + (size_t)channels * p, vals + (size_t)channels * k,
                       sizeof(float) * (size_t)channels);
                filled[p] = 1;
            } else {
                todo[left++] = p;
            }
        }
        open = left;
    }
    free(todo);
    free(vals);
    free(filled);
    return LX_OK;
}

/* The per-texel buffers of the maps of tile t (the maps in memory):
 * this bounce's irradiance (and directional data) and the inside flags,
 * from the valid mask once the validity pass has made it. */
static lx_status tile_begin(gi_run *run, uint32_t t, bool from_valid)
{
    lx_baker *b = run->b;
    lx_status st = lx_bake_tile_need(b, b->tile_first_map[t]);
    for (uint32_t m = b->tile_first_map[t]; m < b->tile_first_map[t + 1] && st == LX_OK; m++) {
        const lx_lightmap *map = &b->maps[m];
        gi_map *g = &run->maps[m];
        size_t used = map->info.used_texels + 1;
        g->next = malloc(sizeof(lx_vec3) * used);
        g->invalid = malloc(used);
        g->next_sh = map->sh ? malloc(sizeof(lx_sh4) * used) : NULL;
        g->next_var = map->gi_variance ? malloc(sizeof(float) * used) : NULL;
        if (!g->next || !g->invalid || (map->sh && !g->next_sh) ||
            (map->gi_variance && !g->next_var)) {
            st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for global illumination",
                         map->name);
            break;
        }
        if (from_valid)
            for (uint32_t i = 0; i < map->info.used_texels; i++)
                g->invalid[i] = !g->valid[map->texels[i].pixel];
    }
    return st;
}

static void tile_end(gi_run *run, uint32_t t)
{
    for (uint32_t m = run->b->tile_first_map[t]; m < run->b->tile_first_map[t + 1]; m++) {
        gi_map *g = &run->maps[m];
        free(g->next);
        free(g->invalid);
        free(g->next_sh);
        free(g->next_var);
        g->next = NULL;
        g->invalid = NULL;
        g->next_sh = NULL;
        g->next_var = NULL;
    }
}

/* A source buffer from per-texel irradiance e: albedo / pi x e at valid
 * texels, 0 elsewhere (emission is direct light, emitters.c: already in
 * the first bounce's e). */
static void make_source(const lx_lightmap *map, const gi_map *g, const lx_vec3 *e, float *dst)
{
    memset(dst, 0, sizeof(float) * 3 * (size_t)map->info.width * (size_t)map->info.height);
    for (uint32_t i = 0; i < map->info.used_texels; i++) {
        if (g->invalid[i])
            continue;
        lx_vec3 l = lx_scale(lx_mul(map->albedo[i], e[i]), 1.0f / LX_PI);
        float *px = dst + 3 * (size_t)map->texels[i].pixel;
        px[0] = l.x, px[1] = l.y, px[2] = l.z;
    }
}

/* Adds a tile map's bounce to its baked light (and directional data). */
static void add_bounce(lx_lightmap *map, const gi_map *g)
{
    for (uint32_t i = 0; i < map->info.used_texels; i++) {
        size_t p = map->texels[i].pixel;
        float *px = map->baked + 3 * p;
        px[0] += g->next[i].x;
        px[1] += g->next[i].y;
        px[2] += g->next[i].z;
        if (g->next_sh) {
            float *q = map->sh + p * LX_SH_FLOATS;
            for (int c = 0; c < LX_SH_FLOATS; c++)
                q[c] += g->next_sh[i].c[c];
        }
        if (g->next_var)
            map->gi_variance[p] += g->next_var[i];
    }
}

static lx_status fill_invalid(lx_lightmap *map, const gi_map *g)
{
    lx_status st = lx_gi_fill_invalid(map, g->valid, g->invalid, map->baked, 3);
    if (st == LX_OK && map->sh)
        st = lx_gi_fill_invalid(map, g->valid, g->invalid, map->sh, LX_SH_FLOATS);
    return st;
}

/* One pass over tile t with the gi_map buffers of its maps: false and
 * *st set when it fails or is cancelled (its buffers let go). */
static bool tile_pass(gi_run *run, uint32_t t, bool validity, uint32_t key, float from, float to,
                      lx_status *st)
{
    float tf, tt;
    lx_bake_tile_share(run->b, t, from, to, &tf, &tt);
    if (!lx_bake_report(run->b, tf) || (*st = tile_begin(run, t, !validity)) != LX_OK ||
        (*st = run_pass(run, validity, key, tf, tt)) != LX_OK) {
        if (*st == LX_OK)
            *st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
        tile_end(run, t);
        return false;
    }
    return true;
}

/* The mean luminance of the valid texels' sources (the radiance the
 * gathers read), over every map. */
static double mean_source(const gi_run *run)
{
    double sum = 0.0;
    uint64_t n = 0;
    for (uint32_t m = 0; m < run->b->map_count; m++) {
        const lx_lightmap *map = &run->b->maps[m];
        size_t pixels = (size_t)map->info.width * (size_t)map->info.height;
        for (size_t p = 0; p < pixels; p++)
            if (run->maps[m].valid[p]) {
                sum += lx_luminance(run->maps[m].source + 3 * p);
                n++;
            }
    }
    return n ? sum / (double)n : 0.0;
}

/* The passes run tile by tile (one tile when the maps fit the memory
 * together): the validity pass makes each map's valid mask and first
 * sources from its direct light; each bounce gathers a tile's texels
 * against every map's sources of the last bounce, adds the result and
 * makes the tile's sources of the next; the last bounce fills the invalid
 * texels. Every value is the one the maps would get all at once. */
lx_status lx_bake_indirect(lx_baker *b, float progress_base, float progress_span)
{
    uint32_t count = b->map_count;
    gi_run run = {.b = b};
    run.threads = lx_thread_count(b->desc.threads);
    run.maps = calloc(count + 1, sizeof(gi_map));
    run.sources = calloc(count + 1, sizeof(lx_radiance_source));
    lx_status st = LX_OK;
    if (!run.maps || !run.sources)
        st = lx_fail(LX_ERR_NOMEM, "out of memory for global illumination");
    uint64_t bytes = 0;
    for (uint32_t m = 0; m < count && st == LX_OK; m++)
        bytes += (uint64_t)b->maps[m].info.width * (uint64_t)b->maps[m].info.height *
                 (b->desc.bounces > 1 ? 25 : 13);
    if (st == LX_OK)
        st = lx_check_memory(bytes, "global illumination's buffers");
    for (uint32_t m = 0; m < count && st == LX_OK; m++) {
        const lx_lightmap *map = &b->maps[m];
        gi_map *g = &run.maps[m];
        size_t pixels = (size_t)map->info.width * (size_t)map->info.height;
        g->valid = malloc(pixels);
        g->source = malloc(sizeof(float) * 3 * pixels);
        g->source_next = b->desc.bounces > 1 ? malloc(sizeof(float) * 3 * pixels) : NULL;
        /* the variance the denoiser is guided by, summed over the bounces */
        free(b->maps[m].gi_variance);
        b->maps[m].gi_variance =
            b->desc.denoise == LX_DENOISE_INDIRECT ? calloc(pixels + 1, sizeof(float)) : NULL;
        if (!g->valid || !g->source || (b->desc.bounces > 1 && !g->source_next) ||
            (b->desc.denoise == LX_DENOISE_INDIRECT && !b->maps[m].gi_variance))
            st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for global illumination",
                         map->name);
        run.sources[m].valid = g->valid;
    }
    float span = progress_span / (float)(b->desc.bounces + 1);
    /* validity, and the first sources: albedo / pi x the direct light */
    b->gi_invalid_texels = 0;
    for (uint32_t t = 0; t < b->tile_count && st == LX_OK; t++) {
        if (!tile_pass(&run, t, true, 0, progress_base, progress_base + span, &st))
            break;
        for (uint32_t m = b->tile_first_map[t]; m < b->tile_first_map[t + 1]; m++) {
            const lx_lightmap *map = &b->maps[m];
            gi_map *g = &run.maps[m];
            memcpy(g->valid, map->mask, (size_t)map->info.width * (size_t)map->info.height);
            for (uint32_t i = 0; i < map->info.used_texels; i++) {
                size_t p = map->texels[i].pixel;
                g->next[i] = lx_v3(map->baked[3 * p], map->baked[3 * p + 1], map->baked[3 * p + 2]);
                if (g->invalid[i]) {
                    g->valid[p] = 0;
                    b->gi_invalid_texels++;
                }
            }
            make_source(map, g, g->next, g->source);
        }
        tile_end(&run, t);
    }
    for (int k = 1; k <= b->desc.bounces && st == LX_OK; k++) {
        bool last = k == b->desc.bounces;
        float from = progress_base + span * (float)k;
        for (uint32_t m = 0; m < count; m++)
            run.sources[m].source = run.maps[m].source;
        run.dark = b->desc.gi_adaptive ? 0.1 * mean_source(&run) : 0.0;
        run.samples = lx_gi_bounce_samples(b->desc.gi_samples, k);
        for (uint32_t t = 0; t < b->tile_count && st == LX_OK; t++) {
            if (!tile_pass(&run, t, false, GI_KEY + 2u * (uint32_t)k, from, from + span, &st))
                break;
            for (uint32_t m = b->tile_first_map[t]; m < b->tile_first_map[t + 1] && st == LX_OK;
                 m++) {
                lx_lightmap *map = &b->maps[m];
                gi_map *g = &run.maps[m];
                add_bounce(map, g);
                if (!last)
                    make_source(map, g, g->next, g->source_next);
                else if (b->gi_invalid_texels)
                    st = fill_invalid(map, g);
            }
            tile_end(&run, t);
        }
        /* the next bounce reads what this one made */
        for (uint32_t m = 0; m < count && st == LX_OK && !last; m++) {
            float *swap = run.maps[m].source;
            run.maps[m].source = run.maps[m].source_next;
            run.maps[m].source_next = swap;
        }
    }
    if (st == LX_OK && b->gi_invalid_texels)
        lx_log(LX_LOG_INFO,
               "global illumination: %llu texels sit inside geometry (their rays mostly hit back "
               "faces); they take their valid neighbours' light",
               (unsigned long long)b->gi_invalid_texels);
    for (uint32_t m = 0; run.maps && m < count; m++) {
        /* the valid mask stays for the denoiser (invalid texels keep their
         * filled light), when a texel is invalid */
        free(b->maps[m].gi_valid);
        b->maps[m].gi_valid = NULL;
        if (st == LX_OK && b->gi_invalid_texels)
            b->maps[m].gi_valid = run.maps[m].valid;
        else
            free(run.maps[m].valid);
        free(run.maps[m].source);
        free(run.maps[m].source_next);
        free(run.maps[m].next);
        free(run.maps[m].invalid);
        free(run.maps[m].next_sh);
        free(run.maps[m].next_var);
    }
    free(run.maps);
    free(run.sources);
    return st;
}
