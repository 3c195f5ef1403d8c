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
 * irradiance integral). Escaping rays and back faces bring nothing.
 * Validity (Unity's "backface tolerance"): a texel whose rays mostly hit
 * back faces sits inside geometry; it is left out of the bounces and takes
 * its valid neighbours' average at the end. Every texel's rays are seeded
 * by (map, texel, sample, bounce), and each texel is written by one tile,
 * so the bytes are the same for any thread count. */
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

lx_status lx_gi_prepare(lx_baker *b, const lx_scene *scene)
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
        bool any = emits;
        for (int s = 0; s < LX_MAX_UV_SETS && ok; s++) {
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
                if (mi >= scene->mesh_count || !b->mesh_positions[mi])
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

/* Per map during the indirect pass. */
typedef struct gi_map {
    uint8_t *valid;   /* width * height: covered and not inside geometry */
    float *source;    /* width * height * 3: exitant radiance of the last bounce */
    lx_vec3 *prev;    /* per texel: the last bounce's irradiance */
    lx_vec3 *next;    /* per texel: this bounce's */
    lx_sh4 *next_sh;  /* per texel: this bounce's directional data (NULL
                         unless desc.directional) */
    uint8_t *invalid; /* per texel, from the validity pass */
} gi_map;

typedef struct gi_run {
    lx_baker *b;
    gi_map *maps;
    lx_radiance_source *sources; /* each map's valid and source, for lx_hit_radiance */
    uint32_t *map_first_tile;
    int tiles;
    int threads;
    /* progress */
    uint64_t total_work;
    float base, span;
} gi_run;

lx_gather_frame lx_gather_frame_of(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                                   uint32_t i)
{
    lx_gather_frame f;
    lx_vec3 p = map->world_position[i];
    f.n = map->world_normal[i];
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
        if (lx_tracer_closest(b->tracer, &ray, &h) && lx_dot(ray.dir, h.normal) > 0.0f)
            back++;
    }
    return 2 * back > cells;
}

/* One gather for one texel: pi / N x the radiance its rays bring; with
 * sh, the same rays' estimate of int L Y dw (lx_sh_ray_weight / N x L Y,
 * directional.c). */
static lx_vec3 texel_gather(const gi_run *run, uint32_t map_index, uint32_t i, uint32_t key,
                            lx_sh4 *sh)
{
    const lx_baker *b = run->b;
    const lx_lightmap *map = &b->maps[map_index];
    uint32_t sx, sy;
    lx_cosine_strata(b->desc.gi_samples, &sx, &sy);
    uint32_t cells = sx * sy;
    double sum[3] = {0.0, 0.0, 0.0}, shs[LX_SH_FLOATS] = {0};
    lx_gather_frame f = lx_gather_frame_of(b, map_index, map, i);
    for (uint32_t k = 0; k < cells; k++) {
        lx_ray ray;
        lx_hit h;
        if (!lx_gather_ray(&f, k, sx, sy, key, &ray))
            continue;
        if (!lx_tracer_closest(b->tracer, &ray, &h) || !(lx_dot(ray.dir, h.normal) < 0.0f))
            continue; /* escaped (sky: direct light), or a back face */
        /* emission is direct light (emitters.c), not picked up here */
        lx_vec3 l = lx_hit_radiance(b, run->sources, false, &h);
        sum[0] += l.x;
        sum[1] += l.y;
        sum[2] += l.z;
        if (sh) {
            lx_vec3 d = ray.dir;
            float w0;
            lx_vec3 v;
            lx_sh_ray_weight(k, sx, d, f.n, &w0, &v);
            double y[4] = {LX_SH_Y0 * w0, LX_SH_Y1 * v.y, LX_SH_Y1 * v.z, LX_SH_Y1 * v.x};
            for (int c = 0; c < 4; c++) {
                shs[3 * c] += l.x * y[c];
                shs[3 * c + 1] += l.y * y[c];
                shs[3 * c + 2] += l.z * y[c];
            }
        }
    }
    if (sh)
        for (int c = 0; c < LX_SH_FLOATS; c++)
            sh->c[c] = (float)(shs[c] / (double)cells);
    double scale = LX_PI / (double)cells;
    return lx_v3((float)(sum[0] * scale), (float)(sum[1] * scale), (float)(sum[2] * scale));
}

/* One pass over every tile of every map: the validity pass (validity) or
 * a gather into gi_map.next (keyed by key). false when cancelled. */
static bool run_pass(gi_run *run, bool validity, uint32_t key, float from, float to)
{
    lx_baker *b = run->b;
    bool report = b->desc.progress != NULL;
    volatile int cancelled = 0;
    uint64_t done_work = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(run->threads)
    for (int global = 0; global < run->tiles; global++) {
        if (cancelled)
            continue;
        uint32_t m = 0;
        while (run->map_first_tile[m + 1] <= (uint32_t)global)
            m++;
        const lx_lightmap *map = &b->maps[m];
        gi_map *g = &run->maps[m];
        uint32_t tile = (uint32_t)global - run->map_first_tile[m];
        uint32_t first = map->tile_start[tile], count = map->tile_start[tile + 1] - first;
        for (uint32_t i = first; i < first + count; i++) {
            if (validity) {
                g->invalid[i] = lx_gi_texel_inside(b, m, i);
            } else if (g->invalid[i]) {
                g->next[i] = lx_v3(0.0f, 0.0f, 0.0f);
                if (g->next_sh)
                    memset(&g->next_sh[i], 0, sizeof(lx_sh4));
            } else {
                g->next[i] = texel_gather(run, m, i, key, g->next_sh ? &g->next_sh[i] : NULL);
            }
        }
        if (report) {
            uint64_t done;
#pragma omp atomic capture
            done = done_work += count + 1;
            if (omp_get_thread_num() == 0) {
                double f = (double)done / (double)run->total_work;
                if (!b->desc.progress(b->desc.progress_user,
                                      run->base + run->span * (from + (to - from) * (float)f)))
                    cancelled = 1;
            }
        }
    }
    return !cancelled;
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

lx_status lx_bake_indirect(lx_baker *b, float progress_base, float progress_span)
{
    uint32_t count = b->map_count;
    gi_run run = {.b = b, .base = progress_base, .span = progress_span};
    run.threads = lx_thread_count(b->desc.threads);
    run.maps = calloc(count + 1, sizeof(gi_map));
    run.sources = calloc(count + 1, sizeof(lx_radiance_source));
    run.map_first_tile = malloc(sizeof(uint32_t) * (count + 1));
    lx_status st = LX_OK;
    if (!run.maps || !run.sources || !run.map_first_tile)
        st = lx_fail(LX_ERR_NOMEM, "out of memory for global illumination");
    uint64_t bytes = 0;
    for (uint32_t m = 0; m < count && st == LX_OK; m++) {
        const lx_lightmap *map = &b->maps[m];
        uint64_t pixels = (uint64_t)map->info.width * (uint64_t)map->info.height;
        bytes += pixels * 13 + (uint64_t)map->info.used_texels * 25;
        if (map->sh)
            bytes += (uint64_t)map->info.used_texels * sizeof(lx_sh4);
    }
    if (st == LX_OK)
        st = lx_check_memory(bytes, "global illumination's buffers");
    if (run.map_first_tile)
        run.map_first_tile[0] = 0;
    for (uint32_t m = 0; m < count && st == LX_OK; m++) {
        const lx_lightmap *map = &b->maps[m];
        gi_map *g = &run.maps[m];
        size_t pixels = (size_t)map->info.width * (size_t)map->info.height;
        size_t used = map->info.used_texels + 1;
        g->valid = malloc(pixels);
        g->source = malloc(sizeof(float) * 3 * pixels);
        g->prev = malloc(sizeof(lx_vec3) * used);
        g->next = malloc(sizeof(lx_vec3) * used);
        g->invalid = malloc(used);
        g->next_sh = map->sh ? malloc(sizeof(lx_sh4) * used) : NULL;
        if (!g->valid || !g->source || !g->prev || !g->next || !g->invalid ||
            (map->sh && !g->next_sh))
            st = lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for global illumination",
                         map->name);
        run.sources[m].valid = g->valid;
        run.sources[m].source = g->source;
        run.map_first_tile[m + 1] = run.map_first_tile[m] + map->tile_count;
        run.total_work += map->info.used_texels + map->tile_count;
    }
    run.tiles = st == LX_OK ? (int)run.map_first_tile[count] : 0;
    float passes = (float)(b->desc.bounces + 1);
    /* validity */
    if (st == LX_OK && !run_pass(&run, true, 0, 0.0f, 1.0f / passes))
        st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
    b->gi_invalid_texels = 0;
    for (uint32_t m = 0; m < count && st == LX_OK; m++) {
        const lx_lightmap *map = &b->maps[m];
        gi_map *g = &run.maps[m];
        memcpy(g->valid, map->mask, (size_t)map->info.width * (size_t)map->info.height);
        for (uint32_t i = 0; i < map->info.used_texels; i++) {
            size_t p = map->texels[i].pixel;
            if (g->invalid[i]) {
                g->valid[p] = 0;
                b->gi_invalid_texels++;
            }
            g->prev[i] = lx_v3(map->baked[3 * p], map->baked[3 * p + 1], map->baked[3 * p + 2]);
        }
    }
    for (int k = 1; k <= b->desc.bounces && st == LX_OK; k++) {
        /* the sources: albedo / pi x the last bounce (emission is direct
         * light, emitters.c: already in the first) */
        for (uint32_t m = 0; m < count; m++) {
            const lx_lightmap *map = &b->maps[m];
            gi_map *g = &run.maps[m];
            memset(g->source, 0,
                   sizeof(float) * 3 * (size_t)map->info.width * (size_t)map->info.height);
            for (uint32_t i = 0; i < map->info.used_texels; i++) {
                if (g->invalid[i])
                    continue;
                lx_vec3 l = lx_scale(lx_mul(map->albedo[i], g->prev[i]), 1.0f / LX_PI);
                float *dst = g->source + 3 * (size_t)map->texels[i].pixel;
                dst[0] = l.x, dst[1] = l.y, dst[2] = l.z;
            }
        }
        if (!run_pass(&run, false, GI_KEY + 2u * (uint32_t)k, (float)k / passes,
                      (float)(k + 1) / passes)) {
            st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
            break;
        }
        for (uint32_t m = 0; m < count; m++) {
            lx_lightmap *map = &b->maps[m];
            gi_map *g = &run.maps[m];
            for (uint32_t i = 0; i < map->info.used_texels; i++) {
                float *px = map->baked + 3 * (size_t)map->texels[i].pixel;
                px[0] += g->next[i].x;
                px[1] += g->next[i].y;
                px[2] += g->next[i].z;
                if (g->next_sh) {
                    float *q = map->sh + (size_t)map->texels[i].pixel * LX_SH_FLOATS;
                    for (int c = 0; c < LX_SH_FLOATS; c++)
                        q[c] += g->next_sh[i].c[c];
                }
            }
            lx_vec3 *swap = g->prev;
            g->prev = g->next;
            g->next = swap;
        }
    }
    for (uint32_t m = 0; m < count && st == LX_OK; m++)
        if (b->gi_invalid_texels)
        {
            st = lx_gi_fill_invalid(&b->maps[m], run.maps[m].valid, run.maps[m].invalid,
                                    b->maps[m].baked, 3);
            if (st == LX_OK && b->maps[m].sh)
                st = lx_gi_fill_invalid(&b->maps[m], run.maps[m].valid, run.maps[m].invalid,
                                        b->maps[m].sh, LX_SH_FLOATS);
        }
    if (st == LX_OK && b->gi_invalid_texels)
        lx_log(LX_LOG_INFO,
               "global illumination: %llu texels sit inside geometry (their rays mostly hit back "
               "faces); they take their valid neighbours' light",
               (unsigned long long)b->gi_invalid_texels);
    for (uint32_t m = 0; run.maps && m < count; m++) {
        free(run.maps[m].valid);
        free(run.maps[m].source);
        free(run.maps[m].prev);
        free(run.maps[m].next);
        free(run.maps[m].invalid);
        free(run.maps[m].next_sh);
    }
    free(run.maps);
    free(run.sources);
    free(run.map_first_tile);
    return st;
}
