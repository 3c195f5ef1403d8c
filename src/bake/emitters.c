/* Emissive surfaces as direct light: next-event estimation of the emissive
 * triangles (Shirley, Wang and Zimmerman, "Monte Carlo Techniques for
 * Direct Lighting Calculations", ACM TOG 1996; Pharr, Jakob and Humphreys,
 * Physically Based Rendering, 3rd ed., 14.2: light sampling), with the
 * exact unshadowed irradiance of each triangle (Lambert's polygon formula,
 * Arvo, "Analytic Methods for Simulated Light Transport", 1995) as a
 * control variate when the emitters are few.
 *
 * The emitters are every node's emissive triangles, picked for each
 * texel by a light tree (emitter_tree.c: with probability close to each
 * one's share of the texel's light, from its power, distance and
 * orientation, so a texel beside one of many small emitters samples that
 * one); a point on the picked triangle is uniform in area. A texel
 * casts S stratified samples (the unit square in sx x sy cells, jittered
 * by (map, texel, sample), so any thread count gives the same bytes): the
 * first coordinate picks the triangle down the tree and, rescaled within
 * the picked share, places the point with the second. Each sample
 * brings L_e(x) V cos(theta) cos(theta') / d^2 / pdf(x), V from a shadow
 * ray (lx_shadow_ray), theta at the texel's shading normal, theta' at the
 * emitter's front face (an emitter emits from its front only, as the
 * gathers see it).
 *
 * With at most EXACT_TRIANGLES emissive triangles, the estimator is
 *     E = sum_j L_j F_j + 1/S sum_k (L_e(x_k) V_k - L_j(k)) G_k / pdf_k,
 * F_j the triangle's exact point-to-polygon transfer (the triangle clipped
 * to the texel's hemisphere), L_j its emission at its centroid: unbiased
 * (the correction's expectation is the shadowed part less the exact
 * unshadowed sum), and exact wherever every sample is visible and the
 * emission uniform - only penumbrae are noisy. Beyond that count, the
 * plain estimator (1/S sum L_e V G / pdf). A result below zero (a
 * correction larger than the exact sum, noise) is clamped to zero.
 *
 * The gathers (gi.c) no longer pick up emission: each emitter's light is
 * counted here once. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* lx_random dimensions apart from the lights', the sky's and GI's */
#define NEE_KEY 0x6400u
/* the control variate sums every triangle at every texel up to this many */
#define EXACT_TRIANGLES 64u
/* shadow rays per texel at most (desc.gi_samples when fewer) */
#define NEE_SAMPLES_MAX 256u

typedef struct emitter_tri {
    lx_vec3 p0, e1, e2; /* a vertex and the edges to the other two */
    lx_vec3 n;          /* unit front normal */
    float area;
    lx_vec3 le; /* emission at the centroid */
    uint32_t node, mesh, triangle;
    bool textured;
} emitter_tri;

struct lx_emitter_set {
    emitter_tri *tri;
    uint32_t count;
    lx_emitter_tree *tree; /* picks a triangle for a texel (emitter_tree.c) */
    bool exact;
    float **emission; /* per map: emitted radiance per pixel, or NULL (all NULL
                         when no emitter has a texture) */
};
typedef struct lx_emitter_set emitter_set;

static float max3(lx_vec3 v)
{
    return fmaxf(v.x, fmaxf(v.y, v.z));
}

/* The emission at barycentrics (u, v) of an emitter triangle: the
 * material's without a texture; with one, its lightmap's texels there
 * (a textured emitter without a lightmap: the factor). */
static lx_vec3 emission_at(const lx_baker *b, const emitter_set *set, const emitter_tri *t, float u,
                           float v)
{
    if (!t->textured)
        return b->mesh_emission[t->mesh];
    uint32_t mi;
    float fx, fy;
    if (!lx_gi_hit_texel(b, t->node, t->mesh, t->triangle, u, v, &mi, &fx, &fy) ||
        !set->emission[mi])
        return b->mesh_emission[t->mesh];
    return lx_gi_lookup(&b->maps[mi], b->maps[mi].mask, set->emission[mi], fx, fy);
}

static void emitter_set_free(const lx_baker *b, emitter_set *set)
{
    for (uint32_t m = 0; set->emission && m < b->map_count; m++)
        free(set->emission[m]);
    free(set->emission);
    free(set->tri);
    lx_emitter_tree_destroy(set->tree);
}

static lx_status emitter_set_build(lx_baker *b, emitter_set *set)
{
    memset(set, 0, sizeof *set);
    uint64_t n = 0;
    for (uint32_t e = 0; e < b->emitter_count; e++)
        n += b->mesh_triangles[b->emitters[e].mesh];
    if (n > UINT32_MAX / 2)
        return lx_fail(LX_ERR_INVALID, "%llu emissive triangles are too many",
                       (unsigned long long)n);
    /* the triangles, their bounds while building, and the tree's nodes */
    lx_status st = lx_check_memory(n * (sizeof(emitter_tri) + sizeof(lx_emitter_bounds) + 256),
                                   "the emitters");
    if (st != LX_OK)
        return st;
    set->tri = malloc(sizeof(emitter_tri) * (n + 1));
    lx_emitter_bounds *bounds = malloc(sizeof(lx_emitter_bounds) * (n + 1));
    set->emission = calloc(b->map_count + 1, sizeof(float *));
    if (!set->tri || !bounds || !set->emission) {
        free(bounds);
        emitter_set_free(b, set);
        return lx_fail(LX_ERR_NOMEM, "out of memory for the emitters");
    }
    /* the emitting maps' emission per pixel, for textured emitters (a
     * tiled baker builds each map's texels again to read it) */
    bool textured = false;
    for (uint32_t e = 0; e < b->emitter_count; e++)
        textured |= b->mesh_emission_textured[b->emitters[e].mesh] != 0;
    for (uint32_t m = 0; m < b->map_count && textured; m++) {
        lx_status need = lx_bake_tile_need(b, m);
        if (need != LX_OK) {
            free(bounds);
            emitter_set_free(b, set);
            return need;
        }
        const lx_lightmap *map = &b->maps[m];
        if (!map->emission)
            continue;
        size_t pixels = (size_t)map->info.width * (size_t)map->info.height;
        if (!(set->emission[m] = calloc(pixels * 3, sizeof(float)))) {
            free(bounds);
            emitter_set_free(b, set);
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for its emission",
                           map->name);
        }
        for (uint32_t i = 0; i < map->info.used_texels; i++) {
            float *px = set->emission[m] + 3 * (size_t)map->texels[i].pixel;
            px[0] = map->emission[i].x, px[1] = map->emission[i].y, px[2] = map->emission[i].z;
        }
    }
    uint32_t count = 0;
    for (uint32_t e = 0; e < b->emitter_count; e++) {
        uint32_t node = b->emitters[e].node, mesh = b->emitters[e].mesh;
        const lx_mat4 *w = &b->node_world[node];
        float flip = lx_mat4_det3(w) < 0.0f ? -1.0f : 1.0f;
        lx_vec3 le = b->mesh_emission[mesh];
        float rgb[3] = {le.x, le.y, le.z};
        double lum = lx_luminance(rgb);
        const lx_vec3 *pos = b->mesh_positions[mesh];
        for (uint32_t t = 0; t < b->mesh_triangles[mesh]; t++) {
            const uint32_t *idx = b->mesh_indices[mesh] + 3 * (size_t)t;
            emitter_tri *tr = &set->tri[count];
            lx_vec3 a = lx_mat4_point(w, pos[idx[0]]), bb = lx_mat4_point(w, pos[idx[1]]),
                    c = lx_mat4_point(w, pos[idx[2]]);
            tr->p0 = a;
            tr->e1 = lx_sub(bb, a);
            tr->e2 = lx_sub(c, a);
            lx_vec3 cr = lx_cross(tr->e1, tr->e2);
            float len = lx_length(cr);
            tr->area = 0.5f * len;
            if (!(tr->area > 0.0f) || !isfinite(tr->area) || !(lum > 0.0))
                continue; /* emits nothing */
            tr->n = lx_scale(cr, flip / len);
            tr->node = node, tr->mesh = mesh, tr->triangle = t;
            tr->textured = b->mesh_emission_textured[mesh] != 0;
            tr->le = emission_at(b, set, tr, 1.0f / 3.0f, 1.0f / 3.0f);
            lx_emitter_bounds *bd = &bounds[count];
            bd->lo = lx_v3(fminf(a.x, fminf(bb.x, c.x)), fminf(a.y, fminf(bb.y, c.y)),
                           fminf(a.z, fminf(bb.z, c.z)));
            bd->hi = lx_v3(fmaxf(a.x, fmaxf(bb.x, c.x)), fmaxf(a.y, fmaxf(bb.y, c.y)),
                           fmaxf(a.z, fmaxf(bb.z, c.z)));
            bd->normal = tr->n;
            bd->power = lum * (double)tr->area;
            count++;
        }
    }
    set->count = count;
    set->exact = count <= EXACT_TRIANGLES;
    st = lx_emitter_tree_build(bounds, count, &set->tree);
    free(bounds);
    if (st != LX_OK)
        emitter_set_free(b, set);
    return st;
}

/* Lambert's formula: the irradiance at p (unit normal n) from a convex
 * polygon of unit radiance, 1/2 |sum_i gamma_i n . c_i| (gamma_i the angle
 * the edge subtends, c_i the unit normal of the plane through p and the
 * edge). The polygon lies in the hemisphere of n. */
static double polygon_transfer(const double (*v)[3], int count, const double p[3],
                               const double n[3])
{
    double sum = 0.0;
    for (int i = 0; i < count; i++) {
        const double *q0 = v[i], *q1 = v[(i + 1) % count];
        double a[3] = {q0[0] - p[0], q0[1] - p[1], q0[2] - p[2]};
        double b[3] = {q1[0] - p[0], q1[1] - p[1], q1[2] - p[2]};
        double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
        double cl = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        if (!(cl > 0.0))
            continue;
        double gamma = atan2(cl, dot);
        sum += gamma * (n[0] * c[0] + n[1] * c[1] + n[2] * c[2]) / cl;
    }
    return 0.5 * fabs(sum);
}

/* The exact unshadowed transfer of a triangle to a point: the triangle
 * clipped to the point's hemisphere (Sutherland-Hodgman, one plane). */
static double triangle_transfer(const emitter_tri *t, lx_vec3 p, lx_vec3 n)
{
    double in[3][3], out[4][3], pd[3] = {p.x, p.y, p.z}, nd[3] = {n.x, n.y, n.z};
    lx_vec3 q[3] = {t->p0, lx_add(t->p0, t->e1), lx_add(t->p0, t->e2)};
    double h[3];
    for (int i = 0; i < 3; i++) {
        in[i][0] = q[i].x, in[i][1] = q[i].y, in[i][2] = q[i].z;
        h[i] = (in[i][0] - pd[0]) * nd[0] + (in[i][1] - pd[1]) * nd[1] + (in[i][2] - pd[2]) * nd[2];
    }
    int m = 0;
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3;
        if (h[i] >= 0.0)
            memcpy(out[m++], in[i], sizeof in[i]);
        if ((h[i] >= 0.0) != (h[j] >= 0.0)) {
            double s = h[i] / (h[i] - h[j]);
            for (int c = 0; c < 3; c++)
                out[m][c] = in[i][c] + s * (in[j][c] - in[i][c]);
            m++;
        }
    }
    return m >= 3 ? polygon_transfer((const double(*)[3])out, m, pd, nd) : 0.0;
}

/* Whether p is in front of an emitter triangle (further than the bias:
 * a texel on the emitter's own plane gets nothing from it). */
static bool in_front(const lx_baker *b, const emitter_tri *t, lx_vec3 p)
{
    return lx_dot(t->n, lx_sub(p, t->p0)) > b->bias;
}

/* The shadow ray from texel point p (geometric normal ng) to emitter
 * point x (front normal ne), d = x - p: both ends moved off their
 * surfaces by the scale-aware bias (lx_shadow_ray's at p; at x along the
 * emitter's normal), so the ray neither starts behind the texel's surface
 * nor reaches the emitter itself, at any angle. */
static lx_ray shadow_ray(const lx_baker *b, lx_vec3 p, lx_vec3 ng, lx_vec3 x, lx_vec3 ne, lx_vec3 d)
{
    lx_vec3 side = lx_dot(ng, d) >= 0.0f ? ng : lx_neg(ng);
    lx_vec3 o = lx_madd(p, side, b->bias + 4e-6f * lx_max_abs_component(p));
    lx_vec3 end = lx_madd(x, ne, b->bias + 4e-6f * lx_max_abs_component(x));
    lx_vec3 dir = lx_sub(end, o);
    float len = lx_length(dir);
    lx_ray r;
    r.origin = o;
    r.dir = len > 0.0f ? lx_scale(dir, 1.0f / len) : lx_v3(0.0f, 1.0f, 0.0f);
    r.tmin = 0.0f;
    r.tmax = len;
    return r;
}

/* order[0..n) a permutation of 0..n-1 (n <= NEE_SAMPLES_MAX), from the
 * texel's seed (Fisher-Yates). */
static void shuffle(uint8_t *order, uint32_t n, uint32_t map_index, uint32_t pixel, uint32_t key)
{
    for (uint32_t i = 0; i < n; i++)
        order[i] = (uint8_t)i;
    for (uint32_t i = n; i > 1; i--) {
        uint32_t j = (uint32_t)(lx_random(map_index, pixel, i, key) * (float)i);
        j = j < i ? j : i - 1;
        uint8_t t = order[i - 1];
        order[i - 1] = order[j];
        order[j] = t;
    }
}

/* The emitters' irradiance at texel i of map. */
static lx_vec3 texel_emitters(const lx_baker *b, const emitter_set *set, uint32_t map_index,
                              const lx_lightmap *map, uint32_t i, lx_vec3 *towards,
                              float *variance)
{
    double lum_sum = 0.0, lum_squares = 0.0; /* the samples' luminance */
    lx_vec3 p = map->world_position[i], n = map->world_normal[i];
    lx_vec3 ng = map->world_geometric_normal[i];
    uint32_t pixel = map->texels[i].pixel;
    double sum[3] = {0.0, 0.0, 0.0}, exact[3] = {0.0, 0.0, 0.0};
    /* where the light comes from, for the directional data: the exact
     * sum's triangles by their share (towards their centroids), else the
     * visible samples by theirs */
    double dir[3] = {0.0, 0.0, 0.0};
    if (set->exact)
        for (uint32_t j = 0; j < set->count; j++) {
            const emitter_tri *t = &set->tri[j];
            if (!in_front(b, t, p))
                continue;
            double f = triangle_transfer(t, p, n);
            exact[0] += f * t->le.x, exact[1] += f * t->le.y, exact[2] += f * t->le.z;
            lx_vec3 c = lx_add(t->p0, lx_scale(lx_add(t->e1, t->e2), 1.0f / 3.0f));
            lx_vec3 u = lx_normalize(lx_sub(c, p));
            double w = f * (double)max3(t->le);
            dir[0] += w * u.x, dir[1] += w * u.y, dir[2] += w * u.z;
        }
    uint32_t want = b->desc.gi_samples < NEE_SAMPLES_MAX ? b->desc.gi_samples : NEE_SAMPLES_MAX;
    uint32_t sx, sy;
    lx_cosine_strata(want, &sx, &sy);
    uint32_t cells = sx * sy;
    /* multi-jittered samples (Chiu, Shirley and Wang, "Multi-jittered
     * sampling", Graphics Gems IV, 1994; Kensler's correlated form):
     * stratified in the sx x sy cells and over all `cells` strata on each
     * axis, so the tree's pick (the first coordinate) sees every stratum
     * of its unit interval once. The columns' and rows' orders are
     * shuffled per texel. */
    uint8_t column[NEE_SAMPLES_MAX], row[NEE_SAMPLES_MAX];
    shuffle(column, sx, map_index, pixel, NEE_KEY + 2);
    shuffle(row, sy, map_index, pixel, NEE_KEY + 3);
    enum { BATCH = 64 };
    lx_ray rays[BATCH];
    lx_vec3 on[BATCH], off[BATCH]; /* what a visible and a blocked sample add */
    lx_vec3 ways[BATCH];
    uint8_t occluded[BATCH];
    uint32_t k = 0;
    while (k < cells) {
        uint32_t m = 0;
        for (; m < BATCH && k < cells; k++) {
            float u = ((float)k + lx_random(map_index, pixel, k, NEE_KEY)) / (float)cells;
            float v = ((float)column[k % sx] +
                       ((float)row[k / sx] + lx_random(map_index, pixel, k, NEE_KEY + 1)) /
                           (float)sy) /
                      (float)sx;
            u = fminf(u, 0x1.fffffep-1f), v = fminf(v, 0x1.fffffep-1f);
            /* the triangle, by its share of the texel's light (the tree) */
            uint32_t pick;
            double prob;
            float ur;
            if (!lx_emitter_tree_pick(set->tree, p, n, u, &pick, &prob, &ur))
                continue;
            const emitter_tri *t = &set->tri[pick];
            if (!in_front(b, t, p))
                continue;
            float su = sqrtf(ur), bu = su * (1.0f - v), bv = su * v;
            lx_vec3 x = lx_add(t->p0, lx_add(lx_scale(t->e1, bu), lx_scale(t->e2, bv)));
            lx_vec3 d = lx_sub(x, p);
            float d2 = lx_dot(d, d);
            if (!(d2 > 0.0f))
                continue;
            float dist = sqrtf(d2);
            float cos_r = lx_dot(n, d) / dist, cos_e = -lx_dot(t->n, d) / dist;
            if (!(cos_r > 0.0f) || !(cos_e > 0.0f))
                continue;
            /* G / pdf, pdf = prob / area */
            double g = (double)cos_r * (double)cos_e / (double)d2 / prob * (double)t->area;
            if (!isfinite(g))
                continue;
            lx_vec3 le = t->textured ? emission_at(b, set, t, bu, bv) : t->le;
            if (set->exact && t->textured &&
                max3(lx_v3(fabsf(le.x - t->le.x), fabsf(le.y - t->le.y), fabsf(le.z - t->le.z))) <=
                    1e-5f * max3(t->le))
                le = t->le; /* the same emission read twice: no float noise */
            lx_vec3 base = set->exact ? t->le : lx_v3(0.0f, 0.0f, 0.0f);
            on[m] = lx_v3((float)((le.x - base.x) * g), (float)((le.y - base.y) * g),
                          (float)((le.z - base.z) * g));
            off[m] = lx_v3((float)(-base.x * g), (float)(-base.y * g), (float)(-base.z * g));
            /* the sample's direction weighted by what it brings when seen */
            ways[m] = lx_scale(d, (float)((double)max3(le) * g) / dist);
            rays[m] = lx_lift_shadow_ray(shadow_ray(b, p, ng, x, t->n, d), ng, map->lift, i);
            m++;
        }
        if (m == 0)
            continue;
        lx_tracer_occluded_batch(b->tracer, rays, m, true, occluded);
        for (uint32_t j = 0; j < m; j++) {
            lx_vec3 c = occluded[j] ? off[j] : on[j];
            sum[0] += c.x, sum[1] += c.y, sum[2] += c.z;
            double y = lx_luminance3(c);
            lum_sum += y, lum_squares += y * y;
            if (!set->exact && !occluded[j])
                dir[0] += ways[j].x, dir[1] += ways[j].y, dir[2] += ways[j].z;
        }
    }
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    *towards = len > 0.0 ? lx_v3((float)(dir[0] / len), (float)(dir[1] / len),
                                 (float)(dir[2] / len))
                         : n;
    double inv = 1.0 / (double)cells;
    /* the mean of `cells` samples (skipped cells are zeros) */
    double spread = cells > 1 ? (lum_squares - lum_sum * lum_sum * inv) / (double)(cells - 1) : 0.0;
    *variance = spread > 0.0 ? (float)(spread * inv) : 0.0f;
    return lx_v3((float)fmax(exact[0] + sum[0] * inv, 0.0), (float)fmax(exact[1] + sum[1] * inv, 0.0),
                 (float)fmax(exact[2] + sum[2] * inv, 0.0));
}

lx_status lx_emitter_set_create(lx_baker *b, lx_emitter_set **out)
{
    *out = NULL;
    if (b->emitter_count == 0)
        return LX_OK;
    emitter_set *set = malloc(sizeof *set);
    if (!set)
        return lx_fail(LX_ERR_NOMEM, "out of memory for the emitters");
    lx_status st = emitter_set_build(b, set);
    if (st != LX_OK) {
        free(set);
        return st;
    }
    if (set->count == 0) {
        lx_emitter_set_destroy(b, set);
        return LX_OK;
    }
    *out = set;
    return LX_OK;
}

void lx_emitter_set_destroy(const lx_baker *b, lx_emitter_set *set)
{
    if (!set)
        return;
    emitter_set_free(b, set);
    free(set);
}

lx_status lx_bake_emitters(lx_baker *b, const lx_emitter_set *set, float progress_base,
                           float progress_span)
{
    if (b->tracer_dirty) {
        lx_status st = lx_tracer_commit(b->tracer);
        if (st != LX_OK)
            return st;
        b->tracer_dirty = false;
    }
    lx_tile_walk w;
    lx_status st = lx_tile_walk_begin(b, progress_base, progress_span, 1, &w);
    if (st != LX_OK)
        return st;
    int threads = lx_thread_count(b->desc.threads);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int global = 0; global < w.tiles; global++) {
        if (w.cancelled)
            continue;
        uint32_t m, first, count;
        lx_tile_walk_at(&w, global, &m, &first, &count);
        lx_lightmap *map = &b->maps[m];
        for (uint32_t i = first; i < first + count; i++) {
            lx_vec3 towards;
            float variance;
            lx_vec3 e = texel_emitters(b, set, m, map, i, &towards, &variance);
            size_t pixel = map->texels[i].pixel;
            float *px = map->baked + 3 * pixel;
            px[0] += e.x, px[1] += e.y, px[2] += e.z;
            if (map->sampled) { /* sampled light: the denoiser's (bake_denoise.c) */
                float *ps = map->sampled + 3 * pixel;
                ps[0] += e.x, ps[1] += e.y, ps[2] += e.z;
                map->sampled_variance[pixel] += variance;
            }
            if (map->sh) {
                /* as an area light's: its irradiance from its mean direction */
                lx_sh4 add = {{0}};
                lx_sh4_add_lit_floor(&add, e, map->world_normal[i], towards, 0.1f);
                float *q = map->sh + pixel * LX_SH_FLOATS;
                for (int c = 0; c < LX_SH_FLOATS; c++)
                    q[c] += add.c[c];
            }
        }
        lx_tile_walk_done(&w, global, count);
    }
    return lx_tile_walk_end(&w);
}
